//! Small test models for the JP and ROM tests: a random 3D spring-mass chain clamped at one
//! end, with 3D friction contacts at the free end (node-to-ground, and optionally a node pair).
#![allow(dead_code)]

use faer::Mat;
use jprom::contact::{Contact, ContactLaw, IDENTITY_FRAME};
use jprom::model::{Damping, Excitation, HarmonicForce, Model};
use jprom::aft::{evaluate_contacts, AftPlan, ContactForces};
use jprom::contact::ContactState;
use jprom::hbm::default_nt;
use jprom::jp::prediction::static_solution;
use jprom::jp::{stuck_mode, ContactJacobian};
use jprom::model::ContactCoordinates;
use rand::{rngs::StdRng, Rng, SeedableRng};

/// Below this actual error `e_1` the reference full-order solution (Newton to a residual of
/// 1e-10 of the largest force, the static preload included) is no more accurate than the
/// reduced one, so `e*_1 >= e_1` is not checked there: a complete band-condensed FR basis has
/// `e*_1` 2e-9 and `e_1` 4e-8 on the chain, the latter being the full-order error.
pub const FO_ACCURACY: f64 = 1e-6;

/// Options of [`chain_model`].
pub struct ChainOptions {
    pub n_nodes: usize,
    pub seed: u64,
    /// Node-to-ground contacts on the last `n_ground` nodes.
    pub n_ground: usize,
    /// Add a node pair contact between the two nodes before them.
    pub pair: bool,
    pub mu: f64,
    pub kt: f64,
    pub kn: f64,
}

impl Default for ChainOptions {
    fn default() -> Self {
        ChainOptions { n_nodes: 8, seed: 7, n_ground: 3, pair: true, mu: 0.3, kt: 2.0, kn: 3.0 }
    }
}

fn add_spring(k: &mut Mat<f64>, a: usize, b: Option<usize>, dir: [f64; 3], stiff: f64) {
    for i in 0..3 {
        for j in 0..3 {
            let v = stiff * dir[i] * dir[j];
            k[(3 * a + i, 3 * a + j)] += v;
            if let Some(b) = b {
                k[(3 * b + i, 3 * b + j)] += v;
                k[(3 * a + i, 3 * b + j)] -= v;
                k[(3 * b + i, 3 * a + j)] -= v;
            }
        }
    }
}

fn unit(rng: &mut StdRng) -> [f64; 3] {
    loop {
        let v: [f64; 3] = [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0)];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if n > 0.2 && n <= 1.0 {
            return [v[0] / n, v[1] / n, v[2] / n];
        }
    }
}

/// Chain of `n_nodes` nodes (3 DoFs each): node 0 clamped by stiff springs, random directional
/// springs between neighbours and second neighbours. Static force presses every contact node
/// along its normal (+z); first-harmonic force along y at node 1 and x at node 2.
pub fn chain_model(o: &ChainOptions) -> Model {
    let n = 3 * o.n_nodes;
    let mut rng = StdRng::seed_from_u64(o.seed);
    let mut k = Mat::<f64>::zeros(n, n);
    for d in 0..3 {
        let mut dir = [0.0; 3];
        dir[d] = 1.0;
        add_spring(&mut k, 0, None, dir, 50.0);
    }
    for i in 0..o.n_nodes - 1 {
        for _ in 0..3 {
            let dir = unit(&mut rng);
            add_spring(&mut k, i, Some(i + 1), dir, rng.gen_range(5.0..15.0));
        }
        if i + 2 < o.n_nodes {
            let dir = unit(&mut rng);
            add_spring(&mut k, i, Some(i + 2), dir, rng.gen_range(1.0..3.0));
        }
    }
    let mut m = Mat::<f64>::zeros(n, n);
    for i in 0..o.n_nodes {
        let mi = rng.gen_range(0.5..1.5);
        for d in 0..3 {
            m[(3 * i + d, 3 * i + d)] = mi;
        }
    }
    let law = ContactLaw::Friction3D { kt1: o.kt, kt2: o.kt * 1.1, kn: o.kn, mu: o.mu, n0: 0.0 };
    let mut contacts = Vec::new();
    let mut contact_nodes = Vec::new();
    for c in 0..o.n_ground {
        let node = o.n_nodes - 1 - c;
        contacts.push(Contact::ground_3d([3 * node, 3 * node + 1, 3 * node + 2], IDENTITY_FRAME, law.clone()));
        contact_nodes.push(node);
    }
    if o.pair {
        let a = o.n_nodes - 1 - o.n_ground;
        let b = a - 1;
        // A tilted frame (rotation about x by 30 degrees).
        let (s, c) = (0.5f64, 0.75f64.sqrt());
        let frame = [[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]];
        contacts.push(Contact::pair_3d([3 * a, 3 * a + 1, 3 * a + 2], [3 * b, 3 * b + 1, 3 * b + 2], frame, law.clone()));
        contact_nodes.push(a);
    }
    let mut f0 = vec![0.0; n];
    for (ci, c) in contacts.iter().enumerate() {
        // Press along the normal: +n on node a (w = R (x_a - x_b), v positive into contact).
        let nrm = c.frame[2];
        for d in 0..3 {
            f0[c.dofs_a[d]] += 1.0 * nrm[d] * (1.0 + 0.2 * ci as f64);
        }
    }
    let mut f1c = vec![0.0; n];
    f1c[3 + 1] = 1.0;
    f1c[6] = 0.5;
    let excitation = Excitation {
        static_force: f0,
        harmonics: vec![HarmonicForce { cos: f1c, sin: vec![0.0; n] }],
        dynamic_scale: 1.0,
    };
    let _ = contact_nodes;
    let outputs = vec![3 * (o.n_nodes / 2), 3 * (o.n_nodes / 2) + 1, 3 * (o.n_nodes - 1) + 1];
    Model::new(m, k, Damping { mass_coeff: 0.0, stiffness_coeff: 0.002 }, excitation, contacts, outputs).unwrap()
}

