//! The reference of a JP prediction (docs/formulation.md §8.10): the contact patterns of one
//! prediction differ from the boundary conditions at its smallest amplitude only at the contacts
//! whose state changes, so the model-sized factorisations are made once and each pattern costs
//! dense work on its *active* contact coordinates alone.
//!
//! The reference `K̂_ref` puts one `d x d` block per contact on every harmonic coefficient (the
//! contact's `K̂_00` at the first sample: stuck, open or slipping as the static state has it).
//! A pattern is `K̂ = K̂_ref + E_a^T D E_a`, `E_a` selecting the coordinates of the active
//! contacts (those whose `(2H + 1) d` block differs from the reference's). With
//! `A_ref = K + K̂_ref,00` and `B_h = A_ref - σ h^2 M` factorised once, and their solves with
//! the contact coordinates `Y_h = B_h^-1 E^T` (`B_0 = A_ref`), the Woodbury identity gives
//!
//! ```text
//! A_0^-1 E_a^T = Y_0,a (I + D_00 G_aa)^-1,        G_aa = E_a Y_0,a,
//! A_0^-1 b     = A_ref^-1 b - (A_0^-1 E_a^T) D_00 E_a A_ref^-1 b,
//! K_JC - σ M_JC = blockdiag_c(B_h(c)) + E_a^T ΔS E_a,
//! ΔS_ij = D_ij - D_i0 g_aa D_0j,                   g_aa = E_a A_0^-1 E_a^T,
//! ```
//!
//! so a pattern needs one LU of size `r = dim(a)` for the static condensation (28) and one of
//! size `2 H r` for the shift-invert solves of (31), instead of `n` and `2 H n_w`. Near stick
//! `r` is small; in gross slip it approaches `n_w` and the cost that of the per-pattern path.

use super::ContactJacobian;
use crate::aft::ContactForces;
use crate::error::{JpError, Result};
use crate::model::ContactCoordinates;
use crate::linalg::{product, DenseLu};
use faer::Mat;

/// Entries of a pattern's contact block within this fraction of the contact's stuck stiffness
/// from the reference count as equal (the AFT's round-off of a time-invariant stiffness).
pub const ACTIVE_TOLERANCE: f64 = 1e-12;

/// The factorisations of one prediction's reference, shared by all its patterns.
#[derive(Debug)]
pub struct ReferenceFactors {
    harmonics: usize,
    shift: f64,
    /// Per contact block, its reference `d x d` stiffness (column-major).
    blocks: Vec<Vec<f64>>,
    /// `A_ref = K + K̂_ref,00` (dense, `n x n`).
    a_ref: Mat<f64>,
    /// LU of `B_h`, `h = 0..=H` (`B_0 = A_ref`).
    lu: Vec<DenseLu<f64>>,
    /// `Y_h = B_h^-1 E^T` (`n x n_w`), `h = 0..=H`.
    y: Vec<Mat<f64>>,
}

/// Estimated bytes of [`ReferenceFactors`]: `A_ref`, and per `h = 0..=H` an LU (`n^2`) and
/// `Y_h` (`n n_w`).
pub fn reference_working_set_bytes(n: usize, nw: usize, harmonics: usize) -> u128 {
    use crate::memory::{bytes_of, product};
    let per_h = product(&[n, n]).saturating_add(product(&[n, nw]));
    bytes_of::<f64>(product(&[n, n]).saturating_add(per_h.saturating_mul(harmonics as u128 + 1)))
}

/// Columns of the Woodbury capacitance `I + S_l R` that the shifted solve on a reference forms
/// at a time (`shift_invert::ShiftedSolve::new`); its temporaries are sized by it.
pub(crate) const CAPACITANCE_PANEL: usize = 512;

