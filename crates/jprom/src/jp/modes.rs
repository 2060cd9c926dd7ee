//! JP modes of one set of boundary conditions (docs/formulation.md §8, paper (27)-(35)).
//!
//! Given the contact stiffness `K̂` (a [`ContactJacobian`]):
//! 1. static condensation (28) with `A_0 = K + K̂_00`;
//! 2. condensed stiffness (30) on the coefficients of harmonics `1..H`,
//!    `K_JC(i,j) = δ_ij K + K̂_ij - K̂_i0 A_0^-1 K̂_0j`; `M_JC = blockdiag(h^2 M)`;
//! 3. the non-symmetric eigenproblem (31) `K_JC v = λ M_JC v`, made standard with the Cholesky
//!    factor of `M` (`M_JC` is SPD): `L_J^-1 K_JC L_J^-T u = λ u`, `v = L_J^-T u`; dense.
//!    A mode is in the band when `sqrt(Re λ)` (the fundamental angular frequency at which one
//!    of its harmonics resonates) lies in `[omega_lo, omega_hi]`;
//! 4. per-harmonic columns (33): the cos and sin parts of harmonic `h` of the real and imaginary
//!    parts of every kept eigenvector, each normalised to unit length (a decision of jprom: the
//!    SVD conditioning (38) then judges directions, not the arbitrary scale of each
//!    eigenvector); a complex eigenvector in its canonical phase, a multiple eigenvalue's
//!    eigenspace in its canonical basis, so that the columns do not depend on what the eigen
//!    solver returned (docs/formulation.md §8.4);
//! 5. static columns (35): `A_0^-1 K̂_{0c} φ` for every column `φ` of `Φ_h` and both
//!    coefficients `c` (cos and sin) of harmonic `h` (loads at round-off left out,
//!    [`COUPLING_FLOOR`]), plus `A_0^-1 f_E^0` and `A_0^-1 [g; 0]` with `g` the
//!    non-homogeneous part of the static contact force ([`ContactJacobian::static_offset`]).
//!    With these, the linearised static condensation (28) of any combination of the dynamic
//!    columns is exactly in the span of `Φ_0`.
//!
//! Two eigen solvers ([`EigenSolver`]): the dense path costs `O((2 H n)^3)` and suits
//! Craig-Bampton-sized models (`2 H n` up to a few hundred); the shift-invert path
//! ([`super::shift_invert`]) finds the few eigenpairs around the band by Arnoldi over one
//! factorisation of `K - σ h^2 M` per harmonic and a correction on the contact coordinates,
//! and never forms the dense `K_JC` unless the static correction asks for it.
//! [`jp_modes_on_reference`] gives the same modes from a prediction's shared factorisations
//! ([`super::reference`]) with dense work on a pattern's active contacts only.

use super::condensed::condensed_stiffness;
use super::reference::{active_pattern_working_set_bytes, active_statics, ActivePart, ReferenceFactors};
use super::shift_invert::{problem_shift, solved_eigenpairs, CondensedProblem, Eigenpairs, ShiftedFactorisation, ShiftedSolve};
pub use super::mode_selection::{EigenSolver, ModeOptions, AUTO_DENSE_MAX, AUTO_SHIFT_INVERT_MIN, AUTO_SHIFT_INVERT_REQUEST};
use super::{col_norm, lu_solve, stack_columns, ContactJacobian};
use crate::error::{JpError, Result};
use crate::model::ContactCoordinates;
use faer::{Mat, Side};

/// Parts of eigenvectors shorter than this (eigenvectors have unit length) are treated as
/// round-off and dropped, e.g. the harmonic-2 part of a fully stuck harmonic-1 mode.
pub const PART_FLOOR: f64 = 1e-9;

/// A conjugate pair whose imaginary part is below this fraction of `|λ|` is a double real
/// eigenvalue in round-off (a dense solver may return a stuck pair so).
pub const DEGENERATE_IMAG: f64 = 1e-8;

/// Eigenvalues within this relative distance of each other (conjugates folded together) make
/// one eigenspace, whose span, not its vectors, gives the columns (33) (`canonical_basis`).
pub const CLUSTER_TOLERANCE: f64 = 1e-3;

/// Directions of an eigenspace's vectors (real and imaginary parts, unit length) with a singular
/// value below this fraction of the largest are dropped as round-off of the eigen solve.
pub const SPAN_TOLERANCE: f64 = 1e-6;

/// A static coupling load (`K̂_0c φ` of a unit column `φ`, or `K̂_c0 A_0^-1 (f_E^0 + g)`) smaller
/// than this fraction of the largest entry of `K̂` (times the static displacement) is treated as
/// round-off: its response's direction would be noise (the AFT's round-off of a time-invariant
/// contact stiffness couples the static term and the harmonics at about 1e-16).
pub const COUPLING_FLOOR: f64 = 1e-7;

