//! Sweeps over one parameter of a family of frictional operators, with mode tracking and
//! couplings: the friction coefficient of a scene ([`SceneMu`]: an equilibrium per value,
//! the operator rebuilt when the contact set changes) and the parameter of a parametric
//! operator directory ([`Parametric`]: `squeal_io::ParametricOperator::at` per value, at
//! a fixed mu). `squeal sweep mu` ([`crate::mu_sweep`]) and `squeal sweep param` both run
//! [`run_family_sweep`]; only the family and the reference modes of the signatures differ.
//!
//! **Reference modes.** Tracking compares modes by their signatures on real reference
//! modes ([`crate::sweep`]). A scene has its free-interface modes (no contact). An operator
//! read from files has no model, so [`reference_modes`] builds them from the operator
//! itself: the real modes of its real-mode pair at the sweep's first value (the pair its
//! directory names in `[modal]`, else the symmetric parts `(K + K^T)/2`, `(M + M^T)/2` of
//! its friction-free parts, shifted positive definite when the stiffness's is not; no
//! damping, no gyroscopic or circulatory term, no friction), up to 1.5 times the band
//! top, computed once. They are
//! `M`-orthonormal for that mass, so the signature MAC is the MAC of the modes projected on
//! them; it stays meaningful along the sweep as long as the modes of the band remain in
//! their span (a parameter that moves modes far out of the band's reference span loses
//! tracking, which then starts new branches rather than joining wrong ones).

use crate::pipeline::{FreeModes, Method, PipelineError, Prepared, Result, StepResult};
use crate::profile::Profile;
use crate::sweep::{
    active_hash, couplings, signature, track, Branch, Checkpoint, SweepMode, SweepPoint,
    TrackOptions,
};
use serde::Serialize;
use squeal_core::operator::ComplexModes;
use squeal_core::reduction::real_mode_pair;
use squeal_core::{EigenParams, FrictionalOperator, Params, Registry, SymmetricProblem};
use std::time::Instant;

/// The operator of one value of the swept parameter.
pub struct Member<'a> {
    /// The operator.
    pub op: &'a FrictionalOperator,
    /// The friction coefficient to solve it at.
    pub mu: f64,
    /// Whether the operator differs from the previous call's (a new contact set, a new
    /// parameter value): it invalidates a basis built for the previous one. `true` on the
    /// first call.
    pub changed: bool,
    /// Active contact pairs (0 for an operator read from files).
    pub active_pairs: usize,
    /// Fingerprint of what the operator depends on besides mu (the active set of a scene;
    /// the parameter value of a parametric operator, so that every point counts as a new
    /// operator).
    pub active_hash: u64,
    /// Wall times (s): the equilibrium, the operator's assembly.
    pub times_s: [f64; 2],
}

/// A family of frictional operators over one parameter.
pub trait OperatorFamily {
    /// The operator at `value` (called with the sweep's values in increasing order,
    /// skipping those read back from a checkpoint).
    fn member(&mut self, value: f64) -> Result<Member<'_>>;
}

/// The friction coefficient of a prepared scene: the sliding equilibrium at each mu, the
/// operator rebuilt only when the active set changes.
pub struct SceneMu<'a> {
    prep: &'a Prepared,
    registry: &'a Registry,
    equilibrium: String,
    law: String,
    law_params: Params,
    current: Option<(Vec<bool>, FrictionalOperator)>,
}

impl<'a> SceneMu<'a> {
    /// Equilibria of `prep` by the solver `equilibrium` with contact law `law` and its
    /// parameters `law_params`.
    pub fn new(
        prep: &'a Prepared,
        registry: &'a Registry,
        equilibrium: &str,
        law: &str,
        law_params: &Params,
    ) -> Self {
        Self {
            prep,
            registry,
            equilibrium: equilibrium.into(),
            law: law.into(),
            law_params: law_params.clone(),
            current: None,
        }
    }
}

