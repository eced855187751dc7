//! One definition of a method against a reference: modes matched in frequency, the
//! errors of frequency and DvR, missed and false unstable modes, backward errors.

use crate::jsonl::{nan, null_as_nan};
use serde::{Deserialize, Serialize};
use squeal_core::operator::{ComplexModes, Stability};

/// When a run counts as accurate: every reference mode in the band found, no missed or
/// false unstable mode, and the errors below these bounds.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Accuracy {
    /// Largest relative frequency error.
    pub freq_rel: f64,
    /// Largest absolute DvR error.
    pub dvr_abs: f64,
}

impl Default for Accuracy {
    fn default() -> Self {
        Self {
            freq_rel: 1e-3,
            dvr_abs: 1e-4,
        }
    }
}

/// Errors of a set of modes against the reference in the band.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ModeErrors {
    /// Reference modes in the band.
    pub reference_modes: usize,
    /// Reference modes without a partner within 1 % in frequency.
    pub missed_modes: usize,
    /// Modes in the band matched to no reference mode.
    pub extra_modes: usize,
    /// Largest relative frequency error over matched modes (NaN when none matched).
    #[serde(deserialize_with = "null_as_nan")]
    pub max_rel_freq_err: f64,
    /// Largest absolute DvR error over matched modes.
    #[serde(deserialize_with = "null_as_nan")]
    pub max_abs_dvr_err: f64,
    /// Unstable reference modes.
    pub reference_unstable: usize,
    /// Reference modes neutral within their error bound.
    #[serde(default)]
    pub reference_neutral: usize,
    /// Unstable reference modes without an unstable partner (a partner neutral within
    /// its bound is a miss too: the method could not tell).
    pub missed_unstable: usize,
    /// Unstable modes in the band whose partner is not unstable, or without partner.
    pub false_unstable: usize,
    /// Modes in the band the method leaves neutral within their error bound.
    #[serde(default)]
    pub neutral: usize,
    /// Worst backward error (on the full operator) of the modes in the band.
    #[serde(deserialize_with = "null_as_nan")]
    pub max_backward_error: f64,
    /// Worst forward error estimate (`error_bound`, relative eigenvalue error) of the
    /// modes in the band; NaN when not computed (full order above
    /// [`CONDITION_AUTO_MAX_DIM`](squeal_core::qep::CONDITION_AUTO_MAX_DIM) DOFs without
    /// [`super::BenchOptions::condition`]).
    #[serde(default = "nan", deserialize_with = "null_as_nan")]
    pub max_error_bound: f64,
    /// Worst condition number of the modes in the band; NaN when not computed.
    #[serde(default = "nan", deserialize_with = "null_as_nan")]
    pub max_cond: f64,
    /// Largest relative eigenvalue error `|lambda - lambda_ref| / |lambda_ref|` over
    /// matched modes (NaN when none matched): the actual error `error_bound` estimates.
    #[serde(default = "nan", deserialize_with = "null_as_nan")]
    pub max_rel_lambda_err: f64,
    /// Matched modes whose relative eigenvalue error exceeds their own `error_bound` by
    /// more than the reference's accuracy ([`BOUND_FLOOR`], or the reference mode's own
    /// bound when larger); modes without a bound are not counted.
    #[serde(default)]
    pub above_bound: usize,
}

/// The smallest eigenvalue error a bound is held to: below it the reference itself
/// (solved to 1e-12) is not accurate enough to tell.
pub const BOUND_FLOOR: f64 = 1e-12;

/// The largest of `values` that are not NaN (NaN when all are, or there are none).
fn worst(values: impl Iterator<Item = f64>) -> f64 {
    values.fold(f64::NAN, |m, v| if v.is_nan() || m >= v { m } else { v })
}

impl ModeErrors {
    pub(super) fn failed() -> Self {
        Self {
            reference_modes: 0,
            missed_modes: 0,
            extra_modes: 0,
            max_rel_freq_err: f64::NAN,
            max_abs_dvr_err: f64::NAN,
            reference_unstable: 0,
            reference_neutral: 0,
            missed_unstable: 0,
            false_unstable: 0,
            neutral: 0,
            max_backward_error: f64::NAN,
            max_error_bound: f64::NAN,
            max_cond: f64::NAN,
            max_rel_lambda_err: f64::NAN,
            above_bound: 0,
        }
    }

    /// Whether these errors meet `acc` (every mode found, no missed or false instability).
    pub fn accurate(&self, acc: &Accuracy) -> bool {
        self.missed_modes == 0
            && self.missed_unstable == 0
            && self.false_unstable == 0
            && self.max_rel_freq_err <= acc.freq_rel
            && self.max_abs_dvr_err <= acc.dvr_abs
    }
}

