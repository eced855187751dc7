//! Contact maps: one panel per contact set, either a shared colour scale ([`contact_map`],
//! e.g. the normal force) or two colours for pairs in and out of contact ([`layout_map`]).

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::colormap::viridis;
use crate::{font, render, tick_in, title_font, Figure, PlotError, HIGHLIGHT};

/// One panel of a [`contact_map`]: the contact pairs of one contact set (or one load case).
///
/// Coordinates and sizes are in metres; the map shows them in mm.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MapPanel {
    /// Panel caption, e.g. `"mu = 0.4"` or `"pad, inner"`.
    pub title: String,
    /// In-plane position (x, y) of each contact pair, in metres.
    pub xy: Vec<[f64; 2]>,
    /// Value of each pair (same length as `xy`), e.g. the normal force in N.
    /// Values `<= 0` are drawn as open pairs (light grey); positive values use the
    /// shared viridis scale from 0 to the largest value over all panels.
    pub values: Vec<f64>,
    /// Width and height (x, y) of the square drawn for each pair, in metres
    /// (typically the contact element size). Both must be positive. Unused when `cells`
    /// is given.
    pub cell: [f64; 2],
    /// The rectangle drawn for each pair, `[x_min, x_max, y_min, y_max]` in metres (same
    /// length as `xy`), for grids whose spacing varies (a refined contact zone); empty
    /// draws a `cell`-sized rectangle centred on each pair.
    pub cells: Vec<[f64; 4]>,
    /// Sliding direction in the x-y plane, drawn as an arrow from the panel centre.
    /// Normalised before drawing; `None` draws no arrow.
    pub arrow: Option<[f64; 2]>,
    /// Text drawn at the arrow tip, e.g. `"sliding"` or `"v = 1 m/s"`.
    pub arrow_label: String,
}

/// Colour of open pairs (value `<= 0`).
const OPEN: RGBColor = RGBColor(222, 222, 222);
/// Colour of closed pairs in a [`layout_map`].
const CLOSED: RGBColor = RGBColor(31, 119, 180);
/// Panels per row before wrapping to a grid.
const MAX_COLS: usize = 3;
const PANEL_W: u32 = 440;
const PANEL_H: u32 = 420;
const CBAR_W: u32 = 150;
/// Of the colour-bar strip: the tick label area and the title strip at its right edge.
const CBAR_TICKS_W: u32 = 62;
const CBAR_TITLE_W: u32 = 28;
const TITLE_H: u32 = 50;
/// Margins and label areas of a panel chart (pixels), used for the equal-aspect ranges.
const MARGIN: u32 = 12;
const X_LABEL_H: u32 = 45;
const Y_LABEL_W: u32 = 65;
const CAPTION_H: u32 = 30;

/// Pixel size (width, height) of a [`contact_map`] with `n_panels` panels: panels of
/// 440 x 420 px, at most 3 per row, plus a 150 px colour bar strip and a 50 px title.
pub fn contact_map_size(n_panels: usize) -> (u32, u32) {
    let (rows, cols) = grid(n_panels);
    (
        cols as u32 * PANEL_W + CBAR_W,
        rows as u32 * PANEL_H + TITLE_H,
    )
}

fn grid(n: usize) -> (usize, usize) {
    let n = n.max(1);
    let cols = n.min(MAX_COLS);
    (n.div_ceil(cols), cols)
}

