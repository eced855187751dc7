//! The search: a trust-region Gauss-Newton method (argmin's `TrustRegion` with the
//! Steihaug subproblem on `f = |r|^2 / 2`, gradient `J^T r`, Hessian `J^T J`) over the
//! parameters mapped into their bounds, with a forward-difference Jacobian.
//!
//! **Bounds.** Each parameter's position `u` in `[0, 1]` over its range (linear or
//! logarithmic) is `u = (1 + sin z) / 2`, so the search runs on an unbounded `z` and never
//! leaves the box; a parameter that wants to cross a bound stops at it (the Jacobian
//! column vanishes there).
//!
//! **Correction ratios.** The search evaluates the cheap rule `search.rule`; each target
//! is aimed at `target / q` with `q = fine / coarse`, the ratio of the scene's own rule to
//! the cheap one, measured at the start (and again after each search when
//! `corrections > 1`). The last point is confirmed on the scene's own rule.
//!
//! **Stopping.** The evaluation budget, an accepted step lowering the cost by less than
//! `tolerance` of it, or three rejected steps in a row (the radius shrunk 64-fold).

use super::evaluate::{evaluate, Evaluation};
use super::search::*;
use super::spec::{CalibrationSpec, Method, Target};
use crate::pipeline::{PipelineError, Result};
use argmin::core::{Error as ArgminError, Executor, State};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::trustregion::{Steihaug, TrustRegion};
use nalgebra::DVector;
use serde::Serialize;
use squeal_core::Registry;
use squeal_scene::Scene;
use std::cell::RefCell;
use std::time::Instant;

