//! CalculiX reader: the stiffness and mass matrices that `ccx` stores with
//! `*FREQUENCY, SOLVER=MATRIXSTORAGE` (`jobname.sti`, `jobname.mas`, `jobname.dof`), and the
//! node coordinates and node sets of the input deck (`jobname.inp`, with its `*INCLUDE`d
//! files such as a `.msh`).
//!
//! # The files `ccx` writes (CalculiX 2.20, `matrixstorage.c`)
//!
//! A step `*STEP` / `*FREQUENCY, SOLVER=MATRIXSTORAGE` / `*END STEP` (no data line: with this
//! solver `*FREQUENCY` reads none) makes `ccx` assemble the matrices of the active degrees of
//! freedom, write three files and stop:
//!
//! * `jobname.sti` (stiffness) and `jobname.mas` (mass): one entry a line, written as
//!   `"%d %d %20.13e\n"`: **row, column, value**, indices **1-based**. Only the **upper
//!   triangle** is stored (row <= column; the lower triangle is its mirror), every diagonal
//!   entry is written (even a zero one), off-diagonal entries are those of the sparsity
//!   pattern (some are exactly or numerically zero). Entries are sorted by column, then by row
//!   ("column per column"). Both files have the same pattern and the same number of lines,
//!   `neq + nzs` (equations plus off-diagonal entries).
//! * `jobname.dof`: one line per row (and column) of the matrices, in order, written as
//!   `"%d.%d\n"`: `node.direction`, the node number of the deck and the global direction
//!   (1, 2, 3 = x, y, z translations). So line `r` names row `r`.
//!
//! Degrees of freedom fixed by `*BOUNDARY` (single point constraints) and the dependent
//! degrees of freedom of `*EQUATION`s / MPCs are **not active**: they have no row, do not
//! appear in the `.dof`, and the matrices are those of the remaining (free) DoFs. Nodes that no
//! element uses have no DoF either. (With `GLOBAL=NO` the directions are local ones; a cyclic
//! symmetric model stores a matrix twice the size of its `.dof`, which this reader refuses;
//! shell and beam elements, which `ccx` expands into 3-D nodes, name their original node on
//! several rows, which this reader refuses as a duplicate DoF.)
//!
//! # What is read from the deck
//!
//! Only `*NODE` and `*NSET` (and `*INCLUDE`), following CalculiX's own rules (`readinput.c`,
//! `nodes.f`, `noelsets.f`): blanks and tabs are removed from every line, lines starting with
//! `**` and empty lines are skipped, keywords, parameters and set names are case-insensitive
//! (taken in upper case), and the lines after `*HEADING` are left alone.
//!
//! * `*NODE[, NSET=name]`, data lines `id, x, y, z` (a missing coordinate is 0, as in `ccx`;
//!   a coordinate of more than 20 characters is refused, since `ccx` reads only 20, Fortran
//!   `f20.0`). A node defined twice takes its last coordinates (as in `ccx`).
//! * `*NSET, NSET=name[, GENERATE]`: data lines of node ids and names of node sets defined
//!   before (whose nodes are added), or with `GENERATE` lines `start, end[, step]` (step 1 by
//!   default). A set defined again is extended. As in `ccx`, every `*NODE` card is taken
//!   before any `*NSET` card, so a set may list nodes defined further down the deck; the
//!   `*NSET` cards are taken in deck order, so a set can only use sets defined above it.
//!   A `GENERATE` range keeps the node ids in it that `*NODE` defines; an explicit id that
//!   `*NODE` does not define is refused (stricter than `ccx`, which lets it pass until used).
//!   Sets are returned sorted by node id, without repetitions.
//! * `*INCLUDE, INPUT=file` (or `INPUT="file"`): the file is read in place. A relative path is
//!   taken from the directory of the file that includes it (`ccx` takes it from its working
//!   directory: the same when `ccx` ran in the deck's directory). At most 9 levels, as `ccx`.
//!
//! Every other card and its data lines are skipped.
//!
//! # Errors
//!
//! A missing, unreadable or non-regular file is [`JpError::Io`] naming it; a malformed line is
//! [`JpError::Parse`] with the file, the 1-based line number and the reason. Nothing panics
//! on bad input, and nothing is allocated from a size that the files do not back: the
//! matrices' size comes from the `.dof`, whose lines are there, and every entry's indices are
//! checked against it.

use crate::error::{JpError, Result};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

/// Sparse matrix in compressed sparse columns, full (both triangles) storage.
pub type SparseMat = SparseColMat<usize, f64>;

/// One row (and column) of the matrices: `(node id, direction)`, direction 1..=6
/// (1, 2, 3: translations x, y, z; 4, 5, 6: rotations).
pub type Dof = (i64, u8);

/// How deep `*INCLUDE`s may nest (as in `ccx`).
pub const MAX_INCLUDE_DEPTH: usize = 9;

/// Longest set name `ccx` accepts.
pub const MAX_SET_NAME: usize = 80;

