//! The memory budget through the Rust API (one test: the budget is process-wide): a request
//! estimated beyond it is refused with the estimate and the budget, before anything is
//! allocated, and the default comes back when it is reset.

use jprom::io::matrix_market::parse_matrix_market;
use jprom::memory::MemoryBudget;
use jprom::JpError;

#[test]
fn requests_beyond_the_budget_are_refused_with_the_estimate() {
    let default = MemoryBudget::global();
    assert_eq!(default, MemoryBudget::machine_default());
    MemoryBudget::set_global(Some(MemoryBudget::new(1 << 20)));

    // a file whose text and values would not fit is not read
    let p = std::env::temp_dir().join(format!("jprom-budget-{}.json", std::process::id()));
    std::fs::write(&p, vec![b' '; 200_000]).unwrap();
    let e = jprom::io::read_text(&p).unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { budget: 1048576, .. }), "{e:?}");
    assert!(e.to_string().contains("more than the memory budget of 1.0 MiB (1048576 bytes)"), "{e}");

    // a Matrix Market file whose column pointers alone exceed it (10^6 columns, one entry)
    let e = parse_matrix_market("%%MatrixMarket matrix coordinate real general\n1000000 1000000 1\n1 1 1.0\n", "big.mtx").unwrap_err();
    assert!(matches!(&e, JpError::TooLarge { .. }) && e.to_string().contains("the 1000000 x 1000000 matrix of big.mtx"), "{e}");

    // a model loaded from a small file is within it
    std::fs::write(&p, "{}").unwrap();
    assert!(!matches!(jprom::io::read_text(&p), Err(JpError::TooLarge { .. })));

    MemoryBudget::set_global(None);
    assert_eq!(MemoryBudget::global(), default);
    assert!(parse_matrix_market("%%MatrixMarket matrix coordinate real general\n1000000 1000000 1\n1 1 1.0\n", "big.mtx").is_ok());
}
