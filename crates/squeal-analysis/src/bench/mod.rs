//! The solver benchmark: every registered (basis x eigen) combination on the same
//! frictional operator, against a full-order reference, with time, memory and error.
//!
//! One [`bench_case`] call takes one operator at one mu. The reference is the full-order
//! solve of [`BenchOptions::reference_eigen`] at [`BenchOptions::reference_tol`]; every
//! other run is compared with it mode by mode ([`compare`]). Bases are built once per
//! (basis, parameter variant) and handed to every eigen solver, so the setup cost is the
//! basis build plus its projection and the solve cost is the reduced eigen solve plus
//! the expansion and the backward errors on the full operator. Which bases and solvers
//! run comes from the [`Registry`] ([`BenchOptions::all`]), so a basis registered at run
//! time is benchmarked with no change here.

use crate::jsonl::{nan, null_as_nan};
use crate::pipeline::{PipelineError, Result};
use serde::{Deserialize, Serialize};
use squeal_core::contact::BasisRequest;
use squeal_core::qep::ComplexModes;
use squeal_core::reduction::ReducedOperator;
use squeal_core::{EigenParams, EigenSolver, FrictionalOperator, ModelStage, Params, Registry};
use std::time::Instant;

mod suite;
pub use suite::{
    run_suite, stress_cases, BenchSource, CaseInfo, StressCase, SuiteEvent, SuiteSettings,
    SuiteSummary,
};

/// A peak-memory probe. The `squeal` binary implements it with a counting global
/// allocator; library users may pass `None` (memory is then not reported).
pub trait MemoryProbe: Sync {
    /// Bytes of heap in use now; starts a new peak window.
    fn reset(&self) -> usize;
    /// Peak bytes of heap in use since the last [`MemoryProbe::reset`].
    fn peak(&self) -> usize;
}

/// When a run counts as accurate: every reference mode in the band found, no missed or
/// false unstable mode, and the errors below these bounds.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Accuracy {
    /// Largest relative frequency error.
    pub freq_rel: f64,
    /// Largest absolute DvR error.
    pub dvr_abs: f64,
}

impl Default for Accuracy {
    fn default() -> Self {
        Self {
            freq_rel: 1e-3,
            dvr_abs: 1e-4,
        }
    }
}

/// What a benchmark runs.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Frequency band (Hz).
    pub band_hz: [f64; 2],
    /// Relative tolerance of the benchmarked eigen solvers.
    pub tol: f64,
    /// Full-order reference solver.
    pub reference_eigen: String,
    /// Its tolerance.
    pub reference_tol: f64,
    /// A mode is unstable when its DvR = Re/Im exceeds this.
    pub dvr_tol: f64,
    /// Bases to run (`none` = full order).
    pub bases: Vec<String>,
    /// Eigen solvers to run (of the reduced problem when there is a basis).
    pub eigens: Vec<String>,
    /// Parameter variants of the bases (e.g. `cutoff_factor = [1.2, 2.5]`), each run
    /// besides the defaults by every basis that accepts the parameter.
    pub vary: Vec<(String, Vec<f64>)>,
    /// Whether each basis also runs with its default parameters.
    pub defaults: bool,
    /// Symmetric solver the bases use for their real modes.
    pub modal: String,
    /// The accuracy a run must reach to count as accurate.
    pub accuracy: Accuracy,
    /// Whether full-order modes (the reference's and the full-order runs') always get
    /// condition numbers and forward error estimates: the solvers compute them only up to
    /// [`CONDITION_AUTO_MAX_DIM`](squeal_core::qep::CONDITION_AUTO_MAX_DIM) DOFs; above,
    /// with this set, they are added afterwards ([`squeal_core::qep::add_condition`]) and
    /// timed apart ([`BenchRun::condition_s`]). Reduced runs always have them.
    pub condition: bool,
}

impl BenchOptions {
    /// Every registered basis (and full order) with every registered eigen solver,
    /// against full-order `arpack` at 1e-12.
    pub fn all(registry: &Registry) -> Self {
        let mut bases = vec!["none".to_string()];
        bases.extend(registry.bases.names());
        Self {
            band_hz: [0.0, 10_000.0],
            tol: 1e-10,
            reference_eigen: "arpack".into(),
            reference_tol: 1e-12,
            dvr_tol: 1e-6,
            bases,
            eigens: registry.eigen.names(),
            vary: Vec::new(),
            defaults: true,
            modal: "arpack".into(),
            accuracy: Accuracy::default(),
            condition: false,
        }
    }