/// Writes a contact map to `<stem>.svg` and `<stem>.png` (size [`contact_map_size`]).
///
/// One panel per entry of `panels`, side by side (a grid of 3 columns beyond 3 panels).
/// Each pair is a filled rectangle (its `cells` entry, or `cell` centred on it), coloured on a
/// colour scale shared by all panels: light grey for open pairs (value `<= 0`), viridis
/// from 0 to the largest value for closed pairs. A colour bar on the right is labelled
/// `value_label` (give the unit: `"normal force (N)"`). Inputs are metres; axes are
/// labelled `x (mm)` and `y (mm)` with equal scales. When `arrow` is set, an arrow from
/// the panel centre shows the sliding direction, with `arrow_label` at its tip.
///
/// # Errors
/// [`PlotError::EmptyData`] if there is no panel or a panel has no pair;
/// [`PlotError::NanData`] for a non-finite position, value, cell or arrow;
/// [`PlotError::InvalidInput`] if `xy` and `values` differ in length, a cell size is not
/// positive or an arrow has zero length; [`PlotError::Io`] / [`PlotError::Backend`] when
/// writing fails.
pub fn contact_map(
    stem: &Path,
    title: &str,
    value_label: &str,
    panels: &[MapPanel],
) -> Result<Vec<PathBuf>, PlotError> {
    draw_map(stem, title, Legend::Scale(value_label), panels)
}

/// Writes a contact layout map to `<stem>.svg` and `<stem>.png` (size
/// [`contact_map_size`]): like [`contact_map`], but pairs with a positive value are drawn
/// in one colour and open pairs (value `<= 0`) in light grey, with a two-entry legend
/// (`closed_label`, "open") in place of the colour bar. For contact layouts, where a
/// pair is in contact or not.
///
/// # Errors
/// As [`contact_map`].
pub fn layout_map(
    stem: &Path,
    title: &str,
    closed_label: &str,
    panels: &[MapPanel],
) -> Result<Vec<PathBuf>, PlotError> {
    draw_map(stem, title, Legend::TwoColours(closed_label), panels)
}

fn draw_map(
    stem: &Path,
    title: &str,
    legend: Legend<'_>,
    panels: &[MapPanel],
) -> Result<Vec<PathBuf>, PlotError> {
    let vmax = check_panels(stem, panels)?;
    let fig = ContactFig {
        title,
        legend,
        panels,
        vmax,
    };
    render(stem, &fig)
}

/// Checks the panels of a map; returns the largest value over all of them (at least 0).
fn check_panels(stem: &Path, panels: &[MapPanel]) -> Result<f64, PlotError> {
    if panels.is_empty() {
        return Err(PlotError::empty(stem, "no panel"));
    }
    let mut vmax = 0.0f64;
    for (k, p) in panels.iter().enumerate() {
        let name = format!("panel {k} ({:?})", p.title);
        if p.xy.is_empty() {
            return Err(PlotError::empty(stem, format!("{name} has no pair")));
        }
        if p.xy.len() != p.values.len() {
            return Err(PlotError::invalid(
                stem,
                format!(
                    "{name}: {} positions but {} values",
                    p.xy.len(),
                    p.values.len()
                ),
            ));
        }
        if let Some(i) = p.xy.iter().position(|q| !q.iter().all(|c| c.is_finite())) {
            return Err(PlotError::nan(
                stem,
                format!("{name}: position of pair {i}"),
            ));
        }
        if let Some(i) = p.values.iter().position(|v| !v.is_finite()) {
            return Err(PlotError::nan(stem, format!("{name}: value of pair {i}")));
        }
        if !p.cell.iter().all(|c| c.is_finite()) {
            return Err(PlotError::nan(stem, format!("{name}: cell {:?}", p.cell)));
        }
        if !p.cell.iter().all(|c| *c > 0.0) {
            return Err(PlotError::invalid(
                stem,
                format!("{name}: cell {:?} must be positive", p.cell),
            ));
        }
        if let Some(a) = p.arrow {
            if !a.iter().all(|c| c.is_finite()) {
                return Err(PlotError::nan(stem, format!("{name}: arrow {a:?}")));
            }
            if a[0] == 0.0 && a[1] == 0.0 {
                return Err(PlotError::invalid(stem, format!("{name}: zero arrow")));
            }
        }
        if !p.cells.is_empty() {
            if p.cells.len() != p.xy.len() {
                return Err(PlotError::invalid(
                    stem,
                    format!(
                        "{name}: {} positions but {} cells",
                        p.xy.len(),
                        p.cells.len()
                    ),
                ));
            }
            if let Some(i) = p
                .cells
                .iter()
                .position(|c| !c.iter().all(|v| v.is_finite()))
            {
                return Err(PlotError::nan(stem, format!("{name}: cell of pair {i}")));
            }
            if let Some(i) = p.cells.iter().position(|c| c[1] <= c[0] || c[3] <= c[2]) {
                return Err(PlotError::invalid(
                    stem,
                    format!(
                        "{name}: cell of pair {i} {:?} must have x_min < x_max and \
                         y_min < y_max",
                        p.cells[i]
                    ),
                ));
            }
        }
        vmax = p.values.iter().fold(vmax, |m, v| m.max(*v));
    }
    Ok(vmax)
}

