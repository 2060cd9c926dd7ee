//! Linear 8-node hexahedral solid element (isotropic, linear elastic): stiffness by exact
//! 2x2x2 Gauss integration and consistent mass (also 2x2x2, exact for parallelepipeds).
//!
//! Node order (natural coordinates `xi, eta, zeta`): `(-,-,-) (+,-,-) (+,+,-) (-,+,-)` then the
//! same four at `zeta = +1`. Element DoFs are node-major: `3 * node + component`.

use crate::error::{JpError, Result};

/// Natural coordinates of the 8 nodes.
pub const NODE_SIGNS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Isotropic linear elastic material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Young's modulus `E`.
    pub young: f64,
    /// Poisson's ratio `nu`.
    pub poisson: f64,
    /// Density `rho`.
    pub density: f64,
}

impl Material {
    /// Steel in mm, tonne, s: `E = 2.0e5` MPa, `nu = 0.3`, `rho = 7.8e-9` tonne/mm^3.
    pub const STEEL_MM_TONNE: Material = Material { young: 2.0e5, poisson: 0.3, density: 7.8e-9 };

    /// Rejects non-physical values.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] for `E <= 0`, `rho <= 0` or `nu` outside `(-1, 0.5)`.
    pub fn validate(&self) -> Result<()> {
        if !(self.young.is_finite() && self.young > 0.0) {
            return Err(JpError::invalid("material.young", format!("must be > 0, got {}", self.young)));
        }
        if !(self.density.is_finite() && self.density > 0.0) {
            return Err(JpError::invalid("material.density", format!("must be > 0, got {}", self.density)));
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return Err(JpError::invalid("material.poisson", format!("must be in (-1, 0.5), got {}", self.poisson)));
        }
        Ok(())
    }

    /// Elasticity matrix in Voigt order `xx, yy, zz, xy, yz, zx` (engineering shear strains).
    pub fn elasticity(&self) -> [[f64; 6]; 6] {
        let (e, nu) = (self.young, self.poisson);
        let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mut d = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                d[i][j] = if i == j { c * (1.0 - nu) } else { c * nu };
            }
            d[3 + i][3 + i] = c * (1.0 - 2.0 * nu) / 2.0;
        }
        d
    }
}

/// Shape functions and their natural derivatives at `(xi, eta, zeta)`.
fn shape(p: [f64; 3]) -> ([f64; 8], [[f64; 3]; 8]) {
    let mut n = [0.0; 8];
    let mut dn = [[0.0; 3]; 8];
    for (a, s) in NODE_SIGNS.iter().enumerate() {
        let f = [1.0 + s[0] * p[0], 1.0 + s[1] * p[1], 1.0 + s[2] * p[2]];
        n[a] = f[0] * f[1] * f[2] / 8.0;
        dn[a] = [s[0] * f[1] * f[2] / 8.0, f[0] * s[1] * f[2] / 8.0, f[0] * f[1] * s[2] / 8.0];
    }
    (n, dn)
}

/// The 8 Gauss points of the 2x2x2 rule (all weights 1).
fn gauss_points() -> [[f64; 3]; 8] {
    let g = 1.0 / 3f64.sqrt();
    let mut out = [[0.0; 3]; 8];
    for (a, s) in NODE_SIGNS.iter().enumerate() {
        out[a] = [s[0] * g, s[1] * g, s[2] * g];
    }
    out
}

/// Shape function values, global derivatives `dN/dx` and `det J` at a natural point.
///
/// # Errors
/// [`JpError::InvalidValue`] if the element is inverted or degenerate (`det J <= 0`).
fn global_derivatives(coords: &[[f64; 3]; 8], p: [f64; 3]) -> Result<([f64; 8], [[f64; 3]; 8], f64)> {
    let (n, dn) = shape(p);
    // J[i][j] = d x_j / d xi_i
    let mut j = [[0.0; 3]; 3];
    for a in 0..8 {
        for i in 0..3 {
            for k in 0..3 {
                j[i][k] += dn[a][i] * coords[a][k];
            }
        }
    }
    let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
        + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    if !(det.is_finite() && det > 0.0) {
        return Err(JpError::invalid("hex8 element", format!("inverted or degenerate (det J = {det:.3e})")));
    }
    let inv = [
        [
            (j[1][1] * j[2][2] - j[1][2] * j[2][1]) / det,
            (j[0][2] * j[2][1] - j[0][1] * j[2][2]) / det,
            (j[0][1] * j[1][2] - j[0][2] * j[1][1]) / det,
        ],
        [
            (j[1][2] * j[2][0] - j[1][0] * j[2][2]) / det,
            (j[0][0] * j[2][2] - j[0][2] * j[2][0]) / det,
            (j[0][2] * j[1][0] - j[0][0] * j[1][2]) / det,
        ],
        [
            (j[1][0] * j[2][1] - j[1][1] * j[2][0]) / det,
            (j[0][1] * j[2][0] - j[0][0] * j[2][1]) / det,
            (j[0][0] * j[1][1] - j[0][1] * j[1][0]) / det,
        ],
    ];
    // dN/dx_k = sum_i (J^-1)[k][i] dN/dxi_i
    let mut dx = [[0.0; 3]; 8];
    for a in 0..8 {
        for k in 0..3 {
            dx[a][k] = (0..3).map(|i| inv[k][i] * dn[a][i]).sum();
        }
    }
    Ok((n, dx, det))
}

