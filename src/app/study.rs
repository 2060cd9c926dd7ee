//! The study file read by the `jprom` command-line program: what to model, how to force it,
//! which band and harmonics, which bases and which solvers. TOML (or JSON, by extension).
//!
//! ```toml
//! [model]
//! kind = "blade"            # built-in shrouded blade, or "matrix_market"
//! refinement = 1            # blade only: 1 -> 18 contact nodes, 2 -> ~200, 3 -> ~2,000
//! cb_modes = 50             # Craig-Bampton fixed-interface modes
//! damping_ratio = 0.002     # modal damping ratio at the band centre (stiffness-proportional)
//!
//! [band]
//! hz_start = 2140.0
//! hz_end = 2190.0
//! points = 200              # target number of points per sweep
//!
//! [hbm]
//! harmonics = 1
//! nt = 64
//!
//! [forcing]
//! levels = [0.1, 0.001]     # alpha / alpha_ST
//!
//! [basis]
//! gamma = 1000.0
//! samples = 100
//! error_threshold = 0.05
//! max_corrections = 3
//!
//! [solvers]
//! full_order = true
//! fr = true
//! nlr = true
//!
//! [output]
//! dir = "jprom-out"
//! ```
//!
//! Unknown keys are errors, and every error names the offending key.

use crate::error::{JpError, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A whole study.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Study {
    pub model: ModelSpec,
    #[serde(default)]
    pub band: BandSpec,
    #[serde(default)]
    pub hbm: HbmSpec,
    #[serde(default)]
    pub forcing: ForcingSpec,
    #[serde(default)]
    pub basis: BasisSpec,
    #[serde(default)]
    pub solvers: SolverSpec,
    #[serde(default)]
    pub output: OutputSpec,
}

/// Where the structure comes from.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ModelSpec {
    /// The built-in shrouded blade (method.md §11).
    Blade {
        #[serde(default = "one")]
        refinement: usize,
        #[serde(default = "fifty")]
        cb_modes: usize,
        #[serde(default = "default_damping_ratio")]
        damping_ratio: f64,
        #[serde(default)]
        contact: ContactSpec,
    },
    /// Matrix Market `M`, `K` and a node/DoF map placing contacts, outputs and forces.
    MatrixMarket {
        mass: PathBuf,
        stiffness: PathBuf,
        dof_map: PathBuf,
        #[serde(default = "fifty")]
        cb_modes: usize,
        #[serde(default = "default_damping_ratio")]
        damping_ratio: f64,
        #[serde(default)]
        contact: ContactSpec,
    },
}

/// Contact parameters per node (defaults: method.md §11).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSpec {
    pub mu: f64,
    pub kt1: f64,
    pub kt2: f64,
    pub kn: f64,
}

impl Default for ContactSpec {
    fn default() -> Self {
        ContactSpec { mu: 0.4, kt1: 2.0126e4, kt2: 2.0059e4, kn: 2.34152e4 }
    }
}

/// Frequency band, in Hz.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct BandSpec {
    pub hz_start: f64,
    pub hz_end: f64,
    pub points: usize,
}

impl Default for BandSpec {
    fn default() -> Self {
        BandSpec { hz_start: 2140.0, hz_end: 2190.0, points: 200 }
    }
}

/// Harmonic balance settings.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct HbmSpec {
    pub harmonics: usize,
    pub nt: usize,
}

impl Default for HbmSpec {
    fn default() -> Self {
        HbmSpec { harmonics: 1, nt: 64 }
    }
}

/// Excitation levels, as `alpha / alpha_ST`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct ForcingSpec {
    pub levels: Vec<f64>,
}

impl Default for ForcingSpec {
    fn default() -> Self {
        ForcingSpec { levels: vec![0.1, 1e-3] }
    }
}

/// JP basis options.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct BasisSpec {
    pub gamma: f64,
    pub samples: usize,
    pub error_threshold: f64,
    /// Most basis corrections of the self-correcting sweep per level and ROM.
    pub max_corrections: usize,
}

impl Default for BasisSpec {
    fn default() -> Self {
        BasisSpec { gamma: 1e3, samples: 100, error_threshold: 0.05, max_corrections: 3 }
    }
}

/// Which solvers run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    pub full_order: bool,
    pub fr: bool,
    pub nlr: bool,
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec { full_order: true, fr: true, nlr: true }
    }
}

/// Where results go.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct OutputSpec {
    pub dir: PathBuf,
    pub plots: bool,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec { dir: PathBuf::from("jprom-out"), plots: true }
    }
}

fn one() -> usize {
    1
}
fn fifty() -> usize {
    50
}
fn default_damping_ratio() -> f64 {
    0.002
}

