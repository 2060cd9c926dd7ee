//! The README's demo (`jprom demo`, the built-in blade study `demo_study.toml`): every sweep of
//! every solver at every level covers the band, so the demo exits 0. The NLR sweep at the lower
//! level crosses hundreds of corners of its branch (contact samples changing state); it used to
//! stall there at the point cap (see the continuation's corner rule, docs/formulation.md §6).

use jprom_cli::run::run_study;
use jprom_cli::study::Study;

#[test]
fn every_demo_sweep_reaches_the_end_of_the_band() {
    let mut study = Study::from_file(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/demo_study.toml"))).unwrap();
    // the sweeps only: the error-vs-size study and the plots are not what is checked here
    study.basis.gamma_study.clear();
    study.output.plots = false;
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("demo-sweeps");
    let summary = run_study(&study, &out, false).unwrap();
    for r in &summary.rows {
        println!("{:e} {:<16} {:>5} points  end {}", r.level, r.solver, r.points, r.end);
    }
    assert_eq!(summary.rows.len(), 3 * study.forcing.levels.len(), "FO, FR and NLR at each level");
    assert!(summary.incomplete.is_empty(), "sweeps that did not cover the band: {:?}", summary.incomplete);
    assert!(summary.rows.iter().all(|r| r.complete && r.end == "reached_end"));
}
