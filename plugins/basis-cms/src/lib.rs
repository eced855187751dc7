//! # squeal-basis-cms
//!
//! Free-interface component mode synthesis, registered as `"cms"`: a basis for the many
//! contact sets of one model (mu sweeps whose contact set changes, macroscopic zones,
//! mesoscopic plateau layouts) that costs no sparse eigen solve and no factorization per
//! contact set.
//!
//! Once per model and set of candidate pairs, in its model stage
//! ([`ReductionBasis::prepare`]), the basis builds a [`FreeInterface`] (normal modes of the
//! unconstrained bodies up to `modes_factor x` the band top, static responses to unit
//! contact loads and the residual contact flexibilities; [`synthesis`]) on the caller's
//! factor of `K`. For each contact set and mu the basis then synthesizes the modes of the tied, frictional system by MacNeal's
//! residual-flexibility method (an `m x m` eigenproblem, `m` free-interface modes, after
//! one `nA x nA` LU), expands those up to `cutoff_factor x` the band top, and returns their
//! real and imaginary parts, `M_c`-orthonormalized, as Ritz vectors of the exact operator:
//! the shared reduced solve then refines them and gives every mode its backward error on
//! the full operator.
//!
//! An operator read from files has no free model and no pairs: there the synthesis takes
//! the operator's friction load directions as its interface (free-interface modes of its
//! real-mode pair, attachment modes of the friction loads, the frictional operator solved
//! on them; module `loads`), and an operator without friction loads is refused with what
//! to add.
//!
//! The synthesis is undamped (a damped operator is still projected whole); the basis
//! depends on mu ([`ReductionBasis::depends_on_mu`] is `true`): it is rebuilt at every mu,
//! which costs far less than one real-mode solve.
//!
//! ## Parameters
//!
//! - `modes_factor` (default 3, > 1): free-interface modes up to `modes_factor x` band top.
//! - `cutoff_factor` (default 1.5, > 0): synthesized modes expanded up to
//!   `cutoff_factor x` band top.
//! - `second_order` (default 1 = on, 0 = off): add, for each expanded mode, its
//!   second-order residual direction `G2 B_A^T r` (the inertia of the residual flexibility,
//!   corrected statically onto the ties; [`FreeInterface::expand_with_correction`]), which
//!   the Ritz step uses to recover most of what the static residual flexibility leaves out.
//! - `rank_tol` (default [`DEFAULT_RANK_TOL`]): relative rank cut of the
//!   orthonormalization.
//! - `projection` (default `full`): `pairs` assembles every contact set's projection from
//!   data on the candidate pairs computed once in the model stage
//!   ([`FreeInterface::project_on_pairs`]: three more block solves per block of pairs and
//!   `288 nR^2` bytes there; per contact set no `n x m` basis, no sparse product and no
//!   solve but forming the columns once, two block solves, for the modes a solve
//!   returns). For studies of many contact sets of a few hundred pairs each (the per-case
//!   products on the pairs grow as `nA^2` per column). A damped operator is projected the
//!   `full` way.

use squeal_core::faer::Mat;
use squeal_core::linalg::Cholesky;
use squeal_core::params::{fraction, positive};
use squeal_core::reduction::{m_orthonormalize, DEFAULT_RANK_TOL};
use squeal_core::{
    Basis, BasisRequest, Error, FreeModel, ModelStage, Params, ReductionBasis, Registry, Result,
};
use std::sync::Arc;
use std::time::Instant;

mod loads;
pub mod synthesis;

pub use synthesis::{FreeInterface, Synthesized};

/// Name under which the basis is registered.
pub const NAME: &str = "cms";

/// One-line description shown by the registry.
pub const DESCRIPTION: &str = "free-interface modal synthesis with residual flexibility \
                               (built once per model and candidate pairs), its modes up to \
                               cutoff_factor x band top as Ritz vectors; options \
                               modes_factor (3), cutoff_factor (1.5), second_order (1), rank_tol, \
                               projection (full | pairs)";

/// Default of the `modes_factor` parameter.
pub const DEFAULT_MODES_FACTOR: f64 = 3.0;
/// Default of the `cutoff_factor` parameter.
pub const DEFAULT_CUTOFF_FACTOR: f64 = 1.5;

