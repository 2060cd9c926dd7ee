//! The robustness campaign (docs/formulation.md §6.9, `jprom_testkit::campaign`): random solid
//! FE models, ten levels each from stuck to gross slip, `H` = 1, 3 or 5, `Nt` 64 to 256, the
//! full order and the self-correcting FR and NLR sweeps, each checked (band end, cold starts,
//! `e*` against the full order). Prints one line per sweep and the summary: sweeps, reached
//! end, gaps (each listed with why), stalls, turned back, median points per sweep, time.
//!
//! `cargo bench --bench continuation_campaign` (defaults: 10 models x 10 levels x 3 solvers =
//! 300 sweeps, seed 2026, the oriented continuation). `JPROM_CAMPAIGN_MODELS`,
//! `JPROM_CAMPAIGN_SEED`, `JPROM_CAMPAIGN_LEVELS` (levels per model, evenly picked from the
//! ten), `JPROM_CAMPAIGN_SOLVERS` (`fo`, `fo,fr`, ...) change it. `JPROM_CAMPAIGN_METHOD`:
//! `oriented` (default), `secant` (the earlier continuation), or `both`: the same sweeps by
//! each, then the built-in demo blade (18 contacts, CB(50), 2,140-2,190 Hz) at five levels by
//! each, and a table of points and time per sweep, one method against the other.

use jprom::hbm::ContinuationMethod;
use jprom_testkit::blade::Blade;
use jprom_testkit::campaign::{self, model::Built, Outcome, Solver};
use rand::rngs::StdRng;
use rand::SeedableRng;

fn env<T: std::str::FromStr>(key: &str, default: T) -> T {
    std::env::var(key).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn name(m: ContinuationMethod) -> &'static str {
    match m {
        ContinuationMethod::Oriented => "oriented",
        ContinuationMethod::Secant => "secant",
    }
}

/// The campaign's sweeps by `method`.
fn campaign_run(models: &[(campaign::model::ModelSpec, Built)], seed: u64, per_model: usize, solvers: &[Solver], method: ContinuationMethod) -> Vec<Outcome> {
    let all_levels = campaign::levels();
    let picked: Vec<f64> = (0..per_model.min(10)).map(|k| all_levels[k * 10 / per_model.min(10)]).collect();
    let mut rng = StdRng::seed_from_u64(seed ^ 0x5eed);
    let mut outcomes: Vec<Outcome> = Vec::new();
    for (index, (spec, built)) in models.iter().enumerate() {
        let harmonics = campaign::random_harmonics(&mut rng);
        let nt = campaign::random_nt(&mut rng, harmonics);
        println!(
            "model {index}: {} ({} FE DoFs, {} reduced, {} contacts), band {:.1}-{:.1} Hz, level 1 = {}",
            spec.describe(),
            built.n_fe_dofs,
            built.model.n_dof(),
            built.model.contacts.len(),
            built.band.0 / std::f64::consts::TAU,
            built.band.1 / std::f64::consts::TAU,
            built.reference
        );
        for (k, &level) in picked.iter().enumerate() {
            for o in campaign::run_level(index, built, level, harmonics, nt, solvers, method, 20, seed + (100 * index + k) as u64) {
                campaign::print_outcome(&o);
                outcomes.push(o);
            }
        }
    }
    outcomes
}

/// The demo blade as a campaign model: level 1 is `alpha_ST`.
fn demo_blade() -> Built {
    let blade = Blade::build();
    let model = blade.at_level(blade.alpha_st);
    Built { level_scale: model.excitation.dynamic_scale, n_fe_dofs: 0, model, band: blade.band, reference: "alpha_ST".into() }
}

/// Median points and total seconds per solver.
fn per_solver(outcomes: &[Outcome], solver: Solver) -> Option<(usize, usize, f64, usize)> {
    let of: Vec<&Outcome> = outcomes.iter().filter(|o| o.solver == solver).collect();
    if of.is_empty() {
        return None;
    }
    let mut points: Vec<usize> = of.iter().map(|o| o.points).collect();
    points.sort_unstable();
    Some((of.len(), points[points.len() / 2], of.iter().map(|o| o.seconds).sum(), of.iter().filter(|o| o.reached_end()).count()))
}

fn main() {
    let n_models: usize = env("JPROM_CAMPAIGN_MODELS", 10);
    let seed: u64 = env("JPROM_CAMPAIGN_SEED", 2026);
    let per_model: usize = env("JPROM_CAMPAIGN_LEVELS", 10);
    let solvers: Vec<Solver> = env("JPROM_CAMPAIGN_SOLVERS", "fo,fr,nlr".to_string())
        .split(',')
        .map(|s| match s.trim() {
            "fo" => Solver::Fo,
            "fr" => Solver::Fr,
            "nlr" => Solver::Nlr,
            other => panic!("unknown solver {other}"),
        })
        .collect();
    let methods: Vec<ContinuationMethod> = match env("JPROM_CAMPAIGN_METHOD", "oriented".to_string()).as_str() {
        "secant" => vec![ContinuationMethod::Secant],
        "both" => vec![ContinuationMethod::Oriented, ContinuationMethod::Secant],
        _ => vec![ContinuationMethod::Oriented],
    };
    let t0 = std::time::Instant::now();
    let (models, failed) = campaign::models(seed, n_models);
    for (spec, why) in &failed {
        println!("model not built ({}): {why}", spec.describe());
    }
    println!("{} models built in {:.1} s", models.len(), t0.elapsed().as_secs_f64());
    let mut runs = Vec::new();
    for &method in &methods {
        println!("== the campaign, {} continuation", name(method));
        let t = std::time::Instant::now();
        let outcomes = campaign_run(&models, seed, per_model, &solvers, method);
        campaign::print_summary(&outcomes, t.elapsed().as_secs_f64());
        runs.push((method, "campaign", outcomes));
    }
    if methods.len() > 1 {
        let demo = demo_blade();
        for &method in &methods {
            println!("== the demo blade, {} continuation", name(method));
            let mut outcomes = Vec::new();
            for (k, level) in [2.0, 0.2, 0.05, 0.02, 0.002].into_iter().enumerate() {
                for o in campaign::run_level(0, &demo, level, 1, 64, &solvers, method, 0, seed + k as u64) {
                    campaign::print_outcome(&o);
                    outcomes.push(o);
                }
            }
            runs.push((method, "demo blade", outcomes));
        }
        println!("== oriented against secant: sweeps, reached the end, median points, total seconds");
        for case in ["campaign", "demo blade"] {
            for solver in &solvers {
                let row: Vec<String> = runs
                    .iter()
                    .filter(|(_, c, _)| *c == case)
                    .filter_map(|(m, _, o)| per_solver(o, *solver).map(|(n, median, secs, reached)| format!("{} {n} sweeps, {reached} reached, median {median} points, {secs:.1} s", name(*m))))
                    .collect();
                println!("{case:>10} {:>3}: {}", solver.name(), row.join(" | "));
            }
        }
    }
    println!("total {:.1} s", t0.elapsed().as_secs_f64());
}
