//! `squeal validate`: the uniform-contact validation of the paper, the project's main job
//! ([`squeal_analysis::validate`] does the work; this module checks the options, prints
//! progress, draws the charts and prints the paper table). `--disc-only` runs its first
//! stage alone.

use anyhow::{Context, Result};
use squeal_analysis::mu_sweep::{mu_list, MuSweep, SweepEvent, SweepSummary};
use squeal_analysis::outdir::RunError;
use squeal_analysis::pipeline::Prepared;
use squeal_analysis::validate::{ValidateHooks, ValidateSettings};
use squeal_contact::LoadedEquilibrium;
use squeal_core::Registry;
use std::path::Path;

/// `squeal validate`.
#[derive(clap::Args)]
pub struct ValidateArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Report directory.
    #[arg(long, default_value = "out/validate")]
    out: std::path::PathBuf,
    /// Basis of the paper's Figure 5: its sweep gives the couplings of the paper table.
    #[arg(long, default_value = "cms")]
    figure_basis: String,
    /// Step of that sweep (0 to 0.8); the paper's resolution is 0.01.
    #[arg(long, default_value = "0.01")]
    step: f64,
    /// Further bases swept as checks, comma separated (the paper's two; `none`: no check).
    #[arg(long, value_delimiter = ',', default_value = "enriched,residue")]
    bases: Vec<String>,
    /// Step of the check sweeps (0.05 puts points inside both couplings' windows).
    #[arg(long, default_value = "0.05")]
    check_step: f64,
    /// Frequency band `FMIN:FMAX` (Hz) of the sweeps and reference points; default: the
    /// scene's `study.band_hz`.
    #[arg(long)]
    band: Option<String>,
    /// Friction coefficients of the full-order reference solves, comma separated (each
    /// must be a point of every sweep).
    #[arg(long, value_delimiter = ',', default_value = "0.3,0.7")]
    reference_mu: Vec<f64>,
    /// Full-order eigen solver of the reference points.
    #[arg(long, default_value = "arpack")]
    eigen: String,
    /// Continue an interrupted validation in --out (its finished sweep points are kept).
    #[arg(long)]
    resume: bool,
    /// Only the disc modes against Table 2 (the first stage).
    #[arg(long)]
    disc_only: bool,
    /// With --disc-only: write the table as JSON here.
    #[arg(long)]
    json: Option<std::path::PathBuf>,
}

impl ValidateArgs {
    /// Runs the validation (or its first stage), every option checked first.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        registry
            .eigen
            .create(&self.eigen, &squeal_core::Params::new())
            .map_err(|e| anyhow::anyhow!("--eigen {}: {e}", self.eigen))?;
        if self.disc_only {
            return disc_only(
                registry,
                self.scene.as_deref(),
                &self.eigen,
                self.json.as_deref(),
            );
        }
        if self.json.is_some() {
            anyhow::bail!(
                "--json: only with --disc-only (the full validation writes report.json in --out)"
            );
        }
        mu_list(0.0, 0.8, self.step).map_err(|e| anyhow::anyhow!("--step {}: {e}", self.step))?;
        mu_list(0.0, 0.8, self.check_step)
            .map_err(|e| anyhow::anyhow!("--check-step {}: {e}", self.check_step))?;
        let band = self
            .band
            .as_deref()
            .map(crate::opts::parse_band)
            .transpose()?;
        let checks: Vec<String> = self
            .bases
            .iter()
            .filter(|b| *b != "none")
            .cloned()
            .collect();
        for &mu in &self.reference_mu {
            crate::opts::check_mu("--reference-mu", mu)?;
        }
        let settings = ValidateSettings {
            sweeps: std::iter::once((self.figure_basis.clone(), self.step))
                .chain(checks.iter().map(|b| (b.clone(), self.check_step)))
                .collect(),
            band_hz: band,
            reference_mu: self.reference_mu.clone(),
            eigen: self.eigen.clone(),
            resume: self.resume,
        };
        squeal_analysis::validate::check(registry, &settings).map_err(|e| match e {
            // the library names the settings' fields; here they are options
            RunError::Input { field, message } => {
                let flag = match field.as_str() {
                    "sweeps[0].basis" => "--figure-basis",
                    f if f.ends_with(".basis") => "--bases",
                    "sweeps[0].step" => "--step",
                    f if f.ends_with(".step") => "--check-step",
                    "reference_mu" => "--reference-mu",
                    "eigen" => "--eigen",
                    other => other,
                };
                anyhow::anyhow!("{flag} {message}")
            }
            e => e.into(),
        })?;
        run(registry, self.scene.as_deref(), &self.out, &settings)
    }
}

