//! Tests of the complex Krylov-Schur kernel on operators with a known spectrum.

use super::*;
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::linalg::solvers::Solve;
use squeal_core::faer::{Accum, MatMut, MatRef};
use std::time::Instant;

/// Deterministic uniform numbers in `[-1, 1)` (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
    fn c(&mut self) -> c64 {
        c64::new(self.next(), self.next())
    }
}

/// A dense operator.
struct Dense(Mat<c64>);

impl LinOp<c64> for Dense {
    fn dim(&self) -> usize {
        self.0.nrows()
    }
    fn apply(&self, x: &[c64], y: &mut [c64]) {
        let n = self.dim();
        matmul(
            MatMut::from_column_major_slice_mut(y, n, 1),
            Accum::Replace,
            self.0.as_ref(),
            MatRef::from_column_major_slice(x, n, 1),
            ONE,
            squeal_core::faer::Par::Seq,
        );
    }
}

/// `S diag(d) S^-1` with `S = R (I + 0.3 G / sqrt n)` (`G` random, `R = diag(r)`); the
/// row scaling `r` sets the non-normality (eigenvector condition ~ max r / min r).
fn similar(d: &[c64], rows: impl Fn(usize) -> f64, seed: u64) -> (Mat<c64>, Mat<c64>) {
    let n = d.len();
    let mut rng = Rng(seed);
    let g = 0.3 / (n as f64).sqrt();
    let s = Mat::from_fn(n, n, |i, j| {
        let base = if i == j { ONE } else { ZERO };
        (base + rng.c() * g) * rows(i)
    });
    let sinv = s.partial_piv_lu().solve(Mat::<c64>::identity(n, n));
    let sd = Mat::from_fn(n, n, |i, j| s[(i, j)] * d[j]);
    (times(sd.as_ref(), sinv.as_ref()), s)
}

/// The test spectrum (n = 200): an exact double, a pair split by 1e-6, a complex
/// conjugate pair, a clustered tail, and a bulk of modulus <= 3.
fn spectrum(n: usize) -> Vec<c64> {
    let mut d = vec![
        c64::new(10.0, 0.0),
        c64::new(10.0, 0.0),
        c64::new(-8.0, 0.0),
        c64::new(-8.0 * (1.0 + 1e-6), 0.0),
        c64::new(6.0, 3.0),
        c64::new(6.0, -3.0),
    ];
    // Clustered tail 5.00, 4.99, ...: the 10th value is 4.97, the 11th 4.96.
    for i in 0..40 {
        d.push(c64::new(5.0 - 0.01 * i as f64, 0.0));
    }
    let mut rng = Rng(77);
    while d.len() < n {
        let r = 3.0 * (0.5 * (rng.next() + 1.0)).sqrt();
        let a = std::f64::consts::PI * rng.next();
        d.push(c64::new(r * a.cos(), r * a.sin()));
    }
    d
}

/// Expected top-10 by modulus.
fn top(d: &[c64], k: usize) -> Vec<c64> {
    let mut v = d.to_vec();
    v.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    v.truncate(k);
    v
}

/// Max relative residual `||OP v - theta v|| / (|theta| ||v||)` of the output.
fn max_residual(op: &dyn LinOp<c64>, out: &ComplexKernelOutput) -> f64 {
    let n = op.dim();
    let mut y = vec![ZERO; n];
    let mut worst: f64 = 0.0;
    for (j, &th) in out.theta.iter().enumerate() {
        let v = out.vectors.col_as_slice(j);
        op.apply(v, &mut y);
        let r: Vec<c64> = y.iter().zip(v).map(|(a, b)| a - th * b).collect();
        worst = worst.max(cnorm(&r) / (th.norm() * cnorm(v)));
    }
    worst
}

