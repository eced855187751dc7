//! Normal-mode analysis of a built model: solve, attribute each mode to a body, label
//! it, pair doublets, and compare the disc with the paper's Table 2.

use crate::labels::{body_shares, label_disc, label_pin, nodal_weights};
use crate::outdir::RunError;
use crate::pipeline::PipelineError;
use crate::reference::paper;
use serde::Serialize;
use squeal_core::{
    EigenParams, EigenSolver, Params, RealModes, Registry, Result, SymmetricProblem,
};
use squeal_scene::{build, BodyKind, Model, Scene};
use std::time::Instant;

/// One labelled mode (the `modes` entries of `squeal modes --json`).
#[derive(Debug, Clone, Serialize)]
pub struct ModeRecord {
    /// `disc` or `pin` (the pin with its plates).
    pub body: String,
    /// Index in the frequency-sorted list of the solve, from 1.
    pub index: usize,
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// Label (`a,0,3`, `c,1`, `r,2` for the disc; `tilt-y` ... for the pin).
    pub label: String,
    /// Relative residual of the eigenpair.
    pub residual: f64,
    /// Index of the other member of a doublet.
    pub partner: Option<usize>,
}

/// Doublet members must lie within this relative frequency distance.
pub const DOUBLET_TOL: f64 = 0.02;

/// Solves the normal modes of `model` and labels them.
pub fn normal_modes(
    model: &Model,
    solver: &dyn EigenSolver,
    params: &EigenParams,
) -> Result<(RealModes, Vec<ModeRecord>)> {
    let problem = SymmetricProblem {
        k: model.k.as_ref(),
        m: model.m.as_ref(),
    };
    let modes = solver.solve_symmetric(&problem, params)?;
    let records = label_modes(model, &modes);
    Ok((modes, records))
}

/// The labelled normal modes of some bodies of a scene, as `squeal modes --json` writes
/// them.
#[derive(Debug, Clone, Serialize)]
pub struct BodyModes {
    /// The scene's name in messages.
    pub scene: String,
    /// Units of the numbers.
    pub units: &'static str,
    /// Free DOFs of the model.
    pub dofs: usize,
    /// Hexahedra of the mesh.
    pub elements: usize,
    /// Mass of the model (kg).
    pub total_mass_kg: f64,
    /// Eigen solver plugin.
    pub solver: String,
    /// Relative tolerance of the solve.
    pub tol: f64,
    /// Band top (Hz).
    pub max_freq_hz: f64,
    /// Time to build the model (s).
    pub build_time_s: f64,
    /// Time of the eigen solve (s).
    pub solve_time_s: f64,
    /// Wall time (s).
    pub time_s: f64,
    /// The solver's notes.
    pub notes: Vec<String>,
    /// The modes, labelled.
    pub modes: Vec<ModeRecord>,
}

/// Builds the bodies `which` of `scene` (named `file` in messages) with a free contact
/// face and solves their normal modes up to `max_freq` Hz with the eigen plugin `eigen`
/// at tolerance `tol`. Returns the report, the model and the modes (for mode shapes).
pub fn body_modes(
    registry: &Registry,
    scene: &Scene,
    file: &str,
    which: BodyKind,
    max_freq: f64,
    eigen: &str,
    tol: f64,
) -> std::result::Result<(BodyModes, Model, RealModes), RunError> {
    let start = Instant::now();
    let model = build(scene, which, registry, file).map_err(PipelineError::from)?;
    let stage = format!("normal modes of {file} with `{eigen}`");
    let core = |source| RunError::Stage {
        stage: stage.clone(),
        source: Box::new(PipelineError::Core {
            stage: "eigen solve".into(),
            source,
        }),
    };
    let solver = registry.eigen.create(eigen, &Params::new()).map_err(core)?;
    let params = EigenParams {
        fmax_hz: max_freq,
        tol,
        ..EigenParams::default()
    };
    let (modes, records) = normal_modes(&model, solver.as_ref(), &params).map_err(core)?;
    let report = BodyModes {
        scene: file.to_string(),
        units: "SI: frequencies in Hz, masses in kg, times in s",
        dofs: model.dofs.n_free(),
        elements: model.mesh.hexes.len(),
        total_mass_kg: model.total_mass,
        solver: eigen.into(),
        tol,
        max_freq_hz: max_freq,
        build_time_s: model.build_time_s,
        solve_time_s: modes.info.time_s,
        time_s: start.elapsed().as_secs_f64(),
        notes: modes.info.notes.clone(),
        modes: records,
    };
    Ok((report, model, modes))
}

