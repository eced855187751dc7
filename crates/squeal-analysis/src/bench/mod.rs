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

use crate::jsonl::null_as_nan;
use crate::pipeline::Result;
use case::{core, variants};
use serde::{Deserialize, Serialize};
use squeal_core::{EigenParams, ModelStage, Params, Registry};
use std::time::Instant;

mod case;
mod compare;
mod stress;
mod suite;
pub use case::{bench_case, BenchRun, ReferenceSolve};
pub use compare::{compare, Accuracy, ModeErrors, BOUND_FLOOR};
pub use stress::{bound_flags, bound_threshold, stress_rows, StressRow};
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
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    pub dvr_margin: f64,
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
            dvr_margin: 0.0,
            bases,
            eigens: registry.eigen.names(),
            vary: Vec::new(),
            defaults: true,
            modal: crate::pipeline::MODAL_SOLVER.into(),
            accuracy: Accuracy::default(),
            condition: false,
        }
    }

    pub(super) fn params(&self, tol: f64) -> EigenParams {
        EigenParams {
            fmin_hz: self.band_hz[0],
            fmax_hz: self.band_hz[1],
            tol,
            ..EigenParams::default()
        }
    }
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
/// free-interface synthesis) on `model` and the candidate pairs `set`, one per stage key,
/// each completed by every basis that shares it
/// ([`squeal_core::ReductionBasis::complete_stage`]). Built once and handed to every
/// [`bench_case`] of the model.
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
            if let Some(s) = stages.iter_mut().find(|s| s.key == key) {
                // what this basis adds to a stage another one prepared: computed here, so
                // that no case's set-up pays it
                let t = Instant::now();
                plugin
                    .complete_stage(&s.stage)
                    .map_err(core(format!("model stage of `{basis}`")))?;
                s.time_s += t.elapsed().as_secs_f64();
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
                None,
            )?;
            if let Some(stage) = stage {
                plugin
                    .complete_stage(&stage)
                    .map_err(core(format!("model stage of `{basis}`")))?;
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
