//! `jprom modes STUDY`: the natural frequencies a band is chosen from. For an FE model (Matrix
//! Market or CalculiX) the lowest frequencies of the FE model on its supports (sparse
//! shift-invert Lanczos, [`FeModel::natural_frequencies_hz`]); for every model the modes of the
//! reduced (Craig-Bampton) model with the contacts open (free) and with the contacts' stuck
//! springs (stuck), each with its modal force and its share of the load
//! ([`natural_modes`]); the stuck mode `jprom run` uses for the band (the one nearest its
//! centre, [`stuck_mode`]), and a warning when the band holds no stuck mode.
//!
//! [`FeModel::natural_frequencies_hz`]: jprom::fe::FeModel::natural_frequencies_hz

use super::progress::Progress;
use super::run::{build_model_with, read_fe_model, reduce_fe_model};
use super::study::{ModelSpec, Study};
use jprom::error::{JpError, Result};
use jprom::jp::prediction::stuck_mode;
use jprom::model::modes::{natural_modes, Boundary, NaturalMode};
use jprom::model::ContactCoordinates;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// The lowest natural frequencies of the FE model before reduction.
#[derive(Clone, Debug)]
pub struct FeFrequencies {
    pub n_dof: usize,
    pub hz: Vec<f64>,
}

/// What `jprom modes` reports.
#[derive(Clone, Debug)]
pub struct ModesReport {
    /// The FE model's frequencies (FE models only).
    pub fe: Option<FeFrequencies>,
    pub reduced_dofs: usize,
    pub contacts: usize,
    /// Every mode of the reduced model, contacts open, lowest first.
    pub free: Vec<NaturalMode>,
    /// Every mode of the reduced model with the stuck contact springs, lowest first.
    pub stuck: Vec<NaturalMode>,
    /// The study's band in Hz.
    pub band_hz: (f64, f64),
    /// The stuck mode `jprom run` uses for the band (nearest its centre), Hz.
    pub band_stuck_hz: f64,
    /// Set when the band holds no stuck mode ([`band_warning`]).
    pub warning: Option<String>,
}

/// Whether `hz` lies in the band `(start, end)` (either order, edges included).
pub fn in_band(hz: f64, band_hz: (f64, f64)) -> bool {
    let (lo, hi) = (band_hz.0.min(band_hz.1), band_hz.0.max(band_hz.1));
    (lo..=hi).contains(&hz)
}

/// `None` if a stuck mode of `stuck` lies in the band; otherwise a warning naming the nearest
/// stuck mode, the one the runner uses (`chosen_hz`, nearest the band centre), and, as a band
/// centre with a band of the same width, the stuck mode the load drives most (largest
/// participation) among those within a factor 2 of the band (the nearest if none).
pub fn band_warning(stuck: &[NaturalMode], band_hz: (f64, f64), chosen_hz: f64) -> Option<String> {
    if stuck.iter().any(|m| in_band(m.frequency_hz, band_hz)) {
        return None;
    }
    let (lo, hi) = (band_hz.0.min(band_hz.1), band_hz.0.max(band_hz.1));
    let distance = |f: f64| if f < lo { lo - f } else { f - hi };
    let nearest = stuck.iter().min_by(|a, b| distance(a.frequency_hz).total_cmp(&distance(b.frequency_hz)));
    // the load's mode near the band: largest participation within a factor 2 of it (the top
    // modes of a Craig-Bampton model are its constraint modes, not the structure's)
    let near = |m: &&NaturalMode| m.frequency_hz > 0.0 && m.frequency_hz >= 0.5 * lo && m.frequency_hz <= 2.0 * hi;
    let driven = stuck.iter().filter(near).max_by(|a, b| a.participation.total_cmp(&b.participation)).or(nearest);
    let mut w = format!("the band {lo} - {hi} Hz holds no stuck mode");
    if let Some(n) = nearest {
        w.push_str(&format!(": the nearest is at {:.3} Hz (participation {:.3e})", n.frequency_hz, n.participation));
    }
    w.push_str(&format!("; levels and bases use the stuck mode nearest the band centre, {chosen_hz:.3} Hz"));
    if let Some(d) = driven {
        let half = 0.5 * (hi - lo);
        let f = d.frequency_hz;
        w.push_str(&format!(
            "; near the band the load drives the stuck mode at {f:.3} Hz most (participation {:.3e}): centre the band there, e.g. hz_start = {:.1}, hz_end = {:.1} (jprom modes STUDY lists the stuck modes)",
            d.participation,
            (f - half).max(0.0),
            f + half
        ));
    }
    Some(w)
}

/// The warning of [`band_warning`] when the stuck modes could not be computed (`e`): only the
/// stuck mode nearest the band centre is known, and it lies outside the band.
pub fn band_warning_without_modes(band_hz: (f64, f64), chosen_hz: f64, e: &JpError) -> String {
    format!(
        "the stuck mode nearest the centre of the band {} - {} Hz is at {chosen_hz:.3} Hz, outside the band: the band may hold no stuck mode (the stuck modes could not be listed: {e})",
        band_hz.0, band_hz.1
    )
}

