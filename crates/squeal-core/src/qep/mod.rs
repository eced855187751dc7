//! The non-symmetric quadratic eigenproblem (QEP) of the frictional operator and the
//! machinery every complex backend shares.
//!
//! `(lambda^2 M~ + lambda C~ + K~) u = 0` with `X~ = X_c - mu F_X` (see
//! [`FrictionalOperator`](crate::contact::FrictionalOperator)). Convention
//! `U = u exp(lambda t)`: a mode is unstable iff `Re(lambda) > 0`; its frequency is
//! `Im(lambda) / 2 pi` and its divergence rate `DvR = Re(lambda) / Im(lambda)`. Results keep
//! the `Im(lambda) > 0` member of each conjugate pair.
//!
//! Full-order backends differ only in their Krylov iteration ([`ComplexKernel`]); the
//! shift-invert operator on the companion form ([`QepShiftInvert`]), the band driver
//! ([`solve_qep_band`]), the dense solver for small and reduced problems ([`dense_qep`]) and
//! the backward error ([`backward_error`]) are written once, here.
//! Undamped frictional operators may instead go through the low-rank (Woodbury) path of
//! [`crate::lowrank`] ([`solve_frictional_band`], [`QepBandOptions::low_rank`]).
//!
//! Backward error of a pair on the operator it was computed for:
//! `eta = ||Q(lambda) u|| / ((|lambda|^2 ||M~|| + |lambda| ||C~|| + ||K~||) ||u||)`
//! (1-norms of the matrices, 2-norm of the vectors).

use crate::linalg::check_square_finite;
use crate::{Result, SparseMat};

mod band;
pub mod condition;
mod dense;
mod kernel;
mod modes;
mod residual;
mod shift_invert;
#[cfg(test)]
mod tests;
pub(crate) mod vector;
mod window;

pub use band::{
    solve_frictional_band, solve_frictional_band_with, solve_qep_band, solve_qep_band_with,
    LowRank, QepBandOptions, LOW_RANK_AUTO_MIN_DIM,
};
pub use condition::{
    left_eigenvectors, Condition, LeftInfo, CLUSTER_REL, CONDITION_AUTO_MAX_DIM, DENSE_LEFT_MAX_DIM,
};
pub use dense::{dense_qep, RIGID_BODY_REL};
pub use kernel::{ComplexKernel, ComplexKernelOutput, ComplexLinOp};
pub use modes::{
    add_condition, band_pairs, finish_modes, finish_modes_with, finish_operator_modes,
    finish_operator_modes_with_left, ComplexModes, REAL_ROOT_REL,
};
pub use residual::backward_error;
pub use shift_invert::{QepShiftInvert, QepSquaredShift, QepSymbolic};
pub use vector::spmv_complex;

/// One quadratic eigenproblem `(lambda^2 M + lambda C + K) u = 0` (one mu, one contact set).
#[derive(Debug, Clone)]
pub struct Qep {
    /// Mass part `M~` (kg).
    pub m: SparseMat,
    /// Damping part `C~` (N s/m); `None` means zero.
    pub c: Option<SparseMat>,
    /// Stiffness part `K~` (N/m).
    pub k: SparseMat,
}

impl Qep {
    /// Size of the problem.
    pub fn dim(&self) -> usize {
        self.k.nrows()
    }
}

/// Checks that `M`, `C` and `K` are square of the same size with finite entries.
pub fn check_qep(qep: &Qep) -> Result<()> {
    let n = qep.dim();
    check_square_finite(qep.k.as_ref(), n, "K~")?;
    check_square_finite(qep.m.as_ref(), n, "M~")?;
    if let Some(c) = &qep.c {
        check_square_finite(c.as_ref(), n, "C~")?;
    }
    Ok(())
}
