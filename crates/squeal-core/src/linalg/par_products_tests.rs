//! Parallel dense products against sequential ones on the shapes squeal multiplies.
//!
//! faer's parallel `matmul` has been reported to return a silently wrong block on
//! row-major views of matrices with large exact-zero blocks, while `Par::Seq` was correct.
//! squeal multiplies such operands: a transposed (row-major) basis in `V^T X V`, the
//! Gram products of the orthonormalization, reduction bases whose columns vanish outside
//! one substructure (component modes) or one contact pair (friction responses), and the
//! dense `Z = S^-1 U` of the Woodbury path. Each case here compares `Par::rayon(2)` with
//! `Par::Seq` entry by entry against the round-off bound `4 k eps (|A| |B|)_ij` of a
//! length-`k` dot product; a corrupted partial accumulation breaks it by orders of
//! magnitude.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};

/// Deterministic entries in `[-1, 1)`, exact zeros where `zero(i, j)`.
fn operand(n: usize, m: usize, seed: u64, zero: impl Fn(usize, usize) -> bool) -> Mat<f64> {
    let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15).wrapping_add(1);
    Mat::from_fn(n, m, |i, j| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let v = ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0;
        if zero(i, j) {
            0.0
        } else {
            v
        }
    })
}

fn product(a: MatRef<'_, f64>, b: MatRef<'_, f64>, par: Par) -> Mat<f64> {
    let mut c = Mat::<f64>::zeros(a.nrows(), b.ncols());
    matmul(c.as_mut(), Accum::Replace, a, b, 1.0, par);
    c
}

/// Largest violation ratio `|C_par - C_seq|_ij / (4 k eps (|A| |B|)_ij)` (> 1 fails).
fn worst_ratio(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
    let seq = product(a, b, Par::Seq);
    let par = product(a, b, Par::rayon(2));
    let abs_a = Mat::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)].abs());
    let abs_b = Mat::from_fn(b.nrows(), b.ncols(), |i, j| b[(i, j)].abs());
    let bound = product(abs_a.as_ref(), abs_b.as_ref(), Par::Seq);
    let k = a.ncols() as f64;
    let mut worst = 0.0f64;
    for j in 0..seq.ncols() {
        for i in 0..seq.nrows() {
            let d = (par[(i, j)] - seq[(i, j)]).abs();
            let tol = 4.0 * k * f64::EPSILON * bound[(i, j)];
            let r = if tol > 0.0 {
                d / tol
            } else if d > 0.0 {
                f64::INFINITY
            } else {
                0.0
            };
            worst = worst.max(r);
        }
    }
    worst
}

#[test]
fn parallel_products_agree_with_sequential_ones_on_squeals_shapes() {
    // (rows, columns) of a tall basis; the zero pattern of component modes: the first
    // half of the columns vanish on the second half of the rows and vice versa
    let n = 12_000;
    let cases: [(usize, usize); 3] = [(n, 96), (n, 200), (5_018, 64)];
    for (rows, cols) in cases {
        let blocks = |i: usize, j: usize| (i < rows / 2) != (j < cols / 2);
        let v = operand(rows, cols, 7, blocks);
        let w = operand(rows, cols, 11, |i, j| blocks(i, j) || i % 97 == 0);
        // V^T W: a row-major (transposed) operand with exact-zero blocks
        let r = worst_ratio(v.transpose(), w.as_ref());
        assert!(r <= 1.0, "V^T W ({rows} x {cols}): ratio {r:e}");
        // V C: tall times small (expansion of reduced vectors, Z t of the Woodbury path)
        let c = operand(cols, 8, 13, |i, _| i % 5 == 0);
        let r = worst_ratio(v.as_ref(), c.as_ref());
        assert!(
            r <= 1.0,
            "V C ({rows} x {cols} times {cols} x 8): ratio {r:e}"
        );
        // (V^T)^T of a row-major copy: the same product through a row-major view of V
        let vt = v.transpose().to_owned();
        let r = worst_ratio(vt.transpose(), c.as_ref());
        assert!(r <= 1.0, "row-major V C ({rows} x {cols}): ratio {r:e}");
    }
    // a square symmetric matrix with two far-apart blocks times itself through
    // row-major views (the reported trigger's structure, at a size squeal's reduced
    // operators reach)
    let m = 1_200;
    let a = operand(m, m, 17, |i, j| (i < m / 3) != (j < m / 3));
    let sym = Mat::from_fn(m, m, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let row_major = sym.transpose().to_owned();
    let r = worst_ratio(row_major.transpose(), row_major.transpose());
    assert!(r <= 1.0, "row-major A A ({m} x {m}): ratio {r:e}");
}
