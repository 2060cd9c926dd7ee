//! Partial eigen solve of the JP problem (31) by shift-invert Arnoldi (docs/formulation.md §8, step 3),
//! for models too large for the dense solve of the whole condensed problem.
//!
//! With the shift `σ` (the square of the band centre, rad/s) the operator
//!
//! ```text
//! A = (K_JC - σ M_JC)^-1 M_JC
//! ```
//!
//! has the eigenvectors of (31) and eigenvalues `θ = 1 / (λ - σ)`, so its largest ones are the
//! eigenvalues of (31) nearest the band. faer's matrix-free Krylov-Schur solver
//! (`faer::matrix_free::eigen::partial_eigen`, real non-symmetric, eigenvalues of largest
//! magnitude) finds them, or from [`BLOCK_KRYLOV_MIN_DIM`] unknowns block Arnoldi
//! ([`crate::linalg::block_arnoldi`], [`Krylov`]): there one application of `A` reads
//! factors of hundreds of MB, and a block of vectors costs about what one vector does;
//! `(K_JC - σ M_JC)` is never inverted, only factorised
//! ([`ShiftedSolve`]): either densely, or — the structured form — as a factorisation of the
//! model itself plus a correction on the contact coordinates,
//!
//! ```text
//! K_JC - σ M_JC = blockdiag_c(B_h(c)) + E^T S E,   B_h = K - σ h^2 M,
//! S_ij = K̂_ij - K̂_i0 A_0^-1|_ww K̂_0j   (i, j = 1..=2H),
//! ```
//!
//! `E` selecting the first `n_w` rows (the contact coordinates) of each of the `2H` coefficient
//! blocks. One LU per harmonic (shared by its cos and sin blocks) and the Woodbury identity
//! `(B + E^T S E)^-1 = B^-1 - B^-1 E^T (I + S R)^-1 S E B^-1`, `R = E B^-1 E^T`, give the
//! solve with one further dense LU of size `2 H n_w`.
//!
//! **Coverage.** `k` eigenpairs are requested; every eigenvalue nearer to `σ` than the farthest
//! converged one has been found, so the selection is complete when the `λ`-range of the band
//! (widened to the farthest kept extra eigenpair) lies inside the disc
//! `|λ - σ| < min 1 / |θ|`. Otherwise `k` is doubled (a bounded number of times).
//!
//! **Multiplicities.** Arnoldi from one start vector sees one direction of each eigenspace. In
//! full stick (and whenever `K̂` does not depend on time) (31) commutes with the time shift
//! `J: (q_hc, q_hs) -> (-q_hs, q_hc)`, so each eigenvalue comes in an equal pair `v`, `J v`;
//! a missing partner `J v` (an eigenvector with the same eigenvalue, independent of those
//! found) is added, as are missing complex conjugates, so the kept eigenvalues match the dense
//! solve's (which counts a stuck pair as 2).

use super::mode_selection::ModeOptions;
use super::reference::{reads_lead_columns_in_place, ActivePart, ReferenceFactors, CAPACITANCE_PANEL};
use super::ContactJacobian;
use crate::error::{JpError, Result};
use crate::model::ContactCoordinates;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use crate::linalg::block_arnoldi::BlockArnoldiOptions;
use crate::linalg::gmres::{gmres, GmresOptions};
use crate::linalg::DenseLu;
use faer::matrix_free::LinOp;
use faer::{c64, Mat, MatMut, MatRef, Par};

/// Kept eigenpairs of (31): eigenvalues `(Re, Im)` and the real and imaginary parts of the
/// eigenvectors (`2 H n x m`).
pub type Eigenpairs = (Vec<(f64, f64)>, Mat<f64>, Mat<f64>);

/// Relative tolerance of the Krylov-Schur residual (on the operator scaled to unit norm), and of
/// the block Arnoldi's (relative to its largest Ritz value).
pub const ARNOLDI_TOLERANCE: f64 = 1e-12;
/// Largest accepted relative residual `|K_JC v - λ M_JC v| / (|K_JC v| + |λ| |M_JC v| + f)` of a
/// kept eigenpair, `f` the rounding floor of the products (see `residuals`).
pub const RESIDUAL_TOLERANCE: f64 = 1e-6;
/// Eigenpairs requested at first; doubled until the band is covered.
pub const INITIAL_REQUEST: usize = 16;
/// Number of doublings of the request before giving up.
pub const MAX_DOUBLINGS: usize = 8;
/// Problems of at least this dimension `2 H n` are solved by block Arnoldi
/// ([`crate::linalg::block_arnoldi`]): one application of the operator reads the model-sized
/// factors from memory (about 270 MB at `n` = 5,843), and a block of [`KRYLOV_BLOCK`] vectors
/// costs about what one does. Below it a solve is cheap and faer's Krylov-Schur is kept.
pub const BLOCK_KRYLOV_MIN_DIM: usize = 8_000;
/// Vectors per block of the block Arnoldi.
pub const KRYLOV_BLOCK: usize = 8;
/// Smallest cap of the block Arnoldi's space (`8 k` if larger, `k` the request); past it
/// faer's Krylov-Schur takes over.
pub const BLOCK_KRYLOV_MAX_DIM: usize = 256;

/// From this order `2 H r_l` on, the Woodbury capacitance is factorised in single precision
/// and its solves are refined in double (`Capacitance::Mixed`): the LU is `(2/3) N^3` flops
/// (14 s at `N` = 12,000 on 2 cores, 190 s at 27,648, the 1,922-contact blade's gross-slip
/// patterns at H = 3) and runs twice as fast in single precision, while each refinement step
/// reads the single-precision factors once more. Below it the double LU is cheap.
pub const MIXED_CAPACITANCE_MIN_DIM: usize = 12_000;
/// Largest contraction of the residual by the first refinement step of a probe right-hand
/// side (about `cond(C) eps_single`) at which the single-precision capacitance is kept: each
/// step then gains at least two digits. Otherwise it is factorised again in double precision.
pub const MIXED_ACCEPT: f64 = 1e-2;
/// Refinement steps of a mixed-precision capacitance solve at most; it stops earlier when the
/// residual reaches the rounding floor (`4 eps |b|`) or no longer halves.
pub const MAX_REFINEMENTS: usize = 10;

fn par() -> Par {
    faer::get_global_parallelism()
}

/// How the Krylov space of the shift-invert eigen solve is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Krylov {
    /// One vector at a time: faer's Krylov-Schur.
    Single,
    /// Blocks of [`KRYLOV_BLOCK`] vectors ([`crate::linalg::block_arnoldi`]); an error if its
    /// space reaches its cap first.
    Block,
    /// Blocks from [`BLOCK_KRYLOV_MIN_DIM`] unknowns (Single if their space reaches its cap
    /// first), else Single.
    Auto,
}

/// How [`ShiftedSolve`] factorises `K_JC - σ M_JC`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShiftedFactorisation {
    /// One dense LU of the whole `2 H n` square matrix.
    Dense,
    /// One LU of `K - σ h^2 M` per harmonic and a dense LU of size `2 H n_w` (Woodbury); the
    /// latter in single precision with refined solves from [`MIXED_CAPACITANCE_MIN_DIM`]
    /// ([`ShiftedFactorisation::WoodburyMixed`]), else in double.
    Woodbury,
    /// Woodbury with the capacitance factorised in single precision and its solves refined in
    /// double precision (mixed-precision iterative refinement), whatever its size; in double
    /// if the refinement contracts the residual of a probe by less than [`MIXED_ACCEPT`].
    WoodburyMixed,
    /// The cheaper of the two by a flop estimate (Woodbury when the contact coordinates are a
    /// small part of the model), Dense if the Woodbury solve turns out inaccurate.
    Auto,
}

/// The pieces of the condensed problem (30)-(31) in structured form:
/// `K_JC = blockdiag(K_b) + E_r^T S E_r`, `M_JC = blockdiag(h^2 M)`: either `K_b = K` and `S` on
/// all contact coordinates ([`CondensedProblem::new`]), or `K_b = A_ref` of a prediction's
/// reference and `S = ΔS` on a pattern's active coordinates
/// ([`CondensedProblem::on_reference`], [`super::reference`]).
#[derive(Debug)]
pub struct CondensedProblem<'a> {
    coords: &'a ContactCoordinates,
    harmonics: usize,
    /// `K_b` of every coefficient block.
    base: &'a Mat<f64>,
    /// The contact coordinates `S` acts on (indices into `w`).
    rows: Vec<usize>,
    /// The positions in `rows` of the rows of `S` that may differ from zero (`r_l` of them;
    /// all of `rows` but on a reference, [`ActivePart::lead`]): `S = E_l^T S_l`, so the
    /// Woodbury capacitance is `2 H r_l` square.
    lead: Vec<usize>,
    /// `S`, `2 H r` square (coefficient blocks `1..=2H`, `r = rows.len()`); empty on a
    /// reference, where `factors` give it.
    s: Mat<f64>,
    /// The reference whose factorisations the shifted solves use.
    reference: Option<&'a ReferenceFactors>,
    /// On a reference, the factors of `S` (see [`ActiveCondensation`]).
    factors: Option<ActiveCondensation<'a>>,
}

