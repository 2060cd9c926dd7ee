//! The C callback element of issue 18 (`jprom_model_add_element_callback`) driven from Rust
//! with `extern "C"` callbacks: a cubic callback gives the solution of the polynomial spring
//! (another AFT path) to 1e-12; a callback returning 3 ends the solve with
//! `JPROM_CALLBACK_ERROR` and "element k: callback returned 3 at sample j"; a NULL callback,
//! a bad dim and saving such a model are refused.

use crate::*;
use std::ffi::{c_void, CStr};
use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicUsize, Ordering};

unsafe fn ok(s: jprom_status) {
    assert_eq!(s, jprom_status::JPROM_OK, "{}", CStr::from_ptr(jprom_last_error_message()).to_string_lossy());
}

unsafe fn message() -> String {
    CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned()
}

/// `user_data` points to `[k1, k3]`: `F = k1 w + k3 w^3`.
unsafe extern "C" fn cubic(user_data: *mut c_void, dim: usize, w: *const f64, force: *mut f64, jacobian: *mut f64) -> i32 {
    if dim != 1 {
        return 7;
    }
    let k = &*(user_data as *const [f64; 2]);
    let w = *w;
    *force = k[0] * w + k[1] * w * w * w;
    *jacobian = k[0] + 3.0 * k[1] * w * w;
    0
}

/// Counts its calls in `user_data` (an `AtomicUsize`); returns 3 from the 4th call on (the
/// 1st is the stuck stiffness at `w = 0`, made when the element is added).
unsafe extern "C" fn fails_on_fourth(user_data: *mut c_void, _dim: usize, w: *const f64, force: *mut f64, jacobian: *mut f64) -> i32 {
    let calls = &*(user_data as *const AtomicUsize);
    if calls.fetch_add(1, Ordering::SeqCst) + 1 >= 4 {
        return 3;
    }
    *force = 0.8 * *w;
    *jacobian = 0.8;
    0
}

/// 2 DoFs, M = diag(1, 0.5), K = [[1, 0], [0, 0]], damping diag(0.02, 0.01), static and
/// first-harmonic forces.
unsafe fn two_dof() -> *mut jprom_model {
    let m = [1.0, 0.0, 0.0, 0.5];
    let k = [1.0, 0.0, 0.0, 0.0];
    let mut p = null_mut();
    ok(jprom_model_new(2, m.as_ptr(), k.as_ptr(), &mut p));
    ok(jprom_model_set_damping_matrix(p, [0.02, 0.0, 0.0, 0.01].as_ptr(), 2));
    ok(jprom_model_set_static_force(p, [0.1, -0.05].as_ptr(), 2));
    ok(jprom_model_set_harmonic_force(p, 1, [0.3, 0.1].as_ptr(), [0.0, 0.0].as_ptr(), 2));
    ok(jprom_model_set_output_dofs(p, [0usize, 1].as_ptr(), 2));
    p
}

unsafe fn options(h: usize) -> jprom_hbm_options {
    let mut o = std::mem::zeroed::<jprom_hbm_options>();
    ok(jprom_hbm_options_default(&mut o));
    o.harmonics = h;
    o
}

unsafe fn outputs(s: *mut jprom_solution) -> Vec<f64> {
    handle::get(s, "solution").unwrap().point.outputs.clone()
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    d / b.iter().map(|y| y * y).sum::<f64>().sqrt().max(f64::MIN_POSITIVE)
}

#[test]
fn a_cubic_callback_equals_the_polynomial_spring() {
    unsafe {
        let k = [0.8f64, 0.6];
        let poly = two_dof();
        ok(jprom_model_add_polynomial_spring(poly, 1, &0usize, [k[0], 0.0, k[1]].as_ptr(), 3));
        let cb = two_dof();
        ok(jprom_model_add_element_callback(cb, 1, &1usize, &0usize, null(), Some(cubic), &k as *const [f64; 2] as *mut c_void));
        let lin = two_dof();
        ok(jprom_model_add_polynomial_spring(lin, 1, &0usize, [k[0]].as_ptr(), 1));
        let o = options(3);
        let mut worst = 0.0f64;
        for omega in [0.5, 0.9, 1.6] {
            let (mut a, mut b, mut c) = (null_mut(), null_mut(), null_mut());
            ok(jprom_solve_point(poly, omega, &o, &mut a));
            ok(jprom_solve_point(cb, omega, &o, &mut b));
            ok(jprom_solve_point(lin, omega, &o, &mut c));
            let (xa, xb, xc) = (outputs(a), outputs(b), outputs(c));
            let (d, nl) = (rel_diff(&xb, &xa), rel_diff(&xa, &xc));
            println!("w = {omega}: callback vs polynomial {d:.2e}, cubic vs linear {nl:.2e}");
            assert!(nl > 1e-3, "the cubic term has no effect");
            worst = worst.max(d);
            for s in [a, b, c] {
                ok(jprom_solution_free(s));
            }
        }
        assert!(worst < 1e-12, "{worst:.3e}");
        for p in [poly, cb, lin] {
            ok(jprom_model_free(p));
        }
    }
}

