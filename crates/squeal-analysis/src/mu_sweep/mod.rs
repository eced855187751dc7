//! A friction-coefficient sweep of a prepared scene, run end to end: the mu list, the
//! free-interface modes (the reference of tracking), the method (full order or a basis),
//! the points ([`crate::pipeline::run_mu_sweep`]), the tracked branches and the couplings
//! with the free-interface modes each unstable mode is made of. `squeal sweep mu`,
//! `validate` and the calibration's coupling targets all run it; [`run_into`] runs it
//! into an output directory (checkpoint, `sweep.csv`, `summary.json`).

use crate::family::{run_family_sweep, SceneMu};
use crate::pipeline::{FreeModes, Method, Prepared, Result, MODAL_SOLVER};
use crate::profile::Profile;
use crate::sweep::{Branch, Checkpoint, SweepPoint};
use serde::Serialize;
use squeal_core::{EigenParams, Params, Registry};
use std::time::Instant;

mod dir;
pub use crate::sweep::files::SweepEvent;
pub use dir::{run_into, SweepSummary};

/// What a sweep computes and how.
#[derive(Debug, Clone)]
pub struct MuSweepSettings {
    /// Friction coefficients, increasing.
    pub mus: Vec<f64>,
    /// Reduction basis plugin, or `none` for full order.
    pub basis: String,
    /// The basis plugin's parameters.
    pub basis_params: Params,
    /// Eigen solver (of the reduced problem with a basis).
    pub eigen: String,
    /// Band (Hz).
    pub band_hz: [f64; 2],
    /// Relative tolerance of the eigen solves.
    pub tol: f64,
    /// Equilibrium solver plugin.
    pub equilibrium: String,
    /// Contact law plugin.
    pub law: String,
    /// The contact law's parameters (a penalty's stiffness).
    pub law_params: Params,
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    pub dvr_margin: f64,
    /// Friction coefficients whose complex modes (with their vectors) are kept in
    /// [`MuSweep::kept`], for comparisons with full order.
    pub keep_modes_at: Vec<f64>,
    /// Whether full-order modes get condition numbers and forward error estimates above
    /// the size where the solvers skip them ([`Method::set_condition`]).
    pub condition: bool,
}

impl MuSweepSettings {
    /// A sweep over `mus` through `basis` (`none`: full order with `arpack`, else the
    /// reduced problem with `dense`), band `band_hz`, `lcp` equilibrium, Lagrange contact,
    /// tolerance 1e-10, no DvR margin.
    pub fn new(mus: Vec<f64>, basis: &str, band_hz: [f64; 2]) -> Self {
        Self {
            mus,
            basis: basis.into(),
            basis_params: Params::new(),
            eigen: if basis == "none" { "arpack" } else { "dense" }.into(),
            band_hz,
            tol: 1e-10,
            equilibrium: "lcp".into(),
            law: "lagrange".into(),
            law_params: Params::new(),
            dvr_margin: 0.0,
            keep_modes_at: Vec::new(),
            condition: false,
        }
    }
}

/// Most points of one mu list (a finer step is a typing error, not a study).
pub const MAX_POINTS: usize = 10_000;

/// The friction coefficients `from, from + step, ..., <= to` (rounded to 1e-12), or what
/// is wrong with the range (at most [`MAX_POINTS`]).
pub fn mu_list(from: f64, to: f64, step: f64) -> std::result::Result<Vec<f64>, String> {
    list(from, to, step, true)
}

/// The values `from, from + step, ..., <= to` of any swept parameter (rounded to 1e-12),
/// or what is wrong with the range (at most [`MAX_POINTS`]).
pub fn value_list(from: f64, to: f64, step: f64) -> std::result::Result<Vec<f64>, String> {
    list(from, to, step, false)
}

fn list(
    from: f64,
    to: f64,
    step: f64,
    non_negative: bool,
) -> std::result::Result<Vec<f64>, String> {
    if !(from.is_finite()
        && to.is_finite()
        && step.is_finite()
        && (from >= 0.0 || !non_negative)
        && to >= from
        && step > 0.0)
    {
        return Err(format!(
            "expected {}from <= to and step > 0, got from = {from}, to = {to}, step = {step}",
            if non_negative { "0 <= " } else { "" }
        ));
    }
    let points = (to - from) / step + 1e-9;
    if points >= MAX_POINTS as f64 {
        return Err(format!(
            "{:.3e} points from {from} to {to} by {step}: expected at most {MAX_POINTS} (a larger step)",
            points.floor() + 1.0
        ));
    }
    let n = points.floor() as usize;
    Ok((0..=n)
        .map(|k| ((from + k as f64 * step) * 1e12).round() / 1e12)
        .collect())
}

