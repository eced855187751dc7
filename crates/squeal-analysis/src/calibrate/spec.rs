//! The calibration spec: a TOML file naming the base scene, the parameters (scene paths
//! with bounds and a scale) and the weighted targets (`docs/calibrate.md`).

use serde::{Deserialize, Serialize};
use squeal_scene::Scene;
use std::path::Path;
use thiserror::Error;

/// A spec that cannot be used; each names the file and the field.
#[derive(Debug, Error)]
pub enum SpecError {
    /// Unreadable file.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// Path.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// TOML syntax, unknown field, wrong type.
    #[error("{file}: {message}")]
    Parse {
        /// Path.
        file: String,
        /// The parser's message.
        message: String,
    },
    /// A field with an invalid value.
    #[error("{file}: field `{field}`: {message}")]
    Field {
        /// Path.
        file: String,
        /// Dotted field name, e.g. `parameter[1].min`.
        field: String,
        /// What is expected.
        message: String,
    },
    /// The base scene.
    #[error(transparent)]
    Scene(#[from] squeal_scene::SceneError),
}

/// A calibration: what to fit, within which bounds, to which targets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationSpec {
    /// The base scene: an embedded scene name or a TOML file relative to the spec.
    pub scene: String,
    /// How the search runs.
    #[serde(default)]
    pub search: Search,
    /// What may change.
    #[serde(default, rename = "parameter")]
    pub parameters: Vec<Parameter>,
    /// What the model should match.
    #[serde(rename = "target")]
    pub targets: Vec<Target>,
}

/// How the search runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Search {
    /// Scene values (dotted path = number) of the cheap rule the search evaluates, e.g.
    /// `"mesh.elements_per_wavelength" = 8.0`; empty: the search runs on the scene's own
    /// rule. Each target is corrected by the ratio of the scene's own rule to this one,
    /// measured at the search's result, and the search repeated (`corrections` times).
    pub rule: std::collections::BTreeMap<String, f64>,
    /// Correction rounds (each: one evaluation on the scene's own rule and a new search
    /// from the last point with corrected targets). 0: no confirmation run.
    pub corrections: usize,
    /// Most model evaluations of one search (finite-difference Jacobians included).
    pub max_evaluations: usize,
    /// Stop when a step lowers the cost by less than this fraction of it.
    pub tolerance: f64,
    /// Forward-difference step of the Jacobian, as a fraction of each parameter's range
    /// (in its scale).
    pub difference_step: f64,
    /// The search method: `gauss-newton` (a trust region on the residuals, for smooth
    /// targets) or `nelder-mead` (a simplex on the cost, for targets that jump, such as
    /// couplings).
    pub method: Method,
    /// Eigen solver of the modal targets.
    pub eigen: String,
    /// Equilibrium solver of the stiffness target and the equilibrium contact sets.
    pub equilibrium: String,
    /// The mu sweep of the coupling targets.
    pub sweep: SweepSearch,
}

/// The mu sweep that coupling targets measure (one per evaluation, shared by them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SweepSearch {
    /// `[from, to, step]` of mu.
    pub mu: [f64; 3],
    /// Band (Hz).
    pub band_hz: [f64; 2],
    /// Reduction basis (`none`: full order).
    pub basis: String,
}

impl Default for SweepSearch {
    fn default() -> Self {
        Self {
            mu: [0.1, 0.8, 0.02],
            band_hz: [0.0, 5000.0],
            basis: "cms".into(),
        }
    }
}

impl Default for Search {
    fn default() -> Self {
        Self {
            rule: Default::default(),
            corrections: 1,
            max_evaluations: 80,
            tolerance: 1e-3,
            difference_step: 0.02,
            method: Method::GaussNewton,
            eigen: "arpack".into(),
            equilibrium: "lcp".into(),
            sweep: SweepSearch::default(),
        }
    }
}

/// The search method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Trust-region Gauss-Newton with a forward-difference Jacobian.
    GaussNewton,
    /// Nelder-Mead simplex on the cost.
    NelderMead,
}

/// How a parameter is searched: in its logarithm or linearly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    /// Uniform steps of the value.
    #[default]
    Linear,
    /// Uniform steps of its logarithm (positive bounds).
    Log,
}

