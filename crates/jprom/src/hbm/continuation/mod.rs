//! Pseudo-arclength continuation of HBM solutions over a frequency band
//! (docs/formulation.md §6).
//!
//! Unknowns `y = (z, omega)`; arclength is measured in the scaled metric
//! `|dy|_S^2 = |dz|^2 / z_ref^2 + domega^2 / span^2` (see [`SweepOptions`]). Two methods share
//! the corrector and the tangent of this module ([`SweepOptions::method`]):
//!
//! * [`oriented`] (the default): the tangent at each point is the null vector of
//!   `[J_z  R_omega]`, oriented so that `det [J_z R_omega; (S t)^T]` keeps the sign it had at
//!   the first point. That sign is constant along a regular branch, through smooth folds and
//!   through the corners where a contact changes state, so the sweep cannot turn back onto
//!   the branch it traced; it changes at a branch point. A corrected point is taken when it
//!   lies ahead along the tangents at both ends of its chord; steps are sized by the
//!   corrector's iterations and the tangents' turn; a corner is crossed along the tangent of
//!   the next piece; where no step converges the sweep steps over the place at fixed
//!   frequency and marks a gap. Folds and branch points are located and reported.
//! * [`legacy`]: the secant continuation of the first releases, kept for comparison.
//!
//! Shared: the bordered corrector `[R(z, omega); g(y) / ds] = 0` (hyperplane or sphere
//! constraint) solved by the trust-region Newton method of [`super::newton`], and
//! `dR/domega` in closed form where the system gives it
//! ([`HarmonicSystem::linear_part_with_derivative_into`]), else by a central difference of
//! [`HarmonicSystem::linear_part`]; contact forces do not depend on `omega`
//! (rate-independent friction).

mod legacy;
mod oriented;

use super::newton::{self, Evaluation, NewtonSettings, NonlinearProblem};
use super::residual::{evaluate_into, linear_residual_into, ResidualWorkspace};
use super::solve::reference_force;
use super::{ContinuationMethod, HarmonicSystem, HbmOptions, LinearPart, PointSolution, SweepOptions, SweepResult};
use crate::aft::AftPlan;
use crate::error::{JpError, Result};
use crate::linalg::{norm2, Matrix, MatrixLu};
use std::ops::ControlFlow;

/// Tolerance on the arclength constraint, relative to the step.
const CONSTRAINT_TOLERANCE: f64 = 1e-8;

/// `dR/domega` at `(z, omega)` by a central difference of the linear part with step `delta`
/// (the contact forces do not depend on `omega`).
///
/// # Errors
/// Those of [`HarmonicSystem::linear_part`].
pub fn residual_omega_derivative(system: &dyn HarmonicSystem, omega: f64, z: &[f64], delta: f64) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    OmegaDerivative::default().evaluate(system, omega, z, delta, &mut out)?;
    Ok(out)
}

/// The buffers of [`residual_omega_derivative`]: the linear parts at `omega +- delta` and
/// their residuals, kept across the corrector's iterations.
#[derive(Default)]
struct OmegaDerivative {
    plus: Option<LinearPart>,
    minus: Option<LinearPart>,
    r_plus: Vec<f64>,
    r_minus: Vec<f64>,
}

impl OmegaDerivative {
    /// [`residual_omega_derivative`] into `out`.
    fn evaluate(&mut self, system: &dyn HarmonicSystem, omega: f64, z: &[f64], delta: f64, out: &mut Vec<f64>) -> Result<()> {
        let layout = system.layout();
        system.linear_part_into(omega + delta, &mut self.plus)?;
        system.linear_part_into(omega - delta, &mut self.minus)?;
        linear_residual_into(layout, self.plus.as_ref().expect("set above"), z, &mut self.r_plus);
        linear_residual_into(layout, self.minus.as_ref().expect("set above"), z, &mut self.r_minus);
        out.clear();
        out.extend(self.r_plus.iter().zip(&self.r_minus).map(|(a, b)| (a - b) / (2.0 * delta)));
        Ok(())
    }
}