/// The JP modes of one set of boundary conditions, before conditioning.
#[derive(Clone, Debug)]
pub struct JpModes {
    /// Kept eigenvalues `λ` of (31) as `(Re, Im)`, sorted by `Re λ`.
    pub eigenvalues: Vec<(f64, f64)>,
    /// Raw basis columns per harmonic `h = 0..=H` (unit columns, not orthogonal).
    pub phi: Vec<Mat<f64>>,
}

impl JpModes {
    /// `sqrt(max(Re λ, 0))` of each kept eigenvalue (angular frequency).
    pub fn frequencies(&self) -> Vec<f64> {
        self.eigenvalues.iter().map(|&(re, _)| re.max(0.0).sqrt()).collect()
    }
}

/// Estimated bytes of the dense matrices of one pattern's JP-mode solve: `K̂`
/// (`((2H + 1) n_w)^2`), the shifted condensed matrix and its LU (`2 (2 H n)^2`), and the
/// `n`-square static condensation blocks. Saturating, like the other stages' estimates.
pub fn pattern_working_set_bytes(n: usize, nw: usize, harmonics: usize) -> u128 {
    use crate::memory::{bytes_of, product};
    let k_hat = product(&[2 * harmonics + 1, nw]);
    let shifted = product(&[2 * harmonics, n]);
    bytes_of::<f64>(k_hat.saturating_mul(k_hat).saturating_add(shifted.saturating_mul(shifted).saturating_mul(2)).saturating_add(product(&[3, n, n])))
}

/// Computes the JP modes (31)-(35) of the boundary conditions `k_hat` on the model `coords`.
///
/// # Errors
/// [`JpError::BadSize`] if `k_hat` does not match the model; [`JpError::InvalidValue`] for a bad
/// band; [`JpError::SingularMatrix`] if `K + K̂_00` is singular (a free structure with no
/// contact holding it statically) or `M` not positive definite; [`JpError::Eigen`] if the
/// eigen solver fails.
pub fn jp_modes(coords: &ContactCoordinates, k_hat: &ContactJacobian, opts: &ModeOptions) -> Result<JpModes> {
    let (n, nw, hh) = check_inputs(coords, k_hat, opts)?;
    crate::memory::check(
        &format!("the JP modes of one contact pattern at H = {hh} (n = {n} DoFs, n_w = {nw})"),
        pattern_working_set_bytes(n, nw, hh),
    )?;

    // (28): A_0 = K + K̂_00 and the responses A_0^-1 [I_w; 0], A_0^-1 f_E^0, A_0^-1 [g; 0].
    let mut a0 = coords.stiffness.clone();
    for j in 0..nw {
        for i in 0..nw {
            a0[(i, j)] += k_hat.k_hat[(i, j)];
        }
    }
    let mut rhs = Mat::<f64>::zeros(n, nw + 2);
    for i in 0..nw {
        rhs[(i, i)] = 1.0;
        rhs[(i, nw + 1)] = k_hat.static_offset[i];
    }
    for i in 0..n {
        rhs[(i, nw)] = coords.static_force[i];
    }
    let sol = lu_solve("K + K̂_00 (static condensation (28))", &a0, &rhs)?;
    drop(a0);
    let g_ww = sol.as_ref().submatrix(0, 0, nw, nw).to_owned();
    let rows: Vec<usize> = (0..nw).collect();
    let statics = Statics {
        a0_inv_e: sol.as_ref().submatrix(0, 0, n, nw),
        rows: &rows,
        x_force: sol.col(nw).iter().copied().collect(),
        x_offset: sol.col(nw + 1).iter().copied().collect(),
    };
    let coupling = |k: usize, l: usize, x: faer::MatRef<'_, f64>| k_hat.block(k, l) * x;

    // (30): the dense K_JC is needed by the dense eigen solve and by the static correction;
    // the shift-invert path works from K̂ and A_0^-1|_ww alone.
    let solver = opts.solver.resolve(2 * hh * n);
    // Auto on a problem small enough for the dense solve: a bounded shift-invert attempt first
    // (AUTO_SHIFT_INVERT_REQUEST), which needs K_JC only if it fails
    let attempt = solver != EigenSolver::ShiftInvert && opts.solver == EigenSolver::Auto && 2 * hh * n >= AUTO_SHIFT_INVERT_MIN;
    let mut kjc = if (solver != EigenSolver::ShiftInvert && !attempt) || opts.static_correction { Some(condensed_stiffness(coords, k_hat, &g_ww)) } else { None };

    // A singular K_JC (a structure free in some direction once its contacts slip) has no
    // static correction; the eigenvectors alone then make the basis.
    let corrections = match (&kjc, opts.static_correction) {
        (Some(kjc), true) => {
            let rhs = static_correction_rhs(coords, hh, &statics, &coupling, k_hat.k_hat.norm_max());
            static_corrections(rhs, |b| lu_solve("K_JC (static correction of the JP modes)", kjc, b)).unwrap_or_default()
        }
        _ => Vec::new(),
    };

    let eig = if solver == EigenSolver::ShiftInvert {
        super::shift_invert::shift_invert_eigenpairs(coords, k_hat, &g_ww, opts)?
    } else {
        // the dense solve where the attempt finds fewer modes than the band holds, or fails
        let tried = if attempt { super::shift_invert::shift_invert_eigenpairs_upto(coords, k_hat, &g_ww, opts, AUTO_SHIFT_INVERT_REQUEST).ok().flatten() } else { None };
        match tried {
            Some(eig) => eig,
            None => {
                let k = kjc.take().unwrap_or_else(|| condensed_stiffness(coords, k_hat, &g_ww));
                if 2 * hh * n <= POLISH_MAX_DIM {
                    kjc = Some(k.clone());
                }
                dense_eigenpairs(coords, k, hh, opts)?
            }
        }
    };
    let eig = if 2 * hh * n <= POLISH_MAX_DIM { polished(&kjc.unwrap_or_else(|| condensed_stiffness(coords, k_hat, &g_ww)), &coords.mass, eig) } else { eig };
    Ok(assemble(coords, hh, eig, &corrections, &statics, &coupling, k_hat.k_hat.norm_max()))
}

