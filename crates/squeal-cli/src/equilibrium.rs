//! `squeal equilibrium`: the sliding equilibrium for one or several mu, as JSON, CSV and
//! a contact force map.

use anyhow::{Context, Result};
use serde::Serialize;
use squeal_contact::{problem, reference_load, solve_on, ContactSet, LoadedEquilibrium};
use squeal_core::contact::Condensation;
use squeal_core::{Params, Registry};
use squeal_scene::{build, BodyKind, Scene};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

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

/// Everything needed to solve equilibria of one scene for several mu.
pub struct Setup {
    pub scene: Scene,
    pub file: String,
    pub model: squeal_scene::Model,
    pub set: ContactSet,
    pub build_time_s: f64,
}

impl Setup {
    pub fn new(registry: &Registry, scene_arg: Option<&str>) -> Result<Self> {
        let start = Instant::now();
        let (scene, file) = crate::load_scene(scene_arg)?;
        let model = build(&scene, BodyKind::All, registry, &file)?;
        let set = ContactSet::new(&model, &scene.contact.zone, scene.study.rotation)
            .with_context(|| format!("contact pairs of {file}"))?;
        Ok(Self {
            scene,
            file,
            model,
            set,
            build_time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// Solves for every mu with one condensation.
    pub fn solve(
        &self,
        registry: &Registry,
        solver: &str,
        law: &str,
        law_params: &Params,
        mus: &[f64],
    ) -> Result<(Vec<LoadedEquilibrium>, f64)> {
        let solver_obj = registry.equilibrium.create(solver, &Params::new())?;
        let law_obj = registry.contact_laws.create(law, law_params)?;
        for &mu in mus {
            squeal_contact::check_user_mu(mu)?;
        }
        let (f, g0) = reference_load(&self.model, &self.set);
        let prob = problem(&self.model, &self.set, &f, &g0);
        let cond = Condensation::new(&prob).context("condensation on the contact pairs")?;
        let mut out = Vec::new();
        for &mu in mus {
            let eq = solve_on(
                &cond,
                &prob,
                &self.set,
                &self.scene.load,
                solver_obj.as_ref(),
                law_obj.as_ref(),
                mu,
            )
            .with_context(|| format!("equilibrium at mu = {mu} with `{solver}`"))?;
            out.push(eq);
        }
        Ok((out, cond.time_s))
    }
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
            "{:.9e},{:.9e},{:.9e},{:.9e},{}",
            set.xy[i][0],
            set.xy[i][1],
            eq.eq.rn[i],
            eq.eq.mu * eq.eq.rn[i],
            u8::from(eq.eq.active[i])
        )?;
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
pub fn run(
    registry: &Registry,
    scene_arg: Option<&str>,
    mus: &[f64],
    solver: &str,
    law: &str,
    law_params: &Params,
    out: &Path,
) -> Result<Vec<EquilibriumReport>> {
    let start = Instant::now();
    if mus.is_empty() {
        anyhow::bail!("--mu: give at least one friction coefficient");
    }
    let setup = Setup::new(registry, scene_arg)?;
    let (eqs, cond_time) = setup.solve(registry, solver, law, law_params, mus)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut reports = Vec::new();
    let c = setup.set.len() / 2;
    let dir = setup.set.direction[c];
    for eq in &eqs {
        let csv = if eqs.len() == 1 {
            "pairs.csv".to_string()
        } else {
            format!("pairs_mu{:.3}.csv", eq.eq.mu)
        };
        write_csv(&out.join(&csv), &setup.set, eq)?;
        reports.push(EquilibriumReport {
            scene: setup.file.clone(),
            units: "SI: forces in N, lengths in m, times in s",
            solver: solver.into(),
            law: law.into(),
            mu: eq.eq.mu,
            total_normal_force_n: eq.total_normal_force_n,
            total_tangential_force_n: eq.total_tangential_force_n,
            tangential_resultant_n: eq.tangential_resultant_n,
            disc_displacement_m: eq.displacement_m,
            active_pairs: eq.eq.active.iter().filter(|&&a| a).count(),
            pairs: setup.set.len(),
            iterations: eq.eq.iterations,
            factorizations: 1,
            residual: eq.eq.equilibrium_residual,
            complementarity_residual: eq.eq.complementarity_residual,
            centroid_m: eq.centroid_m,
            sliding_direction: [dir[0], dir[1]],
            leading_edge: leading_edge(setup.set.rotation),
            build_time_s: setup.build_time_s,
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
    let grid = setup
        .model
        .contact
        .as_ref()
        .expect("a contact set has a grid");
    let cell = [grid.xs[1] - grid.xs[0], grid.ys[1] - grid.ys[0]];
    let grid_cells = grid.cells();
    let cells: Vec<[f64; 4]> = setup
        .set
        .grid_index
        .iter()
        .map(|&g| grid_cells[g])
        .collect();
    let panels: Vec<squeal_plot::MapPanel> = eqs
        .iter()
        .map(|eq| squeal_plot::MapPanel {
            title: format!(
                "mu = {} ({} of {} pairs)",
                eq.eq.mu,
                eq.eq.active.iter().filter(|&&a| a).count(),
                setup.set.len()
            ),
            xy: setup.set.xy.clone(),
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
            setup
                .scene
                .load
                .normal_force_n
                .map_or("imposed-displacement".to_string(), |f| format!("{f}"))
        ),
        "Rn (N)",
        &panels,
    )
    .context("contact force map")?;
    let _ = start;
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
