//! Writes one chart of each kind (SVG + PNG) into the directory given as argument.
//!
//! ```text
//! cargo run -p squeal-plot --example demo -- /tmp/squeal-plot-demo
//! ```

use std::path::PathBuf;

use squeal_plot::{
    bar_chart, contact_map, line_chart, pareto_chart, ChartOptions, MapPanel, PlotError, Series,
    SeriesStyle,
};

/// A 20 x 8 grid of contact pairs on a 40 mm x 16 mm pad (2 mm cells), with a normal
/// force that grows towards the leading edge and a few open pairs at the trailing edge.
fn pad(mu: f64) -> MapPanel {
    let (nx, ny, h) = (20, 8, 2e-3);
    let mut xy = Vec::new();
    let mut values = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
            xy.push([x, y]);
            let s = x / (nx as f64 * h); // 0 at trailing edge, 1 at leading edge
            let f = 10.0 * (1.0 + 4.0 * mu * (s - 0.5)) * (1.0 - 0.3 * (y / 0.016 - 0.5).powi(2));
            values.push(if s < 0.15 * mu * 2.5 { 0.0 } else { f.max(0.0) });
        }
    }
    MapPanel {
        title: format!("mu = {mu}"),
        xy,
        values,
        cell: [h, h],
        cells: Vec::new(),
        arrow: Some([1.0, 0.0]),
        arrow_label: "sliding".into(),
    }
}

fn main() -> Result<(), PlotError> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "squeal-plot-demo".to_string()),
    );
    let mut files = Vec::new();

    files.extend(contact_map(
        &dir.join("contact_map"),
        "Normal contact force at the sliding equilibrium",
        "normal force (N)",
        &[pad(0.2), pad(0.4), pad(0.6)],
    )?);

    // Stability map: real part vs frequency along a friction sweep, unstable in red.
    let mut modes = Vec::new();
    for k in 0..12 {
        let f0 = 900.0 + 750.0 * k as f64;
        for m in 0..6 {
            let mu = 0.1 * m as f64;
            let re = if k == 5 || k == 9 {
                60.0 * (mu - 0.25)
            } else {
                -5.0 - 2.0 * k as f64 * mu
            };
            modes.push((f0 + 40.0 * mu * (k % 3) as f64, re));
        }
    }
    let highlight = modes.iter().map(|p| p.1 > 0.0).collect();
    let stability = Series {
        name: "modes (mu = 0 .. 0.5)".into(),
        points: modes,
        style: SeriesStyle::Markers,
        neutral: Vec::new(),
        highlight,
    };
    files.extend(line_chart(
        &dir.join("stability"),
        "Stability map",
        "frequency (Hz)",
        "real part of eigenvalue (1/s)",
        &[stability],
        &ChartOptions {
            hline: Some(0.0),
            highlight_label: Some("unstable".into()),
            ..ChartOptions::default()
        },
    )?);

    // Convergence of two solvers on a log axis.
    let conv = |name: &str, rate: f64| Series {
        name: name.into(),
        points: (0..25)
            .map(|i| (i as f64, (-(rate * i as f64)).exp() + 1e-15))
            .collect(),
        style: SeriesStyle::LineMarkers,
        neutral: Vec::new(),
        highlight: Vec::new(),
    };
    files.extend(line_chart(
        &dir.join("convergence"),
        "Backward error per iteration",
        "iteration",
        "backward error (-)",
        &[conv("Krylov-Schur", 1.1), conv("ARPACK", 1.4)],
        &ChartOptions {
            log_y: true,
            ..ChartOptions::default()
        },
    )?);

    let methods: Vec<(String, f64, f64)> = [
        ("dense QZ", 86.0, 1e-13),
        ("modes (n=50)", 0.8, 3e-3),
        ("modes (n=200)", 2.5, 4e-4),
        ("enriched", 1.9, 2e-6),
        ("residue", 3.1, 5e-8),
        ("ARPACK full", 12.0, 1e-12),
        ("Krylov full", 17.0, 3e-12),
    ]
    .into_iter()
    .map(|(n, t, e)| (n.to_string(), t, e))
    .collect();
    files.extend(pareto_chart(
        &dir.join("pareto"),
        "Cost and accuracy of reductions",
        "time (s)",
        "max relative eigenvalue error (-)",
        &methods,
    )?);

    let timings: Vec<(String, f64)> = [
        ("assembly", 1.2),
        ("equilibrium", 0.4),
        ("factorization", 3.5),
        ("eigen", 5.1),
        ("post", 0.3),
    ]
    .into_iter()
    .map(|(n, t)| (n.to_string(), t))
    .collect();
    files.extend(bar_chart(
        &dir.join("timings"),
        "Time per stage",
        "stage",
        "time (s)",
        &timings,
    )?);

    for f in &files {
        let len = std::fs::metadata(f).map(|m| m.len()).unwrap_or(0);
        println!("{:>9} bytes  {}", len, f.display());
    }
    Ok(())
}