/// What the strip right of the panels shows.
enum Legend<'a> {
    /// A viridis colour bar from 0 to the largest value, with this label.
    Scale(&'a str),
    /// One swatch for closed pairs, with this label, and one for open pairs.
    TwoColours(&'a str),
}

/// Rectangle `[x_min, x_max, y_min, y_max]` (mm) of pair `k` of `p`.
fn rect_mm(p: &MapPanel, k: usize) -> [f64; 4] {
    match p.cells.get(k) {
        Some(c) => c.map(|v| v * 1e3),
        None => {
            let (x, y) = (p.xy[k][0] * 1e3, p.xy[k][1] * 1e3);
            let (hx, hy) = (0.5e3 * p.cell[0], 0.5e3 * p.cell[1]);
            [x - hx, x + hx, y - hy, y + hy]
        }
    }
}

struct ContactFig<'a> {
    title: &'a str,
    legend: Legend<'a>,
    panels: &'a [MapPanel],
    /// Largest value over all panels (0 when every pair is open).
    vmax: f64,
}

impl ContactFig<'_> {
    fn color(&self, v: f64) -> RGBColor {
        match self.legend {
            _ if v <= 0.0 || self.vmax <= 0.0 => OPEN,
            Legend::Scale(_) => viridis(v / self.vmax),
            Legend::TwoColours(_) => CLOSED,
        }
    }

    fn vtop(&self) -> f64 {
        if self.vmax > 0.0 {
            self.vmax
        } else {
            1.0
        }
    }
}

/// Axis ranges in mm of a panel drawn in an area of `px` pixels, with equal mm per pixel
/// on both axes and a 5 % margin.
fn panel_ranges(p: &MapPanel, px: (u32, u32)) -> (Range<f64>, Range<f64>) {
    let mut b = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for k in 0..p.xy.len() {
        let r = rect_mm(p, k);
        b = [
            b[0].min(r[0]),
            b[1].max(r[1]),
            b[2].min(r[2]),
            b[3].max(r[3]),
        ];
    }
    let (cx, cy) = (0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]));
    let (sx, sy) = (1.1 * (b[1] - b[0]), 1.1 * (b[3] - b[2]));
    let w = px.0.saturating_sub(Y_LABEL_W + 2 * MARGIN).max(10) as f64;
    let h =
        px.1.saturating_sub(X_LABEL_H + CAPTION_H + 2 * MARGIN)
            .max(10) as f64;
    let mm_per_px = (sx / w).max(sy / h);
    let (sx, sy) = (0.5 * mm_per_px * w, 0.5 * mm_per_px * h);
    (cx - sx..cx + sx, cy - sy..cy + sy)
}

