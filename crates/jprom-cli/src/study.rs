//! The study file read by the `jprom` command-line program: what to model, how to force it,
//! which band and harmonics, which bases and which solvers. TOML (or JSON, by extension).
//!
//! ```toml
//! [model]
//! kind = "blade"            # built-in shrouded blade, "matrix_market" or "calculix" (see below)
//! refinement = 1            # blade only: 2 (2r + 1)^2 contact nodes: 1 -> 18, 5 -> 242, 15 -> 1,922 (at most 15)
//! cb_modes = 50             # Craig-Bampton fixed-interface modes
//! cache = false             # blade only: keep the Craig-Bampton model in output.dir and reuse it
//! damping_ratio = 0.002     # modal damping ratio at the band centre (stiffness-proportional)
//! # or, instead, any of the damping forms (they add up; forms not given are 0):
//! # [model.damping]
//! # ratio_at_centre = 0.002 # as damping_ratio
//! # alpha = 0.0             # Rayleigh alpha M + beta K (1/s, s)
//! # beta = 0.0
//! # modal_ratios = [0.002, 0.003]  # per mode of the reduced model (contacts open), lowest first
//! # modal_others = 0.002    # every mode after the list
//! # loss_factor = 0.0       # structural damping: (1 + i eta) K on the harmonics
//! # matrix = "C.mtx"        # FE models: the FE code's damping matrix, reduced with the model
//!
//! [band]
//! hz_start = 2140.0
//! hz_end = 2190.0
//! points = 200              # target number of points per sweep (more at resonances)
//! # optional continuation keys: min_step, max_step (scaled arclength), max_angle (rad), max_points
//!
//! [hbm]
//! harmonics = 1
//! nt = 64
//! max_iterations = 400      # Newton iterations per point (and per continuation corrector)
//!
//! [forcing]
//! levels = [0.1, 0.001]     # alpha / alpha_ST
//!
//! [basis]
//! gamma = 1000.0
//! samples = 100
//! error_threshold = 0.05
//! max_corrections = 5
//! regeneration_samples = 10
//! screen = true            # judge each candidate basis where the last was worst before sweeping it
//!
//! [solvers]
//! full_order = true
//! fr = true
//! nlr = true
//! fall_back = false        # the full order where a reduced sweep is not trusted (jprom run --fall-back)
//!
//! [output]
//! dir = "jprom-out"
//! ```
//!
//! A Matrix Market model (paths relative to the study file):
//!
//! ```toml
//! [model]
//! kind = "matrix_market"
//! mass = "M.mtx"
//! stiffness = "K.mtx"
//! dof_map = "nodes.json"    # io::dof_map: node ids -> coordinates and x, y, z DoFs
//! cb_modes = 30
//! cb_cutoff_hz = 20000.0    # optional: keep the fixed-interface modes up to this frequency (cb_modes a cap)
//! output_nodes = [501, 502]
//! output_components = ["y"] # default ["x", "y", "z"]; outputs are node-major
//!
//! [[model.contacts]]        # one set per law; node-to-ground
//! nodes = [1, 2, 3]
//! normal = [-1.0, 0.0, 0.0] # into the ground, every node; or normals = [[..], [..], [..]] (one
//!                           # per node id, in order); or a cylindrical frame (below)
//! tangent = [0.0, 1.0, 0.0] # optional t1 (default: the axis most perpendicular to normal)
//! mu = 0.4                  # mu, kt1, kt2, kn: required (no defaults for FE models)
//! kt1 = 2.0e4
//! kt2 = 2.0e4
//! kn = 2.3e4
//! n0 = 0.0                  # optional normal preload per node (default 0)
//!
//! [forcing]
//! levels = [0.1]
//! [[forcing.static]]        # f_E^0: magnitude along direction on each node
//! nodes = [1, 2, 3]
//! direction = [-1.0, 0.0, 0.0]
//! magnitude = 33.3
//! [[forcing.harmonic]]      # f_E^1 (cos part), scaled to the levels
//! nodes = [501]
//! direction = [0.0, 1.0, 0.0]
//! magnitude = 1.0
//! ```
//!
//! A CalculiX model: `deck` is the job's input deck `job.inp`; `job.sti`, `job.mas`, `job.dof`
//! (from `*FREQUENCY, SOLVER=MATRIXSTORAGE`) are beside it. Node coordinates and `*NSET`s come
//! from the deck (and its `*INCLUDE`s), and a node set's name (case-insensitive) can stand
//! wherever node ids go:
//!
//! ```toml
//! [model]
//! kind = "calculix"
//! deck = "blade.inp"
//! output_nodes = "OUT"
//!
//! [[model.contacts]]
//! nodes = "TIP"
//! # cylindrical frame: at each node n is radial from the axis (sense = "outward": away from
//! # it, the ground outside, e.g. a casing; "inward": towards it), t1 along the axis, t2 = n x t1
//! axis = { origin = [0.0, 0.0, 0.0], direction = [0.0, 0.0, 1.0], sense = "outward" }
//! mu = 0.3
//! kt1 = 1.0e4
//! kt2 = 1.0e4
//! kn = 2.0e4
//! ```
//!
//! Parameter cases: the same model with other contact parameters, damping ratio or static
//! load, each case running every level and solver ([`CaseSpec`]; output files prefixed with
//! the case's name):
//!
//! ```toml
//! [[cases]]
//! name = "mu0.2"
//! mu = 0.2
//! [[cases]]
//! name = "kn-high"
//! kn = 4.0e4
//! damping_ratio = 0.003
//! static_scale = 1.5
//! ```
//!
//! `jprom check` opens every file the study names (Matrix Market headers and size lines, not
//! the entries; the DoF map; the CalculiX `.dof` and deck) and checks every node id, node set
//! and frame against the model ([`crate::check`]); it prints the defaults it applied.
//!
//! Unknown keys are errors, and every error names the offending key and its line. Sizes have
//! documented caps ([`jprom::limits`]): `hbm.nt` <= 65536, `band.points` <= 100000,
//! `basis.samples` and `basis.regeneration_samples` <= 10000, `model.cb_modes` <= 5000, `model.refinement` <= 15.

use jprom::fe::BladeParams;
use jprom::error::{JpError, Result};
use crate::locate::toml_line;
use jprom::io::locate::{json_line, key_path};
use jprom::limits::{MAX_BAND_POINTS, MAX_BLADE_REFINEMENT, MAX_CB_MODES, MAX_NT, MAX_SAMPLES};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A whole study.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Study {
    pub model: ModelSpec,
    #[serde(default)]
    pub band: BandSpec,
    #[serde(default)]
    pub hbm: HbmSpec,
    #[serde(default)]
    pub forcing: ForcingSpec,
    #[serde(default)]
    pub basis: BasisSpec,
    #[serde(default)]
    pub solvers: SolverSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// Parameter cases (`[[cases]]`): the same model with other contact parameters, damping
    /// ratio or static load; empty: the study as written is the one case.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cases: Vec<CaseSpec>,
}

