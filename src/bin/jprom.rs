//! `jprom`: runs a study described in a TOML or JSON file, or the built-in blade demo.
//!
//! ```text
//! jprom demo  [--out DIR]          built-in shrouded blade: FO, FR and NLR at two levels
//! jprom run   STUDY [--out DIR] [--keep-partial]
//!                                  a study file (see examples/demo_study.toml)
//! jprom check STUDY                validate a study file only
//! ```
//!
//! Exit status: 0 on success, 2 on an error (message on stderr), 3 when a sweep did not cover
//! its band (the results written so far are kept; `--keep-partial` or `output.keep_partial =
//! true` makes that a success).

use jprom::app::run::{run_study, summary_table};
use jprom::app::study::Study;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "usage:
  jprom demo  [--out DIR]        run the built-in shrouded-blade demo (results in DIR, default jprom-demo)
  jprom run   STUDY [--out DIR] [--keep-partial]
                                 run a study file (.toml or .json); exits with 3 if a sweep
                                 did not cover its band, unless --keep-partial
  jprom check STUDY              validate a study file and print it with its defaults
  jprom --help";

/// The demo's study (also in examples/demo_study.toml).
pub const DEMO_STUDY: &str = include_str!("../../examples/demo_study.toml");

fn out_dir(args: &[String], default: &str) -> Result<PathBuf, String> {
    match args.iter().position(|a| a == "--out") {
        Some(i) => args.get(i + 1).map(PathBuf::from).ok_or_else(|| "--out needs a directory".to_string()),
        None => Ok(PathBuf::from(default)),
    }
}

/// A sweep that did not cover its band (exit status 3).
const INCOMPLETE: u8 = 3;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let keep_partial = args.iter().any(|a| a == "--keep-partial");
    let result = match args.first().map(String::as_str) {
        None | Some("--help") | Some("-h") | Some("help") => {
            println!("{USAGE}");
            Ok(Outcome::Complete)
        }
        Some("demo") => out_dir(&args, "jprom-demo").and_then(|dir| {
            let study = Study::from_toml_str(DEMO_STUDY).map_err(|e| e.to_string())?;
            run(&study, &dir, keep_partial)
        }),
        Some("run") => match args.get(1) {
            Some(path) if path != "--out" => Study::from_file(std::path::Path::new(path))
                .map_err(|e| e.to_string())
                .and_then(|study| out_dir(&args, &study.output.dir.display().to_string()).and_then(|dir| run(&study, &dir, keep_partial))),
            _ => Err(format!("run needs a study file\n{USAGE}")),
        },
        Some("check") => match args.get(1) {
            Some(path) => Study::from_file(std::path::Path::new(path)).map_err(|e| e.to_string()).map(|s| {
                println!("{path}: valid\n{}", toml::to_string_pretty(&s).unwrap_or_default());
                Outcome::Complete
            }),
            None => Err(format!("check needs a study file\n{USAGE}")),
        },
        Some(other) => Err(format!("unknown command '{other}'\n{USAGE}")),
    };
    match result {
        Ok(Outcome::Complete) => ExitCode::SUCCESS,
        Ok(Outcome::Incomplete(lines)) => {
            eprintln!("jprom: {} sweep(s) did not cover the band (results kept; --keep-partial accepts them):", lines.len());
            for l in lines {
                eprintln!("  {l}");
            }
            ExitCode::from(INCOMPLETE)
        }
        Err(message) => {
            eprintln!("jprom: {message}");
            ExitCode::from(2)
        }
    }
}

enum Outcome {
    Complete,
    /// The sweeps that did not cover their band.
    Incomplete(Vec<String>),
}

fn run(study: &Study, dir: &std::path::Path, keep_partial: bool) -> Result<Outcome, String> {
    let t = std::time::Instant::now();
    let summary = run_study(study, dir, std::io::stderr().is_terminal()).map_err(|e| e.to_string())?;
    print!("{}", summary_table(&summary));
    println!("results in {} ({:.1} s)", dir.display(), t.elapsed().as_secs_f64());
    if summary.incomplete.is_empty() || keep_partial || study.output.keep_partial {
        Ok(Outcome::Complete)
    } else {
        Ok(Outcome::Incomplete(summary.incomplete))
    }
}