impl Figure for ContactFig<'_> {
    fn size(&self) -> (u32, u32) {
        contact_map_size(self.panels.len())
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (w, _) = root.dim_in_pixel();
        let (head, body) = root.split_vertically(TITLE_H);
        head.draw(&Text::new(
            self.title.to_string(),
            (w as i32 / 2, TITLE_H as i32 / 2),
            title_font().pos(Pos::new(HPos::Center, VPos::Center)),
        ))?;
        let (maps, bar) = body.split_horizontally(w - CBAR_W);
        let (rows, cols) = grid(self.panels.len());
        let areas = maps.split_evenly((rows, cols));
        for (p, area) in self.panels.iter().zip(areas.iter()) {
            self.draw_panel(p, area)?;
        }
        match self.legend {
            Legend::Scale(label) => self.draw_colour_bar(&bar, label),
            Legend::TwoColours(label) => {
                let y = (CAPTION_H + MARGIN) as i32;
                swatch(&bar, y, CLOSED, label)?;
                swatch(&bar, y + 30, OPEN, "open")
            }
        }
    }
}

impl ContactFig<'_> {
    fn draw_panel<DB: DrawingBackend>(
        &self,
        p: &MapPanel,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (xr, yr) = panel_ranges(p, area.dim_in_pixel());
        // the caption in 18 px, or smaller down to 11 px when it would spill into the
        // next panel
        let room = area.dim_in_pixel().0.saturating_sub(2 * MARGIN);
        let mut size = 18;
        while size > 11 && area.estimate_text_size(&p.title, &font(size))?.0 > room {
            size -= 1;
        }
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, font(size))
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_H)
            .y_label_area_size(Y_LABEL_W)
            .build_cartesian_2d(xr.clone(), yr.clone())?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x (mm)")
            .y_desc("y (mm)")
            .x_labels(6)
            .y_labels(6)
            .x_label_formatter(&tick_in(&xr, false))
            .y_label_formatter(&tick_in(&yr, false))
            .label_style(font(13))
            .axis_desc_style(font(15))
            .draw()?;
        chart.draw_series(p.values.iter().enumerate().map(|(k, &v)| {
            let r = rect_mm(p, k);
            Rectangle::new([(r[0], r[3]), (r[1], r[2])], self.color(v).filled())
        }))?;

        if let Some(a) = p.arrow {
            let n = a[0].hypot(a[1]);
            let (ux, uy) = (a[0] / n, a[1] / n);
            // Centre of the pairs, arrow length 30 % of the shorter visible span.
            let (cx, cy) = (0.5 * (xr.start + xr.end), 0.5 * (yr.start + yr.end));
            let len = 0.3 * (xr.end - xr.start).min(yr.end - yr.start);
            let tip = (cx + len * ux, cy + len * uy);
            let (hl, hw) = (0.25 * len, 0.12 * len);
            let base = (tip.0 - hl * ux, tip.1 - hl * uy);
            let style = ShapeStyle::from(HIGHLIGHT).stroke_width(3);
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(cx, cy), base],
                style,
            )))?;
            chart.draw_series(std::iter::once(Polygon::new(
                vec![
                    tip,
                    (base.0 - hw * uy, base.1 + hw * ux),
                    (base.0 + hw * uy, base.1 - hw * ux),
                ],
                HIGHLIGHT.filled(),
            )))?;
            if !p.arrow_label.is_empty() {
                let hpos = if ux < -0.3 {
                    HPos::Right
                } else if ux > 0.3 {
                    HPos::Left
                } else {
                    HPos::Center
                };
                let vpos = if uy > 0.3 {
                    VPos::Bottom
                } else if uy < -0.3 {
                    VPos::Top
                } else {
                    VPos::Center
                };
                let at = (tip.0 + 0.05 * len * ux, tip.1 + 0.05 * len * uy);
                chart.draw_series(std::iter::once(Text::new(
                    p.arrow_label.clone(),
                    at,
                    font(15).color(&HIGHLIGHT).pos(Pos::new(hpos, vpos)),
                )))?;
            }
        }
        Ok(())
    }

    fn draw_colour_bar<DB: DrawingBackend>(
        &self,
        bar: &DrawingArea<DB, Shift>,
        value_label: &str,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let (w, h) = bar.dim_in_pixel();
        let vtop = self.vtop();
        let top = CAPTION_H + MARGIN;
        let bottom = X_LABEL_H + MARGIN + 30;
        // The title is drawn in its own strip at the right edge, not as the axis
        // description, which plotters places over tick labels wider than its guess.
        let mut cb = ChartBuilder::on(bar)
            .margin_top(top)
            .margin_bottom(bottom)
            .margin_left(10)
            .margin_right(CBAR_TITLE_W)
            .set_label_area_size(LabelAreaPosition::Right, CBAR_TICKS_W)
            .build_cartesian_2d(0.0..1.0, 0.0..vtop)?;
        let ticks = tick_in(&(0.0..vtop), false);
        cb.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(6)
            .y_label_formatter(&ticks)
            .label_style(font(13))
            .draw()?;
        let mid = (top as i32 + (h as i32 - bottom as i32)) / 2;
        bar.draw(&Text::new(
            value_label.to_string(),
            (w as i32 - CBAR_TITLE_W as i32 / 2, mid),
            font(15)
                .transform(FontTransform::Rotate90)
                .pos(Pos::new(HPos::Center, VPos::Center)),
        ))?;
        const STEPS: usize = 64;
        cb.draw_series((0..STEPS).map(|k| {
            let (y0, y1) = (
                vtop * k as f64 / STEPS as f64,
                vtop * (k + 1) as f64 / STEPS as f64,
            );
            let c = if self.vmax > 0.0 {
                viridis((k as f64 + 0.5) / STEPS as f64)
            } else {
                OPEN
            };
            Rectangle::new([(0.0, y1), (1.0, y0)], c.filled())
        }))?;
        // Swatch for open pairs below the bar.
        swatch(
            bar,
            h as i32 - X_LABEL_H as i32 - MARGIN as i32 + 5,
            OPEN,
            "open (0)",
        )
    }
}

