//! HBM with friction contacts (issue 2, acceptance 4 and 5, and the analytical Jacobian):
//! the linear limit against an independent dense FRF, a friction-damped oscillator from stick
//! to gross slip, full vs condensed solves, harmonic truncation, and the assembled Jacobian
//! against finite differences.

use jprom_testkit::hbm as common;

use common::*;
use faer::Mat;
use jprom::aft::AftPlan;
use jprom::condensation::CondensedSystem;
use jprom::contact::{Contact, ContactLaw};
use jprom::hbm::residual::{evaluate, ResidualWorkspace};
use jprom::hbm::{solve_point, sweep, FullSystem, HarmonicSystem, HbmOptions, Storage, SweepOptions};
use jprom::model::{Damping, Model};
use std::ops::ControlFlow;

/// A rotation: unit vectors t1, t2, n as rows.
fn tilted_frame(a: f64, b: f64) -> [[f64; 3]; 3] {
    let (ca, sa, cb, sb) = (a.cos(), a.sin(), b.cos(), b.sin());
    // R = Rz(a) * Rx(b), rows of its transpose give an orthonormal frame
    let r = [[ca, -sa * cb, sa * sb], [sa, ca * cb, -ca * sb], [0.0, sb, cb]];
    [[r[0][0], r[1][0], r[2][0]], [r[0][1], r[1][1], r[2][1]], [r[0][2], r[1][2], r[2][2]]]
}

/// 4 nodes x 3 DoFs, a ground contact on node 0 (tilted) and a pair between nodes 2 and 3.
fn contact_model(mu: f64, n0: f64, dyn_scale: f64) -> (Model, Vec<[[f64; 3]; 3]>) {
    let n = 12;
    let (k, m) = chain_matrices(n, 1.0e4, 1.0e-3, 7);
    let law = ContactLaw::Friction3D { kt1: 3.0e3, kt2: 2.0e3, kn: 5.0e3, mu, n0 };
    let f1 = tilted_frame(0.3, 0.2);
    let f2 = tilted_frame(-0.5, 0.4);
    let contacts = vec![Contact::ground_3d([0, 1, 2], f1, law.clone()), Contact::pair_3d([6, 7, 8], [9, 10, 11], f2, law)];
    let f0: Vec<f64> = (0..n).map(|i| 0.3 * ((i as f64) * 0.7).sin()).collect();
    let fc: Vec<f64> = (0..n).map(|i| dyn_scale * (1.0 + 0.1 * i as f64)).collect();
    let fs: Vec<f64> = (0..n).map(|i| dyn_scale * 0.05 * (i as f64).cos()).collect();
    let model = model(k, m, Damping { mass_coeff: 0.0, stiffness_coeff: 2e-5 }, f0, vec![harmonic_force(fc, fs)], contacts, (0..n).collect());
    (model, vec![f1, f2])
}

/// Adds R^T diag(k) R to the (a, a), (a, b), (b, a), (b, b) blocks.
fn add_spring(kk: &mut Mat<f64>, a: usize, b: Option<usize>, r: &[[f64; 3]; 3], k: [f64; 3]) {
    let mut kl = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            kl[i][j] = (0..3).map(|l| r[l][i] * k[l] * r[l][j]).sum();
        }
    }
    for i in 0..3 {
        for j in 0..3 {
            kk[(a + i, a + j)] += kl[i][j];
            if let Some(b) = b {
                kk[(b + i, b + j)] += kl[i][j];
                kk[(a + i, b + j)] -= kl[i][j];
                kk[(b + i, a + j)] -= kl[i][j];
            }
        }
    }
}

