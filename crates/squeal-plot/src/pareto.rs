//! Cost/accuracy trade-off charts: methods as (time, error) points and their Pareto front.

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::{auto_log, fmt_tick, font, render, title_font, Figure, PlotError, CHART_SIZE};
use crate::{series_colour, series_marker, with_decade, HIGHLIGHT};

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

/// Writes a log-log trade-off chart to `<stem>.svg` and `<stem>.png`.
///
/// `points` are `(label, x, y)` per method, typically `(name, time in s, error)`; both are
/// minimised. Every point is a marker of its own colour (and, past nine points, its own
/// shape), named in a legend beside the plot area (no text on the plot area, so
/// clustered methods stay readable, and no legend box over a point); the Pareto front
/// ([`pareto_front`]) is a red line through red rings around its points, in order of x.
/// Points with a non-positive coordinate cannot appear on log axes and are dropped (also
/// from the front). The image is [`CHART_SIZE`] widened by the legend strip (160 to 520
/// px, after the longest label) and taller when the legend needs it.
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

/// Log range of `vals` widened by `lo`/`hi` decades times its number of decades (taken
/// as at least one) below/above, holding a power of ten for the ticks.
fn padded(vals: impl Iterator<Item = f64>, lo: f64, hi: f64) -> Range<f64> {
    let r = auto_log(vals).unwrap_or(0.1..10.0);
    let d = (r.end / r.start).log10().max(1.0);
    with_decade(r.start / 10f64.powf(lo * d)..r.end * 10f64.powf(hi * d))
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

/// Legend rows (pixels) and the strip's margins.
const ROW_H: i32 = 22;
const LEGEND_PAD: i32 = 12;

impl ParetoFig<'_> {
    /// Legend entries: the front (when drawn) and every point.
    fn entries(&self) -> usize {
        self.points.len() + usize::from(self.front.len() >= 2)
    }

    /// Width of the legend strip: room for the longest label (DejaVu Sans 14 px is
    /// under 8 px per character) after a marker, within [160, 520] px.
    fn legend_w(&self) -> u32 {
        let chars = self
            .points
            .iter()
            .map(|p| p.0.chars().count())
            .chain(std::iter::once("Pareto front".len()))
            .max()
            .unwrap_or(0);
        (40 + 8 * chars as u32).clamp(160, 520)
    }
}

impl Figure for ParetoFig<'_> {
    /// [`CHART_SIZE`] for the plot, plus the legend strip on the right; taller when the
    /// legend needs it.
    fn size(&self) -> (u32, u32) {
        let rows = self.entries() as u32;
        let h = CHART_SIZE
            .1
            .max(rows * ROW_H as u32 + 2 * LEGEND_PAD as u32 + 60);
        (CHART_SIZE.0 + self.legend_w(), h)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (w, _) = root.dim_in_pixel();
        // the legend lives in its own strip, so it never hides a point
        let (plot, strip) = root.split_horizontally(w - self.legend_w());
        let mut chart = ChartBuilder::on(&plot)
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

        // every method its own colour and marker, named in the legend (no text next to
        // the points, which piles up where methods cluster); the front is a red line
        // through red rings around its points
        if self.front.len() >= 2 {
            chart.draw_series(LineSeries::new(
                self.front
                    .iter()
                    .map(|&i| (self.points[i].1, self.points[i].2)),
                HIGHLIGHT.stroke_width(2),
            ))?;
        }
        chart.draw_series(self.front.iter().map(|&i| {
            Circle::new(
                (self.points[i].1, self.points[i].2),
                10,
                HIGHLIGHT.stroke_width(2),
            )
        }))?;
        for (k, (_, x, y)) in self.points.iter().enumerate() {
            chart.draw_series(std::iter::once(
                EmptyElement::at((*x, *y))
                    + Polygon::new(series_marker(k, 6), series_colour(k).filled()),
            ))?;
        }

        // the legend: a framed box at the top of the strip
        let rows = self.entries() as i32;
        let (sw, _) = strip.dim_in_pixel();
        let (x0, y0) = (4, 50);
        strip.draw(&Rectangle::new(
            [(x0, y0), (sw as i32 - 6, y0 + rows * ROW_H + LEGEND_PAD)],
            BLACK.mix(0.5).stroke_width(1),
        ))?;
        let text = |s: &str, y: i32| {
            Text::new(
                s.to_string(),
                (x0 + 34, y),
                font(14).pos(Pos::new(HPos::Left, VPos::Center)),
            )
        };
        let mut y = y0 + LEGEND_PAD / 2 + ROW_H / 2;
        if self.front.len() >= 2 {
            strip.draw(&PathElement::new(
                vec![(x0 + 8, y), (x0 + 26, y)],
                HIGHLIGHT.stroke_width(2),
            ))?;
            strip.draw(&Circle::new((x0 + 17, y), 7, HIGHLIGHT.stroke_width(2)))?;
            strip.draw(&text("Pareto front", y))?;
            y += ROW_H;
        }
        for (k, (label, _, _)) in self.points.iter().enumerate() {
            strip.draw(
                &(EmptyElement::at((x0 + 17, y))
                    + Polygon::new(series_marker(k, 6), series_colour(k).filled())),
            )?;
            strip.draw(&text(label, y))?;
            y += ROW_H;
        }
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