/// One scene value the fit may change.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parameter {
    /// Dotted path of a numeric scene field (`thin_plate.thickness_m`).
    pub path: String,
    /// Lower bound (the field's unit).
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// Search scale.
    #[serde(default)]
    pub scale: Scale,
    /// Start value; absent: the base scene's value (the middle of the range when the
    /// scene leaves the field to its default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<f64>,
}

impl Parameter {
    /// The parameter's position in `[0, 1]` over its range, in its scale.
    pub fn to_unit(&self, x: f64) -> f64 {
        match self.scale {
            Scale::Linear => (x - self.min) / (self.max - self.min),
            Scale::Log => (x / self.min).ln() / (self.max / self.min).ln(),
        }
    }

    /// The value at position `u` in `[0, 1]`.
    pub fn from_unit(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        match self.scale {
            Scale::Linear => self.min + u * (self.max - self.min),
            Scale::Log => self.min * (self.max / self.min).powf(u),
        }
    }
}

/// One weighted target.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "toml::Table")]
pub struct Target {
    /// Name in reports; absent: made from the kind.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Weight of the target's residual (>= 0; 0 reports it without fitting it).
    pub weight: f64,
    /// Relative tolerance band: a value within `within` of the target has no residual
    /// (Table 2 "within 5 %"); default 0.
    pub within: f64,
    /// What is measured.
    #[serde(flatten)]
    pub kind: TargetKind,
}

impl TryFrom<toml::Table> for Target {
    type Error = String;
    /// `name` and `weight` are read here and the rest as the kind's own table, so an
    /// unknown field is refused (serde's `flatten` would let it pass).
    fn try_from(mut table: toml::Table) -> Result<Self, String> {
        let name = match table.remove("name") {
            None => None,
            Some(toml::Value::String(s)) => Some(s),
            Some(v) => return Err(format!("`name`: expected a string, got {}", v.type_str())),
        };
        let weight = match table.remove("weight") {
            None => 1.0,
            Some(toml::Value::Float(w)) => w,
            Some(toml::Value::Integer(w)) => w as f64,
            Some(v) => return Err(format!("`weight`: expected a number, got {}", v.type_str())),
        };
        let within = match table.remove("within") {
            None => 0.0,
            Some(toml::Value::Float(w)) => w,
            Some(toml::Value::Integer(w)) => w as f64,
            Some(v) => return Err(format!("`within`: expected a number, got {}", v.type_str())),
        };
        let kind = TargetKind::deserialize(toml::Value::Table(table))
            .map_err(|e| e.message().trim_end().to_string())?;
        Ok(Target {
            name,
            weight,
            within,
            kind,
        })
    }
}

/// What a target measures; its residual is the log-ratio of model to target (count
/// targets: how far the modes around the threshold are on the wrong side of it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TargetKind {
    /// Axial stiffness of the rig at mu = 0 on the whole face: the total normal force
    /// over the disc clamp's approach (N/m). The paper's datum: 200 N at 125 um.
    Stiffness {
        /// Target (N/m).
        value_n_per_m: f64,
    },
    /// A labelled normal mode of one body with a free contact face (the mean of a
    /// doublet): `body = "disc"`, `label = "a,0,4"`, or `body = "pin"`, `label =
    /// "tilt-y"` (the lowest such).
    Mode {
        /// `disc` or `pin` (the pin with its plates).
        body: String,
        /// Automatic label (`squeal modes`).
        label: String,
        /// Target (Hz).
        freq_hz: f64,
    },
    /// Exactly `count` normal modes of `body` below `below_hz`.
    ModeCount {
        /// `disc` or `pin`.
        body: String,
        /// Threshold (Hz).
        below_hz: f64,
        /// Wanted count.
        count: usize,
    },
    /// An instability of the stability analysis itself (the mu sweep of
    /// `search.sweep`): the coupling within 15 % of `freq_hz` with the largest DvR, its
    /// frequency against `freq_hz` and its first and last unstable mu against `mu_range`.
    Coupling {
        /// Target (Hz).
        freq_hz: f64,
        /// Where the mode should be unstable.
        mu_range: [f64; 2],
    },
    /// A mode of the tied system (the closed pairs bonded, mu = 0) picked by its make-up:
    /// the largest MAC share on the free-interface modes whose `body:label` starts with
    /// `makeup` within `window_hz`. `makeup` may list alternatives separated by `|`:
    /// `pin:tilt-y|pin:shift-x` is the pin's rocking in the sliding plane (its pitch, with
    /// the translation it carries on its plate).
    TiedMode {
        /// Contact set: the sliding equilibrium's at this mu; absent: the whole face.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        mu: Option<f64>,
        /// Free-interface label prefix (`pin:tilt-y`, `disc:a,0,4`, `pin:`), or several
        /// separated by `|`.
        makeup: String,
        /// Target (Hz).
        freq_hz: f64,
        /// Count only the lowest this many free-interface modes that match `makeup`
        /// (`1`: the pin's first rocking mode, not its higher bending ones); absent: all.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        makeup_lowest: Option<usize>,
        /// Where the mode is looked for (Hz); default: half to twice the target.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        window_hz: Option<[f64; 2]>,
    },
}

