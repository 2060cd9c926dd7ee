//! `dD/domega` and `df/domega` of the condensed systems in closed form (docs/formulation.md §7,
//! `HarmonicSystem::linear_part_with_derivative_into`) against a central difference of their
//! linear parts: the condensed full order and the projected condensation of the NLR model, at
//! H = 1 and 3, with Rayleigh damping and a structural loss factor, on a chain with linear DoFs
//! and on the built-in blade's Craig-Bampton model. The continuation's `dR/domega` uses it.

use faer::Mat;
use jprom::condensation::CondensedSystem;
use jprom::hbm::continuation::residual_omega_derivative;
use jprom::hbm::residual::linear_residual;
use jprom::hbm::{HarmonicSystem, LinearPart};
use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::{ContactCoordinates, Model};
use jprom::rom::NlrRom;
use jprom_testkit::chain::{chain_model, ChainOptions};
use rand::{rngs::StdRng, Rng, SeedableRng};

fn rel(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    (a - b).norm_l2() / b.norm_l2().max(f64::MIN_POSITIVE)
}

fn relv(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    d / b.iter().map(|y| y * y).sum::<f64>().sqrt().max(f64::MIN_POSITIVE)
}

/// The closed-form derivative of `system` at `omega` against the central difference of its
/// linear part with step `1e-5 omega`; returns the worst relative difference.
fn check(system: &dyn HarmonicSystem, omega: f64, label: &str) -> f64 {
    let (mut lin, mut d) = (None, None);
    assert!(system.linear_part_with_derivative_into(omega, &mut lin, &mut d).unwrap(), "{label}: no closed form");
    let (lin, d): (LinearPart, LinearPart) = (lin.unwrap(), d.unwrap());
    // the linear part itself is the one linear_part gives
    let plain = system.linear_part(omega).unwrap();
    for h in 0..plain.dh_re.len() {
        assert!(rel(&lin.dh_re[h].to_dense(), &plain.dh_re[h].to_dense()) < 1e-14, "{label}: linear part changed");
    }
    let delta = 1e-5 * omega;
    let (p, m) = (system.linear_part(omega + delta).unwrap(), system.linear_part(omega - delta).unwrap());
    let fd = |a: &Mat<f64>, b: &Mat<f64>| (a - b) * faer::Scale(0.5 / delta);
    let fdv = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y) * 0.5 / delta).collect::<Vec<f64>>();
    assert_eq!(d.d0.to_dense().norm_l2(), 0.0, "{label}: the static term depends on omega?");
    assert!(d.f0.iter().all(|&x| x == 0.0));
    let mut worst = 0.0f64;
    for h in 0..plain.dh_re.len() {
        let e_re = rel(&d.dh_re[h].to_dense(), &fd(&p.dh_re[h].to_dense(), &m.dh_re[h].to_dense()));
        let e_im = rel(&d.dh_im[h].to_dense(), &fd(&p.dh_im[h].to_dense(), &m.dh_im[h].to_dense()));
        let fc = fdv(&p.fh_cos[h], &m.fh_cos[h]);
        let fs = fdv(&p.fh_sin[h], &m.fh_sin[h]);
        // a force without linear-DoF part does not depend on omega: both zero then
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let e_fc = if norm(&fc) == 0.0 { norm(&d.fh_cos[h]) } else { relv(&d.fh_cos[h], &fc) };
        let e_fs = if norm(&fs) == 0.0 { norm(&d.fh_sin[h]) } else { relv(&d.fh_sin[h], &fs) };
        println!("{label} omega {omega:.4e} h {}: re {e_re:.1e} im {e_im:.1e} f_cos {e_fc:.1e} f_sin {e_fs:.1e}", h + 1);
        worst = worst.max(e_re).max(e_im).max(e_fc).max(e_fs);
    }
    worst
}

fn with_loss_factor(mut model: Model, eta: f64) -> Model {
    model.loss_factor = eta;
    model.validate().unwrap();
    model
}

