//! Runs a [`Study`]: builds the model (built-in blade, or Matrix Market `M`, `K` with a node/DoF
//! map, then Craig-Bampton; each parameter case's contact laws, damping and static load on it),
//! sweeps the band with the condensed full-order solver and the FR and NLR reduced models at
//! each excitation level of each case, evaluates the error predictor, optionally
//! studies error vs basis size (`basis.gamma_study`), and writes CSV, JSON and SVG results.

use super::plots::{level_series, solver_color, write_energy_map, write_plot, Dash, Legend, Marker, PlotSpec, Series, Style};
use plotters::style::RGBColor;
use super::study::{CaseSpec, DampingSpec, FeSource, ModelSpec, Study, BLADE_MODEL_CACHE};
use jprom::contact::ContactLaw;
use jprom::fe::{BladeParams, BuiltinBlade, FeModel, Reduction};
use jprom::io::dof_map::DofMap;
use jprom::io::calculix::{read_model_files, CalculixFiles};
use jprom::io::matrix_market::read_symmetric_matrix_market;
use super::check::{placement, ModelNodes};
use super::progress::Progress;
use super::progress as jprom_progress;
use jprom::condensation::CondensedSystem;
use jprom::contact::ContactState;
use jprom::error::{JpError, Result};
use jprom::rom::error_metric::{actual_error, predicted_error, reduced_contact_cycles};
use jprom::hbm::{solve_point, sweep, HarmonicSystem, HbmOptions, PointSolution, SweepOptions, SweepResult};
use jprom::level::stuck_limit;
use jprom::jp::prediction::PredictionOptions;
use jprom::jp::{predict_basis, JpBasis, PredictionReport};
use jprom::model::{ContactCoordinates, Damping, Model};
use jprom::rom::{adaptive_sweep_from, reduced_model, AdaptiveOptions, RomKind};
use serde::{Deserialize, Serialize};
use super::units::{run_units_threads, study_units, Unit, UnitKind};
use std::io::Write;
use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// One solver at one excitation level.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SolverRow {
    pub level: f64,
    pub solver: String,
    /// Unknowns per harmonic (`n_0, n_1, ...`).
    pub sizes: Vec<usize>,
    pub points: usize,
    /// Seconds for the sweep (for ROMs: reduced sweeps, error checks and corrections, plus the
    /// level's share of the case's shared basis prediction, its time over the number of levels).
    pub sweep_seconds: f64,
    /// The part of `sweep_seconds` spent on the basis (ROMs; 0 for the full order): the share
    /// of the shared prediction, the ROM's construction with its first reduced point, and for
    /// each correction the error checks that asked for it, its prediction and the new ROM.
    pub basis_seconds: f64,
    /// Basis corrections made by the self-correcting sweep (ROMs).
    pub corrections: usize,
    /// Resonance (largest `X1` at the response output, `output.response`) frequency and amplitude;
    /// NaN (`null` in `summary.json`, `-` in the table) for a sweep without points and for a
    /// reduced sweep that is not trusted (`trusted`).
    pub peak_hz: f64,
    pub peak_x1: f64,
    pub peak_x0: f64,
    /// Errors against the full order at the full-order resonance (ROMs only): of `|X1|` at the
    /// response output, relative; of `X0`, the largest over the outputs relative to the
    /// largest full-order `|X0|` there.
    pub error_x1: Option<f64>,
    pub error_x0: Option<f64>,
    /// Predicted `e*_1` and actual `e_1` there (ROMs only).
    pub predicted_e1: Option<f64>,
    pub actual_e1: Option<f64>,
    /// Largest error of the dissipated energy per contact node there, relative to the largest
    /// energy per contact node met anywhere in the study (ROMs only; `None` when no contact
    /// dissipates anywhere).
    pub energy_error: Option<f64>,
    /// Why the sweep ended (`reached_end`, `stalled`, `point_cap`, `left_band`, `cancelled`),
    /// and whether it covered the band.
    pub end: String,
    /// Why the sweep ended, in words (`reached the band's end`, or why and where it stopped).
    pub end_reason: String,
    pub complete: bool,
    /// What the reader of this row must know: an incomplete sweep (with where and why), a peak
    /// on the band's edge, a level at which every contact sticks, errors taken against an
    /// incomplete full-order sweep.
    pub warnings: Vec<String>,
    /// The error the self-correcting sweep judged its final basis by: the largest `e_lin_1` at
    /// its checks, or the largest `e*_1` without checks (ROMs only; see `rom::adaptive`).
    pub worst_error: Option<f64>,
    /// Why its corrections ended (`within_threshold`, `max_corrections`, `no_progress`,
    /// `cancelled`; ROMs only): the two in the middle leave the basis above the threshold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corrections_end: Option<String>,
    /// The largest linearised error of the static contact displacement at the final pass'
    /// checks (ROMs whose condensed full order is small enough to check; see
    /// `rom::AdaptiveSweep::worst_static_error`). Not judged by the corrections; above
    /// `basis.error_threshold` the static term `X0` is poor and `warnings` says so.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub static_contact_error: Option<f64>,
    /// Whether the self-correcting sweep's result can be trusted (ROMs only): its final pass
    /// covered the band and every point's judged error is within the threshold
    /// (docs/formulation.md §10.7). The peak of a row that is not trusted is not reported
    /// (`peak_*` are empty) and `trust_reason` and `warnings` say why.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trusted: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trust_reason: Option<String>,
    /// A full-order row that gives its level's result in place of reduced sweeps that are not
    /// trusted or did not finish (`solvers.fall_back`, [`crate::fall_back`]): each such
    /// `solver: why`. Empty otherwise (and not in `summary.json`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stands_in_for: Vec<String>,
    /// The full-order sweep's time at this level over this ROM's (`sweep_seconds`, with its
    /// share of the shared basis) (ROMs only, when the full order ran).
    #[serde(default)]
    pub speed_up: Option<f64>,
    /// The parameter case (`[[cases]]`) of the row; empty (and not in `summary.json`) for a
    /// study without cases.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub case: String,
    /// The folds and branch points located along the sweep, in branch order
    /// (docs/formulation.md §6.6).
    #[serde(default)]
    pub events: Vec<EventRow>,
    /// The parts of the band the sweep stepped over at fixed frequency, with why.
    #[serde(default)]
    pub gaps: Vec<GapRow>,
}

/// A fold or branch point of a sweep, in the study's units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EventRow {
    /// `fold` or `branch_point`.
    pub kind: String,
    pub freq_hz: f64,
    /// The event lies within `freq_hz +- tolerance_hz` along the branch.
    pub tolerance_hz: f64,
    /// Index (0-based) of the sweep's point just before it, the row of the sweep's CSV.
    pub after_point: usize,
    /// First-harmonic amplitude of the first output there.
    pub amplitude: f64,
}

/// A part of the band a sweep stepped over at fixed frequency.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GapRow {
    pub from_hz: f64,
    pub to_hz: f64,
    /// Why the continuation could not go on there.
    pub reason: String,
}

/// The events and gaps of `res` as rows.
fn events_and_gaps(res: &SweepResult) -> (Vec<EventRow>, Vec<GapRow>) {
    let events = res
        .events
        .iter()
        .map(|e| EventRow { kind: e.kind.name().into(), freq_hz: e.omega / TWO_PI, tolerance_hz: e.omega_tolerance / TWO_PI, after_point: e.after_point, amplitude: e.amplitude })
        .collect();
    let gaps = res.gaps.iter().map(|g| GapRow { from_hz: g.from / TWO_PI, to_hz: g.to / TWO_PI, reason: g.reason.clone() }).collect();
    (events, gaps)
}

/// One basis of the error-vs-basis-size study (`basis.gamma_study`) with one ROM, solved at the
/// full-order resonance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BasisStudyRow {
    pub level: f64,
    pub solver: String,
    pub gamma: f64,
    /// Reduced unknowns per harmonic `n_0, n_1, ...` of the ROM (for FR on a band-condensed
    /// basis about twice the JP basis' `n_1`, see [`FrRom::new`]).
    pub sizes: Vec<usize>,
    /// Errors of `X1` and `X0` as [`SolverRow::error_x1`], `error_x0` (`None`: the ROM did not
    /// converge).
    pub error_x1: Option<f64>,
    pub error_x0: Option<f64>,
    /// Predicted `e*_1` and actual `e_1`.
    pub predicted_e1: Option<f64>,
    pub actual_e1: Option<f64>,
    /// The parameter case, as [`SolverRow::case`].
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub case: String,
}


/// Error vs basis size at one level: one basis predicted with the largest `gamma` of
/// `basis.gamma_study`, re-conditioned to each, and each ROM solved at the full-order
/// resonance `fo` (from zero: no sweep). A ROM that does not converge gives a row without errors.
#[allow(clippy::too_many_arguments)]
fn gamma_study(
    study: &Study,
    coords: &ContactCoordinates,
    condensed: &CondensedSystem,
    popts: &PredictionOptions,
    hopts: &HbmOptions,
    fo: &PointSolution,
    level: f64,
    kinds: &[(&str, RomKind)],
) -> Result<Vec<BasisStudyRow>> {
    let mut gammas = study.basis.gamma_study.clone();
    gammas.sort_by(f64::total_cmp);
    gammas.dedup();
    let g_max = *gammas.last().expect("a gamma");
    let (big, _) = predict_basis(coords, &PredictionOptions { gamma: g_max, ..popts.clone() })?;
    let mut out = Vec::new();
    for &g in &gammas {
        let basis = big.reconditioned(g)?;
        for &(name, kind) in kinds {
            let rom = reduced_model(kind, coords, Some(condensed), &basis)?;
            let mut row = BasisStudyRow { level, solver: name.to_string(), gamma: g, sizes: rom.layout().sizes.clone(), error_x1: None, error_x0: None, predicted_e1: None, actual_e1: None, case: String::new() };
            if let Ok(r) = solve_point(rom.as_ref(), fo.omega, None, hopts) {
                let j = study.response_output();
                row.error_x1 = Some(rel(r.output_amplitude(1, j), fo.output_amplitude(1, j)));
                row.error_x0 = Some(static_error(&r, fo));
                row.predicted_e1 = predicted_error(rom.as_ref(), r.omega, &r.z)?.get(1).copied();
                row.actual_e1 = actual_error(rom.as_ref(), r.omega, &r.z, fo)?.get(1).copied();
            }
            out.push(row);
        }
    }
    Ok(out)
}

/// What a study produced.
#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    pub model_dofs: usize,
    pub contacts: usize,
    pub stuck_resonance_hz: f64,
    /// Whether that stuck mode (the one nearest the band centre, which the levels and the basis
    /// prediction use) lies inside the band.
    pub stuck_mode_in_band: bool,
    /// `alpha_ST = |f_E^0| / |f_E^1|` at which the stuck resonance just reaches the friction
    /// limit ([`jprom::level`]); `None` when the contacts are closed by their preload alone.
    pub alpha_st: Option<f64>,
    /// `|f_E^1|` at the stuck limit (levels are relative to it).
    pub stuck_limit_force: f64,
    /// What the levels are relative to, in words ([`jprom::level::StuckLimit::describe`]).
    pub level_reference: String,
    /// The sweeps that did not cover the band, one line each (solver, level, why, where).
    pub incomplete: Vec<String>,
    /// What the reader of the whole study must know (the band holds no stuck mode).
    pub warnings: Vec<String>,
    pub build_seconds: f64,
    /// The threads the run had (`RAYON_NUM_THREADS`, else the machine's cores) and whether its
    /// linear-algebra kernels ran on one thread (`--reproducible`): without it, the numbers of
    /// a run are reproduced on the same number of threads only (README, "Reproducibility").
    pub threads: usize,
    pub reproducible: bool,
    /// Units of the CSV headers and amplitudes: `mm` and `mj` for the built-in blade, `lu` (the
    /// FE model's length unit) and `flu` (its force unit times `lu`) for an FE model.
    pub length_unit: String,
    pub energy_unit: String,
    pub rows: Vec<SolverRow>,
    /// The error-vs-basis-size study (`basis.gamma_study`), empty if not asked for.
    pub basis_study: Vec<BasisStudyRow>,
    /// Seconds spent on it (all levels).
    pub basis_study_seconds: f64,
    /// The response output (index into the model's outputs): the peak, the FRF plots and the
    /// errors of `X1` and `X0` are of it.
    pub response_output: usize,
    /// It in words (`the tip (flap)` for the blade's default, else `output j`), as the plots
    /// name it.
    pub response_name: String,
    /// Each case's JP basis shared by its levels and ROMs (empty without ROMs).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub shared_bases: Vec<SharedBasisSummary>,
    /// Per case and solver, the time over all levels and the full order's over it.
    pub totals: Vec<SolverTotal>,
    /// The parameter cases (`[[cases]]`), each with its own stuck mode and level reference;
    /// empty (and not in `summary.json`) for a study without cases. With cases, the fields
    /// above about the stuck mode and the level reference are the first case's.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub cases: Vec<CaseSummary>,
}

