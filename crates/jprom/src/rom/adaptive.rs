//! The self-correcting reduced sweep (docs/formulation.md §8.8 last paragraph, §10): predict a basis from
//! the stuck mode, sweep the reduced model, evaluate `e*_1` at every point; if its worst value
//! exceeds the threshold, predict a new set of JP modes with the reduced solution at the point
//! of worst `e*_1` as generating shape (its static part and first harmonic, cos and sin parts,
//! (39)) and sweep with them alone in place of the basis ([`CorrectionKind::Replaced`]); if
//! that pass is within the threshold the new modes are the basis (of the size of one
//! prediction), otherwise they are united with the current basis ([`JpBasis::union`]: stacked
//! and re-conditioned by SVD, [`CorrectionKind::Regenerated`]) and swept again, and the
//! better of the two is kept. On the blade at
//! alpha_ST / 100 the stuck-mode basis [37, 11] is replaced by [25, 11] (judged error 9.0e-3);
//! the union would be [44, 20]. Each of these sweeps is reported as a correction of its own,
//! but `max_corrections` counts steps: a regeneration is one step, its union included (on the
//! 50-contact blade at alpha_ST / 3000, four steps reach the threshold; counted one per sweep
//! they ran out first). After a regeneration the next correction enlarges `gamma`
//! (conditioning the last prediction's modes again with the larger `gamma`, which needs no
//! eigen solve, and uniting as well); after a `gamma` step, the next regenerates if that step
//! halved the worst error (its reduced solution is then the better generating shape), else
//! enlarges `gamma` again (`regenerates_next`; on the demo blade at alpha_ST / 3000, FR from
//! the stuck-mode basis: two steps, 2.3 s, where regenerating after every regeneration that
//! halved the error took four, 5.9 s; the path depends on the model's rounding,
//! tests/correction_policy.rs). A
//! correction after which the worst `e*_1` is larger is reported (its `worst_error_after` is
//! above its `worst_error_before`) and dropped: the sweep goes on from the basis before it, so
//! the result is the best basis found.
//!
//! **Screening** ([`AdaptiveOptions::screen`], default on; docs/formulation.md §10.5). A
//! candidate basis (the regenerated modes alone, a union, a `gamma` step) is first solved at
//! the frequency where the current basis was judged worst, then at the other points where the
//! bases before it were judged poor (at most four points, a resonance's checks counted once),
//! and its linearised error checked there (one reduced solve, one full-order factorisation
//! each); above the threshold at one of them it cannot pass, so it is not swept
//! ([`Correction::swept`] false, its error there reported) but competes at that point: the
//! better one is kept and the next correction starts from its solution there. Within the threshold there it is swept; a `gamma` step swept after steps
//! judged at one point is followed by a regeneration from its own worst point. The first basis is screened at the
//! band's start. A candidate that passes those points is screened where its own response
//! peaks ([`crate::rom::tangent_peak`], the tangent response at its first solution); a
//! `gamma` step judged at such a new point is followed by a regeneration from there. A basis kept without a pass is swept before it is the result. On the demo's
//! blade at 98 contact nodes, gross slip, FR from the stuck-mode basis: three passes instead
//! of six, the same final basis [33, 39] and judged error 1.38e-2.
//!
//! **How a pass is judged.** `e*` is evaluated at every point; it flags, the **linearised
//! error** ([`crate::rom::error_metric::linearised_error`], one full-order Newton step from the
//! reduced solution, equal to the actual error to first order) decides: it is evaluated at the
//! reduced resonance and at the [`CHECKED_POINTS`] points of largest `e*`, and the pass is judged
//! by its largest value there. `e*` misjudges both ways (see [`crate::rom::error_metric`]): it can
//! fall below the actual error near a resonance, and it overstates it by the ratio of the
//! structure's dynamic stiffness to the contact stiffness where contacts stick off resonance
//! (measured on the twisted plate: `e*_1 = 0.67` for an actual `e_1 = 8.5e-4`, which would
//! spend every correction on a good basis). Where the condensed full-order Jacobian is too
//! large to factorise for a check ([`MAX_CHECK_UNKNOWNS`]), or with
//! [`AdaptiveOptions::verify`] off, the pass is judged by `e*` as in the paper.
//! Each check also gives the linearised error of the static contact displacement
//! ([`ErrorCheck::static_displacement`]), reported by [`AdaptiveSweep::worst_static_error`]
//! but not judged: at gross slip the static term converges only with a nearly complete basis
//! (docs/formulation.md §10.6), which no correction short of the full order gives.
//! Corrections stop when the worst error is below the threshold, after
//! `max_corrections`, or when no correction is left to try (a dropped correction at the
//! largest `gamma` would only be repeated); [`AdaptiveSweep::end`] says which.

use super::tangent_peak::tangent_peak;
use super::{ReducedModel, RomKind};
use crate::aft::Discretisation;
use crate::condensation::CondensedSystem;
use crate::error::{JpError, Result};
use crate::rom::error_metric::{checked_error, linearised_errors, CheckBasis, POOR_BASIS_THRESHOLD};
use crate::hbm::{HarmonicSystem, HbmOptions, PointSolution, SweepEnd, SweepOptions, SweepResult};
use crate::jp::{predict_basis, predict_modes, GeneratingShape, JpBasis, PredictedModes, PredictionOptions, PredictionReport};
use crate::model::{ContactCoordinates, Model};
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;


