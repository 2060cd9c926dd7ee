//! Full-order solves from C: options, `jprom_solve_point`, `jprom_sweep` with a progress
//! callback, and the `jprom_solution` / `jprom_sweep_result` result handles with their accessors.

use super::guard::{check_capacity, ffi_guard, finite_arg, out_arg, path_arg, slice_out};
use super::handle::{self, Handle};
use super::model::jprom_model;
use super::status::jprom_status::{self, *};
use super::status::FfiError;
use super::versioned::{read_options, write_defaults, Versioned};
use jprom::condensation::CondensedSystem;
use jprom::hbm::{self, Discretisation, FullSystem, HarmonicSystem, HbmOptions, PointSolution, SweepEnd, SweepOptions, SweepResult};
use jprom::io::Document;
use jprom::rom::SweepRecord;
use std::ffi::{c_char, c_int, c_void};
use std::ops::ControlFlow;

/// Settings of one harmonic-balance solve. Fill with `jprom_hbm_options_default`, then change
/// fields. `struct_size` says which version of the struct the caller was compiled with (see
/// the ABI policy in the README): leave it as the default function wrote it.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_camel_case_types)]
pub struct jprom_hbm_options {
    pub struct_size: usize,
    /// Highest harmonic H (default 1, at most `JPROM_MAX_HARMONICS`); the static term is
    /// always included.
    pub harmonics: usize,
    /// AFT samples per period, a power of two >= 4 (H + 1) and at most `JPROM_MAX_NT`;
    /// 0 (default) = 64 for H <= 3, more above.
    pub nt: usize,
    /// Relative residual tolerance (default 1e-10).
    pub residual_tolerance: f64,
    /// Newton iterations per point, all attempts (load stepping included) together (default 400).
    pub max_iterations: usize,
    /// 1 (default): solve on the contact DoFs after condensing the linear ones (docs/formulation.md §7);
    /// 0: solve on all DoFs.
    pub condensed: c_int,
}

/// Settings of a frequency sweep by pseudo-arclength continuation (rad/s). Fill with
/// `jprom_sweep_options_default`. Version 1 ends at `max_points`
/// (`JPROM_SWEEP_OPTIONS_V1_SIZE` bytes); version 2 (jprom 0.2) adds `max_omega_step` and
/// `max_angle`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_camel_case_types)]
pub struct jprom_sweep_options {
    pub struct_size: usize,
    pub omega_start: f64,
    pub omega_end: f64,
    /// Arclength steps (scaled; defaults 0.02, 1e-6, 0.1).
    pub initial_step: f64,
    pub min_step: f64,
    pub max_step: f64,
    /// Most points (default 5000).
    pub max_points: usize,
    /// Version 2: largest frequency increment of one step as a fraction of the band (default
    /// 0.02, in (0, 1]).
    pub max_omega_step: f64,
    /// Version 2: largest angle (radians) between the tangents of two successive points
    /// (default 0.15); a step that turns more is retried shorter.
    pub max_angle: f64,
}

/// `struct_size` of version 1 of `jprom_sweep_options` (up to `max_points`).
pub const JPROM_SWEEP_OPTIONS_V1_SIZE: usize = 56;
/// `struct_size` of version 1 of `jprom_hbm_options`.
pub const JPROM_HBM_OPTIONS_V1_SIZE: usize = 48;

// A released prefix ends where the next version's fields begin, so reading a prefix never
// reads a new field's bytes from an old caller's padding.
const _: () = assert!(std::mem::offset_of!(jprom_sweep_options, max_omega_step) == JPROM_SWEEP_OPTIONS_V1_SIZE);
const _: () = assert!(std::mem::size_of::<jprom_hbm_options>() == JPROM_HBM_OPTIONS_V1_SIZE);

impl Versioned for jprom_hbm_options {
    const NAME: &'static str = "jprom_hbm_options";
    const SIZES: &'static [usize] = &[JPROM_HBM_OPTIONS_V1_SIZE];
    fn defaults() -> Self {
        let d = HbmOptions::default();
        jprom_hbm_options {
            struct_size: std::mem::size_of::<jprom_hbm_options>(),
            harmonics: Discretisation::default().harmonics,
            nt: 0,
            residual_tolerance: d.residual_tolerance,
            max_iterations: d.max_iterations,
            condensed: 1,
        }
    }
}

