//! Every damping form against a linear FRF computed independently: the CalculiX block
//! (tests/data/calculix/block) reduced by Craig-Bampton with all its fixed-interface modes (an
//! exact change of coordinates), solved by jprom's HBM at H = 1, against a dense complex solve
//! `(K (1 + i eta) - w^2 M + i w C) x = f` on the full FE matrices. Forms: Rayleigh `alpha M +
//! beta K`, the FE code's `C` (reduced with the model), modal ratios per mode (on the reduced
//! model, against the full model's modes), the structural loss factor, and all at once. Then
//! the same forms through the condensed system (docs/formulation.md §7) against the full one
//! with a stuck contact, and the FE model's natural frequencies against ccx's `.dat`.

use faer::prelude::Solve;
use faer::{c64, Mat};
use jprom::contact::{ContactLaw, IDENTITY_FRAME};
use jprom::condensation::CondensedSystem;
use jprom::fe::{FeModel, NodalContact, NodalForce, Reduction};
use jprom::hbm::{solve_point, FullSystem, HbmOptions};
use jprom::io::calculix::read_model;
use jprom::linalg::eigen::dense_generalized_modes;
use jprom::linalg::sparse::{sparse_from_triplets, sparse_to_dense, sparse_triplets};
use jprom::model::{Damping, Model};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

fn data(model: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/calculix").join(model)
}

/// One damping form: how jprom is told, and the full-model `C` and `eta` it stands for.
struct Form {
    name: &'static str,
    rayleigh: Damping,
    fe_c: bool,
    modal: bool,
    eta: f64,
}

/// A diagonally dominant sparse symmetric `C` with the mass matrix's pattern plus a
/// stiffness part: `c_m M + c_k K` with the off-diagonal mass entries halved (so not Rayleigh).
fn fe_damping(fe: &FeModel) -> jprom::linalg::SparseMat {
    let mut t: Vec<(usize, usize, f64)> = sparse_triplets(&fe.mass).into_iter().map(|(i, j, v)| (i, j, if i == j { 40.0 * v } else { 20.0 * v })).collect();
    t.extend(sparse_triplets(&fe.stiffness).into_iter().map(|(i, j, v)| (i, j, 2e-7 * v)));
    sparse_from_triplets(fe.n_dof(), fe.n_dof(), t).unwrap()
}

/// Modal damping ratio of a mode at `hz`: smooth in frequency, so degenerate modes (the
/// block's bending pairs) get equal ratios and the damping does not depend on their basis.
fn ratio_at(hz: f64, f1: f64) -> f64 {
    0.004 + 0.002 * (hz / f1).ln()
}

/// How many of the lowest modes get a ratio (the others none): the first frequency gap of
/// more than 1 % past the 8th mode, so that no degenerate pair is split. (Damping every mode
/// of an exact reduction would weigh the round-off in its highest, least accurate modes by
/// `2 zeta omega`; a user damps the modes of the band.)
fn damped_modes(hz: &[f64]) -> usize {
    (8..hz.len()).find(|&r| hz[r] > 1.01 * hz[r - 1]).unwrap_or(hz.len())
}

