//! Dense pieces of the Krylov-Schur kernel: complex vector operations, block
//! Gram-Schmidt, the Schur deflation and eigenvectors of triangular matrices, and the
//! dense fallback for small operators.

use super::*;
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::linalg::solvers::Solve;
use squeal_core::faer::{Accum, Mat, MatMut, MatRef};
use squeal_core::qep::ComplexKernelOutput;
use squeal_core::spectral::LinOp;
use squeal_core::{c64, Error, Result};

/// `nev >= n`: every eigenpair of the operator, densely.
pub(super) fn dense_fallback(op: &dyn LinOp<c64>, nev: usize) -> Result<ComplexKernelOutput> {
    let n = op.dim();
    if n > DENSE_MAX {
        return Err(Error::param(
            "nev",
            format!(
                "krylov: nev = {nev} >= n = {n} asks for every eigenvalue; the dense \
                 fallback is limited to n <= {DENSE_MAX}"
            ),
        ));
    }
    let mut a = Mat::<c64>::zeros(n, n);
    let mut e = vec![ZERO; n];
    let mut col = vec![ZERO; n];
    for j in 0..n {
        e[j] = ONE;
        op.apply(&e, &mut col);
        e[j] = ZERO;
        for i in 0..n {
            a[(i, j)] = col[i];
        }
    }
    let eig = a
        .eigen()
        .map_err(|e| Error::Invalid(format!("krylov: dense eigen fallback: {e:?}")))?;
    let s = eig.S();
    let u = eig.U();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| s[j].norm().total_cmp(&s[i].norm()));
    let theta = order.iter().map(|&i| s[i]).collect();
    let vectors = Mat::from_fn(n, n, |i, c| u[(i, order[c])]);
    let vectors = normalized_columns(vectors);
    Ok(ComplexKernelOutput {
        theta,
        vectors,
        iterations: 0,
        all_converged: true,
    })
}

/// Deterministic pseudo-random complex vector.
pub(super) fn complex_random(dirs: &mut Directions, n: usize) -> Vec<c64> {
    let re = dirs.vector(n);
    let im = dirs.vector(n);
    re.into_iter()
        .zip(im)
        .map(|(a, b)| c64::new(a, b))
        .collect()
}

/// `sum conj(a_i) b_i`.
pub(super) fn cdot(a: &[c64], b: &[c64]) -> c64 {
    a.iter().zip(b).fold(ZERO, |s, (x, y)| s + x.conj() * y)
}

/// Euclidean norm.
pub(super) fn cnorm(a: &[c64]) -> f64 {
    a.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt()
}

pub(super) fn scale(a: &mut [c64], s: f64) {
    a.iter_mut().for_each(|x| *x *= s);
}

pub(super) fn frobenius(a: MatRef<'_, c64>) -> f64 {
    let mut s = 0.0;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            s += a[(i, j)].norm_sqr();
        }
    }
    s.sqrt()
}

pub(super) fn normalized_columns(mut a: Mat<c64>) -> Mat<c64> {
    for j in 0..a.ncols() {
        let nrm = (0..a.nrows())
            .map(|i| a[(i, j)].norm_sqr())
            .sum::<f64>()
            .sqrt();
        if nrm > 0.0 {
            for i in 0..a.nrows() {
                a[(i, j)] *= 1.0 / nrm;
            }
        }
    }
    a
}

/// `Q Y` for a column-major `n x q` block and a dense `q x c` matrix.
pub(super) fn times(q: MatRef<'_, c64>, y: MatRef<'_, c64>) -> Mat<c64> {
    let mut out = Mat::<c64>::zeros(q.nrows(), y.ncols());
    matmul(
        out.as_mut(),
        Accum::Replace,
        q,
        y,
        ONE,
        par_for(q.nrows() * q.ncols() * y.ncols()),
    );
    out
}

