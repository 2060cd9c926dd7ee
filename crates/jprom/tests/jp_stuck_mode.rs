//! The stuck mode that generates the predicted boundary conditions (docs/formulation.md §8.8) on a refined
//! blade (refinement 2: 50 contact nodes, 227 CB DoFs). faer 0.24's symmetric eigen solver
//! with vectors returns a NaN eigenvalue on this matrix (its eigenvalue-only path is right);
//! the prediction then picked a mode the forcing does not excite and sampled one amplitude.

use jprom_testkit::blade as blade_support;

use blade_support::*;
use faer::Mat;
use jprom::jp::{predict_basis, stuck_mode, PredictionOptions};
use jprom::model::ContactCoordinates;

#[test]
fn stuck_mode_of_the_refined_blade_is_its_first_bending_mode() {
    let blade = Blade::build_refined(2);
    let model = blade.at_level(blade.alpha_st / 10.0);
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let (omega, phi) = stuck_mode(&coords, blade.band).unwrap();
    // Same frequency as the Craig-Bampton model's own first stuck mode (dense, eigenvalues only).
    assert!((omega / blade.omega_stuck - 1.0).abs() < 1e-8, "stuck mode {omega} vs first bending {}", blade.omega_stuck);
    // And a true eigenvector of (K + stuck springs) phi = omega^2 M phi, in contact coordinates.
    let mut k = coords.stiffness.clone();
    for (law, &off) in coords.laws.iter().zip(&coords.offsets) {
        for (i, ks) in law.stuck_stiffness().into_iter().enumerate() {
            k[(off + i, off + i)] += ks;
        }
    }
    let v = Mat::from_fn(phi.len(), 1, |i, _| phi[i]);
    let kv = &k * &v;
    let r = &kv - &coords.mass * &v * faer::Scale(omega * omega);
    assert!(r.norm_l2() < 1e-8 * kv.norm_l2(), "residual {:e}", r.norm_l2() / kv.norm_l2());

    // The prediction samples a range of amplitudes along it and finds several contact states.
    let mut popts = PredictionOptions::new(blade.band);
    popts.modes.extra_outside = 2;
    let (basis, report) = predict_basis(&coords, &popts).unwrap();
    println!("sizes {:?} patterns {} p {:e}..{:e}", basis.sizes, report.n_patterns, report.p_min, report.p_max);
    assert!(report.p_max > 2.0 * report.p_min, "p_min {:e} p_max {:e}", report.p_min, report.p_max);
    assert!(report.n_patterns > 10, "{} patterns", report.n_patterns);
}
