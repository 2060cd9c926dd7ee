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
use crate::model::{Damping, Model};
use std::collections::HashMap;

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

/// An FE model: `K`, `M` (`n x n`, full symmetric storage) and its nodes.
#[derive(Clone, Debug)]
pub struct FeModel {
    pub stiffness: SparseMat,
    pub mass: SparseMat,
    nodes: Vec<FeNode>,
    by_id: HashMap<i64, usize>,
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
    /// Fixed-interface modes kept.
    pub cb_modes: usize,
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
        Ok(FeModel { stiffness, mass, nodes, by_id })
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
        Self::new(ccx.stiffness.clone(), ccx.mass.clone(), nodes)
    }

    /// Number of DoFs.
    pub fn n_dof(&self) -> usize {
        self.stiffness.nrows()
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
        let mut boundary_nodes: Vec<i64> = Vec::new();
        for c in &spec.contacts {
            self.node(c.node)?.translations()?;
            if boundary_nodes.contains(&c.node) {
                return Err(JpError::invalid(format!("node {}", c.node), "is a contact node twice"));
            }
            boundary_nodes.push(c.node);
        }
        let others = spec.static_forces.iter().chain(&spec.harmonic_forces).map(|f| f.node);
        let others = others.chain(spec.outputs.iter().map(|o| o.0)).chain(spec.extra_nodes.iter().copied());
        for id in others {
            self.node(id)?.translations()?;
            if !boundary_nodes.contains(&id) {
                boundary_nodes.push(id);
            }
        }
        for &(id, d) in &spec.outputs {
            if d >= 3 {
                return Err(JpError::invalid(format!("output at node {id}"), format!("direction {d} is not a translation (0, 1, 2)")));
            }
        }
        let pos: HashMap<i64, usize> = boundary_nodes.iter().enumerate().map(|(p, &id)| (id, p)).collect();
        let mut boundary = Vec::with_capacity(3 * boundary_nodes.len());
        for &id in &boundary_nodes {
            boundary.extend(self.node(id)?.translations()?);
        }
        let cb = CraigBampton::reduce(&self.stiffness, &self.mass, &boundary, CbOptions { n_modes: spec.cb_modes, keep_recovery: false })?;
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
}