/// A coupling of a sweep with what it is made of.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CouplingReport {
    /// Frequency at the largest DvR (Hz).
    pub freq_hz: f64,
    /// First unstable mu.
    pub mu_from: f64,
    /// Last unstable mu.
    pub mu_to: f64,
    /// Largest DvR.
    pub max_dvr: f64,
    /// The unstable branch and its partner.
    pub partners: Vec<usize>,
    /// The free-interface modes the unstable mode is made of (MAC > 0.1 at its peak).
    pub free_interface_mac: Vec<(String, f64)>,
}

/// A finished sweep.
pub struct MuSweep {
    /// The points, in increasing mu.
    pub points: Vec<SweepPoint>,
    /// Tracked branches.
    pub branches: Vec<Branch>,
    /// Couplings, in the order of their first unstable mu.
    pub couplings: Vec<CouplingReport>,
    /// The free-interface modes of tracking and make-up.
    pub free: FreeModes,
    /// The complex modes at [`MuSweepSettings::keep_modes_at`] computed in this run (a
    /// point read back from a checkpoint keeps none).
    pub kept: Vec<(f64, squeal_core::operator::ComplexModes)>,
    /// Wall time (s).
    pub time_s: f64,
    /// Where it went: the free model's modes and synthesis, then the stages of the points
    /// computed in this run.
    pub profile: Profile,
}

/// Runs the sweep `s` on `prep`; finished points go to `checkpoint` (a resumed sweep
/// reads them back), `progress` sees every point.
pub fn run_sweep(
    registry: &Registry,
    prep: &Prepared,
    s: &MuSweepSettings,
    checkpoint: Option<&Checkpoint>,
    progress: impl FnMut(&SweepPoint),
) -> Result<MuSweep> {
    let start = Instant::now();
    let params = EigenParams {
        fmin_hz: s.band_hz[0],
        fmax_hz: s.band_hz[1],
        tol: s.tol,
        ..EigenParams::default()
    };
    let mut method = Method::new(
        registry,
        &s.basis,
        &s.basis_params,
        &s.eigen,
        MODAL_SOLVER,
        params,
    )?;
    method.set_condition(s.condition);
    method.share_modal_cache(prep.modal_cache());
    // consecutive points are near each other: an iterative basis starts from the last
    method.set_warm_start(true);
    let mut profile = Profile::new();
    // the basis's model stage first: the modes of a synthesis, up to a higher cutoff,
    // serve the tracking too
    let t = Instant::now();
    if method.prepare_stage_on(prep)?.is_some() {
        profile.add(
            &format!("model stage of `{}`", method.basis_name),
            t.elapsed().as_secs_f64(),
        );
    }
    let t = Instant::now();
    let free = prep.free_interface_modes(registry, MODAL_SOLVER, 1.5 * s.band_hz[1])?;
    profile.add("free modes of tracking", t.elapsed().as_secs_f64());
    let mut family = SceneMu::new(prep, registry, &s.equilibrium, &s.law, &s.law_params);
    let sweep = run_family_sweep(
        &mut family,
        &s.mus,
        &mut method,
        &free,
        s.dvr_margin,
        &s.keep_modes_at,
        checkpoint,
        progress,
    )?;
    let couplings = sweep
        .couplings
        .into_iter()
        .map(|c| CouplingReport {
            freq_hz: c.freq_hz,
            mu_from: c.from,
            mu_to: c.to,
            max_dvr: c.max_dvr,
            partners: c.partners,
            free_interface_mac: c.makeup,
        })
        .collect();
    profile.extend_prefixed("", &sweep.profile);
    Ok(MuSweep {
        points: sweep.points,
        branches: sweep.branches,
        couplings,
        free,
        kept: sweep.kept,
        time_s: start.elapsed().as_secs_f64(),
        profile,
    })
}

/// The coupling of `couplings` that stands for a published one at `freq_hz`: within 15 %
/// of it in frequency, the largest DvR among those (`validate`'s paper comparison and the
/// calibration's coupling targets).
pub fn matching_coupling(couplings: &[CouplingReport], freq_hz: f64) -> Option<&CouplingReport> {
    couplings
        .iter()
        .filter(|c| (c.freq_hz - freq_hz).abs() / freq_hz < 0.15)
        .max_by(|x, y| x.max_dvr.total_cmp(&y.max_dvr))
}
