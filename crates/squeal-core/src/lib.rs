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
//! - shared numerical machinery that every backend uses the same way, along the data
//!   path, each module using only those above it in this list: [`ordering`] and [`linalg`]
//!   (sparse kernels and factorizations); [`operator`] (the QEP, the frictional operator,
//!   modes and solve reports); [`lowrank`] (the Woodbury path of undamped frictional
//!   operators); [`spectral`] (every spectral transformation, behind one operator trait);
//!   [`eigen`] (the solver trait and the symmetric band driver); [`qep`] (the QEP band
//!   driver, dense solver, backward errors, condition numbers); [`contact`] (contact laws,
//!   equilibrium, the basis trait and the model stage); [`reduction`] (projection and
//!   reduced solves for every basis);
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
pub mod operator;
pub mod ordering;
pub mod params;
pub mod qep;
pub mod reduction;
pub mod registry;
pub mod spectral;

pub use contact::{
    build_basis, Basis, BasisRequest, ContactLaw, EquilibriumSolver, FreeModel, ImplicitColumns,
    ModelStage, PairDofs, ReductionBasis, Seed,
};
pub use eigen::{
    solve_symmetric_band, solve_symmetric_band_on, EigenParams, EigenSolver, KernelOutput,
    SymmetricKernel, SymmetricProblem,
};
pub use error::{Error, Result};
pub use lowrank::{FrictionLowRank, SymmetricPencil, SymmetricShift, Woodbury};
pub use material::{Material, Voigt6};
pub use operator::{
    ComplexModes, FrictionalOperator, Qep, RealModes, SolveInfo, Stability, StopReason, Verdict,
};
pub use params::{ParamValue, Params};
pub use qep::{
    dense_qep, solve_frictional_band, solve_qep_band, ComplexKernel, ComplexKernelOutput,
    KernelSolver, LowRank,
};
pub use reduction::{solve_reduced, ReducedOperator, ReducedSolve};
pub use registry::Registry;
pub use spectral::{
    LinOp, QepShiftInvert, QepSymbolic, ShiftInvert, SpectralTransform, SquaredShift,
};

pub use faer;
/// Complex double, the scalar of the frictional (non-symmetric) problems.
pub use faer::c64;
/// Real sparse matrix in compressed-column form, the storage of `K`, `M`, `C`.
pub type SparseMat = faer::sparse::SparseColMat<usize, f64>;
/// Borrowed view of a [`SparseMat`].
pub type SparseRef<'a> = faer::sparse::SparseColMatRef<'a, usize, f64>;
