//! The `squeal` command line.

mod bench;
mod equilibrium;
mod modes;
mod scene_cmd;
mod stability;
mod study;
mod study_charts;
mod sweep;
mod validate;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use squeal_scene::Scene;

/// Counts heap allocations so `squeal bench` can report each run's peak memory.
#[global_allocator]
static HEAP: peak_alloc::PeakAlloc = peak_alloc::PeakAlloc;

/// Brake-squeal stability analysis.
#[derive(Parser)]
#[command(name = "squeal", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Bodies of a scene.
#[derive(Clone, Copy, ValueEnum)]
enum Body {
    Disc,
    Pin,
    All,
}

#[derive(Subcommand)]
enum Command {
    /// Normal modes of the scene's bodies (free contact face), labelled.
    Modes {
        /// Scene file (TOML) or embedded scene name; default: the embedded `pin-on-disc`.
        scene: Option<String>,
        /// Which bodies.
        #[arg(long, value_enum, default_value = "all")]
        body: Body,
        /// Band top (Hz).
        #[arg(long, default_value_t = 10_500.0)]
        max_freq: f64,
        /// Eigen solver plugin.
        #[arg(long, default_value = "arpack")]
        eigen: String,
        /// Relative tolerance of the eigen solver.
        #[arg(long, default_value_t = 1e-12)]
        tol: f64,
        /// Write the modes as JSON here.
        #[arg(long)]
        json: Option<std::path::PathBuf>,
        /// Write the mesh and mode shapes for ParaView here (VTU files + modes.pvd).
        #[arg(long)]
        vtu: Option<std::path::PathBuf>,
    },
    /// The main job: the uniform-contact validation on the embedded default scene: disc
    /// modes vs Table 2, sliding equilibria, the mu sweep through two bases, full-order
    /// reference points, report.md/report.json and a paper-vs-squeal table.
    Validate {
        /// Scene file or embedded name.
        scene: Option<String>,
        /// Report directory.
        #[arg(long, default_value = "out/validate")]
        out: std::path::PathBuf,
        /// Step of the mu sweep (0 to 0.8); the paper's resolution is 0.01.
        #[arg(long, default_value_t = 0.1)]
        step: f64,
        /// Frequency band `FMIN:FMAX` (Hz) of the sweeps and reference points: the
        /// paper's couplings lie near 2100 and 3500 Hz; the scene's whole band (e.g.
        /// 0:10000) costs a larger basis per contact set.
        #[arg(long, default_value = "0:5000")]
        band: String,
        /// Reduction bases to sweep with, comma separated.
        #[arg(long, value_delimiter = ',', default_value = "enriched,residue")]
        bases: Vec<String>,
        /// Friction coefficients of the full-order reference solves, comma separated.
        #[arg(long, value_delimiter = ',', default_value = "0.3,0.7")]
        reference_mu: Vec<f64>,
        /// Full-order eigen solver of the reference points.
        #[arg(long, default_value = "arpack")]
        eigen: String,
        /// Only the disc modes against Table 2 (the first stage), as JSON here if given.
        #[arg(long)]
        disc_only: bool,
        /// With --disc-only: write the table as JSON here.
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
    /// The steady sliding equilibrium (unilateral contact, Coulomb friction) for one or
    /// several mu: equilibrium.json (one object, or a list for several mu), per-pair CSV
    /// and a contact force map.
    Equilibrium {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
        /// Friction coefficient(s), comma separated (default: the scene's study.mu).
        #[arg(long, value_delimiter = ',')]
        mu: Vec<f64>,
        /// Equilibrium solver plugin (`lorang`, `lcp`).
        #[arg(long, default_value = "lcp")]
        solver: String,
        /// Contact law plugin (`lagrange`, `penalty`).
        #[arg(long, default_value = "lagrange")]
        law: String,
        /// Contact law parameters, `key=value` (e.g. `kn_n_per_m=1e10`).
        #[arg(long = "law-opt")]
        law_opt: Vec<String>,
        /// Output directory.
        #[arg(long, default_value = "out/equilibrium")]
        out: std::path::PathBuf,
    },
    /// Complex modes of the frictional operator (full order): of a scene at its sliding
    /// equilibrium, or of an operator directory (`--operator DIR`).
    Stability {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
        /// Operator directory (Mc.mtx, Kc.mtx, ... as written by `squeal export`).
        #[arg(long)]
        operator: Option<std::path::PathBuf>,
        /// Friction coefficient (default: the scene's study.mu; required with --operator).
        #[arg(long)]
        mu: Option<f64>,
        /// Eigen solver plugin (`arpack`, `krylov`, `dense`); default `arpack`, or `dense`
        /// for the reduced problem when a basis is given.
        #[arg(long)]
        eigen: Option<String>,
        /// Reduction basis plugin (`modes`, `enriched`, `residue`, ...) or `none` (full
        /// order).
        #[arg(long, default_value = "none")]
        basis: String,
        /// Basis parameters `key=value` (e.g. `cutoff_factor=2`).
        #[arg(long = "basis-opt")]
        basis_opt: Vec<String>,
        /// Frequency band `FMIN:FMAX` in Hz.
        #[arg(long, default_value = "0:10000")]
        band: String,
        /// Relative tolerance of the eigen solver.
        #[arg(long, default_value_t = 1e-12)]
        tol: f64,
        /// A mode is unstable when Re(lambda) > this times |lambda|.
        #[arg(long, default_value_t = 1e-8)]
        unstable_tol: f64,
        /// Equilibrium solver plugin.
        #[arg(long, default_value = "lcp")]
        equilibrium: String,
        /// Contact law plugin.
        #[arg(long, default_value = "lagrange")]
        law: String,
        /// Write the result as JSON here.
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
    /// Writes the frictional operator of a scene at its equilibrium for MU, in both forms:
    /// constrained parts (Mc, Kc, FM, FK, T) and full form (M, K, pairs.csv), + README.txt.
    Export {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
        /// Friction coefficient of the equilibrium (default: the scene's study.mu).
        #[arg(long)]
        mu: Option<f64>,
        /// Equilibrium solver plugin.
        #[arg(long, default_value = "lcp")]
        equilibrium: String,
        /// Contact law plugin.
        #[arg(long, default_value = "lagrange")]
        law: String,
        /// Output directory.
        #[arg(long)]
        out: std::path::PathBuf,
    },
    /// The solver benchmark: every registered basis x eigen solver (and full order) on
    /// the same frictional operator against full-order `arpack` at a tight tolerance:
    /// time (setup, solve), peak memory, basis size, errors, missed and false unstable
    /// modes, backward errors. Writes bench.json, bench-summary.json and error-vs-time /
    /// error-vs-size charts; `--stress` runs the stress set instead (stress.json,
    /// stress-table.json).
    Bench {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
        /// Operator directory (as written by `squeal export`) instead of a scene.
        #[arg(long)]
        operator: Option<std::path::PathBuf>,
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
        /// Frequency band `FMIN:FMAX` (Hz).
        #[arg(long, default_value = "0:10000")]
        band: String,
        /// Tolerance of the benchmarked eigen solvers.
        #[arg(long, default_value_t = 1e-10)]
        tol: f64,
        /// Full-order reference solver.
        #[arg(long, default_value = "arpack")]
        reference: String,
        /// Tolerance of the reference.
        #[arg(long, default_value_t = 1e-12)]
        reference_tol: f64,
        /// Run the stress set (cases built to break methods) instead of the mu list.
        #[arg(long)]
        stress: bool,
        /// Only redraw the charts (and the stress table) from the `bench.json` or
        /// `stress.json` already in `--out`, without solving anything.
        #[arg(long)]
        replot: bool,
        /// Equilibrium solver plugin.
        #[arg(long, default_value = "lcp")]
        equilibrium: String,
        /// Contact law plugin.
        #[arg(long, default_value = "lagrange")]
        law: String,
        /// Output directory.
        #[arg(long, default_value = "out/bench")]
        out: std::path::PathBuf,
    },
    /// Parameter sweeps.
    Sweep {
        #[command(subcommand)]
        kind: SweepKind,
    },
    /// Joins the directories of a study's shards (`--shard K/N` runs) into one: the same
    /// results.jsonl and summary.json as one run over the whole study, plus its charts.
    Merge {
        /// Study directories (the --out of each shard).
        #[arg(required = true)]
        dirs: Vec<std::path::PathBuf>,
        /// Merged directory (must not be one of the inputs).
        #[arg(long)]
        out: std::path::PathBuf,
        /// Skip the charts.
        #[arg(long)]
        no_charts: bool,
    },
    /// Lists the registered plugins.
    Plugins,
    /// Scene inspection.
    Scene {
        #[command(subcommand)]
        action: SceneAction,
    },
}

#[derive(Subcommand)]
enum SweepKind {
    /// Friction-coefficient sweep: equilibrium, operator (rebuilt when the contact set
    /// changes), modes, tracking by MAC, couplings; sweep.csv, summary.json and charts.
    /// Resumes from DIR/sweep.partial.jsonl.
    Mu {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
        #[arg(long, default_value_t = 0.0)]
        from: f64,
        #[arg(long, default_value_t = 0.8)]
        to: f64,
        #[arg(long, default_value_t = 0.01)]
        step: f64,
        /// Reduction basis plugin, or `none` for full order.
        #[arg(long, default_value = "none")]
        basis: String,
        /// Basis parameters `key=value`.
        #[arg(long = "basis-opt")]
        basis_opt: Vec<String>,
        /// Eigen solver plugin; default `arpack`, or `dense` for the reduced problem when
        /// a basis is given.
        #[arg(long)]
        eigen: Option<String>,
        /// Frequency band `FMIN:FMAX` (Hz).
        #[arg(long, default_value = "0:10000")]
        band: String,
        /// Equilibrium solver plugin.
        #[arg(long, default_value = "lcp")]
        equilibrium: String,
        /// Contact law plugin.
        #[arg(long, default_value = "lagrange")]
        law: String,
        /// A mode is unstable when its DvR exceeds this.
        #[arg(long, default_value_t = 1e-6)]
        dvr_tol: f64,
        /// Output directory.
        #[arg(long, default_value = "out/sweep-mu")]
        out: std::path::PathBuf,
    },
    /// Macroscopic effective zones (paper section 3.1): every rectangle (x0, y0, a, b) of
    /// the grid of lists, all its pairs closed and sliding, at each mu. Lists are
    /// comma-separated values and FROM:TO:STEP ranges, in m from the pin face's corner
    /// (x along sliding, y radial). Writes study.json, results.jsonl, summary.json,
    /// timings.jsonl, timings.json and charts; resumable (--resume), shardable (--shard).
    Macro {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
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
        opts: study::StudyOpts,
        /// Output directory.
        #[arg(long, default_value = "out/sweep-macro")]
        out: std::path::PathBuf,
    },
    /// Mesoscopic plateaus (paper section 3.2): a fixed region of the pin face cut into
    /// square patches, seeded random subsets of them in contact (all their pairs closed
    /// and sliding), --layouts per patch size. Defaults: the paper's patch sizes and mu
    /// for --coupling 2 (2100 Hz) or 1 (3500 Hz); those patches need a contact grid of
    /// 0.2 mm / 0.5 mm in the region (mesh.contact_refinement; scenes/pin-on-disc-meso.toml
    /// and scenes/pin-on-disc-meso-c1.toml): on the default scene (1 mm) give --patch.
    /// Same outputs, resume and shards as `sweep macro`.
    Meso {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
        /// Which coupling's defaults: 2 (2100 Hz: region 0.010,0.003,0.010,0.014, patches
        /// 0.4-1.6 mm) or 1 (3500 Hz: region 0.003,0.003,0.014,0.014, patches 0.5-3.5 mm).
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
        /// Fraction of the patches in contact in each layout, in (0, 1].
        #[arg(long, default_value_t = 0.5)]
        fraction: f64,
        /// Base seed of the layouts.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Friction coefficients.
        #[arg(long, default_value = "0.36")]
        mu: String,
        #[command(flatten)]
        opts: study::StudyOpts,
        /// Output directory.
        #[arg(long, default_value = "out/sweep-meso")]
        out: std::path::PathBuf,
    },
}

#[derive(Subcommand)]
enum SceneAction {
    /// DOFs per body, contact pairs, element sizes and quality, and the size rule.
    Info {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
    },
    /// Prints the scene as the program reads it (TOML, every default filled in).
    Show {
        /// Scene file (TOML) or embedded scene name; default: `pin-on-disc`.
        scene: Option<String>,
    },
}

/// Loads a scene: a file path, else an embedded name, else the default.
pub fn load_scene(arg: Option<&str>) -> Result<(Scene, String)> {
    match arg {
        None => Ok((
            Scene::builtin("pin-on-disc")?,
            "<builtin pin-on-disc>".into(),
        )),
        Some(a) if std::path::Path::new(a).exists() => {
            Ok((Scene::from_file(std::path::Path::new(a))?, a.to_string()))
        }
        Some(a) if !a.ends_with(".toml") => Ok((Scene::builtin(a)?, format!("<builtin {a}>"))),
        Some(a) => Err(anyhow::anyhow!("{a}: no such scene file")),
    }
}

/// Parses `FMIN:FMAX` (Hz).
pub fn parse_band(text: &str) -> Result<[f64; 2]> {
    let (a, b) = text
        .split_once(':')
        .with_context(|| format!("--band `{text}`: expected FMIN:FMAX in Hz, e.g. 0:10000"))?;
    let parse = |s: &str| -> Result<f64> {
        s.trim()
            .parse::<f64>()
            .with_context(|| format!("--band `{text}`: `{s}` is not a frequency in Hz"))
    };
    let band = [parse(a)?, parse(b)?];
    if !(band[0] >= 0.0 && band[1] > band[0] && band[1].is_finite()) {
        anyhow::bail!("--band `{text}`: expected 0 <= FMIN < FMAX (Hz)");
    }
    Ok(band)
}

fn main() {
    // A closed pipe (`squeal ... | head`) ends the process quietly, as for other Unix
    // tools, instead of a panic in `println!`.
    #[cfg(unix)]
    // SAFETY: restoring the default action of one signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> Result<()> {
    let cli = Cli::parse();
    let registry = squeal::registry();
    match cli.command {
        Command::Modes {
            scene,
            body,
            max_freq,
            eigen,
            tol,
            json,
            vtu,
        } => {
            let which = match body {
                Body::Disc => squeal_scene::BodyKind::Disc,
                Body::Pin => squeal_scene::BodyKind::Pin,
                Body::All => squeal_scene::BodyKind::All,
            };
            let report = modes::run(
                &registry,
                scene.as_deref(),
                which,
                max_freq,
                &eigen,
                tol,
                vtu.as_deref(),
            )?;
            print!("{}", modes::format(&report));
            if let Some(path) = json {
                modes::write_json(&report, &path)?;
            }
        }
        Command::Validate {
            scene,
            out,
            step,
            band,
            bases,
            reference_mu,
            eigen,
            disc_only,
            json,
        } if !disc_only => {
            let _ = json;
            validate::run(
                &registry,
                &validate::Args {
                    scene: scene.as_deref(),
                    out: &out,
                    step,
                    band: parse_band(&band)?,
                    bases: &bases,
                    reference_mu: &reference_mu,
                    eigen: &eigen,
                },
            )?;
        }
        Command::Validate {
            scene, eigen, json, ..
        } => {
            let report = modes::run(
                &registry,
                scene.as_deref(),
                squeal_scene::BodyKind::Disc,
                10_500.0,
                &eigen,
                1e-12,
                None,
            )?;
            let rows = squeal_analysis::modal::compare_table2(&report.modes);
            println!("Disc normal modes (free friction face): paper Table 2 vs squeal");
            println!(
                "model: {} DOFs, {} elements, solved by `{}` in {:.2} s (build {:.2} s)\n",
                report.dofs,
                report.elements,
                report.solver,
                report.solve_time_s,
                report.build_time_s
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
                std::fs::write(&path, serde_json::to_string_pretty(&v)?)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
        }
        Command::Scene { action } => match action {
            SceneAction::Info { scene } => {
                let (scene, file) = load_scene(scene.as_deref())?;
                scene_cmd::info(&registry, &scene, &file)?;
            }
            SceneAction::Show { scene } => {
                let (scene, _) = load_scene(scene.as_deref())?;
                print!("{}", scene.to_toml());
            }
        },
        Command::Equilibrium {
            scene,
            mu,
            solver,
            law,
            law_opt,
            out,
        } => {
            let mut law_params = squeal_core::Params::new();
            for kv in &law_opt {
                let (k, v) = squeal_core::Params::parse_kv(kv)?;
                law_params.0.insert(k, v);
            }
            let mus = if mu.is_empty() {
                vec![load_scene(scene.as_deref())?.0.study.mu]
            } else {
                mu
            };
            let reports = equilibrium::run(
                &registry,
                scene.as_deref(),
                &mus,
                &solver,
                &law,
                &law_params,
                &out,
            )?;
            println!(
                "{:>6} {:>10} {:>10} {:>7} {:>6} {:>10} {:>10} {:>13} {:>8}",
                "mu",
                "Fn (N)",
                "Ft (N)",
                "active",
                "iter",
                "residual",
                "compl.",
                "centroid x mm",
                "time s"
            );
            for r in &reports {
                println!(
                    "{:>6.3} {:>10.4} {:>10.4} {:>7} {:>6} {:>10.2e} {:>10.2e} {:>13.4} {:>8.3}",
                    r.mu,
                    r.total_normal_force_n,
                    r.total_tangential_force_n,
                    r.active_pairs,
                    r.iterations,
                    r.residual,
                    r.complementarity_residual,
                    r.centroid_m[0] * 1e3,
                    r.time_s
                );
            }
            if let Some(r) = reports.first() {
                println!("leading edge {}", r.leading_edge);
            }
            for p in equilibrium::outputs(&out, &reports) {
                println!("wrote {}", p.display());
            }
        }
        Command::Stability {
            scene,
            operator,
            mu,
            eigen,
            band,
            tol,
            unstable_tol,
            equilibrium,
            law,
            json,
            basis,
            basis_opt,
        } => {
            let eigen = eigen
                .unwrap_or_else(|| if basis == "none" { "arpack" } else { "dense" }.to_string());
            let args = stability::Args {
                scene: scene.as_deref(),
                operator: operator.as_deref(),
                mu,
                basis: &basis,
                basis_opts: &basis_opt,
                eigen: &eigen,
                band: parse_band(&band)?,
                tol,
                unstable_tol,
                equilibrium: &equilibrium,
                law: &law,
            };
            let report = stability::run(&registry, &args)?;
            stability::print(&report);
            if let Some(path) = json {
                std::fs::write(&path, serde_json::to_string_pretty(&report)?)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
        }
        Command::Export {
            scene,
            mu,
            equilibrium,
            law,
            out,
        } => stability::export(&registry, scene.as_deref(), mu, &equilibrium, &law, &out)?,
        Command::Sweep {
            kind:
                SweepKind::Mu {
                    scene,
                    from,
                    to,
                    step,
                    basis,
                    basis_opt,
                    eigen,
                    band,
                    equilibrium,
                    law,
                    dvr_tol,
                    out,
                },
        } => {
            let eigen = eigen
                .unwrap_or_else(|| if basis == "none" { "arpack" } else { "dense" }.to_string());
            let args = sweep::Args {
                scene: scene.as_deref(),
                from,
                to,
                step,
                eigen: &eigen,
                basis: &basis,
                basis_opts: &basis_opt,
                band: parse_band(&band)?,
                equilibrium: &equilibrium,
                law: &law,
                dvr_tol,
                out: &out,
            };
            let s = sweep::run(&registry, &args)?;
            println!(
                "{} points ({} contact sets), {} couplings, max backward error {:.1e}, {:.1} s",
                s.points,
                s.rebuilds,
                s.couplings.len(),
                s.max_backward_error,
                s.time_s
            );
            for c in &s.couplings {
                println!(
                    "  {:>8.1} Hz  mu {:.3}-{:.3}  max DvR {:.4}  partners {:?}",
                    c.freq_hz, c.mu_from, c.mu_to, c.max_dvr, c.partners
                );
            }
            println!(
                "wrote {}/{{sweep.csv,summary.json,*.svg,*.png}}",
                out.display()
            );
        }
        Command::Bench {
            scene,
            operator,
            mu,
            bases,
            eigens,
            vary,
            band,
            tol,
            reference,
            reference_tol,
            stress,
            replot,
            equilibrium,
            law,
            out,
        } => {
            if replot {
                return bench::replot(&out, stress);
            }
            let mut opts = squeal_analysis::bench::BenchOptions::all(&registry);
            if !bases.is_empty() {
                opts.bases = bases;
            }
            if !eigens.is_empty() {
                opts.eigens = eigens;
            }
            for name in opts.bases.iter().filter(|b| *b != "none") {
                registry
                    .bases
                    .create(name, &squeal_core::Params::new())
                    .with_context(|| format!("--bases: `{name}`"))?;
            }
            for name in opts.eigens.iter().chain([&reference]) {
                registry
                    .eigen
                    .create(name, &squeal_core::Params::new())
                    .with_context(|| format!("--eigens/--reference: `{name}`"))?;
            }
            opts.vary = bench::parse_vary(&vary)?;
            opts.band_hz = parse_band(&band)?;
            opts.tol = tol;
            opts.reference_eigen = reference;
            opts.reference_tol = reference_tol;
            for (what, t) in [("--tol", tol), ("--reference-tol", reference_tol)] {
                if !(t > 0.0 && t < 1.0) {
                    anyhow::bail!("{what}: expected a relative tolerance in (0, 1), got {t}");
                }
            }
            let probe = bench::HeapProbe(&HEAP);
            bench::run(
                &registry,
                &bench::Args {
                    scene: scene.as_deref(),
                    operator: operator.as_deref(),
                    mus: &mu,
                    out: &out,
                    opts,
                    equilibrium: &equilibrium,
                    law: &law,
                    stress,
                },
                Some(&probe),
            )?;
        }
        Command::Sweep {
            kind:
                SweepKind::Macro {
                    scene,
                    x0,
                    y0,
                    a,
                    b,
                    mu,
                    opts,
                    out,
                },
        } => study::run_macro(
            &registry,
            &study::MacroArgs {
                scene: scene.as_deref(),
                x0: &x0,
                y0: &y0,
                a: &a,
                b: &b,
                mu: &mu,
                out: &out,
                opts: &opts,
            },
        )?,
        Command::Sweep {
            kind:
                SweepKind::Meso {
                    scene,
                    coupling,
                    region,
                    patch,
                    layouts,
                    fraction,
                    seed,
                    mu,
                    opts,
                    out,
                },
        } => study::run_meso(
            &registry,
            &study::MesoArgs {
                scene: scene.as_deref(),
                coupling,
                region: region.as_deref(),
                patch: patch.as_deref(),
                layouts,
                fraction,
                seed,
                mu: &mu,
                out: &out,
                opts: &opts,
            },
        )?,
        Command::Merge {
            dirs,
            out,
            no_charts,
        } => {
            study::check_dirs(&dirs)?;
            study::merge(&dirs, &out, no_charts)?;
        }
        Command::Plugins => {
            for (kind, list) in [
                ("material", registry.materials.describe()),
                ("contact law", registry.contact_laws.describe()),
                ("equilibrium", registry.equilibrium.describe()),
                ("basis", registry.bases.describe()),
                ("eigen", registry.eigen.describe()),
            ] {
                for (name, desc) in list {
                    println!("{kind:<12} {name:<24} {desc}");
                }
            }
        }
    }
    Ok(())
}
