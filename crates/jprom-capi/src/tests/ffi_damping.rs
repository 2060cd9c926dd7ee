//! Damping and natural modes from C: each `jprom_*` damping setter gives the model the Rust API
//! gives (bit for bit), `jprom_model_modes` and `jprom_fe_model_modes` the core's modes, and bad
//! input a status and a reason with the model unchanged.

use crate::*;
use jprom::fe::FeModel;
use jprom::io::calculix::read_model;
use jprom::linalg::sparse_triplets;
use jprom::model::modes::{natural_modes, Boundary};
use jprom::model::Damping;
use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

fn message() -> String {
    unsafe { CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned() }
}

fn block_inp() -> CString {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../jprom/tests/data/calculix/block/block.inp");
    CString::new(p.to_str().unwrap()).unwrap()
}

/// CSC of `c_m M + c_k K` of the FE model (a damping matrix a user could pass).
fn damping_csc(fe: &FeModel) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    let mut t: Vec<(usize, usize, f64)> = sparse_triplets(&fe.mass).into_iter().map(|(i, j, v)| (i, j, 30.0 * v)).collect();
    t.extend(sparse_triplets(&fe.stiffness).into_iter().map(|(i, j, v)| (i, j, 1e-7 * v)));
    let c = jprom::linalg::sparse_from_triplets(fe.n_dof(), fe.n_dof(), t).unwrap();
    let c = c.as_ref();
    (c.symbolic().col_ptr().to_vec(), c.symbolic().row_idx().to_vec(), c.val().to_vec())
}

