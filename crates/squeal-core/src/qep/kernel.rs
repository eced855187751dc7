//! The trait of the full-order complex backends: a Krylov iteration for the eigenvalues
//! of largest modulus of a complex operator ([`ComplexKernel`]).

use crate::spectral::LinOp;
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
}
