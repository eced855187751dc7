//! Backward errors of QEP eigenpairs (formula in the module docs of [`crate::qep`]): one
//! pair ([`backward_error`]) or a batch at once, on an assembled problem or on the parts
//! `X_c - mu F_X` of a frictional operator without assembling it.

use crate::linalg::norm1;
use crate::linalg::{norm2_c, spmv_complex, spmv_complex_add};
use crate::operator::{FrictionalOperator, Qep};
use crate::{c64, SparseMat, SparseRef};
use faer::{Mat, MatRef};

/// The three norms entering the backward error (1-norms), and upper bounds of the
/// 2-norms of `M` and `C` (`sqrt(||X||_1 ||X||_inf)`) for the smallest condition number
/// an eigenvalue can have ([`QepNorms::cond_floor`]).
pub(super) struct QepNorms {
    pub(super) m: f64,
    pub(super) c: f64,
    pub(super) k: f64,
    pub(super) m2: f64,
    pub(super) c2: f64,
}

/// `||A||_inf`, the largest row sum of `|a_ij|`.
fn norm_inf(a: SparseRef<'_>) -> f64 {
    let mut rows = vec![0.0f64; a.nrows()];
    for j in 0..a.ncols() {
        for (&i, v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            rows[i] += v.abs();
        }
    }
    rows.into_iter().fold(0.0, f64::max)
}

impl QepNorms {
    /// The smallest condition number (`ComplexModes::cond`) an eigenvalue `lambda` can
    /// have: `|y^H Q'(lambda) x| <= ||y|| ||x|| (2 |lambda| ||M||_2 + ||C||_2)`, so
    /// `cond >= (|l|^2 ||M|| + |l| ||C|| + ||K||) / (|l| (2 |l| ||M||_2 + ||C||_2))`, and
    /// never below [`MIN_COND`](crate::operator::MIN_COND). For a finite element model,
    /// whose `||K|| / ||M||` is the square of its highest frequency, this is large for the
    /// modes of the band.
    pub(super) fn cond_floor(&self, lambda: c64) -> f64 {
        let al = lambda.norm();
        let den = al * (2.0 * al * self.m2 + self.c2);
        let w = al * al * self.m + al * self.c + self.k;
        let floor = if den > 0.0 { w / den } else { f64::NAN };
        if floor.is_finite() {
            floor.max(crate::operator::MIN_COND)
        } else {
            crate::operator::MIN_COND
        }
    }

    /// The backward error `||r|| / ((|l|^2 ||M|| + |l| ||C|| + ||K||) ||u||)` from the
    /// residual norm `num` and the vector norm `un`; `0` for a zero residual on a zero
    /// scale, infinite for a nonzero one.
    fn relative(&self, lambda: c64, num: f64, un: f64) -> f64 {
        let al = lambda.norm();
        let den = (al * al * self.m + al * self.c + self.k) * un;
        if den > 0.0 {
            num / den
        } else if num == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }

    pub(super) fn of(qep: &Qep) -> Self {
        let two = |a: SparseRef<'_>| (norm1(a) * norm_inf(a)).sqrt();
        Self {
            m: norm1(qep.m.as_ref()),
            c: qep.c.as_ref().map_or(0.0, |c| norm1(c.as_ref())),
            k: norm1(qep.k.as_ref()),
            m2: two(qep.m.as_ref()),
            c2: qep.c.as_ref().map_or(0.0, |c| two(c.as_ref())),
        }
    }
}

