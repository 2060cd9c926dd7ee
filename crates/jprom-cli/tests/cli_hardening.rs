//! Issue 12 (hardening), the `jprom` program: absurd sizes in a study or its Matrix Market
//! files fail at once with exit status 2 (invalid study) or 1 (failed run) and a message
//! naming the key, instead of aborting after minutes; a non-symmetric K is refused; and the
//! run exits non-zero when any output (CSV, SVG, stdout) cannot be written.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn jprom(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_jprom")).args(args).output().expect("run jprom");
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-hardening").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn check_refuses_absurd_sizes_with_key_and_line() {
    let dir = scratch("check");
    let f = dir.join("nt.toml");
    std::fs::write(&f, "[model]\nkind = \"blade\"\n[hbm]\nnt = 1099511627776\n").unwrap();
    for cmd in ["check", "run"] {
        let t = Instant::now();
        // (check writes nothing: it takes no --out)
        let out = dir.join("out");
        let args = if cmd == "run" { vec![cmd, f.to_str().unwrap(), "--out", out.to_str().unwrap()] } else { vec![cmd, f.to_str().unwrap()] };
        let (code, _, err) = jprom(&args);
        assert_eq!(code, 2, "{cmd}: {err}");
        assert!(err.contains("hbm.nt") && err.contains("line 4") && err.contains("limit of 65536"), "{cmd}: {err}");
        assert!(t.elapsed() < Duration::from_secs(5));
    }
}

/// A Matrix Market study over the files `mass`, `stiffness` in `dir` (the DoF map is never
/// reached when a matrix is refused).
fn mm_study(dir: &Path, mass: &str, stiffness: &str) -> PathBuf {
    std::fs::write(dir.join("M.mtx"), mass).unwrap();
    std::fs::write(dir.join("K.mtx"), stiffness).unwrap();
    std::fs::write(
        dir.join("nodes.json"),
        r#"{"format": "jprom-dof-map", "version": 1, "n_dof": 3, "nodes": [{"id": 1, "coords": [0, 0, 0], "dofs": [0, 1, 2]}]}"#,
    )
    .unwrap();
    let study = dir.join("study.toml");
    std::fs::write(
        &study,
        "[model]\nkind = \"matrix_market\"\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\ndof_map = \"nodes.json\"\ncb_modes = 1\noutput_nodes = [1]\n\
         [[model.contacts]]\nnodes = [1]\nnormal = [0.0, 0.0, 1.0]\nmu = 0.4\nkt1 = 2.0e4\nkt2 = 2.0e4\nkn = 2.3e4\n\
         [forcing]\nlevels = [0.1]\n[[forcing.harmonic]]\nnodes = [1]\ndirection = [1.0, 0.0, 0.0]\nmagnitude = 1.0\n",
    )
    .unwrap();
    study
}

const IDENTITY3: &str = "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n1 1 1.0\n2 2 1.0\n3 3 1.0\n";

#[test]
fn matrix_market_files_with_absurd_size_lines_fail_at_once() {
    let dir = scratch("mm_sizes");
    // (the run checks the files' headers first: a size unlike the stiffness' is found there,
    // with the study's line of the key)
    for (size_line, says, line) in [
        ("1000000 1000000 1000000000000", "1000000 x 1000000, but model.stiffness is 3 x 3", "line 3"),
        ("1000000000 1000000000 1", "at least one entry per row", "line 2"),
    ] {
        let mass = format!("%%MatrixMarket matrix coordinate real symmetric\n{size_line}\n1 1 1.0\n");
        let study = mm_study(&dir, &mass, IDENTITY3);
        let t = Instant::now();
        let (code, _, err) = jprom(&["run", study.to_str().unwrap(), "--out", dir.join("out").to_str().unwrap()]);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("model.mass") && err.contains("M.mtx") && err.contains(line) && err.contains(says), "{err}");
        assert!(t.elapsed() < Duration::from_secs(5), "took {:?}", t.elapsed());
    }
}

