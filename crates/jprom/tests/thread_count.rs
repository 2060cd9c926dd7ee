//! Reproducibility across thread counts (README, "Reproducibility"). faer's parallel kernels
//! round differently on different thread counts, and the JP prediction's contact patterns can
//! change with round-off (the demo on one thread and on two: shared basis [35, 14] from 78
//! patterns vs [35, 13] from 76). jprom's numerics take their parallelism from faer's global
//! setting, so with `jprom::parallelism::set_reproducible(true)` (faer's `Par::Seq`) they do
//! not depend on rayon's thread count: the patterns still run in parallel, each solve on one
//! thread.
//!
//! One test in its own binary: it sets the process-wide setting.

use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::ContactCoordinates;
use jprom_testkit::blade::Blade;

#[test]
fn with_sequential_kernels_the_model_and_basis_do_not_depend_on_the_thread_count() {
    jprom::parallelism::set_reproducible(true);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            // Craig-Bampton of the blade, then the stuck-mode prediction at a partial-slip level
            let blade = Blade::build();
            let model = blade.at_level(blade.alpha_st / 20.0);
            let coords = ContactCoordinates::new(&model, 1).unwrap();
            let (basis, report) = predict_basis(&coords, &PredictionOptions::new(blade.band)).unwrap();
            ((blade.omega_stuck, blade.alpha_st), basis, report.n_patterns)
        })
    };
    let (f1, b1, p1) = run(1);
    let (f2, b2, p2) = run(2);
    assert_eq!(f1, f2, "stuck resonance of the Craig-Bampton model and alpha_ST, bit for bit");
    assert_eq!((b1.sizes.clone(), p1), (b2.sizes.clone(), p2), "sizes and patterns");
    for (a, b) in b1.phi.iter().zip(&b2.phi) {
        assert!(a == b, "the basis, bit for bit");
    }
    println!("1 and 2 threads: sizes {:?}, {} patterns, the same bits", b1.sizes, p1);
}
