//! Charts for squeal, written as SVG and PNG with no system font dependency.
//!
//! Every chart function takes an output *stem* (a path without extension) and writes two
//! files of the same pixel size next to each other: `<stem>.svg` and `<stem>.png`. It
//! returns their paths in that order. Missing parent directories are created.
//!
//! Text is rendered with DejaVu Sans, embedded in the crate (`fonts/DejaVuSans.ttf`,
//! licence in `fonts/LICENSE-DejaVu.txt`) and registered once with plotters under the
//! family name `"sans-serif"`; plotters is built without its `ttf` feature, so neither
//! fontconfig nor any installed font is needed. SVG files keep text as `<text>` elements.
//!
//! Units in axis labels are the caller's job (`"frequency (Hz)"`, `"DvR (1/s)"`), except
//! for [`contact_map`], which takes coordinates in metres and labels its axes in mm.
//!
//! ```no_run
//! use squeal_plot::{line_chart, ChartOptions, Series, SeriesStyle};
//! let modes = Series {
//!     name: "modes".into(),
//!     points: vec![(1200.0, -3.0), (2400.0, 0.0), (5100.0, 12.5)],
//!     style: SeriesStyle::Markers,
//!     highlight: vec![false, false, true], // unstable modes in red
//!     neutral: vec![false, true, false],   // neutral within the error bound: a ring
//! };
//! let opts = ChartOptions { hline: Some(0.0), ..ChartOptions::default() };
//! let files = line_chart(
//!     std::path::Path::new("out/stability"),
//!     "Stability map",
//!     "frequency (Hz)",
//!     "real part (1/s)",
//!     &[modes],
//!     &opts,
//! )?;
//! assert_eq!(files.len(), 2); // out/stability.svg, out/stability.png
//! # Ok::<(), squeal_plot::PlotError>(())
//! ```

use std::ffi::OsString;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

mod bar;
mod colormap;
mod contact;
mod line;
mod pareto;

pub use bar::bar_chart;
pub use contact::{contact_map, contact_map_size, layout_map, MapPanel};
pub use line::{line_chart, ChartOptions, Series, SeriesStyle};
pub use pareto::{pareto_chart, pareto_front};

/// Pixel size (width, height) of [`bar_chart`] outputs and of the plot area of
/// [`pareto_chart`] (which adds its legend strip), and the
/// default [`ChartOptions::size`] of [`line_chart`].
pub const CHART_SIZE: (u32, u32) = (900, 600);

/// Font family name under which the embedded DejaVu Sans is registered.
const FAMILY: &str = "sans-serif";

/// DejaVu Sans (Bitstream Vera licence, see `fonts/LICENSE-DejaVu.txt`).
static FONT_BYTES: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");
static FONT_ONCE: Once = Once::new();
static FONT_OK: AtomicBool = AtomicBool::new(false);

/// Registers the embedded font once per process; false if plotters rejected it.
fn ensure_font() -> bool {
    FONT_ONCE.call_once(|| {
        let ok = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT_BYTES).is_ok();
        FONT_OK.store(ok, Ordering::SeqCst);
    });
    FONT_OK.load(Ordering::SeqCst)
}

/// Errors of the chart functions. Each variant names the file (or output stem) concerned.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// Creating the output directory or writing an output file failed.
    #[error("cannot write {}: {source}", .path.display())]
    Io {
        /// The file or directory that could not be written.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The plotters drawing backend (or the embedded font) failed.
    #[error("drawing {} failed: {message}", .path.display())]
    Backend {
        /// The output file being drawn.
        path: PathBuf,
        /// The backend's error message.
        message: String,
    },
    /// Nothing to draw (no panels, no series, no points, or every point dropped from a
    /// log axis). Nothing is written.
    #[error("{}.{{svg,png}}: nothing to plot: {what}", .stem.display())]
    EmptyData {
        /// The output stem (the files would have been `<stem>.svg` and `<stem>.png`).
        stem: PathBuf,
        /// What is empty.
        what: String,
    },
    /// A value is NaN or infinite. Nothing is written.
    #[error("{}.{{svg,png}}: non-finite (NaN or infinite) data: {what}", .stem.display())]
    NanData {
        /// The output stem.
        stem: PathBuf,
        /// Where the first non-finite value is.
        what: String,
    },
    /// Inconsistent input (length mismatch, empty or inverted axis range, non-positive
    /// cell size, zero arrow, ...). Nothing is written.
    #[error("{}.{{svg,png}}: invalid input: {what}", .stem.display())]
    InvalidInput {
        /// The output stem.
        stem: PathBuf,
        /// What is wrong.
        what: String,
    },
}

