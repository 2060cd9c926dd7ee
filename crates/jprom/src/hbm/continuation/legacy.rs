//! The secant continuation of the first releases ([`crate::hbm::ContinuationMethod::Secant`]),
//! kept for comparison with the oriented one (docs/formulation.md §6.8).
//!
//! Unknowns `y = (z, omega)`; arclength is measured in the scaled metric
//! `|dy|^2 = |dz|^2 / z_ref^2 + domega^2 / span^2` (see [`SweepOptions`]).
//!
//! * **Tangent** `t` at a converged point: the null vector of `[J_z  dR/domega]`, from the
//!   bordered system `[J_z  R_omega; (S t_prev)^T] t = [0; 1]`, normalised to unit length. The
//!   last row orients `t` along the previous tangent (`t_prev^T S t > 0`), so the direction of
//!   travel never reverses on its own, also through folds, where `J_z` is singular.
//!   `dR/domega = D' z - f'` in closed form where the system gives it
//!   ([`HarmonicSystem::linear_part_with_derivative_into`]: the condensed systems), else
//!   `(D(omega + delta) - D(omega - delta)) z / (2 delta) - (f(+) - f(-)) / (2 delta)`
//!   by a central difference of [`HarmonicSystem::linear_part`] (`delta = omega_difference *
//!   omega`); contact forces do not depend on `omega` (rate-independent friction). For the full
//!   system `D` is quadratic in `omega`, so the difference is exact up to rounding.
//! * **Predictor** `y_p = y + ds t`.
//! * **Corrector**: the trust-region Newton method of [`super::newton`] on
//!   `R(z, omega) = 0`, `t^T S (y - y_p) = 0` (the bordered system). Where the branch turns so
//!   sharply that this hyperplane misses it (a contact kink), the corrector retries on the
//!   sphere `|y - y_k|_S = ds` around the last point, forward only.
//! * **Direction**: the first step follows the tangent; every later one the last chord
//!   `y_k - y_{k-1}` (a secant predictor). On a branch made of many short smooth pieces (each
//!   AFT sample switching between stick and slip is a kink) the one-sided tangents zigzag
//!   while the chords follow the branch.
//! * **Acceptance**: a corrected point must lie ahead of the last one along the direction
//!   (`d^T S (y - y_k) > 0`), so points are strictly ordered along the arclength and the branch
//!   is never retraced. A chord that turns by more than [`sharp_turn`] from the last one is
//!   retried at half the length (at most [`MAX_ANGLE_RETRIES`] times). A turn that does not
//!   shrink with the step (still above [`CORNER_RATIO`] of the longer step's) is a corner of the
//!   branch, where a contact changes state: that step is taken, and the next one goes on with
//!   the step planned before the corner instead of a step shrunk by the corner's angle. A step
//!   back in frequency that lands on the part of the branch already traced ([`retraces`]) is
//!   halved instead, down to the restart below (a fold goes on along another part of the
//!   branch and is taken).
//! * **Step control**: after a success `ds` is scaled by the smaller of
//!   `target_iterations / iterations` and `max_angle / (2 kappa ds)`, `kappa` the smaller turn
//!   per unit arclength (the angle between successive chords over `ds`) of this step and the
//!   last (a kink turns one step alone: docs/formulation.md §6.8), each clamped to `[1/2, 2]`,
//!   within `[min_step, max_step]`, and capped so that
//!   `omega` moves by at most `max_omega_step` of the band; a failed corrector halves `ds`.
//! * **Restart**: when `ds` falls below `min_step` (a corrector that cannot settle on a kink),
//!   the sweep tries to step over it at fixed frequency: the point solver at a slightly larger
//!   frequency (`1e-4`, `1e-3`, then `1e-2` of the band ahead) from the last point, kept if it
//!   converges close to it; the frequency it restarted from is recorded in
//!   [`SweepResult::restarts`] (at most [`MAX_RESTARTS`], 1,000). Otherwise the sweep ends with
//!   [`SweepEnd::StepTooSmall`] and the corrector's last error.
//! * **Folds**: where the tangent's frequency component changes sign the branch turns back in
//!   frequency; the fold's frequency is recorded in [`SweepResult::folds`].
//! * The point that passes `omega_end` is replaced by a fixed-frequency solve at `omega_end`
//!   (kept as it is if that solve fails: it is converged, just past the end).


