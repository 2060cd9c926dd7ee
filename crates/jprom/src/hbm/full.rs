//! The full-order harmonic system: every DoF of the model, in the contact coordinates
//! `z = [w; y]` of [`ContactCoordinates`] (contact coordinates first, so
//! [`ContactMap::Leading`]). Per harmonic `D_h = K - (h omega)^2 M + i h omega C`, `D_0 = K`
//! (docs/formulation.md §2).

use super::{HarmonicLayout, HarmonicSystem, HbmOptions, LinearPart};
use crate::contact::Contacts;
use crate::error::{JpError, Result};
use crate::linalg::{Matrix, SparseMat};
use crate::model::contact_coordinates::dissipation;
use crate::model::{ContactCoordinates, Model};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::Mat;

/// How a full-order system stores its linear part and its HBM Jacobian.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Storage {
    /// Sparse when the system has at least [`SPARSE_MIN_UNKNOWNS`] unknowns and `K`, `M`, `C`
    /// together fill at most [`SPARSE_MAX_FILL`] of their entries; dense otherwise.
    #[default]
    Auto,
    Dense,
    Sparse,
}

/// Fewest HBM unknowns `N (2H + 1)` for which [`Storage::Auto`] may choose sparse storage.
pub const SPARSE_MIN_UNKNOWNS: usize = 1000;
/// Largest share of nonzero entries of `K`, `M`, `C` (their union) for which
/// [`Storage::Auto`] chooses sparse storage.
pub const SPARSE_MAX_FILL: f64 = 0.05;

/// `K`, `M` and `C` of the contact coordinates on the union of their patterns.
#[derive(Clone, Debug)]
struct SparseParts {
    pattern: SymbolicSparseColMat<usize>,
    k: Vec<f64>,
    m: Vec<f64>,
    c: Vec<f64>,
}

