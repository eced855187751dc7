//! `squeal calibrate SPEC.toml --out DIR`: model updating (`docs/calibrate.md`).

use anyhow::{Context, Result};
use squeal_analysis::calibrate::{calibrate, scene_at, CalibrationSpec, FitResult, Step};
use squeal_core::Registry;
use squeal_plot::{line_chart, ChartOptions, Series, SeriesStyle};
use std::path::{Path, PathBuf};

/// Fits scene parameters to targets (mode frequencies, stiffness, tied-system modes):
/// fit.json, the fitted scene and a convergence chart.
#[derive(clap::Args)]
pub struct CalibrateArgs {
    /// The calibration spec (TOML): base scene, parameters, targets, search.
    spec: PathBuf,
    /// Output directory.
    #[arg(long, default_value = "out/calibrate")]
    out: PathBuf,
    /// Evaluate the targets at the start point only (no search).
    #[arg(long)]
    evaluate_only: bool,
}

impl CalibrateArgs {
    /// Runs the calibration and writes its outputs.
    pub fn run(&self, registry: &Registry) -> Result<()> {
        let file = self.spec.display().to_string();
        let spec = CalibrationSpec::from_file(&self.spec)?;
        let dir = self.spec.parent().unwrap_or(Path::new("."));
        let (scene, scene_file) = spec.load_scene(dir, &file)?;
        spec.check_against(&scene, &file)?;
        crate::opts::claim_out(&self.out, "calibrate")?;
        println!(
            "calibrate {}: scene {}, {} parameter(s), {} target(s)",
            file,
            scene_file,
            spec.parameters.len(),
            spec.targets.len()
        );
        let names: Vec<String> = spec.targets.iter().map(|t| t.label()).collect();
        let fit = if self.evaluate_only {
            // one evaluation on the scene's own rule
            let mut only = spec.clone();
            only.parameters.clear();
            only.search.rule.clear();
            only.search.max_evaluations = 1;
            calibrate(registry, &only, &scene, &scene_file, |s| print_step(s, &[]))?
        } else {
            let paths: Vec<&str> = spec.parameters.iter().map(|p| p.path.as_str()).collect();
            calibrate(registry, &spec, &scene, &scene_file, |s| {
                print_step(s, &paths)
            })?
        };
        print!("{}", format_result(&spec, &names, &fit));
        let fitted = scene_at(&spec, &scene, &scene_file, &fit.values, &[])?;
        let toml_path = self.out.join("fitted.toml");
        std::fs::write(&toml_path, fitted.to_toml())
            .with_context(|| format!("writing {}", toml_path.display()))?;
        let json_path = self.out.join("fit.json");
        let json = serde_json::json!({
            "spec": spec,
            "scene": scene_file,
            "units": "SI: Hz, N/m; parameters in their scene units",
            "method": "trust-region Gauss-Newton (argmin TrustRegion + Steihaug), forward-difference Jacobian, bounds by u = (1 + sin z) / 2",
            "parameters": spec.parameters.iter().zip(&fit.values).zip(&fit.start).map(|((p, v), s)| serde_json::json!({
                "path": p.path, "start": s, "value": v, "min": p.min, "max": p.max,
                "scale": p.scale,
            })).collect::<Vec<_>>(),
            "targets": spec.targets.iter().zip(&names).enumerate().map(|(i, (t, name))| {
                let m = &fit.confirmed.measured[i];
                serde_json::json!({
                    "name": name, "target": t.value(), "weight": t.weight,
                    "value": finite(m.value), "residual": finite(m.residual),
                    "start_value": fit.start_confirmed.as_ref().map(|e| finite(e.measured[i].value)),
                    "correction_ratio": fit.ratios[i], "note": m.note,
                })
            }).collect::<Vec<_>>(),
            "cost": fit.confirmed.cost(&spec.targets, &vec![1.0; spec.targets.len()]),
            "evaluations": fit.steps.len(),
            "stops": fit.stops,
            "dofs": { "search": fit.dofs[0], "confirm": fit.dofs[1] },
            "time_s": fit.time_s,
            "steps": fit.steps.iter().map(|s| serde_json::json!({
                "index": s.index, "round": s.round, "kind": s.kind, "values": s.values,
                "cost": finite(s.cost), "measured": s.measured.iter().map(|v| finite(*v)).collect::<Vec<_>>(),
                "time_s": s.time_s, "error": s.error,
            })).collect::<Vec<_>>(),
        });
        std::fs::write(&json_path, serde_json::to_string_pretty(&json)? + "\n")
            .with_context(|| format!("writing {}", json_path.display()))?;
        let mut written = vec![json_path, toml_path];
        if fit.steps.iter().any(|s| s.cost > 0.0 && s.cost.is_finite()) {
            written.extend(chart(&self.out, &fit)?);
        }
        println!(
            "wrote {}",
            written
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
        Ok(())
    }
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

fn print_step(s: &Step, paths: &[&str]) {
    let vals = s
        .values
        .iter()
        .zip(paths)
        .map(|(v, p)| format!("{}={v:.5e}", p.rsplit('.').next().unwrap_or(p)))
        .collect::<Vec<_>>()
        .join(" ");
    let measured = s
        .measured
        .iter()
        .map(|v| format!("{v:.4e}"))
        .collect::<Vec<_>>()
        .join(" ");
    match &s.error {
        Some(e) => println!("[{:>3}] {:<8} {vals}  failed: {e}", s.index, s.kind),
        None => println!(
            "[{:>3}] {:<8} cost {:.4e}  {vals}  | {measured}  ({:.1} s)",
            s.index, s.kind, s.cost, s.time_s
        ),
    }
}

/// The result table: parameters, then targets against the model on the scene's own rule.
pub fn format_result(spec: &CalibrationSpec, names: &[String], fit: &FitResult) -> String {
    let mut out = String::new();
    if !spec.parameters.is_empty() {
        out +=
            "\nparameter                                   start          fitted         bounds\n";
        for ((p, v), s) in spec.parameters.iter().zip(&fit.values).zip(&fit.start) {
            out += &format!(
                "{:<40} {s:>12.5e}  {v:>12.5e}   [{:.4e}, {:.4e}] {}\n",
                p.path,
                p.min,
                p.max,
                if (v - p.min).abs() < 1e-6 * (p.max - p.min)
                    || (v - p.max).abs() < 1e-6 * (p.max - p.min)
                {
                    "(at a bound)"
                } else {
                    ""
                }
            );
        }
    }
    out += &format!(
        "\ntarget                                   target        model     error   weight   ({} DOFs)\n",
        fit.dofs[1]
    );
    for (i, (t, name)) in spec.targets.iter().zip(names).enumerate() {
        let m = &fit.confirmed.measured[i];
        let err = if t.scalable() {
            format!("{:+.2} %", 100.0 * (m.value / t.value() - 1.0))
        } else {
            format!("{:+.0}", m.value - t.value())
        };
        out += &format!(
            "{name:<36} {:>12.5e} {:>12.5e} {err:>9} {:>8.2}   {}\n",
            t.value(),
            m.value,
            t.weight,
            m.note
        );
    }
    out += &format!(
        "{} evaluations in {:.0} s; search stopped: {}\n",
        fit.steps.len(),
        fit.time_s,
        fit.stops.join("; ")
    );
    out
}

fn chart(out: &Path, fit: &FitResult) -> Result<Vec<PathBuf>> {
    let mut series = Vec::new();
    for (kind, style) in [
        ("search", SeriesStyle::LineMarkers),
        ("jacobian", SeriesStyle::Markers),
        ("confirm", SeriesStyle::Markers),
    ] {
        let points: Vec<(f64, f64)> = fit
            .steps
            .iter()
            .filter(|s| s.kind == kind && s.cost.is_finite() && s.cost > 0.0)
            .map(|s| (s.index as f64, s.cost))
            .collect();
        if !points.is_empty() {
            series.push(Series {
                name: match kind {
                    "search" => "search steps (cheap rule)".into(),
                    "jacobian" => "difference steps".into(),
                    _ => "scene's own rule".into(),
                },
                points,
                style,
                neutral: Vec::new(),
                highlight: Vec::new(),
            });
        }
    }
    Ok(line_chart(
        &out.join("convergence"),
        "Calibration: cost per model evaluation",
        "evaluation",
        "cost sum (w ln(model / target))^2 / 2",
        &series,
        &ChartOptions {
            log_y: true,
            ..ChartOptions::default()
        },
    )?)
}