/// A case's shared JP basis ([`RunSummary::shared_bases`]).
#[derive(Clone, Debug, Serialize)]
pub struct SharedBasisSummary {
    #[serde(skip_serializing_if = "String::is_empty")]
    pub case: String,
    /// Basis sizes `n_h`, `gamma`, the contact-state patterns met and the samples.
    pub sizes: Vec<usize>,
    pub gamma: f64,
    pub patterns: usize,
    pub samples: usize,
    pub seconds: f64,
    /// The levels that share it: each ROM row's time counts `seconds / levels`.
    pub levels: usize,
    /// Why it could not be predicted (then `sizes` is empty).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failed: Option<String>,
}

/// A solver's time over all levels of a case ([`RunSummary::totals`]): for a ROM its sweeps,
/// checks, corrections and the shared basis once; `speed_up` is the full order's total over
/// it (ROMs, when the full order ran at every level).
#[derive(Clone, Debug, Serialize)]
pub struct SolverTotal {
    #[serde(skip_serializing_if = "String::is_empty")]
    pub case: String,
    pub solver: String,
    pub seconds: f64,
    pub speed_up: Option<f64>,
}

/// Speed-ups of the ROM rows against the full-order row of their level, and each solver's
/// total over the levels (`rows` of one case).
fn speed_ups(rows: &mut [SolverRow], case: &str) -> Vec<SolverTotal> {
    let fo: Vec<(f64, f64)> = rows.iter().filter(|r| r.solver.starts_with("FO") && r.points > 0).map(|r| (r.level, r.sweep_seconds)).collect();
    for r in rows.iter_mut().filter(|r| !r.solver.starts_with("FO") && r.points > 0 && r.sweep_seconds > 0.0) {
        r.speed_up = fo.iter().find(|f| f.0 == r.level).map(|f| f.1 / r.sweep_seconds);
    }
    let mut totals: Vec<SolverTotal> = Vec::new();
    for r in rows.iter() {
        match totals.iter_mut().find(|t| t.solver == r.solver) {
            Some(t) => t.seconds += r.sweep_seconds,
            None => totals.push(SolverTotal { case: case.to_string(), solver: r.solver.clone(), seconds: r.sweep_seconds, speed_up: None }),
        }
    }
    let levels = rows.iter().filter(|r| r.solver.starts_with("FO")).count();
    let fo_total = (fo.len() == levels && levels > 0).then(|| fo.iter().map(|f| f.1).sum::<f64>());
    for t in totals.iter_mut().filter(|t| !t.solver.starts_with("FO")) {
        t.speed_up = fo_total.map(|f| f / t.seconds);
    }
    totals
}

/// A parameter case's own figures ([`RunSummary::cases`]).
#[derive(Clone, Debug, Serialize)]
pub struct CaseSummary {
    pub name: String,
    /// Its overrides in words (`mu = 0.2, kn = 30000`).
    pub overrides: String,
    pub stuck_resonance_hz: f64,
    pub stuck_mode_in_band: bool,
    pub alpha_st: Option<f64>,
    pub stuck_limit_force: f64,
    pub level_reference: String,
}

/// Builds the study's model (no progress shown: [`build_model_with`]).
///
/// # Errors
/// As [`build_model_with`].
pub fn build_model(study: &Study) -> Result<Model> {
    build_model_with(study, Progress::Quiet)
}

/// Builds the study's model, showing the import and Craig-Bampton steps on `progress`.
///
/// # Errors
/// The blade builder's and Craig-Bampton's errors; for an FE model, as [`build_fe_model`].
pub fn build_model_with(study: &Study, progress: Progress) -> Result<Model> {
    build_case_models(study, &[CaseSpec::base()], progress).map(|mut m| m.remove(0))
}

/// The models of the parameter `cases` (see [`CaseSpec`]), on one Craig-Bampton reduction: the
/// contact laws enter neither the FE matrices nor the reduction (the contact nodes are its
/// boundary), so each case's model is the reduced model with the case's contact laws, its
/// damping and its static load. The built-in blade's pre-twist is scaled to its target preload
/// in the linear stuck state, which depends on the contact stiffnesses: for a case with other
/// `kt1`, `kt2` or `kn` the blade is assembled again (no second reduction) for its pre-twist.
/// A case without overrides gives the model of the study as written, bit for bit.
///
/// # Errors
/// As [`build_model_with`].
pub fn build_case_models(study: &Study, cases: &[CaseSpec], progress: Progress) -> Result<Vec<Model>> {
    build_case_models_placed(study, cases, progress).map(|(models, _)| models)
}

/// [`build_case_models`], and the coordinates of the contact nodes in the models' contact order
/// (empty when the FE model has no node coordinates).
fn build_case_models_placed(study: &Study, cases: &[CaseSpec], progress: Progress) -> Result<(Vec<Model>, Vec<[f64; 3]>)> {
    let centre = TWO_PI * 0.5 * (study.band.hz_start + study.band.hz_end);
    let named = |case: &CaseSpec, what: &str| if case.name.is_empty() { what.to_string() } else { format!("case {}: {what}", case.name) };
    match &study.model {
        ModelSpec::Blade { refinement, cb_modes, cache, damping, contact } => {
            let params = BladeParams { refinement: *refinement, mu: contact.mu, kt1: contact.kt1, kt2: contact.kt2, kn: contact.kn, ..Default::default() };
            let cache_file = cache.then(|| study.output.dir.join(BLADE_MODEL_CACHE));
            let (undamped, positions) = blade_model(&params, *cb_modes, cache_file.as_deref(), progress)?;
            let n_static = undamped.excitation.static_force.len();
            let mut models = Vec::with_capacity(cases.len());
            for case in cases {
                let c = case.contact(contact);
                let case_params = BladeParams { mu: c.mu, kt1: c.kt1, kt2: c.kt2, kn: c.kn, ..params.clone() };
                let law = case_params.contact_law();
                let mut model = undamped.clone();
                for k in model.contacts.iter_mut() {
                    k.law = law.clone();
                }
                if (c.kt1, c.kt2, c.kn) != (contact.kt1, contact.kt2, contact.kn) {
                    let step = progress.step(named(case, "the blade's pre-twist for its contact stiffnesses"));
                    let fe_case = BuiltinBlade::build(&case_params)?;
                    step.done();
                    model.excitation.static_force = boundary_load(&fe_case.static_force, &fe_case.boundary_dofs(), n_static).map_err(|e| with_key(&format!("cases ({})", case.name), e))?;
                }
                model.validate()?;
                if let Some(scale) = case.static_scale {
                    model.excitation.static_force.iter_mut().for_each(|f| *f *= scale);
                }
                case.damping(damping).apply(&mut model, centre).map_err(|e| with_key("model.damping", e))?;
                models.push(model);
            }
            Ok((models, positions))
        }
        ModelSpec::Fe(_) => {
            let read = read_fe_model(study, progress)?;
            let positions: Vec<[f64; 3]> = read.reduction.contacts.iter().map(|c| read.fe.node(c.node).ok().and_then(|n| n.coords)).collect::<Option<Vec<_>>>().unwrap_or_default();
            let undamped = reduce_fe_model_undamped(&read, progress)?;
            let mut models = Vec::with_capacity(cases.len());
            for case in cases {
                let mut model = undamped.clone();
                for k in model.contacts.iter_mut() {
                    if let ContactLaw::Friction3D { kt1, kt2, kn, mu, .. } = &mut k.law {
                        *mu = case.mu.unwrap_or(*mu);
                        *kt1 = case.kt1.unwrap_or(*kt1);
                        *kt2 = case.kt2.unwrap_or(*kt2);
                        *kn = case.kn.unwrap_or(*kn);
                    }
                }
                if let Some(scale) = case.static_scale {
                    model.excitation.static_force.iter_mut().for_each(|f| *f *= scale);
                }
                case.damping(&read.damping).apply(&mut model, centre).map_err(|e| with_key("model.damping", e))?;
                models.push(model);
            }
            Ok((models, positions))
        }
    }
}

/// The built-in blade's cached Craig-Bampton model (`model.cache`, [`BLADE_MODEL_CACHE`]): the
/// reduced model, undamped, with the study's contact law and pre-twist, the contact nodes'
/// coordinates, and the key it was built for.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BladeModelCache {
    /// What the model depends on: the blade's parameters, the Craig-Bampton modes and the
    /// jprom version that built it ([`blade_cache_key`]). A file with another key is rebuilt.
    key: String,
    positions: Vec<[f64; 3]>,
    model: Model,
}

const BLADE_CACHE_KIND: &str = "blade_model_cache";

/// Everything the built-in blade's reduced model depends on, in words.
fn blade_cache_key(params: &BladeParams, cb_modes: usize) -> String {
    format!("jprom {}; cb_modes {cb_modes}; blade {params:?}", env!("CARGO_PKG_VERSION"))
}

/// The built-in blade's Craig-Bampton model, undamped, with `params`' contact law and
/// pre-twist, and its contact nodes' coordinates: read from `cache` when that file holds the
/// model of the same key, else built (and then written to `cache`). A cache file that cannot be
/// read or holds another key is rebuilt and replaced, and the progress lines say so; one that
/// cannot be written is an error (the study says where), never a silent miss.
fn blade_model(params: &BladeParams, cb_modes: usize, cache: Option<&Path>, progress: Progress) -> Result<(Model, Vec<[f64; 3]>)> {
    let key = blade_cache_key(params, cb_modes);
    if let Some(path) = cache.filter(|p| p.exists()) {
        let step = progress.step(format!("Craig-Bampton model from {}", path.display()));
        match jprom::io::load_json::<BladeModelCache>(BLADE_CACHE_KIND, path) {
            Ok(c) if c.key == key && c.model.validate().is_ok() && c.positions.len() == c.model.contacts.len() => {
                step.done_with(&format!(", {} DoFs", c.model.n_dof()));
                return Ok((c.model, c.positions));
            }
            Ok(_) => step.done_with(": built for other parameters or another jprom, rebuilt"),
            Err(e) => step.done_with(&format!(": not usable ({e}), rebuilt")),
        }
    }
    let step = progress.step(format!("building the built-in blade (refinement {})", params.refinement));
    let fe = BuiltinBlade::build(params)?;
    step.done_with(&format!(", {} DoFs", fe.n_dof()));
    let positions: Vec<[f64; 3]> = fe.contacts.iter().map(|c| fe.coords[c.node]).collect();
    let step = progress.step(format!("Craig-Bampton ({cb_modes} fixed-interface modes)"));
    let model = fe.reduce(cb_modes)?.to_model(Damping::default())?;
    step.done();
    if let Some(path) = cache {
        let step = progress.step(format!("keeping the Craig-Bampton model in {}", path.display()));
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| JpError::Io { path: dir.display().to_string(), reason: format!("model.cache: {e}") })?;
        }
        let doc = BladeModelCache { key, positions, model };
        // written beside and renamed, so that a reader never sees half a file (and two
        // builders, threads or processes, never write into one)
        static WRITES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp = path.with_extension(format!("json.{}-{n}.tmp", std::process::id()));
        let written = jprom::io::save_json(BLADE_CACHE_KIND, &doc, &tmp)
            .and_then(|()| std::fs::rename(&tmp, path).map_err(|e| JpError::Io { path: path.display().to_string(), reason: format!("model.cache: {e}") }));
        if written.is_err() {
            // no half-written file left beside the cache
            let _ = std::fs::remove_file(&tmp);
        }
        written?;
        step.done();
        return Ok((doc.model, doc.positions));
    }
    Ok((model, positions))
}

/// A load `f` on the FE DoFs that acts on the `boundary` DoFs only, in reduced coordinates of
/// `n_reduced` (boundary first, then the modal ones, where it is zero): exact without the
/// constraint modes, as the blade's own reduction takes it.
fn boundary_load(f: &[f64], boundary: &[usize], n_reduced: usize) -> Result<Vec<f64>> {
    let mut on_boundary = vec![false; f.len()];
    for &d in boundary {
        on_boundary[d] = true;
    }
    if f.iter().zip(&on_boundary).any(|(v, b)| *v != 0.0 && !b) {
        return Err(JpError::invalid("static load", "acts on DoFs that are not boundary DoFs of the reduction"));
    }
    let mut out: Vec<f64> = boundary.iter().map(|&d| f[d]).collect();
    out.resize(n_reduced, 0.0);
    Ok(out)
}

