//! The friction part as an explicit low-rank product `F_K = U W_K^T`, `F_M = U W_M^T`
//! ([`FrictionLowRank`]).

use crate::linalg::norm1;
use crate::operator::FrictionalOperator;
use crate::{Error, Result, SparseMat, SparseRef};
use faer::sparse::Triplet;

/// Relative error of `U W^T` against `F_K` / `F_M` above which the friction part is not
/// considered recovered ([`FrictionLowRank::new`]).
pub const MAX_IDENTITY_ERROR: f64 = 1e-10;

/// The friction part as an explicit low-rank product: `F_K = U W_K^T`, `F_M = U W_M^T`,
/// `U = T^T P~t^T` (`n x nA`), `W_K`, `W_M` sparse `n x nA`.
#[derive(Debug, Clone)]
pub struct FrictionLowRank {
    /// The friction load directions `U` (one column per active pair).
    pub u: SparseMat,
    /// `W_K` with `F_K = U W_K^T`.
    pub wk: SparseMat,
    /// `W_M` with `F_M = U W_M^T`.
    pub wm: SparseMat,
    /// Measured `max(||F_K x - U W_K^T x|| / (||F_K||_1 ||x||), same for F_M)` on probe
    /// vectors.
    pub identity_error: f64,
}

impl FrictionLowRank {
    /// Recovers `W_K` and `W_M` from `op.fk`, `op.fm` and `op.friction_loads`: the row `r`
    /// of the largest `|U_ri|` of column `i` carries only pair `i`, so
    /// `w_i^T = F_X[r, :] / U[r, i]`. Fails when `friction_loads` is missing, when such a
    /// row is shared by two columns, or when the recovered product does not reproduce
    /// `F_K` and `F_M` (relative error above [`MAX_IDENTITY_ERROR`]).
    pub fn new(op: &FrictionalOperator) -> Result<Self> {
        let n = op.dim();
        let u = op.friction_loads.as_ref().ok_or_else(|| {
            Error::Invalid("low-rank friction: the operator has no friction_loads (U)".into())
        })?;
        if u.nrows() != n {
            return Err(Error::Dimension {
                context: "low-rank friction: rows of friction_loads".into(),
                expected: n,
                got: u.nrows(),
            });
        }
        let na = u.ncols();
        let ur = u.as_ref();
        let mut row_count = vec![0usize; n];
        for j in 0..na {
            for (i, v) in ur.row_idx_of_col(j).zip(ur.val_of_col(j)) {
                if *v != 0.0 {
                    row_count[i] += 1;
                }
            }
        }
        // pivot row of each column -> (column, 1 / U[r, column])
        let mut pivot_of_row: Vec<Option<(usize, f64)>> = vec![None; n];
        for j in 0..na {
            let best = ur
                .row_idx_of_col(j)
                .zip(ur.val_of_col(j))
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
            let Some((r, &v)) = best else { continue };
            if v == 0.0 {
                continue;
            }
            if row_count[r] != 1 || pivot_of_row[r].is_some() {
                return Err(Error::Invalid(format!(
                    "low-rank friction: row {r} of U is shared by several pairs (column {j})"
                )));
            }
            pivot_of_row[r] = Some((j, 1.0 / v));
        }
        let recover = |f: SparseRef<'_>| -> Result<SparseMat> {
            let mut trip = Vec::new();
            for c in 0..n {
                for (r, v) in f.row_idx_of_col(c).zip(f.val_of_col(c)) {
                    if let Some((j, inv)) = pivot_of_row[r] {
                        trip.push(Triplet::new(c, j, v * inv));
                    }
                }
            }
            SparseMat::try_new_from_triplets(n, na, &trip)
                .map_err(|e| Error::Invalid(format!("low-rank friction: {e:?}")))
        };
        let wk = recover(op.fk.as_ref())?;
        let wm = recover(op.fm.as_ref())?;
        let mut out = Self {
            u: u.clone(),
            wk,
            wm,
            identity_error: 0.0,
        };
        out.identity_error = out
            .product_error(op.fk.as_ref(), false)
            .max(out.product_error(op.fm.as_ref(), true));
        if out.identity_error.is_nan() || out.identity_error > MAX_IDENTITY_ERROR {
            return Err(Error::Invalid(format!(
                "low-rank friction: U W^T reproduces F_K / F_M only to {:.2e} (relative)",
                out.identity_error
            )));
        }
        Ok(out)
    }

    /// Rank `nA` (number of active pairs).
    pub fn rank(&self) -> usize {
        self.u.ncols()
    }

    /// `max ||F x - U W^T x|| / (||F||_1 ||x||)` over two probe vectors (`W = W_M` when
    /// `mass`, else `W_K`).
    fn product_error(&self, f: SparseRef<'_>, mass: bool) -> f64 {
        let n = f.nrows();
        let w = if mass { &self.wm } else { &self.wk };
        let fnorm = norm1(f);
        let mut worst = 0.0f64;
        for k in 0..2 {
            let x: Vec<f64> = (0..n)
                .map(|i| 1.0 + 0.5 * ((i * (k + 1)) as f64 * 0.37).sin())
                .collect();
            let mut y = vec![0.0; n];
            crate::linalg::spmv(f, &x, &mut y);
            let t = sparse_t_dense(w.as_ref(), &x);
            let ur = self.u.as_ref();
            for j in 0..ur.ncols() {
                for (i, v) in ur.row_idx_of_col(j).zip(ur.val_of_col(j)) {
                    y[i] -= v * t[j];
                }
            }
            let e = crate::linalg::norm2(&y);
            let den = fnorm * crate::linalg::norm2(&x);
            if den > 0.0 {
                worst = worst.max(e / den);
            } else if e > 0.0 {
                worst = f64::INFINITY;
            }
        }
        worst
    }
}

/// `W^T x` for a sparse `n x k` `W` and a dense vector.
fn sparse_t_dense(w: SparseRef<'_>, x: &[f64]) -> Vec<f64> {
    (0..w.ncols())
        .map(|j| {
            w.row_idx_of_col(j)
                .zip(w.val_of_col(j))
                .map(|(i, v)| v * x[i])
                .sum()
        })
        .collect()
}
