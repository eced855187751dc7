//! # squeal-fe
//!
//! Solid finite elements: structured hexahedral meshes ([`mesh`]), the 8-node hexahedron
//! with incompatible modes ([`hex8`]), DOF numbering with Dirichlet elimination
//! ([`dofs`]) and parallel sparse assembly ([`assembly`]). SI units.

pub mod assembly;
pub mod dofs;
pub mod hex8;
pub mod mesh;

pub use assembly::{assemble, Assembled};
pub use dofs::{DofMap, Tie};
pub use mesh::Mesh;
