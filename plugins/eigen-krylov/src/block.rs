//! Block thick-restart Lanczos in the `M` inner product (Krylov-Schur form), for the
//! largest eigenvalues of `OP = (K - sigma M)^-1 M`.
//!
//! The single-vector kernel ([`super::lanczos`]) applies `OP` one column at a time: each
//! application reads the whole sparse Cholesky factor, so on a solid model of 10^5 DOFs
//! and more its cost is the memory traffic of the factor, not the arithmetic. A block of
//! `b` columns reads the factor once for all of them, so the same Krylov dimension costs
//! several times less; the block also holds up to `b` copies of a repeated eigenvalue
//! (the doublets of a disc) without validation runs.
//!
//! ## Method
//!
//! The basis `V_m` (`M`-orthonormal, blocks of `b` columns, `M V_m` stored next to it)
//! satisfies the Krylov decomposition
//!
//! ```text
//! OP V_m = V_m H_m + Q R E^T,     V_m^T M Q = 0,  Q^T M Q = I,
//! ```
//!
//! with `H_m = V_m^T M OP V_m` symmetric and `E` selecting the last block. Expanding the
//! last block `V_l`: `W = OP V_l`, two classical Gram-Schmidt passes against all of `V_m`
//! in the `M` inner product (the coefficients fill column block `l` of `H`, mirrored into
//! its row block), then a Gram-Schmidt QR of the remainder in the `M` inner product gives
//! the next block `Q` and `R` (a column that loses all but `1e-12` of its `M` norm is
//! replaced by a fresh direction with `R_jj = 0`: the space is invariant there).
//! For a Ritz pair `H_m y = theta y`, `||y|| = 1`, the Ritz vector `x = V_m y` has
//! `||OP x - theta x||_M = ||R y_l||` exactly (`y_l`: the rows of `y` on the last block), so
//! the pair is accepted when `||R y_l|| <= tol |theta|`, the test of the single-vector
//! kernel. When the basis is full and the `nev` largest have not all converged, the
//! `k = nev + (cap - nev) / 2` largest Ritz pairs are kept (`V_k <- V_m Y_k`,
//! `H <- diag(theta_k)`), `Q` becomes the next block, and the coupling `R Y_k,l` between
//! them is recovered by the next expansion's Gram-Schmidt coefficients (Stewart 2001).
//!
//! ## Locking and purification
//!
//! The relation above holds only to the accuracy of the block solves (about
//! `cond(K - sigma M) eps theta_max`), which can exceed the tolerance asked of the
//! smallest wanted `theta`. Two steps keep the solves' error out of the results:
//! - at a restart, the kept Ritz vectors that passed the test are *locked*: their coupling
//!   to the following blocks is held at zero (recomputed, it is the solves' error, which
//!   would undo their convergence at every restart);
//! - at the end, each returned pair's residual `OP x - theta x` is computed explicitly;
//!   when one exceeds the tolerance, one Rayleigh-Ritz step on `span [X, R]` with
//!   `K - sigma M` and `M` themselves (not the Krylov relation) refines the pairs, each
//!   input pair taking the Ritz vector that overlaps it most. Residuals within the
//!   tolerance (or at rounding level) add no direction: in a multiple eigenvalue their
//!   noise would bring in unconverged copies.
//!
//! Start block: deterministic pseudo-random columns, so results are reproducible, or the
//! columns of a given start (approximate wanted vectors of a nearby problem) completed by
//! such columns.

use super::{par_for, Directions, BREAKDOWN};
use squeal_core::eigen::{dense_symmetric_pencil, KernelOutput};
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::linalg::triangular_solve::solve_upper_triangular_in_place;
use squeal_core::faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use squeal_core::linalg::{dot, symmetric_times};
use squeal_core::spectral::{LinOp, ShiftInvert};
use squeal_core::{Error, Result};

/// `C (+)= A^T B` for dense blocks.
fn tmul_into(c: MatMut<'_, f64>, accum: Accum, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    let par = par_for(a.nrows() * a.ncols() * b.ncols());
    matmul(c, accum, a.transpose(), b, 1.0, par);
}

