//! Alternating frequency-time (AFT) evaluation of the contact forces and of their analytical
//! Jacobian (docs/formulation.md §4).
//!
//! Harmonic coefficients use the real layout `k = 0` (static), `k = 2h - 1` (cos `h`),
//! `k = 2h` (sin `h`), `h = 1..=H`, so `2H + 1` coefficients per coordinate:
//! `x(t) = c_0 + sum_h (c_{2h-1} cos(h w t) + c_{2h} sin(h w t))`.
//!
//! * For **one contact** of dimension `d` (3 for the 3D element, 1 for Jenkins), vectors are
//!   coefficient-major: entry `k * d + i` is coefficient `k` of local coordinate `i`.
//!   Its Jacobian block is `n x n`, `n = d (2H + 1)`, column-major:
//!   `jac[row + col * n] = dF_row / dw_col`.
//! * For **all contacts** of a system, vectors are harmonic-major over the contact
//!   coordinates: entry `k * n_w + offset_c + i`.
//!
//! `F` is the element force (`T1, T2, N` for 3D), positive when it resists `w`; the force on
//! the structure is `-F`. So `dF/dw` is the contact stiffness `K̂` of docs/formulation.md §2.

mod discretisation;
mod fourier;
mod period;

pub use discretisation::{default_nt, Discretisation};
pub use fourier::{AftBackend, TABLES_MAX_H};

use crate::contact::elastic::{Friction2D, Polynomial, Unilateral};
use crate::contact::jenkins::Jenkins;
use crate::contact::law::Friction3D;
use crate::contact::{ContactLaw, ContactState, ExternalLaw, SampleLaw};
use crate::error::{JpError, Result};
use fourier::Fourier;
use rustfft::num_complex::Complex;
use serde::{Deserialize, Serialize};

/// Maximum number of passes over the period when looking for the periodic stick/slip state.
pub const MAX_PASSES: usize = 5;
/// Relative tolerance on the tangential state at the start of the period (docs/formulation.md §4.2).
pub const PERIODIC_TOLERANCE: f64 = 1e-12;

/// What one contact did over one steady-state period.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactCycle {
    /// State at each of the `Nt` time samples (the "boundary condition" of §6).
    pub states: Vec<ContactState>,
    /// Energy dissipated by friction per cycle: the work of the friction force over the slip
    /// increments, `W = sum over slipping samples of T . Kt^-1 (T* - T)` (the slip increment is
    /// the part of `du` the tangential spring does not take, `Kt^-1 (T* - T)`). Each term is
    /// `>= 0` (in slip `T` is `T*` scaled down), so `W >= 0`, `W = 0` exactly in full stick, and
    /// for the Jenkins element under `u = a cos(w t)` it tends to `4 Fs (a - Fs / kt)` as the
    /// samples get finer.
    pub dissipated_energy: f64,
}

/// FFT plans and sizes for a given number of harmonics `H` and time samples `Nt`.
/// Made once, shared (read-only) by all threads.
pub struct AftPlan {
    harmonics: usize,
    nt: usize,
    fourier: Fourier,
}

/// Per-thread scratch memory of the AFT, so that the contact loop does not allocate.
#[derive(Clone, Debug, Default)]
pub struct AftWorkspace {
    /// `(H, Nt)` the buffers are sized for.
    key: (usize, usize),
    /// Samples `u1 | u2 | v` (or `u` for Jenkins), `3 Nt`.
    x: Vec<f64>,
    /// Tangential force samples `T1 | T2`, `2 Nt`.
    tangential: Vec<f64>,
    /// Normal force samples and `dN/dv` per sample.
    normal: Vec<f64>,
    d_normal: Vec<f64>,
    states: Vec<ContactState>,
    /// `dT(t_j)/dw` per sample: `g[j * 2n + r * n + col]`.
    g: Vec<f64>,
    /// Derivative of the start state of the current pass, and a temporary, `2n` each.
    g_start: Vec<f64>,
    g_tmp: Vec<f64>,
    /// Accumulators of the table DFT of the Jacobian: `2 nc n` tangential, `nc^2` normal.
    acc: Vec<f64>,
    buf: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    /// Gathered local coefficients of one contact (used by [`evaluate_contacts`]).
    w_local: Vec<f64>,
    /// Force, Jacobian and cycle of one member of a [`ContactLaw::Parallel`] (sized on first
    /// use, then reused).
    member_force: Vec<f64>,
    member_jac: Vec<f64>,
    member_cycle: ContactCycle,
    /// Force samples `d Nt` and Jacobian samples `d^2 Nt` of an [`ContactLaw::External`] law
    /// (sized on first use, then reused).
    ext_force: Vec<f64>,
    ext_jac: Vec<f64>,
    /// The first failure of an [`ContactLaw::External`] law since it was last taken.
    error: Option<JpError>,
}

