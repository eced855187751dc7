//! Shared sparse linear algebra: combinations, products (real and complex), norms and the
//! sparse Cholesky factorization every symmetric solve uses ([`Cholesky`]), and the
//! inertia of a symmetric matrix ([`inertia`]).

mod cholesky;
mod complex;
pub(crate) mod explain;
mod inertia;

pub use cholesky::Cholesky;
pub(crate) use cholesky::{LltFailure, SparseLlt};
pub use complex::spmv_complex;
pub use inertia::{inertia, Inertia, ZERO_PIVOT_REL};

/// A solver of `A X = B` in place for a block of right-hand sides: a sparse factorization
/// ([`Cholesky`]), or a solve assembled from others (the tied solves of
/// [`crate::reduction::TiedSolve`]).
pub trait BlockSolve: Send + Sync {
    /// `B <- A^-1 B`.
    fn solve_block(&self, b: MatMut<'_, f64>);
}

impl BlockSolve for Cholesky {
    fn solve_block(&self, b: MatMut<'_, f64>) {
        self.solve_in_place(b);
    }
}
pub(crate) use complex::{norm2_c, spmv_complex_add, spmv_complex_split};

use crate::{Error, Result, SparseMat, SparseRef};
use faer::sparse::Triplet;
use faer::{Mat, MatMut, MatRef, Par};

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

/// `A X` for a symmetric sparse `A` (both triangles stored): the gather product
/// [`sparse_transpose_times`], `A^T X = A X`, about twice as fast as [`sparse_times`]
/// (no scattered writes). For the mass and stiffness matrices and their images.
///
/// # Panics
/// If `A` has not as many rows as `X` (a programming error, as in faer).
pub fn symmetric_times(a: SparseRef<'_>, x: MatRef<'_, f64>) -> Mat<f64> {
    sparse_transpose_times(a, x)
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

/// Applies the sequential solve `solve` to the columns of `b`, split into as many column
/// blocks as faer's global parallelism has threads and solved side by side. A sparse
/// triangular solve gains little from parallelism inside a supernode (each thread waits
/// on the others at every one), so blocks of right-hand sides run sequentially on a
/// thread each (on two cores a 128-column solve of a 125,000-unknown 3D factor takes
/// 0.49 s so, against 2.16 s in faer's parallel solve and 0.89 s on one thread).
pub(crate) fn solve_by_columns(b: MatMut<'_, f64>, solve: &(dyn Fn(MatMut<'_, f64>) + Sync)) {
    let threads = match faer::get_global_parallelism() {
        Par::Seq => 1,
        Par::Rayon(n) => n.get(),
    };
    split_columns(b, threads, solve);
}

fn split_columns(b: MatMut<'_, f64>, parts: usize, solve: &(dyn Fn(MatMut<'_, f64>) + Sync)) {
    let parts = parts.min(b.ncols());
    if parts <= 1 {
        if b.ncols() > 0 {
            solve(b);
        }
        return;
    }
    let left = parts / 2;
    let mid = b.ncols() * left / parts;
    let (l, r) = b.split_at_col_mut(mid);
    rayon::join(
        || split_columns(l, left, solve),
        || split_columns(r, parts - left, solve),
    );
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
    clear_vector_uppers();
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
    clear_vector_uppers();
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

/// Clears the upper halves of the vector registers (`vzeroupper`) on x86-64 CPUs with
/// AVX; a no-op elsewhere.
///
/// faer's AVX-512 matrix-product kernels (the `private-gemm-x86` crate) return with the
/// upper bits of the vector registers in use. Until something clears them, the
/// legacy-SSE code that this crate's scalar loops compile to for the baseline x86-64
/// target runs several times slower on that thread: on an AMD EPYC with AVX-512, a
/// 16-column product with the rig's mass matrix (12 million entries) took 0.36 s after a
/// dense product on the same thread against 0.06 s before, and stayed so until the next
/// `vzeroupper` (the input data, allocation, subnormals and idle pool threads were each
/// ruled out). The hot kernels of this crate (sparse products, dot products, norms) call
/// this on entry, on whichever thread runs them; it costs one instruction.
#[inline]
pub fn clear_vector_uppers() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: `vzeroupper` exists on every CPU with AVX (checked above); it zeroes bits
        // 128 and up of the vector registers, which the baseline x86-64 code around it
        // never holds values in, and the caller-saved registers are declared clobbered.
        unsafe {
            std::arch::asm!(
                "vzeroupper",
                clobber_abi("C"),
                options(nomem, nostack, preserves_flags)
            )
        };
    }
}

