//! Full-order cost on a chain of `n` Jenkins-damped masses at H = 5 (issue 18's benchmark):
//! time to place the `n` contacts one by one (each addition checked as the C API checks it),
//! time per converged frequency point of the full and the condensed system, the peak resident
//! memory and the share of system time (allocation churn shows there).
//!
//! `cargo bench -p jprom --bench chain_fo` prints a table for n = 20, 50, 200;
//! `JPROM_BENCH_LARGE=1` adds n = 1,000 (the dense path then needs several GB and minutes per
//! point: the HBM Jacobian is solved dense although it has O(n H^2) nonzeros).
//! A Python peer (pyHarm) is timed beside it only if `python3 -c "import pyHarm"` works.

mod common;

use common::vm_hwm_mb;
use faer::Mat;
use jprom::condensation::CondensedSystem;
use jprom::contact::Contact;
use jprom::hbm::{solve_point, FullSystem, HarmonicSystem, HbmOptions};
use jprom::model::{Damping, Excitation, HarmonicForce, Model};
use std::time::Instant;

const H: usize = 5;

/// User and system CPU seconds of this process so far (`/proc/self/stat`, clock ticks of 100 Hz).
fn cpu_seconds() -> (f64, f64) {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0) / 100.0;
    (tick(11), tick(12)) // utime, stime are fields 14 and 15 of the whole line
}

/// `n` unit masses in a chain of unit springs, the first tied to ground; each mass has a Jenkins
/// element to ground (kt = 0.5, slip force 0.05); the last mass is driven at amplitude 0.1.
fn chain(n: usize) -> (Model, f64) {
    let mut k = Mat::<f64>::zeros(n, n);
    k[(0, 0)] += 1.0;
    for i in 0..n - 1 {
        k[(i, i)] += 1.0;
        k[(i + 1, i + 1)] += 1.0;
        k[(i, i + 1)] -= 1.0;
        k[(i + 1, i)] -= 1.0;
    }
    let m = Mat::<f64>::identity(n, n);
    let mut f1 = vec![0.0; n];
    f1[n - 1] = 0.1;
    let exc = Excitation { static_force: vec![0.0; n], harmonics: vec![HarmonicForce { cos: f1, sin: vec![0.0; n] }], dynamic_scale: 1.0 };
    let mut model = Model::new(m, k, Damping { mass_coeff: 0.0, stiffness_coeff: 0.01 }, exc, Vec::new(), vec![n - 1]).expect("chain");
    let t = Instant::now();
    for i in 0..n {
        model.contacts.push(Contact::jenkins(i, None, 0.5, 0.05, 1.0));
        model.validate_contacts().expect("contact");
    }
    (model, t.elapsed().as_secs_f64())
}

fn main() {
    let mut sizes = vec![20, 50, 200];
    if std::env::var("JPROM_BENCH_LARGE").is_ok() {
        sizes.push(1000);
    }
    let opts = HbmOptions::with_harmonics(H);
    println!("chain of n Jenkins-damped masses, H = {H}, nt = {}, one point from zero near the first stuck resonance", opts.nt());
    println!("{:>6} {:>12} {:>12} {:>8} {:>14} {:>8} {:>10} {:>10}", "n", "add n [s]", "full [s/pt]", "iters", "condensed [s]", "iters", "sys share", "peak MB");
    for n in sizes {
        let (model, add_s) = chain(n);
        // near the lowest stuck natural frequency (K + 0.5 I): omega_1 ~ sqrt(0.5 + small)
        let omega = 0.75;
        let (u0, s0) = cpu_seconds();
        let full = FullSystem::new(&model, &opts).expect("full system");
        let t = Instant::now();
        let p = solve_point(&full, omega, None, &opts);
        let full_s = t.elapsed().as_secs_f64();
        let full_it = p.as_ref().map(|p| p.iterations.to_string()).unwrap_or_else(|e| format!("fail: {e}"));
        let cond = CondensedSystem::new(&model, &opts).expect("condensed system");
        let t = Instant::now();
        let q = solve_point(&cond, omega, None, &opts);
        let cond_s = t.elapsed().as_secs_f64();
        let cond_it = q.as_ref().map(|p| p.iterations.to_string()).unwrap_or_else(|e| format!("fail: {e}"));
        if let (Ok(p), Ok(q)) = (&p, &q) {
            let (a, b) = (p.output_amplitude(1, 0), q.output_amplitude(1, 0));
            assert!((a - b).abs() <= 1e-6 * a.abs().max(1e-12), "full {a} vs condensed {b}");
        }
        let (u1, s1) = cpu_seconds();
        let share = if u1 + s1 > u0 + s0 { (s1 - s0) / ((u1 - u0) + (s1 - s0)) } else { 0.0 };
        println!("{n:>6} {add_s:>12.4} {full_s:>12.3} {full_it:>8} {cond_s:>14.3} {cond_it:>8} {:>9.0}% {:>10.0}", 100.0 * share, vm_hwm_mb());
        let _ = full.layout();
    }
    let peer = std::process::Command::new("python3").args(["-c", "import pyHarm"]).output();
    match peer {
        Ok(o) if o.status.success() => println!("pyHarm is installed: time it on the same chain by hand (no driver here yet)"),
        _ => println!("pyHarm is not installed: no peer ratio"),
    }
}
