//! Contact elements (docs/formulation.md §4.2): where they sit in the model and which law they follow.
//!
//! A contact acts on a *local relative displacement* `w`: `w = R (x_a - x_b)` for a node pair,
//! `w = R x_a` for a node against ground, with `w = (u1, u2, v)` and `v` positive into the
//! contact. The element force `F = (T1, T2, N)` is what the contact pushes back with, so the
//! force on the structure is `f_a = -R^T F` (and `f_b = +R^T F`). The *contact stiffness*
//! `K̂ = dF/dw` is positive semi-definite while everything sticks.

pub mod law;
pub mod jenkins;

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
    /// Number of tangential directions (2 for the 3D element, 1 for Jenkins).
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
}

impl ContactLaw {
    /// Number of local coordinates the law acts on (3 or 1).
    pub fn dim(&self) -> usize {
        match self {
            ContactLaw::Friction3D { .. } => 3,
            ContactLaw::Jenkins { .. } => 1,
        }
    }

    /// Linear stiffness of the fully stuck, closed contact: `diag(kt1, kt2, kn)` or `kt`.
    pub fn stuck_stiffness(&self) -> Vec<f64> {
        match *self {
            ContactLaw::Friction3D { kt1, kt2, kn, .. } => vec![kt1, kt2, kn],
            ContactLaw::Jenkins { kt, .. } => vec![kt],
        }
    }

    /// Rejects negative or non-finite parameters.
    pub fn validate(&self, what: &str) -> Result<()> {
        let check = |name: &str, v: f64| -> Result<()> {
            if !v.is_finite() || v < 0.0 {
                Err(JpError::invalid(format!("{what}.{name}"), format!("must be finite and >= 0, got {v}")))
            } else {
                Ok(())
            }
        };
        match *self {
            ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 } => {
                check("kt1", kt1)?;
                check("kt2", kt2)?;
                check("kn", kn)?;
                check("mu", mu)?;
                if !n0.is_finite() {
                    return Err(JpError::invalid(format!("{what}.n0"), format!("must be finite, got {n0}")));
                }
                Ok(())
            }
            ContactLaw::Jenkins { kt, mu, normal_load } => {
                check("kt", kt)?;
                check("mu", mu)?;
                check("normal_load", normal_load)
            }
        }
    }
}

/// The contacts of a system as the AFT sees them: their laws in order, the offset of each
/// contact's coordinates in `w`, and the number of contact coordinates `n_w`.
#[derive(Clone, Copy, Debug)]
pub struct Contacts<'a> {
    pub laws: &'a [ContactLaw],
    pub offsets: &'a [usize],
    pub n_w: usize,
}

/// Where a contact sits: the DoFs of node `a` (and `b` for a pair) and the local frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// Global DoF indices of node `a` (3 for a 3D law, 1 for Jenkins).
    pub dofs_a: Vec<usize>,
    /// Global DoF indices of node `b` for a node pair; `None` for a contact with ground.
    pub dofs_b: Option<Vec<usize>>,
    /// Rotation to the local frame: rows are the unit vectors `t1`, `t2`, `n` in global
    /// coordinates, so `w = R x`. For Jenkins, `[[1]]`-like: only `frame[0][0]` (sign) is used.
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

    /// Number of local coordinates (3 or 1).
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
