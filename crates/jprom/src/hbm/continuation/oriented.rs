//! The oriented pseudo-arclength continuation ([`ContinuationMethod::Oriented`],
//! docs/formulation.md §6): its decisions rest on two invariants of a branch, not on angles
//! fitted to a model.
//!
//! * **Orientation.** The tangent `t` at a point is the null vector of `[J_z  R_omega]`, signed
//!   so that `sign det [J_z R_omega; (S t)^T] = sigma`, the sign it had at the first point
//!   (tangent towards `omega_end`). Along a regular branch that sign does not change: not
//!   through a smooth fold (where `det J_z` and `t_omega` change sign together), and not
//!   across a corner where a contact changes state (the piecewise-linear continuation
//!   argument: the two pieces' Jacobians agree on the corner's face). So the direction of
//!   travel is defined at every point, whatever the angle between the pieces.
//! * **Acceptance.** A corrected point `y*` with chord `c = y* - y_k` is ahead of `y_k` when
//!   `c^T S (t_k + t*) > 0`: on a smooth piece `c` is along both tangents; across one corner
//!   of turn `theta < pi`, `c = a t_k + b t*` with `a, b > 0` gives `(a + b)(1 + cos theta)`;
//!   a point behind (on the part already traced) gives the opposite sign. So the branch is
//!   never retraced, and a corner is taken at any angle. A corrected point farther than
//!   `2 ds` from `y_k` has left the step's neighbourhood and is refused.
//! * **Branch points.** Where `det` changes sign on a smooth piece (the tangent oriented by the
//!   last one and the last tangent within `max_angle`), another branch crosses this one: the
//!   sweep goes straight on, `sigma` changes, and the point is located and reported.
//! * **Corners.** A step whose corrector fails is retried along the tangent of the next piece
//!   (the null vector at the predicted point, oriented by `sigma`), then at half the length.
//! * **Step length** from the corrector's iterations (`target_iterations / iterations`) and the
//!   turn of the tangent over the step (`max_angle / angle`), each clamped to `[1/2, 2]`.
//! * **Gaps.** Below `min_step`, or where the branch comes back to a point it passed in the
//!   same direction (it circles where contacts change state), the sweep steps over the place at
//!   fixed frequency: ahead by `1e-4`, `1e-3`, `1e-2`, `3e-2`, `0.1` of the band (a gap right
//!   after a gap starts one size further), from the last point, from it extrapolated along its
//!   tangent, and from zero; it takes the first solution off the branch already traced whose
//!   tangent towards `omega_end` is where it goes on (the orientation starts again there), and
//!   marks the gap ([`SweepResult::gaps`]). It ends only when none does.
//! * **Folds** (a sign change of `t_omega`) and branch points are located between their two
//!   points by corrector solves on the chord's hyperplanes (regula falsi on `t_omega`, bisection
//!   on the determinant's sign) and reported ([`SweepResult::events`]).

use super::{characteristic_displacement, correct, Constraint, Corrected, Corrector, Metric};
use crate::aft::AftPlan;
use crate::error::{JpError, Result};
use crate::hbm::residual::ResidualWorkspace;
use crate::hbm::solve::{finish_point, newton, plan_for, AtFrequency, NewtonOutcome};
use crate::hbm::{BranchEvent, ContinuationMethod, EventKind, HarmonicSystem, HbmOptions, PointSolution, SweepEnd, SweepGap, SweepOptions, SweepResult, LEFT_BAND_EXCURSION};
use crate::linalg::{Matrix, MatrixLu};
use std::ops::ControlFlow;

/// Fractions of the band a gap steps over, tried in turn.
const GAP_STEPS: [f64; 5] = [1e-4, 1e-3, 1e-2, 3e-2, 1e-1];

/// Points just before the newest that a revisit is not looked for among (its neighbours on
/// the branch).
const REVISIT_SKIP: usize = 3;

/// Most corrector solves spent locating one event.
const MAX_LOCATE_SOLVES: usize = 40;

/// Relative frequency width to which an event is located.
const LOCATE_TOLERANCE: f64 = 1e-10;

/// A converged point with its oriented unit tangent.
#[derive(Clone)]
struct Oriented {
    y: Vec<f64>,
    t: Vec<f64>,
}

/// A step taken: the new point, its tangent, the corrector's work, and whether the
/// determinant's sign changed on a smooth piece (a branch point within the step).
struct Step {
    to: Oriented,
    corrected: Corrected,
    branch_point: bool,
}

