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
//!
//! Backward error of a pair on the operator it was computed for:
//! `eta = ||Q(lambda) u|| / ((|lambda|^2 ||M~|| + |lambda| ||C~|| + ||K~||) ||u||)`
//! (1-norms of the matrices, 2-norm of the vectors).

use crate::eigen::{EigenParams, SolveInfo};
use crate::{c64, Error, Result, SparseMat};
use faer::Mat;

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

/// Complex modes of a QEP in a frequency band, sorted by frequency.
#[derive(Debug, Clone)]
pub struct ComplexModes {
    /// Eigenvalues `lambda` (1/s), the `Im > 0` member of each pair.
    pub lambda: Vec<c64>,
    /// Matching mode shapes on the operator's DOFs, one column per mode, unit 2-norm.
    pub vectors: Mat<c64>,
    /// Frequencies `Im(lambda) / 2 pi` (Hz).
    pub freq_hz: Vec<f64>,
    /// Divergence rates `Re(lambda) / Im(lambda)`.
    pub dvr: Vec<f64>,
    /// Backward error of each pair on the operator (see module docs).
    pub backward_error: Vec<f64>,
    /// How the solve went.
    pub info: SolveInfo,
}

impl ComplexModes {
    /// Number of modes.
    pub fn len(&self) -> usize {
        self.lambda.len()
    }
    /// Whether no mode was found.
    pub fn is_empty(&self) -> bool {
        self.lambda.is_empty()
    }
    /// Whether mode `i` is unstable (`Re(lambda) > 0` beyond `rel_tol |lambda|`).
    pub fn is_unstable(&self, i: usize, rel_tol: f64) -> bool {
        self.lambda[i].re > rel_tol * self.lambda[i].norm()
    }
}

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

/// Shift-invert of the companion form at a complex shift `sigma`:
/// `OP = (A - sigma B)^-1 B` with `A = [0 I; -K -C]`, `B = [I 0; 0 M]`, applied through one
/// sparse LU of `Q(sigma) = sigma^2 M + sigma C + K`:
/// `x1 = -Q^-1 [b2 + (C + sigma M) b1]`, `x2 = b1 + sigma x1` where `b = B x`.
/// Eigenvalues map back as `lambda = sigma + 1/theta`.
pub struct QepShiftInvert<'a> {
    qep: &'a Qep,
    sigma: c64,
    #[allow(dead_code)]
    lu: Option<faer::sparse::linalg::solvers::Lu<usize, c64>>,
}

impl<'a> QepShiftInvert<'a> {
    /// Factorizes `Q(sigma)`.
    pub fn new(qep: &'a Qep, sigma: c64) -> Result<Self> {
        let _ = (qep, sigma);
        Err(Error::Unsupported {
            plugin: "squeal-core".into(),
            operation: "QepShiftInvert (not implemented yet)".into(),
        })
    }
    /// The shift.
    pub fn sigma(&self) -> c64 {
        self.sigma
    }
    /// The problem it was built for.
    pub fn qep(&self) -> &Qep {
        self.qep
    }
    /// `lambda = sigma + 1/theta`.
    pub fn lambda_of_theta(&self, theta: c64) -> c64 {
        self.sigma + c64::new(1.0, 0.0) / theta
    }
}

/// Band driver shared by the full-order complex backends: shifts `i 2 pi f` chosen to cover
/// `[params.fmin_hz, params.fmax_hz]`, the kernel run on [`QepShiftInvert`] for each, `nev`
/// grown until every window is covered, eigenvalues mapped back, duplicates merged, and the
/// result finished by [`finish_modes`].
pub fn solve_qep_band(
    solver: &str,
    kernel: &dyn ComplexKernel,
    qep: &Qep,
    params: &EigenParams,
) -> Result<ComplexModes> {
    let _ = (solver, kernel, qep, params);
    Err(Error::Unsupported {
        plugin: solver.into(),
        operation: "solve_qep_band (not implemented yet)".into(),
    })
}

/// All eigenpairs of a small QEP, densely: companion form scaled by
/// `gamma = sqrt(||K|| / ||M||)`, infinite and rigid-body roots filtered out.
/// Returns every finite eigenvalue (both members of conjugate pairs) and its vector `u`.
pub fn dense_qep(qep: &Qep) -> Result<(Vec<c64>, Mat<c64>)> {
    let _ = qep;
    Err(Error::Unsupported {
        plugin: "squeal-core".into(),
        operation: "dense_qep (not implemented yet)".into(),
    })
}

/// Backward error of `(lambda, u)` on `qep` (see module docs).
pub fn backward_error(qep: &Qep, lambda: c64, u: &[c64]) -> f64 {
    let _ = (qep, lambda, u);
    f64::NAN
}

/// Keeps the pairs with `Im(lambda) > 0` and frequency in the band, normalizes the vectors,
/// computes frequencies, DvR and backward errors, and sorts by frequency.
pub fn finish_modes(
    qep: &Qep,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
) -> Result<ComplexModes> {
    let _ = (qep, lambda, vectors, params, info);
    Err(Error::Unsupported {
        plugin: "squeal-core".into(),
        operation: "finish_modes (not implemented yet)".into(),
    })
}
