//! # squeal
//!
//! Brake-squeal stability analysis: the facade crate. It re-exports the workspace crates
//! and builds the default [`Registry`] with every built-in plugin. Adding a method is one
//! crate under `plugins/` (exposing `pub fn register(reg: &mut Registry)`) plus its one
//! dependency line in the root `Cargo.toml`: the build script finds it there and
//! registers it.

pub use squeal_analysis as analysis;
pub use squeal_contact as contact;
pub use squeal_core as core;
pub use squeal_core::Registry;
pub use squeal_fe as fe;
pub use squeal_scene as scene;

include!(concat!(env!("OUT_DIR"), "/plugins.rs"));

/// The registry with every built-in plugin.
pub fn registry() -> Registry {
    let mut reg = Registry::new();
    register_plugins(&mut reg);
    reg
}
