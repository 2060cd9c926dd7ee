//! Jacobian Projection from C: predicting a `jprom_basis` (method.md §7-8), sweeping the FR or
//! NLR reduced model (§9) with the error predictor `e*` (§10) at every point.

use super::guard::{check_capacity, ffi_guard, finite_arg, out_arg, path_arg, slice_out};
use super::handle::{self, Handle};
use super::model::jprom_model;
use super::solve::{cancelled_status, hbm_options, jprom_hbm_options, jprom_progress_fn, jprom_sweep_options, jprom_sweep_result, progress_adapter, sweep_options};
use super::status::jprom_status::{self, *};
use super::status::FfiError;
use crate::aft::AftPlan;
use crate::condensation::CondensedSystem;
use crate::error_metric::predicted_error;
use crate::hbm::{self, SweepEnd};
use crate::jp::{predict_basis, JpBasis, PredictionOptions};
use crate::model::ContactCoordinates;
use crate::rom::{FrRom, NlrRom, ReducedModel};
use std::ffi::{c_char, c_int, c_void};

/// A JP basis `Φ_h`, `h = 0..H`. Released with `jprom_basis_free`.
#[allow(non_camel_case_types)]
pub struct jprom_basis {
    magic: u64,
    basis: JpBasis,
}

impl Handle for jprom_basis {
    const MAGIC: u64 = 0x4A50_524F_4D42_4153; // "JPROMBAS"
    const KIND: &'static str = "jprom_basis";
    fn magic_mut(&mut self) -> &mut u64 {
        &mut self.magic
    }
    fn magic(&self) -> u64 {
        self.magic
    }
}

/// Full-DoF reduced model (FR): `q_h = Φ_h p_h` on all DoFs.
pub const JPROM_ROM_FR: c_int = 0;
/// Nonlinear-DoF reduced model (NLR) on the condensed system.
pub const JPROM_ROM_NLR: c_int = 1;

/// Predicts a JP basis for `model` without any full-order solution: boundary conditions
/// sampled along the stuck mode nearest the band `[omega_lo, omega_hi]` (rad/s) at
/// `n_samples` amplitudes, JP modes of each distinct contact-state pattern, SVD conditioning
/// with ratio `gamma` (typically 1e2 to 1e4). `options->harmonics` and `nt` set `H` and the
/// AFT samples.
#[no_mangle]
pub unsafe extern "C" fn jprom_basis_predict(
    model: *const jprom_model,
    options: *const jprom_hbm_options,
    omega_lo: f64,
    omega_hi: f64,
    gamma: f64,
    n_samples: usize,
    out: *mut *mut jprom_basis,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let o = options.as_ref().ok_or_else(|| FfiError::null("options"))?;
        let out = out_arg(out, "out")?;
        let hopts = hbm_options(o)?;
        let band = (finite_arg("omega_lo", omega_lo)?, finite_arg("omega_hi", omega_hi)?);
        let coords = ContactCoordinates::new(&m.model, hopts.harmonics)?;
        let mut p = PredictionOptions::new(band);
        p.harmonics = hopts.harmonics;
        p.nt = hopts.nt;
        p.gamma = finite_arg("gamma", gamma)?;
        p.n_samples = n_samples;
        let (basis, _) = predict_basis(&coords, &p)?;
        *out = handle::into_raw(jprom_basis { magic: jprom_basis::MAGIC, basis });
        Ok(())
    })
}

/// Releases a basis (NULL is a no-op).
#[no_mangle]
pub unsafe extern "C" fn jprom_basis_free(basis: *mut jprom_basis) -> jprom_status {
    ffi_guard!({ handle::free(basis, "basis") })
}

/// Basis sizes `n_h`, `h = 0..H` (`H + 1` values) into `buf` of capacity `len`; `*harmonics`
/// (may be NULL) receives `H`.
#[no_mangle]
pub unsafe extern "C" fn jprom_basis_sizes(basis: *const jprom_basis, buf: *mut usize, len: usize, harmonics: *mut usize) -> jprom_status {
    ffi_guard!({
        let b = &handle::get(basis, "basis")?.basis;
        if let Some(h) = harmonics.as_mut() {
            *h = b.harmonics();
        }
        check_capacity("buf", b.sizes.len(), len)?;
        slice_out(buf, b.sizes.len(), "buf")?.copy_from_slice(&b.sizes);
        Ok(())
    })
}

