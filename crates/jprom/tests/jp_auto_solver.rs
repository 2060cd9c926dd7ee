//! `EigenSolver::Auto` between `AUTO_SHIFT_INVERT_MIN` and `AUTO_DENSE_MAX` (docs/formulation.md
//! §8.3): a bounded shift-invert attempt, the dense solve where the band holds more modes. Either
//! way the prediction gives the dense solver's basis: on the demo blade (a few modes near the
//! band, the attempt succeeds) and on a chain whose band holds dozens of modes (it falls back).

use jprom::jp::mode_selection::{AUTO_DENSE_MAX, AUTO_SHIFT_INVERT_MIN};
use jprom::jp::{predict_basis, EigenSolver, PredictionOptions};
use jprom::model::{ContactCoordinates, Model};
use jprom_testkit::blade::Blade;
use jprom_testkit::chain::{chain_model, ChainOptions};
use std::f64::consts::PI;

fn same_basis_as_dense(model: &Model, band: (f64, f64), label: &str) {
    let coords = ContactCoordinates::new(model, 1).unwrap();
    let dim = 2 * coords.n_dof;
    assert!((AUTO_SHIFT_INVERT_MIN..=AUTO_DENSE_MAX).contains(&dim), "{label}: 2 H n = {dim} is outside the attempt's range");
    let basis = |solver: EigenSolver| {
        let mut p = PredictionOptions::new(band);
        p.modes.solver = solver;
        predict_basis(&coords, &p).unwrap()
    };
    let (dense, dr) = basis(EigenSolver::Dense);
    let (auto, ar) = basis(EigenSolver::Auto);
    println!("{label}: 2 H n = {dim}, {} patterns, dense {:?}, Auto {:?}", dr.n_patterns, dense.sizes, auto.sizes);
    assert_eq!(dr.n_patterns, ar.n_patterns, "{label}");
    assert_eq!(dense.sizes, auto.sizes, "{label}");
    assert!(auto.spans_the_same(&dense, 1e-6), "{label}: Auto's basis differs from the dense one");
}

#[test]
fn auto_gives_the_dense_basis_where_the_band_holds_few_modes() {
    let blade = Blade::build();
    same_basis_as_dense(&blade.at_level(blade.alpha_st / 3000.0), (2.0 * PI * 1620.0, 2.0 * PI * 2200.0), "demo blade");
}

#[test]
fn auto_gives_the_dense_basis_where_the_band_holds_many_modes() {
    // 60 nodes, 180 DoFs: the band keeps dozens of modes, beyond the attempt's 16 eigenpairs
    let model = chain_model(&ChainOptions { n_nodes: 60, ..Default::default() });
    same_basis_as_dense(&model, (0.2, 3.0), "chain");
}
