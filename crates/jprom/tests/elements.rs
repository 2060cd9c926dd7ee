//! The elements of issue 18: polynomial (cubic) spring, unilateral spring, 2D friction element,
//! several laws on one coordinate (Parallel) and chains of elements ("q1 to ground, q2 - q1").
//! Each: analytical AFT Jacobian against central finite differences, its linear limit against
//! the same spring added to K, closed forms where they exist (undamped Duffing at H = 1), and
//! the chain against the same system written by hand in relative coordinates.

use jprom_testkit::hbm::{harmonic_force, rel_diff};

use faer::Mat;
use jprom::aft::{AftBackend, AftPlan, ContactCycle};
use jprom::contact::{Contact, ContactLaw, ContactState};
use jprom::hbm::{solve_point, sweep, FullSystem, HbmOptions, PointSolution, SweepOptions};
use jprom::model::{ContactCoordinates, Damping, Excitation, Model};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::ops::ControlFlow;

fn force(plan: &AftPlan, law: &ContactLaw, w: &[f64]) -> Vec<f64> {
    let mut ws = plan.workspace();
    let mut f = vec![0.0; w.len()];
    plan.contact(law, w, &mut f, None, None, &mut ws);
    f
}

fn fd_jacobian(plan: &AftPlan, law: &ContactLaw, w: &[f64], h: f64) -> Vec<f64> {
    let n = w.len();
    let mut jac = vec![0.0; n * n];
    let mut wp = w.to_vec();
    for col in 0..n {
        wp[col] = w[col] + h;
        let fp = force(plan, law, &wp);
        wp[col] = w[col] - h;
        let fm = force(plan, law, &wp);
        wp[col] = w[col];
        for row in 0..n {
            jac[row + col * n] = (fp[row] - fm[row]) / (2.0 * h);
        }
    }
    jac
}

/// Random states (static offset `offset[i]` per coordinate, amplitudes `amp[i]` decaying with
/// the harmonic); returns (accepted draws, worst relative error, states seen).
fn check_random(law: &ContactLaw, h: usize, nt: usize, backend: AftBackend, draws: usize, seed: u64, offset: &[(f64, f64)], amp: &[f64]) -> (usize, f64, [bool; 3]) {
    let plan = AftPlan::with_backend(h, nt, backend).unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let mut ws = plan.workspace();
    let d = law.dim();
    let nc = plan.n_coeffs();
    let n = d * nc;
    let (mut accepted, mut worst, mut seen) = (0, 0.0f64, [false; 3]);
    for _ in 0..draws {
        let mut w = vec![0.0; n];
        for i in 0..d {
            w[i] = rng.gen_range(offset[i].0..offset[i].1);
            let a = rng.gen_range(0.05..1.0) * amp[i];
            for k in 1..nc {
                w[k * d + i] = a * rng.gen_range(-1.0..1.0) / ((k + 1) / 2) as f64;
            }
        }
        let mut f = vec![0.0; n];
        let mut jac = vec![0.0; n * n];
        let mut cycle = ContactCycle::default();
        plan.contact(law, &w, &mut f, Some(&mut jac), Some(&mut cycle), &mut ws);
        let scale = w.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let j1 = fd_jacobian(&plan, law, &w, 1e-7 * scale);
        let j2 = fd_jacobian(&plan, law, &w, 2e-7 * scale);
        // A sample at a kink (stick/slip, open/closed) makes the FD itself unreliable.
        if rel_diff(&j1, &j2) > 1e-7 {
            continue;
        }
        accepted += 1;
        worst = worst.max(rel_diff(&jac, &j1));
        for s in &cycle.states {
            seen[*s as usize] = true;
        }
    }
    (accepted, worst, seen)
}

fn cubic(k1: f64, k3: f64) -> ContactLaw {
    ContactLaw::Polynomial { coefficients: vec![k1, 0.0, k3] }
}

#[test]
fn polynomial_jacobian_matches_finite_differences() {
    // Hardening and softening terms, even and odd powers.
    let law = ContactLaw::Polynomial { coefficients: vec![1.5, -0.7, 2.0, 0.0, -0.3] };
    for (h, nt) in [(1, 32), (3, 64), (5, 128)] {
        for backend in [AftBackend::Tables, AftBackend::Fft] {
            let (acc, worst, seen) = check_random(&law, h, nt, backend, 15, 3 + h as u64, &[(-0.5, 0.5)], &[2.0]);
            println!("polynomial H={h} {backend:?}: accepted {acc}/15, worst rel. error {worst:.2e}");
            assert!(acc >= 14, "a memoryless smooth law must always give a smooth FD: {acc}");
            assert!(seen[0] && !seen[1] && !seen[2], "always Stick: {seen:?}");
            assert!(worst < 1e-7, "H={h}: {worst:.3e}");
        }
    }
}

