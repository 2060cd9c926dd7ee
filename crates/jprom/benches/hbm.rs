//! Time per converged frequency point of the condensed full-order HBM solve on the built-in
//! blade (Craig-Bampton, 50 modes), for 18 and 242 contact nodes at H = 1 and 3, and where
//! the time goes: the linear part (condensation `H_h(omega)`), one residual + Jacobian
//! evaluation (AFT and assembly), one LU of the Jacobian.
//!
//! `cargo bench --bench hbm` prints a table. `JPROM_BENCH_LARGE=1` adds a synthetic
//! 1,800-contact case at H = 1 (condensed Jacobian 16,200 x 16,200: about 2.1 GB).

mod common;

use common::{blade_model, vm_hwm_mb};
use faer::Mat;
use jprom::aft::AftPlan;
use jprom::condensation::CondensedSystem;
use jprom::contact::{Contact, ContactLaw, IDENTITY_FRAME};
use jprom::hbm::residual::{evaluate, ResidualWorkspace};
use jprom::hbm::{sweep, HarmonicSystem, HbmOptions, SweepOptions};
use jprom::model::{Damping, Excitation, HarmonicForce, Model};
use std::ops::ControlFlow;
use std::time::Instant;

/// `n` masses on springs, each pressed on ground by a 3D contact, coupled in a ring.
fn synthetic_model(n_contacts: usize) -> Model {
    let n = 3 * n_contacts + 60;
    let mut k = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        k[(i, i)] += 3.0e5;
        let j = (i + 3) % n;
        k[(i, j)] -= 1.0e5;
        k[(j, i)] -= 1.0e5;
        k[(i, i)] += 1.0e5;
        k[(j, j)] += 1.0e5;
    }
    let m = Mat::from_fn(n, n, |i, j| if i == j { 1e-3 } else { 0.0 });
    let law = ContactLaw::Friction3D { kt1: 2.0e4, kt2: 2.0e4, kn: 2.3e4, mu: 0.4, n0: 30.0 };
    let contacts = (0..n_contacts).map(|c| Contact::ground_3d([3 * c, 3 * c + 1, 3 * c + 2], IDENTITY_FRAME, law.clone())).collect();
    let f1: Vec<f64> = (0..n).map(|i| if i % 3 == 0 { 1.0 } else { 0.0 }).collect();
    let exc = Excitation { static_force: vec![0.0; n], harmonics: vec![HarmonicForce { cos: f1, sin: vec![0.0; n] }], dynamic_scale: 20.0 };
    Model::new(m, k, Damping { mass_coeff: 0.0, stiffness_coeff: 1e-6 }, exc, contacts, vec![0]).expect("synthetic")
}

fn run(label: &str, model: &Model, h: usize, band: (f64, f64)) {
    let opts = HbmOptions::default();
    let sys = CondensedSystem::new(model, h).expect("condense");
    let n_unknowns = sys.layout().total();
    let sopts = SweepOptions { max_points: 25, ..SweepOptions::band(band.0, band.1) };
    let t = Instant::now();
    let res = sweep(&sys, &sopts, &opts, &mut |_| ControlFlow::Continue(())).expect("sweep");
    let per_point = t.elapsed().as_secs_f64() / res.points.len().max(1) as f64;
    let iters: usize = res.points.iter().map(|p| p.iterations).sum();
    let p = res.points.last().expect("a point");
    // components at the last point
    let t = Instant::now();
    let lin = sys.linear_part(p.omega).expect("linear part");
    let t_lin = t.elapsed().as_secs_f64();
    let plan = AftPlan::new(h, jprom::hbm::default_nt(h)).expect("plan");
    let mut ws = ResidualWorkspace::new();
    let t = Instant::now();
    let (_, jac) = evaluate(&sys, &lin, Some(&plan), &p.z, true, &mut ws).expect("evaluate");
    let t_eval = t.elapsed().as_secs_f64();
    let jac = jac.expect("jacobian").into_dense();
    let t = Instant::now();
    let lu = jac.partial_piv_lu();
    let t_lu = t.elapsed().as_secs_f64();
    std::hint::black_box(&lu);
    let slip: usize = p.contact_cycles.iter().map(|c| c.states.iter().filter(|s| **s != jprom::contact::ContactState::Stick).count()).sum();
    let total: usize = p.contact_cycles.iter().map(|c| c.states.len()).sum();
    println!(
        "{:<18} {:>3} {:>8} {:>7} {:>9.4} {:>7.1} {:>9.5} {:>9.5} {:>9.5} {:>7.0}% {:>8.0}",
        label,
        h,
        model.contacts.len(),
        n_unknowns,
        per_point,
        iters as f64 / res.points.len() as f64,
        t_lin,
        t_eval,
        t_lu,
        100.0 * slip as f64 / total.max(1) as f64,
        vm_hwm_mb()
    );
}

fn main() {
    println!("condensed full-order HBM, time per converged point of a 25-point sweep near resonance");
    println!(
        "{:<18} {:>3} {:>8} {:>7} {:>9} {:>7} {:>9} {:>9} {:>9} {:>8} {:>8}",
        "model", "H", "contacts", "unknwn", "s/point", "it/pt", "linear s", "AFT+J s", "LU s", "not stk", "VmHWM MB"
    );
    let band = (2.0 * std::f64::consts::PI * 2140.0, 2.0 * std::f64::consts::PI * 2190.0);
    for refinement in [1usize, 5] {
        let model = blade_model(refinement, 30.0);
        for h in [1usize, 3] {
            run(&format!("blade r={refinement}"), &model, h, band);
        }
    }
    if std::env::var("JPROM_BENCH_LARGE").map(|v| v == "1").unwrap_or(false) {
        let model = synthetic_model(1800);
        run("synthetic", &model, 1, (2.0e4, 2.2e4));
    }
}
