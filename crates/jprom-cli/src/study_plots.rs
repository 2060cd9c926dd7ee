//! A study's figures ([`write_study_plots`]): per level the FRF, the static term, the energy
//! dissipated per contact and `e*_1` along the ROM sweeps; over the levels predicted against
//! actual error and the FRFs per unit of forcing; error against basis size (gamma study).

use super::plots::{solver_color, write_energy_map, write_plot, Dash, Legend, Marker, PlotSpec, Series, Style};
use super::labels::{response_words, units};
use super::rows::{BasisStudyRow, SolverRow};
use super::study::Study;
use jprom::error::Result;
use plotters::style::RGBColor;
use std::path::Path;

/// The study's figures: FRF and dissipated energy per level, predicted vs actual error and
/// error vs level over the levels, error vs basis size per level (gamma study).
pub(crate) fn write_study_plots(study: &Study, out_dir: &Path, summary: &CaseRows, plots: &CasePlots) -> Result<()> {
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

/// A case's curves for its plots, gathered from its units ([`write_study_plots`]).
pub(crate) struct CasePlots {
    /// The prefix of its files, its rows and gamma-study rows in the summary.
    pub(crate) prefix: String,
    pub(crate) rows: std::ops::Range<usize>,
    pub(crate) basis_rows: std::ops::Range<usize>,
    /// Per level: FRF (`|X1|`), static term, energy per contact, `e*_1` along the ROM sweeps.
    pub(crate) frf: Vec<(f64, Vec<Series>)>,
    pub(crate) frf0: Vec<(f64, Vec<Series>)>,
    pub(crate) energy: Vec<(f64, Vec<Series>)>,
    pub(crate) e_star: Vec<(f64, Vec<Series>)>,
    /// (actual, predicted) error pairs per ROM.
    pub(crate) err_points: Vec<(String, Vec<(f64, f64)>)>,
    /// Every level's FRFs per unit of the dynamic scale, on one chart.
    pub(crate) levels: Vec<Series>,
    /// The contact nodes' coordinates and frames (empty: no energy map).
    pub(crate) positions: Vec<[f64; 3]>,
    pub(crate) frames: Vec<[[f64; 3]; 3]>,
}

/// A case's part of the summary and the prefix of its files (empty without `[[cases]]`).
pub(crate) struct CaseRows<'a> {
    pub(crate) prefix: &'a str,
    pub(crate) rows: &'a [SolverRow],
    pub(crate) basis_study: &'a [BasisStudyRow],
}