#[test]
fn unilateral_jacobian_matches_finite_differences() {
    for n0 in [-0.3, 0.0, 0.8] {
        let law = ContactLaw::Unilateral { kn: 2.5, n0 };
        for (h, nt) in [(1, 64), (3, 64), (5, 128)] {
            for backend in [AftBackend::Tables, AftBackend::Fft] {
                let (acc, worst, seen) = check_random(&law, h, nt, backend, 20, 17 + h as u64, &[(-0.2, 0.4)], &[1.5]);
                println!("unilateral n0={n0} H={h} {backend:?}: accepted {acc}/20, worst {worst:.2e}, seen {seen:?}");
                assert!(acc >= 12, "{acc}");
                assert!(seen[0] && seen[2] && !seen[1], "closed and open samples: {seen:?}");
                assert!(worst < 1e-6, "{worst:.3e}");
            }
        }
    }
}

#[test]
fn friction_2d_jacobian_matches_finite_differences() {
    let law = ContactLaw::Friction2D { kt: 1.2, kn: 1.5, mu: 0.4, n0: 1.0 };
    for (h, nt) in [(1, 64), (3, 64), (5, 128)] {
        for backend in [AftBackend::Tables, AftBackend::Fft] {
            let (acc, worst, seen) = check_random(&law, h, nt, backend, 40, 31 + h as u64, &[(-0.5, 0.5), (-0.3, 0.5)], &[2.0, 1.2]);
            println!("2D H={h} {backend:?}: accepted {acc}/40, worst {worst:.2e}, seen {seen:?}");
            assert!(acc >= 20, "{acc}");
            assert!(seen.iter().all(|&s| s), "stick, slip and separation: {seen:?}");
            assert!(worst < 1e-6, "{worst:.3e}");
        }
    }
}

#[test]
fn parallel_jacobian_and_force_are_the_members_sums() {
    let members = vec![ContactLaw::Jenkins { kt: 1.3, mu: 0.5, normal_load: 1.0 }, cubic(0.5, 0.8), ContactLaw::Unilateral { kn: 2.0, n0: -0.1 }];
    let law = ContactLaw::Parallel(members.clone());
    law.validate("law").unwrap();
    let (acc, worst, seen) = check_random(&law, 3, 64, AftBackend::Auto, 30, 5, &[(-0.5, 0.5)], &[2.0]);
    println!("parallel H=3: accepted {acc}/30, worst {worst:.2e}, seen {seen:?}");
    assert!(acc >= 15 && worst < 1e-6, "{acc} {worst:.3e}");
    assert!(seen[0] && seen[1], "{seen:?}");
    // The sum, member by member.
    let plan = AftPlan::new(3, 64).unwrap();
    let w: Vec<f64> = (0..7).map(|k| 0.3 + 0.5 * (k as f64).sin()).collect();
    let total = force(&plan, &law, &w);
    let mut sum = vec![0.0; 7];
    for m in &members {
        for (s, v) in sum.iter_mut().zip(force(&plan, m, &w)) {
            *s += v;
        }
    }
    assert!(rel_diff(&total, &sum) < 1e-14, "{:.2e}", rel_diff(&total, &sum));
    // Nested, empty and mixed-dimension Parallel laws are refused.
    for bad in [ContactLaw::Parallel(vec![]), ContactLaw::Parallel(vec![law.clone()]), ContactLaw::Parallel(vec![cubic(1.0, 0.0), ContactLaw::Friction2D { kt: 1.0, kn: 1.0, mu: 0.1, n0: 0.0 }])] {
        let e = bad.validate("law").unwrap_err().to_string();
        assert!(e.contains("Parallel"), "{e}");
    }
}

