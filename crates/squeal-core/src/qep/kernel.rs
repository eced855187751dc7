//! The traits of the full-order complex backends: a complex linear operator
//! ([`ComplexLinOp`]) and a Krylov iteration for its eigenvalues of largest modulus
//! ([`ComplexKernel`]).

use crate::{c64, Result};
use faer::Mat;

/// A complex linear operator `y = OP x` (a shift-invert operator, a test matrix...).
pub trait ComplexLinOp: Sync {
    /// Size of the operator.
    fn dim(&self) -> usize;
    /// `y = OP x`; `x` and `y` have length [`dim`](Self::dim).
    fn apply(&self, x: &[c64], y: &mut [c64]);
}

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
        op: &dyn ComplexLinOp,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<ComplexKernelOutput>;
}
