//! `squeal sweep mu`: the friction-coefficient sweep with mode tracking, coupling
//! detection, CSV/JSON outputs and the paper's Figure 5 and 7 charts.

use anyhow::{Context, Result};
use serde::Serialize;
use squeal_analysis::pipeline::{run_mu_sweep, FreeModes, Prepared};
use squeal_analysis::sweep::{
    couplings, track, Branch, Checkpoint, Coupling, SweepPoint, TrackOptions,
};
use squeal_core::{EigenParams, FrictionalOperator, Registry};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Inputs of a sweep.
pub struct Args<'a> {
    pub scene: Option<&'a str>,
    pub from: f64,
    pub to: f64,
    pub step: f64,
    pub eigen: &'a str,
    pub basis: &'a str,
    pub basis_opts: &'a [String],
    pub band: [f64; 2],
    pub equilibrium: &'a str,
    pub law: &'a str,
    pub dvr_tol: f64,
    pub out: &'a Path,
}

/// `summary.json`.
#[derive(Serialize)]
pub struct Summary {
    pub scene: String,
    pub units: &'static str,
    pub mu: [f64; 3],
    pub band_hz: [f64; 2],
    pub eigen: String,
    pub basis: String,
    pub equilibrium: String,
    pub law: String,
    pub dofs: usize,
    pub dvr_tol: f64,
    pub points: usize,
    pub rebuilds: usize,
    pub max_basis_size: usize,
    pub max_backward_error: f64,
    pub free_interface_modes: usize,
    pub time_s: f64,
    pub couplings: Vec<CouplingOut>,
}

#[derive(Serialize)]
pub struct CouplingOut {
    pub freq_hz: f64,
    pub mu_from: f64,
    pub mu_to: f64,
    pub max_dvr: f64,
    pub partners: Vec<usize>,
    /// The free-interface modes the unstable mode is made of (MAC > 0.1 at its peak).
    pub free_interface_mac: Vec<(String, f64)>,
}

pub fn mus(from: f64, to: f64, step: f64) -> Result<Vec<f64>> {
    if !(from.is_finite()
        && to.is_finite()
        && step.is_finite()
        && from >= 0.0
        && to >= from
        && step > 0.0)
    {
        anyhow::bail!(
            "--from/--to/--step: expected 0 <= from <= to and step > 0, got {from}, {to}, {step}"
        );
    }
    let n = ((to - from) / step + 1e-9).floor() as usize;
    Ok((0..=n)
        .map(|k| ((from + k as f64 * step) * 1e12).round() / 1e12)
        .collect())
}