impl AftWorkspace {
    /// The first failure of an [`ContactLaw::External`] law recorded by
    /// [`AftPlan::contact`] since the last call, if any (and forgets it).
    pub fn take_error(&mut self) -> Option<JpError> {
        self.error.take()
    }
}

impl AftPlan {
    /// Plans for `H = harmonics >= 1` and `nt` samples (a power of two, `>= 4 (H + 1)`),
    /// with [`AftBackend::Auto`].
    ///
    /// # Errors
    /// As [`Discretisation::validate`]: [`JpError::InvalidValue`] if `H = 0` or `nt` is not a
    /// power of two `>= 4 (H + 1)`, [`JpError::OverLimit`] above jprom's caps.
    pub fn new(harmonics: usize, nt: usize) -> Result<Self> {
        Self::with_backend(harmonics, nt, AftBackend::Auto)
    }

    /// As [`AftPlan::new`], with an explicit transform backend.
    ///
    /// # Errors
    /// As [`AftPlan::new`].
    pub fn with_backend(harmonics: usize, nt: usize, backend: AftBackend) -> Result<Self> {
        // one owner of the checks (and the caps, before the tables are sized by them)
        Discretisation::with_nt(harmonics, nt).validate()?;
        Ok(AftPlan { harmonics, nt, fourier: Fourier::new(harmonics, nt, backend) })
    }
    /// `H`.
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }
    /// `Nt`.
    pub fn nt(&self) -> usize {
        self.nt
    }
    /// `2H + 1`.
    pub fn n_coeffs(&self) -> usize {
        2 * self.harmonics + 1
    }
    /// Whether the transforms go through rustfft (`true`) or the cos/sin tables.
    pub fn uses_fft(&self) -> bool {
        self.fourier.use_fft
    }
    /// Scratch for contacts of dimension up to 3.
    pub fn workspace(&self) -> AftWorkspace {
        let (nt, nc) = (self.nt, self.n_coeffs());
        let n = 3 * nc;
        AftWorkspace {
            key: (self.harmonics, nt),
            x: vec![0.0; 3 * nt],
            tangential: vec![0.0; 2 * nt],
            normal: vec![0.0; nt],
            d_normal: vec![0.0; nt],
            states: vec![ContactState::Stick; nt],
            g: vec![0.0; nt * 2 * n],
            g_start: vec![0.0; 2 * n],
            g_tmp: vec![0.0; 2 * n],
            acc: vec![0.0; 2 * nc * n + nc * nc],
            buf: vec![Complex::new(0.0, 0.0); nt],
            scratch: vec![Complex::new(0.0, 0.0); self.fourier.scratch_len.max(1)],
            w_local: vec![0.0; n],
            member_force: Vec::new(),
            member_jac: Vec::new(),
            member_cycle: ContactCycle::default(),
            ext_force: Vec::new(),
            ext_jac: Vec::new(),
            error: None,
        }
    }

    /// Harmonics of the force of one contact for the local displacement harmonics `w`,
    /// with optionally its analytical Jacobian and its cycle report. Layouts in the module doc.
    ///
    /// The time loop runs over the period from the start state `T = Kt u(t_{-1})` projected
    /// on the friction cone, then repeats from each pass's end state until the start state
    /// repeats ([`PERIODIC_TOLERANCE`], at most [`MAX_PASSES`] passes); forces, states and
    /// derivatives come from the last pass, whose start-state derivative is carried through
    /// the earlier passes, so `jac` is the exact derivative of the returned force.
    ///
    /// An [`ContactLaw::External`] law (docs/formulation.md §4.6) takes the memoryless path
    /// instead: `F_h = DFT f(w(t_j))`, `jac = DFT diag(dF/dw(t_j)) IDFT`, states `Stick` and no
    /// dissipated energy. If its callable fails, `force`, `jac` and the cycle's energy are NaN
    /// and the error is kept in `ws` ([`AftWorkspace::take_error`]; the first one is kept);
    /// [`AftPlan::try_contact`] returns it instead.
    ///
    /// # Panics
    /// If `w` or `force` are not of length `n = dim (2H + 1)`, `jac` not of length `n^2`,
    /// or `ws` was made by a plan with another `(H, Nt)` (programming errors).
    pub fn contact(
        &self,
        law: &ContactLaw,
        w: &[f64],
        force: &mut [f64],
        jac: Option<&mut [f64]>,
        cycle: Option<&mut ContactCycle>,
        ws: &mut AftWorkspace,
    ) {
        let n = law.dim() * self.n_coeffs();
        assert_eq!(ws.key, (self.harmonics, self.nt), "AftWorkspace made for another plan");
        assert_eq!(w.len(), n, "w length");
        assert_eq!(force.len(), n, "force length");
        if let Some(j) = &jac {
            assert_eq!(j.len(), n * n, "jac length");
        }
        match law {
            ContactLaw::Friction3D { .. } => {
                let p = Friction3D::from_law(law).expect("3D law");
                self.contact_law(&p, w, force, jac, cycle, ws)
            }
            ContactLaw::Jenkins { .. } => {
                let p = Jenkins::from_law(law).expect("Jenkins law");
                self.contact_law(&p, w, force, jac, cycle, ws)
            }
            ContactLaw::Polynomial { .. } => {
                let p = Polynomial::from_law(law).expect("polynomial law");
                self.contact_law(&p, w, force, jac, cycle, ws)
            }
            ContactLaw::Unilateral { .. } => {
                let p = Unilateral::from_law(law).expect("unilateral law");
                self.contact_law(&p, w, force, jac, cycle, ws)
            }
            ContactLaw::Friction2D { .. } => {
                let p = Friction2D::from_law(law).expect("2D law");
                self.contact_law(&p, w, force, jac, cycle, ws)
            }
            ContactLaw::Parallel(laws) => self.contact_parallel(laws, w, force, jac, cycle, ws),
            ContactLaw::External(law) => self.contact_external(law, w, force, jac, cycle, ws),
        }
    }

    /// [`AftPlan::contact`], with the failure of an [`ContactLaw::External`] law as an error.
    ///
    /// # Errors
    /// [`JpError::Callback`] naming the law, the time sample and the reason.
    ///
    /// # Panics
    /// As [`AftPlan::contact`].
    pub fn try_contact(
        &self,
        law: &ContactLaw,
        w: &[f64],
        force: &mut [f64],
        jac: Option<&mut [f64]>,
        cycle: Option<&mut ContactCycle>,
        ws: &mut AftWorkspace,
    ) -> Result<()> {
        ws.error = None;
        self.contact(law, w, force, jac, cycle, ws);
        ws.error.take().map_or(Ok(()), Err)
    }

    /// The memoryless path of an [`ContactLaw::External`] law: no chain through the samples,
    /// `dF(t_j)/dw_h = dF/dw(t_j) b_h(t_j)`, so each entry `(r, s)` of the per-sample Jacobian
    /// contributes the `nc x nc` block `DFT (dF_r/dw_s(t_j) b_k(t_j))` (one transform per pair
    /// of columns `k`).
    fn contact_external(
        &self,
        law: &ExternalLaw,
        w: &[f64],
        force: &mut [f64],
        jac: Option<&mut [f64]>,
        cycle: Option<&mut ContactCycle>,
        ws: &mut AftWorkspace,
    ) {
        let f = &self.fourier;
        let (nt, nc) = (self.nt, f.nc);
        let d = law.dim();
        let n = d * nc;
        let AftWorkspace { x, tangential, buf, scratch, ext_force, ext_jac, error, .. } = ws;
        ext_force.resize(3 * nt, 0.0);
        ext_jac.resize(9 * nt, 0.0);
        let mut i = 0;
        while i < d {
            let (a, rest) = x[i * nt..].split_at_mut(nt);
            if i + 1 < d {
                f.synthesize(w, d, i, a, Some((i + 1, &mut rest[..nt])), buf, scratch);
            } else {
                f.synthesize(w, d, i, a, None, buf, scratch);
            }
            i += 2;
        }
        let (mut wj, mut fj, mut jj) = ([0.0; 3], [0.0; 3], [0.0; 9]);
        for j in 0..nt {
            for i in 0..d {
                wj[i] = x[i * nt + j];
            }
            if let Err(reason) = law.eval(&wj[..d], &mut fj[..d], &mut jj[..d * d]) {
                if error.is_none() {
                    *error = Some(JpError::Callback { element: law.name_or_default(), sample: j, reason });
                }
                force.fill(f64::NAN);
                if let Some(jac) = jac {
                    jac.fill(f64::NAN);
                }
                if let Some(cy) = cycle {
                    cy.states.clear();
                    cy.states.resize(nt, ContactState::Stick);
                    cy.dissipated_energy = f64::NAN;
                }
                return;
            }
            for i in 0..d {
                ext_force[i * nt + j] = fj[i];
            }
            for e in 0..d * d {
                ext_jac[e * nt + j] = jj[e];
            }
        }
        for i in 0..d {
            f.analyze(&ext_force[i * nt..(i + 1) * nt], None, force, i, i, d, buf, scratch);
        }
        if let Some(cy) = cycle {
            cy.states.clear();
            cy.states.resize(nt, ContactState::Stick);
            cy.dissipated_energy = 0.0;
        }
        let Some(jac) = jac else { return };
        jac.fill(0.0);
        let basis = &f.basis;
        let (ya, yb) = tangential.split_at_mut(nt);
        for s in 0..d {
            for r in 0..d {
                let g = &ext_jac[(r + s * d) * nt..(r + s * d + 1) * nt];
                if g.iter().all(|&v| v == 0.0) {
                    continue;
                }
                let mut k = 0;
                while k < nc {
                    let k2 = k + 1;
                    for j in 0..nt {
                        ya[j] = g[j] * basis[j * nc + k];
                    }
                    if k2 < nc {
                        for j in 0..nt {
                            yb[j] = g[j] * basis[j * nc + k2];
                        }
                        f.analyze(ya, Some(&yb[..nt]), jac, r + (k * d + s) * n, r + (k2 * d + s) * n, d, buf, scratch);
                    } else {
                        f.analyze(ya, None, jac, r + (k * d + s) * n, r + (k * d + s) * n, d, buf, scratch);
                    }
                    k += 2;
                }
            }
        }
    }

    /// The members of a [`ContactLaw::Parallel`] one after the other on the same `w`: forces,
    /// Jacobians and dissipated energies summed; the state of a sample is `Slip` if a member
    /// slips, else `Stick` if a member acts, else `Separated`.
    fn contact_parallel(
        &self,
        laws: &[ContactLaw],
        w: &[f64],
        force: &mut [f64],
        mut jac: Option<&mut [f64]>,
        mut cycle: Option<&mut ContactCycle>,
        ws: &mut AftWorkspace,
    ) {
        let n = force.len();
        force.fill(0.0);
        if let Some(j) = jac.as_deref_mut() {
            j.fill(0.0);
        }
        let mut f_m = std::mem::take(&mut ws.member_force);
        let mut j_m = std::mem::take(&mut ws.member_jac);
        let mut cy_m = std::mem::take(&mut ws.member_cycle);
        f_m.resize(n, 0.0);
        if jac.is_some() {
            j_m.resize(n * n, 0.0);
        }
        for (i, law) in laws.iter().enumerate() {
            let jm = if jac.is_some() { Some(&mut j_m[..n * n]) } else { None };
            let cm = if cycle.is_some() { Some(&mut cy_m) } else { None };
            // Members are never Parallel themselves (ContactLaw::validate).
            self.contact(law, w, &mut f_m[..n], jm, cm, ws);
            for (o, v) in force.iter_mut().zip(&f_m[..n]) {
                *o += v;
            }
            if let Some(j) = jac.as_deref_mut() {
                for (o, v) in j.iter_mut().zip(&j_m[..n * n]) {
                    *o += v;
                }
            }
            if let Some(cy) = cycle.as_deref_mut() {
                if i == 0 {
                    cy.states.clear();
                    cy.states.extend_from_slice(&cy_m.states);
                    cy.dissipated_energy = cy_m.dissipated_energy;
                } else {
                    for (s, &sm) in cy.states.iter_mut().zip(&cy_m.states) {
                        *s = match (*s, sm) {
                            (ContactState::Slip, _) | (_, ContactState::Slip) => ContactState::Slip,
                            (ContactState::Stick, _) | (_, ContactState::Stick) => ContactState::Stick,
                            _ => ContactState::Separated,
                        };
                    }
                    cy.dissipated_energy += cy_m.dissipated_energy;
                }
            }
        }
        ws.member_force = f_m;
        ws.member_jac = j_m;
        ws.member_cycle = cy_m;
    }

    /// The one chain-rule loop over the period for any [`SampleLaw`] (docs/formulation.md §3):
    /// forces sample by sample, `dT(t_j)/dw` carried from sample to sample, the dissipated
    /// energy, then the forward transforms of the forces and of their derivatives.
    fn contact_law<L: SampleLaw>(
        &self,
        p: &L,
        w: &[f64],
        force: &mut [f64],
        jac: Option<&mut [f64]>,
        cycle: Option<&mut ContactCycle>,
        ws: &mut AftWorkspace,
    ) {
        let f = &self.fourier;
        let (nt, nc) = (self.nt, f.nc);
        let m = L::TANGENTIAL;
        let d = m + usize::from(L::HAS_NORMAL);
        let n = d * nc;
        // `dT(t_j)/dw` of one sample: `m` rows of `n`
        let nm = m * n;
        let want_jac = jac.is_some();
        let AftWorkspace { x, tangential, normal, d_normal, states, g, g_start, g_tmp, acc, buf, scratch, .. } = ws;
        let (u1, rest) = x.split_at_mut(nt);
        let (u2, v) = rest.split_at_mut(nt);
        let v = &mut v[..nt];
        if m == 2 {
            f.synthesize(w, d, 0, u1, Some((1, u2)), buf, scratch);
        } else if m == 1 {
            f.synthesize(w, d, 0, u1, None, buf, scratch);
            u2.fill(0.0);
        } else {
            // No tangential direction (memoryless scalar laws): the predictor sees no motion.
            u1.fill(0.0);
            u2.fill(0.0);
        }
        if L::HAS_NORMAL {
            f.synthesize(w, d, m, v, None, buf, scratch);
        }
        for j in 0..nt {
            let (nj, dj) = if L::HAS_NORMAL { p.normal(v[j]) } else { (0.0, 0.0) };
            normal[j] = nj;
            d_normal[j] = dj;
        }
        let basis = &f.basis;
        let kt = p.tangential_stiffness();

        // First start state: Kt u(t_{-1}) through the corrector, so that full stick is exactly
        // linear.
        let last = nt - 1;
        let c0 = p.correct([kt[0] * u1[last], kt[1] * u2[last]], normal[last]);
        if want_jac {
            let y = &mut g_tmp[..nm];
            y.fill(0.0);
            let bl = &basis[last * nc..(last + 1) * nc];
            period::add_elastic::<L>(y, kt, bl, None, n);
            period::slip_map::<L>(&c0.d_predictor, &c0.d_normal, d_normal[last], bl, y, &mut g_start[..nm], n);
        }
        let samples = period::Samples { u1, u2, normal: &normal[..nt], d_normal: &d_normal[..nt], basis, nc, n };
        let g_bufs = if want_jac { Some((&mut g[..], &mut g_start[..], &mut g_tmp[..])) } else { None };
        let dissipated = period::steady_state(p, &samples, c0, period::SteadyOut { tangential, states, g: g_bufs });

        // Forward DFT of the forces.
        let (t1, t2) = tangential.split_at(nt);
        if m == 2 {
            f.analyze(t1, Some(&t2[..nt]), force, 0, 1, d, buf, scratch);
        } else if m == 1 {
            f.analyze(t1, None, force, 0, 0, d, buf, scratch);
        }
        if L::HAS_NORMAL {
            f.analyze(&normal[..nt], None, force, m, m, d, buf, scratch);
        }

        if let Some(cy) = cycle {
            cy.states.clear();
            cy.states.extend_from_slice(&states[..nt]);
            cy.dissipated_energy = dissipated;
        }

        let Some(jac) = jac else { return };
        jac.fill(0.0);
        if !f.use_fft {
            // Tables: jac rows (k', r) = sum_j weight_k'(t_j) dF_r(t_j)/dw.
            let (acc_t, acc_n) = acc.split_at_mut(m * nc * n);
            acc_t.fill(0.0);
            let acc_n = &mut acc_n[..nc * nc];
            acc_n.fill(0.0);
            for j in 0..nt {
                if states[j] == ContactState::Separated {
                    continue;
                }
                let fj = &f.weights[j * nc..(j + 1) * nc];
                let gj = &g[j * nm..(j + 1) * nm];
                for r in 0..m {
                    let gr = &gj[r * n..(r + 1) * n];
                    for kk in 0..nc {
                        let a = fj[kk];
                        let row = &mut acc_t[(r * nc + kk) * n..(r * nc + kk + 1) * n];
                        for (o, &gv) in row.iter_mut().zip(gr) {
                            *o += a * gv;
                        }
                    }
                }
                let dn = d_normal[j];
                if L::HAS_NORMAL && dn != 0.0 {
                    let bj = &basis[j * nc..(j + 1) * nc];
                    for kk in 0..nc {
                        let a = fj[kk] * dn;
                        let row = &mut acc_n[kk * nc..(kk + 1) * nc];
                        for (o, &b) in row.iter_mut().zip(bj) {
                            *o += a * b;
                        }
                    }
                }
            }
            for r in 0..m {
                for kk in 0..nc {
                    let row = &acc_t[(r * nc + kk) * n..(r * nc + kk + 1) * n];
                    for (col, &val) in row.iter().enumerate() {
                        jac[(kk * d + r) + col * n] = val;
                    }
                }
            }
            if L::HAS_NORMAL {
                for kk in 0..nc {
                    for k in 0..nc {
                        jac[(kk * d + m) + (k * d + m) * n] = acc_n[kk * nc + k];
                    }
                }
            }
        } else {
            // FFT: two real columns per complex transform.
            for r in 0..m {
                let mut col = 0;
                while col < n {
                    let c2 = col + 1;
                    let b = &mut buf[..nt];
                    for j in 0..nt {
                        let base = j * nm + r * n;
                        let im = if c2 < n { g[base + c2] } else { 0.0 };
                        b[j] = Complex::new(g[base + col], im);
                    }
                    f.forward.process_with_scratch(b, &mut scratch[..f.scratch_len]);
                    if c2 < n {
                        f.unpack_pair(b, jac, r + col * n, r + c2 * n, d);
                    } else {
                        f.unpack_one(b, jac, r + col * n, d);
                    }
                    col += 2;
                }
            }
            if L::HAS_NORMAL {
                let mut k = 0;
                while k < nc {
                    let k2 = k + 1;
                    let b = &mut buf[..nt];
                    for j in 0..nt {
                        let dn = d_normal[j];
                        let im = if k2 < nc { dn * basis[j * nc + k2] } else { 0.0 };
                        b[j] = Complex::new(dn * basis[j * nc + k], im);
                    }
                    f.forward.process_with_scratch(b, &mut scratch[..f.scratch_len]);
                    if k2 < nc {
                        f.unpack_pair(b, jac, m + (k * d + m) * n, m + (k2 * d + m) * n, d);
                    } else {
                        f.unpack_one(b, jac, m + (k * d + m) * n, d);
                    }
                    k += 2;
                }
            }
        }
    }
}