/// Strain-displacement matrix `B` (6 x 24) from the global shape derivatives.
fn strain_matrix(dx: &[[f64; 3]; 8]) -> [[f64; 24]; 6] {
    let mut b = [[0.0; 24]; 6];
    for a in 0..8 {
        let [x, y, z] = dx[a];
        let c = 3 * a;
        b[0][c] = x;
        b[1][c + 1] = y;
        b[2][c + 2] = z;
        b[3][c] = y;
        b[3][c + 1] = x;
        b[4][c + 1] = z;
        b[4][c + 2] = y;
        b[5][c] = z;
        b[5][c + 2] = x;
    }
    b
}

/// Element stiffness `K_e = int B^T D B dV` (24 x 24, row-major), 2x2x2 Gauss.
///
/// # Errors
/// [`JpError::InvalidValue`] for an inverted or degenerate element.
pub fn stiffness(coords: &[[f64; 3]; 8], mat: &Material) -> Result<[[f64; 24]; 24]> {
    let d = mat.elasticity();
    let mut k = [[0.0; 24]; 24];
    for p in gauss_points() {
        let (_, dx, det) = global_derivatives(coords, p)?;
        let b = strain_matrix(&dx);
        let mut db = [[0.0; 24]; 6];
        for i in 0..6 {
            for c in 0..24 {
                db[i][c] = (0..6).map(|m| d[i][m] * b[m][c]).sum::<f64>() * det;
            }
        }
        for r in 0..24 {
            for c in 0..24 {
                k[r][c] += (0..6).map(|m| b[m][r] * db[m][c]).sum::<f64>();
            }
        }
    }
    symmetrise(&mut k);
    Ok(k)
}

/// Makes a 24 x 24 matrix exactly symmetric (removes round-off asymmetry).
fn symmetrise(a: &mut [[f64; 24]; 24]) {
    for r in 0..24 {
        for c in 0..r {
            let v = 0.5 * (a[r][c] + a[c][r]);
            a[r][c] = v;
            a[c][r] = v;
        }
    }
}

/// Consistent element mass `M_e = rho int N^T N dV` (24 x 24, row-major), 2x2x2 Gauss.
///
/// # Errors
/// [`JpError::InvalidValue`] for an inverted or degenerate element.
pub fn mass(coords: &[[f64; 3]; 8], mat: &Material) -> Result<[[f64; 24]; 24]> {
    let mut m = [[0.0; 24]; 24];
    for p in gauss_points() {
        let (n, _, det) = global_derivatives(coords, p)?;
        for a in 0..8 {
            for b in 0..8 {
                let v = mat.density * n[a] * n[b] * det;
                for c in 0..3 {
                    m[3 * a + c][3 * b + c] += v;
                }
            }
        }
    }
    Ok(m)
}

/// Stress (Voigt order) at the element centre for element displacements `u` (24, node-major).
///
/// # Errors
/// [`JpError::InvalidValue`] for an inverted or degenerate element.
pub fn centre_stress(coords: &[[f64; 3]; 8], mat: &Material, u: &[f64; 24]) -> Result<[f64; 6]> {
    let (_, dx, _) = global_derivatives(coords, [0.0; 3])?;
    let b = strain_matrix(&dx);
    let d = mat.elasticity();
    let mut eps = [0.0; 6];
    for i in 0..6 {
        eps[i] = (0..24).map(|c| b[i][c] * u[c]).sum();
    }
    let mut s = [0.0; 6];
    for i in 0..6 {
        s[i] = (0..6).map(|m| d[i][m] * eps[m]).sum();
    }
    Ok(s)
}
