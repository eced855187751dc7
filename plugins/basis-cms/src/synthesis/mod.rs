//! Free-interface modal synthesis with residual flexibility (MacNeal) for a family of
//! contact sets drawn from one set of candidate pairs: the model stage of the `cms`
//! basis, built once per model and region and then reused for every contact set and mu.
//!
//! For the active pairs `A` the linearized problem is the descriptor system
//! `(lambda^2 M + K) u = B_A^T r`, `Pn_A u = 0`, `B_A = Pn_A + mu Pt_A`
//! (undamped). With the free-interface modes `Phi` of the unconstrained model
//! (no pair tied: `K Phi = M Phi Omega^2`, `Phi^T M Phi = I`) up to a cutoff, and the
//! residual flexibility `G = K^-1 - Phi Omega^-2 Phi^T` taken at `lambda = 0`,
//!
//! `u = Phi eta + G B_A^T r`, `(lambda^2 + Omega^2) eta = Phi^T B_A^T r`.
//!
//! The ties give `r = -S^-1 P eta` with `S = Pn_A G B_A^T` (`nA x nA`) and `P = Pn_A Phi`,
//! hence the `m x m` standard eigenproblem `lambda^2 eta = -(Omega^2 + Q^T S^-1 P) eta`,
//! `Q = B_A Phi`, whatever the number of pairs. The residual contact flexibilities
//! `Pn G Pn^T`, `Pn G Pt^T` of the candidate pairs are computed once (one Cholesky
//! factorization of `K`, kept, and `2 nR` solves whose pair rows alone are kept, so the
//! memory is `O(nR^2)`, not `O(n nR)`; the whole responses `K^-1 (Pn^T | Pt^T)` are stored
//! too when they fit [`STORE_LIMIT_BYTES`], and their second-order terms when both fit
//! [`STORE_SECOND_LIMIT_BYTES`]): a new contact
//! set or mu then costs one `nA x nA` LU, one `m x m` eigen decomposition and the
//! expansion `u = Phi (eta - Omega^-2 Q^T r) + K^-1 B_A^T r` (products with the stored
//! responses, or block solves for the modes expanded), which satisfies `Pn_A u = 0`
//! exactly.
//!
//! The residual flexibility is static (its inertia is neglected), so the synthesized modes
//! are approximations whose error falls with the ratio of the band to the modal cutoff;
//! the `cms` basis uses them as Ritz vectors of the exact operator of the contact set, so
//! every returned mode still carries its backward error on the full operator.
//!
//! Normals are `+e_z` (flat disc face), as in the operator builder.

use squeal_core::faer::{Mat, MatRef, Par};
use squeal_core::linalg::Cholesky;
use squeal_core::SparseMat;
use std::sync::Arc;

mod construct;
mod expand;
mod pairs;
mod synthesize;
#[cfg(test)]
mod tests;

pub use pairs::{PairColumns, PairsProjection, PAIR_MOMENTS_LIMIT_BYTES};
pub use squeal_core::PairDofs;
pub use synthesize::Synthesized;

