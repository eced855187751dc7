//! Shared sparse linear algebra: combinations, products, norms and the symmetric
//! shift-invert operator that every symmetric eigen backend drives.
//!
//! The shift-invert operator of the generalized problem `K x = lambda M x` is
//! `OP = (K - sigma M)^-1 M`. It is self-adjoint in the `M` inner product and its
//! eigenvalues `theta = 1 / (lambda - sigma)` are largest for the `lambda` nearest
//! `sigma`. With `sigma` below the spectrum, `K - sigma M` is positive definite and
//! one sparse Cholesky factorization (faer supernodal, ordered by
//! [`crate::ordering`]) serves every application.

use crate::ordering::{symmetric_ordering, FillOrdering};
use crate::{Error, Result, SparseMat, SparseRef};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
};
use faer::sparse::Triplet;
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};

/// `alpha A + beta B` for square sparse matrices of the same size (patterns may differ).
pub fn add_scaled(a: SparseRef<'_>, alpha: f64, b: SparseRef<'_>, beta: f64) -> Result<SparseMat> {
    if a.nrows() != b.nrows() || a.ncols() != b.ncols() {
        return Err(Error::Dimension {
            context: "add_scaled".into(),
            expected: a.nrows(),
            got: b.nrows(),
        });
    }
    let sorted = |m: SparseRef<'_>| {
        (0..m.ncols()).all(|j| m.row_idx_of_col_raw(j).windows(2).all(|w| w[0] < w[1]))
    };
    if sorted(a) && sorted(b) {
        // Column-by-column merge of sorted patterns: linear in nnz (the triplet path
        // below sorts, about 10x slower on a 58k-DOF operator evaluated per mu).
        let n = a.ncols();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let cap = a.compute_nnz() + b.compute_nnz();
        let (mut rows, mut vals) = (Vec::with_capacity(cap), Vec::with_capacity(cap));
        col_ptr.push(0usize);
        for j in 0..n {
            let (ra, va) = (a.row_idx_of_col_raw(j), a.val_of_col(j));
            let (rb, vb) = (b.row_idx_of_col_raw(j), b.val_of_col(j));
            let (mut p, mut q) = (0, 0);
            while p < ra.len() || q < rb.len() {
                let (i, v) = if q == rb.len() || (p < ra.len() && ra[p] < rb[q]) {
                    p += 1;
                    (ra[p - 1], alpha * va[p - 1])
                } else if p == ra.len() || rb[q] < ra[p] {
                    q += 1;
                    (rb[q - 1], beta * vb[q - 1])
                } else {
                    p += 1;
                    q += 1;
                    (ra[p - 1], alpha * va[p - 1] + beta * vb[q - 1])
                };
                rows.push(i);
                vals.push(v);
            }
            col_ptr.push(rows.len());
        }
        let sym =
            faer::sparse::SymbolicSparseColMat::new_checked(a.nrows(), n, col_ptr, None, rows);
        return Ok(SparseMat::new(sym, vals));
    }
    let mut trip = Vec::with_capacity(a.compute_nnz() + b.compute_nnz());
    for (m, s) in [(a, alpha), (b, beta)] {
        for j in 0..m.ncols() {
            for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                trip.push(Triplet::new(i, j, s * v));
            }
        }
    }
    SparseMat::try_new_from_triplets(a.nrows(), a.ncols(), &trip)
        .map_err(|e| Error::Invalid(format!("add_scaled: {e:?}")))
}

/// `A X` for a sparse `A` and a dense `X`.
///
/// The columns of `X` go in blocks (16, 8 or 4 wide), each block streaming `A` once and
/// the blocks running in parallel under faer's global parallelism. faer 0.24's
/// sparse-dense product streams `A` once per column of `X`, serially; this one is several
/// times faster for the `n x 100s` blocks of the reduction and the synthesis. Every entry is
/// summed over the columns of `A` in the same order as that product, so the two give the
/// same bits.
///
/// # Panics
/// If `A` has not as many columns as `X` rows (a programming error, as in faer).
pub fn sparse_times(a: SparseRef<'_>, x: MatRef<'_, f64>) -> Mat<f64> {
    product(a, x, Product::Scatter)
}

/// `A^T X` for a sparse `A` (CSC) and a dense `X`: every entry is a gather over one
/// column of `A` (its rows in ascending order), so no entry of the result is written more
/// than once. With the columns of `X` in blocks of 16, 8 or 4 run in parallel as in
/// [`sparse_times`], this is about twice as fast as that scatter product; it gives
/// `V^T A V = (A^T V)^T V` for any `A`, and `A X` itself for a symmetric `A`.
///
/// # Panics
/// If `A` has not as many rows as `X` (a programming error, as in faer).
pub fn sparse_transpose_times(a: SparseRef<'_>, x: MatRef<'_, f64>) -> Mat<f64> {
    product(a, x, Product::Gather)
}

