//! Sampling along the slipping mode (docs/formulation.md §8.8, `SlippingSamples`): at gross slip
//! the stuck mode is a poor generating shape. On the built-in blade (18 contacts, CB(50)) at
//! alpha_ST / 3000 over 1,620-2,200 Hz (the demo's band, which holds the slipping resonance
//! near 1,672 Hz), the FR ROM of the stuck-mode basis misses the resonance; with the slipping
//! samples it finds it, without any correction. Checked against the full-order sweep.

use jprom_testkit::blade as blade_support;

use blade_support::*;
use faer::Mat;
use jprom::condensation::CondensedSystem;
use jprom::hbm::{sweep, HbmOptions, SweepOptions};
use jprom::jp::{predict_basis, slipping_mode, stuck_mode, PredictionOptions, SlippingSamples};
use jprom::model::ContactCoordinates;
use jprom::rom::FrRom;
use std::f64::consts::PI;
use std::ops::ControlFlow;

const DEMO_BAND_HZ: (f64, f64) = (1620.0, 2200.0);

fn band() -> (f64, f64) {
    (2.0 * PI * DEMO_BAND_HZ.0, 2.0 * PI * DEMO_BAND_HZ.1)
}

#[test]
fn slipping_mode_is_the_mode_with_tangentially_free_contacts() {
    let blade = Blade::build();
    let coords = ContactCoordinates::new(&blade.model, 1).unwrap();
    let (w_st, phi_st) = stuck_mode(&coords, band()).unwrap();
    let (w_sl, phi) = slipping_mode(&coords, band(), &phi_st).unwrap().expect("the blade has friction contacts");
    // an eigenvector of K + normal springs (the tangential ones left out), independently assembled
    let mut k = coords.stiffness.clone();
    for (law, &off) in coords.laws.iter().zip(&coords.offsets) {
        let kn = law.stuck_stiffness()[2];
        k[(off + 2, off + 2)] += kn;
    }
    let v = Mat::from_fn(phi.len(), 1, |i, _| phi[i]);
    let kv = &k * &v;
    let r = &kv - &coords.mass * &v * faer::Scale(w_sl * w_sl);
    assert!(r.norm_l2() < 1e-8 * kv.norm_l2(), "residual {:e}", r.norm_l2() / kv.norm_l2());
    // softer than the stuck mode: the first bending with the shroud free to slide (1,672 Hz)
    let (f_sl, f_st) = (w_sl / (2.0 * PI), w_st / (2.0 * PI));
    println!("stuck mode {f_st:.2} Hz, slipping mode {f_sl:.2} Hz");
    assert!(f_sl < f_st && (1650.0..1700.0).contains(&f_sl), "slipping mode at {f_sl} Hz, stuck {f_st} Hz");
}

