//! JP on the built-in blade (issue 5 acceptance; docs/formulation.md §12): Craig-Bampton with 50 modes,
//! 18 node-to-ground contacts, band 2140-2190 Hz around the stuck first bending mode (2165 Hz).
//!
//! `alpha_ST` is found from the linear stuck response (tests/blade_support::alpha_stuck) and
//! checked here against the nonlinear solution. Bases from the full-order (FO) solution's own
//! contact Jacobian at resonance are compared with the FO (condensed) solution at
//! `alpha_ST / 10` (partial slip) and `alpha_ST / 3000` (gross slip).
//!
//! What the 0.1 % acceptance takes on this blade (measured; bases carry the static
//! correction of `ModeOptions::static_correction`; FR is `FrRom::new`, whose linear-DoF rows
//! follow the contact rows by condensation over the band, `rom::band_condensed_basis`):
//! - X1 at the tip, in-band modes + the 4 nearest: FR and NLR 4.2e-5 / 2.9e-5 at alpha_ST / 10
//!   / 3000 (FR with the JP modes' own rows, the paper's FR: 7.6e-4 / 6.0e-4).
//! - X0 at the tip is a different quantity: the pressing load is a couple on the shroud, so the
//!   static tip displacement across the flap direction is set by the mean tangential forces of
//!   the slipping contacts (6.7e-5 mm against 0.09 mm for X1 at gross slip), and those follow
//!   the small normal motion of the contacts. It needs in-band + 20 modes: FR and NLR 8.2e-5
//!   at alpha_ST / 10 and 9.2e-5 at alpha_ST / 3000 (n_1 = 60 and 55 for FR, 48 and 43 for
//!   NLR). The paper's FR on the same basis stays at 10 % at gross slip (X1 7e-6 there): its
//!   Galerkin projection distorts that small normal motion, which the band-condensed rows fix.

use jprom_testkit::blade as blade_support;

use blade_support::*;
use jprom::condensation::CondensedSystem;
use jprom::contact::ContactState;
use jprom::rom::error_metric::{actual_error, predicted_error};
use jprom::hbm::{solve_point, HarmonicSystem, HbmOptions, PointSolution, SweepOptions};
use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::ContactCoordinates;
use jprom::rom::{adaptive_sweep, AdaptiveOptions, AdaptiveSweep, CorrectionKind, FrRom, NlrRom, ReducedModel, RomKind};
use std::sync::OnceLock;

fn blade() -> &'static Blade {
    static B: OnceLock<Blade> = OnceLock::new();
    B.get_or_init(Blade::build)
}

/// Own-Jacobian bases at `alpha_ST / div` ([`own_jacobian_outcomes`]); one FO solve for all.
fn own_basis(harmonics: usize, div: f64, extras: &[usize]) -> Vec<(Outcome, Outcome)> {
    let b = blade();
    let model = b.at_level(b.alpha_st / div);
    let hopts = HbmOptions::default();
    let cond = CondensedSystem::new(&model, harmonics).unwrap();
    let sopts = SweepOptions { max_step: if harmonics == 1 { 0.02 } else { 0.05 }, ..SweepOptions::band(b.band.0, b.band.1) };
    let (fo, _) = full_order_resonance(&cond, &hopts, b.band, Some(sopts));
    own_jacobian_outcomes(&model, &cond, &fo, b.band, extras, &format!("H={harmonics} alpha_ST/{div}"))
}

#[test]
fn alpha_st_separates_full_stick_from_slip() {
    let b = blade();
    let hopts = HbmOptions::default();
    let states = |alpha: f64| -> Vec<ContactState> {
        let cond = CondensedSystem::new(&b.at_level(alpha), 1).unwrap();
        let s = solve_point(&cond, b.omega_stuck, None, &hopts).unwrap();
        s.contact_cycles.iter().flat_map(|c| c.states.clone()).collect()
    };
    assert!(states(1.02 * b.alpha_st).iter().all(|&s| s == ContactState::Stick));
    assert!(states(b.alpha_st / 1.05).iter().any(|&s| s != ContactState::Stick));
}