use super::{characteristic_displacement, correct, tangent, Constraint, Corrected, Corrector, Metric};
use crate::error::{JpError, Result};
use crate::hbm::residual::ResidualWorkspace;
use crate::hbm::solve::{finish_point, newton, plan_for, AtFrequency, NewtonOutcome};
use crate::hbm::{HarmonicSystem, HbmOptions, PointSolution, SweepEnd, SweepOptions, SweepResult, LEFT_BAND_MARGIN};
use crate::linalg::norm2;
use std::ops::ControlFlow;

/// Most retries of one step at half the length because its tangent turned by more than
/// [`SweepOptions::max_angle`]; past them the step is taken (a corner of the branch).
pub(crate) const MAX_ANGLE_RETRIES: usize = 4;

/// A retried step whose turn is still more than this fraction of the turn of the step twice
/// as long is at a corner of the branch (on a smooth branch the turn halves with the step).
pub(crate) const CORNER_RATIO: f64 = 0.7;

/// Most restarts over a kink per sweep (see the module doc). Each restart moves forward in
/// frequency and adds a point, so `SweepOptions::max_points` bounds them as well; this only
/// stops a sweep that would do nothing but restart. It was 10, which ended the 18-contact
/// blade's NLR at alpha_ST / 20 (a basis with the slipping samples) at 90.5 % of the band,
/// in a friction-damped resonance whose stick-slip kinks needed 47 (tests/sweep_restarts.rs).
pub(crate) const MAX_RESTARTS: usize = 1000;

/// Whether a step (`(length, turn)`) turned as a kink does, judged against the step before it:
/// it is at most 3/4 as long, and yet turned more than `max_angle / 2` and at least
/// [`CORNER_RATIO`] as much. On a smooth branch the turn shrinks with the step; where contacts
/// change state at every few hundredths of a hertz (NLR on the 98-contact blade at
/// `alpha_ST / 20`: turns of 0.2 to 0.45 rad at steps from 1e-5 to 1e-2) it does not, and
/// shortening the steps for it only adds points (that sweep took 1,385 points, 1,280 of them
/// within 40 Hz of the resonance). From the first such step on, turns below the sharp turn
/// ([`sharp_turn`], which is still retried shorter) no longer shorten the steps below its
/// length (docs/formulation.md §6.8).
pub(crate) fn is_kink_turn((ds_last, angle_last): (f64, f64), (ds, angle): (f64, f64), sopts: &SweepOptions) -> bool {
    ds <= 0.75 * ds_last && angle > 0.5 * sopts.max_angle && angle >= CORNER_RATIO * angle_last
}

/// The turn between successive chords above which a step is retried shorter: three times
/// `max_angle`, at least 0.5 rad.
pub(crate) fn sharp_turn(sopts: &SweepOptions) -> f64 {
    (3.0 * sopts.max_angle).max(0.5)
}

/// How many of the last points [`retraces`] compares a step back in frequency with.
pub(crate) const RETRACE_WINDOW: usize = 50;

