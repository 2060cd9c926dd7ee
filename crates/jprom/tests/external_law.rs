//! The external (user-defined, memoryless) law of issue 18 (`ContactLaw::External`, the core
//! of the C callback element): a cubic spring written as a callable gives the HBM solution of
//! `ContactLaw::Polynomial` (which runs through the other AFT path, the SampleLaw loop); a
//! linear one equals the spring in K; its analytical AFT Jacobian (1 to 3 coupled coordinates)
//! against central finite differences; a failing or panicking callable ends the solve with an
//! error naming the element and the sample; a model holding one cannot be saved.

use jprom_testkit::hbm::{harmonic_force, rel_diff};

use faer::Mat;
use jprom::aft::{AftBackend, AftPlan};
use jprom::contact::{Contact, ContactLaw, ExternalFn, ExternalLaw, IDENTITY_FRAME};
use jprom::error::JpError;
use jprom::hbm::{solve_point, FullSystem, HbmOptions, PointSolution};
use jprom::model::{Damping, Excitation, Model};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

fn external(dim: usize, f: impl Fn(&[f64], &mut [f64], &mut [f64]) -> Result<(), String> + Send + Sync + 'static) -> ContactLaw {
    let f: Arc<ExternalFn> = Arc::new(f);
    ContactLaw::External(ExternalLaw::new(dim, f).unwrap())
}

fn cubic_external(k1: f64, k3: f64) -> ContactLaw {
    external(1, move |w, f, j| {
        f[0] = k1 * w[0] + k3 * w[0].powi(3);
        j[0] = k1 + 3.0 * k3 * w[0] * w[0];
        Ok(())
    })
}

fn on_pair(law: ContactLaw, dim: usize, a: usize, b: Option<usize>) -> Contact {
    let dofs_a = (a..a + dim).collect();
    let dofs_b = b.map(|b| (b..b + dim).collect());
    Contact { dofs_a, dofs_b, frame: IDENTITY_FRAME, law }
}

fn diag(v: &[f64]) -> Mat<f64> {
    Mat::from_fn(v.len(), v.len(), |i, j| if i == j { v[i] } else { 0.0 })
}

/// 2 DoFs: spring 1.0 from DoF 0 to ground, `k_between` between DoFs 0 and 1.
fn two_dof(k_between: f64, contacts: Vec<Contact>) -> Model {
    let k = Mat::from_fn(2, 2, |i, j| match (i, j) {
        (0, 0) => 1.0 + k_between,
        (1, 1) => k_between,
        _ => -k_between,
    });
    let exc = Excitation { static_force: vec![0.1, -0.05], harmonics: vec![harmonic_force(vec![0.3, 0.1], vec![0.0; 2])], dynamic_scale: 1.0 };
    let mut model = Model::new(diag(&[1.0, 0.5]), k, Damping::default(), exc, contacts, vec![0, 1]).expect("valid model");
    model.added_damping = Some(diag(&[0.02, 0.01]));
    model.validate().unwrap();
    model
}

fn solve(model: &Model, h: usize, omega: f64) -> Result<PointSolution, JpError> {
    let opts = HbmOptions::default();
    let sys = FullSystem::new(model, h)?;
    solve_point(&sys, omega, None, &opts)
}

#[test]
fn external_cubic_equals_the_polynomial_law_at_h3() {
    let (k1, k3) = (0.8, 0.6);
    let poly = two_dof(0.0, vec![Contact::polynomial(1, Some(0), vec![k1, 0.0, k3])]);
    let ext = two_dof(0.0, vec![on_pair(cubic_external(k1, k3), 1, 1, Some(0))]);
    let mut worst = 0.0f64;
    for omega in [0.5, 0.9, 1.3, 1.6] {
        let (a, b) = (solve(&poly, 3, omega).unwrap(), solve(&ext, 3, omega).unwrap());
        let d = rel_diff(&a.outputs, &b.outputs);
        // the cubic must matter: the solution differs from the linear one (k3 = 0)
        let lin = solve(&two_dof(k1, vec![]), 3, omega).unwrap();
        let nl = rel_diff(&a.outputs, &lin.outputs);
        println!("w = {omega}: external vs polynomial {d:.2e}, polynomial vs linear {nl:.2e}");
        assert!(nl > 1e-3, "the cubic term has no effect at w = {omega}: {nl:.2e}");
        // outputs[k * 2 + j]: cos 3 is k = 5, sin 3 is k = 6
        assert!(a.outputs[5 * 2].hypot(a.outputs[6 * 2]) > 1e-8, "no third harmonic at w = {omega}");
        worst = worst.max(d);
    }
    assert!(worst < 1e-12, "external cubic vs Polynomial: {worst:.3e}");
}

