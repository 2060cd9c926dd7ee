//! Condensation of the harmonic equations onto the contact coordinates (docs/formulation.md §7,
//! paper (12)-(15)).
//!
//! In the contact coordinates `z = [w; y]` of [`ContactCoordinates`] the contact forces act
//! on `w` only (the "nonlinear" set `N`, the leading `n_w` coordinates); the remaining
//! coordinates `L` are linear. Per harmonic, with complex `D_h = K - (h omega)^2 M + i h omega C`
//! and force `f_h = f_hc - i f_hs`:
//!
//! ```text
//! H_h = D_NN - D_NL D_LL^-1 D_LN                 (condensed dynamic stiffness)
//! g_h = f_N  - D_NL D_LL^-1 f_L                  (condensed force)
//! q_L = D_LL^-1 (f_L - D_LN q_N)                 (recovery, (13))
//! ```
//!
//! and `D_0 = K` (real) for the static term. The condensed system is exact for the linear
//! DoFs: its HBM solution equals the full-order one on `w`.
//!
//! The continuation needs `dR/domega`, so `dH_h/domega` and `dg_h/domega`. With
//! `D' = dD_h/domega = -2 h^2 omega M + i h C` (the loss factor's `i eta K` does not depend on
//! omega), `D` symmetric, `Y = D_LL^-1 D_LN` and `u = D_LL^-1 f_L` (both already solved for
//! `H_h` and `g_h`):
//!
//! ```text
//! H_h' = D'_NN - D'_LN^T Y - Y^T D'_LN + Y^T D'_LL Y
//! g_h' = - D'_LN^T u + Y^T D'_LL u
//! ```
//!
//! which costs products only: no second factorisation, where a central difference of `H_h`
//! costs two more ([`HarmonicSystem::linear_part_with_derivative_into`]).

use crate::contact::Contacts;
use crate::error::{JpError, Result};
use crate::hbm::options::check_omega;
use crate::aft::Discretisation;
use crate::hbm::{HarmonicLayout, HarmonicSystem, LinearPart};
use crate::linalg::{lu_checked, product};
use crate::model::contact_coordinates::dissipation;
use crate::model::{ContactCoordinates, Model};
use faer::{c64, Mat};

/// Estimated bytes of a condensed system of `n` DoFs, `n_w` of them contact coordinates,
/// beyond its coordinates: the static `K_LL` and its LU, `H_0` (`n_w` square), and one
/// harmonic's complex `D_LL`, its LU and right-hand sides at a frequency. Not the Newton
/// Jacobian on `(2H + 1) n_w` unknowns of a full-order solve on it
/// ([`crate::hbm::residual::dense_jacobian_bytes`], checked by the solve before its first
/// step): an NLR model projects the condensed system and never forms it.
pub fn working_set_bytes(n: usize, n_w: usize) -> u128 {
    use crate::memory::{bytes_of, product};
    let nl = n.saturating_sub(n_w);
    bytes_of::<f64>(product(&[2, nl, nl]))
        .saturating_add(bytes_of::<f64>(product(&[n_w, n_w])))
        .saturating_add(bytes_of::<c64>(product(&[2, nl, nl])))
        .saturating_add(bytes_of::<c64>(product(&[3, nl, n_w + 1])))
}

/// The condensed full-order system on the contact coordinates.
#[derive(Clone, Debug)]
pub struct CondensedSystem {
    coords: ContactCoordinates,
    layout: HarmonicLayout,
    /// Static condensation, `omega`-independent: `H_0` and `g_0`.
    h0: Mat<f64>,
    g0: Vec<f64>,
}

/// Complex `D_h` restricted to rows `r0..r0+nr`, columns `c0..c0+nc` of the z-coordinates.
fn block(c: &ContactCoordinates, omega: f64, h: usize, r0: usize, nr: usize, c0: usize, nc: usize) -> Mat<c64> {
    let hw = h as f64 * omega;
    Mat::from_fn(nr, nc, |i, j| {
        let (a, b) = (r0 + i, c0 + j);
        c64::new(c.stiffness[(a, b)] - hw * hw * c.mass[(a, b)], c.dissipation(hw, a, b))
    })
}