/// `validate --disc-only`: the disc's modes against Table 2.
fn disc_only(
    registry: &Registry,
    scene: Option<&str>,
    eigen: &str,
    json: Option<&Path>,
) -> Result<()> {
    let report = crate::modes::run(
        registry,
        scene,
        squeal_scene::BodyKind::Disc,
        10_500.0,
        eigen,
        1e-10,
        None,
    )?;
    let rows = squeal_analysis::modal::compare_table2(&report.modes);
    println!("Disc normal modes (free friction face): paper Table 2 vs squeal");
    println!(
        "model: {} DOFs, {} elements, solved by `{}` in {:.2} s (build {:.2} s)\n",
        report.dofs, report.elements, report.solver, report.solve_time_s, report.build_time_s
    );
    print!("{}", squeal_analysis::modal::format_table(&rows));
    let within = |t: f64| {
        rows.iter()
            .filter(|r| r.rel_err.is_some_and(|e| e.abs() <= t))
            .count()
    };
    println!(
        "\n{} of {} labels found; {} within 5 %, {} within 10 %",
        rows.iter().filter(|r| r.squeal_hz.is_some()).count(),
        rows.len(),
        within(0.05),
        within(0.10)
    );
    if let Some(path) = json {
        let v = serde_json::json!({ "units": "SI (Hz)", "table2": rows, "modes": report.modes });
        std::fs::write(path, serde_json::to_string_pretty(&v)?)
            .with_context(|| format!("--json {}: cannot write", path.display()))?;
    }
    Ok(())
}

/// Progress lines on stderr and the charts of each stage.
struct Hooks {
    eta: crate::opts::Eta,
}

impl ValidateHooks for Hooks {
    fn stage(&mut self, k: usize, n: usize, what: &str) {
        eprintln!("[{k}/{n}] {what}");
    }

    fn equilibria(
        &mut self,
        out: &Path,
        prep: &Prepared,
        eqs: &[LoadedEquilibrium],
    ) -> Result<(), RunError> {
        crate::equilibrium::contact_map(out, prep, eqs, "lcp", "lagrange")
            .map_err(|e| RunError::Output(format!("{e:#}")))
    }

    fn sweep_event(&mut self, out: &Path, prep: &Prepared, event: SweepEvent<'_>) {
        crate::sweep::report_event(&mut self.eta, out, prep, 1e-6, event);
    }

    fn sweep_done(
        &mut self,
        out: &Path,
        _summary: &SweepSummary,
        sweep: &MuSweep,
    ) -> Result<(), RunError> {
        crate::sweep_charts::sweep_charts(out, sweep, 1e-6)
            .map_err(|e| RunError::Output(format!("{e:#}")))
    }
}

/// Runs the validation into `out` and prints its paper table and rig line.
fn run(
    registry: &Registry,
    scene: Option<&str>,
    out: &Path,
    settings: &ValidateSettings,
) -> Result<()> {
    crate::opts::claim_out(out, "validate")?;
    crate::opts::set_resume_hint(out);
    let (scene, file) = crate::opts::load_scene(scene)?;
    let band = settings.band_hz.unwrap_or(scene.study.band_hz);
    crate::opts::check_band_against(band, &scene)?;
    let mut hooks = Hooks {
        eta: crate::opts::Eta::new(0, 0),
    };
    let v = squeal_analysis::validate::run(registry, &scene, &file, settings, out, &mut hooks)
        .map_err(crate::opts::out_error)?;
    let p = squeal_analysis::reference::paper();
    println!("{}", v.paper_table());
    println!(
        "rig: {} pin modes below 10 kHz, {:.3} MN/m ({:.1} N at {:.0} um); {:.0} s, peak {}",
        v.pin_below.len(),
        v.stiffness_n_per_m / 1e6,
        v.force_at_datum_n,
        p.load_displacement_m * 1e6,
        v.time_s,
        v.peak_rss_mb.map_or("-".into(), |m| format!("{m:.0} MB"))
    );
    println!("report: {}", out.join("report.md").display());
    Ok(())
}
