//! Full-DoF reduction FR (docs/formulation.md §9, paper (16)-(20)): `q_h = Φ_h p_h` on every DoF.
//!
//! `K`, `M`, `C` and the forces are projected once per harmonic, and the contact map is the
//! dense `W_h` = first `n_w` rows of `Φ_h`, so a reduced iteration (residual, Jacobian
//! `Φ^T (D + K̂) Φ`, AFT) never touches the `n` full DoFs. `K Φ_h`, `M Φ_h`, `C Φ_h` are kept
//! (`n x n_h` each) for the error predictor (40) and output recovery is through the output
//! rows of `T Φ_h`.
//!
//! Linear-DoF rows: the paper's FR keeps the JP modes' own rows ([`FrRom::with_jp_rows`]).
//! By default ([`FrRom::new`] on a basis that knows its band) they are rebuilt from the contact
//! rows by dynamic condensation at the band edges ([`band_condensed_basis`]), which makes FR as
//! accurate as NLR on the same basis; see that function for why.

use super::ReducedModel;
use crate::contact::{ContactLaw, Contacts};
use crate::error::{check_finite, JpError, Result};
use crate::hbm::{ContactMap, HarmonicLayout, HarmonicSystem, LinearPart};
use crate::jp::JpBasis;
use crate::model::contact_coordinates::dissipation;
use crate::model::ContactCoordinates;
use faer::Mat;

/// Per-harmonic projected matrices of the FR model.
#[derive(Clone, Debug)]
struct Projected {
    k: Mat<f64>,
    m: Mat<f64>,
    c: Mat<f64>,
    f_cos: Vec<f64>,
    f_sin: Vec<f64>,
    /// `W_h`: contact rows of `Φ_h`.
    w: Mat<f64>,
    /// Output rows of `T Φ_h`.
    out: Mat<f64>,
    /// `K Φ_h`, `M Φ_h`, `C Φ_h` (full size) and the full forces, for (40).
    k_phi: Mat<f64>,
    m_phi: Mat<f64>,
    c_phi: Mat<f64>,
    full_f_cos: Vec<f64>,
    full_f_sin: Vec<f64>,
}

/// The FR reduced model: a [`HarmonicSystem`] with `n_h` unknowns per harmonic.
#[derive(Clone, Debug)]
pub struct FrRom {
    layout: HarmonicLayout,
    laws: Vec<ContactLaw>,
    offsets: Vec<usize>,
    n_w: usize,
    n_dof: usize,
    n_outputs: usize,
    parts: Vec<Projected>,
    basis: JpBasis,
    /// Full `K`, `M`, `C` in contact coordinates, for the linear-DoF transfer of (40).
    full: (Mat<f64>, Mat<f64>, Mat<f64>),
    /// Structural loss factor `eta` (acts on `K`).
    loss_factor: f64,
    /// AFT samples, the coordinates' (`coords.discretisation`).
    nt: usize,
}

impl FrRom {
    /// FR of `coords` (built for at least `H` harmonics) on `basis`. When the basis knows its
    /// analysis band ([`JpBasis::band`], set by every JP constructor), the linear-DoF rows are
    /// those of [`band_condensed_basis`] over that band: NLR's accuracy at FR's cost, for about
    /// twice the first-harmonic size (blade, alpha_ST / 3000: X0 at the tip 10 % -> 9e-5,
    /// X1 7e-6 -> 3.5e-7; tests/jp_blade.rs). Without a band, as [`FrRom::with_jp_rows`].
    ///
    /// # Errors
    /// As [`FrRom::with_jp_rows`] and [`band_condensed_basis`].
    pub fn new(coords: &ContactCoordinates, basis: &JpBasis) -> Result<Self> {
        crate::jp::require_contacts("FR reduced model", coords.n_w)?;
        match basis.band {
            Some(band) => Self::band_condensed(coords, basis, band),
            None => Self::with_jp_rows(coords, basis),
        }
    }

