//! Prediction of the boundary conditions (docs/formulation.md §8.8, paper §3.3-3.4).
//!
//! The contact stiffness is sampled along a generating shape instead of a full-order solution:
//! `q_0` = the nonlinear static solution under `f_E^0` (with contacts), `q_1 = p̂ (φ_c, φ_s)`
//! (cos and sin parts of the shape), other harmonics zero, for `p̂` between
//! - `p̂_min`, the amplitude at which the first contact starts to slip, searched from below
//!   ([`slip_onset_amplitude`]);
//! - `p̂_max`, for the stuck mode the linear estimate `|(D_1 + K̂_ST)^-1 f_E^1| / |Φ_ST|` at the
//!   stuck resonance; for a given shape (a reduced solution's first harmonic, (39))
//!   [`GIVEN_SHAPE_P_MAX`] times the shape; or a user value.
//!
//! At gross slip the stuck mode is a poor generating shape (the response follows the mode of
//! the structure whose contacts slip, far below the stuck resonance). On request
//! ([`SlippingSamples`]: always, or when the linear stuck response is at least
//! [`GROSS_SLIP_RATIO`] times the amplitude at which slip begins, `p̂_max >= 50 p̂_min`, about
//! `alpha <= alpha_ST / 50`) the contacts are also sampled along the **slipping mode**
//! ([`slipping_mode`]), the same way, with the same number of samples; the slipping patterns'
//! modes are conditioned on their own and united with the stuck ones (docs/formulation.md §8.8).
//!
//! `p̂` is oversampled (default 100 values, logarithmic spacing — slip spreads over the contact
//! over decades of amplitude, so log spacing meets more distinct patterns; linear spacing is an
//! option, and is used when `p̂_min = 0`), each sample's contact-state pattern (state of every
//! contact at every AFT time sample) is recorded, duplicates are dropped, and the JP modes of
//! the distinct patterns are stacked per harmonic (36) and conditioned (38). On models where the
//! eigen solve is shift-invert the patterns share one reference's factorisations
//! ([`super::reference`], [`PatternFactorisation`]).

use super::basis::JpBasis;
use super::modes::{jp_modes, modes_of_active_part, EigenSolver, JpModes, ModeOptions};
use super::reference::{active_pattern_working_set_bytes, reference_working_set_bytes, ActivePart, ReferenceFactors};
use super::{lu_solve, ContactJacobian};
use crate::aft::{evaluate_contacts, AftPlan, ContactForces};
use crate::contact::ContactState;
use crate::error::{JpError, Result};
use crate::linalg::norm2;
use crate::model::ContactCoordinates;
use crate::linalg::lu_checked;
use faer::Mat;
use super::modes::pattern_working_set_bytes;
use serde::{Deserialize, Serialize};
use std::collections::HashSet;

/// Largest estimated working set of one pattern's JP-mode solve ([`pattern_working_set_bytes`])
/// for which [`predict_basis`] solves the patterns in parallel.
pub(crate) const PARALLEL_PATTERNS_MAX_BYTES: u128 = 500_000_000;

/// How many contact patterns [`predict_basis`] solves at once: in parallel (up to the thread
/// count and `n_samples`) while one pattern's working set is below
/// `PARALLEL_PATTERNS_MAX_BYTES` and as many fit in the memory budget; else one at a time
/// (each solve parallel inside).
pub fn patterns_at_once(per_pattern_bytes: u128, budget_bytes: usize, n_samples: usize) -> usize {
    if per_pattern_bytes > PARALLEL_PATTERNS_MAX_BYTES {
        return 1;
    }
    reference_patterns_at_once(per_pattern_bytes, budget_bytes, n_samples)
}

/// How many contact patterns [`predict_basis`] solves at once on a shared reference: as many
/// as threads, patterns and the memory budget allow, whatever a pattern's size. A pattern there
/// mixes dense products and factorisations (parallel inside, near the processor's peak) with
/// work that leaves a thread waiting (the Arnoldi iteration's one-vector solves, gathers of
/// rows, the per-contact `D` blocks), which a second pattern beside it fills.
pub fn reference_patterns_at_once(per_pattern_bytes: u128, budget_bytes: usize, n_patterns: usize) -> usize {
    if per_pattern_bytes == 0 {
        return 1;
    }
    let fit = usize::try_from(budget_bytes as u128 / per_pattern_bytes).unwrap_or(usize::MAX).max(1);
    rayon::current_num_threads().min(n_patterns).min(fit).max(1)
}

