//! The study directory ([`StudyDir`]): its files, the claim a run lays on it, and the
//! merge of shard directories into one ([`merge`]).

use super::run::{Record, Timing};
use super::summary::{summarize, Summary, TimingSummary};
use super::{files, input, CaseList, Result, StudyDef};
use crate::jsonl;
use std::path::{Path, PathBuf};

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

/// Writes `study.json`, or checks an existing one is the same study (or, on resume, the
/// same meso study with fewer layouts per patch size: it is extended).
pub(super) fn claim(dir: &StudyDir, def: &StudyDef, resume: bool) -> Result<()> {
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
pub(super) fn finalize(
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
