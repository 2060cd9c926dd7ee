//! Save/load through the C API: a model, a solution and a sweep written to versioned JSON and
//! read back give back the same numbers (bit for bit), and a file of the wrong kind is refused.

use crate::*;
use std::ffi::CString;
use std::ptr::{null, null_mut};

unsafe fn ok(s: jprom_status) {
    assert_eq!(s, jprom_status::JPROM_OK, "{}", std::ffi::CStr::from_ptr(jprom_last_error_message()).to_string_lossy());
}

/// Two DoFs on a chain, a Jenkins element from DoF 1 to ground, forcing on DoF 0.
unsafe fn model() -> *mut jprom_model {
    let m = [1.0, 0.0, 0.0, 1.0];
    let k = [2.0e4, -1.0e4, -1.0e4, 1.0e4];
    let mut p = null_mut();
    ok(jprom_model_new(2, m.as_ptr(), k.as_ptr(), &mut p));
    ok(jprom_model_add_jenkins(p, 1, null(), 2.0e4, 0.3, 10.0));
    ok(jprom_model_set_rayleigh_damping(p, 0.0, 2e-4));
    ok(jprom_model_set_harmonic_force(p, 1, [4.0, 0.0].as_ptr(), null(), 2));
    ok(jprom_model_set_output_dofs(p, [0usize, 1].as_ptr(), 2));
    p
}

fn tmp(name: &str) -> CString {
    let dir = std::env::temp_dir().join(format!("jprom-ffi-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    CString::new(dir.join(name).to_str().unwrap()).unwrap()
}

unsafe fn options() -> (jprom_hbm_options, jprom_sweep_options) {
    let mut o = std::mem::zeroed();
    let mut s = std::mem::zeroed();
    ok(jprom_hbm_options_default(&mut o));
    ok(jprom_sweep_options_default(&mut s));
    o.harmonics = 3;
    s.omega_start = 60.0;
    s.omega_end = 200.0;
    (o, s)
}

unsafe fn amplitudes(sol: *const jprom_solution) -> Vec<f64> {
    let (mut h, mut n) = (0, 0);
    ok(jprom_solution_sizes(sol, &mut h, &mut n, null_mut()));
    let mut coeffs = vec![0.0; (2 * h + 1) * n];
    ok(jprom_solution_output_coeffs(sol, coeffs.as_mut_ptr(), coeffs.len()));
    coeffs
}

#[test]
fn model_solution_and_sweep_round_trip() {
    unsafe {
        let m = model();
        let (o, s) = options();
        let path = tmp("model.json");
        ok(jprom_model_save_json(m, path.as_ptr()));
        let mut m2 = null_mut();
        ok(jprom_model_load_json(path.as_ptr(), &mut m2));
        let (mut n, mut nc) = (0, 0);
        ok(jprom_model_n_dof(m2, &mut n));
        ok(jprom_model_n_contacts(m2, &mut nc));
        assert_eq!((n, nc), (2, 1));

        // the reloaded model solves to the same point
        let (mut a, mut b) = (null_mut(), null_mut());
        ok(jprom_solve_point(m, 120.0, &o, &mut a));
        ok(jprom_solve_point(m2, 120.0, &o, &mut b));
        assert_eq!(amplitudes(a), amplitudes(b));

        let sp = tmp("solution.json");
        ok(jprom_solution_save_json(a, sp.as_ptr()));
        let mut a2 = null_mut();
        ok(jprom_solution_load_json(sp.as_ptr(), &mut a2));
        assert_eq!(amplitudes(a), amplitudes(a2));
        let (mut e1, mut e2) = ([0.0], [0.0]);
        ok(jprom_solution_dissipated_energy(a, e1.as_mut_ptr(), 1));
        ok(jprom_solution_dissipated_energy(a2, e2.as_mut_ptr(), 1));
        assert_eq!(e1, e2);

        let mut sw = null_mut();
        ok(jprom_sweep(m, &o, &s, None, null_mut(), &mut sw));
        let wp = tmp("sweep.json");
        ok(jprom_sweep_result_save_json(sw, wp.as_ptr()));
        let mut sw2 = null_mut();
        ok(jprom_sweep_result_load_json(wp.as_ptr(), &mut sw2));
        let (mut n1, mut n2) = (0, 0);
        ok(jprom_sweep_result_n_points(sw, &mut n1));
        ok(jprom_sweep_result_n_points(sw2, &mut n2));
        assert!(n1 > 5);
        assert_eq!(n1, n2);
        for i in 0..n1 {
            let (mut w1, mut w2, mut x1, mut x2) = (0.0, 0.0, 0.0, 0.0);
            ok(jprom_sweep_result_point_omega(sw, i, &mut w1));
            ok(jprom_sweep_result_point_omega(sw2, i, &mut w2));
            ok(jprom_sweep_result_point_amplitude(sw, i, 1, 0, &mut x1));
            ok(jprom_sweep_result_point_amplitude(sw2, i, 1, 0, &mut x2));
            assert_eq!((w1, x1), (w2, x2));
        }

        // kinds are checked: a solution file is not a sweep
        let mut wrong = null_mut();
        // (the data of a solution does not parse as a sweep: PARSE; an envelope of another kind
        // whose data happened to parse would be refused as IO)
        let st = jprom_sweep_result_load_json(sp.as_ptr(), &mut wrong);
        assert!(matches!(st, jprom_status::JPROM_PARSE | jprom_status::JPROM_IO), "{st:?}");
        assert!(!std::ffi::CStr::from_ptr(jprom_last_error_message()).to_bytes().is_empty());
        assert!(wrong.is_null(), "out written on failure");

        for p in [sw, sw2] {
            ok(jprom_sweep_result_free(p));
        }
        for p in [a, b, a2] {
            ok(jprom_solution_free(p));
        }
        ok(jprom_model_free(m));
        ok(jprom_model_free(m2));
    }
}
