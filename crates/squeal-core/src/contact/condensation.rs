//! The contact problem condensed on the pairs after one factorization of `K`
//! ([`Condensation`]), shared by every equilibrium solver.

use super::{ContactLaw, ContactProblem, Equilibrium};
use crate::linalg::{norm2, spmv, Cholesky};
use crate::{Error, Result, SparseMat, SparseRef};
use faer::sparse::Triplet;
use faer::Mat;
use std::sync::Arc;

/// The contact problem condensed on the pairs after one Cholesky factorization of `K`:
/// gaps `g = q + (W + mu Wnt) Rn` with `q = g0 + Pn K^-1 F`, `W = Pn K^-1 Pn^T` and
/// `Wnt = Pn K^-1 Pt^T` (contact flexibilities, m/N). Shared by every equilibrium
/// solver; it keeps the factorization to recover displacements.
pub struct Condensation {
    factor: Arc<Cholesky>,
    /// `W = Pn K^-1 Pn^T` (m/N), symmetric positive definite.
    pub w: Mat<f64>,
    /// `Wnt = Pn K^-1 Pt^T` (m/N).
    pub wnt: Mat<f64>,
    /// Gaps under the external load alone, `g0 + Pn K^-1 F` (m).
    pub q: Vec<f64>,
    /// Wall time of the condensation (s).
    pub time_s: f64,
}

