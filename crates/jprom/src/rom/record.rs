//! A reduced sweep as one record: the points, the error predictor `e*_h` at each point and the
//! basis corrections that led to the final basis (docs/formulation.md §10). It is what the C
//! API's sweep handle holds and what a saved reduced sweep contains (a jprom `reduced_sweep`
//! document), so `e*` and the corrections survive a save and a load.

use super::adaptive::{AdaptiveSweep, Correction, CorrectionEnd, Trust};
use crate::error::Result;
use crate::hbm::SweepResult;
use crate::jp::JpBasis;
use crate::io::documents::{bad, Check, Document};
use serde::{Deserialize, Serialize};

/// A sweep with its predicted errors and corrections (both empty for a full-order sweep).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SweepRecord {
    /// The points (reduced unknowns in `points[i].z` for a reduced sweep).
    pub sweep: SweepResult,
    /// `e*_h`, `h = 0..=H`, at every point (empty for a full-order sweep).
    #[serde(default)]
    pub predicted_errors: Vec<Vec<f64>>,
    /// Basis corrections of a self-correcting sweep, in order.
    #[serde(default)]
    pub corrections: Vec<Correction>,
    /// How the corrections of a self-correcting sweep ended (`None` for any other sweep, and in
    /// a reduced sweep saved before jprom kept it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome: Option<CorrectionOutcome>,
    /// Whether a self-correcting sweep can be trusted, and why not ([`Trust`]; `None` for any
    /// other sweep and in files saved before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trust: Option<Trust>,
    /// The judged error `e_1` per point of a self-correcting sweep
    /// ([`AdaptiveSweep::judged_errors`]; empty for any other sweep). A non-finite error is
    /// kept as `f64::MAX` (JSON has no infinity); read it with [`SweepRecord::judged_error`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    judged_errors: Vec<f64>,
}

/// How a self-correcting sweep's corrections ended: why, and the judged error of the final
/// pass ([`AdaptiveSweep::worst_error`]), which a caller compares with the threshold: above it,
/// the basis stayed poor.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CorrectionOutcome {
    pub end: CorrectionEnd,
    /// The judged error of the final pass; `None` if it was not finite (a point whose `e*` is
    /// not, which counts as the worst).
    pub worst_error: Option<f64>,
    /// The largest linearised error of the static contact displacement at the final pass'
    /// checks ([`AdaptiveSweep::worst_static_error`], not judged by the corrections);
    /// `None` without checks and in files saved before it existed. A non-finite error is kept
    /// as `f64::MAX` (JSON has no infinity); read it with [`CorrectionOutcome::static_error`],
    /// which gives `+inf` back.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    static_error: Option<f64>,
}

impl CorrectionOutcome {
    /// The static contact displacement's error of the final pass (see the field), `+inf` if
    /// it was not finite; `None` without checks.
    pub fn static_error(&self) -> Option<f64> {
        self.static_error.map(|e| if e == f64::MAX { f64::INFINITY } else { e })
    }
}

impl SweepRecord {
    /// A full-order sweep: no `e*`, no corrections.
    pub fn full_order(sweep: SweepResult) -> Self {
        SweepRecord { sweep, predicted_errors: Vec::new(), corrections: Vec::new(), outcome: None, trust: None, judged_errors: Vec::new() }
    }

    /// A reduced sweep with its predicted errors `e*_h` and no corrections.
    pub fn reduced(sweep: SweepResult, predicted_errors: Vec<Vec<f64>>) -> Self {
        SweepRecord { sweep, predicted_errors, corrections: Vec::new(), outcome: None, trust: None, judged_errors: Vec::new() }
    }

    /// The judged error `e_1` at point `i` of a self-correcting sweep (`+inf` where it was not
    /// finite); `None` for any other sweep, a file saved before it existed, or `i` out of range.
    pub fn judged_error(&self, i: usize) -> Option<f64> {
        self.judged_errors.get(i).map(|&e| if e == f64::MAX { f64::INFINITY } else { e })
    }

    /// Whether the record carries reduced-model data (`e*` or corrections).
    pub fn is_reduced(&self) -> bool {
        !self.predicted_errors.is_empty() || !self.corrections.is_empty()
    }
}

