//! The README's claims that can drift: its two commands (the test command is the one `.ci/run`
//! runs, the demo command names this crate's program), every path of its layout table exists,
//! its list of deprecated C functions is the header's, and the demo it describes is the demo study.

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

/// The install and "Use it from ..." sections (issue 15): the install command is the script CI
/// runs, the installed file names carry the workspace version and the soname its major, the
/// CMake targets and pkg-config modules named exist in packaging/, and every packaging/ or
/// fortran/ path named exists.
#[test]
fn install_sections_match_packaging_and_ci() {
    let text = readme();
    let section = |title: &str| -> String {
        let start = text.find(&format!("\n## {title}\n")).unwrap_or_else(|| panic!("README lacks the section {title}"));
        let rest = &text[start + 4..];
        rest[..rest.find("\n## ").unwrap_or(rest.len())].to_string()
    };
    let install = section("Install");
    let usage: String = ["Use it from C++ (CMake)", "Use it from C (pkg-config)", "Use it from Fortran", "Upgrading"].iter().map(|t| section(t)).collect();
    let all = format!("{install}{usage}");

    // the command, and CI runs the same script
    assert!(install.lines().any(|l| l.trim().starts_with("packaging/install.sh --prefix ")), "the install command");
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    assert!(ci.lines().any(|l| l.trim_start().starts_with("packaging/ci-check.sh ")), ".ci/run runs packaging/ci-check.sh");
    let check = std::fs::read_to_string(root().join("packaging/ci-check.sh")).unwrap();
    assert!(check.contains("packaging/install.sh --prefix"), "ci-check.sh installs with packaging/install.sh");

    // versions: the installed names and the soname follow the workspace version
    let toml = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let version = toml.lines().find_map(|l| l.strip_prefix("version = \"")).unwrap().trim_end_matches('"');
    let major = version.split('.').next().unwrap();
    assert!(install.contains(&format!("`lib/libjprom.so.{version}`")), "README install table names lib/libjprom.so.{version}");
    assert!(install.contains(&format!("soname `libjprom.so.{major}`")), "README names the soname libjprom.so.{major}");
    let minor = version.split('.').nth(1).unwrap();
    assert!(usage.contains(&format!("find_package(jprom {major}.{minor} CONFIG REQUIRED)")), "find_package asks for this version");
    let build_rs = std::fs::read_to_string(root().join("crates/jprom-capi/build.rs")).unwrap();
    assert!(build_rs.contains("-Wl,-soname,{soname}") && build_rs.contains("format!(\"libjprom.so.{major}\")"), "build.rs sets the soname from the major version");

    // CMake targets and pkg-config modules named in the README exist
    let config = std::fs::read_to_string(root().join("packaging/jpromConfig.cmake.in")).unwrap();
    let mut targets = 0;
    for piece in all.split("jprom::").skip(1) {
        let name: String = piece.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
        assert!(config.contains(&format!("add_library(jprom::{name} ")), "README names jprom::{name}, which jpromConfig.cmake.in does not define");
        targets += 1;
    }
    assert!(targets >= 4, "CMake targets named: {targets}");
    for line in all.lines().filter(|l| l.contains("pkg-config ")) {
        for piece in line.split("pkg-config ").skip(1) {
            let module = piece.split_whitespace().find(|w| !w.starts_with('-')).map(|w| w.trim_matches(|c: char| !(c.is_ascii_alphanumeric() || c == '-')));
            if let Some(m) = module.filter(|m| m.starts_with("jprom")) {
                assert!(root().join(format!("packaging/{m}.pc.in")).exists(), "README runs pkg-config on {m}, which packaging/ does not install");
            }
        }
    }
    // every path into packaging/ or fortran/ exists
    for piece in all.split('`').skip(1).step_by(2) {
        if piece.starts_with("packaging/") || piece.starts_with("fortran/") {
            let path = piece.split_whitespace().next().unwrap();
            assert!(root().join(path).exists(), "README names {path}, which does not exist");
        }
    }
}

