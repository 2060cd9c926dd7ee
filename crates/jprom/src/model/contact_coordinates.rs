//! Relative contact coordinates: the change of variables `x = T z` with
//! `z = [w; y]`, where `w` stacks every contact's local relative displacement
//! (`w_c = R_c (x_a - x_b)` or `R_c x_a`) and `y` holds the physical DoFs that are not the `a`
//! node of a contact, in their original order.
//!
//! In these coordinates the contact forces act on `w` only, as `-F(w)`, so the HBM residual
//! is `D z - f_E + [F(w); 0]` and its Jacobian `D + K̂` with `K̂ = dF/dw` on the leading block.
//! Node pairs become a contact coordinate plus ordinary linear DoFs, which is what makes the
//! condensation of §5 and the contact rows of the JP bases (§9) simple.

use crate::aft::Discretisation;
use crate::contact::{Contact, ContactLaw};
use std::collections::HashMap;
use crate::error::{JpError, Result};
use crate::model::Model;
use faer::{c64, Mat};

/// The transformation `x = T z` and the model's matrices and forces in `z` coordinates.
#[derive(Clone, Debug)]
pub struct ContactCoordinates {
    /// Number of physical DoFs.
    pub n_dof: usize,
    /// Number of contact coordinates `n_w` (the leading entries of `z`).
    pub n_w: usize,
    /// Offset of each contact coordinate block in `w` (one block per group of contacts with
    /// the same kinematics, see [`ContactGroups`]; one per contact when no two share one).
    pub offsets: Vec<usize>,
    /// The law of each block: the contact's own law, or a [`ContactLaw::Parallel`] of the
    /// laws of the group's contacts in model order.
    pub laws: Vec<ContactLaw>,
    /// For each block, the model contacts acting on it (indices into `Model::contacts`).
    pub groups: Vec<Vec<usize>>,
    /// For each physical DoF `i`, the entries `(j, T_ij)` of row `i` of `T`.
    pub rows: Vec<Vec<(usize, f64)>>,
    /// For each `z` coordinate `j >= n_w`, the physical DoF it is.
    pub linear_dofs: Vec<usize>,
    /// `T^T M T`, `T^T K T`, `T^T C T`.
    pub mass: Mat<f64>,
    pub stiffness: Mat<f64>,
    pub damping: Mat<f64>,
    /// Structural loss factor `eta` (the harmonics see `(1 + i eta) K`; `T^T (eta K) T = eta`
    /// times [`Self::stiffness`]).
    pub loss_factor: f64,
    /// `T^T f_E^0`, and `T^T` of the cos and sin parts of `f_E^h`, `h = 1..=H` (scaled).
    pub static_force: Vec<f64>,
    pub harmonic_force: Vec<(Vec<f64>, Vec<f64>)>,
    /// Output DoFs of the model (physical indices).
    pub output_dofs: Vec<usize>,
    /// Harmonics `0..=H` (the forces above are for `1..=H`) and AFT samples: the
    /// discretisation of every system built on these coordinates.
    pub discretisation: Discretisation,
}

/// Imaginary part of the dynamic stiffness `D_h = K - (h w)^2 M + i (h w C + eta K)` at
/// harmonic angular frequency `hw = h w`, from entries `c` of `C` and `k` of `K` (in any basis
/// both are projected on): `hw c + eta k` for a harmonic, 0 for the static term (`hw = 0`),
/// which neither viscous nor structural damping acts on (docs/formulation.md §1).
#[inline]
pub fn dissipation(hw: f64, c: f64, k: f64, loss_factor: f64) -> f64 {
    if hw == 0.0 {
        0.0
    } else {
        hw * c + loss_factor * k
    }
}

impl ContactCoordinates {
    /// `K` with every contact's stuck springs (`kt1, kt2, kn` in its frame) added on its
    /// contact coordinates: the stiffness of the stuck linear limit (docs/formulation.md §8).
    pub fn stuck_stiffness(&self) -> Mat<f64> {
        // the full block: an external law's Jacobian at w = 0 may couple its coordinates
        self.with_contact_blocks(|law| Some(law.stuck_stiffness_block())).expect("every law has a stuck block")
    }

