//! Typed errors of the numerical core. The C boundary maps each variant onto a fixed
//! status code (`ffi::status`); inside the crate nothing is a string until it is displayed.

use thiserror::Error;

/// Everything that can go wrong in jprom, with enough context to say what and where.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum JpError {
    /// An array has the wrong length or a matrix the wrong shape.
    #[error("bad size for {what}: expected {expected}, got {got}")]
    BadSize { what: String, expected: usize, got: usize },

    /// A value is outside its admissible range (negative stiffness, NaN, index out of range, ...).
    #[error("invalid value for {what}: {reason}")]
    InvalidValue { what: String, reason: String },

    /// A matrix that must be factorised is singular or not positive definite.
    #[error("singular matrix: {what}")]
    SingularMatrix { what: String },

    /// An iterative solver stopped without meeting its tolerance: `residual` is the last
    /// one it reached, `tolerance` the one it was asked for (both relative, as the solver
    /// measures them). `iterations` 0 and a non-finite `residual` or `tolerance` where the step
    /// that failed was not an iteration (a point refused by the continuation): the message
    /// then says nothing it does not know.
    #[error("no convergence in {what}{}", convergence_tail(*iterations, *residual, *tolerance))]
    NoConvergence { what: String, iterations: usize, residual: f64, tolerance: f64 },

    /// Reading or writing a file failed, or a file is malformed.
    #[error("I/O error on {path}: {reason}")]
    Io { path: String, reason: String },

    /// A file could be read but its content is malformed, with the line where it went wrong
    /// (`0`: no single line, e.g. a value taken by default).
    #[error("parse error in {path}{}: {reason}", at_line(*line))]
    Parse { path: String, line: usize, reason: String },

    /// The caller asked to stop (progress callback returned non-zero).
    #[error("cancelled by the caller")]
    Cancelled,

    /// An eigen solver failed or returned too few converged pairs.
    #[error("eigen solver failed: {what}")]
    Eigen { what: String },

    /// What a size from outside asks for would need more memory than the budget
    /// (`crate::memory::MemoryBudget`, raised with `MemoryBudget::set_global`; each front end
    /// adds its own way to the message); nothing was allocated.
    #[error("{what} is too large: it needs about {}, more than the memory budget of {}", human_bytes(*bytes), human_bytes(*budget as u128))]
    TooLarge { what: String, bytes: u128, budget: usize },

    /// What sizes from outside ask for would take longer than the time budget
    /// ([`crate::time_budget`]) at the assumed rate; nothing was computed.
    /// `flops` and `seconds` NaN where the work was stopped at the budget instead
    /// ([`crate::time_budget::Deadline`]).
    #[error("{}", too_long(what, *flops, *seconds, *budget))]
    TooLong { what: String, flops: f64, seconds: f64, budget: f64 },

    /// A size from outside exceeds one of jprom's documented caps ([`crate::limits`]).
    #[error("{what} = {value} is above jprom's limit of {limit}")]
    OverLimit { what: String, value: u128, limit: u128 },

    /// A user-defined law ([`crate::contact::ExternalLaw`], a C callback) failed: it returned
    /// an error, panicked, or gave a non-finite force or Jacobian at time sample `sample` of
    /// the AFT. `element` names it ("element 3").
    #[error("{element}: {reason} at sample {sample}")]
    Callback { element: String, sample: usize, reason: String },
}

/// `" after N iterations (residual r, tolerance t)"`, without the parts that are not
/// known: no NaN and no "after 0 iterations" in a message.
fn convergence_tail(iterations: usize, residual: f64, tolerance: f64) -> String {
    let mut tail = String::new();
    if iterations > 0 {
        tail += &format!(" after {iterations} iterations");
    }
    match (residual.is_finite(), tolerance.is_finite()) {
        (true, true) => tail += &format!(" (residual {residual:.3e}, tolerance {tolerance:.3e})"),
        (true, false) => tail += &format!(" (residual {residual:.3e})"),
        _ => {}
    }
    tail
}

fn too_long(what: &str, flops: f64, seconds: f64, budget: f64) -> String {
    if flops.is_finite() && seconds.is_finite() {
        format!(
            "{what} is too large: it needs about {flops:.1e} floating-point operations, about {} at the assumed rate, more than the time budget of {}",
            seconds_text(seconds),
            seconds_text(budget)
        )
    } else {
        format!("{what} took longer than the time budget of {}", seconds_text(budget))
    }
}

/// `"500 s"`, `"2.5 h"`: a duration for a message.
fn seconds_text(s: f64) -> String {
    if s < 10.0 {
        format!("{s:.2} s")
    } else if s < 1e4 {
        format!("{} s", s.round())
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(" at line {line}")
    }
}

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, JpError>;

impl JpError {
    /// Shorthand for [`JpError::InvalidValue`].
    pub fn invalid(what: impl Into<String>, reason: impl Into<String>) -> Self {
        JpError::InvalidValue { what: what.into(), reason: reason.into() }
    }
    /// Shorthand for [`JpError::BadSize`].
    pub fn bad_size(what: impl Into<String>, expected: usize, got: usize) -> Self {
        JpError::BadSize { what: what.into(), expected, got }
    }
    /// Shorthand for [`JpError::OverLimit`].
    pub fn over_limit(what: impl Into<String>, value: u128, limit: u128) -> Self {
        JpError::OverLimit { what: what.into(), value, limit }
    }
    /// Shorthand for [`JpError::SingularMatrix`].
    pub fn singular(what: impl Into<String>) -> Self {
        JpError::SingularMatrix { what: what.into() }
    }
}

/// Checks that every entry is finite; names the first bad index.
pub fn check_finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(JpError::invalid(what, format!("entry {i} is not finite ({})", values[i]))),
    }
}

/// `1.5 GiB`-style text for a byte count.
pub fn human_bytes(bytes: u128) -> String {
    const UNITS: [&str; 7] = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = bytes as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{v:.1} {} ({bytes} bytes)", UNITS[u])
    }
}

#[cfg(test)]
mod tests {
    use super::JpError;

    #[test]
    fn a_convergence_message_says_only_what_it_knows() {
        let e = |iterations, residual, tolerance| JpError::NoConvergence { what: "x".into(), iterations, residual, tolerance }.to_string();
        assert_eq!(e(3, 0.5, f64::NAN), "no convergence in x after 3 iterations (residual 5.000e-1)");
        assert_eq!(e(12, 1.807e-10, 1e-10), "no convergence in x after 12 iterations (residual 1.807e-10, tolerance 1.000e-10)");
        assert_eq!(e(0, f64::NAN, 1e-10), "no convergence in x");
        assert_eq!(e(7, f64::INFINITY, 1e-10), "no convergence in x after 7 iterations");
        assert!(!e(0, f64::NAN, f64::NAN).contains("NaN"));
    }
}