/// One classical Gram-Schmidt pass: `c = Q^H w`, `w <- w - Q c`. Adds `c` to `acc` (when
/// given) and returns `||c||^2`.
pub(super) fn cgs_pass(w: &mut [c64], q: MatRef<'_, c64>, acc: Option<&mut [c64]>) -> f64 {
    let k = q.ncols();
    if k == 0 {
        return 0.0;
    }
    let n = w.len();
    let par = par_for(n * k);
    let mut c = vec![ZERO; k];
    matmul(
        MatMut::from_column_major_slice_mut(&mut c, k, 1),
        Accum::Replace,
        q.adjoint(),
        MatRef::from_column_major_slice(w, n, 1),
        ONE,
        par,
    );
    matmul(
        MatMut::from_column_major_slice_mut(w, n, 1),
        Accum::Add,
        q,
        MatRef::from_column_major_slice(&c, k, 1),
        -ONE,
        par,
    );
    if let Some(acc) = acc {
        acc.iter_mut().zip(&c).for_each(|(a, ci)| *a += ci);
    }
    c.iter().map(|x| x.norm_sqr()).sum()
}

/// Eigenvector `w` of the upper triangular part of `t` for `theta = t_jj` (`w_j = 1`,
/// `w_i = 0` for `i > j`), by back-substitution. A copy of a semisimple repeated
/// eigenvalue (tiny pivot *and* tiny right-hand side) gets `w_i = 0`; other tiny pivots
/// are replaced by `eps ||T||` (LAPACK `ztrevc`).
pub(super) fn triangular_eigvec(t: MatRef<'_, c64>, j: usize, tol: f64, tnorm: f64) -> Vec<c64> {
    let p = t.nrows();
    let th = t[(j, j)];
    let smin = (f64::EPSILON * tnorm).max(f64::MIN_POSITIVE);
    let mut w = vec![ZERO; p];
    w[j] = ONE;
    let mut wnorm2: f64 = 1.0;
    for i in (0..j).rev() {
        let mut s = ZERO;
        for l in i + 1..=j {
            s += t[(i, l)] * w[l];
        }
        let piv = t[(i, i)] - th;
        let scale_ref = th.norm() * wnorm2.sqrt();
        w[i] = if piv.norm() <= REPEAT_REL * th.norm() && s.norm() <= tol * scale_ref {
            ZERO
        } else if piv.norm() < smin {
            -s / c64::new(smin, 0.0)
        } else {
            -s / piv
        };
        wnorm2 += w[i].norm_sqr();
    }
    w
}

/// Orthonormal basis of the `H`-invariant subspace of the eigenvalues `targets` (any
/// order, repeats allowed): returns the unitary `Z` (`m x m`) whose first
/// `targets.len()` columns span it, and `W = Z^H H Z` with the sub-diagonal part of those
/// columns set to zero (upper triangular there, `W_jj ~ targets[j]`). `y[:, guess[j]]`
/// is an eigenvector of `H` for `targets[j]`, used as a start.
pub(super) fn schur_deflate(
    h: MatRef<'_, c64>,
    targets: &[c64],
    y: &Mat<c64>,
    guess: &[usize],
) -> Result<(Mat<c64>, Mat<c64>)> {
    let m = h.nrows();
    let mut w = h.to_owned();
    let mut z = Mat::<c64>::identity(m, m);
    let hnorm = frobenius(h).max(f64::MIN_POSITIVE);
    for (j, &sigma) in targets.iter().enumerate() {
        let s = m - j;
        // Start: the eigenvector of H in the current coordinates; its tail is an
        // eigenvector of the trailing block unless the eigenvalue was already deflated
        // (a repeated one), in which case a fixed vector is used.
        let g = guess[j];
        let mut x0: Vec<c64> = (j..m)
            .map(|i| (0..m).fold(ZERO, |acc, r| acc + z[(r, i)].conj() * y[(r, g)]))
            .collect();
        if cnorm(&x0) < 1e-3 {
            x0 = (0..s)
                .map(|i| c64::new(1.0 + 0.3 * (i as f64 * 1.3).sin(), 0.2 * (i as f64).cos()))
                .collect();
        }
        let x = trailing_eigvec(w.get(j.., j..), sigma, x0, hnorm)?;
        // Householder reflector P = I - tau v v^H with P x = beta e_1, so P e_1 ~ x.
        let x0n = x[0].norm();
        let phase = if x0n > 0.0 { x[0] / x0n } else { ONE };
        let mut v = x.clone();
        v[0] += phase * cnorm(&x);
        let vv: f64 = v.iter().map(|a| a.norm_sqr()).sum();
        if vv > 0.0 {
            let tau = 2.0 / vv;
            // Rows j.. of W: W <- P W.
            for col in 0..m {
                let mut d = ZERO;
                for i in 0..s {
                    d += v[i].conj() * w[(j + i, col)];
                }
                let d = d * tau;
                for i in 0..s {
                    let vi = v[i];
                    w[(j + i, col)] -= vi * d;
                }
            }
            // Columns j.. of W and Z: A <- A P.
            for a in [&mut w, &mut z] {
                for row in 0..m {
                    let mut d = ZERO;
                    for i in 0..s {
                        d += a[(row, j + i)] * v[i];
                    }
                    let d = d * tau;
                    for i in 0..s {
                        let vc = v[i].conj();
                        a[(row, j + i)] -= d * vc;
                    }
                }
            }
        }
        for i in j + 1..m {
            w[(i, j)] = ZERO;
        }
    }
    Ok((z, w))
}

