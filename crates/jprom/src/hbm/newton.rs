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
use crate::linalg::{norm2, Matrix, MatrixLu};

/// A residual and, when asked for, its Jacobian: the buffers a [`NonlinearProblem`] writes
/// into. The solver keeps two (the current point's and the trial's) and swaps them, so a
/// problem that refills them in place makes the iterations allocation-free.
#[derive(Default)]
pub(crate) struct Evaluation {
    pub r: Vec<f64>,
    pub jac: Option<Matrix>,
}

/// A square system as the solver sees it.
pub(crate) trait NonlinearProblem {
    /// Dimensionless residual at `x` into `out.r` and, when asked, its Jacobian (square, dense
    /// or sparse) into `out.jac`, reusing their storage where it can.
    fn evaluate(&mut self, x: &[f64], want_jacobian: bool, out: &mut Evaluation) -> Result<()>;
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

/// A converged solve: the solution, the iterations used, the residual there and the
/// Jacobian evaluated with it (at the solution itself).
pub(crate) struct Converged {
    pub x: Vec<f64>,
    pub iterations: usize,
    pub residual: Vec<f64>,
    pub jacobian: Option<Matrix>,
}

/// Why a solve did not converge: the iterations it used and where it stopped.
pub(crate) struct NotConverged {
    pub iterations: usize,
    pub residual_norm: f64,
    pub error: JpError,
}

/// Column norms of `a` into `out` (zero or non-finite columns get 1).
fn column_norms_into(a: &Matrix, out: &mut [f64]) {
    a.column_norms_into(out);
    out.iter_mut().for_each(|s| {
        if !(*s > 0.0 && s.is_finite()) {
            *s = 1.0
        }
    });
}

/// `|diag .* v|`.
fn scaled_norm(diag: &[f64], v: &[f64]) -> f64 {
    diag.iter().zip(v).map(|(d, x)| (d * x) * (d * x)).sum::<f64>().sqrt()
}

/// Vectors of the dogleg step, kept between iterations.
struct DoglegWork {
    p_newton: Vec<f64>,
    g: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
}

impl DoglegWork {
    fn new(n: usize) -> Self {
        DoglegWork { p_newton: vec![0.0; n], g: vec![0.0; n], a: vec![0.0; n], b: vec![0.0; n] }
    }
}

/// The dogleg step in unscaled unknowns into `out`, for radius `delta` in scaled ones.
fn dogleg(jac: &Matrix, r: &[f64], diag: &[f64], newton_dz: &[f64], delta: f64, w: &mut DoglegWork, out: &mut [f64]) {
    let n = r.len();
    for j in 0..n {
        w.p_newton[j] = diag[j] * newton_dz[j];
    }
    let len_newton = norm2(&w.p_newton);
    if len_newton <= delta {
        out.copy_from_slice(newton_dz);
        return;
    }
    // Cauchy point of the scaled model: g̃ = J̃^T r = diag^-1 J^T r.
    jac.mat_t_vec_into(r, &mut w.g);
    for j in 0..n {
        w.g[j] /= diag[j];
        w.a[j] = w.g[j] / diag[j];
    }
    jac.mat_vec_into(&w.a, &mut w.b); // J g, g unscaled
    let (g2, jg2) = (norm2(&w.g).powi(2), norm2(&w.b).powi(2));
    // the scaled step p into out
    if jg2 == 0.0 || g2 == 0.0 {
        for j in 0..n {
            out[j] = w.p_newton[j] * delta / len_newton;
        }
    } else {
        let p_c = &mut w.a;
        for j in 0..n {
            p_c[j] = -w.g[j] * g2 / jg2;
        }
        let len_c = norm2(p_c);
        if len_c >= delta {
            for j in 0..n {
                out[j] = p_c[j] * delta / len_c;
            }
        } else {
            // |p_c + tau (p_n - p_c)| = delta, tau in (0, 1).
            let dpc = &mut w.b;
            for j in 0..n {
                dpc[j] = w.p_newton[j] - p_c[j];
            }
            let a = norm2(dpc).powi(2);
            let b = 2.0 * (0..n).map(|j| p_c[j] * dpc[j]).sum::<f64>();
            let c = len_c * len_c - delta * delta;
            let tau = (-b + (b * b - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a);
            for j in 0..n {
                out[j] = p_c[j] + tau * dpc[j];
            }
        }
    }
    for j in 0..n {
        out[j] /= diag[j];
    }
}

/// Solves `problem` from `x0` within `settings.max_iterations` Jacobian evaluations after the
/// first. An unconverged point is never returned as converged.
///
/// Every buffer of the iteration (the current and trial evaluations, the LU, the steps) is
/// sized once, at the first evaluation and factorisation: the iterations themselves do not
/// allocate when the problem refills its evaluations in place (checked by
/// `tests/newton_allocations.rs`).
pub(crate) fn solve(problem: &mut dyn NonlinearProblem, x0: Vec<f64>, settings: &NewtonSettings) -> std::result::Result<Converged, NotConverged> {
    let fail = |iterations: usize, residual_norm: f64, error: JpError| NotConverged { iterations, residual_norm, error };
    let n = x0.len();
    let mut x = x0;
    let mut cur = Evaluation::default();
    problem.evaluate(&x, true, &mut cur).map_err(|e| fail(0, f64::NAN, e))?;
    let mut rel = norm2(&cur.r);
    if !rel.is_finite() {
        return Err(fail(0, rel, JpError::invalid("initial guess", "residual is not finite")));
    }
    if problem.converged(&cur.r, settings.tolerance) {
        return Ok(Converged { x, iterations: 0, residual: cur.r, jacobian: cur.jac });
    }
    let mut diag = vec![1.0; n];
    let mut norms = vec![0.0; n];
    if settings.scaling {
        column_norms_into(cur.jac.as_ref().expect("jacobian requested"), &mut diag);
    }
    let mut radius: Option<f64> = None;
    let what = problem.what();
    // one LU workspace for the solve: refactorised in place (a sparse pattern analysed once)
    let mut lu = MatrixLu::empty();
    let mut newton_dz = vec![0.0; n];
    let newton_step = |lu: &mut MatrixLu, ev: &Evaluation, newton_dz: &mut [f64]| -> Result<()> {
        lu.factor(ev.jac.as_ref().expect("jacobian requested"), || format!("Jacobian of the {what}"))?;
        lu.solve_into(&ev.r, newton_dz);
        newton_dz.iter_mut().for_each(|v| *v = -*v);
        Ok(())
    };
    newton_step(&mut lu, &cur, &mut newton_dz).map_err(|e| fail(0, rel, e))?;
    let mut trial = Evaluation::default();
    let (mut dz, mut x_trial, mut jdz) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut work = DoglegWork::new(n);
    let mut iterations = 0;
    while iterations < settings.max_iterations {
        iterations += 1;
        let jac = cur.jac.as_ref().expect("jacobian requested");
        let len_newton = scaled_norm(&diag, &newton_dz);
        if settings.trust_region {
            let delta = *radius.get_or_insert(settings.initial_radius_factor * len_newton);
            dogleg(jac, &cur.r, &diag, &newton_dz, delta, &mut work, &mut dz);
        } else {
            dz.copy_from_slice(&newton_dz);
        }
        let step_scaled = scaled_norm(&diag, &dz);
        let x_scaled = scaled_norm(&diag, &x);
        for j in 0..n {
            x_trial[j] = x[j] + dz[j];
        }
        // the model's prediction, from the current Jacobian
        jac.mat_vec_into(&dz, &mut jdz);
        let evaluated = match problem.evaluate(&x_trial, true, &mut trial) {
            Ok(()) => norm2(&trial.r).is_finite(),
            Err(e) if !settings.trust_region => return Err(fail(iterations, rel, e)),
            // a failed external law (C callback) is not a bad step: it ends the solve
            Err(e @ JpError::Callback { .. }) => return Err(fail(iterations, rel, e)),
            Err(_) => false,
        };
        let rel_trial = if evaluated { norm2(&trial.r) } else { f64::INFINITY };
        let accepted = if !settings.trust_region {
            evaluated
        } else {
            let model: f64 = (0..n).map(|i| (cur.r[i] + jdz[i]).powi(2)).sum();
            let pred = rel * rel - model;
            let actual = rel * rel - rel_trial * rel_trial;
            let rho = if !evaluated {
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
            std::mem::swap(&mut x, &mut x_trial);
            std::mem::swap(&mut cur, &mut trial);
            rel = rel_trial;
            if problem.converged(&cur.r, settings.tolerance) {
                return Ok(Converged { x, iterations, residual: cur.r, jacobian: cur.jac });
            }
            if settings.scaling {
                column_norms_into(cur.jac.as_ref().expect("jacobian requested"), &mut norms);
                for (d, c) in diag.iter_mut().zip(&norms) {
                    *d = d.max(*c);
                }
            }
            newton_step(&mut lu, &cur, &mut newton_dz).map_err(|e| fail(iterations, rel, e))?;
        }
        if step_scaled <= settings.step_tolerance * (1.0 + x_scaled) {
            break;
        }
    }
    Err(fail(iterations, rel, JpError::NoConvergence { what: format!("Newton on the {}", problem.what()), iterations, residual: rel, tolerance: settings.tolerance }))
}
