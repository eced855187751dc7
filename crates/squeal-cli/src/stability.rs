//! `squeal stability`: complex modes of the frictional operator of a scene (after its
//! sliding equilibrium) or of an operator directory.

use anyhow::{Context, Result};
use serde::Serialize;
use squeal_analysis::pipeline::Prepared;
use squeal_core::{EigenParams, FrictionalOperator, Registry, Stability};
use std::path::Path;
use std::time::Instant;

/// One mode in the JSON output.
#[derive(Serialize)]
pub struct ModeOut {
    pub freq_hz: f64,
    pub re: f64,
    pub im: f64,
    pub dvr: f64,
    /// Whether the mode is unstable (`stability == "unstable"`).
    pub unstable: bool,
    /// `unstable`, `neutral` or `stable`: the real part against its forward error bound
    /// (`re_bound`), and the DvR against the physical margin `dvr_margin` when one is set.
    pub stability: &'static str,
    /// Forward error bound of the real part (1/s), `cond x backward_error x |lambda|`
    /// (null when the sign of a real part far beyond any bound decided the class alone).
    pub re_bound: f64,
    pub backward_error: f64,
    /// Condition number of the eigenvalue (null when not computed: full order above 1000
    /// DOFs without --condition).
    pub cond: f64,
    /// First-order estimate of the relative eigenvalue error, `cond * backward_error`
    /// (null when not computed).
    pub error_bound: f64,
}

/// What `squeal stability --json` writes.
#[derive(Serialize)]
pub struct StabilityReport {
    pub source: String,
    /// The parameter value of a parametric operator (`--param`, e.g. `W=5`).
    pub param: Option<String>,
    pub units: &'static str,
    pub dofs: usize,
    pub full_dofs: usize,
    pub mu: f64,
    pub eigen: String,
    pub basis: String,
    pub basis_size: usize,
    pub basis_time_s: f64,
    pub band_hz: [f64; 2],
    pub tol: f64,
    pub dvr_margin: f64,
    pub active_pairs: Option<usize>,
    pub pairs: Option<usize>,
    /// The scene's damping (`none`, or its Rayleigh coefficients and contact dashpots), or
    /// whether an operator directory has a damping part.
    pub damping: String,
    pub equilibrium_time_s: f64,
    pub operator_time_s: f64,
    pub solve_time_s: f64,
    pub time_s: f64,
    pub converged: usize,
    pub reason: String,
    pub factorizations: usize,
    pub notes: Vec<String>,
    pub max_backward_error: f64,
    /// Worst `error_bound` of the modes (null when not computed).
    pub max_error_bound: f64,
    /// How many modes are unstable, neutral (within their bound) and stable.
    pub unstable: usize,
    pub neutral: usize,
    pub stable: usize,
    pub modes: Vec<ModeOut>,
}

/// `squeal stability`.
#[derive(clap::Args)]
pub struct StabilityArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Operator directory (Mc.mtx, Kc.mtx, ... as written by `squeal export`) instead of
    /// a scene.
    #[arg(long)]
    operator: Option<std::path::PathBuf>,
    /// The parameter of a parametric operator directory (--operator), `NAME=VALUE` with
    /// the name its operator.toml declares, e.g. `W=5`.
    #[arg(long, value_name = "NAME=VALUE")]
    param: Option<String>,
    /// Friction coefficient (default: the scene's study.mu; with --operator, required when
    /// the operator has friction parts, else 0).
    #[arg(long)]
    mu: Option<f64>,
    #[command(flatten)]
    method: crate::opts::MethodArgs,
    /// Condition numbers and forward error estimates for every mode, also at full order
    /// above 1000 DOFs where the solvers skip them (one extra factorization per mode).
    #[arg(long)]
    condition: bool,
    #[command(flatten)]
    contact: crate::opts::ContactArgs,
    /// Write the result as JSON here.
    #[arg(long)]
    json: Option<std::path::PathBuf>,
}

impl StabilityArgs {
    /// Solves, prints and writes the JSON.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        self.method.check(registry)?;
        self.contact.check(registry)?;
        if let Some(mu) = self.mu {
            crate::opts::check_mu("--mu", mu)?;
        }
        if let Some(p) = &self.param {
            crate::opts::parse_param(p)?;
            if self.operator.is_none() {
                anyhow::bail!(
                    "--param {p}: needs --operator DIR (a parametric operator directory), not a scene"
                );
            }
        }
        let eigen = self.method.eigen();
        let basis_opts = self.method.basis_opt.clone();
        let args = Args {
            scene: self.scene.as_deref(),
            operator: self.operator.as_deref(),
            param: self.param.as_deref(),
            condition: self.condition,
            mu: self.mu,
            basis: &self.method.basis,
            basis_opts: &basis_opts,
            eigen: &eigen,
            band: self.method.band.clone(),
            tol: self.method.tol,
            dvr_margin: self.method.dvr_margin,
            contact: &self.contact,
        };
        let report = run(registry, &args)?;
        print(&report);
        if let Some(path) = &self.json {
            std::fs::write(path, serde_json::to_string_pretty(&report)?)
                .with_context(|| format!("--json {}: cannot write", path.display()))?;
        }
        Ok(())
    }
}

