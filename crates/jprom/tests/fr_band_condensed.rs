//! The band-condensed FR basis (`rom::band_condensed_basis`, the default rows of `FrRom::new`):
//! its linear-DoF rows are the dynamic condensation of its contact rows at the band edges, so
//! with every contact direction in the basis FR is the condensed full-order system itself at
//! those two frequencies (docs/formulation.md §7), whatever the contact states.

use jprom_testkit::chain as jp_support;

use faer::Mat;
use jp_support::*;
use jprom::error::JpError;
use jprom::rom::error_metric::output_error;
use jprom::hbm::{solve_point, sweep, FullSystem, HarmonicSystem, HbmOptions, PointSolution, SweepOptions};
use std::ops::ControlFlow;
use jprom::jp::JpBasis;
use jprom::model::{ContactCoordinates, Model};
use jprom::rom::{band_condensed_basis, FrRom};

/// The chain (3 ground contacts and a node pair) at a slipping level, and a band around its
/// first stuck mode.
fn case() -> (Model, (f64, f64)) {
    let mut model = chain_model(&ChainOptions::default());
    model.excitation.dynamic_scale = 0.05;
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    (model, (0.97 * freqs[0], 1.01 * freqs[0]))
}

/// `[I_w; 0]` for every harmonic: every contact direction, no linear-DoF information at all.
fn contact_identity(coords: &ContactCoordinates, harmonics: usize, band: (f64, f64)) -> JpBasis {
    let raw: Vec<Mat<f64>> = (0..=harmonics).map(|_| Mat::from_fn(coords.n_dof, coords.n_w, |i, j| if i == j { 1.0 } else { 0.0 })).collect();
    JpBasis::from_raw(&raw, 1e10, 1, coords.n_w).unwrap().with_band(band)
}

/// Full-order solutions at `omegas`, each from the nearest point of a full-order sweep over
/// `band` (the band edges are both in it).
fn full_order(model: &Model, harmonics: usize, hopts: &HbmOptions, band: (f64, f64), omegas: &[f64]) -> Vec<PointSolution> {
    let full = FullSystem::new(model, harmonics).unwrap();
    let sopts = SweepOptions { max_step: 0.02, ..SweepOptions::band(band.0, band.1) };
    let sw = sweep(&full, &sopts, hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    omegas
        .iter()
        .map(|&om| {
            let near = sw.points.iter().min_by(|a, b| (a.omega - om).abs().total_cmp(&(b.omega - om).abs())).unwrap();
            solve_point(&full, om, Some(&near.z), hopts).unwrap()
        })
        .collect()
}

#[test]
fn complete_contact_rows_make_fr_exact_at_the_band_edges() {
    let (model, band) = case();
    for harmonics in [1, 3] {
        let hopts = HbmOptions::default();
        let coords = ContactCoordinates::new(&model, harmonics).unwrap();
        let basis = contact_identity(&coords, harmonics, band);
        let fr = FrRom::new(&coords, &basis).unwrap();
        // Contact directions plus the loads' condensed responses, at two frequencies; the
        // static term has one frequency.
        assert_eq!(fr.layout().sizes[0], coords.n_w + 1, "n_0: the static load adds one column");
        assert!(fr.layout().sizes[1] > coords.n_w && fr.layout().sizes[1] <= 2 * (coords.n_w + 2));
        let omegas = [band.0, band.1, 0.5 * (band.0 + band.1)];
        let fos = full_order(&model, harmonics, &hopts, band, &omegas);
        let mut errors = Vec::new();
        for (&omega, fo) in omegas.iter().zip(&fos) {
            let s = solve_point(&fr, omega, None, &hopts).unwrap();
            let (e0, e1) = (output_error(&s.outputs, &fo.outputs, fo.n_outputs, 0), output_error(&s.outputs, &fo.outputs, fo.n_outputs, 1));
            println!("H={harmonics} omega {omega:.4}: FR sizes {:?} X0 {e0:.2e} X1 {e1:.2e}", fr.layout().sizes);
            errors.push((e0, e1));
        }
        // Exact at the edges (to the full-order solution's own accuracy) ...
        for &(e0, e1) in &errors[..2] {
            assert!(e0 < 1e-7 && e1 < 1e-7, "H={harmonics}: band edge X0 {e0:.2e} X1 {e1:.2e}");
        }
        // ... and inside the band up to the variation of the condensation across it.
        assert!(errors[2].1 < 1e-6, "H={harmonics}: mid-band X1 {:.2e}", errors[2].1);
    }
}

#[test]
fn basis_without_band_keeps_its_rows_and_bad_input_is_refused() {
    let (model, band) = case();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let basis = contact_identity(&coords, 1, band);
    // A basis that does not know its band (from_raw, or a file saved before the field) is
    // projected as it is.
    let no_band = JpBasis { band: None, ..basis.clone() };
    assert_eq!(FrRom::new(&coords, &no_band).unwrap().layout().sizes, vec![coords.n_w, coords.n_w]);
    let json = serde_json::to_value(&basis).unwrap();
    let mut old = json.clone();
    old.as_object_mut().unwrap().remove("band");
    let loaded: JpBasis = serde_json::from_value(old).unwrap();
    assert_eq!(loaded.band, None);
    let round: JpBasis = serde_json::from_value(json).unwrap();
    assert_eq!(round.band, Some(band));

    for bad in [(0.0, 1.0), (2.0, 1.0), (f64::NAN, 1.0), (1.0, f64::INFINITY)] {
        match band_condensed_basis(&coords, &basis, bad) {
            Err(JpError::InvalidValue { .. }) => {}
            other => panic!("band {bad:?}: expected InvalidValue, got {other:?}"),
        }
    }
    let other = ContactCoordinates::new(&chain_model(&ChainOptions { n_nodes: 9, ..ChainOptions::default() }), 1).unwrap();
    assert!(matches!(band_condensed_basis(&other, &basis, band), Err(JpError::BadSize { .. })));
}
