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
    // progress in plain lines (stderr is a pipe here): every long stage starts and ends with its time
    for stage in [
        "jprom: building the built-in blade (refinement 1) ...",
        "jprom: Craig-Bampton (50 fixed-interface modes): done in",
        "jprom: FO sweep, alpha_ST x 1e-1 ...",
        "jprom: JP basis for every level: done in",
        "jprom: NLR reduced model, alpha_ST x 1e-1: done in",
        "jprom: NLR sweep, alpha_ST x 1e-1, basis 0: done in",
    ] {
        assert!(err.contains(stage), "no '{stage}' in the progress:\n{err}");
    }
    // the FO sweep's line counts the points it really made (the CSV's rows)
    let fo_rows = std::fs::read_to_string(out_dir.join("alpha_ST_x1e-1_fo.csv")).unwrap().lines().count() - 1;
    assert!(err.contains("jprom: FO sweep, alpha_ST x 1e-1: done in") && err.lines().any(|l| l.starts_with("jprom: FO sweep") && l.contains(&format!(", {fo_rows} points"))), "{fo_rows} points:\n{err}");
    for file in ["alpha_ST_x1e-1_fo.csv", "alpha_ST_x1e-1_nlr.csv", "summary.json", "frf_alpha_ST_x1e-1.svg", "frf_x0_alpha_ST_x1e-1.svg", "predicted_vs_actual_error.svg", "predicted_error_vs_frequency_alpha_ST_x1e-1.svg", "energy_alpha_ST_x1e-1.svg", "error_vs_level.svg"] {
        assert!(out_dir.join(file).exists(), "missing {file}");
    }
    // the plots name H and the ROM's basis sizes and gamma in their legends
    let frf = std::fs::read_to_string(out_dir.join("frf_alpha_ST_x1e-1.svg")).unwrap();
    assert!(frf.contains("H = 1") && frf.contains("FO (condensed)") && frf.contains("NLR, n_h = [") && frf.contains("gamma = 1e3") && !frf.contains("FR,"), "frf legend");
    // the static term X0 along the same sweeps (the paper's Fig. 3c/d), one series per solver
    let x0 = std::fs::read_to_string(out_dir.join("frf_x0_alpha_ST_x1e-1.svg")).unwrap();
    assert!(x0.contains("Static term at the tip (flap)") && x0.contains("X0 at the tip (flap) [") && x0.contains("FO (condensed)") && x0.contains("NLR, n_h = [") && !x0.contains("FR,"), "X0 plot");
    for label in ["FO (condensed)", "NLR, n_h = ["] {
        assert_eq!(x0.matches(label).count(), frf.matches(label).count(), "the X0 plot names the X1 plot's series ({label})");
    }
    let e_star = std::fs::read_to_string(out_dir.join("predicted_error_vs_frequency_alpha_ST_x1e-1.svg")).unwrap();
    assert!(e_star.contains("predicted e*_1") && e_star.contains("threshold 0.05") && e_star.contains("NLR, n_h = ["), "e* plot");
    // and the linearised errors that judged the pass, as circles (the sweep's e* has none)
    assert!(e_star.contains("NLR, e_lin_1 at the checks") && e_star.matches("<circle").count() >= 2, "e* plot: the checks");
    // peak |X1| of FO and NLR from the CSVs
    let peak = |name: &str| {
        let text = std::fs::read_to_string(out_dir.join(name)).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        // the blade's response output: its tip's flap displacement
        let col = header.iter().position(|h| *h == "x1_out25_mm").unwrap();
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
    // the basis time is measured: part of the ROM's time, not zero
    let (basis, total) = (nlr_row["basis_seconds"].as_f64().unwrap(), nlr_row["sweep_seconds"].as_f64().unwrap());
    assert!(basis > 0.0 && basis < total, "basis {basis} s of {total} s");
    // --quiet: no progress at all
    let (code, _, err) = jprom(&["run", f.to_str().unwrap(), "--quiet", "--out", out_dir.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(err.is_empty(), "--quiet: {err}");
}

/// `--version`, `--help`/`-h` on every command (usage and options on stdout, exit 0, nothing
/// run), and an option a command does not take is a usage error (exit 2) naming it.
#[test]
fn version_help_and_unknown_options_follow_the_conventions() {
    let (code, out, _) = jprom(&["--version"]);
    assert_eq!(code, 0);
    assert_eq!(out.trim(), format!("jprom {}", env!("CARGO_PKG_VERSION")));
    let (code, out, _) = jprom(&["--help"]);
    assert_eq!(code, 0);
    for cmd in ["demo", "run", "check", "modes"] {
        assert!(out.contains(&format!("jprom {cmd}")), "top-level help lists {cmd}: {out}");
        for flag in ["--help", "-h"] {
            let (code, out, err) = jprom(&[cmd, flag]);
            assert_eq!(code, 0, "{cmd} {flag}: {err}");
            assert!(out.starts_with(&format!("usage: jprom {cmd}")) && out.contains("options:") && out.contains("--help, -h"), "{cmd} {flag}: {out}");
            // nothing was run: no model built, no progress, no results
            assert!(err.is_empty() && !out.contains("results in"), "{cmd} {flag} ran something: {err}");
        }
        // --help after other arguments, too
        let study: &[&str] = if cmd == "demo" { &[] } else { &["study.toml"] };
        let (code, out, _) = jprom(&[&[cmd], study, &["--help"]].concat());
        assert_eq!(code, 0);
        assert!(out.starts_with(&format!("usage: jprom {cmd}")));
        let (code, out, err) = jprom(&[&[cmd], study, &["--frobnicate"]].concat());
        assert_eq!(code, 2, "{cmd} --frobnicate: {out}");
        assert!(err.contains("'--frobnicate'") && err.contains(&format!("usage: jprom {cmd}")), "{err}");
    }
    let (_, out, _) = jprom(&["run", "--help"]);
    for opt in ["--out DIR", "--keep-partial", "--quiet"] {
        assert!(out.contains(opt), "run --help lists {opt}: {out}");
    }
    let (_, out, _) = jprom(&["modes", "-h"]);
    assert!(out.contains("--count N"), "{out}");
    // a value missing, an extra argument
    let (code, _, err) = jprom(&["run", "study.toml", "--out"]);
    assert_eq!(code, 2);
    assert!(err.contains("--out needs a value"), "{err}");
    let (code, _, err) = jprom(&["check", "a.toml", "b.toml"]);
    assert_eq!(code, 2);
    assert!(err.contains("unexpected argument 'b.toml'"), "{err}");
    let (code, _, err) = jprom(&["demo", "--quiet=yes"]);
    assert_eq!(code, 2);
    assert!(err.contains("--quiet takes no value"), "{err}");
}
