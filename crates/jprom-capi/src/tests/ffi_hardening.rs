//! Issue 12 (hardening) at the C boundary: the bad-input catalogue as a C program
//! (tests/c/hostile_input.c), a short run of the seeded random-call harness
//! (tests/c/api_fuzz.c; `.ci/run` runs 100,000 calls), and the file cases that need a JSON
//! edited between saving and loading: each returns its documented status and a message naming
//! what is wrong, never JPROM_PANIC, never an abort or a hang.

use jprom_testkit::native;

use crate::*;
use native::*;
use serde_json::Value;
use std::ffi::{CStr, CString};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::ptr::{null, null_mut};
use std::time::{Duration, Instant};

fn scratch_dir(name: &str) -> PathBuf {
    let d = root().join("target").join("native-tests").join(format!("{name}-scratch"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs a program with a time limit; returns (exit code, stdout). A hang fails the test.
fn run_limited(exe: &Path, args: &[&str], limit: Duration) -> (i32, String) {
    let out_file = exe.with_extension("stdout");
    let mut child = Command::new(exe).args(args).stdout(std::fs::File::create(&out_file).unwrap()).spawn().expect("start program");
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{} {args:?} did not finish within {limit:?} (a hang)", exe.display());
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let out = std::fs::read_to_string(&out_file).unwrap();
    assert!(status.code().is_some(), "{} {args:?} was killed by a signal ({status:?}, a crash):\n{out}", exe.display());
    (status.code().unwrap(), out)
}

#[test]
fn c_catalogue_of_bad_input_gets_documented_statuses() {
    let exe = compile_c(&[&root().join("crates/jprom-capi/tests/c/hostile_input.c")], "hostile_input", &[]);
    let dir = scratch_dir("hostile_input");
    let (code, out) = run_limited(&exe, &[dir.to_str().unwrap()], Duration::from_secs(120));
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("all checks passed"), "{out}");
    assert!(!out.contains("FAIL"), "{out}");
    let checks = out.lines().filter(|l| l.starts_with("ok ")).count();
    assert!(checks >= 80, "only {checks} checks ran:\n{out}");
}

#[test]
fn api_fuzz_short_run_has_no_panic_crash_or_hang() {
    let exe = compile_c(&[&root().join("crates/jprom-capi/tests/c/api_fuzz.c")], "api_fuzz", &[]);
    let dir = scratch_dir("api_fuzz");
    let (code, out) = run_limited(&exe, &["4000", "12", dir.to_str().unwrap()], Duration::from_secs(180));
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("calls: 4") && out.contains("violations: 0, panics: 0"), "{out}");
    // the run reached the interesting statuses, not only NULL arguments
    for status in ["JPROM_OK=", "JPROM_BAD_SIZE=", "JPROM_INVALID_VALUE=", "JPROM_INVALID_HANDLE=", "JPROM_IO="] {
        let count: u64 = out.split(status).nth(1).and_then(|r| r.split_whitespace().next()).and_then(|n| n.parse().ok()).unwrap_or(0);
        assert!(count > 0, "no {status} in {out}");
    }
}

// ---------------------------------------------------------------- files edited between save and load

unsafe fn ok(s: jprom_status) {
    assert_eq!(s, jprom_status::JPROM_OK, "{}", last_error());
}

unsafe fn last_error() -> String {
    CStr::from_ptr(jprom_last_error_message()).to_string_lossy().into_owned()
}

fn c_path(p: &Path) -> CString {
    CString::new(p.to_str().unwrap()).unwrap()
}

/// Two DoFs on a chain, a Jenkins element from DoF 1 to ground, forcing on DoF 0, two outputs.
unsafe fn model() -> *mut jprom_model {
    let m = [1.0, 0.0, 0.0, 1.0];
    let k = [2.0e4, -1.0e4, -1.0e4, 1.0e4];
    let mut p = null_mut();
    ok(jprom_model_new(2, m.as_ptr(), k.as_ptr(), &mut p));
    ok(jprom_model_add_jenkins(p, 1, null(), 2.0e4, 0.3, 10.0));
    ok(jprom_model_set_rayleigh_damping(p, 0.0, 2e-4));
    ok(jprom_model_set_harmonic_force(p, 1, [4.0, 0.0].as_ptr(), null(), 2));
    ok(jprom_model_set_static_force(p, [0.0, 1.0].as_ptr(), 2));
    ok(jprom_model_set_output_dofs(p, [0usize, 1].as_ptr(), 2));
    p
}

unsafe fn options() -> (jprom_hbm_options, jprom_sweep_options) {
    let mut o = std::mem::zeroed();
    let mut s = std::mem::zeroed();
    ok(jprom_hbm_options_default(&mut o));
    ok(jprom_sweep_options_default(&mut s));
    o.harmonics = 2;
    s.omega_start = 60.0;
    s.omega_end = 200.0;
    s.max_points = 8;
    (o, s)
}

/// Reads a saved JSON file, lets `edit` change it, writes it back pretty-printed (so that
/// lines mean something).
fn edit_json(path: &Path, edit: impl FnOnce(&mut Value)) {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
}

/// The 1-based line of the first line of `text` containing `needle`.
fn line_of(path: &Path, needle: &str) -> usize {
    std::fs::read_to_string(path).unwrap().lines().position(|l| l.contains(needle)).expect(needle) + 1
}

#[test]
fn edited_solution_and_sweep_files_are_refused_at_loading_not_indexed_out_of_bounds() {
    unsafe {
        let dir = scratch_dir("edited_files");
        let m = model();
        let (o, s) = options();
        let mut sweep = null_mut();
        ok(jprom_sweep(m, &o, &s, None, null_mut(), &mut sweep));
        let mut sol = null_mut();
        ok(jprom_sweep_result_point(sweep, 1, &mut sol));
        let sol_path = dir.join("solution.json");
        let sweep_path = dir.join("sweep.json");
        ok(jprom_solution_save_json(sol, c_path(&sol_path).as_ptr()));
        ok(jprom_sweep_result_save_json(sweep, c_path(&sweep_path).as_ptr()));

        // n_outputs edited: the amplitude accessor would read past `outputs`
        let p = dir.join("solution_n_outputs.json");
        std::fs::copy(&sol_path, &p).unwrap();
        edit_json(&p, |v| v["data"]["n_outputs"] = Value::from(7));
        let mut loaded = null_mut();
        assert_eq!(jprom_solution_load_json(c_path(&p).as_ptr(), &mut loaded), jprom_status::JPROM_PARSE);
        let msg = last_error();
        assert!(msg.contains("key 'data.outputs'") && msg.contains("(2 H + 1) x n_outputs = 5 x 7"), "{msg}");
        assert!(msg.contains(&format!("line {}", line_of(&p, "\"outputs\""))), "{msg}");
        assert!(loaded.is_null());

        // harmonics edited: sizes and z no longer match the layout
        let p = dir.join("solution_harmonics.json");
        std::fs::copy(&sol_path, &p).unwrap();
        edit_json(&p, |v| v["data"]["layout"]["harmonics"] = Value::from(9));
        assert_eq!(jprom_solution_load_json(c_path(&p).as_ptr(), &mut loaded), jprom_status::JPROM_PARSE);
        let msg = last_error();
        assert!(msg.contains("data.layout.sizes") && msg.contains("harmonics + 1 = 10"), "{msg}");
        edit_json(&p, |v| v["data"]["layout"]["harmonics"] = Value::from(1u64 << 40));
        assert_eq!(jprom_solution_load_json(c_path(&p).as_ptr(), &mut loaded), jprom_status::JPROM_PARSE);
        assert!(last_error().contains("data.layout.harmonics"), "{}", last_error());

        // a point of a sweep edited
        let p = dir.join("sweep_point.json");
        std::fs::copy(&sweep_path, &p).unwrap();
        edit_json(&p, |v| v["data"]["points"][2]["n_outputs"] = Value::from(1));
        let mut w = null_mut();
        assert_eq!(jprom_sweep_result_load_json(c_path(&p).as_ptr(), &mut w), jprom_status::JPROM_PARSE);
        let msg = last_error();
        assert!(msg.contains("key 'data.points[2].outputs'"), "{msg}");
        assert!(w.is_null());
        // a second contact record with a sample fewer than the first
        std::fs::copy(&sweep_path, &p).unwrap();
        edit_json(&p, |v| {
            let cycles = v["data"]["points"][0]["contact_cycles"].as_array_mut().unwrap();
            let mut c = cycles[0].clone();
            c["states"].as_array_mut().unwrap().pop();
            cycles.push(c);
        });
        let mut w2 = null_mut();
        assert_eq!(jprom_sweep_result_load_json(c_path(&p).as_ptr(), &mut w2), jprom_status::JPROM_PARSE);
        assert!(last_error().contains("data.points[0].contact_cycles[1].states"), "{}", last_error());
        // every point must have the sizes of the first
        std::fs::copy(&sweep_path, &p).unwrap();
        edit_json(&p, |v| {
            let cycles = v["data"]["points"][3]["contact_cycles"].as_array_mut().unwrap();
            let c = cycles[0].clone();
            cycles.push(c);
        });
        assert_eq!(jprom_sweep_result_load_json(c_path(&p).as_ptr(), &mut w2), jprom_status::JPROM_PARSE);
        assert!(last_error().contains("data.points[3]") && last_error().contains("other sizes"), "{}", last_error());
        assert!(w2.is_null());
        // the untouched files load
        ok(jprom_sweep_result_load_json(c_path(&sweep_path).as_ptr(), &mut w));
        let mut amp = 0.0;
        ok(jprom_sweep_result_point_amplitude(w, 1, 2, 1, &mut amp));
        jprom_sweep_result_free(w);
        jprom_solution_free(sol);
        jprom_sweep_result_free(sweep);
        jprom_model_free(m);
    }
}

#[test]
fn an_edited_basis_says_what_differs() {
    unsafe {
        let dir = scratch_dir("edited_basis");
        let m = model();
        let (o, _) = options();
        let mut jo = std::mem::zeroed();
        ok(jprom_jp_options_default(&mut jo));
        jo.n_samples = 5;
        let mut b = null_mut();
        ok(jprom_basis_predict_opts(m, &o, &jo, 60.0, 200.0, &mut b));
        let path = dir.join("basis.json");
        ok(jprom_basis_save_json(b, c_path(&path).as_ptr()));
        // phi[1] reshaped to one row: the same number of entries ("expected 6, got 6" before)
        edit_json(&path, |v| {
            let phi = &mut v["data"]["phi"][1];
            let entries = phi["nrows"].as_u64().unwrap() * phi["ncols"].as_u64().unwrap();
            phi["nrows"] = Value::from(1);
            phi["ncols"] = Value::from(entries);
        });
        let text: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let (rows, n_dof) = (text["data"]["phi"][1]["nrows"].as_u64().unwrap(), text["data"]["n_dof"].as_u64().unwrap());
        assert_ne!(rows, n_dof);
        let mut loaded = null_mut();
        assert_eq!(jprom_basis_load_json(c_path(&path).as_ptr(), &mut loaded), jprom_status::JPROM_PARSE);
        let msg = last_error();
        assert!(msg.contains(&format!("harmonic 1 has {rows} rows, n_dof is {n_dof}")), "{msg}");
        assert!(loaded.is_null());
        jprom_basis_free(b);
        jprom_model_free(m);
    }
}

#[test]
fn model_files_with_absurd_matrices_or_unknown_keys_are_refused_at_once() {
    unsafe {
        let dir = scratch_dir("model_files");
        let m = model();
        let path = dir.join("model.json");
        ok(jprom_model_save_json(m, c_path(&path).as_ptr()));
        let mut loaded = null_mut();
        for (rows, cols, what) in [(1u64 << 32, 1u64 << 32, "2^32 x 2^32"), (0, 1 << 62, "0 x 2^62"), (1 << 40, 0, "2^40 x 0")] {
            let p = dir.join("absurd.json");
            std::fs::copy(&path, &p).unwrap();
            edit_json(&p, |v| v["data"]["mass"] = serde_json::json!({"nrows": rows, "ncols": cols, "data": []}));
            let t = Instant::now();
            assert_eq!(jprom_model_load_json(c_path(&p).as_ptr(), &mut loaded), jprom_status::JPROM_PARSE, "{what}");
            assert!(t.elapsed() < Duration::from_secs(2), "{what} took {:?}", t.elapsed());
            let msg = last_error();
            assert!(msg.contains("above jprom's limit of 1048576 rows or columns") && msg.contains("data.mass"), "{what}: {msg}");
        }
        // an unknown key inside a contact, on its line
        let p = dir.join("unknown_key.json");
        std::fs::copy(&path, &p).unwrap();
        edit_json(&p, |v| v["data"]["contacts"][0]["frictoin"] = Value::from(0.3));
        assert_eq!(jprom_model_load_json(c_path(&p).as_ptr(), &mut loaded), jprom_status::JPROM_PARSE);
        let msg = last_error();
        assert!(msg.contains("unknown key 'data.contacts[0].frictoin'"), "{msg}");
        assert!(msg.contains(&format!("line {}", line_of(&p, "frictoin"))), "{msg}");
        // and at the top of the document
        std::fs::copy(&path, &p).unwrap();
        edit_json(&p, |v| v["data"]["damping_ratio"] = Value::from(0.01));
        assert_eq!(jprom_model_load_json(c_path(&p).as_ptr(), &mut loaded), jprom_status::JPROM_PARSE);
        assert!(last_error().contains("unknown key 'data.damping_ratio'"), "{}", last_error());
        assert!(loaded.is_null());
        ok(jprom_model_load_json(c_path(&path).as_ptr(), &mut loaded));
        jprom_model_free(loaded);
        jprom_model_free(m);
    }
}

/// A callback that makes a failing nested call each time, then lets the sweep go on.
unsafe extern "C" fn failing_nested_call(user: *mut std::ffi::c_void, _: usize, _: f64, _: *const f64, _: usize) -> std::ffi::c_int {
    let mut n = 0usize;
    if jprom_model_n_dof(null(), &mut n) == jprom_status::JPROM_NULL_ARGUMENT {
        *(user as *mut usize) += 1;
    }
    0
}

#[test]
fn an_ok_return_leaves_no_stale_message_from_a_nested_failure() {
    unsafe {
        let m = model();
        let (o, s) = options();
        let mut nested = 0usize;
        let mut sweep = null_mut();
        let st = jprom_sweep(m, &o, &s, Some(failing_nested_call), &mut nested as *mut usize as *mut _, &mut sweep);
        assert_eq!(st, jprom_status::JPROM_OK);
        assert!(nested > 0);
        assert_eq!(last_error(), "", "stale message after an OK return");
        jprom_sweep_result_free(sweep);
        jprom_model_free(m);
    }
}
