//! # squeal-eigen-krylov
//!
//! A pure-Rust symmetric eigen backend: thick-restart Lanczos (Wu & Simon 2000), which
//! for symmetric operators is the same method as Stewart's Krylov-Schur (2001), run on
//! the shift-invert operator of the normal-mode problem. Registered as `"krylov"`.
//!
//! The frictional (non-symmetric, quadratic) problem goes through the complex kernel
//! [`KrylovSchurKernel`] (module [`schur`]: Krylov-Schur in complex arithmetic with
//! locking and validation runs for repeated eigenvalues), run by the shared band driver
//! [`squeal_core::qep::solve_qep_band`] on the companion-form shift-invert operator.
//!
//! ## Spectral transformation
//!
//! Normal modes solve `K x = lambda M x` (`lambda = omega^2`). With a shift `sigma`
//! below the spectrum, `K - sigma M` is positive definite and is factorized once
//! (sparse Cholesky, [`ShiftInvert`]). The operator
//!
//! ```text
//! OP = (K - sigma M)^-1 M,        OP x = theta x  <=>  K x = lambda M x,
//! theta = 1 / (lambda - sigma)
//! ```
//!
//! is self-adjoint in the `M` inner product `<x, y>_M = x^T M y`
//! (`<x, OP y>_M = x^T M (K - sigma M)^-1 M y` is symmetric in `x, y`), positive
//! definite, and its *largest* eigenvalues `theta` are the `lambda` nearest `sigma`, i.e.
//! the lowest modes (Ericsson & Ruhe 1980). The band driver
//! [`squeal_core::solve_symmetric_band`] does the transformation back.
//!
//! ## Lanczos in the `M` inner product
//!
//! After `m` steps the method holds an `M`-orthonormal basis `V_m` (`V_m^T M V_m = I`),
//! a symmetric `m x m` matrix `T_m` and a residual `f = beta v_{m+1}` with
//!
//! ```text
//! OP V_m = V_m T_m + beta v_{m+1} e_m^T,        V_m^T M v_{m+1} = 0.
//! ```
//!
//! For every eigenpair `T_m y = theta y` (`||y|| = 1`) the Ritz vector `x = V_m y`
//! satisfies `||OP x - theta x||_M = |beta y_m|` exactly, so the pair is accepted when
//!
//! ```text
//! |beta y_{m,i}| <= tol |theta_i|.
//! ```
//!
//! Each step costs one sparse triangular solve pair (`OP v_j` from the stored `M v_j`),
//! one product by `M` (for the new `M`-norm) and the orthogonalization. The products
//! `M v_j` are stored next to the basis, so every `M` inner product is a plain dot
//! product: memory `2 n (ncv + 1)` for the basis plus `2 n nev` for converged pairs.
//!
//! **Full reorthogonalization.** Every new vector is orthogonalized against *all* basis
//! vectors (and all locked vectors, below) by classical Gram-Schmidt applied twice in the
//! `M` inner product (Daniel, Gragg, Kaufman & Stewart 1976, "twice is enough"), a third
//! pass being added when less than `1e-6` of the vector's `M`-norm survives. Only the
//! diagonal coefficient `alpha_j` and the norm `beta_j` enter `T`; the other
//! coefficients are rounding-level corrections. Semi-orthogonality is therefore never
//! lost and no spurious copies of converged eigenvalues appear.
//!
//! ## Thick restart
//!
//! The subspace holds `ncv = min(n, max(2 nev + 1, nev + 20))` vectors. When it is full
//! and the wanted pairs have not converged, the `k = nev + (ncv - nev) / 2` largest Ritz
//! pairs are kept: `V_k <- V_m Y_k`, `v_{k+1} <- v_{m+1}`, and `T` becomes the arrowhead
//!
//! ```text
//! T_{k+1} = [ diag(theta_1..theta_k)   b   ]      b_i = beta y_{m,i},
//!           [          b^T           alpha ]
//! ```
//!
//! after which the three-term Lanczos recurrence resumes (Wu & Simon 2000, sec. 2;
//! Stewart 2001 shows the equivalence with Krylov-Schur restarting). The projected
//! matrix is stored densely and diagonalized by faer (`self_adjoint_eigen`).
//!
//! ## Breakdown and repeated eigenvalues
//!
//! If the new residual collapses (`beta_j <= 1e-12 ||OP v_j||_M`), the basis spans an
//! invariant subspace: the coupling is set to zero and the iteration continues with a
//! new deterministic pseudo-random vector `M`-orthogonalized against everything held.
//!
//! In exact arithmetic the Krylov space of one start vector contains a single direction
//! of every eigenspace, so one copy of a repeated eigenvalue (the doublets of a disc) is
//! invisible to it, however long it runs. After the first run has converged the `nev`
//! largest Ritz pairs, they are *locked* (kept aside and deflated by orthogonalizing every
//! new vector against them) and a *validation run* is started from a fresh vector in
//! their `M`-orthogonal complement. It stops as soon as its largest converged Ritz value
//! lies below the smallest locked one (nothing was missed, usually within the first
//! basis); otherwise the newly found pairs are merged, the `nev` largest are kept, and
//! the validation is repeated. Each validation round exposes one more copy, so every
//! multiplicity is resolved (compare the block methods of Grimes, Lewis & Simon 1994).
//!
//! ## Budget and output
//!
//! `max_restarts` caps the number of restarts summed over all runs of one call, the start
//! of each validation run counting as one restart; `iterations` reports that sum. When
//! the cap is hit, only the pairs that passed the convergence test are returned and
//! `all_converged` is `false`. All start vectors are deterministic (`1 + 0.1 sin i` for
//! the first run, a fixed SplitMix64 sequence afterwards), so results are reproducible.
//!
//! ## References
//!
//! - K. Wu, H. Simon, *Thick-restart Lanczos method for large symmetric eigenvalue
//!   problems*, SIAM J. Matrix Anal. Appl. 22(2), 602-616, 2000.
//! - G. W. Stewart, *A Krylov-Schur algorithm for large eigenproblems*, SIAM J. Matrix
//!   Anal. Appl. 23(3), 601-614, 2001.
//! - T. Ericsson, A. Ruhe, *The spectral transformation Lanczos method for the numerical
//!   solution of large sparse generalized symmetric eigenvalue problems*, Math. Comp. 35,
//!   1251-1268, 1980.
//! - J. W. Daniel, W. B. Gragg, L. Kaufman, G. W. Stewart, *Reorthogonalization and
//!   stable algorithms for updating the Gram-Schmidt QR factorization*, Math. Comp. 30,
//!   772-795, 1976.
//! - R. G. Grimes, J. G. Lewis, H. D. Simon, *A shifted block Lanczos algorithm for
//!   solving sparse symmetric generalized eigenproblems*, SIAM J. Matrix Anal. Appl.
//!   15(1), 228-272, 1994.
//! - B. N. Parlett, *The Symmetric Eigenvalue Problem*, SIAM, 1998.

