//! The complex modes of a QEP ([`ComplexModes`]) and the finishing step every solver
//! ends with ([`finish_modes`] and its forms): band selection, normalization, backward
//! errors and, from left eigenvectors, condition numbers and error bounds
//! ([`add_condition`]).

use super::condition::{self, LeftSource, NeededProblem};
use super::residual::{check_pairs, QepTerms};
use super::{left_eigenvectors, Condition};
use crate::eigen::EigenParams;
use crate::linalg::norm2_c;
use crate::operator::{needs_condition, ComplexModes, FrictionalOperator, Qep, SolveInfo};
use crate::{c64, Error, Result};
use faer::Mat;
use std::time::Instant;

/// Size above which [`Condition::Auto`] does not compute `cond` even for the modes whose
/// class depends on it: a complex sparse LU of `Q(lambda)` per mode (faer's, in its
/// column ordering) took 29 s and 4.6 GB at 45k DOFs, and runs out of 24 GB at the
/// default rig's 172k. Those modes then stay neutral within the square-root rule
/// ([`crate::operator::classify`]), noted in the solve's report.
pub const CONDITION_WHERE_NEEDED_MAX_DIM: usize = 50_000;

/// Relative size of `Im(lambda)` below which a root counts as real (not an oscillating
/// mode): `|Im(lambda)| <= REAL_ROOT_REL |lambda|`. Such roots are dropped by
/// [`finish_modes`].
pub const REAL_ROOT_REL: f64 = 1e-10;

/// The eigenvalues [`finish_modes`] keeps, as `(frequency in Hz, index)` sorted by
/// frequency then real part: finite, oscillating (`Im(lambda) > REAL_ROOT_REL |lambda|`)
/// and in the band of `params` (inclusive, relative slack `1e-12`). Reduced solves use it
/// to expand only these vectors.
pub fn band_pairs(lambda: &[c64], params: &EigenParams) -> Vec<(f64, usize)> {
    let two_pi = 2.0 * std::f64::consts::PI;
    let lo = params.fmin_hz * (1.0 - 1e-12);
    let hi = params.fmax_hz * (1.0 + 1e-12);
    let mut keep: Vec<(f64, usize)> = lambda
        .iter()
        .enumerate()
        .filter(|(_, l)| l.re.is_finite() && l.im.is_finite())
        .filter(|(_, l)| l.im > REAL_ROOT_REL * l.norm())
        // heavily damped roots are no vibration modes (see `finish_modes`)
        .filter(|(_, l)| -l.re <= l.im)
        .map(|(i, l)| (l.im / two_pi, i))
        .filter(|&(f, _)| f >= lo && f <= hi)
        .collect();
    keep.sort_by(|a, b| {
        a.0.total_cmp(&b.0)
            .then(lambda[a.1].re.total_cmp(&lambda[b.1].re))
    });
    keep
}

/// Keeps the pairs with `Im(lambda) > 0` and frequency in the band, normalizes the vectors,
/// computes frequencies, DvR and backward errors, and sorts by frequency.
///
/// Real roots (`|Im| <= REAL_ROOT_REL |lambda|`, rigid-body zeros included) are not
/// oscillating modes and are dropped, and so are heavily damped roots with
/// `Re(lambda) < -Im(lambda)` (damping ratio `-Re / |lambda|` above `1/sqrt 2`): a damped
/// operator has them (overdamped modes under stiffness-proportional damping, where a
/// cluster of real roots near `-1/beta` comes out of a dense solver as pairs with
/// round-off imaginary parts), they can never be unstable, and a shift-invert solver aimed
/// at the band does not see them. The band is inclusive with a relative slack of
/// `1e-12`. Vectors get unit 2-norm and a deterministic phase (their largest-modulus
/// component real positive). `info` is passed through (the caller sets `time_s`).
///
/// Left eigenvectors, condition numbers and forward error estimates are computed as
/// [`Condition::Auto`] says (by inverse iteration on `qep`, one factorization per kept
/// mode, counted in `info.factorizations` and noted).
pub fn finish_modes(
    qep: &Qep,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
) -> Result<ComplexModes> {
    finish_modes_with(qep, lambda, vectors, params, info, Condition::Auto)
}

/// [`finish_modes`] with an explicit choice of left eigenvectors.
pub fn finish_modes_with(
    qep: &Qep,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
    condition: Condition,
) -> Result<ComplexModes> {
    let left = if condition.applies(qep.dim()) {
        LeftSource::InverseIteration(qep)
    } else if condition.where_needed(qep.dim()) {
        LeftSource::WhereNeeded(NeededProblem::Qep(qep))
    } else {
        LeftSource::None
    };
    finish_terms(&QepTerms::of_qep(qep), lambda, vectors, left, params, info)
}