#[test]
fn external_linear_spring_equals_the_spring_in_k() {
    let kc = 0.8;
    let ext = two_dof(0.0, vec![on_pair(cubic_external(kc, 0.0), 1, 1, Some(0))]);
    let lin = two_dof(kc, vec![]);
    for omega in [0.5, 0.9, 1.6] {
        let (a, b) = (solve(&ext, 3, omega).unwrap(), solve(&lin, 3, omega).unwrap());
        let d = rel_diff(&a.outputs, &b.outputs);
        println!("linear external at w = {omega}: rel. diff {d:.2e}");
        assert!(d < 1e-10, "{d:.3e}");
    }
}

fn force(plan: &AftPlan, law: &ContactLaw, w: &[f64]) -> Vec<f64> {
    let mut ws = plan.workspace();
    let mut f = vec![0.0; w.len()];
    plan.try_contact(law, w, &mut f, None, None, &mut ws).unwrap();
    f
}

/// A coupled, non-symmetric 3D memoryless law (a cubic spring per axis plus cross terms).
fn coupled_3d() -> ContactLaw {
    external(3, |w, f, j| {
        let (x, y, z) = (w[0], w[1], w[2]);
        f[0] = 2.0 * x + 0.5 * x.powi(3) + 0.3 * x * y;
        f[1] = 1.5 * y + 0.2 * y * z * z + 0.1 * x;
        f[2] = 3.0 * z + z.powi(3) - 0.4 * x * x;
        // column-major: j[r + 3 c] = dF_r / dw_c
        j[0] = 2.0 + 1.5 * x * x + 0.3 * y;
        j[1] = 0.1;
        j[2] = -0.8 * x;
        j[3] = 0.3 * x;
        j[4] = 1.5 + 0.2 * z * z;
        j[5] = 0.0;
        j[6] = 0.0;
        j[7] = 0.4 * y * z;
        j[8] = 3.0 + 3.0 * z * z;
        Ok(())
    })
}

#[test]
fn external_aft_jacobian_matches_finite_differences() {
    let laws = [(cubic_external(0.8, 0.6), "cubic 1D"), (coupled_3d(), "coupled 3D")];
    for backend in [AftBackend::Fft, AftBackend::Tables] {
        let h = if backend == AftBackend::Tables { 1 } else { 3 };
        let plan = AftPlan::with_backend(h, 64, backend).unwrap();
        for (law, name) in &laws {
            let d = law.dim();
            let nc = plan.n_coeffs();
            let n = d * nc;
            let w: Vec<f64> = (0..n).map(|i| 0.7 * ((i as f64 * 1.37).sin()) / (1 + i / d) as f64).collect();
            let mut f = vec![0.0; n];
            let mut jac = vec![0.0; n * n];
            let mut ws = plan.workspace();
            plan.try_contact(law, &w, &mut f, Some(&mut jac), None, &mut ws).unwrap();
            let step = 1e-6;
            let mut fd = vec![0.0; n * n];
            let mut wp = w.clone();
            for col in 0..n {
                wp[col] = w[col] + step;
                let fp = force(&plan, law, &wp);
                wp[col] = w[col] - step;
                let fm = force(&plan, law, &wp);
                wp[col] = w[col];
                for row in 0..n {
                    fd[row + col * n] = (fp[row] - fm[row]) / (2.0 * step);
                }
            }
            let e = rel_diff(&jac, &fd);
            let off_diag: f64 = (0..n).flat_map(|r| (0..n).map(move |c| (r, c))).filter(|(r, c)| r % d != c % d).map(|(r, c)| jac[r + c * n].abs()).sum();
            println!("{name}, {backend:?} H = {h}: |J - J_fd| / |J| = {e:.2e}, coupling mass {off_diag:.2e}");
            assert!(e < 1e-8, "{name} {backend:?}: {e:.3e}");
            if d == 3 {
                assert!(off_diag > 1e-3, "the coupled law's Jacobian has no coupling");
            }
        }
    }
}

#[test]
fn a_failing_callable_ends_the_solve_with_the_element_and_the_sample() {
    let calls = Arc::new(AtomicUsize::new(0));
    let counter = calls.clone();
    let law = external(1, move |w, f, j| {
        // call 1 is ExternalLaw::new's stuck stiffness at w = 0; the 5th fails
        if counter.fetch_add(1, Ordering::SeqCst) + 1 == 5 {
            return Err("the host law refused".into());
        }
        f[0] = 0.8 * w[0] + 0.6 * w[0].powi(3);
        j[0] = 0.8 + 1.8 * w[0] * w[0];
        Ok(())
    });
    // the failing element is contact 1 (contact 0 is a polynomial spring to ground)
    let model = two_dof(0.0, vec![Contact::polynomial(0, None, vec![0.1]), on_pair(law, 1, 1, Some(0))]);
    let err = solve(&model, 3, 0.9).expect_err("the callable's error must end the solve");
    println!("{err}");
    match &err {
        JpError::Callback { element, sample, reason } => {
            assert_eq!(element, "element 1");
            assert_eq!(*sample, 3, "the 5th call is sample 3 of the first evaluation");
            assert_eq!(reason, "the host law refused");
        }
        other => panic!("expected a Callback error, got {other:?}"),
    }
    assert_eq!(err.to_string(), "element 1: the host law refused at sample 3");
}

