//! The JP reduction basis `Φ_h`, `h = 0..=H` (docs/formulation.md §8): JP modes of one or several sets
//! of boundary conditions, stacked per harmonic (36) and conditioned (38).

use super::conditioning::condition;
use super::modes::{jp_modes, JpModes, ModeOptions};
use super::ContactJacobian;
use crate::aft::{evaluate_contacts, ContactForces};
use crate::error::{JpError, Result};
use crate::io::documents::{bad, finite, Check, Document};
use crate::limits::MAX_HARMONICS;
use crate::hbm::PointSolution;
use crate::linalg::serde_mat_vec;
use crate::model::ContactCoordinates;
use faer::Mat;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// How a basis is built from JP modes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BasisOptions {
    /// Selection of the eigenpairs (band, extra modes).
    pub modes: ModeOptions,
    /// Conditioning ratio `gamma` of (38) (typically 1e2 to 1e4; larger is bigger and more accurate).
    pub gamma: f64,
}

/// A conditioned JP basis in contact coordinates (`z = [w; y]`, so the contact rows are the
/// first `n_w`). Serialisable; saved as a versioned "basis" document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JpBasis {
    /// Orthonormal `Φ_h` (`n x n_h`), `h = 0..=H`.
    #[serde(with = "serde_mat_vec")]
    pub phi: Vec<Mat<f64>>,
    /// `n_h`, `h = 0..=H`.
    pub sizes: Vec<usize>,
    /// Conditioning ratio used.
    pub gamma: f64,
    /// Number of distinct boundary conditions (contact-state patterns) whose modes were stacked.
    pub n_patterns: usize,
    /// Number of model DoFs `n` and contact coordinates `n_w` the basis was built for.
    pub n_dof: usize,
    pub n_w: usize,
    /// Singular values of the raw stacked modes per harmonic (for choosing `gamma`).
    pub singular_values: Vec<Vec<f64>>,
    /// Analysis band `[omega_lo, omega_hi]` (rad/s) the JP modes were selected in, when known
    /// (set by [`JpBasis::from_jacobian`], [`JpBasis::from_solution`] and
    /// [`super::predict_basis`]; `None` for [`JpBasis::from_raw`] and for files saved before
    /// it existed). [`crate::rom::FrRom::new`] condenses its linear-DoF rows over this band.
    #[serde(default)]
    pub band: Option<(f64, f64)>,
}

impl JpBasis {
    /// This basis conditioned with a smaller `gamma` (docs/formulation.md §8.7): (38) keeps
    /// the left singular vectors whose singular value is at least `s_max / gamma`, and the
    /// basis holds the leading ones of the same SVD with all singular values, so this is a
    /// column truncation, identical to predicting the basis again with `gamma`.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] if `gamma` exceeds the basis' own.
    pub fn reconditioned(&self, gamma: f64) -> Result<JpBasis> {
        let basis = self;
        if !(gamma >= 1.0 && gamma <= basis.gamma) {
            return Err(JpError::invalid("gamma", format!("must be in [1, {}] to re-condition this basis, got {gamma}", basis.gamma)));
        }
        let mut out = basis.clone();
        out.gamma = gamma;
        for (h, (phi, sv)) in basis.phi.iter().zip(&basis.singular_values).enumerate() {
            let s_max = sv.first().copied().unwrap_or(0.0);
            let keep = if s_max > 0.0 { sv.iter().take_while(|&&x| x >= s_max / gamma).count().min(phi.ncols()) } else { 0 };
            out.phi[h] = phi.as_ref().subcols(0, keep).to_owned();
            out.sizes[h] = keep;
        }
        Ok(out)
    }

    /// Highest harmonic `H`.
    pub fn harmonics(&self) -> usize {
        self.phi.len() - 1
    }

    /// Conditions the raw stacked modes `raw[h]` with `gamma`.
    ///
    /// # Errors
    /// As [`condition`]; [`JpError::BadSize`] if the harmonics have different row counts.
    pub fn from_raw(raw: &[Mat<f64>], gamma: f64, n_patterns: usize, n_w: usize) -> Result<Self> {
        if raw.len() < 2 {
            return Err(JpError::invalid("JP basis", "needs the static term and at least one harmonic"));
        }
        let n = raw[0].nrows();
        let mut phi = Vec::with_capacity(raw.len());
        let mut singular_values = Vec::with_capacity(raw.len());
        for (h, r) in raw.iter().enumerate() {
            if r.nrows() != n {
                return Err(JpError::bad_size(format!("JP modes of harmonic {h} (rows)"), n, r.nrows()));
            }
            let c = condition(r, gamma)?;
            phi.push(c.basis);
            singular_values.push(c.singular_values);
        }
        let sizes = phi.iter().map(|p| p.ncols()).collect();
        Ok(JpBasis { phi, sizes, gamma, n_patterns, n_dof: n, n_w, singular_values, band: None })
    }

