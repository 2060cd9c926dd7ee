//! HBM residual and Jacobian of a [`HarmonicSystem`] (docs/formulation.md §2, paper (4)-(6)):
//!
//! ```text
//! r = D z - f + W^T F(W z),        J = D + W^T K̂ W,      K̂ = dF/dw (from the AFT, §3)
//! ```
//!
//! `D` is block-diagonal over harmonics, each harmonic `h >= 1` in the real cos/sin form of
//! [`super`]. `F` and `K̂` come from [`crate::aft::evaluate_contacts`]; `K̂` is block-diagonal
//! per contact (each contact couples only its own coordinates, across all harmonics).
//! With [`ContactMap::Leading`] the blocks are scattered straight into the rows/columns of
//! the leading `n_w` unknowns of each harmonic; with [`ContactMap::Dense`] the product
//! `W^T K̂ W` is formed contact by contact and added with one matrix product.

use super::{ContactMap, HarmonicLayout, HarmonicSystem, LinearPart};
use crate::aft::{evaluate_contacts, AftPlan, ContactCycle, ContactForces};
use crate::error::{JpError, Result};
use crate::linalg::sparse::{check_triplets, sparse_from_triplets_in};
use crate::linalg::{sparse_from_triplets, Matrix, SparseMat};
use faer::{Accum, Mat, MatRef, Par};

/// Scratch memory of [`evaluate`], reused across Newton iterations.
#[derive(Default)]
pub struct ResidualWorkspace {
    w_all: Vec<f64>,
    triplets: Vec<(usize, usize, f64)>,
    assembly: Option<SparseAssembly>,
    forces: ContactForces,
    contact_force_norm: f64,
}

/// The pattern of a sparse HBM Jacobian and the slot each generated entry (of `D`, then of the
/// contact blocks, always in the same order) is summed into: built at the first evaluation,
/// then every evaluation refills the values of a Jacobian with this pattern in place.
struct SparseAssembly {
    /// `(row, col)` of every generated entry, in generation order
    keys: Vec<(usize, usize)>,
    slot: Vec<usize>,
    template: SparseMat,
}

impl SparseAssembly {
    /// Whether the entries `t` are the ones this assembly was built for.
    fn fits(&self, n: usize, t: &[(usize, usize, f64)]) -> bool {
        self.template.nrows() == n && self.keys.len() == t.len() && self.keys.iter().zip(t).all(|(k, e)| k.0 == e.0 && k.1 == e.1)
    }

    fn new(n: usize, t: &[(usize, usize, f64)]) -> Result<Self> {
        // the pattern: entries sorted by column then row (stable: duplicates keep generation order)
        let mut order: Vec<usize> = (0..t.len()).collect();
        order.sort_by_key(|&k| (t[k].1, t[k].0));
        let mut sorted: Vec<(usize, usize, f64)> = order.iter().map(|&k| (t[k].0, t[k].1, 0.0)).collect();
        let template = sparse_from_triplets_in(n, n, &mut sorted)?;
        let (cp, ri) = (template.as_ref().symbolic().col_ptr().to_vec(), template.as_ref().symbolic().row_idx().to_vec());
        let mut slot = vec![0; t.len()];
        let mut pos = 0;
        for &k in &order {
            let (i, j) = (t[k].0, t[k].1);
            // sorted entries are visited in pattern order: the slot only moves forward
            while !(pos >= cp[j] && pos < cp[j + 1] && ri[pos] == i) {
                pos += 1;
            }
            slot[k] = pos;
        }
        Ok(SparseAssembly { keys: t.iter().map(|e| (e.0, e.1)).collect(), slot, template })
    }

