//! The built-in blade benchmark case shared by `tests/jp_blade.rs` and `examples/jp_report.rs`
//! (docs/formulation.md §12): Craig-Bampton with 50 fixed-interface modes, 18 node-to-ground contacts,
//! band 2140-2190 Hz around the stuck first bending mode, the stuck level `alpha_ST`, and the
//! full-order (condensed) solution at resonance.
#![allow(dead_code)]

use jprom::aft::{evaluate_contacts, ContactForces};
use jprom::fe::{BladeParams, BuiltinBlade};
use jprom::condensation::CondensedSystem;
use jprom::contact::ContactLaw;
use jprom::rom::error_metric::{actual_error, full_order_contact_displacement, predicted_error, reduced_contact_cycles};
use jprom::hbm::{solve_point, sweep, HbmOptions, PointSolution, SweepOptions};
use jprom::jp::{BasisOptions, ContactJacobian, JpBasis, ModeOptions};
use jprom::rom::{FrRom, NlrRom, ReducedModel};
use jprom::model::{ContactCoordinates, Damping, Model};
use faer::linalg::solvers::Solve;
use faer::Mat;
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// Modal damping ratio of the stuck first bending mode (stiffness-proportional damping).
pub const ZETA: f64 = 0.002;
/// Analysis band of the paper (Hz).
pub const BAND_HZ: (f64, f64) = (2140.0, 2190.0);
/// Output node: the blade tip node (the 9th output node, `z = L`); its 3 DoFs are outputs
/// `24..27`, the flap (forced) direction `y` is output 25.
pub const TIP: std::ops::Range<usize> = 24..27;

/// The blade case at unit dynamic scale.
pub struct Blade {
    pub model: Model,
    /// Stuck first bending (rad/s).
    pub omega_stuck: f64,
    /// Band (rad/s).
    pub band: (f64, f64),
    /// `alpha_ST` (see [`alpha_stuck`]).
    pub alpha_st: f64,
}

impl Blade {
    pub fn build() -> Blade {
        Self::build_refined(1)
    }

    /// The blade with contact refinement `r` (18 contact nodes at 1, 242 at 5), CB(50).
    pub fn build_refined(refinement: usize) -> Blade {
        let params = BladeParams { refinement, ..BladeParams::default() };
        let cb = BuiltinBlade::build(&params).unwrap().reduce(50).unwrap();
        let f_st = cb.natural_frequencies_hz(true).unwrap()[0];
        let omega_stuck = 2.0 * PI * f_st;
        let model = cb.to_model(Damping::from_modal_ratio(ZETA, omega_stuck)).unwrap();
        let alpha_st = alpha_stuck(&model, omega_stuck);
        Blade { model, omega_stuck, band: (2.0 * PI * BAND_HZ.0, 2.0 * PI * BAND_HZ.1), alpha_st }
    }

    /// The model at excitation level `alpha = |f_E^0| / |f_E^1|`.
    pub fn at_level(&self, alpha: f64) -> Model {
        let mut m = self.model.clone();
        m.excitation.set_level(alpha).unwrap();
        m
    }
}

