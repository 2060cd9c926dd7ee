//! Falling back to the full order (`solvers.fall_back = true`, `jprom run --fall-back`).
//!
//! A reduced sweep that is not trusted (its verdict, docs/formulation.md §10.7: the final pass
//! did not cover the band, or a point's judged error is above the threshold), that did not
//! cover the band, or whose unit failed, does not give the level's result. With fall back on:
//!
//! - at a level without a full-order unit (`solvers.full_order = false`), the full-order sweep
//!   runs there after the study's units, and its row takes the level's place in the table;
//! - at a level with one, the full-order row is already there.
//!
//! Either way the full-order row names the reduced models it stands in for and why
//! (`SolverRow::stands_in_for`), and each of those rows says that the full order's row stands
//! in for it. The decision rests on the verdicts only, not on times, so `summary.json` of a
//! reproducible run does not depend on the machine's speed; where a reduced model cost more
//! than the full order, the table says so beside the row.
//!
//! Under MPI, rank 0 runs the fall-back sweeps in its `--jobs` threads once the other ranks'
//! units are in.

use crate::run::{SolverRow, UnitOutput, UnitRunner};
use crate::units::{run_units_threads, Unit, UnitKind};

/// Why a reduced row does not give its level's result, `None` where it does (or for the full
/// order's own rows).
pub fn why_fall_back(row: &SolverRow) -> Option<String> {
    if row.solver.starts_with("FO") {
        return None;
    }
    if row.trusted == Some(false) {
        return Some(format!("not trusted: {}", row.trust_reason.clone().unwrap_or_else(|| "no reason given".into())));
    }
    if !row.complete {
        return Some(format!("incomplete: {}", row.warnings.first().cloned().unwrap_or_else(|| row.end_reason.clone())));
    }
    None
}

/// The warning a reduced row carries when the full order stands in for it.
pub const STOOD_IN: &str = "the full order's row stands in for this one at this level (solvers.fall_back)";

/// `units` and their `outputs` (in unit order) with the fall-back full-order sweeps run and
/// placed after the units of their level, and the rows marked (see the module doc). Without
/// fall back, both as they were.
pub fn with_fall_backs(runner: &UnitRunner, fall_back: bool, units: Vec<Unit>, mut outputs: Vec<UnitOutput>, jobs: usize) -> (Vec<Unit>, Vec<UnitOutput>) {
    if !fall_back {
        return (units, outputs);
    }
    // per (case, level): the units' indices, whether the full order ran, the reasons
    let mut levels: Vec<((usize, usize), Vec<usize>)> = Vec::new();
    for (i, u) in units.iter().enumerate() {
        let key = (u.case_index, u.level_index);
        match levels.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(i),
            None => levels.push((key, vec![i])),
        }
    }
    let mut new_units = Vec::new();
    let mut owed: Vec<(usize, Vec<String>)> = Vec::new(); // (index of the level's last unit, reasons)
    for (_, idx) in &levels {
        let reasons: Vec<String> = idx.iter().flat_map(|&i| outputs[i].rows.iter()).filter_map(|r| why_fall_back(r).map(|w| format!("{}: {w}", r.solver))).collect();
        if reasons.is_empty() {
            continue;
        }
        for &i in idx {
            for r in outputs[i].rows.iter_mut().filter(|r| why_fall_back(r).is_some()) {
                r.warnings.push(STOOD_IN.into());
            }
        }
        match idx.iter().find(|&&i| units[i].kind == UnitKind::FullOrder) {
            Some(&fo) => {
                for r in outputs[fo].rows.iter_mut().filter(|r| r.solver.starts_with("FO")) {
                    r.stands_in_for.clone_from(&reasons);
                }
            }
            None => {
                let u = &units[idx[0]];
                new_units.push(Unit { kind: UnitKind::FullOrder, after: None, ..u.clone() });
                owed.push((*idx.last().expect("a level has a unit"), reasons));
            }
        }
    }
    if new_units.is_empty() {
        return (units, outputs);
    }
    let mut fo_outputs = run_units_threads(runner, &new_units, jobs);
    for (out, (_, reasons)) in fo_outputs.iter_mut().zip(&owed) {
        for r in &mut out.rows {
            r.stands_in_for.clone_from(reasons);
        }
    }
    // place each after the last unit of its level, from the back so the indices hold
    let mut units = units;
    for ((unit, out), (after, _)) in new_units.into_iter().zip(fo_outputs).zip(owed).rev() {
        units.insert(after + 1, unit);
        outputs.insert(after + 1, out);
    }
    (units, outputs)
}
