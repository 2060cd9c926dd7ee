//! The robustness campaign (docs/formulation.md §6.9, `jprom_testkit::campaign`): random solid
//! FE models, ten levels each from stuck to gross slip, `H` = 1, 3 or 5, `Nt` 64 to 256, the
//! full order and the self-correcting FR and NLR sweeps, each checked (band end, cold starts,
//! `e*` against the full order). Prints one line per sweep and the summary: sweeps, reached
//! end, gaps, stalls, turned back, median points per sweep, time.
//!
//! `cargo bench --bench continuation_campaign` (defaults: 10 models x 10 levels x 3 solvers =
//! 300 sweeps, seed 2026). `JPROM_CAMPAIGN_MODELS`, `JPROM_CAMPAIGN_SEED`,
//! `JPROM_CAMPAIGN_LEVELS` (levels per model, evenly picked from the ten),
//! `JPROM_CAMPAIGN_SOLVERS` (`fo`, `fo,fr`, ...) and `JPROM_CAMPAIGN_METHOD=secant` (the
//! earlier continuation, for the comparison) change it.

use jprom::hbm::ContinuationMethod;
use jprom_testkit::campaign::{self, Outcome, Solver};
use rand::rngs::StdRng;
use rand::SeedableRng;

fn env<T: std::str::FromStr>(key: &str, default: T) -> T {
    std::env::var(key).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
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
    let method = match env("JPROM_CAMPAIGN_METHOD", "oriented".to_string()).as_str() {
        "secant" => ContinuationMethod::Secant,
        _ => ContinuationMethod::Oriented,
    };
    let t0 = std::time::Instant::now();
    let (models, failed) = campaign::models(seed, n_models);
    for (spec, why) in &failed {
        println!("model not built ({}): {why}", spec.describe());
    }
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
            for o in campaign::run_level(index, built, level, harmonics, nt, &solvers, method, 20, seed + (100 * index + k) as u64) {
                campaign::print_outcome(&o);
                outcomes.push(o);
            }
        }
    }
    campaign::print_summary(&outcomes, t0.elapsed().as_secs_f64());
}
