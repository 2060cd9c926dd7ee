//! A second solid FE model, unlike the built-in blade: a pre-twisted cantilever plate of linear
//! hexahedra, clamped at the root, whose tip nodes touch a casing with *radial* normals and are
//! held closed by a normal preload `n0` alone (no static load). It stands for the kind of model
//! users bring from their own FE codes (a blade with tip or interlock contacts), and it is
//! exported and read back through the Matrix Market path in the tests.
//!
//! Geometry (mm): the untwisted plate is `x in [-c/2, c/2]` (chord), `y in [-t/2, t/2]`
//! (thickness), `z in [0, L]` (span). Each cross-section is turned about the span axis by
//! `theta(z) = twist * z / L`. The root `z = 0` is clamped.
//!
//! Contacts: the tip nodes on the mid-thickness line (`n_chord + 1` of them), node to ground.
//! The engine axis is the line `y = 0, z = -hub_radius` along `x`; the normal of a tip node is the
//! radial direction from that axis through the node (outwards, into the casing), so every node
//! has its own normal; `t1` is the axial direction `x`, `t2 = n x t1`.
//!
//! Loads: a first-harmonic force at the leading-edge node (`x = -c/2` before twist,
//! mid-thickness) at 60 % span, along the global `y` (flap). Outputs: that node and the tip
//! trailing-edge node (`x, y, z` each).
//!
//! DoFs: node `i` (root nodes excluded) owns `3 i + {0, 1, 2}`.

use super::nodal::{FeModel, FeNode, NodalContact, NodalForce, Reduction};
use super::hex8::{self, Material};
use crate::linalg::sparse::{sparse_from_triplets, SparseMat};
use crate::contact::ContactLaw;
use crate::error::{JpError, Result};

/// Parameters of the twisted plate.
#[derive(Clone, Debug, PartialEq)]
pub struct PlateParams {
    /// Span `L`, chord `c`, thickness `t` (mm).
    pub length: f64,
    pub chord: f64,
    pub thickness: f64,
    /// Twist of the tip section relative to the root (radians).
    pub twist: f64,
    /// Distance from the engine axis to the root (mm): sets the radial contact normals.
    pub hub_radius: f64,
    /// Elements along span, chord and thickness (`n_thickness` even, so that mid-thickness is a
    /// grid line).
    pub n_span: usize,
    pub n_chord: usize,
    pub n_thickness: usize,
    /// Material (default steel in mm, tonne, s).
    pub material: Material,
    /// Contact law per tip node (`n0` is the preload that closes it).
    pub mu: f64,
    pub kt: f64,
    pub kn: f64,
    pub n0: f64,
    /// First-harmonic force at the leading-edge node (N).
    pub force: f64,
}

impl Default for PlateParams {
    fn default() -> Self {
        PlateParams {
            length: 120.0,
            chord: 40.0,
            thickness: 3.0,
            twist: 30f64.to_radians(),
            hub_radius: 250.0,
            n_span: 24,
            n_chord: 15,
            n_thickness: 2,
            material: Material::STEEL_MM_TONNE,
            mu: 0.3,
            kt: 2.0,
            kn: 20.0,
            n0: 1.0,
            force: 1.0,
        }
    }
}

impl PlateParams {
    /// Checks ranges.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the bad parameter.
    pub fn validate(&self) -> Result<()> {
        for (what, v) in [("length", self.length), ("chord", self.chord), ("thickness", self.thickness), ("hub_radius", self.hub_radius)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(JpError::invalid(format!("plate.{what}"), format!("must be finite and > 0, got {v}")));
            }
        }
        if !self.twist.is_finite() {
            return Err(JpError::invalid("plate.twist", "must be finite"));
        }
        if self.n_span == 0 || self.n_chord == 0 || self.n_thickness < 2 || self.n_thickness % 2 != 0 {
            return Err(JpError::invalid("plate mesh", "need n_span, n_chord >= 1 and an even n_thickness >= 2"));
        }
        self.material.validate()?;
        self.contact_law().validate("plate contact")
    }

    /// The contact law of each tip node.
    pub fn contact_law(&self) -> ContactLaw {
        ContactLaw::Friction3D { kt1: self.kt, kt2: self.kt, kn: self.kn, mu: self.mu, n0: self.n0 }
    }
}

