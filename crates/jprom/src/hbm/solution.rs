//! What a solve returns: one converged frequency point ([`PointSolution`]) and a branch of
//! them ([`SweepResult`]).

use super::HarmonicLayout;
use crate::aft::ContactCycle;
use crate::error::JpError;
use serde::{Deserialize, Serialize};

/// One converged harmonic-balance solution (an unconverged point is never returned).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointSolution {
    /// Angular frequency (rad/s).
    pub omega: f64,
    /// Unknowns of the system, in the order of `layout`.
    pub z: Vec<f64>,
    /// Layout of `z`.
    pub layout: HarmonicLayout,
    /// Always true for a returned point (kept for callers that store failed attempts).
    pub converged: bool,
    /// Newton (or corrector) iterations used.
    pub iterations: usize,
    /// `|r| / |f_ref|` at the solution.
    pub residual_norm: f64,
    /// Physical response at the output DoFs, entry `k * n_outputs + j` (`k = 0`, `2h - 1`
    /// cos, `2h` sin).
    pub outputs: Vec<f64>,
    /// Number of output DoFs.
    pub n_outputs: usize,
    /// Per contact: state at each time sample and dissipated energy per cycle.
    pub contact_cycles: Vec<ContactCycle>,
}

impl PointSolution {
    /// Output coefficient `k` of output DoF `j`.
    pub fn output_coeff(&self, k: usize, j: usize) -> f64 {
        self.outputs[k * self.n_outputs + j]
    }

    /// Amplitude of harmonic `h` at output DoF `j`: `sqrt(c^2 + s^2)` for `h >= 1`, `|c_0|`
    /// for `h = 0`.
    pub fn output_amplitude(&self, h: usize, j: usize) -> f64 {
        if h == 0 {
            self.output_coeff(0, j).abs()
        } else {
            self.output_coeff(2 * h - 1, j).hypot(self.output_coeff(2 * h, j))
        }
    }

    /// Harmonic-major contact displacement `w` (`2H + 1` blocks of `n_w`) of a full-order or
    /// condensed full-order solution, whose unknowns start with the `n_w` contact coordinates
    /// in every coefficient.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if `z` does not match the layout or a harmonic has fewer than `n_w`
    /// unknowns.
    pub fn contact_displacement(&self, n_w: usize) -> Result<Vec<f64>, JpError> {
        let layout = &self.layout;
        if self.z.len() != layout.total() {
            return Err(JpError::bad_size("solution z", layout.total(), self.z.len()));
        }
        if layout.sizes.iter().any(|&s| s < n_w) {
            return Err(JpError::bad_size("solution unknowns per harmonic", n_w, *layout.sizes.iter().min().unwrap_or(&0)));
        }
        let nc = 2 * layout.harmonics + 1;
        let mut w = Vec::with_capacity(n_w * nc);
        for k in 0..nc {
            let (o, _) = layout.coeff_range(k);
            w.extend_from_slice(&self.z[o..o + n_w]);
        }
        Ok(w)
    }

    /// Total energy dissipated by friction per cycle, over all contacts.
    pub fn dissipated_energy(&self) -> f64 {
        self.contact_cycles.iter().map(|c| c.dissipated_energy).sum()
    }
}

/// Why a sweep ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SweepEnd {
    /// The branch reached `omega_end`.
    ReachedEnd,
    /// The callback returned `Break` (the C ABI reports it as cancelled).
    StoppedByCaller,
    /// A step was rejected at the minimum step size: the corrector did not converge.
    StepTooSmall,
    /// `max_points` points were computed before reaching `omega_end`.
    MaxPoints,
    /// The branch turned back at a fold and left the band behind `omega_start` by more than
    /// [`LEFT_BAND_EXCURSION`] of its width ([`LEFT_BAND_MARGIN`] for the secant
    /// continuation); the points up to there are kept.
    LeftBand,
}

/// How far (as a fraction of the band width) a branch may run back past `omega_start` before
/// the secant continuation ends with [`SweepEnd::LeftBand`].
pub const LEFT_BAND_MARGIN: f64 = 0.1;