/// `squeal export`.
#[derive(clap::Args)]
pub struct ExportArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Friction coefficient of the equilibrium (default: the scene's study.mu).
    #[arg(long)]
    mu: Option<f64>,
    #[command(flatten)]
    contact: crate::opts::ContactArgs,
    /// Output directory.
    #[arg(long)]
    out: std::path::PathBuf,
}

impl ExportArgs {
    /// Writes both forms of the operator.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        self.contact.check(registry)?;
        if let Some(mu) = self.mu {
            crate::opts::check_mu("--mu", mu)?;
        }
        export(
            registry,
            self.scene.as_deref(),
            self.mu,
            &self.contact,
            &self.out,
        )
    }
}

/// Inputs of one stability run.
pub struct Args<'a> {
    pub scene: Option<&'a str>,
    pub operator: Option<&'a Path>,
    /// `--param NAME=VALUE` of a parametric operator directory, as given.
    pub param: Option<&'a str>,
    /// Condition numbers also at full order above the solvers' automatic size.
    pub condition: bool,
    pub mu: Option<f64>,
    pub eigen: &'a str,
    /// `--band` as given; `None`: the scene's band.
    pub band: Option<String>,
    pub tol: f64,
    pub dvr_margin: f64,
    /// Equilibrium solver, contact law and its parameters.
    pub contact: &'a crate::opts::ContactArgs,
    pub basis: &'a str,
    pub basis_opts: &'a [String],
}

/// The operator of a scene at its equilibrium, or read from a directory.
pub struct Source {
    pub name: String,
    pub op: FrictionalOperator,
    pub mu: f64,
    pub active_pairs: Option<usize>,
    pub pairs: Option<usize>,
    pub damping: String,
    pub equilibrium_time_s: f64,
    pub operator_time_s: f64,
    /// The band of the scene (`study.band_hz`), or the default of operator files.
    pub band_hz: [f64; 2],
    /// The built scene (none for an operator read from files).
    pub prep: Option<Prepared>,
}

pub fn source(registry: &Registry, a: &Args<'_>) -> Result<Source> {
    if let Some(dir) = a.operator {
        if a.scene.is_some() {
            anyhow::bail!("give either a scene or --operator DIR, not both");
        }
        let start = Instant::now();
        let op = crate::opts::read_operator_at(dir, a.param)?;
        let mu = match a.mu {
            Some(mu) => mu,
            None if op.has_friction() => anyhow::bail!(
                "--mu: required, the operator in {} has friction parts (X - mu F_X)",
                dir.display()
            ),
            None => 0.0,
        };
        squeal_contact::check_user_mu(mu)?;
        let damping = if op.cc.is_some() || op.fc.is_some() {
            "read from the operator files (C_c, F_C)".into()
        } else {
            "none".into()
        };
        return Ok(Source {
            name: match a.param {
                Some(p) => format!("{} at {p}", dir.display()),
                None => dir.display().to_string(),
            },
            op,
            mu,
            active_pairs: None,
            pairs: None,
            damping,
            equilibrium_time_s: 0.0,
            operator_time_s: start.elapsed().as_secs_f64(),
            band_hz: crate::opts::OPERATOR_BAND_HZ,
            prep: None,
        });
    }
    let (scene, file) = crate::opts::load_scene(a.scene)?;
    let mu = a.mu.unwrap_or(scene.study.mu);
    let prep = Prepared::new(registry, scene, &file)?;
    let t0 = Instant::now();
    let c = a.contact;
    let eq = prep.equilibrium_with(registry, &c.equilibrium, &c.law, &c.law_params()?, mu)?;
    let equilibrium_time_s = t0.elapsed().as_secs_f64() + prep.condensation.time_s;
    let t1 = Instant::now();
    let op = prep.operator(&eq.eq.active)?;
    Ok(Source {
        name: file,
        op,
        mu,
        active_pairs: Some(eq.eq.active.iter().filter(|&&x| x).count()),
        pairs: Some(prep.set.len()),
        damping: prep.scene.damping.describe(),
        equilibrium_time_s,
        operator_time_s: t1.elapsed().as_secs_f64(),
        band_hz: prep.scene.study.band_hz,
        prep: Some(prep),
    })
}

