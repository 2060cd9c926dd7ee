//! Contact elements (docs/formulation.md §4.2): where they sit in the model and which law they follow.
//!
//! A contact acts on a *local relative displacement* `w`: `w = R (x_a - x_b)` for a node pair,
//! `w = R x_a` for a node against ground, with `w = (u1, u2, v)` and `v` positive into the
//! contact. The element force `F = (T1, T2, N)` is what the contact pushes back with, so the
//! force on the structure is `f_a = -R^T F` (and `f_b = +R^T F`). The *contact stiffness*
//! `K̂ = dF/dw` is positive semi-definite while everything sticks.

pub mod law;
pub mod jenkins;
pub mod elastic;
pub mod external;

pub use external::{ExternalFn, ExternalLaw};

use crate::error::{JpError, Result};
use serde::{Deserialize, Serialize};

/// A contact law seen one time sample at a time, as the AFT's single chain-rule loop uses it
/// (docs/formulation.md §4): the normal force from the normal displacement, then the
/// tangential force from an elastic predictor `T* = T_prev + Kt du` and a corrector that returns
/// `T*` to the slip limit, each with its derivatives. A new contact law implements this trait
/// and gets its AFT forces, analytical Jacobian and dissipated energy from
/// [`crate::aft::AftPlan::contact`] unchanged.
///
/// Local coordinates are the `TANGENTIAL` directions first, then the normal one if
/// `HAS_NORMAL`; tangential quantities are `[f64; 2]` with the unused entries zero.
pub trait SampleLaw {
    /// Number of tangential directions (2 for the 3D element, 1 for Jenkins and the 2D
    /// element, 0 for the memoryless scalar springs).
    const TANGENTIAL: usize;
    /// Whether a normal coordinate follows the tangential ones.
    const HAS_NORMAL: bool;
    /// Tangential stiffness per direction, `Kt = diag(kt1, kt2)`.
    fn tangential_stiffness(&self) -> [f64; 2];
    /// Normal force and `dN/dv` at the normal displacement `v` (`(0, 0)` without a normal
    /// coordinate).
    fn normal(&self, v: f64) -> (f64, f64);
    /// Corrector: the force, state, `dT/dT*` and `dT/dN` for the predictor `T*` under the
    /// normal force `N`.
    fn correct(&self, trial: [f64; 2], normal: f64) -> law::Corrector;
    /// Friction work of one sample, `T . Kt^-1 (T* - T)` (zero in stick, `>= 0` in slip).
    fn slip_work(&self, trial: [f64; 2], force: [f64; 2]) -> f64;

    /// Predictor `T* = T_prev + Kt du`.
    #[inline]
    fn predictor(&self, t_prev: [f64; 2], du: [f64; 2]) -> [f64; 2] {
        let kt = self.tangential_stiffness();
        [t_prev[0] + kt[0] * du[0], t_prev[1] + kt[1] * du[1]]
    }
}

impl SampleLaw for law::Friction3D {
    const TANGENTIAL: usize = 2;
    const HAS_NORMAL: bool = true;
    #[inline]
    fn tangential_stiffness(&self) -> [f64; 2] {
        self.kt
    }
    #[inline]
    fn normal(&self, v: f64) -> (f64, f64) {
        law::Friction3D::normal(self, v)
    }
    #[inline]
    fn correct(&self, trial: [f64; 2], normal: f64) -> law::Corrector {
        law::Friction3D::correct(self, trial, normal)
    }
    #[inline]
    fn slip_work(&self, trial: [f64; 2], force: [f64; 2]) -> f64 {
        law::Friction3D::slip_work(self, trial, force)
    }
}

