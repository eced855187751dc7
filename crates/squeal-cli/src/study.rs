//! `squeal sweep macro`, `squeal sweep meso` and `squeal merge`: the paper's contact-zone
//! studies (sections 3.1 and 3.2) as resumable, shardable, parallel runs. The library side
//! (cases, records, resume, shards, merge, summaries) is `squeal_analysis::study`; this
//! module turns options into a study definition, shows progress and draws the charts
//! (`study_charts`).

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use squeal_analysis::study::{
    self, parse_list, parse_region, Axis, MacroSpec, MesoSpec, Progress, RunOptions, Shard,
    SolveSpec, StudyDef, StudyDir, StudySpec, Summary,
};
use squeal_core::Registry;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// The paper's patch sides (m), `paper-data.toml` `[mesoscopic.coupling_2]` (2100 Hz).
pub const PAPER_PATCHES_COUPLING_2: &str = "0.0004,0.0006,0.0008,0.0010,0.0012,0.0014,0.0016";
/// The paper's patch sides (m), `paper-data.toml` `[mesoscopic.coupling_1]` (3500 Hz).
pub const PAPER_PATCHES_COUPLING_1: &str = "0.0005,0.0010,0.0015,0.0020,0.0025,0.0030,0.0035";
/// Region cut into patches for coupling 2 (m from the face corner): the paper gives no
/// numbers, only "medium rectangular zones near the leading edge" (section 3.1): a
/// 10 x 14 mm rectangle on the leading (+x) half, centred radially; on the default scene
/// it is unstable at 2169 Hz (DvR 0.0074, mu = 0.36, `enriched`).
pub const REGION_COUPLING_2: &str = "0.010,0.003,0.010,0.014";
/// Region for coupling 1: "large, near-square zones around the centre": 14 x 14 mm, centred.
pub const REGION_COUPLING_1: &str = "0.003,0.003,0.014,0.014";

/// Options every study shares.
#[derive(clap::Args)]
pub struct StudyOpts {
    /// Reduction basis plugin, or `none` for full order.
    #[arg(long, default_value = "enriched")]
    pub basis: String,
    /// Basis parameters `key=value`.
    #[arg(long = "basis-opt")]
    pub basis_opt: Vec<String>,
    /// Eigen solver plugin; default `arpack`, or `dense` for the reduced problem when a
    /// basis is given.
    #[arg(long)]
    pub eigen: Option<String>,
    /// Frequency band `FMIN:FMAX` (Hz).
    #[arg(long, default_value = "0:5000")]
    pub band: String,
    /// Relative tolerance of the eigen solvers.
    #[arg(long, default_value_t = 1e-10)]
    pub tol: f64,
    /// A mode is unstable when its DvR exceeds this.
    #[arg(long, default_value_t = 1e-6)]
    pub dvr_tol: f64,
    /// Coupling classes (Hz): an unstable mode belongs to the nearest within
    /// --class-width.
    #[arg(long, default_value = "2100,3500")]
    pub classes: String,
    /// Relative half-width of a class.
    #[arg(long, default_value_t = 0.2)]
    pub class_width: f64,
    /// Cases solved in parallel (each worker with its own basis and solver).
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
    /// Continue the study already in --out (finished cases are skipped).
    #[arg(long)]
    pub resume: bool,
    /// Run part K of N of the cases (`K/N`, e.g. a job array index); join the parts with
    /// `squeal merge`.
    #[arg(long)]
    pub shard: Option<String>,
    /// Stop after this many new cases (the rest is left for --resume).
    #[arg(long)]
    pub max_cases: Option<usize>,
    /// Skip the charts (results and summaries only).
    #[arg(long)]
    pub no_charts: bool,
}

/// `squeal sweep macro`.
pub struct MacroArgs<'a> {
    pub scene: Option<&'a str>,
    pub x0: &'a str,
    pub y0: &'a str,
    pub a: &'a str,
    pub b: &'a str,
    pub mu: &'a str,
    pub out: &'a Path,
    pub opts: &'a StudyOpts,
}

/// `squeal sweep meso`.
pub struct MesoArgs<'a> {
    pub scene: Option<&'a str>,
    pub coupling: u8,
    pub region: Option<&'a str>,
    pub patch: Option<&'a str>,
    pub layouts: usize,
    pub fraction: f64,
    pub seed: u64,
    pub mu: &'a str,
    pub out: &'a Path,
    pub opts: &'a StudyOpts,
}

fn solve_spec(o: &StudyOpts) -> Result<SolveSpec> {
    let eigen = o
        .eigen
        .clone()
        .unwrap_or_else(|| if o.basis == "none" { "arpack" } else { "dense" }.to_string());
    let s = SolveSpec {
        basis: o.basis.clone(),
        basis_params: o.basis_opt.clone(),
        eigen,
        modal: "arpack".into(),
        band_hz: crate::parse_band(&o.band)?,
        tol: o.tol,
        dvr_tol: o.dvr_tol,
        classes_hz: parse_list("--classes", &o.classes)?,
        class_width: o.class_width,
    };
    s.check()?;
    Ok(s)
}