#[test]
fn a_general_stiffness_with_an_entry_above_the_diagonal_only_is_refused() {
    let dir = scratch("mm_symmetry");
    let k = "%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 2.0e4\n1 2 -1.0e4\n2 2 2.0e4\n3 3 1.0e4\n";
    let study = mm_study(&dir, IDENTITY3, k);
    let (code, _, err) = jprom(&["run", study.to_str().unwrap(), "--out", dir.join("out").to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("model.stiffness") && err.contains("entry (1, 2) = -1e4 while (2, 1) = 0e0 (not given)"), "{err}");
}

/// A small full-order-only blade study.
fn small_blade_study(dir: &Path, plots: bool) -> PathBuf {
    let f = dir.join("small.toml");
    std::fs::write(
        &f,
        format!(
            "[model]\nkind = \"blade\"\ncb_modes = 20\n[band]\nhz_start = 2140.0\nhz_end = 2190.0\npoints = 8\n\
             [forcing]\nlevels = [0.1]\n[solvers]\nfr = false\nnlr = false\n[output]\nplots = {plots}\n"
        ),
    )
    .unwrap();
    f
}

#[test]
fn a_run_exits_non_zero_when_an_output_cannot_be_written() {
    let dir = scratch("outputs");
    let study = small_blade_study(&dir, true);
    // the CSV of the full-order sweep goes to a full device
    let out = dir.join("csv-out");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink("/dev/full", out.join("alpha_ST_x1e-1_fo.csv")).unwrap();
    let (code, stdout, err) = jprom(&["run", study.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(code, 1, "{stdout}\n{err}");
    assert!(err.contains("alpha_ST_x1e-1_fo.csv") && err.contains("No space left"), "{err}");
    // a plot cannot be written: everything before it is, and the run still fails
    let out = dir.join("svg-out");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink("/dev/full", out.join("frf_alpha_ST_x1e-1.svg")).unwrap();
    let (code, stdout, err) = jprom(&["run", study.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(code, 1, "{stdout}\n{err}");
    assert!(err.contains("frf_alpha_ST_x1e-1.svg") && err.contains("No space left"), "{err}");
    assert!(out.join("summary.json").exists() && out.join("alpha_ST_x1e-1_fo.csv").exists());
}

#[test]
fn a_full_standard_output_is_a_failure_not_a_panic() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/demo_study.toml");
    let o = Command::new(env!("CARGO_BIN_EXE_jprom"))
        .args(["check", path])
        .stdout(Stdio::from(std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap()))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot write to standard output") && !err.contains("panicked"), "{err}");
}

/// `--memory-budget SIZE` caps what one stage may take: a blade run at 1M stops at the
/// Craig-Bampton reduction with the size it needs and the option that raises it; bad sizes
/// are usage errors; a size the run fits in runs it.
#[test]
fn memory_budget_option_stops_a_stage_with_what_it_needs() {
    let dir = scratch("memory-budget");
    let study = small_blade_study(&dir, false);
    let out = dir.join("out");
    let (code, stdout, err) = jprom(&["run", study.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet", "--memory-budget", "1M"]);
    assert_eq!(code, 1, "{stdout}\n{err}");
    assert!(err.contains("the Craig-Bampton reduction") && err.contains("more than the memory budget of 1.0 MiB (1048576 bytes)"), "{err}");
    assert!(err.contains("it needs about") && err.contains("raise it with --memory-budget SIZE") && !err.contains("jprom_set_memory_budget"), "{err}");
    for bad in ["0", "abc", "-5G", "12X", "G"] {
        let (code, _, err) = jprom(&["run", study.to_str().unwrap(), "--memory-budget", bad]);
        assert_eq!(code, 2, "--memory-budget {bad}: {err}");
        assert!(err.contains("--memory-budget needs a size") && err.contains(&format!("got '{bad}'")), "{err}");
    }
    let (code, stdout, err) = jprom(&["run", study.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet", "--memory-budget=1.5GiB"]);
    assert_eq!(code, 0, "{stdout}\n{err}");
    let (code, help, _) = jprom(&["run", "--help"]);
    assert_eq!(code, 0);
    assert!(help.contains("--memory-budget SIZE"), "{help}");
}
