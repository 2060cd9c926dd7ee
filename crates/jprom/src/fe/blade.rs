//! The built-in shrouded-blade benchmark (docs/formulation.md §12): a cantilever blade of linear
//! hexahedra with a tip shroud whose two contact faces press against ground.
//!
//! Geometry (mm): the blade is the box `x in [-c/2, c/2]` (chord), `y in [-t/2, t/2]`
//! (thickness), `z in [0, L]` (span), clamped at `z = 0` (root DoFs removed). The shroud is the
//! box `x in [-c/2, c/2]`, `y in [-Y, Y]`, `z in [L, L + h]` on top of it. Like a Z-shroud, its
//! two contact faces are on opposite chord ends of the two arms:
//! - patch 0 on the face `x = -c/2`, `y in [Y - w, Y]`, normal (into the ground) `-x`;
//! - patch 1 on the face `x = +c/2`, `y in [-Y, -Y + w]`, normal `+x`.
//!
//! Each patch is a `(2r+1) x (2r+1)` grid of contact nodes (`r` = [`BladeParams::refinement`]:
//! 18 contact nodes at `r = 1`, 242 at `r = 5`, 2,178 at `r = 16`). Refinement only subdivides
//! the shroud (its height and the two patch bands in `y`), never the blade. Per-node contact
//! stiffnesses are the paper's values times `9 / nodes_per_patch`, so each patch keeps the
//! paper's total stiffness. Local frames have rows `t1 = +y` (the flap-bending direction),
//! `t2 = n x t1` (so `t1 x t2 = n`, right-handed: `-z` on patch 0, `+z` on patch 1) and `n` as above.
//!
//! Loads: the static pre-twist `f_E^0` is a couple about the span axis that presses each shroud
//! arm onto its ground face: equal forces along the patch normal `n` on every contact node (so
//! that it loads boundary DoFs only and the Craig-Bampton static response stays exact; a
//! rigid-rotation torque on the shroud would also slide the patches, `|T| / N > mu`, unless the
//! shroud arms are long compared with the chord, as they are here). The scale is chosen so that, in the linear stuck state (contact springs, `n0 = 0`), the
//! normal force on each patch is [`BladeParams::preload_per_patch`] on average (default 300 N;
//! the two patches differ by the blade's asymmetry under twist; both are reported in
//! [`BladeFe::stuck_patch_forces`]). The first-harmonic load `f_E^1` is a force
//! [`BladeParams::forcing_per_node`] along `+y` (flap bending) on each of the 9 output nodes,
//! which sit on the blade surface `y = +t/2` at mid-chord, at `z = L k / 9`, `k = 1..9`.
//!
//! DoFs: node `i` (root nodes excluded) owns DoFs `3 i + {0, 1, 2}` (`x, y, z`).

use super::craig_bampton::{CbOptions, CraigBampton};
use crate::linalg::eigen::dense_generalized_eigenvalues;
use crate::linalg::lanczos::{lowest_modes, SparseCholesky};
use super::hex8::{self, Material};
use crate::linalg::sparse::{sparse_from_triplets, sparse_triplets, SparseMat};
use crate::contact::{Contact, ContactLaw};
use crate::error::{JpError, Result};
use crate::model::{Damping, Excitation, HarmonicForce, Model};

/// Parameters of the built-in blade. `Default` is the benchmark of docs/formulation.md §12.
#[derive(Clone, Debug, PartialEq)]
pub struct BladeParams {
    /// Span `L` (mm).
    pub length: f64,
    /// Chord `c` (mm).
    pub chord: f64,
    /// Thickness `t` (mm).
    pub thickness: f64,
    /// Shroud height `h` along the span (mm).
    pub shroud_height: f64,
    /// Shroud half-width `Y` (mm), measured along `y` from the blade's mid-plane.
    pub shroud_half_width: f64,
    /// Width `w` (along `y`) of each contact patch (mm).
    pub patch_width: f64,
    /// Elements along the span (a multiple of 9 puts the output nodes exactly at `L k / 9`).
    pub n_span: usize,
    /// Elements along the chord (even, so that mid-chord is a grid line).
    pub n_chord: usize,
    /// Elements through the thickness.
    pub n_thickness: usize,
    /// Elements (along `y`) between the blade surface and each contact band of the shroud.
    pub n_shroud_gap: usize,
    /// Contact refinement `r >= 1`: `2r` elements along each side of a patch.
    pub refinement: usize,
    /// Material (default steel in mm, tonne, s).
    pub material: Material,
    /// Friction coefficient.
    pub mu: f64,
    /// Tangential stiffness `kt1` per node of a 9-node patch (N/mm).
    pub kt1: f64,
    /// Tangential stiffness `kt2` per node of a 9-node patch (N/mm).
    pub kt2: f64,
    /// Normal stiffness `kn` per node of a 9-node patch (N/mm).
    pub kn: f64,
    /// Target normal preload per patch from `f_E^0` in the linear stuck state (N).
    pub preload_per_patch: f64,
    /// First-harmonic force per output node along `+y` (N).
    pub forcing_per_node: f64,
}

