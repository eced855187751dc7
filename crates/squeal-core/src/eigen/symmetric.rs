//! The symmetric (real-mode) problem `K x = omega^2 M x`: its types, the band driver
//! every symmetric backend shares ([`solve_symmetric_band`], [`finish_real_modes`]) and
//! the dense solver ([`dense_symmetric`]).

use super::{too_many_modes, validate_params, EigenParams};
use crate::linalg::{col, dot, norm1, norm2, symmetric_times};
use crate::operator::{RealModes, SolveInfo, StopReason};
use crate::spectral::{LinOp, ShiftInvert, SpectralTransform};
use crate::{Error, Result, SparseRef};
use faer::{Mat, MatRef};
use std::time::Instant;

/// `K x = omega^2 M x` on the free DOFs.
#[derive(Clone, Copy)]
pub struct SymmetricProblem<'a> {
    /// Stiffness (N/m), symmetric positive semi-definite.
    pub k: SparseRef<'a>,
    /// Mass (kg), symmetric positive definite.
    pub m: SparseRef<'a>,
}

/// Output of a [`SymmetricKernel`]: the largest eigenvalues of the shift-invert operator.
#[derive(Debug, Clone)]
pub struct KernelOutput {
    /// Converged operator eigenvalues `theta`, any order.
    pub theta: Vec<f64>,
    /// Matching eigenvectors (columns), any scaling.
    pub vectors: Mat<f64>,
    /// Restarts / iterations used.
    pub iterations: usize,
    /// Whether every requested pair converged.
    pub all_converged: bool,
}

