//! `squeal bench`: every registered basis x eigen solver on the same frictional operator
//! against the full-order reference, and the stress set (`--stress`).

use anyhow::{Context, Result};
use squeal_analysis::bench::{
    bound_threshold, run_suite, stress_rows, Accuracy, BenchOptions, BenchRun, BenchSource,
    MemoryProbe, StressRow, SuiteEvent, SuiteSettings,
};
use squeal_analysis::outdir::RunError;
use squeal_analysis::pipeline::Prepared;
use squeal_core::Registry;
use std::path::{Path, PathBuf};

/// The counting allocator of the binary, as a [`MemoryProbe`].
pub struct HeapProbe(pub &'static peak_alloc::PeakAlloc);

impl MemoryProbe for HeapProbe {
    fn reset(&self) -> usize {
        self.0.reset_peak_usage();
        self.0.current_usage()
    }
    fn peak(&self) -> usize {
        self.0.peak_usage()
    }
}

/// `squeal bench`.
#[derive(clap::Args)]
pub struct BenchArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Operator directory (as written by `squeal export`, or parametric with --param)
    /// instead of a scene.
    #[arg(long)]
    operator: Option<PathBuf>,
    /// The parameter of a parametric operator directory (--operator), `NAME=VALUE` with
    /// the name its operator.toml declares, e.g. `W=5`.
    #[arg(long, value_name = "NAME=VALUE")]
    param: Option<String>,
    /// Condition numbers and forward error estimates also for full-order modes above 1000
    /// DOFs (reference included; one extra factorization per mode, timed apart as
    /// `condition_s`): without it those runs have no `error_bound`.
    #[arg(long)]
    condition: bool,
    /// Friction coefficients, comma separated (one operator each).
    #[arg(long, value_delimiter = ',', default_value = "0.3,0.7")]
    mu: Vec<f64>,
    /// Bases, comma separated (`none` = full order); default: `none` and every
    /// registered basis.
    #[arg(long, value_delimiter = ',')]
    bases: Vec<String>,
    /// Eigen solvers, comma separated; default: every registered one.
    #[arg(long, value_delimiter = ',')]
    eigens: Vec<String>,
    /// Basis parameter variants run besides the defaults, `key=v1,v2` (by every basis
    /// that accepts the key); `--vary none` for defaults only.
    #[arg(long, default_value = "cutoff_factor=2.5")]
    vary: Vec<String>,
    /// Frequency band `FMIN:FMAX` (Hz); default: the scene's `study.band_hz`.
    #[arg(long)]
    band: Option<String>,
    /// Relative tolerance of the benchmarked eigen solvers.
    #[arg(long, default_value = "1e-10")]
    tol: f64,
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    #[arg(long, visible_alias = "dvr-tol", default_value = "0")]
    dvr_margin: f64,
    /// Full-order reference solver.
    #[arg(long, default_value = "arpack")]
    reference: String,
    /// Tolerance of the reference.
    #[arg(long, default_value = "1e-12")]
    reference_tol: f64,
    /// Run the stress set (cases built to break methods) instead of the mu list.
    #[arg(long)]
    stress: bool,
    /// Only redraw the charts (and the stress table) from the `bench.json` or
    /// `stress.json` already in `--out`, without solving anything.
    #[arg(long)]
    replot: bool,
    #[command(flatten)]
    contact: crate::opts::ContactArgs,
    /// Output directory.
    #[arg(long, default_value = "out/bench")]
    out: PathBuf,
}