/// Matches every expected eigenvalue to a distinct computed one; returns the worst
/// relative error.
fn match_error(expected: &[c64], got: &[c64]) -> f64 {
    assert_eq!(
        expected.len(),
        got.len(),
        "expected {expected:?}\ngot {got:?}"
    );
    let mut used = vec![false; got.len()];
    let mut worst: f64 = 0.0;
    for e in expected {
        let (best, err) = got
            .iter()
            .enumerate()
            .filter(|(i, _)| !used[*i])
            .map(|(i, g)| (i, (g - e).norm() / e.norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        used[best] = true;
        worst = worst.max(err);
    }
    worst
}

/// Smallest singular value of the unit-normalized columns `cols` of `v` (independence).
fn independence(v: &Mat<c64>, cols: &[usize]) -> f64 {
    let n = v.nrows();
    let a = Mat::from_fn(n, cols.len(), |i, j| v[(i, cols[j])]);
    let a = normalized_columns(a);
    let s = a.singular_values().unwrap();
    s.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Distance of the true eigenvectors `S e_j` (`j in idx`) from the span of the computed
/// columns `cols` (relative).
fn span_error(v: &Mat<c64>, cols: &[usize], s: &Mat<c64>, idx: &[usize]) -> f64 {
    let n = v.nrows();
    let a = Mat::from_fn(n, cols.len(), |i, j| v[(i, cols[j])]);
    let qr = a.qr();
    let q = qr.compute_thin_Q();
    let mut worst: f64 = 0.0;
    for &j in idx {
        let mut x: Vec<c64> = (0..n).map(|i| s[(i, j)]).collect();
        let nx = cnorm(&x);
        cgs_pass(&mut x, q.as_ref(), None);
        cgs_pass(&mut x, q.as_ref(), None);
        worst = worst.max(cnorm(&x) / nx);
    }
    worst
}

fn cols_near(theta: &[c64], value: c64, rel: f64) -> Vec<usize> {
    (0..theta.len())
        .filter(|&i| (theta[i] - value).norm() <= rel * value.norm())
        .collect()
}

#[test]
fn well_conditioned_spectrum_with_double_near_pair_conjugates_and_cluster() {
    let n = 200;
    let d = spectrum(n);
    let (a, s) = similar(&d, |_| 1.0, 11);
    let op = Dense(a);
    let out = KrylovSchurKernel.largest(&op, 10, 1e-12, 300).unwrap();
    assert!(out.all_converged, "iterations {}", out.iterations);
    assert_eq!(out.theta.len(), 10);
    let err = match_error(&top(&d, 10), &out.theta);
    assert!(err <= 1e-10, "eigenvalue error {err:e}: {:?}", out.theta);
    let res = max_residual(&op, &out);
    assert!(res <= 1e-10, "residual {res:e}");

    // Both copies of the exact double, with independent vectors spanning the eigenspace.
    let double = cols_near(&out.theta, c64::new(10.0, 0.0), 1e-9);
    assert_eq!(double.len(), 2, "{:?}", out.theta);
    let sv = independence(&out.vectors, &double);
    assert!(
        sv > 0.1,
        "copies of the double are not independent: sigma_min {sv:e}"
    );
    let span = span_error(&out.vectors, &double, &s, &[0, 1]);
    assert!(span <= 1e-9, "eigenspace of the double missed: {span:e}");
    // The near pair: two distinct values, each with its own eigenvector.
    for (j, value) in [(2, d[2]), (3, d[3])] {
        let c = cols_near(&out.theta, value, 1e-9);
        assert_eq!(c.len(), 1, "near pair value {value}: {:?}", out.theta);
        let e = span_error(&out.vectors, &c, &s, &[j]);
        assert!(e <= 1e-4, "eigenvector of near-pair member {j}: {e:e}");
    }
    // The conjugate pair.
    for value in [d[4], d[5]] {
        assert_eq!(cols_near(&out.theta, value, 1e-10).len(), 1);
    }
    eprintln!(
        "well-conditioned n = {n}: restarts {}, eig err {err:.1e}, residual {res:.1e}, \
         double sigma_min {sv:.2}",
        out.iterations
    );
}

#[test]
fn non_normal_operator_converges() {
    let n = 200;
    let d = spectrum(n);
    // Row scaling from 1 to 1e-4: eigenvector condition ~ 1e4.
    let (a, s) = similar(&d, |i| 10f64.powf(-4.0 * i as f64 / (n - 1) as f64), 23);
    let cond = {
        let sv = s.singular_values().unwrap();
        sv[0] / sv[n - 1]
    };
    assert!(
        cond > 5e3,
        "test matrix not ill-conditioned enough: {cond:e}"
    );
    let op = Dense(a);
    let out = KrylovSchurKernel.largest(&op, 10, 1e-12, 500).unwrap();
    assert!(out.all_converged, "iterations {}", out.iterations);
    assert_eq!(out.theta.len(), 10);
    let res = max_residual(&op, &out);
    assert!(res <= 1e-10, "residual {res:e}");
    let err = match_error(&top(&d, 10), &out.theta);
    // Eigenvalue error ~ condition x residual.
    assert!(err <= 1e-7, "eigenvalue error {err:e}: {:?}", out.theta);
    let double = cols_near(&out.theta, c64::new(10.0, 0.0), 1e-7);
    assert_eq!(double.len(), 2, "{:?}", out.theta);
    let sv = independence(&out.vectors, &double);
    assert!(
        sv > 1e-3,
        "copies of the double are not independent: {sv:e}"
    );
    eprintln!(
        "non-normal (cond(S) = {cond:.1e}): restarts {}, eig err {err:.1e}, residual {res:.1e}, \
         double sigma_min {sv:.2e}",
        out.iterations
    );
}

#[test]
fn exact_triple_returns_three_independent_copies() {
    // A triple eigenvalue on top of a bulk: three independent vectors spanning the
    // eigenspace (found by locking + deflation or by the validation runs).
    let n = 120;
    let mut d: Vec<c64> = (0..n)
        .map(|i| c64::new(1.0 + 0.02 * i as f64, 0.0))
        .collect();
    d[n - 1] = c64::new(9.0, 1.0);
    d[n - 2] = c64::new(9.0, 1.0);
    d[n - 3] = c64::new(9.0, 1.0);
    let (a, s) = similar(&d, |_| 1.0, 5);
    let op = Dense(a);
    let out = KrylovSchurKernel.largest(&op, 6, 1e-12, 300).unwrap();
    assert!(out.all_converged);
    let triple = cols_near(&out.theta, c64::new(9.0, 1.0), 1e-9);
    assert_eq!(triple.len(), 3, "{:?}", out.theta);
    assert!(independence(&out.vectors, &triple) > 0.1);
    assert!(span_error(&out.vectors, &triple, &s, &[n - 3, n - 2, n - 1]) < 1e-9);
    assert!(max_residual(&op, &out) <= 1e-10);
    assert!(match_error(&top(&d, 6), &out.theta) <= 1e-10);
}

#[test]
fn restart_cap_reports_not_converged_instead_of_failing() {
    let n = 200;
    let d = spectrum(n);
    let (a, _) = similar(&d, |_| 1.0, 11);
    let op = Dense(a);
    let out = KrylovSchurKernel.largest(&op, 10, 1e-12, 1).unwrap();
    assert!(!out.all_converged);
    assert!(out.theta.len() < 10, "{:?}", out.theta);
    assert!(out.iterations <= 1);
    // Whatever is returned passed the convergence test.
    assert!(max_residual(&op, &out) <= 1e-9);
}

#[test]
fn nev_at_least_n_uses_the_dense_fallback() {
    let n = 30;
    let d: Vec<c64> = (0..n)
        .map(|i| c64::new(1.0 + i as f64, 0.5 * (i as f64).sin()))
        .collect();
    let (a, _) = similar(&d, |_| 1.0, 3);
    let op = Dense(a);
    for nev in [n, n + 7] {
        let out = KrylovSchurKernel.largest(&op, nev, 1e-12, 10).unwrap();
        assert!(out.all_converged);
        assert_eq!(out.theta.len(), n);
        assert!(match_error(&d, &out.theta) <= 1e-10);
        assert!(max_residual(&op, &out) <= 1e-10);
    }
}

#[test]
fn small_operator_exhausts_the_space() {
    // n = 20 < ncv: the basis covers the space; Ritz pairs are exact.
    let n = 20;
    let mut d: Vec<c64> = (0..n).map(|i| c64::new(1.0 + i as f64, 1.0)).collect();
    d[0] = c64::new(30.0, 0.0);
    d[1] = c64::new(30.0, 0.0);
    let (a, _) = similar(&d, |_| 1.0, 9);
    let op = Dense(a);
    let out = KrylovSchurKernel.largest(&op, 5, 1e-12, 50).unwrap();
    assert!(out.all_converged);
    assert!(match_error(&top(&d, 5), &out.theta) <= 1e-10);
    assert!(max_residual(&op, &out) <= 1e-10);
}

#[test]
fn invalid_tolerance_is_rejected() {
    let op = Dense(Mat::identity(4, 4));
    assert!(KrylovSchurKernel.largest(&op, 2, 0.0, 10).is_err());
    assert!(KrylovSchurKernel.largest(&op, 2, f64::NAN, 10).is_err());
    let out = KrylovSchurKernel.largest(&op, 0, 1e-10, 10).unwrap();
    assert!(out.theta.is_empty() && out.all_converged);
}

/// Shift-invert of a non-symmetric tridiagonal (1-D convection-diffusion)
/// `T = tridiag(-(1 + e), 2, -(1 - e))`, `OP = (T - sigma I)^-1` by a complex Thomas
/// factorization. Eigenvalues of `T`: `2 - 2 sqrt(1 - e^2) cos(j pi / (n + 1))`.
struct TridiagShiftInvert {
    n: usize,
    sub: f64,
    sup: f64,
    /// Thomas factors: modified super-diagonal and pivots.
    cp: Vec<c64>,
    piv: Vec<c64>,
}

impl TridiagShiftInvert {
    fn new(n: usize, e: f64, sigma: c64) -> Self {
        let (sub, sup) = (-(1.0 + e), -(1.0 - e));
        let diag = c64::new(2.0, 0.0) - sigma;
        let mut cp = vec![ZERO; n];
        let mut piv = vec![ZERO; n];
        for i in 0..n {
            piv[i] = if i == 0 { diag } else { diag - cp[i - 1] * sub };
            cp[i] = c64::new(sup, 0.0) / piv[i];
        }
        Self {
            n,
            sub,
            sup,
            cp,
            piv,
        }
    }

    fn eigenvalue(n: usize, e: f64, j: usize) -> f64 {
        2.0 - 2.0 * (1.0 - e * e).sqrt() * (j as f64 * std::f64::consts::PI / (n + 1) as f64).cos()
    }
}

impl LinOp<c64> for TridiagShiftInvert {
    fn dim(&self) -> usize {
        self.n
    }
    fn apply(&self, x: &[c64], y: &mut [c64]) {
        let n = self.n;
        for i in 0..n {
            let prev = if i == 0 { ZERO } else { y[i - 1] * self.sub };
            y[i] = (x[i] - prev) / self.piv[i];
        }
        for i in (0..n - 1).rev() {
            let next = y[i + 1];
            y[i] -= self.cp[i] * next;
        }
        let _ = self.sup;
    }
}

#[test]
fn tridiagonal_shift_invert_small() {
    let (n, e) = (2000, 2e-3);
    let sigma = c64::new(1.0, 1e-3);
    let op = TridiagShiftInvert::new(n, e, sigma);
    let out = KrylovSchurKernel.largest(&op, 12, 1e-12, 500).unwrap();
    assert!(out.all_converged);
    let lambda: Vec<c64> = out.theta.iter().map(|t| sigma + ONE / t).collect();
    let mut exact: Vec<c64> = (1..=n)
        .map(|j| c64::new(TridiagShiftInvert::eigenvalue(n, e, j), 0.0))
        .collect();
    exact.sort_by(|a, b| (a - sigma).norm().total_cmp(&(b - sigma).norm()));
    exact.truncate(12);
    let err = match_error(&exact, &lambda);
    assert!(err <= 1e-10, "{err:e}");
    assert!(max_residual(&op, &out) <= 1e-10);
}

/// Timing at n = 20 000, nev = 40 (run with `--ignored --nocapture`).
#[test]
#[ignore]
fn timing_tridiagonal_n20000_nev40() {
    let (n, e, nev) = (20_000, 2e-4, 40);
    let sigma = c64::new(1.0, 1e-4);
    let op = TridiagShiftInvert::new(n, e, sigma);
    let t0 = Instant::now();
    let out = KrylovSchurKernel.largest(&op, nev, 1e-10, 1000).unwrap();
    let dt = t0.elapsed().as_secs_f64();
    let lambda: Vec<c64> = out.theta.iter().map(|t| sigma + ONE / t).collect();
    let mut exact: Vec<c64> = (1..=n)
        .map(|j| c64::new(TridiagShiftInvert::eigenvalue(n, e, j), 0.0))
        .collect();
    exact.sort_by(|a, b| (a - sigma).norm().total_cmp(&(b - sigma).norm()));
    exact.truncate(nev);
    let err = match_error(&exact, &lambda);
    let res = max_residual(&op, &out);
    eprintln!(
        "n = {n}, nev = {nev}: {dt:.2} s, restarts {}, converged {} ({}), \
         lambda err {err:.1e}, residual {res:.1e}",
        out.iterations,
        out.theta.len(),
        out.all_converged
    );
    assert!(out.all_converged);
    assert!(err <= 1e-8);
}

struct DiagOp(Vec<c64>);
impl LinOp<c64> for DiagOp {
    fn dim(&self) -> usize {
        self.0.len()
    }
    fn apply(&self, x: &[c64], y: &mut [c64]) {
        for i in 0..x.len() {
            y[i] = self.0[i] * x[i];
        }
    }
}

/// An exactly diagonal (normal) operator: rounding barely seeds the second copy of a
/// double, so the first run misses it (checked by disabling the validation runs) and only
/// the validation run on the deflated operator finds it.
#[test]
fn missed_copy_of_a_double_is_found_by_the_validation_run() {
    let n = 300;
    let mut d: Vec<c64> = (0..n)
        .map(|i| c64::new(0.99 * (1.0 - i as f64 / n as f64), 0.0))
        .collect();
    d[7] = ONE;
    d[100] = ONE;
    for nev in [2, 3] {
        let op = DiagOp(d.clone());
        let out = KrylovSchurKernel.largest(&op, nev, 1e-10, 300).unwrap();
        assert!(out.all_converged);
        let copies = cols_near(&out.theta, ONE, 1e-8);
        assert_eq!(copies.len(), 2, "nev {nev}: {:?}", out.theta);
        assert!(independence(&out.vectors, &copies) > 0.1);
        // The two vectors span {e_7, e_100}.
        for &c in &copies {
            let v = out.vectors.col_as_slice(c);
            let off = (v[7].norm_sqr() + v[100].norm_sqr() - 1.0).abs();
            assert!(off < 1e-9, "{off:e}");
        }
        assert!(match_error(&top(&d, nev), &out.theta) <= 1e-9);
        assert!(max_residual(&op, &out) <= 1e-9);
    }
}
