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
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::{self, Accum, Mat, MatMut, MatRef, Par, Side};
use squeal_core::linalg::{dot, ShiftInvert};
use squeal_core::{
    ComplexModes, EigenParams, EigenSolver, Error, FrictionalOperator, Params, Qep, RealModes,
    Registry, Result, SymmetricProblem,
};

pub mod schur;
#[cfg(test)]
mod tests;

pub use schur::KrylovSchurKernel;

/// Name under which the solver is registered.
pub const NAME: &str = "krylov";

/// One-line description shown by the registry.
pub const DESCRIPTION: &str = "pure-Rust thick-restart Lanczos (M inner product, full \
                               reorthogonalization) on a sparse Cholesky of K - sigma M; \
                               complex Krylov-Schur for the frictional QEP";

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
    reg.eigen.register(NAME, DESCRIPTION, |_: &Params| {
        let solver: Box<dyn EigenSolver> = Box::new(KrylovSolver);
        Ok(solver)
    });
}

/// The `"krylov"` eigen solver: the shared band driver
/// [`squeal_core::solve_symmetric_band`] around [`LanczosKernel`].
#[derive(Debug, Clone, Copy, Default)]
pub struct KrylovSolver;

impl EigenSolver for KrylovSolver {
    fn name(&self) -> &str {
        NAME
    }

    fn solve_symmetric(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        squeal_core::solve_symmetric_band(NAME, &LanczosKernel, problem, params)
    }

    /// The frictional QEP: the shared complex band driver
    /// [`squeal_core::qep::solve_qep_band`] around [`KrylovSchurKernel`].
    fn solve_qep(&self, qep: &Qep, params: &EigenParams) -> Result<ComplexModes> {
        squeal_core::qep::solve_qep_band(NAME, &KrylovSchurKernel, qep, params)
    }

    /// The frictional operator through [`squeal_core::qep::solve_frictional_band`]: an
    /// undamped operator may take the low-rank (symmetric factorization + Woodbury) path.
    fn solve_frictional(
        &self,
        op: &FrictionalOperator,
        mu: f64,
        params: &EigenParams,
    ) -> Result<ComplexModes> {
        squeal_core::qep::solve_frictional_band(NAME, &KrylovSchurKernel, op, mu, params)
    }
}

/// Thick-restart Lanczos for the largest eigenvalues of `OP = (K - sigma M)^-1 M` in
/// the `M` inner product, with full reorthogonalization, locking and validation runs
/// for repeated eigenvalues (see the crate docs for the method).
#[derive(Debug, Clone, Copy, Default)]
pub struct LanczosKernel;

impl SymmetricKernel for LanczosKernel {
    fn largest(
        &self,
        op: &ShiftInvert<'_>,
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
        let start: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
        largest_from(op, nev, tol, max_restarts, start)
    }
}

/// [`LanczosKernel::largest`] from a given start vector.
fn largest_from(
    op: &ShiftInvert<'_>,
    nev: usize,
    tol: f64,
    max_restarts: usize,
    start: Vec<f64>,
) -> Result<KernelOutput> {
    let n = op.dim();
    let nev = nev.min(n);
    let mut ctx = Ctx {
        op,
        tol,
        max_restarts,
        restarts: 0,
        dirs: Directions::new(),
    };
    if nev == 0 {
        return Ok(Pairs::new(n).into_output(0, true));
    }

    // First run: the nev largest Ritz pairs of one Krylov space.
    let first = ctx.run(&Pairs::new(n), nev, start, None)?;
    let mut found = first.pairs;
    if !first.complete {
        return Ok(found.into_output(ctx.restarts, false));
    }

    // Validation runs in the M-complement of what was found: any eigenvalue larger
    // than the smallest found one (a missed copy of a repeated eigenvalue) is merged.
    let margin = (10.0 * tol).clamp(1e-10, 1e-4);
    loop {
        if found.len() >= n {
            return Ok(found.into_output(ctx.restarts, true));
        }
        if ctx.restarts >= ctx.max_restarts {
            return Ok(found.into_output(ctx.restarts, false));
        }
        ctx.restarts += 1;
        let floor = found.min_theta() * (1.0 + margin);
        let start = ctx.dirs.vector(n);
        let check = ctx.run(&found, nev, start, Some(floor))?;
        let above = check.pairs.filtered(|t| t > floor);
        if above.len() == 0 {
            return Ok(found.into_output(ctx.restarts, check.complete));
        }
        found = Pairs::merged(&found, &above, nev);
        if !check.complete {
            return Ok(found.into_output(ctx.restarts, false));
        }
    }
}

