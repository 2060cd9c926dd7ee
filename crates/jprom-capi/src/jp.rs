//! Jacobian Projection from C: predicting a `jprom_basis` (docs/formulation.md §8.7-8.8), sweeping the FR or
//! NLR reduced model (§9) with the error predictor `e*` (§10) at every point.

use super::guard::{check_capacity, ffi_guard, finite_arg, out_arg, path_arg, slice_out};
use super::handle::{self, Handle};
use super::model::jprom_model;
use super::solve::{
    hbm_options, jprom_hbm_options, jprom_progress_fn, jprom_solution, jprom_sweep_options, jprom_sweep_result, progress_adapter,
    sweep_options, Origin,
};
use super::status::jprom_status::{self, *};
use super::status::FfiError;
use super::versioned::{read_options, write_defaults, Versioned};
use jprom::aft::Discretisation;
use jprom::condensation::CondensedSystem;
use jprom::rom::error_metric::actual_error;
use jprom::rom;
use jprom::hbm::PointSolution;
use jprom::jp::{predict_basis, BasisOptions, JpBasis, ModeOptions, PredictionOptions, SlippingSamples};
use jprom::model::ContactCoordinates;
use jprom::rom::{SweepRecord, adaptive_sweep_with_progress, AdaptiveOptions, CorrectionEnd, CorrectionKind, ReducedModel, RomKind};
use std::ffi::{c_char, c_int, c_void};
use std::ops::ControlFlow;

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

/// The kind of reduced model, passed as the `int kind` of `jprom_rom_sweep` and
/// `jprom_rom_sweep_adaptive`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum jprom_rom_kind {
    /// Full-DoF reduced model (FR): `q_h = Φ_h p_h` on all DoFs.
    JPROM_ROM_FR = 0,
    /// Nonlinear-DoF reduced model (NLR) on the condensed system.
    JPROM_ROM_NLR = 1,
}

/// Predicts a JP basis for `model` without any full-order solution: boundary conditions
/// sampled along the stuck mode nearest the band between `omega_start` and `omega_end` (rad/s,
/// either order, as in `jprom_sweep_options`) at
/// `n_samples` amplitudes, JP modes of each distinct contact-state pattern, SVD conditioning
/// with ratio `gamma` (typically 1e2 to 1e4). `options->harmonics` and `nt` set `H` and the
/// AFT samples. `n_samples` is at most `JPROM_MAX_SAMPLES` (else `JPROM_BAD_SIZE`).
///
/// Deprecated since 0.2 (kept, as every released function): `jprom_basis_predict_opts` takes
/// the same settings in a `jprom_jp_options` that can grow.
#[no_mangle]
#[deprecated(since = "0.2.0", note = "use jprom_basis_predict_opts")]
pub unsafe extern "C" fn jprom_basis_predict(
    model: *const jprom_model,
    options: *const jprom_hbm_options,
    omega_start: f64,
    omega_end: f64,
    gamma: f64,
    n_samples: usize,
    out: *mut *mut jprom_basis,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let (disc, _, _) = hbm_options(options)?;
        let out = out_arg(out, "out")?;
        let band = band_arg(omega_start, omega_end)?;
        let coords = ContactCoordinates::new(&m.model, disc)?;
        let mut p = PredictionOptions::new(band);
        p.gamma = finite_arg("gamma", gamma)?;
        jprom::limits::at_most("n_samples", n_samples, jprom::limits::MAX_SAMPLES)?;
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

/// Loads a basis saved by `jprom_basis_save_json`, checked as a whole (every matrix against
/// `n_dof` and `sizes`; `JPROM_PARSE` naming the key and line otherwise).
#[no_mangle]
pub unsafe extern "C" fn jprom_basis_load_json(path: *const c_char, out: *mut *mut jprom_basis) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let basis: JpBasis = jprom::io::load_document(&path_arg(path, "path")?)?;
        *out = handle::into_raw(jprom_basis { magic: jprom_basis::MAGIC, basis });
        Ok(())
    })
}

/// Sweeps the reduced model `kind` (`JPROM_ROM_FR` or `JPROM_ROM_NLR`) of `model` on `basis`,
/// like `jprom_sweep` (same callback and cancellation rules), and evaluates the error
/// predictor `e*_h` at every point (`jprom_sweep_result_point_predicted_error`; above about 0.05
/// for `h = 1` the basis is poor). Output amplitudes are physical, as for full-order sweeps.
/// A model without contacts: `JPROM_INVALID_VALUE`, "the model has no contact: JP reduces onto
/// the contact coordinates and there are none" (every JP entry point says the same).
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
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let b = &handle::get(basis, "basis")?.basis;
        let (disc, hopts, _) = hbm_options(options)?;
        let sopts = sweep_options(sweep_opts)?;
        let out = out_arg(out, "out")?;
        let rom = build_rom(m, b, rom_kind(kind)?, disc)?;
        let mut on_point = progress_adapter(callback, user_data);
        let (result, errors) = rom::sweep_with_predicted_error(rom.as_ref(), &sopts, &hopts, &mut on_point)?;
        *out = jprom_sweep_result::wrap(SweepRecord::reduced(result, errors), Origin::Reduced);
        Ok(())
    })
}

