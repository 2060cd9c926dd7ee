//! Matrix Market import and export of sparse FE matrices (`M`, `K`, optional `C`).
//!
//! Supported: `%%MatrixMarket matrix coordinate real|integer general|symmetric`, 1-based
//! indices. A `general` file is kept exactly as given, both triangles. A `symmetric` file
//! stores the lower triangle only (an entry above the diagonal is an error, naming the
//! lower-triangle value it would conflict with); it is expanded to full storage on reading.
//! Duplicate entries are summed (as most FE exporters expect). Unsupported (each a readable
//! error): `array` format, `complex` and `pattern` fields, `skew-symmetric` and `hermitian`
//! symmetry.
//!
//! Sizes are checked before anything is allocated: the declared entry count against the
//! lines the file has, and the storage against the memory budget ([`crate::memory`]).
//! Matrices used as symmetric (`M`, `K`: [`read_symmetric_matrix_market`]) must be square,
//! have at least one entry per row, and be symmetric; a `general` one that is not is refused
//! with the first offending pair of entries.
//!
//! Every malformed file gives [`JpError::Parse`] with the 1-based line number and the reason;
//! nothing panics on bad input.

use crate::linalg::sparse::{sparse_triplets, SparseMat};
use crate::error::{JpError, Result};
use crate::linalg::SYMMETRY_TOLERANCE;
use std::path::Path;

mod entries;

fn perr(path: &str, line: usize, reason: impl Into<String>) -> JpError {
    JpError::Parse { path: path.to_string(), line, reason: reason.into() }
}

/// Reads a Matrix Market coordinate file into a CSC matrix (full storage).
///
/// # Errors
/// [`JpError::Io`] if the file cannot be read, [`JpError::Parse`] if it is malformed,
/// [`JpError::TooLarge`] if its storage would exceed the memory budget.
pub fn read_matrix_market(path: &Path) -> Result<SparseMat> {
    let text = super::read_text(path)?;
    parse_matrix_market(&text, &path.display().to_string())
}

/// Reads a matrix that is used as symmetric (a mass or stiffness matrix): as
/// [`read_matrix_market`], and the matrix must be square with at least one entry per row
/// (checked from the size line, before reading the entries) and symmetric to
/// [`SYMMETRY_TOLERANCE`] relative to its largest entry.
///
/// # Errors
/// As [`read_matrix_market`]; [`JpError::Parse`] for a non-square matrix, too few entries, or
/// a `general` matrix that is not symmetric (naming the entry, its value and its mirror's).
pub fn read_symmetric_matrix_market(path: &Path) -> Result<SparseMat> {
    let text = super::read_text(path)?;
    parse_symmetric_matrix_market(&text, &path.display().to_string())
}

/// [`read_symmetric_matrix_market`] on a text; `name` is used in error messages.
///
/// # Errors
/// As [`read_symmetric_matrix_market`].
pub fn parse_symmetric_matrix_market(text: &str, name: &str) -> Result<SparseMat> {
    let (a, symmetric_file) = parse_with_symmetry(text, name, true)?;
    // a symmetric file's matrix is symmetric by construction; a general one is checked
    if !symmetric_file {
        check_symmetric(&a, name)?;
    }
    Ok(a)
}

/// Parses Matrix Market text; `name` is used in error messages.
///
/// # Errors
/// [`JpError::Parse`] with the line number and reason for a malformed text;
/// [`JpError::TooLarge`] if its storage would exceed the memory budget.
pub fn parse_matrix_market(text: &str, name: &str) -> Result<SparseMat> {
    parse(text, name, false)
}

/// Whether a line holds data (not blank, not a comment).
fn is_data(l: &str) -> bool {
    let t = l.trim();
    !t.is_empty() && !t.starts_with('%')
}

/// Bytes of the triplets and the CSC storage of `entries` values in a matrix of `ncols`.
fn storage_bytes(entries: usize, ncols: usize) -> u128 {
    use crate::memory::{bytes_of, product};
    // triplets (row, col, value), then CSC: column pointers, row indices and values
    bytes_of::<(usize, usize, f64)>(entries as u128)
        .saturating_add(bytes_of::<usize>(ncols as u128 + 1))
        .saturating_add(product(&[entries, 16]))
}

