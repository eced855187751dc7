//! The exact solver of the linear complementarity problem of the equilibrium
//! ([`solve_lcp`]): block principal pivoting.

use crate::{Error, Result};
use faer::{Mat, MatRef};

/// Outcome of [`solve_lcp`].
#[derive(Debug, Clone)]
pub struct LcpSolution {
    /// The solution `z >= 0`.
    pub z: Vec<f64>,
    /// `w = q + A z >= 0`.
    pub w: Vec<f64>,
    /// Pivoting iterations (one dense solve each).
    pub iterations: usize,
}

/// Solves the linear complementarity problem `0 <= z ⟂ w = q + A z >= 0` exactly by
/// block principal pivoting (Júdice and Pires), falling back to Murty's single
/// least-index pivot when the number of infeasibilities stops decreasing: finite for a
/// P-matrix `A` (e.g. `W + mu Wnt` below the flutter of the contact problem, or a
/// symmetric positive definite `W`). Tolerances are relative to `max |q|` and `max |z|`.
pub fn solve_lcp(a: MatRef<'_, f64>, q: &[f64], max_iterations: usize) -> Result<LcpSolution> {
    let n = q.len();
    if a.nrows() != n || a.ncols() != n {
        return Err(Error::Dimension {
            context: "LCP matrix".into(),
            expected: n,
            got: a.nrows(),
        });
    }
    if q.iter().any(|v| !v.is_finite()) || (0..n).any(|j| (0..n).any(|i| !a[(i, j)].is_finite())) {
        return Err(Error::Invalid(
            "LCP data hold NaN or infinite values".into(),
        ));
    }
    let qscale = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut basic: Vec<bool> = q.iter().map(|&v| v < 0.0).collect();
    let mut best = usize::MAX;
    let mut trials = 3;
    let mut z = vec![0.0; n];
    let mut w = q.to_vec();
    let mut last = (0usize, 0.0f64, 0.0f64);
    for it in 1..=max_iterations {
        let s: Vec<usize> = (0..n).filter(|&i| basic[i]).collect();
        z.iter_mut().for_each(|v| *v = 0.0);
        if !s.is_empty() {
            let ass = Mat::from_fn(s.len(), s.len(), |i, j| a[(s[i], s[j])]);
            let rhs = Mat::from_fn(s.len(), 1, |i, _| -q[s[i]]);
            let zs = faer::linalg::solvers::Solve::solve(&ass.partial_piv_lu(), &rhs);
            for (k, &i) in s.iter().enumerate() {
                z[i] = zs[(k, 0)];
            }
        }
        for i in 0..n {
            w[i] = q[i] + s.iter().map(|&j| a[(i, j)] * z[j]).sum::<f64>();
        }
        if z.iter().chain(&w).any(|v| !v.is_finite()) {
            return Err(Error::NotConverged {
                method: "LCP block pivoting".into(),
                iterations: it,
                detail: "singular principal submatrix: the LCP matrix is not a P-matrix \
                         (friction too high for a unique sliding equilibrium?)"
                    .into(),
            });
        }
        let zscale = z
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        let (ez, ew) = (1e-12 * zscale, 1e-12 * qscale.max(f64::MIN_POSITIVE));
        let bad: Vec<usize> = (0..n)
            .filter(|&i| (basic[i] && z[i] < -ez) || (!basic[i] && w[i] < -ew))
            .collect();
        if bad.is_empty() {
            for i in 0..n {
                if basic[i] {
                    w[i] = 0.0; // w_S = 0 up to round-off
                } else {
                    z[i] = 0.0;
                }
            }
            return Ok(LcpSolution {
                z: z.iter().map(|v| v.max(0.0)).collect(),
                w,
                iterations: it,
            });
        }
        let worst_z = bad
            .iter()
            .filter(|&&i| basic[i])
            .map(|&i| -z[i])
            .fold(0.0, f64::max);
        let worst_w = bad
            .iter()
            .filter(|&&i| !basic[i])
            .map(|&i| -w[i])
            .fold(0.0, f64::max);
        last = (bad.len(), worst_z, worst_w);
        if bad.len() < best {
            best = bad.len();
            trials = 3;
            bad.iter().for_each(|&i| basic[i] = !basic[i]);
        } else if trials > 0 {
            trials -= 1;
            bad.iter().for_each(|&i| basic[i] = !basic[i]);
        } else {
            let i = bad[0]; // Murty: least index

            basic[i] = !basic[i];
        }
    }
    Err(Error::NotConverged {
        method: "LCP block pivoting".into(),
        iterations: max_iterations,
        detail: format!(
            "{} infeasible pairs left (largest negative reaction {:.3e}, largest \
             penetration {:.3e})",
            last.0, last.1, last.2
        ),
    })
}
