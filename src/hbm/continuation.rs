//! Pseudo-arclength continuation of HBM solutions over a frequency band.
//!
//! Unknowns `y = (z, omega)`, arclength measured in the metric
//! `|dy|^2 = |dz|^2 / z_ref^2 + domega^2 / span^2` (see [`SweepOptions`]).
//!
//! * **Tangent** `t` at a converged point: null vector of `[J_z  dR/domega]`, from the
//!   bordered system `[J_z  R_omega; t_prev^T S] t = [0; 1]`, normalised to unit length (the
//!   last row keeps the direction of travel, also through folds, where `J_z` is singular).
//!   `dR/domega = (D(omega + delta) - D(omega - delta)) z / (2 delta) - (f(+) - f(-)) / (2 delta)`
//!   by a central difference of [`HarmonicSystem::linear_part`] (`delta = omega_difference *
//!   omega`); contact forces do not depend on `omega` (rate-independent friction). For the full
//!   system `D` is quadratic in `omega`, so the difference is exact up to rounding.
//! * **Predictor** `y_p = y + ds t`.
//! * **Corrector**: Newton on `R(z, omega) = 0`, `t^T S (y - y_p) = 0` with the bordered
//!   Jacobian. Converged when `|R| <= tol f_ref` as in [`super::solve_point`].
//! * **Step control**: a corrector that fails (too many iterations, singular matrix, non-finite
//!   residual) halves `ds`; below `min_step` the sweep ends with [`SweepEnd::StepTooSmall`].
//!   After a success `ds *= clamp(target / iterations, 1/2, 2)`, within `[min_step, max_step]`.
//! * The point that passes `omega_end` is replaced by a fixed-frequency solve at `omega_end`.

use super::residual::{evaluate, linear_residual, ResidualWorkspace};
use super::solve::{finish_point, lu_checked, lu_solve, newton, plan_for, reference_force, NewtonOutcome};
use super::{HarmonicSystem, HbmOptions, LinearPart, PointSolution, SweepEnd, SweepOptions, SweepResult, LEFT_BAND_MARGIN};
use crate::aft::AftPlan;
use crate::error::{JpError, Result};
use crate::linalg::norm2;
use faer::Mat;
use std::ops::ControlFlow;

/// `dR/domega` at `(z, omega)` by a central difference of the linear part with step `delta`
/// (the contact forces do not depend on `omega`).
///
/// # Errors
/// Those of [`HarmonicSystem::linear_part`].
pub fn residual_omega_derivative(system: &dyn HarmonicSystem, omega: f64, z: &[f64], delta: f64) -> Result<Vec<f64>> {
    let layout = system.layout();
    let lp = system.linear_part(omega + delta)?;
    let lm = system.linear_part(omega - delta)?;
    let rp = linear_residual(layout, &lp, z);
    let rm = linear_residual(layout, &lm, z);
    Ok(rp.iter().zip(&rm).map(|(a, b)| (a - b) / (2.0 * delta)).collect())
}

/// Residual, `J_z`, `R_omega` and reference force at one `(z, omega)`.
struct Linearisation {
    r: Vec<f64>,
    jz: Mat<f64>,
    r_omega: Vec<f64>,
    f_ref: f64,
}

fn linearise(
    system: &dyn HarmonicSystem,
    plan: Option<&AftPlan>,
    z: &[f64],
    omega: f64,
    sopts: &SweepOptions,
    ws: &mut ResidualWorkspace,
) -> Result<Linearisation> {
    let lin: LinearPart = system.linear_part(omega)?;
    let (r, jz) = evaluate(system, &lin, plan, z, true, ws)?;
    let f_ref = reference_force(&lin, ws.contact_force_norm(), norm2(&r));
    let r_omega = residual_omega_derivative(system, omega, z, sopts.omega_difference * omega)?;
    Ok(Linearisation { r, jz: jz.expect("jacobian requested"), r_omega, f_ref })
}

/// Metric weights: `|dz|^2 sz + domega^2 sw`.
#[derive(Clone, Copy)]
struct Metric {
    sz: f64,
    sw: f64,
}