/// Widest numeric field `ccx` reads on a `*NODE` line: node ids `i10`, coordinates `f20.0`.
const MAX_ID_CHARS: usize = 10;
const MAX_COORD_CHARS: usize = 20;

/// An FE model from CalculiX: the matrices of the active DoFs, what each row is, and the
/// mesh data that places contacts, loads and outputs on it.
#[derive(Clone, Debug)]
pub struct CalculixModel {
    /// Stiffness `K` (`.sti`), `n x n`, full storage, exactly symmetric.
    pub stiffness: SparseMat,
    /// Mass `M` (`.mas`), `n x n`, full storage, exactly symmetric.
    pub mass: SparseMat,
    /// Row `r` of `K` and `M` is DoF `dofs[r]` (`.dof`).
    pub dofs: Vec<Dof>,
    /// Node coordinates from `*NODE` (every node of the deck, used or not).
    pub coords: BTreeMap<i64, [f64; 3]>,
    /// Node sets from `*NSET` and `*NODE, NSET=`, names in upper case, ids sorted.
    pub node_sets: BTreeMap<String, Vec<i64>>,
    /// Row of each DoF (the inverse of `dofs`).
    rows: BTreeMap<Dof, usize>,
    /// The deck, for messages.
    pub(crate) inp: PathBuf,
}

impl CalculixModel {
    /// Number of DoFs (rows of `K` and `M`).
    pub fn n(&self) -> usize {
        self.dofs.len()
    }

    /// The row of `(node, direction)`, or `None` if that DoF is not active (fixed by
    /// `*BOUNDARY`, dependent in an MPC, or on a node no element uses).
    pub fn row_of(&self, node: i64, direction: u8) -> Option<usize> {
        self.rows.get(&(node, direction)).copied()
    }

    /// The nodes of a set (name case-insensitive, as in CalculiX).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the deck and the sets it defines if there is no such set.
    pub fn node_set(&self, name: &str) -> Result<&[i64]> {
        node_set_of(&self.node_sets, name, &self.inp)
    }

    /// The rows of the active DoFs of the nodes of a set, node by node and direction by
    /// direction, with the nodes of the set that have none (e.g. clamped ones) apart.
    ///
    /// # Errors
    /// As [`CalculixModel::node_set`].
    pub fn set_rows(&self, name: &str) -> Result<(Vec<usize>, Vec<i64>)> {
        let mut rows = Vec::new();
        let mut without = Vec::new();
        for &node in self.node_set(name)? {
            let before = rows.len();
            rows.extend(self.rows.range((node, 0)..=(node, u8::MAX)).map(|(_, &r)| r));
            if rows.len() == before {
                without.push(node);
            }
        }
        Ok((rows, without))
    }
}

/// Node coordinates and node sets of a CalculiX deck ([`read_mesh`]).
#[derive(Clone, Debug, Default)]
pub struct CalculixMesh {
    /// Coordinates of every node defined by `*NODE`.
    pub coords: BTreeMap<i64, [f64; 3]>,
    /// Node sets, names in upper case, ids sorted without repetition.
    pub node_sets: BTreeMap<String, Vec<i64>>,
    /// The files read: the deck first, then its includes in the order met.
    pub files: Vec<PathBuf>,
}

impl CalculixMesh {
    /// The nodes of a set (name case-insensitive).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the deck and its sets if there is no such set.
    pub fn node_set(&self, name: &str) -> Result<&[i64]> {
        let deck = self.files.first().cloned().unwrap_or_default();
        node_set_of(&self.node_sets, name, &deck)
    }
}

/// The node set `name` of `sets` (case-insensitive), or an error naming the sets there are and
/// where they come from (`deck`).
pub(crate) fn node_set_of<'a>(sets: &'a BTreeMap<String, Vec<i64>>, name: &str, deck: &Path) -> Result<&'a [i64]> {
    let source = if deck.as_os_str().is_empty() { "the model".to_string() } else { deck.display().to_string() };
    node_set_in(sets, name, &source)
}

/// The node set `name` of `sets` (names in upper case, looked up case-insensitively as CalculiX
/// does), or an error naming the sets there are and where they come from (`source`: a deck's
/// path, "the model", ...). The one node-set lookup of jprom: FE models, meshes, the C API and
/// the study checks use it.
///
/// # Errors
/// [`JpError::InvalidValue`] if there is no such set.
pub fn node_set_in<'a>(sets: &'a BTreeMap<String, Vec<i64>>, name: &str, source: &str) -> Result<&'a [i64]> {
    match sets.get(&name.to_ascii_uppercase()) {
        Some(s) => Ok(s),
        None => {
            let known: Vec<&str> = sets.keys().map(String::as_str).collect();
            Err(JpError::invalid(
                format!("node set '{name}'"),
                format!("{source} defines no such set (its node sets: {})", if known.is_empty() { "none".to_string() } else { known.join(", ") }),
            ))
        }
    }
}

/// The four files of a CalculiX job.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CalculixFiles {
    /// The deck (`*NODE`, `*NSET`, `*INCLUDE`).
    pub inp: PathBuf,
    /// Stiffness matrix.
    pub sti: PathBuf,
    /// Mass matrix.
    pub mas: PathBuf,
    /// Row -> node.direction.
    pub dof: PathBuf,
}