#[test]
fn slipping_samples_find_the_gross_slip_resonance_that_the_stuck_mode_misses() {
    let blade = Blade::build();
    let model = blade.at_level(blade.alpha_st / 3000.0);
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let condensed = CondensedSystem::new(&model, 1).unwrap();
    let hopts = HbmOptions::default();
    let sopts = SweepOptions::band(band().0, band().1);
    let peak = |sys: &dyn jprom::hbm::HarmonicSystem| {
        let sw = sweep(sys, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
        assert!(sw.reached_end(), "{:?}", sw.end);
        sw.points.iter().map(|p| (p.omega / (2.0 * PI), tip_amplitude(p))).fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a })
    };
    let (fo_hz, fo_x1) = peak(&condensed);
    println!("full order: peak {fo_x1:.5e} at {fo_hz:.2} Hz");
    assert!((1650.0..1700.0).contains(&fo_hz), "the gross-slip resonance is the slipping mode's: {fo_hz} Hz");

    let mut popts = PredictionOptions::new(band());
    let (stuck_only, r0) = predict_basis(&coords, &popts).unwrap();
    assert_eq!((r0.slipping_patterns, r0.omega_slipping), (0, None));
    popts.slipping = SlippingSamples::AtGrossSlip;
    let (with_slipping, r1) = predict_basis(&coords, &popts).unwrap();
    println!("stuck only: {:?}, {} patterns; with slipping samples: {:?}, {} + {} patterns, slipping mode {:.2} Hz, p_max / p_min {:.0}", stuck_only.sizes, r0.n_patterns, with_slipping.sizes, r1.n_patterns - r1.slipping_patterns, r1.slipping_patterns, r1.omega_slipping.unwrap_or(f64::NAN) / (2.0 * PI), r1.p_max / r1.p_min);
    assert!(r1.p_max >= jprom::jp::prediction::GROSS_SLIP_RATIO * r1.p_min);
    assert!(r1.slipping_patterns > 0 && r1.n_patterns == r0.n_patterns + r1.slipping_patterns);

    let (hz0, x0) = peak(&FrRom::new(&coords, &stuck_only).unwrap());
    let (hz1, x1) = peak(&FrRom::new(&coords, &with_slipping).unwrap());
    let (e0, e1) = ((x0 - fo_x1).abs() / fo_x1, (x1 - fo_x1).abs() / fo_x1);
    println!("FR peak, stuck-mode basis: {x0:.5e} at {hz0:.2} Hz (error {e0:.2e}); with slipping samples: {x1:.5e} at {hz1:.2} Hz (error {e1:.2e})");
    assert!(e0 > 0.5, "the stuck-mode basis was expected to miss the gross-slip resonance (error {e0:.2e})");
    assert!(e1 < 0.01 && (hz1 - fo_hz).abs() < 2.0, "with the slipping samples: error {e1:.2e}, {hz1} Hz vs {fo_hz} Hz");
}

#[test]
fn at_partial_slip_the_slipping_samples_are_not_taken() {
    let blade = Blade::build();
    let model = blade.at_level(blade.alpha_st / 10.0);
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let never = PredictionOptions::new(band());
    let at_gross = PredictionOptions { slipping: SlippingSamples::AtGrossSlip, ..never.clone() };
    let (a, ra) = predict_basis(&coords, &never).unwrap();
    let (b, rb) = predict_basis(&coords, &at_gross).unwrap();
    assert!(rb.p_max < jprom::jp::prediction::GROSS_SLIP_RATIO * rb.p_min, "p_max / p_min = {}", rb.p_max / rb.p_min);
    assert_eq!(rb.slipping_patterns, 0);
    assert_eq!((a.sizes, ra.n_patterns), (b.sizes, rb.n_patterns));
    // Always samples it whatever the level
    let (_, rc) = predict_basis(&coords, &PredictionOptions { slipping: SlippingSamples::Always, ..never }).unwrap();
    assert!(rc.slipping_patterns > 0 && rc.omega_slipping.is_some());
}

/// The paths without a slipping mode: a model whose contacts have no tangential springs
/// (frictionless: the slipping limit is the stuck one) and one with an external law (its
/// slipping limit unknown). `slipping_mode` says `None`, and `SlippingSamples::Always` then
/// leaves the prediction as it is without it.
#[test]
fn without_friction_or_with_an_external_law_there_are_no_slipping_samples() {
    use jprom::contact::{ContactLaw, ExternalFn, ExternalLaw};
    use std::sync::Arc;
    let blade = Blade::build();
    let gross = blade.at_level(blade.alpha_st / 3000.0);
    let check = |model: &jprom::model::Model, what: &str| {
        let coords = ContactCoordinates::new(model, 1).unwrap();
        assert!(!coords.has_friction(), "{what}");
        let (_, phi_st) = stuck_mode(&coords, band()).unwrap();
        assert!(slipping_mode(&coords, band(), &phi_st).unwrap().is_none(), "{what}");
        let never = PredictionOptions::new(band());
        let (a, ra) = predict_basis(&coords, &never).unwrap();
        let (b, rb) = predict_basis(&coords, &PredictionOptions { slipping: SlippingSamples::Always, ..never }).unwrap();
        println!("{what}: {:?}, {} patterns", a.sizes, ra.n_patterns);
        assert_eq!((rb.slipping_patterns, rb.omega_slipping), (0, None), "{what}");
        assert_eq!((a.sizes, ra.n_patterns), (b.sizes, rb.n_patterns), "{what}");
    };
    // the blade as it is has friction
    assert!(ContactCoordinates::new(&gross, 1).unwrap().has_friction());

    let mut frictionless = gross.clone();
    for c in &mut frictionless.contacts {
        let ContactLaw::Friction3D { kt1, kt2, .. } = &mut c.law else { panic!("the blade's contacts are 3D friction elements") };
        (*kt1, *kt2) = (0.0, 0.0);
    }
    check(&frictionless, "no tangential springs");

    // the first contact's law as a C-style callable: a linear spring with the stuck stiffness
    let mut external = gross.clone();
    let k = external.contacts[0].law.stuck_stiffness();
    let f: Arc<ExternalFn> = Arc::new(move |w: &[f64], f: &mut [f64], j: &mut [f64]| {
        for i in 0..3 {
            f[i] = k[i] * w[i];
            for m in 0..3 {
                j[i + 3 * m] = if i == m { k[i] } else { 0.0 };
            }
        }
        Ok(())
    });
    external.contacts[0].law = ContactLaw::External(ExternalLaw::new(3, f).unwrap());
    check(&external, "an external law");
}