/// `Y -= A B` for dense blocks.
fn sub_mul(y: MatMut<'_, f64>, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    if a.ncols() > 0 {
        let par = par_for(a.nrows() * a.ncols() * b.ncols());
        matmul(y, Accum::Add, a, b, -1.0, par);
    }
}

/// `A B` for dense blocks.
fn times(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(a.nrows(), b.ncols());
    let par = par_for(a.nrows() * a.ncols() * b.ncols());
    matmul(out.as_mut(), Accum::Replace, a, b, 1.0, par);
    out
}

/// `M X` ([`symmetric_times`]).
fn m_times(op: &ShiftInvert<'_>, x: MatRef<'_, f64>) -> Mat<f64> {
    symmetric_times(op.m(), x)
}

/// Largest `M` inner product of a normalized new block with a held column that counts as
/// rounding; above it the block is orthogonalized and factorized again.
const REORTHOGONALIZE_ABOVE: f64 = 1e-14;

/// Smallest `R_jj` of a Cholesky QR, relative to the column's norm before the
/// orthogonalization, that the block path accepts: below it the Gram matrix has lost too
/// many digits and the block goes through modified Gram-Schmidt.
const CHOL_QR_MIN: f64 = 1e-6;

/// One Cholesky QR in the `M` inner product: `G = W^T M W = R^T R`, `Q = W R^-1`,
/// `M Q = (M W) R^-1`. `None` when the Cholesky fails or a diagonal `R_jj` is below
/// [`CHOL_QR_MIN`] of the column's norm before orthogonalization (`sqrt(removed_j + G_jj)`).
fn chol_qr(w: &Mat<f64>, mw: &Mat<f64>, removed: &[f64]) -> Option<(Mat<f64>, Mat<f64>, Mat<f64>)> {
    let b = w.ncols();
    let mut g = Mat::<f64>::zeros(b, b);
    tmul_into(g.as_mut(), Accum::Replace, w.as_ref(), mw.as_ref());
    let g = Mat::from_fn(b, b, |i, j| 0.5 * (g[(i, j)] + g[(j, i)]));
    let llt = g.llt(Side::Lower).ok()?;
    let r = llt.L().transpose().to_owned();
    for j in 0..b {
        let before = (removed[j] + g[(j, j)]).max(0.0).sqrt();
        if r[(j, j)].is_nan() || r[(j, j)] <= CHOL_QR_MIN * before {
            return None;
        }
    }
    let mut rinv = Mat::<f64>::identity(b, b);
    solve_upper_triangular_in_place(r.as_ref(), rinv.as_mut(), Par::Seq);
    Some((
        times(w.as_ref(), rinv.as_ref()),
        times(mw.as_ref(), rinv.as_ref()),
        r,
    ))
}

/// The basis, `M` times it and the projected matrix of one call.
struct State<'o, 'a> {
    op: &'o ShiftInvert<'a>,
    v: Mat<f64>,
    mv: Mat<f64>,
    h: Mat<f64>,
    /// Columns held.
    m: usize,
    dirs: Directions,
}

impl State<'_, '_> {
    /// Two classical Gram-Schmidt passes of the block `w` against the `m` held columns in
    /// the `M` inner product; returns the summed coefficients (`m x b`).
    fn orthogonalize(&self, w: &mut Mat<f64>) -> Mat<f64> {
        let (m, b) = (self.m, w.ncols());
        let mut coef = Mat::<f64>::zeros(m, b);
        if m == 0 {
            return coef;
        }
        for _ in 0..2 {
            let c = self.coefficients(w.as_ref());
            sub_mul(w.as_mut(), self.v.as_ref().subcols(0, m), c.as_ref());
            coef += &c;
        }
        coef
    }