    /// `K` with every contact's gross-slip springs ([`crate::contact::ContactLaw::slipping_stiffness_block`]:
    /// the normal springs, no tangential ones) added on its contact coordinates: the stiffness
    /// of the slipping linear limit of a large excitation (docs/formulation.md §8.8). `None` when
    /// a law's slipping limit is not known (an external law).
    pub fn slipping_stiffness(&self) -> Option<Mat<f64>> {
        self.with_contact_blocks(ContactLaw::slipping_stiffness_block)
    }

    /// Whether some contact's slipping limit differs from its stuck one (a friction law with
    /// tangential stiffness): without, the slipping and stuck linear limits are the same.
    /// `false` when a law's slipping limit is not known (an external law).
    pub fn has_friction(&self) -> bool {
        let slipping: Option<Vec<_>> = self.laws.iter().map(ContactLaw::slipping_stiffness_block).collect();
        slipping.is_some_and(|sl| sl.iter().zip(&self.laws).any(|(b, law)| *b != law.stuck_stiffness_block()))
    }

    /// `K` plus each law's `dim x dim` column-major block (`block(law)`) on its coordinates;
    /// `None` if a block is.
    fn with_contact_blocks(&self, block: impl Fn(&ContactLaw) -> Option<Vec<f64>>) -> Option<Mat<f64>> {
        let mut k = self.stiffness.clone();
        for (law, &off) in self.laws.iter().zip(&self.offsets) {
            let d = law.dim();
            for (idx, ks) in block(law)?.into_iter().enumerate() {
                k[(off + idx % d, off + idx / d)] += ks;
            }
        }
        Some(k)
    }

    /// The first harmonic's linear response in complex form at `omega`, with `k` the stiffness
    /// of a linear limit (`K` plus its contact springs): `D = k - omega^2 M + i (omega C + eta K)`
    /// and `f = f_c - i f_s`, so that `D z = f` gives `z = x_c - i x_s` of the real cos/sin form
    /// (docs/formulation.md §8.8 step 4).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] if the model has no first-harmonic force.
    pub fn first_harmonic_complex(&self, k: &Mat<f64>, omega: f64) -> Result<(Mat<c64>, Mat<c64>)> {
        let n = self.n_dof;
        let (fc, fs) = self.harmonic_force.first().ok_or_else(|| JpError::invalid("excitation", "no first-harmonic force"))?;
        let w2 = omega * omega;
        let d = Mat::from_fn(n, n, |i, j| c64::new(k[(i, j)] - w2 * self.mass[(i, j)], self.dissipation(omega, i, j)));
        let f = Mat::from_fn(n, 1, |i, _| c64::new(fc[i], -fs[i]));
        Ok((d, f))
    }

    /// [`dissipation`] of entry `(i, j)` of the `z`-coordinate matrices.
    #[inline]
    pub fn dissipation(&self, hw: f64, i: usize, j: usize) -> f64 {
        dissipation(hw, self.damping[(i, j)], self.stiffness[(i, j)], self.loss_factor)
    }

