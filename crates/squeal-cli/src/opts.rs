//! Options and helpers every command shares: the scene argument, the band, plugin
//! parameters and the output directory. One name, meaning and default each.

use anyhow::{Context, Result};
use squeal_scene::Scene;
use std::path::Path;

/// The scene a command works on.
#[derive(clap::Args, Debug, Clone)]
pub struct SceneArg {
    /// Scene file (TOML) or embedded scene name (`squeal scene list`); default: the
    /// embedded `pin-on-disc`.
    pub scene: Option<String>,
}

impl SceneArg {
    /// Loads the scene (a notice on stderr when none was given).
    pub fn load(&self) -> Result<(Scene, String)> {
        load_scene(self.scene.as_deref())
    }

    /// The argument as given.
    pub fn as_deref(&self) -> Option<&str> {
        self.scene.as_deref()
    }
}

/// Loads a scene: a file path, else an embedded name, else the default (with a notice
/// naming it, its size and where the others are listed).
pub fn load_scene(arg: Option<&str>) -> Result<(Scene, String)> {
    match arg {
        None => {
            eprintln!(
                "no SCENE given: using the embedded `pin-on-disc` (the full rig, minutes per \
                 analysis; `squeal scene list` shows the smaller ones)"
            );
            Ok((
                Scene::builtin("pin-on-disc")?,
                "<builtin pin-on-disc>".into(),
            ))
        }
        Some(a) if Path::new(a).is_file() => Ok((Scene::from_file(Path::new(a))?, a.to_string())),
        Some(a) if Path::new(a).is_dir() => {
            anyhow::bail!(
                "SCENE {a}: is a directory, expected a scene file (TOML) or an embedded scene name"
            )
        }
        Some(a) if !a.ends_with(".toml") => Ok((Scene::builtin(a)?, format!("<builtin {a}>"))),
        Some(a) => Err(anyhow::anyhow!("SCENE {a}: no such scene file")),
    }
}

/// Parses `FMIN:FMAX` (Hz) for option `flag`.
pub fn parse_band_for(flag: &str, text: &str) -> Result<[f64; 2]> {
    let (a, b) = text
        .split_once(':')
        .with_context(|| format!("{flag} `{text}`: expected FMIN:FMAX in Hz, e.g. 0:5000"))?;
    let parse = |s: &str| -> Result<f64> {
        s.trim()
            .parse::<f64>()
            .with_context(|| format!("{flag} `{text}`: `{s}` is not a frequency in Hz"))
    };
    let band = [parse(a)?, parse(b)?];
    if !(band[0] >= 0.0 && band[1] > band[0] && band[1].is_finite()) {
        anyhow::bail!("{flag} `{text}`: expected 0 <= FMIN < FMAX (Hz)");
    }
    Ok(band)
}

/// Parses `FMIN:FMAX` (Hz) of `--band`.
pub fn parse_band(text: &str) -> Result<[f64; 2]> {
    parse_band_for("--band", text)
}

/// Refuses a `--band` whose top lies far above what the scene's mesh resolves (it would
/// ask for modes the mesh cannot represent, and for the whole spectrum).
pub fn check_band_against(band: [f64; 2], scene: &Scene) -> Result<()> {
    let top = 10.0 * scene.mesh.max_freq_hz;
    if band[1] > top {
        anyhow::bail!(
            "--band {}:{}: the scene's mesh resolves up to {} Hz (mesh.max_freq_hz); expected a \
             band top <= {top} Hz",
            band[0],
            band[1],
            scene.mesh.max_freq_hz
        );
    }
    Ok(())
}

/// Parses `key=value` options into plugin parameters.
pub fn parse_params(opts: &[String]) -> Result<squeal_core::Params> {
    let mut p = squeal_core::Params::new();
    for kv in opts {
        let (k, v) = squeal_core::Params::parse_kv(kv)?;
        p.0.insert(k, v);
    }
    Ok(p)
}

/// A library error about an output directory as the CLI names it: `--out DIR: ...`.
pub fn out_error(e: squeal_analysis::outdir::RunError) -> anyhow::Error {
    match e {
        squeal_analysis::outdir::RunError::Dir { .. } => anyhow::anyhow!("--out {e}"),
        e => e.into(),
    }
}

