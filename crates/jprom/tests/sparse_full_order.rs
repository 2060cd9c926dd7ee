//! The sparse full-order path (issue 18): a full-order system of a sparse model keeps its linear
//! part and its HBM Jacobian sparse and factorises it with a sparse LU. Checked against the
//! dense path on the same models (points and whole sweeps, stick to gross slip, a chain with
//! 'b' DoFs), and the automatic choice of storage by size and fill.

use faer::Mat;
use jprom::hbm::{solve_point, sweep, FullSystem, HbmOptions, PointSolution, Storage, SweepOptions};
use jprom::model::Model;
use std::ops::ControlFlow;

fn chain(n: usize, slip: f64, force: f64, relative: bool) -> Model {
    jprom_testkit::chain::jenkins_chain(n, slip, force, relative)
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().chain(b).fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

fn point(sys: &FullSystem, omega: f64, opts: &HbmOptions) -> PointSolution {
    solve_point(sys, omega, None, opts).unwrap_or_else(|e| panic!("{:?} at omega = {omega}: {e}", sys.storage()))
}

#[test]
fn sparse_and_dense_points_agree_from_stuck_to_gross_slip() {
    for relative in [false, true] {
        for (slip, label) in [(10.0, "stuck"), (0.05, "partial slip"), (0.002, "gross slip")] {
            let model = chain(12, slip, 0.1, relative);
            let opts = HbmOptions::default();
            let dense = FullSystem::with_storage(&model, 3, Storage::Dense).unwrap();
            let sparse = FullSystem::with_storage(&model, 3, Storage::Sparse).unwrap();
            assert_eq!((dense.storage(), sparse.storage()), (Storage::Dense, Storage::Sparse));
            for omega in [0.3, 0.75, 1.4] {
                let (a, b) = (point(&dense, omega, &opts), point(&sparse, omega, &opts));
                let e = max_rel(&a.z, &b.z);
                assert!(e < 1e-9, "{label} (relative {relative}) at omega = {omega}: z differs by {e:.2e}");
                let (ea, eb): (f64, f64) = (
                    a.contact_cycles.iter().map(|c| c.dissipated_energy).sum(),
                    b.contact_cycles.iter().map(|c| c.dissipated_energy).sum(),
                );
                assert!((ea - eb).abs() <= 1e-9 * ea.abs().max(1e-12), "{label}: energy {ea} vs {eb}");
                if label == "gross slip" {
                    assert!(ea > 0.0, "gross slip dissipates energy");
                }
            }
        }
    }
}

#[test]
fn a_sparse_sweep_lies_on_the_dense_branch() {
    // step control reacts to round-off, so the two storages need not take the same steps:
    // the sparse sweep's points are checked by dense solves started from them
    let model = chain(8, 0.02, 0.1, false);
    let opts = HbmOptions::default();
    let sopts = SweepOptions { omega_start: 0.4, omega_end: 1.0, ..Default::default() };
    let sparse = FullSystem::with_storage(&model, 3, Storage::Sparse).unwrap();
    let dense = FullSystem::with_storage(&model, 3, Storage::Dense).unwrap();
    let res = sweep(&sparse, &sopts, &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    assert!(!res.stopped_early, "{:?}", res.failure);
    let last = res.points.last().unwrap().omega;
    assert!((last - 1.0).abs() < 1e-9, "ends at {last}");
    let stride = (res.points.len() / 12).max(1);
    for p in res.points.iter().step_by(stride) {
        let q = solve_point(&dense, p.omega, Some(&p.z), &opts).unwrap();
        let e = max_rel(&p.outputs, &q.outputs);
        assert!(e < 1e-7, "outputs at omega = {} differ by {e:.2e}", p.omega);
    }
}

#[test]
fn automatic_storage_follows_size_and_fill() {
    // 11 x 20 = 220 unknowns: small, dense
    assert_eq!(FullSystem::new(&chain(20, 0.05, 0.1, false), 5).unwrap().storage(), Storage::Dense);
    // 11 x 200 = 2,200 unknowns, K/M/C fill 1.5 %: sparse
    assert_eq!(FullSystem::new(&chain(200, 0.05, 0.1, false), 5).unwrap().storage(), Storage::Sparse);
    // the relative chain's coordinates couple every mass to all below it: T^T K T is full
    assert_eq!(FullSystem::new(&chain(200, 0.05, 0.1, true), 5).unwrap().storage(), Storage::Dense);
    // a large model with a dense stiffness stays dense
    let n = 120;
    let mut model = chain(n, 0.05, 0.1, false);
    model.stiffness = Mat::from_fn(n, n, |i, j| if i == j { 2.0 * n as f64 } else { 0.5 / (1.0 + i.abs_diff(j) as f64) });
    model.validate().unwrap();
    assert_eq!(FullSystem::new(&model, 5).unwrap().storage(), Storage::Dense);
}

#[test]
fn a_large_sparse_chain_solves_and_matches_the_dense_path() {
    // 11 x 150 = 1,650 unknowns: automatic storage is sparse; the dense path is the reference
    let model = chain(150, 0.05, 0.1, false);
    let opts = HbmOptions::default();
    let sparse = FullSystem::new(&model, 5).unwrap();
    assert_eq!(sparse.storage(), Storage::Sparse);
    let dense = FullSystem::with_storage(&model, 5, Storage::Dense).unwrap();
    let (a, b) = (point(&dense, 0.75, &opts), point(&sparse, 0.75, &opts));
    let e = max_rel(&a.z, &b.z);
    assert!(e < 1e-9, "z differs by {e:.2e}");
    assert!(b.contact_cycles.iter().any(|c| c.dissipated_energy > 0.0), "some contacts slip at this level");
}
