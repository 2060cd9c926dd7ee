//! Hex8 element: patch test (a linear displacement field is reproduced exactly, on distorted
//! elements too), consistent mass, and a cantilever's first bending frequency against
//! Euler-Bernoulli.

use jprom::fe::hex8::{self, Material, NODE_SIGNS};
use jprom::linalg::lanczos::{lowest_modes, SparseCholesky};
use jprom::linalg::{sparse_from_triplets, sparse_matvec, SparseMat};

/// Structured `nx x ny x nz` grid of a box, with optional distortion of interior nodes.
fn grid(dims: [f64; 3], n: [usize; 3], distort: f64) -> (Vec<[f64; 3]>, Vec<[usize; 8]>) {
    let id = |i: usize, j: usize, k: usize| (k * (n[1] + 1) + j) * (n[0] + 1) + i;
    let mut xyz = Vec::new();
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                let mut p = [
                    dims[0] * i as f64 / n[0] as f64,
                    dims[1] * j as f64 / n[1] as f64,
                    dims[2] * k as f64 / n[2] as f64,
                ];
                let interior = i > 0 && i < n[0] && j > 0 && j < n[1] && k > 0 && k < n[2];
                if interior {
                    let s = ((i * 7 + j * 13 + k * 29) % 11) as f64 / 11.0 - 0.5;
                    p[0] += distort * s * dims[0] / n[0] as f64;
                    p[1] -= distort * s * dims[1] / n[1] as f64;
                    p[2] += 0.5 * distort * s * dims[2] / n[2] as f64;
                }
                xyz.push(p);
            }
        }
    }
    let mut el = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let mut c = [0; 8];
                for (a, s) in NODE_SIGNS.iter().enumerate() {
                    c[a] = id(i + (s[0] > 0.0) as usize, j + (s[1] > 0.0) as usize, k + (s[2] > 0.0) as usize);
                }
                el.push(c);
            }
        }
    }
    (xyz, el)
}

fn assemble(xyz: &[[f64; 3]], el: &[[usize; 8]], mat: &Material, mass: bool) -> SparseMat {
    let n = 3 * xyz.len();
    let mut tr = Vec::new();
    for c in el {
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| xyz[c[a]]);
        let ke = if mass { hex8::mass(&x, mat).unwrap() } else { hex8::stiffness(&x, mat).unwrap() };
        for r in 0..24 {
            for s in 0..24 {
                tr.push((3 * c[r / 3] + r % 3, 3 * c[s / 3] + s % 3, ke[r][s]));
            }
        }
    }
    sparse_from_triplets(n, n, tr).unwrap()
}

#[test]
fn patch_test_linear_field_is_exact_on_distorted_mesh() {
    let mat = Material::STEEL_MM_TONNE;
    let n = [3usize, 3, 3];
    let (xyz, el) = grid([2.0, 3.0, 1.5], n, 0.4);
    let k = assemble(&xyz, &el, &mat, false);
    // u = A x + b with a general (non-symmetric) gradient A.
    let a = [[1e-3, 2e-4, -3e-4], [5e-4, -2e-3, 1e-4], [-4e-4, 3e-4, 1.5e-3]];
    let b = [0.1, -0.2, 0.05];
    let u: Vec<f64> = (0..3 * xyz.len())
        .map(|d| {
            let (nd, c) = (d / 3, d % 3);
            b[c] + (0..3).map(|m| a[c][m] * xyz[nd][m]).sum::<f64>()
        })
        .collect();
    let f = sparse_matvec(&k, &u);
    let fmax = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for kk in 1..n[2] {
        for j in 1..n[1] {
            for i in 1..n[0] {
                let nd = (kk * (n[1] + 1) + j) * (n[0] + 1) + i;
                for c in 0..3 {
                    worst = worst.max(f[3 * nd + c].abs());
                }
            }
        }
    }
    assert!(fmax > 1.0, "boundary nodes carry the traction resultants ({fmax})");
    assert!(worst < 1e-10 * fmax, "interior residual {worst} vs {fmax}");
    // Exact stress from Hooke's law in every element.
    let eps = [a[0][0], a[1][1], a[2][2], a[0][1] + a[1][0], a[1][2] + a[2][1], a[2][0] + a[0][2]];
    let (e, nu) = (mat.young, mat.poisson);
    let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let g = e / (2.0 * (1.0 + nu));
    let tr = eps[0] + eps[1] + eps[2];
    let expect = [
        lam * tr + 2.0 * g * eps[0],
        lam * tr + 2.0 * g * eps[1],
        lam * tr + 2.0 * g * eps[2],
        g * eps[3],
        g * eps[4],
        g * eps[5],
    ];
    for c in &el {
        let x: [[f64; 3]; 8] = std::array::from_fn(|q| xyz[c[q]]);
        let ue: [f64; 24] = std::array::from_fn(|r| u[3 * c[r / 3] + r % 3]);
        let s = hex8::centre_stress(&x, &mat, &ue).unwrap();
        for q in 0..6 {
            assert!((s[q] - expect[q]).abs() < 1e-9 * 500.0, "stress {q}: {} vs {}", s[q], expect[q]);
        }
    }
}

