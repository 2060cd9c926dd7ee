//! The study's model: the built-in blade (its Craig-Bampton model cached in the output folder
//! when `model.cache` is on), a Matrix Market model or a CalculiX model, read, placed and
//! reduced by Craig-Bampton, with each parameter case's contact laws, damping and static load.

use super::check::{placement, ModelNodes};
use super::progress::Progress;
use super::study::{CaseSpec, DampingSpec, FeSource, ModelSpec, Study, BLADE_MODEL_CACHE};
use jprom::contact::ContactLaw;
use jprom::error::{JpError, Result};
use jprom::fe::{BladeParams, BuiltinBlade, FeModel, Reduction};
use jprom::io::calculix::{read_model_files, CalculixFiles};
use jprom::io::dof_map::DofMap;
use jprom::io::matrix_market::read_symmetric_matrix_market;
use jprom::model::{Damping, Model};
use serde::{Deserialize, Serialize};
use std::path::Path;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

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
pub(crate) fn build_case_models_placed(study: &Study, cases: &[CaseSpec], progress: Progress) -> Result<(Vec<Model>, Vec<[f64; 3]>)> {
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