/// Forces, Jacobian blocks and cycle reports of all contacts of a system.
#[derive(Clone, Debug, Default)]
pub struct ContactForces {
    /// Harmonic-major force coefficients, length `(2H + 1) n_w`.
    pub force: Vec<f64>,
    /// Concatenated per-contact Jacobian blocks (column-major, contact-local layout).
    pub jac: Vec<f64>,
    /// Start of each contact's block in `jac`.
    pub jac_offsets: Vec<usize>,
    /// One report per contact (filled when asked for).
    pub cycles: Vec<ContactCycle>,
    /// Contact-major local forces (scratch, so that the parallel loop writes disjoint slices).
    local_force: Vec<f64>,
    /// One workspace per parallel chunk, kept across calls.
    workspaces: Vec<AftWorkspace>,
    /// The first failure of an [`ContactLaw::External`] law in the last evaluation.
    error: Option<JpError>,
}

impl ContactForces {
    /// The failure of an [`ContactLaw::External`] law in the last [`evaluate_contacts`] (its
    /// outputs are then NaN), if any, and forgets it.
    pub fn take_error(&mut self) -> Option<JpError> {
        self.error.take()
    }

    /// `Err` with the failure of the last [`evaluate_contacts`], if any.
    ///
    /// # Errors
    /// [`JpError::Callback`] naming the element, the time sample and the reason.
    pub fn check(&mut self) -> Result<()> {
        self.take_error().map_or(Ok(()), Err)
    }
}

