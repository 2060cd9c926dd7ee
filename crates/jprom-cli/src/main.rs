//! `jprom`: runs a study described in a TOML or JSON file, or the built-in blade demo.
//!
//! ```text
//! jprom demo  [--out DIR]          built-in shrouded blade: FO, FR and NLR at three levels
//! jprom run   STUDY [--out DIR]    a study file (see crates/jprom-cli/demo_study.toml)
//!             [--jobs N]           N units (a solver at a level of a case) at once, in threads
//!             [--reproducible]     the same numbers on any number of threads
//! jprom check STUDY                validate a study file and every file and node it names
//! jprom modes STUDY [--count N]    natural frequencies: FE model, CB model free and stuck
//! jprom --version                  jprom <version>
//! ```
//!
//! `jprom COMMAND --help` (or `-h`) prints the command's usage and options (exit 0); an option
//! the command does not take, a missing value or an extra argument is a usage error (exit 2).
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
#[cfg(not(feature = "mpi"))]
use jprom_cli::run::run_study_jobs;
use jprom_cli::run::summary_table;
use jprom_cli::study::Study;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "usage:
  jprom demo  [--out DIR] [--jobs N] [--keep-partial] [--fall-back] [--memory-budget SIZE] [--reproducible] [--quiet]
                                 run the built-in shrouded-blade demo (results in DIR, default jprom-demo)
  jprom run   STUDY [--out DIR] [--jobs N] [--keep-partial] [--fall-back] [--memory-budget SIZE] [--reproducible] [--quiet]
                                 run a study file (.toml or .json); --jobs N runs N units
                                 (a solver at a level of a case) at once in threads, same results;
                                 --memory-budget SIZE (12G) caps what one stage may take;
                                 --reproducible: the same numbers on any number of threads
  jprom check STUDY              validate a study file and the files and nodes it names
                                 (without reading the matrices), print it with its defaults
  jprom modes STUDY [--count N] [--memory-budget SIZE] [--reproducible] [--quiet]
                                 natural frequencies of the FE model (lowest N, default 10), of
                                 its Craig-Bampton model with contacts open and stuck (modal
                                 forces, participation; * a stuck mode in the band), the stuck
                                 mode for the band and a warning if the band holds none
  jprom --help | -h              this text (jprom COMMAND --help: the command's options)
  jprom --version | -V           the version
exit status: 0 done (every output written), 1 the run failed (model, solver or an output
that could not be written), 2 bad command line or invalid study, 3 a sweep did not cover its
band (results kept; --keep-partial makes it 0)";

/// A subcommand's command line: its usage text, whether it takes a study file, and its options
/// (name, takes a value, help).
struct Command {
    name: &'static str,
    synopsis: &'static str,
    about: &'static str,
    takes_study: bool,
    options: &'static [(&'static str, bool, &'static str)],
}

const QUIET: (&str, bool, &str) = ("--quiet", false, "no progress on standard error (bars on a terminal, plain lines otherwise)");
const KEEP_PARTIAL: (&str, bool, &str) = ("--keep-partial", false, "exit 0 when a sweep did not cover its band (exit 3 otherwise; results are kept either way)");
const HELP: (&str, bool, &str) = ("--help, -h", false, "this text");
const FALL_BACK: (&str, bool, &str) = (
    "--fall-back",
    false,
    "where a reduced sweep is not trusted or did not finish, the full order gives the level's result (run there when solvers.full_order is off); as solvers.fall_back = true",
);
const JOBS: (&str, bool, &str) = ("--jobs", true, "N: run N units (a solver at a level of a case) at once, in threads (default 1); the results do not depend on N");
const MEMORY_BUDGET: (&str, bool, &str) = (
    "--memory-budget",
    true,
    "SIZE: the most a stage (Craig-Bampton, a system, the JP prediction) may take, in bytes or with K, M, G, T (powers of 1024: 12G); default 70 % of the machine's memory. A stage beyond it stops the run with the size it needs",
);

const REPRODUCIBLE: (&str, bool, &str) = (
    "--reproducible",
    false,
    "the same numbers on any number of threads (RAYON_NUM_THREADS): every linear-algebra kernel on one thread, the independent tasks (contact patterns, units) still in parallel; slower on large models. Without it a JP basis can differ between thread counts (README, \"Reproducibility\")",
);

const COMMANDS: [Command; 4] = [
    Command {
        name: "demo",
        synopsis: "jprom demo [--out DIR] [--jobs N] [--keep-partial] [--fall-back] [--memory-budget SIZE] [--reproducible] [--quiet]",
        about: "Runs the built-in shrouded-blade demo (crates/jprom-cli/demo_study.toml): full order, FR and\nNLR sweeps at each level, error predictor, summary table, CSV, JSON and SVG plots.",
        takes_study: false,
        options: &[("--out", true, "DIR: where results go (default jprom-demo, in the current folder)"), JOBS, KEEP_PARTIAL, FALL_BACK, MEMORY_BUDGET, REPRODUCIBLE, QUIET, HELP],
    },
    Command {
        name: "run",
        synopsis: "jprom run STUDY [--out DIR] [--jobs N] [--keep-partial] [--fall-back] [--memory-budget SIZE] [--reproducible] [--quiet]",
        about: "Runs a study file (TOML or JSON): model, Craig-Bampton, sweeps, bases, CSV, JSON and SVG.",
        takes_study: true,
        options: &[("--out", true, "DIR: where results go (default: the study's output.dir, relative to the study file)"), JOBS, KEEP_PARTIAL, FALL_BACK, MEMORY_BUDGET, REPRODUCIBLE, QUIET, HELP],
    },
    Command {
        name: "check",
        synopsis: "jprom check STUDY [--quiet]",
        about: "Validates a study file and every file and node it names (without reading the matrices)\nand prints it with the defaults applied.",
        takes_study: true,
        options: &[("--quiet", false, "accepted for symmetry (check shows no progress)"), HELP],
    },
    Command {
        name: "modes",
        synopsis: "jprom modes STUDY [--count N] [--memory-budget SIZE] [--reproducible] [--quiet]",
        about: "Natural frequencies of the FE model (lowest N), of its Craig-Bampton model with the contacts\nopen and stuck (modal forces, participation; * a stuck mode in the band), the stuck mode for\nthe band and a warning if the band holds none.",
        takes_study: true,
        options: &[("--count", true, "N: how many FE natural frequencies (default 10)"), MEMORY_BUDGET, REPRODUCIBLE, QUIET, HELP],
    },
];

impl Command {
    fn usage(&self) -> String {
        let mut s = format!("usage: {}\n\n{}\n\noptions:\n", self.synopsis, self.about);
        for (name, value, help) in self.options {
            // a value's name starts its help: "DIR: where results go"
            let (name, help) = match help.split_once(": ") {
                Some((meta, rest)) if *value => (format!("{name} {meta}"), rest),
                _ => (name.to_string(), *help),
            };
            s.push_str(&format!("  {name:<16} {help}\n"));
        }
        s.push_str("\nexit status: 0 done, 1 the run failed, 2 bad command line or invalid study");
        if self.options.iter().any(|o| o.0 == "--keep-partial") {
            s.push_str(", 3 a sweep did not cover its band");
        }
        s.push('\n');
        s
    }
}

/// A parsed subcommand line: the study path (if the command takes one), the options given.
struct Parsed {
    study: Option<String>,
    values: Vec<(&'static str, String)>,
    flags: Vec<&'static str>,
}

impl Parsed {
    fn value(&self, name: &str) -> Option<&str> {
        self.values.iter().rev().find(|v| v.0 == name).map(|v| v.1.as_str())
    }
    fn flag(&self, name: &str) -> bool {
        self.flags.contains(&name)
    }
}

/// What the command line asks for.
enum Request {
    Help(String),
    Run(&'static Command, Parsed),
}

/// Parses `args` (after the program name): `--help`/`-h` anywhere after a command gives that
/// command's usage; an unknown option, a missing value or study, or an extra argument is a
/// usage error (exit 2).
fn parse(args: &[String]) -> Result<Request, Failure> {
    let cmd_name = args.first().map(String::as_str).unwrap_or("--help");
    if matches!(cmd_name, "--help" | "-h" | "help") {
        return Ok(Request::Help(format!("{USAGE}\n")));
    }
    if matches!(cmd_name, "--version" | "-V") {
        return Ok(Request::Help(format!("jprom {}\n", env!("CARGO_PKG_VERSION"))));
    }
    let cmd = COMMANDS.iter().find(|c| c.name == cmd_name).ok_or_else(|| Failure::Usage(format!("unknown command '{cmd_name}'\n{USAGE}")))?;
    let bad = |what: String| Failure::Usage(format!("{what}\n{}", cmd.usage()));
    if args[1..].iter().any(|a| a == "--help" || a == "-h") {
        return Ok(Request::Help(cmd.usage()));
    }
    let mut parsed = Parsed { study: None, values: Vec::new(), flags: Vec::new() };
    let mut rest = args[1..].iter();
    while let Some(a) = rest.next() {
        if a.starts_with('-') && a.len() > 1 {
            let (name, inline) = match a.split_once('=') {
                Some((n, v)) => (n, Some(v.to_string())),
                None => (a.as_str(), None),
            };
            let opt = cmd.options.iter().find(|o| o.0 == name).ok_or_else(|| bad(format!("{} does not take the option '{name}'", cmd.name)))?;
            if opt.1 {
                let v = match inline {
                    Some(v) => v,
                    None => rest.next().cloned().ok_or_else(|| bad(format!("{name} needs a value")))?,
                };
                parsed.values.push((opt.0, v));
            } else if inline.is_some() {
                return Err(bad(format!("{name} takes no value")));
            } else {
                parsed.flags.push(opt.0);
            }
        } else if cmd.takes_study && parsed.study.is_none() {
            parsed.study = Some(a.clone());
        } else {
            return Err(bad(format!("unexpected argument '{a}'")));
        }
    }
    if cmd.takes_study && parsed.study.is_none() {
        return Err(bad(format!("{} needs a study file", cmd.name)));
    }
    Ok(Request::Run(cmd, parsed))
}

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

/// `study` with `solvers.fall_back` on where the command line says `--fall-back`.
fn with_fall_back(mut study: Study, args: &Parsed) -> Study {
    study.solvers.fall_back |= args.flag("--fall-back");
    study
}

/// `--jobs N` (default 1), a positive integer.
fn jobs_arg(args: &Parsed) -> Result<usize, Failure> {
    match args.value("--jobs") {
        Some(v) => match v.parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(Failure::Usage("--jobs needs a positive integer".to_string())),
        },
        None => Ok(1),
    }
}

/// `--count N` (default 10), a positive integer.
fn count_arg(args: &Parsed) -> Result<usize, Failure> {
    match args.value("--count") {
        Some(v) => match v.parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(Failure::Usage("--count needs a positive integer".to_string())),
        },
        None => Ok(10),
    }
}

/// `--memory-budget SIZE`: bytes, or a number with K, M, G or T (powers of 1024, an optional
/// `B` or `iB` after it: `12G`, `1.5GiB`, `800M`), more than 0.
fn memory_budget_arg(args: &Parsed) -> Result<Option<usize>, Failure> {
    let Some(text) = args.value("--memory-budget") else { return Ok(None) };
    let bad = || Failure::Usage(format!("--memory-budget needs a size in bytes or with K, M, G, T (for example 12G), got '{text}'"));
    let lower = text.trim().to_ascii_lowercase();
    let number = lower.trim_end_matches("ib").trim_end_matches('b');
    let (digits, scale) = match number.chars().last() {
        Some('k') => (&number[..number.len() - 1], 1u64 << 10),
        Some('m') => (&number[..number.len() - 1], 1 << 20),
        Some('g') => (&number[..number.len() - 1], 1 << 30),
        Some('t') => (&number[..number.len() - 1], 1 << 40),
        _ => (number, 1),
    };
    let value: f64 = digits.trim().parse().map_err(|_| bad())?;
    let bytes = value * scale as f64;
    if !(bytes.is_finite() && bytes >= 1.0 && bytes < usize::MAX as f64) {
        return Err(bad());
    }
    Ok(Some(bytes as usize))
}

/// A failed run; a refusal by the memory budget names the option that raises it.
fn run_failure(e: jprom::JpError) -> Failure {
    match e {
        jprom::JpError::TooLarge { .. } => Failure::Run(format!("{e} (raise it with --memory-budget SIZE if the machine has the memory)")),
        e => Failure::Run(e.to_string()),
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
    let result = parse(&args).and_then(|request| match request {
        Request::Help(text) => print_out(&text),
        Request::Run(cmd, p) => {
            let progress = Progress::for_stderr(p.flag("--quiet"));
            let keep_partial = p.flag("--keep-partial");
            let out = p.value("--out").map(PathBuf::from);
            let jobs = jobs_arg(&p)?;
            if let Some(bytes) = memory_budget_arg(&p)? {
                jprom::memory::MemoryBudget::set_global(Some(jprom::memory::MemoryBudget::new(bytes)));
            }
            if p.flag("--reproducible") {
                jprom::parallelism::set_reproducible(true);
            }
            match (cmd.name, p.study.as_deref()) {
                ("demo", _) => {
                    let study = with_fall_back(Study::from_toml_str(DEMO_STUDY).map_err(|e| Failure::Usage(e.to_string()))?, &p);
                    run(&study, &out.unwrap_or_else(|| PathBuf::from("jprom-demo")), keep_partial, progress, jobs)
                }
                ("run", Some(path)) => study_from(path).and_then(|study| {
                    // every file and node the study names, checked before the long reads (errors with their line)
                    // (a file that is missing or malformed fails the run, status 1, as the full read would)
                    check_study_file(std::path::Path::new(path)).map_err(|e| Failure::Run(e.to_string()))?;
                    let study = with_fall_back(study, &p);
                    run(&study, &out.unwrap_or_else(|| study.output.dir.clone()), keep_partial, progress, jobs)
                }),
                ("check", Some(path)) => check_study_file(std::path::Path::new(path)).map_err(|e| Failure::Usage(e.to_string())).and_then(|text| print_out(&text)),
                ("modes", Some(path)) => count_arg(&p).and_then(|count| {
                    let study = study_from(path)?;
                    check_study_file(std::path::Path::new(path)).map_err(|e| Failure::Usage(e.to_string()))?;
                    let report = modes_report(&study, count, progress).map_err(run_failure)?;
                    print_out(&modes_table(&report, count))
                }),
                (name, _) => Err(Failure::Usage(format!("{name} needs a study file\n{USAGE}"))),
            }
        }
    });
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

/// Runs the study in `jobs` threads; built with the `mpi` feature, on every rank of
/// `MPI_COMM_WORLD` (`mpirun -np N jprom run STUDY`), rank 0 printing the summary.
fn run(study: &Study, dir: &std::path::Path, keep_partial: bool, progress: Progress, jobs: usize) -> Result<(), Failure> {
    let t = std::time::Instant::now();
    #[cfg(not(feature = "mpi"))]
    let summary = run_study_jobs(study, dir, progress, jobs).map_err(run_failure)?;
    #[cfg(feature = "mpi")]
    let (summary, _mpi) = {
        // MPI_Finalize when `_mpi` drops, after the summary is out
        let mpi = jprom_cli::mpi_run::Mpi::init().ok_or_else(|| Failure::Run("MPI could not be initialised with MPI_THREAD_FUNNELED".into()))?;
        match jprom_cli::mpi_run::run_study_mpi(&mpi, study, dir, progress, jobs).map_err(run_failure)? {
            Some(summary) => (summary, mpi),
            // ranks other than 0: rank 0 reports
            None => return Ok(()),
        }
    };
    print_out(&format!("{}results in {} ({:.1} s)\n", summary_table(&summary), dir.display(), t.elapsed().as_secs_f64()))?;
    if summary.incomplete.is_empty() || keep_partial || study.output.keep_partial {
        Ok(())
    } else {
        Err(Failure::Incomplete(summary.incomplete))
    }
}
