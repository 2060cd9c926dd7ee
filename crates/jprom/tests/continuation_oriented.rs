//! The decisions of the oriented continuation (docs/formulation.md §6) on constructed branches:
//! a smooth fold pair (Duffing, H = 5) crossed both ways with the folds located to 1e-6 in
//! frequency against a fine continuation; corners where a contact changes state (stick-slip
//! onset of a Jenkins oscillator, separation of a unilateral spring), crossed without a gap and
//! checked point by point; and a branch point (two identical Duffing oscillators coupled by a
//! soft spring and forced alike: the in-phase branch meets the out-of-phase one where the
//! antisymmetric block of the Jacobian is singular), located, checked against that block and
//! crossed.

use faer::Mat;
use jprom::contact::{Contact, ContactState};
use jprom::hbm::residual::{evaluate, ResidualWorkspace};
use jprom::hbm::{solve_point, sweep, ContinuationMethod, EventKind, FullSystem, HarmonicSystem, HbmOptions, PointSolution, SweepOptions, SweepResult};
use jprom::model::{Damping, Excitation, HarmonicForce, Model};
use std::ops::ControlFlow;

fn run(system: &dyn HarmonicSystem, sopts: &SweepOptions) -> SweepResult {
    let r = sweep(system, sopts, &HbmOptions::default(), &mut |_| ControlFlow::Continue(())).unwrap();
    assert!(r.reached_end(), "ended with {:?}: {:?}", r.end, r.failure);
    assert!(r.gaps.is_empty(), "gaps {:?}", r.gaps);
    assert_eq!(sopts.method, ContinuationMethod::Oriented);
    r
}

fn amplitude(p: &PointSolution) -> f64 {
    p.output_amplitude(1, 0)
}

fn relative(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt() / b.iter().map(|y| y * y).sum::<f64>().sqrt()
}

/// Every point of `r` away from its folds is a solution that Newton at its frequency, from
/// the point itself moved by 1e-3, comes back to (so the sweep's points are the equations'
/// solutions, not the corrector's artefacts).
fn points_are_solutions(system: &dyn HarmonicSystem, r: &SweepResult) {
    let hopts = HbmOptions::default();
    for p in r.points.iter().filter(|p| r.folds.iter().all(|f| (f - p.omega).abs() > 1e-4 * p.omega)) {
        let guess: Vec<f64> = p.z.iter().map(|v| v * 1.001).collect();
        let q = solve_point(system, p.omega, Some(&guess), &hopts).unwrap();
        assert!(relative(&q.z, &p.z) < 1e-7, "omega {}: {}", p.omega, relative(&q.z, &p.z));
    }
}

/// Unit masses on unit springs to ground with a cubic spring `alpha` each, viscous damping
/// `c`, forced alike by `f` (cos), coupled in a chain by `kc`.
fn duffings(count: usize, alpha: f64, c: f64, f: f64, kc: f64) -> Model {
    let mut k = Mat::<f64>::identity(count, count);
    for i in 0..count.saturating_sub(1) {
        k[(i, i)] += kc;
        k[(i + 1, i + 1)] += kc;
        k[(i, i + 1)] -= kc;
        k[(i + 1, i)] -= kc;
    }
    let exc = Excitation { static_force: vec![0.0; count], harmonics: vec![HarmonicForce { cos: vec![f; count], sin: vec![0.0; count] }], dynamic_scale: 1.0 };
    let contacts = (0..count).map(|i| Contact::polynomial(i, None, vec![0.0, 0.0, alpha])).collect();
    Model::new(Mat::identity(count, count), k, Damping { mass_coeff: c, stiffness_coeff: 0.0 }, exc, contacts, (0..count).collect()).unwrap()
}

/// The fold's frequency from a fine sweep: the extremum of the parabola through the three
/// points around the point of extreme frequency next to `near`.
fn fine_fold(fine: &SweepResult, near: f64) -> f64 {
    let w: Vec<f64> = fine.points.iter().map(|p| p.omega).collect();
    let i = (1..w.len() - 1)
        .filter(|&i| (w[i] - w[i - 1]) * (w[i + 1] - w[i]) <= 0.0)
        .min_by(|&a, &b| (w[a] - near).abs().total_cmp(&(w[b] - near).abs()))
        .expect("a turn in frequency");
    // omega against arclength (chord lengths in (omega, amplitude) of the fine sweep)
    let s = |j: usize| -> f64 {
        (i.min(j)..i.max(j)).map(|k| (w[k + 1] - w[k]).hypot(amplitude(&fine.points[k + 1]) - amplitude(&fine.points[k]))).sum::<f64>() * if j < i { -1.0 } else { 1.0 }
    };
    let (s0, s1, s2) = (s(i - 1), 0.0, s(i + 1));
    let (w0, w1, w2) = (w[i - 1], w[i], w[i + 1]);
    // w = a s^2 + b s + c through the three points; the extremum is c - b^2 / 4a
    let a = ((w2 - w1) / (s2 - s1) - (w1 - w0) / (s1 - s0)) / (s2 - s0);
    let b = (w1 - w0) / (s1 - s0) - a * (s1 + s0);
    w1 - b * b / (4.0 * a)
}

