//! Where the time of a run goes: named stages with their wall time, how many times each
//! ran and, where the run measured it, the peak resident memory while it ran
//! ([`Profile`]); the process's peak resident memory ([`peak_rss_mb`]) and the peak since
//! the last stage ([`take_peak_rss_mb`]); the machine a run measured its times on
//! ([`Machine`]). Every report (`validate`, sweeps, studies, bench) carries one.

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
    /// Peak resident memory while it ran (MB; the largest over its runs), where measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_rss_mb: Option<f64>,
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
        self.add_measured(stage, time_s, count, None);
    }

    /// Adds one run of `stage` that took `time_s` with a peak resident memory of
    /// `peak_rss_mb` (from [`take_peak_rss_mb`] at its end).
    pub fn add_with_peak(&mut self, stage: &str, time_s: f64, peak_rss_mb: Option<f64>) {
        self.add_measured(stage, time_s, 1, peak_rss_mb);
    }

    fn add_measured(&mut self, stage: &str, time_s: f64, count: usize, peak: Option<f64>) {
        match self.stages.iter_mut().find(|s| s.stage == stage) {
            Some(s) => {
                s.time_s += time_s;
                s.count += count;
                s.peak_rss_mb = max_opt(s.peak_rss_mb, peak);
            }
            None => self.stages.push(StageTime {
                stage: stage.to_string(),
                time_s,
                count,
                peak_rss_mb: peak,
            }),
        }
    }

    /// Adds `time_s` to the row of `step` listed under `stage` (named `"<stage>: <step>"`,
    /// which [`Profile::is_step`] recognizes: part of the stage's time, not more of it).
    pub fn add_step(&mut self, stage: &str, step: &str, time_s: f64) {
        self.add(&format!("{stage}: {step}"), time_s);
    }

    /// The largest stage peak (MB), where any was measured.
    pub fn peak_rss_mb(&self) -> Option<f64> {
        self.stages
            .iter()
            .filter_map(|s| s.peak_rss_mb)
            .reduce(f64::max)
    }

    /// Appends the stages of `other`, their names prefixed by `prefix` (e.g. `sweep cms:
    /// `).
    pub fn extend_prefixed(&mut self, prefix: &str, other: &Profile) {
        for s in &other.stages {
            self.add_runs(&format!("{prefix}{}", s.stage), s.time_s, s.count);
        }
    }

    /// Sum of the stage times (s), the steps listed under a stage (`"<stage>: <step>"`,
    /// such as a basis's, [`Profile::is_step`]) left out: they are part of its time.
    pub fn total_s(&self) -> f64 {
        self.stages
            .iter()
            .filter(|s| !self.is_step(&s.stage))
            .map(|s| s.time_s)
            .sum()
    }

    /// Whether `stage` is a step of another stage of this profile: its name is that
    /// stage's followed by `": "` and the step's.
    pub fn is_step(&self, stage: &str) -> bool {
        self.stages.iter().any(|p| {
            stage
                .strip_prefix(p.stage.as_str())
                .is_some_and(|rest| rest.len() > 2 && rest.starts_with(": "))
        })
    }

    /// A Markdown table: stage, runs, time (s), share of `wall_s` (the run's wall time;
    /// stages nested in others or run outside the profile make the shares not sum to 100)
    /// and, when any stage measured it, its peak resident memory (MB).
    pub fn markdown(&self, wall_s: f64) -> String {
        let peaks = self.stages.iter().any(|s| s.peak_rss_mb.is_some());
        let mut md = if peaks {
            String::from(
                "| stage | runs | time (s) | share | peak RSS (MB) |\n|---|---|---|---|---|\n",
            )
        } else {
            String::from("| stage | runs | time (s) | share |\n|---|---|---|---|\n")
        };
        for s in &self.stages {
            let _ = write!(
                md,
                "| {} | {} | {:.1} | {:.0} % |",
                s.stage,
                s.count,
                s.time_s,
                100.0 * s.time_s / wall_s.max(f64::MIN_POSITIVE)
            );
            if peaks {
                let _ = match s.peak_rss_mb {
                    Some(mb) => write!(md, " {mb:.0} |"),
                    None => write!(md, " - |"),
                };
            }
            md.push('\n');
        }
        md
    }
}

/// The machine a run's times were measured on: the same code on another processor of the
/// same core count can take twice as long, so every timed report names it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// Processor model (`model name` of `/proc/cpuinfo`; `unknown` where it is not given).
    pub cpu: String,
    /// Cores the run may use.
    pub cores: usize,
    /// Physical memory (GiB), where known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub memory_gib: Option<f64>,
}

impl Machine {
    /// The machine this process runs on.
    pub fn here() -> Self {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|t| cpuinfo_model(&t))
            .unwrap_or_else(|| "unknown".into());
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let memory_gib = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|t| meminfo_kib(&t, "MemTotal:"))
            .map(|kib| kib / (1024.0 * 1024.0));
        Self {
            cpu,
            cores,
            memory_gib,
        }
    }
}