/// Whether the corrected point `c` (`[z; omega]`), reached from the last point `y` by a step
/// back in frequency (against the band's direction), lies on the branch already traced: within half that step (in the metric)
/// of the straight line between two successive of the last [`RETRACE_WINDOW`] points whose
/// frequencies bracket its own. Past a fold the branch goes on at another response, about
/// twice the step away from the traced part at the same frequency, and is not a retrace.
fn retraces(points: &[PointSolution], c: &[f64], y: &[f64], m: Metric) -> bool {
    let n = c.len() - 1;
    let d: Vec<f64> = c.iter().zip(y).map(|(a, b)| a - b).collect();
    let step = m.dot(&d, &d).sqrt();
    let recent = &points[points.len().saturating_sub(RETRACE_WINDOW)..];
    recent.windows(2).any(|w| {
        let (a, b) = (&w[0], &w[1]);
        if (c[n] - a.omega) * (c[n] - b.omega) > 0.0 || a.omega == b.omega || a.z.len() != n || b.z.len() != n {
            return false;
        }
        let s = (c[n] - a.omega) / (b.omega - a.omega);
        let gap: f64 = (0..n).map(|i| (c[i] - a.z[i] - s * (b.z[i] - a.z[i])).powi(2)).sum();
        (m.sz * gap).sqrt() < 0.5 * step
    })
}

/// Steps over a kink at fixed frequency: the point solver at `omega + f span` for `f` = 1e-4,
/// 1e-3, 1e-2 (`signed_span` carries the sweep's direction) from the last point `y`; the first
/// solution within half of `z_ref` of it, with `[z; omega]`.
fn restart(system: &dyn HarmonicSystem, y: &[f64], signed_span: f64, z_ref: f64, hopts: &HbmOptions) -> Option<(PointSolution, Vec<f64>)> {
    let n = y.len() - 1;
    [1e-4, 1e-3, 1e-2].iter().find_map(|f| {
        let omega = y[n] + f * signed_span;
        let p = crate::hbm::solve_point(system, omega, Some(&y[..n]), hopts).ok()?;
        let jump = norm2(&p.z.iter().zip(&y[..n]).map(|(a, b)| a - b).collect::<Vec<_>>());
        (jump <= 0.5 * z_ref).then(|| {
            let y_new = p.z.iter().copied().chain([omega]).collect();
            (p, y_new)
        })
    })
}

