//! A user's FE model on nodes, reduced to a jprom [`Model`] (docs/formulation.md §1, §12): sparse
//! symmetric `K` and `M` as an FE code exports them, which rows belong to which node and
//! direction, and the contacts, loads and outputs placed on node ids. [`FeModel::reduce`] keeps
//! the contact, loaded, output and extra nodes as Craig-Bampton boundary, adds fixed-interface
//! modes, and returns the same dense [`Model`] the rest of the library takes.
//!
//! Readers build an [`FeModel`]: [`FeModel::from_dof_map`] (Matrix Market with a jprom DoF
//! map), [`FeModel::from_calculix`] (`*MATRIX STORAGE` output).

use super::blade::CbModel;
use super::craig_bampton::{CbOptions, CraigBampton};
use crate::contact::{Contact, ContactLaw};
use crate::error::{JpError, Result};
use crate::io::calculix::CalculixModel;
use crate::io::dof_map::DofMap;
use crate::linalg::SparseMat;
use crate::model::{Damping, Excitation, HarmonicForce, Model};
use std::collections::{BTreeMap, HashMap};

/// Directions of a node's DoFs: translations x, y, z (0, 1, 2), rotations (3, 4, 5).
pub const DIRECTIONS: usize = 6;

/// One node of an FE model: which row of `K` and `M` each of its DoFs is.
#[derive(Clone, Debug, PartialEq)]
pub struct FeNode {
    /// The FE code's node id.
    pub id: i64,
    /// Coordinates, when the model has them (contact frames from an axis need them).
    pub coords: Option<[f64; 3]>,
    /// Row of direction `d` (0..6: x, y, z, rx, ry, rz), `None` if the node has no such DoF
    /// (not in the element's formulation, or fixed).
    pub dofs: [Option<usize>; DIRECTIONS],
}

impl FeNode {
    /// The rows of the translations x, y, z.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the node and the missing direction.
    pub fn translations(&self) -> Result<[usize; 3]> {
        let mut out = [0; 3];
        for (d, o) in out.iter_mut().enumerate() {
            *o = self.dofs[d].ok_or_else(|| {
                JpError::invalid(format!("node {}", self.id), format!("has no active {} translation (fixed, or not in the model)", ["x", "y", "z"][d]))
            })?;
        }
        Ok(out)
    }
}

impl FeNode {
    /// The cylindrical contact frame of this node about an axis ([`cylindrical_frame`] at its
    /// coordinates).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the node if it has no coordinates; as
    /// [`cylindrical_frame`].
    pub fn cylindrical_frame(&self, origin: [f64; 3], direction: [f64; 3], sense: RadialSense) -> Result<[[f64; 3]; 3]> {
        let p = self.coords.ok_or_else(|| {
            JpError::invalid(format!("node {}", self.id), "has no coordinates: a cylindrical contact frame needs them (give its normal instead)")
        })?;
        cylindrical_frame(p, origin, direction, sense).map_err(|e| match e {
            JpError::InvalidValue { what, reason } if what == "point" => JpError::invalid(format!("node {}", self.id), reason),
            other => other,
        })
    }
}

fn norm3(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A contact frame, rows `t1, t2, n` (unit, right-handed: `t2 = n x t1`), from the normal
/// `normal` (pointing into the ground; any nonzero length) and a first tangent `tangent`, of
/// which the part normal to `n` is taken; without one, `t1` is the global axis least aligned
/// with `n` (the first one on ties), made normal to `n`.
///
/// # Errors
/// [`JpError::InvalidValue`] with `what` = `"normal"` for a zero or non-finite normal,
/// `"tangent"` for a tangent that is zero, not finite or parallel to the normal.
pub fn contact_frame(normal: [f64; 3], tangent: Option<[f64; 3]>) -> Result<[[f64; 3]; 3]> {
    let nn = norm3(normal);
    if !(nn.is_finite() && nn > 0.0) {
        return Err(JpError::invalid("normal", format!("must be a finite nonzero vector, got {normal:?}")));
    }
    let n = normal.map(|x| x / nn);
    let t = match tangent {
        Some(t) => t,
        None => {
            let k = (0..3).min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs())).unwrap_or(0);
            let mut e = [0.0; 3];
            e[k] = 1.0;
            e
        }
    };
    let d = dot3(t, n);
    let t1 = [t[0] - d * n[0], t[1] - d * n[1], t[2] - d * n[2]];
    let nt = norm3(t1);
    if !(nt.is_finite() && nt > 1e-6 * norm3(t).max(f64::MIN_POSITIVE)) {
        return Err(JpError::invalid("tangent", format!("tangent {t:?} is zero, not finite or parallel to the normal")));
    }
    let t1 = t1.map(|x| x / nt);
    let t2 = [n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2], n[0] * t1[1] - n[1] * t1[0]];
    Ok([t1, t2, n])
}

