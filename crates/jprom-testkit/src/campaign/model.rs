//! The campaign's models: a meshed cantilever ([`super::mesh`]) with contacts over a surface,
//! along a tip or between two bodies, closed by preload, open with a gap, or both, reduced by
//! Craig-Bampton to a jprom [`Model`], with its band and the forcing scale its levels are
//! measured against.

use super::mesh::{cross, dot, unit, Body, EndShape, Mesh};
use jprom::contact::{Contact, ContactLaw};
use jprom::fe::hex8::Material;
use jprom::fe::{FeModel, FeNode, NodalContact, NodalForce, Reduction};
use jprom::jp::prediction::static_solution;
use jprom::level::{stuck_limit, LevelReference};
use jprom::model::{ContactCoordinates, Damping, Model};
use rand::rngs::StdRng;
use rand::Rng;

/// Where the contacts are.
#[derive(Clone, Debug, PartialEq)]
pub enum Site {
    /// The end face's nodes over `fraction` of the chord (on the `x > 0` facet of a mitre)
    /// pressed against a rigid wall: one normal for the patch, stiffnesses from the nodes'
    /// areas.
    EndPatch { fraction: f64 },
    /// The tip's mid-thickness nodes against a casing, each with its own radial normal from
    /// an engine axis `hub_radius` below the root.
    TipLine { hub_radius: f64 },
    /// Node pairs between the first body's face `eta = 1/2` and a second body beside it, over
    /// the last `layers` element layers of the span; the second body's thickness is `ratio`
    /// times the first's, its density `density_ratio` times.
    NodePairs { layers: usize, ratio: f64, density_ratio: f64 },
}

/// How the contacts are closed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Closure {
    /// A normal preload `n0 = kn g` at each node.
    Preload,
    /// An initial gap `g` at each node (`n0 = -kn g`).
    Gap,
    /// Preload at some nodes, gaps at the others.
    Mixed,
    /// No `n0`: a static force pressing the contacts shut (`kn g` per node along the normal).
    StaticForce,
}

/// One model of the campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSpec {
    pub body: Body,
    pub site: Site,
    pub closure: Closure,
    pub mu: f64,
    /// `kt / kn`.
    pub kt_over_kn: f64,
    /// Total normal stiffness of the contacts over the body's static tip stiffness `3 E I / L^3`.
    pub stiffness_ratio: f64,
    /// Preload interference or gap per node (mm).
    pub g: f64,
    pub cb_modes: usize,
    /// Modal damping ratio at the stuck resonance.
    pub zeta: f64,
    /// Seed of the per-node choices (mixed closures).
    pub seed: u64,
}

fn log_uniform(rng: &mut StdRng, lo: f64, hi: f64) -> f64 {
    (rng.gen_range(lo.ln()..hi.ln())).exp()
}

impl ModelSpec {
    /// A random model: plate or blade proportions, twist, taper, end shape, contact site,
    /// closure and contact parameters (`kt/kn` 0.1 to 10, `mu` 0.1 to 0.8, preload and gaps over
    /// two decades).
    pub fn random(rng: &mut StdRng) -> ModelSpec {
        let length = rng.gen_range(80.0..150.0);
        let chord = rng.gen_range(20.0..45.0);
        let thickness = rng.gen_range(2.5..6.0);
        let end = match rng.gen_range(0..3) {
            0 => EndShape::Flat,
            1 => EndShape::Inclined(rng.gen_range(10f64..35.0).to_radians()),
            _ => EndShape::Mitred(rng.gen_range(10f64..30.0).to_radians()),
        };
        let body = Body {
            length,
            chord,
            thickness,
            taper: rng.gen_range(0.5..1.0),
            twist: rng.gen_range(0f64..40.0).to_radians(),
            end,
            nx: 2 * rng.gen_range(3..5),
            ny: 2,
            nz: rng.gen_range(10..15),
            material: Material::STEEL_MM_TONNE,
        };
        let site = match rng.gen_range(0..3) {
            0 => Site::EndPatch { fraction: rng.gen_range(0.5..1.0) },
            1 => Site::TipLine { hub_radius: rng.gen_range(150.0..400.0) },
            _ => Site::NodePairs { layers: rng.gen_range(1..3), ratio: rng.gen_range(0.6..1.5), density_ratio: rng.gen_range(0.8..1.25) },
        };
        let closure = match rng.gen_range(0..4) {
            0 => Closure::Preload,
            1 => Closure::Gap,
            2 => Closure::Mixed,
            _ => Closure::StaticForce,
        };
        ModelSpec {
            body,
            site,
            closure,
            mu: rng.gen_range(0.1..0.8),
            kt_over_kn: log_uniform(rng, 0.1, 10.0),
            stiffness_ratio: log_uniform(rng, 30.0, 3000.0),
            g: log_uniform(rng, 1e-4, 1e-2),
            cb_modes: rng.gen_range(10..16),
            zeta: log_uniform(rng, 0.002, 0.01),
            seed: rng.gen(),
        }
    }

