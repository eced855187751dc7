//! Running a study: one case ([`run_case`]), the study directory ([`StudyDir`]), runs
//! with resume and shards ([`run`]) and the merge of shard directories ([`merge`]).

use super::summary::{summarize, Summary, TimingSummary};
use super::{files, input, Case, CaseList, Result, Shard, SolveSpec, StudyDef, StudyError};
use crate::jsonl;
use crate::pipeline::{damped_operator, Method, PipelineError};
use crate::profile::Profile;
use serde::{Deserialize, Serialize};
use squeal_contact::ContactSet;
use squeal_core::Registry;
use squeal_scene::{Damping, Model};
use std::path::{Path, PathBuf};
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
    /// Unstable modes (DvR above the study's threshold), by frequency.
    pub unstable: Vec<UnstableMode>,
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
        rec.basis_size = basis_size;
        let mut idx: Vec<usize> = (0..modes.len()).collect();
        idx.sort_by(|&a, &b| modes.freq_hz[a].total_cmp(&modes.freq_hz[b]));
        for i in idx {
            let (f, d, be) = (modes.freq_hz[i], modes.dvr[i], modes.backward_error[i]);
            rec.modes.push([f, d]);
            rec.max_backward_error = rec.max_backward_error.max(be);
            if d > solve.dvr_tol {
                rec.unstable.push(UnstableMode {
                    freq_hz: f,
                    dvr: d,
                    backward_error: be,
                    class_hz: solve.class_of(f),
                });
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

/// The files of a study directory.
pub struct StudyDir {
    /// The directory.
    pub dir: PathBuf,
}

impl StudyDir {
    /// A study directory (not created yet).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }
    /// `study.json`: the definition.
    pub fn study(&self) -> PathBuf {
        self.dir.join("study.json")
    }
    /// `results.jsonl`: one [`Record`] a line.
    pub fn results(&self) -> PathBuf {
        self.dir.join("results.jsonl")
    }
    /// `timings.jsonl`: one [`Timing`] a line.
    pub fn timings(&self) -> PathBuf {
        self.dir.join("timings.jsonl")
    }
    /// `summary.json`: the [`Summary`].
    pub fn summary(&self) -> PathBuf {
        self.dir.join("summary.json")
    }
    /// `timings.json`: the [`TimingSummary`].
    pub fn timing_summary(&self) -> PathBuf {
        self.dir.join("timings.json")
    }

    /// Reads `study.json`.
    pub fn read_def(&self) -> Result<StudyDef> {
        let p = self.study();
        let text = std::fs::read_to_string(&p)
            .map_err(|e| files(&p, format!("{e} (not a study directory?)")))?;
        serde_json::from_str(&text).map_err(|e| files(&p, e))
    }

    /// Records of `results.jsonl` (a torn last line is ignored).
    pub fn records(&self) -> Result<Vec<Record>> {
        jsonl::load(&self.results()).map_err(|e| files(&self.results(), e))
    }

    /// Timings of `timings.jsonl`.
    pub fn timing_records(&self) -> Result<Vec<Timing>> {
        jsonl::load(&self.timings()).map_err(|e| files(&self.timings(), e))
    }
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

/// Writes `study.json`, or checks an existing one is the same study (or, on resume, the
/// same meso study with fewer layouts per patch size: it is extended).
fn claim(dir: &StudyDir, def: &StudyDef, resume: bool) -> Result<()> {
    std::fs::create_dir_all(&dir.dir).map_err(|e| files(&dir.dir, e))?;
    let has_results = std::fs::metadata(dir.results()).is_ok_and(|m| m.len() > 0);
    if has_results && !resume {
        return Err(input(
            "dir",
            format!(
                "{} already holds results: set options.resume to continue that study, or choose another directory",
                dir.dir.display()
            ),
        ));
    }
    let want = serde_json::to_value(def).map_err(|e| files(&dir.study(), e))?;
    if dir.study().exists() {
        let have = serde_json::to_value(dir.read_def()?).map_err(|e| files(&dir.study(), e))?;
        if resume && extends_layouts(&have, &want) {
            // more layouts per patch size: the layouts done keep their ids and results
            let text = serde_json::to_string_pretty(&want).map_err(|e| files(&dir.study(), e))?;
            return jsonl::write_atomic(&dir.study(), text.as_bytes())
                .map_err(|e| files(&dir.study(), e));
        }
        if have != want {
            return Err(files(
                &dir.study(),
                format!(
                    "written for another study (differs at {}): use another directory",
                    crate::jsonl::first_difference(&have, &want)
                ),
            ));
        }
        return Ok(());
    }
    let text = serde_json::to_string_pretty(&want).map_err(|e| files(&dir.study(), e))?;
    jsonl::write_atomic(&dir.study(), text.as_bytes()).map_err(|e| files(&dir.study(), e))
}

/// Whether study `want` is study `have` with more layouts per patch size and nothing else
/// changed (a meso study extended on resume).
fn extends_layouts(have: &serde_json::Value, want: &serde_json::Value) -> bool {
    let layouts = |v: &serde_json::Value| v["study"]["layouts"].as_u64();
    let (Some(h), Some(w)) = (layouts(have), layouts(want)) else {
        return false;
    };
    let mut same = have.clone();
    same["study"]["layouts"] = w.into();
    w > h && &same == want
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
        let stage = probe.prepare_stage(model, &all)?;
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
    let workers = opts.jobs.clamp(1, todo.len().max(1));
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
    let computed = *counter.lock().unwrap_or_else(|p| p.into_inner());
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

/// Joins shard directories of one study into `out`: the same `study.json`,
/// `results.jsonl`, `timings.jsonl`, `summary.json` and `timings.json` as one run over the
/// whole study. Errors if the shards are of different studies or disagree on a case.
pub fn merge(inputs: &[PathBuf], out: &Path) -> Result<(StudyDef, Summary, TimingSummary)> {
    let Some(first) = inputs.first() else {
        return Err(input("dirs", "expected at least one study directory"));
    };
    let def = StudyDir::new(first).read_def()?;
    let want = serde_json::to_value(&def).map_err(|e| files(first, e))?;
    let mut records: std::collections::BTreeMap<String, Record> = Default::default();
    let mut timings: std::collections::BTreeMap<String, Timing> = Default::default();
    for d in inputs {
        let sd = StudyDir::new(d);
        let other = serde_json::to_value(sd.read_def()?).map_err(|e| files(d, e))?;
        if other != want {
            return Err(files(
                &sd.study(),
                format!(
                    "another study than {} (differs at {})",
                    StudyDir::new(first).study().display(),
                    crate::jsonl::first_difference(&want, &other)
                ),
            ));
        }
        for r in sd.records()? {
            if let Some(prev) = records.get(&r.case.id) {
                if prev != &r {
                    return Err(files(
                        &sd.results(),
                        format!(
                            "case {} differs from the one in another directory",
                            r.case.id
                        ),
                    ));
                }
            }
            records.insert(r.case.id.clone(), r);
        }
        for t in sd.timing_records()? {
            timings.insert(t.id.clone(), t);
        }
    }
    let list = def.cases()?;
    let od = StudyDir::new(out);
    if od.dir.canonicalize().ok().is_some_and(|o| {
        inputs
            .iter()
            .any(|i| i.canonicalize().ok().as_ref() == Some(&o))
    }) {
        return Err(input(
            "dir",
            "the merged directory must not be one of the inputs",
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| files(out, e))?;
    let text = serde_json::to_string_pretty(&want).map_err(|e| files(&od.study(), e))?;
    jsonl::write_atomic(&od.study(), text.as_bytes()).map_err(|e| files(&od.study(), e))?;
    let (s, t) = finalize(
        &od,
        &def,
        &list,
        records.into_values().collect(),
        timings.into_values().collect(),
    )?;
    Ok((def, s, t))
}

/// Rewrites the records sorted by id (only those of the case list, one per id) and writes
/// the summaries.
fn finalize(
    dir: &StudyDir,
    def: &StudyDef,
    list: &CaseList,
    records: Vec<Record>,
    timings: Vec<Timing>,
) -> Result<(Summary, TimingSummary)> {
    let ids: std::collections::BTreeSet<&str> = list.cases.iter().map(|c| c.id.as_str()).collect();
    let mut by_id: std::collections::BTreeMap<String, Record> = Default::default();
    for r in records
        .into_iter()
        .filter(|r| ids.contains(r.case.id.as_str()))
    {
        by_id.insert(r.case.id.clone(), r);
    }
    let records: Vec<Record> = by_id.into_values().collect();
    let mut t_by_id: std::collections::BTreeMap<String, Timing> = Default::default();
    for t in timings.into_iter().filter(|t| ids.contains(t.id.as_str())) {
        t_by_id.insert(t.id.clone(), t);
    }
    let timings: Vec<Timing> = t_by_id.into_values().collect();
    jsonl::write_all(&dir.results(), &records).map_err(|e| files(&dir.results(), e))?;
    jsonl::write_all(&dir.timings(), &timings).map_err(|e| files(&dir.timings(), e))?;
    let summary = summarize(def, list, &records);
    let text = serde_json::to_string_pretty(&summary).map_err(|e| files(&dir.summary(), e))?;
    jsonl::write_atomic(&dir.summary(), format!("{text}\n").as_bytes())
        .map_err(|e| files(&dir.summary(), e))?;
    let tsum = TimingSummary::of(&timings);
    let text = serde_json::to_string_pretty(&tsum).map_err(|e| files(&dir.timing_summary(), e))?;
    jsonl::write_atomic(&dir.timing_summary(), format!("{text}\n").as_bytes())
        .map_err(|e| files(&dir.timing_summary(), e))?;
    Ok((summary, tsum))
}
