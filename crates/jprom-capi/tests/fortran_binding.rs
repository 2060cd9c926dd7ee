//! The Fortran binding `fortran/jprom.f90` covers the whole C API and stays in step with the
//! header (issue 15):
//! - every function of `include/jprom.h` has a `bind(C, name="...")` interface in module
//!   `jprom_c`, and nothing is bound that the header does not declare;
//! - every constant of the header (status codes, enum values, caps, options' V1 sizes) has the
//!   same value in Fortran, and the options types have the header structs' fields, in order,
//!   with the matching kinds;
//! - `tests/fortran/binding.f90` calls every wrapper of module `jprom` and checks each against
//!   another route to the same number (dense vs 1-based CSC, saved vs loaded, sweep point vs
//!   copied solution, a Craig-Bampton reduction keeping every mode vs the model itself).

use jprom_testkit::native::*;
use std::collections::BTreeMap;

fn binding() -> String {
    std::fs::read_to_string(root().join("fortran/jprom.f90")).unwrap()
}

fn header() -> String {
    std::fs::read_to_string(root().join("include/jprom.h")).unwrap()
}

/// Fortran source without comments (`!` to the end of the line; the binding has no `!` in strings).
fn fortran_code(src: &str) -> String {
    src.lines().map(|l| l.split('!').next().unwrap()).collect::<Vec<_>>().join("\n")
}

#[test]
fn every_header_function_has_a_fortran_interface() {
    let declared = header_functions(&header());
    assert!(declared.len() >= 80, "header parser found only {} functions", declared.len());
    let code = fortran_code(&binding());
    let mut bound: Vec<String> = code
        .split("bind(C, name=\"")
        .skip(1)
        .map(|rest| rest.split('"').next().unwrap().to_string())
        .filter(|name| name != "strlen") // the C library's, to read the strings jprom returns
        .collect();
    bound.sort();
    let n_bound = bound.len();
    bound.dedup();
    assert_eq!(n_bound, bound.len(), "a C function is bound twice in fortran/jprom.f90");
    let missing: Vec<&String> = declared.iter().filter(|f| !bound.contains(f)).collect();
    let unknown: Vec<&String> = bound.iter().filter(|f| !declared.contains(f)).collect();
    assert!(
        missing.is_empty(),
        "C functions without a Fortran interface (add a bind(C) interface to module jprom_c in fortran/jprom.f90, \
         and a jp_* wrapper to module jprom where it helps): {missing:?}"
    );
    assert!(unknown.is_empty(), "fortran/jprom.f90 binds functions include/jprom.h does not declare: {unknown:?}");
}

/// `NAME = value` of every `JPROM_*` constant in the header: `#define JPROM_X 72` and enum
/// lines `  JPROM_X = 3,`; the version macros are left out (Fortran asks `jp_version()`).
fn header_constants(header: &str) -> BTreeMap<String, i64> {
    let mut out = BTreeMap::new();
    for line in header.lines() {
        let (name, value) = if let Some(rest) = line.strip_prefix("#define JPROM_") {
            let mut f = rest.split_whitespace();
            match (f.next(), f.next()) {
                (Some(n), Some(v)) => (format!("JPROM_{n}"), v),
                _ => continue,
            }
        } else if let Some(rest) = line.trim().strip_prefix("JPROM_") {
            match rest.split_once(" = ") {
                Some((n, v)) => (format!("JPROM_{n}"), v.trim_end_matches(',')),
                None => continue,
            }
        } else {
            continue;
        };
        if name.starts_with("JPROM_VERSION_") || name == "JPROM_H" {
            continue;
        }
        if let Ok(v) = value.trim_end_matches(['u', 'U']).parse::<i64>() {
            out.insert(name, v);
        }
    }
    out
}

/// `NAME = value` of every `JPROM_*` parameter of the Fortran binding.
fn fortran_constants(code: &str) -> BTreeMap<String, i64> {
    let joined = code.replace("&\n", " ");
    let mut out = BTreeMap::new();
    for line in joined.lines().filter(|l| l.contains("parameter ::")) {
        for item in line.split("::").nth(1).unwrap().split(',') {
            if let Some((n, v)) = item.split_once('=') {
                out.insert(n.trim().to_string(), v.trim().parse().unwrap_or_else(|_| panic!("constant {item}")));
            }
        }
    }
    out
}