/// A Krylov iteration for the `nev` largest eigenvalues of the `M`-self-adjoint
/// operator `OP = (K - sigma M)^-1 M`.
pub trait SymmetricKernel: Send + Sync {
    /// Computes the `nev` eigenpairs of largest `theta`.
    fn largest(
        &self,
        op: &ShiftInvert<'_>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<KernelOutput>;

    /// [`largest`](Self::largest) started from `start`: columns approximating the wanted
    /// eigenvectors (a nearby problem's, the largest `theta` first). The pairs must meet
    /// `tol` as from any start. The default ignores `start`.
    fn largest_from(
        &self,
        op: &ShiftInvert<'_>,
        start: MatRef<'_, f64>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<KernelOutput> {
        let _ = start;
        self.largest(op, nev, tol, max_restarts)
    }
}

/// Band driver shared by all symmetric backends: shift-invert below the spectrum,
/// run the kernel for `nev` pairs, grow `nev` until a converged mode lies above the
/// band top, then back-transform, `M`-normalize, compute residuals and sort.
pub fn solve_symmetric_band(
    solver: &str,
    kernel: &dyn SymmetricKernel,
    problem: &SymmetricProblem<'_>,
    params: &EigenParams,
) -> Result<RealModes> {
    let start = Instant::now();
    validate_params(params)?;
    if problem.k.nrows() == 0 {
        return Err(Error::Invalid("empty eigenproblem (no free DOFs)".into()));
    }
    let two_pi = 2.0 * std::f64::consts::PI;
    let shift_hz = params.shift_hz.unwrap_or(params.fmax_hz / 20.0).abs();
    let sigma = -(two_pi * shift_hz).powi(2);
    let op = ShiftInvert::new(problem.k, problem.m, sigma)?;
    band(solver, kernel, problem, &op, None, params, 1, start)
}

/// [`solve_symmetric_band`] on a shift-invert operator the caller factorized (its shift
/// replaces `params.shift_hz`; it must lie below the spectrum): no factorization here.
/// `start` (approximate modes, ascending frequency, best with the pairs above the band
/// a nearby solve found: [`RealModes::above_band`]; [`SymmetricKernel::largest_from`])
/// is where the kernel starts; the first call asks for as many pairs as it has columns
/// (or `params.nev_hint` when that is more), so that no wanted pair starts from nothing,
/// and grows like any other when they all lie below the band top.
pub fn solve_symmetric_band_on(
    solver: &str,
    kernel: &dyn SymmetricKernel,
    problem: &SymmetricProblem<'_>,
    op: &ShiftInvert<'_>,
    start_modes: Option<MatRef<'_, f64>>,
    params: &EigenParams,
) -> Result<RealModes> {
    let start = Instant::now();
    validate_params(params)?;
    let n = problem.k.nrows();
    if n == 0 {
        return Err(Error::Invalid("empty eigenproblem (no free DOFs)".into()));
    }
    if op.dim() != n {
        return Err(Error::Dimension {
            context: "symmetric band: the shift-invert operator's size".into(),
            expected: n,
            got: op.dim(),
        });
    }
    if let Some(s) = start_modes {
        if s.nrows() != n {
            return Err(Error::Dimension {
                context: "symmetric band: the start modes' rows".into(),
                expected: n,
                got: s.nrows(),
            });
        }
    }
    band(solver, kernel, problem, op, start_modes, params, 0, start)
}

/// The band driver's iteration on the factorized `op` (`factorizations` made for it),
/// from `start_modes` when given.
#[allow(clippy::too_many_arguments)]
fn band(
    solver: &str,
    kernel: &dyn SymmetricKernel,
    problem: &SymmetricProblem<'_>,
    op: &ShiftInvert<'_>,
    start_modes: Option<MatRef<'_, f64>>,
    params: &EigenParams,
    factorizations: usize,
    start: Instant,
) -> Result<RealModes> {
    let n = problem.k.nrows();
    let two_pi = 2.0 * std::f64::consts::PI;
    let sigma = op.shift();
    let mut info = SolveInfo {
        factorizations,
        ..SolveInfo::new(solver)
    };
    let top = (two_pi * params.fmax_hz).powi(2);

    let (omega2, vectors) = if n <= params.dense_below.max(2) {
        info.notes.push(format!(
            "n = {n} <= {}: solved densely instead of `{solver}`",
            params.dense_below
        ));
        dense_symmetric(problem)?
    } else {
        let seeded = start_modes.map_or(0, |s| s.ncols());
        // a start of `seeded` columns holds the band and the pairs above it a nearby
        // solve found: as many pairs are asked for, so that none starts from nothing
        let mut nev = match (params.nev_hint, seeded) {
            (Some(hint), s) => hint.max(s),
            (None, 0) => 24,
            (None, s) => s,
        }
        .clamp(1, n - 1);
        if seeded > 0 {
            info.notes
                .push(format!("started from {seeded} modes of a nearby problem"));
        }
        loop {
            let out = match start_modes {
                Some(s) if s.ncols() > 0 => {
                    kernel.largest_from(op, s, nev, params.tol, params.max_restarts)?
                }
                _ => kernel.largest(op, nev, params.tol, params.max_restarts)?,
            };
            info.iterations += out.iterations;
            info.requested = nev;
            info.converged = out.theta.len();
            if !out.all_converged {
                info.reason = StopReason::MaxIterations;
            }
            let lam: Vec<f64> = out.theta.iter().map(|&t| op.pencil_eigenvalue(t)).collect();
            let reached = lam.iter().any(|&l| l > top);
            if reached || nev >= n - 1 || !out.all_converged {
                if !reached && nev < n - 1 {
                    info.notes.push(format!(
                        "band top not reached: {} of {nev} pairs converged",
                        out.theta.len()
                    ));
                }
                break (lam, out.vectors);
            }
            let grown = grown_nev(nev, &lam, sigma, top).min(n - 1);
            if grown > params.max_modes {
                return Err(too_many_modes(params));
            }
            info.notes.push(format!(
                "{nev} pairs all below the band top; retried with {grown}"
            ));
            nev = grown;
        }
    };
    info.op_applications = op.applications();
    let mut modes = finish_real_modes(problem, &omega2, vectors.as_ref(), params, info);
    modes.info.time_s = start.elapsed().as_secs_f64();
    Ok(modes)
}

/// The number of pairs to ask for when the `nev` eigenvalues `lam` (all converged) lie
/// below the band top `top` (both `omega^2`, shift `sigma`): a count growing as
/// `N(omega^2) ~ (omega^2 - sigma)^(3/4)`, from the highest converged eigenvalue to the
/// band top with a 20 % margin, at least 1.5x and at most 4x `nev`. The exponent lies
/// between a plate's (1/2) and a 3D solid's Weyl law (3/2, which asked for 96 pairs where
/// the default rig's free model has 49 below 15 kHz: its first 24 reach 8.4 kHz, a growth
/// exponent of 0.61 between the two). A rerun starts Lanczos afresh, so asking for too few
/// costs a whole run while asking for too many costs a larger basis and, above
/// the block kernel's limit, the slower single-vector kernel.
fn grown_nev(nev: usize, lam: &[f64], sigma: f64, top: f64) -> usize {
    let highest = lam.iter().fold(f64::NEG_INFINITY, |a, &l| a.max(l));
    let lo = (3 * nev).div_ceil(2);
    let hi = 4 * nev;
    if !(highest.is_finite() && highest > sigma) {
        return hi;
    }
    let ratio = ((top - sigma) / (highest - sigma)).max(1.0);
    let estimate = (1.2 * nev as f64 * ratio.powf(0.75)).ceil();
    if estimate.is_finite() {
        (estimate as usize).clamp(lo, hi)
    } else {
        hi
    }
}

/// Most pairs above the band a solve keeps ([`RealModes::above_band`]): the lowest ones,
/// enough for the margin the band driver asks beyond the band (a dense solve has the
/// whole spectrum).
pub const ABOVE_BAND_KEPT: usize = 8;

/// Finishing step shared by every symmetric backend: keeps the pairs with
/// `omega^2 <= (2 pi fmax)^2` (and `>= (2 pi fmin)^2` when `fmin > 0`), `M`-normalizes the
/// vectors, computes the relative residuals (module docs) and sorts by frequency.
/// `info` is passed through unchanged (the caller sets `time_s`). The lowest pairs above
/// the band (at most [`ABOVE_BAND_KEPT`]) are kept as [`RealModes::above_band`].
pub fn finish_real_modes(
    problem: &SymmetricProblem<'_>,
    omega2_all: &[f64],
    vectors: faer::MatRef<'_, f64>,
    params: &EigenParams,
    info: SolveInfo,
) -> RealModes {
    let n = problem.k.nrows();
    let two_pi = 2.0 * std::f64::consts::PI;
    let top = (two_pi * params.fmax_hz).powi(2);
    let kn = norm1(problem.k);
    let mn = norm1(problem.m);
    let bottom = (two_pi * params.fmin_hz).powi(2);
    let mut keep: Vec<(f64, usize)> = omega2_all
        .iter()
        .enumerate()
        .filter(|(_, &l)| l <= top * (1.0 + 1e-12) && (params.fmin_hz <= 0.0 || l >= bottom))
        .map(|(i, &l)| (l, i))
        .collect();
    keep.sort_by(|a, b| a.0.total_cmp(&b.0));
    // M-normalization and residuals by two block products (K and M are symmetric, so
    // the gather products apply): one pass over each matrix for all the modes
    let mut out_vec = Mat::from_fn(n, keep.len(), |r, c| vectors[(r, keep[c].1)]);
    let mut mx = symmetric_times(problem.m, out_vec.as_ref());
    for c in 0..keep.len() {
        let scale = dot(col(&out_vec, c), col(&mx, c)).sqrt();
        if scale > 0.0 {
            out_vec.col_mut(c).iter_mut().for_each(|v| *v /= scale);
            mx.col_mut(c).iter_mut().for_each(|v| *v /= scale);
        }
    }
    let kx = symmetric_times(problem.k, out_vec.as_ref());
    let residuals: Vec<f64> = keep
        .iter()
        .enumerate()
        .map(|(c, &(l, _))| {
            let r: Vec<f64> = col(&kx, c)
                .iter()
                .zip(col(&mx, c))
                .map(|(a, b)| a - l * b)
                .collect();
            norm2(&r) / ((kn + l.abs() * mn) * norm2(col(&out_vec, c)))
        })
        .collect();
    let omega2: Vec<f64> = keep.iter().map(|p| p.0).collect();
    let freq_hz = omega2.iter().map(|&l| l.max(0.0).sqrt() / two_pi).collect();
    // the pairs above the band, unit M norm: a nearby problem's start
    let mut above: Vec<(f64, usize)> = omega2_all
        .iter()
        .enumerate()
        .filter(|(_, &l)| l > top * (1.0 + 1e-12))
        .map(|(i, &l)| (l, i))
        .collect();
    above.sort_by(|a, b| a.0.total_cmp(&b.0));
    above.truncate(ABOVE_BAND_KEPT);
    let mut above_band = Mat::from_fn(n, above.len(), |r, c| vectors[(r, above[c].1)]);
    let m_above = symmetric_times(problem.m, above_band.as_ref());
    for c in 0..above.len() {
        let scale = dot(col(&above_band, c), col(&m_above, c)).sqrt();
        if scale > 0.0 {
            above_band.col_mut(c).iter_mut().for_each(|v| *v /= scale);
        }
    }
    RealModes {
        omega2,
        freq_hz,
        vectors: out_vec,
        residuals,
        info,
        above_band,
    }
}

/// Dense solution of the whole symmetric pencil (small problems and oracles):
/// `M = L L^T`, `L^-1 K L^-T y = lambda y`, `x = L^-T y`.
pub fn dense_symmetric(problem: &SymmetricProblem<'_>) -> Result<(Vec<f64>, Mat<f64>)> {
    dense_symmetric_pencil(problem.k.to_dense().as_ref(), problem.m.to_dense().as_ref())
}

/// [`dense_symmetric`] of a dense pencil `(K, M)` (a Rayleigh-Ritz step's projected
/// matrices): eigenvalues ascending, eigenvectors `M`-orthonormal.
pub fn dense_symmetric_pencil(
    k: MatRef<'_, f64>,
    m: MatRef<'_, f64>,
) -> Result<(Vec<f64>, Mat<f64>)> {
    let n = k.nrows();
    let llt = m.llt(faer::Side::Lower).map_err(|e| Error::Factorization {
        what: "M (dense)".into(),
        reason: format!(
            "{}: the mass matrix must be positive definite",
            crate::linalg::explain::llt(&e, n)
        ),
    })?;
    let l = llt.L().to_owned();
    // A = L^-1 K L^-T
    let mut a = k.to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(
        l.as_ref(),
        a.as_mut(),
        faer::Par::Seq,
    );
    let mut at = a.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(
        l.as_ref(),
        at.as_mut(),
        faer::Par::Seq,
    );
    // Scale to unit largest entry: faer's divide-and-conquer path (n > 128) returned
    // wrong pairs for entries of order 1e13 (seen on a free block, faer 0.24.4).
    let scale = (0..n)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .fold(0.0f64, |a, (i, j)| a.max(at[(i, j)].abs()))
        .max(f64::MIN_POSITIVE);
    let sym = (&at + at.transpose()) * faer::Scale(0.5 / scale);
    let eig = sym
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| Error::Invalid(format!("dense symmetric eigen failed: {e:?}")))?;
    let s = eig.S();
    let lam: Vec<f64> = (0..n).map(|i| s[i] * scale).collect();
    let mut x = eig.U().to_owned();
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        l.transpose(),
        x.as_mut(),
        faer::Par::Seq,
    );
    Ok((lam, x))
}

