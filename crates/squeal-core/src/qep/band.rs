//! The band driver of the full-order complex backends: its options
//! ([`QepBandOptions`], [`LowRank`]) and entry points ([`solve_qep_band`],
//! [`solve_frictional_band`] and their `_with` forms).

use super::residual::QepNorms;
use super::window::BandRun;
use super::{dense_qep, finish_modes_with, ComplexKernel, Condition};
use crate::eigen::{validate_params, EigenParams};
use crate::lowrank::{FrictionLowRank, SymmetricPencil};
use crate::operator::SolveInfo;
use crate::operator::{check_qep, ComplexModes, FrictionalOperator, Qep};
use crate::spectral::QepSymbolic;
use crate::{c64, Error, Result};
use faer::Mat;
use std::sync::Arc;
use std::time::Instant;

/// Tuning of the band driver [`solve_qep_band_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct QepBandOptions {
    /// Cap on `nev` of one Krylov run (also capped by `n - 2`); a window needing more is
    /// split in two.
    pub max_nev: usize,
    /// Window radius `R = radius_factor * half_width + margin_rel * 2 pi f_top` (rad/s):
    /// `radius_factor > 1` lets the circle reach past the band edges off the imaginary axis.
    pub radius_factor: f64,
    /// Extra radius as a fraction of the window's top angular frequency.
    pub margin_rel: f64,
    /// Maximum depth of window splitting (`2^max_depth` windows at most).
    pub max_depth: usize,
    /// First `nev` when [`EigenParams::nev_hint`] is `None`.
    pub nev_default: usize,
    /// Use the real squared transformation ([`SquaredShift`](crate::spectral::SquaredShift)) when `C = 0`.
    pub squared_when_undamped: bool,
    /// Whether the squared transformation of an undamped frictional operator goes through
    /// the low-rank (Woodbury) path ([`SquaredShift::low_rank`](crate::spectral::SquaredShift::low_rank)) instead of a sparse LU of
    /// `K~ - s M~`. Only [`solve_frictional_band_with`] can use it (it needs the parts of
    /// the operator); [`solve_qep_band_with`] ignores it.
    pub low_rank: LowRank,
    /// Whether the modes get left eigenvectors, condition numbers and forward error
    /// estimates (one extra factorization per mode, see [`Condition`]).
    pub condition: Condition,
}

/// Choice of the low-rank (Woodbury) path of the band driver, see
/// [`QepBandOptions::low_rank`] and [`crate::lowrank`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LowRank {
    /// Use it when it applies (`C = 0`, squared transformation on, `friction_loads`
    /// known and recoverable) and `n > LOW_RANK_AUTO_MIN_DIM`; otherwise, or when building
    /// it fails, fall back to the sparse LU (noted in `info`).
    #[default]
    Auto,
    /// Use it whenever the problem is solved iteratively; an error when it does not apply.
    Always,
    /// Never use it (sparse LU of `K~ - s M~`).
    Never,
}

/// Size above which [`LowRank::Auto`] takes the low-rank path.
pub const LOW_RANK_AUTO_MIN_DIM: usize = 20_000;

impl Default for QepBandOptions {
    fn default() -> Self {
        Self {
            max_nev: 400,
            radius_factor: 1.05,
            margin_rel: 0.01,
            max_depth: 10,
            nev_default: 24,
            squared_when_undamped: true,
            low_rank: LowRank::Auto,
            condition: Condition::Auto,
        }
    }
}

/// Band driver shared by the full-order complex backends: shifts `i 2 pi f` chosen to cover
/// `[params.fmin_hz, params.fmax_hz]`, the kernel run on [`QepShiftInvert`](crate::spectral::QepShiftInvert) for each, `nev`
/// grown until every window is covered, eigenvalues mapped back, duplicates merged, and the
/// result finished by [`finish_modes`](super::finish_modes).
///
/// Same as [`solve_qep_band_with`] with default [`QepBandOptions`] and a fresh symbolic
/// analysis.
pub fn solve_qep_band(
    solver: &str,
    kernel: &dyn ComplexKernel,
    qep: &Qep,
    params: &EigenParams,
) -> Result<ComplexModes> {
    solve_qep_band_with(
        solver,
        kernel,
        qep,
        params,
        &QepBandOptions::default(),
        None,
    )
}

