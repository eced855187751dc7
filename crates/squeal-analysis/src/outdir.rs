//! Output directories of the commands: creating one, the marker that says which command
//! wrote it (so one command never resumes or overwrites another's results), and the
//! errors of runs that write their results into a directory.

use crate::pipeline::PipelineError;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The file that names which command wrote an output directory.
pub const OUTPUT_MARKER: &str = "squeal-output.json";

/// Errors of a run that writes into an output directory; each names the file, directory
/// or input concerned.
#[derive(Debug, Error)]
pub enum RunError {
    /// A stage of the pipeline.
    #[error(transparent)]
    Pipeline(Box<PipelineError>),
    /// A stage of the pipeline, named.
    #[error("{stage}: {source}")]
    Stage {
        /// What was being done, e.g. `equilibrium at mu = 0.3 with `lcp``.
        stage: String,
        /// Cause.
        source: Box<PipelineError>,
    },
    /// An output directory that cannot be used (the message says why and what to do).
    #[error("{}: {message}", .path.display())]
    Dir {
        /// The directory.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A file that cannot be written.
    #[error("{}: {source}", .path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// A bad input value, named by its field.
    #[error("{field}: {message}")]
    Input {
        /// The input, e.g. `sweeps[0].step`.
        field: String,
        /// What is wrong and what is expected.
        message: String,
    },
    /// An output the caller draws (charts) failed.
    #[error("{0}")]
    Output(String),
}

impl From<PipelineError> for RunError {
    fn from(e: PipelineError) -> Self {
        Self::Pipeline(Box::new(e))
    }
}

impl RunError {
    /// A bad input `field`.
    pub fn input(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Input {
            field: field.into(),
            message: message.into(),
        }
    }
}

/// Names the stage of a pipeline error: `.map_err(stage("..."))`.
pub fn stage(stage: impl Into<String>) -> impl FnOnce(PipelineError) -> RunError {
    move |source| RunError::Stage {
        stage: stage.into(),
        source: Box::new(source),
    }
}

/// Writes `bytes` to `path`, naming the file on failure.
pub fn write(path: &Path, bytes: impl AsRef<[u8]>) -> Result<(), RunError> {
    std::fs::write(path, bytes).map_err(|source| RunError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Writes `value` as pretty JSON to `path`.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<(), RunError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| RunError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    })?;
    write(path, text)
}

/// Creates the output directory `out` (and its parents); refuses a path that is a file.
pub fn prepare(out: &Path) -> Result<(), RunError> {
    let dir = |message: String| RunError::Dir {
        path: out.to_path_buf(),
        message,
    };
    if out.exists() && !out.is_dir() {
        return Err(dir("is a file, expected a directory".into()));
    }
    std::fs::create_dir_all(out).map_err(|e| dir(format!("cannot create the directory ({e})")))
}

/// Claims `out` for `command`: creates it and records the command in its marker;
/// refuses a directory another command wrote (its marker, or a study's `study.json` / a
/// mu sweep's `sweep.partial.jsonl` from before markers existed).
pub fn claim(out: &Path, command: &str) -> Result<(), RunError> {
    prepare(out)?;
    let dir = |message: String| RunError::Dir {
        path: out.to_path_buf(),
        message,
    };
    let marker = out.join(OUTPUT_MARKER);
    let owner = if marker.is_file() {
        let text = std::fs::read_to_string(&marker)
            .map_err(|e| dir(format!("cannot read {OUTPUT_MARKER} ({e})")))?;
        serde_json::from_str::<serde_json::Value>(&text)
            .ok()
            .and_then(|v| v["command"].as_str().map(str::to_string))
    } else if out.join("study.json").is_file() {
        Some("sweep macro/meso".into())
    } else if out.join("sweep.partial.jsonl").is_file() {
        Some("sweep mu".into())
    } else {
        None
    };
    let studies = |o: &str| {
        o == "sweep macro/meso" && command.starts_with("sweep m") && command != "sweep mu"
    };
    if let Some(o) = owner.filter(|o| o != command && !studies(o)) {
        return Err(dir(format!(
            "holds the output of `squeal {o}`; choose another directory for `squeal {command}`"
        )));
    }
    let v = serde_json::json!({
        "command": command,
        "squeal": env!("CARGO_PKG_VERSION"),
        "machine": crate::profile::Machine::here(),
    });
    let text = serde_json::to_string_pretty(&v).unwrap_or_default() + "\n";
    std::fs::write(&marker, text).map_err(|e| dir(format!("cannot write {OUTPUT_MARKER} ({e})")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_is_claimed_by_one_command() {
        let dir = std::env::temp_dir().join(format!("squeal-outdir-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        claim(&dir, "validate").unwrap();
        claim(&dir, "validate").unwrap();
        // the marker names the machine the run's times come from
        let marker: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(OUTPUT_MARKER)).unwrap())
                .unwrap();
        assert!(
            marker["machine"]["cores"].as_u64().unwrap() >= 1,
            "{marker}"
        );
        assert!(marker["machine"]["cpu"].is_string(), "{marker}");
        let e = claim(&dir, "bench").unwrap_err().to_string();
        assert!(e.contains("holds the output of `squeal validate`"), "{e}");
        let file = dir.join("a-file");
        std::fs::write(&file, "x").unwrap();
        let e = prepare(&file).unwrap_err().to_string();
        assert!(e.contains("is a file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
