//! The static space of a model ([`StaticSpace`]): an `M`-orthonormal basis `Q` of the free
//! model's responses to every candidate pair's normal and friction loads, built once per
//! model, in which every contact set's tied static responses lie; and the implicit basis
//! of a contact set made of such responses and a few explicit columns ([`StaticBasis`]).
//!
//! With `Z = K^-1 C^T` (normal pair loads) and `X = K^-1 P~t^T` (friction loads), the
//! static response of a contact set to the friction load of its active pair `j` is, on
//! the free DOFs, `y_j = X e_j - Z_A S_AA^-1 (C X)_{A j}` ([`super::tied`] module docs).
//! With `[Z | X] = Q R` (`Q^T M Q = I`, `R` upper triangular, `2 nR` columns) its
//! coordinates `R [-S_AA^-1 (C X)_{A j}; e_j]` cost no product with an `n`-row matrix, nor
//! do their orthonormalization (a dense QR of `2 nR x nA`) and their projection:
//! `(Q c)^T K (Q c') = c^T (Q^T K Q) c'`, `(Q c)^T M (Q c') = c^T c'`, and the friction
//! parts `F_X = U V_X^T` read the rows of `X Q` at the pairs' pin-normal DOFs, kept.
//!
//! The columns `Q W` of a contact set are tie-satisfying combinations of free responses;
//! on the constrained DOFs each takes the value of one free DOF mapped there (its pin and
//! disc normal values agree to the rounding of the ties' correction). Products with the
//! operator's constrained matrices use those rows: `(Q W)_c^T x = W^T Q^T (x` scattered to
//! those free DOFs`)`.
//!
//! `Q` holds `Z` too: `Z = Q_1 R_11` (`R` is upper triangular), so the pair solves it was
//! built on can give up their copy ([`PairSolves::share_normals_with`]).
//!
//! `Q` is computed by Cholesky QR twice (the second pass restores orthonormality to
//! rounding when `[Z | X]` is ill-conditioned) on columns scaled to unit `M` norm; when a
//! pass's Gram matrix is not numerically positive definite (dependent responses) there is
//! no static space and the caller builds its basis explicitly.

use super::tied::{PairSolves, TiedSolve};
use super::{m_orthonormalize, par, tmul};
use crate::contact::{FreeModel, ImplicitColumns};
use crate::linalg::{sparse_transpose_times, symmetric_times};
use crate::operator::FrictionalOperator;
use crate::{c64, Error, Result, SparseMat, SparseRef};
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{matmul as tri_matmul, BlockStructure};
use faer::sparse::Triplet;
use faer::{Accum, Mat, MatRef, Side};
use std::sync::Arc;
use std::time::Instant;

/// Columns of `[Z | X]` whose `M` images are formed together.
const BLOCK: usize = 64;
/// Rows of `Q` transformed together (a bounded workspace).
const ROWS: usize = 4096;

/// The static space of a model (module docs).
pub struct StaticSpace {
    /// `Q` (`n x 2 nR`), `M`-orthonormal: first the `Z` part, then the `X` part.
    q: Arc<Mat<f64>>,
    /// `R` (`2 nR x 2 nR`, upper triangular): `[Z | X] = Q R`.
    r: Mat<f64>,
    /// `Q^T K Q`.
    qkq: Mat<f64>,
    /// `C X` (`nR x nR`): the normal gaps of the friction responses.
    cx: Mat<f64>,
    /// Rows `E_s M Q` and `E_s K Q` (`nR x 2 nR`) at the pins' normal DOFs.
    es_q: [Mat<f64>; 2],
    /// The columns of `M` and `K` at the pins' normal DOFs (row, value), for `E_s X y` of
    /// other vectors.
    es_cols: [Vec<Vec<(usize, f64)>>; 2],
    /// Wall time of the construction (s).
    pub time_s: f64,
}

