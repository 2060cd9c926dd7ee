//! The checked-in C header `include/jprom.h` is exactly what cbindgen generates from this
//! crate (`crates/jprom-capi`, the only place with `extern "C"`), and its version macros match
//! the workspace's Cargo.toml.
//!
//! Regenerate the header with `JPROM_REGENERATE_HEADER=1 cargo test -p jprom-capi --test ffi_header`.

use std::path::PathBuf;

/// This crate's directory.
fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The repository's root.
fn root() -> PathBuf {
    crate_dir().join("../..")
}

fn generate() -> String {
    let config = cbindgen::Config::from_file(crate_dir().join("cbindgen.toml")).expect("read cbindgen.toml");
    let bindings = cbindgen::Builder::new()
        .with_crate(crate_dir())
        .with_config(config)
        .generate()
        .expect("cbindgen failed to generate the header");
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("header is UTF-8")
}

#[test]
fn header_is_up_to_date() {
    let path = root().join("include/jprom.h");
    let fresh = generate();
    if std::env::var_os("JPROM_REGENERATE_HEADER").is_some() {
        std::fs::write(&path, &fresh).expect("write include/jprom.h");
        eprintln!("regenerated {}", path.display());
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    if checked_in != fresh {
        let first_diff = checked_in
            .lines()
            .zip(fresh.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| checked_in.lines().count().min(fresh.lines().count()));
        panic!(
            "include/jprom.h is out of date with crates/jprom-capi/src (first difference at line {}).\n\
             Regenerate it with:  JPROM_REGENERATE_HEADER=1 cargo test -p jprom-capi --test ffi_header\n\
             and commit the result.",
            first_diff + 1
        );
    }
}

fn define(header: &str, name: &str) -> u64 {
    let line = header
        .lines()
        .find(|l| l.starts_with(&format!("#define {name} ")))
        .unwrap_or_else(|| panic!("header lacks #define {name}"));
    line.split_whitespace().nth(2).unwrap().trim_end_matches('u').trim_end_matches('U').parse().unwrap()
}

#[test]
fn version_macros_match_cargo_toml() {
    let header = std::fs::read_to_string(root().join("include/jprom.h")).unwrap();
    // Read Cargo.toml itself rather than env!(), so the check is against the file.
    let toml = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let version = toml
        .lines()
        .find_map(|l| l.strip_prefix("version = \""))
        .map(|v| v.trim_end_matches('"').to_string())
        .expect("version in Cargo.toml");
    let parts: Vec<u64> = version.split('.').map(|p| p.parse().unwrap()).collect();
    assert_eq!(define(&header, "JPROM_VERSION_MAJOR"), parts[0], "JPROM_VERSION_MAJOR vs Cargo.toml {version}");
    assert_eq!(define(&header, "JPROM_VERSION_MINOR"), parts[1], "JPROM_VERSION_MINOR vs Cargo.toml {version}");
    assert_eq!(define(&header, "JPROM_VERSION_PATCH"), parts[2], "JPROM_VERSION_PATCH vs Cargo.toml {version}");
    // the library's own jprom_version() is checked against the same version by the C examples
    assert_eq!(env!("CARGO_PKG_VERSION"), version, "this crate's version vs the workspace's");
}

#[test]
fn header_exports_only_prefixed_names() {
    let header = std::fs::read_to_string(root().join("include/jprom.h")).unwrap();
    for line in header.lines() {
        if let Some(rest) = line.strip_prefix("#define ") {
            let name = rest.split_whitespace().next().unwrap();
            // constants are JPROM_*; the function-like macros are the jprom_*_options_default
            // of the header's trailer (see the ABI policy)
            let function_like = name.starts_with("jprom_") && name.ends_with("_options_default(out)");
            assert!(name.starts_with("JPROM_") || function_like, "unprefixed macro in the C API: {name} (add it to cbindgen.toml's exclude list)");
        }
        // every type name the header declares: `typedef struct X X;`, `} X;`, `typedef ... (*X)(`
        let mut declared: Vec<&str> = Vec::new();
        if let Some(rest) = line.strip_prefix("typedef struct ") {
            declared.extend(rest.trim_end_matches(';').split_whitespace());
        } else if let Some(rest) = line.strip_prefix("} ") {
            declared.push(rest.trim_end_matches(';').trim());
        } else if line.starts_with("typedef ") {
            if let Some(i) = line.find("(*") {
                declared.push(line[i + 2..].split(')').next().unwrap());
            }
        }
        let identifier = |n: &str| !n.is_empty() && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        for name in declared.into_iter().filter(|n| identifier(n)) {
            assert!(name.starts_with("jprom_"), "unprefixed type in the C API: {name} (add it to cbindgen.toml's exclude list)");
        }
    }
}
