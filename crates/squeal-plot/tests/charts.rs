//! Every chart function writes a parseable SVG and a PNG of the documented size, with the
//! expected marks; bad input gives a `PlotError` naming the output and writes nothing.

use std::path::{Path, PathBuf};

use squeal_plot::{
    bar_chart, contact_map, contact_map_size, layout_map, line_chart, pareto_chart, pareto_front,
    ChartOptions, MapPanel, PlotError, Series, SeriesStyle, CHART_SIZE,
};

/// A fresh directory under the system temp dir (never the repository), removed when the
/// guard drops.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("squeal-plot-test-{name}-"))
        .tempdir()
        .unwrap()
}

/// Parsed SVG text plus helpers to count elements.
struct Svg(String);

impl Svg {
    fn load(path: &Path) -> Svg {
        let text = std::fs::read_to_string(path).unwrap();
        roxmltree::Document::parse(&text)
            .unwrap_or_else(|e| panic!("{} is not XML: {e}", path.display()));
        Svg(text)
    }
    fn doc(&self) -> roxmltree::Document<'_> {
        roxmltree::Document::parse(&self.0).unwrap()
    }
    fn count(&self, tag: &str) -> usize {
        self.doc()
            .descendants()
            .filter(|n| n.has_tag_name(tag))
            .count()
    }
    /// Elements `tag` whose attribute `attr` equals `value` (case-insensitive).
    fn count_attr(&self, tag: &str, attr: &str, value: &str) -> usize {
        self.doc()
            .descendants()
            .filter(|n| n.has_tag_name(tag))
            .filter(|n| {
                n.attribute(attr)
                    .is_some_and(|v| v.eq_ignore_ascii_case(value))
            })
            .count()
    }
    /// Trimmed contents of every `<text>` element.
    fn texts(&self) -> Vec<String> {
        self.doc()
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .map(|n| {
                n.descendants()
                    .filter(|c| c.is_text())
                    .filter_map(|c| c.text())
                    .collect::<String>()
                    .trim()
                    .to_string()
            })
            .collect()
    }
    fn has_text(&self, s: &str) -> bool {
        self.texts().iter().any(|t| t == s)
    }
    fn size(&self) -> (u32, u32) {
        let doc = self.doc();
        let root = doc.root_element();
        (
            root.attribute("width").unwrap().parse().unwrap(),
            root.attribute("height").unwrap().parse().unwrap(),
        )
    }
}

/// Checks the PNG signature and returns the IHDR width and height.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    assert!(b.len() > 33, "{} too short", path.display());
    assert_eq!(
        &b[..8],
        b"\x89PNG\r\n\x1a\n",
        "{} signature",
        path.display()
    );
    assert_eq!(&b[12..16], b"IHDR");
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

/// Both files exist as `<stem>.svg`, `<stem>.png` (in that order) with `size` pixels.
fn check_outputs(stem: &Path, files: &[PathBuf], size: (u32, u32)) -> Svg {
    let svg_path = PathBuf::from(format!("{}.svg", stem.display()));
    let png_path = PathBuf::from(format!("{}.png", stem.display()));
    assert_eq!(files, &[svg_path.clone(), png_path.clone()]);
    assert_eq!(png_size(&png_path), size);
    let svg = Svg::load(&svg_path);
    assert_eq!(svg.size(), size);
    svg
}

fn assert_names(err: &PlotError, stem: &Path) {
    let msg = err.to_string();
    assert!(
        msg.contains(&stem.display().to_string()),
        "error does not name {}: {msg}",
        stem.display()
    );
    assert_eq!(err.path(), stem);
    assert!(
        !PathBuf::from(format!("{}.svg", stem.display())).exists()
            && !PathBuf::from(format!("{}.png", stem.display())).exists(),
        "files written despite {msg}"
    );
}

// --------------------------------------------------------------------------- contact map

/// An nx x ny grid of 1 mm pairs; value i (so pair 0 is open and the last is the maximum).
fn grid_panel(title: &str, nx: usize, ny: usize) -> MapPanel {
    let mut xy = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            xy.push([i as f64 * 1e-3, j as f64 * 1e-3]);
        }
    }
    let values = (0..nx * ny).map(|i| i as f64).collect();
    MapPanel {
        title: title.into(),
        xy,
        values,
        cell: [1e-3, 1e-3],
        cells: Vec::new(),
        arrow: Some([0.0, 2.0]), // not unit: normalised by the function
        arrow_label: "sliding".into(),
    }
}