#[test]
fn bad_parameters_are_refused_with_their_name() {
    let cases = [
        (ContactLaw::Polynomial { coefficients: vec![] }, "coefficients"),
        (ContactLaw::Polynomial { coefficients: vec![1.0, f64::NAN] }, "coefficients[1]"),
        (ContactLaw::Unilateral { kn: -1.0, n0: 0.0 }, "kn"),
        (ContactLaw::Unilateral { kn: 1.0, n0: f64::INFINITY }, "n0"),
        (ContactLaw::Friction2D { kt: 1.0, kn: 1.0, mu: -0.1, n0: 0.0 }, "mu"),
        (ContactLaw::Friction2D { kt: f64::NAN, kn: 1.0, mu: 0.1, n0: 0.0 }, "kt"),
    ];
    for (law, name) in cases {
        let e = law.validate("contact[0]").unwrap_err().to_string();
        assert!(e.contains(&format!("contact[0].{name}")), "{e}");
    }
    // A softening polynomial is a legal law.
    cubic(1.0, -0.2).validate("c").unwrap();
}

// ---------------------------------------------------------------------------------------
// Models

fn model(k: Mat<f64>, m: Mat<f64>, c: Option<Mat<f64>>, f0: Vec<f64>, f1: Vec<f64>, contacts: Vec<Contact>) -> Model {
    let n = k.nrows();
    let exc = Excitation { static_force: f0, harmonics: vec![harmonic_force(f1, vec![0.0; n])], dynamic_scale: 1.0 };
    let mut model = Model::new(m, k, Damping::default(), exc, contacts, (0..n).collect()).expect("valid model");
    model.added_damping = c;
    model.validate().unwrap();
    model
}

fn solve(model: &Model, h: usize, omega: f64) -> PointSolution {
    let opts = HbmOptions::default();
    let sys = FullSystem::new(model, h).unwrap();
    solve_point(&sys, omega, None, &opts).unwrap()
}

fn diag(v: &[f64]) -> Mat<f64> {
    Mat::from_fn(v.len(), v.len(), |i, j| if i == j { v[i] } else { 0.0 })
}

/// Stiffness matrix of a chain of springs: `k[0]` to ground at DoF 0, `k[i]` between i-1, i.
fn chain_k(k: &[f64]) -> Mat<f64> {
    let n = k.len();
    let mut kk = Mat::zeros(n, n);
    for i in 0..n {
        kk[(i, i)] += k[i];
        if i > 0 {
            kk[(i - 1, i - 1)] += k[i];
            kk[(i - 1, i)] -= k[i];
            kk[(i, i - 1)] -= k[i];
        }
    }
    kk
}

#[test]
fn cubic_with_k3_zero_equals_a_linear_spring_in_k() {
    // 2 DoFs: k_c between them as Polynomial [k_c] vs added to K.
    let (m, c) = (diag(&[1.0, 0.5]), Some(diag(&[0.02, 0.01])));
    let kc = 0.8;
    let base = chain_k(&[1.0, 0.0]);
    let with_spring = chain_k(&[1.0, kc]);
    let (f0, f1) = (vec![0.1, -0.05], vec![0.3, 0.1]);
    let nl = model(base.clone(), m.clone(), c.clone(), f0.clone(), f1.clone(), vec![Contact::polynomial(1, Some(0), vec![kc, 0.0, 0.0])]);
    let lin = model(with_spring, m, c, f0, f1, vec![]);
    for omega in [0.5, 0.9, 1.6] {
        let (a, b) = (solve(&nl, 3, omega), solve(&lin, 3, omega));
        let d = rel_diff(&a.outputs, &b.outputs);
        println!("k3 = 0 at w = {omega}: rel. diff {d:.2e}");
        assert!(d < 1e-10, "{d:.3e}");
    }
}

#[test]
fn undamped_duffing_at_h1_satisfies_the_amplitude_equation() {
    // m a'' + k1 a + k3 a^3 = f cos(w t) at H = 1: k1 a + 3/4 k3 a^3 - m w^2 a = f.
    let (m, k1, k3, f) = (1.0, 1.0, 0.5, 0.1);
    for (omega, k3) in [(0.5, k3), (1.5, k3), (0.7, -0.3)] {
        let model = model(Mat::zeros(1, 1), diag(&[m]), None, vec![0.0], vec![f], vec![Contact::polynomial(0, None, vec![k1, 0.0, k3])]);
        let s = solve(&model, 1, omega);
        let (a, b) = (s.output_coeff(1, 0), s.output_coeff(2, 0));
        let r = k1 * a + 0.75 * k3 * a.powi(3) - m * omega * omega * a - f;
        println!("Duffing H=1 w={omega} k3={k3}: a = {a:.12}, residual of the amplitude equation {r:.2e}, sin part {b:.1e}");
        assert!(r.abs() < 1e-10 * f, "{r:.3e}");
        assert!(b.abs() < 1e-12 && s.output_coeff(0, 0).abs() < 1e-12);
        // And not the linear answer: the cubic term acts.
        let a_lin = f / (k1 - m * omega * omega);
        assert!((a - a_lin).abs() > 1e-4 * a_lin.abs(), "{a} vs linear {a_lin}");
    }
}