/// Which way the normal of a cylindrical contact frame points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RadialSense {
    /// Away from the axis: the ground is outside (a casing around blade tips).
    Outward,
    /// Towards the axis: the ground is inside (a hub, a disk under a blade root).
    Inward,
}

/// The cylindrical contact frame at `point` about the axis through `origin` along `direction`:
/// `n = ± r / |r|`, with `r` the part of `point - origin` normal to the axis (`+` for
/// [`RadialSense::Outward`]), `t1` the unit axis direction, `t2 = n x t1` (circumferential).
///
/// # Errors
/// [`JpError::InvalidValue`]: `what` = `"axis"` for a zero or non-finite direction or a
/// non-finite origin, `"point"` for a non-finite point or one on the axis (closer to it than
/// 1e-9 times its distance from `origin`, or exactly on it), where the radial direction is
/// undefined.
pub fn cylindrical_frame(point: [f64; 3], origin: [f64; 3], direction: [f64; 3], sense: RadialSense) -> Result<[[f64; 3]; 3]> {
    let na = norm3(direction);
    if !(na.is_finite() && na > 0.0) || origin.iter().any(|x| !x.is_finite()) {
        return Err(JpError::invalid("axis", format!("needs a finite origin and a finite nonzero direction, got origin {origin:?}, direction {direction:?}")));
    }
    if point.iter().any(|x| !x.is_finite()) {
        return Err(JpError::invalid("point", format!("coordinates {point:?} are not finite")));
    }
    let a = direction.map(|x| x / na);
    let v = [point[0] - origin[0], point[1] - origin[1], point[2] - origin[2]];
    let h = dot3(v, a);
    let r = [v[0] - h * a[0], v[1] - h * a[1], v[2] - h * a[2]];
    let nr = norm3(r);
    if !(nr > 1e-9 * norm3(v)) {
        return Err(JpError::invalid("point", format!("at {point:?} lies on the axis: its radial direction is undefined")));
    }
    let s = if sense == RadialSense::Outward { 1.0 } else { -1.0 };
    let n = r.map(|x| s * x / nr);
    let t2 = [n[1] * a[2] - n[2] * a[1], n[2] * a[0] - n[0] * a[2], n[0] * a[1] - n[1] * a[0]];
    Ok([a, t2, n])
}

/// An FE model: `K`, `M` (`n x n`, full symmetric storage), optionally a viscous damping
/// matrix `C`, and its nodes.
#[derive(Clone, Debug)]
pub struct FeModel {
    pub stiffness: SparseMat,
    pub mass: SparseMat,
    /// Viscous damping `C` of the FE code ([`FeModel::set_damping`]); reduced with `K` and `M`
    /// and added to the reduced model's Rayleigh damping.
    damping: Option<SparseMat>,
    nodes: Vec<FeNode>,
    by_id: HashMap<i64, usize>,
    /// Named node sets (CalculiX `*NSET`s; names upper case, ids sorted) and the file they
    /// come from, for [`FeModel::node_set`].
    node_sets: BTreeMap<String, Vec<i64>>,
    node_sets_source: std::path::PathBuf,
}

/// A node-to-ground contact on a node (its three translations), in the local frame `frame`
/// (rows: tangent 1, tangent 2, normal).
#[derive(Clone, Debug, PartialEq)]
pub struct NodalContact {
    pub node: i64,
    pub frame: [[f64; 3]; 3],
    pub law: ContactLaw,
}