/// Prefixes an error with the study key it came from (file reading).
fn with_key(key: &str, e: JpError) -> JpError {
    match e {
        JpError::Io { path, reason } => JpError::Io { path, reason: format!("key '{key}': {reason}") },
        JpError::Parse { path, line, reason } => JpError::Parse { path, line, reason: format!("key '{key}': {reason}") },
        other => JpError::invalid(key, other.to_string()),
    }
}

/// A Matrix Market study's model ([`build_fe_model`], no progress shown).
///
/// # Errors
/// As [`build_fe_model`].
pub fn build_matrix_market_model(study: &Study) -> Result<Model> {
    build_fe_model(study, Progress::Quiet)
}

/// An FE study's model: [`read_fe_model`], then [`reduce_fe_model`].
///
/// # Errors
/// As [`read_fe_model`] and [`reduce_fe_model`].
pub fn build_fe_model(study: &Study, progress: Progress) -> Result<Model> {
    reduce_fe_model(study, &read_fe_model(study, progress)?, progress)
}

/// An FE study's model before reduction: the FE model on its supports, where the study puts
/// contacts, loads and outputs on it, and the damping the study asks for.
pub struct FeStudyModel {
    pub fe: FeModel,
    /// The contacts, loads, outputs and fixed-interface modes of the Craig-Bampton reduction.
    pub reduction: Reduction,
    pub damping: DampingSpec,
}

/// Reads an FE study's model (Matrix Market `M`, `K` and the DoF map, or a CalculiX job) and
/// places the contacts, loads and outputs on node ids or node sets ([`placement`]), showing the
/// import on `progress` (`jprom run` reduces it next, `jprom modes` lists its frequencies).
///
/// # Errors
/// File errors name the key (`model.mass`, `model.deck`, ...), unknown node ids or sets name
/// the key listing them (`model.contacts[0].nodes`, ...); [`JpError::InvalidValue`] for a
/// study whose model is not an FE model.
pub fn read_fe_model(study: &Study, progress: Progress) -> Result<FeStudyModel> {
    let size = |p: &Path| std::fs::metadata(p).map(|m| format!(", {:.1} MB", m.len() as f64 / 1e6)).unwrap_or_default();
    let ModelSpec::Fe(spec) = &study.model else {
        return Err(JpError::invalid("model.kind", "not an FE model"));
    };
    let damping = spec.damping.clone();
    let (mut fe, nodes) = match &spec.source {
        FeSource::MatrixMarket { mass, stiffness, dof_map } => {
            let step = progress.step(format!("reading model.stiffness ({}{})", stiffness.display(), size(stiffness)));
            let k = read_symmetric_matrix_market(stiffness).map_err(|e| with_key("model.stiffness", e))?;
            step.done_with(&format!(", {} x {}, {} stored entries", k.nrows(), k.ncols(), k.compute_nnz()));
            let step = progress.step(format!("reading model.mass ({}{})", mass.display(), size(mass)));
            let m = read_symmetric_matrix_market(mass).map_err(|e| with_key("model.mass", e))?;
            step.done();
            let n = k.nrows();
            if k.ncols() != n {
                return Err(JpError::invalid("model.stiffness", format!("{}: not square ({} x {})", stiffness.display(), n, k.ncols())));
            }
            if m.nrows() != n || m.ncols() != n {
                return Err(JpError::invalid("model.mass", format!("{}: {} x {}, but the stiffness is {n} x {n}", mass.display(), m.nrows(), m.ncols())));
            }
            let map = DofMap::load(dof_map).map_err(|e| with_key("model.dof_map", e))?;
            if map.n_dof != n {
                return Err(JpError::invalid("model.dof_map", format!("{}: n_dof {} but the matrices are {n} x {n}", dof_map.display(), map.n_dof)));
            }
            let fe = FeModel::from_dof_map(k, m, &map).map_err(|e| with_key("model.dof_map", e))?;
            let nodes = ModelNodes::of_fe_model(&fe, None, format!("the DoF map {}", dof_map.display()));
            (fe, nodes)
        }
        FeSource::Calculix { deck } => {
            let files = CalculixFiles::of_job(deck);
            let step = progress.step(format!("reading the CalculiX job {} (.sti{}, .mas, .dof, deck)", files.inp.display(), size(&files.sti)));
            let ccx = read_model_files(&files).map_err(|e| with_key("model.deck", e))?;
            step.done_with(&format!(", {} DoFs", ccx.n()));
            let fe = FeModel::from_calculix(&ccx).map_err(|e| with_key("model.deck", e))?;
            let nodes = ModelNodes::of_fe_model(&fe, Some(ccx.node_sets.clone()), format!("the CalculiX job {}", files.inp.display())).with_mesh_nodes(ccx.coords.keys().copied());
            (fe, nodes)
        }
    };
    if let Some(path) = &damping.matrix {
        let step = progress.step(format!("reading model.damping.matrix ({}{})", path.display(), size(path)));
        let c = read_symmetric_matrix_market(path).map_err(|e| with_key("model.damping.matrix", e))?;
        fe.set_damping(c).map_err(|e| with_key("model.damping.matrix", e))?;
        step.done();
    }
    let reduction = placement(study, &nodes).map_err(|(key, reason)| JpError::invalid(key, reason))?;
    Ok(FeStudyModel { fe, reduction, damping })
}

/// Reduces a read FE study model by Craig-Bampton keeping the contact nodes (in
/// `[[model.contacts]]` order), then the loaded nodes, then the output nodes, plus `cb_modes`
/// fixed-interface modes, showing the step on `progress`. Loads act on boundary DoFs only, so
/// the reduced loads are exact without the constraint modes (which are not kept).
///
/// # Errors
/// Craig-Bampton's and [`Model::new`]'s errors.
pub fn reduce_fe_model(study: &Study, read: &FeStudyModel, progress: Progress) -> Result<Model> {
    let centre = TWO_PI * 0.5 * (study.band.hz_start + study.band.hz_end);
    let mut model = reduce_fe_model_undamped(read, progress)?;
    read.damping.apply(&mut model, centre).map_err(|e| with_key("model.damping", e))?;
    Ok(model)
}

/// [`reduce_fe_model`] before the study's damping (an FE damping matrix is reduced with the
/// model): what the parameter cases share.
///
/// # Errors
/// As [`reduce_fe_model`].
pub fn reduce_fe_model_undamped(read: &FeStudyModel, progress: Progress) -> Result<Model> {
    let FeStudyModel { fe, reduction: spec, .. } = read;
    let step = progress.step(format!("Craig-Bampton: {} DoFs, {} boundary nodes, {} fixed-interface modes", fe.n_dof(), spec.contacts.len() + spec.static_forces.len() + spec.harmonic_forces.len(), spec.cb_modes));
    let model = fe.reduce(spec, Damping::default())?;
    step.done_with(&format!(", {} reduced DoFs", model.n_dof()));
    Ok(model)
}

/// The row of a solver that failed before giving a sweep (its error in the warnings).
fn failed_row(level: f64, solver: &str, sizes: Vec<usize>, e: &JpError) -> SolverRow {
    failed_row_because(level, solver, sizes, &e.to_string())
}

/// The row of a solver that failed, `why` in its end reason and warnings (`failed: {why}`).
fn failed_row_because(level: f64, solver: &str, sizes: Vec<usize>, why: &str) -> SolverRow {
    SolverRow {
        level,
        solver: solver.into(),
        sizes,
        points: 0,
        sweep_seconds: 0.0,
        basis_seconds: 0.0,
        corrections: 0,
        peak_hz: f64::NAN,
        peak_x1: f64::NAN,
        peak_x0: f64::NAN,
        error_x1: None,
        error_x0: None,
        predicted_e1: None,
        actual_e1: None,
        energy_error: None,
        end: "failed".into(),
        end_reason: format!("failed: {why}"),
        complete: false,
        warnings: vec![format!("failed: {why}")],
        worst_error: None,
        corrections_end: None,
        static_contact_error: None,
        trusted: None,
        trust_reason: None,
        stands_in_for: Vec::new(),
        speed_up: None,
        case: String::new(),
        events: Vec::new(),
        gaps: Vec::new(),
    }
}

/// Warnings about a sweep and its peak `p`: the sweep did not cover the band (why and where),
/// or the peak is the sweep's lowest- or highest-frequency point (the band's edge, or where an
/// incomplete sweep stopped): then the resonance may lie outside what was swept.
fn sweep_warnings(res: &SweepResult, p: &PointSolution, band: (f64, f64)) -> Vec<String> {
    let mut w = Vec::new();
    if !res.reached_end() {
        w.push(format!("the sweep did not cover the band: {}", res.failure.clone().unwrap_or_else(|| res.end.name().into())));
    }
    if !res.gaps.is_empty() {
        let spans: Vec<String> = res.gaps.iter().map(|g| format!("{:.3}-{:.3} Hz", g.from / TWO_PI, g.to / TWO_PI)).collect();
        w.push(format!("the sweep stepped over {} part(s) of the band at fixed frequency, where the continuation could not go on: {}", res.gaps.len(), spans.join(", ")));
    }
    if let Some(edge) = peak_on_edge(res, p, band) {
        w.push(format!("the peak is on {edge} ({:.3} Hz): the resonance may lie outside the swept range", p.omega / TWO_PI));
    }
    w
}

/// Where the peak `p` lies if it is an end of what the sweep covered: `the band edge` or `the
/// last point of an incomplete sweep`; `None` for a peak inside.
fn peak_on_edge(res: &SweepResult, p: &PointSolution, band: (f64, f64)) -> Option<&'static str> {
    let (lo, hi) = (band.0.min(band.1), band.0.max(band.1));
    let tol = 1e-9 * (hi - lo);
    if (p.omega - lo).abs() <= tol || (p.omega - hi).abs() <= tol {
        return Some("the band edge");
    }
    let w_min = res.points.iter().map(|q| q.omega).fold(f64::INFINITY, f64::min);
    let w_max = res.points.iter().map(|q| q.omega).fold(f64::NEG_INFINITY, f64::max);
    if p.omega <= w_min + tol || p.omega >= w_max - tol {
        return Some(if res.reached_end() { "the band edge" } else { "the last point of an incomplete sweep" });
    }
    None
}

/// Why a sweep ended, in words: `reached the band's end`, or the sweep's own account of why and
/// where it stopped.
fn end_reason(res: &SweepResult) -> String {
    if res.reached_end() {
        "reached the band's end".into()
    } else {
        res.failure.clone().unwrap_or_else(|| format!("stopped: {}", res.end.name()))
    }
}

/// The point of largest first-harmonic amplitude of output `j` (the study's response).
fn peak(points: &[PointSolution], j: usize) -> Option<&PointSolution> {
    points.iter().max_by(|a, b| a.output_amplitude(1, j).total_cmp(&b.output_amplitude(1, j)))
}

fn state_counts(p: &PointSolution) -> [usize; 3] {
    let mut c = [0usize; 3];
    for cy in &p.contact_cycles {
        for s in &cy.states {
            c[match s {
                ContactState::Stick => 0,
                ContactState::Slip => 1,
                ContactState::Separated => 2,
            }] += 1;
        }
    }
    c
}

/// The units of the CSV headers and the summary: (length, energy). The built-in blade is in
/// mm, tonne, s (N, MPa): lengths in mm, energies in mJ (N mm). An FE model's units are its
/// FE code's: `lu` is its length unit, `flu` its force unit times `lu`.
pub fn units(study: &Study) -> (&'static str, &'static str) {
    match study.model {
        ModelSpec::Blade { .. } => ("mm", "mj"),
        _ => ("lu", "flu"),
    }
}

/// The harmonic count `H` of a point (its outputs hold `2H + 1` coefficients per output).
fn harmonics_of(p: &PointSolution) -> usize {
    p.outputs.len().checked_div(p.n_outputs).map_or(0, |k| k.saturating_sub(1) / 2)
}

/// A sweep's CSV ([`write_csv_rows`]) in memory: a unit's files are written when the units are
/// merged ([`crate::units`]), in unit order, by the process that writes the summary.
fn csv_bytes(res: &SweepResult, errors: Option<(&[Vec<f64>], &[f64])>, units: (&str, &str)) -> Result<Vec<u8>> {
    let mut buf = Vec::new();
    write_csv_rows(&mut buf, res, errors, units).map_err(|e| JpError::Io { path: "(csv in memory)".into(), reason: e.to_string() })?;
    Ok(buf)
}

