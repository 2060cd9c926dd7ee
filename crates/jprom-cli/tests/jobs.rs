//! `jprom run --jobs N` (issue 16): a study's units (a solver at a level of a case) run in N
//! threads give the same CSVs and plots, byte for byte, as one at a time; a unit that fails is a
//! row of the summary naming it and why, the other units' results are kept and the exit status
//! is 3. A study with parameter cases: the same, each case's files prefixed with its name, its
//! parameters reaching its results, and a case without overrides giving the study's own files.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Two levels, FO, FR and NLR: six units, the ROMs of a level waiting for its FO (about 18 s).
const STUDY: &str = include_str!("studies/two_levels.toml");

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("jobs-tests");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// Runs `jprom run STUDY --out <name> --jobs <jobs> --quiet` with `env`: exit status, stdout, stderr.
fn run(name: &str, jobs: &str, env: &[(&str, &str)]) -> (i32, String, String, PathBuf) {
    let study = scratch("two_levels.toml");
    std::fs::write(&study, STUDY).unwrap();
    let out = scratch(name);
    let _ = std::fs::remove_dir_all(&out);
    let o = Command::new(env!("CARGO_BIN_EXE_jprom"))
        .args(["run", study.to_str().unwrap(), "--out", out.to_str().unwrap(), "--jobs", jobs, "--quiet"])
        .env_remove("JPROM_FAIL_UNIT")
        .envs(env.iter().copied())
        .output()
        .expect("run jprom");
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned(), out)
}

/// The files of `dir` with `ext`, sorted by name.
fn files(dir: &Path, ext: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).filter(|n| n.ends_with(ext)).collect();
    v.sort();
    v
}