#[test]
fn unilateral_with_large_preload_equals_a_linear_spring() {
    let (kn, n0) = (0.7, 50.0);
    let (m, c) = (diag(&[1.0, 0.5]), Some(diag(&[0.02, 0.01])));
    let (f0, f1) = (vec![0.1, -0.05], vec![0.3, 0.1]);
    // Unilateral between DoFs 1 (a) and 0 (b): force -N on DoF 1, +N on DoF 0. DoF 1 also
    // hangs on a linear spring (a unilateral spring alone cannot hold a static pull).
    let nl = model(chain_k(&[1.0, 0.3]), m.clone(), c.clone(), f0.clone(), f1.clone(), vec![Contact::unilateral(1, Some(0), kn, n0)]);
    let f0_lin = vec![f0[0] + n0, f0[1] - n0];
    let lin = model(chain_k(&[1.0, 0.3 + kn]), m, c, f0_lin, f1, vec![]);
    for omega in [0.5, 1.1] {
        let (a, b) = (solve(&nl, 3, omega), solve(&lin, 3, omega));
        assert!(a.contact_cycles[0].states.iter().all(|&s| s == ContactState::Stick), "stays closed");
        let d = rel_diff(&a.outputs, &b.outputs);
        println!("unilateral, large preload, w = {omega}: rel. diff {d:.2e}");
        assert!(d < 1e-10, "{d:.3e}");
    }
    // A gap larger than the motion: no force at all, the free system.
    let open = model(chain_k(&[1.0, 0.3]), diag(&[1.0, 0.5]), Some(diag(&[0.02, 0.01])), vec![0.0; 2], vec![0.3, 0.1], vec![Contact::unilateral(1, Some(0), kn, -50.0)]);
    let free = model(chain_k(&[1.0, 0.3]), diag(&[1.0, 0.5]), Some(diag(&[0.02, 0.01])), vec![0.0; 2], vec![0.3, 0.1], vec![]);
    let (a, b) = (solve(&open, 3, 0.8), solve(&free, 3, 0.8));
    assert!(a.contact_cycles[0].states.iter().all(|&s| s == ContactState::Separated));
    assert!(rel_diff(&a.outputs, &b.outputs) < 1e-10);
}

#[test]
fn friction_2d_with_huge_mu_equals_stuck_springs() {
    // 2 DoFs (x, y of one node) to ground through a rotated 2D element.
    let th: f64 = 0.4;
    let r = [[th.cos(), th.sin()], [-th.sin(), th.cos()]];
    let (kt, kn, n0) = (2.0, 3.0, 100.0);
    let k = diag(&[1.0, 1.5]);
    let (m, c) = (diag(&[1.0, 0.8]), Some(diag(&[0.03, 0.02])));
    let (f0, f1) = (vec![0.2, 0.1], vec![0.4, -0.3]);
    let law = ContactLaw::Friction2D { kt, kn, mu: 1e6, n0 };
    let nl = model(k.clone(), m.clone(), c.clone(), f0.clone(), f1.clone(), vec![Contact::friction_2d([0, 1], None, r, law)]);
    // K + R^T diag(kt, kn) R, and the preload -R^T (0, n0) on the node.
    let mut kl = k.clone();
    let kd = [kt, kn];
    for i in 0..2 {
        for j in 0..2 {
            kl[(i, j)] += (0..2).map(|l| r[l][i] * kd[l] * r[l][j]).sum::<f64>();
        }
    }
    let f0_lin = vec![f0[0] - r[1][0] * n0, f0[1] - r[1][1] * n0];
    let lin = model(kl, m, c, f0_lin, f1, vec![]);
    for omega in [0.6, 1.3, 2.2] {
        let (a, b) = (solve(&nl, 3, omega), solve(&lin, 3, omega));
        assert!(a.contact_cycles[0].states.iter().all(|&s| s == ContactState::Stick));
        let d = rel_diff(&a.outputs, &b.outputs);
        println!("2D, mu huge, w = {omega}: rel. diff {d:.2e}");
        assert!(d < 1e-10, "{d:.3e}");
    }
}