/// Physical stiffness with the stuck contact springs `R^T diag(kt1, kt2, kn) R` added
/// (between a and b for pairs).
pub fn stuck_stiffness_physical(model: &Model) -> Mat<f64> {
    let mut k = model.stiffness.clone();
    for c in &model.contacts {
        let ks = c.law.stuck_stiffness();
        let r = c.frame;
        let mut blk = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                blk[i][j] = (0..3).map(|l| r[l][i] * ks[l] * r[l][j]).sum();
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                k[(c.dofs_a[i], c.dofs_a[j])] += blk[i][j];
                if let Some(b) = &c.dofs_b {
                    k[(b[i], b[j])] += blk[i][j];
                    k[(c.dofs_a[i], b[j])] -= blk[i][j];
                    k[(b[i], c.dofs_a[j])] -= blk[i][j];
                }
            }
        }
    }
    k
}

/// Undamped natural angular frequencies and mass-normalised modes of `(k, m)` (dense, via the
/// Cholesky factor of `m`), ascending.
pub fn linear_modes(k: &Mat<f64>, m: &Mat<f64>) -> (Vec<f64>, Mat<f64>) {
    use faer::Side;
    let l = m.llt(Side::Lower).unwrap().L().to_owned();
    let mut a = k.clone();
    l.as_ref().solve_lower_triangular_in_place(a.as_mut());
    let mut at = a.transpose().to_owned();
    l.as_ref().solve_lower_triangular_in_place(at.as_mut());
    let sym = Mat::from_fn(k.nrows(), k.nrows(), |i, j| 0.5 * (at[(i, j)] + at[(j, i)]));
    let evd = sym.self_adjoint_eigen(Side::Lower).unwrap();
    let s = evd.S().column_vector();
    let freqs = (0..s.nrows()).map(|i| s[i].max(0.0).sqrt()).collect();
    let mut v = evd.U().to_owned();
    l.transpose().solve_upper_triangular_in_place(v.as_mut());
    (freqs, v)
}

/// Largest principal-angle sine between span(a) and span(b) columns, measured as the largest
/// residual of projecting each unit column of `b` onto the orthonormal `a`.
pub fn span_residual(a_orth: &Mat<f64>, b: &Mat<f64>) -> f64 {
    let mut worst = 0.0f64;
    for j in 0..b.ncols() {
        let col = b.as_ref().subcols(j, 1).to_owned();
        let nrm = col.norm_l2();
        let proj = a_orth * (a_orth.transpose() * &col);
        worst = worst.max((&col - &proj).norm_l2() / nrm);
    }
    worst
}