fn parse(text: &str, name: &str, structural: bool) -> Result<SparseMat> {
    parse_with_symmetry(text, name, structural).map(|(a, _)| a)
}

/// The matrix, and whether the file was `symmetric` (then the matrix is exactly symmetric by
/// construction: each stored value is used for both triangles).
fn parse_with_symmetry(text: &str, name: &str, structural: bool) -> Result<(SparseMat, bool)> {
    // lines with their ends, numbered from 1; `consumed` counts the bytes of those read
    let mut consumed = 0usize;
    let mut lines = text.split_inclusive('\n').enumerate().map(|(i, l)| (i + 1, l)).inspect(|(_, l)| consumed += l.len());
    let (_, header) = lines.next().ok_or_else(|| perr(name, 1, "empty file (expected a %%MatrixMarket header)"))?;
    let h: Vec<String> = header.split_whitespace().map(|s| s.to_ascii_lowercase()).collect();
    if h.first().map(String::as_str) != Some("%%matrixmarket") {
        return Err(perr(name, 1, "bad header: first line must start with %%MatrixMarket"));
    }
    if h.len() != 5 {
        return Err(perr(name, 1, format!("bad header: expected 5 fields (%%MatrixMarket matrix coordinate <field> <symmetry>), got {}", h.len())));
    }
    if h[1] != "matrix" {
        return Err(perr(name, 1, format!("bad header: object '{}' unsupported (only 'matrix')", h[1])));
    }
    if h[2] != "coordinate" {
        return Err(perr(name, 1, format!("bad header: format '{}' unsupported (only 'coordinate')", h[2])));
    }
    match h[3].as_str() {
        "real" | "integer" | "double" => {}
        "complex" | "pattern" => {
            return Err(perr(name, 1, format!("{} field unsupported (only real or integer values)", h[3])));
        }
        other => return Err(perr(name, 1, format!("bad header: unknown field '{other}'"))),
    }
    let symmetric = match h[4].as_str() {
        "general" => false,
        "symmetric" => true,
        "skew-symmetric" | "hermitian" => {
            return Err(perr(name, 1, format!("{} symmetry unsupported (only general or symmetric)", h[4])));
        }
        other => return Err(perr(name, 1, format!("bad header: unknown symmetry '{other}'"))),
    };

    // Size line: first non-comment, non-blank line.
    let mut size: Option<(usize, usize, usize, usize)> = None;
    let mut last_line = 1;
    for (ln, l) in lines.by_ref() {
        last_line = ln;
        if !is_data(l) {
            continue;
        }
        let v = parse_size_line(l, name, ln, symmetric)?;
        size = Some((v[0], v[1], v[2], ln));
        break;
    }
    let (nrows, ncols, nnz, size_line) = size.ok_or_else(|| perr(name, last_line + 1, "missing size line (rows cols entries)"))?;
    check_counts(name, size_line, [nrows, ncols, nnz], structural)?;
    drop(lines);
    let body = &text[consumed..];
    let chunks = entries::parse_chunks(body, nrows, ncols, symmetric);
    // the declared count against the lines there are, then the storage against the budget
    let entry_lines: usize = chunks.iter().map(|c| c.data_lines).sum();
    if nnz > entry_lines {
        return Err(perr(name, size_line, format!("missing entries: {nnz} declared, the file has {entry_lines} entry lines")));
    }
    let stored = if symmetric { nnz.saturating_mul(2) } else { nnz };
    crate::memory::check(&format!("the {nrows} x {ncols} matrix of {name} ({nnz} entries)"), storage_bytes(stored, ncols))?;

    // the first error in the file: a malformed line, or the first entry beyond the declared
    // count (which wins on its own line, being found before the line is parsed)
    let (mut first, mut data_before) = (size_line + 1, 0usize);
    for c in &chunks {
        let excess = (data_before + c.data_lines > nnz).then(|| entries::nth_data_line(c.text, nnz - data_before)).flatten();
        match (excess, &c.error) {
            (Some(x), Some((e, _))) if x <= *e => return Err(perr(name, first + x, format!("wrong counts: more entries than the {nnz} declared"))),
            (Some(x), None) => return Err(perr(name, first + x, format!("wrong counts: more entries than the {nnz} declared"))),
            (_, Some((e, reason))) => return Err(perr(name, first + e, reason.clone())),
            (None, None) => {}
        }
        data_before += c.data_lines;
        first += c.lines;
    }
    let mut first = size_line + 1;
    for c in &chunks {
        if let Some((i, j, v, l)) = c.upper {
            // the lower-triangle value at (j, i), summed over duplicates, if the file gives one
            let mirror: Vec<f64> = chunks.iter().flat_map(|c| &c.entries).filter(|t| t.0 == j && t.1 == i).map(|t| t.2).collect();
            let reason = if mirror.is_empty() {
                format!("entry ({}, {}) = {v:e} above the diagonal in a symmetric file (store the lower triangle only)", i + 1, j + 1)
            } else {
                let w: f64 = mirror.iter().sum();
                format!(
                    "entry ({}, {}) = {v:e} above the diagonal in a symmetric file, which also gives ({}, {}) = {w:e}{} (store the lower triangle only)",
                    i + 1,
                    j + 1,
                    j + 1,
                    i + 1,
                    if w == v { "" } else { ": the two conflict" }
                )
            };
            return Err(perr(name, first + l, reason));
        }
        first += c.lines;
    }
    let (col_ptr, row_idx, val) = entries::assemble(ncols, &chunks, symmetric);
    drop(chunks);
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(nrows, ncols, col_ptr, None, row_idx);
    Ok((faer::sparse::SparseColMat::new(symbolic, val), symmetric))
}

