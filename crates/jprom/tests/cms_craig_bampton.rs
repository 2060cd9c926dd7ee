//! Sparse Craig-Bampton against dense references on a coarse blade (~1,500 DoFs): natural
//! frequencies (boundary free, boundary fixed, contacts stuck), exact static response to a
//! boundary load, force reduction and recovery, and the conversion to a jprom Model.

use faer::prelude::Solve;
use faer::Mat;
use jprom::linalg::eigen::dense_generalized_eigenvalues;
use jprom::fe::{BladeFe, BladeParams, BuiltinBlade, CbOptions};
use jprom::linalg::lanczos::SparseCholesky;
use jprom::linalg::sparse_to_dense;
use jprom::model::Damping;

fn coarse_blade() -> BladeFe {
    let p = BladeParams { n_span: 18, n_chord: 4, n_thickness: 2, n_shroud_gap: 2, ..Default::default() };
    BuiltinBlade::build(&p).unwrap()
}

fn hz(l: &[f64]) -> Vec<f64> {
    l.iter().map(|v| v.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)).collect()
}

#[test]
fn reduced_frequencies_match_dense_full_model() {
    let fe = coarse_blade();
    let n = fe.n_dof();
    assert!(n > 800 && n < 2500, "coarse blade has {n} DoFs");
    let cb = fe.reduce(50).unwrap();
    let kd = sparse_to_dense(&fe.stiffness);
    let md = sparse_to_dense(&fe.mass);

    // Boundary free: full dense generalised eigen solve.
    let full = hz(&dense_generalized_eigenvalues(&kd, &md).unwrap());
    let red = cb.natural_frequencies_hz(false).unwrap();
    // The band: modes well below the highest fixed-interface mode kept.
    let f_cut = 0.25 * cb.cb.modal_frequencies_hz().last().unwrap();
    let mut checked = 0;
    for (a, b) in full.iter().zip(&red) {
        if *a > f_cut {
            break;
        }
        assert!((a - b).abs() / a < 1e-3, "free mode: full {a} vs CB {b}");
        assert!(b >= &(a * (1.0 - 1e-9)), "CB frequencies are upper bounds");
        checked += 1;
    }
    eprintln!("{checked} free modes below {f_cut:.0} Hz checked");
    assert!(checked >= 6, "only {checked} modes in band");

    // Stuck contacts: springs on the boundary DoFs, same springs on the full model.
    let ks = sparse_to_dense(&fe.stuck_stiffness().unwrap());
    let full_s = hz(&dense_generalized_eigenvalues(&ks, &md).unwrap());
    let red_s = cb.natural_frequencies_hz(true).unwrap();
    for k in 0..6 {
        assert!((full_s[k] - red_s[k]).abs() / full_s[k] < 1e-3, "stuck mode {k}: {} vs {}", full_s[k], red_s[k]);
    }

    // Boundary fixed: fixed-interface modes vs dense K_ii, M_ii.
    let int = &cb.cb.interior_dofs;
    let kii = Mat::from_fn(int.len(), int.len(), |i, j| kd[(int[i], int[j])]);
    let mii = Mat::from_fn(int.len(), int.len(), |i, j| md[(int[i], int[j])]);
    let fixed = hz(&dense_generalized_eigenvalues(&kii, &mii).unwrap());
    for (k, f) in cb.cb.modal_frequencies_hz().iter().enumerate() {
        assert!((f - fixed[k]).abs() / fixed[k] < 1e-8, "fixed-interface mode {k}: {f} vs {}", fixed[k]);
    }
}

#[test]
fn static_boundary_load_is_exact_and_recovered() {
    let fe = coarse_blade();
    let cb = fe.reduce(20).unwrap();
    // Full-model reference: sparse Cholesky solve of (K + contact springs) u = f_E^0 + f_E^1.
    let ks = fe.stuck_stiffness().unwrap();
    let f: Vec<f64> = fe.static_force.iter().zip(&fe.harmonic_force).map(|(a, b)| a + b).collect();
    let chol = SparseCholesky::factor(&ks, "stuck").unwrap();
    let mut u = Mat::from_fn(fe.n_dof(), 1, |i, _| f[i]);
    chol.solve_in_place(u.as_mut());
    // Reduced: (K_red + springs) q = T^T f, then x = T q.
    let fr = cb.cb.reduce_force(&f).unwrap();
    let kr = cb.stuck_stiffness();
    let q = kr.partial_piv_lu().solve(Mat::from_fn(fr.len(), 1, |i, _| fr[i]));
    let x = cb.cb.recover(&(0..fr.len()).map(|i| q[(i, 0)]).collect::<Vec<_>>()).unwrap();
    let num: f64 = (0..fe.n_dof()).map(|i| (x[i] - u[(i, 0)]).powi(2)).sum::<f64>().sqrt();
    let den: f64 = (0..fe.n_dof()).map(|i| u[(i, 0)].powi(2)).sum::<f64>().sqrt();
    assert!(num / den < 1e-9, "relative static error {}", num / den);
    // The blade's loads act on boundary DoFs only, so the stored reduced loads equal T^T f.
    let f0 = cb.cb.reduce_force(&fe.static_force).unwrap();
    for (a, b) in f0.iter().zip(&cb.static_force) {
        assert!((a - b).abs() <= 1e-12 * (1.0 + a.abs()));
    }
}

