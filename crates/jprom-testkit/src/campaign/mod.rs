//! The robustness campaign of the continuation and of JP (docs/formulation.md §6.9): solid FE
//! models nobody tuned for ([`model::ModelSpec::random`]), ten levels from stuck to gross slip
//! with liftoff, `H` = 1, 3 or 5, `Nt` 64 to 256, the full order (condensed) and the
//! self-correcting FR and NLR sweeps. Each sweep is checked: it reaches the band's end; 20 of
//! its points, chosen at random, solved again from zero at their frequency (another path to
//! the same point) agree with it, or with another point the sweep traced at that frequency;
//! for a reduced sweep, every point is compared with a full-order solution at its frequency on
//! the same branch (`e*` against the actual error, X1).
//!
//! `cargo bench --bench continuation_campaign` runs the whole campaign,
//! `tests/continuation_campaign.rs` a subset with a fixed seed.

pub mod diagnosis;
pub mod mesh;
pub mod model;

use jprom::aft::Discretisation;
use jprom::condensation::CondensedSystem;
use jprom::hbm::{solve_point, ContinuationMethod, sweep, HarmonicSystem, HbmOptions, PointSolution, SweepEnd, SweepGap, SweepOptions, SweepResult};
use jprom::jp::PredictionOptions;
use jprom::model::ContactCoordinates;
use jprom::rom::error_metric::POOR_BASIS_THRESHOLD;
use jprom::rom::{adaptive_sweep, AdaptiveOptions, FrRom, NlrRom, ReducedModel, RomKind};
use model::{Built, ModelSpec};
use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use std::ops::ControlFlow;

/// The ten levels `a / a_ST`, log-spaced from 2 (stuck) to 0.002 (gross slip).
pub fn levels() -> Vec<f64> {
    (0..10).map(|k| 2.0 * (1e-3f64).powf(k as f64 / 9.0)).collect()
}

/// Which solver a sweep ran.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// The full order, condensed onto the contact coordinates.
    Fo,
    Fr,
    Nlr,
}

impl Solver {
    pub fn name(self) -> &'static str {
        match self {
            Solver::Fo => "FO",
            Solver::Fr => "FR",
            Solver::Nlr => "NLR",
        }
    }
}

/// The cold-start checks of one sweep.
#[derive(Clone, Debug, Default)]
pub struct ColdChecks {
    pub checked: usize,
    /// Points whose cold solution is the sweep's point, or another traced point there.
    pub agreed: usize,
    pub other_branch: usize,
    /// `(omega, relative distance to the nearest traced solution)`.
    pub disagreed: Vec<(f64, f64)>,
    /// `(omega, why)`: the solve from zero did not converge.
    pub failed: Vec<(f64, String)>,
}

/// The error checks of one reduced sweep against the full order.
#[derive(Clone, Debug, Default)]
pub struct RomChecks {
    /// Points with a full-order solution at their frequency.
    pub compared: usize,
    /// Points with `e_1 > 1e-6`, and among them those with `e*_1 < e_1`.
    pub above_floor: usize,
    pub not_conservative: Vec<(f64, f64, f64)>,
    /// `(omega, e*_1, X1 error)` of points called good (`e*_1` below the threshold) with an
    /// X1 error above [`X1_WHEN_GOOD`].
    pub called_good_but_wrong: Vec<(f64, f64, f64)>,
    /// Those among them with an X1 error above twice the threshold: what the self-correcting
    /// sweep promises never to call good (docs/formulation.md §10.7).
    pub called_good_far_off: Vec<(f64, f64, f64)>,
    /// Largest X1 error where `e*_1` is below the threshold.
    pub worst_x1_when_good: f64,
    /// The judged error of the self-correcting sweep.
    pub judged: f64,
    /// Points where the paper's `e*_1` alone is below `e_1` (above 1e-6): what the checks
    /// correct.
    pub e_star_below_e: usize,
    /// Whether the sweep says it can be trusted, and why not.
    pub trusted: bool,
    pub trust_reason: Option<String>,
    /// The reduced peak against the full order's ([`SweepResult::peak_by`] of X1): relative errors
    /// of its frequency and of its X1.
    pub peak_omega_error: f64,
    pub peak_x1_error: f64,
}

