//! Component mode synthesis: the built-in shrouded-blade benchmark ([`blade`]) and its
//! two-blade shroud-coupled variant with node-pair contacts ([`blade_pair`]), its linear
//! hexahedral element ([`hex8`]), a sparse shift-invert Lanczos eigen solver ([`eigen`]) and the
//! sparse Craig-Bampton reduction ([`craig_bampton`]) that turns a large sparse FE model into a
//! normal dense [`crate::model::Model`].
//!
//! Sparse matrices are `faer::sparse::SparseColMat<usize, f64>` ([`SparseMat`]) in full
//! (both triangles) storage. Nothing here ever forms a dense matrix of the full model size.
//!
//! Cost (benches/cms.rs, 2 cores): default blade (22,134 DoFs, 18 contact nodes) builds in
//! ~1.2 s and reduces (50 modes) in ~5.4 s at ~0.3 GB peak; `refinement = 5` (39,678 DoFs,
//! 242 contact nodes) ~2.3 s + 15 s at ~0.85 GB. With ~2,000 contact nodes
//! (`refinement = 15`, 140,658 DoFs) the model builds in ~16 s (2.3 GB); Craig-Bampton with all
//! ~5,800 contact DoFs as boundary and `keep_recovery: false` (no `n_i x n_b` constraint modes,
//! blocks of 256 boundary columns) took 643 s at 4.0 GB peak on a shared 2-core machine
//! (benches/jp_blade_2k.rs); keeping the constraint modes adds their ~6 GB.

pub mod hex8;
pub mod blade;
pub mod blade_pair;
pub mod plate;
pub mod craig_bampton;
pub mod nodal;

pub use blade::{BladeFe, BladeParams, BuiltinBlade, CbModel, ContactNode};
pub use blade_pair::{BladePair, PairParams, PairSite};
pub use craig_bampton::{CbOptions, CraigBampton};
pub use nodal::{contact_frame, cylindrical_frame, FeModel, FeNode, NodalContact, NodalForce, RadialSense, Reduction};
pub use plate::{PlateContact, PlateFe, PlateParams};
