//! What an FE study names, checked against its model: the files (they exist, are readable and
//! start as they should), every node id and node-set name, every contact frame. `jprom check`
//! does it without reading the matrices ([`check_study_file`]: headers, the DoF map, the
//! CalculiX `.dof` and deck only, well under a second for a 100 MB model); the runner places
//! the contacts, loads and outputs with the same code ([`placement`]) on the model it read.
//! Every error names the study key and its line in the study file.

use crate::locate::toml_line;
use crate::study::{FeSource, FeSpec, ModelSpec, Nodes, Study};
use jprom::contact::ContactLaw;
use jprom::error::{JpError, Result};
use jprom::fe::{FeModel, FeNode, NodalContact, NodalForce, Reduction};
use jprom::io::calculix::{read_dofs, read_mesh, CalculixFiles};
use jprom::io::dof_map::DofMap;
use jprom::io::locate::{json_line, key_path};
use jprom::io::matrix_market::read_matrix_market_header;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// A study key and what is wrong with it.
pub type Bad = (String, String);

/// The nodes an FE study can name: each node (its rows, its coordinates) and the node sets.
#[derive(Clone, Debug, Default)]
pub struct ModelNodes {
    nodes: HashMap<i64, FeNode>,
    /// Node sets, names in upper case (CalculiX).
    sets: BTreeMap<String, Vec<i64>>,
    /// Where the nodes come from, for messages (`the DoF map nodes.json`).
    source: String,
    /// Whether the model has node sets at all (a DoF map has none).
    has_sets: bool,
    /// Nodes the mesh defines that have no DoF (clamped, or used by no element).
    without_dofs: std::collections::HashSet<i64>,
}

impl ModelNodes {
    /// The nodes of an FE model read in full, with the node sets of its mesh (`None`: it has
    /// no sets, as a DoF map).
    pub fn of_fe_model(fe: &FeModel, sets: Option<BTreeMap<String, Vec<i64>>>, source: String) -> Self {
        let nodes = fe.nodes().iter().map(|n| (n.id, n.clone())).collect();
        ModelNodes { nodes, has_sets: sets.is_some(), sets: sets.unwrap_or_default(), source, without_dofs: Default::default() }
    }

    /// Declares the nodes of the mesh (`defined`) that are not nodes of the model: they have no
    /// DoF (for messages).
    pub fn with_mesh_nodes(mut self, defined: impl IntoIterator<Item = i64>) -> Self {
        self.without_dofs = defined.into_iter().filter(|id| !self.nodes.contains_key(id)).collect();
        self
    }

