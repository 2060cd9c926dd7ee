//! File formats: versioned JSON for models, bases and solutions, Matrix Market for FE
//! matrices, and the node/DoF map that places contacts on an imported model.

pub mod dof_map;
pub mod matrix_market;

use crate::error::{JpError, Result};
use serde::{de::DeserializeOwned, Deserialize, Serialize};
use std::path::Path;

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

/// Writes `value` as a versioned JSON document of the given kind ("model", "basis", "solution", ...).
pub fn save_json<T: Serialize>(kind: &str, value: &T, path: &Path) -> Result<()> {
    let env = Envelope { format: "jprom".to_string(), kind: kind.to_string(), version: FORMAT_VERSION, data: value };
    let file = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    serde_json::to_writer(std::io::BufWriter::new(file), &env).map_err(|e| JpError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })
}

/// Reads a versioned JSON document, checking format, kind and version.
pub fn load_json<T: DeserializeOwned>(kind: &str, path: &Path) -> Result<T> {
    let file = std::fs::File::open(path).map_err(|e| io_err(path, e))?;
    let env: Envelope<T> = serde_json::from_reader(std::io::BufReader::new(file)).map_err(|e| JpError::Parse {
        path: path.display().to_string(),
        line: e.line(),
        reason: e.to_string(),
    })?;
    let p = path.display().to_string();
    if env.format != "jprom" {
        return Err(JpError::Io { path: p, reason: format!("not a jprom file (format '{}')", env.format) });
    }
    if env.kind != kind {
        return Err(JpError::Io { path: p, reason: format!("holds a '{}', expected a '{kind}'", env.kind) });
    }
    if env.version > FORMAT_VERSION {
        return Err(JpError::Io {
            path: p,
            reason: format!("format version {} is newer than this library's {FORMAT_VERSION}", env.version),
        });
    }
    Ok(env.data)
}

fn io_err(path: &Path, e: std::io::Error) -> JpError {
    JpError::Io { path: path.display().to_string(), reason: e.to_string() }
}