    /// Builds the transformation for `model` and transforms its matrices, with forces for
    /// harmonics `1..=H` of `discretisation` (`H` alone takes the default `Nt`:
    /// `ContactCoordinates::new(&model, 3)`). Cost `O(n^2)` per matrix.
    ///
    /// # Errors
    /// The discretisation's ([`Discretisation::validate`]) and the model's validation errors;
    /// bad contact groups.
    pub fn new(model: &Model, discretisation: impl Into<Discretisation>) -> Result<Self> {
        let discretisation = discretisation.into();
        discretisation.validate()?;
        let harmonics = discretisation.harmonics;
        let n = model.n_dof();
        crate::memory::check(&format!("the contact coordinates of a model of {n} DoFs (dense M, K, C and the transformation, {n} x {n} each)"), working_set_bytes(n))?;
        model.validate()?;
        let groups = ContactGroups::new(&model.contacts, n)?;
        let mut offsets = Vec::with_capacity(groups.groups.len());
        let mut n_w = 0;
        for g in &groups.groups {
            offsets.push(n_w);
            n_w += model.contacts[g[0]].dim();
        }
        let mut is_a = vec![false; n];
        for c in &model.contacts {
            for &d in &c.dofs_a {
                is_a[d] = true;
            }
        }
        let linear_dofs: Vec<usize> = (0..n).filter(|&i| !is_a[i]).collect();
        let mut z_of_dof = vec![usize::MAX; n];
        for (k, &d) in linear_dofs.iter().enumerate() {
            z_of_dof[d] = n_w + k;
        }
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for &d in &linear_dofs {
            rows[d].push((z_of_dof[d], 1.0));
        }
        // x_a = R^T w + x_b  (R orthonormal, w = R (x_a - x_b)), groups in dependency order so
        // that a 'b' DoF which is itself an 'a' DoF (a chain) has its row already.
        for &g in &groups.order {
            let c = &model.contacts[groups.groups[g][0]];
            let off = offsets[g];
            let dim = c.dim();
            let r = c.rotation();
            for (i, &da) in c.dofs_a.iter().enumerate() {
                let mut row = Vec::new();
                for k in 0..dim {
                    let coef = r[k * dim + i];
                    if coef != 0.0 {
                        row.push((off + k, coef));
                    }
                }
                if let Some(b) = &c.dofs_b {
                    row.extend_from_slice(&rows[b[i]]);
                }
                rows[da] = row;
            }
        }
        let laws = groups
            .groups
            .iter()
            .map(|g| match g.as_slice() {
                [one] => model.contacts[*one].law.clone().labelled(*one),
                many => ContactLaw::Parallel(
                    many.iter().flat_map(|&c| model.contacts[c].law.members().iter().map(move |l| l.clone().labelled(c))).collect(),
                ),
            })
            .collect();
        let nz = n; // T is square and invertible
        let transform = |a: &Mat<f64>| -> Mat<f64> {
            // B = A T  (n x nz)
            let mut b = Mat::<f64>::zeros(n, nz);
            for (l, row) in rows.iter().enumerate() {
                for &(k, t) in row {
                    for i in 0..n {
                        b[(i, k)] += a[(i, l)] * t;
                    }
                }
            }
            // T^T B
            let mut out = Mat::<f64>::zeros(nz, nz);
            for (i, row) in rows.iter().enumerate() {
                for &(j, t) in row {
                    for k in 0..nz {
                        out[(j, k)] += t * b[(i, k)];
                    }
                }
            }
            out
        };
        let apply_t_transpose = |f: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; nz];
            for (i, row) in rows.iter().enumerate() {
                for &(j, t) in row {
                    out[j] += t * f[i];
                }
            }
            out
        };
        let mass = transform(&model.mass);
        let stiffness = transform(&model.stiffness);
        let damping = transform(&model.damping_matrix());
        let static_force = apply_t_transpose(&model.excitation.static_force);
        let harmonic_force = (1..=harmonics)
            .map(|h| {
                let (c, s) = model.excitation.harmonic(h, n);
                (apply_t_transpose(&c), apply_t_transpose(&s))
            })
            .collect();
        Ok(ContactCoordinates {
            n_dof: n,
            n_w,
            offsets,
            laws,
            groups: groups.groups,
            rows,
            linear_dofs,
            mass,
            stiffness,
            damping,
            loss_factor: model.loss_factor,
            static_force,
            harmonic_force,
            output_dofs: model.output_dofs.clone(),
            discretisation,
        })
    }

    /// The contacts as the AFT sees them.
    pub fn contacts(&self) -> crate::contact::Contacts<'_> {
        crate::contact::Contacts { laws: &self.laws, offsets: &self.offsets, n_w: self.n_w, nt: self.discretisation.nt() }
    }

    /// Physical displacement `x = T z` of one harmonic component.
    pub fn to_physical(&self, z: &[f64]) -> Vec<f64> {
        self.rows.iter().map(|row| row.iter().map(|&(j, t)| t * z[j]).sum()).collect()
    }

    /// Physical displacement at the output DoFs, `(T z)[output_dofs]`.
    pub fn at_outputs(&self, z: &[f64]) -> Vec<f64> {
        self.output_dofs.iter().map(|&i| self.rows[i].iter().map(|&(j, t)| t * z[j]).sum()).collect()
    }
}

