//! The [`ReductionBasis`] plugin trait and the data it exchanges: the request
//! ([`BasisRequest`]) and the basis it builds ([`Basis`]).

use super::FrictionalOperator;
use crate::eigen::{EigenParams, EigenSolver};
use crate::Result;
use faer::Mat;

/// A real reduction basis on the constrained space, `M_c`-orthonormal
/// (`V^T M_c V = I` to round-off), with how it was built.
#[derive(Debug, Clone)]
pub struct Basis {
    /// Columns of the basis (`n_c x m`).
    pub v: Mat<f64>,
    /// Wall time to build it (s).
    pub time_s: f64,
    /// Candidate vectors removed by the rank cut (and the optional SVD compression).
    pub dropped: usize,
    /// Iterations (iterative bases), else 0.
    pub iterations: usize,
    /// Friction coefficient the basis was built for; `None` when it does not depend on mu
    /// (valid for every mu of the contact set).
    pub mu: Option<f64>,
    /// Final convergence measure of an iterative basis (the residue method's largest
    /// energy-norm residual of its target modes); `None` otherwise.
    pub residual: Option<f64>,
    /// Anything the user should know (what the columns are, non-convergence, ...).
    pub notes: Vec<String>,
    /// The operator projected on exactly these columns, when the basis computed it while
    /// building (an iterative basis projects at every step): the projection stage takes
    /// it instead of projecting again. `None`: projected after the build.
    pub projected: Option<FrictionalOperator>,
}

impl Basis {
    /// A basis of columns `v` (assumed `M_c`-orthonormal) with empty bookkeeping.
    pub fn new(v: Mat<f64>) -> Self {
        Self {
            v,
            time_s: 0.0,
            dropped: 0,
            iterations: 0,
            mu: None,
            residual: None,
            notes: Vec::new(),
            projected: None,
        }
    }

    /// Number of columns `m`.
    pub fn len(&self) -> usize {
        self.v.ncols()
    }

    /// Whether the basis has no column.
    pub fn is_empty(&self) -> bool {
        self.v.ncols() == 0
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
    /// The free-interface synthesis of the model, built once by the caller for a basis
    /// that asks for it ([`ReductionBasis::free_interface_cutoff`]); `None` otherwise.
    pub free: Option<&'a crate::synthesis::FreeInterface>,
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
    /// The highest free-interface frequency (Hz) the basis needs when it works from a
    /// [`FreeInterface`](crate::synthesis::FreeInterface) of the model, for a band whose
    /// top is `band_top_hz`; `None` (the default) when it does not. The caller then builds
    /// that synthesis once per model and candidate pairs and hands it to every
    /// [`build`](Self::build) in [`BasisRequest::free`].
    fn free_interface_cutoff(&self, band_top_hz: f64) -> Option<f64> {
        let _ = band_top_hz;
        None
    }
    /// Builds the basis described by `request`.
    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis>;
}