impl Condensation {
    /// Factorizes `K` once and solves for the `2 nc` unit contact loads (in blocks).
    pub fn new(problem: &ContactProblem<'_>) -> Result<Self> {
        let start = std::time::Instant::now();
        let n = problem.k.nrows();
        let nc = problem.pn.nrows();
        check_problem(problem)?;
        let factor = Cholesky::new(problem.k, "K (contact condensation)")?;
        let pnt = transpose(problem.pn);
        let ptt = transpose(problem.pt);
        let mut w = Mat::<f64>::zeros(nc, nc);
        let mut wnt = Mat::<f64>::zeros(nc, nc);
        const BLOCK: usize = 64;
        for (src, dst) in [(&pnt, &mut w), (&ptt, &mut wnt)] {
            let mut c0 = 0;
            while c0 < nc {
                let b = BLOCK.min(nc - c0);
                let mut x = Mat::<f64>::zeros(n, b);
                for c in 0..b {
                    let a = src.as_ref();
                    for (r, v) in a.row_idx_of_col(c0 + c).zip(a.val_of_col(c0 + c)) {
                        x[(r, c)] = *v;
                    }
                }
                factor.solve_in_place(x.as_mut());
                let y = crate::linalg::sparse_times(problem.pn, x.as_ref());
                dst.as_mut().subcols_mut(c0, b).copy_from(&y);
                c0 += b;
            }
        }
        let mut kf = problem.f.to_vec();
        factor.solve_vec_in_place(&mut kf);
        let mut q = vec![0.0; nc];
        spmv(problem.pn, &kf, &mut q);
        q.iter_mut().zip(problem.g0).for_each(|(a, b)| *a += b);
        Ok(Self {
            factor: Arc::new(factor),
            w,
            wnt,
            q,
            time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// The Cholesky factor of `K`, shared (a free-interface synthesis of the same model
    /// takes it instead of factorizing `K` again).
    pub fn factor(&self) -> &Arc<Cholesky> {
        &self.factor
    }

    /// Number of pairs.
    pub fn pairs(&self) -> usize {
        self.q.len()
    }

    /// The LCP matrix `W + mu Wnt + c I` of a law with compliance `c`.
    pub fn lcp_matrix(&self, mu: f64, compliance: f64) -> Mat<f64> {
        let nc = self.pairs();
        Mat::from_fn(nc, nc, |i, j| {
            self.w[(i, j)] + mu * self.wnt[(i, j)] + if i == j { compliance } else { 0.0 }
        })
    }

    /// Builds the [`Equilibrium`] of reactions `rn`: displacements from one solve with
    /// the kept factorization, the global equilibrium residual as a backward error
    /// `||K U - F - (Pn + mu Pt)^T Rn|| / (||K||_1 ||U|| + ||F + (Pn + mu Pt)^T Rn||)`
    /// (relative to the load alone it would measure the cancellation in `K U`, about
    /// `cond(K)` times round-off, rather than the solve), the complementarity
    /// residual (largest of: negative reaction / total, penetration beyond the law's
    /// compliance / gap scale, `Rn_i g_i` / (total x gap scale)), and the active set
    /// `Rn_i > 1e-9 max Rn`.
    pub fn finish(
        &self,
        problem: &ContactProblem<'_>,
        law: &dyn ContactLaw,
        rn: Vec<f64>,
        mu: f64,
        iterations: usize,
        time_s: f64,
    ) -> Result<Equilibrium> {
        if !rn.iter().any(|&r| r > 0.0) {
            return Err(Error::Invalid(format!(
                "no contact: the load opens every one of the {} pairs (is the disc pressed \
                 towards the pin?)",
                rn.len()
            )));
        }
        let n = problem.k.nrows();
        let mut load = problem.f.to_vec();
        add_transpose_times(problem.pn, &rn, 1.0, &mut load);
        add_transpose_times(problem.pt, &rn, mu, &mut load);
        let mut u = load.clone();
        self.factor.solve_vec_in_place(&mut u);
        let mut ku = vec![0.0; n];
        spmv(problem.k, &u, &mut ku);
        let r: Vec<f64> = ku.iter().zip(&load).map(|(a, b)| a - b).collect();
        let equilibrium_residual = norm2(&r)
            / (crate::linalg::norm1(problem.k) * norm2(&u) + norm2(&load)).max(f64::MIN_POSITIVE);
        let mut g = vec![0.0; rn.len()];
        spmv(problem.pn, &u, &mut g);
        g.iter_mut().zip(problem.g0).for_each(|(a, b)| *a += b);
        let c = law.compliance();
        let total: f64 = rn.iter().sum::<f64>().abs().max(f64::MIN_POSITIVE);
        let gscale = self
            .q
            .iter()
            .fold(0.0f64, |a, b| a.max(b.abs()))
            .max(f64::MIN_POSITIVE);
        let mut comp = 0.0f64;
        for (ri, gi) in rn.iter().zip(&g) {
            let gap = gi + c * ri; // zero for a closed pair under the law
            comp = comp
                .max((-ri).max(0.0) / total)
                .max((-gap).max(0.0) / gscale)
                .max((ri.max(0.0) / total) * (gap.abs() / gscale));
        }
        let rmax = rn.iter().fold(0.0f64, |a, &b| a.max(b));
        let active = rn.iter().map(|&r| r > 1e-9 * rmax).collect();
        Ok(Equilibrium {
            mu,
            u,
            rn,
            active,
            iterations,
            factorizations: 1,
            equilibrium_residual,
            complementarity_residual: comp,
            time_s,
        })
    }
}

fn check_problem(p: &ContactProblem<'_>) -> Result<()> {
    let n = p.k.nrows();
    let nc = p.pn.nrows();
    if nc == 0 {
        return Err(Error::Invalid(
            "the contact problem has no contact pairs".into(),
        ));
    }
    for (what, got, want) in [
        ("Pn columns", p.pn.ncols(), n),
        ("Pt columns", p.pt.ncols(), n),
        ("Pt rows", p.pt.nrows(), nc),
        ("F length", p.f.len(), n),
        ("g0 length", p.g0.len(), nc),
    ] {
        if got != want {
            return Err(Error::Dimension {
                context: format!("contact problem: {what}"),
                expected: want,
                got,
            });
        }
    }
    if p.f.iter().chain(p.g0).any(|v| !v.is_finite()) {
        return Err(Error::Invalid(
            "contact problem: F or g0 holds NaN or infinite values".into(),
        ));
    }
    Ok(())
}

fn transpose(a: SparseRef<'_>) -> SparseMat {
    let mut t = Vec::with_capacity(a.compute_nnz());
    for j in 0..a.ncols() {
        for (r, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            t.push(Triplet::new(j, r, *v));
        }
    }
    SparseMat::try_new_from_triplets(a.ncols(), a.nrows(), &t).expect("valid transpose")
}

/// `y += alpha A^T x`.
pub fn add_transpose_times(a: SparseRef<'_>, x: &[f64], alpha: f64, y: &mut [f64]) {
    for j in 0..a.ncols() {
        let s: f64 = a
            .row_idx_of_col(j)
            .zip(a.val_of_col(j))
            .map(|(r, v)| v * x[r])
            .sum();
        y[j] += alpha * s;
    }
}
