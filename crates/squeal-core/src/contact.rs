//! First versions of the contact-side plugin traits: [`ContactLaw`],
//! [`EquilibriumSolver`] and [`ReductionBasis`], with the data they exchange.
//!
//! Conventions (METHODS.md section 0): row `i` of `Pn` carries `+n_i` on the pin node and
//! `-n_i` on the disc node of pair `i` (a positive value opens the gap); `Pt` the same with
//! the sliding direction `e_i`. `Rn >= 0` is compressive and the friction `mu Rn` drags
//! the pin along `+e_i`. The static sliding equilibrium solves
//! `K U = F + (Pn + mu Pt)^T Rn`, `0 <= Rn ⟂ g0 + Pn U >= 0`.

use crate::linalg::add_scaled;
use crate::qep::Qep;
use crate::{Error, Result, SparseMat, SparseRef};
use faer::Mat;

/// How the normal reaction of a pair relates to its gap.
pub trait ContactLaw: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Normal stiffness per pair (N/m) of a penalty law; `None` for the exact
    /// unilateral (Signorini) constraint.
    fn normal_stiffness(&self) -> Option<f64>;
}

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
    /// `||K U - F - (Pn + mu Pt)^T Rn|| / ||F||`.
    pub equilibrium_residual: f64,
    /// Complementarity residual, relative to the total normal force.
    pub complementarity_residual: f64,
    /// Wall time (s).
    pub time_s: f64,
}

/// Computes the steady full-sliding equilibrium.
pub trait EquilibriumSolver: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Solves the problem for friction coefficient `mu` under the given law.
    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        law: &dyn ContactLaw,
        mu: f64,
    ) -> Result<Equilibrium>;
}

/// The constrained frictional operator of one contact set: the mu-independent parts
/// `X_c = T^T X T` and the friction parts `F_X`, kept apart so that
/// `X~_c(mu) = X_c - mu F_X` costs nothing per mu.
#[derive(Debug, Clone)]
pub struct FrictionalOperator {
    /// `M_c` (kg).
    pub mc: SparseMat,
    /// `C_c` (N s/m); `None` when undamped.
    pub cc: Option<SparseMat>,
    /// `K_c` (N/m).
    pub kc: SparseMat,
    /// Friction part of the mass.
    pub fm: SparseMat,
    /// Friction part of the damping; `None` when undamped.
    pub fc: Option<SparseMat>,
    /// Friction part of the stiffness.
    pub fk: SparseMat,
    /// The index map `T`: free DOF `j` of the unconstrained model is constrained DOF
    /// `t[j]` (an eliminated pin-normal DOF points at its disc partner). `None` when the
    /// operator was given directly (then the operator's DOFs are the full DOFs).
    pub t: Option<Vec<usize>>,
}

impl FrictionalOperator {
    /// Size of the constrained problem.
    pub fn dim(&self) -> usize {
        self.kc.nrows()
    }

    /// Number of DOFs of the unconstrained model (`dim()` when there is no map).
    pub fn full_dim(&self) -> usize {
        self.t.as_ref().map_or(self.dim(), |t| t.len())
    }

    /// The QEP at friction coefficient `mu`: `X~ = X_c - mu F_X`.
    pub fn at(&self, mu: f64) -> Result<Qep> {
        if !mu.is_finite() {
            return Err(Error::param("mu", format!("must be finite, got {mu}")));
        }
        let comb = |x: &SparseMat, f: &SparseMat| add_scaled(x.as_ref(), 1.0, f.as_ref(), -mu);
        let c = match (&self.cc, &self.fc) {
            (Some(c), Some(f)) => Some(comb(c, f)?),
            (Some(c), None) => Some(c.clone()),
            (None, Some(f)) => Some(add_scaled(f.as_ref(), -mu, f.as_ref(), 0.0)?),
            (None, None) => None,
        };
        Ok(Qep {
            m: comb(&self.mc, &self.fm)?,
            c,
            k: comb(&self.kc, &self.fk)?,
        })
    }

    /// Expands a constrained vector to the unconstrained DOFs, `u = T u_c`.
    pub fn expand<T: Copy>(&self, uc: &[T]) -> Vec<T> {
        match &self.t {
            Some(t) => t.iter().map(|&j| uc[j]).collect(),
            None => uc.to_vec(),
        }
    }
}

/// A real reduction basis on the constrained space, `M_c`-orthonormal.
#[derive(Debug, Clone)]
pub struct Basis {
    /// Columns of the basis (`n_c x m`).
    pub v: Mat<f64>,
    /// Wall time to build it (s).
    pub time_s: f64,
    /// Vectors removed by the rank cut.
    pub dropped: usize,
    /// Iterations (iterative bases), else 0.
    pub iterations: usize,
}

/// Builds a reduction basis for one frictional operator.
pub trait ReductionBasis: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Builds the basis for friction coefficient `mu` and band `(fmin, fmax)` in Hz;
    /// bases fixed in mu ignore `mu`.
    fn build(&self, op: &FrictionalOperator, mu: f64, band_hz: (f64, f64)) -> Result<Basis>;
}
