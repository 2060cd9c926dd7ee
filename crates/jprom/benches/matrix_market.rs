//! Matrix Market reading (issue 13): jprom's reader against scipy's `scipy.io.mmread` on the
//! same files, in the same run. Writes a symmetric pair (`K`, `M`) of 60,000 DoFs and about
//! 3.5 million stored entries each (the lower triangle of a banded SPD matrix whose pattern
//! has a near band and a far band, like a numbered FE mesh; values with 17 significant
//! digits, as exporters write them), times `read_structural_matrices` (both files, to CSC,
//! symmetry checked) and then `python3 -c "scipy.io.mmread(...)"` on both (COO, as scipy
//! returns it; Python's start-up and import are not timed). Skips scipy with a message if
//! it is missing.
//!
//! `cargo bench --bench matrix_market` prints the table. `JPROM_BENCH_MM_DIR=DIR` writes the
//! files there and keeps them (default: a temporary folder, removed at the end).

use jprom::io::matrix_market::{read_structural_matrices, write_matrix_market};
use jprom::linalg::sparse_from_triplets;
use std::path::Path;
use std::time::Instant;

const N: usize = 60_000;

/// Lower triangle of a banded SPD matrix: for each column `j`, rows `j + d` for `d` in the
/// near band `0..29` and the far band `300..329` (about 58 entries a column, 3.48 million in
/// all); off-diagonal values in [-1, 1), the diagonal 100 + its row's sum of magnitudes
/// (diagonally dominant, so positive definite). `seed` changes the values.
fn banded_spd(seed: u64) -> jprom::linalg::SparseMat {
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let offsets: Vec<usize> = (1..29).chain(300..329).collect();
    let mut row_sum = vec![0.0f64; N];
    let mut t = Vec::with_capacity(N * (offsets.len() + 1));
    for j in 0..N {
        for &d in &offsets {
            let i = j + d;
            if i < N {
                let v = next();
                row_sum[i] += v.abs();
                row_sum[j] += v.abs();
                t.push((i, j, v));
            }
        }
    }
    for (j, s) in row_sum.iter().enumerate() {
        t.push((j, j, 100.0 + s));
    }
    // full storage (the writer keeps the lower triangle of a symmetric matrix)
    let upper: Vec<(usize, usize, f64)> = t.iter().filter(|e| e.0 != e.1).map(|&(i, j, v)| (j, i, v)).collect();
    t.extend(upper);
    sparse_from_triplets(N, N, t).expect("banded matrix")
}

fn file_mb(p: &Path) -> f64 {
    std::fs::metadata(p).map(|m| m.len() as f64 / 1e6).unwrap_or(f64::NAN)
}

fn main() {
    let keep = std::env::var_os("JPROM_BENCH_MM_DIR");
    let dir = keep.as_ref().map(std::path::PathBuf::from).unwrap_or_else(|| std::env::temp_dir().join(format!("jprom_bench_mm_{}", std::process::id())));
    std::fs::create_dir_all(&dir).expect("bench folder");
    let (pk, pm) = (dir.join("k.mtx"), dir.join("m.mtx"));
    if !(pk.exists() && pm.exists()) {
        let t = Instant::now();
        let k = banded_spd(1);
        let m = banded_spd(2);
        write_matrix_market(&pk, &k, true).expect("write K");
        write_matrix_market(&pm, &m, true).expect("write M");
        eprintln!("wrote {} and {} in {:.1} s", pk.display(), pm.display(), t.elapsed().as_secs_f64());
    }
    println!("Matrix Market read of a symmetric pair: K {:.0} MB, M {:.0} MB ({} DoFs); rayon threads: {}", file_mb(&pk), file_mb(&pm), N, rayon::current_num_threads());

    // jprom: best of 3 (the files are in the page cache after the first)
    let mut best = f64::INFINITY;
    let mut nnz = 0;
    for _ in 0..3 {
        let t = Instant::now();
        let s = read_structural_matrices(&pm, &pk, None).expect("jprom read");
        best = best.min(t.elapsed().as_secs_f64());
        nnz = s.stiffness.compute_nnz() + s.mass.compute_nnz();
    }
    println!("{:<44} {:>8.2} s  ({} stored entries in full CSC)", "jprom read_structural_matrices (K + M)", best, nnz);

    let script = format!(
        "import time, scipy.io\nbest = 1e9\nfor _ in range(3):\n    t = time.perf_counter(); a = scipy.io.mmread({:?}); b = scipy.io.mmread({:?}); best = min(best, time.perf_counter() - t)\nprint(best, a.nnz + b.nnz)",
        pk.display().to_string(),
        pm.display().to_string()
    );
    match std::process::Command::new("python3").args(["-c", &script]).output() {
        Ok(out) if out.status.success() => {
            let s = String::from_utf8_lossy(&out.stdout);
            let mut f = s.split_whitespace();
            let secs: f64 = f.next().and_then(|v| v.parse().ok()).unwrap_or(f64::NAN);
            let entries = f.next().unwrap_or("?");
            println!("{:<44} {:>8.2} s  ({} stored entries, COO)", "scipy.io.mmread (K + M)", secs, entries);
            println!("{:<44} {:>8.2}", "ratio jprom / scipy", best / secs);
        }
        Ok(out) => println!("scipy skipped: python3 -c 'import scipy.io' failed: {}", String::from_utf8_lossy(&out.stderr).lines().last().unwrap_or("")),
        Err(e) => println!("scipy skipped: python3 not found ({e})"),
    }
    if keep.is_none() {
        std::fs::remove_dir_all(&dir).ok();
    }
}