/// `D_h' = dD_h/domega = -2 h^2 omega M + i h C` restricted like [`block`].
fn d_block(c: &ContactCoordinates, omega: f64, h: usize, r0: usize, nr: usize, c0: usize, nc: usize) -> Mat<c64> {
    let (hf, w) = (h as f64, omega);
    Mat::from_fn(nr, nc, |i, j| {
        let (a, b) = (r0 + i, c0 + j);
        c64::new(-2.0 * hf * hf * w * c.mass[(a, b)], hf * c.damping[(a, b)])
    })
}

/// The derivative of a condensation (module doc): `H' = D'_NN - T - T^T + Y^T D'_LL Y` and
/// `g' = -D'_LN^T u + Y^T D'_LL u`, from `x = [Y u] = D_LL^-1 [D_LN f_L]`, `D'_NN` (`n x n`),
/// `D'_LN` (`n_L x n`) and `D'_LL`. Returns (Re H', Im H', cos g', sin g') with the force
/// convention `g = g_c - i g_s`.
fn condensation_derivative(x: &Mat<c64>, dnn: &Mat<c64>, dln: &Mat<c64>, dll: &Mat<c64>) -> (Mat<f64>, Mat<f64>, Vec<f64>, Vec<f64>) {
    let n = dnn.nrows();
    // T1 = D'_LN^T [Y u], T3 = Y^T D'_LL [Y u]
    let t1 = product(dln.transpose(), x.as_ref());
    let w = product(dll.as_ref(), x.as_ref());
    let t3 = product(x.as_ref().subcols(0, n).transpose(), w.as_ref());
    let h = |i: usize, j: usize| dnn[(i, j)] - t1[(i, j)] - t1[(j, i)] + t3[(i, j)];
    let re = Mat::from_fn(n, n, |i, j| h(i, j).re);
    let im = Mat::from_fn(n, n, |i, j| h(i, j).im);
    let g = |i: usize| t3[(i, n)] - t1[(i, n)];
    (re, im, (0..n).map(|i| g(i).re).collect(), (0..n).map(|i| -g(i).im).collect())
}

/// A linear part's derivative with respect to omega: `D_0' = 0`, `f_0' = 0` (the static term
/// does not depend on omega) and the harmonics' `(Re D_h', Im D_h', f_hc', f_hs')`.
fn derivative_part(n0: usize, harmonics: Vec<(Mat<f64>, Mat<f64>, Vec<f64>, Vec<f64>)>) -> LinearPart {
    let mut d = LinearPart { d0: Mat::<f64>::zeros(n0, n0).into(), f0: vec![0.0; n0], dh_re: Vec::new(), dh_im: Vec::new(), fh_cos: Vec::new(), fh_sin: Vec::new() };
    for (re, im, gc, gs) in harmonics {
        d.dh_re.push(re.into());
        d.dh_im.push(im.into());
        d.fh_cos.push(gc);
        d.fh_sin.push(gs);
    }
    d
}

impl CondensedSystem {
    /// Builds the condensed system with the harmonics and AFT samples of `discretisation`
    /// (`H` alone takes the default `Nt`) and does the static condensation (`h = 0`) once.
    ///
    /// # Errors
    /// The model's validation errors; [`JpError::InvalidValue`] if the model has no contact
    /// (nothing to condense onto) or bad options; [`JpError::SingularMatrix`] if `K_LL` is
    /// singular (the structure is not held when its contact nodes are fixed).
    pub fn new(model: &Model, discretisation: impl Into<Discretisation>) -> Result<Self> {
        if model.contacts.is_empty() {
            return Err(JpError::invalid("CondensedSystem", "the model has no contact to condense onto"));
        }
        // the coordinates check the discretisation
        let coords = ContactCoordinates::new(model, discretisation.into())?;
        let (n, nw) = (coords.n_dof, coords.n_w);
        let hh = coords.discretisation.harmonics;
        crate::memory::check(
            &format!("the condensed system at H = {hh} ({nw} contact coordinates, {} linear DoFs)", n - nw),
            working_set_bytes(n, nw),
        )?;
        let nl = n - nw;
        let k = &coords.stiffness;
        let (h0, g0) = if nl == 0 {
            (k.clone(), coords.static_force.clone())
        } else {
            let kll = Mat::from_fn(nl, nl, |i, j| k[(nw + i, nw + j)]);
            let lu = lu_checked(
                &kll,
                "K_LL (static block of the linear DoFs; is the structure held without its contacts?)",
            )?;
            let rhs = Mat::from_fn(nl, nw + 1, |i, j| {
                if j < nw {
                    k[(nw + i, j)]
                } else {
                    coords.static_force[nw + i]
                }
            });
            let x = lu.solve(&rhs);
            let h0 = Mat::from_fn(nw, nw, |i, j| k[(i, j)] - (0..nl).map(|l| k[(i, nw + l)] * x[(l, j)]).sum::<f64>());
            let g0 = (0..nw)
                .map(|i| coords.static_force[i] - (0..nl).map(|l| k[(i, nw + l)] * x[(l, nw)]).sum::<f64>())
                .collect();
            (h0, g0)
        };
        let layout = HarmonicLayout::uniform(coords.discretisation.harmonics, nw);
        Ok(CondensedSystem { coords, layout, h0, g0 })
    }

