//! What a solve is asked ([`EigenParams`], checked by [`validate_params`]).

use crate::{Error, Result};

/// What to compute and how precisely.
#[derive(Debug, Clone, PartialEq)]
pub struct EigenParams {
    /// Band bottom (Hz): modes below are dropped from the result.
    pub fmin_hz: f64,
    /// Band top (Hz): every mode up to here is returned.
    pub fmax_hz: f64,
    /// Relative convergence tolerance of the Ritz pairs.
    pub tol: f64,
    /// Cap on restarts (or Arnoldi/Lanczos update iterations) of one Krylov run.
    pub max_restarts: usize,
    /// Shift (Hz) used as `sigma = -(2 pi shift_hz)^2`; `None` picks `fmax_hz / 20`.
    pub shift_hz: Option<f64>,
    /// First guess of how many modes lie below `fmax_hz` (grown automatically).
    pub nev_hint: Option<usize>,
    /// Problems up to this size are solved densely (reported in the notes).
    pub dense_below: usize,
    /// Most modes a band may hold: a band that holds more (a band top far above what
    /// the model resolves) is refused instead of computing the whole spectrum.
    pub max_modes: usize,
}

impl Default for EigenParams {
    fn default() -> Self {
        Self {
            fmin_hz: 0.0,
            fmax_hz: 10_000.0,
            tol: 1e-12,
            max_restarts: 300,
            shift_hz: None,
            nev_hint: None,
            dense_below: 120,
            max_modes: 3000,
        }
    }
}

/// The error of a band that holds more than `max_modes` modes.
pub fn too_many_modes(p: &EigenParams) -> Error {
    Error::param(
        "fmax_hz",
        format!(
            "the band {}-{} Hz holds more than {} modes: a band top far above what the \
             model resolves (lower the band top)",
            p.fmin_hz, p.fmax_hz, p.max_modes
        ),
    )
}

/// Checks the band (`0 <= fmin < fmax`, finite, in Hz) and the tolerance (`0 < tol < 1`).
pub fn validate_params(p: &EigenParams) -> Result<()> {
    if !(p.fmax_hz.is_finite() && p.fmax_hz > 0.0) {
        return Err(Error::param(
            "fmax_hz",
            format!(
                "band top must be a positive frequency in Hz, got {}",
                p.fmax_hz
            ),
        ));
    }
    if !(p.fmin_hz.is_finite() && p.fmin_hz >= 0.0 && p.fmin_hz < p.fmax_hz) {
        return Err(Error::param(
            "fmin_hz",
            format!(
                "band bottom must be in [0, {}) Hz, got {}",
                p.fmax_hz, p.fmin_hz
            ),
        ));
    }
    if !(p.tol > 0.0 && p.tol < 1.0) {
        return Err(Error::param(
            "tol",
            format!("relative tolerance must be in (0, 1), got {}", p.tol),
        ));
    }
    Ok(())
}
