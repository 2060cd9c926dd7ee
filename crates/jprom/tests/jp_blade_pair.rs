//! JP with node-pair contacts on a realistic model (issue 5, acceptance point 5): two
//! shroud-coupled copies of the built-in blade ([`jprom::fe::BladePair`]), CB(50) each, 9
//! node-pair contacts between blade A's patch 1 and blade B's patch 0 plus 9 + 9 node-to-ground
//! contacts on the outer patches; both blades forced in anti-phase (engine order N / 2).
//!
//! The band is +-2 % around the pair's stuck anti-phase flap mode (2057 Hz, the counterpart of
//! the single blade's 2165 Hz first bending). `alpha_ST` comes from the linear stuck response
//! (tests/blade_support::alpha_stuck) and is checked against the nonlinear solution.
//!
//! Measured (FO resonance; X0, X1 = relative static / first-harmonic error at blade A's tip;
//! energy = largest per-contact error of the energy dissipated per cycle over the largest FO
//! contact energy; bases from the FO solution's own `K̂`, in-band modes + `extra` nearest,
//! static correction, gamma 1e10). FR is `FrRom::new` (linear-DoF rows condensed over the
//! band, so its size is about twice NLR's and its errors NLR's); "FR (JP rows)" is the paper's
//! FR on the same basis, measured before the band-condensed rows existed:
//!
//! | level        | H | extra | sizes FR / NLR            | FR X0   | FR X1   | NLR X0  | NLR X1  | e*_1 / e_1        | energy  | FR (JP rows) X0 / X1 |
//! |--------------|---|-------|---------------------------|---------|---------|---------|---------|-------------------|---------|----------------------|
//! | a_ST / 10    | 1 | 4     | [33, 34] / [33, 16]       | 4.9e-3  | 2.1e-4  | 4.9e-3  | 2.1e-4  | 7.8e-3 / 1.4e-3   | 1.8e-3  | 1.7e-4 / 7.9e-4      |
//! | a_ST / 10    | 1 | 20    | [51, 72] / [51, 48]       | 1.4e-4  | 3.6e-6  | 1.4e-4  | 3.0e-6  | 1.1e-3 / 2.3e-4   | 3.3e-6  | 1.8e-4 / 5.0e-5      |
//! | a_ST / 10    | 1 | 170   | [51, 105] / [51, 81]      | 2.1e-10 | 1.8e-6  | 3.5e-12 | 1.5e-12 | 4.6e-10 / 7.5e-10 (FR) | 1.4e-13 (NLR) | -       |
//! | a_ST / 1000  | 1 | 4     | [25, 28] / [25, 12]       | 3.9e-1  | 5.1e-3  | 3.9e-1  | 5.1e-3  | 4.7e-1 / 1.3e-1   | 4.4e-3  | 3.4e-1 / 3.9e-2      |
//! | a_ST / 1000  | 1 | 20    | [55, 67] / [55, 44]       | 5.1e-5  | 7.0e-7  | 5.1e-5  | 6.5e-7  | 9.2e-4 / 1.8e-4   | 1.2e-5  | 2.5e-3 / 1.7e-5      |
//! | a_ST / 10    | 3 | 4     | [51, 39, 40, 40] / [51, 20x3] | 2.0e-3 | 4.6e-4 | 2.0e-3 | 4.6e-4 | 1.0e-2 / 3.4e-3 | 1.7e-3 | 3.5e-4 / 2.0e-3     |
//! | a_ST / 10    | 3 | 20    | [51, 76, 83, 88] / [51, 52x3] | 1.8e-5 | 2.8e-6 | 1.8e-5 | 2.0e-6 | 8.6e-4 / 1.9e-4 | 3.5e-6 | 3.4e-4 / 2.1e-5     |
//!
//! At `alpha_ST / 10` 21 of the 27 contacts slip somewhere in the cycle (7 / 9 / 5 on ground A /
//! interface / ground B), resonance 2046 Hz; at `alpha_ST / 1000` all 27 slip and the
//! resonance has left the band (the largest response is at its lower edge, 2016 Hz), which is
//! why in-band + 4 modes are poor there and say so (`e*_1` 0.47): the slipping mode is
//! outside the band. With 20 extra modes every X0 and X1 is within the 0.1 % target, FR and
//! NLR (the paper's FR left 2.5e-3 on the static term at gross slip, the mean-friction quantity
//! of tests/jp_blade.rs). With a basis spanning every contact coordinate NLR is exact, pairs
//! included. `e*_1 >= e_1` on every case.
//!
//! Predicted basis (stuck mode, gamma 1e3, defaults, 94 distinct patterns), NLR sizes
//! [54, 17], at the FO resonance at `alpha_ST / 10`: X1 4.0e-3 (FR and NLR; the paper's FR
//! 2.5e-3), e*_1 / e_1 6.0e-2 / 1.0e-2, energy 1.7e-2. The self-correcting FR sweep regenerates
//! once (worst e*_1 over the band 6.1e-2 -> about 1e-2); at the FO resonance X1 7.4e-4 (FR and
//! NLR), e*_1 / e_1 7.1e-3 / 1.9e-3.
//!
//! Linear stuck limit just above `alpha_ST`: nonlinear = linear with pair springs to 1e-14
//! (static), 1.2e-8 (cos part at the lightly damped resonance), 1.2e-12 (sin part).
//!
//! Runtime (2 loaded cores, test profile): ~105 s for the file, of which the blade build and
//! CB reduction ~10 s, FO sweeps 7 s (H = 1, `alpha_ST / 10`, 215 points), 2 s
//! (`alpha_ST / 1000`), 17-37 s (H = 3), the prediction 13-16 s, the adaptive sweep 44-50 s.
//! Tolerances are about twice the measured worst values.

