//! What every unit of a study shares ([`Shared`], [`build_shared`]): each parameter case's
//! reduced model on the one Craig-Bampton reduction, its stuck mode for the band, its level
//! reference and the JP basis its levels and ROMs start from.

use super::progress::Progress;
use super::study::Study;
use super::study_model::build_case_models_placed;
use jprom::error::{JpError, Result};
use jprom::jp::prediction::PredictionOptions;
use jprom::level::stuck_limit;
use jprom::rom::RomKind;
use jprom::jp::{predict_basis, JpBasis, PredictionReport};
use jprom::model::{ContactCoordinates, Model};
use serde::{Deserialize, Serialize};
use std::time::Instant;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

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
pub fn rom_kinds(study: &Study) -> Vec<(&'static str, RomKind)> {
    [("FR", RomKind::Fr, study.solvers.fr), ("NLR", RomKind::Nlr, study.solvers.nlr)].into_iter().filter(|k| k.2).map(|k| (k.0, k.1)).collect()
}