impl SweepRecord {
    /// The record of a self-correcting sweep, and its final basis.
    pub fn with_basis(a: AdaptiveSweep) -> (Self, JpBasis) {
        let static_error = a.worst_static_error().map(|e| if e.is_finite() { e } else { f64::MAX });
        let outcome = CorrectionOutcome { end: a.end, worst_error: a.worst_error.is_finite().then_some(a.worst_error), static_error };
        let judged_errors = a.judged_errors().into_iter().map(|e| if e.is_finite() { e } else { f64::MAX }).collect();
        (SweepRecord { sweep: a.sweep, predicted_errors: a.predicted_errors, corrections: a.corrections, outcome: Some(outcome), trust: Some(a.trust), judged_errors }, a.basis)
    }
}

impl From<AdaptiveSweep> for SweepRecord {
    fn from(a: AdaptiveSweep) -> Self {
        Self::with_basis(a).0
    }
}

impl Document for SweepRecord {
    const KIND: &'static str = "reduced_sweep";
    fn check(&self) -> Result<Check> {
        if let Err((key, reason)) = self.sweep.check()? {
            return Ok(bad(format!("sweep.{key}"), reason));
        }
        let points = &self.sweep.points;
        if !self.predicted_errors.is_empty() && self.predicted_errors.len() != points.len() {
            return Ok(bad("predicted_errors", format!("has {} rows, the sweep has {} points", self.predicted_errors.len(), points.len())));
        }
        for (i, (e, p)) in self.predicted_errors.iter().zip(points).enumerate() {
            let want = p.layout.harmonics + 1;
            if e.len() != want {
                return Ok(bad(format!("predicted_errors[{i}]"), format!("has {} values, H + 1 = {want} expected", e.len())));
            }
            if let Some(h) = e.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
                return Ok(bad(format!("predicted_errors[{i}][{h}]"), format!("must be finite and >= 0, got {}", e[h])));
            }
        }
        let harmonics = points.first().map(|p| p.layout.harmonics);
        for (i, c) in self.corrections.iter().enumerate() {
            if let Some(h) = harmonics {
                if c.sizes.len() != h + 1 {
                    return Ok(bad(format!("corrections[{i}].sizes"), format!("has {} entries, H + 1 = {} expected", c.sizes.len(), h + 1)));
                }
            }
            if c.worst_error_after.is_nan() || c.worst_error_before.is_nan() {
                return Ok(bad(format!("corrections[{i}]"), "a worst error is NaN"));
            }
        }
        if !self.judged_errors.is_empty() && self.judged_errors.len() != points.len() {
            return Ok(bad("judged_errors", format!("has {} values, the sweep has {} points", self.judged_errors.len(), points.len())));
        }
        if let Some(i) = self.judged_errors.iter().position(|v| !(*v >= 0.0)) {
            return Ok(bad(format!("judged_errors[{i}]"), format!("must be >= 0, got {}", self.judged_errors[i])));
        }
        if let Some(CorrectionOutcome { worst_error: Some(w), .. }) = self.outcome {
            if !(w >= 0.0) {
                return Ok(bad("outcome.worst_error", format!("must be >= 0, got {w}")));
            }
        }
        if let Some(CorrectionOutcome { static_error: Some(w), .. }) = self.outcome {
            if !(w >= 0.0) {
                return Ok(bad("outcome.static_error", format!("must be >= 0, got {w}")));
            }
        }
        Ok(Ok(()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_static_error_survives_json_and_older_files_have_none() {
        let round = |o: &CorrectionOutcome| serde_json::from_str::<CorrectionOutcome>(&serde_json::to_string(o).unwrap()).unwrap();
        // a non-finite error (stored as f64::MAX, JSON having no infinity) comes back as +inf
        let inf = CorrectionOutcome { end: CorrectionEnd::MaxCorrections, worst_error: Some(0.2), static_error: Some(f64::MAX) };
        assert_eq!(round(&inf).static_error(), Some(f64::INFINITY));
        let finite = CorrectionOutcome { static_error: Some(0.3), ..inf };
        assert_eq!(round(&finite).static_error(), Some(0.3));
        // without checks, and in a file saved before the field: none, and nothing written for it
        let none = CorrectionOutcome { static_error: None, ..inf };
        assert!(!serde_json::to_string(&none).unwrap().contains("static_error"));
        let old: CorrectionOutcome = serde_json::from_str(r#"{"end":"MaxCorrections","worst_error":0.2}"#).unwrap();
        assert_eq!((old.end, old.static_error()), (CorrectionEnd::MaxCorrections, None));
    }
}
