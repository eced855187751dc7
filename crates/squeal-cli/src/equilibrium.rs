//! `squeal equilibrium`: the sliding equilibrium for one or several mu, as JSON, CSV and
//! a contact force map.

use anyhow::{Context, Result};
use serde::Serialize;
use squeal_analysis::pipeline::Prepared;
use squeal_contact::{ContactSet, LoadedEquilibrium};
use squeal_core::{Params, Registry};
use std::io::Write;
use std::path::{Path, PathBuf};

/// One equilibrium as written to `equilibrium.json`.
#[derive(Serialize, Clone)]
pub struct EquilibriumReport {
    pub scene: String,
    pub units: &'static str,
    pub solver: String,
    pub law: String,
    pub mu: f64,
    pub total_normal_force_n: f64,
    pub total_tangential_force_n: f64,
    pub tangential_resultant_n: [f64; 2],
    pub disc_displacement_m: f64,
    pub active_pairs: usize,
    pub pairs: usize,
    pub iterations: usize,
    pub factorizations: usize,
    pub residual: f64,
    pub complementarity_residual: f64,
    pub centroid_m: [f64; 2],
    pub sliding_direction: [f64; 2],
    pub leading_edge: String,
    pub build_time_s: f64,
    pub condensation_time_s: f64,
    pub time_s: f64,
    pub csv: String,
}

pub fn leading_edge(rotation: f64) -> String {
    if rotation > 0.0 {
        "+x: the disc surface moves along -x under the pin and enters it at its +x edge".into()
    } else {
        "-x: the disc surface moves along +x under the pin and enters it at its -x edge".into()
    }
}

pub fn write_csv(path: &Path, set: &ContactSet, eq: &LoadedEquilibrium) -> Result<()> {
    let mut f = std::io::BufWriter::new(
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?,
    );
    writeln!(f, "x_m,y_m,rn_n,rt_n,active")?;
    for i in 0..set.len() {
        writeln!(
            f,
            "{},{},{},{},{}",
            crate::num::sci(set.xy[i][0], 9),
            crate::num::sci(set.xy[i][1], 9),
            crate::num::sci(eq.eq.rn[i], 9),
            crate::num::sci(eq.eq.mu * eq.eq.rn[i], 9),
            u8::from(eq.eq.active[i])
        )?;
    }
    Ok(())
}

/// `squeal equilibrium`.
#[derive(clap::Args)]
pub struct EquilibriumArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Friction coefficient(s), comma separated (default: the scene's study.mu).
    #[arg(long, value_delimiter = ',')]
    mu: Vec<f64>,
    /// Equilibrium solver plugin (`lorang`, `lcp`).
    #[arg(long, default_value = "lcp")]
    equilibrium: String,
    /// Contact law plugin (`lagrange`, `penalty`).
    #[arg(long, default_value = "lagrange")]
    law: String,
    /// Contact law parameters, `key=value` (e.g. `kn_n_per_m=1e10`).
    #[arg(long = "law-opt")]
    law_opt: Vec<String>,
    /// Output directory.
    #[arg(long, default_value = "out/equilibrium")]
    out: PathBuf,
}

impl EquilibriumArgs {
    /// Solves, writes and prints the equilibria.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        let law_params = crate::opts::parse_params(&self.law_opt)?;
        for &mu in &self.mu {
            crate::opts::check_mu("--mu", mu)?;
        }
        registry
            .equilibrium
            .create(&self.equilibrium, &Params::new())
            .context("--equilibrium")?;
        registry
            .contact_laws
            .create(&self.law, &law_params)
            .context("--law/--law-opt")?;
        let reports = run(
            registry,
            &self.scene,
            &self.mu,
            &self.equilibrium,
            &self.law,
            &law_params,
            &self.out,
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
                "{:>6.3} {:>10} {:>10} {:>7} {:>6} {:>10.2e} {:>10.2e} {:>13} {:>8.3}",
                r.mu,
                crate::num::fixed(r.total_normal_force_n, 4),
                crate::num::fixed(r.total_tangential_force_n, 4),
                r.active_pairs,
                r.iterations,
                r.residual,
                r.complementarity_residual,
                crate::num::fixed(r.centroid_m[0] * 1e3, 4),
                r.time_s
            );
        }
        if let Some(r) = reports.first() {
            println!("leading edge {}", r.leading_edge);
        }
        for p in outputs(&self.out, &reports) {
            println!("wrote {}", p.display());
        }
        Ok(())
    }
}

