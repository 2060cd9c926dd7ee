//! The node/DoF map that places contacts and outputs on an imported FE model.
//!
//! A small JSON file:
//!
//! ```json
//! {
//!   "format": "jprom-dof-map",
//!   "version": 1,
//!   "n_dof": 21650,
//!   "nodes": [
//!     { "id": 1017, "coords": [12.5, 0.0, 101.0], "dofs": [3051, 3052, 3053] },
//!     { "id": 1018, "coords": [12.5, 1.0, 101.0], "dofs": [3054, 3055, 3056] }
//!   ]
//! }
//! ```
//!
//! - `n_dof`: size of the matrices the map refers to.
//! - `nodes`: the nodes the caller needs (contact, forcing and output nodes; not necessarily
//!   all): user node `id` (any integer, unique), `coords` in model units, and the 0-based row
//!   indices of the node's `x, y, z` DoFs in the matrices (Matrix Market rows minus one).
//!
//! Errors: malformed JSON or an unknown key gives [`JpError::Parse`] with the line; a wrong
//! `format` (checked first: a jprom model file says so) or `version`, a repeated id or DoF,
//! or a DoF `>= n_dof` gives [`JpError::InvalidValue`] naming the node.

use crate::error::{JpError, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Format tag of a DoF map file.
pub const DOF_MAP_FORMAT: &str = "jprom-dof-map";
/// Version of the DoF map format.
pub const DOF_MAP_VERSION: u32 = 1;

/// One node: user id, coordinates and its three DoFs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeDofs {
    /// User node id.
    pub id: i64,
    /// Coordinates `x, y, z`.
    pub coords: [f64; 3],
    /// 0-based DoF indices of `x, y, z`.
    pub dofs: [usize; 3],
}

/// A node/DoF map (see the module doc for the file format).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DofMap {
    /// Always [`DOF_MAP_FORMAT`].
    pub format: String,
    /// Format version ([`DOF_MAP_VERSION`]).
    pub version: u32,
    /// Size of the matrices.
    pub n_dof: usize,
    /// The mapped nodes.
    pub nodes: Vec<NodeDofs>,
}

impl DofMap {
    /// A map of the given nodes for matrices of size `n_dof`.
    ///
    /// # Errors
    /// As [`DofMap::validate`].
    pub fn new(n_dof: usize, nodes: Vec<NodeDofs>) -> Result<Self> {
        let m = DofMap { format: DOF_MAP_FORMAT.to_string(), version: DOF_MAP_VERSION, n_dof, nodes };
        m.validate()?;
        Ok(m)
    }

    /// Parses and validates JSON text; `name` is used in error messages.
    ///
    /// # Errors
    /// [`JpError::Parse`] for malformed JSON, else as [`DofMap::validate`].
    pub fn parse(text: &str, name: &str) -> Result<Self> {
        let perr = |e: serde_json::Error| JpError::Parse { path: name.to_string(), line: e.line(), reason: e.to_string() };
        // the format tag first: a jprom model or sweep given as a DoF map says so
        #[derive(Deserialize)]
        struct Tag {
            format: Option<String>,
            kind: Option<String>,
        }
        let tag: Tag = serde_json::from_str(text).map_err(|e| {
            if e.is_syntax() || e.is_eof() || e.is_data() {
                // not JSON at all (a Matrix Market or CSV file given as the map, say): say what was expected
                let what = if e.is_data() { "not a JSON object" } else { "not JSON" };
                JpError::Parse {
                    path: name.to_string(),
                    line: e.line(),
                    reason: format!("{what} ({e}): a DoF map is a JSON object {{\"format\": \"{DOF_MAP_FORMAT}\", \"version\": 1, \"n_dof\": ..., \"nodes\": [{{\"id\": ..., \"coords\": [x, y, z], \"dofs\": [rx, ry, rz]}}, ...]}}"),
                }
            } else {
                perr(e)
            }
        })?;
        match (tag.format.as_deref(), tag.kind.as_deref()) {
            (Some(DOF_MAP_FORMAT), _) => {}
            (Some("jprom"), Some(kind)) => {
                return Err(JpError::invalid("dof map format", format!("{name} is a jprom {kind} file, expected a DoF map ('{DOF_MAP_FORMAT}')")))
            }
            (other, _) => {
                return Err(JpError::invalid("dof map format", format!("expected '{DOF_MAP_FORMAT}', got {}", other.map_or("no format".to_string(), |f| format!("'{f}'")))))
            }
        }
        let m: DofMap = serde_json::from_str(text).map_err(perr)?;
        m.validate()?;
        Ok(m)
    }

    /// Reads and validates a map file.
    ///
    /// # Errors
    /// [`JpError::Io`] if unreadable, else as [`DofMap::parse`].
    pub fn load(path: &Path) -> Result<Self> {
        let text = super::read_text(path)?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Writes the map as pretty JSON.
    ///
    /// # Errors
    /// [`JpError::Io`] if the file cannot be written.
    pub fn save(&self, path: &Path) -> Result<()> {
        super::write_file(path, |w| serde_json::to_writer_pretty(&mut *w, self).map_err(std::io::Error::from))
    }

    /// Checks format, version, unique ids and DoFs, DoFs in range, finite coordinates.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the first offending node.
    pub fn validate(&self) -> Result<()> {
        if self.format != DOF_MAP_FORMAT {
            return Err(JpError::invalid("dof map format", format!("expected '{DOF_MAP_FORMAT}', got '{}'", self.format)));
        }
        if self.version > DOF_MAP_VERSION {
            return Err(JpError::invalid("dof map version", format!("{} is newer than {DOF_MAP_VERSION}", self.version)));
        }
        let mut ids = std::collections::HashSet::new();
        let mut dofs = std::collections::HashSet::new();
        for n in &self.nodes {
            let what = format!("dof map node {}", n.id);
            if !ids.insert(n.id) {
                return Err(JpError::invalid(what, "id appears twice"));
            }
            if n.coords.iter().any(|c| !c.is_finite()) {
                return Err(JpError::invalid(what, "coordinates are not finite"));
            }
            for &d in &n.dofs {
                if d >= self.n_dof {
                    return Err(JpError::invalid(what, format!("DoF {d} >= n_dof {}", self.n_dof)));
                }
                if !dofs.insert(d) {
                    return Err(JpError::invalid(what, format!("DoF {d} is used by another node")));
                }
            }
        }
        Ok(())
    }

    /// The entry of node `id`.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] if the id is not in the map.
    pub fn node(&self, id: i64) -> Result<&NodeDofs> {
        self.nodes.iter().find(|n| n.id == id).ok_or_else(|| JpError::invalid("dof map", format!("no node with id {id}")))
    }
}
