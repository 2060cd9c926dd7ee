//! User-defined memoryless contact law (docs/formulation.md §4.6): a callable that gives the
//! force `F(w)` and the Jacobian `dF/dw` at one time sample, for host codes with their own
//! contact laws (the C API's `jprom_model_add_element_callback`).
//!
//! * **Memoryless**: `F(t_j)` depends on `w(t_j)` only. The AFT then needs no chain through the
//!   samples: `F_h = DFT f(w(t_j))` and `dF_h/dw_h = DFT diag(dF/dw(t_j)) IDFT`
//!   ([`crate::aft::AftPlan::contact`]). A law with memory (hysteresis, friction) needs
//!   `dF(t_j)/dw(t_k)` for `k < j` and cannot be expressed by this element.
//! * **Errors**: an `Err` from the callable, a panic inside it (caught), or a non-finite force
//!   or Jacobian entry ends the evaluation with [`crate::error::JpError::Callback`] naming the
//!   element, the time sample and the reason; the AFT's outputs are then NaN, never a
//!   plausible number.
//! * **Threads**: the callable may be called from several threads at once (the AFT runs over
//!   contacts in parallel, the JP prediction over frequencies), so it must be `Send + Sync`
//!   and, for a C callback, thread-safe.
//! * **Stuck stiffness**: the Jacobian at `w = 0`, evaluated once by [`ExternalLaw::new`] (the
//!   callable is called there, so a law that fails at `w = 0` is refused when it is made).
//! * Not serialisable: saving a model holding one is an error (there is no way to write a
//!   function into a file).

use crate::error::{JpError, Result};
use std::fmt;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Arc;

/// The callable of an [`ExternalLaw`]: `(w, force, jacobian)` with `w` and `force` of length
/// `d` and `jacobian` `d x d` column-major (`jacobian[r + c d] = dF_r / dw_c`). `force` and
/// `jacobian` are zeroed before each call. `Err(reason)` reports a failure.
pub type ExternalFn = dyn Fn(&[f64], &mut [f64], &mut [f64]) -> std::result::Result<(), String> + Send + Sync;

/// A user-defined memoryless law on `d = 1..=3` local coordinates (see the module doc).
/// `Clone`, `PartialEq` and `Debug` go by the callable's pointer.
#[derive(Clone)]
pub struct ExternalLaw {
    dim: usize,
    label: String,
    f: Arc<ExternalFn>,
    /// `dF/dw` at `w = 0`, `d x d` column-major.
    stuck: Vec<f64>,
}

impl ExternalLaw {
    /// A law on `dim` local coordinates computed by `f`. Calls `f` once at `w = 0` for the
    /// stuck stiffness.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] if `dim` is not 1, 2 or 3; [`JpError::Callback`] if `f` fails
    /// at `w = 0` (error, panic, non-finite output).
    pub fn new(dim: usize, f: Arc<ExternalFn>) -> Result<Self> {
        Self::labelled(dim, String::new(), f)
    }

    /// [`ExternalLaw::new`] with a name for error messages ("element 3"; see
    /// [`ExternalLaw::label`]).
    ///
    /// # Errors
    /// As [`ExternalLaw::new`].
    pub fn labelled(dim: usize, label: impl Into<String>, f: Arc<ExternalFn>) -> Result<Self> {
        if !(1..=3).contains(&dim) {
            return Err(JpError::invalid("external law dim", format!("must be 1, 2 or 3, got {dim}")));
        }
        let mut law = ExternalLaw { dim, label: label.into(), f, stuck: vec![0.0; dim * dim] };
        let mut force = vec![0.0; dim];
        let mut jac = vec![0.0; dim * dim];
        law.eval(&vec![0.0; dim], &mut force, &mut jac)
            .map_err(|reason| JpError::Callback { element: law.name_or_default(), sample: 0, reason: format!("{reason} (evaluating the stuck stiffness at w = 0)") })?;
        law.stuck = jac;
        Ok(law)
    }

    /// Number of local coordinates `d`.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Name used in error messages ("element 3"); empty until
    /// [`crate::model::ContactCoordinates`] names it after its contact index, unless set.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The label, or "external law" without one.
    pub fn name_or_default(&self) -> String {
        if self.label.is_empty() {
            "external law".to_string()
        } else {
            self.label.clone()
        }
    }

    /// The law with the given name for error messages.
    pub fn with_label(mut self, label: impl Into<String>) -> Self {
        self.label = label.into();
        self
    }

    /// `dF/dw` at `w = 0`, `d x d` column-major.
    pub fn stuck_jacobian(&self) -> &[f64] {
        &self.stuck
    }

    /// Calls the callable at `w`: `force` and `jacobian` (zeroed first) receive `F(w)` and
    /// `dF/dw`. A returned error, a panic (caught) or a non-finite output is `Err(reason)`.
    ///
    /// # Panics
    /// If the slices are not of length `d`, `d`, `d^2` (programming error).
    pub fn eval(&self, w: &[f64], force: &mut [f64], jacobian: &mut [f64]) -> std::result::Result<(), String> {
        let d = self.dim;
        assert!(w.len() == d && force.len() == d && jacobian.len() == d * d, "external law slice lengths");
        force.fill(0.0);
        jacobian.fill(0.0);
        match catch_unwind(AssertUnwindSafe(|| (self.f)(w, force, jacobian))) {
            Ok(Ok(())) => {}
            Ok(Err(reason)) => return Err(reason),
            Err(payload) => {
                let what = payload
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown panic payload".to_string());
                return Err(format!("the law panicked ({what})"));
            }
        }
        if let Some(i) = force.iter().position(|v| !v.is_finite()) {
            return Err(format!("non-finite force[{i}] = {}", force[i]));
        }
        if let Some(i) = jacobian.iter().position(|v| !v.is_finite()) {
            return Err(format!("non-finite Jacobian entry dF{}/dw{} = {}", i % d, i / d, jacobian[i]));
        }
        Ok(())
    }
}

impl PartialEq for ExternalLaw {
    fn eq(&self, other: &Self) -> bool {
        self.dim == other.dim && self.label == other.label && Arc::ptr_eq(&self.f, &other.f)
    }
}

impl fmt::Debug for ExternalLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ExternalLaw")
            .field("dim", &self.dim)
            .field("label", &self.label)
            .field("callable", &(Arc::as_ptr(&self.f) as *const () as usize))
            .field("stuck", &self.stuck)
            .finish()
    }
}

impl serde::Serialize for ExternalLaw {
    fn serialize<S: serde::Serializer>(&self, _s: S) -> std::result::Result<S::Ok, S::Error> {
        Err(serde::ser::Error::custom("an External (callback) contact law is a function and cannot be saved"))
    }
}

impl<'de> serde::Deserialize<'de> for ExternalLaw {
    fn deserialize<D: serde::Deserializer<'de>>(_d: D) -> std::result::Result<Self, D::Error> {
        Err(serde::de::Error::custom("an External (callback) contact law cannot be loaded from a file"))
    }
}