#[test]
fn contact_map_writes_svg_and_png_with_one_rect_per_pair() {
    let tmp = temp_dir("contact");
    let dir = tmp.path();
    let stem = dir.join("map");
    let panels = [grid_panel("set A", 10, 4), grid_panel("set B", 6, 5)];
    let files = contact_map(&stem, "Contact map title", "normal force (N)", &panels).unwrap();
    let svg = check_outputs(&stem, &files, contact_map_size(2));
    let pairs: usize = panels.iter().map(|p| p.xy.len()).sum();
    assert!(svg.count("rect") >= pairs, "{} rects", svg.count("rect"));
    // Shared scale: the overall maximum (39, panel A) is the top of viridis; panel B's
    // maximum (29) is not. Pair 0 of each panel is open (light grey), + 1 legend swatch.
    assert_eq!(svg.count_attr("rect", "fill", "#FDE725"), 1);
    assert_eq!(svg.count_attr("rect", "fill", "#DEDEDE"), 2 + 1);
    assert!(svg.has_text("Contact map title"));
    assert!(svg.has_text("set A") && svg.has_text("set B"));
    assert!(svg.has_text("x (mm)") && svg.has_text("y (mm)"));
    assert!(svg.has_text("normal force (N)"));
    assert_eq!(svg.texts().iter().filter(|t| *t == "sliding").count(), 2);
    assert_eq!(svg.count("polygon"), 2, "one arrow head per panel");
}

/// `<text>` elements as (content, x, font-size).
fn text_boxes(svg: &Svg) -> Vec<(String, f64, f64)> {
    svg.doc()
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| {
            let t: String = n
                .descendants()
                .filter(|c| c.is_text())
                .filter_map(|c| c.text())
                .collect();
            let num = |a: &str| n.attribute(a).and_then(|v| v.parse().ok()).unwrap_or(0.0);
            (t.trim().to_string(), num("x"), num("font-size"))
        })
        .collect()
}

#[test]
fn contact_map_texts_do_not_overlap() {
    let tmp = temp_dir("contact-texts");
    let dir = tmp.path();
    let stem = dir.join("map");
    let long = "mu = 0.36, ~2100 Hz (+-20 %): 12 zones (30/36 cases solved)";
    // values up to 12345: wide tick labels on the colour bar
    let mut wide = grid_panel("short", 4, 3);
    wide.values = (0..12).map(|i| 12345.0 * i as f64 / 11.0).collect();
    let panels = [wide, grid_panel(long, 4, 3)];
    let files = contact_map(&stem, "t", "unstable zones covering the pair", &panels).unwrap();
    let svg = Svg::load(&files[0]);
    let boxes = text_boxes(&svg);
    let find = |s: &str| boxes.iter().find(|b| b.0 == s).cloned().unwrap();
    // a caption longer than its panel is drawn smaller than a short one, to fit
    let (short, long) = (find("short"), find(long));
    assert!(long.2 < short.2, "caption sizes {} vs {}", long.2, short.2);
    let panel_w = (contact_map_size(2).0 - 150) as f64 / 2.0;
    assert!(
        // DejaVu Sans averages about 0.56 em per character of such text
        0.56 * long.2 * long.0.chars().count() as f64 <= panel_w,
        "caption of {} px font in a {panel_w} px panel",
        long.2
    );
    // the colour-bar title sits right of every tick label of the bar (numbers of the
    // strip right of the panels), with room for their width
    let title = find("unstable zones covering the pair");
    let strip = 2.0 * panel_w;
    let ticks: Vec<&(String, f64, f64)> = boxes
        .iter()
        .filter(|b| b.1 > strip && b.0.parse::<f64>().is_ok())
        .collect();
    assert!(ticks.len() >= 3, "{boxes:?}");
    for t in ticks {
        // DejaVu Sans digits are 0.64 em wide
        let right = t.1 + 0.64 * t.2 * t.0.chars().count() as f64;
        assert!(
            right + 0.5 * title.2 <= title.1,
            "tick {:?} reaches x = {right}, the title is at x = {}",
            t.0,
            title.1
        );
    }
}

