//! `jprom`: runs a study described in a TOML or JSON file, or the built-in blade demo.
//!
//! ```text
//! jprom demo  [--out DIR]          built-in shrouded blade: FO, FR and NLR at two levels
//! jprom run   STUDY [--out DIR]    a study file (see crates/jprom-cli/demo_study.toml)
//! jprom check STUDY                validate a study file and every file and node it names
//! jprom modes STUDY [--count N]    natural frequencies: FE model, CB model free and stuck
//! ```
//!
//! `modes` lists the lowest `N` (default 10) natural frequencies of an FE model on its supports
//! (sparse shift-invert Lanczos), the modes of the reduced (Craig-Bampton) model with the
//! contacts open and stuck with their modal forces and participations (`*` marks the stuck modes
//! in the band), the stuck mode `run` uses for the band, and a warning when the band holds no
//! stuck mode (`run` puts the same warning in its summary).
//!
//! `--quiet` silences the progress on standard error (bars on a terminal, plain lines with
//! elapsed seconds otherwise). A reader that leaves early (`jprom check STUDY | head -1`)
//! ends the output quietly.
//!
//! Exit status: 0 when everything asked for was computed and every output file (CSV, JSON,
//! SVG) and the printed summary were written in full; 1 when the run failed (the model, a
//! solver, or writing any output); 2 for a bad command line or an invalid study file; 3 when a
//! sweep did not cover its band or a solver failed at some level (everything else is written;
//! `--keep-partial` or `output.keep_partial = true` makes that a success).

use jprom_cli::check::check_study_file;
use jprom_cli::modes::{modes_report, modes_table};
use jprom_cli::progress::Progress;
use jprom_cli::run::{run_study_with, summary_table};
use jprom_cli::study::Study;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "usage:
  jprom demo  [--out DIR]        run the built-in shrouded-blade demo (results in DIR, default jprom-demo)
  jprom run   STUDY [--out DIR] [--keep-partial] [--quiet]
                                 run a study file (.toml or .json)
  jprom check STUDY              validate a study file and the files and nodes it names
                                 (without reading the matrices), print it with its defaults
  jprom modes STUDY [--count N] [--quiet]
                                 natural frequencies of the FE model (lowest N, default 10), of
                                 its Craig-Bampton model with contacts open and stuck (modal
                                 forces, participation; * a stuck mode in the band), the stuck
                                 mode for the band and a warning if the band holds none
  --quiet                        no progress on standard error
  jprom --help
exit status: 0 done (every output written), 1 the run failed (model, solver or an output
that could not be written), 2 bad command line or invalid study, 3 a sweep did not cover its
band (results kept; --keep-partial makes it 0)";

/// The demo's study (crates/jprom-cli/demo_study.toml).
pub const DEMO_STUDY: &str = include_str!("../demo_study.toml");

/// Why `jprom` stops: the exit status and the message.
enum Failure {
    /// Bad command line or study file (exit 2).
    Usage(String),
    /// The run failed, including any output that could not be written (exit 1).
    Run(String),
    /// Everything was written, but these sweeps did not cover their band (exit 3).
    Incomplete(Vec<String>),
}

fn out_dir(args: &[String], default: &str) -> Result<PathBuf, Failure> {
    match args.iter().position(|a| a == "--out") {
        Some(i) => args.get(i + 1).map(PathBuf::from).ok_or_else(|| Failure::Usage("--out needs a directory".to_string())),
        None => Ok(PathBuf::from(default)),
    }
}

/// `--count N` (default 10), a positive integer.
fn count_arg(args: &[String]) -> Result<usize, Failure> {
    match args.iter().position(|a| a == "--count") {
        Some(i) => match args.get(i + 1).map(|v| v.parse::<usize>()) {
            Some(Ok(n)) if n > 0 => Ok(n),
            _ => Err(Failure::Usage("--count needs a positive integer".to_string())),
        },
        None => Ok(10),
    }
}

