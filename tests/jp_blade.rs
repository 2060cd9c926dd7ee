//! JP on the built-in blade (issue 5 acceptance; method.md §11): Craig-Bampton with 50 modes,
//! 18 node-to-ground contacts, band 2140-2190 Hz around the stuck first bending mode (2165 Hz).
//!
//! `alpha_ST` is found from the linear stuck response (tests/blade_support::alpha_stuck) and
//! checked here against the nonlinear solution. Bases from the full-order (FO) solution's own
//! contact Jacobian at resonance are compared with the FO (condensed) solution at
//! `alpha_ST / 10` (partial slip) and `alpha_ST / 3000` (gross slip).
//!
//! What the 0.1 % acceptance takes on this blade (measured, see the report): the first
//! harmonic X1 at the tip is within 0.1 % with the in-band JP modes plus the 4 nearest ones
//! (NLR at both levels, FR at alpha_ST / 10; FR at gross slip stays near 1 %). The static
//! term X0 at the tip is NOT within 0.1 % unless the basis spans all contact coordinates: X0
//! there is a small quantity (2e-4 mm against 3e-3 mm for X1) set by the mean tangential
//! forces of slipping nodes, which depend on the parts of the contact motion the in-band
//! modes leave out (errors 0.13 at alpha_ST / 10, order 1 at gross slip, where the mean
//! tangential position is nearly indeterminate).

#[path = "blade_support/mod.rs"]
mod blade_support;

use blade_support::*;
use jprom::aft::{evaluate_contacts, AftPlan, ContactForces};
use jprom::condensation::CondensedSystem;
use jprom::contact::ContactState;
use jprom::error_metric::{actual_error, full_order_contact_displacement, predicted_error, reduced_contact_cycles};
use jprom::hbm::{solve_point, HbmOptions, PointSolution, SweepOptions};
use jprom::jp::{BasisOptions, ContactJacobian, JpBasis, ModeOptions};
use jprom::model::ContactCoordinates;
use jprom::rom::{FrRom, NlrRom, ReducedModel};
use std::sync::OnceLock;

fn blade() -> &'static Blade {
    static B: OnceLock<Blade> = OnceLock::new();
    B.get_or_init(Blade::build)
}

struct Outcome {
    x0: f64,
    x1: f64,
    e_star: f64,
    e: f64,
    energy: f64,
}

/// Basis from the FO solution's own `K̂`, FR and NLR solved at the FO resonance frequency.
fn own_basis(harmonics: usize, div: f64, extra: usize) -> (Outcome, Outcome) {
    let b = blade();
    let model = b.at_level(b.alpha_st / div);
    let hopts = HbmOptions::with_harmonics(harmonics);
    let cond = CondensedSystem::new(&model, &hopts).unwrap();
    let sopts = SweepOptions { max_step: if harmonics == 1 { 0.02 } else { 0.05 }, ..SweepOptions::band(b.band.0, b.band.1) };
    let (fo, _) = full_order_resonance(&cond, &hopts, b.band, Some(sopts));
    let coords = ContactCoordinates::new(&model, harmonics).unwrap();
    let plan = AftPlan::new(harmonics, hopts.nt()).unwrap();
    let w = full_order_contact_displacement(&fo, coords.n_w).unwrap();
    let mut forces = ContactForces::default();
    evaluate_contacts(&plan, &coords.laws, &coords.offsets, coords.n_w, &w, true, false, &mut forces);
    let k_hat = ContactJacobian::from_forces(&coords.laws, &coords.offsets, coords.n_w, harmonics, &forces, &w).unwrap();
    let opts = BasisOptions { modes: ModeOptions { band: b.band, extra_outside: extra, static_correction: true, solver: jprom::jp::EigenSolver::Auto }, gamma: 1e10 };
    let basis = JpBasis::from_jacobian(&coords, &k_hat, &opts).unwrap();
    let fr = FrRom::new(&coords, &basis).unwrap();
    let nlr = NlrRom::new(&cond, &basis).unwrap();
    let run = |rom: &dyn ReducedModel, name: &str| -> Outcome {
        let s = solve_point(rom, fo.omega, None, &hopts).unwrap();
        let es = predicted_error(rom, &plan, fo.omega, &s.z).unwrap();
        let ea = actual_error(rom, &plan, fo.omega, &s.z, &fo).unwrap();
        let o = Outcome {
            x0: tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 0),
            x1: tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 1),
            e_star: es[1],
            e: ea[1],
            energy: energy_error(rom, &s, &fo, &plan),
        };
        println!(
            "H={harmonics} alpha_ST/{div} extra {extra} {name} sizes {:?}: X0 {:.2e} X1 {:.2e} e*_1 {:.2e} e_1 {:.2e} energy {:.2e}",
            rom.layout().sizes, o.x0, o.x1, o.e_star, o.e, o.energy
        );
        // The predictor is conservative (round-off allowance for exact bases).
        assert!(o.e_star + 1e-9 >= o.e, "{name}: e*_1 {:.3e} < e_1 {:.3e}", o.e_star, o.e);
        o
    };
    (run(&fr, "FR"), run(&nlr, "NLR"))
}