/// The free-interface data of one model and one set of candidate pairs (see the module
/// docs): modes, static contact responses and residual contact flexibilities.
pub struct FreeInterface {
    pairs: Vec<PairDofs>,
    phi: Arc<Mat<f64>>,
    omega2: Vec<f64>,
    /// Cholesky factor of `K`: the static responses `K^-1 (Pn^T | Pt^T) r` of the
    /// expansion, solved for the modes expanded (when they are not stored).
    factor: Arc<Cholesky>,
    /// The static responses of every candidate pair, stored when they fit the memory
    /// limit: faster expansions, `4 n nR` values.
    stored: Option<Stored>,
    /// `M`, for the second-order residual terms `K^-1 M K^-1 (.)`.
    m: Arc<SparseMat>,
    /// The moments of the static responses on the pairs, when built: every contact set's
    /// projection is then assembled on the pairs ([`FreeInterface::project_on_pairs`]).
    moments: Option<pairs::PairMoments>,
    /// The gaps of the second-order terms, `Pn K^-1 M K^-1 Pn^T` and `Pn K^-1 M K^-1 Pt^T`
    /// (`nR x nR` each), when the responses are not stored: the second-order directions'
    /// static correction onto the ties is then known before their solve, which it joins
    /// (one block solve per expansion fewer).
    second_gaps: Option<[Mat<f64>; 2]>,
    /// Full static `Pn K^-1 Pn^T` (`nR x nR`, m/N).
    wfull: Mat<f64>,
    /// Residual `Pn G Pn^T` (`nR x nR`, m/N).
    wn: Mat<f64>,
    /// Residual `Pn G Pt^T` (`nR x nR`, m/N).
    wt: Mat<f64>,
    /// `Pn Phi`, `Pt Phi` (`nR x m`).
    pn_phi: Mat<f64>,
    pt_phi: Mat<f64>,
    /// Highest free-interface frequency kept (Hz).
    pub cutoff_hz: f64,
    /// Wall time of the construction, modes excluded (s).
    pub time_s: f64,
}

/// `K^-1 Pn^T`, `K^-1 Pt^T` and, when they fit too, the second-order terms
/// `K^-1 M K^-1 (Pn^T | Pt^T)` (`n x nR` each; `0 x 0` when not stored).
struct Stored {
    zn: Mat<f64>,
    zt: Mat<f64>,
    yn: Mat<f64>,
    yt: Mat<f64>,
}

impl Stored {
    /// Whether the second-order terms are stored.
    fn second_order(&self) -> bool {
        self.yn.nrows() > 0
    }
}

/// Largest memory (bytes) [`FreeInterface::new`] spends on stored static responses.
pub const STORE_LIMIT_BYTES: usize = 3 << 30;

/// Largest memory (bytes) of the stored static responses with their second-order terms
/// (`32 n nR` bytes). Above it the second-order terms are solved per expansion (one block
/// solve of the modes expanded): on the default rig's 441 pairs they would take 2.3 GiB,
/// more than the model and its factor of `K` together (1.3 GB).
pub const STORE_SECOND_LIMIT_BYTES: usize = 2 << 30;

/// Largest memory (bytes) of the second-order gaps kept when the responses are not
/// stored ([`FreeInterface::for_contact_sets`]; `16 nR^2` bytes: 0.35 GiB for 4,761
/// pairs).
pub const SECOND_GAPS_LIMIT_BYTES: usize = 1 << 30;

fn par() -> Par {
    squeal_core::faer::get_global_parallelism()
}

/// `Pn x`: the normal gaps of the pairs (pin minus disc), `nR x c`.
fn pn_rows(pairs: &[PairDofs], x: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(pairs.len(), x.ncols(), |i, c| {
        x[(pairs[i].pin[2], c)] - x[(pairs[i].disc[2], c)]
    })
}

/// `Pt x`: the sliding displacements of the pairs along their directions, `nR x c`.
fn pt_rows(pairs: &[PairDofs], x: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(pairs.len(), x.ncols(), |i, c| {
        let p = &pairs[i];
        (0..2)
            .map(|a| p.direction[a] * (x[(p.pin[a], c)] - x[(p.disc[a], c)]))
            .sum()
    })
}

/// Adds to column `c` of `x` the pair loads `Pn^T normal + Pt^T sliding` of pair `p`
/// (on the pin node, and opposite on the disc node).
fn add_pair_load(x: &mut Mat<f64>, p: &PairDofs, c: usize, normal: f64, sliding: f64) {
    x[(p.pin[2], c)] += normal;
    x[(p.disc[2], c)] -= normal;
    if sliding != 0.0 {
        for a in 0..2 {
            x[(p.pin[a], c)] += sliding * p.direction[a];
            x[(p.disc[a], c)] -= sliding * p.direction[a];
        }
    }
}
