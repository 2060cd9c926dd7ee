//! Issue 11, acceptance 3, from the `jprom` program: a sweep forced to stall makes `jprom run`
//! exit with 3 and say which sweep stopped where; the summary flags it.

mod slip_onset;

/// The twisted plate's study (tests/slip_onset) at the stuck limit with `max_iterations = 1`
/// and no room to shorten the step: `jprom run` exits with 3 and says which sweep stopped where,
/// the summary flags it, the CSV carries the end, and `--keep-partial` accepts it.
#[test]
fn forced_stall_is_reported_by_the_jprom_program() {
    let fe = jprom::fe::PlateFe::build(&slip_onset::plate_params()).unwrap();
    let dir = slip_onset::scratch("cli-stall");
    let path = slip_onset::export_plate(&fe, &dir, (307.7, 345.4), 1);
    let study = std::fs::read_to_string(&path).unwrap();
    let study = study
        .replace("nt = 64", "nt = 64\nmax_iterations = 1")
        .replace("points = 100", "points = 100\nmin_step = 0.05\nmax_step = 0.05")
        .replace("levels = [1.0]", "levels = [0.5]")
        + "[solvers]\nfull_order = true\nfr = false\nnlr = false\n[output]\ndir = \"out\"\nplots = false\n";
    std::fs::write(&path, study).unwrap();
    let run = |extra: &[&str]| std::process::Command::new(env!("CARGO_BIN_EXE_jprom")).arg("run").arg(&path).args(extra).output().unwrap();
    let out = run(&[]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    println!("{stdout}\n{stderr}");
    assert_eq!(out.status.code(), Some(3), "exit code");
    assert!(stderr.contains("did not cover the band") && stderr.contains("stalled at omega"), "{stderr}");
    assert!(stdout.contains("stalled (!)") && stdout.contains("read with care"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("out/alpha_ST_x5e-1_fo.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(",sweep_end") && csv.lines().skip(1).all(|l| l.ends_with(",stalled")), "{csv}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rows"][0]["end"], "stalled");
    assert_eq!(summary["rows"][0]["complete"], false);
    assert_eq!(summary["incomplete"].as_array().unwrap().len(), 1);
    assert_eq!(run(&["--keep-partial"]).status.code(), Some(0));
}