#[test]
fn damping_and_modes_from_c_equal_the_rust_api() {
    unsafe {
        let mut fe = null_mut();
        assert_eq!(jprom_fe_model_load_calculix(block_inp().as_ptr(), &mut fe), jprom_status::JPROM_OK, "{}", message());
        let rust_fe = FeModel::from_calculix(&read_model(std::path::Path::new(block_inp().to_str().unwrap())).unwrap()).unwrap();
        let n = rust_fe.n_dof();

        // FE frequencies
        let mut hz = vec![0.0; 6];
        assert_eq!(jprom_fe_model_modes(fe, 6, hz.as_mut_ptr()), jprom_status::JPROM_OK, "{}", message());
        assert_eq!(hz, rust_fe.natural_frequencies_hz(6).unwrap());

        // FE damping matrix, reduced with the model
        let (cp, ri, va) = damping_csc(&rust_fe);
        assert_eq!(jprom_fe_model_set_damping_csc(fe, n, cp.as_ptr(), ri.as_ptr(), va.as_ptr()), jprom_status::JPROM_OK, "{}", message());
        let tip = (*fe).fe.node_set("TIP").unwrap().to_vec();
        let frame: Vec<f64> = jprom::contact::IDENTITY_FRAME.iter().flatten().copied().collect();
        for &node in &tip[..3] {
            assert_eq!(jprom_fe_model_add_contact(fe, node, frame.as_ptr(), 1e5, 1e5, 2e5, 0.3, 100.0), jprom_status::JPROM_OK);
        }
        let load = (*fe).fe.node_set("LOAD").unwrap()[0];
        assert_eq!(jprom_fe_model_add_force(fe, load, 1, [0.0, 1.0, 0.0].as_ptr()), jprom_status::JPROM_OK);
        let mut model = null_mut();
        assert_eq!(jprom_fe_model_reduce(fe, 10, &mut model), jprom_status::JPROM_OK, "{}", message());

        let mut rust_fe_c = rust_fe.clone();
        let c = jprom::linalg::sparse_from_triplets(n, n, {
            let mut t = Vec::new();
            for j in 0..n {
                for p in cp[j]..cp[j + 1] {
                    t.push((ri[p], j, va[p]));
                }
            }
            t
        })
        .unwrap();
        rust_fe_c.set_damping(c).unwrap();
        let spec = jprom::fe::Reduction { cb_modes: 10, ..(*fe).spec.clone() };
        let mut rust = rust_fe_c.reduce(&spec, Damping::default()).unwrap();
        assert!(rust.added_damping.is_some());
        assert_eq!((*model).model, rust, "jprom_fe_model_reduce with a damping matrix");

        // Rayleigh + modal ratios + loss factor
        assert_eq!(jprom_model_set_rayleigh_damping(model, 2.0, 1e-8), jprom_status::JPROM_OK);
        let ratios = [0.01, 0.02, 0.015];
        assert_eq!(jprom_model_set_modal_damping_ratios(model, ratios.as_ptr(), 3, 0.005), jprom_status::JPROM_OK, "{}", message());
        assert_eq!(jprom_model_set_loss_factor(model, 0.02), jprom_status::JPROM_OK);
        rust.damping = Damping { mass_coeff: 2.0, stiffness_coeff: 1e-8 };
        rust.set_modal_damping(&ratios, 0.005).unwrap();
        rust.loss_factor = 0.02;
        assert_eq!((*model).model, rust, "Rayleigh, modal ratios, loss factor");

        // a damping matrix from C replaces the added one; NULL removes it
        let nr = rust.n_dof();
        let dense: Vec<f64> = (0..nr * nr).map(|k| if k % (nr + 1) == 0 { 3.0 } else { 0.0 }).collect();
        assert_eq!(jprom_model_set_damping_matrix(model, dense.as_ptr(), nr), jprom_status::JPROM_OK, "{}", message());
        assert_eq!((*model).model.added_damping.as_ref().unwrap()[(1, 1)], 3.0);
        assert_eq!(jprom_model_set_damping_matrix(model, null(), 0), jprom_status::JPROM_OK);
        assert!((*model).model.added_damping.is_none());

        // modes, free and stuck, with modal forces
        for (stuck, boundary) in [(0, Boundary::Free), (1, Boundary::Stuck)] {
            let want = natural_modes(&(*model).model, boundary).unwrap();
            let (mut f, mut force, mut count) = (vec![0.0; 5], vec![0.0; 5], 0usize);
            assert_eq!(jprom_model_modes(model, stuck, f.as_mut_ptr(), force.as_mut_ptr(), 5, &mut count), jprom_status::JPROM_OK, "{}", message());
            assert_eq!(count, nr);
            for k in 0..5 {
                assert_eq!(f[k], want[k].frequency_hz);
                assert_eq!(force[k], want[k].modal_force);
            }
            // NULL modal_force, a larger buffer than modes
            let mut all = vec![-1.0; nr + 3];
            assert_eq!(jprom_model_modes(model, stuck, all.as_mut_ptr(), null_mut(), nr + 3, null_mut()), jprom_status::JPROM_OK);
            assert_eq!(all[nr], -1.0, "nothing written past the modes");
        }
        let stuck_hz = natural_modes(&(*model).model, Boundary::Stuck).unwrap()[0].frequency_hz;
        let free_hz = natural_modes(&(*model).model, Boundary::Free).unwrap()[0].frequency_hz;
        assert!(stuck_hz > free_hz, "the contact springs stiffen the first mode: {stuck_hz} vs {free_hz}");

        // bad input: a status, a reason, the model unchanged
        let before = (*model).model.clone();
        assert_eq!(jprom_model_set_loss_factor(model, -0.1), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("loss factor"), "{}", message());
        assert_eq!(jprom_model_set_loss_factor(model, f64::NAN), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_model_set_modal_damping_ratios(model, [0.01, -1.0].as_ptr(), 2, 0.0), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("ratio 1"), "{}", message());
        assert_eq!(jprom_model_set_modal_damping_ratios(model, [0.01].as_ptr(), 1, f64::INFINITY), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_model_set_modal_damping_ratios(model, null(), 2, 0.0), jprom_status::JPROM_NULL_ARGUMENT);
        assert_eq!(jprom_model_set_damping_matrix(model, dense.as_ptr(), nr - 1), jprom_status::JPROM_BAD_SIZE);
        assert!(message().contains(&format!("{nr} DoFs")), "{}", message());
        let mut asym = dense.clone();
        asym[1] = 1.0;
        assert_eq!(jprom_model_set_damping_matrix(model, asym.as_ptr(), nr), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("symmetric"), "{}", message());
        let mut nan = dense.clone();
        nan[5] = f64::NAN;
        assert_eq!(jprom_model_set_damping_matrix(model, nan.as_ptr(), nr), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("c[5]"), "{}", message());
        let mut f1 = [0.0];
        assert_eq!(jprom_model_modes(model, 2, f1.as_mut_ptr(), null_mut(), 1, null_mut()), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_model_modes(model, 0, null_mut(), null_mut(), 1, null_mut()), jprom_status::JPROM_NULL_ARGUMENT);
        assert_eq!((*model).model, before);
        assert_eq!(jprom_fe_model_modes(fe, n + 1, null_mut()), jprom_status::JPROM_BAD_SIZE);
        assert_eq!(jprom_fe_model_set_damping_csc(fe, n - 1, cp.as_ptr(), ri.as_ptr(), va.as_ptr()), jprom_status::JPROM_BAD_SIZE);
        let mut bad = va.clone();
        bad[0] = f64::NAN;
        assert_eq!(jprom_fe_model_set_damping_csc(fe, n, cp.as_ptr(), ri.as_ptr(), bad.as_ptr()), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_model_free(model), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_free(fe), jprom_status::JPROM_OK);
    }
}