/// The two products by blocks of columns of `X`.
#[derive(Clone, Copy)]
enum Product {
    /// `A X`, each column of `A` scattered into the rows of the block.
    Scatter,
    /// `A^T X`, each entry gathered from one column of `A`.
    Gather,
}

/// `A X` or `A^T X` ([`Product`]), checked for sizes.
fn product(a: SparseRef<'_>, x: MatRef<'_, f64>, product: Product) -> Mat<f64> {
    let (name, inner, outer) = match product {
        Product::Scatter => ("sparse_times: A has {} columns", a.ncols(), a.nrows()),
        Product::Gather => (
            "sparse_transpose_times: A has {} rows",
            a.nrows(),
            a.ncols(),
        ),
    };
    assert_eq!(
        inner,
        x.nrows(),
        "{} but X {} rows",
        name.replace("{}", &inner.to_string()),
        x.nrows()
    );
    let mut y = Mat::<f64>::zeros(outer, x.ncols());
    if outer > 0 && x.ncols() > 0 {
        blocked(a, x, y.as_mut(), product);
    }
    y
}

/// `y <- A X` or `A^T X` ([`Product`]) with the columns of `X` in blocks of 16, 8 or 4.
fn blocked(a: SparseRef<'_>, x: MatRef<'_, f64>, y: MatMut<'_, f64>, product: Product) {
    match x.ncols() {
        c if c >= 12 => by_blocks::<16>(a, x, y, product),
        c if c >= 5 => by_blocks::<8>(a, x, y, product),
        _ => by_blocks::<4>(a, x, y, product),
    }
}

/// [`blocked`] for blocks of `W` columns of `X` (the last one padded with zeros), the
/// blocks in parallel under faer's global parallelism.
fn by_blocks<const W: usize>(
    a: SparseRef<'_>,
    x: MatRef<'_, f64>,
    y: MatMut<'_, f64>,
    product: Product,
) {
    let block = |c0: usize, yb: MatMut<'_, f64>| match product {
        Product::Scatter => scatter_block::<W>(a, x, c0, yb),
        Product::Gather => gather_block::<W>(a, x, c0, yb),
    };
    match faer::get_global_parallelism() {
        Par::Seq => {
            let mut y = y;
            for c0 in (0..y.ncols()).step_by(W) {
                let b = W.min(y.ncols() - c0);
                block(c0, y.as_mut().subcols_mut(c0, b));
            }
        }
        Par::Rayon(_) => {
            use rayon::prelude::*;
            y.par_col_chunks_mut(W)
                .enumerate()
                .for_each(|(k, yb)| block(k * W, yb))
        }
    }
}

/// The columns `c0..c0 + b` of `x` row by row, `W` values per row (zero-padded).
fn interleaved<const W: usize>(x: MatRef<'_, f64>, c0: usize, b: usize) -> Vec<[f64; W]> {
    let mut xt = vec![[0.0f64; W]; x.nrows()];
    for t in 0..b {
        for (i, &v) in x.col(c0 + t).iter().enumerate() {
            xt[i][t] = v;
        }
    }
    xt
}

/// `yb <- A X[:, c0..]`: every column of `A` scattered into the rows of the block.
fn scatter_block<const W: usize>(
    a: SparseRef<'_>,
    x: MatRef<'_, f64>,
    c0: usize,
    mut yb: MatMut<'_, f64>,
) {
    let b = yb.ncols();
    let xt = interleaved::<W>(x, c0, b);
    let mut yt = vec![[0.0f64; W]; a.nrows()];
    for (j, xj) in xt.iter().enumerate() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            let yi = &mut yt[i];
            for t in 0..W {
                yi[t] += v * xj[t];
            }
        }
    }
    for t in 0..b {
        for (yv, yi) in yb.as_mut().col_mut(t).iter_mut().zip(&yt) {
            *yv = yi[t];
        }
    }
}

/// `yb <- A^T X[:, c0..]`: every entry gathered from one column of `A`.
fn gather_block<const W: usize>(
    a: SparseRef<'_>,
    x: MatRef<'_, f64>,
    c0: usize,
    mut yb: MatMut<'_, f64>,
) {
    let b = yb.ncols();
    let xt = interleaved::<W>(x, c0, b);
    for j in 0..a.ncols() {
        let mut acc = [0.0f64; W];
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            let xi = &xt[i];
            for t in 0..W {
                acc[t] += v * xi[t];
            }
        }
        for (t, &v) in acc.iter().enumerate().take(b) {
            yb[(j, t)] = v;
        }
    }
}