/// `f` of every item, `at_once` at a time (in parallel, on a pool of that many threads when
/// fewer than rayon's), the items taken in the order `order` (a permutation of their indices:
/// the costliest first, so that the last to finish is a small one); the results in the items'
/// order, the first error by that order if any.
fn in_parallel<T: Sync>(at_once: usize, items: &[T], order: &[usize], f: impl Fn(&T) -> Result<JpModes> + Sync + Send) -> Result<Vec<JpModes>> {
    if at_once <= 1 || items.len() <= 1 {
        return items.iter().map(f).collect();
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let slots: Vec<std::sync::Mutex<Option<Result<JpModes>>>> = items.iter().map(|_| std::sync::Mutex::new(None)).collect();
    let work = || {
        rayon::scope(|s| {
            for _ in 0..at_once {
                s.spawn(|_| loop {
                    let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&i) = order.get(k) else { break };
                    let out = f(&items[i]);
                    *slots[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(out);
                });
            }
        })
    };
    if at_once >= rayon::current_num_threads() {
        work();
    } else {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(at_once)
            .build()
            .map_err(|e| JpError::invalid("JP prediction", format!("could not start {at_once} threads: {e}")))?;
        pool.install(work);
    }
    slots
        .into_iter()
        .map(|m| m.into_inner().unwrap_or_else(|e| e.into_inner()).unwrap_or_else(|| Err(JpError::invalid("JP prediction", "a contact pattern was not solved"))))
        .collect()
}

/// `p̂_max` of a given generating shape when the caller gives none: sample up to 125 % of it.
pub const GIVEN_SHAPE_P_MAX: f64 = 1.25;

/// `p̂_max / p̂_min` along the stuck mode from which [`SlippingSamples::AtGrossSlip`] samples along the
/// slipping mode as well: the linear stuck response is 50 times the amplitude where slip
/// begins, so the contacts slip over most of the cycle (a Jenkins element at 50 times its slip
/// amplitude sticks for 9 % of each half cycle). On the built-in blade `p̂_max / p̂_min` is
/// `alpha_ST / alpha` (within 0.5 %, tests/jp_slip_onset.rs).
pub const GROSS_SLIP_RATIO: f64 = 50.0;

/// Whether [`predict_basis`] samples along the slipping mode besides the stuck mode (only with
/// [`GeneratingShape::StuckMode`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum SlippingSamples {
    /// Along the stuck mode only (the paper's prediction).
    #[default]
    Never,
    /// When `p̂_max >= `[`GROSS_SLIP_RATIO`]` p̂_min` along the stuck mode.
    AtGrossSlip,
    Always,
}

/// Spacing of the `p̂` samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Spacing {
    /// Geometric between `p̂_min` and `p̂_max` (linear if `p̂_min = 0`).
    Log,
    /// Uniform between `p̂_min` and `p̂_max`.
    Linear,
}

/// The shape along which the contacts are excited.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum GeneratingShape {
    /// The stuck linear mode (of `K` + stuck contact springs) nearest the band centre, as the
    /// cos part, unit length; static part the nonlinear static solution.
    StuckMode,
    /// A given first harmonic (cos and sin parts, z-coordinates, length `n`), e.g. a reduced
    /// solution's (39); optionally with its static part (else the static solution is used).
    Given { static_part: Option<Vec<f64>>, cos: Vec<f64>, sin: Vec<f64> },
}

/// Settings of the prediction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PredictionOptions {
    /// Band and mode selection of (31). The default has no static correction
    /// ([`ModeOptions::static_correction`]): each distinct pattern would add its own correction
    /// vectors, which the SVD keeps as separate directions (measured on the blade at
    /// alpha_ST / 10, gamma 1e3: `n_1` 9 -> 28 for an error 5e-4 -> 4e-5, about what the larger
    /// gamma gives without them). It pays off for a basis of one Jacobian
    /// ([`super::JpBasis::from_jacobian`]). Two eigenpairs beyond the band are kept by default:
    /// at gross slip the slipping mode leaves the band (on the blade at alpha_ST / 100 an
    /// in-band-only FR basis stayed at e*_1 = 1.45 through three corrections).
    pub modes: ModeOptions,
    /// Conditioning ratio of (38).
    pub gamma: f64,
    /// Number of `p̂` samples (default 100).
    pub n_samples: usize,
    /// Spacing of the samples (default [`Spacing::Log`]).
    pub spacing: Spacing,
    /// User value of `p̂_max` (else the estimate described in the module doc).
    pub p_max: Option<f64>,
    /// Generating shape (default the stuck mode).
    pub shape: GeneratingShape,
    /// How the patterns' model-sized matrices are factorised (default
    /// [`PatternFactorisation::Auto`]).
    #[serde(default)]
    pub factorisation: PatternFactorisation,
    /// Samples along the slipping mode as well (default [`SlippingSamples::Never`]). Measured on
    /// the 18-contact blade at alpha_ST / 3000 over 1,620-2,200 Hz (gamma 1e3, no correction):
    /// the stuck-mode basis put the FR resonance at the band's edge, 97 % off in `|X1|`; with the
    /// slipping samples the FR peak is within 1.1e-4 (tests/slipping_samples.rs). `p_max`
    /// applies to the stuck mode; the slipping mode's is its linear estimate.
    #[serde(default)]
    pub slipping: SlippingSamples,
}