/// `jprom_fe_model_fix_dof` and `jprom_fe_model_reduce_cutoff` equal `FeModel::with_fixed` and a reduction
/// with `cb_cutoff_hz`; a placed node's translation cannot be fixed; bad cut-offs are refused.
#[test]
fn fixed_dofs_and_cutoff_from_c_equal_the_rust_api() {
    unsafe {
        let mut fe = null_mut();
        assert_eq!(jprom_fe_model_load_calculix(block_inp().as_ptr(), &mut fe), jprom_status::JPROM_OK, "{}", message());
        let rust_fe = FeModel::from_calculix(&read_model(std::path::Path::new(block_inp().to_str().unwrap())).unwrap()).unwrap();
        let out_node = (*fe).fe.node_set("OUT").unwrap()[0];
        let load = (*fe).fe.node_set("LOAD").unwrap()[0];
        for d in 0..3 {
            assert_eq!(jprom_fe_model_fix_dof(fe, out_node, d), jprom_status::JPROM_OK, "{}", message());
        }
        let mut n = 0usize;
        assert_eq!(jprom_fe_model_n_dof(fe, &mut n), jprom_status::JPROM_OK);
        assert_eq!(n, rust_fe.n_dof() - 3);
        assert_eq!(jprom_fe_model_fix_dof(fe, out_node, 1), jprom_status::JPROM_INVALID_VALUE, "fixed twice");
        assert!(message().contains(&format!("node {out_node}")), "{}", message());
        assert_eq!(jprom_fe_model_fix_dof(fe, 99999, 0), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_fe_model_fix_dof(fe, load, 6), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_fe_model_add_force(fe, load, 1, [0.0, 1.0, 0.0].as_ptr()), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_fix_dof(fe, load, 1), jprom_status::JPROM_INVALID_VALUE, "a loaded node keeps its translations");
        assert!(message().contains("cannot be fixed"), "{}", message());

        let fixed = rust_fe.with_fixed(&[(out_node, 0), (out_node, 1), (out_node, 2)]).unwrap();
        let spec = jprom::fe::Reduction { cb_modes: 40, cb_cutoff_hz: Some(30_000.0), ..(*fe).spec.clone() };
        let rust = fixed.reduce(&spec, Damping::default()).unwrap();
        let mut model = null_mut();
        assert_eq!(jprom_fe_model_reduce_cutoff(fe, 30_000.0, 40, &mut model), jprom_status::JPROM_OK, "{}", message());
        assert_eq!((*model).model, rust);
        assert!(rust.n_dof() < 3 + 40, "the cut-off keeps fewer than the cap");
        assert_eq!(jprom_fe_model_reduce_cutoff(fe, f64::NAN, 40, &mut model), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_fe_model_reduce_cutoff(fe, -5.0, 40, &mut model), jprom_status::JPROM_INVALID_VALUE);
        assert!(message().contains("cut-off"), "{}", message());
        assert_eq!(jprom_model_free(model), jprom_status::JPROM_OK);
        assert_eq!(jprom_fe_model_free(fe), jprom_status::JPROM_OK);
    }
}
