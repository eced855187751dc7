//! # squeal-eigen-arpack
//!
//! The `arpack` eigen solver: ARPACK's implicitly restarted Lanczos method
//! (`dsaupd`/`dseupd`, ARPACK-NG through [`arpack_ffi`]) in shift-invert mode on the
//! symmetric generalized problem of the normal modes, and its implicitly restarted
//! Arnoldi methods, complex (`znaupd`/`zneupd`) and real (`dnaupd`/`dneupd`), for the
//! complex modes of the frictional quadratic eigenproblem (see the last section).
//! Normal modes:
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
//! `dsaupd` map onto the [`ShiftInvert`](squeal_core::spectral::ShiftInvert) operator:
//!
//! | `ido` | ARPACK asks for | computed as |
//! |------:|-----------------|-------------|
//! | -1 | `y = OP x` (no `M x` yet) | `op.apply(x, y)` |
//! |  1 | `y = OP x`, `M x` supplied | `op.apply_with_mx(mx, y)` |
//! |  2 | `y = M x` | `op.m_mul(x, y)` |
//!
//! `dseupd` returns the Ritz values back-transformed, `lambda = sigma + 1 / theta`; the
//! kernel converts them back to `theta` (the [`SymmetricKernel`](squeal_core::SymmetricKernel) contract), and the band
//! driver of squeal-core does the back-transformation, `M`-normalization, residuals and
//! band selection once for every backend.
//!
//! ARPACK is not thread safe (Fortran `SAVE` state): runs are serialized by
//! [`arpack_ffi::ARPACK_LOCK`]. The start vector is fixed, so results are reproducible.
//!
//! ## Complex modes of the frictional QEP
//!
//! [`EigenSolver::solve_qep`](squeal_core::EigenSolver::solve_qep) runs the band driver of squeal-core
//! ([`squeal_core::qep::solve_qep_band`]) with [`ArpackComplexKernel`]: ARPACK's complex
//! Arnoldi iteration `znaupd`/`zneupd` in *standard mode 1* (`bmat = 'I'`,
//! `which = "LM"`) on the user operator `OP = (A - sigma B)^-1 B` of the companion form
//! at a complex shift `sigma = i 2 pi f_c`
//! ([`QepShiftInvert`](squeal_core::spectral::QepShiftInvert)). ARPACK's generalized modes
//! need a Hermitian positive semi-definite `B`, which `B = [I 0; 0 M~]` with a
//! non-symmetric `M~` is not, hence the standard mode on the shift-inverted operator.
//! The only reverse-communication request is `ido = -1 / 1`: `y = OP x`. The kernel
//! returns the operator eigenvalues `theta`; the driver maps them back,
//! `lambda = sigma + 1 / theta`.
//!
//! An undamped operator (`C = 0`) is solved through the squared transformation
//! `OP = (K~ - s M~)^-1 M~` at a real shift ([`SquaredShift`](squeal_core::spectral::SquaredShift)),
//! a real operator: [`ComplexKernel::largest_real`](squeal_core::qep::ComplexKernel::largest_real)
//! runs ARPACK's real driver `dnaupd`/`dneupd` (mode 1, `which = "LM"`) on it, one real
//! column per application and real orthogonalization, where the complex driver would
//! apply it to two real columns in complex arithmetic. Its complex Ritz values come in
//! conjugate pairs, whose vectors `dneupd` stores as a real and an imaginary column;
//! both members are returned.
//!
//! Reference: R. B. Lehoucq, D. C. Sorensen, C. Yang, *ARPACK Users' Guide: Solution of
//! Large-Scale Eigenvalue Problems with Implicitly Restarted Arnoldi Methods*, SIAM,
//! Philadelphia, 1998 (section 3.2.3 and appendix for `dsaupd` mode 3; `info` codes
//! from the `dsaupd`/`dseupd` and `znaupd`/`zneupd` prologues).

mod complex;
mod error;
mod kernel;
mod real;

pub use complex::ArpackComplexKernel;
pub use error::{ArpackError, Routine};
pub use kernel::ArpackKernel;

use squeal_core::{KernelSolver, Params, Result};

/// The registered name.
pub const NAME: &str = "arpack";

/// The `arpack` [`EigenSolver`](squeal_core::EigenSolver): the shared band drivers around
/// [`ArpackKernel`] (normal modes) and [`ArpackComplexKernel`] (complex modes of the QEP).
pub type ArpackSolver = KernelSolver<ArpackKernel, ArpackComplexKernel>;

/// The `arpack` solver.
pub const ARPACK: ArpackSolver = KernelSolver::new(NAME, ArpackKernel, ArpackComplexKernel);

/// Builds the solver from plugin parameters; it takes none, so any key is an error.
pub fn solver(params: &Params) -> Result<ArpackSolver> {
    params.tracked().refuse_unread("eigen", NAME)?;
    Ok(ARPACK)
}

/// Registers the `arpack` eigen solver.
pub fn register(reg: &mut squeal_core::Registry) {
    reg.eigen.register(
        NAME,
        "ARPACK shift-invert Lanczos (dsaupd mode 3) on a sparse Cholesky of K - sigma M; \
         complex modes by znaupd (mode 1) on the companion shift-invert operator (sparse LU), \
         or by dnaupd on the real squared transformation when C = 0",
        |p| Ok(Box::new(solver(p)?)),
    );
}

#[cfg(test)]
mod complex_tests;
#[cfg(test)]
mod tests;