/// Whether [`evaluate_contacts_with`] may run in parallel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Threading {
    /// rayon over contacts when there are at least [`PARALLEL_MIN_CONTACTS`] contacts.
    #[default]
    Auto,
    /// One thread.
    Sequential,
}

/// Below this many contacts [`Threading::Auto`] stays sequential (one contact costs a few
/// microseconds, less than distributing work over threads).
pub const PARALLEL_MIN_CONTACTS: usize = 32;

/// Evaluates every contact (in parallel over contacts) for the harmonic-major contact
/// displacement `w_all` (length `(2H + 1) n_w`); `offsets[c]` is contact `c`'s first
/// coordinate in `w`. Fills `out` (resized as needed, reused across calls). If an
/// [`ContactLaw::External`] law fails, its outputs are NaN and the error is kept in `out`:
/// callers check [`ContactForces::check`] (or [`ContactForces::take_error`]).
///
/// # Panics
/// If `laws` and `offsets` differ in length, `w_all` is not of length `(2H + 1) n_w`, or a
/// contact's coordinates run past `n_w` (programming errors).
#[allow(clippy::too_many_arguments)]
pub fn evaluate_contacts(
    plan: &AftPlan,
    laws: &[ContactLaw],
    offsets: &[usize],
    n_w: usize,
    w_all: &[f64],
    want_jacobian: bool,
    want_cycles: bool,
    out: &mut ContactForces,
) {
    evaluate_contacts_with(plan, laws, offsets, n_w, w_all, want_jacobian, want_cycles, out, Threading::Auto)
}

