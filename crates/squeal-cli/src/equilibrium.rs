//! `squeal equilibrium`: the sliding equilibrium for one or several mu, as JSON, CSV and
//! a contact force map.

use anyhow::{Context, Result};
use squeal_analysis::equilibria::EquilibriumReport;
use squeal_analysis::pipeline::Prepared;
use squeal_contact::LoadedEquilibrium;
use squeal_core::{Params, Registry};
use std::path::{Path, PathBuf};

/// `squeal equilibrium`.
#[derive(clap::Args)]
pub struct EquilibriumArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Friction coefficient(s), comma separated (default: the scene's study.mu).
    #[arg(long, value_delimiter = ',')]
    mu: Vec<f64>,
    #[command(flatten)]
    contact: crate::opts::ContactArgs,
    /// Output directory.
    #[arg(long, default_value = "out/equilibrium")]
    out: PathBuf,
}

impl EquilibriumArgs {
    /// Solves, writes and prints the equilibria.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        let law_params = self.contact.law_params()?;
        for &mu in &self.mu {
            crate::opts::check_mu("--mu", mu)?;
        }
        self.contact.check(registry)?;
        let reports = run(
            registry,
            &self.scene,
            &self.mu,
            &self.contact.equilibrium,
            &self.contact.law,
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
                squeal_analysis::num::fixed(r.total_normal_force_n, 4),
                squeal_analysis::num::fixed(r.total_tangential_force_n, 4),
                r.active_pairs,
                r.iterations,
                r.residual,
                r.complementarity_residual,
                squeal_analysis::num::fixed(r.centroid_m[0] * 1e3, 4),
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
    let (reports, eqs) =
        squeal_analysis::equilibria::run_into(registry, &prep, &mus, solver, law, law_params, out)?;
    contact_map(out, &prep, &eqs, solver, law)?;
    Ok(reports)
}

/// Draws the normal force of every pair of each equilibrium (`contact_map.svg/png`).
pub fn contact_map(
    out: &Path,
    prep: &Prepared,
    eqs: &[LoadedEquilibrium],
    solver: &str,
    law: &str,
) -> Result<()> {
    let grid = prep
        .model
        .contact
        .as_ref()
        .expect("a contact set has a grid");
    let dir = prep.set.direction[prep.set.len() / 2];
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
    Ok(())
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
