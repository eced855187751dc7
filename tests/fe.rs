//! Integration tests of the FE layer and the eigen solvers of `squeal`, one test binary:
//!
//! - `rigid`: a free distorted block has exactly six rigid-body modes, whatever the
//!   solver (dense oracle, `arpack`, `krylov`), and the right mass;
//! - `patch`: a distorted multi-element patch reproduces an affine displacement field
//!   exactly (isotropic and rotated transversely isotropic materials);
//! - `cantilever`: bending frequencies of a slender clamped beam against Euler-Bernoulli;
//! - `solvers_agree`: `arpack` and `krylov` agree on the default scene's disc, whose
//!   `n > 0` modes come in doublets;
//! - `ties`: a fine block tied to a coarse one acts as one body;
//! - `refine`: contact refinement by tied contact layers keeps the rig;
//! - `pin`: the pin assembly of the default scene has a handful of modes below 10 kHz.

#[path = "fe/common.rs"]
mod common;

#[path = "fe/rigid.rs"]
mod rigid;

#[path = "fe/patch.rs"]
mod patch;

#[path = "fe/cantilever.rs"]
mod cantilever;

#[path = "fe/solvers_agree.rs"]
mod solvers_agree;

#[path = "fe/pin.rs"]
mod pin;

#[path = "fe/ties.rs"]
mod ties;

#[path = "fe/refine.rs"]
mod refine;
