//! `p̂_min`, the amplitude along the stuck mode where the first contact starts to slip
//! (docs/formulation.md §8.8 step 5, `slip_onset_amplitude`), on the refinement-5 blade (242
//! contacts, H = 1 and 3).
//!
//! Past the first touch, a contact's steady AFT cycle touches the friction cone at one sample
//! and whether that sample counts as slip is decided by rounding, so "every contact sticks" flips
//! back and forth over the next 10-20 % of amplitude. A bisection on `[0, p̂_max]` landed
//! anywhere in that range: a change of `p̂_max` in its last bits moved `p̂_min` by up to 16 %,
//! and with it every sample and pattern of the prediction. Searched from below, `p̂_min` stays
//! within a few fine steps (0.27 %) of the first touch whatever `p̂_max`.
//!
//! Checked against an independent computation: `alpha_ST` of the test kit, the level at which
//! the linear stuck response at the stuck resonance first reaches `|T| = mu N` at some contact
//! (closed form in the stuck springs, no AFT). Along the stuck mode `p̂_max` is that response's
//! amplitude, so `p̂_max / p̂_min` must be `alpha_ST / alpha` (before, the bisection gave about
//! 0.93 of it on the default blade)
//! (run with `--nocapture` for the figures).

use jprom::contact::ContactState;
use jprom::jp::prediction::{predict_modes, slip_onset_amplitude, static_solution, stuck_mode};
use jprom::jp::PredictionOptions;
use jprom::model::ContactCoordinates;
use jprom_testkit::blade::{forces_along_shape, Blade};

/// Whether every contact sticks at every sample at `q0 + p phi cos`.
fn all_stuck(coords: &ContactCoordinates, q0: &[f64], phi: &[f64], p: f64) -> bool {
    let (_, out) = forces_along_shape(coords, q0, phi, p, false);
    out.cycles.iter().all(|c| c.states.iter().all(|&s| s == ContactState::Stick))
}

fn check(blade: &Blade, h: usize) {
    let coords = ContactCoordinates::new(&blade.model, h).unwrap();
    let q0 = static_solution(&coords).unwrap();
    let (_, phi) = stuck_mode(&coords, blade.band).unwrap();
    let sin = vec![0.0; phi.len()];
    let shape = (&q0[..], &phi[..], &sin[..]);
    // the first touch: a slip flag is reliable, a stuck one past the first touch is not, so the
    // lowest amplitude flagged slipping on a scan from below (steps of 0.2 %), then on a dense
    // one (0.02 %) over the 15 % below that
    let p_max = 1.0;
    assert!(!all_stuck(&coords, &q0, &phi, p_max), "H = {h}: the blade slips at p = {p_max}");
    let mut first = 1e-3;
    while all_stuck(&coords, &q0, &phi, first) {
        first *= 1.002;
    }
    assert!(first > 2e-3 && first < p_max, "H = {h}: first slip {first} inside the scan");
    let touch = (0..=750)
        .map(|k| first * (0.85 + 0.0002 * k as f64))
        .find(|&p| !all_stuck(&coords, &q0, &phi, p))
        .unwrap();
    // and that "every contact sticks" is not monotone past it (what this guards against)
    let flips = (1..200).filter(|k| all_stuck(&coords, &q0, &phi, touch * (1.0 + 0.001 * *k as f64))).count();
    eprintln!("H = {h}: first touch {touch:.6e}, stuck again at {flips} of 199 amplitudes up to 1.2 times it");

    // p_max changed in its last bits, and by whole percents
    let mut found = Vec::new();
    for p in (0..8).map(|k| p_max * (1.0 + 4.0 * k as f64 * f64::EPSILON)).chain([0.9, 1.1, 1.37, 2.0]) {
        let p_min = slip_onset_amplitude(&coords, shape, p).unwrap();
        eprintln!("H = {h}: p_max {p:.17} -> p_min {p_min:.9e} ({:.4} of the first touch)", p_min / touch);
        assert!(all_stuck(&coords, &q0, &phi, p_min), "H = {h}: every contact sticks at p_min {p_min}");
        // within a few fine steps (0.27 %) of the first touch, and of each other
        assert!(p_min / touch > 0.998 && p_min / touch < 1.02, "H = {h}: p_min {p_min} vs first touch {touch}");
        found.push(p_min);
    }
    let (lo, hi) = found.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &p| (a.min(p), b.max(p)));
    assert!(hi / lo < 1.02, "H = {h}: p_min spread {lo} .. {hi}");

    // refused: a p_max that is not finite and > 0, a shape shorter than the contact coordinates
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = slip_onset_amplitude(&coords, shape, bad).unwrap_err();
        assert!(e.to_string().contains("p_max"), "H = {h}: p_max {bad}: {e}");
    }
    let short = &q0[..coords.n_w - 1];
    assert!(slip_onset_amplitude(&coords, (short, &phi[..], &sin[..]), p_max).is_err(), "H = {h}: a short shape");
    // stuck at p_max: p_max itself
    let below = 0.5 * touch;
    assert_eq!(slip_onset_amplitude(&coords, shape, below).unwrap(), below);
}

/// `p̂_max / p̂_min` of the prediction along the stuck mode against `alpha_ST / alpha`.
fn against_stuck_limit(blade: &Blade) {
    for div in [10.0, 100.0] {
        let model = blade.at_level(blade.alpha_st / div);
        let coords = ContactCoordinates::new(&model, 1).unwrap();
        let mut popts = PredictionOptions::new(blade.band);
        popts.n_samples = 1;
        let rep = predict_modes(&coords, &popts).unwrap().1;
        let ratio = rep.p_max / rep.p_min;
        eprintln!("{} contacts at alpha_ST / {div}: p_max / p_min = {ratio:.6}", model.contacts.len());
        assert!((ratio / div - 1.0).abs() < 0.005, "{} contacts: p_max / p_min {ratio} against alpha_ST / alpha = {div}", model.contacts.len());
    }
}

#[test]
fn slip_onset_is_the_stuck_limit_on_the_default_and_refinement_5_blades() {
    against_stuck_limit(&Blade::build());
    against_stuck_limit(&Blade::build_refined(5));
}

#[test]
fn slip_onset_is_found_from_below_on_the_refinement_5_blade() {
    let blade = Blade::build_refined(5);
    check(&blade, 1);
    check(&blade, 3);
}
