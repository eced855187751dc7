//! `squeal modes`: build, solve, label, print and write JSON.

use anyhow::{Context, Result};
use squeal_analysis::modal::{body_modes, BodyModes};
use squeal_core::Registry;
use squeal_scene::BodyKind;
use std::path::PathBuf;

/// Bodies of a scene.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum Body {
    /// The disc.
    Disc,
    /// The pin with its plates.
    Pin,
    /// Every body.
    All,
}

/// `squeal modes`.
#[derive(clap::Args)]
pub struct ModesArgs {
    #[command(flatten)]
    scene: crate::opts::SceneArg,
    /// Which bodies.
    #[arg(long, value_enum, default_value = "all")]
    body: Body,
    /// Band top (Hz).
    #[arg(long, default_value_t = 10_500.0)]
    max_freq: f64,
    /// Eigen solver plugin.
    #[arg(long, default_value = squeal_analysis::pipeline::MODAL_SOLVER)]
    eigen: String,
    /// Relative tolerance of the eigen solver.
    #[arg(long, default_value = "1e-10")]
    tol: f64,
    /// Write the modes as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the mesh and mode shapes for ParaView here (VTU files + modes.pvd).
    #[arg(long)]
    vtu: Option<PathBuf>,
}

impl ModesArgs {
    /// Solves, prints and writes what was asked.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        let which = match self.body {
            Body::Disc => BodyKind::Disc,
            Body::Pin => BodyKind::Pin,
            Body::All => BodyKind::All,
        };
        let report = run(
            registry,
            self.scene.as_deref(),
            which,
            self.max_freq,
            &self.eigen,
            self.tol,
            self.vtu.as_deref(),
        )?;
        print!("{}", format(&report));
        if let Some(path) = &self.json {
            write_json(&report, path)?;
        }
        Ok(())
    }
}

/// What `squeal modes --json` writes.
pub type ModesReport = BodyModes;

pub fn run(
    registry: &Registry,
    scene: Option<&str>,
    which: BodyKind,
    max_freq: f64,
    eigen: &str,
    tol: f64,
    vtu: Option<&std::path::Path>,
) -> Result<ModesReport> {
    let (scene, file) = crate::opts::load_scene(scene)?;
    let (report, model, modes) = body_modes(registry, &scene, &file, which, max_freq, eigen, tol)?;
    if let Some(dir) = vtu {
        let shapes: Vec<(f64, Vec<f64>)> = (0..modes.freq_hz.len())
            .map(|i| {
                let col: Vec<f64> = modes.vectors.col(i).iter().copied().collect();
                (
                    modes.freq_hz[i],
                    squeal_analysis::vtu::nodal(&model.dofs.free_of_full, &col),
                )
            })
            .collect();
        let written = squeal_analysis::vtu::write_modes(dir, &model.mesh, &shapes)
            .with_context(|| format!("writing VTU files to {}", dir.display()))?;
        eprintln!(
            "wrote {} VTU files and {}",
            written.len() - 1,
            dir.join("modes.pvd").display()
        );
    }
    Ok(report)
}

pub fn format(r: &ModesReport) -> String {
    let mut s = format!(
        "{}: {} DOFs, {} elements, {:.3} kg; `{}` in {:.2} s\n  #  body   freq (Hz)   label     residual  doublet\n",
        r.scene, r.dofs, r.elements, r.total_mass_kg, r.solver, r.solve_time_s
    );
    for m in &r.modes {
        s.push_str(&format!(
            "{:>3}  {:<5} {:>10.1}   {:<8} {:>9.1e}  {}\n",
            m.index,
            m.body,
            m.freq_hz,
            m.label,
            m.residual,
            m.partner.map_or(String::new(), |p| format!("with #{p}"))
        ));
    }
    for n in &r.notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s
}

pub fn write_json(r: &ModesReport, path: &std::path::Path) -> Result<()> {
    let text = serde_json::to_string_pretty(r)?;
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}
