//! Real discrete Fourier transforms between harmonic coefficients and `Nt` time samples
//! (docs/formulation.md §4), by precomputed cos/sin tables or by rustfft.
//!
//! Normalisation: `x(t_j) = c_0 + sum_h (c_{2h-1} cos(h t_j) + c_{2h} sin(h t_j))`,
//! `t_j = 2 pi j / Nt`, and forward `c_0 = mean(x)`, `c_{2h-1} = (2/Nt) sum x cos`,
//! `c_{2h} = (2/Nt) sum x sin`. Exact inverses of each other for `H < Nt / 2`.

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// How the AFT transforms between coefficients and samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AftBackend {
    /// Plain DFT with precomputed tables, `O(Nt (2H+1))` per signal. Fastest for small `H`.
    Tables,
    /// rustfft, `O(Nt log Nt)` per pair of signals (two real signals per complex transform).
    Fft,
    /// [`AftBackend::Tables`] for `H <= TABLES_MAX_H`, [`AftBackend::Fft`] above.
    Auto,
}

/// Largest `H` for which [`AftBackend::Auto`] uses the tables; above it, rustfft. Chosen from
/// `benches/aft.rs` (3D contact with Jacobian, 2-core machine): the two tie at `H = 1`
/// (10.9 vs 10.1 us per contact at `Nt = 64`) and rustfft wins from `H = 3` on (19.0 vs 13.4
/// us at `H = 3`, 57 vs 25 us at `H = 8`), because the table DFT of the Jacobian costs
/// `O(Nt (2H+1) n)` against `O(n Nt log Nt)` for packed FFTs of its columns.
pub const TABLES_MAX_H: usize = 1;

/// Transform tables and plans for one `(H, Nt)`.
pub(crate) struct Fourier {
    pub nc: usize,
    pub nt: usize,
    pub use_fft: bool,
    /// `basis[j * nc + k]`: basis function `k` at sample `j` (1, cos, sin).
    pub basis: Vec<f64>,
    /// `weights[j * nc + k]`: forward weight of sample `j` for coefficient `k`.
    pub weights: Vec<f64>,
    pub forward: Arc<dyn Fft<f64>>,
    pub inverse: Arc<dyn Fft<f64>>,
    pub scratch_len: usize,
}

impl Fourier {
    pub fn new(harmonics: usize, nt: usize, backend: AftBackend) -> Self {
        let nc = 2 * harmonics + 1;
        let mut basis = vec![0.0; nt * nc];
        let mut weights = vec![0.0; nt * nc];
        for j in 0..nt {
            basis[j * nc] = 1.0;
            weights[j * nc] = 1.0 / nt as f64;
            for h in 1..=harmonics {
                // Reduce the angle modulo 2 pi exactly through the integer product.
                let theta = 2.0 * std::f64::consts::PI * ((h * j) % nt) as f64 / nt as f64;
                let (s, c) = theta.sin_cos();
                basis[j * nc + 2 * h - 1] = c;
                basis[j * nc + 2 * h] = s;
                weights[j * nc + 2 * h - 1] = 2.0 * c / nt as f64;
                weights[j * nc + 2 * h] = 2.0 * s / nt as f64;
            }
        }
        let mut planner = FftPlanner::new();
        let forward = planner.plan_fft_forward(nt);
        let inverse = planner.plan_fft_inverse(nt);
        let scratch_len = forward.get_inplace_scratch_len().max(inverse.get_inplace_scratch_len());
        let use_fft = match backend {
            AftBackend::Tables => false,
            AftBackend::Fft => true,
            AftBackend::Auto => harmonics > TABLES_MAX_H,
        };
        Fourier { nc, nt, use_fft, basis, weights, forward, inverse, scratch_len }
    }