/// Saves a basis as versioned JSON.
#[no_mangle]
pub unsafe extern "C" fn jprom_basis_save_json(basis: *const jprom_basis, path: *const c_char) -> jprom_status {
    ffi_guard!({
        handle::get(basis, "basis")?.basis.save_json(&path_arg(path, "path")?)?;
        Ok(())
    })
}

/// Loads a basis saved by `jprom_basis_save_json`.
#[no_mangle]
pub unsafe extern "C" fn jprom_basis_load_json(path: *const c_char, out: *mut *mut jprom_basis) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let basis = JpBasis::load_json(&path_arg(path, "path")?)?;
        *out = handle::into_raw(jprom_basis { magic: jprom_basis::MAGIC, basis });
        Ok(())
    })
}

/// Sweeps the reduced model `kind` (`JPROM_ROM_FR` or `JPROM_ROM_NLR`) of `model` on `basis`,
/// like `jprom_sweep` (same callback and cancellation rules), and evaluates the error
/// predictor `e*_h` at every point (`jprom_sweep_point_predicted_error`; above about 0.05
/// for `h = 1` the basis is poor). Output amplitudes are physical, as for full-order sweeps.
#[no_mangle]
pub unsafe extern "C" fn jprom_rom_sweep(
    model: *const jprom_model,
    basis: *const jprom_basis,
    kind: c_int,
    options: *const jprom_hbm_options,
    sweep_opts: *const jprom_sweep_options,
    callback: jprom_progress_fn,
    user_data: *mut c_void,
    out: *mut *mut jprom_sweep_result,
) -> jprom_status {
    let mut cancelled = false;
    let status = ffi_guard!({
        let m = handle::get(model, "model")?;
        let b = &handle::get(basis, "basis")?.basis;
        let o = options.as_ref().ok_or_else(|| FfiError::null("options"))?;
        let so = sweep_opts.as_ref().ok_or_else(|| FfiError::null("sweep_opts"))?;
        let out = out_arg(out, "out")?;
        let hopts = hbm_options(o)?;
        let sopts = sweep_options(so)?;
        let rom: Box<dyn ReducedModel> = match kind {
            JPROM_ROM_FR => Box::new(FrRom::new(&ContactCoordinates::new(&m.model, hopts.harmonics)?, b)?),
            JPROM_ROM_NLR => Box::new(NlrRom::new(&CondensedSystem::new(&m.model, &hopts)?, b)?),
            other => return Err(FfiError::new(JPROM_INVALID_VALUE, format!("kind must be JPROM_ROM_FR (0) or JPROM_ROM_NLR (1), got {other}"))),
        };
        let mut on_point = progress_adapter(callback, user_data);
        let result = hbm::sweep(rom.as_ref(), &sopts, &hopts, &mut on_point)?;
        let plan = AftPlan::new(hopts.harmonics, hopts.nt())?;
        let errors = result.points.iter().map(|p| predicted_error(rom.as_ref(), &plan, p.omega, &p.z)).collect::<crate::Result<Vec<_>>>()?;
        cancelled = result.end == SweepEnd::StoppedByCaller;
        *out = jprom_sweep_result::wrap(result, errors);
        Ok(())
    });
    cancelled_status(status, cancelled)
}

/// Predicted error `e*_h` of point `index` of a reduced sweep (`JPROM_INVALID_VALUE` for a
/// full-order sweep, which has none).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_point_predicted_error(sweep: *const jprom_sweep_result, index: usize, h: usize, out: *mut f64) -> jprom_status {
    ffi_guard!({
        let s = handle::get(sweep, "sweep")?;
        let e = s
            .predicted_errors
            .get(index)
            .ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, format!("no predicted error for point {index} (full-order sweep, or index >= {})", s.predicted_errors.len())))?;
        *out_arg(out, "out")? = *e.get(h).ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, format!("harmonic {h} > H = {}", e.len().saturating_sub(1))))?;
        Ok(())
    })
}