#[test]
fn contact_map_grid_beyond_three_panels() {
    let tmp = temp_dir("contact-grid");
    let dir = tmp.path();
    let stem = dir.join("nested/dir/map"); // parent directories are created
    let panels: Vec<MapPanel> = (0..5)
        .map(|k| MapPanel {
            arrow: None,
            ..grid_panel(&format!("p{k}"), 3, 3)
        })
        .collect();
    let files = contact_map(&stem, "five", "p (Pa)", &panels).unwrap();
    assert_eq!(contact_map_size(5).1, 2 * contact_map_size(3).1 - 50);
    let svg = check_outputs(&stem, &files, contact_map_size(5));
    assert!(svg.count("rect") >= 45);
    assert_eq!(svg.count("polygon"), 0);
}

#[test]
fn contact_map_bad_input() {
    let tmp = temp_dir("contact-bad");
    let dir = tmp.path();
    let stem = dir.join("map");
    let err = contact_map(&stem, "t", "v", &[]).unwrap_err();
    assert!(matches!(err, PlotError::EmptyData { .. }), "{err}");
    assert_names(&err, &stem);

    let empty = MapPanel {
        xy: vec![],
        values: vec![],
        ..grid_panel("e", 1, 1)
    };
    let err = contact_map(&stem, "t", "v", &[grid_panel("a", 2, 2), empty]).unwrap_err();
    assert!(matches!(err, PlotError::EmptyData { .. }), "{err}");
    assert_names(&err, &stem);

    let mut nan = grid_panel("n", 2, 2);
    nan.values[3] = f64::NAN;
    let err = contact_map(&stem, "t", "v", &[nan]).unwrap_err();
    assert!(matches!(err, PlotError::NanData { .. }), "{err}");
    assert_names(&err, &stem);

    let mut nan = grid_panel("n", 2, 2);
    nan.xy[1][1] = f64::INFINITY;
    let err = contact_map(&stem, "t", "v", &[nan]).unwrap_err();
    assert!(matches!(err, PlotError::NanData { .. }), "{err}");

    let mut short = grid_panel("s", 2, 2);
    short.values.pop();
    let err = contact_map(&stem, "t", "v", &[short]).unwrap_err();
    assert!(matches!(err, PlotError::InvalidInput { .. }), "{err}");
    assert_names(&err, &stem);

    let mut zero = grid_panel("z", 2, 2);
    zero.arrow = Some([0.0, 0.0]);
    assert!(matches!(
        contact_map(&stem, "t", "v", &[zero]),
        Err(PlotError::InvalidInput { .. })
    ));

    let mut cells = grid_panel("c", 2, 2);
    cells.cells = vec![[0.0, 1e-3, 0.0, 1e-3]; 3];
    let err = contact_map(&stem, "t", "v", &[cells.clone()]).unwrap_err();
    assert!(matches!(err, PlotError::InvalidInput { .. }), "{err}");
    assert!(err.to_string().contains("3 cells"), "{err}");
    cells.cells.push([1e-3, 1e-3, 0.0, 1e-3]); // x_min == x_max
    let err = layout_map(&stem, "t", "v", &[cells.clone()]).unwrap_err();
    assert!(err.to_string().contains("cell of pair 3"), "{err}");
    cells.cells[3][1] = f64::NAN;
    let err = layout_map(&stem, "t", "v", &[cells]).unwrap_err();
    assert!(matches!(err, PlotError::NanData { .. }), "{err}");
}