impl CalculixFiles {
    /// The files of job `jobname` from the deck's path `jobname.inp` (or from `jobname`):
    /// `jobname.sti`, `jobname.mas`, `jobname.dof` beside it.
    pub fn of_job(inp: &Path) -> Self {
        let job = if inp.extension().is_some_and(|e| e.eq_ignore_ascii_case("inp")) { inp.with_extension("") } else { inp.to_path_buf() };
        let with = |ext: &str| {
            let mut s = job.clone().into_os_string();
            s.push(".");
            s.push(ext);
            PathBuf::from(s)
        };
        CalculixFiles { inp: with("inp"), sti: with("sti"), mas: with("mas"), dof: with("dof") }
    }
}

/// Reads a CalculiX job from its deck's path `jobname.inp`: [`read_model_files`] on
/// [`CalculixFiles::of_job`].
///
/// # Errors
/// As [`read_model_files`].
pub fn read_model(inp: &Path) -> Result<CalculixModel> {
    read_model_files(&CalculixFiles::of_job(inp))
}

/// Reads a CalculiX model: the `.dof` first (it gives the size), then `K` from the `.sti` and
/// `M` from the `.mas` ([`read_matrix`]), then the deck ([`read_mesh`]); every node of the
/// `.dof` must be defined in the deck.
///
/// # Errors
/// [`JpError::Io`] for a missing or unreadable file (naming it); [`JpError::Parse`] with the
/// file and line for anything malformed, or for a `.dof` node the deck does not define.
pub fn read_model_files(files: &CalculixFiles) -> Result<CalculixModel> {
    let dofs = read_dofs(&files.dof)?;
    let n = dofs.len();
    let stiffness = read_matrix(&files.sti, n)?;
    let mass = read_matrix(&files.mas, n)?;
    let mesh = read_mesh(&files.inp)?;
    let mut rows = BTreeMap::new();
    for (r, &dof) in dofs.iter().enumerate() {
        if !mesh.coords.contains_key(&dof.0) {
            return Err(perr(
                &files.dof,
                r + 1,
                format!("node {} (row {}) is not defined by any *NODE card of {} (is it the deck of these matrices?)", dof.0, r + 1, files.inp.display()),
            ));
        }
        rows.insert(dof, r);
    }
    Ok(CalculixModel { stiffness, mass, dofs, coords: mesh.coords, node_sets: mesh.node_sets, rows, inp: files.inp.clone() })
}

// ------------------------------------------------------------------------------------------
// line reading
// ------------------------------------------------------------------------------------------

fn perr(path: &Path, line: usize, reason: impl Into<String>) -> JpError {
    JpError::Parse { path: path.display().to_string(), line, reason: reason.into() }
}

fn ioerr(path: &Path, reason: impl Into<String>) -> JpError {
    JpError::Io { path: path.display().to_string(), reason: reason.into() }
}

/// A file read line by line into one reused buffer (no allocation per line).
struct Lines {
    reader: BufReader<std::fs::File>,
    buf: Vec<u8>,
    /// 1-based number of the line in `buf`.
    line: usize,
    /// The last line read had no end of line (the file ends inside it).
    unterminated: bool,
    len: u64,
    path: PathBuf,
}

impl Lines {
    /// Opens a regular file (a directory, a device or a pipe is [`JpError::Io`]).
    fn open(path: &Path, what: &str) -> Result<Self> {
        let meta = std::fs::metadata(path).map_err(|e| ioerr(path, format!("cannot read the {what}: {e}")))?;
        if meta.is_dir() {
            return Err(ioerr(path, format!("is a directory, not the {what}")));
        }
        if !meta.is_file() {
            return Err(ioerr(path, format!("is not a regular file (a device or a pipe), expected the {what}")));
        }
        let file = std::fs::File::open(path).map_err(|e| ioerr(path, format!("cannot open the {what}: {e}")))?;
        Ok(Lines {
            reader: BufReader::with_capacity(1 << 16, file),
            buf: Vec::with_capacity(256),
            line: 0,
            unterminated: false,
            len: meta.len(),
            path: path.to_path_buf(),
        })
    }

    /// The next line's number (1-based) and text without its end of line (`\n` or `\r\n`),
    /// or `None` at the end.
    fn next_line(&mut self) -> Result<Option<(usize, &[u8])>> {
        self.buf.clear();
        let got = self.reader.read_until(b'\n', &mut self.buf).map_err(|e| ioerr(&self.path, format!("read error after line {}: {e}", self.line)))?;
        if got == 0 {
            return Ok(None);
        }
        self.line += 1;
        let mut end = self.buf.len();
        if self.buf[end - 1] == b'\n' {
            end -= 1;
        } else {
            self.unterminated = true;
        }
        if end > 0 && self.buf[end - 1] == b'\r' {
            end -= 1;
        }
        Ok(Some((self.line, &self.buf[..end])))
    }
}