#[test]
fn linear_limit_matches_the_frf_with_contact_springs() {
    // mu huge, preload high: every contact sticks and stays closed over the whole cycle.
    let n0 = 1.0e3;
    let (model, frames) = contact_model(1.0e6, n0, 1.0);
    let mut kk = model.stiffness.clone();
    add_spring(&mut kk, 0, None, &frames[0], [3.0e3, 2.0e3, 5.0e3]);
    add_spring(&mut kk, 6, Some(9), &frames[1], [3.0e3, 2.0e3, 5.0e3]);
    let c = model.damping_matrix();
    // static: the preload pushes node a away from the contact: f_a = -R^T n0 e_n, f_b = +R^T n0 e_n
    let mut f0 = model.excitation.static_force.clone();
    for i in 0..3 {
        f0[i] -= frames[0][2][i] * n0;
        f0[6 + i] -= frames[1][2][i] * n0;
        f0[9 + i] += frames[1][2][i] * n0;
    }
    let x0 = static_solve(&kk, &f0);
    let (fc, fs) = model.excitation.harmonic(1, 12);
    let opts = HbmOptions::default();
    let full = FullSystem::new(&model, 1).unwrap();
    let cond = CondensedSystem::new(&model, 1).unwrap();
    for &w in &[500.0, 2500.0, 4000.0, 7000.0] {
        let (xc, xs) = linear_frf(&kk, &model.mass, &c, w, &fc, &fs);
        for system in [&full as &dyn HarmonicSystem, &cond] {
            let p = solve_point(system, w, None, &opts).unwrap();
            let n = p.n_outputs;
            let got0: Vec<f64> = (0..n).map(|j| p.output_coeff(0, j)).collect();
            let got_c: Vec<f64> = (0..n).map(|j| p.output_coeff(1, j)).collect();
            let got_s: Vec<f64> = (0..n).map(|j| p.output_coeff(2, j)).collect();
            assert!(rel_diff(&got0, &x0) < 1e-8, "static at w={w}: {}", rel_diff(&got0, &x0));
            let mut both = got_c.clone();
            both.extend(&got_s);
            let mut expect = xc.clone();
            expect.extend(&xs);
            let e = rel_diff(&both, &expect);
            assert!(e < 1e-8, "first harmonic at w={w}: {e}");
            assert!(p.contact_cycles.iter().all(|cy| cy.dissipated_energy.abs() < 1e-12));
        }
    }
}

#[test]
fn assembled_jacobian_matches_finite_differences() {
    // moderate mu and preload: a mix of stick, slip and separation at a random state
    let (model, _) = contact_model(0.3, 20.0, 1.0);
    for h in [1usize, 3] {
        let full = FullSystem::new(&model, h).unwrap();
        // the same system stored sparse: its Jacobian is assembled from entries, not scattered
        let sparse = FullSystem::with_storage(&model, h, Storage::Sparse).unwrap();
        assert_eq!(sparse.storage(), Storage::Sparse);
        let cond = CondensedSystem::new(&model, h).unwrap();
        let plan = AftPlan::new(h, jprom::hbm::default_nt(h)).unwrap();
        for system in [&full as &dyn HarmonicSystem, &sparse, &cond] {
            let w = 3000.0;
            let lin = system.linear_part(w).unwrap();
            let n = system.layout().total();
            let z: Vec<f64> = (0..n).map(|i| 0.02 * ((i as f64) * 1.37).sin()).collect();
            let mut ws = ResidualWorkspace::new();
            let (_, jac) = evaluate(system, &lin, Some(&plan), &z, true, &mut ws).unwrap();
            let jac = jac.unwrap().into_dense();
            let mut max_err = 0.0f64;
            let scale = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).map(|(i, j)| jac[(i, j)].abs()).fold(0.0, f64::max);
            for j in 0..n {
                let step = 1e-7;
                let mut zp = z.clone();
                zp[j] += step;
                let mut zm = z.clone();
                zm[j] -= step;
                let (rp, _) = evaluate(system, &lin, Some(&plan), &zp, false, &mut ws).unwrap();
                let (rm, _) = evaluate(system, &lin, Some(&plan), &zm, false, &mut ws).unwrap();
                for i in 0..n {
                    let fd = (rp[i] - rm[i]) / (2.0 * step);
                    max_err = max_err.max((fd - jac[(i, j)]).abs() / scale);
                }
            }
            assert!(max_err < 1e-6, "H={h}: max relative Jacobian error {max_err:.2e}");
        }
    }
}