/// A QEP as sums of scaled sparse parts (`M~ = sum a_i M_i`, same for `C~`, `K~`), so
/// that the modes of a frictional operator at mu are checked on `X_c - mu F_X` without
/// assembling it.
pub(super) struct QepTerms<'a> {
    pub(super) n: usize,
    pub(super) m: Vec<(SparseRef<'a>, f64)>,
    pub(super) c: Vec<(SparseRef<'a>, f64)>,
    pub(super) k: Vec<(SparseRef<'a>, f64)>,
}

impl<'a> QepTerms<'a> {
    pub(super) fn of_qep(qep: &'a Qep) -> Self {
        Self {
            n: qep.dim(),
            m: vec![(qep.m.as_ref(), 1.0)],
            c: qep.c.iter().map(|c| (c.as_ref(), 1.0)).collect(),
            k: vec![(qep.k.as_ref(), 1.0)],
        }
    }

    /// The parts of `op.at(mu)` (the caller checks `mu`).
    pub(super) fn of_operator(op: &'a FrictionalOperator, mu: f64) -> Self {
        let pair = |x: &'a SparseMat, f: &'a SparseMat| vec![(x.as_ref(), 1.0), (f.as_ref(), -mu)];
        let mut c: Vec<(SparseRef<'a>, f64)> = op.cc.iter().map(|c| (c.as_ref(), 1.0)).collect();
        c.extend(op.fc.iter().map(|f| (f.as_ref(), -mu)));
        Self {
            n: op.dim(),
            m: pair(&op.mc, &op.fm),
            c,
            k: pair(&op.kc, &op.fk),
        }
    }

    /// `||sum a_i A_i||_1` without assembling the sum (a dense column accumulator).
    fn norm1(&self, terms: &[(SparseRef<'_>, f64)]) -> f64 {
        match terms {
            [] => 0.0,
            [(a, s)] => s.abs() * norm1(*a),
            _ => {
                let mut acc = vec![0.0; self.n];
                let mut touched = Vec::new();
                let mut best = 0.0f64;
                for j in 0..self.n {
                    // a column only one term has entries in (all but the pairs' columns
                    // of the friction parts): its sum directly, the same bits
                    let mut with = terms
                        .iter()
                        .filter(|(a, _)| !a.row_idx_of_col_raw(j).is_empty());
                    if let (Some((a, s)), None) = (with.next(), with.next()) {
                        let sum: f64 = a.val_of_col(j).iter().map(|v| (s * v).abs()).sum();
                        best = best.max(sum);
                        continue;
                    }
                    for (a, s) in terms {
                        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
                            if acc[i] == 0.0 {
                                touched.push(i);
                            }
                            acc[i] += s * v;
                        }
                    }
                    let sum: f64 = touched.iter().map(|&i| acc[i].abs()).sum();
                    best = best.max(sum);
                    touched.drain(..).for_each(|i| acc[i] = 0.0);
                }
                best
            }
        }
    }

    pub(super) fn norms(&self) -> QepNorms {
        // ||sum a_i A_i||_inf <= sum |a_i| ||A_i||_inf: an upper bound suits the floor
        let inf = |terms: &[(SparseRef<'_>, f64)]| -> f64 {
            terms.iter().map(|(a, s)| s.abs() * norm_inf(*a)).sum()
        };
        let (m, c) = (self.norm1(&self.m), self.norm1(&self.c));
        QepNorms {
            m,
            c,
            k: self.norm1(&self.k),
            m2: (m * inf(&self.m)).sqrt(),
            c2: (c * inf(&self.c)).sqrt(),
        }
    }
}

pub(super) fn backward_error_with(qep: &Qep, norms: &QepNorms, lambda: c64, u: &[c64]) -> f64 {
    let n = qep.dim();
    assert_eq!(u.len(), n, "backward_error: vector of the wrong length");
    // r = K u + lambda (C u + lambda M u)
    let mut t = vec![c64::new(0.0, 0.0); n];
    spmv_complex(qep.m.as_ref(), u, &mut t);
    t.iter_mut().for_each(|v| *v *= lambda);
    if let Some(c) = &qep.c {
        spmv_complex_add(c.as_ref(), u, &mut t);
    }
    t.iter_mut().for_each(|v| *v *= lambda);
    spmv_complex_add(qep.k.as_ref(), u, &mut t);
    norms.relative(lambda, norm2_c(&t), norm2_c(u))
}

/// Backward errors of the pairs `(lambda[j], u[:, j])` on `qep`, the same numbers as
/// [`backward_error`] one by one ([`check_pairs`] without left vectors).
#[cfg(test)]
pub(super) fn backward_errors(
    qep: &QepTerms<'_>,
    norms: &QepNorms,
    lambda: &[c64],
    u: MatRef<'_, c64>,
) -> Vec<f64> {
    check_pairs(qep, norms, lambda, u, None, true).0
}

/// `|y^H Q'(lambda) x|`, `||x||`, `||y||` of one pair with its left vector `y`
/// (`Q'(lambda) = 2 lambda M + C`): what its condition number needs.
pub(super) type DerivativeProducts = (f64, f64, f64);

/// The backward errors of the pairs `(lambda[j], u[:, j])` on `qep` (when `backward`;
/// else empty) and, with their left vectors `left`, the [`DerivativeProducts`] of each,
/// from one pass over each matrix for all vectors at once (real and imaginary parts as
/// `2 k` right-hand sides stored row by row, so every nonzero updates a contiguous row)
/// instead of `2 k` serial sparse products: the per-mu cost of reduced solves is
/// dominated by this check, and the backward errors and the condition numbers share the
/// products with `M` and `C`. The right-hand sides are split between two threads.
pub(super) fn check_pairs(
    qep: &QepTerms<'_>,
    norms: &QepNorms,
    lambda: &[c64],
    u: MatRef<'_, c64>,
    left: Option<MatRef<'_, c64>>,
    backward: bool,
) -> (Vec<f64>, Vec<DerivativeProducts>) {
    let (n, k) = (u.nrows(), u.ncols());
    let per_pair = in_two_halves(k, |lo, hi| {
        let w = hi - lo;
        let x = interleave(u, lo, hi);
        let mx = terms_times(n, &qep.m, &x, w);
        let kx = backward.then(|| terms_times(n, &qep.k, &x, w));
        let cx = (!qep.c.is_empty()).then(|| terms_times(n, &qep.c, &x, w));
        let (mut num, mut un) = (vec![0.0; w], vec![0.0; w]);
        let (mut d, mut ny) = (vec![c64::new(0.0, 0.0); w], vec![0.0; w]);
        for i in 0..n {
            for j in 0..w {
                let l = lambda[lo + j];
                let m = at(&mx, w, i, j);
                let c = cx.as_ref().map(|cx| at(cx, w, i, j));
                if let Some(kx) = &kx {
                    let mut t = m * l;
                    if let Some(c) = c {
                        t += c;
                    }
                    num[j] += (t * l + at(kx, w, i, j)).norm_sqr();
                }
                un[j] += at(&x, w, i, j).norm_sqr();
                if let Some(y) = left {
                    let mut t = m * (l * 2.0);
                    if let Some(c) = c {
                        t += c;
                    }
                    let yi = y[(i, lo + j)];
                    d[j] += yi.conj() * t;
                    ny[j] += yi.norm_sqr();
                }
            }
        }
        (0..w)
            .map(|j| {
                let be = norms.relative(lambda[lo + j], num[j].sqrt(), un[j].sqrt());
                (be, (d[j].norm(), un[j].sqrt(), ny[j].sqrt()))
            })
            .collect()
    });
    let be = if backward {
        per_pair.iter().map(|p| p.0).collect()
    } else {
        Vec::new()
    };
    let products = if left.is_some() {
        per_pair.into_iter().map(|p| p.1).collect()
    } else {
        Vec::new()
    };
    (be, products)
}

/// Columns `[lo, hi)` of `u` as interleaved `(re, im)` rows of width `2 (hi - lo)`.
pub(super) fn interleave(u: MatRef<'_, c64>, lo: usize, hi: usize) -> Vec<f64> {
    (0..u.nrows())
        .flat_map(|i| (lo..hi).flat_map(move |j| [u[(i, j)].re, u[(i, j)].im]))
        .collect()
}

/// Entry `(i, j)` of `w` interleaved complex columns.
pub(super) fn at(y: &[f64], w: usize, i: usize, j: usize) -> c64 {
    c64::new(y[i * 2 * w + 2 * j], y[i * 2 * w + 2 * j + 1])
}

/// `sum s_i A_i X` for `w` interleaved complex columns `x`: one pass over each matrix
/// for all columns, every nonzero updating a contiguous row.
pub(super) fn terms_times(
    n: usize,
    terms: &[(SparseRef<'_>, f64)],
    x: &[f64],
    w: usize,
) -> Vec<f64> {
    let mut y = vec![0.0; n * 2 * w];
    for (a, s) in terms {
        for c in 0..a.ncols() {
            let xc = &x[c * 2 * w..(c + 1) * 2 * w];
            for (&i, &v) in a.row_idx_of_col_raw(c).iter().zip(a.val_of_col(c)) {
                let yi = &mut y[i * 2 * w..(i + 1) * 2 * w];
                let v = s * v;
                yi.iter_mut().zip(xc).for_each(|(y, x)| *y += v * x);
            }
        }
    }
    y
}

/// `block(lo, hi)` over the `k` columns split between two threads, results in order.
pub(super) fn in_two_halves<T: Send>(
    k: usize,
    block: impl Fn(usize, usize) -> Vec<T> + Sync,
) -> Vec<T> {
    if k == 0 {
        return Vec::new();
    }
    let mid = k / 2;
    if mid == 0 {
        return block(0, k);
    }
    let (mut first, second) = std::thread::scope(|s| {
        let h = s.spawn(|| block(mid, k));
        (block(0, mid), h.join().expect("column block thread"))
    });
    first.extend(second);
    first
}

/// `Q(lambda_j) x_j` and `Q'(lambda_j) x_j = (2 lambda_j M + C) x_j` for the columns `x_j`
/// of `x`, on the parts of `op` at `mu` without assembling them (one pass over each part
/// for all columns).
pub fn residuals_and_derivatives(
    op: &FrictionalOperator,
    mu: f64,
    lambda: &[c64],
    x: MatRef<'_, c64>,
) -> (Mat<c64>, Mat<c64>) {
    let terms = QepTerms::of_operator(op, mu);
    let (n, w) = (x.nrows(), x.ncols());
    let xi = interleave(x, 0, w);
    let mx = terms_times(n, &terms.m, &xi, w);
    let kx = terms_times(n, &terms.k, &xi, w);
    let cx = (!terms.c.is_empty()).then(|| terms_times(n, &terms.c, &xi, w));
    let c_at = |i, j| cx.as_ref().map_or(c64::new(0.0, 0.0), |cx| at(cx, w, i, j));
    let r = Mat::from_fn(n, w, |i, j| {
        let l = lambda[j];
        at(&kx, w, i, j) + l * (c_at(i, j) + l * at(&mx, w, i, j))
    });
    let d = Mat::from_fn(n, w, |i, j| c_at(i, j) + lambda[j] * 2.0 * at(&mx, w, i, j));
    (r, d)
}

/// Backward error of `(lambda, u)` on `qep` (see module docs).
pub fn backward_error(qep: &Qep, lambda: c64, u: &[c64]) -> f64 {
    backward_error_with(qep, &QepNorms::of(qep), lambda, u)
}
