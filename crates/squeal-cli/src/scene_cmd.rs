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

/// Measured wall times of `squeal validate` (its default check step) on a 2-core machine,
/// `(free DOFs, seconds)`, by size: the embedded `pin-on-disc-coarse`, `pin-on-disc` and
/// `pin-on-disc-paper` scenes. They calibrate [`validate_estimate_s`].
const VALIDATE_RUNS: [(f64, f64); 3] = [(1_779.0, 3.2), (171_963.0, 981.0), (330_306.0, 2_354.0)];

/// Exponent of the power law `t = t0 (n / n0)^p` between measured runs `i` and `i + 1`.
fn segment_exponent(i: usize) -> f64 {
    let ((n0, t0), (n1, t1)) = (VALIDATE_RUNS[i], VALIDATE_RUNS[i + 1]);
    (t1 / t0).ln() / (n1 / n0).ln()
}

/// Estimated wall time (s) of `squeal validate` on a scene of `dofs` free DOFs on a
/// 2-core machine: the power law between the two measured [`VALIDATE_RUNS`] around
/// `dofs` (the nearest pair outside them). An estimate: the stages (disc modes,
/// equilibria, sweeps, full-order reference points) do not all scale alike, and other
/// machines differ.
pub fn validate_estimate_s(dofs: usize) -> f64 {
    let n = dofs as f64;
    let last = VALIDATE_RUNS.len() - 2;
    let i = (0..=last)
        .find(|&i| n <= VALIDATE_RUNS[i + 1].0)
        .unwrap_or(last);
    let (n0, t0) = VALIDATE_RUNS[i];
    t0 * (n / n0).powf(segment_exponent(i))
}

/// A duration estimate with two significant digits at most: `~7 s`, `~4 min`, `~77 min`,
/// `~3.3 h`.
fn approx_duration(s: f64) -> String {
    let two = |x: f64| {
        if x >= 10.0 {
            format!("{x:.0}")
        } else {
            let r = format!("{x:.1}");
            r.strip_suffix(".0").map_or(r.clone(), str::to_string)
        }
    };
    if s < 60.0 {
        format!("~{} s", two(s.max(1.0)))
    } else if s < 90.0 * 60.0 {
        format!("~{} min", two(s / 60.0))
    } else {
        format!("~{} h", two(s / 3600.0))
    }
}

/// Prints the embedded scenes with their size, counted by building each, and the
/// estimated run time of `squeal validate` on each.
fn list(registry: &Registry) -> Result<()> {
    println!(
        "{:<22} {:>9} {:>7} {:>16}  what it is",
        "scene", "DOFs", "pairs", "validate (est.)"
    );
    for name in BUILTIN_SCENES {
        let scene = Scene::builtin(name)?;
        let model = build(&scene, BodyKind::All, registry, name)?;
        let dofs = model.dofs.n_free();
        println!(
            "{:<22} {:>9} {:>7} {:>16}  {}",
            name,
            dofs,
            model.contact.as_ref().map_or(0, |c| c.len()),
            approx_duration(validate_estimate_s(dofs)),
            scene.description
        );
    }
    let runs: Vec<String> = VALIDATE_RUNS
        .iter()
        .map(|&(n, t)| format!("{n} DOFs in {}", approx_duration(t).trim_start_matches('~')))
        .collect();
    let exponents: Vec<String> = (0..VALIDATE_RUNS.len() - 1)
        .map(|i| format!("{:.2}", segment_exponent(i)))
        .collect();
    println!(
        "\nvalidate (est.): an estimate of the wall time of `squeal validate SCENE` on a \
         2-core machine, t ~ DOFs^p between the measured runs around the scene's size ({}; \
         p = {}); other machines and scenes that scale differently will differ.",
        runs.join(", "),
        exponents.join(", ")
    );
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

#[cfg(test)]
mod tests {
    use super::{approx_duration, validate_estimate_s, VALIDATE_RUNS};

    #[test]
    fn validate_estimate_goes_through_the_measured_runs() {
        for (n, t) in VALIDATE_RUNS {
            let e = validate_estimate_s(n as usize);
            assert!(
                (e / t - 1.0).abs() < 1e-9,
                "{n} DOFs: {e} s, measured {t} s"
            );
        }
        // growing with the size, faster than linearly but slower than quadratically,
        // continuous across the measured sizes and beyond the largest
        for (a, b) in [(100_000, 200_000), (200_000, 400_000), (400_000, 800_000)] {
            let (ta, tb) = (validate_estimate_s(a), validate_estimate_s(b));
            assert!(tb > 2.0 * ta && tb < 4.0 * ta, "{a}: {ta} s, {b}: {tb} s");
        }
        for &(n, _) in &VALIDATE_RUNS {
            // one DOF either side: the change of a power law of exponent < 2, no jump
            let (below, above) = (
                validate_estimate_s(n as usize - 1),
                validate_estimate_s(n as usize + 1),
            );
            assert!(
                (above / below - 1.0).abs() < 4.0 / n,
                "{n}: {below} {above}"
            );
        }
    }

    #[test]
    fn durations_read_as_estimates() {
        assert_eq!(approx_duration(6.5), "~6.5 s");
        assert_eq!(approx_duration(0.2), "~1 s");
        assert_eq!(approx_duration(240.0), "~4 min");
        assert_eq!(approx_duration(77.0 * 60.0), "~77 min");
        assert_eq!(approx_duration(3.3 * 3600.0), "~3.3 h");
        assert_eq!(approx_duration(12.0 * 3600.0), "~12 h");
    }
}
