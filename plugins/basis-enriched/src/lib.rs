//! # squeal-basis-enriched
//!
//! The enriched real coupled basis (the paper's ref. 40), registered as `"enriched"`:
//! the coupled mu = 0 real modes of `(K_c, M_c)` up to `cutoff_factor x` the band top,
//! plus the static responses to the friction loads `K_c^-1 U`, `U = T^T P~t^T` (one
//! vector per active pair), optionally compressed by an SVD in the `M_c` inner product.
//! Everything is `M_c`-orthonormalized with the rank cut of
//! [`squeal_core::reduction`] (columns scaled to unit `M_c` norm first, so the static
//! vectors, of order 1e-9 m per N, survive next to unit-modal-mass modes).
//!
//! The model stage (built once per model) holds the free model's pair solves
//! ([`PairSolves`]: the factor of `K` and the responses to the candidate pairs' normal
//! loads) and its static space ([`StaticSpace`]: an
//! `M`-orthonormal basis `Q` of the responses to every candidate pair's normal and
//! friction loads, with `Q^T K Q` and the rows the friction parts read). The real modes
//! are solved through the pair solves (shift-invert at 0: the free factor and the Schur
//! complement on the contact set's pairs). On an undamped operator the static responses
//! of a contact set are then coordinates in `Q` (no solve: their ties are corrected on
//! the pairs), orthonormalized by a dense QR of `2 nR x nA`, and the basis is `[Q W, V]`,
//! `V` the real modes orthogonalized against `Q W` (a mode inside the static span is
//! dropped); it stays implicit, the operator projected on it from `Q^T K Q`, products of
//! `Q^T` with the modes' images and the rows at the pairs, and only the reduced vectors a
//! solve returns are expanded. Otherwise (a damped operator, the SVD compression, no
//! stage) the columns are formed: the static responses `K_c^-1 U` from the free model's
//! kept responses to the friction loads corrected onto the ties
//! ([`squeal_core::reduction::TiedSolve::friction_statics`]), or through a sparse
//! Cholesky factorization of `K_c` when there is no stage (an operator read from
//! files), then the modes and the static responses orthonormalized and projected. The
//! basis's note says which and gives the time of each step.
//!
//! Fixed in mu, not in contact set: built once per contact set (a new active set means
//! a new `T` and a new basis) and reused across a whole mu sweep
//! ([`ReductionBasis::depends_on_mu`] is `false`). In a sweep the real modes of a new
//! contact set start from the previous set's ([`Basis::seed`]), which are near them.
//!
//! ## Parameters
//!
//! - `cutoff_factor` (default 1.5, > 0): modes up to `cutoff_factor * band top`.
//! - `svd_tol` (default: none, no compression): keep the left singular vectors of the
//!   `M_c`-normalized static responses with singular value `> svd_tol * sigma_max`.
//! - `rank_tol` (default [`DEFAULT_RANK_TOL`]): relative rank cut of the
//!   orthonormalization.

use squeal_core::linalg::{norm2, Cholesky};
use squeal_core::params::{fraction, positive};
use squeal_core::reduction::{
    coupled_real_modes_on, m_orthonormal_extend, m_orthonormalize, m_svd_compress, real_modes_cost,
    real_modes_seed, PairSolves, StaticSolver, StaticSpace, DEFAULT_RANK_TOL,
    PAIR_SOLVES_STAGE_KEY,
};
use squeal_core::{
    Basis, BasisRequest, Error, FreeModel, ModelStage, Params, ReductionBasis, Registry, Result,
};
use std::sync::Arc;
use std::time::Instant;

/// Name under which the basis is registered.
pub const NAME: &str = "enriched";

/// One-line description shown by the registry.
pub const DESCRIPTION: &str = "real modes up to cutoff_factor x band top (default 1.5) plus \
                               static responses to the friction loads (one per active \
                               pair); options cutoff_factor, svd_tol, rank_tol";

/// Default of the `cutoff_factor` parameter.
pub const DEFAULT_CUTOFF_FACTOR: f64 = 1.5;

/// Registers the `"enriched"` basis.
pub fn register(reg: &mut Registry) {
    reg.bases.register(NAME, DESCRIPTION, |params: &Params| {
        let svd_tol = params.num_opt("svd_tol")?;
        let basis: Box<dyn ReductionBasis> = Box::new(EnrichedBasis::new(
            params.num_or("cutoff_factor", DEFAULT_CUTOFF_FACTOR)?,
            svd_tol,
            params.num_or("rank_tol", DEFAULT_RANK_TOL)?,
        )?);
        Ok(basis)
    });
}