impl Default for BladeParams {
    fn default() -> Self {
        BladeParams {
            length: 105.0,
            chord: 12.0,
            thickness: 5.0,
            shroud_height: 4.0,
            shroud_half_width: 20.0,
            patch_width: 3.0,
            n_span: 54,
            n_chord: 16,
            n_thickness: 6,
            n_shroud_gap: 5,
            refinement: 1,
            material: Material::STEEL_MM_TONNE,
            mu: 0.4,
            kt1: 2.0126e4,
            kt2: 2.0059e4,
            kn: 2.34152e4,
            preload_per_patch: 300.0,
            forcing_per_node: 1.0,
        }
    }
}

impl BladeParams {
    /// Checks dimensions and counts.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the first bad parameter.
    pub fn validate(&self) -> Result<()> {
        let pos = |name: &str, v: f64| -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(JpError::invalid(format!("blade.{name}"), format!("must be finite and > 0, got {v}")))
            }
        };
        pos("length", self.length)?;
        pos("chord", self.chord)?;
        pos("thickness", self.thickness)?;
        pos("shroud_height", self.shroud_height)?;
        pos("patch_width", self.patch_width)?;
        pos("mu", self.mu)?;
        pos("kt1", self.kt1)?;
        pos("kt2", self.kt2)?;
        pos("kn", self.kn)?;
        pos("preload_per_patch", self.preload_per_patch)?;
        if !self.forcing_per_node.is_finite() {
            return Err(JpError::invalid("blade.forcing_per_node", "must be finite"));
        }
        if !(self.shroud_half_width - self.patch_width > self.thickness / 2.0) {
            return Err(JpError::invalid(
                "blade.shroud_half_width",
                "must exceed thickness / 2 + patch_width (the patches sit on the shroud arms)",
            ));
        }
        for (name, v, min) in [
            ("n_span", self.n_span, 1),
            ("n_chord", self.n_chord, 2),
            ("n_thickness", self.n_thickness, 1),
            ("n_shroud_gap", self.n_shroud_gap, 1),
            ("refinement", self.refinement, 1),
        ] {
            if v < min {
                return Err(JpError::invalid(format!("blade.{name}"), format!("must be >= {min}, got {v}")));
            }
        }
        if self.n_chord % 2 != 0 {
            return Err(JpError::invalid("blade.n_chord", "must be even (mid-chord output nodes)"));
        }
        self.material.validate()
    }

    /// Contact nodes per patch, `(2r + 1)^2`.
    pub fn nodes_per_patch(&self) -> usize {
        (2 * self.refinement + 1).pow(2)
    }

    /// Per-node contact law: the paper's per-node values scaled by `9 / nodes_per_patch`, `n0 = 0`.
    pub fn contact_law(&self) -> ContactLaw {
        let s = 9.0 / self.nodes_per_patch() as f64;
        ContactLaw::Friction3D { kt1: self.kt1 * s, kt2: self.kt2 * s, kn: self.kn * s, mu: self.mu, n0: 0.0 }
    }
}

/// Generator of the built-in blade (see the module doc).
pub struct BuiltinBlade;

