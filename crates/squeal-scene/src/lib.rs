//! # squeal-scene
//!
//! A scene is what a user writes to describe one study: bodies, their materials and
//! dimensions, and the mesh rule (TOML, SI units, documented in `docs/scenes.md`).
//! [`Scene::builtin`] gives the embedded default `pin-on-disc`; [`build`] turns a scene
//! into the smallest FE model that resolves its frequency band.

mod edit;
mod model;
mod spec;

pub use model::{
    build, element_size, line_cells, BodyKind, BodyStats, ContactGrid, Model, SizeRule,
};
pub use spec::{
    Clamp, ContactRefinement, ContactSpec, Damping, Disc, Flange, Hat, ImportedMesh, Load,
    MaterialSpec, MeshImport, MeshRule, Pin, Plate, Scene, Study, Zone, BUILTIN_SCENES,
};

use thiserror::Error;

/// Errors of scene reading and model building. Each names the file and the field.
#[derive(Debug, Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// Path.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// TOML syntax error, unknown field, wrong type.
    #[error("{file}: {message}")]
    Parse {
        /// Path (or `<builtin NAME>`).
        file: String,
        /// The parser's message (with line and key).
        message: String,
    },
    /// A field with an invalid value.
    #[error("{file}: field `{field}`: {message}")]
    Field {
        /// Path.
        file: String,
        /// Dotted field name, e.g. `disc.thickness_m`.
        field: String,
        /// What is expected.
        message: String,
    },
    /// An error from the core (materials, assembly).
    #[error("{file}: {context}: {source}")]
    Core {
        /// Path.
        file: String,
        /// What was being built.
        context: String,
        /// Cause.
        source: Box<squeal_core::Error>,
    },
}

/// Result with [`SceneError`].
pub type Result<T> = std::result::Result<T, SceneError>;