/// 2-DoF oscillator, Jenkins element from mass 2 to ground.
fn oscillator(force: f64) -> (Model, HbmOptions) {
    let k = Mat::from_fn(2, 2, |i, j| [[2.0e4, -1.0e4], [-1.0e4, 1.0e4]][i][j]);
    let m = Mat::from_fn(2, 2, |i, j| if i == j { 1.0 } else { 0.0 });
    let contacts = vec![Contact::jenkins(1, None, 3.0e4, 0.5, 20.0)];
    let model = model(
        k,
        m,
        Damping { mass_coeff: 0.0, stiffness_coeff: 1e-4 },
        vec![0.0, 0.0],
        vec![harmonic_force(vec![0.0, force], vec![0.0, 0.0])],
        contacts,
        vec![0, 1],
    );
    (model, HbmOptions::default())
}

/// Peak of |X1| at output 1 over a frequency grid, by sweeping with continuation.
fn resonance(force: f64, h: usize) -> (f64, f64) {
    let (model, opts) = oscillator(force);
    let sys = CondensedSystem::new(&model, h).unwrap();
    let res = sweep(&sys, &SweepOptions::band(40.0, 150.0), &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    assert!(!res.stopped_early, "sweep ended early: {:?}", res.end);
    let mut best = (0.0, 0.0);
    for p in &res.points {
        let a = p.output_amplitude(1, 1) / force;
        if a > best.1 {
            best = (p.omega, a);
        }
    }
    best
}

#[test]
fn friction_damped_oscillator_from_stick_to_gross_slip() {
    // slip force mu N = 10; forces from well below to well above it
    let forces = [0.05, 1.0, 3.0, 10.0, 1.0e4];
    let peaks: Vec<(f64, f64)> = forces.iter().map(|&f| resonance(f, 1)).collect();
    println!("(resonance omega, peak |X1| / force) for forces {forces:?}: {peaks:?}");
    for w in peaks.windows(2) {
        assert!(w[1].0 < w[0].0 + 1e-6, "resonance must move down as friction slips: {peaks:?}");
    }
    // from stick into slip the friction damping takes the peak down
    for w in peaks[..3].windows(2) {
        assert!(w[1].1 < w[0].1, "amplitude per unit force must fall once slip starts: {peaks:?}");
    }
    // stuck limit: natural frequency of K + kt on DoF 1; gross-slip limit: of K alone
    let eig = |kk: [[f64; 2]; 2]| {
        let (a, b, d) = (kk[0][0], kk[0][1], kk[1][1]);
        let tr = a + d;
        let det = a * d - b * b;
        ((tr - (tr * tr - 4.0 * det).sqrt()) / 2.0).sqrt()
    };
    let w_stuck = eig([[2.0e4, -1.0e4], [-1.0e4, 4.0e4]]);
    let w_free = eig([[2.0e4, -1.0e4], [-1.0e4, 1.0e4]]);
    assert!((peaks[0].0 - w_stuck).abs() / w_stuck < 0.01, "stuck peak {} vs {w_stuck}", peaks[0].0);
    assert!((peaks[4].0 - w_free).abs() / w_free < 0.03, "gross-slip peak {} vs {w_free}", peaks[4].0);
    // the friction damping in between takes the amplitude far below both linear limits
    assert!(peaks[2].1 < 0.5 * peaks[0].1 && peaks[2].1 < 0.5 * peaks[4].1);
}

#[test]
fn full_and_condensed_solves_agree() {
    let h = 3;
    let (model, opts) = oscillator(20.0);
    let full = FullSystem::new(&model, h).unwrap();
    let cond = CondensedSystem::new(&model, h).unwrap();
    for &w in &[90.0, 120.0, 150.0] {
        let a = solve_point(&full, w, None, &opts).unwrap();
        let b = solve_point(&cond, w, None, &opts).unwrap();
        let e = rel_diff(&a.outputs, &b.outputs);
        assert!(e < 1e-8, "w={w}: {e:.2e}");
        let (ea, eb) = (a.dissipated_energy(), b.dissipated_energy());
        assert!((ea - eb).abs() <= 1e-8 * ea.abs().max(1e-12), "{ea} vs {eb}");
    }
    let (model3, _) = contact_model(0.3, 20.0, 1.0);
    let opts3 = HbmOptions::default();
    let a = solve_point(&FullSystem::new(&model3, 3).unwrap(), 3000.0, None, &opts3).unwrap();
    let b = solve_point(&CondensedSystem::new(&model3, 3).unwrap(), 3000.0, None, &opts3).unwrap();
    assert!(rel_diff(&a.outputs, &b.outputs) < 1e-8);
}

#[test]
fn harmonic_truncation_converges() {
    let w = 110.0;
    let amp = |h: usize| {
        let (model, opts) = oscillator(20.0);
        let sys = CondensedSystem::new(&model, h).unwrap();
        solve_point(&sys, w, None, &opts).unwrap().output_amplitude(1, 1)
    };
    let a: Vec<f64> = [1usize, 3, 5, 7].iter().map(|&h| amp(h)).collect();
    let d: Vec<f64> = a.windows(2).map(|p| (p[1] - p[0]).abs()).collect();
    println!("X1 for H = 1,3,5,7: {a:?}, successive differences {d:?}");
    assert!(d[0] > d[1] && d[1] > d[2], "{d:?}");
    assert!(d[2] / a[3] < 1e-2);
}


#[test]
fn continuation_passes_the_fold_of_a_hardening_gap_contact() {
    // one node on springs, closing a gap of 0.01 against a stiffer unilateral spring along z:
    // the resonance bends to the right and folds.
    let k = Mat::from_fn(3, 3, |i, j| if i == j { 1.0e4 } else { 0.0 });
    let m = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 } else { 0.0 });
    let kn = 3.0e4;
    let law = ContactLaw::Friction3D { kt1: 1.0e3, kt2: 1.0e3, kn, mu: 1.0e3, n0: -kn * 0.01 };
    let contacts = vec![Contact::ground_3d([0, 1, 2], jprom::contact::IDENTITY_FRAME, law)];
    let model = model(
        k,
        m,
        Damping { mass_coeff: 0.0, stiffness_coeff: 4e-5 },
        vec![0.0; 3],
        vec![harmonic_force(vec![0.0, 0.0, 0.7], vec![0.0; 3])],
        contacts,
        vec![2],
    );
    // the clipped normal force makes the residual nonsmooth where a sample opens or closes:
    // Newton can stall near 1e-7 there (a sample switching back and forth), above the default 1e-10.
    let opts = HbmOptions { residual_tolerance: 1e-8, ..HbmOptions::default() };
    let sys = CondensedSystem::new(&model, jprom::hbm::Discretisation::with_nt(3, 256)).unwrap();
    let res = sweep(&sys, &SweepOptions::band(70.0, 250.0), &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    let omegas: Vec<f64> = res.points.iter().map(|p| p.omega).collect();
    // The branch must go round the first fold: omega rises, then falls back while the
    // amplitude keeps growing along the branch. (Known limit, see the closing note of issue 2:
    // on the unstable branch of this case the corrector can stall on a grazing kink, and the
    // sweep then ends with StepTooSmall and its error instead of a fake point.)
    let first_turn = omegas.windows(2).position(|w| w[1] < w[0]).expect("the sweep never turned back");
    assert!(omegas[first_turn] > 105.0, "turned too early: {omegas:?}");
    let amp: Vec<f64> = res.points.iter().map(|p| p.output_amplitude(1, 0)).collect();
    assert!(amp[first_turn + 1] > 0.0 && res.points.len() > first_turn + 1);
    if res.stopped_early {
        assert!(res.failure.is_some(), "a sweep that ends early must say why");
    }
    assert!(res.points.iter().all(|p| p.residual_norm <= opts.residual_tolerance));
    // past the fold the contact closes for part of the cycle
    let peak = res.points.iter().max_by(|a, b| a.output_amplitude(1, 0).total_cmp(&b.output_amplitude(1, 0))).unwrap();
    let states = &peak.contact_cycles[0].states;
    assert!(states.iter().any(|s| *s == jprom::contact::ContactState::Separated));
    assert!(states.iter().any(|s| *s != jprom::contact::ContactState::Separated));
    assert!(peak.omega > 105.0, "the peak must have moved right of the linear 100 rad/s: {}", peak.omega);
}