impl Target {
    /// The target's name: given, or made from its kind.
    pub fn label(&self) -> String {
        if let Some(n) = &self.name {
            return n.clone();
        }
        match &self.kind {
            TargetKind::Stiffness { .. } => "stiffness".into(),
            TargetKind::Mode { body, label, .. } => format!("{body}:{label}"),
            TargetKind::ModeCount { body, below_hz, .. } => {
                format!("{body} modes below {below_hz} Hz")
            }
            TargetKind::Coupling { freq_hz, mu_range } => {
                format!("coupling {freq_hz} Hz, mu {}-{}", mu_range[0], mu_range[1])
            }
            TargetKind::TiedMode { mu, makeup, .. } => match mu {
                Some(mu) => format!("tied {makeup} at mu {mu}"),
                None => format!("tied {makeup} (full face)"),
            },
        }
    }

    /// The target value in its unit (Hz, N/m, a count).
    pub fn value(&self) -> f64 {
        match &self.kind {
            TargetKind::Stiffness { value_n_per_m } => *value_n_per_m,
            TargetKind::Mode { freq_hz, .. }
            | TargetKind::TiedMode { freq_hz, .. }
            | TargetKind::Coupling { freq_hz, .. } => *freq_hz,
            TargetKind::ModeCount { count, .. } => *count as f64,
        }
    }

    /// Whether a ratio between two mesh rules applies to this target (not to counts).
    pub fn scalable(&self) -> bool {
        !matches!(self.kind, TargetKind::ModeCount { .. })
    }
}

impl CalibrationSpec {
    /// Reads and checks a spec file.
    pub fn from_file(path: &Path) -> Result<Self, SpecError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| SpecError::Io {
            file: file.clone(),
            source,
        })?;
        Self::from_toml(&text, &file)
    }

    /// Parses and checks a spec; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Self, SpecError> {
        let spec: Self = toml::from_str(text).map_err(|e| SpecError::Parse {
            file: file.into(),
            message: e.to_string().trim_end().replace('\n', " "),
        })?;
        spec.check(file)?;
        Ok(spec)
    }

    /// The base scene: a file relative to `dir` (the spec's folder), else an embedded name.
    pub fn load_scene(&self, dir: &Path, file: &str) -> Result<(Scene, String), SpecError> {
        let path = dir.join(&self.scene);
        if path.is_file() {
            return Ok((Scene::from_file(&path)?, path.display().to_string()));
        }
        if self.scene.ends_with(".toml") {
            return Err(SpecError::Field {
                file: file.into(),
                field: "scene".into(),
                message: format!("no scene file {}", path.display()),
            });
        }
        Scene::builtin(&self.scene)
            .map(|s| (s, format!("<builtin {}>", self.scene)))
            .map_err(|_| SpecError::Field {
                file: file.into(),
                field: "scene".into(),
                message: format!(
                    "`{}` is neither a scene file next to the spec nor an embedded scene \
                     ({})",
                    self.scene,
                    squeal_scene::BUILTIN_SCENES.join(", ")
                ),
            })
    }

    /// Start value of parameter `i`: given, the scene's, or the middle of its range.
    pub fn start_value(&self, i: usize, scene: &Scene) -> f64 {
        let p = &self.parameters[i];
        p.start
            .or_else(|| scene.value_at(&p.path))
            .unwrap_or_else(|| p.from_unit(0.5))
            .clamp(p.min, p.max)
    }
}
