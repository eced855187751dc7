//! The [`ReductionBasis`] plugin trait and the data it exchanges: the request
//! ([`BasisRequest`]) and the basis it builds ([`Basis`]).

use super::{FreeModel, ModelStage};
use crate::c64;
use crate::eigen::{EigenParams, EigenSolver};
use crate::operator::FrictionalOperator;
use crate::{Error, Result};
use faer::{Mat, MatRef};
use std::any::Any;
use std::sync::Arc;

/// Basis columns kept by their action rather than stored: a basis whose projection was
/// assembled without forming its `n_c x m` columns (e.g. from data on the contact pairs)
/// expands the reduced vectors it is asked for, `V q`, on demand.
pub trait ImplicitColumns: Send + Sync + std::fmt::Debug {
    /// Rows of the columns (the constrained DOFs `n_c`).
    fn nrows(&self) -> usize;
    /// Number of columns `m`.
    fn ncols(&self) -> usize;
    /// `V q` for the reduced vectors `q` (`m x k`): `n_c x k`.
    fn apply(&self, q: MatRef<'_, c64>) -> Result<Mat<c64>>;
}

/// A real reduction basis on the constrained space, `M_c`-orthonormal
/// (`V^T M_c V = I` to round-off), with how it was built.
#[derive(Debug, Clone)]
pub struct Basis {
    /// Columns of the basis (`n_c x m`); `0 x 0` when they are [`Basis::implicit`].
    pub v: Mat<f64>,
    /// The columns by their action, when they are not stored (then [`Basis::projected`]
    /// is set too: nothing else could project the operator on them).
    pub implicit: Option<Arc<dyn ImplicitColumns>>,
    /// Wall time to build it (s), set by [`build_basis`].
    pub time_s: f64,
    /// Candidate vectors removed by the rank cut (and the optional SVD compression).
    pub dropped: usize,
    /// Iterations (iterative bases), else 0.
    pub iterations: usize,
    /// Friction coefficient the basis was built for; `None` when it does not depend on mu
    /// (valid for every mu of the contact set). Set by [`build_basis`].
    pub mu: Option<f64>,
    /// Final convergence measure of an iterative basis (the residue method's largest
    /// energy-norm residual of its target modes); `None` otherwise.
    pub residual: Option<f64>,
    /// Anything the user should know (what the columns are, non-convergence, ...).
    pub notes: Vec<String>,
    /// Where the build's time went, step by step (`(step, s)`), for a basis that times
    /// its steps; empty otherwise. Reports list them under the basis's time.
    pub steps: Vec<(String, f64)>,
    /// The operator projected on exactly these columns, when the basis computed it while
    /// building (an iterative basis projects at every step): the projection stage takes
    /// it instead of projecting again. `None`: projected after the build.
    pub projected: Option<FrictionalOperator>,
    /// What a basis of the same method at the next point of a sweep may start from
    /// ([`BasisRequest::seed`]); empty when there is nothing to hand on.
    pub seed: Seed,
}

/// What a basis hands to the basis of the same method at the next point of a sweep
/// ([`Basis::seed`], [`BasisRequest::seed`]). Every matrix is on the free model's DOFs
/// (the numbering of the operator's index map `T`, [`crate::reduction::to_free_dofs`]),
/// since each contact set has its own constrained space. A seed changes where an
/// iteration starts, never what it has to reach: results agree with an unseeded build
/// to the tolerances asked.
#[derive(Debug, Clone, Default)]
pub struct Seed {
    /// The contact set's real modes of `(K_c, M_c)` the basis computed: the next contact
    /// set's real modes start their iteration from them
    /// ([`crate::reduction::coupled_real_modes_on`]).
    pub real_modes: Option<Mat<f64>>,
    /// Further directions the method adds to its own start (the residue method: the real
    /// and imaginary parts of its target modes).
    pub directions: Option<Mat<f64>>,
}

impl Seed {
    /// Whether the seed holds nothing.
    pub fn is_empty(&self) -> bool {
        self.real_modes.is_none() && self.directions.is_none()
    }
}

impl Basis {
    /// A basis of columns `v` (assumed `M_c`-orthonormal) with empty bookkeeping.
    pub fn new(v: Mat<f64>) -> Self {
        Self {
            v,
            implicit: None,
            time_s: 0.0,
            dropped: 0,
            iterations: 0,
            mu: None,
            residual: None,
            notes: Vec::new(),
            steps: Vec::new(),
            projected: None,
            seed: Seed::default(),
        }
    }

    /// A basis of implicit columns with the operator `projected` on them.
    pub fn implicit(columns: Arc<dyn ImplicitColumns>, projected: FrictionalOperator) -> Self {
        let mut basis = Self::new(Mat::zeros(0, 0));
        basis.implicit = Some(columns);
        basis.projected = Some(projected);
        basis
    }

    /// Number of columns `m`.
    pub fn len(&self) -> usize {
        self.implicit.as_ref().map_or(self.v.ncols(), |c| c.ncols())
    }

    /// Rows of the columns (the constrained DOFs).
    pub fn nrows(&self) -> usize {
        self.implicit.as_ref().map_or(self.v.nrows(), |c| c.nrows())
    }

