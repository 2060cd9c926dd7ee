//! Issue 18: `jprom_solve_point_from` and `jprom_sweep_from` (a point from a guess, a sweep
//! restarted from a solution), with the guesses they refuse.

use crate::*;
use std::ffi::CStr;
use std::ptr::{null, null_mut};

unsafe fn ok(s: jprom_status) {
    assert_eq!(s, jprom_status::JPROM_OK, "{}", message());
}

fn message() -> String {
    unsafe { CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned() }
}

/// Two DoFs on a chain, a Jenkins element from DoF 1 to ground, forced at DoF 0; resonance
/// near 100 rad/s stuck, lower in slip.
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

unsafe fn options(harmonics: usize, condensed: i32) -> jprom_hbm_options {
    let mut o = std::mem::zeroed();
    ok(jprom_hbm_options_default(&mut o));
    o.harmonics = harmonics;
    o.condensed = condensed;
    o
}

unsafe fn coeffs(s: *const jprom_solution, harmonics: usize) -> Vec<f64> {
    let mut buf = vec![0.0; (2 * harmonics + 1) * 2];
    ok(jprom_solution_output_coeffs(s, buf.as_mut_ptr(), buf.len()));
    buf
}

unsafe fn iterations(s: *const jprom_solution) -> usize {
    let mut it = 0;
    ok(jprom_solution_convergence(s, &mut it, null_mut()));
    it
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    d / b.iter().map(|y| y * y).sum::<f64>().sqrt()
}

#[test]
fn a_point_from_a_neighbours_solution_is_the_point_from_zero_in_fewer_iterations() {
    unsafe {
        let m = model();
        let o = options(3, 1);
        let (mut near, mut from_zero, mut from_guess, mut null_guess) = (null_mut(), null_mut(), null_mut(), null_mut());
        ok(jprom_solve_point(m, 85.0, &o, &mut near));
        ok(jprom_solve_point(m, 86.0, &o, &mut from_zero));
        ok(jprom_solve_point_from(m, 86.0, &o, near, &mut from_guess));
        ok(jprom_solve_point_from(m, 86.0, &o, null(), &mut null_guess));
        let (a, b) = (coeffs(from_guess, 3), coeffs(from_zero, 3));
        assert!(rel_diff(&a, &b) < 1e-8, "{a:?} vs {b:?}");
        // NULL guess: the same solve as jprom_solve_point
        assert_eq!(coeffs(null_guess, 3), b);
        assert_eq!(iterations(null_guess), iterations(from_zero));
        // the neighbour is a far better start than zero in slip
        let (ig, iz) = (iterations(from_guess), iterations(from_zero));
        println!("iterations from the neighbour {ig}, from zero {iz}");
        assert!(ig < iz, "{ig} from the neighbour, {iz} from zero");
        // the guess was only read
        let mut w = 0.0;
        ok(jprom_solution_omega(near, &mut w));
        assert_eq!(w, 85.0);
        for s in [near, from_zero, from_guess, null_guess] {
            ok(jprom_solution_free(s));
        }
        ok(jprom_model_free(m));
    }
}

#[test]
fn a_guess_with_other_harmonics_is_padded_and_a_guess_of_another_system_is_refused() {
    unsafe {
        let m = model();
        let (h1, h3, h3_full) = (options(1, 1), options(3, 1), options(3, 0));
        let (mut g1, mut p, mut reference, mut bad) = (null_mut(), null_mut(), null_mut(), null_mut());
        ok(jprom_solve_point(m, 86.0, &h1, &mut g1));
        ok(jprom_solve_point_from(m, 86.0, &h3, g1, &mut p));
        ok(jprom_solve_point(m, 86.0, &h3, &mut reference));
        assert!(rel_diff(&coeffs(p, 3), &coeffs(reference, 3)) < 1e-8);
        // a condensed solution (1 unknown per harmonic) as the guess of a full solve (2)
        let s = jprom_solve_point_from(m, 86.0, &h3_full, g1, &mut bad);
        assert_eq!(s, jprom_status::JPROM_BAD_SIZE, "{}", message());
        assert!(message().contains("unknowns per harmonic") && message().contains("condensed"), "{}", message());
        assert!(bad.is_null(), "out written on failure");
        // a freed or foreign handle is refused, not read
        let s = jprom_solve_point_from(m, 86.0, &h3, m as *const jprom_solution, &mut bad);
        assert_eq!(s, jprom_status::JPROM_INVALID_HANDLE, "{}", message());
        assert!(bad.is_null());
        let s = jprom_sweep_from(m, &h3_full, &sweep_options(80.0, 90.0), g1, None, null_mut(), null_mut());
        assert_ne!(s, jprom_status::JPROM_OK);
        for s in [g1, p, reference] {
            ok(jprom_solution_free(s));
        }
        ok(jprom_model_free(m));
    }
}

unsafe fn sweep_options(w0: f64, w1: f64) -> jprom_sweep_options {
    let mut s = std::mem::zeroed();
    ok(jprom_sweep_options_default(&mut s));
    s.omega_start = w0;
    s.omega_end = w1;
    s
}

unsafe fn omegas_and_amplitudes(sw: *const jprom_sweep_result) -> Vec<(f64, f64)> {
    let mut n = 0;
    ok(jprom_sweep_result_n_points(sw, &mut n));
    (0..n)
        .map(|i| {
            let (mut w, mut a) = (0.0, 0.0);
            ok(jprom_sweep_result_point_omega(sw, i, &mut w));
            ok(jprom_sweep_result_point_amplitude(sw, i, 1, 0, &mut a));
            (w, a)
        })
        .collect()
}

#[test]
fn a_sweep_restarted_from_one_of_its_points_goes_on_from_that_point() {
    unsafe {
        let m = model();
        let o = options(3, 1);
        let mut whole = null_mut();
        ok(jprom_sweep(m, &o, &sweep_options(60.0, 140.0), None, null_mut(), &mut whole));
        let first = omegas_and_amplitudes(whole);
        let k = first.len() / 2;
        let mut start = null_mut();
        ok(jprom_sweep_result_point(whole, k, &mut start));
        let mut rest = null_mut();
        ok(jprom_sweep_from(m, &o, &sweep_options(first[k].0, 140.0), start, None, null_mut(), &mut rest));
        let second = omegas_and_amplitudes(rest);
        let mut reached = 0;
        ok(jprom_sweep_result_reached_end(rest, &mut reached));
        assert_eq!(reached, 1);
        // it starts on the point it was given (not the solution from zero there), and ends
        // where the whole sweep ended
        assert!((second[0].1 - first[k].1).abs() <= 1e-9 * first[k].1, "{:?} vs {:?}", second[0], first[k]);
        let (a, b) = (second.last().unwrap(), first.last().unwrap());
        assert_eq!(a.0, b.0);
        assert!((a.1 - b.1).abs() <= 1e-8 * b.1, "{a:?} vs {b:?}");
        ok(jprom_solution_free(start));
        ok(jprom_sweep_result_free(whole));
        ok(jprom_sweep_result_free(rest));
        ok(jprom_model_free(m));
    }
}