/// `S = ΔS_ij = D_ij - D_i0 g_aa D_0j` of a pattern on a reference, by its factors: the
/// contact blocks `D_kl` (block diagonal, one `d x d` block per active contact) and `g_aa`
/// (dense, `r` square). `S X` then costs `O(H^2 r d k + r^2 k)` instead of `O(H^2 r^2 k)`,
/// and the capacitance `S R` (`R` block diagonal per coefficient) `2 (2H) r^3` instead of
/// `2 (2H)^2 r^3` flops.
#[derive(Debug, Clone, Copy)]
struct ActiveCondensation<'a> {
    part: &'a ActivePart,
    g_aa: &'a Mat<f64>,
}

impl ActiveCondensation<'_> {
    /// `S X` for `X` (`2 H r x k`, coefficient blocks `1..=2H`).
    fn times(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let r = self.part.len();
        let nj = x.nrows() / r.max(1);
        let k = x.ncols();
        // v = sum_j D_0j x_j, t = g_aa v
        let mut v = Mat::<f64>::zeros(r, k);
        for cj in 1..=nj {
            v += self.part.block_times(0, cj, x.submatrix((cj - 1) * r, 0, r, k));
        }
        let t = self.g_aa * &v;
        let mut out = Mat::<f64>::zeros(nj * r, k);
        for ci in 1..=nj {
            let mut oi = out.as_mut().submatrix_mut((ci - 1) * r, 0, r, k);
            for cj in 1..=nj {
                oi += self.part.block_times(ci, cj, x.submatrix((cj - 1) * r, 0, r, k));
            }
            oi -= self.part.block_times(ci, 0, t.as_ref());
        }
        out
    }

    /// A bound of `|S| x` (`x >= 0`, `2 H r x k`): `sum_j |D_ij| x_j + |D_i0| |g_aa| |D_0j| x_j`
    /// (the rounding scale of `S x`).
    fn abs_times(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let r = self.part.len();
        let nj = x.nrows() / r.max(1);
        let k = x.ncols();
        let mut v = Mat::<f64>::zeros(r, k);
        for cj in 1..=nj {
            v += self.part.abs_block_times(0, cj, x.submatrix((cj - 1) * r, 0, r, k));
        }
        let t = abs_product(self.g_aa, v.as_ref());
        let mut out = Mat::<f64>::zeros(nj * r, k);
        for ci in 1..=nj {
            let mut oi = out.as_mut().submatrix_mut((ci - 1) * r, 0, r, k);
            for cj in 1..=nj {
                oi += self.part.abs_block_times(ci, cj, x.submatrix((cj - 1) * r, 0, r, k));
            }
            oi += self.part.abs_block_times(ci, 0, t.as_ref());
        }
        out
    }

    /// `g_aa E_l^T` (`r x r_l`): the columns of `g_aa` that `D_0j` reaches.
    fn g_lead(&self) -> Mat<f64> {
        let lead = &self.part.lead;
        Mat::from_fn(self.part.len(), lead.len(), |i, j| self.g_aa[(i, lead[j])])
    }

    /// The leading rows of the column block `cj` (`1..=2H`) of `S`, times `x` (`r x k`):
    /// `2 H r_l x k`. `g_lead` is [`ActiveCondensation::g_lead`]; `D_0j x` lives on the
    /// leading rows, so the dense product is `r x r_l` by `r_l x k`.
    fn lead_column_block_times(&self, g_lead: &Mat<f64>, cj: usize, nj: usize, x: MatRef<'_, f64>) -> Mat<f64> {
        let lead = &self.part.lead;
        let rl = lead.len();
        let k = x.ncols();
        let v = self.part.block_times(0, cj, x);
        let v_l = Mat::from_fn(rl, k, |i, j| v[(lead[i], j)]);
        let t = crate::linalg::product(g_lead.as_ref(), v_l.as_ref());
        let r = self.part.len();
        let mut full = Mat::<f64>::zeros(nj * r, k);
        for ci in 1..=nj {
            let mut oi = full.as_mut().submatrix_mut((ci - 1) * r, 0, r, k);
            oi += self.part.block_times(ci, cj, x);
            oi -= self.part.block_times(ci, 0, t.as_ref());
        }
        leading_rows(full.as_ref(), r, lead, nj)
    }
}

impl<'a> CondensedProblem<'a> {
    /// `S_ij = K̂_ij - K̂_i0 g_ww K̂_0j` with `g_ww = (K + K̂_00)^-1|_ww` (the contact block of the
    /// static condensation (28)).
    ///
    /// # Errors
    /// [`JpError::BadSize`] if the sizes do not match.
    pub fn new(coords: &'a ContactCoordinates, k_hat: &ContactJacobian, g_ww: &Mat<f64>) -> Result<Self> {
        let nw = coords.n_w;
        let hh = k_hat.harmonics;
        if k_hat.n_w != nw || k_hat.k_hat.nrows() != (2 * hh + 1) * nw {
            return Err(JpError::bad_size("contact Jacobian (rows)", (2 * hh + 1) * nw, k_hat.k_hat.nrows()));
        }
        if g_ww.nrows() != nw || g_ww.ncols() != nw {
            return Err(JpError::bad_size("static condensation block g_ww", nw, g_ww.nrows()));
        }
        let s = super::condensed::contact_condensation(coords, k_hat, g_ww);
        Ok(CondensedProblem { coords, harmonics: hh, base: &coords.stiffness, rows: (0..nw).collect(), lead: (0..nw).collect(), s, reference: None, factors: None })
    }

    /// The condensed problem of the pattern `part` on `reference`: `K_b = A_ref`,
    /// `S = ΔS_ij = D_ij - D_i0 g_aa D_0j` on the active coordinates.
    pub fn on_reference(coords: &'a ContactCoordinates, reference: &'a ReferenceFactors, part: &'a ActivePart, g_aa: &'a Mat<f64>) -> Self {
        // S is applied by its factors; the dense 2Hr-square S is formed only for
        // `dense_shifted` (tests)
        let s = Mat::<f64>::zeros(0, 0);
        let factors = Some(ActiveCondensation { part, g_aa });
        CondensedProblem { coords, harmonics: reference.harmonics(), base: reference.a_ref(), rows: part.rows.clone(), lead: part.lead.clone(), s, reference: Some(reference), factors }
    }

    /// `S X` (`X` of `2 H r` rows), by the factors of `S` where the problem has them.
    fn s_times(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        match &self.factors {
            Some(f) => f.times(x),
            None => &self.s * x,
        }
    }

    /// Size `2 H n` of the condensed problem.
    pub fn dim(&self) -> usize {
        2 * self.harmonics * self.coords.n_dof
    }

    /// `out = (K_JC - shift M_JC) x` (structured, `O(H n^2 + (H n_w)^2)` per column; the
    /// coefficient blocks of all columns side by side, so each model-sized matrix is read once).
    pub fn apply_shifted(&self, x: MatRef<'_, f64>, shift: f64) -> Mat<f64> {
        let n = self.coords.n_dof;
        let nj = 2 * self.harmonics;
        let k = x.ncols();
        let xs = side_by_side(x, n, nj);
        let mut ys = crate::linalg::product(self.base.as_ref(), xs.as_ref());
        if shift != 0.0 {
            let ms = crate::linalg::product(self.coords.mass.as_ref(), xs.as_ref());
            for c in 0..nj {
                let h = (c / 2 + 1) as f64;
                let mut yc = ys.as_mut().subcols_mut(c * k, k);
                yc -= faer::Scale(shift * h * h) * ms.as_ref().subcols(c * k, k);
            }
        }
        let mut out = stacked(ys.as_ref(), n, nj);
        let r = self.rows.len();
        let ex = gather(x, n, &self.rows, nj);
        let sex = self.s_times(ex.as_ref());
        for c in 0..nj {
            for j in 0..k {
                for (a, &i) in self.rows.iter().enumerate() {
                    out[(c * n + i, j)] += sex[(c * r + a, j)];
                }
            }
        }
        out
    }

