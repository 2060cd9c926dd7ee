//! The analytical AFT Jacobian against central finite differences, the global layout of
//! `evaluate_contacts`, the linear (full stick) limit, and the two transform backends.

use jprom::aft::{evaluate_contacts, evaluate_contacts_with, AftBackend, AftPlan, ContactCycle, ContactForces, Threading};
use jprom::contact::{ContactLaw, ContactState};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn law3d() -> ContactLaw {
    ContactLaw::Friction3D { kt1: 1.0, kt2: 0.7, kn: 1.5, mu: 0.4, n0: 1.0 }
}

fn force(plan: &AftPlan, law: &ContactLaw, w: &[f64]) -> Vec<f64> {
    let mut ws = plan.workspace();
    let mut f = vec![0.0; w.len()];
    plan.contact(law, w, &mut f, None, None, &mut ws);
    f
}

/// Central-difference Jacobian, column-major.
fn fd_jacobian(plan: &AftPlan, law: &ContactLaw, w: &[f64], h: f64) -> Vec<f64> {
    let n = w.len();
    let mut jac = vec![0.0; n * n];
    let mut wp = w.to_vec();
    for col in 0..n {
        wp[col] = w[col] + h;
        let fp = force(plan, law, &wp);
        wp[col] = w[col] - h;
        let fm = force(plan, law, &wp);
        wp[col] = w[col];
        for row in 0..n {
            jac[row + col * n] = (fp[row] - fm[row]) / (2.0 * h);
        }
    }
    jac
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    let den: f64 = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    num / den.max(1e-300)
}

/// Random harmonics for a 3D contact: static normal offset and tangential/normal amplitudes
/// drawn so that stick, slip and separation all occur across the sample.
fn random_w3(rng: &mut StdRng, h: usize) -> Vec<f64> {
    let nc = 2 * h + 1;
    let mut w = vec![0.0; 3 * nc];
    let amp_t = rng.gen_range(0.05..2.0);
    let amp_n = rng.gen_range(0.0..1.2);
    w[0] = rng.gen_range(-0.5..0.5);
    w[1] = rng.gen_range(-0.5..0.5);
    w[2] = rng.gen_range(-0.3..0.5);
    for k in 1..nc {
        let decay = 1.0 / ((k + 1) / 2) as f64;
        w[k * 3] = amp_t * decay * rng.gen_range(-1.0..1.0);
        w[k * 3 + 1] = amp_t * decay * rng.gen_range(-1.0..1.0);
        w[k * 3 + 2] = amp_n * decay * rng.gen_range(-1.0..1.0);
    }
    w
}

/// Compares analytical and FD Jacobians on random states; returns (accepted, worst error,
/// states seen).
fn check_random(law: &ContactLaw, h: usize, nt: usize, backend: AftBackend, draws: usize, seed: u64) -> (usize, f64, [bool; 3]) {
    let plan = AftPlan::with_backend(h, nt, backend).unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let mut ws = plan.workspace();
    let n = law.dim() * plan.n_coeffs();
    let (mut accepted, mut worst, mut seen) = (0, 0.0f64, [false; 3]);
    for _ in 0..draws {
        let w = match law.dim() {
            3 => random_w3(&mut rng, h),
            _ => (0..n).map(|k| if k == 0 { rng.gen_range(-0.5..0.5) } else { rng.gen_range(-2.0..2.0) / ((k + 1) / 2) as f64 }).collect(),
        };
        let mut f = vec![0.0; n];
        let mut jac = vec![0.0; n * n];
        let mut cycle = ContactCycle::default();
        plan.contact(law, &w, &mut f, Some(&mut jac), Some(&mut cycle), &mut ws);
        let scale = w.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let j1 = fd_jacobian(&plan, law, &w, 1e-7 * scale);
        let j2 = fd_jacobian(&plan, law, &w, 2e-7 * scale);
        // Reject draws where the FD itself is not smooth (a sample at a stick/slip transition).
        if rel_diff(&j1, &j2) > 1e-7 {
            continue;
        }
        accepted += 1;
        worst = worst.max(rel_diff(&jac, &j1));
        for s in &cycle.states {
            seen[*s as usize] = true;
        }
    }
    (accepted, worst, seen)
}

