//! Charts of the contact-zone studies (SVG + PNG through `squeal-plot`), drawn from the
//! records of a study directory, so a merged directory gets the same charts as one run.
//!
//! Macroscopic (paper section 3.1): the modes against the zone length `a` at fixed `b`
//! (Figure 12), maps of where the zones giving each coupling lie (Figures 14 and 16) and
//! the area of the unstable zones (Figure 15). Mesoscopic (section 3.2): the unstable
//! fraction against the patch size (Figure 22), DvR against frequency (Figures 20-21) and
//! example layouts that trigger or suppress each coupling (Figures 23-26).

use anyhow::Result;
use squeal_analysis::study::{Record, StudyDef, StudySpec};
use squeal_plot::{
    contact_map, layout_map, line_chart, ChartOptions, MapPanel, Series, SeriesStyle,
};
use std::path::{Path, PathBuf};

/// Draws the charts of a study into `dir`; returns the files written.
pub fn draw(dir: &Path, def: &StudyDef, records: &[Record]) -> Result<Vec<PathBuf>> {
    let ok: Vec<&Record> = records.iter().filter(|r| r.error.is_none()).collect();
    if ok.is_empty() {
        return Ok(Vec::new());
    }
    match &def.study {
        StudySpec::Macro(s) => macro_charts(dir, def, &s.mu, &s.b_m, &ok),
        StudySpec::Meso(s) => meso_charts(dir, def, &s.mu, &s.patch_m, &ok),
    }
}

/// A number for a file name: to 1e-6, `.` as `_` (`14.2` -> `14_2`).
/// A marker chart of the non-empty `series`; no file when every series is empty.
fn scatter(
    stem: &Path,
    title: &str,
    x: &str,
    y: &str,
    series: Vec<Series>,
) -> Result<Vec<PathBuf>> {
    let series: Vec<Series> = series
        .into_iter()
        .filter(|s| !s.points.is_empty())
        .collect();
    if series.is_empty() {
        return Ok(Vec::new());
    }
    Ok(line_chart(
        stem,
        title,
        x,
        y,
        &series,
        &ChartOptions::default(),
    )?)
}

fn tag(v: f64) -> String {
    format!("{}", (v * 1e6).round() / 1e6).replace('.', "_")
}

fn classes_label(def: &StudyDef, c: f64) -> String {
    format!("~{c:.0} Hz (+-{:.0} %)", 100.0 * def.solve.class_width)
}

/// The sliding direction of the disc on the face (the disc enters at the +x edge for a
/// counter-clockwise rotation).
fn arrow(def: &StudyDef) -> Option<[f64; 2]> {
    Some([-def.rotation.signum(), 0.0])
}

