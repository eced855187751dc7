//! Energy-norm error bounds of reduced modes ([`energy_bounds`]).
//!
//! The first-order error of an eigenvalue is `|y*^H r| / |y*^H Q'(lambda) x|`
//! (`r = Q(lambda) x` the residual, `y*` the left eigenvector). The bound every solve
//! carries, `error_bound = cond x backward error = ||y|| ||r|| / (|lambda| |y^H Q' x|)`,
//! replaces `|y^H r|` by the Euclidean Cauchy-Schwarz product `||y|| ||r||`. For the
//! modes of a reduction basis on a finite element model that product is loose by orders
//! of magnitude: the residual of a Ritz vector lives in stiff, short-wavelength
//! directions a low mode hardly touches (on the coarse rig, 10^2 to 10^4 above the actual
//! error, `docs/error-estimate.md`). The same inequality in the energy inner product of
//! a symmetric positive definite `W`, `|y^H r| <= ||y||_W ||r||_{W^-1}`, weighs each by
//! its stiffness:
//!
//! `bound_W = ||y||_W ||r||_{W^-1} / (|lambda| |y^H Q'(lambda) x|)`,
//!
//! a first-order bound like the Euclidean one (exact left vector replaced by the computed
//! one in both), and 5 to 30 times smaller on the coarse rig, still above the actual
//! error of every mode there. Two weights, both without a factorization of their own:
//!
//! - a scene's operator: `W^-1 = (T D^-1)^T K^-1 (T D^-1)` with the free model's factor
//!   of `K` (the model stage's), `T` the operator's index map and `D = T^T T` (1 or 2 per
//!   constrained DOF): a constrained residual `r` is lifted to the free DOFs as
//!   `T D^-1 r` (so `T^T` of the lift is `r`), and `||y||_W^2 = y^H K_c y` with
//!   `K_c = T^T K T`;
//! - an operator read from files: `W = K_s`, its real-mode pair's stiffness
//!   ([`super::real_mode_pair`]), factorized once and kept with the pair.
//!
//! Only the modes whose class the Euclidean bound leaves open get one (a real part within
//! that bound and above the round-off that no bound resolves): two solves each.

use super::real_mode_pair;
use crate::linalg::{spmv, Cholesky};
use crate::operator::{ComplexModes, FrictionalOperator, RealModePair, BACKWARD_ERROR_FLOOR};
use crate::qep::residuals_and_derivatives;
use crate::{c64, Error, Result};
use faer::Mat;
use std::sync::Arc;

/// The symmetric positive definite weight of [`energy_bounds`].
#[derive(Clone, Copy)]
pub enum EnergyWeight<'a> {
    /// The free model's factor of `K` (a scene's operator, with its index map `T`).
    FreeModel(&'a Cholesky),
    /// The operator's real-mode pair (an operator read from files).
    Pair,
}

/// [`energy_bounds`] of the modes solved at `mu` on a reduction basis of `op`, in the
/// weight there is: `free_factor`, the free model's factor that the basis's model stage
/// holds ([`ReductionBasis::stage_factor`](crate::contact::ReductionBasis::stage_factor)),
/// else the real-mode pair of an operator read from files; none (the Euclidean bounds
/// stay) for a scene's operator without a free factor.
///
/// # Errors
/// As [`energy_bounds`].
pub fn energy_bounds_on(
    free_factor: Option<&Cholesky>,
    op: &FrictionalOperator,
    mu: f64,
    modes: &mut ComplexModes,
) -> Result<usize> {
    match (free_factor, &op.modal) {
        (Some(f), _) => energy_bounds(op, mu, modes, EnergyWeight::FreeModel(f)),
        (None, RealModePair::Lazy(_)) => energy_bounds(op, mu, modes, EnergyWeight::Pair),
        (None, RealModePair::Own) => Ok(0),
    }
}

/// `sqrt(z^H A z)` of a complex vector with a real symmetric `A`.
fn a_norm(a: crate::SparseRef<'_>, z: &[c64]) -> f64 {
    let n = z.len();
    let mut y = vec![0.0; n];
    let mut sum = 0.0;
    for part in [|v: &c64| v.re, |v: &c64| v.im] {
        let p: Vec<f64> = z.iter().map(part).collect();
        spmv(a, &p, &mut y);
        sum += p.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>();
    }
    sum.max(0.0).sqrt()
}

/// `sqrt(z^H A^-1 z)` by a factor of `A`.
fn inverse_norm(factor: &Cholesky, z: &[c64]) -> f64 {
    let mut sum = 0.0;
    for part in [|v: &c64| v.re, |v: &c64| v.im] {
        let p: Vec<f64> = z.iter().map(part).collect();
        let mut s = p.clone();
        factor.solve_vec_in_place(&mut s);
        sum += p.iter().zip(&s).map(|(a, b)| a * b).sum::<f64>();
    }
    sum.max(0.0).sqrt()
}