/// The band every command uses unless told otherwise: the scene's `study.band_hz`, or
/// this for an operator read from files (Hz).
pub const OPERATOR_BAND_HZ: [f64; 2] = [0.0, 5000.0];

/// How the complex modes are computed: basis, eigen solver, band, tolerance, threshold.
#[derive(clap::Args, Debug, Clone)]
pub struct MethodArgs {
    /// Reduction basis plugin (`squeal plugins`), or `none` for full order.
    #[arg(long, default_value = "none")]
    pub basis: String,
    /// Basis parameters `key=value` (e.g. `cutoff_factor=2`).
    #[arg(long = "basis-opt")]
    pub basis_opt: Vec<String>,
    /// Eigen solver plugin; default `arpack` for full order, `dense` for the reduced
    /// problem of a basis.
    #[arg(long)]
    pub eigen: Option<String>,
    /// Frequency band `FMIN:FMAX` (Hz); default: the scene's `study.band_hz`.
    #[arg(long)]
    pub band: Option<String>,
    /// Relative tolerance of the eigen solvers.
    #[arg(long, default_value = "1e-10")]
    pub tol: f64,
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    #[arg(long, visible_alias = "dvr-tol", default_value = "0")]
    pub dvr_margin: f64,
}

impl MethodArgs {
    /// The eigen solver: given, else `arpack` (full order) or `dense` (reduced).
    pub fn eigen(&self) -> String {
        self.eigen.clone().unwrap_or_else(|| {
            if self.basis == "none" {
                "arpack"
            } else {
                "dense"
            }
            .to_string()
        })
    }

    /// The band: `--band`, else `default` (the scene's).
    pub fn band(&self, default: [f64; 2]) -> Result<[f64; 2]> {
        match &self.band {
            Some(b) => parse_band(b),
            None => Ok(default),
        }
    }

    /// The band of a scene: `--band` (within what the scene's mesh resolves), else the
    /// scene's `study.band_hz`.
    pub fn band_of(&self, scene: &Scene) -> Result<[f64; 2]> {
        let band = self.band(scene.study.band_hz)?;
        check_band_against(band, scene)?;
        Ok(band)
    }

    /// The basis parameters.
    pub fn basis_params(&self) -> Result<squeal_core::Params> {
        parse_params(&self.basis_opt).context("--basis-opt")
    }

    /// Checks every option against the registry before any work: plugin names, basis
    /// parameters, tolerances, the band's syntax.
    pub fn check(&self, registry: &squeal_core::Registry) -> Result<()> {
        if let Some(b) = &self.band {
            parse_band(b)?;
        }
        check_tol("--tol", self.tol)?;
        if !(self.dvr_margin.is_finite() && self.dvr_margin >= 0.0) {
            anyhow::bail!("--dvr-margin {}: expected a number >= 0", self.dvr_margin);
        }
        if self.basis == "none" {
            if !self.basis_opt.is_empty() {
                anyhow::bail!("--basis-opt: full order (--basis none) takes no basis parameters; give --basis NAME");
            }
        } else {
            registry
                .bases
                .create(&self.basis, &self.basis_params()?)
                .map_err(|e| anyhow::anyhow!("--basis {}: {e}", self.basis))?;
        }
        let eigen = self.eigen();
        registry
            .eigen
            .create(&eigen, &squeal_core::Params::new())
            .map_err(|e| anyhow::anyhow!("--eigen {eigen}: {e}"))?;
        Ok(())
    }
}

/// A relative tolerance in (0, 1).
pub fn check_tol(flag: &str, t: f64) -> Result<()> {
    if t > 0.0 && t < 1.0 {
        Ok(())
    } else {
        anyhow::bail!("{flag} {t}: expected a relative tolerance in (0, 1), e.g. 1e-10")
    }
}

/// The contact solvers of the sliding equilibrium.
#[derive(clap::Args, Debug, Clone)]
pub struct ContactArgs {
    /// Equilibrium solver plugin (`lcp`, `lorang`).
    #[arg(long, default_value = "lcp")]
    pub equilibrium: String,
    /// Contact law plugin (`lagrange`, `penalty`).
    #[arg(long, default_value = "lagrange")]
    pub law: String,
    /// Contact law parameters, `key=value` (e.g. `kn_n_per_m=1e8` for `penalty`: the
    /// normal stiffness per pair, N/m).
    #[arg(long = "law-opt")]
    pub law_opt: Vec<String>,
}