    /// Sums the entries `t` into `jac` (given this assembly's pattern first if it has another).
    fn assemble(&self, t: &[(usize, usize, f64)], jac: &mut Option<Matrix>) {
        let same = match jac {
            Some(Matrix::Sparse(m)) => {
                let (a, b) = (m.as_ref().symbolic(), self.template.as_ref().symbolic());
                a.nrows() == b.nrows() && a.col_ptr() == b.col_ptr() && a.row_idx() == b.row_idx()
            }
            _ => false,
        };
        if !same {
            *jac = Some(Matrix::Sparse(self.template.clone()));
        }
        let Some(Matrix::Sparse(m)) = jac.as_mut() else { unreachable!("set above") };
        let v = m.val_mut();
        v.iter_mut().for_each(|x| *x = 0.0);
        for (e, &k) in t.iter().zip(&self.slot) {
            v[k] += e.2;
        }
    }
}

impl ResidualWorkspace {
    /// Empty workspace (buffers grow on first use).
    pub fn new() -> Self {
        Self::default()
    }
    /// `|W^T F(W z)|` (the contact force on the system's unknowns) at the last evaluation.
    pub fn contact_force_norm(&self) -> f64 {
        self.contact_force_norm
    }
}

/// Checks that the linear part matches the layout.
pub(crate) fn check_linear_part(layout: &HarmonicLayout, lin: &LinearPart) -> Result<()> {
    let h_max = layout.harmonics;
    let n0 = layout.size(0);
    if lin.d0.nrows() != n0 || lin.d0.ncols() != n0 || lin.f0.len() != n0 {
        return Err(JpError::bad_size("LinearPart.d0/f0", n0, lin.f0.len()));
    }
    for v in [lin.dh_re.len(), lin.dh_im.len(), lin.fh_cos.len(), lin.fh_sin.len()] {
        if v != h_max {
            return Err(JpError::bad_size("LinearPart harmonics", h_max, v));
        }
    }
    for h in 1..=h_max {
        let n = layout.size(h);
        let (re, im) = (&lin.dh_re[h - 1], &lin.dh_im[h - 1]);
        if re.nrows() != n || re.ncols() != n || im.nrows() != n || im.ncols() != n {
            return Err(JpError::bad_size(format!("LinearPart D_{h} (rows)"), n, re.nrows()));
        }
        if lin.fh_cos[h - 1].len() != n || lin.fh_sin[h - 1].len() != n {
            return Err(JpError::bad_size(format!("LinearPart f_{h}"), n, lin.fh_cos[h - 1].len()));
        }
    }
    Ok(())
}

/// `D z - f` (the linear residual), in the layout of `z`.
pub fn linear_residual(layout: &HarmonicLayout, lin: &LinearPart, z: &[f64]) -> Vec<f64> {
    let mut r = Vec::new();
    linear_residual_into(layout, lin, z, &mut r);
    r
}

/// `r = D z - f`, reusing `r`'s storage.
pub(crate) fn linear_residual_into(layout: &HarmonicLayout, lin: &LinearPart, z: &[f64], r: &mut Vec<f64>) {
    r.clear();
    r.resize(layout.total(), 0.0);
    let n0 = layout.size(0);
    lin.d0.mul_add(&z[..n0], 1.0, &mut r[..n0]);
    for (ri, f) in r[..n0].iter_mut().zip(&lin.f0) {
        *ri -= f;
    }
    for h in 1..=layout.harmonics {
        let n = layout.size(h);
        let (oc, os) = (layout.cos_offset(h), layout.sin_offset(h));
        let (re, im) = (&lin.dh_re[h - 1], &lin.dh_im[h - 1]);
        let (zc, zs) = (&z[oc..oc + n], &z[os..os + n]);
        // [Re D  Im D; -Im D  Re D] [zc; zs]
        let (rc, rs) = split_pair(r, oc, os, n);
        re.mul_add(zc, 1.0, rc);
        im.mul_add(zs, 1.0, rc);
        im.mul_add(zc, -1.0, rs);
        re.mul_add(zs, 1.0, rs);
        for i in 0..n {
            rc[i] -= lin.fh_cos[h - 1][i];
            rs[i] -= lin.fh_sin[h - 1][i];
        }
    }
}

