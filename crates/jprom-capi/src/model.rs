//! `jprom_model`: building a structural model (docs/formulation.md §1) from C.
//!
//! A model starts from `M` and `K` and is completed by setters; each setter validates the
//! whole model and leaves it unchanged on failure.

use super::guard::{csc_entries, ffi_guard, finite_arg, mul_size, out_arg, path_arg, slice_arg, slice_out};
use super::handle::{self, Handle};
use super::status::jprom_status::{self, *};
use super::status::FfiError;
use jprom::contact::{Contact, ContactLaw, ExternalFn, ExternalLaw, IDENTITY_FRAME};
use jprom::error::Result;
use jprom::model::contact_coordinates::ContactTopology;
use jprom::model::{Damping, Excitation, HarmonicForce, Model};
use faer::Mat;
use std::ffi::{c_char, c_void};
use std::sync::Arc;

/// Opaque structural model: `M`, `K`, damping, excitation, contacts, output DoFs.
/// Created by `jprom_model_new`, `jprom_model_new_csc`, `jprom_model_load_json` or
/// `jprom_model_clone`; owned by the caller, released with `jprom_model_free`.
#[allow(non_camel_case_types)]
pub struct jprom_model {
    magic: u64,
    pub(crate) model: Model,
    /// How the contacts added so far combine, so that each addition is checked against them
    /// in O(1) (built from the model's contacts at the first addition).
    topology: Option<ContactTopology>,
}

impl Handle for jprom_model {
    const MAGIC: u64 = 0x4A50_524F_4D4D_4F44; // "JPROMMOD"
    const KIND: &'static str = "jprom_model";
    fn magic_mut(&mut self) -> &mut u64 {
        &mut self.magic
    }
    fn magic(&self) -> u64 {
        self.magic
    }
}

impl jprom_model {
    pub(crate) fn wrap(model: Model) -> *mut jprom_model {
        handle::into_raw(jprom_model { magic: Self::MAGIC, model, topology: None })
    }
}

/// Largest model size accepted by `jprom_model_new_csc` (the model is stored dense:
/// two `n x n` matrices of doubles).
pub const JPROM_DENSE_MAX_DOF: usize = 10000;

/// Applies `set` to the model, validates, and restores the previous value on failure.
fn replace_validated<T>(model: &mut Model, field: fn(&mut Model) -> &mut T, value: T) -> Result<()> {
    let old = std::mem::replace(field(model), value);
    if let Err(e) = model.validate() {
        *field(model) = old;
        return Err(e);
    }
    Ok(())
}

fn new_model(mass: Mat<f64>, stiffness: Mat<f64>) -> Result<Model> {
    let n = stiffness.nrows();
    Model::new(mass, stiffness, Damping::default(), Excitation::zero(n), Vec::new(), Vec::new())
}

/// Creates a model with `n` DoFs from dense, column-major `n x n` mass and stiffness
/// matrices (both symmetric; `M` with positive diagonal). Damping, excitation, contacts and
/// output DoFs start empty. The arrays are copied.
///
/// On success `*out` receives a new handle (free it with `jprom_model_free`); on failure
/// `*out` is not written.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_new(
    n: usize,
    mass: *const f64,
    stiffness: *const f64,
    out: *mut *mut jprom_model,
) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        if n == 0 {
            return Err(FfiError::new(JPROM_INVALID_VALUE, "n must be > 0"));
        }
        let nn = mul_size("mass", n, n)?;
        let m = slice_arg(mass, nn, "mass")?;
        let k = slice_arg(stiffness, nn, "stiffness")?;
        // the model keeps M and K dense, and its checks make a copy
        jprom::memory::check(&format!("a dense model of n = {n}"), jprom::memory::bytes_of::<f64>(jprom::memory::product(&[3, n, n])))?;
        let model = new_model(
            Mat::from_fn(n, n, |i, j| m[i + j * n]),
            Mat::from_fn(n, n, |i, j| k[i + j * n]),
        )?;
        *out = jprom_model::wrap(model);
        Ok(())
    })
}

/// Reads one CSC matrix (0-based `colptr[n + 1]`, `rowind[nnz]`, `values[nnz]`,
/// `nnz = colptr[n]`) into a dense matrix, summing duplicates.
unsafe fn csc_to_dense(
    name: &str,
    n: usize,
    colptr: *const usize,
    rowind: *const usize,
    values: *const f64,
) -> std::result::Result<Mat<f64>, FfiError> {
    let mut a = Mat::<f64>::zeros(n, n);
    for (i, j, v) in csc_entries(name, n, colptr, rowind, values)? {
        a[(i, j)] += v;
    }
    Ok(a)
}

