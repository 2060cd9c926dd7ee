//! Screening where a candidate's own response peaks (docs/formulation.md §10.5,
//! `rom::tangent_peak`) on the demo's gross-slip level: the demo's blade (50 contact nodes),
//! its shared basis (predicted at its largest level), `alpha_ST / 3000` over 1,620-2,200 Hz,
//! FR and NLR. The stuck-mode basis fails at the band's start; on two threads the candidates
//! regenerated there pass at the band's start and fail at the slipping resonance. Before the
//! tangent estimate only a pass over the band found that (a 109-point pass of a basis that then
//! failed, two passes in all); now such a candidate is judged there unswept, the next
//! correction regenerates from that point, and the only pass is the result's. Checked against
//! the full order: the tangent estimate from the result's solution at the band's start is the
//! full order's resonance within 0.5 %, and the result's `|X1|` there is within 1 % of the full
//! order's.

use jprom::condensation::CondensedSystem;
use jprom::hbm::{solve_point, sweep, HbmOptions, PointSolution};
use jprom::model::ContactCoordinates;
use jprom::rom::tangent_peak::tangent_peak;
use jprom::rom::{adaptive_sweep_from, AdaptiveOptions, CorrectionEnd, CorrectionKind, RomKind};
use jprom_cli::progress::Progress;
use jprom_cli::run::build_shared;
use jprom_cli::study::Study;
use std::collections::BTreeSet;
use std::f64::consts::TAU;
use std::ops::ControlFlow;

#[test]
fn gross_slip_candidates_are_judged_at_their_resonance_without_a_pass() {
    let study = Study::from_file(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/demo_study.toml"))).unwrap();
    let study = jprom_cli::run::writing_to(&study, &std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("resonance-screening"));
    assert!(study.forcing.levels[2] <= 1.0 / 3000.0 + 1e-9, "the demo's gross-slip level is alpha_ST / 3000");
    let shared = build_shared(&study, Progress::for_stderr(true)).unwrap();
    let case = &shared.cases[0];
    let start = case.basis.clone().expect("the demo runs ROMs").expect("the shared basis");
    let mut model = case.model.clone();
    model.excitation.dynamic_scale = case.scales[2];
    let disc = study.discretisation();
    let coords = ContactCoordinates::new(&model, disc).unwrap();
    let condensed = CondensedSystem::new(&model, disc).unwrap();
    let band = (TAU * study.band.hz_start, TAU * study.band.hz_end);
    let popts = jprom_cli::run::prediction_options(&study);
    let sopts = study.band.sweep_options();
    let hopts = HbmOptions::default();
    let response = study.response_output();

    // the full order's resonance, independently
    let fo = sweep(&condensed, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    let peak = |pts: &[PointSolution]| pts.iter().map(|p| (p.omega, p.output_amplitude(1, response))).fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    let (w_fo, x_fo) = peak(&fo.points);
    println!("full order: |X1| {x_fo:.5e} at {:.2} Hz", w_fo / TAU);

    for kind in [RomKind::Fr, RomKind::Nlr] {
        let aopts = AdaptiveOptions {
            kind,
            threshold: study.basis.error_threshold,
            max_corrections: study.basis.max_corrections,
            regeneration_samples: study.basis.regeneration_samples,
            screen: true,
            response_output: response,
            ..AdaptiveOptions::default()
        };
        let mut passes = BTreeSet::new();
        let out = adaptive_sweep_from(&coords, Some(&condensed), (start.basis.clone(), start.prediction.clone()), &popts, &sopts, &hopts, &aopts, &mut |pass, _| {
            passes.insert(pass);
            ControlFlow::Continue(())
        })
        .unwrap();
        for c in &out.corrections {
            println!("{kind:?}: {:?} {:?}: {:.3e} -> {:.3e}, swept {}", c.kind, c.sizes, c.worst_error_before, c.worst_error_after, c.swept);
        }
        println!("{kind:?}: passes {passes:?}, final {:?}, judged {:.3e}", out.basis.sizes, out.worst_error);
        assert_eq!(out.end, CorrectionEnd::WithinThreshold, "{kind:?}: judged {:.3e}", out.worst_error);
        // one pass over the band, the result's: every candidate before it was judged at points
        assert_eq!(passes.len(), 1, "{kind:?}: passes {passes:?}");
        assert!(out.corrections.iter().rev().skip(1).all(|c| !c.swept), "{kind:?}: a correction before the last was swept");
        // where the corrections regenerated from (at the band's start, and on two threads
        // also at the slipping resonance found by screening; the path depends on round-off:
        // on one thread NLR's gamma step is judged at the band's start, 0.052, and is not
        // screened further)
        let from: Vec<f64> = out
            .corrections
            .iter()
            .filter_map(|c| match c.kind {
                CorrectionKind::Regenerated { from_omega } | CorrectionKind::Replaced { from_omega } => Some(from_omega / TAU),
                _ => None,
            })
            .collect();
        println!("{kind:?}: regenerated from {from:.2?} Hz");
        // the estimate screening uses, from the result at the band's start, is the full
        // order's resonance
        let rom = jprom::rom::reduced_model(kind, &coords, Some(&condensed), &out.basis).unwrap();
        let z0 = &out.sweep.points[0].z;
        let estimate = tangent_peak(rom.as_ref(), out.sweep.points[0].omega, z0, band).unwrap().expect("a peak in the band");
        println!("{kind:?}: tangent peak from {:.2} Hz: {:.2} Hz", out.sweep.points[0].omega / TAU, estimate / TAU);
        assert!((estimate - w_fo).abs() < 5e-3 * w_fo, "{kind:?}: tangent peak {:.2} Hz, the full order's resonance {:.2} Hz", estimate / TAU, w_fo / TAU);
        // the result at the full order's resonance
        let at_fo = out.sweep.points.iter().min_by(|a, b| (a.omega - w_fo).abs().total_cmp(&(b.omega - w_fo).abs())).unwrap();
        let p = solve_point(rom.as_ref(), w_fo, Some(&at_fo.z), &hopts).unwrap();
        let x = p.output_amplitude(1, response);
        assert!((x - x_fo).abs() < 0.01 * x_fo, "{kind:?}: |X1| {x:.5e} against the full order's {x_fo:.5e}");
    }
}