/// How the contacts of a model map to contact coordinate blocks.
///
/// * Contacts with the same kinematics ([`Contact::same_kinematics`]: same `dofs_a`, `dofs_b`
///   and frame) share one block: their laws act in parallel (forces summed), so a cubic spring
///   and a Jenkins element on the same DoF to ground both act. Any other reuse of an `a` DoF is
///   refused.
/// * A `b` DoF may be the `a` DoF of another block (a chain, "q1 to ground and q2 - q1"): its
///   row of `T` is resolved first ([`ContactGroups::order`]). A cycle is refused.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ContactGroups {
    /// The contacts of each block, in model order; blocks ordered by their first contact.
    pub groups: Vec<Vec<usize>>,
    /// Block indices in an order where every block comes after the blocks owning its `b` DoFs.
    pub order: Vec<usize>,
}

impl ContactGroups {
    /// Groups the contacts of a model with `n_dof` DoFs (indices already checked).
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the contact when an `a` DoF is shared by contacts of
    /// different kinematics, or when `a`/`b` DoFs form a cycle.
    pub fn new(contacts: &[Contact], n_dof: usize) -> Result<Self> {
        let topology = ContactTopology::new(contacts)?;
        let groups = topology.groups;
        let owner: Vec<usize> = {
            let mut o = vec![usize::MAX; n_dof];
            for (&d, &g) in &topology.owner {
                if d < n_dof {
                    o[d] = g;
                }
            }
            o
        };
        // Dependency order (Kahn): block g needs the blocks owning its 'b' DoFs.
        let ng = groups.len();
        let deps: Vec<Vec<usize>> = groups
            .iter()
            .map(|g| {
                let b = contacts[g[0]].dofs_b.as_deref().unwrap_or(&[]);
                let mut d: Vec<usize> = b.iter().filter(|&&x| x < n_dof && owner[x] != usize::MAX).map(|&x| owner[x]).collect();
                d.sort_unstable();
                d.dedup();
                d
            })
            .collect();
        let mut done = vec![false; ng];
        let mut order = Vec::with_capacity(ng);
        loop {
            let before = order.len();
            for g in 0..ng {
                if !done[g] && deps[g].iter().all(|&h| done[h]) {
                    done[g] = true;
                    order.push(g);
                }
            }
            if order.len() == ng {
                break;
            }
            if order.len() == before {
                let g = (0..ng).find(|&g| !done[g]).expect("a block is left");
                let c = groups[g][0];
                let on: Vec<usize> = deps[g].iter().filter(|&&h| !done[h]).map(|&h| groups[h][0]).collect();
                return Err(JpError::invalid(
                    format!("contact[{c}].dofs_b"),
                    format!(
                        "the 'a'/'b' DoFs of the contacts form a cycle (contact[{c}]'s 'b' DoFs are 'a' DoFs of contact(s) {on:?}, \
                         which depend back on it): a chain of elements must end at ground or at a DoF that is no element's 'a' DoF"
                    ),
                ));
            }
        }
        Ok(ContactGroups { groups, order })
    }
}

/// The grouping of [`ContactGroups`] kept up to date one contact at a time, for callers that
/// add contacts one by one (the C API): an addition is checked against the contacts before it
/// in `O(1)` when its 'a' DoFs are no earlier contact's 'b' DoFs (a contact on DoFs of its own,
/// a parallel element, the next link at the end of a chain); otherwise in the size of the
/// chain it closes, to refuse a cycle.
#[derive(Clone, Debug, Default)]
pub struct ContactTopology {
    /// Block whose 'a' DoF each DoF is.
    owner: HashMap<usize, usize>,
    /// The contacts of each block.
    groups: Vec<Vec<usize>>,
    /// For each DoF, the blocks that have it as a 'b' DoF.
    users: HashMap<usize, Vec<usize>>,
}

