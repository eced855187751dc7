//! Shared machinery of the reduction bases (METHODS.md section 4), written once and used
//! by every [`ReductionBasis`](crate::ReductionBasis):
//!
//! - `M_c`-orthonormalization with a rank cut ([`m_orthonormalize`],
//!   [`m_orthonormal_extend`]) and an optional SVD compression ([`m_svd_compress`]);
//! - the coupled mu = 0 real modes ([`coupled_real_modes`]), the friction load directions
//!   ([`friction_load_directions`]) and static responses with one reused factorization
//!   ([`StaticSolver`]);
//! - projection of every part of a [`FrictionalOperator`] on a basis ([`project`]), the
//!   reduced solve with any [`EigenSolver`], and the expansion of the reduced modes with
//!   their backward errors on the FULL operator ([`ReducedOperator`], [`solve_reduced`]);
//! - the MAC between a real and a complex mode ([`mac_real_complex`]).
//!
//! ## Orthonormalization
//! Columns are first scaled to unit `M_c` norm (so badly scaled static responses, e.g.
//! `K^-1 f` of order 1e-9 m next to modes of unit modal mass, are judged on their
//! direction only), then orthonormalized by block classical Gram-Schmidt with
//! re-orthogonalization (every projection done twice, "twice is enough"; a column that
//! lost more than 90 % of its norm inside its block gets a third pass against every
//! kept column) in the `M_c` inner product: a QR factorization in that inner product. A
//! unit column whose component outside the span of the columns kept before it has an
//! `M_c` norm below `rank_tol` (the sine of its angle to that span) is dropped and
//! counted. The Gram matrix `V^T M V` is never diagonalized: its eigenvalues are the
//! squares of the singular values, so a relative cut at `tol` on them silently drops
//! directions of relative size `sqrt(tol)`, precisely the static vectors nearly parallel
//! to a mode.
//!
//! ## Reduced solve
//! `V^T X V` for each part `X` in {`M_c`, `C_c`, `K_c`, `F_M`, `F_C`, `F_K`} (the friction
//! parts have `4 nA` nonzero rows, so their projection is cheap), a dense-backed
//! [`FrictionalOperator`] with `t: None`, solved by any [`EigenSolver`] (normally `dense`)
//! at each mu; the modes `u_c = V q` are finished by [`finish_operator_modes`] on the
//! parts of `op.at(mu)`, so their backward errors are those of the full problem. When the
//! reduced solver returns left eigenvectors `p`, they are expanded the same way
//! (`y = V p`) and give each mode a condition number and a forward error estimate on the
//! full problem ([`finish_operator_modes_with_left`]; see the `qep::condition` module
//! docs for the limits of this Galerkin left vector).

use crate::contact::{Basis, BasisRequest, FrictionalOperator};
use crate::eigen::{EigenParams, EigenSolver, RealModes, SymmetricProblem};
pub use crate::linalg::sparse_times;
use crate::linalg::{add_scaled, dot, spmv, Cholesky};
use crate::qep::{
    finish_operator_modes, finish_operator_modes_with_left, spmv_complex, ComplexModes,
};
use crate::{c64, Error, Result, SparseMat, SparseRef};
use faer::linalg::matmul::matmul;
use faer::sparse::Triplet;
use faer::{Accum, Mat, MatRef, Par};
use std::time::Instant;

#[cfg(test)]
mod tests;

/// Default relative rank cut of the orthonormalization: a unit-`M_c`-norm column is dropped
/// when the `M_c` norm of its part outside the span of the previous columns (the sine of
/// its angle to that span) is below this.
pub const DEFAULT_RANK_TOL: f64 = 1e-10;

/// Columns orthonormalized together (BLAS-3 projections against the kept columns).
const BLOCK: usize = 32;

fn par() -> Par {
    faer::get_global_parallelism()
}

/// `A^T B` for dense matrices.
fn tmul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut c = Mat::<f64>::zeros(a.ncols(), b.ncols());
    if a.nrows() > 0 {
        matmul(c.as_mut(), Accum::Replace, a.transpose(), b, 1.0, par());
    }
    c
}

/// `Y -= A B` for dense matrices.
fn sub_mul(y: faer::MatMut<'_, f64>, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    if a.ncols() > 0 {
        matmul(y, Accum::Add, a, b, -1.0, par());
    }
}

