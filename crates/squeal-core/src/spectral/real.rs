//! The symmetric shift-invert transformation `OP = (K - sigma M)^-1 M` of the generalized
//! problem `K x = lambda M x`: self-adjoint in the `M` inner product, its eigenvalues
//! `theta = 1 / (lambda - sigma)` are largest for the `lambda` nearest `sigma`. With
//! `sigma` below the spectrum, `K - sigma M` is positive definite and one sparse Cholesky
//! factorization serves every application.

use super::{LinOp, SpectralTransform};
use crate::linalg::{add_scaled, check_square_finite, spmv, BlockSolve, LltFailure, SparseLlt};
use crate::{Error, Result, SparseRef};
use faer::MatMut;

/// `K - sigma M` and its solver: the operator's own factor, or a solver its caller holds.
enum Factor<'a> {
    Owned {
        llt: Box<SparseLlt>,
        shifted: crate::SparseMat,
    },
    Borrowed {
        solve: &'a dyn BlockSolve,
        shifted: SparseRef<'a>,
    },
}

impl Factor<'_> {
    fn solve_in_place(&self, b: MatMut<'_, f64>) {
        match self {
            Factor::Owned { llt, .. } => llt.solve_in_place(b),
            Factor::Borrowed { solve, .. } => solve.solve_block(b),
        }
    }

    fn shifted(&self) -> SparseRef<'_> {
        match self {
            Factor::Owned { shifted, .. } => shifted.as_ref(),
            Factor::Borrowed { shifted, .. } => *shifted,
        }
    }
}

/// The factorized symmetric shift-invert operator `OP = (K - sigma M)^-1 M`.
pub struct ShiftInvert<'a> {
    m: SparseRef<'a>,
    sigma: f64,
    factor: Factor<'a>,
    applications: std::sync::atomic::AtomicUsize,
}

impl<'a> ShiftInvert<'a> {
    /// Factorizes `K - sigma M` (Cholesky). `sigma` must lie below the spectrum so that
    /// the shifted matrix is positive definite; the error says so otherwise.
    pub fn new(k: SparseRef<'_>, m: SparseRef<'a>, sigma: f64) -> Result<Self> {
        let n = k.nrows();
        check_square_finite(k, n, "K")?;
        check_square_finite(m, n, "M")?;
        let shifted = add_scaled(k, 1.0, m, -sigma)?;
        let fail = |reason: String| Error::Factorization {
            what: format!("K - sigma M (sigma = {sigma:.6e} (rad/s)^2, n = {n})"),
            reason,
        };
        let llt = SparseLlt::new(shifted.as_ref()).map_err(|f| match f {
            LltFailure::Symbolic(e) => fail(e),
            LltFailure::Numeric(e) => fail(format!(
                "{e}: an eigenvalue of (K, M) lies below sigma (a negative one, if K is \
                 indefinite), or K has unrestrained rigid-body motions, or M is not positive \
                 definite"
            )),
        })?;
        Ok(Self {
            m,
            sigma,
            factor: Factor::Owned {
                llt: Box::new(llt),
                shifted,
            },
            applications: std::sync::atomic::AtomicUsize::new(0),
        })
    }

    /// The operator on a solver the caller already holds: `shifted` must be
    /// `K - sigma M` for this `m` and `sigma` and `solve` a solver of it (as the static
    /// solver of [`crate::reduction::StaticSolver::shift_invert`] guarantees), so real
    /// modes and static responses share one factorization.
    pub(crate) fn with_factor(
        m: SparseRef<'a>,
        sigma: f64,
        shifted: SparseRef<'a>,
        solve: &'a dyn BlockSolve,
    ) -> Self {
        Self {
            m,
            sigma,
            factor: Factor::Borrowed { solve, shifted },
            applications: std::sync::atomic::AtomicUsize::new(0),
        }
    }