    /// `(| |K_JC| |v| |, | |M_JC| |v| |)` for complex vectors `v` (the rounding scale of the
    /// products), all from one pass over the model-sized matrices.
    fn abs_products(&self, vs: &[&[c64]]) -> Vec<(f64, f64)> {
        let n = self.coords.n_dof;
        let r = self.rows.len();
        let nj = 2 * self.harmonics;
        let m = vs.len();
        // |v| with the coefficient blocks side by side: column c m + p
        let a = Mat::from_fn(n, nj * m, |i, col| {
            let z = vs[col % m][(col / m) * n + i];
            z.re.hypot(z.im)
        });
        let mut ka = abs_product(self.base, a.as_ref());
        let ma = abs_product(&self.coords.mass, a.as_ref());
        if r > 0 {
            // |S| |E v| (coefficient blocks stacked), added on the active rows
            let aw = Mat::from_fn(nj * r, m, |q, p| a[(self.rows[q % r], (q / r) * m + p)]);
            let sa = match &self.factors {
                Some(f) => f.abs_times(aw.as_ref()),
                None => abs_product(&self.s, aw.as_ref()),
            };
            for c in 0..nj {
                for p in 0..m {
                    for (q, &i) in self.rows.iter().enumerate() {
                        ka[(i, c * m + p)] += sa[(c * r + q, p)];
                    }
                }
            }
        }
        (0..m)
            .map(|p| {
                let (mut k2, mut m2) = (0.0, 0.0);
                for c in 0..nj {
                    let h = (c / 2 + 1) as f64;
                    k2 += ka.col(c * m + p).squared_norm_l2();
                    m2 += h.powi(4) * ma.col(c * m + p).squared_norm_l2();
                }
                (k2.sqrt(), m2.sqrt())
            })
            .collect()
    }

    /// `M_JC x`.
    pub fn apply_mass(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let n = self.coords.n_dof;
        let nj = 2 * self.harmonics;
        let k = x.ncols();
        let mut ys = crate::linalg::product(self.coords.mass.as_ref(), side_by_side(x, n, nj).as_ref());
        for c in 0..nj {
            let h = (c / 2 + 1) as f64;
            let mut yc = ys.as_mut().subcols_mut(c * k, k);
            yc *= faer::Scale(h * h);
        }
        stacked(ys.as_ref(), n, nj)
    }

    /// Dense `K_JC - shift M_JC` (for tests and the dense factorisation).
    pub fn dense_shifted(&self, shift: f64) -> Mat<f64> {
        let n = self.coords.n_dof;
        let r = self.rows.len();
        let nj = 2 * self.harmonics;
        let mut a = Mat::<f64>::zeros(nj * n, nj * n);
        for c in 0..nj {
            let h = (c / 2 + 1) as f64;
            let mut blk = a.as_mut().submatrix_mut(c * n, c * n, n, n);
            blk.copy_from(self.base);
            blk -= faer::Scale(shift * h * h) * &self.coords.mass;
        }
        let s_dense = match &self.factors {
            Some(f) => super::reference::active_condensation(f.part, f.g_aa),
            None => self.s.clone(),
        };
        for cj in 0..nj {
            for (b, &j) in self.rows.iter().enumerate() {
                for ci in 0..nj {
                    for (q, &i) in self.rows.iter().enumerate() {
                        a[(ci * n + i, cj * n + j)] += s_dense[(ci * r + q, cj * r + b)];
                    }
                }
            }
        }
        a
    }
}

/// `E_r x`: the rows `rows` of every coefficient block.
fn gather(x: MatRef<'_, f64>, n: usize, rows: &[usize], nj: usize) -> Mat<f64> {
    let r = rows.len();
    Mat::from_fn(nj * r, x.ncols(), |q, j| x[((q / r) * n + rows[q % r], j)])
}

/// `E_l y`: the leading rows `lead` (positions among the `r` rows of a block) of every one of
/// the `nj` coefficient blocks of `y` (`nj r` rows).
fn leading_rows(y: MatRef<'_, f64>, r: usize, lead: &[usize], nj: usize) -> Mat<f64> {
    let rl = lead.len();
    Mat::from_fn(nj * rl, y.ncols(), |q, j| y[((q / rl) * r + lead[q % rl], j)])
}

/// The `nj` coefficient blocks (`n` rows each) of `x` side by side: `n x (nj k)`, block `c`
/// in columns `c k..(c + 1) k`.
fn side_by_side(x: MatRef<'_, f64>, n: usize, nj: usize) -> Mat<f64> {
    let k = x.ncols();
    Mat::from_fn(n, nj * k, |i, col| x[((col / k) * n + i, col % k)])
}

/// The inverse of [`side_by_side`].
fn stacked(y: MatRef<'_, f64>, n: usize, nj: usize) -> Mat<f64> {
    let k = y.ncols() / nj.max(1);
    Mat::from_fn(nj * n, k, |row, j| y[(row % n, (row / n) * k + j)])
}

/// `|m| x` (entrywise absolute values of `m`) by column panels of `|m|`, never all of it.
fn abs_product(m: &Mat<f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    const PANEL: usize = 256;
    let (nr, nc) = (m.nrows(), m.ncols());
    let mut out = Mat::<f64>::zeros(nr, x.ncols());
    let mut panel = Mat::<f64>::zeros(nr, PANEL.min(nc));
    for j0 in (0..nc).step_by(PANEL) {
        let w = PANEL.min(nc - j0);
        for j in 0..w {
            for (p, v) in panel.col_mut(j).iter_mut().zip(m.col(j0 + j).iter()) {
                *p = v.abs();
            }
        }
        faer::linalg::matmul::matmul(out.as_mut(), faer::Accum::Add, panel.as_ref().subcols(0, w), x.subrows(j0, w), 1.0, par());
    }
    out
}

/// The LUs of the `B_h` of a Woodbury solve: its own, or a prediction reference's (index per
/// harmonic `1..=H` into [`ReferenceFactors`]' `B_0..B_H`).
#[derive(Debug)]
enum HarmonicLus<'a> {
    Own(Vec<DenseLu<f64>>),
    Shared(&'a ReferenceFactors, Vec<usize>),
}

impl HarmonicLus<'_> {
    /// LU of `B_h` for harmonic `h = hi + 1`.
    fn get(&self, hi: usize) -> &DenseLu<f64> {
        match self {
            HarmonicLus::Own(v) => &v[hi],
            HarmonicLus::Shared(r, idx) => r.lu(idx[hi]),
        }
    }
}

/// `Y_h,l = B_h^-1 E_l^T`, `h = 1..=H`: its own copies, or (most coordinates leading) the
/// columns of the reference's `Y_h = B_h^-1 E^T`, read in place: on the fully active patterns
/// of the 1,922-contact blade at H = 3 the copies were 645 MB.
#[derive(Debug)]
enum LeadColumns<'a> {
    Own(Vec<Mat<f64>>),
    /// The reference, its `Y` index per harmonic, and the leading coordinates (columns of `Y_h`).
    Shared(&'a ReferenceFactors, Vec<usize>, Vec<usize>),
}

impl LeadColumns<'_> {
    /// Entry `(i, j)` of `Y_h,l`, `h = hi + 1`.
    fn entry(&self, hi: usize, i: usize, j: usize) -> f64 {
        match self {
            LeadColumns::Own(y) => y[hi][(i, j)],
            LeadColumns::Shared(reference, idx, cols) => reference.y(idx[hi])[(i, cols[j])],
        }
    }

    /// `Y_h(c),l u_c` for every coefficient block `c` of `u` (`2 H` blocks of `r_l` rows), the
    /// cos and sin blocks of a harmonic in one product with its `Y_h`: per harmonic
    /// `h = hi + 1` an `n x 2k` matrix, the cos block's columns first.
    fn times_coefficients(&self, u: MatRef<'_, f64>, rl: usize, harmonics: usize) -> Vec<Mat<f64>> {
        let k = u.ncols();
        (0..harmonics)
            .map(|hi| {
                let both = Mat::from_fn(rl, 2 * k, |q, j| u[((2 * hi + j / k) * rl + q, j % k)]);
                self.times(hi, both.as_ref())
            })
            .collect()
    }

    /// `Y_h,l u` (`u` with `r_l` rows), `h = hi + 1`.
    fn times(&self, hi: usize, u: MatRef<'_, f64>) -> Mat<f64> {
        match self {
            LeadColumns::Own(y) => &y[hi] * u,
            LeadColumns::Shared(reference, idx, cols) => {
                let y = reference.y(idx[hi]);
                let mut scattered = Mat::<f64>::zeros(y.ncols(), u.ncols());
                for j in 0..u.ncols() {
                    for (q, &c) in cols.iter().enumerate() {
                        scattered[(c, j)] = u[(q, j)];
                    }
                }
                crate::linalg::product(y.as_ref(), scattered.as_ref())
            }
        }
    }
}

