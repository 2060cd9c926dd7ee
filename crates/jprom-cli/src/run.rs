//! Runs a [`Study`]: builds the model (built-in blade, or Matrix Market `M`, `K` with a node/DoF
//! map, then Craig-Bampton; each parameter case's contact laws, damping and static load on it),
//! sweeps the band with the condensed full-order solver and the FR and NLR reduced models at
//! each excitation level of each case, evaluates the error predictor, optionally
//! studies error vs basis size (`basis.gamma_study`), and writes CSV, JSON and SVG results.
//!
//! The parts it calls on: [`crate::study_model`] (the model), [`crate::shared`] (what every unit
//! shares), [`crate::units`] (the work units and who runs them), [`crate::fall_back`] (the full
//! order where a reduced sweep is not trusted), [`crate::rows`] and [`crate::summary`] (the
//! results), [`crate::study_plots`] (the figures), [`crate::labels`] (units and names).

use super::plots::{level_series, Series};
use super::study::Study;
use super::progress::Progress;
use super::progress as jprom_progress;
use jprom::condensation::CondensedSystem;
use jprom::contact::ContactState;
use jprom::error::{JpError, Result};
use jprom::rom::error_metric::{actual_error, predicted_error, reduced_contact_cycles};
use jprom::hbm::{solve_point, sweep, HarmonicSystem, HbmOptions, PointSolution, SweepOptions, SweepResult};
use jprom::jp::prediction::PredictionOptions;
use jprom::jp::predict_basis;
use jprom::model::ContactCoordinates;
use jprom::rom::{adaptive_sweep_from, reduced_model, AdaptiveOptions, RomKind};
use serde::{Deserialize, Serialize};
use super::units::{run_units_threads, study_units, Unit, UnitKind};
use std::io::Write;
use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

pub use super::labels::{response_words, units};
pub use super::rows::{BasisStudyRow, EventRow, GapRow, SolverRow};
pub use super::shared::{build_shared, rom_kinds, prediction_options, shared_basis, CaseShared, Shared, SharedBasis};
use super::study_plots::{write_study_plots, CasePlots, CaseRows};
pub use super::summary::{summary_table, CaseSummary, RunSummary, SharedBasisSummary, SolverTotal};
pub use super::study_model::{build_case_models, build_fe_model, build_matrix_market_model, build_model, build_model_with, read_fe_model, reduce_fe_model, reduce_fe_model_undamped, FeStudyModel};

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
