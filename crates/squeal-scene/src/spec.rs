//! The scene file format (serde). Every length in metres, modulus in Pa, density in
//! kg/m^3, frequency in Hz; field names carry their unit.

use crate::{Result, SceneError};
use serde::{Deserialize, Serialize};
use squeal_core::{ParamValue, Params};
use std::collections::BTreeMap;

/// The embedded default scene, the paper's pin-on-disc rig.
pub const PIN_ON_DISC: &str = include_str!("../../../scenes/pin-on-disc.toml");

/// The same rig meshed at the paper's model size (about 300 000 DOFs).
pub const PIN_ON_DISC_PAPER: &str = include_str!("../../../scenes/pin-on-disc-paper.toml");

/// The same rig on a deliberately coarse mesh (about 1600 DOFs): tests and quick checks.
pub const PIN_ON_DISC_COARSE: &str = include_str!("../../../scenes/pin-on-disc-coarse.toml");

/// Names of the embedded scenes.
pub const BUILTIN_SCENES: [&str; 3] = ["pin-on-disc", "pin-on-disc-paper", "pin-on-disc-coarse"];

/// A material: plugin name plus its constants.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialSpec {
    /// Material plugin name (`isotropic`, `transversely_isotropic`, ...).
    pub kind: String,
    /// Constants passed to the plugin (names with units, e.g. `youngs_modulus_pa`).
    #[serde(flatten)]
    pub constants: BTreeMap<String, toml::Value>,
}

impl MaterialSpec {
    /// Converts the constants to plugin [`Params`]; `field` names the table for errors.
    pub fn params(&self, file: &str, field: &str) -> Result<Params> {
        let mut p = Params::new();
        for (k, v) in &self.constants {
            let value = match v {
                toml::Value::Float(x) => ParamValue::Num(*x),
                toml::Value::Integer(i) => ParamValue::Num(*i as f64),
                toml::Value::Boolean(b) => ParamValue::Bool(*b),
                toml::Value::String(s) => ParamValue::Str(s.clone()),
                toml::Value::Array(a) => ParamValue::List(
                    a.iter()
                        .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                        .collect::<Option<Vec<f64>>>()
                        .ok_or_else(|| SceneError::Field {
                            file: file.into(),
                            field: format!("{field}.{k}"),
                            message: "expected a list of numbers".into(),
                        })?,
                ),
                other => {
                    return Err(SceneError::Field {
                        file: file.into(),
                        field: format!("{field}.{k}"),
                        message: format!("expected a number, string or list, got {other}"),
                    })
                }
            };
            p.0.insert(k.clone(), value);
        }
        Ok(p)
    }
}

/// An annular disc about the z axis, its top face (z = 0) the friction face. Without a
/// hat it is clamped on its inner cylinder; with one, at the hat's lower end.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Disc {
    /// Inner radius of the disc ring (m): the clamped face when there is no hat.
    pub inner_radius_m: f64,
    /// Outer radius (m).
    pub outer_radius_m: f64,
    /// Thickness (m); the disc spans z in [-thickness, 0].
    pub thickness_m: f64,
    /// Hat joining the ring to the clamp (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hat: Option<Hat>,
    /// Material (of ring and hat).
    pub material: MaterialSpec,
    /// The disc's mesh imported from a Gmsh file instead of generated (optional); the
    /// dimensions above then only document the disc and place the pin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<MeshImport>,
}

/// A body mesh read from a Gmsh MSH 4.1 ASCII file of 8-node hexahedra
/// ([`squeal_io::read_msh`]) instead of generated: `mesh = { file = "disc.msh",
/// contact_group = "contact", fixed_groups = ["clamp"], scale = 1.0 }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshImport {
    /// The file, relative to the scene file's directory.
    pub file: String,
    /// Physical group of the contact face: the disc's friction face or the pin face.
    /// Required when the scene has both a disc and a pin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_group: Option<String>,
    /// Physical groups whose nodes are fixed (all three DOFs): the Dirichlet faces.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed_groups: Vec<String>,
    /// Factor from the file's length unit to metres (`0.001` for a file in mm).
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// The mesh as read by [`Scene::from_file`] (scaled to metres); `None` for a scene
    /// parsed from text, whose file [`build`](crate::build) reads relative to the
    /// working directory.
    #[serde(skip)]
    pub loaded: Option<ImportedMesh>,
}

fn unit_scale() -> f64 {
    1.0
}

/// A mesh read from a [`MeshImport`] file: where from, and the mesh in metres with the
/// file's physical groups as node sets.
#[derive(Clone, PartialEq)]
pub struct ImportedMesh {
    /// The path read.
    pub path: std::path::PathBuf,
    /// The mesh (body 0), coordinates scaled to metres.
    pub mesh: std::sync::Arc<squeal_fe::Mesh>,
}

impl std::fmt::Debug for ImportedMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "ImportedMesh({}: {} nodes, {} hexahedra, groups {:?})",
            self.path.display(),
            self.mesh.nodes.len(),
            self.mesh.hexes.len(),
            self.mesh.node_sets.keys().collect::<Vec<_>>()
        )
    }
}

