//! The search problem of a calibration on argmin: residuals of the cheap rule, their
//! forward-difference Jacobian, and the stalling rule of the trust region.

use super::evaluate::evaluate;
use super::fit::*;
use super::spec::CalibrationSpec;
use argmin::core::{
    CostFunction, Error as ArgminError, Gradient, Hessian, IterState, Problem, Solver,
    TerminationReason, TerminationStatus, KV,
};
use nalgebra::{DMatrix, DVector};
use squeal_core::Registry;
use squeal_scene::Scene;
use std::cell::RefCell;
use std::time::Instant;

pub(super) type Recorder<'r> = dyn FnMut(Step) + 'r;

/// An evaluated point of the search: `z` bits and weighted residuals (`None`: failed).
pub(super) type Cached = (Vec<u64>, Option<Vec<f64>>);

/// The search on `z`: residuals of the cheap rule against the corrected targets.
pub(super) struct SearchProblem<'a, 'r> {
    pub(super) registry: &'a Registry,
    pub(super) spec: &'a CalibrationSpec,
    pub(super) scene: &'a Scene,
    pub(super) file: &'a str,
    pub(super) rule: &'a [(&'a str, f64)],
    pub(super) ratios: &'a [f64],
    pub(super) round: usize,
    pub(super) budget: usize,
    pub(super) used: RefCell<usize>,
    /// Evaluated points: `z` bits and weighted residuals (`None`: failed).
    pub(super) cache: RefCell<Vec<Cached>>,
    pub(super) record: RefCell<&'r mut Recorder<'r>>,
    pub(super) steps: &'a RefCell<Vec<Step>>,
}

impl SearchProblem<'_, '_> {
    /// Weighted residuals at `z` (`None` when the model failed there).
    fn residuals(
        &self,
        z: &DVector<f64>,
        kind: &str,
    ) -> std::result::Result<Option<Vec<f64>>, ArgminError> {
        let key: Vec<u64> = z.iter().map(|v| v.to_bits()).collect();
        if let Some((_, r)) = self.cache.borrow().iter().find(|(k, _)| *k == key) {
            return Ok(r.clone());
        }
        if *self.used.borrow() >= self.budget {
            return Err(ArgminError::msg(BUDGET));
        }
        *self.used.borrow_mut() += 1;
        let values = to_values(self.spec, z);
        let t = Instant::now();
        let result = scene_at(self.spec, self.scene, self.file, &values, self.rule).and_then(|s| {
            evaluate(
                self.registry,
                &s,
                self.file,
                &self.spec.targets,
                &self.spec.search,
            )
        });
        let index = self.steps.borrow().len() + 1;
        let (r, step) = match result {
            Ok(e) => (
                Some(e.weighted(&self.spec.targets, self.ratios)),
                Step {
                    index,
                    round: self.round,
                    kind: kind.into(),
                    values,
                    cost: e.cost(&self.spec.targets, self.ratios),
                    measured: e.measured.iter().map(|m| m.value).collect(),
                    time_s: e.time_s,
                    error: None,
                },
            ),
            Err(err) => (
                None,
                Step {
                    index,
                    round: self.round,
                    kind: kind.into(),
                    values,
                    cost: f64::INFINITY,
                    measured: vec![f64::NAN; self.spec.targets.len()],
                    time_s: t.elapsed().as_secs_f64(),
                    error: Some(err.to_string()),
                },
            ),
        };
        (self.record.borrow_mut())(step);
        self.cache.borrow_mut().push((key, r.clone()));
        Ok(r)
    }