    /// FR as the paper defines it (16)-(20): `q_h = Φ_h p_h` with the JP modes' own rows.
    /// Cost `O(n^2 n_h)` per harmonic, once.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if the basis does not match the model; [`JpError::InvalidValue`] if
    /// the basis has no first-harmonic column or `coords` lacks forces for some harmonic.
    pub fn with_jp_rows(coords: &ContactCoordinates, basis: &JpBasis) -> Result<Self> {
        crate::jp::require_contacts("FR reduced model", coords.n_w)?;
        let n = coords.n_dof;
        let hh = basis.harmonics();
        if basis.n_dof != n || basis.n_w != coords.n_w {
            return Err(JpError::bad_size("JP basis (rows)", n, basis.n_dof));
        }
        if coords.harmonic_force.len() < hh {
            return Err(JpError::invalid("model coordinates", format!("built for {} harmonics, basis has {hh}", coords.harmonic_force.len())));
        }
        if basis.sizes.get(1).copied().unwrap_or(0) == 0 {
            return Err(JpError::invalid("JP basis", "no first-harmonic column"));
        }
        let nw = coords.n_w;
        let mut parts = Vec::with_capacity(hh + 1);
        for h in 0..=hh {
            let phi = &basis.phi[h];
            let nh = phi.ncols();
            if phi.nrows() != n {
                return Err(JpError::bad_size(format!("JP basis harmonic {h} (rows)"), n, phi.nrows()));
            }
            let k_phi = &coords.stiffness * phi;
            let m_phi = &coords.mass * phi;
            let c_phi = &coords.damping * phi;
            let (fc, fs) = if h == 0 {
                (coords.static_force.clone(), vec![0.0; n])
            } else {
                coords.harmonic_force[h - 1].clone()
            };
            let project = |f: &[f64]| -> Vec<f64> { (0..nh).map(|j| (0..n).map(|i| phi[(i, j)] * f[i]).sum()).collect() };
            let out = Mat::from_fn(coords.output_dofs.len(), nh, |o, j| {
                coords.rows[coords.output_dofs[o]].iter().map(|&(k, t)| t * phi[(k, j)]).sum()
            });
            parts.push(Projected {
                k: phi.transpose() * &k_phi,
                m: phi.transpose() * &m_phi,
                c: phi.transpose() * &c_phi,
                f_cos: project(&fc),
                f_sin: project(&fs),
                w: phi.as_ref().subrows(0, nw).to_owned(),
                out,
                k_phi,
                m_phi,
                c_phi,
                full_f_cos: fc,
                full_f_sin: fs,
            });
        }
        Ok(FrRom {
            layout: HarmonicLayout::new(basis.sizes.clone()),
            laws: coords.laws.clone(),
            offsets: coords.offsets.clone(),
            n_w: nw,
            n_dof: n,
            n_outputs: coords.output_dofs.len(),
            parts,
            basis: basis.clone(),
            full: (coords.stiffness.clone(), coords.mass.clone(), coords.damping.clone()),
            loss_factor: coords.loss_factor,
            nt: coords.discretisation.nt(),
        })
    }

    /// FR on the band-condensed basis of `basis` ([`band_condensed_basis`]): linear-DoF rows
    /// that follow the contact motion as the condensation (12)-(15) does over `band`, so FR
    /// approaches NLR's accuracy at FR's cost per iteration.
    ///
    /// # Errors
    /// As [`band_condensed_basis`] and [`FrRom::new`].
    pub fn band_condensed(coords: &ContactCoordinates, basis: &JpBasis, band: (f64, f64)) -> Result<Self> {
        crate::jp::require_contacts("FR reduced model", coords.n_w)?;
        Self::with_jp_rows(coords, &band_condensed_basis(coords, basis, band)?)
    }