/// The factor of the real-mode pair's `K_s`, built once and kept with the pair.
fn pair_factor(op: &FrictionalOperator) -> Result<Arc<Cholesky>> {
    let pair = real_mode_pair(op)?;
    let build = || {
        Cholesky::new(pair.k, "K_s of the real-mode pair (energy norm)")
            .map(Arc::new)
            .map_err(|e| e.to_string())
    };
    match &op.modal {
        RealModePair::Lazy(lazy) => lazy
            .factor
            .get_or_init(build)
            .clone()
            .map_err(Error::Invalid),
        RealModePair::Own => build().map_err(Error::Invalid),
    }
}

/// Tightens the `error_bound` of the modes of a reduced solve of `op` at `mu` (with left
/// vectors) whose class the Euclidean bound leaves open, by the energy-norm bound of the
/// module docs in the weight `weight`; returns how many modes got one (noted in the
/// modes' report). A weight that does not fit the operator (a free factor of another
/// size, or no index map) leaves the modes as they are.
///
/// # Errors
/// A failed factorization of the pair's stiffness.
pub fn energy_bounds(
    op: &FrictionalOperator,
    mu: f64,
    modes: &mut ComplexModes,
    weight: EnergyWeight<'_>,
) -> Result<usize> {
    let Some(y) = modes.left_vectors.as_ref() else {
        return Ok(0);
    };
    let n = op.dim();
    if modes.vectors.nrows() != n || y.nrows() != n {
        return Ok(0);
    }
    // a real part below `cond x BACKWARD_ERROR_FLOOR x |lambda|` stays neutral whatever
    // the bound (round-off, `classify`): no solve for it
    let open: Vec<usize> = (0..modes.len())
        .filter(|&j| {
            let (l, b, c) = (modes.lambda[j], modes.error_bound[j], modes.cond[j]);
            let re = l.re.abs();
            b.is_finite() && re <= b * l.norm() && re > c * BACKWARD_ERROR_FLOOR * l.norm()
        })
        .collect();
    if open.is_empty() {
        return Ok(0);
    }
    let t = std::time::Instant::now();
    let pair_factor = match weight {
        EnergyWeight::Pair => Some(pair_factor(op)?),
        EnergyWeight::FreeModel(_) => None,
    };
    // the lift T D^-1 of a constrained vector, for the free model's factor
    let lift = |z: &[c64], map: &[usize], mult: &[f64]| -> Vec<c64> {
        map.iter().map(|&c| z[c] / mult[c]).collect()
    };
    let mult: Option<Vec<f64>> = match (weight, &op.t) {
        (EnergyWeight::FreeModel(f), Some(map)) if f.dim() == map.len() => {
            let mut m = vec![0.0; n];
            map.iter().for_each(|&c| m[c] += 1.0);
            Some(m)
        }
        (EnergyWeight::FreeModel(_), _) => return Ok(0),
        _ => None,
    };
    let pair = real_mode_pair(op)?;
    let x = Mat::from_fn(n, open.len(), |i, k| modes.vectors[(i, open[k])]);
    let lambda: Vec<c64> = open.iter().map(|&j| modes.lambda[j]).collect();
    let (r, dx) = residuals_and_derivatives(op, mu, &lambda, x.as_ref());
    for (k, &j) in open.iter().enumerate() {
        let l = lambda[k];
        let yj: Vec<c64> = (0..n).map(|i| y[(i, j)]).collect();
        let rk: Vec<c64> = (0..n).map(|i| r[(i, k)]).collect();
        let yqx: c64 = (0..n).map(|i| yj[i].conj() * dx[(i, k)]).sum();
        let (ny, nr) = match (weight, &mult) {
            (EnergyWeight::FreeModel(f), Some(m)) => {
                let map = op.t.as_deref().expect("checked above");
                (
                    a_norm(op.kc.as_ref(), &yj),
                    inverse_norm(f, &lift(&rk, map, m)),
                )
            }
            _ => (
                a_norm(pair.k, &yj),
                inverse_norm(pair_factor.as_deref().expect("built above"), &rk),
            ),
        };
        let bound = ny * nr / (l.norm() * yqx.norm());
        if bound.is_finite() && bound < modes.error_bound[j] {
            modes.error_bound[j] = bound;
        }
    }
    let done = open.len();
    modes.info.notes.push(format!(
        "error_bound in the energy norm of {} for the {done} of {} modes whose class the \
         Euclidean bound left open, {:.3} s",
        match weight {
            EnergyWeight::FreeModel(_) => "the free model's stiffness",
            EnergyWeight::Pair => "the real-mode pair's stiffness",
        },
        modes.len(),
        t.elapsed().as_secs_f64()
    ));
    Ok(done)
}
