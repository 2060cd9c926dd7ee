//! One frequency point (docs/formulation.md §2): the HBM equations at fixed frequency solved by the
//! trust-region Newton method of [`super::newton`], from a guess or from zero, with load
//! stepping on the dynamic forcing as the fallback; and the small dense helpers the solvers
//! share (checked LU, reference force).

use super::newton::{self, Evaluation, NewtonSettings, NonlinearProblem, NotConverged};
use super::residual::{self, evaluate, evaluate_into, ResidualWorkspace};
use super::{HarmonicSystem, HbmOptions, LinearPart, PointSolution};
use crate::aft::AftPlan;
use crate::error::{JpError, Result};
use crate::linalg::{norm2, Matrix, MatrixLu};

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

/// The AFT plan of a system's discretisation (`None` without contacts).
pub(crate) fn plan_for(system: &dyn HarmonicSystem) -> Result<Option<AftPlan>> {
    if system.contact_laws().is_empty() {
        Ok(None)
    } else {
        system.discretisation().plan().map(Some)
    }
}

/// Result of a Newton solve at fixed frequency.
pub(crate) struct NewtonOutcome {
    pub z: Vec<f64>,
    pub iterations: usize,
    /// `|r| / f_ref`.
    pub residual: f64,
}

/// The HBM equations at one frequency as a [`NonlinearProblem`]: residual and Jacobian divided
/// by the reference force of the starting point.
struct PointProblem<'a> {
    system: &'a dyn HarmonicSystem,
    lin: &'a LinearPart,
    plan: Option<&'a AftPlan>,
    ws: &'a mut ResidualWorkspace,
    omega: f64,
    f_ref: Option<f64>,
}

impl NonlinearProblem for PointProblem<'_> {
    fn evaluate(&mut self, z: &[f64], want_jacobian: bool, out: &mut Evaluation) -> Result<()> {
        evaluate_into(self.system, self.lin, self.plan, z, want_jacobian, self.ws, &mut out.r, &mut out.jac)?;
        let f_ref = *self.f_ref.get_or_insert_with(|| reference_force(self.lin, self.ws.contact_force_norm(), norm2(&out.r)));
        if !f_ref.is_finite() {
            // every residual would read as zero against it
            return Err(JpError::invalid("the residual's reference force", "is not finite (the forces' squares overflow): scale the model's units"));
        }
        let s = 1.0 / f_ref;
        out.r.iter_mut().for_each(|v| *v *= s);
        if let (true, Some(j)) = (want_jacobian, out.jac.as_mut()) {
            j.scale(s);
        }
        Ok(())
    }
    fn what(&self) -> String {
        format!("HBM equations at omega = {}", self.omega)
    }
}

/// What every solve at one frequency shares: the system, its AFT plan, the options and the
/// frequency.
#[derive(Clone, Copy)]
pub(crate) struct AtFrequency<'a> {
    pub system: &'a dyn HarmonicSystem,
    pub plan: Option<&'a AftPlan>,
    pub opts: &'a HbmOptions,
    pub omega: f64,
}

/// Newton / dogleg trust region at fixed `lin` (one frequency) from `z0`, with at most
/// `max_iterations` Jacobian evaluations.
pub(crate) fn newton(
    at: AtFrequency<'_>,
    lin: &LinearPart,
    z0: Vec<f64>,
    max_iterations: usize,
    ws: &mut ResidualWorkspace,
) -> std::result::Result<NewtonOutcome, NotConverged> {
    let AtFrequency { system, plan, opts, omega } = at;
    let settings = NewtonSettings {
        tolerance: opts.residual_tolerance,
        step_tolerance: opts.step_tolerance,
        max_iterations,
        trust_region: opts.trust_region,
        initial_radius_factor: opts.initial_radius_factor,
        scaling: opts.scaling,
    };
    let mut problem = PointProblem { system, lin, plan, ws, omega, f_ref: None };
    let c = newton::solve(&mut problem, z0, &settings)?;
    Ok(NewtonOutcome { residual: norm2(&c.residual), z: c.x, iterations: c.iterations })
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
    super::options::check_omega(omega)?;
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
    let plan = plan_for(system)?;
    let lin = system.linear_part(omega)?;
    let mut ws = ResidualWorkspace::new();
    let outcome = solve_with_fallback(AtFrequency { system, plan: plan.as_ref(), opts, omega }, &lin, z0, z_guess.is_none(), &mut ws)?;
    finish_point(system, plan.as_ref(), omega, outcome, &mut ws)
}

