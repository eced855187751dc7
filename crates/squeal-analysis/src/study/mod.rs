//! Long studies over contact zones: the paper's macroscopic effective zones (section 3.1,
//! a rectangle `(x0, y0, a, b)` on the pin face) and mesoscopic plateau layouts (section
//! 3.2, seeded random patches inside a fixed region).
//!
//! **Cases.** A study is a [`StudyDef`] (what to run: the zone grid or the plateau
//! layouts, friction coefficients, methods, the model's contact grid) from which
//! [`StudyDef::cases`] derives the case list, a pure function of the definition: each
//! [`Case`] has a stable id built from its parameters (`mu03600-x004000-y002900-a012000-b014200`:
//! mu to 1e-4, lengths in um; `mu03600-p000400-l00017` for patch 0.4 mm, layout 17), and
//! the list is sorted by id. Zones that do not fit in the pin face, and zones or layouts
//! that hold no contact pair, are skipped and counted.
//!
//! **Physics of a case.** Every pair of the zone is closed and sliding (no equilibrium
//! solve): the contact set is built on the zone directly and the frictional operator on
//! all its pairs, on a model built once for the whole study; the modes come from a
//! [`Method`] (a reduction basis and an eigen solver, or full order).
//!
//! **Records.** Each finished case is appended at once to `results.jsonl` (one
//! [`Record`] a line) and its wall times to `timings.jsonl` (one [`Timing`] a line): a
//! killed run loses nothing, and a resumed run skips the ids already there. Records hold no
//! times, so `results.jsonl` (rewritten sorted by id when a run ends) and `summary.json`
//! are pure functions of the definition: a resumed run, a run with any number of jobs, or
//! shards merged by [`merge`] give them byte for byte. Times live in `timings.jsonl` and
//! `timings.json`.

use crate::pipeline::{Method, PipelineError};
use serde::{Deserialize, Serialize};
use squeal_contact::face_points;
use squeal_core::{EigenParams, Params, Registry};
use squeal_scene::{Model, Zone};
use std::path::{Path, PathBuf};
use thiserror::Error;

mod run;
mod summary;
#[cfg(test)]
mod tests;

pub use run::{
    merge, run, run_case, Progress, Record, RunOptions, RunReport, StudyDir, Timing, UnstableMode,
};
pub use summary::{
    summarize, wilson95, ClassSummary, GridSummary, MuSummary, PatchSummary, Summary, TimingSummary,
};

/// Errors of studies; each names the option, file or case concerned.
#[derive(Debug, Error)]
pub enum StudyError {
    /// A bad input, named by its command-line option.
    #[error("{option}: {message}")]
    Input {
        /// The option, e.g. `--shard`.
        option: String,
        /// What is wrong and what is expected.
        message: String,
    },
    /// A study directory that cannot be used.
    #[error("{}: {message}", .path.display())]
    Files {
        /// The file or directory.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The model or a method.
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
}

/// Result with [`StudyError`].
pub type Result<T> = std::result::Result<T, StudyError>;

pub(crate) fn input(option: &str, message: impl Into<String>) -> StudyError {
    StudyError::Input {
        option: option.into(),
        message: message.into(),
    }
}

pub(crate) fn files(path: &Path, message: impl std::fmt::Display) -> StudyError {
    StudyError::Files {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

// ---------------------------------------------------------------------------------------
// Inputs.

/// Parses a list of numbers: comma-separated values and inclusive ranges
/// `FROM:TO:STEP` (e.g. `0.004:0.02:0.002,0.025`), in the given order; `option` names the
/// option in errors.
pub fn parse_list(option: &str, text: &str) -> Result<Vec<f64>> {
    let num = |s: &str| -> Result<f64> {
        let v = s
            .trim()
            .parse::<f64>()
            .map_err(|_| input(option, format!("`{s}` in `{text}` is not a number")))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(input(option, format!("`{s}` in `{text}` is not finite")))
        }
    };
    let mut out = Vec::new();
    for item in text.split(',').map(str::trim) {
        if item.is_empty() {
            return Err(input(
                option,
                format!("empty item in `{text}`: expected values or FROM:TO:STEP ranges, comma separated"),
            ));
        }
        let parts: Vec<&str> = item.split(':').collect();
        match parts.as_slice() {
            [v] => out.push(num(v)?),
            [a, b, c] => {
                let (a, b, c) = (num(a)?, num(b)?, num(c)?);
                if !(c > 0.0 && b >= a) {
                    return Err(input(
                        option,
                        format!(
                            "range `{item}`: expected FROM:TO:STEP with FROM <= TO and STEP > 0"
                        ),
                    ));
                }
                let n = ((b - a) / c + 1e-9).floor() as usize;
                if n > 100_000 {
                    return Err(input(
                        option,
                        format!("range `{item}` has {} values (at most 100001)", n + 1),
                    ));
                }
                out.extend((0..=n).map(|k| ((a + k as f64 * c) * 1e12).round() / 1e12));
            }
            _ => {
                return Err(input(
                    option,
                    format!("`{item}`: expected a value or FROM:TO:STEP"),
                ))
            }
        }
    }
    Ok(out)
}

/// Where zones start along one axis: centred on the pin face, or at given offsets from
/// the face corner (m).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// The zone's centre on the face centre: `x0 = (size - a) / 2`.
    Centred,
    /// Offsets from the face corner (m).
    Values(Vec<f64>),
}

impl Axis {
    /// `centred` (or `centered`, `center`) or a list as in [`parse_list`], offsets >= 0.
    pub fn parse(option: &str, text: &str) -> Result<Self> {
        if matches!(text.trim(), "centred" | "centered" | "center" | "centre") {
            return Ok(Axis::Centred);
        }
        let v = parse_list(option, text)?;
        if let Some(x) = v.iter().find(|x| **x < 0.0) {
            return Err(input(
                option,
                format!("expected offsets >= 0 m from the pin face corner (or `centred`), got {x}"),
            ));
        }
        Ok(Axis::Values(v))
    }

