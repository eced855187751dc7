//! Running a study: one case ([`run_case`]) and runs with resume and shards ([`run`]);
//! the directory they write is [`StudyDir`](super::StudyDir).

use super::dir::{claim, finalize};
use super::summary::{Summary, TimingSummary};
use super::{files, input, Case, Result, Shard, SolveSpec, StudyDef, StudyDir, StudyError};
use crate::jsonl;
use crate::pipeline::{damped_operator, Method, PipelineError};
use crate::profile::Profile;
use serde::{Deserialize, Serialize};
use squeal_contact::ContactSet;
use squeal_core::{Registry, Stability};
use squeal_scene::{Damping, Model};
use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::Instant;

/// An unstable mode of a case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnstableMode {
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// Divergence rate `Re / Im`.
    pub dvr: f64,
    /// Backward error on the full operator.
    pub backward_error: f64,
    /// Its class (Hz; see [`SolveSpec::class_of`]), absent outside every class.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub class_hz: Option<f64>,
}

/// The result of one case: a line of `results.jsonl` (no times, see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// The case.
    #[serde(flatten)]
    pub case: Case,
    /// Basis size (0 for full order).
    pub basis_size: usize,
    /// Unstable modes (real part above its error bound, and DvR above the study's
    /// physical margin), by frequency.
    pub unstable: Vec<UnstableMode>,
    /// Modes neutral within their error bound, `[freq_hz, dvr]`, by frequency.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub neutral: Vec<[f64; 2]>,
    /// Every mode in the band: `[freq_hz, dvr]`, by frequency.
    pub modes: Vec<[f64; 2]>,
    /// Largest backward error of the modes.
    pub max_backward_error: f64,
    /// Why the case failed (then no mode); failed cases are kept so a resume does not
    /// retry them forever.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

impl Record {
    /// The zone `[x0, y0, a, b]` (m, from the pin face's corner) of a macroscopic case;
    /// `None` for plateau layouts.
    pub fn rectangle(&self) -> Option<[f64; 4]> {
        match self.case.zone {
            squeal_scene::Zone::Rectangle {
                x0_m,
                y0_m,
                a_m,
                b_m,
            } => Some([x0_m, y0_m, a_m, b_m]),
            _ => None,
        }
    }
}

/// Wall times of one case (s): a line of `timings.jsonl`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// Case id.
    pub id: String,
    /// Contact set of the zone.
    pub contact_s: f64,
    /// Frictional operator on all its pairs.
    pub operator_s: f64,
    /// Reduction basis build.
    pub basis_s: f64,
    /// Projection on the basis.
    pub projection_s: f64,
    /// Eigen solve (reduced with a basis).
    pub solve_s: f64,
    /// Expansion and backward errors on the full operator.
    pub expansion_s: f64,
    /// The whole case.
    pub total_s: f64,
    /// The basis's steps (s, by step; [`squeal_core::Basis::steps`]), for a basis that
    /// times them.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub basis_steps: BTreeMap<String, f64>,
}

/// Solves one case on `model` with `method`.
pub fn run_case(
    model: &Model,
    rotation: f64,
    damping: &Damping,
    solve: &SolveSpec,
    case: &Case,
    method: &mut Method,
) -> (Record, Timing) {
    let start = Instant::now();
    let mut t = Timing {
        id: case.id.clone(),
        ..Timing::default()
    };
    let mut rec = Record {
        case: case.clone(),
        basis_size: 0,
        unstable: Vec::new(),
        neutral: Vec::new(),
        modes: Vec::new(),
        max_backward_error: 0.0,
        error: None,
    };
    let res = (|| -> std::result::Result<(), PipelineError> {
        let t0 = Instant::now();
        let set = ContactSet::new(model, &case.zone, rotation)?;
        t.contact_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let op = damped_operator(model, damping, &set, &vec![true; set.len()])?;
        t.operator_s = t1.elapsed().as_secs_f64();
        let (modes, basis_size, _) = method.solve(&op, case.mu, true)?;
        let st = method.last_times();
        (t.basis_s, t.projection_s, t.solve_s, t.expansion_s) =
            (st.basis_s, st.projection_s, st.solve_s, st.expansion_s);
        for (step, s) in method.last_basis_steps() {
            *t.basis_steps.entry(step.clone()).or_insert(0.0) += s;
        }
        rec.basis_size = basis_size;
        let mut idx: Vec<usize> = (0..modes.len()).collect();
        idx.sort_by(|&a, &b| modes.freq_hz[a].total_cmp(&modes.freq_hz[b]));
        for i in idx {
            let (f, d, be) = (modes.freq_hz[i], modes.dvr[i], modes.backward_error[i]);
            rec.modes.push([f, d]);
            rec.max_backward_error = rec.max_backward_error.max(be);
            match modes.stability(i, solve.dvr_margin) {
                Stability::Unstable => rec.unstable.push(UnstableMode {
                    freq_hz: f,
                    dvr: d,
                    backward_error: be,
                    class_hz: solve.class_of(f),
                }),
                Stability::Neutral => rec.neutral.push([f, d]),
                Stability::Stable => {}
            }
        }
        Ok(())
    })();
    if let Err(e) = res {
        rec.error = Some(format!("case {}: {e}", case.id));
    }
    t.total_s = start.elapsed().as_secs_f64();
    (rec, t)
}

