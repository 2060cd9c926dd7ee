//! What a study produced ([`RunSummary`], written as `summary.json`) and its fixed-width text
//! table ([`summary_table`], printed by `jprom run`).

use super::rows::{BasisStudyRow, SolverRow};
use serde::Serialize;

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
