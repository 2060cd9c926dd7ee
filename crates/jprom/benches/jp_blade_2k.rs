//! JP at about 2,000 contact nodes (issue 5 performance): the built-in blade at refinement 15
//! (2 x 31^2 = 1,922 contact nodes, about 141k FE DoFs), Craig-Bampton with 50 modes without
//! the constraint modes (`keep_recovery: false`), the predicted basis (stuck mode, gamma 1e3,
//! in-band + 2 modes) and 200-point FR and NLR sweeps of the band at `alpha_ST / 10`, H = 1.
//! Prints each stage's time and the peak resident memory. The full-order sweep is not run
//! (its dense Jacobian alone is `(3 n_w)^2` doubles, 2.4 GB at H = 1, and each Newton
//! iteration factorises it; see `jp_blade` for its per-point cost on smaller blades and the
//! extrapolation); with `JPROM_2K_FO=1` one full-order point is solved at the NLR resonance
//! from the NLR solution, for its measured cost and the actual errors of both ROMs. That
//! point peaked at 16.6 GB resident (dense Jacobian, its LU and the condensed `n_w x n_w`
//! complex blocks): it needs a machine with ~20 GB free.
//!
//! Measured (shared 2-core machine, load 5-7, 20 samples, cached CB): CB 645 s at 4.0 GB;
//! basis 1,410 s (20 patterns, ~70 s each), sizes [57, 11]; FR 0.113 s/point, NLR
//! 0.124 s/point; e*_1 0.026 (FR), 0.028 (NLR); one FO point 114 s (3 iterations), actual
//! e_1 3.4e-3 (FR), 2.6e-3 (NLR). With the shared reference of the prediction (issue 17, quiet
//! machine, 8 samples): CB 573 s at 3.9 GB; basis 420 s for 8 patterns with 6, 312, 1,500,
//! 3,012, 4,446, 5,454, 5,766 and 5,766 of the 5,766 contact coordinates active, peak 8.1 GB
//! (estimate 6.2 GB); FR 0.19 s/point, NLR 0.16 s/point (measured at 9b502b9, whose columns
//! (33) were weighted per eigenspace: sizes [21, 8], e*_1 0.039; the factorisations, which make
//! the basis time, are today's). Refinement 5, H = 3, today: basis 19.3 s (was 44.8 s), sizes
//! [47, 12, 27, 19], 6 to 726 of 726 coordinates active, estimate 1.0 GB, peak 1.37 GB; on
//! 2026-12-04's slower machine, after the changes below: 7.2 s, the same sizes, estimate
//! 317 MB, peak 452 MB.
//! With the Craig-Bampton's sparse-dense products by a gather kernel (`spmm_t`, the same bits
//! as faer's product), the dependencies without debug assertions, and each block's solve split
//! among the threads (the same bits as faer's solve; the reduced matrices hash the same with
//! and without), the same call in the test profile (quiet machine): refinement 15 573 -> 267 ->
//! 158 s at 4.2 GB, refinement 8 (61,404 DoFs) 68 -> 31.1 -> 22.2 s; with the fixed-interface
//! modes computed alongside the first boundary blocks (the same bits again) refinement 15
//! 143 s at 4.7 GB, refinement 8 17.8 s; with the block buffers reused and the solves visiting
//! only the supernodes that matter (the same bits) this bench's Craig-Bampton stage 124.9 s at
//! 5.05 GB peak (release; 113 s in the test profile). An earlier variant that
//! also ran the Lanczos half solves on one thread and summed four entries per pass took
//! refinement 15 to 138 s, but those two change the rounding of the reduced model, and the
//! principal-angle bounds of tests/jp_reference.rs (1e-8) then failed (1.1e-8 to 2.8e-8).
//!
//! Cost growth with the contact count (H = 1, 8 samples, release, cached CB, 2026-12-03, with
//! `dS` applied by its factors; `JPROM_2K_REFINEMENT` = 1, 5, 15; the stage table is saved
//! under `target/bench-results/`):
//!
//! | contacts | n_w | basis s | sizes | FR s/point | NLR s/point | e*_1 (FR) | peak RSS |
//! |---|---|---|---|---|---|---|---|
//! | 18 | 54 | < 0.05 (per pattern, dense eigen solve) | [30, 9] | 0.001 | 0.001 | 0.040 | 16 MB |
//! | 242 | 726 | 1.3 (shared reference) | [34, 8] | 0.016 | 0.011 | 0.056 | 0.33 GB |
//! | 1,922 | 5,766 | 233.9 (shared reference) | [32, 10] | 0.120 | 0.114 | 0.040 | 6.8 GB |
//!
//! (Before `dS` by its factors, 4163e0b: 259.7 s at 1,922 contacts, 1.5 s at 242.)
//!
//! 2026-12-04, a machine about 1.7 times slower (the same code: CB 148.4 s, basis 403.7 s at
//! 1,922 contacts, 2.2 s at 242): per pattern at 1,922 contacts, 6 to 312 active coordinates
//! took 11 s, of which 4.7 s were the Arnoldi iteration and its refinement and 6 s the eigen
//! residuals (one product with the model-sized matrices per pair and per time-shift partner,
//! and the rounding floors `|K_JC| |v|` by a scalar loop per pair); a fully active one 81 s
//! (statics 17 s, the dense `dS` 4 s, the capacitance 39 s, Arnoldi 10 s, residuals 9 s). Now
//! the residuals of all pairs come from one product (`|K_JC| |V|` by panels of `|K|`), `dS` is
//! only applied by its factors (the residual floors use `|D| + |D_i0| |g_aa| |D_0j|`), the
//! capacitance is factorised in its place, the cos and sin corrections of a harmonic take one
//! product with `Y_h`, and the solves with many right-hand sides (`Y_h`, `A_0^-1 E_a^T`) are
//! checked on three probe combinations instead of the whole product: basis 292.3 s (patterns
//! 5.4 s to 69 s), 1.7 s at 242 contacts, under 0.05 s at 18; sizes, e*_1 and resonances as
//! before; FR 0.076 and NLR 0.081 s/point at 1,922 contacts, 0.010 at 242; estimate of the
//! prediction 6,157 -> 4,029 MB, peak RSS 6,774 -> 5,755 MB. Growth exponent from 242 to 1,922
//! contacts: basis 2.5, FR per point 1.0.
//! Then the Woodbury updates of a pattern take only the rows of `D` that differ from zero (a
//! contact that slips but stays closed keeps its normal row; docs/formulation.md §8.10): the
//! fully active patterns' capacitances are `2H r_l` square with `r_l` 4,192 and 4,608 instead
//! of 5,766: basis 292.3 -> 209.7 to 220.8 s over three runs (per pattern 5 to 41 s: statics
//! up to 12 s, capacitance product 10 to 15 s, its LU 4 to 6 s, Arnoldi 5 to 10 s; the
//! reference 20 s), 1.8 -> 1.4 s at 242 contacts, estimate 4,029 -> 3,803 MB; sizes, e*_1 and
//! resonances unchanged. H = 3 at 1,922 contacts (`JPROM_2K_H=3`, a compile ran beside it for
//! 2 minutes): basis 1,126.5 s, sizes [46, 13, 25, 18], estimate 10,755 MB, peak RSS 12.9 GB;
//! the reference 42 s, patterns 12 s (6 active) to 356 s (fully active, `r_l` 4,608:
//! capacitance 27,648 square, its product 85 s, LU 211 s, Arnoldi 48 s; measured before the
//! `D` blocks were applied on contiguous columns); FR 0.33 s/point; the NLR
//! model is refused by the memory budget (the condensed system at H = 3 needs 26 GB). A second
//! run after that change: basis 1,219.7 s, the same sizes and peak, FR 0.387 s/point, e*_1
//! 0.051, resonance 2146.95 Hz; its stuck-mode and FR stages were 17 to 24 % slower than the
//! first run's on the same binary-independent work (a busier machine).
//! Later on 2026-12-04 (a fresh machine of the same kind; its Craig-Bampton 167.6 s), the
//! capacitance formed by column panels of 512 columns and the reference's `Y_h` read in place
//! for patterns whose leading coordinates are at least half of `w`: H = 1 basis 186.8 s (peak
//! 5,152 MB, the Craig-Bampton's), H = 3 basis 911.0 s at 10,759 MB peak (estimate 10,439 MB;
//! were 1,127-1,220 s and 12.9 GB: whole column blocks had taken about 3 GB of temporaries beside
//! the 6 GB capacitance), FR 0.279 s/point, e*_1 0.051, resonance 2146.95 Hz, the same sizes
//! [46, 13, 25, 18]. Then the patterns on the reference solved two at a time, the costliest
//! first: H = 1 basis 163.2 s, estimate 6,100 MB, peak 6,487 MB, sizes [32, 10], e*_1 0.040,
//! resonances 2146.90 / 2146.69 Hz as before; refinement 5: 1.0 s (H = 1), 5.2 s, estimate 378 MB,
//! peak 431 MB (H = 3). One full-order point at the NLR resonance (`JPROM_2K_FO=1`): 163.6 s
//! (3 iterations, 12.0 GB peak), actual e_1 2.4e-3 for both ROMs, tip X1 error 3.1e-4. The whole
//! H = 1 study (CB 167.6 + basis 163.2 + FR model 1.1 + sweep 20.2 s = 352 s) is 93 times
//! faster than 200 such points. Exponents from 242 to 1,922 contacts: basis 2.5, FR per point 1.1.
//! Then `p̂_min` searched from below (`slip_onset_amplitude`: the first touch of the friction
//! cone, where the bisection had landed anywhere in the 20 % past it) and `p̂_max`'s linear
//! estimate by one complex `n`-square solve instead of the real `2n` one (17.5 -> 6.0 s): H = 1
//! basis 145.1 s, sizes [31, 10], the same active coordinates per pattern within a few, e*_1
//! 0.040, resonances 2146.90 / 2146.68 Hz, FR 0.091 s/point (sweep 18.1 s), NLR 0.094; one
//! full-order point 146.4 s in this run (the same 3 iterations, 12.1 GB; 163.6 s in the run
//! before), actual e_1 2.4e-3, tip X1 error 3.1e-4; the whole study 332 s, 88 times faster than
//! 200 of this run's full-order points (99 times at the earlier run's). H = 3: basis 935.7 s
//! (911.0 s the run before; the same two fully active patterns), peak 10,762 MB, sizes
//! [44, 13, 25, 18], e*_1 0.051, FR 0.312 s/point. Refinement 5: 1.1 s [33, 8] (H = 1), 5.7 s
//! [47, 12, 27, 19] at 432 MB peak (H = 3); refinement 1: [27, 8]. Exponents from 242 to 1,922
//! contacts: basis 2.4, FR per point 1.0.
//! Then the sparse Cholesky factor of `K_ii` ordered by nested dissection (`linalg::ordering`:
//! 151.5 M values against AMD's 203.4 M, numeric factorisation 4.3 s against 8.0 s): the
//! Craig-Bampton stage 111.0 and 104.0 s in two runs (the same bits both times), against 130.3
//! and 132.5 s with AMD's ordering on the same machine that evening (167.6 s earlier that day),
//! peak 4.65-4.78 GB, stuck mode 2150.86 Hz as before. The reduced model's rounding changes:
//! sizes [32, 10], the same active coordinates, e*_1 0.040, resonances 2146.90 / 2146.69 Hz;
//! basis 127.4 to 136.0 s over three runs, FR 0.084 to 0.090 s/point; one full-order point
//! 132.1 and 138.6 s; actual e_1 2.4e-3, tip X1 error 3.1e-4 for both ROMs. The whole H = 1
//! study in one run (CB 104.0 + basis 127.4 + FR model 1.2 + sweep 17.0 = 249.6 s) is 111
//! times faster than 200 of that run's full-order points (138.6 s each).
//! On 2026-12-05, with the memory budget no longer counting the condensed system's Newton
//! Jacobian against an NLR model (which projects the condensed system and never forms it), H = 3
//! at 1,922 contacts (a fresh cache: Craig-Bampton 99.8 s, the same bytes as the day before):
//! basis 760.6 s (759.3 s in a run timed per stage), peak 10,781 MB, sizes [44, 13, 26, 18];
//! FR model 1.9 s, 0.221 s/point; **NLR model 7.1 s, 0.195 s/point** (it was refused for 24.3
//! GiB); e*_1 0.051 for both, resonances 2146.95 (FR) and 2146.90 Hz (NLR), peak tip
//! amplitudes 0.55 % apart. Per stage (patterns one at a time at H = 3, by the budget): before
//! the patterns 10.8 s (static solution 2.2, stuck mode and `p̂_max`'s complex solve 8.6), the
//! reference 14.9 s, then per pattern statics 0 to 9.2 s (31 s in all), the capacitance (its
//! product and LU; `6 r_l` square, `r_l` 4 to 4,608) 0.1 to 192 s (**530 s in all**), the
//! Arnoldi 7.8 to 36 s (188 s in all; faer's Krylov-Schur takes at least a 64-vector space, each
//! vector one solve that reads the reference's and the capacitance's factors). The LUs alone are
//! about 3.7e13 flops, 460 s at the 80 GFlop/s they run at: with this Arnoldi, 600 s is out of
//! reach on 2 cores. H = 1 the same way (two patterns at a time): 123.6 s; the reference 12-13
//! s, per pattern statics up to 17 s, capacitance up to 26 s, Arnoldi 4.5 to 14 s (63 to 73 s of
//! the two lanes' 199 s). Then the eigen solves of problems from 8,000 unknowns by block
//! Arnoldi (`linalg::block_arnoldi`, blocks of 8 vectors; converged at 80 vectors on every
//! pattern, where Krylov-Schur took 150 to 250 one-vector solves, and without the 20-solve
//! power iteration that scaled the operator): H = 1 basis 99.2 and 100.6 s, the same sizes,
//! e*_1, resonances and full-order errors (one point 140.6 s, actual e_1 2.4e-3, tip X1 error
//! 3.1e-4), FR 0.083 s/point; the whole study (CB 99.8 + basis 100.6 + FR model 1.0 + sweep
//! 16.6 = 218.0 s) 129 times faster than 200 full-order points. H = 3: basis 658.7 s (from
//! 760), peak 10,762 MB, sizes [44, 13, 26, 18], FR 0.228 and NLR 0.199 s/point, e*_1 0.051,
//! resonances 2146.95 / 2146.90 Hz. What is left of the 600 s target is the capacitances' LUs.
//! With the capacitances from 12,000 square factorised in single precision and their solves
//! refined in double (`shift_invert::MIXED_CAPACITANCE_MIN_DIM`; at H = 3 the five patterns
//! from 3,012 active coordinates, none at H = 1): H = 3 basis 504.4 and 505.7 s, peak 7,840 MB
//! (was 10,762), sizes [44, 13, 26, 18], FR 0.227 and NLR 0.197 s/point, e*_1 0.051, resonances
//! 2146.95 / 2146.90 Hz, peak tip amplitudes 0.55 % apart, as in double precision.
//! (The refinement-15 row measured earlier, at 9b502b9's successors: basis 420 and 493 s, FR
//! and NLR 0.25 s/point, 8.1 GB.) Exponents `d ln t / d ln n_c` from 242 to 1,922 contacts:
//! basis 2.5; FR per point 1.0, NLR per point 1.1 (from 18 to 242 about 1, the 18-contact
//! times being at the 1 ms resolution of the table). The basis grows
//! super-linearly past a few hundred contacts because the patterns at the largest amplitudes
//! (most contacts slipping) differ from the reference (the first, near-stuck sample) at every
//! contact, and such a fully active pattern factorises a `2H n_w` capacitance matrix.
//!
//! `cargo bench --bench jp_blade_2k` (about an hour on 2 cores). Environment:
//! `JPROM_2K_REFINEMENT` (default 15), `JPROM_2K_SAMPLES` (p̂ samples, default 8),
//! `JPROM_2K_H` (default 1), `JPROM_2K_STOP=cb` to stop after the Craig-Bampton reduction,
//! `JPROM_2K_BUDGET` (bytes; default 70 % of the memory) the memory budget of every stage,
//! `JPROM_2K_CACHE=dir` to keep the reduced model in `dir` and reuse it on the next run.
//! The stage table (with the memory budget's estimate of one contact pattern beside the
//! measured peak) is saved to `target/bench-results/jp_blade_2k_r<refinement>_h<H>.md`; a
//! prediction the budget refuses ends the run with its row marked "refused".

