//! A study as independent work units: for each parameter case (`[[cases]]`, in study order; a
//! study without cases is one case), at each excitation level (in study order) the full-order
//! sweep, each reduced model's self-correcting sweep (FR, then NLR) and the gamma study, in the
//! order a serial run computes them: cases x levels x solvers.
//!
//! Every unit runs on its own from the study's shared inputs ([`crate::run::Shared`]: each
//! case's model on the one Craig-Bampton reduction, and its level reference, built once). The
//! ROM and gamma-study units of a level also take the level's full-order peak (their errors are
//! taken there), so they wait for the full-order unit of their case and level; nothing else
//! orders them. [`Dealer`] hands out the first unit in
//! study order whose full-order unit is done, to threads ([`run_units_threads`], `jprom run
//! --jobs N`) or to MPI ranks (`crate::mpi_run`, feature `mpi`); the outputs are merged in unit
//! order ([`crate::run::merge_units`]), so the CSVs do not depend on who ran what, or when.
//!
//! A unit that fails (an error outside its sweeps, or a panic) becomes one failed row of the
//! table naming the unit and why ([`crate::run::UnitOutput::failed`]); the other units' results
//! are kept and `jprom run` exits with status 3, as for a failed or incomplete sweep (which
//! `--keep-partial` or `output.keep_partial` accepts, failed units included).
//!
//! `JPROM_FAIL_UNIT=K` (a test hook) makes unit `K` (0-based, in the order above) fail with an
//! error, `JPROM_FAIL_UNIT=K:panic` makes it panic.

use crate::run::{FoPeak, UnitOutput, UnitRunner};
use crate::study::Study;
use serde::{Deserialize, Serialize};
use std::sync::{Condvar, Mutex};

/// What a unit computes at its level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum UnitKind {
    /// The full-order (condensed) sweep.
    FullOrder,
    /// The FR ROM's self-correcting sweep.
    Fr,
    /// The NLR ROM's self-correcting sweep.
    Nlr,
    /// Error vs basis size at the full-order resonance (`basis.gamma_study`).
    GammaStudy,
}

impl UnitKind {
    /// The solver's name in the table.
    pub fn solver(self) -> &'static str {
        match self {
            UnitKind::FullOrder => "FO (condensed)",
            UnitKind::Fr => "FR",
            UnitKind::Nlr => "NLR",
            UnitKind::GammaStudy => "gamma study",
        }
    }
}

/// One unit: a solver at a level of a case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Unit {
    /// Index of the case in [`Study::case_list`].
    pub case_index: usize,
    /// The case's name (empty for a study without `[[cases]]`).
    pub case: String,
    /// Index of the level in `forcing.levels`.
    pub level_index: usize,
    /// The level, `alpha / alpha_ST`.
    pub level: f64,
    pub kind: UnitKind,
    /// The unit whose full-order peak this one takes (the level's full-order unit).
    pub after: Option<usize>,
}

impl Unit {
    /// `FR at level 1e-1` (with cases: `FR at level 1e-1 of case mu0.2`).
    pub fn describe(&self) -> String {
        if self.case.is_empty() {
            format!("{} at level {:e}", self.kind.solver(), self.level)
        } else {
            format!("{} at level {:e} of case {}", self.kind.solver(), self.level, self.case)
        }
    }
}

/// The study's units in the order a serial run computes them (see the module doc).
pub fn study_units(study: &Study) -> Vec<Unit> {
    let mut units = Vec::new();
    let roms: Vec<UnitKind> = [(UnitKind::Fr, study.solvers.fr), (UnitKind::Nlr, study.solvers.nlr)].into_iter().filter(|k| k.1).map(|k| k.0).collect();
    for (case_index, case) in study.case_list().into_iter().enumerate() {
        let unit = |level_index: usize, level: f64, kind: UnitKind, after: Option<usize>| Unit { case_index, case: case.name.clone(), level_index, level, kind, after };
        for (level_index, &level) in study.forcing.levels.iter().enumerate() {
            let mut after = None;
            if study.solvers.full_order {
                after = Some(units.len());
                units.push(unit(level_index, level, UnitKind::FullOrder, None));
            }
            for &kind in &roms {
                units.push(unit(level_index, level, kind, after));
            }
            if study.solvers.full_order && !roms.is_empty() && !study.basis.gamma_study.is_empty() {
                units.push(unit(level_index, level, UnitKind::GammaStudy, after));
            }
        }
    }
    units
}

/// What [`Dealer::next`] says.
#[derive(Debug)]
pub enum Next {
    /// Run this unit, with its level's full-order peak if it has one.
    Run(usize, Option<FoPeak>),
    /// Every unit left waits for a full-order unit still running: ask again when one ends.
    Wait,
    /// Every unit has been handed out.
    Finished,
}

