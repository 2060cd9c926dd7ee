//! Gives the shared library its soname, `libjprom.so.<MAJOR>` (Linux), as a C library has it:
//! programs linked against `libjprom.so` record `libjprom.so.<MAJOR>` and keep working with any
//! later library of the same major version (README, "Upgrading"). For 0.x the major is 0: the C
//! ABI only grows within 0.x (0.2 runs programs built against the 0.1 header,
//! tests/abi_growth.rs), so every 0.x library is `libjprom.so.0`.
//!
//! Cargo names the built file `libjprom.so`; a program linked against it in the build tree
//! looks for its soname at run time, so this also puts the link `libjprom.so.<MAJOR> ->
//! libjprom.so` next to it (target/<profile>/). `packaging/install.sh` installs the real
//! layout: libjprom.so.MAJOR.MINOR.PATCH, libjprom.so.MAJOR and libjprom.so.
//!
//! No version script is needed: rustc already links a cdylib with one that exports only the
//! `#[no_mangle] extern "C"` functions (`nm -D --defined-only` lists only `jprom_*`, checked by
//! tests/ffi_examples.rs and packaging/ci-check.sh).

use std::path::{Path, PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("linux") {
        return;
    }
    let major = std::env::var("CARGO_PKG_VERSION_MAJOR").expect("cargo sets CARGO_PKG_VERSION_MAJOR");
    let soname = format!("libjprom.so.{major}");
    println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,{soname}");
    // OUT_DIR is <target>/[<triple>/]<profile>/build/jprom-capi-<hash>/out: the library goes
    // to the <profile> directory three levels up.
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    match out_dir.ancestors().nth(3) {
        Some(profile_dir) if profile_dir.join("build").is_dir() => link_soname(profile_dir, &soname),
        _ => println!("cargo:warning=jprom-capi: unexpected OUT_DIR {}, no {soname} link made", out_dir.display()),
    }
}

/// `<dir>/<soname> -> libjprom.so` (relative), replacing whatever is there.
fn link_soname(dir: &Path, soname: &str) {
    let link = dir.join(soname);
    if std::fs::read_link(&link).map(|t| t == Path::new("libjprom.so")).unwrap_or(false) {
        return;
    }
    let _ = std::fs::remove_file(&link);
    if let Err(e) = std::os::unix::fs::symlink("libjprom.so", &link) {
        println!("cargo:warning=jprom-capi: could not link {} -> libjprom.so: {e}", link.display());
    }
}
