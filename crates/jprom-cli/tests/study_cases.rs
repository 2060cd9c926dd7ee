//! Parameter cases (`[[cases]]`, issue 16): each case is the study's model with its contact
//! parameters, damping ratio or static load, on the one Craig-Bampton reduction; bad cases are
//! refused naming the key and its line; `jprom check` lists them.

use jprom::JpError;
use jprom_cli::run::{build_case_models, build_model};
use jprom_cli::study::{CaseSpec, Study};
use jprom_cli::units::study_units;
use std::process::Command;

/// A small blade study (refinement 1, 20 fixed-interface modes) followed by `extra`.
fn blade(extra: &str) -> String {
    format!("[model]\nkind = \"blade\"\ncb_modes = 20\n[forcing]\nlevels = [0.3, 0.1]\n{extra}")
}

fn toml_error(text: &str) -> (usize, String) {
    match Study::from_toml_str(text) {
        Err(JpError::Parse { line, reason, .. }) => (line, reason),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn bad_cases_are_refused_naming_the_key_and_its_line() {
    // line numbers: the blade() header has 5 lines, so the first case table is on line 6
    for (cases, key, line, words) in [
        ("[[cases]]\nname = \"a\"\nfriction = 0.2\n", "cases[0].friction", 8, "unknown field"),
        ("[[cases]]\nname = \"a\"\n[[cases]]\nname = \"a\"\nmu = 0.2\n", "cases[1].name", 9, "already the name of cases[0]"),
        ("[[cases]]\nname = \"a/b\"\n", "cases[0].name", 7, "letters, digits"),
        ("[[cases]]\nname = \"\"\n", "cases[0].name", 7, "1 to 64"),
        ("[[cases]]\nname = \"..\"\n", "cases[0].name", 7, "must not start with '.'"),
        ("[[cases]]\nname = \"a\"\nmu = -0.1\n", "cases[0].mu", 8, "> 0"),
        ("[[cases]]\nname = \"a\"\n[[cases]]\nname = \"b\"\nkn = nan\n", "cases[1].kn", 10, "> 0"),
        ("[[cases]]\nname = \"a\"\ndamping_ratio = -1.0\n", "cases[0].damping_ratio", 8, ">= 0"),
        ("[[cases]]\nname = \"a\"\nstatic_scale = 0.0\n", "cases[0].static_scale", 8, "> 0"),
        ("[[cases]]\nmu = 0.2\n", "cases[0]", 6, "name"),
    ] {
        let (l, reason) = toml_error(&blade(cases));
        assert!(reason.contains(&format!("key '{key}")), "{cases}: {reason}");
        assert!(reason.contains(words), "{cases}: {reason}");
        assert_eq!(l, line, "{cases}: {reason}");
    }
    // an FE model's case: the values as its contact sets' (>= 0), in JSON too
    let fe = "{\"model\": {\"kind\": \"matrix_market\", \"mass\": \"M.mtx\", \"stiffness\": \"K.mtx\", \"dof_map\": \"d.json\", \"output_nodes\": [2],\n\
              \"contacts\": [{\"nodes\": [1], \"normal\": [1.0, 0.0, 0.0], \"mu\": 0.3, \"kt1\": 1.0, \"kt2\": 1.0, \"kn\": 1.0}]},\n\
              \"forcing\": {\"levels\": [0.1], \"harmonic\": [{\"nodes\": [2], \"direction\": [0.0, 1.0, 0.0], \"magnitude\": 1.0}]},\n\
              \"cases\": [{\"name\": \"ok\", \"mu\": 0.0},\n{\"name\": \"bad\", \"kt2\": -1.0}]}";
    match Study::from_json_str(fe) {
        Err(JpError::Parse { line, reason, .. }) => {
            assert!(reason.contains("key 'cases[1].kt2'") && reason.contains(">= 0"), "{reason}");
            assert_eq!(line, 5, "{reason}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn units_are_cases_then_levels_then_solvers() {
    let study = Study::from_toml_str(&blade("[[cases]]\nname = \"x\"\nmu = 0.3\n[[cases]]\nname = \"y\"\n")).unwrap();
    let units = study_units(&study);
    assert_eq!(units.len(), 12);
    let order: Vec<String> = units.iter().map(|u| u.describe()).collect();
    assert_eq!(order[0], "FO (condensed) at level 3e-1 of case x");
    assert_eq!(order[2], "NLR at level 3e-1 of case x");
    assert_eq!(order[3], "FO (condensed) at level 1e-1 of case x");
    assert_eq!(order[6], "FO (condensed) at level 3e-1 of case y");
    assert_eq!(order[11], "NLR at level 1e-1 of case y");
    // a ROM waits for the full-order unit of its own case and level
    assert_eq!(units[7].after, Some(6));
    assert_eq!(units[10].after, Some(9));
    // without cases: the units of today, unnamed
    let plain = study_units(&Study::from_toml_str(&blade("")).unwrap());
    assert_eq!(plain.len(), 6);
    assert_eq!(plain[1].describe(), "FR at level 3e-1");
}

/// Bit for bit: the same matrices, loads, contact laws and damping.
fn same_model(a: &jprom::model::Model, b: &jprom::model::Model) -> bool {
    serde_json::to_string(a).unwrap() == serde_json::to_string(b).unwrap()
}

#[test]
fn a_case_is_the_study_with_its_parameters_on_the_shared_reduction() {
    let base = Study::from_toml_str(&blade("")).unwrap();
    let case = |extra: &str| -> CaseSpec {
        let s = Study::from_toml_str(&blade(&format!("[[cases]]\nname = \"c\"\n{extra}"))).unwrap();
        s.cases[0].clone()
    };
    let cases = [CaseSpec::base(), case("mu = 0.2\ndamping_ratio = 0.004"), case("kn = 3.0e4\nkt1 = 1.5e4"), case("static_scale = 2.0")];
    let models = build_case_models(&base, &cases, jprom_cli::progress::Progress::Quiet).unwrap();
    // the study as written
    assert!(same_model(&models[0], &build_model(&base).unwrap()), "the base case is the study's model");
    // each case against the study that sets the same parameters in [model]
    for (i, model_keys) in [(1, "damping_ratio = 0.004\n[model.contact]\nmu = 0.2\n"), (2, "[model.contact]\nkn = 3.0e4\nkt1 = 1.5e4\n")] {
        let text = format!("[model]\nkind = \"blade\"\ncb_modes = 20\n{model_keys}[forcing]\nlevels = [0.3, 0.1]\n");
        let alone = build_model(&Study::from_toml_str(&text).unwrap()).unwrap();
        assert!(same_model(&models[i], &alone), "case {i} ({}) is not the study with its parameters", cases[i].describe());
        assert!(!same_model(&models[i], &models[0]), "case {i} is the base model");
    }
    // the stiffer contact's pre-twist is scaled again (same preload target, other stiffness)
    assert_ne!(models[2].excitation.static_force, models[0].excitation.static_force);
    assert_eq!(models[1].excitation.static_force, models[0].excitation.static_force);
    // static_scale multiplies f_E^0 and nothing else
    let doubled: Vec<f64> = models[0].excitation.static_force.iter().map(|f| 2.0 * f).collect();
    assert_eq!(models[3].excitation.static_force, doubled);
    assert_eq!(models[3].excitation.harmonics[0].cos, models[0].excitation.harmonics[0].cos);
}

#[test]
fn check_lists_the_cases() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("study-cases");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cases.toml");
    std::fs::write(&path, blade("[[cases]]\nname = \"mu0.2\"\nmu = 0.2\n[[cases]]\nname = \"stiff\"\nkn = 4.0e4\nstatic_scale = 1.5\n")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_jprom")).args(["check", path.to_str().unwrap()]).output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert!(out.contains("cases: 2 (units: 2 cases x 2 levels x 3 units per level = 12"), "{out}");
    assert!(out.contains("  mu0.2: mu = 0.2\n") && out.contains("  stiff: kn = 40000, static_scale = 1.5\n"), "{out}");
    assert!(out.contains("[[cases]]"), "the study in full shows the cases: {out}");
}
