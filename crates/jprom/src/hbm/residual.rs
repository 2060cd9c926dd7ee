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
use crate::linalg::sparse::sparse_from_triplets_in;
use crate::linalg::{sparse_from_triplets, Matrix};
use faer::{Accum, Mat, Par};

/// Scratch memory of [`evaluate`], reused across Newton iterations.
#[derive(Default)]
pub struct ResidualWorkspace {
    w_all: Vec<f64>,
    triplets: Vec<(usize, usize, f64)>,
    forces: ContactForces,
    contact_force_norm: f64,
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
    let mut r = vec![0.0; layout.total()];
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
        let (rc, rs) = split_pair(&mut r, oc, os, n);
        re.mul_add(zc, 1.0, rc);
        im.mul_add(zs, 1.0, rc);
        im.mul_add(zc, -1.0, rs);
        re.mul_add(zs, 1.0, rs);
        for i in 0..n {
            rc[i] -= lin.fh_cos[h - 1][i];
            rs[i] -= lin.fh_sin[h - 1][i];
        }
    }
    r
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

/// The linear Jacobian `D` (block-diagonal over harmonics): sparse when the linear part is.
pub fn linear_jacobian(layout: &HarmonicLayout, lin: &LinearPart) -> Matrix {
    let nt = layout.total();
    if is_sparse(lin) {
        let mut t = Vec::new();
        linear_triplets(layout, lin, &mut t);
        return Matrix::Sparse(sparse_from_triplets(nt, nt, t).expect("linear part entries are in range and finite"));
    }
    let mut jac = Mat::<f64>::zeros(nt, nt);
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
    Matrix::Dense(jac)
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
    let coeff_off: Vec<usize> = (0..n_coeffs).map(|k| layout.coeff_range(k).0).collect();
    for (c, law) in system.contact_laws().iter().enumerate() {
        let d = law.dim();
        let n = d * n_coeffs;
        let block = &forces.jac[forces.jac_offsets[c]..forces.jac_offsets[c] + n * n];
        let o = system.contact_offsets()[c];
        for col in 0..n {
            let gcol = coeff_off[col / d] + o + col % d;
            for row in 0..n {
                out.push((coeff_off[row / d] + o + row % d, gcol, block[row + col * n]));
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
    let coeff_off: Vec<usize> = (0..n_coeffs).map(|k| layout.coeff_range(k).0).collect();
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
                    let gcol = coeff_off[kc] + o + ic;
                    for kr in 0..n_coeffs {
                        for ir in 0..d {
                            let v = block[kr * d + ir + col * n];
                            if v != 0.0 {
                                jac[(coeff_off[kr] + o + ir, gcol)] += v;
                            }
                        }
                    }
                }
            }
        }
        return;
    }
    // Dense map: Wall ((2H+1) n_w x N_tot, harmonic-major rows), G = K̂ Wall contact by
    // contact, then J += Wall^T G.
    let nt = layout.total();
    let rows = n_coeffs * n_w;
    let mut wall = Mat::<f64>::zeros(rows, nt);
    for k in 0..n_coeffs {
        let h = (k + 1) / 2;
        let (off, n) = layout.coeff_range(k);
        match system.contact_map(h) {
            ContactMap::Leading => {
                for i in 0..n_w {
                    wall[(k * n_w + i, off + i)] = 1.0;
                }
            }
            ContactMap::Dense(w) => {
                for j in 0..n {
                    for i in 0..n_w {
                        wall[(k * n_w + i, off + j)] = w[(i, j)];
                    }
                }
            }
        }
    }
    let mut g = Mat::<f64>::zeros(rows, nt);
    for (c, law) in laws.iter().enumerate() {
        let d = law.dim();
        let n = d * n_coeffs;
        let block = &forces.jac[forces.jac_offsets[c]..forces.jac_offsets[c] + n * n];
        let o = offsets[c];
        let grow = |local: usize| (local / d) * n_w + o + local % d;
        for col in 0..nt {
            for r in 0..n {
                let mut s = 0.0;
                for q in 0..n {
                    let kv = block[r + q * n];
                    if kv != 0.0 {
                        s += kv * wall[(grow(q), col)];
                    }
                }
                g[(grow(r), col)] = s;
            }
        }
    }
    faer::linalg::matmul::matmul(jac.as_mut(), Accum::Add, wall.transpose(), g.as_ref(), 1.0, Par::Seq);
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
    let layout = system.layout();
    if z.len() != layout.total() {
        return Err(JpError::bad_size("HBM unknowns z", layout.total(), z.len()));
    }
    check_linear_part(layout, lin)?;
    let mut r = linear_residual(layout, lin, z);
    let leading = (0..=layout.harmonics).all(|h| matches!(system.contact_map(h), ContactMap::Leading));
    // a sparse system's Jacobian is assembled once from the entries of D and of the contacts
    let sparse = want_jacobian && is_sparse(lin) && leading;
    let mut jac = (want_jacobian && !sparse).then(|| linear_jacobian(layout, lin).into_dense());
    ws.contact_force_norm = 0.0;
    if system.contact_laws().is_empty() {
        let jac = if sparse { Some(linear_jacobian(layout, lin)) } else { jac.map(Matrix::Dense) };
        return Ok((r, jac));
    }
    contact_forces_at(system, plan, z, want_jacobian, false, ws)?;
    ws.contact_force_norm = scatter_contact_force(system, &ws.forces.force, &mut r);
    if sparse {
        let nt = layout.total();
        let mut t = std::mem::take(&mut ws.triplets);
        t.clear();
        linear_triplets(layout, lin, &mut t);
        contact_jacobian_triplets(system, &ws.forces, &mut t);
        let j = sparse_from_triplets_in(nt, nt, &mut t);
        ws.triplets = t;
        return Ok((r, Some(Matrix::Sparse(j?))));
    }
    if let Some(j) = jac.as_mut() {
        scatter_contact_jacobian(system, &ws.forces, j);
    }
    Ok((r, jac.map(Matrix::Dense)))
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