impl std::fmt::Debug for StaticSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StaticSpace")
            .field("dofs", &self.q.nrows())
            .field("columns", &self.q.ncols())
            .finish()
    }
}

/// `G = A^T X A` (`c x c`) for a symmetric `X`, the images `X A` a block of columns at
/// a time (the upper triangle computed, the lower mirrored).
fn gram(m: SparseRef<'_>, a: MatRef<'_, f64>) -> Mat<f64> {
    let c = a.ncols();
    let mut g = Mat::<f64>::zeros(c, c);
    let mut c0 = 0;
    while c0 < c {
        let b = BLOCK.min(c - c0);
        let mb = symmetric_times(m, a.subcols(c0, b));
        matmul(
            g.as_mut().submatrix_mut(0, c0, c0 + b, b),
            Accum::Replace,
            a.subcols(0, c0 + b).transpose(),
            mb.as_ref(),
            1.0,
            par(),
        );
        c0 += b;
    }
    for j in 0..c {
        for i in j + 1..c {
            g[(i, j)] = g[(j, i)];
        }
    }
    g
}

/// One Cholesky QR step in place: `A <- A R^-1` with `g = A^T M A = R^T R`; returns `R`
/// (upper triangular), or `None` when `g` is not numerically positive definite.
fn cholesky_qr_step(a: &mut Mat<f64>, g: Mat<f64>) -> Option<Mat<f64>> {
    let c = a.ncols();
    let llt = g.llt(Side::Lower).ok()?;
    let l = llt.L().to_owned();
    let lmax = (0..c).map(|i| l[(i, i)]).fold(0.0f64, f64::max);
    let lmin = (0..c).map(|i| l[(i, i)]).fold(f64::INFINITY, f64::min);
    // a NaN fails this test too
    if lmin.is_nan() || lmin <= 1e-7 * lmax {
        return None;
    }
    // R^-1 = (L^-1)^T, upper triangular
    let mut linv = Mat::<f64>::identity(c, c);
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(
        l.as_ref(),
        linv.as_mut(),
        par(),
    );
    let rinv = linv.transpose().to_owned();
    let n = a.nrows();
    let mut r0 = 0;
    while r0 < n {
        let h = ROWS.min(n - r0);
        let mut tmp = Mat::<f64>::zeros(h, c);
        tri_matmul(
            tmp.as_mut(),
            BlockStructure::Rectangular,
            Accum::Replace,
            a.as_ref().subrows(r0, h),
            BlockStructure::Rectangular,
            rinv.as_ref(),
            BlockStructure::TriangularUpper,
            1.0,
            par(),
        );
        a.as_mut().subrows_mut(r0, h).copy_from(tmp.as_ref());
        r0 += h;
    }
    Some(l.transpose().to_owned())
}

/// The columns of a symmetric sparse `x` at `dofs` (rows and values).
fn columns_at(x: SparseRef<'_>, dofs: &[usize]) -> Vec<Vec<(usize, f64)>> {
    dofs.iter()
        .map(|&d| {
            x.row_idx_of_col(d)
                .zip(x.val_of_col(d).iter().copied())
                .collect()
        })
        .collect()
}

/// `E_s X y` for the kept columns `cols` of `X` (one row per pair) and free vectors `y`.
fn es_times(cols: &[Vec<(usize, f64)>], y: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(cols.len(), y.ncols(), |i, c| {
        cols[i].iter().map(|&(r, v)| v * y[(r, c)]).sum()
    })
}