impl ContactArgs {
    /// Checks the plugin names and the law's parameters.
    pub fn check(&self, registry: &squeal_core::Registry) -> Result<()> {
        registry
            .equilibrium
            .create(&self.equilibrium, &squeal_core::Params::new())
            .map_err(|e| anyhow::anyhow!("--equilibrium {}: {e}", self.equilibrium))?;
        registry
            .contact_laws
            .create(&self.law, &self.law_params()?)
            .map_err(|e| anyhow::anyhow!("--law {} --law-opt: {e}", self.law))?;
        Ok(())
    }

    /// The contact law's parameters (`--law-opt`).
    pub fn law_params(&self) -> Result<squeal_core::Params> {
        parse_params(&self.law_opt).map_err(|e| anyhow::anyhow!("--law-opt: {e}"))
    }
}

/// The `[k/N, ETA ...]` prefix of progress lines: the rate of the items computed in this
/// run (items finished before a resume count as done, not in the rate).
pub struct Eta {
    /// When the first item computed in this run finished: the rate is measured from there,
    /// so a long set-up before the first item does not inflate the estimate.
    first: Option<std::time::Instant>,
    total: usize,
    done: usize,
    before: usize,
}

impl Eta {
    /// `total` items, `before` of them finished by an earlier run.
    pub fn new(total: usize, before: usize) -> Self {
        Self {
            first: None,
            total,
            done: 0,
            before,
        }
    }

    /// One more item finished: the prefix to print (the estimate from the second item
    /// computed in this run on).
    pub fn tick(&mut self) -> String {
        self.done += 1;
        let k = self.done.min(self.total);
        let computed = self.done.saturating_sub(self.before);
        let left = self.total.saturating_sub(self.done);
        if computed == 1 {
            self.first = Some(std::time::Instant::now());
        }
        match self.first {
            Some(first) if computed >= 2 && left > 0 => {
                let per = first.elapsed().as_secs_f64() / (computed - 1) as f64;
                format!("[{k}/{}, ETA {}]", self.total, duration(per * left as f64))
            }
            _ => format!("[{k}/{}]", self.total),
        }
    }
}

/// A duration for people: `42 s`, `3 min 20 s`, `2 h 05 min`.
pub fn duration(s: f64) -> String {
    let s = s.max(0.0).round() as u64;
    if s < 60 {
        format!("{s} s")
    } else if s < 3600 {
        format!("{} min {:02} s", s / 60, s % 60)
    } else {
        format!("{} h {:02} min", s / 3600, (s % 3600) / 60)
    }
}

/// Claims `out` for `command`: creates it and records the command there; refuses a
/// directory another command wrote ([`squeal_analysis::outdir::claim`]).
pub fn claim_out(out: &Path, command: &str) -> Result<()> {
    squeal_analysis::outdir::claim(out, command).map_err(out_error)
}

/// Checks a friction coefficient given as option `flag`.
pub fn check_mu(flag: &str, mu: f64) -> Result<()> {
    match squeal_contact::check_user_mu(mu) {
        Ok(()) => Ok(()),
        Err(squeal_contact::ContactError::Setup { message, .. }) => {
            anyhow::bail!("{flag} {mu}: {message}")
        }
        Err(e) => Err(e.into()),
    }
}

/// What Ctrl-C prints before the process ends: set by a command that keeps its finished
/// results (checkpoints) so the user knows how to continue.
static RESUME_HINT: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Installs the Ctrl-C handler (once, at start-up): it prints the resume hint of the
/// running command, if any, and exits with status 130.
pub fn install_interrupt_handler() {
    let _ = ctrlc::set_handler(|| {
        let hint = RESUME_HINT.lock().ok().and_then(|h| h.clone());
        match hint {
            Some(h) => eprintln!("\ninterrupted: {h}"),
            None => eprintln!("\ninterrupted"),
        }
        std::process::exit(130);
    });
}

/// Tells the Ctrl-C handler how to continue this run: finished results are in `out`,
/// the same command with `--resume` continues it.
pub fn set_resume_hint(out: &Path) {
    if let Ok(mut h) = RESUME_HINT.lock() {
        *h = Some(format!(
            "the finished results are kept in {}; run the same command with --resume to continue",
            out.display()
        ));
    }
}

