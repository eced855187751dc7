//! Solid finite elements.
pub mod hex8;