pub fn run(registry: &Registry, a: &Args<'_>) -> Result<Summary> {
    let start = Instant::now();
    let mus = mus(a.from, a.to, a.step)?;
    let (scene, file) = crate::load_scene(a.scene)?;
    std::fs::create_dir_all(a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let scene_toml = scene.to_toml();
    let prep = Prepared::new(registry, scene, &file)?;
    let free = prep
        .free_interface_modes(registry, "arpack", 1.5 * a.band[1])
        .context("free-interface modes (the reference of tracking)")?;
    let params = EigenParams {
        fmin_hz: a.band[0],
        fmax_hz: a.band[1],
        tol: 1e-10,
        ..EigenParams::default()
    };
    let mut method = squeal_analysis::pipeline::Method::new(
        registry,
        a.basis,
        &crate::stability::parse_params(a.basis_opts)?,
        a.eigen,
        "arpack",
        params,
    )?;
    method.prepare_free_interface(&prep.model, &prep.set)?;
    let step = |op: &FrictionalOperator, mu: f64, rebuilt: bool| method.solve(op, mu, rebuilt);
    let ckpt = Checkpoint::new(a.out.join("sweep.partial.jsonl"));
    // the points depend on these (not on the mu list: shards and extensions share them)
    let inputs = serde_json::json!({
        "scene": scene_toml,
        "basis": a.basis,
        "basis_opts": a.basis_opts,
        "eigen": a.eigen,
        "equilibrium": a.equilibrium,
        "law": a.law,
        "band_hz": a.band,
        "squeal": env!("CARGO_PKG_VERSION"),
    });
    ckpt.claim(&inputs).map_err(anyhow::Error::msg)?;
    let points = run_mu_sweep(
        &prep,
        registry,
        &mus,
        a.equilibrium,
        a.law,
        &free,
        Some(&ckpt),
        step,
        |p| {
            let unstable = p.modes.iter().filter(|m| m.dvr > a.dvr_tol).count();
            eprintln!(
                "mu {:.3}: {} modes, {} unstable, {} active pairs{}, solve {:.2} s",
                p.mu,
                p.modes.len(),
                unstable,
                p.active_pairs,
                if p.rebuilt { " (new contact set)" } else { "" },
                p.times_s[2]
            );
        },
    )?;
    let branches = track(&points, &TrackOptions::default());
    let cps = couplings(&points, &branches, a.dvr_tol);
    write_csv(&a.out.join("sweep.csv"), &points, &branches, a.dvr_tol)?;
    charts(a.out, &points, &branches, a.dvr_tol)?;
    let coupled: Vec<CouplingOut> = cps
        .iter()
        .map(|c| coupling_out(c, &points, &branches, &free))
        .collect();
    mac_charts(a.out, &coupled)?;
    let summary = Summary {
        scene: file,
        units: "SI: frequencies in Hz, DvR = Re/Im (dimensionless), times in s",
        mu: [a.from, a.to, a.step],
        band_hz: a.band,
        eigen: a.eigen.into(),
        basis: a.basis.into(),
        equilibrium: a.equilibrium.into(),
        law: a.law.into(),
        dofs: prep.model.dofs.n_free(),
        dvr_tol: a.dvr_tol,
        points: points.len(),
        rebuilds: points.iter().filter(|p| p.rebuilt).count(),
        max_basis_size: points.iter().map(|p| p.basis_size).max().unwrap_or(0),
        max_backward_error: points
            .iter()
            .flat_map(|p| p.modes.iter().map(|m| m.backward_error))
            .fold(0.0, f64::max),
        free_interface_modes: free.freq_hz.len(),
        time_s: start.elapsed().as_secs_f64(),
        couplings: coupled,
    };
    std::fs::write(
        a.out.join("summary.json"),
        serde_json::to_string_pretty(&summary)?,
    )?;
    Ok(summary)
}

fn coupling_out(
    c: &Coupling,
    points: &[SweepPoint],
    branches: &[Branch],
    free: &FreeModes,
) -> CouplingOut {
    // the unstable mode at its peak
    let b = &branches[c.partners[0]];
    let peak = (0..points.len())
        .filter_map(|p| b.modes[p].map(|m| (p, m)))
        .max_by(|x, y| {
            points[x.0].modes[x.1]
                .dvr
                .total_cmp(&points[y.0].modes[y.1].dvr)
        });
    let mut mac = Vec::new();
    if let Some((p, m)) = peak {
        let sig = &points[p].modes[m].signature;
        let total: f64 = sig.iter().map(|z| z[0] * z[0] + z[1] * z[1]).sum();
        for (k, z) in sig.iter().enumerate() {
            let v = (z[0] * z[0] + z[1] * z[1]) / total.max(f64::MIN_POSITIVE);
            if v > 0.1 {
                mac.push((format!("{} ({:.0} Hz)", free.labels[k], free.freq_hz[k]), v));
            }
        }
        mac.sort_by(|x, y| y.1.total_cmp(&x.1));
    }
    CouplingOut {
        freq_hz: c.freq_hz,
        mu_from: c.mu_from,
        mu_to: c.mu_to,
        max_dvr: c.max_dvr,
        partners: c.partners.clone(),
        free_interface_mac: mac,
    }
}

fn write_csv(path: &Path, points: &[SweepPoint], branches: &[Branch], tol: f64) -> Result<()> {
    let mut f = std::io::BufWriter::new(
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?,
    );
    writeln!(
        f,
        "mu,branch,mode,freq_hz,re,dvr,unstable,backward_error,active_pairs,basis_size"
    )?;
    for (p, pt) in points.iter().enumerate() {
        for (m, md) in pt.modes.iter().enumerate() {
            let b = branches
                .iter()
                .find(|b| b.modes[p] == Some(m))
                .map_or(usize::MAX, |b| b.id);
            writeln!(
                f,
                "{},{},{},{:.6},{:.6e},{:.6e},{},{:.3e},{},{}",
                pt.mu,
                b,
                m,
                md.freq_hz,
                md.re,
                md.dvr,
                u8::from(md.dvr > tol),
                md.backward_error,
                pt.active_pairs,
                pt.basis_size
            )?;
        }
    }
    Ok(())
}

fn charts(
    out: &Path,
    points: &[SweepPoint],
    branches: &[Branch],
    tol: f64,
) -> Result<Vec<PathBuf>> {
    use squeal_plot::{line_chart, ChartOptions, Series, SeriesStyle};
    let series = |y: &dyn Fn(&squeal_analysis::sweep::SweepMode) -> f64| -> Vec<Series> {
        branches
            .iter()
            .map(|b| {
                let pts: Vec<(usize, usize)> = (0..points.len())
                    .filter_map(|p| b.modes[p].map(|m| (p, m)))
                    .collect();
                Series {
                    name: String::new(),
                    points: pts
                        .iter()
                        .map(|&(p, m)| (points[p].mu, y(&points[p].modes[m])))
                        .collect(),
                    style: SeriesStyle::LineMarkers,
                    highlight: pts
                        .iter()
                        .map(|&(p, m)| points[p].modes[m].dvr > tol)
                        .collect(),
                }
            })
            .collect()
    };
    let mut files = line_chart(
        &out.join("frequency_vs_mu"),
        "Frequency of the tracked modes (unstable in red)",
        "friction coefficient mu",
        "frequency (Hz)",
        &series(&|m| m.freq_hz),
        &ChartOptions {
            highlight_label: Some("unstable".into()),
            ..ChartOptions::default()
        },
    )?;
    files.extend(line_chart(
        &out.join("dvr_vs_mu"),
        "Divergence rate Re/Im of the tracked modes (unstable in red)",
        "friction coefficient mu",
        "DvR = Re(lambda)/Im(lambda)",
        &series(&|m| m.dvr),
        &ChartOptions {
            hline: Some(0.0),
            highlight_label: Some("unstable".into()),
            ..ChartOptions::default()
        },
    )?);
    Ok(files)
}

fn mac_charts(out: &Path, couplings: &[CouplingOut]) -> Result<()> {
    for (i, c) in couplings.iter().enumerate() {
        if c.free_interface_mac.is_empty() {
            continue;
        }
        squeal_plot::bar_chart(
            &out.join(format!("mac_coupling_{}", i + 1)),
            &format!(
                "Unstable mode near {:.0} Hz (mu {}-{}): MAC with the free-interface modes",
                c.freq_hz, c.mu_from, c.mu_to
            ),
            "free-interface mode",
            "MAC",
            &c.free_interface_mac,
        )?;
    }
    Ok(())
}
