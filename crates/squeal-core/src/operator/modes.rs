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
    /// `|lambda - lambda_exact| / |lambda| <~ cond * backward_error`, or, for a mode of a
    /// reduced solve that [`crate::reduction::energy_bounds`] tightened, the same bound
    /// in an energy norm; NaN where `cond` is.
    pub error_bound: Vec<f64>,
    /// The smallest condition number each eigenvalue can have given the matrix norms
    /// (`(|l|^2 ||M|| + |l| ||C|| + ||K||) / (|l| (2 |l| ||M||_2 + ||C||_2))`, at least
    /// [`MIN_COND`]): a real part within it times the backward error is neutral without
    /// computing `cond` ([`classify`]).
    pub cond_floor: Vec<f64>,
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
    /// The stability class of mode `i` ([`classify`]): decided by its real part against
    /// its forward error bound, and beyond the optional physical margin `dvr_margin` on
    /// the divergence rate (0: none).
    pub fn stability(&self, i: usize, dvr_margin: f64) -> Stability {
        self.verdict(i, dvr_margin).class
    }

    /// The class of mode `i` with the bound it was decided by ([`classify`]).
    pub fn verdict(&self, i: usize, dvr_margin: f64) -> Verdict {
        classify(
            self.lambda[i],
            self.backward_error[i],
            self.cond[i],
            self.error_bound[i],
            self.cond_floor.get(i).copied().unwrap_or(f64::NAN),
            dvr_margin,
        )
    }

    /// Whether mode `i` is unstable ([`stability`](Self::stability)).
    pub fn is_unstable(&self, i: usize, dvr_margin: f64) -> bool {
        self.stability(i, dvr_margin) == Stability::Unstable
    }

    /// How many modes fall in each class, `[unstable, neutral, stable]`.
    pub fn class_counts(&self, dvr_margin: f64) -> [usize; 3] {
        let mut counts = [0; 3];
        for i in 0..self.len() {
            counts[self.stability(i, dvr_margin).index()] += 1;
        }
        counts
    }
}

/// The rounding floor of a backward error: a residual `Q(lambda) u` evaluated in double
/// precision carries an error of a few tens of units of round-off of the terms it sums, so
/// a computed backward error below this resolves nothing, and the bound of a mode uses at
/// least this.
pub const BACKWARD_ERROR_FLOOR: f64 = 64.0 * f64::EPSILON;

/// The smallest condition number an eigenvalue can have in the norms of
/// [`ComplexModes::cond`] (`|y^H Q'(lambda) x| <= ||y|| ||x|| (2 |lambda| ||M|| + ||C||)`,
/// so `cond >= 1/2`): a real part below `MIN_COND` times the backward error is within the
/// bound whatever the condition.
pub const MIN_COND: f64 = 0.5;

/// A real part larger than this many times `sqrt(backward error) |lambda|` keeps its sign
/// whatever the condition: even at a coalescence, where the first-order bound fails, an
/// eigenvalue moves by about the square root of the perturbation.
pub const SQRT_RULE: f64 = 10.0;

/// The stability class of a mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stability {
    /// `Re(lambda)` above its forward error bound (and the divergence rate above the
    /// physical margin, when one is asked): certainly growing.
    Unstable,
    /// `Re(lambda)` within its bound (or a positive divergence rate within the margin):
    /// the solve cannot tell the sign, e.g. the round-off real parts of an undamped
    /// operator's uncoupled modes, or a mode at a coalescence.
    Neutral,
    /// `Re(lambda)` below minus its bound: certainly decaying.
    Stable,
}

impl Stability {
    /// Every class, in the order of [`Stability::index`].
    pub const ALL: [Stability; 3] = [Stability::Unstable, Stability::Neutral, Stability::Stable];

    /// `"unstable"`, `"neutral"` or `"stable"`.
    pub fn name(self) -> &'static str {
        match self {
            Stability::Unstable => "unstable",
            Stability::Neutral => "neutral",
            Stability::Stable => "stable",
        }
    }

    /// Position in [`Stability::ALL`] (0 unstable, 1 neutral, 2 stable).
    pub fn index(self) -> usize {
        match self {
            Stability::Unstable => 0,
            Stability::Neutral => 1,
            Stability::Stable => 2,
        }
    }
}

