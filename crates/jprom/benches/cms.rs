//! Build time and peak memory of the built-in blade and its Craig-Bampton reduction (50
//! interior modes), at three contact refinements. Each case runs in a fresh subprocess so that
//! the peak resident memory (VmHWM from /proc/self/status) is its own.
//!
//! `cargo bench --bench cms` prints a table. The ~2,000-contact-node case builds the FE model
//! only, unless `JPROM_BENCH_LARGE=1` (its Craig-Bampton with the constraint modes kept, as
//! here, needs their ~6 GB and about 10 minutes: see the report in the cms module doc;
//! `jp_blade_2k` reduces it without them).

mod common;

use common::vm_hwm_mb;
use jprom::fe::{BladeParams, BuiltinBlade, CbOptions};
use std::time::Instant;

fn run_case(refinement: usize, do_cb: bool) {
    let p = BladeParams { refinement, ..Default::default() };
    let t = Instant::now();
    let fe = BuiltinBlade::build(&p).expect("build");
    let t_build = t.elapsed().as_secs_f64();
    let (t_cb, n_red, f1) = if do_cb {
        let t = Instant::now();
        let cb = fe.reduce_with(CbOptions { n_modes: 50, keep_recovery: true, cutoff_hz: None }).expect("reduce");
        let t_cb = t.elapsed().as_secs_f64();
        let f1 = if cb.cb.n_reduced() <= 1500 { cb.natural_frequencies_hz(true).map(|f| f[0]).unwrap_or(f64::NAN) } else { f64::NAN };
        (t_cb, cb.cb.n_reduced(), f1)
    } else {
        (f64::NAN, 0, f64::NAN)
    };
    println!(
        "{:>4} {:>8} {:>9} {:>9.2} {:>9.2} {:>8} {:>10.1} {:>9.0}",
        refinement,
        fe.contacts.len(),
        fe.n_dof(),
        t_build,
        t_cb,
        n_red,
        f1,
        vm_hwm_mb()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(pos) = args.iter().position(|a| a == "--case") {
        let r: usize = args[pos + 1].parse().expect("refinement");
        let cb = args.get(pos + 2).map(|s| s == "cb").unwrap_or(true);
        run_case(r, cb);
        return;
    }
    let large = std::env::var("JPROM_BENCH_LARGE").map(|v| v == "1").unwrap_or(false);
    println!("built-in blade + Craig-Bampton (50 modes); each row a fresh process");
    println!("{:>4} {:>8} {:>9} {:>9} {:>9} {:>8} {:>10} {:>9}", "r", "contacts", "DoFs", "build s", "CB s", "n_red", "stuck Hz", "VmHWM MB");
    let exe = std::env::current_exe().expect("exe");
    for (r, cb) in [(1usize, true), (5, true), (15, large)] {
        let out = std::process::Command::new(&exe)
            .args(["--case", &r.to_string(), if cb { "cb" } else { "build" }])
            .output()
            .expect("spawn");
        print!("{}", String::from_utf8_lossy(&out.stdout));
        if !out.status.success() {
            println!("case r={r} failed: {}", String::from_utf8_lossy(&out.stderr));
        }
    }
}
