//! The full-order harmonic system: every DoF of the model, in the contact coordinates
//! `z = [w; y]` of [`ContactCoordinates`] (contact coordinates first, so
//! [`ContactMap::Leading`]). Per harmonic `D_h = K - (h omega)^2 M + i h omega C`, `D_0 = K`
//! (docs/formulation.md §2).

use super::{Discretisation, HarmonicLayout, HarmonicSystem, LinearPart};
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
    /// Builds the system with the harmonics and AFT samples of `discretisation` (`H` alone
    /// takes the default `Nt`), stored as [`Storage::Auto`] chooses.
    ///
    /// # Errors
    /// The model's validation errors; [`JpError::InvalidValue`] for bad options;
    /// [`JpError::SingularMatrix`] when the model has no contact and `K` is singular (the
    /// static problem `K q_0 = f_0` then has no unique solution).
    pub fn new(model: &Model, discretisation: impl Into<Discretisation>) -> Result<Self> {
        Self::with_storage(model, discretisation, Storage::Auto)
    }

    /// Builds the system with the given storage.
    ///
    /// # Errors
    /// As [`FullSystem::new`].
    pub fn with_storage(model: &Model, discretisation: impl Into<Discretisation>, storage: Storage) -> Result<Self> {
        let coords = ContactCoordinates::new(model, discretisation)?;
        if model.contacts.is_empty() {
            crate::linalg::check_nonsingular(&coords.stiffness, "stiffness K of a model without contacts")?;
        }
        let layout = HarmonicLayout::uniform(coords.discretisation.harmonics, coords.n_dof);
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
        if sparse.is_none() {
            // the dense Newton Jacobian on (2H + 1) n unknowns and its LU
            let unknowns = layout.total();
            crate::memory::check(
                &format!("the dense harmonic-balance Jacobian of the full-order system ({unknowns} unknowns at H = {})", layout.harmonics),
                super::residual::dense_jacobian_bytes(unknowns),
            )?;
        }
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

/// The real and imaginary parts of `D_h = K - (h omega)^2 M + i (h omega C + eta K)` of the model
/// in contact coordinates, all `N` DoFs, into `re` and `im` (`N x N`).
fn dynamic_stiffness_parts_into(c: &ContactCoordinates, omega: f64, h: usize, re: &mut Mat<f64>, im: &mut Mat<f64>) {
    let hw = h as f64 * omega;
    for j in 0..c.n_dof {
        for i in 0..c.n_dof {
            re[(i, j)] = c.stiffness[(i, j)] - hw * hw * c.mass[(i, j)];
            im[(i, j)] = c.dissipation(hw, i, j);
        }
    }
}

impl FullSystem {
    /// Whether `m` has this system's storage (and, sparse, its pattern).
    fn is_own(&self, m: &Matrix) -> bool {
        let n = self.coords.n_dof;
        match (&self.sparse, m) {
            (Some(p), Matrix::Sparse(a)) => {
                let s = a.as_ref().symbolic();
                s.nrows() == n && s.col_ptr() == p.pattern.col_ptr() && s.row_idx() == p.pattern.row_idx()
            }
            (None, Matrix::Dense(a)) => a.nrows() == n && a.ncols() == n,
            _ => false,
        }
    }

    /// A linear part of this system's storage and sizes (values to be filled).
    fn empty_linear_part(&self) -> LinearPart {
        let n = self.coords.n_dof;
        let h_max = self.layout.harmonics;
        let matrix = || match &self.sparse {
            Some(p) => p.matrix(vec![0.0; p.k.len()]),
            None => Matrix::Dense(Mat::zeros(n, n)),
        };
        LinearPart {
            d0: matrix(),
            f0: vec![0.0; n],
            dh_re: (0..h_max).map(|_| matrix()).collect(),
            dh_im: (0..h_max).map(|_| matrix()).collect(),
            fh_cos: vec![vec![0.0; n]; h_max],
            fh_sin: vec![vec![0.0; n]; h_max],
        }
    }
}

impl HarmonicSystem for FullSystem {
    fn layout(&self) -> &HarmonicLayout {
        &self.layout
    }
    fn contacts(&self) -> Contacts<'_> {
        self.coords.contacts()
    }
    fn linear_part(&self, omega: f64) -> Result<LinearPart> {
        let mut lin = None;
        self.linear_part_into(omega, &mut lin)?;
        Ok(lin.expect("linear_part_into sets it"))
    }
    fn linear_part_into(&self, omega: f64, out: &mut Option<LinearPart>) -> Result<()> {
        super::options::check_omega(omega)?;
        let c = &self.coords;
        let h_max = self.layout.harmonics;
        let fits = out.as_ref().is_some_and(|l| {
            l.dh_re.len() == h_max && l.dh_im.len() == h_max && self.is_own(&l.d0) && l.dh_re.iter().chain(&l.dh_im).all(|m| self.is_own(m))
        });
        if !fits {
            *out = Some(self.empty_linear_part());
        }
        let lin = out.as_mut().expect("set above");
        lin.f0.copy_from_slice(&c.static_force);
        match (&self.sparse, &mut lin.d0) {
            (Some(p), Matrix::Sparse(d0)) => d0.val_mut().copy_from_slice(&p.k),
            (None, Matrix::Dense(d0)) => d0.copy_from(&c.stiffness),
            _ => unreachable!("storage checked above"),
        }
        for h in 1..=h_max {
            let hw = h as f64 * omega;
            match (&self.sparse, &mut lin.dh_re[h - 1], &mut lin.dh_im[h - 1]) {
                (Some(p), Matrix::Sparse(re), Matrix::Sparse(im)) => {
                    for ((v, k), m) in re.val_mut().iter_mut().zip(&p.k).zip(&p.m) {
                        *v = k - hw * hw * m;
                    }
                    for ((v, cv), k) in im.val_mut().iter_mut().zip(&p.c).zip(&p.k) {
                        *v = dissipation(hw, *cv, *k, c.loss_factor);
                    }
                }
                (None, Matrix::Dense(re), Matrix::Dense(im)) => dynamic_stiffness_parts_into(c, omega, h, re, im),
                _ => unreachable!("storage checked above"),
            }
            lin.fh_cos[h - 1].copy_from_slice(&c.harmonic_force[h - 1].0);
            lin.fh_sin[h - 1].copy_from_slice(&c.harmonic_force[h - 1].1);
        }
        Ok(())
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
