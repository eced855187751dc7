//! Factorization failures as sentences: faer's error values print as Rust `Debug` text
//! (`NonPositivePivot { index: 212 }`), which says nothing to a user. These name the
//! pivot in 1-based terms and what it means.

use faer::linalg::cholesky::llt::factor::LltError;
use faer::sparse::linalg::LuError;
use faer::sparse::FaerError;

/// A failed Cholesky factorization of a matrix of size `n`.
pub(crate) fn llt(e: &LltError, n: usize) -> String {
    match e {
        LltError::NonPositivePivot { index } => format!(
            "pivot {} of {n} (in the fill-reducing order) is not positive, so the matrix is \
             not positive definite",
            index + 1
        ),
    }
}

/// A failed sparse LU factorization of a matrix of size `n`.
pub(crate) fn lu(e: &LuError, n: usize) -> String {
    match e {
        LuError::SymbolicSingular { index } => format!(
            "structurally singular: no nonzero pivot at step {} of {n} (a row or column \
             without entries?)",
            index + 1
        ),
        LuError::Generic(g) => generic(g),
    }
}

/// A failed symbolic analysis (out of memory, too many entries).
pub(crate) fn generic(e: &FaerError) -> String {
    match e {
        FaerError::OutOfMemory => "out of memory for the factor".into(),
        FaerError::IndexOverflow => {
            "the factor has more entries than its index type can count".into()
        }
        _ => "the symbolic analysis failed".into(),
    }
}
