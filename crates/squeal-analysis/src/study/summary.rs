//! `summary.json` and `timings.json`: pure functions of the definition and the records.

use super::run::{Record, Timing, UnstableMode};
use super::{CaseList, Skipped, SolveSpec, StudyDef, StudySpec};
use serde::{Deserialize, Serialize};

/// Unstable cases of one class.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClassSummary {
    /// Class frequency (Hz).
    pub class_hz: f64,
    /// Cases with an unstable mode of this class.
    pub cases: usize,
    /// `cases` over the cases done of the group (friction coefficient, patch size).
    pub unstable_fraction: f64,
    /// Its 95 % confidence interval (Wilson score), the layouts being a random sample.
    #[serde(default)]
    pub unstable_ci95: [f64; 2],
    /// Smallest, mean and largest zone area of those cases (m^2).
    pub area_m2: [f64; 3],
    /// Frequency range of the class's unstable modes (Hz).
    pub freq_hz: [f64; 2],
    /// DvR range of the class's unstable modes.
    pub dvr: [f64; 2],
    /// The zones `[x0, y0, a, b]` (m) of those cases (macroscopic studies only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub zones_m: Vec<[f64; 4]>,
}

/// Results at one friction coefficient.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MuSummary {
    /// Friction coefficient.
    pub mu: f64,
    /// Cases done.
    pub cases: usize,
    /// Cases with at least one unstable mode.
    pub unstable: usize,
    /// Unstable cases per class.
    pub classes: Vec<ClassSummary>,
    /// Cases with an unstable mode outside every class.
    pub unclassified: usize,
}

/// Results of one patch size (mesoscopic studies).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatchSummary {
    /// Friction coefficient.
    pub mu: f64,
    /// Patch side asked for (m).
    pub patch_m: f64,
    /// Patch sides actually cut (the region divided into whole patches) (m).
    pub patch_side_m: [f64; 2],
    /// Layouts asked for.
    pub layouts: usize,
    /// Layouts skipped (no contact pair under their patches).
    pub skipped_no_pairs: usize,
    /// Layouts done.
    pub done: usize,
    /// Unstable layouts.
    pub unstable: usize,
    /// `unstable / done`.
    pub unstable_fraction: f64,
    /// Its 95 % confidence interval (Wilson score).
    #[serde(default)]
    pub unstable_ci95: [f64; 2],
    /// Smallest and largest pairs in contact over the layouts.
    pub pairs: [usize; 2],
    /// Unstable layouts per class.
    pub classes: Vec<ClassSummary>,
    /// Layouts with an unstable mode outside every class.
    pub unclassified: usize,
}

/// `summary.json`: a pure function of the definition and the records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// squeal version.
    pub version: String,
    /// `macro` or `meso`.
    pub kind: String,
    /// Units of the fields.
    pub units: String,
    /// Scene.
    pub scene: String,
    /// Free DOFs of the model.
    pub dofs: usize,
    /// Methods and thresholds.
    pub methods: SolveSpec,
    /// What varies.
    pub params: StudySpec,
    /// The contact grid: pairs along x and y, spacing and face size (m).
    pub contact_grid: GridSummary,
    /// Cases of the study.
    pub cases: usize,
    /// Cases with a record.
    pub cases_done: usize,
    /// Whether every case has a record (false in a shard or a stopped run).
    pub complete: bool,
    /// Cases skipped when the list was built.
    pub skipped: Skipped,
    /// Cases whose solve failed (their records carry the error).
    pub failed: usize,
    /// Cases with at least one unstable mode.
    pub unstable_cases: usize,
    /// Cases with at least one mode neutral within its error bound (whose stability the
    /// solve could not tell).
    #[serde(default)]
    pub neutral_cases: usize,
    /// Overall unstable fraction of the cases done.
    pub unstable_fraction: f64,
    /// Its 95 % confidence interval (Wilson score; meaningful for random layouts).
    #[serde(default)]
    pub unstable_ci95: [f64; 2],
    /// Largest backward error over every mode.
    pub max_backward_error: f64,
    /// Per friction coefficient.
    pub by_mu: Vec<MuSummary>,
    /// Per patch size and friction coefficient (mesoscopic studies).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub by_patch: Vec<PatchSummary>,
    /// Warnings (patches below the grid spacing, skipped cases).
    pub warnings: Vec<String>,
    /// Where the wall times are.
    pub timings: String,
}

