//! JP modes (31): dense eigen solve against the shift-invert Arnoldi path, on the built-in
//! blade (Craig-Bampton, 50 modes) at contact refinement 1 (18 contact nodes) and 5 (242),
//! H = 1 and 3, for the stuck contact stiffness and a slipping one (1.5 times the largest
//! all-stuck amplitude of the stuck mode). Also `predict_basis` with the shift-invert path at
//! refinement 5, H = 1. `cargo bench --bench jp_modes`.
//!
//! `JPROM_BENCH_REFINEMENTS` (default `1,5`), `JPROM_BENCH_HARMONICS` (default `1,3`),
//! `JPROM_BENCH_PREDICT=0` skips `predict_basis`. `JPROM_BENCH_DENSE_MAX` (default 180 s): a dense case whose estimated time (the H = 1 time
//! times `(2H n)^3` scaling) exceeds this many seconds is skipped.

use jprom_testkit::chain as jp_support;

use jp_support::slipping_jacobian as jacobian;
use jprom::fe::{BladeParams, BuiltinBlade};
use jprom::jp::{jp_modes, predict_basis, EigenSolver, ModeOptions, PredictionOptions};
use jprom::model::{ContactCoordinates, Damping, Model};
use std::f64::consts::PI;
use std::time::Instant;

fn blade(refinement: usize) -> (Model, (f64, f64), usize) {
    let b = BuiltinBlade::build(&BladeParams { refinement, ..Default::default() }).unwrap();
    let cb = b.reduce(50).unwrap();
    let f_st = cb.natural_frequencies_hz(true).unwrap()[0];
    let model = cb.to_model(Damping::from_modal_ratio(0.002, 2.0 * PI * f_st)).unwrap();
    let nc = model.contacts.len();
    // The benchmark band of docs/formulation.md §12 (2140-2190 Hz around 2165 Hz), around this mesh's
    // stuck first bending.
    (model, (2.0 * PI * (f_st - 25.0), 2.0 * PI * (f_st + 25.0)), nc)
}

fn main() {
    let dense_max: f64 = std::env::var("JPROM_BENCH_DENSE_MAX").ok().and_then(|s| s.parse().ok()).unwrap_or(180.0);
    println!(
        "{:>4} {:>8} {:>5} {:>2} {:>6} {:>6} {:>10} {:>10} {:>8} {:>11} {:>11} {:>6} {:>10}",
        "ref", "contacts", "n", "H", "2Hn", "K̂", "dense s", "s-i s", "speedup", "dense eig s", "s-i eig s", "n_eig", "max |dλ|/λ"
    );
    println!("(dense s, s-i s: jp_modes with the static correction; eig s: without it, i.e. (28), (30), the eigen solve and (33)-(35))");
    let mut big: Option<(Model, (f64, f64))> = None;
    let refinements: Vec<usize> = std::env::var("JPROM_BENCH_REFINEMENTS").ok().map_or_else(|| vec![1, 5], |s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect());
    let harmonics_list: Vec<usize> = std::env::var("JPROM_BENCH_HARMONICS").ok().map_or_else(|| vec![1, 3], |s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect());
    for &refinement in &refinements {
        let t = Instant::now();
        let (model, band, nc) = blade(refinement);
        eprintln!("blade refinement {refinement}: {} DoFs, {nc} contacts, built in {:.1} s", model.n_dof(), t.elapsed().as_secs_f64());
        let mut dense_h1 = None;
        for &harmonics in &harmonics_list {
            let coords = ContactCoordinates::new(&model, harmonics).unwrap();
            let n = coords.n_dof;
            for (name, factor) in [("stuck", 0.0), ("slip", 1.5)] {
                let k_hat = jacobian(&coords, harmonics, band, factor);
                let opts = |solver| ModeOptions { band, extra_outside: 0, static_correction: true, solver };
                let eig_opts = |solver| ModeOptions { band, extra_outside: 0, static_correction: false, solver };
                let t = Instant::now();
                let si = jp_modes(&coords, &k_hat, &opts(EigenSolver::ShiftInvert)).unwrap();
                let t_si = t.elapsed().as_secs_f64();
                let t = Instant::now();
                jp_modes(&coords, &k_hat, &eig_opts(EigenSolver::ShiftInvert)).unwrap();
                let t_si_eig = t.elapsed().as_secs_f64();
                let estimate = dense_h1.map(|t1: f64| t1 * (harmonics as f64).powi(3));
                let (t_dense, t_dense_eig, err) = if estimate.is_some_and(|e| e > dense_max) {
                    (None, None, None)
                } else {
                    let t = Instant::now();
                    jp_modes(&coords, &k_hat, &eig_opts(EigenSolver::Dense)).unwrap();
                    let t_eig = t.elapsed().as_secs_f64();
                    let t = Instant::now();
                    let d = jp_modes(&coords, &k_hat, &opts(EigenSolver::Dense)).unwrap();
                    let td = t.elapsed().as_secs_f64();
                    if harmonics == 1 && dense_h1.is_none() {
                        dense_h1 = Some(td);
                    }
                    let mut ed = d.eigenvalues.clone();
                    let mut es = si.eigenvalues.clone();
                    let key = |a: &(f64, f64), b: &(f64, f64)| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1));
                    ed.sort_by(key);
                    es.sort_by(key);
                    let err = if ed.len() == es.len() {
                        ed.iter().zip(&es).map(|(a, b)| ((a.0 - b.0).hypot(a.1 - b.1)) / a.0.hypot(a.1)).fold(0.0, f64::max)
                    } else {
                        f64::NAN
                    };
                    (Some(td), Some(t_eig), Some(err))
                };
                let fmt = |x: Option<f64>, p: usize| x.map_or_else(|| "skipped".to_string(), |v| format!("{v:.p$}"));
                println!(
                    "{refinement:>4} {nc:>8} {n:>5} {harmonics:>2} {:>6} {name:>6} {:>10} {t_si:>10.2} {:>8} {:>11} {t_si_eig:>11.2} {:>6} {:>10}",
                    2 * harmonics * n,
                    fmt(t_dense, 2),
                    t_dense.map_or_else(|| "-".to_string(), |td| format!("{:.1}x", td / t_si)),
                    fmt(t_dense_eig, 2),
                    si.eigenvalues.len(),
                    err.map_or_else(|| "-".to_string(), |e| format!("{e:.1e}")),
                );
                if t_dense.is_none() {
                    println!("     (dense skipped: estimated {:.0} s > {dense_max:.0} s)", estimate.unwrap_or(0.0));
                }
            }
        }
        if refinement == 5 {
            big = Some((model, band));
        }
    }
    if std::env::var("JPROM_BENCH_PREDICT").is_ok_and(|v| v == "0") {
        big = None;
    }
    if let Some((model, band)) = big {
        let coords = ContactCoordinates::new(&model, 1).unwrap();
        let mut popts = PredictionOptions::new(band);
        popts.modes.solver = EigenSolver::ShiftInvert;
        let t = Instant::now();
        let (basis, report) = predict_basis(&coords, &popts).unwrap();
        println!(
            "predict_basis (refinement 5, H = 1, shift-invert, {} samples): {:.1} s, {} patterns, sizes {:?}",
            report.n_samples,
            t.elapsed().as_secs_f64(),
            report.n_patterns,
            basis.sizes
        );
    }
}
