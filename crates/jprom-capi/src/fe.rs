//! `jprom_fe_model`: a user's FE model (sparse `K`, `M` and its nodes, or CalculiX output)
//! reduced by Craig-Bampton to a `jprom_model` (docs/formulation.md §12). The numerics are the
//! core's [`jprom::fe::FeModel`]; this file converts arguments and keeps the handle.
//!
//! A caller creates the FE model (`jprom_fe_model_new_csc` or `jprom_fe_model_load_calculix`),
//! places contacts, forces, outputs and extra nodes on node ids (`jprom_fe_model_add_*`, checked at
//! once), and calls `jprom_fe_model_reduce`, which returns a new `jprom_model` for the rest of the API.

use super::guard::{csc_entries, ffi_guard, finite_arg, out_arg, path_arg, slice_arg, slice_out};
use super::handle::{self, Handle};
use super::model::jprom_model;
use super::status::jprom_status::{self, *};
use super::status::FfiError;
use jprom::contact::ContactLaw;
use jprom::fe::{FeModel, FeNode, NodalContact, NodalForce, Reduction};
use jprom::io::calculix::read_model;
use jprom::linalg::{sparse_from_triplets, SparseMat};
use jprom::model::Damping;
use std::ffi::c_char;

/// Opaque FE model with what is placed on it so far. Created by `jprom_fe_model_new_csc` or
/// `jprom_fe_model_load_calculix`, released with `jprom_fe_model_free`.
#[allow(non_camel_case_types)]
pub struct jprom_fe_model {
    magic: u64,
    pub(crate) fe: FeModel,
    pub(crate) spec: Reduction,
}

impl Handle for jprom_fe_model {
    const MAGIC: u64 = 0x4A50_524F_4D46_454D; // "JPROMFEM"
    const KIND: &'static str = "jprom_fe_model";
    fn magic_mut(&mut self) -> &mut u64 {
        &mut self.magic
    }
    fn magic(&self) -> u64 {
        self.magic
    }
}

fn wrap(fe: FeModel) -> *mut jprom_fe_model {
    handle::into_raw(jprom_fe_model { magic: jprom_fe_model::MAGIC, fe, spec: Reduction::default() })
}

/// A CSC matrix from the caller, checked ([`csc_entries`], finite values), as a sparse matrix
/// (duplicates summed).
unsafe fn csc_arg(name: &str, n: usize, colptr: *const usize, rowind: *const usize, values: *const f64) -> Result<SparseMat, FfiError> {
    let entries = csc_entries(name, n, colptr, rowind, values)?;
    if let Some(p) = entries.iter().position(|e| !e.2.is_finite()) {
        return Err(FfiError::new(JPROM_INVALID_VALUE, format!("{name}_values[{p}] is not finite")));
    }
    Ok(sparse_from_triplets(n, n, entries)?)
}

/// Creates an FE model from sparse symmetric stiffness and mass matrices in compressed sparse
/// column form (0-based, both triangles, duplicates summed; `n` up to what the memory budget
/// allows: nothing dense of size `n` is formed) and its nodes: `node_ids[n_nodes]` and
/// `node_rows[6 * n_nodes]`, the matrix rows of each node's directions x, y, z, rx, ry, rz
/// (`-1` for a direction the node does not have, e.g. fixed). A row may belong to one node
/// only. `*out` is written only on success; free it with `jprom_fe_model_free`.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_new_csc(
    n: usize,
    stiffness_colptr: *const usize,
    stiffness_rowind: *const usize,
    stiffness_values: *const f64,
    mass_colptr: *const usize,
    mass_rowind: *const usize,
    mass_values: *const f64,
    n_nodes: usize,
    node_ids: *const i64,
    node_rows: *const i64,
    out: *mut *mut jprom_fe_model,
) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        if n == 0 {
            return Err(FfiError::new(JPROM_INVALID_VALUE, "n must be > 0"));
        }
        let k = csc_arg("stiffness", n, stiffness_colptr, stiffness_rowind, stiffness_values)?;
        let m = csc_arg("mass", n, mass_colptr, mass_rowind, mass_values)?;
        let ids = slice_arg(node_ids, n_nodes, "node_ids")?;
        let rows = slice_arg(node_rows, super::guard::mul_size("node_rows", n_nodes, 6)?, "node_rows")?;
        let mut nodes = Vec::with_capacity(n_nodes);
        for (i, &id) in ids.iter().enumerate() {
            let mut dofs = [None; 6];
            for (d, slot) in dofs.iter_mut().enumerate() {
                let r = rows[6 * i + d];
                *slot = match r {
                    -1 => None,
                    r if r >= 0 => Some(r as usize),
                    r => return Err(FfiError::new(JPROM_INVALID_VALUE, format!("node_rows[{}] = {r}: a row or -1", 6 * i + d))),
                };
            }
            nodes.push(FeNode { id, coords: None, dofs });
        }
        *out = wrap(FeModel::new(k, m, nodes)?);
        Ok(())
    })
}