/// A square matrix must equal its transpose to [`SYMMETRY_TOLERANCE`] times its largest
/// entry; else the first (by column) offending pair is named, 1-based.
fn check_symmetric(a: &SparseMat, name: &str) -> Result<()> {
    match crate::linalg::sparse::first_asymmetry(a, SYMMETRY_TOLERANCE) {
        None => Ok(()),
        Some((i, j, v, w)) => Err(perr(
            name,
            0,
            format!(
                "used as symmetric but not symmetric: entry ({}, {}) = {v:e} while ({}, {}) = {w:e}{} (relative tolerance {SYMMETRY_TOLERANCE:e})",
                i + 1,
                j + 1,
                j + 1,
                i + 1,
                if w == 0.0 { " (not given)" } else { "" }
            ),
        )),
    }
}

/// Formats a matrix as Matrix Market text. With `symmetric`, only the lower triangle is
/// written (the matrix must be exactly symmetric). Values use 17 significant digits, so the
/// round trip is exact.
///
/// # Errors
/// [`JpError::InvalidValue`] if `symmetric` is asked for a non-symmetric matrix.
pub fn format_matrix_market(a: &SparseMat, symmetric: bool) -> Result<String> {
    use std::fmt::Write;
    let tr = sparse_triplets(a);
    let entries: Vec<(usize, usize, f64)> = if symmetric {
        if a.nrows() != a.ncols() {
            return Err(JpError::invalid("matrix", "symmetric Matrix Market output needs a square matrix"));
        }
        let t = crate::linalg::sparse::sparse_from_triplets(a.ncols(), a.nrows(), tr.iter().map(|&(i, j, v)| (j, i, v)).collect())?;
        let tt = sparse_triplets(&t);
        if tt.len() != tr.len() || tt.iter().zip(&tr).any(|(x, y)| x != y) {
            return Err(JpError::invalid("matrix", "not exactly symmetric; write it as general"));
        }
        tr.into_iter().filter(|&(i, j, _)| i >= j).collect()
    } else {
        tr
    };
    let mut s = String::with_capacity(40 * entries.len() + 100);
    let sym = if symmetric { "symmetric" } else { "general" };
    let _ = writeln!(s, "%%MatrixMarket matrix coordinate real {sym}");
    let _ = writeln!(s, "% written by jprom");
    let _ = writeln!(s, "{} {} {}", a.nrows(), a.ncols(), entries.len());
    for (i, j, v) in entries {
        let _ = writeln!(s, "{} {} {:.17e}", i + 1, j + 1, v);
    }
    Ok(s)
}

