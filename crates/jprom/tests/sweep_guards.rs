//! Guards of the continuation: a sweep whose branch folds back past its start by more than
//! `LEFT_BAND_MARGIN` of the band ends with `SweepEnd::LeftBand` instead of wandering off.

use faer::Mat;
use jprom::contact::{Contact, ContactLaw, IDENTITY_FRAME};
use jprom::hbm::{solve_point, sweep, FullSystem, HbmOptions, SweepEnd, SweepOptions, LEFT_BAND_MARGIN};
use jprom::model::{Damping, Excitation, HarmonicForce, Model};
use std::ops::ControlFlow;

/// One mass on unit springs, forced across a gap to a stiff stop (normal z): a hardening
/// resonance whose branch overhangs to the right of the linear resonance at 1 rad/s.
fn gap_oscillator() -> Model {
    let n = 3;
    let eye = Mat::<f64>::identity(n, n);
    let gap = 0.5;
    let kn = 3.0;
    let law = ContactLaw::Friction3D { kt1: 1.0, kt2: 1.0, kn, mu: 0.3, n0: -kn * gap };
    let excitation = Excitation {
        static_force: vec![0.0; n],
        harmonics: vec![HarmonicForce { cos: vec![0.0, 0.0, 0.05], sin: vec![0.0; n] }],
        dynamic_scale: 1.0,
    };
    Model::new(eye.clone(), eye, Damping::from_modal_ratio(0.01, 1.0), excitation, vec![Contact::ground_3d([0, 1, 2], IDENTITY_FRAME, law)], vec![2]).unwrap()
}

#[test]
fn sweep_that_folds_back_past_its_start_ends_with_left_band() {
    let model = gap_oscillator();
    // A fine AFT grid: with the default one the contact's engagement time jumps between
    // samples near the fold, and the corrector stalls there at a residual of ~4e-8.
    let hopts = HbmOptions::default();
    let full = FullSystem::new(&model, jprom::hbm::Discretisation::with_nt(1, 512)).unwrap();
    // Upward sweep: the branch turns back at the overhang's tip omega_peak and forward again
    // at the lower fold omega_fold.
    let up = sweep(&full, &SweepOptions { max_step: 0.02, ..SweepOptions::band(0.6, 3.0) }, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    let om: Vec<f64> = up.points.iter().map(|p| p.omega).collect();
    let turn = (1..om.len()).find(|&i| om[i] < om[i - 1]).expect("the hardening branch overhangs");
    let omega_peak = om[turn - 1];
    let omega_fold = om[turn..].iter().copied().fold(f64::INFINITY, f64::min);
    println!("upward: {} points, overhang [{omega_fold:.4}, {omega_peak:.4}], end {:?}", om.len(), up.end);
    assert!(omega_peak > omega_fold + 0.05);

    // Downward from inside the overhang, on the small-amplitude branch: the branch folds at
    // omega_fold and runs back up to omega_peak, far past the start.
    let d = omega_peak - omega_fold;
    let (start, end) = (omega_fold + 0.25 * d, omega_fold - 2.0 * d);
    let first = solve_point(&full, start, None, &hopts).unwrap();
    println!("start amplitude {:.3}", first.output_amplitude(1, 0));
    let down = sweep(&full, &SweepOptions { max_step: 0.02, ..SweepOptions::band(start, end) }, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    let highest = down.points.iter().map(|p| p.omega).fold(f64::NEG_INFINITY, f64::max);
    println!("downward: {} points, end {:?}, highest omega {highest:.4}", down.points.len(), down.end);
    assert_eq!(down.end, SweepEnd::LeftBand);
    // It stopped as soon as it was past the margin, not at the overhang's tip.
    assert!(highest <= start + LEFT_BAND_MARGIN * (start - end) + 0.05 * d, "ran on to {highest}");
    assert!(highest < omega_peak);
}