pub(super) fn sweep_from(
    system: &dyn HarmonicSystem,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    start: Option<&[f64]>,
    on_point: &mut dyn FnMut(&PointSolution) -> ControlFlow<()>,
) -> Result<SweepResult> {
    sopts.validate()?;
    hopts.validate()?;
    let plan = plan_for(system)?;
    let plan = plan.as_ref();
    let mut ws = ResidualWorkspace::new();
    let n = system.layout().total();
    let (w0, w1) = (sopts.omega_start, sopts.omega_end);
    let direction = (w1 - w0).signum();
    let span = (w1 - w0).abs();

    let mut result = SweepResult::empty();
    let finish = |mut res: SweepResult, end: SweepEnd, failure: Option<String>, error: Option<JpError>| {
        res.end = end;
        res.stopped_early = end != SweepEnd::ReachedEnd;
        res.failure = failure.or_else(|| error.as_ref().map(|e| e.to_string()));
        res.error = error;
        res
    };
    let at = |omega: f64| format!("at omega = {omega:.6} rad/s ({:.1} % of the band [{w0}, {w1}])", 100.0 * (omega - w0) / (w1 - w0));

    // First point at omega_start, with the point solver's load-stepping fallback (a reduced
    // model regenerated mid-workflow can leave Newton from zero stuck at a local minimum).
    let first = crate::hbm::solve_point(system, w0, start, hopts)?;
    let mut z_ref = characteristic_displacement(system, &first.z);
    let mut y: Vec<f64> = first.z.iter().copied().chain([w0]).collect();
    let stop = on_point(&first).is_break();
    result.points.push(first);
    if stop {
        return Ok(finish(result, SweepEnd::StoppedByCaller, Some(format!("stopped by the caller {}", at(w0))), None));
    }

    let mut metric = Metric { sz: 1.0 / (z_ref * z_ref), sw: 1.0 / (span * span) };
    // First direction: the tangent, oriented towards omega_end; then the last chord.
    let mut orient = vec![0.0; n + 1];
    orient[n] = direction * span;
    let mut dir = {
        let mut c = Corrector::new(system, plan, sopts, &mut ws, metric, Constraint::Sphere { centre: &y }, 1.0);
        let (_, top) = c.linearise(&y, true)?;
        tangent(&top.expect("jacobian requested"), &orient, metric, w0)?
    };
    let mut ds = sopts.initial_step.clamp(sopts.min_step, sopts.max_step);
    // the length and turn of the last smooth step (None after a corner or a restart), and the
    // length below which turns do not shorten the steps (`kink_floor`, see `is_kink_turn`)
    let mut last_step: Option<(f64, f64)> = None;
    let mut kink_floor: Option<f64> = None;
    loop {
        if result.points.len() >= sopts.max_points {
            let omega = y[n];
            let text = format!("stopped at the point cap (max_points = {}) {}", sopts.max_points, at(omega));
            return Ok(finish(result, SweepEnd::MaxPoints, Some(text), None));
        }
        let omega = y[n];
        // No step moves the frequency by more than max_omega_step of the band.
        let dir_omega = (metric.sw * dir[n] * dir[n]).sqrt();
        if dir_omega > 0.0 {
            ds = ds.min(sopts.max_omega_step / dir_omega);
        }
        ds = ds.max(sopts.min_step);
        let mut last_error: Option<JpError> = None;
        let mut angle_retries = 0;
        // the step as it was before any retry for a sharp turn, and the last turn seen
        let ds_planned = ds;
        let mut last_turn: Option<f64> = None;
        let mut corner = false;
        let (corrected, chord, angle) = loop {
            if ds < sopts.min_step {
                // Step over the kink at fixed frequency, or give up.
                let jump = if result.restarts.len() < MAX_RESTARTS { restart(system, &y, direction * span, z_ref, hopts) } else { None };
                match jump {
                    Some((p, y_new)) => break (Corrected { y: y_new, iterations: p.iterations, residual: p.residual_norm, jacobian: None }, Vec::new(), 0.0),
                    None => {
                        let e = last_error.take().unwrap_or_else(|| JpError::NoConvergence { what: "continuation".into(), iterations: 0, residual: f64::NAN, tolerance: f64::NAN });
                        let text = format!("stalled {}: the step fell below min_step = {:e}; last corrector error: {e}", at(omega), sopts.min_step);
                        return Ok(finish(result, SweepEnd::StepTooSmall, Some(text), Some(e)));
                    }
                }
            }
            let y_pred: Vec<f64> = (0..=n).map(|i| y[i] + ds * dir[i]).collect();
            let attempt = correct(system, plan, &y_pred, Constraint::Hyperplane { t: &dir, y_pred: &y_pred }, ds, metric, sopts, hopts, &mut ws).or_else(|e| {
                correct(system, plan, &y_pred, Constraint::Sphere { centre: &y }, ds, metric, sopts, hopts, &mut ws).map_err(|_| e)
            });
            let verdict = attempt.and_then(|c| {
                let d: Vec<f64> = (0..=n).map(|i| c.y[i] - y[i]).collect();
                let chord = metric.unit(&d).filter(|u| metric.dot(&dir, u) > 0.0).ok_or_else(|| {
                    JpError::invalid("continuation", format!("the corrector went back along the branch near omega = {}", c.y[n]))
                })?;
                let angle = metric.dot(&dir, &chord).clamp(-1.0, 1.0).acos();
                Ok((c, chord, angle))
            });
            // a step back in frequency (against the band's direction: also after a turn) onto
            // the part of the branch already traced
            let back_onto_branch = |c: &Corrected| direction * (c.y[n] - y[n]) < 0.0 && retraces(&result.points, &c.y, &y, metric);
            match verdict {
                // A step that would retrace the branch is not taken (its step is halved, down
                // to the restart): on the 18-contact blade's NLR at alpha_ST / 20 a corner of 62
                // degrees went back in frequency onto the branch, and the tangent there, oriented
                // along that chord, led the sweep 200 points back down the band. A fold, where the
                // branch does turn back, goes on along another part of it and is taken.
                Ok(v) if back_onto_branch(&v.0) => {
                    last_error = Some(JpError::NoConvergence { what: format!("continuation: a step of {:.2} rad back onto the branch already traced", v.2), iterations: 0, residual: f64::NAN, tolerance: f64::NAN });
                    result.rejected_steps += 1;
                    ds *= 0.5;
                }
                // A turn that does not shrink with the step is a corner of the branch (a
                // contact changing state): no shorter step would turn less, so take it.
                Ok(v) if v.2 > sharp_turn(sopts) && last_turn.is_some_and(|t| v.2 > CORNER_RATIO * t) => {
                    corner = true;
                    break v;
                }
                Ok((_, _, angle)) if angle > sharp_turn(sopts) && angle_retries < MAX_ANGLE_RETRIES && 0.5 * ds >= sopts.min_step => {
                    angle_retries += 1;
                    last_turn = Some(angle);
                    result.rejected_steps += 1;
                    ds *= 0.5;
                }
                // A sharp turn that the smallest step cannot resolve is not taken: a chord
                // that sharp at that length is sideways off the branch (on the twisted-blade
                // NLR at alpha_ST / 20 one turned by 83 degrees at a stick-slip kink, and the
                // steps after it retraced the branch back down the band). The restart steps
                // over the kink at fixed frequency instead.
                Ok((_, _, angle)) if angle > sharp_turn(sopts) && 0.5 * ds < sopts.min_step => {
                    last_error = Some(JpError::NoConvergence { what: format!("continuation: a turn of {angle:.2} rad at the smallest step"), iterations: 0, residual: f64::NAN, tolerance: f64::NAN });
                    result.rejected_steps += 1;
                    ds *= 0.5;
                }
                Ok(v) => break v,
                // a failed external law (C callback) is the caller's error, not a hard part of
                // the branch: no shorter step would mend it, so the sweep ends with it
                Err(e @ JpError::Callback { .. }) => return Err(e),
                Err(e) => {
                    last_error = Some(e);
                    result.rejected_steps += 1;
                    ds *= 0.5;
                }
            }
        };
        let restarted = chord.is_empty();
        let chord = if restarted {
            // after a restart, which stepped forward at fixed frequency over a point the
            // corrector could not settle on: the tangent at the new point, oriented forward in
            // frequency (oriented along the last direction it may lead back into that point)
            result.restarts.push(omega);
            ds = sopts.initial_step.clamp(sopts.min_step, sopts.max_step);
            last_step = None;
            kink_floor = None;
            let mut c = Corrector::new(system, plan, sopts, &mut ws, metric, Constraint::Sphere { centre: &y }, 1.0);
            let (_, top) = c.linearise(&corrected.y, true)?;
            tangent(&top.expect("jacobian requested"), &orient, metric, corrected.y[n])?
        } else if corner {
            // past a corner the branch is as smooth as before it: go on with the planned step,
            // along the tangent of the new piece (the chord across the corner points between
            // the two pieces, a poor predictor)
            ds = ds_planned.clamp(sopts.min_step, sopts.max_step);
            last_step = None;
            let mut c = Corrector::new(system, plan, sopts, &mut ws, metric, Constraint::Sphere { centre: &y }, 1.0);
            let (_, top) = c.linearise(&corrected.y, true)?;
            tangent(&top.expect("jacobian requested"), &chord, metric, corrected.y[n])?
        } else {
            let iters = corrected.iterations.max(1) as f64;
            let f_iter = (sopts.target_iterations as f64 / iters).clamp(0.5, 2.0);
            // The smaller of this step's and the last step's turn per unit length: on a smooth
            // branch the two agree; a kink (a contact changing state within the step) turns one
            // step alone, and shortening the next for it would only add points.
            let curvature = angle / ds;
            let smooth = last_step.map_or(curvature, |(ds_last, angle_last)| (angle_last / ds_last).min(curvature));
            let f_angle = if smooth > 0.0 { (0.5 * sopts.max_angle / (smooth * ds)).clamp(0.5, 2.0) } else { 2.0 };
            if last_step.is_some_and(|last| is_kink_turn(last, (ds, angle), sopts)) {
                kink_floor = Some(kink_floor.map_or(ds, |f| f.max(ds)));
            }
            last_step = Some((ds, angle));
            let mut next = ds * f_iter.min(f_angle);
            if let Some(floor) = kink_floor.filter(|_| f_angle < f_iter) {
                // a turn the step's length does not set shortens the step no further
                next = next.max(floor.min(ds));
            }
            ds = next.clamp(sopts.min_step, sopts.max_step);
            chord
        };
        let new_omega = corrected.y[n];
        if dir[n] * chord[n] < 0.0 {
            result.folds.push(omega);
        }
        if (new_omega - w0) * direction < -LEFT_BAND_MARGIN * span {
            let text = format!("the branch turned back and left the band behind omega_start {}", at(new_omega));
            return Ok(finish(result, SweepEnd::LeftBand, Some(text), None));
        }
        let passed_end = (new_omega - w1) * direction >= 0.0;
        let converged = NewtonOutcome { z: corrected.y[..n].to_vec(), iterations: corrected.iterations, residual: corrected.residual };
        let outcome = if passed_end {
            // Fixed-frequency solve at omega_end from the interpolated guess.
            let s = (w1 - omega) / (new_omega - omega);
            let guess: Vec<f64> = (0..n).map(|i| y[i] + s * (corrected.y[i] - y[i])).collect();
            let lin = system.linear_part(w1)?;
            match newton(AtFrequency { system, plan, opts: hopts, omega: w1 }, &lin, guess, hopts.max_iterations, &mut ws) {
                Ok(o) => (w1, o),
                Err(_) => (new_omega, converged),
            }
        } else {
            (new_omega, converged)
        };
        let p = finish_point(system, plan, outcome.0, outcome.1, &mut ws)?;
        let stop = on_point(&p).is_break();
        z_ref = z_ref.max(characteristic_displacement(system, &p.z));
        let point_omega = p.omega;
        result.points.push(p);
        if stop {
            return Ok(finish(result, SweepEnd::StoppedByCaller, Some(format!("stopped by the caller {}", at(point_omega))), None));
        }
        if passed_end {
            return Ok(finish(result, SweepEnd::ReachedEnd, None, None));
        }
        metric = Metric { sz: 1.0 / (z_ref * z_ref), sw: metric.sw };
        dir = metric.unit(&chord).ok_or_else(|| JpError::singular("continuation chord"))?;
        y = corrected.y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A turn that shrinks with the step is curvature; one that does not, at a shorter step,
    /// is a kink (docs/formulation.md §6.8); small turns never count.
    #[test]
    fn turns_that_do_not_shrink_with_the_step_are_kinks() {
        let sopts = SweepOptions::band(1.0, 2.0);
        let a = sopts.max_angle;
        // smooth: half the step, half the turn
        assert!(!is_kink_turn((0.02, 2.0 * a), (0.01, a), &sopts));
        // kink: half the step, the same turn (the 98-contact NLR's 0.35 rad at 0.044 and 0.022)
        assert!(is_kink_turn((0.044, 0.336), (0.022, 0.349), &sopts));
        assert!(is_kink_turn((0.02, 2.0 * a), (0.01, 1.5 * a), &sopts));
        // not shorter: no evidence either way
        assert!(!is_kink_turn((0.01, 2.0 * a), (0.01, 2.0 * a), &sopts));
        // turns within the aim of the step control are not kinks
        assert!(!is_kink_turn((0.02, 0.4 * a), (0.01, 0.45 * a), &sopts));
    }
}
