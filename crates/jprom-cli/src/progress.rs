//! Progress of a run on standard error: the import of the model, Craig-Bampton, basis building
//! and the sweeps. On a terminal, indicatif spinners (a sweep's length is not known in advance:
//! it counts its points and shows the last frequency); otherwise (a log file, a pipe, CI) one
//! plain line when a step starts and one when it ends, with its elapsed seconds, and during a
//! sweep a line such as `jprom: [FO alpha_ST x 1e-1] 40 points, omega 2186.4 Hz, 3.1 s` at most
//! every [`LINE_INTERVAL_S`] seconds; nothing with `--quiet`. A closed standard error is ignored.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::Write;
use std::time::Instant;

/// Least time between two plain progress lines of one sweep ([`Points::point`]).
pub const LINE_INTERVAL_S: f64 = 5.0;

/// How progress is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// Nothing.
    Quiet,
    /// Plain lines: `jprom: <step> ...`, then `jprom: <step>: done in 1.2 s`.
    Lines,
    /// indicatif bars and spinners (for a terminal).
    Bars,
}

impl Progress {
    /// Bars if standard error is a terminal, plain lines if not, nothing if `quiet`.
    pub fn for_stderr(quiet: bool) -> Self {
        use std::io::IsTerminal;
        if quiet {
            Progress::Quiet
        } else if std::io::stderr().is_terminal() {
            Progress::Bars
        } else {
            Progress::Lines
        }
    }

    /// A step of unknown length; [`Step::done`] ends it.
    pub fn step(self, what: impl Into<String>) -> Step {
        let what = what.into();
        let spinner = match self {
            Progress::Bars => {
                let s = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
                s.set_style(ProgressStyle::with_template("{spinner} {msg} {elapsed}").unwrap());
                s.set_message(what.clone());
                s.enable_steady_tick(std::time::Duration::from_millis(200));
                Some(s)
            }
            Progress::Lines => {
                line(&format!("{what} ..."));
                None
            }
            Progress::Quiet => None,
        };
        Step { what, start: Instant::now(), mode: self, spinner }
    }

    /// A sweep of unknown length: counts its points ([`Points::point`]); [`Points::done`] ends it.
    pub fn points(self, what: impl Into<String>) -> Points {
        let what = what.into();
        let spinner = match self {
            Progress::Bars => {
                let s = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
                s.set_style(ProgressStyle::with_template("{spinner} {prefix} {pos} points{msg} {elapsed}").unwrap());
                s.set_prefix(what.clone());
                s.enable_steady_tick(std::time::Duration::from_millis(200));
                Some(s)
            }
            Progress::Lines => {
                line(&format!("{what} ..."));
                None
            }
            Progress::Quiet => None,
        };
        let now = Instant::now();
        Points { what, start: now, last_line: now, last_point: None, count: 0, mode: self, spinner }
    }

    /// A bar of `len` steps (hidden unless [`Progress::Bars`]); as [`Progress::step`] otherwise.
    pub fn bar(self, len: u64, what: &str) -> Bar {
        let target = if self == Progress::Bars { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
        let bar = ProgressBar::with_draw_target(Some(len), target);
        bar.set_style(ProgressStyle::with_template("{msg:28} [{bar:30}] {pos}/{len} {elapsed}").unwrap().progress_chars("=> "));
        bar.set_message(what.to_string());
        let step = if self == Progress::Lines { Progress::Lines.step(what) } else { Progress::Quiet.step(what) };
        Bar { bar, step }
    }
}

fn line(text: &str) {
    let _ = writeln!(std::io::stderr().lock(), "jprom: {text}");
}

/// A step in progress ([`Progress::step`]).
pub struct Step {
    what: String,
    start: Instant,
    mode: Progress,
    spinner: Option<ProgressBar>,
}

impl Step {
    /// Ends the step: `jprom: <step>: done in 1.2 s` (plain lines), the spinner cleared (bars).
    pub fn done(self) {
        self.done_with("");
    }

    /// As [`Step::done`], with a note after the time (e.g. `, 61,440 DoFs`).
    pub fn done_with(mut self, note: &str) {
        if let Some(s) = self.spinner.take() {
            s.finish_and_clear();
        }
        if self.mode == Progress::Lines {
            line(&format!("{}: done in {:.1} s{note}", self.what, self.start.elapsed().as_secs_f64()));
        }
    }
}

impl Drop for Step {
    fn drop(&mut self) {
        if let Some(s) = self.spinner.take() {
            s.finish_and_clear();
        }
    }
}

/// A bar in progress ([`Progress::bar`]).
pub struct Bar {
    bar: ProgressBar,
    step: Step,
}

impl Bar {
    pub fn set_position(&self, pos: u64) {
        self.bar.set_position(pos);
    }

    /// Clears the bar; a plain line with the elapsed time.
    pub fn done(self) {
        self.bar.finish_and_clear();
        self.step.done();
    }
}

/// A sweep in progress ([`Progress::points`]).
pub struct Points {
    what: String,
    start: Instant,
    last_line: Instant,
    last_point: Option<Instant>,
    count: u64,
    mode: Progress,
    spinner: Option<ProgressBar>,
}

impl Points {
    /// One more converged point, at `hz`.
    pub fn point(&mut self, hz: f64) {
        self.count += 1;
        let now = Instant::now();
        self.last_point = Some(now);
        if let Some(s) = &self.spinner {
            s.set_position(self.count);
            s.set_message(format!(", omega {hz:.1} Hz,"));
        }
        if self.mode == Progress::Lines && now.duration_since(self.last_line).as_secs_f64() >= LINE_INTERVAL_S {
            self.last_line = now;
            line(&format!("[{}] {} points, omega {hz:.1} Hz, {:.1} s", self.what, self.count, self.start.elapsed().as_secs_f64()));
        }
    }

    /// Points so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Ends the sweep: `jprom: <what>: done in 3.7 s, 146 points<note>` (the time up to its
    /// last point), the spinner cleared.
    pub fn done(mut self, note: &str) {
        if let Some(s) = self.spinner.take() {
            s.finish_and_clear();
        }
        if self.mode == Progress::Lines {
            let end = self.last_point.unwrap_or_else(Instant::now);
            line(&format!("{}: done in {:.1} s, {} points{note}", self.what, end.duration_since(self.start).as_secs_f64(), self.count));
        }
    }
}

impl Drop for Points {
    fn drop(&mut self) {
        if let Some(s) = self.spinner.take() {
            s.finish_and_clear();
        }
    }
}
