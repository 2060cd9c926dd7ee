//! Matrix Market: exact round trip (symmetric and general) and specific errors for malformed
//! files; DoF map JSON round trip and errors.

use jprom::fe::{BladeParams, BuiltinBlade};
use jprom::linalg::sparse_triplets;
use jprom::io::dof_map::{DofMap, NodeDofs};
use jprom::io::matrix_market::{format_matrix_market, parse_matrix_market, read_structural_matrices, write_matrix_market};
use jprom::JpError;

#[test]
fn round_trip_is_exact() {
    let p = BladeParams { n_span: 9, n_chord: 2, n_thickness: 1, n_shroud_gap: 1, ..Default::default() };
    let fe = BuiltinBlade::build(&p).unwrap();
    let dir = std::env::temp_dir().join(format!("jprom_mm_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (pk, pm) = (dir.join("k.mtx"), dir.join("m.mtx"));
    write_matrix_market(&pk, &fe.stiffness, true).unwrap();
    write_matrix_market(&pm, &fe.mass, false).unwrap();
    let s = read_structural_matrices(&pm, &pk, None).unwrap();
    assert_eq!(sparse_triplets(&s.stiffness), sparse_triplets(&fe.stiffness));
    assert_eq!(sparse_triplets(&s.mass), sparse_triplets(&fe.mass));
    // A non-symmetric matrix cannot be written as symmetric.
    let a = parse_matrix_market("%%MatrixMarket matrix coordinate real general\n2 2 2\n1 2 1.0\n2 2 3\n", "a").unwrap();
    assert!(format_matrix_market(&a, true).is_err());
    let t = format_matrix_market(&a, false).unwrap();
    assert_eq!(sparse_triplets(&parse_matrix_market(&t, "t").unwrap()), sparse_triplets(&a));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn symmetric_file_is_expanded_and_duplicates_summed() {
    let a = parse_matrix_market(
        "%%MatrixMarket matrix coordinate integer symmetric\n% c\n\n3 3 4\n1 1 2\n3 1 -1\n2 2 5\n3 1 -0.5\n",
        "s",
    )
    .unwrap();
    let d = a.as_ref().to_dense();
    assert_eq!(d[(0, 2)], -1.5);
    assert_eq!(d[(2, 0)], -1.5);
    assert_eq!(d[(1, 1)], 5.0);
    assert_eq!(d[(2, 2)], 0.0);
}

fn parse_err(text: &str) -> (usize, String) {
    match parse_matrix_market(text, "bad.mtx") {
        Err(JpError::Parse { path, line, reason }) => {
            assert_eq!(path, "bad.mtx");
            (line, reason)
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn malformed_files_give_specific_errors() {
    const H: &str = "%%MatrixMarket matrix coordinate real general\n";
    let cases: Vec<(String, usize, &str)> = vec![
        ("".into(), 1, "empty file"),
        ("%MatrixMarket matrix coordinate real general\n1 1 1\n1 1 1\n".into(), 1, "bad header"),
        ("%%MatrixMarket matrix array real general\n1 1\n1\n".into(), 1, "format 'array' unsupported"),
        ("%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n".into(), 1, "complex field unsupported"),
        ("%%MatrixMarket matrix coordinate pattern general\n1 1 1\n1 1\n".into(), 1, "pattern field unsupported"),
        ("%%MatrixMarket matrix coordinate real hermitian\n1 1 1\n1 1 1\n".into(), 1, "hermitian symmetry unsupported"),
        (format!("{H}% comment\n2 2\n1 1 1\n"), 3, "size line must have 3"),
        (format!("{H}2 x 1\n1 1 1\n"), 2, "'x' is not a non-negative integer"),
        (format!("{H}2 2 2\n1 1 1.0\n3 1 2.0\n"), 4, "row index 3 out of range"),
        (format!("{H}2 2 2\n1 1 1.0\n1 0 2.0\n"), 4, "column index 0 out of range"),
        (format!("{H}2 2 2\n1 1 abc\n2 2 1\n"), 3, "value 'abc' is not a number"),
        (format!("{H}2 2 2\n1 1 1\n2 2 nan\n"), 4, "not finite"),
        // checked at the size line, before anything is allocated from it
        (format!("{H}2 2 3\n1 1 1\n2 2 1\n"), 2, "missing entries: 3 declared, the file has 2 entry lines"),
        (format!("{H}2 2 1\n1 1 1\n2 2 1\n"), 4, "more entries than the 1 declared"),
        (format!("{H}2 2 1\n1 1\n"), 3, "entry must be 'row col value'"),
        (format!("{H}2 2 5\n"), 2, "5 entries cannot fit in 2 x 2"),
        ("%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 2 1\n".into(), 3, "above the diagonal"),
        ("%%MatrixMarket matrix coordinate real symmetric\n2 3 1\n1 1 1\n".into(), 2, "must be square"),
        (format!("{H}% only comments\n"), 3, "missing size line"),
    ];
    for (text, line, reason) in cases {
        let (l, r) = parse_err(&text);
        assert_eq!(l, line, "line for {reason:?}: got {l} ({r})");
        assert!(r.contains(reason), "reason {r:?} should contain {reason:?}");
    }
    // Missing file: an I/O error, not a panic.
    assert!(matches!(
        jprom::io::matrix_market::read_matrix_market(std::path::Path::new("/nonexistent/k.mtx")),
        Err(JpError::Io { .. })
    ));
}

#[test]
fn dof_map_round_trip_and_errors() {
    let nodes = vec![
        NodeDofs { id: 7, coords: [0.0, 1.0, 2.0], dofs: [0, 1, 2] },
        NodeDofs { id: 9, coords: [1.0, 1.0, 2.0], dofs: [3, 4, 5] },
    ];
    let map = DofMap::new(6, nodes).unwrap();
    let path = std::env::temp_dir().join(format!("jprom_dofmap_{}.json", std::process::id()));
    map.save(&path).unwrap();
    let back = DofMap::load(&path).unwrap();
    assert_eq!(back, map);
    assert_eq!(back.node(9).unwrap().dofs, [3, 4, 5]);
    assert!(back.node(1).is_err());
    std::fs::remove_file(&path).ok();

    let bad_json = "{\n \"format\": \"jprom-dof-map\",\n \"version\": 1,\n \"n_dof\": 6,\n \"nodes\": [ {\"id\": 1 ]\n}";
    match DofMap::parse(bad_json, "map.json") {
        Err(JpError::Parse { line, .. }) => assert_eq!(line, 5),
        other => panic!("{other:?}"),
    }
    let out_of_range = r#"{"format":"jprom-dof-map","version":1,"n_dof":3,"nodes":[{"id":1,"coords":[0,0,0],"dofs":[1,2,3]}]}"#;
    assert!(matches!(DofMap::parse(out_of_range, "m"), Err(JpError::InvalidValue { .. })));
    let dup = r#"{"format":"jprom-dof-map","version":1,"n_dof":9,"nodes":[{"id":1,"coords":[0,0,0],"dofs":[0,1,2]},{"id":2,"coords":[0,0,0],"dofs":[2,3,4]}]}"#;
    assert!(matches!(DofMap::parse(dup, "m"), Err(JpError::InvalidValue { .. })));
}

/// A file of many chunks (the reader parses about 2 MB per thread): random entries in random
/// order with duplicates, comments and blank lines among them, equal bit for bit to the
/// triplets summed in file order; and errors far into the file name their own line.
#[test]
fn large_files_are_read_in_parallel_as_line_by_line() {
    use jprom::linalg::sparse_from_triplets;
    let n = 3000;
    let mut s: u64 = 12345;
    let mut next = |m: u64| {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 33) % m
    };
    for symmetric in [false, true] {
        let mut lines = Vec::new();
        let mut triplets = Vec::new();
        while lines.len() < 200_000 {
            let (mut i, mut j) = (next(n) as usize, next(n) as usize);
            if symmetric && i < j {
                std::mem::swap(&mut i, &mut j);
            }
            let v = (next(1 << 40) as f64 - (1u64 << 39) as f64) * 1.234567e-7;
            match next(50) {
                0 => lines.push("% a comment".to_string()),
                1 => lines.push("   ".to_string()),
                _ => {}
            }
            lines.push(match next(3) {
                0 => format!("{} {} {v:.17e}", i + 1, j + 1),
                1 => format!("  {}\t{}  {v:e} ", i + 1, j + 1),
                _ => format!("{} {} {v}", i + 1, j + 1),
            });
            if symmetric && i != j {
                triplets.push((j, i, v));
            }
            triplets.push((i, j, v));
            // a duplicate of an earlier entry now and then
            if next(20) == 0 {
                let k = next(lines.len() as u64) as usize;
                if !lines[k].starts_with('%') && !lines[k].trim().is_empty() {
                    let l = lines[k].clone();
                    let f: Vec<&str> = l.split_whitespace().collect();
                    let (i, j, v): (usize, usize, f64) = (f[0].parse().unwrap(), f[1].parse().unwrap(), f[2].parse().unwrap());
                    if symmetric && i != j {
                        triplets.push((j - 1, i - 1, v));
                    }
                    triplets.push((i - 1, j - 1, v));
                    lines.push(l);
                }
            }
        }
        let entries = lines.iter().filter(|l| !l.starts_with('%') && !l.trim().is_empty()).count();
        let sym = if symmetric { "symmetric" } else { "general" };
        let text = format!("%%MatrixMarket matrix coordinate real {sym}\n% big\n{n} {n} {entries}\n{}\n", lines.join("\n"));
        assert!(text.len() > 2 * (2 << 20), "several chunks: {} bytes", text.len());
        let a = parse_matrix_market(&text, "big.mtx").unwrap();
        let b = sparse_from_triplets(n as usize, n as usize, triplets).unwrap();
        let (ta, tb) = (sparse_triplets(&a), sparse_triplets(&b));
        assert!(ta.len() == tb.len() && ta.iter().zip(&tb).all(|(x, y)| x.0 == y.0 && x.1 == y.1 && x.2.to_bits() == y.2.to_bits()), "{sym}");

        // errors deep in the file: each at its line (4 header lines before the entries)
        let bad = |k: usize, l: &str| {
            let mut v = lines.clone();
            v[k] = l.to_string();
            let t = format!("%%MatrixMarket matrix coordinate real {sym}\n% big\n{n} {n} {entries}\n{}\n", v.join("\n"));
            parse_err_named(&t)
        };
        let k = lines.len() - 1000;
        let (l, r) = bad(k, "1 1 oops");
        assert_eq!(l, k + 4, "{r}");
        assert!(r.contains("value 'oops' is not a number"), "{r}");
        let (l, r) = bad(k / 2, &format!("{} 1 1", n + 1));
        assert_eq!((l, r.contains("row index")), (k / 2 + 4, true), "{r}");
        // one entry more than declared: named at the first line past the count, even with a
        // malformed line after it
        let mut v = lines.clone();
        v.push("1 1 1".into());
        v.push("1 1 oops".into());
        let t = format!("%%MatrixMarket matrix coordinate real {sym}\n% big\n{n} {n} {entries}\n{}\n", v.join("\n"));
        let (l, r) = parse_err_named(&t);
        assert_eq!(l, lines.len() + 4, "{r}");
        assert!(r.contains("more entries than the"), "{r}");
        if symmetric {
            let (l, r) = bad(k, "1 2 1.0");
            assert_eq!(l, k + 4, "{r}");
            assert!(r.contains("above the diagonal"), "{r}");
        }
    }
}

fn parse_err_named(text: &str) -> (usize, String) {
    match parse_matrix_market(text, "big.mtx") {
        Err(JpError::Parse { line, reason, .. }) => (line, reason),
        other => panic!("expected a parse error, got {:?}", other.map(|a| a.compute_nnz())),
    }
}
