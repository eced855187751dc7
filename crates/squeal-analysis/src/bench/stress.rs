//! The stress report: where each method is wrong on the stress cases, and whether its
//! backward error and its forward error bound would have told.

use super::{Accuracy, BenchRun, ModeErrors};
use serde::Serialize;

/// One run of the stress set judged against its reference and the baseline case.
#[derive(Debug, Clone, Serialize)]
pub struct StressRow {
    /// Stress case.
    pub case: String,
    /// `basis/eigen`.
    pub method: String,
    /// Basis parameters other than the defaults.
    pub basis_opts: String,
    /// The run finished and is not accurate ([`Accuracy::default`]).
    pub wrong: bool,
    /// What is wrong (or the error of a failed run).
    pub why: Vec<String>,
    /// Worst backward error of the run's modes.
    pub max_backward_error: f64,
    /// The same method's worst backward error on the `baseline` case.
    pub baseline_backward_error: f64,
    /// `max_backward_error / baseline_backward_error`.
    pub estimate_ratio: f64,
    /// The backward error rose at least tenfold over the baseline.
    pub flagged: bool,
    /// Worst condition number of the case's modes (null: not computed).
    pub cond: f64,
    /// Worst forward error estimate of the case's modes (null: not computed).
    pub error_bound: f64,
    /// The actual worst relative eigenvalue error of the matched modes.
    pub actual_error: f64,
    /// Matched modes whose actual error exceeds their own bound.
    pub above_bound: usize,
    /// For a wrong run with bounds: whether the bound flagged it (null otherwise).
    pub bound_flagged: Option<bool>,
    /// The method stopped with an error (e.g. `dense` refusing a full-order problem
    /// above its `max_dim`): no answer, so neither right nor wrong.
    pub failed: bool,
}

/// The stress rows of every run but the references, judged with [`Accuracy::default`].
pub fn stress_rows(runs: &[BenchRun]) -> Vec<StressRow> {
    let acc = Accuracy::default();
    let threshold = bound_threshold(&acc);
    let base = |r: &BenchRun| -> f64 {
        runs.iter()
            .find(|b| b.case == "baseline" && b.basis == r.basis && b.eigen == r.eigen)
            .map_or(f64::NAN, |b| b.errors.max_backward_error)
    };
    let mut rows = Vec::new();
    for r in runs.iter().filter(|r| !r.reference) {
        let mut why = Vec::new();
        if r.status != "ok" {
            why.push(r.status.clone());
        } else {
            let e = &r.errors;
            if e.missed_modes > 0 {
                why.push(format!("{} modes missed", e.missed_modes));
            }
            if e.missed_unstable > 0 {
                why.push(format!("{} unstable modes missed", e.missed_unstable));
            }
            if e.false_unstable > 0 {
                why.push(format!("{} false unstable", e.false_unstable));
            }
            if e.max_rel_freq_err > acc.freq_rel {
                why.push(format!("df/f {:.1e}", e.max_rel_freq_err));
            }
            if e.max_abs_dvr_err > acc.dvr_abs {
                why.push(format!("dDvR {:.1e}", e.max_abs_dvr_err));
            }
        }
        let b = base(r);
        let ratio = r.errors.max_backward_error / b;
        let wrong = r.status == "ok" && !why.is_empty();
        let e = &r.errors;
        rows.push(StressRow {
            case: r.case.clone(),
            method: format!("{}/{}", r.basis, r.eigen),
            basis_opts: r.basis_opts.clone(),
            wrong,
            failed: r.status != "ok",
            why,
            max_backward_error: e.max_backward_error,
            baseline_backward_error: b,
            estimate_ratio: ratio,
            flagged: ratio >= 10.0,
            cond: e.max_cond,
            error_bound: e.max_error_bound,
            actual_error: e.max_rel_lambda_err,
            above_bound: e.above_bound,
            bound_flagged: (wrong && !e.max_error_bound.is_nan())
                .then(|| bound_flags(e, threshold)),
        });
    }
    rows
}

/// The forward error estimate above which a run cannot be trusted to be accurate: a
/// relative eigenvalue error `e` moves the frequency by up to about `e` (relative) and
/// the DvR by up to about `e` (absolute), so the smaller of the two accuracy bounds.
pub fn bound_threshold(acc: &Accuracy) -> f64 {
    acc.freq_rel.min(acc.dvr_abs)
}

/// Whether a run's bounds flag its errors: every reference mode found, no extra mode
/// (a bound cannot vouch for a mode it does not have, nor against a spurious one) and
/// every matched mode's actual error within its own bound; or the worst bound above
/// `threshold`.
pub fn bound_flags(e: &ModeErrors, threshold: f64) -> bool {
    let covers = e.missed_modes == 0
        && e.extra_modes == 0
        && e.above_bound == 0
        && e.max_error_bound.is_finite();
    covers || e.max_error_bound > threshold
}
