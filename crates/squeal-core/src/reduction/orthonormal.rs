//! `M_c`-orthonormalization with a rank cut ([`m_orthonormalize`],
//! [`m_orthonormal_extend`], described in the module docs of [`crate::reduction`]) and
//! SVD compression ([`m_svd_compress`]).

use super::{par, tmul};
use crate::linalg::{col, dot, spmv, symmetric_times};
use crate::{Error, Result, SparseRef};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef};

/// Default relative rank cut of the orthonormalization: a unit-`M_c`-norm column is dropped
/// when the `M_c` norm of its part outside the span of the previous columns (the sine of
/// its angle to that span) is below this.
pub const DEFAULT_RANK_TOL: f64 = 1e-10;

/// Columns orthonormalized together (BLAS-3 projections against the kept columns).
const BLOCK: usize = 32;

/// Fraction of the `M` norm at which a column's `M` image was last exact (1 for a column
/// that started at unit norm) below which the image is recomputed by a sparse product
/// rather than carried through the projections: the carried image has an absolute error
/// of a few roundoffs of that norm, so its relative error stays below about 1e-12 above
/// this. Columns that a block pass leaves short are recomputed together, in one sparse
/// product of the block.
const RECOMPUTE_BELOW: f64 = 1e-3;

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
    check_dims(m, q, new)?;
    m_orthonormal_extend_imaged(m, q, symmetric_times(m, q).as_ref(), new, rank_tol)
}

fn check_dims(m: SparseRef<'_>, q: MatRef<'_, f64>, new: MatRef<'_, f64>) -> Result<()> {
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
    Ok(())
}

/// [`m_orthonormal_extend`] when the caller holds the `M` image of the kept columns,
/// `mq = M q` (an iterative basis that keeps the images of its columns): `mq` replaces
/// the sparse product over every kept column; the result is the same.
pub fn m_orthonormal_extend_imaged(
    m: SparseRef<'_>,
    q: MatRef<'_, f64>,
    mq: MatRef<'_, f64>,
    new: MatRef<'_, f64>,
    rank_tol: f64,
) -> Result<(Mat<f64>, usize)> {
    let (mut v, mut mv) = (q.to_owned(), mq.to_owned());
    let dropped = m_orthonormal_extend_in_place(m, &mut v, &mut mv, new, rank_tol)?;
    Ok((v, dropped))
}

/// [`m_orthonormal_extend_imaged`] in place: the `M`-orthonormal columns `v` and their
/// images `mv = M v` grow by the kept directions of `new` (their images carried through
/// the projections). Columns are reserved for every column of `new` unless `v` and `mv`
/// already have the room (a caller that extends many times reserves ahead, so its basis
/// is not copied each time). Returns the number of columns of `new` dropped.
pub(crate) fn m_orthonormal_extend_in_place(
    m: SparseRef<'_>,
    v: &mut Mat<f64>,
    mv: &mut Mat<f64>,
    new: MatRef<'_, f64>,
    rank_tol: f64,
) -> Result<usize> {
    check_rank_tol(rank_tol)?;
    check_dims(m, v.as_ref(), new)?;
    let (n, k) = (v.nrows(), v.ncols());
    if mv.nrows() != n || mv.ncols() != k {
        return Err(Error::Dimension {
            context: format!(
                "M-orthonormalization: the M image of the kept columns is {} x {}",
                mv.nrows(),
                mv.ncols()
            ),
            expected: n * k,
            got: mv.nrows() * mv.ncols(),
        });
    }
    let cap = k + new.ncols();
    let grown = |a: &mut Mat<f64>| {
        let mut a = std::mem::replace(a, Mat::new());
        a.reserve(n, cap);
        a.resize_with(n, cap, |_, _| 0.0);
        a
    };
    let mut ext = Extension {
        m,
        rank_tol,
        out: grown(v),
        mout: grown(mv),
        k,
        dropped: 0,
        w: vec![0.0; n],
        mw: vec![0.0; n],
    };
    let mut c0 = 0;
    while c0 < new.ncols() {
        let b = BLOCK.min(new.ncols() - c0);
        let mut blk = new.subcols(c0, b).to_owned();
        let mut mblk = symmetric_times(m, blk.as_ref());
        let mut alive = vec![true; b];
        for c in 0..b {
            let nrm = dot(col(&blk, c), col(&mblk, c));
            if !(nrm.is_finite() && nrm > 0.0) {
                alive[c] = false;
                continue;
            }
            let s = 1.0 / nrm.sqrt();
            blk.col_mut(c).iter_mut().for_each(|x| *x *= s);
            mblk.col_mut(c).iter_mut().for_each(|x| *x *= s);
        }
        ext.project(blk.as_mut(), mblk.as_mut(), 0, ext.k);
        let mut exact = vec![1.0; b];
        ext.refresh(&blk, &mut mblk, &alive, &mut exact, 0, b);
        // the norm each column keeps outside the earlier blocks (it started at 1)
        let mut before = vec![0.0; b];
        for c in 0..b {
            if alive[c] {
                before[c] = dot(col(&blk, c), col(&mblk, c)).max(0.0).sqrt();
                alive[c] = before[c] >= rank_tol;
            }
            if !alive[c] {
                ext.dropped += 1;
            }
        }
        ext.within(&mut blk, &mut mblk, (&alive, &before, &mut exact), 0, b);
        c0 += b;
    }
    let Extension {
        mut out,
        mut mout,
        k,
        dropped,
        ..
    } = ext;
    // the kept columns are the first `k`: truncated in place, not copied
    out.truncate(n, k);
    mout.truncate(n, k);
    *v = out;
    *mv = mout;
    Ok(dropped)
}