fn macro_charts(
    dir: &Path,
    def: &StudyDef,
    mus: &[f64],
    bs: &[f64],
    recs: &[&Record],
) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let face = def.grid.face_m;
    // Figure 12: modes against a at fixed b, the zone nearest the face centre per a
    for &mu in mus {
        for &b in bs {
            let mut by_a: std::collections::BTreeMap<i64, &Record> = Default::default();
            for r in recs.iter().filter(|r| r.case.mu == mu) {
                let Some(z) = r.rectangle() else { continue };
                if z[3] != b {
                    continue;
                }
                let off = |r: &Record| {
                    let z = r.rectangle().unwrap_or_default();
                    (z[0] + z[2] / 2.0 - face[0] / 2.0).hypot(z[1] + z[3] / 2.0 - face[1] / 2.0)
                };
                let key = (z[2] * 1e6).round() as i64;
                let better = by_a.get(&key).is_none_or(|p| off(r) < off(p) - 1e-12);
                if better {
                    by_a.insert(key, r);
                }
            }
            if by_a.len() < 2 {
                continue;
            }
            for (what, y_label, pick) in [
                ("freq", "frequency (Hz)", 0usize),
                ("dvr", "DvR = Re(lambda)/Im(lambda)", 1),
            ] {
                let mut pts = Vec::new();
                let (mut hi, mut ne) = (Vec::new(), Vec::new());
                for r in by_a.values() {
                    let a = r.rectangle().unwrap_or_default()[2] * 1e3;
                    for m in &r.modes {
                        pts.push((a, m[pick]));
                        hi.push(r.unstable.iter().any(|u| u.freq_hz == m[0]));
                        ne.push(r.neutral.iter().any(|n| n[0] == m[0]));
                    }
                }
                if pts.is_empty() {
                    continue;
                }
                files.extend(line_chart(
                    &dir.join(format!("{what}_vs_a_mu{}_b{}mm", tag(mu), tag(b * 1e3))),
                    &format!(
                        "Modes vs zone length a (b = {:.1} mm, mu = {mu}; unstable in red, neutral ringed)",
                        b * 1e3
                    ),
                    "zone length a along sliding (mm)",
                    y_label,
                    &[Series {
                        name: String::new(),
                        points: pts,
                        style: SeriesStyle::Markers,
                        neutral: ne,
                        highlight: hi,
                    }],
                    &ChartOptions {
                        highlight_label: Some("unstable".into()),
                        neutral_label: Some(crate::sweep_charts::NEUTRAL_LABEL.into()),
                        hline: (pick == 1).then_some(0.0),
                        ..ChartOptions::default()
                    },
                )?);
            }
        }
    }
    // Figures 14 and 16: how many unstable zones of each class cover each contact pair.
    // A mu without a solved case gets no panel (an empty map would read "no unstable
    // zone"); a partly solved one says how many of its cases the count covers.
    let planned = def.cases().map(|l| l.cases).unwrap_or_default();
    let mut panels = Vec::new();
    for &mu in mus {
        let done = recs.iter().filter(|r| r.case.mu == mu).count();
        if done == 0 {
            continue;
        }
        let total = planned.iter().filter(|c| c.mu == mu).count();
        for &c in &def.solve.classes_hz {
            let zones: Vec<&Record> = recs
                .iter()
                .copied()
                .filter(|r| r.case.mu == mu && r.unstable.iter().any(|m| m.class_hz == Some(c)))
                .collect();
            let mut cover = vec![0.0; def.grid.points_m.len()];
            for r in &zones {
                for (v, on) in cover
                    .iter_mut()
                    .zip(r.case.zone.select(&def.grid.points_m, face))
                {
                    *v += f64::from(u8::from(on));
                }
            }
            panels.push(MapPanel {
                title: format!(
                    "mu = {mu}, {}: {}",
                    classes_label(def, c),
                    zone_count(zones.len(), done, total)
                ),
                xy: def.grid.points_m.clone(),
                values: cover,
                cell: def.grid.spacing_m,
                cells: def.grid.cells_m(),
                arrow: arrow(def),
                arrow_label: "disc".into(),
            });
        }
    }
    if panels.is_empty() {
        return Ok(files);
    }
    files.extend(contact_map(
        &dir.join("zone_map"),
        "Unstable zones per coupling: how many of them cover each contact pair",
        "unstable zones covering the pair",
        &panels,
    )?);
    // Figure 15: area of the unstable zones
    let series: Vec<Series> = mus
        .iter()
        .map(|&mu| Series {
            name: format!("mu = {mu}"),
            points: recs
                .iter()
                .filter(|r| r.case.mu == mu)
                .flat_map(|r| r.unstable.iter().map(|m| (r.case.area_m2 * 1e6, m.freq_hz)))
                .collect(),
            style: SeriesStyle::Markers,
            neutral: Vec::new(),
            highlight: Vec::new(),
        })
        .collect();
    files.extend(scatter(
        &dir.join("unstable_area"),
        "Unstable zones: frequency of their unstable modes vs zone area",
        "zone area a b (mm^2)",
        "unstable frequency (Hz)",
        series,
    )?);
    Ok(files)
}

