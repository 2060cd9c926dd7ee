//! The ABI grows without breaking callers (README, "ABI policy"):
//! - the C example of jprom 0.1 (`tests/abi/caller-0.1/`, not beside a header: `#include
//!   "jprom.h"` would find that one first) compiled against the header of jprom 0.1
//!   (`tests/abi/jprom-0.1/`), both kept unchanged (the example calls the `jprom_sweep_*` names
//!   that 0.3 deprecated), and linked with today's library prints the same table as today's
//!   example (`examples-c/sweep_example.c`, on the `jprom_sweep_result_*` names); the 0.1
//!   caller also compiles against today's header, where its old names are marked deprecated
//!   (a warning, silenced by `JPROM_NO_DEPRECATION_WARNINGS`);
//! - a caller of version 1 of `jprom_sweep_options` (a smaller `struct_size`) gets the same
//!   sweep, the new fields act only for callers that set them, and a size of no released
//!   version is refused (`tests/c/abi_sizes.c`).

use jprom_testkit::native::*;
use std::process::Command;

fn crate_dir() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(exe: &std::path::Path) -> String {
    let out = Command::new(exe).output().expect("run");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{} failed:\n{text}{}", exe.display(), String::from_utf8_lossy(&out.stderr));
    text
}

/// The table rows (comment lines carry the version and are left out).
fn rows(text: &str) -> Vec<&str> {
    text.lines().filter(|l| !l.starts_with('#')).collect()
}

#[test]
fn example_compiled_against_the_0_1_header_runs_unchanged() {
    let old_dir = crate_dir().join("tests/abi/jprom-0.1");
    let old_example = crate_dir().join("tests/abi/caller-0.1/sweep_example.c");
    let old = compile_c(&[&old_example], "sweep_example_0_1_header", &[&format!("-I{}", old_dir.display())]);
    let old_today = compile_c(&[&old_example], "sweep_example_0_1_current_header", &["-DJPROM_NO_DEPRECATION_WARNINGS"]);
    let new = compile_c(&[&root().join("examples-c/sweep_example.c")], "sweep_example_current_header", &[]);
    let (old_out, old_today_out, new_out) = (run(&old), run(&old_today), run(&new));
    assert!(rows(&new_out).len() > 40, "{new_out}");
    assert_eq!(rows(&old_out), rows(&new_out), "the 0.1 caller prints another table");
    assert_eq!(rows(&old_today_out), rows(&new_out), "the 0.1 caller built on today's header prints another table");
    let old_header_text = std::fs::read_to_string(old_dir.join("jprom.h")).unwrap();
    assert!(old_header_text.contains("#define JPROM_VERSION_MINOR 1") && !old_header_text.contains("max_omega_step"));
    let old_source = std::fs::read_to_string(&old_example).unwrap();
    assert!(old_source.contains("jprom_sweep_n_points(") && !old_source.contains("jprom_sweep_result_n_points"), "the 0.1 caller must keep the 0.1 names");
}

/// Today's header marks the 0.1 names deprecated: the 0.1 caller built with `-Werror` and no
/// `JPROM_NO_DEPRECATION_WARNINGS` fails, naming the replacement.
#[test]
fn the_0_1_names_are_marked_deprecated_in_todays_header() {
    let include = root().join("include");
    let o = Command::new("gcc")
        .args(["-Wall", "-Werror", "-std=c11", "-fsyntax-only"])
        .arg(format!("-I{}", include.display()))
        .arg(crate_dir().join("tests/abi/caller-0.1/sweep_example.c"))
        .output()
        .expect("run gcc");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "the deprecated names compiled without a warning");
    assert!(err.contains("jprom_sweep_n_points") && err.contains("use jprom_sweep_result_n_points"), "{err}");
}

#[test]
fn version_1_options_struct_is_read_and_unknown_sizes_refused() {
    let exe = compile_c(&[&crate_dir().join("tests/c/abi_sizes.c")], "abi_sizes", &[]);
    let out = run(&exe);
    println!("{out}");
    assert!(out.ends_with("ok\n"), "{out}");
}