#[test]
fn two_jobs_write_the_same_files_as_one_and_a_failing_unit_is_reported() {
    let (code, out1, err1, dir1) = run("jobs1", "1", &[]);
    assert_eq!(code, 0, "{out1}\n{err1}");
    let (code, out2, err2, dir2) = run("jobs2", "2", &[]);
    assert_eq!(code, 0, "{out2}\n{err2}");
    let csvs = files(&dir1, ".csv");
    assert_eq!(csvs.len(), 6, "{csvs:?}");
    assert_eq!(csvs, files(&dir2, ".csv"));
    for f in csvs.iter().chain(&files(&dir1, ".svg")) {
        let (a, b) = (std::fs::read(dir1.join(f)).unwrap(), std::fs::read(dir2.join(f)).unwrap());
        assert!(a == b, "{f} differs between --jobs 1 and --jobs 2");
    }
    assert_eq!(files(&dir1, ".svg"), files(&dir2, ".svg"));

    // unit 1 is FR at the first level (units: FO, FR, NLR at 0.3, then at 0.1); it panics in a
    // worker thread: its row says so, the others' results are the same as above, exit status 3
    let (code, out, err, dir) = run("fail", "2", &[("JPROM_FAIL_UNIT", "1:panic")]);
    assert_eq!(code, 3, "{out}\n{err}");
    assert!(out.contains("unit 1 (FR at level 3e-1)") && out.contains("forced panic of unit 1"), "{out}");
    assert!(err.contains("FR at level 3e-1") && err.contains("did not cover the band"), "{err}");
    let kept = files(&dir, ".csv");
    assert_eq!(kept.len(), 5, "{kept:?}");
    assert!(!kept.contains(&"alpha_ST_x3e-1_fr.csv".to_string()), "{kept:?}");
    for f in &kept {
        assert!(std::fs::read(dir.join(f)).unwrap() == std::fs::read(dir1.join(f)).unwrap(), "{f} differs from the run without failure");
    }
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let rows = summary["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    assert_eq!(rows[1]["solver"], "FR");
    assert_eq!(rows[1]["end"], "failed");

    // an error (not a panic) in one thread of one: the same report
    let (code, out, _, _) = run("fail-error", "1", &[("JPROM_FAIL_UNIT", "4")]);
    assert_eq!(code, 3);
    assert!(out.contains("unit 4 (FR at level 1e-1)") && out.contains("forced failure (JPROM_FAIL_UNIT)"), "{out}");
}

/// Two cases ("base": the study's parameters; "mu0.2": mu 0.2 and kn 3e4) x two levels x FO,
/// FR, NLR: twelve units.
const CASES: &str = include_str!("studies/two_cases.toml");

/// Runs `jprom run` on `text` (written as `file`) into `name` with `--jobs jobs`.
fn run_text(file: &str, text: &str, name: &str, jobs: &str) -> (i32, String, PathBuf) {
    let study = scratch(file);
    std::fs::write(&study, text).unwrap();
    let out = scratch(name);
    let _ = std::fs::remove_dir_all(&out);
    let o = Command::new(env!("CARGO_BIN_EXE_jprom"))
        .args(["run", study.to_str().unwrap(), "--out", out.to_str().unwrap(), "--jobs", jobs, "--quiet"])
        .env_remove("JPROM_FAIL_UNIT")
        .output()
        .expect("run jprom");
    (o.status.code().unwrap_or(-1), format!("{}\n{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)), out)
}

#[test]
fn a_study_with_cases_gives_the_same_files_with_two_jobs_and_each_case_its_own_results() {
    let (code, out1, dir1) = run_text("two_cases.toml", CASES, "cases-jobs1", "1");
    assert_eq!(code, 0, "{out1}");
    let (code, out2, dir2) = run_text("two_cases.toml", CASES, "cases-jobs2", "2");
    assert_eq!(code, 0, "{out2}");
    let csvs = files(&dir1, ".csv");
    assert_eq!(csvs.len(), 12, "{csvs:?}");
    assert_eq!(csvs, files(&dir2, ".csv"));
    assert_eq!(files(&dir1, ".svg"), files(&dir2, ".svg"));
    for f in csvs.iter().chain(&files(&dir1, ".svg")) {
        assert!(f.starts_with("base_") || f.starts_with("mu0.2_"), "{f} has no case prefix");
        let (a, b) = (std::fs::read(dir1.join(f)).unwrap(), std::fs::read(dir2.join(f)).unwrap());
        assert!(a == b, "{f} differs between --jobs 1 and --jobs 2");
    }
    assert!(csvs.contains(&"mu0.2_alpha_ST_x1e-1_fo.csv".to_string()) && files(&dir1, ".svg").contains(&"mu0.2_frf_alpha_ST_x1e-1.svg".to_string()), "{csvs:?}");

    // the summary: a case per row, each case's own level reference
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir1.join("summary.json")).unwrap()).unwrap();
    let rows = summary["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 12);
    let cases: Vec<&str> = rows.iter().map(|r| r["case"].as_str().unwrap()).collect();
    assert_eq!(cases, [["base"; 6], ["mu0.2"; 6]].concat());
    let reference = summary["cases"].as_array().unwrap();
    assert_eq!(reference.len(), 2);
    assert_eq!(reference[1]["name"], "mu0.2");
    assert_ne!(reference[0]["stuck_limit_force"], reference[1]["stuck_limit_force"]);
    assert!(out1.contains("case mu0.2 (mu = 0.2, kn = 30000)") && out1.lines().any(|l| l.starts_with("mu0.2 ") && l.contains("3.0e-1 FR ")), "{out1}");
    // the parameters reach the model: at the same a/a_ST, half the friction gives a smaller peak
    for (base, other) in rows[..6].iter().zip(&rows[6..]) {
        let (a, b) = (base["peak_x1"].as_f64().unwrap(), other["peak_x1"].as_f64().unwrap());
        assert_eq!(base["solver"], other["solver"]);
        assert!(b < 0.9 * a, "{} at {}: peak |X1| {b:e} with mu 0.2 vs {a:e} with mu 0.4", base["solver"], base["level"]);
    }

    // the case with the study's own parameters is the study without cases, file by file
    let plain = CASES.split("\n[[cases]]").next().unwrap();
    let (code, out, dir) = run_text("two_cases_plain.toml", plain, "cases-plain", "2");
    assert_eq!(code, 0, "{out}");
    let plain_files: Vec<String> = files(&dir, ".csv").into_iter().chain(files(&dir, ".svg")).collect();
    // 6 CSVs; per level FRF of X1 and of X0, energy, its map, e*_1; predicted vs actual, error
    // vs level, the levels together
    assert_eq!(plain_files.len(), 6 + 13, "{plain_files:?}");
    for f in &plain_files {
        let a = std::fs::read(dir.join(f)).unwrap();
        let b = std::fs::read(dir1.join(format!("base_{f}"))).unwrap_or_default();
        assert!(a == b, "base_{f} differs from {f} of the study without cases");
    }
    let plain_summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert!(plain_summary.get("cases").is_none() && plain_summary["rows"][0].get("case").is_none(), "no case fields without cases");
    assert_eq!(plain_summary["stuck_limit_force"], reference[0]["stuck_limit_force"]);
}

#[test]
fn jobs_must_be_a_positive_integer() {
    for bad in ["0", "two", "-1"] {
        let o = Command::new(env!("CARGO_BIN_EXE_jprom")).args(["run", "study.toml", "--jobs", bad]).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "--jobs {bad}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("--jobs"), "--jobs {bad}");
    }
}
