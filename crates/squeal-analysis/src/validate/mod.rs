//! The uniform-contact validation of the paper, the project's main job (`squeal
//! validate`). One prepared model serves every stage; each writes into its own folder of
//! the report directory:
//! 1. `disc/`: the disc's free-interface modes against the paper's Table 2;
//! 2. the rig: the pin assembly's modes below 10 kHz and the axial stiffness against the
//!    paper's load datum (200 N at 125 um);
//! 3. `equilibrium/`: sliding equilibria for mu = 0 ... 0.8;
//! 4. `sweep-<basis>/`: the mu sweep through the figure basis (the paper's Figure 5 and
//!    its couplings) and through each check basis;
//! 5. full-order solves at the reference mu, every basis compared with them mode by mode
//!    ([`crate::bench::compare`]);
//! 6. `report.md` and `report.json`, with the time of each stage and the peak memory.
//!
//! The caller draws the charts and prints progress through [`ValidateHooks`].

use crate::bench::{compare, ModeErrors};
use crate::equilibria::EquilibriumReport;
use crate::modal::{BodyModes, ModeRecord, TableRow};
use crate::modal_cache::ModalCache;
use crate::mu_sweep::{
    matching_coupling, mu_list, run_into, MuSweep, MuSweepSettings, SweepEvent, SweepSummary,
};
use crate::outdir::{self, RunError};
use crate::pipeline::{damped_operator, Method, Prepared, MODAL_SOLVER};
use crate::profile::{max_opt, peak_rss_mb, take_peak_rss_mb, Machine, Profile};
use crate::reference::paper;
use serde::Serialize;
use squeal_contact::LoadedEquilibrium;
use squeal_core::operator::ComplexModes;
use squeal_core::{EigenParams, Params, Registry};
use squeal_scene::{BodyKind, Scene};
use std::path::Path;
use std::time::Instant;

mod report;

/// What the validation runs.
#[derive(Debug, Clone)]
pub struct ValidateSettings {
    /// `(basis, step)` of each mu sweep (0 to 0.8), the figure basis first.
    pub sweeps: Vec<(String, f64)>,
    /// Band (Hz) of the sweeps and the reference points; `None`: the scene's.
    pub band_hz: Option<[f64; 2]>,
    /// Friction coefficients of the full-order reference solves (points of every sweep).
    pub reference_mu: Vec<f64>,
    /// Full-order eigen solver of the reference points.
    pub eigen: String,
    /// Continue an interrupted validation (its finished sweep points are kept).
    pub resume: bool,
}