impl SampleLaw for jenkins::Jenkins {
    const TANGENTIAL: usize = 1;
    const HAS_NORMAL: bool = false;
    #[inline]
    fn tangential_stiffness(&self) -> [f64; 2] {
        [self.kt, 0.0]
    }
    #[inline]
    fn normal(&self, _v: f64) -> (f64, f64) {
        (0.0, 0.0)
    }
    #[inline]
    fn correct(&self, trial: [f64; 2], _normal: f64) -> law::Corrector {
        let (t, state, a) = jenkins::Jenkins::correct(self, trial[0]);
        law::Corrector { force: [t, 0.0], state, d_predictor: [[a, 0.0], [0.0, 0.0]], d_normal: [0.0, 0.0] }
    }
    #[inline]
    fn slip_work(&self, trial: [f64; 2], force: [f64; 2]) -> f64 {
        jenkins::Jenkins::slip_work(self, trial[0], force[0])
    }
}

/// State of a contact at one time sample: the "boundary condition" of JP (§6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[repr(u8)]
pub enum ContactState {
    /// Tangential force inside the friction cone (or, for Jenkins, below the slip limit).
    Stick = 0,
    /// Tangential force on the friction cone.
    Slip = 1,
    /// Normal gap open, no force.
    Separated = 2,
}

/// The constitutive law of one contact, independent of where it sits in the model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ContactLaw {
    /// 3D element: tangential springs `kt1`, `kt2` with Coulomb friction `mu`, unilateral normal
    /// spring `kn` with preload `n0` (`N = max(0, n0 + kn v)`). Acts on `w = (u1, u2, v)`.
    Friction3D { kt1: f64, kt2: f64, kn: f64, mu: f64, n0: f64 },
    /// 1D Jenkins element: spring `kt` in series with a slider of limit `mu * normal_load`
    /// (constant normal load, never separates). Acts on a scalar `w = u`.
    Jenkins { kt: f64, mu: f64, normal_load: f64 },
    /// 1D polynomial spring, memoryless: `F(w) = sum_p c_p w^p` with `c_p = coefficients[p - 1]`
    /// (`p = 1..=P`, no constant term), so `[k1, 0, k3]` is the cubic (Duffing) spring
    /// `k1 w + k3 w^3`. Acts on a scalar `w` in both signs; coefficients may be negative
    /// (softening). Its stuck stiffness is the linearisation at `w = 0`, `c_1`.
    Polynomial { coefficients: Vec<f64> },
    /// 1D unilateral spring with gap or preload: `N = max(0, n0 + kn v)` on a scalar `v`
    /// (positive into the contact); the gap is `-n0 / kn` when `n0 < 0`.
    Unilateral { kn: f64, n0: f64 },
    /// 2D friction element: tangential spring `kt` with Coulomb friction `mu` on `u`, unilateral
    /// normal spring `kn` with preload `n0` on `v`. Acts on `w = (u, v)`.
    Friction2D { kt: f64, kn: f64, mu: f64, n0: f64 },
    /// Several laws of the same dimension acting in parallel on the same local coordinates:
    /// the force and the Jacobian are the sums of the members'. [`crate::model::ContactCoordinates`]
    /// builds it for elements with the same kinematics (same `dofs_a`, `dofs_b` and frame);
    /// members may not be `Parallel` themselves.
    Parallel(Vec<ContactLaw>),
    /// User-defined memoryless law on `d = 1..=3` coordinates: a callable gives `F(w)` and
    /// `dF/dw` per AFT time sample (docs/formulation.md §4.6, [`external`]). Not
    /// serialisable; its stuck stiffness is its Jacobian at `w = 0`.
    External(ExternalLaw),
}

impl ContactLaw {
    /// Number of local coordinates the law acts on (3, 2 or 1).
    pub fn dim(&self) -> usize {
        match self {
            ContactLaw::Friction3D { .. } => 3,
            ContactLaw::Friction2D { .. } => 2,
            ContactLaw::Jenkins { .. } | ContactLaw::Polynomial { .. } | ContactLaw::Unilateral { .. } => 1,
            ContactLaw::Parallel(laws) => laws.first().map_or(1, ContactLaw::dim),
            ContactLaw::External(law) => law.dim(),
        }
    }