/// [`jp_modes`] of the pattern `k_hat` on a prediction's reference (docs/formulation.md §8.10,
/// [`super::reference`]): the same modes up to round-off (the eigen solve is shift-invert
/// Arnoldi at the reference's shift), with dense work only on the coordinates of the contacts
/// whose stiffness differs from the reference's.
///
/// # Errors
/// As [`jp_modes`]; [`JpError::BadSize`] if `reference` is not of this model and `H`.
pub fn jp_modes_on_reference(coords: &ContactCoordinates, k_hat: &ContactJacobian, opts: &ModeOptions, reference: &ReferenceFactors) -> Result<JpModes> {
    let (_, _, hh) = check_inputs(coords, k_hat, opts)?;
    if reference.harmonics() != hh {
        return Err(JpError::bad_size("harmonics of the prediction's reference", hh, reference.harmonics()));
    }
    let part = reference.active_part(coords, k_hat)?;
    modes_of_active_part(coords, &part, opts, reference)
}

/// [`jp_modes_on_reference`] of a pattern given by its active part.
pub(crate) fn modes_of_active_part(coords: &ContactCoordinates, part: &ActivePart, opts: &ModeOptions, reference: &ReferenceFactors) -> Result<JpModes> {
    let (n, hh) = (coords.n_dof, reference.harmonics());
    crate::memory::check(
        &format!("the JP modes of one contact pattern at H = {hh} on the prediction's reference (n = {n} DoFs, {} active contact coordinates)", part.len()),
        active_pattern_working_set_bytes(n, coords.n_w, part.len(), part.lead.len(), hh),
    )?;
    let st = active_statics(coords, reference, part)?;
    let statics = Statics { a0_inv_e: st.a0_inv_e.as_ref(), rows: &part.rows, x_force: st.x_force.clone(), x_offset: st.x_offset.clone() };
    let coupling = |k: usize, l: usize, x: faer::MatRef<'_, f64>| part.block_times(k, l, x);
    let problem = CondensedProblem::on_reference(coords, reference, part, &st.g_aa);
    // One factorisation at the band's shift serves the eigen solve and, by GMRES, the static
    // corrections at shift 0; a second one at 0 only if GMRES does not reach the direct
    // solve's accuracy (docs/formulation.md §8.10).
    let solve = ShiftedSolve::new(&problem, problem_shift(&problem, opts), ShiftedFactorisation::Woodbury)?;
    let corrections = if opts.static_correction {
        let rhs = static_correction_rhs(coords, hh, &statics, &coupling, part.k_hat_max);
        static_corrections(rhs, |b| match solve.solve_unshifted(b.as_ref()) {
            Some(x) => Ok(x),
            None => ShiftedSolve::new(&problem, 0.0, ShiftedFactorisation::Woodbury).map(|s0| s0.solve(b.as_ref())),
        })
        .unwrap_or_default()
    } else {
        Vec::new()
    };
    let eig = solved_eigenpairs(&solve, opts)?;
    let eig = if 2 * hh * n <= POLISH_MAX_DIM { polished(&problem.dense_shifted(0.0), &coords.mass, eig) } else { eig };
    Ok(assemble(coords, hh, eig, &corrections, &statics, &coupling, part.k_hat_max))
}