/// [`evaluate_contacts`] with an explicit [`Threading`].
///
/// # Panics
/// As [`evaluate_contacts`].
#[allow(clippy::too_many_arguments)]
pub fn evaluate_contacts_with(
    plan: &AftPlan,
    laws: &[ContactLaw],
    offsets: &[usize],
    n_w: usize,
    w_all: &[f64],
    want_jacobian: bool,
    want_cycles: bool,
    out: &mut ContactForces,
    threading: Threading,
) {
    let nc = plan.n_coeffs();
    assert_eq!(laws.len(), offsets.len(), "one offset per contact");
    assert_eq!(w_all.len(), nc * n_w, "w_all length");
    for (law, &off) in laws.iter().zip(offsets) {
        assert!(off + law.dim() <= n_w, "contact coordinates past n_w");
    }
    // Sizes (no allocation when they are unchanged).
    out.force.resize(nc * n_w, 0.0);
    out.jac_offsets.clear();
    let mut n_jac = 0;
    let mut n_local = 0;
    for law in laws {
        out.jac_offsets.push(n_jac);
        let n = law.dim() * nc;
        n_jac += n * n;
        n_local += n;
    }
    out.jac.resize(if want_jacobian { n_jac } else { 0 }, 0.0);
    out.local_force.resize(n_local, 0.0);
    if want_cycles {
        out.cycles.resize_with(laws.len(), ContactCycle::default);
    } else {
        out.cycles.clear();
    }
    let leaves = match threading {
        Threading::Sequential => 1,
        Threading::Auto if laws.len() < PARALLEL_MIN_CONTACTS => 1,
        Threading::Auto => (laws.len() / 16).clamp(1, 4 * rayon::current_num_threads()),
    };
    let key = (plan.harmonics, plan.nt);
    if out.workspaces.len() < leaves || out.workspaces.iter().any(|w| w.key != key) {
        out.workspaces = (0..leaves).map(|_| plan.workspace()).collect();
    }
    let task = Task {
        plan,
        laws,
        offsets,
        n_w,
        w_all,
        jac: if want_jacobian { Some(&mut out.jac[..]) } else { None },
        local_force: &mut out.local_force[..],
        cycles: if want_cycles { Some(&mut out.cycles[..]) } else { None },
    };
    for ws in &mut out.workspaces {
        ws.error = None;
    }
    task.run(&mut out.workspaces[..leaves]);
    // leaves hold contacts in order: the first error is the lowest-numbered failing contact's
    out.error = out.workspaces.iter_mut().find_map(AftWorkspace::take_error);
    // Scatter the contact-major local forces to the harmonic-major layout.
    let mut pos = 0;
    for (law, &off) in laws.iter().zip(offsets) {
        let d = law.dim();
        for k in 0..nc {
            for i in 0..d {
                out.force[k * n_w + off + i] = out.local_force[pos + k * d + i];
            }
        }
        pos += d * nc;
    }
}