impl std::fmt::Display for Stability {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A mode's class and the bound of its real part it was decided by.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    /// The class.
    pub class: Stability,
    /// Forward error bound of `Re(lambda)` (1/s): `cond x max(backward error,
    /// BACKWARD_ERROR_FLOOR) x |lambda|`; NaN when the class did not need it (no `cond`
    /// and a real part far beyond any bound, see [`classify`]).
    pub re_bound: f64,
}

/// Whether the class of an eigenvalue with this backward error depends on its condition
/// number: a real part between the smallest bound any condition gives
/// (`cond_floor x eta x |lambda|`, [`ComplexModes::cond_floor`]; NaN for
/// [`MIN_COND`]) and the square-root rule (`SQRT_RULE x sqrt(eta) x |lambda|`), `eta`
/// the backward error floored at [`BACKWARD_ERROR_FLOOR`]. Full-order solves compute
/// `cond` for these modes only (see [`Condition::Auto`](crate::qep::Condition)).
pub fn needs_condition(lambda: crate::c64, backward_error: f64, cond_floor: f64) -> bool {
    let e = floored(backward_error);
    let (re, a) = (lambda.re.abs(), lambda.norm());
    re > least_cond(cond_floor) * e * a && re < SQRT_RULE * e.sqrt() * a
}

/// The smallest condition number to count on: `cond_floor`, at least [`MIN_COND`].
fn least_cond(cond_floor: f64) -> f64 {
    if cond_floor.is_nan() {
        MIN_COND
    } else {
        cond_floor.max(MIN_COND)
    }
}

fn floored(backward_error: f64) -> f64 {
    if backward_error.is_nan() {
        f64::INFINITY
    } else {
        backward_error.max(BACKWARD_ERROR_FLOOR)
    }
}

/// The stability class of an eigenvalue `lambda` (1/s) with its backward error and
/// condition number on the full operator.
///
/// The forward error bound of the real part is `b = error_bound x |lambda|`, at least
/// `cond x BACKWARD_ERROR_FLOOR x |lambda|` (`error_bound = cond x eta`, `eta` the backward
/// error, or for a reduced mode the smaller energy-norm bound of
/// [`crate::reduction::energy_bounds`]; `cond x eta` when `error_bound` is NaN): the
/// mode is
/// **unstable** when
/// `Re(lambda) > b` and its divergence rate `Re / Im` exceeds `dvr_margin` (a physical
/// margin; 0 for none), **stable** when `Re(lambda) < -b`, **neutral** otherwise. An
/// infinite `cond` (a defective eigenvalue, where the first-order bound fails) takes the
/// square-root rule `b = sqrt(eta) |lambda|`. Without `cond` (NaN): a real part within
/// `MIN_COND x eta x |lambda|` is neutral (no condition number is smaller), one beyond
/// `SQRT_RULE x sqrt(eta) x |lambda|` is decided by its sign (bound NaN), and one in
/// between ([`needs_condition`]) is neutral within that conservative bound. `cond_floor`
/// ([`ComplexModes::cond_floor`], NaN when unknown) replaces `MIN_COND` when larger.
pub fn classify(
    lambda: crate::c64,
    backward_error: f64,
    cond: f64,
    error_bound: f64,
    cond_floor: f64,
    dvr_margin: f64,
) -> Verdict {
    let e = floored(backward_error);
    let (re, a) = (lambda.re, lambda.norm());
    let least = least_cond(cond_floor);
    let re_bound = if cond.is_finite() && error_bound.is_finite() {
        error_bound.max(cond * BACKWARD_ERROR_FLOOR) * a
    } else if cond.is_finite() {
        cond * e * a
    } else if cond.is_infinite() {
        e.sqrt() * a
    } else if re.abs() <= least * e * a {
        least * e * a
    } else if re.abs() >= SQRT_RULE * e.sqrt() * a {
        f64::NAN
    } else {
        SQRT_RULE * e.sqrt() * a
    };
    let b = if re_bound.is_nan() { 0.0 } else { re_bound };
    let dvr = re / lambda.im;
    let class = if re > b && (dvr > dvr_margin || dvr.is_nan()) {
        Stability::Unstable
    } else if re < -b {
        Stability::Stable
    } else {
        Stability::Neutral
    };
    Verdict { class, re_bound }
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
