//! The vectors bases start from: the coupled mu = 0 real modes ([`coupled_real_modes`])
//! and the friction load directions ([`friction_load_directions`]).

use super::{from_free_dofs, real_mode_pair, sparse_times, to_free_dofs, StaticSolver};
use crate::contact::BasisRequest;
use crate::eigen::{EigenParams, SymmetricProblem};
use crate::linalg::hcat;
use crate::operator::{FrictionalOperator, RealModes};
use crate::{Error, Result};
use faer::Mat;

/// The coupled mu = 0 real modes of `(K_c, M_c)` from 0 to `cutoff_hz`, by
/// `request.modal` (tolerances from `request.params`): of the operator's real-mode pair
/// ([`real_mode_pair`]; `(K_c, M_c)` itself for a scene's operator), its shift undone
/// in the eigenvalues.
pub fn coupled_real_modes(request: &BasisRequest<'_>, cutoff_hz: f64) -> Result<RealModes> {
    real_modes(request, cutoff_hz, None)
}

/// [`coupled_real_modes`] on the factorization of a [`StaticSolver`] (`K_s + shift M_s`,
/// the shift-invert operator's `sigma = -shift`): a basis that needs both the real modes
/// and static responses factorizes once. A modal solver that does not work by
/// shift-invert ignores the factor. In a sweep the iteration starts from the previous
/// contact set's real modes (`request.seed`'s [`crate::Seed::real_modes`], brought to
/// this contact set by [`super::from_free_dofs`]); a basis hands its own on with
/// [`real_modes_seed`].
pub fn coupled_real_modes_on(
    request: &BasisRequest<'_>,
    cutoff_hz: f64,
    statics: &StaticSolver,
) -> Result<RealModes> {
    real_modes(request, cutoff_hz, Some(statics))
}

fn real_modes(
    request: &BasisRequest<'_>,
    cutoff_hz: f64,
    statics: Option<&StaticSolver>,
) -> Result<RealModes> {
    if !(cutoff_hz.is_finite() && cutoff_hz > 0.0) {
        return Err(Error::param(
            "cutoff",
            format!("cutoff frequency must be positive (Hz), got {cutoff_hz}"),
        ));
    }
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: cutoff_hz,
        nev_hint: None,
        ..request.params.clone()
    };
    let op = request.op;
    let pair = real_mode_pair(op)?;
    let params = EigenParams {
        fmax_hz: pair.shifted_cutoff_hz(cutoff_hz),
        ..params
    };
    let problem = SymmetricProblem {
        k: pair.k,
        m: pair.m,
    };
    let modes = match statics {
        Some(s) => {
            let si = s.shift_invert(problem.m)?;
            let start = request
                .seed
                .and_then(|seed| seed.real_modes.as_ref())
                .and_then(|w| from_free_dofs(op, w.as_ref()));
            request.modal.solve_symmetric_on(
                &problem,
                &si,
                start.as_ref().map(|s| s.as_ref()),
                &params,
            )
        }
        None => request.modal.solve_symmetric(&problem, &params),
    }?;
    Ok(pair.unshift(modes))
}

/// How a basis's real modes were found, for its note: the columns the shift-invert
/// operator was applied to and, when the solve started from a nearby contact set's
/// modes, that start.
pub fn real_modes_cost(modes: &RealModes) -> String {
    let started = modes
        .info
        .notes
        .iter()
        .find(|n| n.starts_with("started from"));
    format!(
        "{} applications of the shift-invert operator{}",
        modes.info.op_applications,
        started.map_or(String::new(), |n| format!(", {n}"))
    )
}

/// The real modes `modes` of the operator `op` as the next contact set's start
/// ([`crate::Seed::real_modes`]): the band's modes and the pairs above it the solve
/// found ([`RealModes::above_band`]), which the next solve needs converged too, on the
/// free model's DOFs ([`to_free_dofs`]); `None` when `op` has no index map or there
/// are no modes.
pub fn real_modes_seed(op: &FrictionalOperator, modes: &RealModes) -> Option<Mat<f64>> {
    let (band, above) = (&modes.vectors, &modes.above_band);
    if band.ncols() == 0 {
        return None;
    }
    if above.nrows() != band.nrows() {
        return to_free_dofs(op, band.as_ref());
    }
    to_free_dofs(op, hcat(band.as_ref(), above.as_ref()).as_ref())
}

/// The friction load directions `U = T^T P~t^T` as dense columns (`n_c x nA`). When the
/// operator does not carry them, their span is recovered from `F_K = U V_K^T`
/// (`range F_K = range U` when `V_K` has full column rank): `F_K Omega` for a fixed
/// pseudo-random `Omega` with as many columns as `F_K` has nonzero rows (an upper bound
/// of its rank); the rank cut of the orthonormalization removes the surplus.
pub fn friction_load_directions(op: &FrictionalOperator) -> Result<Mat<f64>> {
    let n = op.dim();
    if let Some(u) = &op.friction_loads {
        if u.nrows() != n {
            return Err(Error::Dimension {
                context: "friction load directions: rows".into(),
                expected: n,
                got: u.nrows(),
            });
        }
        return Ok(u.as_ref().to_dense());
    }
    let fk = op.fk.as_ref();
    let mut used = vec![false; n];
    for j in 0..n {
        for i in fk.row_idx_of_col(j) {
            used[i] = true;
        }
    }
    let p = used.iter().filter(|&&u| u).count();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let omega = Mat::from_fn(n, p, |_, _| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    });
    Ok(sparse_times(fk, omega.as_ref()))
}
