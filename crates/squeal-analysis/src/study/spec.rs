//! What a study is: the zone grid or plateau layouts, how each case is solved, the
//! model's contact grid, the whole definition and its cases.

use super::{input, Axis, Result};
use crate::pipeline::Method;
use serde::{Deserialize, Serialize};
use squeal_contact::face_points;
use squeal_core::{EigenParams, Params, Registry};
use squeal_scene::{Model, Zone};

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
    /// Base seed; layout `l` of patch side `p` uses [`super::derive_seed`]`(seed, p in um, l)`,
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
    /// Physical margin on the divergence rate: a mode counts as unstable only when its DvR
    /// = Re/Im also exceeds this (0: its real part against its forward error bound alone
    /// decides, `squeal_core::operator::classify`).
    #[serde(alias = "dvr_tol")]
    pub dvr_margin: f64,
    /// Frequencies (Hz) that classify unstable modes: a mode belongs to the nearest
    /// class within `class_width` (relative), else to none.
    pub classes_hz: Vec<f64>,
    /// Relative half-width of a class: `|f - c| <= class_width * c`.
    pub class_width: f64,
}

impl SolveSpec {
    /// Checks the band, tolerances and classes, naming the fields.
    pub fn check(&self) -> Result<()> {
        let [lo, hi] = self.band_hz;
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo) {
            return Err(input(
                "solve.band_hz",
                format!("expected 0 <= FMIN < FMAX (Hz), got {lo}:{hi}"),
            ));
        }
        if !(self.tol > 0.0 && self.tol < 1.0) {
            return Err(input(
                "solve.tol",
                format!("expected a tolerance in (0, 1), got {}", self.tol),
            ));
        }
        if !(self.dvr_margin.is_finite() && self.dvr_margin >= 0.0) {
            return Err(input(
                "solve.dvr_margin",
                format!("expected a DvR margin >= 0, got {}", self.dvr_margin),
            ));
        }
        if self.classes_hz.is_empty()
            || self.classes_hz.iter().any(|c| !(c.is_finite() && *c > 0.0))
        {
            return Err(input(
                "solve.classes_hz",
                format!("expected frequencies > 0 Hz, got {:?}", self.classes_hz),
            ));
        }
        if !(self.class_width > 0.0 && self.class_width < 1.0) {
            return Err(input(
                "solve.class_width",
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
            let (k, v) = Params::parse_kv(kv)
                .map_err(|e| input("solve.basis_params", format!("`{kv}`: {e}")))?;
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
                "scene",
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
