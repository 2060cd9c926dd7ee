//! Study files, TOML and JSON (parsing and validation only: nothing is run).
#![no_main]

use jprom_cli::study::Study;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = Study::from_toml_str(text);
    let _ = Study::from_json_str(text);
});