/// A hardening Duffing at H = 5 with a fold pair near its resonance: swept up and down at the
/// default steps, each sweep reports both folds, located to 1e-6 of the frequency against a
/// fine sweep, and the frequency turns back only there.
#[test]
fn smooth_folds_are_crossed_both_ways_and_located() {
    let model = duffings(1, 0.5, 0.05, 0.3, 0.0);
    let system = FullSystem::new(&model, 5).unwrap();
    let up = run(&system, &SweepOptions::band(0.6, 2.6));
    let down = run(&system, &SweepOptions::band(2.6, 0.6));
    let fine = run(&system, &SweepOptions { max_step: 2e-3, initial_step: 1e-3, max_points: 100_000, ..SweepOptions::band(0.6, 2.6) });
    for r in [&up, &down] {
        let folds: Vec<f64> = r.events.iter().filter(|e| e.kind == EventKind::Fold).map(|e| e.omega).collect();
        assert_eq!(folds.len(), 2, "folds {folds:?}");
        assert_eq!(folds, r.folds);
        for &f in &folds {
            let reference = fine_fold(&fine, f);
            assert!((f - reference).abs() < 1e-6 * reference, "fold at {f}, fine continuation {reference}");
        }
        // the frequency changes direction only at the folds
        let dw: Vec<f64> = r.points.windows(2).map(|p| p[1].omega - p[0].omega).collect();
        assert_eq!(dw.windows(2).filter(|d| d[0] * d[1] < 0.0).count(), 2);
        points_are_solutions(&system, r);
    }
    // the same two folds from either side
    let (mut a, mut b) = (up.folds.clone(), down.folds.clone());
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1e-6 * x, "up {a:?} down {b:?}");
    }
}

/// An SDOF Jenkins oscillator through its resonance: the contact sticks at the band's ends and
/// slips around the peak, so the branch has a corner at each onset of slip. The sweep takes
/// them without a gap, with points on both sides, every point a solution.
#[test]
fn stick_slip_corners_are_crossed() {
    let exc = Excitation { static_force: vec![0.0], harmonics: vec![HarmonicForce { cos: vec![0.05], sin: vec![0.0] }], dynamic_scale: 1.0 };
    let model = Model::new(Mat::identity(1, 1), Mat::identity(1, 1), Damping { mass_coeff: 0.0, stiffness_coeff: 0.01 }, exc, vec![Contact::jenkins(0, None, 1.0, 1.0, 0.1)], vec![0]).unwrap();
    let system = FullSystem::new(&model, jprom::hbm::Discretisation::with_nt(3, 256)).unwrap();
    let r = run(&system, &SweepOptions::band(0.8, 2.0));
    let slips = |p: &PointSolution| p.contact_cycles[0].states.contains(&ContactState::Slip);
    let changes = r.points.windows(2).filter(|w| slips(&w[0]) != slips(&w[1])).count();
    assert!(!slips(&r.points[0]) && !slips(r.points.last().unwrap()), "sticks at both ends of the band");
    assert_eq!(changes, 2, "slip starts and ends once");
    assert!(r.points.iter().filter(|p| slips(p)).count() >= 10);
    points_are_solutions(&system, &r);
}

/// A mass whose unilateral spring opens around resonance (a preloaded contact that lifts off):
/// corners at separation and re-closing, crossed without a gap.
#[test]
fn separation_corners_are_crossed() {
    let exc = Excitation { static_force: vec![0.0], harmonics: vec![HarmonicForce { cos: vec![0.1], sin: vec![0.0] }], dynamic_scale: 1.0 };
    let model = Model::new(Mat::identity(1, 1), Mat::identity(1, 1), Damping { mass_coeff: 0.0, stiffness_coeff: 0.02 }, exc, vec![Contact::unilateral(0, None, 2.0, 0.4)], vec![0]).unwrap();
    let system = FullSystem::new(&model, jprom::hbm::Discretisation::with_nt(5, 512)).unwrap();
    let r = run(&system, &SweepOptions::band(0.8, 2.4));
    let opens = |p: &PointSolution| p.contact_cycles[0].states.contains(&ContactState::Separated);
    assert!(!opens(&r.points[0]) && !opens(r.points.last().unwrap()));
    assert!(r.points.iter().filter(|p| opens(p)).count() >= 10, "the contact separates around the peak");
    points_are_solutions(&system, &r);
}