/// Text of a byte field for messages (lossy, shortened).
fn show(b: &[u8]) -> String {
    let s = String::from_utf8_lossy(b);
    if s.chars().count() > 40 {
        format!("{}...", s.chars().take(40).collect::<String>())
    } else {
        s.into_owned()
    }
}

/// A non-negative decimal integer of ASCII digits only (no sign, no blanks).
fn parse_digits(b: &[u8]) -> Option<u64> {
    if b.is_empty() || b.len() > 19 {
        return None;
    }
    let mut v: u64 = 0;
    for &c in b {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v * 10 + (c - b'0') as u64;
    }
    Some(v)
}

// ------------------------------------------------------------------------------------------
// .dof
// ------------------------------------------------------------------------------------------

/// Reads a `.dof` file: line `r` is `node.direction` for row `r` of the matrices (both
/// integers, node >= 1, direction 1..=6), no DoF twice.
///
/// # Errors
/// [`JpError::Io`] if the file is missing or unreadable; [`JpError::Parse`] with the line for
/// a malformed line, a direction outside 1..=6, a DoF given twice (naming both lines), an
/// empty file, or a last line without its end of line (a truncated file).
pub fn read_dofs(path: &Path) -> Result<Vec<Dof>> {
    let mut lines = Lines::open(path, "CalculiX .dof file (node.direction per matrix row)")?;
    let mut dofs: Vec<Dof> = Vec::with_capacity((lines.len / 4).min(1 << 24) as usize);
    while let Some((ln, l)) = lines.next_line()? {
        let t = l.trim_ascii();
        let bad = |why: &str| perr(path, ln, format!("'{}' is not node.direction ({why}; ccx writes e.g. '12.3' for node 12, direction z)", show(t)));
        let dot = t.iter().position(|&c| c == b'.').ok_or_else(|| bad("no '.'"))?;
        let node = parse_digits(&t[..dot]).ok_or_else(|| bad("the node is not a whole number"))?;
        let dir = parse_digits(&t[dot + 1..]).ok_or_else(|| bad("the direction is not a whole number"))?;
        if node == 0 || node > i64::MAX as u64 {
            return Err(perr(path, ln, format!("node {node} out of range (node numbers are 1 or more)")));
        }
        if !(1..=6).contains(&dir) {
            let hint = if dir == 0 { " (0 is the temperature of a heat transfer model)" } else { "" };
            return Err(perr(path, ln, format!("direction {dir} of node {node} is not a structural DoF 1..6{hint}")));
        }
        dofs.push((node as i64, dir as u8));
    }
    if lines.unterminated {
        return Err(perr(path, lines.line, "the file ends inside this line (no end of line): truncated?"));
    }
    if dofs.is_empty() {
        return Err(perr(path, 1, "no DoF: the file is empty (every DoF fixed, or not a .dof written by ccx)"));
    }
    // no DoF twice: sort row numbers by DoF
    let mut order: Vec<usize> = (0..dofs.len()).collect();
    order.sort_unstable_by_key(|&r| (dofs[r], r));
    for w in order.windows(2) {
        if dofs[w[0]] == dofs[w[1]] {
            let (node, dir) = dofs[w[0]];
            return Err(perr(
                path,
                w[1] + 1,
                format!("node {node} direction {dir} is given twice, on lines {} and {} (shell or beam elements, which ccx expands into 3-D nodes, are not supported)", w[0] + 1, w[1] + 1),
            ));
        }
    }
    Ok(dofs)
}

// ------------------------------------------------------------------------------------------
// .sti / .mas
// ------------------------------------------------------------------------------------------

/// One line `row col value` of a `.sti`/`.mas`, 1-based indices checked against `n`.
fn parse_entry(path: &Path, ln: usize, l: &[u8], n: usize) -> Result<(usize, usize, f64)> {
    let mut f = l.split(|c| c.is_ascii_whitespace()).filter(|s| !s.is_empty());
    let (a, b, c) = match (f.next(), f.next(), f.next(), f.next()) {
        (Some(a), Some(b), Some(c), None) => (a, b, c),
        (None, ..) => return Err(perr(path, ln, "empty line (every line of a ccx matrix file is 'row column value')")),
        _ => {
            let k = l.split(|c| c.is_ascii_whitespace()).filter(|s| !s.is_empty()).count();
            return Err(perr(path, ln, format!("expected 'row column value', got {k} fields: '{}'", show(l.trim_ascii()))));
        }
    };
    let index = |s: &[u8], what: &str| -> Result<usize> {
        let i = parse_digits(s).ok_or_else(|| perr(path, ln, format!("{what} '{}' is not a whole number", show(s))))?;
        if i == 0 || i > n as u64 {
            let hint = if i as u128 <= 2 * n as u128 && i > 0 {
                "; a cyclic symmetric model stores matrices twice the size of its .dof, which is not supported"
            } else {
                ""
            };
            return Err(perr(path, ln, format!("{what} {i} out of range 1..={n} (the size given by the .dof){hint}")));
        }
        Ok(i as usize - 1)
    };
    let i = index(a, "row")?;
    let j = index(b, "column")?;
    let v: f64 = std::str::from_utf8(c).ok().and_then(|s| s.parse().ok()).ok_or_else(|| perr(path, ln, format!("value '{}' is not a number", show(c))))?;
    if !v.is_finite() {
        return Err(perr(path, ln, format!("value '{}' is not finite", show(c))));
    }
    Ok((i, j, v))
}

