//! The bench run into an output directory (`squeal bench`): the cases (a mu list, or the
//! stress set of cases built to break methods), each case's operator from the scene at its
//! equilibrium or from an operator read from files, the model stages built once, every
//! run appended at once to `bench.partial.jsonl` (a killed bench keeps what finished),
//! then `bench.json` (`stress.json`) and `bench-summary.json` (`stress-summary.json`).
//! The caller draws the charts and prints the runs.

use super::{
    bench_case, speed_ratios, stages_for, Accuracy, BenchOptions, BenchRun, MemoryProbe,
    ReferenceSolve, SpeedRatio, Stage,
};
use crate::outdir::{self, RunError};
use crate::pipeline::Prepared;
use serde::Serialize;
use squeal_core::{FrictionalOperator, Registry};
use squeal_scene::Zone;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where the operators of the cases come from.
pub enum BenchSource {
    /// A prepared scene: each case's operator at its equilibrium (a stress case may change
    /// the contact zone).
    Scene(Box<Prepared>),
    /// One operator read from files, the same for every case.
    Operator {
        /// Its name in outputs (the directory, and the parameter value).
        name: String,
        /// The operator.
        op: Box<FrictionalOperator>,
    },
}

impl BenchSource {
    /// The name of the source in outputs.
    pub fn name(&self) -> &str {
        match self {
            Self::Scene(prep) => &prep.file,
            Self::Operator { name, .. } => name,
        }
    }
}

/// What the bench runs besides the methods of [`BenchOptions`].
#[derive(Debug, Clone)]
pub struct SuiteSettings {
    /// Friction coefficients of the cases (ignored by the stress set).
    pub mus: Vec<f64>,
    /// Methods, band, tolerances, variants.
    pub opts: BenchOptions,
    /// Equilibrium solver of a scene's cases.
    pub equilibrium: String,
    /// Contact law of a scene's cases.
    pub law: String,
    /// The contact law's parameters (a penalty's stiffness).
    pub law_params: squeal_core::Params,
    /// Run the stress set instead of the mu list.
    pub stress: bool,
}

