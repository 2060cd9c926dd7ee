//! Two shroud-coupled blades: a node-pair contact case built from the built-in blade
//! ([`super::blade`]), e.g. two neighbouring blades of a bladed disk or a linear cascade.
//!
//! Blade B is blade A translated by one pitch `p = (c, -(2Y - w), 0)` (chord `c`, shroud
//! half-width `Y`, patch width `w`). The blade's Z-shroud has its contact patches on opposite
//! chord ends of the two arms (patch 0 on `x = -c/2`, `y in [Y - w, Y]`; patch 1 on `x = +c/2`,
//! `y in [-Y, -Y + w]`), so with this pitch blade A's patch 1 and blade B's patch 0 cover the
//! same square of the plane `x = c/2`, node for node, and the two shrouds touch there and
//! nowhere else. The contacts are:
//! - [`PairSite::GroundA`]: blade A's patch 0, node to ground (the blade before A);
//! - [`PairSite::Interface`]: blade A's patch 1 against blade B's patch 0, node pairs
//!   `w = R (x_a - x_b)` with `a` on blade A, `b` on blade B and `R` blade A's patch-1 frame
//!   (rows `t1 = +y`, `t2 = +z`, `n = +x`: `v > 0` when A's arm moves into B's);
//! - [`PairSite::GroundB`]: blade B's patch 1, node to ground (the blade after B).
//!
//! Blade B's own patch-0 frame is `(+y, -z, -x)`: the same `t1`, opposite normal, so a pair
//! taken from B's side would see `w' = R_B (x_b - x_a) = (-u1, u2, v)`, the same normal gap and
//! the same law; using A's frame loses nothing. The outer patches are not paired with each other
//! (that would be a two-blade cyclic sector, whose coupling is not a plain translation): they
//! stand for the neighbours beyond the pair, held as ground, as in the single-blade benchmark.
//!
//! The blades are coupled only through the interface contacts, so the structure is the
//! block-diagonal assembly of two copies of the blade's Craig-Bampton model (each reduced on its
//! own contact and output DoFs): reduced DoFs `0..n` are blade A's, `n..2n` blade B's, each in
//! [`super::CbModel`] order (contact DoFs, output DoFs, modal coordinates).
//!
//! Loads: each blade carries its pre-twist couple `f_E^0` (normal forces on its contact nodes,
//! [`super::blade`]); at the interface the two couples press the arms against each other. Both
//! are scaled together so that the mean normal force over the three interfaces, in the linear
//! stuck state, is [`super::BladeParams::preload_per_patch`]. The first-harmonic load is blade
//! A's `f_E^1` on blade A and, on blade B, `r f_E^1 cos(omega t - phi)` (`r` =
//! [`PairParams::forcing_ratio`], `phi` = [`PairParams::phase_lag`]): a travelling-wave
//! (engine-order) excitation lags by the inter-blade phase angle from blade to blade; `r = 0`
//! excites blade A only.
//!
//! Modes (default blade, CB(50), stuck springs): 1431 Hz, an in-phase edgewise-flap mode of
//! both blades whose chordwise motion is normal to the shroud faces (it opens and closes the
//! contacts: 20 of the 27 contacts separate at its resonance at `alpha_ST / 10`, and the
//! continuation needs 1000-2000 points); 2057 Hz, the anti-phase flap mode, the
//! pair's counterpart of the single blade's stuck first bending (2165 Hz), which slides the
//! interface tangentially; 2186 Hz, in-phase edgewise. The default forcing (anti-phase,
//! `phi = pi`) drives the 2057 Hz mode. Free contacts: two free blades, every frequency twice.
//!
//! Outputs: blade A's 9 output nodes, then blade B's (`x, y, z` each: 54 output DoFs).

use super::blade::{BladeFe, CbModel};
use crate::linalg::eigen::dense_generalized_eigenvalues;
use super::BladeParams;
use crate::contact::Contact;
use crate::error::{check_finite, JpError, Result};
use crate::model::{Damping, Excitation, HarmonicForce, Model};
use faer::Mat;