    fn params(&self, tol: f64) -> EigenParams {
        EigenParams {
            fmin_hz: self.band_hz[0],
            fmax_hz: self.band_hz[1],
            tol,
            ..EigenParams::default()
        }
    }
}

/// Errors of a set of modes against the reference in the band.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ModeErrors {
    /// Reference modes in the band.
    pub reference_modes: usize,
    /// Reference modes without a partner within 1 % in frequency.
    pub missed_modes: usize,
    /// Modes in the band matched to no reference mode.
    pub extra_modes: usize,
    /// Largest relative frequency error over matched modes (NaN when none matched).
    #[serde(deserialize_with = "null_as_nan")]
    pub max_rel_freq_err: f64,
    /// Largest absolute DvR error over matched modes.
    #[serde(deserialize_with = "null_as_nan")]
    pub max_abs_dvr_err: f64,
    /// Unstable reference modes.
    pub reference_unstable: usize,
    /// Unstable reference modes without an unstable partner.
    pub missed_unstable: usize,
    /// Unstable modes in the band whose partner is stable, or without partner.
    pub false_unstable: usize,
    /// Worst backward error (on the full operator) of the modes in the band.
    #[serde(deserialize_with = "null_as_nan")]
    pub max_backward_error: f64,
    /// Worst forward error estimate (`error_bound`, relative eigenvalue error) of the
    /// modes in the band; NaN when not computed (full order above
    /// [`CONDITION_AUTO_MAX_DIM`](squeal_core::qep::CONDITION_AUTO_MAX_DIM) DOFs without
    /// [`BenchOptions::condition`]).
    #[serde(default = "nan", deserialize_with = "null_as_nan")]
    pub max_error_bound: f64,
    /// Worst condition number of the modes in the band; NaN when not computed.
    #[serde(default = "nan", deserialize_with = "null_as_nan")]
    pub max_cond: f64,
    /// Largest relative eigenvalue error `|lambda - lambda_ref| / |lambda_ref|` over
    /// matched modes (NaN when none matched): the actual error `error_bound` estimates.
    #[serde(default = "nan", deserialize_with = "null_as_nan")]
    pub max_rel_lambda_err: f64,
    /// Matched modes whose relative eigenvalue error exceeds their own `error_bound` by
    /// more than the reference's accuracy ([`BOUND_FLOOR`], or the reference mode's own
    /// bound when larger); modes without a bound are not counted.
    #[serde(default)]
    pub above_bound: usize,
}

/// The smallest eigenvalue error a bound is held to: below it the reference itself
/// (solved to 1e-12) is not accurate enough to tell.
pub const BOUND_FLOOR: f64 = 1e-12;

/// The largest of `values` that are not NaN (NaN when all are, or there are none).
fn worst(values: impl Iterator<Item = f64>) -> f64 {
    values.fold(f64::NAN, |m, v| if v.is_nan() || m >= v { m } else { v })
}

impl ModeErrors {
    fn failed() -> Self {
        Self {
            reference_modes: 0,
            missed_modes: 0,
            extra_modes: 0,
            max_rel_freq_err: f64::NAN,
            max_abs_dvr_err: f64::NAN,
            reference_unstable: 0,
            missed_unstable: 0,
            false_unstable: 0,
            max_backward_error: f64::NAN,
            max_error_bound: f64::NAN,
            max_cond: f64::NAN,
            max_rel_lambda_err: f64::NAN,
            above_bound: 0,
        }
    }

    /// Whether these errors meet `acc` (every mode found, no missed or false instability).
    pub fn accurate(&self, acc: &Accuracy) -> bool {
        self.missed_modes == 0
            && self.missed_unstable == 0
            && self.false_unstable == 0
            && self.max_rel_freq_err <= acc.freq_rel
            && self.max_abs_dvr_err <= acc.dvr_abs
    }
}