/// Whether the shifted solve of a pattern on a reference reads `Y_h,l` in the reference's `Y_h`
/// instead of copying it: when its `r_lead` leading coordinates are at least half of the `n_w`
/// (the product with all of `Y_h` then costs at most twice the copy's).
pub(crate) fn reads_lead_columns_in_place(r_lead: usize, n_w: usize) -> bool {
    2 * r_lead >= n_w
}

/// Estimated bytes of one pattern with `r` active coordinates, `r_l` of them leading
/// ([`ActivePart::lead`]), on the reference of a model of `n` DoFs, `n_w` of them contact
/// coordinates: the static condensation's `n x r` solves and `r`-square blocks, the gathered
/// `Y_h,l` (`H n r_l`, only when `2 r_l < n_w`: otherwise the reference's `Y_h` are read in
/// place), `g_aa E_l^T` (`r r_l`), the capacitance's column panels (`2 (2H + 1) r` by
/// `CAPACITANCE_PANEL`) and
/// the shifted capacitance factorised in its place (`(2 H r_l)^2`, counted in double
/// precision even where it is factorised in single: one that fails its probe is formed again in
/// double, `shift_invert::MIXED_ACCEPT`; `S` is applied by its factors, never formed).
pub fn active_pattern_working_set_bytes(n: usize, n_w: usize, r: usize, r_lead: usize, harmonics: usize) -> u128 {
    use crate::memory::{bytes_of, product};
    let s = product(&[2 * harmonics, r_lead]);
    let lead_copies = if reads_lead_columns_in_place(r_lead, n_w) { 0 } else { product(&[harmonics, n, r_lead]) };
    let panels = product(&[2 * (2 * harmonics + 1), r, CAPACITANCE_PANEL]);
    let vectors = product(&[2, n, r]).saturating_add(lead_copies).saturating_add(panels);
    bytes_of::<f64>(vectors.saturating_add(product(&[3, r, r])).saturating_add(product(&[r, r_lead])).saturating_add(s.saturating_mul(s)))
}

impl ReferenceFactors {
    /// Factorises the reference whose contact blocks are the `K̂_00` blocks of `k_hat` (a
    /// pattern's Jacobian, normally the first sample's), at the shift `shift` (rad²/s²).
    ///
    /// # Errors
    /// As [`ReferenceFactors::new`]; [`JpError::BadSize`] if `k_hat` is not of this model.
    pub fn from_jacobian(coords: &ContactCoordinates, k_hat: &ContactJacobian, shift: f64) -> Result<Self> {
        let nw = coords.n_w;
        let hh = k_hat.harmonics;
        if k_hat.n_w != nw || k_hat.k_hat.nrows() != (2 * hh + 1) * nw {
            return Err(JpError::bad_size("contact Jacobian (rows)", (2 * hh + 1) * nw, k_hat.k_hat.nrows()));
        }
        let blocks = coords
            .laws
            .iter()
            .zip(&coords.offsets)
            .map(|(law, &off)| {
                let d = law.dim();
                (0..d * d).map(|idx| k_hat.k_hat[(off + idx % d, off + idx / d)]).collect()
            })
            .collect();
        Self::new(coords, blocks, hh, shift)
    }

    /// [`ReferenceFactors::from_jacobian`] from the contacts' Jacobian blocks of an AFT
    /// evaluation ([`crate::aft::evaluate_contacts`] with `want_jacobian`) at `H` harmonics,
    /// without assembling `K̂`.
    ///
    /// # Errors
    /// As [`ReferenceFactors::new`]; [`JpError::BadSize`] if the blocks do not match.
    pub fn from_forces(coords: &ContactCoordinates, forces: &ContactForces, harmonics: usize, shift: f64) -> Result<Self> {
        check_blocks(coords, forces, harmonics)?;
        let nc = 2 * harmonics + 1;
        let blocks = coords
            .laws
            .iter()
            .enumerate()
            .map(|(c, law)| {
                let d = law.dim();
                let m = nc * d;
                let start = forces.jac_offsets[c];
                (0..d * d).map(|idx| forces.jac[start + idx % d + (idx / d) * m]).collect()
            })
            .collect();
        Self::new(coords, blocks, harmonics, shift)
    }

