//! HBM on systems without contacts: against dense complex solves of the linear FRF, unit
//! invariance of the scaled Newton, the sweep and its callback, and typed errors.

use jprom_testkit::hbm as common;

use common::*;
use faer::Mat;
use jprom::hbm::{solve_point, sweep, FullSystem, HarmonicSystem, HbmOptions, SweepEnd, SweepOptions};
use jprom::model::Damping;
use jprom::JpError;
use std::ops::ControlFlow;

fn linear_model(n: usize, force_scale: f64, length_scale: f64) -> jprom::model::Model {
    // Units: forces multiplied by force_scale, lengths by length_scale:
    // K, M scale by force_scale / length_scale.
    let (k, m) = chain_matrices(n, 1.0e4, 1.0, 7);
    let s = force_scale / length_scale;
    let k = Mat::from_fn(n, n, |i, j| k[(i, j)] * s);
    let m = Mat::from_fn(n, n, |i, j| m[(i, j)] * s);
    let f0: Vec<f64> = (0..n).map(|i| force_scale * (i as f64 - 2.0)).collect();
    let f1c: Vec<f64> = (0..n).map(|i| force_scale * if i == n - 1 { 1.0 } else { 0.0 }).collect();
    let f1s: Vec<f64> = (0..n).map(|i| force_scale * if i == 0 { 0.5 } else { 0.0 }).collect();
    let f2c: Vec<f64> = (0..n).map(|i| force_scale * 0.1 * i as f64).collect();
    model(
        k,
        m,
        Damping { mass_coeff: 0.5, stiffness_coeff: 1e-4 },
        f0,
        vec![harmonic_force(f1c, f1s), harmonic_force(f2c, vec![0.0; n])],
        vec![],
        (0..n).collect(),
    )
}

#[test]
fn solve_point_matches_dense_linear_frf_per_harmonic() {
    let n = 6;
    let model = linear_model(n, 1.0, 1.0);
    let c = model.damping_matrix();
    for h_max in [1usize, 3] {
        let opts = HbmOptions::default();
        let sys = FullSystem::new(&model, h_max).unwrap();
        for w in [10.0, 55.0, 97.0, 180.0] {
            let p = solve_point(&sys, w, None, &opts).unwrap();
            assert!(p.converged && p.residual_norm <= 1e-10);
            let q0 = static_solve(&model.stiffness, &model.excitation.static_force);
            let got0: Vec<f64> = (0..n).map(|j| p.output_coeff(0, j)).collect();
            assert!(rel_diff(&got0, &q0) < 1e-10, "static part");
            for h in 1..=h_max {
                let (fc, fs) = model.excitation.harmonic(h, n);
                let (xc, xs) = linear_frf(&model.stiffness, &model.mass, &c, h as f64 * w, &fc, &fs);
                let gc: Vec<f64> = (0..n).map(|j| p.output_coeff(2 * h - 1, j)).collect();
                let gs: Vec<f64> = (0..n).map(|j| p.output_coeff(2 * h, j)).collect();
                let expect: Vec<f64> = xc.iter().chain(&xs).copied().collect();
                let got: Vec<f64> = gc.iter().chain(&gs).copied().collect();
                if h <= 2 {
                    assert!(rel_diff(&got, &expect) < 1e-9, "H={h_max} h={h} w={w}: {}", rel_diff(&got, &expect));
                } else {
                    assert!(got.iter().all(|v| v.abs() < 1e-14), "unforced harmonic must vanish");
                }
                let amp = p.output_amplitude(h, n - 1);
                assert!((amp - xc[n - 1].hypot(xs[n - 1])).abs() <= 1e-9 * amp.max(1e-300) + 1e-300);
            }
        }
    }
}

#[test]
fn newton_is_invariant_under_a_change_of_units() {
    let n = 6;
    let opts = HbmOptions::default();
    let base = FullSystem::new(&linear_model(n, 1.0, 1.0), 2).unwrap();
    let scaled = FullSystem::new(&linear_model(n, 1e6, 1e-3), 2).unwrap();
    for w in [20.0, 95.0] {
        let a = solve_point(&base, w, None, &opts).unwrap();
        let b = solve_point(&scaled, w, None, &opts).unwrap();
        assert_eq!(a.iterations, b.iterations);
        let b_back: Vec<f64> = b.z.iter().map(|v| v / 1e-3).collect();
        assert!(rel_diff(&b_back, &a.z) < 1e-9);
        // A poor guess (far away): the same number of trust-region iterations in both units.
        let guess_a: Vec<f64> = a.z.iter().map(|v| 50.0 * v + 1.0).collect();
        let guess_b: Vec<f64> = guess_a.iter().map(|v| v * 1e-3).collect();
        let a2 = solve_point(&base, w, Some(&guess_a), &opts).unwrap();
        let b2 = solve_point(&scaled, w, Some(&guess_b), &opts).unwrap();
        assert_eq!(a2.iterations, b2.iterations);
    }
}