use jprom_testkit::blade as blade_support;
mod common;

use blade_support::*;
use common::vm_hwm_mb;
use jprom::fe::{BladeParams, BuiltinBlade, CbOptions};
use jprom::condensation::CondensedSystem;
use jprom::rom::error_metric::{actual_error, predicted_error};
use jprom::hbm::{solve_point, sweep, HbmOptions, SweepOptions};
use jprom::jp::{predict_basis, stuck_mode, PredictionOptions};
use faer::Mat;
use jprom::model::{ContactCoordinates, Damping, Model};
use jprom::rom::{FrRom, NlrRom, ReducedModel};
use std::f64::consts::PI;
use std::ops::ControlFlow;
use std::time::Instant;

const POINTS: usize = 200;

const TABLE_HEAD: &str = "| contacts | FE DoFs | n_w | H | FE build s | CB s | CB peak RSS MB | setup s | basis s | prediction estimate MB | samples / patterns | sizes n_h | FR build s | FR s/point | NLR build s | NLR s/point | FR e*_1 | NLR e*_1 | FR-NLR peak tip diff | peak RSS MB |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";

/// Prints the stage table and saves it to `target/bench-results/jp_blade_2k_r<refinement>_h<H>.md`.
fn save_table(refinement: usize, h: usize, row: &str) {
    let text = format!("{TABLE_HEAD}\n{row}\n");
    println!("{text}");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/bench-results");
    let path = dir.join(format!("jp_blade_2k_r{refinement}_h{h}.md"));
    match std::fs::create_dir_all(&dir).and_then(|_| std::fs::write(&path, &text)) {
        Ok(()) => eprintln!("[stage table saved to {}]", path.display()),
        Err(e) => eprintln!("[stage table not saved to {}: {e}]", path.display()),
    }
}

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn stage(name: &str, t: Instant) -> f64 {
    let s = t.elapsed().as_secs_f64();
    eprintln!("[{name}] {s:.1} s, peak RSS {:.0} MB", vm_hwm_mb());
    s
}