/// How far (as a fraction of the band width) a branch may run back past `omega_start` before
/// the oriented continuation ends with [`SweepEnd::LeftBand`]: a whole band, so that a
/// resonance whose peak bends out of the band (a softening friction peak below `omega_start`,
/// a hardening one above it on a downward sweep) is followed round and back.
pub const LEFT_BAND_EXCURSION: f64 = 1.0;

/// A branch of converged points from a pseudo-arclength sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepResult {
    /// Converged points in branch order, strictly ordered along the arclength (the frequency
    /// goes back only past a fold in [`SweepResult::folds`]).
    pub points: Vec<PointSolution>,
    /// Continuation steps rejected (corrector failed) and retried with a smaller step.
    pub rejected_steps: usize,
    /// Why the sweep ended.
    pub end: SweepEnd,
    /// True unless the branch reached `omega_end`.
    pub stopped_early: bool,
    /// Unless the sweep reached `omega_end`: why and where it stopped, in words (for
    /// [`SweepEnd::StepTooSmall`] with the corrector's last error and residual).
    pub failure: Option<String>,
    /// For [`SweepEnd::StepTooSmall`]: the last corrector error (not serialised).
    #[serde(skip)]
    pub error: Option<JpError>,
    /// Frequencies where the branch turned back in frequency (the tangent's frequency
    /// component changed sign), in branch order.
    #[serde(default)]
    pub folds: Vec<f64>,
    /// Frequencies from which the sweep stepped over a kink at fixed frequency because the
    /// corrector could not settle there ([`crate::hbm::ContinuationMethod::Secant`] only; the
    /// oriented continuation marks such places as [`SweepResult::gaps`]).
    #[serde(default)]
    pub restarts: Vec<f64>,
    /// Folds and branch points along the branch, in branch order, each located between two
    /// of its points (docs/formulation.md §6.6).
    #[serde(default)]
    pub events: Vec<BranchEvent>,
    /// Parts of the band the continuation could not follow and stepped over at fixed
    /// frequency (docs/formulation.md §6.7); a sweep with gaps that reached the band's end says
    /// so here, its points on either side being converged solutions.
    #[serde(default)]
    pub gaps: Vec<SweepGap>,
}

/// What a [`BranchEvent`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// The branch turns back in frequency: the tangent's frequency component changes sign.
    Fold,
    /// The sign of the bordered Jacobian's determinant changes on a smooth piece of the
    /// branch: another branch crosses it there.
    BranchPoint,
}

impl EventKind {
    /// `fold` or `branch_point`.
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Fold => "fold",
            EventKind::BranchPoint => "branch_point",
        }
    }
}

/// A fold or a branch point located along a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BranchEvent {
    pub kind: EventKind,
    /// Angular frequency (rad/s).
    pub omega: f64,
    /// Half the width, in frequency, of the last bracket of the location (rad/s): the event
    /// lies within `omega +- omega_tolerance` along the branch.
    pub omega_tolerance: f64,
    /// Index in [`SweepResult::points`] of the point just before it on the branch.
    pub after_point: usize,
    /// First-harmonic amplitude of the first output there (0 for a system without outputs).
    pub amplitude: f64,
}

/// A part of the band stepped over at fixed frequency.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepGap {
    /// Frequency of the last point before the gap and of the first point after it (rad/s).
    pub from: f64,
    pub to: f64,
    /// Why the continuation could not go on (the corrector's last error).
    pub reason: String,
}

impl Default for SweepResult {
    fn default() -> Self {
        SweepResult::empty()
    }
}

impl SweepResult {
    /// No point yet; `end` is [`SweepEnd::ReachedEnd`] until set.
    pub fn empty() -> Self {
        SweepResult {
            points: Vec::new(),
            rejected_steps: 0,
            end: SweepEnd::ReachedEnd,
            stopped_early: false,
            failure: None,
            error: None,
            folds: Vec::new(),
            restarts: Vec::new(),
            events: Vec::new(),
            gaps: Vec::new(),
        }
    }