/// Converged eigenpairs of `OP`: values, `M`-orthonormal vectors and `M` times them.
struct Pairs {
    n: usize,
    theta: Vec<f64>,
    x: Vec<f64>,
    mx: Vec<f64>,
}

impl Pairs {
    fn new(n: usize) -> Self {
        Self {
            n,
            theta: Vec::new(),
            x: Vec::new(),
            mx: Vec::new(),
        }
    }

    fn len(&self) -> usize {
        self.theta.len()
    }

    fn push(&mut self, theta: f64, x: &[f64], mx: &[f64]) {
        self.theta.push(theta);
        self.x.extend_from_slice(x);
        self.mx.extend_from_slice(mx);
    }

    fn x(&self, j: usize) -> &[f64] {
        &self.x[j * self.n..(j + 1) * self.n]
    }

    fn mx(&self, j: usize) -> &[f64] {
        &self.mx[j * self.n..(j + 1) * self.n]
    }

    fn x_mat(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.x, self.n, self.len())
    }

    fn mx_mat(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.mx, self.n, self.len())
    }

    fn min_theta(&self) -> f64 {
        self.theta.iter().copied().fold(f64::INFINITY, f64::min)
    }

    fn filtered(&self, keep: impl Fn(f64) -> bool) -> Self {
        let mut out = Self::new(self.n);
        for j in 0..self.len() {
            if keep(self.theta[j]) {
                out.push(self.theta[j], self.x(j), self.mx(j));
            }
        }
        out
    }

    /// The `count` largest pairs of `a` and `b` (mutually `M`-orthogonal sets).
    fn merged(a: &Self, b: &Self, count: usize) -> Self {
        let mut all: Vec<(f64, &Self, usize)> = (0..a.len())
            .map(|j| (a.theta[j], a, j))
            .chain((0..b.len()).map(|j| (b.theta[j], b, j)))
            .collect();
        all.sort_by(|p, q| q.0.total_cmp(&p.0));
        let mut out = Self::new(a.n);
        for &(t, set, j) in all.iter().take(count) {
            out.push(t, set.x(j), set.mx(j));
        }
        out
    }

    fn into_output(self, iterations: usize, all_converged: bool) -> KernelOutput {
        let n = self.n;
        let vectors = Mat::from_fn(n, self.len(), |i, j| self.x[j * n + i]);
        KernelOutput {
            theta: self.theta,
            vectors,
            iterations,
            all_converged,
        }
    }
}

/// The Lanczos basis `V` (`cap` columns) and `M V`, column-major.
struct Basis {
    n: usize,
    v: Vec<f64>,
    mv: Vec<f64>,
}

impl Basis {
    fn new(n: usize, cap: usize) -> Self {
        Self {
            n,
            v: vec![0.0; n * cap],
            mv: vec![0.0; n * cap],
        }
    }

