//! # squeal-core
//!
//! The contracts every other squeal crate builds on:
//!
//! - the five plugin traits [`Material`], [`ContactLaw`], [`EquilibriumSolver`],
//!   [`ReductionBasis`] and [`EigenSolver`];
//! - the problem and result types they exchange ([`SymmetricProblem`], [`RealModes`],
//!   [`SolveInfo`]);
//! - [`Params`], the name/value parameters a plugin is built from;
//! - the [`Registry`] that maps plugin names to constructors;
//! - shared numerical machinery that every backend uses the same way ([`linalg`], [`qep`],
//!   [`lowrank`] for the Woodbury path of undamped frictional operators, and [`reduction`]
//!   for the reduction bases);
//! - [`interop`]: sparse matrices and whole operators to and from `nalgebra-sparse` and
//!   `sprs` (features of the same names).
//!
//! Units: SI throughout (m, kg, s, N, Pa); frequencies in Hz, eigenvalues of the
//! symmetric problem `K x = omega^2 M x` in (rad/s)^2.
#![doc(html_no_source)]

pub mod contact;
pub mod eigen;
pub mod error;
pub mod interop;
pub mod linalg;
pub mod lowrank;
pub mod material;
pub mod ordering;
pub mod params;
pub mod qep;
pub mod reduction;
pub mod registry;

pub use contact::{
    build_basis, Basis, BasisRequest, ContactLaw, EquilibriumSolver, FreeModel, FrictionalOperator,
    ModelStage, PairDofs, ReductionBasis,
};
pub use eigen::{
    solve_symmetric_band, EigenParams, EigenSolver, KernelOutput, RealModes, SolveInfo, StopReason,
    SymmetricKernel, SymmetricProblem,
};
pub use error::{Error, Result};
pub use lowrank::{FrictionLowRank, QepLowRankSquared, SymmetricPencil, SymmetricShift};
pub use material::{Material, Voigt6};
pub use params::{ParamValue, Params};
pub use qep::{
    dense_qep, solve_frictional_band, solve_qep_band, ComplexKernel, ComplexKernelOutput,
    ComplexLinOp, ComplexModes, LowRank, Qep, QepShiftInvert, QepSymbolic,
};
pub use reduction::{solve_reduced, ReducedOperator, ReducedSolve};
pub use registry::Registry;

pub use faer;
/// Complex double, the scalar of the frictional (non-symmetric) problems.
pub use faer::c64;
/// Real sparse matrix in compressed-column form, the storage of `K`, `M`, `C`.
pub type SparseMat = faer::sparse::SparseColMat<usize, f64>;
/// Borrowed view of a [`SparseMat`].
pub type SparseRef<'a> = faer::sparse::SparseColMatRef<'a, usize, f64>;