    /// Linear stiffness of the stuck, closed contact as a full `dim x dim` column-major block:
    /// `diag(`[`ContactLaw::stuck_stiffness`]`)` for the built-in laws, the Jacobian at `w = 0`
    /// (coupling included) for an [`ContactLaw::External`] law, summed over parallel laws.
    pub fn stuck_stiffness_block(&self) -> Vec<f64> {
        let d = self.dim();
        let mut k = vec![0.0; d * d];
        for law in self.members() {
            if let ContactLaw::External(e) = law {
                for (s, v) in k.iter_mut().zip(e.stuck_jacobian()) {
                    *s += v;
                }
            } else {
                for (i, v) in law.stuck_stiffness().into_iter().enumerate() {
                    k[i + i * d] += v;
                }
            }
        }
        k
    }

    /// [`ContactLaw::stuck_stiffness_block`] of the members closed at zero displacement (no
    /// gap: `n0 >= 0`, or no normal law), the open ones counted as zero: the contact's
    /// stiffness in the linear limit that a structure at rest starts from.
    pub fn closed_stiffness_block(&self) -> Vec<f64> {
        let d = self.dim();
        let mut k = vec![0.0; d * d];
        for law in self.members() {
            let open = matches!(law, ContactLaw::Friction3D { n0, .. } | ContactLaw::Friction2D { n0, .. } | ContactLaw::Unilateral { n0, .. } if *n0 < 0.0);
            if !open {
                for (s, v) in k.iter_mut().zip(law.stuck_stiffness_block()) {
                    *s += v;
                }
            }
        }
        k
    }

    /// The law with every [`ContactLaw::External`] member that has no label named
    /// `"element {index}"` (for error messages; [`crate::model::ContactCoordinates`] calls it
    /// with the contact's index in the model).
    pub fn labelled(self, index: usize) -> ContactLaw {
        match self {
            ContactLaw::External(e) if e.label().is_empty() => ContactLaw::External(e.with_label(format!("element {index}"))),
            ContactLaw::Parallel(laws) => ContactLaw::Parallel(laws.into_iter().map(|l| l.labelled(index)).collect()),
            law => law,
        }
    }

    /// Linear stiffness of the fully stuck, closed contact: `diag(kt1, kt2, kn)`, `kt`,
    /// `(kt, kn)`, `kn`, the polynomial's `c_1`, the diagonal of an external law's Jacobian at
    /// `w = 0` (its full block, coupling included, is [`ContactLaw::stuck_stiffness_block`]),
    /// or the sum over parallel laws.
    pub fn stuck_stiffness(&self) -> Vec<f64> {
        match self {
            ContactLaw::Friction3D { kt1, kt2, kn, .. } => vec![*kt1, *kt2, *kn],
            ContactLaw::Friction2D { kt, kn, .. } => vec![*kt, *kn],
            ContactLaw::Jenkins { kt, .. } => vec![*kt],
            ContactLaw::Polynomial { coefficients } => vec![coefficients.first().copied().unwrap_or(0.0)],
            ContactLaw::Unilateral { kn, .. } => vec![*kn],
            ContactLaw::Parallel(laws) => {
                let mut k = vec![0.0; self.dim()];
                for law in laws {
                    for (s, v) in k.iter_mut().zip(law.stuck_stiffness()) {
                        *s += v;
                    }
                }
                k
            }
            ContactLaw::External(law) => {
                let d = law.dim();
                (0..d).map(|i| law.stuck_jacobian()[i + i * d]).collect()
            }
        }
    }

    /// The laws acting on the coordinates: the members of a [`ContactLaw::Parallel`], else
    /// the law itself.
    pub fn members(&self) -> &[ContactLaw] {
        match self {
            ContactLaw::Parallel(laws) => laws,
            law => std::slice::from_ref(law),
        }
    }