#[test]
fn jacobian_3d_matches_finite_differences_h1_h3_h5() {
    for (h, nt) in [(1, 64), (3, 64), (5, 128)] {
        let (accepted, worst, seen) = check_random(&law3d(), h, nt, AftBackend::Auto, 40, 11 + h as u64);
        println!("3D  H={h} Nt={nt}: accepted {accepted}/40, worst rel. error {worst:.2e}, states stick/slip/sep {seen:?}");
        assert!(accepted >= 25, "too few smooth draws: {accepted}");
        assert!(seen.iter().all(|&s| s), "sample must contain stick, slip and separation: {seen:?}");
        assert!(worst < 1e-6, "H={h}: analytical vs FD rel. error {worst:.3e}");
    }
}

#[test]
fn jacobian_3d_fft_backend_matches_finite_differences() {
    let (accepted, worst, seen) = check_random(&law3d(), 3, 64, AftBackend::Fft, 20, 5);
    println!("3D FFT H=3: accepted {accepted}/20, worst {worst:.2e}");
    assert!(accepted >= 12 && seen.iter().all(|&s| s));
    assert!(worst < 1e-6, "{worst:.3e}");
}

#[test]
fn jacobian_3d_frictionless_and_anisotropic() {
    let frictionless = ContactLaw::Friction3D { kt1: 1.0, kt2: 0.7, kn: 1.5, mu: 0.0, n0: 1.0 };
    let (accepted, worst, _) = check_random(&frictionless, 3, 64, AftBackend::Auto, 15, 21);
    println!("mu = 0: accepted {accepted}/15, worst {worst:.2e}");
    assert!(accepted >= 10 && worst < 1e-6, "{worst:.3e}");
    // mu = 0: no tangential force at all.
    let plan = AftPlan::new(3, 64).unwrap();
    let mut rng = StdRng::seed_from_u64(3);
    let f = force(&plan, &frictionless, &random_w3(&mut rng, 3));
    for k in 0..7 {
        assert!(f[k * 3].abs() < 1e-14 && f[k * 3 + 1].abs() < 1e-14);
    }
}

#[test]
fn jacobian_jenkins_matches_finite_differences() {
    let law = ContactLaw::Jenkins { kt: 1.3, mu: 0.5, normal_load: 1.0 };
    for (h, nt) in [(1, 64), (3, 64), (5, 128)] {
        for backend in [AftBackend::Tables, AftBackend::Fft] {
            let (accepted, worst, seen) = check_random(&law, h, nt, backend, 30, 7 + h as u64);
            println!("Jenkins H={h} {backend:?}: accepted {accepted}/30, worst {worst:.2e}, seen {seen:?}");
            assert!(accepted >= 20 && seen[0] && seen[1]);
            assert!(worst < 1e-6, "{worst:.3e}");
        }
    }
}

#[test]
fn backends_agree() {
    let mut rng = StdRng::seed_from_u64(99);
    for h in [1, 3, 5] {
        let nt = 64;
        let a = AftPlan::with_backend(h, nt, AftBackend::Tables).unwrap();
        let b = AftPlan::with_backend(h, nt, AftBackend::Fft).unwrap();
        assert!(!a.uses_fft() && b.uses_fft());
        let (mut wa, mut wb) = (a.workspace(), b.workspace());
        for _ in 0..10 {
            let w = random_w3(&mut rng, h);
            let n = w.len();
            let (mut fa, mut fb) = (vec![0.0; n], vec![0.0; n]);
            let (mut ja, mut jb) = (vec![0.0; n * n], vec![0.0; n * n]);
            a.contact(&law3d(), &w, &mut fa, Some(&mut ja), None, &mut wa);
            b.contact(&law3d(), &w, &mut fb, Some(&mut jb), None, &mut wb);
            assert!(rel_diff(&fb, &fa) < 1e-12, "force {:.2e}", rel_diff(&fb, &fa));
            assert!(rel_diff(&jb, &ja) < 1e-12, "jac {:.2e}", rel_diff(&jb, &ja));
        }
    }
}

