//! The FE-model API ([`jprom::fe::FeModel`]) on a model from another FE code: the CalculiX block
//! of tests/data/calculix (C3D8, clamped at the root, ccx 2.20) read with its node sets, reduced
//! by Craig-Bampton on the TIP, LOAD and OUT nodes; the reduced model's free frequencies converge
//! from above to those ccx printed as modes are added. Then the errors a user meets: an unknown
//! node, a clamped node, a row given twice, a contact node twice.

use jprom::contact::{ContactLaw, IDENTITY_FRAME};
use jprom::error::JpError;
use jprom::fe::{FeModel, FeNode, NodalContact, NodalForce, Reduction};
use jprom::io::calculix::read_model;
use jprom::linalg::eigen::dense_generalized_eigenvalues;
use jprom::linalg::sparse_from_triplets;
use jprom::model::Damping;
use std::path::{Path, PathBuf};

fn data(model: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/calculix").join(model)
}

/// Frequencies (cycles per time unit) of the eigenvalue table of a ccx `.dat`.
fn dat_frequencies(path: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let lines = text.lines().skip_while(|l| !l.contains("E I G E N V A L U E   O U T P U T")).skip(1);
    let mut out = Vec::new();
    for l in lines {
        let f: Vec<&str> = l.split_whitespace().collect();
        if f.len() == 5 && f[0].parse::<usize>().is_ok() {
            out.push(f[3].parse().unwrap());
        } else if !out.is_empty() {
            break;
        }
    }
    assert!(out.len() >= 4, "{}: eigenvalue table", path.display());
    out
}

fn law() -> ContactLaw {
    ContactLaw::Friction3D { kt1: 1e3, kt2: 1e3, kn: 2e3, mu: 0.3, n0: 10.0 }
}

/// The block's reduction: a contact on every TIP node, a load at LOAD, outputs at OUT.
fn block_reduction(ccx: &jprom::io::calculix::CalculixModel, cb_modes: usize) -> Reduction {
    let tip = ccx.node_set("TIP").unwrap();
    Reduction {
        contacts: tip.iter().map(|&node| NodalContact { node, frame: IDENTITY_FRAME, law: law() }).collect(),
        harmonic_forces: ccx.node_set("LOAD").unwrap().iter().map(|&node| NodalForce { node, force: [0.0, 1.0, 0.0] }).collect(),
        outputs: ccx.node_set("OUT").unwrap().iter().map(|&node| (node, 1)).collect(),
        cb_modes,
        ..Reduction::default()
    }
}

fn free_hz(model: &jprom::model::Model) -> Vec<f64> {
    let lam = dense_generalized_eigenvalues(&model.stiffness, &model.mass).unwrap();
    lam.iter().map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)).collect()
}

#[test]
fn calculix_block_reduced_converges_to_calculix_frequencies() {
    let ccx = read_model(&data("block").join("block.inp")).unwrap();
    let fe = FeModel::from_calculix(&ccx).unwrap();
    assert_eq!(fe.n_dof(), ccx.n());
    let reference = dat_frequencies(&data("block").join("block_freq.dat"));
    let mut previous: Option<Vec<f64>> = None;
    for cb_modes in [4, 12, 30] {
        let spec = block_reduction(&ccx, cb_modes);
        let model = fe.reduce(&spec, Damping::default()).unwrap();
        let n_boundary_nodes = spec.contacts.len() + 2; // LOAD (255) is a TIP node; OUT adds 247 and 187
        assert_eq!(model.n_dof(), 3 * (n_boundary_nodes - 1) + cb_modes, "boundary DoFs + modes");
        assert_eq!(model.contacts.len(), spec.contacts.len());
        assert_eq!(model.output_dofs.len(), 3);
        let f = free_hz(&model);
        let errors: Vec<f64> = (0..4).map(|i| f[i] / reference[i] - 1.0).collect();
        println!("CB with {cb_modes:>2} modes: first four frequencies {:?}, relative to ccx {:?}", &f[..4], errors.iter().map(|e| format!("{e:.2e}")).collect::<Vec<_>>());
        for (i, e) in errors.iter().enumerate() {
            assert!(*e > -1e-6, "mode {i}: CB below the full model ({e:.2e})");
        }
        if let Some(p) = &previous {
            for i in 0..4 {
                assert!(f[i] <= p[i] * (1.0 + 1e-9), "mode {i} does not decrease with more modes");
            }
        }
        if cb_modes == 30 {
            assert!(errors.iter().all(|e| *e < 1e-4), "30 modes: {errors:?}");
        }
        previous = Some(f);
    }
}

