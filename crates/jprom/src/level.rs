//! Excitation levels (docs/formulation.md §12): the forcing level `alpha = |f_E^0| / |f_E^1|` is measured
//! against `alpha_ST`, the level at which the linear stuck response at the stuck resonance just
//! reaches the friction limit at its first contact. Studies give levels as `alpha / alpha_ST`:
//! `1` is the onset of slip, `1/10` partial slip, `1/3000` gross slip on the built-in blade.
//!
//! **Contacts closed by a preload alone.** With no static load (`f_E^0 = 0`, the contacts held
//! shut by `n0`), `alpha` is zero at every forcing and `alpha_ST` is not defined. The stuck
//! limit still is: it is the dynamic scale `s_ST` at which the first contact reaches
//! `mu N0` in the linear stuck response. jprom then measures levels by the forcing itself:
//! level `l` means the dynamic scale `s_ST / l`, exactly as `alpha / alpha_ST = l` does when
//! there is a static load (`alpha` is inversely proportional to the scale). So a study's
//! `levels` mean the same thing for both kinds of model.
//!
//! **No stuck state at all.** If a contact is already at its friction limit (or open) in the
//! static state, any vibration makes it slip and there is no stuck limit. The levels then scale
//! the forcing as given: level `l` means the dynamic scale `1 / l`, and
//! [`StuckLimit::describe`] names the contact and why.

use crate::contact::ContactLaw;
use crate::error::{JpError, Result};
use crate::model::ContactCoordinates;

/// What the levels of a study are measured against.
#[derive(Clone, Debug, PartialEq)]
pub enum LevelReference {
    /// The stuck limit: level `l` is the dynamic scale `s_ST / l`.
    StuckLimit,
    /// No stuck state (a contact slides or is open in the static state, named in the text):
    /// level `l` is the dynamic scale `1 / l` of the forcing as given.
    GivenForcing { why: String },
}

/// The stuck limit of a model at its stuck resonance.
#[derive(Clone, Debug, PartialEq)]
pub struct StuckLimit {
    /// Stuck resonance (rad/s) the limit is taken at.
    pub omega_stuck: f64,
    /// Dynamic scale `s_ST` ([`crate::model::Excitation::dynamic_scale`]) at the limit, for a
    /// model whose `dynamic_scale` was 1 when `coords` were built (else relative to it).
    pub scale: f64,
    /// `alpha_ST = |f_E^0| / (s_ST |f_E^1|)`; `None` without a static load (contacts closed by
    /// their preload alone, see the module doc).
    pub alpha: Option<f64>,
    /// Norm of the first-harmonic force at the limit, `s_ST |f_E^1|`.
    pub force: f64,
    /// What the levels are relative to.
    pub reference: LevelReference,
}

impl StuckLimit {
    /// The dynamic scale of level `l = alpha / alpha_ST` (`s_ST / l`).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] unless `l` is finite and `> 0` and the scale is finite.
    pub fn scale_at(&self, level: f64) -> Result<f64> {
        let s = self.scale / level;
        if !(level.is_finite() && level > 0.0 && s.is_finite() && s > 0.0) {
            return Err(JpError::invalid("excitation level", format!("must be finite and > 0 with a finite forcing, got {level}")));
        }
        Ok(s)
    }

    /// One line for a report: `alpha_ST = ...`, or why there is none.
    pub fn describe(&self) -> String {
        if let LevelReference::GivenForcing { why } = &self.reference {
            return format!("alpha_ST: none, there is no stuck state ({why}); levels scale the given forcing (level l = dynamic scale 1/l)");
        }
        match self.alpha {
            Some(a) => format!("alpha_ST = {a:.4e}"),
            None => format!(
                "alpha_ST: none (no static load, the contacts are closed by their preload); levels are relative to the stuck-limit forcing |f_E^1| = {:.4e}",
                self.force
            ),
        }
    }
}

/// The stuck limit at `omega_stuck` from the static solution `static_z` (see
/// [`stuck_limit_scale`]), with `alpha_ST` where there is a static load.
///
/// # Errors
/// As [`stuck_limit_scale`].
/// A contact already at its limit in the static state has no stuck limit: the levels then
/// scale the forcing as given ([`LevelReference::GivenForcing`]).
///
/// # Errors
/// [`JpError::InvalidValue`] if no contact ever reaches a limit (no finite scale: no contact,
/// or a forcing that never moves them), or if the model has no damping (the stuck response at
/// the stuck resonance is unbounded).
pub fn stuck_limit(coords: &ContactCoordinates, static_z: &[f64], omega_stuck: f64) -> Result<StuckLimit> {
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (fc, fs) = &coords.harmonic_force[0];
    // the transformed forces carry the model's current scale
    let f1 = (norm(fc).powi(2) + norm(fs).powi(2)).sqrt();
    let f0 = norm(&coords.static_force);
    let (scale, reference) = match limit_scale(coords, static_z, omega_stuck)? {
        (s, _) if s > 0.0 => (s, LevelReference::StuckLimit),
        (_, why) => (1.0, LevelReference::GivenForcing { why }),
    };
    let force = scale * f1;
    let alpha = (f0 > 0.0 && reference == LevelReference::StuckLimit).then(|| f0 / force);
    Ok(StuckLimit { omega_stuck, scale, alpha, force, reference })
}

