//! # squeal-basis-residue
//!
//! The residue iterative method (Bobillot & Balmes, the paper's ref. 42), registered as
//! `"residue"`. Start from the coupled mu = 0 real modes of `(K_c, M_c)` up to
//! `cutoff_factor x` the band top; then repeat:
//!
//! 1. project the operator at mu on the basis `V` and solve the reduced QEP (the
//!    request's `reduced` solver, normally `dense`) for the target modes, those with
//!    frequency in the band widened by [`TARGET_MARGIN`] on each side;
//! 2. residual of each target on the FULL operator `r_j = Q(lambda_j) V q_j`, static
//!    response `d_j = K_s^-1 r_j` with one factorization of `K_s = K_c + shift M_c`
//!    reused for every iteration (the real modes of the start are computed on it too;
//!    at shift 0 no factorization: `K_c` is solved through the free model's factor and
//!    the pairs of the contact set, the model stage
//!    [`PairSolves`]),
//!    energy-norm residual
//!    `eps_j = sqrt(d_j^H K_s d_j) / sqrt(u_j^H K_s u_j)`
//!    ([`squeal_core::reduction::energy_residuals`], formed from the images `K_c V`,
//!    `M_c V` kept by [`GrowingBasis`]: each column is multiplied by the large sparse
//!    parts once, when it joins the basis);
//! 3. stop when `max_j eps_j <= tol` (converged) or after `max_iterations` enrichments;
//!    else add `Re d_j` and `Im d_j` of every unconverged target and re-orthonormalize
//!    (`M_c`, rank cut of [`squeal_core::reduction`]).
//!
//! In a sweep the start also holds the seed of the previous point
//! ([`BasisRequest::seed`](squeal_core::BasisRequest::seed)): the real and imaginary parts
//! of its final target modes, carried on the free model's DOFs to this contact set. They
//! are near this point's target modes, so the first residuals are small and fewer
//! enrichments reach `tol`; the stopping test is the same, so a seeded basis meets the
//! same tolerance as one built alone (its columns, and the modes to within that
//! tolerance, differ). The basis leaves its own target modes as the next seed
//! ([`Basis::seed`]), with its real modes, from which the next contact set's real modes
//! start ([`squeal_core::reduction::coupled_real_modes_on`]).
//!
//! The error is controlled per mode, but the basis depends on mu and on the contact set
//! ([`ReductionBasis::depends_on_mu`] is `true`). The basis reports its iterations
//! (enrichment steps), its final residual `max eps_j`, and a note when it stopped on
//! the cap or stagnated.
//!
//! ## Parameters
//!
//! - `cutoff_factor` (default 1.5, > 0): starting modes up to `cutoff_factor * band top`.
//! - `tol` (default 1e-6): energy-norm residual tolerance.
//! - `max_iterations` (default 10): cap on enrichment steps.
//! - `shift_hz` (default 0): `K_s = K_c + (2 pi shift_hz)^2 M_c` (a positive shift for a
//!   model with free bodies).
//! - `rank_tol` (default [`DEFAULT_RANK_TOL`]): relative rank cut of the
//!   orthonormalization.

use squeal_core::faer::Mat;
use squeal_core::linalg::{hcat, Cholesky};
use squeal_core::params::{fraction, positive};
use squeal_core::reduction::{
    coupled_real_modes_on, expand, from_free_dofs, m_orthonormalize, real_modes_cost,
    real_modes_seed, to_free_dofs, GrowingBasis, PairSolves, StaticSolver, DEFAULT_RANK_TOL,
    PAIR_SOLVES_STAGE_KEY,
};
use squeal_core::{
    Basis, BasisRequest, EigenParams, Error, FreeModel, ModelStage, Params, ReductionBasis,
    Registry, Result,
};
use std::sync::Arc;
use std::time::Instant;

/// Name under which the basis is registered.
pub const NAME: &str = "residue";

/// One-line description shown by the registry.
pub const DESCRIPTION: &str = "residue iterative method: real modes enriched by the static \
                               responses to the residuals of the target modes (depends on \
                               mu); options cutoff_factor, tol, max_iterations, shift_hz, \
                               rank_tol";