/// The band driver with explicit options and an optional reused symbolic analysis.
///
/// - Companion size `2n <= params.dense_below`: solved by [`dense_qep`] (noted in `info`).
/// - Otherwise one window `[fmin, fmax]` to start with: shift `sigma = i 2 pi f_c` at its
///   centre, radius `R` (see [`QepBandOptions`]). The kernel computes the `nev` largest
///   `|theta|` of `OP`, i.e. the `nev` eigenvalues nearest `sigma`; once one of them lies
///   outside the circle `|lambda - sigma| > R`, every eigenvalue inside it has been found.
///   Until then `nev` doubles (from `params.nev_hint`, else `nev_default`); past the cap
///   the window is split in two halves, recursively.
/// - Each window keeps the eigenvalues with `Im > 0` and frequency in its sub-band;
///   copies found by two windows are merged (relative distance `1e-8`, or 100 `tol R`).
/// - The mode `u` is the first block of the companion eigenvector `z = [u; lambda u]`, or
///   the second divided by `lambda` when that has the smaller backward error.
/// - `params.shift_hz` is not used (the shifts are on the imaginary axis).
pub fn solve_qep_band_with(
    solver: &str,
    kernel: &dyn ComplexKernel,
    qep: &Qep,
    params: &EigenParams,
    options: &QepBandOptions,
    symbolic: Option<&QepSymbolic>,
) -> Result<ComplexModes> {
    band_solve(
        solver,
        kernel,
        qep,
        params,
        options,
        symbolic,
        LowRankChoice::Off,
        Instant::now(),
    )
}

/// Band driver on a frictional operator at `mu`: [`solve_frictional_band_with`] with
/// default [`QepBandOptions`].
pub fn solve_frictional_band(
    solver: &str,
    kernel: &dyn ComplexKernel,
    op: &FrictionalOperator,
    mu: f64,
    params: &EigenParams,
) -> Result<ComplexModes> {
    solve_frictional_band_with(solver, kernel, op, mu, params, &QepBandOptions::default())
}

/// Band driver on a frictional operator at `mu`: the same as
/// [`solve_qep_band_with`] on [`op.at(mu)`](FrictionalOperator::at), except that an
/// undamped operator (`C = 0`, squared transformation) may go through the low-rank path
/// ([`crate::lowrank`]: one symmetric `L B L^T` of `K_c - s M_c` per window and a
/// Woodbury correction of rank `nA`) instead of a sparse LU of `K~ - s M~`, as
/// [`QepBandOptions::low_rank`] says. The notes of the result say which path was taken,
/// the number of stored entries of the factor, the rank and the measured accuracy.
pub fn solve_frictional_band_with(
    solver: &str,
    kernel: &dyn ComplexKernel,
    op: &FrictionalOperator,
    mu: f64,
    params: &EigenParams,
    options: &QepBandOptions,
) -> Result<ComplexModes> {
    let start = Instant::now();
    let qep = op.at(mu)?;
    let n = qep.dim();
    let wanted = match options.low_rank {
        LowRank::Never => false,
        LowRank::Always => true,
        LowRank::Auto => n > LOW_RANK_AUTO_MIN_DIM,
    };
    let iterative = 2 * n > params.dense_below;
    let choice = if !wanted || !iterative {
        LowRankChoice::Off
    } else {
        let why_not = if !options.squared_when_undamped {
            Some("the squared transformation is off".to_string())
        } else if qep.c.is_some() {
            Some("the operator is damped (C != 0)".to_string())
        } else if op.friction_loads.is_none() {
            Some("the operator has no friction_loads".to_string())
        } else {
            None
        };
        let built = match why_not {
            Some(w) => Err(Error::Invalid(w)),
            None => FrictionLowRank::new(op).and_then(|fr| {
                let t = Instant::now();
                let pencil = SymmetricPencil::new(op)?;
                if pencil.asymmetry() > crate::lowrank::MAX_ASYMMETRY {
                    return Err(Error::Invalid(format!(
                        "K_c / M_c are not symmetric (relative asymmetry {:.2e})",
                        pencil.asymmetry()
                    )));
                }
                Ok((fr, pencil, t.elapsed().as_secs_f64()))
            }),
        };
        match built {
            Ok((friction, pencil, t_sym)) => LowRankChoice::On(Box::new(LowRankCtx {
                op,
                mu,
                friction,
                pencil: Arc::new(pencil),
                t_symbolic: t_sym,
            })),
            Err(e) if options.low_rank == LowRank::Always => {
                return Err(Error::Invalid(format!(
                    "low-rank path requested (LowRank::Always) but not applicable: {e}"
                )))
            }
            Err(e) => LowRankChoice::Declined(format!(
                "low-rank path not applicable ({e}); sparse LU used"
            )),
        }
    };
    band_solve(solver, kernel, &qep, params, options, None, choice, start)
}