/// Creates a model from mass and stiffness matrices in compressed sparse column form
/// (0-based; `*_colptr` has `n + 1` entries starting at 0, `*_rowind` and `*_values` have
/// `colptr[n]` entries; both triangles must be given; duplicates are summed). The model is
/// stored dense, so `n <= JPROM_DENSE_MAX_DOF` (else `JPROM_BAD_SIZE`).
///
/// Ownership and `*out` as for `jprom_model_new`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_new_csc(
    n: usize,
    mass_colptr: *const usize,
    mass_rowind: *const usize,
    mass_values: *const f64,
    stiffness_colptr: *const usize,
    stiffness_rowind: *const usize,
    stiffness_values: *const f64,
    out: *mut *mut jprom_model,
) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        if n == 0 {
            return Err(FfiError::new(JPROM_INVALID_VALUE, "n must be > 0"));
        }
        if n > JPROM_DENSE_MAX_DOF {
            return Err(FfiError::new(
                JPROM_BAD_SIZE,
                format!("n = {n} exceeds JPROM_DENSE_MAX_DOF = {JPROM_DENSE_MAX_DOF}"),
            ));
        }
        let m = csc_to_dense("mass", n, mass_colptr, mass_rowind, mass_values)?;
        let k = csc_to_dense("stiffness", n, stiffness_colptr, stiffness_rowind, stiffness_values)?;
        *out = jprom_model::wrap(new_model(m, k)?);
        Ok(())
    })
}

/// Deep copy of a model (e.g. to give each thread its own). `*out` as for `jprom_model_new`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_clone(model: *const jprom_model, out: *mut *mut jprom_model) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let out = out_arg(out, "out")?;
        *out = jprom_model::wrap(m.model.clone());
        Ok(())
    })
}

/// Releases a model. NULL is accepted (no-op). A pointer that is not a live model (already
/// freed, or another handle kind) returns `JPROM_INVALID_HANDLE` when detectable and frees
/// nothing.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_free(model: *mut jprom_model) -> jprom_status {
    ffi_guard!({ handle::free(model, "model") })
}

/// Number of DoFs `n`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_n_dof(model: *const jprom_model, out: *mut usize) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        *out_arg(out, "out")? = m.model.n_dof();
        Ok(())
    })
}

/// Number of contacts added so far (contact `i` is the `i`-th added, 0-based).
#[no_mangle]
pub unsafe extern "C" fn jprom_model_n_contacts(model: *const jprom_model, out: *mut usize) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        *out_arg(out, "out")? = m.model.contacts.len();
        Ok(())
    })
}

/// Number of output DoFs.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_n_outputs(model: *const jprom_model, out: *mut usize) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        *out_arg(out, "out")? = m.model.output_dofs.len();
        Ok(())
    })
}

/// Proportional damping `C = alpha M + beta K` (both `>= 0`, finite).
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_rayleigh_damping(model: *mut jprom_model, alpha: f64, beta: f64) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let d = Damping { mass_coeff: alpha, stiffness_coeff: beta };
        replace_validated(&mut m.model, |m| &mut m.damping, d)?;
        Ok(())
    })
}

/// Stiffness-proportional damping with modal damping ratio `zeta` at angular frequency
/// `omega` (rad/s): `beta = 2 zeta / omega`, `alpha = 0`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_modal_damping(model: *mut jprom_model, zeta: f64, omega: f64) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        finite_arg("zeta", zeta)?;
        if !(finite_arg("omega", omega)? > 0.0) {
            return Err(FfiError::new(JPROM_INVALID_VALUE, format!("omega must be > 0, got {omega}")));
        }
        replace_validated(&mut m.model, |m| &mut m.damping, Damping::from_modal_ratio(zeta, omega))?;
        Ok(())
    })
}