/// One contact node of the FE model.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactNode {
    /// Node index (DoFs `3 node + {0,1,2}`).
    pub node: usize,
    /// Global DoFs `x, y, z`.
    pub dofs: [usize; 3],
    /// Local frame, rows `t1, t2, n` (`n` into the ground).
    pub frame: [[f64; 3]; 3],
    /// Patch index (0 or 1).
    pub patch: usize,
}

/// The assembled sparse FE model of the blade.
#[derive(Clone, Debug)]
pub struct BladeFe {
    /// Parameters it was built from.
    pub params: BladeParams,
    /// Stiffness `K` (sparse, symmetric, full storage), root clamped.
    pub stiffness: SparseMat,
    /// Consistent mass `M` (sparse, symmetric, full storage).
    pub mass: SparseMat,
    /// Node coordinates (mm); node `i` owns DoFs `3 i .. 3 i + 3`.
    pub coords: Vec<[f64; 3]>,
    /// Number of hexahedra.
    pub n_elements: usize,
    /// Contact nodes, patch 0 first.
    pub contacts: Vec<ContactNode>,
    /// Per-node contact law (scaled to the refinement).
    pub contact_law: ContactLaw,
    /// The 9 output/forcing nodes, root to tip.
    pub output_nodes: Vec<usize>,
    /// Their DoFs (`x, y, z` of each node: 27).
    pub output_dofs: Vec<usize>,
    /// Static pre-twist load `f_E^0`.
    pub static_force: Vec<f64>,
    /// First-harmonic load `f_E^1` (cos part; the sin part is zero).
    pub harmonic_force: Vec<f64>,
    /// Normal force on each patch in the linear stuck state under `f_E^0` (N).
    pub stuck_patch_forces: [f64; 2],
    /// Largest tangential-to-normal force ratio over the contact nodes in that state.
    pub stuck_max_friction_ratio: f64,
    /// Tangential-to-normal ratio of each patch's resultant force in that state.
    pub stuck_patch_friction_ratio: [f64; 2],
}

fn push_range(v: &mut Vec<f64>, a: f64, b: f64, n: usize) {
    for k in 1..=n {
        v.push(a + (b - a) * k as f64 / n as f64);
    }
}

