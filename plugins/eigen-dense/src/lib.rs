//! # squeal-eigen-dense
//!
//! The dense eigen backend, registered as `"dense"`: every eigenpair of the whole problem,
//! then the band filter. Meant for small models, reduced (projected) problems of size
//! 10^2 to 10^3 and as an oracle for the sparse backends.
//!
//! - Normal modes: [`squeal_core::eigen::dense_symmetric`] (`M = L L^T`, symmetric
//!   eigendecomposition of `L^-1 K L^-T`), finished by
//!   [`squeal_core::eigen::finish_real_modes`] (band, `M`-normalized vectors, residuals).
//! - Complex modes: [`squeal_core::qep::dense_qep`] (scaled companion form, faer's dense
//!   non-symmetric `eigen`), finished by [`squeal_core::qep::finish_modes`] (band,
//!   `Im > 0` members, unit vectors, backward errors).
//!
//! ## Parameters
//!
//! - `max_dim` (default 3000): largest problem size `n` accepted. Cost and memory are
//!   `O(n^3)` and `O(n^2)`; the QEP works on the companion matrix of size `2n`
//!   (about 1 s at `2n = 1000` on 2 cores, so roughly 30 s at `2n = 3000` and several
//!   minutes at `2n = 6000`). Larger problems are refused with an error pointing to the
//!   sparse backends.

use squeal_core::eigen::{dense_symmetric, finish_real_modes, validate_params};
use squeal_core::operator::check_qep;
use squeal_core::qep::{dense_qep, finish_modes};
use squeal_core::{
    ComplexModes, EigenParams, EigenSolver, Error, Params, Qep, RealModes, Registry, Result,
    SolveInfo, SymmetricProblem,
};
use std::time::Instant;

#[cfg(test)]
mod tests;

/// Name under which the solver is registered.
pub const NAME: &str = "dense";

/// One-line description shown by the registry.
pub const DESCRIPTION: &str = "dense eigen solver (whole spectrum, then band filter) for small \
                               and reduced problems; option max_dim (default 3000)";

/// Default of the `max_dim` parameter.
pub const DEFAULT_MAX_DIM: usize = 3000;

/// Registers the `"dense"` eigen solver.
pub fn register(reg: &mut Registry) {
    reg.eigen.register(NAME, DESCRIPTION, |params: &Params| {
        let max_dim = params.usize_or("max_dim", DEFAULT_MAX_DIM)?;
        if max_dim == 0 {
            return Err(Error::param("max_dim", "must be at least 1"));
        }
        let solver: Box<dyn EigenSolver> = Box::new(DenseSolver { max_dim });
        Ok(solver)
    });
}

/// The `"dense"` eigen solver.
#[derive(Debug, Clone)]
pub struct DenseSolver {
    /// Largest problem size `n` accepted (the QEP companion matrix is `2n x 2n`).
    pub max_dim: usize,
}

impl Default for DenseSolver {
    fn default() -> Self {
        Self {
            max_dim: DEFAULT_MAX_DIM,
        }
    }
}

impl DenseSolver {
    fn check_size(&self, n: usize, what: &str) -> Result<()> {
        if n == 0 {
            return Err(Error::Invalid(format!("empty {what} (no DOFs)")));
        }
        if n > self.max_dim {
            return Err(Error::param(
                "max_dim",
                format!(
                    "`{NAME}` refuses the {what} of size {n} > max_dim = {} (dense cost \
                     O(n^3), memory O(n^2)); use a sparse backend (arpack, krylov) or a \
                     reduction basis, or raise max_dim",
                    self.max_dim
                ),
            ));
        }
        Ok(())
    }

    fn info(&self, count: usize) -> SolveInfo {
        SolveInfo {
            requested: count,
            converged: count,
            ..SolveInfo::new(NAME)
        }
    }
}

impl EigenSolver for DenseSolver {
    fn name(&self) -> &str {
        NAME
    }

    fn solve_symmetric(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        let start = Instant::now();
        validate_params(params)?;
        let n = problem.k.nrows();
        self.check_size(n, "symmetric eigenproblem")?;
        squeal_core::linalg::check_square_finite(problem.k, n, "K")?;
        squeal_core::linalg::check_square_finite(problem.m, n, "M")?;
        let (omega2, vectors) = dense_symmetric(problem)?;
        let info = self.info(omega2.len());
        let mut modes = finish_real_modes(problem, &omega2, vectors.as_ref(), params, info);
        modes.info.time_s = start.elapsed().as_secs_f64();
        Ok(modes)
    }

    fn solve_qep(&self, qep: &Qep, params: &EigenParams) -> Result<ComplexModes> {
        let start = Instant::now();
        validate_params(params)?;
        self.check_size(qep.dim(), "quadratic eigenproblem")?;
        check_qep(qep)?;
        let (lambda, vectors) = dense_qep(qep)?;
        let info = self.info(lambda.len());
        let mut modes = finish_modes(qep, &lambda, vectors.as_ref(), params, info)?;
        modes.info.time_s = start.elapsed().as_secs_f64();
        Ok(modes)
    }
}