#[test]
fn layout_map_draws_two_colours_and_explicit_cells() {
    let tmp = temp_dir("layout");
    let dir = tmp.path();
    let stem = dir.join("layouts");
    // A refined corner: pairs of a 3 x 3 grid whose first column and row are 0.2 mm wide
    // and the rest 1 mm, drawn with their own rectangles; values 0/1 alternate.
    let lines = [0.0, 0.2e-3, 1.2e-3];
    let edges = [-0.1e-3, 0.1e-3, 0.7e-3, 1.7e-3];
    let mut panel = MapPanel {
        title: "layout 7".into(),
        cell: [1.0, 1.0], // would swamp the map if it were used
        arrow: Some([-1.0, 0.0]),
        arrow_label: "disc".into(),
        ..MapPanel::default()
    };
    for j in 0..3 {
        for i in 0..3 {
            panel.xy.push([lines[i], lines[j]]);
            panel
                .cells
                .push([edges[i], edges[i + 1], edges[j], edges[j + 1]]);
            panel.values.push(((i + j) % 2) as f64);
        }
    }
    let files = layout_map(&stem, "Layouts", "in contact", &[panel]).unwrap();
    let svg = check_outputs(&stem, &files, contact_map_size(1));
    // 4 closed pairs + 1 legend swatch in the closed colour, 5 open + 1 swatch in grey,
    // and no colour bar (no viridis).
    assert_eq!(svg.count_attr("rect", "fill", "#1F77B4"), 4 + 1);
    assert_eq!(svg.count_attr("rect", "fill", "#DEDEDE"), 5 + 1);
    assert_eq!(svg.count_attr("rect", "fill", "#FDE725"), 0);
    assert!(svg.has_text("in contact") && svg.has_text("open"));
    assert!(svg.has_text("layout 7") && svg.has_text("disc"));
    // The axes span the cells (-0.1 to 1.7 mm), not the 1 m `cell`.
    assert!(svg.has_text("1.5"), "{:?}", svg.texts());
}

// --------------------------------------------------------------------------- line chart

fn modes() -> Series {
    Series {
        name: "modes".into(),
        points: vec![
            (1000.0, -2.0),
            (2000.0, -1.0),
            (3000.0, 4.0),
            (4000.0, 0.5),
            (5000.0, -3.0),
        ],
        style: SeriesStyle::Markers,
        neutral: Vec::new(),
        highlight: vec![false, false, true, true, false],
    }
}

fn curve() -> Series {
    Series {
        name: "fit".into(),
        points: vec![(1000.0, -1.5), (2500.0, 0.0), (4000.0, 1.0), (5000.0, 2.0)],
        style: SeriesStyle::Line,
        neutral: Vec::new(),
        highlight: vec![],
    }
}

#[test]
fn line_chart_markers_highlights_and_lines() {
    let tmp = temp_dir("line");
    let dir = tmp.path();
    let stem = dir.join("stability");
    let opts = ChartOptions {
        hline: Some(0.0),
        highlight_label: Some("unstable".into()),
        ..ChartOptions::default()
    };
    let files = line_chart(
        &stem,
        "Stability map",
        "frequency (Hz)",
        "real part (1/s)",
        &[modes(), curve()],
        &opts,
    )
    .unwrap();
    let svg = check_outputs(&stem, &files, CHART_SIZE);
    // 3 normal markers (blue) + 2 highlighted (red); the Line series has no markers.
    assert_eq!(svg.count("circle"), 5);
    assert_eq!(svg.count_attr("circle", "fill", "#1F77B4"), 3);
    assert_eq!(svg.count_attr("circle", "fill", "#D62728"), 2);
    // The second series' line (orange).
    assert_eq!(svg.count_attr("polyline", "stroke", "#FF7F0E"), 1);
    for t in [
        "Stability map",
        "frequency (Hz)",
        "real part (1/s)",
        "modes",
        "fit",
        "unstable",
    ] {
        assert!(svg.has_text(t), "missing text {t:?} in {:?}", svg.texts());
    }
}

#[test]
fn line_chart_rings_neutral_points_and_refuses_a_wrong_mask() {
    let tmp = temp_dir("line-neutral");
    let stem = tmp.path().join("classes");
    let s = Series {
        name: String::new(),
        points: vec![(1.0, -2.0), (2.0, 0.0), (3.0, 1e-9), (4.0, 3.0)],
        style: SeriesStyle::Markers,
        neutral: vec![false, true, true, false],
        highlight: vec![false, false, false, true],
    };
    let opts = ChartOptions {
        hline: Some(0.0),
        highlight_label: Some("unstable".into()),
        neutral_label: Some("neutral within the error bound".into()),
        ..ChartOptions::default()
    };
    let files = line_chart(&stem, "Classes", "x", "y", std::slice::from_ref(&s), &opts).unwrap();
    let svg = check_outputs(&stem, &files, CHART_SIZE);
    // a filled marker for each point but the highlighted one, a red one for it, and two
    // rings (plus the legend's): the rings have no fill
    assert_eq!(svg.count_attr("circle", "fill", "#1F77B4"), 3);
    assert_eq!(svg.count_attr("circle", "fill", "#D62728"), 1);
    assert_eq!(svg.count_attr("circle", "stroke", "#FF8C00"), 3);
    assert!(svg.has_text("neutral within the error bound"));
    let wrong = Series {
        neutral: vec![true],
        ..s
    };
    let err = line_chart(&stem, "Classes", "x", "y", &[wrong], &opts).unwrap_err();
    assert!(matches!(err, PlotError::InvalidInput { .. }), "{err}");
}

