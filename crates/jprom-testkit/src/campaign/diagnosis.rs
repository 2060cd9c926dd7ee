//! Why a reduced branch leaves the full order's (issue 59, item 1; docs/formulation.md §10.8).
//!
//! At each point of a reduced sweep with a full-order solution at its frequency on the same
//! branch ([`nearest_full_order`]), three distances of the contact motion `w`, relative to the
//! full order's `|w_FO|`:
//!
//! - the reduced solution's: `d = |w_ROM - w_FO|`;
//! - the basis' own: `p = |w_FO - P w_FO|`, with `P` the orthogonal projector onto the contact
//!   rows of `Φ_h`, per harmonic: the nearest any reduced solution in this basis can come;
//! - and the share of the contact samples that are open, in the full order and the reduced.
//!
//! Where the worst point's actual error `e_1` is above the threshold: `p` near `d` says the
//! basis lacks the full order's directions there (**basis**); `p` much smaller than `d` says
//! the basis holds them but the reduced equations' solution lies elsewhere: a spurious branch of
//! the Galerkin system (**branch**). The sweep's frequency reversals against the full order's
//! say whether the reduced continuation wandered.

use super::{full_order_at, x1};
use jprom::condensation::CondensedSystem;
use jprom::contact::ContactState;
use jprom::hbm::{solve_point, HbmOptions, PointSolution, SweepResult};
use jprom::jp::JpBasis;
use jprom::rom::error_metric::{actual_error, reduced_contact_displacement};
use jprom::rom::ReducedModel;

/// The full-order solution at the reduced point `q`'s frequency on its branch and the actual
/// error (44) per harmonic against it: the nearest (in `e_1`) of the solutions from the
/// full-order sweep's nearest points and from the lifted reduced point (near a fold, or where
/// several solutions lie close at gross slip, they can differ).
pub fn nearest_full_order(condensed: &CondensedSystem, fo: &SweepResult, rom: &dyn ReducedModel, q: &PointSolution, hopts: &HbmOptions) -> Option<(PointSolution, Vec<f64>)> {
    let lifted = reduced_contact_displacement(rom, q.omega, &q.z).ok().and_then(|w| solve_point(condensed, q.omega, Some(&w), hopts).ok());
    full_order_at(condensed, fo, q.omega, x1(q), hopts)
        .into_iter()
        .chain(lifted)
        .filter_map(|f| actual_error(rom, q.omega, &q.z, &f).ok().map(|e| (f, e)))
        .min_by(|a, b| a.1[1].total_cmp(&b.1[1]))
}

/// The distances at one reduced point (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct PointDiagnosis {
    pub omega: f64,
    /// The actual error (44) of the first harmonic.
    pub e1: f64,
    /// `|w_ROM - w_FO| / |w_FO|`.
    pub displacement_error: f64,
    /// `|w_FO - P w_FO| / |w_FO|`.
    pub projection_error: f64,
    /// Open share of the contact samples, full order and reduced.
    pub open_fo: f64,
    pub open_rom: f64,
}

/// What the worst point says (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cause {
    /// The worst point is within the threshold.
    None,
    /// The basis cannot hold the full order's contact motion there (`p >= d / 2`).
    Basis,
    /// The basis holds it; the reduced solution lies on another branch (`p < d / 2`).
    Branch,
}

impl Cause {
    pub fn name(self) -> &'static str {
        match self {
            Cause::None => "-",
            Cause::Basis => "basis",
            Cause::Branch => "branch",
        }
    }
}

/// One reduced sweep against the full order.
#[derive(Clone, Debug)]
pub struct SweepDiagnosis {
    pub points: usize,
    /// Points with a full-order solution to compare with.
    pub compared: usize,
    /// Frequency reversals along the branch, the reduced and the full order's.
    pub reversals: usize,
    pub fo_reversals: usize,
    /// The point of largest `e_1`.
    pub worst: Option<PointDiagnosis>,
    /// The largest projection error over the compared points.
    pub worst_projection: f64,
    pub cause: Cause,
}