    /// Forward-difference Jacobian of the weighted residuals in `z`, stepping inwards.
    fn jacobian(
        &self,
        z: &DVector<f64>,
    ) -> std::result::Result<(Vec<f64>, DMatrix<f64>), ArgminError> {
        let r0 = self.residuals(z, "search")?.ok_or_else(|| {
            ArgminError::msg("calibration: the model failed at the current point")
        })?;
        let h = 2.0 * self.spec.search.difference_step;
        let mut jac = DMatrix::<f64>::zeros(r0.len(), z.len());
        for j in 0..z.len() {
            let mut zj = z.clone();
            let step = if z[j] > 0.0 { -h } else { h };
            zj[j] += step;
            let rj = self.residuals(&zj, "jacobian")?.ok_or_else(|| {
                ArgminError::msg(format!(
                    "calibration: the model failed at a difference step of parameter {j}"
                ))
            })?;
            for i in 0..r0.len() {
                jac[(i, j)] = (rj[i] - r0[i]) / step;
            }
        }
        Ok((r0, jac))
    }
}

impl CostFunction for SearchProblem<'_, '_> {
    type Param = DVector<f64>;
    type Output = f64;
    fn cost(&self, z: &DVector<f64>) -> std::result::Result<f64, ArgminError> {
        Ok(self.residuals(z, "search")?.map_or(f64::INFINITY, |r| {
            r.iter().map(|x| x * x).sum::<f64>() / 2.0
        }))
    }
}

impl Gradient for SearchProblem<'_, '_> {
    type Param = DVector<f64>;
    type Gradient = DVector<f64>;
    fn gradient(&self, z: &DVector<f64>) -> std::result::Result<DVector<f64>, ArgminError> {
        let (r, j) = self.jacobian(z)?;
        Ok(j.transpose() * DVector::from_vec(r))
    }
}

impl Hessian for SearchProblem<'_, '_> {
    type Param = DVector<f64>;
    type Hessian = DMatrix<f64>;
    fn hessian(&self, z: &DVector<f64>) -> std::result::Result<DMatrix<f64>, ArgminError> {
        let (_, j) = self.jacobian(z)?;
        let mut h = j.transpose() * &j;
        let scale = h.diagonal().max().max(1e-12);
        for i in 0..h.nrows() {
            h[(i, i)] += 1e-9 * scale;
        }
        Ok(h)
    }
}

pub(super) type TrState = IterState<DVector<f64>, DVector<f64>, (), DMatrix<f64>, (), f64>;

/// argmin's trust region with the stopping rules of a model-updating search.
pub(super) struct Stalling<S> {
    pub(super) inner: S,
    pub(super) tolerance: f64,
    pub(super) last_cost: f64,
    pub(super) rejected: usize,
}

impl<O, S> Solver<O, TrState> for Stalling<S>
where
    S: Solver<O, TrState>,
{
    fn name(&self) -> &str {
        "trust-region Gauss-Newton"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        state: TrState,
    ) -> std::result::Result<(TrState, Option<KV>), ArgminError> {
        let (state, kv) = self.inner.init(problem, state)?;
        self.last_cost = state.get_cost();
        Ok((state, kv))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: TrState,
    ) -> std::result::Result<(TrState, Option<KV>), ArgminError> {
        let (state, kv) = self.inner.next_iter(problem, state)?;
        let cost = state.get_cost();
        if cost < self.last_cost {
            self.rejected = 0;
        } else {
            self.rejected += 1;
        }
        Ok((state, kv))
    }

    fn terminate(&mut self, state: &TrState) -> TerminationStatus {
        let cost = state.get_cost();
        let out = if self.rejected >= 3 {
            TerminationStatus::Terminated(TerminationReason::SolverExit(
                "three rejected steps in a row".into(),
            ))
        } else if cost < self.last_cost && self.last_cost - cost < self.tolerance * self.last_cost {
            TerminationStatus::Terminated(TerminationReason::SolverExit(
                "the cost stopped falling".into(),
            ))
        } else if cost == 0.0 {
            TerminationStatus::Terminated(TerminationReason::SolverExit("cost zero".into()))
        } else {
            TerminationStatus::NotTerminated
        };
        if cost < self.last_cost {
            self.last_cost = cost;
        }
        out
    }
}