    fn offsets(&self, size: f64, len: f64) -> Vec<f64> {
        match self {
            Axis::Centred => vec![((size - len) / 2.0 * 1e12).round() / 1e12],
            Axis::Values(v) => v.clone(),
        }
    }
}

/// Part `K` of `N` of a study: the cases whose index (in id order) is `K - 1` modulo `N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// 1-based part.
    pub k: usize,
    /// Number of parts.
    pub n: usize,
}

impl Shard {
    /// Parses `K/N` with `1 <= K <= N`.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            input(
                "--shard",
                format!(
                    "`{text}`: expected K/N with 1 <= K <= N (e.g. 2/8: the second of 8 parts)"
                ),
            )
        };
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let (k, n) = (
            k.trim().parse::<usize>().map_err(|_| bad())?,
            n.trim().parse::<usize>().map_err(|_| bad())?,
        );
        if k == 0 || n == 0 || k > n {
            return Err(bad());
        }
        Ok(Self { k, n })
    }

    /// Whether case `index` belongs to this shard.
    pub fn holds(&self, index: usize) -> bool {
        index % self.n == self.k - 1
    }
}

/// Parses a region `x0,y0,a,b` (m from the pin face corner).
pub fn parse_region(option: &str, text: &str) -> Result<[f64; 4]> {
    let v = parse_list(option, text)?;
    match v.as_slice() {
        [x0, y0, a, b] if *x0 >= 0.0 && *y0 >= 0.0 && *a > 0.0 && *b > 0.0 => Ok([*x0, *y0, *a, *b]),
        _ => Err(input(
            option,
            format!("`{text}`: expected x0,y0,a,b in m (x0, y0 >= 0 from the pin face corner, a, b > 0)"),
        )),
    }
}

/// The macroscopic zone grid (paper section 3.1): every combination of the lists.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MacroSpec {
    /// Friction coefficients.
    pub mu: Vec<f64>,
    /// Zone starts along x (sliding direction).
    pub x0: Axis,
    /// Zone starts along y (radius).
    pub y0: Axis,
    /// Zone lengths along x (m).
    pub a_m: Vec<f64>,
    /// Zone widths along y (m).
    pub b_m: Vec<f64>,
}

/// The mesoscopic plateau layouts (paper section 3.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MesoSpec {
    /// Friction coefficients.
    pub mu: Vec<f64>,
    /// The macroscopic region cut into patches, `[x0, y0, a, b]` (m from the face corner).
    pub region_m: [f64; 4],
    /// Patch sides (m).
    pub patch_m: Vec<f64>,
    /// Layouts per patch size.
    pub layouts: usize,
    /// Fraction of the patches in contact, in (0, 1].
    pub fraction: f64,
    /// Base seed; layout `l` of patch side `p` uses [`derive_seed`]`(seed, p in um, l)`,
    /// so a layout does not change when other patch sizes are added or removed.
    pub seed: u64,
}