/// Largest per-contact difference of the energy dissipated per cycle, over the largest FO
/// contact energy.
fn energy_error(rom: &dyn ReducedModel, s: &PointSolution, fo: &PointSolution, plan: &AftPlan) -> f64 {
    let cy = reduced_contact_cycles(rom, plan, s.omega, &s.z).unwrap();
    let wmax = fo.contact_cycles.iter().map(|c| c.dissipated_energy.abs()).fold(0.0, f64::max);
    cy.iter().zip(&fo.contact_cycles).map(|(a, b)| (a.dissipated_energy - b.dissipated_energy).abs()).fold(0.0, f64::max) / wmax
}

#[test]
fn alpha_st_separates_full_stick_from_slip() {
    let b = blade();
    let hopts = HbmOptions::with_harmonics(1);
    let states = |alpha: f64| -> Vec<ContactState> {
        let cond = CondensedSystem::new(&b.at_level(alpha), &hopts).unwrap();
        let s = solve_point(&cond, b.omega_stuck, None, &hopts).unwrap();
        s.contact_cycles.iter().flat_map(|c| c.states.clone()).collect()
    };
    assert!(states(1.02 * b.alpha_st).iter().all(|&s| s == ContactState::Stick));
    assert!(states(b.alpha_st / 1.05).iter().any(|&s| s != ContactState::Stick));
}

#[test]
fn own_jacobian_basis_partial_slip() {
    let (fr, nlr) = own_basis(1, 10.0, 4);
    assert!(fr.x1 < 1e-3 && nlr.x1 < 1e-3, "X1: FR {:.2e} NLR {:.2e}", fr.x1, nlr.x1);
    // Known gap (module doc): X0 is not within 0.1 %; guard the measured level.
    assert!(fr.x0 < 0.2 && nlr.x0 < 0.2);
    // Dissipated energy per contact node.
    assert!(fr.energy < ENERGY_TOL && nlr.energy < ENERGY_TOL, "energy FR {:.2e} NLR {:.2e}", fr.energy, nlr.energy);
    // A basis spanning every contact coordinate makes NLR exact: X0 and X1 to round-off.
    let (_, full) = own_basis(1, 10.0, 40);
    assert!(full.x0 < 1e-6 && full.x1 < 1e-6, "complete NLR: X0 {:.2e} X1 {:.2e}", full.x0, full.x1);
}

/// Per-contact dissipated energy tolerance (relative to the largest FO contact energy).
/// Measured with in-band + 4 modes: 1.0e-2 at alpha_ST / 10 (FR and NLR; the energy of the
/// few slipping nodes carries the same mean-tangential-state error as X0), 3e-3 (FR) and 8e-4
/// (NLR) at alpha_ST / 3000, 4e-3 to 6e-3 for H = 3; twice the worst measured value.
const ENERGY_TOL: f64 = 0.02;

#[test]
fn own_jacobian_basis_gross_slip() {
    let (fr, nlr) = own_basis(1, 3000.0, 4);
    assert!(nlr.x1 < 1e-3, "NLR X1 {:.2e}", nlr.x1);
    // FR at gross slip: about 1 % (known gap).
    assert!(fr.x1 < 2e-2, "FR X1 {:.2e}", fr.x1);
    assert!(fr.energy < ENERGY_TOL && nlr.energy < ENERGY_TOL, "energy FR {:.2e} NLR {:.2e}", fr.energy, nlr.energy);
}

#[test]
fn own_jacobian_basis_partial_slip_h3() {
    let (fr, nlr) = own_basis(3, 10.0, 4);
    assert!(nlr.x1 < 1e-3, "NLR X1 {:.2e}", nlr.x1);
    assert!(fr.x1 < 1e-2, "FR X1 {:.2e}", fr.x1);
    assert!(fr.energy < ENERGY_TOL && nlr.energy < ENERGY_TOL);
}
