//! One evaluation of a scene against the targets of a calibration: build the model, then
//! only the analyses the targets need (free-interface modes, the sliding equilibrium at
//! mu = 0, tied modes on each contact set), each measured value with its residual.

use super::spec::{Search, Target, TargetKind};
use super::tied::*;
use crate::modal::{label_modes, ModeRecord};
use crate::mu_sweep::{
    matching_coupling, mu_list, run_sweep, CouplingReport, MuSweep, MuSweepSettings,
};
use crate::pipeline::{PipelineError, Prepared, Result};
use serde::Serialize;
use squeal_core::{EigenParams, EigenSolver, Params, RealModes, Registry, SymmetricProblem};
use squeal_scene::{build, BodyKind, Model, Scene};
use std::time::Instant;

/// What one target measured on one scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measured {
    /// The value in the target's unit (Hz, N/m, a count); NaN when not found.
    pub value: f64,
    /// Unweighted residual: `ln(value / target)`; for counts, how far (in log-frequency)
    /// the modes next to the threshold lie on its wrong side; 1 when the value is missing.
    pub residual: f64,
    /// Further residuals of the target, weighted like `residual` (a coupling's mu
    /// window: first and last unstable mu against the target's).
    pub extra: Vec<f64>,
    /// What was picked (e.g. the tied mode's make-up share).
    pub note: String,
}

/// An evaluation of all targets on one scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evaluation {
    /// Per target, in the spec's order.
    pub measured: Vec<Measured>,
    /// Free DOFs of the model.
    pub dofs: usize,
    /// Wall time (s).
    pub time_s: f64,
}

impl Evaluation {
    /// `sum (w_i r_i)^2 / 2` with the residuals scaled by `ratios` first (see
    /// [`residual_with`]).
    pub fn cost(&self, targets: &[Target], ratios: &[f64]) -> f64 {
        self.weighted(targets, ratios)
            .iter()
            .map(|r| r * r)
            .sum::<f64>()
            / 2.0
    }

    /// Weighted residuals `w_i r_i`, each against its target divided by `ratios[i]`,
    /// followed by the target's further residuals.
    pub fn weighted(&self, targets: &[Target], ratios: &[f64]) -> Vec<f64> {
        targets
            .iter()
            .zip(&self.measured)
            .zip(ratios)
            .flat_map(|((t, m), &q)| {
                std::iter::once(t.weight * residual_with(t, m, q))
                    .chain(m.extra.iter().map(move |r| t.weight * r))
            })
            .collect()
    }
}

/// The residual of `m` against target `t` whose value is divided by `ratio` (the
/// correction from the search rule to the scene's own: a frequency that the fine rule
/// puts 2 % lower is aimed 2 % higher on the coarse one).
pub fn residual_with(t: &Target, m: &Measured, ratio: f64) -> f64 {
    if !t.scalable() || !m.value.is_finite() {
        return m.residual;
    }
    let r = m.residual + ratio.ln();
    // inside the target's tolerance band the residual is zero, outside it counts from
    // the band's edge
    let band = t.within.ln_1p();
    r.signum() * (r.abs() - band).max(0.0)
}