impl Versioned for jprom_sweep_options {
    const NAME: &'static str = "jprom_sweep_options";
    const SIZES: &'static [usize] = &[JPROM_SWEEP_OPTIONS_V1_SIZE, std::mem::size_of::<jprom_sweep_options>()];
    fn defaults() -> Self {
        let d = SweepOptions::default();
        jprom_sweep_options {
            struct_size: std::mem::size_of::<jprom_sweep_options>(),
            omega_start: d.omega_start,
            omega_end: d.omega_end,
            initial_step: d.initial_step,
            min_step: d.min_step,
            max_step: d.max_step,
            max_points: d.max_points,
            max_omega_step: d.max_omega_step,
            max_angle: d.max_angle,
        }
    }
}

/// Progress callback of `jprom_sweep`: called on the calling thread after each converged
/// point with its index, angular frequency and the first-harmonic amplitude at each output
/// DoF (`n_outputs` values, valid during the call). Return 0 to go on, nonzero to stop.
#[allow(non_camel_case_types)]
pub type jprom_progress_fn =
    Option<unsafe extern "C" fn(user_data: *mut c_void, point_index: usize, omega: f64, amplitudes: *const f64, n_outputs: usize) -> c_int>;

/// What computed a solution: it decides whether `z` holds physical (full-order or condensed)
/// unknowns or reduced ones. Not part of the C API.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Origin {
    /// `jprom_solve_point`, `jprom_sweep`.
    FullOrder,
    /// `jprom_rom_sweep`, `jprom_rom_sweep_adaptive`.
    Reduced,
    /// Loaded from a file (the files do not say).
    Unknown,
}

/// One converged frequency point. Released with `jprom_solution_free`.
#[allow(non_camel_case_types)]
pub struct jprom_solution {
    magic: u64,
    pub(crate) point: PointSolution,
    pub(crate) origin: Origin,
}

/// The points of a sweep. Released with `jprom_sweep_result_free`.
#[allow(non_camel_case_types)]
pub struct jprom_sweep_result {
    magic: u64,
    /// The points, with `e*` and the corrections of a reduced sweep (the core's record).
    pub(crate) record: SweepRecord,
    pub(crate) origin: Origin,
}

impl jprom_sweep_result {
    pub(crate) fn wrap(record: SweepRecord, origin: Origin) -> *mut jprom_sweep_result {
        handle::into_raw(jprom_sweep_result { magic: Self::MAGIC, record, origin })
    }
}

impl Handle for jprom_solution {
    const MAGIC: u64 = 0x4A50_524F_4D53_4F4C; // "JPROMSOL"
    const KIND: &'static str = "jprom_solution";
    fn magic_mut(&mut self) -> &mut u64 {
        &mut self.magic
    }
    fn magic(&self) -> u64 {
        self.magic
    }
}

impl Handle for jprom_sweep_result {
    const MAGIC: u64 = 0x4A50_524F_4D53_5750; // "JPROMSWP"
    const KIND: &'static str = "jprom_sweep_result";
    fn magic_mut(&mut self) -> &mut u64 {
        &mut self.magic
    }
    fn magic(&self) -> u64 {
        self.magic
    }
}

/// Writes the defaults of version 1 of `jprom_hbm_options` into `*out`. In `jprom.h` this
/// name is a macro for `jprom_hbm_options_init(out, sizeof *out)`.
#[no_mangle]
pub unsafe extern "C" fn jprom_hbm_options_default(out: *mut jprom_hbm_options) -> jprom_status {
    ffi_guard!({ write_defaults(out, JPROM_HBM_OPTIONS_V1_SIZE) })
}

/// Writes the defaults into the `struct_size` bytes of `*out` (pass `sizeof *out`; it must be
/// the size of a released version of the struct, else `JPROM_BAD_SIZE`) and sets its
/// `struct_size`.
#[no_mangle]
pub unsafe extern "C" fn jprom_hbm_options_init(out: *mut jprom_hbm_options, struct_size: usize) -> jprom_status {
    ffi_guard!({ write_defaults(out, struct_size) })
}

/// Writes the defaults of version 1 of `jprom_sweep_options` into `*out` (band 0..0: set
/// `omega_start` and `omega_end`). In `jprom.h` this name is a macro for
/// `jprom_sweep_options_init(out, sizeof *out)`, which also writes the newer fields.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_options_default(out: *mut jprom_sweep_options) -> jprom_status {
    ffi_guard!({ write_defaults(out, JPROM_SWEEP_OPTIONS_V1_SIZE) })
}

/// Writes the defaults into the `struct_size` bytes of `*out` (pass `sizeof *out`; a released
/// size, else `JPROM_BAD_SIZE`) and sets its `struct_size`. Band 0..0: set `omega_start` and
/// `omega_end`.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_options_init(out: *mut jprom_sweep_options, struct_size: usize) -> jprom_status {
    ffi_guard!({ write_defaults(out, struct_size) })
}