/// How to run a study.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Parallel cases (each worker with its own [`Method`]); 0 or 1 runs them one after
    /// the other on the calling thread (each case still uses every core through faer).
    pub jobs: usize,
    /// Only this part of the cases.
    pub shard: Option<Shard>,
    /// Continue a directory that already holds results (else that is an error).
    pub resume: bool,
    /// Stop after this many new cases (a batch slot; the rest is left for a resume).
    pub max_cases: Option<usize>,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// Cases of the whole study.
    pub cases: usize,
    /// Cases of this run's shard.
    pub shard_cases: usize,
    /// Cases found already done.
    pub resumed: usize,
    /// Cases computed now.
    pub computed: usize,
    /// Shard cases still to do (after `max_cases`).
    pub remaining: usize,
    /// The summary written.
    pub summary: Summary,
    /// The timings summary written.
    pub timings: TimingSummary,
    /// Where this run's time went: the free-interface synthesis (when the basis works
    /// from one), then each stage summed over the cases computed now.
    pub profile: Profile,
}

/// What [`run`] tells its observer.
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    /// Before the first case: `resumed` cases of the shard were already done, `todo`
    /// will be computed now, of `shard` cases in this run's shard.
    Start {
        /// Cases found done.
        resumed: usize,
        /// Cases to compute now.
        todo: usize,
        /// Cases of the shard.
        shard: usize,
    },
    /// A case finished and was appended (`done` of `todo` so far in this run).
    Case {
        /// Cases computed so far by this run.
        done: usize,
        /// The record just appended.
        record: &'a Record,
    },
}