impl MeshImport {
    /// Reads the file (relative to `dir`, or as given), scales it to metres and checks
    /// that every named group exists and holds nodes. `field` (`disc.mesh`, `pin.mesh`)
    /// and the scene `file` name the place in errors.
    pub fn load(
        &self,
        dir: Option<&std::path::Path>,
        file: &str,
        field: &str,
    ) -> Result<ImportedMesh> {
        let err = |f: &str, message: String| SceneError::Field {
            file: file.into(),
            field: format!("{field}.{f}"),
            message,
        };
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(err(
                "scale",
                format!(
                    "expected a positive factor from the file's unit to metres, got {}",
                    self.scale
                ),
            ));
        }
        let path = match dir {
            Some(d) => d.join(&self.file),
            None => std::path::PathBuf::from(&self.file),
        };
        if !path.is_file() {
            return Err(err(
                "file",
                format!(
                    "mesh file `{}` not found; expected a Gmsh MSH 4.1 ASCII file, relative to \
                     the scene file's directory",
                    path.display()
                ),
            ));
        }
        let mut mesh = squeal_io::read_msh(&path).map_err(|e| err("file", e.to_string()))?;
        for p in mesh.nodes.iter_mut() {
            p.iter_mut().for_each(|x| *x *= self.scale);
        }
        let groups = self
            .contact_group
            .iter()
            .map(|g| ("contact_group", g))
            .chain(self.fixed_groups.iter().map(|g| ("fixed_groups", g)));
        for (f, g) in groups {
            match mesh.node_sets.get(g) {
                Some(v) if !v.is_empty() => {}
                found => {
                    return Err(err(
                        f,
                        format!(
                            "{} `{g}` in {}; available physical groups: {}",
                            if found.is_some() {
                                "no hexahedron node in physical group"
                            } else {
                                "no physical group"
                            },
                            path.display(),
                            if mesh.node_sets.is_empty() {
                                "none".to_string()
                            } else {
                                mesh.node_sets
                                    .keys()
                                    .map(|k| format!("`{k}`"))
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            }
                        ),
                    ))
                }
            }
        }
        Ok(ImportedMesh {
            path,
            mesh: std::sync::Arc::new(mesh),
        })
    }
}

/// A hat: a thin cylindrical wall under the disc ring, from `radius_m` (default: the
/// ring's inner radius) outwards by `thickness_m`, `height_m` deep, clamped at its
/// lower end. It is the compliant
/// mounting that sets the rig disc's low rocking and in-plane (ovalling) modes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hat {
    /// Inner radius of the wall (m); absent means `disc.inner_radius_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_m: Option<f64>,
    /// Wall height below the ring (m).
    pub height_m: f64,
    /// Wall thickness (m), less than the ring's radial width.
    pub thickness_m: f64,
    /// An annular plate closing the wall's lower end, clamped at its bore (a bolted hub
    /// flange); absent: the wall's lower end is clamped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flange: Option<Flange>,
}

/// The hat's bottom plate: from the wall inward to `inner_radius_m`, where it is
/// clamped, `thickness_m` thick, under the wall.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Flange {
    /// Bore radius (m), where the flange is clamped; less than the wall's inner radius.
    pub inner_radius_m: f64,
    /// Plate thickness (m).
    pub thickness_m: f64,
}

/// The pin: a rectangular block standing on the disc's friction face.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pin {
    /// Radius of the pin face centre (the mean friction radius) (m).
    pub center_radius_m: f64,
    /// Face size along the sliding direction x (m).
    pub size_x_m: f64,
    /// Face size along the radius y (m).
    pub size_y_m: f64,
    /// Height (m).
    pub height_m: f64,
    /// Material (the pad's, transversely isotropic about z).
    pub material: MaterialSpec,
    /// The pin's mesh imported from a Gmsh file instead of generated (optional); the
    /// dimensions above then only document the pin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<MeshImport>,
}

/// A rectangular plate centred over the pin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plate {
    /// Length along x (m).
    pub length_x_m: f64,
    /// Width along y (m).
    pub width_y_m: f64,
    /// Thickness (m).
    pub thickness_m: f64,
    /// Which pair of edges of the thin plate is fixed (the thick plate is not fixed:
    /// `None` there); `None` on the thin plate means the two x ends.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clamp: Option<Clamp>,
    /// Material.
    pub material: MaterialSpec,
}

/// The fixed edges of the thin plate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Clamp {
    /// The two ends across x (x = +-length_x / 2): the plate bends along x.
    #[default]
    X,
    /// The two edges across y (y = centre +- width_y / 2): the plate bends along y.
    Y,
    /// All four edges.
    Xy,
}

impl Clamp {
    /// The node sets of a generated block that this clamp fixes.
    pub fn node_sets(self) -> &'static [&'static str] {
        match self {
            Clamp::X => &["xmin", "xmax"],
            Clamp::Y => &["ymin", "ymax"],
            Clamp::Xy => &["xmin", "xmax", "ymin", "ymax"],
        }
    }
}

/// How element sizes follow from the frequency band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MeshRule {
    /// Highest frequency the model must resolve (Hz).
    pub max_freq_hz: f64,
    /// Elements per bending wavelength at `max_freq_hz`.
    pub elements_per_wavelength: f64,
    /// Elements per bending wavelength of the thin and thick plates, when they need a
    /// finer rule than the other bodies; `None`: `elements_per_wavelength`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plate_elements_per_wavelength: Option<f64>,
    /// Minimum element layers through any thickness.
    pub min_layers: usize,
    /// Elements along each side of the pin face (the contact grid has
    /// `(pin_face_elements + 1)^2` pairs).
    pub pin_face_elements: usize,
    /// Growth ratio of consecutive element sizes away from the refined contact patch.
    pub grading_ratio: f64,
    /// A finer contact grid over part of the pin face, for mesoscopic contact studies:
    /// thin contact layers tied to the coarse bodies (see [`ContactRefinement`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_refinement: Option<ContactRefinement>,
    /// Most DOFs (3 per node) a build may reach: the meshes are counted before any is
    /// made, and a rule that asks for more is refused with its count (a typing error in
    /// `max_freq_hz` must not fill the memory). Raise it for a deliberately large model.
    pub max_dofs: usize,
}