/// Compares `modes` with `reference` in `band_hz`: every reference mode in the band is
/// matched to the nearest unused eigenvalue of `modes` within 1 % in frequency (none
/// there: missed); modes of `modes` up to 1 % beyond the band edges may be
/// partners (a mode at the edge may fall either side), those inside the band and matched
/// to nothing are extra. A mode's class is [`ComplexModes::stability`] (its real part
/// against its own error bound, and the physical margin `dvr_margin`). The worst
/// `error_bound` and `cond` of the modes in the band are recorded next to their worst
/// backward error, with the actual relative eigenvalue errors of the matched modes and how
/// many exceed their own bound.
pub fn compare(
    reference: &ComplexModes,
    modes: &ComplexModes,
    band_hz: [f64; 2],
    dvr_margin: f64,
) -> ModeErrors {
    let in_band = |f: f64| f >= band_hz[0] && f <= band_hz[1];
    let near_band = |f: f64| f >= band_hz[0] * 0.99 && f <= band_hz[1] * 1.01;
    let mut e = ModeErrors {
        max_rel_freq_err: 0.0,
        max_abs_dvr_err: 0.0,
        max_backward_error: 0.0,
        max_rel_lambda_err: 0.0,
        ..ModeErrors::failed()
    };
    let mut used = vec![false; modes.len()];
    let mut matched = 0;
    for i in (0..reference.len()).filter(|&i| in_band(reference.freq_hz[i])) {
        e.reference_modes += 1;
        let class_ref = reference.stability(i, dvr_margin);
        let unstable_ref = class_ref == Stability::Unstable;
        e.reference_unstable += usize::from(unstable_ref);
        e.reference_neutral += usize::from(class_ref == Stability::Neutral);
        // the nearest eigenvalue among the unused modes within 1 % in frequency: a strongly
        // unstable mode's nearest eigenvalue can be a mode of another frequency
        let rel_df = |j: usize| {
            (modes.freq_hz[j] - reference.freq_hz[i]).abs() / reference.freq_hz[i].abs().max(1e-300)
        };
        let best = (0..modes.len())
            .filter(|&j| !used[j] && near_band(modes.freq_hz[j]) && rel_df(j) <= 0.01)
            .map(|j| (j, (reference.lambda[i] - modes.lambda[j]).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let Some((j, _)) = best else {
            e.missed_modes += 1;
            e.missed_unstable += usize::from(unstable_ref);
            continue;
        };
        let df = rel_df(j);
        used[j] = true;
        matched += 1;
        let err = (reference.lambda[i] - modes.lambda[j]).norm() / reference.lambda[i].norm();
        e.max_rel_lambda_err = e.max_rel_lambda_err.max(err);
        let floor = match reference.error_bound.get(i) {
            Some(&b) if b.is_finite() => b.max(BOUND_FLOOR),
            _ => BOUND_FLOOR,
        };
        let bound = modes.error_bound.get(j).copied().unwrap_or(f64::NAN);
        e.above_bound += usize::from(err > bound + floor);
        e.max_rel_freq_err = e.max_rel_freq_err.max(df);
        e.max_abs_dvr_err = e
            .max_abs_dvr_err
            .max((modes.dvr[j] - reference.dvr[i]).abs());
        let unstable = modes.is_unstable(j, dvr_margin);
        if unstable_ref && !unstable {
            e.missed_unstable += 1;
        } else if unstable && !unstable_ref {
            e.false_unstable += 1;
        }
    }
    for j in (0..modes.len()).filter(|&j| in_band(modes.freq_hz[j])) {
        e.max_backward_error = e.max_backward_error.max(modes.backward_error[j]);
        e.neutral += usize::from(modes.stability(j, dvr_margin) == Stability::Neutral);
        if !used[j] {
            e.extra_modes += 1;
            e.false_unstable += usize::from(modes.is_unstable(j, dvr_margin));
        }
    }
    let band: Vec<usize> = (0..modes.len())
        .filter(|&j| in_band(modes.freq_hz[j]))
        .collect();
    let at = |v: &[f64], j: usize| v.get(j).copied().unwrap_or(f64::NAN);
    e.max_error_bound = worst(band.iter().map(|&j| at(&modes.error_bound, j)));
    e.max_cond = worst(band.iter().map(|&j| at(&modes.cond, j)));
    if matched == 0 {
        e.max_rel_freq_err = f64::NAN;
        e.max_abs_dvr_err = f64::NAN;
        e.max_rel_lambda_err = f64::NAN;
    }
    e
}