/// Runs (or resumes) a study in `dir` on `model` (built from the definition's scene).
/// Every finished case is appended at once; when the run ends, `results.jsonl` and
/// `timings.jsonl` are rewritten sorted by id and `summary.json`, `timings.json` written
/// from every record in the directory. With `jobs > 1`, `jobs` rayon workers each own a
/// [`Method`] and take the next case until none is left.
pub fn run(
    registry: &Registry,
    model: &Model,
    def: &StudyDef,
    dir: &StudyDir,
    opts: &RunOptions,
    progress: &(dyn Fn(Progress<'_>) + Sync),
) -> Result<RunReport> {
    def.solve.check()?;
    if model.dofs.n_free() != def.dofs {
        return Err(input(
            "scene",
            format!(
                "the model has {} DOFs, the study {}",
                model.dofs.n_free(),
                def.dofs
            ),
        ));
    }
    let list = def.cases()?;
    // fail fast on unknown plugins or parameters
    let mut probe = def.solve.method(registry)?;
    claim(dir, def, opts.resume)?;
    let done: std::collections::BTreeSet<String> =
        dir.records()?.into_iter().map(|r| r.case.id).collect();
    let shard: Vec<&Case> = list
        .cases
        .iter()
        .enumerate()
        .filter(|(i, _)| opts.shard.is_none_or(|s| s.holds(*i)))
        .map(|(_, c)| c)
        .collect();
    let resumed = shard.iter().filter(|c| done.contains(&c.id)).count();
    let mut todo: Vec<&Case> = shard
        .iter()
        .copied()
        .filter(|c| !done.contains(&c.id))
        .collect();
    let limit = opts.max_cases.unwrap_or(usize::MAX);
    let remaining = todo.len().saturating_sub(limit);
    todo.truncate(limit);
    // a basis with a model stage (`cms`: the free-interface synthesis) gets it built here
    // once for every pair of the face and shared by the workers
    let mut profile = Profile::new();
    let stage = if todo.is_empty() || probe.stage_key().is_none() {
        None
    } else {
        let t = std::time::Instant::now();
        let all = ContactSet::new(model, &squeal_scene::Zone::Uniform, def.rotation)
            .map_err(PipelineError::from)?;
        let stage = probe.prepare_stage(model, &all, Some(todo.len()))?;
        profile.add(
            &format!("model stage of `{}`", probe.basis_name),
            t.elapsed().as_secs_f64(),
        );
        stage
    };
    drop(probe);
    progress(Progress::Start {
        resumed,
        todo: todo.len(),
        shard: shard.len(),
    });
    let computed = run_cases(registry, model, def, dir, &todo, stage, opts.jobs, progress)?;
    let records = dir.records()?;
    let timings = dir.timing_records()?;
    let now: Vec<&Timing> = timings
        .iter()
        .filter(|t| todo.iter().any(|c| c.id == t.id))
        .collect();
    for t in &now {
        for (stage, s) in [
            ("contact set", t.contact_s),
            ("operator", t.operator_s),
            ("basis", t.basis_s),
        ] {
            profile.add(stage, s);
        }
        // the basis's own steps, under its time
        for (step, s) in &t.basis_steps {
            profile.add_step("basis", step, *s);
        }
        for (stage, s) in [
            ("projection", t.projection_s),
            ("eigen solve", t.solve_s),
            ("expansion + backward errors", t.expansion_s),
        ] {
            profile.add(stage, s);
        }
    }
    let (summary, tsum) = finalize(dir, def, &list, records, timings)?;
    Ok(RunReport {
        cases: list.cases.len(),
        shard_cases: shard.len(),
        resumed,
        computed,
        remaining,
        summary,
        timings: tsum,
        profile,
    })
}

/// Computes the cases `todo` of study `def` in `dir` on `jobs` workers (each with its own
/// [`Method`] on the shared model stage), appending each finished case at once; returns
/// how many were computed. The first error stops every worker and is returned.
#[allow(clippy::too_many_arguments)]
fn run_cases(
    registry: &Registry,
    model: &Model,
    def: &StudyDef,
    dir: &StudyDir,
    todo: &[&Case],
    stage: Option<squeal_core::ModelStage>,
    jobs: usize,
    progress: &(dyn Fn(Progress<'_>) + Sync),
) -> Result<usize> {
    let counter = Mutex::new(0usize);
    let failure: Mutex<Option<StudyError>> = Mutex::new(None);
    let failed = || failure.lock().map(|f| f.is_some()).unwrap_or(true);
    let fail = |e: StudyError| {
        let mut f = failure.lock().unwrap_or_else(|p| p.into_inner());
        f.get_or_insert(e);
    };
    // appends a finished case; false stops the run (an I/O error)
    let finish = |rec: Record, t: Timing| -> bool {
        let mut n = counter.lock().unwrap_or_else(|p| p.into_inner());
        let res = jsonl::append(&dir.results(), &rec)
            .map_err(|e| files(&dir.results(), e))
            .and_then(|_| jsonl::append(&dir.timings(), &t).map_err(|e| files(&dir.timings(), e)));
        if let Err(e) = res {
            fail(e);
            return false;
        }
        *n += 1;
        progress(Progress::Case {
            done: *n,
            record: &rec,
        });
        true
    };
    let rotation = def.rotation;
    let next = std::sync::atomic::AtomicUsize::new(0);
    let worker = || match def.solve.method(registry) {
        Ok(mut method) => loop {
            method.set_stage(stage.clone());
            if failed() {
                break;
            }
            let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            let Some(case) = todo.get(i) else { break };
            let (rec, t) = run_case(model, rotation, &def.damping, &def.solve, case, &mut method);
            if !finish(rec, t) {
                break;
            }
        },
        Err(e) => fail(e),
    };
    let workers = jobs.clamp(1, todo.len().max(1));
    if workers == 1 {
        worker();
    } else {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(workers)
            .build()
            .map_err(|e| {
                input(
                    "options.jobs",
                    format!("cannot start {workers} workers: {e}"),
                )
            })?;
        pool.scope(|s| {
            for _ in 0..workers {
                s.spawn(|_| worker());
            }
        });
    }
    if let Some(e) = failure.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    Ok(counter.into_inner().unwrap_or_else(|p| p.into_inner()))
}