#[test]
fn a_callback_error_is_a_status_with_the_element_and_the_sample() {
    unsafe {
        let calls = AtomicUsize::new(0);
        let p = two_dof();
        ok(jprom_model_add_polynomial_spring(p, 0, null(), [0.1].as_ptr(), 1));
        ok(jprom_model_add_element_callback(p, 1, &1usize, &0usize, null(), Some(fails_on_fourth), &calls as *const AtomicUsize as *mut c_void));
        assert_eq!(calls.load(Ordering::SeqCst), 1, "the stuck stiffness is taken once when the element is added");
        let mut s = null_mut();
        let st = jprom_solve_point(p, 0.9, &options(3), &mut s);
        let msg = message();
        println!("{st:?}: {msg}");
        assert_eq!(st, jprom_status::JPROM_CALLBACK_ERROR, "{msg}");
        assert!(s.is_null());
        assert_eq!(msg, "element 1: callback returned 3 at sample 2");
        assert_eq!(CStr::from_ptr(jprom_status_name(12)).to_str().unwrap(), "JPROM_CALLBACK_ERROR");
        ok(jprom_model_free(p));
    }
}

/// A linear law that returns 5 from its 3,000th call on (a few points into a sweep).
unsafe extern "C" fn fails_after_many(user_data: *mut c_void, _dim: usize, w: *const f64, force: *mut f64, jacobian: *mut f64) -> i32 {
    let calls = &*(user_data as *const AtomicUsize);
    if calls.fetch_add(1, Ordering::SeqCst) + 1 >= 3000 {
        return 5;
    }
    *force = 0.8 * *w;
    *jacobian = 0.8;
    0
}

#[test]
fn a_sweep_that_meets_a_callback_error_returns_its_status() {
    unsafe {
        let calls = AtomicUsize::new(0);
        let p = two_dof();
        ok(jprom_model_add_element_callback(p, 1, &1usize, &0usize, null(), Some(fails_after_many), &calls as *const AtomicUsize as *mut c_void));
        let mut so = std::mem::zeroed::<jprom_sweep_options>();
        ok(jprom_sweep_options_init(&mut so, std::mem::size_of::<jprom_sweep_options>()));
        so.omega_start = 0.3;
        so.omega_end = 3.0;
        let mut out = null_mut();
        let st = jprom_sweep(p, &options(3), &so, None, null_mut(), &mut out);
        let msg = message();
        println!("{st:?}: {msg} after {} calls", calls.load(Ordering::SeqCst));
        assert_eq!(st, jprom_status::JPROM_CALLBACK_ERROR, "{msg}");
        assert!(out.is_null(), "nothing is written on an error");
        assert!(msg.starts_with("element 0: callback returned 5 at sample"), "{msg}");
        ok(jprom_model_free(p));
    }
}

#[test]
fn null_callback_bad_dim_bad_frame_and_saving_are_refused() {
    unsafe {
        let k = [1.0f64, 0.5];
        let ud = &k as *const [f64; 2] as *mut c_void;
        let p = two_dof();
        let st = jprom_model_add_element_callback(p, 1, &1usize, &0usize, null(), None, ud);
        assert_eq!(st, jprom_status::JPROM_NULL_ARGUMENT);
        assert!(message().contains("callback"), "{}", message());
        let st = jprom_model_add_element_callback(p, 4, [0usize, 1, 0, 1].as_ptr(), null(), null(), Some(cubic), ud);
        assert_eq!(st, jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("dim"), "{}", message());
        assert_eq!(jprom_model_add_element_callback(p, 1, null(), null(), null(), Some(cubic), ud), jprom_status::JPROM_NULL_ARGUMENT);
        // a frame that is not a rotation: refused by the model checks
        let st = jprom_model_add_element_callback(p, 1, &1usize, &0usize, [0.5].as_ptr(), Some(cubic), ud);
        assert_eq!(st, jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("frame"), "{}", message());
        // a callback failing at w = 0 (cubic() refuses dim 2) is refused when added
        let st = jprom_model_add_element_callback(p, 2, [0usize, 1].as_ptr(), null(), [1.0, 0.0, 0.5, 1.0].as_ptr(), Some(cubic), ud);
        assert_eq!(st, jprom_status::JPROM_CALLBACK_ERROR, "{}", message());
        assert_eq!(message(), "element 0: callback returned 7 (evaluating the stuck stiffness at w = 0) at sample 0");
        assert_eq!(handle::get(p, "model").unwrap().model.contacts.len(), 0);

        ok(jprom_model_add_element_callback(p, 1, &1usize, &0usize, [-1.0].as_ptr(), Some(cubic), ud));
        assert_eq!(handle::get(p, "model").unwrap().model.contacts[0].frame[0][0], -1.0);
        let dir = std::env::temp_dir().join(format!("jprom_cb_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("model.json");
        let cpath = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
        let st = jprom_model_save_json(p, cpath.as_ptr());
        println!("{st:?}: {}", message());
        assert_eq!(st, jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("contacts[0]") && message().contains("cannot be saved"), "{}", message());
        assert!(!path.exists(), "no file may be written");
        std::fs::remove_dir_all(&dir).ok();
        ok(jprom_model_free(p));
    }
}
