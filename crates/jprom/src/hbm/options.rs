//! Settings of the HBM point solver ([`HbmOptions`]) and of the continuation ([`SweepOptions`]).

use crate::error::{JpError, Result};
use serde::{Deserialize, Serialize};

/// Settings of the Newton solve of one harmonic-balance point (docs/formulation.md §5). The
/// harmonics and AFT samples are the system's ([`crate::aft::Discretisation`], given when it is
/// built), not the solver's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HbmOptions {
    /// Converged when `|r| <= residual_tolerance * |f_ref|`, with `f_ref` the larger of the
    /// external force norm and the contact force norm at the initial guess (default `1e-10`).
    pub residual_tolerance: f64,
    /// Stagnation: the solve stops with [`JpError::NoConvergence`] when a scaled step is below
    /// `step_tolerance * (1 + |scaled z|)` while the residual is still above tolerance
    /// (default `1e-14`).
    pub step_tolerance: f64,
    /// Most Newton iterations (Jacobian evaluations) per point, all attempts together: the
    /// solve from the guess gets a quarter of them, the load-stepping fallback half of the rest
    /// and the continuation in the forcing level what is left
    /// (default 400; a point that converges at all usually takes fewer than 10, but a reduced
    /// model solved from zero near a resonance in partial slip was measured at 94).
    pub max_iterations: usize,
    /// Dogleg trust region on the scaled problem (default true). When false, plain Newton.
    pub trust_region: bool,
    /// Initial trust radius as a multiple of the first full Newton step's scaled length
    /// (default 1: the first Newton step is always tried in full).
    pub initial_radius_factor: f64,
    /// Scale unknowns by the Jacobian's column norms and the residual by `f_ref`
    /// (default true). Without it the trust region acts on the raw unknowns.
    pub scaling: bool,
}

pub use crate::aft::default_nt;

impl Default for HbmOptions {
    fn default() -> Self {
        HbmOptions {
            residual_tolerance: 1e-10,
            step_tolerance: 1e-14,
            max_iterations: 400,
            trust_region: true,
            initial_radius_factor: 1.0,
            scaling: true,
        }
    }
}

impl HbmOptions {
    /// Checks ranges.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the bad option.
    pub fn validate(&self) -> Result<()> {
        positive("HbmOptions.residual_tolerance", self.residual_tolerance)?;
        if !(self.step_tolerance.is_finite() && self.step_tolerance >= 0.0) {
            return Err(JpError::invalid("HbmOptions.step_tolerance", "must be finite and >= 0"));
        }
        if self.max_iterations == 0 {
            return Err(JpError::invalid("HbmOptions.max_iterations", "must be >= 1"));
        }
        positive("HbmOptions.initial_radius_factor", self.initial_radius_factor)
    }
}

/// Settings of the pseudo-arclength continuation over a frequency band (see
/// [`super::continuation`] for how they act).
///
/// Arclength is measured on scaled variables: `omega / |omega_end - omega_start|` and
/// `z / z_ref`, with `z_ref` the largest norm of the harmonic (`h >= 1`) part of `z` met so far
/// on the branch. A step of 0.05 thus moves at most 5 % of the band in frequency, or changes
/// the response by at most 5 % of its largest value so far.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SweepOptions {
    /// Start and end of the band (rad/s); the sweep goes from start towards end (either way).
    pub omega_start: f64,
    pub omega_end: f64,
    /// First arclength step (default 0.02; clamped into `[min_step, max_step]`), smallest
    /// (default 1e-6) and largest (default 0.1).
    pub initial_step: f64,
    pub min_step: f64,
    pub max_step: f64,
    /// Largest frequency increment of one step, as a fraction of the band (default 0.02: at
    /// least 50 points across the band).
    pub max_omega_step: f64,
    /// Largest angle (radians) between the tangents at two successive points (default 0.15);
    /// a step that turns more is retried shorter, and the step size aims at half of it.
    pub max_angle: f64,
    /// Most points on the branch, start included (default 5000).
    pub max_points: usize,
    /// Corrector Newton iterations before a step is rejected and halved (default 12; never
    /// more than [`HbmOptions::max_iterations`]).
    pub max_corrector_iterations: usize,
    /// Corrector iterations aimed at: the next step is scaled by `target / used`, clamped to
    /// `[0.5, 2]` (default 4).
    pub target_iterations: usize,
    /// Relative frequency increment of the central difference `dR/domega` (default 1e-6), for
    /// systems without its closed form
    /// ([`crate::hbm::HarmonicSystem::linear_part_with_derivative_into`]; the condensed systems
    /// have it and do not use this).
    pub omega_difference: f64,
    /// How steps are oriented, accepted and sized (default
    /// [`ContinuationMethod::Oriented`]; docs/formulation.md §6).
    pub method: ContinuationMethod,
}

