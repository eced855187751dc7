//! # squeal-analysis
//!
//! What each `squeal` command does, as a library: the stability pipeline of a scene
//! ([`pipeline`]: model, contact, equilibrium, operator, complex modes), the
//! uniform-contact validation of the paper ([`validate`](mod@validate)), normal modes of
//! bodies ([`modal`]), equilibria ([`equilibria`]), automatic mode labels ([`labels`]) and
//! the paper's reference values ([`reference`](mod@reference)), method benchmarks
//! ([`bench`](mod@bench)), sweeps over mu or any parameter of an operator family
//! ([`sweep`], [`family`], [`mu_sweep`], [`param_sweep`]), long studies over contact zones
//! ([`study`]) and model updating ([`calibrate`]), with their output directories
//! ([`outdir`]), JSON-lines records ([`jsonl`]) and where their time went ([`profile`]);
//! real modes shared between the methods of a run ([`modal_cache`]). The CLI checks
//! options, prints progress and draws the charts.

pub mod bench;
pub mod calibrate;
pub mod equilibria;
pub mod family;
pub mod jsonl;
pub mod labels;
pub mod modal;
pub mod modal_cache;
pub mod mu_sweep;
pub mod num;
pub mod outdir;
pub mod param_sweep;
pub mod pipeline;
pub mod profile;
pub mod reference;
pub mod study;
pub mod sweep;
pub mod validate;
pub mod vtu;