    fn v(&self, cols: usize) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.v[..cols * self.n], self.n, cols)
    }

    fn mv(&self, cols: usize) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.mv[..cols * self.n], self.n, cols)
    }

    fn mv_col(&self, j: usize) -> &[f64] {
        &self.mv[j * self.n..(j + 1) * self.n]
    }

    fn set(&mut self, j: usize, x: &[f64], mx: &[f64]) {
        let n = self.n;
        self.v[j * n..(j + 1) * n].copy_from_slice(x);
        self.mv[j * n..(j + 1) * n].copy_from_slice(mx);
    }

    fn copy_col(&mut self, from: usize, to: usize) {
        let n = self.n;
        self.v.copy_within(from * n..(from + 1) * n, to * n);
        self.mv.copy_within(from * n..(from + 1) * n, to * n);
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

    fn vector(&mut self, n: usize) -> Vec<f64> {
        (0..n)
            .map(|_| (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0)
            .collect()
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

/// `Q Y` for a column-major `n x q` block and a dense `q x c` matrix.
fn times(q: MatRef<'_, f64>, y: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(q.nrows(), y.ncols());
    matmul(
        out.as_mut(),
        Accum::Replace,
        q,
        y,
        1.0,
        par_for(q.nrows() * q.ncols() * y.ncols()),
    );
    out
}

/// One classical Gram-Schmidt pass in the `M` inner product: `c = (M Q)^T w`,
/// `w <- w - Q c`. Adds `c` to `acc` (when given) and returns `||c||^2`.
fn cgs_pass(
    w: &mut [f64],
    q: MatRef<'_, f64>,
    mq: MatRef<'_, f64>,
    acc: Option<&mut [f64]>,
) -> f64 {
    let k = q.ncols();
    if k == 0 {
        return 0.0;
    }
    let n = w.len();
    let par = par_for(n * k);
    let mut c = vec![0.0; k];
    matmul(
        MatMut::from_column_major_slice_mut(&mut c, k, 1),
        Accum::Replace,
        mq.transpose(),
        MatRef::from_column_major_slice(w, n, 1),
        1.0,
        par,
    );
    matmul(
        MatMut::from_column_major_slice_mut(w, n, 1),
        Accum::Add,
        q,
        MatRef::from_column_major_slice(&c, k, 1),
        -1.0,
        par,
    );
    if let Some(acc) = acc {
        acc.iter_mut().zip(&c).for_each(|(a, ci)| *a += ci);
    }
    dot(&c, &c)
}

/// State shared by the runs of one [`LanczosKernel::largest`] call.
struct Ctx<'o, 'a> {
    op: &'o ShiftInvert<'a>,
    tol: f64,
    max_restarts: usize,
    restarts: usize,
    dirs: Directions,
}

/// Result of one run: converged wanted pairs, and whether all wanted ones converged.
struct RunOut {
    pairs: Pairs,
    complete: bool,
}

/// Rayleigh-Ritz analysis of the current projected matrix.
struct Ritz {
    /// Ritz values, ascending.
    theta: Vec<f64>,
    /// Eigenvectors of `T` (columns).
    y: Mat<f64>,
    /// Indices of the wanted pairs, largest first.
    wanted: Vec<usize>,
    /// Convergence flag of each pair.
    converged: Vec<bool>,
    /// The basis is too small to hold every wanted pair.
    short: bool,
}

impl Ritz {
    /// Every wanted pair present and converged.
    fn done(&self) -> bool {
        !self.short && self.all_converged()
    }

    /// Every wanted pair the basis holds is converged.
    fn all_converged(&self) -> bool {
        self.wanted.iter().all(|&i| self.converged[i])
    }
}

impl Ctx<'_, '_> {
    /// Orthogonalizes `w` in the `M` inner product against the locked pairs and the
    /// first `nb` basis vectors (`passes` classical Gram-Schmidt passes). Returns the
    /// basis coefficients summed over the passes and `||c||^2` of the first pass.
    fn orthogonalize(
        &self,
        w: &mut [f64],
        locked: &Pairs,
        basis: &Basis,
        nb: usize,
        passes: usize,
    ) -> (Vec<f64>, f64) {
        let mut h = vec![0.0; nb];
        let mut first = 0.0;
        for pass in 0..passes {
            let removed = cgs_pass(w, locked.x_mat(), locked.mx_mat(), None)
                + cgs_pass(w, basis.v(nb), basis.mv(nb), Some(&mut h));
            if pass == 0 {
                first = removed;
            }
        }
        (h, first)
    }

    /// `M`-norm of `w`, leaving `M w` in `mw`.
    fn m_norm(&self, w: &[f64], mw: &mut [f64]) -> f64 {
        self.op.m_mul(w, mw);
        dot(w, mw).max(0.0).sqrt()
    }

    /// Makes `x` a unit vector `M`-orthogonal to the locked pairs and the first `nb`
    /// basis vectors; on collapse, tries fresh pseudo-random vectors. `None` when the
    /// complement is numerically exhausted.
    fn new_direction(
        &mut self,
        mut x: Vec<f64>,
        locked: &Pairs,
        basis: &Basis,
        nb: usize,
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        let n = x.len();
        let mut mx = vec![0.0; n];
        for _ in 0..NEW_DIRECTION_TRIES {
            let before = self.m_norm(&x, &mut mx);
            if before > 0.0 && before.is_finite() {
                self.orthogonalize(&mut x, locked, basis, nb, 3);
                let after = self.m_norm(&x, &mut mx);
                if after > NEW_DIRECTION_MIN * before {
                    x.iter_mut().for_each(|v| *v /= after);
                    mx.iter_mut().for_each(|v| *v /= after);
                    return Some((x, mx));
                }
            }
            x = self.dirs.vector(n);
        }
        None
    }

    /// Rayleigh-Ritz on the leading `m x m` block of `t` with residual norm `beta`.
    fn ritz(
        &self,
        t: &Mat<f64>,
        m: usize,
        beta: f64,
        want: usize,
        floor: Option<f64>,
    ) -> Result<Ritz> {
        let eig = t
            .get(..m, ..m)
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| Error::Invalid(format!("krylov: projected eigenproblem: {e:?}")))?;
        let s = eig.S();
        let theta: Vec<f64> = (0..m).map(|i| s[i]).collect();
        let y = eig.U().to_owned();
        let converged: Vec<bool> = (0..m)
            .map(|i| (beta * y[(m - 1, i)]).abs() <= self.tol * theta[i].abs())
            .collect();
        // Without a floor: the `want` largest. With one (validation): every Ritz value
        // above the floor plus the next one, which must converge below the floor.
        let count = match floor {
            None => want,
            Some(f) => (theta.iter().filter(|&&t| t > f).count() + 1).min(want),
        };
        let wanted = (0..count.min(m)).map(|r| m - 1 - r).collect();
        Ok(Ritz {
            theta,
            y,
            wanted,
            converged,
            short: count > m,
        })
    }

    /// The converged wanted Ritz pairs of an `m`-vector basis.
    fn converged_pairs(&self, basis: &Basis, m: usize, ritz: &Ritz) -> Pairs {
        let n = self.op.dim();
        let sel: Vec<usize> = ritz
            .wanted
            .iter()
            .copied()
            .filter(|&i| ritz.converged[i])
            .collect();
        let ysel = Mat::from_fn(m, sel.len(), |i, c| ritz.y[(i, sel[c])]);
        let x = times(basis.v(m), ysel.as_ref());
        let mx = times(basis.mv(m), ysel.as_ref());
        let mut out = Pairs::new(n);
        for (c, &i) in sel.iter().enumerate() {
            out.push(ritz.theta[i], x.col_as_slice(c), mx.col_as_slice(c));
        }
        out
    }

    /// One thick-restart Lanczos run for the `want` largest eigenpairs of `OP` restricted
    /// to the `M`-complement of `locked`, from `start`. With a `floor`, the run only has
    /// to find the pairs above it (and prove the next one lies below).
    fn run(
        &mut self,
        locked: &Pairs,
        want: usize,
        start: Vec<f64>,
        floor: Option<f64>,
    ) -> Result<RunOut> {
        let op = self.op;
        let n = op.dim();
        let dim = n.saturating_sub(locked.len());
        let want = want.min(dim);
        let empty = RunOut {
            pairs: Pairs::new(n),
            complete: true,
        };
        if want == 0 {
            return Ok(empty);
        }
        let ncv = dim.min((2 * want + 1).max(want + 20));
        let keep = (want + (ncv - want) / 2).min(ncv - 1).max(1);
        let mut basis = Basis::new(n, ncv + 1);
        let mut t = Mat::<f64>::zeros(ncv, ncv);
        match self.new_direction(start, locked, &basis, 0) {
            Some((v, mv)) => basis.set(0, &v, &mv),
            None => return Ok(empty),
        }
        let mut k = 0;
        let mut w = vec![0.0; n];
        let mut mw = vec![0.0; n];
        loop {
            // Expand the basis from k to ncv vectors (or to an exhausted complement).
            let mut beta = 0.0;
            let mut ritz = None;
            for j in k..ncv {
                op.apply_with_mx(basis.mv_col(j), &mut w);
                let (mut h, first) = self.orthogonalize(&mut w, locked, &basis, j + 1, 2);
                let mut b = self.m_norm(&w, &mut mw);
                let norm0 = (first + b * b).sqrt();
                if b < THIRD_PASS * norm0 && b > BREAKDOWN * norm0 {
                    let (h3, _) = self.orthogonalize(&mut w, locked, &basis, j + 1, 1);
                    h.iter_mut().zip(&h3).for_each(|(a, c)| *a += c);
                    b = self.m_norm(&w, &mut mw);
                }
                if !(b.is_finite() && h[j].is_finite()) {
                    return Err(Error::Invalid(format!(
                        "krylov: non-finite Lanczos coefficient at step {j} (alpha = {}, \
                         beta = {b}): the factorization of K - sigma M is unusable",
                        h[j]
                    )));
                }
                t[(j, j)] = h[j];
                let mut exhausted = false;
                let broke = b <= BREAKDOWN * norm0;
                if !broke {
                    w.iter_mut().for_each(|v| *v /= b);
                    mw.iter_mut().for_each(|v| *v /= b);
                    basis.set(j + 1, &w, &mw);
                    beta = b;
                } else {
                    // Invariant subspace: continue with a new direction, coupling 0.
                    beta = 0.0;
                    b = 0.0;
                    let fresh = self.dirs.vector(n);
                    match self.new_direction(fresh, locked, &basis, j + 1) {
                        Some((v, mv)) => basis.set(j + 1, &v, &mv),
                        None => exhausted = true,
                    }
                }
                if j + 1 < ncv {
                    t[(j + 1, j)] = b;
                    t[(j, j + 1)] = b;
                }
                // Early checks skip breakdown steps: an invariant subspace has exact Ritz
                // pairs that need not be the largest; the new direction may show more.
                let size = j + 1;
                if exhausted || size == ncv || (!broke && (size - k) % CHECK_EVERY == 0) {
                    let r = self.ritz(&t, size, beta, want, floor)?;
                    if r.done() || exhausted {
                        // Exhausted: the basis spans the whole complement, nothing is missing.
                        let complete = r.all_converged();
                        return Ok(RunOut {
                            pairs: self.converged_pairs(&basis, size, &r),
                            complete,
                        });
                    }
                    if size == ncv {
                        ritz = Some(r);
                    }
                }
            }
            let m = ncv;
            let ritz = match ritz {
                Some(r) => r,
                None => self.ritz(&t, m, beta, want, floor)?,
            };
            if self.restarts >= self.max_restarts {
                return Ok(RunOut {
                    pairs: self.converged_pairs(&basis, m, &ritz),
                    complete: false,
                });
            }
            self.restarts += 1;

            // Thick restart: keep the `keep` largest Ritz pairs and the residual vector.
            k = keep.min(m - 1);
            let idx: Vec<usize> = (0..k).map(|r| m - 1 - r).collect();
            let yk = Mat::from_fn(m, k, |i, c| ritz.y[(i, idx[c])]);
            let v_new = times(basis.v(m), yk.as_ref());
            let mv_new = times(basis.mv(m), yk.as_ref());
            basis.copy_col(m, k);
            for c in 0..k {
                basis.set(c, v_new.col_as_slice(c), mv_new.col_as_slice(c));
            }
            t.fill(0.0);
            for (c, &i) in idx.iter().enumerate() {
                let b = beta * ritz.y[(m - 1, i)];
                t[(c, c)] = ritz.theta[i];
                t[(k, c)] = b;
                t[(c, k)] = b;
            }
        }
    }
}
