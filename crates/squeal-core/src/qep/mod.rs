//! The drivers of the non-symmetric quadratic eigenproblem (QEP) of the frictional operator
//! that every complex backend shares.
//!
//! `(lambda^2 M~ + lambda C~ + K~) u = 0` with `X~ = X_c - mu F_X` (see
//! [`Qep`](crate::operator::Qep) and
//! [`FrictionalOperator`](crate::operator::FrictionalOperator)). Convention
//! `U = u exp(lambda t)`: a mode is unstable iff `Re(lambda) > 0`; its frequency is
//! `Im(lambda) / 2 pi` and its divergence rate `DvR = Re(lambda) / Im(lambda)`. Results keep
//! the `Im(lambda) > 0` member of each conjugate pair.
//!
//! Full-order backends differ only in their Krylov iteration ([`ComplexKernel`]) on a
//! spectral transformation of [`crate::spectral`]; the band driver
//! ([`solve_qep_band`]), the dense solver for small and reduced problems ([`dense_qep`]) and
//! the backward error ([`backward_error`]) are written once, here.
//! Undamped frictional operators may instead go through the low-rank (Woodbury) path of
//! [`crate::lowrank`] ([`solve_frictional_band`], [`QepBandOptions::low_rank`]).
//!
//! Backward error of a pair on the operator it was computed for:
//! `eta = ||Q(lambda) u|| / ((|lambda|^2 ||M~|| + |lambda| ||C~|| + ||K~||) ||u||)`
//! (1-norms of the matrices, 2-norm of the vectors).

mod band;
pub mod condition;
mod dense;
mod kernel;
mod kernel_solver;
mod modes;
mod residual;
#[cfg(test)]
mod tests;
mod window;

pub use band::{
    solve_frictional_band, solve_frictional_band_with, solve_qep_band, solve_qep_band_with,
    LowRank, QepBandOptions, LOW_RANK_AUTO_MIN_DIM,
};
pub use condition::{
    left_eigenvectors, Condition, LeftInfo, CLUSTER_REL, CONDITION_AUTO_MAX_DIM, DENSE_LEFT_MAX_DIM,
};
pub use dense::{dense_qep, RIGID_BODY_REL};
pub use kernel::{ComplexKernel, ComplexKernelOutput};
pub use kernel_solver::KernelSolver;
pub use modes::{
    add_condition, band_pairs, finish_modes, finish_modes_with, finish_operator_modes,
    finish_operator_modes_with_left, CONDITION_WHERE_NEEDED_MAX_DIM, REAL_ROOT_REL,
};
pub use residual::{backward_error, residuals_and_derivatives};
