//! The jprom documents (model, solution, sweep, basis: each implements [`Document`] where it
//! is defined) and the whole-file consistency check each gets on loading: every size against every array, so that no accessor can index out
//! of bounds in a loaded (possibly hand-edited) file, and the sizes against jprom's caps.
//! An inconsistency is a [`JpError::Parse`] naming the key and its line.

use super::locate::json_line;
use crate::error::{JpError, Result};
use serde::{de::DeserializeOwned, Serialize};
use std::path::Path;

/// A key (as in messages, relative to the envelope's `data`) and what is wrong there.
pub type Inconsistency = (String, String);

/// A kind of jprom JSON document.
pub trait Document: Serialize + DeserializeOwned {
    /// The envelope's `kind`.
    const KIND: &'static str;
    /// Whole-document consistency. `Ok(Err(..))` names a key of the file that is
    /// inconsistent; `Err` is a domain error (e.g. a model that does not validate).
    fn check(&self) -> Result<std::result::Result<(), Inconsistency>>;
}

/// Reads, parses and checks a document of kind `T::KIND` (see [`super::load_json`]).
///
/// # Errors
/// As [`super::load_json`]; [`JpError::Parse`] naming the key and line of an inconsistency;
/// the document's own validation errors (a model: [`Model::validate`]).
pub fn load_document<T: Document>(path: &Path) -> Result<T> {
    let text = super::read_text(path)?;
    parse_document(&text, &path.display().to_string())
}

/// [`load_document`] on a text already read; `name` is used in messages.
pub fn parse_document<T: Document>(text: &str, name: &str) -> Result<T> {
    let doc: T = super::parse_json(T::KIND, text, name)?;
    if let Err((key, reason)) = doc.check()? {
        let full = format!("data.{key}");
        return Err(JpError::Parse {
            path: name.to_string(),
            line: json_line(text, &super::steps(&full)).unwrap_or(0),
            reason: format!("key '{full}': {reason}"),
        });
    }
    Ok(doc)
}

/// The outcome of a consistency check.
pub type Check = std::result::Result<(), Inconsistency>;

/// An inconsistency at `key`.
pub fn bad(key: impl Into<String>, reason: impl Into<String>) -> Check {
    Err((key.into(), reason.into()))
}

/// Every entry of `v` (at `key`) finite.
pub fn finite(key: &str, v: &[f64]) -> Check {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => bad(format!("{key}[{i}]"), format!("is not finite ({})", v[i])),
    }
}

