//! The structural model (docs/formulation.md §1): free `M`, `K`, damping (Rayleigh, an added
//! viscous matrix, modal ratios, a structural loss factor), excitation per harmonic, contact
//! elements and output DoFs.

pub mod contact_coordinates;
pub mod modes;

use crate::contact::Contact;
use crate::io::documents::Document;
use crate::error::{JpError, Result};
use crate::limits::{check_magnitude, MAX_DISPLACEMENT_SCALE};
use crate::linalg::{check_symmetric, norm2, serde_mat};
use faer::Mat;
use serde::{Deserialize, Serialize};

pub use contact_coordinates::ContactCoordinates;

/// Proportional damping `C = mass_coeff * M + stiffness_coeff * K`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Damping {
    /// `alpha` in `C = alpha M + beta K`.
    pub mass_coeff: f64,
    /// `beta` in `C = alpha M + beta K`.
    pub stiffness_coeff: f64,
}

impl Damping {
    /// Stiffness-proportional damping giving modal damping ratio `zeta` at angular frequency
    /// `omega` (`beta = 2 zeta / omega`).
    pub fn from_modal_ratio(zeta: f64, omega: f64) -> Self {
        Damping { mass_coeff: 0.0, stiffness_coeff: 2.0 * zeta / omega }
    }
}

/// The cos and sin parts of one harmonic of the excitation: `f(t) = cos * cos(h w t) + sin * sin(h w t)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HarmonicForce {
    pub cos: Vec<f64>,
    pub sin: Vec<f64>,
}

/// Excitation `f_E`: a static part and harmonic parts `h = 1, 2, ...` (missing ones are zero).
/// The dynamic parts are multiplied by `dynamic_scale`, so that the excitation level
/// `alpha = |f_E^0| / |f_E^1|` can be swept without rebuilding anything.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Excitation {
    pub static_force: Vec<f64>,
    pub harmonics: Vec<HarmonicForce>,
    pub dynamic_scale: f64,
}

impl Excitation {
    /// No force on `n` DoFs.
    pub fn zero(n: usize) -> Self {
        Excitation { static_force: vec![0.0; n], harmonics: Vec::new(), dynamic_scale: 1.0 }
    }

    /// Effective cos and sin parts of harmonic `h >= 1` (scaled), zero if not given.
    pub fn harmonic(&self, h: usize, n: usize) -> (Vec<f64>, Vec<f64>) {
        match self.harmonics.get(h.wrapping_sub(1)) {
            Some(hf) if h >= 1 => (
                hf.cos.iter().map(|v| v * self.dynamic_scale).collect(),
                hf.sin.iter().map(|v| v * self.dynamic_scale).collect(),
            ),
            _ => (vec![0.0; n], vec![0.0; n]),
        }
    }

    /// `alpha = |f_E^0| / |f_E^1|` with the current scale (infinite if there is no dynamic force).
    pub fn level(&self) -> f64 {
        let f1 = match self.harmonics.first() {
            Some(hf) => (norm2(&hf.cos).powi(2) + norm2(&hf.sin).powi(2)).sqrt() * self.dynamic_scale.abs(),
            None => 0.0,
        };
        norm2(&self.static_force) / f1
    }

