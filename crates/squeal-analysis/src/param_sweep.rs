//! A sweep of the parameter of a parametric operator directory (`operator.toml` with
//! `parameter = "W"`, docs/operators.md) at a fixed mu, run into an output directory
//! (`squeal sweep param`): the operator at each value, its modes, tracking by MAC on the
//! real modes of its symmetric part at the first value, couplings; the checkpoint,
//! `sweep.csv` and `summary.json` of a mu sweep. The charts are drawn by the caller.

use crate::family::{reference_modes, run_family_sweep, FamilySweep, Parametric, SweepCoupling};
use crate::mu_sweep::value_list;
use crate::outdir::{self, RunError};
use crate::pipeline::{FreeModes, Method, MODAL_SOLVER};
use crate::sweep::files::{max_error_bound, open_checkpoint, write_csv, SweepEvent};
use serde::Serialize;
use squeal_core::{EigenParams, Params, Registry};
use squeal_io::ParametricOperator;
use std::path::Path;
use std::time::Instant;

/// What a parameter sweep computes and how. Errors name these fields (`from`, `mu`, ...).
#[derive(Debug, Clone)]
pub struct ParamSweepSettings {
    /// First value of the parameter.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Step.
    pub step: f64,
    /// Friction coefficient of every point: required when the operator has friction
    /// parts, 0 otherwise.
    pub mu: Option<f64>,
    /// Reduction basis plugin, or `none` for full order.
    pub basis: String,
    /// The basis plugin's parameters.
    pub basis_params: Params,
    /// Eigen solver.
    pub eigen: String,
    /// Band (Hz).
    pub band_hz: [f64; 2],
    /// Relative tolerance of the eigen solves.
    pub tol: f64,
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    pub dvr_margin: f64,
    /// Condition numbers of full-order modes above the solvers' automatic size.
    pub condition: bool,
}

/// `summary.json` of a parameter sweep.
#[derive(Serialize)]
pub struct ParamSummary {
    /// The operator directory.
    pub operator: String,
    /// Units of the numbers.
    pub units: &'static str,
    /// The swept parameter's name.
    pub parameter: String,
    /// `[from, to, step]` as given.
    pub range: [f64; 3],
    /// Friction coefficient of every point.
    pub mu: f64,
    /// Band (Hz).
    pub band_hz: [f64; 2],
    /// Eigen solver.
    pub eigen: String,
    /// Reduction basis.
    pub basis: String,
    /// Size of the operator.
    pub dofs: usize,
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    pub dvr_margin: f64,
    /// Points of the sweep.
    pub points: usize,
    /// Largest basis.
    pub max_basis_size: usize,
    /// Worst backward error of every point's modes.
    pub max_backward_error: f64,
    /// Worst `error_bound` of every point's modes (null: not computed).
    pub max_error_bound: f64,
    /// What the signatures of tracking are taken on.
    pub reference: String,
    /// Reference modes of tracking.
    pub reference_modes: usize,
    /// Wall time (s).
    pub time_s: f64,
    /// Couplings: frequency at the largest DvR, first and last unstable value, largest
    /// DvR, branches, and the reference modes the unstable mode is made of.
    pub couplings: Vec<SweepCoupling>,
}

/// What the reference modes of a parameter sweep are: the real modes of the operator's
/// real-mode pair at the first value (`pair`, its description).
fn reference_text(reference: &FreeModes, pair: &str) -> String {
    format!(
        "{} real modes ({:.1} to {:.1} Hz) of the real-mode pair: {pair} (no damping, \
         gyroscopic, circulatory or friction term)",
        reference.freq_hz.len(),
        reference.freq_hz.first().copied().unwrap_or(0.0),
        reference.freq_hz.last().copied().unwrap_or(0.0),
    )
}

