//! A sweep through a friction-damped resonance whose branch has many stick-slip kinks, each
//! stepped over at fixed frequency (a gap of the continuation, docs/formulation.md §6.6): the
//! demo's study on the 18-contact blade (refinement 1, CB(50), 1,620-2,200 Hz) at alpha_ST / 20, NLR on the basis
//! predicted at the demo's largest excitation with the slipping samples
//! (`SlippingSamples::AtGrossSlip`). With at most 10 restarts per sweep it stalled at 90.5 % of
//! the band (the eleventh kink); it needs several tens. Checked against the full order.

use jprom::condensation::CondensedSystem;
use jprom::hbm::{sweep, HbmOptions, PointSolution};
use jprom::jp::{predict_basis, PredictionOptions, SlippingSamples};
use jprom::model::ContactCoordinates;
use jprom::rom::NlrRom;
use jprom_cli::progress::Progress;
use jprom_cli::run::build_shared;
use jprom_cli::study::Study;
use std::f64::consts::TAU;
use std::ops::ControlFlow;

#[test]
fn nlr_sweep_steps_over_every_kink_of_a_partial_slip_resonance() {
    // the demo's study on the 18-contact blade (refinement 1), where the kink was found
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/demo_study.toml")).unwrap();
    assert!(text.contains("\nrefinement = 2\n"), "the demo's refinement line");
    let study = Study::from_toml_str(&text.replace("\nrefinement = 2\n", "\nrefinement = 1\n")).unwrap();
    // the demo keeps its reduced model in its output folder: here, not in the source tree
    let study = jprom_cli::run::writing_to(&study, &std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("sweep-restarts"));
    assert!((study.forcing.levels[1] - 0.05).abs() < 1e-12, "the demo's partial-slip level is alpha_ST / 20");
    let shared = build_shared(&study, Progress::for_stderr(true)).unwrap();
    let case = &shared.cases[0];
    let disc = study.discretisation();
    let at_scale = |scale: f64| {
        let mut m = case.model.clone();
        m.excitation.dynamic_scale = scale;
        m
    };
    // the demo's shared basis (predicted at its largest excitation), with the slipping samples
    let largest = case.scales.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let band = (TAU * study.band.hz_start, TAU * study.band.hz_end);
    let popts = PredictionOptions { gamma: study.basis.gamma, n_samples: study.basis.samples, slipping: SlippingSamples::AtGrossSlip, ..PredictionOptions::new(band) };
    let (basis, report) = predict_basis(&ContactCoordinates::new(&at_scale(largest), disc).unwrap(), &popts).unwrap();
    assert!(report.slipping_patterns > 0, "the slipping samples are taken at the largest excitation");

    let model = at_scale(case.scales[1]);
    let condensed = CondensedSystem::new(&model, disc).unwrap();
    let rom = NlrRom::new(&condensed, &basis).unwrap();
    let sopts = study.band.sweep_options();
    let hopts = HbmOptions::default();
    let response = study.response_output();
    let peak = |pts: &[PointSolution]| pts.iter().map(|p| (p.omega / TAU, p.output_amplitude(1, response))).fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });

    let nlr = sweep(&rom, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    let restarts_hz: Vec<f64> = nlr.restarts.iter().map(|w| w / TAU).collect();
    println!("NLR {:?}: {} points, {} rejected steps, {} restarts at {restarts_hz:.2?} Hz", basis.sizes, nlr.points.len(), nlr.rejected_steps, nlr.restarts.len());
    assert!(nlr.reached_end(), "the NLR sweep did not cover the band: {:?}", nlr.failure);
    assert!(restarts_hz.windows(2).all(|w| w[1] > w[0]) && restarts_hz.iter().all(|f| (study.band.hz_start..study.band.hz_end).contains(f)), "restarts move forward in the band");

    let fo = sweep(&condensed, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    assert!(fo.reached_end());
    let ((f_fo, x_fo), (f_nlr, x_nlr)) = (peak(&fo.points), peak(&nlr.points));
    println!("peak |X1|: full order {x_fo:.5e} at {f_fo:.3} Hz, NLR {x_nlr:.5e} at {f_nlr:.3} Hz");
    assert!((x_nlr - x_fo).abs() < 0.01 * x_fo && (f_nlr - f_fo).abs() < 1.0, "NLR peak {x_nlr} at {f_nlr} Hz vs full order {x_fo} at {f_fo} Hz");
}