/// The `options` argument of a solve, any released version, checked: the discretisation the
/// systems are built with (`harmonics`, `nt`), the Newton settings, and the struct as read.
pub(crate) unsafe fn hbm_options(p: *const jprom_hbm_options) -> Result<(Discretisation, HbmOptions, jprom_hbm_options), FfiError> {
    let o = read_options(p, "options")?;
    let disc = Discretisation { harmonics: o.harmonics, nt: if o.nt == 0 { None } else { Some(o.nt) } };
    disc.validate()?;
    let opts = HbmOptions {
        residual_tolerance: finite_arg("residual_tolerance", o.residual_tolerance)?,
        max_iterations: o.max_iterations,
        ..HbmOptions::default()
    };
    opts.validate()?;
    Ok((disc, opts, o))
}

/// The `sweep_opts` argument: any released version, checked.
pub(crate) unsafe fn sweep_options(p: *const jprom_sweep_options) -> Result<SweepOptions, FfiError> {
    let o = read_options(p, "sweep_opts")?;
    let s = SweepOptions {
        omega_start: o.omega_start,
        omega_end: o.omega_end,
        initial_step: o.initial_step,
        min_step: o.min_step,
        max_step: o.max_step,
        max_points: o.max_points,
        max_omega_step: o.max_omega_step,
        max_angle: o.max_angle,
        ..SweepOptions::default()
    };
    s.validate()?;
    Ok(s)
}

/// The system of `model` (condensed onto its contacts or full-order); each refuses, with its
/// estimate, a size beyond the memory budget before allocating it.
fn system(model: &jprom_model, disc: Discretisation, condensed: c_int) -> Result<Box<dyn HarmonicSystem>, FfiError> {
    Ok(if condensed != 0 {
        Box::new(CondensedSystem::new(&model.model, disc)?)
    } else {
        Box::new(FullSystem::new(&model.model, disc)?)
    })
}

/// Solves one frequency point `omega` (rad/s) from a zero initial guess.
/// `JPROM_NO_CONVERGENCE` if Newton fails (no solution is returned then).
#[no_mangle]
pub unsafe extern "C" fn jprom_solve_point(
    model: *const jprom_model,
    omega: f64,
    options: *const jprom_hbm_options,
    out: *mut *mut jprom_solution,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let (disc, opts, o) = hbm_options(options)?;
        let out = out_arg(out, "out")?;
        let sys = system(m, disc, o.condensed)?;
        let point = hbm::solve_point(sys.as_ref(), finite_arg("omega", omega)?, None, &opts)?;
        *out = handle::into_raw(jprom_solution { magic: jprom_solution::MAGIC, point, origin: Origin::FullOrder });
        Ok(())
    })
}

/// The unknowns `z` of `guess` laid out for `sys`: a full-order solution (`jprom_solve_point`,
/// `jprom_sweep`, or loaded from a file) of a system with the same unknowns per harmonic; a
/// different `H` is fine (missing harmonics start at zero, extra ones are dropped).
unsafe fn guess_for(sys: &dyn HarmonicSystem, guess: *const jprom_solution, name: &str) -> Result<Vec<f64>, FfiError> {
    let g = handle::get(guess, name)?;
    if g.origin == Origin::Reduced {
        return Err(FfiError::new(
            JPROM_INVALID_VALUE,
            format!("'{name}' is a reduced-order solution (its unknowns are the ROM's); pass a full-order one (jprom_solve_point, jprom_sweep)"),
        ));
    }
    let (have, want) = (&g.point.layout, sys.layout());
    let n = want.size(0);
    let uniform = |l: &hbm::HarmonicLayout| l.sizes.iter().all(|&s| s == l.size(0));
    if have.size(0) != n || !uniform(have) || !uniform(want) || g.point.z.len() != have.total() {
        return Err(FfiError::new(
            JPROM_BAD_SIZE,
            format!(
                "'{name}' has {} unknowns per harmonic, this solve {n} (a condensed solve has the contact coordinates as unknowns, a full one all DoFs: use the same `condensed` and model)",
                have.size(0)
            ),
        ));
    }
    let mut z = vec![0.0; want.total()];
    for k in 0..(2 * have.harmonics.min(want.harmonics) + 1) {
        let (src, _) = have.coeff_range(k);
        let (dst, _) = want.coeff_range(k);
        z[dst..dst + n].copy_from_slice(&g.point.z[src..src + n]);
    }
    Ok(z)
}