/// The two disjoint ranges `[a, a + n)` and `[b, b + n)` of `r` (`a + n <= b`).
fn split_pair(r: &mut [f64], a: usize, b: usize, n: usize) -> (&mut [f64], &mut [f64]) {
    let (lo, hi) = r.split_at_mut(b);
    (&mut lo[a..a + n], &mut hi[..n])
}

/// Whether the linear part is stored sparse (then the Jacobian is built sparse).
fn is_sparse(lin: &LinearPart) -> bool {
    lin.d0.is_sparse() && lin.dh_re.iter().chain(&lin.dh_im).all(Matrix::is_sparse)
}

/// The `(row, col, value)` entries of the linear Jacobian `D` (every stored entry, zeros
/// included, so the pattern is the same at every frequency).
fn linear_triplets(layout: &HarmonicLayout, lin: &LinearPart, out: &mut Vec<(usize, usize, f64)>) {
    lin.d0.for_each_entry(|i, j, v| out.push((i, j, v)));
    for h in 1..=layout.harmonics {
        let (oc, os) = (layout.cos_offset(h), layout.sin_offset(h));
        lin.dh_re[h - 1].for_each_entry(|i, j, v| {
            out.push((oc + i, oc + j, v));
            out.push((os + i, os + j, v));
        });
        lin.dh_im[h - 1].for_each_entry(|i, j, v| {
            out.push((oc + i, os + j, v));
            out.push((os + i, oc + j, -v));
        });
    }
}

/// Estimated bytes of a dense Newton Jacobian on `unknowns` unknowns and its LU: what a
/// harmonic system's Newton iteration allocates (checked before its first step, so a
/// condensed system too large to solve at full order is refused there, not when built).
pub fn dense_jacobian_bytes(unknowns: usize) -> u128 {
    crate::memory::bytes_of::<f64>(crate::memory::product(&[2, unknowns, unknowns]))
}

/// The linear Jacobian `D` (block-diagonal over harmonics): sparse when the linear part is.
pub fn linear_jacobian(layout: &HarmonicLayout, lin: &LinearPart) -> Matrix {
    let nt = layout.total();
    if is_sparse(lin) {
        let mut t = Vec::new();
        linear_triplets(layout, lin, &mut t);
        return Matrix::Sparse(sparse_from_triplets(nt, nt, t).expect("linear part entries are in range and finite"));
    }
    let mut jac = Mat::<f64>::zeros(nt, nt);
    fill_linear_jacobian(layout, lin, &mut jac);
    Matrix::Dense(jac)
}

/// Writes the dense linear Jacobian `D` into `jac` (`N_tot` square; every entry written).
fn fill_linear_jacobian(layout: &HarmonicLayout, lin: &LinearPart, jac: &mut Mat<f64>) {
    jac.fill(0.0);
    lin.d0.for_each_entry(|i, j, v| jac[(i, j)] = v);
    for h in 1..=layout.harmonics {
        let (oc, os) = (layout.cos_offset(h), layout.sin_offset(h));
        lin.dh_re[h - 1].for_each_entry(|i, j, v| {
            jac[(oc + i, oc + j)] = v;
            jac[(os + i, os + j)] = v;
        });
        lin.dh_im[h - 1].for_each_entry(|i, j, v| {
            jac[(oc + i, os + j)] = v;
            jac[(os + i, oc + j)] = -v;
        });
    }
}