/// Attributes, labels and pairs the modes of `model`.
pub fn label_modes(model: &Model, modes: &RealModes) -> Vec<ModeRecord> {
    let mesh = &model.mesh;
    let weights = nodal_weights(mesh);
    let body_of = |name: &str| model.body_names.iter().position(|b| b == name);
    let disc_nodes = body_of("disc")
        .map(|b| mesh.body_nodes(b))
        .unwrap_or_default();
    let pin_nodes = body_of("pin")
        .map(|b| mesh.body_nodes(b))
        .unwrap_or_default();
    let mut out: Vec<ModeRecord> = (0..modes.freq_hz.len())
        .map(|i| {
            let free: Vec<f64> = (0..modes.vectors.nrows())
                .map(|r| modes.vectors[(r, i)])
                .collect();
            let u = model.dofs.expand(&free);
            let shares = body_shares(mesh, &weights, &u, model.body_names.len());
            let disc_share = body_of("disc").map(|b| shares[b]).unwrap_or(0.0);
            let (body, label) = if disc_share >= 0.5 {
                (
                    "disc",
                    label_disc(mesh, &weights, &disc_nodes, &u).to_string(),
                )
            } else {
                ("pin", label_pin(mesh, &pin_nodes, &u))
            };
            ModeRecord {
                body: body.into(),
                index: i + 1,
                freq_hz: modes.freq_hz[i],
                label,
                residual: modes.residuals[i],
                partner: None,
            }
        })
        .collect();
    pair_doublets(&mut out);
    unresolve_repeated_labels(&mut out);
    out
}

/// Writes `?` for the nodal diameters ([`crate::labels::unresolved_label`]) of every disc
/// label that two distinct modes carry, a doublet (two partners, see [`pair_doublets`])
/// counting as one: a label names one mode (or doublet), so at least one of them is
/// wrong, and which one the shapes do not tell. `a,0,1` on five doublets becomes
/// `a,0,?` on all ten modes. Labels already holding `?` are left as they are.
pub fn unresolve_repeated_labels(modes: &mut [ModeRecord]) {
    let mut families: std::collections::BTreeMap<String, usize> = Default::default();
    for m in modes.iter() {
        // one count per doublet: its member of lower index
        let first_of_pair = m.partner.is_none_or(|p| m.index < p);
        if m.body == "disc" && !m.label.contains('?') && first_of_pair {
            *families.entry(m.label.clone()).or_default() += 1;
        }
    }
    for m in modes.iter_mut() {
        if m.body == "disc" && families.get(&m.label).is_some_and(|&k| k > 1) {
            m.label = crate::labels::unresolved_label(&m.label);
        }
    }
}

/// Pairs disc modes of equal label with `n > 0` whose frequencies differ by less than
/// [`DOUBLET_TOL`]: nearest unpaired partner first.
pub fn pair_doublets(modes: &mut [ModeRecord]) {
    for i in 0..modes.len() {
        if modes[i].partner.is_some() || modes[i].body != "disc" || modes[i].label.ends_with(",0") {
            continue;
        }
        let best = (0..modes.len())
            .filter(|&j| j != i && modes[j].partner.is_none() && modes[j].body == "disc")
            .filter(|&j| modes[j].label == modes[i].label)
            .map(|j| (j, (modes[j].freq_hz / modes[i].freq_hz - 1.0).abs()))
            .filter(|&(_, d)| d < DOUBLET_TOL)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((j, _)) = best {
            modes[i].partner = Some(modes[j].index);
            modes[j].partner = Some(modes[i].index);
        }
    }
}

/// One row of the comparison with the paper's Table 2.
#[derive(Debug, Clone, Serialize)]
pub struct TableRow {
    /// Label.
    pub label: String,
    /// The paper's FE frequency (Hz).
    pub paper_hz: f64,
    /// Whether the paper lists a doublet.
    pub paper_double: bool,
    /// squeal's frequency (Hz): the mean of a doublet, `None` if no mode has the label.
    pub squeal_hz: Option<f64>,
    /// Relative error `(squeal - paper) / paper`.
    pub rel_err: Option<f64>,
    /// Relative split of the doublet `(f2 - f1) / f1`, when paired.
    pub doublet_split: Option<f64>,
}

