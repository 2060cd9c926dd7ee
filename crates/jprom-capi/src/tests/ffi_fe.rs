//! The FE-model functions (`jprom_fe_*`) on bad input: each a documented status with a message
//! naming what is wrong (the node id, the set, the argument), nothing written on failure; and
//! a small CSC model reduced from C equals the same model reduced by the Rust API.

use crate::*;
use jprom::contact::{ContactLaw, IDENTITY_FRAME};
use jprom::fe::{FeModel, FeNode, NodalContact, NodalForce, Reduction};
use jprom::linalg::sparse_from_triplets;
use jprom::model::Damping;
use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

fn message() -> String {
    unsafe { CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned() }
}

/// A chain of 4 nodes (x, y, z each, 12 DoFs), springs 1e4 between neighbours and to ground at
/// node 1: `K`, `M` as CSC, node ids 101..104.
fn chain() -> (usize, Vec<usize>, Vec<usize>, Vec<f64>, Vec<usize>, Vec<usize>, Vec<f64>, Vec<i64>, Vec<i64>) {
    let n = 12;
    let mut k = vec![vec![0.0; n]; n];
    for node in 0..4 {
        for d in 0..3 {
            let i = 3 * node + d;
            k[i][i] += if node == 0 { 2e4 } else { 1e4 };
            if node < 3 {
                let j = i + 3;
                k[j][j] += 1e4;
                k[i][j] -= 1e4;
                k[j][i] -= 1e4;
            }
        }
    }
    let csc = |a: &Vec<Vec<f64>>| {
        let (mut cp, mut ri, mut va) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for (i, row) in a.iter().enumerate() {
                if row[j] != 0.0 {
                    ri.push(i);
                    va.push(row[j]);
                }
            }
            cp.push(ri.len());
        }
        (cp, ri, va)
    };
    let m: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect()).collect();
    let (kc, kr, kv) = csc(&k);
    let (mc, mr, mv) = csc(&m);
    let ids = vec![101, 102, 103, 104];
    let rows: Vec<i64> = (0..4).flat_map(|nd| [3 * nd, 3 * nd + 1, 3 * nd + 2, -1, -1, -1]).collect();
    (n, kc, kr, kv, mc, mr, mv, ids, rows)
}

unsafe fn new_fe() -> *mut jprom_fe_model {
    let (n, kc, kr, kv, mc, mr, mv, ids, rows) = chain();
    let mut fe = null_mut();
    let s = jprom_fe_model_new_csc(n, kc.as_ptr(), kr.as_ptr(), kv.as_ptr(), mc.as_ptr(), mr.as_ptr(), mv.as_ptr(), 4, ids.as_ptr(), rows.as_ptr(), &mut fe);
    assert_eq!(s, jprom_status::JPROM_OK, "{}", message());
    fe
}

