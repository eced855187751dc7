//! One benchmark case: the reference solve and every (basis, variant, eigen solver) run
//! on one operator at one mu.

use super::{compare, BenchOptions, MemoryProbe, ModeErrors, Stages};
use crate::jsonl::{nan, null_as_nan};
use crate::pipeline::{PipelineError, Result};
use crate::profile::max_opt;
use serde::{Deserialize, Serialize};
use squeal_core::contact::BasisRequest;
use squeal_core::linalg::Cholesky;
use squeal_core::operator::{ComplexModes, Stability};
use squeal_core::reduction::{energy_bounds_on, ReducedOperator};
use squeal_core::{EigenParams, EigenSolver, FrictionalOperator, Params, Registry};
use std::sync::Arc;
use std::time::Instant;

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
    /// What the basis says of itself (its columns, the real-mode pair it drew them from,
    /// its steps); empty for full order.
    #[serde(default)]
    pub basis_notes: Vec<String>,
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
    /// Modes neutral within their error bound `[freq_hz, dvr]` (the physical margin
    /// applied as for `unstable`).
    #[serde(default)]
    pub neutral: Vec<[f64; 2]>,
    /// Worst backward error in the band.
    #[serde(deserialize_with = "null_as_nan")]
    pub max_backward_error: f64,
    /// Worst forward error estimate in the band (NaN when not computed).
    #[serde(default = "nan", deserialize_with = "null_as_nan")]
    pub max_error_bound: f64,
}

pub(super) fn core(stage: String) -> impl FnOnce(squeal_core::Error) -> PipelineError {
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

/// The parameter variants of `basis`: its defaults (when `opts.defaults`) and each value
/// of `opts.vary` the plugin accepts (a plugin that rejects a parameter is not varied in
/// it). When nothing else is left the defaults run.
pub(super) fn variants(
    registry: &Registry,
    basis: &str,
    opts: &BenchOptions,
) -> Vec<(String, Params)> {
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

/// Runs the reference and every combination of `opts` on `op` at `mu`. `on_run` sees
/// each run as soon as it finishes (to append it to a results file). A failing run is
/// recorded with its error; only a failing reference stops the case. `stages` are the
/// model stages of the bases that have one ([`super::stages_for`]; `cms`); without its
/// stage (an operator read from files) such a basis is recorded as failed.
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
    // the reference
    let meter = Meter::start(memory);
    let t = Instant::now();
    let mut reference = eigen_solver(registry, &opts.reference_eigen)?
        .solve_frictional(op, mu, &opts.params(opts.reference_tol))
        .map_err(core(format!(
            "reference `{}` at mu = {mu} ({case})",
            opts.reference_eigen
        )))?;
    let ref_time = t.elapsed().as_secs_f64();
    let ref_condition_s = with_condition(opts, op, mu, &mut reference)?;
    let ref_peak = meter.peak_mb();
    let self_errors = compare(&reference, &reference, opts.band_hz, opts.dvr_margin);
    let in_band = |f: f64| f >= opts.band_hz[0] && f <= opts.band_hz[1];
    let of_class = |class: Stability| -> Vec<[f64; 2]> {
        (0..reference.len())
            .filter(|&i| {
                in_band(reference.freq_hz[i]) && reference.stability(i, opts.dvr_margin) == class
            })
            .map(|i| [reference.freq_hz[i], reference.dvr[i]])
            .collect()
    };
    let ref_out = ReferenceSolve {
        case: case.into(),
        mu,
        eigen: opts.reference_eigen.clone(),
        tol: opts.reference_tol,
        dofs: op.dim(),
        time_s: ref_time,
        peak_mb: ref_peak,
        modes: self_errors.reference_modes,
        unstable: of_class(Stability::Unstable),
        neutral: of_class(Stability::Neutral),
        max_backward_error: self_errors.max_backward_error,
        max_error_bound: self_errors.max_error_bound,
    };
    let runner = Runner {
        registry,
        case,
        op,
        stages,
        mu,
        opts,
        memory,
        reference: &reference,
        params: opts.params(opts.tol),
    };
    let mut runs = Vec::new();
    let mut push = |mut run: BenchRun| {
        run.time_s = run.setup_s + run.solve_s;
        run.accurate = run.status == "ok" && run.errors.accurate(&opts.accuracy);
        // A failed run has no speed-up (its time is that of the failure).
        let ok = run.status == "ok";
        run.speedup = if ok { ref_time / run.time_s } else { f64::NAN };
        run.solve_speedup = if ok { ref_time / run.solve_s } else { f64::NAN };
        on_run(&run);
        runs.push(run);
    };
    push(BenchRun {
        reference: true,
        solve_s: ref_time,
        peak_mb: ref_peak,
        condition_s: ref_condition_s,
        tol: opts.reference_tol,
        errors: self_errors,
        ..runner.blank("none", "", &opts.reference_eigen)
    });
    for basis in &opts.bases {
        if basis == "none" {
            for eigen in opts.eigens.iter().filter(|e| **e != opts.reference_eigen) {
                push(runner.full_order(eigen));
            }
            continue;
        }
        for (label, p) in variants(registry, basis, opts) {
            runner.reduced(basis, &label, &p, &mut push);
        }
    }
    Ok((ref_out, runs))
}

/// What the runs of one case share: the operator, the options and the reference.
struct Runner<'a> {
    registry: &'a Registry,
    case: &'a str,
    op: &'a FrictionalOperator,
    stages: &'a Stages,
    mu: f64,
    opts: &'a BenchOptions,
    memory: Option<&'a dyn MemoryProbe>,
    reference: &'a ComplexModes,
    params: EigenParams,
}