/// `alpha_ST`: the largest level `alpha` (smallest first-harmonic load) at which the linear
/// stuck response at the stuck resonance `omega_ST` breaks the stick condition
/// `|T(t)| <= mu N(t)` nowhere: `T`, `N` are the contact forces of the linear model with the
/// stuck springs, static part from `f_E^0` and first harmonic from `s f_E^1`, sampled over the
/// cycle; `s*` is found by bisection on `max_{c,t} |T| / (mu N) = 1` and
/// `alpha_ST = |f_E^0| / (s* |f_E^1|)`. Above `alpha_ST` the nonlinear response at resonance is
/// exactly the linear stuck one.
pub fn alpha_stuck(model: &Model, omega: f64) -> f64 {
    let coords = ContactCoordinates::new(model, 1).unwrap();
    let n = coords.n_dof;
    let mut k = coords.stiffness.clone();
    for (law, &off) in coords.laws.iter().zip(&coords.offsets) {
        for (i, ks) in law.stuck_stiffness().into_iter().enumerate() {
            k[(off + i, off + i)] += ks;
        }
    }
    let f0 = Mat::from_fn(n, 1, |i, _| coords.static_force[i]);
    let q0 = k.partial_piv_lu().solve(&f0);
    let (fc, fs) = &coords.harmonic_force[0];
    let a = Mat::from_fn(2 * n, 2 * n, |i, j| {
        let (r, c) = (i % n, j % n);
        let re = k[(r, c)] - omega * omega * coords.mass[(r, c)];
        let im = omega * coords.damping[(r, c)];
        match (i < n, j < n) {
            (true, true) | (false, false) => re,
            (true, false) => im,
            (false, true) => -im,
        }
    });
    let b = Mat::from_fn(2 * n, 1, |i, _| if i < n { fc[i] } else { fs[i - n] });
    let q1 = a.partial_piv_lu().solve(&b);
    let ratio = |s: f64| -> f64 {
        let mut worst = 0.0f64;
        for (law, &off) in coords.laws.iter().zip(&coords.offsets) {
            let ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 } = *law else { panic!("blade has 3D contacts") };
            for t in 0..256 {
                let th = 2.0 * PI * t as f64 / 256.0;
                let w = |i: usize| q0[(off + i, 0)] + s * (q1[(off + i, 0)] * th.cos() + q1[(n + off + i, 0)] * th.sin());
                let (t1, t2, nn) = (kt1 * w(0), kt2 * w(1), n0 + kn * w(2));
                worst = worst.max((t1 * t1 + t2 * t2).sqrt() / (mu * nn.max(1e-300)));
            }
        }
        worst
    };
    assert!(ratio(0.0) < 1.0, "static preload does not hold the contacts");
    let (mut lo, mut hi) = (0.0, 1.0);
    while ratio(hi) < 1.0 {
        hi *= 2.0;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) < 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let mut m = model.clone();
    m.excitation.dynamic_scale = lo;
    m.excitation.level()
}

/// The contact coordinates `w` (all harmonics) at the static part `q0` and first-harmonic cos
/// part `p phi`, a point of the prediction's generating motion (docs/formulation.md §8.8), and
/// the AFT's forces there, with their cycles (and `K̂` when `jacobian`).
pub fn forces_along_shape(coords: &ContactCoordinates, q0: &[f64], phi: &[f64], p: f64, jacobian: bool) -> (Vec<f64>, ContactForces) {
    let plan = coords.discretisation.plan().unwrap();
    let (hh, nw) = (plan.harmonics(), coords.n_w);
    let mut w = vec![0.0; nw * (2 * hh + 1)];
    w[..nw].copy_from_slice(&q0[..nw]);
    for i in 0..nw {
        w[nw + i] = p * phi[i];
    }
    let mut out = ContactForces::default();
    evaluate_contacts(&plan, &coords.laws, &coords.offsets, nw, &w, jacobian, true, &mut out);
    (w, out)
}

/// Tip-node output harmonic `h` (3-vector, cos and sin parts) of an output vector.
pub fn tip(outputs: &[f64], n_outputs: usize, h: usize) -> Vec<f64> {
    let ks: Vec<usize> = if h == 0 { vec![0] } else { vec![2 * h - 1, 2 * h] };
    ks.iter().flat_map(|&k| TIP.map(move |j| outputs[k * n_outputs + j])).collect()
}