/// How [`predict_basis`] factorises the model-sized matrices of its contact patterns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum PatternFactorisation {
    /// Each pattern on its own ([`jp_modes`]): `K + K̂_00`, and `K_JC - σ M_JC` or the dense
    /// eigen solve of (31), per pattern.
    PerPattern,
    /// Once per prediction on the first sample's boundary conditions
    /// ([`super::reference`], docs/formulation.md §8.10); each pattern then works on its active
    /// contacts only, with shift-invert Arnoldi at the band centre. The same basis up to
    /// round-off.
    SharedReference,
    /// [`PatternFactorisation::SharedReference`] when the eigen solver resolves to shift-invert
    /// (`2 H n` above [`super::modes::AUTO_DENSE_MAX`]), else per pattern; per pattern as well if
    /// the reference is singular at the band centre.
    #[default]
    Auto,
}

impl PredictionOptions {
    /// Defaults for a band `[omega_lo, omega_hi]` (rad/s): `H = 1`, stuck mode, 100 log-spaced
    /// samples, `gamma = 1e3`, two eigenpairs beyond the band, no static correction.
    pub fn new(band: (f64, f64)) -> Self {
        PredictionOptions {
            modes: ModeOptions { extra_outside: 2, static_correction: false, ..ModeOptions::in_band(band) },
            gamma: 1e3,
            n_samples: 100,
            spacing: Spacing::Log,
            p_max: None,
            shape: GeneratingShape::StuckMode,
            factorisation: PatternFactorisation::Auto,
            slipping: SlippingSamples::Never,
        }
    }
}

/// What the prediction found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PredictionReport {
    /// Stuck resonance (rad/s), for [`GeneratingShape::StuckMode`].
    pub omega_stuck: Option<f64>,
    pub p_min: f64,
    pub p_max: f64,
    pub n_samples: usize,
    /// Number of distinct contact-state patterns (boundary conditions) used.
    pub n_patterns: usize,
    /// `p̂` of the first sample of each distinct pattern (along the slipping mode for the last
    /// [`PredictionReport::slipping_patterns`]).
    pub pattern_amplitudes: Vec<f64>,
    /// The slipping mode's frequency (rad/s) when the contacts were also sampled along it
    /// ([`SlippingSamples`]), and how many of the distinct patterns came from it.
    #[serde(default)]
    pub omega_slipping: Option<f64>,
    #[serde(default)]
    pub slipping_patterns: usize,
    /// On a shared reference ([`PatternFactorisation`]): the number of active contact
    /// coordinates of each distinct pattern (0 for the reference itself); `None` per pattern.
    #[serde(default)]
    pub active_coordinates: Option<Vec<usize>>,
    /// The memory budget's estimate of the prediction's dense work (bytes): the patterns solved
    /// at once and, on a shared reference, its factorisations.
    #[serde(default)]
    pub estimated_bytes: u128,
    /// The nonlinear static solution (z-coordinates).
    pub static_solution: Vec<f64>,
}

/// The stuck linear mode nearest the centre of `band`: `(omega_ST, Φ_ST)`, `Φ_ST` of unit
/// Euclidean length in z-coordinates.
///
/// # Errors
/// [`JpError::Eigen`] if the shift-invert iteration fails (as for a mass matrix that is not
/// positive definite, or a band centre exactly on a stuck eigenvalue).
pub fn stuck_mode(coords: &ContactCoordinates, band: (f64, f64)) -> Result<(f64, Vec<f64>)> {
    let k = coords.stuck_stiffness();
    let centre = 0.5 * (band.0 + band.1);
    // Shift-invert at the band centre: one LU of the model size, no full eigen solve.
    let (lambda, mut phi) = crate::linalg::eigen::generalized_eigenpair_nearest(&k, &coords.mass, centre * centre, "stuck modes")?;
    // Unit length, and a sign that does not depend on the solver: largest entry positive.
    let big = phi.iter().copied().fold(0.0f64, |a, x| if x.abs() > a.abs() { x } else { a });
    let nrm = norm2(&phi).copysign(big);
    phi.iter_mut().for_each(|x| *x /= nrm);
    Ok((lambda.max(0.0).sqrt(), phi))
}

/// Slipping modes [`slipping_mode`] chooses from: the nearest the band centre.
const SLIPPING_CANDIDATES: usize = 4;

/// The slipping linear mode of the band (docs/formulation.md §8.8): of the
/// [`SLIPPING_CANDIDATES`] modes of `K` plus the contacts' gross-slip springs
/// ([`ContactCoordinates::slipping_stiffness`]: normal springs only) nearest the band centre,
/// the one most like the stuck mode `phi_st` (largest `|φ^T M Φ_ST|` over `|φ|_M |Φ_ST|_M`),
/// the mode the stuck one softens into as the contacts slip. `(omega, φ)`, `φ` of unit length,
/// largest entry positive. `None` when the model has no friction (the slipping stiffness is the
/// stuck one) or a law whose slipping limit is unknown.
///
/// # Errors
/// [`JpError::Eigen`] if the subspace iteration fails.
pub fn slipping_mode(coords: &ContactCoordinates, band: (f64, f64), phi_st: &[f64]) -> Result<Option<(f64, Vec<f64>)>> {
    Ok(slipping_mode_and_stiffness(coords, band, phi_st)?.map(|(w, phi, _)| (w, phi)))
}