/// Contact coordinates' harmonics `w_all` (harmonic-major, `(2H + 1) n_w`) from `z`.
fn gather_contact_coords(system: &dyn HarmonicSystem, z: &[f64], w_all: &mut Vec<f64>) {
    let layout = system.layout();
    let n_w = system.n_contact_coords();
    let n_coeffs = 2 * layout.harmonics + 1;
    w_all.clear();
    w_all.resize(n_coeffs * n_w, 0.0);
    for k in 0..n_coeffs {
        let h = (k + 1) / 2;
        let (off, n) = layout.coeff_range(k);
        let dst = &mut w_all[k * n_w..(k + 1) * n_w];
        match system.contact_map(h) {
            ContactMap::Leading => dst.copy_from_slice(&z[off..off + n_w]),
            ContactMap::Dense(w) if w.row_stride() == 1 => {
                // W_k z_k as a sum of W_k's (contiguous) columns
                dst.fill(0.0);
                for j in 0..n {
                    let zj = z[off + j];
                    let col = w.col(j).try_as_col_major().expect("row stride 1").as_slice();
                    for (d, wv) in dst.iter_mut().zip(col) {
                        *d += wv * zj;
                    }
                }
            }
            ContactMap::Dense(w) => {
                for i in 0..n_w {
                    dst[i] = (0..n).map(|j| w[(i, j)] * z[off + j]).sum();
                }
            }
        }
    }
}

/// Adds `W^T F` (harmonic-major `F`) to `r`, and returns `|W^T F|`.
fn scatter_contact_force(system: &dyn HarmonicSystem, force: &[f64], r: &mut [f64]) -> f64 {
    let layout = system.layout();
    let n_w = system.n_contact_coords();
    let n_coeffs = 2 * layout.harmonics + 1;
    let mut norm2_sq = 0.0;
    for k in 0..n_coeffs {
        let h = (k + 1) / 2;
        let (off, n) = layout.coeff_range(k);
        let fk = &force[k * n_w..(k + 1) * n_w];
        match system.contact_map(h) {
            ContactMap::Leading => {
                for i in 0..n_w {
                    r[off + i] += fk[i];
                    norm2_sq += fk[i] * fk[i];
                }
            }
            ContactMap::Dense(w) => {
                for j in 0..n {
                    let v: f64 = (0..n_w).map(|i| w[(i, j)] * fk[i]).sum();
                    r[off + j] += v;
                    norm2_sq += v * v;
                }
            }
        }
    }
    norm2_sq.sqrt()
}

/// The entries of `W^T K̂ W` for a system whose contact coordinates lead every harmonic
/// ([`ContactMap::Leading`]): each contact's whole `d (2H+1)` square block, zeros included.
fn contact_jacobian_triplets(system: &dyn HarmonicSystem, forces: &ContactForces, out: &mut Vec<(usize, usize, f64)>) {
    let layout = system.layout();
    let n_coeffs = 2 * layout.harmonics + 1;
    let coeff_off = |k: usize| layout.coeff_range(k).0;
    for (c, law) in system.contact_laws().iter().enumerate() {
        let d = law.dim();
        let n = d * n_coeffs;
        let block = &forces.jac[forces.jac_offsets[c]..forces.jac_offsets[c] + n * n];
        let o = system.contact_offsets()[c];
        for col in 0..n {
            let gcol = coeff_off(col / d) + o + col % d;
            for row in 0..n {
                out.push((coeff_off(row / d) + o + row % d, gcol, block[row + col * n]));
            }
        }
    }
}