/// Reads a CalculiX model: `inp` is the deck of a `*FREQUENCY, SOLVER=MATRIXSTORAGE` run; its
/// `.sti`, `.mas` and `.dof` (same job name) give `K`, `M` and the rows, the deck the node
/// coordinates and `*NSET`s (`jprom_fe_model_node_set`). Rows of fixed DoFs are absent, so a
/// clamped node has no DoF. `*out` is written only on success.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_load_calculix(inp: *const c_char, out: *mut *mut jprom_fe_model) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let ccx = read_model(&path_arg(inp, "inp")?)?;
        let fe = FeModel::from_calculix(&ccx)?;
        *out = wrap(fe);
        Ok(())
    })
}

/// Releases an FE model (NULL is a no-op).
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_free(fe: *mut jprom_fe_model) -> jprom_status {
    ffi_guard!({ handle::free(fe, "fe") })
}

/// Number of DoFs (rows of `K`).
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_n_dof(fe: *const jprom_fe_model, out: *mut usize) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = handle::get(fe, "fe")?.fe.n_dof();
        Ok(())
    })
}

/// The node ids of the node set `name` (case-insensitive; CalculiX `*NSET`s) into `ids` of
/// capacity `len`; `*count` (may be NULL) receives the set's size. `ids` may be NULL with
/// `len = 0` to ask the size. `JPROM_BAD_SIZE` (nothing written) if `len` is nonzero but below
/// the size; `JPROM_INVALID_VALUE` naming the sets there are if there is no such set.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_node_set(fe: *const jprom_fe_model, name: *const c_char, ids: *mut i64, len: usize, count: *mut usize) -> jprom_status {
    ffi_guard!({
        let f = handle::get(fe, "fe")?;
        if name.is_null() {
            return Err(FfiError::null("name"));
        }
        let name = std::ffi::CStr::from_ptr(name).to_str().map_err(|_| FfiError::new(JPROM_INVALID_VALUE, "name is not UTF-8"))?;
        let set = f.fe.node_set(name)?;
        if let Some(c) = count.as_mut() {
            *c = set.len();
        }
        if len > 0 {
            super::guard::check_capacity("ids", set.len(), len)?;
            slice_out(ids, set.len(), "ids")?.copy_from_slice(set);
        }
        Ok(())
    })
}

/// Places a node-to-ground 3D friction contact on node `node` (its x, y, z DoFs) with
/// `frame[9]` (row-major rows `t1`, `t2`, `n`, as in `jprom_model_add_contact_3d`) and the law
/// `kt1, kt2, kn, mu >= 0`, preload `n0`. Contacts keep the order they are added in.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_add_contact(fe: *mut jprom_fe_model, node: i64, frame: *const f64, kt1: f64, kt2: f64, kn: f64, mu: f64, n0: f64) -> jprom_status {
    ffi_guard!({
        let f = handle::get_mut(fe, "fe")?;
        let r = slice_arg(frame, 9, "frame")?;
        let frame = [[r[0], r[1], r[2]], [r[3], r[4], r[5]], [r[6], r[7], r[8]]];
        let law = ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 };
        law.validate("contact")?;
        f.fe.node(node)?.translations()?;
        if f.spec.contacts.iter().any(|c| c.node == node) {
            return Err(FfiError::new(JPROM_INVALID_VALUE, format!("node {node} already has a contact")));
        }
        f.spec.contacts.push(NodalContact { node, frame, law });
        Ok(())
    })
}

/// Adds the force `force[3]` (x, y, z) on node `node` to harmonic `harmonic`: 0 the static load
/// `f_E^0`, 1 the first harmonic (cos part).
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_add_force(fe: *mut jprom_fe_model, node: i64, harmonic: usize, force: *const f64) -> jprom_status {
    ffi_guard!({
        let f = handle::get_mut(fe, "fe")?;
        let v = slice_arg(force, 3, "force")?;
        let force = [finite_arg("force[0]", v[0])?, finite_arg("force[1]", v[1])?, finite_arg("force[2]", v[2])?];
        f.fe.node(node)?.translations()?;
        let load = NodalForce { node, force };
        match harmonic {
            0 => f.spec.static_forces.push(load),
            1 => f.spec.harmonic_forces.push(load),
            h => return Err(FfiError::new(JPROM_INVALID_VALUE, format!("harmonic {h}: 0 (static) or 1 (first harmonic)"))),
        }
        Ok(())
    })
}