#[test]
fn line_chart_custom_size_and_line_markers() {
    let tmp = temp_dir("line-size");
    let dir = tmp.path();
    let stem = dir.join("conv");
    let s = Series {
        name: String::new(), // no legend
        points: (0..8).map(|i| (i as f64, 10f64.powi(-i))).collect(),
        style: SeriesStyle::LineMarkers,
        neutral: Vec::new(),
        highlight: vec![],
    };
    let opts = ChartOptions {
        log_y: true,
        size: (640, 480),
        ..ChartOptions::default()
    };
    let files = line_chart(&stem, "Convergence", "iteration", "error (-)", &[s], &opts).unwrap();
    let svg = check_outputs(&stem, &files, (640, 480));
    assert_eq!(svg.count("circle"), 8);
    assert_eq!(svg.count_attr("polyline", "stroke", "#1F77B4"), 1);
    assert!(svg.has_text("Convergence"));
}

#[test]
fn line_chart_log_axes_drop_non_positive_points() {
    let tmp = temp_dir("line-log");
    let dir = tmp.path();
    let stem = dir.join("loglog");
    let s = Series {
        name: "s".into(),
        points: vec![
            (1.0, 1.0),
            (10.0, 0.0),
            (100.0, 1e-3),
            (-1.0, 5.0),
            (1e3, -2.0),
        ],
        style: SeriesStyle::Markers,
        neutral: Vec::new(),
        highlight: vec![false, true, false, false, true],
    };
    let opts = ChartOptions {
        log_x: true,
        log_y: true,
        hline: Some(0.0), // not drawable on a log axis: ignored
        ..ChartOptions::default()
    };
    let files = line_chart(
        &stem,
        "log",
        "x (-)",
        "y (-)",
        std::slice::from_ref(&s),
        &opts,
    )
    .unwrap();
    let svg = check_outputs(&stem, &files, CHART_SIZE);
    assert_eq!(svg.count("circle"), 2, "only (1, 1) and (100, 1e-3) remain");
    assert_eq!(svg.count_attr("circle", "fill", "#D62728"), 0);

    // Nothing positive left: empty.
    let bad = Series {
        points: vec![(0.0, 1.0), (-3.0, 2.0)],
        neutral: Vec::new(),
        highlight: vec![],
        ..s
    };
    let stem2 = dir.join("none");
    let err = line_chart(&stem2, "log", "x", "y", &[bad], &opts).unwrap_err();
    assert!(matches!(err, PlotError::EmptyData { .. }), "{err}");
    assert_names(&err, &stem2);
}

#[test]
fn line_chart_bad_input() {
    let tmp = temp_dir("line-bad");
    let dir = tmp.path();
    let stem = dir.join("c");
    let o = ChartOptions::default();
    let err = line_chart(&stem, "t", "x", "y", &[], &o).unwrap_err();
    assert!(matches!(err, PlotError::EmptyData { .. }), "{err}");
    assert_names(&err, &stem);
    let empty = Series::default();
    let err = line_chart(&stem, "t", "x", "y", &[empty], &o).unwrap_err();
    assert!(matches!(err, PlotError::EmptyData { .. }), "{err}");

    let mut nan = modes();
    nan.points[2].1 = f64::NAN;
    let err = line_chart(&stem, "t", "x", "y", &[nan], &o).unwrap_err();
    assert!(matches!(err, PlotError::NanData { .. }), "{err}");
    assert_names(&err, &stem);

    let mut mask = modes();
    mask.highlight.pop();
    let err = line_chart(&stem, "t", "x", "y", &[mask], &o).unwrap_err();
    assert!(matches!(err, PlotError::InvalidInput { .. }), "{err}");

    let inverted = ChartOptions {
        x_range: Some((5.0, 1.0)),
        ..ChartOptions::default()
    };
    let err = line_chart(&stem, "t", "x", "y", &[modes()], &inverted).unwrap_err();
    assert!(matches!(err, PlotError::InvalidInput { .. }), "{err}");
    assert_names(&err, &stem);
}

