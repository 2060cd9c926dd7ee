//! Dissipated energy per cycle (issue 11): the work of the friction force over the slip
//! increments is never negative, whatever the contact state, vanishes in full stick, and
//! matches the Jenkins closed form `4 Fs (a - Fs / kt)`; the 3D element under circular gross
//! slip matches `2 pi r mu N` as the samples get finer.

use jprom::aft::{evaluate_contacts, AftPlan, ContactCycle, ContactForces};
use jprom::contact::{ContactLaw, ContactState};
use rand::{Rng, SeedableRng};

fn cycle(law: &ContactLaw, w: &[f64], harmonics: usize, nt: usize) -> ContactCycle {
    let plan = AftPlan::new(harmonics, nt).unwrap();
    let mut ws = plan.workspace();
    let mut f = vec![0.0; w.len()];
    let mut c = ContactCycle::default();
    plan.contact(law, w, &mut f, None, Some(&mut c), &mut ws);
    c
}

#[test]
fn energy_is_never_negative_on_random_states() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let (mut slipping, mut separated, mut stuck) = (0, 0, 0);
    for case in 0..4000 {
        let harmonics = rng.gen_range(1..=5);
        let nt = [32usize, 64, 128][rng.gen_range(0..3)].max(4 * (harmonics + 1)).next_power_of_two();
        let nc = 2 * harmonics + 1;
        // amplitudes over decades so that stick, partial slip, gross slip and lift-off all occur
        let scale = 10f64.powf(rng.gen_range(-3.0..1.0));
        let (law, dim) = if case % 4 == 3 {
            (ContactLaw::Jenkins { kt: rng.gen_range(0.1..10.0), mu: rng.gen_range(0.0..1.0), normal_load: rng.gen_range(0.0..2.0) }, 1)
        } else {
            let kn = rng.gen_range(0.1..10.0);
            let law = ContactLaw::Friction3D {
                kt1: rng.gen_range(0.0..10.0),
                kt2: rng.gen_range(0.1..10.0),
                kn,
                mu: rng.gen_range(0.0..1.0),
                n0: rng.gen_range(-0.5..2.0),
            };
            (law, 3)
        };
        let w: Vec<f64> = (0..dim * nc).map(|_| scale * rng.gen_range(-1.0..1.0)).collect();
        let c = cycle(&law, &w, harmonics, nt);
        assert!(c.dissipated_energy >= 0.0 && c.dissipated_energy.is_finite(), "case {case}: {law:?} w {w:?}: W = {}", c.dissipated_energy);
        if c.states.iter().all(|s| *s == ContactState::Stick) {
            stuck += 1;
            assert_eq!(c.dissipated_energy, 0.0, "case {case}: full stick dissipates nothing");
        }
        if c.states.contains(&ContactState::Slip) {
            slipping += 1;
        }
        if c.states.contains(&ContactState::Separated) {
            separated += 1;
        }
    }
    println!("4000 random cycles: {stuck} fully stuck, {slipping} with slip, {separated} with lift-off");
    assert!(stuck > 100 && slipping > 1000 && separated > 100, "the states were not all met");
}

#[test]
fn energy_through_the_system_layout_is_per_contact_and_nonnegative() {
    // evaluate_contacts (the path of every solver) reports the same per-contact energies
    let plan = AftPlan::new(3, 64).unwrap();
    let laws = vec![
        ContactLaw::Friction3D { kt1: 2.0, kt2: 1.0, kn: 3.0, mu: 0.3, n0: 0.5 },
        ContactLaw::Jenkins { kt: 1.0, mu: 0.5, normal_load: 1.0 },
    ];
    let offsets = [0, 3];
    let n_w = 4;
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let w_all: Vec<f64> = (0..7 * n_w).map(|_| rng.gen_range(-1.0..1.0)).collect();
    let mut out = ContactForces::default();
    evaluate_contacts(&plan, &laws, &offsets, n_w, &w_all, false, true, &mut out);
    for (c, (law, &off)) in laws.iter().zip(&offsets).enumerate() {
        let d = law.dim();
        let local: Vec<f64> = (0..7).flat_map(|k| (0..d).map(move |i| (k, i))).map(|(k, i)| w_all[k * n_w + off + i]).collect();
        let alone = cycle(law, &local, 3, 64);
        assert_eq!(alone.dissipated_energy, out.cycles[c].dissipated_energy);
        assert!(alone.dissipated_energy > 0.0, "contact {c} slips here");
    }
}

#[test]
fn jenkins_energy_matches_the_closed_form_and_is_zero_when_stuck() {
    let (kt, fs) = (3.0, 0.9);
    let law = ContactLaw::Jenkins { kt, mu: 0.45, normal_load: 2.0 };
    let xs = fs / kt;
    for a in [0.1, 0.29, 0.31, 0.5, 1.0, 7.0] {
        for nt in [16, 64, 1024] {
            let c = cycle(&law, &[0.0, a, 0.0], 1, nt);
            let exact = if a <= xs { 0.0 } else { 4.0 * fs * (a - xs) };
            assert!((c.dissipated_energy - exact).abs() <= 1e-12 * exact.max(1.0), "a = {a}, Nt = {nt}: W = {} vs {exact}", c.dissipated_energy);
        }
    }
    // a phase-shifted drive with a static offset and a second harmonic: the loop is no longer
    // symmetric, the energy is still >= 0 and converges as Nt grows
    let w = [0.2, 0.6, 0.8, 0.0, 0.3];
    let mut prev = f64::NAN;
    let mut diffs = Vec::new();
    for nt in [64, 256, 1024, 4096] {
        let e = cycle(&law, &w, 2, nt).dissipated_energy;
        assert!(e > 0.0);
        if prev.is_finite() {
            diffs.push((e - prev).abs());
        }
        prev = e;
    }
    println!("asymmetric Jenkins loop: successive energy differences {diffs:?}");
    assert!(diffs.windows(2).all(|d| d[1] < d[0]), "no convergence with Nt: {diffs:?}");
}

#[test]
fn circular_gross_slip_dissipates_the_perimeter_times_the_friction_force() {
    // u1 = r cos, u2 = r sin at constant N: in steady gross slip the spring, stretched by
    // x_s = mu N / kt, leads the slider along its path, so the slider runs on a circle of
    // radius sqrt(r^2 - x_s^2) and the energy tends to 2 pi sqrt(r^2 - x_s^2) mu N
    let (kt, kn, mu, n0, r) = (10.0, 5.0, 0.4, 2.0, 1.0);
    let law = ContactLaw::Friction3D { kt1: kt, kt2: kt, kn, mu, n0 };
    let xs = mu * n0 / kt;
    let exact = 2.0 * std::f64::consts::PI * (r * r - xs * xs).sqrt() * mu * n0;
    let mut errs = Vec::new();
    for nt in [64, 256, 1024, 4096] {
        let w = [0.0, 0.0, 0.0, r, 0.0, 0.0, 0.0, r, 0.0];
        let e = cycle(&law, &w, 1, nt).dissipated_energy;
        errs.push((e - exact).abs() / exact);
    }
    println!("circular gross slip: relative errors {errs:?}");
    assert!(errs.windows(2).all(|d| d[1] < d[0]) && errs[3] < 1e-3, "{errs:?}");
}