#[test]
fn a_panicking_or_non_finite_callable_is_reported_not_propagated() {
    let armed = Arc::new(AtomicUsize::new(0));
    let a2 = armed.clone();
    let panicking = external(1, move |w, f, j| {
        if a2.load(Ordering::SeqCst) == 1 && w[0].abs() > 1e-3 {
            panic!("host bug");
        }
        f[0] = w[0];
        j[0] = 1.0;
        Ok(())
    });
    armed.store(1, Ordering::SeqCst);
    let model = two_dof(0.0, vec![on_pair(panicking, 1, 1, Some(0))]);
    let err = solve(&model, 3, 0.9).expect_err("a panic inside the law must be an error");
    println!("{err}");
    assert!(matches!(&err, JpError::Callback { element, .. } if element == "element 0"), "{err:?}");
    assert!(err.to_string().contains("panicked (host bug)"), "{err}");

    let nan = external(1, |w, f, j| {
        f[0] = if w[0] > 1e-3 { f64::NAN } else { w[0] };
        j[0] = 1.0;
        Ok(())
    });
    let model = two_dof(0.0, vec![on_pair(nan, 1, 1, Some(0))]);
    let err = solve(&model, 3, 0.9).expect_err("a NaN force must be an error");
    println!("{err}");
    assert!(err.to_string().contains("non-finite force[0] = NaN"), "{err}");
}

#[test]
fn external_laws_are_checked_when_made_and_cannot_be_saved() {
    let f: Arc<ExternalFn> = Arc::new(|_w: &[f64], _f: &mut [f64], _j: &mut [f64]| Ok(()));
    assert!(matches!(ExternalLaw::new(0, f.clone()), Err(JpError::InvalidValue { .. })));
    assert!(matches!(ExternalLaw::new(4, f.clone()), Err(JpError::InvalidValue { .. })));
    let bad: Arc<ExternalFn> = Arc::new(|_w: &[f64], _f: &mut [f64], _j: &mut [f64]| Err("no".into()));
    let e = ExternalLaw::new(1, bad).unwrap_err();
    assert!(e.to_string().contains("at w = 0"), "{e}");

    // stuck stiffness: the Jacobian at w = 0, diagonal and full block
    let law = coupled_3d();
    assert_eq!(law.stuck_stiffness(), vec![2.0, 1.5, 3.0]);
    assert_eq!(law.stuck_stiffness_block(), vec![2.0, 0.1, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0, 3.0]);
    // equality by pointer
    let a = ContactLaw::External(ExternalLaw::new(1, f.clone()).unwrap());
    assert_eq!(a, a.clone());
    assert_ne!(a, ContactLaw::External(ExternalLaw::new(1, Arc::new(|_w: &[f64], _f: &mut [f64], _j: &mut [f64]| Ok(()))).unwrap()));

    let model = two_dof(0.0, vec![on_pair(cubic_external(1.0, 0.1), 1, 1, Some(0))]);
    let dir = std::env::temp_dir().join(format!("jprom_external_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("model.json");
    let e = model.save_json(&path).unwrap_err();
    println!("{e}");
    assert!(e.to_string().contains("cannot be saved"), "{e}");
    assert!(!path.exists(), "a model that cannot be saved must leave no file");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_sweep_that_meets_a_failing_callable_stops_with_its_error() {
    use jprom::hbm::{sweep, SweepOptions};
    use std::ops::ControlFlow;
    // fails once |w| > 0.5 (near the resonance of the 2-DoF system), fine below
    let law = external(1, |w, f, j| {
        if w[0].abs() > 0.5 {
            return Err("out of the host law's range".into());
        }
        f[0] = 0.8 * w[0] + 0.6 * w[0].powi(3);
        j[0] = 0.8 + 1.8 * w[0] * w[0];
        Ok(())
    });
    let model = two_dof(0.0, vec![on_pair(law, 1, 1, Some(0))]);
    let opts = HbmOptions::default();
    let sys = FullSystem::new(&model, 3).unwrap();
    let mut streamed = 0;
    let res = sweep(&sys, &SweepOptions::band(0.3, 2.0), &opts, &mut |_| {
        streamed += 1;
        ControlFlow::Continue(())
    });
    // the sweep ends with the law's own error (the C API's JPROM_CALLBACK_ERROR), not with a
    // stall that would hide it behind "step too small"; the points before it were streamed
    let e = res.expect_err("a failing law must end the sweep with its error");
    assert!(matches!(&e, JpError::Callback { element, .. } if element == "element 0"), "{e:?}");
    assert!(streamed > 0, "the points below the failure were delivered");
}