impl Metric {
    fn dot(&self, a: &[f64], b: &[f64]) -> f64 {
        let n = a.len() - 1;
        self.sz * (0..n).map(|i| a[i] * b[i]).sum::<f64>() + self.sw * a[n] * b[n]
    }
}

/// The bordered matrix `[J_z  R_omega; t^T S]`.
fn bordered(lz: &Linearisation, t: &[f64], m: Metric) -> Mat<f64> {
    let n = lz.r.len();
    Mat::from_fn(n + 1, n + 1, |i, j| {
        if i < n {
            if j < n {
                lz.jz[(i, j)]
            } else {
                lz.r_omega[i]
            }
        } else if j < n {
            m.sz * t[j]
        } else {
            m.sw * t[n]
        }
    })
}

/// Unit tangent at a linearised point, oriented along `t_prev`.
fn tangent(lz: &Linearisation, t_prev: &[f64], m: Metric, omega: f64) -> Result<Vec<f64>> {
    let n = lz.r.len();
    let b = bordered(lz, t_prev, m);
    let lu = lu_checked(&b, &format!("continuation tangent system at omega = {omega}"))?;
    let mut rhs = vec![0.0; n + 1];
    rhs[n] = 1.0;
    let t = lu_solve(&lu, &rhs);
    let len = m.dot(&t, &t).sqrt();
    if !(len.is_finite() && len > 0.0) {
        return Err(JpError::singular(format!("continuation tangent at omega = {omega}")));
    }
    Ok(t.iter().map(|v| v / len).collect())
}

/// A converged corrector: the point and its linearisation (reused for the next tangent).
struct Corrected {
    y: Vec<f64>,
    lz: Linearisation,
    iterations: usize,
}

#[allow(clippy::too_many_arguments)]
fn correct(
    system: &dyn HarmonicSystem,
    plan: Option<&AftPlan>,
    y_pred: &[f64],
    t: &[f64],
    m: Metric,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    ws: &mut ResidualWorkspace,
    sphere: Option<(&[f64], f64)>,
) -> Result<Corrected> {
    let n = y_pred.len() - 1;
    let mut y = y_pred.to_vec();
    let mut iterations = 0;
    let mut lz = linearise_checked(system, plan, &y, sopts, ws)?;
    loop {
        let omega = y[n];
        let rel = norm2(&lz.r) / lz.f_ref;
        if rel <= hopts.residual_tolerance {
            return Ok(Corrected { y, lz, iterations });
        }
        if iterations >= sopts.max_corrector_iterations {
            return Err(JpError::NoConvergence {
                what: format!("continuation corrector near omega = {omega}"),
                iterations,
                residual: rel,
            });
        }
        // Constraint: the pseudo-arclength hyperplane `t . S (y - y_pred) = 0`, or the sphere
        // `|y - y_c|_S^2 = r^2` around the previous point, which still cuts the branch where it
        // turns by more than a right angle (a sharp fold made by a contact kink).
        let (row, g) = match sphere {
            None => {
                let dy: Vec<f64> = (0..=n).map(|i| y[i] - y_pred[i]).collect();
                (t.to_vec(), m.dot(t, &dy))
            }
            Some((yc, radius)) => {
                let d: Vec<f64> = (0..=n).map(|i| y[i] - yc[i]).collect();
                (d.iter().map(|v| 2.0 * v).collect(), m.dot(&d, &d) - radius * radius)
            }
        };
        let b = bordered(&lz, &row, m);
        let lu = lu_checked(&b, &format!("bordered continuation Jacobian at omega = {omega}"))?;
        let mut rhs: Vec<f64> = lz.r.iter().map(|v| -v).collect();
        rhs.push(-g);
        let step = lu_solve(&lu, &rhs);
        // Backtracking: contact laws make the residual piecewise smooth, and a full Newton
        // step can jump back and forth across a kink (a time sample opening or closing, a
        // contact entering slip). Halve the step while it does not reduce the residual.
        let mut alpha = 1.0;
        loop {
            let trial: Vec<f64> = (0..=n).map(|i| y[i] + alpha * step[i]).collect();
            let tz = linearise_checked(system, plan, &trial, sopts, ws);
            let accept = match &tz {
                Ok(l) => norm2(&l.r) / l.f_ref < rel || alpha <= 1.0 / 16.0,
                Err(_) => false,
            };
            if accept {
                y = trial;
                lz = tz?;
                break;
            }
            if alpha <= 1.0 / 16.0 {
                return Err(tz.err().unwrap_or_else(|| JpError::invalid("continuation", "corrector line search failed")));
            }
            alpha *= 0.5;
        }
        iterations += 1;
    }
}