/// Solves one frequency point `omega` (rad/s) from the solution `guess` (for example the
/// nearest point of a sweep, or a solution at a lower excitation level), or from zero when
/// `guess` is NULL (then as `jprom_solve_point`). `guess` must come from a full-order solve
/// with the same `condensed` setting and model size (`JPROM_BAD_SIZE` otherwise; a reduced-order
/// solution is `JPROM_INVALID_VALUE`); its `H` may differ (missing harmonics start at zero).
/// If Newton fails from the guess, the load-stepping fallback runs as from zero; all
/// attempts together stay within `options.max_iterations`. `JPROM_NO_CONVERGENCE` if no
/// attempt converges (`*out` is not written then). `guess` is only read.
#[no_mangle]
pub unsafe extern "C" fn jprom_solve_point_from(
    model: *const jprom_model,
    omega: f64,
    options: *const jprom_hbm_options,
    guess: *const jprom_solution,
    out: *mut *mut jprom_solution,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let (disc, opts, o) = hbm_options(options)?;
        let out = out_arg(out, "out")?;
        let omega = finite_arg("omega", omega)?;
        let sys = system(m, disc, o.condensed)?;
        let z = if guess.is_null() { None } else { Some(guess_for(sys.as_ref(), guess, "guess")?) };
        let point = hbm::solve_point(sys.as_ref(), omega, z.as_deref(), &opts)?;
        *out = handle::into_raw(jprom_solution { magic: jprom_solution::MAGIC, point, origin: Origin::FullOrder });
        Ok(())
    })
}

/// `jprom_sweep` whose first point, at `sweep_opts.omega_start`, is solved from the solution
/// `start` instead of from zero: to restart a sweep from one of its points (pass that point's
/// frequency as `omega_start`), or to follow another branch. NULL `start` is `jprom_sweep`.
/// `start` is checked as the `guess` of `jprom_solve_point_from` and only read.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_from(
    model: *const jprom_model,
    options: *const jprom_hbm_options,
    sweep_opts: *const jprom_sweep_options,
    start: *const jprom_solution,
    callback: jprom_progress_fn,
    user_data: *mut c_void,
    out: *mut *mut jprom_sweep_result,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let (disc, opts, o) = hbm_options(options)?;
        let sopts = sweep_options(sweep_opts)?;
        let out = out_arg(out, "out")?;
        let sys = system(m, disc, o.condensed)?;
        let z = if start.is_null() { None } else { Some(guess_for(sys.as_ref(), start, "start")?) };
        let mut on_point = progress_adapter(callback, user_data);
        let result = hbm::sweep_from(sys.as_ref(), &sopts, &opts, z.as_deref(), &mut on_point)?;
        *out = jprom_sweep_result::wrap(SweepRecord::full_order(result), Origin::FullOrder);
        Ok(())
    })
}

/// Sweeps `[omega_start, omega_end]` by pseudo-arclength continuation.
///
/// `callback` may be NULL. If it returns nonzero the sweep stops there: the call returns
/// `JPROM_OK` with the points computed so far and the end reason `JPROM_SWEEP_CANCELLED`.
/// If continuation fails before the end of the band, the call also returns `JPROM_OK` with the
/// points found; `jprom_sweep_result_reached_end` tells whether the band was covered, and
/// `jprom_sweep_result_failure_copy` why not. If not even the first point converges, the status is
/// that error and `*out` is not written.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep(
    model: *const jprom_model,
    options: *const jprom_hbm_options,
    sweep_opts: *const jprom_sweep_options,
    callback: jprom_progress_fn,
    user_data: *mut c_void,
    out: *mut *mut jprom_sweep_result,
) -> jprom_status {
    jprom_sweep_from(model, options, sweep_opts, std::ptr::null(), callback, user_data, out)
}

/// Adapts the C progress callback to the sweep's `on_point` closure.
pub(crate) fn progress_adapter(callback: jprom_progress_fn, user_data: *mut c_void) -> impl FnMut(&PointSolution) -> ControlFlow<()> {
    let mut index = 0usize;
    let mut amps = Vec::new();
    move |p: &PointSolution| {
        let stop = match callback {
            Some(cb) => {
                amps.clear();
                amps.extend((0..p.n_outputs).map(|j| if p.layout.harmonics >= 1 { p.output_amplitude(1, j) } else { 0.0 }));
                // SAFETY: the caller passed a valid function pointer with this signature.
                unsafe { cb(user_data, index, p.omega, amps.as_ptr(), amps.len()) != 0 }
            }
            None => false,
        };
        index += 1;
        if stop {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Releases a solution (NULL is a no-op).
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_free(solution: *mut jprom_solution) -> jprom_status {
    ffi_guard!({ handle::free(solution, "solution") })
}

/// Releases a sweep (NULL is a no-op).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_free(sweep: *mut jprom_sweep_result) -> jprom_status {
    ffi_guard!({ handle::free(sweep, "sweep") })
}

/// Number of converged points in a sweep.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_n_points(sweep: *const jprom_sweep_result, out: *mut usize) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = handle::get(sweep, "sweep")?.record.sweep.points.len();
        Ok(())
    })
}