/// The `"enriched"` basis.
#[derive(Debug, Clone)]
pub struct EnrichedBasis {
    /// Cutoff frequency of the modes over band top.
    pub cutoff_factor: f64,
    /// Relative singular value cut of the static responses; `None`: no compression.
    pub svd_tol: Option<f64>,
    /// Relative rank cut of the orthonormalization.
    pub rank_tol: f64,
}

impl EnrichedBasis {
    /// Checks and stores the parameters.
    pub fn new(cutoff_factor: f64, svd_tol: Option<f64>, rank_tol: f64) -> Result<Self> {
        positive("cutoff_factor", cutoff_factor)?;
        if let Some(t) = svd_tol {
            fraction("svd_tol", t)?;
        }
        fraction("rank_tol", rank_tol)?;
        Ok(Self {
            cutoff_factor,
            svd_tol,
            rank_tol,
        })
    }
}

impl ReductionBasis for EnrichedBasis {
    fn name(&self) -> &str {
        NAME
    }

    /// The free model's pair solves (every contact set's `K_c` is solved through them)
    /// and its static space.
    fn stage_key(&self, _band_top_hz: f64) -> Option<String> {
        Some(format!("{PAIR_SOLVES_STAGE_KEY}, and the static space"))
    }

    /// The pair solves of the free model and its static space (the stage is shared by
    /// every parameter set of the basis).
    fn prepare(&self, free: &FreeModel<'_>) -> Result<Option<ModelStage>> {
        let Some(pairs) = PairSolves::stage(free)? else {
            return Ok(None);
        };
        let mut pairs = match Arc::downcast::<PairSolves>(pairs) {
            Ok(p) => p,
            Err(_) => return Err(Error::Invalid("enriched: pair solves expected".into())),
        };
        let space = StaticSpace::new(free, &pairs)?;
        // the space holds Z = K^-1 C^T in its basis: the pair solves give up their copy
        if let (Some(sp), Some(own)) = (&space, Arc::get_mut(&mut pairs)) {
            own.share_normals_with(sp)?;
        }
        Ok(Some(Arc::new(EnrichedStage { pairs, space })))
    }

    /// The responses to every candidate pair's friction load, solved now rather than at
    /// the first contact set that ties each pair (none to solve with a static space).
    fn complete_stage(&self, stage: &ModelStage) -> Result<()> {
        if let Some(st) = stage.downcast_ref::<EnrichedStage>() {
            if st.space.is_none() {
                st.pairs.solve_friction_responses();
            }
        }
        Ok(())
    }

    fn stage_factor(&self, stage: &ModelStage) -> Option<Arc<Cholesky>> {
        stage
            .downcast_ref::<EnrichedStage>()
            .map(|s| s.pairs.factor())
    }

    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis> {
        let op = request.op;
        let stage = request
            .stage
            .and_then(|s| s.downcast_ref::<EnrichedStage>());
        let pairs = stage.map(|s| s.pairs.as_ref());
        if let Some(space) = stage.and_then(|s| s.space.as_ref()) {
            let undamped = op.cc.is_none() && op.t.is_some() && op.friction_loads.is_some();
            if undamped && self.svd_tol.is_none() {
                return self.build_in_space(request, pairs.expect("with the space"), space);
            }
        }
        let mc = op.mc.as_ref();
        let cutoff = self.cutoff_factor * request.band_hz.1;
        // one solver of K_c (through the model stage's pair solves, or a factorization of
        // its own) serves the real modes (shift-invert at sigma = 0: the static responses
        // need K_c itself, and it is positive definite when they exist) and the static
        // responses
        let clock = Instant::now();
        let mut ks = StaticSolver::tied_or_new(op, pairs, 0.0)?;
        let t_factor = clock.elapsed().as_secs_f64();
        let modes = coupled_real_modes_on(request, cutoff, &ks)?;
        let t_modes = clock.elapsed().as_secs_f64() - t_factor;
        let (vm, dropped_modes) = m_orthonormalize(mc, modes.vectors.as_ref(), self.rank_tol)?;
        // static responses K_c^-1 U, one per active pair
        let clock = Instant::now();
        let (statics, kept_responses) = ks.friction_statics(op)?;
        let loads = statics.ncols();
        let t_statics = clock.elapsed().as_secs_f64();
        // a factor of its own is the largest allocation here: freed before the
        // orthonormalization
        let mut method = std::mem::take(&mut ks.method);
        if !ks.is_own() {
            method += "; static responses K_c^-1 U by a sparse LU of the operator's own \
                       (non-symmetric) K_c";
        }
        drop(ks);
        let finite = (0..statics.ncols())
            .all(|c| norm2(statics.col(c).try_as_col_major().unwrap().as_slice()).is_finite());
        if !finite {
            return Err(Error::Invalid(
                "enriched basis: non-finite static response (singular K_c?)".into(),
            ));
        }
        let (statics, dropped_svd) = match self.svd_tol {
            Some(tol) => m_svd_compress(mc, statics.as_ref(), tol)?,
            None => (statics, 0),
        };
        let clock = Instant::now();
        let (v, dropped_static) =
            m_orthonormal_extend(mc, vm.as_ref(), statics.as_ref(), self.rank_tol)?;
        let t_orth = clock.elapsed().as_secs_f64();
        let mut basis = Basis::new(v);
        basis.seed.real_modes = real_modes_seed(op, &modes);
        basis.dropped = dropped_modes + dropped_svd + dropped_static;
        basis.steps = vec![
            ("set-up".into(), t_factor),
            ("real modes".into(), t_modes),
            ("static responses".into(), t_statics),
            ("orthonormalization".into(), t_orth),
        ];
        basis.notes.push(format!(
            "{NAME}: {} real modes up to {cutoff:.1} Hz (`{}`) + {} static vectors of {loads} \
             friction loads ({} removed by the SVD cut{}, {} by the rank cut); {}; times: set-up \
             {t_factor:.2} s (shared by modes and statics), modes {t_modes:.2} s ({}), static \
             responses {t_statics:.2} s{}, orthonormalization {t_orth:.2} s",
            vm.ncols(),
            request.modal.name(),
            basis.len() - vm.ncols(),
            dropped_svd,
            self.svd_tol.map_or(String::new(), |t| format!(" at {t:e}")),
            dropped_static,
            method,
            real_modes_cost(&modes),
            if kept_responses {
                " (corrected onto the ties from the free model's kept responses to the \
                 pairs' friction loads)"
            } else {
                ""
            }
        ));
        Ok(basis)
    }
}