impl ContactTopology {
    /// The topology of `contacts`, checked contact by contact.
    ///
    /// # Errors
    /// As [`ContactTopology::add`].
    pub fn new(contacts: &[Contact]) -> Result<Self> {
        let mut t = ContactTopology::default();
        for i in 0..contacts.len() {
            t.add(contacts, i)?;
        }
        Ok(t)
    }

    /// Number of contacts recorded.
    pub fn len(&self) -> usize {
        self.groups.iter().map(Vec::len).sum()
    }

    /// Whether no contact is recorded.
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// Checks `contacts[i]` against `contacts[..i]` (recorded before) and records it; on an
    /// error nothing is recorded.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the contact when one of its 'a' DoFs is the 'a' DoF of an
    /// earlier contact with other kinematics, or when it closes a cycle of 'a'/'b' DoFs.
    pub fn add(&mut self, contacts: &[Contact], i: usize) -> Result<()> {
        let c = &contacts[i];
        if let Some(&dof) = c.dofs_a.iter().find(|d| self.owner.contains_key(d)) {
            let g = self.owner[&dof];
            let first = self.groups[g][0];
            if !c.same_kinematics(&contacts[first]) {
                return Err(JpError::invalid(
                    format!("contact[{i}].dofs_a"),
                    format!(
                        "DoF {dof} is already the 'a' DoF of contact[{first}] with other kinematics; several elements may \
                         share an 'a' DoF only with the same dofs_a, dofs_b and frame (they then act in parallel on one \
                         coordinate), and a DoF may be the 'b' DoF of any number of elements and the 'a' DoF of a chain \
                         link (q1 to ground, q2 - q1)"
                    ),
                ));
            }
            // same kinematics: the block's dependencies are unchanged
            self.groups[g].push(i);
            return Ok(());
        }
        let b = c.dofs_b.as_deref().unwrap_or(&[]);
        // blocks that will depend on the new one: those with one of its 'a' DoFs as a 'b' DoF
        let dependants: Vec<usize> = c.dofs_a.iter().filter_map(|d| self.users.get(d)).flatten().copied().collect();
        if !dependants.is_empty() {
            // a cycle closes if the new block depends (through the blocks owning its 'b' DoFs,
            // transitively) on one of them
            let mut seen = std::collections::HashSet::new();
            let mut stack: Vec<usize> = b.iter().filter_map(|d| self.owner.get(d)).copied().collect();
            while let Some(h) = stack.pop() {
                if dependants.contains(&h) {
                    let on: Vec<usize> = b.iter().filter_map(|d| self.owner.get(d)).map(|&h| self.groups[h][0]).collect();
                    return Err(JpError::invalid(
                        format!("contact[{i}].dofs_b"),
                        format!(
                            "the 'a'/'b' DoFs of the contacts form a cycle (contact[{i}]'s 'b' DoFs are 'a' DoFs of contact(s) \
                             {on:?}, which depend back on it): a chain of elements must end at ground or at a DoF that is no \
                             element's 'a' DoF"
                        ),
                    ));
                }
                if !seen.insert(h) {
                    continue;
                }
                let hb = contacts[self.groups[h][0]].dofs_b.as_deref().unwrap_or(&[]);
                stack.extend(hb.iter().filter_map(|d| self.owner.get(d)).copied());
            }
        }
        let g = self.groups.len();
        for &d in &c.dofs_a {
            self.owner.insert(d, g);
        }
        for &d in b {
            self.users.entry(d).or_default().push(g);
        }
        self.groups.push(vec![i]);
        Ok(())
    }
}

/// Estimated bytes of [`ContactCoordinates::new`] for a model of `n` DoFs: four dense
/// `n x n` matrices (`M`, `K`, `C` in z-coordinates and the transformation).
pub fn working_set_bytes(n: usize) -> u128 {
    crate::memory::bytes_of::<f64>(crate::memory::product(&[4, n, n]))
}