/// Adds `W^T K̂ W` to `jac` from the per-contact blocks of `forces`.
fn scatter_contact_jacobian(system: &dyn HarmonicSystem, forces: &ContactForces, jac: &mut Mat<f64>) {
    let layout = system.layout();
    let n_w = system.n_contact_coords();
    let n_coeffs = 2 * layout.harmonics + 1;
    let laws = system.contact_laws();
    let offsets = system.contact_offsets();
    let coeff_off = |k: usize| layout.coeff_range(k).0;
    let leading = (0..=layout.harmonics).all(|h| matches!(system.contact_map(h), ContactMap::Leading));
    if leading {
        for (c, law) in laws.iter().enumerate() {
            let d = law.dim();
            let n = d * n_coeffs;
            let block = &forces.jac[forces.jac_offsets[c]..forces.jac_offsets[c] + n * n];
            let o = offsets[c];
            for kc in 0..n_coeffs {
                for ic in 0..d {
                    let col = kc * d + ic;
                    let gcol = coeff_off(kc) + o + ic;
                    for kr in 0..n_coeffs {
                        for ir in 0..d {
                            let v = block[kr * d + ir + col * n];
                            if v != 0.0 {
                                jac[(coeff_off(kr) + o + ir, gcol)] += v;
                            }
                        }
                    }
                }
            }
        }
        return;
    }
    // Dense map: coefficient k's unknowns see the contacts through W_k (n_w x n_k), so
    // J_kl += W_k^T K̂_kl W_l, with K̂_kl the block-diagonal (per contact, d x d) coupling of
    // coefficients k and l. T = K̂_kl W_l is formed column by column (contiguous), then one
    // product W_k^T T per pair: 2 n_w N_tot^2 flops in all, where the whole (2H+1) n_w-row
    // map would multiply the zeros of the other coefficients too.
    // each coefficient's map with contiguous columns (a leading map written out as [I 0])
    let maps: Vec<Option<Mat<f64>>> = (0..n_coeffs)
        .map(|k| {
            let (_, n) = layout.coeff_range(k);
            match system.contact_map((k + 1) / 2) {
                ContactMap::Leading => Some(Mat::from_fn(n_w, n, |i, j| if i == j { 1.0 } else { 0.0 })),
                ContactMap::Dense(w) if w.row_stride() != 1 => Some(w.to_owned()),
                ContactMap::Dense(_) => None,
            }
        })
        .collect();
    let map = |k: usize| -> MatRef<'_, f64> {
        match (&maps[k], system.contact_map((k + 1) / 2)) {
            (Some(m), _) => m.as_ref(),
            (None, ContactMap::Dense(w)) => w,
            (None, ContactMap::Leading) => unreachable!("a leading map is written out above"),
        }
    };
    let mut t = Mat::<f64>::zeros(n_w, 0);
    for l in 0..n_coeffs {
        let (off_l, n_l) = layout.coeff_range(l);
        let w_l = map(l);
        for k in 0..n_coeffs {
            let (off_k, n_k) = layout.coeff_range(k);
            t.resize_with(n_w, n_l, |_, _| 0.0);
            for j in 0..n_l {
                let wcol = w_l.col(j).try_as_col_major().expect("contiguous columns (above)").as_slice();
                let tcol = t.col_as_slice_mut(j);
                for (c, law) in laws.iter().enumerate() {
                    let d = law.dim();
                    let n = d * n_coeffs;
                    let block = &forces.jac[forces.jac_offsets[c]..forces.jac_offsets[c] + n * n];
                    let o = offsets[c];
                    for ir in 0..d {
                        let mut s = 0.0;
                        for ic in 0..d {
                            s += block[(k * d + ir) + (l * d + ic) * n] * wcol[o + ic];
                        }
                        tcol[o + ir] = s;
                    }
                }
            }
            faer::linalg::matmul::matmul(jac.as_mut().submatrix_mut(off_k, off_l, n_k, n_l), Accum::Add, map(k).transpose(), t.as_ref(), 1.0, Par::Seq);
        }
    }
}

/// Residual `r = D z - f + W^T F(W z)` and, when asked, the Jacobian `J = D + W^T K̂ W`
/// (`N_tot x N_tot`, sparse when the system's linear part is, dense otherwise). `plan` may be `None` only for a system without contacts (the
/// AFT is never called then).
///
/// # Errors
/// [`JpError::BadSize`] if `z` or `lin` do not match the layout; [`JpError::InvalidValue`]
/// if the system has contacts and no plan is given, or if the plan's `H` differs.
pub fn evaluate(
    system: &dyn HarmonicSystem,
    lin: &LinearPart,
    plan: Option<&AftPlan>,
    z: &[f64],
    want_jacobian: bool,
    ws: &mut ResidualWorkspace,
) -> Result<(Vec<f64>, Option<Matrix>)> {
    let (mut r, mut jac) = (Vec::new(), None);
    evaluate_into(system, lin, plan, z, want_jacobian, ws, &mut r, &mut jac)?;
    Ok((r, if want_jacobian { jac } else { None }))
}

