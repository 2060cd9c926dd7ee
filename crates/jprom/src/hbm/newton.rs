//! Newton's method with a dogleg trust region for a square nonlinear system `r(x) = 0`: the one
//! solver behind a frequency point ([`super::solve_point`]) and the continuation corrector
//! ([`super::sweep`]).
//!
//! **Scaling.** The problem hands over its residual already scaled to be dimensionless
//! (`r / f_ref` for the HBM equations, see [`super::HbmOptions::residual_tolerance`]). The
//! unknowns are scaled by the Jacobian's column norms `d_j` (kept as the running maximum over
//! iterations, as in MINPACK): `x̃_j = d_j x_j`, so `J̃ = J diag(d)^-1` has unit columns. Both are
//! invariant under a change of units of length or force.
//!
//! **Trust region.** Dogleg between the Cauchy point and the Newton step in `x̃`, radius
//! initialised to `initial_radius_factor` times the first Newton step's length (so a linear
//! system converges in one step), shrunk on poor agreement (`rho < 1/4`) and doubled on good
//! agreement at the boundary. A trial point whose residual cannot be evaluated (a non-finite
//! value, a frequency pushed below zero) counts as a failed trial and shrinks the radius.

use crate::error::{JpError, Result};
use crate::linalg::{norm2, Matrix, MatrixLu, SymbolicCache};

/// A square system as the solver sees it.
pub(crate) trait NonlinearProblem {
    /// Dimensionless residual at `x` and, when asked, its Jacobian (square, dense or sparse).
    fn evaluate(&mut self, x: &[f64], want_jacobian: bool) -> Result<(Vec<f64>, Option<Matrix>)>;
    /// Whether `r` (as returned by [`NonlinearProblem::evaluate`]) is converged.
    fn converged(&self, r: &[f64], tolerance: f64) -> bool {
        norm2(r) <= tolerance
    }
    /// What is being solved, for error messages ("HBM equations at omega = ...").
    fn what(&self) -> String;
}

/// Settings of one solve.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NewtonSettings {
    pub tolerance: f64,
    pub step_tolerance: f64,
    pub max_iterations: usize,
    pub trust_region: bool,
    pub initial_radius_factor: f64,
    pub scaling: bool,
}

/// A converged solve: the solution, the iterations used and the residual there.
pub(crate) struct Converged {
    pub x: Vec<f64>,
    pub iterations: usize,
    pub residual: Vec<f64>,
}

/// Why a solve did not converge: the iterations it used and where it stopped.
pub(crate) struct NotConverged {
    pub iterations: usize,
    pub residual_norm: f64,
    pub error: JpError,
}

/// Column norms of `a` (zero or non-finite columns get 1).
pub(crate) fn column_norms(a: &Matrix) -> Vec<f64> {
    a.column_norms().into_iter().map(|s| if s > 0.0 && s.is_finite() { s } else { 1.0 }).collect()
}