    /// Moves the linear-DoF rows `r_y` of `D_h Φ_h p_h - f_E^h` onto the contact rows:
    /// `f*_w -= D_h,wy D_h,yy^-1 r_y`. The contact rows then hold `H_h w_h - g_h`, the contact
    /// force that the reduced contact motion `w_h = W_h p_h` implies when the linear DoFs are
    /// in exact equilibrium (§5 condensation), i.e. the full-order residual at the reduced
    /// contact motion. This is (40) with FR's linear-DoF equilibrium error expressed as the
    /// contact force it stands for (the bare linear rows are in other units for a
    /// Craig-Bampton model; see [`crate::rom::error_metric`]). One dense factorisation of `D_h,yy`
    /// per harmonic: a post-processing cost, never paid inside the reduced iterations.
    fn transfer_linear_residual(&self, omega: f64, out: &mut [Vec<f64>]) -> Result<()> {
        let (n, nw) = (self.n_dof, self.n_w);
        let ny = n - nw;
        if ny == 0 {
            return Ok(());
        }
        let (k, m, c) = &self.full;
        for h in 0..=self.layout.harmonics {
            let hw = h as f64 * omega;
            let a = |i: usize, j: usize| k[(i, j)] - hw * hw * m[(i, j)];
            let b = |i: usize, j: usize| dissipation(hw, c[(i, j)], k[(i, j)], self.loss_factor);
            let sol = if h == 0 {
                let dyy = Mat::from_fn(ny, ny, |i, j| a(nw + i, nw + j));
                let r = Mat::from_fn(ny, 1, |i, _| out[0][nw + i]);
                crate::jp::lu_solve("D_0,yy (error predictor)", &dyy, &r)?
            } else {
                let dyy = Mat::from_fn(2 * ny, 2 * ny, |i, j| {
                    let (r, q) = (nw + i % ny, nw + j % ny);
                    match (i < ny, j < ny) {
                        (true, true) | (false, false) => a(r, q),
                        (true, false) => b(r, q),
                        (false, true) => -b(r, q),
                    }
                });
                let r = Mat::from_fn(2 * ny, 1, |i, _| if i < ny { out[2 * h - 1][nw + i] } else { out[2 * h][nw + i - ny] });
                crate::jp::lu_solve("D_h,yy (error predictor)", &dyy, &r)?
            };
            for i in 0..nw {
                if h == 0 {
                    out[0][i] -= (0..ny).map(|j| a(i, nw + j) * sol[(j, 0)]).sum::<f64>();
                } else {
                    let (mut dc, mut ds) = (0.0, 0.0);
                    for j in 0..ny {
                        let (xc, xs) = (sol[(j, 0)], sol[(ny + j, 0)]);
                        dc += a(i, nw + j) * xc + b(i, nw + j) * xs;
                        ds += -b(i, nw + j) * xc + a(i, nw + j) * xs;
                    }
                    out[2 * h - 1][i] -= dc;
                    out[2 * h][i] -= ds;
                }
            }
        }
        Ok(())
    }

    /// The basis the model projects on (for a band-condensed FR, the condensed one, not the JP
    /// basis it was made from).
    pub fn basis(&self) -> &JpBasis {
        &self.basis
    }

    fn check_z(&self, z: &[f64]) -> Result<()> {
        if z.len() != self.layout.total() {
            return Err(JpError::bad_size("reduced unknowns p", self.layout.total(), z.len()));
        }
        check_finite("reduced unknowns p", z)
    }

    /// Coefficient `k` of the reduced unknowns.
    fn coeff<'a>(&self, z: &'a [f64], k: usize) -> &'a [f64] {
        let (o, len) = self.layout.coeff_range(k);
        &z[o..o + len]
    }
}

fn mat_vec(a: &Mat<f64>, v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.nrows()];
    for (j, &x) in v.iter().enumerate() {
        if x != 0.0 {
            for (i, o) in out.iter_mut().enumerate() {
                *o += a[(i, j)] * x;
            }
        }
    }
    out
}

impl HarmonicSystem for FrRom {
    fn layout(&self) -> &HarmonicLayout {
        &self.layout
    }
    fn contacts(&self) -> Contacts<'_> {
        Contacts { laws: &self.laws, offsets: &self.offsets, n_w: self.n_w, nt: self.nt }
    }
    fn contact_map(&self, h: usize) -> ContactMap<'_> {
        ContactMap::Dense(self.parts[h].w.as_ref())
    }
    fn linear_part(&self, omega: f64) -> Result<LinearPart> {
        check_finite("omega", &[omega])?;
        if omega <= 0.0 {
            return Err(JpError::invalid("omega", format!("must be > 0, got {omega}")));
        }
        let p0 = &self.parts[0];
        let mut lin = LinearPart {
            d0: p0.k.clone().into(),
            f0: p0.f_cos.clone(),
            dh_re: Vec::new(),
            dh_im: Vec::new(),
            fh_cos: Vec::new(),
            fh_sin: Vec::new(),
        };
        for h in 1..=self.layout.harmonics {
            let p = &self.parts[h];
            let hw = h as f64 * omega;
            let nh = p.k.nrows();
            lin.dh_re.push(Mat::from_fn(nh, nh, |i, j| p.k[(i, j)] - hw * hw * p.m[(i, j)]).into());
            lin.dh_im.push(Mat::from_fn(nh, nh, |i, j| dissipation(hw, p.c[(i, j)], p.k[(i, j)], self.loss_factor)).into());
            lin.fh_cos.push(p.f_cos.clone());
            lin.fh_sin.push(p.f_sin.clone());
        }
        Ok(lin)
    }
    fn output_harmonics(&self, _omega: f64, z: &[f64]) -> Result<Vec<f64>> {
        self.check_z(z)?;
        let n_out = self.n_outputs;
        let nc = 2 * self.layout.harmonics + 1;
        let mut out = vec![0.0; nc * n_out];
        for k in 0..nc {
            let h = (k + 1) / 2;
            let v = mat_vec(&self.parts[h].out, self.coeff(z, k));
            out[k * n_out..(k + 1) * n_out].copy_from_slice(&v);
        }
        Ok(out)
    }
    fn n_outputs(&self) -> usize {
        self.n_outputs
    }
}

