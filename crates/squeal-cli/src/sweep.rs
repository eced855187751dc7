//! `squeal sweep mu`: the friction-coefficient sweep with mode tracking, coupling
//! detection, CSV/JSON outputs and the paper's Figure 5 and 7 charts; `squeal sweep
//! param`: the same for the parameter of a parametric operator directory.

use anyhow::{Context, Result};
use serde::Serialize;
use squeal_analysis::family::{reference_modes, run_family_sweep, Parametric, SweepCoupling};
use squeal_analysis::mu_sweep::{
    mu_list, run_sweep, value_list, CouplingReport, MuSweep, MuSweepSettings,
};
use squeal_analysis::pipeline::{FreeModes, Method, Prepared};
use squeal_analysis::profile::{peak_rss_mb, Profile, StageTime};
use squeal_analysis::sweep::{Branch, Checkpoint, SweepPoint};
use squeal_core::{EigenParams, Registry};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `squeal sweep`: the parameter sweeps.
#[derive(clap::Subcommand)]
pub enum SweepCmd {
    /// Friction-coefficient sweep: equilibrium, operator (rebuilt when the contact set
    /// changes), modes, tracking by MAC, couplings; sweep.csv, summary.json and charts.
    /// Finished points are kept in DIR/sweep.partial.jsonl: --resume continues a killed run.
    #[command(allow_negative_numbers = true)]
    Mu(MuArgs),
    /// Sweep of the parameter of a parametric operator directory (operator.toml with
    /// `parameter = "W"`, docs/operators.md) at a fixed mu: the operator at each value,
    /// modes, tracking by MAC on the real modes of its symmetric part at the first value,
    /// couplings; the outputs, progress and --resume of `sweep mu`.
    #[command(allow_negative_numbers = true)]
    Param(ParamArgs),
    /// Macroscopic effective zones (paper section 3.1): every rectangle (x0, y0, a, b) of
    /// the grid of lists, all its pairs closed and sliding, at each mu. Lists are
    /// comma-separated values and FROM:TO:STEP ranges, in m from the pin face's corner
    /// (x along sliding, y radial). Writes study.json, results.jsonl, summary.json,
    /// timings.jsonl, timings.json and charts; resumable (--resume), shardable (--shard).
    #[command(allow_negative_numbers = true)]
    Macro(crate::study::MacroArgs),
    /// Mesoscopic plateaus (paper section 3.2): a fixed region of the pin face cut into
    /// square patches, seeded random subsets of them in contact (all their pairs closed
    /// and sliding), --layouts per patch size. Defaults: the paper's patch sizes and mu
    /// for --coupling 2 (2100 Hz) or 1 (3500 Hz); those patches need a contact grid of
    /// 0.2 mm / 0.5 mm in the region (mesh.contact_refinement; scenes/pin-on-disc-meso.toml
    /// and scenes/pin-on-disc-meso-c1.toml): on the default scene (1 mm) give --patch.
    /// Same outputs, resume and shards as `sweep macro`.
    #[command(allow_negative_numbers = true)]
    Meso(crate::study::MesoArgs),
}

impl SweepCmd {
    /// Runs the chosen sweep.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        match self {
            SweepCmd::Mu(a) => a.run(registry),
            SweepCmd::Param(a) => a.run(registry),
            SweepCmd::Macro(a) => a.run(registry),
            SweepCmd::Meso(a) => a.run(registry),
        }
    }
}

/// `squeal sweep mu`.
#[derive(clap::Args)]
pub struct MuArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// First friction coefficient.
    #[arg(long, default_value_t = 0.0)]
    from: f64,
    /// Last friction coefficient.
    #[arg(long, default_value_t = 0.8)]
    to: f64,
    /// Step (the paper's resolution is 0.01).
    #[arg(long, default_value_t = 0.01)]
    step: f64,
    #[command(flatten)]
    method: crate::opts::MethodArgs,
    #[command(flatten)]
    contact: crate::opts::ContactArgs,
    /// Condition numbers and forward error estimates of full-order modes also above
    /// 1000 DOFs (one extra factorization per mode); reduced solves always have them.
    #[arg(long)]
    condition: bool,
    /// Continue the sweep already in --out (its finished points are kept).
    #[arg(long)]
    resume: bool,
    /// Output directory.
    #[arg(long, default_value = "out/sweep-mu")]
    out: PathBuf,
}

