//! The ABI grows without breaking callers (README, "ABI policy"):
//! - the C example compiled against the header of jprom 0.1 (`tests/abi/jprom-0.1/jprom.h`, kept
//!   unchanged) and linked with today's library prints the same table as when compiled against
//!   today's header;
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
    let example = root().join("examples-c/sweep_example.c");
    let old_header = crate_dir().join("tests/abi/jprom-0.1");
    let old = compile_c(&[&example], "sweep_example_0_1_header", &[&format!("-I{}", old_header.display())]);
    let new = compile_c(&[&example], "sweep_example_current_header", &[]);
    let (old_out, new_out) = (run(&old), run(&new));
    assert!(rows(&new_out).len() > 40, "{new_out}");
    assert_eq!(rows(&old_out), rows(&new_out), "the 0.1 caller prints another table");
    let old_header_text = std::fs::read_to_string(old_header.join("jprom.h")).unwrap();
    assert!(old_header_text.contains("#define JPROM_VERSION_MINOR 1") && !old_header_text.contains("max_omega_step"));
}

#[test]
fn version_1_options_struct_is_read_and_unknown_sizes_refused() {
    let exe = compile_c(&[&crate_dir().join("tests/c/abi_sizes.c")], "abi_sizes", &[]);
    let out = run(&exe);
    println!("{out}");
    assert!(out.ends_with("ok\n"), "{out}");
}
