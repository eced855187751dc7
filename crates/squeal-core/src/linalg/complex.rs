//! Products of real sparse matrices with complex vectors, and the complex 2-norm.

use super::clear_vector_uppers;
use crate::{c64, SparseRef};
use faer::Mat;

/// `y = A x` for a real sparse matrix and a complex vector (overwrites `y`).
pub fn spmv_complex(a: SparseRef<'_>, x: &[c64], y: &mut [c64]) {
    y.iter_mut().for_each(|v| *v = c64::new(0.0, 0.0));
    spmv_complex_add(a, x, y);
}

/// `y += A x` for a real sparse matrix and a complex vector.
pub(crate) fn spmv_complex_add(a: SparseRef<'_>, x: &[c64], y: &mut [c64]) {
    clear_vector_uppers();
    debug_assert_eq!(x.len(), a.ncols());
    debug_assert_eq!(y.len(), a.nrows());
    for j in 0..a.ncols() {
        let xj = x[j];
        if xj.re == 0.0 && xj.im == 0.0 {
            continue;
        }
        for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            y[i] += xj * *v;
        }
    }
}

/// `A x` for a real sparse matrix and a complex vector, as an `n x 2` real block
/// (columns: real and imaginary parts), ready for a real factorization's solve.
pub(crate) fn spmv_complex_split(a: SparseRef<'_>, x: &[c64]) -> Mat<f64> {
    clear_vector_uppers();
    let mut b = Mat::<f64>::zeros(a.nrows(), 2);
    for j in 0..a.ncols() {
        let (xr, xi) = (x[j].re, x[j].im);
        if xr == 0.0 && xi == 0.0 {
            continue;
        }
        for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            b[(i, 0)] += v * xr;
            b[(i, 1)] += v * xi;
        }
    }
    b
}

pub(crate) fn norm2_c(x: &[c64]) -> f64 {
    clear_vector_uppers();
    x.iter()
        .map(|v| v.re * v.re + v.im * v.im)
        .sum::<f64>()
        .sqrt()
}