/// Why a sweep ended (`jprom_sweep_result_end_reason`). The values never change.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum jprom_sweep_end {
    /// The branch reached `omega_end`.
    JPROM_SWEEP_REACHED_END = 0,
    /// The corrector could not converge even at the smallest step (`min_step`) and no gap could
    /// be stepped over: the text of `jprom_sweep_result_failure_copy` has where and the last
    /// residual.
    JPROM_SWEEP_STALLED = 1,
    /// `max_points` points were computed before reaching `omega_end`.
    JPROM_SWEEP_POINT_CAP = 2,
    /// The branch turned back at a fold and left the band behind `omega_start`.
    JPROM_SWEEP_LEFT_BAND = 3,
    /// The progress callback asked to stop.
    JPROM_SWEEP_CANCELLED = 4,
}

impl From<SweepEnd> for jprom_sweep_end {
    fn from(e: SweepEnd) -> Self {
        match e {
            SweepEnd::ReachedEnd => jprom_sweep_end::JPROM_SWEEP_REACHED_END,
            SweepEnd::StepTooSmall => jprom_sweep_end::JPROM_SWEEP_STALLED,
            SweepEnd::MaxPoints => jprom_sweep_end::JPROM_SWEEP_POINT_CAP,
            SweepEnd::LeftBand => jprom_sweep_end::JPROM_SWEEP_LEFT_BAND,
            SweepEnd::StoppedByCaller => jprom_sweep_end::JPROM_SWEEP_CANCELLED,
        }
    }
}

/// Why the sweep ended (`JPROM_SWEEP_REACHED_END` if it covered the band); the words, with
/// where it stopped, come from `jprom_sweep_result_failure_copy`.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_end_reason(sweep: *const jprom_sweep_result, out: *mut jprom_sweep_end) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = handle::get(sweep, "sweep")?.record.sweep.end.into();
        Ok(())
    })
}

/// A short name for a `jprom_sweep_end` value ("reached_end", "stalled", "point_cap",
/// "left_band", "cancelled"; "unknown" for any other value). Static storage: do not free.
#[no_mangle]
pub extern "C" fn jprom_sweep_end_name(reason: c_int) -> *const c_char {
    // the words of SweepEnd::name, in the order of jprom_sweep_end's values
    crate::guard::enum_name(reason, &[c"reached_end", c"stalled", c"point_cap", c"left_band", c"cancelled"])
}

/// 1 if the sweep covered the whole band, 0 if it ended early (see `jprom_sweep_result_end_reason`
/// and `jprom_sweep_result_failure_copy`).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_reached_end(sweep: *const jprom_sweep_result, out: *mut c_int) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = (handle::get(sweep, "sweep")?.record.sweep.end == SweepEnd::ReachedEnd) as c_int;
        Ok(())
    })
}

/// Copies why the sweep ended early (empty if it did not) into `buf`, with the convention of
/// `jprom_last_error_copy`: NUL-terminated, `*written` = full length, `JPROM_BAD_SIZE` if
/// truncated.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_failure_copy(sweep: *const jprom_sweep_result, buf: *mut c_char, len: usize, written: *mut usize) -> jprom_status {
    ffi_guard!({
        let s = handle::get(sweep, "sweep")?;
        let text = s.record.sweep.failure.as_deref().unwrap_or_default();
        crate::status::copy_result_text(text, buf, len, written)
    })
}

unsafe fn sweep_point<'a>(sweep: *const jprom_sweep_result, index: usize) -> Result<&'a PointSolution, FfiError> {
    crate::guard::index_arg(&handle::get(sweep, "sweep")?.record.sweep.points, index, "point")
}