    /// The class of issue 59's public model, generated: a cantilever plate whose end, inclined
    /// by `incline` (rad), is pressed by a static force against a rigid wall through every node
    /// of its end face (`(nx + 1) 3` nodes: 27 to 57 for `nx` 8 to 18), one normal for the
    /// patch, penalty stiffnesses from the nodes' areas, `mu` 0.36; liftoff over part of the
    /// cycle at the middle levels.
    pub fn inclined_patch(nx: usize, incline: f64) -> ModelSpec {
        ModelSpec {
            body: Body {
                length: 120.0,
                chord: 30.0,
                thickness: 4.0,
                taper: 0.8,
                twist: 0.0,
                end: EndShape::Inclined(incline),
                nx,
                ny: 2,
                nz: 12,
                material: Material::STEEL_MM_TONNE,
            },
            site: Site::EndPatch { fraction: 1.0 },
            closure: Closure::StaticForce,
            mu: 0.36,
            kt_over_kn: 1.0,
            stiffness_ratio: 300.0,
            g: 1e-3,
            cb_modes: 12,
            zeta: 0.004,
            seed: 59,
        }
    }

    /// One line for a report.
    pub fn describe(&self) -> String {
        let b = &self.body;
        let end = match b.end {
            EndShape::Flat => "flat end".to_string(),
            EndShape::Inclined(a) => format!("end inclined {:.0} deg", a.to_degrees()),
            EndShape::Mitred(a) => format!("end mitred {:.0} deg", a.to_degrees()),
        };
        let site = match &self.site {
            Site::EndPatch { fraction } => format!("end patch ({:.0} % of the chord)", 100.0 * fraction),
            Site::TipLine { .. } => "tip line, radial normals".to_string(),
            Site::NodePairs { layers, ratio, .. } => format!("node pairs to a second body ({layers} layers, thickness ratio {ratio:.2})"),
        };
        format!(
            "{:.0} x {:.0} x {:.1} mm, taper {:.2}, twist {:.0} deg, {end}, {}x{}x{} hex8; {site}; {:?}, g {:.1e} mm; mu {:.2}, kt/kn {:.2}, kn/k_tip {:.0}; {} CB modes, zeta {:.3}",
            b.length, b.chord, b.thickness, b.taper, b.twist.to_degrees(), b.nx, b.ny, b.nz, self.closure, self.g, self.mu, self.kt_over_kn, self.stiffness_ratio, self.cb_modes, self.zeta
        )
    }

    /// The mesh of the model (two bodies for node pairs).
    pub fn mesh(&self) -> Mesh {
        match &self.site {
            Site::NodePairs { ratio, density_ratio, .. } => {
                let m = self.body.material;
                Mesh::new(&self.body, Some((*ratio, Material { density: m.density * density_ratio, ..m })))
            }
            _ => Mesh::new(&self.body, None),
        }
    }
}

/// A campaign model built: the reduced model at dynamic scale 1, its band (rad/s), the
/// dynamic scale of level 1 and what it means.
#[derive(Clone, Debug)]
pub struct Built {
    pub model: Model,
    pub band: (f64, f64),
    pub level_scale: f64,
    /// The stuck limit, or the forcing at which the open resonance closes the smallest gap.
    pub reference: String,
    pub n_fe_dofs: usize,
}

/// One contact of the model before reduction: node(s), frame rows `t1, t2, n`, area weight.
struct Site3 {
    a: usize,
    b: Option<usize>,
    frame: [[f64; 3]; 3],
    weight: f64,
}

fn frame_of(n: [f64; 3], hint: [f64; 3]) -> [[f64; 3]; 3] {
    let t1 = unit({
        let d = dot(hint, n);
        [hint[0] - d * n[0], hint[1] - d * n[1], hint[2] - d * n[2]]
    });
    let t2 = cross(n, t1);
    [t1, t2, n]
}