/// What a study varies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum StudySpec {
    /// Macroscopic rectangles.
    Macro(MacroSpec),
    /// Mesoscopic plateaus.
    Meso(MesoSpec),
}

/// How each case is solved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolveSpec {
    /// Reduction basis plugin, or `none` for full order.
    pub basis: String,
    /// Basis parameters `key=value`.
    pub basis_params: Vec<String>,
    /// Eigen solver (of the reduced problem with a basis).
    pub eigen: String,
    /// Sparse symmetric solver of the basis's real modes.
    pub modal: String,
    /// Band (Hz).
    pub band_hz: [f64; 2],
    /// Relative tolerance of the eigen solvers.
    pub tol: f64,
    /// A mode is unstable when its DvR exceeds this.
    pub dvr_tol: f64,
    /// Frequencies (Hz) that classify unstable modes: a mode belongs to the nearest
    /// class within `class_width` (relative), else to none.
    pub classes_hz: Vec<f64>,
    /// Relative half-width of a class: `|f - c| <= class_width * c`.
    pub class_width: f64,
}

impl SolveSpec {
    /// Checks the band, tolerances and classes, naming the options.
    pub fn check(&self) -> Result<()> {
        let [lo, hi] = self.band_hz;
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo) {
            return Err(input(
                "--band",
                format!("expected 0 <= FMIN < FMAX (Hz), got {lo}:{hi}"),
            ));
        }
        if !(self.tol > 0.0 && self.tol < 1.0) {
            return Err(input(
                "--tol",
                format!("expected a tolerance in (0, 1), got {}", self.tol),
            ));
        }
        if !(self.dvr_tol.is_finite() && self.dvr_tol >= 0.0) {
            return Err(input(
                "--dvr-tol",
                format!("expected a DvR threshold >= 0, got {}", self.dvr_tol),
            ));
        }
        if self.classes_hz.is_empty()
            || self.classes_hz.iter().any(|c| !(c.is_finite() && *c > 0.0))
        {
            return Err(input(
                "--classes",
                format!("expected frequencies > 0 Hz, got {:?}", self.classes_hz),
            ));
        }
        if !(self.class_width > 0.0 && self.class_width < 1.0) {
            return Err(input(
                "--class-width",
                format!(
                    "expected a relative half-width in (0, 1), got {}",
                    self.class_width
                ),
            ));
        }
        Ok(())
    }

    /// The class of a frequency: the nearest class frequency within `class_width`.
    pub fn class_of(&self, freq_hz: f64) -> Option<f64> {
        self.classes_hz
            .iter()
            .copied()
            .filter(|c| (freq_hz - c).abs() <= self.class_width * c)
            .min_by(|a, b| (a - freq_hz).abs().total_cmp(&(b - freq_hz).abs()))
    }

    fn eigen_params(&self) -> EigenParams {
        EigenParams {
            fmin_hz: self.band_hz[0],
            fmax_hz: self.band_hz[1],
            tol: self.tol,
            ..EigenParams::default()
        }
    }

    /// A [`Method`] for one worker.
    pub fn method(&self, registry: &Registry) -> Result<Method> {
        let mut params = Params::new();
        for kv in &self.basis_params {
            let (k, v) =
                Params::parse_kv(kv).map_err(|e| input("--basis-opt", format!("`{kv}`: {e}")))?;
            params.0.insert(k, v);
        }
        Ok(Method::new(
            registry,
            &self.basis,
            &params,
            &self.eigen,
            &self.modal,
            self.eigen_params(),
        )?)
    }
}

/// The contact grid of the model, in face coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridInfo {
    /// Pin face size `[size_x, size_y]` (m).
    pub face_m: [f64; 2],
    /// Pairs along x and y.
    pub n: [usize; 2],
    /// Largest grid spacing along x and y (m).
    pub spacing_m: [f64; 2],
    /// Every pair (m from the face corner), in grid order.
    pub points_m: Vec<[f64; 2]>,
}