/// Unit eigenvector of `a` for the eigenvalue nearest `sigma`: shifted inverse iteration
/// from `x0`, dense `eigen` as fallback.
pub(super) fn trailing_eigvec(
    a: MatRef<'_, c64>,
    sigma: c64,
    x0: Vec<c64>,
    hnorm: f64,
) -> Result<Vec<c64>> {
    let s = a.nrows();
    if s == 1 {
        return Ok(vec![ONE]);
    }
    let accept = DEFLATION_ACCEPT * f64::EPSILON * hnorm;
    let residual = |x: &[c64]| -> f64 {
        let xm = MatRef::from_column_major_slice(x, s, 1);
        let ax = times(a, xm);
        let rho = cdot(x, ax.col_as_slice(0));
        let r: Vec<c64> = ax
            .col_as_slice(0)
            .iter()
            .zip(x)
            .map(|(p, q)| p - rho * q)
            .collect();
        cnorm(&r)
    };
    let delta = c64::new(0.6, 0.8) * (16.0 * f64::EPSILON * hnorm);
    let shifted = Mat::from_fn(s, s, |i, j| {
        if i == j {
            a[(i, j)] - sigma - delta
        } else {
            a[(i, j)]
        }
    });
    let lu = shifted.partial_piv_lu();
    let mut x = x0;
    let n0 = cnorm(&x);
    scale(&mut x, 1.0 / n0);
    for _ in 0..INVERSE_STEPS {
        let mut rhs = Mat::from_fn(s, 1, |i, _| x[i]);
        lu.solve_in_place(rhs.as_mut());
        let mut xn: Vec<c64> = rhs.col_as_slice(0).to_vec();
        let nrm = cnorm(&xn);
        if !(nrm.is_finite() && nrm > 0.0) {
            break;
        }
        scale(&mut xn, 1.0 / nrm);
        x = xn;
        if residual(&x) <= accept {
            return Ok(x);
        }
    }
    // Fallback: dense eigen of the block, eigenvalue nearest sigma.
    let eig = a
        .eigen()
        .map_err(|e| Error::Invalid(format!("krylov: Schur deflation: {e:?}")))?;
    let sv = eig.S();
    let best = (0..s)
        .min_by(|&i, &j| (sv[i] - sigma).norm().total_cmp(&(sv[j] - sigma).norm()))
        .unwrap_or(0);
    let mut x: Vec<c64> = (0..s).map(|i| eig.U()[(i, best)]).collect();
    let nrm = cnorm(&x);
    scale(&mut x, 1.0 / nrm);
    Ok(x)
}
