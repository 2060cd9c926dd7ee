//! The entry lines of a Matrix Market coordinate file, parsed in parallel, and their CSC
//! assembly by column counts (no global sort).
//!
//! The body (the text after the size line) is cut into chunks at line ends; each chunk is
//! parsed on its own thread. A line takes the fast path (ASCII digits for the indices, no
//! allocation) when it is plainly `row col value`; any other line (a sign on an index, a non-ASCII space, a
//! bad field) goes through the reference parser ([`slow_entry`]), which accepts exactly what
//! `str::parse` accepts and words every error. The chunks' line counts then turn each chunk's
//! first error into the file's line number, and the error that comes first in the file is the
//! one reported, as a line-by-line reader would.
//!
//! Assembly: the entries are counted per column, scattered in file order (so that duplicates
//! are summed in file order, as a stable sort would), then each column is sorted by row only
//! if it is not already (an FE export written column by column needs no sort), and its
//! duplicates summed.

use rayon::prelude::*;

/// Bytes per chunk: large enough that the per-chunk work is negligible, small enough that
/// two to eight threads share a 100 MB file evenly.
const CHUNK_BYTES: usize = 1 << 21;

/// An entry as read: 0-based row and column, value.
pub(super) type Entry = (usize, usize, f64);

/// What one chunk gives.
pub(super) struct Chunk<'a> {
    /// The chunk's text.
    pub text: &'a str,
    /// Lines in the chunk (its text ends at a line end, or at the end of the file).
    pub lines: usize,
    /// Data lines (not blank, not a comment), counted to the end of the chunk even after an
    /// error, so that the file's count of entry lines is exact.
    pub data_lines: usize,
    /// The entries read, in file order, up to the first error.
    pub entries: Vec<Entry>,
    /// The first malformed line: 0-based line within the chunk, and the reason.
    pub error: Option<(usize, String)>,
    /// The first entry above the diagonal (for a `symmetric` file): row, column, value, and
    /// its 0-based line within the chunk. It is kept in `entries` too.
    pub upper: Option<(usize, usize, f64, usize)>,
}

/// Whether a line holds data (not blank, not a comment), as `is_data` in the parent decides,
/// without building a `&str` for ASCII lines.
fn is_data(l: &[u8]) -> bool {
    for (k, &b) in l.iter().enumerate() {
        match b {
            b' ' | b'\t' | b'\r' | 0x0b | 0x0c => continue,
            b'%' => return false,
            0x80.. => return std::str::from_utf8(&l[k..]).map_or(true, super::is_data),
            _ => return true,
        }
    }
    false
}

/// A 1-based index of at most 18 ASCII digits, with the whitespace after it; `None` for
/// anything else (the reference parser then decides).
#[inline]
fn fast_index(l: &[u8], pos: &mut usize, max: usize) -> Option<usize> {
    let start = *pos;
    let mut v: u64 = 0;
    while *pos < l.len() && l[*pos].is_ascii_digit() {
        v = v * 10 + u64::from(l[*pos] - b'0');
        *pos += 1;
        if *pos - start > 18 {
            return None;
        }
    }
    if *pos == start || v == 0 || v > max as u64 {
        return None;
    }
    Some(v as usize - 1)
}

#[inline]
fn skip_blanks(l: &[u8], pos: &mut usize) -> bool {
    let start = *pos;
    while *pos < l.len() && matches!(l[*pos], b' ' | b'\t' | b'\r') {
        *pos += 1;
    }
    *pos > start
}

