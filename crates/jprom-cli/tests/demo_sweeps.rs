//! The README's demo (`jprom demo`, the built-in blade study `demo_study.toml`): every sweep of
//! every solver at every level covers the band, so the demo exits 0. The NLR sweep at the lower
//! level crosses hundreds of corners of its branch (contact samples changing state); it used to
//! stall there at the point cap (see the continuation's corner rule, docs/formulation.md §6).

use jprom_cli::run::{run_study, summary_table};
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

/// What the demo shows (README, "Two commands"): the paper's three regimes, from a peak where
/// most contact samples stick to gross slip, whose resonance is the slipping mode's, far below
/// the stuck one; one JP basis for every level, which the self-correcting sweep corrects at
/// gross slip; the ROMs within 1 % of the full order's `|X1|` at its resonance at every level;
/// a speed-up for every ROM row and the totals over the levels.
#[test]
fn demo_covers_stick_to_gross_slip_with_one_basis_corrected_where_poor() {
    let study = Study::from_file(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/demo_study.toml"))).unwrap();
    let levels = &study.forcing.levels;
    assert_eq!(levels.len(), 3);
    assert!(levels[2] <= 1.0 / 3000.0 + 1e-9, "the gross-slip level is alpha_ST / 3000");
    let mut quiet = study.clone();
    quiet.output.plots = false;
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("demo-regimes");
    let s = run_study(&quiet, &out, false).unwrap();
    let fo = |level: f64| s.rows.iter().find(|r| r.level == level && r.solver.starts_with("FO")).unwrap();
    // near stuck: the peak at the stuck resonance, more samples stuck than slipping;
    // gross slip: at the slipping mode (1,672 Hz), far below the stuck resonance
    assert!((fo(levels[0]).peak_hz - s.stuck_resonance_hz).abs() < 2.0, "{}", fo(levels[0]).peak_hz);
    assert!(fo(levels[1]).peak_hz < fo(levels[0]).peak_hz - 5.0);
    assert!((fo(levels[2]).peak_hz - 1672.0).abs() < 10.0, "{}", fo(levels[2]).peak_hz);
    assert_eq!(s.shared_bases.len(), 1);
    let basis = &s.shared_bases[0];
    assert!(basis.failed.is_none() && basis.patterns > 10, "{basis:?}");
    for r in s.rows.iter().filter(|r| !r.solver.starts_with("FO")) {
        let e = r.error_x1.expect("errors at the FO resonance");
        assert!(e < 0.01, "{} at {:e}: |X1| error {e}", r.solver, r.level);
        assert!(r.speed_up.is_some_and(|x| x > 0.0), "{r:?}");
        assert!(r.sweep_seconds >= basis.seconds / 3.0, "a ROM row counts its share of the shared basis");
        // why the corrections ended agrees with the judged error and the threshold
        let within = r.worst_error.unwrap() <= study.basis.error_threshold;
        assert_eq!(r.corrections_end.as_deref() == Some("within_threshold"), within, "{r:?}");
        // the static contact displacement's error is reported, and warned of above the threshold
        let w0 = r.static_contact_error.expect("the demo's checks give the static error");
        let warned = r.warnings.iter().any(|w| w.contains("static term X0 is poor"));
        assert_eq!(warned, w0 > study.basis.error_threshold, "{r:?}");
        // where the static contact displacement is off, so is X0 at the outputs
        if w0 > 1.0 {
            assert!(r.error_x0.unwrap() > 1.0, "static error {w0} but err X0 {:?}", r.error_x0);
        }
        if r.level == levels[2] {
            assert!(r.corrections >= 1, "the stuck-mode basis is corrected at gross slip");
            assert!(r.worst_error.unwrap() <= study.basis.error_threshold, "corrected within the threshold: {:?}", r.worst_error);
        }
    }
    assert!(s.rows.iter().filter(|r| r.solver.starts_with("FO")).all(|r| r.corrections_end.is_none()), "a full-order row has no corrections");
    assert_eq!(s.totals.iter().filter(|t| t.speed_up.is_some()).count(), 2, "FR and NLR totals against the full order");
    assert!(summary_table(&s).contains("speed-up"));
}

/// An NLR sweep over a wide band (1,620-2,200 Hz, the blade's slip and stuck resonances) at
/// alpha_ST / 20 meets, near its peak, a stick-slip kink that the smallest step cannot resolve:
/// the continuation used to take that 83-degree turn, and the steps after it retraced the
/// branch back down the band until the point cap (1,200 points, ending at 26 % of the band).
/// Now the restart steps over it: the sweep reaches the band's end and never goes back by more
/// than a fold's width.
#[test]
fn nlr_sweep_steps_over_a_sharp_kink_instead_of_retracing_the_branch() {
    let study = Study::from_toml_str(
        r#"
[model]
kind = "blade"
refinement = 1
cb_modes = 50
[model.damping]
beta = 2.9402e-7
[band]
hz_start = 1620.0
hz_end = 2200.0
points = 60
[forcing]
levels = [0.05]
[basis]
max_corrections = 0
[solvers]
full_order = false
fr = false
nlr = true
[output]
plots = false
"#,
    )
    .unwrap();
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("nlr-kink");
    let summary = run_study(&study, &out, false).unwrap();
    let row = &summary.rows[0];
    println!("NLR: {} points, end {}", row.points, row.end);
    assert_eq!(row.end, "reached_end", "{:?}", row.warnings);
    let csv = std::fs::read_to_string(out.join("alpha_ST_x5e-2_nlr.csv")).unwrap();
    let hz: Vec<f64> = csv.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    let mut highest = f64::NEG_INFINITY;
    for &f in &hz {
        highest = highest.max(f);
        assert!(f > highest - 1.0, "the sweep went back from {highest} Hz to {f} Hz");
    }
}
