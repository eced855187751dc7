//! Directions handed from one contact set to the next ([`crate::Basis::seed`],
//! [`crate::BasisRequest::seed`]). Each contact set has its own constrained space (its
//! ties merge the normal DOFs of its active pairs), so a direction travels on the free
//! model's DOFs: [`to_free_dofs`] copies each constrained value to the free DOFs it
//! stands for, [`from_free_dofs`] averages the free DOFs of each constrained one (two
//! for a tie the next set shares, one otherwise).

use crate::operator::FrictionalOperator;
use faer::{Mat, MatRef};

/// The columns `v` of the constrained space of `op` on the free model's DOFs
/// (`u = T v`); `None` when `op` has no index map `T` (an operator read from files) or
/// `v` has not its rows.
pub fn to_free_dofs(op: &FrictionalOperator, v: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let t = op.t.as_deref()?;
    if v.nrows() != op.dim() || t.iter().any(|&c| c >= v.nrows()) {
        return None;
    }
    Some(Mat::from_fn(t.len(), v.ncols(), |j, c| v[(t[j], c)]))
}

/// Columns `w` on the free model's DOFs brought to the constrained space of `op`: each
/// constrained DOF takes the mean of the free DOFs `T` maps to it. `None` when `op`
/// has no index map or `w` has not one row per free DOF.
pub fn from_free_dofs(op: &FrictionalOperator, w: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let t = op.t.as_deref()?;
    let nc = op.dim();
    if w.nrows() != t.len() || t.iter().any(|&c| c >= nc) {
        return None;
    }
    let mut count = vec![0.0f64; nc];
    t.iter().for_each(|&c| count[c] += 1.0);
    let mut v = Mat::<f64>::zeros(nc, w.ncols());
    for col in 0..w.ncols() {
        for (j, &c) in t.iter().enumerate() {
            v[(c, col)] += w[(j, col)];
        }
        for (c, &k) in count.iter().enumerate() {
            if k > 1.0 {
                v[(c, col)] /= k;
            }
        }
    }
    Some(v)
}
