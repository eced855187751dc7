//! Where the time of a run goes: named stages with their wall time and how many times
//! each ran ([`Profile`]), and the process's peak resident memory ([`peak_rss_mb`]).
//! Every report (`validate`, sweeps, studies, bench) carries one.

use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// One stage of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageTime {
    /// What ran.
    pub stage: String,
    /// Wall time summed over its runs (s).
    pub time_s: f64,
    /// How many times it ran.
    pub count: usize,
}

/// Stages in the order they first ran.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// The stages.
    pub stages: Vec<StageTime>,
}

impl Profile {
    /// An empty profile.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one run of `stage` that took `time_s` (summed with earlier runs of the same
    /// stage).
    pub fn add(&mut self, stage: &str, time_s: f64) {
        self.add_runs(stage, time_s, 1);
    }

    /// Adds `count` runs of `stage` that took `time_s` together.
    pub fn add_runs(&mut self, stage: &str, time_s: f64, count: usize) {
        match self.stages.iter_mut().find(|s| s.stage == stage) {
            Some(s) => {
                s.time_s += time_s;
                s.count += count;
            }
            None => self.stages.push(StageTime {
                stage: stage.to_string(),
                time_s,
                count,
            }),
        }
    }

    /// Appends the stages of `other`, their names prefixed by `prefix` (e.g. `sweep cms:
    /// `).
    pub fn extend_prefixed(&mut self, prefix: &str, other: &Profile) {
        for s in &other.stages {
            self.add_runs(&format!("{prefix}{}", s.stage), s.time_s, s.count);
        }
    }

    /// Sum of the stage times (s).
    pub fn total_s(&self) -> f64 {
        self.stages.iter().map(|s| s.time_s).sum()
    }

    /// A Markdown table: stage, runs, time (s), share of `wall_s` (the run's wall time;
    /// stages nested in others or run outside the profile make the shares not sum to 100).
    pub fn markdown(&self, wall_s: f64) -> String {
        let mut md = String::from("| stage | runs | time (s) | share |\n|---|---|---|---|\n");
        for s in &self.stages {
            let _ = writeln!(
                md,
                "| {} | {} | {:.1} | {:.0} % |",
                s.stage,
                s.count,
                s.time_s,
                100.0 * s.time_s / wall_s.max(f64::MIN_POSITIVE)
            );
        }
        md
    }
}

/// Peak resident memory of the process (MB), from `/proc/self/status` (`VmHWM`); `None`
/// where that file does not exist.
pub fn peak_rss_mb() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stages_accumulate_in_first_run_order() {
        let mut p = Profile::new();
        p.add("basis", 2.0);
        p.add("solve", 1.0);
        p.add("basis", 3.0);
        assert_eq!(p.stages.len(), 2);
        assert_eq!(p.stages[0].stage, "basis");
        assert_eq!(p.stages[0].count, 2);
        assert!((p.stages[0].time_s - 5.0).abs() < 1e-15);
        assert!((p.total_s() - 6.0).abs() < 1e-15);
        let mut q = Profile::new();
        q.extend_prefixed("sweep: ", &p);
        assert_eq!(q.stages[1].stage, "sweep: solve");
        let md = p.markdown(12.0);
        assert!(md.contains("| basis | 2 | 5.0 | 42 % |"), "{md}");
    }

    #[test]
    fn peak_memory_is_positive_on_linux() {
        if std::path::Path::new("/proc/self/status").exists() {
            let mb = peak_rss_mb().expect("VmHWM in /proc/self/status");
            assert!(mb > 0.0, "{mb}");
        }
    }
}