impl OperatorFamily for SceneMu<'_> {
    fn member(&mut self, mu: f64) -> Result<Member<'_>> {
        let t0 = Instant::now();
        let eq = self.prep.equilibrium_with(
            self.registry,
            &self.equilibrium,
            &self.law,
            &self.law_params,
            mu,
        )?;
        let t_eq = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        // a new operator when the contact set changed or none was built in this run (a
        // resumed sweep or a shard starts without one)
        let changed = !matches!(&self.current, Some((a, _)) if *a == eq.eq.active);
        if changed {
            let op = self.prep.operator(&eq.eq.active)?;
            self.current = Some((eq.eq.active, op));
        }
        let (active, op) = self.current.as_ref().expect("operator built");
        Ok(Member {
            op,
            mu,
            changed,
            active_pairs: active.iter().filter(|&&a| a).count(),
            active_hash: active_hash(active),
            times_s: [t_eq, t1.elapsed().as_secs_f64()],
        })
    }
}

/// The parameter of a parametric operator directory at a fixed friction coefficient: the
/// operator assembled at each value.
pub struct Parametric<'a> {
    op: &'a squeal_io::ParametricOperator,
    mu: f64,
    current: Option<FrictionalOperator>,
}

impl<'a> Parametric<'a> {
    /// `op` at friction coefficient `mu`.
    pub fn new(op: &'a squeal_io::ParametricOperator, mu: f64) -> Self {
        Self {
            op,
            mu,
            current: None,
        }
    }
}

impl OperatorFamily for Parametric<'_> {
    fn member(&mut self, value: f64) -> Result<Member<'_>> {
        let t = Instant::now();
        let op = self.current.insert(self.op.at(value)?);
        Ok(Member {
            op,
            mu: self.mu,
            changed: true,
            active_pairs: 0,
            active_hash: value.to_bits(),
            times_s: [0.0, t.elapsed().as_secs_f64()],
        })
    }
}

/// The reference modes of tracking for an operator without a model (module docs): the
/// real modes of its real-mode pair ([`squeal_core::reduction::real_mode_pair`]: the
/// pair its directory names, else the symmetric parts of `M_c` and `K_c`, shifted
/// positive definite when the stiffness's is not) up to `fmax_hz`, by the symmetric
/// solver `eigen`, labelled `ref 1`, `ref 2`, ... in increasing frequency.
pub fn reference_modes(
    registry: &Registry,
    op: &FrictionalOperator,
    eigen: &str,
    fmax_hz: f64,
) -> Result<FreeModes> {
    let stage = |s: &str| {
        let s = s.to_string();
        move |source| PipelineError::Core { stage: s, source }
    };
    let solver = registry
        .eigen
        .create(eigen, &Params::new())
        .map_err(stage("eigen solver"))?;
    let pair = real_mode_pair(op).map_err(stage("reference modes of tracking"))?;
    let (m, k) = (pair.m, pair.k);
    let modes = solver
        .solve_symmetric(
            &SymmetricProblem { k, m },
            &EigenParams {
                fmax_hz: pair.shifted_cutoff_hz(fmax_hz),
                ..EigenParams::default()
            },
        )
        .map_err(stage(&format!(
            "reference modes of tracking (real modes of {})",
            pair.source
        )))?;
    let modes = pair.unshift(modes);
    let n = m.nrows();
    let kk = modes.freq_hz.len();
    let mut mphi = squeal_core::faer::Mat::<f64>::zeros(n, kk);
    let mut y = vec![0.0; n];
    for c in 0..kk {
        let x: Vec<f64> = modes.vectors.col(c).iter().copied().collect();
        squeal_core::linalg::spmv(m, &x, &mut y);
        for r in 0..n {
            mphi[(r, c)] = y[r];
        }
    }
    Ok(FreeModes {
        freq_hz: modes.freq_hz.clone(),
        labels: (1..=kk).map(|i| format!("ref {i}")).collect(),
        mphi,
    })
}