/// Writes a matrix to a Matrix Market file (see [`format_matrix_market`]).
///
/// # Errors
/// [`JpError::Io`] if the file cannot be written, or as [`format_matrix_market`].
pub fn write_matrix_market(path: &Path, a: &SparseMat, symmetric: bool) -> Result<()> {
    let s = format_matrix_market(a, symmetric)?;
    super::write_file(path, |w| w.write_all(s.as_bytes()))
}

/// Structural matrices read from Matrix Market files.
#[derive(Clone, Debug)]
pub struct StructuralMatrices {
    /// Mass `M`.
    pub mass: SparseMat,
    /// Stiffness `K`.
    pub stiffness: SparseMat,
    /// Damping `C`, if given.
    pub damping: Option<SparseMat>,
}

/// Reads `M`, `K` and optionally `C` (each used as symmetric:
/// [`read_symmetric_matrix_market`]), and checks they are of one size.
///
/// # Errors
/// As [`read_matrix_market`]; [`JpError::BadSize`] if the sizes disagree.
pub fn read_structural_matrices(mass: &Path, stiffness: &Path, damping: Option<&Path>) -> Result<StructuralMatrices> {
    let m = read_symmetric_matrix_market(mass)?;
    let k = read_symmetric_matrix_market(stiffness)?;
    let c = damping.map(read_symmetric_matrix_market).transpose()?;
    let n = k.nrows();
    for (what, a) in [("stiffness", Some(&k)), ("mass", Some(&m)), ("damping", c.as_ref())] {
        if let Some(a) = a {
            if a.nrows() != n || a.ncols() != n {
                return Err(JpError::bad_size(format!("{what} (rows x cols)"), n * n, a.nrows() * a.ncols()));
            }
        }
    }
    Ok(StructuralMatrices { mass: m, stiffness: k, damping: c })
}

/// What the first lines of a Matrix Market file declare (read by
/// [`read_matrix_market_header`] without reading the entries).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MatrixMarketHeader {
    pub rows: usize,
    pub cols: usize,
    /// Entries declared on the size line (stored ones: a `symmetric` file stores one triangle).
    pub entries: usize,
    pub symmetric: bool,
    /// Size of the file in bytes.
    pub file_bytes: u64,
}

/// Reads only the header and the size line of a Matrix Market file, with the same rules as
/// [`read_matrix_market`] for them (a quick check of a file before reading it all: the entries
/// are not read, so a malformed entry is found only by the full reader). For a
/// `structural` matrix (a mass or stiffness), the size line must also declare a square matrix
/// with at least one entry per row, as [`read_symmetric_matrix_market`] requires.
///
/// # Errors
/// [`JpError::Io`] if the file is missing, not a regular file or unreadable;
/// [`JpError::Parse`] with the line for a bad header or size line.
pub fn read_matrix_market_header(path: &Path, structural: bool) -> Result<MatrixMarketHeader> {
    use std::io::{BufRead, Read};
    let name = path.display().to_string();
    let io = |e: std::io::Error| JpError::Io { path: name.clone(), reason: e.to_string() };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(JpError::Io { path: name.clone(), reason: "is not a regular file".into() });
    }
    let mut reader = std::io::BufReader::new(std::fs::File::open(path).map_err(io)?);
    // header and comments are short: a line longer than this is not a Matrix Market header
    let mut head = String::new();
    let mut ln = 0usize;
    let mut size_line: Option<(usize, String)> = None;
    loop {
        let mut line = Vec::new();
        let got = (&mut reader).take(1 << 16).read_until(b'\n', &mut line).map_err(io)?;
        if got == 0 {
            break;
        }
        ln += 1;
        let text = String::from_utf8(line).map_err(|_| perr(&name, ln, "not UTF-8 text"))?;
        if ln == 1 {
            head = text;
            continue;
        }
        if is_data(&text) {
            size_line = Some((ln, text));
            break;
        }
    }
    // the full reader's rules on the first lines: header, comments, size line
    let mut text = head;
    if !text.ends_with('\n') && !text.is_empty() {
        text.push('\n');
    }
    // a bad header first, as the full reader says it (an empty matrix: nothing allocated)
    if let Err(JpError::Parse { line: 1, reason, .. }) = parse(&format!("{text}0 0 0\n"), &name, false) {
        return Err(perr(&name, 1, reason));
    }
    let (size_ln, size) = size_line.ok_or_else(|| perr(&name, ln + 1, "missing size line (rows cols entries)"))?;
    let symmetric = symmetric_header(&text);
    let [rows, cols, entries] = parse_size_line(&size, &name, size_ln, symmetric)?;
    check_counts(&name, size_ln, [rows, cols, entries], structural)?;
    Ok(MatrixMarketHeader { rows, cols, entries, symmetric, file_bytes: meta.len() })
}

