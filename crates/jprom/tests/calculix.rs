//! The CalculiX reader on real CalculiX 2.20 output (tests/data/calculix, written by
//! make_models.py): three solids (C3D8 block, twisted C3D20 plate, C3D15 ring sector) read
//! from `.sti/.mas/.dof/.inp`; their natural frequencies from jprom's sparse shift-invert
//! Lanczos match those `ccx` printed in its `.dat` to 1e-6 relative. Then bad input: each an
//! error naming the file and the line.

use jprom::linalg::lanczos::{lowest_modes, SparseCholesky};
use jprom::error::JpError;
use jprom::io::calculix::*;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn data(model: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/calculix").join(model)
}

fn deck(model: &str) -> PathBuf {
    data(model).join(format!("{model}.inp"))
}

/// A scratch directory of its own for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("jprom_ccx_{}_{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The eigenvalue table of a ccx `.dat` ("E I G E N V A L U E   O U T P U T"): per mode,
/// (eigenvalue in (rad/time)^2, frequency in cycles/time).
fn dat_eigenvalues(path: &Path) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().skip_while(|l| !l.contains("E I G E N V A L U E   O U T P U T"));
    assert!(lines.next().is_some(), "{}: no eigenvalue table", path.display());
    let mut out = Vec::new();
    for l in lines {
        let f: Vec<&str> = l.split_whitespace().collect();
        if f.len() == 5 && f[0].parse::<usize>().is_ok() {
            assert_eq!(f[0].parse::<usize>().unwrap(), out.len() + 1, "{l}");
            assert_eq!(f[4].parse::<f64>().unwrap(), 0.0, "imaginary part: {l}");
            out.push((f[1].parse().unwrap(), f[3].parse().unwrap()));
        } else if !out.is_empty() {
            break;
        }
    }
    out
}

/// `a(i, j)`, 0 if not stored.
fn entry(a: &SparseMat, i: usize, j: usize) -> f64 {
    let a = a.as_ref();
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    ri[cp[j]..cp[j + 1]].binary_search(&i).map_or(0.0, |k| v[cp[j] + k])
}

/// Exactly symmetric (bit for bit), every diagonal entry positive; returns the stored count.
fn check_symmetric_positive_diagonal(a: &SparseMat, what: &str) -> usize {
    let r = a.as_ref();
    let (cp, ri, v) = (r.symbolic().col_ptr(), r.symbolic().row_idx(), r.val());
    for j in 0..a.ncols() {
        assert!(entry(a, j, j) > 0.0, "{what}: diagonal {j} = {}", entry(a, j, j));
        for k in cp[j]..cp[j + 1] {
            assert_eq!(v[k].to_bits(), entry(a, j, ri[k]).to_bits(), "{what}: ({}, {j}) vs its mirror", ri[k]);
        }
    }
    v.len()
}

fn lines_of(path: &Path) -> usize {
    std::fs::read_to_string(path).unwrap().lines().count()
}

/// What each fixture is: (model, nodes, root nodes, node ids of TIP, LOAD, OUT).
struct Expect {
    model: &'static str,
    nodes: usize,
    root: usize,
    tip: usize,
}

const MODELS: [Expect; 3] = [
    // 17 x 5 x 3 grid, root face 5 x 3, tip face 5 x 3
    Expect { model: "block", nodes: 255, root: 15, tip: 15 },
    // 20-node hexahedra 8 x 3 x 1: corners 9*4*2 + edges 8*4*2 + 9*3*2 + 9*4; root face 4*2+3*2+4
    Expect { model: "plate", nodes: 226, root: 18, tip: 7 },
    // 15-node wedges on a 2 x 8 x 1 grid, the end faces: 5 x 2 + 3 mid-height nodes
    Expect { model: "arc", nodes: 197, root: 13, tip: 13 },
];