/// Metric weights: `|dz|^2 sz + domega^2 sw`.
#[derive(Clone, Copy, Debug)]
struct Metric {
    sz: f64,
    sw: f64,
}

impl Metric {
    fn dot(&self, a: &[f64], b: &[f64]) -> f64 {
        let n = a.len() - 1;
        self.sz * (0..n).map(|i| a[i] * b[i]).sum::<f64>() + self.sw * a[n] * b[n]
    }
    /// `S v`.
    fn apply(&self, v: &[f64]) -> Vec<f64> {
        let n = v.len() - 1;
        v.iter().enumerate().map(|(i, x)| if i < n { self.sz * x } else { self.sw * x }).collect()
    }
    /// `|a - b|_S`.
    fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
        self.dot(&d, &d).sqrt()
    }
    fn unit(&self, v: &[f64]) -> Option<Vec<f64>> {
        let len = self.dot(v, v).sqrt();
        (len.is_finite() && len > 0.0).then(|| v.iter().map(|x| x / len).collect())
    }
}

/// `[J_z  R_omega]` at a point (rows divided by the reference force, which changes neither the
/// tangent nor the corrector's Newton step): `J_z` in the system's storage and the column
/// `R_omega`.
struct Linearisation {
    jz: Matrix,
    r_omega: Vec<f64>,
}

impl Linearisation {
    /// `[J_z  R_omega; row^T]`.
    fn bordered(&self, row: &[f64]) -> Result<Matrix> {
        self.jz.bordered(&self.r_omega, row)
    }
}

/// Unit tangent (in the metric) of the branch whose linearisation is `lz`, oriented so that
/// `orient^T S t > 0`.
fn tangent(lz: &Linearisation, orient: &[f64], m: Metric, omega: f64) -> Result<Vec<f64>> {
    let n = lz.jz.nrows();
    let b = lz.bordered(&m.apply(orient))?;
    let mut lu = MatrixLu::new(&b, &format!("continuation tangent system at omega = {omega}"))?;
    let mut rhs = vec![0.0; n + 1];
    rhs[n] = 1.0;
    m.unit(&lu.solve(&rhs)).ok_or_else(|| JpError::singular(format!("continuation tangent at omega = {omega}")))
}

/// The arclength constraint of the corrector.
#[derive(Clone, Copy)]
enum Constraint<'a> {
    /// `t^T S (y - y_p) = 0`.
    Hyperplane { t: &'a [f64], y_pred: &'a [f64] },
    /// `|y - y_c|_S^2 = ds^2`.
    Sphere { centre: &'a [f64] },
}

/// The bordered system `[R(z, omega); g(y) / ds]` of the corrector.
struct Corrector<'a> {
    system: &'a dyn HarmonicSystem,
    plan: Option<&'a AftPlan>,
    sopts: &'a SweepOptions,
    ws: &'a mut ResidualWorkspace,
    metric: Metric,
    constraint: Constraint<'a>,
    ds: f64,
    f_ref: Option<f64>,
    buf: CorrectorBuffers,
}

/// What the corrector's evaluations refill in place (the Newton solver keeps the evaluations
/// themselves): its iterations allocate nothing when the system refills its linear part in
/// place (the full-order system does).
#[derive(Default)]
struct CorrectorBuffers {
    lin: Option<LinearPart>,
    /// `dD/domega`, `df/domega` where the system has them in closed form
    lin_derivative: Option<LinearPart>,
    jz: Option<Matrix>,
    r_omega: Vec<f64>,
    omega_derivative: OmegaDerivative,
    /// the constraint's row of the bordered Jacobian
    row: Vec<f64>,
}

impl<'a> Corrector<'a> {
    fn new(
        system: &'a dyn HarmonicSystem,
        plan: Option<&'a AftPlan>,
        sopts: &'a SweepOptions,
        ws: &'a mut ResidualWorkspace,
        metric: Metric,
        constraint: Constraint<'a>,
        ds: f64,
    ) -> Self {
        Corrector { system, plan, sopts, ws, metric, constraint, ds, f_ref: None, buf: CorrectorBuffers::default() }
    }

