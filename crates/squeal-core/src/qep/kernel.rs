//! The trait of the full-order complex backends: a Krylov iteration for the eigenvalues
//! of largest modulus of a complex operator ([`ComplexKernel`]).

use crate::spectral::{LinOp, RealOp};
use crate::{c64, Result};
use faer::Mat;

/// Output of a [`ComplexKernel`]: eigenpairs of largest modulus of the operator.
#[derive(Debug, Clone)]
pub struct ComplexKernelOutput {
    /// Converged operator eigenvalues `theta`, any order.
    pub theta: Vec<c64>,
    /// Matching eigenvectors (columns), any scaling.
    pub vectors: Mat<c64>,
    /// Restarts / iterations used.
    pub iterations: usize,
    /// Whether every requested pair converged.
    pub all_converged: bool,
}

/// A Krylov iteration for the `nev` eigenvalues of largest modulus of a general complex
/// operator (ARPACK `znaupd`, Krylov-Schur, ...).
pub trait ComplexKernel: Send + Sync {
    /// Computes the `nev` eigenpairs of largest `|theta|` to relative tolerance `tol`.
    fn largest(
        &self,
        op: &dyn LinOp<c64>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<ComplexKernelOutput>;

    /// The same for a real operator ([`RealOp`]), whose eigenvalues are real or come in
    /// conjugate pairs (both members returned). A backend with a real iteration uses
    /// [`RealOp::real`]: one real column per application and real orthogonalization,
    /// against two columns and complex arithmetic on the complex view. The default runs
    /// [`largest`](Self::largest) on [`RealOp::complex`].
    fn largest_real(
        &self,
        op: &dyn RealOp,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<ComplexKernelOutput> {
        self.largest(op.complex(), nev, tol, max_restarts)
    }
}