/// [`slipping_mode`] with the slipping stiffness it was solved on, `(omega, φ, K_sl)`.
fn slipping_mode_and_stiffness(coords: &ContactCoordinates, band: (f64, f64), phi_st: &[f64]) -> Result<Option<(f64, Vec<f64>, Mat<f64>)>> {
    if !coords.has_friction() {
        return Ok(None);
    }
    let Some(k) = coords.slipping_stiffness() else { return Ok(None) };
    let centre = 0.5 * (band.0 + band.1);
    let pairs = crate::linalg::eigen::generalized_eigenpairs_nearest(&k, &coords.mass, centre * centre, SLIPPING_CANDIDATES, "slipping modes")?;
    let m = &coords.mass;
    let n = coords.n_dof;
    let m_dot = |a: &[f64], b: &[f64]| -> f64 { (0..n).map(|j| b[j] * (0..n).map(|i| a[i] * m[(i, j)]).sum::<f64>()).sum() };
    let st = m_dot(phi_st, phi_st).max(f64::MIN_POSITIVE);
    let likeness = |x: &[f64]| m_dot(x, phi_st).abs() / (m_dot(x, x).max(f64::MIN_POSITIVE) * st).sqrt();
    let Some((lambda, mut phi)) = pairs.into_iter().max_by(|a, b| likeness(&a.1).total_cmp(&likeness(&b.1))) else { return Ok(None) };
    let big = phi.iter().copied().fold(0.0f64, |a, x| if x.abs() > a.abs() { x } else { a });
    let nrm = norm2(&phi).copysign(big);
    phi.iter_mut().for_each(|x| *x /= nrm);
    Ok(Some((lambda.max(0.0).sqrt(), phi, k)))
}

/// Harmonic-major contact displacement with static part `q0` and first harmonic `(c, s)`.
fn contact_w(nw: usize, harmonics: usize, q0: &[f64], c: &[f64], s: &[f64], p: f64) -> Vec<f64> {
    let mut w = vec![0.0; nw * (2 * harmonics + 1)];
    w[..nw].copy_from_slice(&q0[..nw]);
    for i in 0..nw {
        w[nw + i] = p * c[i];
        w[2 * nw + i] = p * s[i];
    }
    w
}

/// The contact forces at `w`; a failed external law (C callback) is its error.
fn eval(coords: &ContactCoordinates, plan: &AftPlan, w: &[f64], jac: bool, cycles: bool) -> Result<ContactForces> {
    let mut out = ContactForces::default();
    evaluate_contacts(plan, &coords.laws, &coords.offsets, coords.n_w, w, jac, cycles, &mut out);
    out.check()?;
    Ok(out)
}

/// The nonlinear static solution under `f_E^0` with contacts (zero dynamic part): Newton on
/// `K q_0 - f_E^0 + [F_0(w_0); 0] = 0` with Jacobian `K + K̂_00`, from the stuck linear
/// solution, with step halving on the residual norm.
///
/// # Errors
/// [`JpError::SingularMatrix`], [`JpError::NoConvergence`].
pub fn static_solution(coords: &ContactCoordinates) -> Result<Vec<f64>> {
    let n = coords.n_dof;
    let nw = coords.n_w;
    let plan = &coords.discretisation.plan()?;
    let hh = plan.harmonics();
    let f0 = Mat::from_fn(n, 1, |i, _| coords.static_force[i]);
    let x = lu_solve("K + stuck contact stiffness", &coords.stuck_stiffness(), &f0)?;
    let mut q: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    let zeros = vec![0.0; nw];
    let residual = |q: &[f64], jac: bool| -> Result<(Vec<f64>, ContactForces)> {
        let forces = eval(coords, plan, &contact_w(nw, hh, q, &zeros, &zeros, 0.0), jac, false)?;
        let mut r: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| coords.stiffness[(i, j)] * q[j]).sum::<f64>() - coords.static_force[i])
            .collect();
        for i in 0..nw {
            r[i] += forces.force[i];
        }
        Ok((r, forces))
    };
    let (mut r, mut forces) = residual(&q, true)?;
    // Forces of the problem: the static load, and the contact forces at the start (a preload
    // acts without any static load; scaling by the load alone made a zero load unsolvable).
    let scale = norm2(&coords.static_force).max(norm2(&forces.force[..nw])).max(f64::MIN_POSITIVE);
    let mut rn = norm2(&r);
    for _ in 0..60 {
        if rn <= 1e-11 * scale {
            return Ok(q);
        }
        let kj = ContactJacobian::from_forces(&coords.laws, &coords.offsets, nw, hh, &forces, &contact_w(nw, hh, &q, &zeros, &zeros, 0.0))?;
        let mut a = coords.stiffness.clone();
        for j in 0..nw {
            for i in 0..nw {
                a[(i, j)] += kj.k_hat[(i, j)];
            }
        }
        let rm = Mat::from_fn(n, 1, |i, _| r[i]);
        let dx = lu_solve("K + K̂_00 (static Newton)", &a, &rm)?;
        let mut t = 1.0;
        loop {
            let trial: Vec<f64> = (0..n).map(|i| q[i] - t * dx[(i, 0)]).collect();
            let (rt, ft) = residual(&trial, true)?;
            let rtn = norm2(&rt);
            if rtn < rn || t < 1e-6 {
                q = trial;
                r = rt;
                forces = ft;
                rn = rtn;
                break;
            }
            t *= 0.5;
        }
    }
    if rn <= 1e-8 * scale {
        return Ok(q);
    }
    Err(JpError::NoConvergence { what: "static solution with contacts".into(), iterations: 60, residual: rn / scale, tolerance: 1e-8 })
}