    fn of_dof_map(map: &DofMap, source: String) -> Self {
        let nodes = map
            .nodes
            .iter()
            .map(|nd| {
                let mut dofs = [None; 6];
                for d in 0..3 {
                    dofs[d] = Some(nd.dofs[d]);
                }
                (nd.id, FeNode { id: nd.id, coords: Some(nd.coords), dofs })
            })
            .collect();
        ModelNodes { nodes, sets: BTreeMap::new(), source, has_sets: false, without_dofs: Default::default() }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The node ids `nodes` names, each a node of the model with its three translations.
    fn resolve(&self, key: &str, nodes: &Nodes) -> std::result::Result<Vec<i64>, Bad> {
        let bad = |reason: String| (key.to_string(), reason);
        let (ids, set) = match nodes {
            Nodes::Ids(ids) => (ids.clone(), None),
            Nodes::Set(name) => {
                if !self.has_sets {
                    return Err(bad(format!("\"{name}\" is a node set name, but {} has no node sets (give node ids)", self.source)));
                }
                let ids = jprom::io::calculix::node_set_in(&self.sets, name, &self.source).map_err(|e| match e {
                    JpError::InvalidValue { what, reason } => bad(format!("{what}: {reason}")),
                    other => bad(other.to_string()),
                })?;
                if ids.is_empty() {
                    return Err(bad(format!("node set \"{name}\" of {} is empty", self.source)));
                }
                (ids.to_vec(), Some(name.as_str()))
            }
        };
        let of_set = set.map(|s| format!(" (of node set \"{s}\")")).unwrap_or_default();
        for &id in &ids {
            let node = self.nodes.get(&id).ok_or_else(|| {
                if self.without_dofs.contains(&id) {
                    bad(format!("node {id}{of_set} has no active DoF in {} (fixed by *BOUNDARY, or used by no element)", self.source))
                } else {
                    bad(format!("no node with id {id}{of_set} in {}", self.source))
                }
            })?;
            if let Err(e) = node.translations() {
                let reason = match e {
                    JpError::InvalidValue { what, reason } => format!("{what}{of_set} {reason}"),
                    other => other.to_string(),
                };
                return Err(bad(reason));
            }
        }
        Ok(ids)
    }
}

/// Places the contacts (in `[[model.contacts]]` order, each with its frame and law), the loads
/// and the outputs of an FE study on `nodes`: the Craig-Bampton reduction to make.
///
/// # Errors
/// The key and why: an unknown node id or set name, a node without its translations, a
/// contact node given twice, a frame that cannot be built (a node on the axis).
pub fn placement(study: &Study, nodes: &ModelNodes) -> std::result::Result<Reduction, Bad> {
    let ModelSpec::Fe(FeSpec { contacts, output_nodes, output_components, cb_modes, cb_cutoff_hz, .. }) = &study.model else {
        return Err(("model.kind".into(), "not an FE model".into()));
    };
    let mut spec = Reduction { cb_modes: *cb_modes, cb_cutoff_hz: *cb_cutoff_hz, ..Reduction::default() };
    let mut contact_key: HashMap<i64, usize> = HashMap::new();
    for (i, set) in contacts.iter().enumerate() {
        let key = |k: &str| format!("model.contacts[{i}].{k}");
        let ids = nodes.resolve(&key("nodes"), &set.nodes)?;
        let (mu, kt1, kt2, kn) = set.law().map_err(|k| (key(k), "is required".to_string()))?;
        let law = ContactLaw::Friction3D { kt1, kt2, kn, mu, n0: set.n0 };
        for (k, &id) in ids.iter().enumerate() {
            if let Some(j) = contact_key.insert(id, i) {
                let also = if j == i { "twice in this set".to_string() } else { format!("also in model.contacts[{j}]") };
                return Err((key("nodes"), format!("node {id} is a contact node {also}")));
            }
            let frame = set.frame_of(k, &nodes.nodes[&id]).map_err(|(kk, r)| (key(&kk), r))?;
            spec.contacts.push(NodalContact { node: id, frame, law: law.clone() });
        }
    }
    for (name, loads) in [("static", &study.forcing.static_loads), ("harmonic", &study.forcing.harmonic_loads)] {
        for (i, l) in loads.iter().enumerate() {
            let force = l.vector().map_err(|r| (format!("forcing.{name}[{i}].direction"), r))?;
            for id in nodes.resolve(&format!("forcing.{name}[{i}].nodes"), &l.nodes)? {
                let f = NodalForce { node: id, force };
                if name == "static" {
                    spec.static_forces.push(f)
                } else {
                    spec.harmonic_forces.push(f)
                }
            }
        }
    }
    for id in nodes.resolve("model.output_nodes", output_nodes)? {
        spec.outputs.extend(output_components.iter().map(|c| (id, c.index())));
    }
    Ok(spec)
}

/// What [`check_files`] found.
#[derive(Clone, Debug, Default)]
pub struct FileReport {
    /// One line per file: its key, path and what was read from it.
    pub files: Vec<String>,
    /// The reduction the study asks for (contacts, loads, outputs on node ids).
    pub contacts: usize,
}

fn io_reason(e: JpError) -> String {
    match e {
        JpError::Io { path, reason } => format!("{path}: {reason}"),
        JpError::Parse { path, line, reason } if line > 0 => format!("{path}, line {line}: {reason}"),
        JpError::Parse { path, reason, .. } => format!("{path}: {reason}"),
        other => other.to_string(),
    }
}

/// Opens and validates every file an FE study names without reading the matrices: Matrix
/// Market headers and size lines (square, one size), the DoF map (in full: it is small; its
/// `n_dof` against the matrices), the CalculiX `.dof` and deck (node ids, coordinates, sets;
/// `.sti`/`.mas` opened and their first line read); then every node id, node set and frame
/// ([`placement`]). A blade study has no files.
///
/// # Errors
/// The key and why (the file's own error, with its line, inside the reason).
pub fn check_files(study: &Study) -> std::result::Result<FileReport, Bad> {
    let mut report = FileReport::default();
    if let ModelSpec::Fe(FeSpec { damping, .. }) = &study.model {
        if let Some(path) = &damping.matrix {
            let key = "model.damping.matrix";
            let h = read_matrix_market_header(path, true).map_err(|e| (key.to_string(), io_reason(e)))?;
            report.files.push(format!("{key} = {}: {} x {}, {} entries, {:.1} MB (header read)", path.display(), h.rows, h.cols, h.entries, h.file_bytes as f64 / 1e6));
        }
    }
    let ModelSpec::Fe(fe) = &study.model else {
        return Ok(report);
    };
    let nodes = match &fe.source {
        FeSource::MatrixMarket { mass, stiffness, dof_map } => {
            let mut n = None;
            for (key, path) in [("model.stiffness", stiffness), ("model.mass", mass)] {
                let h = read_matrix_market_header(path, true).map_err(|e| (key.to_string(), io_reason(e)))?;
                match n {
                    None => n = Some(h.rows),
                    Some(k) if k != h.rows => {
                        return Err((key.into(), format!("{}: {} x {}, but model.stiffness is {k} x {k}", path.display(), h.rows, h.cols)));
                    }
                    _ => {}
                }
                report.files.push(format!(
                    "{key} = {}: {} x {}, {} entries ({}), {:.1} MB (header read)",
                    path.display(),
                    h.rows,
                    h.cols,
                    h.entries,
                    if h.symmetric { "symmetric" } else { "general" },
                    h.file_bytes as f64 / 1e6
                ));
            }
            let map = DofMap::load(dof_map).map_err(|e| ("model.dof_map".to_string(), io_reason(e)))?;
            let n = n.unwrap_or(0);
            if map.n_dof != n {
                return Err(("model.dof_map".into(), format!("{}: n_dof {} but the matrices are {n} x {n}", dof_map.display(), map.n_dof)));
            }
            report.files.push(format!("model.dof_map = {}: {} nodes", dof_map.display(), map.nodes.len()));
            ModelNodes::of_dof_map(&map, format!("the DoF map {}", dof_map.display()))
        }
        FeSource::Calculix { deck } => {
            let files = CalculixFiles::of_job(deck);
            let key = "model.deck";
            let bad = |e: JpError| (key.to_string(), io_reason(e));
            for p in [&files.sti, &files.mas] {
                first_line(p).map_err(|r| (key.to_string(), format!("{} (beside the deck): {r}", p.display())))?;
            }
            let dofs = read_dofs(&files.dof).map_err(bad)?;
            let mesh = read_mesh(&files.inp).map_err(bad)?;
            let mut nodes: HashMap<i64, FeNode> = HashMap::new();
            for (row, &(id, dir)) in dofs.iter().enumerate() {
                let coords = mesh.coords.get(&id).copied();
                if coords.is_none() {
                    return Err((key.into(), format!("{}, line {}: node {id} is not defined by any *NODE card of {}", files.dof.display(), row + 1, files.inp.display())));
                }
                let node = nodes.entry(id).or_insert(FeNode { id, coords, dofs: [None; 6] });
                node.dofs[usize::from(dir) - 1] = Some(row);
            }
            report.files.push(format!(
                "model.deck = {}: {} nodes, node sets {}; {}: {} DoFs on {} nodes; {} and {} opened",
                files.inp.display(),
                mesh.coords.len(),
                if mesh.node_sets.is_empty() { "none".to_string() } else { mesh.node_sets.keys().cloned().collect::<Vec<_>>().join(", ") },
                files.dof.display(),
                dofs.len(),
                nodes.len(),
                files.sti.display(),
                files.mas.display()
            ));
            let defined: Vec<i64> = mesh.coords.keys().copied().collect();
            ModelNodes { nodes, sets: mesh.node_sets, source: format!("the CalculiX job {}", files.inp.display()), has_sets: true, without_dofs: Default::default() }.with_mesh_nodes(defined)
        }
    };
    let spec = placement(study, &nodes)?;
    report.contacts = spec.contacts.len();
    Ok(report)
}

/// Opens a file and reads its first line (a quick check that it is there and readable).
fn first_line(path: &Path) -> std::result::Result<(), String> {
    use std::io::{BufRead, Read};
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("is not a regular file".into());
    }
    let f = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut line = Vec::new();
    std::io::BufReader::new(f).take(4096).read_until(b'\n', &mut line).map_err(|e| e.to_string())?;
    let text = String::from_utf8_lossy(&line);
    let fields: Vec<&str> = text.split_whitespace().collect();
    if fields.len() != 3 || fields[0].parse::<u64>().is_err() || fields[1].parse::<u64>().is_err() || fields[2].parse::<f64>().is_err() {
        return Err(format!("line 1 is not 'row column value' (a ccx *MATRIX STORAGE file): '{}'", text.trim()));
    }
    Ok(())
}

