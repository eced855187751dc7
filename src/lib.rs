//! # squeal
//!
//! Brake-squeal stability analysis: the facade crate. It re-exports the workspace crates
//! and builds the default [`Registry`] with every built-in plugin. Adding a method is one
//! crate under `plugins/` plus one `register` line in [`registry`].

pub use squeal_analysis as analysis;
pub use squeal_contact as contact;
pub use squeal_core as core;
pub use squeal_core::Registry;
pub use squeal_fe as fe;
pub use squeal_scene as scene;

/// The registry with every built-in plugin.
pub fn registry() -> Registry {
    let mut reg = Registry::new();
    squeal_materials::register(&mut reg);
    squeal_contact_laws::register(&mut reg);
    squeal_equilibrium_lorang::register(&mut reg);
    squeal_equilibrium_lcp::register(&mut reg);
    squeal_eigen_arpack::register(&mut reg);
    squeal_eigen_krylov::register(&mut reg);
    squeal_eigen_dense::register(&mut reg);
    squeal_basis_modes::register(&mut reg);
    squeal_basis_enriched::register(&mut reg);
    squeal_basis_residue::register(&mut reg);
    squeal_basis_cms::register(&mut reg);
    reg
}