/// Linear estimate `|(D_1 + K̂)^-1 f_E^1|` at `omega` (cos and sin parts together), `K + K̂`
/// the linear limit's stiffness `k` (stuck or slipping). One complex solve
/// ([`ContactCoordinates::first_harmonic_complex`]), `|z| = |(x_c, x_s)|`: half the size and half the flops of the real `2n` form (on the
/// 1,922-contact blade 6.0 s instead of 17.5 s).
fn linear_response_norm(coords: &ContactCoordinates, k: &Mat<f64>, omega: f64) -> Result<f64> {
    let (d, rhs) = coords.first_harmonic_complex(k, omega)?;
    let z = lu_checked(&d, "D_1 + K̂ of a linear limit at its resonance")?.solve(&rhs);
    Ok(z.norm_l2())
}

/// True when every contact sticks at every time sample.
fn all_stuck(forces: &ContactForces) -> bool {
    forces.cycles.iter().all(|c| c.states.iter().all(|&s| s == ContactState::Stick))
}

fn pattern(forces: &ContactForces) -> Vec<u8> {
    forces.cycles.iter().flat_map(|c| c.states.iter().map(|&s| s as u8)).collect()
}

/// One sample of the prediction whose contact-state pattern was new: its amplitude along its
/// generating shape, its contact displacement and forces.
struct Sampled {
    p: f64,
    w: Vec<f64>,
    forces: ContactForces,
}

/// Steps of the upward scans of [`slip_onset_amplitude`]: coarse `2^(1/16)` (4.4 %), then fine
/// `2^(1/256)` (0.27 %) over the last [`ONSET_FINE_SPAN`] coarse steps.
const ONSET_COARSE_STEP: f64 = 1.044_273_782_427_413_8;
const ONSET_FINE_STEP: f64 = 1.002_711_275_050_202_5;
const ONSET_FINE_SPAN: i32 = 4;
/// Halvings of `p̂_max` after which [`slip_onset_amplitude`] stops looking for a stuck
/// amplitude (`p̂_max / 2^60`): a contact that slips at every amplitude above that.
const ONSET_MAX_HALVINGS: usize = 60;