/// Sizes `(n, n_w, H)` after checking `k_hat` and the band.
fn check_inputs(coords: &ContactCoordinates, k_hat: &ContactJacobian, opts: &ModeOptions) -> Result<(usize, usize, usize)> {
    let n = coords.stiffness.nrows();
    let nw = coords.n_w;
    super::require_contacts("JP modes", nw)?;
    let hh = k_hat.harmonics;
    if hh == 0 {
        return Err(JpError::invalid("harmonics", "JP modes need H >= 1"));
    }
    if k_hat.n_w != nw || k_hat.k_hat.nrows() != (2 * hh + 1) * nw {
        return Err(JpError::bad_size("contact Jacobian (rows)", (2 * hh + 1) * nw, k_hat.k_hat.nrows()));
    }
    let (lo, hi) = opts.band;
    if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi >= lo) {
        return Err(JpError::invalid("band", format!("need 0 <= omega_lo <= omega_hi, got ({lo}, {hi})")));
    }
    Ok((n, nw, hh))
}

/// The static condensation (28) as the columns need it: `A_0^-1 E_r^T` on the contact
/// coordinates `rows` that `K̂_0c` (c >= 1) can reach (all of `w`, or a pattern's active ones),
/// `A_0^-1 f_E^0` and `A_0^-1 [g; 0]`.
struct Statics<'m> {
    a0_inv_e: faer::MatRef<'m, f64>,
    rows: &'m [usize],
    x_force: Vec<f64>,
    x_offset: Vec<f64>,
}

