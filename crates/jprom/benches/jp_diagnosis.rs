//! Why reduced branches leave the full order on an inclined patch pressed on a wall (issue 59,
//! item 1; docs/formulation.md §10.8). At each of the campaign's ten levels, from stuck to gross
//! slip with liftoff, the condensed full order, then FR and NLR with their first basis alone (no
//! corrections) and at the defaults. For each reduced sweep at its worst point (largest actual
//! `e_1`): `e_1`, the contact motion's distance to the full order (`d`) and the basis' own
//! (`p`, the part of the full order's motion outside the basis), the open share of the contact
//! samples (full order / reduced), the frequency reversals (reduced / full order) and the cause
//! (`jprom_testkit::campaign::diagnosis`).
//!
//! `cargo bench --bench jp_diagnosis`; `JPROM_DIAGNOSIS_H=3` for `H = 3`.

use jprom::aft::Discretisation;
use jprom::condensation::CondensedSystem;
use jprom::hbm::{sweep, HbmOptions, SweepOptions};
use jprom::jp::PredictionOptions;
use jprom::model::ContactCoordinates;
use jprom::rom::error_metric::POOR_BASIS_THRESHOLD;
use jprom::rom::{adaptive_sweep, AdaptiveOptions, FrRom, NlrRom, ReducedModel, RomKind};
use jprom_testkit::campaign::{self, diagnosis, model};
use std::ops::ControlFlow;

fn main() {
    let harmonics: usize = std::env::var("JPROM_DIAGNOSIS_H").ok().and_then(|v| v.parse().ok()).unwrap_or(1);
    let spec = model::ModelSpec::inclined_patch(10, 25f64.to_radians());
    let built = model::build(&spec, None).expect("the inclined-patch model builds");
    let disc = Discretisation::with_nt(harmonics, 64.max(32 * harmonics).next_power_of_two());
    let hopts = HbmOptions::default();
    let sopts = SweepOptions::band(built.band.0, built.band.1);
    println!("== inclined patch ({} contacts, {} FE DoFs), H = {harmonics}", built.model.contacts.len(), built.n_fe_dofs);
    println!("| level | solver | basis | n_h | points | reversals ROM / FO | worst e_1 | d | p | open FO / ROM | cause | largest p | verdict |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut causes = std::collections::BTreeMap::<(&str, &str, &str), usize>::new();
    for level in campaign::levels() {
        let mut m = built.model.clone();
        m.excitation.dynamic_scale = built.level_scale / level;
        let condensed = CondensedSystem::new(&m, disc).expect("the condensed system");
        let coords = ContactCoordinates::new(&m, disc).expect("the contact coordinates");
        let fo = sweep(&condensed, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).expect("the full-order sweep");
        for (solver, kind) in [("FR", RomKind::Fr), ("NLR", RomKind::Nlr)] {
            for (label, corrections) in [("first", 0), ("defaults", AdaptiveOptions::default().max_corrections)] {
                let opts = AdaptiveOptions { kind, max_corrections: corrections, ..AdaptiveOptions::default() };
                let a = match adaptive_sweep(&m, disc, &PredictionOptions::new(built.band), &sopts, &hopts, &opts) {
                    Ok(a) => a,
                    Err(e) => {
                        println!("| {level:.3e} | {solver} | {label} | - | - | - | - | - | - | - | failed: {e} | - | - |");
                        continue;
                    }
                };
                let rom: Box<dyn ReducedModel> = match kind {
                    RomKind::Fr => Box::new(FrRom::new(&coords, &a.basis).expect("the sweep's own basis")),
                    RomKind::Nlr => Box::new(NlrRom::new(&condensed, &a.basis).expect("the sweep's own basis")),
                };
                let d = diagnosis::diagnose(&condensed, &fo, rom.as_ref(), &a.basis, &a.sweep, &hopts, POOR_BASIS_THRESHOLD);
                *causes.entry((solver, label, d.cause.name())).or_default() += 1;
                let verdict = a.trust.reason.as_deref().map_or("trusted".to_string(), |w| format!("not trusted: {w}"));
                let end = if a.sweep.reached_end() { String::new() } else { format!(" ({})", a.sweep.end.name()) };
                match &d.worst {
                    Some(w) => println!(
                        "| {level:.3e} | {solver} | {label} | {:?} | {}{end} | {} / {} | {:.2e} | {:.2e} | {:.2e} | {:.2} / {:.2} | {} | {:.2e} | {verdict} |",
                        a.basis.sizes, d.points, d.reversals, d.fo_reversals, w.e1, w.displacement_error, w.projection_error, w.open_fo, w.open_rom, d.cause.name(), d.worst_projection
                    ),
                    None => println!("| {level:.3e} | {solver} | {label} | {:?} | {}{end} | {} / {} | - | - | - | - | no point compared | - | {verdict} |", a.basis.sizes, d.points, d.reversals, d.fo_reversals),
                }
            }
        }
    }
    println!("\n| solver | basis | cause | sweeps |");
    println!("|---|---|---|---|");
    for ((solver, label, cause), n) in causes {
        println!("| {solver} | {label} | {cause} | {n} |");
    }
}
