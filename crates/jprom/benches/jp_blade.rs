//! JP at scale on the built-in blade (issue 5 performance): a 200-point sweep of the band at
//! `alpha_ST / 10`, full order (condensed, §5) vs FR vs NLR with a predicted basis (stuck mode,
//! gamma 1e3, in-band + 2 modes), for 18 and 242 contact nodes and H = 1, 3; basis sizes and
//! build time, time per point, and the first-harmonic tip error of each ROM at the FO
//! resonance. Where the FO sweep would take longer than `FO_BUDGET_S` its cost is measured
//! on a few points and extrapolated to 200. `cargo bench --bench jp_blade`.

use jprom_testkit::blade as blade_support;

use blade_support::*;
use jprom::condensation::CondensedSystem;
use jprom::rom::error_metric::predicted_error;
use jprom::hbm::{solve_point, sweep, HarmonicSystem, HbmOptions, PointSolution, SweepOptions};
use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::ContactCoordinates;
use jprom::rom::{FrRom, NlrRom, ReducedModel};
use std::ops::ControlFlow;
use std::time::Instant;

const FO_BUDGET_S: f64 = 150.0;
const POINTS: usize = 200;
/// `p̂` samples of the prediction on the refined blade (100 on the default one).
const SAMPLES_REFINED: usize = 30;

fn sweep_opts(band: (f64, f64)) -> SweepOptions {
    SweepOptions { max_step: 0.006, initial_step: 0.006, max_points: POINTS, ..SweepOptions::band(band.0, band.1) }
}

/// Timed sweep: (seconds, points, peak point).
fn timed_sweep(sys: &dyn HarmonicSystem, band: (f64, f64), hopts: &HbmOptions) -> (f64, usize, Option<PointSolution>) {
    let t = Instant::now();
    let r = sweep(sys, &sweep_opts(band), hopts, &mut |_| ControlFlow::Continue(()));
    let ts = t.elapsed().as_secs_f64();
    match r {
        Ok(r) => {
            let peak = r.points.iter().max_by(|a, b| tip_amplitude(a).total_cmp(&tip_amplitude(b))).cloned();
            (ts, r.points.len(), peak)
        }
        Err(e) => {
            eprintln!("sweep failed: {e}");
            (ts, 0, None)
        }
    }
}

fn main() {
    println!("| contacts | n_w | H | FO s/point | FO 200 points s | basis build s | samples / patterns | sizes n_h | FR s/point | NLR s/point | FR X1 err | NLR X1 err | NLR e*_1 |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut fo_cost: Vec<(usize, usize, f64)> = Vec::new();
    for refinement in [1usize, 5] {
        let blade = Blade::build_refined(refinement);
        let model = blade.at_level(blade.alpha_st / 10.0);
        let n_contacts = model.contacts.len();
        for h in [1usize, 3] {
            let hopts = HbmOptions::default();
            let coords = ContactCoordinates::new(&model, h).unwrap();
            let cond = CondensedSystem::new(&model, h).unwrap();
            // FO cost per point, measured on a few points near the stuck resonance first.
            let t = Instant::now();
            let mut guess: Option<Vec<f64>> = None;
            let probe = 3;
            for k in 0..probe {
                let om = blade.omega_stuck * (0.995 + 0.002 * k as f64);
                guess = solve_point(&cond, om, guess.as_deref(), &hopts).ok().map(|s| s.z);
            }
            let per_point = t.elapsed().as_secs_f64() / probe as f64;
            let (fo_total, fo_peak) = if per_point * POINTS as f64 <= FO_BUDGET_S {
                let (ts, np, peak) = timed_sweep(&cond, blade.band, &hopts);
                (format!("{ts:.1} ({np} points)"), peak)
            } else {
                (format!("~{:.0} (extrapolated)", per_point * POINTS as f64), None)
            };
            fo_cost.push((n_contacts, h, per_point));
            let mut popts = PredictionOptions::new(blade.band);
            popts.modes.extra_outside = 2;
            // At 242 contacts nearly every sample is a distinct contact-state pattern and each
            // costs one JP eigen solve (about 1 s at H = 1, 20 s at H = 3 by shift-invert).
            popts.n_samples = if n_contacts > 100 { SAMPLES_REFINED } else { 100 };
            let t = Instant::now();
            let (basis, rep) = predict_basis(&coords, &popts).unwrap();
            let t_basis = t.elapsed().as_secs_f64();
            let fr = FrRom::new(&coords, &basis).unwrap();
            let nlr = NlrRom::new(&cond, &basis).unwrap();
            let (t_fr, n_fr, _) = timed_sweep(&fr, blade.band, &hopts);
            let (t_nlr, n_nlr, nlr_peak) = timed_sweep(&nlr, blade.band, &hopts);
            // Errors at the FO resonance (or, without an FO sweep, at the NLR peak).
            let fo = match fo_peak {
                Some(p) => solve_point(&cond, p.omega, Some(&p.z), &hopts).ok(),
                None => nlr_peak.and_then(|p| solve_point(&cond, p.omega, guess.as_deref(), &hopts).ok()),
            };
            let (mut e_fr, mut e_nlr, mut es) = (f64::NAN, f64::NAN, f64::NAN);
            if let Some(fo) = &fo {
                let err = |rom: &dyn ReducedModel| -> (f64, f64) {
                    match solve_point(rom, fo.omega, None, &hopts) {
                        Ok(s) => (
                            tip_error(&s.outputs, &fo.outputs, fo.n_outputs, 1),
                            predicted_error(rom, fo.omega, &s.z).map(|e| e[1]).unwrap_or(f64::NAN),
                        ),
                        Err(_) => (f64::NAN, f64::NAN),
                    }
                };
                e_fr = err(&fr).0;
                (e_nlr, es) = err(&nlr);
            }
            println!(
                "| {n_contacts} | {} | {h} | {per_point:.3} | {fo_total} | {t_basis:.1} | {} / {} | {:?} | {:.4} | {:.4} | {e_fr:.1e} | {e_nlr:.1e} | {es:.1e} |",
                coords.n_w,
                popts.n_samples,
                rep.n_patterns,
                basis.sizes,
                t_fr / n_fr.max(1) as f64,
                t_nlr / n_nlr.max(1) as f64,
            );
        }
    }
    // The dense FO Jacobian grows as ((2H + 1) n_w)^2 and its LU as its cube; the reduced sizes
    // do not grow with the contact nodes (table), so a ROM point grows only with the AFT (linear
    // in contacts).
    println!("\nFull order extrapolated to the refinement-15 blade (1,922 contact nodes; its ROMs are run by `cargo bench --bench jp_blade_2k`):");
    for &(nc, h, per_point) in fo_cost.iter().filter(|x| x.0 > 18) {
        let f = (1922.0 / nc as f64).powi(3);
        let nw = 3.0 * 1922.0 * (2 * h + 1) as f64;
        println!("- H = {h}: FO ~{:.0} s per point ({:.0} s for 200 points), dense Jacobian {:.1} GB", per_point * f, per_point * f * POINTS as f64, nw * nw * 8.0 / 1e9);
    }
}