/// Runs the sweep `s` of `family_op` (read from `dir`, parameter `name`) into `out`,
/// claimed for `squeal sweep param`. A directory that holds finished points is continued
/// with `resume` and refused without it.
#[allow(clippy::too_many_arguments)]
pub fn run_into(
    registry: &Registry,
    dir: &Path,
    family_op: &ParametricOperator,
    name: &str,
    s: &ParamSweepSettings,
    out: &Path,
    resume: bool,
    mut events: impl FnMut(SweepEvent<'_>),
) -> Result<(ParamSummary, FamilySweep), RunError> {
    let start = Instant::now();
    let values =
        value_list(s.from, s.to, s.step).map_err(|e| RunError::input("from/to/step", e))?;
    if let Some((lo, hi)) = family_op.range() {
        let last = *values.last().expect("a value list is never empty");
        if values[0] < lo || last > hi {
            return Err(RunError::input(
                "from/to",
                format!(
                    "{name} = {} ... {last} leaves the range [{lo}, {hi}] the operator in {} \
                     declares",
                    values[0],
                    dir.display()
                ),
            ));
        }
    }
    let first = family_op
        .at(values[0])
        .map_err(|e| RunError::input("from", format!("{}: {e}", values[0])))?;
    first.check_pencil().map_err(|e| {
        RunError::input(
            "operator",
            format!("{} at {name} = {}: {e}", dir.display(), values[0]),
        )
    })?;
    let mu = match s.mu {
        Some(mu) => mu,
        None if first.has_friction() => {
            return Err(RunError::input(
                "mu",
                format!(
                    "required, the operator in {} has friction parts (X - mu F_X)",
                    dir.display()
                ),
            ))
        }
        None => 0.0,
    };
    // the points depend on these (not on the value list, except its first value, where
    // the reference modes of tracking are taken)
    let toml = std::fs::read_to_string(dir.join("operator.toml")).unwrap_or_default();
    let inputs = serde_json::json!({
        "operator": dir.display().to_string(),
        "operator_toml": toml,
        "parameter": name,
        "reference_value": values[0],
        "mu": mu,
        "basis": s.basis,
        "basis_opts": format!("{:?}", s.basis_params),
        "eigen": s.eigen,
        "band_hz": s.band_hz,
        "tol": s.tol,
        "squeal": env!("CARGO_PKG_VERSION"),
    });
    let ckpt = open_checkpoint(
        out,
        "sweep param",
        "a parameter sweep",
        resume,
        inputs,
        s.condition,
        values.len(),
        &mut events,
    )?;
    let at_first = || outdir::stage(format!("{} at {name} = {}", dir.display(), values[0]));
    let reference =
        reference_modes(registry, &first, MODAL_SOLVER, 1.5 * s.band_hz[1]).map_err(at_first())?;
    let mut method = Method::new(
        registry,
        &s.basis,
        &s.basis_params,
        &s.eigen,
        MODAL_SOLVER,
        EigenParams {
            fmin_hz: s.band_hz[0],
            fmax_hz: s.band_hz[1],
            tol: s.tol,
            ..EigenParams::default()
        },
    )
    .map_err(at_first())?;
    method.set_condition(s.condition);
    let mut family = Parametric::new(family_op, mu);
    let sweep = run_family_sweep(
        &mut family,
        &values,
        &mut method,
        &reference,
        s.dvr_margin,
        &[],
        Some(&ckpt),
        |p| events(SweepEvent::Point(p)),
    )
    .map_err(outdir::stage(format!("the sweep of {name}")))?;
    let points = &sweep.points;
    write_csv(
        &out.join("sweep.csv"),
        name,
        points,
        &sweep.branches,
        s.dvr_margin,
    )?;
    let summary = ParamSummary {
        operator: dir.display().to_string(),
        units: "SI: frequencies in Hz, DvR = Re/Im (dimensionless), times in s",
        parameter: name.to_string(),
        range: [s.from, s.to, s.step],
        mu,
        band_hz: s.band_hz,
        eigen: s.eigen.clone(),
        basis: s.basis.clone(),
        dofs: first.dim(),
        dvr_margin: s.dvr_margin,
        points: points.len(),
        max_basis_size: points.iter().map(|p| p.basis_size).max().unwrap_or(0),
        max_backward_error: points
            .iter()
            .flat_map(|p| p.modes.iter().map(|m| m.backward_error))
            .fold(0.0, f64::max),
        max_error_bound: max_error_bound(points),
        reference: reference_text(
            &reference,
            &squeal_core::reduction::real_mode_pair(&first)
                .map(|p| p.source.into_owned())
                .unwrap_or_default(),
        ),
        reference_modes: reference.freq_hz.len(),
        time_s: start.elapsed().as_secs_f64(),
        couplings: sweep.couplings.clone(),
    };
    outdir::write_json(&out.join("summary.json"), &summary)?;
    Ok((summary, sweep))
}