/// Predicted error `e*_h` of point `index` of a reduced sweep (`JPROM_INVALID_VALUE` for a
/// full-order sweep, which has none).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_point_predicted_error(sweep: *const jprom_sweep_result, index: usize, h: usize, out: *mut f64) -> jprom_status {
    ffi_guard!({
        let s = handle::get(sweep, "sweep")?;
        let e = s
            .record
            .predicted_errors
            .get(index)
            .ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, format!("no predicted error for point {index} (full-order sweep, or index >= {})", s.record.predicted_errors.len())))?;
        *out_arg(out, "out")? = *e.get(h).ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, format!("harmonic {h} > H = {}", e.len().saturating_sub(1))))?;
        Ok(())
    })
}

/// `kind` of the C API as a [`RomKind`].
fn rom_kind(kind: c_int) -> Result<RomKind, FfiError> {
    match kind {
        k if k == jprom_rom_kind::JPROM_ROM_FR as c_int => Ok(RomKind::Fr),
        k if k == jprom_rom_kind::JPROM_ROM_NLR as c_int => Ok(RomKind::Nlr),
        other => Err(FfiError::new(JPROM_INVALID_VALUE, format!("kind must be JPROM_ROM_FR (0) or JPROM_ROM_NLR (1), got {other}"))),
    }
}

fn build_rom(m: &jprom_model, b: &JpBasis, kind: RomKind, disc: Discretisation) -> Result<Box<dyn ReducedModel>, FfiError> {
    let coords = ContactCoordinates::new(&m.model, disc)?;
    // NLR's condensation would refuse it in its own words: JP's are the same at every entry
    jprom::jp::require_contacts("reduced model", coords.n_w)?;
    let condensed = if kind == RomKind::Nlr { Some(CondensedSystem::new(&m.model, disc)?) } else { None };
    Ok(rom::reduced_model(kind, &coords, condensed.as_ref(), b)?)
}

/// Settings of the JP basis and of the self-correcting sweep. Fill with
/// `jprom_jp_options_default`, then change fields. `struct_size` must stay
/// `sizeof(jprom_jp_options)` (lets the struct grow). Used by `jprom_basis_predict_opts`,
/// `jprom_basis_from_solution` (basis fields only) and `jprom_rom_sweep_adaptive` (all).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_camel_case_types)]
pub struct jprom_jp_options {
    pub struct_size: usize,
    /// Conditioning ratio `gamma >= 1` of the SVD (default 1e3; typically 1e2 to 1e4, larger
    /// is bigger and more accurate).
    pub gamma: f64,
    /// Amplitudes sampled along the generating shape by the prediction (default 100, >= 1,
    /// at most `JPROM_MAX_SAMPLES`).
    pub n_samples: usize,
    /// Eigenpairs kept outside the band as well, nearest first (default 2).
    pub extra_outside: usize,
    /// 0 (default, as the prediction): eigenvectors only; 1: add the static-correction vectors
    /// `K_JC^-1 F` to the JP modes. Worth 1 for `jprom_basis_from_solution` (a basis of one
    /// Jacobian); in the prediction every contact state would add its own.
    pub static_correction: c_int,
    /// Self-correcting sweep: the basis is corrected while the worst `e*_1` of the sweep
    /// exceeds this (default 0.05; must be > 0).
    pub threshold: f64,
    /// Most correction steps (default 5; 0 = predict and sweep once). A regeneration is one
    /// step, reported as one or two corrections (the modes alone, then their union). A step
    /// whose candidates were all screened out without a pass counts only towards a limit of
    /// twice `max_corrections` steps in all.
    pub max_corrections: usize,
    /// Factor applied to `gamma` when a regeneration does not halve the worst `e*_1`
    /// (default 10, > 1), up to `max_gamma` (default 1e6, >= `gamma`).
    pub gamma_growth: f64,
    pub max_gamma: f64,
    /// Version 2 (0.3): whether the prediction also samples along the slipping mode, a
    /// `jprom_slipping_samples` (default `JPROM_SLIPPING_NEVER`; `JPROM_SLIPPING_AT_GROSS_SLIP`
    /// is worth it at gross slip, where the stuck mode misses the resonance;
    /// docs/formulation.md §8.8).
    pub slipping: c_int,
    /// Version 3 (0.3, after `slipping`): samples of a correction's prediction along the
    /// reduced solution it regenerates from (default 10, >= 1, at most `JPROM_MAX_SAMPLES`; the
    /// first basis takes `n_samples`). Along a reduced solution nearly every sample is a contact
    /// pattern of its own, so a regeneration with 100 samples costs as much as the first basis
    /// and adds as many modes (docs/formulation.md §8.9).
    pub regeneration_samples: usize,
    /// Version 3: nonzero (default 1) judges each candidate basis first at the points where the bases
    /// before it were judged poor and where its own response peaks, and sweeps it over the
    /// band only if it is within `threshold` there; 0 sweeps every candidate
    /// (docs/formulation.md §10.5).
    pub screen: c_int,
    /// Version 3: nonzero (default 1) judges each pass by the linearised error (one full-order Newton
    /// step from the reduced solution) at its resonance and at the points of largest `e*_1`;
    /// 0 judges it by `e*_1` alone, as the paper (which overstates the error where contacts
    /// stick off resonance; docs/formulation.md §10).
    pub verify: c_int,
    /// Version 3: the output (`0 ..` the model's outputs) whose first-harmonic amplitude
    /// locates a pass' resonance, where its linearised error is checked (default 0).
    pub response_output: usize,
}