fn check_rank_tol(rank_tol: f64) -> Result<()> {
    if !(rank_tol > 0.0 && rank_tol < 1.0) {
        return Err(Error::param(
            "rank_tol",
            format!("relative rank cut must be in (0, 1), got {rank_tol}"),
        ));
    }
    Ok(())
}

/// `M`-orthonormal basis of the span of the columns of `v`, in their order, with the
/// rank cut described in the module docs. Returns the basis and the number of columns
/// dropped (zero, non-finite or dependent columns).
pub fn m_orthonormalize(
    m: SparseRef<'_>,
    v: MatRef<'_, f64>,
    rank_tol: f64,
) -> Result<(Mat<f64>, usize)> {
    let empty = Mat::<f64>::zeros(m.nrows(), 0);
    m_orthonormal_extend(m, empty.as_ref(), v, rank_tol)
}

/// Extends the `M`-orthonormal columns `q` (kept unchanged, first) with the columns of
/// `new`, orthonormalized against `q` and each other with the rank cut of the module
/// docs. Returns `[q | kept new directions]` and the number of columns of `new` dropped.
pub fn m_orthonormal_extend(
    m: SparseRef<'_>,
    q: MatRef<'_, f64>,
    new: MatRef<'_, f64>,
    rank_tol: f64,
) -> Result<(Mat<f64>, usize)> {
    check_rank_tol(rank_tol)?;
    let n = m.nrows();
    if m.ncols() != n {
        return Err(Error::Dimension {
            context: "M-orthonormalization: M must be square".into(),
            expected: n,
            got: m.ncols(),
        });
    }
    for (what, rows) in [("kept columns", q.nrows()), ("new columns", new.nrows())] {
        if rows != n {
            return Err(Error::Dimension {
                context: format!("M-orthonormalization: rows of the {what}"),
                expected: n,
                got: rows,
            });
        }
    }
    let cap = q.ncols() + new.ncols();
    let mut out = Mat::<f64>::zeros(n, cap);
    let mut mout = Mat::<f64>::zeros(n, cap);
    out.as_mut().subcols_mut(0, q.ncols()).copy_from(q);
    mout.as_mut()
        .subcols_mut(0, q.ncols())
        .copy_from(sparse_times(m, q).as_ref());
    let mut k = q.ncols();
    let mut dropped = 0;
    let mut w = vec![0.0; n];
    let mut mw = vec![0.0; n];
    let mut c0 = 0;
    while c0 < new.ncols() {
        let b = BLOCK.min(new.ncols() - c0);
        let mut blk = new.subcols(c0, b).to_owned();
        let mut mblk = sparse_times(m, blk.as_ref());
        let mut alive = vec![true; b];
        for c in 0..b {
            let nrm = dot(blk.col(c).try_as_col_major().unwrap().as_slice(), {
                mblk.col(c).try_as_col_major().unwrap().as_slice()
            });
            if !(nrm.is_finite() && nrm > 0.0) {
                alive[c] = false;
                continue;
            }
            let s = 1.0 / nrm.sqrt();
            blk.col_mut(c).iter_mut().for_each(|x| *x *= s);
            mblk.col_mut(c).iter_mut().for_each(|x| *x *= s);
        }
        // two block passes against the kept columns
        for _ in 0..2 {
            if k > 0 {
                let coef = tmul(mout.as_ref().subcols(0, k), blk.as_ref());
                sub_mul(blk.as_mut(), out.as_ref().subcols(0, k), coef.as_ref());
                sub_mul(mblk.as_mut(), mout.as_ref().subcols(0, k), coef.as_ref());
            }
        }
        let k_block = k;
        for c in 0..b {
            if !alive[c] {
                dropped += 1;
                continue;
            }
            w.copy_from_slice(blk.col(c).try_as_col_major().unwrap().as_slice());
            spmv(m, &w, &mut mw);
            let before = dot(&w, &mw).max(0.0).sqrt();
            if before < rank_tol || before.is_nan() {
                dropped += 1;
                continue;
            }
            let passes = |w: &mut Vec<f64>, mw: &mut Vec<f64>, from: usize, to: usize| {
                for _ in 0..2 {
                    if to > from {
                        let qq = out.as_ref().subcols(from, to - from);
                        let mq = mout.as_ref().subcols(from, to - from);
                        let wm = faer::MatRef::from_column_major_slice(w, n, 1);
                        let coef = tmul(mq, wm);
                        let mut wmut = faer::MatMut::from_column_major_slice_mut(w, n, 1);
                        sub_mul(wmut.as_mut(), qq, coef.as_ref());
                    }
                }
                spmv(m, w, mw);
                dot(w, mw).max(0.0).sqrt()
            };
            let mut nrm = passes(&mut w, &mut mw, k_block, k);
            if nrm < 0.1 * before {
                // heavy cancellation inside the block: one more pass against everything
                nrm = passes(&mut w, &mut mw, 0, k);
            }
            if !(nrm >= rank_tol && nrm.is_finite()) {
                dropped += 1;
                continue;
            }
            for r in 0..n {
                out[(r, k)] = w[r] / nrm;
                mout[(r, k)] = mw[r] / nrm;
            }
            k += 1;
        }
        c0 += b;
    }
    let out = out.as_ref().subcols(0, k).to_owned();
    Ok((out, dropped))
}