/// A force on a node's translations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodalForce {
    pub node: i64,
    pub force: [f64; 3],
}

/// What to keep and how to load the reduced model.
#[derive(Clone, Debug, Default)]
pub struct Reduction {
    /// Contacts, in the order the model's contacts will have.
    pub contacts: Vec<NodalContact>,
    /// Static load `f_E^0`.
    pub static_forces: Vec<NodalForce>,
    /// First-harmonic load `f_E^1` (cos part).
    pub harmonic_forces: Vec<NodalForce>,
    /// Output DoFs: `(node, direction 0..3)`.
    pub outputs: Vec<(i64, usize)>,
    /// Nodes kept as boundary besides those above.
    pub extra_nodes: Vec<i64>,
    /// Fixed-interface modes kept (a cap when `cb_cutoff_hz` is set).
    pub cb_modes: usize,
    /// Keep the fixed-interface modes up to this frequency (Hz), at most `cb_modes` of them.
    pub cb_cutoff_hz: Option<f64>,
}

impl FeModel {
    /// Checks `K`, `M` and the nodes against each other: square, same size, every row of at
    /// most one node and direction, node ids unique.
    ///
    /// # Errors
    /// [`JpError::BadSize`] for matrices of other sizes, [`JpError::InvalidValue`] for a row
    /// out of range or used twice, or a node id given twice.
    pub fn new(stiffness: SparseMat, mass: SparseMat, nodes: Vec<FeNode>) -> Result<Self> {
        let n = stiffness.nrows();
        if stiffness.ncols() != n {
            return Err(JpError::bad_size("stiffness (columns)", n, stiffness.ncols()));
        }
        if mass.nrows() != n || mass.ncols() != n {
            return Err(JpError::bad_size("mass (rows and columns)", n, if mass.nrows() != n { mass.nrows() } else { mass.ncols() }));
        }
        let mut owner: Vec<Option<(i64, usize)>> = vec![None; n];
        let mut by_id = HashMap::with_capacity(nodes.len());
        for (i, node) in nodes.iter().enumerate() {
            if by_id.insert(node.id, i).is_some() {
                return Err(JpError::invalid("nodes", format!("node {} is given twice", node.id)));
            }
            for (d, row) in node.dofs.iter().enumerate() {
                let Some(r) = *row else { continue };
                if r >= n {
                    return Err(JpError::invalid(format!("node {}", node.id), format!("row {r} of direction {d} is beyond the matrices' {n} rows")));
                }
                if let Some((other, od)) = owner[r] {
                    return Err(JpError::invalid(format!("node {}", node.id), format!("row {r} is also direction {od} of node {other}")));
                }
                owner[r] = Some((node.id, d));
            }
        }
        Ok(FeModel { stiffness, mass, damping: None, nodes, by_id, node_sets: BTreeMap::new(), node_sets_source: Default::default() })
    }

    /// From matrices and a jprom DoF map (three translations per node).
    ///
    /// # Errors
    /// [`JpError::BadSize`] if the map's `n_dof` is not the matrices' size; as [`FeModel::new`].
    pub fn from_dof_map(stiffness: SparseMat, mass: SparseMat, map: &DofMap) -> Result<Self> {
        if map.n_dof != stiffness.nrows() {
            return Err(JpError::bad_size("dof map n_dof", stiffness.nrows(), map.n_dof));
        }
        let nodes = map
            .nodes
            .iter()
            .map(|nd| {
                let mut dofs = [None; DIRECTIONS];
                for d in 0..3 {
                    dofs[d] = Some(nd.dofs[d]);
                }
                FeNode { id: nd.id, coords: Some(nd.coords), dofs }
            })
            .collect();
        Self::new(stiffness, mass, nodes)
    }