/// Compares `modes` with `reference` in `band_hz`: every reference mode in the band is
/// matched to the nearest unused eigenvalue of `modes` within 1 % in frequency (none
/// there: missed); modes of `modes` up to 1 % beyond the band edges may be
/// partners (a mode at the edge may fall either side), those inside the band and matched
/// to nothing are extra. A mode is unstable when its DvR exceeds `dvr_tol`. The worst
/// `error_bound` and `cond` of the modes in the band are recorded next to their worst
/// backward error, with the actual relative eigenvalue errors of the matched modes and how
/// many exceed their own bound.
pub fn compare(
    reference: &ComplexModes,
    modes: &ComplexModes,
    band_hz: [f64; 2],
    dvr_tol: f64,
) -> ModeErrors {
    let in_band = |f: f64| f >= band_hz[0] && f <= band_hz[1];
    let near_band = |f: f64| f >= band_hz[0] * 0.99 && f <= band_hz[1] * 1.01;
    let mut e = ModeErrors {
        max_rel_freq_err: 0.0,
        max_abs_dvr_err: 0.0,
        max_backward_error: 0.0,
        max_rel_lambda_err: 0.0,
        ..ModeErrors::failed()
    };
    let mut used = vec![false; modes.len()];
    let mut matched = 0;
    for i in (0..reference.len()).filter(|&i| in_band(reference.freq_hz[i])) {
        e.reference_modes += 1;
        let unstable_ref = reference.is_unstable(i, dvr_tol);
        e.reference_unstable += usize::from(unstable_ref);
        // the nearest eigenvalue among the unused modes within 1 % in frequency: a strongly
        // unstable mode's nearest eigenvalue can be a mode of another frequency
        let rel_df = |j: usize| {
            (modes.freq_hz[j] - reference.freq_hz[i]).abs() / reference.freq_hz[i].abs().max(1e-300)
        };
        let best = (0..modes.len())
            .filter(|&j| !used[j] && near_band(modes.freq_hz[j]) && rel_df(j) <= 0.01)
            .map(|j| (j, (reference.lambda[i] - modes.lambda[j]).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let Some((j, _)) = best else {
            e.missed_modes += 1;
            e.missed_unstable += usize::from(unstable_ref);
            continue;
        };
        let df = rel_df(j);
        used[j] = true;
        matched += 1;
        let err = (reference.lambda[i] - modes.lambda[j]).norm() / reference.lambda[i].norm();
        e.max_rel_lambda_err = e.max_rel_lambda_err.max(err);
        let floor = match reference.error_bound.get(i) {
            Some(&b) if b.is_finite() => b.max(BOUND_FLOOR),
            _ => BOUND_FLOOR,
        };
        let bound = modes.error_bound.get(j).copied().unwrap_or(f64::NAN);
        e.above_bound += usize::from(err > bound + floor);
        e.max_rel_freq_err = e.max_rel_freq_err.max(df);
        e.max_abs_dvr_err = e
            .max_abs_dvr_err
            .max((modes.dvr[j] - reference.dvr[i]).abs());
        let unstable = modes.is_unstable(j, dvr_tol);
        if unstable_ref && !unstable {
            e.missed_unstable += 1;
        } else if unstable && !unstable_ref {
            e.false_unstable += 1;
        }
    }
    for j in (0..modes.len()).filter(|&j| in_band(modes.freq_hz[j])) {
        e.max_backward_error = e.max_backward_error.max(modes.backward_error[j]);
        if !used[j] {
            e.extra_modes += 1;
            e.false_unstable += usize::from(modes.is_unstable(j, dvr_tol));
        }
    }
    let band: Vec<usize> = (0..modes.len())
        .filter(|&j| in_band(modes.freq_hz[j]))
        .collect();
    let at = |v: &[f64], j: usize| v.get(j).copied().unwrap_or(f64::NAN);
    e.max_error_bound = worst(band.iter().map(|&j| at(&modes.error_bound, j)));
    e.max_cond = worst(band.iter().map(|&j| at(&modes.cond, j)));
    if matched == 0 {
        e.max_rel_freq_err = f64::NAN;
        e.max_abs_dvr_err = f64::NAN;
        e.max_rel_lambda_err = f64::NAN;
    }
    e
}

/// One benchmark run: one (basis, parameters, eigen solver) on one operator at one mu.
/// The keys of `bench.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchRun {
    /// Case name (e.g. `mu=0.3`, or a stress case).
    pub case: String,
    /// Basis plugin, or `none` for full order.
    pub basis: String,
    /// Basis parameters other than the defaults (`key=value,...`, empty for defaults).
    pub basis_opts: String,
    /// Eigen solver plugin.
    pub eigen: String,
    /// Friction coefficient.
    pub mu: f64,
    /// `ok`, or `error: <message>` when the run failed (its errors are then NaN).
    pub status: String,
    /// Whether this run is the reference itself.
    pub reference: bool,
    /// `setup_s + solve_s` (s).
    pub time_s: f64,
    /// Basis build and projection (s); 0 for full order (factorizations are inside the
    /// solve there).
    pub setup_s: f64,
    /// Eigen solve, expansion and backward errors (s).
    pub solve_s: f64,
    /// Of `solve_s` for a reduced run: the reduced eigen solve alone (s).
    pub reduced_solve_s: Option<f64>,
    /// Of `solve_s` for a reduced run: expansion of the in-band modes and their backward
    /// errors on the full operator (s).
    pub expansion_s: Option<f64>,
    /// Peak heap above what was in use when the run started (MB), when measured.
    pub peak_mb: Option<f64>,
    /// Left eigenvectors added to full-order modes for `cond` and `error_bound`
    /// ([`BenchOptions::condition`]), not counted in `solve_s` (s).
    #[serde(default)]
    pub condition_s: Option<f64>,
    /// Basis size (0 for full order).
    pub basis_size: usize,
    /// DOFs of the (constrained) operator.
    pub dofs: usize,
    /// Eigen solver tolerance.
    pub tol: f64,
    /// Errors against the reference.
    #[serde(flatten)]
    pub errors: ModeErrors,
    /// Whether the errors meet the accuracy bounds of the bench.
    pub accurate: bool,
    /// Reference time / `time_s`.
    #[serde(deserialize_with = "null_as_nan")]
    pub speedup: f64,
    /// Reference time / `solve_s` (the per-mu speed-up of a basis reused across mu).
    #[serde(deserialize_with = "null_as_nan")]
    pub solve_speedup: f64,
}

/// The reference solve of a case.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReferenceSolve {
    /// Case name.
    pub case: String,
    /// Friction coefficient.
    pub mu: f64,
    /// Solver and tolerance.
    pub eigen: String,
    /// Tolerance.
    pub tol: f64,
    /// Operator DOFs.
    pub dofs: usize,
    /// Wall time (s).
    pub time_s: f64,
    /// Peak heap (MB), when measured.
    pub peak_mb: Option<f64>,
    /// Modes in the band.
    pub modes: usize,
    /// Unstable modes `[freq_hz, dvr]`.
    pub unstable: Vec<[f64; 2]>,
    /// Worst backward error in the band.
    #[serde(deserialize_with = "null_as_nan")]
    pub max_backward_error: f64,
    /// Worst forward error estimate in the band (NaN when not computed).
    #[serde(default = "nan", deserialize_with = "null_as_nan")]
    pub max_error_bound: f64,
}