/// What the steps of one sweep share.
struct Context<'a> {
    system: &'a dyn HarmonicSystem,
    plan: Option<&'a AftPlan>,
    sopts: &'a SweepOptions,
    hopts: &'a HbmOptions,
    ws: ResidualWorkspace,
    lu: MatrixLu,
    n: usize,
    metric: Metric,
    /// `sign det [J_z R_omega; (S t)^T]` of the forward tangent
    sigma: f64,
}

impl Context<'_> {
    /// `[J_z  R_omega; 0]` at `y` (rows divided by the reference force there).
    fn bordered_at(&mut self, y: &[f64]) -> Result<Matrix> {
        let mut c = Corrector::new(self.system, self.plan, self.sopts, &mut self.ws, self.metric, Constraint::Sphere { centre: y }, 1.0);
        let (_, top) = c.linearise(y, true)?;
        let top = top.expect("jacobian requested");
        top.jz.bordered(&top.r_omega, &vec![0.0; self.n + 1])
    }

    /// The unit tangent of the bordered Jacobian `b` (its border row overwritten) with
    /// `t^T S reference > 0`, and `sign det [J_z R_omega; (S t)^T]`: that of `b` with the row
    /// `S reference`, since `det [J; (S t)^T] = det b * t^T S t` for `t = b^-1 e_n`. A sparse
    /// factorisation has no sign: it is taken as `sigma` (the orientation by the last tangent).
    fn tangent_of(&mut self, mut b: Matrix, reference: &[f64], omega: f64) -> Result<(Vec<f64>, f64)> {
        b.set_border_row(&self.metric.apply(reference))?;
        self.lu.factor(&b, || format!("continuation tangent system at omega = {omega}"))?;
        let mut rhs = vec![0.0; self.n + 1];
        rhs[self.n] = 1.0;
        let t = self.metric.unit(&self.lu.solve(&rhs)).ok_or_else(|| JpError::singular(format!("continuation tangent at omega = {omega}")))?;
        let sign = self.lu.determinant_sign().unwrap_or(self.sigma);
        Ok((t, sign))
    }

    /// The forward tangent at `y` from its bordered Jacobian `b`: the tangent that `sigma`
    /// orients, and that tangent's own (unflipped) sign against `reference`.
    fn forward_tangent(&mut self, b: Matrix, reference: &[f64], omega: f64) -> Result<(Vec<f64>, Vec<f64>, f64)> {
        let (t, sign) = self.tangent_of(b, reference, omega)?;
        let forward = if sign == self.sigma { t.clone() } else { t.iter().map(|v| -v).collect() };
        Ok((forward, t, sign))
    }

    /// The corrector from `y_p = y + ds d` on the hyperplane through `y_p` normal to `d`, then
    /// on the sphere of radius `ds` around `y`.
    fn correct_from(&mut self, y: &[f64], d: &[f64], ds: f64) -> Result<Corrected> {
        let y_pred: Vec<f64> = (0..=self.n).map(|i| y[i] + ds * d[i]).collect();
        let (system, plan, sopts, hopts, metric) = (self.system, self.plan, self.sopts, self.hopts, self.metric);
        correct(system, plan, &y_pred, Constraint::Hyperplane { t: d, y_pred: &y_pred }, ds, metric, sopts, hopts, &mut self.ws)
            .or_else(|e| correct(system, plan, &y_pred, Constraint::Sphere { centre: y }, ds, metric, sopts, hopts, &mut self.ws).map_err(|_| e))
    }

    /// Whether the corrected point `c` is a step ahead of `from` (module doc), with its
    /// forward tangent.
    fn judge(&mut self, from: &Oriented, mut c: Corrected, ds: f64) -> Result<Step> {
        let n = self.n;
        let b = match c.jacobian.take() {
            Some(b) => b,
            None => self.bordered_at(&c.y)?,
        };
        let (forward, own, sign) = self.forward_tangent(b, &from.t, c.y[n])?;
        let chord: Vec<f64> = (0..=n).map(|i| c.y[i] - from.y[i]).collect();
        let length = self.metric.dot(&chord, &chord).sqrt();
        if !(length <= 2.0 * ds) {
            return Err(JpError::NoConvergence {
                what: format!("continuation: the corrected point lies {length:.3e} from the last one, more than twice the step {ds:.3e}, near omega = {}", c.y[n]),
                iterations: 0,
                residual: f64::NAN,
                tolerance: f64::NAN,
            });
        }
        let m = self.metric;
        // a converged point refused for where it lies: the message says why, with no residual
        // (it met the tolerance) and no iteration count (the refusal was not an iteration)
        let reject = |what: String| Err(JpError::NoConvergence { what, iterations: 0, residual: f64::NAN, tolerance: f64::NAN });
        let sum: Vec<f64> = from.t.iter().zip(&forward).map(|(a, b)| a + b).collect();
        if sign == self.sigma {
            // the tangent oriented by the last one is the forward one: a turn below a right
            // angle, the point ahead when the chord is along both tangents' sum
            if m.dot(&chord, &sum) > 0.0 {
                return Ok(Step { to: Oriented { y: c.y.clone(), t: forward }, corrected: c, branch_point: false });
            }
            return reject(format!("continuation: the corrected point lies behind the last one on the branch, near omega = {}", c.y[n]));
        }
        // The determinant changed sign against the tangent oriented by the last one. A corner
        // that turns by more than a right angle: the chord lies within half the turn of the
        // tangents' bisector (a turn within max_angle of a full reversal is a cusp or a branch
        // running back beside this one, which no test on the chord tells apart, and a shorter
        // step decides). Otherwise, with the chord along both the last tangent and the new one,
        // the branch went straight on through a branch point.
        let bisector = m.dot(&sum, &sum).sqrt();
        let along_bisector = if bisector > 0.0 { m.dot(&chord, &sum) / (bisector * length) } else { -1.0 };
        let reversal = m.dot(&forward, &from.t) < -self.sopts.max_angle.cos();
        if !reversal && along_bisector >= (0.5 * self.sopts.max_angle).sin() {
            return Ok(Step { to: Oriented { y: c.y.clone(), t: forward }, corrected: c, branch_point: false });
        }
        if m.dot(&chord, &own) > 0.0 && m.dot(&chord, &from.t) > 0.0 {
            self.sigma = sign;
            return Ok(Step { to: Oriented { y: c.y.clone(), t: own }, corrected: c, branch_point: true });
        }
        if reversal {
            return reject(format!("continuation: the tangent turned back by more than pi - max_angle near omega = {}", c.y[n]));
        }
        reject(format!("continuation: the corrected point lies behind the last one on the branch, near omega = {}", c.y[n]))
    }

    /// One step from `from`: along its tangent, then along the tangent of the next piece, at
    /// `ds` and then at half of it, down to `min_step`. The last error if none is taken.
    fn step(&mut self, from: &Oriented, mut ds: f64, rejected: &mut usize) -> std::result::Result<(Step, f64), JpError> {
        let n = self.n;
        let mut last_error: Option<JpError> = None;
        while ds >= self.sopts.min_step {
            let mut directions = vec![from.t.clone()];
            let mut tried_corner = false;
            let mut k = 0;
            while k < directions.len() {
                let d = directions[k].clone();
                k += 1;
                let attempt = self.correct_from(&from.y, &d, ds).and_then(|c| self.judge(from, c, ds));
                match attempt {
                    Ok(s) => return Ok((s, ds)),
                    Err(e @ JpError::Callback { .. }) => return Err(e),
                    Err(e) => last_error = Some(e),
                }
                *rejected += 1;
                if !tried_corner {
                    tried_corner = true;
                    // the tangent of the piece beyond a corner: the null vector at the point
                    // the tangent predicted, oriented by sigma
                    let y_pred: Vec<f64> = (0..=n).map(|i| from.y[i] + ds * from.t[i]).collect();
                    if let Ok(b) = self.bordered_at(&y_pred) {
                        if let Ok((t_next, _, _)) = self.forward_tangent(b, &from.t, y_pred[n]) {
                            if self.metric.dot(&t_next, &from.t) < 1.0 - 1e-12 {
                                directions.push(t_next);
                            }
                        }
                    }
                }
            }
            ds *= 0.5;
        }
        Err(last_error.unwrap_or_else(|| JpError::invalid("continuation", "no step was tried (min_step above the step)")))
    }

    /// Steps over the place the corrector cannot pass at fixed frequency (module doc): the
    /// first solution ahead by a fraction of the band whose forward tangent points ahead in
    /// frequency, with that tangent.
    fn step_over(&mut self, from: &Oriented, direction: f64, span: f64, traced: &[PointSolution], first: usize) -> Option<(PointSolution, Oriented)> {
        let n = self.n;
        let omega = from.y[n];
        for &f in &GAP_STEPS[first.min(GAP_STEPS.len())..] {
            let target = omega + direction * f * span;
            let mut starts: Vec<Option<Vec<f64>>> = vec![Some(from.y[..n].to_vec())];
            if from.t[n] * direction > 0.0 {
                let s = (target - omega) / from.t[n];
                starts.push(Some((0..n).map(|i| from.y[i] + s * from.t[i]).collect()));
            }
            starts.push(None);
            for start in starts {
                let Ok(p) = crate::hbm::solve_point(self.system, target, start.as_deref(), self.hopts) else { continue };
                let y: Vec<f64> = p.z.iter().copied().chain([target]).collect();
                if on_traced(traced, &y, self.metric) {
                    continue;
                }
                let mut towards = vec![0.0; n + 1];
                towards[n] = direction;
                let Ok(b) = self.bordered_at(&y) else { continue };
                // past a gap the orientation starts again, towards omega_end: the point may lie
                // on another part of the solution set, or beyond a branch point
                let Ok((forward, sign)) = self.tangent_of(b, &towards, target) else { continue };
                if forward[n] * direction > 0.0 {
                    self.sigma = sign;
                    return Some((p, Oriented { y, t: forward }));
                }
            }
        }
        None
    }

    /// Whether the new point `y` with forward tangent `t` comes back to an earlier point of the
    /// branch (not one of its last [`REVISIT_SKIP`] neighbours) in the same direction: within
    /// `radius` of it, the tangents there and here less than a right angle apart. A regular
    /// branch never does; one that circles where contacts change state at every step does.
    fn revisits(&self, traced: &[PointSolution], tangents: &[Vec<f64>], y: &[f64], t: &[f64], radius: f64) -> Option<usize> {
        let n = self.n;
        let end = traced.len().saturating_sub(REVISIT_SKIP);
        let m = self.metric;
        (0..end).find(|&i| {
            let p = &traced[i];
            let dw = (p.omega - y[n]) * m.sw.sqrt();
            if dw.abs() > radius || p.z.len() != n {
                return false;
            }
            let d2: f64 = m.sz * (0..n).map(|k| (p.z[k] - y[k]).powi(2)).sum::<f64>() + dw * dw;
            d2.sqrt() <= radius && m.dot(&tangents[i], t) > 0.0
        })
    }

    /// The point on the branch between `a` and `b` at the fraction `s` of their chord, within
    /// the bracket `lo`, `hi` (points at the fractions `lo.0 < s < hi.0`): the corrector on the
    /// hyperplane through `a + s (b - a)` normal to the chord, from the bracket's ends
    /// interpolated there, with its tangent oriented by `a`'s. A solution farther from that
    /// start than the bracket's ends are from each other lies on another branch crossing the
    /// hyperplane (near a branch point, the branch that bifurcates) and is refused.
    fn on_chord(&mut self, a: &Oriented, b: &Oriented, lo: &(f64, Oriented), hi: &(f64, Oriented), s: f64) -> Result<(Oriented, Vec<f64>, f64)> {
        let n = self.n;
        let m = self.metric;
        let chord: Vec<f64> = (0..=n).map(|i| b.y[i] - a.y[i]).collect();
        let length = m.dot(&chord, &chord).sqrt();
        let d: Vec<f64> = chord.iter().map(|v| v / length).collect();
        let on_plane: Vec<f64> = (0..=n).map(|i| a.y[i] + s * chord[i]).collect();
        let f = (s - lo.0) / (hi.0 - lo.0);
        let start: Vec<f64> = (0..=n).map(|i| lo.1.y[i] + f * (hi.1.y[i] - lo.1.y[i])).collect();
        let (system, plan, sopts, hopts) = (self.system, self.plan, self.sopts, self.hopts);
        let mut c = correct(system, plan, &start, Constraint::Hyperplane { t: &d, y_pred: &on_plane }, s * length, m, sopts, hopts, &mut self.ws)?;
        let width: Vec<f64> = (0..=n).map(|i| hi.1.y[i] - lo.1.y[i]).collect();
        let moved: Vec<f64> = (0..=n).map(|i| c.y[i] - start[i]).collect();
        if m.dot(&moved, &moved) > m.dot(&width, &width) {
            return Err(JpError::NoConvergence { what: format!("locating an event: the corrected point left the bracket near omega = {}", c.y[n]), iterations: 0, residual: f64::NAN, tolerance: f64::NAN });
        }
        let bordered = match c.jacobian.take() {
            Some(m) => m,
            None => self.bordered_at(&c.y)?,
        };
        let (forward, own, sign) = self.forward_tangent(bordered, &lo.1.t, c.y[n])?;
        Ok((Oriented { y: c.y, t: forward }, own, sign))
    }

    /// Locates a fold (the sign change of `t_omega`) between `a` and `b`: regula falsi
    /// (Illinois) on `t_omega` along the chord, the tangents oriented by `sigma`, or by
    /// continuity (`straight_on`) in a step that crosses a branch point. The point nearest the
    /// fold and the bracket's half width in frequency.
    fn locate_fold(&mut self, a: &Oriented, b: &Oriented, straight_on: bool) -> (Vec<f64>, f64) {
        let n = self.n;
        let (mut lo, mut hi) = ((0.0, a.clone()), (1.0, b.clone()));
        let mut best = if a.t[n].abs() < b.t[n].abs() { a.y.clone() } else { b.y.clone() };
        let mut side = 0i32;
        for _ in 0..MAX_LOCATE_SOLVES {
            let width = (hi.1.y[n] - lo.1.y[n]).abs();
            if width <= LOCATE_TOLERANCE * best[n].abs() {
                break;
            }
            let (f_lo, f_hi) = (if side == 1 { 0.5 * lo.1.t[n] } else { lo.1.t[n] }, if side == -1 { 0.5 * hi.1.t[n] } else { hi.1.t[n] });
            let mut s = lo.0 - f_lo * (hi.0 - lo.0) / (f_hi - f_lo);
            if !(s > lo.0 && s < hi.0) {
                s = 0.5 * (lo.0 + hi.0);
            }
            let Ok((mut p, own, _)) = self.on_chord(a, b, &lo, &hi, s) else { break };
            if straight_on {
                p.t = own;
            }
            let f = p.t[n];
            best = p.y.clone();
            if f == 0.0 {
                hi = lo.clone();
                break;
            }
            if (f > 0.0) == (lo.1.t[n] > 0.0) {
                lo = (s, p);
                side = -1;
            } else {
                hi = (s, p);
                side = 1;
            }
        }
        let tolerance = 0.5 * (hi.1.y[n] - lo.1.y[n]).abs();
        (best, tolerance)
    }

    /// Locates a branch point (the determinant's sign change) between `a` (sign `sign_a`) and
    /// `b` by bisection along the chord: its frequency, the bracket's half width, and the
    /// bracket's end on `a`'s side.
    fn locate_branch_point(&mut self, a: &Oriented, b: &Oriented, sign_a: f64) -> (f64, f64, Vec<f64>) {
        let n = self.n;
        let (mut lo, mut hi) = ((0.0, a.clone()), (1.0, b.clone()));
        let saved = std::mem::replace(&mut self.sigma, sign_a);
        for _ in 0..MAX_LOCATE_SOLVES {
            if (hi.1.y[n] - lo.1.y[n]).abs() <= LOCATE_TOLERANCE * lo.1.y[n].abs() {
                break;
            }
            let s = 0.5 * (lo.0 + hi.0);
            let Ok((p, own, sign)) = self.on_chord(a, b, &lo, &hi, s) else { break };
            if sign == sign_a {
                lo = (s, p);
            } else {
                hi = (s, Oriented { y: p.y, t: own });
            }
        }
        self.sigma = saved;
        (0.5 * (lo.1.y[n] + hi.1.y[n]), 0.5 * (hi.1.y[n] - lo.1.y[n]).abs(), lo.1.y)
    }
}