#[test]
fn fixtures_read_with_their_sizes_sets_and_exact_symmetry() {
    for e in &MODELS {
        let m = read_model(&deck(e.model)).unwrap_or_else(|err| panic!("{}: {err}", e.model));
        let n = m.n();
        let dof = data(e.model).join(format!("{}.dof", e.model));
        let sti = data(e.model).join(format!("{}.sti", e.model));
        assert_eq!(n, lines_of(&dof), "{}", e.model);
        for (a, what) in [(&m.stiffness, "K"), (&m.mass, "M")] {
            assert_eq!((a.nrows(), a.ncols()), (n, n), "{} {what}", e.model);
            let stored = check_symmetric_positive_diagonal(a, &format!("{} {what}", e.model));
            // the file stores one triangle with the diagonal: full storage has 2 lines - n
            assert_eq!(stored, 2 * lines_of(&sti) - n, "{} {what}", e.model);
        }
        // K and M of one pattern (ccx assembles them together)
        assert_eq!(m.stiffness.as_ref().symbolic().row_idx(), m.mass.as_ref().symbolic().row_idx(), "{}", e.model);

        // mesh: every node read, every set there
        assert_eq!(m.coords.len(), e.nodes, "{}", e.model);
        for set in ["ROOT", "TIP", "LOAD", "OUT"] {
            assert!(m.node_set(set).is_ok(), "{}: {set}", e.model);
        }
        let root: BTreeSet<i64> = m.node_set("ROOT").unwrap().iter().copied().collect();
        assert_eq!(root.len(), e.root, "{}", e.model);
        assert_eq!(m.node_set("TIP").unwrap().len(), e.tip, "{}", e.model);
        assert_eq!(m.node_set("LOAD").unwrap().len(), 1, "{}", e.model);
        assert_eq!(m.node_set("out").unwrap().len(), 3, "{}: names are case-insensitive", e.model);

        // .dof: every node used by an element and not clamped has x, y, z (*BOUNDARY ROOT, 1, 3
        // removes the root's DoFs from the matrices), and nothing else
        assert_eq!(n, 3 * (e.nodes - e.root), "{}", e.model);
        for (r, &(node, dir)) in m.dofs.iter().enumerate() {
            assert!((1..=3).contains(&dir), "{}: row {r}", e.model);
            assert!(!root.contains(&node), "{}: clamped node {node} has row {r}", e.model);
            assert_eq!(m.row_of(node, dir), Some(r));
        }
        for &node in &root {
            assert_eq!(m.row_of(node, 1), None);
        }
        // rows of sets: 3 per free node, the clamped ones apart
        let (rows, without) = m.set_rows("TIP").unwrap();
        assert_eq!((rows.len(), without.len()), (3 * e.tip, 0), "{}", e.model);
        let (rows, without) = m.set_rows("ROOT").unwrap();
        assert_eq!((rows.len(), without.len()), (0, e.root), "{}", e.model);
    }
}

#[test]
fn fixture_geometry_and_generated_sets() {
    // block: ids x fastest on a 17 x 5 x 3 grid; TIP by GENERATE = the face x = 100
    let m = read_mesh(&deck("block")).unwrap();
    assert_eq!(m.files.len(), 1);
    let tip: Vec<i64> = m.coords.iter().filter(|(_, x)| x[0] == 100.0).map(|(&id, _)| id).collect();
    assert_eq!(m.node_set("TIP").unwrap(), tip.as_slice());
    assert_eq!(m.node_set("EDGE").unwrap(), (1..=17).collect::<Vec<i64>>().as_slice());
    let root: Vec<i64> = m.coords.iter().filter(|(_, x)| x[0] == 0.0).map(|(&id, _)| id).collect();
    assert_eq!(m.node_set("ROOT").unwrap(), root.as_slice());
    assert_eq!(m.coords[&255], [100.0, 20.0, 10.0]);
    assert_eq!(m.node_set("NALL").unwrap().len(), 255, "*NODE, NSET=NALL");

    // plate: mesh and sets in plate.msh (*INCLUDE); WATCH = LOAD + OUT (a set of sets)
    let m = read_mesh(&deck("plate")).unwrap();
    assert_eq!(m.files.len(), 2);
    assert!(m.files[1].ends_with("plate.msh"));
    let mut watch: Vec<i64> = m.node_set("LOAD").unwrap().iter().chain(m.node_set("OUT").unwrap()).copied().collect();
    watch.sort();
    watch.dedup();
    assert_eq!(m.node_set("WATCH").unwrap(), watch.as_slice());
    for id in m.node_set("TIP").unwrap() {
        assert!((m.coords[id][0] - 120.0).abs() < 1e-9, "TIP node {id} at the free end");
    }

    // arc: node ids from 1001 with gaps; TIP at 60 degrees; `*NSET,NSET=load` is LOAD
    let m = read_mesh(&deck("arc")).unwrap();
    assert_eq!(*m.coords.keys().next().unwrap(), 1001);
    let last = *m.coords.keys().last().unwrap();
    assert!(last - 1001 + 1 > m.coords.len() as i64, "gaps in the ids");
    for id in m.node_set("TIP").unwrap() {
        let x = m.coords[id];
        assert!((x[1].atan2(x[0]).to_degrees() - 60.0).abs() < 1e-9);
    }
    assert_eq!(m.node_set("LOAD").unwrap(), &[1255]);
    assert!(m.node_set("load").is_ok());
}