impl MuArgs {
    /// Runs the sweep and prints its couplings.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        self.method.check(registry)?;
        self.contact.check(registry)?;
        mus(self.from, self.to, self.step)?;
        let band = self
            .method
            .band
            .as_deref()
            .map(crate::opts::parse_band)
            .transpose()?;
        let eigen = self.method.eigen();
        let args = Args {
            scene: self.scene.as_deref(),
            from: self.from,
            to: self.to,
            step: self.step,
            eigen: &eigen,
            basis: &self.method.basis,
            basis_opts: &self.method.basis_opt,
            band,
            equilibrium: &self.contact.equilibrium,
            law: &self.contact.law,
            dvr_tol: self.method.dvr_tol,
            tol: self.method.tol,
            condition: self.condition,
            resume: self.resume,
            out: &self.out,
        };
        let s = run(registry, &args)?;
        println!(
            "{} points ({} contact sets), {} couplings, max backward error {:.1e}, max error \
             bound {}, {:.1} s",
            s.points,
            s.rebuilds,
            s.couplings.len(),
            s.max_backward_error,
            crate::stability::sci(s.max_error_bound),
            s.time_s
        );
        print_couplings(
            "mu",
            s.couplings
                .iter()
                .map(|c| (c.freq_hz, c.mu_from, c.mu_to, c.max_dvr, &c.partners[..])),
            &self.out,
        );
        Ok(())
    }
}

/// `squeal sweep param`.
#[derive(clap::Args)]
pub struct ParamArgs {
    /// Parametric operator directory (operator.toml with `format =
    /// "squeal-parametric-operator"`, see docs/operators.md).
    #[arg(long)]
    operator: PathBuf,
    /// The parameter to sweep: the name the operator declares.
    #[arg(long)]
    param: String,
    /// First value.
    #[arg(long)]
    from: f64,
    /// Last value.
    #[arg(long)]
    to: f64,
    /// Step.
    #[arg(long)]
    step: f64,
    /// Friction coefficient of every point (required when the operator has friction
    /// parts FM, FC or FK).
    #[arg(long)]
    mu: Option<f64>,
    #[command(flatten)]
    method: crate::opts::MethodArgs,
    /// Condition numbers and forward error estimates of full-order modes also above
    /// 1000 DOFs (one extra factorization per mode); reduced solves always have them.
    #[arg(long)]
    condition: bool,
    /// Continue the sweep already in --out (its finished points are kept).
    #[arg(long)]
    resume: bool,
    /// Output directory.
    #[arg(long, default_value = "out/sweep-param")]
    out: PathBuf,
}

/// `summary.json` of `squeal sweep param`.
#[derive(Serialize)]
pub struct ParamSummary {
    pub operator: String,
    pub units: &'static str,
    /// The swept parameter's name.
    pub parameter: String,
    /// `[from, to, step]` as given.
    pub range: [f64; 3],
    pub mu: f64,
    pub band_hz: [f64; 2],
    pub eigen: String,
    pub basis: String,
    pub dofs: usize,
    pub dvr_tol: f64,
    pub points: usize,
    pub max_basis_size: usize,
    pub max_backward_error: f64,
    /// Worst `error_bound` of every point's modes (null: not computed).
    pub max_error_bound: f64,
    /// What the signatures of tracking are taken on.
    pub reference: String,
    pub reference_modes: usize,
    pub time_s: f64,
    /// Couplings: frequency at the largest DvR, first and last unstable value, largest
    /// DvR, branches, and the reference modes the unstable mode is made of.
    pub couplings: Vec<SweepCoupling>,
}

