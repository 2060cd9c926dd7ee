//! jprom JSON documents (model, solution, sweep, basis) from arbitrary text: a loader returns
//! a value or an error, never panics, and a loaded document's accessors stay in bounds.
#![no_main]

use jprom::hbm::{PointSolution, SweepResult};
use jprom::io::parse_document;
use jprom::jp::JpBasis;
use jprom::memory::MemoryBudget;
use jprom::model::Model;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // a budget well inside libFuzzer's memory limit: beyond it is a refusal, not an OOM
    MemoryBudget::set_global(Some(MemoryBudget::new(256 << 20)));
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = parse_document::<Model>(text, "fuzz");
    if let Ok(p) = parse_document::<PointSolution>(text, "fuzz") {
        touch(&p);
    }
    if let Ok(s) = parse_document::<SweepResult>(text, "fuzz") {
        s.points.iter().for_each(touch);
    }
    if let Ok(b) = parse_document::<JpBasis>(text, "fuzz") {
        let _ = b.n_unknowns();
    }
});

/// Every accessor a C caller can reach on a loaded point.
fn touch(p: &PointSolution) {
    for h in 0..=p.layout.harmonics {
        for j in 0..p.n_outputs {
            let _ = p.output_amplitude(h, j);
        }
    }
    let _ = p.dissipated_energy();
}