pub fn run(registry: &Registry, a: &Args<'_>) -> Result<StabilityReport> {
    let start = Instant::now();
    let src = source(registry, a)?;
    let band = match &a.band {
        Some(b) => crate::opts::parse_band(b)?,
        None => src.band_hz,
    };
    if let Some(prep) = &src.prep {
        crate::opts::check_band_against(band, &prep.scene)?;
    }
    let params = EigenParams {
        fmin_hz: band[0],
        fmax_hz: band[1],
        tol: a.tol,
        ..EigenParams::default()
    };
    let mut method = squeal_analysis::pipeline::Method::new(
        registry,
        a.basis,
        &crate::opts::parse_params(a.basis_opts)?,
        a.eigen,
        squeal_analysis::pipeline::MODAL_SOLVER,
        params,
    )?;
    method.set_condition(a.condition);
    if let Some(prep) = &src.prep {
        method.prepare_stage_on(prep)?;
    }
    let (modes, basis_size, basis_time_s) = method.solve(&src.op, src.mu, true)?;
    let out: Vec<ModeOut> = (0..modes.len())
        .map(|i| {
            let v = modes.verdict(i, a.dvr_margin);
            ModeOut {
                freq_hz: modes.freq_hz[i],
                re: modes.lambda[i].re,
                im: modes.lambda[i].im,
                dvr: modes.dvr[i],
                unstable: v.class == Stability::Unstable,
                stability: v.class.name(),
                re_bound: v.re_bound,
                backward_error: modes.backward_error[i],
                cond: modes.cond[i],
                error_bound: modes.error_bound[i],
            }
        })
        .collect();
    let [unstable, neutral, stable] = modes.class_counts(a.dvr_margin);
    Ok(StabilityReport {
        source: src.name,
        param: a.param.map(str::to_string),
        units: "SI: frequencies in Hz, real parts in 1/s, times in s; DvR = Re/Im",
        dofs: src.op.dim(),
        full_dofs: src.op.full_dim(),
        mu: src.mu,
        eigen: a.eigen.into(),
        basis: a.basis.into(),
        basis_size,
        basis_time_s,
        band_hz: band,
        tol: a.tol,
        dvr_margin: a.dvr_margin,
        active_pairs: src.active_pairs,
        pairs: src.pairs,
        damping: src.damping,
        equilibrium_time_s: src.equilibrium_time_s,
        operator_time_s: src.operator_time_s,
        solve_time_s: modes.info.time_s,
        time_s: start.elapsed().as_secs_f64(),
        converged: modes.info.converged,
        reason: format!("{:?}", modes.info.reason),
        factorizations: modes.info.factorizations,
        notes: modes.info.notes.clone(),
        max_backward_error: modes.backward_error.iter().fold(0.0, |m: f64, &b| m.max(b)),
        max_error_bound: squeal_analysis::sweep::files::worst(&modes.error_bound),
        unstable,
        neutral,
        stable,
        modes: out,
    })
}

pub fn print(r: &StabilityReport) {
    println!(
        "{}: {} DOFs (constrained; {} full), mu = {}, `{}`{}: {} modes in {:?} Hz in {:.2} s",
        r.source,
        r.dofs,
        r.full_dofs,
        r.mu,
        r.eigen,
        if r.basis == "none" {
            String::new()
        } else {
            format!(
                " on basis `{}` ({} vectors, built in {:.2} s)",
                r.basis, r.basis_size, r.basis_time_s
            )
        },
        r.modes.len(),
        r.band_hz,
        r.solve_time_s
    );
    if let (Some(a), Some(p)) = (r.active_pairs, r.pairs) {
        println!("contact: {a} of {p} pairs active");
    }
    if r.damping != "none" {
        println!("damping: {}", r.damping);
    }
    println!(
        "{:>4} {:>12} {:>14} {:>12} {:>9} {:>10} {:>10} {:>10} {:>10}",
        "#", "freq (Hz)", "Re (1/s)", "DvR", "class", "Re bound", "backward", "cond", "err bound"
    );
    for (i, m) in r.modes.iter().enumerate() {
        println!(
            "{:>4} {:>12.3} {:>14} {:>12} {:>9} {:>10} {:>10.1e} {:>10} {:>10}",
            i + 1,
            m.freq_hz,
            squeal_analysis::num::sci(m.re, 6),
            squeal_analysis::num::sci(m.dvr, 4),
            match m.stability {
                "unstable" => "UNSTABLE",
                other => other,
            },
            sci(m.re_bound),
            m.backward_error,
            sci(m.cond),
            sci(m.error_bound)
        );
    }
    println!(
        "{} unstable, {} neutral (within their bound), {} stable{}",
        r.unstable,
        r.neutral,
        r.stable,
        if r.dvr_margin > 0.0 {
            format!(
                " (unstable also needs DvR > {:e}, the --dvr-margin)",
                r.dvr_margin
            )
        } else {
            String::new()
        }
    );
    if r.modes.iter().any(|m| m.cond.is_nan()) {
        println!(
            "cond, err bound: `-` where the class does not depend on them (full order above \
             1000 DOFs; --condition computes them for every mode); Re bound `-`: the sign \
             decided"
        );
    }
    for n in &r.notes {
        println!("note: {n}");
    }
}

