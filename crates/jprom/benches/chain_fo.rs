//! Full-order cost on a chain of `n` Jenkins-damped masses at H = 5 (issue 18's benchmark):
//! time to place the `n` contacts one by one (each addition checked as the C API checks it:
//! on its own and against the earlier ones, `Model::validate_contact` and `ContactTopology::add`),
//! time per converged frequency point of the full and the condensed system, the peak resident
//! memory, the share of system time, and the heap allocations per Newton iteration of the full
//! solve (count and MB, from a counting allocator: the allocation churn of the iteration).
//!
//! `cargo bench -p jprom --bench chain_fo` prints a table for n = 20, 50, 200, 1,000 (the full
//! system as stored by default: sparse HBM Jacobian and sparse LU from 1,000 unknowns; up to
//! n = 200 also the dense and the condensed solve, each checked against it);
//! `JPROM_BENCH_LARGE=1` adds n = 5,000.
//! A Python peer (pyHarm) is timed beside it only if `python3 -c "import pyHarm"` works.

mod common;

use common::vm_hwm_mb;
use jprom::condensation::CondensedSystem;
use jprom::hbm::full::SPARSE_MIN_UNKNOWNS;
use jprom::hbm::{solve_point, FullSystem, HbmOptions, Storage};
use jprom::model::contact_coordinates::ContactTopology;
use jprom::model::Model;
use jprom_testkit::chain::jenkins_chain;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

const H: usize = 5;

/// The system allocator, counting allocations and bytes (the allocation churn of a solve).
struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);
static BYTES: AtomicUsize = AtomicUsize::new(0);
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(layout.size(), Ordering::Relaxed);
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(new_size, Ordering::Relaxed);
        System.realloc(ptr, layout, new_size)
    }
}
#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocated() -> (usize, usize) {
    (ALLOCS.load(Ordering::Relaxed), BYTES.load(Ordering::Relaxed))
}

/// User and system CPU seconds of this process so far (`/proc/self/stat`, clock ticks of 100 Hz).
fn cpu_seconds() -> (f64, f64) {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0) / 100.0;
    (tick(11), tick(12)) // utime, stime are fields 14 and 15 of the whole line
}

/// The chain of [`jenkins_chain`] (n unit masses, a Jenkins element each to ground, kt = 0.5,
/// slip force 0.05, the last mass driven at 0.1), and the time its n contacts take to add one by
/// one with the checks the C API makes for each.
fn chain(n: usize) -> (Model, f64) {
    let mut model = jenkins_chain(n, 0.05, 0.1, false);
    let contacts = std::mem::take(&mut model.contacts);
    let t = Instant::now();
    let mut topology = ContactTopology::default();
    for (i, c) in contacts.into_iter().enumerate() {
        model.contacts.push(c);
        model.validate_contact(i).expect("contact");
        topology.add(&model.contacts, i).expect("topology");
    }
    (model, t.elapsed().as_secs_f64())
}

fn main() {
    let mut sizes = vec![20, 50, 200, 1000];
    if std::env::var("JPROM_BENCH_LARGE").is_ok() {
        sizes.push(5000);
    }
    let opts = HbmOptions::default();
    println!("chain of n Jenkins-damped masses, H = {H}, nt = {}, one point from zero near the first stuck resonance", jprom::hbm::default_nt(H));
    println!("full = the full-order system as stored by default (sparse from {SPARSE_MIN_UNKNOWNS} unknowns when K, M, C are sparse); dense and condensed up to n = {DENSE_UP_TO}");
    println!(
        "{:>6} {:>10} {:>8} {:>12} {:>6} {:>12} {:>12} {:>12} {:>14} {:>10} {:>8}",
        "n", "add n [s]", "storage", "full [s/pt]", "iters", "allocs/iter", "MB/iter", "dense [s/pt]", "condensed [s]", "sys share", "peak MB"
    );
    // one solve first: the process's one-time allocations (thread pools, FFT plans) are not
    // the iteration's
    let (warm, _) = chain(20);
    let (w0, wb0) = allocated();
    let _ = solve_point(&FullSystem::new(&warm, H).expect("full system"), 0.75, None, &opts);
    let (w1, wb1) = allocated();
    println!("warm-up solve (n = 20): {} allocations, {:.1} MB", w1 - w0, (wb1 - wb0) as f64 / 1e6);
    for n in sizes {
        let (model, add_s) = chain(n);
        // near the lowest stuck natural frequency (K + 0.5 I): omega_1 ~ sqrt(0.5 + small)
        let omega = 0.75;
        let (u0, s0) = cpu_seconds();
        let full = FullSystem::new(&model, H).expect("full system");
        let (a0, b0) = allocated();
        let t = Instant::now();
        let p = solve_point(&full, omega, None, &opts);
        let full_s = t.elapsed().as_secs_f64();
        let (a1, b1) = allocated();
        let iters = p.as_ref().map(|p| p.iterations.max(1)).unwrap_or(1) as f64;
        let (allocs_it, mb_it) = ((a1 - a0) as f64 / iters, (b1 - b0) as f64 / iters / 1e6);
        let (u1, s1) = cpu_seconds();
        let share = if u1 + s1 > u0 + s0 { (s1 - s0) / ((u1 - u0) + (s1 - s0)) } else { 0.0 };
        let full_it = p.as_ref().map(|p| p.iterations.to_string()).unwrap_or_else(|e| format!("fail: {e}"));
        let (mut dense_s, mut cond_s) = (String::from("-"), String::from("-"));
        if n <= DENSE_UP_TO {
            for (storage, out) in [(Storage::Dense, &mut dense_s)] {
                let sys = FullSystem::with_storage(&model, H, storage).expect("dense system");
                let t = Instant::now();
                let q = solve_point(&sys, omega, None, &opts);
                *out = format!("{:.3}", t.elapsed().as_secs_f64());
                check_same(&p, &q, "dense");
            }
            let cond = CondensedSystem::new(&model, H).expect("condensed system");
            let t = Instant::now();
            let q = solve_point(&cond, omega, None, &opts);
            cond_s = format!("{:.3}", t.elapsed().as_secs_f64());
            check_same(&p, &q, "condensed");
        }
        let storage = format!("{:?}", full.storage()).to_lowercase();
        println!(
            "{n:>6} {add_s:>10.4} {storage:>8} {full_s:>12.3} {full_it:>6} {allocs_it:>12.0} {mb_it:>12.2} {dense_s:>12} {cond_s:>14} {:>9.0}% {:>8.0}",
            100.0 * share,
            vm_hwm_mb()
        );
    }
    let peer = std::process::Command::new("python3").args(["-c", "import pyHarm"]).output();
    match peer {
        Ok(o) if o.status.success() => println!("pyHarm is installed: time it on the same chain by hand (no driver here yet)"),
        _ => println!("pyHarm is not installed: no peer ratio"),
    }
}

/// Largest `n` solved also dense and condensed (both dense solves of `(n (2H+1))^2` matrices).
const DENSE_UP_TO: usize = 200;

fn check_same(p: &jprom::Result<jprom::hbm::PointSolution>, q: &jprom::Result<jprom::hbm::PointSolution>, what: &str) {
    if let (Ok(p), Ok(q)) = (p, q) {
        let (a, b) = (p.output_amplitude(1, 0), q.output_amplitude(1, 0));
        assert!((a - b).abs() <= 1e-6 * a.abs().max(1e-12), "full {a} vs {what} {b}");
    }
}