/// Compresses the span of the columns of `v` by an SVD in the `M` inner product: columns
/// scaled to unit `M` norm, `M`-orthonormalized (`S = Q R`, rank cut
/// [`DEFAULT_RANK_TOL`]), `R = U Sigma W^T`; keeps `Q U_r` for the singular values
/// `sigma_i > svd_tol sigma_1`. Returns the `M`-orthonormal directions and the number of
/// columns of `v` they replace minus the number kept (dropped).
pub fn m_svd_compress(
    m: SparseRef<'_>,
    v: MatRef<'_, f64>,
    svd_tol: f64,
) -> Result<(Mat<f64>, usize)> {
    if !(svd_tol > 0.0 && svd_tol < 1.0) {
        return Err(Error::param(
            "svd_tol",
            format!("relative singular value cut must be in (0, 1), got {svd_tol}"),
        ));
    }
    let n = m.nrows();
    let mut s = v.to_owned();
    let ms = sparse_times(m, v);
    for c in 0..s.ncols() {
        let nrm = (0..n).map(|r| s[(r, c)] * ms[(r, c)]).sum::<f64>().sqrt();
        let f = if nrm.is_finite() && nrm > 0.0 {
            1.0 / nrm
        } else {
            0.0
        };
        s.col_mut(c).iter_mut().for_each(|x| *x *= f);
    }
    let (q, _) = m_orthonormalize(m, s.as_ref(), DEFAULT_RANK_TOL)?;
    if q.ncols() == 0 {
        return Ok((q, v.ncols()));
    }
    let r = tmul(sparse_times(m, q.as_ref()).as_ref(), s.as_ref());
    let svd = r
        .thin_svd()
        .map_err(|e| Error::Invalid(format!("SVD of the M-QR factor failed: {e:?}")))?;
    let sig = svd.S();
    let smax = (0..sig.dim()).fold(0.0f64, |a, i| a.max(sig[i]));
    let keep: Vec<usize> = (0..sig.dim())
        .filter(|&i| sig[i] > svd_tol * smax)
        .collect();
    let u = svd.U();
    let ur = Mat::from_fn(u.nrows(), keep.len(), |i, j| u[(i, keep[j])]);
    let out = &q * &ur;
    let dropped = v.ncols() - keep.len();
    Ok((out, dropped))
}

/// Largest entry of `|V^T M V - I|`: how far `V` is from `M`-orthonormal.
pub fn m_orthonormality_error(m: SparseRef<'_>, v: MatRef<'_, f64>) -> f64 {
    let g = tmul(v, sparse_times(m, v).as_ref());
    let mut worst = 0.0f64;
    for j in 0..g.ncols() {
        for i in 0..g.nrows() {
            let e = g[(i, j)] - if i == j { 1.0 } else { 0.0 };
            worst = worst.max(e.abs());
        }
    }
    worst
}

