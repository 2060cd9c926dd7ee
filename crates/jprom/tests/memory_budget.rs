//! The memory budget through the Rust API (one test: the budget is process-wide): a request
//! estimated beyond it is refused with the estimate and the budget, before anything is
//! allocated, and the default comes back when it is reset. Covered: file reads, Matrix Market
//! sizes, and the stages that size dense matrices by the model (contact coordinates, the
//! condensed system, the dense Newton Jacobian of a solve on it and of a study's error checks,
//! the JP prediction and one pattern's JP modes, Craig-Bampton).

use jprom::condensation::CondensedSystem;
use jprom::fe::{BladeParams, BuiltinBlade, CbOptions, CraigBampton};
use jprom::io::matrix_market::parse_matrix_market;
use jprom::jp::{jp_modes, predict_basis, ContactJacobian, ModeOptions, PredictionOptions};
use jprom::memory::human_bytes;
use jprom::model::ContactCoordinates;
use jprom::jp::prediction::{patterns_at_once, reference_patterns_at_once, PatternFactorisation};
use jprom_testkit::chain::{chain_model, linear_modes, stuck_stiffness_physical, ChainOptions};
use jprom::memory::MemoryBudget;
use jprom::JpError;

#[test]
fn requests_beyond_the_budget_are_refused_with_the_estimate() {
    let default = MemoryBudget::global();
    assert_eq!(default, MemoryBudget::machine_default());
    MemoryBudget::set_global(Some(MemoryBudget::new(1 << 20)));

    // a file whose text and values would not fit is not read
    let p = std::env::temp_dir().join(format!("jprom-budget-{}.json", std::process::id()));
    std::fs::write(&p, vec![b' '; 200_000]).unwrap();
    let e = jprom::io::read_text(&p).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { budget: 1048576, .. }), "{e:?}");
    assert!(e.to_string().contains("more than the memory budget of 1.0 MiB (1048576 bytes)"), "{e}");

    // a Matrix Market file whose column pointers alone exceed it (10^6 columns, one entry)
    let e = parse_matrix_market("%%MatrixMarket matrix coordinate real general\n1000000 1000000 1\n1 1 1.0\n", "big.mtx").unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { .. }) && e.to_string().contains("the 1000000 x 1000000 matrix of big.mtx"), "{e}");

    // a model loaded from a small file is within it
    std::fs::write(&p, "{}").unwrap();
    assert!(!matches!(jprom::io::read_text(&p), Err(JpError::TooLarge { .. })));

    // the stages that size dense matrices by the model: each refuses with its estimate
    let model = chain_model(&ChainOptions { n_nodes: 100, ..ChainOptions::default() });
    let e = ContactCoordinates::new(&model, 1).unwrap_err();
    let need = jprom::model::contact_coordinates::working_set_bytes(300);
    assert_eq!(need, 4 * 300 * 300 * 8);
    assert!(matches!(&e, JpError::TooLarge { bytes, .. } if *bytes == need), "{e:?}");
    assert!(e.to_string().contains("the contact coordinates of a model of 300 DoFs") && e.to_string().contains("it needs about 2.7 MiB"), "{e}");

    // a budget that holds the coordinates of a 180-DoF chain but not its condensed system at
    // H = 3 nor one JP pattern
    let small = chain_model(&ChainOptions { n_nodes: 60, ..ChainOptions::default() });
    let coords_need = jprom::model::contact_coordinates::working_set_bytes(180);
    MemoryBudget::set_global(Some(MemoryBudget::new(coords_need as usize + 1000)));
    let coords = ContactCoordinates::new(&small, 3).unwrap();
    let nw = coords.n_w;
    let condensed_need = jprom::condensation::working_set_bytes(180, nw);
    assert!(condensed_need > coords_need + 1000, "{condensed_need} vs {coords_need}");
    let e = CondensedSystem::new(&small, 3).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { bytes, .. } if *bytes == condensed_need), "{e:?}");
    assert!(e.to_string().contains(&format!("the condensed system at H = 3 ({nw} contact coordinates, {} linear DoFs)", 180 - nw)), "{e}");
    // a condensed system within the budget (what an NLR model projects) whose full-order
    // solve is not: the solve refuses before its first Newton step, with the Jacobian's size
    let many = chain_model(&ChainOptions { n_nodes: 60, n_ground: 30, ..ChainOptions::default() });
    let many_nw = ContactCoordinates::new(&many, 3).unwrap().n_w;
    let build = jprom::condensation::working_set_bytes(180, many_nw).max(coords_need);
    let unknowns = 7 * many_nw;
    let jacobian = jprom::hbm::residual::dense_jacobian_bytes(unknowns);
    assert_eq!(jacobian, 2 * 8 * (unknowns as u128).pow(2));
    assert!(jacobian > build + 1000, "{jacobian} vs {build}");
    MemoryBudget::set_global(Some(MemoryBudget::new(build as usize + 1000)));
    let condensed = CondensedSystem::new(&many, 3).unwrap();
    let e = jprom::hbm::solve_point(&condensed, 1.0, None, &jprom::hbm::HbmOptions::default()).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { bytes, .. } if *bytes == jacobian), "{e:?}");
    assert!(e.to_string().contains(&format!("the dense harmonic-balance Jacobian ({unknowns} unknowns at H = 3)")), "{e}");
    // a self-correcting study whose error checks would factorise that Jacobian is refused
    // before its prediction, not left to skip the checks
    let band = (10.0, 20.0);
    let study = jprom::rom::adaptive_sweep(&many, 3, &PredictionOptions::new(band), &jprom::hbm::SweepOptions::band(band.0, band.1), &jprom::hbm::HbmOptions::default(), &jprom::rom::AdaptiveOptions::default());
    let e = study.unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { bytes, .. } if *bytes == jacobian), "{e:?}");
    assert!(e.to_string().contains(&format!("the condensed full-order Jacobian of the error checks ({unknowns} unknowns at H = 3)")), "{e}");
    MemoryBudget::set_global(Some(MemoryBudget::new(coords_need as usize + 1000)));
    let pattern = jprom::jp::modes::pattern_working_set_bytes(180, nw, 3);
    assert!(pattern > coords_need + 1000);
    let per_pattern = PredictionOptions { factorisation: PatternFactorisation::PerPattern, ..PredictionOptions::new(band) };
    let e = predict_basis(&coords, &per_pattern).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { .. }), "{e:?}");
    let text = e.to_string();
    assert!(text.contains("the JP prediction at H = 3 (n = 180 DoFs") && text.contains(&human_bytes(pattern)), "{text}");
    // by default (2 H n = 1080 > 600: shift-invert) on a shared reference: its factorisations
    let reference = jprom::jp::reference::reference_working_set_bytes(180, nw, 3);
    assert!(reference > coords_need + 1000);
    let e = predict_basis(&coords, &PredictionOptions::new(band)).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { bytes, .. } if *bytes == reference), "{e:?}");
    assert!(e.to_string().contains("the shared factorisations of the JP prediction at H = 3 (n = 180 DoFs"), "{e}");
    // one pattern's JP modes alone (a corrected or a solution's basis) is refused as well
    let k_hat = ContactJacobian::stuck(&coords.laws, &coords.offsets, nw, 3).unwrap();
    let e = jp_modes(&coords, &k_hat, &ModeOptions::in_band(band)).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { .. }) && e.to_string().contains("the JP modes of one contact pattern at H = 3"), "{e}");
    // Craig-Bampton: its dense parts (the constraint modes dominate with many boundary DoFs)
    let blade = BuiltinBlade::build(&BladeParams { n_span: 18, n_chord: 4, n_thickness: 2, n_shroud_gap: 2, ..Default::default() }).unwrap();
    let n = blade.n_dof();
    let boundary: Vec<usize> = (0..90).collect();
    let opts = CbOptions { n_modes: 20, ..CbOptions::default() };
    let need = jprom::fe::craig_bampton::working_set_bytes(n - 90, 90, 20, false, true);
    assert!(need > (coords_need + 1000) && need < 1 << 26, "{need}");
    let e = CraigBampton::reduce(&blade.stiffness, &blade.mass, &boundary, opts).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { bytes, .. } if *bytes == need), "{e:?}");
    assert!(e.to_string().contains(&format!("the Craig-Bampton reduction ({} interior and 90 boundary DoFs, up to 20 fixed-interface modes, constraint modes kept", n - 90)), "{e}");
    // without the constraint modes the estimate is smaller by n_i x n_b values
    let lean = jprom::fe::craig_bampton::working_set_bytes(n - 90, 90, 20, false, false);
    assert_eq!(need - lean, 8 * ((n - 90) * 90) as u128);
    // the unreduced FE model (JP without Craig-Bampton): dense M and K, 2 n^2 doubles
    let e = blade.to_full_model(jprom::model::Damping::default()).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { bytes, .. } if *bytes == 16 * (n as u128).pow(2)), "{e:?}");
    assert!(e.to_string().contains(&format!("the dense FE model of the blade ({n} DoFs, M and K)")), "{e}");

    // the prediction solves as many patterns at once as fit: a budget of one and a half patterns
    // runs them one at a time (it refused before, asking for a pattern per thread), and a
    // budget below one pattern refuses
    let chain = chain_model(&ChainOptions::default());
    let chain_coords = ContactCoordinates::new(&chain, 1).unwrap();
    let (n, nw) = (chain_coords.n_dof, chain_coords.n_w);
    let one = jprom::jp::modes::pattern_working_set_bytes(n, nw, 1);
    assert_eq!(patterns_at_once(one, (one * 3 / 2) as usize, 100), 1);
    assert_eq!(patterns_at_once(one, usize::MAX, 100), rayon::current_num_threads().min(100));
    assert_eq!(patterns_at_once(one, usize::MAX, 1), 1);
    assert_eq!(patterns_at_once(600_000_000, usize::MAX, 100), 1, "large patterns are solved one at a time");
    // on a shared reference patterns of any size run side by side while they fit
    assert_eq!(reference_patterns_at_once(600_000_000, usize::MAX, 100), rayon::current_num_threads().min(100));
    assert_eq!(reference_patterns_at_once(600_000_000, 900_000_000, 100), 1, "one and a half patterns fit: one at a time");
    assert_eq!(reference_patterns_at_once(600_000_000, usize::MAX, 1), 1);
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&chain), &chain.mass);
    let chain_band = (0.9 * freqs[0], 1.1 * freqs[0]);
    let mut popts = PredictionOptions::new(chain_band);
    popts.n_samples = 20;
    MemoryBudget::set_global(Some(MemoryBudget::new((one * 3 / 2) as usize)));
    let (basis, report) = predict_basis(&chain_coords, &popts).unwrap();
    MemoryBudget::set_global(None);
    let (unbounded, _) = predict_basis(&chain_coords, &popts).unwrap();
    assert!(report.n_patterns > 1, "{report:?}");
    assert_eq!(basis.sizes, unbounded.sizes, "one at a time or in parallel, the same basis");
    MemoryBudget::set_global(Some(MemoryBudget::new((one * 9 / 10) as usize)));
    let e = predict_basis(&chain_coords, &popts).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { .. }) && e.to_string().contains("1 contact pattern(s) at once"), "{e}");

    // with the default budget every stage runs
    MemoryBudget::set_global(None);
    MemoryBudget::set_global(None);
    assert!(CondensedSystem::new(&small, 3).is_ok());
    let tiny = ContactCoordinates::new(&chain_model(&ChainOptions::default()), 3).unwrap();
    let k_tiny = ContactJacobian::stuck(&tiny.laws, &tiny.offsets, tiny.n_w, 3).unwrap();
    assert!(jp_modes(&tiny, &k_tiny, &ModeOptions::in_band(band)).is_ok());

    MemoryBudget::set_global(None);
    assert_eq!(MemoryBudget::global(), default);
    assert!(parse_matrix_market("%%MatrixMarket matrix coordinate real general\n1000000 1000000 1\n1 1 1.0\n", "big.mtx").is_ok());
}