#[test]
fn natural_frequencies_match_calculix_to_1e6() {
    for e in &MODELS {
        let m = read_model(&deck(e.model)).unwrap();
        let expected = dat_eigenvalues(&data(e.model).join(format!("{}_freq.dat", e.model)));
        assert_eq!(expected.len(), 10, "{}", e.model);
        let chol = SparseCholesky::factor(&m.stiffness, "K").unwrap();
        let modes = lowest_modes(&chol, &m.mass, expected.len()).unwrap();
        let (mut worst_lambda, mut worst_hz, mut worst_digits) = (0.0f64, 0.0f64, 0.0f64);
        for (k, (&lambda, &(lambda_ccx, hz_ccx))) in modes.eigenvalues.iter().zip(&expected).enumerate() {
            let hz = lambda.sqrt() / (2.0 * std::f64::consts::PI);
            let (el, eh) = ((lambda / lambda_ccx - 1.0).abs(), (hz / hz_ccx - 1.0).abs());
            assert!(el <= 1e-6 && eh <= 1e-6, "{} mode {}: jprom {lambda:.9e} ({hz:.9e} Hz), ccx {lambda_ccx:.7e} ({hz_ccx:.7e} Hz)", e.model, k + 1);
            // ccx prints 7 significant digits (E14.7): the difference in units of half the
            // last printed digit (<= 1: jprom's value rounds to what ccx printed)
            let half_digit = 0.5e-7 * 10f64.powi(lambda_ccx.abs().log10().floor() as i32 + 1);
            worst_digits = worst_digits.max((lambda - lambda_ccx).abs() / half_digit);
            worst_lambda = worst_lambda.max(el);
            worst_hz = worst_hz.max(eh);
        }
        println!(
            "{}: {} DoFs, f1 = {:.6} Hz, f10 = {:.6} Hz; largest relative difference to ccx: eigenvalue {worst_lambda:.2e}, frequency {worst_hz:.2e}; eigenvalue difference / half the last printed digit {worst_digits:.2}",
            e.model,
            m.n(),
            modes.eigenvalues[0].sqrt() / (2.0 * std::f64::consts::PI),
            modes.eigenvalues[9].sqrt() / (2.0 * std::f64::consts::PI),
        );
    }
}