/// `struct_size` of version 1 of `jprom_jp_options` (up to `max_gamma`).
pub const JPROM_JP_OPTIONS_V1_SIZE: usize = 72;
/// `struct_size` of version 2 of `jprom_jp_options` (up to `slipping`, padded).
pub const JPROM_JP_OPTIONS_V2_SIZE: usize = 80;
// A released prefix ends where the next version's fields begin (see solve.rs).
const _: () = assert!(std::mem::offset_of!(jprom_jp_options, slipping) == JPROM_JP_OPTIONS_V1_SIZE);
const _: () = assert!(std::mem::offset_of!(jprom_jp_options, regeneration_samples) == JPROM_JP_OPTIONS_V2_SIZE);

/// Where the JP prediction samples the contacts besides the stuck mode: the
/// `slipping` field of `jprom_jp_options` (docs/formulation.md §8.8).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum jprom_slipping_samples {
    /// Along the stuck mode only.
    JPROM_SLIPPING_NEVER = 0,
    /// Also along the slipping mode when the level is gross slip (the stuck mode's largest
    /// sampled amplitude at least 50 times its smallest).
    JPROM_SLIPPING_AT_GROSS_SLIP = 1,
    /// Also along the slipping mode at any level.
    JPROM_SLIPPING_ALWAYS = 2,
}

/// The one mapping between the Rust and the C enum (the parser below inverts it).
impl From<SlippingSamples> for jprom_slipping_samples {
    fn from(s: SlippingSamples) -> Self {
        match s {
            SlippingSamples::Never => jprom_slipping_samples::JPROM_SLIPPING_NEVER,
            SlippingSamples::AtGrossSlip => jprom_slipping_samples::JPROM_SLIPPING_AT_GROSS_SLIP,
            SlippingSamples::Always => jprom_slipping_samples::JPROM_SLIPPING_ALWAYS,
        }
    }
}

fn slipping_samples(v: c_int) -> Result<SlippingSamples, FfiError> {
    [SlippingSamples::Never, SlippingSamples::AtGrossSlip, SlippingSamples::Always]
        .into_iter()
        .find(|&s| jprom_slipping_samples::from(s) as c_int == v)
        .ok_or_else(|| {
            FfiError::new(
                JPROM_INVALID_VALUE,
                format!("jprom_jp_options.slipping is {v}, not a jprom_slipping_samples (JPROM_SLIPPING_NEVER 0, JPROM_SLIPPING_AT_GROSS_SLIP 1, JPROM_SLIPPING_ALWAYS 2)"),
            )
        })
}

impl Versioned for jprom_jp_options {
    const NAME: &'static str = "jprom_jp_options";
    const SIZES: &'static [usize] = &[JPROM_JP_OPTIONS_V1_SIZE, JPROM_JP_OPTIONS_V2_SIZE, std::mem::size_of::<jprom_jp_options>()];
    fn defaults() -> Self {
        let p = PredictionOptions::new((0.0, 0.0));
        let a = AdaptiveOptions::default();
        jprom_jp_options {
            struct_size: std::mem::size_of::<jprom_jp_options>(),
            gamma: p.gamma,
            n_samples: p.n_samples,
            extra_outside: p.modes.extra_outside,
            static_correction: p.modes.static_correction as c_int,
            threshold: a.threshold,
            max_corrections: a.max_corrections,
            gamma_growth: a.gamma_growth,
            max_gamma: a.max_gamma,
            slipping: jprom_slipping_samples::from(p.slipping) as c_int,
            regeneration_samples: a.regeneration_samples,
            screen: a.screen as c_int,
            verify: a.verify as c_int,
            response_output: a.response_output,
        }
    }
}