impl SparseParts {
    fn new(c: &ContactCoordinates) -> Self {
        let n = c.n_dof;
        let (mut col_ptr, mut row_idx) = (vec![0usize], Vec::new());
        let (mut k, mut m, mut d) = (Vec::new(), Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..n {
                let (kv, mv, cv) = (c.stiffness[(i, j)], c.mass[(i, j)], c.damping[(i, j)]);
                if kv != 0.0 || mv != 0.0 || cv != 0.0 {
                    row_idx.push(i);
                    k.push(kv);
                    m.push(mv);
                    d.push(cv);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        SparseParts { pattern, k, m, c: d }
    }

    fn matrix(&self, values: Vec<f64>) -> Matrix {
        let a: SparseMat = SparseColMat::new(self.pattern.clone(), values);
        Matrix::Sparse(a)
    }
}

/// Full-order HBM system of a [`Model`].
#[derive(Clone, Debug)]
pub struct FullSystem {
    coords: ContactCoordinates,
    layout: HarmonicLayout,
    /// Present when the system is stored sparse.
    sparse: Option<SparseParts>,
}

impl FullSystem {
    /// Builds the system for `opts.harmonics` harmonics, stored as [`Storage::Auto`] chooses.
    ///
    /// # Errors
    /// The model's validation errors; [`JpError::InvalidValue`] for bad options;
    /// [`JpError::SingularMatrix`] when the model has no contact and `K` is singular (the
    /// static problem `K q_0 = f_0` then has no unique solution).
    pub fn new(model: &Model, opts: &HbmOptions) -> Result<Self> {
        Self::with_storage(model, opts, Storage::Auto)
    }

    /// Builds the system with the given storage.
    ///
    /// # Errors
    /// As [`FullSystem::new`].
    pub fn with_storage(model: &Model, opts: &HbmOptions, storage: Storage) -> Result<Self> {
        opts.validate()?;
        let coords = ContactCoordinates::new(model, opts.harmonics)?;
        if model.contacts.is_empty() {
            crate::linalg::check_nonsingular(&coords.stiffness, "stiffness K of a model without contacts")?;
        }
        let layout = HarmonicLayout::uniform(opts.harmonics, coords.n_dof);
        let sparse = match storage {
            Storage::Dense => None,
            Storage::Sparse => Some(SparseParts::new(&coords)),
            Storage::Auto if layout.total() < SPARSE_MIN_UNKNOWNS => None,
            Storage::Auto => {
                let parts = SparseParts::new(&coords);
                let n = coords.n_dof as f64;
                (parts.k.len() as f64 <= SPARSE_MAX_FILL * n * n).then_some(parts)
            }
        };
        Ok(FullSystem { coords, layout, sparse })
    }

    /// The model in contact coordinates.
    pub fn coordinates(&self) -> &ContactCoordinates {
        &self.coords
    }

    /// The storage in use: [`Storage::Dense`] or [`Storage::Sparse`].
    pub fn storage(&self) -> Storage {
        if self.sparse.is_some() {
            Storage::Sparse
        } else {
            Storage::Dense
        }
    }
}

/// `D_h` and `f_h` of the model in contact coordinates, all `N` DoFs.
pub(crate) fn dynamic_stiffness_parts(c: &ContactCoordinates, omega: f64, h: usize) -> (Mat<f64>, Mat<f64>) {
    let hw = h as f64 * omega;
    let n = c.n_dof;
    let re = Mat::from_fn(n, n, |i, j| c.stiffness[(i, j)] - hw * hw * c.mass[(i, j)]);
    let im = Mat::from_fn(n, n, |i, j| c.dissipation(hw, i, j));
    (re, im)
}

impl HarmonicSystem for FullSystem {
    fn layout(&self) -> &HarmonicLayout {
        &self.layout
    }
    fn contacts(&self) -> Contacts<'_> {
        self.coords.contacts()
    }
    fn linear_part(&self, omega: f64) -> Result<LinearPart> {
        super::options::check_omega(omega)?;
        let c = &self.coords;
        let mut lin = LinearPart {
            d0: match &self.sparse {
                Some(p) => p.matrix(p.k.clone()),
                None => c.stiffness.clone().into(),
            },
            f0: c.static_force.clone(),
            dh_re: Vec::new(),
            dh_im: Vec::new(),
            fh_cos: Vec::new(),
            fh_sin: Vec::new(),
        };
        for h in 1..=self.layout.harmonics {
            let (re, im) = match &self.sparse {
                Some(p) => {
                    let hw = h as f64 * omega;
                    let re = p.k.iter().zip(&p.m).map(|(k, m)| k - hw * hw * m).collect();
                    let im = p.c.iter().zip(&p.k).map(|(cv, k)| dissipation(hw, *cv, *k, c.loss_factor)).collect();
                    (p.matrix(re), p.matrix(im))
                }
                None => {
                    let (re, im) = dynamic_stiffness_parts(c, omega, h);
                    (re.into(), im.into())
                }
            };
            lin.dh_re.push(re);
            lin.dh_im.push(im);
            lin.fh_cos.push(c.harmonic_force[h - 1].0.clone());
            lin.fh_sin.push(c.harmonic_force[h - 1].1.clone());
        }
        Ok(lin)
    }
    fn output_harmonics(&self, _omega: f64, z: &[f64]) -> Result<Vec<f64>> {
        if z.len() != self.layout.total() {
            return Err(JpError::bad_size("HBM unknowns z", self.layout.total(), z.len()));
        }
        let n_coeffs = 2 * self.layout.harmonics + 1;
        let mut out = Vec::with_capacity(n_coeffs * self.coords.output_dofs.len());
        for k in 0..n_coeffs {
            let (off, n) = self.layout.coeff_range(k);
            out.extend(self.coords.at_outputs(&z[off..off + n]));
        }
        Ok(out)
    }
    fn n_outputs(&self) -> usize {
        self.coords.output_dofs.len()
    }
}
