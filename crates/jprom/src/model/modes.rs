//! Natural frequencies of a model, to choose a band (docs/formulation.md §12): the free
//! structure (`K`, `M`, contacts open) or the stuck one (`K` plus every contact's stuck springs
//! `kt1, kt2, kn` in its frame, the linear limit of small excitation, §8), each mode with its
//! modal force at the first-harmonic load.

use super::{ContactCoordinates, Model};
use crate::error::Result;
use crate::linalg::eigen::dense_generalized_modes;
use std::f64::consts::PI;

/// Which linear structure the modes are of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Boundary {
    /// `K`, `M` alone: contacts open (rigid-body modes if the model is not held otherwise).
    Free,
    /// `K` plus the stuck contact springs: the linear limit of a small excitation.
    Stuck,
}

/// One natural mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NaturalMode {
    /// Natural frequency in Hz (0 for a rigid-body mode).
    pub frequency_hz: f64,
    /// Modal force `|phi^T f_E^1|` of the mass-normalised mode at the first-harmonic load
    /// (cos and sin parts together, at the current excitation scale).
    pub modal_force: f64,
    /// Share of the load this mode takes: `modal_force^2` over the sum over all modes of the
    /// model (`f^T M^-1 f`), between 0 and 1.
    pub participation: f64,
}

/// All natural modes of `model`, lowest first (the model is dense and reduced: every mode is
/// computed, `O(n^3)`).
///
/// # Errors
/// The model's validation errors; the eigensolver's (a mass that is not positive definite).
pub fn natural_modes(model: &Model, boundary: Boundary) -> Result<Vec<NaturalMode>> {
    let coords = ContactCoordinates::new(model, 1)?;
    let k = match boundary {
        Boundary::Free => coords.stiffness.clone(),
        Boundary::Stuck => coords.stuck_stiffness(),
    };
    // z = T^-1 x is a congruence: the pencil (T^T K T, T^T M T) has the physical frequencies
    let (lambda, phi) = dense_generalized_modes(&k, &coords.mass)?;
    let n = coords.n_dof;
    let (fc, fs) = coords.harmonic_force.first().cloned().unwrap_or_else(|| (vec![0.0; n], vec![0.0; n]));
    let forces: Vec<f64> = (0..n)
        .map(|r| {
            let (mut c, mut s) = (0.0, 0.0);
            for i in 0..n {
                c += phi[(i, r)] * fc[i];
                s += phi[(i, r)] * fs[i];
            }
            c.hypot(s)
        })
        .collect();
    let total: f64 = forces.iter().map(|f| f * f).sum();
    Ok(lambda
        .iter()
        .zip(&forces)
        .map(|(&l, &f)| NaturalMode {
            frequency_hz: l.max(0.0).sqrt() / (2.0 * PI),
            modal_force: f,
            participation: if total > 0.0 { f * f / total } else { 0.0 },
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Contact;
    use crate::model::{Damping, Excitation, HarmonicForce};
    use faer::Mat;

    /// Two masses on springs, the second held to ground by a stuck contact: closed forms.
    #[test]
    fn two_masses_free_and_stuck_match_the_closed_form() {
        let (m1, m2, k1, k2, kt) = (2.0, 1.0, 3.0e4, 1.0e4, 5.0e3);
        let mass = Mat::from_fn(2, 2, |i, j| if i != j { 0.0 } else if i == 0 { m1 } else { m2 });
        let stiffness = Mat::from_fn(2, 2, |i, j| match (i, j) {
            (0, 0) => k1 + k2,
            (1, 1) => k2,
            _ => -k2,
        });
        let excitation = Excitation { static_force: vec![0.0, 1.0], harmonics: vec![HarmonicForce { cos: vec![0.0, 1.0], sin: vec![0.0; 2] }], dynamic_scale: 1.0 };
        let model = Model::new(mass, stiffness, Damping::default(), excitation, vec![Contact::jenkins(1, None, kt, 0.5, 1.0)], vec![1]).unwrap();
        let closed = |k22: f64| {
            // det(K - l M) = 0 for the 2 x 2 pencil
            let (a, b, c) = (m1 * m2, -((k1 + k2) * m2 + k22 * m1), (k1 + k2) * k22 - k2 * k2);
            let d = (b * b - 4.0 * a * c).sqrt();
            [(-b - d) / (2.0 * a), (-b + d) / (2.0 * a)].map(|l: f64| l.sqrt() / (2.0 * PI))
        };
        for (boundary, k22) in [(Boundary::Free, k2), (Boundary::Stuck, k2 + kt)] {
            let modes = natural_modes(&model, boundary).unwrap();
            let want = closed(k22);
            for (m, w) in modes.iter().zip(want) {
                assert!((m.frequency_hz - w).abs() <= 1e-12 * w, "{boundary:?}: {} vs {w}", m.frequency_hz);
            }
            let share: f64 = modes.iter().map(|m| m.participation).sum();
            assert!((share - 1.0).abs() < 1e-12, "participations sum to {share}");
            // f^T M^-1 f = 1 / m2 is the sum of the squared modal forces
            let total: f64 = modes.iter().map(|m| m.modal_force * m.modal_force).sum();
            assert!((total - 1.0 / m2).abs() < 1e-12, "{total}");
        }
    }
}
