//! How jprom's kernels use threads, and results that do not depend on the thread count.
//!
//! Every dense and sparse kernel of jprom (LU, Cholesky, Lanczos, eigen solves, products) takes
//! its parallelism from faer's global setting; the independent tasks above them (the JP
//! prediction's contact patterns, a study's units) run on rayon's pool. faer's parallel
//! kernels split their sums by thread count, so a result differs in round-off between one and
//! two threads, and the JP prediction's contact patterns, which switch between stick and slip
//! at thresholds, can change with that round-off: the demo on one thread and on two gave a
//! shared basis of [35, 14] from 78 patterns against [35, 13] from 76 (README,
//! "Reproducibility").
//!
//! [`set_reproducible`] runs every kernel on one thread (faer's `Par::Seq`); the tasks above
//! them still run in parallel and are collected in order, so the numbers are the same on any
//! thread count (tests/thread_count.rs). Process-wide, like the memory budget; C:
//! `jprom_set_reproducible`, the `jprom` program: `--reproducible`.

use faer::Par;

/// Runs every kernel on one thread (`true`), so that results do not depend on the thread
/// count, or restores faer's default, kernels on rayon's pool (`false`). Process-wide; takes
/// effect at the next kernel call.
pub fn set_reproducible(on: bool) {
    faer::set_global_parallelism(if on { Par::Seq } else { Par::rayon(0) });
}

/// Whether the kernels run on one thread ([`set_reproducible`]).
pub fn reproducible() -> bool {
    matches!(faer::get_global_parallelism(), Par::Seq)
}

/// The number of threads of the pool jprom's parallel tasks run on (rayon's current pool: the
/// global one, `RAYON_NUM_THREADS` or the machine's cores, unless called inside another).
pub fn threads() -> usize {
    rayon::current_num_threads()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_setting_round_trips_through_faer() {
        let before = reproducible();
        set_reproducible(true);
        assert!(reproducible() && matches!(faer::get_global_parallelism(), Par::Seq));
        set_reproducible(false);
        assert!(!reproducible() && matches!(faer::get_global_parallelism(), Par::Rayon(_)));
        set_reproducible(before);
    }
}