impl PlotError {
    /// The output file, directory or stem this error is about.
    pub fn path(&self) -> &Path {
        match self {
            PlotError::Io { path, .. } | PlotError::Backend { path, .. } => path,
            PlotError::EmptyData { stem, .. }
            | PlotError::NanData { stem, .. }
            | PlotError::InvalidInput { stem, .. } => stem,
        }
    }

    pub(crate) fn empty(stem: &Path, what: impl Into<String>) -> Self {
        PlotError::EmptyData {
            stem: stem.to_path_buf(),
            what: what.into(),
        }
    }

    pub(crate) fn nan(stem: &Path, what: impl Into<String>) -> Self {
        PlotError::NanData {
            stem: stem.to_path_buf(),
            what: what.into(),
        }
    }

    pub(crate) fn invalid(stem: &Path, what: impl Into<String>) -> Self {
        PlotError::InvalidInput {
            stem: stem.to_path_buf(),
            what: what.into(),
        }
    }
}

/// A chart that can be drawn on any plotters backend (SVG and bitmap).
pub(crate) trait Figure {
    /// Pixel size of the drawing.
    fn size(&self) -> (u32, u32);
    /// Draws the whole figure on `root` (already filled white).
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>;
}

/// `<stem>.<ext>` (appends, so a stem containing dots keeps them).
fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s: OsString = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

fn backend_err(path: &Path, e: impl std::fmt::Display) -> PlotError {
    PlotError::Backend {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Draws `fig` twice, to `<stem>.svg` and `<stem>.png`.
pub(crate) fn render(stem: &Path, fig: &impl Figure) -> Result<Vec<PathBuf>, PlotError> {
    let svg = with_ext(stem, "svg");
    let png = with_ext(stem, "png");
    if !ensure_font() {
        return Err(backend_err(
            &svg,
            "the embedded DejaVu Sans font was rejected",
        ));
    }
    if let Some(parent) = svg.parent() {
        if !parent.as_os_str().is_empty() {
            std::fs::create_dir_all(parent).map_err(|source| PlotError::Io {
                path: parent.to_path_buf(),
                source,
            })?;
        }
    }
    let size = fig.size();

    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| backend_err(&svg, e))?;
        fig.draw(&root).map_err(|e| backend_err(&svg, e))?;
        root.present().map_err(|e| backend_err(&svg, e))?;
    }
    std::fs::write(&svg, text).map_err(|source| PlotError::Io {
        path: svg.clone(),
        source,
    })?;

    // Create the file first so that an unwritable location is reported as I/O.
    std::fs::File::create(&png).map_err(|source| PlotError::Io {
        path: png.clone(),
        source,
    })?;
    {
        let root = BitMapBackend::new(&png, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| backend_err(&png, e))?;
        fig.draw(&root).map_err(|e| backend_err(&png, e))?;
        root.present().map_err(|e| backend_err(&png, e))?;
    }
    Ok(vec![svg, png])
}

// ---------------------------------------------------------------------------------------
// Shared styling helpers.

/// Qualitative palette for series: tab10 without its red (which marks highlights), then
/// the light tab20 partners of those nine, so up to 18 series get distinct colours.
pub(crate) const PALETTE: [RGBColor; 18] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(174, 199, 232),
    RGBColor(255, 187, 120),
    RGBColor(152, 223, 138),
    RGBColor(197, 176, 213),
    RGBColor(196, 156, 148),
    RGBColor(247, 182, 210),
    RGBColor(199, 199, 199),
    RGBColor(219, 219, 141),
    RGBColor(158, 218, 229),
];

/// Colour of series `k`: [`PALETTE`] for the first 18, then hues spaced by the golden
/// angle (skipping the reds kept for highlights) at alternating lightness, so no two
/// series share a colour however many there are.
pub(crate) fn series_colour(k: usize) -> RGBColor {
    if let Some(c) = PALETTE.get(k) {
        return *c;
    }
    let j = k - PALETTE.len();
    // hues in [0.1, 0.9] of the circle: away from red at 0
    let h = 0.1 + 0.8 * (0.13 + j as f64 * 0.618_033_988_75).fract();
    let l = if j % 2 == 0 { 0.38 } else { 0.58 };
    let (r, g, b) = hsl_to_rgb(h, 0.65, l);
    RGBColor(r, g, b)
}

fn hsl_to_rgb(h: f64, s: f64, l: f64) -> (u8, u8, u8) {
    let c = (1.0 - (2.0 * l - 1.0).abs()) * s;
    let hp = h * 6.0;
    let x = c * (1.0 - (hp % 2.0 - 1.0).abs());
    let (r, g, b) = match hp as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = l - c / 2.0;
    let q = |v: f64| ((v + m) * 255.0).round().clamp(0.0, 255.0) as u8;
    (q(r), q(g), q(b))
}