/// One row per sweep point: `freq_hz`, then per output `j` the static term `x0_out{j}` (signed)
/// and the amplitudes `x{h}_out{j}` of every harmonic `h = 1..H` (unit suffix: `_mm` or `_lu`),
/// `e_star_0..e_star_H` and the self-correcting sweep's judged error `judged_e1` (ROMs; `inf`
/// where no full-order solution was reached from the point), Newton iterations, residual, stick/slip/separated AFT samples,
/// the dissipated energy per cycle (`_mj` or `_flu`), what the branch meets between this point
/// and the next (`events_after`: `fold`, `branch_point`, `gap`, joined by `+`; empty for
/// nothing) and the sweep's end reason.
fn write_csv_rows(f: &mut dyn Write, res: &SweepResult, errors: Option<(&[Vec<f64>], &[f64])>, (len, energy): (&str, &str)) -> std::io::Result<()> {
    let n_out = res.points.first().map(|p| p.n_outputs).unwrap_or(0);
    let h_max = res.points.first().map(harmonics_of).unwrap_or(0);
    let mut header = String::from("freq_hz");
    for j in 0..n_out {
        for h in 0..=h_max {
            header.push_str(&format!(",x{h}_out{j}_{len}"));
        }
    }
    for h in 0..=h_max {
        header.push_str(&format!(",e_star_{h}"));
    }
    header.push_str(",judged_e1");
    header.push_str(&format!(",iterations,residual,stick_samples,slip_samples,separated_samples,dissipated_energy_{energy},events_after,sweep_end"));
    writeln!(f, "{header}")?;
    for (i, p) in res.points.iter().enumerate() {
        let mut line = format!("{:.6}", p.omega / TWO_PI);
        for j in 0..n_out {
            line.push_str(&format!(",{:.9e}", p.output_coeff(0, j)));
            for h in 1..=h_max {
                line.push_str(&format!(",{:.9e}", p.output_amplitude(h, j)));
            }
        }
        let e = errors.and_then(|e| e.0.get(i));
        for h in 0..=h_max {
            match e.and_then(|e| e.get(h)) {
                Some(v) => line.push_str(&format!(",{v:.4e}")),
                None => line.push(','),
            }
        }
        match errors.and_then(|e| e.1.get(i)) {
            Some(v) if v.is_finite() => line.push_str(&format!(",{v:.4e}")),
            Some(_) => line.push_str(",inf"),
            None => line.push(','),
        }
        let c = state_counts(p);
        let mut after: Vec<&str> = res.events.iter().filter(|e| e.after_point == i).map(|e| e.kind.name()).collect();
        if res.points.get(i + 1).is_some_and(|q| res.gaps.iter().any(|g| g.from == p.omega && g.to == q.omega)) {
            after.push("gap");
        }
        line.push_str(&format!(",{},{:.3e},{},{},{},{:.6e},{},{}", p.iterations, p.residual_norm, c[0], c[1], c[2], p.dissipated_energy(), after.join("+"), res.end.name()));
        writeln!(f, "{line}")?;
    }
    Ok(())
}

fn write_basis_study_csv(path: &Path, rows: &[BasisStudyRow]) -> Result<()> {
    jprom::io::write_file(path, |f| write_basis_study_rows(f, rows))
}

