//! Krylov-Schur (Stewart 2001) in complex arithmetic for the eigenvalues of largest
//! modulus of a general (non-Hermitian) operator: the kernel of the `"krylov"` backend for
//! the frictional quadratic eigenproblem (run by [`squeal_core::qep::solve_qep_band`] on
//! the shift-invert operator of the companion form).
//!
//! ## Krylov decomposition
//!
//! The active part of the method is an orthonormal basis `V_m` (`V_m^H V_m = I`), an
//! `m x m` projected matrix `H` and a residual `f = beta v_{m+1}` with
//!
//! ```text
//! OP V_m = Q_L G + V_m H + beta v_{m+1} e_m^T,      [Q_L V_m v_{m+1}] orthonormal,
//! ```
//!
//! where `Q_L` (`p` columns) is the *locked* basis: an orthonormal basis of the invariant
//! subspace spanned by the eigenvectors converged so far (`OP Q_L ~ Q_L T_L`, `T_L` upper
//! triangular). `H` is the projection of the deflated operator `(I - Q_L Q_L^H) OP`,
//! whose spectrum is that of `OP` without the locked eigenvalues, so the eigenvalues of
//! `H` approximate the next ones. For an eigenpair `H y = theta y` (`||y|| = 1`) the
//! vector `x = Q_L z + V_m y` with `(T_L - theta) z = -G y` is a Ritz vector of `OP` with
//! residual exactly `||OP x - theta x|| = beta |y_m|`, so a pair is accepted when
//!
//! ```text
//! beta |e_m^T y| <= tol |theta|.
//! ```
//!
//! **Expansion** is Arnoldi with full reorthogonalization: every new vector `OP v_j` is
//! orthogonalized against `Q_L` and all of `V_j` by classical Gram-Schmidt applied twice
//! (a third pass when less than `1e-6` of its norm survives), the coefficients against
//! `V_j` forming column `j` of `H`. A breakdown (`beta <= 1e-12 ||OP v_j||`) means an
//! invariant subspace: the coupling is set to zero and the iteration continues from a new
//! deterministic pseudo-random vector orthogonal to everything held.
//!
//! ## Restart (Krylov-Schur) and locking
//!
//! The basis holds `ncv = min(n - p, max(2 nev + 1, nev + 16))` vectors. When it is full,
//! the eigenvalues of `H` are computed (faer's dense complex `eigen`), and `keep =
//! want + (ncv - want) / 2` of them are selected: first the converged wanted ones, then
//! the unconverged wanted ones (largest modulus first), then the next largest. An
//! orthonormal basis `Z_k` of the `H`-invariant subspace belonging to the selected
//! eigenvalues is built column by column as in the constructive proof of Schur's theorem
//! (faer does not expose an ordered complex Schur form): for each selected `sigma_j`,
//! an eigenvector `x` of the trailing block `W_22` of the current `W = Z^H H Z` is
//! computed (shifted inverse iteration started from the transformed Ritz vector, dense
//! `eigen` of the block as fallback), and a Householder reflector with first column
//! `x` is applied to `W` and `Z`. Since `W_22 x - (x^H W_22 x) x` is a residual of
//! rounding size, dropping the new sub-diagonal block is a backward-stable deflation,
//! also for repeated and nearly repeated eigenvalues (where individual eigenvectors of
//! `H` are ill-determined, but the invariant subspace is not). Then
//!
//! ```text
//! OP (V_m Z_k) = Q_L (G Z_k) + (V_m Z_k) T_k + v_{m+1} (beta e_m^T Z_k),
//! ```
//!
//! `T_k = Z_k^H H Z_k` upper triangular: a Krylov decomposition with a general coupling
//! row, which is all Krylov-Schur needs. The leading `c` columns (the converged wanted
//! pairs) are **locked**: appended to `Q_L` and their coupling dropped (a perturbation of
//! size `beta |e_m^T y| <= tol |theta|` per eigenvector, the Ritz residual); the other
//! `keep - c` columns stay active with `H <- T_k[c.., c..]`, the coupling row
//! `beta e_m^T Z_k[:, c..]` as the next row of `H`, and `v_{m+1}` as the next basis
//! vector, from which Arnoldi resumes.
//!
//! ## Repeated eigenvalues: validation runs
//!
//! The Krylov space of one start vector contains a single direction of every eigenspace,
//! so one copy of an exactly repeated eigenvalue (a disc doublet) is invisible to it in
//! exact arithmetic. After the first run has locked `nev` pairs, a *validation run* is
//! started from a fresh vector orthogonal to `Q_L`: it works on the deflated operator and
//! stops as soon as its largest converged Ritz value lies below the `nev`-th largest
//! locked modulus (nothing was missed); pairs above it are locked too and the validation
//! is repeated. Each round exposes one more copy, so every multiplicity is resolved (as in
//! the Lanczos kernel of this crate).
//!
//! ## Output and verification
//!
//! At the end, `OP Q_L` is formed (`p` operator applications) and `T_L = Q_L^H OP Q_L`;
//! its strictly lower part (of the order of the dropped couplings) is discarded. The
//! eigenvalues are the diagonal of `T_L` (Rayleigh quotients of the Schur vectors), the
//! eigenvectors `x = Q_L w` with `w` from back-substitution on `T_L`. When a pivot
//! `T_ii - theta` is below `1e-8 |theta|` *and* the right-hand side is below
//! `tol |theta| ||w||`, the pair is a copy of a semisimple repeated eigenvalue and
//! `w_i = 0` is chosen (otherwise ill-determined: `0 / 0`), so the copies get
//! independent eigenvectors. Every pair's true residual `||OP x - theta x||` is computed;
//! pairs above `100 tol |theta|` (plus a rounding floor) are dropped and the call then
//! reports `all_converged = false`. The `nev` largest in modulus are returned, sorted by
//! decreasing modulus, with unit-norm vectors.
//!
//! ## Budget, small problems
//!
//! `max_restarts` caps the restarts summed over all runs of one call (the start of each
//! validation run counts as one); when it is hit, the converged pairs are returned with
//! `all_converged = false` (never an error). Start vectors are deterministic.
//!
//! **`nev >= n` uses a dense fallback**: the operator is formed column by column (`n`
//! applications) and all `n` eigenpairs are computed by faer's dense complex `eigen`,
//! for `n <= 4096` (an error beyond, where asking for every eigenvalue of a matrix-free
//! operator is a mistake).
//!
//! ## References
//!
//! - G. W. Stewart, *A Krylov-Schur algorithm for large eigenproblems*, SIAM J. Matrix
//!   Anal. Appl. 23(3), 601-614, 2001.
//! - V. Hernandez, J. E. Roman, A. Tomas, *Krylov-Schur methods in SLEPc*, SLEPc
//!   technical report STR-7, 2007.
//! - R. B. Lehoucq, D. C. Sorensen, C. Yang, *ARPACK Users' Guide*, SIAM, 1998.