/// The size line `rows cols entries` at line `ln` (a symmetric matrix must be square).
fn parse_size_line(l: &str, name: &str, ln: usize, symmetric: bool) -> Result<[usize; 3]> {
    let f: Vec<&str> = l.split_whitespace().collect();
    if f.len() != 3 {
        return Err(perr(name, ln, format!("size line must have 3 integers (rows cols entries), got {} fields", f.len())));
    }
    let mut v = [0usize; 3];
    for k in 0..3 {
        v[k] = f[k].parse().map_err(|_| perr(name, ln, format!("size line: '{}' is not a non-negative integer", f[k])))?;
    }
    if symmetric && v[0] != v[1] {
        return Err(perr(name, ln, format!("symmetric matrix must be square, got {} x {}", v[0], v[1])));
    }
    Ok(v)
}

/// The declared counts: entries that fit in `rows x cols`, and for a `structural` matrix (a
/// mass or stiffness) a square one with at least its diagonal.
fn check_counts(name: &str, ln: usize, [nrows, ncols, nnz]: [usize; 3], structural: bool) -> Result<()> {
    if nnz as u128 > crate::memory::product(&[nrows, ncols]) {
        return Err(perr(name, ln, format!("wrong counts: {nnz} entries cannot fit in {nrows} x {ncols}")));
    }
    if structural {
        if nrows != ncols {
            return Err(perr(name, ln, format!("a mass or stiffness matrix must be square, got {nrows} x {ncols}")));
        }
        if nnz < nrows {
            return Err(perr(
                name,
                ln,
                format!("{nrows} x {ncols} with {nnz} entries: a mass or stiffness matrix needs at least one entry per row (its diagonal), so at least {nrows}"),
            ));
        }
    }
    Ok(())
}

fn symmetric_header(header: &str) -> bool {
    header.lines().next().is_some_and(|h| h.to_ascii_lowercase().split_whitespace().nth(4) == Some("symmetric"))
}

#[cfg(test)]
mod header_tests {
    use super::*;

    #[test]
    fn the_header_is_read_without_the_entries() {
        let dir = std::env::temp_dir().join(format!("jprom-mm-header-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.mtx");
        std::fs::write(&p, "%%MatrixMarket matrix coordinate real symmetric\n% comment\n\n3 3 4\nthis is not an entry\n").unwrap();
        let h = read_matrix_market_header(&p, true).unwrap();
        assert_eq!((h.rows, h.cols, h.entries, h.symmetric), (3, 3, 4, true));
        assert!(read_matrix_market(&p).is_err(), "the full reader reads the entries");
        for (text, line, says) in [
            ("%%MatrixMarket matrix array real general\n3 3\n", 1, "format 'array'"),
            ("%%MatrixMarket matrix coordinate real general\n3 2 6\n", 2, "square"),
            ("%%MatrixMarket matrix coordinate real general\n% only a comment\n", 3, "missing size line"),
            ("%%MatrixMarket matrix coordinate real general\n3 x 6\n", 2, "not a non-negative integer"),
            ("not a header\n3 3 3\n", 1, "%%MatrixMarket"),
        ] {
            std::fs::write(&p, text).unwrap();
            match read_matrix_market_header(&p, true) {
                Err(JpError::Parse { line: l, reason, .. }) => assert!(l == line && reason.contains(says), "{text:?}: line {l}: {reason}"),
                other => panic!("{text:?}: {other:?}"),
            }
        }
        assert!(matches!(read_matrix_market_header(&dir.join("none.mtx"), true), Err(JpError::Io { .. })));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