fn write_basis_study_rows(f: &mut dyn Write, rows: &[BasisStudyRow]) -> std::io::Result<()> {
    writeln!(f, "level,solver,gamma,n_0,n_1,error_x1,error_x0,e_star_1,e_1")?;
    let opt = |v: Option<f64>| v.map(|x| format!("{x:.4e}")).unwrap_or_default();
    for r in rows {
        let n = |h: usize| r.sizes.get(h).copied().unwrap_or(0);
        writeln!(
            f,
            "{:e},{},{:e},{},{},{},{},{},{}",
            r.level,
            r.solver,
            r.gamma,
            n(0),
            n(1),
            opt(r.error_x1),
            opt(r.error_x0),
            opt(r.predicted_e1),
            opt(r.actual_e1)
        )?;
    }
    Ok(())
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// The error of the static term `X0` of `r` against the full-order point `fo`: the largest
/// difference over the outputs relative to the largest `|X0|` of the full order over them (the
/// response output's own `X0` can be near zero, as the blade's tip flap under its pre-twist
/// couple, where a relative error means nothing).
fn static_error(r: &PointSolution, fo: &PointSolution) -> f64 {
    let outputs = r.n_outputs.min(fo.n_outputs);
    let scale = (0..outputs).map(|k| fo.output_coeff(0, k).abs()).fold(0.0, f64::max);
    let diff = (0..outputs).map(|k| (r.output_coeff(0, k) - fo.output_coeff(0, k)).abs()).fold(0.0, f64::max);
    diff / scale.max(f64::MIN_POSITIVE)
}

/// Energy errors of the ROM rows, relative to the largest energy per contact node met in the
/// study (never round-off: a stuck contact dissipates exactly zero); a level without slip says
/// so. `energies_at_peak`: per ROM row (index into `rows`), the FO and ROM energies per contact.
fn energy_errors(rows: &mut [SolverRow], energies_at_peak: &[(usize, Vec<f64>, Vec<f64>)]) {
    let largest = energies_at_peak.iter().flat_map(|(_, a, b)| a.iter().chain(b)).fold(0.0f64, |m, &e| m.max(e));
    for (i, fo_w, rom_w) in energies_at_peak {
        if fo_w.iter().all(|&e| e == 0.0) && rom_w.iter().all(|&e| e == 0.0) {
            rows[*i].warnings.push("every contact sticks at the full-order resonance: no friction dissipation".into());
        } else if !rom_w.is_empty() && largest > 0.0 {
            rows[*i].energy_error = Some(rom_w.iter().zip(fo_w).map(|(a, b)| (a - b).abs() / largest).fold(0.0, f64::max));
        }
    }
}

/// The response output in words, for plot labels: `the tip (flap)` for the blade's default,
/// else `output j`.
fn response_words(study: &Study) -> String {
    let j = study.response_output();
    if matches!(study.model, ModelSpec::Blade { .. }) && j == super::study::BLADE_TIP_FLAP_OUTPUT {
        "the tip (flap)".into()
    } else {
        format!("output {j}")
    }
}

/// The study's figures: FRF and dissipated energy per level, predicted vs actual error and
/// error vs level over the levels, error vs basis size per level (gamma study).
fn write_study_plots(study: &Study, out_dir: &Path, summary: &CaseRows, plots: &CasePlots) -> Result<()> {
    let CasePlots { frf: frf_series, frf0: frf0_series, energy: energy_series, e_star: e_star_series, .. } = plots;
    let err_points = plots.err_points.clone();
    let h = study.hbm.harmonics;
    let (len_unit, energy_unit) = units(study);
    // a case's files are prefixed with its name
    let file = |name: String| out_dir.join(format!("{}{name}", summary.prefix));
    let response = response_words(study);
    let x1_label = format!("|X1| at {response} [{len_unit}]");
    for (level, series) in frf_series {
        let title = format!("First harmonic at {response}, alpha = alpha_ST x {level:e}, H = {h}");
        let spec = PlotSpec { title: &title, x_label: "frequency [Hz]", y_label: &x1_label, log_x: false, log_y: false, diagonal: false, legend: Legend::UpperRight };
        write_plot(&file(format!("frf_alpha_ST_x{level:e}.svg")), &spec, series)?;
    }
    if study.forcing.levels.len() > 1 && !plots.levels.is_empty() {
        let title = format!("First harmonic per unit forcing at every level (|X1| / s, s the dynamic scale), H = {h}");
        let y_label = format!("|X1| / s at {response} [{len_unit}]");
        let spec = PlotSpec { title: &title, x_label: "frequency [Hz]", y_label: &y_label, log_x: false, log_y: true, diagonal: false, legend: Legend::UpperRight };
        write_plot(&file("frf_levels.svg".to_string()), &spec, &plots.levels)?;
    }
    let x0_label = format!("X0 at {response} [{len_unit}]");
    for (level, series) in frf0_series {
        let title = format!("Static term at {response}, alpha = alpha_ST x {level:e}, H = {h}");
        let spec = PlotSpec { title: &title, x_label: "frequency [Hz]", y_label: &x0_label, log_x: false, log_y: false, diagonal: false, legend: Legend::UpperRight };
        write_plot(&file(format!("frf_x0_alpha_ST_x{level:e}.svg")), &spec, series)?;
    }
    for (level, series) in energy_series {
        let stuck = series.iter().all(|s| s.points.iter().all(|p| p.1 == 0.0));
        let title = if stuck {
            format!("Every contact sticks at the FO resonance (no dissipation), alpha_ST x {level:e}, H = {h}")
        } else {
            format!("Dissipated energy per contact node at the FO resonance, alpha_ST x {level:e}, H = {h}")
        };
        let energy_label = format!("energy per cycle [{energy_unit}]");
        let spec = PlotSpec { title: &title, x_label: "contact node (study order)", y_label: &energy_label, log_x: false, log_y: false, diagonal: false, legend: Legend::MiddleRight };
        write_plot(&file(format!("energy_alpha_ST_x{level:e}.svg")), &spec, series)?;
        // beside it, where those nodes are: the full order's energies on the contact nodes
        if let Some(fo) = series.iter().find(|s| s.label.starts_with("FO")).filter(|s| s.points.len() == plots.positions.len()) {
            let energies: Vec<f64> = fo.points.iter().map(|p| p.1).collect();
            let title = format!("FO dissipated energy on the contact nodes at the FO resonance, alpha_ST x {level:e}, H = {h}");
            write_energy_map(&file(format!("energy_map_alpha_ST_x{level:e}.svg")), &title, &plots.positions, &plots.frames, &energies, &energy_label)?;
        }
    }
    if !err_points.is_empty() {
        // the gamma study's points first (light), the levels' over them
        let mut series: Vec<Series> = Vec::new();
        for solver in ["FR", "NLR"] {
            let pts: Vec<(f64, f64)> = summary
                .basis_study
                .iter()
                .filter(|r| r.solver == solver)
                .filter_map(|r| Some((r.actual_e1?, r.predicted_e1?)))
                .collect();
            if !pts.is_empty() {
                let c = solver_color(solver);
                let light = RGBColor(c.0 / 2 + 128, c.1 / 2 + 128, c.2 / 2 + 128);
                let marker = if solver == "FR" { Marker::Square } else { Marker::Circle };
                series.push(Series::markers(format!("{solver}, gamma study"), pts).styled(Style { color: light, dash: Dash::None, width: 1, marker, max_markers: 0 }));
            }
        }
        series.extend(err_points.into_iter().map(|(l, p)| Series::solver(format!("{l}, at each level"), p, false)));
        let title = format!("Predicted e*_1 vs actual e_1 at the FO resonance (all levels), H = {h}");
        let spec = PlotSpec { title: &title, x_label: "actual e_1", y_label: "predicted e*_1", log_x: true, log_y: true, diagonal: true, legend: Legend::LowerRight };
        write_plot(&file("predicted_vs_actual_error.svg".to_string()), &spec, &series)?;
        let mut by_solver: Vec<Series> = Vec::new();
        for r in summary.rows.iter().filter(|r| r.error_x1.is_some()) {
            let p = (r.level, r.error_x1.unwrap().max(1e-16));
            match by_solver.iter_mut().find(|s| s.label == r.solver) {
                Some(s) => s.points.push(p),
                None => {
                    let dash = if r.solver == "FR" { Dash::Dashed } else { Dash::Solid };
                    let marker = if r.solver == "FR" { Marker::Square } else { Marker::Triangle };
                    by_solver.push(Series::solver(r.solver.clone(), vec![p], true).styled(Style { color: solver_color(&r.solver), dash, width: 2, marker, max_markers: 0 }))
                }
            }
        }
        let title = format!("Error of |X1| at the FO resonance vs excitation level, H = {h}");
        let spec = PlotSpec { title: &title, x_label: "alpha / alpha_ST", y_label: "relative error of X1", log_x: true, log_y: true, diagonal: false, legend: Legend::UpperRight };
        write_plot(&file("error_vs_level.svg".to_string()), &spec, &by_solver)?;
    }
    for (level, series) in e_star_series.iter().filter(|(_, s)| !s.is_empty()) {
        let mut series = series.clone();
        let (lo, hi) = (study.band.hz_start, study.band.hz_end);
        let threshold = study.basis.error_threshold;
        series.push(Series::line(format!("threshold {threshold}"), vec![(lo, threshold), (hi, threshold)]).styled(Style { color: RGBColor(120, 120, 120), dash: Dash::Dashed, width: 1, marker: Marker::None, max_markers: 0 }));
        let title = format!("Predicted error e*_1 along the reduced sweeps, linearised error at the checks, alpha_ST x {level:e}, H = {h}");
        let spec = PlotSpec { title: &title, x_label: "frequency [Hz]", y_label: "predicted e*_1 (lines), linearised e_lin_1 (circles)", log_x: false, log_y: true, diagonal: false, legend: Legend::UpperRight };
        write_plot(&file(format!("predicted_error_vs_frequency_alpha_ST_x{level:e}.svg")), &spec, &series)?;
    }
    for &level in &study.forcing.levels {
        let rows: Vec<&BasisStudyRow> = summary.basis_study.iter().filter(|r| r.level == level).collect();
        if rows.is_empty() {
            continue;
        }
        // per solver one colour: |X1| error (line), actual e_1 (line + squares), e*_1 (circles)
        let mut series: Vec<Series> = Vec::new();
        for (color, solver) in [(1usize, "FR"), (2, "NLR")] {
            for (style, what, get) in [
                (0, "error of |X1|", (|r: &BasisStudyRow| r.error_x1) as fn(&BasisStudyRow) -> Option<f64>),
                (1, "actual e_1", |r: &BasisStudyRow| r.actual_e1),
                (2, "predicted e*_1", |r: &BasisStudyRow| r.predicted_e1),
            ] {
                let pts: Vec<(f64, f64)> = rows.iter().filter(|r| r.solver == solver).filter_map(|r| get(r).map(|e| (r.sizes.get(1).copied().unwrap_or(0) as f64, e.max(1e-16)))).collect();
                if !pts.is_empty() {
                    let label = format!("{solver}: {what}");
                    let s = match style {
                        0 => Series::line(label, pts),
                        1 => Series::line_and_markers(label, pts),
                        _ => Series::markers(label, pts),
                    };
                    series.push(s.color(color));
                }
            }
        }
        let title = format!("Error at the FO resonance vs basis size (gamma study), alpha_ST x {level:e}, H = {h}");
        let spec = PlotSpec { title: &title, x_label: "n_1 (first-harmonic basis size)", y_label: "relative error", log_x: false, log_y: true, diagonal: false, legend: Legend::UpperRight };
        write_plot(&file(format!("error_vs_basis_size_alpha_ST_x{level:e}.svg")), &spec, &series)?;
    }

    Ok(())
}

/// Runs the study and writes its results into `out_dir`; `show_progress` draws progress bars
/// on stderr.
///
/// # Errors
/// Model building, solver and I/O errors.
pub fn run_study(study: &Study, out_dir: &Path, show_progress: bool) -> Result<RunSummary> {
    run_study_with(study, out_dir, if show_progress { Progress::Bars } else { Progress::Quiet })
}

/// The full-order (condensed) sweep of one level: its CSV, its row, its curves. `None` when it
/// failed or found no point (the failure is in its row; the ROMs still run).
fn full_order_level(run: &Run, level: f64, tag: &str, condensed: &CondensedSystem, c: &mut Collected, series: &mut LevelSeries) -> Result<Option<FoPeak>> {
    let mut bar = run.progress.points(format!("FO sweep, alpha_ST x {level:e}"));
    let t = Instant::now();
    let res = sweep(condensed, &run.sopts, &run.hopts, &mut |p| {
        bar.point(p.omega / TWO_PI);
        ControlFlow::Continue(())
    });
    bar.done(&res.as_ref().map(|r| format!(", {}", r.end.name())).unwrap_or_else(|_| ", failed".into()));
    let res = match res {
        Ok(r) => r,
        Err(e) => {
            c.rows.push(failed_row(level, "FO (condensed)", condensed.layout().sizes.clone(), &e));
            SweepResult::empty()
        }
    };
    if res.points.is_empty() {
        // the failure is in its row; the ROMs still run
        return Ok(None);
    }
    let secs = t.elapsed().as_secs_f64();
    c.files.push((format!("{tag}_fo.csv"), csv_bytes(&res, None, units(run.study))?));
    let p = peak(&res.points, run.response).ok_or_else(|| JpError::invalid("full-order sweep", "no point"))?.clone();
    series.frf.push(SolverSeries::new("FO (condensed)", res.points.iter().map(|q| (q.omega / TWO_PI, q.output_amplitude(1, run.response))).collect(), true));
    series.frf0.push(SolverSeries::new("FO (condensed)", res.points.iter().map(|q| (q.omega / TWO_PI, q.output_coeff(0, run.response))).collect(), true));
    series.energies.push(SolverSeries::new("FO (condensed)", p.contact_cycles.iter().enumerate().map(|(i, c)| (i as f64 + 1.0, c.dissipated_energy)).collect(), false));
    let warnings = sweep_warnings(&res, &p, run.band);
    let edge = peak_on_edge(&res, &p, run.band).map(|edge| {
        format!("the full-order peak is on {edge} ({:.3} Hz): the errors \"at resonance\" are taken there, not at a resonance", p.omega / TWO_PI)
    });
    let warning = (!res.reached_end()).then(|| format!("errors taken against a full-order sweep that did not cover the band ({})", res.end.name()));
    c.energies_at_peak.push((c.rows.len(), p.contact_cycles.iter().map(|c| c.dissipated_energy).collect(), Vec::new()));
    let (events, gaps) = events_and_gaps(&res);
    c.rows.push(SolverRow {
        level,
        solver: "FO (condensed)".into(),
        sizes: condensed.layout().sizes.clone(),
        points: res.points.len(),
        sweep_seconds: secs,
        basis_seconds: 0.0,
        corrections: 0,
        peak_hz: p.omega / TWO_PI,
        peak_x1: p.output_amplitude(1, run.response),
        peak_x0: p.output_coeff(0, run.response),
        error_x1: None,
        error_x0: None,
        predicted_e1: None,
        actual_e1: None,
        energy_error: None,
        end: res.end.name().into(),
        end_reason: end_reason(&res),
        complete: res.reached_end(),
        warnings,
        worst_error: None,
        corrections_end: None,
        static_contact_error: None,
        trusted: None,
        trust_reason: None,
        stands_in_for: Vec::new(),
        speed_up: None,
        case: String::new(),
        events,
        gaps,
    });
    Ok(Some(FoPeak { point: p, warning, edge }))
}

/// One reduced model's self-correcting sweep at one level (predicted basis, reduced sweep, `e*`
/// at every point, corrections while `e*_1` is above the threshold): its CSV, its row with the
/// errors at the full-order peak `fo_peak`, its curves. A failure goes into its row.
#[allow(clippy::too_many_arguments)]
fn reduced_level(
    run: &Run,
    level: f64,
    tag: &str,
    (name, kind): (&str, RomKind),
    start: &SharedBasis,
    coords: &ContactCoordinates,
    condensed: &CondensedSystem,
    fo_peak: Option<&FoPeak>,
    c: &mut Collected,
    series: &mut LevelSeries,
) -> Result<()> {
    // the self-correcting workflow: predicted basis, reduced sweep, e* at every point,
    // regeneration from the worst reduced point (or a larger gamma) while e*_1 > threshold
    let aopts = AdaptiveOptions {
        kind,
        threshold: run.study.basis.error_threshold,
        max_corrections: run.study.basis.max_corrections,
        regeneration_samples: run.study.basis.regeneration_samples,
        screen: run.study.basis.screen,
        response_output: run.response,
        ..AdaptiveOptions::default()
    };
    let t = Instant::now();
    // the basis time: this level's share of the shared prediction (one of the study's
    // levels), from the start to the first reduced point (the ROM's construction and its first
    // solve), and between the last point of a pass and the first of the next (the error checks
    // that judged the pass, the correction's prediction, the new ROM); the reduced
    // continuation steps are the rest
    let share = start.seconds / run.study.forcing.levels.len().max(1) as f64;
    let mut basis_step = Some(run.progress.step(format!("{name} reduced model, alpha_ST x {level:e}")));
    let mut points: Option<jprom_progress::Points> = None;
    let mut pass_now = usize::MAX;
    let mut since = Instant::now();
    let mut basis_seconds = 0.0;
    let initial = (start.basis.clone(), start.prediction.clone());
    let adaptive = adaptive_sweep_from(coords, Some(condensed), initial, &run.popts, &run.sopts, &run.hopts, &aopts, &mut |pass, p| {
        if pass != pass_now {
            let gap = since.elapsed().as_secs_f64();
            basis_seconds += gap;
            if let Some(step) = basis_step.take() {
                step.done();
            }
            if let Some(prev) = points.take() {
                prev.done(&format!(", then error checks and basis correction {pass} in {gap:.1} s"));
            }
            points = Some(run.progress.points(format!("{name} sweep, alpha_ST x {level:e}, basis {pass}")));
            pass_now = pass;
        }
        if let Some(pts) = points.as_mut() {
            pts.point(p.omega / TWO_PI);
        }
        since = Instant::now();
        ControlFlow::Continue(())
    });
    drop(basis_step);
    if let Some(pts) = points.take() {
        pts.done(&adaptive.as_ref().map(|a| format!(", {}, worst e*_1 {:.2e}", a.sweep.end.name(), a.worst_error)).unwrap_or_else(|e| format!(", failed: {e}")));
    }
    let adaptive = match adaptive {
        Ok(a) => a,
        Err(e) => {
            c.rows.push(failed_row(level, name, Vec::new(), &e));
            return Ok(());
        }
    };
    let secs = t.elapsed().as_secs_f64() + share;
    basis_seconds += share;
    let basis = &adaptive.basis;
    let rom = reduced_model(kind, coords, Some(condensed), basis)?;
    let res = &adaptive.sweep;
    let errors = &adaptive.predicted_errors;
    c.files.push((format!("{tag}_{}.csv", name.to_lowercase()), csv_bytes(res, Some((errors, &adaptive.judged_errors())), units(run.study))?));
    let rom_label = format!("{name}, n_h = {:?}, gamma = {:e}", rom.layout().sizes, basis.gamma);
    series.frf.push(SolverSeries::new(rom_label.clone(), res.points.iter().map(|q| (q.omega / TWO_PI, q.output_amplitude(1, run.response))).collect(), true));
    series.frf0.push(SolverSeries::new(rom_label.clone(), res.points.iter().map(|q| (q.omega / TWO_PI, q.output_coeff(0, run.response))).collect(), true));
    series.e_stars.push(SolverSeries::new(rom_label.clone(), res.points.iter().zip(errors).filter_map(|(q, e)| Some((q.omega / TWO_PI, *e.get(1)?))).collect(), true));
    // e* flags, the linearised error at the checks judges the pass (rom::adaptive): both on
    // one chart, so that an e* above the threshold on a pass within it reads right
    if !adaptive.checks.is_empty() {
        let checks = adaptive.checks.iter().map(|k| (k.omega / TWO_PI, k.linearised)).collect();
        series.e_stars.push(SolverSeries { checks: true, ..SolverSeries::new(format!("{name}, e_lin_1 at the checks"), checks, false) });
    }
    let p = peak(&res.points, run.response).ok_or_else(|| JpError::invalid("reduced sweep", "no point"))?;
    let mut warnings = sweep_warnings(res, p, run.band);
    if adaptive.worst_error > aopts.threshold {
        warnings.push(format!(
            "the basis stayed poor: worst error {:.3e} > {:e} after {} corrections ({})",
            adaptive.worst_error,
            aopts.threshold,
            adaptive.corrections.len(),
            adaptive.end.name()
        ));
    }
    let static_contact_error = adaptive.worst_static_error();
    if let Some(e) = static_contact_error.filter(|&e| !(e <= aopts.threshold)) {
        warnings.push(format!(
            "the static term X0 is poor: linearised error of the static contact displacement {e:.3e} > {:e} (the corrections judge the first harmonic only); at gross slip the static term converges only with a nearly complete basis: raise basis.gamma where X0 matters, or use the full order (docs/formulation.md §10.6)",
            aopts.threshold
        ));
    }
    let trust = &adaptive.trust;
    if let Some(why) = &trust.reason {
        warnings.push(format!("not trusted, so its peak is not reported as the reduced model's resonance: {why}"));
    }
    let (events, gaps) = events_and_gaps(res);
    let mut row = SolverRow {
        level,
        solver: name.to_string(),
        sizes: rom.layout().sizes.clone(),
        points: res.points.len(),
        sweep_seconds: secs,
        basis_seconds,
        corrections: adaptive.corrections.len(),
        peak_hz: if trust.trusted { p.omega / TWO_PI } else { f64::NAN },
        peak_x1: if trust.trusted { p.output_amplitude(1, run.response) } else { f64::NAN },
        peak_x0: if trust.trusted { p.output_coeff(0, run.response) } else { f64::NAN },
        error_x1: None,
        error_x0: None,
        predicted_e1: None,
        actual_e1: None,
        energy_error: None,
        end: res.end.name().into(),
        end_reason: end_reason(res),
        complete: res.reached_end(),
        warnings,
        worst_error: Some(adaptive.worst_error),
        corrections_end: Some(adaptive.end.name().into()),
        static_contact_error,
        trusted: Some(trust.trusted),
        trust_reason: trust.reason.clone(),
        stands_in_for: Vec::new(),
        speed_up: None,
        case: String::new(),
        events,
        gaps,
    };
    if let Some(FoPeak { point: fo, warning: fo_warning, edge: fo_edge }) = fo_peak {
        // the ROM at the full-order resonance frequency, from its nearest sweep point
        let guess = res.points.iter().min_by(|a, b| (a.omega - fo.omega).abs().total_cmp(&(b.omega - fo.omega).abs())).map(|q| q.z.clone());
        let r = match solve_point(rom.as_ref(), fo.omega, guess.as_deref(), &run.hopts) {
            Ok(r) => r,
            Err(e) => {
                row.warnings.push(format!("no errors: the reduced model did not converge at the full-order peak ({e})"));
                c.rows.push(row);
                return Ok(());
            }
        };
        let j = run.response;
        row.error_x1 = Some(rel(r.output_amplitude(1, j), fo.output_amplitude(1, j)));
        row.error_x0 = Some(static_error(&r, fo));
        let e_star = predicted_error(rom.as_ref(), r.omega, &r.z)?;
        let e = actual_error(rom.as_ref(), r.omega, &r.z, fo)?;
        row.predicted_e1 = e_star.get(1).copied();
        row.actual_e1 = e.get(1).copied();
        let cycles = reduced_contact_cycles(rom.as_ref(), r.omega, &r.z)?;
        let fo_energies = fo.contact_cycles.iter().map(|c| c.dissipated_energy).collect();
        c.energies_at_peak.push((c.rows.len(), fo_energies, cycles.iter().map(|c| c.dissipated_energy).collect()));
        row.warnings.extend(fo_warning.iter().chain(fo_edge.iter()).cloned());
        series.energies.push(SolverSeries::new(rom_label.clone(), cycles.iter().enumerate().map(|(i, c)| (i as f64 + 1.0, c.dissipated_energy)).collect(), false));
        if let (Some(ps), Some(a)) = (row.predicted_e1, row.actual_e1) {
            let label = name.to_string();
            match c.err_points.iter_mut().find(|(l, _)| *l == label) {
                Some((_, v)) => v.push((a, ps)),
                None => c.err_points.push((label, vec![(a, ps)])),
            }
        }
    }
    c.rows.push(row);
    Ok(())
}

/// The settings every unit of a run uses.
struct Run<'a> {
    study: &'a Study,
    progress: Progress,
    hopts: HbmOptions,
    /// The band (rad/s).
    band: (f64, f64),
    sopts: SweepOptions,
    popts: PredictionOptions,
    /// The response output ([`Study::response_output`]).
    response: usize,
}

