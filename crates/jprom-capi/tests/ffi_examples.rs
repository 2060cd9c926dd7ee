//! The C, C++ and Fortran examples compile with -Wall -Werror / -Wall -std=f2008, run, and print the
//! same numbers as the Rust API for the same model (issue 3, acceptance 1), for the full-order
//! sweep and for the JP workflow (self-correcting NLR sweep with e*_1 per point); a C program checks
//! every documented error status (acceptance 2); a C program takes the address of every
//! function in the header (acceptance 4).

use jprom_testkit::native;
use jprom_testkit::chain as jp_support;

use jprom::condensation::CondensedSystem;
use jprom::hbm::{sweep, HbmOptions, SweepOptions};
use jprom::jp::PredictionOptions;
use jprom::rom::{adaptive_sweep, AdaptiveOptions, RomKind};
use jp_support::examples_model;
use native::*;
use std::ops::ControlFlow;

/// The examples' model and sweeps, through the Rust API: the full-order rows (index, omega,
/// |X1| node 0 x, |X1| node 1 x), then the rows of the self-correcting NLR sweep with the
/// default JP settings (index, omega, |X1| node 0 x, |X1| node 1 x, e*_1); and the
/// self-correcting sweep's static contact displacement error
/// ([`jprom::rom::AdaptiveSweep::worst_static_error`]).
fn rust_table_and_static_error() -> (Vec<Vec<f64>>, Option<f64>, String) {
    let model = examples_model();
    let opts = HbmOptions::default();
    let sys = CondensedSystem::new(&model, 3).unwrap();
    let res = sweep(&sys, &SweepOptions::band(60.0, 160.0), &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    let mut rows: Vec<Vec<f64>> =
        res.points.iter().enumerate().map(|(i, p)| vec![i as f64, p.omega, p.output_amplitude(1, 0), p.output_amplitude(1, 1)]).collect();
    assert!(rows.len() > 20, "too few full-order points");
    let pred = PredictionOptions::new((60.0, 160.0));
    let jp = adaptive_sweep(&model, 3, &pred, &SweepOptions::band(60.0, 160.0), &opts, &AdaptiveOptions { kind: RomKind::Nlr, ..AdaptiveOptions::default() }).unwrap();
    assert!(jp.sweep.points.len() > 20, "too few JP points");
    rows.extend(jp.sweep.points.iter().zip(&jp.predicted_errors).enumerate().map(|(i, (p, e))| {
        vec![i as f64, p.omega, p.output_amplitude(1, 0), p.output_amplitude(1, 1), e[1]]
    }));
    let trust = match &jp.trust.reason {
        None => "# JP: trusted: yes".to_string(),
        Some(why) => format!("# JP: trusted: no: {why}"),
    };
    (rows, jp.worst_static_error(), trust)
}

/// `e*_1` below this is round-off (the threshold of a poor basis is 0.05).
const E_STAR_ROUND_OFF: f64 = 1e-9;

fn assert_same_table(what: &str, got: &[Vec<f64>], expect: &[Vec<f64>]) {
    assert_eq!(got.len(), expect.len(), "{what}: number of points");
    assert!(got.len() > 20, "{what}: too few points");
    for (g, e) in got.iter().zip(expect) {
        assert_eq!(g.len(), e.len(), "{what}: row {g:?} vs {e:?}");
        for (k, (a, b)) in g.iter().zip(e).enumerate() {
            // The examples print 11 significant digits. e*_1 (column 4 of the JP rows) of an
            // exact basis is round-off, 1e-15 to 1e-12 depending on the summation order of the
            // parallel products; below 1e-9 both sides count as zero.
            let round_off = k == 4 && a.abs().max(b.abs()) < E_STAR_ROUND_OFF;
            assert!(round_off || (a - b).abs() <= 1e-9 * b.abs().max(1e-12), "{what}: {g:?} vs {e:?}");
        }
    }
}

#[test]
fn c_cpp_and_fortran_examples_print_the_rust_numbers() {
    let (expect, rust_static, rust_trust) = rust_table_and_static_error();
    let c = compile_c(&[&root().join("examples-c/sweep_example.c")], "sweep_example_c", &[]);
    let c_out = run(&c);
    assert_same_table("C example", &table(&c_out), &expect);
    let n_full = expect.iter().filter(|r| r.len() == 4).count();
    assert!(c_out.contains(&format!("({n_full} reported by the callback)")), "{c_out}");
    assert!(c_out.contains("# JP: self-correcting NLR sweep"), "{c_out}");
    assert!(c_out.lines().any(|l| l == rust_trust), "the C example's verdict is not Rust's ({rust_trust}): {c_out}");
    let cpp = compile_cpp(&[&root().join("examples-c/cpp_raii.cpp")], "cpp_raii");
    let cpp_out = run(&cpp);
    assert_same_table("C++ RAII example", &table(&cpp_out), &expect);
    assert!(cpp_out.contains("out-of-range point rejected"), "{cpp_out}");
    // both report the static term's error of the self-correcting sweep, the same value
    let static_line = |out: &str| out.lines().find(|l| l.starts_with("# JP: static contact displacement error")).map(str::to_string);
    let (c_static, cpp_static) = (static_line(&c_out), static_line(&cpp_out));
    assert!(c_static.is_some(), "the C example does not print the static error: {c_out}");
    assert_eq!(c_static, cpp_static, "C and C++ static errors differ");
    let value: f64 = c_static.unwrap().rsplit(' ').next().unwrap().parse().expect("a number");
    let rust_static = rust_static.expect("the Rust sweep has checks");
    // 7 significant digits printed; below 1e-9 both are round-off of an exact static term
    assert!((value - rust_static).abs() <= 1e-6 * rust_static || value.max(rust_static) < 1e-9, "static error: C {value:e}, Rust {rust_static:e}");
    if have_gfortran() {
        let f = compile_fortran(&[&root().join("fortran/jprom.f90"), &root().join("examples-fortran/sweep_example.f90")], "sweep_example_f90");
        assert_same_table("Fortran example", &table(&run(&f)), &expect);
    }
}

#[test]
fn c_program_gets_documented_statuses_for_bad_input() {
    let exe = compile_c(&[&root().join("crates/jprom-capi/tests/c/bad_input.c")], "bad_input", &[]);
    let out = run(&exe);
    assert!(out.contains("all checks passed"), "{out}");
    // every check printed its status and message
    let checks = out.lines().filter(|l| l.starts_with("ok ")).count();
    assert!(checks >= 12, "{out}");
}

/// `jprom_*` functions exported by the shared library (`nm -D --defined-only`).
fn exported_functions(lib: &std::path::Path) -> Vec<String> {
    let o = std::process::Command::new("nm").args(["-D", "--defined-only"]).arg(lib).output().expect("run nm");
    assert!(o.status.success(), "nm failed: {}", String::from_utf8_lossy(&o.stderr));
    let mut names: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter_map(|l| {
            let mut f = l.split_whitespace();
            let (kind, name) = (f.nth(1)?, f.next()?);
            (kind == "T" && name.starts_with("jprom_")).then(|| name.to_string())
        })
        .collect();
    names.sort();
    names.dedup();
    names
}

#[test]
fn every_header_function_links() {
    let header = std::fs::read_to_string(root().join("include/jprom.h")).unwrap();
    let names = header_functions(&header);
    for must in ["jprom_version", "jprom_last_error_message", "jprom_status_name", "jprom_model_new", "jprom_sweep"] {
        assert!(names.iter().any(|n| n == must), "parser missed {must}: {names:?}");
    }
    assert!(names.len() >= 40, "found only {} functions: {names:?}", names.len());
    // the header and the library agree exactly: nothing exported undeclared, nothing declared missing
    let exported = exported_functions(&lib_dir().join("libjprom.so"));
    assert_eq!(names, exported, "functions declared in include/jprom.h vs exported by libjprom.so");
    // and a C program can take the address of each one (links against the library)
    let mut src = String::from("#include <stdio.h>\n#define JPROM_NO_DEPRECATION_WARNINGS /* every function links, the deprecated ones too */\n#include \"jprom.h\"\ntypedef void (*any_fn)(void);\nint main(void) {\n    any_fn fns[] = {\n");
    for n in &names {
        src.push_str(&format!("        (any_fn)&{n},\n"));
    }
    src.push_str("    };\n    size_t n = 0;\n    for (size_t i = 0; i < sizeof fns / sizeof fns[0]; ++i) n += fns[i] != NULL;\n    printf(\"%zu\\n\", n);\n    return 0;\n}\n");
    let dir = root().join("target/native-tests");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("link_all.c");
    std::fs::write(&file, src).unwrap();
    let exe = compile_c(&[&file], "link_all", &[]);
    let out = run(&exe);
    assert_eq!(out.trim().parse::<usize>().unwrap(), names.len());
}
