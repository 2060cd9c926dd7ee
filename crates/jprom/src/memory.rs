//! The memory budget: one process-wide ceiling on what a single allocation driven by outside
//! input may take. Sizes that come from callers or files (C arguments, options, JSON and
//! Matrix Market files, study files) are turned into a byte estimate with overflow-checked
//! arithmetic and checked here *before* anything is allocated, so that a hostile or mistyped
//! size gives [`JpError::TooLarge`] (`JPROM_BAD_SIZE` in C, an error in the `jprom` program)
//! instead of an allocation failure that aborts the host process.
//!
//! The default budget is [`DEFAULT_FRACTION`] of the physical memory (or of the cgroup's
//! limit, if lower); [`MemoryBudget::set_global`] (C: `jprom_set_memory_budget`) changes it.

use crate::error::{JpError, Result};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Share of the machine's memory that the default budget allows.
pub const DEFAULT_FRACTION: f64 = 0.7;

/// Budget used when the machine's memory cannot be read (4 GiB).
pub const FALLBACK_BYTES: usize = 4 << 30;

/// A ceiling in bytes for one data-driven allocation (or one stage's estimate).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryBudget {
    pub bytes: usize,
}

/// The global budget in bytes; 0 means "not set": the machine default.
static GLOBAL: AtomicUsize = AtomicUsize::new(0);

impl MemoryBudget {
    /// A budget of `bytes`.
    pub fn new(bytes: usize) -> Self {
        MemoryBudget { bytes }
    }

    /// [`DEFAULT_FRACTION`] of the physical memory (or of the cgroup limit if lower),
    /// [`FALLBACK_BYTES`] if neither can be read.
    pub fn machine_default() -> Self {
        let bytes = match available_memory() {
            Some(total) => (total as f64 * DEFAULT_FRACTION) as usize,
            None => FALLBACK_BYTES,
        };
        MemoryBudget { bytes }
    }

    /// The budget in force for the process.
    pub fn global() -> Self {
        match GLOBAL.load(Ordering::Relaxed) {
            0 => Self::machine_default(),
            bytes => MemoryBudget { bytes },
        }
    }

    /// Sets the process-wide budget; `None` (or 0 bytes) restores the machine default.
    pub fn set_global(budget: Option<MemoryBudget>) {
        GLOBAL.store(budget.map_or(0, |b| b.bytes), Ordering::Relaxed);
    }

    /// `Ok` if `bytes` fit in the budget, else [`JpError::TooLarge`] naming `what`, the
    /// estimate and the budget.
    pub fn check(&self, what: &str, bytes: u128) -> Result<()> {
        if bytes <= self.bytes as u128 {
            Ok(())
        } else {
            Err(JpError::TooLarge { what: what.to_string(), bytes, budget: self.bytes })
        }
    }
}

/// [`MemoryBudget::check`] against the global budget.
pub fn check(what: &str, bytes: u128) -> Result<()> {
    MemoryBudget::global().check(what, bytes)
}

/// Bytes taken by `count` values of `T` (saturating: an estimate never wraps round).
pub fn bytes_of<T>(count: u128) -> u128 {
    count.saturating_mul(std::mem::size_of::<T>() as u128)
}

/// Product of sizes without overflow (saturates at `u128::MAX`, which no budget admits).
pub fn product(factors: &[usize]) -> u128 {
    factors.iter().fold(1u128, |acc, &f| acc.saturating_mul(f as u128))
}

pub use crate::error::human_bytes;

/// Physical memory in bytes, lowered to the cgroup (v2) limit when there is one.
fn available_memory() -> Option<u128> {
    // SAFETY: sysconf has no preconditions.
    let (pages, page) = unsafe { (libc::sysconf(libc::_SC_PHYS_PAGES), libc::sysconf(libc::_SC_PAGESIZE)) };
    let physical = (pages > 0 && page > 0).then(|| pages as u128 * page as u128);
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max").ok().and_then(|s| s.trim().parse::<u128>().ok());
    match (physical, cgroup) {
        (Some(p), Some(c)) => Some(p.min(c)),
        (p, c) => p.or(c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_budget_admits_up_to_its_size_and_names_the_excess() {
        let b = MemoryBudget::new(1000);
        assert!(b.check("x", 1000).is_ok());
        let e = b.check("the matrix", 1001).unwrap_err();
        assert!(matches!(e, JpError::TooLarge { bytes: 1001, budget: 1000, .. }), "{e:?}");
        assert!(e.to_string().contains("the matrix is too large") && e.to_string().contains("1001 bytes"), "{e}");
    }

    #[test]
    fn estimates_saturate_instead_of_wrapping() {
        assert_eq!(product(&[usize::MAX, usize::MAX, usize::MAX]), u128::MAX);
        assert_eq!(bytes_of::<f64>(u128::MAX / 2), u128::MAX);
        assert_eq!(product(&[1 << 32, 1 << 32]), 1u128 << 64);
        assert!(MemoryBudget::new(usize::MAX).check("x", u128::MAX).is_err());
    }

    #[test]
    fn the_machine_default_is_a_fraction_of_the_memory() {
        let b = MemoryBudget::machine_default();
        let total = available_memory().expect("Linux reports its memory");
        assert!(b.bytes > 0 && (b.bytes as u128) < total, "{b:?} of {total}");
        assert!(((b.bytes as f64) / total as f64 - DEFAULT_FRACTION).abs() < 1e-6);
    }

    #[test]
    fn human_bytes_reads_well() {
        assert_eq!(human_bytes(12), "12 bytes");
        assert!(human_bytes(3 << 30).starts_with("3.0 GiB"), "{}", human_bytes(3 << 30));
    }
}