use squeal_core::eigen::{KernelOutput, SymmetricKernel};
use squeal_core::faer::{self, MatRef, Par};
use squeal_core::spectral::{LinOp, ShiftInvert};
use squeal_core::{EigenSolver, Error, KernelSolver, Params, Registry, Result};

mod block;
mod lanczos;
mod pairs;
pub mod schur;
#[cfg(test)]
mod tests;

use lanczos::largest_from;
#[cfg(test)]
use lanczos::Ctx;
#[cfg(test)]
use pairs::Pairs;
pub use schur::KrylovSchurKernel;

/// Name under which the solver is registered.
pub const NAME: &str = "krylov";

/// One-line description shown by the registry.
pub const DESCRIPTION: &str = "pure-Rust block thick-restart Lanczos (M inner product, \
                               full reorthogonalization; option block, default 8) on a \
                               sparse Cholesky of K - sigma M; complex Krylov-Schur for \
                               the frictional QEP";

/// A residual below this fraction of `||OP v_j||_M` is a breakdown (invariant subspace).
const BREAKDOWN: f64 = 1e-12;
/// Below this fraction the residual gets a third Gram-Schmidt pass.
const THIRD_PASS: f64 = 1e-6;
/// A new direction is accepted if this fraction of its `M`-norm survives orthogonalization.
const NEW_DIRECTION_MIN: f64 = 1e-8;
/// Attempts at a new direction before the complement is declared exhausted.
const NEW_DIRECTION_TRIES: usize = 4;
/// Convergence is also checked every that many expansion steps (cheap early exits).
const CHECK_EVERY: usize = 8;
/// Products with fewer entries than this run sequentially.
const PAR_THRESHOLD: usize = 1 << 16;

/// Registers the `"krylov"` eigen solver.
pub fn register(reg: &mut Registry) {
    reg.eigen.register(NAME, DESCRIPTION, |p: &Params| {
        let p = p.tracked();
        let block = p.usize_or("block", DEFAULT_BLOCK)?;
        if block == 0 {
            return Err(Error::param(
                "block",
                "the block size of the normal-mode Lanczos must be >= 1 (1: single vector)",
            ));
        }
        p.refuse_unread("eigen", NAME)?;
        let solver: Box<dyn EigenSolver> = Box::new(KrylovSolver::new(
            NAME,
            LanczosKernel { block },
            KrylovSchurKernel,
        ));
        Ok(solver)
    });
}

/// The `"krylov"` eigen solver: the shared band drivers around [`LanczosKernel`] (normal
/// modes) and [`KrylovSchurKernel`] (complex modes of the QEP).
pub type KrylovSolver = KernelSolver<LanczosKernel, KrylovSchurKernel>;

/// The `"krylov"` solver with its default block size.
pub const KRYLOV: KrylovSolver = KernelSolver::new(
    NAME,
    LanczosKernel {
        block: DEFAULT_BLOCK,
    },
    KrylovSchurKernel,
);

