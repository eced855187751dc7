//! The model stage of a reduction basis: what a basis may compute once per model, before
//! any contact set, and reuse for every contact set and mu of a study.
//!
//! Every contact set of a study ties a subset of one list of candidate pairs on one free
//! (unconstrained) model. A basis that works from the free model (a modal synthesis, a
//! factorization on the pairs, precomputed snapshots) says so with
//! [`ReductionBasis::stage_key`](super::ReductionBasis::stage_key) and computes its data in
//! [`ReductionBasis::prepare`](super::ReductionBasis::prepare) from a [`FreeModel`]; the
//! caller builds that [`ModelStage`] once, keeps it as long as a later step needs it, and
//! hands it back in every [`BasisRequest::stage`](super::BasisRequest::stage). The stage's
//! type belongs to its plugin: the caller only stores it.

use crate::eigen::{EigenParams, EigenSolver};
use crate::linalg::Cholesky;
use crate::operator::RealModes;
use crate::{Result, SparseRef};
use std::any::Any;
use std::sync::Arc;

/// The DOFs of one candidate contact pair in the unconstrained (free) numbering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairDofs {
    /// Pin node DOFs (x, y, z).
    pub pin: [usize; 3],
    /// Disc node DOFs (x, y, z).
    pub disc: [usize; 3],
    /// Unit in-plane sliding direction `e_i` (the friction on the pin points along it).
    pub direction: [f64; 3],
}

/// The normal modes of the free model up to a frequency (Hz), computed once by the caller
/// and shared by every stage and step that asks (`fmax_hz -> modes`, sorted by frequency).
pub type NormalModes<'a> = dyn Fn(f64) -> Result<RealModes> + 'a;

/// The free model a basis prepares on (see the module docs).
pub struct FreeModel<'a> {
    /// Stiffness of the free model (no pair tied, supports applied), N/m.
    pub k: SparseRef<'a>,
    /// Mass of the free model, kg.
    pub m: SparseRef<'a>,
    /// The candidate pairs: every contact set of the study ties a subset of them.
    pub pairs: &'a [PairDofs],
    /// The caller's Cholesky factor of `K`, when it holds one (the contact condensation
    /// does): a stage that needs `K^-1` takes it instead of factoring `K` again.
    pub k_factor: Option<Arc<Cholesky>>,
    /// The free model's normal modes (from the caller's cache).
    pub normal_modes: &'a NormalModes<'a>,
    /// The symmetric sparse solver of the caller (for anything else the stage solves).
    pub modal: &'a dyn EigenSolver,
    /// Frequency band of the stability analysis `(fmin, fmax)` (Hz).
    pub band_hz: (f64, f64),
    /// The caller's tolerances and limits.
    pub params: &'a EigenParams,
    /// How many contact sets the caller will build on this stage, when it knows (a
    /// study's cases): a stage may then spend more once to spend less per contact set.
    /// `None` when unknown (one scene, a mu sweep).
    pub contact_sets: Option<usize>,
}

/// What a basis computed in its model stage, stored by the caller and handed back
/// unchanged; the plugin downcasts it to its own type.
pub type ModelStage = Arc<dyn Any + Send + Sync>;