/// `predict_modes` keeps the per-pattern modes that `predict_basis` conditions: conditioned
/// with another `gamma` they give the basis a new prediction with that `gamma` gives (what the
/// self-correcting sweep's `gamma` steps rely on), with and without the slipping patterns'
/// separate conditioning, at H = 1 and H = 3.
#[test]
fn predicted_modes_give_the_basis_of_another_gamma_without_a_new_prediction() {
    use jprom::jp::predict_modes;
    let blade = Blade::build();
    let model = blade.at_level(blade.alpha_st / 3000.0);
    for (harmonics, slipping, samples) in [(1, SlippingSamples::Always, 100), (3, SlippingSamples::Never, 12)] {
        let coords = ContactCoordinates::new(&model, harmonics).unwrap();
        let mut opts = PredictionOptions::new(band());
        opts.slipping = slipping;
        opts.n_samples = samples;
        let (modes, report) = predict_modes(&coords, &opts).unwrap();
        assert_eq!(modes.modes.len(), report.n_patterns);
        assert_eq!(modes.slipping_patterns, report.slipping_patterns);
        if slipping == SlippingSamples::Always {
            assert!(report.slipping_patterns > 0, "no slipping pattern at alpha_ST / 3000");
        }
        let mut sizes = Vec::new();
        for gamma in [1e2, 1e4] {
            let reused = modes.basis(gamma).unwrap();
            let (fresh, fresh_report) = predict_basis(&coords, &PredictionOptions { gamma, ..opts.clone() }).unwrap();
            assert_eq!(fresh_report.n_patterns, report.n_patterns);
            assert_eq!(reused.sizes, fresh.sizes, "H = {harmonics}, gamma {gamma}");
            assert!(reused.spans_the_same(&fresh, 1e-8), "H = {harmonics}, gamma {gamma}: spans differ");
            assert_eq!(reused.band, fresh.band);
            sizes.push(reused.sizes.iter().sum::<usize>());
        }
        println!("H = {harmonics}: {} patterns, sizes {sizes:?}", report.n_patterns);
        // the check means something: the two gammas give different bases
        assert!(sizes[1] > sizes[0], "H = {harmonics}: gamma 1e4 gave no more columns than 1e2: {sizes:?}");
    }
}

/// A bad `gamma` is refused before the prediction's eigen solves.
#[test]
fn prediction_refuses_a_bad_gamma() {
    let blade = Blade::build();
    let coords = ContactCoordinates::new(&blade.model, 1).unwrap();
    for gamma in [0.5, f64::NAN, f64::INFINITY] {
        let err = predict_basis(&coords, &PredictionOptions { gamma, ..PredictionOptions::new(band()) }).unwrap_err();
        assert!(err.to_string().contains("gamma"), "{err}");
    }
}