#[derive(Debug)]
enum Factors<'a> {
    Dense(DenseLu<f64>),
    Woodbury {
        /// LU of `B_h = K_b - σ h^2 M`, `h = 1..=H`.
        b: HarmonicLus<'a>,
        /// `B_h^-1 E_l^T` (`n x r_l`, the leading coordinates), `h = 1..=H`.
        y: LeadColumns<'a>,
        /// LU of `I + S_l R` (`2 H r_l` square).
        cap: Capacitance,
    },
}

/// The LU of the Woodbury capacitance `C = I + S_l R`: in double precision, or in single
/// precision with every solve refined in double (`C` applied by its factors,
/// [`capacitance_times`]): `u_0 = LU^-1 b`, `u_i+1 = u_i + LU^-1 (b - C u_i)` — LAPACK's
/// `dsgesv` scheme, which reaches the double LU's accuracy when `cond(C)` is well below
/// `1 / eps_single` (checked on a probe when it is made).
#[derive(Debug)]
enum Capacitance {
    Double(DenseLu<f64>),
    Mixed(DenseLu<f32>),
}

/// `I + S_l R`, `R = blockdiag_c(E_r Y_h(c),l)`, by column panels of at most
/// [`CAPACITANCE_PANEL`] columns (the temporaries — `R`'s panel, `S R`'s and the products
/// inside — stay small beside the capacitance: at H = 3 whole column blocks took 3 GB beside
/// its 6 GB on the 1,922-contact blade), each entry stored by `store` (rounded to single
/// precision for a [`Capacitance::Mixed`]).
fn capacitance_matrix<T: faer::traits::ComplexField + Copy>(problem: &CondensedProblem<'_>, y: &LeadColumns<'_>, store: impl Fn(f64) -> T) -> Mat<T> {
    let r = problem.rows.len();
    let rl = problem.lead.len();
    let nj = 2 * problem.harmonics;
    let g_lead = problem.factors.as_ref().map(|f| f.g_lead());
    let mut cap = Mat::<T>::zeros(nj * rl, nj * rl);
    for cj in 0..nj {
        for p0 in (0..rl).step_by(CAPACITANCE_PANEL) {
            let w = CAPACITANCE_PANEL.min(rl - p0);
            let rr = Mat::from_fn(r, w, |q, j| y.entry(cj / 2, problem.rows[q], p0 + j));
            let sr = match (&problem.factors, &g_lead) {
                (Some(f), Some(g)) => f.lead_column_block_times(g, cj + 1, nj, rr.as_ref()),
                _ => {
                    let full = problem.s.as_ref().submatrix(0, cj * r, nj * r, r) * &rr;
                    leading_rows(full.as_ref(), r, &problem.lead, nj)
                }
            };
            for j in 0..w {
                let col = cj * rl + p0 + j;
                for (i, c) in cap.as_mut().col_mut(col).iter_mut().enumerate() {
                    *c = store(if i == col { 1.0 + sr[(i, j)] } else { sr[(i, j)] });
                }
            }
        }
    }
    cap
}

/// `C u = u + S_l R u` (`u` of `2 H r_l` rows) from the factors of `C`: per harmonic one
/// product with `Y_h,l`, and `S` by its factors.
fn capacitance_times(problem: &CondensedProblem<'_>, y: &LeadColumns<'_>, u: MatRef<'_, f64>) -> Mat<f64> {
    let r = problem.rows.len();
    let rl = problem.lead.len();
    let nj = 2 * problem.harmonics;
    let k = u.ncols();
    let mut ru = Mat::<f64>::zeros(nj * r, k);
    for (hi, yu) in y.times_coefficients(u, rl, nj / 2).iter().enumerate() {
        for half in 0..2 {
            for j in 0..k {
                for (a, &i) in problem.rows.iter().enumerate() {
                    ru[((2 * hi + half) * r + a, j)] = yu[(i, half * k + j)];
                }
            }
        }
    }
    let sru = problem.s_times(ru.as_ref());
    leading_rows(sru.as_ref(), r, &problem.lead, nj) + u
}

/// `C^-1 b` by the single-precision LU of `C` and refinement in double precision
/// ([`Capacitance`]), and the contraction of the first refinement step (the largest
/// `|b_j - C u_j|` after it over the largest before it, relative to `|b_j|`; 0 if the first
/// solve is at the rounding floor): about `cond(C) eps_single`, the rate at which every step
/// gains digits until the residual reaches the double LU's floor. Each correction's
/// right-hand side is scaled to unit size before it is rounded to single precision.
fn refined_solve(lu: &DenseLu<f32>, problem: &CondensedProblem<'_>, y: &LeadColumns<'_>, b: &Mat<f64>) -> (Mat<f64>, f64) {
    let k = b.ncols();
    let single_solve = |rhs: &Mat<f64>| -> Mat<f64> {
        let scale: Vec<f64> = (0..k).map(|j| rhs.col(j).iter().fold(0.0f64, |a, x| a.max(x.abs()))).map(|m| if m > 0.0 { m } else { 1.0 }).collect();
        let x = lu.solve(&Mat::<f32>::from_fn(rhs.nrows(), k, |i, j| (rhs[(i, j)] / scale[j]) as f32));
        Mat::from_fn(rhs.nrows(), k, |i, j| f64::from(x[(i, j)]) * scale[j])
    };
    let b_norm: Vec<f64> = (0..k).map(|j| b.col(j).norm_l2()).collect();
    let relative = |res: &Mat<f64>| (0..k).map(|j| if b_norm[j] > 0.0 { res.col(j).norm_l2() / b_norm[j] } else { res.col(j).norm_l2() }).fold(0.0f64, f64::max);
    let mut u = single_solve(b);
    let mut res = b - capacitance_times(problem, y, u.as_ref());
    let mut rel = relative(&res);
    let mut first_contraction = None;
    for _ in 0..MAX_REFINEMENTS {
        if !(rel > 4.0 * f64::EPSILON) {
            break;
        }
        let next = &u + single_solve(&res);
        let next_res = b - capacitance_times(problem, y, next.as_ref());
        let next_rel = relative(&next_res);
        first_contraction.get_or_insert(next_rel / rel);
        if !(next_rel < rel) {
            break;
        }
        let halved = next_rel <= 0.5 * rel;
        (u, res, rel) = (next, next_res, next_rel);
        if !halved {
            break;
        }
    }
    (u, first_contraction.unwrap_or(0.0))
}

/// A factorisation of `K_JC - σ M_JC` and its solve.
#[derive(Debug)]
pub struct ShiftedSolve<'p, 'a> {
    problem: &'p CondensedProblem<'a>,
    shift: f64,
    factors: Factors<'a>,
}

