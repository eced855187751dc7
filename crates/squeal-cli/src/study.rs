//! `squeal sweep macro`, `squeal sweep meso` and `squeal merge`: the paper's contact-zone
//! studies (sections 3.1 and 3.2) as resumable, shardable, parallel runs. The library side
//! (cases, records, resume, shards, merge, summaries) is `squeal_analysis::study`; this
//! module turns options into a study definition, shows progress and draws the charts
//! (`study_charts`).

use anyhow::{Context, Result};
use squeal_analysis::study::{
    self, parse_list, parse_region, Axis, MacroSpec, MesoSpec, RunOptions, Shard, SolveSpec,
    StudyDef, StudyDir, StudySpec, Summary,
};
use squeal_core::Registry;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The paper's patch sides (m), `paper-data.toml` `[mesoscopic.coupling_2]` (2100 Hz).
pub const PAPER_PATCHES_COUPLING_2: &str = "0.0004,0.0006,0.0008,0.0010,0.0012,0.0014,0.0016";
/// The paper's patch sides (m), `paper-data.toml` `[mesoscopic.coupling_1]` (3500 Hz).
pub const PAPER_PATCHES_COUPLING_1: &str = "0.0005,0.0010,0.0015,0.0020,0.0025,0.0030,0.0035";
/// Region cut into patches for coupling 2 (m from the face corner): the paper gives no
/// numbers, only "medium rectangular zones near the leading edge" (section 3.1). This is
/// the default rig's own coupling-2 zone of the macro grid (`docs/results/macro-grid`,
/// mu 0.36): 12 x 12 mm from x = 8 mm (the leading +x side), centred radially.
pub const REGION_COUPLING_2: &str = "0.008,0.004,0.012,0.012";
/// Region for coupling 1: "large, near-square zones around the centre"; on the default rig
/// only zones that span the face in x give coupling 1 (macro grid): the whole face.
pub const REGION_COUPLING_1: &str = "0,0,0.020,0.020";

/// Options every study shares.
#[derive(clap::Args)]
pub struct StudyOpts {
    #[command(flatten)]
    pub method: crate::opts::MethodArgs,
    /// Coupling classes (Hz): an unstable mode belongs to the nearest within
    /// --class-width.
    #[arg(long, default_value = "2100,3500")]
    pub classes: String,
    /// Relative half-width of a class.
    #[arg(long, default_value_t = 0.2)]
    pub class_width: f64,
    /// Cases solved in parallel (each worker with its own basis and solver; >= 1).
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
#[derive(clap::Args)]
pub struct MacroArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Zone starts along x (m), or `centred`.
    #[arg(long, default_value = "centred")]
    x0: String,
    /// Zone starts along y (m), or `centred`.
    #[arg(long, default_value = "centred")]
    y0: String,
    /// Zone lengths along x, the sliding direction (m).
    #[arg(long, default_value = "0.004:0.02:0.002")]
    a: String,
    /// Zone widths along y (m); the paper's Figure 12 uses 14.2 mm.
    #[arg(long, default_value = "0.0142")]
    b: String,
    /// Friction coefficients (the paper's 0.36 and 0.43).
    #[arg(long, default_value = "0.36,0.43")]
    mu: String,
    #[command(flatten)]
    opts: StudyOpts,
    /// Output directory.
    #[arg(long, default_value = "out/sweep-macro")]
    out: PathBuf,
}

impl MacroArgs {
    /// Runs (or resumes) the study.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        let spec = StudySpec::Macro(MacroSpec {
            mu: parse_list("--mu", &self.mu)?,
            x0: Axis::parse("--x0", &self.x0)?,
            y0: Axis::parse("--y0", &self.y0)?,
            a_m: parse_list("--a", &self.a)?,
            b_m: parse_list("--b", &self.b)?,
        });
        execute(
            registry,
            &self.scene,
            spec,
            &self.out,
            &self.opts,
            "sweep macro",
        )
    }
}

/// `squeal sweep meso`.
#[derive(clap::Args)]
pub struct MesoArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Which coupling's defaults: 2 (2100 Hz: region 0.008,0.004,0.012,0.012, patches
    /// 0.4-1.6 mm) or 1 (3500 Hz: region 0,0,0.020,0.020, patches 0.5-3.5 mm).
    #[arg(long, default_value_t = 2)]
    coupling: u8,
    /// Region cut into patches, `x0,y0,a,b` (m from the pin face's corner).
    #[arg(long)]
    region: Option<String>,
    /// Patch sides (m), a list.
    #[arg(long)]
    patch: Option<String>,
    /// Random layouts per patch size.
    #[arg(long, default_value_t = 200)]
    layouts: usize,
    /// Fraction of the patches in contact in each layout, in (0, 1] (the paper does not
    /// give it; `docs/studies.md`).
    #[arg(long, default_value_t = 0.7)]
    fraction: f64,
    /// Base seed of the layouts.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Friction coefficients.
    #[arg(long, default_value = "0.36")]
    mu: String,
    #[command(flatten)]
    opts: StudyOpts,
    /// Output directory.
    #[arg(long, default_value = "out/sweep-meso")]
    out: PathBuf,
}

