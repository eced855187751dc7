//! The charts of `squeal bench`: error against time per case (one point per basis
//! variant, a line per method), identical series merged.

use anyhow::Result;
use squeal_analysis::bench::BenchRun;
use squeal_plot::{line_chart, pareto_chart, ChartOptions, Series, SeriesStyle};
use std::path::{Path, PathBuf};

fn label(r: &BenchRun) -> String {
    if r.basis_opts.is_empty() {
        format!("{}/{}", r.basis, r.eigen)
    } else {
        format!("{} [{}]/{}", r.basis, r.basis_opts, r.eigen)
    }
}

/// Chart points `(label, time, error)`: the runs of one basis variant whose errors agree
/// to 1 % (the eigen solvers of one reduced problem do, to a few digits) become one point
/// at the fastest time, labelled `basis [opts]/fastest (~ others)`, so labels do not
/// overlap on the log axes.
fn merged_points(
    runs: &[&BenchRun],
    err: fn(&BenchRun) -> f64,
    time: fn(&BenchRun) -> f64,
) -> Vec<(String, f64, f64)> {
    let mut groups: Vec<Vec<&BenchRun>> = Vec::new();
    for r in runs.iter().filter(|r| err(r).is_finite()) {
        let same = |g: &Vec<&BenchRun>| {
            let h = g[0];
            h.basis == r.basis
                && h.basis_opts == r.basis_opts
                && (err(h) - err(r)).abs() <= 1e-2 * err(h).abs().max(err(r).abs())
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(r),
            None => groups.push(vec![r]),
        }
    }
    groups
        .into_iter()
        .map(|mut g| {
            g.sort_by(|a, b| time(a).total_cmp(&time(b)));
            let mut name = label(g[0]);
            if g.len() > 1 {
                let others: Vec<&str> = g[1..].iter().map(|r| r.eigen.as_str()).collect();
                name.push_str(&format!(" (~ {})", others.join(", ")));
            }
            (name, time(g[0]), err(g[0]))
        })
        .collect()
}

/// Error-vs-size series (named `basis/eigen`) of one basis whose points agree (same
/// sizes, errors to 1 %: the eigen solvers of one reduced problem) become one series
/// named `basis/first (~ others)`, so no line hides under another of a different colour.
fn merged_series(series: Vec<Series>) -> Vec<Series> {
    let basis = |s: &Series| s.name.split('/').next().unwrap_or("").to_string();
    let same = |a: &Series, b: &Series| {
        basis(a) == basis(b)
            && a.points.len() == b.points.len()
            && a.points
                .iter()
                .zip(&b.points)
                .all(|(p, q)| p.0 == q.0 && (p.1 - q.1).abs() <= 1e-2 * p.1.abs().max(q.1.abs()))
    };
    let mut out: Vec<(Series, Vec<String>)> = Vec::new();
    for s in series {
        match out.iter_mut().find(|(g, _)| same(g, &s)) {
            Some((_, others)) => {
                others.push(s.name.rsplit('/').next().unwrap_or("").to_string());
            }
            None => out.push((s, Vec::new())),
        }
    }
    out.into_iter()
        .map(|(mut s, others)| {
            if !others.is_empty() {
                s.name.push_str(&format!(" (~ {})", others.join(", ")));
            }
            s
        })
        .collect()
}

/// Error vs time (total, and per mu with the basis reused; Pareto front marked) and
/// error vs basis size, per case.
pub fn charts(out: &Path, runs: &[BenchRun]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut cases: Vec<&str> = runs.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    for case in cases {
        let ok: Vec<&BenchRun> = runs
            .iter()
            .filter(|r| r.case == case && r.status == "ok" && !r.reference)
            .collect();
        let tag = case.replace('=', "");
        let ref_time = runs
            .iter()
            .find(|r| r.case == case && r.reference)
            .map_or(f64::NAN, |r| r.solve_s);
        for (what, key, err) in [
            (
                "max relative frequency error",
                "freq",
                (|r: &BenchRun| r.errors.max_rel_freq_err) as fn(&BenchRun) -> f64,
            ),
            ("max |DvR error|", "dvr", |r: &BenchRun| {
                r.errors.max_abs_dvr_err
            }),
        ] {
            for (stem, stem_title, axis, time) in [
                (
                    "time",
                    "total time",
                    "time (setup + solve)",
                    (|r: &BenchRun| r.time_s) as fn(&BenchRun) -> f64,
                ),
                (
                    "solve_time",
                    "per-mu time",
                    "per-mu solve time, basis reused",
                    |r: &BenchRun| r.solve_s,
                ),
            ] {
                let pts = merged_points(&ok, err, time);
                if pts.iter().any(|p| p.1 > 0.0 && p.2 > 0.0) {
                    files.extend(pareto_chart(
                        &out.join(format!("{key}_error_vs_{stem}_{tag}")),
                        &format!("{case}: {what} vs {stem_title} (reference {ref_time:.1} s)"),
                        &format!("{axis} (s)"),
                        what,
                        &pts,
                    )?);
                }
            }
        }
        // error vs basis size, one series per basis/eigen
        let mut series: Vec<Series> = Vec::new();
        for r in ok.iter().filter(|r| r.basis != "none") {
            let name = format!("{}/{}", r.basis, r.eigen);
            let p = (r.basis_size as f64, r.errors.max_rel_freq_err);
            if !p.1.is_finite() {
                continue;
            }
            match series.iter_mut().find(|s| s.name == name) {
                Some(s) => s.points.push(p),
                None => series.push(Series {
                    name,
                    points: vec![p],
                    style: SeriesStyle::LineMarkers,
                    neutral: Vec::new(),
                    highlight: Vec::new(),
                }),
            }
        }
        for s in &mut series {
            s.points.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        let series = merged_series(series);
        if series
            .iter()
            .any(|s| s.points.iter().any(|p| p.0 > 0.0 && p.1 > 0.0))
        {
            files.extend(line_chart(
                &out.join(format!("error_vs_size_{tag}")),
                &format!("{case}: max relative frequency error vs basis size"),
                "basis size (vectors)",
                "max relative frequency error",
                &series,
                &ChartOptions {
                    log_y: true,
                    ..ChartOptions::default()
                },
            )?);
        }
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::merged_series;
    use squeal_plot::{Series, SeriesStyle};

    #[test]
    fn identical_size_series_merge_by_basis() {
        let s = |name: &str, pts: &[(f64, f64)]| Series {
            name: name.into(),
            points: pts.to_vec(),
            style: SeriesStyle::LineMarkers,
            neutral: Vec::new(),
            highlight: Vec::new(),
        };
        let merged = merged_series(vec![
            s("cms/arpack", &[(30.0, 1e-6), (40.0, 2e-7)]),
            s("cms/dense", &[(30.0, 1.001e-6), (40.0, 2e-7)]),
            s("cms/krylov", &[(30.0, 1e-6), (40.0, 3e-7)]),
            s("pod/arpack", &[(30.0, 1e-6), (40.0, 2e-7)]),
        ]);
        let names: Vec<&str> = merged.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(
            names,
            ["cms/arpack (~ dense)", "cms/krylov", "pod/arpack"],
            "same basis and points merge; a different error or basis does not"
        );
    }
}