/// A parameter case (`[[cases]]`): the study's model with these overrides; keys not given keep
/// the study's values. Every case shares the Craig-Bampton reduction (the contact laws do not
/// enter it); each has its own level reference (`alpha_ST` depends on the contact stiffnesses,
/// the damping and the static load). Its output files are prefixed with `name` and `_`.
///
/// ```toml
/// [[cases]]
/// name = "mu0.2"            # letters, digits, '-', '_', '.' (not first); unique
/// mu = 0.2                  # model.contact.mu (FE models: every [[model.contacts]] set's mu)
/// # kt1, kt2, kn likewise
/// # damping_ratio = 0.003   # model.damping_ratio (ratio_at_centre; other damping forms kept)
/// # static_scale = 1.5      # multiplies the static load f_E^0 (the blade's pre-twist preload)
/// ```
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CaseSpec {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kt1: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kt2: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kn: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub static_scale: Option<f64>,
}

impl CaseSpec {
    /// The study as written: no name (no file prefix), no override.
    pub fn base() -> Self {
        CaseSpec { name: String::new(), mu: None, kt1: None, kt2: None, kn: None, damping_ratio: None, static_scale: None }
    }

    /// The prefix of the case's output files: `name_`, or nothing for the study as written.
    pub fn prefix(&self) -> String {
        if self.name.is_empty() {
            String::new()
        } else {
            format!("{}_", self.name)
        }
    }

    /// `mu = 0.2, kn = 3e4`: the overrides, in words (`the study's parameters` if none).
    pub fn describe(&self) -> String {
        let v: Vec<String> = [("mu", self.mu), ("kt1", self.kt1), ("kt2", self.kt2), ("kn", self.kn), ("damping_ratio", self.damping_ratio), ("static_scale", self.static_scale)]
            .into_iter()
            .filter_map(|(k, v)| v.map(|v| format!("{k} = {v}")))
            .collect();
        if v.is_empty() {
            "the study's parameters".into()
        } else {
            v.join(", ")
        }
    }

    /// Whether `name` is a safe file-name part: 1 to 64 letters, digits, `-`, `_`, `.`, not
    /// starting with `.` or `-`.
    fn name_problem(name: &str) -> Option<String> {
        if name.is_empty() || name.len() > 64 {
            return Some(format!("must have 1 to 64 characters, got {:?}", name));
        }
        if name.starts_with('.') || name.starts_with('-') {
            return Some(format!("must not start with '.' or '-', got {name:?}"));
        }
        if let Some(c) = name.chars().find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))) {
            return Some(format!("may hold letters, digits, '-', '_' and '.' only (it prefixes file names), got {c:?} in {name:?}"));
        }
        None
    }
}

/// Where the structure comes from. Read through the flat table [`RawModel`] (so that a bad
/// value deep inside `[model]` is reported with its full key and line, which an internally
/// tagged enum would lose), then checked for keys that do not belong to its `kind`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(try_from = "RawModel", into = "RawModel")]
pub enum ModelSpec {
    /// The built-in shrouded blade (docs/formulation.md §12).
    Blade {
        refinement: usize,
        cb_modes: usize,
        /// Keep the Craig-Bampton model in the output folder ([`BLADE_MODEL_CACHE`]) and reuse
        /// it when a later run into that folder builds the same blade (`model.cache`).
        cache: bool,
        damping: DampingSpec,
        contact: ContactSpec,
    },
    /// The user's FE model (`kind = "matrix_market"` or `"calculix"`).
    Fe(FeSpec),
}

/// An FE model of the user's: where its matrices come from, and what the study places on it.
/// Craig-Bampton keeps the contact, forced and output nodes as boundary.
#[derive(Clone, Debug, PartialEq)]
pub struct FeSpec {
    pub source: FeSource,
    pub cb_modes: usize,
    /// Keep the fixed-interface modes up to this frequency (Hz); `cb_modes` is then a cap.
    pub cb_cutoff_hz: Option<f64>,
    pub damping: DampingSpec,
    /// Node-to-ground contact sets (`[[model.contacts]]`).
    pub contacts: Vec<ContactSetSpec>,
    /// Output node ids; the first component of the first node is the response plotted.
    pub output_nodes: Nodes,
    /// Which of each output node's DoFs are outputs (default all three).
    pub output_components: Vec<Axis>,
}

/// Where an FE model's matrices come from. Paths are relative to the study file.
#[derive(Clone, Debug, PartialEq)]
pub enum FeSource {
    /// Matrix Market `M`, `K` and a node/DoF map ([`jprom::io::dof_map`]) placing contacts,
    /// outputs and forces (`[[forcing.static]]`, `[[forcing.harmonic]]`).
    MatrixMarket { mass: PathBuf, stiffness: PathBuf, dof_map: PathBuf },
    /// A CalculiX job: `K`, `M` and the row of each DoF from `*MATRIX STORAGE` (`job.sti`,
    /// `job.mas`, `job.dof` beside the deck), node coordinates and `*NSET`s from the deck
    /// `job.inp` ([`jprom::io::calculix`]); node sets of the deck can be named wherever node
    /// ids go.
    Calculix { deck: PathBuf },
}

impl FeSpec {
    /// The FE parts of a `[model]` table of an FE kind (output components default to x, y, z).
    #[allow(clippy::too_many_arguments)]
    fn from_raw(source: FeSource, damping: DampingSpec, cb_modes: usize, cb_cutoff_hz: Option<f64>, contacts: Vec<ContactSetSpec>, output_nodes: Nodes, output_components: Option<Vec<Axis>>) -> Self {
        FeSpec { source, cb_modes, cb_cutoff_hz, damping, contacts, output_nodes, output_components: output_components.unwrap_or_else(xyz) }
    }
}

impl FeSource {
    /// The `model.kind` of this source.
    pub fn kind(&self) -> &'static str {
        match self {
            FeSource::MatrixMarket { .. } => "matrix_market",
            FeSource::Calculix { .. } => "calculix",
        }
    }
}

/// `model.kind`.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    Blade,
    MatrixMarket,
    Calculix,
}

/// The `[model]` table as written: every key of every kind.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RawModel {
    pub kind: ModelKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refinement: Option<usize>,
    #[serde(default = "fifty")]
    pub cb_modes: usize,
    /// Blade only: keep the reduced model in the output folder and reuse it (`model.cache`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub cache: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cb_cutoff_hz: Option<f64>,
    /// Short form of `[model.damping] ratio_at_centre`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<DampingSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dof_map: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deck: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<ContactSetSpec>,
    #[serde(default, skip_serializing_if = "Nodes::is_empty")]
    pub output_nodes: Nodes,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_components: Option<Vec<Axis>>,
}