/// Adds an output: direction `direction` (0, 1, 2: x, y, z) of node `node`. Outputs keep the
/// order they are added in (output `j` of the reduced model is the `j`-th added).
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_add_output(fe: *mut jprom_fe_model, node: i64, direction: usize) -> jprom_status {
    ffi_guard!({
        let f = handle::get_mut(fe, "fe")?;
        if direction > 2 {
            return Err(FfiError::new(JPROM_INVALID_VALUE, format!("direction {direction}: 0, 1 or 2 (x, y, z)")));
        }
        f.fe.node(node)?.translations()?;
        f.spec.outputs.push((node, direction));
        Ok(())
    })
}

/// Keeps node `node` (its x, y, z) in the reduced model although nothing is placed on it.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_keep_node(fe: *mut jprom_fe_model, node: i64) -> jprom_status {
    ffi_guard!({
        let f = handle::get_mut(fe, "fe")?;
        f.fe.node(node)?.translations()?;
        f.spec.extra_nodes.push(node);
        Ok(())
    })
}

/// Sets the FE model's viscous damping matrix `C` (compressed sparse column form like `K` and
/// `M` in `jprom_fe_model_new_csc`; symmetric, `n` = the model's DoF count). `jprom_fe_model_reduce`
/// reduces it with the model (`T^T C T`) into the reduced model's added damping matrix.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_set_damping_csc(
    fe: *mut jprom_fe_model,
    n: usize,
    damping_colptr: *const usize,
    damping_rowind: *const usize,
    damping_values: *const f64,
) -> jprom_status {
    ffi_guard!({
        let f = handle::get_mut(fe, "fe")?;
        let nd = f.fe.n_dof();
        if n != nd {
            return Err(FfiError::new(JPROM_BAD_SIZE, format!("damping matrix: n = {n}, the FE model has {nd} DoFs")));
        }
        let c = csc_arg("damping", n, damping_colptr, damping_rowind, damping_values)?;
        f.fe.set_damping(c)?;
        Ok(())
    })
}

/// The `n_modes` lowest natural frequencies (Hz) of the FE model on its own supports (no
/// contact), by sparse shift-invert Lanczos (a free structure's rigid-body modes come out as
/// 0), into `frequency_hz[n_modes]`. `n_modes` must not exceed the DoF count.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_modes(fe: *const jprom_fe_model, n_modes: usize, frequency_hz: *mut f64) -> jprom_status {
    ffi_guard!({
        let f = handle::get(fe, "fe")?;
        if n_modes > f.fe.n_dof() {
            return Err(FfiError::new(JPROM_BAD_SIZE, format!("n_modes = {n_modes} exceeds the FE model's {} DoFs", f.fe.n_dof())));
        }
        let out = slice_out(frequency_hz, n_modes, "frequency_hz")?;
        let hz = f.fe.natural_frequencies_hz(n_modes)?;
        out.copy_from_slice(&hz[..n_modes]);
        Ok(())
    })
}

/// Fixes (clamps) direction `direction` (0..5: x, y, z, rx, ry, rz) of node `node`: its row and
/// column leave `K`, `M` and `C`, for FE exports without supports. Call before placing
/// contacts, forces, outputs or kept nodes (those are checked against the current DoFs; a
/// contact on a node that loses a translation is refused).
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_fix_dof(fe: *mut jprom_fe_model, node: i64, direction: usize) -> jprom_status {
    ffi_guard!({
        let f = handle::get_mut(fe, "fe")?;
        let placed = f.spec.contacts.iter().map(|c| c.node).chain(f.spec.static_forces.iter().chain(&f.spec.harmonic_forces).map(|l| l.node));
        let placed: Vec<i64> = placed.chain(f.spec.outputs.iter().map(|o| o.0)).chain(f.spec.extra_nodes.iter().copied()).collect();
        if direction < 3 && placed.contains(&node) {
            return Err(FfiError::new(JPROM_INVALID_VALUE, format!("node {node} carries a contact, force, output or is kept: its translations cannot be fixed")));
        }
        f.fe = f.fe.with_fixed(&[(node, direction)])?;
        Ok(())
    })
}

/// As `jprom_fe_model_reduce`, keeping the fixed-interface modes up to `cutoff_hz` (finite, > 0), at
/// most `max_modes` of them. `*out` is written only on success.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_reduce_cutoff(fe: *const jprom_fe_model, cutoff_hz: f64, max_modes: usize, out: *mut *mut jprom_model) -> jprom_status {
    ffi_guard!({
        let f = handle::get(fe, "fe")?;
        let out = out_arg(out, "out")?;
        finite_arg("cutoff_hz", cutoff_hz)?;
        let spec = Reduction { cb_modes: max_modes, cb_cutoff_hz: Some(cutoff_hz), ..f.spec.clone() };
        *out = jprom_model::wrap(f.fe.reduce(&spec, Damping::default())?);
        Ok(())
    })
}