#[test]
fn each_damping_form_reproduces_the_dense_complex_frf() {
    let ccx = read_model(&data("block").join("block.inp")).unwrap();
    let mut fe = FeModel::from_calculix(&ccx).unwrap();
    let n = fe.n_dof();
    let (k, m) = (sparse_to_dense(&fe.stiffness), sparse_to_dense(&fe.mass));
    let c_fe = fe_damping(&fe);
    fe.set_damping(c_fe.clone()).unwrap();
    let c_fe = sparse_to_dense(&c_fe);
    let (lambda, phi) = dense_generalized_modes(&k, &m).unwrap();
    let hz: Vec<f64> = lambda.iter().map(|l| l.sqrt() / (2.0 * PI)).collect();
    let n_damped = damped_modes(&hz);
    let ratios: Vec<f64> = hz.iter().enumerate().map(|(r, &f)| if r < n_damped { ratio_at(f, hz[0]) } else { 0.0 }).collect();
    let mphi = &m * &phi;
    let c_modal = Mat::from_fn(n, n, |i, r| mphi[(i, r)] * 2.0 * ratios[r] * 2.0 * PI * hz[r]) * mphi.transpose();

    let load = ccx.node_set("LOAD").unwrap()[0];
    let out = ccx.node_set("OUT").unwrap().to_vec();
    let force = [0.3, 1.0, -0.2];
    let spec = Reduction {
        harmonic_forces: vec![NodalForce { node: load, force }],
        static_forces: vec![NodalForce { node: load, force: [0.0, 0.0, 1.0] }],
        outputs: out.iter().flat_map(|&o| (0..3).map(move |d| (o, d))).collect(),
        cb_modes: n, // every interior mode: T is square, the reduction exact
        ..Reduction::default()
    };
    let mut f = vec![0.0; n];
    let rows = fe.node(load).unwrap().translations().unwrap();
    for a in 0..3 {
        f[rows[a]] = force[a];
    }
    let out_rows: Vec<usize> = out.iter().flat_map(|&o| fe.node(o).unwrap().translations().unwrap()).collect();

    let (alpha, beta) = (25.0, 3e-7);
    let forms = [
        Form { name: "Rayleigh", rayleigh: Damping { mass_coeff: alpha, stiffness_coeff: beta }, fe_c: false, modal: false, eta: 0.0 },
        Form { name: "FE matrix C", rayleigh: Damping::default(), fe_c: true, modal: false, eta: 0.0 },
        Form { name: "modal ratios", rayleigh: Damping::default(), fe_c: false, modal: true, eta: 0.0 },
        Form { name: "loss factor", rayleigh: Damping::default(), fe_c: false, modal: false, eta: 0.02 },
        Form { name: "all at once", rayleigh: Damping { mass_coeff: alpha, stiffness_coeff: beta }, fe_c: true, modal: true, eta: 0.01 },
    ];
    let opts = HbmOptions::default();
    let mut worst = 0.0f64;
    for form in &forms {
        let mut fe_form = fe.clone();
        if !form.fe_c {
            fe_form = FeModel::new(fe.stiffness.clone(), fe.mass.clone(), fe.nodes().to_vec()).unwrap();
        }
        let mut model = fe_form.reduce(&spec, form.rayleigh).unwrap();
        assert_eq!(model.added_damping.is_some(), form.fe_c, "{}", form.name);
        if form.modal {
            // the reduced model's modes are the full model's (exact reduction): same ratios
            let reduced: Vec<f64> = jprom::model::modes::natural_modes(&model, jprom::model::modes::Boundary::Free).unwrap().iter().map(|m| m.frequency_hz).collect();
            assert_eq!(damped_modes(&reduced), n_damped);
            let r: Vec<f64> = reduced[..n_damped].iter().map(|&f| ratio_at(f, hz[0])).collect();
            let fe_part = model.added_damping.take();
            model.set_modal_damping(&r, 0.0).unwrap();
            if let Some(c) = fe_part {
                model.added_damping = Some(model.added_damping.take().unwrap() + c);
            }
        }
        model.loss_factor = form.eta;
        model.validate().unwrap();
        // the independent full-model operator
        let c_full = Mat::from_fn(n, n, |i, j| {
            form.rayleigh.mass_coeff * m[(i, j)]
                + form.rayleigh.stiffness_coeff * k[(i, j)]
                + if form.fe_c { c_fe[(i, j)] } else { 0.0 }
                + if form.modal { c_modal[(i, j)] } else { 0.0 }
        });
        let sys = FullSystem::new(&model, 1).unwrap();
        for w in [0.8, 0.995, 1.0, 1.6, 2.9].map(|s| s * 2.0 * PI * hz[0]) {
            let d = Mat::from_fn(n, n, |i, j| c64::new(k[(i, j)] - w * w * m[(i, j)], w * c_full[(i, j)] + form.eta * k[(i, j)]));
            let rhs = Mat::from_fn(n, 1, |i, _| c64::new(f[i], 0.0));
            let x = d.partial_piv_lu().solve(&rhs);
            let p = solve_point(&sys, w, None, &opts).unwrap();
            assert!(p.converged, "{} at {w}", form.name);
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for (j, &r) in out_rows.iter().enumerate() {
                // x = xc cos + xs sin  <->  complex amplitude xc - i xs
                let (xc, xs) = (p.output_coeff(1, j), p.output_coeff(2, j));
                num += (xc - x[(r, 0)].re).powi(2) + (xs + x[(r, 0)].im).powi(2);
                den += x[(r, 0)].norm().powi(2);
            }
            let e = (num / den).sqrt();
            worst = worst.max(e);
            assert!(e < 1e-8, "{} at {:.4} Hz: relative difference {e:.2e}", form.name, w / (2.0 * PI));
        }
    }
    println!("{n}-DoF CalculiX block, 5 damping forms x 5 frequencies: largest relative difference to the dense complex FRF {worst:.2e}");
}