/// First-harmonic amplitude of the tip node (Euclidean over its 3 DoFs, cos and sin parts).
pub fn tip_amplitude(p: &PointSolution) -> f64 {
    tip(&p.outputs, p.n_outputs, 1).iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Relative error of harmonic `h` at the tip node.
pub fn tip_error(rom: &[f64], fo: &[f64], n_outputs: usize, h: usize) -> f64 {
    let (a, b) = (tip(rom, n_outputs, h), tip(fo, n_outputs, h));
    let num: f64 = a.iter().zip(&b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    let den: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
    num / den
}

/// Full-order (condensed, exact on the linear DoFs) sweep over `band` and its resonant point
/// (largest tip first-harmonic amplitude), refined by a fixed-frequency solve.
pub fn full_order_resonance(condensed: &CondensedSystem, hopts: &HbmOptions, band: (f64, f64), sopts: Option<SweepOptions>) -> (PointSolution, usize) {
    let sopts = sopts.unwrap_or(SweepOptions { max_step: 0.02, ..SweepOptions::band(band.0, band.1) });
    let sw = sweep(condensed, &sopts, hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    let peak = sw.points.iter().max_by(|a, b| tip_amplitude(a).total_cmp(&tip_amplitude(b))).unwrap().clone();
    let p = solve_point(condensed, peak.omega, Some(&peak.z), hopts).unwrap();
    (p, sw.points.len())
}

/// Errors of one reduced solution against the full-order one (tip node of the first blade).
pub struct Outcome {
    pub x0: f64,
    pub x1: f64,
    pub e_star: f64,
    pub e: f64,
    /// [`energy_error`].
    pub energy: f64,
}

/// Largest per-contact difference of the energy dissipated per cycle, over the largest FO
/// contact energy.
pub fn energy_error(rom: &dyn ReducedModel, s: &PointSolution, fo: &PointSolution) -> f64 {
    let cy = reduced_contact_cycles(rom, s.omega, &s.z).unwrap();
    let wmax = fo.contact_cycles.iter().map(|c| c.dissipated_energy.abs()).fold(0.0, f64::max);
    cy.iter().zip(&fo.contact_cycles).map(|(a, b)| (a.dissipated_energy - b.dissipated_energy).abs()).fold(0.0, f64::max) / wmax
}

/// Bases from the full-order solution `fo`'s own `K̂` (in-band modes of `band` plus each of
/// `extras` nearest ones, static correction, gamma 1e10): FR (`FrRom::new`, band-condensed
/// rows) and NLR solved at `fo.omega`, with `e*_1 >= e_1` asserted; the paper's FR
/// (`FrRom::with_jp_rows`) is solved and printed for comparison. `label` prefixes the lines.
pub fn own_jacobian_outcomes(model: &Model, cond: &CondensedSystem, fo: &PointSolution, band: (f64, f64), extras: &[usize], label: &str) -> Vec<(Outcome, Outcome)> {
    let harmonics = fo.layout.harmonics;
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(model, harmonics).unwrap();
    let plan = coords.discretisation.plan().unwrap();
    let w = full_order_contact_displacement(fo, coords.n_w).unwrap();
    let mut forces = ContactForces::default();
    evaluate_contacts(&plan, &coords.laws, &coords.offsets, coords.n_w, &w, true, false, &mut forces);
    let k_hat = ContactJacobian::from_forces(&coords.laws, &coords.offsets, coords.n_w, harmonics, &forces, &w).unwrap();
    let mut out = Vec::new();
    for &extra in extras {
        let opts = BasisOptions { modes: ModeOptions { extra_outside: extra, ..ModeOptions::in_band(band) }, gamma: 1e10 };
        let basis = JpBasis::from_jacobian(&coords, &k_hat, &opts).unwrap();
        let run = |rom: &dyn ReducedModel, name: &str| -> Outcome {
            let t = std::time::Instant::now();
            let s = solve_point(rom, fo.omega, None, &hopts).unwrap();
            let es = predicted_error(rom, fo.omega, &s.z).unwrap();
            let ea = actual_error(rom, fo.omega, &s.z, fo).unwrap();
            let o = Outcome {
                x0: tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 0),
                x1: tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 1),
                e_star: es[1],
                e: ea[1],
                energy: energy_error(rom, &s, fo),
            };
            println!(
                "{label} extra {extra} {name} sizes {:?}: X0 {:.2e} X1 {:.2e} e*_1 {:.2e} e_1 {:.2e} energy {:.2e} ({:?})",
                rom.layout().sizes, o.x0, o.x1, o.e_star, o.e, o.energy, t.elapsed()
            );
            // The predictor is conservative (round-off allowance for exact bases).
            assert!(o.e_star + 1e-9 >= o.e, "{name}: e*_1 {:.3e} < e_1 {:.3e}", o.e_star, o.e);
            o
        };
        run(&FrRom::with_jp_rows(&coords, &basis).unwrap(), "FR (JP rows)");
        let fr = run(&FrRom::new(&coords, &basis).unwrap(), "FR");
        let nlr = run(&NlrRom::new(cond, &basis).unwrap(), "NLR");
        out.push((fr, nlr));
    }
    out
}