    /// Whether the branch covered the band: it reached `omega_end`.
    pub fn reached_end(&self) -> bool {
        self.end == SweepEnd::ReachedEnd
    }

    /// The peak `(omega, amplitude)` of `amplitude` along the branch: the largest point, moved
    /// to the vertex of the parabola through it and its two neighbours where the three are in
    /// increasing or decreasing frequency and the vertex lies between the neighbours. A
    /// friction-damped peak is flat over several continuation steps; the largest point alone
    /// is off the resonance by up to a step (1 % and more on such a peak), the vertex by much
    /// less. `None` without points.
    pub fn peak_by(&self, amplitude: impl Fn(&PointSolution) -> f64) -> Option<(f64, f64)> {
        let y: Vec<f64> = self.points.iter().map(&amplitude).collect();
        let k = (0..y.len()).max_by(|&a, &b| y[a].total_cmp(&y[b]))?;
        let at = (self.points[k].omega, y[k]);
        if k == 0 || k + 1 == y.len() {
            return Some(at);
        }
        Some(parabola_vertex([self.points[k - 1].omega, at.0, self.points[k + 1].omega], [y[k - 1], y[k], y[k + 1]]).unwrap_or(at))
    }
}

/// The vertex of the parabola through three points `(x_i, y_i)` with `x` strictly monotone,
/// if it is a maximum between `x_0` and `x_2`.
fn parabola_vertex(x: [f64; 3], y: [f64; 3]) -> Option<(f64, f64)> {
    let (a, b) = (x[1] - x[0], x[1] - x[2]);
    if !(a * b < 0.0) {
        return None;
    }
    let (p, q) = (a * (y[1] - y[2]), b * (y[1] - y[0]));
    let den = p - q;
    let curvature = ((y[2] - y[1]) / (x[2] - x[1]) - (y[1] - y[0]) / (x[1] - x[0])) / (x[2] - x[0]);
    if den == 0.0 || !den.is_finite() || !(curvature < 0.0) {
        return None;
    }
    let xv = x[1] - 0.5 * (a * p - b * q) / den;
    let (lo, hi) = (x[0].min(x[2]), x[0].max(x[2]));
    if !(lo..=hi).contains(&xv) {
        return None;
    }
    let basis = |i: usize, j: usize, k: usize| (xv - x[j]) * (xv - x[k]) / ((x[i] - x[j]) * (x[i] - x[k]));
    let yv = y[0] * basis(0, 1, 2) + y[1] * basis(1, 0, 2) + y[2] * basis(2, 0, 1);
    (yv >= y[1] && yv.is_finite()).then_some((xv, yv))
}

#[cfg(test)]
mod tests {
    use super::parabola_vertex;

    #[test]
    fn the_vertex_of_a_sampled_parabola_is_its_maximum() {
        let f = |x: f64| 3.0 - 0.5 * (x - 1.3) * (x - 1.3);
        for xs in [[1.0, 1.2, 1.9], [2.0, 1.5, 0.4]] {
            let (xv, yv) = parabola_vertex(xs, xs.map(f)).expect("a maximum between the outer points");
            assert!((xv - 1.3).abs() < 1e-12 && (yv - 3.0).abs() < 1e-12, "{xv} {yv}");
        }
        assert!(parabola_vertex([1.0, 1.2, 1.1], [1.0, 2.0, 1.5]).is_none(), "not monotone");
        assert!(parabola_vertex([0.0, 1.0, 2.0], [0.0, 1.0, 2.0]).is_none(), "a line");
        assert!(parabola_vertex([0.0, 1.0, 2.0], [2.0, 1.0, 2.0]).is_none(), "a minimum");
    }
}

impl SweepEnd {
    /// A short name for tables and files (`reached_end`, `stalled`, `point_cap`, `left_band`,
    /// `cancelled`).
    pub fn name(self) -> &'static str {
        match self {
            SweepEnd::ReachedEnd => "reached_end",
            SweepEnd::StepTooSmall => "stalled",
            SweepEnd::MaxPoints => "point_cap",
            SweepEnd::LeftBand => "left_band",
            SweepEnd::StoppedByCaller => "cancelled",
        }
    }
}