impl std::fmt::Display for Machine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}, {} cores", self.cpu, self.cores)?;
        if let Some(g) = self.memory_gib {
            write!(f, ", {g:.0} GiB")?;
        }
        Ok(())
    }
}

/// The first `model name` of a `/proc/cpuinfo` text.
fn cpuinfo_model(text: &str) -> Option<String> {
    let line = text.lines().find(|l| l.starts_with("model name"))?;
    let name = line
        .split_once(':')?
        .1
        .split_whitespace()
        .collect::<Vec<_>>();
    (!name.is_empty()).then(|| name.join(" "))
}

/// The value (kB) of `key` in a `/proc/meminfo` text.
fn meminfo_kib(text: &str, key: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The larger of two optional measurements (either one when the other is missing).
pub fn max_opt(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) => x,
        (None, y) => y,
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

/// Returns the memory the allocator holds free to the system (glibc's `malloc_trim`:
/// freed blocks inside its heaps otherwise stay resident, and a later stage whose blocks
/// do not fit in them grows the heap beside them); nothing elsewhere.
pub fn return_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free pages of glibc's heaps to the system.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Peak resident memory (MB) since the previous call (or the process's start), then the
/// memory the allocator holds free returned to the system ([`return_free_memory`]) and
/// the mark reset to the memory resident now (Linux: `VmHWM` of `/proc/self/status`,
/// reset by writing `5` to `/proc/self/clear_refs`), so each stage of a run gets its own
/// peak.
/// After a call, [`peak_rss_mb`] gives the peak since that call, not the process's: a run
/// that takes stage peaks reports the largest of them as its peak. `None` where the files
/// do not exist; when the reset is refused the peaks are cumulative (still upper bounds).
pub fn take_peak_rss_mb() -> Option<f64> {
    let peak = peak_rss_mb()?;
    return_free_memory();
    let _ = std::fs::write("/proc/self/clear_refs", "5");
    Some(peak)
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
        // a step listed under a stage is part of its time, not more of it
        p.add_step("basis", "expansion", 4.0);
        p.add("basis expansion", 0.5);
        assert!(p.is_step("basis: expansion") && !p.is_step("basis expansion"));
        assert!(!p.is_step("basis") && !p.is_step("basis: "));
        assert!((p.total_s() - 6.5).abs() < 1e-15);
        q.extend_prefixed("sweep: ", &p);
        assert!(q.is_step("sweep: basis: expansion"));
        assert!((q.total_s() - 12.5).abs() < 1e-15);
    }

    #[test]
    fn the_machine_is_read_from_proc_texts() {
        let cpuinfo = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD  EPYC 9B14\n";
        assert_eq!(cpuinfo_model(cpuinfo).as_deref(), Some("AMD EPYC 9B14"));
        assert_eq!(cpuinfo_model("processor\t: 0\n"), None);
        let meminfo = "MemTotal:       25165824 kB\nMemFree:  1 kB\n";
        assert_eq!(meminfo_kib(meminfo, "MemTotal:"), Some(25_165_824.0));
        let m = Machine {
            cpu: "AMD EPYC 9B14".into(),
            cores: 2,
            memory_gib: Some(24.0),
        };
        assert_eq!(m.to_string(), "AMD EPYC 9B14, 2 cores, 24 GiB");
        assert!(Machine::here().cores >= 1);
    }

    #[test]
    fn stage_peaks_are_kept_and_tabled() {
        let mut p = Profile::new();
        p.add_with_peak("model", 2.0, Some(900.0));
        p.add_with_peak("sweep", 4.0, Some(1500.0));
        p.add_with_peak("sweep", 1.0, Some(1200.0));
        p.add("report", 0.5);
        assert_eq!(p.stages[1].peak_rss_mb, Some(1500.0));
        assert_eq!(p.stages[2].peak_rss_mb, None);
        assert_eq!(p.peak_rss_mb(), Some(1500.0));
        let md = p.markdown(10.0);
        assert!(md.contains("| peak RSS (MB) |"), "{md}");
        assert!(md.contains("| sweep | 2 | 5.0 | 50 % | 1500 |"), "{md}");
        assert!(md.contains("| report | 1 | 0.5 | 5 % | - |"), "{md}");
        // without measured peaks the table keeps four columns
        assert!(!Profile::new().markdown(1.0).contains("peak"));
    }

    #[test]
    fn a_stage_peak_sees_memory_freed_before_it_ends() {
        if !std::path::Path::new("/proc/self/clear_refs").exists() {
            return;
        }
        // 256 MB touched and freed inside the stage: its peak holds them
        let _ = take_peak_rss_mb();
        let before = peak_rss_mb().unwrap();
        let big = vec![1u8; 256 << 20];
        std::hint::black_box(&big);
        drop(big);
        let stage = take_peak_rss_mb().unwrap();
        assert!(
            stage >= before + 200.0,
            "stage peak {stage} MB, before {before} MB"
        );
    }

    #[test]
    fn peak_memory_is_positive_on_linux() {
        if std::path::Path::new("/proc/self/status").exists() {
            let mb = peak_rss_mb().expect("VmHWM in /proc/self/status");
            assert!(mb > 0.0, "{mb}");
        }
    }
}