/// One sweep of the campaign and its checks.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub model: usize,
    pub level: f64,
    pub harmonics: usize,
    pub nt: usize,
    pub solver: Solver,
    pub end: SweepEnd,
    pub failure: Option<String>,
    pub points: usize,
    pub gaps: Vec<SweepGap>,
    pub folds: usize,
    pub branch_points: usize,
    /// Whether a point lies below the band's start by more than 10 % of the band.
    pub turned_back: bool,
    pub seconds: f64,
    pub cold: ColdChecks,
    pub rom: Option<RomChecks>,
    /// Why the sweep could not be run at all (the first point, a basis).
    pub error: Option<String>,
}

impl Outcome {
    pub fn reached_end(&self) -> bool {
        self.error.is_none() && self.end == SweepEnd::ReachedEnd
    }
}

/// `|a - b| / |b|`.
fn relative(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    let s: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
    d / s.max(1e-300)
}

/// The largest relative X1 error of a reduced point whose `e*_1` is below the threshold: what
/// "good" promises.
pub const X1_WHEN_GOOD: f64 = 0.01;

/// Relative distance within which two solutions of the same equations are the same point.
pub const SAME_POINT: f64 = 1e-6;

/// The cold-start checks of `r` on `system` at `count` random points (module doc).
pub fn cold_checks(system: &dyn HarmonicSystem, r: &SweepResult, hopts: &HbmOptions, count: usize, rng: &mut StdRng) -> ColdChecks {
    let mut out = ColdChecks::default();
    let mut idx: Vec<usize> = (0..r.points.len()).collect();
    idx.shuffle(rng);
    for &i in idx.iter().take(count) {
        let p = &r.points[i];
        out.checked += 1;
        // the check is of the branch, not of the cold solver's budget: a solve from zero that
        // runs out of iterations gets five times as many
        let patient = HbmOptions { max_iterations: 5 * hopts.max_iterations, ..hopts.clone() };
        let cold = match solve_point(system, p.omega, None, hopts).or_else(|_| solve_point(system, p.omega, None, &patient)) {
            Ok(c) => c,
            Err(e) => {
                out.failed.push((p.omega, e.to_string()));
                continue;
            }
        };
        let d = relative(&cold.z, &p.z);
        if d <= SAME_POINT {
            out.agreed += 1;
            continue;
        }
        // another part of the traced branch at this frequency: its points solved there
        let mut best = d;
        for w in r.points.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if (a.omega - p.omega) * (b.omega - p.omega) > 0.0 || a.omega == b.omega {
                continue;
            }
            let s = (p.omega - a.omega) / (b.omega - a.omega);
            let guess: Vec<f64> = a.z.iter().zip(&b.z).map(|(x, y)| x + s * (y - x)).collect();
            if let Ok(q) = solve_point(system, p.omega, Some(&guess), hopts) {
                best = best.min(relative(&cold.z, &q.z));
            }
            if best <= SAME_POINT {
                break;
            }
        }
        if best <= SAME_POINT {
            out.agreed += 1;
            out.other_branch += 1;
        } else {
            out.disagreed.push((p.omega, best));
        }
    }
    out
}

/// The first-harmonic amplitude of output 0.
pub fn x1(p: &PointSolution) -> f64 {
    p.output_amplitude(1, 0)
}

/// The full-order solution at `omega` on the branch of `fo` nearest the amplitude `a`: solved
/// from the three sweep points nearest in frequency and amplitude.
fn full_order_at(condensed: &CondensedSystem, fo: &SweepResult, omega: f64, a: f64, hopts: &HbmOptions) -> Option<PointSolution> {
    let peak = fo.points.iter().map(x1).fold(0.0, f64::max).max(1e-300);
    let mut idx: Vec<usize> = (0..fo.points.len()).collect();
    let key = |p: &PointSolution| (p.omega - omega).abs() / omega + (x1(p) - a).abs() / peak;
    idx.sort_by(|&i, &j| key(&fo.points[i]).total_cmp(&key(&fo.points[j])));
    idx.iter().take(3).find_map(|&i| solve_point(condensed, omega, Some(&fo.points[i].z), hopts).ok())
}

