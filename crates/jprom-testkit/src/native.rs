// Building the C library and compiling C and Fortran programs against it, for the FFI tests
// (included with `#[path]`).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The repository's root (the workspace).
pub fn root() -> PathBuf {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    here.parent().and_then(|p| p.parent()).map(PathBuf::from).unwrap_or(here)
}

/// `target/debug`, after making sure `libjprom.so` and `libjprom.a` are built from the current
/// sources (the C API crate's library is not built by `cargo test`). Runs
/// `cargo build --workspace --lib --tests` once per test binary: with the tests in the build,
/// Cargo resolves the dependencies' features as `cargo test` does, so nothing but the C library
/// itself is compiled again (`cargo build -p jprom-capi` alone would build every dependency a
/// second time with other features).
pub fn lib_dir() -> PathBuf {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT
        .get_or_init(|| {
            let out = Command::new(env!("CARGO")).args(["build", "--workspace", "--lib", "--tests"]).current_dir(root()).output().expect("run cargo build --workspace --lib --tests");
            assert!(out.status.success(), "cargo build --workspace --lib --tests failed:\n{}", String::from_utf8_lossy(&out.stderr));
            let target = std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| root().join("target"));
            target.join("debug")
        })
        .clone()
}

fn scratch(name: &str) -> PathBuf {
    let d = root().join("target").join("native-tests");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// Compiles C sources with `-Wall -Werror -std=c11` against the shared library.
pub fn compile_c(sources: &[&Path], exe: &str, extra: &[&str]) -> PathBuf {
    let lib = lib_dir();
    let out = scratch(exe);
    let mut cmd = Command::new("gcc");
    // include directories in `extra` come first, so that a test can compile against another header
    let (includes, others): (Vec<&str>, Vec<&str>) = extra.iter().partition(|a| a.starts_with("-I"));
    cmd.args(["-Wall", "-Werror", "-std=c11", "-O1"]).args(includes).arg(format!("-I{}", root().join("include").display()));
    cmd.args(sources).args(others).arg("-o").arg(&out);
    cmd.arg(format!("-L{}", lib.display())).arg("-ljprom").arg(format!("-Wl,-rpath,{}", lib.display())).args(["-lm", "-lpthread"]);
    let o = cmd.output().expect("run gcc");
    assert!(o.status.success(), "gcc failed:\n{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// Compiles C++ sources with `-Wall -Werror -std=c++17` against the shared library.
pub fn compile_cpp(sources: &[&Path], exe: &str) -> PathBuf {
    let lib = lib_dir();
    let out = scratch(exe);
    let o = Command::new("g++")
        .args(["-Wall", "-Werror", "-std=c++17", "-O1"])
        .arg(format!("-I{}", root().join("include").display()))
        .args(sources)
        .arg("-o")
        .arg(&out)
        .arg(format!("-L{}", lib.display()))
        .arg("-ljprom")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .output()
        .expect("run g++");
    assert!(o.status.success(), "g++ failed:\n{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// Whether gfortran can be used; under CI (CI=true) its absence is a failure, elsewhere the
/// Fortran checks are skipped with a notice.
pub fn have_gfortran() -> bool {
    let ok = Command::new("gfortran").arg("--version").output().map(|o| o.status.success()).unwrap_or(false);
    if !ok {
        assert!(std::env::var("CI").map(|v| v != "true").unwrap_or(true), "gfortran is required under CI (.ci/run installs it)");
        eprintln!("NOTICE: gfortran not found, Fortran example not checked");
    }
    ok
}

/// Compiles the Fortran module and a program with `-Wall -std=f2008` against the shared library.
pub fn compile_fortran(sources: &[&Path], exe: &str) -> PathBuf {
    let lib = lib_dir();
    let out = scratch(exe);
    let moddir = scratch(&format!("{exe}-mod"));
    std::fs::create_dir_all(&moddir).unwrap();
    let o = Command::new("gfortran")
        .args(["-Wall", "-std=f2008", "-J"])
        .arg(&moddir)
        .args(sources)
        .arg("-o")
        .arg(&out)
        .arg(format!("-L{}", lib.display()))
        .arg("-ljprom")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .output()
        .expect("run gfortran");
    assert!(o.status.success(), "gfortran failed:\n{}", String::from_utf8_lossy(&o.stderr));
    let warnings = String::from_utf8_lossy(&o.stderr);
    assert!(!warnings.contains("Warning"), "gfortran warnings:\n{warnings}");
    out
}

/// Names of the functions declared in the header: every identifier `jprom_*` directly followed
/// by `(` once comments are removed (callback typedefs read `(*jprom_x_fn)(`, so are not taken).
pub fn header_functions(header: &str) -> Vec<String> {
    let mut code = String::new();
    let mut rest = header;
    while let Some(i) = rest.find("/*") {
        code.push_str(&rest[..i]);
        rest = rest[i..].find("*/").map(|j| &rest[i + j + 2..]).unwrap_or("");
    }
    code.push_str(rest);
    let code: String = code.lines().map(|l| l.split("//").next().unwrap()).collect::<Vec<_>>().join("\n");
    let bytes = code.as_bytes();
    let mut names = Vec::new();
    let mut i = 0;
    while let Some(off) = code[i..].find("jprom_") {
        let start = i + off;
        let mut end = start;
        while end < bytes.len() && (bytes[end].is_ascii_alphanumeric() || bytes[end] == b'_') {
            end += 1;
        }
        let word_start = start == 0 || !(bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_');
        if word_start && bytes.get(end) == Some(&b'(') {
            names.push(code[start..end].to_string());
        }
        i = end.max(start + 1);
    }
    names.sort();
    names.dedup();
    names
}

/// Runs a program, asserts exit code 0, returns stdout.
pub fn run(exe: &Path) -> String {
    let o = Command::new(exe).output().expect("run program");
    assert!(o.status.success(), "{} failed ({:?}):\n{}\n{}", exe.display(), o.status, String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

/// Rows of numbers of a table printed by the examples (comment lines skipped).
pub fn table(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|t| t.parse::<f64>().unwrap_or_else(|_| panic!("bad number '{t}' in '{l}'"))).collect())
        .collect()
}