#[test]
fn full_stick_is_exactly_linear() {
    // mu huge, preload large, small motion: F = K w coefficient by coefficient.
    let (kt1, kt2, kn) = (2.0, 3.0, 5.0);
    let law = ContactLaw::Friction3D { kt1, kt2, kn, mu: 1e6, n0: 100.0 };
    let mut rng = StdRng::seed_from_u64(1);
    for backend in [AftBackend::Tables, AftBackend::Fft] {
        for h in [1, 3] {
            let plan = AftPlan::with_backend(h, 32, backend).unwrap();
            let mut ws = plan.workspace();
            let nc = plan.n_coeffs();
            let n = 3 * nc;
            let w: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let mut f = vec![0.0; n];
            let mut jac = vec![0.0; n * n];
            let mut cycle = ContactCycle::default();
            plan.contact(&law, &w, &mut f, Some(&mut jac), Some(&mut cycle), &mut ws);
            assert!(cycle.states.iter().all(|&s| s == ContactState::Stick));
            assert!(cycle.dissipated_energy.abs() < 1e-12, "W = {}", cycle.dissipated_energy);
            let k = [kt1, kt2, kn];
            for row in 0..n {
                let i = row % 3;
                let mut expect = k[i] * w[row];
                if row == 2 {
                    expect += 100.0; // preload in the static normal force
                }
                assert!((f[row] - expect).abs() < 1e-11 * (1.0 + expect.abs()), "{backend:?} F[{row}] {} vs {expect}", f[row]);
                for col in 0..n {
                    let expect = if row == col { k[i] } else { 0.0 };
                    assert!((jac[row + col * n] - expect).abs() < 1e-11, "{backend:?} J[{row},{col}] = {}", jac[row + col * n]);
                }
            }
        }
    }
}

#[test]
fn plan_rejects_bad_sizes() {
    assert!(AftPlan::new(0, 64).is_err());
    assert!(AftPlan::new(3, 15).is_err()); // < 4 (H + 1) = 16
    assert!(AftPlan::new(3, 24).is_err()); // not a power of two
    assert!(AftPlan::new(3, 16).is_ok());
}

