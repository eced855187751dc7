//! Line and scatter charts (stability maps, convergence curves, sweeps).

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::{
    auto_linear, auto_log, check_range, font, render, series_colour, series_marker, tick_in,
    title_font, with_axes, Figure, PlotError, CHART_SIZE, HIGHLIGHT, NEUTRAL,
};

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeriesStyle {
    /// Points joined by a line, in the given order.
    #[default]
    Line,
    /// One filled circle per point.
    Markers,
    /// A line and a circle per point.
    LineMarkers,
}

/// One data series of a [`line_chart`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend entry; series with an empty name get no legend entry.
    pub name: String,
    /// (x, y) points in the caller's units, in drawing order for lines.
    pub points: Vec<(f64, f64)>,
    /// Line, markers or both.
    pub style: SeriesStyle,
    /// Highlight mask, one flag per point, or empty for none. Highlighted points are drawn
    /// as bigger red circles (whatever the style), e.g. the unstable modes of a
    /// stability map.
    pub highlight: Vec<bool>,
    /// Neutral mask, one flag per point, or empty for none. Marked points get a ring in
    /// the neutral colour (whatever the style), e.g. the modes whose stability the solve
    /// cannot decide within their error bound.
    pub neutral: Vec<bool>,
}

/// Options of a [`line_chart`]. `ChartOptions::default()` gives linear axes with
/// automatic ranges, no reference line and a [`CHART_SIZE`] image.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartOptions {
    /// Logarithmic x axis. Points with `x <= 0` are dropped (not drawn, not counted in
    /// the automatic range).
    pub log_x: bool,
    /// Logarithmic y axis. Points with `y <= 0` are dropped, as is a non-positive `hline`.
    pub log_y: bool,
    /// Fixed x range `(min, max)`; `None` fits the data with a 5 % margin.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range `(min, max)`; `None` fits the data (and `hline`) with a 5 % margin.
    pub y_range: Option<(f64, f64)>,
    /// Horizontal reference line at this y, e.g. `Some(0.0)` for the stability limit
    /// (zero real part / zero damping ratio).
    pub hline: Option<f64>,
    /// Legend entry for highlighted points (e.g. `"unstable"`); `None` for no entry.
    pub highlight_label: Option<String>,
    /// Legend entry for neutral points (e.g. `"neutral within the error bound"`); `None`
    /// for no entry.
    pub neutral_label: Option<String>,
    /// Image size in pixels (width, height), for both the SVG and the PNG.
    pub size: (u32, u32),
}

impl Default for ChartOptions {
    fn default() -> Self {
        ChartOptions {
            log_x: false,
            log_y: false,
            x_range: None,
            y_range: None,
            hline: None,
            highlight_label: None,
            neutral_label: None,
            size: CHART_SIZE,
        }
    }
}

/// Writes a line/scatter chart of `series` to `<stem>.svg` and `<stem>.png`
/// (size `opts.size`).
///
/// Series get distinct colours (never red, which is kept for highlighted points) and a
/// legend entry when named. Ranges are automatic with a 5 % margin unless fixed in
/// `opts`; on a log axis, points with a non-positive coordinate on that axis are
/// silently dropped (see [`ChartOptions::log_x`]). Markers outside a fixed range are not
/// drawn; lines are clipped.
///
/// # Errors
/// [`PlotError::EmptyData`] if there is no point at all (also after dropping the points a
/// log axis cannot show); [`PlotError::NanData`] if a point, `hline` or fixed range is not
/// finite; [`PlotError::InvalidInput`] if a highlight mask has the wrong length, a fixed
/// range is empty/inverted (or not positive on a log axis) or a size is zero;
/// [`PlotError::Io`] / [`PlotError::Backend`] when writing fails.
pub fn line_chart(
    stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    opts: &ChartOptions,
) -> Result<Vec<PathBuf>, PlotError> {
    if opts.size.0 == 0 || opts.size.1 == 0 {
        return Err(PlotError::invalid(stem, format!("size {:?}", opts.size)));
    }
    if let Some(h) = opts.hline {
        if !h.is_finite() {
            return Err(PlotError::nan(stem, format!("hline {h}")));
        }
    }
    let mut kept = Vec::with_capacity(series.len());
    for (k, s) in series.iter().enumerate() {
        if let Some(i) = s
            .points
            .iter()
            .position(|(x, y)| !(x.is_finite() && y.is_finite()))
        {
            return Err(PlotError::nan(
                stem,
                format!("series {k} ({:?}), point {i}: {:?}", s.name, s.points[i]),
            ));
        }
        if !s.highlight.is_empty() && s.highlight.len() != s.points.len() {
            return Err(PlotError::invalid(
                stem,
                format!(
                    "series {k} ({:?}): {} highlight flags for {} points",
                    s.name,
                    s.highlight.len(),
                    s.points.len()
                ),
            ));
        }
        if !s.neutral.is_empty() && s.neutral.len() != s.points.len() {
            return Err(PlotError::invalid(
                stem,
                format!(
                    "series {k} ({:?}): {} neutral flags for {} points",
                    s.name,
                    s.neutral.len(),
                    s.points.len()
                ),
            ));
        }
        let pts: Vec<((f64, f64), Mark)> = s
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let mark = if s.highlight.get(i).copied().unwrap_or(false) {
                    Mark::Highlight
                } else if s.neutral.get(i).copied().unwrap_or(false) {
                    Mark::Neutral
                } else {
                    Mark::None
                };
                (*p, mark)
            })
            .filter(|((x, y), _)| (!opts.log_x || *x > 0.0) && (!opts.log_y || *y > 0.0))
            .collect();
        kept.push(pts);
    }
    let all = || kept.iter().flatten().map(|(p, _)| *p);
    if all().next().is_none() {
        return Err(PlotError::empty(
            stem,
            if opts.log_x || opts.log_y {
                "no point with positive log-axis coordinates"
            } else {
                "no point in any series"
            },
        ));
    }
    let hline = opts.hline.filter(|h| !opts.log_y || *h > 0.0);
    let xr = match opts.x_range {
        Some(r) => check_range(stem, "x", r, opts.log_x)?,
        None => auto(all().map(|p| p.0), opts.log_x),
    };
    let yr = match opts.y_range {
        Some(r) => check_range(stem, "y", r, opts.log_y)?,
        None => auto(all().map(|p| p.1).chain(hline), opts.log_y),
    };
    let fig = LineFig {
        title,
        x_label,
        y_label,
        series,
        kept,
        hline,
        opts,
        xr,
        yr,
    };
    render(stem, &fig)
}

