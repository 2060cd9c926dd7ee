//! FE -> Craig-Bampton at user-model sizes (issue 13): the twisted hex8 plate of
//! `fe::PlateFe` meshed to about 60,000 and 200,000 DoFs, turned into a user's FE model
//! (`fe::FeModel`, node ids and DoFs) and reduced by `FeModel::reduce` to 50 fixed-interface
//! modes and the tip contacts', load's and outputs' nodes. Prints the time of each stage and
//! the peak resident memory after it (VmHWM from /proc/self/status); each size runs in a
//! fresh process so that its peak is its own.
//!
//! `cargo bench --bench fe_cb` runs both sizes; `cargo bench --bench fe_cb -- 60k` one of them.
//!
//! Measured (2 cores, quiet machine, 2026-12-01): 60k (60,147 DoFs, 41 tip contacts) CB 13.5 s;
//! 200k (200,385 DoFs, 61 tip contacts, factor of `K_ii` 186 M values) assembly 7.3 s, CB 87 s
//! (91.7 s and 99.6 s in all on main at 74d3a2d), 3.3 GB peak, with the Lanczos subspace of
//! `3 n_modes` that `linalg::lanczos` uses above `LARGE_MODEL_DOFS` (with `2 n_modes` its
//! modes had not converged after 14 min). 2026-12-03 at 4163e0b (the modes alongside the
//! boundary blocks, the block buffers reused, the pruned solves): 200k assembly 4.9 s,
//! CB 45.1 s, 50.2 s in all, 4.7 GB peak. 2026-12-04, with the sparse Cholesky ordered by
//! nested dissection where that fills less than AMD (`linalg::ordering`, from 50,000
//! unknowns): 200k CB 49.6 -> 39.5 s, peak 4,682 -> 4,179 MB (A/B on this machine, 70f698c
//! against its successor); 60k 6.7 -> 6.5 s.

mod common;

use common::vm_hwm_mb;
use jprom::fe::{PlateFe, PlateParams};
use jprom::linalg::eigen::dense_generalized_eigenvalues;
use jprom::model::Damping;
use std::time::Instant;

/// (label, elements along span, chord, thickness).
const CASES: [(&str, usize, usize, usize); 2] = [("60k", 163, 40, 2), ("200k", 219, 60, 4)];

fn run_case(label: &str, n_span: usize, n_chord: usize, n_thickness: usize) {
    let p = PlateParams { n_span, n_chord, n_thickness, ..PlateParams::default() };
    let stage = |name: &str, secs: f64| println!("{label:>5} {name:<34} {secs:>8.2} s  VmHWM {:>7.0} MB", vm_hwm_mb());
    let t = Instant::now();
    let plate = PlateFe::build(&p).expect("plate");
    stage("hex8 assembly of K and M", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let (fe, spec) = plate.fe_model(50).expect("FE model");
    drop(plate);
    let (n, nnz) = (fe.n_dof(), fe.stiffness.compute_nnz());
    stage("FeModel (node table, checks)", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let model = fe.reduce(&spec, Damping::default()).expect("Craig-Bampton");
    stage("Craig-Bampton, 50 modes (reduce)", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let f1 = dense_generalized_eigenvalues(&model.stiffness, &model.mass).map(|l| l[0].sqrt() / (2.0 * std::f64::consts::PI)).unwrap_or(f64::NAN);
    stage("first free mode of the CB model", t.elapsed().as_secs_f64());
    println!("{label:>5} {n} DoFs, K {nnz} entries, {} tip contacts, reduced to {} DoFs, first free mode {f1:.2} Hz", spec.contacts.len(), model.n_dof());
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(pos) = args.iter().position(|a| a == "--case") {
        let (label, s, c, t) = CASES.iter().copied().find(|c| c.0 == args[pos + 1]).expect("case");
        run_case(label, s, c, t);
        return;
    }
    // `cargo bench` passes `--bench`; any other argument picks the cases by label
    let only: Vec<&String> = args.iter().skip(1).filter(|a| !a.starts_with("--")).collect();
    println!("FE (hex8 plate) -> Craig-Bampton (50 modes); rayon threads: {}; each size a fresh process", rayon::current_num_threads());
    let exe = std::env::current_exe().expect("exe");
    for (label, ..) in CASES {
        if !only.is_empty() && !only.iter().any(|a| a.as_str() == label) {
            continue;
        }
        let t = Instant::now();
        let out = std::process::Command::new(&exe).args(["--case", label]).output().expect("spawn");
        print!("{}", String::from_utf8_lossy(&out.stdout));
        if out.status.success() {
            println!("{label:>5} total {:.1} s", t.elapsed().as_secs_f64());
        } else {
            println!("{label:>5} failed ({}): {}", out.status, String::from_utf8_lossy(&out.stderr).lines().last().unwrap_or(""));
        }
    }
}
