//! The [`EigenSolver`] plugin trait.

use super::{EigenParams, SymmetricProblem};
use crate::operator::{ComplexModes, FrictionalOperator, Qep, RealModes};
use crate::{Error, Result};

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