impl BenchArgs {
    /// Runs the bench (every option checked first).
    pub fn run(&self, registry: &Registry, heap: &'static peak_alloc::PeakAlloc) -> Result<()> {
        if self.replot {
            return replot(&self.out, self.stress);
        }
        if let Some(p) = &self.param {
            crate::opts::parse_param(p)?;
            if self.operator.is_none() {
                anyhow::bail!(
                    "--param {p}: needs --operator DIR (a parametric operator directory), not a scene"
                );
            }
        }
        let mut opts = BenchOptions::all(registry);
        if !self.bases.is_empty() {
            opts.bases = self.bases.clone();
        }
        if !self.eigens.is_empty() {
            opts.eigens = self.eigens.clone();
        }
        for name in opts.bases.iter().filter(|b| *b != "none") {
            registry
                .bases
                .create(name, &squeal_core::Params::new())
                .map_err(|e| anyhow::anyhow!("--bases {name}: {e}"))?;
        }
        for name in &opts.eigens {
            registry
                .eigen
                .create(name, &squeal_core::Params::new())
                .map_err(|e| anyhow::anyhow!("--eigens {name}: {e}"))?;
        }
        registry
            .eigen
            .create(&self.reference, &squeal_core::Params::new())
            .map_err(|e| anyhow::anyhow!("--reference {}: {e}", self.reference))?;
        self.contact.check(registry)?;
        opts.vary = parse_vary(&self.vary)?;
        crate::opts::check_tol("--tol", self.tol)?;
        crate::opts::check_tol("--reference-tol", self.reference_tol)?;
        if !(self.dvr_margin.is_finite() && self.dvr_margin >= 0.0) {
            anyhow::bail!("--dvr-margin {}: expected a number >= 0", self.dvr_margin);
        }
        for &mu in &self.mu {
            crate::opts::check_mu("--mu", mu)?;
        }
        let band = self
            .band
            .as_deref()
            .map(crate::opts::parse_band)
            .transpose()?;
        opts.tol = self.tol;
        opts.dvr_margin = self.dvr_margin;
        opts.reference_eigen = self.reference.clone();
        opts.reference_tol = self.reference_tol;
        opts.condition = self.condition;
        let probe = HeapProbe(heap);
        run(
            registry,
            &Args {
                scene: self.scene.as_deref(),
                operator: self.operator.as_deref(),
                param: self.param.as_deref(),
                mus: &self.mu,
                out: &self.out,
                opts,
                band,
                contact: &self.contact,
                stress: self.stress,
            },
            Some(&probe),
        )
    }
}

/// Inputs of `squeal bench`.
pub struct Args<'a> {
    pub scene: Option<&'a str>,
    pub operator: Option<&'a Path>,
    /// `--param NAME=VALUE` of a parametric operator directory, as given.
    pub param: Option<&'a str>,
    pub mus: &'a [f64],
    pub out: &'a Path,
    pub opts: BenchOptions,
    /// `None`: the scene's `study.band_hz` (operator files: the default band).
    pub band: Option<[f64; 2]>,
    /// Equilibrium solver, contact law and its parameters.
    pub contact: &'a crate::opts::ContactArgs,
    pub stress: bool,
}

fn print_run(r: &BenchRun) {
    let opts = if r.basis_opts.is_empty() {
        String::new()
    } else {
        format!(" [{}]", r.basis_opts)
    };
    if r.status != "ok" {
        println!(
            "  {:<26} {}",
            format!("{}/{}{opts}", r.basis, r.eigen),
            r.status
        );
        return;
    }
    let split = match (r.reduced_solve_s, r.expansion_s) {
        (Some(a), Some(b)) => format!(" (reduced {a:.2} + expansion {b:.2})"),
        _ => String::new(),
    };
    println!(
        "  {:<26} n={:<6} setup {:>7.2} s  solve {:>7.2} s{split}  df/f {:>8.1e}  \
         dDvR {:>8.1e}  missed {} modes, {} unstable; false unstable {}; {} neutral  \
         bwd {:>8.1e}  bound {:>8}  {}{}",
        format!("{}/{}{opts}", r.basis, r.eigen),
        if r.basis_size == 0 {
            r.dofs
        } else {
            r.basis_size
        },
        r.setup_s,
        r.solve_s,
        r.errors.max_rel_freq_err,
        r.errors.max_abs_dvr_err,
        r.errors.missed_modes,
        r.errors.missed_unstable,
        r.errors.false_unstable,
        r.errors.neutral,
        r.errors.max_backward_error,
        crate::stability::sci(r.errors.max_error_bound),
        times(r.solve_speedup),
        if r.accurate { "" } else { "  (not accurate)" }
    );
}

/// A speed ratio with two significant digits: `x64`, `x2.5`, `x0.042`.
fn times(x: f64) -> String {
    if !x.is_finite() || x <= 0.0 {
        return "-".into();
    }
    // decimals for two significant digits (none from 10 up)
    let digits = |v: f64| (1 - v.log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.*}", digits(x));
    // rounding into the next decade (9.96 -> 10.0) needs one decimal less
    let v: f64 = s.parse().unwrap_or(x);
    format!("x{v:.*}", digits(v))
}

/// Redraws the charts (or the stress table) of a finished run from its `bench.json`
/// (`stress.json`) in `out`.
pub fn replot(out: &Path, stress: bool) -> Result<()> {
    let json = out.join(if stress { "stress.json" } else { "bench.json" });
    let text = std::fs::read_to_string(&json)
        .with_context(|| format!("--replot: reading {} (run the bench first)", json.display()))?;
    let runs: Vec<BenchRun> = serde_json::from_str(&text)
        .with_context(|| format!("--replot: {} is not a list of bench runs", json.display()))?;
    let files = if stress {
        stress_report(out, &runs)?
    } else {
        crate::bench_charts::charts(out, &runs)?
    };
    println!("redrew {} files in {}", files.len(), out.display());
    Ok(())
}

