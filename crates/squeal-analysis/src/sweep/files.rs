//! The files of a sweep's output directory: the checkpoint opened for a run (or a
//! resumed one), what a sweep run into a directory reports as it goes, and `sweep.csv`
//! (one row per mode and point, with its branch).

use super::{Branch, Checkpoint, SweepPoint};
use crate::outdir::{self, RunError};
use squeal_core::operator::Stability;
use std::io::Write;
use std::path::Path;

/// What a sweep run into a directory reports as it goes.
pub enum SweepEvent<'a> {
    /// The checkpoint is open: `done` of `total` points were finished by an earlier run.
    Opened {
        /// Points already computed.
        done: usize,
        /// Points of the sweep.
        total: usize,
    },
    /// A point is finished (read back or computed).
    Point(&'a SweepPoint),
}

/// Claims `out` for `command` and opens its checkpoint: refuses a directory holding
/// `what` (finished points or a summary) without `resume`, and a checkpoint of other
/// `inputs` (with `"condition": true` added when `condition`). Tells `events` how many of
/// the `total` points it holds, and returns it.
#[allow(clippy::too_many_arguments)]
pub fn open_checkpoint(
    out: &Path,
    command: &str,
    what: &str,
    resume: bool,
    mut inputs: serde_json::Value,
    condition: bool,
    total: usize,
    events: &mut impl FnMut(SweepEvent<'_>),
) -> Result<Checkpoint, RunError> {
    if condition {
        inputs["condition"] = true.into();
    }
    outdir::claim(out, command)?;
    let ckpt_path = out.join("sweep.partial.jsonl");
    let done = Checkpoint::new(ckpt_path.clone())
        .load()
        .map(|p| p.len())
        .unwrap_or(0);
    if (done > 0 || out.join("summary.json").is_file()) && !resume {
        return Err(RunError::Dir {
            path: out.to_path_buf(),
            message: format!(
                "holds {what} ({done} finished points): pass --resume to continue it, or \
                 choose another directory"
            ),
        });
    }
    let ckpt = Checkpoint::new(ckpt_path);
    ckpt.claim(&inputs).map_err(|message| RunError::Dir {
        path: out.to_path_buf(),
        message,
    })?;
    events(SweepEvent::Opened { done, total });
    Ok(ckpt)
}

/// The largest of `values` that are not NaN (NaN when all are, or there are none).
pub fn worst(values: &[f64]) -> f64 {
    values
        .iter()
        .fold(f64::NAN, |m, &v| if v.is_nan() || m >= v { m } else { v })
}

/// The worst `error_bound` of every point's modes (NaN when none was computed).
pub fn max_error_bound(points: &[SweepPoint]) -> f64 {
    let all: Vec<f64> = points
        .iter()
        .flat_map(|p| p.modes.iter().map(|m| m.error_bound))
        .collect();
    worst(&all)
}

/// Writes `sweep.csv`: one row per mode and point, the swept value in column `column`,
/// the branch the mode belongs to, whether it is unstable (`unstable` 0/1), its class
/// (`stability`: unstable, neutral or stable) and the bound of its real part it was
/// decided by (`re_bound`, 1/s; empty when its sign alone decided), with the physical
/// DvR margin `tol` ([`squeal_core::operator::classify`]).
pub fn write_csv(
    path: &Path,
    column: &str,
    points: &[SweepPoint],
    branches: &[Branch],
    tol: f64,
) -> Result<(), RunError> {
    let failed = |source| RunError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(failed)?);
    let mut text = format!(
        "{column},branch,mode,freq_hz,re,dvr,unstable,backward_error,cond,error_bound,active_pairs,basis_size,stability,re_bound\n"
    );
    // an estimate that was not computed is an empty field
    let num = |x: f64| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x:.3e}")
        }
    };
    for (p, pt) in points.iter().enumerate() {
        for (m, md) in pt.modes.iter().enumerate() {
            let verdict = md.verdict(tol);
            let b = branches
                .iter()
                .find(|b| b.modes[p] == Some(m))
                .map_or(usize::MAX, |b| b.id);
            text += &format!(
                "{},{},{},{:.6},{:.6e},{:.6e},{},{:.3e},{},{},{},{},{},{}\n",
                pt.value,
                b,
                m,
                md.freq_hz,
                // `+ 0.0` writes an undamped mode's -0 as 0
                md.re + 0.0,
                md.dvr + 0.0,
                u8::from(verdict.class == Stability::Unstable),
                md.backward_error,
                num(md.cond),
                num(md.error_bound),
                pt.active_pairs,
                pt.basis_size,
                verdict.class,
                num(verdict.re_bound)
            );
        }
    }
    f.write_all(text.as_bytes())
        .and_then(|()| f.flush())
        .map_err(failed)
}
