//! Issue 57: a sweep's folds, branch points and gaps through C (`jprom_sweep_result_event`,
//! `jprom_sweep_result_gap`): a Duffing oscillator's two folds swept in C equal the Rust API's,
//! a gap written into a sweep reads back with its reason, and bad indices are refused.

use crate::*;
use jprom::hbm::{EventKind, FullSystem, HbmOptions, SweepGap, SweepOptions};
use jprom::rom::SweepRecord;
use std::ffi::CStr;
use std::ops::ControlFlow;
use std::ptr::{null, null_mut};

unsafe fn ok(s: jprom_status) {
    assert_eq!(s, jprom_status::JPROM_OK, "{}", message());
}

fn message() -> String {
    unsafe { CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned() }
}

/// `x'' + 0.05 x' + x + 0.5 x^3 = 0.3 cos(omega t)`: a hardening peak with two folds in
/// 0.6-2.6 rad/s.
unsafe fn duffing() -> *mut jprom_model {
    let mut p = null_mut();
    ok(jprom_model_new(1, [1.0].as_ptr(), [1.0].as_ptr(), &mut p));
    ok(jprom_model_add_polynomial_spring(p, 0, null(), [0.0, 0.0, 0.5].as_ptr(), 3));
    ok(jprom_model_set_rayleigh_damping(p, 0.05, 0.0));
    ok(jprom_model_set_harmonic_force(p, 1, [0.3].as_ptr(), null(), 1));
    ok(jprom_model_set_output_dofs(p, [0usize].as_ptr(), 1));
    p
}

#[test]
fn the_folds_of_a_sweep_through_c_are_the_rust_sweeps() {
    unsafe {
        let m = duffing();
        let mut o = std::mem::zeroed();
        ok(jprom_hbm_options_default(&mut o));
        o.harmonics = 5;
        o.condensed = 0;
        let mut s: jprom_sweep_options = std::mem::zeroed();
        ok(jprom_sweep_options_default(&mut s));
        s.omega_start = 0.6;
        s.omega_end = 2.6;
        let mut sweep = null_mut();
        ok(jprom_sweep(m, &o, &s, None, null_mut(), &mut sweep));

        let model = handle::get(m, "model").unwrap().model.clone();
        let system = FullSystem::new(&model, 5).unwrap();
        let rust = jprom::hbm::sweep(&system, &SweepOptions::band(0.6, 2.6), &HbmOptions::default(), &mut |_| ControlFlow::Continue(())).unwrap();
        assert_eq!(rust.events.iter().filter(|e| e.kind == EventKind::Fold).count(), 2, "{:?}", rust.events);

        let mut n = usize::MAX;
        ok(jprom_sweep_result_n_events(sweep, &mut n));
        assert_eq!(n, rust.events.len());
        for (i, e) in rust.events.iter().enumerate() {
            let (mut kind, mut omega, mut tol, mut after, mut amp) = (jprom_event_kind::JPROM_EVENT_BRANCH_POINT, 0.0, 0.0, 0usize, 0.0);
            ok(jprom_sweep_result_event(sweep, i, &mut kind, &mut omega, &mut tol, &mut after, &mut amp));
            assert_eq!(kind, jprom_event_kind::from(e.kind));
            assert_eq!(CStr::from_ptr(jprom_event_kind_name(kind as i32)).to_str().unwrap(), e.kind.name());
            assert!((omega - e.omega).abs() <= 1e-12 * e.omega, "event {i}: {omega} in C, {} in Rust", e.omega);
            assert!(tol > 0.0 && tol <= 1e-6 * omega, "tolerance {tol}");
            assert_eq!(after, e.after_point);
            assert!((amp - e.amplitude).abs() <= 1e-10 * e.amplitude && amp > 0.0, "amplitude {amp} against {}", e.amplitude);
            // every out pointer may be NULL
            ok(jprom_sweep_result_event(sweep, i, null_mut(), null_mut(), null_mut(), null_mut(), null_mut()));
        }
        let (mut lo, mut hi) = (0.0, 0.0);
        ok(jprom_sweep_result_event(sweep, 0, null_mut(), &mut lo, null_mut(), null_mut(), null_mut()));
        ok(jprom_sweep_result_event(sweep, 1, null_mut(), &mut hi, null_mut(), null_mut(), null_mut()));
        assert!(0.6 < lo.min(hi) && lo.max(hi) < 2.6 && lo != hi, "folds at {lo} and {hi}");

        // out of range, NULL handles and NULL counts are statuses with a reason
        assert_eq!(jprom_sweep_result_event(sweep, n, null_mut(), &mut lo, null_mut(), null_mut(), null_mut()), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains(&format!("event index {n} >= {n}")), "{}", message());
        let mut gaps = usize::MAX;
        ok(jprom_sweep_result_n_gaps(sweep, &mut gaps));
        assert_eq!(gaps, 0);
        assert_eq!(jprom_sweep_result_gap(sweep, 0, &mut lo, &mut hi), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("gap index 0 >= 0"), "{}", message());
        assert_eq!(jprom_sweep_result_n_events(null(), &mut n), jprom_status::JPROM_NULL_ARGUMENT);
        assert_eq!(jprom_sweep_result_n_gaps(sweep, null_mut()), jprom_status::JPROM_NULL_ARGUMENT);
        assert_eq!(CStr::from_ptr(jprom_event_kind_name(7)).to_str().unwrap(), "unknown");
        ok(jprom_sweep_result_free(sweep));
        ok(jprom_model_free(m));
    }
}

#[test]
fn a_gap_reads_back_with_its_ends_and_reason() {
    unsafe {
        let mut record = SweepRecord::full_order(jprom::hbm::SweepResult::empty());
        let reason = "no convergence in continuation: a test's gap".to_string();
        record.sweep.gaps.push(SweepGap { from: 101.5, to: 102.25, reason: reason.clone() });
        let sweep = jprom_sweep_result::wrap(record, crate::solve::Origin::Unknown);
        let mut n = 0;
        ok(jprom_sweep_result_n_gaps(sweep, &mut n));
        assert_eq!(n, 1);
        let (mut from, mut to) = (0.0, 0.0);
        ok(jprom_sweep_result_gap(sweep, 0, &mut from, &mut to));
        assert_eq!((from, to), (101.5, 102.25));
        ok(jprom_sweep_result_gap(sweep, 0, null_mut(), null_mut()));
        let mut buf = vec![0 as std::ffi::c_char; 128];
        let mut written = 0;
        ok(jprom_sweep_result_gap_reason_copy(sweep, 0, buf.as_mut_ptr(), buf.len(), &mut written));
        assert_eq!(written, reason.len());
        assert_eq!(CStr::from_ptr(buf.as_ptr()).to_str().unwrap(), reason);
        assert_eq!(jprom_sweep_result_gap_reason_copy(sweep, 0, buf.as_mut_ptr(), 8, &mut written), jprom_status::JPROM_BAD_SIZE);
        assert_eq!(written, reason.len());
        assert_eq!(jprom_sweep_result_gap_reason_copy(sweep, 1, buf.as_mut_ptr(), buf.len(), &mut written), jprom_status::JPROM_INVALID_VALUE);
        ok(jprom_sweep_result_free(sweep));
    }
}