    /// The model in contact coordinates.
    pub fn coordinates(&self) -> &ContactCoordinates {
        &self.coords
    }

    /// Condensed dynamic stiffness `H_h(omega)` (real and imaginary parts, `n_w x n_w`) and
    /// condensed force (cos and sin parts) of harmonic `h` (`h = 0`: `H_0`, `g_0`, zero
    /// imaginary / sin parts).
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] if `D_h,LL` is singular at this frequency;
    /// [`JpError::InvalidValue`] for `omega <= 0` or `h > H`.
    #[allow(clippy::type_complexity)]
    pub fn condensed_harmonic(&self, omega: f64, h: usize) -> Result<(Mat<f64>, Mat<f64>, Vec<f64>, Vec<f64>)> {
        Ok(self.condensed_harmonic_and_derivative(omega, h, false)?.0)
    }

    /// [`CondensedSystem::condensed_harmonic`] and, when asked, its derivative with respect to
    /// omega in the same form (module doc; `h >= 1`), from the same factorisation.
    ///
    /// # Errors
    /// As [`CondensedSystem::condensed_harmonic`].
    #[allow(clippy::type_complexity)]
    fn condensed_harmonic_and_derivative(&self, omega: f64, h: usize, derivative: bool) -> Result<((Mat<f64>, Mat<f64>, Vec<f64>, Vec<f64>), Option<(Mat<f64>, Mat<f64>, Vec<f64>, Vec<f64>)>)> {
        check_omega(omega)?;
        let nw = self.coords.n_w;
        if h == 0 {
            return Ok(((self.h0.clone(), Mat::zeros(nw, nw), self.g0.clone(), vec![0.0; nw]), None));
        }
        if h > self.layout.harmonics {
            return Err(JpError::invalid("harmonic", format!("{h} > H = {}", self.layout.harmonics)));
        }
        let c = &self.coords;
        let nl = c.n_dof - nw;
        let (fc, fs) = &c.harmonic_force[h - 1];
        let d_nn = block(c, omega, h, 0, nw, 0, nw);
        let d_nn_prime = derivative.then(|| d_block(c, omega, h, 0, nw, 0, nw));
        if nl == 0 {
            let re = Mat::from_fn(nw, nw, |i, j| d_nn[(i, j)].re);
            let im = Mat::from_fn(nw, nw, |i, j| d_nn[(i, j)].im);
            let d = d_nn_prime.map(|dp| (Mat::from_fn(nw, nw, |i, j| dp[(i, j)].re), Mat::from_fn(nw, nw, |i, j| dp[(i, j)].im), vec![0.0; nw], vec![0.0; nw]));
            return Ok(((re, im, fc[..nw].to_vec(), fs[..nw].to_vec()), d));
        }
        let d_ll = block(c, omega, h, nw, nl, nw, nl);
        let lu = lu_checked(&d_ll, &format!("D_LL of harmonic {h} at omega = {omega}"))?;
        let mut rhs = block(c, omega, h, nw, nl, 0, nw + 1);
        for i in 0..nl {
            rhs[(i, nw)] = c64::new(fc[nw + i], -fs[nw + i]);
        }
        let x = lu.solve(&rhs);
        let d_nl = block(c, omega, h, 0, nw, nw, nl);
        let prod = product(d_nl.as_ref(), x.as_ref());
        let re = Mat::from_fn(nw, nw, |i, j| d_nn[(i, j)].re - prod[(i, j)].re);
        let im = Mat::from_fn(nw, nw, |i, j| d_nn[(i, j)].im - prod[(i, j)].im);
        // g = f_N - D_NL D_LL^-1 f_L with f = f_c - i f_s: cos = Re g, sin = -Im g.
        let gc = (0..nw).map(|i| fc[i] - prod[(i, nw)].re).collect();
        let gs = (0..nw).map(|i| fs[i] + prod[(i, nw)].im).collect();
        let d = d_nn_prime.map(|dnn| {
            let dln = d_block(c, omega, h, nw, nl, 0, nw);
            let dll = d_block(c, omega, h, nw, nl, nw, nl);
            condensation_derivative(&x, &dnn, &dln, &dll)
        });
        Ok(((re, im, gc, gs), d))
    }

    /// `H_h q_h - g_h` of the condensed unknowns `q` (harmonic-major, `(2H + 1) n_w`) per
    /// harmonic coefficient (`0`, then cos and sin of each `h`), without forming `H_h`: with
    /// the linear coordinates recovered by (13) ([`CondensedSystem::recover`], one right-hand
    /// side per harmonic), `H_h q_N - g_h = D_NN q_N + D_NL q_L - f_N` (the condensed linear part
    /// would solve `n_w + 1`). The NLR error predictor's `f*_C` (docs/formulation.md §10).
    ///
    /// # Errors
    /// [`JpError::BadSize`] for a wrong length of `q`; as [`CondensedSystem::recover`].
    pub fn linear_residual_parts(&self, omega: f64, q: &[f64]) -> Result<Vec<Vec<f64>>> {
        check_omega(omega)?;
        let c = &self.coords;
        let (n, nw) = (c.n_dof, c.n_w);
        let hh = self.layout.harmonics;
        if q.len() != (2 * hh + 1) * nw {
            return Err(JpError::bad_size("condensed unknowns", (2 * hh + 1) * nw, q.len()));
        }
        let mut out = Vec::with_capacity(2 * hh + 1);
        let h0q = product(self.h0.as_ref(), Mat::from_fn(nw, 1, |i, _| q[i]).as_ref());
        out.push((0..nw).map(|i| h0q[(i, 0)] - self.g0[i]).collect());
        for h in 1..=hh {
            let (fc, fs) = &c.harmonic_force[h - 1];
            let (full_c, full_s) = self.recover(omega, h, &q[(2 * h - 1) * nw..2 * h * nw], &q[2 * h * nw..(2 * h + 1) * nw])?;
            // complex z = z_c - i z_s, f = f_c - i f_s (module doc's convention); r = r_c - i r_s
            let z = Mat::from_fn(n, 1, |i, _| c64::new(full_c[i], -full_s[i]));
            let r = product(block(c, omega, h, 0, nw, 0, n).as_ref(), z.as_ref());
            out.push((0..nw).map(|i| r[(i, 0)].re - fc[i]).collect());
            out.push((0..nw).map(|i| -r[(i, 0)].im - fs[i]).collect());
        }
        Ok(out)
    }

    /// Condensed dynamic stiffness `H_h(omega) = D_NN - D_NL D_LL^-1 D_LN` as (real,
    /// imaginary) parts; for the JP NLR model (docs/formulation.md §9).
    ///
    /// # Errors
    /// As [`CondensedSystem::condensed_harmonic`].
    pub fn condensed_dynamic_stiffness(&self, omega: f64, h: usize) -> Result<(Mat<f64>, Mat<f64>)> {
        let (re, im, _, _) = self.condensed_harmonic(omega, h)?;
        Ok((re, im))
    }

    /// Recovers all z-coordinates of one harmonic coefficient from the contact part,
    /// `q_L = D_LL^-1 (f_L - D_LN q_N)` ((13)); `h = 0` uses `K`. `zc`, `zs` are the cos
    /// and sin parts (`zs` ignored for `h = 0`). Returns the full (cos, sin) parts.
    ///
    /// # Errors
    /// As [`CondensedSystem::condensed_harmonic`].
    pub fn recover(&self, omega: f64, h: usize, zc: &[f64], zs: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
        let c = &self.coords;
        let (n, nw) = (c.n_dof, c.n_w);
        let nl = n - nw;
        let mut full_c = zc.to_vec();
        let mut full_s = zs.to_vec();
        full_c.resize(n, 0.0);
        full_s.resize(n, 0.0);
        if nl == 0 {
            return Ok((full_c, full_s));
        }
        if h == 0 {
            let k = &c.stiffness;
            let kll = Mat::from_fn(nl, nl, |i, j| k[(nw + i, nw + j)]);
            let lu = lu_checked(&kll, "K_LL")?;
            let rhs = Mat::from_fn(nl, 1, |i, _| {
                c.static_force[nw + i] - (0..nw).map(|j| k[(nw + i, j)] * zc[j]).sum::<f64>()
            });
            let x = lu.solve(&rhs);
            for i in 0..nl {
                full_c[nw + i] = x[(i, 0)];
            }
            return Ok((full_c, full_s));
        }
        check_omega(omega)?;
        let (fc, fs) = &c.harmonic_force[h - 1];
        let d_ll = block(c, omega, h, nw, nl, nw, nl);
        let lu = lu_checked(&d_ll, &format!("D_LL of harmonic {h} at omega = {omega}"))?;
        let d_ln = block(c, omega, h, nw, nl, 0, nw);
        let rhs = Mat::from_fn(nl, 1, |i, _| {
            let mut s = c64::new(fc[nw + i], -fs[nw + i]);
            for j in 0..nw {
                s -= d_ln[(i, j)] * c64::new(zc[j], -zs[j]);
            }
            s
        });
        let x = lu.solve(&rhs);
        for i in 0..nl {
            full_c[nw + i] = x[(i, 0)].re;
            full_s[nw + i] = -x[(i, 0)].im;
        }
        Ok((full_c, full_s))
    }
}