    /// Linear stiffness of the closed contact in gross slip, as a full `dim x dim` column-major
    /// block: the normal springs alone (tangential friction forces do not grow with the
    /// displacement), `diag(0, 0, kn)` for [`ContactLaw::Friction3D`], `diag(0, kn)` for
    /// [`ContactLaw::Friction2D`], `0` for [`ContactLaw::Jenkins`]; the stuck stiffness of the
    /// laws without friction; summed over parallel laws. `None` for an [`ContactLaw::External`]
    /// law (its slipping limit is not known). The other linear limit besides
    /// [`ContactLaw::stuck_stiffness_block`] (docs/formulation.md §8.8).
    pub fn slipping_stiffness_block(&self) -> Option<Vec<f64>> {
        let d = self.dim();
        let mut k = vec![0.0; d * d];
        for law in self.members() {
            let diag = match law {
                ContactLaw::External(_) => return None,
                ContactLaw::Friction3D { kn, .. } => vec![0.0, 0.0, *kn],
                ContactLaw::Friction2D { kn, .. } => vec![0.0, *kn],
                ContactLaw::Jenkins { .. } => vec![0.0],
                other => other.stuck_stiffness(),
            };
            for (i, v) in diag.into_iter().enumerate() {
                k[i + i * d] += v;
            }
        }
        Some(k)
    }

    /// A short name of the law for messages ("Friction3D", "Polynomial", ...).
    pub fn name(&self) -> &'static str {
        match self {
            ContactLaw::Friction3D { .. } => "Friction3D",
            ContactLaw::Friction2D { .. } => "Friction2D",
            ContactLaw::Jenkins { .. } => "Jenkins",
            ContactLaw::Polynomial { .. } => "Polynomial",
            ContactLaw::Unilateral { .. } => "Unilateral",
            ContactLaw::Parallel(_) => "Parallel",
            ContactLaw::External(_) => "External",
        }
    }

    /// Rejects negative or non-finite parameters (a polynomial's coefficients need only be
    /// finite; it needs one to [`POLYNOMIAL_MAX_TERMS`] of them), an empty or nested
    /// [`ContactLaw::Parallel`] and one whose members differ in dimension.
    pub fn validate(&self, what: &str) -> Result<()> {
        let limit = crate::limits::MAX_MAGNITUDE;
        let check = |name: &str, v: f64| -> Result<()> {
            if !v.is_finite() || v < 0.0 {
                Err(JpError::invalid(format!("{what}.{name}"), format!("must be finite and >= 0, got {v}")))
            } else if v > limit {
                Err(JpError::invalid(format!("{what}.{name}"), format!("is {v:e}, beyond jprom's magnitude limit of {limit:e}")))
            } else {
                Ok(())
            }
        };
        let finite = |name: &str, v: f64| -> Result<()> {
            if !v.is_finite() {
                Err(JpError::invalid(format!("{what}.{name}"), format!("must be finite, got {v}")))
            } else if v.abs() > limit {
                Err(JpError::invalid(format!("{what}.{name}"), format!("is {v:e}, beyond jprom's magnitude limit of {limit:e}")))
            } else {
                Ok(())
            }
        };
        match self {
            ContactLaw::Polynomial { coefficients } => {
                if coefficients.is_empty() || coefficients.len() > POLYNOMIAL_MAX_TERMS {
                    return Err(JpError::invalid(
                        format!("{what}.coefficients"),
                        format!("needs 1 to {POLYNOMIAL_MAX_TERMS} coefficients (c_1 .. c_P), got {}", coefficients.len()),
                    ));
                }
                for (i, &c) in coefficients.iter().enumerate() {
                    finite(&format!("coefficients[{i}]"), c)?;
                }
                Ok(())
            }
            ContactLaw::Unilateral { kn, n0 } => {
                check("kn", *kn)?;
                finite("n0", *n0)
            }
            ContactLaw::Friction2D { kt, kn, mu, n0 } => {
                check("kt", *kt)?;
                check("kn", *kn)?;
                check("mu", *mu)?;
                finite("n0", *n0)
            }
            ContactLaw::Parallel(laws) => {
                let Some(first) = laws.first() else {
                    return Err(JpError::invalid(what.to_string(), "a Parallel law needs at least one member"));
                };
                for (i, law) in laws.iter().enumerate() {
                    let wi = format!("{what}.Parallel[{i}]");
                    if matches!(law, ContactLaw::Parallel(_)) {
                        return Err(JpError::invalid(wi, "a Parallel law cannot contain another Parallel law"));
                    }
                    if law.dim() != first.dim() {
                        return Err(JpError::invalid(
                            wi,
                            format!("{} acts on {} coordinates, the first member on {}", law.name(), law.dim(), first.dim()),
                        ));
                    }
                    law.validate(&wi)?;
                }
                Ok(())
            }
            &ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 } => {
                check("kt1", kt1)?;
                check("kt2", kt2)?;
                check("kn", kn)?;
                check("mu", mu)?;
                finite("n0", n0)
            }
            &ContactLaw::Jenkins { kt, mu, normal_load } => {
                check("kt", kt)?;
                check("mu", mu)?;
                check("normal_load", normal_load)
            }
            ContactLaw::External(law) => {
                if !(1..=3).contains(&law.dim()) {
                    return Err(JpError::invalid(format!("{what}.dim"), format!("must be 1, 2 or 3, got {}", law.dim())));
                }
                Ok(())
            }
        }
    }
}