    /// The `M` inner products `(M V)^T W` of a block with the `m` held columns (`m x b`).
    fn coefficients(&self, w: MatRef<'_, f64>) -> Mat<f64> {
        let mut c = Mat::<f64>::zeros(self.m, w.ncols());
        if self.m > 0 {
            tmul_into(
                c.as_mut(),
                Accum::Replace,
                self.mv.as_ref().subcols(0, self.m),
                w,
            );
        }
        c
    }

    /// `M`-orthonormal QR of the block `w` (already `M`-orthogonal to the held columns):
    /// `w = Q R`. `removed[j]` is the squared `M` norm the Gram-Schmidt passes against the
    /// held columns took from column `j`; a column left with less than [`BREAKDOWN`] of
    /// its norm before them is replaced by a fresh direction (orthogonal to the held
    /// columns and to `Q`) with a zero row of `R`. Returns `(Q, M Q, R)`.
    fn block_qr(&mut self, w: Mat<f64>, removed: &[f64]) -> (Mat<f64>, Mat<f64>, Mat<f64>) {
        let mw = m_times(self.op, w.as_ref());
        if let Some((q1, mq1, r1)) = chol_qr(&w, &mw, removed) {
            // the second pass restores the orthogonality the first lost to the Gram matrix
            if let Some((q, _, r2)) = chol_qr(&q1, &mq1, &vec![0.0; q1.ncols()]) {
                // the stored images exact, not carried through the passes
                let mq = m_times(self.op, q.as_ref());
                return (q, mq, times(r2.as_ref(), r1.as_ref()));
            }
        }
        self.mgs_qr(w, mw, removed)
    }

    /// [`Self::block_qr`] column by column (modified Gram-Schmidt, two passes), the path
    /// of a block whose Cholesky QR fails or loses accuracy.
    fn mgs_qr(
        &mut self,
        w: Mat<f64>,
        mw: Mat<f64>,
        removed: &[f64],
    ) -> (Mat<f64>, Mat<f64>, Mat<f64>) {
        let (n, b) = (w.nrows(), w.ncols());
        let col = |x: &Mat<f64>, j: usize| x.col(j).try_as_col_major().unwrap().as_slice().to_vec();
        let mut qs: Vec<Vec<f64>> = Vec::with_capacity(b);
        let mut mqs: Vec<Vec<f64>> = Vec::with_capacity(b);
        let mut r = Mat::<f64>::zeros(b, b);
        // two passes against the columns of Q already made, M images carried
        let passes = |x: &mut [f64], mx: &mut [f64], qs: &[Vec<f64>], mqs: &[Vec<f64>]| {
            let mut coef = vec![0.0; qs.len()];
            for _ in 0..2 {
                for (i, (q, mq)) in qs.iter().zip(mqs).enumerate() {
                    let c = dot(mq, x);
                    coef[i] += c;
                    x.iter_mut().zip(q).for_each(|(a, qi)| *a -= c * qi);
                    mx.iter_mut().zip(mq).for_each(|(a, qi)| *a -= c * qi);
                }
            }
            coef
        };
        for j in 0..b {
            let (mut x, mut mx) = (col(&w, j), col(&mw, j));
            let before = (removed[j] + dot(&x, &mx)).max(0.0).sqrt();
            let coef = passes(&mut x, &mut mx, &qs, &mqs);
            let norm = dot(&x, &mx).max(0.0).sqrt();
            if norm > BREAKDOWN * before && norm.is_finite() {
                for (i, c) in coef.into_iter().enumerate() {
                    r[(i, j)] = c;
                }
                r[(j, j)] = norm;
            } else {
                // invariant subspace: a fresh direction, orthogonal to everything held,
                // with a zero column of R (the block's column j lies in the span of Q)
                for (i, c) in coef.into_iter().enumerate() {
                    r[(i, j)] = c;
                }
                let mut f = Mat::from_fn(n, 1, |_, _| 0.0);
                let dir = self.dirs.vector(n);
                f.col_mut(0).iter_mut().zip(dir).for_each(|(a, d)| *a = d);
                self.orthogonalize(&mut f);
                x = col(&f, 0);
                mx = col(&m_times(self.op, f.as_ref()), 0);
                passes(&mut x, &mut mx, &qs, &mqs);
            }
            let norm = dot(&x, &mx).max(0.0).sqrt();
            x.iter_mut().for_each(|a| *a /= norm);
            mx.iter_mut().for_each(|a| *a /= norm);
            qs.push(x);
            mqs.push(mx);
        }
        let q = Mat::from_fn(n, b, |row, j| qs[j][row]);
        // the stored images exact, not carried through the passes
        let mq = m_times(self.op, q.as_ref());
        (q, mq, r)
    }