/// Global harmonic-major layout: contacts scattered in `w` (3D, Jenkins, 3D node pair's
/// relative coordinate), forces and blocks against per-contact calls, and the assembled
/// global Jacobian against FD of the global force.
#[test]
fn evaluate_contacts_layout_and_global_jacobian() {
    let h = 3;
    let plan = AftPlan::new(h, 64).unwrap();
    let nc = plan.n_coeffs();
    let laws = vec![
        law3d(),
        ContactLaw::Jenkins { kt: 1.3, mu: 0.5, normal_load: 1.0 },
        ContactLaw::Friction3D { kt1: 0.5, kt2: 0.9, kn: 2.0, mu: 0.2, n0: 0.3 },
    ];
    let offsets = vec![4, 0, 1]; // n_w = 7, contacts not in order
    let n_w = 7;
    let mut rng = StdRng::seed_from_u64(42);
    let w0 = random_w3(&mut rng, h);
    let w2 = random_w3(&mut rng, h);
    let wj: Vec<f64> = (0..nc).map(|_| rng.gen_range(-1.5..1.5)).collect();
    let mut w_all = vec![0.0; nc * n_w];
    for k in 0..nc {
        for i in 0..3 {
            w_all[k * n_w + 4 + i] = w0[k * 3 + i];
            w_all[k * n_w + 1 + i] = w2[k * 3 + i];
        }
        w_all[k * n_w] = wj[k];
    }
    let mut out = ContactForces::default();
    evaluate_contacts(&plan, &laws, &offsets, n_w, &w_all, true, true, &mut out);
    assert_eq!(out.cycles.len(), 3);
    // Per-contact references.
    let locals = [w0.clone(), wj.clone(), w2.clone()];
    let mut ws = plan.workspace();
    for (c, law) in laws.iter().enumerate() {
        let d = law.dim();
        let n = d * nc;
        let mut f = vec![0.0; n];
        let mut jac = vec![0.0; n * n];
        plan.contact(law, &locals[c], &mut f, Some(&mut jac), None, &mut ws);
        for k in 0..nc {
            for i in 0..d {
                assert_eq!(out.force[k * n_w + offsets[c] + i], f[k * d + i]);
            }
        }
        assert_eq!(&out.jac[out.jac_offsets[c]..out.jac_offsets[c] + n * n], &jac[..]);
    }
    // Global dense Jacobian from the blocks vs FD of the global force.
    let ng = nc * n_w;
    let mut jg = vec![0.0; ng * ng];
    for (c, law) in laws.iter().enumerate() {
        let d = law.dim();
        let n = d * nc;
        let glob = |l: usize| (l / d) * n_w + offsets[c] + l % d;
        for col in 0..n {
            for row in 0..n {
                jg[glob(row) + glob(col) * ng] = out.jac[out.jac_offsets[c] + row + col * n];
            }
        }
    }
    let mut fd = vec![0.0; ng * ng];
    let mut tmp = ContactForces::default();
    let mut wp = w_all.clone();
    let step = 1e-7;
    for col in 0..ng {
        wp[col] = w_all[col] + step;
        evaluate_contacts(&plan, &laws, &offsets, n_w, &wp, false, false, &mut tmp);
        let fp = tmp.force.clone();
        wp[col] = w_all[col] - step;
        evaluate_contacts(&plan, &laws, &offsets, n_w, &wp, false, false, &mut tmp);
        wp[col] = w_all[col];
        for row in 0..ng {
            fd[row + col * ng] = (fp[row] - tmp.force[row]) / (2.0 * step);
        }
    }
    let err = rel_diff(&jg, &fd);
    println!("global Jacobian vs FD: {err:.2e}");
    assert!(err < 1e-6, "{err:.3e}");
}

/// Many contacts: the rayon path gives exactly the sequential result, and a reused
/// `ContactForces` keeps its buffers.
#[test]
fn parallel_matches_sequential() {
    let h = 1;
    let plan = AftPlan::new(h, 64).unwrap();
    let nc = plan.n_coeffs();
    let n_contacts = 200;
    let laws: Vec<ContactLaw> = (0..n_contacts)
        .map(|c| if c % 7 == 3 { ContactLaw::Jenkins { kt: 1.0, mu: 0.3, normal_load: 1.0 } } else { law3d() })
        .collect();
    let mut offsets = Vec::new();
    let mut n_w = 0;
    for l in &laws {
        offsets.push(n_w);
        n_w += l.dim();
    }
    let mut rng = StdRng::seed_from_u64(8);
    let w_all: Vec<f64> = (0..nc * n_w).map(|_| rng.gen_range(-1.0..1.0)).collect();
    let mut seq = ContactForces::default();
    let mut par = ContactForces::default();
    evaluate_contacts_with(&plan, &laws, &offsets, n_w, &w_all, true, true, &mut seq, Threading::Sequential);
    evaluate_contacts_with(&plan, &laws, &offsets, n_w, &w_all, true, true, &mut par, Threading::Auto);
    assert_eq!(seq.force, par.force);
    assert_eq!(seq.jac, par.jac);
    assert_eq!(seq.cycles, par.cycles);
    let ptr = par.jac.as_ptr();
    evaluate_contacts_with(&plan, &laws, &offsets, n_w, &w_all, true, true, &mut par, Threading::Auto);
    assert_eq!(ptr, par.jac.as_ptr(), "reused output must not reallocate");
    assert_eq!(seq.jac, par.jac);
}