impl TryFrom<RawModel> for ModelSpec {
    type Error = String;
    fn try_from(r: RawModel) -> std::result::Result<Self, String> {
        let damping = match (r.damping_ratio, r.damping.clone()) {
            (Some(_), Some(_)) => return Err("key 'model.damping_ratio': give it or a [model.damping] table, not both (ratio_at_centre is the same setting)".into()),
            (Some(z), None) => DampingSpec { ratio_at_centre: Some(z), ..DampingSpec::default() },
            (None, Some(d)) => d,
            (None, None) => DampingSpec { ratio_at_centre: Some(default_damping_ratio()), ..DampingSpec::default() },
        };
        let not_for = |key: &str, kind: &str| Err(format!("key 'model.{key}' does not apply to kind = \"{kind}\""));
        match r.kind {
            ModelKind::Blade => {
                for (key, given) in [
                    ("cb_cutoff_hz", r.cb_cutoff_hz.is_some()),
                    ("mass", r.mass.is_some()),
                    ("stiffness", r.stiffness.is_some()),
                    ("dof_map", r.dof_map.is_some()),
                    ("deck", r.deck.is_some()),
                    ("contacts", !r.contacts.is_empty()),
                    ("output_nodes", !r.output_nodes.is_empty()),
                    ("output_components", r.output_components.is_some()),
                ] {
                    if given {
                        return not_for(key, "blade");
                    }
                }
                Ok(ModelSpec::Blade {
                    refinement: r.refinement.unwrap_or(1),
                    cb_modes: r.cb_modes,
                    cache: r.cache,
                    damping: damping.clone(),
                    contact: r.contact.unwrap_or_default(),
                })
            }
            ModelKind::MatrixMarket | ModelKind::Calculix if r.cache => {
                not_for("cache", if r.kind == ModelKind::Calculix { "calculix" } else { "matrix_market" })
            }
            ModelKind::MatrixMarket => {
                if r.refinement.is_some() {
                    return not_for("refinement", "matrix_market");
                }
                if r.deck.is_some() {
                    return not_for("deck", "matrix_market (the CalculiX deck is for kind = \"calculix\")");
                }
                if r.contact.is_some() {
                    return not_for("contact", "matrix_market (use [[model.contacts]] sets)");
                }
                let need = |key: &str, p: Option<PathBuf>| p.ok_or_else(|| format!("key 'model.{key}' is required for kind = \"matrix_market\""));
                let source = FeSource::MatrixMarket { mass: need("mass", r.mass)?, stiffness: need("stiffness", r.stiffness)?, dof_map: need("dof_map", r.dof_map)? };
                Ok(ModelSpec::Fe(FeSpec::from_raw(source, damping.clone(), r.cb_modes, r.cb_cutoff_hz, r.contacts, r.output_nodes, r.output_components)))
            }
            ModelKind::Calculix => {
                for (key, given) in [("refinement", r.refinement.is_some()), ("mass", r.mass.is_some()), ("stiffness", r.stiffness.is_some()), ("dof_map", r.dof_map.is_some())] {
                    if given {
                        return Err(format!("key 'model.{key}' does not apply to kind = \"calculix\" (deck = \"job.inp\" names the job: job.sti, job.mas, job.dof beside it)"));
                    }
                }
                if r.contact.is_some() {
                    return not_for("contact", "calculix (use [[model.contacts]] sets)");
                }
                let source = FeSource::Calculix { deck: r.deck.ok_or_else(|| "key 'model.deck' is required for kind = \"calculix\"".to_string())? };
                Ok(ModelSpec::Fe(FeSpec::from_raw(source, damping.clone(), r.cb_modes, r.cb_cutoff_hz, r.contacts, r.output_nodes, r.output_components)))
            }
        }
    }
}

impl From<ModelSpec> for RawModel {
    fn from(m: ModelSpec) -> RawModel {
        match m {
            ModelSpec::Blade { refinement, cb_modes, cache, damping, contact } => RawModel {
                kind: ModelKind::Blade,
                refinement: Some(refinement),
                cb_modes,
                cache,
                cb_cutoff_hz: None,
                damping_ratio: damping.short_form(),
                damping: if damping.short_form().is_some() { None } else { Some(damping) },
                contact: Some(contact),
                mass: None,
                stiffness: None,
                dof_map: None,
                deck: None,
                contacts: Vec::new(),
                output_nodes: Nodes::default(),
                output_components: None,
            },
            ModelSpec::Fe(FeSpec { source, cb_modes, cb_cutoff_hz, damping, contacts, output_nodes, output_components }) => {
                let (kind, mass, stiffness, dof_map, deck) = match source {
                    FeSource::MatrixMarket { mass, stiffness, dof_map } => (ModelKind::MatrixMarket, Some(mass), Some(stiffness), Some(dof_map), None),
                    FeSource::Calculix { deck } => (ModelKind::Calculix, None, None, None, Some(deck)),
                };
                RawModel {
                    kind,
                    refinement: None,
                    cb_modes,
                    cache: false,
                    cb_cutoff_hz,
                    damping_ratio: damping.short_form(),
                    damping: if damping.short_form().is_some() { None } else { Some(damping) },
                    contact: None,
                    mass,
                    stiffness,
                    dof_map,
                    deck,
                    contacts,
                    output_nodes,
                    output_components: Some(output_components),
                }
            }
        }
    }
}

/// A global axis.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

fn xyz() -> Vec<Axis> {
    vec![Axis::X, Axis::Y, Axis::Z]
}

/// Nodes, by id or by name: a list of node ids (`nodes = [1, 2, 3]`) or the name of a node set
/// of the model (`nodes = "TIP"`: a CalculiX `*NSET`, case-insensitive).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Nodes {
    Ids(Vec<i64>),
    Set(String),
}

impl Default for Nodes {
    fn default() -> Self {
        Nodes::Ids(Vec::new())
    }
}

impl Nodes {
    /// An empty list of ids (a set name is never empty here: its size is the model's).
    pub fn is_empty(&self) -> bool {
        matches!(self, Nodes::Ids(v) if v.is_empty())
    }
}

impl From<Vec<i64>> for Nodes {
    fn from(v: Vec<i64>) -> Self {
        Nodes::Ids(v)
    }
}

impl Serialize for Nodes {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Nodes::Ids(v) => v.serialize(s),
            Nodes::Set(name) => name.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Nodes {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Nodes;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a list of node ids ([1, 2, 3]) or the name of a node set (\"TIP\")")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> std::result::Result<Nodes, E> {
                Ok(Nodes::Set(v.to_string()))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut a: A) -> std::result::Result<Nodes, A::Error> {
                let mut ids = Vec::new();
                while let Some(id) = a.next_element::<i64>()? {
                    ids.push(id);
                }
                Ok(Nodes::Ids(ids))
            }
        }
        d.deserialize_any(V)
    }
}

/// Which way a cylindrical frame's normal points (`axis.sense`).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Sense {
    /// Away from the axis: the ground is outside the nodes (a casing around blade tips).
    Outward,
    /// Towards the axis: the ground is inside (a hub).
    Inward,
}

/// A cylindrical contact frame (`axis = { origin = [..], direction = [..], sense = "outward" }`):
/// at each node, the normal is radial from the axis (`sense` says which way), `t1` is along
/// the axis, `t2 = n x t1` is circumferential ([`jprom::fe::cylindrical_frame`]).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    pub origin: [f64; 3],
    pub direction: [f64; 3],
    pub sense: Sense,
}