    /// Factorises the reference with the contact blocks `blocks` (`d x d`, column-major, one
    /// per contact block of `coords`) at `H` harmonics and the shift `shift` (rad²/s²).
    ///
    /// # Errors
    /// [`JpError::TooLarge`] beyond the memory budget; [`JpError::SingularMatrix`] if `A_ref` or
    /// a `B_h` is singular (a free structure, or the shift on an eigenvalue of the reference);
    /// [`JpError::BadSize`], [`JpError::InvalidValue`] for bad blocks or shift.
    pub fn new(coords: &ContactCoordinates, blocks: Vec<Vec<f64>>, harmonics: usize, shift: f64) -> Result<Self> {
        let (n, nw, hh) = (coords.n_dof, coords.n_w, harmonics);
        if hh == 0 {
            return Err(JpError::invalid("harmonics", "JP modes need H >= 1"));
        }
        if !(shift.is_finite() && shift >= 0.0) {
            return Err(JpError::invalid("shift", format!("must be finite and >= 0, got {shift}")));
        }
        if blocks.len() != coords.laws.len() {
            return Err(JpError::bad_size("reference contact blocks", coords.laws.len(), blocks.len()));
        }
        crate::memory::check(
            &format!("the shared factorisations of the JP prediction at H = {hh} (n = {n} DoFs, n_w = {nw})"),
            reference_working_set_bytes(n, nw, hh),
        )?;
        let mut a_ref = coords.stiffness.clone();
        for (c, (law, &off)) in coords.laws.iter().zip(&coords.offsets).enumerate() {
            let d = law.dim();
            if blocks[c].len() != d * d {
                return Err(JpError::bad_size(format!("reference block of contact {c}"), d * d, blocks[c].len()));
            }
            for j in 0..d {
                for i in 0..d {
                    a_ref[(off + i, off + j)] += blocks[c][i + j * d];
                }
            }
        }
        let mut e = Mat::<f64>::zeros(n, nw);
        for i in 0..nw {
            e[(i, i)] = 1.0;
        }
        let mut lu = Vec::with_capacity(hh + 1);
        let mut y = Vec::with_capacity(hh + 1);
        for h in 0..=hh {
            let what = if h == 0 {
                "K + K̂_ref,00 (the reference static condensation of the JP prediction)".to_string()
            } else {
                format!("K + K̂_ref,00 - sigma h^2 M at h = {h} (the reference shift-invert of the JP prediction)")
            };
            let b = if h == 0 { a_ref.clone() } else { &a_ref - faer::Scale(shift * (h * h) as f64) * &coords.mass };
            let f = DenseLu::new(&b);
            let yh = f.solve(&e);
            // the solve must be accurate for the Woodbury corrections to be: its residual on
            // fixed combinations of the columns (`linalg::lu::probes`) (B (Y v) - E v), not the n x n_w product
            let probes = crate::linalg::lu::probes(nw);
            let yv = product(yh.as_ref(), probes.as_ref());
            let mut r = product(b.as_ref(), yv.as_ref());
            for j in 0..probes.ncols() {
                for i in 0..nw {
                    r[(i, j)] -= probes[(i, j)];
                }
            }
            let finite = (0..nw).all(|j| (0..n).all(|i| yh[(i, j)].is_finite()));
            if !finite || r.norm_l2() > 1e-9 * (b.norm_l2() * yv.norm_l2() + probes.norm_l2()) {
                return Err(JpError::singular(what));
            }
            lu.push(f);
            y.push(yh);
        }
        Ok(ReferenceFactors { harmonics: hh, shift, blocks, a_ref, lu, y })
    }

    /// The shift `σ` of the `B_h`.
    pub fn shift(&self) -> f64 {
        self.shift
    }