/// Settings of [`adaptive_sweep`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveOptions {
    pub kind: RomKind,
    /// `e*_1` above which a basis is corrected (default [`POOR_BASIS_THRESHOLD`] = 0.05).
    pub threshold: f64,
    /// Most correction steps (default 5; on the blade at alpha_ST / 3000 the fourth brought the
    /// worst e*_1 from 0.077 to 0.026). A regeneration is one step: the regenerated modes
    /// alone and, unless they are within the threshold, their union with the basis. With
    /// [`AdaptiveOptions::screen`], a step whose candidates were all judged at screening points
    /// (none swept) counts only up to `2 max_corrections` steps in all (on the test kit's
    /// 50-contact blade at gross slip the first three steps were screened at the band's start,
    /// and counted each the sweep ended above the threshold; tests/screening_points.rs).
    pub max_corrections: usize,
    /// Factor applied to `gamma` when regeneration alone is not enough (default 10), up to
    /// `max_gamma` (default 1e6).
    pub gamma_growth: f64,
    pub max_gamma: f64,
    /// Judge each pass by the linearised error at the reduced resonance and the points of
    /// largest `e*` (default true; each check costs about one full-order Newton iteration); off,
    /// by `e*` alone. See the module doc.
    pub verify: bool,
    /// The output whose first-harmonic amplitude locates a pass's resonance, where its
    /// linearised error is checked (default 0, the first output).
    #[serde(default)]
    pub response_output: usize,
    /// `p̂` samples of a regeneration's prediction, along the reduced solution it starts from
    /// (default [`REGENERATION_SAMPLES`] = 10; the first basis takes the prediction options'
    /// `n_samples`). See [`REGENERATION_SAMPLES`] for why fewer.
    #[serde(default = "regeneration_samples_default")]
    pub regeneration_samples: usize,
    /// Judge each candidate basis first at the current basis' judged point (one reduced solve
    /// and one linearised check there) and sweep it over the band only if it is within the
    /// threshold there (default true; false sweeps every candidate). See the module doc.
    #[serde(default = "screen_default")]
    pub screen: bool,
}

/// Default [`AdaptiveOptions::regeneration_samples`]. A regeneration's generating shape is a
/// reduced solution, whose contact states are those near `p̂ = 1`, where the first basis' 100
/// samples span the stuck mode from first slip to the largest level. Along a gross-slip
/// solution nearly every one of 100 samples is a pattern of its own on 98 and 242 contact
/// nodes, so a regeneration cost as much as the first basis and added as many modes; with 10
/// the bases are smaller and as accurate (docs/formulation.md §8.9, measured there).
pub const REGENERATION_SAMPLES: usize = 10;

fn screen_default() -> bool {
    true
}

fn regeneration_samples_default() -> usize {
    REGENERATION_SAMPLES
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        AdaptiveOptions { kind: RomKind::Fr, threshold: POOR_BASIS_THRESHOLD, max_corrections: 5, gamma_growth: 10.0, max_gamma: 1e6, verify: true, response_output: 0, regeneration_samples: REGENERATION_SAMPLES, screen: true }
    }
}

/// Points of largest `e*_1` at which a pass checks the linearised error (besides the reduced
/// resonance).
pub(crate) const CHECKED_POINTS: usize = 3;

/// Largest condensed full-order system, `(2H + 1) n_w` unknowns, whose Jacobian a check
/// factorises (a dense LU: about 10 s at this size on 2 cores).
pub(crate) const MAX_CHECK_UNKNOWNS: usize = 12_000;

/// Largest condensed full-order system, `(2H + 1) n_w` unknowns, at which every point of a pass
/// is checked (each check about one full-order Newton iteration: 0.1 s at this size on 2
/// cores). Above it, the reduced resonance, the [`CHECKED_POINTS`] points of largest `e*` and
/// [`SPREAD_CHECKS`] points spread along the branch are; the others are judged by `e*`.
pub(crate) const EVERY_POINT_CHECK_UNKNOWNS: usize = 3_000;

/// Points spread evenly along a pass' branch that are checked when not every point is.
pub(crate) const SPREAD_CHECKS: usize = 8;

/// The points of a pass to check: all of them on a condensed system of at most
/// [`EVERY_POINT_CHECK_UNKNOWNS`] unknowns, else `peak`, the points of largest `e*_1` and
/// points spread along the branch, each once.
fn checked_points(errors: &[Vec<f64>], peak: usize, unknowns: usize) -> Vec<usize> {
    let n = errors.len();
    if unknowns <= EVERY_POINT_CHECK_UNKNOWNS {
        return (0..n).collect();
    }
    let mut by_error: Vec<usize> = (0..n).collect();
    by_error.sort_by(|&a, &b| errors[b][1].total_cmp(&errors[a][1]));
    let mut at = vec![peak];
    at.extend(by_error.into_iter().filter(|&i| i != peak).take(CHECKED_POINTS));
    for k in 0..SPREAD_CHECKS {
        let i = (k * n.saturating_sub(1)) / SPREAD_CHECKS.saturating_sub(1).max(1);
        if !at.contains(&i) {
            at.push(i);
        }
    }
    at
}

/// A point of a pass where the linearised error was checked.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ErrorCheck {
    /// Index of the point in the pass's sweep, and its frequency.
    pub index: usize,
    pub omega: f64,
    /// `e*_1` and the linearised error `e_lin_1` there.
    pub predicted: f64,
    pub linearised: f64,
    /// The linearised error of the static contact displacement there
    /// ([`crate::rom::error_metric::LinearisedErrors::static_displacement`]). It does not judge
    /// the pass (the paper's criterion is the first harmonic's, and at gross slip a good static
    /// term needs a nearly complete basis, docs/formulation.md §10.6);
    /// [`AdaptiveSweep::worst_static_error`] reports it.
    #[serde(default)]
    pub static_displacement: f64,
    /// The judged error `e_1` there: `e_lin_1` at the checks that judge a pass, the checked
    /// error ([`crate::rom::error_metric::checked_error`]) at the final pass' verdict checks
    /// ([`AdaptiveSweep::checks`]).
    #[serde(default)]
    pub checked: f64,
    /// How the checked error was reached (`None` where `checked` is `e_lin_1`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub basis: Option<CheckBasis>,
}

/// Why the self-correcting sweep stopped correcting.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum CorrectionEnd {
    /// The worst error of the final pass is within the threshold.
    WithinThreshold,
    /// `max_corrections` correction steps were made.
    MaxCorrections,
    /// No correction is left to try: a regeneration did not improve the basis and `gamma` is at
    /// `max_gamma`.
    NoProgress,
    /// The caller stopped a pass.
    Stopped,
}

impl CorrectionEnd {
    /// A short name: "within_threshold", "max_corrections", "no_progress", "cancelled" (the word
    /// of [`crate::hbm::SweepEnd::name`] for a sweep its caller stopped).
    pub fn name(self) -> &'static str {
        match self {
            CorrectionEnd::WithinThreshold => "within_threshold",
            CorrectionEnd::MaxCorrections => "max_corrections",
            CorrectionEnd::NoProgress => "no_progress",
            CorrectionEnd::Stopped => "cancelled",
        }
    }
}

