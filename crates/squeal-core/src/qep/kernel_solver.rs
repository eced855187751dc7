//! The eigen solver of a Krylov backend ([`KernelSolver`]): its two kernels around the
//! shared band drivers, so a backend writes its iterations and nothing else.

use super::{solve_frictional_band, solve_qep_band, ComplexKernel};
use crate::eigen::{
    solve_symmetric_band, solve_symmetric_band_on, EigenParams, EigenSolver, SymmetricKernel,
    SymmetricProblem,
};
use crate::operator::{ComplexModes, FrictionalOperator, Qep, RealModes};
use crate::spectral::ShiftInvert;
use crate::Result;
use faer::MatRef;

/// An [`EigenSolver`] made of a symmetric and a complex Krylov kernel: normal modes by
/// [`solve_symmetric_band`], complex modes by [`solve_qep_band`] and frictional operators
/// by [`solve_frictional_band`] (which may take the low-rank path of an undamped one).
#[derive(Debug, Clone, Copy)]
pub struct KernelSolver<S, C> {
    name: &'static str,
    symmetric: S,
    complex: C,
}

impl<S: SymmetricKernel, C: ComplexKernel> KernelSolver<S, C> {
    /// The solver `name` (its registered name, reported in every [`SolveInfo`](crate::SolveInfo)).
    pub const fn new(name: &'static str, symmetric: S, complex: C) -> Self {
        Self {
            name,
            symmetric,
            complex,
        }
    }

    /// The kernel of the normal modes.
    pub fn symmetric_kernel(&self) -> &S {
        &self.symmetric
    }

    /// The kernel of the complex modes.
    pub fn complex_kernel(&self) -> &C {
        &self.complex
    }
}

impl<S: SymmetricKernel, C: ComplexKernel> EigenSolver for KernelSolver<S, C> {
    fn name(&self) -> &str {
        self.name
    }

    fn solve_symmetric(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        solve_symmetric_band(self.name, &self.symmetric, problem, params)
    }

    fn solve_symmetric_on(
        &self,
        problem: &SymmetricProblem<'_>,
        op: &ShiftInvert<'_>,
        start: Option<MatRef<'_, f64>>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        solve_symmetric_band_on(self.name, &self.symmetric, problem, op, start, params)
    }

    fn solve_qep(&self, qep: &Qep, params: &EigenParams) -> Result<ComplexModes> {
        solve_qep_band(self.name, &self.complex, qep, params)
    }

    fn solve_frictional(
        &self,
        op: &FrictionalOperator,
        mu: f64,
        params: &EigenParams,
    ) -> Result<ComplexModes> {
        solve_frictional_band(self.name, &self.complex, op, mu, params)
    }
}