impl BuiltinBlade {
    /// Meshes and assembles the blade, places contacts, outputs and loads.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] for bad parameters; [`JpError::SingularMatrix`] should the
    /// stuck static problem be singular (it is not for valid parameters).
    pub fn build(params: &BladeParams) -> Result<BladeFe> {
        params.validate()?;
        let p = params;
        let (c, t, l, h, yw, w) = (p.chord, p.thickness, p.length, p.shroud_height, p.shroud_half_width, p.patch_width);
        let r2 = 2 * p.refinement;
        // Tensor grid lines.
        let mut xs = vec![-c / 2.0];
        push_range(&mut xs, -c / 2.0, c / 2.0, p.n_chord);
        let mut ys = vec![-yw];
        push_range(&mut ys, -yw, -yw + w, r2);
        push_range(&mut ys, -yw + w, -t / 2.0, p.n_shroud_gap);
        push_range(&mut ys, -t / 2.0, t / 2.0, p.n_thickness);
        push_range(&mut ys, t / 2.0, yw - w, p.n_shroud_gap);
        push_range(&mut ys, yw - w, yw, r2);
        let mut zs = vec![0.0];
        push_range(&mut zs, 0.0, l, p.n_span);
        push_range(&mut zs, l, l + h, r2);
        let (nx, ny, nz) = (xs.len(), ys.len(), zs.len());
        let j_blade = (r2 + p.n_shroud_gap, r2 + p.n_shroud_gap + p.n_thickness); // y cells of the blade
        let grid = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
        let cell_exists = |j: usize, k: usize| k >= p.n_span || (j >= j_blade.0 && j < j_blade.1);

        // Nodes used by some cell, root (k = 0) excluded.
        let mut used = vec![false; nx * ny * nz];
        for k in 0..nz - 1 {
            for j in 0..ny - 1 {
                if !cell_exists(j, k) {
                    continue;
                }
                for i in 0..nx - 1 {
                    for s in hex8::NODE_SIGNS {
                        let (a, b, cc) = (i + (s[0] > 0.0) as usize, j + (s[1] > 0.0) as usize, k + (s[2] > 0.0) as usize);
                        used[grid(a, b, cc)] = true;
                    }
                }
            }
        }
        let mut node_of = vec![usize::MAX; nx * ny * nz];
        let mut coords = Vec::new();
        for k in 1..nz {
            for j in 0..ny {
                for i in 0..nx {
                    if used[grid(i, j, k)] {
                        node_of[grid(i, j, k)] = coords.len();
                        coords.push([xs[i], ys[j], zs[k]]);
                    }
                }
            }
        }
        let n_dof = 3 * coords.len();

        // Assembly (root nodes have no DoF: their rows/columns are dropped = clamped).
        let mat = p.material;
        let mut kt = Vec::new();
        let mut mt = Vec::new();
        let mut n_elements = 0;
        for k in 0..nz - 1 {
            for j in 0..ny - 1 {
                if !cell_exists(j, k) {
                    continue;
                }
                for i in 0..nx - 1 {
                    let mut xyz = [[0.0; 3]; 8];
                    let mut dofs = [usize::MAX; 24];
                    for (a, s) in hex8::NODE_SIGNS.iter().enumerate() {
                        let (ii, jj, kk) = (i + (s[0] > 0.0) as usize, j + (s[1] > 0.0) as usize, k + (s[2] > 0.0) as usize);
                        xyz[a] = [xs[ii], ys[jj], zs[kk]];
                        let nd = node_of[grid(ii, jj, kk)];
                        if nd != usize::MAX {
                            for comp in 0..3 {
                                dofs[3 * a + comp] = 3 * nd + comp;
                            }
                        }
                    }
                    let ke = hex8::stiffness(&xyz, &mat)?;
                    let me = hex8::mass(&xyz, &mat)?;
                    for r in 0..24 {
                        if dofs[r] == usize::MAX {
                            continue;
                        }
                        for s in 0..24 {
                            if dofs[s] == usize::MAX {
                                continue;
                            }
                            kt.push((dofs[r], dofs[s], ke[r][s]));
                            mt.push((dofs[r], dofs[s], me[r][s]));
                        }
                    }
                    n_elements += 1;
                }
            }
        }
        let stiffness = sparse_from_triplets(n_dof, n_dof, kt)?;
        let mass = sparse_from_triplets(n_dof, n_dof, mt)?;

        // Contact patches.
        let k_shroud = p.n_span; // z index of the shroud's bottom face
        let mut contacts = Vec::new();
        let frames = [
            [[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]],
            [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
        ];
        for patch in 0..2 {
            let (i, j0) = if patch == 0 { (0, ny - 1 - r2) } else { (nx - 1, 0) };
            for kk in k_shroud..=k_shroud + r2 {
                for jj in j0..=j0 + r2 {
                    let nd = node_of[grid(i, jj, kk)];
                    contacts.push(ContactNode { node: nd, dofs: [3 * nd, 3 * nd + 1, 3 * nd + 2], frame: frames[patch], patch });
                }
            }
        }
        // Output nodes: mid-chord, y = +t/2, z = L m / 9.
        let i_mid = p.n_chord / 2;
        let j_top = j_blade.1;
        let mut output_nodes = Vec::new();
        for m in 1..=9usize {
            let kk = ((m as f64) * p.n_span as f64 / 9.0).round().max(1.0) as usize;
            output_nodes.push(node_of[grid(i_mid, j_top, kk)]);
        }
        let mut dedup = output_nodes.clone();
        dedup.sort_unstable();
        dedup.dedup();
        if dedup.len() != 9 {
            return Err(JpError::invalid("blade.n_span", "too few span elements for 9 distinct output nodes"));
        }
        let output_dofs: Vec<usize> = output_nodes.iter().flat_map(|&nd| [3 * nd, 3 * nd + 1, 3 * nd + 2]).collect();
        let mut harmonic_force = vec![0.0; n_dof];
        for &nd in &output_nodes {
            harmonic_force[3 * nd + 1] = p.forcing_per_node;
        }
        // Unit pressing load: a force along the patch normal (into the ground) on every
        // contact node, so that f_E^0 acts on boundary DoFs only.
        let mut twist = vec![0.0; n_dof];
        for cn in &contacts {
            for comp in 0..3 {
                twist[cn.dofs[comp]] += cn.frame[2][comp];
            }
        }
        let mut fe = BladeFe {
            params: p.clone(),
            stiffness,
            mass,
            coords,
            n_elements,
            contacts,
            contact_law: p.contact_law(),
            output_nodes,
            output_dofs,
            static_force: twist,
            harmonic_force,
            stuck_patch_forces: [0.0; 2],
            stuck_max_friction_ratio: 0.0,
            stuck_patch_friction_ratio: [0.0; 2],
        };
        // Scale the twist so that the mean stuck normal force per patch is the target.
        let k_stuck = fe.stuck_stiffness()?;
        let chol = SparseCholesky::factor(&k_stuck, "stuck blade stiffness")?;
        let mut u = faer::Mat::from_fn(n_dof, 1, |i, _| fe.static_force[i]);
        chol.solve_in_place(u.as_mut());
        let u: Vec<f64> = (0..n_dof).map(|i| u[(i, 0)]).collect();
        let (forces, _) = fe.stuck_contact_forces(&u);
        let mean = 0.5 * (forces[0] + forces[1]);
        if !(forces[0] > 0.0 && forces[1] > 0.0) {
            return Err(JpError::invalid(
                "blade geometry",
                format!("pre-twist does not press both patches (normal forces {:.3e}, {:.3e})", forces[0], forces[1]),
            ));
        }
        let s = p.preload_per_patch / mean;
        for v in fe.static_force.iter_mut() {
            *v *= s;
        }
        let us: Vec<f64> = u.iter().map(|v| v * s).collect();
        let (forces, ratio) = fe.stuck_contact_forces(&us);
        fe.stuck_patch_forces = forces;
        fe.stuck_max_friction_ratio = ratio;
        fe.stuck_patch_friction_ratio = fe.stuck_patch_resultant_ratio(&us);
        Ok(fe)
    }
}

impl BladeFe {
    /// Number of DoFs.
    pub fn n_dof(&self) -> usize {
        self.stiffness.nrows()
    }