/// Evaluates every target on `scene` (`file` names it in errors).
pub fn evaluate(
    registry: &Registry,
    scene: &Scene,
    file: &str,
    targets: &[Target],
    search: &Search,
) -> Result<Evaluation> {
    let start = Instant::now();
    let (prep, own) = build_for(registry, scene, file, targets)?;
    let model = match (&prep, &own) {
        (Some(p), _) => &p.model,
        (None, Some(m)) => m,
        (None, None) => unreachable!("one of them is built"),
    };
    let solver = registry
        .eigen
        .create(&search.eigen, &Params::new())
        .map_err(|e| core("eigen solver", e))?;
    let (top, free) = free_modes(solver.as_ref(), model, targets)?;
    let mphi = free.as_ref().map(|(m, _)| times_mass(model, m));
    let mut tied_cache: Vec<(Option<u64>, RealModes, Vec<Vec<f64>>)> = Vec::new();
    let mut sweep: Option<MuSweep> = None;
    let mut measured = Vec::with_capacity(targets.len());
    for t in targets {
        let m = match &t.kind {
            TargetKind::Stiffness { value_n_per_m } => {
                let prep = prep.as_ref().expect("contact targets build the rig");
                let eq = prep.equilibrium(registry, &search.equilibrium, "lagrange", 0.0)?;
                let k = eq.total_normal_force_n / eq.displacement_m;
                Measured {
                    extra: Vec::new(),
                    value: k,
                    residual: (k / value_n_per_m).ln(),
                    note: format!(
                        "{:.1} N at {:.2} um",
                        eq.total_normal_force_n,
                        eq.displacement_m * 1e6
                    ),
                }
            }
            TargetKind::Mode {
                body,
                label,
                freq_hz,
            } => {
                let (_, records) = free.as_ref().expect("free modes solved");
                mode_measure(records, body, label, *freq_hz, top)
            }
            TargetKind::ModeCount {
                body,
                below_hz,
                count,
            } => {
                let (_, records) = free.as_ref().expect("free modes solved");
                count_residual(records, body, *below_hz, *count, top)
            }
            TargetKind::Coupling { freq_hz, mu_range } => {
                let prep = prep.as_ref().expect("contact targets build the rig");
                if sweep.is_none() {
                    let [from, to, step] = search.sweep.mu;
                    let mus = mu_list(from, to, step).map_err(|e| PipelineError::Core {
                        stage: "the calibration's sweep".into(),
                        source: squeal_core::Error::Invalid(e),
                    })?;
                    let settings =
                        MuSweepSettings::new(mus, &search.sweep.basis, search.sweep.band_hz);
                    sweep = Some(run_sweep(registry, prep, &settings, None, |_| {})?);
                }
                let cps = &sweep.as_ref().expect("swept").couplings;
                coupling_measure(cps, *freq_hz, *mu_range)
            }
            TargetKind::TiedMode {
                mu,
                makeup,
                freq_hz,
                makeup_lowest,
                ..
            } => {
                let prep = prep.as_ref().expect("contact targets build the rig");
                let key = mu.map(f64::to_bits);
                if !tied_cache.iter().any(|(k, _, _)| *k == key) {
                    let fmax = targets
                        .iter()
                        .filter(|u| matches!(u.kind, TargetKind::TiedMode { mu: m2, .. } if m2.map(f64::to_bits) == key))
                        .map(|u| window(u)[1])
                        .fold(0.0, f64::max);
                    let (modes, shapes) = tied_modes(registry, prep, search, *mu, fmax)?;
                    tied_cache.push((key, modes, shapes));
                }
                let (_, modes, shapes) = tied_cache
                    .iter()
                    .find(|(k, _, _)| *k == key)
                    .expect("cached");
                let (_, records) = free.as_ref().expect("free modes solved");
                let mphi = mphi.as_ref().expect("free modes solved");
                let matching = makeup_columns(records, makeup, *makeup_lowest);
                pick_by_makeup(
                    model,
                    modes,
                    shapes,
                    records,
                    mphi,
                    &matching,
                    *freq_hz,
                    window(t),
                )
            }
        };
        measured.push(m);
    }
    Ok(Evaluation {
        measured,
        dofs: model.m.nrows(),
        time_s: start.elapsed().as_secs_f64(),
    })
}

/// What the targets need built: the whole rig with its condensation (contact targets),
/// or only the bodies the modal targets name.
pub(super) fn build_for(
    registry: &Registry,
    scene: &Scene,
    file: &str,
    targets: &[Target],
) -> Result<(Option<Prepared>, Option<Model>)> {
    // contact targets need the whole rig and its condensation; modal targets only the
    // bodies they name
    let contact = targets.iter().any(|t| {
        matches!(
            t.kind,
            TargetKind::Stiffness { .. }
                | TargetKind::TiedMode { .. }
                | TargetKind::Coupling { .. }
        )
    });
    Ok(if contact {
        (Some(Prepared::new(registry, scene.clone(), file)?), None)
    } else {
        let bodies: Vec<&str> = targets
            .iter()
            .filter_map(|t| match &t.kind {
                TargetKind::Mode { body, .. } | TargetKind::ModeCount { body, .. } => {
                    Some(body.as_str())
                }
                _ => None,
            })
            .collect();
        let which = if bodies.iter().all(|b| *b == "disc") {
            BodyKind::Disc
        } else if bodies.iter().all(|b| *b == "pin") {
            BodyKind::Pin
        } else {
            BodyKind::All
        };
        (None, Some(build(scene, which, registry, file)?))
    })
}

