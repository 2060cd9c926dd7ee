//! The CLI's study file: valid files parse with their defaults, malformed ones are rejected
//! with a message naming the offending key and the reason (issue 6, acceptance 3).

use jprom::app::study::{ModelSpec, Study};
use jprom::JpError;

fn reason(text: &str) -> (usize, String) {
    match Study::from_toml_str(text) {
        Err(JpError::Parse { line, reason, .. }) => (line, reason),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn minimal_study_takes_documented_defaults() {
    let s = Study::from_toml_str("[model]\nkind = \"blade\"\n").unwrap();
    assert_eq!(s.band.hz_start, 2140.0);
    assert_eq!(s.band.hz_end, 2190.0);
    assert_eq!(s.hbm.harmonics, 1);
    match s.model {
        ModelSpec::Blade { refinement, cb_modes, .. } => assert_eq!((refinement, cb_modes), (1, 50)),
        _ => panic!("wrong model kind"),
    }
}

#[test]
fn wrong_type_names_the_key_and_line() {
    let (line, r) = reason("[model]\nkind = \"blade\"\n[band]\nhz_start = \"low\"\n");
    assert!(r.contains("band.hz_start"), "{r}");
    assert!(r.contains("invalid type"), "{r}");
    assert_eq!(line, 4);
}

#[test]
fn unknown_key_is_rejected_by_name() {
    let (_, r) = reason("[model]\nkind = \"blade\"\n[hbm]\nharmonic = 3\n");
    assert!(r.contains("harmonic"), "{r}");
    assert!(r.contains("unknown field"), "{r}");
}

#[test]
fn out_of_range_values_name_their_key() {
    let cases = [
        ("[band]\nhz_start = 2200.0\nhz_end = 2100.0\n", "band.hz_end"),
        ("[hbm]\nharmonics = 3\nnt = 8\n", "hbm.nt"),
        ("[forcing]\nlevels = [0.1, -1.0]\n", "forcing.levels[1]"),
        ("[basis]\ngamma = 0.5\n", "basis.gamma"),
        ("[solvers]\nfull_order = false\nfr = false\nnlr = false\n", "solvers"),
    ];
    for (tail, key) in cases {
        let text = format!("[model]\nkind = \"blade\"\n{tail}");
        let (_, r) = reason(&text);
        assert!(r.contains(&format!("'{key}'")), "{key}: {r}");
    }
    let (_, r) = reason("[model]\nkind = \"blade\"\nrefinement = 7\n");
    assert!(r.contains("model.refinement"), "{r}");
    let (_, r) = reason("[model]\nkind = \"plate\"\n");
    assert!(r.contains("model") && r.contains("plate"), "{r}");
}

#[test]
fn json_studies_name_the_key_too() {
    let e = Study::from_json_str(r#"{"model": {"kind": "blade"}, "band": {"points": "many"}}"#).unwrap_err();
    match e {
        JpError::Parse { reason, .. } => assert!(reason.contains("band.points"), "{reason}"),
        other => panic!("{other:?}"),
    }
}
