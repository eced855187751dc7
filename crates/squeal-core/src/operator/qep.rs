//! One quadratic eigenproblem `(lambda^2 M + lambda C + K) u = 0` and its input check.

use crate::linalg::check_square_finite;
use crate::{Result, SparseMat};

/// One quadratic eigenproblem `(lambda^2 M + lambda C + K) u = 0` (one mu, one contact set).
#[derive(Debug, Clone)]
pub struct Qep {
    /// Mass part `M~` (kg).
    pub m: SparseMat,
    /// Damping part `C~` (N s/m); `None` means zero.
    pub c: Option<SparseMat>,
    /// Stiffness part `K~` (N/m).
    pub k: SparseMat,
}

impl Qep {
    /// Size of the problem.
    pub fn dim(&self) -> usize {
        self.k.nrows()
    }
}

/// Checks that `M`, `C` and `K` are square of the same size with finite entries.
pub fn check_qep(qep: &Qep) -> Result<()> {
    let n = qep.dim();
    check_square_finite(qep.k.as_ref(), n, "K~")?;
    check_square_finite(qep.m.as_ref(), n, "M~")?;
    if let Some(c) = &qep.c {
        check_square_finite(c.as_ref(), n, "C~")?;
    }
    Ok(())
}
