//! JP reduction through the C API: a predicted basis and an NLR/FR sweep give the same numbers
//! as the Rust API, with the error predictor per point.

use faer::Mat;
use jprom::condensation::CondensedSystem;
use jprom::contact::{Contact, ContactLaw, IDENTITY_FRAME};
use jprom::ffi::*;
use jprom::hbm::{sweep, HbmOptions, SweepOptions};
use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::{ContactCoordinates, Damping, Excitation, HarmonicForce, Model};
use jprom::rom::NlrRom;
use std::ops::ControlFlow;

/// A 4-node chain (12 DoFs) on springs, two ground contacts with preload: the same model for
/// the C and the Rust side.
fn parts() -> (usize, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = 12;
    let mut k = vec![0.0; n * n];
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        m[i + i * n] = 1.0;
        k[i + i * n] += 2.0e4;
        if i + 3 < n {
            k[i + i * n] += 1.0e4;
            k[(i + 3) + (i + 3) * n] += 1.0e4;
            k[i + (i + 3) * n] -= 1.0e4;
            k[(i + 3) + i * n] -= 1.0e4;
        }
    }
    let f0: Vec<f64> = (0..n).map(|i| if i % 3 == 2 { -5.0 } else { 0.0 }).collect();
    let f1: Vec<f64> = (0..n).map(|i| if i % 3 == 0 { 1.0 } else { 0.0 }).collect();
    (n, m, k, f0, f1)
}

const LAW: (f64, f64, f64, f64, f64) = (2.0e4, 2.0e4, 3.0e4, 0.3, 10.0);

fn rust_model() -> Model {
    let (n, m, k, f0, f1) = parts();
    let law = ContactLaw::Friction3D { kt1: LAW.0, kt2: LAW.1, kn: LAW.2, mu: LAW.3, n0: LAW.4 };
    let contacts = vec![Contact::ground_3d([6, 7, 8], IDENTITY_FRAME, law.clone()), Contact::ground_3d([9, 10, 11], IDENTITY_FRAME, law)];
    let exc = Excitation { static_force: f0, harmonics: vec![HarmonicForce { cos: f1, sin: vec![0.0; n] }], dynamic_scale: 1.0 };
    Model::new(Mat::from_fn(n, n, |i, j| m[i + j * n]), Mat::from_fn(n, n, |i, j| k[i + j * n]), Damping { mass_coeff: 0.0, stiffness_coeff: 2e-5 }, exc, contacts, vec![0, 9]).unwrap()
}

unsafe fn c_model() -> *mut jprom_model {
    let (n, m, k, f0, f1) = parts();
    let mut model = std::ptr::null_mut();
    assert_eq!(jprom_model_new(n, m.as_ptr(), k.as_ptr(), &mut model), jprom_status::JPROM_OK);
    let frame = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    for a in [[6usize, 7, 8], [9, 10, 11]] {
        assert_eq!(jprom_model_add_contact_3d(model, a.as_ptr(), std::ptr::null(), frame.as_ptr(), LAW.0, LAW.1, LAW.2, LAW.3, LAW.4), jprom_status::JPROM_OK);
    }
    assert_eq!(jprom_model_set_static_force(model, f0.as_ptr(), n), jprom_status::JPROM_OK);
    let zeros = vec![0.0; n];
    assert_eq!(jprom_model_set_harmonic_force(model, 1, f1.as_ptr(), zeros.as_ptr(), n), jprom_status::JPROM_OK);
    assert_eq!(jprom_model_set_rayleigh_damping(model, 0.0, 2e-5), jprom_status::JPROM_OK);
    let outs = [0usize, 9];
    assert_eq!(jprom_model_set_output_dofs(model, outs.as_ptr(), 2), jprom_status::JPROM_OK);
    model
}

#[test]
fn rom_sweep_through_c_matches_the_rust_api() {
    let band = (80.0, 200.0);
    // Rust
    let model = rust_model();
    let hopts = HbmOptions::with_harmonics(1);
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let mut p = PredictionOptions::new(band);
    p.gamma = 1e3;
    p.n_samples = 30;
    let (basis, _) = predict_basis(&coords, &p).unwrap();
    let cond = CondensedSystem::new(&model, &hopts).unwrap();
    let rom = NlrRom::new(&cond, &basis).unwrap();
    let expect = sweep(&rom, &SweepOptions::band(band.0, band.1), &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    unsafe {
        let m = c_model();
        let mut opts = std::mem::zeroed();
        let mut sopts = std::mem::zeroed();
        jprom_hbm_options_default(&mut opts);
        jprom_sweep_options_default(&mut sopts);
        sopts.omega_start = band.0;
        sopts.omega_end = band.1;
        let mut b = std::ptr::null_mut();
        assert_eq!(jprom_basis_predict(m, &opts, band.0, band.1, 1e3, 30, &mut b), jprom_status::JPROM_OK);
        let mut sizes = [0usize; 2];
        let mut hh = 0;
        assert_eq!(jprom_basis_sizes(b, sizes.as_mut_ptr(), 2, &mut hh), jprom_status::JPROM_OK);
        assert_eq!(sizes.to_vec(), basis.sizes);
        assert_eq!(jprom_basis_sizes(b, sizes.as_mut_ptr(), 1, &mut hh), jprom_status::JPROM_BAD_SIZE);
        let mut s = std::ptr::null_mut();
        assert_eq!(jprom_rom_sweep(m, b, 7, &opts, &sopts, None, std::ptr::null_mut(), &mut s), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_rom_sweep(m, b, JPROM_ROM_NLR, &opts, &sopts, None, std::ptr::null_mut(), &mut s), jprom_status::JPROM_OK);
        let mut n = 0;
        jprom_sweep_n_points(s, &mut n);
        assert_eq!(n, expect.points.len());
        for (i, p) in expect.points.iter().enumerate() {
            let (mut w, mut a, mut e) = (0.0, 0.0, 0.0);
            jprom_sweep_point_omega(s, i, &mut w);
            jprom_sweep_point_amplitude(s, i, 1, 1, &mut a);
            assert_eq!(jprom_sweep_point_predicted_error(s, i, 1, &mut e), jprom_status::JPROM_OK);
            assert_eq!(w, p.omega);
            assert_eq!(a, p.output_amplitude(1, 1));
            assert!(e.is_finite() && e >= 0.0);
        }
        jprom_sweep_free(s);
        // a full-order sweep has no predicted error
        let mut fo = std::ptr::null_mut();
        assert_eq!(jprom_sweep(m, &opts, &sopts, None, std::ptr::null_mut(), &mut fo), jprom_status::JPROM_OK);
        let mut e = 0.0;
        assert_eq!(jprom_sweep_point_predicted_error(fo, 0, 1, &mut e), jprom_status::JPROM_INVALID_VALUE);
        // FR runs too
        let mut fr = std::ptr::null_mut();
        assert_eq!(jprom_rom_sweep(m, b, JPROM_ROM_FR, &opts, &sopts, None, std::ptr::null_mut(), &mut fr), jprom_status::JPROM_OK);
        jprom_sweep_free(fr);
        jprom_sweep_free(fo);
        jprom_basis_free(b);
        assert_eq!(jprom_basis_free(b), jprom_status::JPROM_INVALID_HANDLE);
        jprom_model_free(m);
    }
}