/// [`finish_modes`] on `op.at(mu)`, without assembling it: the backward errors are
/// computed on the parts `X_c - mu F_X` (the same numbers to round-off). Left
/// eigenvectors only for the modes whose stability class depends on their condition
/// ([`needs_condition`]; `op.at(mu)` is then assembled for their inverse iteration),
/// `cond` and `error_bound` NaN for the others; reduced solves use
/// [`finish_operator_modes_with_left`].
pub fn finish_operator_modes(
    op: &FrictionalOperator,
    mu: f64,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
) -> Result<ComplexModes> {
    if !mu.is_finite() {
        return Err(Error::param("mu", format!("must be finite, got {mu}")));
    }
    finish_terms(
        &QepTerms::of_operator(op, mu),
        lambda,
        vectors,
        LeftSource::WhereNeeded(NeededProblem::Operator(op, mu)),
        params,
        info,
    )
}

/// [`finish_operator_modes`] with given left eigenvectors (one column per eigenvalue of
/// `lambda`, e.g. a reduced solve's left vectors expanded by the basis), from which the
/// condition numbers and forward error estimates are computed on `op.at(mu)`.
pub fn finish_operator_modes_with_left(
    op: &FrictionalOperator,
    mu: f64,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    left: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
) -> Result<ComplexModes> {
    if !mu.is_finite() {
        return Err(Error::param("mu", format!("must be finite, got {mu}")));
    }
    if left.nrows() != op.dim() || left.ncols() != lambda.len() {
        return Err(Error::Dimension {
            context: "finish_modes: one left vector of the operator size per eigenvalue".into(),
            expected: lambda.len(),
            got: left.ncols(),
        });
    }
    finish_terms(
        &QepTerms::of_operator(op, mu),
        lambda,
        vectors,
        LeftSource::Given(left),
        params,
        info,
    )
}

/// Adds left eigenvectors, condition numbers and forward error estimates to modes of
/// `op` at `mu` that were computed without them (a full-order solve above
/// [`CONDITION_AUTO_MAX_DIM`](super::CONDITION_AUTO_MAX_DIM), where
/// [`Condition::Auto`] skips them): the left vectors by [`left_eigenvectors`] on
/// `op.at(mu)` (one factorization of `Q(lambda)` per mode), then `cond` and
/// `error_bound` from the modes' own backward errors. Modes that already carry left
/// vectors are left as they are. The factorizations are counted in `info` and noted with
/// their time; `info.time_s` is not changed.
///
/// # Errors
/// A non-finite `mu`, modes whose vectors do not have the operator's size, or a failure
/// of the left solves.
pub fn add_condition(op: &FrictionalOperator, mu: f64, modes: &mut ComplexModes) -> Result<()> {
    if modes.left_vectors.is_some() {
        return Ok(());
    }
    if !mu.is_finite() {
        return Err(Error::param("mu", format!("must be finite, got {mu}")));
    }
    if modes.vectors.nrows() != op.dim() || modes.vectors.ncols() != modes.len() {
        return Err(Error::Dimension {
            context: "add_condition: one mode vector of the operator size per eigenvalue".into(),
            expected: op.dim(),
            got: modes.vectors.nrows(),
        });
    }
    let t = Instant::now();
    let qep = op.at(mu)?;
    let (y, how) = left_eigenvectors(&qep, &modes.lambda, modes.vectors.as_ref())?;
    let terms = QepTerms::of_operator(op, mu);
    let (cond, error_bound) = condition::condition_numbers(
        &terms,
        &terms.norms(),
        &modes.lambda,
        modes.vectors.as_ref(),
        y.as_ref(),
        &modes.backward_error,
    );
    modes.info.factorizations += how.factorizations;
    if !modes.is_empty() {
        modes.info.notes.push(format!(
            "left eigenvectors for cond, error_bound (asked for): {}{} factorizations of \
             Q(lambda), {:.3} s",
            if how.transposed_solve {
                "one dense solve of the transposed problem, "
            } else {
                ""
            },
            how.factorizations,
            t.elapsed().as_secs_f64()
        ));
    }
    modes.cond = cond;
    modes.error_bound = error_bound;
    modes.left_vectors = Some(y);
    Ok(())
}