    /// `R / f_ref` into `r` and, when asked, `[J_z  R_omega] / f_ref` into `self.buf` (`f_ref`
    /// fixed at the first call).
    fn linearise_into(&mut self, y: &[f64], want_jacobian: bool, r: &mut Vec<f64>) -> Result<()> {
        let n = y.len() - 1;
        let omega = y[n];
        if !(omega.is_finite() && omega > 0.0) {
            return Err(JpError::invalid("continuation", format!("corrector left omega > 0 ({omega})")));
        }
        let CorrectorBuffers { lin, lin_derivative, jz, r_omega, omega_derivative, .. } = &mut self.buf;
        // dR/domega in closed form where the system has it, else by a central difference below
        let closed_form = if want_jacobian { self.system.linear_part_with_derivative_into(omega, lin, lin_derivative)? } else {
            self.system.linear_part_into(omega, lin)?;
            false
        };
        let lin = lin.as_ref().expect("set above");
        evaluate_into(self.system, lin, self.plan, &y[..n], want_jacobian, self.ws, r, jz)?;
        let f_ref = *self.f_ref.get_or_insert_with(|| reference_force(lin, self.ws.contact_force_norm(), norm2(r)));
        let s = 1.0 / f_ref;
        r.iter_mut().for_each(|v| *v *= s);
        if !norm2(r).is_finite() {
            return Err(JpError::invalid("continuation", "non-finite residual in the corrector"));
        }
        if want_jacobian {
            match lin_derivative.as_ref().filter(|_| closed_form) {
                Some(d) => linear_residual_into(self.system.layout(), d, &y[..n], r_omega),
                None => omega_derivative.evaluate(self.system, omega, &y[..n], self.sopts.omega_difference * omega, r_omega)?,
            }
            jz.as_mut().expect("jacobian requested").scale(s);
            r_omega.iter_mut().for_each(|v| *v *= s);
        }
        Ok(())
    }

    /// `R / f_ref` and `[J_z  R_omega] / f_ref` at `y` (`f_ref` fixed at the first call).
    fn linearise(&mut self, y: &[f64], want_jacobian: bool) -> Result<(Vec<f64>, Option<Linearisation>)> {
        let mut r = Vec::new();
        self.linearise_into(y, want_jacobian, &mut r)?;
        let top = want_jacobian.then(|| Linearisation { jz: self.buf.jz.take().expect("jacobian requested"), r_omega: std::mem::take(&mut self.buf.r_omega) });
        Ok((r, top))
    }
}

impl NonlinearProblem for Corrector<'_> {
    fn evaluate(&mut self, y: &[f64], want_jacobian: bool, out: &mut Evaluation) -> Result<()> {
        let n = y.len() - 1;
        self.linearise_into(y, want_jacobian, &mut out.r)?;
        let m = self.metric;
        let weight = |i: usize| if i < n { m.sz } else { m.sw };
        let row = &mut self.buf.row;
        row.clear();
        let g = match self.constraint {
            Constraint::Hyperplane { t, y_pred } => {
                row.extend((0..=n).map(|i| weight(i) * t[i]));
                (0..=n).map(|i| row[i] * (y[i] - y_pred[i])).sum::<f64>()
            }
            Constraint::Sphere { centre } => {
                row.extend((0..=n).map(|i| y[i] - centre[i]));
                let g = m.dot(row, row) - self.ds * self.ds;
                for (i, v) in row.iter_mut().enumerate() {
                    *v = 2.0 * (weight(i) * *v);
                }
                g
            }
        };
        out.r.push(g / self.ds);
        row.iter_mut().for_each(|v| *v /= self.ds);
        if want_jacobian {
            let jz = self.buf.jz.as_ref().expect("jacobian requested");
            jz.bordered_into(&self.buf.r_omega, &self.buf.row, &mut out.jac)?;
        }
        Ok(())
    }
    fn converged(&self, r: &[f64], tolerance: f64) -> bool {
        let n = r.len() - 1;
        norm2(&r[..n]) <= tolerance && r[n].abs() <= CONSTRAINT_TOLERANCE
    }
    fn what(&self) -> String {
        "continuation corrector".into()
    }
}