/// What one unit adds to the study: its table rows, its full-order peak's energies per contact
/// (with each ROM's there, for the energy errors; indices into `rows`), the (actual, predicted)
/// error pairs per ROM, its CSV files (name in the output folder, contents).
#[derive(Default)]
struct Collected {
    rows: Vec<SolverRow>,
    energies_at_peak: Vec<(usize, Vec<f64>, Vec<f64>)>,
    err_points: Vec<(String, Vec<(f64, f64)>)>,
    files: Vec<(String, Vec<u8>)>,
}

/// One unit's curves for its level's plots: response, energies at the peak, `e*_1` along each
/// ROM sweep.
#[derive(Default)]
struct LevelSeries {
    frf: Vec<SolverSeries>,
    /// The static term `X0` at the response output along each sweep (the paper's Fig. 3c/d).
    frf0: Vec<SolverSeries>,
    energies: Vec<SolverSeries>,
    e_stars: Vec<SolverSeries>,
}

/// A solver's curve as a unit returns it ([`Series::solver`]'s arguments: label, points, line);
/// plain data, so that a unit computed in another process sends it back.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SolverSeries {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub line: bool,
    /// The points where a ROM pass' linearised error was checked ([`Series::checks`]).
    #[serde(default)]
    pub checks: bool,
}

impl SolverSeries {
    fn new(label: impl Into<String>, points: Vec<(f64, f64)>, line: bool) -> Self {
        SolverSeries { label: label.into(), points, line, checks: false }
    }
    fn series(self) -> Series {
        if self.checks {
            Series::checks(self.label, self.points)
        } else {
            Series::solver(self.label, self.points, self.line)
        }
    }
}

/// A level's full-order peak and what the ROM rows must say about it (a full-order unit's
/// result that the level's ROM and gamma-study units take).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FoPeak {
    point: PointSolution,
    /// The full-order sweep did not cover the band.
    warning: Option<String>,
    /// The peak is on the band edge.
    edge: Option<String>,
}

/// What every unit of a study shares, built once (by rank 0 under MPI, which sends it to the
/// others): each parameter case's reduced model (one Craig-Bampton reduction, the case's contact
/// laws, damping and static load) and level reference, with what the summary says about them.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Shared {
    /// One per case of [`Study::case_list`] (one, unnamed, for a study without `[[cases]]`).
    pub cases: Vec<CaseShared>,
    pub build_seconds: f64,
}

/// A parameter case's model and level reference ([`Shared`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseShared {
    /// The case's name (empty: the study without `[[cases]]`).
    pub name: String,
    /// Its overrides in words.
    pub overrides: String,
    /// The model at unit dynamic scale (each level sets its own).
    pub model: Model,
    /// The model's `excitation.dynamic_scale` at each of the study's levels.
    pub scales: Vec<f64>,
    pub omega_st: f64,
    pub stuck_mode_in_band: bool,
    pub alpha_st: Option<f64>,
    pub stuck_limit_force: f64,
    pub level_reference: String,
    pub warnings: Vec<String>,
    /// The JP basis every ROM of the case starts from, predicted once at the largest
    /// excitation of the study ([`shared_basis`]), or why it could not be (the ROM rows then
    /// fail with it). `None` when the study runs no ROM.
    pub basis: Option<std::result::Result<SharedBasis, String>>,
    /// The contact nodes' coordinates in contact order (empty when the FE model has none),
    /// for the energy map.
    pub contact_positions: Vec<[f64; 3]>,
}

/// The JP basis shared by a case's levels and ROMs, and how long its prediction took.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SharedBasis {
    pub basis: JpBasis,
    pub prediction: PredictionReport,
    pub seconds: f64,
}

/// The prediction options of a study: its band, `gamma`, samples and modes beyond the band.
pub fn prediction_options(study: &Study) -> PredictionOptions {
    let band = (TWO_PI * study.band.hz_start, TWO_PI * study.band.hz_end);
    let mut popts = PredictionOptions::new(band);
    popts.gamma = study.basis.gamma;
    popts.n_samples = study.basis.samples;
    popts.modes.extra_outside = study.basis.extra_modes;
    popts.slipping = study.basis.slipping.into();
    popts
}

/// The JP basis predicted from the stuck mode at the largest excitation of the study (the
/// largest of `scales`): its samples of the generating amplitude run from the onset of slip to
/// that level's linear stuck response, so they span the contact patterns of every smaller
/// excitation too, and one prediction serves every level and both ROMs (each level's
/// self-correcting sweep then corrects it for itself).
///
/// # Errors
/// The prediction's errors.
pub fn shared_basis(study: &Study, model: &Model, scales: &[f64]) -> Result<SharedBasis> {
    let t = Instant::now();
    let mut m = model.clone();
    m.excitation.dynamic_scale = scales.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let coords = ContactCoordinates::new(&m, study.discretisation())?;
    let (basis, prediction) = predict_basis(&coords, &prediction_options(study))?;
    Ok(SharedBasis { basis, prediction, seconds: t.elapsed().as_secs_f64() })
}

/// Builds what every unit shares ([`Shared`]): the cases' models ([`build_case_models`]), and
/// for each its stuck mode for the band and its level reference, showing the stages on
/// `progress`.
///
/// # Errors
/// The model's errors; a level the reference cannot scale to.
pub fn build_shared(study: &Study, progress: Progress) -> Result<Shared> {
    let band = (TWO_PI * study.band.hz_start, TWO_PI * study.band.hz_end);
    let t = Instant::now();
    let cases = study.case_list();
    let (models, positions) = build_case_models_placed(study, &cases, progress)?;
    let mut out = Vec::with_capacity(cases.len());
    for (case, model) in cases.iter().zip(models) {
        let step = progress.step(if case.name.is_empty() { "stuck mode and level reference".to_string() } else { format!("case {}: stuck mode and level reference", case.name) });
        let coords = ContactCoordinates::new(&model, study.discretisation())?;
        let omega_st = jprom::jp::prediction::stuck_mode(&coords, band)?.0;
        let static_z = jprom::jp::prediction::static_solution(&coords)?;
        // the model's dynamic scale is 1 here, so the limit's scale is the dynamic scale s_ST
        let limit = stuck_limit(&coords, &static_z, omega_st)?;
        step.done_with(&format!(", stuck resonance {:.2} Hz", omega_st / TWO_PI));
        let mut warnings = Vec::new();
        let stuck_mode_in_band = super::modes::in_band(omega_st / TWO_PI, (study.band.hz_start, study.band.hz_end));
        if !stuck_mode_in_band {
            // the cheap test failed: all stuck modes (dense, this path only) to say where they are
            let band_hz = (study.band.hz_start, study.band.hz_end);
            let warning = match jprom::model::modes::natural_modes(&model, jprom::model::modes::Boundary::Stuck) {
                Ok(stuck) => super::modes::band_warning(&stuck, band_hz, omega_st / TWO_PI),
                Err(e) => Some(super::modes::band_warning_without_modes(band_hz, omega_st / TWO_PI, &e)),
            };
            let of_case = if case.name.is_empty() { String::new() } else { format!("case {}: ", case.name) };
            warnings.extend(warning.map(|w| format!("{of_case}{w}")));
        }
        let scales = study.forcing.levels.iter().map(|&level| limit.scale_at(level)).collect::<Result<Vec<f64>>>()?;
        let response = study.response_output();
        if response >= model.output_dofs.len() {
            return Err(JpError::invalid("output.response", format!("output {response} does not exist: the model has {} outputs (0 to {})", model.output_dofs.len(), model.output_dofs.len().saturating_sub(1))));
        }
        let contact_positions = if positions.len() == model.contacts.len() { positions.clone() } else { Vec::new() };
        let basis = (!rom_kinds(study).is_empty()).then(|| {
            let step = progress.step(if case.name.is_empty() { "JP basis for every level".to_string() } else { format!("case {}: JP basis for every level", case.name) });
            let b = shared_basis(study, &model, &scales);
            match &b {
                Ok(b) => step.done_with(&format!(", n_h = {:?} from {} contact-state patterns", b.basis.sizes, b.prediction.n_patterns)),
                Err(e) => step.done_with(&format!(", failed: {e}")),
            }
            b.map_err(|e| e.to_string())
        });
        out.push(CaseShared {
            name: case.name.clone(),
            overrides: case.describe(),
            model,
            scales,
            omega_st,
            stuck_mode_in_band,
            alpha_st: limit.alpha,
            stuck_limit_force: limit.force,
            level_reference: limit.describe(),
            warnings,
            basis,
            contact_positions,
        });
    }
    Ok(Shared { cases: out, build_seconds: t.elapsed().as_secs_f64() })
}

/// The ROMs a study asks for, in table order.
fn rom_kinds(study: &Study) -> Vec<(&'static str, RomKind)> {
    [("FR", RomKind::Fr, study.solvers.fr), ("NLR", RomKind::Nlr, study.solvers.nlr)].into_iter().filter(|k| k.2).map(|k| (k.0, k.1)).collect()
}

/// A level's systems, built by the first unit of the level that a process runs and shared by
/// its others (as the serial loop built them once per level).
struct LevelSystems {
    coords: ContactCoordinates,
    condensed: CondensedSystem,
}