    /// Contact-spring stiffness `sum R^T diag(kt1, kt2, kn) R` over the contact nodes (sparse).
    ///
    /// # Errors
    /// Never for a model built by [`BuiltinBlade::build`].
    pub fn contact_stiffness(&self) -> Result<SparseMat> {
        let kd = self.contact_law.stuck_stiffness();
        let mut tr = Vec::with_capacity(9 * self.contacts.len());
        for cn in &self.contacts {
            for a in 0..3 {
                for b in 0..3 {
                    let v: f64 = (0..3).map(|q| cn.frame[q][a] * kd[q] * cn.frame[q][b]).sum();
                    tr.push((cn.dofs[a], cn.dofs[b], v));
                }
            }
        }
        sparse_from_triplets(self.n_dof(), self.n_dof(), tr)
    }

    /// `K` plus the stuck contact springs.
    ///
    /// # Errors
    /// Never for a model built by [`BuiltinBlade::build`].
    pub fn stuck_stiffness(&self) -> Result<SparseMat> {
        let mut tr = sparse_triplets(&self.stiffness);
        tr.extend(sparse_triplets(&self.contact_stiffness()?));
        sparse_from_triplets(self.n_dof(), self.n_dof(), tr)
    }

    /// Normal force per patch and the largest `|T| / N` of the linear stuck contact springs
    /// at displacement `u` (spring force `F = diag(k) R u`).
    pub fn stuck_contact_forces(&self, u: &[f64]) -> ([f64; 2], f64) {
        let kd = self.contact_law.stuck_stiffness();
        let mut n = [0.0; 2];
        let mut ratio = 0.0f64;
        for cn in &self.contacts {
            let w: Vec<f64> = (0..3).map(|q| (0..3).map(|a| cn.frame[q][a] * u[cn.dofs[a]]).sum::<f64>()).collect();
            let f: Vec<f64> = (0..3).map(|q| kd[q] * w[q]).collect();
            n[cn.patch] += f[2];
            ratio = ratio.max(f[0].hypot(f[1]) / f[2].abs().max(f64::MIN_POSITIVE));
        }
        (n, ratio)
    }