// --------------------------------------------------------------------------- pareto

fn methods() -> Vec<(String, f64, f64)> {
    [
        ("dense", 80.0, 1e-13),   // front
        ("modes", 0.5, 1e-3),     // front
        ("big modes", 2.0, 1e-2), // dominated by modes
        ("enriched", 1.5, 1e-6),  // front
        ("krylov", 90.0, 1e-12),  // dominated by dense
    ]
    .into_iter()
    .map(|(l, t, e)| (l.to_string(), t, e))
    .collect()
}

#[test]
fn pareto_front_selection() {
    let pts: Vec<(f64, f64)> = methods().iter().map(|m| (m.1, m.2)).collect();
    assert_eq!(pareto_front(&pts), vec![1, 3, 0]);
    assert_eq!(pareto_front(&[(1.0, 1.0)]), vec![0]);
    assert_eq!(pareto_front(&[(1.0, 2.0), (2.0, 1.0)]), vec![0, 1]);
    assert_eq!(pareto_front(&[(2.0, 2.0), (1.0, 2.0)]), vec![1]);
    assert_eq!(pareto_front(&[(2.0, 2.0), (2.0, 1.0)]), vec![1]);
}

#[test]
fn pareto_chart_marks_front_and_labels() {
    let tmp = temp_dir("pareto");
    let dir = tmp.path();
    let stem = dir.join("pareto");
    let mut pts = methods();
    pts.push(("free lunch?".into(), 0.0, 1e-3)); // not on a log axis: dropped
    let files = pareto_chart(&stem, "Pareto title", "time (s)", "error (-)", &pts).unwrap();
    // the plot area is CHART_SIZE, the legend strip (at least 160 px) is added on the right
    let svg = Svg::load(&files[0]);
    let (w, h) = svg.size();
    assert!(w >= CHART_SIZE.0 + 160 && h == CHART_SIZE.1, "{w} x {h}");
    let svg = check_outputs(&stem, &files, (w, h));
    // each method its own colour: one point marker and one legend marker each
    for color in ["#1F77B4", "#FF7F0E", "#2CA02C", "#9467BD", "#8C564B"] {
        assert_eq!(svg.count_attr("polygon", "fill", color), 2, "{color}");
    }
    // the 3 front points ringed in red (and the legend's ring), the front line (and its
    // legend swatch) in red
    assert_eq!(svg.count_attr("circle", "stroke", "#D62728"), 4);
    assert!(
        svg.count_attr("polyline", "stroke", "#D62728") >= 1,
        "front line"
    );
    for (l, _, _) in &methods() {
        assert!(svg.has_text(l), "missing label {l}");
    }
    assert!(!svg.has_text("free lunch?"));
    assert!(svg.has_text("Pareto title") && svg.has_text("Pareto front"));
}

/// The x attribute of the `<text>` element reading `s`.
fn text_x(svg: &Svg, s: &str) -> Option<f64> {
    svg.doc()
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .find(|n| {
            n.descendants()
                .filter(|c| c.is_text())
                .filter_map(|c| c.text())
                .collect::<String>()
                .trim()
                == s
        })
        .and_then(|n| n.attribute("x"))
        .and_then(|x| x.parse().ok())
}

