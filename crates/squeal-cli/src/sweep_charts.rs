//! The charts of the parameter sweeps (`squeal sweep mu`, `squeal sweep param`,
//! `squeal validate`): frequency and divergence rate against the swept quantity (the
//! paper's Figure 5) and the make-up of each coupling.

use anyhow::Result;
use squeal_analysis::family::SweepCoupling;
use squeal_analysis::mu_sweep::MuSweep;
use squeal_analysis::sweep::{Branch, SweepPoint};
use squeal_core::Stability;
use std::path::{Path, PathBuf};

/// Legend entry of the modes whose stability the solve cannot tell within their error
/// bound (ringed in the charts).
pub const NEUTRAL_LABEL: &str = "neutral within the error bound";

/// The charts of a finished mu sweep: frequency and DvR against mu (Figure 5), and the
/// make-up of each coupling.
pub fn sweep_charts(out: &Path, sweep: &MuSweep, dvr_margin: f64) -> Result<()> {
    charts(out, &Axis::mu(), &sweep.points, &sweep.branches, dvr_margin)?;
    let makeup: Vec<SweepCoupling> = sweep
        .couplings
        .iter()
        .map(|c| SweepCoupling {
            freq_hz: c.freq_hz,
            from: c.mu_from,
            to: c.mu_to,
            max_dvr: c.max_dvr,
            partners: c.partners.clone(),
            makeup: c.free_interface_mac.clone(),
        })
        .collect();
    mac_charts(out, &Axis::mu(), &makeup)
}

/// The swept quantity of charts and CSV: its column name, its axis label and the modes
/// the signatures are taken on (one of them, and all of them).
pub struct Axis {
    column: String,
    label: String,
    item: &'static str,
    reference: &'static str,
}

impl Axis {
    pub fn mu() -> Self {
        Self {
            column: "mu".into(),
            label: "friction coefficient mu".into(),
            item: "free-interface mode",
            reference: "the free-interface modes",
        }
    }

    pub fn param(name: &str) -> Self {
        Self {
            column: name.into(),
            label: format!("parameter {name}"),
            item: "reference mode",
            reference: "the reference modes",
        }
    }
}

/// Frequency and divergence rate of every tracked branch against the swept quantity.
pub fn charts(
    out: &Path,
    axis: &Axis,
    points: &[SweepPoint],
    branches: &[Branch],
    tol: f64,
) -> Result<Vec<PathBuf>> {
    use squeal_plot::{line_chart, ChartOptions, Series, SeriesStyle};
    let series = |y: &dyn Fn(&squeal_analysis::sweep::SweepMode) -> f64| -> Vec<Series> {
        branches
            .iter()
            .map(|b| {
                let pts: Vec<(usize, usize)> = (0..points.len())
                    .filter_map(|p| b.modes[p].map(|m| (p, m)))
                    .collect();
                Series {
                    name: String::new(),
                    points: pts
                        .iter()
                        .map(|&(p, m)| (points[p].value, y(&points[p].modes[m])))
                        .collect(),
                    style: SeriesStyle::LineMarkers,
                    neutral: pts
                        .iter()
                        .map(|&(p, m)| points[p].modes[m].stability(tol) == Stability::Neutral)
                        .collect(),
                    highlight: pts
                        .iter()
                        .map(|&(p, m)| points[p].modes[m].stability(tol) == Stability::Unstable)
                        .collect(),
                }
            })
            .collect()
    };
    let mut files = line_chart(
        &out.join(format!("frequency_vs_{}", axis.column)),
        "Frequency of the tracked modes (unstable in red, neutral ringed)",
        &axis.label,
        "frequency (Hz)",
        &series(&|m| m.freq_hz),
        &ChartOptions {
            highlight_label: Some("unstable".into()),
            neutral_label: Some(NEUTRAL_LABEL.into()),
            ..ChartOptions::default()
        },
    )?;
    files.extend(line_chart(
        &out.join(format!("dvr_vs_{}", axis.column)),
        "Divergence rate Re/Im of the tracked modes (unstable in red, neutral ringed)",
        &axis.label,
        "DvR = Re(lambda)/Im(lambda)",
        &series(&|m| m.dvr),
        &ChartOptions {
            hline: Some(0.0),
            highlight_label: Some("unstable".into()),
            neutral_label: Some(NEUTRAL_LABEL.into()),
            ..ChartOptions::default()
        },
    )?);
    Ok(files)
}

/// One bar chart per coupling: the MAC of the unstable mode with the reference modes of
/// the signatures.
pub fn mac_charts(out: &Path, axis: &Axis, couplings: &[SweepCoupling]) -> Result<()> {
    for (i, c) in couplings.iter().enumerate() {
        if c.makeup.is_empty() {
            continue;
        }
        squeal_plot::bar_chart(
            &out.join(format!("mac_coupling_{}", i + 1)),
            &format!(
                "Unstable mode near {:.0} Hz ({} {}-{}): MAC with {}",
                c.freq_hz, axis.column, c.from, c.to, axis.reference
            ),
            axis.item,
            "MAC",
            &c.makeup,
        )?;
    }
    Ok(())
}