/// [`linearise`] at `y = [z; omega]`, rejecting a non-positive frequency or a non-finite residual.
fn linearise_checked(
    system: &dyn HarmonicSystem,
    plan: Option<&AftPlan>,
    y: &[f64],
    sopts: &SweepOptions,
    ws: &mut ResidualWorkspace,
) -> Result<Linearisation> {
    let n = y.len() - 1;
    let omega = y[n];
    if !(omega.is_finite() && omega > 0.0) {
        return Err(JpError::invalid("continuation", format!("corrector left omega > 0 ({omega})")));
    }
    let lz = linearise(system, plan, &y[..n], omega, sopts, ws)?;
    if !(norm2(&lz.r) / lz.f_ref).is_finite() {
        return Err(JpError::invalid("continuation", "non-finite residual in the corrector"));
    }
    Ok(lz)
}

/// Norm of the harmonic (`h >= 1`) part of `z`, or of all of `z` if that vanishes, or 1.
fn characteristic_displacement(system: &dyn HarmonicSystem, z: &[f64]) -> f64 {
    let n0 = system.layout().size(0);
    let dynamic = norm2(&z[n0..]);
    if dynamic > 0.0 {
        dynamic
    } else {
        let all = norm2(z);
        if all > 0.0 {
            all
        } else {
            1.0
        }
    }
}

