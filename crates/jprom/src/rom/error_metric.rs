//! The error predictor `e*` of a reduced solution (docs/formulation.md §10.1, paper (40)-(44)).
//!
//! For a reduced solution `p` the full-size linear equations give the contact force the
//! solution *implies*, `f*_C^h = D_h Φ_h p_h - f_E^h` (40) (on the condensed system for NLR);
//! the AFT gives the force the reduced contact displacement *produces*,
//! `f_ROM^h = -[F^h(W p); 0]`. Without loss of information they agree (41); the predictor is
//! `e*_h = |f*_C^h - f_ROM^h|_w / |f_ROM^h|` (43), norms over the cos and sin parts together.
//!
//! **Decision: contact rows, linear residual transferred.** In the contact coordinates
//! `z = [w; y]` the contact force acts on the `w` rows alone (paper (41): `f_C` is a contact
//! force vector), so (43) compares the `w` rows. For FR the `y` rows of (40) are the Galerkin
//! residual `r_y` of the linear DoFs' equilibrium, which FR does not satisfy; for a
//! Craig-Bampton model they are generalised forces on mass-normalised modal coordinates, in
//! other units, and comparing the full-size vectors gave `e*_1 ≈ 7` on the built-in blade
//! whatever the basis. Dropping them (bare contact rows) was informative on the blade but not
//! conservative on the spring-mass chain (`e* = 0.012 < e = 0.066`). So FR's
//! [`ReducedModel::implied_contact_force`] moves `r_y` onto the contact rows as the contact
//! force it stands for, `-D_wy D_yy^-1 r_y`: the `w` rows are then `H_h w_h - g_h`, the
//! full-order (condensed) residual at the reduced contact motion, the same form as NLR's.
//! Conservative on every case tested (tests/rom_reproduce.rs, tests/rom_prediction.rs,
//! tests/jp_blade.rs), and of the order of the actual error, as in the paper's Fig. 6.
//! The actual error (44) against a full-order solution is `e_h = |F_FO^h - F_ROM^h| / |F_ROM^h|`.
//!
//! **Where `e*` is not conservative, and the check that is.** `e*` is the full-order residual
//! `r` at the reduced contact motion, relative to the contact force; the actual error is the
//! force error that residual leaves, `F(w_FO) - F(w_ROM) ≈ K̂ δw` with `δw = -J^-1 r` and `J`
//! the condensed full-order Jacobian `H + K̂`. So `e / e* ≈ |K̂ J^-1 r| / |r|`, which exceeds 1
//! where `J` is soft along the part of `r` it amplifies: near a resonance, when the reduced
//! model's (Galerkin) residual is not orthogonal to the resonant mode's *left* vector, which it
//! need not be since `J` is not symmetric (damping, friction). Measured on the spring-mass
//! chain at `H = 3` with a deliberately small basis (the paper's FR, sizes `[5, 4, 2, 2]`):
//! `e*_1 = 0.030 < e_1 = 0.032`. [`linearised_error`] evaluates that relation itself: one
//! Newton step of the condensed full-order system from the reduced solution,
//! `e_lin = |F(w + δw) - F(w)| / |F(w)|` (the same case: `e_lin = 0.032`, equal to `e` to three
//! digits). It costs one factorisation of `J`, about one full-order Newton iteration, so the
//! self-correcting sweep ([`crate::rom::adaptive_sweep`]) evaluates it at the few points that
//! decide (the reduced resonance and the worst `e*`) and acts on the larger of the two.

use crate::aft::{evaluate_contacts, AftPlan, ContactCycle, ContactForces};
use crate::condensation::CondensedSystem;
use crate::hbm::residual::{evaluate, ResidualWorkspace};
use crate::hbm::HarmonicSystem;
use crate::error::{JpError, Result};
use crate::hbm::{HbmOptions, PointSolution};
use serde::{Deserialize, Serialize};
use crate::rom::ReducedModel;

/// Threshold of `e*_1` above which a basis is called poor (the paper's practical limit).
pub const POOR_BASIS_THRESHOLD: f64 = 0.05;