    /// Highest harmonic `H`.
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }

    /// `A_ref = K + K̂_ref,00`.
    pub(crate) fn a_ref(&self) -> &Mat<f64> {
        &self.a_ref
    }

    /// LU of `B_h` (`h = 0`: `A_ref`).
    pub(crate) fn lu(&self, h: usize) -> &DenseLu<f64> {
        &self.lu[h]
    }

    /// `Y_h = B_h^-1 E^T` (`n x n_w`).
    pub(crate) fn y(&self, h: usize) -> &Mat<f64> {
        &self.y[h]
    }

    /// `Y_h = B_h^-1 E^T` restricted to the columns `rows`.
    pub(crate) fn y_columns(&self, h: usize, rows: &[usize]) -> Mat<f64> {
        let y = &self.y[h];
        Mat::from_fn(y.nrows(), rows.len(), |i, j| y[(i, rows[j])])
    }

    /// `E_a Y_h E_a^T` (`r x r`).
    pub(crate) fn y_block(&self, h: usize, rows: &[usize]) -> Mat<f64> {
        let y = &self.y[h];
        Mat::from_fn(rows.len(), rows.len(), |i, j| y[(rows[i], rows[j])])
    }

    /// The part of `k_hat` that differs from the reference: its active contacts and their
    /// `D` blocks.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if `k_hat` is not of this reference's model and `H`.
    pub fn active_part(&self, coords: &ContactCoordinates, k_hat: &ContactJacobian) -> Result<ActivePart> {
        let (nw, hh) = (coords.n_w, self.harmonics);
        if k_hat.harmonics != hh || k_hat.n_w != nw || k_hat.k_hat.nrows() != (2 * hh + 1) * nw {
            return Err(JpError::bad_size("contact Jacobian of the pattern (against its reference)", (2 * hh + 1) * nw, k_hat.k_hat.nrows()));
        }
        let k = &k_hat.k_hat;
        self.active_part_with(coords, k_hat.static_offset.clone(), k.norm_max(), |_, off, d, row, col| {
            let (kk, i, l, j) = (row / d, row % d, col / d, col % d);
            k[(kk * nw + off + i, l * nw + off + j)]
        })
    }

    /// [`ReferenceFactors::active_part`] of the pattern whose AFT evaluation at the contact
    /// displacement `w_all` (harmonic-major) is `forces`, without assembling `K̂`.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if the blocks or `w_all` do not match.
    pub fn active_part_of_forces(&self, coords: &ContactCoordinates, forces: &ContactForces, w_all: &[f64]) -> Result<ActivePart> {
        let (nw, hh) = (coords.n_w, self.harmonics);
        check_blocks(coords, forces, hh)?;
        if w_all.len() != (2 * hh + 1) * nw || forces.force.len() != (2 * hh + 1) * nw {
            return Err(JpError::bad_size("contact displacement w", (2 * hh + 1) * nw, w_all.len()));
        }
        let g = super::static_offset(&coords.laws, &coords.offsets, nw, hh, forces, w_all);
        let k_max = forces.jac.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let nc = 2 * hh + 1;
        self.active_part_with(coords, g, k_max, |c, _, d, row, col| forces.jac[forces.jac_offsets[c] + row + col * nc * d])
    }

    /// The active contacts of the pattern whose contact `c` (offset `off`, dimension `d`) has
    /// the entry `entry(c, off, d, row, col)` in its coefficient-major block.
    fn active_part_with(&self, coords: &ContactCoordinates, static_offset: Vec<f64>, k_hat_max: f64, entry: impl Fn(usize, usize, usize, usize, usize) -> f64) -> Result<ActivePart> {
        if self.blocks.len() != coords.laws.len() {
            return Err(JpError::bad_size("contact blocks of the pattern (against its reference)", self.blocks.len(), coords.laws.len()));
        }
        let nc = 2 * self.harmonics + 1;
        let mut part = ActivePart { harmonics: self.harmonics, rows: Vec::new(), lead: Vec::new(), contacts: Vec::new(), static_offset, k_hat_max };
        for (ci, (law, &off)) in coords.laws.iter().zip(&coords.offsets).enumerate() {
            let d = law.dim();
            let m = nc * d;
            let scale = law.stuck_stiffness_block().iter().fold(0.0f64, |a, x| a.max(x.abs()));
            let reference = &self.blocks[ci];
            // D in contact-local, coefficient-major order: (k d + i, l d + j)
            let mut delta = vec![0.0; m * m];
            let mut big = 0.0f64;
            for col in 0..m {
                for row in 0..m {
                    let (k, i, l, j) = (row / d, row % d, col / d, col % d);
                    let v = entry(ci, off, d, row, col) - if k == l { reference[i + j * d] } else { 0.0 };
                    big = big.max(v.abs());
                    delta[row + col * m] = v;
                }
            }
            let tolerance = ACTIVE_TOLERANCE * scale.max(f64::MIN_POSITIVE);
            if big > tolerance {
                let start = part.rows.len();
                part.rows.extend(off..off + d);
                // the rows of D that differ: a slipping contact that stays closed keeps its
                // normal row (`k_n` on every coefficient); rows within the tolerance are zeroed
                for i in 0..d {
                    let rows_of_i = (0..nc).map(|k| k * d + i);
                    let row_big = rows_of_i.clone().flat_map(|row| (0..m).map(move |col| row + col * m)).fold(0.0f64, |a, idx| a.max(delta[idx].abs()));
                    if row_big > tolerance {
                        part.lead.push(start + i);
                    } else {
                        for row in rows_of_i {
                            for col in 0..m {
                                delta[row + col * m] = 0.0;
                            }
                        }
                    }
                }
                part.contacts.push(ActiveContact { start, dim: d, delta });
            }
        }
        Ok(part)
    }
}