/// Issue 19: the licence files Cargo.toml's `license` names exist and the README points to
/// them; the default output folders of `jprom demo` (main.rs) and of a study (study.rs) are
/// git-ignored, as the README says.
#[test]
fn licence_files_and_ignored_output_folders_are_as_the_readme_says() {
    let toml = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    assert!(toml.lines().any(|l| l.trim() == "license = \"MIT OR Apache-2.0\""), "workspace licence");
    let text = readme();
    let mit = std::fs::read_to_string(root().join("LICENSE-MIT")).unwrap();
    assert!(mit.contains("Permission is hereby granted, free of charge") && mit.contains("Copyright (c) the jprom developers"));
    let apache = std::fs::read_to_string(root().join("LICENSE-APACHE")).unwrap();
    assert!(apache.contains("Apache License") && apache.contains("Version 2.0, January 2004") && apache.contains("END OF TERMS AND CONDITIONS"));
    assert!(text.contains("(LICENSE-APACHE)") && text.contains("(LICENSE-MIT)"), "README links the licence files");

    let ignore = std::fs::read_to_string(root().join(".gitignore")).unwrap();
    let main = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/main.rs")).unwrap();
    let study = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/study.rs")).unwrap();
    assert!(main.contains("PathBuf::from(\"jprom-demo\")"), "the demo's default folder is jprom-demo");
    assert!(study.contains("dir: PathBuf::from(\"jprom-out\")"), "a study's default output.dir is jprom-out");
    for dir in ["jprom-demo", "jprom-out"] {
        assert!(ignore.lines().any(|l| l.trim() == format!("{dir}/")), ".gitignore lacks {dir}/");
        assert!(text.contains(&format!("`{dir}/`")), "README does not name {dir}/");
    }
    // the README's output section names every plot file the runner writes
    let plots = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/study_plots.rs")).unwrap();
    for prefix in ["frf_", "predicted_error_vs_frequency_", "energy_"] {
        assert!(plots.contains(&format!("\"{prefix}alpha_ST_x{{level:e}}.svg\"")), "study_plots.rs writes {prefix}*");
        assert!(text.contains(&format!("`{prefix}*`")), "README does not name {prefix}*");
    }
}

#[test]
fn status_codes_listed_are_the_headers() {
    // "Status codes (fixed values): `OK 0, NULL_ARGUMENT 1, ...`" against `JPROM_X = n` in the
    // header's jprom_status enum: every code, with its value, and no other
    let text = readme();
    let start = text.find("Status codes (fixed values): `").expect("status code list") + "Status codes (fixed values): `".len();
    let list = &text[start..start + text[start..].find('`').unwrap()];
    let listed: Vec<(String, i64)> = list
        .split(',')
        .map(|item| {
            let mut it = item.split_whitespace();
            (format!("JPROM_{}", it.next().unwrap()), it.next().unwrap().parse().unwrap())
        })
        .collect();
    let header = std::fs::read_to_string(root().join("include/jprom.h")).unwrap();
    let end = header.find("} jprom_status;").unwrap();
    let body = &header[header[..end].rfind("typedef enum {").unwrap()..end];
    let declared: Vec<(String, i64)> = body
        .lines()
        .filter_map(|l| {
            let l = l.trim();
            let (name, value) = l.strip_suffix(',')?.split_once(" = ")?;
            Some((name.to_string(), value.parse().ok()?))
        })
        .collect();
    assert!(declared.len() >= 13, "header enum not found: {declared:?}");
    assert_eq!(listed, declared, "README status list vs include/jprom.h");
}

/// The README's description of the demo and of the program: the demo's three levels are the
/// demo study's, `jprom --version` prints this version, and the default response output it
/// names is the code's.
#[test]
fn demo_levels_version_and_response_default_are_the_codes() {
    let text = readme();
    let demo = jprom_cli::study::Study::from_file(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("demo_study.toml")).unwrap();
    let levels = &demo.forcing.levels;
    assert_eq!(levels.len(), 3, "the README names three regimes");
    for (level, words) in levels.iter().zip(["`alpha_ST / 2`", "`alpha_ST / 20`", "`alpha_ST / 3000`"]) {
        let divisor: f64 = words.trim_matches('`').rsplit(' ').next().unwrap().parse().unwrap();
        assert!((level * divisor - 1.0).abs() < 1e-3, "demo level {level} vs README {words}");
        assert!(text.contains(words), "README names {words}");
    }
    assert!(text.contains(&format!("jprom --version                # jprom {}", env!("CARGO_PKG_VERSION"))), "README's --version line");
    let default = jprom_cli::study::BLADE_TIP_FLAP_OUTPUT;
    assert!(text.contains(&format!("| `output.response` | blade: {default}, FE: 0 |")), "README's output.response default");
}