use jprom_testkit::blade as blade_support;

use blade_support::*;
use jprom::fe::{BladePair, BladeParams, PairParams, PairSite};
use jprom::condensation::CondensedSystem;
use jprom::contact::ContactState;
use jprom::rom::error_metric::{actual_error, predicted_error};
use jprom::hbm::{solve_point, HbmOptions, PointSolution, SweepOptions};
use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::{ContactCoordinates, Damping, Model};
use jprom::rom::{adaptive_sweep, AdaptiveOptions, FrRom, NlrRom, ReducedModel, RomKind};
use faer::linalg::solvers::Solve;
use faer::Mat;
use std::f64::consts::PI;
use std::sync::OnceLock;
use std::time::Instant;

/// The two-blade case at unit dynamic scale.
struct Pair {
    pair: BladePair,
    model: Model,
    /// Stuck anti-phase flap mode (rad/s).
    omega_stuck: f64,
    band: (f64, f64),
    alpha_st: f64,
}

impl Pair {
    fn at_level(&self, alpha: f64) -> Model {
        let mut m = self.model.clone();
        m.excitation.set_level(alpha).unwrap();
        m
    }
}

fn pair() -> &'static Pair {
    static P: OnceLock<Pair> = OnceLock::new();
    P.get_or_init(|| {
        let t = Instant::now();
        let pair = BladePair::from_params(&BladeParams::default(), 50, &PairParams::default()).unwrap();
        let f = pair.natural_frequencies_hz(true).unwrap();
        assert!(f[1] > 2000.0 && f[1] < 2100.0, "stuck anti-phase flap mode {} Hz", f[1]);
        let omega_stuck = 2.0 * PI * f[1];
        let model = pair.to_model(Damping::from_modal_ratio(ZETA, omega_stuck)).unwrap();
        let alpha_st = alpha_stuck(&model, omega_stuck);
        println!("pair built in {:?}: stuck {:.1?} Hz, alpha_ST {alpha_st:.4e}, site forces {:.1?}", t.elapsed(), &f[..3], pair.stuck_site_forces);
        Pair { pair, model, omega_stuck, band: (0.98 * omega_stuck, 1.02 * omega_stuck), alpha_st }
    })
}

/// The FO resonance at `alpha_ST / 10`, H = 1 (shared by the own-basis and predicted-basis
/// tests).
fn fo_partial_slip() -> &'static (CondensedSystem, PointSolution) {
    static FO: OnceLock<(CondensedSystem, PointSolution)> = OnceLock::new();
    FO.get_or_init(|| fo_resonance(&pair().at_level(pair().alpha_st / 10.0), 1))
}

