//! The CLI's study file: valid files parse with their defaults, malformed ones are rejected
//! with a message naming the offending key and the reason (issue 6, acceptance 3).

use jprom_cli::study::{ModelSpec, Study};
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
    // the library's blade accepts any refinement >= 1; the study caps it at 15 (1,922 contacts)
    let (_, r) = reason("[model]\nkind = \"blade\"\nrefinement = 16\n");
    assert!(r.contains("model.refinement"), "{r}");
    let (_, r) = reason("[model]\nkind = \"plate\"\n");
    assert!(r.contains("model") && r.contains("plate"), "{r}");
}

#[test]
fn keys_inside_model_are_named_with_their_line() {
    let (line, r) = reason("[model]\nkind = \"blade\"\nrefinement = \"fine\"\n");
    assert!(r.contains("model.refinement") && r.contains("invalid type"), "{r}");
    assert_eq!(line, 3);
    let (_, r) = reason("[model]\nkind = \"blade\"\nrefinment = 2\n");
    assert!(r.contains("refinment") && r.contains("unknown field"), "{r}");
    let (_, r) = reason("[model]\nkind = \"blade\"\n[model.contact]\nmu = \"high\"\n");
    assert!(r.contains("model.contact.mu"), "{r}");
    // keys of the other kind
    let (_, r) = reason("[model]\nkind = \"blade\"\nmass = \"M.mtx\"\n");
    assert!(r.contains("model.mass") && r.contains("blade"), "{r}");
    let (_, r) = reason("[model]\nkind = \"matrix_market\"\nstiffness = \"K.mtx\"\ndof_map = \"n.json\"\n");
    assert!(r.contains("model.mass") && r.contains("required"), "{r}");
}

#[test]
fn gamma_study_values_name_their_key() {
    let (_, r) = reason("[model]\nkind = \"blade\"\n[basis]\ngamma_study = [100.0, 0.5]\n");
    assert!(r.contains("basis.gamma_study[1]"), "{r}");
    let (_, r) = reason("[model]\nkind = \"blade\"\n[basis]\ngamma_study = [100.0]\n[solvers]\nfull_order = false\n");
    assert!(r.contains("basis.gamma_study") && r.contains("full_order"), "{r}");
    let s = Study::from_toml_str("[model]\nkind = \"blade\"\n[basis]\ngamma_study = [10.0, 1e4]\n").unwrap();
    assert_eq!(s.basis.gamma_study, vec![10.0, 1e4]);
}

#[test]
fn a_study_prints_and_reads_back_the_same() {
    for text in ["[model]\nkind = \"blade\"\n", "[model]\nkind = \"matrix_market\"\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\ndof_map = \"n.json\"\noutput_nodes = [7]\n[[model.contacts]]\nnodes = [1]\nnormal = [0.0, 0.0, 1.0]\nmu = 0.3\nkt1 = 1.0\nkt2 = 1.0\nkn = 2.0\n[[forcing.harmonic]]\nnodes = [7]\ndirection = [1.0, 0.0, 0.0]\nmagnitude = 2.0\n",
        "[model]\nkind = \"calculix\"\ndeck = \"job.inp\"\noutput_nodes = \"OUT\"\n[[model.contacts]]\nnodes = \"TIP\"\naxis = { origin = [0.0, 0.0, 0.0], direction = [0.0, 0.0, 1.0], sense = \"outward\" }\nmu = 0.3\nkt1 = 1.0\nkt2 = 1.0\nkn = 2.0\n[[model.contacts]]\nnodes = [3, 4]\nnormals = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\nmu = 0.3\nkt1 = 1.0\nkt2 = 1.0\nkn = 2.0\n[[forcing.harmonic]]\nnodes = \"LOAD\"\ndirection = [1.0, 0.0, 0.0]\nmagnitude = 2.0\n"] {
        let s = Study::from_toml_str(text).unwrap();
        let again = Study::from_toml_str(&toml::to_string_pretty(&s).unwrap()).unwrap();
        assert_eq!(s, again);
    }
}

#[test]
fn json_studies_name_the_key_too() {
    let e = Study::from_json_str(r#"{"model": {"kind": "blade"}, "band": {"points": "many"}}"#).unwrap_err();
    match e {
        JpError::Parse { reason, .. } => assert!(reason.contains("band.points"), "{reason}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn slipping_samples_key_takes_its_three_words_and_names_itself_otherwise() {
    use jprom_cli::study::SlippingSpec;
    let s = Study::from_toml_str("[model]\nkind = \"blade\"\n").unwrap();
    assert_eq!(s.basis.slipping, SlippingSpec::Never);
    for (word, spec, lib) in [("never", SlippingSpec::Never, jprom::jp::SlippingSamples::Never), ("at_gross_slip", SlippingSpec::AtGrossSlip, jprom::jp::SlippingSamples::AtGrossSlip), ("always", SlippingSpec::Always, jprom::jp::SlippingSamples::Always)] {
        let s = Study::from_toml_str(&format!("[model]\nkind = \"blade\"\n[basis]\nslipping = \"{word}\"\n")).unwrap();
        assert_eq!(s.basis.slipping, spec);
        assert_eq!(jprom::jp::SlippingSamples::from(s.basis.slipping), lib);
    }
    let (line, r) = reason("[model]\nkind = \"blade\"\n[basis]\nslipping = \"sometimes\"\n");
    assert!(r.contains("basis.slipping") && r.contains("at_gross_slip"), "{r}");
    assert_eq!(line, 4);
}
