//! The whole-file consistency of saved solutions and sweeps ([`Document`]): every size against
//! every array, so that no accessor can index out of bounds in a loaded, possibly edited, file.

use super::{HarmonicLayout, PointSolution, SweepEnd, SweepResult};
use crate::error::Result;
use crate::io::documents::{bad, finite, Check, Document, Inconsistency};
use crate::limits::MAX_HARMONICS;

/// The layout's own consistency; returns the number of unknowns.
pub(crate) fn check_layout(key: &str, l: &HarmonicLayout) -> std::result::Result<usize, Inconsistency> {
    if l.harmonics == 0 || l.harmonics > MAX_HARMONICS {
        return Err((format!("{key}.harmonics"), format!("must be in 1..={MAX_HARMONICS}, got {}", l.harmonics)));
    }
    if l.sizes.len() != l.harmonics + 1 {
        return Err((format!("{key}.sizes"), format!("has {} entries, harmonics + 1 = {} expected", l.sizes.len(), l.harmonics + 1)));
    }
    l.sizes[1..]
        .iter()
        .try_fold(0usize, |acc, &s| acc.checked_add(s))
        .and_then(|s| s.checked_mul(2))
        .and_then(|s| s.checked_add(l.sizes[0]))
        .ok_or_else(|| (format!("{key}.sizes"), "the total number of unknowns overflows".to_string()))
}

/// A point's sizes against its arrays (`key` locates it in the file).
fn check_point(key: &str, p: &PointSolution) -> Check {
    let at = |k: &str| format!("{key}{k}");
    if !(p.omega.is_finite() && p.omega > 0.0) {
        return bad(at("omega"), format!("must be finite and > 0, got {}", p.omega));
    }
    let total = check_layout(&at("layout"), &p.layout)?;
    if p.z.len() != total {
        return bad(at("z"), format!("has {} values, the layout {:?} has {total} unknowns", p.z.len(), p.layout.sizes));
    }
    finite(&at("z"), &p.z)?;
    let coeffs = 2 * p.layout.harmonics + 1;
    match coeffs.checked_mul(p.n_outputs) {
        Some(n) if n == p.outputs.len() => {}
        _ => {
            return bad(
                at("outputs"),
                format!("has {} values, (2 H + 1) x n_outputs = {coeffs} x {} expected", p.outputs.len(), p.n_outputs),
            )
        }
    }
    finite(&at("outputs"), &p.outputs)?;
    if !(p.residual_norm.is_finite() && p.residual_norm >= 0.0) {
        return bad(at("residual_norm"), format!("must be finite and >= 0, got {}", p.residual_norm));
    }
    if let Some(first) = p.contact_cycles.first() {
        let ns = first.states.len();
        for (c, cy) in p.contact_cycles.iter().enumerate() {
            if cy.states.len() != ns {
                return bad(at(&format!("contact_cycles[{c}].states")), format!("has {} samples, contact 0 has {ns}", cy.states.len()));
            }
            if !cy.dissipated_energy.is_finite() {
                return bad(at(&format!("contact_cycles[{c}].dissipated_energy")), "is not finite");
            }
        }
    }
    Ok(())
}

impl Document for PointSolution {
    const KIND: &'static str = "solution";
    fn check(&self) -> Result<Check> {
        Ok(check_point("", self))
    }
}

impl Document for SweepResult {
    const KIND: &'static str = "sweep";
    fn check(&self) -> Result<Check> {
        if self.stopped_early != (self.end != SweepEnd::ReachedEnd) {
            return Ok(bad("stopped_early", format!("is {} while end is {:?}", self.stopped_early, self.end)));
        }
        let first = match self.points.first() {
            Some(p) => p,
            None => return Ok(Ok(())),
        };
        for (i, p) in self.points.iter().enumerate() {
            let key = format!("points[{i}].");
            if let Err(e) = check_point(&key, p) {
                return Ok(Err(e));
            }
            if p.layout != first.layout || p.n_outputs != first.n_outputs || p.contact_cycles.len() != first.contact_cycles.len() {
                return Ok(bad(format!("points[{i}]"), "has other sizes (layout, outputs or contacts) than point 0"));
            }
        }
        Ok(Ok(()))
    }
}

