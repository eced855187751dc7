//! The error type of squeal-core, shared by the plugins through [`Error::Backend`].

use thiserror::Error;

/// Result with the core [`Error`](enum@Error).
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong at the level of the core contracts.
#[derive(Debug, Error)]
pub enum Error {
    /// A parameter is missing, has the wrong type or an invalid value.
    #[error("parameter `{name}`: {reason}")]
    Param {
        /// The parameter name as the user wrote it.
        name: String,
        /// What is expected.
        reason: String,
    },
    /// A material's constants do not describe a valid elastic law.
    #[error("material `{material}`: {field} = {value}: {expected}")]
    Material {
        /// Plugin name of the material.
        material: String,
        /// The offending constant.
        field: String,
        /// Its value.
        value: f64,
        /// What would be valid.
        expected: String,
    },
    /// No plugin of that kind is registered under that name.
    #[error("unknown {kind} plugin `{name}`; registered: {available}")]
    UnknownPlugin {
        /// Plugin kind ("eigen", "material", ...).
        kind: &'static str,
        /// The name asked for.
        name: String,
        /// Comma separated list of what is registered.
        available: String,
    },
    /// Matrices or vectors with incompatible sizes.
    #[error("dimension mismatch in {context}: expected {expected}, got {got}")]
    Dimension {
        /// Where it happened.
        context: String,
        /// Expected size.
        expected: usize,
        /// Actual size.
        got: usize,
    },
    /// A sparse factorization failed (not positive definite, singular, out of memory).
    #[error("factorization of {what} failed: {reason}")]
    Factorization {
        /// Which matrix.
        what: String,
        /// Why.
        reason: String,
    },
    /// The plugin does not implement this operation.
    #[error("`{plugin}` does not support {operation}")]
    Unsupported {
        /// Plugin name.
        plugin: String,
        /// The operation asked for.
        operation: String,
    },
    /// An iterative method stopped without meeting its tolerance.
    #[error("{method} did not converge after {iterations} iterations: {detail}")]
    NotConverged {
        /// Method name.
        method: String,
        /// Iterations performed.
        iterations: usize,
        /// Last residuals or other diagnostics.
        detail: String,
    },
    /// Invalid input data (a matrix with NaN, an empty problem...).
    #[error("invalid input: {0}")]
    Invalid(String),
    /// An error raised by a backend plugin (ARPACK codes, out-of-tree plugins).
    #[error(transparent)]
    Backend(#[from] Box<dyn std::error::Error + Send + Sync>),
}

impl Error {
    /// Shorthand for a [`Error::Param`].
    pub fn param(name: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Param {
            name: name.into(),
            reason: reason.into(),
        }
    }
}
