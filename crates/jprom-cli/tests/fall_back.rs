//! Issue 59, item 4: `jprom run --fall-back` (`solvers.fall_back`). A study with only the FR
//! ROM whose threshold no basis can meet (1e-12, no corrections) ends with FR rows that are not
//! trusted; with fall back the full order runs at each level and gives its result, with the
//! same peak as a study that runs the full order itself; without it there is no full-order row.

use serde_json::Value;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("jprom-fall-back-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The two-level blade study with FR only (and the full order where `full_order`), at a
/// threshold of 1e-12.
fn study(dir: &Path, full_order: bool) -> PathBuf {
    let base = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/studies/two_levels.toml")).unwrap();
    let text = base
        .replace("max_corrections = 0", "max_corrections = 0\nerror_threshold = 1e-12")
        .replace("full_order = true", &format!("full_order = {full_order}"))
        .replace("nlr = true", "nlr = false")
        .replace("plots = true", "plots = false");
    assert!(text.contains("error_threshold = 1e-12") && text.contains("nlr = false"), "the study changed: {text}");
    let path = dir.join("study.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn run(path: &Path, out: &Path, extra: &[&str]) -> (Option<i32>, String, Value) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_jprom")).arg("run").arg(path).arg("--out").arg(out).arg("--quiet").args(extra).output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout).to_string();
    println!("{stdout}\n{}", String::from_utf8_lossy(&o.stderr));
    let summary = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    (o.status.code(), stdout, summary)
}

fn rows<'a>(s: &'a Value, solver: &str) -> Vec<&'a Value> {
    s["rows"].as_array().unwrap().iter().filter(|r| r["solver"].as_str().unwrap().starts_with(solver)).collect()
}

#[test]
fn the_full_order_stands_in_where_the_reduced_sweep_is_not_trusted() {
    let dir = scratch("fr-only");
    let path = study(&dir, false);

    let (code, _, plain) = run(&path, &dir.join("plain"), &[]);
    assert_eq!(code, Some(0), "an untrusted sweep that covered the band is not a failed run");
    assert!(rows(&plain, "FO").is_empty(), "no full order without fall back");
    let fr = rows(&plain, "FR");
    assert_eq!(fr.len(), 2);
    assert!(fr.iter().all(|r| r["trusted"] == false && r["peak_hz"].is_null()), "a 1e-12 threshold cannot be met: {fr:?}");

    let (code, stdout, fell) = run(&path, &dir.join("fell"), &["--fall-back"]);
    assert_eq!(code, Some(0));
    let levels: Vec<f64> = fell["rows"].as_array().unwrap().iter().map(|r| r["level"].as_f64().unwrap()).collect();
    assert_eq!(levels, [0.3, 0.3, 0.1, 0.1], "each level's full order after its reduced row");
    for fo in rows(&fell, "FO") {
        let why = fo["stands_in_for"].as_array().unwrap();
        assert_eq!(why.len(), 1);
        assert!(why[0].as_str().unwrap().starts_with("FR: not trusted"), "{why:?}");
        assert_eq!(fo["complete"], true);
        assert!(fo["peak_hz"].as_f64().unwrap() > 2140.0);
    }
    for fr in rows(&fell, "FR") {
        assert!(fr["warnings"].as_array().unwrap().iter().any(|w| w.as_str().unwrap().contains("stands in for this one")), "{fr}");
    }
    assert!(stdout.contains("gives the level's result in place of"), "{stdout}");

    // the same sweep as a study that runs the full order itself, where the flag only marks it
    let with_fo = study(&dir, true);
    let (code, _, full) = run(&with_fo, &dir.join("full"), &["--fall-back"]);
    assert_eq!(code, Some(0));
    let (a, b) = (rows(&fell, "FO"), rows(&full, "FO"));
    assert_eq!(a.len(), b.len());
    for (a, b) in a.iter().zip(&b) {
        for key in ["peak_hz", "peak_x1"] {
            let (x, y) = (a[key].as_f64().unwrap(), b[key].as_f64().unwrap());
            assert!((x - y).abs() <= 1e-9 * y.abs(), "{key}: {x} vs {y}");
        }
        assert_eq!(a["stands_in_for"], b["stands_in_for"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