/// Registers the `"cms"` basis.
pub fn register(reg: &mut Registry) {
    reg.bases.register(NAME, DESCRIPTION, |params: &Params| {
        let second_order = params.num_or("second_order", 1.0)?;
        if second_order != 0.0 && second_order != 1.0 {
            return Err(Error::param(
                "second_order",
                format!("must be 1 (on) or 0 (off), got {second_order}"),
            ));
        }
        let on_pairs = match params.str_or("projection", "full")? {
            "full" => false,
            "pairs" => true,
            other => {
                return Err(Error::param(
                    "projection",
                    format!("expected `full` or `pairs`, got `{other}`"),
                ))
            }
        };
        let mut basis = CmsBasis::new(
            params.num_or("modes_factor", DEFAULT_MODES_FACTOR)?,
            params.num_or("cutoff_factor", DEFAULT_CUTOFF_FACTOR)?,
            params.num_or("rank_tol", DEFAULT_RANK_TOL)?,
            second_order == 1.0,
        )?;
        basis.on_pairs = on_pairs;
        let basis: Box<dyn ReductionBasis> = Box::new(basis);
        Ok(basis)
    });
}

/// The `"cms"` basis.
#[derive(Debug, Clone)]
pub struct CmsBasis {
    /// Free-interface modes up to this factor times the band top.
    pub modes_factor: f64,
    /// Synthesized modes expanded up to this factor times the band top.
    pub cutoff_factor: f64,
    /// Relative rank cut of the orthonormalization.
    pub rank_tol: f64,
    /// Whether the second-order residual directions join the Ritz vectors.
    pub second_order: bool,
    /// Whether each contact set's projection is assembled on the pairs (`projection =
    /// pairs`) instead of from the basis's columns.
    pub on_pairs: bool,
}

impl CmsBasis {
    /// Checks and stores the parameters.
    pub fn new(
        modes_factor: f64,
        cutoff_factor: f64,
        rank_tol: f64,
        second_order: bool,
    ) -> Result<Self> {
        if !(modes_factor.is_finite() && modes_factor > 1.0) {
            return Err(Error::param(
                "modes_factor",
                format!(
                    "must be a number above 1 (free modes beyond the band), got {modes_factor}"
                ),
            ));
        }
        positive("cutoff_factor", cutoff_factor)?;
        fraction("rank_tol", rank_tol)?;
        Ok(Self {
            modes_factor,
            cutoff_factor,
            rank_tol,
            second_order,
            on_pairs: false,
        })
    }
}

impl ReductionBasis for CmsBasis {
    fn name(&self) -> &str {
        NAME
    }

    fn depends_on_mu(&self) -> bool {
        true
    }

    fn stage_key(&self, band_top_hz: f64) -> Option<String> {
        Some(format!(
            "{NAME}: free-interface modes to {} Hz{}",
            self.modes_factor * band_top_hz,
            if self.on_pairs {
                ", moments on the pairs"
            } else {
                ""
            }
        ))
    }

    /// The free-interface synthesis of the model on its candidate pairs, from the normal
    /// modes up to `modes_factor x` the band top, on the caller's factor of `K` when it
    /// has one; for a caller that announces its number of contact sets, with what pays
    /// for that many ([`FreeInterface::for_contact_sets`]).
    fn prepare(&self, free: &FreeModel<'_>) -> Result<Option<ModelStage>> {
        let modes = (free.normal_modes)(self.modes_factor * free.band_hz.1)?;
        let (k, m, pairs, factor) = (free.k, free.m, free.pairs, free.k_factor.clone());
        let fi = if self.on_pairs {
            FreeInterface::with_pair_moments(k, m, pairs, &modes, factor)?
        } else if let Some(sets) = free.contact_sets {
            FreeInterface::for_contact_sets(k, m, pairs, &modes, factor, sets)?
        } else if let Some(factor) = factor {
            FreeInterface::with_factor(k, m, pairs, &modes, factor)?
        } else {
            FreeInterface::new(k, m, pairs, &modes)?
        };
        Ok(Some(Arc::new(fi)))
    }