/// `y = A x` (overwrites `y`).
pub fn spmv(a: SparseRef<'_>, x: &[f64], y: &mut [f64]) {
    debug_assert_eq!(x.len(), a.ncols());
    debug_assert_eq!(y.len(), a.nrows());
    y.iter_mut().for_each(|v| *v = 0.0);
    for j in 0..a.ncols() {
        let xj = x[j];
        if xj == 0.0 {
            continue;
        }
        for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            y[i] += v * xj;
        }
    }
}

/// Maximum absolute column sum, `||A||_1`: the scale used by relative residuals.
pub fn norm1(a: SparseRef<'_>) -> f64 {
    (0..a.ncols())
        .map(|j| a.val_of_col(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Euclidean norm.
pub fn norm2(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// Dot product.
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// Checks that a matrix is square of size `n` with finite entries.
pub fn check_square_finite(a: SparseRef<'_>, n: usize, what: &str) -> Result<()> {
    if a.nrows() != n || a.ncols() != n {
        return Err(Error::Dimension {
            context: format!("{what} must be {n} x {n}"),
            expected: n,
            got: if a.nrows() != n { a.nrows() } else { a.ncols() },
        });
    }
    for j in 0..n {
        if a.val_of_col(j).iter().any(|v| !v.is_finite()) {
            return Err(Error::Invalid(format!(
                "{what} has a non-finite entry in column {j}"
            )));
        }
    }
    Ok(())
}

/// A sparse supernodal `A = L L^T` (faer) in the fill-reducing ordering of
/// [`FillOrdering::of`]: the symbolic analysis and the values of `L`.
struct SparseLlt {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
}

/// Why a [`SparseLlt`] failed: its symbolic analysis (and ordering), or its numeric
/// factorization (the matrix is not positive definite).
enum LltFailure {
    Symbolic(String),
    Numeric(String),
}

impl SparseLlt {
    /// Orders, analyses and factorizes the lower triangle of `a`.
    fn new(a: SparseRef<'_>) -> std::result::Result<Self, LltFailure> {
        let ordering =
            FillOrdering::of(a.symbolic()).map_err(|e| LltFailure::Symbolic(e.to_string()))?;
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            symmetric_ordering(ordering.as_ref()),
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| LltFailure::Symbolic(format!("{e:?}")))?;
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
            .map_err(|e| LltFailure::Numeric(format!("{e:?}")))?;
        Ok(Self { symbolic, values })
    }

    /// Entries stored in `L`.
    fn factor_entries(&self) -> usize {
        self.symbolic.len_val()
    }

    /// `B <- A^-1 B`.
    fn solve_in_place(&self, b: MatMut<'_, f64>) {
        let par = faer::get_global_parallelism();
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(b.ncols(), par));
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            b,
            par,
            MemStack::new(&mut mem),
        );
    }
}

/// A sparse Cholesky factorization `A = L L^T` of a symmetric positive definite matrix
/// (faer supernodal, ordered by [`crate::ordering`]), solved against one or many
/// right-hand sides.
pub struct Cholesky {
    llt: SparseLlt,
    n: usize,
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
                    format!("{e} (not positive definite: are the rigid-body motions restrained?)")
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

/// The factorized symmetric shift-invert operator `OP = (K - sigma M)^-1 M`.
pub struct ShiftInvert<'a> {
    m: SparseRef<'a>,
    sigma: f64,
    llt: SparseLlt,
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
                "{e} (not positive definite: is sigma below the lowest eigenvalue, \
                 and are the rigid-body motions of K restrained or M positive?)"
            )),
        })?;
        Ok(Self {
            m,
            sigma,
            llt,
            applications: std::sync::atomic::AtomicUsize::new(0),
        })
    }

    /// Problem size.
    pub fn dim(&self) -> usize {
        self.m.nrows()
    }

    /// The shift `sigma`, in (rad/s)^2.
    pub fn sigma(&self) -> f64 {
        self.sigma
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
        self.llt.solve_in_place(mat);
    }

    /// `y = (K - sigma M)^-1 M x`, the operator application.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        self.m_mul(x, y);
        self.solve_in_place(y);
        self.applications
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// `y = (K - sigma M)^-1 b` where `b = M x` is already known (saves one product).
    pub fn apply_with_mx(&self, mx: &[f64], y: &mut [f64]) {
        y.copy_from_slice(mx);
        self.solve_in_place(y);
        self.applications
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// How many times the operator was applied (a cost measure reported by solvers).
    pub fn applications(&self) -> usize {
        self.applications.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Back-transforms an operator eigenvalue `theta` to `lambda = sigma + 1 / theta`.
    pub fn lambda_of_theta(&self, theta: f64) -> f64 {
        self.sigma + 1.0 / theta
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diag(v: &[f64]) -> SparseMat {
        let t: Vec<_> = v
            .iter()
            .enumerate()
            .map(|(i, &x)| Triplet::new(i, i, x))
            .collect();
        SparseMat::try_new_from_triplets(v.len(), v.len(), &t).unwrap()
    }

    #[test]
    fn sparse_times_gives_the_bits_of_faers_product_for_every_block_width() {
        // 37 x 29, unsymmetric, some empty columns, values of mixed sign and magnitude
        let mut state = 11u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut trip = Vec::new();
        for j in 0..29 {
            if j % 7 == 3 {
                continue;
            }
            for i in 0..37 {
                if next() < 0.2 {
                    trip.push(Triplet::new(
                        i,
                        j,
                        (next() - 0.5) * 10f64.powi((i % 5) as i32),
                    ));
                }
            }
        }
        let a = SparseMat::try_new_from_triplets(37, 29, &trip).unwrap();
        for c in [1, 3, 4, 5, 8, 11, 12, 16, 17, 40] {
            let x = Mat::from_fn(29, c, |_, _| next() - 0.3);
            let mut want = Mat::<f64>::zeros(37, c);
            faer::sparse::linalg::matmul::sparse_dense_matmul(
                want.as_mut(),
                faer::Accum::Replace,
                a.as_ref(),
                x.as_ref(),
                1.0,
                Par::Seq,
            );
            let got = sparse_times(a.as_ref(), x.as_ref());
            assert_eq!((got.nrows(), got.ncols()), (37, c));
            for i in 0..37 {
                for k in 0..c {
                    assert_eq!(
                        got[(i, k)].to_bits(),
                        want[(i, k)].to_bits(),
                        "{c} columns, ({i}, {k})"
                    );
                }
            }
        }
        assert_eq!(
            sparse_times(a.as_ref(), Mat::<f64>::zeros(29, 0).as_ref()).ncols(),
            0
        );
    }

    #[test]
    fn transpose_product_is_the_product_by_the_transpose() {
        let mut state = 7u64;
        let mut rnd = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        // a non-symmetric 37 x 29 pattern with empty rows and columns
        let mut t = Vec::new();
        for j in 0..29 {
            for i in 0..37 {
                if (i * 5 + j * 3) % 7 == 0 && i != 4 && j != 11 {
                    t.push(Triplet::new(i, j, rnd()));
                }
            }
        }
        let a = SparseMat::try_new_from_triplets(37, 29, &t).unwrap();
        let at = a.as_ref().transpose().to_col_major().unwrap();
        for c in [1usize, 3, 5, 9, 12, 17, 40] {
            let x = Mat::from_fn(37, c, |_, _| rnd());
            let got = sparse_transpose_times(a.as_ref(), x.as_ref());
            let want = sparse_times(at.as_ref(), x.as_ref());
            assert_eq!((got.nrows(), got.ncols()), (29, c));
            for j in 0..29 {
                for k in 0..c {
                    let (g, w) = (got[(j, k)], want[(j, k)]);
                    assert!(
                        (g - w).abs() <= 1e-14 * (1.0 + w.abs()),
                        "{c}: ({j}, {k}) {g} {w}"
                    );
                }
            }
            assert!((0..c).all(|k| got[(11, k)] == 0.0), "an empty column of A");
        }
    }

    #[test]
    fn add_scaled_merges_different_patterns_like_dense_addition() {
        // Two 9 x 9 patterns that overlap partly, some columns empty in one of them.
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        let mut pattern = |density: usize| -> Vec<Triplet<usize, usize, f64>> {
            (0..9)
                .flat_map(|j| (0..9).map(move |i| (i, j)))
                .filter(|_| next() % 10 < density)
                .map(|(i, j)| Triplet::new(i, j, 1.0 + (i * 9 + j) as f64))
                .collect()
        };
        let (ta, tb) = (pattern(4), pattern(3));
        let a = SparseMat::try_new_from_triplets(9, 9, &ta).unwrap();
        let b = SparseMat::try_new_from_triplets(9, 9, &tb).unwrap();
        let c = add_scaled(a.as_ref(), 2.0, b.as_ref(), -0.5).unwrap();
        let (da, db, dc) = (a.to_dense(), b.to_dense(), c.to_dense());
        for i in 0..9 {
            for j in 0..9 {
                assert_eq!(
                    dc[(i, j)],
                    2.0 * da[(i, j)] - 0.5 * db[(i, j)],
                    "({i}, {j})"
                );
            }
        }
        let union = (0..9)
            .flat_map(|j| (0..9).map(move |i| (i, j)))
            .filter(|&(i, j)| da[(i, j)] != 0.0 || db[(i, j)] != 0.0)
            .count();
        assert_eq!(c.compute_nnz(), union, "the pattern is the union of both");
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
        approx::assert_relative_eq!(op.lambda_of_theta(0.5), 1.0, epsilon = 1e-14);
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
