//! `--reproducible`: the same numbers on any number of threads. The two-level study run on one
//! rayon thread and on two gives the same summary (every number but the times, to the last
//! bit) and the same CSVs with the flag; without it the summaries differ (faer's kernels round
//! differently on one and two threads: the Craig-Bampton stuck resonance already differs in
//! the 12th digit), which shows that the comparison would see a flag that does nothing.

use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

const STUDY: &str = include_str!("studies/two_levels.toml");

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("reproducible-tests");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// The summary without its times (keys ending in `seconds`, the speed-ups they make) and its
/// thread count.
fn without_times(v: Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(m.into_iter().filter(|(k, _)| !(k.ends_with("seconds") || k == "speed_up" || k == "threads")).map(|(k, v)| (k, without_times(v))).collect()),
        Value::Array(a) => Value::Array(a.into_iter().map(without_times).collect()),
        v => v,
    }
}

/// Runs the study on `threads` rayon threads: its summary without times, and its CSVs by name.
fn run(threads: &str, reproducible: bool) -> (Value, Vec<(String, String)>) {
    let study = scratch("two_levels.toml");
    std::fs::write(&study, STUDY).unwrap();
    let out = scratch(&format!("t{threads}-{reproducible}"));
    let _ = std::fs::remove_dir_all(&out);
    let mut args = vec!["run", study.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"];
    if reproducible {
        args.push("--reproducible");
    }
    let o = Command::new(env!("CARGO_BIN_EXE_jprom")).args(&args).env("RAYON_NUM_THREADS", threads).output().expect("run jprom");
    assert!(o.status.success(), "jprom {args:?} on {threads} thread(s): {}", String::from_utf8_lossy(&o.stderr));
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    // the summary says how it was run
    assert_eq!(summary["threads"].as_u64(), threads.parse::<u64>().ok(), "summary.json's threads");
    assert_eq!(summary["reproducible"].as_bool(), Some(reproducible), "summary.json's reproducible");
    let mut csvs: Vec<(String, String)> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read_to_string(&p).unwrap()))
        .collect();
    csvs.sort();
    (without_times(summary), csvs)
}

#[test]
fn reproducible_runs_give_the_same_numbers_on_one_and_two_threads() {
    let (s1, c1) = run("1", true);
    let (s2, c2) = run("2", true);
    assert!(c1.len() >= 6, "two levels, three solvers: {} CSVs", c1.len());
    assert!(s1 == s2, "with --reproducible the summaries differ between 1 and 2 threads:\n{s1}\n{s2}");
    assert!(c1 == c2, "with --reproducible the CSVs differ between 1 and 2 threads");
    let (d1, _) = run("1", false);
    let (d2, _) = run("2", false);
    assert!(d1 != d2, "without --reproducible the summaries on 1 and 2 threads were expected to differ in round-off (else this test cannot see a flag that does nothing)");
    println!("stuck resonance, reproducible: {} Hz; default: {} Hz (1 thread), {} Hz (2 threads)", s1["stuck_resonance_hz"], d1["stuck_resonance_hz"], d2["stuck_resonance_hz"]);
}