/// The condensed system (contact coordinates only, §7) carries every form as the full system
/// does: same first-harmonic response with a stuck (preloaded, high-friction) contact.
#[test]
fn condensed_system_carries_every_damping_form() {
    let ccx = read_model(&data("block").join("block.inp")).unwrap();
    let mut fe = FeModel::from_calculix(&ccx).unwrap();
    fe.set_damping(fe_damping(&fe)).unwrap();
    let tip = ccx.node_set("TIP").unwrap();
    // stuck at every sample: friction and preload far above what the load can mobilise
    let law = ContactLaw::Friction3D { kt1: 1e5, kt2: 1e5, kn: 2e5, mu: 10.0, n0: 1e4 };
    let spec = Reduction {
        contacts: tip.iter().take(4).map(|&node| NodalContact { node, frame: IDENTITY_FRAME, law: law.clone() }).collect(),
        harmonic_forces: vec![NodalForce { node: ccx.node_set("LOAD").unwrap()[0], force: [0.0, 1.0, 0.0] }],
        outputs: ccx.node_set("OUT").unwrap().iter().map(|&o| (o, 1)).collect(),
        cb_modes: 12,
        ..Reduction::default()
    };
    let mut model: Model = fe.reduce(&spec, Damping { mass_coeff: 10.0, stiffness_coeff: 1e-7 }).unwrap();
    let c = model.added_damping.take().unwrap();
    model.set_modal_damping(&[0.01, 0.02], 0.005).unwrap();
    model.added_damping = Some(model.added_damping.take().unwrap() + c);
    model.loss_factor = 0.015;
    let opts = HbmOptions::default();
    let full = FullSystem::new(&model, 3).unwrap();
    let condensed = CondensedSystem::new(&model, 3).unwrap();
    let stuck = jprom::model::modes::natural_modes(&model, jprom::model::modes::Boundary::Stuck).unwrap();
    for s in [0.7, 1.0, 1.3] {
        let w = s * 2.0 * PI * stuck[0].frequency_hz;
        let a = solve_point(&full, w, None, &opts).unwrap();
        let b = solve_point(&condensed, w, None, &opts).unwrap();
        let d: f64 = a.outputs.iter().zip(&b.outputs).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
        let r: f64 = a.outputs.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(d <= 1e-8 * r, "at {s} x the first stuck frequency: full and condensed differ by {:.2e}", d / r);
    }
}

#[test]
fn fe_natural_frequencies_match_calculix() {
    for name in ["block", "plate"] {
        let fe = FeModel::from_calculix(&read_model(&data(name).join(format!("{name}.inp"))).unwrap()).unwrap();
        let text = std::fs::read_to_string(data(name).join(format!("{name}_freq.dat"))).unwrap();
        let lines = text.lines().skip_while(|l| !l.contains("E I G E N V A L U E   O U T P U T")).skip(1);
        let mut ccx: Vec<f64> = Vec::new();
        for l in lines {
            let f: Vec<&str> = l.split_whitespace().collect();
            if f.len() == 5 && f[0].parse::<usize>().is_ok() {
                ccx.push(f[3].parse().unwrap());
            } else if !ccx.is_empty() {
                break;
            }
        }
        let got = fe.natural_frequencies_hz(ccx.len()).unwrap();
        for (g, c) in got.iter().zip(&ccx) {
            assert!((g / c - 1.0).abs() < 1e-6, "{name}: {g} Hz vs ccx {c} Hz");
        }
    }
}
