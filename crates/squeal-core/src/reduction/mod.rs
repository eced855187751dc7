//! Shared machinery of the reduction bases, written once and used
//! by every [`ReductionBasis`](crate::ReductionBasis):
//!
//! - `M_c`-orthonormalization with a rank cut ([`m_orthonormalize`],
//!   [`m_orthonormal_extend`]) and an optional SVD compression ([`m_svd_compress`]);
//! - the coupled mu = 0 real modes ([`coupled_real_modes`]), the friction load directions
//!   ([`friction_load_directions`]) and static responses with one reused factorization
//!   ([`StaticSolver`]), which the real modes can share ([`coupled_real_modes_on`]), or
//!   solves with any contact set's `K_c` through one factorization of the free model
//!   ([`PairSolves`], a model stage), and the model's static space, in which every
//!   contact set's static responses are coordinates and a basis of them stays implicit
//!   ([`StaticSpace`]);
//! - projection of every part of a [`FrictionalOperator`](crate::operator::FrictionalOperator) on a basis ([`project`]), or of a
//!   basis grown column by column with the images of its columns kept ([`GrowingBasis`]), the
//!   reduced solve with any [`EigenSolver`](crate::EigenSolver), and the expansion of the reduced modes with
//!   their backward errors on the FULL operator ([`ReducedOperator`], [`solve_reduced`]);
//! - the MAC between a real and a complex mode ([`mac_real_complex`]).
//!
//! ## Orthonormalization
//! Columns are first scaled to unit `M_c` norm (so badly scaled static responses, e.g.
//! `K^-1 f` of order 1e-9 m next to modes of unit modal mass, are judged on their
//! direction only), then orthonormalized by block classical Gram-Schmidt with
//! re-orthogonalization (every projection done twice, "twice is enough"; a column that
//! lost more than 90 % of its norm inside its block gets a third pass against every
//! kept column) in the `M_c` inner product: a QR factorization in that inner product.
//! Inside a block of 32 columns the same is done recursively (left half, right half
//! projected on what the left half kept, right half; four columns at a time one by one),
//! so each column of the block is read a logarithmic number of times. A
//! unit column whose component outside the span of the columns kept before it has an
//! `M_c` norm below `rank_tol` (the sine of its angle to that span) is dropped and
//! counted. The Gram matrix `V^T M V` is never diagonalized: its eigenvalues are the
//! squares of the singular values, so a relative cut at `tol` on them silently drops
//! directions of relative size `sqrt(tol)`, precisely the static vectors nearly parallel
//! to a mode.
//!
//! ## Reduced solve
//! `V^T X V` for each part `X` in {`M_c`, `C_c`, `K_c`, `F_M`, `F_C`, `F_K`} (the friction
//! parts have `4 nA` nonzero rows, so their projection is cheap), a dense-backed
//! [`FrictionalOperator`](crate::operator::FrictionalOperator) with `t: None`, solved by any [`EigenSolver`](crate::EigenSolver) (normally `dense`)
//! at each mu; the modes `u_c = V q` are finished by [`finish_operator_modes`](crate::qep::finish_operator_modes) on the
//! parts of `op.at(mu)`, so their backward errors are those of the full problem. When the
//! reduced solver returns left eigenvectors `p`, they are expanded the same way
//! (`y = V p`) and give each mode a condition number and a forward error estimate on the
//! full problem ([`finish_operator_modes_with_left`](crate::qep::finish_operator_modes_with_left); see the `qep::condition` module
//! docs for the limits of this Galerkin left vector).

pub use crate::linalg::sparse_times;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};

mod candidates;
mod energy;
mod growing;
mod mac;
mod modal;
mod orthonormal;
mod project;
mod seed;
mod solve;
mod static_space;
mod statics;
#[cfg(test)]
mod tests;
mod tied;

pub use crate::linalg::expand;
pub use candidates::{
    coupled_real_modes, coupled_real_modes_on, friction_load_directions, real_modes_cost,
    real_modes_seed,
};
pub use energy::{energy_bounds, energy_bounds_on, EnergyWeight};
pub use growing::GrowingBasis;
pub use mac::mac_real_complex;
pub use modal::{real_mode_pair, symmetric_part, PairRef};
pub use orthonormal::{
    m_orthonormal_extend, m_orthonormal_extend_imaged, m_orthonormality_error, m_orthonormalize,
    m_svd_compress, DEFAULT_RANK_TOL,
};
pub use project::{dense_to_sparse, project};
pub use seed::{from_free_dofs, to_free_dofs};
pub use solve::{solve_reduced, ReducedOperator, ReducedSolve};
pub use static_space::{StaticBasis, StaticColumns, StaticSpace};
pub use statics::{energy_residuals, StaticSolver};
pub use tied::{PairSolves, TiedSolve, PAIR_SOLVES_LIMIT_BYTES, PAIR_SOLVES_STAGE_KEY};

fn par() -> Par {
    faer::get_global_parallelism()
}

/// `A^T B` for dense matrices.
fn tmul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut c = Mat::<f64>::zeros(a.ncols(), b.ncols());
    if a.nrows() > 0 {
        matmul(c.as_mut(), Accum::Replace, a.transpose(), b, 1.0, par());
    }
    c
}