impl StaticSpace {
    /// Builds the static space of `free` from its pair solves (`pairs`; the responses to
    /// every candidate pair's friction load are solved here, one block solve, and not
    /// kept).
    /// `Ok(None)` when the responses are numerically dependent or `Q` would pass
    /// [`PAIR_SOLVES_LIMIT_BYTES`](super::PAIR_SOLVES_LIMIT_BYTES) (no static space).
    pub fn new(free: &FreeModel<'_>, pairs: &PairSolves) -> Result<Option<Self>> {
        let start = Instant::now();
        let (n, nr) = (pairs.dim(), pairs.pairs());
        if free.k.nrows() != n || free.m.nrows() != n || free.pairs.len() != nr {
            return Err(Error::Dimension {
                context: "static space: the free model against its pair solves".into(),
                expected: n,
                got: free.k.nrows(),
            });
        }
        let nq = 2 * nr;
        if n.saturating_mul(nq).saturating_mul(8) > super::PAIR_SOLVES_LIMIT_BYTES {
            return Ok(None);
        }
        let mut a = Mat::<f64>::zeros(n, nq);
        pairs.normal_responses_into(a.as_mut().subcols_mut(0, nr));
        let all: Vec<usize> = (0..nr).collect();
        pairs.friction_responses_into(&all, a.as_mut().subcols_mut(nr, nr));
        let normals = pairs.normal_dofs();
        let cx = Mat::from_fn(nr, nr, |i, j| {
            a[(normals[i].0, nr + j)] - a[(normals[i].1, nr + j)]
        });
        // unit M norms first, so that the Cholesky QR judges directions only
        let g = gram(free.m, a.as_ref());
        let d: Vec<f64> = (0..nq).map(|c| g[(c, c)].max(0.0).sqrt()).collect();
        if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Ok(None);
        }
        for (c, &dc) in d.iter().enumerate() {
            a.col_mut(c).iter_mut().for_each(|v| *v /= dc);
        }
        let g = Mat::from_fn(nq, nq, |i, j| g[(i, j)] / (d[i] * d[j]));
        let Some(r1) = cholesky_qr_step(&mut a, g) else {
            return Ok(None);
        };
        // the second pass restores the orthonormality the first lost to rounding
        let g = gram(free.m, a.as_ref());
        let Some(r2) = cholesky_qr_step(&mut a, g) else {
            return Ok(None);
        };
        // R = R2 R1 D
        let mut r = Mat::<f64>::zeros(nq, nq);
        tri_matmul(
            r.as_mut(),
            BlockStructure::TriangularUpper,
            Accum::Replace,
            r2.as_ref(),
            BlockStructure::TriangularUpper,
            r1.as_ref(),
            BlockStructure::TriangularUpper,
            1.0,
            par(),
        );
        for (c, &dc) in d.iter().enumerate() {
            r.col_mut(c).iter_mut().for_each(|v| *v *= dc);
        }
        let qkq = gram(free.k, a.as_ref());
        let pins: Vec<usize> = free.pairs.iter().map(|p| p.pin[2]).collect();
        let es_cols = [columns_at(free.m, &pins), columns_at(free.k, &pins)];
        let es_q = [
            es_times(&es_cols[0], a.as_ref()),
            es_times(&es_cols[1], a.as_ref()),
        ];
        Ok(Some(Self {
            q: Arc::new(a),
            r,
            qkq,
            cx,
            es_q,
            es_cols,
            time_s: start.elapsed().as_secs_f64(),
        }))
    }

    /// Columns of `Q` (`2 nR`).
    pub fn dim(&self) -> usize {
        self.q.ncols()
    }

    /// Number of candidate pairs.
    pub fn pairs(&self) -> usize {
        self.cx.nrows()
    }

    /// `Q` and the leading `nR x nR` block `R_11` of `R`: `Z = Q_1 R_11`
    /// ([`PairSolves::share_normals_with`]).
    pub(crate) fn normal_factors(&self) -> (Arc<Mat<f64>>, Mat<f64>) {
        let nr = self.pairs();
        (
            self.q.clone(),
            self.r.as_ref().submatrix(0, 0, nr, nr).to_owned(),
        )
    }

    /// The coordinates in `Q` of the tied static responses to the friction loads of the
    /// active pairs of `tied` (`2 nR x nA`, one column per active pair in its order).
    pub fn tied_statics(&self, tied: &TiedSolve<'_>) -> Mat<f64> {
        let nr = self.pairs();
        let active = tied.active();
        let na = active.len();
        // lambda = -S_AA^-1 (C X)_{A, A}
        let mut lambda = Mat::from_fn(na, na, |i, j| -self.cx[(active[i], active[j])]);
        tied.solve_pairs(lambda.as_mut());
        let rn = Mat::from_fn(self.dim(), na, |i, k| self.r[(i, active[k])]);
        let mut c = Mat::from_fn(self.dim(), na, |i, k| self.r[(i, nr + active[k])]);
        matmul(
            c.as_mut(),
            Accum::Add,
            rn.as_ref(),
            lambda.as_ref(),
            1.0,
            par(),
        );
        c
    }

    /// The implicit basis of `op` made of the static directions `Q coords` (orthonormalized
    /// with the rank cut) and the explicit columns `extra` (`n_c x e`, `M_c`-orthonormal;
    /// orthogonalized against the static ones, then cut), with `op` projected on it.
    /// `op` must be undamped, with its friction loads; `tied` is its tied solve
    /// ([`PairSolves::on`]: its active pairs and one free DOF of each constrained DOF).
    pub fn basis(
        &self,
        op: &FrictionalOperator,
        tied: &TiedSolve<'_>,
        coords: MatRef<'_, f64>,
        extra: MatRef<'_, f64>,
        rank_tol: f64,
    ) -> Result<StaticBasis> {
        let u = op.friction_loads.as_ref().ok_or_else(|| {
            Error::Invalid("static space: the operator has no friction loads".into())
        })?;
        if op.cc.is_some() {
            return Err(Error::Invalid(
                "static space: a damped operator is projected explicitly".into(),
            ));
        }
        let (n, nc) = (self.q.nrows(), op.dim());
        let (active, rep) = (tied.active(), tied.rep());
        if rep.len() != nc || extra.nrows() != nc || coords.nrows() != self.dim() {
            return Err(Error::Dimension {
                context: "static space: the operator's constrained DOFs".into(),
                expected: nc,
                got: rep.len(),
            });
        }
        if u.ncols() != active.len() || active.iter().any(|&i| i >= self.pairs()) {
            return Err(Error::Invalid(format!(
                "static space: {} friction loads for {} active pairs of {} candidates",
                u.ncols(),
                active.len(),
                self.pairs()
            )));
        }
        // the static directions, orthonormal in the coordinates of Q
        let ident = identity(self.dim())?;
        let (w, dropped_statics) = m_orthonormalize(ident.as_ref(), coords, rank_tol)?;
        let q = self.q.as_ref().as_ref();
        // Q^T of constrained vectors scattered onto their free DOFs
        let qt = |x: MatRef<'_, f64>| -> Mat<f64> {
            let mut v = Mat::<f64>::zeros(n, x.ncols());
            for (c, &j) in rep.iter().enumerate() {
                for k in 0..x.ncols() {
                    v[(j, k)] = x[(c, k)];
                }
            }
            tmul(q, v.as_ref())
        };
        // the explicit columns orthogonalized against Q W (twice), then cut at rank_tol of
        // their unit norm and orthonormalized among themselves
        let mut e = extra.to_owned();
        for _ in 0..2 {
            let me = symmetric_times(op.mc.as_ref(), e.as_ref());
            let coef = tmul(w.as_ref(), qt(me.as_ref()).as_ref());
            let y = mul(q, mul(w.as_ref(), coef.as_ref()).as_ref());
            for (c, &j) in rep.iter().enumerate() {
                for k in 0..e.ncols() {
                    e[(c, k)] -= y[(j, k)];
                }
            }
        }
        let me = symmetric_times(op.mc.as_ref(), e.as_ref());
        let keep: Vec<usize> = (0..e.ncols())
            .filter(|&k| {
                let s: f64 = (0..nc).map(|i| e[(i, k)] * me[(i, k)]).sum();
                s.max(0.0).sqrt() >= rank_tol
            })
            .collect();
        let kept = Mat::from_fn(nc, keep.len(), |i, k| e[(i, keep[k])]);
        let (v, dropped_in) = m_orthonormalize(op.mc.as_ref(), kept.as_ref(), rank_tol)?;
        let dropped_extra = extra.ncols() - keep.len() + dropped_in;
        let (ns, ne) = (w.ncols(), v.ncols());
        let m = ns + ne;
        // projections: statics block in coordinates, cross terms through Q^T, extra block
        let mv = symmetric_times(op.mc.as_ref(), v.as_ref());
        let kv = symmetric_times(op.kc.as_ref(), v.as_ref());
        let block = |ss: Mat<f64>, xv: &Mat<f64>| -> Mat<f64> {
            let se = tmul(w.as_ref(), qt(xv.as_ref()).as_ref());
            let ee = tmul(v.as_ref(), xv.as_ref());
            Mat::from_fn(m, m, |i, j| match (i < ns, j < ns) {
                (true, true) => 0.5 * (ss[(i, j)] + ss[(j, i)]),
                (true, false) => se[(i, j - ns)],
                (false, true) => se[(j, i - ns)],
                (false, false) => 0.5 * (ee[(i - ns, j - ns)] + ee[(j - ns, i - ns)]),
            })
        };
        let mp = block(tmul(w.as_ref(), w.as_ref()), &mv);
        let kp = block(
            tmul(w.as_ref(), mul(self.qkq.as_ref(), w.as_ref()).as_ref()),
            &kv,
        );
        // friction parts F_X = U V_X^T: U^T B from the rows of B at U's rows, V_X^T B from
        // the pins' normal rows of X Q and of X (T v)
        let urows: Vec<usize> = {
            let mut r: Vec<usize> = (0..u.ncols())
                .flat_map(|c| u.row_idx_of_col_raw(c).iter().copied())
                .collect();
            r.sort_unstable();
            r.dedup();
            r
        };
        let qrows = Mat::from_fn(urows.len(), self.dim(), |i, k| q[(rep[urows[i]], k)]);
        let bs_rows = mul(qrows.as_ref(), w.as_ref());
        let mut pos = vec![usize::MAX; nc];
        for (i, &r) in urows.iter().enumerate() {
            pos[r] = i;
        }
        let na = u.ncols();
        let mut utb = Mat::<f64>::zeros(na, m);
        let utv = sparse_transpose_times(u.as_ref(), v.as_ref());
        for c in 0..na {
            for (&r, &val) in u.row_idx_of_col_raw(c).iter().zip(u.val_of_col(c)) {
                for k in 0..ns {
                    utb[(c, k)] += val * bs_rows[(pos[r], k)];
                }
            }
            for k in 0..ne {
                utb[(c, ns + k)] = utv[(c, k)];
            }
        }
        let vfree = super::to_free_dofs(op, v.as_ref()).ok_or_else(|| {
            Error::Invalid("static space: explicit columns on the free DOFs".into())
        })?;
        let vx = |x: usize| -> Mat<f64> {
            let sel = Mat::from_fn(na, self.dim(), |i, k| self.es_q[x][(active[i], k)]);
            let s = mul(sel.as_ref(), w.as_ref());
            // every candidate pair's row (a few hundred sparse dots), the active ones read
            let e = es_times(&self.es_cols[x], vfree.as_ref());
            Mat::from_fn(na, m, |i, k| {
                if k < ns {
                    s[(i, k)]
                } else {
                    e[(active[i], k - ns)]
                }
            })
        };
        let fm = tmul(utb.as_ref(), vx(0).as_ref());
        let fk = tmul(utb.as_ref(), vx(1).as_ref());
        let sparse = |x: Mat<f64>| super::dense_to_sparse(x.as_ref());
        let projected = FrictionalOperator {
            mc: sparse(mp)?,
            cc: None,
            kc: sparse(kp)?,
            fm: sparse(fm)?,
            fc: None,
            fk: sparse(fk)?,
            t: None,
            friction_loads: Some(sparse(utb.transpose().to_owned())?),
            modal: Default::default(),
        };
        Ok(StaticBasis {
            columns: StaticColumns {
                q: self.q.clone(),
                w,
                v,
                rep: rep.to_vec(),
            },
            projected,
            dropped_statics,
            dropped_extra,
        })
    }
}