/// Most pairs one call of the block kernel is asked for; larger calls take the
/// single-vector kernel. Measured with blocks of 8 and a basis of four times the wanted
/// pairs: the tied rig's real modes (24 pairs) and the default rig's free model (69 pairs,
/// 26.8 s against 56 s in the single-vector kernel) converge to `tol = 1e-10` in one
/// restart at most, and so do the coarse rig's free model's 96 pairs, whose smallest
/// wanted theta lie in clusters of relative width 1e-3 at the end of the wanted range.
/// Above this the basis (`2 n` values per column, about 1.1 GB at 96 pairs on the
/// default rig) outgrows the single-vector kernel's.
pub const BLOCK_MAX_NEV: usize = 96;

/// Default of the `block` parameter: columns per application of `OP` in the normal-mode
/// Lanczos.
pub const DEFAULT_BLOCK: usize = 8;

/// Thick-restart Lanczos for the largest eigenvalues of `OP = (K - sigma M)^-1 M` in
/// the `M` inner product with full reorthogonalization (see the crate docs for the
/// method): with `block = 1` one vector at a time, with locking and validation runs for
/// repeated eigenvalues; with `block > 1` on blocks of that many columns (module
/// `block`), which holds up to `block` copies of a repeated eigenvalue and reads the
/// factor of `K - sigma M` once per block. Problems too small for the block basis, and
/// calls for more than [`BLOCK_MAX_NEV`] pairs, take the single-vector path; so does a
/// block run that makes no progress for `block::STALL_RESTARTS` restarts in a row (the
/// single-vector kernel then starts afresh with the restarts left).
#[derive(Debug, Clone, Copy)]
pub struct LanczosKernel {
    /// Columns per application of `OP` (1: single-vector Lanczos).
    pub block: usize,
}

impl LanczosKernel {
    /// The single-vector kernel.
    pub const SINGLE: Self = Self { block: 1 };
}

impl SymmetricKernel for LanczosKernel {
    fn largest(
        &self,
        op: &ShiftInvert<'_>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<KernelOutput> {
        self.run(op, None, nev, tol, max_restarts)
    }

    /// The block path starts from `block` pseudo-random combinations of the `start`
    /// columns (the columns themselves when there are no more than `block`): a start
    /// near an invariant subspace of dimension `s` spans it again after about `s / block`
    /// blocks, and the later blocks refine it. Measured on the default rig's tied system
    /// (24 pairs, blocks of 8, the previous contact set's modes as the start): 16 blocks
    /// and no restart instead of 19-20 and one. Blocks as wide as the start (24) took 10
    /// blocks of 24 and two restarts: the Krylov degree, which refines, grows once per
    /// block.
    fn largest_from(
        &self,
        op: &ShiftInvert<'_>,
        start: MatRef<'_, f64>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<KernelOutput> {
        self.run(op, Some(start), nev, tol, max_restarts)
    }
}

impl LanczosKernel {
    /// [`SymmetricKernel::largest_from`], or from pseudo-random columns without `start`.
    fn run(
        &self,
        op: &ShiftInvert<'_>,
        start: Option<MatRef<'_, f64>>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<KernelOutput> {
        let n = op.dim();
        if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
            return Err(Error::param(
                "tol",
                format!("relative tolerance must be in (0, 1), got {tol}"),
            ));
        }
        let bs = self.block;
        let mixed = start.filter(|s| s.nrows() == n && s.ncols() > 0).map(|s| {
            if s.ncols() <= bs {
                s.to_owned()
            } else {
                let mut d = Directions::new();
                let omega = faer::Mat::from_fn(s.ncols(), bs, |_, _| d.unit());
                s * omega
            }
        });
        let mut spent = 0;
        if bs > 1 && nev <= BLOCK_MAX_NEV && block::fits(n, nev, bs) {
            match block::largest_block(
                op,
                nev,
                tol,
                max_restarts,
                bs,
                mixed.as_ref().map(|m| m.as_ref()),
            )? {
                block::BlockOutcome::Done(out) => return Ok(out),
                // the single-vector kernel takes over with the restarts left
                block::BlockOutcome::Stalled { restarts } => spent = restarts,
            }
        }
        // the single-vector kernel starts from one combination of `start`'s columns
        let start: Vec<f64> = match &mixed {
            Some(m) => m.col(0).iter().copied().collect(),
            None => (0..n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect(),
        };
        let mut out = largest_from(op, nev, tol, max_restarts.saturating_sub(spent), start)?;
        out.iterations += spent;
        Ok(out)
    }
}

/// Deterministic pseudo-random directions (SplitMix64), uniform in `[-1, 1)`.
struct Directions {
    state: u64,
}

impl Directions {
    fn new() -> Self {
        Self {
            state: 0x5EA1_5EA1_2024_0001,
        }
    }

    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// One value.
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    fn vector(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.unit()).collect()
    }
}

/// `Par::Seq` for small products, faer's global setting otherwise.
fn par_for(size: usize) -> Par {
    if size < PAR_THRESHOLD {
        Par::Seq
    } else {
        faer::get_global_parallelism()
    }
}