    /// The basis of one set of boundary conditions (e.g. a full-order solution's own `K̂`).
    ///
    /// # Errors
    /// As [`jp_modes`] and [`condition`].
    pub fn from_jacobian(coords: &ContactCoordinates, k_hat: &ContactJacobian, opts: &BasisOptions) -> Result<Self> {
        let modes = jp_modes(coords, k_hat, &opts.modes)?;
        Ok(Self::from_raw(&modes.phi, opts.gamma, 1, coords.n_w)?.with_band(opts.modes.band))
    }

    /// The basis of a full-order solution's own boundary conditions: the contact displacement
    /// `w` of `fo` (a point of a [`crate::hbm::FullSystem`], `n` unknowns per coefficient, or of
    /// a [`crate::condensation::CondensedSystem`], `n_w` per coefficient), its contact stiffness
    /// `K̂ = dF/dw` by the AFT of `plan` ([`ContactJacobian::from_forces`]), then
    /// [`JpBasis::from_jacobian`]. With every eigenpair kept this basis reproduces `fo`
    /// (docs/formulation.md §8; tests/rom_reproduce.rs).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] if `fo`'s `H` differs from `coords`'; [`JpError::BadSize`] if
    /// `fo` is not laid out as a full-order or condensed solution of `coords` (e.g. a reduced
    /// solution); as [`JpBasis::from_jacobian`].
    pub fn from_solution(coords: &ContactCoordinates, fo: &PointSolution, opts: &BasisOptions) -> Result<Self> {
        super::require_contacts("JP basis", coords.n_w)?;
        let plan = &coords.discretisation.plan()?;
        let hh = plan.harmonics();
        if fo.layout.harmonics != hh {
            return Err(JpError::invalid("full-order solution", format!("H = {}, the coordinates' H = {hh}", fo.layout.harmonics)));
        }
        let n0 = fo.layout.sizes[0];
        if (n0 != coords.n_dof && n0 != coords.n_w) || fo.layout.sizes.iter().any(|&s| s != n0) {
            return Err(JpError::bad_size("full-order solution unknowns per harmonic (n or n_w for every h)", coords.n_dof, n0));
        }
        let w = fo.contact_displacement(coords.n_w)?;
        let mut forces = ContactForces::default();
        evaluate_contacts(plan, &coords.laws, &coords.offsets, coords.n_w, &w, true, false, &mut forces);
        forces.check()?;
        let k_hat = ContactJacobian::from_forces(&coords.laws, &coords.offsets, coords.n_w, hh, &forces, &w)?;
        Self::from_jacobian(coords, &k_hat, opts)
    }

    /// Stacks (36) the modes of several boundary conditions and conditions them.
    ///
    /// # Errors
    /// As [`condition`]; [`JpError::InvalidValue`] if `modes` is empty or harmonics differ.
    pub fn from_modes(modes: &[JpModes], gamma: f64, n_w: usize) -> Result<Self> {
        let first = modes.first().ok_or_else(|| JpError::invalid("JP modes", "no boundary conditions given"))?;
        let nh = first.phi.len();
        let n = first.phi[0].nrows();
        let mut raw = Vec::with_capacity(nh);
        for h in 0..nh {
            let total: usize = modes.iter().map(|m| m.phi.get(h).map_or(0, |p| p.ncols())).sum();
            let mut stacked = Mat::zeros(n, total);
            let mut at = 0;
            for m in modes {
                let p = m.phi.get(h).ok_or_else(|| JpError::invalid("JP modes", "different numbers of harmonics"))?;
                stacked.as_mut().submatrix_mut(0, at, n, p.ncols()).copy_from(p);
                at += p.ncols();
            }
            raw.push(stacked);
        }
        Self::from_raw(&raw, gamma, modes.len(), n_w)
    }

    /// Re-conditions with another `gamma` is not possible from the conditioned basis alone;
    /// this extends the basis by extra columns (orthonormalised against it, dropping those
    /// within `tol` of its span), e.g. to add a regenerated set of modes.
    pub fn extended(&self, extra: &[Mat<f64>], tol: f64) -> Result<Self> {
        if extra.len() != self.phi.len() {
            return Err(JpError::bad_size("extra columns (harmonics)", self.phi.len(), extra.len()));
        }
        let mut phi = Vec::with_capacity(self.phi.len());
        for (p, e) in self.phi.iter().zip(extra) {
            phi.push(orthonormal_extension(p, e, tol)?);
        }
        let sizes = phi.iter().map(|p| p.ncols()).collect();
        Ok(JpBasis { phi, sizes, singular_values: self.singular_values.clone(), ..self.clone() })
    }