/// Runs one level of one model: the full order, then the reduced sweeps of `solvers`, with
/// their checks.
#[allow(clippy::too_many_arguments)]
pub fn run_level(index: usize, built: &Built, level: f64, harmonics: usize, nt: usize, solvers: &[Solver], method: ContinuationMethod, cold_points: usize, seed: u64) -> Vec<Outcome> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut model = built.model.clone();
    model.excitation.dynamic_scale = built.level_scale / level;
    let hopts = HbmOptions::default();
    let sopts = SweepOptions { method, ..SweepOptions::band(built.band.0, built.band.1) };
    let disc = Discretisation::with_nt(harmonics, nt);
    let span = built.band.1 - built.band.0;
    let base = |solver: Solver| Outcome {
        model: index,
        level,
        harmonics,
        nt,
        solver,
        end: SweepEnd::StepTooSmall,
        failure: None,
        points: 0,
        gaps: Vec::new(),
        folds: 0,
        branch_points: 0,
        turned_back: false,
        seconds: 0.0,
        cold: ColdChecks::default(),
        rom: None,
        error: None,
    };
    let fill = |o: &mut Outcome, r: &SweepResult, seconds: f64| {
        o.end = r.end;
        o.failure = r.failure.clone();
        o.points = r.points.len();
        o.gaps = r.gaps.clone();
        o.folds = r.folds.len();
        o.branch_points = r.events.iter().filter(|e| e.kind == jprom::hbm::EventKind::BranchPoint).count();
        o.turned_back = r.points.iter().any(|p| p.omega < built.band.0 - 0.1 * span);
        o.seconds = seconds;
    };
    let mut out = Vec::new();
    let condensed = match CondensedSystem::new(&model, disc) {
        Ok(c) => c,
        Err(e) => {
            let mut o = base(Solver::Fo);
            o.error = Some(e.to_string());
            return vec![o];
        }
    };
    let t = std::time::Instant::now();
    let fo = match sweep(&condensed, &sopts, &hopts, &mut |_| ControlFlow::Continue(())) {
        Ok(r) => r,
        Err(e) => {
            let mut o = base(Solver::Fo);
            o.error = Some(e.to_string());
            return vec![o];
        }
    };
    let mut o = base(Solver::Fo);
    fill(&mut o, &fo, t.elapsed().as_secs_f64());
    o.cold = cold_checks(&condensed, &fo, &hopts, cold_points, &mut rng);
    out.push(o);
    let coords = match ContactCoordinates::new(&model, disc) {
        Ok(c) => c,
        Err(_) => return out,
    };
    for &solver in solvers.iter().filter(|s| **s != Solver::Fo) {
        let kind = if solver == Solver::Fr { RomKind::Fr } else { RomKind::Nlr };
        let mut o = base(solver);
        let t = std::time::Instant::now();
        let a = match adaptive_sweep(&model, disc, &PredictionOptions::new(built.band), &sopts, &hopts, &AdaptiveOptions { kind, ..AdaptiveOptions::default() }) {
            Ok(a) => a,
            Err(e) => {
                o.error = Some(e.to_string());
                out.push(o);
                continue;
            }
        };
        fill(&mut o, &a.sweep, t.elapsed().as_secs_f64());
        let rom: Box<dyn ReducedModel> = match kind {
            RomKind::Fr => Box::new(FrRom::new(&coords, &a.basis).expect("the sweep's own basis")),
            RomKind::Nlr => Box::new(NlrRom::new(&condensed, &a.basis).expect("the sweep's own basis")),
        };
        o.cold = cold_checks(rom.as_ref(), &a.sweep, &hopts, cold_points, &mut rng);
        let peak = |r: &SweepResult| r.peak_by(x1);
        let (peak_omega_error, peak_x1_error) = match (peak(&a.sweep), peak(&fo)) {
            (Some((wr, xr)), Some((wf, xf))) => ((wr - wf).abs() / wf, (xr - xf).abs() / xf.max(1e-300)),
            _ => (f64::INFINITY, f64::INFINITY),
        };
        let mut checks = RomChecks { judged: a.worst_error, trusted: a.trust.trusted, trust_reason: a.trust.reason.clone(), peak_omega_error, peak_x1_error, ..RomChecks::default() };
        let judged = a.judged_errors();
        for ((q, paper), &e_star) in a.sweep.points.iter().zip(&a.predicted_errors).zip(&judged) {
            let Some((f, e)) = diagnosis::nearest_full_order(&condensed, &fo, rom.as_ref(), q, &hopts) else { continue };
            checks.compared += 1;
            let x1_error = (x1(q) - x1(&f)).abs() / x1(&f).max(1e-300);
            if e[1] > 1e-6 {
                checks.above_floor += 1;
                if e_star < e[1] {
                    checks.not_conservative.push((q.omega, e_star, e[1]));
                }
                if paper[1] < e[1] {
                    checks.e_star_below_e += 1;
                }
            }
            if e_star < POOR_BASIS_THRESHOLD {
                checks.worst_x1_when_good = checks.worst_x1_when_good.max(x1_error);
                if x1_error > X1_WHEN_GOOD {
                    checks.called_good_but_wrong.push((q.omega, e_star, x1_error));
                }
                if x1_error > 2.0 * POOR_BASIS_THRESHOLD {
                    checks.called_good_far_off.push((q.omega, e_star, x1_error));
                }
            }
        }
        o.rom = Some(checks);
        out.push(o);
    }
    out
}

