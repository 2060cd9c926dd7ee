//! `JpBasis::from_solution` (the basis of a full-order solution's own contact Jacobian) is the
//! basis tests/rom_reproduce.rs builds by hand (AFT Jacobian at the solution's `w`, then
//! `from_jacobian`), for a full and a condensed full-order solution, and refuses solutions that
//! are not full-order.

use jprom_testkit::chain as jp_support;

use jp_support::*;
use jprom::aft::{evaluate_contacts, AftPlan, ContactForces};
use jprom::condensation::CondensedSystem;
use jprom::rom::error_metric::full_order_contact_displacement;
use jprom::hbm::{solve_point, FullSystem, HbmOptions, PointSolution};
use jprom::jp::{BasisOptions, ContactJacobian, JpBasis, ModeOptions};
use jprom::model::{ContactCoordinates, Model};
use jprom::hbm::HarmonicSystem;
use jprom::rom::NlrRom;
use jprom::JpError;

fn by_hand(coords: &ContactCoordinates, fo: &PointSolution, plan: &AftPlan, opts: &BasisOptions) -> JpBasis {
    let w = full_order_contact_displacement(fo, coords.n_w).unwrap();
    let mut forces = ContactForces::default();
    evaluate_contacts(plan, &coords.laws, &coords.offsets, coords.n_w, &w, true, false, &mut forces);
    let k_hat = ContactJacobian::from_forces(&coords.laws, &coords.offsets, coords.n_w, plan.harmonics(), &forces, &w).unwrap();
    JpBasis::from_jacobian(coords, &k_hat, opts).unwrap()
}

fn setup(harmonics: usize) -> (Model, HbmOptions, ContactCoordinates, f64, BasisOptions) {
    let mut model = chain_model(&ChainOptions::default());
    model.excitation.dynamic_scale = 0.05;
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, harmonics).unwrap();
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    let mut modes = ModeOptions::in_band((0.9 * freqs[0], 1.02 * freqs[0]));
    modes.extra_outside = 4;
    (model, hopts, coords, 0.95 * freqs[0], BasisOptions { modes, gamma: 1e3 })
}

#[test]
fn from_solution_is_the_own_jacobian_basis() {
    for harmonics in [1, 3] {
        let (model, hopts, coords, omega, opts) = setup(harmonics);
        let plan = AftPlan::new(harmonics, jprom::hbm::default_nt(harmonics)).unwrap();
        let full = solve_point(&FullSystem::new(&model, harmonics).unwrap(), omega, None, &hopts).unwrap();
        let condensed = solve_point(&CondensedSystem::new(&model, harmonics).unwrap(), omega, None, &hopts).unwrap();
        for fo in [&full, &condensed] {
            let got = JpBasis::from_solution(&coords, fo, &opts).unwrap();
            assert_eq!(got, by_hand(&coords, fo, &plan, &opts), "H = {harmonics}, {} unknowns", fo.layout.sizes[0]);
            assert!(got.sizes[1] > 0);
        }
    }
}

#[test]
fn from_solution_refuses_other_solutions() {
    let (model, hopts, coords, omega, opts) = setup(1);
    let fo = solve_point(&FullSystem::new(&model, 1).unwrap(), omega, None, &hopts).unwrap();
    // a reduced solution: unknowns per harmonic are the basis sizes
    let basis = JpBasis::from_solution(&coords, &fo, &opts).unwrap();
    let rom = NlrRom::new(&CondensedSystem::new(&model, 1).unwrap(), &basis).unwrap();
    let reduced = solve_point(&rom, omega, None, &hopts).unwrap();
    assert_eq!(reduced.layout.sizes, rom.layout().sizes);
    assert!(matches!(JpBasis::from_solution(&coords, &reduced, &opts), Err(JpError::BadSize { .. })));
    // another H than the coordinates'
    let coords3 = jprom::model::ContactCoordinates::new(&model, 3).unwrap();
    assert!(matches!(JpBasis::from_solution(&coords3, &fo, &opts), Err(JpError::InvalidValue { .. })));
}