#[cfg(test)]
mod tests {
    use super::grown_nev;

    fn w2(f_hz: f64) -> f64 {
        (2.0 * std::f64::consts::PI * f_hz).powi(2)
    }

    #[test]
    fn grown_nev_extrapolates_the_count_within_bounds() {
        let sigma = -w2(750.0);
        let top = w2(15_000.0);
        // the highest converged mode near the top: the smallest growth
        assert_eq!(grown_nev(24, &[w2(100.0), w2(14_900.0)], sigma, top), 36);
        // two thirds of the way in frequency: (1.5^2)^0.75 = 1.84, times 1.2
        let mid = grown_nev(24, &[w2(10_000.0)], sigma, top);
        assert!((50..=56).contains(&mid), "{mid}");
        // the default rig's free model: 24 pairs up to 8382 Hz, 49 below 15 kHz
        let rig = grown_nev(24, &[w2(717.0), w2(8_382.0)], sigma, top);
        assert!((49..=72).contains(&rig), "{rig}");
        // far below the top: capped at 4x
        assert_eq!(grown_nev(24, &[w2(1_000.0)], sigma, top), 96);
        // no usable eigenvalue: the cap
        assert_eq!(grown_nev(10, &[], sigma, top), 40);
        assert_eq!(grown_nev(10, &[f64::NAN], sigma, top), 40);
        // more converged modes never ask for fewer
        let a = grown_nev(24, &[w2(12_000.0)], sigma, top);
        let b = grown_nev(24, &[w2(9_000.0)], sigma, top);
        assert!(b >= a, "{a} {b}");
    }
}