/// Harmonic-major contact displacement `w` of a reduced solution.
pub fn reduced_contact_displacement(rom: &dyn ReducedModel, omega: f64, z: &[f64]) -> Result<Vec<f64>> {
    let nw = rom.n_contact_coords();
    let coeffs = rom.full_coefficients(omega, z)?;
    let mut w = Vec::with_capacity(nw * coeffs.len());
    for c in &coeffs {
        w.extend_from_slice(&c[..nw]);
    }
    Ok(w)
}

/// Harmonic-major contact displacement `w` of a full-order or condensed full-order solution
/// (a system whose unknowns start with `w` in every coefficient); see
/// [`PointSolution::contact_displacement`].
///
/// # Errors
/// As [`PointSolution::contact_displacement`].
pub fn full_order_contact_displacement(fo: &PointSolution, n_w: usize) -> Result<Vec<f64>> {
    fo.contact_displacement(n_w)
}

/// Contact forces (and, on request, cycle reports) at the harmonic-major `w`.
///
/// # Errors
/// A failed external law's error ([`JpError::Callback`]), never its NaN.
pub fn contact_forces(rom: &dyn ReducedModel, w: &[f64], want_cycles: bool) -> Result<ContactForces> {
    contact_forces_with(rom, &rom.discretisation().plan()?, w, want_cycles)
}

fn contact_forces_with(rom: &dyn ReducedModel, plan: &AftPlan, w: &[f64], want_cycles: bool) -> Result<ContactForces> {
    let mut out = ContactForces::default();
    evaluate_contacts(plan, rom.contact_laws(), rom.contact_offsets(), rom.n_contact_coords(), w, false, want_cycles, &mut out);
    out.check()?;
    Ok(out)
}

/// Norm over the cos and sin parts of harmonic `h` of per-coefficient vectors.
fn harmonic_norm(per_coeff: &[Vec<f64>], h: usize) -> f64 {
    let ks: &[usize] = if h == 0 { &[0] } else { &[2 * h - 1, 2 * h] };
    ks.iter().map(|&k| per_coeff[k].iter().map(|x| x * x).sum::<f64>()).sum::<f64>().sqrt()
}

/// Harmonic-major `w` (`n_coeffs` blocks of `n_w`) as one vector per coefficient. A model
/// without contacts (`n_w = 0`) gives `n_coeffs` empty vectors, so its `e*` is 0.
fn split(w: &[f64], n_w: usize, n_coeffs: usize) -> Vec<Vec<f64>> {
    if n_w == 0 {
        return vec![Vec::new(); n_coeffs];
    }
    w.chunks(n_w).map(|c| c.to_vec()).collect()
}

/// The predicted error `e*_h`, `h = 0..=H` (43) of the reduced solution `z` at `omega`.
/// A harmonic with no contact force gives `e*_h = 0` if the implied force is zero too, else
/// infinity.
///
/// # Errors
/// Size errors from the model.
pub fn predicted_error(rom: &dyn ReducedModel, omega: f64, z: &[f64]) -> Result<Vec<f64>> {
    predicted_error_with(rom, &rom.discretisation().plan()?, omega, z)
}

/// [`predicted_error`] with the ROM's AFT plan made once by the caller (a sweep's points).
pub(crate) fn predicted_error_with(rom: &dyn ReducedModel, plan: &AftPlan, omega: f64, z: &[f64]) -> Result<Vec<f64>> {
    let hh = rom.layout().harmonics;
    let nw = rom.n_contact_coords();
    let w = reduced_contact_displacement(rom, omega, z)?;
    let forces = contact_forces_with(rom, plan, &w, false)?;
    let f_rom = split(&forces.force, nw, 2 * hh + 1);
    let mut defect = rom.implied_contact_force(omega, z)?;
    // Contact rows only (see the module doc).
    for d in defect.iter_mut() {
        d.truncate(nw);
    }
    // f* - f_ROM = f* + F on the contact rows.
    for (d, f) in defect.iter_mut().zip(&f_rom) {
        for (di, fi) in d.iter_mut().zip(f) {
            *di += fi;
        }
    }
    Ok((0..=hh).map(|h| ratio(harmonic_norm(&defect, h), harmonic_norm(&f_rom, h))).collect())
}

