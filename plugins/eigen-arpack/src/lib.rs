//! # squeal-eigen-arpack
//!
//! The `arpack` eigen solver: ARPACK's implicitly restarted Lanczos method
//! (`dsaupd`/`dseupd`, ARPACK-NG through [`arpack_ffi`]) in shift-invert mode on the
//! symmetric generalized problem of the normal modes,
//!
//! ```text
//! K x = lambda M x,   lambda = omega^2,   K = K^T >= 0,   M = M^T > 0.
//! ```
//!
//! With a shift `sigma` below the spectrum (chosen by [`squeal_core::solve_symmetric_band`],
//! `sigma = -(2 pi shift_hz)^2`), `K - sigma M` is positive definite and factorized once
//! by a sparse Cholesky decomposition. ARPACK's *mode 3* (`bmat = 'G'`, `which = "LM"`)
//! runs Lanczos on
//!
//! ```text
//! OP = (K - sigma M)^-1 M,   OP x = theta x,   theta = 1 / (lambda - sigma),
//! ```
//!
//! which is self-adjoint in the `M` inner product `<x, y>_M = x^T M y`; the largest
//! `theta` are the `lambda` nearest `sigma`, i.e. the lowest modes, and they converge
//! fast because `theta` decays like `1 / lambda`. The reverse-communication requests of
//! `dsaupd` map onto the [`ShiftInvert`](squeal_core::linalg::ShiftInvert) operator:
//!
//! | `ido` | ARPACK asks for | computed as |
//! |------:|-----------------|-------------|
//! | -1 | `y = OP x` (no `M x` yet) | `op.apply(x, y)` |
//! |  1 | `y = OP x`, `M x` supplied | `op.apply_with_mx(mx, y)` |
//! |  2 | `y = M x` | `op.m_mul(x, y)` |
//!
//! `dseupd` returns the Ritz values back-transformed, `lambda = sigma + 1 / theta`; the
//! kernel converts them back to `theta` (the [`SymmetricKernel`] contract), and the band
//! driver of squeal-core does the back-transformation, `M`-normalization, residuals and
//! band selection once for every backend.
//!
//! ARPACK is not thread safe (Fortran `SAVE` state): runs are serialized by
//! [`arpack_ffi::ARPACK_LOCK`]. The start vector is fixed, so results are reproducible.
//!
//! Reference: R. B. Lehoucq, D. C. Sorensen, C. Yang, *ARPACK Users' Guide: Solution of
//! Large-Scale Eigenvalue Problems with Implicitly Restarted Arnoldi Methods*, SIAM,
//! Philadelphia, 1998 (section 3.2.3 and appendix for `dsaupd` mode 3; `info` codes
//! from the `dsaupd`/`dseupd` prologues).

mod error;
mod kernel;

pub use error::{ArpackError, Routine};
pub use kernel::ArpackKernel;

use squeal_core::eigen::SymmetricKernel;
use squeal_core::{EigenParams, EigenSolver, Params, RealModes, Result, SymmetricProblem};

/// The registered name.
pub const NAME: &str = "arpack";

/// The `arpack` [`EigenSolver`]: the shared band driver around [`ArpackKernel`].
#[derive(Debug, Clone, Copy, Default)]
pub struct ArpackSolver;

impl ArpackSolver {
    /// Builds the solver from plugin parameters; it takes none, so any key is an error.
    pub fn new(params: &Params) -> Result<Self> {
        params.reject_unknown(NAME, &[])?;
        Ok(Self)
    }

    /// The Krylov kernel used by [`EigenSolver::solve_symmetric`].
    pub fn kernel(&self) -> &dyn SymmetricKernel {
        &ArpackKernel
    }
}

impl EigenSolver for ArpackSolver {
    fn name(&self) -> &str {
        NAME
    }

    fn solve_symmetric(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        squeal_core::solve_symmetric_band(NAME, &ArpackKernel, problem, params)
    }
}

/// Registers the `arpack` eigen solver.
pub fn register(reg: &mut squeal_core::Registry) {
    reg.eigen.register(
        NAME,
        "ARPACK shift-invert Lanczos (dsaupd mode 3) on a sparse Cholesky of K - sigma M",
        |p| Ok(Box::new(ArpackSolver::new(p)?)),
    );
}

#[cfg(test)]
mod tests;