/// A dense matrix stored as a sparse one (its nonzero entries).
fn dense_to_sparse(a: MatRef<'_, f64>) -> Result<SparseMat> {
    let mut t = Vec::with_capacity(a.nrows() * a.ncols());
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            if a[(i, j)] != 0.0 {
                t.push(Triplet::new(i, j, a[(i, j)]));
            }
        }
    }
    SparseMat::try_new_from_triplets(a.nrows(), a.ncols(), &t)
        .map_err(|e| Error::Invalid(format!("reduced matrix: {e:?}")))
}

/// `V^T X V` exploiting the zero rows of `X` (the friction parts have `4 nA` nonzero
/// rows).
fn project_part(x: SparseRef<'_>, v: MatRef<'_, f64>) -> Result<SparseMat> {
    let n = x.nrows();
    let mut used = vec![false; n];
    for j in 0..x.ncols() {
        for i in x.row_idx_of_col(j) {
            used[i] = true;
        }
    }
    let rows: Vec<usize> = (0..n).filter(|&i| used[i]).collect();
    let m = v.ncols();
    if rows.is_empty() {
        return dense_to_sparse(Mat::<f64>::zeros(m, m).as_ref());
    }
    let xv = sparse_times(x, v);
    let red = if rows.len() == n {
        tmul(v, xv.as_ref())
    } else {
        let vr = Mat::from_fn(rows.len(), m, |i, j| v[(rows[i], j)]);
        let yr = Mat::from_fn(rows.len(), m, |i, j| xv[(rows[i], j)]);
        tmul(vr.as_ref(), yr.as_ref())
    };
    dense_to_sparse(red.as_ref())
}

/// Projects every part of `op` on the columns of `v` (`n_c x m`): `X_r = V^T X V`, the
/// friction load directions to `V^T U`, no index map. The result is a small
/// (dense-backed) operator that any [`EigenSolver`] solves.
pub fn project(op: &FrictionalOperator, v: MatRef<'_, f64>) -> Result<FrictionalOperator> {
    let n = op.dim();
    if v.nrows() != n {
        return Err(Error::Dimension {
            context: "projection: rows of the basis".into(),
            expected: n,
            got: v.nrows(),
        });
    }
    if v.ncols() == 0 {
        return Err(Error::Invalid("projection on an empty basis".into()));
    }
    let opt = |x: &Option<SparseMat>| -> Result<Option<SparseMat>> {
        x.as_ref().map(|x| project_part(x.as_ref(), v)).transpose()
    };
    let friction_loads = match &op.friction_loads {
        Some(u) => {
            // V^T U column by column: U has a few nonzeros per column (never densified:
            // `n x nA` would be gigabytes for thousands of pairs)
            let u = u.as_ref();
            let mut r = Mat::<f64>::zeros(v.ncols(), u.ncols());
            for j in 0..u.ncols() {
                for (i, x) in u.row_idx_of_col(j).zip(u.val_of_col(j)) {
                    for c in 0..v.ncols() {
                        r[(c, j)] += x * v[(i, c)];
                    }
                }
            }
            Some(dense_to_sparse(r.as_ref())?)
        }
        None => None,
    };
    Ok(FrictionalOperator {
        mc: project_part(op.mc.as_ref(), v)?,
        cc: opt(&op.cc)?,
        kc: project_part(op.kc.as_ref(), v)?,
        fm: project_part(op.fm.as_ref(), v)?,
        fc: opt(&op.fc)?,
        fk: project_part(op.fk.as_ref(), v)?,
        t: None,
        friction_loads,
    })
}

/// Expands reduced vectors: `u = V q` (`V` real `n x m`, `q` complex `m x k`).
pub fn expand(v: MatRef<'_, f64>, q: MatRef<'_, c64>) -> Mat<c64> {
    // One real product V [Re Q, Im Q] (BLAS-3, parallel), then recombined.
    let k = q.ncols();
    let parts = Mat::from_fn(q.nrows(), 2 * k, |i, j| {
        if j < k {
            q[(i, j)].re
        } else {
            q[(i, j - k)].im
        }
    });
    let mut u = Mat::<f64>::zeros(v.nrows(), 2 * k);
    if k > 0 && v.ncols() > 0 {
        matmul(u.as_mut(), Accum::Replace, v, parts.as_ref(), 1.0, par());
    }
    Mat::from_fn(v.nrows(), k, |i, j| c64::new(u[(i, j)], u[(i, j + k)]))
}