/// Writes the defaults of version 1 of `jprom_jp_options` (up to `max_gamma`) into `*out`. In `jprom.h` this name
/// is a macro for `jprom_jp_options_init(out, sizeof *out)`.
#[no_mangle]
pub unsafe extern "C" fn jprom_jp_options_default(out: *mut jprom_jp_options) -> jprom_status {
    ffi_guard!({ write_defaults(out, JPROM_JP_OPTIONS_V1_SIZE) })
}

/// Writes the defaults into the `struct_size` bytes of `*out` (pass `sizeof *out`; a released
/// size, else `JPROM_BAD_SIZE`) and sets its `struct_size`.
#[no_mangle]
pub unsafe extern "C" fn jprom_jp_options_init(out: *mut jprom_jp_options, struct_size: usize) -> jprom_status {
    ffi_guard!({ write_defaults(out, struct_size) })
}

/// A checked `jp_options` argument: its values, and its enum fields parsed, so that no field is
/// read unchecked.
struct JpOptions {
    c: jprom_jp_options,
    slipping: SlippingSamples,
}

impl JpOptions {
    fn modes(&self, band: (f64, f64)) -> ModeOptions {
        let mut m = ModeOptions::in_band(band);
        m.extra_outside = self.c.extra_outside;
        m.static_correction = self.c.static_correction != 0;
        m
    }

    fn prediction(&self, band: (f64, f64)) -> PredictionOptions {
        let mut p = PredictionOptions::new(band);
        p.gamma = self.c.gamma;
        p.n_samples = self.c.n_samples;
        p.modes = self.modes(band);
        p.slipping = self.slipping;
        p
    }

    fn adaptive(&self, kind: RomKind) -> AdaptiveOptions {
        AdaptiveOptions {
            kind,
            threshold: self.c.threshold,
            max_corrections: self.c.max_corrections,
            gamma_growth: self.c.gamma_growth,
            max_gamma: self.c.max_gamma,
            verify: self.c.verify != 0,
            response_output: self.c.response_output,
            regeneration_samples: self.c.regeneration_samples,
            screen: self.c.screen != 0,
        }
    }
}

/// The `jp_options` argument: any released version, with finite and consistent values.
unsafe fn jp_options_arg(p: *const jprom_jp_options) -> Result<JpOptions, FfiError> {
    let o = read_options(p, "jp_options")?;
    finite_arg("gamma", o.gamma)?;
    finite_arg("threshold", o.threshold)?;
    finite_arg("gamma_growth", o.gamma_growth)?;
    finite_arg("max_gamma", o.max_gamma)?;
    jprom::limits::at_most("jprom_jp_options.n_samples", o.n_samples, jprom::limits::MAX_SAMPLES)?;
    jprom::limits::at_most("jprom_jp_options.regeneration_samples", o.regeneration_samples, jprom::limits::MAX_SAMPLES)?;
    if o.regeneration_samples == 0 {
        return Err(FfiError::new(JPROM_INVALID_VALUE, "jprom_jp_options.regeneration_samples is 0; it must be >= 1 (default 10)"));
    }
    if o.max_gamma < o.gamma {
        return Err(FfiError::new(JPROM_INVALID_VALUE, format!("max_gamma ({}) < gamma ({})", o.max_gamma, o.gamma)));
    }
    let slipping = slipping_samples(o.slipping)?;
    Ok(JpOptions { c: o, slipping })
}

/// The band between `omega_start` and `omega_end`, in either order (as a sweep's
/// `jprom_sweep_options`), as `(lo, hi)`.
fn band_arg(omega_start: f64, omega_end: f64) -> Result<(f64, f64), FfiError> {
    let (a, b) = (finite_arg("omega_start", omega_start)?, finite_arg("omega_end", omega_end)?);
    Ok((a.min(b), a.max(b)))
}

/// `jprom_basis_predict` with every basis setting of `jp_options` (`gamma`, `n_samples`,
/// `extra_outside`, `static_correction`; the sweep fields are ignored). `*out` is written only
/// on success; free it with `jprom_basis_free`.
/// A model without contacts: `JPROM_INVALID_VALUE`, "the model has no contact: JP reduces onto
/// the contact coordinates and there are none" (every JP entry point says the same).
#[no_mangle]
pub unsafe extern "C" fn jprom_basis_predict_opts(
    model: *const jprom_model,
    options: *const jprom_hbm_options,
    jp_options: *const jprom_jp_options,
    omega_start: f64,
    omega_end: f64,
    out: *mut *mut jprom_basis,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let (disc, _, _) = hbm_options(options)?;
        let jo = jp_options_arg(jp_options)?;
        let out = out_arg(out, "out")?;
        let band = band_arg(omega_start, omega_end)?;
        let coords = ContactCoordinates::new(&m.model, disc)?;
        let (basis, _) = predict_basis(&coords, &jo.prediction(band))?;
        *out = handle::into_raw(jprom_basis { magic: jprom_basis::MAGIC, basis });
        Ok(())
    })
}