#[test]
fn consistent_mass_integrates_total_mass() {
    let mat = Material::STEEL_MM_TONNE;
    let (xyz, el) = grid([2.0, 3.0, 1.5], [2, 2, 2], 0.3);
    let m = assemble(&xyz, &el, &mat, true);
    let u: Vec<f64> = (0..3 * xyz.len()).map(|d| if d % 3 == 0 { 1.0 } else { 0.0 }).collect();
    let mu = sparse_matvec(&m, &u);
    let total: f64 = u.iter().zip(&mu).map(|(a, b)| a * b).sum();
    let exact = mat.density * 2.0 * 3.0 * 1.5;
    assert!((total - exact).abs() < 1e-12 * exact, "{total} vs {exact}");
}

#[test]
fn inverted_element_is_an_error() {
    let mat = Material::STEEL_MM_TONNE;
    let mut x: [[f64; 3]; 8] = std::array::from_fn(|a| [NODE_SIGNS[a][0], NODE_SIGNS[a][1], NODE_SIGNS[a][2]]);
    x.swap(0, 4);
    x.swap(1, 5);
    x.swap(2, 6);
    x.swap(3, 7);
    assert!(hex8::stiffness(&x, &mat).is_err());
}

/// First bending frequency of a clamped hex8 cantilever (length 100, section 5 x 5 mm).
fn cantilever_first_hz(n_len: usize, n_sec: usize) -> f64 {
    let mat = Material::STEEL_MM_TONNE;
    let (xyz, el) = grid([5.0, 5.0, 100.0], [n_sec, n_sec, n_len], 0.0);
    let k = assemble(&xyz, &el, &mat, false);
    let m = assemble(&xyz, &el, &mat, true);
    let keep: Vec<usize> = (0..3 * xyz.len()).filter(|d| xyz[d / 3][2] > 0.0).collect();
    let mut map = vec![usize::MAX; 3 * xyz.len()];
    for (r, &d) in keep.iter().enumerate() {
        map[d] = r;
    }
    let sub = |a: &SparseMat| {
        let tr: Vec<_> = jprom::linalg::sparse::sparse_triplets(a)
            .into_iter()
            .filter(|&(i, j, _)| map[i] != usize::MAX && map[j] != usize::MAX)
            .map(|(i, j, v)| (map[i], map[j], v))
            .collect();
        sparse_from_triplets(keep.len(), keep.len(), tr).unwrap()
    };
    let (k, m) = (sub(&k), sub(&m));
    let chol = SparseCholesky::factor(&k, "cantilever").unwrap();
    let e = lowest_modes(&chol, &m, 2).unwrap();
    // Square section: the two bending modes coincide.
    assert!((e.eigenvalues[1] / e.eigenvalues[0] - 1.0).abs() < 1e-6);
    e.eigenvalues[0].sqrt() / (2.0 * std::f64::consts::PI)
}

#[test]
fn cantilever_bending_converges_to_euler_bernoulli() {
    let mat = Material::STEEL_MM_TONNE;
    let (b, l) = (5.0f64, 100.0f64);
    let i = b.powi(4) / 12.0;
    let a = b * b;
    let beta = 1.875_104_068_711_961f64;
    let f_eb = beta * beta / (2.0 * std::f64::consts::PI) * (mat.young * i / (mat.density * a * l.powi(4))).sqrt();
    let errs: Vec<f64> =
        [(10, 1), (20, 2), (40, 4)].iter().map(|&(nl, ns)| (cantilever_first_hz(nl, ns) - f_eb) / f_eb).collect();
    eprintln!("Euler-Bernoulli {f_eb:.2} Hz, relative errors {errs:?}");
    // Full integration locks in bending: errors decrease monotonically on refinement.
    assert!(errs[1].abs() < errs[0].abs() && errs[2].abs() < errs[1].abs(), "{errs:?}");
    // The locking error falls like h^2 (each mesh halves h): within 6% on the finest mesh, and
    // the Richardson extrapolation (4 f_3 - f_2) / 3 agrees with Euler-Bernoulli to 1.5% (what
    // is left is the 3D/beam-theory difference, e.g. shear and Poisson effects).
    assert!(errs[2] > 0.0 && errs[2] < 0.06, "finest mesh error {}", errs[2]);
    let rich = (4.0 * errs[2] - errs[1]) / 3.0;
    assert!(rich.abs() < 0.015, "extrapolated error {rich}");
}
