//! One JP basis for several excitation levels (`rom::adaptive_sweep_from`): predicted from the
//! stuck mode at the largest excitation, its amplitude samples span those of a smaller one, and
//! the self-correcting sweep at the smaller level starts from it and follows the full order.
//! `adaptive_sweep` is the same sweep from the basis predicted at its own level.

use jprom_testkit::chain::examples_model;
use jprom::condensation::CondensedSystem;
use jprom::hbm::{sweep, HbmOptions, SweepEnd, SweepOptions};
use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::ContactCoordinates;
use jprom::rom::{adaptive_sweep, adaptive_sweep_from, AdaptiveOptions, RomKind};
use jprom::JpError;
use std::ops::ControlFlow;

const BAND: (f64, f64) = (60.0, 160.0);

fn peak(points: &[jprom::hbm::PointSolution]) -> f64 {
    points.iter().map(|p| p.output_amplitude(1, 0)).fold(0.0, f64::max)
}

#[test]
fn a_basis_predicted_at_the_largest_excitation_serves_a_smaller_one() {
    let opts = HbmOptions::default();
    let pred = PredictionOptions::new(BAND);
    let large = examples_model();
    let mut small = examples_model();
    small.excitation.dynamic_scale = 0.2;
    let (shared, shared_report) = predict_basis(&ContactCoordinates::new(&large, 1).unwrap(), &pred).unwrap();
    let coords = ContactCoordinates::new(&small, 1).unwrap();
    let (_, own_report) = predict_basis(&coords, &pred).unwrap();
    // the same onset of slip, five times the largest amplitude: the small level's range inside
    assert!((shared_report.p_min - own_report.p_min).abs() <= 1e-6 * own_report.p_min, "{} vs {}", shared_report.p_min, own_report.p_min);
    assert!((shared_report.p_max / own_report.p_max - 5.0).abs() < 1e-9, "{} vs {}", shared_report.p_max, own_report.p_max);
    let condensed = CondensedSystem::new(&small, 1).unwrap();
    let sopts = SweepOptions::band(BAND.0, BAND.1);
    let fo = sweep(&condensed, &sopts, &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    for kind in [RomKind::Fr, RomKind::Nlr] {
        let aopts = AdaptiveOptions { kind, ..Default::default() };
        let a = adaptive_sweep_from(&coords, Some(&condensed), (shared.clone(), shared_report.clone()), &pred, &sopts, &opts, &aopts, &mut |_, _| ControlFlow::Continue(())).unwrap();
        assert_eq!(a.sweep.end, SweepEnd::ReachedEnd);
        assert!(a.worst_error <= aopts.threshold, "{kind:?}: {}", a.worst_error);
        let (x_fo, x_rom) = (peak(&fo.points), peak(&a.sweep.points));
        assert!((x_rom - x_fo).abs() < 0.01 * x_fo, "{kind:?}: peak {x_rom} vs full order {x_fo}");
    }
    // NLR is the condensed system's projection: it needs it
    let nlr = AdaptiveOptions { kind: RomKind::Nlr, ..Default::default() };
    let e = adaptive_sweep_from(&coords, None, (shared, shared_report), &pred, &sopts, &opts, &nlr, &mut |_, _| ControlFlow::Continue(())).unwrap_err();
    assert!(matches!(e, JpError::InvalidValue { .. }), "{e}");
}

#[test]
fn adaptive_sweep_is_the_sweep_from_its_own_levels_basis() {
    let opts = HbmOptions::default();
    let mut model = examples_model();
    model.excitation.dynamic_scale = 0.5;
    let mut pred = PredictionOptions::new(BAND);
    pred.n_samples = 30;
    let sopts = SweepOptions::band(BAND.0, BAND.1);
    let aopts = AdaptiveOptions { kind: RomKind::Nlr, ..Default::default() };
    let a = adaptive_sweep(&model, 1, &pred, &sopts, &opts, &aopts).unwrap();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let condensed = CondensedSystem::new(&model, 1).unwrap();
    let initial = predict_basis(&coords, &pred).unwrap();
    let b = adaptive_sweep_from(&coords, Some(&condensed), initial, &pred, &sopts, &opts, &aopts, &mut |_, _| ControlFlow::Continue(())).unwrap();
    assert_eq!(a.sweep.points.len(), b.sweep.points.len());
    assert!(a.sweep.points.iter().zip(&b.sweep.points).all(|(p, q)| p.omega == q.omega && p.z == q.z));
    assert_eq!(a.corrections, b.corrections);
}
