//! The README's claims that can drift: its two commands (the test command is the one `.ci/run`
//! runs, the demo command names this crate's program), every path of its layout table exists,
//! and its list of deprecated C functions is the header's.

use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

#[test]
fn the_two_commands_are_the_ones_ci_and_this_crate_run() {
    let text = readme();
    let commands: Vec<&str> = text.lines().filter(|l| l.starts_with("    cargo ")).map(str::trim).take(2).collect();
    assert_eq!(commands, ["cargo run -p jprom-cli -- demo", "cargo test"], "the first two commands of the README");
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    assert!(ci.lines().any(|l| l.trim() == "cargo test"), ".ci/run runs the README's test command");
    // the demo command runs this package's `jprom` program, whose `demo` subcommand exists
    assert_eq!(env!("CARGO_PKG_NAME"), "jprom-cli");
    let main = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/main.rs")).unwrap();
    assert!(main.contains("\"demo\""), "jprom has a demo subcommand");
}

#[test]
fn every_path_of_the_layout_table_exists() {
    let text = readme();
    let table = text.split("## Layout").nth(1).unwrap().split("\n## ").next().unwrap();
    let mut crate_dir = PathBuf::new();
    let mut checked = 0;
    for line in table.lines().filter(|l| l.starts_with("| `")) {
        let cell = line.split('|').nth(1).unwrap().trim();
        for path in cell.split(", ").map(|p| p.trim().trim_matches('`').trim()) {
            let full = if path.starts_with("src/") { root().join(&crate_dir).join(path) } else { root().join(path) };
            assert!(full.exists(), "README layout: {path} ({}) does not exist", full.display());
            if path.starts_with("crates/") && !path.contains("/benches") {
                crate_dir = PathBuf::from(path);
            }
            checked += 1;
        }
    }
    assert!(checked >= 15, "only {checked} layout paths found");
}

#[test]
fn deprecated_functions_listed_are_the_headers() {
    let header = std::fs::read_to_string(root().join("include/jprom.h")).unwrap();
    let mut in_header: Vec<String> = Vec::new();
    let lines: Vec<&str> = header.lines().collect();
    for (i, l) in lines.iter().enumerate() {
        if l.starts_with("JPROM_DEPRECATED(") {
            let decl = lines[i + 1];
            let name = decl.split('(').next().unwrap().split_whitespace().last().unwrap().trim_start_matches('*');
            in_header.push(name.to_string());
        }
    }
    let text = readme();
    let listed = text.split("Deprecated so far:").nth(1).expect("the README lists the deprecated functions");
    let listed = listed.split('.').next().unwrap();
    for name in &in_header {
        assert!(listed.contains(&format!("`{name}`")), "{name} is deprecated in the header but not listed in the README");
    }
    assert!(!in_header.is_empty());
}