impl ReducedModel for FrRom {
    fn full_size(&self) -> usize {
        self.n_dof
    }
    fn implied_contact_force(&self, omega: f64, z: &[f64]) -> Result<Vec<Vec<f64>>> {
        self.check_z(z)?;
        let mut out = Vec::with_capacity(2 * self.layout.harmonics + 1);
        let p0 = &self.parts[0];
        let mut f0 = mat_vec(&p0.k_phi, self.coeff(z, 0));
        for (f, e) in f0.iter_mut().zip(&p0.full_f_cos) {
            *f -= e;
        }
        out.push(f0);
        for h in 1..=self.layout.harmonics {
            let p = &self.parts[h];
            let hw = h as f64 * omega;
            let (zc, zs) = (self.coeff(z, 2 * h - 1), self.coeff(z, 2 * h));
            let (kc, ks) = (mat_vec(&p.k_phi, zc), mat_vec(&p.k_phi, zs));
            let (mc, ms) = (mat_vec(&p.m_phi, zc), mat_vec(&p.m_phi, zs));
            let (cc, cs) = (mat_vec(&p.c_phi, zc), mat_vec(&p.c_phi, zs));
            let n = self.n_dof;
            let eta = self.loss_factor;
            let fc: Vec<f64> = (0..n).map(|i| kc[i] - hw * hw * mc[i] + (hw * cs[i] + eta * ks[i]) - p.full_f_cos[i]).collect();
            let fs: Vec<f64> = (0..n).map(|i| ks[i] - hw * hw * ms[i] - (hw * cc[i] + eta * kc[i]) - p.full_f_sin[i]).collect();
            out.push(fc);
            out.push(fs);
        }
        self.transfer_linear_residual(omega, &mut out)?;
        Ok(out)
    }
    fn full_coefficients(&self, _omega: f64, z: &[f64]) -> Result<Vec<Vec<f64>>> {
        self.check_z(z)?;
        let nc = 2 * self.layout.harmonics + 1;
        Ok((0..nc).map(|k| mat_vec(&self.basis.phi[(k + 1) / 2], self.coeff(z, k))).collect())
    }
}

/// Singular-value ratio below which [`band_condensed_basis`] treats columns as dependent: a
/// floor at the accuracy of the `D_yy` solves, not a `gamma`. The columns at the two band
/// edges differ by little, and that little is what they add at `h = 1` (near the resonance
/// the condensation varies across the band). At `h >= 2` it is often no more than the
/// solves' round-off: kept with a 1e10 floor, those noise directions stopped a blade H = 3
/// sweep after its first point (1e8: 200 points; X1 at gross slip 3.5e-7 against 6e-8).
const BAND_CONDENSED_RATIO: f64 = 1e8;