/// A contiguous range of contacts with their output slices.
struct Task<'a> {
    plan: &'a AftPlan,
    laws: &'a [ContactLaw],
    offsets: &'a [usize],
    n_w: usize,
    w_all: &'a [f64],
    jac: Option<&'a mut [f64]>,
    local_force: &'a mut [f64],
    cycles: Option<&'a mut [ContactCycle]>,
}

impl<'a> Task<'a> {
    /// Runs on `ws.len()` leaves: splits in two with `rayon::join` until one workspace is left.
    fn run(self, ws: &mut [AftWorkspace]) {
        if ws.len() <= 1 || self.laws.len() <= 1 {
            self.run_sequential(&mut ws[0]);
            return;
        }
        let half = ws.len() / 2;
        let m = self.laws.len() * half / ws.len();
        let (left, right) = self.split(m);
        let (ws_l, ws_r) = ws.split_at_mut(half);
        rayon::join(|| left.run(ws_l), || right.run(ws_r));
    }

    fn split(self, m: usize) -> (Task<'a>, Task<'a>) {
        let nc = self.plan.n_coeffs();
        let (mut n_jac, mut n_local) = (0, 0);
        for law in &self.laws[..m] {
            let n = law.dim() * nc;
            n_jac += n * n;
            n_local += n;
        }
        let (lf_l, lf_r) = self.local_force.split_at_mut(n_local);
        let (jac_l, jac_r) = match self.jac {
            Some(j) => {
                let (a, b) = j.split_at_mut(n_jac);
                (Some(a), Some(b))
            }
            None => (None, None),
        };
        let (cy_l, cy_r) = match self.cycles {
            Some(c) => {
                let (a, b) = c.split_at_mut(m);
                (Some(a), Some(b))
            }
            None => (None, None),
        };
        (
            Task {
                plan: self.plan,
                laws: &self.laws[..m],
                offsets: &self.offsets[..m],
                n_w: self.n_w,
                w_all: self.w_all,
                jac: jac_l,
                local_force: lf_l,
                cycles: cy_l,
            },
            Task {
                plan: self.plan,
                laws: &self.laws[m..],
                offsets: &self.offsets[m..],
                n_w: self.n_w,
                w_all: self.w_all,
                jac: jac_r,
                local_force: lf_r,
                cycles: cy_r,
            },
        )
    }

    fn run_sequential(self, ws: &mut AftWorkspace) {
        let nc = self.plan.n_coeffs();
        let mut w_local = std::mem::take(&mut ws.w_local);
        let (mut pos_f, mut pos_j) = (0, 0);
        let mut jac = self.jac;
        let mut cycles = self.cycles;
        for (c, (law, &off)) in self.laws.iter().zip(self.offsets).enumerate() {
            let d = law.dim();
            let n = d * nc;
            for k in 0..nc {
                for i in 0..d {
                    w_local[k * d + i] = self.w_all[k * self.n_w + off + i];
                }
            }
            let jac_c = jac.as_deref_mut().map(|j| &mut j[pos_j..pos_j + n * n]);
            let cycle_c = cycles.as_deref_mut().map(|cy| &mut cy[c]);
            self.plan.contact(law, &w_local[..n], &mut self.local_force[pos_f..pos_f + n], jac_c, cycle_c, ws);
            pos_f += n;
            pos_j += n * n;
        }
        ws.w_local = w_local;
    }
}