#[test]
fn reduced_model_is_a_valid_jprom_model() {
    let fe = coarse_blade();
    let cb = fe.reduce(10).unwrap();
    let m = cb.to_model(Damping::from_modal_ratio(0.001, 2.0 * std::f64::consts::PI * 2150.0)).unwrap();
    assert_eq!(m.n_dof(), 18 * 3 + 27 + 10);
    assert_eq!(m.contacts.len(), 18);
    assert_eq!(m.output_dofs.len(), 27);
    // Contact DoFs point at the same physical DoFs as the FE contact nodes.
    for (c, node) in m.contacts.iter().zip(&fe.contacts) {
        for a in 0..3 {
            assert_eq!(cb.cb.boundary_dofs[c.dofs_a[a]], node.dofs[a]);
        }
        assert_eq!(c.frame, node.frame);
    }
    // Output DoFs map to the FE output DoFs.
    for (o, d) in m.output_dofs.iter().zip(&fe.output_dofs) {
        assert_eq!(cb.cb.boundary_dofs[*o], *d);
    }
}

/// The reduced matrices are `T^T K T`, `T^T M T` with `T` built densely from the kept
/// constraint and fixed-interface modes, and the same without keeping the constraint modes
/// (the blocked path with the second solve). Refinement 3 has 98 contact nodes, so the
/// 321 boundary DoFs span two column blocks.
#[test]
fn reduced_matrices_are_the_projection_with_and_without_recovery() {
    let mut p = BladeParams { n_span: 18, n_chord: 4, n_thickness: 2, n_shroud_gap: 2, ..Default::default() };
    p.refinement = 3;
    let fe = BuiltinBlade::build(&p).unwrap();
    let nb = fe.boundary_dofs().len();
    assert!(nb > 256, "{nb} boundary DoFs do not span two blocks");
    let kept = fe.reduce_with(CbOptions { n_modes: 12, keep_recovery: true, cutoff_hz: None }).unwrap().cb;
    let lean = fe.reduce_with(CbOptions { n_modes: 12, keep_recovery: false, cutoff_hz: None }).unwrap().cb;
    assert!(lean.constraint_modes.is_none());
    assert!(lean.recover(&vec![0.0; lean.n_reduced()]).is_err());
    let psi = kept.constraint_modes.as_ref().unwrap();
    let (n, nr) = (fe.n_dof(), kept.n_reduced());
    let mut t = Mat::<f64>::zeros(n, nr);
    for (r, &d) in kept.boundary_dofs.iter().enumerate() {
        t[(d, r)] = 1.0;
    }
    for (r, &d) in kept.interior_dofs.iter().enumerate() {
        for c in 0..nb {
            t[(d, c)] = psi[(r, c)];
        }
        for c in 0..kept.modal_eigenvalues.len() {
            t[(d, nb + c)] = kept.fixed_interface_modes[(r, c)];
        }
    }
    let kd = sparse_to_dense(&fe.stiffness);
    let md = sparse_to_dense(&fe.mass);
    let k_ref = t.transpose() * &kd * &t;
    let m_ref = t.transpose() * &md * &t;
    let rel = |a: &Mat<f64>, b: &Mat<f64>| (a - b).norm_l2() / b.norm_l2();
    for (name, cb) in [("kept", &kept), ("lean", &lean)] {
        assert!(rel(&cb.stiffness, &k_ref) < 1e-9, "{name} K_red: {:.2e}", rel(&cb.stiffness, &k_ref));
        assert!(rel(&cb.mass, &m_ref) < 1e-9, "{name} M_red: {:.2e}", rel(&cb.mass, &m_ref));
    }
    assert!(rel(&lean.mass, &kept.mass) < 1e-11 && rel(&lean.stiffness, &kept.stiffness) < 1e-11);
}