/// The README's study-file key table (`| key | default | meaning |`) against the code, for the
/// sections with defaults (`band`, `hbm`, `forcing`, `basis`, `solvers`, `output`): every key it
/// lists is one a study file accepts (a study setting it to the README's default parses), every
/// default it gives is the code's, and every key of those sections is named in the README.
#[test]
fn study_key_table_defaults_and_keys_are_the_codes() {
    use jprom_cli::study::{BandSpec, BasisSpec, ForcingSpec, HbmSpec, OutputSpec, SolverSpec, Study};
    let text = readme();
    let table = text.split("| key | default | meaning |").nth(1).expect("the study key table").split("\n\n").next().unwrap();
    let defaults: Vec<(&str, serde_json::Value)> = vec![
        ("band", serde_json::to_value(BandSpec::default()).unwrap()),
        ("hbm", serde_json::to_value(HbmSpec::default()).unwrap()),
        ("forcing", serde_json::to_value(ForcingSpec::default()).unwrap()),
        ("basis", serde_json::to_value(BasisSpec::default()).unwrap()),
        ("solvers", serde_json::to_value(SolverSpec::default()).unwrap()),
        ("output", serde_json::to_value(OutputSpec::default()).unwrap()),
    ];
    // a README value as TOML (numbers, booleans, quoted strings, lists)
    let parse = |cell: &str| -> toml::Value { toml::from_str::<toml::Table>(&format!("v = {cell}")).unwrap_or_else(|e| panic!("README default {cell:?}: {e}"))["v"].clone() };
    let same = |readme: &toml::Value, code: Option<&serde_json::Value>| -> bool {
        match (readme, code) {
            (toml::Value::Array(a), None) => a.is_empty(),
            (toml::Value::Array(a), Some(serde_json::Value::Array(b))) => a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.as_float().or(x.as_integer().map(|i| i as f64)) == y.as_f64()),
            (toml::Value::Float(x), Some(y)) => y.as_f64().is_some_and(|y| (x - y).abs() <= 1e-12 * y.abs()),
            (toml::Value::Integer(x), Some(y)) => y.as_f64() == Some(*x as f64),
            (toml::Value::Boolean(x), Some(y)) => y.as_bool() == Some(*x),
            (toml::Value::String(x), Some(y)) => y.as_str() == Some(x.as_str()),
            _ => false,
        }
    };
    let mut checked = 0;
    for line in table.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.split(" | ").collect();
        let key = cells[0].trim_start_matches("| ").trim_matches('`');
        let Some((section, names)) = key.split_once('.') else { continue };
        let Some((_, code)) = defaults.iter().find(|(s, _)| *s == section) else { continue };
        let names: Vec<&str> = names.trim_start_matches('{').trim_end_matches('}').split(',').collect();
        let cell = cells[1].trim();
        if cell == "—" || cell.contains(':') {
            continue;
        }
        // one value per name, or one for all
        let values: Vec<&str> = if names.len() == 1 { vec![cell] } else { cell.split(", ").collect() };
        assert!(values.len() == names.len() || values.len() == 1, "README row {key}: {} names, defaults {cell}", names.len());
        for (i, name) in names.iter().enumerate() {
            let value = values[if values.len() == 1 { 0 } else { i }];
            let readme_value = parse(value);
            assert!(same(&readme_value, code.get(name)), "README default of {section}.{name} is {value}, the code's is {:?}", code.get(name));
            let study = format!("[model]\nkind = \"blade\"\n[{section}]\n{name} = {value}\n");
            Study::from_toml_str(&study).unwrap_or_else(|e| panic!("README key {section}.{name} = {value} is not accepted: {e}"));
            checked += 1;
        }
    }
    assert!(checked >= 15, "only {checked} keys checked: did the table's format change?");
    // every key of these sections appears in the README (in the table or the text around it)
    let named = |section: &str, name: &str| {
        text.contains(&format!("`{section}.{name}`")) || text.lines().any(|l| l.contains(&format!("`{section}.{{")) && l.split('`').any(|k| k.starts_with(&format!("{section}.{{")) && k.trim_start_matches(&format!("{section}.{{")).trim_end_matches('}').split(',').any(|n| n == name)))
    };
    let missing: Vec<String> = defaults.iter().flat_map(|(section, code)| code.as_object().unwrap().keys().filter(|name| !named(section, name)).map(move |name| format!("{section}.{name}"))).collect();
    assert!(missing.is_empty(), "study keys not in the README: {missing:?}");
}
