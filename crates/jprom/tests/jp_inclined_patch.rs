//! JP on the class of model where e* once called a 200 % error good (docs/formulation.md
//! §10.7): a generated cantilever whose inclined end is pressed by a static force against a
//! rigid wall through 33 contact nodes (one normal, area-weighted stiffnesses, liftoff over
//! part of the cycle at the middle levels), ten levels from stuck to gross slip, H = 1 and
//! H = 3, the full order and the self-correcting FR and NLR sweeps at the defaults. Every
//! reduced sweep reaches the band's end; where it says it can be trusted, its peak is within
//! 0.5 % in frequency and 1 % in X1 of the full order's; at every reduced point compared with a
//! full-order solution at its frequency, the judged error is at least the actual one
//! (e > 1e-6), and no point judged good has an X1 error above twice the threshold.

use jprom::hbm::ContinuationMethod;
use jprom_testkit::campaign::{self, model, Solver};

#[test]
fn reduced_sweeps_on_an_inclined_pressed_patch_are_trusted_only_where_right() {
    let started = std::time::Instant::now();
    let spec = model::ModelSpec::inclined_patch(10, 25f64.to_radians());
    let built = model::build(&spec, None).expect("the inclined-patch model builds");
    let contacts = built.model.contacts.len();
    assert!((20..=60).contains(&contacts), "{contacts} contact nodes");
    println!("{} ({} FE DoFs, {contacts} contacts), level 1 = {}", spec.describe(), built.n_fe_dofs, built.reference);
    // the twenty (H, level) cases on two workers, each case's sweeps in order
    let cases: Vec<(usize, usize, f64)> = [1, 3].into_iter().flat_map(|h| campaign::levels().into_iter().enumerate().map(move |(k, level)| (h, k, level))).collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut outcomes: Vec<_> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..2)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    while let Some(&(harmonics, k, level)) = cases.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed)) {
                        let run = campaign::run_level(0, &built, level, harmonics, 64, &[Solver::Fo, Solver::Fr, Solver::Nlr], ContinuationMethod::Oriented, 0, 59 + k as u64);
                        done.push(((harmonics, k), run));
                    }
                    done
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().expect("a worker panicked")).collect()
    });
    outcomes.sort_by_key(|(case, _)| *case);
    let outcomes: Vec<_> = outcomes.into_iter().flat_map(|(_, run)| run).collect();
    outcomes.iter().for_each(campaign::print_outcome);
    campaign::print_summary(&outcomes, started.elapsed().as_secs_f64());
    let mut problems = Vec::new();
    for o in &outcomes {
        let what = format!("H {} level {:.3} {}", o.harmonics, o.level, o.solver.name());
        if !o.reached_end() {
            problems.push(format!("{what}: {:?} {:?} {:?}", o.end, o.error, o.failure));
        }
        let Some(r) = &o.rom else { continue };
        if r.trusted && (r.peak_omega_error > 5e-3 || r.peak_x1_error > 1e-2) {
            problems.push(format!("{what}: trusted, but its peak is off by {:.2e} in frequency and {:.2e} in X1", r.peak_omega_error, r.peak_x1_error));
        }
        if !r.not_conservative.is_empty() {
            problems.push(format!("{what}: judged error below e_1 (above 1e-6) at {:?}", r.not_conservative));
        }
        if !r.called_good_far_off.is_empty() {
            problems.push(format!("{what}: judged good with X1 off by more than twice the threshold at {:?}", r.called_good_far_off));
        }
        if r.trusted != r.trust_reason.is_none() {
            problems.push(format!("{what}: trusted {} with reason {:?}", r.trusted, r.trust_reason));
        }
    }
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
}