/// Viscous damping matrix added to the Rayleigh part: `C = alpha M + beta K + C_added`, from a
/// dense, column-major `n x n` array (`n` = the model's DoF count; symmetric). `c = NULL` with
/// `n = 0` removes it. A model from `jprom_fe_model_reduce` already holds the reduced FE `C` here
/// if one was set with `jprom_fe_model_set_damping_csc`; this replaces it.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_damping_matrix(model: *mut jprom_model, c: *const f64, n: usize) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let value = if c.is_null() && n == 0 {
            None
        } else {
            let nd = m.model.n_dof();
            if n != nd {
                return Err(FfiError::new(JPROM_BAD_SIZE, format!("damping matrix: n = {n}, the model has {nd} DoFs")));
            }
            let a = slice_arg(c, mul_size("c", n, n)?, "c")?;
            if let Some(p) = a.iter().position(|v| !v.is_finite()) {
                return Err(FfiError::new(JPROM_INVALID_VALUE, format!("c[{p}] is not finite")));
            }
            Some(Mat::from_fn(n, n, |i, j| a[i + j * n]))
        };
        replace_validated(&mut m.model, |m| &mut m.added_damping, value)?;
        Ok(())
    })
}

/// Modal damping per mode, on the model's own modes (its `K` and `M`, contacts open): mode `r`
/// (counted from the lowest, rigid-body modes included) gets damping ratio `ratios[r]` for
/// `r < n_ratios` and `others` after; `C_modal = M Phi diag(2 zeta_r omega_r) Phi^T M` replaces
/// the added damping matrix (`jprom_model_set_damping_matrix`). Keep `alpha = beta = 0` for pure
/// modal damping. Ratios finite and `>= 0`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_modal_damping_ratios(model: *mut jprom_model, ratios: *const f64, n_ratios: usize, others: f64) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let r = slice_arg(ratios, n_ratios, "ratios")?;
        let mut next = m.model.clone();
        next.set_modal_damping(r, others)?;
        m.model.added_damping = next.added_damping;
        Ok(())
    })
}

/// Structural (hysteretic) damping: the harmonics see the stiffness `(1 + i eta) K`
/// (`eta` finite, `>= 0`; 0 removes it). The static term is undamped.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_loss_factor(model: *mut jprom_model, eta: f64) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        replace_validated(&mut m.model, |m| &mut m.loss_factor, eta)?;
        Ok(())
    })
}

/// Natural modes of the model, lowest first: with `stuck = 0` of `K`, `M` alone (contacts
/// open), with `stuck = 1` with every contact's stuck springs (`kt1, kt2, kn`) added, the linear
/// limit of a small excitation. Writes the lowest `min(len, n)` modes: `frequency_hz[k]` and, if
/// not NULL, `modal_force[k]` (`|phi^T f_E^1|` of the mass-normalised mode at the current
/// first-harmonic load); `*count` (may be NULL) receives `n`, the number of modes (the model's
/// DoF count). All modes are computed (dense, `O(n^3)`): meant for reduced models.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_modes(
    model: *const jprom_model,
    stuck: i32,
    frequency_hz: *mut f64,
    modal_force: *mut f64,
    len: usize,
    count: *mut usize,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        let boundary = match stuck {
            0 => jprom::model::modes::Boundary::Free,
            1 => jprom::model::modes::Boundary::Stuck,
            s => return Err(FfiError::new(JPROM_INVALID_VALUE, format!("stuck must be 0 or 1, got {s}"))),
        };
        let n = m.model.n_dof();
        let k = len.min(n);
        let freq = slice_out(frequency_hz, k, "frequency_hz")?;
        let force = if modal_force.is_null() { None } else { Some(slice_out(modal_force, k, "modal_force")?) };
        let modes = jprom::model::modes::natural_modes(&m.model, boundary)?;
        for (i, mode) in modes.iter().take(k).enumerate() {
            freq[i] = mode.frequency_hz;
        }
        if let Some(force) = force {
            for (i, mode) in modes.iter().take(k).enumerate() {
                force[i] = mode.modal_force;
            }
        }
        if let Some(c) = count.as_mut() {
            *c = n;
        }
        Ok(())
    })
}

/// Static force `f_E^0` (length `n`, must equal the model's DoF count).
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_static_force(model: *mut jprom_model, force: *const f64, n: usize) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let f = slice_arg(force, n, "force")?.to_vec();
        replace_validated(&mut m.model, |m| &mut m.excitation.static_force, f)?;
        Ok(())
    })
}

/// Highest harmonic index accepted by `jprom_model_set_harmonic_force`.
pub const JPROM_MAX_FORCE_HARMONIC: usize = 1024;