fn finish_terms(
    qep: &QepTerms<'_>,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    left: LeftSource<'_>,
    params: &EigenParams,
    mut info: SolveInfo,
) -> Result<ComplexModes> {
    let n = qep.n;
    if vectors.nrows() != n {
        return Err(Error::Dimension {
            context: "finish_modes: rows of the mode vectors".into(),
            expected: n,
            got: vectors.nrows(),
        });
    }
    if vectors.ncols() != lambda.len() {
        return Err(Error::Dimension {
            context: "finish_modes: one vector per eigenvalue".into(),
            expected: lambda.len(),
            got: vectors.ncols(),
        });
    }
    let keep = band_pairs(lambda, params);
    let norms = qep.norms();
    let mut out = Mat::<c64>::zeros(n, keep.len());
    let (mut lam, mut freq, mut dvr) = (vec![], vec![], vec![]);
    for (c, &(f, i)) in keep.iter().enumerate() {
        let l = lambda[i];
        let mut u: Vec<c64> = (0..n).map(|r| vectors[(r, i)]).collect();
        let (mut p, mut big) = (0, 0.0);
        for (r, v) in u.iter().enumerate() {
            if v.norm() > big {
                big = v.norm();
                p = r;
            }
        }
        let nrm = norm2_c(&u);
        if big > 0.0 {
            let phase = u[p].conj() / (big * nrm);
            u.iter_mut().for_each(|v| *v *= phase);
            u[p] = c64::new(u[p].norm(), 0.0);
        }
        for r in 0..n {
            out[(r, c)] = u[r];
        }
        lam.push(l);
        freq.push(f);
        dvr.push(l.re / l.im);
    }
    let mut where_needed = None;
    let left = match left {
        LeftSource::None => None,
        LeftSource::WhereNeeded(problem) => {
            where_needed = Some(problem);
            None
        }
        LeftSource::Given(y) => Some(Mat::from_fn(n, keep.len(), |r, c| y[(r, keep[c].1)])),
        LeftSource::InverseIteration(q) => {
            let t = Instant::now();
            let (y, how) = left_eigenvectors(q, &lam, out.as_ref())?;
            info.factorizations += how.factorizations;
            if !lam.is_empty() {
                info.notes.push(format!(
                    "left eigenvectors for cond, error_bound: {}{} factorizations of \
                     Q(lambda) for inverse iteration, {:.3} s",
                    if how.transposed_solve {
                        "one dense solve of the transposed problem, "
                    } else {
                        ""
                    },
                    how.factorizations,
                    t.elapsed().as_secs_f64()
                ));
            }
            Some(y)
        }
    };
    // one pass over the matrices for the backward errors and the condition numbers
    let (be, products) = check_pairs(
        qep,
        &norms,
        &lam,
        out.as_ref(),
        left.as_ref().map(|y| y.as_ref()),
        true,
    );
    let (mut cond, mut error_bound) = match &left {
        Some(_) => condition::condition_from_products(&norms, &lam, &products, &be),
        None => (vec![f64::NAN; lam.len()], vec![f64::NAN; lam.len()]),
    };
    let cond_floor: Vec<f64> = lam.iter().map(|&l| norms.cond_floor(l)).collect();
    if let Some(problem) = where_needed {
        let need: Vec<usize> = (0..lam.len())
            .filter(|&j| needs_condition(lam[j], be[j], cond_floor[j]))
            .collect();
        if !need.is_empty() && n > CONDITION_WHERE_NEEDED_MAX_DIM {
            info.notes.push(format!(
                "cond not computed for the {} of {} modes whose stability class depends on \
                 it: {n} DOFs is above {CONDITION_WHERE_NEEDED_MAX_DIM}, where a complex \
                 sparse LU of Q(lambda) per mode costs more than the solve (they stay \
                 neutral within the square-root rule; --condition forces it)",
                need.len(),
                lam.len()
            ));
        } else if !need.is_empty() {
            let t = Instant::now();
            let q = problem.qep()?;
            let lam_n: Vec<c64> = need.iter().map(|&j| lam[j]).collect();
            let be_n: Vec<f64> = need.iter().map(|&j| be[j]).collect();
            let x = Mat::from_fn(n, need.len(), |r, c| out[(r, need[c])]);
            let (y, how) = left_eigenvectors(&q, &lam_n, x.as_ref())?;
            let (c, b) = condition::condition_numbers(
                &QepTerms::of_qep(&q),
                &norms,
                &lam_n,
                x.as_ref(),
                y.as_ref(),
                &be_n,
            );
            for (k, &j) in need.iter().enumerate() {
                cond[j] = c[k];
                error_bound[j] = b[k];
            }
            info.factorizations += how.factorizations;
            info.notes.push(format!(
                "cond, error_bound for the {} of {} modes whose stability class depends on \
                 them (real part between the smallest bound and the square-root rule): {} \
                 factorizations of Q(lambda), {:.3} s",
                need.len(),
                lam.len(),
                how.factorizations,
                t.elapsed().as_secs_f64()
            ));
        }
    }
    Ok(ComplexModes {
        lambda: lam,
        vectors: out,
        freq_hz: freq,
        dvr,
        backward_error: be,
        cond,
        error_bound,
        cond_floor,
        left_vectors: left,
        info,
    })
}