impl GridInfo {
    /// The contact grid of `model`.
    pub fn of(model: &Model) -> Result<Self> {
        let grid = model.contact.as_ref().ok_or_else(|| {
            input(
                "SCENE",
                "the model has no contact pairs: a study needs a scene with a [disc] and a [pin]",
            )
        })?;
        let (points_m, face_m) = face_points(grid);
        let step = |v: &[f64]| v.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        Ok(Self {
            face_m,
            n: [grid.xs.len(), grid.ys.len()],
            spacing_m: [step(&grid.xs), step(&grid.ys)],
            points_m,
        })
    }

    /// Largest grid spacing along x and y between the grid lines inside the rectangle
    /// `[x0, y0, a, b]` (m from the face corner): the resolution a refined contact grid
    /// has there.
    pub fn spacing_in(&self, region_m: [f64; 4]) -> [f64; 2] {
        let [x0, y0, a, b] = region_m;
        let tol = 1e-9 * self.face_m[0].max(self.face_m[1]);
        let [xs, ys] = self.lines();
        let step = |v: &[f64], lo: f64, hi: f64| {
            // the lines inside, and the nearest line beyond each end
            let i0 = v.iter().rposition(|&x| x <= lo + tol).unwrap_or(0);
            let i1 = v.iter().position(|&x| x >= hi - tol).unwrap_or(v.len() - 1);
            v[i0..=i1]
                .windows(2)
                .map(|w| w[1] - w[0])
                .fold(0.0, f64::max)
        };
        [step(&xs, x0, x0 + a), step(&ys, y0, y0 + b)]
    }

    /// The grid lines along x and along y (m from the face corner).
    fn lines(&self) -> [Vec<f64>; 2] {
        [
            self.points_m[..self.n[0]].iter().map(|p| p[0]).collect(),
            (0..self.n[1])
                .map(|j| self.points_m[j * self.n[0]][1])
                .collect(),
        ]
    }

    /// The area each pair stands for, `[x_min, x_max, y_min, y_max]` (m), in grid order:
    /// bounded by the midlines to the neighbouring grid lines and by the face edges (a
    /// pair on an edge stands for half a cell). Where the grid is refined, the cells are
    /// as fine as the pairs.
    pub fn cells_m(&self) -> Vec<[f64; 4]> {
        let [xs, ys] = self.lines();
        let bx = squeal_scene::line_cells(&xs, 0.0, self.face_m[0]);
        let by = squeal_scene::line_cells(&ys, 0.0, self.face_m[1]);
        by.iter()
            .flat_map(|y| bx.iter().map(move |x| [x[0], x[1], y[0], y[1]]))
            .collect()
    }

    /// Pairs of the grid inside `zone`.
    pub fn pairs_in(&self, zone: &Zone) -> usize {
        zone.select(&self.points_m, self.face_m)
            .iter()
            .filter(|&&b| b)
            .count()
    }
}

/// A whole study: written to `study.json`, equal in every shard of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyDef {
    /// squeal version that defined the study.
    pub version: String,
    /// Scene (file or embedded name).
    pub scene: String,
    /// The scene as read, every default filled in (TOML): a resume or a merge with an
    /// edited scene file is refused.
    pub scene_toml: String,
    /// Free DOFs of the model.
    pub dofs: usize,
    /// Rotation sense of the disc.
    pub rotation: f64,
    /// Damping of the scene (absent: undamped).
    #[serde(default, skip_serializing_if = "squeal_scene::Damping::is_none")]
    pub damping: squeal_scene::Damping,
    /// The contact grid.
    pub grid: GridInfo,
    /// What varies.
    pub study: StudySpec,
    /// How cases are solved.
    pub solve: SolveSpec,
}

/// One case: a zone and a friction coefficient.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Case {
    /// Stable id (see the module docs).
    pub id: String,
    /// Friction coefficient.
    pub mu: f64,
    /// The zone, every pair of which is closed and sliding.
    pub zone: Zone,
    /// Patch side asked for (m; plateaus only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patch_m: Option<f64>,
    /// Layout number within its patch size (plateaus only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layout: Option<usize>,
    /// Contact pairs in the zone.
    pub pairs: usize,
    /// Nominal area of the zone (m^2): `a b`, or the patches' total area.
    pub area_m2: f64,
}

/// Cases skipped when the case list was built.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Skipped {
    /// Zones that do not fit in the pin face.
    pub outside_face: usize,
    /// Zones or layouts holding no contact pair.
    pub no_pairs: usize,
}