/// `Nt` for `H`: a power of two from 64 to 256, at least jprom's default for `H`.
pub fn random_nt(rng: &mut StdRng, harmonics: usize) -> usize {
    let lowest = jprom::aft::default_nt(harmonics).max(64);
    let choices: Vec<usize> = [64, 128, 256].into_iter().filter(|&n| n >= lowest).collect();
    *choices.choose(rng).unwrap_or(&lowest)
}

/// `count` (at least 3) models from `seed` among which every contact site occurs (end patch,
/// tip line, node pairs): the first model of each site as drawn, then the rest in order.
pub fn models_with_every_site(seed: u64, count: usize) -> Vec<(ModelSpec, Built)> {
    let mut rng = StdRng::seed_from_u64(seed);
    let kind = |s: &ModelSpec| std::mem::discriminant(&s.site);
    let mut picked: Vec<(ModelSpec, Built)> = Vec::new();
    let mut rest: Vec<(ModelSpec, Built)> = Vec::new();
    for _ in 0..50 * count.max(3) {
        let spec = ModelSpec::random(&mut rng);
        let Ok(b) = model::build(&spec, None) else { continue };
        if picked.iter().any(|(p, _)| kind(p) == kind(&spec)) {
            rest.push((spec, b));
        } else {
            picked.push((spec, b));
        }
        if picked.len() == 3 && picked.len() + rest.len() >= count {
            break;
        }
    }
    let fill = count.saturating_sub(picked.len());
    picked.extend(rest.into_iter().take(fill));
    picked
}

/// `count` models from `seed`, each assembled natively ([`model::build`] without a CalculiX
/// directory), with the ones that could not be built and why.
pub fn models(seed: u64, count: usize) -> (Vec<(ModelSpec, Built)>, Vec<(ModelSpec, String)>) {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut ok = Vec::new();
    let mut failed = Vec::new();
    while ok.len() < count {
        let spec = ModelSpec::random(&mut rng);
        match model::build(&spec, None) {
            Ok(b) => ok.push((spec, b)),
            Err(e) => {
                failed.push((spec, e));
                if failed.len() > 4 * count {
                    break;
                }
            }
        }
    }
    (ok, failed)
}

/// Prints one line per outcome.
pub fn print_outcome(o: &Outcome) {
    let cold = &o.cold;
    let rom = o.rom.as_ref().map_or(String::new(), |r| {
        format!(
            ", judged<e at {}/{} (paper e* < e at {}), called good but X1 off by > 1 %: {} (> 2x the threshold: {}), worst X1 when good {:.1e}, judged {:.1e}, peak off by {:.1e} in omega, {:.1e} in X1, {}",
            r.not_conservative.len(),
            r.above_floor,
            r.e_star_below_e,
            r.called_good_but_wrong.len(),
            r.called_good_far_off.len(),
            r.worst_x1_when_good,
            r.judged,
            r.peak_omega_error,
            r.peak_x1_error,
            r.trust_reason.as_ref().map_or("trusted".to_string(), |w| format!("not trusted: {w}"))
        )
    });
    println!(
        "model {} level {:.3} H {} Nt {} {:>3}: {} {} pts, {} gaps, {} folds, {:.2} s; cold {}/{} (other branch {}, disagree {}, failed {}){rom}{}",
        o.model,
        o.level,
        o.harmonics,
        o.nt,
        o.solver.name(),
        o.error.as_ref().map_or(o.end.name().to_string(), |_| "error".to_string()),
        o.points,
        o.gaps.len(),
        o.folds,
        o.seconds,
        cold.agreed,
        cold.checked,
        cold.other_branch,
        cold.disagreed.len(),
        cold.failed.len(),
        o.error.as_ref().or(o.failure.as_ref()).map_or(String::new(), |e| format!(" -- {e}"))
    );
}