#[test]
fn condensed_derivatives_equal_central_differences_on_a_chain() {
    for (harmonics, eta) in [(1usize, 0.0), (3, 0.02)] {
        let model = with_loss_factor(chain_model(&ChainOptions { n_nodes: 10, ..Default::default() }), eta);
        let cond = CondensedSystem::new(&model, harmonics).unwrap();
        let nw = cond.coordinates().n_w;
        assert!(cond.coordinates().n_dof > nw, "the model needs linear DoFs");
        let mut rng = StdRng::seed_from_u64(5 + harmonics as u64);
        let bases: Vec<Mat<f64>> = (0..=harmonics).map(|h| Mat::from_fn(nw, 2 + h, |_, _| rng.gen_range(-1.0..1.0))).collect();
        let nlr = NlrRom::new(&cond, &jprom::jp::JpBasis::from_raw(&bases.iter().map(|b| {
            // rows beyond the contact coordinates are not used by NLR: zero
            let n = cond.coordinates().n_dof;
            Mat::from_fn(n, b.ncols(), |i, j| if i < nw { b[(i, j)] } else { 0.0 })
        }).collect::<Vec<_>>(), 1e12, 1, nw).unwrap()).unwrap();
        for omega in [0.3, 1.1, 2.7] {
            let e = check(&cond, omega, &format!("condensed H={harmonics} eta={eta}"));
            assert!(e < 1e-6, "condensed H = {harmonics}, omega {omega}: {e:.2e}");
            let e = check(&nlr, omega, &format!("NLR H={harmonics} eta={eta}"));
            assert!(e < 1e-6, "NLR H = {harmonics}, omega {omega}: {e:.2e}");
        }
    }
}

/// On the blade's CB model: the continuation's `dR/domega` from the closed form equals
/// `residual_omega_derivative` (central difference) at random unknowns, for the condensed full
/// order and an NLR model of a predicted basis.
#[test]
fn residual_omega_derivative_in_closed_form_on_the_blade() {
    let blade = jprom_testkit::blade::Blade::build();
    let model = blade.at_level(blade.alpha_st / 20.0);
    let band = (2.0 * std::f64::consts::PI * 2100.0, 2.0 * std::f64::consts::PI * 2200.0);
    let cond = CondensedSystem::new(&model, 1).unwrap();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let (basis, _) = predict_basis(&coords, &PredictionOptions::new(band)).unwrap();
    let nlr = NlrRom::new(&cond, &basis).unwrap();
    let mut rng = StdRng::seed_from_u64(3);
    for (system, label) in [(&cond as &dyn HarmonicSystem, "condensed"), (&nlr as &dyn HarmonicSystem, "NLR")] {
        for omega in [band.0, 0.5 * (band.0 + band.1), band.1] {
            let z: Vec<f64> = (0..system.layout().total()).map(|_| rng.gen_range(-1e-3..1e-3)).collect();
            let (mut lin, mut d) = (None, None);
            assert!(system.linear_part_with_derivative_into(omega, &mut lin, &mut d).unwrap());
            let closed = linear_residual(system.layout(), &d.unwrap(), &z);
            let fd = residual_omega_derivative(system, omega, &z, 1e-6 * omega).unwrap();
            let e = relv(&closed, &fd);
            println!("{label} at {:.1} Hz: |dR/domega| {:.3e}, closed form vs central difference {e:.1e}", omega / (2.0 * std::f64::consts::PI), fd.iter().map(|x| x * x).sum::<f64>().sqrt());
            assert!(e < 1e-6, "{label} at omega {omega}: {e:.2e}");
            let e = check(system, omega, label);
            assert!(e < 1e-5, "{label} at omega {omega}: {e:.2e}");
        }
    }
}

/// `CondensedSystem::linear_residual_parts` (one right-hand side per harmonic, NLR's `f*_C`)
/// equals `H_h q_h - g_h` from the condensed linear part, H = 1 and 3, with a loss factor.
#[test]
fn linear_residual_parts_equal_the_condensed_linear_part_times_q() {
    for (harmonics, eta) in [(1usize, 0.0), (3, 0.02)] {
        let model = with_loss_factor(chain_model(&ChainOptions { n_nodes: 10, ..Default::default() }), eta);
        let cond = CondensedSystem::new(&model, harmonics).unwrap();
        let mut rng = StdRng::seed_from_u64(17);
        let q: Vec<f64> = (0..cond.layout().total()).map(|_| rng.gen_range(-1.0..1.0)).collect();
        for omega in [0.3, 1.1, 2.7] {
            let parts = cond.linear_residual_parts(omega, &q).unwrap();
            let whole = linear_residual(cond.layout(), &cond.linear_part(omega).unwrap(), &q);
            let joined: Vec<f64> = parts.concat();
            let e = relv(&joined, &whole);
            assert!(e < 1e-12, "H = {harmonics}, omega {omega}: {e:.2e}");
        }
        assert!(cond.linear_residual_parts(1.0, &q[1..]).is_err());
    }
}