fn fo_resonance(model: &Model, harmonics: usize) -> (CondensedSystem, PointSolution) {
    let p = pair();
    let hopts = HbmOptions::default();
    let cond = CondensedSystem::new(model, harmonics).unwrap();
    let sopts = SweepOptions { max_step: if harmonics == 1 { 0.02 } else { 0.05 }, ..SweepOptions::band(p.band.0, p.band.1) };
    let t = Instant::now();
    let (fo, n) = full_order_resonance(&cond, &hopts, p.band, Some(sopts));
    let slipping: Vec<usize> = [PairSite::GroundA, PairSite::Interface, PairSite::GroundB]
        .iter()
        .map(|&s| {
            fo.contact_cycles
                .iter()
                .zip(&p.pair.sites)
                .filter(|(c, &site)| site == s && c.states.iter().any(|&x| x != ContactState::Stick))
                .count()
        })
        .collect();
    println!(
        "FO H={harmonics}: {n} points in {:?}, resonance {:.2} Hz, tip A {:.3e} mm, slipping per site (ground A, interface, ground B) {slipping:?}",
        t.elapsed(),
        fo.omega / (2.0 * PI),
        tip_amplitude(&fo)
    );
    (cond, fo)
}

/// Own-Jacobian bases at `alpha_ST / div` ([`own_jacobian_outcomes`]).
fn own_basis(harmonics: usize, div: f64, extras: &[usize]) -> Vec<(Outcome, Outcome)> {
    let p = pair();
    let model = p.at_level(p.alpha_st / div);
    let computed;
    let (cond, fo) = if harmonics == 1 && div == 10.0 {
        let c = fo_partial_slip();
        (&c.0, &c.1)
    } else {
        computed = fo_resonance(&model, harmonics);
        (&computed.0, &computed.1)
    };
    own_jacobian_outcomes(&model, cond, fo, p.band, extras, &format!("H={harmonics} alpha_ST/{div}"))
}

fn assert_below(what: &str, values: &[(&str, f64)], tol: f64) {
    for (name, v) in values {
        assert!(*v < tol, "{what}: {name} {v:.3e} >= {tol:.1e}");
    }
}

/// Energy tolerance with in-band + 4 modes (measured worst 3.3e-3, H = 3) and with + 20
/// (measured worst 3.0e-5).
const ENERGY_TOL_4: f64 = 7e-3;
const ENERGY_TOL_20: f64 = 1e-4;

#[test]
fn own_jacobian_basis_partial_slip_h1() {
    let r = own_basis(1, 10.0, &[4, 20, 170]);
    let (fr, nlr) = &r[0];
    assert_below("+4", &[("FR X1", fr.x1), ("NLR X1", nlr.x1)], 1.6e-3);
    assert_below("+4", &[("FR X0", fr.x0), ("NLR X0", nlr.x0)], 1e-2);
    assert_below("+4", &[("FR energy", fr.energy), ("NLR energy", nlr.energy)], ENERGY_TOL_4);
    // + 20 modes: within the 0.1 % target, static term included.
    let (fr, nlr) = &r[1];
    assert_below("+20", &[("FR X0", fr.x0), ("FR X1", fr.x1), ("NLR X0", nlr.x0), ("NLR X1", nlr.x1)], 1e-3);
    assert_below("+20", &[("FR energy", fr.energy), ("NLR energy", nlr.energy)], ENERGY_TOL_20);
    // A basis spanning every contact coordinate (node pairs included) makes NLR exact.
    let (_, full) = &r[2];
    assert_below("complete NLR", &[("X0", full.x0), ("X1", full.x1), ("energy", full.energy)], 1e-9);
}

#[test]
fn own_jacobian_basis_gross_slip_h1() {
    let r = own_basis(1, 1000.0, &[4, 20]);
    // In-band + 4 misses the slipping mode, which has left the band; the predictor says so.
    let (fr, nlr) = &r[0];
    assert!(fr.e_star > 0.05 && nlr.e_star > 0.05, "poor basis not flagged: e*_1 FR {:.2e} NLR {:.2e}", fr.e_star, nlr.e_star);
    let (fr, nlr) = &r[1];
    assert_below("+20", &[("FR X0", fr.x0), ("FR X1", fr.x1), ("NLR X0", nlr.x0), ("NLR X1", nlr.x1)], 1e-3);
    assert_below("+20", &[("FR energy", fr.energy), ("NLR energy", nlr.energy)], ENERGY_TOL_20);
    assert_below("+20", &[("FR e*_1", fr.e_star), ("NLR e*_1", nlr.e_star)], 0.01);
}