/// `p̂_min` (docs/formulation.md §8.8 step 5): the amplitude along the generating shape
/// (static part `q0`, first harmonic `p̂ (c, s)`) at which the first contact starts to slip,
/// searched from below; `p_max` if every contact sticks there, 0 if one already slips at 0.
///
/// "Every contact sticks at every sample" is not monotone in `p̂`: a contact that slipped in the
/// AFT's first pass settles with its steady cycle touching the friction cone at one sample (no
/// dissipation), and whether that sample counts as slip is decided by rounding. On the
/// 242-contact blade all contacts count as stuck again at a quarter of the amplitudes over the
/// 20 % past the first touch. A bisection on `[0, p̂_max]` landed anywhere in that range (a
/// change of `p̂_max` in its last bits moved `p̂_min` by 16 %, and every sample and pattern with
/// it). A slip flag is reliable (the trial force reached the cone); a stuck one past the first
/// touch is not. So: halve `p̂_max` until two halvings in a row stick, scan up by coarse steps
/// to the first slip, scan again by fine steps from four coarse steps below it up to it (the
/// coarse scan may have passed stuck flags of the rounding there), and bisect the fine step
/// where the first slip is met, to a relative 1e-6: at most 64 fine steps.
///
/// # Errors
/// [`JpError::InvalidValue`] for a `p_max` that is not finite and > 0, [`JpError::BadSize`]
/// for a shape shorter than the contact coordinates; a failed external law (C callback).
pub fn slip_onset_amplitude(coords: &ContactCoordinates, (q0, c, s): (&[f64], &[f64], &[f64]), p_max: f64) -> Result<f64> {
    if !(p_max.is_finite() && p_max > 0.0) {
        return Err(JpError::invalid("p_max", format!("must be finite and > 0, got {p_max}")));
    }
    if let Some(short) = [q0, c, s].iter().map(|v| v.len()).find(|&l| l < coords.n_w) {
        return Err(JpError::bad_size("generating shape (contact coordinates)", coords.n_w, short));
    }
    let plan = &coords.discretisation.plan()?;
    let (nw, hh) = (coords.n_w, plan.harmonics());
    let stuck = |p: f64| -> Result<bool> { Ok(all_stuck(&eval(coords, plan, &contact_w(nw, hh, q0, c, s, p), false, true)?)) };
    if stuck(p_max)? {
        return Ok(p_max);
    }
    if !stuck(0.0)? {
        return Ok(0.0);
    }
    // below the first touch: two stuck halvings in a row
    let mut below = p_max;
    let mut in_a_row = 0;
    for _ in 0..ONSET_MAX_HALVINGS {
        below *= 0.5;
        in_a_row = if stuck(below)? { in_a_row + 1 } else { 0 };
        if in_a_row == 2 {
            break;
        }
    }
    if in_a_row == 0 {
        return Ok(0.0);
    }
    // (last stuck, first slipping) amplitude of the grid `from step^k`, up to `to` (which slips)
    let scan_up = |from: f64, step: f64, to: f64| -> Result<(f64, f64)> {
        let mut lo = from;
        loop {
            let next = (lo * step).min(to);
            if next >= to || !stuck(next)? {
                return Ok((lo, next));
            }
            lo = next;
        }
    };
    let (_, coarse) = scan_up(below, ONSET_COARSE_STEP, p_max)?;
    let from = (coarse / ONSET_COARSE_STEP.powi(ONSET_FINE_SPAN)).max(below);
    let (mut lo, mut hi) = scan_up(from, ONSET_FINE_STEP, coarse)?;
    while hi - lo > 1e-6 * hi {
        let mid = 0.5 * (lo + hi);
        if stuck(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(lo)
}

/// Samples the contacts along one generating shape (static part `q0`, first harmonic
/// `(c, s)`): `p̂_min` ([`slip_onset_amplitude`]), `opts.n_samples` amplitudes up to `p_max`
/// (`opts.spacing`), and each sample whose pattern is not in `seen` appended to `chosen`.
/// Returns `p̂_min`.
fn sample_shape(
    coords: &ContactCoordinates,
    plan: &AftPlan,
    opts: &PredictionOptions,
    (q0, c, s): (&[f64], &[f64], &[f64]),
    p_max: f64,
    seen: &mut HashSet<Vec<u8>>,
    chosen: &mut Vec<Sampled>,
) -> Result<f64> {
    let (nw, hh) = (coords.n_w, plan.harmonics());
    let p_min = slip_onset_amplitude(coords, (q0, c, s), p_max)?;
    let ns = opts.n_samples;
    for k in 0..ns {
        let t = if ns == 1 { 1.0 } else { k as f64 / (ns - 1) as f64 };
        let p = match opts.spacing {
            Spacing::Log if p_min > 0.0 => p_min * (p_max / p_min).powf(t),
            _ => p_min + t * (p_max - p_min),
        };
        let w = contact_w(nw, hh, q0, c, s, p);
        let forces = eval(coords, plan, &w, true, true)?;
        if seen.insert(pattern(&forces)) {
            chosen.push(Sampled { p, w, forces });
        }
    }
    Ok(p_min)
}

/// Predicts a JP basis (docs/formulation.md §8.7-8.8) without any full-order solution, with the
/// harmonics `H` and AFT samples of `coords` ([`ContactCoordinates::discretisation`]):
/// [`predict_modes`], conditioned with `opts.gamma`.
///
/// # Errors
/// Bad options ([`JpError::InvalidValue`]); the static solve's and [`jp_modes`]' errors.
pub fn predict_basis(coords: &ContactCoordinates, opts: &PredictionOptions) -> Result<(JpBasis, PredictionReport)> {
    // a bad gamma is refused before the eigen solves, not after them
    crate::jp::conditioning::check_gamma(opts.gamma)?;
    let (modes, report) = predict_modes(coords, opts)?;
    Ok((modes.basis(opts.gamma)?, report))
}

/// The JP modes of every distinct contact pattern of a prediction, before the SVD conditioning
/// (36)-(38): what [`predict_basis`] conditions with its `gamma`. Kept, they give the basis of
/// any other `gamma` without a single eigen solve ([`PredictedModes::basis`]): the
/// self-correcting sweep's `gamma` steps re-use the last prediction's modes this way.
#[derive(Clone, Debug)]
pub struct PredictedModes {
    /// Per distinct pattern, in sampling order: the stuck (or given) shape's patterns first,
    /// then the [`PredictedModes::slipping_patterns`] along the slipping mode.
    pub modes: Vec<JpModes>,
    pub slipping_patterns: usize,
    pub n_w: usize,
    pub band: (f64, f64),
}

impl PredictedModes {
    /// The conditioned basis (38) with ratio `gamma`: the stacked modes conditioned by SVD, and
    /// the slipping patterns' modes conditioned on their own and united with the others (on
    /// one SVD the few slipping directions fall below the stuck ones' cut).
    ///
    /// # Errors
    /// As [`JpBasis::from_modes`] and [`JpBasis::union`].
    pub fn basis(&self, gamma: f64) -> Result<JpBasis> {
        let stuck_count = self.modes.len() - self.slipping_patterns;
        let basis = if self.slipping_patterns > 0 && stuck_count > 0 {
            let stuck = JpBasis::from_modes(&self.modes[..stuck_count], gamma, self.n_w)?;
            let slipping = JpBasis::from_modes(&self.modes[stuck_count..], gamma, self.n_w)?;
            JpBasis { n_patterns: self.modes.len(), ..stuck.union(&slipping, gamma)? }
        } else {
            JpBasis::from_modes(&self.modes, gamma, self.n_w)?
        };
        Ok(basis.with_band(self.band))
    }
}

/// The sampling and the per-pattern JP modes of [`predict_basis`], without the conditioning
/// ([`PredictedModes::basis`]; `opts.gamma` is not used).
///
/// # Errors
/// As [`predict_basis`].
pub fn predict_modes(coords: &ContactCoordinates, opts: &PredictionOptions) -> Result<(PredictedModes, PredictionReport)> {
    let n = coords.n_dof;
    let nw = coords.n_w;
    super::require_contacts("JP prediction", nw)?;
    let plan = &coords.discretisation.plan()?;
    let hh = plan.harmonics();
    if opts.n_samples == 0 {
        return Err(JpError::invalid("PredictionOptions.n_samples", "must be >= 1"));
    }
    let q_static = static_solution(coords)?;
    let (omega_stuck, q0, c, s, p_est) = match &opts.shape {
        GeneratingShape::StuckMode => {
            let (w_st, phi) = stuck_mode(coords, opts.modes.band)?;
            let p_est = linear_response_norm(coords, &coords.stuck_stiffness(), w_st)? / norm2(&phi);
            (Some(w_st), q_static.clone(), phi, vec![0.0; n], p_est)
        }
        GeneratingShape::Given { static_part, cos, sin } => {
            if cos.len() != n || sin.len() != n {
                return Err(JpError::bad_size("generating shape", n, cos.len().min(sin.len())));
            }
            let q0 = match static_part {
                Some(q) if q.len() == n => q.clone(),
                Some(q) => return Err(JpError::bad_size("generating shape static part", n, q.len())),
                None => q_static.clone(),
            };
            (None, q0, cos.clone(), sin.clone(), GIVEN_SHAPE_P_MAX)
        }
    };
    let p_max = opts.p_max.unwrap_or(p_est);
    if !(p_max.is_finite() && p_max > 0.0) {
        return Err(JpError::invalid("p_max", format!("must be finite and > 0, got {p_max}")));
    }
    // Distinct patterns; their boundary conditions (the dense K̂, `((2H + 1) n_w)^2`) are
    // assembled one pattern at a time, inside the JP-mode solve.
    let mut seen = HashSet::new();
    let mut chosen: Vec<Sampled> = Vec::new();
    let p_min = sample_shape(coords, plan, opts, (&q0, &c, &s), p_max, &mut seen, &mut chosen)?;
    let ns = opts.n_samples;

    // At gross slip, along the slipping mode as well (module doc).
    let mut omega_slipping = None;
    let mut slipping_patterns = 0;
    let slipping_wanted = match opts.slipping {
        SlippingSamples::AtGrossSlip => p_min > 0.0 && p_max >= GROSS_SLIP_RATIO * p_min,
        SlippingSamples::Always => true,
        SlippingSamples::Never => false,
    };
    if slipping_wanted && omega_stuck.is_some() {
        if let Some((w_sl, phi_sl, k_sl)) = slipping_mode_and_stiffness(coords, opts.modes.band, &c)? {
            let p_sl = linear_response_norm(coords, &k_sl, w_sl)? / norm2(&phi_sl);
            if !(p_sl.is_finite() && p_sl > 0.0) {
                return Err(JpError::invalid("slipping mode", format!("its linear response estimate is {p_sl} (no damping?)")));
            }
            let before = chosen.len();
            sample_shape(coords, plan, opts, (&q_static, &phi_sl, &vec![0.0; n]), p_sl, &mut seen, &mut chosen)?;
            slipping_patterns = chosen.len() - before;
            omega_slipping = Some(w_sl);
        }
    }
    let budget = crate::memory::MemoryBudget::global().bytes;
    let check = |at_once: usize, per_pattern: u128, shared: u128, how: &str| -> Result<u128> {
        let bytes = per_pattern.saturating_mul(at_once as u128).saturating_add(shared);
        crate::memory::check(
            &format!(
                "the JP prediction at H = {hh} (n = {n} DoFs, n_w = {nw}; {how}{at_once} contact pattern(s) at once, {} each)",
                crate::memory::human_bytes(per_pattern)
            ),
            bytes,
        )?;
        Ok(bytes)
    };
    let estimated_bytes;
    let mut active_coordinates = None;

    // The shared reference: the first sample's boundary conditions, factorised once.
    let use_reference = match opts.factorisation {
        PatternFactorisation::PerPattern => false,
        PatternFactorisation::SharedReference => true,
        PatternFactorisation::Auto => opts.modes.solver.resolve(2 * hh * n) == EigenSolver::ShiftInvert,
    };
    let centre = 0.5 * (opts.modes.band.0 + opts.modes.band.1);
    let reference = if use_reference {
        match ReferenceFactors::from_forces(coords, &chosen[0].forces, hh, centre * centre) {
            Ok(r) => Some(r),
            Err(JpError::SingularMatrix { .. }) if opts.factorisation == PatternFactorisation::Auto => None,
            Err(e) => return Err(e),
        }
    } else {
        None
    };

    let modes: Vec<JpModes> = match &reference {
        Some(reference) => {
            let parts: Vec<ActivePart> = chosen.iter().map(|x| reference.active_part_of_forces(coords, &x.forces, &x.w)).collect::<Result<_>>()?;
            let per_pattern = parts.iter().map(|a| active_pattern_working_set_bytes(n, nw, a.len(), a.lead.len(), hh)).max().unwrap_or(0);
            let at_once = reference_patterns_at_once(per_pattern, budget.saturating_sub(reference_working_set_bytes(n, nw, hh).min(usize::MAX as u128) as usize), parts.len());
            estimated_bytes = check(at_once, per_pattern, reference_working_set_bytes(n, nw, hh), "on a shared reference, ")?;
            active_coordinates = Some(parts.iter().map(ActivePart::len).collect());
            // shift-invert: the modes in the band grow with H and no estimate bounds the
            // cost beforehand; the budget stops it between patterns
            let deadline = crate::time_budget::Deadline::start();
            let done = std::sync::atomic::AtomicUsize::new(0);
            let what = format!("the JP prediction at H = {hh} ({} contact pattern(s), shift-invert on a shared reference)", parts.len());
            let modes_of = |part: &ActivePart| {
                deadline.check(&what, done.load(std::sync::atomic::Ordering::Relaxed), parts.len())?;
                let m = modes_of_active_part(coords, part, &opts.modes, reference);
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                m
            };
            // the costliest first: the capacitance's factorisation grows as r_l^3
            let mut order: Vec<usize> = (0..parts.len()).collect();
            order.sort_by_key(|&i| std::cmp::Reverse((parts[i].lead.len(), parts[i].len())));
            in_parallel(at_once, &parts, &order, modes_of)?
        }
        None => {
            // the patterns' dense matrices, as many at once as run in parallel
            let per_pattern = pattern_working_set_bytes(n, nw, hh);
            let at_once = patterns_at_once(per_pattern, budget, opts.n_samples);
            estimated_bytes = check(at_once, per_pattern, 0, "")?;
            if opts.modes.solver.resolve(2 * hh * n) == EigenSolver::Dense {
                // each pattern's dense eigenproblem of order 2 H n dominates
                let order = 2 * hh * n;
                crate::time_budget::check(
                    &format!("the JP prediction at H = {hh} ({} contact pattern(s), a dense eigenproblem of order {order} each)", chosen.len()),
                    chosen.len() as f64 * (crate::time_budget::eigen_flops(order) + 2.0 * crate::time_budget::lu_flops(n)),
                )?;
            }
            let deadline = crate::time_budget::Deadline::start();
            let done = std::sync::atomic::AtomicUsize::new(0);
            let what = format!("the JP prediction at H = {hh} ({} contact pattern(s))", chosen.len());
            let modes_of = |x: &Sampled| -> Result<JpModes> {
                deadline.check(&what, done.load(std::sync::atomic::Ordering::Relaxed), chosen.len())?;
                let kj = ContactJacobian::from_forces(&coords.laws, &coords.offsets, nw, hh, &x.forces, &x.w)?;
                let m = jp_modes(coords, &kj, &opts.modes);
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                m
            };
            let order: Vec<usize> = (0..chosen.len()).collect();
            in_parallel(at_once, &chosen, &order, modes_of)?
        }
    };
    let predicted = PredictedModes { modes, slipping_patterns, n_w: nw, band: opts.modes.band };
    let report = PredictionReport {
        omega_stuck,
        p_min,
        p_max,
        n_samples: ns,
        n_patterns: chosen.len(),
        pattern_amplitudes: chosen.iter().map(|x| x.p).collect(),
        omega_slipping,
        slipping_patterns,
        static_solution: q_static,
        active_coordinates,
        estimated_bytes,
    };
    Ok((predicted, report))
}