#[test]
fn constants_and_option_structs_match_the_header() {
    let header = header();
    let code = fortran_code(&binding());
    let c = header_constants(&header);
    assert!(c.len() >= 25 && c.contains_key("JPROM_PARSE") && c.contains_key("JPROM_SWEEP_OPTIONS_V1_SIZE"), "{c:?}");
    let f = fortran_constants(&code);
    for (name, value) in &c {
        assert_eq!(f.get(name), Some(value), "{name} = {value} in include/jprom.h; fortran/jprom.f90 has {:?}", f.get(name));
    }
    for name in f.keys() {
        assert!(c.contains_key(name), "fortran/jprom.f90 defines {name}, which include/jprom.h does not");
    }

    // the options structs: `typedef struct { size_t struct_size; ... } jprom_x;` in C and
    // `type, bind(C) :: jprom_x ... end type` in Fortran, field by field
    let lines: Vec<&str> = header.lines().collect();
    let mut checked = 0;
    for (i, l) in lines.iter().enumerate() {
        if *l != "typedef struct {" {
            continue;
        }
        let end = i + lines[i..].iter().position(|l| l.starts_with("} ")).unwrap();
        let name = lines[end].trim_start_matches("} ").trim_end_matches(';');
        let c_fields: Vec<(String, String)> = lines[i + 1..end]
            .iter()
            .map(|l| l.trim())
            .filter(|l| !l.is_empty() && !l.starts_with("//"))
            .map(|l| {
                let (ty, field) = l.trim_end_matches(';').rsplit_once(' ').unwrap();
                let kind = match ty {
                    "size_t" => "integer(c_size_t)",
                    "double" => "real(c_double)",
                    "int" => "integer(c_int)",
                    other => panic!("{name}.{field}: no Fortran kind for C type {other}"),
                };
                (field.to_string(), kind.to_string())
            })
            .collect();
        let start = code.find(&format!("type, bind(C) :: {name}\n")).unwrap_or_else(|| panic!("no Fortran type {name}"));
        let body = &code[start..];
        let body = &body[..body.find("end type").unwrap()];
        let f_fields: Vec<(String, String)> = body
            .lines()
            .skip(1)
            .filter(|l| l.contains("::"))
            .flat_map(|l| {
                let (ty, names) = l.split_once("::").unwrap();
                let ty = ty.trim().to_string();
                names.split(',').map(move |n| (n.trim().to_string(), ty.clone())).collect::<Vec<_>>()
            })
            .collect();
        assert_eq!(f_fields, c_fields, "fields of {name}: fortran/jprom.f90 vs include/jprom.h");
        checked += 1;
    }
    assert_eq!(checked, 3, "the header's options structs");
}

#[test]
fn every_fortran_wrapper_works() {
    if !have_gfortran() {
        return;
    }
    let exe = compile_fortran(&[&root().join("fortran/jprom.f90"), &root().join("crates/jprom-capi/tests/fortran/binding.f90")], "fortran_binding");
    let files = root().join("target/native-tests/fortran_binding_files");
    let _ = std::fs::remove_dir_all(&files);
    std::fs::create_dir_all(&files).unwrap();
    let o = std::process::Command::new(&exe).arg(&files).output().expect("run the Fortran binding program");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.ends_with("all checks passed\n"), "{out}");
    assert!(out.contains(&format!("version {}\n", env!("CARGO_PKG_VERSION"))), "jp_version(): {out}");
    let checks = out.lines().filter(|l| l.starts_with("ok ")).count();
    assert!(checks >= 35, "only {checks} checks ran:\n{out}");
    // the saved files are what they claim to be
    for (file, kind) in [("model.json", "model"), ("solution.json", "solution"), ("sweep.json", "sweep"), ("basis.json", "basis")] {
        let text = std::fs::read_to_string(files.join(file)).unwrap();
        assert!(text.contains(&format!("\"kind\": \"{kind}\"")) || text.contains(&format!("\"kind\":\"{kind}\"")), "{file}");
    }
}
