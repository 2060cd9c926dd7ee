//! The contact laws through the AFT against closed forms (docs/formulation.md §4.2): the Jenkins
//! element under `u = a cos(theta)` (energy and first harmonic), the 3D element driven along
//! `t1` at constant normal load (same closed forms), circular gross slip, and the unilateral
//! normal spring (clipped cosine).

use jprom::aft::{AftPlan, ContactCycle};
use jprom::contact::{ContactLaw, ContactState};
use std::f64::consts::PI;

struct Jk {
    kt: f64,
    fs: f64,
    a: f64,
}

impl Jk {
    fn xs(&self) -> f64 {
        self.fs / self.kt
    }
    fn energy(&self) -> f64 {
        4.0 * self.fs * (self.a - self.xs())
    }
    fn c1_s1(&self) -> (f64, f64) {
        let th = (1.0 - 2.0 * self.xs() / self.a).acos();
        let c1 = self.kt * self.a / PI * (th - (2.0 * th).sin() / 2.0);
        let s1 = -(4.0 * self.fs / PI) * (1.0 - self.xs() / self.a);
        (c1, s1)
    }
}

/// Runs one law on `w` with `H = 1`; returns force harmonics and the cycle.
fn run(law: &ContactLaw, w: &[f64], nt: usize) -> (Vec<f64>, ContactCycle) {
    let plan = AftPlan::new(1, nt).unwrap();
    let mut ws = plan.workspace();
    let mut f = vec![0.0; w.len()];
    let mut cycle = ContactCycle::default();
    plan.contact(law, w, &mut f, None, Some(&mut cycle), &mut ws);
    (f, cycle)
}

/// Relative errors (energy, first harmonic) of a run against the Jenkins closed form.
fn errors(jk: &Jk, f_cos: f64, f_sin: f64, w_diss: f64) -> (f64, f64) {
    let (c1, s1) = jk.c1_s1();
    let e_w = (w_diss - jk.energy()).abs() / jk.energy();
    let e_h = ((f_cos - c1).powi(2) + (f_sin - s1).powi(2)).sqrt() / (c1 * c1 + s1 * s1).sqrt();
    (e_w, e_h)
}

#[test]
fn jenkins_matches_closed_form_and_converges_with_nt() {
    let jk = Jk { kt: 3.0, fs: 0.9, a: 1.0 }; // x_s = 0.3 a: partial slip
    let law = ContactLaw::Jenkins { kt: jk.kt, mu: 0.45, normal_load: 2.0 };
    let (c1, s1) = jk.c1_s1();
    assert!(s1 < 0.0, "docs/formulation.md: s1 < 0 for a force resisting u = a cos");
    println!("Jenkins, closed form: W = {:.6}, c1 = {c1:.6}, s1 = {s1:.6}", jk.energy());
    println!("{:>6} {:>12} {:>12} {:>12} {:>12}", "Nt", "c1", "s1", "err W", "err harm1");
    let mut prev = (f64::INFINITY, f64::INFINITY);
    for nt in [64, 256, 1024] {
        let (f, cycle) = run(&law, &[0.0, jk.a, 0.0], nt);
        let (e_w, e_h) = errors(&jk, f[1], f[2], cycle.dissipated_energy);
        println!("{nt:>6} {:>12.6} {:>12.6} {e_w:>12.3e} {e_h:>12.3e}", f[1], f[2]);
        assert!(f[0].abs() < 1e-12, "no static force for a symmetric cycle");
        assert!(cycle.states.contains(&ContactState::Stick) && cycle.states.contains(&ContactState::Slip));
        // The energy is the slider force times the slip over the cycle; both turning points of
        // u = a cos(theta) are samples, so the discrete slip is exact at every Nt.
        assert!(e_w < 1e-12, "Nt = {nt}: energy error {e_w:.3e}");
        assert!(e_h < prev.1, "first-harmonic error must shrink as Nt grows");
        prev = (e_w, e_h);
    }
    assert!(prev.1 < 1e-3, "Nt = 1024: errors {prev:?}");
}

#[test]
fn jenkins_sign_and_energy_several_amplitudes() {
    // Stick below x_s (no dissipation, F = kt u), slip above it.
    let (kt, fs) = (2.0, 1.0);
    let law = ContactLaw::Jenkins { kt, mu: 1.0, normal_load: fs };
    for a in [0.3, 0.8, 1.5, 4.0, 20.0] {
        let (f, cycle) = run(&law, &[0.0, a, 0.0], 1024);
        let xs = fs / kt;
        if a <= xs {
            assert!((f[1] - kt * a).abs() < 1e-12 && f[2].abs() < 1e-12);
            assert!(cycle.dissipated_energy.abs() < 1e-12);
        } else {
            let jk = Jk { kt, fs, a };
            let (e_w, e_h) = errors(&jk, f[1], f[2], cycle.dissipated_energy);
            println!("a = {a}: err W {e_w:.2e}, err harm1 {e_h:.2e}");
            assert!(e_w < 1e-3 && e_h < 2e-3, "a = {a}: {e_w:.2e} {e_h:.2e}");
            assert!(f[2] < 0.0);
        }
    }
}