/// The CB model cached as raw little-endian `M`, `K` (column-major) plus JSON for the rest.
fn save_model(path: &std::path::Path, m: &Model, n_fe: usize) {
    let mut raw = Vec::with_capacity(16 * m.n_dof() * m.n_dof());
    for a in [&m.mass, &m.stiffness] {
        for j in 0..a.ncols() {
            for i in 0..a.nrows() {
                raw.extend_from_slice(&a[(i, j)].to_le_bytes());
            }
        }
    }
    let rest = Model { mass: Mat::zeros(0, 0), stiffness: Mat::zeros(0, 0), ..m.clone() };
    let _ = std::fs::write(path.with_extension("bin"), raw);
    let _ = std::fs::write(path.with_extension("json"), serde_json::to_string(&(rest, n_fe, m.n_dof())).unwrap());
}

fn load_model(path: &std::path::Path) -> Option<(Model, usize)> {
    let (mut m, n_fe, n): (Model, usize, usize) = serde_json::from_str(&std::fs::read_to_string(path.with_extension("json")).ok()?).ok()?;
    let raw = std::fs::read(path.with_extension("bin")).ok()?;
    if raw.len() != 16 * n * n {
        return None;
    }
    let at = |k: usize| f64::from_le_bytes(raw[8 * k..8 * k + 8].try_into().unwrap());
    m.mass = Mat::from_fn(n, n, |i, j| at(i + j * n));
    m.stiffness = Mat::from_fn(n, n, |i, j| at(n * n + i + j * n));
    Some((m, n_fe))
}