/// The contact grid in a summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridSummary {
    /// Pairs along x and y.
    pub pairs: [usize; 2],
    /// Largest spacing along x and y (m).
    pub spacing_m: [f64; 2],
    /// Pin face size (m).
    pub face_m: [f64; 2],
}

/// The 95 % Wilson score interval of a proportion `k / n` (`[0, 1]` when `n = 0`): unlike
/// the normal approximation it stays inside `[0, 1]` and is not empty at `k = 0` or `n`.
pub fn wilson95(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let z = 1.959_963_984_540_054_f64;
    let (k, n) = (k as f64, n as f64);
    let p = k / n;
    let den = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / den;
    let half = z / den * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    // exact ends at k = 0 and k = n (the formula gives them up to round-off)
    let lo = if k == 0.0 {
        0.0
    } else {
        (centre - half).max(0.0)
    };
    let hi = if k == n {
        1.0
    } else {
        (centre + half).min(1.0)
    };
    [lo, hi]
}

fn class_summaries(solve: &SolveSpec, records: &[&Record], with_zones: bool) -> Vec<ClassSummary> {
    solve
        .classes_hz
        .iter()
        .map(|&c| {
            let of: Vec<&Record> = records
                .iter()
                .copied()
                .filter(|r| r.unstable.iter().any(|m| m.class_hz == Some(c)))
                .collect();
            let modes: Vec<&UnstableMode> = of
                .iter()
                .flat_map(|r| r.unstable.iter().filter(|m| m.class_hz == Some(c)))
                .collect();
            let range = |v: &mut dyn Iterator<Item = f64>| -> [f64; 2] {
                v.fold([f64::INFINITY, f64::NEG_INFINITY], |a, x| {
                    [a[0].min(x), a[1].max(x)]
                })
            };
            let fix = |r: [f64; 2]| if r[0].is_finite() { r } else { [0.0, 0.0] };
            let areas: Vec<f64> = of.iter().map(|r| r.case.area_m2).collect();
            let ar = fix(range(&mut areas.iter().copied()));
            let mean = if areas.is_empty() {
                0.0
            } else {
                areas.iter().sum::<f64>() / areas.len() as f64
            };
            ClassSummary {
                class_hz: c,
                cases: of.len(),
                unstable_fraction: if records.is_empty() {
                    0.0
                } else {
                    of.len() as f64 / records.len() as f64
                },
                unstable_ci95: wilson95(of.len(), records.len()),
                area_m2: [ar[0], mean, ar[1]],
                freq_hz: fix(range(&mut modes.iter().map(|m| m.freq_hz))),
                dvr: fix(range(&mut modes.iter().map(|m| m.dvr))),
                zones_m: if with_zones {
                    of.iter().filter_map(|r| r.rectangle()).collect()
                } else {
                    Vec::new()
                },
            }
        })
        .collect()
}

fn unclassified(records: &[&Record]) -> usize {
    records
        .iter()
        .filter(|r| r.unstable.iter().any(|m| m.class_hz.is_none()))
        .count()
}