#[test]
fn friction_2d_equals_the_3d_element_with_a_free_direction() {
    // The 3D element with kt2 = 0 on (x, z) and a dummy y DoF: the workaround issue 18 names.
    let law2 = ContactLaw::Friction2D { kt: 2.0, kn: 3.0, mu: 0.3, n0: 0.5 };
    let law3 = ContactLaw::Friction3D { kt1: 2.0, kt2: 0.0, kn: 3.0, mu: 0.3, n0: 0.5 };
    let (f0, f1) = (vec![0.2, 0.1], vec![0.8, -0.5]);
    let nl2 = model(diag(&[1.0, 1.5]), diag(&[1.0, 0.8]), Some(diag(&[0.03, 0.02])), f0.clone(), f1.clone(), vec![Contact::friction_2d([0, 1], None, [[1.0, 0.0], [0.0, 1.0]], law2)]);
    let nl3 = model(diag(&[1.0, 1.0, 1.5]), diag(&[1.0, 1.0, 0.8]), Some(diag(&[0.03, 0.03, 0.02])), vec![f0[0], 0.0, f0[1]], vec![f1[0], 0.0, f1[1]], vec![Contact::ground_3d([0, 1, 2], jprom::contact::IDENTITY_FRAME, law3)]);
    for omega in [0.8, 1.2] {
        let (a, b) = (solve(&nl2, 5, omega), solve(&nl3, 5, omega));
        assert!(a.contact_cycles[0].states.contains(&ContactState::Slip), "the case slips");
        let b2: Vec<f64> = b.outputs.chunks(3).flat_map(|c| [c[0], c[2]]).collect();
        let d = rel_diff(&a.outputs, &b2);
        println!("2D vs 3D with a free direction, w = {omega}: rel. diff {d:.2e}");
        assert!(d < 1e-9, "{d:.3e}");
    }
}

#[test]
fn several_laws_on_one_coordinate_act_in_parallel() {
    // Jenkins + Polynomial [k1] on DoF 0 to ground == Jenkins with k1 added to K.
    let (m, c) = (diag(&[1.0, 0.5]), Some(diag(&[0.02, 0.01])));
    let (f0, f1) = (vec![0.0, 0.0], vec![0.6, 0.2]);
    let jen = Contact::jenkins(0, None, 1.5, 0.3, 1.0);
    let nl = model(chain_k(&[0.0, 1.0]), m.clone(), c.clone(), f0.clone(), f1.clone(), vec![jen.clone(), Contact::polynomial(0, None, vec![0.7])]);
    let reference = model(chain_k(&[0.7, 1.0]), m, c, f0, f1, vec![jen]);
    let coords = ContactCoordinates::new(&nl, 3).unwrap();
    assert_eq!((coords.n_w, coords.groups.clone()), (1, vec![vec![0, 1]]), "one shared coordinate");
    for omega in [0.6, 1.0, 1.4] {
        let (a, b) = (solve(&nl, 5, omega), solve(&reference, 5, omega));
        assert!(a.contact_cycles[0].states.contains(&ContactState::Slip), "the Jenkins slips");
        let d = rel_diff(&a.outputs, &b.outputs);
        println!("Jenkins + linear polynomial on one DoF, w = {omega}: rel. diff {d:.2e}");
        assert!(d < 1e-9, "{d:.3e}");
    }
}

/// `q = P y` for the chain `y_0 = q_0`, `y_i = q_i - q_{i-1}`: `P` lower triangular of ones.
fn chain_p(n: usize) -> Mat<f64> {
    Mat::from_fn(n, n, |i, j| if j <= i { 1.0 } else { 0.0 })
}