/// A set of node-to-ground contacts sharing a law (FE models). Its frame: exactly one of
/// `normal` (one for every node), `normals` (one per node, in the order of `nodes`) and
/// `axis` (a cylindrical frame, radial normals from the nodes' coordinates).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactSetSpec {
    /// Contact node ids, or a node set's name.
    pub nodes: Nodes,
    /// Contact normal of every node, pointing into the ground (normalised; need not be unit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// One normal per node (node ids only, same order and count).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normals: Option<Vec<[f64; 3]>>,
    /// A cylindrical frame about an axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<AxisSpec>,
    /// First tangent direction `t1` with `normal` or `normals` (its part normal to each normal
    /// is used); default: the global axis most perpendicular to the normal. `t2 = n x t1`.
    /// Not with `axis` (`t1` is the axis there).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangent: Option<[f64; 3]>,
    /// The law, per node: all four required (no defaults for FE models).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kt1: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kt2: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kn: Option<f64>,
    /// Normal preload per node at zero normal displacement (`N = max(0, n0 + kn v)`).
    #[serde(default)]
    pub n0: f64,
}

impl ContactSetSpec {
    /// Which key sets the frame: `normal`, `normals` or `axis`, or why not exactly one.
    pub fn frame_key(&self) -> std::result::Result<&'static str, String> {
        let given: Vec<&'static str> = [("normal", self.normal.is_some()), ("normals", self.normals.is_some()), ("axis", self.axis.is_some())]
            .into_iter()
            .filter(|g| g.1)
            .map(|g| g.0)
            .collect();
        match given.as_slice() {
            [one] => Ok(one),
            [] => Err("needs a frame: one of normal (every node), normals (one per node) or axis (cylindrical)".into()),
            more => Err(format!("give one frame, not {}", more.join(" and "))),
        }
    }

    /// The law `(mu, kt1, kt2, kn)`, or the first key missing.
    pub fn law(&self) -> std::result::Result<(f64, f64, f64, f64), &'static str> {
        Ok((self.mu.ok_or("mu")?, self.kt1.ok_or("kt1")?, self.kt2.ok_or("kt2")?, self.kn.ok_or("kn")?))
    }

    /// The frame of the set's `k`-th node (`coords`: its node, for `axis`), rows `t1, t2, n`,
    /// or the offending key (`normal`, `normals[k]`, `tangent`, `axis`) and why.
    pub fn frame_of(&self, k: usize, node: &jprom::fe::FeNode) -> std::result::Result<[[f64; 3]; 3], (String, String)> {
        let split = |e: JpError, normal_key: String| match e {
            JpError::InvalidValue { what, reason } if what == "tangent" => ("tangent".to_string(), reason),
            JpError::InvalidValue { what, reason } if what == "normal" => (normal_key, reason),
            JpError::InvalidValue { what, reason } if what == "axis" => ("axis".to_string(), reason),
            JpError::InvalidValue { what, reason } => ("axis".to_string(), format!("{what} {reason}")),
            other => ("axis".to_string(), other.to_string()),
        };
        match self.frame_key().map_err(|r| ("normal".to_string(), r))? {
            "normal" => jprom::fe::contact_frame(self.normal.unwrap_or_default(), self.tangent).map_err(|e| split(e, "normal".into())),
            "normals" => {
                let ns = self.normals.as_deref().unwrap_or_default();
                let n = ns.get(k).ok_or_else(|| ("normals".to_string(), format!("has {} normals, but the set has more nodes", ns.len())))?;
                jprom::fe::contact_frame(*n, self.tangent).map_err(|e| split(e, format!("normals[{k}]")))
            }
            _ => {
                let a = self.axis.as_ref().expect("axis");
                if self.tangent.is_some() {
                    return Err(("tangent".into(), "does not apply to a cylindrical frame (t1 is the axis)".into()));
                }
                let sense = match a.sense {
                    Sense::Outward => jprom::fe::RadialSense::Outward,
                    Sense::Inward => jprom::fe::RadialSense::Inward,
                };
                node.cylindrical_frame(a.origin, a.direction, sense).map_err(|e| split(e, "normal".into()))
            }
        }
    }
}

/// A nodal load: `magnitude` along unit `direction` on each of `nodes` (Matrix Market models).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct NodalLoad {
    /// Node ids, or a node set's name.
    pub nodes: Nodes,
    pub direction: [f64; 3],
    /// Force per node.
    pub magnitude: f64,
}

impl NodalLoad {
    /// `magnitude * direction / |direction|`, or why not.
    pub fn vector(&self) -> std::result::Result<[f64; 3], String> {
        let d = self.direction;
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if !(n.is_finite() && n > 0.0) {
            return Err(format!("must be a finite nonzero vector, got {d:?}"));
        }
        Ok(d.map(|x| self.magnitude * x / n))
    }
}

/// Contact parameters per node (defaults: docs/formulation.md §12).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSpec {
    pub mu: f64,
    pub kt1: f64,
    pub kt2: f64,
    pub kn: f64,
}

impl Default for ContactSpec {
    fn default() -> Self {
        ContactSpec { mu: default_mu(), kt1: default_kt1(), kt2: default_kt2(), kn: default_kn() }
    }
}

fn default_mu() -> f64 {
    0.4
}
fn default_kt1() -> f64 {
    2.0126e4
}
fn default_kt2() -> f64 {
    2.0059e4
}
fn default_kn() -> f64 {
    2.34152e4
}

/// Frequency band, in Hz.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct BandSpec {
    pub hz_start: f64,
    pub hz_end: f64,
    pub points: usize,
    /// Continuation steps in the scaled arclength, the largest turn between chords, and the
    /// point cap of each sweep; unset keys take [`jprom::hbm::SweepOptions`]' defaults (the cap:
    /// 40 x `points`, within 2,000 and 100,000: a partial-slip resonance is a string of
    /// stick-slip kinks, each of which takes a few points).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_step: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_step: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_angle: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_points: Option<usize>,
}

impl Default for BandSpec {
    fn default() -> Self {
        BandSpec { hz_start: 2140.0, hz_end: 2190.0, points: 200, min_step: None, max_step: None, max_angle: None, max_points: None }
    }
}

impl BandSpec {
    /// The continuation settings of the band (rad/s): about `points` points where the response
    /// is smooth, more at resonances and folds, and the keys given.
    pub fn sweep_options(&self) -> jprom::hbm::SweepOptions {
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut s = jprom::hbm::SweepOptions {
            max_points: (40 * self.points).clamp(2000, 100_000),
            ..jprom::hbm::SweepOptions::with_points(two_pi * self.hz_start, two_pi * self.hz_end, self.points)
        };
        if let Some(v) = self.min_step {
            s.min_step = v;
        }
        if let Some(v) = self.max_step {
            s.max_step = v;
        }
        s.initial_step = s.initial_step.clamp(s.min_step.min(s.max_step), s.max_step);
        if let Some(v) = self.max_angle {
            s.max_angle = v;
        }
        if let Some(v) = self.max_points {
            s.max_points = v;
        }
        s
    }
}

