//! Cost/accuracy trade-off charts: methods as (time, error) points and their Pareto front.

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::{auto_log, fmt_tick, font, render, title_font, Figure, PlotError, CHART_SIZE};
use crate::{HIGHLIGHT, PALETTE};

/// Indices of the Pareto-optimal points when both coordinates are to be minimised,
/// sorted by increasing x (then y, then index).
///
/// A point is on the front unless another point is at least as good in both coordinates
/// and strictly better in one. Exact duplicates are therefore all kept. Points with a
/// NaN coordinate are never on the front and never dominate.
///
/// ```
/// let pts = [(1.0, 5.0), (2.0, 2.0), (3.0, 3.0), (4.0, 1.0)];
/// assert_eq!(squeal_plot::pareto_front(&pts), vec![0, 1, 3]);
/// ```
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let ok = |p: &(f64, f64)| !(p.0.is_nan() || p.1.is_nan());
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let p = points[i];
            ok(&p)
                && !points
                    .iter()
                    .any(|q| ok(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1))
        })
        .collect();
    front.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
            .then(a.cmp(&b))
    });
    front
}

/// Writes a log-log trade-off chart to `<stem>.svg` and `<stem>.png` (size
/// [`CHART_SIZE`]).
///
/// `points` are `(label, x, y)` per method, typically `(name, time in s, error)`; both are
/// minimised. Every point is a circle of its own colour named in the legend (no text on
/// the plot area, so clustered methods stay readable); the Pareto front
/// ([`pareto_front`]) is a red line through red rings around its points, in order of x. Points with a non-positive coordinate cannot appear on log axes and are
/// dropped (also from the front).
///
/// # Errors
/// [`PlotError::EmptyData`] if there is no point with both coordinates positive;
/// [`PlotError::NanData`] if a coordinate is NaN or infinite; [`PlotError::Io`] /
/// [`PlotError::Backend`] when writing fails.
pub fn pareto_chart(
    stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    points: &[(String, f64, f64)],
) -> Result<Vec<PathBuf>, PlotError> {
    if let Some((l, x, y)) = points
        .iter()
        .find(|(_, x, y)| !(x.is_finite() && y.is_finite()))
    {
        return Err(PlotError::nan(stem, format!("point {l:?}: ({x}, {y})")));
    }
    let kept: Vec<(String, f64, f64)> = points
        .iter()
        .filter(|(_, x, y)| *x > 0.0 && *y > 0.0)
        .cloned()
        .collect();
    if kept.is_empty() {
        return Err(PlotError::empty(
            stem,
            if points.is_empty() {
                "no point"
            } else {
                "no point with both coordinates positive (log axes)"
            },
        ));
    }
    let xy: Vec<(f64, f64)> = kept.iter().map(|(_, x, y)| (*x, *y)).collect();
    let front = pareto_front(&xy);
    let xr = padded(xy.iter().map(|p| p.0), 0.05, 0.25);
    let yr = padded(xy.iter().map(|p| p.1), 0.05, 0.15);
    let fig = ParetoFig {
        title,
        x_label,
        y_label,
        points: kept,
        front,
        xr,
        yr,
    };
    render(stem, &fig)
}

/// Log range of `vals` widened by `lo`/`hi` times its number of decades (at least one
/// decade) below/above, to leave room for the point labels.
fn padded(vals: impl Iterator<Item = f64>, lo: f64, hi: f64) -> Range<f64> {
    let r = auto_log(vals).unwrap_or(0.1..10.0);
    let d = (r.end / r.start).log10().max(1.0);
    r.start / 10f64.powf(lo * d)..r.end * 10f64.powf(hi * d)
}

struct ParetoFig<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    points: Vec<(String, f64, f64)>,
    front: Vec<usize>,
    xr: Range<f64>,
    yr: Range<f64>,
}

impl Figure for ParetoFig<'_> {
    fn size(&self) -> (u32, u32) {
        CHART_SIZE
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, title_font())
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(75)
            .build_cartesian_2d(self.xr.clone().log_scale(), self.yr.clone().log_scale())?;
        chart
            .configure_mesh()
            .x_desc(self.x_label)
            .y_desc(self.y_label)
            .x_label_formatter(&fmt_tick)
            .y_label_formatter(&fmt_tick)
            .label_style(font(14))
            .axis_desc_style(font(16))
            .draw()?;

        // every method its own colour and legend entry (no text next to the points,
        // which piles up where methods cluster); the front is a red line through red
        // rings around its points
        if self.front.len() >= 2 {
            chart
                .draw_series(LineSeries::new(
                    self.front
                        .iter()
                        .map(|&i| (self.points[i].1, self.points[i].2)),
                    HIGHLIGHT.stroke_width(2),
                ))?
                .label("Pareto front")
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 14, y)], HIGHLIGHT.stroke_width(2))
                });
        }
        chart.draw_series(self.front.iter().map(|&i| {
            Circle::new(
                (self.points[i].1, self.points[i].2),
                9,
                HIGHLIGHT.stroke_width(2),
            )
        }))?;
        for (k, (label, x, y)) in self.points.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            chart
                .draw_series(std::iter::once(Circle::new((*x, *y), 6, color.filled())))?
                .label(label.clone())
                .legend(move |(x, y)| Circle::new((x + 7, y), 6, color.filled()));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(font(14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .draw()?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_basic() {
        // (time, error)
        let pts = [
            (1.0, 1e-3), // 0: fastest
            (2.0, 1e-6), // 1: front
            (3.0, 1e-5), // 2: dominated by 1
            (5.0, 1e-9), // 3: most accurate
            (5.0, 1e-8), // 4: dominated by 3 (same time)
            (0.5, 1e-3), // 5: dominates 0 (same error, faster)
        ];
        assert_eq!(pareto_front(&pts), vec![5, 1, 3]);
    }

    #[test]
    fn front_duplicates_nan_and_empty() {
        assert!(pareto_front(&[]).is_empty());
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0, 1]);
        assert_eq!(
            pareto_front(&[(f64::NAN, 0.0), (1.0, 1.0), (0.5, f64::NAN)]),
            vec![1]
        );
        // A single point dominating all others.
        assert_eq!(pareto_front(&[(3.0, 3.0), (1.0, 1.0), (2.0, 5.0)]), vec![1]);
    }
}
