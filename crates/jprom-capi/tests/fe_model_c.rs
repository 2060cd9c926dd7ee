//! Issue 13: from a CalculiX model to a self-correcting JP sweep in C (`tests/c/fe_calculix.c`,
//! the `jprom_fe_*` functions) and in Fortran (`tests/fortran/fe_calculix.f90`, the `jp_fe_*`
//! wrappers) gives the same table as the Rust API (`fe::FeModel`, `rom::adaptive_sweep`) to
//! 1e-9, on the CalculiX block of the core's test data.

use jprom::contact::ContactLaw;
use jprom::fe::{FeModel, NodalContact, NodalForce, Reduction};
use jprom::hbm::{HbmOptions, SweepEnd, SweepOptions};
use jprom::io::calculix::read_model;
use jprom::jp::prediction::{static_solution, stuck_mode};
use jprom::jp::PredictionOptions;
use jprom::level::stuck_limit;
use jprom::linalg::eigen::dense_generalized_eigenvalues;
use jprom::model::{ContactCoordinates, Damping};
use jprom::rom::{adaptive_sweep_with_progress, AdaptiveOptions, CorrectionEnd, CorrectionKind, RomKind};
use jprom_testkit::native::*;

#[test]
fn calculix_block_to_adaptive_sweep_in_c_matches_rust() {
    let deck = root().join("crates/jprom/tests/data/calculix/block/block.inp");
    let ccx = read_model(&deck).unwrap();
    let fe = FeModel::from_calculix(&ccx).unwrap();
    // contact springs a small fraction of the tip's own stiffness
    let tip = ccx.node_set("TIP").unwrap().to_vec();
    let diag: f64 = tip.iter().map(|&id| {
        let r = fe.node(id).unwrap().translations().unwrap()[1];
        let k = fe.stiffness.as_ref();
        let (cp, ri, v) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
        (cp[r]..cp[r + 1]).find(|&p| ri[p] == r).map(|p| v[p]).unwrap()
    }).sum::<f64>() / tip.len() as f64;
    let (kt, kn, mu, n0, cb_modes) = (0.002 * diag, 0.02 * diag, 0.3, 1.0, 12);
    let frame = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
    let law = ContactLaw::Friction3D { kt1: kt, kt2: kt, kn, mu, n0 };
    let spec = Reduction {
        contacts: tip.iter().map(|&node| NodalContact { node, frame, law: law.clone() }).collect(),
        harmonic_forces: vec![NodalForce { node: ccx.node_set("LOAD").unwrap()[0], force: [0.0, 1.0, 0.0] }],
        outputs: ccx.node_set("OUT").unwrap().iter().map(|&n| (n, 1)).collect(),
        cb_modes,
        ..Reduction::default()
    };
    // the band: from 3 % below the free first mode to 3 % above the stuck one nearest it (at
    // most 1.5 times the free one)
    let probe = fe.reduce(&spec, Damping::default()).unwrap();
    let free = dense_generalized_eigenvalues(&probe.stiffness, &probe.mass).unwrap()[0].sqrt();
    let coords = ContactCoordinates::new(&probe, 1).unwrap();
    let (w_stuck, _) = stuck_mode(&coords, (free, 1.2 * free)).unwrap();
    let band = (0.97 * free, (1.03 * w_stuck).min(1.5 * free));
    let beta = 2.0 * 0.005 / (0.5 * (band.0 + band.1));
    // the level reference needs damping: undamped, the stuck response at the stuck resonance is
    // unbounded (this test once took its level from the undamped model: a scale of ~1e-14 and
    // a response of 1e-14 everywhere)
    let z0 = static_solution(&coords).unwrap();
    let undamped = stuck_limit(&coords, &z0, w_stuck).unwrap_err().to_string();
    assert!(undamped.contains("no damping"), "{undamped}");
    let mut model = fe.reduce(&spec, Damping { mass_coeff: 0.0, stiffness_coeff: beta }).unwrap();
    let damped = ContactCoordinates::new(&model, 1).unwrap();
    let scale = stuck_limit(&damped, &z0, w_stuck).unwrap().scale_at(0.1).unwrap();
    model.excitation.dynamic_scale = scale;
    let mut swept = std::collections::BTreeSet::new();
    let rust = adaptive_sweep_with_progress(&model, 1, &PredictionOptions::new(band), &SweepOptions::band(band.0, band.1), &HbmOptions::default(), &AdaptiveOptions { kind: RomKind::Nlr, ..AdaptiveOptions::default() }, &mut |pass, _| {
        swept.insert(pass);
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    println!("band {:.1}-{:.1} Hz, kt {kt:.3e}, {} points, end {:?}, {} corrections, judged error {:.3e} ({:?}), peak |X1| {:.4e}", band.0 / 6.283185307179586, band.1 / 6.283185307179586, rust.sweep.points.len(), rust.sweep.end, rust.corrections.len(), rust.worst_error, rust.end, rust.sweep.points.iter().map(|p| p.output_amplitude(1, 0)).fold(0.0, f64::max));
    for (i, c) in rust.corrections.iter().enumerate() {
        let was_swept = swept.contains(&(i + 1));
        println!("correction {}: {:?}, {:.4} -> {:.4}, sizes {:?}, swept {was_swept}", i + 1, c.kind, c.worst_error_before, c.worst_error_after, c.sizes);
        // a correction is swept unless its modes add nothing to the basis (then it is reported
        // with the error unchanged) or its error where the basis before it was judged worst is
        // above the threshold (screening; then that error is reported)
        assert_eq!(was_swept, c.swept, "the record says which corrections were swept: {c:?}");
        if !was_swept {
            let unchanged = c.worst_error_after == c.worst_error_before && !matches!(c.kind, CorrectionKind::Replaced { .. });
            assert!(unchanged || c.worst_error_after > AdaptiveOptions::default().threshold, "a correction not swept: {c:?}");
        }
    }
    assert_eq!(rust.sweep.end, SweepEnd::ReachedEnd, "{:?}", rust.sweep.failure);

    let exe = compile_c(&[&std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/c/fe_calculix.c")], "fe_calculix", &[]);
    let args: Vec<String> = [kt, kn, mu, n0, scale, band.0, band.1, beta].iter().map(|v| format!("{v:.17e}")).chain([cb_modes.to_string()]).collect();
    let out = std::process::Command::new(&exe).arg(&deck).args(&args).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "C: {text}{}", String::from_utf8_lossy(&out.stderr));
    println!("{}", text.lines().next().unwrap());
    // why the corrections ended and the judged error, C and Fortran against Rust
    let end_code = match rust.end {
        CorrectionEnd::WithinThreshold => 0,
        CorrectionEnd::MaxCorrections => 1,
        CorrectionEnd::NoProgress => 2,
        CorrectionEnd::Stopped => 3,
    };
    let compare_end = |lang: &str, text: &str| {
        let line = text.lines().find_map(|l| l.strip_prefix("# corrections end ")).unwrap_or_else(|| panic!("{lang}: no correction end in {text}"));
        let v: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(v[0].parse::<i32>().unwrap(), end_code, "{lang}: correction end ({:?})", rust.end);
        let judged: f64 = v[1].parse().unwrap();
        assert!((judged - rust.worst_error).abs() <= 1e-9 * rust.worst_error.abs(), "{lang}: judged error {judged} vs {}", rust.worst_error);
    };
    let compare = |lang: &str, text: &str| {
        compare_end(lang, text);
        let rows: Vec<Vec<f64>> = text.lines().filter(|l| !l.starts_with('#')).map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect()).collect();
        assert_eq!(rows.len(), rust.sweep.points.len(), "{lang}: points");
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1e-300) || (a - b).abs() < 1e-15;
        for (row, (p, e)) in rows.iter().zip(rust.sweep.points.iter().zip(&rust.predicted_errors)) {
            let want = [p.omega, p.output_amplitude(1, 0), e[1]];
            assert_eq!(row.len(), 3, "{lang}: {row:?}");
            for (a, b) in row.iter().zip(want) {
                assert!(close(*a, b), "{lang} {row:?} vs Rust {want:?}");
            }
        }
    };
    compare("C", &text);
    if have_gfortran() {
        let f = compile_fortran(&[&root().join("fortran/jprom.f90"), &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fortran/fe_calculix.f90")], "fe_calculix_f90");
        let out = std::process::Command::new(&f).arg(&deck).args(&args).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "Fortran: {text}{}", String::from_utf8_lossy(&out.stderr));
        println!("{}", text.lines().next().unwrap());
        compare("Fortran", &text);
    }
}