fn ratio(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        num / den
    } else if num == 0.0 {
        0.0
    } else {
        f64::INFINITY
    }
}

/// The actual error `e_h`, `h = 0..=H` (44): contact forces of the reduced solution against
/// those of a full-order solution `fo` (of a [`crate::hbm::FullSystem`] or
/// [`crate::condensation::CondensedSystem`] of the same model and `H`).
///
/// # Errors
/// Size errors; a full-order solution whose `H` differs.
pub fn actual_error(rom: &dyn ReducedModel, omega: f64, z: &[f64], fo: &PointSolution) -> Result<Vec<f64>> {
    let hh = rom.layout().harmonics;
    let plan = &rom.discretisation().plan()?;
    if fo.layout.harmonics != hh {
        return Err(JpError::invalid("full-order solution", format!("H = {}, model H = {hh}", fo.layout.harmonics)));
    }
    let nw = rom.n_contact_coords();
    let f_rom = split(&contact_forces_with(rom, plan, &reduced_contact_displacement(rom, omega, z)?, false)?.force, nw, 2 * hh + 1);
    let f_fo = split(&contact_forces_with(rom, plan, &full_order_contact_displacement(fo, nw)?, false)?.force, nw, 2 * hh + 1);
    let diff: Vec<Vec<f64>> = f_rom.iter().zip(&f_fo).map(|(a, b)| a.iter().zip(b).map(|(x, y)| x - y).collect()).collect();
    Ok((0..=hh).map(|h| ratio(harmonic_norm(&diff, h), harmonic_norm(&f_rom, h))).collect())
}

/// The linearised actual error `e_lin_h`, `h = 0..=H`, of the reduced solution `z` at `omega`
/// (see the module doc): one Newton step `δw = -J^-1 r` of the condensed full-order system
/// `condensed` (of the same model and `H`) from the reduced contact motion `w`, and
/// `e_lin_h = |F^h(w + δw) - F^h(w)| / |F^h(w)|`. Equal to the actual error (44) to first
/// order, without a full-order solution. [`linearised_errors`] gives the static contact
/// displacement's error from the same step.
///
/// # Errors
/// Size errors; a system whose `H` differs; [`JpError::SingularMatrix`] if `J` is singular at
/// this point.
pub fn linearised_error(rom: &dyn ReducedModel, condensed: &CondensedSystem, omega: f64, z: &[f64]) -> Result<Vec<f64>> {
    Ok(linearised_errors(rom, condensed, omega, z)?.force)
}

/// What one full-order Newton step from a reduced solution says of its error
/// ([`linearised_errors`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LinearisedErrors {
    /// `e_lin_h`, `h = 0..=H`: the contact forces' error per harmonic ([`linearised_error`]).
    pub force: Vec<f64>,
    /// `|δw_0| / |w_0 + δw_0|`: the static contact displacement's error (docs/formulation.md
    /// §10.6). The contact forces' static part can be right while the static displacement is
    /// not: at gross slip the mean friction force hardly depends on the static offsets, so a
    /// small force error leaves a large offset error (on the blade at alpha_ST / 3000,
    /// `e_lin_0` = 0.0078 with the static contact displacement 2.1 times its size off;
    /// tests/static_term.rs).
    pub static_displacement: f64,
}

/// [`linearised_error`] and the static contact displacement's error from the same Newton step.
///
/// # Errors
/// As [`linearised_error`].
pub fn linearised_errors(rom: &dyn ReducedModel, condensed: &CondensedSystem, omega: f64, z: &[f64]) -> Result<LinearisedErrors> {
    Ok(newton_probe(rom, condensed, omega, z, false)?.errors)
}