/// A point of a sweep as a new, independent `jprom_solution` (free it).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_point(sweep: *const jprom_sweep_result, index: usize, out: *mut *mut jprom_solution) -> jprom_status {
    ffi_guard!({
        let origin = handle::get(sweep, "sweep")?.origin;
        let p = sweep_point(sweep, index)?.clone();
        // the out pointer is checked before the handle is registered (an assignment evaluates
        // its right side first: a NULL `out` leaked a live handle)
        let out = out_arg(out, "out")?;
        *out = handle::into_raw(jprom_solution { magic: jprom_solution::MAGIC, point: p, origin });
        Ok(())
    })
}

/// Angular frequency of point `index` of a sweep.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_point_omega(sweep: *const jprom_sweep_result, index: usize, out: *mut f64) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = sweep_point(sweep, index)?.omega;
        Ok(())
    })
}

/// Amplitude of harmonic `h` at output `j` of point `index` (`|c_0|` for `h = 0`,
/// `sqrt(c^2 + s^2)` for `h >= 1`).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_point_amplitude(sweep: *const jprom_sweep_result, index: usize, h: usize, j: usize, out: *mut f64) -> jprom_status {
    ffi_guard!({
        let p = sweep_point(sweep, index)?;
        *out_arg(out, "out")? = amplitude(p, h, j)?;
        Ok(())
    })
}

/// Copies the output-DoF coefficients of point `index` (`(2H + 1) * n_outputs` values, entry
/// `k * n_outputs + j`, H = `options.harmonics` of the sweep) into `buf` of capacity `len`.
/// `JPROM_BAD_SIZE` if `len` is too small (nothing is written then).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_point_output_coeffs(sweep: *const jprom_sweep_result, index: usize, buf: *mut f64, len: usize) -> jprom_status {
    ffi_guard!({ copy_output_coeffs(sweep_point(sweep, index)?, buf, len) })
}

/// Energy dissipated per cycle by each contact at point `index` (`n_contacts` values) into
/// `buf` of capacity `len`.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_point_dissipated_energy(sweep: *const jprom_sweep_result, index: usize, buf: *mut f64, len: usize) -> jprom_status {
    ffi_guard!({ copy_dissipated_energy(sweep_point(sweep, index)?, buf, len) })
}

/// Newton iterations and final relative residual of point `index` (either pointer may be NULL).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_point_convergence(sweep: *const jprom_sweep_result, index: usize, iterations: *mut usize, residual: *mut f64) -> jprom_status {
    ffi_guard!({
        write_convergence(sweep_point(sweep, index)?, iterations, residual);
        Ok(())
    })
}

fn amplitude(p: &PointSolution, h: usize, j: usize) -> Result<f64, FfiError> {
    if h > p.layout.harmonics {
        return Err(FfiError::new(JPROM_INVALID_VALUE, format!("harmonic {h} > H = {}", p.layout.harmonics)));
    }
    if j >= p.n_outputs {
        return Err(FfiError::new(JPROM_INVALID_VALUE, format!("output index {j} >= {}", p.n_outputs)));
    }
    Ok(p.output_amplitude(h, j))
}

/// Angular frequency of a solution.
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_omega(solution: *const jprom_solution, out: *mut f64) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = handle::get(solution, "solution")?.point.omega;
        Ok(())
    })
}

/// Harmonics `H` and output count of a solution (either pointer may be NULL).
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_sizes(solution: *const jprom_solution, harmonics: *mut usize, n_outputs: *mut usize, n_contacts: *mut usize) -> jprom_status {
    ffi_guard!({
        let p = &handle::get(solution, "solution")?.point;
        if let Some(h) = harmonics.as_mut() {
            *h = p.layout.harmonics;
        }
        if let Some(n) = n_outputs.as_mut() {
            *n = p.n_outputs;
        }
        if let Some(n) = n_contacts.as_mut() {
            *n = p.contact_cycles.len();
        }
        Ok(())
    })
}

/// Copies the output-DoF coefficients (`(2H + 1) * n_outputs` values, entry `k * n_outputs + j`)
/// into `buf` of capacity `len`.
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_output_coeffs(solution: *const jprom_solution, buf: *mut f64, len: usize) -> jprom_status {
    ffi_guard!({
        copy_output_coeffs(&handle::get(solution, "solution")?.point, buf, len)
    })
}

/// Size-checked copy of a point's output coefficients (entry `k * n_outputs + j`).
unsafe fn copy_output_coeffs(p: &PointSolution, buf: *mut f64, len: usize) -> Result<(), FfiError> {
    check_capacity("buf", p.outputs.len(), len)?;
    slice_out(buf, p.outputs.len(), "buf")?.copy_from_slice(&p.outputs);
    Ok(())
}