/// Runs the bench (or the stress set), prints each run and writes its outputs and charts.
pub fn run(registry: &Registry, a: &Args<'_>, probe: Option<&dyn MemoryProbe>) -> Result<()> {
    // an operator directory is read (and checked) before anything is written
    let operator = match a.operator {
        Some(dir) => {
            if a.scene.is_some() {
                anyhow::bail!("give either a scene or --operator DIR, not both");
            }
            if a.stress {
                anyhow::bail!(
                    "--stress changes the contact zone and mu: it needs a scene, not --operator"
                );
            }
            Some(BenchSource::Operator {
                name: match a.param {
                    Some(p) => format!("{} at {p}", dir.display()),
                    None => dir.display().to_string(),
                },
                op: Box::new(crate::opts::read_operator_at(dir, a.param)?),
            })
        }
        None => None,
    };
    crate::opts::claim_out(a.out, "bench")?;
    let src = match operator {
        Some(src) => src,
        None => {
            let (scene, file) = crate::opts::load_scene(a.scene)?;
            BenchSource::Scene(Box::new(Prepared::new(registry, scene, &file)?))
        }
    };
    // the band: given, or the scene's (operator files: the default)
    let mut opts = a.opts.clone();
    opts.band_hz = a.band.unwrap_or(match &src {
        BenchSource::Scene(prep) => prep.scene.study.band_hz,
        BenchSource::Operator { .. } => crate::opts::OPERATOR_BAND_HZ,
    });
    if let BenchSource::Scene(prep) = &src {
        crate::opts::check_band_against(opts.band_hz, &prep.scene)?;
    }
    let settings = SuiteSettings {
        mus: a.mus.to_vec(),
        opts,
        equilibrium: a.contact.equilibrium.clone(),
        law: a.contact.law.clone(),
        law_params: a.contact.law_params()?,
        stress: a.stress,
    };
    let (_, summary) = run_suite(
        registry,
        &src,
        &settings,
        a.out,
        probe,
        |e| match e {
            SuiteEvent::Stage(s) => println!(
                "model stage `{}`: built once in {:.1} s, shared by every case (not in the run \
                 times)",
                s.key, s.time_s
            ),
            SuiteEvent::Case(case, what) => println!("case {case}: {what}"),
            SuiteEvent::Run(r) => print_run(r),
            SuiteEvent::Reference(r) => println!(
                "  reference `{}`: {} modes in band, {} unstable, {} neutral within their \
                 error bound, {:.1} s",
                r.eigen,
                r.modes,
                r.unstable.len(),
                r.neutral.len(),
                r.time_s
            ),
        },
        |runs| {
            if a.stress {
                stress_report(a.out, runs)
            } else {
                crate::bench_charts::charts(a.out, runs)
            }
            .map_err(|e| RunError::Output(format!("{e:#}")))
        },
    )
    .map_err(|e| match e {
        RunError::Input { field, message } => anyhow::anyhow!("--{field}: {message}"),
        e => crate::opts::out_error(e),
    })?;
    if !a.stress {
        println!("\nspeed-up over the reference at equal accuracy (fastest accurate run):");
        for r in &summary.speed_ratios {
            println!(
                "  {:<8} {:<22} {:<20} total {:<9} per mu {}",
                r.case,
                r.method,
                r.basis_opts,
                times(r.speedup),
                times(r.solve_speedup)
            );
        }
    }
    let stem = if a.stress { "stress" } else { "bench" };
    println!(
        "wrote {}, {} and {} charts in {:.1} s",
        a.out.join(format!("{stem}.json")).display(),
        a.out.join(format!("{stem}-summary.json")).display(),
        summary.charts.len(),
        summary.time_s
    );
    Ok(())
}

