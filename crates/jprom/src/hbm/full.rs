//! The full-order harmonic system: every DoF of the model, in the contact coordinates
//! `z = [w; y]` of [`ContactCoordinates`] (contact coordinates first, so
//! [`ContactMap::Leading`]). Per harmonic `D_h = K - (h omega)^2 M + i h omega C`, `D_0 = K`
//! (docs/formulation.md §2).

use super::{HarmonicLayout, HarmonicSystem, HbmOptions, LinearPart};
use crate::contact::Contacts;
use crate::error::{JpError, Result};
use crate::model::{ContactCoordinates, Model};
use faer::Mat;

/// Full-order HBM system of a [`Model`].
#[derive(Clone, Debug)]
pub struct FullSystem {
    coords: ContactCoordinates,
    layout: HarmonicLayout,
}

impl FullSystem {
    /// Builds the system for `opts.harmonics` harmonics.
    ///
    /// # Errors
    /// The model's validation errors; [`JpError::InvalidValue`] for bad options;
    /// [`JpError::SingularMatrix`] when the model has no contact and `K` is singular (the
    /// static problem `K q_0 = f_0` then has no unique solution).
    pub fn new(model: &Model, opts: &HbmOptions) -> Result<Self> {
        opts.validate()?;
        let coords = ContactCoordinates::new(model, opts.harmonics)?;
        if model.contacts.is_empty() {
            crate::linalg::check_nonsingular(&coords.stiffness, "stiffness K of a model without contacts")?;
        }
        let layout = HarmonicLayout::uniform(opts.harmonics, coords.n_dof);
        Ok(FullSystem { coords, layout })
    }

    /// The model in contact coordinates.
    pub fn coordinates(&self) -> &ContactCoordinates {
        &self.coords
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
            d0: c.stiffness.clone(),
            f0: c.static_force.clone(),
            dh_re: Vec::new(),
            dh_im: Vec::new(),
            fh_cos: Vec::new(),
            fh_sin: Vec::new(),
        };
        for h in 1..=self.layout.harmonics {
            let (re, im) = dynamic_stiffness_parts(c, omega, h);
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