/// Contact refinement: the contact grid gets lines every `element_m` or less inside
/// `region_m` (widened to the coarse grid lines around it), the coarse lines elsewhere.
/// The fine grid lives in two contact layers tied to the coarse bodies: on the pin, a
/// layer one coarse step thick (pad material, in place of the pin's first coarse layer);
/// on the disc, a layer `element_m` thick under the pin face (disc material, added on the
/// disc's surface; the pin assembly sits that much higher).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactRefinement {
    /// `[x0, y0, a, b]` (m): the refined rectangle, from the pin face's (-x, -y) corner
    /// (as contact zones), `a` along the sliding direction x, `b` radial.
    pub region_m: [f64; 4],
    /// Largest contact element side inside the region (m).
    pub element_m: f64,
}

impl Default for MeshRule {
    fn default() -> Self {
        Self {
            max_freq_hz: 10_500.0,
            elements_per_wavelength: 15.0,
            plate_elements_per_wavelength: None,
            min_layers: 4,
            pin_face_elements: 20,
            grading_ratio: 1.25,
            contact_refinement: None,
            max_dofs: 2_000_000,
        }
    }
}

/// A scene: the bodies present, their materials and the mesh rule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// The disc, if present.
    pub disc: Option<Disc>,
    /// The pin, if present.
    pub pin: Option<Pin>,
    /// The thin plate the pin is glued on, fixed at its x ends.
    pub thin_plate: Option<Plate>,
    /// The thick plate on the thin plate, over the pin.
    pub thick_plate: Option<Plate>,
    /// Mesh rule.
    #[serde(default)]
    pub mesh: MeshRule,
    /// Contact between the pin face and the disc.
    #[serde(default)]
    pub contact: ContactSpec,
    /// The load pressing the disc against the pin.
    #[serde(default)]
    pub load: Load,
    /// Friction coefficient and frequency band of the study.
    #[serde(default)]
    pub study: Study,
    /// Damping of the stability analysis (none by default).
    #[serde(default, skip_serializing_if = "Damping::is_none")]
    pub damping: Damping,
}

/// Which contact pairs may carry load (the effective zone is then decided by the
/// equilibrium within them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "snake_case")]
pub enum Zone {
    /// Every pair of the pin face.
    #[default]
    Uniform,
    /// Pairs inside the rectangle `[x0, x0 + a] x [y0, y0 + b]`, coordinates relative to
    /// the pin face's corner at (-size_x/2, center_radius - size_y/2) (m).
    Rectangle {
        /// Start along x (sliding direction) (m).
        x0_m: f64,
        /// Start along y (radius) (m).
        y0_m: f64,
        /// Length along x (m).
        a_m: f64,
        /// Width along y (m).
        b_m: f64,
    },
    /// Mesoscopic plateaus: the region (default the whole pin face; else the rectangle
    /// `region_m = [x0, y0, a, b]` as for `rectangle`) is cut into square patches of side
    /// `patch_m`, and a seeded random subset of them (`fraction` of the patches, or
    /// `count` patches) may touch. The same seed gives the same layout on every machine
    /// (splitmix64 + Fisher-Yates).
    Plateaus {
        /// Patch side (m).
        patch_m: f64,
        /// Random seed.
        seed: u64,
        /// Fraction of the patches in contact, in (0, 1].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        fraction: Option<f64>,
        /// Number of patches in contact.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        count: Option<usize>,
        /// Region cut into patches, `[x0, y0, a, b]` (m); absent: the whole face.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        region_m: Option<[f64; 4]>,
    },
    /// An explicit mask: one 0/1 per pair, row by row (along x) from the pin face's
    /// (-x, -y) corner, `(pin_face_elements + 1)^2` values; inline (`values`) or in a text
    /// file (`file`, whitespace or comma separated, relative to the scene file).
    Mask {
        /// The mask values.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        values: Option<Vec<u8>>,
        /// A mask file.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        file: Option<String>,
    },
}

impl Zone {
    /// Which of the points `xy` (m, relative to the pin face's corner, in grid order) lie
    /// in the zone on a face of `size = [size_x, size_y]`: rectangles and plateaus include
    /// their edges (to `1e-9` of the face size); a mask selects by index (`values[p] == 1`;
    /// the caller checks its length). The one inside test of contact sets, studies and maps.
    pub fn select(&self, xy: &[[f64; 2]], size: [f64; 2]) -> Vec<bool> {
        let eps = 1e-9 * (size[0] + size[1]);
        let in_rect = |p: &[f64; 2], r: &[f64; 4]| -> bool {
            p[0] >= r[0] - eps
                && p[0] <= r[0] + r[2] + eps
                && p[1] >= r[1] - eps
                && p[1] <= r[1] + r[3] + eps
        };
        let plateaus = self.plateau_rectangles(size);
        xy.iter()
            .enumerate()
            .map(|(i, p)| match self {
                Zone::Uniform => true,
                Zone::Rectangle {
                    x0_m,
                    y0_m,
                    a_m,
                    b_m,
                } => in_rect(p, &[*x0_m, *y0_m, *a_m, *b_m]),
                Zone::Plateaus { .. } => plateaus
                    .as_ref()
                    .is_some_and(|rs| rs.iter().any(|r| in_rect(p, r))),
                Zone::Mask { values, .. } => values.as_ref().is_some_and(|v| v.get(i) == Some(&1)),
            })
            .collect()
    }