fn meso_charts(
    dir: &Path,
    def: &StudyDef,
    mus: &[f64],
    patches: &[f64],
    recs: &[&Record],
) -> Result<Vec<PathBuf>> {
    let mut files = unstable_vs_patch(dir, def, mus, patches, recs)?;
    files.extend(dvr_vs_freq(dir, patches, recs)?);
    files.extend(trigger_and_suppress(dir, def, recs)?);
    Ok(files)
}

/// Figure 22: the unstable share of the layouts against the patch size, overall and per
/// class.
fn unstable_vs_patch(
    dir: &Path,
    def: &StudyDef,
    mus: &[f64],
    patches: &[f64],
    recs: &[&Record],
) -> Result<Vec<PathBuf>> {
    // Figure 22: unstable fraction vs patch size, overall and per class
    let mut series = Vec::new();
    for &mu in mus {
        let frac = |pred: &dyn Fn(&Record) -> bool| -> Vec<(f64, f64)> {
            patches
                .iter()
                .filter_map(|&p| {
                    let rs: Vec<&&Record> = recs
                        .iter()
                        .filter(|r| r.case.mu == mu && r.case.patch_m == Some(p))
                        .collect();
                    (!rs.is_empty()).then(|| {
                        let u = rs.iter().filter(|r| pred(r)).count();
                        (p * 1e3, 100.0 * u as f64 / rs.len() as f64)
                    })
                })
                .collect()
        };
        series.push(Series {
            name: format!("mu = {mu}, any unstable mode"),
            points: frac(&|r| !r.unstable.is_empty()),
            style: SeriesStyle::LineMarkers,
            neutral: Vec::new(),
            highlight: Vec::new(),
        });
        for &c in &def.solve.classes_hz {
            let pts = frac(&|r| r.unstable.iter().any(|m| m.class_hz == Some(c)));
            if pts.iter().any(|p| p.1 > 0.0) {
                series.push(Series {
                    name: format!("mu = {mu}, {}", classes_label(def, c)),
                    points: pts,
                    style: SeriesStyle::LineMarkers,
                    neutral: Vec::new(),
                    highlight: Vec::new(),
                });
            }
        }
    }
    Ok(line_chart(
        &dir.join("unstable_fraction_vs_patch"),
        "Unstable layouts vs patch size",
        "patch side (mm)",
        "unstable layouts (%)",
        &series,
        &ChartOptions {
            y_range: Some((0.0, 100.0)),
            ..ChartOptions::default()
        },
    )?)
}

/// Figures 20-21: DvR against frequency of the unstable modes, one series per patch size.
fn dvr_vs_freq(dir: &Path, patches: &[f64], recs: &[&Record]) -> Result<Vec<PathBuf>> {
    let series: Vec<Series> = patches
        .iter()
        .map(|&p| Series {
            name: format!("patch {:.2} mm", p * 1e3),
            points: recs
                .iter()
                .filter(|r| r.case.patch_m == Some(p))
                .flat_map(|r| r.unstable.iter().map(|m| (m.freq_hz, m.dvr)))
                .collect(),
            style: SeriesStyle::Markers,
            neutral: Vec::new(),
            highlight: Vec::new(),
        })
        .collect();
    scatter(
        &dir.join("dvr_vs_freq"),
        "Unstable modes of the plateau layouts",
        "frequency (Hz)",
        "DvR = Re(lambda)/Im(lambda)",
        series,
    )
}