/// The basis of a full-order solution's own boundary conditions (docs/formulation.md §8): the contact
/// stiffness at `solution` (from `jprom_solve_point`, or a point of `jprom_sweep`, condensed
/// or not), its JP modes in the band between `omega_start` and `omega_end` (rad/s, either order;
/// plus `jp_options->extra_outside` nearest
/// ones) and SVD conditioning with `jp_options->gamma`. With every mode kept it reproduces the
/// solution. `options->harmonics` must be the solution's `H`; `options->nt` sets the AFT
/// samples. `JPROM_INVALID_VALUE` for a reduced solution (a point of a ROM sweep). `*out` is
/// written only on success; free it with `jprom_basis_free`. The solution stays the caller's.
/// A model without contacts: `JPROM_INVALID_VALUE`, as `jprom_basis_predict_opts`.
#[no_mangle]
pub unsafe extern "C" fn jprom_basis_from_solution(
    model: *const jprom_model,
    solution: *const jprom_solution,
    options: *const jprom_hbm_options,
    jp_options: *const jprom_jp_options,
    omega_start: f64,
    omega_end: f64,
    out: *mut *mut jprom_basis,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let sol = handle::get(solution, "solution")?;
        let (disc, _, _) = hbm_options(options)?;
        let jo = jp_options_arg(jp_options)?;
        let out = out_arg(out, "out")?;
        if sol.origin == Origin::Reduced {
            return Err(FfiError::new(JPROM_INVALID_VALUE, "'solution' is a reduced solution (a point of a ROM sweep); a full-order one is needed"));
        }
        let band = band_arg(omega_start, omega_end)?;
        let coords = ContactCoordinates::new(&m.model, disc)?;
        let bopts = BasisOptions { modes: jo.modes(band), gamma: jo.c.gamma };
        let basis = JpBasis::from_solution(&coords, &sol.point, &bopts)?;
        *out = handle::into_raw(jprom_basis { magic: jprom_basis::MAGIC, basis });
        Ok(())
    })
}

/// The self-correcting reduced sweep, jprom's default JP workflow (docs/formulation.md): predicts
/// a basis for the band `[sweep_opts->omega_start, omega_end]` along the stuck mode, sweeps the
/// reduced model `kind` (`JPROM_ROM_FR` or `JPROM_ROM_NLR`) with `e*_h` at every point, and
/// while the worst `e*_1` exceeds `jp_options->threshold` (at most `max_corrections` steps)
/// regenerates modes from the worst reduced point and sweeps with them alone, then, if that is
/// not within the threshold, with their union with the basis (or unites the basis with modes
/// predicted with a larger `gamma`). Read the corrections with `jprom_sweep_result_n_corrections` /
/// `jprom_sweep_result_correction`, `e*` with `jprom_sweep_result_point_predicted_error`.
///
/// `callback` (may be NULL) is called after each converged point of each reduced sweep;
/// `point_index` restarts at 0 when a correction starts a new sweep. If it returns nonzero,
/// that sweep stops, no further correction is made, and the call returns `JPROM_OK` with the
/// sweep so far (end reason `JPROM_SWEEP_CANCELLED`) and the basis, as `jprom_sweep`.
///
/// On success `*out` receives the final sweep (free it with `jprom_sweep_result_free`) and, if
/// `basis_out` is not NULL, `*basis_out` the final basis (free it with `jprom_basis_free`).
/// On failure neither is written.
/// A model without contacts: `JPROM_INVALID_VALUE`, "the model has no contact: JP reduces onto
/// the contact coordinates and there are none" (every JP entry point says the same).
#[no_mangle]
pub unsafe extern "C" fn jprom_rom_sweep_adaptive(
    model: *const jprom_model,
    kind: c_int,
    options: *const jprom_hbm_options,
    sweep_opts: *const jprom_sweep_options,
    jp_options: *const jprom_jp_options,
    callback: jprom_progress_fn,
    user_data: *mut c_void,
    out: *mut *mut jprom_sweep_result,
    basis_out: *mut *mut jprom_basis,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let (disc, hopts, _) = hbm_options(options)?;
        let sopts = sweep_options(sweep_opts)?;
        let jo = jp_options_arg(jp_options)?;
        let out = out_arg(out, "out")?;
        let kind = rom_kind(kind)?;
        // the JP band is the band swept, whichever way it is swept
        let pred = jo.prediction((sopts.omega_start.min(sopts.omega_end), sopts.omega_start.max(sopts.omega_end)));
        let aopts = jo.adaptive(kind);
        // one progress counter per reduced sweep
        let mut pass_now = 0;
        let mut adapter = progress_adapter(callback, user_data);
        let mut on_point = |pass: usize, p: &PointSolution| -> ControlFlow<()> {
            if pass != pass_now {
                pass_now = pass;
                adapter = progress_adapter(callback, user_data);
            }
            adapter(p)
        };
        let a = adaptive_sweep_with_progress(&m.model, disc, &pred, &sopts, &hopts, &aopts, &mut on_point)?;
        let (record, basis) = SweepRecord::with_basis(a);
        *out = jprom_sweep_result::wrap(record, Origin::Reduced);
        if let Some(b) = basis_out.as_mut() {
            *b = handle::into_raw(jprom_basis { magic: jprom_basis::MAGIC, basis });
        }
        Ok(())
    })
}