/// One Newton step of the condensed full-order system from a reduced solution, and on request
/// a second (chord) step with the same factorisation.
struct Probe {
    errors: LinearisedErrors,
    /// The largest `|δw_k| / |δw_{k-1}|` of the chord steps (0 where `δw_1 = 0`); `None`
    /// without them.
    contraction: Option<f64>,
    /// `w + δw_1`: the start of a full-order Newton solve where the contraction is poor.
    corrected: Vec<f64>,
    /// Per harmonic, relative to `|F^h(w)|`: `|F^h(w_K) - F^h(w)|` and `|F^h(w_K) - F^h(w_{K-1})|`
    /// at the last chord iterates (`K` = [`CHORD_STEPS`], fewer where `θ` exceeded
    /// [`MAX_CONTRACTION`]); empty without the chord steps.
    chord: Vec<(f64, f64)>,
    /// Per harmonic: no contact force in it at the reduced point (every contact open over the
    /// cycle) while the contacts move; `chord` then holds the contact motion's errors.
    open: Vec<bool>,
    /// The reduced contact motion `w`, per coefficient.
    w: Vec<Vec<f64>>,
}

fn newton_probe(rom: &dyn ReducedModel, condensed: &CondensedSystem, omega: f64, z: &[f64], chord_steps: bool) -> Result<Probe> {
    let hh = rom.layout().harmonics;
    let nw = rom.n_contact_coords();
    if condensed.layout().harmonics != hh || condensed.n_contact_coords() != nw {
        return Err(JpError::invalid("condensed system", format!("H = {}, n_w = {}; the reduced model has H = {hh}, n_w = {nw}", condensed.layout().harmonics, condensed.n_contact_coords())));
    }
    let w = reduced_contact_displacement(rom, omega, z)?;
    let lin = condensed.linear_part(omega)?;
    let plan = &condensed.discretisation().plan()?;
    let mut ws = ResidualWorkspace::new();
    let (r, jac) = evaluate(condensed, &lin, Some(plan), &w, true, &mut ws)?;
    let jac = jac.expect("jacobian requested").into_dense();
    let lu = crate::linalg::lu_checked(&jac, &format!("condensed full-order Jacobian at omega = {omega} (linearised error)"))?;
    let dw = crate::linalg::lu_solve(&lu, &r);
    let corrected: Vec<f64> = w.iter().zip(&dw).map(|(a, d)| a - d).collect();
    let f_rom = split(&contact_forces_with(rom, plan, &w, false)?.force, nw, 2 * hh + 1);
    let f_new = split(&contact_forces_with(rom, plan, &corrected, false)?.force, nw, 2 * hh + 1);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let relative = |a: &[Vec<f64>], b: &[Vec<f64>], h: usize| ratio(harmonic_norm(&difference(a, b), h), harmonic_norm(&f_rom, h));
    // a harmonic in which no contact carries force over the cycle (all open) has no force error;
    // its contact motion's error stands for it
    let w_parts = split(&w, nw, 2 * hh + 1);
    let open: Vec<bool> = (0..=hh).map(|h| harmonic_norm(&f_rom, h) == 0.0 && harmonic_norm(&w_parts, h) > 0.0).collect();
    let (contraction, chord) = if chord_steps {
        // chord steps with the same factorisation: w_k = w_{k-1} + δw_k, θ the largest
        // |δw_k| / |δw_{k-1}| met
        let (mut theta, mut last_step, mut w_k, mut f_prev) = (0.0f64, norm(&dw), corrected.clone(), f_new.clone());
        let (mut f_k, mut w_prev) = (f_new.clone(), w.clone());
        for _ in 1..CHORD_STEPS {
            let (r_k, _) = evaluate(condensed, &lin, Some(plan), &w_k, false, &mut ws)?;
            let dw_k = crate::linalg::lu_solve(&lu, &r_k);
            let step = norm(&dw_k);
            theta = theta.max(if last_step > 0.0 { step / last_step } else if step == 0.0 { 0.0 } else { f64::INFINITY });
            last_step = step;
            w_prev.clone_from(&w_k);
            w_k.iter_mut().zip(&dw_k).for_each(|(a, d)| *a -= d);
            f_prev = std::mem::replace(&mut f_k, split(&contact_forces_with(rom, plan, &w_k, false)?.force, nw, 2 * hh + 1));
            if !(theta <= MAX_CONTRACTION) {
                break;
            }
        }
        let (ws_k, ws_prev) = (split(&w_k, nw, 2 * hh + 1), split(&w_prev, nw, 2 * hh + 1));
        let chord = (0..=hh)
            .map(|h| match open[h] {
                false => (relative(&f_k, &f_rom, h), relative(&f_k, &f_prev, h)),
                true => (displacement_error(&ws_k, &w_parts, h), ratio(harmonic_norm(&difference(&ws_k, &ws_prev), h), harmonic_norm(&w_parts, h))),
            })
            .collect();
        (Some(theta), chord)
    } else {
        (None, Vec::new())
    };
    let errors = LinearisedErrors {
        force: (0..=hh).map(|h| relative(&f_new, &f_rom, h)).collect(),
        static_displacement: ratio(norm(&dw[..nw]), norm(&corrected[..nw])),
    };
    Ok(Probe { errors, contraction, corrected, chord, open, w: w_parts })
}