/// What a correction did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum CorrectionKind {
    /// Modes predicted along the reduced solution at `from_omega` (the point of worst `e*_1`)
    /// and united with the basis.
    Regenerated { from_omega: f64 },
    /// The last prediction's modes conditioned with a larger `gamma` (the same samples and
    /// patterns: no eigen solve) and united with the basis.
    GammaIncreased { gamma: f64 },
    /// Modes predicted along the reduced solution at `from_omega`, alone, in place of the basis.
    Replaced { from_omega: f64 },
}

/// One correction of the basis and its effect.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Correction {
    pub kind: CorrectionKind,
    /// Worst `e*_1` over the sweep before and after (before is infinite when the previous basis
    /// did not converge at the first frequency of the band, so there was no sweep to judge;
    /// after is infinite when the corrected basis did not). The corrected basis is kept only if
    /// `after < before`; of a [`CorrectionKind::Replaced`] and the union that follows it, the
    /// one with the smaller `after`.
    pub worst_error_before: f64,
    pub worst_error_after: f64,
    /// Basis sizes `n_h` after.
    pub sizes: Vec<usize>,
    /// Whether its basis was swept over the band. Not swept: modes already in the basis' span
    /// (the error unchanged), or, with [`AdaptiveOptions::screen`], a basis whose error at the
    /// current basis' judged point (`worst_error_after`, then) is above the threshold.
    #[serde(default = "swept_default")]
    pub swept: bool,
}

fn swept_default() -> bool {
    true
}

/// Result of [`adaptive_sweep`].
#[derive(Clone, Debug)]
pub struct AdaptiveSweep {
    /// The final reduced sweep (reduced unknowns in `points[i].z`).
    pub sweep: SweepResult,
    /// `e*_h`, `h = 0..=H`, at every point of the final sweep.
    pub predicted_errors: Vec<Vec<f64>>,
    /// The final basis and the report of its prediction.
    pub basis: JpBasis,
    pub prediction: PredictionReport,
    /// Corrections made, in order (empty if the first basis was good).
    pub corrections: Vec<Correction>,
    /// The checks of the final pass its verdict rests on ([`AdaptiveSweep::trust`]): the
    /// checked error at every point where the condensed full order has at most 3,000 unknowns,
    /// else at the resonance, the points of largest `e*_1` and points spread along the branch
    /// (docs/formulation.md §10.7); empty without checks.
    pub checks: Vec<ErrorCheck>,
    /// The worst error of the final pass, which the corrections were judged by: the largest
    /// `e_lin_1` at the checks, or the largest `e*_1` without checks (see the module doc).
    pub worst_error: f64,
    /// Why the corrections stopped.
    pub end: CorrectionEnd,
    /// Whether the final sweep can be trusted, and if not why ([`Trust`]).
    pub trust: Trust,
}

/// Whether a self-correcting sweep's result can be trusted (docs/formulation.md §10.7): its
/// final pass covered the band and every point's judged error is within the threshold (the
/// checked error where the point was checked, `e*_1` elsewhere). A result that is not trusted
/// says why; its peak is not the reduced model's resonance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trust {
    pub trusted: bool,
    /// Why not (`None` when trusted).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

impl Trust {
    /// The verdict on a final pass `sweep` whose points are judged by `judged` (one value per
    /// point, NaN as the worst) against `threshold`.
    pub fn of(sweep: &SweepResult, judged: &[f64], threshold: f64) -> Trust {
        let mut why = Vec::new();
        if !sweep.reached_end() {
            let at = sweep.points.last().map_or(String::new(), |p| format!(" at {:.6e} rad/s", p.omega));
            let failure = sweep.failure.as_ref().map_or(String::new(), |f| format!(": {f}"));
            why.push(format!("the final reduced sweep did not cover the band ({}{at}{failure})", sweep.end.name()));
        }
        let above: Vec<usize> = (0..judged.len()).filter(|&i| !(judged[i] <= threshold)).collect();
        if let Some(&w) = above.iter().max_by(|&&a, &&b| nan_as_worst(judged[a]).total_cmp(&nan_as_worst(judged[b]))) {
            let e = nan_as_worst(judged[w]);
            let value = if e.is_finite() { format!("{e:.3e}") } else { "not bounded".into() };
            why.push(format!("at {} of {} points the judged error is above the threshold {threshold:e} (worst {value}, at {:.6e} rad/s)", above.len(), judged.len(), sweep.points[w].omega));
        }
        if why.is_empty() {
            Trust { trusted: true, reason: None }
        } else {
            Trust { trusted: false, reason: Some(why.join("; ")) }
        }
    }
}

impl AdaptiveSweep {
    /// The judged error `e_1` at every point of the final sweep: the checked error
    /// ([`ErrorCheck::checked`]) where the point was checked, `e*_1` elsewhere.
    pub fn judged_errors(&self) -> Vec<f64> {
        judged_errors(&self.predicted_errors, &self.checks)
    }

    /// The largest linearised error of the static contact displacement at the final pass'
    /// checks ([`ErrorCheck::static_displacement`]; `None` without checks). Above the
    /// threshold the static term `X0` is poor even where the first harmonic is within it.
    pub fn worst_static_error(&self) -> Option<f64> {
        self.checks.iter().map(|c| nan_as_worst(c.static_displacement)).reduce(f64::max)
    }
}

struct Pass {
    sweep: SweepResult,
    errors: Vec<Vec<f64>>,
    checks: Vec<ErrorCheck>,
    /// The judged error (see the module doc).
    worst: f64,
    /// Index of the point with the worst error.
    worst_at: usize,
}