#[test]
fn own_jacobian_basis_partial_slip() {
    let r = own_basis(1, 10.0, &[4, 20, 40]);
    // In-band + 4 modes: the first harmonic at the tip within 0.1 %, FR and NLR.
    let (fr, nlr) = &r[0];
    assert!(fr.x1 < 1e-3 && nlr.x1 < 1e-3, "X1: FR {:.2e} NLR {:.2e}", fr.x1, nlr.x1);
    assert!(fr.energy < ENERGY_TOL && nlr.energy < ENERGY_TOL, "energy FR {:.2e} NLR {:.2e}", fr.energy, nlr.energy);
    // In-band + 20: the static term too (module doc: X0 at the tip is set by mean friction forces).
    let (fr, nlr) = &r[1];
    for (what, e) in [("FR X0", fr.x0), ("FR X1", fr.x1), ("NLR X0", nlr.x0), ("NLR X1", nlr.x1)] {
        assert!(e < 1e-3, "{what} {e:.2e} >= 0.1 %");
    }
    // A basis spanning every contact coordinate makes NLR exact: X0 and X1 to round-off.
    let (_, full) = &r[2];
    assert!(full.x0 < 1e-6 && full.x1 < 1e-6, "complete NLR: X0 {:.2e} X1 {:.2e}", full.x0, full.x1);
}

/// Per-contact dissipated energy tolerance (relative to the largest FO contact energy).
/// Measured with in-band + 4 modes: 1.0e-2 at alpha_ST / 10 (FR and NLR; the energy of the
/// few slipping nodes carries the same mean-tangential-state error as X0), 3e-3 (FR) and 8e-4
/// (NLR) at alpha_ST / 3000, 4e-3 to 6e-3 for H = 3; twice the worst measured value.
const ENERGY_TOL: f64 = 0.02;

#[test]
fn own_jacobian_basis_gross_slip() {
    let r = own_basis(1, 3000.0, &[4, 20]);
    let (fr, nlr) = &r[0];
    assert!(fr.x1 < 1e-3 && nlr.x1 < 1e-3, "X1: FR {:.2e} NLR {:.2e}", fr.x1, nlr.x1);
    assert!(fr.energy < ENERGY_TOL && nlr.energy < ENERGY_TOL, "energy FR {:.2e} NLR {:.2e}", fr.energy, nlr.energy);
    // In-band + 20: the static term too, FR (band-condensed rows) and NLR.
    let (fr, nlr) = &r[1];
    for (what, e) in [("FR X0", fr.x0), ("FR X1", fr.x1), ("NLR X0", nlr.x0), ("NLR X1", nlr.x1)] {
        assert!(e < 1e-3, "{what} {e:.2e} >= 0.1 %");
    }
}

#[test]
fn own_jacobian_basis_partial_slip_h3() {
    let r = own_basis(3, 10.0, &[4]);
    let (fr, nlr) = &r[0];
    assert!(fr.x1 < 1e-3 && nlr.x1 < 1e-3, "X1: FR {:.2e} NLR {:.2e}", fr.x1, nlr.x1);
    assert!(fr.energy < ENERGY_TOL && nlr.energy < ENERGY_TOL);
}

/// A predicted basis' sizes and its FR and NLR first-harmonic errors at the FO resonance.
#[derive(Debug)]
struct PredictedRow {
    /// JP basis sizes `n_0`, `n_1` (FR's own first-harmonic size is about twice `n_1`).
    n0: usize,
    n1: usize,
    /// Tip X1 error, `e*_1` and `e_1` of FR and NLR.
    fr: (f64, f64, f64),
    nlr: (f64, f64, f64),
}