fn difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> Vec<Vec<f64>> {
    a.iter().zip(b).map(|(x, y)| x.iter().zip(y).map(|(p, q)| p - q).collect()).collect()
}

/// `|a^h - w^h| / |w^h|` of two contact motions split per coefficient.
fn displacement_error(a: &[Vec<f64>], w: &[Vec<f64>], h: usize) -> f64 {
    ratio(harmonic_norm(&difference(a, w), h), harmonic_norm(w, h))
}

/// Chord steps [`checked_error`] takes from a reduced point (the first a Newton step).
pub const CHORD_STEPS: usize = 3;

/// Largest contraction `θ` of the chord step for which [`checked_error`] takes the linearised
/// error as the estimate `e_lin / (1 - θ)`.
pub const MAX_CONTRACTION: f64 = 0.5;

/// Relative margin [`checked_error`] adds to its estimate: the full-order solution it stands for
/// is itself converged only to the corrector's residual tolerance, and another solve of the same
/// point (from another start) lands within that tolerance times the condition of `J` of it, not
/// on it (near the inclined-patch model's resonance two such solves differ by up to 5e-5
/// relative in the error they give; docs/formulation.md §10.7).
pub const CHECK_MARGIN: f64 = 1e-3;

/// Absolute margin [`checked_error`] adds to its estimate, for the same reason: the corrector's
/// default residual tolerance (`HbmOptions::residual_tolerance`, 1e-10), so that a complete basis is still judged at its solver's accuracy.
pub const CHECK_FLOOR: f64 = 1e-10;

/// How [`checked_error`] reached its estimate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum CheckBasis {
    /// The chord iteration from the reduced point contracts (`θ <= 1/2`): the estimate is
    /// the chord-iteration estimate of [`checked_error`].
    Contracting,
    /// It does not: the full-order solution Newton reaches from the reduced point judged it
    /// (the actual error (44) against that solution).
    Solved,
    /// Neither: no full-order solution was reached from the reduced point; the estimate is
    /// infinite.
    Unverified,
}

/// The checked error of a reduced point ([`checked_error`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedError {
    /// The linearised errors of the first Newton step.
    pub linearised: LinearisedErrors,
    /// `θ`, the chord iteration's contraction (the largest `|δw_k| / |δw_{k-1}|`).
    pub contraction: f64,
    /// The estimate per harmonic, `h = 0..=H` (see [`CheckBasis`]).
    pub error: Vec<f64>,
    pub basis: CheckBasis,
}