fn study_from(path: &str) -> Result<Study, Failure> {
    Study::from_file(std::path::Path::new(path)).map_err(|e| Failure::Usage(e.to_string()))
}

/// Writes `text` to stdout and flushes it; a full stdout (or any other write error) is a
/// failed run, a reader that left (a closed pipe: `jprom check STUDY | head -1`) is not.
fn print_out(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Failure::Run(format!("cannot write to standard output: {e}"))),
        _ => Ok(()),
    }
}

/// A line on stderr; a closed stderr is ignored (no panic).
fn say(text: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{text}");
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let keep_partial = args.iter().any(|a| a == "--keep-partial");
    let progress = Progress::for_stderr(args.iter().any(|a| a == "--quiet"));
    let result = match args.first().map(String::as_str) {
        None | Some("--help") | Some("-h") | Some("help") => print_out(&format!("{USAGE}\n")),
        Some("demo") => out_dir(&args, "jprom-demo").and_then(|dir| {
            let study = Study::from_toml_str(DEMO_STUDY).map_err(|e| Failure::Usage(e.to_string()))?;
            run(&study, &dir, keep_partial, progress)
        }),
        Some("run") => match args.get(1) {
            Some(path) if !path.starts_with("--") => study_from(path).and_then(|study| {
                // every file and node the study names, checked before the long reads (errors with their line)
                // (a file that is missing or malformed fails the run, status 1, as the full read would)
                check_study_file(std::path::Path::new(path)).map_err(|e| Failure::Run(e.to_string()))?;
                out_dir(&args, &study.output.dir.display().to_string()).and_then(|dir| run(&study, &dir, keep_partial, progress))
            }),
            _ => Err(Failure::Usage(format!("run needs a study file\n{USAGE}"))),
        },
        Some("check") => match args.get(1) {
            Some(path) if !path.starts_with("--") => check_study_file(std::path::Path::new(path)).map_err(|e| Failure::Usage(e.to_string())).and_then(|text| print_out(&text)),
            _ => Err(Failure::Usage(format!("check needs a study file\n{USAGE}"))),
        },
        Some("modes") => match args.get(1) {
            Some(path) if !path.starts_with("--") => count_arg(&args).and_then(|count| {
                let study = study_from(path)?;
                check_study_file(std::path::Path::new(path)).map_err(|e| Failure::Usage(e.to_string()))?;
                let report = modes_report(&study, count, progress).map_err(|e| Failure::Run(e.to_string()))?;
                print_out(&modes_table(&report, count))
            }),
            _ => Err(Failure::Usage(format!("modes needs a study file\n{USAGE}"))),
        },
        Some(other) => Err(Failure::Usage(format!("unknown command '{other}'\n{USAGE}"))),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Usage(message)) => {
            say(&format!("jprom: {message}"));
            ExitCode::from(2)
        }
        Err(Failure::Run(message)) => {
            say(&format!("jprom: {message}"));
            ExitCode::from(1)
        }
        Err(Failure::Incomplete(lines)) => {
            say(&format!("jprom: {} sweep(s) did not cover the band (results kept; --keep-partial accepts them):", lines.len()));
            for l in lines {
                say(&format!("  {l}"));
            }
            ExitCode::from(3)
        }
    }
}

fn run(study: &Study, dir: &std::path::Path, keep_partial: bool, progress: Progress) -> Result<(), Failure> {
    let t = std::time::Instant::now();
    let summary = run_study_with(study, dir, progress).map_err(|e| Failure::Run(e.to_string()))?;
    print_out(&format!("{}results in {} ({:.1} s)\n", summary_table(&summary), dir.display(), t.elapsed().as_secs_f64()))?;
    if summary.incomplete.is_empty() || keep_partial || study.output.keep_partial {
        Ok(())
    } else {
        Err(Failure::Incomplete(summary.incomplete))
    }
}