impl Study {
    /// Reads a study from a `.toml` or `.json` file and validates it.
    ///
    /// # Errors
    /// [`JpError::Parse`] naming the file, the line where known, the offending key and the reason.
    pub fn from_file(path: &Path) -> Result<Study> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| JpError::Io { path: path.display().to_string(), reason: e.to_string() })?;
        let is_json = path.extension().map(|e| e == "json").unwrap_or(false);
        let study = if is_json { Self::from_json_str(&text) } else { Self::from_toml_str(&text) };
        study.map_err(|e| match e {
            JpError::Parse { line, reason, .. } => JpError::Parse { path: path.display().to_string(), line, reason },
            other => other,
        })
    }

    /// Parses and validates TOML text.
    pub fn from_toml_str(text: &str) -> Result<Study> {
        let de = toml::Deserializer::parse(text).map_err(|e| parse_error(text, e.span().map(|s| s.start), e.message()))?;
        let study: Study = serde_path_to_error::deserialize(de).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            parse_error(text, inner.span().map(|s| s.start), &format!("key '{key}': {}", inner.message()))
        })?;
        study.validate()?;
        Ok(study)
    }

    /// Parses and validates JSON text.
    pub fn from_json_str(text: &str) -> Result<Study> {
        let mut de = serde_json::Deserializer::from_str(text);
        let study: Study = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            JpError::Parse { path: "<study>".into(), line: inner.line(), reason: format!("key '{key}': {inner}") }
        })?;
        study.validate()?;
        Ok(study)
    }

    /// Range and consistency checks; each error names its key.
    pub fn validate(&self) -> Result<()> {
        let bad = |key: &str, reason: String| Err(JpError::Parse { path: "<study>".into(), line: 0, reason: format!("key '{key}': {reason}") });
        let (cb_modes, damping_ratio, contact) = match &self.model {
            ModelSpec::Blade { refinement, cb_modes, damping_ratio, contact } => {
                if !(1..=3).contains(refinement) {
                    return bad("model.refinement", format!("must be 1, 2 or 3, got {refinement}"));
                }
                (*cb_modes, *damping_ratio, contact)
            }
            ModelSpec::MatrixMarket { cb_modes, damping_ratio, contact, .. } => (*cb_modes, *damping_ratio, contact),
        };
        if cb_modes == 0 {
            return bad("model.cb_modes", "must be at least 1".into());
        }
        if !(damping_ratio.is_finite() && damping_ratio >= 0.0) {
            return bad("model.damping_ratio", format!("must be finite and >= 0, got {damping_ratio}"));
        }
        for (k, v) in [("mu", contact.mu), ("kt1", contact.kt1), ("kt2", contact.kt2), ("kn", contact.kn)] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(&format!("model.contact.{k}"), format!("must be finite and >= 0, got {v}"));
            }
        }
        let b = &self.band;
        if !(b.hz_start.is_finite() && b.hz_start > 0.0) {
            return bad("band.hz_start", format!("must be finite and > 0, got {}", b.hz_start));
        }
        if !(b.hz_end.is_finite() && b.hz_end > b.hz_start) {
            return bad("band.hz_end", format!("must be finite and > band.hz_start, got {}", b.hz_end));
        }
        if b.points < 2 {
            return bad("band.points", format!("must be at least 2, got {}", b.points));
        }
        if !(1..=16).contains(&self.hbm.harmonics) {
            return bad("hbm.harmonics", format!("must be in 1..=16, got {}", self.hbm.harmonics));
        }
        let nt = self.hbm.nt;
        if !nt.is_power_of_two() || nt < 4 * (self.hbm.harmonics + 1) {
            return bad("hbm.nt", format!("must be a power of two >= 4 (harmonics + 1), got {nt}"));
        }
        if self.forcing.levels.is_empty() {
            return bad("forcing.levels", "needs at least one level".into());
        }
        for (i, &l) in self.forcing.levels.iter().enumerate() {
            if !(l.is_finite() && l > 0.0) {
                return bad(&format!("forcing.levels[{i}]"), format!("must be finite and > 0, got {l}"));
            }
        }
        if !(self.basis.gamma.is_finite() && self.basis.gamma >= 1.0) {
            return bad("basis.gamma", format!("must be finite and >= 1, got {}", self.basis.gamma));
        }
        if self.basis.samples < 2 {
            return bad("basis.samples", format!("must be at least 2, got {}", self.basis.samples));
        }
        if !(self.basis.error_threshold.is_finite() && self.basis.error_threshold > 0.0) {
            return bad("basis.error_threshold", format!("must be finite and > 0, got {}", self.basis.error_threshold));
        }
        if !(self.solvers.full_order || self.solvers.fr || self.solvers.nlr) {
            return bad("solvers", "enable at least one of full_order, fr, nlr".into());
        }
        Ok(())
    }
}

fn parse_error(text: &str, offset: Option<usize>, reason: &str) -> JpError {
    let line = offset.map(|o| text[..o.min(text.len())].lines().count().max(1)).unwrap_or(0);
    JpError::Parse { path: "<study>".into(), line, reason: reason.to_string() }
}