/// The model stage of `enriched`: the free model's pair solves and, when built, its
/// static space.
struct EnrichedStage {
    pairs: Arc<PairSolves>,
    space: Option<StaticSpace>,
}

impl EnrichedBasis {
    /// The basis of an undamped contact set in the model's static space: its real modes
    /// solved through the pair solves, its static responses as coordinates in the space
    /// (no solve, no `n`-row product), the basis implicit with the operator projected on
    /// it.
    fn build_in_space(
        &self,
        request: &BasisRequest<'_>,
        pairs: &PairSolves,
        space: &StaticSpace,
    ) -> Result<Basis> {
        let op = request.op;
        let cutoff = self.cutoff_factor * request.band_hz.1;
        let clock = Instant::now();
        let ks = StaticSolver::tied(op, pairs)?;
        let t_factor = clock.elapsed().as_secs_f64();
        let modes = coupled_real_modes_on(request, cutoff, &ks)?;
        let t_modes = clock.elapsed().as_secs_f64() - t_factor;
        let (vm, dropped_modes) =
            m_orthonormalize(op.mc.as_ref(), modes.vectors.as_ref(), self.rank_tol)?;
        let clock = Instant::now();
        let tied = ks.tied_solve().expect("a solver through the pair solves");
        let coords = space.tied_statics(tied);
        let loads = coords.ncols();
        let sb = space.basis(op, tied, coords.as_ref(), vm.as_ref(), self.rank_tol)?;
        let t_space = clock.elapsed().as_secs_f64();
        let (ns, ne) = (sb.columns.statics(), sb.columns.explicit());
        let mut basis = Basis::implicit(Arc::new(sb.columns), sb.projected);
        basis.seed.real_modes = real_modes_seed(op, &modes);
        basis.dropped = dropped_modes + sb.dropped_statics + sb.dropped_extra;
        basis.steps = vec![
            ("set-up".into(), t_factor),
            ("real modes".into(), t_modes),
            ("statics, orthonormalization and projection".into(), t_space),
        ];
        basis.notes.push(format!(
            "{NAME}: {ns} static vectors of {loads} friction loads in the model's static \
             space ({} directions; {} removed by the rank cut) + {ne} real modes up to \
             {cutoff:.1} Hz (`{}`; {} removed inside the static span or by the rank cut); \
             {}; times: set-up {t_factor:.2} s, modes {t_modes:.2} s ({}), statics, \
             orthonormalization and projection {t_space:.2} s",
            space.dim(),
            sb.dropped_statics,
            request.modal.name(),
            dropped_modes + sb.dropped_extra,
            ks.method,
            real_modes_cost(&modes),
        ));
        Ok(basis)
    }
}