/// Harmonic `h >= 1` of the excitation: `f(t) = cos_part cos(h omega t) + sin_part sin(h omega t)`
/// (before the dynamic scale). Both arrays have length `n`, which must be the model's DoF
/// count (else `JPROM_BAD_SIZE`); either may be NULL, meaning zero. Harmonics never set are
/// zero.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_harmonic_force(
    model: *mut jprom_model,
    h: usize,
    cos_part: *const f64,
    sin_part: *const f64,
    n: usize,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        if h == 0 || h > JPROM_MAX_FORCE_HARMONIC {
            return Err(FfiError::new(
                JPROM_INVALID_VALUE,
                format!("harmonic h = {h} must be in 1..={JPROM_MAX_FORCE_HARMONIC} (use jprom_model_set_static_force for h = 0)"),
            ));
        }
        // the length is checked before anything is allocated from it
        let n_dof = m.model.n_dof();
        if n != n_dof {
            return Err(FfiError::new(JPROM_BAD_SIZE, format!("n = {n} must equal the model's DoF count {n_dof}")));
        }
        jprom::memory::check("the harmonic forces", jprom::memory::bytes_of::<f64>(jprom::memory::product(&[2, h, n_dof])))?;
        let part = |p: *const f64, name: &str| -> std::result::Result<Vec<f64>, FfiError> {
            if p.is_null() { Ok(vec![0.0; n]) } else { Ok(slice_arg(p, n, name)?.to_vec()) }
        };
        let hf = HarmonicForce { cos: part(cos_part, "cos_part")?, sin: part(sin_part, "sin_part")? };
        let mut harmonics = m.model.excitation.harmonics.clone();
        while harmonics.len() < h {
            harmonics.push(HarmonicForce { cos: vec![0.0; n_dof], sin: vec![0.0; n_dof] });
        }
        harmonics[h - 1] = hf;
        replace_validated(&mut m.model, |m| &mut m.excitation.harmonics, harmonics)?;
        Ok(())
    })
}

/// Multiplier of all harmonic (dynamic) force parts; default 1.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_dynamic_scale(model: *mut jprom_model, scale: f64) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        replace_validated(&mut m.model, |m| &mut m.excitation.dynamic_scale, finite_arg("scale", scale)?)?;
        Ok(())
    })
}

/// Sets the dynamic scale so that the excitation level `|f_E^0| / |f_E^1|` equals `alpha > 0`
/// (needs nonzero static and first-harmonic forces).
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_excitation_level(model: *mut jprom_model, alpha: f64) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        m.model.excitation.set_level(alpha)?;
        Ok(())
    })
}

/// Current excitation level `|f_E^0| / |f_E^1|` (infinite without dynamic force).
#[no_mangle]
pub unsafe extern "C" fn jprom_model_excitation_level(model: *const jprom_model, out: *mut f64) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        *out_arg(out, "out")? = m.model.excitation.level();
        Ok(())
    })
}

/// Adds a contact after checking it on its own and against the earlier ones (the handle's
/// matrices were checked when it was made; only the new contact can be wrong now), in O(1).
fn push_contact(m: &mut jprom_model, c: Contact) -> Result<()> {
    let i = m.model.contacts.len();
    m.model.contacts.push(c);
    let checked = m.model.validate_contact(i).and_then(|()| {
        let topology = match m.topology.take() {
            Some(t) => t,
            None => ContactTopology::new(&m.model.contacts[..i])?,
        };
        m.topology = Some(topology);
        m.topology.as_mut().expect("set above").add(&m.model.contacts, i)
    });
    if let Err(e) = checked {
        m.model.contacts.pop();
        return Err(e);
    }
    Ok(())
}

