//! Issue 12 (hardening), study files: absurd sizes are refused by `check` (not by an abort in
//! the run), every value error carries the line of its key, and the blade refinements the
//! library accepts are accepted.

use jprom_cli::study::{ModelSpec, Study};
use jprom::JpError;

fn toml_error(text: &str) -> (usize, String) {
    match Study::from_toml_str(text) {
        Err(JpError::Parse { line, reason, .. }) => (line, reason),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

fn json_error(text: &str) -> (usize, String) {
    match Study::from_json_str(text) {
        Err(JpError::Parse { line, reason, .. }) => (line, reason),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn absurd_sizes_are_refused_by_check_with_their_key_line_and_limit() {
    let cases = [
        ("[hbm]\nnt = 1099511627776\n", "hbm.nt", 4, "1099511627776 is above jprom's limit of 65536"),
        ("[band]\npoints = 1000000000000\n", "band.points", 4, "1000000000000 is above jprom's limit of 100000"),
        ("[basis]\nsamples = 1000000000000\n", "basis.samples", 4, "1000000000000 is above jprom's limit of 10000"),
        ("cb_modes = 1000000000\n", "model.cb_modes", 3, "1000000000 is above jprom's limit of 5000"),
    ];
    for (tail, key, line, says) in cases {
        let text = format!("[model]\nkind = \"blade\"\n{tail}");
        let (l, r) = toml_error(&text);
        assert!(r.contains(&format!("key '{key}'")) && r.contains(says), "{key}: {r}");
        assert_eq!(l, line, "{key}: {r}");
        // and the message prints the line, not 'line 0'
        let shown = Study::from_toml_str(&text).unwrap_err().to_string();
        assert!(shown.contains(&format!("at line {line}")), "{shown}");
    }
}

#[test]
fn value_errors_carry_the_real_line_in_toml_and_json() {
    let (line, r) = toml_error("[model]\nkind = \"blade\"\n\n[band]\nhz_start = 2140.0\nhz_end = 2100.0\n");
    assert!(r.contains("band.hz_end"), "{r}");
    assert_eq!(line, 6);
    let (line, r) = toml_error("[model]\nkind = \"blade\"\n[forcing]\nlevels = [\n  0.1,\n  -1.0,\n]\n");
    assert!(r.contains("forcing.levels[1]"), "{r}");
    assert_eq!(line, 6);
    let (line, r) = json_error("{\n  \"model\": {\"kind\": \"blade\"},\n  \"band\": {\n    \"hz_start\": 2140.0,\n    \"points\": 1\n  }\n}");
    assert!(r.contains("band.points") && r.contains("at least 2"), "{r}");
    assert_eq!(line, 5);
    let (line, r) = json_error("{\"model\": {\"kind\": \"blade\"},\n \"hbm\": {\"nt\": 1099511627776}}");
    assert!(r.contains("hbm.nt") && r.contains("limit"), "{r}");
    assert_eq!(line, 2);
    // a key that is wrong by its default has no line of its own: no 'line 0' either
    let e = Study::from_toml_str("[model]\nkind = \"blade\"\n[hbm]\nharmonics = 16\n").unwrap_err().to_string();
    assert!(e.contains("hbm.nt") && !e.contains("line 0"), "{e}");
}

#[test]
fn the_blade_refinements_of_the_library_are_accepted() {
    for r in [1usize, 2, 5, 15] {
        let s = Study::from_toml_str(&format!("[model]\nkind = \"blade\"\nrefinement = {r}\n")).unwrap();
        assert!(matches!(s.model, ModelSpec::Blade { refinement, .. } if refinement == r));
    }
    let (line, r) = toml_error("[model]\nkind = \"blade\"\nrefinement = 0\n");
    assert!(r.contains("model.refinement") && r.contains("must be >= 1"), "{r}");
    assert_eq!(line, 3);
    let (_, r) = toml_error("[model]\nkind = \"blade\"\nrefinement = 16\n");
    assert!(r.contains("above jprom's limit of 15"), "{r}");
    // the blade's own rules on the contact law, under the study's key
    let (line, r) = toml_error("[model]\nkind = \"blade\"\n[model.contact]\nmu = 0.0\n");
    assert!(r.contains("model.contact.mu"), "{r}");
    assert_eq!(line, 4);
}

/// `output.response` picks the output the peak, the FRFs and the errors are of: the blade's
/// default is its tip flap displacement, an FE model's its first output, and an index past the
/// model's outputs is refused with the count before any sweep.
#[test]
fn the_response_output_defaults_per_model_and_is_checked_against_the_outputs() {
    let blade = Study::from_toml_str("[model]\nkind = \"blade\"\n").unwrap();
    assert_eq!(blade.response_output(), jprom_cli::study::BLADE_TIP_FLAP_OUTPUT);
    assert_eq!(jprom_cli::study::BLADE_TIP_FLAP_OUTPUT, 25, "node 9 of 9 (the tip), y (flap)");
    let given = Study::from_toml_str("[model]\nkind = \"blade\"\n[output]\nresponse = 4\n").unwrap();
    assert_eq!(given.response_output(), 4);
    let past = Study::from_toml_str("[model]\nkind = \"blade\"\n[solvers]\nfr = false\nnlr = false\n[output]\nresponse = 27\n").unwrap();
    match jprom_cli::run::build_shared(&past, jprom_cli::progress::Progress::Quiet) {
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains("output.response") && text.contains("27 outputs"), "{text}");
        }
        Ok(_) => panic!("output 27 of the blade's 27 accepted"),
    }
}
