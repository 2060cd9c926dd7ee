//! The built-in blade: size, contacts, loads, and the stuck first-bending frequency of its
//! Craig-Bampton model (with contact springs) in the paper's 2.1-2.2 kHz range.

use jprom::fe::{BladeParams, BuiltinBlade};
use jprom::contact::ContactLaw;

#[test]
fn default_blade_stuck_first_bending_is_near_2150_hz() {
    let fe = BuiltinBlade::build(&BladeParams::default()).unwrap();
    assert!(fe.n_dof() > 18_000 && fe.n_dof() < 25_000, "{} DoFs", fe.n_dof());
    assert_eq!(fe.contacts.len(), 18);
    assert_eq!(fe.output_dofs.len(), 27);
    // Preload: 300 N per patch, held by friction mu = 0.4 (linear stuck static solution).
    for f in fe.stuck_patch_forces {
        assert!((f - 300.0).abs() < 1e-6, "{f}");
    }
    assert!(fe.stuck_max_friction_ratio < 0.4, "{}", fe.stuck_max_friction_ratio);
    let cb = fe.reduce(50).unwrap();
    let f = cb.natural_frequencies_hz(true).unwrap();
    eprintln!("stuck CB frequencies (Hz): {:?}", &f[..4]);
    assert!(f[0] > 2100.0 && f[0] < 2200.0, "stuck first bending {} Hz", f[0]);
    // Independent check: the full sparse model with the same springs (Lanczos).
    let full = fe.natural_frequencies_hz(1, true).unwrap();
    assert!((full[0] - f[0]).abs() / full[0] < 1e-3, "full {} vs CB {}", full[0], f[0]);
    // The mode is flap bending: the first-harmonic (y) load does work on it.
    let m = cb.to_model(jprom::model::Damping::default()).unwrap();
    assert_eq!(m.n_dof(), 54 + 27 + 50);
}

#[test]
fn refinement_scales_contacts_and_keeps_patch_stiffness() {
    let base = BladeParams { n_span: 18, n_chord: 4, n_thickness: 2, n_shroud_gap: 2, ..Default::default() };
    let fine = BladeParams { refinement: 3, ..base.clone() };
    let a = BuiltinBlade::build(&base).unwrap();
    let b = BuiltinBlade::build(&fine).unwrap();
    assert_eq!(b.contacts.len(), 2 * 49);
    let total = |fe: &jprom::fe::BladeFe| match fe.contact_law {
        ContactLaw::Friction3D { kt1, kt2, kn, .. } => {
            let n = fe.contacts.len() as f64 / 2.0;
            [kt1 * n, kt2 * n, kn * n]
        }
        _ => unreachable!(),
    };
    let (ta, tb) = (total(&a), total(&b));
    for q in 0..3 {
        assert!((ta[q] - tb[q]).abs() < 1e-9 * ta[q]);
    }
    assert!((ta[2] - 9.0 * 2.34152e4).abs() < 1e-6);
    // Only the shroud is refined: the blade's element count is unchanged.
    let blade_elems = 18 * 4 * 2;
    assert!(b.n_elements - blade_elems > a.n_elements - blade_elems);
    // Frames: orthonormal, right-handed, normal along -x / +x.
    for c in &b.contacts {
        let [t1, t2, n] = c.frame;
        let cross = [t1[1] * t2[2] - t1[2] * t2[1], t1[2] * t2[0] - t1[0] * t2[2], t1[0] * t2[1] - t1[1] * t2[0]];
        for q in 0..3 {
            assert!((cross[q] - n[q]).abs() < 1e-15);
        }
        let x = b.coords[c.node][0];
        assert!(n[0] * x > 0.0, "normal points out of the face into the ground");
    }
}

#[test]
fn bad_parameters_are_errors() {
    let p = BladeParams { n_chord: 3, ..Default::default() };
    assert!(BuiltinBlade::build(&p).is_err());
    let p = BladeParams { thickness: -1.0, ..Default::default() };
    assert!(BuiltinBlade::build(&p).is_err());
    let p = BladeParams { refinement: 0, ..Default::default() };
    assert!(BuiltinBlade::build(&p).is_err());
}