/// The stress table: per case and method, whether it is wrong; whether its own error
/// estimate (the worst backward error) rose against the baseline case; its worst
/// condition number and forward error estimate (`error_bound`), and, where it is wrong,
/// whether that bound flagged it: the bound covers every matched mode's actual eigenvalue
/// error and no mode was missed, or the bound exceeds the accuracy threshold
/// ([`bound_threshold`]). Printed, and written to `stress-table.txt` and
/// `stress-table.json`.
fn stress_report(out: &Path, runs: &[BenchRun]) -> Result<Vec<PathBuf>> {
    let threshold = bound_threshold(&Accuracy::default());
    let rows = stress_rows(runs);
    let mut text = format!(
        "stress set: where each method is wrong; whether its backward error rose >= 10x over \
         the baseline case (flagged); its worst cond and error_bound (relative eigenvalue \
         error estimate) against the actual worst relative eigenvalue error; for a WRONG run, \
         whether the bound flagged it (it covers every matched mode's error with no mode \
         missed, or exceeds {threshold:.0e})\n"
    );
    text.push_str(&format!(
        "  {:<10} {:<36} {:<6} {:>10} {:>9} {:<7} {:>9} {:>9} {:>9} {:<7} why\n",
        "case",
        "method",
        "wrong",
        "bwd err",
        "x base",
        "flagged",
        "cond",
        "bound",
        "actual",
        "bound?"
    ));
    for r in &rows {
        text.push_str(&format!(
            "  {:<10} {:<36} {:<6} {:>10.1e} {:>9.1} {:<7} {:>9} {:>9} {:>9} {:<7} {}\n",
            r.case,
            format!(
                "{}{}",
                r.method,
                if r.basis_opts.is_empty() {
                    String::new()
                } else {
                    format!(" [{}]", r.basis_opts)
                }
            ),
            if r.failed {
                "failed"
            } else if r.wrong {
                "WRONG"
            } else {
                "ok"
            },
            r.max_backward_error,
            r.estimate_ratio,
            if r.flagged { "yes" } else { "no" },
            crate::stability::sci(r.cond),
            crate::stability::sci(r.error_bound),
            crate::stability::sci(r.actual_error),
            match r.bound_flagged {
                Some(true) => "yes",
                Some(false) => "NO",
                None => "-",
            },
            r.why.join("; ")
        ));
    }
    let wrong = rows.iter().filter(|r| r.wrong).count();
    let flagged = rows
        .iter()
        .filter(|r| r.bound_flagged == Some(true))
        .count();
    let unbounded = rows
        .iter()
        .filter(|r| r.wrong && r.bound_flagged.is_none())
        .count();
    let accurate: Vec<&StressRow> = rows.iter().filter(|r| !r.wrong && !r.failed).collect();
    let alarms = accurate
        .iter()
        .filter(|r| r.error_bound > threshold)
        .count();
    text.push_str(&format!(
        "wrong runs: {wrong}, flagged by their bound: {flagged}{}; accurate runs whose bound \
         exceeds {threshold:.0e} (false alarms): {alarms} of {}; matched modes above their \
         own bound: {}\n",
        if unbounded > 0 {
            format!(" ({unbounded} without bounds: full order above 1000 DOFs, see --condition)")
        } else {
            String::new()
        },
        accurate.len(),
        rows.iter().map(|r| r.above_bound).sum::<usize>()
    ));
    println!("\n{text}");
    let txt = out.join("stress-table.txt");
    std::fs::write(&txt, &text).with_context(|| format!("writing {}", txt.display()))?;
    let path = out.join("stress-table.json");
    std::fs::write(&path, serde_json::to_string_pretty(&rows)?)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(vec![txt, path])
}

/// Parses `--vary key=v1,v2` options (`none` for no variant).
pub fn parse_vary(items: &[String]) -> Result<Vec<(String, Vec<f64>)>> {
    let mut out = Vec::new();
    for item in items.iter().filter(|i| i.as_str() != "none") {
        let (k, vs) = item.split_once('=').with_context(|| {
            format!("--vary `{item}`: expected key=v1,v2 (e.g. cutoff_factor=2,3)")
        })?;
        let values = vs
            .split(',')
            .map(|v| {
                v.trim()
                    .parse::<f64>()
                    .with_context(|| format!("--vary `{item}`: `{v}` is not a number"))
            })
            .collect::<Result<Vec<f64>>>()?;
        out.push((k.trim().to_string(), values));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::times;

    #[test]
    fn speed_ups_keep_two_significant_digits() {
        assert_eq!(times(64.4), "x64");
        assert_eq!(times(2.54), "x2.5");
        assert_eq!(times(0.42), "x0.42");
        assert_eq!(times(0.042), "x0.042");
        assert_eq!(times(0.0131), "x0.013");
        assert_eq!(times(9.96), "x10");
        assert_eq!(times(0.996), "x1.0");
        // never x0.0: the printed ratio is within 5 % of the true one, however small
        for x in [0.04, 0.004, 4e-5, 0.0999, 0.049, 0.951, 1.04] {
            let t = times(x);
            let v: f64 = t[1..].parse().unwrap_or_else(|_| panic!("{x}: {t}"));
            assert!((v / x - 1.0).abs() < 0.05, "{x}: {t}");
        }
        assert_eq!(times(0.0), "-");
        assert_eq!(times(f64::NAN), "-");
    }
}