    /// The next block from `W = OP V_l`: `W = V C + Q R` with `Q` `M`-orthonormal and
    /// `M`-orthogonal to the held columns. Gram-Schmidt against them (two passes), a QR of
    /// the remainder, then one more pass of the normalized block against them: a remainder
    /// much shorter than `W` carries the rounding of the passes, which its normalization
    /// magnifies (block Gram-Schmidt twice, Barlow & Smoktunowicz 2013); when that pass
    /// finds more than rounding, the block is corrected and factorized again. Returns
    /// `(Q, M Q, R, C)`.
    fn remainder(&mut self, mut w: Mat<f64>) -> (Mat<f64>, Mat<f64>, Mat<f64>, Mat<f64>) {
        let mut coef = self.orthogonalize(&mut w);
        // the M norm the passes removed (the held columns are M-orthonormal)
        let removed: Vec<f64> = (0..w.ncols())
            .map(|j| coef.col(j).iter().map(|c| c * c).sum())
            .collect();
        let (mut q, mut mq, mut r) = self.block_qr(w, &removed);
        // the check is one product with the held images; the passes run only when it
        // finds more than rounding
        let drift = if self.m > 0 {
            self.coefficients(q.as_ref()).norm_max()
        } else {
            0.0
        };
        if drift > REORTHOGONALIZE_ABOVE {
            let mut again = q.clone();
            let c2 = self.orthogonalize(&mut again);
            let (q2, mq2, r2) = self.block_qr(again, &vec![0.0; q.ncols()]);
            coef += times(c2.as_ref(), r.as_ref());
            r = times(r2.as_ref(), r.as_ref());
            q = q2;
            mq = mq2;
        }
        (q, mq, r, coef)
    }

    /// Appends the block `(q, mq)` at column `m`.
    fn append(&mut self, q: &Mat<f64>, mq: &Mat<f64>) {
        let b = q.ncols();
        self.v.as_mut().subcols_mut(self.m, b).copy_from(q);
        self.mv.as_mut().subcols_mut(self.m, b).copy_from(mq);
        self.m += b;
    }
}

/// Columns of the basis for `nev` wanted pairs in blocks of `b`: four times the wanted
/// pairs, at least two blocks more than them, and the next block. Measured with blocks of
/// 8: on the default rig's tied system (24 pairs) three times needs two restarts and four
/// times one, for the same number of block solves; on its free model (69 pairs, 49 below
/// 15 kHz) and on the coarse rig's (96 pairs in clusters of relative width 1e-3) three
/// times stalls (the thick restarts add too few blocks to separate the clusters) where
/// four times converges in one restart at most.
fn capacity(nev: usize, b: usize) -> usize {
    (4 * nev).max(nev + 2 * b).div_ceil(b) * b + b
}