/// Newton from `z0`; if it does not converge and `z0` is a cold start (zero), Newton from the
/// linear limit (the closed contacts stuck, [`linear_limit_start`]); then load stepping (see
/// [`load_stepping`]) from that start with half of the rest, then continuation in the level
/// (see [`level_continuation`]); all attempts together use at most `opts.max_iterations`
/// Jacobian evaluations, and the outcome reports them all. The first attempt gets a quarter of
/// the budget (a point that converges at all usually does so in a few iterations), the linear
/// limit's another.
pub(crate) fn solve_with_fallback(at: AtFrequency<'_>, lin: &LinearPart, z0: Vec<f64>, cold: bool, ws: &mut ResidualWorkspace) -> Result<NewtonOutcome> {
    let opts = at.opts;
    let budget = opts.max_iterations;
    let first = (budget / 4).max(1);
    match newton(at, lin, z0.clone(), first, ws) {
        Ok(o) => Ok(o),
        Err(NotConverged { iterations, error: e @ JpError::NoConvergence { .. }, .. }) if budget > iterations + 1 => {
            let mut iterations = iterations;
            let mut z0 = z0;
            if cold {
                if let Ok(Some(z_lin)) = linear_limit_start(at, lin, ws) {
                    match newton(at, lin, z_lin, first.min(budget - iterations), ws) {
                        Ok(mut o) => {
                            o.iterations += iterations;
                            return Ok(o);
                        }
                        Err(f) if matches!(f.error, JpError::NoConvergence { .. }) => iterations += f.iterations,
                        Err(f) => return Err(f.error),
                    }
                    // the homotopy in the level starts from the static linear limit
                    if let Ok(Some(z_static)) = linear_limit_start(at, &lin.with_harmonic_forces_scaled(0.0), ws) {
                        z0 = z_static;
                    }
                }
                if budget <= iterations + 1 {
                    return Err(e);
                }
            }
            // load stepping gets half of what is left; if it stops at a fold in the level (the
            // response at this frequency has several branches), the arclength continuation in
            // the level follows the branch round it with the rest
            let left = budget - iterations;
            let share = (left / 2).max(1);
            let staged = match load_stepping(at, lin, z0.clone(), share, ws) {
                Err(JpError::NoConvergence { iterations: it2, .. }) if left > it2 + 1 => {
                    level_continuation(at, lin, z0, left - it2, ws).map(|mut o| {
                        o.iterations += it2;
                        o
                    }).map_err(|e| match e {
                        JpError::NoConvergence { iterations: it3, residual, tolerance, .. } => JpError::NoConvergence { what: String::new(), iterations: it2 + it3, residual, tolerance },
                        other => other,
                    })
                }
                other => other,
            };
            staged.map(|mut o| {
                o.iterations += iterations;
                o
            }).map_err(|ls| match ls {
                // report the first attempt's residual, and all iterations spent
                JpError::NoConvergence { iterations: it2, .. } => match e {
                    JpError::NoConvergence { what, residual, tolerance, .. } => JpError::NoConvergence {
                        what: format!("{what}, then {}load stepping and continuation in the forcing level", if cold { "from the linear limit, " } else { "" }),
                        iterations: iterations + it2,
                        residual,
                        tolerance,
                    },
                    other => other,
                },
                other => other,
            })
        }
        Err(NotConverged { error, .. }) => Err(error),
    }
}

/// The linear limit at `lin`: one Newton step from zero with the Jacobian in which every
/// contact closed at zero displacement is its stuck spring
/// ([`super::residual::linear_limit_at_zero`]); `None` where that is the step Newton from zero
/// took.
///
/// # Errors
/// A singular Jacobian, or the evaluation's errors.
fn linear_limit_start(at: AtFrequency<'_>, lin: &LinearPart, ws: &mut ResidualWorkspace) -> Result<Option<Vec<f64>>> {
    let Some((r, j)) = residual::linear_limit_at_zero(at.system, lin, at.plan, ws)? else { return Ok(None) };
    let mut lu = crate::linalg::MatrixLu::new(&j, "the linear limit's Jacobian")?;
    let mut z = lu.solve(&r);
    z.iter_mut().for_each(|v| *v = -*v);
    crate::error::check_finite("the linear limit", &z)?;
    Ok(Some(z))
}