/// Solves the equilibria of `scene` at `mus` (the scene's study.mu when empty), writes
/// equilibrium.json, one CSV per mu and the contact force map into `out`.
pub fn run(
    registry: &Registry,
    scene: &crate::opts::SceneArg,
    mus: &[f64],
    solver: &str,
    law: &str,
    law_params: &Params,
    out: &Path,
) -> Result<Vec<EquilibriumReport>> {
    let (scene, file) = scene.load()?;
    let mus = if mus.is_empty() {
        vec![scene.study.mu]
    } else {
        mus.to_vec()
    };
    let prep = Prepared::new(registry, scene, &file)?;
    crate::opts::claim_out(out, "equilibrium")?;
    run_on(registry, &prep, &mus, solver, law, law_params, out)
}

/// The equilibria of a prepared scene at `mus`, written into `out` (shared with
/// `validate`).
pub fn run_on(
    registry: &Registry,
    prep: &Prepared,
    mus: &[f64],
    solver: &str,
    law: &str,
    law_params: &Params,
    out: &Path,
) -> Result<Vec<EquilibriumReport>> {
    let mut eqs = Vec::new();
    for &mu in mus {
        eqs.push(
            prep.equilibrium_with(registry, solver, law, law_params, mu)
                .with_context(|| format!("equilibrium at mu = {mu} with `{solver}`"))?,
        );
    }
    let cond_time = prep.condensation.time_s;
    crate::opts::prepare_out(out)?;
    let mut reports = Vec::new();
    let c = prep.set.len() / 2;
    let dir = prep.set.direction[c];
    for eq in &eqs {
        let csv = if eqs.len() == 1 {
            "pairs.csv".to_string()
        } else {
            format!("pairs_mu{:.3}.csv", eq.eq.mu)
        };
        write_csv(&out.join(&csv), &prep.set, eq)?;
        reports.push(EquilibriumReport {
            scene: prep.file.clone(),
            units: "SI: forces in N, lengths in m, times in s",
            solver: solver.into(),
            law: law.into(),
            mu: eq.eq.mu,
            total_normal_force_n: eq.total_normal_force_n,
            total_tangential_force_n: eq.total_tangential_force_n,
            tangential_resultant_n: eq.tangential_resultant_n,
            disc_displacement_m: eq.displacement_m,
            active_pairs: eq.eq.active.iter().filter(|&&a| a).count(),
            pairs: prep.set.len(),
            iterations: eq.eq.iterations,
            factorizations: 1,
            residual: eq.eq.equilibrium_residual,
            complementarity_residual: eq.eq.complementarity_residual,
            centroid_m: eq.centroid_m,
            sliding_direction: [dir[0], dir[1]],
            leading_edge: leading_edge(prep.set.rotation),
            build_time_s: prep.build_time_s,
            condensation_time_s: cond_time,
            time_s: eq.eq.time_s,
            csv,
        });
    }
    let json = if reports.len() == 1 {
        serde_json::to_string_pretty(&reports[0])?
    } else {
        serde_json::to_string_pretty(&reports)?
    };
    let path = out.join("equilibrium.json");
    std::fs::write(&path, json).with_context(|| format!("writing {}", path.display()))?;
    let grid = prep
        .model
        .contact
        .as_ref()
        .expect("a contact set has a grid");
    let cell = [grid.xs[1] - grid.xs[0], grid.ys[1] - grid.ys[0]];
    let grid_cells = grid.cells();
    let cells: Vec<[f64; 4]> = prep.set.grid_index.iter().map(|&g| grid_cells[g]).collect();
    let panels: Vec<squeal_plot::MapPanel> = eqs
        .iter()
        .map(|eq| squeal_plot::MapPanel {
            title: format!(
                "mu = {} ({} of {} pairs)",
                eq.eq.mu,
                eq.eq.active.iter().filter(|&&a| a).count(),
                prep.set.len()
            ),
            xy: prep.set.xy.clone(),
            values: eq.eq.rn.clone(),
            cell,
            cells: cells.clone(),
            arrow: Some([dir[0], dir[1]]),
            arrow_label: "disc sliding".into(),
        })
        .collect();
    squeal_plot::contact_map(
        &out.join("contact_map"),
        &format!(
            "Normal contact force per pair, {} N total ({solver}, {law})",
            prep.scene
                .load
                .normal_force_n
                .map_or("imposed-displacement".to_string(), |f| format!("{f}"))
        ),
        "Rn (N)",
        &panels,
    )
    .context("contact force map")?;
    Ok(reports)
}

/// Output paths written by [`run`] besides the charts.
pub fn outputs(out: &Path, reports: &[EquilibriumReport]) -> Vec<PathBuf> {
    let mut v = vec![
        out.join("equilibrium.json"),
        out.join("contact_map.svg"),
        out.join("contact_map.png"),
    ];
    v.extend(reports.iter().map(|r| out.join(&r.csv)));
    v
}