    /// Tangential-to-normal ratio of each patch's resultant spring force at displacement `u`.
    pub fn stuck_patch_resultant_ratio(&self, u: &[f64]) -> [f64; 2] {
        let kd = self.contact_law.stuck_stiffness();
        let mut f = [[0.0f64; 3]; 2];
        for cn in &self.contacts {
            for q in 0..3 {
                let w: f64 = (0..3).map(|a| cn.frame[q][a] * u[cn.dofs[a]]).sum();
                f[cn.patch][q] += kd[q] * w;
            }
        }
        [f[0][0].hypot(f[0][1]) / f[0][2], f[1][0].hypot(f[1][1]) / f[1][2]]
    }

    /// Boundary DoFs of the Craig-Bampton reduction: the contact nodes' DoFs (3 each, in
    /// [`BladeFe::contacts`] order), then the output DoFs.
    pub fn boundary_dofs(&self) -> Vec<usize> {
        let mut b: Vec<usize> = self.contacts.iter().flat_map(|c| c.dofs).collect();
        b.extend(&self.output_dofs);
        b
    }

    /// Lowest natural frequencies (Hz) of the full sparse model, free contacts (`stuck = false`)
    /// or with the stuck contact springs, by sparse shift-invert Lanczos.
    ///
    /// # Errors
    /// As [`lowest_modes`].
    pub fn natural_frequencies_hz(&self, n_modes: usize, stuck: bool) -> Result<Vec<f64>> {
        let k = if stuck { self.stuck_stiffness()? } else { self.stiffness.clone() };
        let chol = SparseCholesky::factor(&k, "blade stiffness")?;
        let e = lowest_modes(&chol, &self.mass, n_modes)?;
        Ok(e.eigenvalues.iter().map(|l| l.sqrt() / (2.0 * std::f64::consts::PI)).collect())
    }

    /// The FE model itself as a jprom [`Model`], without reduction: dense `M` and `K` of all
    /// `n` DoFs, the contacts on the contact nodes' FE DoFs, the outputs on the output nodes'
    /// DoFs, the full load vectors. JP then runs directly on the FE model (docs/formulation.md
    /// §12, "JP without Craig-Bampton"); [`BladeFe::reduce`] and [`CbModel::to_model`] give the
    /// same structure through Craig-Bampton. Dense: for FE models up to a few thousand DoFs
    /// (`2 n^2` doubles, checked against the memory budget before anything is allocated).
    ///
    /// # Errors
    /// [`JpError::TooLarge`] past the memory budget; as [`Model::new`].
    pub fn to_full_model(&self, damping: Damping) -> Result<Model> {
        let n = self.n_dof();
        crate::memory::check(&format!("the dense FE model of the blade ({n} DoFs, M and K)"), 16u128.saturating_mul((n as u128).pow(2)))?;
        let excitation = Excitation {
            static_force: self.static_force.clone(),
            harmonics: vec![HarmonicForce { cos: self.harmonic_force.clone(), sin: vec![0.0; n] }],
            dynamic_scale: 1.0,
        };
        let contacts = self.contacts.iter().map(|c| Contact::ground_3d(c.dofs, c.frame, self.contact_law.clone())).collect();
        Model::new(self.mass.as_ref().to_dense(), self.stiffness.as_ref().to_dense(), damping, excitation, contacts, self.output_dofs.clone())
    }

    /// Craig-Bampton reduction keeping the contact and output DoFs and `n_modes` interior modes.
    ///
    /// # Errors
    /// As [`CraigBampton::reduce`].
    pub fn reduce(&self, n_modes: usize) -> Result<CbModel> {
        self.reduce_with(CbOptions { n_modes, keep_recovery: true, cutoff_hz: None })
    }