/// The FR basis whose linear-DoF rows follow its contact rows by dynamic condensation.
///
/// A JP eigenvector's linear rows are the condensation `y = -D_yy(λ)^-1 D_yw(λ) w` at its own
/// eigenvalue `λ`; the static corrections and the modes kept outside the band carry linear rows
/// of other frequencies. FR's Galerkin projection then distorts the small components of the
/// contact motion (the normal motion of sliding contacts) whose mean friction sets the static
/// term: on the blade at gross slip, X1 within 7e-6 but X0 off by 10 % (tests/jp_blade.rs).
/// Here, per harmonic `h >= 1`, with `Q_h` an orthonormal basis of the contact rows of `Φ_h`
/// and `D(ω) = K - (h ω)^2 M`, the columns are
/// `[Q_h; -D_yy^-1 D_yw Q_h]` and `[0; D_yy^-1 f_y^h]` (cos and sin) at both band edges
/// `ω = band.0, band.1`; for `h = 0` the same at `ω = 0` (static condensation and
/// `K_yy^-1 f_y^0`). Orthonormalised by SVD with a round-off floor. Any solution whose contact
/// motion lies in the span of `Q_h` is then represented up to the variation of the
/// condensation across the band (second order in the band width). NLR uses only the contact
/// rows, so this is the FR counterpart of the same basis.
///
/// # Errors
/// [`JpError::BadSize`] if `basis` does not match `coords`; [`JpError::InvalidValue`] for a
/// bad band; [`JpError::SingularMatrix`] if `D_yy` is singular at a band edge (a resonance of
/// the structure with its contacts clamped: use [`FrRom::new`] there).
pub fn band_condensed_basis(coords: &ContactCoordinates, basis: &JpBasis, band: (f64, f64)) -> Result<JpBasis> {
    let (n, nw) = (coords.n_dof, coords.n_w);
    if basis.n_dof != n || basis.n_w != nw {
        return Err(JpError::bad_size("JP basis (rows)", n, basis.n_dof));
    }
    let (lo, hi) = band;
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi >= lo) {
        return Err(JpError::invalid("band", format!("need 0 < omega_lo <= omega_hi, got ({lo}, {hi})")));
    }
    let hh = basis.harmonics();
    if coords.harmonic_force.len() < hh {
        return Err(JpError::invalid("model coordinates", format!("built for {} harmonics, basis has {hh}", coords.harmonic_force.len())));
    }
    let ny = n - nw;
    if ny == 0 {
        return Ok(basis.clone());
    }
    let mut phi = Vec::with_capacity(hh + 1);
    let mut singular_values = Vec::with_capacity(hh + 1);
    for h in 0..=hh {
        let q = crate::jp::condition(&basis.phi[h].as_ref().subrows(0, nw).to_owned(), BAND_CONDENSED_RATIO)?.basis;
        let (fc, fs) = if h == 0 { (coords.static_force.clone(), vec![0.0; n]) } else { coords.harmonic_force[h - 1].clone() };
        let loads: Vec<&[f64]> = [&fc[nw..], &fs[nw..]].into_iter().filter(|f| f.iter().any(|&x| x != 0.0)).collect();
        let omegas: Vec<f64> = if h == 0 { vec![0.0] } else if hi > lo { vec![lo, hi] } else { vec![lo] };
        let per = q.ncols() + loads.len();
        let mut raw = Mat::<f64>::zeros(n, per * omegas.len());
        for (e, &om) in omegas.iter().enumerate() {
            let hw2 = (h as f64 * om).powi(2);
            let d = |i: usize, j: usize| coords.stiffness[(i, j)] - hw2 * coords.mass[(i, j)];
            let dyy = Mat::from_fn(ny, ny, |i, j| d(nw + i, nw + j));
            let rhs = Mat::from_fn(ny, per, |i, j| {
                if j < q.ncols() {
                    -(0..nw).map(|k| d(nw + i, k) * q[(k, j)]).sum::<f64>()
                } else {
                    loads[j - q.ncols()][i]
                }
            });
            let y = crate::jp::lu_solve("D_yy at a band edge (band-condensed FR basis)", &dyy, &rhs)?;
            let at = e * per;
            raw.as_mut().submatrix_mut(0, at, nw, q.ncols()).copy_from(&q);
            raw.as_mut().submatrix_mut(nw, at, ny, per).copy_from(&y);
        }
        // Columns of very different lengths (a unit contact motion against its linear rows)
        // would let the SVD floor drop the short ones: scale each to unit length first.
        for j in 0..raw.ncols() {
            let norm = crate::jp::col_norm(&raw, j);
            if norm > 0.0 {
                for i in 0..n {
                    raw[(i, j)] /= norm;
                }
            }
        }
        let c = crate::jp::condition(&raw, BAND_CONDENSED_RATIO)?;
        phi.push(c.basis);
        singular_values.push(c.singular_values);
    }
    let sizes = phi.iter().map(|p| p.ncols()).collect();
    Ok(JpBasis { phi, sizes, singular_values, ..basis.clone() })
}