/// Runs units of a study from its [`Shared`] inputs ([`UnitRunner::run`]); one per process,
/// shared by its threads.
pub struct UnitRunner<'a> {
    run: Run<'a>,
    shared: &'a Shared,
    kinds: Vec<(&'static str, RomKind)>,
    levels: Vec<std::sync::OnceLock<Result<LevelSystems>>>,
}

impl<'a> UnitRunner<'a> {
    /// The runner of `study`'s units; `progress` shows each unit's sweeps.
    ///
    /// # Errors
    /// The study's sweep settings or AFT plan are invalid.
    pub fn new(study: &'a Study, shared: &'a Shared, progress: Progress) -> Result<Self> {
        let band = (TWO_PI * study.band.hz_start, TWO_PI * study.band.hz_end);
        let popts = prediction_options(study);
        study.discretisation().validate()?;
        // about `points` points where the response is smooth, more at resonances and folds
        let sopts = study.band.sweep_options();
        sopts.validate().map_err(|e| JpError::invalid("band", e.to_string()))?;
        let hopts = HbmOptions { max_iterations: study.hbm.max_iterations, ..HbmOptions::default() };
        let run = Run { study, progress, hopts, band, sopts, popts, response: study.response_output() };
        let levels = (0..shared.cases.len() * study.forcing.levels.len()).map(|_| std::sync::OnceLock::new()).collect();
        Ok(UnitRunner { run, shared, kinds: rom_kinds(study), levels })
    }

    /// The level's model (at its excitation level), contact coordinates and condensed system,
    /// of case `case`.
    fn level(&self, case: usize, i: usize) -> Result<&LevelSystems> {
        let n_levels = self.run.study.forcing.levels.len();
        self.levels[case * n_levels + i]
            .get_or_init(|| {
                let shared = &self.shared.cases[case];
                let mut model = shared.model.clone();
                model.excitation.dynamic_scale = shared.scales[i];
                // the transformed forces carry the excitation level: built for this level
                let coords = ContactCoordinates::new(&model, self.run.study.discretisation())?;
                let condensed = CondensedSystem::new(&model, self.run.study.discretisation())?;
                Ok(LevelSystems { coords, condensed })
            })
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Runs one unit; `fo` is the full-order peak of its level (ROM and gamma-study units, when
    /// the study has a full-order solver and its sweep found a point).
    ///
    /// # Errors
    /// The level's systems cannot be built, or a step of the unit that is not a sweep failed
    /// (a sweep that fails is a row of the unit's output, as in a serial run).
    pub fn run(&self, unit: &Unit, fo: Option<&FoPeak>) -> Result<UnitOutput> {
        let level = unit.level;
        // a case's files are prefixed with its name
        let prefix = if unit.case.is_empty() { String::new() } else { format!("{}_", unit.case) };
        let tag = format!("{prefix}alpha_ST_x{level:e}");
        let sys = self.level(unit.case_index, unit.level_index)?;
        let mut c = Collected::default();
        let mut series = LevelSeries::default();
        let mut out = UnitOutput::default();
        match unit.kind {
            UnitKind::FullOrder => out.fo_peak = full_order_level(&self.run, level, &tag, &sys.condensed, &mut c, &mut series)?,
            UnitKind::Fr | UnitKind::Nlr => {
                let kind = if unit.kind == UnitKind::Fr { ("FR", RomKind::Fr) } else { ("NLR", RomKind::Nlr) };
                match &self.shared.cases[unit.case_index].basis {
                    Some(Ok(start)) => reduced_level(&self.run, level, &tag, kind, start, &sys.coords, &sys.condensed, fo, &mut c, &mut series)?,
                    Some(Err(why)) => c.rows.push(failed_row_because(level, kind.0, Vec::new(), &format!("the JP basis could not be predicted: {why}"))),
                    None => c.rows.push(failed_row_because(level, kind.0, Vec::new(), "no JP basis was predicted for this case")),
                }
            }
            UnitKind::GammaStudy => {
                if let Some(fo) = fo {
                    let bar = self.run.progress.step(format!("gamma study, level {level:e}"));
                    let t = Instant::now();
                    out.basis_study = gamma_study(self.run.study, &sys.coords, &sys.condensed, &self.run.popts, &self.run.hopts, &fo.point, level, &self.kinds)?;
                    out.basis_study_seconds = t.elapsed().as_secs_f64();
                    bar.done();
                }
            }
        }
        out.rows = c.rows;
        for r in &mut out.rows {
            r.case.clone_from(&unit.case);
        }
        for r in &mut out.basis_study {
            r.case.clone_from(&unit.case);
        }
        out.energies_at_peak = c.energies_at_peak;
        out.err_points = c.err_points;
        out.files = c.files;
        out.frf = series.frf;
        out.frf0 = series.frf0;
        out.energies = series.energies;
        out.e_stars = series.e_stars;
        Ok(out)
    }
}

/// What a unit produced, merged by [`merge_units`] in unit order. Plain data: under MPI it
/// travels from the rank that ran the unit to rank 0.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct UnitOutput {
    pub rows: Vec<SolverRow>,
    /// The full-order peak's energies per contact and each ROM's there (index into `rows`).
    pub energies_at_peak: Vec<(usize, Vec<f64>, Vec<f64>)>,
    /// (actual, predicted) error pairs per ROM.
    pub err_points: Vec<(String, Vec<(f64, f64)>)>,
    /// Files for the output folder: name, contents.
    pub files: Vec<(String, Vec<u8>)>,
    pub frf: Vec<SolverSeries>,
    #[serde(default)]
    pub frf0: Vec<SolverSeries>,
    pub energies: Vec<SolverSeries>,
    pub e_stars: Vec<SolverSeries>,
    pub basis_study: Vec<BasisStudyRow>,
    pub basis_study_seconds: f64,
    /// A full-order unit's peak, which its level's other units take.
    pub fo_peak: Option<FoPeak>,
}

impl UnitOutput {
    /// The output of a unit that failed: one row saying which unit failed and why.
    pub fn failed(unit: &Unit, index: usize, reason: &str) -> Self {
        let why = format!("unit {index} ({}): {reason}", unit.describe());
        let row = SolverRow { case: unit.case.clone(), ..failed_row_because(unit.level, unit.kind.solver(), Vec::new(), &why) };
        UnitOutput { rows: vec![row], ..UnitOutput::default() }
    }
}

/// Merges the units' outputs (in unit order, whatever order they finished in) into the study's
/// summary, and writes the CSVs, `summary.json`, the plots and `basis_study.csv` into `out_dir`.
///
/// # Errors
/// A file that cannot be written.
pub fn merge_units(study: &Study, out_dir: &Path, shared: &Shared, study_units: &[Unit], outputs: Vec<UnitOutput>) -> Result<RunSummary> {
    std::fs::create_dir_all(out_dir).map_err(|e| JpError::Io { path: out_dir.display().to_string(), reason: e.to_string() })?;
    let kinds = rom_kinds(study);
    let mut rows: Vec<SolverRow> = Vec::new();
    let mut basis_study: Vec<BasisStudyRow> = Vec::new();
    let mut totals: Vec<SolverTotal> = Vec::new();
    let mut basis_study_seconds = 0.0;
    let mut outputs = outputs.into_iter().zip(study_units).peekable();
    // each case on its own (energies relative to the case's largest, its plots and
    // basis_study.csv prefixed with its name), as if it were a study of its own
    let mut case_plots = Vec::new();
    for (ci, case) in shared.cases.iter().enumerate() {
        let mut c = Collected::default();
        let (mut frf_series, mut frf0_series, mut energy_series, mut e_star_series) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut case_basis_study: Vec<BasisStudyRow> = Vec::new();
        let mut levels_series: Vec<Series> = Vec::new();
        for (i, &level) in study.forcing.levels.iter().enumerate() {
            let mut series = LevelSeries::default();
            while let Some((out, _)) = outputs.next_if(|(_, u)| u.case_index == ci && u.level_index == i) {
                for (name, bytes) in &out.files {
                    jprom::io::write_file(&out_dir.join(name), |f| f.write_all(bytes))?;
                }
                let base = c.rows.len();
                c.energies_at_peak.extend(out.energies_at_peak.into_iter().map(|(k, a, b)| (base + k, a, b)));
                c.rows.extend(out.rows);
                for (label, pts) in out.err_points {
                    match c.err_points.iter_mut().find(|(l, _)| *l == label) {
                        Some((_, v)) => v.extend(pts),
                        None => c.err_points.push((label, pts)),
                    }
                }
                series.frf.extend(out.frf);
                series.frf0.extend(out.frf0);
                series.energies.extend(out.energies);
                series.e_stars.extend(out.e_stars);
                case_basis_study.extend(out.basis_study);
                basis_study_seconds += out.basis_study_seconds;
            }
            // every level on one chart, the response per unit of the dynamic scale
            let scale = case.scales[i];
            for sv in &series.frf {
                let label = format!("{}, alpha_ST x {level:.1e}", sv.label.split(',').next().unwrap_or(&sv.label));
                levels_series.push(level_series(label, i, sv.points.iter().map(|&(f, x)| (f, x / scale)).collect()));
            }
            let plot = |v: Vec<SolverSeries>| v.into_iter().map(SolverSeries::series).collect::<Vec<Series>>();
            frf_series.push((level, plot(series.frf)));
            frf0_series.push((level, plot(series.frf0)));
            energy_series.push((level, plot(series.energies)));
            if !kinds.is_empty() {
                e_star_series.push((level, plot(series.e_stars)));
            }
        }
        let Collected { rows: mut case_rows, energies_at_peak, err_points, .. } = c;
        energy_errors(&mut case_rows, &energies_at_peak);
        totals.extend(speed_ups(&mut case_rows, &case.name));
        let prefix = if case.name.is_empty() { String::new() } else { format!("{}_", case.name) };
        case_plots.push(CasePlots {
            prefix,
            rows: rows.len()..rows.len() + case_rows.len(),
            basis_rows: basis_study.len()..basis_study.len() + case_basis_study.len(),
            frf: frf_series,
            frf0: frf0_series,
            energy: energy_series,
            e_star: e_star_series,
            err_points,
            levels: levels_series,
            positions: case.contact_positions.clone(),
            frames: case.model.contacts.iter().map(|c| c.frame).collect(),
        });
        rows.extend(case_rows);
        basis_study.extend(case_basis_study);
    }

    // a reduced sweep the full order stands in for, with a full sweep, leaves no level without
    // its result (solvers.fall_back)
    let stood_in = |r: &SolverRow| r.warnings.iter().any(|w| w == crate::fall_back::STOOD_IN) && rows.iter().any(|f| f.case == r.case && f.level == r.level && f.complete && !f.stands_in_for.is_empty());
    let incomplete = rows
        .iter()
        .filter(|r| !r.complete && !stood_in(r))
        .map(|r| {
            let of_case = if r.case.is_empty() { String::new() } else { format!(" of case {}", r.case) };
            format!("{} at level {:e}{of_case}: {}", r.solver, r.level, r.warnings.first().cloned().unwrap_or_else(|| r.end.clone()))
        })
        .collect();
    let first = &shared.cases[0];
    let named = !study.cases.is_empty();
    let summary = RunSummary {
        model_dofs: first.model.n_dof(),
        contacts: first.model.contacts.len(),
        stuck_resonance_hz: first.omega_st / TWO_PI,
        stuck_mode_in_band: first.stuck_mode_in_band,
        alpha_st: first.alpha_st,
        stuck_limit_force: first.stuck_limit_force,
        level_reference: first.level_reference.clone(),
        incomplete,
        warnings: shared.cases.iter().flat_map(|c| c.warnings.iter().cloned()).collect(),
        build_seconds: shared.build_seconds,
        threads: jprom::parallelism::threads(),
        reproducible: jprom::parallelism::reproducible(),
        length_unit: units(study).0.into(),
        energy_unit: units(study).1.into(),
        rows,
        basis_study,
        basis_study_seconds,
        response_output: study.response_output(),
        response_name: response_words(study),
        shared_bases: shared
            .cases
            .iter()
            .filter_map(|c| {
                let b = c.basis.as_ref()?;
                Some(match b {
                    Ok(b) => SharedBasisSummary {
                        case: c.name.clone(),
                        sizes: b.basis.sizes.clone(),
                        gamma: b.basis.gamma,
                        patterns: b.prediction.n_patterns,
                        samples: b.prediction.n_samples,
                        seconds: b.seconds,
                        levels: study.forcing.levels.len(),
                        failed: None,
                    },
                    Err(why) => SharedBasisSummary { case: c.name.clone(), sizes: Vec::new(), gamma: study.basis.gamma, patterns: 0, samples: study.basis.samples, seconds: 0.0, levels: study.forcing.levels.len(), failed: Some(why.clone()) },
                })
            })
            .collect(),
        totals,
        cases: if named {
            shared
                .cases
                .iter()
                .map(|c| CaseSummary {
                    name: c.name.clone(),
                    overrides: c.overrides.clone(),
                    stuck_resonance_hz: c.omega_st / TWO_PI,
                    stuck_mode_in_band: c.stuck_mode_in_band,
                    alpha_st: c.alpha_st,
                    stuck_limit_force: c.stuck_limit_force,
                    level_reference: c.level_reference.clone(),
                })
                .collect()
        } else {
            Vec::new()
        },
    };
    jprom::io::write_file(&out_dir.join("summary.json"), |w| serde_json::to_writer_pretty(&mut *w, &summary).map_err(std::io::Error::from))?;
    for plots in case_plots {
        let case = CaseRows { prefix: &plots.prefix, rows: &summary.rows[plots.rows.clone()], basis_study: &summary.basis_study[plots.basis_rows.clone()] };
        if study.output.plots {
            write_study_plots(study, out_dir, &case, &plots)?;
        }
        if !case.basis_study.is_empty() {
            write_basis_study_csv(&out_dir.join(format!("{}basis_study.csv", plots.prefix)), case.basis_study)?;
        }
    }
    Ok(summary)
}

/// A case's curves for its plots, gathered from its units ([`write_study_plots`]).
struct CasePlots {
    /// The prefix of its files, its rows and gamma-study rows in the summary.
    prefix: String,
    rows: std::ops::Range<usize>,
    basis_rows: std::ops::Range<usize>,
    /// Per level: FRF (`|X1|`), static term, energy per contact, `e*_1` along the ROM sweeps.
    frf: Vec<(f64, Vec<Series>)>,
    frf0: Vec<(f64, Vec<Series>)>,
    energy: Vec<(f64, Vec<Series>)>,
    e_star: Vec<(f64, Vec<Series>)>,
    /// (actual, predicted) error pairs per ROM.
    err_points: Vec<(String, Vec<(f64, f64)>)>,
    /// Every level's FRFs per unit of the dynamic scale, on one chart.
    levels: Vec<Series>,
    /// The contact nodes' coordinates and frames (empty: no energy map).
    positions: Vec<[f64; 3]>,
    frames: Vec<[[f64; 3]; 3]>,
}

/// A case's part of the summary and the prefix of its files (empty without `[[cases]]`).
struct CaseRows<'a> {
    prefix: &'a str,
    rows: &'a [SolverRow],
    basis_study: &'a [BasisStudyRow],
}