/// `y = A x` (overwrites `y`).
pub fn spmv(a: SparseRef<'_>, x: &[f64], y: &mut [f64]) {
    clear_vector_uppers();
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

/// Column `c` of a column-major dense matrix as a slice (every `Mat` is column-major).
pub(crate) fn col(x: &Mat<f64>, c: usize) -> &[f64] {
    x.col(c).try_as_col_major().unwrap().as_slice()
}

/// Euclidean norm.
pub fn norm2(x: &[f64]) -> f64 {
    clear_vector_uppers();
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// Dot product.
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    clear_vector_uppers();
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

/// The columns of `a` then those of `b`, side by side: `[a | b]` (the same rows).
pub fn hcat(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    debug_assert_eq!(a.nrows(), b.nrows());
    let k = a.ncols();
    let mut out = Mat::<f64>::zeros(a.nrows(), k + b.ncols());
    out.as_mut().subcols_mut(0, k).copy_from(a);
    out.as_mut().subcols_mut(k, b.ncols()).copy_from(b);
    out
}

/// Expands reduced vectors: `u = V q` (`V` real `n x m`, `q` complex `m x k`).
pub fn expand(v: MatRef<'_, f64>, q: MatRef<'_, crate::c64>) -> Mat<crate::c64> {
    // One real product V [Re Q, Im Q] (BLAS-3, parallel), then recombined.
    let k = q.ncols();
    let parts = Mat::from_fn(q.nrows(), 2 * k, |i, j| {
        if j < k {
            q[(i, j)].re
        } else {
            q[(i, j - k)].im
        }
    });
    let mut u = Mat::<f64>::zeros(v.nrows(), 2 * k);
    if k > 0 && v.ncols() > 0 {
        faer::linalg::matmul::matmul(
            u.as_mut(),
            faer::Accum::Replace,
            v,
            parts.as_ref(),
            1.0,
            faer::get_global_parallelism(),
        );
    }
    Mat::from_fn(v.nrows(), k, |i, j| {
        crate::c64::new(u[(i, j)], u[(i, j + k)])
    })
}

#[cfg(test)]
mod par_products_tests;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hcat_puts_the_columns_side_by_side() {
        let a = Mat::from_fn(3, 2, |i, j| (10 * i + j) as f64);
        let b = Mat::from_fn(3, 1, |i, _| -(i as f64) - 1.0);
        let ab = hcat(a.as_ref(), b.as_ref());
        assert_eq!((ab.nrows(), ab.ncols()), (3, 3));
        for i in 0..3 {
            assert_eq!(ab[(i, 0)], a[(i, 0)]);
            assert_eq!(ab[(i, 1)], a[(i, 1)]);
            assert_eq!(ab[(i, 2)], b[(i, 0)]);
        }
        let none = hcat(a.as_ref(), Mat::<f64>::zeros(3, 0).as_ref());
        assert_eq!(none, a);
    }

    #[test]
    fn column_split_solves_every_column_once_for_any_thread_count() {
        // the "solve" doubles its columns and records its block's width: every column
        // must be doubled exactly once, and no block may be empty
        for ncols in [0usize, 1, 2, 3, 7, 64] {
            for parts in [1usize, 2, 3, 4, 9] {
                let mut b = Mat::from_fn(5, ncols, |i, c| (i + 10 * c) as f64 + 1.0);
                let widths = std::sync::Mutex::new(Vec::new());
                split_columns(b.as_mut(), parts, &|mut blk: MatMut<'_, f64>| {
                    widths.lock().unwrap().push(blk.ncols());
                    for c in 0..blk.ncols() {
                        blk.as_mut().col_mut(c).iter_mut().for_each(|x| *x *= 2.0);
                    }
                });
                for c in 0..ncols {
                    for i in 0..5 {
                        assert_eq!(b[(i, c)], 2.0 * ((i + 10 * c) as f64 + 1.0));
                    }
                }
                let widths = widths.into_inner().unwrap();
                assert!(
                    widths.iter().all(|&w| w > 0),
                    "{ncols} columns, {parts} parts"
                );
                assert_eq!(widths.iter().sum::<usize>(), ncols);
                assert_eq!(widths.len(), parts.min(ncols));
            }
        }
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

    /// Deterministic values uniform in `[-0.5, 0.5)` (xorshift from `seed`).
    fn xorshift(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    #[test]
    fn transpose_product_is_the_product_by_the_transpose() {
        let mut rnd = xorshift(7);
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
    fn symmetric_times_is_the_product_for_symmetric_matrices_and_only_those() {
        // a symmetric 23 x 23 pattern (both triangles stored), an empty row/column, values
        // of mixed sign; the same pattern with one off-diagonal entry changed is not
        // symmetric, and there the gather product gives A^T X, not A X
        let mut rnd = xorshift(5);
        let n = 23;
        let mut t = Vec::new();
        for j in 0..n {
            for i in j..n {
                if (i * 3 + j * 5) % 4 == 0 && i != 6 && j != 6 {
                    let v = rnd();
                    t.push(Triplet::new(i, j, v));
                    if i != j {
                        t.push(Triplet::new(j, i, v));
                    }
                }
            }
        }
        let a = SparseMat::try_new_from_triplets(n, n, &t).unwrap();
        let x = Mat::from_fn(n, 13, |_, _| rnd());
        let got = symmetric_times(a.as_ref(), x.as_ref());
        let want = sparse_times(a.as_ref(), x.as_ref());
        let scale = want.norm_max();
        assert!(scale > 0.0);
        assert!((&got - &want).norm_max() <= 1e-15 * scale * n as f64);
        assert!(
            (0..13).all(|k| got[(6, k)] == 0.0),
            "the empty row and column"
        );
        // one entry of the upper triangle changed: no longer symmetric
        let (i, j) = t
            .iter()
            .map(|e| (e.row, e.col))
            .find(|&(i, j)| i < j)
            .unwrap();
        t.push(Triplet::new(i, j, 1.0));
        let b = SparseMat::try_new_from_triplets(n, n, &t).unwrap();
        let diff = &symmetric_times(b.as_ref(), x.as_ref()) - &sparse_times(b.as_ref(), x.as_ref());
        assert!(
            diff.norm_max() > 0.1 * scale,
            "a non-symmetric matrix is told apart"
        );
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
}