    /// Sets `dynamic_scale` so that `level()` equals `alpha`.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] if `alpha` is not finite and positive, if the static or the
    /// first-harmonic force is zero, or if the resulting scale is not finite and positive
    /// (e.g. `alpha = 1e-320`); the scale is unchanged then.
    pub fn set_level(&mut self, alpha: f64) -> Result<()> {
        if !(alpha.is_finite() && alpha > 0.0) {
            return Err(JpError::invalid("excitation level", format!("must be finite and > 0, got {alpha}")));
        }
        let f1 = match self.harmonics.first() {
            Some(hf) => (norm2(&hf.cos).powi(2) + norm2(&hf.sin).powi(2)).sqrt(),
            None => 0.0,
        };
        let f0 = norm2(&self.static_force);
        if f1 == 0.0 || f0 == 0.0 {
            return Err(JpError::invalid("excitation level", "needs nonzero static and first-harmonic forces"));
        }
        // alpha = 1e-320 (subnormal) would give an infinite scale, a huge alpha a zero one:
        // either would make every later solve fail, so the level is refused instead
        let scale = f0 / (alpha * f1);
        if !(scale.is_finite() && scale > 0.0) {
            return Err(JpError::invalid(
                "excitation level",
                format!("alpha = {alpha:e} gives the dynamic scale |f_E^0| / (alpha |f_E^1|) = {scale:e}, which must be finite and > 0"),
            ));
        }
        self.dynamic_scale = scale;
        Ok(())
    }
}

/// A structural model ready for harmonic balance. Build with [`Model::new`], which validates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Model {
    /// Mass matrix `M` (symmetric, positive diagonal).
    #[serde(with = "serde_mat")]
    pub mass: Mat<f64>,
    /// Stiffness matrix `K` of the free structure (symmetric).
    #[serde(with = "serde_mat")]
    pub stiffness: Mat<f64>,
    /// Proportional (Rayleigh) damping `alpha M + beta K`.
    pub damping: Damping,
    /// Viscous damping added to the Rayleigh part: an FE code's `C` (reduced with the model) or
    /// modal damping ([`Model::set_modal_damping`]). `C = alpha M + beta K + added_damping`.
    #[serde(default, with = "serde_opt_mat", skip_serializing_if = "Option::is_none")]
    pub added_damping: Option<Mat<f64>>,
    /// Structural (hysteretic) loss factor `eta`: the harmonics `h >= 1` see the complex
    /// stiffness `(1 + i eta) K`, independent of frequency (docs/formulation.md §1).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub loss_factor: f64,
    /// Excitation `f_E`.
    pub excitation: Excitation,
    /// Contact elements.
    pub contacts: Vec<Contact>,
    /// DoFs whose response is reported (e.g. the blade's output nodes).
    pub output_dofs: Vec<usize>,
}

pub use crate::linalg::SYMMETRY_TOLERANCE;

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// [`check_magnitude`] on every entry of `m`, naming the first offending `(i, j)`.
fn matrix_magnitude(what: &str, m: &Mat<f64>) -> Result<()> {
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            check_magnitude(what, &[m[(i, j)]]).map_err(|_| {
                JpError::invalid(what, format!("entry ({i}, {j}) is {:e}, beyond jprom's magnitude limit of {:e}", m[(i, j)], crate::limits::MAX_MAGNITUDE))
            })?;
        }
    }
    Ok(())
}