/// Whether `y` lies on the branch already traced: nearer to the straight line between two
/// successive points whose frequencies bracket its own than they are to each other.
fn on_traced(traced: &[PointSolution], y: &[f64], m: Metric) -> bool {
    let n = y.len() - 1;
    traced.windows(2).any(|w| {
        let (a, b) = (&w[0], &w[1]);
        if (y[n] - a.omega) * (y[n] - b.omega) > 0.0 || a.omega == b.omega || a.z.len() != n || b.z.len() != n {
            return false;
        }
        let s = (y[n] - a.omega) / (b.omega - a.omega);
        let gap: f64 = (0..n).map(|i| (y[i] - a.z[i] - s * (b.z[i] - a.z[i])).powi(2)).sum();
        let length = m.sz * (0..n).map(|i| (b.z[i] - a.z[i]).powi(2)).sum::<f64>() + m.sw * (b.omega - a.omega).powi(2);
        m.sz * gap <= length
    })
}

/// The amplitude of the first output's first harmonic at `y` (0 without outputs).
fn first_amplitude(system: &dyn HarmonicSystem, y: &[f64]) -> f64 {
    let n = y.len() - 1;
    if system.n_outputs() == 0 || system.layout().harmonics == 0 {
        return 0.0;
    }
    match system.output_harmonics(y[n], &y[..n]) {
        Ok(out) => {
            let m = system.n_outputs();
            out[m].hypot(out[2 * m])
        }
        Err(_) => 0.0,
    }
}

