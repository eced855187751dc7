//! Modes as every solver returns them: complex modes of a QEP ([`ComplexModes`]), real
//! normal modes ([`RealModes`]), each with the report of its solve ([`SolveInfo`]).

use crate::c64;
use faer::Mat;

/// Complex modes of a QEP in a frequency band, sorted by frequency.
#[derive(Debug, Clone)]
pub struct ComplexModes {
    /// Eigenvalues `lambda` (1/s), the `Im > 0` member of each pair.
    pub lambda: Vec<c64>,
    /// Matching mode shapes on the operator's DOFs, one column per mode, unit 2-norm.
    pub vectors: Mat<c64>,
    /// Frequencies `Im(lambda) / 2 pi` (Hz).
    pub freq_hz: Vec<f64>,
    /// Divergence rates `Re(lambda) / Im(lambda)`.
    pub dvr: Vec<f64>,
    /// Backward error of each pair on the operator (see module docs).
    pub backward_error: Vec<f64>,
    /// Condition number of each eigenvalue,
    /// `||y|| ||x|| (|lambda|^2 ||M|| + |lambda| ||C|| + ||K||) / (|lambda| |y^H Q'(lambda) x|)`
    /// with the left eigenvector `y`; NaN where no left vector was computed (see
    /// [`Condition`](crate::qep::Condition) and the [`condition`](crate::qep::condition)
    /// module for what it promises and where it fails).
    pub cond: Vec<f64>,
    /// First-order estimate of the relative forward error of each eigenvalue,
    /// `|lambda - lambda_exact| / |lambda| <~ cond * backward_error`; NaN where `cond` is.
    pub error_bound: Vec<f64>,
    /// The left eigenvectors behind `cond` (`y^H Q(lambda) = 0`), one column per mode,
    /// unit 2-norm except inside a cluster of (nearly) equal eigenvalues, where they are
    /// bi-orthogonalized against the right vectors; `None` when not computed.
    pub left_vectors: Option<Mat<c64>>,
    /// How the solve went.
    pub info: SolveInfo,
}

impl ComplexModes {
    /// Number of modes.
    pub fn len(&self) -> usize {
        self.lambda.len()
    }
    /// Whether no mode was found.
    pub fn is_empty(&self) -> bool {
        self.lambda.is_empty()
    }
    /// Whether mode `i` is unstable: its divergence rate `DvR = Re / Im` exceeds
    /// `dvr_tol` (the one threshold of every command, `--dvr-tol`).
    pub fn is_unstable(&self, i: usize, dvr_tol: f64) -> bool {
        self.dvr[i] > dvr_tol
    }
}

/// Real normal modes in a band, sorted by frequency.
#[derive(Debug, Clone)]
pub struct RealModes {
    /// Eigenvalues `omega^2`, (rad/s)^2.
    pub omega2: Vec<f64>,
    /// Frequencies (Hz); negative round-off eigenvalues give 0.
    pub freq_hz: Vec<f64>,
    /// Mode shapes on the free DOFs, one column per mode, `M`-orthonormal.
    pub vectors: Mat<f64>,
    /// Relative residual of each pair (see module docs).
    pub residuals: Vec<f64>,
    /// How the solve went.
    pub info: SolveInfo,
    /// Converged eigenvectors above the band that the solve found on the way (an
    /// iterative solver asks for more pairs than the band holds, to see its top), by
    /// ascending frequency, unit `M` norm; `n x 0` when there are none. With
    /// [`vectors`](Self::vectors) they start a nearby problem's solve
    /// ([`crate::EigenSolver::solve_symmetric_on`]).
    pub above_band: Mat<f64>,
}

/// Why a solve stopped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StopReason {
    /// All requested pairs met the tolerance.
    Converged,
    /// The iteration cap was hit; `converged` in [`SolveInfo`] says how many made it.
    MaxIterations,
}

/// Cost and convergence report attached to every solve.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveInfo {
    /// Backend name.
    pub solver: String,
    /// Wall time (s), factorizations included.
    pub time_s: f64,
    /// Pairs requested in the last Krylov run.
    pub requested: usize,
    /// Pairs converged in the last Krylov run.
    pub converged: usize,
    /// Restarts / update iterations, summed over runs.
    pub iterations: usize,
    /// Operator applications (one sparse solve each).
    pub op_applications: usize,
    /// Sparse factorizations performed.
    pub factorizations: usize,
    /// Why it stopped.
    pub reason: StopReason,
    /// Anything the user should know (fallbacks, enlarged requests).
    pub notes: Vec<String>,
}

impl SolveInfo {
    /// A report of `solver` with every count zero, stopped on convergence, no notes: the
    /// start of every backend's report.
    pub fn new(solver: impl Into<String>) -> Self {
        Self {
            solver: solver.into(),
            time_s: 0.0,
            requested: 0,
            converged: 0,
            iterations: 0,
            op_applications: 0,
            factorizations: 0,
            reason: StopReason::Converged,
            notes: Vec::new(),
        }
    }
}