/// Free-interface modes with their labels.
pub(super) type FreeModes = (RealModes, Vec<ModeRecord>);

/// The free-interface modes of `model` up to past every frequency a target looks at
/// (that top, and the modes with their labels; none when no target needs them).
pub(super) fn free_modes(
    solver: &dyn EigenSolver,
    model: &Model,
    targets: &[Target],
) -> Result<(f64, Option<FreeModes>)> {
    let top = targets
        .iter()
        .map(|t| match &t.kind {
            TargetKind::Stiffness { .. } => 0.0,
            TargetKind::Mode { freq_hz, .. } => 1.3 * freq_hz,
            TargetKind::ModeCount { below_hz, .. } => 1.3 * below_hz,
            TargetKind::Coupling { .. } => 0.0,
            TargetKind::TiedMode { .. } => 1.5 * window(t)[1],
        })
        .fold(0.0, f64::max);
    let free = if top > 0.0 {
        let params = EigenParams {
            fmax_hz: top,
            tol: 1e-10,
            ..EigenParams::default()
        };
        let modes = solver
            .solve_symmetric(
                &SymmetricProblem {
                    k: model.k.as_ref(),
                    m: model.m.as_ref(),
                },
                &params,
            )
            .map_err(|e| core("free-interface modes", e))?;
        let records = label_modes(model, &modes);
        Some((modes, records))
    } else {
        None
    };
    Ok((top, free))
}

/// A labelled mode target: the mean frequency of the body's modes with that label (the
/// two members of a disc doublet).
pub(super) fn mode_measure(
    records: &[ModeRecord],
    body: &str,
    label: &str,
    freq_hz: f64,
    top: f64,
) -> Measured {
    let f: Vec<f64> = records
        .iter()
        .filter(|r| r.body == body && r.label == label)
        .map(|r| r.freq_hz)
        .collect();
    let pick: Vec<f64> = if body == "disc" {
        f.iter().take(2).copied().collect()
    } else {
        f.iter().take(1).copied().collect()
    };
    if pick.is_empty() {
        missing(format!("no {body} mode labelled {label} below {top:.0} Hz"))
    } else {
        let v = pick.iter().sum::<f64>() / pick.len() as f64;
        Measured {
            extra: Vec::new(),
            value: v,
            residual: (v / freq_hz).ln(),
            note: format!("{} mode(s)", pick.len()),
        }
    }
}

pub(super) fn core(stage: &str, source: squeal_core::Error) -> PipelineError {
    PipelineError::Core {
        stage: stage.into(),
        source,
    }
}

/// A coupling target measured on a sweep's couplings: frequency log-ratio, then the
/// first and last unstable mu against the wanted window; a missing coupling counts as a
/// full misfit (1, and half the window's distance scale for each end).
pub(super) fn coupling_measure(cps: &[CouplingReport], freq_hz: f64, range: [f64; 2]) -> Measured {
    match matching_coupling(cps, freq_hz) {
        Some(c) => Measured {
            value: c.freq_hz,
            residual: (c.freq_hz / freq_hz).ln(),
            extra: vec![c.mu_from - range[0], c.mu_to - range[1]],
            note: format!(
                "mu {}-{}, max DvR {:.2e}; {}",
                c.mu_from,
                c.mu_to,
                c.max_dvr,
                c.free_interface_mac
                    .iter()
                    .take(2)
                    .map(|(l, m)| format!("{l} {m:.2}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        },
        None => Measured {
            value: f64::NAN,
            residual: 1.0,
            extra: vec![0.5, 0.5],
            note: format!(
                "no coupling within 15 % of {freq_hz} Hz (found: {})",
                cps.iter()
                    .map(|c| format!("{:.0} Hz mu {}-{}", c.freq_hz, c.mu_from, c.mu_to))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        },
    }
}

pub(super) fn missing(note: String) -> Measured {
    Measured {
        extra: Vec::new(),
        value: f64::NAN,
        residual: 1.0,
        note,
    }
}

/// The window of a tied-mode target (Hz).
pub(super) fn window(t: &Target) -> [f64; 2] {
    match &t.kind {
        TargetKind::TiedMode {
            freq_hz, window_hz, ..
        } => window_hz.unwrap_or([0.5 * freq_hz, 2.0 * freq_hz]),
        _ => [0.0, 0.0],
    }
}
