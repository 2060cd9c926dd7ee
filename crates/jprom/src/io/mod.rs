//! File formats: versioned JSON for models, bases and solutions, Matrix Market for FE
//! matrices, and the node/DoF map that places contacts on an imported model.
//!
//! Reading is checked as a whole: a file is read only if its size fits the memory budget, a
//! directory or unreadable path is [`JpError::Io`], the envelope's `format` and `kind` are
//! checked before the data is parsed (a sweep file given where a model is expected says so),
//! unknown keys are refused, and [`documents`] checks every size against every array.
//! Writing is checked to the end: the last buffered bytes are flushed and the file synced,
//! and any error is returned ([`write_file`]).

pub mod calculix;
pub mod documents;
pub mod dof_map;
pub mod locate;
pub mod matrix_market;

use crate::error::{JpError, Result};
use locate::{json_line, key_path, key_text, Step};
use serde::{de::DeserializeOwned, de::IgnoredAny, Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

pub use documents::{load_document, parse_document, Document};

/// Version of the JSON envelope `{ "format": "jprom", "kind": ..., "version": ..., "data": ... }`.
/// Files with a newer version are refused with a clear error.
pub const FORMAT_VERSION: u32 = 1;

#[derive(Serialize, Deserialize)]
struct Envelope<T> {
    format: String,
    kind: String,
    version: u32,
    data: T,
}

/// What the envelope says, read before the data (every other key ignored here).
#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    kind: Option<String>,
    version: Option<u32>,
    #[allow(dead_code)]
    data: Option<IgnoredAny>,
}

/// How many bytes of memory reading a text file of `len` bytes may take: the text and the
/// values parsed from it (a JSON or Matrix Market number takes at least 2 bytes of text and
/// at most 24 bytes parsed, e.g. as a triplet entry).
const READ_EXPANSION: u128 = 13;

/// Reads a whole text file. A directory, a device, a missing or unreadable file is
/// [`JpError::Io`]; a
/// file whose text and parsed values would not fit the memory budget is
/// [`JpError::TooLarge`], before it is read.
pub fn read_text(path: &Path) -> Result<String> {
    let meta = std::fs::metadata(path).map_err(|e| io_err(path, e))?;
    if meta.is_dir() {
        return Err(JpError::Io { path: path.display().to_string(), reason: "is a directory, not a file".into() });
    }
    if !meta.is_file() {
        // a device or a pipe has no size to check, and /dev/zero or /dev/full never ends
        return Err(JpError::Io { path: path.display().to_string(), reason: "is not a regular file (a device or a pipe)".into() });
    }
    crate::memory::check(&format!("reading {} ({} bytes)", path.display(), meta.len()), (meta.len() as u128).saturating_mul(READ_EXPANSION))?;
    let bytes = std::fs::read(path).map_err(|e| io_err(path, e))?;
    String::from_utf8(bytes).map_err(|e| JpError::Io { path: path.display().to_string(), reason: format!("not UTF-8 text: {e}") })
}

/// Creates (or truncates) `path`, lets `write` fill it through a buffer, then flushes the
/// buffer and syncs the file: every error, including the last flush (a full disk, a quota,
/// `/dev/full`), is returned, so a file reported written was written.
pub fn write_file(path: &Path, write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let err = |e: std::io::Error| io_err(path, e);
    let file = std::fs::File::create(path).map_err(err)?;
    let mut buf = std::io::BufWriter::new(file);
    write(&mut buf).map_err(err)?;
    let file = buf.into_inner().map_err(|e| err(e.into_error()))?;
    sync(&file).map_err(err)
}

/// `sync_all`, except on files that cannot be synced (devices, pipes: `EINVAL`, `ENOTSUP`),
/// where the data has reached the device already.
fn sync(file: &std::fs::File) -> std::io::Result<()> {
    match file.sync_all() {
        Err(e) if matches!(e.raw_os_error(), Some(libc::EINVAL) | Some(libc::ENOTSUP) | Some(libc::EROFS)) => Ok(()),
        other => other,
    }
}

/// Writes `value` as a versioned JSON document of the given kind ("model", "basis", "solution", ...).
///
/// # Errors
/// [`JpError::Io`] if the file cannot be created or any byte of it cannot be written.
pub fn save_json<T: Serialize>(kind: &str, value: &T, path: &Path) -> Result<()> {
    let env = Envelope { format: "jprom".to_string(), kind: kind.to_string(), version: FORMAT_VERSION, data: value };
    write_file(path, |w| serde_json::to_writer(&mut *w, &env).map_err(std::io::Error::from))
}

