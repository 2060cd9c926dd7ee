//! Matrix Market import and export of sparse FE matrices (`M`, `K`, optional `C`).
//!
//! Supported: `%%MatrixMarket matrix coordinate real|integer general|symmetric`, 1-based
//! indices. A symmetric file stores the lower triangle only (an entry above the diagonal is
//! an error); it is expanded to full storage on reading. Duplicate entries are summed (as most
//! FE exporters expect). Unsupported (each a readable error): `array` format, `complex` and
//! `pattern` fields, `skew-symmetric` and `hermitian` symmetry.
//!
//! Every malformed file gives [`JpError::Parse`] with the 1-based line number and the reason;
//! nothing panics on bad input.

use crate::cms::{sparse_from_triplets, sparse_triplets, SparseMat};
use crate::error::{JpError, Result};
use std::path::Path;

fn perr(path: &str, line: usize, reason: impl Into<String>) -> JpError {
    JpError::Parse { path: path.to_string(), line, reason: reason.into() }
}

/// Reads a Matrix Market coordinate file into a CSC matrix (full storage).
///
/// # Errors
/// [`JpError::Io`] if the file cannot be read, [`JpError::Parse`] if it is malformed.
pub fn read_matrix_market(path: &Path) -> Result<SparseMat> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| JpError::Io { path: path.display().to_string(), reason: e.to_string() })?;
    parse_matrix_market(&text, &path.display().to_string())
}

/// Parses Matrix Market text; `name` is used in error messages.
///
/// # Errors
/// [`JpError::Parse`] with the line number and reason for a malformed text.
pub fn parse_matrix_market(text: &str, name: &str) -> Result<SparseMat> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
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
        let t = l.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        let f: Vec<&str> = t.split_whitespace().collect();
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
        size = Some((v[0], v[1], v[2], ln));
        break;
    }
    let (nrows, ncols, nnz, _) = size.ok_or_else(|| perr(name, last_line + 1, "missing size line (rows cols entries)"))?;
    if nnz > nrows.saturating_mul(ncols) {
        return Err(perr(name, last_line, format!("wrong counts: {nnz} entries cannot fit in {nrows} x {ncols}")));
    }

    let mut triplets = Vec::with_capacity(if symmetric { 2 * nnz } else { nnz });
    let mut count = 0usize;
    for (ln, l) in lines {
        last_line = ln;
        let t = l.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        if count == nnz {
            return Err(perr(name, ln, format!("wrong counts: more entries than the {nnz} declared")));
        }
        let f: Vec<&str> = t.split_whitespace().collect();
        if f.len() != 3 {
            return Err(perr(name, ln, format!("entry must be 'row col value', got {} fields", f.len())));
        }
        let idx = |s: &str, what: &str, max: usize| -> Result<usize> {
            let i: i64 = s.parse().map_err(|_| perr(name, ln, format!("{what} index '{s}' is not an integer")))?;
            if i < 1 || i as u64 > max as u64 {
                return Err(perr(name, ln, format!("{what} index {i} out of range 1..={max}")));
            }
            Ok(i as usize - 1)
        };
        let i = idx(f[0], "row", nrows)?;
        let j = idx(f[1], "column", ncols)?;
        let v: f64 = f[2].parse().map_err(|_| perr(name, ln, format!("value '{}' is not a number", f[2])))?;
        if !v.is_finite() {
            return Err(perr(name, ln, format!("value '{}' is not finite", f[2])));
        }
        if symmetric {
            if i < j {
                return Err(perr(
                    name,
                    ln,
                    format!("entry ({}, {}) above the diagonal in a symmetric file (store the lower triangle)", i + 1, j + 1),
                ));
            }
            if i != j {
                triplets.push((j, i, v));
            }
        }
        triplets.push((i, j, v));
        count += 1;
    }
    if count < nnz {
        return Err(perr(name, last_line + 1, format!("missing entries: {nnz} declared, {count} found")));
    }
    sparse_from_triplets(nrows, ncols, triplets).map_err(|e| perr(name, 0, e.to_string()))
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
        let t = crate::cms::sparse_from_triplets(a.ncols(), a.nrows(), tr.iter().map(|&(i, j, v)| (j, i, v)).collect())?;
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
    std::fs::write(path, s).map_err(|e| JpError::Io { path: path.display().to_string(), reason: e.to_string() })
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

/// Reads `M`, `K` and optionally `C`, and checks they are square and of one size.
///
/// # Errors
/// As [`read_matrix_market`]; [`JpError::BadSize`] if the sizes disagree.
pub fn read_structural_matrices(mass: &Path, stiffness: &Path, damping: Option<&Path>) -> Result<StructuralMatrices> {
    let m = read_matrix_market(mass)?;
    let k = read_matrix_market(stiffness)?;
    let c = damping.map(read_matrix_market).transpose()?;
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
