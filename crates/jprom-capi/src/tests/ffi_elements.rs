//! The element functions of issue 18 through the C API: a polynomial (cubic) spring, a
//! unilateral spring and a 2D friction element reach the model with their parameters, a chain
//! and parallel elements are accepted, and bad input (NaN, negative stiffness, DoF out of
//! range, NULL arrays, a bad frame, a cycle) is a status with a message, the model unchanged.

use crate::*;
use jprom::contact::ContactLaw;
use std::ffi::CStr;
use std::ptr::{null, null_mut};

unsafe fn ok(s: jprom_status) {
    assert_eq!(s, jprom_status::JPROM_OK, "{}", CStr::from_ptr(jprom_last_error_message()).to_string_lossy());
}

unsafe fn fails(s: jprom_status, status: jprom_status, words: &[&str]) {
    assert_eq!(s, status);
    let msg = CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned();
    for w in words {
        assert!(msg.contains(w), "message '{msg}' lacks '{w}'");
    }
}

unsafe fn model(n: usize) -> *mut jprom_model {
    let m: Vec<f64> = (0..n * n).map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 }).collect();
    let k: Vec<f64> = m.iter().map(|v| 2.0 * v).collect();
    let mut p = null_mut();
    ok(jprom_model_new(n, m.as_ptr(), k.as_ptr(), &mut p));
    p
}

unsafe fn contacts(p: *mut jprom_model) -> Vec<jprom::contact::Contact> {
    handle::get(p, "model").unwrap().model.contacts.clone()
}

#[test]
fn each_element_reaches_the_model_with_its_parameters() {
    unsafe {
        let p = model(4);
        ok(jprom_model_add_polynomial_spring(p, 0, null(), [1.0, 0.0, 0.5].as_ptr(), 3));
        // a chain link q1 - q0 and a parallel element on the same kinematics
        ok(jprom_model_add_polynomial_spring(p, 1, &0usize, [0.0, 0.0, 2.0].as_ptr(), 3));
        ok(jprom_model_add_jenkins(p, 1, &0usize, 3.0, 0.2, 1.0));
        ok(jprom_model_add_unilateral_spring(p, 0, null(), 5.0, -0.1));
        let frame = [0.6, 0.8, -0.8, 0.6];
        ok(jprom_model_add_friction_2d(p, [2usize, 3].as_ptr(), null(), frame.as_ptr(), 4.0, 6.0, 0.3, 2.0));
        let c = contacts(p);
        assert_eq!(c.len(), 5);
        assert_eq!(c[0].law, ContactLaw::Polynomial { coefficients: vec![1.0, 0.0, 0.5] });
        assert_eq!((c[1].dofs_a.clone(), c[1].dofs_b.clone()), (vec![1], Some(vec![0])));
        assert_eq!(c[3].law, ContactLaw::Unilateral { kn: 5.0, n0: -0.1 });
        assert_eq!(c[4].law, ContactLaw::Friction2D { kt: 4.0, kn: 6.0, mu: 0.3, n0: 2.0 });
        assert_eq!(c[4].rotation(), frame.to_vec());
        assert_eq!(c[4].dofs_a, vec![2, 3]);
        ok(jprom_model_validate(p));
        jprom_model_free(p);
    }
}

#[test]
fn bad_element_input_is_a_status_with_a_message_and_leaves_the_model_unchanged() {
    use jprom_status::*;
    unsafe {
        let p = model(3);
        let good = [1.0, 0.0, 0.5];
        fails(jprom_model_add_polynomial_spring(p, 0, null(), [1.0, f64::NAN].as_ptr(), 2), JPROM_INVALID_VALUE, &["coefficients[1]", "finite"]);
        fails(jprom_model_add_polynomial_spring(p, 0, null(), good.as_ptr(), 0), JPROM_INVALID_VALUE, &["coefficients"]);
        fails(jprom_model_add_polynomial_spring(p, 0, null(), null(), 3), JPROM_NULL_ARGUMENT, &["coefficients"]);
        fails(jprom_model_add_polynomial_spring(p, 7, null(), good.as_ptr(), 3), JPROM_INVALID_VALUE, &["DoF 7", "model size 3"]);
        fails(jprom_model_add_polynomial_spring(p, 0, &9usize, good.as_ptr(), 3), JPROM_INVALID_VALUE, &["DoF 9"]);
        fails(jprom_model_add_polynomial_spring(null_mut(), 0, null(), good.as_ptr(), 3), JPROM_NULL_ARGUMENT, &["model"]);
        fails(jprom_model_add_unilateral_spring(p, 0, null(), -1.0, 0.0), JPROM_INVALID_VALUE, &["kn", ">= 0"]);
        fails(jprom_model_add_unilateral_spring(p, 0, null(), 1.0, f64::NAN), JPROM_INVALID_VALUE, &["n0"]);
        fails(jprom_model_add_unilateral_spring(p, 0, &0usize, 1.0, 0.0), JPROM_INVALID_VALUE, &["shares a DoF"]);
        let frame = [1.0, 0.0, 0.0, 1.0];
        let dofs = [0usize, 1];
        fails(jprom_model_add_friction_2d(p, dofs.as_ptr(), null(), frame.as_ptr(), -4.0, 6.0, 0.3, 2.0), JPROM_INVALID_VALUE, &["kt"]);
        fails(jprom_model_add_friction_2d(p, dofs.as_ptr(), null(), frame.as_ptr(), 4.0, 6.0, f64::NAN, 2.0), JPROM_INVALID_VALUE, &["mu"]);
        fails(jprom_model_add_friction_2d(p, dofs.as_ptr(), null(), [1.0, 0.0, 1.0, 0.0].as_ptr(), 4.0, 6.0, 0.3, 2.0), JPROM_INVALID_VALUE, &["orthonormal"]);
        fails(jprom_model_add_friction_2d(p, null(), null(), frame.as_ptr(), 4.0, 6.0, 0.3, 2.0), JPROM_NULL_ARGUMENT, &["dofs_a"]);
        fails(jprom_model_add_friction_2d(p, dofs.as_ptr(), null(), null(), 4.0, 6.0, 0.3, 2.0), JPROM_NULL_ARGUMENT, &["frame"]);
        fails(jprom_model_add_friction_2d(p, [0usize, 5].as_ptr(), null(), frame.as_ptr(), 4.0, 6.0, 0.3, 2.0), JPROM_INVALID_VALUE, &["DoF 5"]);
        assert!(contacts(p).is_empty(), "refused elements are not kept");
        // A cycle 0 -> 1 -> 0 and an overlap with other kinematics.
        ok(jprom_model_add_jenkins(p, 0, &1usize, 1.0, 0.1, 1.0));
        fails(jprom_model_add_polynomial_spring(p, 1, &0usize, good.as_ptr(), 3), JPROM_INVALID_VALUE, &["cycle"]);
        fails(jprom_model_add_unilateral_spring(p, 0, null(), 1.0, 0.0), JPROM_INVALID_VALUE, &["other kinematics", "same dofs_a, dofs_b and frame"]);
        assert_eq!(contacts(p).len(), 1);
        jprom_model_free(p);
    }
}