/// Compares labelled disc modes with Table 2 of the paper.
pub fn compare_table2(modes: &[ModeRecord]) -> Vec<TableRow> {
    paper()
        .disc_modes
        .iter()
        .map(|d| {
            let (label, paper_hz, paper_double) = (d.label.as_str(), d.freq_hz, d.double);
            let first = modes.iter().find(|m| m.body == "disc" && m.label == label);
            let (squeal_hz, split) = match first {
                None => (None, None),
                Some(m) => match m.partner.and_then(|p| modes.iter().find(|x| x.index == p)) {
                    Some(p) => (
                        Some(0.5 * (m.freq_hz + p.freq_hz)),
                        Some((p.freq_hz - m.freq_hz).abs() / m.freq_hz.min(p.freq_hz)),
                    ),
                    None => (Some(m.freq_hz), None),
                },
            };
            TableRow {
                label: label.into(),
                paper_hz,
                paper_double,
                squeal_hz,
                rel_err: squeal_hz.map(|f| (f - paper_hz) / paper_hz),
                doublet_split: split,
            }
        })
        .collect()
}

/// Plain-text table of [`compare_table2`] rows.
pub fn format_table(rows: &[TableRow]) -> String {
    let mut s = String::from("label    paper (Hz)  squeal (Hz)   error   doublet split\n");
    for r in rows {
        let f = r.squeal_hz.map_or("missing".into(), |v| format!("{v:.1}"));
        let e = r
            .rel_err
            .map_or("-".into(), |v| format!("{:+.2} %", 100.0 * v));
        let d = match (r.paper_double, r.doublet_split) {
            (true, Some(x)) => format!("{:.3} %", 100.0 * x),
            (true, None) => "unpaired".into(),
            (false, _) => "single".into(),
        };
        s.push_str(&format!(
            "{:<8} {:>10.1} {:>12} {:>9}   {}\n",
            r.label, r.paper_hz, f, e, d
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(index: usize, body: &str, freq_hz: f64, label: &str) -> ModeRecord {
        ModeRecord {
            body: body.into(),
            index,
            freq_hz,
            label: label.into(),
            residual: 0.0,
            partner: None,
        }
    }

    /// Five distinct doublets all labelled `a,0,1` (a coarse mesh aliasing their
    /// harmonics) are all `a,0,?`; a label carried by one doublet or one single mode
    /// is kept, and pin labels are not disc labels.
    #[test]
    fn repeated_labels_become_unresolved() {
        let mut modes = vec![
            mode(1, "disc", 1000.0, "a,0,0"),
            mode(2, "pin", 1100.0, "tilt-x"),
            mode(3, "pin", 1150.0, "tilt-x"),
        ];
        for (k, f) in [1200.0, 2500.0, 4100.0, 6000.0, 8300.0].iter().enumerate() {
            modes.push(mode(4 + 2 * k, "disc", *f, "a,0,1"));
            modes.push(mode(5 + 2 * k, "disc", f * 1.001, "a,0,1"));
        }
        modes.push(mode(14, "disc", 9000.0, "a,0,2"));
        modes.push(mode(15, "disc", 9001.0, "a,0,2"));
        modes.push(mode(16, "disc", 9500.0, "c,0"));
        pair_doublets(&mut modes);
        unresolve_repeated_labels(&mut modes);
        let labels: Vec<&str> = modes.iter().map(|m| m.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "a,0,0", "tilt-x", "tilt-x", "a,0,?", "a,0,?", "a,0,?", "a,0,?", "a,0,?", "a,0,?",
                "a,0,?", "a,0,?", "a,0,?", "a,0,?", "a,0,2", "a,0,2", "c,0"
            ]
        );
        // the doublets stay paired
        assert_eq!(modes[3].partner, Some(5));
        // two single modes with one label are two families too
        let mut singles = vec![
            mode(1, "disc", 3000.0, "c,1"),
            mode(2, "disc", 11000.0, "c,1"),
        ];
        pair_doublets(&mut singles);
        unresolve_repeated_labels(&mut singles);
        assert_eq!(singles[0].label, "c,?");
        assert_eq!(singles[1].label, "c,?");
    }

    /// Table 2 finds no frequency for a label squeal left unresolved.
    #[test]
    fn unresolved_labels_are_missing_from_table2() {
        let mut modes = vec![
            mode(1, "disc", 900.0, "a,0,1"),
            mode(2, "disc", 901.0, "a,0,1"),
            mode(3, "disc", 2000.0, "a,0,1"),
            mode(4, "disc", 2001.0, "a,0,1"),
        ];
        pair_doublets(&mut modes);
        unresolve_repeated_labels(&mut modes);
        let rows = compare_table2(&modes);
        let row = rows
            .iter()
            .find(|r| r.label == "a,0,1")
            .expect("Table 2 lists a,0,1");
        assert_eq!(row.squeal_hz, None);
    }
}