/// A number in scientific notation with two digits, `-` when it was not computed (NaN).
pub fn sci(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else {
        format!("{x:.1e}")
    }
}

/// Reads an operator directory in either form: the constrained parts (`Mc.mtx`, ...),
/// preferred when present, or the full form (`M.mtx`, `K.mtx`, `pairs.csv`).
pub fn read_operator_any(dir: &Path) -> Result<FrictionalOperator> {
    let op = if dir.join(squeal_io::FILE_MC).is_file() {
        squeal_io::read_operator_dir(dir)?
    } else if squeal_contact::files::is_full_form(dir) {
        squeal_contact::files::read_full_form(dir)?
    } else {
        anyhow::bail!(
            "{}: not an operator directory: expected Mc.mtx and Kc.mtx (constrained form) or \
             M.mtx, K.mtx and pairs.csv (full form), as written by `squeal export`",
            dir.display()
        )
    };
    op.check_pencil()
        .map_err(|e| anyhow::anyhow!("--operator {}: {e}", dir.display()))?;
    Ok(op)
}

/// `squeal export`: both forms of a scene's operator at its equilibrium for `mu`.
pub fn export(
    registry: &Registry,
    scene: Option<&str>,
    mu: Option<f64>,
    contact: &crate::opts::ContactArgs,
    out: &Path,
) -> Result<()> {
    let (scene, file) = crate::opts::load_scene(scene)?;
    let mu = mu.unwrap_or(scene.study.mu);
    let prep = Prepared::new(registry, scene, &file)?;
    let (equilibrium, law, law_params) =
        (&contact.equilibrium, &contact.law, contact.law_params()?);
    let eq = prep.equilibrium_with(registry, equilibrium, law, &law_params, mu)?;
    let op = prep.operator(&eq.eq.active)?;
    let active = eq.eq.active.iter().filter(|&&a| a).count();
    squeal_io::write_operator_dir(
        out,
        &op,
        &squeal_io::OperatorMeta {
            scene: prep.scene.name.clone(),
            mu,
            active_pairs: active,
            source: format!(
                "squeal {} export of {file}: equilibrium `{equilibrium}` with `{law}`{} at mu = {mu}",
                env!("CARGO_PKG_VERSION"),
                if law_params.0.is_empty() {
                    String::new()
                } else {
                    format!(" ({law_params})")
                },
            ),
        },
    )?;
    let c =
        squeal_contact::damping_matrix(&prep.model, &prep.set, &eq.eq.active, &prep.scene.damping)?;
    squeal_contact::files::write_full_form(
        out,
        &prep.model.m,
        c.as_ref(),
        &prep.model.k,
        &prep.set,
        &eq.eq.active,
    )?;
    let readme = out.join("README.txt");
    let mut text = std::fs::read_to_string(&readme).unwrap_or_default();
    text.push_str(&format!(
        "\nFULL FORM (the same operator before elimination)\n\
         M.mtx, K.mtx: mass (kg) and stiffness (N/m) on the {} free DOFs of the model\n\
         (Dirichlet DOFs eliminated); {}.\n\
         pairs.csv: one row per candidate contact pair ({} pairs, {active} active at mu = {mu}):\n\
         pin_dof_x..z, disc_dof_x..z (0-based rows of M and K), x_m, y_m (position), nx, ny, nz\n\
         (normal, +z from the disc into the pin), ex, ey, ez (unit sliding direction: the disc's\n\
         surface velocity), active (1 = in the effective contact set).\n\
         The constrained form eliminates each active pair's pin-normal DOF onto its disc\n\
         partner (T.txt: constrained index of every full DOF) and keeps the friction parts\n\
         apart. `squeal stability --operator DIR` reads the constrained form when present and\n\
         builds it from the full form otherwise.\n",
        prep.model.dofs.n_free(),
        if c.is_some() {
            "C.mtx: damping (N s/m) of the scene's [damping] for this active set"
        } else {
            "no damping in this scene, so no C.mtx"
        },
        prep.set.len()
    ));
    std::fs::write(&readme, text)?;
    println!(
        "wrote {}: constrained operator ({} DOFs) and full form ({} DOFs, {} pairs, {active} active) at mu = {mu}",
        out.display(),
        op.dim(),
        prep.model.dofs.n_free(),
        prep.set.len()
    );
    Ok(())
}