/// The contact sites of `spec` on `mesh` (node indices of the mesh).
fn sites(spec: &ModelSpec, mesh: &Mesh) -> Vec<Site3> {
    let b = &mesh.bodies[0];
    let (nx, ny, nz) = (b.nx, b.ny, b.nz);
    match &spec.site {
        Site::EndPatch { fraction } => {
            // end-face nodes in the patch, tributary areas of the end-face quads
            let lo = ((1.0 - fraction) * nx as f64 / 2.0).floor() as usize;
            let (i0, i1) = match b.end {
                EndShape::Mitred(_) => (nx / 2, nx),
                _ => (lo, nx - lo),
            };
            let mut weight = vec![0.0; (nx + 1) * (ny + 1)];
            for i in i0..i1 {
                for j in 0..ny {
                    let p = |ii, jj| mesh.coords[mesh.node(0, ii, jj, nz)];
                    let (a, bb, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
                    let d1 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                    let d2 = [d[0] - bb[0], d[1] - bb[1], d[2] - bb[2]];
                    let area = 0.5 * dot(cross(d1, d2), cross(d1, d2)).sqrt();
                    for (ii, jj) in [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)] {
                        weight[jj * (nx + 1) + ii] += 0.25 * area;
                    }
                }
            }
            let xi = 0.5 * ((i0 + i1) as f64 / nx as f64) - 0.5;
            let n = b.end_normal(xi);
            let th = b.twist;
            let frame = frame_of(n, [th.cos(), th.sin(), 0.0]);
            let total: f64 = weight.iter().sum();
            (0..=ny)
                .flat_map(|j| (i0..=i1).map(move |i| (i, j)))
                .map(|(i, j)| Site3 { a: mesh.node(0, i, j, nz), b: None, frame, weight: weight[j * (nx + 1) + i] / total })
                .collect()
        }
        Site::TipLine { hub_radius } => {
            let count = nx + 1;
            (0..=nx)
                .map(|i| {
                    let node = mesh.node(0, i, ny / 2, nz);
                    let x = mesh.coords[node];
                    let n = unit([0.0, x[1], x[2] + hub_radius]);
                    Site3 { a: node, b: None, frame: frame_of(n, [1.0, 0.0, 0.0]), weight: 1.0 / count as f64 }
                })
                .collect()
        }
        Site::NodePairs { layers, .. } => {
            let mut out = Vec::new();
            let ny2 = mesh.bodies[1].ny;
            let count = (nx + 1) * layers;
            for k in nz + 1 - layers..=nz {
                let th = b.twist * k as f64 / nz as f64;
                // from the first body to the second: the thickness direction of the section
                let n = [-th.sin(), th.cos(), 0.0];
                let frame = frame_of(n, [th.cos(), th.sin(), 0.0]);
                for i in 0..=nx {
                    out.push(Site3 { a: mesh.node(0, i, ny, k), b: Some(mesh.node(1, i, 0, k)), frame, weight: 1.0 / count as f64 });
                }
            }
            let _ = ny2;
            out
        }
    }
}

/// Static tip stiffness `3 E I / L^3` of the first body (flap, root section).
fn tip_stiffness(b: &Body) -> f64 {
    let i = b.chord * b.thickness.powi(3) / 12.0;
    3.0 * b.material.young * i / b.length.powi(3)
}