/// Adds a 3D friction contact (docs/formulation.md §4.2). `dofs_a[3]`: the global DoFs (x, y, z) of node
/// `a`; `dofs_b[3]`: those of node `b`, or NULL for a contact with ground. `frame[9]`:
/// row-major rotation whose rows are the unit vectors `t1`, `t2`, `n` (normal pointing into
/// the contact), so the local displacement is `w = R (x_a - x_b)`. Tangential stiffnesses
/// `kt1`, `kt2`, normal stiffness `kn`, friction coefficient `mu` (all `>= 0`), normal preload
/// `n0` (`N = max(0, n0 + kn v)`). The new contact's index is the previous contact count.
/// Values beyond `JPROM_MAX_MAGNITUDE` are `JPROM_INVALID_VALUE`.
///
/// Parallel elements: a second contact with the same `dofs_a`, `dofs_b` and `frame` is
/// accepted and acts in parallel with the first (their forces add on the same relative
/// displacement; docs/formulation.md §4.6), as two friction elements of one contact patch do.
/// A node's DoFs that are the `a` DoFs of another contact with different `dofs_b` or frame
/// are `JPROM_INVALID_VALUE`; a node `b` that is another contact's node `a` chains them.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_add_contact_3d(
    model: *mut jprom_model,
    dofs_a: *const usize,
    dofs_b: *const usize,
    frame: *const f64,
    kt1: f64,
    kt2: f64,
    kn: f64,
    mu: f64,
    n0: f64,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let a = slice_arg(dofs_a, 3, "dofs_a")?;
        let b = if dofs_b.is_null() { None } else { Some(slice_arg(dofs_b, 3, "dofs_b")?.to_vec()) };
        let f = slice_arg(frame, 9, "frame")?;
        let frame = [[f[0], f[1], f[2]], [f[3], f[4], f[5]], [f[6], f[7], f[8]]];
        let c = Contact { dofs_a: a.to_vec(), dofs_b: b, frame, law: ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 } };
        push_contact(m, c)?;
        Ok(())
    })
}

/// Adds a 1D Jenkins element (spring `kt` in series with a slider of limit
/// `mu * normal_load`, constant normal load) on DoF `dof_a`, against ground if `dof_b` is
/// NULL, else relative to DoF `*dof_b`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_add_jenkins(
    model: *mut jprom_model,
    dof_a: usize,
    dof_b: *const usize,
    kt: f64,
    mu: f64,
    normal_load: f64,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let b = if dof_b.is_null() { None } else { Some(*dof_b) };
        push_contact(m, Contact::jenkins(dof_a, b, kt, mu, normal_load))?;
        Ok(())
    })
}

/// Adds a 1D polynomial spring (docs/formulation.md §4.6), memoryless:
/// `F(w) = sum_p c_p w^p` for `p = 1..=n_coefficients`, `c_p = coefficients[p - 1]` (no
/// constant term), on `w = x[dof_a]` against ground if `dof_b` is NULL, else
/// `w = x[dof_a] - x[*dof_b]`; the force on `dof_a` is `-F(w)` (and `+F(w)` on `*dof_b`). The
/// cubic (Duffing) spring `k1 w + k3 w^3` is `coefficients = {k1, 0, k3}`. Coefficients must be
/// finite; they may be negative (softening). 1 to 16 coefficients; `coefficients` is copied.
///
/// Elements may share DoFs: `dof_a` may be the `b` DoF of other elements and `*dof_b` the `a`
/// DoF of another one (a chain, "q1 to ground, q2 - q1"; no cycle), and elements with the same
/// `dof_a` and `dof_b` act in parallel on one coordinate (solutions then report one contact
/// cycle for them, at the first one's place). Any other reuse of `dof_a` is refused.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_add_polynomial_spring(
    model: *mut jprom_model,
    dof_a: usize,
    dof_b: *const usize,
    coefficients: *const f64,
    n_coefficients: usize,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let b = if dof_b.is_null() { None } else { Some(*dof_b) };
        let c = slice_arg(coefficients, n_coefficients, "coefficients")?.to_vec();
        push_contact(m, Contact::polynomial(dof_a, b, c))?;
        Ok(())
    })
}

/// Adds a 1D unilateral spring with gap or preload (docs/formulation.md §4.6):
/// `N = max(0, n0 + kn v)` with `v = x[dof_a]` against ground if `dof_b` is NULL, else
/// `v = x[dof_a] - x[*dof_b]` (positive into the contact); the force on `dof_a` is `-N`. A gap
/// `g > 0` is `n0 = -kn g`. `kn >= 0` and `n0` finite. DoF sharing as for
/// `jprom_model_add_polynomial_spring`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_add_unilateral_spring(
    model: *mut jprom_model,
    dof_a: usize,
    dof_b: *const usize,
    kn: f64,
    n0: f64,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let b = if dof_b.is_null() { None } else { Some(*dof_b) };
        push_contact(m, Contact::unilateral(dof_a, b, kn, n0))?;
        Ok(())
    })
}