    /// The rectangles `[x0, y0, a, b]` (m, from the pin face's corner) of a plateau
    /// layout on a face of `size = [size_x, size_y]`; `None` for other zones.
    pub fn plateau_rectangles(&self, size: [f64; 2]) -> Option<Vec<[f64; 4]>> {
        let Zone::Plateaus {
            patch_m,
            seed,
            fraction,
            count,
            region_m,
        } = self
        else {
            return None;
        };
        let [x0, y0, a, b] = region_m.unwrap_or([0.0, 0.0, size[0], size[1]]);
        let nx = ((a / patch_m).round() as usize).max(1);
        let ny = ((b / patch_m).round() as usize).max(1);
        let (px, py) = (a / nx as f64, b / ny as f64);
        let total = nx * ny;
        let want = match (fraction, count) {
            (Some(f), _) => ((f * total as f64).round() as usize).clamp(1, total),
            (None, Some(c)) => (*c).clamp(1, total),
            (None, None) => total,
        };
        let mut state = *seed;
        let mut next = || {
            // splitmix64
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let mut idx: Vec<usize> = (0..total).collect();
        for i in (1..total).rev() {
            let j = (next() % (i as u64 + 1)) as usize;
            idx.swap(i, j);
        }
        let mut chosen: Vec<usize> = idx[..want].to_vec();
        chosen.sort_unstable();
        Some(
            chosen
                .iter()
                .map(|&k| {
                    let (i, j) = (k % nx, k / nx);
                    [x0 + i as f64 * px, y0 + j as f64 * py, px, py]
                })
                .collect(),
        )
    }
}

/// Contact between the pin face and the disc.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSpec {
    /// Pairs allowed to touch.
    pub zone: Zone,
}

/// The load: a target total normal force, or an imposed axial displacement of the disc
/// towards the pin (exactly one of the two).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Load {
    /// Target total normal force (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_force_n: Option<f64>,
    /// Imposed axial displacement of the disc's clamped face towards the pin (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub disc_displacement_m: Option<f64>,
}

impl Default for Load {
    fn default() -> Self {
        Self {
            normal_force_n: Some(200.0),
            disc_displacement_m: None,
        }
    }
}

/// Friction and band of the study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Study {
    /// Coulomb friction coefficient.
    pub mu: f64,
    /// Frequency band of the stability analysis (Hz): every command's default `--band`.
    /// Default 0-5 kHz, where the paper's couplings lie; the mesh resolves up to
    /// `mesh.max_freq_hz`.
    pub band_hz: [f64; 2],
    /// Rotation sense of the disc about +z: `1` counter-clockwise, `-1` clockwise.
    pub rotation: f64,
}

impl Default for Study {
    fn default() -> Self {
        Self {
            mu: 0.3,
            band_hz: [0.0, 5_000.0],
            rotation: 1.0,
        }
    }
}

/// Damping of the stability analysis: `C = alpha M + beta K + C_t`, where `C_t` holds
/// viscous tangential dashpots between the pin and disc nodes of every closed contact
/// pair. None of it changes the static sliding equilibrium. Absent or all zero means
/// undamped (`C = 0`), the paper's setting.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct Damping {
    /// Rayleigh mass-proportional coefficient `alpha` (1/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rayleigh_alpha_per_s: Option<f64>,
    /// Rayleigh stiffness-proportional coefficient `beta` (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rayleigh_beta_s: Option<f64>,
    /// Rayleigh damping given instead as a modal damping ratio (dimensionless) reached at
    /// both frequencies of `rayleigh_freqs_hz`; excludes `rayleigh_alpha_per_s` and
    /// `rayleigh_beta_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rayleigh_ratio: Option<f64>,
    /// The two frequencies (Hz) where the modal damping ratio equals `rayleigh_ratio`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rayleigh_freqs_hz: Option<[f64; 2]>,
    /// Viscous tangential contact damping per unit contact area (N s/m^3): each closed
    /// pair gets a dashpot `c = value x tributary area` on the relative in-plane velocity
    /// of its pin and disc nodes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_tangential_n_s_per_m3: Option<f64>,
}

impl Damping {
    /// Whether no damping is given (the scene is undamped).
    pub fn is_none(&self) -> bool {
        *self == Damping::default()
    }

    /// The Rayleigh coefficients `(alpha (1/s), beta (s))`; a ratio `zeta` at
    /// `f1`, `f2` gives `alpha = 2 zeta w1 w2 / (w1 + w2)`, `beta = 2 zeta / (w1 + w2)`.
    pub fn rayleigh(&self) -> (f64, f64) {
        match (self.rayleigh_ratio, self.rayleigh_freqs_hz) {
            (Some(z), Some([f1, f2])) => {
                let (w1, w2) = (
                    2.0 * std::f64::consts::PI * f1,
                    2.0 * std::f64::consts::PI * f2,
                );
                (2.0 * z * w1 * w2 / (w1 + w2), 2.0 * z / (w1 + w2))
            }
            _ => (
                self.rayleigh_alpha_per_s.unwrap_or(0.0),
                self.rayleigh_beta_s.unwrap_or(0.0),
            ),
        }
    }

    /// Contact dashpot coefficient per unit area (N s/m^3), 0 when absent.
    pub fn contact_tangential(&self) -> f64 {
        self.contact_tangential_n_s_per_m3.unwrap_or(0.0)
    }