/// The study's modes: reads the model (FE models: the lowest `count` FE frequencies first),
/// reduces it, and computes the free and stuck modes of the reduced model and the stuck mode
/// for the band, showing each step on `progress`.
///
/// # Errors
/// The model's reading and reduction errors (as `jprom run`'s); the eigensolvers'.
pub fn modes_report(study: &Study, count: usize, progress: Progress) -> Result<ModesReport> {
    let (fe, model) = match &study.model {
        ModelSpec::Fe(_) => {
            let read = read_fe_model(study, progress)?;
            let n = count.min(read.fe.n_dof());
            let step = progress.step(format!("FE natural frequencies ({n} lowest, shift-invert Lanczos, {} DoFs)", read.fe.n_dof()));
            let hz = read.fe.natural_frequencies_hz(n)?;
            step.done();
            let fe = FeFrequencies { n_dof: read.fe.n_dof(), hz };
            (Some(fe), reduce_fe_model(study, &read, progress)?)
        }
        ModelSpec::Blade { .. } => (None, build_model_with(study, progress)?),
    };
    let step = progress.step(format!("modes of the reduced model ({} DoFs), contacts open and stuck", model.n_dof()));
    let free = natural_modes(&model, Boundary::Free)?;
    let stuck = natural_modes(&model, Boundary::Stuck)?;
    step.done();
    let step = progress.step("stuck mode for the band");
    let band_hz = (study.band.hz_start, study.band.hz_end);
    let coords = ContactCoordinates::new(&model, study.discretisation())?;
    let band_stuck_hz = stuck_mode(&coords, (TWO_PI * band_hz.0, TWO_PI * band_hz.1))?.0 / TWO_PI;
    step.done_with(&format!(", {band_stuck_hz:.2} Hz"));
    let warning = band_warning(&stuck, band_hz, band_stuck_hz);
    Ok(ModesReport { fe, reduced_dofs: model.n_dof(), contacts: model.contacts.len(), free, stuck, band_hz, band_stuck_hz, warning })
}

/// The report as text: the FE frequencies (FE models), the lowest `count` free and stuck modes
/// of the reduced model side by side (`*`: a stuck mode in the band), the stuck mode for the
/// band, and the warning.
pub fn modes_table(r: &ModesReport, count: usize) -> String {
    let mut out = String::new();
    if let Some(fe) = &r.fe {
        out.push_str(&format!("FE model: {} DoFs, lowest {} natural frequencies on its supports (no contact):\n", fe.n_dof, fe.hz.len()));
        out.push_str(&format!("{:>6} {:>18}\n", "mode", "frequency Hz"));
        for (i, f) in fe.hz.iter().enumerate() {
            out.push_str(&format!("{:>6} {:>18.9e}\n", i + 1, f));
        }
    }
    let (lo, hi) = (r.band_hz.0.min(r.band_hz.1), r.band_hz.0.max(r.band_hz.1));
    out.push_str(&format!(
        "reduced model: {} DoFs (Craig-Bampton), {} contact nodes; modes with contacts open (free) and stuck; band {lo} - {hi} Hz (* stuck mode in the band)\n",
        r.reduced_dofs, r.contacts
    ));
    out.push_str(&format!(
        "{:>6} {:>18} {:>12} {:>13} {:>18} {:>12} {:>13} {}\n",
        "mode", "free Hz", "modal force", "participation", "stuck Hz", "modal force", "participation", "band"
    ));
    let n = count.min(r.free.len().max(r.stuck.len()));
    for i in 0..n {
        let cols = |m: Option<&NaturalMode>| match m {
            Some(m) => format!("{:>18.9e} {:>12.4e} {:>13.4e}", m.frequency_hz, m.modal_force, m.participation),
            None => format!("{:>18} {:>12} {:>13}", "-", "-", "-"),
        };
        let mark = r.stuck.get(i).map_or("", |m| if in_band(m.frequency_hz, r.band_hz) { "*" } else { "" });
        out.push_str(format!("{:>6} {} {} {}", i + 1, cols(r.free.get(i)), cols(r.stuck.get(i)), mark).trim_end());
        out.push('\n');
    }
    let inside = r.stuck.iter().filter(|m| in_band(m.frequency_hz, r.band_hz)).count();
    out.push_str(&format!("stuck modes in the band: {inside}\n"));
    out.push_str(&format!(
        "stuck mode for the band (nearest its centre, used by jprom run): {:.9e} Hz{}\n",
        r.band_stuck_hz,
        if in_band(r.band_stuck_hz, r.band_hz) { "" } else { ", outside the band" }
    ));
    if let Some(w) = &r.warning {
        out.push_str(&format!("warning: {w}\n"));
    }
    out
}
