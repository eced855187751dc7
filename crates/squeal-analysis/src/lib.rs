//! # squeal-analysis
//!
//! The analysis pipeline and its post-processing. For now: normal modes of a built
//! scene ([`modal`]), automatic mode labels ([`labels`]) and the paper's reference
//! values ([`reference`](mod@reference)).

pub mod labels;
pub mod modal;
pub mod reference;