/// Default of the `cutoff_factor` parameter.
pub const DEFAULT_CUTOFF_FACTOR: f64 = 1.5;
/// Default of the `tol` parameter.
pub const DEFAULT_TOL: f64 = 1e-6;
/// Default of the `max_iterations` parameter.
pub const DEFAULT_MAX_ITERATIONS: usize = 10;
/// Relative widening of the band on each side that defines the target modes (so that a
/// mode just outside the band in the reduced model, inside in the full one, is treated).
pub const TARGET_MARGIN: f64 = 0.02;

/// Registers the `"residue"` basis.
pub fn register(reg: &mut Registry) {
    reg.bases.register(NAME, DESCRIPTION, |params: &Params| {
        let basis: Box<dyn ReductionBasis> = Box::new(ResidueBasis::new(
            params.num_or("cutoff_factor", DEFAULT_CUTOFF_FACTOR)?,
            params.num_or("tol", DEFAULT_TOL)?,
            params.usize_or("max_iterations", DEFAULT_MAX_ITERATIONS)?,
            params.num_or("shift_hz", 0.0)?,
            params.num_or("rank_tol", DEFAULT_RANK_TOL)?,
        )?);
        Ok(basis)
    });
}

/// The `"residue"` basis.
#[derive(Debug, Clone)]
pub struct ResidueBasis {
    /// Cutoff frequency of the starting modes over band top.
    pub cutoff_factor: f64,
    /// Energy-norm residual tolerance.
    pub tol: f64,
    /// Cap on enrichment steps.
    pub max_iterations: usize,
    /// Static shift (Hz): `K_s = K_c + (2 pi shift_hz)^2 M_c`.
    pub shift_hz: f64,
    /// Relative rank cut of the orthonormalization.
    pub rank_tol: f64,
}

impl ResidueBasis {
    /// Checks and stores the parameters.
    pub fn new(
        cutoff_factor: f64,
        tol: f64,
        max_iterations: usize,
        shift_hz: f64,
        rank_tol: f64,
    ) -> Result<Self> {
        positive("cutoff_factor", cutoff_factor)?;
        fraction("tol", tol)?;
        fraction("rank_tol", rank_tol)?;
        if !(shift_hz.is_finite() && shift_hz >= 0.0) {
            return Err(Error::param(
                "shift_hz",
                format!("must be a frequency >= 0 Hz, got {shift_hz}"),
            ));
        }
        Ok(Self {
            cutoff_factor,
            tol,
            max_iterations,
            shift_hz,
            rank_tol,
        })
    }
}

impl ReductionBasis for ResidueBasis {
    fn name(&self) -> &str {
        NAME
    }

    fn depends_on_mu(&self) -> bool {
        true
    }

    /// The free model's pair solves when the static shift is 0: every `K_c` is then
    /// solved through them.
    fn stage_key(&self, _band_top_hz: f64) -> Option<String> {
        (self.shift_hz == 0.0).then(|| PAIR_SOLVES_STAGE_KEY.into())
    }

    fn prepare(&self, free: &FreeModel<'_>) -> Result<Option<ModelStage>> {
        PairSolves::stage(free)
    }