/// A finite value, by `str::parse::<f64>` (correctly rounded). A faster float parser
/// (`fast-float2`) was measured here and made no difference: the time is in scanning the
/// lines and assembling the matrix.
#[inline]
pub(super) fn fast_value(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// The fast path for one data line: `row col value` and optional trailing blanks.
#[inline]
fn fast_entry(l: &[u8], nrows: usize, ncols: usize) -> Option<Entry> {
    let mut pos = 0;
    skip_blanks(l, &mut pos);
    let i = fast_index(l, &mut pos, nrows)?;
    if !skip_blanks(l, &mut pos) {
        return None;
    }
    let j = fast_index(l, &mut pos, ncols)?;
    if !skip_blanks(l, &mut pos) {
        return None;
    }
    let start = pos;
    while pos < l.len() && !matches!(l[pos], b' ' | b'\t' | b'\r') {
        pos += 1;
    }
    let v = fast_value(&l[start..pos])?;
    skip_blanks(l, &mut pos);
    (pos == l.len()).then_some((i, j, v))
}

/// The reference parser of one data line (the reader's rules, word for word): fields split
/// on any whitespace, indices as `i64` in range, the value by `str::parse::<f64>`, finite.
pub(super) fn slow_entry(l: &str, nrows: usize, ncols: usize) -> Result<Entry, String> {
    let f: Vec<&str> = l.split_whitespace().collect();
    if f.len() != 3 {
        return Err(format!("entry must be 'row col value', got {} fields", f.len()));
    }
    let idx = |s: &str, what: &str, max: usize| -> Result<usize, String> {
        let i: i64 = s.parse().map_err(|_| format!("{what} index '{s}' is not an integer"))?;
        if i < 1 || i as u64 > max as u64 {
            return Err(format!("{what} index {i} out of range 1..={max}"));
        }
        Ok(i as usize - 1)
    };
    let i = idx(f[0], "row", nrows)?;
    let j = idx(f[1], "column", ncols)?;
    let v: f64 = f[2].parse().map_err(|_| format!("value '{}' is not a number", f[2]))?;
    if !v.is_finite() {
        return Err(format!("value '{}' is not finite", f[2]));
    }
    Ok((i, j, v))
}

/// Parses one chunk of lines (a `&str` cut at line ends).
fn parse_chunk(text: &str, nrows: usize, ncols: usize, symmetric: bool) -> Chunk<'_> {
    let bytes = text.as_bytes();
    // about 30 bytes a line in FE exports; the vector grows if lines are shorter
    let mut c = Chunk { text, lines: 0, data_lines: 0, entries: Vec::with_capacity(bytes.len() / 28 + 1), error: None, upper: None };
    let mut start = 0;
    while start < bytes.len() {
        let end = bytes[start..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |k| start + k);
        let l = &bytes[start..end];
        let ln = c.lines;
        c.lines += 1;
        start = end + 1;
        if !is_data(l) {
            continue;
        }
        c.data_lines += 1;
        if c.error.is_some() {
            continue;
        }
        let e = match fast_entry(l, nrows, ncols) {
            Some(e) => Ok(e),
            // a line of a &str cut at '\n' is a &str
            None => slow_entry(std::str::from_utf8(l).unwrap_or_default(), nrows, ncols),
        };
        match e {
            Ok(e) => {
                if symmetric && e.0 < e.1 && c.upper.is_none() {
                    c.upper = Some((e.0, e.1, e.2, ln));
                }
                c.entries.push(e);
            }
            Err(reason) => c.error = Some((ln, reason)),
        }
    }
    c
}

/// Cuts `text` into pieces of about [`CHUNK_BYTES`] that end at line ends and parses them in
/// parallel, in order.
pub(super) fn parse_chunks(text: &str, nrows: usize, ncols: usize, symmetric: bool) -> Vec<Chunk<'_>> {
    let bytes = text.as_bytes();
    let mut pieces = Vec::with_capacity(bytes.len() / CHUNK_BYTES + 1);
    let mut start = 0;
    while start < bytes.len() {
        let mut end = (start + CHUNK_BYTES).min(bytes.len());
        if end < bytes.len() {
            end = bytes[end..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |k| end + k + 1);
        }
        pieces.push(&text[start..end]);
        start = end;
    }
    pieces.into_par_iter().map(|p| parse_chunk(p, nrows, ncols, symmetric)).collect()
}

/// The 0-based line, within `text`, of its `k`-th data line (0-based); `None` if it has fewer.
pub(super) fn nth_data_line(text: &str, k: usize) -> Option<usize> {
    text.split('\n').enumerate().filter(|(_, l)| is_data(l.as_bytes())).nth(k).map(|(ln, _)| ln)
}