/// [`evaluate`] into `r` and, when `want_jacobian`, `jac`, reusing their storage: a Jacobian
/// of the same storage and size (for a sparse one, the same pattern) is refilled in place, so
/// that the Newton iterations of a solve do not allocate (`jac` is left as it was when no
/// Jacobian is asked for).
///
/// # Errors
/// As [`evaluate`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate_into(
    system: &dyn HarmonicSystem,
    lin: &LinearPart,
    plan: Option<&AftPlan>,
    z: &[f64],
    want_jacobian: bool,
    ws: &mut ResidualWorkspace,
    r: &mut Vec<f64>,
    jac: &mut Option<Matrix>,
) -> Result<()> {
    let layout = system.layout();
    if z.len() != layout.total() {
        return Err(JpError::bad_size("HBM unknowns z", layout.total(), z.len()));
    }
    check_linear_part(layout, lin)?;
    linear_residual_into(layout, lin, z, r);
    let leading = (0..=layout.harmonics).all(|h| matches!(system.contact_map(h), ContactMap::Leading));
    // a sparse system's Jacobian is assembled from the entries of D and of the contacts
    let sparse = want_jacobian && is_sparse(lin) && leading;
    let nt = layout.total();
    if want_jacobian && !sparse {
        if !matches!(jac, Some(Matrix::Dense(m)) if m.nrows() == nt && m.ncols() == nt) {
            crate::memory::check(
                &format!("the dense harmonic-balance Jacobian ({nt} unknowns at H = {})", layout.harmonics),
                dense_jacobian_bytes(nt),
            )?;
            *jac = Some(Matrix::Dense(Mat::zeros(nt, nt)));
        }
        let Some(Matrix::Dense(m)) = jac.as_mut() else { unreachable!("set above") };
        fill_linear_jacobian(layout, lin, m);
    }
    ws.contact_force_norm = 0.0;
    let contacts = !system.contact_laws().is_empty();
    if contacts {
        contact_forces_at(system, plan, z, want_jacobian, false, ws)?;
        ws.contact_force_norm = scatter_contact_force(system, &ws.forces.force, r);
    }
    if sparse {
        let mut t = std::mem::take(&mut ws.triplets);
        t.clear();
        linear_triplets(layout, lin, &mut t);
        if contacts {
            contact_jacobian_triplets(system, &ws.forces, &mut t);
        }
        let assembled = check_triplets(nt, nt, &t).and_then(|()| {
            if !ws.assembly.as_ref().is_some_and(|a| a.fits(nt, &t)) {
                ws.assembly = Some(SparseAssembly::new(nt, &t)?);
            }
            ws.assembly.as_ref().expect("set above").assemble(&t, jac);
            Ok(())
        });
        ws.triplets = t;
        return assembled;
    }
    if contacts && want_jacobian {
        let Some(Matrix::Dense(m)) = jac.as_mut() else { unreachable!("dense Jacobian set above") };
        scatter_contact_jacobian(system, &ws.forces, m);
    }
    Ok(())
}