    /// From CalculiX's `*MATRIX STORAGE` output and deck ([`crate::io::calculix`]): a node per
    /// node with an active DoF, with the deck's coordinates.
    ///
    /// # Errors
    /// As [`FeModel::new`].
    pub fn from_calculix(ccx: &CalculixModel) -> Result<Self> {
        let mut index: HashMap<i64, usize> = HashMap::new();
        let mut nodes: Vec<FeNode> = Vec::new();
        for (row, &(id, direction)) in ccx.dofs.iter().enumerate() {
            let i = *index.entry(id).or_insert_with(|| {
                nodes.push(FeNode { id, coords: ccx.coords.get(&id).copied(), dofs: [None; DIRECTIONS] });
                nodes.len() - 1
            });
            let d = usize::from(direction).checked_sub(1).filter(|&d| d < DIRECTIONS).ok_or_else(|| {
                JpError::invalid(format!("node {id}"), format!("direction {direction} is not 1..=6"))
            })?;
            nodes[i].dofs[d] = Some(row);
        }
        let mut fe = Self::new(ccx.stiffness.clone(), ccx.mass.clone(), nodes)?;
        fe.node_sets = ccx.node_sets.clone();
        fe.node_sets_source = ccx.inp.clone();
        Ok(fe)
    }

    /// The node ids of node set `name` (case-insensitive; the CalculiX deck's `*NSET`s, none
    /// for a model from matrices), sorted.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the sets the model has if there is no such set.
    pub fn node_set(&self, name: &str) -> Result<&[i64]> {
        crate::io::calculix::node_set_of(&self.node_sets, name, &self.node_sets_source)
    }

    /// All node sets, upper-case names to sorted node ids.
    pub fn node_sets(&self) -> &BTreeMap<String, Vec<i64>> {
        &self.node_sets
    }

    /// Number of DoFs.
    pub fn n_dof(&self) -> usize {
        self.stiffness.nrows()
    }

    /// Sets the viscous damping matrix `C` (sparse, symmetric, full storage, the size of `K`).
    ///
    /// # Errors
    /// [`JpError::BadSize`] for another size, [`JpError::InvalidValue`] for a value that is not
    /// finite or a matrix that is not symmetric (to [`crate::model::SYMMETRY_TOLERANCE`]).
    pub fn set_damping(&mut self, c: SparseMat) -> Result<()> {
        let n = self.n_dof();
        if c.nrows() != n || c.ncols() != n {
            return Err(JpError::bad_size("damping matrix C (rows and columns)", n, if c.nrows() != n { c.nrows() } else { c.ncols() }));
        }
        crate::error::check_finite("damping matrix C", c.val())?;
        if let Some((i, j, a_ij, a_ji)) = crate::linalg::sparse::first_asymmetry(&c, crate::model::SYMMETRY_TOLERANCE) {
            return Err(JpError::invalid("damping matrix C", format!("is not symmetric: entry ({i}, {j}) = {a_ij:e} while ({j}, {i}) = {a_ji:e}")));
        }
        self.damping = Some(c);
        Ok(())
    }