/// Two identical hardening Duffing oscillators, coupled by a soft spring and forced alike:
/// from rest the sweep follows the in-phase branch, on which the antisymmetric part of the
/// Jacobian (the single oscillator's Jacobian plus `2 kc` on every displacement) is singular at
/// branch points (symmetry breaking). The sweep reports them, located where that block is
/// singular, and goes on along the in-phase branch (`x1 = x2` at every point) to the end.
#[test]
fn branch_points_are_located_and_crossed() {
    let (alpha, c, f, kc) = (0.5, 0.05, 0.3, 0.02);
    let pair = FullSystem::new(&duffings(2, alpha, c, f, kc), 3).unwrap();
    let single = FullSystem::new(&duffings(1, alpha, c, f, 0.0), 3).unwrap();
    let r = run(&pair, &SweepOptions::band(0.6, 2.6));
    let bps: Vec<_> = r.events.iter().filter(|e| e.kind == EventKind::BranchPoint).collect();
    assert!(!bps.is_empty(), "no branch point found; events {:?}", r.events);
    for p in &r.points {
        let n = p.layout.sizes[0];
        for k in 0..p.z.len() / n {
            assert!((p.z[k * n] - p.z[k * n + 1]).abs() <= 1e-8 * p.z.iter().map(|v| v.abs()).fold(0.0, f64::max), "left the in-phase branch at {}", p.omega);
        }
    }
    // at each located branch point the antisymmetric block J_1 + 2 kc I is singular: its
    // smallest singular value relative to its largest, against the same away from it
    let antisymmetric_conditioning = |omega: f64, z1: &[f64]| -> f64 {
        let lin = single.linear_part(omega).unwrap();
        let plan = single.discretisation().plan().unwrap();
        let (_, j) = evaluate(&single, &lin, Some(&plan), z1, true, &mut ResidualWorkspace::new()).unwrap();
        let mut j = j.unwrap().to_dense();
        for i in 0..j.nrows() {
            j[(i, i)] += 2.0 * kc;
        }
        let s = j.singular_values().unwrap();
        s[s.len() - 1] / s[0]
    };
    // the in-phase branch is the single oscillator's: the same folds, also where a fold and a
    // branch point fall within one step
    let folds = |r: &SweepResult| -> Vec<f64> { r.events.iter().filter(|e| e.kind == EventKind::Fold).map(|e| e.omega).collect() };
    let (pair_folds, single_folds) = (folds(&r), folds(&run(&single, &SweepOptions::band(0.6, 2.6))));
    assert_eq!(pair_folds.len(), single_folds.len(), "folds {pair_folds:?} vs {single_folds:?}");
    for (a, b) in pair_folds.iter().zip(&single_folds) {
        assert!((a - b).abs() < 1e-6 * b, "folds {pair_folds:?} vs the single oscillator's {single_folds:?}");
    }
    let hopts = HbmOptions::default();
    for bp in &bps {
        assert!(bp.omega_tolerance < 1e-8 * bp.omega, "bracket {}", bp.omega_tolerance);
        // the in-phase solution there (one oscillator's unknowns), solved from the points on
        // either side: the one with the event's amplitude (near a fold there are two)
        let in_phase = |p: &jprom::hbm::PointSolution| -> Vec<f64> {
            let n = p.layout.sizes[0];
            (0..p.z.len() / n).map(|k| p.z[k * n]).collect()
        };
        let near = &r.points[bp.after_point];
        let z1 = in_phase(near);
        let p = [near, &r.points[bp.after_point + 1]]
            .iter()
            .filter_map(|q| solve_point(&single, bp.omega, Some(&in_phase(q)), &hopts).ok())
            .min_by(|a, b| (a.output_amplitude(1, 0) - bp.amplitude).abs().total_cmp(&(b.output_amplitude(1, 0) - bp.amplitude).abs()))
            .unwrap();
        assert!((p.output_amplitude(1, 0) - bp.amplitude).abs() < 1e-4 * bp.amplitude, "amplitude {} vs the event's {}", p.output_amplitude(1, 0), bp.amplitude);
        let at = antisymmetric_conditioning(bp.omega, &p.z);
        let away = antisymmetric_conditioning(near.omega, &z1);
        assert!(at < 1e-5 && at < 1e-2 * away, "branch point at {}: conditioning {at:e} (at the point before it {away:e})", bp.omega);
    }
}