/// Options of the two-blade model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairParams {
    /// Amplitude of blade B's first-harmonic load relative to blade A's (`r >= 0`; 0: blade A
    /// only).
    pub forcing_ratio: f64,
    /// Phase lag `phi` (rad) of blade B's load: `f_B(t) = r f_E^1 cos(omega t - phi)`.
    pub phase_lag: f64,
}

impl Default for PairParams {
    /// Both blades forced alike in anti-phase (inter-blade phase angle `pi`, engine order
    /// `N / 2` of an `N`-blade disk), which drives the pair's anti-phase flap mode and slides
    /// the interface (module doc).
    fn default() -> Self {
        PairParams { forcing_ratio: 1.0, phase_lag: std::f64::consts::PI }
    }
}

impl PairParams {
    /// Checks the values.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] for a negative or non-finite ratio or a non-finite phase.
    pub fn validate(&self) -> Result<()> {
        if !(self.forcing_ratio.is_finite() && self.forcing_ratio >= 0.0) {
            return Err(JpError::invalid("pair.forcing_ratio", format!("must be finite and >= 0, got {}", self.forcing_ratio)));
        }
        check_finite("pair.phase_lag", &[self.phase_lag])
    }
}

/// Where a contact of the two-blade model sits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PairSite {
    /// Blade A's patch 0 against ground.
    GroundA,
    /// Blade A's patch 1 against blade B's patch 0 (node pair).
    Interface,
    /// Blade B's patch 1 against ground.
    GroundB,
}

impl PairSite {
    /// Index `0, 1, 2` (in the order of the variants), for per-site arrays.
    pub fn index(self) -> usize {
        match self {
            PairSite::GroundA => 0,
            PairSite::Interface => 1,
            PairSite::GroundB => 2,
        }
    }
}

/// Two shroud-coupled copies of the built-in blade (module doc), in reduced coordinates.
#[derive(Clone, Debug)]
pub struct BladePair {
    /// Options it was built with.
    pub params: PairParams,
    /// Translation from blade A to blade B (mm).
    pub pitch: [f64; 3],
    /// Reduced DoFs per blade (blade B's start at this offset).
    pub n_blade: usize,
    /// Block-diagonal reduced stiffness (`2 n_blade` square).
    pub stiffness: Mat<f64>,
    /// Block-diagonal reduced mass.
    pub mass: Mat<f64>,
    /// Contacts: blade A's patch 0 to ground, the interface pairs (in blade A's patch-1 order),
    /// blade B's patch 1 to ground.
    pub contacts: Vec<Contact>,
    /// Site of each contact.
    pub sites: Vec<PairSite>,
    /// FE node numbers `(node on A, node on B)` of each interface pair (the same FE mesh for
    /// both blades; B's node sits at `coords[node] + pitch`).
    pub interface_nodes: Vec<(usize, usize)>,
    /// Largest distance between the two nodes of an interface pair (mm), zero up to round-off.
    pub interface_mismatch: f64,
    /// Output DoFs: blade A's 27, then blade B's 27.
    pub output_dofs: Vec<usize>,
    /// Static load (both pre-twists, scaled as in the module doc).
    pub static_force: Vec<f64>,
    /// First-harmonic load, cos part.
    pub harmonic_cos: Vec<f64>,
    /// First-harmonic load, sin part.
    pub harmonic_sin: Vec<f64>,
    /// Normal force per site (indexed by [`PairSite::index`]) in the linear stuck state under
    /// the static load (N).
    pub stuck_site_forces: [f64; 3],
    /// Largest tangential-to-normal force ratio over the contacts in that state.
    pub stuck_max_friction_ratio: f64,
}