/// Follows the branch of HBM solutions from `sopts.omega_start` to `sopts.omega_end` by
/// pseudo-arclength continuation, calling `on_point` with each converged point (the first one
/// included); `ControlFlow::Break` stops the sweep ([`SweepEnd::StoppedByCaller`]).
///
/// # Errors
/// Bad options ([`JpError::InvalidValue`]); the first point's solve error (the sweep has no
/// point then). Later failures end the sweep with [`SweepEnd::StepTooSmall`] and the error in
/// [`SweepResult::error`], keeping the points found.
pub fn sweep(
    system: &dyn HarmonicSystem,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    on_point: &mut dyn FnMut(&PointSolution) -> ControlFlow<()>,
) -> Result<SweepResult> {
    sopts.validate()?;
    hopts.validate()?;
    if system.layout().harmonics != hopts.harmonics {
        return Err(JpError::invalid(
            "HbmOptions.harmonics",
            format!("system has H = {}, options say {}", system.layout().harmonics, hopts.harmonics),
        ));
    }
    let plan = plan_for(system, hopts)?;
    let plan = plan.as_ref();
    let mut ws = ResidualWorkspace::new();
    let n = system.layout().total();
    let (w0, w1) = (sopts.omega_start, sopts.omega_end);
    let direction = (w1 - w0).signum();
    let span = (w1 - w0).abs();

    let mut result = SweepResult {
        points: Vec::new(),
        rejected_steps: 0,
        end: SweepEnd::ReachedEnd,
        stopped_early: false,
        failure: None,
        error: None,
    };
    let finish = |mut res: SweepResult, end: SweepEnd, error: Option<JpError>| {
        res.end = end;
        res.stopped_early = end != SweepEnd::ReachedEnd;
        res.failure = error.as_ref().map(|e| e.to_string());
        res.error = error;
        res
    };

    // First point at omega_start, with the point solver's load-stepping fallback (a reduced
    // model regenerated mid-workflow can leave Newton from zero stuck at a local minimum).
    let first = super::solve_point(system, w0, None, hopts)?;
    let mut z_ref = characteristic_displacement(system, &first.z);
    let mut y: Vec<f64> = first.z.iter().copied().chain([w0]).collect();
    let stop = on_point(&first).is_break();
    result.points.push(first);
    if stop {
        return Ok(finish(result, SweepEnd::StoppedByCaller, None));
    }

    let mut metric = Metric { sz: 1.0 / (z_ref * z_ref), sw: 1.0 / (span * span) };
    let mut t_prev = vec![0.0; n + 1];
    t_prev[n] = direction * span;
    let mut lz = linearise(system, plan, &y[..n], w0, sopts, &mut ws)?;
    let mut ds = sopts.initial_step;
    let mut last_error: Option<JpError> = None;
    loop {
        if result.points.len() >= sopts.max_points {
            return Ok(finish(result, SweepEnd::MaxPoints, None));
        }
        let omega = y[n];
        let t = match tangent(&lz, &t_prev, metric, omega) {
            Ok(t) => t,
            Err(e) => return Ok(finish(result, SweepEnd::StepTooSmall, Some(e))),
        };
        // Predict, correct; halve the step until the corrector converges.
        let corrected = loop {
            if ds < sopts.min_step {
                let e = last_error.take().unwrap_or_else(|| JpError::NoConvergence {
                    what: "continuation".into(),
                    iterations: 0,
                    residual: f64::NAN,
                });
                return Ok(finish(result, SweepEnd::StepTooSmall, Some(e)));
            }
            let y_pred: Vec<f64> = (0..=n).map(|i| y[i] + ds * t[i]).collect();
            let attempt = correct(system, plan, &y_pred, &t, metric, sopts, hopts, &mut ws, None).or_else(|e| {
                // fallback: the sphere of radius ds around the current point, forward only
                let c = correct(system, plan, &y_pred, &t, metric, sopts, hopts, &mut ws, Some((&y, ds))).map_err(|_| e.clone())?;
                let d: Vec<f64> = (0..=n).map(|i| c.y[i] - y[i]).collect();
                if metric.dot(&t, &d) > 0.0 {
                    Ok(c)
                } else {
                    Err(e)
                }
            });
            match attempt {
                Ok(c) => break c,
                Err(e) => {
                    last_error = Some(e);
                    result.rejected_steps += 1;
                    ds *= 0.5;
                }
            }
        };
        let iters = corrected.iterations.max(1) as f64;
        let factor = (sopts.target_iterations as f64 / iters).clamp(0.5, 2.0);
        ds = (ds * factor).clamp(sopts.min_step, sopts.max_step);
        let new_omega = corrected.y[n];
        if (new_omega - w0) * direction < -LEFT_BAND_MARGIN * span {
            return Ok(finish(result, SweepEnd::LeftBand, None));
        }
        let passed_end = (new_omega - w1) * direction >= 0.0;
        let point = if passed_end {
            // Fixed-frequency solve at omega_end from the interpolated guess.
            let s = (w1 - omega) / (new_omega - omega);
            let guess: Vec<f64> = (0..n).map(|i| y[i] + s * (corrected.y[i] - y[i])).collect();
            let lin = system.linear_part(w1)?;
            match newton(system, &lin, plan, guess, hopts, w1, &mut ws) {
                Ok(o) => Some(finish_point(system, plan, w1, o, &mut ws)?),
                Err(_) => None,
            }
        } else {
            let out = NewtonOutcome {
                z: corrected.y[..n].to_vec(),
                iterations: corrected.iterations,
                residual: norm2(&corrected.lz.r) / corrected.lz.f_ref,
            };
            Some(finish_point(system, plan, new_omega, out, &mut ws)?)
        };
        if let Some(p) = point {
            let stop = on_point(&p).is_break();
            z_ref = z_ref.max(characteristic_displacement(system, &p.z));
            result.points.push(p);
            if stop {
                return Ok(finish(result, SweepEnd::StoppedByCaller, None));
            }
        }
        if passed_end {
            return Ok(finish(result, SweepEnd::ReachedEnd, None));
        }
        metric = Metric { sz: 1.0 / (z_ref * z_ref), sw: metric.sw };
        t_prev = t;
        y = corrected.y;
        lz = corrected.lz;
        last_error = None;
    }
}