/// Checks the Jacobian blocks of an AFT evaluation against the contact blocks of `coords`.
fn check_blocks(coords: &ContactCoordinates, forces: &ContactForces, harmonics: usize) -> Result<()> {
    if forces.jac_offsets.len() != coords.laws.len() {
        return Err(JpError::bad_size("contact Jacobian blocks", coords.laws.len(), forces.jac_offsets.len()));
    }
    for (c, law) in coords.laws.iter().enumerate() {
        let m = law.dim() * (2 * harmonics + 1);
        if forces.jac_offsets[c] + m * m > forces.jac.len() {
            return Err(JpError::bad_size(format!("Jacobian block of contact {c}"), forces.jac_offsets[c] + m * m, forces.jac.len()));
        }
    }
    Ok(())
}

/// One active contact of a pattern: its coordinates `start..start + dim` among the active ones
/// and its `D` block (`(2H + 1) d` square, column-major, coefficient-major).
#[derive(Clone, Debug)]
pub struct ActiveContact {
    start: usize,
    dim: usize,
    delta: Vec<f64>,
}

/// The active contacts of one pattern against its reference.
#[derive(Clone, Debug)]
pub struct ActivePart {
    harmonics: usize,
    /// The pattern's static offset `g` ([`ContactJacobian::static_offset`]), length `n_w`.
    pub static_offset: Vec<f64>,
    /// Largest absolute entry of the pattern's `K̂`.
    pub k_hat_max: f64,
    /// The contact coordinates (indices into `w`) of the active contacts, in order.
    pub rows: Vec<usize>,
    /// The *leading* active coordinates: positions in `rows` where a row of `D` differs
    /// from zero (`r_l` of them). `D = E_l^T D_l`, so the Woodbury capacitances are `r_l`
    /// and `2 H r_l` square.
    pub lead: Vec<usize>,
    contacts: Vec<ActiveContact>,
}