fn core(stage: String) -> impl FnOnce(squeal_core::Error) -> PipelineError {
    move |source| PipelineError::Core { stage, source }
}

struct Meter<'a>(Option<&'a dyn MemoryProbe>, usize);

impl<'a> Meter<'a> {
    fn start(probe: Option<&'a dyn MemoryProbe>) -> Self {
        let base = probe.map_or(0, |p| p.reset());
        Self(probe, base)
    }
    /// Peak above the start (MB) since the last window, and opens a new window.
    fn peak_mb(&self) -> Option<f64> {
        self.0.map(|p| {
            let peak = p.peak().saturating_sub(self.1) as f64 / 1e6;
            p.reset();
            peak
        })
    }
}

fn max_opt(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// The parameter variants of `basis`: its defaults (when `opts.defaults`) and each value
/// of `opts.vary` the plugin accepts (a plugin that rejects a parameter is not varied in
/// it). When nothing else is left the defaults run.
fn variants(registry: &Registry, basis: &str, opts: &BenchOptions) -> Vec<(String, Params)> {
    let mut out = Vec::new();
    if opts.defaults {
        out.push((String::new(), Params::new()));
    }
    for (key, values) in &opts.vary {
        for &v in values {
            let p = Params::new().with_num(key, v);
            if registry.bases.create(basis, &p).is_ok() {
                out.push((format!("{key}={v}"), p));
            }
        }
    }
    if out.is_empty() {
        out.push((String::new(), Params::new()));
    }
    out
}

/// A model stage ([`squeal_core::ReductionBasis::prepare`]), built once per model and
/// shared by every case: not part of any run's time, so reported apart.
#[derive(Clone)]
pub struct Stage {
    /// Its [`squeal_core::ReductionBasis::stage_key`].
    pub key: String,
    /// The stage.
    pub stage: ModelStage,
    /// Wall time to build it (s).
    pub time_s: f64,
}

/// The model stages of a bench, one per stage key.
pub type Stages = Vec<Stage>;

/// The model stages the bases of `opts` and their variants need (`cms`: the
/// free-interface synthesis) on `model` and the candidate pairs `set`, one per stage key.
/// Built once and handed to every [`bench_case`] of the model.
pub fn stages_for(
    registry: &Registry,
    opts: &BenchOptions,
    model: &squeal_scene::Model,
    set: &squeal_contact::ContactSet,
) -> Result<Stages> {
    let mut stages: Stages = Vec::new();
    let params = opts.params(opts.tol);
    for basis in opts.bases.iter().filter(|b| *b != "none") {
        for (_, p) in variants(registry, basis, opts) {
            let plugin = registry
                .bases
                .create(basis, &p)
                .map_err(core(format!("basis `{basis}`")))?;
            let Some(key) = plugin.stage_key(opts.band_hz[1]) else {
                continue;
            };
            if stages.iter().any(|s| s.key == key) {
                continue;
            }
            let t = Instant::now();
            let modal = registry
                .eigen
                .create(&opts.modal, &Params::new())
                .map_err(core(format!("eigen solver `{}`", opts.modal)))?;
            let stage = crate::pipeline::prepare_stage_alone(
                plugin.as_ref(),
                model,
                set,
                modal.as_ref(),
                &params,
            )?;
            if let Some(stage) = stage {
                stages.push(Stage {
                    key,
                    stage,
                    time_s: t.elapsed().as_secs_f64(),
                });
            }
        }
    }
    Ok(stages)
}

/// Runs the reference and every combination of `opts` on `op` at `mu`. `on_run` sees
/// each run as soon as it finishes (to append it to a results file). A failing run is
/// recorded with its error; only a failing reference stops the case. `stages` are the
/// model stages of the bases that have one ([`stages_for`]; `cms`); without its stage
/// (an operator read from files) such a basis is recorded as failed.
#[allow(clippy::too_many_arguments)]
pub fn bench_case(
    registry: &Registry,
    case: &str,
    op: &FrictionalOperator,
    stages: &Stages,
    mu: f64,
    opts: &BenchOptions,
    memory: Option<&dyn MemoryProbe>,
    mut on_run: impl FnMut(&BenchRun),
) -> Result<(ReferenceSolve, Vec<BenchRun>)> {
    let create = |name: &str| eigen_solver(registry, name);
    // the reference
    let meter = Meter::start(memory);
    let t = Instant::now();
    let mut reference = create(&opts.reference_eigen)?
        .solve_frictional(op, mu, &opts.params(opts.reference_tol))
        .map_err(core(format!(
            "reference `{}` at mu = {mu} ({case})",
            opts.reference_eigen
        )))?;
    let ref_time = t.elapsed().as_secs_f64();
    let ref_condition_s = with_condition(opts, op, mu, &mut reference)?;
    let ref_peak = meter.peak_mb();
    let self_errors = compare(&reference, &reference, opts.band_hz, opts.dvr_tol);
    let in_band = |f: f64| f >= opts.band_hz[0] && f <= opts.band_hz[1];
    let ref_out = ReferenceSolve {
        case: case.into(),
        mu,
        eigen: opts.reference_eigen.clone(),
        tol: opts.reference_tol,
        dofs: op.dim(),
        time_s: ref_time,
        peak_mb: ref_peak,
        modes: self_errors.reference_modes,
        unstable: (0..reference.len())
            .filter(|&i| in_band(reference.freq_hz[i]) && reference.is_unstable(i, opts.dvr_tol))
            .map(|i| [reference.freq_hz[i], reference.dvr[i]])
            .collect(),
        max_backward_error: self_errors.max_backward_error,
        max_error_bound: self_errors.max_error_bound,
    };
    let mut runs = Vec::new();
    let mut push = |mut run: BenchRun, runs: &mut Vec<BenchRun>| {
        run.time_s = run.setup_s + run.solve_s;
        run.accurate = run.status == "ok" && run.errors.accurate(&opts.accuracy);
        // A failed run has no speed-up (its time is that of the failure).
        let ok = run.status == "ok";
        run.speedup = if ok { ref_time / run.time_s } else { f64::NAN };
        run.solve_speedup = if ok { ref_time / run.solve_s } else { f64::NAN };
        on_run(&run);
        runs.push(run);
    };
    let blank = |basis: &str, basis_opts: &str, eigen: &str| BenchRun {
        case: case.into(),
        basis: basis.into(),
        basis_opts: basis_opts.into(),
        eigen: eigen.into(),
        mu,
        status: "ok".into(),
        reference: false,
        time_s: 0.0,
        setup_s: 0.0,
        solve_s: 0.0,
        reduced_solve_s: None,
        expansion_s: None,
        peak_mb: None,
        condition_s: None,
        basis_size: 0,
        dofs: op.dim(),
        tol: opts.tol,
        errors: ModeErrors::failed(),
        accurate: false,
        speedup: f64::NAN,
        solve_speedup: f64::NAN,
    };
    push(
        BenchRun {
            reference: true,
            solve_s: ref_time,
            peak_mb: ref_peak,
            condition_s: ref_condition_s,
            tol: opts.reference_tol,
            errors: self_errors,
            ..blank("none", "", &opts.reference_eigen)
        },
        &mut runs,
    );
    let params = opts.params(opts.tol);
    for basis in &opts.bases {
        if basis == "none" {
            for eigen in opts.eigens.iter().filter(|e| **e != opts.reference_eigen) {
                let mut run = blank("none", "", eigen);
                let meter = Meter::start(memory);
                let t = Instant::now();
                match create(eigen).and_then(|s| {
                    s.solve_frictional(op, mu, &params)
                        .map_err(core(format!("`{eigen}` at mu = {mu}")))
                }) {
                    Ok(mut modes) => {
                        run.solve_s = t.elapsed().as_secs_f64();
                        match with_condition(opts, op, mu, &mut modes) {
                            Ok(c) => {
                                run.condition_s = c;
                                run.errors =
                                    compare(&reference, &modes, opts.band_hz, opts.dvr_tol);
                            }
                            Err(e) => run.status = format!("error: {e}"),
                        }
                    }
                    Err(e) => {
                        run.solve_s = t.elapsed().as_secs_f64();
                        run.status = format!("error: {e}");
                    }
                }
                run.peak_mb = meter.peak_mb();
                push(run, &mut runs);
            }
            continue;
        }
        for (label, p) in variants(registry, basis, opts) {
            let meter = Meter::start(memory);
            let t = Instant::now();
            let built = reduced_operator(registry, basis, &p, op, mu, opts, stages, &params);
            let setup_s = t.elapsed().as_secs_f64();
            let setup_peak = meter.peak_mb();
            let red = match built {
                Ok(r) => r,
                Err(e) => {
                    for eigen in &opts.eigens {
                        push(
                            BenchRun {
                                setup_s,
                                peak_mb: setup_peak,
                                status: format!("error: {e}"),
                                ..blank(basis, &label, eigen)
                            },
                            &mut runs,
                        );
                    }
                    continue;
                }
            };
            for eigen in &opts.eigens {
                let mut run = BenchRun {
                    setup_s,
                    basis_size: red.basis.len(),
                    ..blank(basis, &label, eigen)
                };
                let t = Instant::now();
                match create(eigen).and_then(|s| {
                    red.solve(op, mu, s.as_ref(), &params)
                        .map_err(core(format!("`{eigen}` on basis `{basis}` at mu = {mu}")))
                }) {
                    Ok(r) => {
                        run.solve_s = t.elapsed().as_secs_f64();
                        run.reduced_solve_s = Some(r.solve_time_s);
                        run.expansion_s = Some(r.expansion_time_s);
                        run.errors = compare(&reference, &r.modes, opts.band_hz, opts.dvr_tol);
                    }
                    Err(e) => {
                        run.solve_s = t.elapsed().as_secs_f64();
                        run.status = format!("error: {e}");
                    }
                }
                run.peak_mb = max_opt(setup_peak, meter.peak_mb());
                push(run, &mut runs);
            }
        }
    }
    Ok((ref_out, runs))
}

/// The eigen solver plugin `name`.
fn eigen_solver(registry: &Registry, name: &str) -> Result<Box<dyn EigenSolver>> {
    registry
        .eigen
        .create(name, &Params::new())
        .map_err(core(format!("eigen solver `{name}`")))
}

/// Builds basis `basis` with parameters `p` on `op` at `mu` (its model stage from
/// `stages`, if it has one) and projects `op` on it.
#[allow(clippy::too_many_arguments)]
fn reduced_operator(
    registry: &Registry,
    basis: &str,
    p: &Params,
    op: &FrictionalOperator,
    mu: f64,
    opts: &BenchOptions,
    stages: &Stages,
    params: &EigenParams,
) -> Result<ReducedOperator> {
    let create = |name: &str| eigen_solver(registry, name);
    let plugin = registry
        .bases
        .create(basis, p)
        .map_err(core(format!("basis `{basis}`")))?;
    let modal = create(&opts.modal)?;
    let dense = create("dense")?;
    let stage = plugin.stage_key(opts.band_hz[1]).and_then(|key| {
        stages
            .iter()
            .find(|s| s.key == key)
            .map(|s| s.stage.as_ref())
    });
    let req = BasisRequest {
        op,
        mu,
        band_hz: (opts.band_hz[0], opts.band_hz[1]),
        modal: modal.as_ref(),
        reduced: dense.as_ref(),
        params,
        stage,
    };
    let b = squeal_core::contact::build_basis(plugin.as_ref(), &req)
        .map_err(core(format!("basis `{basis}` at mu = {mu}")))?;
    ReducedOperator::new(op, b).map_err(core(format!("projection on `{basis}`")))
}

/// Adds condition numbers to full-order `modes` when `opts.condition` asks for them and
/// the solver skipped them; returns the time spent (`None` when nothing was done).
fn with_condition(
    opts: &BenchOptions,
    op: &FrictionalOperator,
    mu: f64,
    modes: &mut ComplexModes,
) -> Result<Option<f64>> {
    if !opts.condition || modes.left_vectors.is_some() {
        return Ok(None);
    }
    let t = Instant::now();
    squeal_core::qep::add_condition(op, mu, modes)
        .map_err(core(format!("condition numbers at mu = {mu}")))?;
    Ok(Some(t.elapsed().as_secs_f64()))
}

/// The speed-up at equal accuracy of each (basis, eigen) over the reference: for every
/// method, its fastest accurate run (by `time_s` and by `solve_s`), per case.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SpeedRatio {
    /// Case.
    pub case: String,
    /// `basis/eigen`.
    pub method: String,
    /// Parameters of the fastest accurate run.
    pub basis_opts: String,
    /// Reference time / time of that run (setup included).
    #[serde(deserialize_with = "null_as_nan")]
    pub speedup: f64,
    /// Reference time / its per-mu solve time.
    #[serde(deserialize_with = "null_as_nan")]
    pub solve_speedup: f64,
}

/// [`SpeedRatio`] of every method with at least one accurate run in `runs`.
pub fn speed_ratios(runs: &[BenchRun]) -> Vec<SpeedRatio> {
    let mut out: Vec<SpeedRatio> = Vec::new();
    for r in runs.iter().filter(|r| r.accurate && !r.reference) {
        let method = format!("{}/{}", r.basis, r.eigen);
        match out
            .iter_mut()
            .find(|s| s.case == r.case && s.method == method)
        {
            Some(s) if s.speedup >= r.speedup => {}
            Some(s) => {
                s.basis_opts = r.basis_opts.clone();
                s.speedup = r.speedup;
                s.solve_speedup = r.solve_speedup;
            }
            None => out.push(SpeedRatio {
                case: r.case.clone(),
                method,
                basis_opts: r.basis_opts.clone(),
                speedup: r.speedup,
                solve_speedup: r.solve_speedup,
            }),
        }
    }
    out
}