/// Data of the low-rank path of one band solve.
pub(super) struct LowRankCtx<'a> {
    pub(super) op: &'a FrictionalOperator,
    pub(super) mu: f64,
    pub(super) friction: FrictionLowRank,
    pub(super) pencil: Arc<SymmetricPencil>,
    pub(super) t_symbolic: f64,
}

/// Whether a band solve uses the low-rank path.
enum LowRankChoice<'a> {
    /// Not considered.
    Off,
    /// Considered and declined (the note says why).
    Declined(String),
    /// Used.
    On(Box<LowRankCtx<'a>>),
}

/// The band driver proper (see [`solve_qep_band_with`]).
fn band_solve(
    solver: &str,
    kernel: &dyn ComplexKernel,
    qep: &Qep,
    params: &EigenParams,
    options: &QepBandOptions,
    symbolic: Option<&QepSymbolic>,
    low_rank: LowRankChoice<'_>,
    start: Instant,
) -> Result<ComplexModes> {
    validate_params(params)?;
    check_qep(qep)?;
    let n = qep.dim();
    if n == 0 {
        return Err(Error::Invalid("empty quadratic eigenproblem".into()));
    }
    let valid = options.radius_factor.is_finite()
        && options.radius_factor >= 1.0
        && options.margin_rel.is_finite()
        && options.margin_rel >= 0.0;
    if options.max_nev == 0 || !valid {
        return Err(Error::param(
            "qep band options",
            format!("need max_nev >= 1, radius_factor >= 1, margin_rel >= 0; got {options:?}"),
        ));
    }
    let mut info = SolveInfo::new(solver);
    if 2 * n <= params.dense_below {
        info.notes.push(format!(
            "companion size 2n = {} <= {}: solved densely instead of `{solver}`",
            2 * n,
            params.dense_below
        ));
        let (lambda, vectors) = dense_qep(qep)?;
        info.requested = lambda.len();
        info.converged = lambda.len();
        let mut modes = finish_modes_with(
            qep,
            &lambda,
            vectors.as_ref(),
            params,
            info,
            options.condition,
        )?;
        modes.info.time_s = start.elapsed().as_secs_f64();
        return Ok(modes);
    }
    let low_rank = match low_rank {
        LowRankChoice::On(ctx) => Some(*ctx),
        LowRankChoice::Declined(note) => {
            info.notes.push(note);
            None
        }
        LowRankChoice::Off => None,
    };
    let cap = options.max_nev.min(n.saturating_sub(2)).max(1);
    let mut run = BandRun {
        kernel,
        qep,
        params,
        options,
        sym: symbolic,
        sym_owned: None,
        low_rank,
        cap,
        norms: QepNorms::of(qep),
        info,
        lambda: Vec::new(),
        vectors: Vec::new(),
    };
    let nev0 = params.nev_hint.unwrap_or(options.nev_default).clamp(1, cap);
    run.window(params.fmin_hz, params.fmax_hz, 0, nev0)?;
    let mut vectors = Mat::<c64>::zeros(n, run.lambda.len());
    for (c, v) in run.vectors.iter().enumerate() {
        for r in 0..n {
            vectors[(r, c)] = v[r];
        }
    }
    let mut modes = finish_modes_with(
        qep,
        &run.lambda,
        vectors.as_ref(),
        params,
        run.info,
        options.condition,
    )?;
    modes.info.time_s = start.elapsed().as_secs_f64();
    Ok(modes)
}