/// Most Newton iterations of one load-stepping stage: a stage that needs more is better cut in
/// half (a good stage converges in a few).
const LOAD_STAGE_ITERATIONS: usize = 50;

/// Fallback when Newton fails from the given guess: a homotopy on the dynamic forcing,
/// `f_h -> lambda f_h` (`h >= 1`) for `lambda` from 0 to 1, each stage starting from the
/// previous solution. The step in `lambda` doubles after a success and halves after a
/// failure (a stage that does not converge in [`LOAD_STAGE_ITERATIONS`]), down to 1/1024,
/// within `budget` Jacobian evaluations in all. Friction makes the
/// residual nonsmooth, and a far guess can leave the trust region stuck at a local minimum of
/// `|r|`; near the stuck (linear) solution at `lambda = 0` it cannot.
///
/// # Errors
/// [`JpError::NoConvergence`] with the iterations spent when the budget runs out or the step in
/// `lambda` falls below 1/1024; a singular Jacobian's error.
fn load_stepping(at: AtFrequency<'_>, lin: &LinearPart, z0: Vec<f64>, budget: usize, ws: &mut ResidualWorkspace) -> Result<NewtonOutcome> {
    let omega = at.omega;
    let no_convergence = |iterations: usize, residual: f64| JpError::NoConvergence {
        what: format!("HBM load stepping at omega = {omega}"),
        iterations,
        residual,
        tolerance: at.opts.residual_tolerance,
    };
    let mut used = 0;
    let mut current = match newton(at, &lin.with_harmonic_forces_scaled(0.0), z0, budget, ws) {
        Ok(o) => o,
        Err(f) => return Err(if matches!(f.error, JpError::NoConvergence { .. }) { no_convergence(f.iterations, f.residual_norm) } else { f.error }),
    };
    used += current.iterations;
    let (mut lambda, mut step) = (0.0f64, 0.25f64);
    while lambda < 1.0 {
        if used >= budget {
            return Err(no_convergence(used, f64::NAN));
        }
        let next = (lambda + step).min(1.0);
        let stage = if next == 1.0 { lin.clone() } else { lin.with_harmonic_forces_scaled(next) };
        match newton(at, &stage, current.z.clone(), (budget - used).min(LOAD_STAGE_ITERATIONS), ws) {
            Ok(o) => {
                used += o.iterations;
                current = o;
                lambda = next;
                step = (2.0 * step).min(0.5);
            }
            Err(NotConverged { iterations: it, residual_norm, error: JpError::NoConvergence { .. } }) => {
                used += it.max(1);
                step *= 0.5;
                if step < 1.0 / 1024.0 {
                    return Err(no_convergence(used, residual_norm));
                }
            }
            Err(f) => return Err(f.error),
        }
    }
    current.iterations = used;
    Ok(current)
}

/// The HBM equations with the dynamic forcing scaled by `lambda`, `y = (z, lambda)`, bordered
/// by the arclength constraint `(S t)^T (y - y_p) / ds = 0` (`S = diag(1 / z_ref^2, 1)`).
struct LevelProblem<'a> {
    system: &'a dyn HarmonicSystem,
    /// The linear part at `lambda = 0` (static force only).
    lin0: &'a LinearPart,
    plan: Option<&'a AftPlan>,
    ws: &'a mut ResidualWorkspace,
    /// `f_dyn / f_ref`: `R(z, lambda) = R(z, 0) - lambda f_dyn`.
    g: &'a [f64],
    f_ref: f64,
    /// `S t` and the predictor; `None` while computing the residual alone.
    constraint: Option<(Vec<f64>, Vec<f64>)>,
    ds: f64,
    omega: f64,
}

impl LevelProblem<'_> {
    /// `R(z, lambda) / f_ref` and `[J_z  -f_dyn] / f_ref` (as `J_z / f_ref` and its last column).
    fn top(&mut self, y: &[f64], want_jacobian: bool) -> Result<(Vec<f64>, Option<(Matrix, Vec<f64>)>)> {
        let n = y.len() - 1;
        let (mut r, jz) = evaluate(self.system, self.lin0, self.plan, &y[..n], want_jacobian, self.ws)?;
        let s = 1.0 / self.f_ref;
        for (i, v) in r.iter_mut().enumerate() {
            *v = *v * s - y[n] * self.g[i];
        }
        Ok((
            r,
            jz.map(|mut jz| {
                jz.scale(s);
                (jz, self.g.iter().map(|g| -g).collect())
            }),
        ))
    }
}