#[allow(clippy::too_many_arguments)]
fn run_pass(
    rom: &dyn ReducedModel,
    condensed: Option<&CondensedSystem>,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    (pass, response): (usize, usize),
    on_point: &mut dyn FnMut(usize, &PointSolution) -> ControlFlow<()>,
) -> Result<Pass> {
    let (sw, errors) = super::sweep_with_predicted_error(rom, sopts, hopts, &mut |p: &PointSolution| on_point(pass, p))?;
    if sw.points.is_empty() {
        return Err(JpError::NoConvergence { what: "reduced sweep (no point)".into(), iterations: 0, residual: f64::NAN, tolerance: f64::NAN });
    }
    let mut worst = -1.0f64;
    let mut worst_at = 0;
    for (i, e) in errors.iter().enumerate() {
        // A NaN e* counts as worst.
        if !(e[1] <= worst) {
            worst = nan_as_worst(e[1]);
            worst_at = i;
        }
    }
    let mut checks = Vec::new();
    if let Some(condensed) = condensed {
        let amplitude = |p: &PointSolution| if response < p.n_outputs { p.output_amplitude(1, response) } else { 0.0 };
        let peak = (0..sw.points.len()).max_by(|&a, &b| amplitude(&sw.points[a]).total_cmp(&amplitude(&sw.points[b]))).unwrap_or(0);
        let mut by_error: Vec<usize> = (0..sw.points.len()).collect();
        by_error.sort_by(|&a, &b| errors[b][1].total_cmp(&errors[a][1]));
        let mut at = vec![peak];
        at.extend(by_error.into_iter().filter(|&i| i != peak).take(CHECKED_POINTS));
        let (mut judged, mut judged_at) = (-1.0f64, 0);
        for i in at {
            let p = &sw.points[i];
            // A singular full-order Jacobian at this point leaves it unchecked.
            if let Ok(lin) = linearised_errors(rom, condensed, p.omega, &p.z) {
                let e = &lin.force;
                checks.push(ErrorCheck { index: i, omega: p.omega, predicted: errors[i][1], linearised: e[1], static_displacement: lin.static_displacement, checked: nan_as_worst(e[1]), basis: None });
                if !(e[1] <= judged) {
                    judged = nan_as_worst(e[1]);
                    judged_at = i;
                }
            }
        }
        if !checks.is_empty() {
            worst = judged;
            worst_at = judged_at;
        }
    }
    Ok(Pass { sweep: sw, errors, checks, worst: worst.max(0.0), worst_at })
}

/// The judged error `e_1` per point: the checked error where the point was checked, `e*_1`
/// elsewhere.
pub(crate) fn judged_errors(errors: &[Vec<f64>], checks: &[ErrorCheck]) -> Vec<f64> {
    let mut judged: Vec<f64> = errors.iter().map(|e| e.get(1).copied().unwrap_or(0.0)).collect();
    for c in checks {
        if let Some(j) = judged.get_mut(c.index) {
            *j = c.checked;
        }
    }
    judged
}

/// A basis of the self-correcting sweep with its reduced model and what judged it.
struct Judged {
    basis: JpBasis,
    prediction: PredictionReport,
    rom: Box<dyn ReducedModel>,
    /// Its pass over the band; `None` for a candidate judged at one point only (screened).
    pass: Option<Pass>,
    /// The point that judged it (its pass' worst point, or the screening point), the reduced
    /// solution there, and the judged error.
    omega: f64,
    z: Vec<f64>,
    error: f64,
    /// Its error at the first screening point (the current basis' judged point).
    screened: Option<f64>,
}

impl Judged {
    fn swept(basis: JpBasis, prediction: PredictionReport, rom: Box<dyn ReducedModel>, pass: Pass) -> Self {
        let p = &pass.sweep.points[pass.worst_at];
        let (omega, z, error) = (p.omega, p.z.clone(), pass.worst);
        Judged { basis, prediction, rom, pass: Some(pass), omega, z, error, screened: None }
    }
    fn unswept(basis: JpBasis, prediction: PredictionReport, rom: Box<dyn ReducedModel>) -> Self {
        Judged { basis, prediction, rom, pass: None, omega: f64::NAN, z: Vec::new(), error: f64::INFINITY, screened: None }
    }
    /// The error by which it competes with a basis judged at one point only (`unswept`): its
    /// error at that point when it was screened there, else its judged error.
    fn error_against(&self, unswept: bool) -> f64 {
        match (unswept, self.screened) {
            (true, Some(e)) => e,
            _ => self.error,
        }
    }
    fn stopped(&self) -> bool {
        self.pass.as_ref().is_some_and(|p| p.sweep.end == SweepEnd::StoppedByCaller)
    }
}

/// The reduced solution of `rom` at `omega` alone (from the linear guess, with the solver's
/// fallbacks) and its linearised error `e_lin_1` there; `None` where it does not solve or the
/// check fails (a singular full-order Jacobian).
fn screen(rom: &dyn ReducedModel, condensed: &CondensedSystem, omega: f64, hopts: &HbmOptions) -> Option<(Vec<f64>, f64)> {
    let p = crate::hbm::solve_point(rom, omega, None, hopts).ok()?;
    let e = linearised_errors(rom, condensed, omega, &p.z).ok()?.force[1];
    Some((p.z, nan_as_worst(e)))
}

/// What screening found of a candidate: the first point where its linearised error is above
/// the threshold (the frequency, its reduced solution there and the error), and its error at
/// the first point that was asked for.
struct Screening {
    failed: Option<(f64, Vec<f64>, f64)>,
    first_error: Option<f64>,
}

/// Screens a candidate (`rom`) at `omegas` in turn ([`screen`]; points that do not solve are
/// passed over) and then where its own tangent response peaks in the band, estimated from its
/// first solution ([`tangent_peak`]), unless that is one of `omegas`: a basis that passes
/// where the bases before it failed may still fail at its resonance, which its pass would
/// find only after sweeping the band (at gross slip, the stuck-mode basis' first corrections
/// pass at the band's start and fail at the slipping resonance).
fn screen_candidate(rom: &dyn ReducedModel, condensed: &CondensedSystem, omegas: &[f64], threshold: f64, sopts: &SweepOptions, hopts: &HbmOptions) -> Screening {
    let mut first_error = None;
    let mut first_solution = None;
    for (i, &omega) in omegas.iter().enumerate() {
        let Some((z, e)) = screen(rom, condensed, omega, hopts) else { continue };
        if i == 0 {
            first_error = Some(e);
        }
        if e > threshold {
            return Screening { failed: Some((omega, z, e)), first_error };
        }
        if first_solution.is_none() {
            first_solution = Some((omega, z));
        }
    }
    let band = (sopts.omega_start.min(sopts.omega_end), sopts.omega_start.max(sopts.omega_end));
    let peak = first_solution.and_then(|(omega, z)| tangent_peak(rom, omega, &z, band).ok().flatten());
    let failed = peak
        .filter(|&w| !omegas.iter().any(|&p| same_point(p, w)))
        .and_then(|w| screen(rom, condensed, w, hopts).filter(|(_, e)| *e > threshold).map(|(z, e)| (w, z, e)));
    Screening { failed, first_error }
}

