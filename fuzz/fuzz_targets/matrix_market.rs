//! Matrix Market text, read as a general matrix and as a symmetric (mass or stiffness) one.
#![no_main]

use jprom::io::matrix_market::{parse_matrix_market, parse_symmetric_matrix_market};
use jprom::memory::MemoryBudget;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    MemoryBudget::set_global(Some(MemoryBudget::new(256 << 20)));
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = parse_matrix_market(text, "fuzz");
    let _ = parse_symmetric_matrix_market(text, "fuzz");
});
