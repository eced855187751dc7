//! # squeal-equilibrium-lorang
//!
//! The paper's fixed point (Lorang) for the full-sliding equilibrium: the friction forces
//! `mu Rn` of the previous iterate are applied as known loads, an inner Signorini
//! active-set loop gives the new normal reactions, and the two are repeated (with
//! optional relaxation `omega`) until the reactions and the active set stop changing.
//! With a fixed active set it converges iff `mu rho(W_AA^-1 Wnt_AA) < 1`;
//! relaxation helps when that ratio is close to one.
//!
//! Parameters: `relaxation` (omega in (0, 1], default 1), `tol` (relative change of
//! `Rn`, default 1e-11), `max_iterations` (outer, default 500).

use squeal_core::contact::{check_mu, solve_lcp, Condensation, ContactProblem, Equilibrium};
use squeal_core::{ContactLaw, EquilibriumSolver, Error, Registry, Result};
use std::time::Instant;

/// The fixed-point equilibrium solver.
#[derive(Debug, Clone)]
pub struct LorangSolver {
    /// Relaxation `omega` of the reaction update.
    pub relaxation: f64,
    /// Relative change of `Rn` (infinity norm) at convergence.
    pub tol: f64,
    /// Cap on outer iterations.
    pub max_iterations: usize,
}

impl Default for LorangSolver {
    fn default() -> Self {
        Self {
            relaxation: 1.0,
            tol: 1e-11,
            max_iterations: 500,
        }
    }
}

impl EquilibriumSolver for LorangSolver {
    fn name(&self) -> &str {
        "lorang"
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
        let nc = cond.pairs();
        let c = law.compliance();
        // the symmetric part only: W + c I (friction enters as a known load)
        let w = cond.lcp_matrix(0.0, c);
        let mut rn = vec![0.0; nc];
        let mut active: Vec<bool> = vec![false; nc];
        let mut change = f64::INFINITY;
        for it in 1..=self.max_iterations {
            // friction of the previous iterate as a known load
            let q: Vec<f64> = (0..nc)
                .map(|i| cond.q[i] + mu * (0..nc).map(|j| cond.wnt[(i, j)] * rn[j]).sum::<f64>())
                .collect();
            let inner = solve_lcp(w.as_ref(), &q, 10 * nc + 100)?;
            let new: Vec<f64> = inner
                .z
                .iter()
                .zip(&rn)
                .map(|(a, b)| self.relaxation * a + (1.0 - self.relaxation) * b)
                .collect();
            let scale = new.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            change = new
                .iter()
                .zip(&rn)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                / scale.max(f64::MIN_POSITIVE);
            let new_active: Vec<bool> = inner.z.iter().map(|&z| z > 0.0).collect();
            let same_set = new_active == active;
            rn = new;
            active = new_active;
            if !change.is_finite() {
                break;
            }
            if change <= self.tol && same_set {
                return cond.finish(problem, law, rn, mu, it, start.elapsed().as_secs_f64());
            }
        }
        Err(Error::NotConverged {
            method: "lorang fixed point".into(),
            iterations: self.max_iterations,
            detail: format!(
                "last relative change of Rn {change:.3e} (tol {:.1e}), {} active pairs; the \
                 fixed point diverges when mu rho(W^-1 Wnt) >= 1: try relaxation < 1 or the \
                 `lcp` solver",
                self.tol,
                active.iter().filter(|&&a| a).count()
            ),
        })
    }
}

/// Registers `lorang`.
pub fn register(reg: &mut Registry) {
    reg.equilibrium.register(
        "lorang",
        "fixed point on the friction forces with an inner Signorini active-set loop \
         (relaxation, tol, max_iterations)",
        |p| {
            let relaxation = p.num_or("relaxation", 1.0)?;
            if !(relaxation > 0.0 && relaxation <= 1.0) {
                return Err(Error::param(
                    "relaxation",
                    format!("expected omega in (0, 1], got {relaxation}"),
                ));
            }
            let tol = p.num_or("tol", 1e-11)?;
            if !(tol > 0.0 && tol < 1.0) {
                return Err(Error::param(
                    "tol",
                    format!("expected a relative tolerance in (0, 1), got {tol}"),
                ));
            }
            Ok(Box::new(LorangSolver {
                relaxation,
                tol,
                max_iterations: p.usize_or("max_iterations", 500)?,
            }))
        },
    );
}