/// Hands out units as workers become free, first in study order among those whose full-order
/// unit is done, and keeps their outputs.
pub struct Dealer {
    units: Vec<Unit>,
    given: Vec<bool>,
    outputs: Vec<Option<UnitOutput>>,
}

impl Dealer {
    pub fn new(units: &[Unit]) -> Self {
        Dealer { units: units.to_vec(), given: vec![false; units.len()], outputs: vec![None; units.len()] }
    }

    /// The next unit to run (see [`Next`]).
    pub fn next(&mut self) -> Next {
        let mut waiting = false;
        for i in 0..self.units.len() {
            if self.given[i] {
                continue;
            }
            match self.units[i].after {
                Some(j) if self.outputs[j].is_none() => waiting = true,
                after => {
                    self.given[i] = true;
                    let fo = after.and_then(|j| self.outputs[j].as_ref().and_then(|o| o.fo_peak.clone()));
                    return Next::Run(i, fo);
                }
            }
        }
        if waiting {
            Next::Wait
        } else {
            Next::Finished
        }
    }

    /// Keeps unit `i`'s output.
    pub fn done(&mut self, i: usize, out: UnitOutput) {
        self.outputs[i] = Some(out);
    }

    /// Whether every unit's output is in.
    pub fn all_done(&self) -> bool {
        self.outputs.iter().all(Option::is_some)
    }

    /// The outputs in unit order (a unit never handed back counts as failed).
    pub fn into_outputs(self) -> Vec<UnitOutput> {
        let units = self.units;
        self.outputs.into_iter().enumerate().map(|(i, o)| o.unwrap_or_else(|| UnitOutput::failed(&units[i], i, "no result came back"))).collect()
    }
}

/// Runs unit `i`: its output, or its failure (an error, a panic, or the `JPROM_FAIL_UNIT` test
/// hook) as a failed row naming it (and `rank`, the MPI rank that ran it, if given).
pub fn run_unit(runner: &UnitRunner, units: &[Unit], i: usize, fo: Option<&FoPeak>, rank: Option<usize>) -> UnitOutput {
    let unit = &units[i];
    let forced = std::env::var("JPROM_FAIL_UNIT").ok().and_then(|v| {
        let (k, how) = v.split_once(':').unwrap_or((v.as_str(), ""));
        (k.trim().parse::<usize>().ok() == Some(i)).then(|| how.trim() == "panic")
    });
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        match forced {
            Some(true) => panic!("forced panic of unit {i} (JPROM_FAIL_UNIT)"),
            Some(false) => return Err("forced failure (JPROM_FAIL_UNIT)".to_string()),
            None => {}
        }
        runner.run(unit, fo).map_err(|e| e.to_string())
    }));
    let on = rank.map(|r| format!("on rank {r}: ")).unwrap_or_default();
    match result {
        Ok(Ok(out)) => out,
        Ok(Err(reason)) => UnitOutput::failed(unit, i, &format!("{on}{reason}")),
        Err(panic) => {
            let what = panic.downcast_ref::<String>().cloned().or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string())).unwrap_or_default();
            UnitOutput::failed(unit, i, &format!("{on}panicked: {what}"))
        }
    }
}

/// Runs `units` in `jobs` threads (at least one; one runs them in this thread, in order), each
/// taking the next unit from a [`Dealer`] when it is free; the outputs in unit order.
pub fn run_units_threads(runner: &UnitRunner, units: &[Unit], jobs: usize) -> Vec<UnitOutput> {
    let dealer = Mutex::new(Dealer::new(units));
    let changed = Condvar::new();
    let work = || loop {
        let (i, fo) = {
            let mut d = dealer.lock().unwrap_or_else(|e| e.into_inner());
            loop {
                match d.next() {
                    Next::Run(i, fo) => break (i, fo),
                    Next::Wait => d = changed.wait(d).unwrap_or_else(|e| e.into_inner()),
                    Next::Finished => return,
                }
            }
        };
        let out = run_unit(runner, units, i, fo.as_ref(), None);
        dealer.lock().unwrap_or_else(|e| e.into_inner()).done(i, out);
        changed.notify_all();
    };
    let jobs = jobs.clamp(1, units.len().max(1));
    if jobs == 1 {
        work();
    } else {
        std::thread::scope(|s| {
            for k in 0..jobs {
                // the main thread's stack size, not the 2 MB default of spawned threads
                std::thread::Builder::new().name(format!("jprom-unit-{k}")).stack_size(8 << 20).spawn_scoped(s, || work()).expect("a unit thread");
            }
        });
    }
    dealer.into_inner().unwrap_or_else(|e| e.into_inner()).into_outputs()
}