/// Builds the model: mesh, native assembly (or the CalculiX files of `ccx_dir`, the deck's
/// job already run there), contacts, loads, Craig-Bampton, damping, band and level scale.
///
/// # Errors
/// A description of the first step that failed.
pub fn build(spec: &ModelSpec, ccx_dir: Option<&std::path::Path>) -> Result<Built, String> {
    let mesh = spec.mesh();
    let rows = mesh.rows();
    let fe = match ccx_dir {
        Some(dir) => {
            let inp = dir.join("campaign.inp");
            let ccx = jprom::io::calculix::read_model(&inp).map_err(|e| e.to_string())?;
            FeModel::from_calculix(&ccx).map_err(|e| e.to_string())?
        }
        None => {
            let (k, m) = mesh.assemble();
            let nodes = (0..mesh.coords.len())
                .filter_map(|i| rows[i].map(|r| FeNode { id: i as i64 + 1, coords: Some(mesh.coords[i]), dofs: [Some(3 * r), Some(3 * r + 1), Some(3 * r + 2), None, None, None] }))
                .collect();
            FeModel::new(k, m, nodes).map_err(|e| e.to_string())?
        }
    };
    let id = |node: usize| node as i64 + 1;
    let sites = sites(spec, &mesh);
    let kn_total = spec.stiffness_ratio * tip_stiffness(&spec.body);
    let mut pick = <StdRng as rand::SeedableRng>::seed_from_u64(spec.seed);
    let laws: Vec<ContactLaw> = sites
        .iter()
        .map(|s| {
            let kn = kn_total * s.weight;
            let open = match spec.closure {
                Closure::Gap => true,
                Closure::Mixed => pick.gen_bool(0.5),
                Closure::Preload | Closure::StaticForce => false,
            };
            let n0 = match spec.closure {
                Closure::StaticForce => 0.0,
                _ if open => -kn * spec.g,
                _ => kn * spec.g,
            };
            ContactLaw::Friction3D { kt1: spec.kt_over_kn * kn, kt2: spec.kt_over_kn * kn, kn, mu: spec.mu, n0 }
        })
        .collect();
    // loads: a harmonic force at the leading edge at 60 % span (flap, some chord), the
    // static force of a StaticForce closure at the contact nodes along their normals
    let b = &spec.body;
    let k_load = ((0.6 * b.nz as f64).round() as usize).clamp(1, b.nz);
    let load = mesh.node(0, 0, b.ny / 2, k_load);
    let th = b.twist * k_load as f64 / b.nz as f64;
    let flap = [-th.sin(), th.cos(), 0.0];
    let chordwise = [th.cos(), th.sin(), 0.0];
    let force = [flap[0] + 0.3 * chordwise[0], flap[1] + 0.3 * chordwise[1], 0.0];
    let tip = mesh.node(0, b.nx, b.ny, b.nz);
    let static_forces: Vec<NodalForce> = if spec.closure == Closure::StaticForce {
        sites
            .iter()
            .map(|s| {
                let f = kn_total * s.weight * spec.g;
                let n = s.frame[2];
                NodalForce { node: id(s.a), force: [f * n[0], f * n[1], f * n[2]] }
            })
            .collect()
    } else {
        Vec::new()
    };
    let pairs = sites.iter().any(|s| s.b.is_some());
    let mut extra: Vec<i64> = Vec::new();
    if pairs {
        for s in &sites {
            extra.push(id(s.a));
            extra.push(id(s.b.expect("pairs")));
        }
    }
    let spec_red = Reduction {
        contacts: if pairs { Vec::new() } else { sites.iter().zip(&laws).map(|(s, l)| NodalContact { node: id(s.a), frame: s.frame, law: l.clone() }).collect() },
        static_forces: static_forces.clone(),
        harmonic_forces: vec![NodalForce { node: id(load), force }],
        outputs: vec![(id(load), 1), (id(tip), 1)],
        extra_nodes: extra.clone(),
        cb_modes: spec.cb_modes,
        cb_cutoff_hz: None,
    };
    let mut model = fe.reduce(&spec_red, Damping { mass_coeff: 0.0, stiffness_coeff: 0.0 }).map_err(|e| e.to_string())?;
    if pairs {
        // the kept nodes' order (FeModel::reduce): contacts (none), loads, outputs, extras
        let mut order: Vec<i64> = Vec::new();
        for nid in static_forces.iter().map(|f| f.node).chain([id(load)]).chain(spec_red.outputs.iter().map(|o| o.0)).chain(extra.iter().copied()) {
            if !order.contains(&nid) {
                order.push(nid);
            }
        }
        let dofs = |nid: i64| {
            let p = order.iter().position(|&q| q == nid).expect("kept node");
            [3 * p, 3 * p + 1, 3 * p + 2]
        };
        model.contacts = sites.iter().zip(&laws).map(|(s, l)| Contact::pair_3d(dofs(id(s.a)), dofs(id(s.b.expect("pairs"))), s.frame, l.clone())).collect();
        model.validate().map_err(|e| e.to_string())?;
    }
    // band: the first modes stuck (every contact's stiffness), slipping (normal only) and
    // open (none), widened by 10 %
    let first = |kind: u8| -> Result<f64, String> {
        let mut k = model.stiffness.clone();
        for c in &model.contacts {
            let ContactLaw::Friction3D { kt1, kn, n0, .. } = c.law else { continue };
            if n0 < 0.0 || kind == 2 {
                continue;
            }
            let diag = if kind == 0 { [kt1, kt1, kn] } else { [0.0, 0.0, kn] };
            let sides: Vec<(&Vec<usize>, f64)> = std::iter::once((&c.dofs_a, 1.0)).chain(c.dofs_b.as_ref().map(|d| (d, -1.0))).collect();
            for (da, sa) in &sides {
                for (db, sb) in &sides {
                    for p in 0..3 {
                        for q in 0..3 {
                            let v: f64 = (0..3).map(|r| c.frame[r][p] * diag[r] * c.frame[r][q]).sum();
                            k[(da[p], db[q])] += sa * sb * v;
                        }
                    }
                }
            }
        }
        let ev = jprom::linalg::eigen::dense_generalized_eigenvalues(&k, &model.mass).map_err(|e| e.to_string())?;
        Ok(ev.iter().copied().filter(|l| *l > 0.0).fold(f64::INFINITY, f64::min).sqrt())
    };
    let (w_stuck, w_slip, w_open) = (first(0)?, first(1)?, first(2)?);
    let any_open = laws.iter().any(|l| matches!(l, ContactLaw::Friction3D { n0, .. } if *n0 < 0.0));
    let lo = if any_open { w_slip.min(w_open) } else { w_slip }.min(w_stuck);
    let band = (0.9 * lo, 1.1 * w_stuck.max(if any_open { w_open } else { 0.0 }));
    model.damping = Damping::from_modal_ratio(spec.zeta, w_stuck);
    model.validate().map_err(|e| e.to_string())?;
    // level 1: the stuck limit, or the forcing at which the open resonance closes a gap
    let coords = ContactCoordinates::new(&model, 1).map_err(|e| e.to_string())?;
    let z0 = static_solution(&coords).map_err(|e| e.to_string())?;
    let limit = stuck_limit(&coords, &z0, w_stuck).map_err(|e| e.to_string())?;
    let (level_scale, reference) = match limit.reference {
        LevelReference::StuckLimit => (limit.scale, format!("stuck limit at {:.1} Hz", w_stuck / std::f64::consts::TAU)),
        LevelReference::GivenForcing { .. } => {
            let s = gap_closing_scale(&model, w_open, spec.g)?;
            (s, format!("the open resonance ({:.1} Hz) closes a gap of {:.1e} mm", w_open / std::f64::consts::TAU, spec.g))
        }
    };
    Ok(Built { model, band, level_scale, reference, n_fe_dofs: fe.n_dof() })
}