/// The residual at `z = 0` and the Jacobian of the linear limit there: `D + W^T K_c W`, every
/// contact closed at zero displacement as its stuck spring
/// ([`crate::contact::ContactLaw::closed_stiffness_block`]
/// on every harmonic), the open ones as nothing. One Newton step from zero with it gives the
/// linear stuck response, the start a cold solve takes when zero does not converge (a
/// contact closed by a static force has no stiffness at zero, where it only just touches).
///
/// # Errors
/// As [`evaluate`].
/// `None` when that Jacobian is the one at zero already (every contact's stiffness there is its
/// linear limit's), so that the step from zero is the linear limit.
pub(crate) fn linear_limit_at_zero(system: &dyn HarmonicSystem, lin: &LinearPart, plan: Option<&AftPlan>, ws: &mut ResidualWorkspace) -> Result<Option<(Vec<f64>, Matrix)>> {
    let layout = system.layout();
    let z = vec![0.0; layout.total()];
    let (mut r, mut jac) = (Vec::new(), None);
    evaluate_into(system, lin, plan, &z, true, ws, &mut r, &mut jac)?;
    if system.contact_laws().is_empty() {
        return Ok(None);
    }
    let n_coeffs = 2 * layout.harmonics + 1;
    let mut changed = false;
    for (c, law) in system.contact_laws().iter().enumerate() {
        let d = law.dim();
        let n = d * n_coeffs;
        let k = law.closed_stiffness_block();
        let block = &mut ws.forces.jac[ws.forces.jac_offsets[c]..ws.forces.jac_offsets[c] + n * n];
        let mut closed = vec![0.0; n * n];
        for coeff in 0..n_coeffs {
            for row in 0..d {
                for col in 0..d {
                    closed[(coeff * d + row) + (coeff * d + col) * n] = k[row + col * d];
                }
            }
        }
        // the same up to the transforms' round-off, against the block's largest entry
        let size = block.iter().chain(&closed).fold(0.0f64, |m, v| m.max(v.abs()));
        changed |= block.iter().zip(&closed).any(|(a, b)| (a - b).abs() > 1e-9 * size);
        block.copy_from_slice(&closed);
    }
    if !changed {
        return Ok(None);
    }
    match jac.as_mut().expect("jacobian requested") {
        Matrix::Dense(m) => {
            fill_linear_jacobian(layout, lin, m);
            scatter_contact_jacobian(system, &ws.forces, m);
        }
        Matrix::Sparse(_) => {
            let mut t = std::mem::take(&mut ws.triplets);
            t.clear();
            linear_triplets(layout, lin, &mut t);
            contact_jacobian_triplets(system, &ws.forces, &mut t);
            ws.assembly.as_ref().expect("the evaluation above assembled it").assemble(&t, &mut jac);
            ws.triplets = t;
        }
    }
    Ok(Some((r, jac.expect("jacobian requested"))))
}

/// The per-contact cycle reports (states per time sample, dissipated energy) at `z`; empty
/// for a system without contacts.
///
/// # Errors
/// As [`evaluate`].
pub fn contact_cycles(
    system: &dyn HarmonicSystem,
    plan: Option<&AftPlan>,
    z: &[f64],
    ws: &mut ResidualWorkspace,
) -> Result<Vec<ContactCycle>> {
    if system.contact_laws().is_empty() {
        return Ok(Vec::new());
    }
    if z.len() != system.layout().total() {
        return Err(JpError::bad_size("HBM unknowns z", system.layout().total(), z.len()));
    }
    contact_forces_at(system, plan, z, false, true, ws)?;
    Ok(std::mem::take(&mut ws.forces.cycles))
}

/// The contact forces (and, when asked, their Jacobian blocks and cycle reports) at `z`, into
/// `ws.forces`.
fn contact_forces_at(system: &dyn HarmonicSystem, plan: Option<&AftPlan>, z: &[f64], want_jacobian: bool, want_cycles: bool, ws: &mut ResidualWorkspace) -> Result<()> {
    let plan = contact_plan(system, plan)?;
    gather_contact_coords(system, z, &mut ws.w_all);
    evaluate_contacts(
        plan,
        system.contact_laws(),
        system.contact_offsets(),
        system.n_contact_coords(),
        &ws.w_all,
        want_jacobian,
        want_cycles,
        &mut ws.forces,
    );
    // a failed external law (C callback) ends the evaluation with its error, never NaN
    ws.forces.check()
}

fn contact_plan<'p>(system: &dyn HarmonicSystem, plan: Option<&'p AftPlan>) -> Result<&'p AftPlan> {
    let plan = plan.ok_or_else(|| JpError::invalid("AFT plan", "a system with contacts needs an AftPlan"))?;
    if plan.harmonics() != system.layout().harmonics {
        return Err(JpError::invalid(
            "AFT plan",
            format!("plan has H = {}, system has H = {}", plan.harmonics(), system.layout().harmonics),
        ));
    }
    Ok(plan)
}
