//! The jprom documents (model, solution, sweep, basis) and the whole-file consistency check
//! each gets on loading: every size against every array, so that no accessor can index out
//! of bounds in a loaded (possibly hand-edited) file, and the sizes against jprom's caps.
//! An inconsistency is a [`JpError::Parse`] naming the key and its line.

use super::locate::json_line;
use crate::error::{JpError, Result};
use crate::hbm::{HarmonicLayout, PointSolution, SweepEnd, SweepResult};
use crate::jp::JpBasis;
use crate::limits::MAX_HARMONICS;
use crate::model::Model;
use serde::{de::DeserializeOwned, Serialize};
use std::path::Path;

/// A key (as in messages, relative to the envelope's `data`) and what is wrong there.
pub type Inconsistency = (String, String);

/// A kind of jprom JSON document.
pub trait Document: Serialize + DeserializeOwned {
    /// The envelope's `kind`.
    const KIND: &'static str;
    /// Whole-document consistency. `Ok(Err(..))` names a key of the file that is
    /// inconsistent; `Err` is a domain error (e.g. a model that does not validate).
    fn check(&self) -> Result<std::result::Result<(), Inconsistency>>;
}

/// Reads, parses and checks a document of kind `T::KIND` (see [`super::load_json`]).
///
/// # Errors
/// As [`super::load_json`]; [`JpError::Parse`] naming the key and line of an inconsistency;
/// the document's own validation errors (a model: [`Model::validate`]).
pub fn load_document<T: Document>(path: &Path) -> Result<T> {
    let text = super::read_text(path)?;
    parse_document(&text, &path.display().to_string())
}

/// [`load_document`] on a text already read; `name` is used in messages.
pub fn parse_document<T: Document>(text: &str, name: &str) -> Result<T> {
    let doc: T = super::parse_json(T::KIND, text, name)?;
    if let Err((key, reason)) = doc.check()? {
        let full = format!("data.{key}");
        return Err(JpError::Parse {
            path: name.to_string(),
            line: json_line(text, &super::steps(&full)).unwrap_or(0),
            reason: format!("key '{full}': {reason}"),
        });
    }
    Ok(doc)
}

type Check = std::result::Result<(), Inconsistency>;

fn bad(key: impl Into<String>, reason: impl Into<String>) -> Check {
    Err((key.into(), reason.into()))
}

fn finite(key: &str, v: &[f64]) -> Check {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => bad(format!("{key}[{i}]"), format!("is not finite ({})", v[i])),
    }
}

impl Document for Model {
    const KIND: &'static str = "model";
    fn check(&self) -> Result<Check> {
        self.validate()?;
        Ok(Ok(()))
    }
}

/// The layout's own consistency; returns the number of unknowns.
fn check_layout(key: &str, l: &HarmonicLayout) -> std::result::Result<usize, Inconsistency> {
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

impl Document for JpBasis {
    const KIND: &'static str = "basis";
    fn check(&self) -> Result<Check> {
        Ok(check_basis(self))
    }
}

fn check_basis(b: &JpBasis) -> Check {
    if b.phi.len() < 2 || b.phi.len() > MAX_HARMONICS + 1 {
        return bad("phi", format!("has {} harmonics' matrices, 2..={} (h = 0..=H) expected", b.phi.len(), MAX_HARMONICS + 1));
    }
    if b.sizes.len() != b.phi.len() {
        return bad("sizes", format!("has {} entries, phi has {} matrices (h = 0..=H)", b.sizes.len(), b.phi.len()));
    }
    if b.singular_values.len() != b.phi.len() {
        return bad("singular_values", format!("has {} lists, phi has {} matrices", b.singular_values.len(), b.phi.len()));
    }
    if b.n_w > b.n_dof {
        return bad("n_w", format!("{} contact coordinates in a model of n_dof = {}", b.n_w, b.n_dof));
    }
    for (h, p) in b.phi.iter().enumerate() {
        if p.nrows() != b.n_dof {
            return bad(format!("phi[{h}].nrows"), format!("harmonic {h} has {} rows, n_dof is {}", p.nrows(), b.n_dof));
        }
        if p.ncols() != b.sizes[h] {
            return bad(format!("phi[{h}].ncols"), format!("harmonic {h} has {} columns, sizes[{h}] is {}", p.ncols(), b.sizes[h]));
        }
        for j in 0..p.ncols() {
            for i in 0..p.nrows() {
                if !p[(i, j)].is_finite() {
                    return bad(format!("phi[{h}].data"), format!("entry ({i}, {j}) is not finite"));
                }
            }
        }
        finite(&format!("singular_values[{h}]"), &b.singular_values[h])?;
    }
    if !(b.gamma.is_finite() && b.gamma >= 1.0) {
        return bad("gamma", format!("must be finite and >= 1, got {}", b.gamma));
    }
    if let Some((lo, hi)) = b.band {
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > 0.0) {
            return bad("band", format!("must be two finite positive frequencies, got ({lo}, {hi})"));
        }
    }
    Ok(())
}
