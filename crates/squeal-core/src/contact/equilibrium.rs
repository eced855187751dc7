//! The [`EquilibriumSolver`] plugin trait and the data it exchanges: the static contact
//! problem ([`ContactProblem`]) and its sliding equilibrium ([`Equilibrium`]).

use super::{Condensation, ContactLaw};
use crate::{Error, Result, SparseRef};

/// The static contact problem on the free DOFs.
#[derive(Clone, Copy)]
pub struct ContactProblem<'a> {
    /// Stiffness on the free DOFs (N/m).
    pub k: SparseRef<'a>,
    /// External load on the free DOFs (N), imposed displacements included.
    pub f: &'a [f64],
    /// Normal projection, `nc x n`.
    pub pn: SparseRef<'a>,
    /// Tangential projection along each pair's sliding direction, `nc x n`.
    pub pt: SparseRef<'a>,
    /// Initial gaps (m), one per pair.
    pub g0: &'a [f64],
}

/// A sliding equilibrium and how it was reached.
#[derive(Debug, Clone)]
pub struct Equilibrium {
    /// Friction coefficient it was computed for.
    pub mu: f64,
    /// Displacements on the free DOFs (m).
    pub u: Vec<f64>,
    /// Normal reactions (N), one per pair.
    pub rn: Vec<f64>,
    /// Pairs in the effective contact set.
    pub active: Vec<bool>,
    /// Outer iterations.
    pub iterations: usize,
    /// Sparse factorizations of `K` performed.
    pub factorizations: usize,
    /// Backward error of the global equilibrium,
    /// `||K U - F - (Pn + mu Pt)^T Rn|| / (||K||_1 ||U|| + ||F + (Pn + mu Pt)^T Rn||)`.
    pub equilibrium_residual: f64,
    /// Complementarity residual, relative to the total normal force.
    pub complementarity_residual: f64,
    /// Wall time (s).
    pub time_s: f64,
}

/// Computes the steady full-sliding equilibrium.
///
/// A solver works on the problem condensed on the contact pairs ([`Condensation`]), so
/// that a sweep over mu factorizes `K` once; [`solve`](Self::solve) condenses and solves.
pub trait EquilibriumSolver: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Solves for friction coefficient `mu` under the given law, on a condensation of
    /// `problem`.
    fn solve_condensed(
        &self,
        cond: &Condensation,
        problem: &ContactProblem<'_>,
        law: &dyn ContactLaw,
        mu: f64,
    ) -> Result<Equilibrium>;
    /// Condenses `problem` (one factorization of `K`) and solves it.
    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        law: &dyn ContactLaw,
        mu: f64,
    ) -> Result<Equilibrium> {
        let start = std::time::Instant::now();
        check_mu(mu)?;
        let cond = Condensation::new(problem)?;
        let mut eq = self.solve_condensed(&cond, problem, law, mu)?;
        eq.time_s = start.elapsed().as_secs_f64();
        Ok(eq)
    }
}

/// Rejects a non-finite friction coefficient (a negative one is valid here: it is the
/// same as reversing the rotation; user-facing inputs reject it earlier).
pub fn check_mu(mu: f64) -> Result<()> {
    if mu.is_finite() {
        Ok(())
    } else {
        Err(Error::param(
            "mu",
            format!("expected a finite friction coefficient, got {mu}"),
        ))
    }
}
