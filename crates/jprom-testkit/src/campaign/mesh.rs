//! Solid cantilevers of linear hexahedra for the robustness campaign: plates and blades,
//! pre-twisted and tapered, with a flat, inclined or mitred free end, one body or two side by
//! side; assembled here (`jprom::fe::hex8`) or written as a CalculiX deck (C3D8) for `ccx`.
//!
//! Geometry (mm): a body is the grid `i = 0..=nx` (chord), `j = 0..=ny` (thickness),
//! `k = 0..=nz` (span) mapped to `xi = i / nx - 1/2`, `eta = eta0 + (j / ny) h`, `zeta = k / nz`:
//! local `x = xi c(zeta)`, `y = eta t(zeta)` with the chord and thickness tapering linearly
//! to `taper` times their root values, `z = zeta z_end(x)` with the free end
//! `z_end = L + x tan(a)` (inclined), `L - |x| tan(a)` (mitred) or `L`; then turned about the
//! span axis by `twist zeta`. So the end faces are planes (two for the mitre). The root
//! `k = 0` is clamped. A second body (node-pair contacts) is the grid of `eta` from `1/2` to
//! `1/2 + ratio`, sharing the first body's face `eta = 1/2` position for position but not its
//! nodes.

use jprom::fe::hex8::{self, Material};
use jprom::linalg::{sparse_from_triplets, SparseMat};
use std::fmt::Write;

/// The shape of the free end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EndShape {
    Flat,
    /// `z_end = L + x tan(a)`.
    Inclined(f64),
    /// `z_end = L - |x| tan(a)`.
    Mitred(f64),
}

/// One cantilever body.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub length: f64,
    pub chord: f64,
    pub thickness: f64,
    /// Tip chord and thickness over the root's.
    pub taper: f64,
    /// Twist of the tip section (rad).
    pub twist: f64,
    pub end: EndShape,
    pub nx: usize,
    pub ny: usize,
    pub nz: usize,
    pub material: Material,
}

impl Body {
    /// The local position of grid point `(i, j, k)` for thickness coordinates from `eta0`
    /// over `height` (`-1/2` and 1 for the first body).
    pub fn position(&self, i: usize, j: usize, k: usize, eta0: f64, height: f64) -> [f64; 3] {
        let xi = i as f64 / self.nx as f64 - 0.5;
        let eta = eta0 + height * j as f64 / self.ny as f64;
        let zeta = k as f64 / self.nz as f64;
        let scale = 1.0 - (1.0 - self.taper) * zeta;
        let x = xi * self.chord * scale;
        let y = eta * self.thickness * scale;
        let z_end = match self.end {
            EndShape::Flat => self.length,
            EndShape::Inclined(a) => self.length + x * a.tan(),
            EndShape::Mitred(a) => self.length - x.abs() * a.tan(),
        };
        let z = zeta * z_end;
        let th = self.twist * zeta;
        [x * th.cos() - y * th.sin(), x * th.sin() + y * th.cos(), z]
    }

    /// The unit outward normal of the end face at chord position `xi` (the facet of `xi` for
    /// a mitre).
    pub fn end_normal(&self, xi: f64) -> [f64; 3] {
        let (th, s) = (self.twist, match self.end {
            EndShape::Flat => 0.0,
            EndShape::Inclined(a) => -a.tan(),
            EndShape::Mitred(a) => if xi >= 0.0 { a.tan() } else { -a.tan() },
        });
        // gradient of z - z_end(x_local), x_local = x cos th + y sin th
        let g = [s * th.cos(), s * th.sin(), 1.0];
        unit(g)
    }
}

pub fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A meshed assembly: nodes (root nodes included, flagged), hex8 elements, and per body the
/// grid-to-node map.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub coords: Vec<[f64; 3]>,
    pub clamped: Vec<bool>,
    /// Eight node indices per element, in `hex8::NODE_SIGNS` order, and the element's material.
    pub elements: Vec<([usize; 8], Material)>,
    /// `grid[b][(k * (ny + 1) + j) * (nx + 1) + i]`: node of body `b`'s grid point.
    pub grid: Vec<Vec<usize>>,
    pub bodies: Vec<Body>,
}

impl Mesh {
    /// Meshes `first`, and `second` beside it (thickness from `eta = 1/2` to `1/2 + ratio`,
    /// with its own material) when given.
    pub fn new(first: &Body, second: Option<(f64, Material)>) -> Mesh {
        let mut mesh = Mesh { coords: Vec::new(), clamped: Vec::new(), elements: Vec::new(), grid: Vec::new(), bodies: Vec::new() };
        mesh.add_body(first, -0.5, 1.0);
        if let Some((ratio, material)) = second {
            let b = Body { material, ..first.clone() };
            mesh.add_body(&b, 0.5, ratio);
        }
        mesh
    }