    /// One line for reports: `none`, or the Rayleigh coefficients and the contact
    /// dashpots with their units.
    pub fn describe(&self) -> String {
        if self.is_zero() {
            return "none".into();
        }
        let (a, b) = self.rayleigh();
        let mut parts = Vec::new();
        if a != 0.0 || b != 0.0 {
            let from = match (self.rayleigh_ratio, self.rayleigh_freqs_hz) {
                (Some(z), Some([f1, f2])) => format!(" (ratio {z} at {f1} and {f2} Hz)"),
                _ => String::new(),
            };
            parts.push(format!(
                "Rayleigh alpha = {a:.6e} 1/s, beta = {b:.6e} s{from}"
            ));
        }
        let c = self.contact_tangential();
        if c != 0.0 {
            parts.push(format!("contact tangential {c:e} N s/m^3"));
        }
        parts.join("; ")
    }

    /// Whether the damping matrix is zero.
    pub fn is_zero(&self) -> bool {
        let (a, b) = self.rayleigh();
        a == 0.0 && b == 0.0 && self.contact_tangential() == 0.0
    }

    fn validate(&self, file: &str) -> Result<()> {
        let field = |f: &str, m: String| SceneError::Field {
            file: file.into(),
            field: format!("damping.{f}"),
            message: m,
        };
        let non_negative = |f: &str, v: Option<f64>, unit: &str| -> Result<()> {
            match v {
                Some(v) if !(v.is_finite() && v >= 0.0) => Err(field(
                    f,
                    format!("expected a finite value >= 0 in {unit}, got {v}"),
                )),
                _ => Ok(()),
            }
        };
        non_negative("rayleigh_alpha_per_s", self.rayleigh_alpha_per_s, "1/s")?;
        non_negative("rayleigh_beta_s", self.rayleigh_beta_s, "s")?;
        non_negative(
            "contact_tangential_n_s_per_m3",
            self.contact_tangential_n_s_per_m3,
            "N s/m^3",
        )?;
        match (self.rayleigh_ratio, self.rayleigh_freqs_hz) {
            (None, None) => Ok(()),
            (Some(z), Some([f1, f2])) => {
                if self.rayleigh_alpha_per_s.is_some() || self.rayleigh_beta_s.is_some() {
                    return Err(field(
                        "rayleigh_ratio",
                        "give either rayleigh_ratio with rayleigh_freqs_hz or                          rayleigh_alpha_per_s / rayleigh_beta_s, not both"
                            .into(),
                    ));
                }
                if !(z.is_finite() && (0.0..1.0).contains(&z)) {
                    return Err(field(
                        "rayleigh_ratio",
                        format!("expected a damping ratio in [0, 1), got {z}"),
                    ));
                }
                if !(f1.is_finite() && f2.is_finite() && f1 > 0.0 && f2 > 0.0) {
                    return Err(field(
                        "rayleigh_freqs_hz",
                        format!("expected two positive frequencies in Hz, got [{f1}, {f2}]"),
                    ));
                }
                Ok(())
            }
            (Some(_), None) => Err(field(
                "rayleigh_freqs_hz",
                "rayleigh_ratio needs rayleigh_freqs_hz = [f1, f2] (Hz)".into(),
            )),
            (None, Some(_)) => Err(field(
                "rayleigh_ratio",
                "rayleigh_freqs_hz needs rayleigh_ratio (the damping ratio at both)".into(),
            )),
        }
    }
}