#[test]
fn chain_q1_to_ground_q2_minus_q1_matches_relative_coordinates_by_hand() {
    // 3 masses, linear springs and viscous dampers plus: Jenkins on q0 to ground, cubic on
    // q1 - q0, Jenkins + cubic on q2 - q1. By hand: y = P^-1 q, every element to ground on y_i.
    let n = 3;
    let k = chain_k(&[0.3, 0.5, 0.8]);
    let m = diag(&[1.0, 0.7, 0.4]);
    let c = Mat::from_fn(n, n, |i, j| 0.02 * k[(i, j)] + if i == j { 0.01 } else { 0.0 });
    let (f0, f1) = (vec![0.05, 0.0, -0.02], vec![0.5, 0.1, 0.2]);
    let el = |a: usize, b: Option<usize>| {
        [
            Contact::jenkins(a, b, 1.2, 0.4, 1.0),
            Contact::polynomial(a, b, vec![0.6, 0.0, 0.9]),
            Contact::jenkins(a, b, 0.9, 0.3, 1.0),
        ]
    };
    let [j0, _, _] = el(0, None);
    let [_, c1, _] = el(1, Some(0));
    let [j2, c2, _] = el(2, Some(1));
    let chained = model(k.clone(), m.clone(), Some(c.clone()), f0.clone(), f1.clone(), vec![j0, c1, j2, c2]);
    let p = chain_p(n);
    let pt = p.transpose().to_owned();
    let tr = |a: &Mat<f64>| &pt * a * &p;
    let ft = |f: &[f64]| -> Vec<f64> { (0..n).map(|j| (0..n).map(|i| p[(i, j)] * f[i]).sum()).collect() };
    let [h0, _, _] = el(0, None);
    let [_, g1, _] = el(1, None);
    let [h2, g2, _] = el(2, None);
    let by_hand = model(tr(&k), tr(&m), Some(tr(&c)), ft(&f0), ft(&f1), vec![h0, g1, h2, g2]);
    let coords = ContactCoordinates::new(&chained, 3).unwrap();
    assert_eq!(coords.n_w, 3, "one coordinate per link");
    let mut any_slip = false;
    for omega in [0.5, 0.9, 1.5] {
        let (a, b) = (solve(&chained, 5, omega), solve(&by_hand, 5, omega));
        // physical q = P y
        let nc = 11;
        let q_hand: Vec<f64> = (0..nc).flat_map(|kk| (0..n).map(move |i| (kk, i))).map(|(kk, i)| (0..=i).map(|j| b.output_coeff(kk, j)).sum()).collect();
        let d = rel_diff(&a.outputs, &q_hand);
        let slips = a.contact_cycles.iter().any(|cy| cy.states.contains(&ContactState::Slip));
        println!("chain vs relative coordinates by hand, w = {omega}: rel. diff {d:.2e} (slip: {slips})");
        any_slip |= slips;
        assert!(d < 1e-9, "{d:.3e}");
    }
    assert!(any_slip, "the case must be nonlinear");
}

#[test]
fn unsupported_overlaps_and_cycles_are_refused_with_what_is_supported() {
    let m = diag(&[1.0, 1.0, 1.0]);
    let k = chain_k(&[1.0, 1.0, 1.0]);
    let exc = Excitation::zero(3);
    let make = |contacts: Vec<Contact>| Model::new(m.clone(), k.clone(), Damping::default(), exc.clone(), contacts, vec![0]);
    // Same 'a' DoF, other kinematics.
    let e = make(vec![Contact::jenkins(0, None, 1.0, 0.1, 1.0), Contact::polynomial(0, Some(1), vec![1.0])]).unwrap_err().to_string();
    assert!(e.contains("contact[1].dofs_a") && e.contains("same dofs_a, dofs_b and frame") && e.contains("chain"), "{e}");
    // A cycle 0 -> 1 -> 2 -> 0.
    let e = make(vec![Contact::jenkins(0, Some(1), 1.0, 0.1, 1.0), Contact::jenkins(1, Some(2), 1.0, 0.1, 1.0), Contact::polynomial(2, Some(0), vec![1.0])])
        .unwrap_err()
        .to_string();
    assert!(e.contains("cycle"), "{e}");
    // A 2D element whose 'a' node overlaps a scalar element's 'a' DoF.
    let e = make(vec![Contact::unilateral(1, None, 1.0, 0.0), Contact::friction_2d([0, 1], None, [[1.0, 0.0], [0.0, 1.0]], ContactLaw::Friction2D { kt: 1.0, kn: 1.0, mu: 0.1, n0: 1.0 })])
        .unwrap_err()
        .to_string();
    assert!(e.contains("DoF 1") && e.contains("other kinematics"), "{e}");
    // Supported: chain, parallel, and a DoF that is the 'b' DoF of several elements.
    make(vec![Contact::jenkins(0, None, 1.0, 0.1, 1.0), Contact::polynomial(0, None, vec![1.0]), Contact::unilateral(1, Some(0), 1.0, 0.0), Contact::jenkins(2, Some(0), 1.0, 0.1, 1.0)]).unwrap();
}