impl MesoArgs {
    /// Runs (or resumes) the study.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        let (region, patch) = match self.coupling {
            2 => (REGION_COUPLING_2, PAPER_PATCHES_COUPLING_2),
            1 => (REGION_COUPLING_1, PAPER_PATCHES_COUPLING_1),
            c => anyhow::bail!("--coupling {c}: expected 1 (3500 Hz) or 2 (2100 Hz)"),
        };
        let spec = StudySpec::Meso(MesoSpec {
            mu: parse_list("--mu", &self.mu)?,
            region_m: parse_region("--region", self.region.as_deref().unwrap_or(region))?,
            patch_m: parse_list("--patch", self.patch.as_deref().unwrap_or(patch))?,
            layouts: self.layouts,
            fraction: self.fraction,
            seed: self.seed,
        });
        execute(
            registry,
            &self.scene,
            spec,
            &self.out,
            &self.opts,
            "sweep meso",
        )
    }
}

/// `squeal merge`.
#[derive(clap::Args)]
pub struct MergeArgs {
    /// Study directories (the --out of each shard).
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Merged directory (must not be one of the inputs).
    #[arg(long)]
    out: PathBuf,
    /// Skip the charts.
    #[arg(long)]
    no_charts: bool,
}

impl MergeArgs {
    /// Merges the shards.
    pub fn run(&self) -> Result<()> {
        check_dirs(&self.dirs)?;
        merge(&self.dirs, &self.out, self.no_charts)
    }
}

fn solve_spec(o: &StudyOpts, scene: &squeal_scene::Scene) -> Result<SolveSpec> {
    let m = &o.method;
    let s = SolveSpec {
        basis: m.basis.clone(),
        basis_params: m.basis_opt.clone(),
        eigen: m.eigen(),
        modal: squeal_analysis::pipeline::MODAL_SOLVER.into(),
        band_hz: m.band_of(scene)?,
        tol: m.tol,
        dvr_margin: m.dvr_margin,
        classes_hz: parse_list("--classes", &o.classes)?,
        class_width: o.class_width,
    };
    s.check().map_err(crate::study_flags::flags)?;
    Ok(s)
}

fn run_options(o: &StudyOpts) -> Result<RunOptions> {
    Ok(RunOptions {
        jobs: o.jobs,
        shard: o
            .shard
            .as_deref()
            .map(Shard::parse)
            .transpose()
            .map_err(crate::study_flags::flags)?,
        resume: o.resume,
        max_cases: o.max_cases,
    })
}

/// Builds the model and the definition, runs the study with a progress bar, writes the
/// charts and prints the summary.
fn execute(
    registry: &Registry,
    scene_arg: &crate::opts::SceneArg,
    spec: StudySpec,
    out: &Path,
    o: &StudyOpts,
    command: &str,
) -> Result<()> {
    let start = Instant::now();
    o.method.check(registry)?;
    if o.jobs == 0 {
        anyhow::bail!("--jobs 0: expected at least 1 worker");
    }
    let opts = run_options(o)?;
    let (scene, file) = scene_arg.load()?;
    let solve = solve_spec(o, &scene)?;
    crate::opts::claim_out(out, command)?;
    crate::opts::set_resume_hint(out);
    eprintln!("building {file} ...");
    let model = squeal_scene::build(&scene, squeal_scene::BodyKind::All, registry, &file)?;
    let def =
        StudyDef::new(&file, &scene, &model, spec, solve).map_err(crate::study_flags::flags)?;
    let list = def.cases().map_err(crate::study_flags::flags)?;
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
    let bar = crate::study_progress::Bar::new();
    let dir = StudyDir::new(out);
    let report = study::run(registry, &model, &def, &dir, &opts, &|p| bar.update(p))
        .map_err(crate::study_flags::flags)?;
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
    if report.computed > 0 {
        println!(
            "\nwhere this run's time went (case stages summed over the workers):\n{}peak \
             resident memory: {}",
            report.profile.markdown(start.elapsed().as_secs_f64()),
            squeal_analysis::profile::peak_rss_mb()
                .map_or("not measured".into(), |m| format!("{m:.0} MB"))
        );
    }
    finish_outputs(&dir, &def, o.no_charts)
}

/// `squeal merge DIR... --out DIR`.
pub fn merge(dirs: &[PathBuf], out: &Path, no_charts: bool) -> Result<()> {
    let (def, summary, _) = study::merge(dirs, out).map_err(crate::study_flags::flags)?;
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
        "{} of {} cases done, {} unstable ({:.1} %, 95 % interval {:.1}-{:.1} %), {} failed, \
         max backward error {:.1e}",
        s.cases_done,
        s.cases,
        s.unstable_cases,
        100.0 * s.unstable_fraction,
        100.0 * s.unstable_ci95[0],
        100.0 * s.unstable_ci95[1],
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
            "  {:>6} {:>9} {:>7} {:>10} {:>13}  per class",
            "mu", "patch mm", "done", "unstable", "95 % interval"
        );
        for p in &s.by_patch {
            let classes: Vec<String> = p
                .classes
                .iter()
                .map(|c| {
                    format!(
                        "{:.0} Hz {:.1} % ({:.1}-{:.1})",
                        c.class_hz,
                        100.0 * c.unstable_fraction,
                        100.0 * c.unstable_ci95[0],
                        100.0 * c.unstable_ci95[1]
                    )
                })
                .collect();
            println!(
                "  {:>6.3} {:>9.3} {:>7} {:>9.1}% {:>6.1}-{:<5.1}%  {}",
                p.mu,
                p.patch_m * 1e3,
                p.done,
                100.0 * p.unstable_fraction,
                100.0 * p.unstable_ci95[0],
                100.0 * p.unstable_ci95[1],
                classes.join(", ")
            );
        }
    }
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