/// Amplitude of harmonic `h` at output `j`.
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_amplitude(solution: *const jprom_solution, h: usize, j: usize, out: *mut f64) -> jprom_status {
    ffi_guard!({
        let p = &handle::get(solution, "solution")?.point;
        *out_arg(out, "out")? = amplitude(p, h, j)?;
        Ok(())
    })
}

/// Newton iterations and final relative residual (either pointer may be NULL).
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_convergence(solution: *const jprom_solution, iterations: *mut usize, residual: *mut f64) -> jprom_status {
    ffi_guard!({
        write_convergence(&handle::get(solution, "solution")?.point, iterations, residual);
        Ok(())
    })
}

unsafe fn write_convergence(p: &PointSolution, iterations: *mut usize, residual: *mut f64) {
    if let Some(i) = iterations.as_mut() {
        *i = p.iterations;
    }
    if let Some(r) = residual.as_mut() {
        *r = p.residual_norm;
    }
}

/// Energy dissipated per cycle by each contact (`n_contacts` values) into `buf` of capacity `len`.
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_dissipated_energy(solution: *const jprom_solution, buf: *mut f64, len: usize) -> jprom_status {
    ffi_guard!({
        copy_dissipated_energy(&handle::get(solution, "solution")?.point, buf, len)
    })
}

unsafe fn copy_dissipated_energy(p: &PointSolution, buf: *mut f64, len: usize) -> Result<(), FfiError> {
    let n = p.contact_cycles.len();
    check_capacity("buf", n, len)?;
    let out = slice_out(buf, n, "buf")?;
    for (o, c) in out.iter_mut().zip(&p.contact_cycles) {
        *o = c.dissipated_energy;
    }
    Ok(())
}

/// Number of AFT time samples per contact in the solution's state record.
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_n_samples(solution: *const jprom_solution, out: *mut usize) -> jprom_status {
    ffi_guard!({
        let p = &handle::get(solution, "solution")?.point;
        *out_arg(out, "out")? = p.contact_cycles.first().map(|c| c.states.len()).unwrap_or(0);
        Ok(())
    })
}

/// Contact states (0 stick, 1 slip, 2 separated) of contact `contact` at each time sample,
/// into `buf` of capacity `len` (`jprom_solution_n_samples` values).
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_contact_states(solution: *const jprom_solution, contact: usize, buf: *mut u8, len: usize) -> jprom_status {
    ffi_guard!({
        let p = &handle::get(solution, "solution")?.point;
        let c = p
            .contact_cycles
            .get(contact)
            .ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, format!("contact index {contact} >= {}", p.contact_cycles.len())))?;
        check_capacity("buf", c.states.len(), len)?;
        let out = slice_out(buf, c.states.len(), "buf")?;
        for (o, s) in out.iter_mut().zip(&c.states) {
            *o = *s as u8;
        }
        Ok(())
    })
}

/// Saves a solution as versioned JSON.
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_save_json(solution: *const jprom_solution, path: *const c_char) -> jprom_status {
    ffi_guard!({
        let p = &handle::get(solution, "solution")?.point;
        jprom::io::save_json("solution", p, &path_arg(path, "path")?)?;
        Ok(())
    })
}

/// Loads a solution saved by `jprom_solution_save_json`, checked as a whole (every size
/// against every array; `JPROM_PARSE` naming the key and line otherwise; `JPROM_IO` for a
/// file of another kind or a directory). The file does not say whether the
/// solution is full-order or reduced: `jprom_basis_from_solution` and `jprom_rom_actual_error`
/// check a loaded solution's sizes only.
#[no_mangle]
pub unsafe extern "C" fn jprom_solution_load_json(path: *const c_char, out: *mut *mut jprom_solution) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let point: PointSolution = jprom::io::load_document(&path_arg(path, "path")?)?;
        *out = handle::into_raw(jprom_solution { magic: jprom_solution::MAGIC, point, origin: Origin::Unknown });
        Ok(())
    })
}

/// Saves all points of a sweep as versioned JSON.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_save_json(sweep: *const jprom_sweep_result, path: *const c_char) -> jprom_status {
    ffi_guard!({
        let s = handle::get(sweep, "sweep")?;
        let path = path_arg(path, "path")?;
        // a reduced sweep keeps its e* and corrections; a full-order one is a plain sweep file
        if s.origin == Origin::Reduced || s.record.is_reduced() {
            jprom::io::save_json(SweepRecord::KIND, &s.record, &path)?;
        } else {
            jprom::io::save_json(SweepResult::KIND, &s.record.sweep, &path)?;
        }
        Ok(())
    })
}

