//! The reduced solve: a basis with the operator projected on it ([`ReducedOperator`]),
//! solved at any mu, its modes expanded with backward errors on the full operator.

use super::project;
use crate::contact::Basis;
use crate::eigen::{EigenParams, EigenSolver};
use crate::operator::{ComplexModes, FrictionalOperator};
use crate::qep::{finish_operator_modes, finish_operator_modes_with_left};
use crate::{c64, Error, Result};
use faer::Mat;
use std::time::Instant;

/// Complex modes of a reduced solve, expanded to the constrained space, with the cost of
/// each stage.
#[derive(Debug, Clone)]
pub struct ReducedSolve {
    /// The modes on the constrained DOFs (`u_c = V q`), with backward errors on the FULL
    /// operator `op.at(mu)`. `info` is the reduced solver's, with `time_s` = reduced solve
    /// + expansion + backward errors (per mu) and notes on the basis.
    pub modes: ComplexModes,
    /// Columns of the basis.
    pub basis_size: usize,
    /// Time to build the basis (s), as reported by the basis.
    pub basis_time_s: f64,
    /// Time to project the operator on the basis (s), once per basis.
    pub projection_time_s: f64,
    /// Time of the reduced eigen solve (s), per mu.
    pub solve_time_s: f64,
    /// Time to expand the modes and compute their backward errors on the full operator
    /// (s), per mu.
    pub expansion_time_s: f64,
}

/// A basis with the operator projected on it: project once, solve at any mu (a basis
/// fixed in mu serves a whole sweep at one contact set).
#[derive(Debug, Clone)]
pub struct ReducedOperator {
    /// The basis.
    pub basis: Basis,
    /// `V^T X V` for every part.
    pub reduced: FrictionalOperator,
    /// Time of the projection (s).
    pub projection_time_s: f64,
}

impl ReducedOperator {
    /// Projects `op` on `basis` (or takes the projection the basis carries).
    pub fn new(op: &FrictionalOperator, mut basis: Basis) -> Result<Self> {
        let start = Instant::now();
        // a sweep's driver takes the seed for the next point before; nothing here uses it
        basis.seed = crate::contact::Seed::default();
        let m = basis.len();
        let reduced = match basis.projected.take() {
            Some(p) if p.dim() == m => p,
            _ if basis.implicit.is_some() => {
                return Err(Error::Invalid(
                    "a basis of implicit columns without its projected operator".into(),
                ))
            }
            _ => project(op, basis.v.as_ref())?,
        };
        Ok(Self {
            basis,
            reduced,
            projection_time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// Solves the reduced QEP at `mu` with `eigen` in the band of `params`, expands the
    /// modes and computes their backward errors on `op.at(mu)` (`op` is the operator the
    /// basis was projected from).
    pub fn solve(
        &self,
        op: &FrictionalOperator,
        mu: f64,
        eigen: &dyn EigenSolver,
        params: &EigenParams,
    ) -> Result<ReducedSolve> {
        if op.dim() != self.basis.nrows() {
            return Err(Error::Dimension {
                context: "reduced solve: the basis was built for another operator".into(),
                expected: op.dim(),
                got: self.basis.nrows(),
            });
        }
        if let Some(b) = self.basis.mu {
            if b != mu {
                return Err(Error::Invalid(format!(
                    "reduced solve at mu = {mu} on a basis built for mu = {b} (this basis \
                     depends on mu: rebuild it)"
                )));
            }
        }
        let start = Instant::now();
        let red = eigen.solve_frictional(&self.reduced, mu, params)?;
        let solve_time_s = start.elapsed().as_secs_f64();
        let start = Instant::now();
        // Only the pairs `finish_modes` keeps are expanded: a dense reduced solve returns
        // every root, and expanding them all would cost n x m x 2m.
        let kept: Vec<usize> = crate::qep::band_pairs(&red.lambda, params)
            .into_iter()
            .map(|(_, i)| i)
            .collect();
        let q = Mat::from_fn(red.vectors.nrows(), kept.len(), |i, j| {
            red.vectors[(i, kept[j])]
        });
        let lambda: Vec<c64> = kept.iter().map(|&i| red.lambda[i]).collect();
        let u = self.basis.expand(q.as_ref())?;
        let mut info = red.info.clone();
        info.notes.push(format!(
            "reduced on a basis of {} vectors ({} dropped by the rank cut, {} iterations); \
             modes expanded, backward errors on the full operator",
            self.basis.len(),
            self.basis.dropped,
            self.basis.iterations
        ));
        info.notes.extend(self.basis.notes.iter().cloned());
        let mut modes = match &red.left_vectors {
            Some(p) => {
                let pk = Mat::from_fn(p.nrows(), kept.len(), |i, j| p[(i, kept[j])]);
                let y = self.basis.expand(pk.as_ref())?;
                finish_operator_modes_with_left(
                    op,
                    mu,
                    &lambda,
                    u.as_ref(),
                    y.as_ref(),
                    params,
                    info,
                )?
            }
            None => finish_operator_modes(op, mu, &lambda, u.as_ref(), params, info)?,
        };
        let expansion_time_s = start.elapsed().as_secs_f64();
        modes.info.time_s = solve_time_s + expansion_time_s;
        Ok(ReducedSolve {
            modes,
            basis_size: self.basis.len(),
            basis_time_s: self.basis.time_s,
            projection_time_s: self.projection_time_s,
            solve_time_s,
            expansion_time_s,
        })
    }
}

/// Projects `op` on `basis`, solves at `mu` with `eigen` (normally `dense`) and expands:
/// [`ReducedOperator::new`] then [`ReducedOperator::solve`].
pub fn solve_reduced(
    op: &FrictionalOperator,
    basis: &Basis,
    mu: f64,
    eigen: &dyn EigenSolver,
    params: &EigenParams,
) -> Result<ReducedSolve> {
    ReducedOperator::new(op, basis.clone())?.solve(op, mu, eigen, params)
}
