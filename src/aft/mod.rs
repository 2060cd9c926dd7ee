//! Alternating frequency-time (AFT) evaluation of the contact forces and of their analytical
//! Jacobian (method.md §3).
//!
//! Harmonic coefficients use the real layout `k = 0` (static), `k = 2h - 1` (cos `h`),
//! `k = 2h` (sin `h`), `h = 1..=H`, so `2H + 1` coefficients per coordinate:
//! `x(t) = c_0 + sum_h (c_{2h-1} cos(h w t) + c_{2h} sin(h w t))`.
//!
//! * For **one contact** of dimension `d` (3 for the 3D element, 1 for Jenkins), vectors are
//!   coefficient-major: entry `k * d + i` is coefficient `k` of local coordinate `i`.
//!   Its Jacobian block is `n x n`, `n = d (2H + 1)`, column-major:
//!   `jac[row + col * n] = dF_row / dw_col`.
//! * For **all contacts** of a system, vectors are harmonic-major over the contact
//!   coordinates: entry `k * n_w + offset_c + i`.
//!
//! `F` is the element force (`T1, T2, N` for 3D), positive when it resists `w`; the force on
//! the structure is `-F`. So `dF/dw` is the contact stiffness `K̂` of method.md §2.

use crate::contact::{ContactLaw, ContactState};
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// What one contact did over one steady-state period.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactCycle {
    /// State at each of the `Nt` time samples (the "boundary condition" of §6).
    pub states: Vec<ContactState>,
    /// Energy dissipated by friction per cycle, `W = closed integral of T . du`.
    pub dissipated_energy: f64,
}

/// FFT plans and sizes for a given number of harmonics `H` and time samples `Nt`.
/// Made once, shared (read-only) by all threads.
pub struct AftPlan {
    harmonics: usize,
    nt: usize,
}

/// Per-thread scratch memory of the AFT, so that the contact loop does not allocate.
pub struct AftWorkspace {}

impl AftPlan {
    /// Plans for `H = harmonics >= 1` and `nt` samples (a power of two, `>= 4 (H + 1)`).
    pub fn new(harmonics: usize, nt: usize) -> Result<Self> {
        let _ = (harmonics, nt);
        todo!("aft: AftPlan::new")
    }
    /// `H`.
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }
    /// `Nt`.
    pub fn nt(&self) -> usize {
        self.nt
    }
    /// `2H + 1`.
    pub fn n_coeffs(&self) -> usize {
        2 * self.harmonics + 1
    }
    /// Scratch for contacts of dimension up to 3.
    pub fn workspace(&self) -> AftWorkspace {
        todo!("aft: workspace")
    }

    /// Harmonics of the force of one contact for the local displacement harmonics `w`,
    /// with optionally its analytical Jacobian and its cycle report. Layouts in the module doc.
    pub fn contact(
        &self,
        law: &ContactLaw,
        w: &[f64],
        force: &mut [f64],
        jac: Option<&mut [f64]>,
        cycle: Option<&mut ContactCycle>,
        ws: &mut AftWorkspace,
    ) {
        let _ = (law, w, force, jac, cycle, ws);
        todo!("aft: contact")
    }
}

/// Forces, Jacobian blocks and cycle reports of all contacts of a system.
#[derive(Clone, Debug, Default)]
pub struct ContactForces {
    /// Harmonic-major force coefficients, length `(2H + 1) n_w`.
    pub force: Vec<f64>,
    /// Concatenated per-contact Jacobian blocks (column-major, contact-local layout).
    pub jac: Vec<f64>,
    /// Start of each contact's block in `jac`.
    pub jac_offsets: Vec<usize>,
    /// One report per contact (filled when asked for).
    pub cycles: Vec<ContactCycle>,
}

/// Evaluates every contact (in parallel over contacts) for the harmonic-major contact
/// displacement `w_all` (length `(2H + 1) n_w`); `offsets[c]` is contact `c`'s first
/// coordinate in `w`. Fills `out` (resized as needed, reused across calls).
pub fn evaluate_contacts(
    plan: &AftPlan,
    laws: &[ContactLaw],
    offsets: &[usize],
    n_w: usize,
    w_all: &[f64],
    want_jacobian: bool,
    want_cycles: bool,
    out: &mut ContactForces,
) {
    let _ = (plan, laws, offsets, n_w, w_all, want_jacobian, want_cycles, out);
    todo!("aft: evaluate_contacts")
}
