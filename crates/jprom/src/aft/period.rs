//! The steady state of a law with memory over one period (docs/formulation.md §4.3): passes
//! of the predictor-corrector recursion from the elastic start `T = Kt u(t_{-1})` on the
//! friction cone, each from the last one's end state, until the start state repeats or
//! [`MAX_PASSES`] have run; forces, states and derivatives come from the last pass, the start
//! state's derivative carried from pass to pass, so that the Jacobian is exact for the force
//! returned.
//!
//! A pass maps a perturbation of its start state unchanged through stick, through the
//! corrector's `dT/dT*` in slip (its part across the slip direction scaled by `mu N / |T*|`),
//! and to zero where the contact opens. So the state repeats after one or two passes where a
//! contact opens, slips in one direction or sticks throughout; a contact that barely slips in
//! a turning direction approaches its periodic state by `mu N / |T*|` per slipping sample, and
//! after `MAX_PASSES` passes the state is short of the periodic one. The exact fixed point of the period map is
//! not used: as the slip of such a contact vanishes, the fixed point's part across the slip
//! direction at the slipping sample is zero while the stuck state's (the elastic start) is
//! not, so the force would jump at the onset of slip, and the residual with it.

use super::{MAX_PASSES, PERIODIC_TOLERANCE};
use crate::contact::{law, ContactState, SampleLaw};

/// The samples a pass runs over, and the layout of the derivatives.
pub(super) struct Samples<'a> {
    pub u1: &'a [f64],
    pub u2: &'a [f64],
    pub normal: &'a [f64],
    pub d_normal: &'a [f64],
    /// `basis[j nc + k]`: the value of coefficient `k`'s basis function at sample `j`.
    pub basis: &'a [f64],
    pub nc: usize,
    /// Columns of a sample's derivative (`d nc`).
    pub n: usize,
}

/// What a pass writes: forces and states per sample and, when asked, `dT(t_j)/dw` (`g`, from
/// `g_start`, with the scratch `g_tmp`).
pub(super) struct PassOut<'a> {
    pub tangential: &'a mut [f64],
    pub states: &'a mut [ContactState],
    pub g: Option<(&'a mut [f64], &'a [f64], &'a mut [f64])>,
}

/// The end of a pass: the last sample's force, the largest force norm met (the start's
/// included) and the friction work.
#[derive(Clone, Copy)]
pub(super) struct PassEnd {
    pub t_end: [f64; 2],
    pub scale: f64,
    pub dissipated: f64,
}

#[inline]
fn norm2(t: [f64; 2]) -> f64 {
    (t[0] * t[0] + t[1] * t[1]).sqrt()
}

/// One pass of the recursion over the period from `t_start`.
pub(super) fn pass<L: SampleLaw>(p: &L, s: &Samples, t_start: [f64; 2], out: PassOut<'_>) -> PassEnd {
    let nt = s.normal.len();
    let m = L::TANGENTIAL;
    let n = s.n;
    let nm = m * n;
    let nc = s.nc;
    let kt = p.tangential_stiffness();
    let PassOut { tangential, states, mut g } = out;
    let mut t_prev = t_start;
    let mut scale = norm2(t_start);
    let mut dissipated = 0.0;
    for j in 0..nt {
        let jm = if j == 0 { nt - 1 } else { j - 1 };
        let ts = p.predictor(t_prev, [s.u1[j] - s.u1[jm], s.u2[j] - s.u2[jm]]);
        let c = p.correct(ts, s.normal[j]);
        tangential[j] = c.force[0];
        if m == 2 {
            tangential[nt + j] = c.force[1];
        }
        states[j] = c.state;
        if c.state == ContactState::Slip {
            dissipated += p.slip_work(ts, c.force);
        }
        t_prev = c.force;
        scale = scale.max(norm2(c.force));
        if let Some((g, g_start, g_tmp)) = g.as_mut() {
            // dT_j/dw from dT_{j-1}/dw (chain rule through the sample, §3)
            let (before, after) = g.split_at_mut(j * nm);
            let prev: &[f64] = if j == 0 { &g_start[..nm] } else { &before[(j - 1) * nm..] };
            let out = &mut after[..nm];
            let bj = &s.basis[j * nc..(j + 1) * nc];
            let bm = &s.basis[jm * nc..(jm + 1) * nc];
            match c.state {
                ContactState::Separated => out.fill(0.0),
                ContactState::Stick => {
                    out.copy_from_slice(prev);
                    add_elastic::<L>(out, kt, bj, Some(bm), n);
                }
                ContactState::Slip => {
                    let y = &mut g_tmp[..nm];
                    y.copy_from_slice(prev);
                    add_elastic::<L>(y, kt, bj, Some(bm), n);
                    slip_map::<L>(&c.d_predictor, &c.d_normal, s.d_normal[j], bj, y, out, n);
                }
            }
        }
    }
    PassEnd { t_end: t_prev, scale, dissipated }
}

