//! # squeal-equilibrium-lcp
//!
//! The direct sliding-equilibrium solver `lcp`: one Cholesky factorization of `K`,
//! condensation on the contact pairs (`2 nc` solves), then the non-symmetric linear
//! complementarity problem `0 <= Rn ⟂ q + (W + mu Wnt + c I) Rn >= 0` solved exactly by
//! block principal pivoting. `c` is the contact law's compliance
//! (0 for `lagrange`, `1/kn` for `penalty`).
//!
//! Parameters: `max_iterations` (pivoting steps, default 1000).

use squeal_core::contact::{check_mu, solve_lcp, Condensation, ContactProblem, Equilibrium};
use squeal_core::{ContactLaw, EquilibriumSolver, Registry, Result};
use std::time::Instant;

/// The condensed-LCP equilibrium solver.
#[derive(Debug, Clone)]
pub struct LcpSolver {
    /// Cap on pivoting steps.
    pub max_iterations: usize,
}

impl Default for LcpSolver {
    fn default() -> Self {
        Self {
            max_iterations: 1000,
        }
    }
}

impl EquilibriumSolver for LcpSolver {
    fn name(&self) -> &str {
        "lcp"
    }

    fn solve_condensed(
        &self,
        cond: &Condensation,
        problem: &ContactProblem<'_>,
        law: &dyn ContactLaw,
        mu: f64,
    ) -> Result<Equilibrium> {
        let start = Instant::now();
        check_mu(mu)?;
        let a = cond.lcp_matrix(mu, law.compliance());
        let sol = solve_lcp(a.as_ref(), &cond.q, self.max_iterations)?;
        cond.finish(
            problem,
            law,
            sol.z,
            mu,
            sol.iterations,
            start.elapsed().as_secs_f64(),
        )
    }
}

/// Registers `lcp`.
pub fn register(reg: &mut Registry) {
    reg.equilibrium.register(
        "lcp",
        "direct: condensation on the pairs after one factorization of K, exact LCP \
         (max_iterations)",
        |p| {
            Ok(Box::new(LcpSolver {
                max_iterations: p.usize_or("max_iterations", 1000)?,
            }))
        },
    );
}