impl CondensedSystem {
    /// The linear part at `omega` and, when asked, its derivative with respect to omega
    /// (module doc).
    fn linear_part_and_derivative(&self, omega: f64, derivative: bool) -> Result<(LinearPart, Option<LinearPart>)> {
        check_omega(omega)?;
        let mut lin = LinearPart {
            d0: self.h0.clone().into(),
            f0: self.g0.clone(),
            dh_re: Vec::new(),
            dh_im: Vec::new(),
            fh_cos: Vec::new(),
            fh_sin: Vec::new(),
        };
        let mut harmonics = Vec::new();
        for h in 1..=self.layout.harmonics {
            let ((re, im, gc, gs), d) = self.condensed_harmonic_and_derivative(omega, h, derivative)?;
            lin.dh_re.push(re.into());
            lin.dh_im.push(im.into());
            lin.fh_cos.push(gc);
            lin.fh_sin.push(gs);
            harmonics.extend(d);
        }
        let d = derivative.then(|| derivative_part(self.layout.size(0), harmonics));
        Ok((lin, d))
    }
}

impl HarmonicSystem for CondensedSystem {
    fn layout(&self) -> &HarmonicLayout {
        &self.layout
    }
    fn contacts(&self) -> Contacts<'_> {
        self.coords.contacts()
    }
    fn linear_part(&self, omega: f64) -> Result<LinearPart> {
        Ok(self.linear_part_and_derivative(omega, false)?.0)
    }
    fn linear_part_with_derivative_into(&self, omega: f64, out: &mut Option<LinearPart>, derivative: &mut Option<LinearPart>) -> Result<bool> {
        let (lin, d) = self.linear_part_and_derivative(omega, true)?;
        *out = Some(lin);
        *derivative = d;
        Ok(true)
    }
    fn output_harmonics(&self, omega: f64, z: &[f64]) -> Result<Vec<f64>> {
        if z.len() != self.layout.total() {
            return Err(JpError::bad_size("HBM unknowns z", self.layout.total(), z.len()));
        }
        let nw = self.coords.n_w;
        let n_out = self.coords.output_dofs.len();
        let n_coeffs = 2 * self.layout.harmonics + 1;
        let mut out = vec![0.0; n_coeffs * n_out];
        if n_out == 0 {
            return Ok(out);
        }
        let (full0, _) = self.recover(omega, 0, &z[..nw], &[])?;
        out[..n_out].copy_from_slice(&self.coords.at_outputs(&full0));
        for h in 1..=self.layout.harmonics {
            let (oc, os) = (self.layout.cos_offset(h), self.layout.sin_offset(h));
            let (fc, fs) = self.recover(omega, h, &z[oc..oc + nw], &z[os..os + nw])?;
            let k = 2 * h - 1;
            out[k * n_out..(k + 1) * n_out].copy_from_slice(&self.coords.at_outputs(&fc));
            out[(k + 1) * n_out..(k + 2) * n_out].copy_from_slice(&self.coords.at_outputs(&fs));
        }
        Ok(out)
    }
    fn n_outputs(&self) -> usize {
        self.coords.output_dofs.len()
    }
}

