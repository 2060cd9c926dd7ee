//! The rows of a study's results: one solver at one level ([`SolverRow`]) with its folds,
//! branch points and gaps, and the rows of the error-vs-basis-size study ([`BasisStudyRow`]).

use serde::{Deserialize, Serialize};

/// One solver at one excitation level.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SolverRow {
    pub level: f64,
    pub solver: String,
    /// Unknowns per harmonic (`n_0, n_1, ...`).
    pub sizes: Vec<usize>,
    pub points: usize,
    /// Seconds for the sweep (for ROMs: reduced sweeps, error checks and corrections, plus the
    /// level's share of the case's shared basis prediction, its time over the number of levels).
    pub sweep_seconds: f64,
    /// The part of `sweep_seconds` spent on the basis (ROMs; 0 for the full order): the share
    /// of the shared prediction, the ROM's construction with its first reduced point, and for
    /// each correction the error checks that asked for it, its prediction and the new ROM.
    pub basis_seconds: f64,
    /// Basis corrections made by the self-correcting sweep (ROMs).
    pub corrections: usize,
    /// Resonance (largest `X1` at the response output, `output.response`) frequency and amplitude;
    /// NaN (`null` in `summary.json`, `-` in the table) for a sweep without points and for a
    /// reduced sweep that is not trusted (`trusted`).
    pub peak_hz: f64,
    pub peak_x1: f64,
    pub peak_x0: f64,
    /// Errors against the full order at the full-order resonance (ROMs only): of `|X1|` at the
    /// response output, relative; of `X0`, the largest over the outputs relative to the
    /// largest full-order `|X0|` there.
    pub error_x1: Option<f64>,
    pub error_x0: Option<f64>,
    /// Predicted `e*_1` and actual `e_1` there (ROMs only).
    pub predicted_e1: Option<f64>,
    pub actual_e1: Option<f64>,
    /// Largest error of the dissipated energy per contact node there, relative to the largest
    /// energy per contact node met anywhere in the study (ROMs only; `None` when no contact
    /// dissipates anywhere).
    pub energy_error: Option<f64>,
    /// Why the sweep ended (`reached_end`, `stalled`, `point_cap`, `left_band`, `cancelled`),
    /// and whether it covered the band.
    pub end: String,
    /// Why the sweep ended, in words (`reached the band's end`, or why and where it stopped).
    pub end_reason: String,
    pub complete: bool,
    /// What the reader of this row must know: an incomplete sweep (with where and why), a peak
    /// on the band's edge, a level at which every contact sticks, errors taken against an
    /// incomplete full-order sweep.
    pub warnings: Vec<String>,
    /// The error the self-correcting sweep judged its final basis by: the largest `e_lin_1` at
    /// its checks, or the largest `e*_1` without checks (ROMs only; see `rom::adaptive`).
    pub worst_error: Option<f64>,
    /// Why its corrections ended (`within_threshold`, `max_corrections`, `no_progress`,
    /// `cancelled`; ROMs only): the two in the middle leave the basis above the threshold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corrections_end: Option<String>,
    /// The largest linearised error of the static contact displacement at the final pass'
    /// checks (ROMs whose condensed full order is small enough to check; see
    /// `rom::AdaptiveSweep::worst_static_error`). Not judged by the corrections; above
    /// `basis.error_threshold` the static term `X0` is poor and `warnings` says so.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub static_contact_error: Option<f64>,
    /// Whether the self-correcting sweep's result can be trusted (ROMs only): its final pass
    /// covered the band and every point's judged error is within the threshold
    /// (docs/formulation.md §10.7). The peak of a row that is not trusted is not reported
    /// (`peak_*` are empty) and `trust_reason` and `warnings` say why.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trusted: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trust_reason: Option<String>,
    /// A full-order row that gives its level's result in place of reduced sweeps that are not
    /// trusted or did not finish (`solvers.fall_back`, [`crate::fall_back`]): each such
    /// `solver: why`. Empty otherwise (and not in `summary.json`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stands_in_for: Vec<String>,
    /// The full-order sweep's time at this level over this ROM's (`sweep_seconds`, with its
    /// share of the shared basis) (ROMs only, when the full order ran).
    #[serde(default)]
    pub speed_up: Option<f64>,
    /// The parameter case (`[[cases]]`) of the row; empty (and not in `summary.json`) for a
    /// study without cases.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub case: String,
    /// The folds and branch points located along the sweep, in branch order
    /// (docs/formulation.md §6.6).
    #[serde(default)]
    pub events: Vec<EventRow>,
    /// The parts of the band the sweep stepped over at fixed frequency, with why.
    #[serde(default)]
    pub gaps: Vec<GapRow>,
}

/// A fold or branch point of a sweep, in the study's units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EventRow {
    /// `fold` or `branch_point`.
    pub kind: String,
    pub freq_hz: f64,
    /// The event lies within `freq_hz +- tolerance_hz` along the branch.
    pub tolerance_hz: f64,
    /// Index (0-based) of the sweep's point just before it, the row of the sweep's CSV.
    pub after_point: usize,
    /// First-harmonic amplitude of the first output there.
    pub amplitude: f64,
}

/// A part of the band a sweep stepped over at fixed frequency.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GapRow {
    pub from_hz: f64,
    pub to_hz: f64,
    /// Why the continuation could not go on there.
    pub reason: String,
}

/// One basis of the error-vs-basis-size study (`basis.gamma_study`) with one ROM, solved at the
/// full-order resonance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BasisStudyRow {
    pub level: f64,
    pub solver: String,
    pub gamma: f64,
    /// Reduced unknowns per harmonic `n_0, n_1, ...` of the ROM (for FR on a band-condensed
    /// basis about twice the JP basis' `n_1`, see [`FrRom::new`]).
    pub sizes: Vec<usize>,
    /// Errors of `X1` and `X0` as [`SolverRow::error_x1`], `error_x0` (`None`: the ROM did not
    /// converge).
    pub error_x1: Option<f64>,
    pub error_x0: Option<f64>,
    /// Predicted `e*_1` and actual `e_1`.
    pub predicted_e1: Option<f64>,
    pub actual_e1: Option<f64>,
    /// The parameter case, as [`SolverRow::case`].
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub case: String,
}