/// The summary of `records` (sorted by id, those of `list`).
pub fn summarize(def: &StudyDef, list: &CaseList, records: &[Record]) -> Summary {
    let is_macro = matches!(def.study, StudySpec::Macro(_));
    let mus: Vec<f64> = match &def.study {
        StudySpec::Macro(s) => s.mu.clone(),
        StudySpec::Meso(s) => s.mu.clone(),
    };
    let unstable = |r: &Record| !r.unstable.is_empty();
    let by_mu = mus
        .iter()
        .map(|&mu| {
            let rs: Vec<&Record> = records.iter().filter(|r| r.case.mu == mu).collect();
            MuSummary {
                mu,
                cases: rs.len(),
                unstable: rs.iter().filter(|r| unstable(r)).count(),
                classes: class_summaries(&def.solve, &rs, is_macro),
                unclassified: unclassified(&rs),
            }
        })
        .collect();
    let mut by_patch = Vec::new();
    if let StudySpec::Meso(s) = &def.study {
        let [_, _, a, b] = s.region_m;
        for &mu in &s.mu {
            for (pi, &p) in s.patch_m.iter().enumerate() {
                let rs: Vec<&Record> = records
                    .iter()
                    .filter(|r| r.case.mu == mu && r.case.patch_m == Some(p))
                    .collect();
                let nx = ((a / p).round() as usize).max(1);
                let ny = ((b / p).round() as usize).max(1);
                let u = rs.iter().filter(|r| unstable(r)).count();
                by_patch.push(PatchSummary {
                    mu,
                    patch_m: p,
                    patch_side_m: [a / nx as f64, b / ny as f64],
                    layouts: s.layouts,
                    skipped_no_pairs: list.no_pairs_by_patch.get(pi).copied().unwrap_or(0),
                    done: rs.len(),
                    unstable: u,
                    unstable_fraction: if rs.is_empty() {
                        0.0
                    } else {
                        u as f64 / rs.len() as f64
                    },
                    unstable_ci95: wilson95(u, rs.len()),
                    pairs: [
                        rs.iter().map(|r| r.case.pairs).min().unwrap_or(0),
                        rs.iter().map(|r| r.case.pairs).max().unwrap_or(0),
                    ],
                    classes: class_summaries(&def.solve, &rs, false),
                    unclassified: unclassified(&rs),
                });
            }
        }
    }
    let n_unstable = records.iter().filter(|r| unstable(r)).count();
    Summary {
        version: def.version.clone(),
        kind: if is_macro { "macro" } else { "meso" }.into(),
        units: "SI: lengths in m, areas in m^2, frequencies in Hz, DvR = Re/Im (dimensionless)"
            .into(),
        scene: def.scene.clone(),
        dofs: def.dofs,
        methods: def.solve.clone(),
        params: def.study.clone(),
        contact_grid: GridSummary {
            pairs: def.grid.n,
            spacing_m: def.grid.spacing_m,
            face_m: def.grid.face_m,
        },
        cases: list.cases.len(),
        cases_done: records.len(),
        complete: records.len() == list.cases.len(),
        skipped: list.skipped.clone(),
        failed: records.iter().filter(|r| r.error.is_some()).count(),
        unstable_cases: n_unstable,
        neutral_cases: records.iter().filter(|r| !r.neutral.is_empty()).count(),
        unstable_fraction: if records.is_empty() {
            0.0
        } else {
            n_unstable as f64 / records.len() as f64
        },
        unstable_ci95: wilson95(n_unstable, records.len()),
        max_backward_error: records
            .iter()
            .map(|r| r.max_backward_error)
            .fold(0.0, f64::max),
        by_mu,
        by_patch,
        warnings: def.warnings(list),
        timings: "timings.jsonl (per case) and timings.json (totals): wall times are kept out of \
                  results.jsonl and summary.json so that those are reproducible byte for byte"
            .into(),
    }
}

/// `timings.json`: where the time of the cases went (s).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TimingSummary {
    /// Cases timed.
    pub cases: usize,
    /// Sum over the cases of each stage (s).
    pub total: Timing,
    /// Mean per case of each stage (s).
    pub mean: Timing,
}

impl TimingSummary {
    /// Totals and means of `timings`.
    pub fn of(timings: &[Timing]) -> Self {
        let mut total = Timing {
            id: "total".into(),
            ..Timing::default()
        };
        for t in timings {
            total.contact_s += t.contact_s;
            total.operator_s += t.operator_s;
            total.basis_s += t.basis_s;
            total.projection_s += t.projection_s;
            total.solve_s += t.solve_s;
            total.expansion_s += t.expansion_s;
            total.total_s += t.total_s;
            for (step, s) in &t.basis_steps {
                *total.basis_steps.entry(step.clone()).or_insert(0.0) += s;
            }
        }
        let n = timings.len().max(1) as f64;
        let mean = Timing {
            id: "mean".into(),
            contact_s: total.contact_s / n,
            operator_s: total.operator_s / n,
            basis_s: total.basis_s / n,
            projection_s: total.projection_s / n,
            solve_s: total.solve_s / n,
            expansion_s: total.expansion_s / n,
            total_s: total.total_s / n,
            basis_steps: total
                .basis_steps
                .iter()
                .map(|(step, s)| (step.clone(), s / n))
                .collect(),
        };
        Self {
            cases: timings.len(),
            total,
            mean,
        }
    }
}