/// Serde adapter for `Option<Mat<f64>>` (absent = `None`).
mod serde_opt_mat {
    use super::serde_mat;
    use faer::Mat;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    struct Wrap(#[serde(with = "serde_mat")] Mat<f64>);

    pub fn serialize<S: Serializer>(m: &Option<Mat<f64>>, s: S) -> std::result::Result<S::Ok, S::Error> {
        m.as_ref().map(|m| Wrap(m.clone())).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<Mat<f64>>, D::Error> {
        Ok(Option::<Wrap>::deserialize(d)?.map(|w| w.0))
    }
}

impl Model {
    /// Builds and validates a model. See [`Model::validate`] for the checks.
    pub fn new(
        mass: Mat<f64>,
        stiffness: Mat<f64>,
        damping: Damping,
        excitation: Excitation,
        contacts: Vec<Contact>,
        output_dofs: Vec<usize>,
    ) -> Result<Self> {
        let m = Model { mass, stiffness, damping, added_damping: None, loss_factor: 0.0, excitation, contacts, output_dofs };
        m.validate()?;
        Ok(m)
    }

    /// Number of DoFs.
    pub fn n_dof(&self) -> usize {
        self.stiffness.nrows()
    }

    /// Checks sizes, symmetry (to [`SYMMETRY_TOLERANCE`]), finite values, positive masses,
    /// contact parameters and DoF indices, and the contact topology the relative contact
    /// coordinates need ([`contact_coordinates::ContactGroups::new`]): a DoF is the `a` DoF of
    /// several contacts only when they have the same kinematics (same `dofs_a`, `dofs_b`,
    /// frame; they then act in parallel), and chains (a `b` DoF that is another contact's `a`
    /// DoF) have no cycle.
    ///
    /// # Errors
    /// [`JpError::BadSize`] or [`JpError::InvalidValue`] naming the offending item.
    pub fn validate(&self) -> Result<()> {
        let n = self.stiffness.nrows();
        if n == 0 {
            return Err(JpError::invalid("stiffness", "model has no DoF"));
        }
        if self.mass.nrows() != n || self.mass.ncols() != n {
            return Err(JpError::bad_size("mass (rows x cols)", n * n, self.mass.nrows() * self.mass.ncols()));
        }
        check_symmetric("stiffness", &self.stiffness, SYMMETRY_TOLERANCE)?;
        check_symmetric("mass", &self.mass, SYMMETRY_TOLERANCE)?;
        matrix_magnitude("stiffness", &self.stiffness)?;
        matrix_magnitude("mass", &self.mass)?;
        for i in 0..n {
            if !(self.mass[(i, i)] > 0.0) {
                return Err(JpError::invalid("mass", format!("diagonal entry {i} is not positive ({})", self.mass[(i, i)])));
            }
        }
        let d = self.damping;
        check_magnitude("damping", &[d.mass_coeff, d.stiffness_coeff])?;
        if d.mass_coeff < 0.0 || d.stiffness_coeff < 0.0 {
            return Err(JpError::invalid("damping", "coefficients must be >= 0"));
        }
        if let Some(c) = &self.added_damping {
            if c.nrows() != n || c.ncols() != n {
                return Err(JpError::bad_size("added damping matrix (rows x cols)", n * n, c.nrows() * c.ncols()));
            }
            check_symmetric("added damping matrix", c, SYMMETRY_TOLERANCE)?;
            matrix_magnitude("added damping matrix", c)?;
        }
        if !(self.loss_factor.is_finite() && self.loss_factor >= 0.0) {
            return Err(JpError::invalid("loss factor", format!("must be finite and >= 0, got {}", self.loss_factor)));
        }
        let e = &self.excitation;
        if e.static_force.len() != n {
            return Err(JpError::bad_size("excitation.static_force", n, e.static_force.len()));
        }
        check_magnitude("excitation.static_force", &e.static_force)?;
        check_magnitude("excitation.dynamic_scale", &[e.dynamic_scale])?;
        for (i, hf) in e.harmonics.iter().enumerate() {
            let what = format!("excitation.harmonics[{i}]");
            if hf.cos.len() != n {
                return Err(JpError::bad_size(format!("{what}.cos"), n, hf.cos.len()));
            }
            if hf.sin.len() != n {
                return Err(JpError::bad_size(format!("{what}.sin"), n, hf.sin.len()));
            }
            // the force acts scaled: the scaled values are the ones bounded
            let scaled: Vec<f64> = hf.cos.iter().chain(&hf.sin).map(|v| v * e.dynamic_scale).collect();
            check_magnitude(&format!("{what} (cos then sin, times the dynamic scale {:e})", e.dynamic_scale), &scaled)?;
        }
        self.check_displacement_scale()?;
        self.validate_contacts()?;
        for &o in &self.output_dofs {
            if o >= n {
                return Err(JpError::invalid("output_dofs", format!("DoF {o} >= model size {n}")));
            }
        }
        Ok(())
    }

    /// The load's static displacement scale `|f|_inf / max_i K_ii` at most
    /// [`MAX_DISPLACEMENT_SCALE`] (no bound without a positive diagonal stiffness).
    fn check_displacement_scale(&self) -> Result<()> {
        let k = (0..self.n_dof()).map(|i| self.stiffness[(i, i)]).fold(0.0f64, f64::max);
        if !(k > 0.0) {
            return Ok(());
        }
        let e = &self.excitation;
        let harmonic = e.harmonics.iter().flat_map(|h| h.cos.iter().chain(&h.sin)).fold(0.0f64, |a, v| a.max(v.abs())) * e.dynamic_scale.abs();
        let f = e.static_force.iter().fold(harmonic, |a, v| a.max(v.abs()));
        if f / k > MAX_DISPLACEMENT_SCALE {
            return Err(JpError::invalid(
                "excitation",
                format!(
                    "the largest force {f:e} over the largest diagonal stiffness {k:e} is a displacement scale of {:e}, beyond jprom's limit of {MAX_DISPLACEMENT_SCALE:e}",
                    f / k
                ),
            ));
        }
        Ok(())
    }

    /// The contact part of [`Model::validate`]: each contact's DoFs, frame and law, and how
    /// contacts share DoFs (same kinematics only, chains without a cycle). Cost `O(contacts +
    /// n)`, so adding contacts one by one to a valid model need not re-check the matrices.
    ///
    /// # Errors
    /// As [`Model::validate`], for the contacts.
    pub fn validate_contacts(&self) -> Result<()> {
        for i in 0..self.contacts.len() {
            self.validate_contact(i)?;
        }
        // Shared 'a' DoFs (same kinematics only) and chains (no cycle).
        contact_coordinates::ContactGroups::new(&self.contacts, self.n_dof())?;
        Ok(())
    }

    /// Checks contact `i` on its own (law, DoFs in range, no DoF repeated within a node), in
    /// `O(1)`: what an incremental addition checks. How contacts combine (shared 'a' DoFs,
    /// chains) is checked by [`Model::validate_contacts`], once, when a system is built.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the contact and the field.
    pub fn validate_contact(&self, i: usize) -> Result<()> {
        let n = self.n_dof();
        let c = self.contacts.get(i).ok_or_else(|| JpError::invalid("contact index", format!("{i} >= {} contacts", self.contacts.len())))?;
        c.validate(i, n)?;
        for (k, &dof) in c.dofs_a.iter().enumerate() {
            if c.dofs_a[..k].contains(&dof) {
                return Err(JpError::invalid(
                    format!("contact[{i}].dofs_a"),
                    format!("DoF {dof} is repeated within the node ({:?}): a node's x, y, z DoFs must differ", c.dofs_a),
                ));
            }
        }
        let b = c.dofs_b.as_deref().unwrap_or(&[]);
        if let Some(k) = (1..b.len()).find(|&k| b[..k].contains(&b[k])) {
            return Err(JpError::invalid(
                format!("contact[{i}].dofs_b"),
                format!("DoF {} is repeated within the node ({b:?}): a node's x, y, z DoFs must differ", b[k]),
            ));
        }
        Ok(())
    }

    /// Viscous damping matrix `C = alpha M + beta K + added_damping`.
    pub fn damping_matrix(&self) -> Mat<f64> {
        let (a, b) = (self.damping.mass_coeff, self.damping.stiffness_coeff);
        let c = Mat::from_fn(self.n_dof(), self.n_dof(), |i, j| a * self.mass[(i, j)] + b * self.stiffness[(i, j)]);
        match &self.added_damping {
            Some(extra) => c + extra,
            None => c,
        }
    }

    /// Sets the added viscous damping to modal damping on the model's own modes (free `K`, `M`,
    /// no contact springs): `C_modal = M Phi diag(2 zeta_r omega_r) Phi^T M` with mass-normalised
    /// `Phi`, so that mode `r` alone has damping ratio `zeta_r`. `ratios[r]` is the ratio of the
    /// `r`-th mode counted from the lowest (rigid-body modes included; they get no damping since
    /// `omega_r = 0`), `others` the ratio of every mode after the list. Replaces any added matrix
    /// ([`Model::add_modal_damping`] adds to it); keep `alpha`, `beta` at 0 for pure modal
    /// damping.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] for a ratio that is not finite and `>= 0`; the eigensolver's
    /// errors (a mass matrix that is not positive definite). The model is unchanged on error.
    pub fn set_modal_damping(&mut self, ratios: &[f64], others: f64) -> Result<()> {
        let c = self.modal_damping_matrix(ratios, others)?;
        self.added_damping = Some(c);
        Ok(())
    }

    /// As [`Model::set_modal_damping`], but adds `C_modal` to the added damping already there
    /// (for example an FE code's reduced `C`).
    ///
    /// # Errors
    /// As [`Model::set_modal_damping`]; the model is unchanged on error.
    pub fn add_modal_damping(&mut self, ratios: &[f64], others: f64) -> Result<()> {
        let c = self.modal_damping_matrix(ratios, others)?;
        match self.added_damping.as_mut() {
            Some(a) if a.nrows() == c.nrows() && a.ncols() == c.ncols() => *a += &c,
            Some(a) => return Err(JpError::bad_size("added damping matrix (rows x cols)", c.nrows() * c.ncols(), a.nrows() * a.ncols())),
            None => self.added_damping = Some(c),
        }
        Ok(())
    }

    /// `C_modal = M Phi diag(2 zeta_r omega_r) Phi^T M` on the free modes (see
    /// [`Model::set_modal_damping`]), symmetrised.
    fn modal_damping_matrix(&self, ratios: &[f64], others: f64) -> Result<Mat<f64>> {
        for (r, &z) in ratios.iter().enumerate() {
            if !(z.is_finite() && z >= 0.0) {
                return Err(JpError::invalid(format!("modal damping ratio {r}"), format!("must be finite and >= 0, got {z}")));
            }
        }
        if !(others.is_finite() && others >= 0.0) {
            return Err(JpError::invalid("modal damping ratio of the other modes", format!("must be finite and >= 0, got {others}")));
        }
        let (lambda, phi) = crate::linalg::eigen::dense_generalized_modes(&self.stiffness, &self.mass)?;
        let n = self.n_dof();
        // M Phi diag(2 zeta omega) (M Phi)^T
        let m_phi = &self.mass * &phi;
        let scaled = Mat::from_fn(n, n, |i, r| {
            let omega = lambda[r].max(0.0).sqrt();
            let zeta = ratios.get(r).copied().unwrap_or(others);
            m_phi[(i, r)] * 2.0 * zeta * omega
        });
        let c = &scaled * m_phi.transpose();
        Ok(Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)])))
    }

    /// Saves as JSON (serde; the format is versioned by [`crate::io::FORMAT_VERSION`]).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the contact if one has an external (callback) law,
    /// before any file is created; [`JpError::Io`] if the file cannot be written.
    pub fn save_json(&self, path: &std::path::Path) -> Result<()> {
        let external = |c: &crate::contact::Contact| c.law.members().iter().any(|l| matches!(l, crate::contact::ContactLaw::External(_)));
        if let Some(k) = self.contacts.iter().position(external) {
            return Err(JpError::invalid(
                format!("model.contacts[{k}]"),
                "an External (callback) contact law is a function and cannot be saved; save the model without it and add it again after loading",
            ));
        }
        crate::io::save_json("model", self, path)
    }

    /// Loads from JSON (kind checked first, unknown keys refused) and validates.
    pub fn load_json(path: &std::path::Path) -> Result<Self> {
        crate::io::load_document(path)
    }
}

impl Document for Model {
    const KIND: &'static str = "model";
    fn check(&self) -> Result<crate::io::documents::Check> {
        self.validate()?;
        Ok(Ok(()))
    }
}