/// The error of the reduced solution `z` at `omega` as the self-correcting sweep checks it
/// (docs/formulation.md §10.7). One Newton step `δw_1 = -J^-1 r` of the condensed full-order
/// system from the reduced contact motion `w` gives `e_lin` ([`linearised_errors`]); further
/// steps with the same factorisation, `δw_k = -J^-1 r(w_{k-1})` ([`CHORD_STEPS`] in all),
/// measure the contraction `θ = max |δw_k| / |δw_{k-1}|` of that (chord) iteration. Where
/// `θ <= 1/2` the iteration converges to a full-order solution `w_FO` with
/// `|w_FO - w_K| <= |δw_K| θ / (1 - θ)`, and the estimate is the larger of `e_lin_h / (1 - θ)`
/// and the force error at the last iterate plus the geometric tail of the rest,
/// `(|F^h(w_K) - F^h(w)| + |F^h(w_K) - F^h(w_{K-1})| θ / (1 - θ)) / |F^h(w)|` (the contact
/// forces are not linear in `w`, so the first alone can fall short), each raised by
/// [`CHECK_MARGIN`] and [`CHECK_FLOOR`]. A harmonic with no contact force at the reduced point
/// while the contacts move (all open) is judged by its contact motion's error instead, the same
/// estimate with `w^h` for `F^h`. Where `θ` is larger (a contact changing state within the steps, a fold
/// near), Newton is run from `w + δw_1` to a full-order solution and the actual error (44)
/// against it is the estimate; where none is reached the estimate is infinite: such a point is
/// never called good. The cost: one factorisation, [`CHORD_STEPS`] residuals and as many
/// contact-force evaluations, plus a Newton solve where the chord iteration does not contract.
///
/// # Errors
/// As [`linearised_error`].
pub fn checked_error(rom: &dyn ReducedModel, condensed: &CondensedSystem, omega: f64, z: &[f64], hopts: &HbmOptions) -> Result<CheckedError> {
    let probe = newton_probe(rom, condensed, omega, z, true)?;
    let theta = probe.contraction.unwrap_or(f64::INFINITY);
    if theta <= MAX_CONTRACTION {
        let tail = theta / (1.0 - theta);
        let error = probe.errors.force.iter().zip(&probe.chord).map(|(e_lin, (to_last, last))| (e_lin / (1.0 - theta)).max(to_last + last * tail) * (1.0 + CHECK_MARGIN) + CHECK_FLOOR).collect();
        return Ok(CheckedError { linearised: probe.errors, contraction: theta, error, basis: CheckBasis::Contracting });
    }
    let solved = crate::hbm::solve_point(condensed, omega, Some(&probe.corrected), hopts).ok();
    let nw = rom.n_contact_coords();
    let with_open = |fo: PointSolution| -> Option<Vec<f64>> {
        let mut e = actual_error(rom, omega, z, &fo).ok()?;
        let w_fo = split(&full_order_contact_displacement(&fo, nw).ok()?, nw, 2 * rom.layout().harmonics + 1);
        for (h, e_h) in e.iter_mut().enumerate().filter(|(h, _)| probe.open[*h]) {
            *e_h = e_h.max(displacement_error(&w_fo, &probe.w, h));
        }
        Some(e)
    };
    let (error, basis) = match solved.and_then(with_open) {
        Some(e) => (e.iter().map(|e| e * (1.0 + CHECK_MARGIN) + CHECK_FLOOR).collect(), CheckBasis::Solved),
        None => (vec![f64::INFINITY; rom.layout().harmonics + 1], CheckBasis::Unverified),
    };
    Ok(CheckedError { linearised: probe.errors, contraction: theta, error, basis })
}

/// Relative error of harmonic `h` of the output response, `|X_ROM^h - X_FO^h| / |X_FO^h|`
/// over all output DoFs (cos and sin parts together), from two output vectors laid out as
/// [`PointSolution::outputs`].
pub fn output_error(rom_outputs: &[f64], fo_outputs: &[f64], n_outputs: usize, h: usize) -> f64 {
    let ks: Vec<usize> = if h == 0 { vec![0] } else { vec![2 * h - 1, 2 * h] };
    let (mut num, mut den) = (0.0, 0.0);
    for k in ks {
        for j in 0..n_outputs {
            let (a, b) = (rom_outputs[k * n_outputs + j], fo_outputs[k * n_outputs + j]);
            num += (a - b) * (a - b);
            den += b * b;
        }
    }
    ratio(num.sqrt(), den.sqrt())
}

/// Per-contact cycle reports (states, dissipated energy) of a reduced solution.
pub fn reduced_contact_cycles(rom: &dyn ReducedModel, omega: f64, z: &[f64]) -> Result<Vec<ContactCycle>> {
    let w = reduced_contact_displacement(rom, omega, z)?;
    Ok(contact_forces(rom, &w, true)?.cycles)
}
