//! Issue 11, acceptance 3, from C and Fortran: a sweep forced to stall reports its reason
//! (`jprom_sweep_result_end_reason`, `jprom_sweep_result_failure_copy`; `jp_sweep_end`).

use jprom_testkit::native::*;

fn crate_dir() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn forced_stall_reports_its_reason_in_c_and_fortran() {
    let c = compile_c(&[&crate_dir().join("tests/c/sweep_end.c")], "sweep_end_c", &[]);
    let out = std::process::Command::new(&c).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{text}");
    assert!(out.status.success(), "C: {text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("end reached_end: \n") && text.contains("end stalled: stalled at omega"), "{text}");
    if have_gfortran() {
        let f = compile_fortran(&[&root().join("fortran/jprom.f90"), &crate_dir().join("tests/fortran/sweep_end.f90")], "sweep_end_f90");
        let out = std::process::Command::new(&f).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        println!("{text}");
        assert!(out.status.success(), "Fortran: {text}{}", String::from_utf8_lossy(&out.stderr));
        assert!(text.contains("end 0: \n") && text.contains("end 1: stalled at omega"), "{text}");
    }
}