/// The kind of a correction of `jprom_rom_sweep_adaptive`, written to the `int kind` of
/// `jprom_sweep_result_correction`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum jprom_correction_kind {
    /// Modes regenerated from the reduced solution at the point of worst `e*_1` (the value is
    /// that point's omega, rad/s).
    JPROM_CORRECTION_REGENERATED = 0,
    /// Modes predicted with a larger `gamma` (the value is the new gamma).
    JPROM_CORRECTION_GAMMA_INCREASED = 1,
    /// Modes regenerated from the reduced solution at the point of worst `e*_1`, swept alone in
    /// place of the basis (the value is that point's omega, rad/s). Within the threshold they
    /// are the basis; otherwise a `JPROM_CORRECTION_REGENERATED` (their union with the basis)
    /// follows, and the better of the two is kept. Since 0.3.
    JPROM_CORRECTION_REPLACED = 2,
}

impl jprom_correction_kind {
    /// The C kind of a correction and its value (the omega regenerated from, or the new gamma).
    fn of(kind: &CorrectionKind) -> (Self, f64) {
        match *kind {
            CorrectionKind::Regenerated { from_omega } => (Self::JPROM_CORRECTION_REGENERATED, from_omega),
            CorrectionKind::GammaIncreased { gamma } => (Self::JPROM_CORRECTION_GAMMA_INCREASED, gamma),
            CorrectionKind::Replaced { from_omega } => (Self::JPROM_CORRECTION_REPLACED, from_omega),
        }
    }
}

/// A short name for a `jprom_correction_kind` value ("regenerated", "gamma_increased",
/// "replaced"; "unknown" for any other value), for logs. Static storage: do not free. Since 0.3.
#[no_mangle]
pub extern "C" fn jprom_correction_kind_name(kind: c_int) -> *const c_char {
    crate::guard::enum_name(kind, &[c"regenerated", c"gamma_increased", c"replaced"])
}

/// Why the corrections of `jprom_rom_sweep_adaptive` ended, from
/// `jprom_sweep_result_correction_end`. Since 0.3.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum jprom_correction_end {
    /// The judged error of the final pass is within `jprom_jp_options.threshold`.
    JPROM_CORRECTIONS_WITHIN_THRESHOLD = 0,
    /// `max_corrections` steps were made; the basis stayed above the threshold.
    JPROM_CORRECTIONS_MAX_CORRECTIONS = 1,
    /// No correction was left to try (a regeneration did not improve the basis and `gamma` is
    /// at `max_gamma`); the basis stayed above the threshold.
    JPROM_CORRECTIONS_NO_PROGRESS = 2,
    /// The progress callback stopped a pass (nonzero return).
    JPROM_CORRECTIONS_CANCELLED = 3,
}

impl From<CorrectionEnd> for jprom_correction_end {
    fn from(e: CorrectionEnd) -> Self {
        match e {
            CorrectionEnd::WithinThreshold => Self::JPROM_CORRECTIONS_WITHIN_THRESHOLD,
            CorrectionEnd::MaxCorrections => Self::JPROM_CORRECTIONS_MAX_CORRECTIONS,
            CorrectionEnd::NoProgress => Self::JPROM_CORRECTIONS_NO_PROGRESS,
            CorrectionEnd::Stopped => Self::JPROM_CORRECTIONS_CANCELLED,
        }
    }
}

/// A short name for a `jprom_correction_end` value ("within_threshold", "max_corrections",
/// "no_progress", "cancelled"; "unknown" for any other value), for logs. Static storage: do
/// not free. Since 0.3.
#[no_mangle]
pub extern "C" fn jprom_correction_end_name(end: c_int) -> *const c_char {
    // the words of CorrectionEnd::name, in the order of jprom_correction_end's values
    crate::guard::enum_name(end, &[c"within_threshold", c"max_corrections", c"no_progress", c"cancelled"])
}