/// Reads a `.sti` or `.mas` file of a matrix of `n` rows (the `.dof`'s line count) into a
/// symmetric CSC matrix in full storage.
///
/// The file stores one triangle (`ccx`: the upper one, `row <= column`): each off-diagonal
/// entry is stored at its place and mirrored, each diagonal entry once. An entry of the lower
/// triangle is mirrored as well, but a pair of indices given twice (twice the same entry, or
/// both `(i, j)` and `(j, i)`) is refused, as is a missing diagonal entry (`ccx` writes them
/// all: one missing means a cut file).
///
/// # Errors
/// [`JpError::Io`] if the file is missing or unreadable; [`JpError::Parse`] with the line for
/// a line that is not `row column value`, an index outside `1..=n`, a value that is not a
/// finite number, an index pair given twice (naming both lines), a missing diagonal entry or
/// a last line without end of line (a truncated file).
pub fn read_matrix(path: &Path, n: usize) -> Result<SparseMat> {
    let mut lines = Lines::open(path, "CalculiX matrix file (.sti or .mas)")?;
    // ccx writes 24 bytes or more a line; the reservation is backed by the file's size
    let max_entries = (n as u128) * (n as u128 + 1) / 2;
    let guess = ((lines.len / 24) as u128).min(max_entries).min(1 << 28) as usize;
    let mut entries: Vec<(usize, usize, f64)> = Vec::new();
    entries.try_reserve_exact(guess).map_err(|_| ioerr(path, format!("out of memory for {guess} entries")))?;
    while let Some((ln, l)) = lines.next_line()? {
        let e = parse_entry(path, ln, l, n)?;
        if entries.len() as u128 == max_entries {
            return Err(perr(path, ln, format!("more entries than one triangle of a {n} x {n} matrix holds ({max_entries}): some index pair is given twice")));
        }
        entries.push(e);
    }
    let last = lines.line;
    if lines.unterminated {
        return Err(perr(path, last, "the file ends inside this line (no end of line after the last entry): truncated?"));
    }
    drop(lines);
    if entries.len() < n {
        // fewer entries than diagonals: name the first missing one before allocating n columns
        let mut diag: Vec<usize> = entries.iter().filter(|e| e.0 == e.1).map(|e| e.0).collect();
        diag.sort_unstable();
        diag.dedup();
        let missing = diag.iter().enumerate().find(|&(k, &d)| k != d).map_or(diag.len(), |(k, _)| k);
        return Err(missing_diagonal(path, last, missing));
    }

    // full storage: a diagonal entry once, an off-diagonal one in both columns
    let mut col_ptr = vec![0usize; n + 1];
    for &(i, j, _) in &entries {
        col_ptr[j + 1] += 1;
        if i != j {
            col_ptr[i + 1] += 1;
        }
    }
    for c in 0..n {
        col_ptr[c + 1] += col_ptr[c];
    }
    let nnz = col_ptr[n];
    let mut row_idx = vec![0usize; nnz];
    let mut val = vec![0.0f64; nnz];
    let mut next = col_ptr[..n].to_vec();
    for &(i, j, v) in &entries {
        row_idx[next[j]] = i;
        val[next[j]] = v;
        next[j] += 1;
        if i != j {
            row_idx[next[i]] = j;
            val[next[i]] = v;
            next[i] += 1;
        }
    }
    drop(next);
    drop(entries);
    // rows in each column: already increasing for ccx's order (by column, then row; the
    // mirrored entries of column c arrive later, from columns > c, in increasing order)
    let mut pairs: Vec<(usize, f64)> = Vec::new();
    for c in 0..n {
        let (s, e) = (col_ptr[c], col_ptr[c + 1]);
        if row_idx[s..e].windows(2).all(|w| w[0] < w[1]) {
            continue;
        }
        pairs.clear();
        pairs.extend(row_idx[s..e].iter().copied().zip(val[s..e].iter().copied()));
        pairs.sort_by_key(|p| p.0);
        for (k, &(r, v)) in pairs.iter().enumerate() {
            row_idx[s + k] = r;
            val[s + k] = v;
        }
        if let Some(w) = row_idx[s..e].windows(2).find(|w| w[0] == w[1]) {
            return Err(duplicate(path, w[0], c, n));
        }
    }
    for c in 0..n {
        let (s, e) = (col_ptr[c], col_ptr[c + 1]);
        if row_idx[s..e].binary_search(&c).is_err() {
            return Err(missing_diagonal(path, last, c));
        }
    }
    let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    Ok(SparseColMat::new(symbolic, val))
}