/// The sparse identity of size `n`.
fn identity(n: usize) -> Result<SparseMat> {
    let t: Vec<Triplet<usize, usize, f64>> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    SparseMat::try_new_from_triplets(n, n, &t)
        .map_err(|e| Error::Invalid(format!("identity: {e:?}")))
}

/// `a b`.
fn mul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut c = Mat::<f64>::zeros(a.nrows(), b.ncols());
    if a.ncols() > 0 {
        matmul(c.as_mut(), Accum::Replace, a, b, 1.0, par());
    }
    c
}

/// A contact set's basis in a [`StaticSpace`] ([`StaticSpace::basis`]): its columns kept
/// implicit, the operator projected on them, and what the rank cuts dropped.
pub struct StaticBasis {
    /// The columns `[Q W | V]` on the constrained DOFs.
    pub columns: StaticColumns,
    /// The operator projected on them.
    pub projected: FrictionalOperator,
    /// Static directions dropped by the rank cut.
    pub dropped_statics: usize,
    /// Explicit columns dropped (inside the static directions' span, or dependent).
    pub dropped_extra: usize,
}

/// The columns `[(Q W)_c | V]` of a [`StaticBasis`]: `Q W` on the free DOFs read at one
/// free DOF of each constrained DOF, `V` explicit.
pub struct StaticColumns {
    q: Arc<Mat<f64>>,
    w: Mat<f64>,
    v: Mat<f64>,
    rep: Vec<usize>,
}

