//! One frequency point: Newton's method with a dogleg trust region on the scaled problem
//! (method.md §2).
//!
//! **Scaling.** With `f_ref` the reference force (see [`HbmOptions::residual_tolerance`]) and
//! `d_j` the column norms of the Jacobian (kept as the running maximum over iterations, as in
//! MINPACK), the solver works on `r̃ = r / f_ref` and `x̃_j = d_j z_j / f_ref`, so
//! `J̃ = J diag(d)^-1` has unit columns. Both are invariant under a change of units of
//! length or force: a solve takes the same steps in mm and N as in m and MN.
//!
//! **Trust region.** Dogleg between the Cauchy point and the Newton step in `x̃`, radius
//! initialised to the first Newton step's length (so a linear system converges in one step),
//! shrunk on poor agreement (`rho < 1/4`) and doubled on good agreement at the boundary.

use super::residual::{self, evaluate, ResidualWorkspace};
use super::{HarmonicSystem, HbmOptions, LinearPart, PointSolution};
use crate::aft::AftPlan;
use crate::error::{JpError, Result};
use crate::linalg::norm2;
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::Mat;

/// Factorises `a` by LU with partial pivoting and rejects (numerically) singular matrices:
/// any pivot below `100 n eps` times the largest, or a non-finite pivot.
///
/// # Errors
/// [`JpError::SingularMatrix`] naming `what`.
pub(crate) fn lu_checked(a: &Mat<f64>, what: &str) -> Result<PartialPivLu<f64>> {
    let lu = a.partial_piv_lu();
    let u = lu.U();
    let n = u.nrows();
    let mut max_p = 0.0f64;
    let mut min_p = f64::INFINITY;
    for i in 0..n {
        let p = u[(i, i)].abs();
        if !p.is_finite() {
            return Err(JpError::singular(format!("{what}: non-finite pivot {i}")));
        }
        max_p = max_p.max(p);
        min_p = min_p.min(p);
    }
    if n > 0 && (max_p == 0.0 || min_p <= 100.0 * n as f64 * f64::EPSILON * max_p) {
        return Err(JpError::singular(format!(
            "{what} ({n} x {n}): smallest pivot {min_p:.3e} vs largest {max_p:.3e}"
        )));
    }
    Ok(lu)
}

/// Checks that a square matrix is numerically nonsingular (see [`lu_checked`]).
pub(crate) fn check_nonsingular(a: &Mat<f64>, what: &str) -> Result<()> {
    lu_checked(a, what).map(|_| ())
}

/// Solves `lu x = b`.
pub(crate) fn lu_solve(lu: &PartialPivLu<f64>, b: &[f64]) -> Vec<f64> {
    let rhs = Mat::from_fn(b.len(), 1, |i, _| b[i]);
    let x = lu.solve(&rhs);
    (0..b.len()).map(|i| x[(i, 0)]).collect()
}

/// Norm of the external force `f` of a linear part (all harmonics).
pub(crate) fn force_norm(lin: &LinearPart) -> f64 {
    let mut s = norm2(&lin.f0).powi(2);
    for (c, si) in lin.fh_cos.iter().zip(&lin.fh_sin) {
        s += norm2(c).powi(2) + norm2(si).powi(2);
    }
    s.sqrt()
}

/// Reference force: the larger of `|f|` and the contact force at the starting point; if both
/// vanish, `|r|` at the start; 1 if that vanishes too.
pub(crate) fn reference_force(lin: &LinearPart, contact_force_norm: f64, r0: f64) -> f64 {
    let f = force_norm(lin).max(contact_force_norm);
    if f > 0.0 {
        f
    } else if r0 > 0.0 {
        r0
    } else {
        1.0
    }
}

/// Column norms of `a` (zero columns get 1).
pub(crate) fn column_norms(a: &Mat<f64>) -> Vec<f64> {
    (0..a.ncols())
        .map(|j| {
            let s = (0..a.nrows()).map(|i| a[(i, j)] * a[(i, j)]).sum::<f64>().sqrt();
            if s > 0.0 && s.is_finite() {
                s
            } else {
                1.0
            }
        })
        .collect()
}

/// `a v`.
pub(crate) fn mat_vec(a: &Mat<f64>, v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.nrows()];
    for j in 0..a.ncols() {
        let vj = v[j];
        if vj != 0.0 {
            for i in 0..a.nrows() {
                out[i] += a[(i, j)] * vj;
            }
        }
    }
    out
}

/// `a^T v`.
fn mat_t_vec(a: &Mat<f64>, v: &[f64]) -> Vec<f64> {
    (0..a.ncols()).map(|j| (0..a.nrows()).map(|i| a[(i, j)] * v[i]).sum()).collect()
}

/// The AFT plan a system needs (`None` without contacts).
pub(crate) fn plan_for(system: &dyn HarmonicSystem, opts: &HbmOptions) -> Result<Option<AftPlan>> {
    if system.contact_laws().is_empty() {
        Ok(None)
    } else {
        AftPlan::new(system.layout().harmonics, opts.nt()).map(Some)
    }
}

