//! The [`EigenSolver`] plugin trait and the symmetric (real-mode) problem.
//!
//! Normal modes solve `K x = omega^2 M x` with `K` symmetric positive semi-definite and
//! `M` symmetric positive definite, on the free DOFs. Every backend works on the same
//! [`ShiftInvert`](crate::spectral::ShiftInvert) transformation `(K - sigma M)^-1 M` (shift below the spectrum, one Cholesky
//! factorization) through the [`SymmetricKernel`] trait; the band logic, the
//! back-transformation, the normalization and the residuals are written once, in
//! [`solve_symmetric_band`], so backends differ only in their Krylov iteration.
//!
//! Residual of a pair: `||K x - omega^2 M x|| / ((||K||_1 + omega^2 ||M||_1) ||x||)`,
//! a relative backward error.

mod params;
mod solver;
mod symmetric;

pub use params::{too_many_modes, validate_params, EigenParams};
pub use solver::EigenSolver;
pub use symmetric::{
    dense_symmetric, dense_symmetric_pencil, finish_real_modes, solve_symmetric_band,
    solve_symmetric_band_on, KernelOutput, SymmetricKernel, SymmetricProblem, ABOVE_BAND_KEPT,
};