impl ParamArgs {
    /// Checks every option, runs the sweep and prints its couplings.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        let start = Instant::now();
        self.method.check(registry)?;
        let values = value_list(self.from, self.to, self.step)
            .map_err(|e| anyhow::anyhow!("--from/--to/--step: {e}"))?;
        if let Some(mu) = self.mu {
            crate::opts::check_mu("--mu", mu)?;
        }
        let band = self.method.band(crate::opts::OPERATOR_BAND_HZ)?;
        let name = self.param.as_str();
        let flag = format!("--param {name}");
        let dir = &self.operator;
        let family_op = crate::opts::read_parametric(dir, name, &flag)?;
        if let Some((lo, hi)) = family_op.range() {
            let last = *values.last().expect("a value list is never empty");
            if values[0] < lo || last > hi {
                anyhow::bail!(
                    "--from/--to: {name} = {} ... {last} leaves the range [{lo}, {hi}] the \
                     operator in {} declares",
                    values[0],
                    dir.display()
                );
            }
        }
        let first = family_op
            .at(values[0])
            .map_err(|e| anyhow::anyhow!("--from {}: {e}", values[0]))?;
        first.check_pencil().map_err(|e| {
            anyhow::anyhow!(
                "--operator {} at {name} = {}: {e}",
                dir.display(),
                values[0]
            )
        })?;
        let frictional = first.fm.compute_nnz() > 0
            || first.fk.compute_nnz() > 0
            || first.fc.as_ref().is_some_and(|f| f.compute_nnz() > 0);
        let mu = match self.mu {
            Some(mu) => mu,
            None if frictional => anyhow::bail!(
                "--mu: required, the operator in {} has friction parts (X - mu F_X)",
                dir.display()
            ),
            None => 0.0,
        };
        // the points depend on these (not on the value list, except its first value,
        // where the reference modes of tracking are taken)
        let toml = std::fs::read_to_string(dir.join("operator.toml")).unwrap_or_default();
        let mut inputs = serde_json::json!({
            "operator": dir.display().to_string(),
            "operator_toml": toml,
            "parameter": name,
            "reference_value": values[0],
            "mu": mu,
            "basis": self.method.basis,
            "basis_opts": format!("{:?}", self.method.basis_params()?),
            "eigen": self.method.eigen(),
            "band_hz": band,
            "tol": self.method.tol,
            "squeal": env!("CARGO_PKG_VERSION"),
        });
        if self.condition {
            inputs["condition"] = true.into();
        }
        let out = &self.out;
        let (ckpt, done) = open_checkpoint(
            out,
            "sweep param",
            "a parameter sweep",
            self.resume,
            &inputs,
        )?;
        let reference = reference_modes(registry, &first, "arpack", 1.5 * band[1])
            .with_context(|| format!("--operator {} at {name} = {}", dir.display(), values[0]))?;
        let mut method = Method::new(
            registry,
            &self.method.basis,
            &self.method.basis_params()?,
            &self.method.eigen(),
            "arpack",
            EigenParams {
                fmin_hz: band[0],
                fmax_hz: band[1],
                tol: self.method.tol,
                ..EigenParams::default()
            },
        )?;
        method.set_condition(self.condition);
        let mut eta = crate::opts::Eta::new(values.len(), done);
        let dvr_tol = self.method.dvr_tol;
        let mut family = Parametric::new(&family_op, mu);
        let sweep = run_family_sweep(
            &mut family,
            &values,
            &mut method,
            &reference,
            dvr_tol,
            &[],
            Some(&ckpt),
            |p| {
                let unstable = p.modes.iter().filter(|m| m.dvr > dvr_tol).count();
                eprintln!(
                    "{} {name} {}: {} modes, {} unstable, max error bound {}, solve {:.2} s",
                    eta.tick(),
                    p.value,
                    p.modes.len(),
                    unstable,
                    crate::stability::sci(crate::stability::worst(
                        &p.modes.iter().map(|m| m.error_bound).collect::<Vec<_>>()
                    )),
                    p.times_s[2]
                );
            },
        )
        .with_context(|| format!("the sweep of {name}"))?;
        let axis = Axis::param(name);
        let points = &sweep.points;
        write_csv(
            &out.join("sweep.csv"),
            name,
            points,
            &sweep.branches,
            dvr_tol,
        )?;
        charts(out, &axis, points, &sweep.branches, dvr_tol)?;
        mac_charts(out, &axis, &sweep.couplings)?;
        let summary = ParamSummary {
            operator: dir.display().to_string(),
            units: "SI: frequencies in Hz, DvR = Re/Im (dimensionless), times in s",
            parameter: name.to_string(),
            range: [self.from, self.to, self.step],
            mu,
            band_hz: band,
            eigen: self.method.eigen(),
            basis: self.method.basis.clone(),
            dofs: first.dim(),
            dvr_tol,
            points: points.len(),
            max_basis_size: points.iter().map(|p| p.basis_size).max().unwrap_or(0),
            max_backward_error: points
                .iter()
                .flat_map(|p| p.modes.iter().map(|m| m.backward_error))
                .fold(0.0, f64::max),
            max_error_bound: max_error_bound(points),
            reference: reference_text(name, values[0], &reference),
            reference_modes: reference.freq_hz.len(),
            time_s: start.elapsed().as_secs_f64(),
            couplings: sweep.couplings.clone(),
        };
        std::fs::write(
            out.join("summary.json"),
            serde_json::to_string_pretty(&summary)?,
        )?;
        println!(
            "{} points of {name} at mu = {mu}, {} couplings, max backward error {:.1e}, max \
             error bound {}, {:.1} s",
            summary.points,
            summary.couplings.len(),
            summary.max_backward_error,
            crate::stability::sci(summary.max_error_bound),
            summary.time_s
        );
        print_couplings(
            name,
            summary
                .couplings
                .iter()
                .map(|c| (c.freq_hz, c.from, c.to, c.max_dvr, &c.partners[..])),
            out,
        );
        Ok(())
    }
}

