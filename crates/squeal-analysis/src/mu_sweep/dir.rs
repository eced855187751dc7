//! A mu sweep run into an output directory: its checkpoint (finished points survive a
//! killed run and `resume` continues it), `sweep.csv` and `summary.json`. The charts are
//! drawn by the caller from the returned sweep.

use super::{run_sweep, CouplingReport, MuSweep, MuSweepSettings};
use crate::outdir::{self, RunError};
use crate::pipeline::Prepared;
use crate::profile::{peak_rss_mb, Profile, StageTime};
use crate::sweep::files::{max_error_bound, open_checkpoint, write_csv, SweepEvent};
use serde::Serialize;
use squeal_core::Registry;
use std::path::Path;
use std::time::Instant;

/// `summary.json` of a mu sweep.
#[derive(Serialize)]
pub struct SweepSummary {
    /// The scene's name in messages.
    pub scene: String,
    /// Units of the numbers.
    pub units: &'static str,
    /// `[from, to, step]` as given.
    pub mu: [f64; 3],
    /// Band (Hz).
    pub band_hz: [f64; 2],
    /// Eigen solver.
    pub eigen: String,
    /// Reduction basis (`none`: full order).
    pub basis: String,
    /// Equilibrium solver.
    pub equilibrium: String,
    /// Contact law.
    pub law: String,
    /// The contact law's parameters, `k=v, ...` (left out when none was given).
    #[serde(skip_serializing_if = "String::is_empty")]
    pub law_params: String,
    /// Free DOFs of the model.
    pub dofs: usize,
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    pub dvr_margin: f64,
    /// Points of the sweep.
    pub points: usize,
    /// Points where the contact set changed (a new operator and basis).
    pub rebuilds: usize,
    /// Largest basis.
    pub max_basis_size: usize,
    /// Worst backward error of every point's modes.
    pub max_backward_error: f64,
    /// Worst forward error estimate (`error_bound`) of every point's modes (null: not
    /// computed).
    pub max_error_bound: f64,
    /// Free-interface modes of tracking.
    pub free_interface_modes: usize,
    /// Wall time (s).
    pub time_s: f64,
    /// The couplings.
    pub couplings: Vec<CouplingReport>,
    /// Where the time went (points read back from a checkpoint excluded).
    pub stages: Vec<StageTime>,
    /// Peak resident memory of the process (MB).
    pub peak_rss_mb: Option<f64>,
}

/// Runs the sweep `settings` of `prep` into `out`, claimed for `command`: checkpoint,
/// `sweep.csv`, `summary.json`. `range` is `[from, to, step]` as given; `setup` holds the
/// stages run before (building `prep`), reported first. A directory that holds finished
/// points is continued with `resume` and refused without it.
#[allow(clippy::too_many_arguments)]
pub fn run_into(
    registry: &Registry,
    prep: &Prepared,
    settings: &MuSweepSettings,
    range: [f64; 3],
    out: &Path,
    resume: bool,
    setup: &Profile,
    mut events: impl FnMut(SweepEvent<'_>),
) -> Result<(SweepSummary, MuSweep), RunError> {
    let start = Instant::now();
    // the points depend on these (not on the mu list: shards and extensions share them)
    let mut inputs = serde_json::json!({
        "scene": prep.scene.to_toml(),
        "basis": settings.basis,
        "basis_opts": format!("{:?}", settings.basis_params),
        "eigen": settings.eigen,
        "equilibrium": settings.equilibrium,
        "law": settings.law,
        "band_hz": settings.band_hz,
        "tol": settings.tol,
        "squeal": env!("CARGO_PKG_VERSION"),
    });
    // only when given, so that sweeps run before law parameters existed still resume
    if !settings.law_params.0.is_empty() {
        inputs["law_params"] = settings.law_params.to_string().into();
    }
    let ckpt = open_checkpoint(
        out,
        "sweep mu",
        "a mu sweep",
        resume,
        inputs,
        settings.condition,
        settings.mus.len(),
        &mut events,
    )?;
    let sweep = run_sweep(registry, prep, settings, Some(&ckpt), |p| {
        events(SweepEvent::Point(p))
    })
    .map_err(outdir::stage("the mu sweep"))?;
    let points = &sweep.points;
    write_csv(
        &out.join("sweep.csv"),
        "mu",
        points,
        &sweep.branches,
        settings.dvr_margin,
    )?;
    let mut profile = setup.clone();
    profile.extend_prefixed("", &sweep.profile);
    let summary = SweepSummary {
        scene: prep.file.clone(),
        units: "SI: frequencies in Hz, DvR = Re/Im (dimensionless), times in s",
        mu: range,
        band_hz: settings.band_hz,
        eigen: settings.eigen.clone(),
        basis: settings.basis.clone(),
        equilibrium: settings.equilibrium.clone(),
        law: settings.law.clone(),
        law_params: settings.law_params.to_string(),
        dofs: prep.model.dofs.n_free(),
        dvr_margin: settings.dvr_margin,
        points: points.len(),
        rebuilds: points.iter().filter(|p| p.rebuilt).count(),
        max_basis_size: points.iter().map(|p| p.basis_size).max().unwrap_or(0),
        max_backward_error: points
            .iter()
            .flat_map(|p| p.modes.iter().map(|m| m.backward_error))
            .fold(0.0, f64::max),
        max_error_bound: max_error_bound(points),
        free_interface_modes: sweep.free.freq_hz.len(),
        time_s: start.elapsed().as_secs_f64(),
        couplings: sweep.couplings.clone(),
        stages: profile.stages,
        peak_rss_mb: peak_rss_mb(),
    };
    outdir::write_json(&out.join("summary.json"), &summary)?;
    Ok((summary, sweep))
}
