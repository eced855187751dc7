//! # squeal-analysis
//!
//! The analysis pipeline and its post-processing: the stability pipeline of a scene
//! ([`pipeline`]: model, contact, equilibrium, operator, complex modes), normal modes of a
//! built scene ([`modal`]), automatic mode labels ([`labels`]) and the paper's reference
//! values ([`reference`](mod@reference)), method benchmarks ([`bench`](mod@bench)),
//! sweeps over mu or any parameter of an operator family ([`sweep`], [`family`],
//! [`mu_sweep`]) and long studies over contact zones ([`study`]), with their
//! JSON-lines records ([`jsonl`]) and where their time went ([`profile`]); real modes
//! shared between the methods of a run ([`modal_cache`]).

pub mod bench;
pub mod calibrate;
pub mod family;
pub mod jsonl;
pub mod labels;
pub mod modal;
pub mod modal_cache;
pub mod mu_sweep;
pub mod pipeline;
pub mod profile;
pub mod reference;
pub mod study;
pub mod sweep;
pub mod vtu;