/// One tip contact node.
#[derive(Clone, Debug, PartialEq)]
pub struct PlateContact {
    pub node: usize,
    pub dofs: [usize; 3],
    /// Rows `t1, t2, n` (`n` radial, into the casing).
    pub frame: [[f64; 3]; 3],
}

/// The assembled plate.
#[derive(Clone, Debug)]
pub struct PlateFe {
    pub params: PlateParams,
    /// Stiffness and consistent mass (sparse, full storage), root clamped.
    pub stiffness: SparseMat,
    pub mass: SparseMat,
    /// Node coordinates (twisted).
    pub coords: Vec<[f64; 3]>,
    pub contacts: Vec<PlateContact>,
    /// The forced leading-edge node and the tip trailing-edge node.
    pub load_node: usize,
    pub tip_node: usize,
    /// First-harmonic load (cos part).
    pub harmonic_force: Vec<f64>,
}

impl PlateFe {
    /// Meshes and assembles the plate (see the module doc).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] for bad parameters.
    pub fn build(p: &PlateParams) -> Result<PlateFe> {
        p.validate()?;
        let (nx, ny, nz) = (p.n_chord + 1, p.n_thickness + 1, p.n_span + 1);
        let grid = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
        let position = |i: usize, j: usize, k: usize| -> [f64; 3] {
            let x = -p.chord / 2.0 + p.chord * i as f64 / p.n_chord as f64;
            let y = -p.thickness / 2.0 + p.thickness * j as f64 / p.n_thickness as f64;
            let z = p.length * k as f64 / p.n_span as f64;
            let th = p.twist * z / p.length;
            [x * th.cos() - y * th.sin(), x * th.sin() + y * th.cos(), z]
        };
        // node numbering: root layer k = 0 has no DoF
        let node_of = |i: usize, j: usize, k: usize| -> Option<usize> { (k > 0).then(|| grid(i, j, k) - nx * ny) };
        let mut coords = Vec::with_capacity(nx * ny * (nz - 1));
        for k in 1..nz {
            for j in 0..ny {
                for i in 0..nx {
                    coords.push(position(i, j, k));
                }
            }
        }
        let n_dof = 3 * coords.len();
        let mut kt = Vec::new();
        let mut mt = Vec::new();
        for k in 0..nz - 1 {
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    let mut xyz = [[0.0; 3]; 8];
                    let mut dofs = [usize::MAX; 24];
                    for (a, s) in hex8::NODE_SIGNS.iter().enumerate() {
                        let (ii, jj, kk) = (i + (s[0] > 0.0) as usize, j + (s[1] > 0.0) as usize, k + (s[2] > 0.0) as usize);
                        xyz[a] = position(ii, jj, kk);
                        if let Some(nd) = node_of(ii, jj, kk) {
                            for c in 0..3 {
                                dofs[3 * a + c] = 3 * nd + c;
                            }
                        }
                    }
                    let ke = hex8::stiffness(&xyz, &p.material)?;
                    let me = hex8::mass(&xyz, &p.material)?;
                    for r in 0..24 {
                        if dofs[r] == usize::MAX {
                            continue;
                        }
                        for s in 0..24 {
                            if dofs[s] != usize::MAX {
                                kt.push((dofs[r], dofs[s], ke[r][s]));
                                mt.push((dofs[r], dofs[s], me[r][s]));
                            }
                        }
                    }
                }
            }
        }
        let stiffness = sparse_from_triplets(n_dof, n_dof, kt)?;
        let mass = sparse_from_triplets(n_dof, n_dof, mt)?;
        let j_mid = p.n_thickness / 2;
        let contacts = (0..nx)
            .map(|i| {
                let node = node_of(i, j_mid, nz - 1).expect("tip node");
                let x = coords[node];
                let r = [0.0, x[1], x[2] + p.hub_radius];
                let rn = (r[1] * r[1] + r[2] * r[2]).sqrt();
                let n = [0.0, r[1] / rn, r[2] / rn];
                let t1 = [1.0, 0.0, 0.0];
                let t2 = [n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2], n[0] * t1[1] - n[1] * t1[0]];
                PlateContact { node, dofs: [3 * node, 3 * node + 1, 3 * node + 2], frame: [t1, t2, n] }
            })
            .collect();
        let k_load = ((0.6 * p.n_span as f64).round() as usize).clamp(1, p.n_span);
        let load_node = node_of(0, j_mid, k_load).expect("load node");
        let tip_node = node_of(nx - 1, p.n_thickness, nz - 1).expect("tip node");
        let mut harmonic_force = vec![0.0; n_dof];
        harmonic_force[3 * load_node + 1] = p.force;
        Ok(PlateFe { params: p.clone(), stiffness, mass, coords, contacts, load_node, tip_node, harmonic_force })
    }

    /// Number of DoFs.
    pub fn n_dof(&self) -> usize {
        self.stiffness.nrows()
    }
    /// Node id of mesh node `node` in [`PlateFe::fe_model`] (as an FE code would number it).
    pub fn node_id(node: usize) -> i64 {
        7000 + node as i64
    }

    /// The plate as a user's FE model ([`FeModel`], every node with its x, y, z rows) and what
    /// to keep of it: the 16 tip contacts, the leading-edge load, `y` outputs at the load and
    /// tip nodes, `cb_modes` fixed-interface modes.
    ///
    /// # Errors
    /// As [`FeModel::new`].
    pub fn fe_model(&self, cb_modes: usize) -> Result<(FeModel, Reduction)> {
        let nodes = (0..self.coords.len())
            .map(|i| FeNode { id: Self::node_id(i), coords: Some(self.coords[i]), dofs: [Some(3 * i), Some(3 * i + 1), Some(3 * i + 2), None, None, None] })
            .collect();
        let fe = FeModel::new(self.stiffness.clone(), self.mass.clone(), nodes)?;
        let law = self.params.contact_law();
        let spec = Reduction {
            contacts: self.contacts.iter().map(|c| NodalContact { node: Self::node_id(c.node), frame: c.frame, law: law.clone() }).collect(),
            harmonic_forces: vec![NodalForce { node: Self::node_id(self.load_node), force: [0.0, self.params.force, 0.0] }],
            outputs: vec![(Self::node_id(self.load_node), 1), (Self::node_id(self.tip_node), 1)],
            cb_modes,
            ..Reduction::default()
        };
        Ok((fe, spec))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_radial_and_orthonormal() {
        let fe = PlateFe::build(&PlateParams::default()).unwrap();
        assert_eq!(fe.contacts.len(), 16);
        let mut normals = Vec::new();
        for c in &fe.contacts {
            let f = c.frame;
            for a in 0..3 {
                for b in 0..3 {
                    let d: f64 = (0..3).map(|q| f[a][q] * f[b][q]).sum();
                    assert!((d - if a == b { 1.0 } else { 0.0 }).abs() < 1e-12);
                }
            }
            normals.push(f[2]);
        }
        // the tip is twisted, so the radial normals differ from node to node
        let spread = normals.iter().map(|n| n[1]).fold(f64::NEG_INFINITY, f64::max) - normals.iter().map(|n| n[1]).fold(f64::INFINITY, f64::min);
        assert!(spread > 1e-3, "normals all alike ({spread})");
        assert_eq!(fe.n_dof(), 3 * 16 * 3 * 24);
    }
}