    /// The shifted matrix `K - sigma M`.
    pub fn shifted(&self) -> SparseRef<'_> {
        self.factor.shifted()
    }

    /// The mass matrix.
    pub fn m(&self) -> SparseRef<'a> {
        self.m
    }

    /// `y = M x`.
    pub fn m_mul(&self, x: &[f64], y: &mut [f64]) {
        spmv(self.m, x, y);
    }

    /// `y <- (K - sigma M)^-1 y`.
    pub fn solve_in_place(&self, y: &mut [f64]) {
        let n = y.len();
        let mat = MatMut::from_column_major_slice_mut(y, n, 1);
        self.factor.solve_in_place(mat);
    }

    /// `Y <- (K - sigma M)^-1 Y` for a block of columns, each counted as one application
    /// (`Y = M X` known: `OP X`). One pass over the factor serves every column, which is
    /// what makes block Krylov methods cheaper per column on large factors.
    pub fn solve_block_in_place(&self, mut y: MatMut<'_, f64>) {
        let cols = y.ncols();
        self.factor.solve_in_place(y.as_mut());
        self.applications
            .fetch_add(cols, std::sync::atomic::Ordering::Relaxed);
    }

    /// `y = (K - sigma M)^-1 b` where `b = M x` is already known (saves one product).
    pub fn apply_with_mx(&self, mx: &[f64], y: &mut [f64]) {
        y.copy_from_slice(mx);
        self.solve_in_place(y);
        self.applications
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }
}

impl LinOp<f64> for ShiftInvert<'_> {
    fn dim(&self) -> usize {
        self.m.nrows()
    }

    /// `y = (K - sigma M)^-1 M x`.
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        self.m_mul(x, y);
        self.solve_in_place(y);
        self.applications
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }
}

impl SpectralTransform<f64> for ShiftInvert<'_> {
    /// The shift `sigma`, in (rad/s)^2.
    fn shift(&self) -> f64 {
        self.sigma
    }
    fn applications(&self) -> usize {
        self.applications.load(std::sync::atomic::Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SparseMat;
    use faer::sparse::Triplet;

    fn diag(v: &[f64]) -> SparseMat {
        let t: Vec<_> = v
            .iter()
            .enumerate()
            .map(|(i, &x)| Triplet::new(i, i, x))
            .collect();
        SparseMat::try_new_from_triplets(v.len(), v.len(), &t).unwrap()
    }

    #[test]
    fn shift_invert_on_a_diagonal_pencil() {
        let k = diag(&[1.0, 4.0, 9.0]);
        let m = diag(&[1.0, 2.0, 3.0]);
        let op = ShiftInvert::new(k.as_ref(), m.as_ref(), -1.0).unwrap();
        let mut y = vec![0.0; 3];
        op.apply(&[1.0, 1.0, 1.0], &mut y);
        // (k_i + m_i)^-1 m_i
        approx::assert_relative_eq!(y[0], 0.5, epsilon = 1e-14);
        approx::assert_relative_eq!(y[1], 2.0 / 6.0, epsilon = 1e-14);
        approx::assert_relative_eq!(y[2], 3.0 / 12.0, epsilon = 1e-14);
        assert_eq!(op.applications(), 1);
        approx::assert_relative_eq!(op.pencil_eigenvalue(0.5), 1.0, epsilon = 1e-14);
    }

    #[test]
    fn shift_above_spectrum_is_a_clear_error() {
        let k = diag(&[1.0, 4.0]);
        let m = diag(&[1.0, 1.0]);
        let e = ShiftInvert::new(k.as_ref(), m.as_ref(), 2.0)
            .err()
            .expect("indefinite shift must fail")
            .to_string();
        assert!(
            e.contains("sigma") && e.contains("positive definite"),
            "{e}"
        );
    }

    #[test]
    fn non_finite_matrix_is_rejected() {
        let k = diag(&[1.0, f64::NAN]);
        let m = diag(&[1.0, 1.0]);
        assert!(ShiftInvert::new(k.as_ref(), m.as_ref(), 0.0).is_err());
    }
}