fn predicted_row(div: f64, gamma: f64, fo: &PointSolution) -> PredictedRow {
    let b = blade();
    let model = b.at_level(b.alpha_st / div);
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let cond = CondensedSystem::new(&model, 1).unwrap();
    let mut popts = PredictionOptions::new(b.band);
    popts.modes.extra_outside = 2;
    popts.gamma = gamma;
    let (basis, _) = predict_basis(&coords, &popts).unwrap();
    let fr = FrRom::new(&coords, &basis).unwrap();
    let nlr = NlrRom::new(&cond, &basis).unwrap();
    let fr_sizes = fr.layout().sizes.clone();
    let eval = |rom: &dyn ReducedModel| -> (f64, f64, f64) {
        let s = solve_point(rom, fo.omega, None, &hopts).unwrap();
        let es = predicted_error(rom, fo.omega, &s.z).unwrap();
        let ea = actual_error(rom, fo.omega, &s.z, fo).unwrap();
        (tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 1), es[1], ea[1])
    };
    let row = PredictedRow { n0: basis.sizes[0], n1: basis.sizes[1], fr: eval(&fr), nlr: eval(&nlr) };
    let ((fx, fes, fe), (nx, nes, ne)) = (row.fr, row.nlr);
    println!("alpha_ST/{div} gamma {gamma:.0e} sizes {:?} (FR {fr_sizes:?}): FR X1 {fx:.2e} e*_1 {fes:.2e} e_1 {fe:.2e} | NLR X1 {nx:.2e} e*_1 {nes:.2e} e_1 {ne:.2e}", basis.sizes);
    row
}

fn fo_resonance(div: f64) -> PointSolution {
    let b = blade();
    let hopts = HbmOptions::default();
    let cond = CondensedSystem::new(&b.at_level(b.alpha_st / div), 1).unwrap();
    full_order_resonance(&cond, &hopts, b.band, None).0
}

/// Acceptance 2 and the first half of 3: predicted bases (stuck mode as generating shape) with
/// gamma 1e2..1e4; the error at resonance falls as the basis grows, and e*_1 >= e_1 on every
/// case (FR and NLR).
#[test]
fn predicted_bases_error_falls_with_size_and_predictor_is_conservative() {
    let fo = fo_resonance(10.0);
    let rows: Vec<_> = [1e2, 1e3, 1e4].iter().map(|&g| predicted_row(10.0, g, &fo)).collect();
    for r in &rows {
        assert!(r.fr.1 + 1e-9 >= r.fr.2, "FR e*_1 {:.2e} < e_1 {:.2e}", r.fr.1, r.fr.2);
        assert!(r.nlr.1 + 1e-9 >= r.nlr.2, "NLR e*_1 {:.2e} < e_1 {:.2e}", r.nlr.1, r.nlr.2);
    }
    for w in rows.windows(2) {
        assert!(w[1].n1 >= w[0].n1, "n_1 grows with gamma");
        assert!(w[1].fr.0 < w[0].fr.0 && w[1].nlr.0 < w[0].nlr.0, "error falls as the basis grows: {:?} -> {:?}", w[0], w[1]);
    }
    // The largest basis is accurate and says so.
    assert!(rows[2].nlr.0 < 1e-3 && rows[2].nlr.1 < 0.05);
}

/// Acceptance 3 at `alpha_ST / div`: the stuck-mode basis (gamma 1e3) is flagged by e*_1
/// (> 0.05, and conservative), and the self-correcting NLR sweep ends with the error it judges
/// by (the linearised error at the resonance and the points of largest e*_1, see
/// `rom::adaptive`) at most 0.05 and X1 at the FO resonance below 1 %. Returns the first
/// basis' row, the sweep and that X1 error.
fn flagged_and_corrected(div: f64) -> (PredictedRow, AdaptiveSweep, f64) {
    let b = blade();
    let fo = fo_resonance(div);
    let first = predicted_row(div, 1e3, &fo);
    assert!(first.nlr.1 > 0.05, "e*_1 {:.2e} should flag the stuck-mode basis", first.nlr.1);
    assert!(first.nlr.1 + 1e-9 >= first.nlr.2);
    let model = b.at_level(b.alpha_st / div);
    let hopts = HbmOptions::default();
    let sopts = SweepOptions { max_step: 0.02, ..SweepOptions::band(b.band.0, b.band.1) };
    let out = adaptive_sweep(&model, 1, &PredictionOptions::new(b.band), &sopts, &hopts, &AdaptiveOptions { kind: RomKind::Nlr, ..Default::default() }).unwrap();
    for c in &out.corrections {
        println!("{:?}: {:.2e} -> {:.2e} {:?}", c.kind, c.worst_error_before, c.worst_error_after, c.sizes);
    }
    assert!(!out.corrections.is_empty(), "the sweep must have corrected its basis");
    let worst = out.predicted_errors.iter().map(|e| e[1]).fold(0.0, f64::max);
    println!("after correction: judged {:.2e}, worst e*_1 {worst:.2e}, checks {:?}", out.worst_error, out.checks);
    assert!(out.worst_error <= 0.05, "judged error after correction {:.2e}", out.worst_error);
    assert!(!out.checks.is_empty() && out.checks.iter().all(|c| c.linearised <= out.worst_error));
    let cond = CondensedSystem::new(&model, 1).unwrap();
    let s = solve_point(&NlrRom::new(&cond, &out.basis).unwrap(), fo.omega, None, &hopts).unwrap();
    let x1 = tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 1);
    println!("alpha_ST/{div}: final sizes {:?} (first {:?}), X1 error {x1:.2e}", out.basis.sizes, (first.n0, first.n1));
    assert!(x1 < 1e-2, "X1 error after correction {x1:.2e}");
    (first, out, x1)
}