/// Result of a Newton solve at fixed frequency.
pub(crate) struct NewtonOutcome {
    pub z: Vec<f64>,
    pub iterations: usize,
    /// `|r| / f_ref`.
    pub residual: f64,
}

/// Newton / dogleg trust region at fixed `lin` (one frequency) from `z0`.
pub(crate) fn newton(
    system: &dyn HarmonicSystem,
    lin: &LinearPart,
    plan: Option<&AftPlan>,
    z0: Vec<f64>,
    opts: &HbmOptions,
    omega: f64,
    ws: &mut ResidualWorkspace,
) -> Result<NewtonOutcome> {
    let n = z0.len();
    let mut z = z0;
    let (mut r, jac) = evaluate(system, lin, plan, &z, true, ws)?;
    let mut jac = jac.expect("jacobian requested");
    let f_ref = reference_force(lin, ws.contact_force_norm(), norm2(&r));
    let tol = opts.residual_tolerance;
    let mut rel = norm2(&r) / f_ref;
    if !rel.is_finite() {
        return Err(JpError::invalid("HBM initial guess", "residual is not finite"));
    }
    if rel <= tol {
        return Ok(NewtonOutcome { z, iterations: 0, residual: rel });
    }
    let mut diag = if opts.scaling { column_norms(&jac) } else { vec![1.0; n] };
    let unit = if opts.scaling { f_ref } else { 1.0 };
    let mut radius: Option<f64> = None;
    let what = || format!("HBM Jacobian at omega = {omega}");
    let mut lu = lu_checked(&jac, &what())?;
    let mut newton_dz: Vec<f64> = lu_solve(&lu, &r).iter().map(|v| -v).collect();
    let mut iterations = 0;
    while iterations < opts.max_iterations {
        iterations += 1;
        // Scaled Newton step p̃_N = diag dz / unit.
        let p_newton: Vec<f64> = (0..n).map(|j| diag[j] * newton_dz[j] / unit).collect();
        let len_newton = norm2(&p_newton);
        let dz: Vec<f64> = if !opts.trust_region {
            newton_dz.clone()
        } else {
            let delta = *radius.get_or_insert(opts.initial_radius_factor * len_newton);
            if len_newton <= delta {
                newton_dz.clone()
            } else {
                // Cauchy point of the scaled model, J̃ = J diag^-1 unit / f_ref, r̃ = r / f_ref:
                // g̃ = J̃^T r̃ = diag^-1 J^T r unit / f_ref^2.
                let jt_r = mat_t_vec(&jac, &r);
                let g: Vec<f64> = (0..n).map(|j| jt_r[j] / diag[j] * unit / (f_ref * f_ref)).collect();
                let g_unscaled: Vec<f64> = (0..n).map(|j| g[j] / diag[j] * unit).collect();
                let jg: Vec<f64> = mat_vec(&jac, &g_unscaled).iter().map(|v| v / f_ref).collect();
                let g2 = norm2(&g).powi(2);
                let jg2 = norm2(&jg).powi(2);
                let p = if jg2 == 0.0 || g2 == 0.0 {
                    p_newton.iter().map(|v| v * delta / len_newton).collect::<Vec<_>>()
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
                (0..n).map(|j| p[j] / diag[j] * unit).collect()
            }
        };
        let step_scaled = norm2(&(0..n).map(|j| diag[j] * dz[j] / unit).collect::<Vec<_>>());
        let x_scaled = norm2(&(0..n).map(|j| diag[j] * z[j] / unit).collect::<Vec<_>>());
        let z_trial: Vec<f64> = (0..n).map(|j| z[j] + dz[j]).collect();
        let (r_trial, jac_trial) = evaluate(system, lin, plan, &z_trial, true, ws)?;
        let rel_trial = norm2(&r_trial) / f_ref;
        let accepted = if !opts.trust_region {
            rel_trial.is_finite()
        } else {
            let jdz = mat_vec(&jac, &dz);
            let model: f64 = (0..n).map(|i| ((r[i] + jdz[i]) / f_ref).powi(2)).sum();
            let pred = rel * rel - model;
            let actual = rel * rel - rel_trial * rel_trial;
            let rho = if !rel_trial.is_finite() {
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
            z = z_trial;
            r = r_trial;
            rel = rel_trial;
            jac = jac_trial.expect("jacobian requested");
            if rel <= tol {
                return Ok(NewtonOutcome { z, iterations, residual: rel });
            }
            if opts.scaling {
                for (d, c) in diag.iter_mut().zip(column_norms(&jac)) {
                    *d = d.max(c);
                }
            }
            lu = lu_checked(&jac, &what())?;
            newton_dz = lu_solve(&lu, &r).iter().map(|v| -v).collect();
        }
        if step_scaled <= opts.step_tolerance * (1.0 + x_scaled) {
            break;
        }
    }
    Err(JpError::NoConvergence { what: format!("HBM Newton at omega = {omega}"), iterations, residual: rel })
}

/// Builds the reported solution (outputs, contact cycles) for a converged `z`.
pub(crate) fn finish_point(
    system: &dyn HarmonicSystem,
    plan: Option<&AftPlan>,
    omega: f64,
    outcome: NewtonOutcome,
    ws: &mut ResidualWorkspace,
) -> Result<PointSolution> {
    let outputs = system.output_harmonics(omega, &outcome.z)?;
    let contact_cycles = residual::contact_cycles(system, plan, &outcome.z, ws)?;
    Ok(PointSolution {
        omega,
        layout: system.layout().clone(),
        z: outcome.z,
        converged: true,
        iterations: outcome.iterations,
        residual_norm: outcome.residual,
        outputs,
        n_outputs: system.n_outputs(),
        contact_cycles,
    })
}

/// Solves the HBM equations of `system` at angular frequency `omega` from `z_guess` (zero if
/// `None`: the first Newton step is then the linear, fully stuck response).
///
/// # Errors
/// [`JpError::InvalidValue`] / [`JpError::BadSize`] for bad options, frequency or guess;
/// [`JpError::SingularMatrix`] if a Jacobian is singular; [`JpError::NoConvergence`] if the
/// residual tolerance is not met within `opts.max_iterations` (or the steps stagnate). An
/// unconverged point is never returned.
pub fn solve_point(
    system: &dyn HarmonicSystem,
    omega: f64,
    z_guess: Option<&[f64]>,
    opts: &HbmOptions,
) -> Result<PointSolution> {
    opts.validate()?;
    if system.layout().harmonics != opts.harmonics {
        return Err(JpError::invalid(
            "HbmOptions.harmonics",
            format!("system has H = {}, options say {}", system.layout().harmonics, opts.harmonics),
        ));
    }
    super::full::check_omega(omega)?;
    let n = system.layout().total();
    let z0 = match z_guess {
        Some(g) => {
            if g.len() != n {
                return Err(JpError::bad_size("z_guess", n, g.len()));
            }
            crate::error::check_finite("z_guess", g)?;
            g.to_vec()
        }
        None => vec![0.0; n],
    };
    let plan = plan_for(system, opts)?;
    let lin = system.linear_part(omega)?;
    let mut ws = ResidualWorkspace::new();
    let outcome = match newton(system, &lin, plan.as_ref(), z0.clone(), opts, omega, &mut ws) {
        Ok(o) => o,
        Err(e @ JpError::NoConvergence { .. }) if opts.max_iterations > 1 => {
            load_stepping(system, &lin, plan.as_ref(), z0, opts, omega, &mut ws).map_err(|_| e)?
        }
        Err(e) => return Err(e),
    };
    finish_point(system, plan.as_ref(), omega, outcome, &mut ws)
}

/// Fallback when Newton fails from the given guess: a homotopy on the dynamic forcing,
/// `f_h -> lambda f_h` (`h >= 1`) for `lambda` from 0 to 1, each stage starting from the
/// previous solution. The step in `lambda` doubles after a success and halves after a
/// failure, down to 1/1024. Friction makes the residual nonsmooth, and a far guess can leave
/// the trust region stuck at a local minimum of `|r|`; near the stuck (linear) solution at
/// `lambda = 0` it cannot.
fn load_stepping(
    system: &dyn HarmonicSystem,
    lin: &LinearPart,
    plan: Option<&AftPlan>,
    z0: Vec<f64>,
    opts: &HbmOptions,
    omega: f64,
    ws: &mut ResidualWorkspace,
) -> Result<NewtonOutcome> {
    let scaled = |lambda: f64| {
        let mut l = lin.clone();
        for f in l.fh_cos.iter_mut().chain(l.fh_sin.iter_mut()) {
            f.iter_mut().for_each(|v| *v *= lambda);
        }
        l
    };
    let mut current = newton(system, &scaled(0.0), plan, z0, opts, omega, ws)?;
    let mut iterations = current.iterations;
    let (mut lambda, mut step) = (0.0f64, 0.25f64);
    while lambda < 1.0 {
        let next = (lambda + step).min(1.0);
        let stage = if next == 1.0 { lin.clone() } else { scaled(next) };
        match newton(system, &stage, plan, current.z.clone(), opts, omega, ws) {
            Ok(o) => {
                iterations += o.iterations;
                current = o;
                lambda = next;
                step = (2.0 * step).min(0.5);
            }
            Err(JpError::NoConvergence { iterations: it, .. }) => {
                iterations += it;
                step *= 0.5;
                if step < 1.0 / 1024.0 {
                    return Err(JpError::NoConvergence {
                        what: format!("HBM load stepping at omega = {omega}"),
                        iterations,
                        residual: f64::NAN,
                    });
                }
            }
            Err(e) => return Err(e),
        }
    }
    current.iterations = iterations;
    Ok(current)
}