/// The sweep point of the modes of `op` (signatures on `reference`).
pub fn sweep_point(
    op: &FrictionalOperator,
    modes: &ComplexModes,
    reference: &FreeModes,
    value: f64,
    mu: f64,
    active_pairs: usize,
) -> SweepPoint {
    let out = (0..modes.len())
        .map(|i| {
            let uc: Vec<squeal_core::c64> = modes.vectors.col(i).iter().copied().collect();
            let u = op.expand(&uc);
            SweepMode {
                freq_hz: modes.freq_hz[i],
                re: modes.lambda[i].re,
                dvr: modes.dvr[i],
                backward_error: modes.backward_error[i],
                cond: modes.cond[i],
                error_bound: modes.error_bound[i],
                cond_floor: modes.cond_floor[i],
                signature: signature(reference.mphi.as_ref(), &u),
            }
        })
        .collect();
    SweepPoint {
        value,
        mu,
        active_pairs,
        rebuilt: false,
        active_hash: 0,
        basis_size: 0,
        times_s: [0.0; 3],
        modes: out,
    }
}

/// The points of a sweep of `family` over `values`: `solve(value, op, mu, changed)` for
/// the modes of each member (full order, or through a basis the closure keeps across calls),
/// signatures on `reference`. Points already in `checkpoint` (matched by value) are not
/// recomputed; each new one is appended before the next starts, so a killed run resumes
/// where it stopped. `progress` sees every point.
pub fn sweep_points(
    family: &mut dyn OperatorFamily,
    values: &[f64],
    reference: &FreeModes,
    checkpoint: Option<&Checkpoint>,
    solve: impl FnMut(f64, &FrictionalOperator, f64, bool) -> Result<StepResult>,
    progress: impl FnMut(&SweepPoint),
) -> Result<Vec<SweepPoint>> {
    let mut profile = Profile::new();
    sweep_points_profiled(
        family,
        values,
        reference,
        checkpoint,
        solve,
        progress,
        &mut profile,
    )
}

/// [`sweep_points`], adding the time of the equilibria, the operators' assembly (when
/// the contact set changed) and the signatures of the points computed to `profile`.
pub fn sweep_points_profiled(
    family: &mut dyn OperatorFamily,
    values: &[f64],
    reference: &FreeModes,
    checkpoint: Option<&Checkpoint>,
    mut solve: impl FnMut(f64, &FrictionalOperator, f64, bool) -> Result<StepResult>,
    mut progress: impl FnMut(&SweepPoint),
    profile: &mut Profile,
) -> Result<Vec<SweepPoint>> {
    let done = match checkpoint {
        Some(c) => c.load().map_err(|e| PipelineError::Core {
            stage: "reading the sweep checkpoint".into(),
            source: squeal_core::Error::Invalid(e.to_string()),
        })?,
        None => Vec::new(),
    };
    let mut points: Vec<SweepPoint> = Vec::new();
    for &value in values {
        let prev_hash = points.last().map(|p| p.active_hash);
        if let Some(p) = done
            .iter()
            .find(|p| (p.value - value).abs() <= 1e-12 * (1.0 + value.abs()))
        {
            progress(p);
            points.push(p.clone());
            continue;
        }
        let m = family.member(value)?;
        if m.times_s[0] > 0.0 {
            profile.add("equilibrium", m.times_s[0]);
        }
        if m.changed {
            profile.add("operator assembly", m.times_s[1]);
        }
        let (modes, basis_size, basis_time) = solve(value, m.op, m.mu, m.changed)?;
        let t = Instant::now();
        let mut pt = sweep_point(m.op, &modes, reference, value, m.mu, m.active_pairs);
        profile.add("signatures", t.elapsed().as_secs_f64());
        pt.active_hash = m.active_hash;
        pt.rebuilt = prev_hash != Some(pt.active_hash);
        pt.basis_size = basis_size;
        pt.times_s = [m.times_s[0], m.times_s[1] + basis_time, modes.info.time_s];
        if let Some(c) = checkpoint {
            c.append(&pt).map_err(|e| PipelineError::Core {
                stage: "writing the sweep checkpoint".into(),
                source: squeal_core::Error::Invalid(e.to_string()),
            })?;
        }
        progress(&pt);
        points.push(pt);
    }
    Ok(points)
}