/// Adds a 2D friction element (docs/formulation.md §4.6): one tangential direction and the
/// normal. `dofs_a[2]`: the global DoFs (x, y) of node `a`; `dofs_b[2]`: those of node `b`, or
/// NULL for a contact with ground. `frame[4]`: row-major 2 x 2 rotation whose rows are the unit
/// vectors `t` and `n` (normal into the contact), so `w = (u, v) = R (x_a - x_b)`. Tangential
/// spring `kt` with Coulomb friction `mu`, normal spring `kn` (all `>= 0`), preload `n0`
/// (`N = max(0, n0 + kn v)`, `|T| <= mu N`). DoF sharing as for
/// `jprom_model_add_polynomial_spring`, with both DoFs of a node.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_add_friction_2d(
    model: *mut jprom_model,
    dofs_a: *const usize,
    dofs_b: *const usize,
    frame: *const f64,
    kt: f64,
    kn: f64,
    mu: f64,
    n0: f64,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let a = slice_arg(dofs_a, 2, "dofs_a")?;
        let b = if dofs_b.is_null() { None } else { Some(slice_arg(dofs_b, 2, "dofs_b")?) };
        let f = slice_arg(frame, 4, "frame")?;
        let c = Contact::friction_2d(
            [a[0], a[1]],
            b.map(|b| [b[0], b[1]]),
            [[f[0], f[1]], [f[2], f[3]]],
            ContactLaw::Friction2D { kt, kn, mu, n0 },
        );
        push_contact(m, c)?;
        Ok(())
    })
}

/// A user-defined element law (`jprom_model_add_element_callback`): at one time sample, from
/// the local relative displacement `w[dim]`, write the force `force[dim]` (what the element
/// pushes back with, positive when it resists `w`) and the Jacobian `jacobian[dim * dim]`,
/// column-major (`jacobian[r + c * dim] = dF_r / dw_c`); both arrive zeroed. Return 0 on
/// success, nonzero to report an error (the solve then ends with `JPROM_CALLBACK_ERROR`). The
/// pointers are valid during the call only. Must be thread-safe and must not unwind (no C++
/// exception, no longjmp) out of the call.
#[allow(non_camel_case_types)]
pub type jprom_element_fn =
    Option<unsafe extern "C" fn(user_data: *mut c_void, dim: usize, w: *const f64, force: *mut f64, jacobian: *mut f64) -> i32>;

/// The caller's `user_data`, carried into the element law's closure.
#[derive(Clone, Copy)]
struct UserData(*mut c_void);

impl UserData {
    fn ptr(self) -> *mut c_void {
        self.0
    }
}

// SAFETY: jprom never dereferences the pointer; it only hands it back to the caller's
// callback. `jprom_model_add_element_callback` documents that the caller keeps it valid while
// the model (and every model, solution or ROM made from it) lives, and that the callback is
// safe to call from several threads at once with it.
unsafe impl Send for UserData {}
unsafe impl Sync for UserData {}