/// One explicit Rayleigh-Ritz step on `span [X, R]`, `R = OP X - X diag(theta)`, with
/// `K - sigma M` and `M` themselves (not the Krylov relation, which the block solves'
/// errors break): returns the `nev` largest `theta` and their vectors. Only the pairs
/// whose explicit residual `||R_j||_M` exceeds `tol theta_j` bring their residual in;
/// when every pair passes, the pairs are returned as they came.
fn purify(
    op: &ShiftInvert<'_>,
    theta: &[f64],
    x: Mat<f64>,
    tol: f64,
) -> Result<(Vec<f64>, Mat<f64>)> {
    let (n, k) = (x.nrows(), x.ncols());
    if k == 0 {
        return Ok((theta.to_vec(), x));
    }
    let mx = m_times(op, x.as_ref());
    let mut r = mx.clone();
    op.solve_block_in_place(r.as_mut());
    for j in 0..k {
        for i in 0..n {
            r[(i, j)] -= theta[j] * x[(i, j)];
        }
    }
    // R against X twice, then unit M norms
    for _ in 0..2 {
        let mut c = Mat::<f64>::zeros(k, k);
        tmul_into(c.as_mut(), Accum::Replace, mx.as_ref(), r.as_ref());
        sub_mul(r.as_mut(), x.as_ref(), c.as_ref());
    }
    let mr = m_times(op, r.as_ref());
    let mut failing = 0;
    for j in 0..k {
        let nrm = dot(
            r.col(j).try_as_col_major().unwrap().as_slice(),
            mr.col(j).try_as_col_major().unwrap().as_slice(),
        )
        .max(0.0)
        .sqrt();
        // a residual within the tolerance needs no correction, and one at rounding level
        // is noise: its direction is left out (in a multiple eigenvalue it would bring in
        // unconverged copies)
        let f = if nrm > tol.max(PURIFY_NOISE) * theta[j].abs() {
            failing += 1;
            1.0 / nrm
        } else {
            0.0
        };
        r.col_mut(j).iter_mut().for_each(|v| *v *= f);
    }
    if failing == 0 {
        return Ok((theta.to_vec(), x));
    }
    // orthonormal directions of R (eigenvectors of its Gram matrix above 1e-10)
    let mr = m_times(op, r.as_ref());
    let mut g = Mat::<f64>::zeros(k, k);
    tmul_into(g.as_mut(), Accum::Replace, r.as_ref(), mr.as_ref());
    let g = Mat::from_fn(k, k, |i, j| 0.5 * (g[(i, j)] + g[(j, i)]));
    let ge = g
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::Invalid(format!("krylov: purification Gram matrix: {e:?}")))?;
    let gmax = (0..k).fold(0.0f64, |a, i| a.max(ge.S()[i]));
    let keep: Vec<usize> = (0..k).filter(|&i| ge.S()[i] > 1e-10 * gmax).collect();
    let u = Mat::from_fn(k, keep.len(), |i, j| {
        ge.U()[(i, keep[j])] / ge.S()[keep[j]].sqrt()
    });
    let wr = times(r.as_ref(), u.as_ref());
    let w = Mat::from_fn(n, k + wr.ncols(), |i, j| {
        if j < k {
            x[(i, j)]
        } else {
            wr[(i, j - k)]
        }
    });
    let p = w.ncols();
    let aw = symmetric_times(op.shifted(), w.as_ref());
    let mw = m_times(op, w.as_ref());
    let mut ga = Mat::<f64>::zeros(p, p);
    let mut gm = Mat::<f64>::zeros(p, p);
    tmul_into(ga.as_mut(), Accum::Replace, w.as_ref(), aw.as_ref());
    tmul_into(gm.as_mut(), Accum::Replace, w.as_ref(), mw.as_ref());
    let gm = Mat::from_fn(p, p, |i, j| 0.5 * (gm[(i, j)] + gm[(j, i)]));
    let ga = Mat::from_fn(p, p, |i, j| 0.5 * (ga[(i, j)] + ga[(j, i)]));
    // the pencil (Ga, Gm): eigenvalues lambda - sigma = 1 / theta, Gm-orthonormal vectors
    let (shifted, y) = dense_symmetric_pencil(ga.as_ref(), gm.as_ref())
        .map_err(|e| Error::Invalid(format!("krylov: purification: {e}")))?;
    // each input pair takes the Ritz vector that overlaps it most (W's first k columns are
    // X, so the overlaps are Y^T Gm[.., ..k]), so the step refines the pairs it was given
    let overlap = times(y.transpose(), gm.as_ref().subcols(0, k));
    let mut used = vec![false; p];
    let mut pick = Vec::with_capacity(k);
    for j in 0..k {
        let best = (0..p)
            .filter(|&i| !used[i] && shifted[i] > 0.0)
            .max_by(|&a, &b| overlap[(a, j)].abs().total_cmp(&overlap[(b, j)].abs()));
        match best {
            Some(i) => {
                used[i] = true;
                pick.push(i);
            }
            None => return Ok((theta.to_vec(), x)),
        }
    }
    let ysel = Mat::from_fn(p, k, |i, j| y[(i, pick[j])]);
    let xn = times(w.as_ref(), ysel.as_ref());
    Ok((pick.iter().map(|&i| 1.0 / shifted[i]).collect(), xn))
}