/// A coupling of a sweep with what it is made of.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepCoupling {
    /// Frequency at the largest DvR (Hz).
    pub freq_hz: f64,
    /// First unstable value of the swept parameter.
    pub from: f64,
    /// Last unstable value.
    pub to: f64,
    /// Largest DvR.
    pub max_dvr: f64,
    /// The unstable branch and its partner.
    pub partners: Vec<usize>,
    /// The reference modes the unstable mode is made of (MAC share > 0.1 at its peak),
    /// labelled with their frequency.
    pub makeup: Vec<(String, f64)>,
}

/// A finished sweep.
pub struct FamilySweep {
    /// The points, in increasing value.
    pub points: Vec<SweepPoint>,
    /// Tracked branches.
    pub branches: Vec<Branch>,
    /// Couplings, in the order of their first unstable value.
    pub couplings: Vec<SweepCoupling>,
    /// The complex modes at the values asked to be kept, computed in this run (a point
    /// read back from a checkpoint keeps none).
    pub kept: Vec<(f64, ComplexModes)>,
    /// Wall time (s).
    pub time_s: f64,
    /// Where the time of the points computed in this run went.
    pub profile: Profile,
}

/// Runs `method` over `values` of `family` (signatures on `reference`), then tracks the
/// branches and finds the couplings (DvR above `dvr_margin`) with their make-up on
/// `reference`. The complex modes at the values of `keep_modes_at` are kept. Finished
/// points go to `checkpoint`; `progress` sees every point.
#[allow(clippy::too_many_arguments)]
pub fn run_family_sweep(
    family: &mut dyn OperatorFamily,
    values: &[f64],
    method: &mut Method,
    reference: &FreeModes,
    dvr_margin: f64,
    keep_modes_at: &[f64],
    checkpoint: Option<&Checkpoint>,
    progress: impl FnMut(&SweepPoint),
) -> Result<FamilySweep> {
    let start = Instant::now();
    let mut kept = Vec::new();
    let mut solves = Profile::new();
    let step = |value: f64, op: &FrictionalOperator, mu: f64, changed: bool| {
        let out = method.solve(op, mu, changed)?;
        let t = method.last_times();
        if t.basis_s > 0.0 {
            solves.add("basis", t.basis_s);
        }
        // the basis's own steps, under its time
        for (step, s) in method.last_basis_steps() {
            solves.add_step("basis", step, *s);
        }
        for (stage, s) in [
            ("projection", t.projection_s),
            ("eigen solve", t.solve_s),
            ("expansion + backward errors", t.expansion_s),
            ("condition numbers", t.condition_s),
        ] {
            if s > 0.0 {
                solves.add(stage, s);
            }
        }
        if keep_modes_at.iter().any(|&k| (k - value).abs() <= 1e-9) {
            kept.push((value, out.0.clone()));
        }
        Ok(out)
    };
    let mut profile = Profile::new();
    let points = sweep_points_profiled(
        family,
        values,
        reference,
        checkpoint,
        step,
        progress,
        &mut profile,
    )?;
    profile.extend_prefixed("", &solves);
    let t = Instant::now();
    let branches = track(&points, &TrackOptions::default());
    let couplings = couplings(&points, &branches, dvr_margin)
        .iter()
        .map(|c| SweepCoupling {
            freq_hz: c.freq_hz,
            from: c.from,
            to: c.to,
            max_dvr: c.max_dvr,
            partners: c.partners.clone(),
            makeup: makeup(&points, &branches[c.partners[0]], reference),
        })
        .collect();
    profile.add("tracking + couplings", t.elapsed().as_secs_f64());
    Ok(FamilySweep {
        points,
        branches,
        couplings,
        kept,
        time_s: start.elapsed().as_secs_f64(),
        profile,
    })
}

/// The reference modes (MAC share > 0.1) of branch `b` at its largest DvR.
fn makeup(points: &[SweepPoint], b: &Branch, reference: &FreeModes) -> Vec<(String, f64)> {
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
                mac.push((
                    format!("{} ({:.0} Hz)", reference.labels[k], reference.freq_hz[k]),
                    v,
                ));
            }
        }
        mac.sort_by(|x, y| y.1.total_cmp(&x.1));
    }
    mac
}
