//! Long studies over contact zones: the paper's macroscopic effective zones (section 3.1,
//! a rectangle `(x0, y0, a, b)` on the pin face) and mesoscopic plateau layouts (section
//! 3.2, seeded random patches inside a fixed region).
//!
//! **Cases.** A study is a [`StudyDef`] (what to run: the zone grid or the plateau
//! layouts, friction coefficients, methods, the model's contact grid) from which
//! [`StudyDef::cases`] derives the case list, a pure function of the definition: each
//! [`Case`] has a stable id built from its parameters (`mu03600-x004000-y002900-a012000-b014200`:
//! mu to 1e-4, lengths in um; `mu03600-p000400-l00017` for patch 0.4 mm, layout 17), and
//! the list is sorted by id. Zones that do not fit in the pin face, and zones or layouts
//! that hold no contact pair, are skipped and counted.
//!
//! **Physics of a case.** Every pair of the zone is closed and sliding (no equilibrium
//! solve): the contact set is built on the zone directly and the frictional operator on
//! all its pairs, on a model built once for the whole study; the modes come from a
//! [`Method`](crate::pipeline::Method) (a reduction basis and an eigen solver, or full order).
//!
//! **Records.** Each finished case is appended at once to `results.jsonl` (one
//! [`Record`] a line) and its wall times to `timings.jsonl` (one [`Timing`] a line): a
//! killed run loses nothing, and a resumed run skips the ids already there. Records hold no
//! times, so `results.jsonl` (rewritten sorted by id when a run ends) and `summary.json`
//! are pure functions of the definition: a resumed run, a run with any number of jobs, or
//! shards merged by [`merge`] give them byte for byte. Times live in `timings.jsonl` and
//! `timings.json`.

use crate::pipeline::PipelineError;
use std::path::{Path, PathBuf};
use thiserror::Error;

mod cases;
mod dir;
mod input;
mod run;
mod spec;
mod summary;
#[cfg(test)]
mod tests;

pub use cases::derive_seed;
pub use dir::{merge, StudyDir};
pub use input::{parse_list, parse_region, Axis, Shard};
pub use run::{run, run_case, Progress, Record, RunOptions, RunReport, Timing, UnstableMode};
pub use spec::{
    Case, CaseList, GridInfo, MacroSpec, MesoSpec, Skipped, SolveSpec, StudyDef, StudySpec,
};
pub use summary::{
    summarize, wilson95, ClassSummary, GridSummary, MuSummary, PatchSummary, Summary, TimingSummary,
};

/// Errors of studies; each names the field, file or case concerned.
#[derive(Debug, Error)]
pub enum StudyError {
    /// A bad input, named by its field: `study.*` and `solve.*` of [`StudyDef`],
    /// `options.*` of [`RunOptions`], `dir`, `dirs` or `scene` (the `squeal` binary names
    /// the matching command-line options instead).
    #[error("{field}: {message}")]
    Input {
        /// The field, e.g. `study.patch_m`.
        field: String,
        /// What is wrong and what is expected.
        message: String,
    },
    /// A study directory that cannot be used.
    #[error("{}: {message}", .path.display())]
    Files {
        /// The file or directory.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The model or a method.
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
}

/// Result with [`StudyError`].
pub type Result<T> = std::result::Result<T, StudyError>;

pub(crate) fn input(field: &str, message: impl Into<String>) -> StudyError {
    StudyError::Input {
        field: field.into(),
        message: message.into(),
    }
}

pub(crate) fn files(path: &Path, message: impl std::fmt::Display) -> StudyError {
    StudyError::Files {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}