impl<'p, 'a> ShiftedSolve<'p, 'a> {
    /// Factorises `K_JC - shift M_JC` the way `how` says. A problem on a prediction's reference
    /// ([`CondensedProblem::on_reference`]) always uses the reference's LUs (Woodbury on its
    /// active coordinates), at the reference's shift or at 0.
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] if the matrix (or, for [`ShiftedFactorisation::Woodbury`],
    /// one of its pieces) is singular or the solve is inaccurate; [`JpError::InvalidValue`] for
    /// a problem on a reference at another shift.
    pub fn new(problem: &'p CondensedProblem<'a>, shift: f64, how: ShiftedFactorisation) -> Result<Self> {
        let n = problem.coords.n_dof;
        let rl = problem.lead.len();
        let hh = problem.harmonics;
        let nf = |x: usize| x as f64;
        let how = match (how, problem.reference) {
            (ShiftedFactorisation::WoodburyMixed, Some(_)) => ShiftedFactorisation::WoodburyMixed,
            (_, Some(_)) => ShiftedFactorisation::Woodbury,
            (ShiftedFactorisation::Auto, None) => {
                let dense = nf(2 * hh * n).powi(3) * 2.0 / 3.0;
                let wood = nf(hh) * nf(n).powi(3) * 2.0 / 3.0 + nf(hh) * 2.0 * nf(n).powi(2) * nf(rl) + nf(2 * hh * rl).powi(3) * 2.0 / 3.0;
                if wood < dense {
                    match Self::new(problem, shift, ShiftedFactorisation::Woodbury) {
                        Ok(s) => return Ok(s),
                        Err(_) => ShiftedFactorisation::Dense,
                    }
                } else {
                    ShiftedFactorisation::Dense
                }
            }
            (h, None) => h,
        };
        let factors = match how {
            ShiftedFactorisation::Dense => Factors::Dense(DenseLu::new(&problem.dense_shifted(shift))),
            _ => {
                // the coordinates of the leading rows of S
                let lead_rows: Vec<usize> = problem.lead.iter().map(|&q| problem.rows[q]).collect();
                let (b, y) = match problem.reference {
                    Some(reference) => {
                        let idx: Vec<usize> = if shift == reference.shift() {
                            (1..=hh).collect()
                        } else if shift == 0.0 {
                            vec![0; hh]
                        } else {
                            return Err(JpError::invalid("shift", format!("a problem on a reference is solved at its shift {} or at 0, not {shift}", reference.shift())));
                        };
                        let y = if reads_lead_columns_in_place(lead_rows.len(), problem.coords.n_w) {
                            LeadColumns::Shared(reference, idx.clone(), lead_rows.clone())
                        } else {
                            LeadColumns::Own(idx.iter().map(|&h| reference.y_columns(h, &lead_rows)).collect())
                        };
                        (HarmonicLus::Shared(reference, idx), y)
                    }
                    None => {
                        let mut e = Mat::<f64>::zeros(n, rl);
                        for (q, &i) in lead_rows.iter().enumerate() {
                            e[(i, q)] = 1.0;
                        }
                        let mut lus = Vec::with_capacity(hh);
                        let mut y = Vec::with_capacity(hh);
                        for h in 1..=hh {
                            let bh = problem.base - faer::Scale(shift * (h * h) as f64) * &problem.coords.mass;
                            let lu = DenseLu::new(&bh);
                            y.push(lu.solve(&e));
                            lus.push(lu);
                        }
                        (HarmonicLus::Own(lus), LeadColumns::Own(y))
                    }
                };
                let nj = 2 * hh;
                let mixed = how == ShiftedFactorisation::WoodburyMixed || (how == ShiftedFactorisation::Woodbury && nj * rl >= MIXED_CAPACITANCE_MIN_DIM);
                let cap = if mixed {
                    let lu = DenseLu::from_matrix(capacitance_matrix(problem, &y, |x| x as f32));
                    let probe = Mat::from_fn(nj * rl, 1, |i, _| 1.0 + ((i * 7919) % 13) as f64 / 13.0);
                    let pivots_ok = lu.check_pivots(&String::new).is_ok();
                    if pivots_ok && refined_solve(&lu, problem, &y, &probe).1 <= MIXED_ACCEPT {
                        Capacitance::Mixed(lu)
                    } else {
                        drop(lu);
                        Capacitance::Double(DenseLu::from_matrix(capacitance_matrix(problem, &y, |x| x)))
                    }
                } else {
                    Capacitance::Double(DenseLu::from_matrix(capacitance_matrix(problem, &y, |x| x)))
                };
                Factors::Woodbury { b, y, cap }
            }
        };
        let solve = ShiftedSolve { problem, shift, factors };
        // Check the factorisation on a fixed right-hand side.
        let dim = problem.dim();
        let rhs = Mat::from_fn(dim, 1, |i, _| 1.0 + ((i * 7919) % 13) as f64 / 13.0);
        let x = solve.solve(rhs.as_ref());
        let finite = (0..dim).all(|i| x[(i, 0)].is_finite());
        let res = problem.apply_shifted(x.as_ref(), shift) - &rhs;
        let scale = problem.apply_shifted(x.as_ref(), 0.0).norm_l2() + shift.abs() * problem.apply_mass(x.as_ref()).norm_l2() + rhs.norm_l2();
        if !finite || res.norm_l2() > 1e-9 * scale {
            let on = if problem.reference.is_some() { ", on the prediction's reference" } else { "" };
            return Err(JpError::singular(format!("K_JC - sigma M_JC (shift-invert of the JP problem (31), {how:?} factorisation{on})")));
        }
        Ok(solve)
    }

    /// The shift `σ`.
    pub fn shift(&self) -> f64 {
        self.shift
    }

    /// Whether the Woodbury capacitance is factorised in single precision (its solves refined
    /// in double, [`ShiftedFactorisation::WoodburyMixed`]).
    pub fn single_precision_capacitance(&self) -> bool {
        matches!(self.factors, Factors::Woodbury { cap: Capacitance::Mixed(_), .. })
    }

    /// `K_JC^-1 rhs` (the shift-0 solves of the static corrections) by GMRES on `K_JC`, right
    /// preconditioned with this factorisation at the band's shift σ (docs/formulation.md
    /// §8.10): `K_JC (K_JC - σ M_JC)^-1 = I + σ M_JC (K_JC - σ M_JC)^-1` has the eigenvalues
    /// `λ / (λ - σ)`, clustered at 1 but for the few modes near and below the band, so a few
    /// dozen solves on the factorisation at hand replace a second one at shift 0. `None` when a
    /// column does not reach [`UNSHIFTED_ACCEPT`] (the caller then factorises at 0).
    pub fn solve_unshifted(&self, rhs: MatRef<'_, f64>) -> Option<Mat<f64>> {
        let solve = self;
        let dim = solve.problem.dim();
        if solve.shift == 0.0 {
            return Some(solve.solve(rhs));
        }
        let col = |v: &[f64]| Mat::from_fn(dim, 1, |i, _| v[i]);
        let a = |v: &[f64]| solve.problem.apply_shifted(col(v).as_ref(), 0.0).col(0).iter().copied().collect::<Vec<f64>>();
        let m_inv = |v: &[f64]| solve.solve(col(v).as_ref()).col(0).iter().copied().collect::<Vec<f64>>();
        let mut out = Mat::<f64>::zeros(dim, rhs.ncols());
        for j in 0..rhs.ncols() {
            let b: Vec<f64> = rhs.col(j).iter().copied().collect();
            let found = gmres(&a, &m_inv, &b, &UNSHIFTED_GMRES);
            if !(found.residual <= UNSHIFTED_ACCEPT) {
                return None;
            }
            for (i, x) in found.x.into_iter().enumerate() {
                out[(i, j)] = x;
            }
        }
        Some(out)
    }

    /// `(K_JC - σ M_JC)^-1 rhs`.
    pub fn solve(&self, rhs: MatRef<'_, f64>) -> Mat<f64> {
        let n = self.problem.coords.n_dof;
        let r = self.problem.rows.len();
        let lead = &self.problem.lead;
        let rl = lead.len();
        let nj = 2 * self.problem.harmonics;
        let k = rhs.ncols();
        match &self.factors {
            Factors::Dense(lu) => lu.solve(rhs),
            Factors::Woodbury { b, y, cap } => {
                // x0 = B^-1 rhs, cos and sin blocks of a harmonic in one solve.
                let mut x = Mat::<f64>::zeros(nj * n, k);
                for hi in 0..nj / 2 {
                    let both = Mat::from_fn(n, 2 * k, |i, j| rhs[((2 * hi + j / k) * n + i, j % k)]);
                    let sol = b.get(hi).solve(&both);
                    for j in 0..2 * k {
                        for i in 0..n {
                            x[((2 * hi + j / k) * n + i, j % k)] = sol[(i, j)];
                        }
                    }
                }
                if rl == 0 {
                    return x;
                }
                // u = (I + S_l R)^-1 S_l E_r x0; x = x0 - B^-1 E_l^T u.
                let sex = self.problem.s_times(gather(x.as_ref(), n, &self.problem.rows, nj).as_ref());
                let sex_l = leading_rows(sex.as_ref(), r, lead, nj);
                let u = match cap {
                    Capacitance::Double(lu) => lu.solve(&sex_l),
                    Capacitance::Mixed(lu) => refined_solve(lu, self.problem, y, &sex_l).0,
                };
                for (hi, corr) in y.times_coefficients(u.as_ref(), rl, nj / 2).iter().enumerate() {
                    for half in 0..2 {
                        let mut xc = x.as_mut().submatrix_mut((2 * hi + half) * n, 0, n, k);
                        xc -= corr.as_ref().subcols(half * k, k);
                    }
                }
                x
            }
        }
    }
}

/// GMRES settings of [`unshifted_solve`]: it aims at `1e-13 |b|` and stops at the rounding
/// floor; a column is accepted at a true residual of [`UNSHIFTED_ACCEPT`] `|b|`.
const UNSHIFTED_GMRES: GmresOptions = GmresOptions { tolerance: 1e-13, restart: 100, max_iterations: 300 };

/// Largest relative residual `|b - K_JC x| / |b|` at which [`unshifted_solve`] accepts a column.
pub const UNSHIFTED_ACCEPT: f64 = 1e-11;