/// A random `H` of 1, 3, 5.
pub fn random_harmonics(rng: &mut StdRng) -> usize {
    [1, 3, 5][rng.gen_range(0..3)]
}

/// The campaign's figures: sweeps, reached end, with gaps, stalled, turned back, median
/// points, cold-start disagreements, reduced points called good but wrong, time.
pub fn print_summary(outcomes: &[Outcome], seconds: f64) {
    for solver in [Solver::Fo, Solver::Fr, Solver::Nlr] {
        let of: Vec<&Outcome> = outcomes.iter().filter(|o| o.solver == solver).collect();
        if of.is_empty() {
            continue;
        }
        let mut points: Vec<usize> = of.iter().map(|o| o.points).collect();
        points.sort_unstable();
        let reached = of.iter().filter(|o| o.reached_end()).count();
        let with_gaps = of.iter().filter(|o| o.reached_end() && !o.gaps.is_empty()).count();
        let stalled = of.iter().filter(|o| o.error.is_none() && o.end == SweepEnd::StepTooSmall).count();
        let capped = of.iter().filter(|o| o.error.is_none() && o.end == SweepEnd::MaxPoints).count();
        let left = of.iter().filter(|o| o.error.is_none() && o.end == SweepEnd::LeftBand).count();
        let errors = of.iter().filter(|o| o.error.is_some()).count();
        let turned_back = of.iter().filter(|o| o.turned_back).count();
        let disagree: usize = of.iter().map(|o| o.cold.disagreed.len()).sum();
        let cold_failed: usize = of.iter().map(|o| o.cold.failed.len()).sum();
        let checked: usize = of.iter().map(|o| o.cold.checked).sum();
        let wrong: usize = of.iter().filter_map(|o| o.rom.as_ref()).map(|r| r.called_good_but_wrong.len()).sum();
        let far: usize = of.iter().filter_map(|o| o.rom.as_ref()).map(|r| r.called_good_far_off.len()).sum();
        let not_cons: usize = of.iter().filter_map(|o| o.rom.as_ref()).map(|r| r.not_conservative.len()).sum();
        let above: usize = of.iter().filter_map(|o| o.rom.as_ref()).map(|r| r.above_floor).sum();
        let paper: usize = of.iter().filter_map(|o| o.rom.as_ref()).map(|r| r.e_star_below_e).sum();
        let untrusted = of.iter().filter_map(|o| o.rom.as_ref()).filter(|r| !r.trusted).count();
        let time: f64 = of.iter().map(|o| o.seconds).sum();
        println!(
            "{:>3}: {} sweeps, {} reached the end ({} with gaps), {} stalled, {} point cap, {} left the band, {} errors; {} ran below the band by > 10 %; median {} points; cold starts {} checked, {} disagree, {} failed{}; {:.1} s",
            solver.name(),
            of.len(),
            reached,
            with_gaps,
            stalled,
            capped,
            left,
            errors,
            turned_back,
            points[points.len() / 2],
            checked,
            disagree,
            cold_failed,
            if solver == Solver::Fo { String::new() } else { format!("; judged error < e at {not_cons} of {above} points (the paper's e* alone at {paper}), {wrong} points called good with X1 off by > 1 % ({far} by > 2x the threshold), {untrusted} not trusted") },
            time
        );
    }
    for o in outcomes.iter().filter(|o| !o.gaps.is_empty()) {
        for g in &o.gaps {
            println!("gap: model {} level {:.3} {}: {:.3} to {:.3} rad/s: {}", o.model, o.level, o.solver.name(), g.from, g.to, g.reason);
        }
    }
    for o in outcomes.iter().filter(|o| !o.reached_end()) {
        println!("did not reach the end: model {} level {:.3} {}: {}", o.model, o.level, o.solver.name(), o.error.clone().or_else(|| o.failure.clone()).unwrap_or_else(|| o.end.name().into()));
    }
    println!("campaign: {} sweeps in {seconds:.1} s", outcomes.len());
}
