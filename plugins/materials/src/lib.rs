//! (being written)
/// Registers the plugins of this crate.
pub fn register(_reg: &mut squeal_core::Registry) {}