impl ActivePart {
    /// Number `r` of active coordinates.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True when the pattern is the reference itself.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Entry of `D_kl` between active coordinates `(a, b)` of one contact.
    fn entry(&self, c: &ActiveContact, k: usize, l: usize, i: usize, j: usize) -> f64 {
        let d = c.dim;
        let m = (2 * self.harmonics + 1) * d;
        c.delta[(k * d + i) + (l * d + j) * m]
    }

    /// `D_kl` as a dense `r x r` matrix (block-diagonal by contact).
    pub fn block(&self, k: usize, l: usize) -> Mat<f64> {
        let r = self.len();
        let mut out = Mat::<f64>::zeros(r, r);
        for c in &self.contacts {
            for j in 0..c.dim {
                for i in 0..c.dim {
                    out[(c.start + i, c.start + j)] = self.entry(c, k, l, i, j);
                }
            }
        }
        out
    }

    /// `D_kl x` (`x` with `r` rows).
    pub fn block_times(&self, k: usize, l: usize, x: faer::MatRef<'_, f64>) -> Mat<f64> {
        self.blocks_times(k, l, x, |v| v)
    }

    /// `|D_kl| x` (entrywise absolute values of `D_kl`; `x` with `r` rows).
    pub fn abs_block_times(&self, k: usize, l: usize, x: faer::MatRef<'_, f64>) -> Mat<f64> {
        self.blocks_times(k, l, x, f64::abs)
    }

    /// `f(D_kl) x`, `f` applied entrywise: the `d x d` blocks of `D_kl` gathered once, then
    /// each column of `x` block by block on contiguous slices.
    fn blocks_times(&self, k: usize, l: usize, x: faer::MatRef<'_, f64>, f: impl Fn(f64) -> f64) -> Mat<f64> {
        let mut blocks = Vec::with_capacity(self.contacts.iter().map(|c| c.dim * c.dim).sum());
        for c in &self.contacts {
            for j in 0..c.dim {
                for i in 0..c.dim {
                    blocks.push(f(self.entry(c, k, l, i, j)));
                }
            }
        }
        let mut out = Mat::<f64>::zeros(self.len(), x.ncols());
        let mut buffer = Vec::new();
        for col in 0..x.ncols() {
            // the column as a slice (copied only when its rows are strided)
            let xc: &[f64] = match x.col(col).try_as_col_major() {
                Some(c) => c.as_slice(),
                None => {
                    buffer.clear();
                    buffer.extend(x.col(col).iter().copied());
                    &buffer
                }
            };
            let oc = out.col_as_slice_mut(col);
            let mut b = 0;
            for c in &self.contacts {
                let (s, d) = (c.start, c.dim);
                for j in 0..d {
                    let xj = xc[s + j];
                    for i in 0..d {
                        oc[s + i] += blocks[b + i + j * d] * xj;
                    }
                }
                b += d * d;
            }
        }
        out
    }

    /// `x D_kl` (`x` with `r` columns).
    pub fn times_block(&self, x: faer::MatRef<'_, f64>, k: usize, l: usize) -> Mat<f64> {
        let mut out = Mat::<f64>::zeros(x.nrows(), self.len());
        for c in &self.contacts {
            for j in 0..c.dim {
                for i in 0..c.dim {
                    let v = self.entry(c, k, l, i, j);
                    if v != 0.0 {
                        for row in 0..x.nrows() {
                            out[(row, c.start + j)] += x[(row, c.start + i)] * v;
                        }
                    }
                }
            }
        }
        out
    }

    /// Largest absolute entry of `D`.
    pub fn norm_max(&self) -> f64 {
        self.contacts.iter().flat_map(|c| c.delta.iter()).fold(0.0f64, |a, x| a.max(x.abs()))
    }
}