/// Acceptance 3: at alpha_ST / 100 the stuck mode is a poor generating shape on this blade;
/// e*_1 flags it, and the self-correcting sweep regenerates from its own reduced solution and
/// brings the first-harmonic error at the FO resonance below 1 % with a basis of similar size.
/// Measured: the modes regenerated from the reduced solution replace the stuck-mode basis,
/// [37, 11] -> [25, 11], judged error 0.16 -> 9.0e-3, X1 1.2e-3 (with Craig-Bampton modes
/// from a Lanczos subspace of 3 instead of 2 x 50, equal to its tolerance: [36, 11] -> [33,
/// 16], 7.0e-3, X1 9.5e-4). Their union with the first basis (the only correction before
/// `Replaced` existed) was [44, 20], and [44, 25] with those modes.
#[test]
fn poor_generating_shape_is_flagged_and_corrected() {
    let (first, out, _) = flagged_and_corrected(100.0);
    assert!(matches!(out.corrections[0].kind, CorrectionKind::Replaced { .. }), "{:?}", out.corrections);
    assert_eq!(out.basis.sizes, out.corrections[0].sizes, "the regenerated modes alone are the basis");
    assert!(out.basis.sizes[1] <= 2 * first.n1, "similar size: n_1 {} from {}", out.basis.sizes[1], first.n1);
}

/// FR's band-condensed rows at H = 3 keep the reduced system smooth enough to continue: a
/// predicted basis at alpha_ST / 10 sweeps on from the band start (with the condensation
/// directions kept down to 1e-10 the sweep stopped after its first point, `StepTooSmall`).
#[test]
fn band_condensed_fr_sweeps_at_h3() {
    let b = blade();
    let model = b.at_level(b.alpha_st / 10.0);
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, 3).unwrap();
    let popts = PredictionOptions::new(b.band);
    let (basis, _) = predict_basis(&coords, &popts).unwrap();
    let fr = FrRom::new(&coords, &basis).unwrap();
    let sopts = SweepOptions { max_step: 0.006, initial_step: 0.006, max_points: 30, ..SweepOptions::band(b.band.0, b.band.1) };
    let sw = jprom::hbm::sweep(&fr, &sopts, &hopts, &mut |_| std::ops::ControlFlow::Continue(())).unwrap();
    println!("H=3 FR sizes {:?}: {} points, end {:?}", fr.layout().sizes, sw.points.len(), sw.end);
    assert_eq!(sw.points.len(), 30, "end {:?}", sw.end);
}

/// Acceptance 3 at gross slip (alpha_ST / 3000): flagged and corrected as above. Measured
/// (judged by the linearised error): one regeneration, 1.17 -> 0.017, n_1 9 -> 15, X1 1.7e-4
/// (e*_1 alone stays at 0.22 at the band edges, where it overstates the error: the linearised
/// error there is 0.017). The result is the best basis found: its judged error is the
/// smallest of all passes.
#[test]
fn gross_slip_is_flagged_and_corrected() {
    let (_, out, _) = flagged_and_corrected(3000.0);
    let best = out.corrections.iter().map(|c| c.worst_error_after).fold(f64::INFINITY, f64::min);
    assert!((out.worst_error - best).abs() <= 1e-12 * best, "kept {:.3e}, best pass {best:.3e}", out.worst_error);
}