/// The condensed linear part (docs/formulation.md §7) projected onto per-harmonic contact-row bases
/// `P_h` (`n_w x n_h`), without forming any `n_w x n_w` matrix per frequency:
///
/// ```text
/// P^T H_h P = P^T D_NN P - (D_LN P)^T D_LL^-1 (D_LN P),
/// P^T g_h   = P^T f_N   - (D_LN P)^T D_LL^-1 f_L
/// ```
///
/// (`D` symmetric), with `P^T A_NN P` and `A_LN P` for `A = K, M, C` formed once. A frequency
/// then costs an LU of the `n_L`-square `D_LL` and products of size `n_L x n_h`, instead of the
/// `O(n_w^2 n_L)` condensation and `O(n_w^2 n_h)` projection of the dense `H_h`. This is the
/// linear part of the JP NLR model (docs/formulation.md §9).
#[derive(Clone, Debug)]
pub struct ProjectedCondensation {
    harmonics: usize,
    /// `P_0^T H_0 P_0`, `P_0^T g_0`.
    d0: Mat<f64>,
    f0: Vec<f64>,
    /// Per harmonic `h = 1..=H`: `P^T A_NN P` and `A_LN P` for `A = K, M, C`, and the
    /// projected contact-row force and the linear-row force (cos, sin).
    nn: Vec<[Mat<f64>; 3]>,
    ln: Vec<[Mat<f64>; 3]>,
    f_n: Vec<(Vec<f64>, Vec<f64>)>,
    f_l: Vec<(Vec<f64>, Vec<f64>)>,
    /// `A_LL` for `A = K, M, C`.
    ll: [Mat<f64>; 3],
    /// Structural loss factor `eta` (acts on the projected `K`).
    loss_factor: f64,
}