/// Adds a user-defined memoryless element (docs/formulation.md §4.6) on `dim` = 1, 2 or 3
/// local coordinates: `dofs_a[dim]` the global DoFs of node `a`, `dofs_b[dim]` those of node
/// `b` or NULL for ground, `frame[dim * dim]` the row-major rotation (rows: local axes; NULL =
/// identity), so `w = R (x_a - x_b)`; the force on the structure is `-R^T F` at `a` (and
/// `+R^T F` at `b`). At every AFT time sample jprom calls `callback(user_data, dim, w, force,
/// jacobian)` (see `jprom_element_fn`) and builds the harmonic force and its exact Jacobian
/// from those values.
///
/// * **Memoryless**: `F(t)` may depend on `w(t)` only. A law with memory (hysteresis,
///   friction) needs `dF(t_j)/dw(t_k)` for earlier samples `k < j`: use the built-in friction
///   elements for those.
/// * **Errors**: a nonzero return, or a non-finite force or Jacobian entry, ends
///   `jprom_solve_point` (and a JP prediction) with `JPROM_CALLBACK_ERROR` and the message
///   "element k: callback returned <code> at sample j", `k` the element's index (the previous
///   contact count); no NaN reaches a solution. A sweep (`jprom_sweep`, the ROM sweeps) ends
///   with the same status and message, writing no result (its progress callback has seen the
///   frequencies and amplitudes of the points before the failure).
/// * **Stuck stiffness**: the callback is called once here at `w = 0`; its Jacobian there is
///   the element's linearisation for the stuck limit and the JP modes (a failure here is
///   `JPROM_CALLBACK_ERROR` and the model is unchanged).
/// * **Threads**: the callback may be called from several threads at once (the JP prediction
///   runs frequencies in parallel, the AFT runs many contacts in parallel): it must be
///   thread-safe. `user_data` is stored as given; the caller keeps what it points to alive
///   while the model and every solution, sweep or ROM made from it live.
/// * A model holding a callback element cannot be saved: `jprom_model_save_json` returns
///   `JPROM_INVALID_VALUE` naming the element and writes no file.
///
/// `JPROM_NULL_ARGUMENT` for a NULL `callback`, `dofs_a` or model; `JPROM_INVALID_VALUE` for
/// `dim` not 1..3 or the checks of `jprom_model_add_friction_2d` (DoFs, orthonormal frame).
/// DoF sharing as for `jprom_model_add_polynomial_spring`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_add_element_callback(
    model: *mut jprom_model,
    dim: usize,
    dofs_a: *const usize,
    dofs_b: *const usize,
    frame: *const f64,
    callback: jprom_element_fn,
    user_data: *mut c_void,
) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let cb = callback.ok_or_else(|| FfiError::null("callback"))?;
        if !(1..=3).contains(&dim) {
            return Err(FfiError::new(JPROM_INVALID_VALUE, format!("dim must be 1, 2 or 3, got {dim}")));
        }
        let a = slice_arg(dofs_a, dim, "dofs_a")?.to_vec();
        let b = if dofs_b.is_null() { None } else { Some(slice_arg(dofs_b, dim, "dofs_b")?.to_vec()) };
        let mut full = IDENTITY_FRAME;
        if !frame.is_null() {
            let f = slice_arg(frame, dim * dim, "frame")?;
            full = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    full[i][j] = if i < dim && j < dim { f[i * dim + j] } else if i == j { 1.0 } else { 0.0 };
                }
            }
        }
        let ud = UserData(user_data);
        let f: Arc<ExternalFn> = Arc::new(move |w: &[f64], force: &mut [f64], jac: &mut [f64]| {
            // SAFETY: the slices hold dim, dim and dim * dim values; the callback's contract
            // (jprom_element_fn) is the caller's.
            let code = unsafe { cb(ud.ptr(), w.len(), w.as_ptr(), force.as_mut_ptr(), jac.as_mut_ptr()) };
            if code == 0 {
                Ok(())
            } else {
                Err(format!("callback returned {code}"))
            }
        });
        let index = m.model.contacts.len();
        let law = ExternalLaw::labelled(dim, format!("element {index}"), f)?;
        push_contact(m, Contact { dofs_a: a, dofs_b: b, frame: full, law: ContactLaw::External(law) })?;
        Ok(())
    })
}

/// DoFs whose response is reported by solutions and sweeps (0-based, `n_outputs` entries;
/// NULL allowed when `n_outputs == 0`). Replaces any previous list.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_set_output_dofs(model: *mut jprom_model, dofs: *const usize, n_outputs: usize) -> jprom_status {
    ffi_guard!({
        let m = handle::get_mut(model, "model")?;
        let d = slice_arg(dofs, n_outputs, "dofs")?.to_vec();
        replace_validated(&mut m.model, |m| &mut m.output_dofs, d)?;
        Ok(())
    })
}

/// Re-runs every model check (sizes, symmetry, finite values, contacts, DoF indices).
#[no_mangle]
pub unsafe extern "C" fn jprom_model_validate(model: *const jprom_model) -> jprom_status {
    ffi_guard!({
        handle::get(model, "model")?.model.validate()?;
        Ok(())
    })
}

/// Saves the model as versioned JSON at `path` (NUL-terminated UTF-8).
#[no_mangle]
pub unsafe extern "C" fn jprom_model_save_json(model: *const jprom_model, path: *const c_char) -> jprom_status {
    ffi_guard!({
        let m = handle::get(model, "model")?;
        m.model.save_json(&path_arg(path, "path")?)?;
        Ok(())
    })
}

/// Loads and validates a model saved by `jprom_model_save_json`: `JPROM_IO` for a missing
/// file, a directory or a file of another kind (it says which), `JPROM_PARSE` with the line for
/// malformed JSON or an unknown key, the model checks' status otherwise. `*out` as for
/// `jprom_model_new`.
#[no_mangle]
pub unsafe extern "C" fn jprom_model_load_json(path: *const c_char, out: *mut *mut jprom_model) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let model = Model::load_json(&path_arg(path, "path")?)?;
        *out = jprom_model::wrap(model);
        Ok(())
    })
}