impl Scene {
    /// Parses a scene from TOML text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Scene> {
        let scene: Scene = toml::from_str(text).map_err(|e| SceneError::Parse {
            file: file.into(),
            message: e.to_string(),
        })?;
        scene.validate(file)?;
        Ok(scene)
    }

    /// Reads a scene file.
    pub fn from_file(path: &std::path::Path) -> Result<Scene> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            file: file.clone(),
            source,
        })?;
        let mut scene: Scene = toml::from_str(&text).map_err(|e| SceneError::Parse {
            file: file.clone(),
            message: e.to_string(),
        })?;
        if let Zone::Mask {
            values: values @ None,
            file: Some(mask),
        } = &mut scene.contact.zone
        {
            let mpath = path
                .parent()
                .unwrap_or(std::path::Path::new("."))
                .join(&*mask);
            let mname = mpath.display().to_string();
            let mtext = std::fs::read_to_string(&mpath).map_err(|source| SceneError::Io {
                file: format!("{mname} (contact.zone.file of {file})"),
                source,
            })?;
            let mut v = Vec::new();
            for (l, line) in mtext.lines().enumerate() {
                let line = line.split('#').next().unwrap_or("");
                for tok in line
                    .split(|c: char| c == ',' || c.is_whitespace())
                    .filter(|t| !t.is_empty())
                {
                    match tok {
                        "0" => v.push(0u8),
                        "1" => v.push(1u8),
                        other => {
                            return Err(SceneError::Field {
                                file: format!("{mname}:{}", l + 1),
                                field: "contact.zone.file".into(),
                                message: format!("expected 0 or 1, got `{other}`"),
                            })
                        }
                    }
                }
            }
            *values = Some(v);
        }
        scene.validate(&file)?;
        let dir = path.parent().unwrap_or(std::path::Path::new("."));
        if let Some(imp) = scene.disc.as_mut().and_then(|d| d.mesh.as_mut()) {
            imp.loaded = Some(imp.load(Some(dir), &file, "disc.mesh")?);
        }
        if let Some(imp) = scene.pin.as_mut().and_then(|p| p.mesh.as_mut()) {
            imp.loaded = Some(imp.load(Some(dir), &file, "pin.mesh")?);
        }
        Ok(scene)
    }

    /// An embedded scene by name (`pin-on-disc`, `pin-on-disc-paper`, `pin-on-disc-coarse`).
    pub fn builtin(name: &str) -> Result<Scene> {
        match name {
            "pin-on-disc" => Self::from_toml(PIN_ON_DISC, "<builtin pin-on-disc>"),
            "pin-on-disc-paper" => {
                Self::from_toml(PIN_ON_DISC_PAPER, "<builtin pin-on-disc-paper>")
            }
            "pin-on-disc-coarse" => {
                Self::from_toml(PIN_ON_DISC_COARSE, "<builtin pin-on-disc-coarse>")
            }
            other => Err(SceneError::Field {
                file: format!("<builtin {other}>"),
                field: "name".into(),
                message: format!(
                    "no such embedded scene; available: {}",
                    BUILTIN_SCENES.join(", ")
                ),
            }),
        }
    }

    /// Writes the scene back as TOML.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).expect("scene serializes")
    }

    /// Checks every dimension; errors name the field and the expected range.
    pub fn validate(&self, file: &str) -> Result<()> {
        self.damping.validate(file)?;
        let field = |f: &str, m: String| SceneError::Field {
            file: file.into(),
            field: f.into(),
            message: m,
        };
        let positive = |f: &str, v: f64| -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(field(
                    f,
                    format!("expected a positive length in metres, got {v}"),
                ))
            }
        };
        if let Some(d) = &self.disc {
            positive("disc.inner_radius_m", d.inner_radius_m)?;
            positive("disc.outer_radius_m", d.outer_radius_m)?;
            if d.inner_radius_m >= d.outer_radius_m {
                return Err(field(
                    "disc.inner_radius_m",
                    format!(
                        "{} m: expected less than disc.outer_radius_m = {} m",
                        d.inner_radius_m, d.outer_radius_m
                    ),
                ));
            }
            positive("disc.thickness_m", d.thickness_m)?;
            if let Some(hat) = &d.hat {
                positive("disc.hat.height_m", hat.height_m)?;
                positive("disc.hat.thickness_m", hat.thickness_m)?;
                let r0 = hat.radius_m.unwrap_or(d.inner_radius_m);
                if r0 < d.inner_radius_m || r0 + hat.thickness_m >= d.outer_radius_m {
                    return Err(field(
                        "disc.hat.radius_m",
                        format!(
                            "the wall ({r0} to {} m) must lie under the ring ({} to {} m)",
                            r0 + hat.thickness_m,
                            d.inner_radius_m,
                            d.outer_radius_m
                        ),
                    ));
                }
                if let Some(fl) = &hat.flange {
                    positive("disc.hat.flange.inner_radius_m", fl.inner_radius_m)?;
                    positive("disc.hat.flange.thickness_m", fl.thickness_m)?;
                    if fl.inner_radius_m >= r0 {
                        return Err(field(
                            "disc.hat.flange.inner_radius_m",
                            format!(
                                "expected less than the wall's inner radius {r0} m, got {}",
                                fl.inner_radius_m
                            ),
                        ));
                    }
                }
                if hat.thickness_m >= d.outer_radius_m - d.inner_radius_m {
                    return Err(field(
                        "disc.hat.thickness_m",
                        format!(
                            "expected less than the ring width {} m, got {}",
                            d.outer_radius_m - d.inner_radius_m,
                            hat.thickness_m
                        ),
                    ));
                }
            }
            if d.inner_radius_m >= d.outer_radius_m {
                return Err(field(
                    "disc.inner_radius_m",
                    format!(
                        "expected less than disc.outer_radius_m = {}, got {}",
                        d.outer_radius_m, d.inner_radius_m
                    ),
                ));
            }
        }
        if let Some(p) = &self.pin {
            positive("pin.center_radius_m", p.center_radius_m)?;
            positive("pin.size_x_m", p.size_x_m)?;
            positive("pin.size_y_m", p.size_y_m)?;
            positive("pin.height_m", p.height_m)?;
            if let Some(d) = &self.disc {
                let (r0, r1) = (
                    p.center_radius_m - p.size_y_m / 2.0,
                    p.center_radius_m + p.size_y_m / 2.0,
                );
                let rmax = (r1 * r1 + p.size_x_m * p.size_x_m / 4.0).sqrt();
                let wall = d.hat.as_ref().map_or(d.inner_radius_m, |h| {
                    h.radius_m.unwrap_or(d.inner_radius_m) + h.thickness_m
                });
                if r0 <= wall || rmax >= d.outer_radius_m {
                    return Err(field(
                        "pin.center_radius_m",
                        format!(
                            "the pin face (radii {r0:.4} to {rmax:.4} m) must lie on the disc face \
                             between radius {wall} (inner radius or hat wall) and \
                             disc.outer_radius_m = {}",
                            d.outer_radius_m
                        ),
                    ));
                }
            }
        }
        for (name, plate) in [
            ("thin_plate", &self.thin_plate),
            ("thick_plate", &self.thick_plate),
        ] {
            if let Some(pl) = plate {
                positive(&format!("{name}.length_x_m"), pl.length_x_m)?;
                positive(&format!("{name}.width_y_m"), pl.width_y_m)?;
                positive(&format!("{name}.thickness_m"), pl.thickness_m)?;
                if name == "thick_plate" && pl.clamp.is_some() {
                    return Err(field(
                        "thick_plate.clamp",
                        "only the thin plate is fixed: remove `clamp` from [thick_plate]".into(),
                    ));
                }
                if let Some(p) = &self.pin {
                    if pl.length_x_m < p.size_x_m || pl.width_y_m < p.size_y_m {
                        return Err(field(
                            &format!("{name}.length_x_m"),
                            format!(
                                "the plate ({} x {} m) must cover the pin face ({} x {} m)",
                                pl.length_x_m, pl.width_y_m, p.size_x_m, p.size_y_m
                            ),
                        ));
                    }
                }
            }
        }
        if (self.thin_plate.is_some() || self.thick_plate.is_some()) && self.pin.is_none() {
            return Err(field(
                "pin",
                "plates are placed over the pin: a [pin] table is required".into(),
            ));
        }
        if self.thick_plate.is_some() && self.thin_plate.is_none() {
            return Err(field(
                "thin_plate",
                "the thick plate sits on the thin plate: a [thin_plate] table is required".into(),
            ));
        }
        let m = &self.mesh;
        if !(m.max_freq_hz.is_finite() && m.max_freq_hz > 0.0) {
            return Err(field(
                "mesh.max_freq_hz",
                format!("expected a positive frequency in Hz, got {}", m.max_freq_hz),
            ));
        }
        if !(m.elements_per_wavelength.is_finite() && m.elements_per_wavelength >= 2.0) {
            return Err(field(
                "mesh.elements_per_wavelength",
                format!("expected a number >= 2, got {}", m.elements_per_wavelength),
            ));
        }
        if let Some(p) = m.plate_elements_per_wavelength {
            if !(p.is_finite() && p >= 2.0) {
                return Err(field(
                    "mesh.plate_elements_per_wavelength",
                    format!("expected a number >= 2, got {p}"),
                ));
            }
        }
        if m.max_dofs == 0 {
            return Err(field(
                "mesh.max_dofs",
                "expected a positive number of DOFs (default 2000000)".into(),
            ));
        }
        if m.min_layers == 0 {
            return Err(field(
                "mesh.min_layers",
                "expected at least 1 element layer through every thickness".into(),
            ));
        }
        if m.pin_face_elements == 0 {
            return Err(field(
                "mesh.pin_face_elements",
                "expected at least 1 element along each side of the pin face".into(),
            ));
        }
        if let Some(r) = &m.contact_refinement {
            let Some(p) = &self.pin else {
                return Err(field(
                    "mesh.contact_refinement",
                    "refines the pin face's contact grid: a [pin] table is required".into(),
                ));
            };
            if p.mesh.is_some() || self.disc.as_ref().is_some_and(|d| d.mesh.is_some()) {
                return Err(field(
                    "mesh.contact_refinement",
                    "only generated meshes are refined; an imported mesh brings its own grid"
                        .into(),
                ));
            }
            let step = p.size_x_m.min(p.size_y_m) / m.pin_face_elements as f64;
            if !(r.element_m.is_finite() && r.element_m > 0.0 && r.element_m < step) {
                return Err(field(
                    "mesh.contact_refinement.element_m",
                    format!(
                        "expected an element side in (0, {step:e}) m (below the coarse contact \
                         grid step), got {}",
                        r.element_m
                    ),
                ));
            }
            let [x0, y0, a, b] = r.region_m;
            let fits = |lo: f64, len: f64, size: f64| {
                lo.is_finite()
                    && len.is_finite()
                    && lo >= 0.0
                    && len > 0.0
                    && lo + len <= size * (1.0 + 1e-9)
            };
            if !(fits(x0, a, p.size_x_m) && fits(y0, b, p.size_y_m)) {
                return Err(field(
                    "mesh.contact_refinement.region_m",
                    format!(
                        "expected [x0, y0, a, b] (m) with a, b > 0 inside the {} x {} m pin \
                         face, got {:?}",
                        p.size_x_m, p.size_y_m, r.region_m
                    ),
                ));
            }
        }
        if !(m.grading_ratio.is_finite() && (1.0..=3.0).contains(&m.grading_ratio)) {
            return Err(field(
                "mesh.grading_ratio",
                format!("expected a ratio in [1, 3], got {}", m.grading_ratio),
            ));
        }
        match (self.load.normal_force_n, self.load.disc_displacement_m) {
            (Some(f), None) if f.is_finite() && f > 0.0 => {}
            (None, Some(d)) if d.is_finite() && d > 0.0 => {}
            (Some(f), None) => {
                return Err(field(
                    "load.normal_force_n",
                    format!("expected a positive force in N, got {f}"),
                ))
            }
            (None, Some(d)) => {
                return Err(field(
                    "load.disc_displacement_m",
                    format!("expected a positive displacement in m towards the pin, got {d}"),
                ))
            }
            _ => {
                return Err(field(
                    "load",
                    "give exactly one of normal_force_n and disc_displacement_m".into(),
                ))
            }
        }
        let st = &self.study;
        if !(st.mu.is_finite() && st.mu >= 0.0) {
            return Err(field(
                "study.mu",
                format!("expected a friction coefficient >= 0, got {}", st.mu),
            ));
        }
        if !(st.band_hz[0].is_finite()
            && st.band_hz[1].is_finite()
            && st.band_hz[0] >= 0.0
            && st.band_hz[0] < st.band_hz[1])
        {
            return Err(field(
                "study.band_hz",
                format!(
                    "expected [fmin, fmax] in Hz with 0 <= fmin < fmax, got {:?}",
                    st.band_hz
                ),
            ));
        }
        if st.rotation != 1.0 && st.rotation != -1.0 {
            return Err(field(
                "study.rotation",
                format!(
                    "expected 1 (counter-clockwise about +z) or -1, got {}",
                    st.rotation
                ),
            ));
        }
        if let (
            Zone::Rectangle {
                x0_m,
                y0_m,
                a_m,
                b_m,
            },
            Some(p),
        ) = (&self.contact.zone, &self.pin)
        {
            let ok = [*x0_m, *y0_m].iter().all(|v| v.is_finite() && *v >= 0.0)
                && *a_m > 0.0
                && *b_m > 0.0
                && x0_m + a_m <= p.size_x_m * (1.0 + 1e-9)
                && y0_m + b_m <= p.size_y_m * (1.0 + 1e-9);
            if !ok {
                return Err(field(
                    "contact.zone",
                    format!(
                        "rectangle x0_m = {x0_m}, y0_m = {y0_m}, a_m = {a_m}, b_m = {b_m} must \
                         have a, b > 0 and lie inside the pin face ({} x {} m)",
                        p.size_x_m, p.size_y_m
                    ),
                ));
            }
        }
        match (&self.contact.zone, &self.pin) {
            (
                Zone::Plateaus {
                    patch_m,
                    fraction,
                    count,
                    region_m,
                    ..
                },
                Some(p),
            ) => {
                let [x0, y0, a, b] = region_m.unwrap_or([0.0, 0.0, p.size_x_m, p.size_y_m]);
                let inside = x0 >= 0.0
                    && y0 >= 0.0
                    && a > 0.0
                    && b > 0.0
                    && x0 + a <= p.size_x_m * (1.0 + 1e-9)
                    && y0 + b <= p.size_y_m * (1.0 + 1e-9);
                if !inside {
                    return Err(field(
                        "contact.zone.region_m",
                        format!(
                            "expected [x0, y0, a, b] inside the pin face ({} x {} m), got {:?}",
                            p.size_x_m,
                            p.size_y_m,
                            [x0, y0, a, b]
                        ),
                    ));
                }
                if !(patch_m.is_finite() && *patch_m > 0.0 && *patch_m <= a.min(b) * (1.0 + 1e-9)) {
                    return Err(field(
                        "contact.zone.patch_m",
                        format!(
                            "expected a patch side in (0, {}] m, got {patch_m}",
                            a.min(b)
                        ),
                    ));
                }
                match (fraction, count) {
                    (Some(f), None) if *f > 0.0 && *f <= 1.0 => {}
                    (None, Some(c)) if *c >= 1 => {}
                    _ => {
                        return Err(field(
                            "contact.zone.fraction",
                            "give exactly one of fraction (in (0, 1]) and count (>= 1)".into(),
                        ))
                    }
                }
            }
            (Zone::Mask { .. }, Some(_)) if m.contact_refinement.is_some() => {
                return Err(field(
                    "contact.zone",
                    "a mask zone lists the uniform grid's pairs; it cannot be combined with \
                     mesh.contact_refinement (use a rectangle or plateaus zone)"
                        .into(),
                ))
            }
            (Zone::Mask { values, file }, Some(_)) => {
                let want = (m.pin_face_elements + 1) * (m.pin_face_elements + 1);
                match (values, file) {
                    (Some(v), _) => {
                        if v.len() != want {
                            return Err(field(
                                "contact.zone.values",
                                format!(
                                    "expected {want} mask values ({0} x {0} pairs, row by row \
                                     from the (-x, -y) corner), got {1}",
                                    m.pin_face_elements + 1,
                                    v.len()
                                ),
                            ));
                        }
                        if let Some(bad) = v.iter().find(|&&x| x > 1) {
                            return Err(field(
                                "contact.zone.values",
                                format!("expected 0 or 1, got {bad}"),
                            ));
                        }
                    }
                    (None, Some(_)) => {
                        return Err(field(
                            "contact.zone.file",
                            "a mask file is read relative to the scene file: load the scene \
                             with Scene::from_file"
                                .into(),
                        ))
                    }
                    (None, None) => {
                        return Err(field(
                            "contact.zone",
                            "a mask needs `values` or `file`".into(),
                        ))
                    }
                }
            }
            _ => {}
        }
        let imports = [
            (
                "disc.mesh",
                self.disc.as_ref().and_then(|d| d.mesh.as_ref()),
            ),
            ("pin.mesh", self.pin.as_ref().and_then(|p| p.mesh.as_ref())),
        ];
        for (name, imp) in imports {
            let Some(imp) = imp else { continue };
            if !(imp.scale.is_finite() && imp.scale > 0.0) {
                return Err(field(
                    &format!("{name}.scale"),
                    format!(
                        "expected a positive factor from the file's unit to metres, got {}",
                        imp.scale
                    ),
                ));
            }
            if imp.file.trim().is_empty() {
                return Err(field(
                    &format!("{name}.file"),
                    "expected the path of a Gmsh MSH 4.1 ASCII file".into(),
                ));
            }
            if imp.contact_group.is_none() && self.disc.is_some() && self.pin.is_some() {
                return Err(field(
                    &format!("{name}.contact_group"),
                    "expected the physical group of the contact face: the scene has a disc \
                     and a pin in contact"
                        .into(),
                ));
            }
        }
        if self
            .disc
            .as_ref()
            .is_some_and(|d| d.mesh.is_some() && d.hat.is_some())
        {
            return Err(field(
                "disc.hat",
                "a hat is generated with the disc: with disc.mesh, mesh the hat in the file \
                 and remove disc.hat"
                    .into(),
            ));
        }
        if self.pin.as_ref().is_some_and(|p| p.mesh.is_some()) {
            for (name, plate) in [
                ("thin_plate", &self.thin_plate),
                ("thick_plate", &self.thick_plate),
            ] {
                if plate.is_some() {
                    return Err(field(
                        name,
                        "plates are generated on the generated pin's grid: with pin.mesh, \
                         mesh the plates in the pin's file and remove the plate tables"
                            .into(),
                    ));
                }
            }
        }
        if self.disc.is_none() && self.pin.is_none() {
            return Err(field(
                "disc",
                "a scene needs at least a [disc] or a [pin]".into(),
            ));
        }
        Ok(())
    }
}
