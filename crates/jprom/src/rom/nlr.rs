//! Nonlinear-DoF reduction NLR (docs/formulation.md §9, paper (21)-(26)): `q_N,h = Φ_N,h s_h` on the
//! condensed system of §5 ([`CondensedSystem`]), with `Φ_N,h` the contact rows of the JP basis,
//! orthonormalised. The linear DoFs stay exact (condensation); per frequency the reduced
//! dynamic stiffness `Φ_N^T H_h(omega) Φ_N` costs one condensation of `D_h` (a factorisation
//! of `D_h,LL`), which is what makes NLR slower per iteration than FR. The condensation is
//! done on the projected blocks ([`ProjectedCondensation`]), so a frequency costs nothing of
//! order `n_w^2`.

use super::ReducedModel;
use crate::condensation::{CondensedSystem, ProjectedCondensation};
use crate::contact::Contacts;
use crate::error::{check_finite, JpError, Result};
use crate::hbm::{ContactMap, HarmonicLayout, HarmonicSystem, LinearPart};
use crate::jp::JpBasis;
use faer::Mat;

/// Relative singular-value floor when orthonormalising the contact rows of a basis.
pub const CONTACT_ROWS_TOLERANCE: f64 = 1e-10;

/// The NLR reduced model: a [`HarmonicSystem`] with `s_h` unknowns per harmonic.
#[derive(Clone, Debug)]
pub struct NlrRom {
    condensed: CondensedSystem,
    layout: HarmonicLayout,
    /// Orthonormal `Φ_N,h` (`n_w x s_h`).
    phi_n: Vec<Mat<f64>>,
    /// The linear part projected onto `Φ_N,h`.
    projected: ProjectedCondensation,
}

/// Orthonormal basis of the columns of `a` (thin SVD, singular values above `tol * s_max`).
fn orthonormal_columns(a: &Mat<f64>, tol: f64) -> Result<Mat<f64>> {
    if a.ncols() == 0 {
        return Ok(Mat::zeros(a.nrows(), 0));
    }
    let svd = a.thin_svd().map_err(|e| JpError::Eigen { what: format!("SVD of the contact rows: {e:?}") })?;
    let s = svd.S().column_vector();
    let smax = if s.nrows() > 0 { s[0] } else { 0.0 };
    let keep = (0..s.nrows()).take_while(|&i| smax > 0.0 && s[i] > tol * smax).count();
    Ok(svd.U().subcols(0, keep).to_owned())
}

impl NlrRom {
    /// Builds the NLR model of `condensed` from the contact rows of `basis`.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if the basis does not match the model; [`JpError::InvalidValue`] if
    /// the basis has more harmonics than the condensed system or no first-harmonic column.
    pub fn new(condensed: &CondensedSystem, basis: &JpBasis) -> Result<Self> {
        let coords = condensed.coordinates();
        let hh = basis.harmonics();
        if basis.n_dof != coords.n_dof || basis.n_w != coords.n_w {
            return Err(JpError::bad_size("JP basis (rows)", coords.n_dof, basis.n_dof));
        }
        if condensed.layout().harmonics != hh {
            return Err(JpError::invalid("JP basis", format!("has H = {hh}, condensed system H = {}", condensed.layout().harmonics)));
        }
        let nw = coords.n_w;
        let phi_n: Vec<Mat<f64>> = basis
            .phi
            .iter()
            .map(|p| orthonormal_columns(&p.as_ref().subrows(0, nw).to_owned(), CONTACT_ROWS_TOLERANCE))
            .collect::<Result<_>>()?;
        if phi_n[1].ncols() == 0 {
            return Err(JpError::invalid("JP basis", "no first-harmonic column on the contact coordinates"));
        }
        let layout = HarmonicLayout::new(phi_n.iter().map(|p| p.ncols()).collect());
        let projected = condensed.project(&phi_n)?;
        Ok(NlrRom { condensed: condensed.clone(), layout, phi_n, projected })
    }

    /// Orthonormal contact-row bases `Φ_N,h`.
    pub fn contact_basis(&self) -> &[Mat<f64>] {
        &self.phi_n
    }

    fn check_z(&self, z: &[f64]) -> Result<()> {
        if z.len() != self.layout.total() {
            return Err(JpError::bad_size("reduced unknowns s", self.layout.total(), z.len()));
        }
        check_finite("reduced unknowns s", z)
    }

    /// Condensed-system unknowns `q_N = Φ_N s` (layout of the condensed system).
    pub fn condensed_unknowns(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.check_z(z)?;
        let nw = self.condensed.coordinates().n_w;
        let hh = self.layout.harmonics;
        let mut q = vec![0.0; nw * (2 * hh + 1)];
        for k in 0..2 * hh + 1 {
            let h = (k + 1) / 2;
            let (o, len) = self.layout.coeff_range(k);
            let v = mat_vec(&self.phi_n[h], &z[o..o + len]);
            q[k * nw..(k + 1) * nw].copy_from_slice(&v);
        }
        Ok(q)
    }
}

fn mat_vec(a: &Mat<f64>, v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.nrows()];
    for (j, &x) in v.iter().enumerate() {
        for (i, o) in out.iter_mut().enumerate() {
            *o += a[(i, j)] * x;
        }
    }
    out
}


impl HarmonicSystem for NlrRom {
    fn layout(&self) -> &HarmonicLayout {
        &self.layout
    }
    fn contacts(&self) -> Contacts<'_> {
        self.condensed.contacts()
    }
    fn contact_map(&self, h: usize) -> ContactMap<'_> {
        ContactMap::Dense(self.phi_n[h].as_ref())
    }
    fn linear_part(&self, omega: f64) -> Result<LinearPart> {
        self.projected.linear_part(omega)
    }
    fn linear_part_with_derivative_into(&self, omega: f64, out: &mut Option<LinearPart>, derivative: &mut Option<LinearPart>) -> Result<bool> {
        let (lin, d) = self.projected.linear_part_and_derivative(omega, true)?;
        *out = Some(lin);
        *derivative = d;
        Ok(true)
    }
    fn output_harmonics(&self, omega: f64, z: &[f64]) -> Result<Vec<f64>> {
        let q = self.condensed_unknowns(z)?;
        self.condensed.output_harmonics(omega, &q)
    }
    fn n_outputs(&self) -> usize {
        self.condensed.n_outputs()
    }
}

impl ReducedModel for NlrRom {
    fn full_size(&self) -> usize {
        self.condensed.coordinates().n_w
    }
    /// `f*_C^h = H_h Φ_N,h s_h - g_h` on the contact coordinates (the NLR form of (40)).
    fn implied_contact_force(&self, omega: f64, z: &[f64]) -> Result<Vec<Vec<f64>>> {
        let q = self.condensed_unknowns(z)?;
        self.condensed.linear_residual_parts(omega, &q)
    }
    /// All z-coordinates, recovered through the condensation (13).
    fn full_coefficients(&self, omega: f64, z: &[f64]) -> Result<Vec<Vec<f64>>> {
        let q = self.condensed_unknowns(z)?;
        let nw = self.full_size();
        let mut out = Vec::new();
        let (c0, _) = self.condensed.recover(omega, 0, &q[..nw], &[])?;
        out.push(c0);
        for h in 1..=self.layout.harmonics {
            let (c, s) = self.condensed.recover(omega, h, &q[(2 * h - 1) * nw..2 * h * nw], &q[2 * h * nw..(2 * h + 1) * nw])?;
            out.push(c);
            out.push(s);
        }
        Ok(out)
    }
}