#[test]
fn pareto_chart_many_clustered_methods_stay_apart() {
    // 24 methods with nearly equal time and error (a cluster, as the solvers of one
    // reduced problem give): every one a distinct colour, every name in the legend beside
    // the plot area, none written over the points
    let tmp = temp_dir("pareto-many");
    let dir = tmp.path();
    let stem = dir.join("pareto");
    let pts: Vec<(String, f64, f64)> = (0..24)
        .map(|k| {
            (
                format!("basis{k}/eigen"),
                0.3 * (1.0 + 0.01 * k as f64),
                1e-9 * (1.0 + 0.02 * k as f64),
            )
        })
        .collect();
    let files = pareto_chart(&stem, "many", "time (s)", "error (-)", &pts).unwrap();
    let svg = Svg::load(&files[0]);
    let fills: Vec<String> = svg
        .doc()
        .descendants()
        .filter(|n| n.has_tag_name("polygon"))
        .filter_map(|n| n.attribute("fill").map(str::to_uppercase))
        .collect();
    let mut distinct = fills.clone();
    distinct.sort();
    distinct.dedup();
    // 24 points + 24 legend markers, in 24 colours
    assert_eq!(fills.len(), 48, "{fills:?}");
    assert_eq!(distinct.len(), 24, "{distinct:?}");
    for (l, _, _) in &pts {
        let x = text_x(&svg, l).unwrap_or_else(|| panic!("no legend entry {l}"));
        assert!(
            x > f64::from(CHART_SIZE.0),
            "{l} at x = {x}, inside the plot area"
        );
    }
    // the cluster spans less than a decade in error: the log axis still has tick labels
    assert!(
        svg.texts().iter().any(|t| t.contains("e-9")),
        "no tick label on the error axis: {:?}",
        svg.texts()
    );
}

#[test]
fn pareto_chart_bad_input() {
    let tmp = temp_dir("pareto-bad");
    let dir = tmp.path();
    let stem = dir.join("p");
    let err = pareto_chart(&stem, "t", "x", "y", &[]).unwrap_err();
    assert!(matches!(err, PlotError::EmptyData { .. }), "{err}");
    assert_names(&err, &stem);
    let err = pareto_chart(&stem, "t", "x", "y", &[("a".into(), -1.0, 1.0)]).unwrap_err();
    assert!(matches!(err, PlotError::EmptyData { .. }), "{err}");
    let mut pts = methods();
    pts[1].2 = f64::NAN;
    let err = pareto_chart(&stem, "t", "x", "y", &pts).unwrap_err();
    assert!(matches!(err, PlotError::NanData { .. }), "{err}");
    assert_names(&err, &stem);
}

// --------------------------------------------------------------------------- bars

#[test]
fn bar_chart_one_rect_per_bar() {
    let tmp = temp_dir("bars");
    let dir = tmp.path();
    let stem = dir.join("timings");
    let bars: Vec<(String, f64)> = [
        ("assembly", 1.5),
        ("factor", 4.0),
        ("eigen", 2.25),
        ("loss", -0.5),
    ]
    .into_iter()
    .map(|(l, v)| (l.to_string(), v))
    .collect();
    let files = bar_chart(&stem, "Bar title", "stage", "time (s)", &bars).unwrap();
    let svg = check_outputs(&stem, &files, CHART_SIZE);
    assert_eq!(svg.count_attr("rect", "fill", "#1F77B4"), bars.len());
    assert!(svg.count("rect") >= bars.len());
    for (l, v) in &bars {
        assert!(svg.has_text(l), "missing label {l}");
        assert!(svg.has_text(&format!("{v}")), "missing value {v}");
    }
    assert!(svg.has_text("Bar title") && svg.has_text("time (s)"));
}

#[test]
fn bar_chart_bad_input() {
    let tmp = temp_dir("bars-bad");
    let dir = tmp.path();
    let stem = dir.join("b");
    let err = bar_chart(&stem, "t", "x", "y", &[]).unwrap_err();
    assert!(matches!(err, PlotError::EmptyData { .. }), "{err}");
    assert_names(&err, &stem);
    let err = bar_chart(&stem, "t", "x", "y", &[("a".into(), f64::NAN)]).unwrap_err();
    assert!(matches!(err, PlotError::NanData { .. }), "{err}");
    assert_names(&err, &stem);
}

#[test]
fn unwritable_output_is_an_io_error_naming_the_path() {
    let tmp = temp_dir("io");
    let dir = tmp.path();
    // A regular file where the output directory should be.
    let blocker = dir.join("not-a-dir");
    std::fs::write(&blocker, b"x").unwrap();
    let stem = blocker.join("out");
    let err = bar_chart(&stem, "t", "x", "y", &[("a".into(), 1.0)]).unwrap_err();
    assert!(matches!(err, PlotError::Io { .. }), "{err}");
    assert!(
        err.to_string().contains(&blocker.display().to_string()),
        "{err}"
    );
}