/// A converged corrector: the point, the iterations used, the residual `|R| / f_ref` and the
/// bordered Jacobian evaluated there (its last row the corrector's constraint).
struct Corrected {
    y: Vec<f64>,
    iterations: usize,
    residual: f64,
    jacobian: Option<Matrix>,
}

#[allow(clippy::too_many_arguments)]
fn correct(
    system: &dyn HarmonicSystem,
    plan: Option<&AftPlan>,
    y0: &[f64],
    constraint: Constraint<'_>,
    ds: f64,
    m: Metric,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    ws: &mut ResidualWorkspace,
) -> Result<Corrected> {
    let omega = y0[y0.len() - 1];
    let mut problem = Corrector::new(system, plan, sopts, ws, m, constraint, ds);
    let settings = NewtonSettings {
        tolerance: hopts.residual_tolerance,
        step_tolerance: hopts.step_tolerance,
        // a point's budget bounds the corrector too
        max_iterations: sopts.max_corrector_iterations.min(hopts.max_iterations),
        trust_region: true,
        initial_radius_factor: 1.0,
        scaling: hopts.scaling,
    };
    match newton::solve(&mut problem, y0.to_vec(), &settings) {
        Ok(c) => {
            let n = c.x.len() - 1;
            Ok(Corrected { residual: norm2(&c.residual[..n]), y: c.x, iterations: c.iterations, jacobian: c.jacobian })
        }
        Err(f) => Err(match f.error {
            JpError::NoConvergence { iterations, residual, tolerance, .. } => JpError::NoConvergence {
                what: format!("continuation corrector near omega = {omega}"),
                iterations,
                residual,
                tolerance,
            },
            other => other,
        }),
    }
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
/// point then); a failed external law ([`JpError::Callback`]) wherever it happens (the points
/// before it went to `on_point`). Other later failures end the sweep with a reason
/// ([`SweepResult::end`], [`SweepResult::failure`]), keeping the points found.
pub fn sweep(
    system: &dyn HarmonicSystem,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    on_point: &mut dyn FnMut(&PointSolution) -> ControlFlow<()>,
) -> Result<SweepResult> {
    sweep_from(system, sopts, hopts, None, on_point)
}

/// [`sweep`] whose first point at `sopts.omega_start` is solved from the guess `start` (for
/// example the `z` of a converged solution at that frequency, to restart a sweep or to follow
/// another branch) instead of from zero.
///
/// # Errors
/// As [`sweep`]; [`JpError::BadSize`] if `start` does not fit the system.
pub fn sweep_from(
    system: &dyn HarmonicSystem,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    start: Option<&[f64]>,
    on_point: &mut dyn FnMut(&PointSolution) -> ControlFlow<()>,
) -> Result<SweepResult> {
    match sopts.method {
        ContinuationMethod::Oriented => oriented::sweep_from(system, sopts, hopts, start, on_point),
        ContinuationMethod::Secant => legacy::sweep_from(system, sopts, hopts, start, on_point),
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::hbm::solve::plan_for;
    use crate::allocation_count::on_this_thread;
    use crate::contact::Contact;
    use crate::hbm::{FullSystem, Storage};
    use crate::model::{Damping, Excitation, HarmonicForce, Model};
    use faer::Mat;

    /// A chain of `n` unit masses with a Jenkins element each to ground (slip force 0.05), the
    /// last mass driven.
    fn chain(n: usize) -> Model {
        let mut k = Mat::<f64>::zeros(n, n);
        k[(0, 0)] += 1.0;
        for i in 0..n - 1 {
            k[(i, i)] += 1.0;
            k[(i + 1, i + 1)] += 1.0;
            k[(i, i + 1)] -= 1.0;
            k[(i + 1, i)] -= 1.0;
        }
        let mut f1 = vec![0.0; n];
        f1[n - 1] = 0.1;
        let exc = Excitation { static_force: vec![0.0; n], harmonics: vec![HarmonicForce { cos: f1, sin: vec![0.0; n] }], dynamic_scale: 1.0 };
        let contacts = (0..n).map(|i| Contact::jenkins(i, None, 0.5, 0.05, 1.0)).collect();
        Model::new(Mat::identity(n, n), k, Damping { mass_coeff: 0.0, stiffness_coeff: 0.01 }, exc, contacts, vec![n - 1]).unwrap()
    }

    /// The corrector's evaluations (linear part, residual, Jacobian, `dR/domega`, bordered
    /// system) and the refactorisation of the bordered Jacobian allocate nothing once their
    /// buffers exist (issue 18), sparse and dense; and they equal a fresh evaluation's.
    #[test]
    fn corrector_iterations_reuse_their_buffers() {
        for (n, storage) in [(200, Storage::Sparse), (12, Storage::Dense)] {
            let hopts = HbmOptions::default();
            let system = FullSystem::with_storage(&chain(n), 3, storage).unwrap();
            let sopts = SweepOptions::band(0.5, 1.0);
            let plan = plan_for(&system).unwrap();
            let point = crate::hbm::solve_point(&system, 0.75, None, &hopts).unwrap();
            let y0: Vec<f64> = point.z.iter().copied().chain([0.75]).collect();
            let t: Vec<f64> = (0..y0.len()).map(|i| if i + 1 == y0.len() { 1.0 } else { 1e-3 * y0[i] }).collect();
            let metric = Metric { sz: 1.0, sw: 1.0 };
            let mut ws = ResidualWorkspace::new();
            let mut c = Corrector::new(&system, plan.as_ref(), &sopts, &mut ws, metric, Constraint::Hyperplane { t: &t, y_pred: &y0 }, 0.01);
            let mut ev = Evaluation::default();
            let mut lu = MatrixLu::empty();
            let y1: Vec<f64> = y0.iter().enumerate().map(|(i, v)| v * (1.0 + 1e-3 * (i % 7) as f64)).collect();
            c.evaluate(&y0, true, &mut ev).unwrap();
            lu.factor(ev.jac.as_ref().unwrap(), || "bordered".into()).unwrap();
            let mut dz = vec![0.0; y0.len()];
            // ten iterations: rayon's job queue (the AFT over 200 contacts and faer's sparse LU
            // hand it work) allocates one block per 63 jobs pushed from outside its pool, from
            // whichever thread pushes; a buffer rebuilt per iteration would show ten times
            let before = on_this_thread();
            for _ in 0..10 {
                c.evaluate(&y1, true, &mut ev).unwrap();
                lu.factor(ev.jac.as_ref().unwrap(), || "bordered".into()).unwrap();
                lu.solve_into(&ev.r, &mut dz);
            }
            let allocations = on_this_thread() - before;
            assert!(allocations <= 2, "{storage:?}: ten corrector iterations allocated {allocations} times");
            // the refilled evaluation equals a fresh corrector's
            let mut fresh = Evaluation::default();
            let mut ws2 = ResidualWorkspace::new();
            let mut c2 = Corrector::new(&system, plan.as_ref(), &sopts, &mut ws2, metric, Constraint::Hyperplane { t: &t, y_pred: &y0 }, 0.01);
            c2.f_ref = c.f_ref;
            c2.evaluate(&y1, true, &mut fresh).unwrap();
            assert_eq!(ev.r, fresh.r);
            assert_eq!(ev.jac.as_ref().unwrap().to_dense(), fresh.jac.as_ref().unwrap().to_dense());
            assert_eq!(ev.jac.as_ref().unwrap().is_sparse(), storage == Storage::Sparse);
        }
    }
}