/// The buffers [`steady_state`] writes (see [`PassOut`]).
pub(super) struct SteadyOut<'a> {
    pub tangential: &'a mut [f64],
    pub states: &'a mut [ContactState],
    /// `g`, `g_start`, `g_tmp` as in [`PassOut`] (`g_start` is overwritten)
    pub g: Option<(&'a mut [f64], &'a mut [f64], &'a mut [f64])>,
}

/// The steady pass from the start state `start` (the elastic start of the module doc, and
/// its derivative in `g_start` when derivatives are asked for): passes from each pass's end
/// state until the start state repeats ([`PERIODIC_TOLERANCE`]) or [`MAX_PASSES`] have run,
/// the start state's derivative carried from pass to pass. The friction work of the last.
pub(super) fn steady_state<L: SampleLaw>(p: &L, s: &Samples, start: law::Corrector, out: SteadyOut<'_>) -> f64 {
    let nm = L::TANGENTIAL * s.n;
    let nt = s.normal.len();
    let SteadyOut { tangential, states, mut g } = out;
    let mut t_start = start.force;
    let mut dissipated = 0.0;
    for pass_index in 0..MAX_PASSES {
        let g_arg = g.as_mut().map(|(g, g0, gt)| (&mut **g, &**g0, &mut **gt));
        let e = pass(p, s, t_start, PassOut { tangential, states, g: g_arg });
        dissipated = e.dissipated;
        let diff = norm2([e.t_end[0] - t_start[0], e.t_end[1] - t_start[1]]);
        if diff <= PERIODIC_TOLERANCE * e.scale || pass_index + 1 == MAX_PASSES {
            break;
        }
        t_start = e.t_end;
        if let Some((g, g0, _)) = g.as_mut() {
            g0[..nm].copy_from_slice(&g[(nt - 1) * nm..nt * nm]);
        }
    }
    dissipated
}

/// `y[r n + k d + r] += kt_r (b_k - b_prev_k)`: the predictor's derivative
/// `Kt d(u(t_j) - u(t_{j-1}))/dw` added to `y` (`b_prev` absent: `Kt du(t_j)/dw`).
#[inline]
pub(super) fn add_elastic<L: SampleLaw>(y: &mut [f64], kt: [f64; 2], b: &[f64], b_prev: Option<&[f64]>, n: usize) {
    let m = L::TANGENTIAL;
    let d = m + usize::from(L::HAS_NORMAL);
    for (k, &bk) in b.iter().enumerate() {
        let db = match b_prev {
            Some(bp) => bk - bp[k],
            None => bk,
        };
        for r in 0..m {
            y[r * n + k * d + r] += kt[r] * db;
        }
    }
}

/// `out = a y + dT/dN dN/dv b_j` (rows `r` of `n`): the corrector's derivative applied to the
/// predictor's, plus the normal force's.
pub(super) fn slip_map<L: SampleLaw>(a: &[[f64; 2]; 2], dt_dn: &[f64; 2], dn_dv: f64, bj: &[f64], y: &[f64], out: &mut [f64], n: usize) {
    let m = L::TANGENTIAL;
    let d = m + usize::from(L::HAS_NORMAL);
    for r in 0..m {
        let o = &mut out[r * n..(r + 1) * n];
        for (c, oc) in o.iter_mut().enumerate() {
            *oc = (0..m).map(|s| a[r][s] * y[s * n + c]).sum();
        }
    }
    if L::HAS_NORMAL && dn_dv != 0.0 {
        for r in 0..m {
            if dt_dn[r] == 0.0 {
                continue;
            }
            for (k, &b) in bj.iter().enumerate() {
                out[r * n + k * d + m] += dt_dn[r] * dn_dv * b;
            }
        }
    }
}