    /// [`BladeFe::reduce`] with explicit options.
    ///
    /// # Errors
    /// As [`CraigBampton::reduce`].
    pub fn reduce_with(&self, options: CbOptions) -> Result<CbModel> {
        let boundary = self.boundary_dofs();
        let cb = CraigBampton::reduce(&self.stiffness, &self.mass, &boundary, options)?;
        // Loads act on boundary DoFs only, so T^T f is exact without the constraint modes.
        let reduce_boundary_load = |f: &[f64]| -> Result<Vec<f64>> {
            let mut out: Vec<f64> = boundary.iter().map(|&d| f[d]).collect();
            let mut covered = vec![false; f.len()];
            for &d in &boundary {
                covered[d] = true;
            }
            if f.iter().zip(&covered).any(|(v, c)| *v != 0.0 && !c) {
                return cb.reduce_force(f);
            }
            out.extend(std::iter::repeat(0.0).take(cb.modal_eigenvalues.len()));
            Ok(out)
        };
        let static_force = reduce_boundary_load(&self.static_force)?;
        let harmonic_force = reduce_boundary_load(&self.harmonic_force)?;
        let contacts = self
            .contacts
            .iter()
            .enumerate()
            .map(|(k, c)| Contact::ground_3d([3 * k, 3 * k + 1, 3 * k + 2], c.frame, self.contact_law.clone()))
            .collect();
        let nc = 3 * self.contacts.len();
        Ok(CbModel {
            output_dofs: (nc..nc + self.output_dofs.len()).collect(),
            cb,
            contacts,
            static_force,
            harmonic_force,
        })
    }
}

/// A Craig-Bampton reduced structure with its contacts, outputs and loads in reduced
/// coordinates (boundary DoFs first, then modal coordinates).
#[derive(Clone, Debug)]
pub struct CbModel {
    /// The reduction (matrices, modes, recovery).
    pub cb: CraigBampton,
    /// Node-to-ground contacts on reduced DoF indices.
    pub contacts: Vec<Contact>,
    /// Output DoFs (reduced indices).
    pub output_dofs: Vec<usize>,
    /// Reduced static load `T^T f_E^0`.
    pub static_force: Vec<f64>,
    /// Reduced first-harmonic load `T^T f_E^1` (cos part).
    pub harmonic_force: Vec<f64>,
}

impl CbModel {
    /// Reduced stiffness plus the stuck contact springs `R^T diag(kt1, kt2, kn) R`.
    pub fn stuck_stiffness(&self) -> faer::Mat<f64> {
        let mut k = self.cb.stiffness.clone();
        for c in &self.contacts {
            let kd = c.law.stuck_stiffness();
            for a in 0..3 {
                for b in 0..3 {
                    let v: f64 = (0..3).map(|q| c.frame[q][a] * kd[q] * c.frame[q][b]).sum();
                    k[(c.dofs_a[a], c.dofs_a[b])] += v;
                }
            }
        }
        k
    }

    /// Natural frequencies (Hz, ascending) of the reduced model with free contacts
    /// (`stuck = false`) or with the stuck contact springs (dense solve).
    ///
    /// # Errors
    /// [`JpError::Eigen`] if the dense solve fails.
    pub fn natural_frequencies_hz(&self, stuck: bool) -> Result<Vec<f64>> {
        let k = if stuck { self.stuck_stiffness() } else { self.cb.stiffness.clone() };
        let lam = dense_generalized_eigenvalues(&k, &self.cb.mass)?;
        Ok(lam.iter().map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)).collect())
    }

    /// A normal jprom [`Model`]: dense reduced `M`, `K`, the contacts, output DoFs and the
    /// excitation (`f_E^0`, first harmonic `f_E^1` as cos part). For a modal damping ratio
    /// `zeta` at angular frequency `omega`, pass `Damping::from_modal_ratio(zeta, omega)`
    /// (e.g. with `omega` the stuck first-bending frequency from
    /// [`CbModel::natural_frequencies_hz`]).
    ///
    /// # Errors
    /// As [`Model::new`].
    pub fn to_model(&self, damping: Damping) -> Result<Model> {
        let n = self.cb.n_reduced();
        let excitation = Excitation {
            static_force: self.static_force.clone(),
            harmonics: vec![HarmonicForce { cos: self.harmonic_force.clone(), sin: vec![0.0; n] }],
            dynamic_scale: 1.0,
        };
        let mut model = Model::new(
            self.cb.mass.clone(),
            self.cb.stiffness.clone(),
            damping,
            excitation,
            self.contacts.clone(),
            self.output_dofs.clone(),
        )?;
        if let Some(c) = &self.cb.damping {
            model.added_damping = Some(c.clone());
            model.validate()?;
        }
        Ok(model)
    }
}