/// Prints the couplings of a sweep over `name` (frequency, first and last unstable
/// value, largest DvR, partner branches), one a line, then the files written to `out`.
fn print_couplings<'a>(
    name: &str,
    couplings: impl Iterator<Item = (f64, f64, f64, f64, &'a [usize])>,
    out: &Path,
) {
    for (freq_hz, from, to, max_dvr, partners) in couplings {
        println!(
            "  {freq_hz:>8.1} Hz  {name} {from}-{to}  max DvR {max_dvr:.4}  partners \
             {partners:?}"
        );
    }
    println!(
        "wrote {}/{{sweep.csv,summary.json,*.svg,*.png}}",
        out.display()
    );
}

/// What the reference modes of a parameter sweep are.
fn reference_text(name: &str, value: f64, reference: &FreeModes) -> String {
    format!(
        "{} real modes ({:.1} to {:.1} Hz) of the symmetric parts of M and K at {name} = \
         {value} (no damping, gyroscopic, circulatory or friction term)",
        reference.freq_hz.len(),
        reference.freq_hz.first().copied().unwrap_or(0.0),
        reference.freq_hz.last().copied().unwrap_or(0.0),
    )
}

/// Inputs of a sweep.
pub struct Args<'a> {
    pub scene: Option<&'a str>,
    pub from: f64,
    pub to: f64,
    pub step: f64,
    pub eigen: &'a str,
    pub basis: &'a str,
    pub basis_opts: &'a [String],
    /// `None`: the scene's `study.band_hz`.
    pub band: Option<[f64; 2]>,
    pub equilibrium: &'a str,
    pub law: &'a str,
    pub dvr_tol: f64,
    pub tol: f64,
    /// Condition numbers of full-order modes above the solvers' automatic size.
    pub condition: bool,
    /// Continue the sweep in `out` (else a directory holding one is refused).
    pub resume: bool,
    pub out: &'a Path,
}