/// Harmonic balance settings.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct HbmSpec {
    pub harmonics: usize,
    pub nt: usize,
    /// Newton iterations per point, all attempts together; bounds the continuation's corrector
    /// too (default 400, [`jprom::hbm::HbmOptions::max_iterations`]).
    pub max_iterations: usize,
}

impl Default for HbmSpec {
    fn default() -> Self {
        HbmSpec { harmonics: 1, nt: 64, max_iterations: jprom::hbm::HbmOptions::default().max_iterations }
    }
}

/// Excitation levels, as `alpha / alpha_ST`, and (Matrix Market models) the loads.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct ForcingSpec {
    pub levels: Vec<f64>,
    /// Static load `f_E^0` (`[[forcing.static]]`, Matrix Market models only).
    #[serde(rename = "static", skip_serializing_if = "Vec::is_empty")]
    pub static_loads: Vec<NodalLoad>,
    /// First-harmonic load `f_E^1`, cos part (`[[forcing.harmonic]]`, Matrix Market models only);
    /// its scale is set by `levels`.
    #[serde(rename = "harmonic", skip_serializing_if = "Vec::is_empty")]
    pub harmonic_loads: Vec<NodalLoad>,
}

impl Default for ForcingSpec {
    fn default() -> Self {
        ForcingSpec { levels: vec![0.1, 1e-3], static_loads: Vec::new(), harmonic_loads: Vec::new() }
    }
}

/// JP basis options.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct BasisSpec {
    pub gamma: f64,
    pub samples: usize,
    pub error_threshold: f64,
    /// Most basis corrections of the self-correcting sweep per level and ROM.
    pub max_corrections: usize,
    /// `p̂` samples of a correction's regeneration (`jprom::rom::AdaptiveOptions::regeneration_samples`).
    pub regeneration_samples: usize,
    /// Judge each candidate basis of a correction at the point where the current basis was
    /// judged worst before sweeping it (`jprom::rom::AdaptiveOptions::screen`).
    pub screen: bool,
    /// JP eigenpairs kept beyond the band, nearest first (`ModeOptions::extra_outside`): at
    /// gross slip the slipping mode leaves the band, and the in-band ones alone may miss it.
    pub extra_modes: usize,
    /// Whether the prediction also samples the contacts along the slipping mode
    /// (`jprom::jp::SlippingSamples`, docs/formulation.md §8.8): `"never"` (default),
    /// `"at_gross_slip"` (when the linear stuck response is 50 times the amplitude where slip
    /// begins, about `alpha_ST / 50` and below) or `"always"`.
    pub slipping: SlippingSpec,
    /// Error vs basis size: at each level, one predicted basis per `gamma` in this list, each
    /// ROM solved at the full-order resonance (needs `solvers.full_order`). Empty: no study.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub gamma_study: Vec<f64>,
}

impl Default for BasisSpec {
    fn default() -> Self {
        BasisSpec { gamma: 1e3, samples: 100, error_threshold: 0.05, max_corrections: 5, regeneration_samples: jprom::rom::REGENERATION_SAMPLES, screen: jprom::rom::AdaptiveOptions::default().screen, extra_modes: 2, slipping: SlippingSpec::Never, gamma_study: Vec::new() }
    }
}

/// `basis.slipping`: the study file's words for [`jprom::jp::SlippingSamples`].
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SlippingSpec {
    #[default]
    Never,
    AtGrossSlip,
    Always,
}

impl From<SlippingSpec> for jprom::jp::SlippingSamples {
    fn from(s: SlippingSpec) -> Self {
        match s {
            SlippingSpec::Never => jprom::jp::SlippingSamples::Never,
            SlippingSpec::AtGrossSlip => jprom::jp::SlippingSamples::AtGrossSlip,
            SlippingSpec::Always => jprom::jp::SlippingSamples::Always,
        }
    }
}

/// Which solvers run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    pub full_order: bool,
    pub fr: bool,
    pub nlr: bool,
    /// Where a reduced sweep is not trusted or did not finish, the full order gives the
    /// level's result, run there after the study's units when `full_order` is off
    /// ([`crate::fall_back`]; `jprom run --fall-back`). Default off.
    pub fall_back: bool,
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec { full_order: true, fr: true, nlr: true, fall_back: false }
    }
}

/// Where results go.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct OutputSpec {
    pub dir: PathBuf,
    pub plots: bool,
    /// Exit with success even when a sweep did not cover the band (default false: `jprom run`
    /// then exits with status 3 after writing what it has).
    pub keep_partial: bool,
    /// The response: the output (index into the model's outputs, node-major) whose amplitude
    /// locates the resonance, is plotted and is compared ([`Study::response_output`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub response: Option<usize>,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec { dir: PathBuf::from("jprom-out"), plots: true, keep_partial: false, response: None }
    }
}

/// The file in the output folder that holds the built-in blade's Craig-Bampton model when
/// `model.cache` is on.
pub const BLADE_MODEL_CACHE: &str = "blade_model_cache.json";

/// The built-in blade's response output: the flap (`y`) displacement of the tip output node
/// (the last of its 9 output nodes, 3 outputs each).
pub const BLADE_TIP_FLAP_OUTPUT: usize = 8 * 3 + 1;

