//! The sparse supernodal Cholesky factorization `A = L L^T` (faer) in the fill-reducing
//! ordering of [`crate::ordering`].

use super::check_square_finite;
use crate::ordering::{symmetric_ordering, FillOrdering};
use crate::{Error, Result, SparseRef};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
};
use faer::{Conj, MatMut, Par, Side};

/// A sparse supernodal `A = L L^T` (faer) in the fill-reducing ordering of
/// [`FillOrdering::of`]: the symbolic analysis and the values of `L`.
pub(crate) struct SparseLlt {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
}

/// Why a [`SparseLlt`] failed: its symbolic analysis (and ordering), or its numeric
/// factorization (the matrix is not positive definite).
pub(crate) enum LltFailure {
    Symbolic(String),
    Numeric(String),
}

impl SparseLlt {
    /// Orders, analyses and factorizes the lower triangle of `a`.
    pub(crate) fn new(a: SparseRef<'_>) -> std::result::Result<Self, LltFailure> {
        let ordering =
            FillOrdering::of(a.symbolic()).map_err(|e| LltFailure::Symbolic(e.to_string()))?;
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            symmetric_ordering(ordering.as_ref()),
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| LltFailure::Symbolic(super::explain::generic(&e)))?;
        let mut values = Vec::new();
        values.try_reserve_exact(symbolic.len_val()).map_err(|_| {
            LltFailure::Symbolic(format!(
                "out of memory for {} entries of L",
                symbolic.len_val()
            ))
        })?;
        values.resize(symbolic.len_val(), 0.0);
        let par = faer::get_global_parallelism();
        let mut mem = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
        )
        .map_err(|_| {
            LltFailure::Symbolic("out of memory for the factorization's workspace".into())
        })?;
        symbolic
            .factorize_numeric_llt(
                &mut values,
                a,
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| LltFailure::Numeric(super::explain::llt(&e, a.nrows())))?;
        Ok(Self { symbolic, values })
    }

    /// Entries stored in `L`.
    pub(crate) fn factor_entries(&self) -> usize {
        self.symbolic.len_val()
    }

    /// `B <- A^-1 B`, column blocks side by side ([`super::solve_by_columns`]).
    pub(crate) fn solve_in_place(&self, b: MatMut<'_, f64>) {
        super::solve_by_columns(b, &|b: MatMut<'_, f64>| {
            let mut mem = MemBuffer::new(
                self.symbolic
                    .solve_in_place_scratch::<f64>(b.ncols(), Par::Seq),
            );
            LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
                Conj::No,
                b,
                Par::Seq,
                MemStack::new(&mut mem),
            );
        });
    }
}

/// A sparse Cholesky factorization `A = L L^T` of a symmetric positive definite matrix
/// (faer supernodal, ordered by [`crate::ordering`]), solved against one or many
/// right-hand sides.
pub struct Cholesky {
    llt: SparseLlt,
    n: usize,
}

impl std::fmt::Debug for Cholesky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cholesky")
            .field("n", &self.n)
            .field("factor_entries", &self.factor_entries())
            .finish()
    }
}

impl Cholesky {
    /// Factorizes `a`; `what` names the matrix in errors.
    pub fn new(a: SparseRef<'_>, what: &str) -> Result<Self> {
        let n = a.nrows();
        check_square_finite(a, n, what)?;
        let llt = SparseLlt::new(a).map_err(|f| Error::Factorization {
            what: format!("{what} (n = {n})"),
            reason: match f {
                LltFailure::Symbolic(e) => e,
                LltFailure::Numeric(e) => {
                    format!(
                        "{e}: are the rigid-body motions restrained, and is the matrix \
                         symmetric positive definite?"
                    )
                }
            },
        })?;
        Ok(Self { llt, n })
    }

    /// Size.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Entries stored in the factor `L`.
    pub fn factor_entries(&self) -> usize {
        self.llt.factor_entries()
    }

    /// `B <- A^-1 B` for a block of right-hand sides (columns).
    pub fn solve_in_place(&self, b: MatMut<'_, f64>) {
        self.llt.solve_in_place(b);
    }

    /// `y <- A^-1 y`.
    pub fn solve_vec_in_place(&self, y: &mut [f64]) {
        let n = y.len();
        self.llt
            .solve_in_place(MatMut::from_column_major_slice_mut(y, n, 1));
    }
}