/// Marker outline of series `k`, as pixel offsets around the point, `r` pixels in
/// radius: circles for the first 9 series (the strong colours of [`PALETTE`]), then
/// squares, triangles and diamonds, so that series whose colours are light/dark
/// partners also differ in shape.
pub(crate) fn series_marker(k: usize, r: i32) -> Vec<(i32, i32)> {
    let rf = f64::from(r);
    let poly = |n: usize, phase: f64, scale: f64| -> Vec<(i32, i32)> {
        (0..n)
            .map(|i| {
                let a = phase + std::f64::consts::TAU * i as f64 / n as f64;
                (
                    (scale * rf * a.cos()).round() as i32,
                    (-scale * rf * a.sin()).round() as i32,
                )
            })
            .collect()
    };
    match (k / 9) % 4 {
        0 => poly(20, 0.0, 1.0),
        1 => poly(4, std::f64::consts::FRAC_PI_4, 1.2),
        2 => poly(3, std::f64::consts::FRAC_PI_2, 1.3),
        _ => poly(4, 0.0, 1.3),
    }
}

/// Colour of highlighted points (unstable modes, Pareto front).
pub(crate) const HIGHLIGHT: RGBColor = RGBColor(214, 39, 40);

/// Colour of the ring of neutral points (modes within their error bound).
pub(crate) const NEUTRAL: RGBColor = RGBColor(255, 140, 0);

pub(crate) fn title_font() -> TextStyle<'static> {
    font(24)
}

pub(crate) fn font(size: u32) -> TextStyle<'static> {
    (FAMILY, size).into_font().into()
}

/// Tick label: plain decimals for moderate magnitudes, compact scientific otherwise.
pub(crate) fn fmt_tick(v: &f64) -> String {
    let v = *v;
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.2e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.')
        } else {
            m
        };
        format!("{m}e{e}")
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.to_string()
        }
    }
}

/// [`fmt_tick`] for an axis spanning `range`: on a linear axis a tick that is zero to
/// round-off of the span (a linear axis through 0 computes its 0 tick as 6.9e-18) reads
/// `0`; a logarithmic axis keeps its small values.
pub(crate) fn tick_in(range: &Range<f64>, log: bool) -> impl Fn(&f64) -> String {
    let span = (range.end - range.start).abs();
    move |v: &f64| {
        if !log && v.abs() <= 1e-9 * span {
            "0".into()
        } else {
            fmt_tick(v)
        }
    }
}

/// Automatic linear range of `vals` with a 5 % margin (a unit-ish window if degenerate).
pub(crate) fn auto_linear(vals: impl Iterator<Item = f64>) -> Option<Range<f64>> {
    let (lo, hi) = min_max(vals)?;
    if hi > lo {
        let m = 0.05 * (hi - lo);
        Some(lo - m..hi + m)
    } else {
        let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        Some(lo - d..hi + d)
    }
}

/// Automatic log range of positive `vals` with a margin of 5 % of the decades spanned,
/// widened down to a power of ten when it holds none ([`with_decade`]).
pub(crate) fn auto_log(vals: impl Iterator<Item = f64>) -> Option<Range<f64>> {
    let (lo, hi) = min_max(vals.filter(|v| *v > 0.0))?;
    if hi > lo {
        let f = (hi / lo).powf(0.05).max(1.05);
        Some(with_decade(lo / f..hi * f))
    } else {
        Some(with_decade(lo / 2.0..hi * 2.0))
    }
}

/// A positive log range that holds a power of ten: plotters puts log-axis ticks at the
/// powers of ten in range (and at their multiples after the first one), so a range
/// inside one decade would have no tick label at all. Such a range is extended down to
/// the power of ten below it.
pub(crate) fn with_decade(r: Range<f64>) -> Range<f64> {
    let below = 10f64.powf(r.start.log10().floor());
    let next = below * 10.0;
    if r.start > below && next > r.end {
        // 1.0001 keeps the tick inside the range despite round-off of powf
        below / 1.0001..r.end
    } else {
        r
    }
}