/// `summary.json`.
#[derive(Serialize)]
pub struct Summary {
    pub scene: String,
    pub units: &'static str,
    pub mu: [f64; 3],
    pub band_hz: [f64; 2],
    pub eigen: String,
    pub basis: String,
    pub equilibrium: String,
    pub law: String,
    pub dofs: usize,
    pub dvr_tol: f64,
    pub points: usize,
    pub rebuilds: usize,
    pub max_basis_size: usize,
    pub max_backward_error: f64,
    /// Worst forward error estimate (`error_bound`) of every point's modes (null: not
    /// computed).
    pub max_error_bound: f64,
    pub free_interface_modes: usize,
    pub time_s: f64,
    pub couplings: Vec<CouplingReport>,
    /// Where the time went (points read back from a checkpoint excluded).
    pub stages: Vec<StageTime>,
    /// Peak resident memory of the process (MB).
    pub peak_rss_mb: Option<f64>,
}

/// The range rule of every mu list (`--from/--to/--step`).
pub fn mus(from: f64, to: f64, step: f64) -> Result<Vec<f64>> {
    mu_list(from, to, step).map_err(|e| anyhow::anyhow!("--from/--to/--step: {e}"))
}

pub fn run(registry: &Registry, a: &Args<'_>) -> Result<Summary> {
    let mus = mus(a.from, a.to, a.step)?;
    let (scene, file) = crate::opts::load_scene(a.scene)?;
    let band = a.band.unwrap_or(scene.study.band_hz);
    crate::opts::check_band_against(band, &scene)?;
    let prep = Prepared::new(registry, scene, &file)?;
    let mut setup = Profile::new();
    setup.add("model build", prep.build_time_s);
    setup.add("contact condensation", prep.condensation.time_s);
    let settings = MuSweepSettings {
        basis_params: crate::opts::parse_params(a.basis_opts)?,
        eigen: a.eigen.into(),
        equilibrium: a.equilibrium.into(),
        law: a.law.into(),
        dvr_tol: a.dvr_tol,
        tol: a.tol,
        condition: a.condition,
        ..MuSweepSettings::new(mus, a.basis, band)
    };
    Ok(run_on(
        registry,
        &prep,
        &settings,
        [a.from, a.to, a.step],
        a.out,
        a.resume,
        &setup,
    )?
    .0)
}

/// Runs the sweep `settings` of `prep` into `out` (checkpoint, CSV, charts, summary):
/// the command's work, shared with `validate`. `range` is `[from, to, step]` as given;
/// `setup` holds the stages run before (building `prep`), reported first.
pub fn run_on(
    registry: &Registry,
    prep: &Prepared,
    settings: &MuSweepSettings,
    range: [f64; 3],
    out: &Path,
    resume: bool,
    setup: &Profile,
) -> Result<(Summary, MuSweep)> {
    let start = Instant::now();
    // the points depend on these (not on the mu list: shards and extensions share them)
    let mut inputs = serde_json::json!({
        "scene": prep.scene.to_toml(),
        "basis": settings.basis,
        "basis_opts": format!("{:?}", settings.basis_params),
        "eigen": settings.eigen,
        "equilibrium": settings.equilibrium,
        "law": settings.law,
        "band_hz": settings.band_hz,
        "tol": settings.tol,
        "squeal": env!("CARGO_PKG_VERSION"),
    });
    if settings.condition {
        inputs["condition"] = true.into();
    }
    let (ckpt, done) = open_checkpoint(out, "sweep mu", "a mu sweep", resume, &inputs)?;
    let mut eta = crate::opts::Eta::new(settings.mus.len(), done);
    let dvr_tol = settings.dvr_tol;
    if done < settings.mus.len() {
        eprintln!(
            "free modes of the model (and the free-interface synthesis a basis such as `cms` \
             works from) up to the needed cutoff: {} DOFs, the longest setup stage",
            prep.model.dofs.n_free()
        );
    }
    let sweep = run_sweep(registry, prep, settings, Some(&ckpt), |p| {
        let unstable = p.modes.iter().filter(|m| m.dvr > dvr_tol).count();
        eprintln!(
            "{} mu {:.3}: {} modes, {} unstable, {} active pairs{}, solve {:.2} s",
            eta.tick(),
            p.mu,
            p.modes.len(),
            unstable,
            p.active_pairs,
            if p.rebuilt { " (new contact set)" } else { "" },
            p.times_s[2]
        );
    })
    .context("the mu sweep")?;
    let (points, branches, free) = (&sweep.points, &sweep.branches, &sweep.free);
    write_csv(&out.join("sweep.csv"), "mu", points, branches, dvr_tol)?;
    charts(out, &Axis::mu(), points, branches, dvr_tol)?;
    let makeup: Vec<SweepCoupling> = sweep
        .couplings
        .iter()
        .map(|c| SweepCoupling {
            freq_hz: c.freq_hz,
            from: c.mu_from,
            to: c.mu_to,
            max_dvr: c.max_dvr,
            partners: c.partners.clone(),
            makeup: c.free_interface_mac.clone(),
        })
        .collect();
    mac_charts(out, &Axis::mu(), &makeup)?;
    let mut profile = setup.clone();
    profile.extend_prefixed("", &sweep.profile);
    let wall = start.elapsed().as_secs_f64() + setup.total_s();
    eprintln!("\nwhere the time went:\n{}", profile.markdown(wall));
    let summary = Summary {
        scene: prep.file.clone(),
        units: "SI: frequencies in Hz, DvR = Re/Im (dimensionless), times in s",
        mu: range,
        band_hz: settings.band_hz,
        eigen: settings.eigen.clone(),
        basis: settings.basis.clone(),
        equilibrium: settings.equilibrium.clone(),
        law: settings.law.clone(),
        dofs: prep.model.dofs.n_free(),
        dvr_tol,
        points: points.len(),
        rebuilds: points.iter().filter(|p| p.rebuilt).count(),
        max_basis_size: points.iter().map(|p| p.basis_size).max().unwrap_or(0),
        max_backward_error: points
            .iter()
            .flat_map(|p| p.modes.iter().map(|m| m.backward_error))
            .fold(0.0, f64::max),
        max_error_bound: max_error_bound(points),
        free_interface_modes: free.freq_hz.len(),
        time_s: start.elapsed().as_secs_f64(),
        couplings: sweep.couplings.clone(),
        stages: profile.stages,
        peak_rss_mb: peak_rss_mb(),
    };
    std::fs::write(
        out.join("summary.json"),
        serde_json::to_string_pretty(&summary)?,
    )?;
    Ok((summary, sweep))
}