/// Most coefficients a [`ContactLaw::Polynomial`] may have (powers 1 to 16).
pub const POLYNOMIAL_MAX_TERMS: usize = 16;

/// The contacts of a system as the AFT sees them: their laws in order, the offset of each
/// contact's coordinates in `w`, and the number of contact coordinates `n_w`.
#[derive(Clone, Copy, Debug)]
pub struct Contacts<'a> {
    pub laws: &'a [ContactLaw],
    pub offsets: &'a [usize],
    pub n_w: usize,
    /// AFT time samples per period the contact forces are evaluated with (the system's `Nt`).
    pub nt: usize,
}

/// Where a contact sits: the DoFs of node `a` (and `b` for a pair) and the local frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// Global DoF indices of node `a` (one per local coordinate: 3 for the 3D law, 2 for the
    /// 2D law, 1 for the scalar laws).
    pub dofs_a: Vec<usize>,
    /// Global DoF indices of node `b` for a node pair; `None` for a contact with ground.
    pub dofs_b: Option<Vec<usize>>,
    /// Rotation to the local frame: rows are the unit vectors `t1`, `t2`, `n` in global
    /// coordinates, so `w = R x`. Only the leading `dim x dim` block is used: for the 2D law a
    /// 2 x 2 rotation (rows `t`, `n`), for the scalar laws `frame[0][0] = +-1` (the sign).
    pub frame: [[f64; 3]; 3],
    /// Constitutive law.
    pub law: ContactLaw,
}

impl Contact {
    /// A 3D node-to-ground contact.
    pub fn ground_3d(dofs_a: [usize; 3], frame: [[f64; 3]; 3], law: ContactLaw) -> Self {
        Contact { dofs_a: dofs_a.to_vec(), dofs_b: None, frame, law }
    }
    /// A 3D node-pair contact: `w = R (x_a - x_b)`.
    pub fn pair_3d(dofs_a: [usize; 3], dofs_b: [usize; 3], frame: [[f64; 3]; 3], law: ContactLaw) -> Self {
        Contact { dofs_a: dofs_a.to_vec(), dofs_b: Some(dofs_b.to_vec()), frame, law }
    }
    /// A 1D Jenkins element on one DoF against ground (`dof_b = None`) or between two DoFs.
    pub fn jenkins(dof_a: usize, dof_b: Option<usize>, kt: f64, mu: f64, normal_load: f64) -> Self {
        Contact {
            dofs_a: vec![dof_a],
            dofs_b: dof_b.map(|b| vec![b]),
            frame: IDENTITY_FRAME,
            law: ContactLaw::Jenkins { kt, mu, normal_load },
        }
    }