fn min_max(vals: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    vals.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Checks a user-given axis range: finite, increasing, positive on a log axis.
pub(crate) fn check_range(
    stem: &Path,
    axis: &str,
    r: (f64, f64),
    log: bool,
) -> Result<Range<f64>, PlotError> {
    if !(r.0.is_finite() && r.1.is_finite()) {
        return Err(PlotError::nan(stem, format!("{axis} range {r:?}")));
    }
    if r.0 >= r.1 {
        return Err(PlotError::invalid(
            stem,
            format!("{axis} range {r:?} is empty or inverted"),
        ));
    }
    if log && r.0 <= 0.0 {
        return Err(PlotError::invalid(
            stem,
            format!("{axis} range {r:?} must be positive on a log axis"),
        ));
    }
    Ok(r.0..r.1)
}

/// Builds linear (`RangedCoordf64`) or log (`LogCoord<f64>`) coordinates from two
/// `Range<f64>` and evaluates `$body` with them bound to `$x`, `$y`.
macro_rules! with_axes {
    ($logx:expr, $logy:expr, $xr:expr, $yr:expr, |$x:ident, $y:ident| $body:expr) => {{
        use plotters::coord::types::RangedCoordf64;
        use plotters::prelude::{IntoLogRange as _, LogCoord};
        let (xr, yr): (std::ops::Range<f64>, std::ops::Range<f64>) = ($xr, $yr);
        match ($logx, $logy) {
            (false, false) => {
                let $x: RangedCoordf64 = xr.into();
                let $y: RangedCoordf64 = yr.into();
                $body
            }
            (true, false) => {
                let $x: LogCoord<f64> = xr.log_scale().into();
                let $y: RangedCoordf64 = yr.into();
                $body
            }
            (false, true) => {
                let $x: RangedCoordf64 = xr.into();
                let $y: LogCoord<f64> = yr.log_scale().into();
                $body
            }
            (true, true) => {
                let $x: LogCoord<f64> = xr.log_scale().into();
                let $y: LogCoord<f64> = yr.log_scale().into();
                $body
            }
        }
    }};
}
pub(crate) use with_axes;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_format() {
        assert_eq!(fmt_tick(&0.0), "0");
        assert_eq!(fmt_tick(&0.30000000000000004), "0.3");
        assert_eq!(fmt_tick(&1500.0), "1500");
        assert_eq!(fmt_tick(&1e-6), "1e-6");
        assert_eq!(fmt_tick(&2.5e6), "2.5e6");
        assert_eq!(fmt_tick(&-1e-12), "-1e-12");
        // a zero tick computed to round-off reads 0 on a linear axis
        let t = tick_in(&(-0.05..0.05), false);
        assert_eq!(t(&6.94e-18), "0");
        assert_eq!(t(&0.01), "0.01");
        assert_eq!(tick_in(&(1e-12..1e-2), true)(&1e-12), "1e-12");
    }

    #[test]
    fn series_colours_are_distinct_and_not_red() {
        let cs: Vec<RGBColor> = (0..60).map(series_colour).collect();
        for i in 0..cs.len() {
            for j in 0..i {
                assert_ne!(cs[i], cs[j], "series {i} and {j}");
            }
            assert_ne!(cs[i], HIGHLIGHT, "series {i}");
            // no pure reds: red well above both green and blue
            let RGBColor(r, g, b) = cs[i];
            assert!(
                !(r > 150 && g < 90 && b < 90),
                "series {i} is red: {:?}",
                cs[i]
            );
        }
        assert_eq!(series_colour(3), PALETTE[3]);
    }

    #[test]
    fn series_markers_differ_between_light_and_dark_partners() {
        // series k and k + 9 have light/dark partner colours: their shapes differ
        for k in 0..9 {
            assert_ne!(series_marker(k, 6).len(), 0);
            assert_ne!(series_marker(k, 6), series_marker(k + 9, 6), "series {k}");
        }
        assert_ne!(series_marker(18, 6), series_marker(27, 6));
    }

    #[test]
    fn log_ranges_hold_a_power_of_ten() {
        // inside one decade: extended down to the power below
        let r = with_decade(2.0e-9..7.0e-9);
        assert!(
            r.start <= 1e-9 && r.start > 0.9e-9 && r.end == 7.0e-9,
            "{r:?}"
        );
        // already holding a power of ten: unchanged
        assert_eq!(with_decade(0.5..3.0), 0.5..3.0);
        assert_eq!(with_decade(1e-3..1e3), 1e-3..1e3);
        let r = auto_log([3.1e-6, 3.3e-6].into_iter()).unwrap();
        assert!(r.start < 1e-6 && r.end > 3.3e-6, "{r:?}");
    }

    #[test]
    fn auto_ranges() {
        let r = auto_linear([0.0, 10.0].into_iter()).unwrap();
        assert!((r.start + 0.5).abs() < 1e-12 && (r.end - 10.5).abs() < 1e-12);
        let r = auto_linear([3.0].into_iter()).unwrap();
        assert!(r.start < 3.0 && r.end > 3.0);
        let r = auto_log([-1.0, 0.0, 1e-3, 1e3].into_iter()).unwrap();
        assert!(r.start > 0.0 && r.start < 1e-3 && r.end > 1e3);
        assert!(auto_log([-1.0, 0.0].into_iter()).is_none());
    }

    #[test]
    fn ext_appends() {
        assert_eq!(
            with_ext(Path::new("a/b.v2"), "svg"),
            PathBuf::from("a/b.v2.svg")
        );
    }
}