fn fifty() -> usize {
    50
}
/// `[model.damping]`: the damping forms, which add up (docs/formulation.md §1). The short form
/// `model.damping_ratio = z` is `ratio_at_centre = z` alone; with neither, `ratio_at_centre =
/// 0.002`. In a table, forms not given are zero.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// Stiffness-proportional damping with this modal ratio at the band centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio_at_centre: Option<f64>,
    /// Rayleigh `alpha` (1/s) of `alpha M + beta K`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub alpha: f64,
    /// Rayleigh `beta` (s).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub beta: f64,
    /// Modal damping ratios of the reduced model's lowest modes (contacts open), lowest first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub modal_ratios: Vec<f64>,
    /// Modal damping ratio of every mode after `modal_ratios`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub modal_others: f64,
    /// Structural loss factor `eta`: the harmonics see `(1 + i eta) K`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub loss_factor: f64,
    /// The FE code's viscous damping matrix `C` (Matrix Market, symmetric, the size of `K`),
    /// reduced with the model; FE models only. Relative to the study file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<PathBuf>,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl DampingSpec {
    /// The short form's ratio, when this is nothing but `ratio_at_centre`.
    pub fn short_form(&self) -> Option<f64> {
        let rest = DampingSpec { ratio_at_centre: None, ..self.clone() };
        if rest == DampingSpec::default() {
            self.ratio_at_centre
        } else {
            None
        }
    }

    /// Values finite and `>= 0`, naming the key.
    fn check(&self) -> std::result::Result<(), (String, String)> {
        let mut values: Vec<(String, f64)> = vec![("alpha".into(), self.alpha), ("beta".into(), self.beta), ("modal_others".into(), self.modal_others), ("loss_factor".into(), self.loss_factor)];
        if let Some(z) = self.ratio_at_centre {
            values.push(("ratio_at_centre".into(), z));
        }
        values.extend(self.modal_ratios.iter().enumerate().map(|(i, &z)| (format!("modal_ratios[{i}]"), z)));
        for (k, v) in values {
            if !(v.is_finite() && v >= 0.0) {
                let key = if k == "ratio_at_centre" && self.short_form().is_some() { "model.damping_ratio".to_string() } else { format!("model.damping.{k}") };
                return Err((key, format!("must be finite and >= 0, got {v}")));
            }
        }
        Ok(())
    }

    /// Applies the forms that act on the reduced model: Rayleigh (with the ratio at
    /// `centre_rad_s`), modal ratios (added to an FE damping matrix already there), loss factor.
    ///
    /// # Errors
    /// [`jprom::model::Model::add_modal_damping`]'s and validation errors.
    pub fn apply(&self, model: &mut jprom::model::Model, centre_rad_s: f64) -> Result<()> {
        let from_ratio = self.ratio_at_centre.map(|z| jprom::model::Damping::from_modal_ratio(z, centre_rad_s)).unwrap_or_default();
        model.damping = jprom::model::Damping { mass_coeff: self.alpha + from_ratio.mass_coeff, stiffness_coeff: self.beta + from_ratio.stiffness_coeff };
        if !self.modal_ratios.is_empty() || self.modal_others > 0.0 {
            model.add_modal_damping(&self.modal_ratios, self.modal_others)?;
        }
        model.loss_factor = self.loss_factor;
        model.validate()
    }
}

fn default_damping_ratio() -> f64 {
    0.002
}