    /// Samples of coordinate(s) from coefficients. `coef` is coefficient-major with stride
    /// `dim`; coordinate `i` goes to `out_a`, coordinate `i2` (if any) to `out_b`.
    pub fn synthesize(
        &self,
        coef: &[f64],
        dim: usize,
        i: usize,
        out_a: &mut [f64],
        second: Option<(usize, &mut [f64])>,
        buf: &mut [Complex<f64>],
        scratch: &mut [Complex<f64>],
    ) {
        let (nc, nt) = (self.nc, self.nt);
        if !self.use_fft {
            for j in 0..nt {
                let b = &self.basis[j * nc..(j + 1) * nc];
                out_a[j] = (0..nc).map(|k| b[k] * coef[k * dim + i]).sum();
            }
            if let Some((i2, out_b)) = second {
                for j in 0..nt {
                    let b = &self.basis[j * nc..(j + 1) * nc];
                    out_b[j] = (0..nc).map(|k| b[k] * coef[k * dim + i2]).sum();
                }
            }
            return;
        }
        // Spectrum of x + i y: X_h = (a_h - i b_h)/2 at h, conjugate at Nt - h.
        let (i2, has2) = match &second {
            Some((i2, _)) => (*i2, true),
            None => (0, false),
        };
        let get = |k: usize, c: usize| coef[k * dim + c];
        let buf = &mut buf[..nt];
        buf.iter_mut().for_each(|z| *z = Complex::new(0.0, 0.0));
        let y0 = if has2 { get(0, i2) } else { 0.0 };
        buf[0] = Complex::new(get(0, i), y0);
        for h in 1..=(nc - 1) / 2 {
            let xa = Complex::new(0.5 * get(2 * h - 1, i), -0.5 * get(2 * h, i));
            let ya = if has2 { Complex::new(0.5 * get(2 * h - 1, i2), -0.5 * get(2 * h, i2)) } else { Complex::new(0.0, 0.0) };
            let i_unit = Complex::new(0.0, 1.0);
            buf[h] += xa + i_unit * ya;
            buf[nt - h] += xa.conj() + i_unit * ya.conj();
        }
        self.inverse.process_with_scratch(buf, &mut scratch[..self.scratch_len]);
        for j in 0..nt {
            out_a[j] = buf[j].re;
        }
        if let Some((_, out_b)) = second {
            for j in 0..nt {
                out_b[j] = buf[j].im;
            }
        }
    }

    /// Coefficients of one or two real signals: coefficient `k` of `x` goes to
    /// `out[off_a + k * stride]`, of `y` (if given) to `out[off_b + k * stride]`.
    pub fn analyze(
        &self,
        x: &[f64],
        second: Option<&[f64]>,
        out: &mut [f64],
        off_a: usize,
        off_b: usize,
        stride: usize,
        buf: &mut [Complex<f64>],
        scratch: &mut [Complex<f64>],
    ) {
        let (nc, nt) = (self.nc, self.nt);
        if !self.use_fft {
            for k in 0..nc {
                out[off_a + k * stride] = (0..nt).map(|j| self.weights[j * nc + k] * x[j]).sum();
            }
            if let Some(y) = second {
                for k in 0..nc {
                    out[off_b + k * stride] = (0..nt).map(|j| self.weights[j * nc + k] * y[j]).sum();
                }
            }
            return;
        }
        let buf = &mut buf[..nt];
        match second {
            Some(y) => {
                for j in 0..nt {
                    buf[j] = Complex::new(x[j], y[j]);
                }
            }
            None => {
                for j in 0..nt {
                    buf[j] = Complex::new(x[j], 0.0);
                }
            }
        }
        self.forward.process_with_scratch(buf, &mut scratch[..self.scratch_len]);
        match second {
            Some(_) => self.unpack_pair(buf, out, off_a, off_b, stride),
            None => self.unpack_one(buf, out, off_a, stride),
        }
    }

    /// Coefficients from the DFT `buf` of one real signal, to `out[off + k * stride]`.
    pub fn unpack_one(&self, buf: &[Complex<f64>], out: &mut [f64], off: usize, stride: usize) {
        let s = 1.0 / self.nt as f64;
        out[off] = buf[0].re * s;
        for h in 1..=(self.nc - 1) / 2 {
            out[off + (2 * h - 1) * stride] = 2.0 * s * buf[h].re;
            out[off + 2 * h * stride] = -2.0 * s * buf[h].im;
        }
    }

    /// Coefficients of `x` and `y` from the DFT `buf` of `x + i y`:
    /// `X_h = (Z_h + conj Z_{Nt-h}) / 2`, `Y_h = (Z_h - conj Z_{Nt-h}) / (2 i)`.
    pub fn unpack_pair(&self, buf: &[Complex<f64>], out: &mut [f64], off_a: usize, off_b: usize, stride: usize) {
        let nt = self.nt;
        let s = 1.0 / nt as f64;
        out[off_a] = buf[0].re * s;
        out[off_b] = buf[0].im * s;
        for h in 1..=(self.nc - 1) / 2 {
            let z = buf[h];
            let zc = buf[nt - h].conj();
            let x = (z + zc) * 0.5;
            let y = (z - zc) * Complex::new(0.0, -0.5);
            out[off_a + (2 * h - 1) * stride] = 2.0 * s * x.re;
            out[off_a + 2 * h * stride] = -2.0 * s * x.im;
            out[off_b + (2 * h - 1) * stride] = 2.0 * s * y.re;
            out[off_b + 2 * h * stride] = -2.0 * s * y.im;
        }
    }
}
