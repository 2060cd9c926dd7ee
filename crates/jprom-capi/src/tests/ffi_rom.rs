//! JP reduction through the C API: a predicted basis, an NLR/FR sweep, the self-correcting
//! sweep with its corrections, the basis of a full-order solution and the actual error give the
//! same numbers as the Rust API, with the error predictor per point.

use faer::Mat;
use jprom::condensation::CondensedSystem;
use jprom::contact::{Contact, ContactLaw, IDENTITY_FRAME};
use crate::*;
use jprom::rom::error_metric::actual_error;
use jprom::hbm::{solve_point, sweep, HbmOptions, SweepOptions};
use jprom::jp::{predict_basis, BasisOptions, JpBasis, ModeOptions, PredictionOptions, SlippingSamples};
use jprom::model::{ContactCoordinates, Damping, Excitation, HarmonicForce, Model};
use jprom::rom::{adaptive_sweep, adaptive_sweep_with_progress, AdaptiveOptions, Correction, CorrectionEnd, CorrectionKind, NlrRom, RomKind};
use std::ffi::{c_char, c_int, c_void};
use std::ops::ControlFlow;

/// A 4-node chain (12 DoFs) on springs, two ground contacts with preload: the same model for
/// the C and the Rust side.
fn parts() -> (usize, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = 12;
    let mut k = vec![0.0; n * n];
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        m[i + i * n] = 1.0;
        k[i + i * n] += 2.0e4;
        if i + 3 < n {
            k[i + i * n] += 1.0e4;
            k[(i + 3) + (i + 3) * n] += 1.0e4;
            k[i + (i + 3) * n] -= 1.0e4;
            k[(i + 3) + i * n] -= 1.0e4;
        }
    }
    let f0: Vec<f64> = (0..n).map(|i| if i % 3 == 2 { -5.0 } else { 0.0 }).collect();
    let f1: Vec<f64> = (0..n).map(|i| if i % 3 == 0 { 1.0 } else { 0.0 }).collect();
    (n, m, k, f0, f1)
}

const LAW: (f64, f64, f64, f64, f64) = (2.0e4, 2.0e4, 3.0e4, 0.3, 10.0);

fn rust_model() -> Model {
    let (n, m, k, f0, f1) = parts();
    let law = ContactLaw::Friction3D { kt1: LAW.0, kt2: LAW.1, kn: LAW.2, mu: LAW.3, n0: LAW.4 };
    let contacts = vec![Contact::ground_3d([6, 7, 8], IDENTITY_FRAME, law.clone()), Contact::ground_3d([9, 10, 11], IDENTITY_FRAME, law)];
    let exc = Excitation { static_force: f0, harmonics: vec![HarmonicForce { cos: f1, sin: vec![0.0; n] }], dynamic_scale: 1.0 };
    Model::new(Mat::from_fn(n, n, |i, j| m[i + j * n]), Mat::from_fn(n, n, |i, j| k[i + j * n]), Damping { mass_coeff: 0.0, stiffness_coeff: 2e-5 }, exc, contacts, vec![0, 9]).unwrap()
}

unsafe fn c_model() -> *mut jprom_model {
    let (n, m, k, f0, f1) = parts();
    let mut model = std::ptr::null_mut();
    assert_eq!(jprom_model_new(n, m.as_ptr(), k.as_ptr(), &mut model), jprom_status::JPROM_OK);
    let frame = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    for a in [[6usize, 7, 8], [9, 10, 11]] {
        assert_eq!(jprom_model_add_contact_3d(model, a.as_ptr(), std::ptr::null(), frame.as_ptr(), LAW.0, LAW.1, LAW.2, LAW.3, LAW.4), jprom_status::JPROM_OK);
    }
    assert_eq!(jprom_model_set_static_force(model, f0.as_ptr(), n), jprom_status::JPROM_OK);
    let zeros = vec![0.0; n];
    assert_eq!(jprom_model_set_harmonic_force(model, 1, f1.as_ptr(), zeros.as_ptr(), n), jprom_status::JPROM_OK);
    assert_eq!(jprom_model_set_rayleigh_damping(model, 0.0, 2e-5), jprom_status::JPROM_OK);
    let outs = [0usize, 9];
    assert_eq!(jprom_model_set_output_dofs(model, outs.as_ptr(), 2), jprom_status::JPROM_OK);
    model
}