/// Reads a versioned JSON document, checking format, kind and version first, then parsing
/// the data with unknown keys refused. (Consistency of the data: [`load_document`].)
///
/// # Errors
/// [`JpError::Io`] for an unreadable file, a directory, or a file of another format or kind
/// (naming what it is); [`JpError::Parse`] with the line for malformed JSON, a wrong value
/// or an unknown key; [`JpError::TooLarge`] for a file beyond the memory budget.
pub fn load_json<T: DeserializeOwned>(kind: &str, path: &Path) -> Result<T> {
    let text = read_text(path)?;
    parse_json(kind, &text, &path.display().to_string())
}

/// [`load_json`] on a text already read; `name` is used in messages.
pub fn parse_json<T: DeserializeOwned>(kind: &str, text: &str, name: &str) -> Result<T> {
    check_header(kind, text, name)?;
    let mut unknown: Vec<Vec<Step>> = Vec::new();
    let mut de = serde_json::Deserializer::from_str(text);
    let parsed: std::result::Result<Envelope<T>, _> = {
        let mut on_unknown = |p: serde_ignored::Path| unknown.push(steps_of(&p));
        let ignored = serde_ignored::Deserializer::new(&mut de, &mut on_unknown);
        serde_path_to_error::deserialize(ignored)
    };
    let env = parsed.map_err(|e| {
        let key = e.path().to_string();
        let inner = e.into_inner();
        JpError::Parse { path: name.to_string(), line: inner.line(), reason: format!("key '{key}': {inner}") }
    })?;
    de.end().map_err(|e| JpError::Parse { path: name.to_string(), line: e.line(), reason: e.to_string() })?;
    if let Some(key) = unknown.first() {
        return Err(JpError::Parse {
            path: name.to_string(),
            line: json_line(text, key).unwrap_or(0),
            reason: format!("unknown key '{}' in a jprom {kind} file", key_text(key)),
        });
    }
    Ok(env.data)
}

/// The envelope's `format`, `kind` and `version`, checked before the data is parsed.
/// The envelope's `kind` of a jprom document's text (`None` if the text is not a jprom
/// envelope with a kind); for loaders that accept several kinds.
pub fn document_kind(text: &str) -> Option<String> {
    let h: Header = serde_json::from_str(text).ok()?;
    match h.format.as_deref() {
        Some("jprom") => h.kind,
        _ => None,
    }
}

fn check_header(kind: &str, text: &str, name: &str) -> Result<()> {
    let h: Header = serde_json::from_str(text).map_err(|e| JpError::Parse { path: name.to_string(), line: e.line(), reason: e.to_string() })?;
    let io = |reason: String| Err(JpError::Io { path: name.to_string(), reason });
    match h.format.as_deref() {
        Some("jprom") => {}
        Some(dof_map::DOF_MAP_FORMAT) => return io(format!("this is a jprom DoF map file, expected a jprom {kind} file")),
        Some(other) => return io(format!("not a jprom file (format '{other}'), expected a jprom {kind} file")),
        None => return io(format!("not a jprom file (no \"format\": \"jprom\" envelope), expected a jprom {kind} file")),
    }
    match h.kind.as_deref() {
        Some(k) if k == kind => {}
        Some(other) => return io(format!("this is a jprom {other} file, expected a {kind}")),
        None => return io(format!("the envelope has no \"kind\", expected a jprom {kind} file")),
    }
    match h.version {
        Some(v) if v <= FORMAT_VERSION => Ok(()),
        Some(v) => io(format!("format version {v} is newer than this library's {FORMAT_VERSION}")),
        None => io("the envelope has no \"version\"".into()),
    }
}

/// A serde_ignored path as key steps.
fn steps_of(p: &serde_ignored::Path) -> Vec<Step> {
    use serde_ignored::Path as P;
    let mut out = match p {
        P::Root => return Vec::new(),
        P::Seq { parent, .. } | P::Map { parent, .. } | P::Some { parent } | P::NewtypeStruct { parent } | P::NewtypeVariant { parent } => steps_of(parent),
    };
    match p {
        P::Seq { index, .. } => out.push(Step::Index(*index)),
        P::Map { key, .. } => out.push(Step::Key(key.clone())),
        _ => {}
    }
    out
}

/// A key path written as in messages, as steps (re-exported for the document checks).
pub(crate) fn steps(key: &str) -> Vec<Step> {
    key_path(key)
}

pub(crate) fn io_err(path: &Path, e: std::io::Error) -> JpError {
    JpError::Io { path: path.display().to_string(), reason: e.to_string() }
}