/// Loads a sweep saved by `jprom_sweep_result_save_json`, checked as a whole like
/// `jprom_solution_load_json`. `*out` is written only on success; free
/// it with `jprom_sweep_result_free`. A reduced sweep comes back with its predicted errors (`e*`)
/// and corrections.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_load_json(path: *const c_char, out: *mut *mut jprom_sweep_result) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let path = path_arg(path, "path")?;
        let text = jprom::io::read_text(&path)?;
        let name = path.display().to_string();
        let handle = if jprom::io::document_kind(&text).as_deref() == Some(SweepRecord::KIND) {
            jprom_sweep_result::wrap(jprom::io::parse_document::<SweepRecord>(&text, &name)?, Origin::Reduced)
        } else {
            let result: SweepResult = jprom::io::parse_document(&text, &name)?;
            jprom_sweep_result::wrap(SweepRecord::full_order(result), Origin::Unknown)
        };
        *out = handle;
        Ok(())
    })
}

// Names of 0.1 and 0.2, before every function on a `jprom_sweep_result` was named
// `jprom_sweep_result_*`.

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_free`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_free")]
pub unsafe extern "C" fn jprom_sweep_free(sweep: *mut jprom_sweep_result) -> jprom_status {
    jprom_sweep_result_free(sweep)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_n_points`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_n_points")]
pub unsafe extern "C" fn jprom_sweep_n_points(sweep: *const jprom_sweep_result, out: *mut usize) -> jprom_status {
    jprom_sweep_result_n_points(sweep, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_end_reason`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_end_reason")]
pub unsafe extern "C" fn jprom_sweep_end_reason(sweep: *const jprom_sweep_result, out: *mut jprom_sweep_end) -> jprom_status {
    jprom_sweep_result_end_reason(sweep, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_reached_end`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_reached_end")]
pub unsafe extern "C" fn jprom_sweep_reached_end(sweep: *const jprom_sweep_result, out: *mut c_int) -> jprom_status {
    jprom_sweep_result_reached_end(sweep, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_failure_copy`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_failure_copy")]
pub unsafe extern "C" fn jprom_sweep_failure_copy(sweep: *const jprom_sweep_result, buf: *mut c_char, len: usize, written: *mut usize) -> jprom_status {
    jprom_sweep_result_failure_copy(sweep, buf, len, written)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_point`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_point")]
pub unsafe extern "C" fn jprom_sweep_point(sweep: *const jprom_sweep_result, index: usize, out: *mut *mut jprom_solution) -> jprom_status {
    jprom_sweep_result_point(sweep, index, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_point_omega`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_point_omega")]
pub unsafe extern "C" fn jprom_sweep_point_omega(sweep: *const jprom_sweep_result, index: usize, out: *mut f64) -> jprom_status {
    jprom_sweep_result_point_omega(sweep, index, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_point_amplitude`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_point_amplitude")]
pub unsafe extern "C" fn jprom_sweep_point_amplitude(sweep: *const jprom_sweep_result, index: usize, h: usize, j: usize, out: *mut f64) -> jprom_status {
    jprom_sweep_result_point_amplitude(sweep, index, h, j, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_point_output_coeffs`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_point_output_coeffs")]
pub unsafe extern "C" fn jprom_sweep_point_output_coeffs(sweep: *const jprom_sweep_result, index: usize, buf: *mut f64, len: usize) -> jprom_status {
    jprom_sweep_result_point_output_coeffs(sweep, index, buf, len)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_point_dissipated_energy`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_point_dissipated_energy")]
pub unsafe extern "C" fn jprom_sweep_point_dissipated_energy(sweep: *const jprom_sweep_result, index: usize, buf: *mut f64, len: usize) -> jprom_status {
    jprom_sweep_result_point_dissipated_energy(sweep, index, buf, len)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_point_convergence`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_point_convergence")]
pub unsafe extern "C" fn jprom_sweep_point_convergence(sweep: *const jprom_sweep_result, index: usize, iterations: *mut usize, residual: *mut f64) -> jprom_status {
    jprom_sweep_result_point_convergence(sweep, index, iterations, residual)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_save_json`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_save_json")]
pub unsafe extern "C" fn jprom_sweep_save_json(sweep: *const jprom_sweep_result, path: *const c_char) -> jprom_status {
    jprom_sweep_result_save_json(sweep, path)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_sweep_result_load_json`, named like every other
/// function on a `jprom_sweep_result`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_sweep_result_load_json")]
pub unsafe extern "C" fn jprom_sweep_load_json(path: *const c_char, out: *mut *mut jprom_sweep_result) -> jprom_status {
    jprom_sweep_result_load_json(path, out)
}