/// The dogleg step in unscaled unknowns, for radius `delta` in scaled ones.
fn dogleg(jac: &Matrix, r: &[f64], diag: &[f64], newton_dz: &[f64], delta: f64) -> Vec<f64> {
    let n = r.len();
    let p_newton: Vec<f64> = (0..n).map(|j| diag[j] * newton_dz[j]).collect();
    let len_newton = norm2(&p_newton);
    if len_newton <= delta {
        return newton_dz.to_vec();
    }
    // Cauchy point of the scaled model: g̃ = J̃^T r = diag^-1 J^T r.
    let jt_r = jac.mat_t_vec(r);
    let g: Vec<f64> = (0..n).map(|j| jt_r[j] / diag[j]).collect();
    let g_unscaled: Vec<f64> = (0..n).map(|j| g[j] / diag[j]).collect();
    let jg = jac.mat_vec(&g_unscaled);
    let (g2, jg2) = (norm2(&g).powi(2), norm2(&jg).powi(2));
    let p: Vec<f64> = if jg2 == 0.0 || g2 == 0.0 {
        p_newton.iter().map(|v| v * delta / len_newton).collect()
    } else {
        let p_c: Vec<f64> = g.iter().map(|v| -v * g2 / jg2).collect();
        let len_c = norm2(&p_c);
        if len_c >= delta {
            p_c.iter().map(|v| v * delta / len_c).collect()
        } else {
            // |p_c + tau (p_n - p_c)| = delta, tau in (0, 1).
            let dpc: Vec<f64> = (0..n).map(|j| p_newton[j] - p_c[j]).collect();
            let a = norm2(&dpc).powi(2);
            let b = 2.0 * (0..n).map(|j| p_c[j] * dpc[j]).sum::<f64>();
            let c = len_c * len_c - delta * delta;
            let tau = (-b + (b * b - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a);
            (0..n).map(|j| p_c[j] + tau * dpc[j]).collect()
        }
    };
    (0..n).map(|j| p[j] / diag[j]).collect()
}

/// Solves `problem` from `x0` within `settings.max_iterations` Jacobian evaluations after the
/// first. An unconverged point is never returned as converged.
pub(crate) fn solve(problem: &mut dyn NonlinearProblem, x0: Vec<f64>, settings: &NewtonSettings) -> std::result::Result<Converged, NotConverged> {
    let fail = |iterations: usize, residual_norm: f64, error: JpError| NotConverged { iterations, residual_norm, error };
    let n = x0.len();
    let mut x = x0;
    let (mut r, jac) = problem.evaluate(&x, true).map_err(|e| fail(0, f64::NAN, e))?;
    let mut jac = jac.expect("jacobian requested");
    let mut rel = norm2(&r);
    if !rel.is_finite() {
        return Err(fail(0, rel, JpError::invalid("initial guess", "residual is not finite")));
    }
    if problem.converged(&r, settings.tolerance) {
        return Ok(Converged { x, iterations: 0, residual: r });
    }
    let mut diag = if settings.scaling { column_norms(&jac) } else { vec![1.0; n] };
    let mut radius: Option<f64> = None;
    let what = problem.what();
    // the Jacobians of one solve share a pattern: a sparse one is analysed once
    let mut cache = SymbolicCache::new();
    let mut factor = |jac: &Matrix| -> Result<MatrixLu> { MatrixLu::new(jac, &format!("Jacobian of the {what}"), &mut cache) };
    let mut lu = factor(&jac).map_err(|e| fail(0, rel, e))?;
    let mut newton_dz: Vec<f64> = lu.solve(&r).iter().map(|v| -v).collect();
    let mut iterations = 0;
    while iterations < settings.max_iterations {
        iterations += 1;
        let len_newton = norm2(&(0..n).map(|j| diag[j] * newton_dz[j]).collect::<Vec<_>>());
        let dz = if settings.trust_region {
            let delta = *radius.get_or_insert(settings.initial_radius_factor * len_newton);
            dogleg(&jac, &r, &diag, &newton_dz, delta)
        } else {
            newton_dz.clone()
        };
        let step_scaled = norm2(&(0..n).map(|j| diag[j] * dz[j]).collect::<Vec<_>>());
        let x_scaled = norm2(&(0..n).map(|j| diag[j] * x[j]).collect::<Vec<_>>());
        let x_trial: Vec<f64> = (0..n).map(|j| x[j] + dz[j]).collect();
        let trial = problem.evaluate(&x_trial, true);
        let trial = match trial {
            Ok((rt, jt)) if norm2(&rt).is_finite() => Some((rt, jt.expect("jacobian requested"))),
            Ok(_) => None,
            Err(e) if !settings.trust_region => return Err(fail(iterations, rel, e)),
            // a failed external law (C callback) is not a bad step: it ends the solve
            Err(e @ JpError::Callback { .. }) => return Err(fail(iterations, rel, e)),
            Err(_) => None,
        };
        let rel_trial = trial.as_ref().map(|(rt, _)| norm2(rt)).unwrap_or(f64::INFINITY);
        let accepted = if !settings.trust_region {
            trial.is_some()
        } else {
            let jdz = jac.mat_vec(&dz);
            let model: f64 = (0..n).map(|i| (r[i] + jdz[i]).powi(2)).sum();
            let pred = rel * rel - model;
            let actual = rel * rel - rel_trial * rel_trial;
            let rho = if trial.is_none() {
                -1.0
            } else if pred > 0.0 {
                actual / pred
            } else if actual > 0.0 {
                1.0
            } else {
                -1.0
            };
            let delta = radius.as_mut().expect("radius set");
            if rho < 0.25 {
                *delta = 0.25 * step_scaled.min(*delta);
            } else if rho > 0.75 && step_scaled >= 0.99 * *delta {
                *delta *= 2.0;
            }
            rho > 1e-4
        };
        if accepted {
            let (rt, jt) = trial.expect("accepted trials were evaluated");
            x = x_trial;
            r = rt;
            rel = rel_trial;
            jac = jt;
            if problem.converged(&r, settings.tolerance) {
                return Ok(Converged { x, iterations, residual: r });
            }
            if settings.scaling {
                for (d, c) in diag.iter_mut().zip(column_norms(&jac)) {
                    *d = d.max(c);
                }
            }
            lu = factor(&jac).map_err(|e| fail(iterations, rel, e))?;
            newton_dz = lu.solve(&r).iter().map(|v| -v).collect();
        }
        if step_scaled <= settings.step_tolerance * (1.0 + x_scaled) {
            break;
        }
    }
    Err(fail(iterations, rel, JpError::NoConvergence { what: format!("Newton on the {}", problem.what()), iterations, residual: rel }))
}