/// A framed colour swatch at height `y` (pixels) of the legend strip, `label` on its right.
fn swatch<DB: DrawingBackend>(
    bar: &DrawingArea<DB, Shift>,
    y: i32,
    colour: RGBColor,
    label: &str,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    bar.draw(&Rectangle::new([(10, y), (34, y + 18)], colour.filled()))?;
    bar.draw(&Rectangle::new(
        [(10, y), (34, y + 18)],
        BLACK.stroke_width(1),
    ))?;
    bar.draw(&Text::new(
        label.to_string(),
        (40, y + 9),
        font(14).pos(Pos::new(HPos::Left, VPos::Center)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_and_clamp() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(2.0), viridis(1.0));
        assert_eq!(viridis(-1.0), viridis(0.0));
        assert_eq!(viridis(0.5), RGBColor(38, 130, 142));
    }

    #[test]
    fn grid_layout() {
        assert_eq!(grid(1), (1, 1));
        assert_eq!(grid(3), (1, 3));
        assert_eq!(grid(4), (2, 3));
        assert_eq!(grid(7), (3, 3));
        assert_eq!(contact_map_size(2), (2 * 440 + 150, 420 + 50));
    }

    #[test]
    fn equal_aspect_ranges_contain_cells() {
        let p = MapPanel {
            xy: vec![[0.0, 0.0], [0.02, 0.0], [0.02, 0.005]],
            values: vec![1.0; 3],
            cell: [0.002, 0.001],
            ..MapPanel::default()
        };
        let px = (440, 420);
        let (xr, yr) = panel_ranges(&p, px);
        assert!(xr.start <= -1.0 && xr.end >= 21.0);
        assert!(yr.start <= -0.5 && yr.end >= 5.5);
        let w = (px.0 - Y_LABEL_W - 2 * MARGIN) as f64;
        let h = (px.1 - X_LABEL_H - CAPTION_H - 2 * MARGIN) as f64;
        let (ax, ay) = ((xr.end - xr.start) / w, (yr.end - yr.start) / h);
        assert!((ax - ay).abs() < 1e-9 * ax, "{ax} vs {ay}");
    }
}