/// Reduces the FE model by Craig-Bampton: the contact nodes (in the order added), then the
/// loaded, output and kept nodes are the boundary, plus `cb_modes` fixed-interface modes. The
/// new model's damping is the reduced FE `C` if one was set (`jprom_fe_model_set_damping_csc`),
/// else none; add Rayleigh, modal or structural damping with the `jprom_model_set_*` damping
/// functions. Its contact `i` is the `i`-th added, its output `j` the `j`-th. `*out` is written only on success; free it with `jprom_model_free`.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_reduce(fe: *const jprom_fe_model, cb_modes: usize, out: *mut *mut jprom_model) -> jprom_status {
    ffi_guard!({
        let f = handle::get(fe, "fe")?;
        let out = out_arg(out, "out")?;
        let spec = Reduction { cb_modes, ..f.spec.clone() };
        *out = jprom_model::wrap(f.fe.reduce(&spec, Damping::default())?);
        Ok(())
    })
}

/// The FE model without reduction (JP on the FE model itself, docs/formulation.md §12): every
/// FE DoF kept, with dense `M`, `K` (and the FE `C` if one was set), the contacts, forces and
/// outputs added so far on the nodes' own DoFs (kept nodes change nothing). Its contact `i` is
/// the `i`-th added, its output `j` the `j`-th, as in `jprom_fe_model_reduce`, so the two
/// models can be compared point by point. Dense: for FE models up to a few thousand DoFs;
/// `2 n^2` doubles (`3 n^2` with `C`) beyond the memory budget is `JPROM_BAD_SIZE` with the
/// size it needs, before anything is allocated. `*out` is written only on success; free it
/// with `jprom_model_free`.
#[no_mangle]
pub unsafe extern "C" fn jprom_fe_model_unreduced(fe: *const jprom_fe_model, out: *mut *mut jprom_model) -> jprom_status {
    ffi_guard!({
        let f = handle::get(fe, "fe")?;
        let out = out_arg(out, "out")?;
        *out = jprom_model::wrap(f.fe.unreduced(&f.spec, Damping::default())?);
        Ok(())
    })
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_fe_model_add_contact`, named like every other
/// function on a `jprom_fe_model`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_fe_model_add_contact")]
pub unsafe extern "C" fn jprom_fe_add_contact(fe: *mut jprom_fe_model, node: i64, frame: *const f64, kt1: f64, kt2: f64, kn: f64, mu: f64, n0: f64) -> jprom_status {
    jprom_fe_model_add_contact(fe, node, frame, kt1, kt2, kn, mu, n0)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_fe_model_add_force`, named like every other
/// function on a `jprom_fe_model`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_fe_model_add_force")]
pub unsafe extern "C" fn jprom_fe_add_force(fe: *mut jprom_fe_model, node: i64, harmonic: usize, force: *const f64) -> jprom_status {
    jprom_fe_model_add_force(fe, node, harmonic, force)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_fe_model_add_output`, named like every other
/// function on a `jprom_fe_model`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_fe_model_add_output")]
pub unsafe extern "C" fn jprom_fe_add_output(fe: *mut jprom_fe_model, node: i64, direction: usize) -> jprom_status {
    jprom_fe_model_add_output(fe, node, direction)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_fe_model_keep_node`, named like every other
/// function on a `jprom_fe_model`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_fe_model_keep_node")]
pub unsafe extern "C" fn jprom_fe_keep_node(fe: *mut jprom_fe_model, node: i64) -> jprom_status {
    jprom_fe_model_keep_node(fe, node)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_fe_model_fix_dof`, named like every other
/// function on a `jprom_fe_model`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_fe_model_fix_dof")]
pub unsafe extern "C" fn jprom_fe_fix_dof(fe: *mut jprom_fe_model, node: i64, direction: usize) -> jprom_status {
    jprom_fe_model_fix_dof(fe, node, direction)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_fe_model_reduce_cutoff`, named like every other
/// function on a `jprom_fe_model`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_fe_model_reduce_cutoff")]
pub unsafe extern "C" fn jprom_fe_reduce_cutoff(fe: *const jprom_fe_model, cutoff_hz: f64, max_modes: usize, out: *mut *mut jprom_model) -> jprom_status {
    jprom_fe_model_reduce_cutoff(fe, cutoff_hz, max_modes, out)
}

/// Deprecated since 0.3 (kept, as every released function): `jprom_fe_model_reduce`, named like every other
/// function on a `jprom_fe_model`.
#[no_mangle]
#[deprecated(since = "0.3.0", note = "use jprom_fe_model_reduce")]
pub unsafe extern "C" fn jprom_fe_reduce(fe: *const jprom_fe_model, cb_modes: usize, out: *mut *mut jprom_model) -> jprom_status {
    jprom_fe_model_reduce(fe, cb_modes, out)
}