impl BladePair {
    /// Builds and reduces the blade (`n_modes` fixed-interface modes), then the pair.
    ///
    /// # Errors
    /// As [`super::BuiltinBlade::build`], [`BladeFe::reduce`] and [`BladePair::build`].
    pub fn from_params(blade: &BladeParams, n_modes: usize, params: &PairParams) -> Result<Self> {
        let fe = super::BuiltinBlade::build(blade)?;
        let cb = fe.reduce(n_modes)?;
        Self::build(&fe, &cb, params)
    }

    /// Assembles two copies of `cb` (the reduction of `fe` by [`BladeFe::reduce`]) into the
    /// shroud-coupled pair of the module doc.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] for bad `params`, a `cb` that is not `fe`'s reduction, or a
    /// geometry whose facing patches do not match node for node (not possible for a blade of
    /// [`super::BuiltinBlade::build`]); [`JpError::SingularMatrix`] should the stuck static
    /// problem be singular.
    pub fn build(fe: &BladeFe, cb: &CbModel, params: &PairParams) -> Result<Self> {
        params.validate()?;
        if cb.cb.boundary_dofs != fe.boundary_dofs() || cb.contacts.len() != fe.contacts.len() {
            return Err(JpError::invalid("blade pair", "the Craig-Bampton model is not this blade's reduction"));
        }
        let bp = &fe.params;
        let pitch = [bp.chord, -(2.0 * bp.shroud_half_width - bp.patch_width), 0.0];
        let n = cb.cb.n_reduced();
        let tol = 1e-9 * bp.chord.max(bp.shroud_half_width);

        // Pair blade A's patch-1 nodes with blade B's patch-0 nodes by position.
        let mut interface_nodes = Vec::new();
        let mut interface_contacts = Vec::new(); // (contact on A, contact on B)
        let mut mismatch = 0.0f64;
        let mut used = vec![false; fe.contacts.len()];
        for (ka, ca) in fe.contacts.iter().enumerate().filter(|(_, c)| c.patch == 1) {
            let xa = fe.coords[ca.node];
            let (kb, d) = fe
                .contacts
                .iter()
                .enumerate()
                .filter(|(_, c)| c.patch == 0)
                .map(|(kb, cbn)| {
                    let xb = fe.coords[cbn.node];
                    (kb, (0..3).map(|q| (xb[q] + pitch[q] - xa[q]).powi(2)).sum::<f64>().sqrt())
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .ok_or_else(|| JpError::invalid("blade pair", "blade has no patch-0 contact node"))?;
            if d > tol || used[kb] {
                return Err(JpError::invalid(
                    "blade pair geometry",
                    format!("patch-1 node {} has no unique facing patch-0 node (distance {d:.3e} mm)", ca.node),
                ));
            }
            used[kb] = true;
            mismatch = mismatch.max(d);
            // Facing frames: same t1, opposite normals.
            let fb = fe.contacts[kb].frame;
            let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
            if (dot(ca.frame[0], fb[0]) - 1.0).abs() > 1e-12 || (dot(ca.frame[2], fb[2]) + 1.0).abs() > 1e-12 {
                return Err(JpError::invalid("blade pair geometry", "facing patches' frames are not opposite"));
            }
            interface_nodes.push((ca.node, fe.contacts[kb].node));
            interface_contacts.push((ka, kb));
        }
        if interface_contacts.is_empty() || used.iter().filter(|&&u| u).count() != fe.contacts.iter().filter(|c| c.patch == 0).count() {
            return Err(JpError::invalid("blade pair geometry", "the facing patches do not have the same nodes"));
        }

        // Contacts on the reduced DoFs (contact k of the blade model owns 3k..3k+3).
        let dofs = |blade: usize, k: usize| -> [usize; 3] {
            let d = &cb.contacts[k].dofs_a;
            [blade * n + d[0], blade * n + d[1], blade * n + d[2]]
        };
        let law = fe.contact_law.clone();
        let mut contacts = Vec::new();
        let mut sites = Vec::new();
        for (k, c) in fe.contacts.iter().enumerate().filter(|(_, c)| c.patch == 0) {
            contacts.push(Contact::ground_3d(dofs(0, k), c.frame, law.clone()));
            sites.push(PairSite::GroundA);
        }
        for &(ka, kb) in &interface_contacts {
            contacts.push(Contact::pair_3d(dofs(0, ka), dofs(1, kb), fe.contacts[ka].frame, law.clone()));
            sites.push(PairSite::Interface);
        }
        for (k, c) in fe.contacts.iter().enumerate().filter(|(_, c)| c.patch == 1) {
            contacts.push(Contact::ground_3d(dofs(1, k), c.frame, law.clone()));
            sites.push(PairSite::GroundB);
        }

        let block_diag = |a: &Mat<f64>| {
            Mat::from_fn(2 * n, 2 * n, |i, j| if i / n == j / n { a[(i % n, j % n)] } else { 0.0 })
        };
        let (r, phi) = (params.forcing_ratio, params.phase_lag);
        let f1 = &cb.harmonic_force;
        let mut pair = BladePair {
            params: *params,
            pitch,
            n_blade: n,
            stiffness: block_diag(&cb.cb.stiffness),
            mass: block_diag(&cb.cb.mass),
            contacts,
            sites,
            interface_nodes,
            interface_mismatch: mismatch,
            output_dofs: cb.output_dofs.iter().copied().chain(cb.output_dofs.iter().map(|d| n + d)).collect(),
            static_force: cb.static_force.iter().chain(&cb.static_force).copied().collect(),
            harmonic_cos: f1.iter().copied().chain(f1.iter().map(|v| r * phi.cos() * v)).collect(),
            harmonic_sin: std::iter::repeat(0.0).take(n).chain(f1.iter().map(|v| r * phi.sin() * v)).collect(),
            stuck_site_forces: [0.0; 3],
            stuck_max_friction_ratio: 0.0,
        };

        // Scale the pre-twists to the target mean normal force in the linear stuck state.
        let u = pair.stuck_static_displacement()?;
        let (forces, _) = pair.stuck_contact_forces(&u);
        if forces.iter().any(|&f| f.is_nan() || f <= 0.0) {
            return Err(JpError::invalid(
                "blade pair geometry",
                format!("pre-twists do not press every interface (normal forces {:.3e}, {:.3e}, {:.3e})", forces[0], forces[1], forces[2]),
            ));
        }
        let s = bp.preload_per_patch / (forces.iter().sum::<f64>() / 3.0);
        pair.static_force.iter_mut().for_each(|v| *v *= s);
        let us: Vec<f64> = u.iter().map(|v| v * s).collect();
        let (forces, ratio) = pair.stuck_contact_forces(&us);
        pair.stuck_site_forces = forces;
        pair.stuck_max_friction_ratio = ratio;
        Ok(pair)
    }

    /// Number of reduced DoFs (`2 n_blade`).
    pub fn n_dof(&self) -> usize {
        self.stiffness.nrows()
    }

    /// Stiffness plus the stuck contact springs `R^T diag(kt1, kt2, kn) R` (between `a` and
    /// `b` for the interface pairs).
    pub fn stuck_stiffness(&self) -> Mat<f64> {
        let mut k = self.stiffness.clone();
        for c in &self.contacts {
            let kd = c.law.stuck_stiffness();
            for a in 0..3 {
                for b in 0..3 {
                    let v: f64 = (0..3).map(|q| c.frame[q][a] * kd[q] * c.frame[q][b]).sum();
                    k[(c.dofs_a[a], c.dofs_a[b])] += v;
                    if let Some(db) = &c.dofs_b {
                        k[(db[a], db[b])] += v;
                        k[(c.dofs_a[a], db[b])] -= v;
                        k[(db[a], c.dofs_a[b])] -= v;
                    }
                }
            }
        }
        k
    }

    /// Linear stuck static displacement under the static load, `(K + K_c)^-1 f_E^0`.
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] if the stuck stiffness is singular.
    pub fn stuck_static_displacement(&self) -> Result<Vec<f64>> {
        let k = self.stuck_stiffness();
        let f = Mat::from_fn(self.n_dof(), 1, |i, _| self.static_force[i]);
        let u = crate::linalg::DenseLu::new(&k).solve(&f);
        let u: Vec<f64> = (0..self.n_dof()).map(|i| u[(i, 0)]).collect();
        if u.iter().any(|v| !v.is_finite()) {
            return Err(JpError::singular("stuck blade-pair stiffness"));
        }
        Ok(u)
    }

    /// Normal force per site (indexed by [`PairSite::index`]) and the largest `|T| / N` of the
    /// linear stuck contact springs at displacement `u` (`F = diag(k) R (x_a - x_b)`).
    pub fn stuck_contact_forces(&self, u: &[f64]) -> ([f64; 3], f64) {
        let mut n = [0.0; 3];
        let mut ratio = 0.0f64;
        for (c, site) in self.contacts.iter().zip(&self.sites) {
            let kd = c.law.stuck_stiffness();
            let rel = |a: usize| u[c.dofs_a[a]] - c.dofs_b.as_ref().map_or(0.0, |b| u[b[a]]);
            let f: Vec<f64> = (0..3).map(|q| kd[q] * (0..3).map(|a| c.frame[q][a] * rel(a)).sum::<f64>()).collect();
            n[site.index()] += f[2];
            ratio = ratio.max(f[0].hypot(f[1]) / f[2].abs().max(f64::MIN_POSITIVE));
        }
        (n, ratio)
    }

    /// Natural frequencies (Hz, ascending) with free contacts (`stuck = false`; the pair is
    /// then two free blades, each frequency twice) or with the stuck contact springs.
    ///
    /// # Errors
    /// [`JpError::Eigen`] if the dense solve fails.
    pub fn natural_frequencies_hz(&self, stuck: bool) -> Result<Vec<f64>> {
        let k = if stuck { self.stuck_stiffness() } else { self.stiffness.clone() };
        let lam = dense_generalized_eigenvalues(&k, &self.mass)?;
        Ok(lam.iter().map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)).collect())
    }

    /// A jprom [`Model`] of the pair with the given damping (see [`CbModel::to_model`]).
    ///
    /// # Errors
    /// As [`Model::new`].
    pub fn to_model(&self, damping: Damping) -> Result<Model> {
        let excitation = Excitation {
            static_force: self.static_force.clone(),
            harmonics: vec![HarmonicForce { cos: self.harmonic_cos.clone(), sin: self.harmonic_sin.clone() }],
            dynamic_scale: 1.0,
        };
        Model::new(self.mass.clone(), self.stiffness.clone(), damping, excitation, self.contacts.clone(), self.output_dofs.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::BuiltinBlade;

    fn coarse() -> BladeParams {
        BladeParams { n_span: 9, n_chord: 2, n_thickness: 1, n_shroud_gap: 1, ..BladeParams::default() }
    }

    #[test]
    fn pair_geometry_loads_and_validation() {
        let fe = BuiltinBlade::build(&coarse()).unwrap();
        let cb = fe.reduce(10).unwrap();
        let params = PairParams { forcing_ratio: 0.5, phase_lag: 1.0 };
        let pair = BladePair::build(&fe, &cb, &params).unwrap();
        let n = cb.cb.n_reduced();
        assert_eq!(pair.n_dof(), 2 * n);
        // 9 + 9 + 9 contacts; the interface nodes coincide after the pitch translation.
        let count = |s: PairSite| pair.sites.iter().filter(|&&x| x == s).count();
        assert_eq!([count(PairSite::GroundA), count(PairSite::Interface), count(PairSite::GroundB)], [9, 9, 9]);
        assert_eq!(pair.interface_nodes.len(), 9);
        assert!(pair.interface_mismatch < 1e-12, "{}", pair.interface_mismatch);
        for &(a, b) in &pair.interface_nodes {
            let (xa, xb) = (fe.coords[a], fe.coords[b]);
            for q in 0..3 {
                assert!((xb[q] + pair.pitch[q] - xa[q]).abs() < 1e-12);
            }
            assert!((xa[0] - fe.params.chord / 2.0).abs() < 1e-12, "interface on the face x = c/2");
        }
        for (c, site) in pair.contacts.iter().zip(&pair.sites) {
            let on = |d: usize| d / n; // blade of a reduced DoF
            match site {
                PairSite::GroundA => assert!(c.dofs_b.is_none() && c.dofs_a.iter().all(|&d| on(d) == 0)),
                PairSite::GroundB => assert!(c.dofs_b.is_none() && c.dofs_a.iter().all(|&d| on(d) == 1)),
                PairSite::Interface => {
                    // a on blade A, b on blade B, frame of A's patch 1: normal +x into blade B.
                    let b = c.dofs_b.as_ref().unwrap();
                    assert!(c.dofs_a.iter().all(|&d| on(d) == 0) && b.iter().all(|&d| on(d) == 1));
                    assert_eq!(c.frame, [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]);
                }
            }
        }
        let model = pair.to_model(Damping::default()).unwrap();
        assert_eq!(model.output_dofs.len(), 54);
        // Preload: mean 300 N over the three interfaces, all pressed, friction holds.
        let f = pair.stuck_site_forces;
        assert!((f.iter().sum::<f64>() / 3.0 - 300.0).abs() < 1e-9, "{f:?}");
        assert!(f.iter().all(|&x| x > 100.0), "{f:?}");
        assert!(pair.stuck_max_friction_ratio < 0.4);
        // Identical blades: the two grounded patches carry the same force (the pair is
        // symmetric under the half turn about the interface's span line).
        assert!((f[0] - f[2]).abs() < 1e-6 * f[0], "{f:?}");
        // Forcing: blade B gets r f cos(omega t - phi).
        for i in 0..n {
            let fa = cb.harmonic_force[i];
            assert_eq!(pair.harmonic_cos[i], fa);
            assert_eq!(pair.harmonic_sin[i], 0.0);
            assert!((pair.harmonic_cos[n + i] - 0.5 * 1f64.cos() * fa).abs() <= 1e-15 * fa.abs());
            assert!((pair.harmonic_sin[n + i] - 0.5 * 1f64.sin() * fa).abs() <= 1e-15 * fa.abs());
        }
        // Free contacts: two identical free blades, each frequency twice.
        let free = pair.natural_frequencies_hz(false).unwrap();
        for k in 0..4 {
            assert!((free[2 * k] - free[2 * k + 1]).abs() < 1e-6 * free[2 * k], "{:?}", &free[..8]);
        }
        // The stuck interface transmits force: the pair is stiffer than two free blades, and
        // softer than two blades with every patch grounded (the single blade).
        let stuck = pair.natural_frequencies_hz(true).unwrap();
        let single = cb.natural_frequencies_hz(true).unwrap();
        assert!(stuck[0] > free[0] && stuck[0] < single[0], "{} {} {}", free[0], stuck[0], single[0]);

        // Validation.
        for bad in [PairParams { forcing_ratio: -1.0, ..params }, PairParams { phase_lag: f64::NAN, ..params }] {
            assert!(matches!(BladePair::build(&fe, &cb, &bad), Err(JpError::InvalidValue { .. })));
        }
        let other = BuiltinBlade::build(&BladeParams { refinement: 2, ..coarse() }).unwrap();
        assert!(matches!(BladePair::build(&other, &cb, &params), Err(JpError::InvalidValue { .. })));
    }
}