#[test]
fn two_dof_duffing_chain_sweeps_over_the_band_at_default_settings() {
    // NLvib-style 2-DoF chain (primary mass and a light absorber, cubic spring k3 = 1 between
    // them; parameters in the spirit of NLvib's cubic-spring example, not verified against it).
    let k = chain_k(&[1.0, 0.0453]);
    let c = chain_k(&[0.002, 0.013]);
    let m = diag(&[1.0, 0.05]);
    let model = model(k, m, Some(c), vec![0.0; 2], vec![0.11, 0.0], vec![Contact::polynomial(1, Some(0), vec![0.0, 0.0, 1.0])]);
    let opts = HbmOptions::default();
    let sys = FullSystem::new(&model, 7).unwrap();
    let res = sweep(&sys, &SweepOptions::band(0.5, 2.0), &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    let last = res.points.last().unwrap().omega;
    println!("2-DoF Duffing chain H=7: {} points, end {:?}, last W = {last}, failure {:?}", res.points.len(), res.end, res.failure);
    assert!(res.reached_end(), "ended {:?} at W = {last}: {:?}", res.end, res.failure);
    // The cubic acts: the peak differs from the linear chain's.
    let peak = res.points.iter().map(|p| p.output_amplitude(1, 0)).fold(0.0, f64::max);
    assert!(peak.is_finite() && peak > 0.0);
}

#[test]
fn contacts_added_one_by_one_are_checked_against_the_earlier_ones() {
    use jprom::model::contact_coordinates::{ContactGroups, ContactTopology};
    // a chain q0 to ground, q1 - q0, ..., q(n-1) - q(n-2), added in order; then a link that
    // closes it (q0 - q(n-1)) is refused, naming the contact and the cycle
    let n = 50;
    let mut contacts: Vec<Contact> = vec![Contact::jenkins(0, None, 1.0, 0.1, 1.0)];
    contacts.extend((1..n).map(|i| Contact::polynomial(i, Some(i - 1), vec![1.0])));
    let mut t = ContactTopology::default();
    for i in 0..contacts.len() {
        t.add(&contacts, i).unwrap();
    }
    assert_eq!(t.len(), n);
    let batch = ContactGroups::new(&contacts, n).unwrap();
    assert_eq!(batch.groups.len(), n);
    assert_eq!(batch.order, (0..n).collect::<Vec<_>>(), "a chain resolves from ground up");
    // a parallel element on q3 (same kinematics as the q3 - q2 link) joins its block
    contacts.push(Contact::polynomial(3, Some(2), vec![0.0, 0.0, 2.0]));
    t.add(&contacts, n).unwrap();
    // a cycle: q0's 'a' DoF is the start of the chain; an element on (q0 - q(n-1)) would make
    // q0 depend on the end of the chain that depends on it. Ground Jenkins owns q0 already,
    // so take a fresh chain without a ground link to see the cycle refused
    let ring: Vec<Contact> = (0..5).map(|i| Contact::polynomial((i + 1) % 5, Some(i), vec![1.0])).collect();
    let mut r = ContactTopology::default();
    for i in 0..4 {
        r.add(&ring, i).unwrap();
    }
    let e = r.add(&ring, 4).unwrap_err().to_string();
    assert!(e.contains("contact[4]") && e.contains("cycle"), "{e}");
    assert_eq!(r.len(), 4, "a refused contact is not recorded");
    // other kinematics on a taken 'a' DoF
    let clash = vec![Contact::polynomial(1, Some(0), vec![1.0]), Contact::polynomial(1, None, vec![1.0])];
    let mut c = ContactTopology::default();
    c.add(&clash, 0).unwrap();
    let e = c.add(&clash, 1).unwrap_err().to_string();
    assert!(e.contains("other kinematics"), "{e}");
    assert!(ContactGroups::new(&ring, 5).is_err() && ContactGroups::new(&clash, 2).is_err());
}