/// Judges a candidate basis (`j`, unswept): with `screen_at` (the condensed system and the
/// frequencies where the bases before it were judged poor, the current basis' judged point
/// first), it is first solved at each of those frequencies alone (from the linear guess, with
/// the solver's fallbacks) and its linearised error checked there; above the threshold at one
/// of them it is not swept (docs/formulation.md §10.5: a basis that fails where the bases
/// before it failed fails its pass) and is judged there. Otherwise (points that do not solve
/// are passed over) its pass over the band judges it. Its error at the first frequency is kept
/// as `screened` either way.
///
/// # Errors
/// Its pass' errors: [`JpError::NoConvergence`] when it does not converge at the first
/// frequency.
#[allow(clippy::too_many_arguments)]
fn judge_candidate(
    mut j: Judged,
    screen_at: Option<(&CondensedSystem, &[f64])>,
    threshold: f64,
    check_with: Option<&CondensedSystem>,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    pass_no: (usize, usize),
    on_point: &mut dyn FnMut(usize, &PointSolution) -> ControlFlow<()>,
) -> Result<Judged> {
    let mut screened = None;
    if let Some((condensed, omegas)) = screen_at {
        let s = screen_candidate(j.rom.as_ref(), condensed, omegas, threshold, sopts, hopts);
        screened = s.first_error;
        if let Some((omega, z, e)) = s.failed {
            (j.omega, j.z, j.error, j.screened) = (omega, z, e, screened);
            return Ok(j);
        }
    }
    let p = run_pass(j.rom.as_ref(), check_with, sopts, hopts, pass_no, on_point)?;
    Ok(Judged { screened, ..Judged::swept(j.basis, j.prediction, j.rom, p) })
}

/// An error that is NaN (a failed evaluation) counts as the worst.
fn nan_as_worst(e: f64) -> f64 {
    if e.is_nan() {
        f64::INFINITY
    } else {
        e
    }
}

/// At most this many frequencies screen a candidate (the current basis' judged point first).
const SCREENED_POINTS: usize = 4;

/// Two frequencies closer than this (relative) are one point of the screening: a resonance's
/// checks (on the 50-contact blade at gross slip, four within 1 Hz of 1,672 Hz) are one.
const SAME_POINT: f64 = 1e-3;

fn same_point(a: f64, b: f64) -> bool {
    (a - b).abs() <= SAME_POINT * a.abs().max(b.abs())
}

/// Adds where `j` was judged above `threshold` (its judged point, and its pass' checks above
/// it) to `poor` ([`add_poor`]). Candidates are screened there: on the 50-contact blade at
/// gross slip NLR's regenerated modes passed at the resonance, where the basis before them had
/// failed, and failed at the band's start, where the first basis had (tests/screening_points.rs).
fn note_poor(poor: &mut Vec<(f64, f64)>, j: &Judged, threshold: f64) {
    let checks = j.pass.iter().flat_map(|p| &p.checks).map(|c| (c.omega, c.linearised));
    add_poor(poor, std::iter::once((j.omega, j.error)).chain(checks), threshold);
}

/// Adds the `(frequency, error)` pairs above `threshold` to `poor`: one entry per point
/// ([`same_point`]) with the largest error seen there (NaN as infinite), worst first, at most
/// [`SCREENED_POINTS`].
fn add_poor(poor: &mut Vec<(f64, f64)>, points: impl Iterator<Item = (f64, f64)>, threshold: f64) {
    for (omega, error) in points {
        let error = nan_as_worst(error);
        if !(error > threshold) || !omega.is_finite() {
            continue;
        }
        match poor.iter_mut().find(|p| same_point(p.0, omega)) {
            Some(p) => p.1 = p.1.max(error),
            None => poor.push((omega, error)),
        }
    }
    poor.sort_by(|a, b| b.1.total_cmp(&a.1));
    poor.truncate(SCREENED_POINTS);
}

/// The modes of the last prediction of a self-correcting sweep and the options they were
/// predicted with (its `gamma` aside).
struct LastPrediction {
    opts: PredictionOptions,
    modes: PredictedModes,
    report: PredictionReport,
}

/// The basis `opts` predicts: a `gamma` step along the shape of the last prediction conditions
/// its modes again ([`PredictedModes::basis`]; the samples, patterns and modes would be the
/// same), anything else is predicted and becomes the last prediction.
fn predict(coords: &ContactCoordinates, opts: &PredictionOptions, last: &mut Option<LastPrediction>) -> Result<(JpBasis, PredictionReport)> {
    let same_samples = |l: &LastPrediction| PredictionOptions { gamma: opts.gamma, ..l.opts.clone() } == *opts;
    if let Some(l) = last.as_ref().filter(|l| same_samples(l)) {
        return Ok((l.modes.basis(opts.gamma)?, l.report.clone()));
    }
    crate::jp::conditioning::check_gamma(opts.gamma)?;
    let (modes, report) = predict_modes(coords, opts)?;
    let basis = modes.basis(opts.gamma)?;
    *last = Some(LastPrediction { opts: opts.clone(), modes, report: report.clone() });
    Ok((basis, report))
}

/// Whether the correction after a step regenerates (else it grows `gamma`): after a
/// regeneration, a `gamma` step (no eigen solve: the regenerated modes conditioned again);
/// after a `gamma` step, a regeneration if that step halved the judged error (`before` ->
/// `after`; its reduced solution is then the better generating shape), else a further `gamma`
/// step; a regeneration whenever `gamma` is at its maximum.
fn regenerates_next(gamma_step: bool, before: f64, after: f64, at_max_gamma: bool) -> bool {
    (gamma_step && after < 0.5 * before) || at_max_gamma
}

/// Largest entry of the part of a correction's basis outside the current basis' span below
/// which the two are taken as one basis ([`JpBasis::spans_the_same`]; both orthonormal, so
/// this bounds the sine of the largest principal angle per column).
const SAME_SPAN_TOL: f64 = 1e-8;