impl Study {
    /// Reads a study from a `.toml` or `.json` file and validates it.
    ///
    /// # Errors
    /// [`JpError::Parse`] naming the file, the line where known, the offending key and the reason.
    pub fn from_file(path: &Path) -> Result<Study> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| JpError::Io { path: path.display().to_string(), reason: e.to_string() })?;
        let is_json = path.extension().map(|e| e == "json").unwrap_or(false);
        let study = if is_json { Self::from_json_str(&text) } else { Self::from_toml_str(&text) };
        let mut study = study.map_err(|e| match e {
            JpError::Parse { line, reason, .. } => JpError::Parse { path: path.display().to_string(), line, reason },
            other => other,
        })?;
        study.resolve_paths(path.parent().unwrap_or(Path::new("")));
        Ok(study)
    }

    /// Makes the relative paths of the study (model files, `output.dir`) relative to `base`,
    /// the study file's directory. [`Study::from_file`] does this.
    pub fn resolve_paths(&mut self, base: &Path) {
        let fix = |p: &mut PathBuf| {
            if p.is_relative() && !base.as_os_str().is_empty() {
                *p = base.join(&*p);
            }
        };
        if let ModelSpec::Fe(fe) = &mut self.model {
            match &mut fe.source {
                FeSource::MatrixMarket { mass, stiffness, dof_map } => {
                    fix(mass);
                    fix(stiffness);
                    fix(dof_map);
                }
                FeSource::Calculix { deck } => fix(deck),
            }
            if let Some(c) = fe.damping.matrix.as_mut() {
                fix(c);
            }
        }
        fix(&mut self.output.dir);
    }

    /// Parses and validates TOML text.
    pub fn from_toml_str(text: &str) -> Result<Study> {
        let de = toml::Deserializer::parse(text).map_err(|e| parse_error(text, e.span().map(|s| s.start), e.message()))?;
        let study: Study = serde_path_to_error::deserialize(de).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            let message = inner.message();
            // an error of a whole table that names a key inside it (a key of the wrong model
            // kind): the line of that key
            let named_line = message.strip_prefix("key '").and_then(|m| m.split('\'').next()).and_then(|k| toml_line(text, &key_path(k)));
            // an unknown key: the line of that key, not of its table
            let unknown_line = if message.starts_with("unknown field") { toml_line(text, &key_path(&key)) } else { None };
            match (inner.span(), named_line) {
                (_, Some(line)) if message.starts_with("key '") => JpError::Parse { path: "<study>".into(), line, reason: message.to_string() },
                _ if unknown_line.is_some() => JpError::Parse { path: "<study>".into(), line: unknown_line.unwrap_or(0), reason: format!("key '{key}': {message}") },
                (Some(span), _) => parse_error(text, Some(span.start), &format!("key '{key}': {message}")),
                // an error of a whole table (a key of the wrong model kind, a required key
                // missing): the line of the key it names, else of the table
                (None, _) => {
                    let named = message.strip_prefix("key '").and_then(|m| m.split('\'').next()).unwrap_or(&key);
                    let line = toml_line(text, &key_path(named)).or_else(|| toml_line(text, &key_path(&key))).unwrap_or(0);
                    let reason = if message.starts_with("key '") { message.to_string() } else { format!("key '{key}': {message}") };
                    JpError::Parse { path: "<study>".into(), line, reason }
                }
            }
        })?;
        study.check().map_err(|(key, reason)| study_error(toml_line(text, &key_path(&key)).unwrap_or(0), &key, &reason))?;
        Ok(study)
    }

    /// Parses and validates JSON text.
    pub fn from_json_str(text: &str) -> Result<Study> {
        let mut de = serde_json::Deserializer::from_str(text);
        let study: Study = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            JpError::Parse { path: "<study>".into(), line: inner.line(), reason: format!("key '{key}': {inner}") }
        })?;
        study.check().map_err(|(key, reason)| study_error(json_line(text, &key_path(&key)).unwrap_or(0), &key, &reason))?;
        Ok(study)
    }

    /// Range and consistency checks; each error names its key (the parsers
    /// [`Study::from_toml_str`] and [`Study::from_json_str`] add its line).
    pub fn validate(&self) -> Result<()> {
        self.check().map_err(|(key, reason)| study_error(0, &key, &reason))
    }

    /// [`Study::validate`] as the offending key and the reason.
    fn check(&self) -> std::result::Result<(), (String, String)> {
        let bad = |key: &str, reason: String| Err((key.to_string(), reason));
        let over = |key: &str, value: usize, limit: usize, why: &str| Err((key.to_string(), format!("{value} is above jprom's limit of {limit} ({why})")));
        let (cb_modes, damping, contact) = match &self.model {
            ModelSpec::Blade { refinement, cb_modes, damping, contact, .. } => {
                if *refinement > MAX_BLADE_REFINEMENT {
                    return over("model.refinement", *refinement, MAX_BLADE_REFINEMENT, "15 gives 1,922 contact nodes and 140,658 FE DoFs");
                }
                // the library's own rules for the blade (refinement >= 1, positive contact law)
                let params = BladeParams { refinement: *refinement, mu: contact.mu, kt1: contact.kt1, kt2: contact.kt2, kn: contact.kn, ..Default::default() };
                if let Err(e) = params.validate() {
                    let (key, reason) = match e {
                        JpError::InvalidValue { what, reason } => (what, reason),
                        other => ("blade".to_string(), other.to_string()),
                    };
                    let key = match key.strip_prefix("blade.") {
                        Some(k @ ("mu" | "kt1" | "kt2" | "kn")) => format!("model.contact.{k}"),
                        Some(k) => format!("model.{k}"),
                        None => key,
                    };
                    return bad(&key, reason);
                }
                if damping.matrix.is_some() {
                    return bad("model.damping.matrix", "a damping matrix file is for FE models, kind = \"matrix_market\" or \"calculix\"".into());
                }
                (*cb_modes, damping, Some(contact))
            }
            ModelSpec::Fe(FeSpec { source, cb_modes, damping, contacts, output_nodes, output_components, .. }) => {
                let kind = source.kind();
                if contacts.is_empty() {
                    return bad("model.contacts", format!("a {kind} model needs at least one [[model.contacts]] set"));
                }
                for (i, c) in contacts.iter().enumerate() {
                    let key = |k: &str| format!("model.contacts[{i}].{k}");
                    if c.nodes.is_empty() {
                        return bad(&key("nodes"), "needs at least one node id (or a node set's name)".into());
                    }
                    let frame = c.frame_key().map_err(|r| (key("nodes"), r))?;
                    match (frame, &c.nodes) {
                        ("normal", _) => {
                            if let Err((k, reason)) = c.frame_of(0, &jprom::fe::FeNode { id: 0, coords: None, dofs: [None; 6] }) {
                                return bad(&key(&k), reason);
                            }
                        }
                        ("normals", Nodes::Set(name)) => {
                            return bad(&key("normals"), format!("needs node ids in `nodes` (one normal per id, in order), not the set \"{name}\": use normal or axis for a set"));
                        }
                        ("normals", Nodes::Ids(ids)) => {
                            let ns = c.normals.as_deref().unwrap_or_default();
                            if ns.len() != ids.len() {
                                return bad(&key("normals"), format!("{} normals for {} nodes: give one per node, in the order of `nodes`", ns.len(), ids.len()));
                            }
                            for k in 0..ns.len() {
                                if let Err((kk, reason)) = c.frame_of(k, &jprom::fe::FeNode { id: 0, coords: None, dofs: [None; 6] }) {
                                    return bad(&key(&kk), reason);
                                }
                            }
                        }
                        _ => {
                            // the axis alone (each node's frame needs its coordinates: checked with the model)
                            // (at a point off the axis: origin + the global axis least aligned with it)
                            let a = c.axis.as_ref().map(|a| (a.origin, a.direction)).unwrap_or_default();
                            let k = (0..3).min_by(|&i, &j| a.1[i].abs().total_cmp(&a.1[j].abs())).unwrap_or(0);
                            let mut p = a.0;
                            p[k] += 1.0;
                            let probe = jprom::fe::FeNode { id: 0, coords: Some(p), dofs: [None; 6] };
                            if let Err((k, reason)) = c.frame_of(0, &probe) {
                                return bad(&key(&k), reason);
                            }
                        }
                    }
                    if let Err(k) = c.law() {
                        return bad(
                            &key(k),
                            format!("is required: a {kind} model's contact law has no default (give mu, kt1, kt2 and kn in every [[model.contacts]] set)"),
                        );
                    }
                    for (k, v) in [("mu", c.mu), ("kt1", c.kt1), ("kt2", c.kt2), ("kn", c.kn)] {
                        let v = v.unwrap_or_default();
                        if !(v.is_finite() && v >= 0.0) {
                            return bad(&key(k), format!("must be finite and >= 0, got {v}"));
                        }
                    }
                    if !c.n0.is_finite() {
                        return bad(&key("n0"), format!("must be finite, got {}", c.n0));
                    }
                }
                if output_nodes.is_empty() {
                    return bad("model.output_nodes", "needs at least one node id (or a node set's name)".into());
                }
                if output_components.is_empty() {
                    return bad("model.output_components", "needs at least one of \"x\", \"y\", \"z\"".into());
                }
                if self.forcing.harmonic_loads.is_empty() {
                    return bad("forcing.harmonic", format!("a {kind} model needs at least one [[forcing.harmonic]] load"));
                }
                for (name, loads) in [("static", &self.forcing.static_loads), ("harmonic", &self.forcing.harmonic_loads)] {
                    for (i, l) in loads.iter().enumerate() {
                        if l.nodes.is_empty() {
                            return bad(&format!("forcing.{name}[{i}].nodes"), "needs at least one node id (or a node set's name)".into());
                        }
                        if !l.magnitude.is_finite() {
                            return bad(&format!("forcing.{name}[{i}].magnitude"), format!("must be finite, got {}", l.magnitude));
                        }
                        if let Err(reason) = l.vector() {
                            return bad(&format!("forcing.{name}[{i}].direction"), reason);
                        }
                    }
                }
                (*cb_modes, damping, None)
            }
        };
        if matches!(self.model, ModelSpec::Blade { .. }) {
            if !self.forcing.static_loads.is_empty() {
                return bad("forcing.static", "nodal loads are for FE models, kind = \"matrix_market\" or \"calculix\" (the blade has its own)".into());
            }
            if !self.forcing.harmonic_loads.is_empty() {
                return bad("forcing.harmonic", "nodal loads are for FE models, kind = \"matrix_market\" or \"calculix\" (the blade has its own)".into());
            }
        }
        if cb_modes == 0 {
            return bad("model.cb_modes", "must be at least 1".into());
        }
        if cb_modes > MAX_CB_MODES {
            return over("model.cb_modes", cb_modes, MAX_CB_MODES, "the reduced model is dense");
        }
        if let ModelSpec::Fe(FeSpec { cb_cutoff_hz: Some(f), .. }) = &self.model {
            if !(f.is_finite() && *f > 0.0) {
                return bad("model.cb_cutoff_hz", format!("must be finite and > 0 Hz, got {f}"));
            }
        }
        damping.check()?;
        for (k, v) in contact.iter().flat_map(|c| [("mu", c.mu), ("kt1", c.kt1), ("kt2", c.kt2), ("kn", c.kn)]) {
            if !(v.is_finite() && v >= 0.0) {
                return bad(&format!("model.contact.{k}"), format!("must be finite and >= 0, got {v}"));
            }
        }
        let b = &self.band;
        if !(b.hz_start.is_finite() && b.hz_start > 0.0) {
            return bad("band.hz_start", format!("must be finite and > 0, got {}", b.hz_start));
        }
        if !(b.hz_end.is_finite() && b.hz_end > b.hz_start) {
            return bad("band.hz_end", format!("must be finite and > band.hz_start, got {}", b.hz_end));
        }
        if b.points < 2 {
            return bad("band.points", format!("must be at least 2, got {}", b.points));
        }
        if b.points > MAX_BAND_POINTS {
            return over("band.points", b.points, MAX_BAND_POINTS, "points per sweep");
        }
        if !(1..=16).contains(&self.hbm.harmonics) {
            return bad("hbm.harmonics", format!("must be in 1..=16, got {}", self.hbm.harmonics));
        }
        let nt = self.hbm.nt;
        if !nt.is_power_of_two() || nt < 4 * (self.hbm.harmonics + 1) {
            return bad("hbm.nt", format!("must be a power of two >= 4 (harmonics + 1), got {nt}"));
        }
        if nt > MAX_NT {
            return over("hbm.nt", nt, MAX_NT, "AFT samples per period");
        }
        if self.forcing.levels.is_empty() {
            return bad("forcing.levels", "needs at least one level".into());
        }
        for (i, &l) in self.forcing.levels.iter().enumerate() {
            if !(l.is_finite() && l > 0.0) {
                return bad(&format!("forcing.levels[{i}]"), format!("must be finite and > 0, got {l}"));
            }
        }
        if !(self.basis.gamma.is_finite() && self.basis.gamma >= 1.0) {
            return bad("basis.gamma", format!("must be finite and >= 1, got {}", self.basis.gamma));
        }
        if self.basis.samples < 2 {
            return bad("basis.samples", format!("must be at least 2, got {}", self.basis.samples));
        }
        if self.basis.samples > MAX_SAMPLES {
            return over("basis.samples", self.basis.samples, MAX_SAMPLES, "amplitude samples of the prediction");
        }
        if self.basis.regeneration_samples < 1 {
            return bad("basis.regeneration_samples", format!("must be at least 1, got {}", self.basis.regeneration_samples));
        }
        if self.basis.regeneration_samples > MAX_SAMPLES {
            return over("basis.regeneration_samples", self.basis.regeneration_samples, MAX_SAMPLES, "amplitude samples of a regeneration");
        }
        if !(self.basis.error_threshold.is_finite() && self.basis.error_threshold > 0.0) {
            return bad("basis.error_threshold", format!("must be finite and > 0, got {}", self.basis.error_threshold));
        }
        for (i, &g) in self.basis.gamma_study.iter().enumerate() {
            if !(g.is_finite() && g >= 1.0) {
                return bad(&format!("basis.gamma_study[{i}]"), format!("must be finite and >= 1, got {g}"));
            }
        }
        if !self.basis.gamma_study.is_empty() && !(self.solvers.full_order && (self.solvers.fr || self.solvers.nlr)) {
            return bad("basis.gamma_study", "needs solvers.full_order and at least one of fr, nlr (errors are against the full order)".into());
        }
        if !(self.solvers.full_order || self.solvers.fr || self.solvers.nlr) {
            return bad("solvers", "enable at least one of full_order, fr, nlr".into());
        }
        self.check_cases()
    }

    /// `[[cases]]`: names safe and unique, values as the keys they override.
    fn check_cases(&self) -> std::result::Result<(), (String, String)> {
        let bad = |key: String, reason: String| Err((key, reason));
        for (i, case) in self.cases.iter().enumerate() {
            let key = |k: &str| format!("cases[{i}].{k}");
            if let Some(reason) = CaseSpec::name_problem(&case.name) {
                return bad(key("name"), reason);
            }
            if let Some(j) = self.cases[..i].iter().position(|c| c.name == case.name) {
                return bad(key("name"), format!("{:?} is already the name of cases[{j}] (names prefix the output files)", case.name));
            }
            match &self.model {
                ModelSpec::Blade { refinement, contact, .. } => {
                    // the library's own rules for the blade's contact law (> 0)
                    let c = case.contact(contact);
                    let params = BladeParams { refinement: *refinement, mu: c.mu, kt1: c.kt1, kt2: c.kt2, kn: c.kn, ..Default::default() };
                    if let Err(JpError::InvalidValue { what, reason }) = params.validate() {
                        if let Some(k @ ("mu" | "kt1" | "kt2" | "kn")) = what.strip_prefix("blade.") {
                            return bad(key(k), reason);
                        }
                    }
                }
                ModelSpec::Fe(_) => {
                    for (k, v) in [("mu", case.mu), ("kt1", case.kt1), ("kt2", case.kt2), ("kn", case.kn)] {
                        if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= 0.0)) {
                            return bad(key(k), format!("must be finite and >= 0, got {v}"));
                        }
                    }
                }
            }
            if let Some(z) = case.damping_ratio.filter(|z| !(z.is_finite() && *z >= 0.0)) {
                return bad(key("damping_ratio"), format!("must be finite and >= 0, got {z}"));
            }
            if let Some(s) = case.static_scale.filter(|s| !(s.is_finite() && *s > 0.0)) {
                return bad(key("static_scale"), format!("must be finite and > 0, got {s}"));
            }
        }
        Ok(())
    }

    /// The study's cases in order: its `[[cases]]`, or the study as written ([`CaseSpec::base`]).
    pub fn case_list(&self) -> Vec<CaseSpec> {
        if self.cases.is_empty() {
            vec![CaseSpec::base()]
        } else {
            self.cases.clone()
        }
    }

    /// The harmonics and AFT samples of `[hbm]`: the discretisation of every system the study
    /// builds.
    pub fn discretisation(&self) -> jprom::hbm::Discretisation {
        jprom::hbm::Discretisation::with_nt(self.hbm.harmonics, self.hbm.nt)
    }

    /// The response output: `output.response`, else the blade's tip flap displacement
    /// ([`BLADE_TIP_FLAP_OUTPUT`]) or an FE model's first output (the first component of its
    /// first output node).
    pub fn response_output(&self) -> usize {
        self.output.response.unwrap_or(match self.model {
            ModelSpec::Blade { .. } => BLADE_TIP_FLAP_OUTPUT,
            _ => 0,
        })
    }
}