/// The keys a study file does not give, with the values they take (`band.points = 200`):
/// every leaf of the study as read that the file's own text lacks.
pub fn defaults_applied(study: &Study, text: &str, is_json: bool) -> Vec<String> {
    let given: Option<serde_json::Value> = if is_json { serde_json::from_str(text).ok() } else { toml::from_str(text).ok() };
    let (Some(given), Ok(full)) = (given, serde_json::to_value(study)) else { return Vec::new() };
    let mut out = Vec::new();
    missing_leaves(&full, Some(&given), String::new(), &mut out);
    out
}

fn missing_leaves(full: &serde_json::Value, given: Option<&serde_json::Value>, path: String, out: &mut Vec<String>) {
    use serde_json::Value;
    match (full, given) {
        (Value::Object(m), Some(Value::Object(g))) => {
            for (k, v) in m {
                let p = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
                missing_leaves(v, g.get(k), p, out);
            }
        }
        (Value::Array(a), Some(Value::Array(g))) if a.iter().any(Value::is_object) => {
            for (i, v) in a.iter().enumerate() {
                missing_leaves(v, g.get(i), format!("{path}[{i}]"), out);
            }
        }
        (Value::Object(m), None) => {
            for (k, v) in m {
                missing_leaves(v, None, format!("{path}.{k}"), out);
            }
        }
        (v, None) => {
            let shown = toml::Value::try_from(v).map(|t| t.to_string()).unwrap_or_else(|_| v.to_string());
            out.push(format!("{path} = {shown}"));
        }
        _ => {}
    }
}