#[test]
fn sweep_follows_the_linear_frf_and_the_callback_can_stop_it() {
    let n = 4;
    let model = linear_model(n, 1.0, 1.0);
    let c = model.damping_matrix();
    let opts = HbmOptions::default();
    let sys = FullSystem::new(&model, 1).unwrap();
    let sopts = SweepOptions::band(20.0, 200.0);
    let mut seen = 0usize;
    let res = sweep(&sys, &sopts, &opts, &mut |_| {
        seen += 1;
        ControlFlow::Continue(())
    })
    .unwrap();
    assert_eq!(res.end, SweepEnd::ReachedEnd);
    assert!(!res.stopped_early);
    assert_eq!(seen, res.points.len());
    assert!(res.points.len() > 10);
    assert!((res.points.last().unwrap().omega - 200.0).abs() < 1e-12);
    let mut prev = 0.0;
    for p in &res.points {
        assert!(p.omega > prev, "no fold in a linear FRF");
        prev = p.omega;
        let (fc, fs) = model.excitation.harmonic(1, n);
        let (xc, xs) = linear_frf(&model.stiffness, &model.mass, &c, p.omega, &fc, &fs);
        let got: Vec<f64> = (0..n).map(|j| p.output_coeff(1, j)).chain((0..n).map(|j| p.output_coeff(2, j))).collect();
        let expect: Vec<f64> = xc.iter().chain(&xs).copied().collect();
        assert!(rel_diff(&got, &expect) < 1e-8, "omega {}: {}", p.omega, rel_diff(&got, &expect));
    }
    let mut count = 0;
    let res = sweep(&sys, &sopts, &opts, &mut |_| {
        count += 1;
        if count == 3 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
    .unwrap();
    assert_eq!(res.points.len(), 3);
    assert_eq!(res.end, SweepEnd::StoppedByCaller);
    assert!(res.stopped_early);
}

#[test]
fn bad_inputs_give_typed_errors() {
    let n = 4;
    let model = linear_model(n, 1.0, 1.0);
    let opts = HbmOptions::default();
    let sys = FullSystem::new(&model, 1).unwrap();
    assert!(matches!(solve_point(&sys, f64::NAN, None, &opts), Err(JpError::InvalidValue { .. })));
    assert!(matches!(solve_point(&sys, -1.0, None, &opts), Err(JpError::InvalidValue { .. })));
    assert!(matches!(solve_point(&sys, 10.0, Some(&[0.0; 3]), &opts), Err(JpError::BadSize { .. })));
    let mut g = vec![0.0; sys.layout().total()];
    g[1] = f64::NAN;
    assert!(matches!(solve_point(&sys, 10.0, Some(&g), &opts), Err(JpError::InvalidValue { .. })));
    assert!(matches!(FullSystem::new(&model, jprom::hbm::Discretisation::with_nt(1, 12)), Err(JpError::InvalidValue { .. })));
    assert!(matches!(FullSystem::new(&model, 0), Err(JpError::InvalidValue { .. })));
    // Singular K (free-free chain) without contacts.
    let kf = Mat::from_fn(n, n, |i, j| {
        if i == j {
            if i == 0 || i == n - 1 { 1.0 } else { 2.0 }
        } else if i.abs_diff(j) == 1 {
            -1.0
        } else {
            0.0
        }
    });
    let mut free = model.clone();
    free.stiffness = kf;
    assert!(matches!(FullSystem::new(&free, 1), Err(JpError::SingularMatrix { .. })));
    // Condensation needs a contact.
    assert!(matches!(jprom::condensation::CondensedSystem::new(&model, 1), Err(JpError::InvalidValue { .. })));
    // Sweep options.
    let s = SweepOptions::band(10.0, 10.0);
    assert!(matches!(sweep(&sys, &s, &opts, &mut |_| ControlFlow::Continue(())), Err(JpError::InvalidValue { .. })));
    let s = SweepOptions { min_step: 1.0, ..SweepOptions::band(10.0, 20.0) };
    assert!(matches!(sweep(&sys, &s, &opts, &mut |_| ControlFlow::Continue(())), Err(JpError::InvalidValue { .. })));
}