    fn stage_factor(&self, stage: &ModelStage) -> Option<Arc<Cholesky>> {
        PairSolves::in_stage(Some(stage.as_ref())).map(PairSolves::factor)
    }

    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis> {
        let (op, mu) = (request.op, request.mu);
        let mc = op.mc.as_ref();
        let (fmin, fmax) = request.band_hz;
        let cutoff = self.cutoff_factor * fmax;
        // one factorization of K_s serves the real modes (shift-invert at sigma = -shift)
        // and every static response
        let shift = (2.0 * std::f64::consts::PI * self.shift_hz).powi(2);
        let clock = Instant::now();
        let ks = StaticSolver::tied_or_new(op, PairSolves::in_stage(request.stage), shift)?;
        let t_factor = clock.elapsed().as_secs_f64();
        let modes = coupled_real_modes_on(request, cutoff, &ks)?;
        let t_modes = clock.elapsed().as_secs_f64() - t_factor;
        let clock = Instant::now();
        // the previous sweep point's target modes, brought to this contact set, join the
        // start: the residuals then start near where that point ended
        let seed = request
            .seed
            .and_then(|s| s.directions.as_ref())
            .and_then(|s| from_free_dofs(op, s.as_ref()));
        let start = match &seed {
            Some(s) => hcat(modes.vectors.as_ref(), s.as_ref()),
            None => modes.vectors.clone(),
        };
        let (v, mut dropped) = m_orthonormalize(mc, start.as_ref(), self.rank_tol)?;
        drop(start);
        let start_size = v.ncols();
        let seeded = seed.as_ref().map_or(0, |s| s.ncols());
        let mut v = GrowingBasis::new(op, v)?;
        let targets = EigenParams {
            fmin_hz: fmin * (1.0 - TARGET_MARGIN),
            fmax_hz: fmax * (1.0 + TARGET_MARGIN),
            ..request.params.clone()
        };
        let mut notes = Vec::new();
        let mut iterations = 0;
        let mut history = Vec::new();
        let mut projected;
        // the reduced target modes of the last projection: the seed of the next point
        let mut last;
        let residual = loop {
            let reduced = v.project()?;
            let red = request.reduced.solve_frictional(&reduced, mu, &targets)?;
            projected = reduced;
            last = red.vectors.clone();
            if red.is_empty() {
                notes.push(format!(
                    "{NAME}: no target mode in [{:.1}, {:.1}] Hz",
                    targets.fmin_hz, targets.fmax_hz
                ));
                break 0.0;
            }
            let (eps, d) = v.energy_residuals(mu, &ks, &red.lambda, red.vectors.as_ref());
            let residual = eps.iter().fold(0.0f64, |a, &b| a.max(b));
            history.push(residual);
            if residual <= self.tol {
                break residual;
            }
            if iterations >= self.max_iterations {
                notes.push(format!(
                    "{NAME}: NOT converged: energy residual {residual:.3e} > tol {:.1e} after \
                     {iterations} iterations (the cap)",
                    self.tol
                ));
                break residual;
            }
            let bad: Vec<usize> = (0..eps.len()).filter(|&j| eps[j] > self.tol).collect();
            let n = op.dim();
            let new = Mat::from_fn(n, 2 * bad.len(), |r, c| {
                let z = d[(r, bad[c / 2])];
                if c % 2 == 0 {
                    z.re
                } else {
                    z.im
                }
            });
            let before = v.len();
            dropped += v.extend(new.as_ref(), self.rank_tol)?;
            iterations += 1;
            if v.len() == before {
                notes.push(format!(
                    "{NAME}: stagnated: every new residual direction fell under the rank cut \
                     (energy residual {residual:.3e})"
                ));
                break residual;
            }
        };
        // the next point's seed: the last reduced target modes, on the columns they were
        // solved on
        let next_seed = Some(last).filter(|q| q.ncols() > 0).and_then(|q| {
            let u = expand(v.columns(), q.as_ref());
            let parts = Mat::from_fn(u.nrows(), 2 * u.ncols(), |r, c| {
                let z = u[(r, c / 2)];
                if c % 2 == 0 {
                    z.re
                } else {
                    z.im
                }
            });
            to_free_dofs(op, parts.as_ref())
        });
        let mut basis = Basis::new(v.into_columns());
        basis.seed.directions = next_seed;
        basis.seed.real_modes = real_modes_seed(op, &modes);
        // every exit of the loop leaves `v` as it was last projected (the stagnation exit
        // kept its columns)
        basis.projected = Some(projected);
        basis.dropped = dropped;
        basis.iterations = iterations;
        basis.residual = Some(residual);
        let t_iterations = clock.elapsed().as_secs_f64();
        basis.steps = vec![
            ("set-up".into(), t_factor),
            ("real modes".into(), t_modes),
            ("iterations".into(), t_iterations),
        ];
        notes.insert(
            0,
            format!(
                "{NAME}: {} real modes up to {cutoff:.1} Hz (`{}`){} + {} residual \
                 vectors in {iterations} iterations at mu = {mu}; energy residuals {:?}; \
                 {}; times: set-up {t_factor:.2} s (shared by modes and residuals), modes \
                 {t_modes:.2} s ({}), iterations {:.2} s",
                modes.vectors.ncols(),
                request.modal.name(),
                if seeded > 0 {
                    format!(
                        " and {} directions of the previous point's target modes ({seeded} \
                         given)",
                        start_size.saturating_sub(modes.vectors.ncols())
                    )
                } else {
                    String::new()
                },
                basis.len() - start_size,
                history
                    .iter()
                    .map(|r| format!("{r:.2e}"))
                    .collect::<Vec<_>>(),
                ks.method,
                real_modes_cost(&modes),
                t_iterations
            ),
        );
        basis.notes = notes;
        Ok(basis)
    }
}