impl NonlinearProblem for LevelProblem<'_> {
    fn evaluate(&mut self, y: &[f64], want_jacobian: bool, out: &mut Evaluation) -> Result<()> {
        let n = y.len() - 1;
        let (mut r, top) = self.top(y, want_jacobian)?;
        let (st, yp) = self.constraint.as_ref().expect("a constraint is set before solving");
        r.push((0..=n).map(|i| st[i] * (y[i] - yp[i])).sum::<f64>() / self.ds);
        let row: Vec<f64> = st.iter().map(|v| v / self.ds).collect();
        out.jac = top.map(|(jz, col)| jz.bordered(&col, &row)).transpose()?;
        out.r = r;
        Ok(())
    }
    fn what(&self) -> String {
        format!("continuation in the forcing level at omega = {}", self.omega)
    }
}

/// Fallback when load stepping stops at a fold in the forcing level (at a frequency where the
/// response has several branches, the branch that starts from the static solution can turn
/// back in the level before reaching it): pseudo-arclength continuation of `R(z, lambda) = 0`
/// in `(z, lambda)` from the `lambda = 0` solution, tangent oriented along the previous one,
/// corrected points kept only ahead of the last one, until `lambda` passes 1; then Newton at
/// `lambda = 1` from the interpolated point. At most `budget` Jacobian evaluations in all.
///
/// # Errors
/// [`JpError::NoConvergence`] with the iterations spent when the budget runs out, the step
/// falls below `1e-6` or the branch runs back below `lambda = -1`; a singular system's error.
fn level_continuation(at: AtFrequency<'_>, lin: &LinearPart, z0: Vec<f64>, budget: usize, ws: &mut ResidualWorkspace) -> Result<NewtonOutcome> {
    let AtFrequency { system, plan, opts, omega } = at;
    let no_convergence = |iterations: usize, residual: f64| JpError::NoConvergence {
        what: format!("HBM continuation in the forcing level at omega = {omega}"),
        iterations,
        residual,
        tolerance: opts.residual_tolerance,
    };
    let lin0 = lin.with_harmonic_forces_scaled(0.0);
    let start = newton(at, &lin0, z0, budget, ws).map_err(|f| match f.error {
        JpError::NoConvergence { .. } => no_convergence(f.iterations, f.residual_norm),
        e => e,
    })?;
    let mut used = start.iterations.max(1);
    let layout = system.layout();
    let f_ref = reference_force(lin, 0.0, 1.0);
    // f_dyn = R(z, 0) - R(z, 1) for the linear part (the contact forces cancel)
    let (r0, r1) = (super::residual::linear_residual(layout, &lin0, &start.z), super::residual::linear_residual(layout, lin, &start.z));
    let g: Vec<f64> = r0.iter().zip(&r1).map(|(a, b)| (a - b) / f_ref).collect();
    let n = start.z.len();
    let mut y: Vec<f64> = start.z.iter().copied().chain([0.0]).collect();
    let mut problem = LevelProblem { system, lin0: &lin0, plan, ws, g: &g, f_ref, constraint: None, ds: 1.0, omega };
    let mut t_prev = vec![0.0; n + 1];
    t_prev[n] = 1.0;
    let mut sz: Option<f64> = None;
    let mut sigma: Option<f64> = None;
    let mut ds = 0.1;
    // the residual of the last corrector that failed (the last point's, converged, before any)
    let mut last_residual = start.residual;
    let settings = NewtonSettings {
        tolerance: opts.residual_tolerance,
        step_tolerance: opts.step_tolerance,
        max_iterations: 12,
        trust_region: true,
        initial_radius_factor: 1.0,
        scaling: opts.scaling,
    };
    while used < budget {
        // tangent: [J_z  -g; (S t_prev)^T] t = [0; 1]
        let (_, top) = problem.top(&y, true)?;
        used += 1;
        let (jz, col) = top.expect("jacobian requested");
        let weights = |sz: f64| (0..=n).map(|i| if i < n { sz } else { 1.0 }).collect::<Vec<f64>>();
        let w = weights(sz.unwrap_or(1.0));
        let row: Vec<f64> = (0..=n).map(|j| w[j] * t_prev[j]).collect();
        let b = jz.bordered(&col, &row)?;
        let mut rhs = vec![0.0; n + 1];
        rhs[n] = 1.0;
        let mut lu = MatrixLu::new(&b, &format!("level continuation tangent at omega = {omega}"))?;
        let t_raw = lu.solve(&rhs);
        // t_raw^T S t_prev = 1, so sign det [J_z -g; (S t_raw)^T] = sign det b
        let sign = lu.determinant_sign();
        // z scaled by |dz/dlambda| at the start: a unit of arclength first moves lambda by ~1
        let sz = *sz.get_or_insert_with(|| {
            let dz = norm2(&t_raw[..n]) / t_raw[n].abs().max(1e-300);
            if dz.is_finite() && dz > 0.0 { 1.0 / (dz * dz) } else { 1.0 }
        });
        let w = weights(sz);
        let len = (0..=n).map(|i| w[i] * t_raw[i] * t_raw[i]).sum::<f64>().sqrt();
        if !(len.is_finite() && len > 0.0) {
            return Err(JpError::singular(format!("level continuation tangent at omega = {omega}")));
        }
        let mut t: Vec<f64> = t_raw.iter().map(|v| v / len).collect();
        // oriented as the first tangent was (towards lambda > 0) by the determinant's sign,
        // which keeps through folds and corners where a contact changes state (§6.1); by the
        // last tangent where the factorisation has no sign (sparse)
        let sigma = *sigma.get_or_insert(sign.unwrap_or(1.0));
        if sign.is_some_and(|s| s != sigma) {
            t.iter_mut().for_each(|v| *v = -*v);
        }
        let st: Vec<f64> = (0..=n).map(|i| w[i] * t[i]).collect();
        loop {
            if ds < 1e-6 || used >= budget {
                return Err(no_convergence(used.min(budget), last_residual));
            }
            let yp: Vec<f64> = (0..=n).map(|i| y[i] + ds * t[i]).collect();
            problem.constraint = Some((st.clone(), yp.clone()));
            problem.ds = ds;
            let s = NewtonSettings { max_iterations: settings.max_iterations.min(budget - used), ..settings };
            match super::newton::solve(&mut problem, yp, &s) {
                Ok(c) if (0..=n).map(|i| st[i] * (c.x[i] - y[i])).sum::<f64>() > 0.0 => {
                    used += c.iterations.max(1);
                    let y_new = c.x;
                    if y_new[n] >= 1.0 {
                        // Newton at lambda = 1 from the point interpolated there
                        let a = (1.0 - y[n]) / (y_new[n] - y[n]);
                        let guess: Vec<f64> = (0..n).map(|i| y[i] + a * (y_new[i] - y[i])).collect();
                        let left = budget.saturating_sub(used);
                        if left == 0 {
                            return Err(no_convergence(used, last_residual));
                        }
                        // from a step that crossed lambda = 1 far away (a contact changed
                        // state between), a shorter step that ends before it, and again
                        let far = a * ds > 1e-6 && left > 4 * settings.max_iterations;
                        let tries = if far { 4 * settings.max_iterations } else { left };
                        match newton(at, lin, guess, tries, problem.ws) {
                            Ok(mut o) => {
                                o.iterations += used;
                                return Ok(o);
                            }
                            Err(f) if far && matches!(f.error, JpError::NoConvergence { .. }) => {
                                used += f.iterations.max(1);
                                last_residual = f.residual_norm;
                                ds *= 0.5 * a;
                                continue;
                            }
                            Err(f) => {
                                return Err(match f.error {
                                    JpError::NoConvergence { .. } => no_convergence(used + f.iterations, f.residual_norm),
                                    e => e,
                                })
                            }
                        }
                    }
                    if y_new[n] < -1.0 {
                        return Err(no_convergence(used, c.residual.iter().map(|v| v * v).sum::<f64>().sqrt()));
                    }
                    if c.iterations <= 4 {
                        ds = (1.5 * ds).min(0.5);
                    }
                    y = y_new;
                    t_prev = t;
                    break;
                }
                Ok(c) => {
                    used += c.iterations.max(1);
                    ds *= 0.5;
                }
                Err(f) => {
                    used += f.iterations.max(1);
                    last_residual = f.residual_norm;
                    ds *= 0.5;
                }
            }
        }
    }
    Err(no_convergence(used.min(budget), last_residual))
}