#[test]
fn fe_model_errors_name_the_node() {
    let ccx = read_model(&data("block").join("block.inp")).unwrap();
    let fe = FeModel::from_calculix(&ccx).unwrap();
    let message = |e: JpError| e.to_string();
    // an id the model does not have
    let mut spec = block_reduction(&ccx, 4);
    spec.outputs.push((99999, 1));
    let e = message(fe.reduce(&spec, Damping::default()).unwrap_err());
    assert!(e.contains("node 99999"), "{e}");
    // a clamped node (ROOT) has no active DoF, so it is not a node of the reduced-to model
    let root = ccx.node_set("ROOT").unwrap()[0];
    let mut spec = block_reduction(&ccx, 4);
    spec.extra_nodes.push(root);
    let e = message(fe.reduce(&spec, Damping::default()).unwrap_err());
    assert!(e.contains(&format!("node {root}")), "{e}");
    // a contact node twice
    let mut spec = block_reduction(&ccx, 4);
    let first = spec.contacts[0].clone();
    spec.contacts.push(first);
    let e = message(fe.reduce(&spec, Damping::default()).unwrap_err());
    assert!(e.contains("contact node twice"), "{e}");
    // rows: out of range, or one row for two nodes
    let eye = |n: usize| sparse_from_triplets(n, n, (0..n).map(|i| (i, i, 1.0)).collect()).unwrap();
    let node = |id: i64, r: usize| FeNode { id, coords: None, dofs: [Some(r), Some(r + 1), Some(r + 2), None, None, None] };
    let e = message(FeModel::new(eye(6), eye(6), vec![node(1, 0), node(2, 4)]).unwrap_err());
    assert!(e.contains("node 2") && e.contains("beyond"), "{e}");
    let e = message(FeModel::new(eye(6), eye(6), vec![node(1, 0), node(2, 2)]).unwrap_err());
    assert!(e.contains("node 2") && e.contains("node 1"), "{e}");
    let e = message(FeModel::new(eye(6), eye(6), vec![node(1, 0), node(1, 3)]).unwrap_err());
    assert!(e.contains("node 1 is given twice"), "{e}");
    let e = message(FeModel::new(eye(6), eye(5), vec![node(1, 0)]).unwrap_err());
    assert!(e.contains("mass"), "{e}");
    // a rotation as output
    let mut spec = block_reduction(&ccx, 4);
    spec.outputs[0].1 = 4;
    let e = message(fe.reduce(&spec, Damping::default()).unwrap_err());
    assert!(e.contains("not a translation"), "{e}");
}

/// A cut-off frequency keeps exactly the fixed-interface modes below it: the block reduced with
/// a cut-off between its 7th and 8th fixed-interface modes equals the one reduced with 7 modes.
#[test]
fn craig_bampton_cutoff_keeps_the_modes_below_it() {
    let ccx = read_model(&data("block").join("block.inp")).unwrap();
    let fe = FeModel::from_calculix(&ccx).unwrap();
    // the boundary FeModel::reduce makes: contact nodes, then loaded, then output nodes, once each
    let spec0 = block_reduction(&ccx, 0);
    let mut nodes: Vec<i64> = spec0.contacts.iter().map(|c| c.node).collect();
    for id in spec0.harmonic_forces.iter().map(|f| f.node).chain(spec0.outputs.iter().map(|o| o.0)) {
        if !nodes.contains(&id) {
            nodes.push(id);
        }
    }
    let boundary: Vec<usize> = nodes.iter().flat_map(|&id| fe.node(id).unwrap().translations().unwrap()).collect();
    let all = jprom::fe::CraigBampton::reduce(&fe.stiffness, &fe.mass, &boundary, jprom::fe::CbOptions { n_modes: 30, keep_recovery: false, cutoff_hz: None }).unwrap();
    let hz = all.modal_frequencies_hz();
    let cut = 0.5 * (hz[6] + hz[7]);
    let mut spec = block_reduction(&ccx, 200);
    spec.cb_cutoff_hz = Some(cut);
    let with_cut = fe.reduce(&spec, Damping::default()).unwrap();
    let with_7 = fe.reduce(&block_reduction(&ccx, 7), Damping::default()).unwrap();
    assert_eq!(with_cut.n_dof(), with_7.n_dof(), "cut-off at {cut:.1} Hz keeps 7 modes");
    let (a, b) = (free_hz(&with_cut), free_hz(&with_7));
    for (x, y) in a.iter().zip(&b).take(10) {
        assert!((x / y - 1.0).abs() < 1e-8, "{x} vs {y}");
    }
    // a cap below the count under the cut-off wins; a bad cut-off is refused
    spec.cb_modes = 3;
    assert_eq!(fe.reduce(&spec, Damping::default()).unwrap().n_dof(), with_7.n_dof() - 4);
    spec.cb_cutoff_hz = Some(-1.0);
    let e = fe.reduce(&spec, Damping::default()).unwrap_err().to_string();
    assert!(e.contains("cut-off"), "{e}");
}