/// The static condensation (28) of one pattern on the reference.
#[derive(Debug)]
pub struct ActiveStatics {
    /// `A_0^-1 E_a^T` (`n x r`).
    pub a0_inv_e: Mat<f64>,
    /// `g_aa = E_a A_0^-1 E_a^T` (`r x r`).
    pub g_aa: Mat<f64>,
    /// `A_0^-1 f_E^0` and `A_0^-1 [g; 0]` (`g` the static offset).
    pub x_force: Vec<f64>,
    pub x_offset: Vec<f64>,
}

/// The static condensation (28) of the pattern `part` on `reference`.
///
/// # Errors
/// [`JpError::SingularMatrix`] if `I + D_00 G_aa` (so `K + K̂_00`) is singular.
pub fn active_statics(coords: &ContactCoordinates, reference: &ReferenceFactors, part: &ActivePart) -> Result<ActiveStatics> {
    let (n, nw) = (coords.n_dof, coords.n_w);
    let r = part.len();
    let z = reference.y_columns(0, &part.rows); // A_ref^-1 E_a^T
    let lead = &part.lead;
    let a0_inv_e = if lead.is_empty() {
        z
    } else {
        // D_00 = E_l^T D_l (its leading rows): A_0^-1 E_a^T = Z - Z_l C^-1 (D_00 G_aa)_l,
        // C = I + (D_00 G_aa)_ll, r_l square
        let g = reference.y_block(0, &part.rows);
        let dg = part.block_times(0, 0, g.as_ref());
        let rl = lead.len();
        let c = Mat::from_fn(rl, rl, |i, j| dg[(lead[i], lead[j])] + if i == j { 1.0 } else { 0.0 });
        let dg_l = Mat::from_fn(rl, r, |i, j| dg[(lead[i], j)]);
        let w = super::lu_solve("K + K̂_00 (static condensation (28), on the reference)", &c, &dg_l)?;
        let z_l = Mat::from_fn(n, rl, |i, j| z[(i, lead[j])]);
        z - product(z_l.as_ref(), w.as_ref())
    };
    let g_aa = Mat::from_fn(r, r, |i, j| a0_inv_e[(part.rows[i], j)]);
    // A_0^-1 b = A_ref^-1 b - (A_0^-1 E_a^T) D_00 E_a A_ref^-1 b for b = f_E^0 and [g; 0]
    let mut b = Mat::<f64>::zeros(n, 2);
    for i in 0..n {
        b[(i, 0)] = coords.static_force[i];
    }
    for i in 0..nw {
        b[(i, 1)] = part.static_offset[i];
    }
    let mut x = reference.lu(0).solve(&b);
    if r > 0 {
        let xa = Mat::from_fn(r, 2, |i, j| x[(part.rows[i], j)]);
        let corr = &a0_inv_e * part.block_times(0, 0, xa.as_ref());
        x -= &corr;
    }
    if !(0..2).all(|j| (0..n).all(|i| x[(i, j)].is_finite())) {
        return Err(JpError::singular("K + K̂_00 (static condensation (28), on the reference)"));
    }
    Ok(ActiveStatics { a0_inv_e, g_aa, x_force: x.col(0).iter().copied().collect(), x_offset: x.col(1).iter().copied().collect() })
}

/// `ΔS_ij = D_ij - D_i0 g_aa D_0j` on the active coordinates of the coefficients `1..=2H`
/// (block `c - 1` of size `r`): the pattern's part of `S` beyond the reference.
pub fn active_condensation(part: &ActivePart, g_aa: &Mat<f64>) -> Mat<f64> {
    let r = part.len();
    let nj = 2 * part.harmonics;
    let mut s = Mat::<f64>::zeros(nj * r, nj * r);
    for ci in 1..=nj {
        let left = part.block_times(ci, 0, g_aa.as_ref());
        for cj in 1..=nj {
            let corr = part.times_block(left.as_ref(), 0, cj);
            let dij = part.block(ci, cj);
            let mut blk = s.as_mut().submatrix_mut((ci - 1) * r, (cj - 1) * r, r, r);
            blk.copy_from(&dij - &corr);
        }
    }
    s
}