/// Complex modes of a reduced solve, expanded to the constrained space, with the cost of
/// each stage.
#[derive(Debug, Clone)]
pub struct ReducedSolve {
    /// The modes on the constrained DOFs (`u_c = V q`), with backward errors on the FULL
    /// operator `op.at(mu)`. `info` is the reduced solver's, with `time_s` = reduced solve
    /// + expansion + backward errors (per mu) and notes on the basis.
    pub modes: ComplexModes,
    /// Columns of the basis.
    pub basis_size: usize,
    /// Time to build the basis (s), as reported by the basis.
    pub basis_time_s: f64,
    /// Time to project the operator on the basis (s), once per basis.
    pub projection_time_s: f64,
    /// Time of the reduced eigen solve (s), per mu.
    pub solve_time_s: f64,
    /// Time to expand the modes and compute their backward errors on the full operator
    /// (s), per mu.
    pub expansion_time_s: f64,
}

/// A basis with the operator projected on it: project once, solve at any mu (a basis
/// fixed in mu serves a whole sweep at one contact set).
#[derive(Debug, Clone)]
pub struct ReducedOperator {
    /// The basis.
    pub basis: Basis,
    /// `V^T X V` for every part.
    pub reduced: FrictionalOperator,
    /// Time of the projection (s).
    pub projection_time_s: f64,
}