/// The shift-invert operator `scale (K_JC - σ M_JC)^-1 M_JC`.
#[derive(Debug)]
struct Operator<'s, 'p, 'a> {
    solve: &'s ShiftedSolve<'p, 'a>,
    scale: f64,
}

impl Operator<'_, '_, '_> {
    fn apply_to(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>) {
        let mx = self.solve.problem.apply_mass(rhs);
        let x = self.solve.solve(mx.as_ref());
        let mut out = out;
        out.copy_from(faer::Scale(self.scale) * &x);
    }
}

impl LinOp<f64> for Operator<'_, '_, '_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.solve.problem.dim()
    }
    fn ncols(&self) -> usize {
        self.solve.problem.dim()
    }
    fn apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        self.apply_to(out, rhs);
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        self.apply_to(out, rhs);
    }
}

/// One eigenpair of (31) with a complex eigenvector of unit length.
#[derive(Clone, Debug)]
struct Pair {
    lambda: c64,
    v: Vec<c64>,
}

fn cnorm(v: &[c64]) -> f64 {
    v.iter().map(|z| z.re * z.re + z.im * z.im).sum::<f64>().sqrt()
}

fn normalised(v: Vec<c64>) -> Vec<c64> {
    let s = cnorm(&v);
    v.into_iter().map(|z| c64::new(z.re / s, z.im / s)).collect()
}

/// Relative residuals `|K_JC v - λ M_JC v| / (|K_JC v| + |λ| |M_JC v|)` of the pairs
/// `(λ, v)`, and with `floor` the same quantities with the rounding floor of the products,
/// `u (| |K_JC| |v| | + |λ| | |M_JC| |v| |)` (`u` the unit round-off times `sqrt(n)`), in the
/// denominator: on stiff models (`|K| >> λ |M|` on the contact coordinates) the computed
/// residual of even an exact eigenvector is at that floor. All pairs share one product with
/// the model-sized matrices (read once, not once per pair).
fn residuals(problem: &CondensedProblem<'_>, pairs: &[(c64, &[c64])], floor: bool) -> Vec<(f64, f64)> {
    let Some(dim) = pairs.first().map(|p| p.1.len()) else {
        return Vec::new();
    };
    let v = Mat::from_fn(dim, 2 * pairs.len(), |i, j| if j % 2 == 0 { pairs[j / 2].1[i].re } else { pairs[j / 2].1[i].im });
    let kv = problem.apply_shifted(v.as_ref(), 0.0);
    let mv = problem.apply_mass(v.as_ref());
    let abs = if floor { Some(problem.abs_products(&pairs.iter().map(|p| p.1).collect::<Vec<_>>())) } else { None };
    pairs
        .iter()
        .enumerate()
        .map(|(p, &(lambda, _))| {
            let (c0, c1) = (2 * p, 2 * p + 1);
            let (lr, li) = (lambda.re, lambda.im);
            let (mut r2, mut k2, mut m2) = (0.0, 0.0, 0.0);
            for i in 0..dim {
                // (kr + i ki) - (lr + i li)(mr + i mi)
                let rr = kv[(i, c0)] - (lr * mv[(i, c0)] - li * mv[(i, c1)]);
                let ri = kv[(i, c1)] - (lr * mv[(i, c1)] + li * mv[(i, c0)]);
                r2 += rr * rr + ri * ri;
                k2 += kv[(i, c0)] * kv[(i, c0)] + kv[(i, c1)] * kv[(i, c1)];
                m2 += mv[(i, c0)] * mv[(i, c0)] + mv[(i, c1)] * mv[(i, c1)];
            }
            let lam = (lr * lr + li * li).sqrt();
            let den = k2.sqrt() + lam * m2.sqrt();
            let fl = abs.as_ref().map_or(0.0, |a| f64::EPSILON * (problem.coords.n_dof as f64).sqrt() * (a[p].0 + lam * a[p].1));
            (r2.sqrt() / den.max(f64::MIN_POSITIVE), r2.sqrt() / (den + fl).max(f64::MIN_POSITIVE))
        })
        .collect()
}

/// Residual of `v` against the span of `basis` (complex, orthonormal) relative to `|v|`.
fn out_of_span(basis: &[Vec<c64>], v: &[c64]) -> (f64, Vec<c64>) {
    let mut r = v.to_vec();
    for _ in 0..2 {
        for q in basis {
            // coefficient q^H r
            let (mut cr, mut ci) = (0.0, 0.0);
            for (a, b) in q.iter().zip(&r) {
                cr += a.re * b.re + a.im * b.im;
                ci += a.re * b.im - a.im * b.re;
            }
            for (a, b) in q.iter().zip(r.iter_mut()) {
                b.re -= cr * a.re - ci * a.im;
                b.im -= cr * a.im + ci * a.re;
            }
        }
    }
    (cnorm(&r) / cnorm(v).max(f64::MIN_POSITIVE), r)
}

/// Refines the Arnoldi pairs by Rayleigh-Ritz on `span(A V, A^2 V)`, `V` the real and
/// imaginary parts of their vectors, for the pencil `(K_JC, M_JC)` itself, and replaces each
/// pair (most accurate first) by the unused Ritz pair of nearest eigenvalue.
///
/// The Krylov-Schur residual is small relative to the largest `θ`: the stiff directions of
/// the model (tiny `θ`) can carry error that is large in the residual of (31), and when `σ`
/// nearly coincides with an eigenvalue, the other pairs are comparatively inaccurate. The
/// applications of `A` damp the stiff directions; the projection resolves the mixing among
/// the nearby ones (plain inverse iteration `v <- A v` would amplify the eigenvector nearest
/// `σ` in every other pair).
fn refine(problem: &CondensedProblem<'_>, op: &Operator<'_, '_, '_>, pairs: &mut [Pair]) -> Result<()> {
    if pairs.is_empty() {
        return Ok(());
    }
    let dim = pairs[0].v.len();
    let m = pairs.len();
    let v = Mat::from_fn(dim, 2 * m, |i, j| if j % 2 == 0 { pairs[j / 2].v[i].re } else { pairs[j / 2].v[i].im });
    let mut x = Mat::<f64>::zeros(dim, 4 * m);
    op.apply_to(x.as_mut().subcols_mut(0, 2 * m), v.as_ref());
    let av = x.as_ref().subcols(0, 2 * m).to_owned();
    op.apply_to(x.as_mut().subcols_mut(2 * m, 2 * m), av.as_ref());
    for j in 0..x.ncols() {
        let nrm = x.col(j).norm_l2();
        if nrm > 0.0 {
            let mut c = x.col_mut(j);
            c /= nrm;
        }
    }
    let svd = x.thin_svd().map_err(|e| JpError::Eigen { what: format!("Rayleigh-Ritz basis: {e:?}") })?;
    let sv = svd.S().column_vector();
    let r = (0..sv.nrows()).filter(|&i| sv[i] > 1e-10 * sv[0]).count();
    let q = svd.U().subcols(0, r).to_owned();
    let kq = problem.apply_shifted(q.as_ref(), 0.0);
    let mq = problem.apply_mass(q.as_ref());
    let kr = crate::linalg::product(q.transpose(), kq.as_ref());
    let mr = crate::linalg::product(q.transpose(), mq.as_ref());
    let mr = Mat::from_fn(r, r, |i, j| 0.5 * (mr[(i, j)] + mr[(j, i)]));
    let l = mr.llt(faer::Side::Lower).map_err(|_| JpError::Eigen { what: "Rayleigh-Ritz: projected mass not positive definite".into() })?.L().to_owned();
    let mut b = kr;
    l.as_ref().solve_lower_triangular_in_place(b.as_mut());
    let mut bt = b.transpose().to_owned();
    l.as_ref().solve_lower_triangular_in_place(bt.as_mut());
    let evd = bt.transpose().to_owned().eigen().map_err(|e| JpError::Eigen { what: format!("Rayleigh-Ritz: {e:?}") })?;
    let (mu, y) = (evd.S(), evd.U());
    let mut yre = Mat::from_fn(r, r, |i, k| y[(i, k)].re);
    let mut yim = Mat::from_fn(r, r, |i, k| y[(i, k)].im);
    l.transpose().solve_upper_triangular_in_place(yre.as_mut());
    l.transpose().solve_upper_triangular_in_place(yim.as_mut());
    let (xre, xim) = (crate::linalg::product(q.as_ref(), yre.as_ref()), crate::linalg::product(q.as_ref(), yim.as_ref()));
    let mut used = vec![false; r];
    for p in pairs.iter_mut() {
        let best = (0..r)
            .filter(|&k| !used[k])
            .min_by(|&a, &b| {
                let da = (mu[a].re - p.lambda.re).hypot(mu[a].im - p.lambda.im);
                let db = (mu[b].re - p.lambda.re).hypot(mu[b].im - p.lambda.im);
                da.total_cmp(&db)
            });
        if let Some(k) = best {
            used[k] = true;
            p.lambda = c64::new(mu[k].re, mu[k].im);
            p.v = normalised((0..dim).map(|i| c64::new(xre[(i, k)], xim[(i, k)])).collect());
        }
    }
    Ok(())
}