/// The error for a missing diagonal entry `c` (0-based), at the end of a file of `last` lines.
fn missing_diagonal(path: &Path, last: usize, c: usize) -> JpError {
    perr(
        path,
        last + 1,
        format!(
            "the file ends without the diagonal entry ({}, {}): ccx writes every diagonal entry, so the file is incomplete (truncated?) or not ccx's",
            c + 1,
            c + 1
        ),
    )
}

/// The error for an index pair `{a, b}` (0-based) given twice: the file is read again to name
/// the lines (only on this error path).
fn duplicate(path: &Path, a: usize, b: usize, n: usize) -> JpError {
    let (lo, hi) = (a.min(b), a.max(b));
    let mut found = Vec::new();
    if let Ok(mut lines) = Lines::open(path, "matrix file") {
        while let Ok(Some((ln, l))) = lines.next_line() {
            if let Ok((i, j, _)) = parse_entry(path, ln, l, n) {
                if i.min(j) == lo && i.max(j) == hi {
                    found.push(ln);
                    if found.len() == 2 {
                        break;
                    }
                }
            }
        }
    }
    let (line, where_) = match found.as_slice() {
        [first, second, ..] => (*second, format!(" (lines {first} and {second})")),
        _ => (0, String::new()),
    };
    perr(
        path,
        line,
        format!("entry ({}, {}) is given twice{where_}: the file must store one triangle, each entry once (ccx: the upper triangle)", lo + 1, hi + 1),
    )
}

// ------------------------------------------------------------------------------------------
// .inp / .msh
// ------------------------------------------------------------------------------------------

/// Where a data item came from: (file index in `files`, line).
type Loc = (usize, usize);

/// An item of a `*NSET` data line.
enum Item {
    Node(i64, Loc),
    Range { start: i64, end: i64, step: i64, loc: Loc },
    Set(String, Loc),
}

/// A `*NSET` card: its set and its items in order.
struct NsetCard {
    name: String,
    items: Vec<Item>,
}

/// What the data lines being read belong to.
#[derive(Default)]
enum Block {
    #[default]
    Skip,
    Node {
        set: Option<String>,
    },
    Nset {
        card: usize,
        generate: bool,
    },
}

/// Everything gathered in one pass over the deck and its includes.
#[derive(Default)]
struct Deck {
    files: Vec<PathBuf>,
    coords: BTreeMap<i64, [f64; 3]>,
    /// `*NODE, NSET=` sets, taken before every `*NSET` card (as in ccx).
    node_card_sets: BTreeMap<String, Vec<i64>>,
    cards: Vec<NsetCard>,
    /// The card whose data lines come next; an `*INCLUDE` leaves it as it is (ccx reads the
    /// included lines in place, so a `*NODE` card's data may continue in an include).
    block: Block,
    /// Inside `*HEADING` text.
    heading: bool,
}

/// Reads the node coordinates and node sets of a CalculiX deck (see the module doc for the
/// rules), following `*INCLUDE`s.
///
/// # Errors
/// [`JpError::Io`] for a missing or unreadable deck or include (the include's error names
/// the card that asks for it); [`JpError::Parse`] with the file and line for a malformed
/// `*NODE` or `*NSET` line, a node id < 1, a set name too long, a set used before it is
/// defined, an explicit node id that no `*NODE` defines, a bad `GENERATE` range, includes
/// nested deeper than [`MAX_INCLUDE_DEPTH`], or a deck without any node.
pub fn read_mesh(path: &Path) -> Result<CalculixMesh> {
    let mut deck = Deck::default();
    read_deck_file(path, 0, &mut deck)?;
    if deck.coords.is_empty() {
        return Err(perr(path, 0, "the deck defines no node (no *NODE card with data lines)"));
    }
    let Deck { files, coords, node_card_sets, cards, .. } = deck;
    let mut sets: BTreeMap<String, BTreeSet<i64>> = node_card_sets.into_iter().map(|(k, v)| (k, v.into_iter().collect())).collect();
    for card in cards {
        let mut add: BTreeSet<i64> = BTreeSet::new();
        let card_empty = card.items.is_empty();
        for item in card.items {
            match item {
                Item::Node(id, (f, ln)) => {
                    if !coords.contains_key(&id) {
                        return Err(perr(&files[f], ln, format!("node {id} of set {} is not defined by any *NODE card", card.name)));
                    }
                    add.insert(id);
                }
                Item::Range { start, end, step, loc: (f, ln) } => {
                    let mut selected = 0usize;
                    for id in coords.range(start..=end).map(|(&id, _)| id).filter(|id| (id - start) % step == 0) {
                        add.insert(id);
                        selected += 1;
                    }
                    if selected == 0 {
                        return Err(perr(&files[f], ln, format!("GENERATE {start}, {end}, {step} of set {} selects no node defined by *NODE", card.name)));
                    }
                }
                Item::Set(name, (f, ln)) => {
                    if name == card.name {
                        continue; // a set naming itself adds nothing (as in ccx)
                    }
                    match sets.get(&name) {
                        Some(s) => add.extend(s.iter().copied()),
                        None => {
                            return Err(perr(&files[f], ln, format!("node set {name} (in set {}) is not defined above this line", card.name)));
                        }
                    }
                }
            }
        }
        if card_empty && !sets.contains_key(&card.name) {
            continue; // a new set without data lines is dropped (as in ccx)
        }
        sets.entry(card.name).or_default().extend(add);
    }
    let node_sets = sets.into_iter().map(|(k, v)| (k, v.into_iter().collect())).collect();
    Ok(CalculixMesh { coords, node_sets, files })
}

