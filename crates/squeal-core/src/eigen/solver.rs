//! The [`EigenSolver`] plugin trait.

use super::{EigenParams, SymmetricProblem};
use crate::operator::{ComplexModes, FrictionalOperator, Qep, RealModes};
use crate::spectral::ShiftInvert;
use crate::{Error, Result};
use faer::MatRef;

/// The eigen solver plugin trait: real normal modes of a symmetric pencil and complex
/// modes of the frictional quadratic eigenproblem.
pub trait EigenSolver: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// All normal modes in `[params.fmin_hz, params.fmax_hz]`.
    fn solve_symmetric(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
    ) -> Result<RealModes>;
    /// The normal modes as [`solve_symmetric`](Self::solve_symmetric), on a shift-invert
    /// operator whose factorization the caller already holds (its shift replaces
    /// `params.shift_hz`), so a caller that also solves with `K - sigma M` (static
    /// responses) factorizes once. `start`, when given, holds approximations of the wanted
    /// modes (a nearby problem's, columns by ascending frequency) that an iterative
    /// solver may start from; the modes must meet `params.tol` either way. The default,
    /// for solvers that do not work by shift-invert, ignores `op` and `start`.
    fn solve_symmetric_on(
        &self,
        problem: &SymmetricProblem<'_>,
        op: &ShiftInvert<'_>,
        start: Option<MatRef<'_, f64>>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        let _ = (op, start);
        self.solve_symmetric(problem, params)
    }
    /// All complex modes of `qep` with frequency in `[params.fmin_hz, params.fmax_hz]`.
    fn solve_qep(&self, qep: &Qep, params: &EigenParams) -> Result<ComplexModes> {
        let _ = (qep, params);
        Err(Error::Unsupported {
            plugin: self.name().to_string(),
            operation: "the quadratic (frictional) eigenproblem".into(),
        })
    }
    /// The frictional operator at `mu`. The default combines the parts and calls
    /// [`solve_qep`](Self::solve_qep); a backend may exploit the low-rank friction part.
    fn solve_frictional(
        &self,
        op: &FrictionalOperator,
        mu: f64,
        params: &EigenParams,
    ) -> Result<ComplexModes> {
        self.solve_qep(&op.at(mu)?, params)
    }
}
