//! How a study's results are labelled: the units of its CSV headers and summary, and its
//! response output in words.

use super::study::{ModelSpec, Study};

/// The units of the CSV headers and the summary: (length, energy). The built-in blade is in
/// mm, tonne, s (N, MPa): lengths in mm, energies in mJ (N mm). An FE model's units are its
/// FE code's: `lu` is its length unit, `flu` its force unit times `lu`.
pub fn units(study: &Study) -> (&'static str, &'static str) {
    match study.model {
        ModelSpec::Blade { .. } => ("mm", "mj"),
        _ => ("lu", "flu"),
    }
}

/// The response output in words, for plot labels: `the tip (flap)` for the blade's default,
/// else `output j`.
pub fn response_words(study: &Study) -> String {
    let j = study.response_output();
    if matches!(study.model, ModelSpec::Blade { .. }) && j == super::study::BLADE_TIP_FLAP_OUTPUT {
        "the tip (flap)".into()
    } else {
        format!("output {j}")
    }
}