fn run_options(o: &StudyOpts) -> Result<RunOptions> {
    Ok(RunOptions {
        jobs: o.jobs,
        shard: o.shard.as_deref().map(Shard::parse).transpose()?,
        resume: o.resume,
        max_cases: o.max_cases,
    })
}

pub fn run_macro(registry: &Registry, a: &MacroArgs<'_>) -> Result<()> {
    let spec = StudySpec::Macro(MacroSpec {
        mu: parse_list("--mu", a.mu)?,
        x0: Axis::parse("--x0", a.x0)?,
        y0: Axis::parse("--y0", a.y0)?,
        a_m: parse_list("--a", a.a)?,
        b_m: parse_list("--b", a.b)?,
    });
    execute(registry, a.scene, spec, a.out, a.opts)
}

pub fn run_meso(registry: &Registry, a: &MesoArgs<'_>) -> Result<()> {
    let (region, patch) = match a.coupling {
        2 => (REGION_COUPLING_2, PAPER_PATCHES_COUPLING_2),
        1 => (REGION_COUPLING_1, PAPER_PATCHES_COUPLING_1),
        c => anyhow::bail!("--coupling: expected 1 (3500 Hz) or 2 (2100 Hz), got {c}"),
    };
    let spec = StudySpec::Meso(MesoSpec {
        mu: parse_list("--mu", a.mu)?,
        region_m: parse_region("--region", a.region.unwrap_or(region))?,
        patch_m: parse_list("--patch", a.patch.unwrap_or(patch))?,
        layouts: a.layouts,
        fraction: a.fraction,
        seed: a.seed,
    });
    execute(registry, a.scene, spec, a.out, a.opts)
}

/// Builds the model and the definition, runs the study with a progress bar, writes the
/// charts and prints the summary.
fn execute(
    registry: &Registry,
    scene_arg: Option<&str>,
    spec: StudySpec,
    out: &Path,
    o: &StudyOpts,
) -> Result<()> {
    let start = Instant::now();
    let solve = solve_spec(o)?;
    let opts = run_options(o)?;
    let (scene, file) = crate::load_scene(scene_arg)?;
    eprintln!("building {file} ...");
    let model = squeal_scene::build(&scene, squeal_scene::BodyKind::All, registry, &file)?;
    let def = StudyDef::new(&file, &scene, &model, spec, solve)?;
    let list = def.cases()?;
    for w in def.warnings(&list) {
        eprintln!("warning: {w}");
    }
    eprintln!(
        "{} DOFs, {} x {} contact pairs; {} cases{}",
        def.dofs,
        def.grid.n[0],
        def.grid.n[1],
        list.cases.len(),
        opts.shard
            .map(|s| format!(" (shard {}/{})", s.k, s.n))
            .unwrap_or_default()
    );
    let bar = Bar::new();
    let dir = StudyDir::new(out);
    let report = study::run(registry, &model, &def, &dir, &opts, &|p| bar.update(p))?;
    bar.finish();
    println!(
        "{} of {} cases in this run's part: {} computed now, {} found done, {} left{}",
        report.shard_cases - report.remaining,
        report.shard_cases,
        report.computed,
        report.resumed,
        report.remaining,
        if report.remaining > 0 {
            " (continue with --resume)"
        } else {
            ""
        }
    );
    print_summary(&report.summary);
    println!(
        "mean per case {:.2} s (basis {:.2}, projection {:.2}, solve {:.2}, expansion {:.2}); \
         wall {:.1} s",
        report.timings.mean.total_s,
        report.timings.mean.basis_s,
        report.timings.mean.projection_s,
        report.timings.mean.solve_s,
        report.timings.mean.expansion_s,
        start.elapsed().as_secs_f64()
    );
    finish_outputs(&dir, &def, o.no_charts)
}

/// `squeal merge DIR... --out DIR`.
pub fn merge(dirs: &[PathBuf], out: &Path, no_charts: bool) -> Result<()> {
    let (def, summary, _) = study::merge(dirs, out)?;
    println!(
        "merged {} directories: {} of {} cases{}",
        dirs.len(),
        summary.cases_done,
        summary.cases,
        if summary.complete {
            ""
        } else {
            " (incomplete: run the missing shards, or --resume them, and merge again)"
        }
    );
    print_summary(&summary);
    finish_outputs(&StudyDir::new(out), &def, no_charts)
}