/// Removes blanks and tabs (as ccx does) into `out`.
fn strip_blanks(l: &[u8], out: &mut Vec<u8>) {
    out.clear();
    out.extend(l.iter().copied().filter(|&c| c != b' ' && c != b'\t'));
}

/// A set name from the deck: upper case, 1 to 80 characters, UTF-8.
fn set_name(raw: &[u8], path: &Path, ln: usize) -> Result<String> {
    if raw.is_empty() {
        return Err(perr(path, ln, "empty set name"));
    }
    if raw.len() > MAX_SET_NAME {
        return Err(perr(path, ln, format!("set name '{}' is longer than {MAX_SET_NAME} characters (ccx refuses it)", show(raw))));
    }
    let s = std::str::from_utf8(raw).map_err(|_| perr(path, ln, format!("set name '{}' is not text", show(raw))))?;
    Ok(s.to_ascii_uppercase())
}

/// A signed decimal integer (an id field of at most `MAX_ID_CHARS`).
fn parse_int(b: &[u8]) -> Option<i64> {
    if b.len() > MAX_ID_CHARS {
        return None;
    }
    let (neg, d) = match b.first() {
        Some(b'-') => (true, &b[1..]),
        Some(b'+') => (false, &b[1..]),
        _ => (false, b),
    };
    let v = parse_digits(d)? as i64;
    Some(if neg { -v } else { v })
}

/// A Fortran real (`f20.0` as ccx reads it): empty is 0; besides Rust's forms, a `d`/`D`
/// exponent (`1.5d3`) and an exponent without its letter (`1.5+3`, `2.-4`) are read.
fn parse_real(b: &[u8]) -> Option<f64> {
    if b.is_empty() {
        return Some(0.0);
    }
    let s = std::str::from_utf8(b).ok()?;
    if let Ok(v) = s.parse::<f64>() {
        return v.is_finite().then_some(v);
    }
    let mut t = s.replace(['d', 'D'], "e");
    if !t.contains(['e', 'E']) {
        // a sign after the mantissa starts the exponent
        if let Some(k) = t.char_indices().skip(1).find(|&(k, c)| (c == '+' || c == '-') && t.as_bytes()[k - 1] != b'e').map(|(k, _)| k) {
            t.insert(k, 'e');
        }
    }
    let v: f64 = t.parse().ok()?;
    // Rust also reads "inf" and "nan", which Fortran's f20.0 does not take from a deck
    v.is_finite().then_some(v)
}