fn auto(vals: impl Iterator<Item = f64>, log: bool) -> Range<f64> {
    let r = if log {
        auto_log(vals)
    } else {
        auto_linear(vals)
    };
    // Callers checked there is at least one (positive on log axes) value.
    r.unwrap_or(if log { 0.1..10.0 } else { -1.0..1.0 })
}

/// How a point is marked on top of its series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mark {
    None,
    Highlight,
    Neutral,
}

struct LineFig<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    series: &'a [Series],
    /// Points left after dropping those a log axis cannot show, with their mark.
    kept: Vec<Vec<((f64, f64), Mark)>>,
    hline: Option<f64>,
    opts: &'a ChartOptions,
    xr: Range<f64>,
    yr: Range<f64>,
}

impl Figure for LineFig<'_> {
    fn size(&self) -> (u32, u32) {
        self.opts.size
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        with_axes!(
            self.opts.log_x,
            self.opts.log_y,
            self.xr.clone(),
            self.yr.clone(),
            |x, y| self.draw_on(root, x, y)
        )
    }
}

impl LineFig<'_> {
    fn draw_on<DB, X, Y>(
        &self,
        root: &DrawingArea<DB, Shift>,
        x: X,
        y: Y,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
    where
        DB: DrawingBackend,
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, title_font())
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(75)
            .build_cartesian_2d(x, y)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label)
            .y_desc(self.y_label)
            .x_label_formatter(&tick_in(&self.xr, self.opts.log_x))
            .y_label_formatter(&tick_in(&self.yr, self.opts.log_y))
            .label_style(font(14))
            .axis_desc_style(font(16))
            .draw()?;

        if let Some(h) = self.hline {
            chart.draw_series(LineSeries::new(
                vec![(self.xr.start, h), (self.xr.end, h)],
                BLACK.mix(0.7).stroke_width(1),
            ))?;
        }

        let inside = |&(x, y): &(f64, f64)| self.xr.contains(&x) && self.yr.contains(&y);
        let mut legend = false;
        for (k, (s, pts)) in self.series.iter().zip(&self.kept).enumerate() {
            let color = series_colour(k);
            let line = matches!(s.style, SeriesStyle::Line | SeriesStyle::LineMarkers);
            let marks = matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers);
            let mut labelled = false;
            let mut add_label = |ann: &mut plotters::chart::SeriesAnno<'_, DB>| {
                if !s.name.is_empty() && !labelled {
                    ann.label(s.name.clone()).legend(move |(x, y)| {
                        Rectangle::new([(x, y - 5), (x + 14, y + 5)], color.filled())
                    });
                    labelled = true;
                    legend = true;
                }
            };
            if line && pts.len() >= 2 {
                let ann = chart.draw_series(LineSeries::new(
                    pts.iter().map(|(p, _)| *p),
                    color.stroke_width(2),
                ))?;
                add_label(ann);
            }
            let normal = pts
                .iter()
                .filter(|(p, h)| marks && *h != Mark::Highlight && inside(p));
            // circles for the first nine series, then the other shapes of
            // `series_marker`, so light/dark partner colours also differ in shape
            let ann = if k < 9 {
                chart.draw_series(normal.map(|(p, _)| Circle::new(*p, 3, color.filled())))?
            } else {
                chart.draw_series(normal.map(|(p, _)| {
                    EmptyElement::at(*p) + Polygon::new(series_marker(k, 3), color.filled())
                }))?
            };
            add_label(ann);
        }
        // Neutral rings, then highlighted points last, on top of every series.
        let marked = |m: Mark| -> Vec<(f64, f64)> {
            self.kept
                .iter()
                .flatten()
                .filter(|(p, h)| *h == m && inside(p))
                .map(|(p, _)| *p)
                .collect()
        };
        let nl = marked(Mark::Neutral);
        let ann = chart.draw_series(
            nl.iter()
                .map(|p| Circle::new(*p, 5, NEUTRAL.stroke_width(1))),
        )?;
        if let (Some(label), false) = (&self.opts.neutral_label, nl.is_empty()) {
            ann.label(label.clone())
                .legend(|(x, y)| Circle::new((x + 7, y), 5, NEUTRAL.stroke_width(1)));
            legend = true;
        }
        let hl = marked(Mark::Highlight);
        let ann = chart.draw_series(hl.iter().map(|p| Circle::new(*p, 5, HIGHLIGHT.filled())))?;
        if let (Some(label), false) = (&self.opts.highlight_label, hl.is_empty()) {
            ann.label(label.clone())
                .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], HIGHLIGHT.filled()));
            legend = true;
        }
        if legend {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .label_font(font(14))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.5))
                .draw()?;
        }
        Ok(())
    }
}