/// CSC arrays (column pointers, row indices, values) of the entries, in the order given;
/// with `symmetric`, an entry `(i, j)` off the diagonal also stands for `(j, i)` (put first,
/// as the mirror of a lower-triangle entry). Duplicates are summed in input order, so the
/// values are those of a stable sort by (column, row) followed by a running sum.
pub(super) fn assemble(ncols: usize, chunks: &[Chunk<'_>], symmetric: bool) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    let mut col_ptr = vec![0usize; ncols + 1];
    for c in chunks {
        for &(i, j, _) in &c.entries {
            col_ptr[j + 1] += 1;
            if symmetric && i != j {
                col_ptr[i + 1] += 1;
            }
        }
    }
    for j in 0..ncols {
        col_ptr[j + 1] += col_ptr[j];
    }
    let total = col_ptr[ncols];
    let mut rows = vec![0usize; total];
    let mut vals = vec![0.0f64; total];
    let mut next = col_ptr.clone();
    for c in chunks {
        for &(i, j, v) in &c.entries {
            if symmetric && i != j {
                let k = next[i];
                rows[k] = j;
                vals[k] = v;
                next[i] += 1;
            }
            let k = next[j];
            rows[k] = i;
            vals[k] = v;
            next[j] += 1;
        }
    }
    drop(next);
    // sort each column by row (stable) unless it is sorted, and sum its duplicates in place:
    // `kept[j]` entries remain at the head of column j
    let mut kept = vec![0usize; ncols];
    {
        let mut cols: Vec<(&mut [usize], &mut [f64], &mut usize)> = Vec::with_capacity(ncols);
        let (mut r, mut v) = (rows.as_mut_slice(), vals.as_mut_slice());
        for (j, kj) in kept.iter_mut().enumerate() {
            let len = col_ptr[j + 1] - col_ptr[j];
            let (rc, rt) = r.split_at_mut(len);
            let (vc, vt) = v.split_at_mut(len);
            cols.push((rc, vc, kj));
            (r, v) = (rt, vt);
        }
        cols.into_par_iter().with_min_len(256).for_each(|(r, v, kj)| *kj = sort_and_sum(r, v));
    }
    // compact
    let mut out = 0;
    let mut new_ptr = vec![0usize; ncols + 1];
    for j in 0..ncols {
        let s = col_ptr[j];
        if out != s {
            rows.copy_within(s..s + kept[j], out);
            vals.copy_within(s..s + kept[j], out);
        }
        out += kept[j];
        new_ptr[j + 1] = out;
    }
    rows.truncate(out);
    vals.truncate(out);
    (new_ptr, rows, vals)
}

/// Sorts one column's entries by row (stable), sums duplicates in order, and returns how many
/// distinct rows remain at the head of the slices.
fn sort_and_sum(r: &mut [usize], v: &mut [f64]) -> usize {
    if !r.windows(2).all(|w| w[0] <= w[1]) {
        let mut p: Vec<(usize, f64)> = r.iter().copied().zip(v.iter().copied()).collect();
        p.sort_by_key(|e| e.0);
        for (k, (ri, vi)) in p.into_iter().enumerate() {
            r[k] = ri;
            v[k] = vi;
        }
    }
    let mut n = 0;
    for k in 0..r.len() {
        if n > 0 && r[n - 1] == r[k] {
            v[n - 1] += v[k];
        } else {
            r[n] = r[k];
            v[n] = v[k];
            n += 1;
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast path takes a value only when `str::parse` gives the same bits, and leaves the
    /// rest (which `str::parse` accepts or refuses in its own words) to the reference parser.
    #[test]
    fn fast_values_equal_std_parse_bit_for_bit() {
        let tricky = [
            "0", "-0", "0.0", "-0.0", "1", "+1", "-1", "1.", ".5", "-.5", "1e5", "1E5", "1e+5", "1e-5", "1.5e+05", "-1.5E-05",
            "2.2250738585072011e-308", "2.2250738585072014e-308", "4.9406564584124654e-324", "2.4703282292062327e-324",
            "2.4703282292062328e-324", "1e-400", "1.7976931348623157e308", "1.7976931348623158e308", "9007199254740993",
            "9007199254740992.5", "1e23", "8.98846567431158e307", "0.1", "0.30000000000000004", "123456789012345678901234567890",
            "3.14159265358979323846264338327950288", "7.2057594037927933e16", "1.00000000000000011102230246251565404236316680908203125",
            "1.00000000000000011102230246251565404236316680908203124", "1.2345678901234567e-05", "6.0221408570000000e+23",
            "-0.00000000000000000000000000000000000000000000000001", "5e-324", "1e308", "00012.5000", "1.e5",
            // refused by one or both, or not finite: the reference parser decides
            "1e400", "inf", "-inf", "nan", "NaN", "infinity", "", ".", "e5", "1e", "1e+", "--1", "+-1", "1.0d5", "1.0D+05",
            "0x1p3", "1_000", "1.2.3", "1e5.5", "++1", "-", "+", "1-", "1e-5-",
        ];
        for t in tricky {
            let std = t.parse::<f64>().ok().filter(|v| v.is_finite());
            match fast_value(t.as_bytes()) {
                Some(v) => assert_eq!(Some(v.to_bits()), std.map(f64::to_bits), "{t:?}"),
                None => assert!(std.is_none() || !t.bytes().all(|b| b.is_ascii_digit() || b"+-.eE".contains(&b)), "fast path refused {t:?}"),
            }
        }
        // random values written with 17 and fewer significant digits, and random bit patterns
        let mut s: u64 = 0x9E3779B97F4A7C15;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        for k in 0..200_000 {
            let x = f64::from_bits(next());
            if !x.is_finite() {
                continue;
            }
            let text = match k % 4 {
                0 => format!("{x:e}"),
                1 => format!("{x:.17e}"),
                2 => format!("{:.6e}", x),
                _ => format!("{x}"),
            };
            assert_eq!(fast_value(text.as_bytes()).map(f64::to_bits), Some(text.parse::<f64>().unwrap().to_bits()), "{text}");
        }
    }

    #[test]
    fn fast_and_reference_entries_agree() {
        for l in ["1 2 3.5", "  1\t2   3.5  \r", "10 1 -1e-3", "1 1 1", "3 3 2.5e+00"] {
            assert_eq!(fast_entry(l.as_bytes(), 10, 10).map(|e| (e.0, e.1, e.2.to_bits())), slow_entry(l, 10, 10).ok().map(|e| (e.0, e.1, e.2.to_bits())), "{l:?}");
        }
        // refused by the fast path, decided by the reference
        for l in ["+1 2 3", "0 1 1", "11 1 1", "1 2", "1 2 3 4", "1,2,3", "1 2 inf", "1 2 3x", "01 2 3", "1\u{a0}2 3"] {
            if let Some(e) = fast_entry(l.as_bytes(), 10, 10) {
                assert_eq!(Ok(e), slow_entry(l, 10, 10), "{l:?}");
            }
        }
    }
}