// ------------------------------------------------------------------------------------------
// exact semantics on small hand-written files
// ------------------------------------------------------------------------------------------

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn parse_err(r: Result<impl std::fmt::Debug, JpError>) -> (String, usize, String) {
    match r {
        Err(JpError::Parse { path, line, reason }) => (path, line, reason),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn one_triangle_is_mirrored_and_the_diagonal_kept_once() {
    let d = scratch("mirror");
    // ccx order: by column, upper triangle
    let upper = write(&d, "u.sti", "1 1  4.0e+00\n1 2 -1.0e+00\n2 2  5.0e+00\n2 3 -2.0e+00\n3 3  6.0e+00\n");
    // the same matrix from its lower triangle, in another order
    let lower = write(&d, "l.sti", "3 3 6.0\n2 1 -1.0\n3 2 -2.0\n1 1 4.0\n2 2 5.0\n");
    let want = [[4.0, -1.0, 0.0], [-1.0, 5.0, -2.0], [0.0, -2.0, 6.0]];
    for p in [&upper, &lower] {
        let a = read_matrix(p, 3).unwrap();
        for (i, row) in want.iter().enumerate() {
            for (j, &w) in row.iter().enumerate() {
                assert_eq!(entry(&a, i, j), w, "{} ({i}, {j})", p.display());
            }
        }
        assert_eq!(a.as_ref().val().len(), 7);
    }
    // a matrix wider than the file's largest index: rows without entries are refused
    // (ccx writes every diagonal entry)
    let (_, line, reason) = parse_err(read_matrix(&upper, 4));
    assert_eq!(line, 6);
    assert!(reason.contains("diagonal entry (4, 4)"), "{reason}");
}

#[test]
fn bad_matrix_files_name_the_file_and_the_line() {
    let d = scratch("badmat");
    let good = "1 1 4.0e+00\n1 2 -1.0e+00\n2 2 5.0e+00\n2 3 -2.0e+00\n3 3 6.0e+00\n";
    let cases: [(&str, String, usize, &str); 8] = [
        ("truncated inside a line", good[..good.len() - 5].to_string(), 5, "truncated"),
        ("truncated after a line", good[..good.len() - 12].to_string(), 5, "diagonal entry (3, 3)"),
        ("non-numeric value", good.replace("-2.0e+00", "-2.0x+00"), 4, "'-2.0x+00' is not a number"),
        ("non-numeric index", good.replace("2 3 ", "2 c "), 4, "column 'c' is not a whole number"),
        ("index beyond the size", good.replace("2 3 ", "2 4 "), 4, "column 4 out of range 1..=3"),
        ("index 0", good.replace("1 2 ", "0 2 "), 2, "row 0 out of range"),
        ("both triangles", format!("{good}3 2 -2.0e+00\n"), 6, "(2, 3) is given twice (lines 4 and 6)"),
        ("missing field", good.replace("2 2 5.0e+00", "2 2"), 3, "expected 'row column value', got 2 fields"),
    ];
    for (what, text, want_line, want) in cases {
        let p = write(&d, "bad.sti", &text);
        let (path, line, reason) = parse_err(read_matrix(&p, 3));
        assert_eq!(path, p.display().to_string(), "{what}");
        assert_eq!(line, want_line, "{what}: {reason}");
        assert!(reason.contains(want), "{what}: {reason}");
    }
    // an infinite value and an empty line
    let p = write(&d, "inf.sti", &good.replace("6.0e+00", "inf"));
    assert!(parse_err(read_matrix(&p, 3)).2.contains("not finite"));
    let p = write(&d, "blank.sti", &good.replace("2 2 5.0e+00\n", "2 2 5.0e+00\n\n"));
    assert_eq!(parse_err(read_matrix(&p, 3)).1, 4);
    // a size far beyond the file: refused before n columns are allocated
    let p = write(&d, "small.sti", good);
    let (_, line, reason) = parse_err(read_matrix(&p, usize::MAX));
    assert_eq!(line, 6);
    assert!(reason.contains("diagonal entry (4, 4)"), "{reason}");
    // a missing file, a directory
    match read_matrix(&d.join("none.sti"), 3) {
        Err(JpError::Io { path, .. }) => assert!(path.ends_with("none.sti")),
        other => panic!("{other:?}"),
    }
    assert!(matches!(read_matrix(&d, 3), Err(JpError::Io { .. })));
}

#[test]
fn bad_dof_files_name_the_file_and_the_line() {
    let d = scratch("baddof");
    let cases = [
        ("2.1\n2.2\n2x3\n", 3, "no '.'"),
        ("2.1\n2.2\n2.\n", 3, "direction is not a whole number"),
        ("2.1\n2.7\n", 2, "direction 7 of node 2"),
        ("2.1\n0.2\n", 2, "node 0 out of range"),
        ("2.1\n3.1\n2.1\n", 3, "given twice, on lines 1 and 3"),
        ("2.1\n2.2\n2", 3, "no '.'"),
        ("2.1\n2.2\n2.3", 3, "truncated"),
        ("", 1, "empty"),
    ];
    for (text, want_line, want) in cases {
        let p = write(&d, "bad.dof", text);
        let (path, line, reason) = parse_err(read_dofs(&p));
        assert_eq!(path, p.display().to_string());
        assert_eq!(line, want_line, "{text:?}: {reason}");
        assert!(reason.contains(want), "{text:?}: {reason}");
    }
    assert_eq!(read_dofs(&write(&d, "ok.dof", "2.1\r\n2.2\r\n10.3\r\n")).unwrap(), vec![(2, 1), (2, 2), (10, 3)]);
}

/// A copy of the block job in a scratch directory, to break one file at a time.
fn block_copy(name: &str) -> PathBuf {
    let d = scratch(name);
    for ext in ["inp", "sti", "mas", "dof"] {
        std::fs::copy(data("block").join(format!("block.{ext}")), d.join(format!("block.{ext}"))).unwrap();
    }
    d
}

#[test]
fn a_broken_job_names_the_file_and_the_line() {
    // missing .dof
    let d = block_copy("nodof");
    std::fs::remove_file(d.join("block.dof")).unwrap();
    match read_model(&d.join("block.inp")) {
        Err(JpError::Io { path, reason }) => assert!(path.ends_with("block.dof") && reason.contains(".dof"), "{path}: {reason}"),
        other => panic!("{other:?}"),
    }
    // a .dof one row shorter than the matrices: the last column's index is beyond it
    let d = block_copy("shortdof");
    let dof = std::fs::read_to_string(d.join("block.dof")).unwrap();
    let n = dof.lines().count();
    let short: String = dof.lines().take(n - 1).map(|l| format!("{l}\n")).collect();
    std::fs::write(d.join("block.dof"), short).unwrap();
    let (path, line, reason) = parse_err(read_model(&d.join("block.inp")));
    assert!(path.ends_with("block.sti"));
    let first =
        std::fs::read_to_string(d.join("block.sti")).unwrap().lines().position(|l| l.split_whitespace().take(2).any(|f| f == n.to_string())).unwrap() + 1;
    assert_eq!(line, first, "{reason}");
    assert!(reason.contains(&format!("{n} out of range 1..={}", n - 1)), "{reason}");
    // truncated .mas
    let d = block_copy("cutmas");
    let mas = std::fs::read(d.join("block.mas")).unwrap();
    std::fs::write(d.join("block.mas"), &mas[..mas.len() / 2]).unwrap();
    let (path, line, reason) = parse_err(read_model(&d.join("block.inp")));
    assert!(path.ends_with("block.mas"));
    let cut = &mas[..mas.len() / 2];
    let lines = String::from_utf8_lossy(cut).lines().count();
    // cut inside a line: that line; cut after one: the end of the file, a diagonal missing
    let want = if cut.ends_with(b"\n") { lines + 1 } else { lines };
    assert_eq!(line, want, "{reason}");
    // a .dof node the deck does not define
    let d = block_copy("wrongdeck");
    let dof = std::fs::read_to_string(d.join("block.dof")).unwrap().replacen("2.1\n", "9999.1\n", 1);
    std::fs::write(d.join("block.dof"), dof).unwrap();
    let (path, line, reason) = parse_err(read_model(&d.join("block.inp")));
    assert!(path.ends_with("block.dof") && line == 1 && reason.contains("node 9999"), "{path}:{line}: {reason}");
    // a set name the deck does not have
    let m = read_model(&deck("block")).unwrap();
    match m.node_set("NOPE") {
        Err(JpError::InvalidValue { what, reason }) => {
            assert!(what.contains("NOPE") && reason.contains("block.inp") && reason.contains("TIP"), "{what}: {reason}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_decks_name_the_file_and_the_line() {
    let d = scratch("baddeck");
    let head = "*HEADING\n1, 2, 3 (a heading line, not data)\n*NODE, NSET=NALL\n1, 0, 0, 0\n2, 1.0d0, 0, 0\n3, 1, 1\n";
    // a good deck first: Fortran reals, missing coordinates, heading text left alone
    let m = read_mesh(&write(&d, "ok.inp", &format!("{head}** comment\n*Nset, nset=Tip\n 2 , 3,\n*NSET,NSET=ALL2\nTIP,1\n"))).unwrap();
    assert_eq!(m.coords[&2], [1.0, 0.0, 0.0]);
    assert_eq!(m.coords[&3], [1.0, 1.0, 0.0]);
    assert_eq!(m.node_set("TIP").unwrap(), &[2, 3]);
    assert_eq!(m.node_set("ALL2").unwrap(), &[1, 2, 3]);

    let cases = [
        ("*NSET, NSET=A\nB\n", 8, "node set B (in set A) is not defined above this line"),
        ("*NSET, NSET=A\n1, 7\n", 8, "node 7 of set A is not defined"),
        ("*NSET, NSET=A, GENERATE\n5, 9\n", 8, "selects no node"),
        ("*NSET, NSET=A, GENERATE\n3, 1\n", 8, "is not a range"),
        ("*NSET, NSET=A, GENERATE\n1, x\n", 8, "end 'x' is not a whole number"),
        ("*NSET\n1\n", 7, "*NSET without NSET=name"),
        ("*NODE\n4, 1.0, abc, 0\n", 8, "coordinate 2 'abc' is not a number"),
        ("*NODE\n4, 1.00000000000000000000001, 0, 0\n", 8, "ccx reads only the first 20"),
        ("*NODE\nx4, 1, 0, 0\n", 8, "node number 'x4'"),
        ("*NODE\n0, 1, 0, 0\n", 8, "node number 0"),
        ("*INCLUDE, INPUT=missing.msh\n", 7, "missing.msh does not exist"),
    ];
    for (tail, want_line, want) in cases {
        let p = write(&d, "bad.inp", &format!("{head}{tail}"));
        let (path, line, reason) = parse_err(read_mesh(&p));
        assert_eq!(path, p.display().to_string(), "{tail}");
        assert_eq!(line, want_line, "{tail}: {reason}");
        assert!(reason.contains(want), "{tail}: {reason}");
    }
    // an *INCLUDE inside a *NODE card: ccx reads the included lines in place, so the card goes
    // on in the include (and after it); Fortran reals without the exponent letter
    write(&d, "more.nod", "4, 1.5+1, 2.-1, -3.0D+00\n");
    let m = read_mesh(&write(&d, "nodes.inp", &format!("{head}*INCLUDE, INPUT=more.nod\n5, 0, 0, 1\n"))).unwrap();
    assert_eq!(m.coords[&4], [15.0, 0.2, -3.0]);
    assert_eq!(m.node_set("NALL").unwrap(), &[1, 2, 3, 4, 5]);
    // an error inside an include names the include and its line
    write(&d, "sets.msh", "** sets\n*NSET, NSET=S\n1, 2\n*NSET, NSET=T\nNOSUCHSET\n");
    let (path, line, reason) = parse_err(read_mesh(&write(&d, "inc.inp", &format!("{head}*INCLUDE, INPUT=\"sets.msh\"\n"))));
    assert!(path.ends_with("sets.msh") && line == 5 && reason.contains("NOSUCHSET"), "{path}:{line}: {reason}");
    // includes that never end
    let p = write(&d, "loop.inp", &format!("{head}*INCLUDE, INPUT=loop.inp\n"));
    let (_, line, reason) = parse_err(read_mesh(&p));
    assert_eq!(line, 7);
    assert!(reason.contains("nested deeper than 9"), "{reason}");
    // no node at all
    let (_, _, reason) = parse_err(read_mesh(&write(&d, "empty.inp", "*HEADING\nnothing\n")));
    assert!(reason.contains("no node"), "{reason}");
}

#[test]
fn job_files_are_found_beside_the_deck() {
    let f = CalculixFiles::of_job(Path::new("/x/y/blade.inp"));
    assert_eq!(f.sti, Path::new("/x/y/blade.sti"));
    assert_eq!(f.mas, Path::new("/x/y/blade.mas"));
    assert_eq!(f.dof, Path::new("/x/y/blade.dof"));
    assert_eq!(CalculixFiles::of_job(Path::new("/x/y/blade")), f);
}

/// Reading speed on a synthetic ccx-format file of a 60,000-DoF model (banded, 30 entries a
/// column in the upper triangle: 1.8 M lines, about 55 MB). Not run by default:
/// `cargo test --test calculix -- --ignored --nocapture`.
#[test]
#[ignore]
fn read_speed_60k_dofs() {
    use std::io::Write;
    let d = scratch("speed");
    let (n, band) = (60_000usize, 30usize);
    let sti = d.join("big.sti");
    let mut w = std::io::BufWriter::new(std::fs::File::create(&sti).unwrap());
    let mut lines = 0usize;
    for j in 1..=n {
        for i in j.saturating_sub(band - 1).max(1)..=j {
            let v = if i == j { 1.0e6 + j as f64 } else { -1.0e3 / (1 + j - i) as f64 };
            writeln!(w, "{i} {j} {v:20.13e}").unwrap();
            lines += 1;
        }
    }
    w.flush().unwrap();
    drop(w);
    let bytes = std::fs::metadata(&sti).unwrap().len();
    let t = std::time::Instant::now();
    let a = read_matrix(&sti, n).unwrap();
    let s = t.elapsed().as_secs_f64();
    assert_eq!(a.as_ref().val().len(), 2 * lines - n);
    println!("read {lines} lines ({:.1} MB) of a {n}-DoF matrix in {s:.2} s ({:.0} MB/s)", bytes as f64 / 1e6, bytes as f64 / 1e6 / s);
    let _ = std::fs::remove_dir_all(&d);
}