/// One stress case: a scene change, a mu and basis parameters chosen to break methods.
pub struct StressCase {
    /// Short name.
    pub name: &'static str,
    /// What it probes.
    pub what: &'static str,
    /// Friction coefficient.
    pub mu: f64,
    /// A contact zone other than the scene's.
    pub zone: Option<Zone>,
    /// A basis parameter set for every basis that takes it.
    pub vary: Option<(&'static str, f64)>,
}

/// The stress set.
pub fn stress_cases() -> Vec<StressCase> {
    let case = |name, what, mu| StressCase {
        name,
        what,
        mu,
        zone: None,
        vary: None,
    };
    vec![
        case(
            "baseline",
            "uniform contact, mu = 0.3: the reference point of each method's error estimate",
            0.3,
        ),
        case(
            "threshold",
            "mu = 0.6, just past the onset of the 2150 Hz coupling of the default scene \
             (between 0.55 and 0.6): a small positive real part",
            0.6,
        ),
        StressCase {
            zone: Some(Zone::Rectangle {
                x0_m: 0.016,
                y0_m: 0.008,
                a_m: 0.004,
                b_m: 0.004,
            }),
            ..case(
                "localized",
                "contact zone 4 x 4 mm at the leading edge (x0 = 16 mm, y0 = 8 mm), mu = 0.43",
                0.43,
            )
        },
        case(
            "high-mu",
            "mu = 1.2, far beyond the paper's range: strong friction coupling",
            1.2,
        ),
        StressCase {
            vary: Some(("cutoff_factor", 1.0)),
            ..case(
                "truncated",
                "mu = 0.7 with every basis cut at the band top (cutoff_factor = 1)",
                0.7,
            )
        },
        case(
            "doublet",
            "mu = 0.02: the disc's doublets split by the pin and barely coupled by \
             friction (near-degenerate pairs, DvR near 0 on both sides)",
            0.02,
        ),
    ]
}

/// One case: where its operator came from.
#[derive(Serialize, Clone)]
pub struct CaseInfo {
    /// Case name.
    pub case: String,
    /// Friction coefficient.
    pub mu: f64,
    /// What it is.
    pub what: String,
    /// Pairs in contact at its equilibrium (scene cases).
    pub active_pairs: Option<usize>,
    /// Size of its operator.
    pub dofs: usize,
    /// Time to build its operator (s).
    pub operator_time_s: f64,
}

/// `bench-summary.json` (`stress-summary.json`): what produced `bench.json`.
#[derive(Serialize)]
pub struct SuiteSummary {
    /// The scene or operator directory.
    pub source: String,
    /// squeal's version.
    pub version: &'static str,
    /// Units of the numbers.
    pub units: &'static str,
    /// Band (Hz).
    pub band_hz: [f64; 2],
    /// Tolerance of the benchmarked solvers.
    pub tol: f64,
    /// Whether full-order runs got condition numbers.
    pub condition: bool,
    /// Reference solver.
    pub reference_eigen: String,
    /// Its tolerance.
    pub reference_tol: f64,
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    pub dvr_margin: f64,
    /// What counts as accurate.
    pub accuracy: Accuracy,
    /// Bases.
    pub bases: Vec<String>,
    /// Eigen solvers.
    pub eigens: Vec<String>,
    /// Basis parameter variants.
    pub vary: Vec<String>,
    /// The reference solve of each case.
    pub references: Vec<ReferenceSolve>,
    /// Speed-up over the reference at equal accuracy.
    pub speed_ratios: Vec<SpeedRatio>,
    /// The cases.
    pub cases: Vec<CaseInfo>,
    /// Model stages built once before the cases (e.g. the free-interface synthesis of
    /// `cms`): `(key, time_s)`, not part of any run's time.
    pub model_stages: Vec<(String, f64)>,
    /// Wall time (s).
    pub time_s: f64,
    /// The charts the caller drew.
    pub charts: Vec<String>,
}

/// What the bench reports as it goes.
pub enum SuiteEvent<'a> {
    /// A model stage is built.
    Stage(&'a Stage),
    /// A case starts: its name and what it is.
    Case(&'a str, &'a str),
    /// A run of the case is finished.
    Run(&'a BenchRun),
    /// The reference of the case is finished (after its runs).
    Reference(&'a ReferenceSolve),
}

/// The operator of a case: the scene's at its equilibrium for `mu` (or with a changed
/// zone), or the operator read from files. Returns it, its active pairs and the time.
fn case_operator(
    registry: &Registry,
    src: &BenchSource,
    s: &SuiteSettings,
    mu: f64,
    zone: Option<&Zone>,
) -> Result<(FrictionalOperator, Option<usize>, f64), RunError> {
    let t = Instant::now();
    let base = match src {
        BenchSource::Operator { op, .. } => {
            if zone.is_some() {
                return Err(RunError::input(
                    "stress",
                    "a zone change needs a scene, not an operator read from files",
                ));
            }
            return Ok(((**op).clone(), None, 0.0));
        }
        BenchSource::Scene(prep) => prep,
    };
    let zoned;
    let prep = match zone {
        None => base,
        Some(z) => {
            let mut scene = base.scene.clone();
            scene.contact.zone = z.clone();
            zoned = Prepared::new(registry, scene, &base.file)?;
            &zoned
        }
    };
    let at = || outdir::stage(format!("the operator at mu = {mu}"));
    let eq = prep
        .equilibrium_with(registry, &s.equilibrium, &s.law, &s.law_params, mu)
        .map_err(at())?;
    let op = prep.operator(&eq.eq.active).map_err(at())?;
    Ok((
        op,
        Some(eq.eq.active.iter().filter(|&&x| x).count()),
        t.elapsed().as_secs_f64(),
    ))
}

/// Appends one run to `path` at once (a killed bench keeps what finished).
fn append(path: &Path, run: &BenchRun) -> Result<(), RunError> {
    let failed = |source| RunError::Write {
        path: path.to_path_buf(),
        source,
    };
    let line = serde_json::to_string(run).map_err(|e| failed(std::io::Error::other(e)))?;
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(failed)?;
    writeln!(f, "{line}")
        .and_then(|()| f.flush())
        .map_err(failed)
}

/// Runs the bench (or the stress set) of `s` on `src` into `out` (claimed by the caller):
/// `bench.json` and `bench-summary.json` (`stress.*` for the stress set), with the paths
/// `charts` draws from the runs. `memory` measures each run's peak heap.
pub fn run_suite(
    registry: &Registry,
    src: &BenchSource,
    s: &SuiteSettings,
    out: &Path,
    memory: Option<&dyn MemoryProbe>,
    mut events: impl FnMut(SuiteEvent<'_>),
    charts: impl FnOnce(&[BenchRun]) -> Result<Vec<PathBuf>, RunError>,
) -> Result<(Vec<BenchRun>, SuiteSummary), RunError> {
    let start = Instant::now();
    let partial = out.join("bench.partial.jsonl");
    let _ = std::fs::remove_file(&partial);
    if s.stress && matches!(src, BenchSource::Operator { .. }) {
        return Err(RunError::input(
            "stress",
            "the stress set changes the contact zone and mu: it needs a scene, not an operator \
             read from files",
        ));
    }
    for &mu in &s.mus {
        squeal_contact::check_user_mu(mu)
            .map_err(|e| RunError::input("mu", format!("{mu}: {e}")))?;
    }
    type Case = (
        String,
        String,
        f64,
        Option<Zone>,
        Option<(&'static str, f64)>,
    );
    let cases: Vec<Case> = if s.stress {
        stress_cases()
            .into_iter()
            .map(|c| (c.name.to_string(), c.what.to_string(), c.mu, c.zone, c.vary))
            .collect()
    } else {
        s.mus
            .iter()
            .map(|&mu| (format!("mu={mu}"), format!("mu = {mu}"), mu, None, None))
            .collect()
    };
    // the model stages of the bases that have one (`cms`: the free-interface synthesis),
    // on every pair of the face: a stress zone is a subset
    let stages = match src {
        BenchSource::Scene(prep) => {
            let all = squeal_contact::ContactSet::new(
                &prep.model,
                &Zone::Uniform,
                prep.scene.study.rotation,
            )
            .map_err(|e| RunError::Pipeline(Box::new(e.into())))?;
            stages_for(registry, &s.opts, &prep.model, &all)?
        }
        BenchSource::Operator { .. } => Vec::new(),
    };
    for stage in &stages {
        events(SuiteEvent::Stage(stage));
    }
    let mut all_runs = Vec::new();
    let mut refs = Vec::new();
    let mut infos = Vec::new();
    for (case, what, mu, zone, vary) in &cases {
        events(SuiteEvent::Case(case, what));
        let (op, active, op_time) = case_operator(registry, src, s, *mu, zone.as_ref())?;
        infos.push(CaseInfo {
            case: case.clone(),
            mu: *mu,
            what: what.clone(),
            active_pairs: active,
            dofs: op.dim(),
            operator_time_s: op_time,
        });
        let mut opts = s.opts.clone();
        if let Some((k, v)) = vary {
            opts.vary = vec![(k.to_string(), vec![*v])];
            opts.defaults = false;
        }
        let mut append_err = None;
        let (reference, runs) =
            bench_case(registry, case, &op, &stages, *mu, &opts, memory, |r| {
                events(SuiteEvent::Run(r));
                if let Err(e) = append(&partial, r) {
                    append_err.get_or_insert(e);
                }
            })?;
        if let Some(e) = append_err {
            return Err(e);
        }
        events(SuiteEvent::Reference(&reference));
        refs.push(reference);
        all_runs.extend(runs);
    }
    let stem = if s.stress { "stress" } else { "bench" };
    outdir::write_json(&out.join(format!("{stem}.json")), &all_runs)?;
    let drawn = charts(&all_runs)?;
    let o = &s.opts;
    let summary = SuiteSummary {
        source: src.name().to_string(),
        version: env!("CARGO_PKG_VERSION"),
        units: "times in s, memory in MB (heap above the run's start), frequencies in Hz; \
                errors relative (frequency) or absolute (DvR = Re/Im)",
        band_hz: o.band_hz,
        tol: o.tol,
        condition: o.condition,
        reference_eigen: o.reference_eigen.clone(),
        reference_tol: o.reference_tol,
        dvr_margin: o.dvr_margin,
        accuracy: o.accuracy,
        bases: o.bases.clone(),
        eigens: o.eigens.clone(),
        vary: o.vary.iter().map(|(k, v)| format!("{k}={v:?}")).collect(),
        references: refs,
        speed_ratios: speed_ratios(&all_runs),
        cases: infos,
        model_stages: stages.iter().map(|s| (s.key.clone(), s.time_s)).collect(),
        time_s: start.elapsed().as_secs_f64(),
        charts: drawn.iter().map(|p| p.display().to_string()).collect(),
    };
    outdir::write_json(&out.join(format!("{stem}-summary.json")), &summary)?;
    let _ = std::fs::remove_file(&partial);
    Ok((all_runs, summary))
}
