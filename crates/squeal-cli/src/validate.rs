//! `squeal validate`: the uniform-contact validation of the paper, the project's main job.
//!
//! Stages (each writes into its own folder of the report directory), one prepared model
//! for all of them:
//! 1. `disc/`: the disc's free-interface modes against the paper's Table 2;
//! 2. the rig: the pin assembly's modes below 10 kHz and the axial stiffness against the
//!    paper's load datum (200 N at 125 um);
//! 3. `equilibrium/`: sliding equilibria and contact force maps for mu = 0 ... 0.8;
//! 4. `sweep-<basis>/`: the mu sweep through the figure basis at `--step` (the paper's
//!    Figure 5 and its couplings) and through each check basis at `--check-step`;
//! 5. full-order solves at `--reference-mu`, every basis compared with them (matched mode
//!    by mode: `squeal_analysis::bench::compare`);
//! 6. `report.md`, `report.json` (with the time of each stage and the peak memory) and a
//!    paper-vs-squeal table on stdout.

use anyhow::{Context, Result};
use serde::Serialize;
use squeal_analysis::bench::{compare, ModeErrors};
use squeal_analysis::mu_sweep::{matching_coupling, mu_list, MuSweepSettings};
use squeal_analysis::pipeline::{Method, Prepared};
use squeal_analysis::profile::{peak_rss_mb, Profile};
use squeal_analysis::reference::paper;
use squeal_core::{EigenParams, Registry};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

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
    /// Step of the check sweeps.
    #[arg(long, default_value = "0.1")]
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
        for b in std::iter::once(&self.figure_basis).chain(&checks) {
            registry
                .bases
                .create(b, &squeal_core::Params::new())
                .map_err(|e| anyhow::anyhow!("--figure-basis/--bases {b}: {e}"))?;
        }
        let on_grid = |mu: f64, step: f64| ((mu / step) - (mu / step).round()).abs() < 1e-6;
        for &mu in &self.reference_mu {
            crate::opts::check_mu("--reference-mu", mu)?;
            if !(mu <= 0.8
                && on_grid(mu, self.step)
                && (checks.is_empty() || on_grid(mu, self.check_step)))
            {
                anyhow::bail!(
                    "--reference-mu {mu}: expected a point of every sweep (0 to 0.8, multiples of \
                     --step {} and --check-step {})",
                    self.step,
                    self.check_step
                );
            }
        }
        run(
            registry,
            &Args {
                scene: self.scene.as_deref(),
                out: &self.out,
                sweeps: std::iter::once((self.figure_basis.clone(), self.step))
                    .chain(checks.iter().map(|b| (b.clone(), self.check_step)))
                    .collect(),
                band,
                reference_mu: &self.reference_mu,
                eigen: &self.eigen,
                resume: self.resume,
            },
        )
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

/// Options of the validation.
pub struct Args<'a> {
    pub scene: Option<&'a str>,
    pub out: &'a Path,
    /// `(basis, step)` of each sweep, the figure basis first.
    pub sweeps: Vec<(String, f64)>,
    /// Band (Hz) of the sweeps and the reference points; `None`: the scene's.
    pub band: Option<[f64; 2]>,
    pub reference_mu: &'a [f64],
    pub eigen: &'a str,
    /// Continue an interrupted validation.
    pub resume: bool,
}

/// One paper coupling against one sweep.
#[derive(Serialize)]
struct PaperRow {
    paper_freq_hz: f64,
    paper_mu: [f64; 2],
    basis: String,
    step: f64,
    squeal_freq_hz: Option<f64>,
    squeal_mu: Option<[f64; 2]>,
    max_dvr: Option<f64>,
    made_of: Vec<(String, f64)>,
}

/// One basis against full order at one mu.
#[derive(Serialize)]
struct RefRow {
    mu: f64,
    basis: String,
    errors: ModeErrors,
    reference_time_s: f64,
}