fn finish_outputs(dir: &StudyDir, def: &StudyDef, no_charts: bool) -> Result<()> {
    if !no_charts {
        let records = dir.records()?;
        match crate::study_charts::draw(&dir.dir, def, &records) {
            Ok(files) => {
                for f in files {
                    println!("wrote {}", f.display());
                }
            }
            Err(e) => eprintln!("warning: charts: {e:#}"),
        }
    }
    println!(
        "wrote {}/{{study.json,results.jsonl,summary.json,timings.jsonl,timings.json}}",
        dir.dir.display()
    );
    Ok(())
}

fn print_summary(s: &Summary) {
    println!(
        "{} of {} cases done, {} unstable ({:.1} %), {} failed, max backward error {:.1e}",
        s.cases_done,
        s.cases,
        s.unstable_cases,
        100.0 * s.unstable_fraction,
        s.failed,
        s.max_backward_error
    );
    for m in &s.by_mu {
        let classes: Vec<String> = m
            .classes
            .iter()
            .map(|c| {
                format!(
                    "~{:.0} Hz: {} ({:.1} %)",
                    c.class_hz,
                    c.cases,
                    100.0 * c.unstable_fraction
                )
            })
            .collect();
        println!(
            "  mu {:.3}: {} cases, {} unstable; {}; other {}",
            m.mu,
            m.cases,
            m.unstable,
            classes.join(", "),
            m.unclassified
        );
    }
    if !s.by_patch.is_empty() {
        println!(
            "  {:>6} {:>9} {:>7} {:>10}  per class",
            "mu", "patch mm", "done", "unstable"
        );
        for p in &s.by_patch {
            let classes: Vec<String> = p
                .classes
                .iter()
                .map(|c| format!("{:.0} Hz {:.1} %", c.class_hz, 100.0 * c.unstable_fraction))
                .collect();
            println!(
                "  {:>6.3} {:>9.3} {:>7} {:>9.1}%  {}",
                p.mu,
                p.patch_m * 1e3,
                p.done,
                100.0 * p.unstable_fraction,
                classes.join(", ")
            );
        }
    }
}

/// The progress display: an indicatif bar on a terminal, one line per case otherwise
/// (hidden bar when stderr is not a terminal or `CI=true`).
struct Bar {
    bar: ProgressBar,
    visible: bool,
    state: Mutex<(usize, usize, Instant)>,
}

impl Bar {
    fn new() -> Self {
        let ci = std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
        let visible = std::io::stderr().is_terminal() && !ci;
        let bar = ProgressBar::new(0);
        if visible {
            bar.set_style(
                ProgressStyle::with_template(
                    "{bar:30} {pos}/{len} cases  {per_sec}  ETA {eta}  {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
        } else {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        Self {
            bar,
            visible,
            state: Mutex::new((0, 0, Instant::now())),
        }
    }

    fn update(&self, p: Progress<'_>) {
        let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match p {
            Progress::Start {
                resumed,
                todo,
                shard,
            } => {
                *st = (resumed, todo, Instant::now());
                self.bar.set_length(todo as u64);
                self.bar.reset_eta();
                if resumed > 0 {
                    eprintln!("resuming: {resumed} of {shard} cases already done, {todo} to run");
                }
            }
            Progress::Case { done, record } => {
                let unstable: Vec<String> = record
                    .unstable
                    .iter()
                    .map(|m| format!("{:.0} Hz DvR {:.4}", m.freq_hz, m.dvr))
                    .collect();
                let what = match &record.error {
                    Some(e) => format!("FAILED: {e}"),
                    None if unstable.is_empty() => "stable".into(),
                    None => unstable.join(", "),
                };
                if self.visible {
                    self.bar.set_position(done as u64);
                    self.bar.set_message(format!("{}: {what}", record.case.id));
                } else {
                    let (_, todo, t0) = *st;
                    let el = t0.elapsed().as_secs_f64();
                    let rate = done as f64 / el.max(1e-9);
                    let eta = (todo - done.min(todo)) as f64 / rate.max(1e-12);
                    eprintln!(
                        "[{done}/{todo}] {} ({} pairs): {what}  ({:.2} cases/min, ETA {})",
                        record.case.id,
                        record.case.pairs,
                        rate * 60.0,
                        hms(eta)
                    );
                }
            }
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

fn hms(s: f64) -> String {
    let s = s.round() as u64;
    format!("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60)
}

/// `squeal merge` inputs: each must be a study directory.
pub fn check_dirs(dirs: &[PathBuf]) -> Result<()> {
    if dirs.is_empty() {
        anyhow::bail!("DIRS: expected at least one study directory to merge");
    }
    for d in dirs {
        if !d.join("study.json").is_file() {
            return Err(anyhow::anyhow!(
                "{}: not a study directory (no study.json): expected the --out of a `squeal sweep macro|meso` run",
                d.display()
            ))
            .context("squeal merge");
        }
    }
    Ok(())
}
