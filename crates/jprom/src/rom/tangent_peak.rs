//! Where a reduced model's response peaks in a band, estimated from one of its solutions
//! without sweeping it (docs/formulation.md §10.5): the self-correcting sweep screens candidate
//! bases there as well as where the bases before them were poor.
//!
//! At a solution `z0` at `omega0` the Jacobian splits into the linear part and the contacts'
//! tangent, `J(omega0, z0) = D(omega0) + K_c` with `K_c = W^T K̂(z0) W`. Holding the contacts
//! in that state, the tangent response to the harmonic forces,
//!
//! ```text
//! (D(omega) + K_c) dz = f_h(omega),
//! ```
//!
//! is a linear problem per frequency of the reduced model's size; the frequency where the
//! harmonic part of `dz` is largest estimates the resonance. At gross slip, where the
//! contacts slip over the whole band, the tangent at the band's start is the slipping
//! system's and the estimate lands on its resonance (the demo's blade: 1,672 Hz, where the
//! stuck-mode basis fails), which the band's start alone does not show.

use crate::error::Result;
use crate::hbm::residual::{evaluate, linear_jacobian, ResidualWorkspace};
use crate::hbm::HarmonicSystem;
use crate::linalg::DenseLu;
use faer::Mat;

/// Frequencies of the first, uniform scan of the band.
const SCAN_POINTS: usize = 64;
/// Frequencies of each refinement between the neighbours of the largest response so far.
const REFINE_POINTS: usize = 16;
/// Refinements (each shrinks the interval by `REFINE_POINTS / 2`).
const REFINEMENTS: usize = 2;

/// The frequency in `[omega_start, omega_end]` where the tangent response of `system` at its
/// solution `z0` at `omega0` peaks (module doc); `None` where the tangent cannot be formed or
/// no frequency of the scan solves.
///
/// # Errors
/// The system's own errors (its linear part, its contact forces).
pub fn tangent_peak(system: &dyn HarmonicSystem, omega0: f64, z0: &[f64], (omega_start, omega_end): (f64, f64)) -> Result<Option<f64>> {
    let layout = system.layout().clone();
    if layout.harmonics == 0 || !(omega_end > omega_start) {
        return Ok(None);
    }
    let plan = crate::hbm::solve::plan_for(system)?;
    let lin0 = system.linear_part(omega0)?;
    let (_, jac) = evaluate(system, &lin0, plan.as_ref(), z0, true, &mut ResidualWorkspace::new())?;
    let Some(jac) = jac else { return Ok(None) };
    if jac.is_sparse() {
        // a sparse (full-order) system: not the reduced models this is for
        return Ok(None);
    }
    let mut contact = jac.into_dense();
    let d0 = linear_jacobian(&layout, &lin0).into_dense();
    contact -= &d0;
    let n = layout.total();
    let harmonic = layout.cos_offset(1)..n;
    let amplitude = |omega: f64| -> Result<f64> {
        let lin = system.linear_part(omega)?;
        let mut a = linear_jacobian(&layout, &lin).into_dense();
        a += &contact;
        let mut f = Mat::<f64>::zeros(n, 1);
        for h in 1..=layout.harmonics {
            let (oc, os) = (layout.cos_offset(h), layout.sin_offset(h));
            for (i, (&c, &s)) in lin.fh_cos[h - 1].iter().zip(&lin.fh_sin[h - 1]).enumerate() {
                f[(oc + i, 0)] = c;
                f[(os + i, 0)] = s;
            }
        }
        let dz = DenseLu::new(&a).solve(&f);
        let amp = harmonic.clone().map(|i| dz[(i, 0)] * dz[(i, 0)]).sum::<f64>().sqrt();
        // a singular frequency (an undamped tangent) is the peak itself
        Ok(if amp.is_nan() { f64::INFINITY } else { amp })
    };
    let mut best: Option<(f64, f64)> = None;
    let (mut lo, mut hi, mut points) = (omega_start, omega_end, SCAN_POINTS);
    for _ in 0..=REFINEMENTS {
        let step = (hi - lo) / (points - 1) as f64;
        let mut round: Option<(f64, f64)> = None;
        for k in 0..points {
            let omega = lo + step * k as f64;
            let amp = amplitude(omega)?;
            if round.is_none_or(|(_, a)| amp > a) {
                round = Some((omega, amp));
            }
        }
        let Some((omega, amp)) = round else { break };
        if best.is_none_or(|(_, a)| amp >= a) {
            best = Some((omega, amp));
        }
        let centre = best.expect("set above").0;
        (lo, hi, points) = ((centre - step).max(omega_start), (centre + step).min(omega_end), REFINE_POINTS);
    }
    Ok(best.filter(|&(_, a)| a > 0.0).map(|(omega, _)| omega))
}

#[cfg(test)]
mod tests {
    use super::tangent_peak;
    use crate::contact::Contact;
    use crate::hbm::{solve_point, FullSystem, HbmOptions, Storage};
    use crate::model::{Damping, Excitation, HarmonicForce, Model};
    use faer::Mat;

    /// A unit mass on a unit spring with a Jenkins element to ground (`kt = 1`, slip force
    /// `0.1`), forced at `force`: its tangent resonance is `sqrt(k + kt) = sqrt 2` while the
    /// element sticks and `sqrt(k) = 1` when it slips through almost the whole cycle.
    fn jenkins_oscillator(force: f64) -> FullSystem {
        let one = Mat::from_fn(1, 1, |_, _| 1.0);
        let exc = Excitation { static_force: vec![0.0], harmonics: vec![HarmonicForce { cos: vec![force], sin: vec![0.0] }], dynamic_scale: 1.0 };
        let model = Model::new(one.clone(), one, Damping { mass_coeff: 0.0, stiffness_coeff: 0.002 }, exc, vec![Contact::jenkins(0, None, 1.0, 1.0, 0.1)], vec![0]).unwrap();
        FullSystem::with_storage(&model, crate::hbm::Discretisation::with_nt(1, 256), Storage::Dense).unwrap()
    }

    /// The estimate against the closed forms of the stuck and the slipping oscillator, from a
    /// solution away from the resonance (the band's start), and `None` for an empty band.
    #[test]
    fn tangent_peak_is_the_stuck_or_the_slipping_resonance() {
        let opts = HbmOptions::default();
        let band = (0.5, 2.0);
        for (force, expected) in [(1e-3, 2f64.sqrt()), (50.0, 1.0)] {
            let sys = jenkins_oscillator(force);
            let z0 = solve_point(&sys, 0.5, None, &opts).unwrap().z;
            let peak = tangent_peak(&sys, 0.5, &z0, band).unwrap().expect("a peak in the band");
            // the scan resolves the band to (1.5 / 63) * (2 / 15)^2 ~ 4e-4
            assert!((peak - expected).abs() < 2e-3 * expected, "force {force}: tangent peak {peak}, expected {expected}");
        }
        let sys = jenkins_oscillator(1e-3);
        let z0 = solve_point(&sys, 0.5, None, &opts).unwrap().z;
        assert_eq!(tangent_peak(&sys, 0.5, &z0, (1.0, 1.0)).unwrap(), None);
    }
}