/// The case list of a study.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseList {
    /// Cases sorted by id.
    pub cases: Vec<Case>,
    /// What was skipped.
    pub skipped: Skipped,
    /// Layouts without pairs per patch size (meso; same order as `patch_m`).
    pub no_pairs_by_patch: Vec<usize>,
    /// Layouts that repeat an earlier layout of their patch size (meso; a small region
    /// holds few distinct layouts).
    pub repeats_by_patch: Vec<usize>,
}

/// The seed of layout `layout` of the patch side `patch_um` (um): splitmix64 of the three.
pub fn derive_seed(base: u64, patch_um: u64, layout: usize) -> u64 {
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    mix(mix(mix(base) ^ patch_um) ^ layout as u64)
}

fn um(v: f64) -> i64 {
    (v * 1e6).round() as i64
}

fn check_mu(mu: &[f64]) -> Result<()> {
    if mu.is_empty() {
        return Err(input("--mu", "expected at least one friction coefficient"));
    }
    if let Some(m) = mu.iter().find(|m| !(m.is_finite() && **m >= 0.0)) {
        return Err(input(
            "--mu",
            format!("expected friction coefficients >= 0, got {m} (reverse the scene's study.rotation instead of a negative mu)"),
        ));
    }
    Ok(())
}

fn positive(option: &str, v: &[f64], what: &str) -> Result<()> {
    if v.is_empty() {
        return Err(input(option, format!("expected at least one {what}")));
    }
    if let Some(x) = v.iter().find(|x| x.is_nan() || **x <= 0.0) {
        return Err(input(option, format!("expected {what}s > 0 m, got {x}")));
    }
    Ok(())
}

/// Every start and every length of one axis must fit in the face with at least one value
/// of the other list (combinations that do not fit are skipped and counted).
fn check_axis(
    start_opt: &str,
    len_opt: &str,
    starts: &Axis,
    lens: &[f64],
    size: f64,
    tol: f64,
) -> Result<()> {
    let min_len = lens.iter().copied().fold(f64::INFINITY, f64::min);
    if let Some(l) = lens.iter().find(|l| **l > size + tol) {
        return Err(input(
            len_opt,
            format!(
                "zone size {l} m is larger than the pin face ({size} m): expected values in (0, {size}] m"
            ),
        ));
    }
    if let Axis::Values(v) = starts {
        let min_start = v.iter().copied().fold(f64::INFINITY, f64::min);
        if let Some(x) = v.iter().find(|x| **x + min_len > size + tol) {
            return Err(input(
                start_opt,
                format!(
                    "a zone starting at {x} m leaves the pin face ({size} m) even with the \
                     smallest {len_opt} {min_len} m: expected {start_opt} in [0, {}] m (from \
                     the face corner)",
                    size - min_len
                ),
            ));
        }
        if let Some(l) = lens.iter().find(|l| min_start + **l > size + tol) {
            return Err(input(
                len_opt,
                format!(
                    "a zone of {l} m leaves the pin face ({size} m) even at the smallest \
                     {start_opt} {min_start} m: expected {len_opt} <= {} m",
                    size - min_start
                ),
            ));
        }
    }
    Ok(())
}

impl StudyDef {
    /// The definition of a study of `study` solved by `solve` on `model`, built from
    /// `scene` (named `file`), stamped with this crate's version.
    pub fn new(
        file: &str,
        scene: &squeal_scene::Scene,
        model: &Model,
        study: StudySpec,
        solve: SolveSpec,
    ) -> Result<Self> {
        Ok(Self {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: file.to_string(),
            scene_toml: scene.to_toml(),
            dofs: model.dofs.n_free(),
            rotation: scene.study.rotation,
            damping: scene.damping.clone(),
            grid: GridInfo::of(model)?,
            study,
            solve,
        })
    }