/// `jprom check`: reads and validates the study file, then every file and node it names
/// ([`check_files`]); returns the report to print: the files read, the defaults applied, and
/// the study in full.
///
/// # Errors
/// [`JpError::Parse`] naming the study file, the line of the offending key, the key and why.
pub fn check_study_file(path: &Path) -> Result<String> {
    let study = Study::from_file(path)?;
    let text = std::fs::read_to_string(path).map_err(|e| JpError::Io { path: path.display().to_string(), reason: e.to_string() })?;
    let is_json = path.extension().is_some_and(|e| e == "json");
    let report = check_files(&study).map_err(|(key, reason)| {
        let steps = key_path(&key);
        let line = if is_json { json_line(&text, &steps) } else { toml_line(&text, &steps) };
        JpError::Parse { path: path.display().to_string(), line: line.unwrap_or(0), reason: format!("key '{key}': {reason}") }
    })?;
    let mut out = format!("{}: valid\n", path.display());
    if !report.files.is_empty() {
        out.push_str(&format!("files (checked without reading the matrices; {} contact nodes placed):\n", report.contacts));
        for f in &report.files {
            out.push_str(&format!("  {f}\n"));
        }
    }
    if !study.cases.is_empty() {
        let units = crate::units::study_units(&study).len();
        let levels = study.forcing.levels.len();
        out.push_str(&format!(
            "cases: {} (units: {} cases x {levels} levels x {} units per level = {units}; files prefixed with the case's name):\n",
            study.cases.len(),
            study.cases.len(),
            units / (study.cases.len() * levels).max(1)
        ));
        for c in &study.cases {
            out.push_str(&format!("  {}: {}\n", c.name, c.describe()));
        }
    }
    let defaults = defaults_applied(&study, &text, is_json);
    if !defaults.is_empty() {
        out.push_str("defaults applied (keys the file does not give):\n");
        for d in &defaults {
            out.push_str(&format!("  {d}\n"));
        }
    }
    let full = toml::to_string_pretty(&study).map_err(|e| JpError::invalid("study", format!("cannot print it: {e}")))?;
    out.push_str("the study in full:\n");
    out.push_str(&full);
    Ok(out)
}