/// Claims `out` for `command` and opens its checkpoint: refuses a directory holding `what`
/// (finished points or a summary) without `resume`, and a checkpoint of other `inputs`.
/// Returns the checkpoint and how many points it holds.
fn open_checkpoint(
    out: &Path,
    command: &str,
    what: &str,
    resume: bool,
    inputs: &serde_json::Value,
) -> Result<(Checkpoint, usize)> {
    crate::opts::claim_out(out, command)?;
    let ckpt_path = out.join("sweep.partial.jsonl");
    let done = Checkpoint::new(ckpt_path.clone())
        .load()
        .map(|p| p.len())
        .unwrap_or(0);
    if (done > 0 || out.join("summary.json").is_file()) && !resume {
        anyhow::bail!(
            "--out {}: holds {what} ({done} finished points): pass --resume to continue it, \
             or choose another directory",
            out.display()
        );
    }
    if done > 0 {
        eprintln!(
            "resuming: {done} points already computed in {}",
            ckpt_path.display()
        );
    }
    crate::opts::set_resume_hint(out);
    let ckpt = Checkpoint::new(ckpt_path);
    ckpt.claim(inputs).map_err(anyhow::Error::msg)?;
    Ok((ckpt, done))
}

/// The worst `error_bound` of every point's modes (NaN when none was computed).
fn max_error_bound(points: &[SweepPoint]) -> f64 {
    let all: Vec<f64> = points
        .iter()
        .flat_map(|p| p.modes.iter().map(|m| m.error_bound))
        .collect();
    crate::stability::worst(&all)
}

/// The swept quantity of charts and CSV: its column name, its axis label and the modes
/// the signatures are taken on (one of them, and all of them).
struct Axis {
    column: String,
    label: String,
    item: &'static str,
    reference: &'static str,
}

impl Axis {
    fn mu() -> Self {
        Self {
            column: "mu".into(),
            label: "friction coefficient mu".into(),
            item: "free-interface mode",
            reference: "the free-interface modes",
        }
    }