    /// The case list (sorted by id), with the skipped zones counted. Errors name the
    /// option when no case is left or an input is out of range.
    pub fn cases(&self) -> Result<CaseList> {
        let face = self.grid.face_m;
        let tol = 1e-9 * (face[0] + face[1]);
        let mut cases = Vec::new();
        let mut skipped = Skipped::default();
        let mut no_pairs_by_patch = Vec::new();
        let mut repeats_by_patch = Vec::new();
        match &self.study {
            StudySpec::Macro(s) => {
                check_mu(&s.mu)?;
                positive("--a", &s.a_m, "zone length")?;
                positive("--b", &s.b_m, "zone width")?;
                check_axis("--x0", "--a", &s.x0, &s.a_m, face[0], tol)?;
                check_axis("--y0", "--b", &s.y0, &s.b_m, face[1], tol)?;
                for &mu in &s.mu {
                    for &a in &s.a_m {
                        for &b in &s.b_m {
                            for x0 in s.x0.offsets(face[0], a) {
                                for y0 in s.y0.offsets(face[1], b) {
                                    let fits = x0 >= -tol
                                        && y0 >= -tol
                                        && x0 + a <= face[0] + tol
                                        && y0 + b <= face[1] + tol;
                                    if !fits {
                                        skipped.outside_face += 1;
                                        continue;
                                    }
                                    let (x0, y0) = (x0.max(0.0), y0.max(0.0));
                                    let zone = Zone::Rectangle {
                                        x0_m: x0,
                                        y0_m: y0,
                                        a_m: a,
                                        b_m: b,
                                    };
                                    let pairs = self.grid.pairs_in(&zone);
                                    if pairs == 0 {
                                        skipped.no_pairs += 1;
                                        continue;
                                    }
                                    cases.push(Case {
                                        id: format!(
                                            "mu{:05}-x{:06}-y{:06}-a{:06}-b{:06}",
                                            (mu * 1e4).round() as i64,
                                            um(x0),
                                            um(y0),
                                            um(a),
                                            um(b)
                                        ),
                                        mu,
                                        zone,
                                        patch_m: None,
                                        layout: None,
                                        pairs,
                                        area_m2: a * b,
                                    });
                                }
                            }
                        }
                    }
                }
                if cases.is_empty() {
                    return Err(input(
                        "--x0/--y0/--a/--b",
                        format!(
                            "no zone fits in the pin face ({} x {} mm) with a contact pair \
                             ({} outside the face, {} without a pair): zones are [x0, x0 + a] x \
                             [y0, y0 + b] in m from the face corner",
                            face[0] * 1e3,
                            face[1] * 1e3,
                            skipped.outside_face,
                            skipped.no_pairs
                        ),
                    ));
                }
            }
            StudySpec::Meso(s) => {
                check_mu(&s.mu)?;
                let [x0, y0, a, b] = s.region_m;
                if !(x0 >= 0.0
                    && y0 >= 0.0
                    && a > 0.0
                    && b > 0.0
                    && x0 + a <= face[0] + tol
                    && y0 + b <= face[1] + tol)
                {
                    return Err(input(
                        "--region",
                        format!(
                            "[{x0}, {y0}, {a}, {b}] must lie inside the pin face ({} x {} m) with a, b > 0",
                            face[0], face[1]
                        ),
                    ));
                }
                positive("--patch", &s.patch_m, "patch side")?;
                if let Some(p) = s.patch_m.iter().find(|p| **p > a.min(b) * (1.0 + 1e-9)) {
                    return Err(input(
                        "--patch",
                        format!(
                            "patch side {p} m does not fit in the region ({a} x {b} m, --region): \
                             expected patch sides <= {} m",
                            a.min(b)
                        ),
                    ));
                }
                let sp_in = self.grid.spacing_in(s.region_m);
                let sp = sp_in[0].max(sp_in[1]);
                if let Some(p) = s.patch_m.iter().find(|p| **p < sp * (1.0 - 1e-9)) {
                    return Err(input(
                        "--patch",
                        format!(
                            "patch side {:.3} mm is smaller than the contact grid spacing \
                             {:.3} mm of the scene in the region ({} x {} pairs on the face): \
                             expected patch sides >= {:.3} mm, or a scene with a finer contact \
                             grid there (mesh.contact_refinement = {{ region_m = [{}, {}, {}, \
                             {}], element_m = {} }}, or a larger mesh.pin_face_elements; the \
                             paper used 0.2 mm contact elements)",
                            p * 1e3,
                            sp * 1e3,
                            self.grid.n[0],
                            self.grid.n[1],
                            sp * 1e3,
                            x0,
                            y0,
                            a,
                            b,
                            p / 2.0
                        ),
                    ));
                }
                if s.layouts == 0 {
                    return Err(input(
                        "--layouts",
                        "expected at least one layout per patch size",
                    ));
                }
                if !(s.fraction > 0.0 && s.fraction <= 1.0) {
                    return Err(input(
                        "--fraction",
                        format!(
                            "expected a fraction of the patches in (0, 1], got {}",
                            s.fraction
                        ),
                    ));
                }
                for &patch in &s.patch_m {
                    let mut empty = 0;
                    let mut repeats = 0;
                    let mut seen = std::collections::HashSet::new();
                    for l in 0..s.layouts {
                        let zone = Zone::Plateaus {
                            patch_m: patch,
                            seed: derive_seed(s.seed, um(patch).unsigned_abs(), l),
                            fraction: Some(s.fraction),
                            count: None,
                            region_m: Some(s.region_m),
                        };
                        let pairs = self.grid.pairs_in(&zone);
                        if pairs == 0 {
                            empty += 1;
                            continue;
                        }
                        let rects = zone.plateau_rectangles(face).unwrap_or_default();
                        let key: Vec<[i64; 2]> =
                            rects.iter().map(|r| [um(r[0]), um(r[1])]).collect();
                        if !seen.insert(key) {
                            repeats += 1;
                        }
                        let area_m2 = rects.iter().map(|r| r[2] * r[3]).sum();
                        for &mu in &s.mu {
                            cases.push(Case {
                                id: format!(
                                    "mu{:05}-p{:06}-l{:05}",
                                    (mu * 1e4).round() as i64,
                                    um(patch),
                                    l
                                ),
                                mu,
                                zone: zone.clone(),
                                patch_m: Some(patch),
                                layout: Some(l),
                                pairs,
                                area_m2,
                            });
                        }
                    }
                    skipped.no_pairs += empty * s.mu.len();
                    no_pairs_by_patch.push(empty);
                    repeats_by_patch.push(repeats);
                }
                if cases.is_empty() {
                    return Err(input(
                        "--patch",
                        format!(
                            "no layout holds a contact pair: the patches are smaller than the \
                             contact grid spacing ({:.3} x {:.3} mm); raise mesh.pin_face_elements \
                             in the scene or use larger patches",
                            self.grid.spacing_m[0] * 1e3,
                            self.grid.spacing_m[1] * 1e3
                        ),
                    ));
                }
            }
        }
        cases.sort_by(|a, b| a.id.cmp(&b.id));
        if let Some(w) = cases.windows(2).find(|w| w[0].id == w[1].id) {
            let option = match self.study {
                StudySpec::Macro(_) => "--mu/--x0/--y0/--a/--b",
                StudySpec::Meso(_) => "--mu/--patch",
            };
            return Err(input(
                option,
                format!(
                    "two cases have the same id {} (duplicate values, or values closer than 1 um / 1e-4 in mu)",
                    w[0].id
                ),
            ));
        }
        Ok(CaseList {
            cases,
            skipped,
            no_pairs_by_patch,
            repeats_by_patch,
        })
    }