#[test]
fn rom_sweep_through_c_matches_the_rust_api() {
    let band = (80.0, 200.0);
    // Rust
    let model = rust_model();
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let mut p = PredictionOptions::new(band);
    p.gamma = 1e3;
    p.n_samples = 30;
    let (basis, _) = predict_basis(&coords, &p).unwrap();
    let cond = CondensedSystem::new(&model, 1).unwrap();
    let rom = NlrRom::new(&cond, &basis).unwrap();
    let expect = sweep(&rom, &SweepOptions::band(band.0, band.1), &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    unsafe {
        let m = c_model();
        let mut opts = std::mem::zeroed();
        let mut sopts = std::mem::zeroed();
        jprom_hbm_options_default(&mut opts);
        jprom_sweep_options_default(&mut sopts);
        sopts.omega_start = band.0;
        sopts.omega_end = band.1;
        let mut b = std::ptr::null_mut();
        assert_eq!(jprom_basis_predict(m, &opts, band.0, band.1, 1e3, 30, &mut b), jprom_status::JPROM_OK);
        let mut sizes = [0usize; 2];
        let mut hh = 0;
        assert_eq!(jprom_basis_sizes(b, sizes.as_mut_ptr(), 2, &mut hh), jprom_status::JPROM_OK);
        assert_eq!(sizes.to_vec(), basis.sizes);
        assert_eq!(jprom_basis_sizes(b, sizes.as_mut_ptr(), 1, &mut hh), jprom_status::JPROM_BAD_SIZE);
        let mut s = std::ptr::null_mut();
        assert_eq!(jprom_rom_sweep(m, b, 7, &opts, &sopts, None, std::ptr::null_mut(), &mut s), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_rom_sweep(m, b, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, None, std::ptr::null_mut(), &mut s), jprom_status::JPROM_OK);
        let mut n = 0;
        jprom_sweep_result_n_points(s, &mut n);
        assert_eq!(n, expect.points.len());
        for (i, p) in expect.points.iter().enumerate() {
            let (mut w, mut a, mut e) = (0.0, 0.0, 0.0);
            jprom_sweep_result_point_omega(s, i, &mut w);
            jprom_sweep_result_point_amplitude(s, i, 1, 1, &mut a);
            assert_eq!(jprom_sweep_result_point_predicted_error(s, i, 1, &mut e), jprom_status::JPROM_OK);
            assert_eq!(w, p.omega);
            assert_eq!(a, p.output_amplitude(1, 1));
            assert!(e.is_finite() && e >= 0.0);
        }
        jprom_sweep_result_free(s);
        // a full-order sweep has no predicted error
        let mut fo = std::ptr::null_mut();
        assert_eq!(jprom_sweep(m, &opts, &sopts, None, std::ptr::null_mut(), &mut fo), jprom_status::JPROM_OK);
        let mut e = 0.0;
        assert_eq!(jprom_sweep_result_point_predicted_error(fo, 0, 1, &mut e), jprom_status::JPROM_INVALID_VALUE);
        // FR runs too
        let mut fr = std::ptr::null_mut();
        assert_eq!(jprom_rom_sweep(m, b, jprom_rom_kind::JPROM_ROM_FR as c_int, &opts, &sopts, None, std::ptr::null_mut(), &mut fr), jprom_status::JPROM_OK);
        jprom_sweep_result_free(fr);
        jprom_sweep_result_free(fo);
        jprom_basis_free(b);
        assert_eq!(jprom_basis_free(b), jprom_status::JPROM_INVALID_HANDLE);
        jprom_model_free(m);
    }
}

unsafe fn ok(s: jprom_status) {
    assert_eq!(s, jprom_status::JPROM_OK, "{}", std::ffi::CStr::from_ptr(jprom_last_error_message()).to_string_lossy());
}

unsafe fn c_options(band: (f64, f64)) -> (jprom_hbm_options, jprom_sweep_options, jprom_jp_options) {
    let mut opts = std::mem::zeroed();
    let mut sopts = std::mem::zeroed();
    let mut jo = std::mem::zeroed();
    ok(jprom_hbm_options_default(&mut opts));
    ok(jprom_sweep_options_default(&mut sopts));
    ok(jprom_jp_options_init(&mut jo, std::mem::size_of::<jprom_jp_options>()));
    sopts.omega_start = band.0;
    sopts.omega_end = band.1;
    (opts, sopts, jo)
}

unsafe fn basis_sizes(b: *const jprom_basis) -> Vec<usize> {
    let mut hh = 0;
    let mut sizes = vec![0usize; 16];
    ok(jprom_basis_sizes(b, sizes.as_mut_ptr(), sizes.len(), &mut hh));
    sizes.truncate(hh + 1);
    sizes
}

/// Per point: (omega, |X1| at output 1, e*_1).
unsafe fn c_rows(s: *const jprom_sweep_result) -> Vec<(f64, f64, f64)> {
    let mut n = 0;
    ok(jprom_sweep_result_n_points(s, &mut n));
    (0..n)
        .map(|i| {
            let (mut w, mut a, mut e) = (0.0, 0.0, 0.0);
            ok(jprom_sweep_result_point_omega(s, i, &mut w));
            ok(jprom_sweep_result_point_amplitude(s, i, 1, 1, &mut a));
            ok(jprom_sweep_result_point_predicted_error(s, i, 1, &mut e));
            (w, a, e)
        })
        .collect()
}

#[test]
fn jp_options_defaults_are_the_rust_defaults_and_predict_opts_matches() {
    let band = (80.0, 200.0);
    let model = rust_model();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let mut p = PredictionOptions::new(band);
    p.n_samples = 30;
    p.modes.extra_outside = 2;
    let (basis, _) = predict_basis(&coords, &p).unwrap();
    unsafe {
        let (opts, _, mut jo) = c_options(band);
        let a = AdaptiveOptions::default();
        let d = PredictionOptions::new(band);
        assert_eq!(jo.struct_size, std::mem::size_of::<jprom_jp_options>());
        assert_eq!((jo.gamma, jo.n_samples, jo.extra_outside, jo.static_correction != 0), (d.gamma, d.n_samples, d.modes.extra_outside, d.modes.static_correction));
        assert_eq!((jo.threshold, jo.max_corrections, jo.gamma_growth, jo.max_gamma), (a.threshold, a.max_corrections, a.gamma_growth, a.max_gamma));
        let m = c_model();
        jo.n_samples = 30;
        jo.extra_outside = 2;
        let mut b = std::ptr::null_mut();
        ok(jprom_basis_predict_opts(m, &opts, &jo, band.0, band.1, &mut b));
        assert_eq!(basis_sizes(b), basis.sizes);
        // with the defaults otherwise (extra_outside 2 is the default), the same basis as
        // jprom_basis_predict
        let (mut b1, mut b2) = (std::ptr::null_mut(), std::ptr::null_mut());
        ok(jprom_basis_predict_opts(m, &opts, &jo, band.0, band.1, &mut b1));
        ok(jprom_basis_predict(m, &opts, band.0, band.1, jo.gamma, jo.n_samples, &mut b2));
        assert_eq!(basis_sizes(b1), basis_sizes(b2));
        jo.struct_size -= 1;
        let mut b3 = std::ptr::null_mut();
        assert_eq!(jprom_basis_predict_opts(m, &opts, &jo, band.0, band.1, &mut b3), jprom_status::JPROM_BAD_SIZE);
        assert!(b3.is_null());
        for b in [b, b1, b2] {
            ok(jprom_basis_free(b));
        }
        ok(jprom_model_free(m));
    }
}

/// `jprom_jp_options.slipping` (version 2): the C prediction with each value is the Rust
/// prediction with the same `SlippingSamples` (the same patterns and `Φ_h`); a version-1 struct
/// gets the default (never); a value outside the enum is refused naming the field.
#[test]
fn jp_options_slipping_is_the_rust_slipping_samples() {
    let band = (80.0, 200.0);
    let coords = ContactCoordinates::new(&rust_model(), 1).unwrap();
    let rust = |slipping| predict_basis(&coords, &PredictionOptions { slipping, n_samples: 30, ..PredictionOptions::new(band) }).unwrap();
    let (never, r_never) = rust(SlippingSamples::Never);
    let (always, r_always) = rust(SlippingSamples::Always);
    println!("never: {} patterns, always: {} patterns ({} slipping)", r_never.n_patterns, r_always.n_patterns, r_always.slipping_patterns);
    assert!(r_always.slipping_patterns > 0 && always.n_patterns > never.n_patterns);
    let dir = std::env::temp_dir().join(format!("jprom-slipping-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("basis.json");
    let c_path = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    unsafe {
        let (opts, _, mut jo) = c_options(band);
        assert_eq!(jo.slipping, jprom_slipping_samples::JPROM_SLIPPING_NEVER as c_int);
        assert_eq!(std::mem::offset_of!(jprom_jp_options, slipping), JPROM_JP_OPTIONS_V1_SIZE);
        jo.n_samples = 30;
        let m = c_model();
        let same = |jo: &jprom_jp_options, expect: &JpBasis| {
            let mut b = std::ptr::null_mut();
            ok(jprom_basis_predict_opts(m, &opts, jo, band.0, band.1, &mut b));
            ok(jprom_basis_save_json(b, c_path.as_ptr()));
            ok(jprom_basis_free(b));
            let got = JpBasis::load_json(&path).unwrap();
            assert_eq!((&got.sizes, got.n_patterns), (&expect.sizes, expect.n_patterns));
            for (a, e) in got.phi.iter().zip(&expect.phi) {
                assert!((a - e).norm_max() <= 1e-12, "Φ differs by {:e}", (a - e).norm_max());
            }
        };
        jo.slipping = jprom_slipping_samples::JPROM_SLIPPING_ALWAYS as c_int;
        same(&jo, &always);
        // a caller of version 1 (no `slipping` field): the bytes past its prefix are not read
        jo.struct_size = JPROM_JP_OPTIONS_V1_SIZE;
        same(&jo, &never);
        jo.struct_size = std::mem::size_of::<jprom_jp_options>();
        jo.slipping = jprom_slipping_samples::JPROM_SLIPPING_NEVER as c_int;
        same(&jo, &never);
        for bad in [3, -1] {
            jo.slipping = bad;
            let mut b = std::ptr::null_mut();
            assert_eq!(jprom_basis_predict_opts(m, &opts, &jo, band.0, band.1, &mut b), jprom_status::JPROM_INVALID_VALUE);
            assert!(b.is_null());
            let msg = std::ffi::CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned();
            assert!(msg.contains("slipping") && msg.contains(&bad.to_string()), "{msg}");
        }
        // the exported symbol of the defaults writes version 1, the prefix only
        let mut v1 = std::mem::zeroed::<jprom_jp_options>();
        v1.slipping = 7;
        ok(jprom_jp_options_default(&mut v1));
        assert_eq!((v1.struct_size, v1.slipping), (JPROM_JP_OPTIONS_V1_SIZE, 7));
        ok(jprom_model_free(m));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Version 3 of `jprom_jp_options` carries the self-correcting sweep's remaining settings
/// (`regeneration_samples`, `screen`, `verify`, `response_output`): their defaults are Rust's,
/// set from C they reach the sweep (the same corrections, sizes and swept flags as the Rust
/// sweep with those options, and a different sequence from the defaults', so the comparison
/// can fail), a version-2 caller gets the defaults, and bad values are refused.
#[test]
fn jp_options_version_3_reaches_the_self_correcting_sweep() {
    let band = (80.0, 200.0);
    let model = rust_model();
    let pred = PredictionOptions { n_samples: 5, gamma: 3.0, ..PredictionOptions::new(band) };
    let base = AdaptiveOptions { kind: RomKind::Nlr, threshold: 1e-6, max_corrections: 3, ..AdaptiveOptions::default() };
    let set = AdaptiveOptions { screen: false, verify: false, regeneration_samples: 3, response_output: 1, ..base.clone() };
    let rust = |a: &AdaptiveOptions| adaptive_sweep_with_progress(&model, 1, &pred, &SweepOptions::band(band.0, band.1), &HbmOptions::default(), a, &mut |_, _| ControlFlow::Continue(())).unwrap();
    let summary = |c: &[Correction]| c.iter().map(|c| (std::mem::discriminant(&c.kind), c.sizes.clone(), c.swept)).collect::<Vec<_>>();
    let (r_base, r_set) = (rust(&base), rust(&set));
    assert_ne!(summary(&r_base.corrections), summary(&r_set.corrections), "the settings must change the sequence for this test to tell them apart");
    unsafe {
        let m = c_model();
        let (opts, sopts, mut jo) = c_options(band);
        assert_eq!((jo.regeneration_samples, jo.screen, jo.verify, jo.response_output), (base.regeneration_samples, 1, 1, 0), "defaults");
        assert_eq!(std::mem::offset_of!(jprom_jp_options, regeneration_samples), JPROM_JP_OPTIONS_V2_SIZE);
        jo.n_samples = 5;
        jo.gamma = 3.0;
        jo.threshold = 1e-6;
        jo.max_corrections = 3;
        // the C sweep's corrections: (kind, sizes, swept)
        let c_sweep = |jo: &jprom_jp_options| {
            let mut s = std::ptr::null_mut();
            ok(jprom_rom_sweep_adaptive(m, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, jo, None, std::ptr::null_mut(), &mut s, std::ptr::null_mut()));
            let mut n = 0;
            ok(jprom_sweep_result_n_corrections(s, &mut n));
            let got: Vec<(c_int, Vec<usize>, bool)> = (0..n)
                .map(|i| {
                    let (mut kind, mut swept) = (-1, -1);
                    let mut sizes = [0usize; 2];
                    ok(jprom_sweep_result_correction(s, i, &mut kind, std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut(), sizes.as_mut_ptr(), 2));
                    ok(jprom_sweep_result_correction_swept(s, i, &mut swept));
                    assert!(swept == 0 || swept == 1);
                    (kind, sizes.to_vec(), swept == 1)
                })
                .collect();
            let mut x = 0;
            assert_eq!(jprom_sweep_result_correction_swept(s, n, &mut x), jprom_status::JPROM_INVALID_VALUE);
            assert_eq!(jprom_sweep_result_correction_swept(s, 0, std::ptr::null_mut()), jprom_status::JPROM_NULL_ARGUMENT);
            ok(jprom_sweep_result_free(s));
            got
        };
        let want = |c: &[Correction]| {
            c.iter()
                .map(|c| {
                    let k = match c.kind {
                        CorrectionKind::Regenerated { .. } => jprom_correction_kind::JPROM_CORRECTION_REGENERATED,
                        CorrectionKind::GammaIncreased { .. } => jprom_correction_kind::JPROM_CORRECTION_GAMMA_INCREASED,
                        CorrectionKind::Replaced { .. } => jprom_correction_kind::JPROM_CORRECTION_REPLACED,
                    };
                    (k as c_int, c.sizes.clone(), c.swept)
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(c_sweep(&jo), want(&r_base.corrections), "defaults");
        jo.screen = 0;
        jo.verify = 0;
        jo.regeneration_samples = 3;
        jo.response_output = 1;
        assert_eq!(c_sweep(&jo), want(&r_set.corrections), "version-3 fields set");
        // a version-2 caller: the bytes past its prefix are not read
        jo.struct_size = JPROM_JP_OPTIONS_V2_SIZE;
        assert_eq!(c_sweep(&jo), want(&r_base.corrections), "version 2");
        jo.struct_size = std::mem::size_of::<jprom_jp_options>();
        // refused, naming the field, nothing written
        for (field, bad) in [("regeneration_samples", 0usize), ("regeneration_samples", 10_001), ("response_output", 2)] {
            let mut j = jo;
            match field {
                "regeneration_samples" => j.regeneration_samples = bad,
                _ => j.response_output = bad,
            }
            let mut s = std::ptr::null_mut();
            let st = jprom_rom_sweep_adaptive(m, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, &j, None, std::ptr::null_mut(), &mut s, std::ptr::null_mut());
            assert_ne!(st, jprom_status::JPROM_OK, "{field} = {bad}");
            assert!(s.is_null());
            let msg = std::ffi::CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned();
            assert!(msg.contains(field) && msg.contains(&bad.to_string()), "{msg}");
        }
        ok(jprom_model_free(m));
    }
}

#[test]
fn adaptive_sweep_through_c_matches_the_rust_api() {
    let band = (80.0, 200.0);
    let model = rust_model();
    let hopts = HbmOptions::default();
    // A basis short of complete (gamma 3, 5 samples), so that the errors that decide each
    // correction are far above round-off and the sequence is the same on any number of threads
    // (with the default gamma the basis is exact, the judged errors are 1e-15 and a threshold
    // below them let round-off pick the kinds). Step 1, a regeneration: its modes alone are
    // worse than the first basis and their union ([4, 8]) is above the threshold too where the
    // first basis was judged worst, so neither is swept (screening, the default, which also
    // judged the first basis at the band's start, above the threshold: no pass 0); step 2
    // enlarges gamma to 30, which completes the basis ([6, 10], error ~1e-14 there), so it is
    // swept, within the threshold.
    let mut pred = PredictionOptions::new(band);
    pred.n_samples = 5;
    pred.gamma = 3.0;
    let aopts = AdaptiveOptions { kind: RomKind::Nlr, threshold: 1e-6, max_corrections: 3, ..AdaptiveOptions::default() };
    let mut per_pass = std::collections::BTreeMap::<usize, usize>::new();
    let expect = adaptive_sweep_with_progress(&model, 1, &pred, &SweepOptions::band(band.0, band.1), &hopts, &aopts, &mut |pass, _| {
        *per_pass.entry(pass).or_default() += 1;
        ControlFlow::Continue(())
    })
    .unwrap();
    let kinds: Vec<u8> = expect
        .corrections
        .iter()
        .map(|c| match c.kind {
            CorrectionKind::Replaced { .. } => 0,
            CorrectionKind::Regenerated { .. } => 1,
            CorrectionKind::GammaIncreased { .. } => 2,
        })
        .collect();
    assert_eq!(kinds, [0, 1, 2], "{:?}", expect.corrections);
    let c = &expect.corrections;
    assert!(c[0].worst_error_before > 1e-2 && c[0].worst_error_after > c[0].worst_error_before, "the modes alone lose: {:?}", c[0]);
    // (the error of a complete basis is the reduced sweep's own solver tolerance, 1e-10)
    assert!(c[2].worst_error_after < 1e-8, "the larger gamma completes the basis: {:?}", c[2]);
    assert_eq!(c.iter().map(|c| c.swept).collect::<Vec<_>>(), [false, false, true], "{c:?}");
    assert_eq!(per_pass.keys().copied().collect::<Vec<_>>(), [3], "only the completed basis swept");
    assert_eq!(expect.end, CorrectionEnd::WithinThreshold);
    // With the default gamma the basis spans the space the regenerated modes live in, so their
    // union with it is not swept (JpBasis::spans_the_same) and is reported with the error
    // unchanged; without screening the modes alone are always swept. One step, a threshold
    // below round-off.
    let complete = AdaptiveOptions { threshold: 1e-16, max_corrections: 1, screen: false, ..aopts.clone() };
    let mut swept = std::collections::BTreeSet::new();
    let full = adaptive_sweep_with_progress(&model, 1, &PredictionOptions { n_samples: 30, ..PredictionOptions::new(band) }, &SweepOptions::band(band.0, band.1), &hopts, &complete, &mut |pass, _| {
        swept.insert(pass);
        ControlFlow::Continue(())
    })
    .unwrap();
    assert!(matches!(full.corrections.as_slice(), [Correction { kind: CorrectionKind::Replaced { .. }, .. }, Correction { kind: CorrectionKind::Regenerated { .. }, .. }]), "{:?}", full.corrections);
    assert_eq!(swept.into_iter().collect::<Vec<_>>(), [0, 1], "the union (pass 2) is not swept: {:?}", full.corrections);
    assert_eq!(full.corrections[1].worst_error_after, full.corrections[1].worst_error_before);
    unsafe extern "C" fn count(user: *mut c_void, index: usize, _: f64, _: *const f64, _: usize) -> c_int {
        let v = &mut *(user as *mut Vec<usize>);
        if index == 0 {
            v.push(0);
        }
        *v.last_mut().unwrap() += 1;
        0
    }
    unsafe {
        let m = c_model();
        let (opts, sopts, mut jo) = c_options(band);
        jo.n_samples = 5;
        jo.gamma = 3.0;
        jo.threshold = 1e-6;
        jo.max_corrections = 3;
        let mut counts: Vec<usize> = Vec::new();
        let (mut s, mut b) = (std::ptr::null_mut(), std::ptr::null_mut());
        ok(jprom_rom_sweep_adaptive(m, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, &jo, Some(count), &mut counts as *mut _ as *mut c_void, &mut s, &mut b));
        assert_eq!(counts, per_pass.values().copied().collect::<Vec<_>>(), "points reported per pass");
        let rows = c_rows(s);
        assert_eq!(rows.len(), expect.sweep.points.len());
        for ((w, a, e), (p, es)) in rows.iter().zip(expect.sweep.points.iter().zip(&expect.predicted_errors)) {
            assert_eq!((*w, *a, *e), (p.omega, p.output_amplitude(1, 1), es[1]));
        }
        assert_eq!(basis_sizes(b), expect.basis.sizes);
        let mut nc = 99;
        ok(jprom_sweep_result_n_corrections(s, &mut nc));
        assert_eq!(nc, expect.corrections.len());
        for (i, c) in expect.corrections.iter().enumerate() {
            let (mut kind, mut value, mut before, mut after) = (-1, 0.0, 0.0, 0.0);
            let mut sizes = [0usize; 2];
            ok(jprom_sweep_result_correction(s, i, &mut kind, &mut value, &mut before, &mut after, sizes.as_mut_ptr(), 2));
            let want = match c.kind {
                CorrectionKind::Regenerated { from_omega } => ((jprom_correction_kind::JPROM_CORRECTION_REGENERATED as c_int), from_omega, "regenerated"),
                CorrectionKind::GammaIncreased { gamma } => ((jprom_correction_kind::JPROM_CORRECTION_GAMMA_INCREASED as c_int), gamma, "gamma_increased"),
                CorrectionKind::Replaced { from_omega } => ((jprom_correction_kind::JPROM_CORRECTION_REPLACED as c_int), from_omega, "replaced"),
            };
            assert_eq!((kind, value, before, after, sizes.to_vec()), (want.0, want.1, c.worst_error_before, c.worst_error_after, c.sizes.clone()));
            assert_eq!(std::ffi::CStr::from_ptr(jprom_correction_kind_name(kind)).to_str().unwrap(), want.2, "name of kind {kind}");
            // every pointer may be NULL
            ok(jprom_sweep_result_correction(s, i, std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut(), 0));
            assert_eq!(jprom_sweep_result_correction(s, i, &mut kind, &mut value, &mut before, &mut after, sizes.as_mut_ptr(), 1), jprom_status::JPROM_BAD_SIZE);
        }
        assert_eq!(jprom_sweep_result_correction(s, nc, std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null_mut(), 0), jprom_status::JPROM_INVALID_VALUE);
        // why the corrections ended and the judged error: within the threshold
        let (mut end, mut judged) = (jprom_correction_end::JPROM_CORRECTIONS_NO_PROGRESS, -1.0);
        ok(jprom_sweep_result_correction_end(s, &mut end, &mut judged));
        assert_eq!((end, judged), (jprom_correction_end::JPROM_CORRECTIONS_WITHIN_THRESHOLD, expect.worst_error));
        assert_eq!(std::ffi::CStr::from_ptr(jprom_correction_end_name(end as c_int)).to_str().unwrap(), "within_threshold");
        ok(jprom_sweep_result_correction_end(s, std::ptr::null_mut(), std::ptr::null_mut()));
        // the static contact displacement's error at the checks, as Rust's
        let mut w0 = -1.0;
        ok(jprom_sweep_result_static_error(s, &mut w0));
        assert_eq!(Some(w0), expect.worst_static_error());
        assert!(w0 >= 0.0);
        assert_eq!(jprom_sweep_result_static_error(s, std::ptr::null_mut()), jprom_status::JPROM_NULL_ARGUMENT);
        // the verdict and the judged error per point, as Rust's
        let trust_of = |s: *const jprom_sweep_result| {
            let mut t = -1;
            ok(jprom_sweep_result_trusted(s, &mut t));
            let mut buf = [0 as c_char; 512];
            let mut n = usize::MAX;
            ok(jprom_sweep_result_trust_reason_copy(s, buf.as_mut_ptr(), buf.len(), &mut n));
            let judged: Vec<f64> = (0..rows.len())
                .map(|i| {
                    let mut e = -1.0;
                    ok(jprom_sweep_result_point_judged_error(s, i, &mut e));
                    e
                })
                .collect();
            (t, std::ffi::CStr::from_ptr(buf.as_ptr()).to_str().unwrap().to_string(), n, judged)
        };
        let trust = trust_of(s);
        let reason = expect.trust.reason.clone().unwrap_or_default();
        assert_eq!(trust, (c_int::from(expect.trust.trusted), reason.clone(), reason.len(), expect.judged_errors()));
        assert!(trust.3.iter().all(|e| *e >= 0.0) && trust.3.len() == rows.len());
        let mut e_out = -1.0;
        assert_eq!(jprom_sweep_result_point_judged_error(s, rows.len(), &mut e_out), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(e_out, -1.0, "nothing written for an index out of range");
        assert_eq!(jprom_sweep_result_trusted(s, std::ptr::null_mut()), jprom_status::JPROM_NULL_ARGUMENT);
        // saved and loaded, the reduced sweep keeps its e* and its corrections
        let path = std::env::temp_dir().join(format!("jprom-adaptive-{}.json", std::process::id()));
        let cpath = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
        ok(jprom_sweep_result_save_json(s, cpath.as_ptr()));
        assert!(std::fs::read_to_string(&path).unwrap().contains("\"kind\":\"reduced_sweep\""));
        let mut loaded = std::ptr::null_mut();
        ok(jprom_sweep_result_load_json(cpath.as_ptr(), &mut loaded));
        assert_eq!(c_rows(loaded), rows, "omega, X1 and e*_1 after a save and a load");
        let mut nl = 99;
        ok(jprom_sweep_result_n_corrections(loaded, &mut nl));
        assert_eq!(nl, nc);
        for i in 0..nc {
            let mut a = (-1, 0.0, 0.0, 0.0);
            let mut b2 = (-1, 0.0, 0.0, 0.0);
            ok(jprom_sweep_result_correction(s, i, &mut a.0, &mut a.1, &mut a.2, &mut a.3, std::ptr::null_mut(), 0));
            ok(jprom_sweep_result_correction(loaded, i, &mut b2.0, &mut b2.1, &mut b2.2, &mut b2.3, std::ptr::null_mut(), 0));
            assert_eq!(a, b2);
        }
        let (mut end2, mut judged2) = (jprom_correction_end::JPROM_CORRECTIONS_WITHIN_THRESHOLD, -1.0);
        ok(jprom_sweep_result_correction_end(loaded, &mut end2, &mut judged2));
        assert_eq!((end2, judged2), (end, judged), "how the corrections ended, after a save and a load");
        let mut w0_loaded = -1.0;
        ok(jprom_sweep_result_static_error(loaded, &mut w0_loaded));
        assert_eq!(w0_loaded, w0, "the static error after a save and a load");
        assert_eq!(trust_of(loaded), trust, "the verdict and the judged errors after a save and a load");
        ok(jprom_sweep_result_free(loaded));
        std::fs::remove_file(&path).ok();
        // the final basis is usable: a plain ROM sweep on it gives the final pass again
        let mut again = std::ptr::null_mut();
        ok(jprom_rom_sweep(m, b, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, None, std::ptr::null_mut(), &mut again));
        assert_eq!(c_rows(again), rows);
        let mut zero = 99;
        ok(jprom_sweep_result_n_corrections(again, &mut zero));
        assert_eq!(zero, 0);
        // a plain reduced sweep made no corrections: asking how they ended is refused, nothing written
        let (mut end3, mut judged3) = (jprom_correction_end::JPROM_CORRECTIONS_NO_PROGRESS, -1.0);
        assert_eq!(jprom_sweep_result_correction_end(again, &mut end3, &mut judged3), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!((end3, judged3), (jprom_correction_end::JPROM_CORRECTIONS_NO_PROGRESS, -1.0));
        let mut w0_plain = -1.0;
        assert_eq!(jprom_sweep_result_static_error(again, &mut w0_plain), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(w0_plain, -1.0, "nothing written");
        let mut t_plain = -1;
        assert_eq!(jprom_sweep_result_trusted(again, &mut t_plain), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_sweep_result_point_judged_error(again, 0, &mut w0_plain), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!((t_plain, w0_plain), (-1, -1.0), "nothing written for a plain reduced sweep");
        ok(jprom_sweep_result_free(again));
        ok(jprom_sweep_result_free(s));
        ok(jprom_basis_free(b));

        // one step allowed: the first step's candidates are both screened out (above the
        // threshold where the first basis failed), which does not spend the budget (it counts
        // towards twice max_corrections only); the gamma step that follows is swept and within
        // the threshold
        let one = AdaptiveOptions { max_corrections: 1, ..aopts.clone() };
        let one_step = adaptive_sweep(&model, 1, &pred, &SweepOptions::band(band.0, band.1), &hopts, &one).unwrap();
        assert_eq!((one_step.end, one_step.corrections.len()), (CorrectionEnd::WithinThreshold, 3), "{:?}", one_step.corrections);
        assert_eq!(one_step.corrections.iter().map(|c| c.swept).collect::<Vec<_>>(), vec![false, false, true]);
        // no step allowed: the corrections run out above the threshold at once
        // (MAX_CORRECTIONS, the judged error the basis' own, 0.062), as the Rust API says
        let none = AdaptiveOptions { max_corrections: 0, ..aopts.clone() };
        let short = adaptive_sweep(&model, 1, &pred, &SweepOptions::band(band.0, band.1), &hopts, &none).unwrap();
        assert_eq!((short.end, short.corrections.len()), (CorrectionEnd::MaxCorrections, 0), "{:?}", short.corrections);
        assert!(short.worst_error > 1e-2, "{}", short.worst_error);
        let mut jo1 = jo;
        jo1.max_corrections = 0;
        let mut s1 = std::ptr::null_mut();
        ok(jprom_rom_sweep_adaptive(m, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, &jo1, None, std::ptr::null_mut(), &mut s1, std::ptr::null_mut()));
        let (mut end1, mut judged1) = (jprom_correction_end::JPROM_CORRECTIONS_WITHIN_THRESHOLD, -1.0);
        ok(jprom_sweep_result_correction_end(s1, &mut end1, &mut judged1));
        assert_eq!((end1, judged1), (jprom_correction_end::JPROM_CORRECTIONS_MAX_CORRECTIONS, short.worst_error));
        assert_eq!(std::ffi::CStr::from_ptr(jprom_correction_end_name(end1 as c_int)).to_str().unwrap(), "max_corrections");
        ok(jprom_sweep_result_free(s1));

        // the defaults, FR, no basis wanted
        let (_, _, jo) = c_options(band);
        let mut fr = std::ptr::null_mut();
        ok(jprom_rom_sweep_adaptive(m, jprom_rom_kind::JPROM_ROM_FR as c_int, &opts, &sopts, &jo, None, std::ptr::null_mut(), &mut fr, std::ptr::null_mut()));
        let pred = PredictionOptions::new(band);
        let fr_expect = adaptive_sweep(&model, 1, &pred, &SweepOptions::band(band.0, band.1), &hopts, &AdaptiveOptions { kind: RomKind::Fr, ..AdaptiveOptions::default() }).unwrap();
        let fr_rows = c_rows(fr);
        assert_eq!(fr_rows.len(), fr_expect.sweep.points.len());
        assert_eq!(fr_rows.last().unwrap().2, fr_expect.predicted_errors.last().unwrap()[1]);
        let (mut end4, mut judged4) = (jprom_correction_end::JPROM_CORRECTIONS_CANCELLED, -1.0);
        ok(jprom_sweep_result_correction_end(fr, &mut end4, &mut judged4));
        assert_eq!(end4, fr_expect.end.into());
        assert_eq!(judged4, fr_expect.worst_error);
        assert!(judged4 <= 0.05 || end4 != jprom_correction_end::JPROM_CORRECTIONS_WITHIN_THRESHOLD, "within the threshold means below it");
        let mut w0_fr = -1.0;
        ok(jprom_sweep_result_static_error(fr, &mut w0_fr));
        assert_eq!(Some(w0_fr), fr_expect.worst_static_error());
        ok(jprom_sweep_result_free(fr));

        // a callback that stops: OK with end reason CANCELLED, the points so far and the basis are handed out
        unsafe extern "C" fn stop_at_third(_: *mut c_void, index: usize, _: f64, _: *const f64, _: usize) -> c_int {
            (index >= 2) as c_int
        }
        let (mut s, mut b) = (std::ptr::null_mut(), std::ptr::null_mut());
        assert_eq!(jprom_rom_sweep_adaptive(m, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, &jo, Some(stop_at_third), std::ptr::null_mut(), &mut s, &mut b), jprom_status::JPROM_OK);
        let mut reason = jprom_sweep_end::JPROM_SWEEP_REACHED_END;
        assert_eq!(jprom_sweep_result_end_reason(s, &mut reason), jprom_status::JPROM_OK);
        assert_eq!(reason, jprom_sweep_end::JPROM_SWEEP_CANCELLED);
        let mut n = 0;
        ok(jprom_sweep_result_n_points(s, &mut n));
        assert_eq!(n, 3);
        ok(jprom_sweep_result_n_corrections(s, &mut n));
        assert_eq!(n, 0);
        let mut end5 = jprom_correction_end::JPROM_CORRECTIONS_WITHIN_THRESHOLD;
        ok(jprom_sweep_result_correction_end(s, &mut end5, std::ptr::null_mut()));
        assert_eq!(end5, jprom_correction_end::JPROM_CORRECTIONS_CANCELLED);
        assert!(!b.is_null());
        ok(jprom_sweep_result_free(s));
        ok(jprom_basis_free(b));
        ok(jprom_model_free(m));
    }
}

#[test]
fn basis_from_solution_and_actual_error_through_c_match_the_rust_api() {
    let band = (80.0, 200.0);
    let omega = 120.0;
    let hopts = HbmOptions::default();
    unsafe {
        let m = c_model();
        // The Rust side works on the model the C API holds (saved and reloaded bit for bit).
        let mpath = std::env::temp_dir().join(format!("jprom_ffi_rom_model_{}.json", std::process::id()));
        let cmpath = std::ffi::CString::new(mpath.to_str().unwrap()).unwrap();
        ok(jprom_model_save_json(m, cmpath.as_ptr()));
        let model: Model = jprom::io::load_json("model", &mpath).unwrap();
        let _ = std::fs::remove_file(&mpath);
        let coords = ContactCoordinates::new(&model, 1).unwrap();
        let cond = CondensedSystem::new(&model, 1).unwrap();
        let fo = solve_point(&cond, omega, None, &hopts).unwrap();
        let (opts, sopts, mut jo) = c_options(band);
        jo.extra_outside = 2;
        // a basis of one Jacobian: with the static correction, as ModeOptions::in_band has it
        // (the prediction's default, which jprom_jp_options_default copies, has none)
        jo.static_correction = 1;
        let mut fs = std::ptr::null_mut();
        ok(jprom_solve_point(m, omega, &opts, &mut fs));
        // The C solve is the Rust one to round-off; the basis is built from the C solution on
        // both sides, since a stuck pair's eigenvectors turn with the last bit of K̂.
        let path = std::env::temp_dir().join(format!("jprom_ffi_rom_fo_{}.json", std::process::id()));
        let cpath = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
        ok(jprom_solution_save_json(fs, cpath.as_ptr()));
        let fo_c: jprom::hbm::PointSolution = jprom::io::load_json("solution", &path).unwrap();
        let _ = std::fs::remove_file(&path);
        let d = fo_c.z.iter().zip(&fo.z).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        let zmax = fo.z.iter().map(|x| x.abs()).fold(0.0, f64::max);
        assert!(d <= 1e-10 * zmax, "C and Rust full-order solutions differ by {d:e}");
        let mut modes = ModeOptions::in_band(band);
        modes.extra_outside = 2;
        let basis = JpBasis::from_solution(&coords, &fo_c, &BasisOptions { modes, gamma: 1e3 }).unwrap();
        let rom = NlrRom::new(&cond, &basis).unwrap();
        let expect = sweep(&rom, &SweepOptions::band(band.0, band.1), &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
        let mut b = std::ptr::null_mut();
        ok(jprom_basis_from_solution(m, fs, &opts, &jo, band.0, band.1, &mut b));
        assert_eq!(basis_sizes(b), basis.sizes);
        let mut s = std::ptr::null_mut();
        ok(jprom_rom_sweep(m, b, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, None, std::ptr::null_mut(), &mut s));
        let rows = c_rows(s);
        assert_eq!(rows.len(), expect.points.len());
        for ((w, a, _), p) in rows.iter().zip(&expect.points) {
            assert_eq!((*w, *a), (p.omega, p.output_amplitude(1, 1)));
        }
        // the actual error at the first reduced point against a full-order solve there
        let p0 = &expect.points[0];
        let fo0 = solve_point(&cond, p0.omega, None, &hopts).unwrap();
        let want = actual_error(&rom, p0.omega, &p0.z, &fo0).unwrap();
        let mut rs = std::ptr::null_mut();
        ok(jprom_sweep_result_point(s, 0, &mut rs));
        let mut fs0 = std::ptr::null_mut();
        ok(jprom_solve_point(m, p0.omega, &opts, &mut fs0));
        let mut e = [f64::NAN; 2];
        ok(jprom_rom_actual_error(m, b, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, rs, fs0, e.as_mut_ptr(), 2));
        assert_eq!(e.to_vec(), want);
        // a full-order solution on all DoFs gives the same contact forces to round-off (the
        // basis is exact here: e ~ 1e-15)
        let mut full_opts = opts;
        full_opts.condensed = 0;
        let mut ff0 = std::ptr::null_mut();
        ok(jprom_solve_point(m, p0.omega, &full_opts, &mut ff0));
        let mut e_full = [f64::NAN; 2];
        ok(jprom_rom_actual_error(m, b, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, rs, ff0, e_full.as_mut_ptr(), 2));
        assert!(e_full.iter().zip(&e).all(|(a, b)| (a - b).abs() <= 1e-9), "{e_full:?} vs {e:?}");
        // misuse is refused, and the buffer is left alone
        let mut e_bad = [-1.0; 2];
        assert_eq!(jprom_rom_actual_error(m, b, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, fs0, rs, e_bad.as_mut_ptr(), 2), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_rom_actual_error(m, b, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, rs, fs, e_bad.as_mut_ptr(), 2), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(jprom_rom_actual_error(m, b, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, rs, fs0, e_bad.as_mut_ptr(), 1), jprom_status::JPROM_BAD_SIZE);
        assert_eq!(jprom_rom_actual_error(m, b, 5, &opts, rs, fs0, e_bad.as_mut_ptr(), 2), jprom_status::JPROM_INVALID_VALUE);
        assert_eq!(e_bad, [-1.0; 2]);
        let mut b_bad = std::ptr::null_mut();
        assert_eq!(jprom_basis_from_solution(m, rs, &opts, &jo, band.0, band.1, &mut b_bad), jprom_status::JPROM_INVALID_VALUE);
        assert!(b_bad.is_null());
        for p in [rs, fs0, ff0, fs] {
            ok(jprom_solution_free(p));
        }
        ok(jprom_sweep_result_free(s));
        ok(jprom_basis_free(b));
        ok(jprom_model_free(m));
    }
}

/// The names of 0.1 and 0.2 on a sweep (`jprom_sweep_n_points`, ..., deprecated in 0.3) still
/// work and give what the `jprom_sweep_result_*` names give, on a reduced sweep with
/// corrections and e* at every point.
#[test]
#[allow(deprecated)]
fn deprecated_sweep_names_forward_to_the_new_ones() {
    unsafe {
        let m = c_model();
        let band = (80.0, 200.0);
        let (opts, sopts, mut jo) = c_options(band);
        jo.n_samples = 30;
        jo.threshold = 1e-16;
        jo.max_corrections = 2;
        let (mut s, mut b) = (std::ptr::null_mut(), std::ptr::null_mut());
        ok(jprom_rom_sweep_adaptive(m, jprom_rom_kind::JPROM_ROM_NLR as c_int, &opts, &sopts, &jo, None, std::ptr::null_mut(), &mut s, &mut b));
        let (mut n_old, mut n_new) = (0, 1);
        ok(jprom_sweep_n_points(s, &mut n_old));
        ok(jprom_sweep_result_n_points(s, &mut n_new));
        assert!(n_old > 10 && n_old == n_new, "{n_old} vs {n_new}");
        let (mut e_old, mut e_new) = (jprom_sweep_end::JPROM_SWEEP_STALLED, jprom_sweep_end::JPROM_SWEEP_CANCELLED);
        ok(jprom_sweep_end_reason(s, &mut e_old));
        ok(jprom_sweep_result_end_reason(s, &mut e_new));
        assert_eq!(e_old, e_new);
        let (mut r_old, mut r_new) = (-1, -2);
        ok(jprom_sweep_reached_end(s, &mut r_old));
        ok(jprom_sweep_result_reached_end(s, &mut r_new));
        assert_eq!((r_old, r_new), (1, 1));
        let (mut buf_old, mut buf_new) = ([1 as std::ffi::c_char; 8], [2 as std::ffi::c_char; 8]);
        let (mut w_old, mut w_new) = (9, 9);
        ok(jprom_sweep_failure_copy(s, buf_old.as_mut_ptr(), 8, &mut w_old));
        ok(jprom_sweep_result_failure_copy(s, buf_new.as_mut_ptr(), 8, &mut w_new));
        assert_eq!((w_old, buf_old[0]), (w_new, buf_new[0]));
        let n_out = 2;
        for i in [0, n_old / 2, n_old - 1] {
            let (mut a, mut b2) = ([0.0; 6], [0.0; 6]);
            let (mut w0, mut w1) = (0.0, 1.0);
            ok(jprom_sweep_point_omega(s, i, &mut w0));
            ok(jprom_sweep_result_point_omega(s, i, &mut w1));
            assert_eq!(w0, w1);
            ok(jprom_sweep_point_amplitude(s, i, 1, 1, &mut a[0]));
            ok(jprom_sweep_result_point_amplitude(s, i, 1, 1, &mut b2[0]));
            assert_eq!(a[0], b2[0]);
            ok(jprom_sweep_point_output_coeffs(s, i, a.as_mut_ptr(), 3 * n_out));
            ok(jprom_sweep_result_point_output_coeffs(s, i, b2.as_mut_ptr(), 3 * n_out));
            assert_eq!(a, b2);
            let (mut d0, mut d1) = ([0.0; 2], [1.0; 2]);
            ok(jprom_sweep_point_dissipated_energy(s, i, d0.as_mut_ptr(), 2));
            ok(jprom_sweep_result_point_dissipated_energy(s, i, d1.as_mut_ptr(), 2));
            assert_eq!(d0, d1);
            let (mut it0, mut it1, mut res0, mut res1) = (0, 1, 0.0, 1.0);
            ok(jprom_sweep_point_convergence(s, i, &mut it0, &mut res0));
            ok(jprom_sweep_result_point_convergence(s, i, &mut it1, &mut res1));
            assert_eq!((it0, res0), (it1, res1));
            let (mut p0, mut p1) = (0.0, 1.0);
            ok(jprom_sweep_point_predicted_error(s, i, 1, &mut p0));
            ok(jprom_sweep_result_point_predicted_error(s, i, 1, &mut p1));
            assert_eq!(p0, p1);
            let (mut sol0, mut sol1) = (std::ptr::null_mut(), std::ptr::null_mut());
            ok(jprom_sweep_point(s, i, &mut sol0));
            ok(jprom_sweep_result_point(s, i, &mut sol1));
            assert_eq!((*sol0).point, (*sol1).point);
            ok(jprom_solution_free(sol0));
            ok(jprom_solution_free(sol1));
        }
        let (mut c_old, mut c_new) = (0, 9);
        ok(jprom_sweep_n_corrections(s, &mut c_old));
        ok(jprom_sweep_result_n_corrections(s, &mut c_new));
        assert!(c_old >= 1 && c_old == c_new, "{c_old} vs {c_new}");
        for i in 0..c_old {
            let (mut k0, mut v0, mut b0, mut a0) = (-1, 0.0, 0.0, 0.0);
            let (mut k1, mut v1, mut b1, mut a1) = (-2, 1.0, 1.0, 1.0);
            ok(jprom_sweep_correction(s, i, &mut k0, &mut v0, &mut b0, &mut a0, std::ptr::null_mut(), 0));
            ok(jprom_sweep_result_correction(s, i, &mut k1, &mut v1, &mut b1, &mut a1, std::ptr::null_mut(), 0));
            assert_eq!((k0, v0, b0, a0), (k1, v1, b1, a1));
        }
        // saved by the old name, loaded by the new one, and the other way round
        let dir = std::env::temp_dir();
        let p_old = std::ffi::CString::new(dir.join(format!("jprom-dep-old-{}.json", std::process::id())).to_str().unwrap()).unwrap();
        let p_new = std::ffi::CString::new(dir.join(format!("jprom-dep-new-{}.json", std::process::id())).to_str().unwrap()).unwrap();
        ok(jprom_sweep_save_json(s, p_old.as_ptr()));
        ok(jprom_sweep_result_save_json(s, p_new.as_ptr()));
        let (mut l_old, mut l_new) = (std::ptr::null_mut(), std::ptr::null_mut());
        ok(jprom_sweep_load_json(p_new.as_ptr(), &mut l_old));
        ok(jprom_sweep_result_load_json(p_old.as_ptr(), &mut l_new));
        assert_eq!(c_rows(l_old), c_rows(s));
        assert_eq!(c_rows(l_new), c_rows(s));
        for p in [&p_old, &p_new] {
            std::fs::remove_file(p.to_str().unwrap()).ok();
        }
        ok(jprom_sweep_free(l_old));
        ok(jprom_sweep_result_free(l_new));
        assert_eq!(jprom_sweep_free(std::ptr::null_mut()), jprom_status::JPROM_OK);
        ok(jprom_sweep_free(s));
        ok(jprom_basis_free(b));
        ok(jprom_model_free(m));
    }
}

#[test]
fn correction_end_names_cover_every_end() {
    let name = |k: c_int| unsafe { std::ffi::CStr::from_ptr(jprom_correction_end_name(k)) }.to_str().unwrap().to_owned();
    let ends = [CorrectionEnd::WithinThreshold, CorrectionEnd::MaxCorrections, CorrectionEnd::NoProgress, CorrectionEnd::Stopped];
    let names: Vec<String> = ends.iter().map(|&e| name(jprom_correction_end::from(e) as c_int)).collect();
    assert_eq!(names, ["within_threshold", "max_corrections", "no_progress", "cancelled"]);
    for k in [-1, 4, c_int::MAX] {
        assert_eq!(name(k), "unknown", "end {k}");
    }
}

/// The C names are the core's words (the CLI's tables and files use those): one vocabulary for
/// a sweep's end and a correction's end, whichever side of the ABI reads it.
#[test]
fn c_end_names_are_the_core_names() {
    use jprom::hbm::SweepEnd;
    let c_name = |p: *const std::ffi::c_char| unsafe { std::ffi::CStr::from_ptr(p) }.to_str().unwrap().to_owned();
    for e in [CorrectionEnd::WithinThreshold, CorrectionEnd::MaxCorrections, CorrectionEnd::NoProgress, CorrectionEnd::Stopped] {
        assert_eq!(c_name(jprom_correction_end_name(jprom_correction_end::from(e) as c_int)), e.name(), "{e:?}");
    }
    for e in [SweepEnd::ReachedEnd, SweepEnd::StepTooSmall, SweepEnd::MaxPoints, SweepEnd::LeftBand, SweepEnd::StoppedByCaller] {
        assert_eq!(c_name(jprom_sweep_end_name(jprom_sweep_end::from(e) as c_int)), e.name(), "{e:?}");
    }
    assert_eq!(c_name(jprom_sweep_end_name(5)), "unknown");
    assert_eq!(c_name(jprom_sweep_end_name(-1)), "unknown");
}

#[test]
fn correction_kind_names_cover_every_kind_and_refuse_none() {
    let name = |k: c_int| unsafe { std::ffi::CStr::from_ptr(jprom_correction_kind_name(k)) }.to_str().unwrap().to_owned();
    use jprom_correction_kind::*;
    let kinds = [JPROM_CORRECTION_REGENERATED, JPROM_CORRECTION_GAMMA_INCREASED, JPROM_CORRECTION_REPLACED];
    let names: Vec<String> = kinds.iter().map(|&k| name(k as c_int)).collect();
    assert_eq!(names, ["regenerated", "gamma_increased", "replaced"]);
    // any other value (a newer library's kind read by an older caller, or garbage) has a name too
    for k in [-1, 3, 99, c_int::MIN, c_int::MAX] {
        assert_eq!(name(k), "unknown", "kind {k}");
    }
}