/// One model evaluation of the search or a confirmation.
#[derive(Debug, Clone, Serialize)]
pub struct Step {
    /// Running number over the whole calibration, from 1.
    pub index: usize,
    /// Search round (0 first).
    pub round: usize,
    /// `search`, `jacobian` or `confirm` (on the scene's own rule).
    pub kind: String,
    /// Parameter values (their units).
    pub values: Vec<f64>,
    /// Cost `sum (w r)^2 / 2` against the round's corrected targets (confirmations: the
    /// plain targets); infinite when the evaluation failed.
    pub cost: f64,
    /// Measured values per target (NaN when missing or failed).
    pub measured: Vec<f64>,
    /// Wall time of this evaluation (s).
    pub time_s: f64,
    /// Why an evaluation failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// A calibration's result.
#[derive(Debug, Clone, Serialize)]
pub struct FitResult {
    /// Fitted values, in the spec's parameter order.
    pub values: Vec<f64>,
    /// Start values.
    pub start: Vec<f64>,
    /// The last evaluation on the scene's own rule (the confirmation), or on the search
    /// rule when the search runs on the scene's own rule.
    pub confirmed: Evaluation,
    /// The evaluation at the start point on the scene's own rule, when one was made.
    pub start_confirmed: Option<Evaluation>,
    /// Correction ratios `fine / coarse` of the last round, per target.
    pub ratios: Vec<f64>,
    /// Every evaluation in order.
    pub steps: Vec<Step>,
    /// Why each search round stopped.
    pub stops: Vec<String>,
    /// Free DOFs of the search rule and of the scene's own rule.
    pub dofs: [usize; 2],
    /// Wall time (s).
    pub time_s: f64,
}

/// Runs the calibration of `spec` on `scene` (`file` names it); `progress` sees every
/// evaluation as it finishes.
pub fn calibrate(
    registry: &Registry,
    spec: &CalibrationSpec,
    scene: &Scene,
    file: &str,
    mut progress: impl FnMut(&Step),
) -> Result<FitResult> {
    let start_time = Instant::now();
    let n = spec.parameters.len();
    let start: Vec<f64> = (0..n).map(|i| spec.start_value(i, scene)).collect();
    let rule: Vec<(&str, f64)> = spec
        .search
        .rule
        .iter()
        .map(|(k, v)| (k.as_str(), *v))
        .collect();
    let coarse = !rule.is_empty();
    let steps = RefCell::new(Vec::<Step>::new());
    let mut record = |step: Step| {
        progress(&step);
        steps.borrow_mut().push(step);
    };
    let fine_eval = |values: &[f64]| -> Result<Evaluation> {
        let s = scene_at(spec, scene, file, values, &[])?;
        evaluate(registry, &s, file, &spec.targets, &spec.search)
    };
    let ones = vec![1.0; spec.targets.len()];
    let mut ratios = ones.clone();
    let mut start_confirmed = None;
    let mut values = start.clone();
    let mut stops = Vec::new();
    let mut dofs = [0, 0];
    let rounds = if coarse {
        spec.search.corrections.max(1)
    } else {
        1
    };
    for round in 0..rounds {
        // the round starts where the search's coordinates put it (a bound moved inwards)
        let z0 = to_z(spec, &values);
        values = to_values(spec, &z0);
        let mut seed: Vec<Cached> = Vec::new();
        if coarse && spec.search.corrections > 0 {
            // ratios from the scene's own rule at the round's start
            let fine = fine_eval(&values)?;
            let coarse_here = evaluate(
                registry,
                &scene_at(spec, scene, file, &values, &rule)?,
                file,
                &spec.targets,
                &spec.search,
            )?;
            ratios = correction_ratios(&fine, &coarse_here, &spec.targets);
            dofs = [coarse_here.dofs, fine.dofs];
            record(step_of(
                &steps,
                round,
                "confirm",
                &values,
                &fine,
                &spec.targets,
                &ones,
            ));
            record(step_of(
                &steps,
                round,
                "search",
                &values,
                &coarse_here,
                &spec.targets,
                &ratios,
            ));
            if round == 0 {
                start_confirmed = Some(fine);
            }
            seed.push((
                z0.iter().map(|v| v.to_bits()).collect(),
                Some(coarse_here.weighted(&spec.targets, &ratios)),
            ));
        }
        if n == 0 {
            stops.push("no parameters: evaluation only".into());
            break;
        }
        let problem = SearchProblem {
            registry,
            spec,
            scene,
            file,
            rule: &rule,
            ratios: &ratios,
            round,
            budget: spec.search.max_evaluations,
            used: RefCell::new(0),
            cache: RefCell::new(seed),
            record: RefCell::new(&mut record),
            steps: &steps,
        };
        let (best_z, stop) = run_search(problem, spec, z0)?;
        // the best point evaluated in this round (argmin's best, or the history's when
        // the budget stopped it)
        values = match (best_z, best_of_round(&steps.borrow(), round)) {
            (_, Some(b)) => b,
            (Some(z), None) => to_values(spec, &z),
            (None, None) => values,
        };
        stops.push(stop);
    }
    let confirmed = if coarse && spec.search.corrections > 0 {
        let fine = fine_eval(&values)?;
        record(step_of(
            &steps,
            rounds,
            "confirm",
            &values,
            &fine,
            &spec.targets,
            &ones,
        ));
        fine
    } else {
        let s = scene_at(spec, scene, file, &values, &rule)?;
        let e = evaluate(registry, &s, file, &spec.targets, &spec.search)?;
        dofs = [e.dofs, e.dofs];
        record(step_of(
            &steps,
            rounds,
            "confirm",
            &values,
            &e,
            &spec.targets,
            &ones,
        ));
        e
    };
    Ok(FitResult {
        values,
        start,
        confirmed,
        start_confirmed,
        ratios,
        steps: steps.into_inner(),
        stops,
        dofs,
        time_s: start_time.elapsed().as_secs_f64(),
    })
}

/// The values of the cheapest finite search step of `round`.
fn best_of_round(steps: &[Step], round: usize) -> Option<Vec<f64>> {
    steps
        .iter()
        .filter(|s| s.round == round && s.kind != "confirm" && s.cost.is_finite())
        .min_by(|a, b| a.cost.total_cmp(&b.cost))
        .map(|s| s.values.clone())
}

/// The correction ratio of each target: its value on the scene's own rule over its value
/// on the search's coarse rule (1 where that is not a finite positive number or the
/// target does not scale).
pub(super) fn correction_ratios(
    fine: &Evaluation,
    coarse: &Evaluation,
    targets: &[Target],
) -> Vec<f64> {
    fine.measured
        .iter()
        .zip(&coarse.measured)
        .zip(targets)
        .map(|((f, c), t)| {
            let q = f.value / c.value;
            if t.scalable() && q.is_finite() && q > 0.0 {
                q
            } else {
                1.0
            }
        })
        .collect()
}

/// Runs the spec's search method from `z0` on `problem`: the best point argmin reports
/// (if any) and why it stopped.
pub(super) fn run_search(
    problem: SearchProblem<'_, '_>,
    spec: &CalibrationSpec,
    z0: DVector<f64>,
) -> Result<(Option<DVector<f64>>, String)> {
    let n = z0.len();
    let outcome = match spec.search.method {
        Method::GaussNewton => {
            let solver = Stalling {
                inner: TrustRegion::new(Steihaug::new().with_max_iters(50))
                    .with_radius(0.4)
                    .and_then(|t| t.with_max_radius(1.5))
                    .map_err(|e| search_error(&e))?,
                tolerance: spec.search.tolerance,
                last_cost: f64::INFINITY,
                rejected: 0,
            };
            Executor::new(problem, solver)
                .configure(|s| s.param(z0).max_iters(1000))
                .ctrlc(false)
                .run()
                .map(|r| {
                    let st = r.state();
                    (
                        st.get_best_param().cloned(),
                        st.get_termination_reason().cloned(),
                    )
                })
        }
        Method::NelderMead => {
            // a simplex of steps of a tenth of each range around the start
            let mut simplex = vec![z0.clone()];
            for j in 0..n {
                let mut v = z0.clone();
                v[j] += if z0[j] > 0.0 { -0.3 } else { 0.3 };
                simplex.push(v);
            }
            let solver = NelderMead::new(simplex)
                .with_sd_tolerance(spec.search.tolerance)
                .map_err(|e| search_error(&e))?;
            Executor::new(problem, solver)
                .configure(|s| s.max_iters(1000))
                .ctrlc(false)
                .run()
                .map(|r| {
                    let st = r.state();
                    (
                        st.get_best_param().cloned(),
                        st.get_termination_reason().cloned(),
                    )
                })
        }
    };
    match outcome {
        Ok((z, reason)) => Ok((
            z,
            reason.map_or("stopped".to_string(), |r| r.text().to_string()),
        )),
        Err(e) if e.to_string().contains(BUDGET) => Ok((None, "evaluation budget used".into())),
        Err(e) => Err(search_error(&e)),
    }
}

/// The base scene with the parameters at `values` and the rule overrides `rule`.
pub fn scene_at(
    spec: &CalibrationSpec,
    scene: &Scene,
    file: &str,
    values: &[f64],
    rule: &[(&str, f64)],
) -> Result<Scene> {
    let mut set: Vec<(&str, f64)> = spec
        .parameters
        .iter()
        .zip(values)
        .map(|(p, &v)| (p.path.as_str(), v))
        .collect();
    set.extend_from_slice(rule);
    Ok(scene.with_values(&set, file)?)
}

pub(super) const BUDGET: &str = "calibration: evaluation budget used";

pub(super) fn search_error(e: &ArgminError) -> PipelineError {
    PipelineError::Core {
        stage: "calibration search".into(),
        source: squeal_core::Error::Invalid(e.to_string()),
    }
}

/// Search coordinates of `values`, kept 2 % of the range inside the bounds (where the
/// map `u = (1 + sin z) / 2` still moves).
pub(super) fn to_z(spec: &CalibrationSpec, values: &[f64]) -> DVector<f64> {
    DVector::from_iterator(
        values.len(),
        spec.parameters
            .iter()
            .zip(values)
            .map(|(p, &x)| (2.0 * p.to_unit(x).clamp(0.02, 0.98) - 1.0).asin()),
    )
}

pub(super) fn to_values(spec: &CalibrationSpec, z: &DVector<f64>) -> Vec<f64> {
    spec.parameters
        .iter()
        .zip(z.iter())
        .map(|(p, &zi)| p.from_unit((1.0 + zi.sin()) / 2.0))
        .collect()
}

pub(super) fn step_of(
    steps: &RefCell<Vec<Step>>,
    round: usize,
    kind: &str,
    values: &[f64],
    e: &Evaluation,
    targets: &[Target],
    ratios: &[f64],
) -> Step {
    Step {
        index: steps.borrow().len() + 1,
        round,
        kind: kind.into(),
        values: values.to_vec(),
        cost: e.cost(targets, ratios),
        measured: e.measured.iter().map(|m| m.value).collect(),
        time_s: e.time_s,
        error: None,
    }
}