impl Runner<'_> {
    /// A run of `basis` (variant `basis_opts`) and `eigen` with nothing measured yet.
    fn blank(&self, basis: &str, basis_opts: &str, eigen: &str) -> BenchRun {
        BenchRun {
            case: self.case.into(),
            basis: basis.into(),
            basis_opts: basis_opts.into(),
            eigen: eigen.into(),
            mu: self.mu,
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
            basis_notes: Vec::new(),
            dofs: self.op.dim(),
            tol: self.opts.tol,
            errors: ModeErrors::failed(),
            accurate: false,
            speedup: f64::NAN,
            solve_speedup: f64::NAN,
        }
    }

    /// The full-order solve of `eigen` against the reference.
    fn full_order(&self, eigen: &str) -> BenchRun {
        let (op, mu, opts) = (self.op, self.mu, self.opts);
        let mut run = self.blank("none", "", eigen);
        let meter = Meter::start(self.memory);
        let t = Instant::now();
        match eigen_solver(self.registry, eigen).and_then(|s| {
            s.solve_frictional(op, mu, &self.params)
                .map_err(core(format!("`{eigen}` at mu = {mu}")))
        }) {
            Ok(mut modes) => {
                run.solve_s = t.elapsed().as_secs_f64();
                match with_condition(opts, op, mu, &mut modes) {
                    Ok(c) => {
                        run.condition_s = c;
                        run.errors = compare(self.reference, &modes, opts.band_hz, opts.dvr_margin);
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
        run
    }

    /// Builds basis `basis` with parameters `p` on the case's operator (its model stage
    /// from the runner's stages, if it has one) and projects the operator on it.
    /// Returns it with the free model's factor that the stage holds (for the energy-norm
    /// error bounds of the modes solved on it).
    fn reduced_operator(
        &self,
        basis: &str,
        p: &Params,
    ) -> Result<(ReducedOperator, Option<Arc<Cholesky>>)> {
        let (op, mu, opts) = (self.op, self.mu, self.opts);
        let plugin = self
            .registry
            .bases
            .create(basis, p)
            .map_err(core(format!("basis `{basis}`")))?;
        let modal = eigen_solver(self.registry, &opts.modal)?;
        let dense = eigen_solver(self.registry, "dense")?;
        let stage = plugin
            .stage_key(opts.band_hz[1])
            .and_then(|key| self.stages.iter().find(|s| s.key == key));
        let free = stage.and_then(|s| plugin.stage_factor(&s.stage));
        let stage = stage.map(|s| s.stage.as_ref());
        let req = BasisRequest {
            op,
            mu,
            band_hz: (opts.band_hz[0], opts.band_hz[1]),
            modal: modal.as_ref(),
            reduced: dense.as_ref(),
            params: &self.params,
            stage,
            seed: None,
        };
        let b = squeal_core::contact::build_basis(plugin.as_ref(), &req)
            .map_err(core(format!("basis `{basis}` at mu = {mu}")))?;
        let red = ReducedOperator::new(op, b).map_err(core(format!("projection on `{basis}`")))?;
        Ok((red, free))
    }

    /// Basis `basis` with parameters `p` (labelled `label`) built once, then every eigen
    /// solver on it; each run goes to `push` as it finishes.
    fn reduced(&self, basis: &str, label: &str, p: &Params, push: &mut impl FnMut(BenchRun)) {
        let (op, mu, opts) = (self.op, self.mu, self.opts);
        let meter = Meter::start(self.memory);
        let t = Instant::now();
        let built = self.reduced_operator(basis, p);
        let setup_s = t.elapsed().as_secs_f64();
        let setup_peak = meter.peak_mb();
        let (red, free) = match built {
            Ok(r) => r,
            Err(e) => {
                for eigen in &opts.eigens {
                    push(BenchRun {
                        setup_s,
                        peak_mb: setup_peak,
                        status: format!("error: {e}"),
                        ..self.blank(basis, label, eigen)
                    });
                }
                return;
            }
        };
        for eigen in &opts.eigens {
            let mut run = BenchRun {
                setup_s,
                basis_size: red.basis.len(),
                basis_notes: red.basis.notes.clone(),
                ..self.blank(basis, label, eigen)
            };
            let t = Instant::now();
            let solved = eigen_solver(self.registry, eigen).and_then(|s| {
                let at = format!("`{eigen}` on basis `{basis}` at mu = {mu}");
                let mut r = red
                    .solve(op, mu, s.as_ref(), &self.params)
                    .map_err(core(at.clone()))?;
                let t = Instant::now();
                energy_bounds_on(free.as_deref(), op, mu, &mut r.modes)
                    .map_err(core(format!("energy-norm error bounds of {at}")))?;
                Ok((r, t.elapsed().as_secs_f64()))
            });
            match solved {
                Ok((r, bound_s)) => {
                    run.solve_s = t.elapsed().as_secs_f64();
                    run.reduced_solve_s = Some(r.solve_time_s);
                    run.expansion_s = Some(r.expansion_time_s + bound_s);
                    run.errors = compare(self.reference, &r.modes, opts.band_hz, opts.dvr_margin);
                }
                Err(e) => {
                    run.solve_s = t.elapsed().as_secs_f64();
                    run.status = format!("error: {e}");
                }
            }
            run.peak_mb = max_opt(setup_peak, meter.peak_mb());
            push(run);
        }
    }
}

/// The eigen solver plugin `name`.
fn eigen_solver(registry: &Registry, name: &str) -> Result<Box<dyn EigenSolver>> {
    registry
        .eigen
        .create(name, &Params::new())
        .map_err(core(format!("eigen solver `{name}`")))
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
