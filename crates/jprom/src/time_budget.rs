//! The time budget: one process-wide ceiling on the estimated time of a stage whose cost
//! grows as a power of sizes from outside (the harmonic count above all: a dense JP pattern
//! costs `O((2 H n)^3)`). Such a stage estimates its floating-point operations *before* any
//! work and is refused ([`JpError::TooLong`], `JPROM_BAD_SIZE` in C) when, at
//! [`ASSUMED_FLOP_RATE`], they would take longer than the budget, so that `H = 64` on a small
//! model is an immediate refusal with the estimate, not a call that runs for minutes.
//!
//! The default is [`DEFAULT_SECONDS`]; [`TimeBudget::set_global`] (C: `jprom_set_time_budget`,
//! CLI: `--time-budget`) changes it. The estimate counts the dominant dense factorisations and
//! eigen solves of one core; real runs on several threads are faster, never slower by more
//! than the estimate's constant.

use crate::error::{JpError, Result};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// The rate the estimates assume: 1e10 floating-point operations per second, what the JP
/// prediction's dense eigenproblems reach on a 2-core machine (measured 2-3e10 from `H` = 24
/// to 40 on the CI machine, docs/benchmarks.md): the estimate errs on the long side there.
pub const ASSUMED_FLOP_RATE: f64 = 1e10;

/// The default budget: one hour for one stage.
pub const DEFAULT_SECONDS: f64 = 3600.0;

/// The global budget's bits (`f64::to_bits`); 0 means "not set": the default.
static GLOBAL: AtomicU64 = AtomicU64::new(0);

/// A ceiling in seconds for one stage's estimated time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeBudget {
    pub seconds: f64,
}

impl TimeBudget {
    /// The budget in force for the process.
    pub fn global() -> Self {
        match GLOBAL.load(Ordering::Relaxed) {
            0 => TimeBudget { seconds: DEFAULT_SECONDS },
            bits => TimeBudget { seconds: f64::from_bits(bits) },
        }
    }

    /// Sets the process-wide budget; `None` restores [`DEFAULT_SECONDS`].
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] for a budget that is not finite and positive (the budget in
    /// force is then unchanged).
    pub fn set_global(budget: Option<TimeBudget>) -> Result<()> {
        match budget {
            None => GLOBAL.store(0, Ordering::Relaxed),
            Some(b) if b.seconds.is_finite() && b.seconds > 0.0 => GLOBAL.store(b.seconds.to_bits(), Ordering::Relaxed),
            Some(b) => return Err(JpError::invalid("time budget", format!("must be finite and > 0 seconds, got {}", b.seconds))),
        }
        Ok(())
    }

    /// `Ok` if `flops` at [`ASSUMED_FLOP_RATE`] fit in the budget, else [`JpError::TooLong`]
    /// naming `what` and the estimate.
    pub fn check(&self, what: &str, flops: f64) -> Result<()> {
        let seconds = flops / ASSUMED_FLOP_RATE;
        if seconds <= self.seconds {
            Ok(())
        } else {
            Err(JpError::TooLong { what: what.to_string(), flops, seconds, budget: self.seconds })
        }
    }
}

/// The budget as a deadline for work whose cost no estimate bounds beforehand (a
/// shift-invert eigen solve whose count of modes in the band grows with `H`): checked
/// between its pieces, it ends the work within the budget and one piece.
#[derive(Clone, Copy, Debug)]
pub struct Deadline {
    start: Instant,
    seconds: f64,
}

impl Deadline {
    /// From now, with the global budget.
    pub fn start() -> Self {
        Deadline { start: Instant::now(), seconds: TimeBudget::global().seconds }
    }

    /// `Ok` while within the budget, else [`JpError::TooLong`] saying how far `what` got
    /// (`done` of `total` pieces).
    pub fn check(&self, what: &str, done: usize, total: usize) -> Result<()> {
        let elapsed = self.start.elapsed().as_secs_f64();
        if elapsed <= self.seconds {
            return Ok(());
        }
        Err(JpError::TooLong {
            what: format!("{what} (stopped after {elapsed:.1} s with {done} of {total} done)"),
            flops: f64::NAN,
            seconds: f64::NAN,
            budget: self.seconds,
        })
    }
}

/// [`TimeBudget::check`] against the global budget.
pub fn check(what: &str, flops: f64) -> Result<()> {
    TimeBudget::global().check(what, flops)
}

/// Floating-point operations of a dense LU of order `n`: `2 n^3 / 3`.
pub fn lu_flops(n: usize) -> f64 {
    2.0 / 3.0 * (n as f64).powi(3)
}

/// Floating-point operations of a dense real eigen solve of order `n` with its vectors
/// (Hessenberg reduction, Schur form, the vectors wanted): about `10 n^3`.
pub fn eigen_flops(n: usize) -> f64 {
    10.0 * (n as f64).powi(3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stage_beyond_the_budget_is_refused_with_its_estimate() {
        let b = TimeBudget { seconds: 5.0 };
        assert!(b.check("small", 1e10).is_ok());
        let e = b.check("the JP prediction", 5e12).unwrap_err().to_string();
        assert!(e.contains("the JP prediction") && e.contains("about 500 s") && e.contains("time budget of 5.00 s"), "{e}");
        assert!(TimeBudget::set_global(Some(TimeBudget { seconds: f64::NAN })).is_err());
        assert_eq!(TimeBudget::global().seconds, DEFAULT_SECONDS);
    }
}
