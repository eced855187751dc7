//! The low-rank (Woodbury) shift-invert of an undamped frictional operator.
//!
//! For `C = 0` the squared transformation of the band driver needs solves with
//!
//! ```text
//! A(s) = K~ - s M~ = S(s) - mu (F_K - s F_M),     S(s) = K_c - s M_c,
//! F_K - s F_M = U W(s)^T,                          W(s) = W_K - s W_M,
//! ```
//!
//! where `S(s)` is real symmetric (indefinite for `s` inside the spectrum) and
//! `U = T^T P~t^T` ([`FrictionalOperator::friction_loads`](crate::operator::FrictionalOperator::friction_loads), `n x nA`) has one column per
//! active pair. Every column of `U` is supported on DOFs of its own pair only, so the row
//! `r` of the largest `|U_ri|` gives `w_i^T = F_X[r, :] / U[r, i]` ([`FrictionLowRank`]).
//!
//! `S(s)` is factorized once per shift by faer's supernodal Bunch-Kaufman `L B L^T`
//! (pivoting within supernodes, [`SymmetricShift`]) and, with `Z = S^-1 U` (`nA` solves)
//! and the small dense LU of `G = I - mu W^T Z`, the Woodbury identity gives
//!
//! ```text
//! A^-1 b = S^-1 b + mu Z G^-1 W^T S^-1 b
//! ```
//!
//! ([`Woodbury`]): one symmetric solve and two thin dense products per
//! application. `S(s)`, its factorization, `W(s)` and `Z` depend on `s` only, not on
//! `mu`: a [`SymmetricShift`] is `Arc`-shareable across friction coefficients.
//!
//! Memory: the symmetric factor plus the dense `n x nA` block `Z` (no non-symmetric LU).

mod friction;
mod pencil;
mod shift;
mod woodbury;

pub use friction::{FrictionLowRank, MAX_IDENTITY_ERROR};
pub use pencil::{SymmetricPencil, MAX_ASYMMETRY};
pub use shift::SymmetricShift;
pub use woodbury::{Woodbury, REFINE_ABOVE};