fn main() {
    let refinement = env_usize("JPROM_2K_REFINEMENT", 15);
    let n_samples = env_usize("JPROM_2K_SAMPLES", 8);
    let h = env_usize("JPROM_2K_H", 1);
    let stop_after_cb = std::env::var("JPROM_2K_STOP").map(|v| v == "cb").unwrap_or(false);
    if let Some(bytes) = std::env::var("JPROM_2K_BUDGET").ok().and_then(|v| v.parse().ok()) {
        jprom::memory::MemoryBudget::set_global(Some(jprom::memory::MemoryBudget::new(bytes)));
    }
    eprintln!("[memory budget {}]", jprom::memory::human_bytes(jprom::memory::MemoryBudget::global().bytes as u128));
    let band = (2.0 * PI * BAND_HZ.0, 2.0 * PI * BAND_HZ.1);

    let cache = std::env::var("JPROM_2K_CACHE").ok().map(|d| std::path::PathBuf::from(d).join(format!("blade_r{refinement}")));
    let (model0, n_fe, n_contacts, t_fe, t_cb, rss_cb) = match cache.as_ref().and_then(|c| load_model(c)) {
        Some((m, n_fe)) => {
            eprintln!("[CB model read from the cache {:?}]", cache.as_ref().unwrap());
            let nc = m.contacts.len();
            (m, n_fe, nc, f64::NAN, f64::NAN, f64::NAN)
        }
        None => {
            let t = Instant::now();
            let fe = BuiltinBlade::build(&BladeParams { refinement, ..BladeParams::default() }).expect("blade");
            let n_fe = fe.n_dof();
            let n_contacts = fe.contacts.len();
            let t_fe = stage(&format!("FE model: {n_fe} DoFs, {n_contacts} contact nodes"), t);
            let t = Instant::now();
            let cb = fe.reduce_with(CbOptions { n_modes: 50, keep_recovery: false, cutoff_hz: None }).expect("CB");
            drop(fe);
            let t_cb = stage(&format!("Craig-Bampton: {} reduced DoFs", cb.cb.n_reduced()), t);
            let rss_cb = vm_hwm_mb();
            let m = cb.to_model(Damping::from_modal_ratio(ZETA, 2.0 * PI * 2165.0)).expect("model");
            if let Some(c) = &cache {
                save_model(c, &m, n_fe);
            }
            (m, n_fe, n_contacts, t_fe, t_cb, rss_cb)
        }
    };
    if stop_after_cb {
        return;
    }

    // Stuck first bending of the reduced model (shift-invert, the JP prediction's own stuck
    // mode), the damping at it, and alpha_ST.
    let t = Instant::now();
    let (omega_stuck, _) = stuck_mode(&ContactCoordinates::new(&model0, 1).unwrap(), band).expect("stuck mode");
    let mut model = model0;
    model.damping = Damping::from_modal_ratio(ZETA, omega_stuck);
    let alpha_st = alpha_stuck(&model, omega_stuck);
    let mut model = model;
    model.excitation.set_level(alpha_st / 10.0).unwrap();
    let t_setup = stage(&format!("stuck mode {:.2} Hz, alpha_ST {alpha_st:.4e}", omega_stuck / (2.0 * PI)), t);

    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, h).unwrap();
    let mut popts = PredictionOptions::new(band);
    popts.n_samples = n_samples;
    let t = Instant::now();
    let (basis, rep) = match predict_basis(&coords, &popts) {
        Ok(b) => b,
        Err(e) => {
            stage(&format!("basis refused: {e}"), t);
            // the estimate the budget refused
            let pattern_mb = match &e {
                jprom::JpError::TooLarge { bytes, .. } => *bytes as f64 / 1e6,
                _ => f64::NAN,
            };
            let row = format!("| {n_contacts} | {n_fe} | {} | {h} | {t_fe:.1} | {t_cb:.1} | {rss_cb:.0} | {t_setup:.1} | refused | {pattern_mb:.0} | {n_samples} / - | - | - | - | - | - | - | - | - | {:.0} |", coords.n_w, vm_hwm_mb());
            save_table(refinement, h, &row);
            return;
        }
    };
    let t_basis = stage(
        &format!(
            "basis: {} samples, {} patterns, sizes {:?}, active contact coordinates per pattern {:?} (of {}), estimate {:.0} MB",
            n_samples,
            rep.n_patterns,
            basis.sizes,
            rep.active_coordinates,
            coords.n_w,
            rep.estimated_bytes as f64 / 1e6
        ),
        t,
    );
    let pattern_mb = rep.estimated_bytes as f64 / 1e6;
    let rss_basis = vm_hwm_mb();

    let sopts = SweepOptions { max_step: 0.006, initial_step: 0.006, max_points: POINTS, ..SweepOptions::band(band.0, band.1) };
    let t = Instant::now();
    let fr = FrRom::new(&coords, &basis).unwrap();
    let t_fr_build = stage("FR model", t);
    let t = Instant::now();
    let fr_sweep = sweep(&fr, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).expect("FR sweep");
    let t_fr = stage(&format!("FR sweep: {} points", fr_sweep.points.len()), t) / fr_sweep.points.len().max(1) as f64;
    // NLR projects the condensed system (its static condensation, `n_w` square; the Newton
    // Jacobian on all (2H + 1) n_w contact coordinates, 26 GB at H = 3 on 1,922 contacts, is
    // only the full-order point's): a condensed system beyond the budget is refused, and the
    // row says so
    let t = Instant::now();
    let cond = match CondensedSystem::new(&model, h) {
        Ok(c) => Some(c),
        Err(e) => {
            stage(&format!("NLR refused: {e}"), t);
            None
        }
    };
    let nlr = cond.as_ref().map(|c| NlrRom::new(c, &basis).unwrap());
    let t_nlr_build = if nlr.is_some() { stage("NLR model", t) } else { f64::NAN };
    let t = Instant::now();
    let nlr_sweep = nlr.as_ref().map(|nlr| sweep(nlr, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).expect("NLR sweep"));
    let t_nlr = nlr_sweep.as_ref().map_or(f64::NAN, |s| stage(&format!("NLR sweep: {} points", s.points.len()), t) / s.points.len().max(1) as f64);

    // e*_1 of each ROM at its own resonance (no full-order solution at this size).
    let peak = |pts: &[jprom::hbm::PointSolution]| pts.iter().max_by(|a, b| tip_amplitude(a).total_cmp(&tip_amplitude(b))).cloned().unwrap();
    let pf = peak(&fr_sweep.points);
    let es_fr = predicted_error(&fr, pf.omega, &pf.z).map(|e| e[1]).unwrap_or(f64::NAN);
    let (es_nlr, nlr_vs_fr) = match (&nlr, &nlr_sweep) {
        (Some(nlr), Some(s)) => {
            let pn = peak(&s.points);
            let es = predicted_error(nlr, pn.omega, &pn.z).map(|e| e[1]).unwrap_or(f64::NAN);
            let (a, b) = (tip(&pf.outputs, pf.n_outputs, 1), tip(&pn.outputs, pn.n_outputs, 1));
            let d: f64 = a.iter().zip(&b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
            (es, d / b.iter().map(|y| y * y).sum::<f64>().sqrt())
        }
        _ => (f64::NAN, f64::NAN),
    };
    let row = format!(
        "| {n_contacts} | {n_fe} | {} | {h} | {t_fe:.1} | {t_cb:.1} | {rss_cb:.0} | {t_setup:.1} | {t_basis:.1} | {pattern_mb:.0} | {n_samples} / {} | {:?} | {t_fr_build:.1} | {t_fr:.3} | {t_nlr_build:.1} | {t_nlr:.3} | {es_fr:.1e} | {es_nlr:.1e} | {nlr_vs_fr:.1e} | {:.0} (basis stage {rss_basis:.0}) |",
        coords.n_w,
        rep.n_patterns,
        basis.sizes,
        vm_hwm_mb(),
    );
    save_table(refinement, h, &row);
    let Some((cond, nlr, pn)) = cond.zip(nlr).zip(nlr_sweep.map(|s| peak(&s.points))).map(|((c, n), p)| (c, n, p)) else {
        println!("(resonance {:.2} Hz FR; no NLR)", pf.omega / (2.0 * PI));
        return;
    };
    println!("(resonance {:.2} Hz FR, {:.2} Hz NLR)", pf.omega / (2.0 * PI), pn.omega / (2.0 * PI));

    // One full-order point (condensed, dense Jacobian) at the NLR resonance, from the NLR
    // solution: its measured cost per Newton iteration, and the actual errors e_1 of both ROMs
    // there against their predictors e*_1.
    if std::env::var("JPROM_2K_FO").map(|v| v == "1").unwrap_or(false) {
        let guess = nlr.condensed_unknowns(&pn.z).unwrap();
        let t = Instant::now();
        match solve_point(&cond, pn.omega, Some(&guess), &hopts) {
            Ok(fo) => {
                let t_fo = stage(&format!("FO point: {} iterations, converged {}", fo.iterations, fo.converged), t);
                let fr_pt = solve_point(&fr, pn.omega, Some(&pf.z), &hopts).ok();
                let row = |name: &str, rom: &dyn ReducedModel, z: &[f64], outputs: &[f64]| {
                    let e = actual_error(rom, pn.omega, z, &fo).map(|e| e[1]).unwrap_or(f64::NAN);
                    let es = predicted_error(rom, pn.omega, z).map(|e| e[1]).unwrap_or(f64::NAN);
                    let tip_e = tip_error(outputs, &fo.outputs, fo.n_outputs, 1);
                    println!("| {name} | {e:.1e} | {es:.1e} | {tip_e:.1e} |");
                };
                println!("\nFull order at {:.2} Hz: {:.0} s for {} Newton iterations ({:.0} s each), peak RSS {:.0} MB", pn.omega / (2.0 * PI), t_fo, fo.iterations, t_fo / fo.iterations.max(1) as f64, vm_hwm_mb());
                println!("| ROM | e_1 (actual) | e*_1 (predicted) | tip X1 error |");
                println!("|---|---|---|---|");
                row("NLR", &nlr, &pn.z, &pn.outputs);
                if let Some(p) = fr_pt {
                    row("FR", &fr, &p.z, &p.outputs);
                }
            }
            Err(e) => {
                stage(&format!("FO point failed: {e}"), t);
            }
        }
    }
}