/// The options' own bounds, and `response_output` among the model's `n_outputs` outputs (any
/// value would locate no resonance: a pass' checks would go to the points of largest `e*` only).
fn check_options(aopts: &AdaptiveOptions, n_outputs: usize) -> Result<()> {
    if !(aopts.threshold > 0.0) || !(aopts.gamma_growth > 1.0) {
        return Err(JpError::invalid("AdaptiveOptions", "need threshold > 0 and gamma_growth > 1"));
    }
    if aopts.regeneration_samples == 0 {
        return Err(JpError::invalid("AdaptiveOptions.regeneration_samples", "must be >= 1"));
    }
    if aopts.response_output >= n_outputs.max(1) {
        return Err(JpError::invalid("AdaptiveOptions.response_output", format!("is {}; the model has {n_outputs} outputs", aopts.response_output)));
    }
    Ok(())
}

/// Whether the condensed full-order Jacobian is small enough for the error checks.
fn checkable(coords: &ContactCoordinates) -> bool {
    coords.n_w > 0 && (2 * coords.discretisation.harmonics + 1) * coords.n_w <= MAX_CHECK_UNKNOWNS
}

/// The memory budget's check of the error checks' condensed full-order Jacobian, before a
/// study that makes them starts (a check refused later would leave its point unchecked).
fn check_jacobian_fits(coords: &ContactCoordinates) -> Result<()> {
    let unknowns = (2 * coords.discretisation.harmonics + 1) * coords.n_w;
    crate::memory::check(
        &format!("the condensed full-order Jacobian of the error checks ({unknowns} unknowns at H = {})", coords.discretisation.harmonics),
        crate::hbm::residual::dense_jacobian_bytes(unknowns),
    )
}

/// Predicts a JP basis for `model` discretised by `discretisation` (`H` alone takes the
/// default `Nt`), sweeps the reduced model over `sopts`' band and corrects the basis while the
/// worst `e*_1` exceeds `aopts.threshold` (see the module doc). The band of the JP modes is
/// `pred.modes.band`.
///
/// # Errors
/// Model, prediction and ROM construction errors; the first reduced point's solve error.
pub fn adaptive_sweep(
    model: &Model,
    discretisation: impl Into<Discretisation>,
    pred: &PredictionOptions,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    aopts: &AdaptiveOptions,
) -> Result<AdaptiveSweep> {
    adaptive_sweep_with_progress(model, discretisation, pred, sopts, hopts, aopts, &mut |_, _| ControlFlow::Continue(()))
}

/// [`adaptive_sweep`] reporting progress: `on_point(pass, point)` is called after each
/// converged point of each reduced sweep (`pass` 0 for the first basis, `k` after the `k`-th
/// correction). If it returns `Break`, that sweep stops there (`sweep.end` is
/// [`crate::hbm::SweepEnd::StoppedByCaller`]) and no further correction is made: the result
/// holds the points of the stopped pass, their `e*` and the basis they were computed with.
///
/// # Errors
/// As [`adaptive_sweep`].
pub fn adaptive_sweep_with_progress(
    model: &Model,
    discretisation: impl Into<Discretisation>,
    pred: &PredictionOptions,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    aopts: &AdaptiveOptions,
    on_point: &mut dyn FnMut(usize, &PointSolution) -> ControlFlow<()>,
) -> Result<AdaptiveSweep> {
    check_options(aopts, model.output_dofs.len())?;
    crate::jp::require_contacts("adaptive sweep", model.contacts.len())?;
    let discretisation = discretisation.into();
    let coords = ContactCoordinates::new(model, discretisation)?;
    let checkable = checkable(&coords);
    if aopts.verify && checkable {
        check_jacobian_fits(&coords)?;
    }
    let condensed = if aopts.kind == RomKind::Nlr || (aopts.verify && checkable) { Some(CondensedSystem::new(model, discretisation)?) } else { None };
    let initial = predict_basis(&coords, pred)?;
    adaptive_sweep_from(&coords, condensed.as_ref(), initial, pred, sopts, hopts, aopts, on_point)
}

