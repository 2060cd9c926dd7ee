//! # jprom
//!
//! Steady-state forced response of structures with friction contacts by harmonic balance
//! (HBM) with alternating frequency-time (AFT) contact forces, and its reduction by
//! Jacobian Projection (JP). The formulation, with the decisions the paper leaves open, is
//! `docs/formulation.md` in the repository; `§n` in doc comments are its sections, equation
//! numbers `(n)` the JP paper's.
//!
//! A sweep of a two-node model whose second node rubs on the ground (3D friction contact
//! closed by a preload), solved on the contact DoFs after condensing the linear ones:
//!
//! ```
//! use faer::Mat;
//! use jprom::condensation::CondensedSystem;
//! use jprom::contact::{Contact, ContactLaw, IDENTITY_FRAME};
//! use jprom::hbm::{sweep, HbmOptions, SweepOptions};
//! use jprom::model::{Damping, Excitation, HarmonicForce, Model};
//! use std::ops::ControlFlow;
//!
//! // node 0 (DoFs 0-2) and node 1 (DoFs 3-5), springs 1e4 to ground and between them
//! let n = 6;
//! let mass = Mat::<f64>::identity(n, n);
//! let stiffness = Mat::from_fn(n, n, |i, j| {
//!     if i == j { if i < 3 { 2e4 } else { 1e4 } } else if i + 3 == j || j + 3 == i { -1e4 } else { 0.0 }
//! });
//! let law = ContactLaw::Friction3D { kt1: 3e4, kt2: 3e4, kn: 5e4, mu: 0.5, n0: 20.0 };
//! let contacts = vec![Contact::ground_3d([3, 4, 5], IDENTITY_FRAME, law)];
//! let mut cos = vec![0.0; n];
//! cos[0] = 5.0; // first-harmonic force on node 0, x
//! let excitation = Excitation { static_force: vec![0.0; n], harmonics: vec![HarmonicForce { cos, sin: vec![0.0; n] }], dynamic_scale: 1.0 };
//! let damping = Damping { mass_coeff: 0.0, stiffness_coeff: 1e-4 };
//! let model = Model::new(mass, stiffness, damping, excitation, contacts, vec![0, 3])?;
//!
//! let opts = HbmOptions::default();
//! let system = CondensedSystem::new(&model, 1)?;
//! let result = sweep(&system, &SweepOptions::band(60.0, 160.0), &opts, &mut |_| ControlFlow::Continue(()))?;
//! assert!(result.reached_end(), "{:?}", result.failure);
//! let peak = result.points.iter().map(|p| p.output_amplitude(1, 0)).fold(0.0, f64::max);
//! assert!(peak > 0.0);
//! println!("{} points, largest |X1| at DoF 0: {peak:.4e}", result.points.len());
//! # Ok::<(), jprom::JpError>(())
//! ```
//!
//! Map of the crate, following the method:
//! - [`linalg`]: checked LU, sparse matrices, dense and sparse eigen solvers.
//! - [`model`]: `M`, `K`, damping, excitation, contact elements, output DoFs (§1).
//! - [`contact`]: the 3D stick/slip/separation law and the 1D Jenkins element, seen sample by
//!   sample through [`contact::SampleLaw`] (§4).
//! - [`aft`]: inverse FFT, contact law, FFT, the analytical Jacobian `K̂` and the dissipated
//!   energy (§3-4).
//! - [`hbm`]: harmonic layout, dynamic stiffness, residual, Newton with a trust region (§2, §5),
//!   continuation and its end reasons (§6).
//! - [`condensation`]: condensation onto the contact DoFs (§7).
//! - [`fe`]: FE models on nodes ([`fe::FeModel`]: a user's `K`, `M` and nodes reduced by
//!   Craig-Bampton), the hexahedral element, the built-in blade, the blade pair, the twisted
//!   plate.
//! - [`io`]: versioned JSON documents, Matrix Market, node/DoF maps, CalculiX output.
//! - [`jp`]: JP modes, boundary-condition prediction, SVD conditioning (§8).
//! - [`rom`]: full-DoF (FR) and nonlinear-DoF (NLR) reduced models (§9), the error measures
//!   `e*`, `e` and `e_lin` (§10), the self-correcting sweep and the sweep record.
//! - [`level`]: excitation levels, `alpha_ST` and the stuck limit (§11).
//! - [`memory`], [`limits`]: the memory budget and the documented caps that sizes from
//!   outside are checked against before anything is allocated.
//! - [`parallelism`]: kernels on one thread, for results that do not depend on the thread
//!   count.
//!
//! Units are the caller's; the built-in blade uses mm, tonne, s (so N and MPa). Frequencies in
//! the library are angular (`omega`, rad/s) unless a name says `_hz`.

pub mod error;
pub mod limits;
pub mod memory;
pub mod time_budget;
pub mod parallelism;
pub mod linalg;
pub mod model;
pub mod contact;
pub mod aft;
pub mod hbm;
pub mod condensation;
pub mod fe;
pub mod io;
pub mod jp;
pub mod rom;
pub mod level;

pub use error::{JpError, Result};

/// Counts the heap allocations each thread makes, in the library's own unit tests (the checks
/// that the Newton and corrector iterations reuse their workspaces).
#[cfg(test)]
pub(crate) mod allocation_count {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    thread_local! {
        static COUNT: Cell<usize> = const { Cell::new(0) };
    }

    struct Counting;

    fn add() {
        // try_with: a thread being torn down has no counter any more
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
    }

    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            add();
            System.alloc(layout)
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            System.dealloc(ptr, layout)
        }
        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            add();
            System.realloc(ptr, layout, new_size)
        }
    }

    #[global_allocator]
    static GLOBAL: Counting = Counting;

    /// Allocations made so far by the calling thread.
    pub fn on_this_thread() -> usize {
        COUNT.with(|c| c.get())
    }
}