/// Why the corrections of a self-correcting sweep (`jprom_rom_sweep_adaptive`) ended (`end`),
/// and the judged error of its final pass (`judged_error`: the largest linearised error `e_1`
/// at the checked points, or the largest `e*_1` where the condensed full-order system is too
/// large to check; `+inf` if a point's `e*` was not finite). Above `jprom_jp_options.threshold`
/// the basis stayed poor: the sweep holds the best basis found, not one within the threshold.
/// The sweep's own end (`jprom_sweep_result_end_reason`) says only whether its last pass covered
/// the band. Either pointer may be NULL. `JPROM_INVALID_VALUE` for any other sweep (full order,
/// `jprom_rom_sweep`) and for a self-correcting sweep loaded from a file saved without it
/// (before 0.3); nothing is written then. Since 0.3.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_correction_end(sweep: *const jprom_sweep_result, end: *mut jprom_correction_end, judged_error: *mut f64) -> jprom_status {
    ffi_guard!({
        let s = handle::get(sweep, "sweep")?;
        let o = s.record.outcome.ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, "this sweep is not a self-correcting sweep's result (or was saved without how its corrections ended)"))?;
        if let Some(x) = end.as_mut() {
            *x = o.end.into();
        }
        if let Some(x) = judged_error.as_mut() {
            *x = o.worst_error.unwrap_or(f64::INFINITY);
        }
        Ok(())
    })
}

/// The largest linearised error of the static contact displacement at the checked points of
/// a self-correcting sweep's final pass (`+inf` if not finite). The corrections do not judge it:
/// they judge the first harmonic (`jprom_sweep_result_correction_end`). Above
/// `jprom_jp_options.threshold` the reduced solution's static term is poor even where its first
/// harmonic is good; at gross slip it converges only with a nearly complete basis
/// (docs/formulation.md §10.6). `JPROM_INVALID_VALUE` for any other sweep (full order,
/// `jprom_rom_sweep`), for a sweep without checks (its condensed full order too large to
/// factorise) and for one loaded from a file saved without it; nothing is written then.
/// Since 0.3.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_static_error(sweep: *const jprom_sweep_result, out: *mut f64) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let s = handle::get(sweep, "sweep")?;
        let o = s.record.outcome.ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, "this sweep is not a self-correcting sweep's result (or was saved without how its corrections ended)"))?;
        *out = o.static_error().ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, "no static error: the sweep made no error checks (its condensed full order is too large to factorise), or was saved without it"))?;
        Ok(())
    })
}

/// Number of basis corrections made by `jprom_rom_sweep_adaptive` for this sweep (0 for any
/// other sweep, and when the first basis was good enough).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_n_corrections(sweep: *const jprom_sweep_result, out: *mut usize) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = handle::get(sweep, "sweep")?.record.corrections.len();
        Ok(())
    })
}

/// Correction `index` of a sweep (`JPROM_INVALID_VALUE` beyond its corrections).
fn correction_at(s: &jprom_sweep_result, index: usize) -> Result<&jprom::rom::Correction, FfiError> {
    crate::guard::index_arg(&s.record.corrections, index, "correction")
}

/// Correction `index` (in order, 0-based) of an adaptive sweep: its kind
/// (`JPROM_CORRECTION_REPLACED`, `JPROM_CORRECTION_REGENERATED` or
/// `JPROM_CORRECTION_GAMMA_INCREASED`), the omega it
/// regenerated from or the new gamma (`value`), the worst `e*_1` of the sweep before and after
/// it, and the basis sizes `n_h`, `h = 0..H` after it into `sizes` of capacity `len` (`sizes`
/// may be NULL with `len` 0). Each pointer may be NULL. `JPROM_INVALID_VALUE` if `index` is out
/// of range, `JPROM_BAD_SIZE` if `len` is nonzero but below `H + 1`; nothing is written then.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_correction(
    sweep: *const jprom_sweep_result,
    index: usize,
    kind: *mut c_int,
    value: *mut f64,
    worst_before: *mut f64,
    worst_after: *mut f64,
    sizes: *mut usize,
    len: usize,
) -> jprom_status {
    ffi_guard!({
        let s = handle::get(sweep, "sweep")?;
        let c = correction_at(s, index)?;
        if len > 0 {
            check_capacity("sizes", c.sizes.len(), len)?;
        }
        let buf = slice_out(sizes, if len > 0 { c.sizes.len() } else { 0 }, "sizes")?;
        let (k, v) = jprom_correction_kind::of(&c.kind);
        buf.copy_from_slice(&c.sizes[..buf.len()]);
        if let Some(x) = kind.as_mut() {
            *x = k as c_int;
        }
        if let Some(x) = value.as_mut() {
            *x = v;
        }
        if let Some(x) = worst_before.as_mut() {
            *x = c.worst_error_before;
        }
        if let Some(x) = worst_after.as_mut() {
            *x = c.worst_error_after;
        }
        Ok(())
    })
}

/// Whether correction `index` (0-based) of an adaptive sweep was swept over the band: 1 if
/// its basis was swept, 0 if it was judged without a pass (screened out at the points where
/// the bases before it were poor, or its modes already in the basis' span; its
/// `worst_after` from `jprom_sweep_result_correction` is then its error at the point where it
/// was judged). `JPROM_INVALID_VALUE` if `index` is out of range, nothing written then. Since
/// 0.3.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_correction_swept(sweep: *const jprom_sweep_result, index: usize, out: *mut c_int) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let s = handle::get(sweep, "sweep")?;
        let c = correction_at(s, index)?;
        *out = c_int::from(c.swept);
        Ok(())
    })
}