    fn add_body(&mut self, b: &Body, eta0: f64, height: f64) {
        let (nx, ny, nz) = (b.nx + 1, b.ny + 1, b.nz + 1);
        let first = self.coords.len();
        let mut grid = Vec::with_capacity(nx * ny * nz);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    grid.push(self.coords.len());
                    self.coords.push(b.position(i, j, k, eta0, height));
                    self.clamped.push(k == 0);
                }
            }
        }
        debug_assert_eq!(grid[0], first);
        let g = |i: usize, j: usize, k: usize| grid[(k * ny + j) * nx + i];
        for k in 0..b.nz {
            for j in 0..b.ny {
                for i in 0..b.nx {
                    let mut e = [0; 8];
                    for (a, s) in hex8::NODE_SIGNS.iter().enumerate() {
                        e[a] = g(i + (s[0] > 0.0) as usize, j + (s[1] > 0.0) as usize, k + (s[2] > 0.0) as usize);
                    }
                    self.elements.push((e, b.material));
                }
            }
        }
        self.grid.push(grid);
        self.bodies.push(b.clone());
    }

    /// Node of body `b`'s grid point `(i, j, k)`.
    pub fn node(&self, b: usize, i: usize, j: usize, k: usize) -> usize {
        let body = &self.bodies[b];
        self.grid[b][(k * (body.ny + 1) + j) * (body.nx + 1) + i]
    }

    /// The DoF rows of each node (`None` for clamped ones): `3 r + {0, 1, 2}` over the free
    /// nodes in order.
    pub fn rows(&self) -> Vec<Option<usize>> {
        let mut next = 0;
        self.clamped
            .iter()
            .map(|&c| {
                (!c).then(|| {
                    next += 1;
                    next - 1
                })
            })
            .collect()
    }

    /// `K` and `M` (consistent), root clamped, rows as [`Mesh::rows`].
    pub fn assemble(&self) -> (SparseMat, SparseMat) {
        let rows = self.rows();
        let n = 3 * rows.iter().flatten().count();
        let (mut kt, mut mt) = (Vec::new(), Vec::new());
        for (e, mat) in &self.elements {
            let xyz: [[f64; 3]; 8] = std::array::from_fn(|a| self.coords[e[a]]);
            let ke = hex8::stiffness(&xyz, mat).expect("a valid hexahedron");
            let me = hex8::mass(&xyz, mat).expect("a valid hexahedron");
            let dofs: [Option<usize>; 24] = std::array::from_fn(|r| rows[e[r / 3]].map(|q| 3 * q + r % 3));
            for r in 0..24 {
                let Some(dr) = dofs[r] else { continue };
                for s in 0..24 {
                    if let Some(ds) = dofs[s] {
                        kt.push((dr, ds, ke[r][s]));
                        mt.push((dr, ds, me[r][s]));
                    }
                }
            }
        }
        (sparse_from_triplets(n, n, kt).expect("triplets"), sparse_from_triplets(n, n, mt).expect("triplets"))
    }

    /// A CalculiX deck of the mesh (C3D8, node `i` numbered `i + 1`), its root clamped by
    /// `*BOUNDARY`, one material per body, node sets `ROOT` and `NALL`, and the
    /// `*FREQUENCY, SOLVER=MATRIXSTORAGE` step that makes `ccx` write `K`, `M` and the rows.
    /// Numbers have 14 significant digits: `ccx` refuses a field longer than 20 characters.
    pub fn calculix_deck(&self) -> String {
        let mut s = String::from("*HEADING\njprom robustness campaign cantilever\n*NODE, NSET=NALL\n");
        for (i, x) in self.coords.iter().enumerate() {
            writeln!(s, "{}, {:.13e}, {:.13e}, {:.13e}", i + 1, x[0], x[1], x[2]).unwrap();
        }
        let mut materials: Vec<Material> = Vec::new();
        for (_, m) in &self.elements {
            if !materials.contains(m) {
                materials.push(*m);
            }
        }
        for (mi, mat) in materials.iter().enumerate() {
            writeln!(s, "*ELEMENT, TYPE=C3D8, ELSET=E{mi}").unwrap();
            for (ei, (e, m)) in self.elements.iter().enumerate() {
                if m == mat {
                    // CalculiX C3D8 order: bottom face 1-4 anticlockwise, then top face
                    writeln!(s, "{}, {}", ei + 1, e.iter().map(|v| (v + 1).to_string()).collect::<Vec<_>>().join(", ")).unwrap();
                }
            }
        }
        s.push_str("*NSET, NSET=ROOT\n");
        let root: Vec<String> = (0..self.coords.len()).filter(|&i| self.clamped[i]).map(|i| (i + 1).to_string()).collect();
        for chunk in root.chunks(8) {
            writeln!(s, "{}", chunk.join(", ")).unwrap();
        }
        for (mi, mat) in materials.iter().enumerate() {
            writeln!(s, "*MATERIAL, NAME=M{mi}\n*ELASTIC\n{:.13e}, {:.13e}\n*DENSITY\n{:.13e}", mat.young, mat.poisson, mat.density).unwrap();
            writeln!(s, "*SOLID SECTION, ELSET=E{mi}, MATERIAL=M{mi}").unwrap();
        }
        s.push_str("*BOUNDARY\nROOT, 1, 3\n*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n");
        s
    }
}
