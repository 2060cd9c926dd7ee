//! Guards of the continuation: a branch that folds back past the sweep's start is followed
//! round and back into the band when it returns within a band's width of the start
//! (`LEFT_BAND_EXCURSION`, the oriented continuation); one that runs back further ends with
//! `SweepEnd::LeftBand` instead of wandering off (for the secant continuation, past
//! `LEFT_BAND_MARGIN`).

use faer::Mat;
use jprom::contact::{Contact, ContactLaw, IDENTITY_FRAME};
use jprom::hbm::{solve_point, sweep, ContinuationMethod, EventKind, FullSystem, HbmOptions, SweepEnd, SweepOptions, LEFT_BAND_MARGIN};
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
    // omega_fold and runs back up to omega_peak, past the start by 0.75 of the overhang.
    let d = omega_peak - omega_fold;
    let start = omega_fold + 0.25 * d;
    let first = solve_point(&full, start, None, &hopts).unwrap();
    println!("start amplitude {:.3}", first.output_amplitude(1, 0));
    let opts = |end: f64, method: ContinuationMethod| SweepOptions { max_step: 0.02, method, ..SweepOptions::band(start, end) };
    let run = |o: SweepOptions| sweep(&full, &o, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    let highest = |r: &jprom::hbm::SweepResult| r.points.iter().map(|p| p.omega).fold(f64::NEG_INFINITY, f64::max);
    // A band of 2 d: the excursion of 0.75 d is within a band's width, so the sweep follows the
    // branch round the overhang's tip and back down through both folds to the band's end.
    let round = run(opts(omega_fold - 2.0 * d, ContinuationMethod::Oriented));
    println!("downward over 2 d: {} points, end {:?}, highest omega {:.4}, folds {:?}", round.points.len(), round.end, highest(&round), round.folds);
    assert_eq!(round.end, SweepEnd::ReachedEnd, "{:?}", round.failure);
    assert!((highest(&round) - omega_peak).abs() < 0.02 * d, "went round the tip at {}", highest(&round));
    // two folds of the branch: the overhang's tip (where the contact's engagement moves from
    // sample to sample, the branch turns back and forth within 1e-2 of the band) and its foot
    let folds: Vec<f64> = round.events.iter().filter(|e| e.kind == EventKind::Fold).map(|e| e.omega).collect();
    let near_tip = folds.iter().filter(|f| (*f - omega_peak).abs() < 1e-2 * 2.0 * d).count();
    let near_foot = folds.iter().filter(|f| (*f - omega_fold).abs() < 1e-2 * 2.0 * d).count();
    assert!(near_tip % 2 == 1 && near_foot % 2 == 1 && near_tip + near_foot == folds.len(), "folds {folds:?} (tip {omega_peak}, foot {omega_fold})");
    // A band of d / 2: the branch runs back past its start by more than the band's width.
    let short = run(opts(omega_fold - 0.25 * d, ContinuationMethod::Oriented));
    println!("downward over d / 2: {} points, end {:?}, highest omega {:.4}", short.points.len(), short.end, highest(&short));
    assert_eq!(short.end, SweepEnd::LeftBand);
    assert!(highest(&short) <= start + 0.5 * d + 0.05 * d, "ran on to {}", highest(&short));
    assert!(short.failure.as_deref().is_some_and(|t| t.contains("left the band")), "{:?}", short.failure);
    // The secant continuation ends at its margin of 10 % of the band.
    let end = omega_fold - 2.0 * d;
    let secant = run(opts(end, ContinuationMethod::Secant));
    assert_eq!(secant.end, SweepEnd::LeftBand);
    assert!(highest(&secant) <= start + LEFT_BAND_MARGIN * (start - end) + 0.05 * d, "ran on to {}", highest(&secant));
    assert!(highest(&secant) < omega_peak);
}