pub(super) fn sweep_from(
    system: &dyn HarmonicSystem,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    start: Option<&[f64]>,
    on_point: &mut dyn FnMut(&PointSolution) -> ControlFlow<()>,
) -> Result<SweepResult> {
    debug_assert_eq!(sopts.method, ContinuationMethod::Oriented);
    sopts.validate()?;
    hopts.validate()?;
    let plan = plan_for(system)?;
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

    // First point at omega_start, with the point solver's load-stepping fallback.
    let first = crate::hbm::solve_point(system, w0, start, hopts)?;
    let mut z_ref = characteristic_displacement(system, &first.z);
    let y0: Vec<f64> = first.z.iter().copied().chain([w0]).collect();
    let stop = on_point(&first).is_break();
    result.points.push(first);
    if stop {
        return Ok(finish(result, SweepEnd::StoppedByCaller, Some(format!("stopped by the caller {}", at(w0))), None));
    }
    let mut ctx = Context {
        system,
        plan: plan.as_ref(),
        sopts,
        hopts,
        ws: ResidualWorkspace::new(),
        lu: MatrixLu::empty(),
        n,
        metric: Metric { sz: 1.0 / (z_ref * z_ref), sw: 1.0 / (span * span) },
        sigma: 1.0,
    };
    // the first tangent towards omega_end sets the orientation
    let mut towards = vec![0.0; n + 1];
    towards[n] = direction;
    let b = ctx.bordered_at(&y0)?;
    let (t0, sign0) = ctx.tangent_of(b, &towards, w0)?;
    ctx.sigma = sign0;
    let mut here = Oriented { y: y0, t: t0 };
    // the forward tangent at each point of the branch, for the revisit test
    let mut tangents: Vec<Vec<f64>> = vec![here.t.clone()];
    let mut ds = sopts.initial_step.clamp(sopts.min_step, sopts.max_step);
    let mut last_turn: Option<f64> = None;
    let mut consecutive_gaps = 0;
    loop {
        if result.points.len() >= sopts.max_points {
            let text = format!("stopped at the point cap (max_points = {}) {}", sopts.max_points, at(here.y[n]));
            return Ok(finish(result, SweepEnd::MaxPoints, Some(text), None));
        }
        let omega = here.y[n];
        // no step moves the frequency by more than max_omega_step of the band
        let t_omega = (ctx.metric.sw * here.t[n] * here.t[n]).sqrt();
        if t_omega > 0.0 {
            ds = ds.min(sopts.max_omega_step / t_omega);
        }
        ds = ds.max(sopts.min_step);
        let sigma_before = ctx.sigma;
        let stepped = ctx.step(&here, ds, &mut result.rejected_steps).and_then(|(step, ds_taken)| {
            match ctx.revisits(&result.points, &tangents, &step.to.y, &step.to.t, ds_taken) {
                Some(i) => Err(JpError::NoConvergence {
                    what: format!(
                        "continuation: the branch came back to its point {i} at omega = {} (it circles where contacts change state)",
                        result.points[i].omega
                    ),
                    iterations: 0,
                    residual: f64::NAN,
                    tolerance: f64::NAN,
                }),
                None => Ok((step, ds_taken)),
            }
        });
        let (next, corrected, branch_point, gap_point) = match stepped {
            Ok((step, ds_taken)) => {
                // the turn per unit arclength that this step and the last agree on: curvature
                // turns both, a corner (a contact changing state) one of them alone
                let angle = ctx.metric.dot(&here.t, &step.to.t).clamp(-1.0, 1.0).acos();
                let turn = angle / ds_taken;
                let kappa = last_turn.map_or(turn, |t: f64| t.min(turn));
                last_turn = Some(turn);
                let f_iter = (sopts.target_iterations as f64 / step.corrected.iterations.max(1) as f64).clamp(0.5, 2.0);
                let f_angle = if kappa > 0.0 { (sopts.max_angle / (kappa * ds_taken)).clamp(0.5, 2.0) } else { 2.0 };
                ds = (ds_taken * f_iter.min(f_angle)).clamp(sopts.min_step, sopts.max_step);
                consecutive_gaps = 0;
                (step.to, Some(step.corrected), step.branch_point, None)
            }
            // a failed external law (C callback) is the caller's error: no shorter step mends it
            Err(e @ JpError::Callback { .. }) => return Err(e),
            // a gap after a gap steps further: a run of gaps is not a continuation
            Err(e) => match ctx.step_over(&here, direction, span, &result.points, consecutive_gaps) {
                Some((p, o)) => {
                    result.gaps.push(SweepGap { from: omega, to: p.omega, reason: e.to_string() });
                    consecutive_gaps += 1;
                    ds = sopts.initial_step.clamp(sopts.min_step, sopts.max_step);
                    last_turn = None;
                    (o, None, false, Some(p))
                }
                None => {
                    let text = format!("stalled {}: no step down to min_step = {:e} converged ahead, and no solution ahead at fixed frequency; last corrector error: {e}", at(omega), sopts.min_step);
                    return Ok(finish(result, SweepEnd::StepTooSmall, Some(text), Some(e)));
                }
            },
        };
        let after = result.points.len() - 1;
        if corrected.is_some() {
            // events in the order the branch meets them
            let mut events: Vec<(f64, BranchEvent)> = Vec::new();
            if here.t[n] * next.t[n] < 0.0 {
                let (y_fold, tol) = ctx.locate_fold(&here, &next, branch_point);
                result.folds.push(y_fold[n]);
                events.push((ctx.metric.distance(&y_fold, &here.y), BranchEvent { kind: EventKind::Fold, omega: y_fold[n], omega_tolerance: tol, after_point: after, amplitude: first_amplitude(system, &y_fold) }));
            }
            if branch_point {
                let (w_bp, tol, y_bp) = ctx.locate_branch_point(&here, &next, sigma_before);
                events.push((ctx.metric.distance(&y_bp, &here.y), BranchEvent { kind: EventKind::BranchPoint, omega: w_bp, omega_tolerance: tol, after_point: after, amplitude: first_amplitude(system, &y_bp) }));
            }
            events.sort_by(|a, b| a.0.total_cmp(&b.0));
            result.events.extend(events.into_iter().map(|(_, e)| e));
        }
        let new_omega = next.y[n];
        if (new_omega - w0) * direction < -LEFT_BAND_EXCURSION * span {
            let text = format!("the branch turned back and left the band behind omega_start {}", at(new_omega));
            return Ok(finish(result, SweepEnd::LeftBand, Some(text), None));
        }
        let passed_end = (new_omega - w1) * direction >= 0.0;
        let (iterations, residual) = corrected.as_ref().map_or((0, 0.0), |c| (c.iterations, c.residual));
        let converged = NewtonOutcome { z: next.y[..n].to_vec(), iterations, residual };
        let outcome = if passed_end {
            // a fixed-frequency solve at omega_end from the interpolated guess
            let s = (w1 - omega) / (new_omega - omega);
            let guess: Vec<f64> = (0..n).map(|i| here.y[i] + s * (next.y[i] - here.y[i])).collect();
            let lin = system.linear_part(w1)?;
            match newton(AtFrequency { system, plan: plan.as_ref(), opts: hopts, omega: w1 }, &lin, guess, hopts.max_iterations, &mut ctx.ws) {
                Ok(o) => (w1, o),
                Err(_) => (new_omega, converged),
            }
        } else {
            (new_omega, converged)
        };
        let p = match gap_point {
            // a gap's first point, solved at fixed frequency
            Some(p) if !passed_end => p,
            _ => finish_point(system, plan.as_ref(), outcome.0, outcome.1, &mut ctx.ws)?,
        };
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
        ctx.metric = Metric { sz: 1.0 / (z_ref * z_ref), sw: ctx.metric.sw };
        let t = ctx.metric.unit(&next.t).ok_or_else(|| JpError::singular("continuation tangent"))?;
        tangents.push(t.clone());
        here = Oriented { y: next.y, t };
    }
}