/// Relative size (to `theta`) of a residual `OP x - theta x` below which the purification
/// treats it as rounding and adds no direction for it.
const PURIFY_NOISE: f64 = 1e-13;

/// Whether a problem of `n` DOFs is large enough for the block basis (smaller ones take
/// the single-vector kernel).
pub(crate) fn fits(n: usize, nev: usize, b: usize) -> bool {
    capacity(nev, b) + 2 * b <= n
}

/// Restarts in a row without progress after which the block kernel gives up
/// ([`largest_block`]): no more wanted pairs converged and the largest relative residual
/// estimate among them not halved.
pub(crate) const STALL_RESTARTS: usize = 4;

/// What [`largest_block`] ends with.
pub(crate) enum BlockOutcome {
    /// The pairs (all, or those that passed the test when `max_restarts` was hit).
    Done(KernelOutput),
    /// [`STALL_RESTARTS`] restarts in a row made no progress (after `restarts`): the
    /// caller takes another method.
    Stalled { restarts: usize },
}

/// The `nev` largest eigenpairs of `OP` by block thick-restart Lanczos with blocks of
/// `block` columns (module docs). `max_restarts` caps the restarts; when it is hit the
/// pairs that passed the test are returned with `all_converged = false`.
pub(crate) fn largest_block(
    op: &ShiftInvert<'_>,
    nev: usize,
    tol: f64,
    max_restarts: usize,
    block: usize,
    start: Option<MatRef<'_, f64>>,
) -> Result<BlockOutcome> {
    let n = op.dim();
    let nev = nev.min(n);
    let b = block.max(1);
    let cap = capacity(nev, b);
    if nev == 0 || !fits(n, nev, b) {
        return Err(Error::Invalid(format!(
            "krylov: block Lanczos needs more DOFs ({n}) than its basis ({} columns)",
            cap + b
        )));
    }
    let mut s = State {
        op,
        v: Mat::zeros(n, cap),
        mv: Mat::zeros(n, cap),
        h: Mat::zeros(cap, cap),
        m: 0,
        dirs: Directions::new(),
    };
    // the given start's columns (at most b), then pseudo-random ones
    let given = start.map_or(0, |g| g.ncols().min(b));
    let start = {
        let mut cols = Mat::<f64>::zeros(n, b);
        if let Some(g) = start {
            cols.as_mut()
                .subcols_mut(0, given)
                .copy_from(g.subcols(0, given));
        }
        for j in given..b {
            let d = s.dirs.vector(n);
            cols.col_mut(j)
                .iter_mut()
                .zip(d)
                .for_each(|(x, di)| *x = di);
        }
        cols
    };
    let (q, mq, _) = s.block_qr(start, &vec![0.0; b]);
    s.append(&q, &mq);
    let mut last = 0;
    let mut restarts = 0;
    // leading columns locked at the last restart: converged Ritz vectors whose coupling to
    // the new blocks is below the tolerance and is kept at zero (its recomputed value is
    // the block solves' error, which would otherwise undo their convergence)
    let mut locked = 0;
    // (most wanted pairs converged, smallest largest relative residual, at which restart)
    let mut progress = (0usize, f64::INFINITY, 0usize);
    loop {
        // expand the last block: W = OP V_l = (K - sigma M)^-1 (M V_l)
        let mut w = s.mv.as_ref().subcols(last, s.m - last).to_owned();
        op.solve_block_in_place(w.as_mut());
        let (q, mq, r, coef) = s.remainder(w);
        let m = s.m;
        let bl = m - last;
        for i in 0..m {
            for j in 0..bl {
                let h = if i < locked { 0.0 } else { coef[(i, j)] };
                s.h[(i, last + j)] = h;
                s.h[(last + j, i)] = h;
            }
        }
        // Ritz pairs of H_m and their residuals ||R y_l||
        let eig =
            s.h.as_ref()
                .submatrix(0, 0, m, m)
                .self_adjoint_eigen(Side::Lower)
                .map_err(|e| Error::Invalid(format!("krylov: projected eigenproblem: {e:?}")))?;
        let theta: Vec<f64> = (0..m).map(|i| eig.S()[i]).collect();
        let y = eig.U().to_owned();
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by(|&a, &c| theta[c].total_cmp(&theta[a]));
        let yl = y.as_ref().subrows(last, bl);
        let ry = times(r.as_ref(), yl);
        let residual = |i: usize| ry.col(i).iter().map(|x| x * x).sum::<f64>().sqrt();
        let converged = |i: usize| residual(i) <= tol * theta[i].abs();
        let want = &order[..nev.min(m)];
        let done = want.len() == nev && want.iter().all(|&i| converged(i));
        if done || (s.m + b > cap && restarts >= max_restarts) {
            let keep: Vec<usize> = want.iter().copied().filter(|&i| converged(i)).collect();
            let ysel = Mat::from_fn(m, keep.len(), |r, c| y[(r, keep[c])]);
            let vectors = times(s.v.as_ref().subcols(0, m), ysel.as_ref());
            let theta: Vec<f64> = keep.iter().map(|&i| theta[i]).collect();
            // the basis and its `M` images (`2 n cap` values, 1.5 GB for 69 pairs on
            // 330k DOFs) are freed before the purification's temporaries are made
            drop(s);
            let (theta, vectors) = purify(op, &theta, vectors, tol)?;
            return Ok(BlockOutcome::Done(KernelOutput {
                theta,
                vectors,
                iterations: restarts,
                all_converged: done,
            }));
        }
        if s.m + b <= cap {
            last = s.m;
            s.append(&q, &mq);
            continue;
        }
        // progress since the last restart that made some, else give up after a few
        let converged_now = want.iter().filter(|&&i| converged(i)).count();
        let worst = want
            .iter()
            .map(|&i| residual(i) / theta[i].abs())
            .fold(0.0f64, f64::max);
        if converged_now > progress.0 || worst <= 0.5 * progress.1 {
            progress = (
                converged_now.max(progress.0),
                worst.min(progress.1),
                restarts,
            );
        } else if restarts - progress.2 >= STALL_RESTARTS {
            return Ok(BlockOutcome::Stalled { restarts });
        }
        // thick restart: keep the k largest Ritz pairs, Q becomes the next block
        restarts += 1;
        let k = (nev + (cap - b - nev) / 2).min(m);
        let mut kept: Vec<usize> = order[..k]
            .iter()
            .copied()
            .filter(|&i| want.contains(&i) && converged(i))
            .collect();
        locked = kept.len();
        let rest: Vec<usize> = order[..k]
            .iter()
            .copied()
            .filter(|i| !kept.contains(i))
            .collect();
        kept.extend(rest);
        let order = kept;
        let yk = Mat::from_fn(m, k, |r, c| y[(r, order[c])]);
        let vk = times(s.v.as_ref().subcols(0, m), yk.as_ref());
        let mvk = times(s.mv.as_ref().subcols(0, m), yk.as_ref());
        s.v.as_mut().subcols_mut(0, k).copy_from(&vk);
        s.mv.as_mut().subcols_mut(0, k).copy_from(&mvk);
        s.h.fill(0.0);
        for (c, &i) in order.iter().take(k).enumerate() {
            s.h[(c, c)] = theta[i];
        }
        s.m = k;
        last = k;
        s.append(&q, &mq);
    }
}
