//! The dense solver of small and reduced QEPs ([`dense_qep`]): the scaled companion
//! form, or the `n x n` problem of an undamped one.

use crate::linalg::norm1;
use crate::operator::{check_qep, Qep};
use crate::{c64, Error, Result};
use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef};

/// Roots of the scaled companion form (see [`dense_qep`]) with `|mu| <= RIGID_BODY_REL`,
/// i.e. `|lambda| <= RIGID_BODY_REL sqrt(||K|| / ||M||)`, are rigid-body roots: a zero
/// eigenvalue of a defective pencil is computed as `O(sqrt(eps))` (often a tiny
/// imaginary pair); [`dense_qep`] returns them as exact zeros.
pub const RIGID_BODY_REL: f64 = 1e-6;

/// All eigenpairs of a small QEP, densely: companion form scaled by
/// `gamma = sqrt(||K|| / ||M||)`, infinite and rigid-body roots filtered out.
/// Returns every finite eigenvalue (both members of conjugate pairs) and its vector `u`.
///
/// Scaling (Fan, Lin & Van Dooren 2004): `lambda = gamma mu`, `delta = 2 / (||K|| +
/// gamma ||C||)`, `M_s = gamma^2 delta M`, `C_s = gamma delta C`, `K_s = delta K`; the
/// companion matrix `[0 I; -M_s^-1 K_s  -M_s^-1 C_s]` (one dense LU of `M_s`) is then
/// diagonalized by faer's real non-symmetric `eigen` (no QZ). Non-finite roots are dropped;
/// roots with `|mu| <= RIGID_BODY_REL` are returned as exact zeros (rigid-body motions;
/// [`finish_modes`](super::finish_modes) drops them as non-oscillating). The vector is the first block of the
/// companion eigenvector (`u`), or the second divided by `mu` when `|mu| > 1` (the better
/// conditioned of the two). A singular `M` (massless DOFs) is an error. Cost: `O((2n)^3)`,
/// or `O(n^3)` when `C = 0`: the eigenvalues `t` of `M_s^-1 K_s` give `mu = +-sqrt(-t)`.
pub fn dense_qep(qep: &Qep) -> Result<(Vec<c64>, Mat<c64>)> {
    check_qep(qep)?;
    let n = qep.dim();
    if n == 0 {
        return Ok((Vec::new(), Mat::zeros(0, 0)));
    }
    let kn = norm1(qep.k.as_ref());
    let mn = norm1(qep.m.as_ref());
    let cn = qep.c.as_ref().map_or(0.0, |c| norm1(c.as_ref()));
    if mn == 0.0 {
        return Err(Error::Invalid(
            "dense QEP: the mass matrix M~ is zero (the companion form needs M~ invertible)".into(),
        ));
    }
    let gamma = if kn > 0.0 { (kn / mn).sqrt() } else { 1.0 };
    let denom = kn + gamma * cn;
    let delta = if denom > 0.0 {
        2.0 / denom
    } else {
        1.0 / (gamma * gamma * mn)
    };
    let ms = qep.m.as_ref().to_dense() * faer::Scale(gamma * gamma * delta);
    let lu = ms.partial_piv_lu();
    let u = lu.U();
    let (mut pmin, mut pmax) = (f64::INFINITY, 0.0f64);
    for i in 0..n {
        let p = u[(i, i)].abs();
        pmin = pmin.min(p);
        pmax = pmax.max(p);
    }
    if pmin.is_nan() || pmin <= 1e-14 * pmax {
        return Err(Error::Factorization {
            what: format!("M~ (dense, n = {n})"),
            reason: format!(
                "singular mass matrix (pivot ratio {:.2e}): massless DOFs make infinite \
                 eigenvalues; condense them out before the dense companion solve",
                pmin / pmax
            ),
        });
    }
    // W = M_s^-1 [K_s | C_s] (only M_s^-1 K_s when C = 0)
    let undamped = qep.c.is_none();
    let mut w = Mat::<f64>::zeros(n, if undamped { n } else { 2 * n });
    {
        let kd = qep.k.as_ref().to_dense();
        w.as_mut()
            .submatrix_mut(0, 0, n, n)
            .copy_from(kd * faer::Scale(delta));
        if let Some(c) = &qep.c {
            let cd = c.as_ref().to_dense();
            w.as_mut()
                .submatrix_mut(0, n, n, n)
                .copy_from(cd * faer::Scale(gamma * delta));
        }
    }
    lu.solve_in_place(w.as_mut());
    if undamped {
        return dense_qep_squared(w, gamma);
    }
    let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
    }
    for j in 0..2 * n {
        for i in 0..n {
            a[(n + i, j)] = -w[(i, j)];
        }
    }
    let eig = dense_eigen(a.as_ref(), n, "M~^-1 [K~ C~]", "companion form")?;
    let s = eig.S();
    let z = eig.U();
    let mut lambda = Vec::with_capacity(2 * n);
    let mut cols = Vec::with_capacity(2 * n);
    for k in 0..2 * n {
        let mu = s[k];
        if !(mu.re.is_finite() && mu.im.is_finite()) {
            continue;
        }
        let amu = mu.norm();
        let l = if amu <= RIGID_BODY_REL {
            c64::new(0.0, 0.0)
        } else {
            mu * gamma
        };
        lambda.push(l);
        cols.push((k, mu, amu));
    }
    let mut vectors = Mat::<c64>::zeros(n, lambda.len());
    for (c, &(k, mu, amu)) in cols.iter().enumerate() {
        if amu > 1.0 {
            let inv = c64::new(1.0, 0.0) / mu;
            for r in 0..n {
                vectors[(r, c)] = z[(n + r, k)] * inv;
            }
        } else {
            for r in 0..n {
                vectors[(r, c)] = z[(r, k)];
            }
        }
    }
    Ok((lambda, vectors))
}