#[test]
fn friction3d_along_t1_at_constant_normal_load_is_jenkins() {
    let (kt, mu, n0, a) = (3.0, 0.45, 2.0, 1.0);
    let jk = Jk { kt, fs: mu * n0, a };
    let jenkins = ContactLaw::Jenkins { kt, mu, normal_load: n0 };
    let law = ContactLaw::Friction3D { kt1: kt, kt2: 5.0, kn: 1e3, mu, n0 };
    println!("{:>6} {:>12} {:>12}", "Nt", "err W", "err harm1");
    let mut prev = f64::INFINITY;
    for nt in [64, 256, 1024] {
        // w = (u1, u2, v) coefficient-major: u1 = a cos, v = 0 so N = n0.
        let w3 = [0.0, 0.0, 0.0, a, 0.0, 0.0, 0.0, 0.0, 0.0];
        let (f, cycle) = run(&law, &w3, nt);
        let (fj, cj) = run(&jenkins, &[0.0, a, 0.0], nt);
        for k in 0..3 {
            assert!((f[k * 3] - fj[k]).abs() < 1e-12, "T1 differs from Jenkins");
            assert!(f[k * 3 + 1].abs() < 1e-12, "no T2");
        }
        assert!((f[2] - n0).abs() < 1e-12 && f[5].abs() < 1e-12 && f[8].abs() < 1e-12);
        assert_eq!(cycle.states, cj.states);
        let (e_w, e_h) = errors(&jk, f[3], f[6], cycle.dissipated_energy);
        println!("{nt:>6} {e_w:>12.3e} {e_h:>12.3e}");
        assert!(e_h < prev);
        prev = e_h;
    }
    assert!(prev < 1e-3);
}

#[test]
fn friction3d_circular_gross_slip_dissipation() {
    // u = r (cos, sin), isotropic kt, constant N. In steady gross slip the slider runs on a
    // circle of radius r_s with the spring u - s (length x_s) tangent to it, so
    // r_s = sqrt(r^2 - x_s^2), |T| = mu N, and W = mu N 2 pi r_s.
    let (kt, mu, n0, r) = (4.0, 0.5, 2.0, 1.0);
    let law = ContactLaw::Friction3D { kt1: kt, kt2: kt, kn: 10.0, mu, n0 };
    let xs = mu * n0 / kt;
    let expect = mu * n0 * 2.0 * PI * (r * r - xs * xs).sqrt();
    let w3 = [0.0, 0.0, 0.0, r, 0.0, 0.0, 0.0, r, 0.0];
    let mut prev = f64::INFINITY;
    for nt in [64, 256, 1024] {
        let (f, cycle) = run(&law, &w3, nt);
        let err = (cycle.dissipated_energy - expect).abs() / expect;
        println!("circular slip Nt={nt}: W = {:.6}, expected {expect:.6}, rel err {err:.2e}", cycle.dissipated_energy);
        assert!(cycle.states.iter().all(|&s| s == ContactState::Slip));
        assert!(err < prev);
        prev = err;
        // |T| = mu N throughout: the first harmonic of T1 and of T2 has magnitude mu N.
        let m1 = (f[3].powi(2) + f[6].powi(2)).sqrt();
        let m2 = (f[4].powi(2) + f[7].powi(2)).sqrt();
        assert!((m1 - mu * n0).abs() < 1e-9 && (m2 - mu * n0).abs() < 1e-9, "{m1} {m2}");
    }
    assert!(prev < 2e-3);
}

/// `kn max(0, v0 + a cos)` by a fine midpoint rule (independent of the AFT's grid).
fn clipped_cosine_quadrature(kn: f64, v0: f64, a: f64, h: usize) -> (f64, f64, f64) {
    let m = 1 << 20;
    let (mut c0, mut c, mut s) = (0.0, 0.0, 0.0);
    for i in 0..m {
        let th = 2.0 * PI * (i as f64 + 0.5) / m as f64;
        let f = kn * (v0 + a * th.cos()).max(0.0);
        c0 += f;
        c += f * (h as f64 * th).cos();
        s += f * (h as f64 * th).sin();
    }
    (c0 / m as f64, 2.0 * c / m as f64, 2.0 * s / m as f64)
}

#[test]
fn unilateral_normal_spring_matches_clipped_cosine() {
    let (kn, a, n0) = (7.0, 1.0, 0.7);
    let law = ContactLaw::Friction3D { kt1: 1.0, kt2: 1.0, kn, mu: 0.3, n0 };
    let plan = AftPlan::new(3, 1024).unwrap();
    let mut ws = plan.workspace();
    println!("{:>6} {:>12} {:>12} {:>12} {:>12}", "v0", "F0", "err F0", "err c1", "err h2,h3");
    for v0 in [-0.8, -0.3, 0.0, 0.4, 0.9] {
        // v0 is the total offset: n0 + kn v_static = kn v0.
        let v_static = v0 - n0 / kn;
        let mut w = vec![0.0; 21];
        w[2] = v_static;
        w[3 + 2] = a;
        let mut f = vec![0.0; 21];
        let mut cycle = ContactCycle::default();
        plan.contact(&law, &w, &mut f, None, Some(&mut cycle), &mut ws);
        assert!(cycle.states.contains(&ContactState::Separated));
        let thc = (-v0 / a).acos();
        let f0 = kn / PI * (v0 * thc + a * thc.sin());
        let c1 = kn / PI * (2.0 * v0 * thc.sin() + a * thc + a * thc.sin() * thc.cos());
        let e0 = (f[2] - f0).abs() / f0;
        let e1 = (f[5] - c1).abs() / c1;
        assert!(f[8].abs() < 1e-12, "s1 = 0 for an even signal");
        let mut e_high: f64 = 0.0;
        for h in 2..=3 {
            let (_, ch, sh) = clipped_cosine_quadrature(kn, v0, a, h);
            e_high = e_high.max((f[(2 * h - 1) * 3 + 2] - ch).abs().max((f[2 * h * 3 + 2] - sh).abs()) / f0);
        }
        println!("{v0:>6} {:>12.6} {e0:>12.2e} {e1:>12.2e} {e_high:>12.2e}", f[2]);
        assert!(e0 < 1e-4 && e1 < 1e-4 && e_high < 1e-4, "v0 = {v0}");
        // No friction work with u = 0.
        assert!(cycle.dissipated_energy.abs() < 1e-14);
    }
}
