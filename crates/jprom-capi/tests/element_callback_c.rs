//! Issue 18's C callback element from a real C program (tests/c/element_callback.c): a cubic C
//! callback equals the polynomial spring to 1e-12, and a callback returning 3 ends the solve with
//! JPROM_CALLBACK_ERROR and "element 0: callback returned 3 at sample j".

use jprom_testkit::native::*;

#[test]
fn a_c_callback_cubic_equals_the_polynomial_spring_and_its_error_is_reported() {
    let src = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/c/element_callback.c");
    let exe = compile_c(&[&src], "element_callback_c", &[]);
    let out = std::process::Command::new(&exe).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{text}");
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    let diff: f64 = text.lines().find_map(|l| l.strip_prefix("max rel diff ")).expect("diff line").trim().parse().unwrap();
    assert!(diff < 1e-12, "{diff}");
    assert!(text.contains("error JPROM_CALLBACK_ERROR: element 0: callback returned 3 at sample "), "{text}");
}