    /// Whether the basis has no column.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The full vectors `V q` of reduced vectors `q` (`m x k`).
    pub fn expand(&self, q: MatRef<'_, c64>) -> Result<Mat<c64>> {
        match &self.implicit {
            Some(c) => c.apply(q),
            None => Ok(crate::linalg::expand(self.v.as_ref(), q)),
        }
    }
}

/// Everything a [`ReductionBasis`] may use to build its basis.
#[derive(Clone, Copy)]
pub struct BasisRequest<'a> {
    /// The full frictional operator of the contact set.
    pub op: &'a FrictionalOperator,
    /// Friction coefficient (bases fixed in mu ignore it).
    pub mu: f64,
    /// Frequency band of the stability analysis `(fmin, fmax)` (Hz).
    pub band_hz: (f64, f64),
    /// Solver of the full-order symmetric problems a basis needs (the coupled mu = 0
    /// real modes of `(K_c, M_c)`): normally a sparse backend (`arpack`, `krylov`).
    pub modal: &'a dyn EigenSolver,
    /// Solver of the reduced (projected) QEPs an iterative basis solves: normally `dense`.
    pub reduced: &'a dyn EigenSolver,
    /// Tolerances and limits handed to both solvers (their band fields are overridden).
    pub params: &'a EigenParams,
    /// The basis's own model stage ([`ReductionBasis::prepare`]), built once per model by
    /// the caller for a basis that has one ([`ReductionBasis::stage_key`]); `None`
    /// otherwise, or when the operator comes without its model (read from files).
    pub stage: Option<&'a (dyn Any + Send + Sync)>,
    /// The seed the basis built at the previous point of a sweep left ([`Basis::seed`]),
    /// which a basis may start from: it changes where an iteration starts, not what it
    /// has to reach (its own tolerance). `None` outside sweeps and at a sweep's first
    /// point.
    pub seed: Option<&'a Seed>,
}

/// Builds a reduction basis for one frictional operator.
///
/// The shared machinery (orthonormalization with a rank cut, projection, reduced solve,
/// expansion, backward errors on the full operator) lives in [`crate::reduction`]; a basis
/// only chooses its vectors.
pub trait ReductionBasis: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Whether the basis depends on mu. `false` (the default) means it is built once per
    /// contact set and reused across a whole mu sweep.
    fn depends_on_mu(&self) -> bool {
        false
    }
    /// The key of the model stage the basis needs for a band whose top is `band_top_hz`
    /// (`None`, the default: no model stage). Bases whose keys are equal share one stage:
    /// the key names the plugin and every parameter the stage depends on, e.g.
    /// `cms: free modes to 15000 Hz`.
    fn stage_key(&self, band_top_hz: f64) -> Option<String> {
        let _ = band_top_hz;
        None
    }
    /// The model stage (see [`FreeModel`]): computed once per model from `free` by the
    /// caller when [`stage_key`](Self::stage_key) is `Some`, and handed to every
    /// [`build`](Self::build) in [`BasisRequest::stage`]. The default has nothing to
    /// prepare.
    fn prepare(&self, free: &FreeModel<'_>) -> Result<Option<ModelStage>> {
        let _ = free;
        Ok(None)
    }
    /// Computes ahead, in a model stage of this basis's key (prepared by this basis or by
    /// another one that shares the key), what the basis would otherwise add to it at its
    /// first contact sets. A benchmark calls it before timing any case, so that a case's
    /// set-up time does not depend on which cases ran before it; a sweep need not (the
    /// stage then grows with the contact sets met). The default has nothing to add.
    fn complete_stage(&self, stage: &ModelStage) -> Result<()> {
        let _ = stage;
        Ok(())
    }
    /// The Cholesky factor of the free model's `K` that this basis's model stage holds,
    /// if any: the callers bound the errors of the modes solved on the basis in its
    /// energy norm with it ([`crate::reduction::energy_bounds`]). The default has none.
    fn stage_factor(&self, stage: &ModelStage) -> Option<Arc<crate::linalg::Cholesky>> {
        let _ = stage;
        None
    }
    /// Builds the basis described by `request`.
    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis>;
}

/// Builds `basis` for `request` the way every caller should: checks the request (a finite
/// mu, a band `0 <= fmin < fmax`), times the build into [`Basis::time_s`], records the mu
/// the basis belongs to ([`Basis::mu`], from [`ReductionBasis::depends_on_mu`]) and checks
/// the result (columns of the operator's size, at least one). A plugin's `build` only
/// chooses its vectors.
pub fn build_basis(basis: &dyn ReductionBasis, request: &BasisRequest<'_>) -> Result<Basis> {
    let (fmin, fmax) = request.band_hz;
    if !request.mu.is_finite() {
        return Err(Error::param(
            "mu",
            format!("expected a finite friction coefficient, got {}", request.mu),
        ));
    }
    if !(fmin.is_finite() && fmax.is_finite() && fmin >= 0.0 && fmin < fmax) {
        return Err(Error::param(
            "band_hz",
            format!("expected 0 <= fmin < fmax (Hz), got [{fmin}, {fmax}]"),
        ));
    }
    let start = std::time::Instant::now();
    let mut built = basis.build(request)?;
    if built.is_empty() || built.nrows() != request.op.dim() {
        return Err(Error::Invalid(format!(
            "basis `{}` returned {} x {} columns for an operator of {} DOFs",
            basis.name(),
            built.nrows(),
            built.len(),
            request.op.dim()
        )));
    }
    built.time_s = start.elapsed().as_secs_f64();
    built.mu = basis.depends_on_mu().then_some(request.mu);
    Ok(built)
}
