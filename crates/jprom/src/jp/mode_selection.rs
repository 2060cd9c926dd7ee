//! Which eigenpairs of the JP eigenproblem (31) become JP modes, and how it is solved.

use serde::{Deserialize, Serialize};

/// Which eigenpairs of (31) become JP modes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeOptions {
    /// Analysis band `[omega_lo, omega_hi]`, angular frequency (rad/s).
    pub band: (f64, f64),
    /// Number of further eigenpairs, nearest to the band (in `sqrt(Re λ)`), kept as well.
    /// Eigenvalues are counted one by one (a stuck pair counts 2).
    pub extra_outside: usize,
    /// Add the static-correction vectors of the condensed problem (a jprom extension of (33),
    /// the mode-acceleration idea of CMS): `K_JC^-1 F_h` for the harmonic forcing `F_h` of each
    /// loaded harmonic and `K_JC^-1 K̂_J0 A_0^-1 (f_E^0 + g)` for the static load's coupling into
    /// the harmonics. They carry the quasi-static response of every mode the band leaves out,
    /// which is what limits the accuracy of an in-band basis away from the resonance peak and
    /// in the static term. Default `true`.
    #[serde(default = "default_static_correction")]
    pub static_correction: bool,
    /// Eigen solver of (31) (default [`EigenSolver::Auto`]).
    #[serde(default)]
    pub solver: EigenSolver,
}

/// How the eigenproblem (31) is solved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum EigenSolver {
    /// Dense non-symmetric eigen solve of the whole condensed problem, `O((2 H n)^3)`.
    Dense,
    /// A few eigenpairs around the band by shift-invert Arnoldi over a factorisation of
    /// `K_JC - σ M_JC` ([`crate::jp::shift_invert`]).
    ShiftInvert,
    /// [`EigenSolver::Dense`] up to [`AUTO_DENSE_MAX`] = `2 H n`, else
    /// [`EigenSolver::ShiftInvert`]; from [`AUTO_SHIFT_INVERT_MIN`] up to [`AUTO_DENSE_MAX`],
    /// a shift-invert attempt of at most [`AUTO_SHIFT_INVERT_REQUEST`] eigenpairs first
    /// (`jp_modes`; [`EigenSolver::resolve`] still says dense there: the memory estimates
    /// and the choice of a shared reference are the dense path's).
    #[default]
    Auto,
}

/// Largest condensed size `2 H n` that [`EigenSolver::Auto`] solves densely.
pub const AUTO_DENSE_MAX: usize = 600;

/// Most eigenpairs [`EigenSolver::Auto`] requests from shift-invert Arnoldi on a problem it
/// would otherwise solve densely (`2 H n <= `[`AUTO_DENSE_MAX`]) before it solves densely. Where the
/// band holds a few modes this pays: on the demo blade (`2 H n = 262`, 78 patterns) the same
/// basis (spans within 1e-6) in 0.5 to 0.7 s against 0.9 to 1.3 s. Where it holds dozens,
/// shift-invert is far slower than the dense solve (a 180-DoF chain with 86 modes kept: 222 s
/// against 2.8 s), so the attempt stops at this request.
pub const AUTO_SHIFT_INVERT_REQUEST: usize = 16;

/// Smallest `2 H n` at which [`EigenSolver::Auto`] makes the attempt of
/// [`AUTO_SHIFT_INVERT_REQUEST`]: below it the dense solve is cheap enough that a failed
/// attempt would cost more than a successful one saves.
pub const AUTO_SHIFT_INVERT_MIN: usize = 200;

impl EigenSolver {
    /// The solver used for a condensed problem of size `dim = 2 H n`.
    pub fn resolve(self, dim: usize) -> EigenSolver {
        match self {
            EigenSolver::Auto if dim <= AUTO_DENSE_MAX => EigenSolver::Dense,
            EigenSolver::Auto => EigenSolver::ShiftInvert,
            s => s,
        }
    }
}

fn default_static_correction() -> bool {
    true
}

impl ModeOptions {
    /// The in-band eigenpairs of `band` with the static correction, nothing outside.
    pub fn in_band(band: (f64, f64)) -> Self {
        ModeOptions { band, extra_outside: 0, static_correction: true, solver: EigenSolver::Auto }
    }
}