/// [`adaptive_sweep_with_progress`] from a basis already predicted (`initial`: the basis and
/// its report), on the model's contact coordinates `coords` and condensed full-order system
/// `condensed` (needed for NLR and for the error checks; `None` judges by `e*` alone). One
/// basis predicted for the largest excitation of a study serves every level (its samples span
/// the patterns of the smaller ones); each level's corrections are its own. The corrections
/// predict with `pred` (its band, `gamma`, samples).
///
/// # Errors
/// As [`adaptive_sweep`]; [`JpError::InvalidValue`] for NLR without `condensed`.
#[allow(clippy::too_many_arguments)]
pub fn adaptive_sweep_from(
    coords: &ContactCoordinates,
    condensed: Option<&CondensedSystem>,
    initial: (JpBasis, PredictionReport),
    pred: &PredictionOptions,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    aopts: &AdaptiveOptions,
    on_point: &mut dyn FnMut(usize, &PointSolution) -> ControlFlow<()>,
) -> Result<AdaptiveSweep> {
    check_options(aopts, coords.output_dofs.len())?;
    crate::jp::require_contacts("adaptive sweep", coords.n_w)?;
    if aopts.kind == RomKind::Nlr && condensed.is_none() {
        return Err(JpError::invalid("adaptive sweep", "NLR needs the condensed full-order system"));
    }
    let checkable = checkable(coords);
    let check_with = if aopts.verify && checkable { condensed } else { None };
    if check_with.is_some() {
        check_jacobian_fits(coords)?;
    }
    let mut popts = pred.clone();
    let mut last = None;
    let (mut basis, mut prediction) = initial;
    let mut rom = super::reduced_model(aopts.kind, coords, condensed, &basis)?;
    let mut corrections = Vec::new();
    let screen_with = if aopts.screen { check_with } else { None };
    // Screening judges the first basis at the band's start, then where its tangent response
    // peaks: above the threshold at either it is corrected from that point without a pass (at
    // gross slip the stuck-mode basis fails at the first frequency already).
    let first = screen_with.and_then(|c| screen_candidate(rom.as_ref(), c, &[sopts.omega_start], aopts.threshold, sopts, hopts).failed);
    let mut cur = if let Some((omega, z, error)) = first {
        Judged { omega, z, error, ..Judged::unswept(basis, prediction, rom) }
    } else {
    // A basis too poor to converge at the first frequency has no reduced solution to
    // regenerate from: enlarge gamma (uniting as below) while corrections remain.
    let pass = loop {
        match run_pass(rom.as_ref(), check_with, sopts, hopts, (corrections.len(), aopts.response_output), on_point) {
            Ok(p) => break p,
            Err(e @ JpError::NoConvergence { .. }) => {
                if corrections.len() >= aopts.max_corrections || popts.gamma >= aopts.max_gamma {
                    return Err(e);
                }
                popts.gamma = (popts.gamma * aopts.gamma_growth).min(aopts.max_gamma);
                let (fresh, r) = predict(coords, &popts, &mut last)?;
                basis = basis.union(&fresh, popts.gamma)?;
                prediction = r;
                rom = super::reduced_model(aopts.kind, coords, condensed, &basis)?;
                corrections.push(Correction {
                    kind: CorrectionKind::GammaIncreased { gamma: popts.gamma },
                    worst_error_before: f64::INFINITY,
                    worst_error_after: f64::NAN,
                    sizes: basis.sizes.clone(),
                    swept: true,
                });
            }
            Err(e) => return Err(e),
        }
    };
    if let Some(c) = corrections.last_mut() {
        c.worst_error_after = pass.worst;
    }
    Judged::swept(basis, prediction, rom, pass)
    };
    let mut regenerate_next = true;
    // Where the bases so far were judged poor (screening judges candidates there too).
    let mut poor: Vec<(f64, f64)> = Vec::new();
    note_poor(&mut poor, &cur, aopts.threshold);
    // Correction steps made (a regeneration is one step, its union included).
    let mut steps = corrections.len();
    // Steps whose candidates were all judged at screening points only (no pass; never more
    // than `steps`).
    let mut screened_steps = 0usize;
    let end = loop {
        if cur.pass.as_ref().is_some_and(|p| p.sweep.end == SweepEnd::StoppedByCaller) {
            break CorrectionEnd::Stopped;
        }
        if cur.error <= aopts.threshold {
            break CorrectionEnd::WithinThreshold;
        }
        if steps - screened_steps >= aopts.max_corrections || steps >= aopts.max_corrections.saturating_mul(2) {
            break CorrectionEnd::MaxCorrections;
        }
        // A regeneration from the same point at the largest gamma would repeat a dropped one.
        if let Some(Correction { worst_error_before, worst_error_after, kind: CorrectionKind::Regenerated { from_omega }, .. }) = corrections.last() {
            let dropped = !(worst_error_after < worst_error_before);
            if dropped && cur.omega == *from_omega && popts.gamma >= aopts.max_gamma {
                break CorrectionEnd::NoProgress;
            }
        }
        let (before, judged_before) = (cur.error, cur.omega);
        let kind = if regenerate_next {
            let q = cur.rom.full_coefficients(cur.omega, &cur.z)?;
            popts.shape = GeneratingShape::Given { static_part: Some(q[0].clone()), cos: q[1].clone(), sin: q[2].clone() };
            popts.p_max = None;
            popts.n_samples = aopts.regeneration_samples;
            CorrectionKind::Regenerated { from_omega: cur.omega }
        } else {
            popts.gamma = (popts.gamma * aopts.gamma_growth).min(aopts.max_gamma);
            CorrectionKind::GammaIncreased { gamma: popts.gamma }
        };
        let (fresh, r) = predict(coords, &popts, &mut last)?;
        steps += 1;
        let mut step_swept = false;
        // Where a candidate is judged first when screening: the current basis' judged point,
        // then the other points where the bases so far were poor.
        let mut screen_points = vec![cur.omega];
        screen_points.extend(poor.iter().map(|p| p.0).filter(|&w| !same_point(w, cur.omega)));
        screen_points.truncate(SCREENED_POINTS);
        let screen_at = screen_with.map(|c| (c, &screen_points[..]));
        let judge = |rom: Box<dyn ReducedModel>, basis: JpBasis, prediction: PredictionReport, pass_no: usize, on_point: &mut dyn FnMut(usize, &PointSolution) -> ControlFlow<()>| {
            judge_candidate(Judged::unswept(basis, prediction, rom), screen_at, aopts.threshold, check_with, sopts, hopts, (pass_no, aopts.response_output), on_point)
        };
        // The regenerated modes alone first: where they suffice, the basis keeps the size of one
        // prediction instead of growing by the union. Their sweep is reported as a correction
        // of its own but is part of this step; within the threshold it ends the corrections,
        // otherwise, if better than the basis before, it competes with the union below.
        let mut alone: Option<Judged> = None;
        if let CorrectionKind::Regenerated { from_omega } = kind {
            let alone_rom = super::reduced_model(aopts.kind, coords, condensed, &fresh)?;
            // modes alone that do not converge at the first frequency lose to the union
            let j = match judge(alone_rom, fresh.clone(), r.clone(), corrections.len() + 1, on_point) {
                Ok(j) => Some(j),
                Err(JpError::NoConvergence { .. }) => None,
                Err(e) => return Err(e),
            };
            let after = j.as_ref().map_or(f64::INFINITY, |j| j.error);
            step_swept = j.as_ref().is_some_and(|j| j.pass.is_some());
            corrections.push(Correction { kind: CorrectionKind::Replaced { from_omega }, worst_error_before: before, worst_error_after: after, sizes: fresh.sizes.clone(), swept: step_swept });
            alone = j.filter(|j| j.error_against(cur.pass.is_none()) < before || j.stopped());
            if let Some(j) = alone.take_if(|j| (j.pass.is_some() && j.error <= aopts.threshold) || j.stopped()) {
                cur = j;
                regenerate_next = true;
                continue;
            }
        }
        // The current basis judged at one point only: candidates compete with it there.
        let cur_unswept = cur.pass.is_none();
        let b = cur.basis.union(&fresh, popts.gamma)?;
        // Fresh modes already in the basis' span leave the reduced model as it is: its pass
        // would repeat the current one, so it is not swept again (on the CalculiX block of
        // examples-c/fe_example.c, one of seven corrections). The correction is reported with
        // the error unchanged.
        let union = if b.spans_the_same(&cur.basis, SAME_SPAN_TOL) {
            None
        } else {
            let new_rom = super::reduced_model(aopts.kind, coords, condensed, &b)?;
            Some(judge(new_rom, b, r, corrections.len() + 1, on_point)?)
        };
        let union_sizes = union.as_ref().map_or(cur.basis.sizes.clone(), |j| j.basis.sizes.clone());
        let union_worst = union.as_ref().map_or(before, |j| j.error);
        let gamma_step = matches!(kind, CorrectionKind::GammaIncreased { .. });
        let union_swept = union.as_ref().is_some_and(|j| j.pass.is_some());
        corrections.push(Correction { kind, worst_error_before: before, worst_error_after: union_worst, sizes: union_sizes, swept: union_swept });
        if !(step_swept || union_swept) {
            screened_steps += 1;
        }
        // A correction that made the worst e*_1 larger is reported but not kept (the Galerkin
        // error need not fall as the basis grows: on the blade at alpha_ST / 3000 a third
        // regeneration took it from 0.077 to 0.12). A pass stopped by the caller is kept. Of the
        // regenerated modes alone and their union, the one with the smaller error is kept.
        let stopped = union.as_ref().is_some_and(|j| j.stopped());
        let was_unswept = cur_unswept;
        let union_against = union.as_ref().map_or(before, |u| u.error_against(cur_unswept));
        match (alone, union) {
            (Some(a), _) if !stopped && a.error_against(cur_unswept) <= union_against => cur = a,
            (_, Some(u)) if u.error_against(cur_unswept) < before || stopped => cur = u,
            _ => {}
        }
        // A gamma step swept after steps judged at one point only has found where the basis
        // is worst over the band, and one judged at a new point by screening (its resonance)
        // has found a point where it fails: the next correction regenerates from there (after
        // a regeneration, as always, a gamma step).
        let found = cur.pass.is_some() || !same_point(cur.omega, judged_before);
        regenerate_next = (gamma_step && was_unswept && found) || regenerates_next(gamma_step, before, cur.error, popts.gamma >= aopts.max_gamma);
        note_poor(&mut poor, &cur, aopts.threshold);
    };
    // A basis kept after screening alone is swept over the band before it is the result.
    let (end, pass) = match cur.pass.take() {
        Some(p) => (end, p),
        None => {
            let p = run_pass(cur.rom.as_ref(), check_with, sopts, hopts, (corrections.len() + 1, aopts.response_output), on_point)?;
            let end = if p.sweep.end == SweepEnd::StoppedByCaller {
                CorrectionEnd::Stopped
            } else if p.worst <= aopts.threshold {
                CorrectionEnd::WithinThreshold
            } else {
                end
            };
            (end, p)
        }
    };
    let checks = match check_with {
        Some(condensed) => verdict_checks(cur.rom.as_ref(), condensed, &pass, hopts, aopts.response_output),
        None => Vec::new(),
    };
    let (basis, prediction) = (cur.basis, cur.prediction);
    let judged = judged_errors(&pass.errors, &checks);
    let trust = Trust::of(&pass.sweep, &judged, aopts.threshold);
    Ok(AdaptiveSweep { sweep: pass.sweep, predicted_errors: pass.errors, basis, prediction, corrections, checks, worst_error: pass.worst, end, trust })
}