    /// A 1D polynomial spring `F(w) = sum_p c_p w^p`, `w = x_a` or `x_a - x_b`.
    pub fn polynomial(dof_a: usize, dof_b: Option<usize>, coefficients: Vec<f64>) -> Self {
        Contact { dofs_a: vec![dof_a], dofs_b: dof_b.map(|b| vec![b]), frame: IDENTITY_FRAME, law: ContactLaw::Polynomial { coefficients } }
    }
    /// A 1D unilateral spring `N = max(0, n0 + kn v)`, `v = x_a` or `x_a - x_b`.
    pub fn unilateral(dof_a: usize, dof_b: Option<usize>, kn: f64, n0: f64) -> Self {
        Contact { dofs_a: vec![dof_a], dofs_b: dof_b.map(|b| vec![b]), frame: IDENTITY_FRAME, law: ContactLaw::Unilateral { kn, n0 } }
    }
    /// A 2D friction element on `w = (u, v) = R (x_a - x_b)` (or `R x_a`), `R` the 2 x 2
    /// rotation with rows `t` and `n`.
    pub fn friction_2d(dofs_a: [usize; 2], dofs_b: Option<[usize; 2]>, rotation: [[f64; 2]; 2], law: ContactLaw) -> Self {
        let r = rotation;
        let frame = [[r[0][0], r[0][1], 0.0], [r[1][0], r[1][1], 0.0], [0.0, 0.0, 1.0]];
        Contact { dofs_a: dofs_a.to_vec(), dofs_b: dofs_b.map(|b| b.to_vec()), frame, law }
    }

    /// Number of local coordinates (3, 2 or 1).
    pub fn dim(&self) -> usize {
        self.law.dim()
    }

    /// Local rotation as a `dim x dim` row-major matrix (`w = R x`).
    pub fn rotation(&self) -> Vec<f64> {
        let d = self.dim();
        let mut r = vec![0.0; d * d];
        for i in 0..d {
            for j in 0..d {
                r[i * d + j] = self.frame[i][j];
            }
        }
        r
    }

    /// Whether `other` acts on the same local coordinates: same `dofs_a`, `dofs_b` and
    /// rotation (then both laws act in parallel on one coordinate block).
    pub fn same_kinematics(&self, other: &Contact) -> bool {
        self.dim() == other.dim() && self.dofs_a == other.dofs_a && self.dofs_b == other.dofs_b && self.rotation() == other.rotation()
    }

    /// Checks DoF indices against the model size, the frame for orthonormality, and the law.
    pub fn validate(&self, index: usize, n_dof: usize) -> Result<()> {
        let what = format!("contact[{index}]");
        let d = self.dim();
        if self.dofs_a.len() != d {
            return Err(JpError::bad_size(format!("{what}.dofs_a"), d, self.dofs_a.len()));
        }
        let all = self.dofs_a.iter().chain(self.dofs_b.iter().flatten());
        for &dof in all {
            if dof >= n_dof {
                return Err(JpError::invalid(format!("{what}.dofs"), format!("DoF {dof} >= model size {n_dof}")));
            }
        }
        if let Some(b) = &self.dofs_b {
            if b.len() != d {
                return Err(JpError::bad_size(format!("{what}.dofs_b"), d, b.len()));
            }
            if b.iter().any(|x| self.dofs_a.contains(x)) {
                return Err(JpError::invalid(format!("{what}.dofs_b"), "node b shares a DoF with node a"));
            }
        }
        let r = self.rotation();
        for i in 0..d {
            for j in 0..d {
                let dot: f64 = (0..d).map(|k| r[i * d + k] * r[j * d + k]).sum();
                let expect = if i == j { 1.0 } else { 0.0 };
                if !dot.is_finite() || (dot - expect).abs() > 1e-8 {
                    return Err(JpError::invalid(format!("{what}.frame"), "rows must be orthonormal"));
                }
            }
        }
        self.law.validate(&what)
    }
}

/// The identity local frame (local axes = global axes, normal along z).
pub const IDENTITY_FRAME: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