    fn stage_factor(&self, stage: &ModelStage) -> Option<Arc<Cholesky>> {
        stage.downcast_ref::<FreeInterface>().map(|f| f.factor())
    }

    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis> {
        let Some(stage) = request.stage else {
            if request.op.t.is_none() {
                return loads::build_on_loads(self, request);
            }
            return Err(Error::Invalid(
                "the `cms` basis needs the free-interface synthesis of the model, which the \
                 scene-based commands (stability, sweep, studies, bench with a scene) build \
                 in their model stage; none was given for this contact set"
                    .into(),
            ));
        };
        let free = stage.downcast_ref::<FreeInterface>().ok_or_else(|| {
            Error::Invalid("cms: the model stage is not a free-interface synthesis".into())
        })?;
        let op = request.op;
        let active = free.active_in(op)?;
        let clock = Instant::now();
        let syn = free.synthesize(&active, request.mu)?;
        let t_synthesis = clock.elapsed().as_secs_f64();
        let cutoff = self.cutoff_factor * request.band_hz.1;
        // one member of each conjugate pair of s (their expansions are conjugate)
        let which: Vec<usize> = (0..syn.s.len())
            .filter(|&k| syn.s[k].im >= 0.0 && syn.freq_hz(k) <= cutoff)
            .collect();
        if which.is_empty() {
            return Err(Error::Invalid(format!(
                "cms: no synthesized mode below {cutoff:.1} Hz"
            )));
        }
        if self.on_pairs && op.cc.is_none() && free.has_pair_moments() {
            let t = op.t.as_ref().expect("checked by active_in");
            let clock = Instant::now();
            let p = free.project_on_pairs(&syn, &which, self.second_order, t, op.dim())?;
            let t_pairs = clock.elapsed().as_secs_f64();
            let m = p.reduced.dim();
            let mut basis = Basis::implicit(Arc::new(p.columns), p.reduced);
            basis.dropped = p.dropped;
            basis.steps = vec![
                ("synthesis".into(), t_synthesis),
                ("projection on the pairs".into(), t_pairs),
            ];
            basis.notes.push(format!(
                "{NAME}: {} synthesized modes up to {cutoff:.1} Hz from {} free-interface \
                 modes (to {:.1} Hz) and {} tied pairs of {} candidates, {m} vectors ({} \
                 removed by the Gram cut), projected on the pairs (ties to {:.1e})",
                which.len(),
                free.modes(),
                free.cutoff_hz,
                active.len(),
                free.pairs(),
                p.dropped,
                p.tie_residual
            ));
            return Ok(basis);
        }
        // the expanded modes (and their second-order directions), real and imaginary
        // parts side by side
        let clock = Instant::now();
        let blocks = if self.second_order {
            let (u, w) = free.expand_parts_with_correction(&syn, &which)?;
            vec![u, w]
        } else {
            vec![free.expand_parts(&syn, &which)]
        };
        let t = op.t.as_ref().expect("checked by active_in");
        let raw = constrained_columns(&blocks, which.len(), t, op.dim());
        drop(blocks);
        let t_expansion = clock.elapsed().as_secs_f64();
        let clock = Instant::now();
        let (v, dropped) = m_orthonormalize(op.mc.as_ref(), raw.as_ref(), self.rank_tol)?;
        let mut basis = Basis::new(v);
        basis.dropped = dropped;
        basis.steps = vec![
            ("synthesis".into(), t_synthesis),
            ("expansion".into(), t_expansion),
            ("orthonormalization".into(), clock.elapsed().as_secs_f64()),
        ];
        basis.notes.push(format!(
            "{NAME}: {} synthesized modes up to {cutoff:.1} Hz from {} free-interface modes \
             (to {:.1} Hz) and {} tied pairs of {} candidates, {} vectors ({dropped} removed \
             by the rank cut)",
            which.len(),
            free.modes(),
            free.cutoff_hz,
            active.len(),
            free.pairs(),
            basis.len()
        ));
        Ok(basis)
    }
}

/// The basis's candidate columns in the constrained numbering (`n_c` rows, `T` the index
/// map): for each complex column `c` of each block (`k` columns, real parts in `0..k`,
/// imaginary in `k..2k`), its real part, then its imaginary part unless that is below
/// `1e-8` of the column's largest modulus (a real mode).
fn constrained_columns(blocks: &[Mat<f64>], k: usize, t: &[usize], nc: usize) -> Mat<f64> {
    let mut parts: Vec<(usize, usize)> = Vec::with_capacity(2 * k * blocks.len());
    for (b, u) in blocks.iter().enumerate() {
        for c in 0..k {
            let (re, im) = (u.col(c), u.col(k + c));
            let scale = re
                .iter()
                .zip(im.iter())
                .map(|(a, b)| a.hypot(*b))
                .fold(0.0f64, f64::max);
            let imax = im.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            parts.push((b, c));
            if imax > 1e-8 * scale {
                parts.push((b, k + c));
            }
        }
    }
    let mut raw = Mat::<f64>::zeros(nc, parts.len());
    for (col, &(b, c)) in parts.iter().enumerate() {
        let src = blocks[b].col(c);
        let mut dst = raw.col_mut(col);
        for (j, &tj) in t.iter().enumerate() {
            dst[tj] = src[j];
        }
    }
    raw
}