    /// The `n_modes` lowest natural frequencies in Hz of the FE model on its own supports (no
    /// contact), by shift-invert Lanczos on one sparse Cholesky factor: of `K`, or, if `K` is
    /// singular (a free structure with rigid-body modes, reported as 0 Hz), of `K + s M` with a
    /// small shift `s` (`1e-6` times the mean `K_ii / M_ii`), whose eigenvalues are shifted back.
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] if neither factor exists; the eigensolver's errors.
    pub fn natural_frequencies_hz(&self, n_modes: usize) -> Result<Vec<f64>> {
        use crate::linalg::lanczos::{lowest_modes, SparseCholesky};
        let (chol, shift) = match SparseCholesky::factor(&self.stiffness, "FE stiffness K") {
            Ok(c) => (c, 0.0),
            Err(JpError::SingularMatrix { .. }) => {
                let diag = |a: &SparseMat| -> f64 { crate::linalg::sparse::sparse_triplets(a).iter().filter(|t| t.0 == t.1).map(|t| t.2).sum() };
                let shift = 1e-6 * diag(&self.stiffness) / diag(&self.mass);
                let mut t = crate::linalg::sparse::sparse_triplets(&self.stiffness);
                t.extend(crate::linalg::sparse::sparse_triplets(&self.mass).into_iter().map(|(i, j, v)| (i, j, shift * v)));
                let shifted = crate::linalg::sparse_from_triplets(self.n_dof(), self.n_dof(), t)?;
                (SparseCholesky::factor(&shifted, "shifted FE stiffness K + s M (a free structure)")?, shift)
            }
            Err(e) => return Err(e),
        };
        let modes = lowest_modes(&chol, &self.mass, n_modes)?;
        Ok(modes.eigenvalues.iter().map(|l| (l - shift).max(0.0).sqrt() / (2.0 * std::f64::consts::PI)).collect())
    }

    /// The model with DoFs fixed (clamped): `(node, direction 0..6)` pairs; their rows and
    /// columns of `K`, `M` (and `C`) are removed and the nodes lose those directions. For FE
    /// exports without supports (a free blade whose root is to be clamped).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming a node that is not in the model, a direction above 5 or
    /// one the node does not have (fixed twice, or not in its element), or a model left with no
    /// DoF.
    pub fn with_fixed(&self, fixed: &[(i64, usize)]) -> Result<FeModel> {
        let n = self.n_dof();
        let mut keep = vec![true; n];
        for &(id, d) in fixed {
            if d >= DIRECTIONS {
                return Err(JpError::invalid(format!("fixed DoF of node {id}"), format!("direction {d} is not 0..6 (x, y, z, rx, ry, rz)")));
            }
            let row = self.node(id)?.dofs[d].ok_or_else(|| JpError::invalid(format!("fixed DoF of node {id}"), format!("the node has no active direction {d} (fixed already, or not in its element)")))?;
            keep[row] = false;
        }
        let kept: Vec<usize> = (0..n).filter(|&r| keep[r]).collect();
        if kept.is_empty() {
            return Err(JpError::invalid("fixed DoFs", "every DoF of the model is fixed"));
        }
        let mut new_row = vec![usize::MAX; n];
        for (i, &r) in kept.iter().enumerate() {
            new_row[r] = i;
        }
        let sub = |a: &SparseMat| crate::linalg::sparse::sparse_submatrix(a, &new_row, kept.len(), &kept);
        let nodes = self
            .nodes
            .iter()
            .map(|nd| FeNode { dofs: nd.dofs.map(|r| r.and_then(|r| (new_row[r] != usize::MAX).then_some(new_row[r]))), ..nd.clone() })
            .collect();
        let mut out = FeModel::new(sub(&self.stiffness), sub(&self.mass), nodes)?;
        out.damping = self.damping.as_ref().map(sub);
        out.node_sets = self.node_sets.clone();
        out.node_sets_source = self.node_sets_source.clone();
        Ok(out)
    }

    /// The viscous damping matrix `C`, if set.
    pub fn damping(&self) -> Option<&SparseMat> {
        self.damping.as_ref()
    }

    /// The nodes, in the order given.
    pub fn nodes(&self) -> &[FeNode] {
        &self.nodes
    }

    /// The node with id `id`.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] if the model has no such node.
    pub fn node(&self, id: i64) -> Result<&FeNode> {
        self.by_id.get(&id).map(|&i| &self.nodes[i]).ok_or_else(|| JpError::invalid(format!("node {id}"), "is not a node of the FE model"))
    }

    /// Reduces the model by Craig-Bampton (docs/formulation.md §12): the boundary is the
    /// translations of the contact nodes (in `spec.contacts` order), then the loaded, output
    /// and extra nodes (each once), plus `spec.cb_modes` fixed-interface modes. Loads act on
    /// boundary DoFs, so the reduced loads are exact without the constraint modes, which are
    /// not kept (this is what lets thousands of contact DoFs fit in memory).
    ///
    /// # Errors
    /// A node that is not in the model or lacks a translation, a contact node given twice;
    /// Craig-Bampton's and [`Model::new`]'s errors.
    pub fn reduce(&self, spec: &Reduction, damping: Damping) -> Result<Model> {
        let boundary_nodes = self.kept_nodes(spec)?;
        let pos: HashMap<i64, usize> = boundary_nodes.iter().enumerate().map(|(p, &id)| (id, p)).collect();
        let mut boundary = Vec::with_capacity(3 * boundary_nodes.len());
        for &id in &boundary_nodes {
            boundary.extend(self.node(id)?.translations()?);
        }
        let options = CbOptions { n_modes: spec.cb_modes, keep_recovery: false, cutoff_hz: spec.cb_cutoff_hz };
        let cb = CraigBampton::reduce_with_damping(&self.stiffness, &self.mass, self.damping.as_ref(), &boundary, options)?;
        let n_red = cb.n_reduced();
        let place = |forces: &[NodalForce]| {
            let mut f = vec![0.0; n_red];
            for l in forces {
                let p = pos[&l.node];
                for a in 0..3 {
                    f[3 * p + a] += l.force[a];
                }
            }
            f
        };
        let model = CbModel {
            contacts: spec
                .contacts
                .iter()
                .map(|c| {
                    let p = pos[&c.node];
                    Contact::ground_3d([3 * p, 3 * p + 1, 3 * p + 2], c.frame, c.law.clone())
                })
                .collect(),
            output_dofs: spec.outputs.iter().map(|&(id, d)| 3 * pos[&id] + d).collect(),
            static_force: place(&spec.static_forces),
            harmonic_force: place(&spec.harmonic_forces),
            cb,
        };
        model.to_model(damping)
    }

    /// The nodes `spec` names, checked (in the model, with translations, a contact node once,
    /// output directions 0..3): the contact nodes in order, then the loaded, output and extra
    /// nodes, each once.
    fn kept_nodes(&self, spec: &Reduction) -> Result<Vec<i64>> {
        let mut nodes: Vec<i64> = Vec::new();
        for c in &spec.contacts {
            self.node(c.node)?.translations()?;
            if nodes.contains(&c.node) {
                return Err(JpError::invalid(format!("node {}", c.node), "is a contact node twice"));
            }
            nodes.push(c.node);
        }
        let others = spec.static_forces.iter().chain(&spec.harmonic_forces).map(|f| f.node);
        let others = others.chain(spec.outputs.iter().map(|o| o.0)).chain(spec.extra_nodes.iter().copied());
        for id in others {
            self.node(id)?.translations()?;
            if !nodes.contains(&id) {
                nodes.push(id);
            }
        }
        for &(id, d) in &spec.outputs {
            if d >= 3 {
                return Err(JpError::invalid(format!("output at node {id}"), format!("direction {d} is not a translation (0, 1, 2)")));
            }
        }
        Ok(nodes)
    }

    /// The model without reduction: every FE DoF kept, dense `M`, `K` (and the FE code's `C`),
    /// the contacts, loads and outputs of `spec` on the nodes' own DoFs (`cb_modes`,
    /// `cb_cutoff_hz` and `extra_nodes` do not apply). JP then runs on the FE model itself
    /// (docs/formulation.md §12, "JP without Craig-Bampton"), the reference for
    /// [`FeModel::reduce`]. Dense: for FE models up to a few thousand DoFs (`2 n^2` doubles,
    /// `3 n^2` with `C`, checked against the memory budget before anything is allocated).
    ///
    /// # Errors
    /// As [`FeModel::reduce`] for the nodes; [`JpError::TooLarge`] past the memory budget;
    /// [`Model::new`]'s errors.
    pub fn unreduced(&self, spec: &Reduction, damping: Damping) -> Result<Model> {
        self.kept_nodes(spec)?;
        let n = self.n_dof();
        let matrices = if self.damping.is_some() { 3u128 } else { 2 };
        crate::memory::check(&format!("the unreduced FE model ({n} DoFs, dense M, K{})", if matrices == 3 { ", C" } else { "" }), matrices * 8 * (n as u128).pow(2))?;
        let place = |forces: &[NodalForce]| -> Result<Vec<f64>> {
            let mut f = vec![0.0; n];
            for l in forces {
                for (a, d) in self.node(l.node)?.translations()?.into_iter().enumerate() {
                    f[d] += l.force[a];
                }
            }
            Ok(f)
        };
        let excitation = Excitation {
            static_force: place(&spec.static_forces)?,
            harmonics: vec![HarmonicForce { cos: place(&spec.harmonic_forces)?, sin: vec![0.0; n] }],
            dynamic_scale: 1.0,
        };
        let contacts = spec.contacts.iter().map(|c| Ok(Contact::ground_3d(self.node(c.node)?.translations()?, c.frame, c.law.clone()))).collect::<Result<Vec<_>>>()?;
        let outputs = spec.outputs.iter().map(|&(id, d)| Ok(self.node(id)?.translations()?[d])).collect::<Result<Vec<_>>>()?;
        let mut model = Model::new(self.mass.as_ref().to_dense(), self.stiffness.as_ref().to_dense(), damping, excitation, contacts, outputs)?;
        if let Some(c) = &self.damping {
            model.added_damping = Some(c.as_ref().to_dense());
            model.validate()?;
        }
        Ok(model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-14)
    }

    #[test]
    fn contact_frames_are_orthonormal_and_refuse_bad_vectors() {
        let f = contact_frame([0.0, 0.0, -2.0], Some([1.0, 0.0, 0.5])).unwrap();
        assert!(close(f[2], [0.0, 0.0, -1.0]) && close(f[0], [1.0, 0.0, 0.0]) && close(f[1], [0.0, -1.0, 0.0]), "{f:?}");
        // default tangent: the axis least aligned with n
        let f = contact_frame([1.0, 0.0, 0.0], None).unwrap();
        assert!(close(f[0], [0.0, 1.0, 0.0]), "{f:?}");
        assert!(matches!(contact_frame([0.0; 3], None), Err(JpError::InvalidValue { what, .. }) if what == "normal"));
        assert!(matches!(contact_frame([1.0, 0.0, 0.0], Some([-2.0, 0.0, 0.0])), Err(JpError::InvalidValue { what, .. }) if what == "tangent"));
    }

    #[test]
    fn cylindrical_frames_point_radially_with_the_axis_as_first_tangent() {
        // axis z through (1, 1, 0): a node at (1, 3, 7) is 2 out along +y
        let f = cylindrical_frame([1.0, 3.0, 7.0], [1.0, 1.0, 0.0], [0.0, 0.0, 5.0], RadialSense::Outward).unwrap();
        assert!(close(f[2], [0.0, 1.0, 0.0]) && close(f[0], [0.0, 0.0, 1.0]), "{f:?}");
        // right-handed: t2 = n x t1
        assert!(close(f[1], [1.0, 0.0, 0.0]), "{f:?}");
        let g = cylindrical_frame([1.0, 3.0, 7.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0], RadialSense::Inward).unwrap();
        assert!(close(g[2], [0.0, -1.0, 0.0]), "{g:?}");
        // off-axis direction: n is normal to the axis
        let h = cylindrical_frame([3.0, 4.0, 5.0], [0.0; 3], [1.0, 1.0, 0.0], RadialSense::Outward).unwrap();
        assert!(dot3(h[2], [1.0, 1.0, 0.0]).abs() < 1e-14 && (norm3(h[2]) - 1.0).abs() < 1e-14, "{h:?}");
        assert!(matches!(cylindrical_frame([0.0, 0.0, 3.0], [0.0; 3], [0.0, 0.0, 1.0], RadialSense::Outward), Err(JpError::InvalidValue { what, .. }) if what == "point"));
        assert!(matches!(cylindrical_frame([1.0, 0.0, 0.0], [0.0; 3], [0.0; 3], RadialSense::Outward), Err(JpError::InvalidValue { what, .. }) if what == "axis"));
    }

    #[test]
    fn a_node_without_coordinates_has_no_cylindrical_frame() {
        let node = FeNode { id: 42, coords: None, dofs: [Some(0), Some(1), Some(2), None, None, None] };
        let e = node.cylindrical_frame([0.0; 3], [0.0, 0.0, 1.0], RadialSense::Outward).unwrap_err().to_string();
        assert!(e.contains("node 42") && e.contains("no coordinates"), "{e}");
        let on_axis = FeNode { coords: Some([0.0, 0.0, 1.0]), ..node };
        let e = on_axis.cylindrical_frame([0.0; 3], [0.0, 0.0, 1.0], RadialSense::Outward).unwrap_err().to_string();
        assert!(e.contains("node 42") && e.contains("on the axis"), "{e}");
    }
}