impl CondensedSystem {
    /// The projection of this system's linear part onto `bases[h]` (`n_w` rows each,
    /// `h = 0..=H`), see [`ProjectedCondensation`].
    ///
    /// # Errors
    /// [`JpError::BadSize`] for a wrong number of bases or of rows.
    pub fn project(&self, bases: &[Mat<f64>]) -> Result<ProjectedCondensation> {
        let c = &self.coords;
        let (n, nw) = (c.n_dof, c.n_w);
        let nl = n - nw;
        let hh = self.layout.harmonics;
        if bases.len() != hh + 1 {
            return Err(JpError::bad_size("projection bases (harmonics + 1)", hh + 1, bases.len()));
        }
        if let Some(b) = bases.iter().find(|b| b.nrows() != nw) {
            return Err(JpError::bad_size("projection basis (rows)", nw, b.nrows()));
        }
        let mats = [&c.stiffness, &c.mass, &c.damping];
        let p0 = &bases[0];
        let d0 = p0.transpose() * &self.h0 * p0;
        let f0 = (0..p0.ncols()).map(|j| (0..nw).map(|i| p0[(i, j)] * self.g0[i]).sum()).collect();
        let ll = mats.map(|a| a.as_ref().submatrix(nw, nw, nl, nl).to_owned());
        let mut nn = Vec::with_capacity(hh);
        let mut ln = Vec::with_capacity(hh);
        let mut f_n = Vec::with_capacity(hh);
        let mut f_l = Vec::with_capacity(hh);
        for h in 1..=hh {
            let p = &bases[h];
            nn.push(mats.map(|a| p.transpose() * a.as_ref().submatrix(0, 0, nw, nw) * p));
            ln.push(mats.map(|a| a.as_ref().submatrix(nw, 0, nl, nw) * p));
            let (fc, fs) = &c.harmonic_force[h - 1];
            let proj = |f: &[f64]| -> Vec<f64> { (0..p.ncols()).map(|j| (0..nw).map(|i| p[(i, j)] * f[i]).sum()).collect() };
            f_n.push((proj(fc), proj(fs)));
            f_l.push((fc[nw..].to_vec(), fs[nw..].to_vec()));
        }
        Ok(ProjectedCondensation { harmonics: hh, d0, f0, nn, ln, f_n, f_l, ll, loss_factor: c.loss_factor })
    }
}