/// Figures 23-26: per class, the layouts that trigger the coupling (largest DvR) and those
/// that suppress it (stable in that class although they hold the most pairs).
fn trigger_and_suppress(dir: &Path, def: &StudyDef, recs: &[&Record]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let face = def.grid.face_m;
    let cells = def.grid.cells_m();
    for &c in &def.solve.classes_hz {
        let dvr_of = |r: &Record| {
            r.unstable
                .iter()
                .filter(|m| m.class_hz == Some(c))
                .map(|m| (m.freq_hz, m.dvr))
                .max_by(|a, b| a.1.total_cmp(&b.1))
        };
        let mut trig: Vec<(&Record, (f64, f64))> = recs
            .iter()
            .filter_map(|r| dvr_of(r).map(|d| (*r, d)))
            .collect();
        if trig.is_empty() {
            continue;
        }
        trig.sort_by(|a, b| {
            b.1 .1
                .total_cmp(&a.1 .1)
                .then(a.0.case.id.cmp(&b.0.case.id))
        });
        let mut supp: Vec<&Record> = recs
            .iter()
            .copied()
            .filter(|r| dvr_of(r).is_none())
            .collect();
        supp.sort_by(|a, b| {
            b.case
                .pairs
                .cmp(&a.case.pairs)
                .then(a.case.id.cmp(&b.case.id))
        });
        let name = |r: &Record| {
            format!(
                "patch {:.2} mm #{}",
                r.case.patch_m.unwrap_or(0.0) * 1e3,
                r.case.layout.unwrap_or(0)
            )
        };
        let panel = |r: &Record, title: String| MapPanel {
            title,
            xy: def.grid.points_m.clone(),
            values: r
                .case
                .zone
                .select(&def.grid.points_m, face)
                .into_iter()
                .map(|on| f64::from(u8::from(on)))
                .collect(),
            cell: def.grid.spacing_m,
            cells: cells.clone(),
            arrow: arrow(def),
            arrow_label: "disc".into(),
        };
        let mut panels: Vec<MapPanel> = trig
            .iter()
            .take(2)
            .map(|(r, (f, d))| panel(r, format!("{}: {f:.0} Hz, DvR {}", name(r), dvr_text(*d))))
            .collect();
        panels.extend(supp.iter().take(2).map(|r| {
            panel(
                r,
                format!(
                    "{}: stable near {c:.0} Hz ({} pairs)",
                    name(r),
                    r.case.pairs
                ),
            )
        }));
        let title = if supp.is_empty() {
            format!("Plateau layouts with the largest DvR near {c:.0} Hz (no layout suppresses it)")
        } else {
            format!(
                "Plateau layouts that trigger (left) or suppress (right) the coupling near {c:.0} Hz"
            )
        };
        files.extend(layout_map(
            &dir.join(format!("layouts_{c:.0}hz")),
            &title,
            "in contact",
            &panels,
        )?);
    }
    Ok(files)
}

/// The unstable-zone count of a zone-map panel, with the share of the mu's cases it
/// covers when not all of them were solved (`3 zones (12/40 cases solved)`).
fn zone_count(zones: usize, done: usize, total: usize) -> String {
    let noun = if zones == 1 { "zone" } else { "zones" };
    if done < total {
        format!("{zones} {noun} ({done}/{total} cases solved)")
    } else {
        format!("{zones} {noun}")
    }
}

/// A DvR for a caption: 4 decimals, or 2 significant digits below 1e-3 (weak
/// instabilities would read `0.0000`).
fn dvr_text(d: f64) -> String {
    if d.abs() >= 1e-3 {
        format!("{d:.4}")
    } else {
        format!("{d:.1e}")
    }
}

#[cfg(test)]
mod tests {
    use super::{dvr_text, zone_count};

    #[test]
    fn weak_dvr_keeps_its_digits() {
        assert_eq!(dvr_text(0.02391), "0.0239");
        assert_eq!(dvr_text(2.69e-5), "2.7e-5");
        assert_eq!(dvr_text(1e-3), "0.0010");
    }

    #[test]
    fn zone_count_says_when_cases_are_missing() {
        assert_eq!(zone_count(0, 40, 40), "0 zones");
        assert_eq!(zone_count(1, 40, 40), "1 zone");
        assert_eq!(zone_count(3, 12, 40), "3 zones (12/40 cases solved)");
    }
}