/// The checks of the final pass that its verdict ([`Trust`]) rests on: the checked error
/// ([`checked_error`]) at [`checked_points`]: every point where the condensed full order has at
/// most [`EVERY_POINT_CHECK_UNKNOWNS`] unknowns. A point with a singular full-order Jacobian is
/// left unchecked (judged by `e*_1`).
fn verdict_checks(rom: &dyn ReducedModel, condensed: &CondensedSystem, pass: &Pass, hopts: &HbmOptions, response: usize) -> Vec<ErrorCheck> {
    let sw = &pass.sweep;
    let amplitude = |p: &PointSolution| if response < p.n_outputs { p.output_amplitude(1, response) } else { 0.0 };
    let peak = (0..sw.points.len()).max_by(|&a, &b| amplitude(&sw.points[a]).total_cmp(&amplitude(&sw.points[b]))).unwrap_or(0);
    checked_points(&pass.errors, peak, condensed.layout().total())
        .into_iter()
        .filter_map(|i| {
            let p = &sw.points[i];
            let c = checked_error(rom, condensed, p.omega, &p.z, hopts).ok()?;
            Some(ErrorCheck { index: i, omega: p.omega, predicted: pass.errors[i][1], linearised: c.linearised.force[1], static_displacement: c.linearised.static_displacement, checked: nan_as_worst(c.error[1]), basis: Some(c.basis) })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{add_poor, regenerates_next, SCREENED_POINTS};

    /// The points a candidate is screened at: above the threshold only, a resonance's checks
    /// (within 0.1 % of each other) one point with their largest error, worst first, at most
    /// four; a NaN error counts as the worst.
    #[test]
    fn poor_points_are_merged_ranked_and_capped() {
        let mut poor = Vec::new();
        add_poor(&mut poor, [(1620.0, 1.06), (1672.2, 0.305), (1671.7, 0.304), (1671.2, 0.31), (1700.0, 0.05), (1800.0, 0.01)].into_iter(), 0.05);
        assert_eq!(poor.len(), 2, "{poor:?}");
        assert_eq!(poor[0], (1620.0, 1.06));
        assert_eq!(poor[1], (1672.2, 0.31));
        add_poor(&mut poor, [(1620.5, 2.0), (1900.0, f64::NAN), (1750.0, 0.2), (2000.0, 0.1), (2100.0, 0.07)].into_iter(), 0.05);
        assert_eq!(poor.len(), SCREENED_POINTS);
        assert_eq!(poor[0].0, 1900.0);
        assert_eq!(poor[1], (1620.0, 2.0));
        assert_eq!(poor.iter().map(|p| p.0).collect::<Vec<_>>(), vec![1900.0, 1620.0, 1672.2, 1750.0]);
    }

    /// The rule of docs/formulation.md §10.5 step 3. The former rule (regenerate after any
    /// step that halved the error) fails the second assertion.
    #[test]
    fn a_regeneration_is_followed_by_a_gamma_step() {
        // after a regeneration: gamma, whether it halved the error or not
        assert!(!regenerates_next(false, 1.0, 0.9, false));
        assert!(!regenerates_next(false, 1.0, 0.2, false));
        // after a gamma step: regenerate if it halved the error, else gamma again
        assert!(regenerates_next(true, 1.0, 0.4, false));
        assert!(!regenerates_next(true, 1.0, 0.6, false));
        // at the largest gamma, always regenerate
        assert!(regenerates_next(false, 1.0, 0.9, true));
        assert!(regenerates_next(true, 1.0, 0.9, true));
        // a NaN error (no converged pass) is no halving
        assert!(!regenerates_next(true, 1.0, f64::NAN, false));
    }
}
