//! Whether the reduced models pay (issue 59 performance, docs/formulation.md §10.7): a whole
//! study per model, every level swept by the condensed full order and by the self-correcting FR
//! and NLR sweeps at the library's defaults (100 samples, threshold 0.05, corrections and
//! checks on; each level predicts its own first basis), `H` = 1. Prints per level the seconds
//! (a ROM's: its basis, corrections, checks and passes), the full order's time over the ROM's,
//! the peak errors against the full order and the verdict, then the study's totals.
//!
//! Models: the generated inclined-patch cantilever (33 contacts, ten levels from stuck to gross
//! slip) and the built-in blade at refinements 2 and 5 (CB(50), four levels from `alpha_ST` to
//! `alpha_ST / 3000`). `cargo bench --bench jp_study`; `JPROM_STUDY_MODELS=patch,blade2,blade5`
//! picks some.

use jprom::hbm::ContinuationMethod;
use jprom_testkit::blade::Blade;
use jprom_testkit::campaign::{self, model, model::Built, Outcome, Solver};

fn blade(refinement: usize) -> Built {
    let blade = Blade::build_refined(refinement);
    let model = blade.at_level(blade.alpha_st);
    Built { level_scale: model.excitation.dynamic_scale, n_fe_dofs: 0, model, band: blade.band, reference: "alpha_ST".into() }
}

fn main() {
    let wanted = std::env::var("JPROM_STUDY_MODELS").unwrap_or_else(|_| "patch,blade2,blade5".into());
    let mut studies: Vec<(String, Built, Vec<f64>)> = Vec::new();
    for name in wanted.split(',').map(str::trim) {
        match name {
            "patch" => {
                let spec = model::ModelSpec::inclined_patch(10, 25f64.to_radians());
                let built = model::build(&spec, None).expect("the inclined-patch model builds");
                studies.push((format!("inclined patch ({} contacts)", built.model.contacts.len()), built, campaign::levels()));
            }
            "blade2" | "blade5" => {
                let r = if name == "blade2" { 2 } else { 5 };
                let b = blade(r);
                studies.push((format!("blade, refinement {r} ({} contacts)", b.model.contacts.len()), b, vec![1.0, 0.1, 0.01, 1.0 / 3000.0]));
            }
            other => eprintln!("unknown model {other:?} (patch, blade2, blade5)"),
        }
    }
    let mut totals = Vec::new();
    for (name, built, levels) in &studies {
        println!("== {name}, H = 1, {} levels", levels.len());
        println!("| level | solver | points | s | FO s / s | peak omega err | peak X1 err | judged | verdict |");
        println!("|---|---|---|---|---|---|---|---|---|");
        let mut sum = [0.0f64; 3];
        for (k, &level) in levels.iter().enumerate() {
            let run: Vec<Outcome> = campaign::run_level(0, built, level, 1, 64, &[Solver::Fo, Solver::Fr, Solver::Nlr], ContinuationMethod::Oriented, 0, 59 + k as u64);
            let fo_seconds = run.iter().find(|o| o.solver == Solver::Fo).map_or(f64::NAN, |o| o.seconds);
            for o in &run {
                let slot = match o.solver {
                    Solver::Fo => 0,
                    Solver::Fr => 1,
                    Solver::Nlr => 2,
                };
                sum[slot] += o.seconds;
                let end = if o.reached_end() { String::new() } else { format!(" ({})", o.end.name()) };
                match &o.rom {
                    None => println!("| {level:.3e} | {} | {}{end} | {:.2} | - | - | - | - | - |", o.solver.name(), o.points, o.seconds),
                    Some(r) => println!(
                        "| {level:.3e} | {} | {}{end} | {:.2} | {:.2}x | {:.1e} | {:.1e} | {:.1e} | {} |",
                        o.solver.name(),
                        o.points,
                        o.seconds,
                        fo_seconds / o.seconds,
                        r.peak_omega_error,
                        r.peak_x1_error,
                        r.judged,
                        r.trust_reason.as_deref().map_or("trusted".to_string(), |w| format!("not trusted: {w}"))
                    ),
                }
            }
        }
        println!("whole study: FO {:.1} s, FR {:.1} s ({:.2}x), NLR {:.1} s ({:.2}x)\n", sum[0], sum[1], sum[0] / sum[1], sum[2], sum[0] / sum[2]);
        totals.push((name.clone(), sum));
    }
    println!("| model | FO s | FR s | FO / FR | NLR s | FO / NLR |");
    println!("|---|---|---|---|---|---|");
    for (name, s) in totals {
        println!("| {name} | {:.1} | {:.1} | {:.2}x | {:.1} | {:.2}x |", s[0], s[1], s[0] / s[1], s[2], s[0] / s[2]);
    }
}