/// Adds the missing complex conjugates and time-shift partners `J v` of the found pairs.
fn complete(problem: &CondensedProblem<'_>, pairs: &mut Vec<Pair>) {
    let n = problem.coords.n_dof;
    let nj = 2 * problem.harmonics;
    let close = |a: c64, b: c64| {
        let d = ((a.re - b.re).powi(2) + (a.im - b.im).powi(2)).sqrt();
        d <= 1e-7 * (a.re * a.re + a.im * a.im).sqrt().max(f64::MIN_POSITIVE)
    };
    // Duplicates (the same eigenvector twice).
    let mut kept: Vec<Pair> = Vec::with_capacity(pairs.len());
    for p in pairs.drain(..) {
        let mut basis: Vec<Vec<c64>> = Vec::new();
        for q in kept.iter().filter(|q| close(q.lambda, p.lambda)) {
            let (rel, r) = out_of_span(&basis, &q.v);
            if rel > 1e-6 {
                basis.push(normalised(r));
            }
        }
        if out_of_span(&basis, &p.v).0 > 1e-4 {
            kept.push(p);
        }
    }
    *pairs = kept;
    // Conjugates.
    let mut added = Vec::new();
    for p in pairs.iter() {
        if p.lambda.im.abs() > 1e-10 * p.lambda.re.abs() {
            let conj = c64::new(p.lambda.re, -p.lambda.im);
            if !pairs.iter().chain(added.iter()).any(|q: &Pair| close(q.lambda, conj)) {
                added.push(Pair { lambda: conj, v: p.v.iter().map(|z| c64::new(z.re, -z.im)).collect() });
            }
        }
    }
    pairs.extend(added);
    // Time-shift partners.
    let partner = |p: &Pair| {
        let mut jv = vec![c64::new(0.0, 0.0); p.v.len()];
        for c in (0..nj).step_by(2) {
            for r in 0..n {
                jv[c * n + r] = c64::new(-p.v[(c + 1) * n + r].re, -p.v[(c + 1) * n + r].im);
                jv[(c + 1) * n + r] = p.v[c * n + r];
            }
        }
        Pair { lambda: p.lambda, v: jv }
    };
    // the residuals of the pairs found and of their partners, in one product
    let partners: Vec<Pair> = pairs.iter().map(partner).collect();
    let both: Vec<(c64, &[c64])> = pairs.iter().zip(&partners).flat_map(|(p, c)| [(p.lambda, p.v.as_slice()), (c.lambda, c.v.as_slice())]).collect();
    let found: Vec<f64> = residuals(problem, &both, false).into_iter().map(|r| r.0).collect();
    let mut i = 0;
    while i < pairs.len() {
        let p = &pairs[i];
        let (res_v, res_cand, cand) = if i < partners.len() {
            (found[2 * i], found[2 * i + 1], partners[i].clone())
        } else {
            let cand = partner(p);
            let r = residuals(problem, &[(p.lambda, p.v.as_slice()), (cand.lambda, cand.v.as_slice())], false);
            (r[0].0, r[1].0, cand)
        };
        // J commutes with (31) exactly when the partner is as good an eigenvector as `v`.
        if res_cand <= (2.0 * res_v).max(1e-9) {
            // Orthonormal basis of the found eigenvectors of this eigenvalue.
            let mut basis: Vec<Vec<c64>> = Vec::new();
            for q in pairs.iter().filter(|q| close(q.lambda, cand.lambda)) {
                let (rel, r) = out_of_span(&basis, &q.v);
                if rel > 1e-6 {
                    basis.push(normalised(r));
                }
            }
            let (rel, _) = out_of_span(&basis, &cand.v);
            if rel > 1e-4 {
                pairs.push(Pair { lambda: cand.lambda, v: normalised(cand.v) });
            }
        }
        i += 1;
    }
}

/// The kept eigenpairs of (31) by shift-invert Arnoldi around the band centre, with the
/// contract of the dense solve: eigenvalues `(Re, Im)` sorted by `Re λ` (band, then the
/// `extra_outside` nearest by `sqrt(Re λ)`), and the real and imaginary parts of their
/// eigenvectors (`2 H n x m`, coefficients `1..=2H`, each of unit length, real and imaginary
/// parts together). `g_ww` is the contact block `(K + K̂_00)^-1|_ww` of (28).
///
/// # Errors
/// [`JpError::SingularMatrix`] if `K_JC - σ M_JC` cannot be factorised; [`JpError::Eigen`] if
/// the band is not covered after [`MAX_DOUBLINGS`] doublings of the request, or a kept pair's
/// residual exceeds [`RESIDUAL_TOLERANCE`].
pub fn shift_invert_eigenpairs(coords: &ContactCoordinates, k_hat: &ContactJacobian, g_ww: &Mat<f64>, opts: &ModeOptions) -> Result<Eigenpairs> {
    shift_invert_eigenpairs_with(coords, k_hat, g_ww, opts, ShiftedFactorisation::Auto)
}

/// [`shift_invert_eigenpairs`] with a chosen factorisation.
///
/// # Errors
/// As [`shift_invert_eigenpairs`].
pub fn shift_invert_eigenpairs_with(
    coords: &ContactCoordinates,
    k_hat: &ContactJacobian,
    g_ww: &Mat<f64>,
    opts: &ModeOptions,
    how: ShiftedFactorisation,
) -> Result<Eigenpairs> {
    let problem = CondensedProblem::new(coords, k_hat, g_ww)?;
    problem_eigenpairs(&problem, opts, how)
}

/// [`shift_invert_eigenpairs`] of a structured problem, e.g. a pattern on a prediction's
/// reference ([`CondensedProblem::on_reference`]), whose shift is the reference's (the band
/// centre squared when the prediction made it), else the square of the band centre.
///
/// # Errors
/// As [`shift_invert_eigenpairs`].
pub fn problem_eigenpairs(problem: &CondensedProblem<'_>, opts: &ModeOptions, how: ShiftedFactorisation) -> Result<Eigenpairs> {
    let dim = problem.dim();
    problem_eigenpairs_upto(problem, opts, how, dim)?.ok_or_else(|| JpError::Eigen { what: "shift-invert Arnoldi of (31): the band is not covered".into() })
}

/// [`problem_eigenpairs`] with the Krylov space built the way `krylov` says.
///
/// # Errors
/// As [`shift_invert_eigenpairs`]; with [`Krylov::Block`], [`JpError::Eigen`] if the block
/// space reaches its cap before the requested pairs converge.
pub fn problem_eigenpairs_by(problem: &CondensedProblem<'_>, opts: &ModeOptions, how: ShiftedFactorisation, krylov: Krylov) -> Result<Eigenpairs> {
    let solve = ShiftedSolve::new(problem, problem_shift(problem, opts), how)?;
    solved_eigenpairs_upto(&solve, opts, problem.dim(), krylov)?.ok_or_else(|| JpError::Eigen { what: "shift-invert Arnoldi of (31): the band is not covered".into() })
}

/// [`shift_invert_eigenpairs`] that requests at most `max_request` eigenpairs: `None` when the
/// band and its extra pairs need more (a band holding many modes), where the caller solves
/// densely instead ([`crate::jp::EigenSolver::Auto`] on small problems).
///
/// # Errors
/// As [`shift_invert_eigenpairs`].
pub fn shift_invert_eigenpairs_upto(coords: &ContactCoordinates, k_hat: &ContactJacobian, g_ww: &Mat<f64>, opts: &ModeOptions, max_request: usize) -> Result<Option<Eigenpairs>> {
    let problem = CondensedProblem::new(coords, k_hat, g_ww)?;
    problem_eigenpairs_upto(&problem, opts, ShiftedFactorisation::Auto, max_request)
}

fn problem_eigenpairs_upto(problem: &CondensedProblem<'_>, opts: &ModeOptions, how: ShiftedFactorisation, max_request: usize) -> Result<Option<Eigenpairs>> {
    let solve = ShiftedSolve::new(problem, problem_shift(problem, opts), how)?;
    solved_eigenpairs_upto(&solve, opts, max_request, Krylov::Auto)
}