/// [`run_study`] showing its stages on `progress`, one unit at a time ([`run_study_jobs`] with
/// one job).
///
/// # Errors
/// As [`run_study_jobs`].
pub fn run_study_with(study: &Study, out_dir: &Path, progress: Progress) -> Result<RunSummary> {
    run_study_jobs(study, out_dir, progress, 1)
}

/// Runs a study in `jobs` threads: each case's model, stuck mode and level reference once
/// ([`build_shared`]), then its units ([`crate::units::study_units`]: per case, at each level the
/// full-order sweep ([`full_order_level`]), each reduced model's self-correcting sweep
/// ([`reduced_level`]) and the gamma study), dealt to the threads as they become free
/// ([`crate::units::run_units_threads`]), then merged in unit order ([`merge_units`]): the
/// energy errors, the CSVs, `summary.json`, the plots and `basis_study.csv`, identical for any
/// `jobs`.
///
/// # Errors
/// The model's errors, a file that cannot be written; a sweep or a unit that fails is a row of
/// the table.
pub fn run_study_jobs(study: &Study, out_dir: &Path, progress: Progress, jobs: usize) -> Result<RunSummary> {
    std::fs::create_dir_all(out_dir).map_err(|e| JpError::Io { path: out_dir.display().to_string(), reason: e.to_string() })?;
    let shared = build_shared(&writing_to(study, out_dir), progress)?;
    let all_units = study_units(study);
    // concurrent units print plain lines (bars of several threads would overwrite each other)
    let unit_progress = if jobs > 1 && progress == Progress::Bars { Progress::Lines } else { progress };
    let runner = UnitRunner::new(study, &shared, unit_progress)?;
    let outputs = run_units_threads(&runner, &all_units, jobs);
    let (all_units, outputs) = crate::fall_back::with_fall_backs(&runner, study.solvers.fall_back, all_units, outputs, jobs);
    merge_units(study, out_dir, &shared, &all_units, outputs)
}

/// `study` with its results (and its `model.cache`) in `out_dir`, where the run writes them
/// (`--out` or `output.dir`).
pub fn writing_to(study: &Study, out_dir: &Path) -> Study {
    let mut s = study.clone();
    s.output.dir = out_dir.to_path_buf();
    s
}

/// The summary as a fixed-width text table.
pub fn summary_table(s: &RunSummary) -> String {
    let alpha = &s.level_reference;
    let in_band = |yes: bool| if yes { "in the band" } else { "outside the band (!)" };
    let mut out = if s.cases.is_empty() {
        let mut out = format!(
            "model: {} DoFs (Craig-Bampton), {} contact nodes, stuck resonance {:.1} Hz, {alpha}, built in {:.1} s\n",
            s.model_dofs, s.contacts, s.stuck_resonance_hz, s.build_seconds
        );
        out.push_str(&format!("stuck mode for the band (nearest its centre; levels and bases use it): {:.3} Hz, {}\n", s.stuck_resonance_hz, in_band(s.stuck_mode_in_band)));
        out
    } else {
        // each case its own stuck mode and level reference
        let mut out = format!("model: {} DoFs (Craig-Bampton), {} contact nodes, {} cases, built in {:.1} s\n", s.model_dofs, s.contacts, s.cases.len(), s.build_seconds);
        for c in &s.cases {
            out.push_str(&format!(
                "case {} ({}): stuck mode for the band {:.3} Hz, {}, {}\n",
                c.name,
                c.overrides,
                c.stuck_resonance_hz,
                in_band(c.stuck_mode_in_band),
                c.level_reference
            ));
        }
        out
    };
    // with cases, a first column names the case of each row
    let width = s.cases.iter().map(|c| c.name.len()).max().unwrap_or(0).max(4);
    let case_col = |name: &str| if s.cases.is_empty() { String::new() } else { format!("{name:<width$} ") };
    for w in &s.warnings {
        out.push_str(&format!("(!) {w}\n"));
    }
    for b in &s.shared_bases {
        let of_case = if b.case.is_empty() { String::new() } else { format!(" of case {}", b.case) };
        match &b.failed {
            None => out.push_str(&format!(
                "JP basis{of_case}, predicted once for every level and ROM: n_h = {:?}, gamma = {:e}, {} contact-state patterns from {} samples, {:.2} s (each ROM row's time counts 1/{} of it)\n",
                b.sizes, b.gamma, b.patterns, b.samples, b.seconds, b.levels
            )),
            Some(why) => out.push_str(&format!("(!) JP basis{of_case}: could not be predicted: {why}\n")),
        }
    }
    let output = format!("output {}", s.response_output);
    out.push_str(&if s.response_name == output { format!("response: {output}\n") } else { format!("response: {}, {output}\n", s.response_name) });
    out.push_str(&format!(
        "{}{:>10} {:<15} {:>14} {:>6} {:>8} {:>8} {:>8} {:>8} {:>10} {:>11} {:>9} {:>9} {:>9} {:>9} {:>9} {:<12}\n",
        case_col("case"),
        "a/a_ST", "solver", "n_h", "points", "time s", "speed-up", "basis s", "fixes", "peak Hz", "peak |X1|", "err X1", "err X0", "e*_1", "e_1", "err W", "end"
    ));
    let opt = |v: Option<f64>| v.map(|x| format!("{x:.2e}")).unwrap_or_else(|| "-".into());
    let times = |v: Option<f64>| v.map(|x| format!("{x:.1}x")).unwrap_or_else(|| "-".into());
    for r in &s.rows {
        out.push_str(&format!(
            "{}{:>10.1e} {:<15} {:>14} {:>6} {:>8.2} {:>8} {:>8.2} {:>8} {:>10} {:>11} {:>9} {:>9} {:>9} {:>9} {:>9} {:<12}\n",
            case_col(&r.case),
            r.level,
            r.solver,
            format!("{:?}", r.sizes),
            r.points,
            r.sweep_seconds,
            times(r.speed_up),
            r.basis_seconds,
            r.corrections,
            if r.peak_hz.is_finite() { format!("{:.2}", r.peak_hz) } else { "-".into() },
            if r.peak_x1.is_finite() { format!("{:.4e}", r.peak_x1) } else { "-".into() },
            opt(r.error_x1),
            opt(r.error_x0),
            opt(r.predicted_e1),
            opt(r.actual_e1),
            opt(r.energy_error),
            if r.warnings.is_empty() { r.end.clone() } else { format!("{} (!)", r.end) }
        ));
    }
    let mut by_case: Vec<&str> = Vec::new();
    for t in &s.totals {
        if !by_case.contains(&t.case.as_str()) {
            by_case.push(&t.case);
        }
    }
    for case in by_case {
        let of_case = if case.is_empty() { String::new() } else { format!(" of case {case}") };
        let parts: Vec<String> = s
            .totals
            .iter()
            .filter(|t| t.case == case)
            .map(|t| match t.speed_up {
                Some(x) => format!("{} {:.1} s ({x:.1}x faster)", t.solver, t.seconds),
                None => format!("{} {:.1} s", t.solver, t.seconds),
            })
            .collect();
        out.push_str(&format!("all levels{of_case}, the shared basis included: {}\n", parts.join(", ")));
        for t in s.totals.iter().filter(|t| t.case == case && t.speed_up.is_some_and(|x| x < 1.0)) {
            let fo = t.seconds * t.speed_up.unwrap_or(1.0);
            out.push_str(&format!("(!) {}{of_case} cost more than the full order over all levels: {:.1} s vs {fo:.1} s\n", t.solver, t.seconds));
        }
    }
    // a reduced model dearer than the full order says so here, not among the row's warnings:
    // times differ from run to run, and `summary.json` of a reproducible run does not
    let dearer = |r: &SolverRow| r.speed_up.filter(|&x| x < 1.0).map(|x| format!("the reduced model cost more than the full order at this level: {:.2} s (basis and corrections included) vs {:.2} s", r.sweep_seconds, r.sweep_seconds * x));
    for r in s.rows.iter().filter(|r| !r.stands_in_for.is_empty()) {
        let of_case = if r.case.is_empty() { String::new() } else { format!(" of case {}", r.case) };
        out.push_str(&format!("full order at a/a_ST = {:.1e}{of_case} gives the level's result in place of (solvers.fall_back):\n", r.level));
        for why in &r.stands_in_for {
            out.push_str(&format!("  {why}\n"));
        }
    }
    let flagged: Vec<&SolverRow> = s.rows.iter().filter(|r| !r.warnings.is_empty() || dearer(r).is_some()).collect();
    if !flagged.is_empty() {
        out.push_str("(!) read with care:\n");
        for r in flagged {
            for w in r.warnings.iter().cloned().chain(dearer(r)) {
                let of_case = if r.case.is_empty() { String::new() } else { format!(" of case {}", r.case) };
                out.push_str(&format!("  {} at a/a_ST = {:.1e}{of_case}: {w}\n", r.solver, r.level));
            }
        }
    }
    if !s.basis_study.is_empty() {
        out.push_str(&format!("error vs basis size at the FO resonance (basis.gamma_study, {:.1} s):\n", s.basis_study_seconds));
        out.push_str(&format!("{}{:>10} {:<6} {:>8} {:>14} {:>9} {:>9} {:>9} {:>9}\n", case_col("case"), "a/a_ST", "solver", "gamma", "n_h", "err X1", "err X0", "e*_1", "e_1"));
        for r in &s.basis_study {
            out.push_str(&format!(
                "{}{:>10.1e} {:<6} {:>8.1e} {:>14} {:>9} {:>9} {:>9} {:>9}\n",
                case_col(&r.case),
                r.level,
                r.solver,
                r.gamma,
                format!("{:?}", r.sizes),
                opt(r.error_x1),
                opt(r.error_x0),
                opt(r.predicted_e1),
                opt(r.actual_e1)
            ));
        }
    }
    out
}