/// The actual error `e_h`, `h = 0..H` (docs/formulation.md §10.1, paper (44)) of a reduced solution: the
/// contact forces of `rom_solution` (a point of `jprom_rom_sweep` / `jprom_rom_sweep_adaptive`
/// on `basis`, copied out with `jprom_sweep_result_point`) against those of `full_solution` (a
/// full-order solution at the same omega, e.g. from `jprom_solve_point`), relative to the
/// reduced ones. `model`, `basis`, `kind` and `options` must be those of the reduced sweep
/// (they rebuild the reduced model; `JPROM_BAD_SIZE` if the basis does not match the
/// solution). `H + 1` values go to `buf` of capacity `len`. `JPROM_INVALID_VALUE` if the two
/// omegas differ (beyond 1e-9 relative), if `rom_solution` is full-order or `full_solution`
/// reduced. Compare with `jprom_sweep_result_point_predicted_error` (`e*`, which needs no full-order
/// solution).
#[no_mangle]
pub unsafe extern "C" fn jprom_rom_actual_error(
    model: *const jprom_model,
    basis: *const jprom_basis,
    kind: c_int,
    options: *const jprom_hbm_options,
    rom_solution: *const jprom_solution,
    full_solution: *const jprom_solution,
    buf: *mut f64,
    len: usize,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let b = &handle::get(basis, "basis")?.basis;
        let rs = handle::get(rom_solution, "rom_solution")?;
        let fs = handle::get(full_solution, "full_solution")?;
        let (disc, _, _) = hbm_options(options)?;
        let kind = rom_kind(kind)?;
        check_capacity("buf", disc.harmonics + 1, len)?;
        let buf = slice_out(buf, disc.harmonics + 1, "buf")?;
        if rs.origin == Origin::FullOrder {
            return Err(FfiError::new(JPROM_INVALID_VALUE, "'rom_solution' is a full-order solution; pass a point of a ROM sweep"));
        }
        if fs.origin == Origin::Reduced {
            return Err(FfiError::new(JPROM_INVALID_VALUE, "'full_solution' is a reduced solution; pass a full-order one"));
        }
        let (rp, fp) = (&rs.point, &fs.point);
        if !((rp.omega - fp.omega).abs() <= 1e-9 * rp.omega.abs()) {
            return Err(FfiError::new(JPROM_INVALID_VALUE, format!("the solutions are at different frequencies ({} and {} rad/s)", rp.omega, fp.omega)));
        }
        let rom = build_rom(m, b, kind, disc)?;
        if rom.layout().sizes != rp.layout.sizes {
            return Err(FfiError::new(
                JPROM_BAD_SIZE,
                format!("'rom_solution' has {:?} reduced unknowns per harmonic, the basis {:?}", rp.layout.sizes, rom.layout().sizes),
            ));
        }
        let (n, nw) = (m.model.n_dof(), rom.n_contact_coords());
        let n0 = fp.layout.sizes.first().copied().unwrap_or(0);
        if (n0 != n && n0 != nw) || fp.layout.sizes.iter().any(|&s| s != n0) {
            return Err(FfiError::new(JPROM_BAD_SIZE, format!("'full_solution' has {:?} unknowns per harmonic, not {n} (full) or {nw} (condensed)", fp.layout.sizes)));
        }
        let e = actual_error(rom.as_ref(), rp.omega, &rp.z, fp)?;
        buf.copy_from_slice(&e);
        Ok(())
    })
}

// Names of 0.1 and 0.2, before every function on a `jprom_sweep_result` was named
// `jprom_sweep_result_*`.

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_point_predicted_error`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_point_predicted_error")]
pub unsafe extern "C" fn jprom_sweep_point_predicted_error(sweep: *const jprom_sweep_result, index: usize, h: usize, out: *mut f64) -> jprom_status {
    jprom_sweep_result_point_predicted_error(sweep, index, h, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_n_corrections`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_n_corrections")]
pub unsafe extern "C" fn jprom_sweep_n_corrections(sweep: *const jprom_sweep_result, out: *mut usize) -> jprom_status {
    jprom_sweep_result_n_corrections(sweep, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_correction`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_correction")]
pub unsafe extern "C" fn jprom_sweep_correction(sweep: *const jprom_sweep_result, index: usize, kind: *mut c_int, value: *mut f64, worst_before: *mut f64, worst_after: *mut f64, sizes: *mut usize, len: usize) -> jprom_status {
    jprom_sweep_result_correction(sweep, index, kind, value, worst_before, worst_after, sizes, len)
}