#[test]
fn fe_model_from_c_equals_the_rust_reduction() {
    unsafe {
        let fe = new_fe();
        let frame: Vec<f64> = IDENTITY_FRAME.iter().flatten().copied().collect();
        assert_eq!(jprom_fe_model_add_contact(fe, 104, frame.as_ptr(), 1e3, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_add_force(fe, 102, 1, [0.0, 1.0, 0.0].as_ptr()), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_add_output(fe, 103, 1), jprom_status::JPROM_OK);
        let mut model = null_mut();
        assert_eq!(jprom_fe_model_reduce(fe, 2, &mut model), jprom_status::JPROM_OK, "{}", message());
        let from_c = &(*model).model;

        let (n, kc, kr, kv, _, _, _, ids, _) = chain();
        let mut triplets = Vec::new();
        for j in 0..n {
            for p in kc[j]..kc[j + 1] {
                triplets.push((kr[p], j, kv[p]));
            }
        }
        let k = sparse_from_triplets(n, n, triplets).unwrap();
        let m = sparse_from_triplets(n, n, (0..n).map(|i| (i, i, 1.0)).collect()).unwrap();
        let nodes = ids.iter().enumerate().map(|(i, &id)| FeNode { id, coords: None, dofs: [Some(3 * i), Some(3 * i + 1), Some(3 * i + 2), None, None, None] }).collect();
        let spec = Reduction {
            contacts: vec![NodalContact { node: 104, frame: IDENTITY_FRAME, law: ContactLaw::Friction3D { kt1: 1e3, kt2: 1e3, kn: 2e3, mu: 0.3, n0: 5.0 } }],
            harmonic_forces: vec![NodalForce { node: 102, force: [0.0, 1.0, 0.0] }],
            outputs: vec![(103, 1)],
            cb_modes: 2,
            ..Reduction::default()
        };
        let rust = FeModel::new(k, m, nodes).unwrap().reduce(&spec, Damping::default()).unwrap();
        assert_eq!(from_c.stiffness, rust.stiffness);
        assert_eq!(from_c.mass, rust.mass);
        assert_eq!(from_c.contacts, rust.contacts);
        assert_eq!(from_c.output_dofs, rust.output_dofs);
        assert_eq!(from_c.excitation, rust.excitation);
        assert_eq!(from_c.n_dof(), 9 + 2, "three boundary nodes and two modes");
        assert_eq!(jprom_model_free(model), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_free(fe), jprom_status::JPROM_OK);
    }
}

/// `jprom_fe_model_unreduced`: the Rust `FeModel::unreduced` of the same FE model and spec,
/// the full model whose Craig-Bampton reduction `jprom_fe_model_reduce` is (same first free
/// frequencies, all FE DoFs); NULL arguments refused.
#[test]
fn unreduced_fe_model_from_c_equals_the_rust_one() {
    unsafe {
        let fe = new_fe();
        let frame: Vec<f64> = IDENTITY_FRAME.iter().flatten().copied().collect();
        assert_eq!(jprom_fe_model_add_contact(fe, 104, frame.as_ptr(), 1e3, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_add_force(fe, 102, 1, [0.0, 1.0, 0.0].as_ptr()), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_add_force(fe, 103, 0, [0.0, 0.0, -2.0].as_ptr()), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_add_output(fe, 103, 1), jprom_status::JPROM_OK);
        let mut full = null_mut();
        assert_eq!(jprom_fe_model_unreduced(fe, &mut full), jprom_status::JPROM_OK, "{}", message());
        let from_c = &(*full).model;
        let spec = Reduction {
            contacts: vec![NodalContact { node: 104, frame: IDENTITY_FRAME, law: ContactLaw::Friction3D { kt1: 1e3, kt2: 1e3, kn: 2e3, mu: 0.3, n0: 5.0 } }],
            static_forces: vec![NodalForce { node: 103, force: [0.0, 0.0, -2.0] }],
            harmonic_forces: vec![NodalForce { node: 102, force: [0.0, 1.0, 0.0] }],
            outputs: vec![(103, 1)],
            ..Reduction::default()
        };
        let rust = (*fe).fe.unreduced(&spec, Damping::default()).unwrap();
        assert_eq!(from_c.n_dof(), 12);
        assert_eq!(from_c.stiffness, rust.stiffness);
        assert_eq!(from_c.mass, rust.mass);
        assert_eq!(from_c.contacts, rust.contacts);
        assert_eq!(from_c.output_dofs, rust.output_dofs);
        assert_eq!(from_c.excitation, rust.excitation);
        // the contact sits on node 104's own DoFs (9, 10, 11), the output on node 103's y (7)
        assert_eq!((from_c.contacts[0].dofs_a.clone(), from_c.output_dofs.clone()), (vec![9, 10, 11], vec![7]));
        // the free modes of the reduced model are those of the full one, to the reduction's accuracy
        let mut reduced = null_mut();
        assert_eq!(jprom_fe_model_reduce(fe, 3, &mut reduced), jprom_status::JPROM_OK, "{}", message());
        let (mut f_full, mut f_red) = ([0.0; 2], [0.0; 2]);
        assert_eq!(jprom_model_modes(full, 0, f_full.as_mut_ptr(), null_mut(), 2, null_mut()), jprom_status::JPROM_OK, "{}", message());
        assert_eq!(jprom_model_modes(reduced, 0, f_red.as_mut_ptr(), null_mut(), 2, null_mut()), jprom_status::JPROM_OK, "{}", message());
        for (a, b) in f_full.iter().zip(&f_red) {
            assert!((a - b).abs() <= 1e-9 * a, "free modes {f_full:?} (FE) vs {f_red:?} (CB)");
        }
        // (beyond the memory budget it is refused: tests/c/hostile_input.c, a process of its own)
        let mut none = null_mut();
        assert_eq!(jprom_fe_model_unreduced(null(), &mut none), jprom_status::JPROM_NULL_ARGUMENT);
        assert_eq!(jprom_fe_model_unreduced(fe, null_mut()), jprom_status::JPROM_NULL_ARGUMENT);
        for m in [full, reduced] {
            assert_eq!(jprom_model_free(m), jprom_status::JPROM_OK);
        }
        assert_eq!(jprom_fe_model_free(fe), jprom_status::JPROM_OK);
    }
}

/// The names deprecated in 0.3 (`jprom_fe_add_contact`, ...) still work and give the same
/// reduced model as the `jprom_fe_model_*` names.
#[test]
#[allow(deprecated)]
fn deprecated_fe_names_forward_to_the_new_ones() {
    unsafe {
        let frame: Vec<f64> = IDENTITY_FRAME.iter().flatten().copied().collect();
        let (old, new) = (new_fe(), new_fe());
        assert_eq!(jprom_fe_fix_dof(old, 101, 3), jprom_status::JPROM_INVALID_VALUE, "node 101 has no rx: {}", message());
        assert_eq!(jprom_fe_add_contact(old, 104, frame.as_ptr(), 1e3, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_add_force(old, 102, 1, [0.0, 1.0, 0.0].as_ptr()), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_add_output(old, 103, 1), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_keep_node(old, 999), jprom_status::JPROM_INVALID_VALUE, "no node 999: {}", message());
        assert_eq!(jprom_fe_model_add_contact(new, 104, frame.as_ptr(), 1e3, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_add_force(new, 102, 1, [0.0, 1.0, 0.0].as_ptr()), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_add_output(new, 103, 1), jprom_status::JPROM_OK);
        let (mut a, mut b, mut c, mut d) = (null_mut(), null_mut(), null_mut(), null_mut());
        assert_eq!(jprom_fe_reduce(old, 2, &mut a), jprom_status::JPROM_OK, "{}", message());
        assert_eq!(jprom_fe_model_reduce(new, 2, &mut b), jprom_status::JPROM_OK, "{}", message());
        assert_eq!(jprom_fe_reduce_cutoff(old, 1e9, 2, &mut c), jprom_status::JPROM_OK, "{}", message());
        assert_eq!(jprom_fe_model_reduce_cutoff(new, 1e9, 2, &mut d), jprom_status::JPROM_OK, "{}", message());
        assert_eq!((*a).model, (*b).model);
        assert_eq!((*c).model, (*d).model);
        for m in [a, b, c, d] {
            assert_eq!(jprom_model_free(m), jprom_status::JPROM_OK);
        }
        assert_eq!(jprom_fe_model_free(old), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_free(new), jprom_status::JPROM_OK);
    }
}

#[test]
fn fe_functions_refuse_bad_input_with_a_reason() {
    unsafe {
        let fe = new_fe();
        let frame: Vec<f64> = IDENTITY_FRAME.iter().flatten().copied().collect();
        let f = [0.0, 1.0, 0.0];
        // unknown node ids, named
        assert_eq!(jprom_fe_model_add_contact(fe, 999, frame.as_ptr(), 1e3, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("node 999"), "{}", message());
        assert_eq!(jprom_fe_model_add_force(fe, 998, 1, f.as_ptr()), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("node 998"), "{}", message());
        assert_eq!(jprom_fe_model_add_output(fe, 997, 0), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_fe_model_keep_node(fe, 996), jprom_status::JPROM_INVALID_VALUE);
        // bad values
        assert_eq!(jprom_fe_model_add_contact(fe, 104, frame.as_ptr(), -1.0, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_fe_model_add_force(fe, 102, 2, f.as_ptr()), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("harmonic 2"), "{}", message());
        assert_eq!(jprom_fe_model_add_force(fe, 102, 1, [f64::NAN, 0.0, 0.0].as_ptr()), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_fe_model_add_output(fe, 103, 3), jprom_status::JPROM_INVALID_VALUE);
        // a contact node twice
        assert_eq!(jprom_fe_model_add_contact(fe, 104, frame.as_ptr(), 1e3, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_add_contact(fe, 104, frame.as_ptr(), 1e3, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_INVALID_VALUE);
        // NULL arguments
        assert_eq!(jprom_fe_model_add_contact(fe, 103, null(), 1e3, 1e3, 2e3, 0.3, 5.0), jprom_status::JPROM_NULL_ARGUMENT);
        assert_eq!(jprom_fe_model_add_force(fe, 102, 1, null()), jprom_status::JPROM_NULL_ARGUMENT);
        assert_eq!(jprom_fe_model_reduce(fe, 2, null_mut()), jprom_status::JPROM_NULL_ARGUMENT);
        let mut count = 7usize;
        assert_eq!(jprom_fe_model_node_set(fe, null(), null_mut(), 0, &mut count), jprom_status::JPROM_NULL_ARGUMENT);
        // a model from matrices has no node sets; the message says which there are
        let name = CString::new("tip").unwrap();
        assert_eq!(jprom_fe_model_node_set(fe, name.as_ptr(), null_mut(), 0, &mut count), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("node set 'tip'") && message().contains("no such set") && message().contains("none"), "{}", message());
        // a model handle is not an FE model
        let mut model = null_mut();
        assert_eq!(jprom_fe_model_reduce(fe, 2, &mut model), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_free(model as *mut jprom_fe_model), jprom_status::JPROM_INVALID_HANDLE);
        assert_eq!(jprom_model_free(model), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_free(fe), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_free(null_mut()), jprom_status::JPROM_OK);

        // matrices and nodes that do not fit
        let (n, kc, kr, kv, mc, mr, mv, ids, rows) = chain();
        let mut out = null_mut();
        let mut bad_cp = kc.clone();
        bad_cp[0] = 1;
        assert_eq!(jprom_fe_model_new_csc(n, bad_cp.as_ptr(), kr.as_ptr(), kv.as_ptr(), mc.as_ptr(), mr.as_ptr(), mv.as_ptr(), 4, ids.as_ptr(), rows.as_ptr(), &mut out), jprom_status::JPROM_INVALID_VALUE);
        let mut bad_rows = rows.clone();
        bad_rows[6] = 0; // node 102's x is node 101's x
        assert_eq!(jprom_fe_model_new_csc(n, kc.as_ptr(), kr.as_ptr(), kv.as_ptr(), mc.as_ptr(), mr.as_ptr(), mv.as_ptr(), 4, ids.as_ptr(), bad_rows.as_ptr(), &mut out), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("node 102") && message().contains("node 101"), "{}", message());
        bad_rows[6] = -2;
        assert_eq!(jprom_fe_model_new_csc(n, kc.as_ptr(), kr.as_ptr(), kv.as_ptr(), mc.as_ptr(), mr.as_ptr(), mv.as_ptr(), 4, ids.as_ptr(), bad_rows.as_ptr(), &mut out), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_fe_model_new_csc(0, kc.as_ptr(), kr.as_ptr(), kv.as_ptr(), mc.as_ptr(), mr.as_ptr(), mv.as_ptr(), 4, ids.as_ptr(), rows.as_ptr(), &mut out), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_fe_model_new_csc(n, kc.as_ptr(), kr.as_ptr(), kv.as_ptr(), mc.as_ptr(), mr.as_ptr(), mv.as_ptr(), usize::MAX, ids.as_ptr(), rows.as_ptr(), &mut out), jprom_status::JPROM_BAD_SIZE);
        assert!(out.is_null(), "nothing written on failure");
        let missing = CString::new("/nonexistent/deck.inp").unwrap();
        assert_eq!(jprom_fe_model_load_calculix(missing.as_ptr(), &mut out), jprom_status::JPROM_IO);
        assert!(out.is_null());
    }
}