#[test]
fn own_jacobian_basis_partial_slip_h3() {
    let r = own_basis(3, 10.0, &[4, 20]);
    let (fr, nlr) = &r[0];
    assert_below("H=3 +4", &[("FR X1", fr.x1)], 4e-3);
    assert_below("H=3 +4", &[("NLR X1", nlr.x1)], 1e-3);
    assert_below("H=3 +4", &[("FR energy", fr.energy), ("NLR energy", nlr.energy)], ENERGY_TOL_4);
    let (fr, nlr) = &r[1];
    assert_below("H=3 +20", &[("FR X0", fr.x0), ("FR X1", fr.x1), ("NLR X0", nlr.x0), ("NLR X1", nlr.x1)], 1e-3);
    assert_below("H=3 +20", &[("FR energy", fr.energy), ("NLR energy", nlr.energy)], ENERGY_TOL_20);
}

/// Linear stuck limit: just above `alpha_ST` every contact (ground and pair) sticks at the stuck
/// resonance, and the nonlinear (condensed, contact-coordinate) solution equals the linear
/// response of the physical model with the stuck springs `R^T diag(k) R` between the paired
/// nodes ([`BladePair::stuck_stiffness`], assembled independently of the contact
/// coordinates); just below it something slips.
#[test]
fn stuck_pair_is_the_linear_model_with_pair_springs() {
    let p = pair();
    let hopts = HbmOptions::default();
    let solve = |alpha: f64| {
        let cond = CondensedSystem::new(&p.at_level(alpha), 1).unwrap();
        solve_point(&cond, p.omega_stuck, None, &hopts).unwrap()
    };
    let s = solve(1.02 * p.alpha_st);
    assert!(s.contact_cycles.iter().all(|c| c.states.iter().all(|&x| x == ContactState::Stick)));
    let slipping = solve(p.alpha_st / 1.05);
    assert!(slipping.contact_cycles.iter().any(|c| c.states.iter().any(|&x| x != ContactState::Stick)));

    // Linear reference in physical coordinates: K_s q0 = f0, (K_s - w^2 M + i w C) q1 = f1.
    let m = p.at_level(1.02 * p.alpha_st);
    let n = m.n_dof();
    let ks = p.pair.stuck_stiffness();
    let c = m.damping_matrix();
    let w = p.omega_stuck;
    let sc = m.excitation.dynamic_scale;
    let q0 = ks.partial_piv_lu().solve(&Mat::from_fn(n, 1, |i, _| m.excitation.static_force[i]));
    let a = Mat::from_fn(2 * n, 2 * n, |i, j| {
        let (r, k) = (i % n, j % n);
        let re = ks[(r, k)] - w * w * m.mass[(r, k)];
        let im = w * c[(r, k)];
        match (i < n, j < n) {
            (true, true) | (false, false) => re,
            (true, false) => im,
            (false, true) => -im,
        }
    });
    let hf = &m.excitation.harmonics[0];
    let q1 = a.partial_piv_lu().solve(&Mat::from_fn(2 * n, 1, |i, _| sc * if i < n { hf.cos[i] } else { hf.sin[i - n] }));
    let no = s.n_outputs;
    let mut worst = [0.0f64; 3];
    for k in 0..3 {
        let lin: Vec<f64> = m.output_dofs.iter().map(|&d| if k == 0 { q0[(d, 0)] } else { q1[((k - 1) * n + d, 0)] }).collect();
        let hb = &s.outputs[k * no..(k + 1) * no];
        let num = lin.iter().zip(hb).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
        worst[k] = num / lin.iter().map(|x| x * x).sum::<f64>().sqrt();
    }
    println!("stuck limit: relative output differences (static, cos, sin) {:.2e} {:.2e} {:.2e}", worst[0], worst[1], worst[2]);
    // Measured 1e-14, 1.2e-8, 1.2e-12: the cos part sits on the lightly damped resonance
    // (zeta = 0.2 %), which amplifies the 1e-10 residual tolerance of the HBM solve.
    assert!(worst.iter().all(|&e| e < 1e-6), "{worst:?}");
}