/// The continuation's predictor, orientation and acceptance rules (docs/formulation.md §6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContinuationMethod {
    /// Tangent predictor oriented by the sign of the determinant of the bordered Jacobian
    /// `[J_z R_omega; t^T S]` (constant along a regular branch, through folds and through the
    /// corners where contacts change state); a step is accepted when it lies ahead along the
    /// tangents at both of its ends; corners crossed along the tangent of the next piece;
    /// where no step converges, a gap stepped over at fixed frequency and marked.
    #[default]
    Oriented,
    /// The earlier rules: secant predictor oriented along the last chord, sharp-turn retries,
    /// corner and kink rules and fixed-frequency restarts, kept for comparison.
    Secant,
}

impl Default for SweepOptions {
    fn default() -> Self {
        SweepOptions {
            omega_start: 0.0,
            omega_end: 0.0,
            initial_step: 0.02,
            min_step: 1e-6,
            max_step: 0.1,
            max_omega_step: 0.02,
            max_angle: 0.15,
            max_points: 5000,
            max_corrector_iterations: 12,
            target_iterations: 4,
            omega_difference: 1e-6,
            method: ContinuationMethod::Oriented,
        }
    }
}

impl SweepOptions {
    /// A sweep over `[omega_start, omega_end]` with the default steps.
    pub fn band(omega_start: f64, omega_end: f64) -> Self {
        SweepOptions { omega_start, omega_end, ..Default::default() }
    }

    /// A sweep over the band aiming at about `points` points where the response is smooth
    /// (`max_omega_step = 1 / points`); resonances and folds get more, set by `max_angle`.
    pub fn with_points(omega_start: f64, omega_end: f64, points: usize) -> Self {
        let points = points.max(1) as f64;
        SweepOptions { max_omega_step: 1.0 / points, initial_step: (0.5 / points).max(1e-6), ..Self::band(omega_start, omega_end) }
    }

    /// Checks ranges.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the bad option.
    pub fn validate(&self) -> Result<()> {
        positive("SweepOptions.omega_start", self.omega_start)?;
        positive("SweepOptions.omega_end", self.omega_end)?;
        if self.omega_start == self.omega_end {
            return Err(JpError::invalid("SweepOptions.omega_end", "must differ from omega_start"));
        }
        positive("SweepOptions.min_step", self.min_step)?;
        positive("SweepOptions.initial_step", self.initial_step)?;
        positive("SweepOptions.max_step", self.max_step)?;
        if self.min_step > self.max_step {
            return Err(JpError::invalid("SweepOptions.min_step", format!("must be <= max_step ({} > {})", self.min_step, self.max_step)));
        }
        positive("SweepOptions.max_omega_step", self.max_omega_step)?;
        positive("SweepOptions.max_angle", self.max_angle)?;
        if self.max_angle >= std::f64::consts::FRAC_PI_2 {
            return Err(JpError::invalid("SweepOptions.max_angle", format!("must be below pi/2, got {}", self.max_angle)));
        }
        if self.max_points < 2 {
            return Err(JpError::invalid("SweepOptions.max_points", "must be >= 2"));
        }
        if self.max_corrector_iterations == 0 || self.target_iterations == 0 {
            return Err(JpError::invalid("SweepOptions iterations", "must be >= 1"));
        }
        positive("SweepOptions.omega_difference", self.omega_difference)
    }
}

fn positive(what: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(JpError::invalid(what, format!("must be finite and > 0, got {v}")))
    }
}

/// Checks an angular frequency: finite and `> 0`.
///
/// # Errors
/// [`JpError::InvalidValue`] naming `omega`.
pub fn check_omega(omega: f64) -> Result<()> {
    crate::error::check_finite("omega", &[omega])?;
    if omega <= 0.0 {
        return Err(JpError::invalid("omega", format!("must be > 0, got {omega}")));
    }
    Ok(())
}
