//! The robustness campaign's subset (docs/formulation.md §6.9; the whole campaign is
//! `cargo bench --bench continuation_campaign`): four random solid FE models (seed 57, every contact site among them), four
//! of the ten levels from stuck to gross slip, H = 1 and Nt = 64, the full order and the
//! self-correcting FR and NLR sweeps: 48 sweeps. Every sweep reaches the band's end without
//! running back out of the band; 20 of each sweep's points, solved again from zero, agree with
//! it or with another point it traced at that frequency; no reduced point is called good (its
//! judged error, §10.7, below the threshold) with an X1 error above twice the threshold, the
//! judged error is at least `e_1` wherever `e_1 > 1e-6`, and a sweep that says it can be
//! trusted has its peak within 0.5 % in frequency and 1 % in X1 of the full order's.

use jprom::hbm::ContinuationMethod;
use jprom_testkit::campaign::{self, Solver};

#[test]
fn campaign_subset_reaches_every_band_end_and_agrees_with_cold_starts() {
    let started = std::time::Instant::now();
    let models = campaign::models_with_every_site(57, 4);
    assert_eq!(models.len(), 4, "models built");
    let levels = campaign::levels();
    let picked = [levels[0], levels[3], levels[6], levels[9]];
    let mut outcomes = Vec::new();
    for (index, (spec, built)) in models.iter().enumerate() {
        println!("model {index}: {} ({} FE DoFs, {} contacts)", spec.describe(), built.n_fe_dofs, built.model.contacts.len());
        for (k, &level) in picked.iter().enumerate() {
            for o in campaign::run_level(index, built, level, 1, 64, &[Solver::Fo, Solver::Fr, Solver::Nlr], ContinuationMethod::Oriented, 20, 57 + (10 * index + k) as u64) {
                campaign::print_outcome(&o);
                outcomes.push(o);
            }
        }
    }
    campaign::print_summary(&outcomes, started.elapsed().as_secs_f64());
    assert!(outcomes.len() >= 40, "{} sweeps", outcomes.len());
    let mut problems = Vec::new();
    for o in &outcomes {
        let what = format!("model {} level {:.3} {}", o.model, o.level, o.solver.name());
        if !o.reached_end() {
            problems.push(format!("{what}: {:?} {:?} {:?}", o.end, o.error, o.failure));
        }
        if o.turned_back {
            problems.push(format!("{what}: ran back out of the band"));
        }
        if !o.cold.disagreed.is_empty() || !o.cold.failed.is_empty() {
            problems.push(format!("{what}: cold starts disagree at {:?}, failed at {:?}", o.cold.disagreed, o.cold.failed));
        }
        if let Some(r) = &o.rom {
            if !r.called_good_far_off.is_empty() {
                problems.push(format!("{what}: called good with X1 off by more than twice the threshold at {:?}", r.called_good_far_off));
            }
            if !r.not_conservative.is_empty() {
                problems.push(format!("{what}: judged error below e_1 (above 1e-6) at {:?}", r.not_conservative));
            }
            if r.trusted && (r.peak_omega_error > 5e-3 || r.peak_x1_error > 1e-2) {
                problems.push(format!("{what}: trusted, but its peak is off by {:.2e} in frequency and {:.2e} in X1", r.peak_omega_error, r.peak_x1_error));
            }
        }
    }
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
}