/// The dynamic scale at which the linear stuck response at the stuck resonance `omega_st`
/// just reaches the friction limit at the first contact: every contact `c` satisfies
/// `|T0_c| + s |T1_c| <= mu N0_c` and `s kn |v1_c| <= N0_c`, with `T0`, `N0` from the static
/// solution and `T1`, `v1` the first-harmonic amplitudes per unit scale.
///
/// The scale multiplies the first-harmonic forces of `coords`, which carry the model's
/// `dynamic_scale`; for a model at `dynamic_scale = 1` it is the dynamic scale `s_ST` itself.
/// Jenkins elements count with `|T0| + s |T1| <= mu * normal_load`.
///
/// # Errors
/// [`JpError::InvalidValue`] if no contact ever reaches a limit (no finite scale), or if the
/// model has no damping at `omega_st` (the stuck response there is unbounded).
pub fn stuck_limit_scale(coords: &ContactCoordinates, static_z: &[f64], omega_st: f64) -> Result<f64> {
    match limit_scale(coords, static_z, omega_st)? {
        (s, _) if s > 0.0 => Ok(s),
        (_, why) => Err(JpError::invalid("excitation", format!("no stuck state: {why}"))),
    }
}

/// [`stuck_limit_scale`], or 0 and the first contact at its limit in the static state.
fn limit_scale(coords: &ContactCoordinates, static_z: &[f64], omega_st: f64) -> Result<(f64, String)> {
    let n = coords.n_dof;
    let (d, rhs) = coords.first_harmonic_complex(&coords.stuck_stiffness(), omega_st)?;
    // Undamped (no imaginary part in D), the linear stuck response at the stuck resonance is
    // unbounded: the solve below would return round-off-sized scales (1e-14 on the CalculiX
    // block), silently.
    if (0..n).all(|j| (0..n).all(|i| d[(i, j)].im == 0.0)) {
        return Err(JpError::invalid(
            "stuck limit",
            format!("the model has no damping: its linear stuck response at the stuck resonance ({omega_st:.6e} rad/s) is unbounded, so alpha_ST is not defined; set viscous, modal or hysteretic damping first"),
        ));
    }
    let q = crate::linalg::DenseLu::new(&d).solve(&rhs);
    let mut scale = f64::INFINITY;
    let mut why = String::new();
    // A Parallel block's members each have their own limit; a polynomial spring has none.
    let members = coords.laws.iter().zip(&coords.offsets).enumerate().flat_map(|(c, (l, &off))| l.members().iter().map(move |m| (c, m, off)));
    for (c, law, off) in members {
        if let ContactLaw::Friction2D { kt, kn, mu, n0 } = *law {
            let n_static = n0 + kn * static_z[off + 1];
            let (t0, t1, v1) = (kt * static_z[off].abs(), kt * q[(off, 0)].norm(), kn * q[(off + 1, 0)].norm());
            if n_static <= 0.0 {
                why = format!("2D contact {c} is open in the static state (normal force {n_static:.3e})");
                scale = 0.0;
            } else if t0 >= mu * n_static * (1.0 - 1e-9) {
                why = format!("2D contact {c} slides in the static state (|T0| / N0 = {:.3} >= mu = {mu})", t0 / n_static);
                scale = 0.0;
            }
            if t1 > 0.0 {
                scale = scale.min((mu * n_static - t0).max(0.0) / t1);
            }
            if v1 > 0.0 {
                scale = scale.min(n_static.max(0.0) / v1);
            }
        } else if let ContactLaw::Unilateral { kn, n0 } = *law {
            // A preloaded spring's limit is its opening; one open (a gap) in the static state
            // sets no limit of the stuck (closed) linear response.
            let n_static = n0 + kn * static_z[off];
            let v1 = kn * q[(off, 0)].norm();
            if n_static > 0.0 && v1 > 0.0 {
                scale = scale.min(n_static / v1);
            }
        } else if let ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 } = *law {
            let n_static = n0 + kn * static_z[off + 2];
            let t0 = (kt1 * static_z[off]).hypot(kt2 * static_z[off + 1]);
            let t1 = (kt1 * q[(off, 0)].norm()).hypot(kt2 * q[(off + 1, 0)].norm());
            let v1 = kn * q[(off + 2, 0)].norm();
            if n_static <= 0.0 {
                why = format!("contact {c} is open in the static state (normal force {n_static:.3e})");
                scale = 0.0;
            } else if t0 >= mu * n_static * (1.0 - 1e-9) {
                why = format!("contact {c} slides in the static state (|T0| / N0 = {:.3} >= mu = {mu})", t0 / n_static);
                scale = 0.0;
            }
            if t1 > 0.0 {
                scale = scale.min((mu * n_static - t0).max(0.0) / t1);
            }
            if v1 > 0.0 {
                scale = scale.min(n_static.max(0.0) / v1);
            }
        } else if let ContactLaw::Jenkins { kt, mu, normal_load } = *law {
            let (t0, t1) = (kt * static_z[off].abs(), kt * q[(off, 0)].norm());
            if t0 >= mu * normal_load * (1.0 - 1e-9) {
                why = format!("Jenkins element {c} slides in the static state");
                scale = 0.0;
            }
            if t1 > 0.0 {
                scale = scale.min((mu * normal_load - t0).max(0.0) / t1);
            }
        }
    }
    if !scale.is_finite() {
        return Err(JpError::invalid("excitation", "no contact ever reaches its limit (no contact, or no first-harmonic force on them)"));
    }
    Ok((scale, why))
}