    /// The union of two bases (e.g. a basis and the one regenerated from a reduced solution,
    /// docs/formulation.md §8.8 last paragraph): per harmonic the columns of both are stacked (36) and
    /// re-conditioned by SVD (37)-(38) with `gamma`. Both are orthonormal, so every singular
    /// value of the stack lies in `[0, sqrt 2]` and `gamma` only drops directions the two
    /// share up to `sqrt 2 / gamma`.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if the bases differ in model size or harmonics; as [`condition`].
    pub fn union(&self, other: &JpBasis, gamma: f64) -> Result<Self> {
        if self.n_dof != other.n_dof || self.n_w != other.n_w || self.phi.len() != other.phi.len() {
            return Err(JpError::bad_size("bases to unite (rows x harmonics)", self.n_dof * self.phi.len(), other.n_dof * other.phi.len()));
        }
        let n = self.n_dof;
        let raw: Vec<Mat<f64>> = self
            .phi
            .iter()
            .zip(&other.phi)
            .map(|(a, b)| {
                let mut m = Mat::zeros(n, a.ncols() + b.ncols());
                m.as_mut().submatrix_mut(0, 0, n, a.ncols()).copy_from(a);
                m.as_mut().submatrix_mut(0, a.ncols(), n, b.ncols()).copy_from(b);
                m
            })
            .collect();
        let band = match (self.band, other.band) {
            (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
            (a, b) => a.or(b),
        };
        Ok(JpBasis { band, ..Self::from_raw(&raw, gamma, self.n_patterns + other.n_patterns, self.n_w)? })
    }

    /// Whether `other` spans the same subspace as this basis in every harmonic, to `tol`: the
    /// same sizes, and each column of `other` within `tol` of this basis' span,
    /// `max |Φ'_h - Φ_h Φ_h^T Φ'_h| <= tol` (both orthonormal). A reduced model on either gives
    /// the same reduced solutions.
    pub fn spans_the_same(&self, other: &JpBasis, tol: f64) -> bool {
        self.n_dof == other.n_dof
            && self.sizes == other.sizes
            && self.phi.iter().zip(&other.phi).all(|(a, b)| {
                let coefficients = a.transpose() * b;
                let residual = b - a * &coefficients;
                (0..residual.ncols()).all(|j| (0..residual.nrows()).all(|i| residual[(i, j)].abs() <= tol))
            })
    }

    /// The basis with its analysis band set (see [`JpBasis::band`]).
    pub fn with_band(self, band: (f64, f64)) -> Self {
        JpBasis { band: Some(band), ..self }
    }

    /// Total number of reduced unknowns `n_0 + 2 sum_h n_h`.
    pub fn n_unknowns(&self) -> usize {
        self.sizes[0] + 2 * self.sizes[1..].iter().sum::<usize>()
    }

    /// Saves as a versioned JSON "basis" document.
    pub fn save_json(&self, path: &Path) -> Result<()> {
        crate::io::save_json("basis", self, path)
    }

    /// Loads a "basis" document and checks its consistency.
    ///
    /// # Errors
    /// I/O and parse errors, [`JpError::BadSize`] if the sizes do not match the matrices.
    pub fn load_json(path: &Path) -> Result<Self> {
        let b: JpBasis = crate::io::load_json("basis", path)?;
        if b.phi.len() != b.sizes.len() || b.phi.len() < 2 {
            return Err(JpError::bad_size("basis harmonics", b.sizes.len(), b.phi.len()));
        }
        for (h, p) in b.phi.iter().enumerate() {
            if p.nrows() != b.n_dof || p.ncols() != b.sizes[h] {
                return Err(JpError::bad_size(format!("basis harmonic {h}"), b.n_dof * b.sizes[h], p.nrows() * p.ncols()));
            }
        }
        Ok(b)
    }
}

/// `[p, e']` with `e'` the part of `e` orthogonal to `p`, orthonormalised by a thin SVD and
/// keeping directions whose singular value exceeds `tol` (relative to unit columns).
pub(crate) fn orthonormal_extension(p: &Mat<f64>, e: &Mat<f64>, tol: f64) -> Result<Mat<f64>> {
    let n = p.nrows();
    if e.ncols() == 0 {
        return Ok(p.clone());
    }
    if e.nrows() != n {
        return Err(JpError::bad_size("extra columns (rows)", n, e.nrows()));
    }
    // Normalise, project out span(p) twice (classical Gram-Schmidt with re-orthogonalisation).
    let mut r = e.clone();
    for j in 0..r.ncols() {
        let nrm = super::col_norm(&r, j);
        if nrm > 0.0 {
            for i in 0..n {
                r[(i, j)] /= nrm;
            }
        }
    }
    for _ in 0..2 {
        if p.ncols() > 0 {
            let c = p.transpose() * &r;
            r -= p * &c;
        }
    }
    let svd = r.thin_svd().map_err(|e| JpError::Eigen { what: format!("SVD of basis extension: {e:?}") })?;
    let s = svd.S().column_vector();
    let keep = (0..s.nrows()).take_while(|&i| s[i] > tol).count();
    let mut out = Mat::zeros(n, p.ncols() + keep);
    out.as_mut().submatrix_mut(0, 0, n, p.ncols()).copy_from(p);
    out.as_mut().submatrix_mut(0, p.ncols(), n, keep).copy_from(svd.U().subcols(0, keep));
    Ok(out)
}

impl Document for JpBasis {
    const KIND: &'static str = "basis";
    fn check(&self) -> Result<Check> {
        Ok(check_basis(self))
    }
}

fn check_basis(b: &JpBasis) -> Check {
    if b.phi.len() < 2 || b.phi.len() > MAX_HARMONICS + 1 {
        return bad("phi", format!("has {} harmonics' matrices, 2..={} (h = 0..=H) expected", b.phi.len(), MAX_HARMONICS + 1));
    }
    if b.sizes.len() != b.phi.len() {
        return bad("sizes", format!("has {} entries, phi has {} matrices (h = 0..=H)", b.sizes.len(), b.phi.len()));
    }
    if b.singular_values.len() != b.phi.len() {
        return bad("singular_values", format!("has {} lists, phi has {} matrices", b.singular_values.len(), b.phi.len()));
    }
    if b.n_w > b.n_dof {
        return bad("n_w", format!("{} contact coordinates in a model of n_dof = {}", b.n_w, b.n_dof));
    }
    for (h, p) in b.phi.iter().enumerate() {
        if p.nrows() != b.n_dof {
            return bad(format!("phi[{h}].nrows"), format!("harmonic {h} has {} rows, n_dof is {}", p.nrows(), b.n_dof));
        }
        if p.ncols() != b.sizes[h] {
            return bad(format!("phi[{h}].ncols"), format!("harmonic {h} has {} columns, sizes[{h}] is {}", p.ncols(), b.sizes[h]));
        }
        for j in 0..p.ncols() {
            for i in 0..p.nrows() {
                if !p[(i, j)].is_finite() {
                    return bad(format!("phi[{h}].data"), format!("entry ({i}, {j}) is not finite"));
                }
            }
        }
        finite(&format!("singular_values[{h}]"), &b.singular_values[h])?;
    }
    if !(b.gamma.is_finite() && b.gamma >= 1.0) {
        return bad("gamma", format!("must be finite and >= 1, got {}", b.gamma));
    }
    if let Some((lo, hi)) = b.band {
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > 0.0) {
            return bad("band", format!("must be two finite positive frequencies, got ({lo}, {hi})"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-harmonic basis whose columns are `cols` (orthonormal) in 8 DoFs.
    fn basis(cols: &[[f64; 8]]) -> JpBasis {
        let phi = Mat::from_fn(8, cols.len(), |i, j| cols[j][i]);
        JpBasis { phi: vec![phi], sizes: vec![cols.len()], gamma: 1e3, n_patterns: 1, n_dof: 8, n_w: 8, singular_values: vec![vec![1.0; cols.len()]], band: None }
    }

    fn unit(i: usize, c: f64, k: usize, s: f64) -> [f64; 8] {
        let mut v = [0.0; 8];
        v[i] += c;
        v[k] += s;
        v
    }

    #[test]
    fn a_rotation_within_the_span_is_the_same_span_and_a_tilt_out_of_it_is_not() {
        let a = basis(&[unit(0, 1.0, 0, 0.0), unit(1, 1.0, 1, 0.0), unit(2, 1.0, 2, 0.0)]);
        let (c, s) = (0.6f64, 0.8f64);
        let rotated = basis(&[unit(0, c, 1, s), unit(0, -s, 1, c), unit(2, 1.0, 2, 0.0)]);
        assert!(a.spans_the_same(&rotated, 1e-12) && rotated.spans_the_same(&a, 1e-12));
        // a column tilted by 1e-6 rad out of the span is within 1e-5 but not within 1e-8
        let t = 1e-6f64;
        let tilted = basis(&[unit(0, t.cos(), 5, t.sin()), unit(1, 1.0, 1, 0.0), unit(2, 1.0, 2, 0.0)]);
        assert!(!a.spans_the_same(&tilted, 1e-8));
        assert!(a.spans_the_same(&tilted, 1e-5));
        // a smaller basis inside the span is not the same span
        let smaller = basis(&[unit(0, 1.0, 0, 0.0), unit(1, 1.0, 1, 0.0)]);
        assert!(!a.spans_the_same(&smaller, 1e-12) && !smaller.spans_the_same(&a, 1e-12));
    }
}