impl ReducedOperator {
    /// Projects `op` on `basis`.
    pub fn new(op: &FrictionalOperator, basis: Basis) -> Result<Self> {
        let start = Instant::now();
        let reduced = project(op, basis.v.as_ref())?;
        Ok(Self {
            basis,
            reduced,
            projection_time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// Solves the reduced QEP at `mu` with `eigen` in the band of `params`, expands the
    /// modes and computes their backward errors on `op.at(mu)` (`op` is the operator the
    /// basis was projected from).
    pub fn solve(
        &self,
        op: &FrictionalOperator,
        mu: f64,
        eigen: &dyn EigenSolver,
        params: &EigenParams,
    ) -> Result<ReducedSolve> {
        if op.dim() != self.basis.v.nrows() {
            return Err(Error::Dimension {
                context: "reduced solve: the basis was built for another operator".into(),
                expected: op.dim(),
                got: self.basis.v.nrows(),
            });
        }
        if let Some(b) = self.basis.mu {
            if b != mu {
                return Err(Error::Invalid(format!(
                    "reduced solve at mu = {mu} on a basis built for mu = {b} (this basis \
                     depends on mu: rebuild it)"
                )));
            }
        }
        let start = Instant::now();
        let red = eigen.solve_frictional(&self.reduced, mu, params)?;
        let solve_time_s = start.elapsed().as_secs_f64();
        let start = Instant::now();
        // Only the pairs `finish_modes` keeps are expanded: a dense reduced solve returns
        // every root, and expanding them all would cost n x m x 2m.
        let kept: Vec<usize> = crate::qep::band_pairs(&red.lambda, params)
            .into_iter()
            .map(|(_, i)| i)
            .collect();
        let q = Mat::from_fn(red.vectors.nrows(), kept.len(), |i, j| {
            red.vectors[(i, kept[j])]
        });
        let lambda: Vec<c64> = kept.iter().map(|&i| red.lambda[i]).collect();
        let u = expand(self.basis.v.as_ref(), q.as_ref());
        let mut info = red.info.clone();
        info.notes.push(format!(
            "reduced on a basis of {} vectors ({} dropped by the rank cut, {} iterations); \
             modes expanded, backward errors on the full operator",
            self.basis.len(),
            self.basis.dropped,
            self.basis.iterations
        ));
        info.notes.extend(self.basis.notes.iter().cloned());
        let mut modes = match &red.left_vectors {
            Some(p) => {
                let pk = Mat::from_fn(p.nrows(), kept.len(), |i, j| p[(i, kept[j])]);
                let y = expand(self.basis.v.as_ref(), pk.as_ref());
                finish_operator_modes_with_left(
                    op,
                    mu,
                    &lambda,
                    u.as_ref(),
                    y.as_ref(),
                    params,
                    info,
                )?
            }
            None => finish_operator_modes(op, mu, &lambda, u.as_ref(), params, info)?,
        };
        let expansion_time_s = start.elapsed().as_secs_f64();
        modes.info.time_s = solve_time_s + expansion_time_s;
        Ok(ReducedSolve {
            modes,
            basis_size: self.basis.len(),
            basis_time_s: self.basis.time_s,
            projection_time_s: self.projection_time_s,
            solve_time_s,
            expansion_time_s,
        })
    }
}

/// Projects `op` on `basis`, solves at `mu` with `eigen` (normally `dense`) and expands:
/// [`ReducedOperator::new`] then [`ReducedOperator::solve`].
pub fn solve_reduced(
    op: &FrictionalOperator,
    basis: &Basis,
    mu: f64,
    eigen: &dyn EigenSolver,
    params: &EigenParams,
) -> Result<ReducedSolve> {
    ReducedOperator::new(op, basis.clone())?.solve(op, mu, eigen, params)
}

/// The coupled mu = 0 real modes of `(K_c, M_c)` from 0 to `cutoff_hz`, by
/// `request.modal` (tolerances from `request.params`).
pub fn coupled_real_modes(request: &BasisRequest<'_>, cutoff_hz: f64) -> Result<RealModes> {
    if !(cutoff_hz.is_finite() && cutoff_hz > 0.0) {
        return Err(Error::param(
            "cutoff",
            format!("cutoff frequency must be positive (Hz), got {cutoff_hz}"),
        ));
    }
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: cutoff_hz,
        nev_hint: None,
        ..request.params.clone()
    };
    let op = request.op;
    request.modal.solve_symmetric(
        &SymmetricProblem {
            k: op.kc.as_ref(),
            m: op.mc.as_ref(),
        },
        &params,
    )
}

/// The friction load directions `U = T^T P~t^T` as dense columns (`n_c x nA`). When the
/// operator does not carry them, their span is recovered from `F_K = U V_K^T`
/// (`range F_K = range U` when `V_K` has full column rank): `F_K Omega` for a fixed
/// pseudo-random `Omega` with as many columns as `F_K` has nonzero rows (an upper bound
/// of its rank); the rank cut of the orthonormalization removes the surplus.
pub fn friction_load_directions(op: &FrictionalOperator) -> Result<Mat<f64>> {
    let n = op.dim();
    if let Some(u) = &op.friction_loads {
        if u.nrows() != n {
            return Err(Error::Dimension {
                context: "friction load directions: rows".into(),
                expected: n,
                got: u.nrows(),
            });
        }
        return Ok(u.as_ref().to_dense());
    }
    let fk = op.fk.as_ref();
    let mut used = vec![false; n];
    for j in 0..n {
        for i in fk.row_idx_of_col(j) {
            used[i] = true;
        }
    }
    let p = used.iter().filter(|&&u| u).count();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let omega = Mat::from_fn(n, p, |_, _| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    });
    Ok(sparse_times(fk, omega.as_ref()))
}

/// Static responses `K_s^-1 R` with `K_s = K_c + shift M_c` factorized once (sparse
/// Cholesky; `shift` in (rad/s)^2, `>= 0`).
pub struct StaticSolver {
    factor: Cholesky,
    ks: SparseMat,
    /// The shift (rad/s)^2.
    pub shift: f64,
    /// Factorization time (s).
    pub time_s: f64,
}

impl StaticSolver {
    /// Factorizes `K_c + shift M_c`.
    pub fn new(op: &FrictionalOperator, shift: f64) -> Result<Self> {
        let start = Instant::now();
        if !(shift.is_finite() && shift >= 0.0) {
            return Err(Error::param(
                "shift",
                format!("static shift must be finite and >= 0 (rad/s)^2, got {shift}"),
            ));
        }
        let ks = add_scaled(op.kc.as_ref(), 1.0, op.mc.as_ref(), shift)?;
        let factor = Cholesky::new(ks.as_ref(), "K_c + shift M_c (static responses)")?;
        Ok(Self {
            factor,
            ks,
            shift,
            time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// `R <- K_s^-1 R` for a block of right-hand sides.
    pub fn solve_in_place(&self, r: faer::MatMut<'_, f64>) {
        self.factor.solve_in_place(r);
    }

    /// The factorized matrix `K_s`.
    pub fn matrix(&self) -> SparseRef<'_> {
        self.ks.as_ref()
    }
}

/// Residual of the reduced modes `(lambda_j, u_j = V q_j)` on the full `qep`, in the
/// energy norm of `K_s` ([`StaticSolver`]): `d_j = K_s^-1 r_j`, `r_j = Q(lambda_j) u_j`,
/// `eps_j = sqrt(d_j^H K_s d_j) / sqrt(u_j^H K_s u_j)`. Returns the `eps_j` and the
/// static responses `d_j` (complex, one column each).
pub fn energy_residuals(
    qep: &crate::qep::Qep,
    ks: &StaticSolver,
    lambda: &[c64],
    u: MatRef<'_, c64>,
) -> (Vec<f64>, Mat<c64>) {
    let n = qep.dim();
    let k = lambda.len();
    let mut rr = Mat::<f64>::zeros(n, 2 * k);
    let (mut t, mut s) = (vec![c64::new(0.0, 0.0); n], vec![c64::new(0.0, 0.0); n]);
    for (j, &l) in lambda.iter().enumerate() {
        let uj: Vec<c64> = (0..n).map(|r| u[(r, j)]).collect();
        // r = K u + l (C u + l M u)
        spmv_complex(qep.m.as_ref(), &uj, &mut t);
        t.iter_mut().for_each(|v| *v *= l);
        if let Some(c) = &qep.c {
            spmv_complex(c.as_ref(), &uj, &mut s);
            t.iter_mut().zip(&s).for_each(|(a, b)| *a += *b);
        }
        t.iter_mut().for_each(|v| *v *= l);
        spmv_complex(qep.k.as_ref(), &uj, &mut s);
        for r in 0..n {
            let v = t[r] + s[r];
            rr[(r, 2 * j)] = v.re;
            rr[(r, 2 * j + 1)] = v.im;
        }
    }
    let mut d = rr.clone();
    ks.solve_in_place(d.as_mut());
    let ur = Mat::from_fn(n, 2 * k, |r, c| {
        let z = u[(r, c / 2)];
        if c % 2 == 0 {
            z.re
        } else {
            z.im
        }
    });
    let ksu = sparse_times(ks.matrix(), ur.as_ref());
    let mut eps = Vec::with_capacity(k);
    for j in 0..k {
        let num: f64 = (0..n)
            .map(|r| rr[(r, 2 * j)] * d[(r, 2 * j)] + rr[(r, 2 * j + 1)] * d[(r, 2 * j + 1)])
            .sum();
        let den: f64 = (0..n)
            .map(|r| ur[(r, 2 * j)] * ksu[(r, 2 * j)] + ur[(r, 2 * j + 1)] * ksu[(r, 2 * j + 1)])
            .sum();
        eps.push(if den > 0.0 {
            (num.max(0.0) / den).sqrt()
        } else {
            f64::INFINITY
        });
    }
    let dc = Mat::from_fn(n, k, |r, j| c64::new(d[(r, 2 * j)], d[(r, 2 * j + 1)]));
    (eps, dc)
}

/// MAC between a real mode `phi` and a complex mode `psi` in the `M` inner product,
/// Hermitian form (METHODS.md section 5):
/// `|phi^T M conj(psi)|^2 / ((phi^T M phi) (psi^H M psi))`, in [0, 1], independent of
/// the phase of `psi`.
pub fn mac_real_complex(m: SparseRef<'_>, phi: &[f64], psi: &[c64]) -> f64 {
    let n = phi.len();
    let mut mphi = vec![0.0; n];
    spmv(m, phi, &mut mphi);
    let re: Vec<f64> = psi.iter().map(|z| z.re).collect();
    let im: Vec<f64> = psi.iter().map(|z| z.im).collect();
    let (a, b) = (dot(&mphi, &re), dot(&mphi, &im));
    let pp = dot(&mphi, phi);
    let mut t = vec![0.0; n];
    spmv(m, &re, &mut t);
    let mut qq = dot(&t, &re);
    spmv(m, &im, &mut t);
    qq += dot(&t, &im);
    let den = pp * qq;
    if den > 0.0 {
        (a * a + b * b) / den
    } else {
        0.0
    }
}