/// A predicted basis (stuck anti-phase flap mode as generating shape, gamma 1e3) at the FO
/// resonance at `alpha_ST / 10`: errors and a conservative predictor, FR and NLR.
#[test]
fn predicted_basis_partial_slip() {
    let p = pair();
    let (cond, fo) = fo_partial_slip();
    let model = p.at_level(p.alpha_st / 10.0);
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let t = Instant::now();
    let (basis, report) = predict_basis(&coords, &PredictionOptions::new(p.band)).unwrap();
    println!("predicted in {:?}: sizes {:?}, {} patterns, omega_ST {:.1} Hz", t.elapsed(), basis.sizes, report.n_patterns, report.omega_stuck.unwrap() / (2.0 * PI));
    // The generating shape is the anti-phase flap mode (the stuck mode nearest the band centre).
    assert!((report.omega_stuck.unwrap() / p.omega_stuck - 1.0).abs() < 1e-9);
    let fr = FrRom::new(&coords, &basis).unwrap();
    let nlr = NlrRom::new(cond, &basis).unwrap();
    for (rom, name) in [(&fr as &dyn ReducedModel, "FR"), (&nlr as &dyn ReducedModel, "NLR")] {
        let s = solve_point(rom, fo.omega, None, &hopts).unwrap();
        let es = predicted_error(rom, fo.omega, &s.z).unwrap();
        let ea = actual_error(rom, fo.omega, &s.z, fo).unwrap();
        let x1 = tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 1);
        let energy = energy_error(rom, &s, fo);
        println!("predicted {name}: X1 {x1:.2e} e*_1 {:.2e} e_1 {:.2e} energy {energy:.2e}", es[1], ea[1]);
        assert!(es[1] + 1e-9 >= ea[1], "{name}: e*_1 {:.3e} < e_1 {:.3e}", es[1], ea[1]);
        // Measured: X1 2.5e-3 / 4.0e-3, e*_1 6.0e-2, energy 1.8e-2 (FR / NLR).
        assert_below(name, &[("X1", x1)], 8e-3);
        assert_below(name, &[("e*_1", es[1])], 0.12);
        assert_below(name, &[("energy", energy)], 0.04);
    }
}

/// The self-correcting FR sweep over the band at `alpha_ST / 10`: e*_1 of the predicted basis of
/// [`predicted_basis_partial_slip`] is above the threshold somewhere in the band (6.1e-2), but
/// the linearised error the sweep judges by (at the reduced resonance and at the points of
/// largest e*_1) is 9e-3, so the basis is kept as it is (before the sweep judged by e*_1, one
/// regeneration took it to 1.05e-2 and X1 to 1.75e-3); the basis then does FR and NLR at the
/// FO resonance within 1 %.
#[test]
fn adaptive_sweep_partial_slip() {
    let p = pair();
    let div = 10.0;
    let model = p.at_level(p.alpha_st / div);
    let hopts = HbmOptions::default();
    let sopts = SweepOptions { max_step: 0.02, ..SweepOptions::band(p.band.0, p.band.1) };
    let t = Instant::now();
    let out = adaptive_sweep(&model, 1, &PredictionOptions::new(p.band), &sopts, &hopts, &AdaptiveOptions { kind: RomKind::Fr, ..Default::default() }).unwrap();
    let worst = out.predicted_errors.iter().map(|e| e[1]).fold(0.0, f64::max);
    if let Some(c) = out.corrections.first() {
        assert!(c.worst_error_after < c.worst_error_before);
    }
    println!("adaptive /{div} in {:?}: corrections {:?}, sizes {:?}, worst e*_1 {worst:.2e}, points {}", t.elapsed(), out.corrections, out.basis.sizes, out.sweep.points.len());
    let (cond, fo) = fo_partial_slip();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let fr = FrRom::new(&coords, &out.basis).unwrap();
    let nlr = NlrRom::new(cond, &out.basis).unwrap();
    for (rom, name) in [(&fr as &dyn ReducedModel, "FR"), (&nlr as &dyn ReducedModel, "NLR")] {
        let s = solve_point(rom, fo.omega, None, &hopts).unwrap();
        let es = predicted_error(rom, fo.omega, &s.z).unwrap();
        let ea = actual_error(rom, fo.omega, &s.z, fo).unwrap();
        let x1 = tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 1);
        println!("adaptive /{div} {name} at FO resonance: X1 {x1:.2e} e*_1 {:.2e} e_1 {:.2e} energy {:.2e}", es[1], ea[1], energy_error(rom, &s, fo));
        assert!(es[1] + 1e-9 >= ea[1], "{name}: e*_1 {:.3e} < e_1 {:.3e}", es[1], ea[1]);
        // Measured: X1 4.4e-3 (FR).
        assert_below(name, &[("X1", x1)], 1e-2);
    }
    assert!(out.worst_error <= AdaptiveOptions::default().threshold, "judged error after the sweep {:.2e} (worst e*_1 {worst:.2e})", out.worst_error);
}
