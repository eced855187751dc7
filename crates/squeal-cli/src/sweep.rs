//! `squeal sweep mu`: the friction-coefficient sweep with mode tracking, coupling
//! detection, CSV/JSON outputs and the paper's Figure 5 and 7 charts; `squeal sweep
//! param`: the same for the parameter of a parametric operator directory.

use anyhow::Result;
use squeal_analysis::mu_sweep::{
    mu_list, run_into, value_list, MuSweep, MuSweepSettings, SweepEvent, SweepSummary,
};
use squeal_analysis::outdir::RunError;
use squeal_analysis::param_sweep::ParamSweepSettings;
use squeal_analysis::pipeline::Prepared;
use squeal_analysis::profile::Profile;
use squeal_core::Registry;
use std::path::{Path, PathBuf};

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
            contact: &self.contact,
            dvr_margin: self.method.dvr_margin,
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

impl ParamArgs {
    /// Checks every option, runs the sweep and prints its couplings.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        self.method.check(registry)?;
        value_list(self.from, self.to, self.step)
            .map_err(|e| anyhow::anyhow!("--from/--to/--step: {e}"))?;
        if let Some(mu) = self.mu {
            crate::opts::check_mu("--mu", mu)?;
        }
        let settings = ParamSweepSettings {
            from: self.from,
            to: self.to,
            step: self.step,
            mu: self.mu,
            basis: self.method.basis.clone(),
            basis_params: self.method.basis_params()?,
            eigen: self.method.eigen(),
            band_hz: self.method.band(crate::opts::OPERATOR_BAND_HZ)?,
            tol: self.method.tol,
            dvr_margin: self.method.dvr_margin,
            condition: self.condition,
        };
        let name = self.param.as_str();
        let dir = &self.operator;
        let family_op = crate::opts::read_parametric(dir, name, &format!("--param {name}"))?;
        let out = &self.out;
        crate::opts::set_resume_hint(out);
        let dvr_margin = settings.dvr_margin;
        let mut eta = crate::opts::Eta::new(0, 0);
        let (summary, sweep) = squeal_analysis::param_sweep::run_into(
            registry,
            dir,
            &family_op,
            name,
            &settings,
            out,
            self.resume,
            |e| match e {
                SweepEvent::Opened { done, total } => {
                    eta = crate::opts::Eta::new(total, done);
                    if done > 0 {
                        eprintln!(
                            "resuming: {done} points already computed in {}",
                            out.join("sweep.partial.jsonl").display()
                        );
                    }
                }
                SweepEvent::Point(p) => {
                    let [unstable, neutral, _] = p.class_counts(dvr_margin);
                    eprintln!(
                        "{} {name} {}: {} modes, {} unstable, {} neutral, max error bound {}, \
                         solve {:.2} s",
                        eta.tick(),
                        p.value,
                        p.modes.len(),
                        unstable,
                        neutral,
                        crate::stability::sci(squeal_analysis::sweep::files::worst(
                            &p.modes.iter().map(|m| m.error_bound).collect::<Vec<_>>()
                        )),
                        p.times_s[2]
                    );
                }
            },
        )
        .map_err(|e| match e {
            RunError::Input { field, message } => anyhow::anyhow!(
                "{}: {message}",
                field
                    .split('/')
                    .map(|f| format!("--{f}"))
                    .collect::<Vec<_>>()
                    .join("/")
            ),
            e => crate::opts::out_error(e),
        })?;
        let axis = crate::sweep_charts::Axis::param(name);
        crate::sweep_charts::charts(out, &axis, &sweep.points, &sweep.branches, dvr_margin)?;
        crate::sweep_charts::mac_charts(out, &axis, &sweep.couplings)?;
        println!(
            "{} points of {name} at mu = {}, {} couplings, max backward error {:.1e}, max \
             error bound {}, {:.1} s",
            summary.points,
            summary.mu,
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
            "  {freq_hz:>8.1} Hz  {name} {from}-{to}  max DvR {}  partners {partners:?}",
            squeal_analysis::num::sci(max_dvr, 3)
        );
    }
    println!(
        "wrote {}/{{sweep.csv,summary.json,*.svg,*.png}}",
        out.display()
    );
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
    /// Equilibrium solver, contact law and its parameters.
    pub contact: &'a crate::opts::ContactArgs,
    pub dvr_margin: f64,
    pub tol: f64,
    /// Condition numbers of full-order modes above the solvers' automatic size.
    pub condition: bool,
    /// Continue the sweep in `out` (else a directory holding one is refused).
    pub resume: bool,
    pub out: &'a Path,
}

/// The range rule of every mu list (`--from/--to/--step`).
pub fn mus(from: f64, to: f64, step: f64) -> Result<Vec<f64>> {
    mu_list(from, to, step).map_err(|e| anyhow::anyhow!("--from/--to/--step: {e}"))
}

pub fn run(registry: &Registry, a: &Args<'_>) -> Result<SweepSummary> {
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
        equilibrium: a.contact.equilibrium.clone(),
        law: a.contact.law.clone(),
        law_params: a.contact.law_params()?,
        dvr_margin: a.dvr_margin,
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

/// Runs the sweep `settings` of `prep` into `out` (checkpoint, CSV, summary) with
/// progress lines, then draws its charts. `range` is `[from, to, step]` as given; `setup`
/// holds the stages run before (building `prep`), reported first.
pub fn run_on(
    registry: &Registry,
    prep: &Prepared,
    settings: &MuSweepSettings,
    range: [f64; 3],
    out: &Path,
    resume: bool,
    setup: &Profile,
) -> Result<(SweepSummary, MuSweep)> {
    crate::opts::set_resume_hint(out);
    let dvr_margin = settings.dvr_margin;
    let mut eta = crate::opts::Eta::new(settings.mus.len(), 0);
    let (summary, sweep) = run_into(registry, prep, settings, range, out, resume, setup, |e| {
        report_event(&mut eta, out, prep, dvr_margin, e)
    })
    .map_err(crate::opts::out_error)?;
    crate::sweep_charts::sweep_charts(out, &sweep, dvr_margin)?;
    let profile = Profile {
        stages: summary.stages.clone(),
    };
    eprintln!(
        "\nwhere the time went:\n{}",
        profile.markdown(summary.time_s + setup.total_s())
    );
    Ok((summary, sweep))
}

/// Prints the progress line of a mu sweep's event (`eta` restarts when the checkpoint
/// opens).
pub fn report_event(
    eta: &mut crate::opts::Eta,
    out: &Path,
    prep: &Prepared,
    dvr_margin: f64,
    event: SweepEvent<'_>,
) {
    match event {
        SweepEvent::Opened { done, total } => {
            *eta = crate::opts::Eta::new(total, done);
            if done > 0 {
                eprintln!(
                    "resuming: {done} points already computed in {}",
                    out.join("sweep.partial.jsonl").display()
                );
            }
            if done < total {
                eprintln!(
                    "free modes of the model (and the free-interface synthesis a basis such \
                     as `cms` works from) up to the needed cutoff: {} DOFs, the longest setup \
                     stage",
                    prep.model.dofs.n_free()
                );
            }
        }
        SweepEvent::Point(p) => {
            let [unstable, neutral, _] = p.class_counts(dvr_margin);
            eprintln!(
                "{} mu {:.3}: {} modes, {} unstable, {} neutral, {} active pairs{}, solve {:.2} s",
                eta.tick(),
                p.mu,
                p.modes.len(),
                unstable,
                neutral,
                p.active_pairs,
                if p.rebuilt { " (new contact set)" } else { "" },
                p.times_s[2]
            );
        }
    }
}