/// Eigen decomposition of the dense matrix `a` (`what`, built from `M~^-1` of a QEP of
/// size `n`; `form` names it in errors), refused when it is not finite (singular mass).
fn dense_eigen(
    a: MatRef<'_, f64>,
    n: usize,
    what: &str,
    form: &str,
) -> Result<faer::linalg::solvers::Eigen<f64>> {
    if (0..a.ncols()).any(|j| (0..a.nrows()).any(|i| !a[(i, j)].is_finite())) {
        return Err(Error::Factorization {
            what: format!("M~ (dense, n = {n})"),
            reason: format!("{what} is not finite: the mass matrix is numerically singular"),
        });
    }
    faer::linalg::solvers::Eigen::new_from_real(a).map_err(|e| Error::NotConverged {
        method: format!("dense non-symmetric eigen ({form})"),
        iterations: 0,
        detail: format!("{e:?}"),
    })
}

/// The undamped branch of [`dense_qep`]: with `C = 0`, `mu^2 = -t` for the eigenvalues
/// `t` of `W = M_s^-1 K_s` (`n x n`, against `2n x 2n` for the companion form: 8 times
/// fewer flops), each `t` giving the two roots `mu = +-sqrt(-t)` with the same vector.
fn dense_qep_squared(w: Mat<f64>, gamma: f64) -> Result<(Vec<c64>, Mat<c64>)> {
    let n = w.nrows();
    let eig = dense_eigen(w.as_ref(), n, "M~^-1 K~", "M~^-1 K~, C = 0")?;
    let t = eig.S();
    let z = eig.U();
    let mut lambda = Vec::with_capacity(2 * n);
    let mut cols = Vec::with_capacity(2 * n);
    for k in 0..n {
        let root = (-t[k]).sqrt();
        if !(root.re.is_finite() && root.im.is_finite()) {
            continue;
        }
        for mu in [root, -root] {
            lambda.push(if mu.norm() <= RIGID_BODY_REL {
                c64::new(0.0, 0.0)
            } else {
                mu * gamma
            });
            cols.push(k);
        }
    }
    let vectors = Mat::<c64>::from_fn(n, cols.len(), |r, c| z[(r, cols[c])]);
    Ok((lambda, vectors))
}
