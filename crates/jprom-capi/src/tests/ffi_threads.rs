//! Two threads solving two models at once through the C API get the same results as the
//! same solves run one after the other (issue 3, acceptance 3); error messages stay per thread.

use crate::*;
use std::ffi::CStr;

/// A 6-DoF model with one friction contact, built through the C API; `scale` varies the forcing.
unsafe fn build(scale: f64) -> *mut jprom_model {
    let n = 6usize;
    let mut m = vec![0.0; n * n];
    let mut k = vec![0.0; n * n];
    for d in 0..3 {
        let (a, b) = (d, 3 + d);
        m[a + a * n] = 1.0;
        m[b + b * n] = 1.0;
        k[a + a * n] = 2.0e4;
        k[b + b * n] = 1.0e4;
        k[a + b * n] = -1.0e4;
        k[b + a * n] = -1.0e4;
    }
    let mut model = std::ptr::null_mut();
    assert_eq!(jprom_model_new(n, m.as_ptr(), k.as_ptr(), &mut model), jprom_status::JPROM_OK);
    let frame = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let a = [3usize, 4, 5];
    assert_eq!(jprom_model_add_contact_3d(model, a.as_ptr(), std::ptr::null(), frame.as_ptr(), 3e4, 3e4, 5e4, 0.5, 20.0), jprom_status::JPROM_OK);
    let fc = [5.0 * scale, 0.0, 1.0 * scale, 0.0, 0.0, 0.0];
    let fs = [0.0; 6];
    assert_eq!(jprom_model_set_harmonic_force(model, 1, fc.as_ptr(), fs.as_ptr(), 6), jprom_status::JPROM_OK);
    assert_eq!(jprom_model_set_rayleigh_damping(model, 0.0, 1e-4), jprom_status::JPROM_OK);
    let outs = [0usize, 3];
    assert_eq!(jprom_model_set_output_dofs(model, outs.as_ptr(), 2), jprom_status::JPROM_OK);
    model
}

/// Sweeps a fresh model and returns (omega, |X1| at both outputs) per point, after checking
/// that a deliberate error on this thread leaves this thread's message.
fn solve(scale: f64) -> Vec<[f64; 3]> {
    unsafe {
        let model = build(scale);
        let mut opts = std::mem::zeroed();
        let mut sopts = std::mem::zeroed();
        jprom_hbm_options_default(&mut opts);
        jprom_sweep_options_default(&mut sopts);
        opts.harmonics = 3;
        sopts.omega_start = 60.0;
        sopts.omega_end = 160.0;
        let mut sweep = std::ptr::null_mut();
        assert_eq!(jprom_sweep(model, &opts, &sopts, None, std::ptr::null_mut(), &mut sweep), jprom_status::JPROM_OK);
        let mut n = 0;
        jprom_sweep_result_n_points(sweep, &mut n);
        let mut rows = Vec::new();
        for i in 0..n {
            let mut r = [0.0; 3];
            jprom_sweep_result_point_omega(sweep, i, &mut r[0]);
            jprom_sweep_result_point_amplitude(sweep, i, 1, 0, &mut r[1]);
            jprom_sweep_result_point_amplitude(sweep, i, 1, 1, &mut r[2]);
            rows.push(r);
        }
        let tag = format!("scale {scale}");
        let bad = std::ffi::CString::new(format!("/nonexistent/{tag}.json")).unwrap();
        let mut other = std::ptr::null_mut();
        assert_eq!(jprom_model_load_json(bad.as_ptr(), &mut other), jprom_status::JPROM_IO);
        let msg = CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned();
        assert!(msg.contains(&tag), "message of another thread: {msg}");
        jprom_sweep_result_free(sweep);
        jprom_model_free(model);
        rows
    }
}

#[test]
fn two_threads_match_sequential_solves() {
    let seq_a = solve(1.0);
    let seq_b = solve(3.0);
    assert_ne!(seq_a, seq_b);
    for _ in 0..2 {
        let ta = std::thread::spawn(|| solve(1.0));
        let tb = std::thread::spawn(|| solve(3.0));
        let (a, b) = (ta.join().unwrap(), tb.join().unwrap());
        assert_eq!(a, seq_a, "thread A differs from the sequential solve");
        assert_eq!(b, seq_b, "thread B differs from the sequential solve");
    }
}