/// Where the caller takes part: progress, and the charts of what a stage wrote.
pub trait ValidateHooks {
    /// Stage `k` of `n` starts.
    fn stage(&mut self, k: usize, n: usize, what: &str);
    /// The equilibria are written into `out`.
    fn equilibria(
        &mut self,
        out: &Path,
        prep: &Prepared,
        eqs: &[LoadedEquilibrium],
    ) -> Result<(), RunError>;
    /// An event of the sweep being run into `out`.
    fn sweep_event(&mut self, out: &Path, prep: &Prepared, event: SweepEvent<'_>);
    /// A sweep is finished and written into `out`.
    fn sweep_done(
        &mut self,
        out: &Path,
        summary: &SweepSummary,
        sweep: &MuSweep,
    ) -> Result<(), RunError>;
}

/// One paper coupling against one sweep.
#[derive(Serialize)]
pub struct PaperRow {
    /// The paper's frequency (Hz).
    pub paper_freq_hz: f64,
    /// The paper's unstable mu range.
    pub paper_mu: [f64; 2],
    /// The sweep's basis.
    pub basis: String,
    /// The sweep's step.
    pub step: f64,
    /// The matching coupling's frequency (Hz).
    pub squeal_freq_hz: Option<f64>,
    /// Its unstable mu range.
    pub squeal_mu: Option<[f64; 2]>,
    /// Its largest DvR.
    pub max_dvr: Option<f64>,
    /// The free-interface modes it is made of (MAC).
    pub made_of: Vec<(String, f64)>,
}

/// One basis against full order at one mu.
#[derive(Serialize)]
pub struct RefRow {
    /// Friction coefficient.
    pub mu: f64,
    /// The basis.
    pub basis: String,
    /// Its modes against the full-order ones.
    pub errors: ModeErrors,
    /// Time of the full-order solve (s).
    pub reference_time_s: f64,
}

/// A finished validation: everything `report.md` and `report.json` hold.
pub struct Validation {
    /// The scene's name in messages.
    pub file: String,
    /// The disc's modes.
    pub disc: BodyModes,
    /// The disc against Table 2.
    pub table2: Vec<TableRow>,
    /// The pin assembly's modes below 10 kHz.
    pub pin_below: Vec<ModeRecord>,
    /// Axial stiffness, disc clamp to plate clamps (N/m).
    pub stiffness_n_per_m: f64,
    /// Force at the paper's load displacement (N).
    pub force_at_datum_n: f64,
    /// The load of the equilibria, as text.
    pub load: String,
    /// Band (Hz).
    pub band_hz: [f64; 2],
    /// The equilibria.
    pub equilibria: Vec<EquilibriumReport>,
    /// Each sweep: basis, step, summary.
    pub sweeps: Vec<(String, f64, SweepSummary)>,
    /// Every basis against full order.
    pub references: Vec<RefRow>,
    /// The paper's couplings against every sweep.
    pub paper_rows: Vec<PaperRow>,
    /// Full-order eigen solver of the references.
    pub eigen: String,
    /// The stages' times.
    pub profile: Profile,
    /// The sweeps' inner stages.
    pub detail: Profile,
    /// Peak resident memory (MB).
    pub peak_rss_mb: Option<f64>,
    /// Wall time (s).
    pub time_s: f64,
    /// The machine the times were measured on.
    pub machine: Machine,
}

/// Band top of the disc's modes against Table 2 (Hz).
pub const DISC_MODES_TOP_HZ: f64 = 10_500.0;
/// Band top of the pin assembly's modes (Hz).
pub const PIN_MODES_TOP_HZ: f64 = 10_000.0;
/// Most bytes of tied real modes the check sweeps keep in files for each other (on
/// disk, not in memory): every contact set of a check sweep on the paper preset (14 sets
/// of about 80 MB) fits, so the `residue` check solves none of the `enriched` check's
/// real modes again.
pub const SPILLED_MODES_BYTES: usize = 4 << 30;

/// Friction coefficients of the equilibria.
pub const EQUILIBRIUM_MU: [f64; 5] = [0.0, 0.2, 0.4, 0.6, 0.8];

/// Checks the settings against the registry and each other: the plugins exist, every
/// step gives a mu list, every reference mu is a point of every sweep.
pub fn check(registry: &Registry, s: &ValidateSettings) -> Result<(), RunError> {
    registry
        .eigen
        .create(&s.eigen, &Params::new())
        .map_err(|e| RunError::input("eigen", format!("`{}`: {e}", s.eigen)))?;
    for (i, (basis, step)) in s.sweeps.iter().enumerate() {
        registry
            .bases
            .create(basis, &Params::new())
            .map_err(|e| RunError::input(format!("sweeps[{i}].basis"), format!("{basis}: {e}")))?;
        mu_list(0.0, 0.8, *step)
            .map_err(|e| RunError::input(format!("sweeps[{i}].step"), format!("{step}: {e}")))?;
    }
    let on_grid = |mu: f64, step: f64| ((mu / step) - (mu / step).round()).abs() < 1e-6;
    for &mu in &s.reference_mu {
        squeal_contact::check_user_mu(mu)
            .map_err(|e| RunError::input("reference_mu", format!("{mu}: {e}")))?;
        if !(mu <= 0.8 && s.sweeps.iter().all(|(_, step)| on_grid(mu, *step))) {
            let mut steps: Vec<String> = s.sweeps.iter().map(|(_, st)| st.to_string()).collect();
            steps.dedup();
            return Err(RunError::input(
                "reference_mu",
                format!(
                    "{mu}: expected a point of every sweep (0 to 0.8, multiples of the steps {})",
                    steps.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// Runs the validation of `scene` (named `file`) into `out` (claimed by the caller),
/// writes `report.md` and `report.json` there and returns what they hold.
pub fn run(
    registry: &Registry,
    scene: &Scene,
    file: &str,
    s: &ValidateSettings,
    out: &Path,
    hooks: &mut dyn ValidateHooks,
) -> Result<Validation, RunError> {
    let start = Instant::now();
    let mut profile = Profile::new();
    // the sub-stages of each sweep, listed after the stages
    let mut detail = Profile::new();
    let mut lap = Instant::now();
    // each stage's own peak memory: the mark is reset at every stage's end
    let mut stage = |name: &str, lap: &mut Instant| {
        profile.add_with_peak(name, lap.elapsed().as_secs_f64(), take_peak_rss_mb());
        *lap = Instant::now();
    };
    let band = s.band_hz.unwrap_or(scene.study.band_hz);
    let n = 6;

    // 1. disc modes vs Table 2
    hooks.stage(1, n, "disc modes vs Table 2");
    let (disc, _, _) = crate::modal::body_modes(
        registry,
        scene,
        file,
        BodyKind::Disc,
        DISC_MODES_TOP_HZ,
        MODAL_SOLVER,
        1e-10,
    )?;
    let table2 = crate::modal::compare_table2(&disc.modes);
    outdir::prepare(&out.join("disc"))?;
    outdir::write(
        &out.join("disc/table2.txt"),
        crate::modal::format_table(&table2),
    )?;
    stage("disc modes", &mut lap);

    // 2. the rig: pin modes and stiffness
    hooks.stage(2, n, "the pin assembly's modes and the rig's stiffness");
    let (pin, _, _) = crate::modal::body_modes(
        registry,
        scene,
        file,
        BodyKind::Pin,
        PIN_MODES_TOP_HZ,
        MODAL_SOLVER,
        1e-10,
    )?;
    let pin_below: Vec<ModeRecord> = pin
        .modes
        .into_iter()
        .filter(|m| m.freq_hz < PIN_MODES_TOP_HZ)
        .collect();
    // the check sweeps' tied real modes, solved by one and read by the other, wait in
    // files of the report directory rather than in memory (a run stopped before its end
    // left its files there)
    ModalCache::remove_spill_folders(out);
    let modal_cache = ModalCache::spilling(SPILLED_MODES_BYTES, 0, out);
    let prep = Prepared::new(registry, scene.clone(), file)?.with_modal_cache(modal_cache);
    let eq0 = prep
        .equilibrium(registry, "lcp", "lagrange", 0.0)
        .map_err(outdir::stage("the rig's stiffness (equilibrium at mu = 0)"))?;
    let stiffness = eq0.total_normal_force_n / eq0.displacement_m;
    let force_at_datum = stiffness * paper().load_displacement_m;
    stage("rig", &mut lap);

    // 3. equilibria
    hooks.stage(3, n, "sliding equilibria");
    let eq_dir = out.join("equilibrium");
    let (equilibria, eqs) = crate::equilibria::run_into(
        registry,
        &prep,
        &EQUILIBRIUM_MU,
        "lcp",
        "lagrange",
        &Params::new(),
        &eq_dir,
    )?;
    hooks.equilibria(&eq_dir, &prep, &eqs)?;
    drop(eqs);
    stage("equilibria", &mut lap);

    // 4. sweeps
    let mut sweeps = Vec::new();
    let mut kept = Vec::new();
    let mut paper_rows = Vec::new();
    for (i, (basis, step)) in s.sweeps.iter().enumerate() {
        hooks.stage(
            4,
            n,
            &format!(
                "mu sweep with basis `{basis}`, step {step} ({} of {})",
                i + 1,
                s.sweeps.len()
            ),
        );
        let (summary, sweep) = run_sweep(registry, &prep, s, i, band, out, hooks)?;
        paper_rows.extend(paper_rows_of(basis, *step, &summary));
        detail.extend_prefixed(&format!("sweep {basis}: "), &sweep.profile);
        // a model stage (the synthesis of `cms`) is the largest thing the model keeps:
        // gone once no sweep ahead works from it (the references reuse the kept modes)
        let ahead = s.sweeps[i + 1..].iter().map(|(b, _)| b.as_str());
        prep.release_stages_except(&crate::pipeline::stage_keys(registry, ahead, band[1])?);
        // the references compare eigenvalues only: the mode shapes (n x modes, complex,
        // per basis and reference mu) are not kept for them
        let values = sweep
            .kept
            .into_iter()
            .map(|(mu, m)| (mu, eigenvalues_only(m)));
        kept.push((basis.clone(), values.collect::<Vec<_>>()));
        sweeps.push((basis.clone(), *step, summary));
        stage(&format!("sweep {basis} (step {step})"), &mut lap);
    }

    // 5. full-order reference points: they need none of what the sweeps kept (model
    // stages, free modes, the tied systems' real modes)
    hooks.stage(5, n, "full-order reference points");
    prep.release_kept();
    let references = references(registry, prep, s, band, &kept)?;
    stage("full-order references", &mut lap);

    // 6. report
    let peak = max_opt(profile.peak_rss_mb(), peak_rss_mb());
    let v = Validation {
        file: file.to_string(),
        disc,
        table2,
        pin_below,
        stiffness_n_per_m: stiffness,
        force_at_datum_n: force_at_datum,
        load: scene
            .load
            .normal_force_n
            .map_or("imposed displacement".to_string(), |f| format!("{f} N")),
        band_hz: band,
        equilibria,
        sweeps,
        references,
        paper_rows,
        eigen: s.eigen.clone(),
        profile,
        detail,
        peak_rss_mb: peak,
        time_s: start.elapsed().as_secs_f64(),
        machine: Machine::here(),
    };
    outdir::write(&out.join("report.md"), v.markdown())?;
    outdir::write_json(&out.join("report.json"), &v.json())?;
    Ok(v)
}

/// Runs sweep `i` of `s` into `out/sweep-<basis>` (afresh unless `s.resume`), keeping the
/// modes at the reference mu.
fn run_sweep(
    registry: &Registry,
    prep: &Prepared,
    s: &ValidateSettings,
    i: usize,
    band: [f64; 2],
    out: &Path,
    hooks: &mut dyn ValidateHooks,
) -> Result<(SweepSummary, MuSweep), RunError> {
    let (basis, step) = &s.sweeps[i];
    let dir = out.join(format!("sweep-{basis}"));
    if !s.resume {
        // a new validation: the sweep starts afresh
        for f in [
            "sweep.partial.jsonl",
            "sweep.partial.inputs.json",
            "summary.json",
        ] {
            let _ = std::fs::remove_file(dir.join(f));
        }
    }
    let mus =
        mu_list(0.0, 0.8, *step).map_err(|e| RunError::input(format!("sweeps[{i}].step"), e))?;
    let settings = MuSweepSettings {
        keep_modes_at: s.reference_mu.clone(),
        ..MuSweepSettings::new(mus, basis, band)
    };
    let (summary, sweep) = run_into(
        registry,
        prep,
        &settings,
        [0.0, 0.8, *step],
        &dir,
        true,
        &Profile::new(),
        |e| {
            // each point's blocks go back to the system as it ends: freed pieces of many
            // sizes would otherwise stay resident between the next point's blocks
            if matches!(e, SweepEvent::Point(_)) {
                crate::profile::return_free_memory();
            }
            hooks.sweep_event(&dir, prep, e)
        },
    )?;
    hooks.sweep_done(&dir, &summary, &sweep)?;
    Ok((summary, sweep))
}

/// The paper's couplings against the couplings of one sweep.
fn paper_rows_of(basis: &str, step: f64, summary: &SweepSummary) -> Vec<PaperRow> {
    paper()
        .couplings
        .iter()
        .map(|c| {
            let best = matching_coupling(&summary.couplings, c.freq_hz);
            PaperRow {
                paper_freq_hz: c.freq_hz,
                paper_mu: c.mu_range,
                basis: basis.to_string(),
                step,
                squeal_freq_hz: best.map(|c| c.freq_hz),
                squeal_mu: best.map(|c| [c.mu_from, c.mu_to]),
                max_dvr: best.map(|c| c.max_dvr),
                made_of: best.map_or(Vec::new(), |c| c.free_interface_mac.clone()),
            }
        })
        .collect()
}

/// `modes` without their shapes (`n x modes` complex values each): what the comparison
/// with full order reads.
fn eigenvalues_only(mut modes: ComplexModes) -> ComplexModes {
    modes.vectors = squeal_core::faer::Mat::zeros(0, 0);
    modes.left_vectors = None;
    modes
}

/// Full-order solves at the reference mu, and every swept basis against them. The
/// equilibria (and the basis solves a resumed sweep did not keep) come first, on the
/// whole prepared model; the full-order solves then run on the model and its contact set
/// alone, without the condensation's factor of `K`.
fn references(
    registry: &Registry,
    prep: Prepared,
    s: &ValidateSettings,
    band: [f64; 2],
    kept: &[(String, Vec<(f64, ComplexModes)>)],
) -> Result<Vec<RefRow>, RunError> {
    let params = EigenParams {
        fmin_hz: band[0],
        fmax_hz: band[1],
        tol: 1e-10,
        ..EigenParams::default()
    };
    let at = |mu: f64| outdir::stage(format!("full-order reference at mu = {mu}"));
    // each point's active set and the modes of every basis there
    let mut points = Vec::new();
    for &mu in &s.reference_mu {
        let active = prep
            .equilibrium(registry, "lcp", "lagrange", mu)
            .map_err(at(mu))?
            .eq
            .active;
        let mut modes = Vec::new();
        for (basis, modes_at) in kept {
            let found = modes_at.iter().find(|(m, _)| (m - mu).abs() < 1e-9);
            modes.push(match found {
                Some((_, m)) => m.clone(),
                // a resumed sweep computed this point in an earlier run: solve it again
                None => {
                    let op = prep.operator(&active).map_err(at(mu))?;
                    let mut method = Method::new(
                        registry,
                        basis,
                        &Params::new(),
                        "dense",
                        MODAL_SOLVER,
                        params.clone(),
                    )
                    .map_err(at(mu))?;
                    method.prepare_stage_on(&prep).map_err(at(mu))?;
                    method.share_modal_cache(prep.modal_cache());
                    eigenvalues_only(method.solve(&op, mu, true).map_err(at(mu))?.0)
                }
            });
        }
        points.push((mu, active, modes));
    }
    let (model, set, damping) = prep.into_model();
    crate::profile::return_free_memory();
    let mut refs = Vec::new();
    for (mu, active, modes) in points {
        let op = damped_operator(&model, &damping, &set, &active).map_err(at(mu))?;
        let t = Instant::now();
        let mut full = Method::new(
            registry,
            "none",
            &Params::new(),
            &s.eigen,
            MODAL_SOLVER,
            params.clone(),
        )
        .map_err(at(mu))?;
        let (reference, _, _) = full.solve(&op, mu, true).map_err(at(mu))?;
        let ref_time = t.elapsed().as_secs_f64();
        // the next point's factorization starts from a heap without this one's pieces
        drop((full, op));
        crate::profile::return_free_memory();
        for ((basis, _), modes) in kept.iter().zip(&modes) {
            refs.push(RefRow {
                mu,
                basis: basis.clone(),
                errors: compare(&reference, modes, band, 1e-6),
                reference_time_s: ref_time,
            });
        }
    }
    Ok(refs)
}