    /// Human-readable warnings (patches below the contact grid spacing, skipped cases).
    pub fn warnings(&self, list: &CaseList) -> Vec<String> {
        let mut w = Vec::new();
        if let StudySpec::Meso(s) = &self.study {
            for (i, &p) in s.patch_m.iter().enumerate() {
                if let Some(&n) = list.no_pairs_by_patch.get(i) {
                    if n > 0 {
                        w.push(format!(
                            "patch {:.3} mm: {n} of {} layouts hold no contact pair and were skipped",
                            p * 1e3,
                            s.layouts
                        ));
                    }
                }
                if let Some(&n) = list.repeats_by_patch.get(i) {
                    if n > 0 {
                        w.push(format!(
                            "patch {:.3} mm: {n} of {} layouts repeat an earlier one (the region \
                             holds few distinct layouts of this patch size; the fraction counts \
                             each repeat)",
                            p * 1e3,
                            s.layouts
                        ));
                    }
                }
            }
        }
        if list.skipped.outside_face > 0 {
            w.push(format!(
                "{} zones do not fit in the pin face and were skipped",
                list.skipped.outside_face
            ));
        }
        if list.skipped.no_pairs > 0 && matches!(self.study, StudySpec::Macro(_)) {
            w.push(format!(
                "{} zones hold no contact pair and were skipped",
                list.skipped.no_pairs
            ));
        }
        w
    }
}