/// The per-harmonic columns (33), from the eigenvectors and the static corrections, and the
/// static columns (35). `coupling(k, l, x)` is `K̂_kl x` on `statics.rows` (`x` with `r` rows)
/// for `k` or `l` = 0.
fn assemble(
    coords: &ContactCoordinates,
    hh: usize,
    (eigenvalues, v_re, v_im): (Vec<(f64, f64)>, Mat<f64>, Mat<f64>),
    corrections: &[Vec<f64>],
    statics: &Statics<'_>,
    coupling: &dyn Fn(usize, usize, faer::MatRef<'_, f64>) -> Mat<f64>,
    k_hat_max: f64,
) -> JpModes {
    let n = coords.n_dof;
    let r = statics.rows.len();

    // Real vectors whose parts make the columns: the real and imaginary parts of each simple
    // eigenvector in its canonical phase (`canonical_phase`); for a multiple or nearly multiple
    // eigenvalue (a cluster, `eigen_clusters`) the canonical basis of its eigenspace
    // (`canonical_basis`); then the static corrections. So the columns do not depend on the
    // phases, nor on the basis of a multiple eigenvalue, that an eigen solver returned.
    let dim = v_re.nrows();
    let mut vectors: Vec<Vec<f64>> = Vec::new();
    for cl in eigen_clusters(&eigenvalues) {
        let parts_of = |col: usize| [v_re.col(col).iter().copied().collect::<Vec<f64>>(), v_im.col(col).iter().copied().collect()];
        let simple = match cl.as_slice() {
            [_] => true,
            &[a, b] => {
                let ((ra, ia), (rb, ib)) = (eigenvalues[a], eigenvalues[b]);
                let scale = ra.hypot(ia);
                ia.abs() > DEGENERATE_IMAG * scale && (ra - rb).abs() <= 1e-10 * scale && (ia + ib).abs() <= 1e-10 * scale
            }
            _ => false,
        };
        if simple {
            // a simple eigenvalue, or a conjugate pair: its vectors in the canonical phase
            for &col in &cl {
                let [mut a, mut b] = parts_of(col);
                canonical_phase(&mut a, &mut b);
                vectors.extend([a, b].into_iter().filter(|v| crate::linalg::norm2(v) > 0.0));
            }
        } else {
            let raw: Vec<Vec<f64>> = cl.iter().flat_map(|&col| parts_of(col)).filter(|v| crate::linalg::norm2(v) > 0.0).collect();
            vectors.extend(canonical_basis(dim, n, hh, &raw));
        }
    }
    vectors.extend(corrections.iter().cloned());

    // (33): per harmonic, the cos and sin parts of every vector, each of unit length (parts
    // below round-off dropped).
    let mut phi = Vec::with_capacity(hh + 1);
    phi.push(Mat::zeros(n, 0));
    for h in 1..=hh {
        let mut cols: Vec<Vec<f64>> = Vec::new();
        for v in &vectors {
            for c in [2 * h - 2, 2 * h - 1] {
                let part = &v[c * n..(c + 1) * n];
                let norm = crate::linalg::norm2(part);
                if norm > PART_FLOOR {
                    cols.push(part.iter().map(|x| x / norm).collect());
                }
            }
        }
        phi.push(stack_columns(n, &cols));
    }

    // (35): static columns `A_0^-1 [K̂_0c φ; 0]` for every column `φ` of `Φ_h` and both
    // coefficients `c` of `h`, unit length; a load `K̂_0c φ` at round-off of `K̂` is left out (in
    // full stick `K̂_0c = 0` for c >= 1; the AFT's round-off would give a noise direction).
    let coupling_floor = COUPLING_FLOOR * k_hat_max;
    let mut cols0: Vec<Vec<f64>> = Vec::new();
    if r > 0 {
        for h in 1..=hh {
            let phi_r = Mat::from_fn(r, phi[h].ncols(), |i, j| phi[h][(statics.rows[i], j)]);
            for c in [2 * h - 1, 2 * h] {
                let f = coupling(0, c, phi_r.as_ref());
                let kept: Vec<usize> = (0..f.ncols()).filter(|&j| f.col(j).norm_l2() > coupling_floor).collect();
                let f = Mat::from_fn(r, kept.len(), |i, j| f[(i, kept[j])]);
                let x = statics.a0_inv_e * &f;
                for j in 0..x.ncols() {
                    let norm = x.col(j).norm_l2();
                    if norm > 0.0 {
                        cols0.push(x.col(j).iter().map(|v| v / norm).collect());
                    }
                }
            }
        }
    }
    // the static load's and the preload's responses, unit length
    for x in [&statics.x_force, &statics.x_offset] {
        let norm = crate::linalg::norm2(x);
        if norm > 0.0 {
            cols0.push(x.iter().map(|v| v / norm).collect());
        }
    }
    phi[0] = stack_columns(n, &cols0);

    JpModes { eigenvalues, phi }
}

/// The eigenspaces of the kept eigenvalues: clusters (indices) of eigenvalues within
/// [`CLUSTER_TOLERANCE`] of each other, relatively, with `λ` and its conjugate together.
fn eigen_clusters(eigenvalues: &[(f64, f64)]) -> Vec<Vec<usize>> {
    let mut order: Vec<usize> = (0..eigenvalues.len()).collect();
    let key = |k: usize| (eigenvalues[k].0, eigenvalues[k].1.abs());
    order.sort_by(|&a, &b| key(a).0.total_cmp(&key(b).0).then(key(a).1.total_cmp(&key(b).1)));
    let mut clusters: Vec<Vec<usize>> = Vec::new();
    for k in order {
        let (re, im) = key(k);
        let near = |j: usize| {
            let (r2, i2) = key(j);
            (re - r2).hypot(im - i2) <= CLUSTER_TOLERANCE * re.hypot(im).max(r2.hypot(i2))
        };
        match clusters.iter_mut().find(|cl| cl.iter().any(|&j| near(j))) {
            Some(cl) => cl.push(k),
            None => clusters.push(vec![k]),
        }
    }
    clusters
}

/// Rotates a complex eigenvector `v = a + i b` by the phase that makes its real part the longest,
/// so that `a ⟂ b` and `|a| >= |b|` (eigen solvers return an arbitrary phase; the parts, each
/// scaled to unit length, would depend on it).
fn canonical_phase(a: &mut [f64], b: &mut [f64]) {
    let (aa, bb) = (crate::linalg::norm2(a).powi(2), crate::linalg::norm2(b).powi(2));
    if bb == 0.0 {
        return;
    }
    let ab: f64 = a.iter().zip(b.iter()).map(|(x, y)| x * y).sum();
    // |a cos t - b sin t|^2 is largest at tan 2t = -2 a.b / (|a|^2 - |b|^2)
    let t = 0.5 * (-2.0 * ab).atan2(aa - bb);
    let (c, s) = (t.cos(), t.sin());
    for (x, y) in a.iter_mut().zip(b.iter_mut()) {
        let (u, v) = (*x, *y);
        *x = u * c - v * s;
        *y = u * s + v * c;
    }
}

/// A canonical orthonormal basis of the real span of an eigenspace's vectors `raw` (real and
/// imaginary parts, length `2 H n`): an orthonormal basis `Q` of the span (directions below
/// [`SPAN_TOLERANCE`] of the largest dropped), rotated by the right singular vectors of its cos
/// parts (all harmonics), so that the first vector has the longest cos part and so on. It depends
/// on the span only (unless two singular values of the cos parts are equal), so a double
/// eigenvalue returned as a real pair `v, J v` by one solver and as a complex pair by another,
/// or a complex eigenvector in any phase, gives the same columns.
fn canonical_basis(dim: usize, n: usize, hh: usize, raw: &[Vec<f64>]) -> Vec<Vec<f64>> {
    if raw.is_empty() {
        return Vec::new();
    }
    let Ok(svd) = stack_columns(dim, raw).thin_svd() else {
        return Vec::new();
    };
    let s = svd.S().column_vector();
    let k = (0..s.nrows()).filter(|&j| s[j] > SPAN_TOLERANCE * s[0] && s[j] > 0.0).count();
    let q = svd.U().subcols(0, k).to_owned();
    // cos parts: coefficient blocks 2h - 2 (h = 1..=H)
    let cos = Mat::from_fn(hh * n, k, |i, j| q[((2 * (i / n)) * n + i % n, j)]);
    // (a model smaller than its eigenspace has fewer cos-part directions than vectors: the
    // thin SVD's V is then not square, and the basis is left as it is)
    let rotated = match cos.thin_svd() {
        Ok(c) if k > 1 && c.V().ncols() == k => &q * c.V(),
        _ => q,
    };
    (0..k).map(|j| rotated.col(j).iter().copied().collect()).collect()
}

/// The right-hand sides of the static corrections of [`ModeOptions::static_correction`], each
/// of length `2 H n` (coefficients `1..=2H`): `F_h` for every loaded harmonic `h`, and
/// `K̂_J0 A_0^-1 (f_E^0 + g)` when the static state couples into the harmonics.
fn static_correction_rhs(
    coords: &ContactCoordinates,
    hh: usize,
    statics: &Statics<'_>,
    coupling: &dyn Fn(usize, usize, faer::MatRef<'_, f64>) -> Mat<f64>,
    k_hat_max: f64,
) -> Vec<Vec<f64>> {
    let n = coords.n_dof;
    let dim = 2 * hh * n;
    let mut rhs: Vec<Vec<f64>> = Vec::new();
    for h in 1..=hh {
        if let Some((fc, fs)) = coords.harmonic_force.get(h - 1) {
            let mut f = vec![0.0; dim];
            f[(2 * h - 2) * n..(2 * h - 1) * n].copy_from_slice(fc);
            f[(2 * h - 1) * n..2 * h * n].copy_from_slice(fs);
            rhs.push(f);
        }
    }
    // Static coupling: K̂_J0 restricted to the rows of A_0^-1 (f_E^0 + g).
    let x0 = Mat::from_fn(statics.rows.len(), 1, |i, _| {
        let row = statics.rows[i];
        statics.x_force[row] + statics.x_offset[row]
    });
    let mut f = vec![0.0; dim];
    for c in 1..=2 * hh {
        let kx = coupling(c, 0, x0.as_ref());
        for (q, &i) in statics.rows.iter().enumerate() {
            f[(c - 1) * n + i] = kx[(q, 0)];
        }
    }
    let x0_norm = (0..coords.n_w).map(|i| (statics.x_force[i] + statics.x_offset[i]).powi(2)).sum::<f64>().sqrt();
    if crate::linalg::norm2(&f) > COUPLING_FLOOR * k_hat_max * x0_norm {
        rhs.push(f);
    }
    rhs.into_iter().filter(|f| crate::linalg::norm2(f) > 0.0).collect()
}

/// The static-correction vectors `K_JC^-1 rhs` (`solve` applies `K_JC^-1`), each scaled to
/// unit length, so that the same part floor as for eigenvectors applies.
fn static_corrections(rhs: Vec<Vec<f64>>, solve: impl Fn(&Mat<f64>) -> Result<Mat<f64>>) -> Result<Vec<Vec<f64>>> {
    let Some(dim) = rhs.first().map(Vec::len) else {
        return Ok(Vec::new());
    };
    let x = solve(&stack_columns(dim, &rhs))?;
    Ok((0..x.ncols())
        .map(|j| {
            let norm = col_norm(&x, j);
            (0..dim).map(|i| x[(i, j)] / norm).collect()
        })
        .filter(|v: &Vec<f64>| v.iter().all(|x| x.is_finite()))
        .collect())
}

/// The kept eigenpairs of (31) by a dense non-symmetric eigen solve of the whole condensed
/// problem (`O((2 H n)^3)`): eigenvalues `(Re, Im)` sorted by `Re λ`, and the real and imaginary
/// parts of their eigenvectors (`2 H n x m`, coefficients `1..=2H`, each of unit length).
fn dense_eigenpairs(coords: &ContactCoordinates, mut kjc: Mat<f64>, hh: usize, opts: &ModeOptions) -> Result<(Vec<(f64, f64)>, Mat<f64>, Mat<f64>)> {
    let n = coords.n_dof;
    let nj = 2 * hh;
    let dim = nj * n;
    let (lo, hi) = opts.band;
    // (31) made standard with M = L L^T, L_J = blockdiag(h L).
    let llt = coords.mass.llt(Side::Lower).map_err(|_| JpError::singular("mass matrix (not positive definite)"))?;
    let l = llt.L().to_owned();
    let h_of = |c: usize| (c / 2 + 1) as f64; // block c = coefficient c + 1
    // B = L_J^-1 K_JC
    for c in 0..nj {
        let mut stripe = kjc.as_mut().submatrix_mut(c * n, 0, n, nj * n);
        l.as_ref().solve_lower_triangular_in_place(stripe.as_mut());
        stripe *= faer::Scale(1.0 / h_of(c));
    }
    // A = (L_J^-1 B^T)^T
    let mut bt = kjc.transpose().to_owned();
    drop(kjc);
    for c in 0..nj {
        let mut stripe = bt.as_mut().submatrix_mut(c * n, 0, n, nj * n);
        l.as_ref().solve_lower_triangular_in_place(stripe.as_mut());
        stripe *= faer::Scale(1.0 / h_of(c));
    }
    let a = bt.transpose().to_owned();
    drop(bt);
    let evd = a.eigen().map_err(|e| JpError::Eigen { what: format!("eigen of the condensed JP problem (31): {e:?}") })?;
    let s = evd.S();
    let u = evd.U();

    // Selection in the band, then the nearest outside.
    let freq: Vec<f64> = (0..dim).map(|k| s[k].re.max(0.0).sqrt()).collect();
    let mut keep: Vec<usize> = (0..dim).filter(|&k| freq[k] >= lo && freq[k] <= hi).collect();
    let mut outside: Vec<(f64, usize)> = (0..dim)
        .filter(|&k| !(freq[k] >= lo && freq[k] <= hi))
        .map(|k| ((lo - freq[k]).max(freq[k] - hi), k))
        .collect();
    outside.sort_by(|x, y| x.0.total_cmp(&y.0));
    keep.extend(outside.iter().take(opts.extra_outside).map(|&(_, k)| k));
    keep.sort_by(|&x, &y| s[x].re.total_cmp(&s[y].re));

    // v = L_J^-T u for the kept eigenvectors (real and imaginary parts separately).
    let m = keep.len();
    let mut v_re = Mat::<f64>::zeros(dim, m);
    let mut v_im = Mat::<f64>::zeros(dim, m);
    for (col, &k) in keep.iter().enumerate() {
        for i in 0..dim {
            v_re[(i, col)] = u[(i, k)].re;
            v_im[(i, col)] = u[(i, k)].im;
        }
    }
    let lt = l.transpose();
    for c in 0..nj {
        for v in [&mut v_re, &mut v_im] {
            let mut stripe = v.as_mut().submatrix_mut(c * n, 0, n, m);
            lt.solve_upper_triangular_in_place(stripe.as_mut());
            stripe *= faer::Scale(1.0 / h_of(c));
        }
    }
    for col in 0..m {
        let norm = (col_norm(&v_re, col).powi(2) + col_norm(&v_im, col).powi(2)).sqrt();
        if norm > 0.0 {
            for i in 0..dim {
                v_re[(i, col)] /= norm;
                v_im[(i, col)] /= norm;
            }
        }
    }

    let eigenvalues = keep.iter().map(|&k| (s[k].re, s[k].im)).collect();
    Ok((eigenvalues, v_re, v_im))
}

/// Largest `2 H n` at which the eigenvectors of (31) are polished ([`polished`]): one LU of
/// that order per distinct kept eigenvalue, about what the eigen solve itself costs there (the
/// 18-contact blade is at 262 for H = 1 and 786 for H = 3; the refinement-5 blade, above it,
/// agrees between paths to 3.2e-9 unpolished).
pub const POLISH_MAX_DIM: usize = 1200;

/// The eigenvectors of (31) after one step of inverse iteration at their own eigenvalue,
///
/// ```text
/// v <- (K_JC - λ M_JC)^-1 M_JC v / | . |     (M_JC = blockdiag(h^2 M)),
/// ```
///
/// which leaves each at the accuracy its eigenvalue's separation allows (`eps / gap`) whichever
/// solver found it (dense QR, Krylov-Schur or block Arnoldi, to their own tolerances). The
/// columns (33) are parts of the eigenvectors scaled to unit length, and a part of 1e-4 of its
/// eigenvector magnifies the eigenvector's error 1e4 times: on the 18-contact blade the bases
/// of the three paths differed by up to 4.9e-7 (largest principal angle) before this step, and
/// by 2.4e-10 after it (`tests/jp_reference.rs`). One LU serves the eigenvalues equal to 1e-10
/// (a stuck pair `v`, `J v`) and their conjugates (`A(conj λ) = conj A(λ)`); it is real where
/// the eigenvalue is ([`DEGENERATE_IMAG`]). A vector whose step is not finite (an eigenvalue
/// exact to the last bit makes the matrix singular) is kept as it was.
fn polished(kjc: &Mat<f64>, mass: &Mat<f64>, (eigenvalues, mut v_re, mut v_im): Eigenpairs) -> Eigenpairs {
    use faer::c64;
    let n = mass.nrows();
    let dim = kjc.nrows();
    let m = eigenvalues.len();
    let h2 = |block: usize| ((block / 2 + 1) * (block / 2 + 1)) as f64;
    // M_JC x, block by block
    let m_times = |x: faer::MatRef<'_, f64>| {
        let mut out = Mat::<f64>::zeros(dim, x.ncols());
        for b in 0..dim / n {
            let y = mass * x.submatrix(b * n, 0, n, x.ncols());
            out.as_mut().submatrix_mut(b * n, 0, n, x.ncols()).copy_from(faer::Scale(h2(b)) * &y);
        }
        out
    };
    // K_JC - x M_JC
    let shifted = |x: f64| {
        let mut a = kjc.clone();
        for b in 0..dim / n {
            let mut blk = a.as_mut().submatrix_mut(b * n, b * n, n, n);
            blk -= faer::Scale(x * h2(b)) * mass;
        }
        a
    };
    let mut done = vec![false; m];
    for j in 0..m {
        if done[j] {
            continue;
        }
        let (re, im) = eigenvalues[j];
        let scale = re.hypot(im);
        let group: Vec<usize> = (j..m).filter(|&k| !done[k] && (eigenvalues[k].0 - re).abs() <= 1e-10 * scale && (eigenvalues[k].1.abs() - im.abs()).abs() <= 1e-10 * scale).collect();
        // the right-hand sides M_JC v (real and imaginary parts) of the group's vectors
        let parts = Mat::from_fn(dim, 2 * group.len(), |i, c| if c % 2 == 0 { v_re[(i, group[c / 2])] } else { v_im[(i, group[c / 2])] });
        let rhs = m_times(parts.as_ref());
        // (re, im) parts of each new vector
        let solved: Vec<(Vec<f64>, Vec<f64>)> = if im.abs() <= DEGENERATE_IMAG * scale {
            let w = crate::linalg::DenseLu::from_matrix(shifted(re)).solve(&rhs);
            (0..group.len()).map(|g| (w.col(2 * g).iter().copied().collect(), w.col(2 * g + 1).iter().copied().collect())).collect()
        } else {
            // K_JC - (re + i |im|) M_JC
            let real = shifted(re);
            let a = Mat::<c64>::from_fn(dim, dim, |i, k| {
                let mm = if i / n == k / n { h2(i / n) * mass[(i % n, k % n)] } else { 0.0 };
                c64::new(real[(i, k)], -im.abs() * mm)
            });
            // a conjugate eigenvalue's vector: A(λ) conj(w) = conj(M v)
            let sign = |k: usize| if eigenvalues[k].1 < 0.0 { -1.0 } else { 1.0 };
            let b = Mat::<c64>::from_fn(dim, group.len(), |i, g| c64::new(rhs[(i, 2 * g)], sign(group[g]) * rhs[(i, 2 * g + 1)]));
            let w = crate::linalg::DenseLu::from_matrix(a).solve(&b);
            (0..group.len()).map(|g| ((0..dim).map(|i| w[(i, g)].re).collect(), (0..dim).map(|i| sign(group[g]) * w[(i, g)].im).collect())).collect()
        };
        for (&k, (wr, wi)) in group.iter().zip(solved) {
            done[k] = true;
            let norm = (crate::linalg::norm2(&wr).powi(2) + crate::linalg::norm2(&wi).powi(2)).sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                continue;
            }
            for i in 0..dim {
                v_re[(i, k)] = wr[i] / norm;
                v_im[(i, k)] = wi[i] / norm;
            }
        }
    }
    (eigenvalues, v_re, v_im)
}
