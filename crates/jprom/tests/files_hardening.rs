//! Issue 12 (hardening), the file formats through the Rust API: Matrix Market semantics and
//! sizes, DoF maps, loaded documents, and writes checked to the end (`/dev/full`).

use jprom::linalg::sparse::sparse_triplets;
use jprom::error::JpError;
use jprom::io::dof_map::{DofMap, NodeDofs};
use jprom::io::matrix_market::{parse_matrix_market, parse_symmetric_matrix_market, write_matrix_market};
use jprom::model::{Damping, Excitation, HarmonicForce, Model};
use std::path::Path;
use std::time::{Duration, Instant};

const GENERAL: &str = "%%MatrixMarket matrix coordinate real general\n";
const SYMMETRIC: &str = "%%MatrixMarket matrix coordinate real symmetric\n";

fn parse_error(r: jprom::Result<impl std::fmt::Debug>) -> (usize, String) {
    match r {
        Err(JpError::Parse { line, reason, .. }) => (line, reason),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn matrix_market_size_lines_are_checked_before_anything_is_allocated() {
    // 10^12 entries declared: refused at the size line at once (aborted the process before)
    let t = Instant::now();
    let (line, reason) = parse_error(parse_matrix_market(&format!("{GENERAL}1000000 1000000 1000000000000\n1 1 1.0\n"), "K.mtx"));
    assert_eq!(line, 2);
    assert!(reason.contains("1000000000000 declared, the file has 1 entry lines"), "{reason}");
    // 10^9 x 10^9 with one entry, used as a stiffness: refused from the size line (read for
    // 32 s and 7.6 GB before)
    let (line, reason) = parse_error(parse_symmetric_matrix_market(&format!("{SYMMETRIC}1000000000 1000000000 1\n1 1 1.0\n"), "K.mtx"));
    assert_eq!(line, 2);
    assert!(reason.contains("at least one entry per row") && reason.contains("at least 1000000000"), "{reason}");
    let (_, reason) = parse_error(parse_symmetric_matrix_market(&format!("{GENERAL}3 2 6\n1 1 1\n2 1 1\n3 1 1\n1 2 1\n2 2 1\n3 2 1\n"), "K.mtx"));
    assert!(reason.contains("must be square"), "{reason}");
    // counts that overflow a usize product are not wrapped round
    let (_, reason) = parse_error(parse_matrix_market(&format!("{GENERAL}18446744073709551615 18446744073709551615 18446744073709551615\n"), "K.mtx"));
    assert!(reason.contains("declared, the file has 0 entry lines"), "{reason}");
    assert!(t.elapsed() < Duration::from_secs(2), "took {:?}", t.elapsed());
}

#[test]
fn a_general_matrix_keeps_both_triangles_exactly_and_must_be_symmetric_where_it_is_used_so() {
    // general, symmetric in content: both triangles kept exactly as given
    let text = format!("{GENERAL}2 2 4\n1 1 4.0\n2 1 -1.5\n1 2 -1.5\n2 2 3.0\n");
    let a = parse_matrix_market(&text, "K.mtx").unwrap();
    assert_eq!(sparse_triplets(&a), vec![(0, 0, 4.0), (1, 0, -1.5), (0, 1, -1.5), (1, 1, 3.0)]);
    assert_eq!(sparse_triplets(&parse_symmetric_matrix_market(&text, "K.mtx").unwrap()), sparse_triplets(&a));
    // an entry above the diagonal and none below: kept as given by the general reader ...
    let upper_only = format!("{GENERAL}3 3 4\n1 1 4.0\n1 2 -2.5\n2 2 3.0\n3 3 1.0\n");
    let a = parse_matrix_market(&upper_only, "K.mtx").unwrap();
    assert!(sparse_triplets(&a).contains(&(0, 1, -2.5)));
    // ... and refused where the matrix is used as symmetric, naming the entry and both values
    let (_, reason) = parse_error(parse_symmetric_matrix_market(&upper_only, "K.mtx"));
    assert!(reason.contains("not symmetric: entry (1, 2) = -2.5e0 while (2, 1) = 0e0 (not given)"), "{reason}");
    // two given values that differ
    let differ = format!("{GENERAL}2 2 4\n1 1 4.0\n2 1 -1.0\n1 2 -1.5\n2 2 3.0\n");
    let (_, reason) = parse_error(parse_symmetric_matrix_market(&differ, "K.mtx"));
    assert!(reason.contains("entry (2, 1) = -1e0 while (1, 2) = -1.5e0"), "{reason}");
    // a difference below the tolerance is round-off, accepted
    let close = format!("{GENERAL}2 2 4\n1 1 4.0\n2 1 -1.0\n1 2 -1.000000000001\n2 2 3.0\n");
    assert!(parse_symmetric_matrix_market(&close, "K.mtx").is_ok());
}

#[test]
fn a_symmetric_file_with_an_upper_entry_names_the_value_it_conflicts_with() {
    let (line, reason) = parse_error(parse_matrix_market(&format!("{SYMMETRIC}2 2 4\n1 1 4.0\n2 1 -1.0\n1 2 -1.5\n2 2 3.0\n"), "K.mtx"));
    assert_eq!(line, 5);
    assert!(reason.contains("entry (1, 2) = -1.5e0 above the diagonal") && reason.contains("(2, 1) = -1e0: the two conflict"), "{reason}");
    let (line, reason) = parse_error(parse_matrix_market(&format!("{SYMMETRIC}2 2 2\n1 1 4.0\n1 2 -1.5\n"), "K.mtx"));
    assert_eq!(line, 4);
    assert!(reason.contains("above the diagonal in a symmetric file (store the lower triangle only)"), "{reason}");
}

#[test]
fn dof_maps_check_their_format_first_and_refuse_unknown_keys() {
    let dir = std::env::temp_dir().join(format!("jprom-files-hardening-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // a jprom model given as a DoF map says what it is
    let model = Model::new(
        faer::Mat::identity(3, 3),
        faer::Mat::identity(3, 3),
        Damping::default(),
        Excitation::zero(3),
        Vec::new(),
        Vec::new(),
    )
    .unwrap();
    let p = dir.join("model.json");
    model.save_json(&p).unwrap();
    let e = DofMap::load(&p).unwrap_err();
    assert!(e.to_string().contains("is a jprom model file, expected a DoF map"), "{e}");
    // unknown keys, in the map and in a node
    let ok = r#"{"format": "jprom-dof-map", "version": 1, "n_dof": 3, "nodes": [{"id": 1, "coords": [0, 0, 0], "dofs": [0, 1, 2]}]}"#;
    assert!(DofMap::parse(ok, "map.json").is_ok());
    let e = DofMap::parse(&ok.replace("\"n_dof\"", "\"n_dofs\": 3, \"n_dof\""), "map.json").unwrap_err();
    assert!(matches!(&e, JpError::Parse { .. }) && e.to_string().contains("unknown field `n_dofs`"), "{e}");
    let e = DofMap::parse(&ok.replace("\"coords\"", "\"cords\": [0, 0, 0], \"coords\""), "map.json").unwrap_err();
    assert!(e.to_string().contains("unknown field `cords`"), "{e}");
    // a directory and a device are I/O errors, not parse errors
    assert!(matches!(DofMap::load(&dir), Err(JpError::Io { .. })));
    let e = DofMap::load(Path::new("/dev/zero")).unwrap_err();
    assert!(matches!(&e, JpError::Io { .. }) && e.to_string().contains("not a regular file"), "{e}");
}

#[test]
fn every_writer_reports_a_full_device() {
    let full = Path::new("/dev/full");
    let map = DofMap::new(3, vec![NodeDofs { id: 1, coords: [0.0; 3], dofs: [0, 1, 2] }]).unwrap();
    let e = map.save(full).unwrap_err();
    assert!(matches!(&e, JpError::Io { .. }) && e.to_string().contains("No space left"), "{e}");
    let a = parse_matrix_market(&format!("{GENERAL}1 1 1\n1 1 2.0\n"), "a").unwrap();
    let e = write_matrix_market(full, &a, false).unwrap_err();
    assert!(e.to_string().contains("No space left"), "{e}");
    // a tiny document: all of it sits in the buffer until the final flush
    let e = jprom::io::save_json("model", &[1.0, 2.0], full).unwrap_err();
    assert!(e.to_string().contains("No space left"), "{e}");
    let e = jprom::io::write_file(full, |w| w.write_all(b"x")).unwrap_err();
    assert!(e.to_string().contains("No space left"), "{e}");
    // and a good write is complete when it returns
    let p = std::env::temp_dir().join(format!("jprom-write-{}.txt", std::process::id()));
    jprom::io::write_file(&p, |w| w.write_all(b"all of it")).unwrap();
    assert_eq!(std::fs::read_to_string(&p).unwrap(), "all of it");
}

#[test]
fn an_excitation_level_that_makes_the_scale_infinite_is_refused() {
    let mut e = Excitation::zero(2);
    e.static_force = vec![1.0, 0.0];
    e.harmonics.push(HarmonicForce { cos: vec![0.0, 3.0], sin: vec![0.0, 4.0] });
    e.set_level(0.5).unwrap();
    assert_eq!(e.dynamic_scale, 0.4);
    let err = e.set_level(1e-320).unwrap_err();
    assert!(err.to_string().contains("must be finite and > 0") && err.to_string().contains("inf"), "{err}");
    assert_eq!(e.dynamic_scale, 0.4, "unchanged on failure");
    assert!((e.level() - 0.5).abs() < 1e-15);
}

#[test]
fn a_loaded_file_of_another_kind_says_what_it_is() {
    let dir = std::env::temp_dir().join(format!("jprom-kinds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("x.json");
    jprom::io::save_json("sweep", &serde_json::json!({"points": []}), &p).unwrap();
    let e = Model::load_json(&p).unwrap_err();
    assert!(matches!(&e, JpError::Io { .. }) && e.to_string().contains("this is a jprom sweep file, expected a model"), "{e}");
    std::fs::write(&p, r#"{"format": "jprom-dof-map", "version": 1, "n_dof": 3, "nodes": []}"#).unwrap();
    let e = Model::load_json(&p).unwrap_err();
    assert!(e.to_string().contains("this is a jprom DoF map file, expected a jprom model file"), "{e}");
    std::fs::write(&p, r#"{"mass": 1}"#).unwrap();
    let e = Model::load_json(&p).unwrap_err();
    assert!(e.to_string().contains("not a jprom file"), "{e}");
    let e = Model::load_json(&dir).unwrap_err();
    assert!(matches!(&e, JpError::Io { .. }) && e.to_string().contains("is a directory"), "{e}");
}