    fn param(name: &str) -> Self {
        Self {
            column: name.into(),
            label: format!("parameter {name}"),
            item: "reference mode",
            reference: "the reference modes",
        }
    }
}

fn write_csv(
    path: &Path,
    column: &str,
    points: &[SweepPoint],
    branches: &[Branch],
    tol: f64,
) -> Result<()> {
    let mut f = std::io::BufWriter::new(
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?,
    );
    writeln!(
        f,
        "{column},branch,mode,freq_hz,re,dvr,unstable,backward_error,cond,error_bound,active_pairs,basis_size"
    )?;
    // an estimate that was not computed is an empty field
    let num = |x: f64| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x:.3e}")
        }
    };
    for (p, pt) in points.iter().enumerate() {
        for (m, md) in pt.modes.iter().enumerate() {
            let b = branches
                .iter()
                .find(|b| b.modes[p] == Some(m))
                .map_or(usize::MAX, |b| b.id);
            writeln!(
                f,
                "{},{},{},{:.6},{:.6e},{:.6e},{},{:.3e},{},{},{},{}",
                pt.value,
                b,
                m,
                md.freq_hz,
                // `+ 0.0` writes an undamped mode's -0 as 0
                md.re + 0.0,
                md.dvr + 0.0,
                u8::from(md.dvr > tol),
                md.backward_error,
                num(md.cond),
                num(md.error_bound),
                pt.active_pairs,
                pt.basis_size
            )?;
        }
    }
    Ok(())
}

fn charts(
    out: &Path,
    axis: &Axis,
    points: &[SweepPoint],
    branches: &[Branch],
    tol: f64,
) -> Result<Vec<PathBuf>> {
    use squeal_plot::{line_chart, ChartOptions, Series, SeriesStyle};
    let series = |y: &dyn Fn(&squeal_analysis::sweep::SweepMode) -> f64| -> Vec<Series> {
        branches
            .iter()
            .map(|b| {
                let pts: Vec<(usize, usize)> = (0..points.len())
                    .filter_map(|p| b.modes[p].map(|m| (p, m)))
                    .collect();
                Series {
                    name: String::new(),
                    points: pts
                        .iter()
                        .map(|&(p, m)| (points[p].value, y(&points[p].modes[m])))
                        .collect(),
                    style: SeriesStyle::LineMarkers,
                    highlight: pts
                        .iter()
                        .map(|&(p, m)| points[p].modes[m].dvr > tol)
                        .collect(),
                }
            })
            .collect()
    };
    let mut files = line_chart(
        &out.join(format!("frequency_vs_{}", axis.column)),
        "Frequency of the tracked modes (unstable in red)",
        &axis.label,
        "frequency (Hz)",
        &series(&|m| m.freq_hz),
        &ChartOptions {
            highlight_label: Some("unstable".into()),
            ..ChartOptions::default()
        },
    )?;
    files.extend(line_chart(
        &out.join(format!("dvr_vs_{}", axis.column)),
        "Divergence rate Re/Im of the tracked modes (unstable in red)",
        &axis.label,
        "DvR = Re(lambda)/Im(lambda)",
        &series(&|m| m.dvr),
        &ChartOptions {
            hline: Some(0.0),
            highlight_label: Some("unstable".into()),
            ..ChartOptions::default()
        },
    )?);
    Ok(files)
}

/// One bar chart per coupling: the MAC of the unstable mode with the reference modes of
/// the signatures.
fn mac_charts(out: &Path, axis: &Axis, couplings: &[SweepCoupling]) -> Result<()> {
    for (i, c) in couplings.iter().enumerate() {
        if c.makeup.is_empty() {
            continue;
        }
        squeal_plot::bar_chart(
            &out.join(format!("mac_coupling_{}", i + 1)),
            &format!(
                "Unstable mode near {:.0} Hz ({} {}-{}): MAC with {}",
                c.freq_hz, axis.column, c.from, c.to, axis.reference
            ),
            axis.item,
            "MAC",
            &c.makeup,
        )?;
    }
    Ok(())
}