/// Columns of a block that a leaf of [`Extension::within`] orthonormalizes one by one.
const LEAF: usize = 4;

/// The state of [`m_orthonormal_extend_in_place`]: the kept columns `out[.., ..k]` and their
/// `M` images, and two work vectors.
struct Extension<'a> {
    m: SparseRef<'a>,
    rank_tol: f64,
    out: Mat<f64>,
    mout: Mat<f64>,
    k: usize,
    dropped: usize,
    w: Vec<f64>,
    mw: Vec<f64>,
}

impl Extension<'_> {
    /// Two block passes of `B` against the kept columns `from..to`, its image `MB`
    /// carried along: the coefficients `(M Q)^T B` need `B` only, so the image takes the
    /// two passes' summed coefficients in one product (five `n x k x b` products instead
    /// of six).
    fn project(&self, mut b: MatMut<'_, f64>, mut mb: MatMut<'_, f64>, from: usize, to: usize) {
        if to <= from {
            return;
        }
        let q = self.out.as_ref().subcols(from, to - from);
        let mq = self.mout.as_ref().subcols(from, to - from);
        let mut total = tmul(mq, b.as_ref());
        sub_mul(b.as_mut(), q, total.as_ref());
        let coef = tmul(mq, b.as_ref());
        sub_mul(b.as_mut(), q, coef.as_ref());
        total += &coef;
        sub_mul(mb.as_mut(), mq, total.as_ref());
    }

    /// After a block pass over the columns `lo..hi`: the live columns whose carried image
    /// lost more than [`RECOMPUTE_BELOW`] of the norm at which it was exact (`exact`) get
    /// their images recomputed, all in one sparse product, and `exact` their norms now.
    fn refresh(
        &self,
        blk: &Mat<f64>,
        mblk: &mut Mat<f64>,
        alive: &[bool],
        exact: &mut [f64],
        lo: usize,
        hi: usize,
    ) {
        let short: Vec<usize> = (lo..hi)
            .filter(|&c| {
                alive[c]
                    && dot(col(blk, c), col(mblk, c)).max(0.0).sqrt() < RECOMPUTE_BELOW * exact[c]
            })
            .collect();
        if short.is_empty() {
            return;
        }
        let x = Mat::from_fn(blk.nrows(), short.len(), |i, j| blk[(i, short[j])]);
        let mx = symmetric_times(self.m, x.as_ref());
        for (j, &c) in short.iter().enumerate() {
            mblk.col_mut(c).copy_from(mx.col(j));
            exact[c] = dot(col(blk, c), col(mblk, c)).max(0.0).sqrt();
        }
    }

    /// Orthonormalizes the columns `lo..hi` of a block already projected against the
    /// earlier blocks, in order, recursively: the left half, then the right half projected
    /// against what the left half kept (block passes, the images they leave short
    /// recomputed together), then the right half; a leaf of [`LEAF`] columns goes column
    /// by column. The block passes read each column of the block a logarithmic number of
    /// times instead of once per later column. `state`: which columns are alive, their
    /// norms after the passes against the earlier blocks, and the norms at which their
    /// images were last exact.
    fn within(
        &mut self,
        blk: &mut Mat<f64>,
        mblk: &mut Mat<f64>,
        state: (&[bool], &[f64], &mut [f64]),
        lo: usize,
        hi: usize,
    ) {
        let (alive, before, exact) = state;
        if hi - lo <= LEAF {
            let k_leaf = self.k;
            for c in lo..hi {
                if alive[c] {
                    self.column(col(blk, c), col(mblk, c), (before[c], exact[c]), k_leaf);
                }
            }
            return;
        }
        let mid = lo + (hi - lo) / 2;
        let k_left = self.k;
        self.within(blk, mblk, (alive, before, &mut *exact), lo, mid);
        self.project(
            blk.as_mut().subcols_mut(mid, hi - mid),
            mblk.as_mut().subcols_mut(mid, hi - mid),
            k_left,
            self.k,
        );
        self.refresh(blk, mblk, alive, exact, mid, hi);
        self.within(blk, mblk, (alive, before, exact), mid, hi);
    }

    /// Projects one column against the kept columns `k_leaf..k` of its leaf, twice, and
    /// keeps it unless it falls under the rank cut; `norms`: its `M` norm after the block
    /// passes against the earlier blocks, and the norm at which its image was last exact.
    /// Heavy cancellation inside the block (less than a tenth of the first left) earns
    /// one more pass against every kept column.
    fn column(&mut self, v: &[f64], mv: &[f64], norms: (f64, f64), k_leaf: usize) {
        // `mw = M w` is carried through the projections (`M (w - Q c) = M w - (M Q) c`)
        // instead of one sparse product per pass; it is recomputed exactly only when
        // cancellation left `w` short (below RECOMPUTE_BELOW of the norm at which the
        // image was last exact), where the carried product's relative error would grow
        let (before, mut exact) = norms;
        let mut w = std::mem::take(&mut self.w);
        let mut mw = std::mem::take(&mut self.mw);
        w.copy_from_slice(v);
        mw.copy_from_slice(mv);
        let mut nrm = self.passes(&mut w, &mut mw, k_leaf, &mut exact);
        if nrm < 0.1 * before {
            nrm = self.passes(&mut w, &mut mw, 0, &mut exact);
        }
        if nrm >= self.rank_tol && nrm.is_finite() {
            let k = self.k;
            for (r, (x, y)) in w.iter().zip(&mw).enumerate() {
                self.out[(r, k)] = x / nrm;
                self.mout[(r, k)] = y / nrm;
            }
            self.k += 1;
        } else {
            self.dropped += 1;
        }
        self.w = w;
        self.mw = mw;
    }

    /// Two passes of `w` (image `mw`, exact at the norm `exact`, which a recomputation
    /// updates) against the kept columns `from..k`; returns the `M` norm left.
    fn passes(&self, w: &mut [f64], mw: &mut [f64], from: usize, exact: &mut f64) -> f64 {
        let n = w.len();
        self.project(
            MatMut::from_column_major_slice_mut(w, n, 1),
            MatMut::from_column_major_slice_mut(mw, n, 1),
            from,
            self.k,
        );
        if dot(w, mw).max(0.0).sqrt() < RECOMPUTE_BELOW * *exact {
            spmv(self.m, w, mw);
            *exact = dot(w, mw).max(0.0).sqrt();
        }
        dot(w, mw).max(0.0).sqrt()
    }
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
    let ms = symmetric_times(m, v);
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
    let r = tmul(symmetric_times(m, q.as_ref()).as_ref(), s.as_ref());
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
    let g = tmul(v, symmetric_times(m, v).as_ref());
    let mut worst = 0.0f64;
    for j in 0..g.ncols() {
        for i in 0..g.nrows() {
            let e = g[(i, j)] - if i == j { 1.0 } else { 0.0 };
            worst = worst.max(e.abs());
        }
    }
    worst
}
