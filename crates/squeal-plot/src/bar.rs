//! Bar charts (timings per method, error per mode, ...).

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::PALETTE;
use crate::{
    auto_linear, fmt_tick, font, render, tick_in, title_font, Figure, PlotError, CHART_SIZE,
};

/// Writes a bar chart to `<stem>.svg` and `<stem>.png` (size [`CHART_SIZE`]).
///
/// One bar per `(label, value)` in the given order, labelled below the axis, with its value
/// printed at its end. The value axis always includes 0; negative values give bars below 0.
///
/// # Errors
/// [`PlotError::EmptyData`] if `bars` is empty; [`PlotError::NanData`] if a value is NaN or
/// infinite; [`PlotError::Io`] / [`PlotError::Backend`] when writing fails.
pub fn bar_chart(
    stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    bars: &[(String, f64)],
) -> Result<Vec<PathBuf>, PlotError> {
    if bars.is_empty() {
        return Err(PlotError::empty(stem, "no bar"));
    }
    if let Some((l, v)) = bars.iter().find(|(_, v)| !v.is_finite()) {
        return Err(PlotError::nan(stem, format!("bar {l:?}: {v}")));
    }
    let yr = auto_linear(bars.iter().map(|b| b.1).chain([0.0])).expect("at least one value");
    // Bars start at 0: no margin below 0 for non-negative data (and none above for
    // non-positive data).
    let lo = if bars.iter().all(|b| b.1 >= 0.0) {
        0.0
    } else {
        yr.start
    };
    let hi = if bars.iter().all(|b| b.1 <= 0.0) {
        0.0
    } else {
        yr.end
    };
    let yr = if hi > lo { lo..hi } else { 0.0..1.0 };
    let fig = BarFig {
        title,
        x_label,
        y_label,
        bars,
        yr,
    };
    render(stem, &fig)
}

struct BarFig<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    bars: &'a [(String, f64)],
    yr: Range<f64>,
}

impl Figure for BarFig<'_> {
    fn size(&self) -> (u32, u32) {
        CHART_SIZE
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let n = self.bars.len();
        // Bar i is centred at x = i, with a tick (and its label) there only.
        let x = BarAxis { n };
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, title_font())
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(75)
            .build_cartesian_2d(x, self.yr.clone())?;
        let names = |v: &f64| {
            let i = v.round();
            if (v - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < n {
                self.bars[i as usize].0.clone()
            } else {
                String::new()
            }
        };
        let label_size = if n > 10 { 11 } else { 14 };
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n)
            .x_desc(self.x_label)
            .y_desc(self.y_label)
            .x_label_formatter(&names)
            .y_label_formatter(&tick_in(&self.yr, false))
            .x_label_style(font(label_size))
            .y_label_style(font(14))
            .axis_desc_style(font(16))
            .draw()?;
        chart.draw_series(self.bars.iter().enumerate().map(|(i, (_, v))| {
            let x = i as f64;
            let (top, bottom) = if *v >= 0.0 { (*v, 0.0) } else { (0.0, *v) };
            Rectangle::new([(x - 0.35, top), (x + 0.35, bottom)], PALETTE[0].filled())
        }))?;
        chart.draw_series(self.bars.iter().enumerate().map(|(i, (_, v))| {
            let (dy, vpos) = if *v >= 0.0 {
                (-3, VPos::Bottom)
            } else {
                (3, VPos::Top)
            };
            EmptyElement::at((i as f64, *v))
                + Text::new(
                    fmt_tick(v),
                    (0, dy),
                    font(13).pos(Pos::new(HPos::Center, vpos)),
                )
        }))?;
        Ok(())
    }
}

/// Category axis: x from -0.5 to n - 0.5, key points (ticks, labels, grid) at the bar
/// centres 0, 1, ..., n - 1 only.
#[derive(Clone)]
struct BarAxis {
    n: usize,
}

impl Ranged for BarAxis {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let t = (value + 0.5) / self.n as f64;
        limit.0 + (t * (limit.1 - limit.0) as f64).round() as i32
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        // Every bar if there is room for all of them, else none (no partial labelling).
        if hint.max_num_points() >= self.n {
            (0..self.n).map(|i| i as f64).collect()
        } else {
            Vec::new()
        }
    }

    fn range(&self) -> Range<f64> {
        -0.5..self.n as f64 - 0.5
    }
}
