//! First versions of the contact-side plugin traits: [`ContactLaw`],
//! [`EquilibriumSolver`] and [`ReductionBasis`], with the data they exchange.
//!
//! Conventions: row `i` of `Pn` carries `+n_i` on the pin node and
//! `-n_i` on the disc node of pair `i` (a positive value opens the gap); `Pt` the same with
//! the sliding direction `e_i`. `Rn >= 0` is compressive and the friction `mu Rn` drags
//! the pin along `+e_i`. The static sliding equilibrium solves
//! `K U = F + (Pn + mu Pt)^T Rn`, `0 <= Rn ⟂ g0 + Pn U >= 0`.

mod basis;
mod condensation;
mod equilibrium;
mod law;
mod lcp;
mod stage;

pub use basis::{build_basis, Basis, BasisRequest, ImplicitColumns, ReductionBasis, Seed};
pub use condensation::{add_transpose_times, Condensation};
pub use equilibrium::{check_mu, ContactProblem, Equilibrium, EquilibriumSolver};
pub use law::ContactLaw;
pub use lcp::{solve_lcp, LcpSolution};
pub use stage::{FreeModel, ModelStage, NormalModes, PairDofs};