impl ProjectedCondensation {
    /// The projected linear part at `omega` (the [`LinearPart`] of the reduced unknowns).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] for `omega <= 0`; [`JpError::SingularMatrix`] if `D_LL` is
    /// singular at this frequency.
    pub fn linear_part(&self, omega: f64) -> Result<LinearPart> {
        Ok(self.linear_part_and_derivative(omega, false)?.0)
    }

    /// [`ProjectedCondensation::linear_part`] and, when asked, its derivative with respect to
    /// omega (the module doc's formulas on the projected blocks, from the same factorisation).
    ///
    /// # Errors
    /// As [`ProjectedCondensation::linear_part`].
    pub fn linear_part_and_derivative(&self, omega: f64, derivative: bool) -> Result<(LinearPart, Option<LinearPart>)> {
        check_omega(omega)?;
        let mut harmonics = Vec::new();
        let mut lin = LinearPart {
            d0: self.d0.clone().into(),
            f0: self.f0.clone(),
            dh_re: Vec::new(),
            dh_im: Vec::new(),
            fh_cos: Vec::new(),
            fh_sin: Vec::new(),
        };
        let nl = self.ll[0].nrows();
        let eta = self.loss_factor;
        for h in 1..=self.harmonics {
            let hw = h as f64 * omega;
            let d = |a: &[Mat<f64>; 3], i: usize, j: usize| c64::new(a[0][(i, j)] - hw * hw * a[1][(i, j)], dissipation(hw, a[2][(i, j)], a[0][(i, j)], eta));
            let nn = &self.nn[h - 1];
            let nh = nn[0].nrows();
            let mut re = Mat::from_fn(nh, nh, |i, j| d(nn, i, j).re);
            let mut im = Mat::from_fn(nh, nh, |i, j| d(nn, i, j).im);
            let (mut gc, mut gs) = self.f_n[h - 1].clone();
            // D_h' = -2 h^2 omega M + i h C of stored blocks `a = [K, M, C]`
            let hf = h as f64;
            let dp = |a: &[Mat<f64>; 3], i: usize, j: usize| c64::new(-2.0 * hf * hf * omega * a[1][(i, j)], hf * a[2][(i, j)]);
            let dnn = derivative.then(|| Mat::from_fn(nh, nh, |i, j| dp(nn, i, j)));
            if nl == 0 {
                if let Some(d) = &dnn {
                    harmonics.push((Mat::from_fn(nh, nh, |i, j| d[(i, j)].re), Mat::from_fn(nh, nh, |i, j| d[(i, j)].im), vec![0.0; nh], vec![0.0; nh]));
                }
            } else {
                let d_ll = Mat::from_fn(nl, nl, |i, j| d(&self.ll, i, j));
                let lu = lu_checked(&d_ll, &format!("D_LL of harmonic {h} at omega = {omega}"))?;
                let ln = &self.ln[h - 1];
                let (fc, fs) = &self.f_l[h - 1];
                let dlnp = Mat::from_fn(nl, nh, |i, j| d(ln, i, j));
                let mut rhs = Mat::<c64>::zeros(nl, nh + 1);
                rhs.as_mut().subcols_mut(0, nh).copy_from(&dlnp);
                for i in 0..nl {
                    rhs[(i, nh)] = c64::new(fc[i], -fs[i]);
                }
                let x = lu.solve(&rhs);
                let prod = product(dlnp.transpose(), x.as_ref());
                for j in 0..nh {
                    for i in 0..nh {
                        re[(i, j)] -= prod[(i, j)].re;
                        im[(i, j)] -= prod[(i, j)].im;
                    }
                }
                for i in 0..nh {
                    gc[i] -= prod[(i, nh)].re;
                    gs[i] += prod[(i, nh)].im;
                }
                if let Some(dnn) = dnn {
                    let dln = Mat::from_fn(nl, nh, |i, j| dp(ln, i, j));
                    let dll = Mat::from_fn(nl, nl, |i, j| dp(&self.ll, i, j));
                    harmonics.push(condensation_derivative(&x, &dnn, &dln, &dll));
                }
            }
            lin.dh_re.push(re.into());
            lin.dh_im.push(im.into());
            lin.fh_cos.push(gc);
            lin.fh_sin.push(gs);
        }
        let d = derivative.then(|| derivative_part(self.d0.nrows(), harmonics));
        Ok((lin, d))
    }
}