fn read_deck_file(path: &Path, depth: usize, deck: &mut Deck) -> Result<()> {
    let what = if depth == 0 { "CalculiX input deck" } else { "CalculiX include file" };
    let mut lines = Lines::open(path, what)?;
    let fi = deck.files.len();
    deck.files.push(path.to_path_buf());
    let mut buf: Vec<u8> = Vec::with_capacity(256);
    while let Some((ln, raw)) = lines.next_line()? {
        if deck.heading && !(raw.first() == Some(&b'*') && raw.get(1) != Some(&b'*')) {
            continue; // *HEADING text, left alone
        }
        deck.heading = false;
        strip_blanks(raw, &mut buf);
        if buf.is_empty() || buf.starts_with(b"**") {
            continue;
        }
        if buf[0] == b'*' {
            let mut parts = buf.split(|&c| c == b',');
            let key = parts.next().unwrap_or_default().to_ascii_uppercase();
            if key != b"*INCLUDE" {
                deck.block = Block::Skip;
            }
            match key.as_slice() {
                b"*HEADING" => deck.heading = true,
                b"*INCLUDE" => {
                    let name = include_name(&buf, path, ln)?;
                    if depth + 1 > MAX_INCLUDE_DEPTH {
                        return Err(perr(path, ln, format!("includes nested deeper than {MAX_INCLUDE_DEPTH} levels (as ccx refuses)")));
                    }
                    let target = path.parent().map_or_else(|| PathBuf::from(&name), |d| d.join(&name));
                    if !target.is_file() {
                        let why = if target.exists() { "is not a regular file" } else { "does not exist" };
                        return Err(perr(path, ln, format!("*INCLUDE file {} {why}", target.display())));
                    }
                    read_deck_file(&target, depth + 1, deck)?;
                }
                b"*NODE" => {
                    let mut set = None;
                    for p in parts {
                        let up = p.to_ascii_uppercase();
                        if let Some(v) = up.strip_prefix(b"NSET=") {
                            let name = set_name(v, path, ln)?;
                            deck.node_card_sets.entry(name.clone()).or_default();
                            set = Some(name);
                        }
                        // ccx 2.20 ignores any other parameter of *NODE (with a warning)
                    }
                    deck.block = Block::Node { set };
                }
                b"*NSET" => {
                    let mut name = None;
                    let mut generate = false;
                    for p in parts {
                        let up = p.to_ascii_uppercase();
                        if let Some(v) = up.strip_prefix(b"NSET=") {
                            name = Some(set_name(v, path, ln)?);
                        } else if up == b"GENERATE" {
                            generate = true;
                        }
                    }
                    let name = name.ok_or_else(|| perr(path, ln, "*NSET without NSET=name"))?;
                    deck.cards.push(NsetCard { name, items: Vec::new() });
                    deck.block = Block::Nset { card: deck.cards.len() - 1, generate };
                }
                _ => {}
            }
            continue;
        }
        match &deck.block {
            Block::Skip => {}
            Block::Node { set } => {
                let mut f = buf.split(|&c| c == b',');
                let id_field = f.next().unwrap_or_default();
                let id = parse_int(id_field)
                    .ok_or_else(|| perr(path, ln, format!("*NODE: node number '{}' is not a whole number of at most {MAX_ID_CHARS} digits", show(id_field))))?;
                if id < 1 {
                    return Err(perr(path, ln, format!("*NODE: node number {id} (node numbers are 1 or more)")));
                }
                let mut x = [0.0f64; 3];
                for (k, xk) in x.iter_mut().enumerate() {
                    let Some(s) = f.next() else { break };
                    if s.len() > MAX_COORD_CHARS {
                        return Err(perr(
                            path,
                            ln,
                            format!(
                                "*NODE {id}: coordinate {} '{}' has {} characters; ccx reads only the first {MAX_COORD_CHARS} (Fortran f20.0)",
                                k + 1,
                                show(s),
                                s.len()
                            ),
                        ));
                    }
                    *xk = parse_real(s).ok_or_else(|| perr(path, ln, format!("*NODE {id}: coordinate {} '{}' is not a number", k + 1, show(s))))?;
                }
                deck.coords.insert(id, x);
                if let Some(name) = set {
                    deck.node_card_sets.entry(name.clone()).or_default().push(id);
                }
            }
            Block::Nset { card, generate } => {
                let (card, loc) = (*card, (fi, ln));
                if *generate {
                    let mut f = buf.split(|&c| c == b',');
                    let mut v = [0i64; 3];
                    for (k, what) in ["start", "end", "step"].iter().enumerate() {
                        let s = f.next().unwrap_or_default();
                        v[k] = if s.is_empty() {
                            if k == 2 {
                                1
                            } else {
                                return Err(perr(path, ln, format!("*NSET, GENERATE: the {what} is missing (start, end[, step])")));
                            }
                        } else {
                            parse_int(s).ok_or_else(|| perr(path, ln, format!("*NSET, GENERATE: {what} '{}' is not a whole number", show(s))))?
                        };
                    }
                    let [start, end, step] = v;
                    if start < 1 || end < start || step < 1 {
                        return Err(perr(
                            path,
                            ln,
                            format!("*NSET, GENERATE: {start}, {end}, {step} is not a range start, end, step with 1 <= start <= end and step >= 1"),
                        ));
                    }
                    deck.cards[card].items.push(Item::Range { start, end, step, loc });
                } else {
                    for s in buf.split(|&c| c == b',').filter(|s| !s.is_empty()) {
                        let item = match parse_int(s) {
                            Some(id) if id >= 1 => Item::Node(id, loc),
                            Some(id) => return Err(perr(path, ln, format!("*NSET: node number {id} (node numbers are 1 or more)"))),
                            None => Item::Set(set_name(s, path, ln)?, loc),
                        };
                        deck.cards[card].items.push(item);
                    }
                }
            }
        }
    }
    if lines.unterminated && matches!(deck.block, Block::Node { .. } | Block::Nset { .. }) {
        // a deck cut inside a *NODE or *NSET line would silently lose data
        return Err(perr(path, lines.line, "the file ends inside this line (no end of line): truncated?"));
    }
    Ok(())
}

/// The file name of an `*INCLUDE` card (blanks already removed): what follows the first
/// `=`, or the text between the quotes that follow it (as ccx's `includefilename.f`).
fn include_name(card: &[u8], path: &Path, ln: usize) -> Result<String> {
    let eq = card.iter().position(|&c| c == b'=').ok_or_else(|| perr(path, ln, "*INCLUDE without INPUT=file"))?;
    let rest = &card[eq + 1..];
    let name = if rest.first() == Some(&b'"') {
        let end = rest[1..].iter().position(|&c| c == b'"').ok_or_else(|| perr(path, ln, "*INCLUDE: the closing quote of the file name is missing"))?;
        &rest[1..1 + end]
    } else {
        rest
    };
    if name.is_empty() {
        return Err(perr(path, ln, "*INCLUDE: the file name is missing"));
    }
    std::str::from_utf8(name).map(str::to_string).map_err(|_| perr(path, ln, "*INCLUDE: the file name is not text"))
}