use super::{
    par_for, Directions, BREAKDOWN, CHECK_EVERY, NEW_DIRECTION_MIN, NEW_DIRECTION_TRIES, THIRD_PASS,
};
use squeal_core::faer::Mat;
use squeal_core::qep::{ComplexKernel, ComplexKernelOutput};
use squeal_core::spectral::LinOp;
use squeal_core::{c64, Error, Result};

mod dense;
mod krylov;
#[cfg(test)]
mod tests;

use dense::*;
use krylov::*;

/// Largest problem for the dense fallback used when `nev >= n`.
pub const DENSE_MAX: usize = 4096;
/// Verified residuals above this multiple of `tol |theta|` reject a pair.
const VERIFY_FACTOR: f64 = 100.0;
/// Pivots below this fraction of `|theta|` may mark a copy of a repeated eigenvalue.
const REPEAT_REL: f64 = 1e-8;
/// Inverse-iteration steps in the Schur deflation before the dense fallback.
const INVERSE_STEPS: usize = 3;
/// Accepted deflation residual, in units of `eps ||H||_F`.
const DEFLATION_ACCEPT: f64 = 1e3;

const ONE: c64 = c64 { re: 1.0, im: 0.0 };
const ZERO: c64 = c64 { re: 0.0, im: 0.0 };

/// Krylov-Schur for the `nev` eigenvalues of largest modulus of a general complex
/// operator, with full reorthogonalization, locking and validation runs for repeated
/// eigenvalues (see the module docs for the method).
#[derive(Debug, Clone, Copy, Default)]
pub struct KrylovSchurKernel;

impl ComplexKernel for KrylovSchurKernel {
    fn largest(
        &self,
        op: &dyn LinOp<c64>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<ComplexKernelOutput> {
        if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
            return Err(Error::param(
                "tol",
                format!("relative tolerance must be in (0, 1), got {tol}"),
            ));
        }
        let n = op.dim();
        if nev == 0 || n == 0 {
            return Ok(ComplexKernelOutput {
                theta: Vec::new(),
                vectors: Mat::zeros(n, 0),
                iterations: 0,
                all_converged: true,
            });
        }
        if nev >= n {
            return dense_fallback(op, nev);
        }
        let start: Vec<c64> = (0..n)
            .map(|i| {
                let t = i as f64;
                c64::new(1.0 + 0.1 * t.sin(), 0.1 * (0.7 * t).cos())
            })
            .collect();
        let mut ctx = Ctx {
            op,
            tol,
            max_restarts,
            restarts: 0,
            dirs: Directions::new(),
            locked: Vec::new(),
            locked_theta: Vec::new(),
        };

        // First run: the nev largest eigenvalues seen by one Krylov space.
        let first = ctx.run(nev, start, None)?;
        if !first.complete {
            return ctx.finish(nev, false);
        }

        // Validation runs on the deflated operator: anything larger than the nev-th
        // locked modulus (a missed copy of a repeated eigenvalue) is locked too.
        let margin = (10.0 * tol).clamp(1e-10, 1e-4);
        loop {
            if ctx.p() >= n {
                return ctx.finish(nev, true);
            }
            if ctx.restarts >= ctx.max_restarts {
                return ctx.finish(nev, false);
            }
            ctx.restarts += 1;
            let floor = ctx.nth_locked_modulus(nev) * (1.0 + margin);
            let start = complex_random(&mut ctx.dirs, n);
            let check = ctx.run(nev, start, Some(floor))?;
            if check.found == 0 || !check.complete {
                return ctx.finish(nev, check.complete);
            }
        }
    }
}
