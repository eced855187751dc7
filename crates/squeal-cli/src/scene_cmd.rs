//! `squeal scene info`: what the builder makes of a scene and why.

use anyhow::Result;
use squeal_core::Registry;
use squeal_scene::{build, BodyKind, Scene, BUILTIN_SCENES};

/// `squeal scene`.
#[derive(clap::Subcommand)]
pub enum SceneCmd {
    /// The embedded scenes: size (built now) and what each is for.
    List,
    /// DOFs per body, contact pairs, element sizes and quality, and the size rule.
    Info {
        #[command(flatten)]
        scene: crate::opts::SceneArg,
    },
    /// Prints the scene as the program reads it (TOML, every default filled in).
    Show {
        #[command(flatten)]
        scene: crate::opts::SceneArg,
    },
}

impl SceneCmd {
    /// Runs the action.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        match self {
            SceneCmd::List => list(registry),
            SceneCmd::Info { scene } => {
                let (scene, file) = scene.load()?;
                info(registry, &scene, &file)
            }
            SceneCmd::Show { scene } => {
                let (scene, _) = scene.load()?;
                print!("{}", scene.to_toml());
                Ok(())
            }
        }
    }
}

/// Prints the embedded scenes with their size, counted by building each.
fn list(registry: &Registry) -> Result<()> {
    println!("{:<22} {:>9} {:>7}  what it is", "scene", "DOFs", "pairs");
    for name in BUILTIN_SCENES {
        let scene = Scene::builtin(name)?;
        let model = build(&scene, BodyKind::All, registry, name)?;
        println!(
            "{:<22} {:>9} {:>7}  {}",
            name,
            model.dofs.n_free(),
            model.contact.as_ref().map_or(0, |c| c.len()),
            scene.description
        );
    }
    println!(
        "\nUse a name as SCENE (`squeal stability pin-on-disc-coarse`), or a scene file; \
         `squeal scene show NAME` prints one to start a file from."
    );
    Ok(())
}

/// Builds the whole scene and prints DOFs per body, contact pairs, element sizes, mesh
/// quality and the rule that chose the sizes.
pub fn info(registry: &Registry, scene: &Scene, file: &str) -> Result<()> {
    let model = build(scene, BodyKind::All, registry, file)?;
    let r = &scene.mesh;
    println!("scene `{}` ({file})", scene.name);
    println!(
        "rule: element edge <= bending wavelength at {} Hz / {}{}, >= {} layers per thickness, \
         pin face {} x {} elements, grading ratio {} away from the contact patch",
        r.max_freq_hz,
        r.elements_per_wavelength,
        r.plate_elements_per_wavelength
            .map_or(String::new(), |p| format!(" (plates / {p})")),
        r.min_layers,
        r.pin_face_elements,
        r.pin_face_elements,
        r.grading_ratio
    );
    println!(
        "model: {} free DOFs, {} elements, {} nodes, {:.3} kg, built in {:.2} s",
        model.dofs.full_of_free.len(),
        model.mesh.hexes.len(),
        model.mesh.n_nodes(),
        model.total_mass,
        model.build_time_s
    );
    println!(
        "\n{:<12} {:>8} {:>8} {:>8}  {:>18}  {:>10}",
        "body", "elements", "nodes", "DOFs", "edges (mm)", "min sJ"
    );
    for b in model.body_stats() {
        println!(
            "{:<12} {:>8} {:>8} {:>8}  {:>8.3} - {:<7.3}  {:>10.3}",
            b.body,
            b.elements,
            b.nodes,
            b.dofs,
            b.edge_range_m.0 * 1e3,
            b.edge_range_m.1 * 1e3,
            b.min_scaled_jacobian
        );
    }
    println!("\nsize rule per body:");
    for s in &model.sizes {
        let wl = if s.wavelength_m.is_finite() {
            format!("{:.1} mm", s.wavelength_m * 1e3)
        } else {
            "-".into()
        };
        println!(
            "  {:<12} bending wavelength {:>9}, target edge {:.2} mm, divisions {:?}",
            s.body,
            wl,
            s.element_size_m * 1e3,
            s.divisions
        );
    }
    for (body, imp) in [
        ("disc", scene.disc.as_ref().and_then(|d| d.mesh.as_ref())),
        ("pin", scene.pin.as_ref().and_then(|p| p.mesh.as_ref())),
    ] {
        if let Some(imp) = imp {
            let path = imp
                .loaded
                .as_ref()
                .map_or_else(|| imp.file.clone(), |l| l.path.display().to_string());
            println!(
                "  {body:<12} mesh imported from {path} (scale {} to m), contact group {}, \
                 fixed groups [{}]",
                imp.scale,
                imp.contact_group.as_deref().unwrap_or("-"),
                imp.fixed_groups.join(", ")
            );
        }
    }
    println!("\ndamping: {}", scene.damping.describe());
    match &model.contact {
        Some(c) => {
            let steps = c.xs.windows(2).chain(c.ys.windows(2)).map(|w| w[1] - w[0]);
            let (lo, hi) = steps.fold((f64::INFINITY, 0.0f64), |(l, h), d| (l.min(d), h.max(d)));
            let step = if hi - lo <= 1e-9 * hi {
                format!("step {:.3} mm", hi * 1e3)
            } else {
                format!("steps {:.3}-{:.3} mm", lo * 1e3, hi * 1e3)
            };
            println!(
                "\ncontact: {} node-to-node pairs ({} x {} grid, {step}), max (x, y) mismatch {:.1e} m",
                c.len(),
                c.xs.len(),
                c.ys.len(),
                c.max_mismatch_m
            )
        }
        None => println!("\ncontact: none (the scene needs a disc and a pin)"),
    }
    Ok(())
}