/// Contact stiffness at the static solution plus `p` times the stuck mode (cos part), with
/// `p` a multiple `factor` of the largest all-stuck amplitude (factor 0: fully stuck `K̂`).
pub fn slipping_jacobian(coords: &ContactCoordinates, harmonics: usize, band: (f64, f64), factor: f64) -> ContactJacobian {
    let nw = coords.n_w;
    if factor == 0.0 {
        return ContactJacobian::stuck(&coords.laws, &coords.offsets, nw, harmonics).unwrap();
    }
    let plan = AftPlan::new(harmonics, default_nt(harmonics)).unwrap();
    let q0 = static_solution(coords).unwrap();
    let (_, phi) = stuck_mode(coords, band).unwrap();
    let w_at = |p: f64| {
        let mut w = vec![0.0; nw * (2 * harmonics + 1)];
        w[..nw].copy_from_slice(&q0[..nw]);
        for i in 0..nw {
            w[nw + i] = p * phi[i];
        }
        w
    };
    let eval = |p: f64| {
        let mut f = ContactForces::default();
        evaluate_contacts(&plan, &coords.laws, &coords.offsets, nw, &w_at(p), true, true, &mut f);
        f
    };
    let stuck = |f: &ContactForces| f.cycles.iter().all(|c| c.states.iter().all(|&s| s == ContactState::Stick));
    let mut hi = q0[..nw].iter().map(|x| x.abs()).fold(0.0, f64::max).max(1e-12);
    while stuck(&eval(hi)) {
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if stuck(&eval(mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // Above the first slip the steady state can still shake down to full stick (a slip in the
    // first AFT pass moves the stick point), so step up until some contact slips.
    let n_slip = |f: &ContactForces| f.cycles.iter().filter(|c| c.states.iter().any(|&s| s != ContactState::Stick)).count();
    let mut p = factor * hi;
    let mut forces = eval(p);
    while n_slip(&forces) == 0 && p < 1e3 * hi {
        p *= 1.25;
        forces = eval(p);
    }
    assert!(n_slip(&forces) > 0, "no contact slips up to {p:e} (factor {factor})");
    ContactJacobian::from_forces(&coords.laws, &coords.offsets, nw, harmonics, &forces, &w_at(p)).unwrap()
}

/// The model of the C, C++ and Fortran examples (examples-c/sweep_example.c): two nodes on
/// springs, the second pressed on ground by a contact preload, no static force, a
/// first-harmonic force on the first node.
pub fn examples_model() -> Model {
    let n = 6;
    let mut k = Mat::<f64>::zeros(n, n);
    let mut m = Mat::<f64>::zeros(n, n);
    for d in 0..3 {
        m[(d, d)] = 1.0;
        m[(3 + d, 3 + d)] = 1.0;
        k[(d, d)] = 2.0e4;
        k[(3 + d, 3 + d)] = 1.0e4;
        k[(d, 3 + d)] = -1.0e4;
        k[(3 + d, d)] = -1.0e4;
    }
    let mut fc = vec![0.0; n];
    fc[0] = 5.0;
    let exc = Excitation { static_force: vec![0.0; n], harmonics: vec![HarmonicForce { cos: fc, sin: vec![0.0; n] }], dynamic_scale: 1.0 };
    let law = ContactLaw::Friction3D { kt1: 3.0e4, kt2: 3.0e4, kn: 5.0e4, mu: 0.5, n0: 20.0 };
    Model::new(m, k, Damping { mass_coeff: 0.0, stiffness_coeff: 1e-4 }, exc, vec![Contact::ground_3d([3, 4, 5], IDENTITY_FRAME, law)], vec![0, 3]).unwrap()
}

/// `n` unit masses in a chain of unit springs, the first tied to ground, each with a Jenkins
/// element (kt = 0.5, slip force `slip`) to ground, or to the previous mass when `relative`
/// (NLvib's chain: q1 to ground, q2 - q1, ...); the last mass driven at `force`, stiffness-
/// proportional damping 0.01. `K` is tridiagonal: at H >= 3 and n >= 150 the full-order system
/// is stored sparse.
pub fn jenkins_chain(n: usize, slip: f64, force: f64, relative: bool) -> Model {
    let mut k = Mat::<f64>::zeros(n, n);
    k[(0, 0)] += 1.0;
    for i in 0..n - 1 {
        k[(i, i)] += 1.0;
        k[(i + 1, i + 1)] += 1.0;
        k[(i, i + 1)] -= 1.0;
        k[(i + 1, i)] -= 1.0;
    }
    let mut f1 = vec![0.0; n];
    f1[n - 1] = force;
    let exc = Excitation { static_force: vec![0.0; n], harmonics: vec![HarmonicForce { cos: f1, sin: vec![0.0; n] }], dynamic_scale: 1.0 };
    let mut model = Model::new(Mat::identity(n, n), k, Damping { mass_coeff: 0.0, stiffness_coeff: 0.01 }, exc, Vec::new(), vec![n - 1]).unwrap();
    for i in 0..n {
        let b = (relative && i > 0).then(|| i - 1);
        model.contacts.push(Contact::jenkins(i, b, 0.5, slip, 1.0));
    }
    model.validate().unwrap();
    model
}