/// How often the frequency turns back along a branch (steps shorter than 1e-9 of the frequency
/// are not a direction).
pub fn reversals(r: &SweepResult) -> usize {
    let mut last = 0.0f64;
    let mut count = 0;
    for pair in r.points.windows(2) {
        let d = pair[1].omega - pair[0].omega;
        if d.abs() <= 1e-9 * pair[0].omega.abs() {
            continue;
        }
        if last != 0.0 && d.signum() != last.signum() {
            count += 1;
        }
        last = d;
    }
    count
}

/// Orthonormal columns spanning the first `n_w` rows of `phi` (modified Gram-Schmidt, twice;
/// columns below 1e-10 of the largest dropped).
fn contact_rows_basis(phi: &faer::Mat<f64>, n_w: usize) -> Vec<Vec<f64>> {
    let cols: Vec<Vec<f64>> = (0..phi.ncols()).map(|j| (0..n_w).map(|i| phi[(i, j)]).collect()).collect();
    let largest = cols.iter().map(|c| norm(c)).fold(0.0, f64::max);
    let mut q: Vec<Vec<f64>> = Vec::new();
    for mut c in cols {
        let n0 = norm(&c);
        for _ in 0..2 {
            for b in &q {
                let a: f64 = c.iter().zip(b).map(|(x, y)| x * y).sum();
                c.iter_mut().zip(b).for_each(|(x, y)| *x -= a * y);
            }
        }
        let n = norm(&c);
        if n > 1e-10 * largest && n > 1e-8 * n0 {
            c.iter_mut().for_each(|x| *x /= n);
            q.push(c);
        }
    }
    q
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn open_share(p: &PointSolution) -> f64 {
    let (open, all) = p.contact_cycles.iter().flat_map(|c| &c.states).fold((0usize, 0usize), |(o, a), s| (o + usize::from(*s == ContactState::Separated), a + 1));
    open as f64 / all.max(1) as f64
}

/// `reduced` (a sweep of `rom`, whose basis is `basis`) against the full order `fo` on
/// `condensed`, judged against `threshold` (module doc).
pub fn diagnose(condensed: &CondensedSystem, fo: &SweepResult, rom: &dyn ReducedModel, basis: &JpBasis, reduced: &SweepResult, hopts: &HbmOptions, threshold: f64) -> SweepDiagnosis {
    let n_w = basis.n_w;
    let q: Vec<Vec<Vec<f64>>> = basis.phi.iter().map(|p| contact_rows_basis(p, n_w)).collect();
    let mut out = SweepDiagnosis { points: reduced.points.len(), compared: 0, reversals: reversals(reduced), fo_reversals: reversals(fo), worst: None, worst_projection: 0.0, cause: Cause::None };
    for p in &reduced.points {
        let Some((f, e)) = nearest_full_order(condensed, fo, rom, p, hopts) else { continue };
        let (Ok(w_rom), Ok(w_fo)) = (reduced_contact_displacement(rom, p.omega, &p.z), f.contact_displacement(n_w)) else { continue };
        out.compared += 1;
        let scale = norm(&w_fo).max(1e-300);
        let d: f64 = w_rom.iter().zip(&w_fo).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt() / scale;
        // per coefficient k (harmonic (k + 1) / 2), the part of w_FO outside the basis' span
        let mut outside = 0.0;
        for (k, wk) in w_fo.chunks(n_w).enumerate() {
            let mut r = wk.to_vec();
            for b in &q[(k + 1) / 2] {
                let a: f64 = r.iter().zip(b).map(|(x, y)| x * y).sum();
                r.iter_mut().zip(b).for_each(|(x, y)| *x -= a * y);
            }
            outside += r.iter().map(|x| x * x).sum::<f64>();
        }
        let proj = outside.sqrt() / scale;
        out.worst_projection = out.worst_projection.max(proj);
        let here = PointDiagnosis { omega: p.omega, e1: e[1], displacement_error: d, projection_error: proj, open_fo: open_share(&f), open_rom: open_share(p) };
        if out.worst.as_ref().is_none_or(|w| here.e1 > w.e1) {
            out.worst = Some(here);
        }
    }
    out.cause = match &out.worst {
        Some(w) if w.e1 > threshold => {
            if w.projection_error >= 0.5 * w.displacement_error {
                Cause::Basis
            } else {
                Cause::Branch
            }
        }
        _ => Cause::None,
    };
    out
}
