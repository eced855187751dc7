//! # squeal-basis-modes
//!
//! The real-mode reduction basis, registered as `"modes"`: the coupled mu = 0 modes of
//! `(K_c, M_c)` (of the operator's real-mode pair,
//! [`squeal_core::reduction::real_mode_pair`], for an operator read from files) from 0 Hz
//! up to `cutoff_factor x` the band top, `M_c`-orthonormal — the
//! projection commercial codes use (QRDAMP-style), the baseline of the comparison.
//! Truncated near the band top it misses the friction-induced deformation and
//! over-predicts growth rates; the backward errors of the
//! expanded modes on the full operator say so.
//!
//! The modes come from the request's `modal` solver (normally `arpack` or `krylov`);
//! orthonormalization, projection and expansion are the shared machinery of
//! [`squeal_core::reduction`]. Fixed in mu: built once per contact set.
//!
//! ## Parameters
//!
//! - `cutoff_factor` (default 1.5, > 0): the cutoff frequency is
//!   `cutoff_factor * band top`.
//! - `rank_tol` (default [`DEFAULT_RANK_TOL`]): relative rank cut of the
//!   `M_c`-orthonormalization.

use squeal_core::params::{fraction, positive};
use squeal_core::reduction::{
    coupled_real_modes, m_orthonormalize, real_mode_pair, DEFAULT_RANK_TOL,
};
use squeal_core::{Basis, BasisRequest, Params, ReductionBasis, Registry, Result};

/// Name under which the basis is registered.
pub const NAME: &str = "modes";

/// One-line description shown by the registry.
pub const DESCRIPTION: &str = "coupled mu = 0 real modes up to cutoff_factor x band top \
                               (default 1.5); options cutoff_factor, rank_tol";

/// Default of the `cutoff_factor` parameter.
pub const DEFAULT_CUTOFF_FACTOR: f64 = 1.5;

/// Registers the `"modes"` basis.
pub fn register(reg: &mut Registry) {
    reg.bases.register(NAME, DESCRIPTION, |params: &Params| {
        let basis: Box<dyn ReductionBasis> = Box::new(ModesBasis::new(
            params.num_or("cutoff_factor", DEFAULT_CUTOFF_FACTOR)?,
            params.num_or("rank_tol", DEFAULT_RANK_TOL)?,
        )?);
        Ok(basis)
    });
}

/// The `"modes"` basis.
#[derive(Debug, Clone)]
pub struct ModesBasis {
    /// Cutoff frequency over band top.
    pub cutoff_factor: f64,
    /// Relative rank cut of the orthonormalization.
    pub rank_tol: f64,
}

impl ModesBasis {
    /// Checks and stores the parameters.
    pub fn new(cutoff_factor: f64, rank_tol: f64) -> Result<Self> {
        positive("cutoff_factor", cutoff_factor)?;
        fraction("rank_tol", rank_tol)?;
        Ok(Self {
            cutoff_factor,
            rank_tol,
        })
    }
}

impl ReductionBasis for ModesBasis {
    fn name(&self) -> &str {
        NAME
    }

    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis> {
        let cutoff = self.cutoff_factor * request.band_hz.1;
        let modes = coupled_real_modes(request, cutoff)?;
        let (v, dropped) = m_orthonormalize(
            request.op.mc.as_ref(),
            modes.vectors.as_ref(),
            self.rank_tol,
        )?;
        let mut basis = Basis::new(v);
        basis.dropped = dropped;
        let pair = real_mode_pair(request.op)?;
        basis.notes.push(format!(
            "{NAME}: {} coupled mu = 0 real modes up to {cutoff:.1} Hz (`{}`, {:.3} s){}",
            modes.freq_hz.len(),
            request.modal.name(),
            modes.info.time_s,
            if pair.own {
                String::new()
            } else {
                format!(" of the real-mode pair ({})", pair.source)
            }
        ));
        Ok(basis)
    }
}