/// Parses `--param NAME=VALUE` (the value of a parametric operator's parameter).
pub fn parse_param(text: &str) -> Result<(String, f64)> {
    let (name, value) = text.split_once('=').with_context(|| {
        format!("--param {text}: expected NAME=VALUE with the operator's parameter, e.g. W=5")
    })?;
    let name = name.trim();
    if name.is_empty() {
        anyhow::bail!("--param {text}: expected NAME=VALUE with a parameter name before `=`");
    }
    let v = value
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .with_context(|| format!("--param {text}: `{}` is not a finite number", value.trim()))?;
    Ok((name.to_string(), v))
}

/// Reads the parametric operator directory of option `--operator DIR` and checks that it
/// declares the parameter `name` (given as option `flag`, e.g. `--param W=5`).
pub fn read_parametric(
    dir: &Path,
    name: &str,
    flag: &str,
) -> Result<squeal_io::ParametricOperator> {
    let p = squeal_io::ParametricOperator::read(dir)
        .map_err(|e| anyhow::anyhow!("--operator {}: {e}", dir.display()))?;
    match p.parameter() {
        None => anyhow::bail!(
            "{flag}: --operator {} is not a parametric operator (no `format = \"{}\"` and \
             `parameter` in its operator.toml, see docs/operators.md); drop {flag}",
            dir.display(),
            squeal_io::PARAMETRIC_FORMAT
        ),
        Some(p_name) if p_name != name => anyhow::bail!(
            "{flag}: the operator in {} declares the parameter `{p_name}`, not `{name}`",
            dir.display()
        ),
        Some(_) => Ok(p),
    }
}

/// The operator of `--operator DIR` at `--param NAME=VALUE` (`param` as given), or the
/// fixed operator of `DIR` without it; a parametric directory without `--param` is
/// refused, naming its parameter.
pub fn read_operator_at(
    dir: &Path,
    param: Option<&str>,
) -> Result<squeal_core::FrictionalOperator> {
    let Some(text) = param else {
        // only a description naming the parametric format is worth reading in full
        let toml = std::fs::read_to_string(dir.join("operator.toml")).unwrap_or_default();
        if toml.contains(squeal_io::PARAMETRIC_FORMAT) {
            let p = squeal_io::ParametricOperator::read(dir)
                .map_err(|e| anyhow::anyhow!("--operator {}: {e}", dir.display()))?;
            if let Some(name) = p.parameter() {
                let range = p
                    .range()
                    .map_or(String::new(), |(a, b)| format!(" in [{a}, {b}]"));
                anyhow::bail!(
                    "--operator {}: a parametric operator (parameter `{name}`{range}): give \
                     --param {name}=VALUE",
                    dir.display()
                );
            }
        }
        return crate::stability::read_operator_any(dir);
    };
    let (name, value) = parse_param(text)?;
    let flag = format!("--param {text}");
    let p = read_parametric(dir, &name, &flag)?;
    let op = p.at(value).map_err(|e| anyhow::anyhow!("{flag}: {e}"))?;
    op.check_pencil()
        .map_err(|e| anyhow::anyhow!("--operator {} at {flag}: {e}", dir.display()))?;
    Ok(op)
}

#[cfg(test)]
mod tests {
    use super::{duration, Eta};

    #[test]
    fn eta_starts_after_the_first_item_computed_and_skips_resumed_ones() {
        // 2 of 5 items read back from an earlier run
        let mut eta = Eta::new(5, 2);
        assert_eq!(eta.tick(), "[1/5]");
        assert_eq!(eta.tick(), "[2/5]");
        // the first computed item (its time includes any set-up): no estimate yet
        assert_eq!(eta.tick(), "[3/5]");
        let second = eta.tick();
        assert!(second.starts_with("[4/5, ETA "), "{second}");
        // the last item: nothing left to estimate
        assert_eq!(eta.tick(), "[5/5]");
    }

    #[test]
    fn durations_read_in_the_largest_sensible_units() {
        assert_eq!(duration(42.4), "42 s");
        assert_eq!(duration(200.0), "3 min 20 s");
        assert_eq!(duration(7500.0), "2 h 05 min");
        assert_eq!(duration(-1.0), "0 s");
    }
}
