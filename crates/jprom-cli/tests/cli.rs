//! The `jprom` program: bad study files are rejected with a message naming the key (issue 6,
//! acceptance 3); the demo study validates; a small study runs and writes sane results.

use std::process::Command;

fn jprom(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_jprom")).args(args).output().expect("run jprom");
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-tests");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

#[test]
fn malformed_study_is_rejected_naming_the_key() {
    let f = scratch("bad.toml");
    std::fs::write(&f, "[model]\nkind = \"blade\"\n[band]\nhz_start = 2190.0\nhz_end = 2140.0\n").unwrap();
    let (code, _, err) = jprom(&["check", f.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("band.hz_end") && err.contains("must be"), "{err}");
    std::fs::write(&f, "[model]\nkind = \"blade\"\n[hbm]\nharmonics = \"three\"\n").unwrap();
    let (code, _, err) = jprom(&["run", f.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("hbm.harmonics") && err.contains("line 4"), "{err}");
    let (code, _, err) = jprom(&["run", "/nonexistent/study.toml"]);
    assert_ne!(code, 0);
    assert!(err.contains("/nonexistent/study.toml"), "{err}");
    let (code, _, err) = jprom(&["frobnicate"]);
    assert_ne!(code, 0);
    assert!(err.contains("unknown command"), "{err}");
}

#[test]
fn demo_study_is_valid() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/demo_study.toml");
    let (code, out, err) = jprom(&["check", path]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("valid"));
}

#[test]
fn small_study_writes_results_and_the_rom_follows_the_full_order() {
    let f = scratch("small.toml");
    std::fs::write(
        &f,
        "[model]\nkind = \"blade\"\n[band]\nhz_start = 2140.0\nhz_end = 2190.0\npoints = 30\n\
         [forcing]\nlevels = [0.1]\n[basis]\ngamma = 1000.0\n[solvers]\nfr = false\n",
    )
    .unwrap();
    let out_dir = scratch("small-out");
    let _ = std::fs::remove_dir_all(&out_dir);
    let (code, out, err) = jprom(&["run", f.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}\n{err}");
    for file in ["alpha_ST_x1e-1_fo.csv", "alpha_ST_x1e-1_nlr.csv", "summary.json", "frf_alpha_ST_x1e-1.svg", "predicted_vs_actual_error.svg"] {
        assert!(out_dir.join(file).exists(), "missing {file}");
    }
    // peak |X1| of FO and NLR from the CSVs
    let peak = |name: &str| {
        let text = std::fs::read_to_string(out_dir.join(name)).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = header.iter().position(|h| *h == "X1").unwrap();
        lines.map(|l| l.split(',').nth(col).unwrap().parse::<f64>().unwrap()).fold(0.0, f64::max)
    };
    let (fo, nlr) = (peak("alpha_ST_x1e-1_fo.csv"), peak("alpha_ST_x1e-1_nlr.csv"));
    assert!(fo > 0.0 && (nlr - fo).abs() / fo < 0.03, "FO {fo} vs NLR {nlr}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["contacts"], 18);
    let rows = summary["rows"].as_array().unwrap();
    let nlr_row = rows.iter().find(|r| r["solver"] == "NLR").unwrap();
    let (ps, act) = (nlr_row["predicted_e1"].as_f64().unwrap(), nlr_row["actual_e1"].as_f64().unwrap());
    assert!(ps >= act, "predictor not conservative: e* {ps} < e {act}");
}
