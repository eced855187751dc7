//! Projection of every part of a frictional operator on a basis (`V^T X V`,
//! [`project`]) and expansion of reduced vectors (`u = V q`, [`expand`]).

use super::{par, tmul};
use crate::linalg::{sparse_transpose_times, symmetric_times};
use crate::operator::FrictionalOperator;
use crate::{Error, Result, SparseMat, SparseRef};
use faer::linalg::matmul::triangular::{matmul, BlockStructure};
use faer::sparse::Triplet;
use faer::{Accum, Mat, MatRef};

/// A dense matrix stored as a sparse one (its nonzero entries): how a reduced operator
/// assembled by other means is handed over as a [`FrictionalOperator`].
pub fn dense_to_sparse(a: MatRef<'_, f64>) -> Result<SparseMat> {
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
pub(super) fn project_part(x: SparseRef<'_>, v: MatRef<'_, f64>) -> Result<SparseMat> {
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
    let red = if rows.len() == n {
        // V^T X V = (X^T V)^T V: the gather product, no symmetry of X assumed
        tmul(sparse_transpose_times(x, v).as_ref(), v)
    } else {
        // only the rows X touches: (X V)[rows, :], summed over the columns of X in the
        // same order as `sparse_times`, so the same bits without an n x m product
        let mut pos = vec![usize::MAX; n];
        for (p, &i) in rows.iter().enumerate() {
            pos[i] = p;
        }
        let cols: Vec<usize> = (0..x.ncols())
            .filter(|&j| !x.row_idx_of_col_raw(j).is_empty())
            .collect();
        let mut yr = Mat::<f64>::zeros(rows.len(), m);
        for c in 0..m {
            let vc = v.col(c);
            let mut yc = yr.col_mut(c);
            for &j in &cols {
                let vj = vc[j];
                for (&i, &a) in x.row_idx_of_col_raw(j).iter().zip(x.val_of_col(j)) {
                    yc[pos[i]] += a * vj;
                }
            }
        }
        let vr = Mat::from_fn(rows.len(), m, |i, j| v[(rows[i], j)]);
        tmul(vr.as_ref(), yr.as_ref())
    };
    dense_to_sparse(red.as_ref())
}

/// Whether the sparse `x` equals its transpose exactly (pattern and value bits; sorted
/// row indices, which faer's matrices keep).
pub(super) fn is_symmetric(x: SparseRef<'_>) -> bool {
    if x.nrows() != x.ncols() {
        return false;
    }
    (0..x.ncols()).all(|j| {
        x.row_idx_of_col_raw(j)
            .iter()
            .zip(x.val_of_col(j))
            .all(|(&i, &v)| {
                let rows = x.row_idx_of_col_raw(i);
                rows.binary_search(&j)
                    .is_ok_and(|p| x.val_of_col(i)[p].to_bits() == v.to_bits())
            })
    })
}

/// Columns of a basis from which [`project`] takes the mass and stiffness parts by
/// [`project_symmetric_part`]: the half product saves about `n m^2` flops, the exact
/// symmetry check costs a pass over each matrix with a search per entry whatever `m`. On
/// the default rig (172k DOFs) the `enriched` bases of 200-460 columns projected 0.4 s
/// faster with it, the 42-column `cms` bases 0.36 s slower (0.32 -> 0.68 s per point of
/// the Figure 5 sweep of `squeal validate`).
const SYMMETRIC_PROJECTION_MIN_COLUMNS: usize = 256;

/// `V^T X V` for the mass and stiffness parts: when `X` is symmetric
/// ([`is_symmetric`]) its lower triangle by one triangular product, mirrored (half the
/// flops of the full product, which dominates the projection on a basis of hundreds of
/// columns); else [`project_part`].
pub(super) fn project_symmetric_part(x: SparseRef<'_>, v: MatRef<'_, f64>) -> Result<SparseMat> {
    if !is_symmetric(x) {
        return project_part(x, v);
    }
    let m = v.ncols();
    let xv = symmetric_times(x, v);
    let mut red = Mat::<f64>::zeros(m, m);
    if v.nrows() > 0 {
        matmul(
            red.as_mut(),
            BlockStructure::TriangularLower,
            Accum::Replace,
            v.transpose(),
            BlockStructure::Rectangular,
            xv.as_ref(),
            BlockStructure::Rectangular,
            1.0,
            par(),
        );
    }
    for j in 0..m {
        for i in 0..j {
            red[(i, j)] = red[(j, i)];
        }
    }
    dense_to_sparse(red.as_ref())
}

/// Projects every part of `op` on the columns of `v` (`n_c x m`): `X_r = V^T X V`, the
/// friction load directions to `V^T U`, no index map; the mass and stiffness parts of a
/// basis of 256 columns or more, when exactly symmetric, by their lower triangle (one
/// triangular product, mirrored). The result is a small (dense-backed) operator that any
/// [`EigenSolver`](crate::EigenSolver) solves.
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
    let symmetric = |x: &SparseMat| {
        if v.ncols() >= SYMMETRIC_PROJECTION_MIN_COLUMNS {
            project_symmetric_part(x.as_ref(), v)
        } else {
            project_part(x.as_ref(), v)
        }
    };
    let friction_loads = project_loads(op, v)?;
    Ok(FrictionalOperator {
        mc: symmetric(&op.mc)?,
        cc: opt(&op.cc)?,
        kc: symmetric(&op.kc)?,
        fm: project_part(op.fm.as_ref(), v)?,
        fc: opt(&op.fc)?,
        fk: project_part(op.fk.as_ref(), v)?,
        t: None,
        friction_loads,
        modal: Default::default(),
    })
}

/// `V^T U` of the friction load directions, when the operator carries them.
pub(super) fn project_loads(
    op: &FrictionalOperator,
    v: MatRef<'_, f64>,
) -> Result<Option<SparseMat>> {
    Ok(match &op.friction_loads {
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
    })
}