/// Fixing DoFs removes their rows and columns: the result equals the dense matrices with them
/// deleted, and a clamped node stiffens the structure.
#[test]
fn fixed_dofs_are_removed_from_the_fe_model() {
    let ccx = read_model(&data("block").join("block.inp")).unwrap();
    let fe = FeModel::from_calculix(&ccx).unwrap();
    let out = ccx.node_set("OUT").unwrap().to_vec();
    let fixed: Vec<(i64, usize)> = out.iter().flat_map(|&id| (0..3).map(move |d| (id, d))).collect();
    let clamped = fe.with_fixed(&fixed).unwrap();
    assert_eq!(clamped.n_dof(), fe.n_dof() - fixed.len());
    let removed: Vec<usize> = fixed.iter().map(|&(id, d)| fe.node(id).unwrap().dofs[d].unwrap()).collect();
    let kept: Vec<usize> = (0..fe.n_dof()).filter(|r| !removed.contains(r)).collect();
    let (k0, k1) = (jprom::linalg::sparse_to_dense(&fe.stiffness), jprom::linalg::sparse_to_dense(&clamped.stiffness));
    for (i, &ri) in kept.iter().enumerate().step_by(7) {
        for (j, &rj) in kept.iter().enumerate().step_by(5) {
            assert_eq!(k1[(i, j)], k0[(ri, rj)]);
        }
    }
    for &id in &out {
        assert!(clamped.node(id).unwrap().translations().is_err(), "node {id} keeps no translation");
    }
    let (f0, f1) = (fe.natural_frequencies_hz(3).unwrap(), clamped.natural_frequencies_hz(3).unwrap());
    assert!(f1[0] > f0[0], "clamping stiffens: {} vs {} Hz", f1[0], f0[0]);
    // errors name the node
    let e = fe.with_fixed(&[(99999, 0)]).unwrap_err().to_string();
    assert!(e.contains("node 99999"), "{e}");
    let e = fe.with_fixed(&[(out[0], 6)]).unwrap_err().to_string();
    assert!(e.contains("direction 6"), "{e}");
    let e = clamped.with_fixed(&[(out[0], 1)]).unwrap_err().to_string();
    assert!(e.contains(&format!("node {}", out[0])) && e.contains("no active direction 1"), "{e}");
}

/// `FeModel::unreduced`: the block without Craig-Bampton (every FE DoF, dense) has ccx's
/// frequencies, the contacts, loads and outputs on the nodes' own DoFs, and is the limit the
/// reduced models converge to from above.
#[test]
fn calculix_block_unreduced_has_calculix_frequencies_and_bounds_the_reduced_ones() {
    let ccx = read_model(&data("block").join("block.inp")).unwrap();
    let fe = FeModel::from_calculix(&ccx).unwrap();
    let spec = block_reduction(&ccx, 12);
    let full = fe.unreduced(&spec, Damping::default()).unwrap();
    assert_eq!(full.n_dof(), fe.n_dof());
    let tip = ccx.node_set("TIP").unwrap();
    for (c, &node) in full.contacts.iter().zip(tip) {
        assert_eq!(c.dofs_a, fe.node(node).unwrap().translations().unwrap().to_vec());
    }
    let out = ccx.node_set("OUT").unwrap();
    assert_eq!(full.output_dofs, out.iter().map(|&id| fe.node(id).unwrap().translations().unwrap()[1]).collect::<Vec<_>>());
    let load = ccx.node_set("LOAD").unwrap();
    let total: f64 = full.excitation.harmonics[0].cos.iter().sum();
    assert_eq!(total, load.len() as f64, "one unit force along y per LOAD node");
    let reference = dat_frequencies(&data("block").join("block_freq.dat"));
    let f = free_hz(&full);
    let reduced = free_hz(&fe.reduce(&spec, Damping::default()).unwrap());
    for i in 0..4 {
        let e = f[i] / reference[i] - 1.0;
        println!("mode {i}: unreduced {:.6} Hz, ccx {:.6} Hz ({e:.1e}), CB(12) {:.6} Hz", f[i], reference[i], reduced[i]);
        assert!(e.abs() < 2e-5, "mode {i}: {e:.2e} from ccx");
        assert!(reduced[i] >= f[i] * (1.0 - 1e-9), "mode {i}: CB below the unreduced model");
    }
}