impl CaseSpec {
    /// The blade's contact parameters `base` with the case's overrides.
    pub fn contact(&self, base: &ContactSpec) -> ContactSpec {
        ContactSpec { mu: self.mu.unwrap_or(base.mu), kt1: self.kt1.unwrap_or(base.kt1), kt2: self.kt2.unwrap_or(base.kt2), kn: self.kn.unwrap_or(base.kn) }
    }

    /// The damping `base` with the case's `damping_ratio` as its `ratio_at_centre`.
    pub fn damping(&self, base: &DampingSpec) -> DampingSpec {
        match self.damping_ratio {
            Some(z) => DampingSpec { ratio_at_centre: Some(z), ..base.clone() },
            None => base.clone(),
        }
    }
}

/// A study error about `key` at `line` (0: no line, e.g. a study built in code).
fn study_error(line: usize, key: &str, reason: &str) -> JpError {
    JpError::Parse { path: "<study>".into(), line, reason: format!("key '{key}': {reason}") }
}

fn parse_error(text: &str, offset: Option<usize>, reason: &str) -> JpError {
    // (an offset at the start of a line is on that line)
    let line = offset.map(|o| text.as_bytes()[..o.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1).unwrap_or(0);
    JpError::Parse { path: "<study>".into(), line, reason: reason.to_string() }
}