pub fn run(registry: &Registry, a: &Args<'_>) -> Result<()> {
    let start = Instant::now();
    crate::opts::claim_out(a.out, "validate")?;
    crate::opts::set_resume_hint(a.out);
    let mut profile = Profile::new();
    // the sub-stages of each sweep, listed after the stages
    let mut detail = Profile::new();
    let mut lap = Instant::now();
    let mut stage = |name: &str, lap: &mut Instant| {
        profile.add(name, lap.elapsed().as_secs_f64());
        *lap = Instant::now();
    };
    let mut md = String::new();
    let (scene, file) = crate::opts::load_scene(a.scene)?;
    let band = a.band.unwrap_or(scene.study.band_hz);
    crate::opts::check_band_against(band, &scene)?;
    let n_stages = 6;
    let _ = writeln!(md, "# squeal validation: uniform contact ({file})\n");
    let _ = writeln!(
        md,
        "Units: SI (Hz, N, m, s). DvR = Re(lambda)/Im(lambda). Generated by squeal {}.\n",
        env!("CARGO_PKG_VERSION")
    );

    // 1. disc modes vs Table 2
    eprintln!("[1/{n_stages}] disc modes vs Table 2");
    let disc = crate::modes::run_scene(
        registry,
        &scene,
        &file,
        squeal_scene::BodyKind::Disc,
        10_500.0,
        "arpack",
        1e-10,
        None,
    )?;
    let rows = squeal_analysis::modal::compare_table2(&disc.modes);
    let table = squeal_analysis::modal::format_table(&rows);
    std::fs::create_dir_all(a.out.join("disc"))?;
    std::fs::write(a.out.join("disc/table2.txt"), &table)?;
    let within = |t: f64| {
        rows.iter()
            .filter(|r| r.rel_err.is_some_and(|e| e.abs() <= t))
            .count()
    };
    let _ = writeln!(
        md,
        "## 1. Disc modes (free friction face) vs Table 2\n\n{} DOFs, `arpack` {:.1} s. {} of {} labels found, {} within 5 %, {} within 10 %.\n\n```\n{table}```\n",
        disc.dofs,
        disc.solve_time_s,
        rows.iter().filter(|r| r.squeal_hz.is_some()).count(),
        rows.len(),
        within(0.05),
        within(0.10)
    );
    stage("disc modes", &mut lap);

    // 2. the rig: pin modes and stiffness
    eprintln!("[2/{n_stages}] the pin assembly's modes and the rig's stiffness");
    let pin = crate::modes::run_scene(
        registry,
        &scene,
        &file,
        squeal_scene::BodyKind::Pin,
        10_000.0,
        "arpack",
        1e-10,
        None,
    )?;
    let pin_below: Vec<&squeal_analysis::modal::ModeRecord> =
        pin.modes.iter().filter(|m| m.freq_hz < 10_000.0).collect();
    let prep = Prepared::new(registry, scene.clone(), &file)?;
    let eq0 = prep.equilibrium(registry, "lcp", "lagrange", 0.0)?;
    let stiffness = eq0.total_normal_force_n / eq0.displacement_m;
    let p = paper();
    let force_at_datum = stiffness * p.load_displacement_m;
    let _ = writeln!(
        md,
        "## 2. The rig\n\nPin assembly: {} modes below 10 kHz (the paper: {}): {}.\n\nAxial stiffness, disc clamp to plate clamps (mu = 0, whole face): {:.3} MN/m, so {:.1} N at {:.0} um (the paper: {:.0} N, {:.2} MN/m).\n",
        pin_below.len(),
        p.pin_modes_below_10khz,
        pin_below
            .iter()
            .map(|m| format!("{:.0} Hz {}", m.freq_hz, m.label))
            .collect::<Vec<_>>()
            .join(", "),
        stiffness / 1e6,
        force_at_datum,
        p.load_displacement_m * 1e6,
        p.load_force_n,
        p.rig_stiffness_n_per_m() / 1e6
    );
    stage("rig", &mut lap);

    // 3. equilibria
    eprintln!("[3/{n_stages}] sliding equilibria");
    let eq_mus = [0.0, 0.2, 0.4, 0.6, 0.8];
    let eqs = crate::equilibrium::run_on(
        registry,
        &prep,
        &eq_mus,
        "lcp",
        "lagrange",
        &squeal_core::Params::new(),
        &a.out.join("equilibrium"),
    )?;
    let _ = writeln!(
        md,
        "## 3. Sliding equilibrium ({})\n",
        scene
            .load
            .normal_force_n
            .map_or("imposed displacement".to_string(), |f| format!("{f} N"))
    );
    let _ = writeln!(md, "![contact maps](equilibrium/contact_map.png)\n");
    let _ = writeln!(
        md,
        "| mu | active pairs | centroid x (mm) | Ft (N) | residual |\n|---|---|---|---|---|"
    );
    for r in &eqs {
        let _ = writeln!(
            md,
            "| {} | {} / {} | {} | {} | {:.1e} |",
            r.mu,
            r.active_pairs,
            r.pairs,
            crate::num::fixed(r.centroid_m[0] * 1e3, 3),
            crate::num::fixed(r.total_tangential_force_n, 2),
            r.residual
        );
    }
    let _ = writeln!(md, "\nLeading edge: {}.\n", eqs[0].leading_edge);
    stage("equilibria", &mut lap);

    // 4. sweeps
    let mut summaries = Vec::new();
    let mut kept = Vec::new();
    let mut paper_rows = Vec::new();
    for (i, (basis, step)) in a.sweeps.iter().enumerate() {
        eprintln!(
            "[4/{n_stages}] mu sweep with basis `{basis}`, step {step} ({} of {})",
            i + 1,
            a.sweeps.len()
        );
        let out = a.out.join(format!("sweep-{basis}"));
        if !a.resume {
            // a new validation: the sweep starts afresh
            for f in [
                "sweep.partial.jsonl",
                "sweep.partial.inputs.json",
                "summary.json",
            ] {
                let _ = std::fs::remove_file(out.join(f));
            }
        }
        let settings = MuSweepSettings {
            keep_modes_at: a.reference_mu.to_vec(),
            ..MuSweepSettings::new(
                mu_list(0.0, 0.8, *step).map_err(anyhow::Error::msg)?,
                basis,
                band,
            )
        };
        let (s, sweep) = crate::sweep::run_on(
            registry,
            &prep,
            &settings,
            [0.0, 0.8, *step],
            &out,
            true,
            &Profile::new(),
        )?;
        for c in &p.couplings {
            let best = matching_coupling(&s.couplings, c.freq_hz);
            paper_rows.push(PaperRow {
                paper_freq_hz: c.freq_hz,
                paper_mu: c.mu_range,
                basis: basis.clone(),
                step: *step,
                squeal_freq_hz: best.map(|c| c.freq_hz),
                squeal_mu: best.map(|c| [c.mu_from, c.mu_to]),
                max_dvr: best.map(|c| c.max_dvr),
                made_of: best.map_or(Vec::new(), |c| c.free_interface_mac.clone()),
            });
        }
        detail.extend_prefixed(&format!("sweep {basis}: "), &sweep.profile);
        // a model stage (the synthesis of `cms`) is the largest thing the model keeps:
        // gone once no sweep ahead works from it (the references reuse the kept modes)
        let ahead = a.sweeps[i + 1..].iter().map(|(b, _)| b.as_str());
        prep.release_stages_except(&squeal_analysis::pipeline::stage_keys(
            registry, ahead, band[1],
        )?);
        kept.push((basis.clone(), sweep.kept));
        summaries.push((basis.clone(), *step, s));
        stage(&format!("sweep {basis} (step {step})"), &mut lap);
    }

    // 5. full-order reference points
    eprintln!("[5/{n_stages}] full-order reference points");
    let params = EigenParams {
        fmin_hz: band[0],
        fmax_hz: band[1],
        tol: 1e-10,
        ..EigenParams::default()
    };
    let mut refs = Vec::new();
    for &mu in a.reference_mu {
        let eq = prep.equilibrium(registry, "lcp", "lagrange", mu)?;
        let op = prep.operator(&eq.eq.active)?;
        let t = Instant::now();
        let mut full = Method::new(
            registry,
            "none",
            &squeal_core::Params::new(),
            a.eigen,
            "arpack",
            params.clone(),
        )?;
        let (reference, _, _) = full.solve(&op, mu, true)?;
        let ref_time = t.elapsed().as_secs_f64();
        for (basis, modes_at) in &kept {
            let modes = match modes_at.iter().find(|(m, _)| (m - mu).abs() < 1e-9) {
                Some((_, m)) => m.clone(),
                // a resumed sweep computed this point in an earlier run: solve it again
                None => {
                    let mut method = Method::new(
                        registry,
                        basis,
                        &squeal_core::Params::new(),
                        "dense",
                        "arpack",
                        params.clone(),
                    )?;
                    method.prepare_stage_on(&prep)?;
                    method.share_modal_cache(prep.modal_cache());
                    method.solve(&op, mu, true)?.0
                }
            };
            refs.push(RefRow {
                mu,
                basis: basis.clone(),
                errors: compare(&reference, &modes, band, 1e-6),
                reference_time_s: ref_time,
            });
        }
    }
    stage("full-order references", &mut lap);

    // 6. report
    for (basis, step, s) in &summaries {
        let _ = writeln!(
            md,
            "## 4. Friction sweep with `{basis}` + `dense`, mu = 0 ... 0.8, step {step}, band {:.0}-{:.0} Hz\n\n{} points, {} contact sets, largest basis {} vectors, worst backward error {:.1e}, {:.0} s.\n",
            band[0], band[1], s.points, s.rebuilds, s.max_basis_size, s.max_backward_error, s.time_s
        );
        let _ = writeln!(md, "![frequency](sweep-{basis}/frequency_vs_mu.png)\n![DvR](sweep-{basis}/dvr_vs_mu.png)\n");
        let _ = writeln!(md, "| freq (Hz) | mu from | mu to | max DvR | made of (MAC > 0.1) |\n|---|---|---|---|---|");
        for c in &s.couplings {
            let parts: Vec<String> = c
                .free_interface_mac
                .iter()
                .map(|(l, v)| format!("{l} {v:.2}"))
                .collect();
            let _ = writeln!(
                md,
                "| {:.1} | {} | {} | {:.4} | {} |",
                c.freq_hz,
                c.mu_from,
                c.mu_to,
                c.max_dvr,
                parts.join(", ")
            );
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "## 5. Bases against full order (`{}`, every mode of the band matched)\n\n| mu | basis | modes (ref) | missed | max rel. freq. error | max abs. DvR error | unstable: ref / missed / false | worst backward error | reference time (s) |\n|---|---|---|---|---|---|---|---|---|", a.eigen);
    for r in &refs {
        let e = &r.errors;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.2e} | {:.2e} | {} / {} / {} | {:.1e} | {:.1} |",
            r.mu,
            r.basis,
            e.reference_modes,
            e.missed_modes,
            e.max_rel_freq_err,
            e.max_abs_dvr_err,
            e.reference_unstable,
            e.missed_unstable,
            e.false_unstable,
            e.max_backward_error,
            r.reference_time_s
        );
    }
    let mut table = String::from(
        "paper coupling          basis (step)     squeal freq (Hz)   squeal mu      max DvR\n",
    );
    for r in &paper_rows {
        let _ = writeln!(
            table,
            "{:>6.0} Hz, mu {:.2}-{:.2}  {:<15}  {:>16}   {:<13}  {}",
            r.paper_freq_hz,
            r.paper_mu[0],
            r.paper_mu[1],
            format!("{} ({})", r.basis, r.step),
            r.squeal_freq_hz
                .map_or("not found".into(), |f| format!("{f:.1}")),
            r.squeal_mu
                .map_or("-".into(), |m| format!("{:.2}-{:.2}", m[0], m[1])),
            r.max_dvr.map_or("-".into(), |d| format!("{d:.4}"))
        );
    }
    let peak = peak_rss_mb();
    let total = start.elapsed().as_secs_f64();
    let _ = writeln!(
        md,
        "## 6. Paper vs squeal\n\n```\n{table}```\n\n## Where the time went\n\n{}| total | | {total:.1} | |\n\nInside the sweeps (points read back from a checkpoint excluded):\n\n{}\nPeak resident memory: {}.",
        profile.markdown(total),
        detail.markdown(total),
        peak.map_or("not measured".into(), |m| format!("{m:.0} MB"))
    );
    std::fs::write(a.out.join("report.md"), &md)?;
    let json = serde_json::json!({
        "scene": file,
        "units": "SI: Hz, N, m, s; DvR = Re/Im",
        "table2": rows,
        "pin_modes_below_10khz": pin_below.iter().map(|m| serde_json::json!({"freq_hz": m.freq_hz, "label": m.label})).collect::<Vec<_>>(),
        "stiffness_n_per_m": stiffness,
        "force_at_paper_displacement_n": force_at_datum,
        "band_hz": band,
        "equilibrium": eqs,
        "sweeps": summaries.iter().map(|(b, st, s)| serde_json::json!({"basis": b, "step": st, "summary": s})).collect::<Vec<_>>(),
        "reference": refs,
        "paper_vs_squeal": paper_rows,
        "stages": profile.stages,
        "sweep_stages": detail.stages,
        "peak_rss_mb": peak,
        "time_s": total,
    });
    std::fs::write(
        a.out.join("report.json"),
        serde_json::to_string_pretty(&json)?,
    )?;
    println!("{table}");
    println!(
        "rig: {} pin modes below 10 kHz, {:.3} MN/m ({:.1} N at {:.0} um); {:.0} s, peak {}",
        pin_below.len(),
        stiffness / 1e6,
        force_at_datum,
        p.load_displacement_m * 1e6,
        total,
        peak.map_or("-".into(), |m| format!("{m:.0} MB"))
    );
    println!("report: {}", a.out.join("report.md").display());
    Ok(())
}