impl StaticColumns {
    /// Number of static columns (`Q W`).
    pub fn statics(&self) -> usize {
        self.w.ncols()
    }

    /// Number of explicit columns.
    pub fn explicit(&self) -> usize {
        self.v.ncols()
    }
}

impl std::fmt::Debug for StaticColumns {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StaticColumns")
            .field("constrained_dofs", &self.rep.len())
            .field("statics", &self.w.ncols())
            .field("explicit", &self.v.ncols())
            .finish()
    }
}

impl ImplicitColumns for StaticColumns {
    fn nrows(&self) -> usize {
        self.rep.len()
    }

    fn ncols(&self) -> usize {
        self.w.ncols() + self.v.ncols()
    }

    fn apply(&self, x: MatRef<'_, c64>) -> Result<Mat<c64>> {
        if x.nrows() != self.ncols() {
            return Err(Error::Dimension {
                context: "static basis: reduced vectors".into(),
                expected: self.ncols(),
                got: x.nrows(),
            });
        }
        let (ns, k) = (self.w.ncols(), x.ncols());
        let parts = Mat::from_fn(ns, 2 * k, |i, j| {
            if j < k {
                x[(i, j)].re
            } else {
                x[(i, j - k)].im
            }
        });
        let y = mul(
            self.q.as_ref().as_ref(),
            mul(self.w.as_ref(), parts.as_ref()).as_ref(),
        );
        let mut out = crate::linalg::expand(self.v.as_ref(), x.subrows(ns, self.v.ncols()));
        for (c, &j) in self.rep.iter().enumerate() {
            for col in 0..k {
                out[(c, col)] += c64::new(y[(j, col)], y[(j, k + col)]);
            }
        }
        Ok(out)
    }
}