/// The shift of the eigen solve of `problem`: its reference's, else the square of the band
/// centre.
pub(crate) fn problem_shift(problem: &CondensedProblem<'_>, opts: &ModeOptions) -> f64 {
    let centre = 0.5 * (opts.band.0 + opts.band.1);
    problem.reference.map_or(centre * centre, |r| r.shift())
}

/// [`problem_eigenpairs`] on a factorisation made at [`problem_shift`].
///
/// # Errors
/// As [`shift_invert_eigenpairs`].
pub(crate) fn solved_eigenpairs(solve: &ShiftedSolve<'_, '_>, opts: &ModeOptions) -> Result<Eigenpairs> {
    solved_eigenpairs_upto(solve, opts, solve.problem.dim(), Krylov::Auto)?.ok_or_else(|| JpError::Eigen { what: "shift-invert Arnoldi of (31): the band is not covered".into() })
}

fn solved_eigenpairs_upto(solve: &ShiftedSolve<'_, '_>, opts: &ModeOptions, max_request: usize, krylov: Krylov) -> Result<Option<Eigenpairs>> {
    let problem = solve.problem;
    let (lo, hi) = opts.band;
    let dim = problem.dim();
    let sigma = solve.shift;

    let blocks = match krylov {
        Krylov::Single => false,
        Krylov::Block => true,
        Krylov::Auto => dim >= BLOCK_KRYLOV_MIN_DIM,
    };
    // Krylov-Schur's tolerance is absolute: it runs on the operator scaled to about unit norm
    // (a power iteration, 20 solves); the block Arnoldi's is relative to its largest Ritz value,
    // and it runs on `A` itself (the estimate is made only if it hands over).
    let norm_estimate = || -> Result<f64> {
        let op0 = Operator { solve: &solve, scale: 1.0 };
        let est = crate::linalg::eigen::operator_norm_estimate(dim, 20, |w, v| op0.apply_to(w, v));
        if !(est.is_finite() && est > 0.0) {
            return Err(JpError::Eigen { what: format!("shift-invert operator of (31): norm estimate {est}") });
        }
        Ok(est)
    };
    let mut estimate = if blocks { None } else { Some(norm_estimate()?) };
    let freq = |l: c64| l.re.max(0.0).sqrt();
    let in_band = |f: f64| f >= lo && f <= hi;

    let mut k = INITIAL_REQUEST.min(dim);
    let mut attempt = 0;
    let (pairs, keep) = loop {
        // (θ, v) of the operator scaled by 1 / est: by blocks on a large problem (est = 1),
        // else (or if the blocks' space reaches its cap first) faer's Krylov-Schur
        let by_blocks = if blocks {
            let unscaled = Operator { solve: &solve, scale: 1.0 };
            let cap = (8 * k).max(BLOCK_KRYLOV_MAX_DIM);
            let found = crate::linalg::block_arnoldi::largest_eigenpairs(dim, k, &BlockArnoldiOptions { block: KRYLOV_BLOCK, max_dim: cap, tolerance: ARNOLDI_TOLERANCE }, |w, v| unscaled.apply_to(w, v));
            if found.is_none() && krylov == Krylov::Block {
                return Err(JpError::Eigen { what: format!("block Arnoldi of (31): {k} eigenpairs not converged within a space of {cap}") });
            }
            found
        } else {
            None
        };
        let est = match (&by_blocks, estimate) {
            (Some(_), _) => 1.0,
            (None, Some(e)) => e,
            (None, None) => {
                let e = norm_estimate()?;
                estimate = Some(e);
                e
            }
        };
        let op = Operator { solve: &solve, scale: 1.0 / est };
        let (vals, vecs): (Vec<c64>, Mat<c64>) = match by_blocks {
            Some(found) => (found.iter().map(|f| f.0).collect(), Mat::from_fn(dim, found.len(), |i, j| found[j].1[i])),
            None => {
                let params = faer::matrix_free::eigen::PartialEigenParams { max_dim: (2 * k).max(64).min(dim), ..Default::default() };
                let req = faer::matrix_free::eigen::partial_eigen_scratch::<f64>(&op, k, par(), params);
                let mut mem = MemBuffer::new(req);
                let mut vecs = Mat::<c64>::zeros(dim, k);
                let mut vals = vec![c64::new(0.0, 0.0); k];
                let v0 = faer::Col::<f64>::from_fn(dim, |i| 1.0 + ((i * 104729) % 17) as f64 / 17.0);
                let info = faer::matrix_free::eigen::partial_eigen(
                    vecs.as_mut(),
                    &mut vals,
                    &op,
                    v0.as_ref(),
                    ARNOLDI_TOLERANCE,
                    par(),
                    MemStack::new(&mut mem),
                    params,
                );
                let nconv = info.n_converged_eigen.min(k);
                vals.truncate(nconv);
                (vals, vecs.as_ref().subcols(0, nconv).to_owned())
            }
        };
        let nconv = vals.len();
        let mut pairs: Vec<Pair> = Vec::with_capacity(nconv);
        // Distance to σ of the farthest converged eigenvalue: all nearer ones are found.
        let mut radius = 0.0f64;
        for j in 0..nconv {
            let th = c64::new(vals[j].re * est, vals[j].im * est);
            let m2 = th.re * th.re + th.im * th.im;
            if !(m2.is_finite() && m2 > 0.0) {
                continue;
            }
            radius = radius.max(1.0 / m2.sqrt());
            // λ = σ + 1/θ
            let lambda = c64::new(sigma + th.re / m2, -th.im / m2);
            pairs.push(Pair { lambda, v: normalised((0..dim).map(|i| vecs[(i, j)]).collect()) });
        }
        refine(problem, &op, &mut pairs)?;
        complete(problem, &mut pairs);
        let all_found = nconv >= dim;

        // Selection as in the dense path.
        let mut keep: Vec<usize> = (0..pairs.len()).filter(|&j| in_band(freq(pairs[j].lambda))).collect();
        let mut outside: Vec<(f64, usize)> = (0..pairs.len())
            .filter(|&j| !in_band(freq(pairs[j].lambda)))
            .map(|j| ((lo - freq(pairs[j].lambda)).max(freq(pairs[j].lambda) - hi), j))
            .collect();
        outside.sort_by(|x, y| x.0.total_cmp(&y.0));
        let extra: Vec<(f64, usize)> = outside.iter().take(opts.extra_outside).copied().collect();
        let enough_extra = extra.len() == opts.extra_outside;
        let d = extra.last().map_or(0.0, |e| e.0);
        keep.extend(extra.iter().map(|&(_, j)| j));
        // λ-range that must be inside the disc |λ - σ| < radius.
        let (a, b) = (if lo > d { (lo - d) * (lo - d) } else { 0.0 }, (hi + d) * (hi + d));
        let covered = (a - sigma).abs().max((b - sigma).abs()) < radius && enough_extra;
        if covered || all_found {
            break (pairs, keep);
        }
        if 2 * k > max_request && max_request < dim {
            return Ok(None);
        }
        if attempt >= MAX_DOUBLINGS || k >= dim {
            return Err(JpError::Eigen {
                what: format!(
                    "shift-invert Arnoldi of (31): {nconv} of {k} eigenpairs converged, nearest-to-shift disc radius {radius:.4e} does not cover the band's lambda range [{a:.4e}, {b:.4e}] around sigma = {sigma:.4e}"
                ),
            });
        }
        attempt += 1;
        k = (2 * k).min(dim);
    };

    let mut keep = keep;
    keep.sort_by(|&x, &y| pairs[x].lambda.re.total_cmp(&pairs[y].lambda.re));
    let m = keep.len();
    let mut v_re = Mat::<f64>::zeros(dim, m);
    let mut v_im = Mat::<f64>::zeros(dim, m);
    let mut eigenvalues = Vec::with_capacity(m);
    let kept: Vec<(c64, &[c64])> = keep.iter().map(|&j| (pairs[j].lambda, pairs[j].v.as_slice())).collect();
    let res_kept = residuals(problem, &kept, true);
    for (col, &j) in keep.iter().enumerate() {
        let p = &pairs[j];
        let (raw, res) = res_kept[col];
        if res.is_nan() || res >= RESIDUAL_TOLERANCE {
            return Err(JpError::Eigen {
                what: format!("shift-invert eigenpair lambda = {:.6e}{:+.3e}i of (31): relative residual {raw:.2e} ({res:.2e} with the rounding floor)", p.lambda.re, p.lambda.im),
            });
        }
        for i in 0..dim {
            v_re[(i, col)] = p.v[i].re;
            v_im[(i, col)] = p.v[i].im;
        }
        eigenvalues.push((p.lambda.re, p.lambda.im));
    }
    Ok(Some((eigenvalues, v_re, v_im)))
}