/// The dynamic scale at which the linear response at `omega`, contacts open, moves some
/// contact by `gap` along its normal.
fn gap_closing_scale(model: &Model, omega: f64, gap: f64) -> Result<f64, String> {
    let n = model.n_dof();
    let c = &model.mass * model.damping.mass_coeff + &model.stiffness * model.damping.stiffness_coeff;
    let a = &model.stiffness - &model.mass * (omega * omega);
    let b = &c * omega;
    // [A -B; B A] [x_c; x_s] = [f; 0] for (A + i B)(x_c + i x_s) = f
    let big = faer::Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => a[(i, j)],
        (true, false) => -b[(i, j - n)],
        (false, true) => b[(i - n, j)],
        (false, false) => a[(i - n, j - n)],
    });
    let f = &model.excitation.harmonics[0].cos;
    let rhs = faer::Mat::from_fn(2 * n, 1, |i, _| if i < n { f[i] } else { 0.0 });
    let x = jprom::linalg::solve_checked("open linear response", &big, &rhs).map_err(|e| e.to_string())?;
    let mut worst = 0.0f64;
    for ct in &model.contacts {
        let nrm = ct.frame[2];
        let rel = |k: usize| -> f64 {
            let va: f64 = (0..3).map(|p| nrm[p] * x[(ct.dofs_a[p] + k, 0)]).sum();
            let vb: f64 = ct.dofs_b.as_ref().map_or(0.0, |d| (0..3).map(|p| nrm[p] * x[(d[p] + k, 0)]).sum());
            va - vb
        };
        worst = worst.max(rel(0).hypot(rel(n)));
    }
    if !(worst > 0.0) {
        return Err("the forcing does not move any contact along its normal".into());
    }
    Ok(gap / worst)
}
