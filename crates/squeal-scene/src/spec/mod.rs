//! The scene file format (serde). Every length in metres, modulus in Pa, density in
//! kg/m^3, frequency in Hz; field names carry their unit.
//!
//! One file per group of tables, each with the check of its tables; [`Scene`] gathers
//! them.

use crate::{Result, SceneError};
use serde::{Deserialize, Serialize};

mod bodies;
mod contact;
mod material;
mod mesh;
mod study;

pub use bodies::{Clamp, Disc, Flange, Hat, Pin, Plate};
pub use contact::{ContactSpec, Load, Zone};
pub use material::MaterialSpec;
pub use mesh::{ContactRefinement, ImportedMesh, MeshImport, MeshRule};
pub use study::{Damping, Study};

/// The embedded default scene, the paper's pin-on-disc rig.
pub const PIN_ON_DISC: &str = include_str!("../../../../scenes/pin-on-disc.toml");

/// The same rig meshed at the paper's model size (about 300 000 DOFs).
pub const PIN_ON_DISC_PAPER: &str = include_str!("../../../../scenes/pin-on-disc-paper.toml");

/// The same rig on a deliberately coarse mesh (about 1600 DOFs): tests and quick checks.
pub const PIN_ON_DISC_COARSE: &str = include_str!("../../../../scenes/pin-on-disc-coarse.toml");

/// Names of the embedded scenes.
pub const BUILTIN_SCENES: [&str; 3] = ["pin-on-disc", "pin-on-disc-paper", "pin-on-disc-coarse"];

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
        bodies::validate_disc(self, file)?;
        bodies::validate_pin(self, file)?;
        bodies::validate_plates(self, file)?;
        mesh::validate_mesh(self, file)?;
        contact::validate_load(self, file)?;
        study::validate_study(self, file)?;
        contact::validate_contact(self, file)?;
        mesh::validate_imports(self, file)
    }
}

/// The error of the field `field` (dotted, e.g. `disc.thickness_m`) of `file`.
fn field_error(file: &str, field: &str, message: String) -> SceneError {
    SceneError::Field {
        file: file.into(),
        field: field.into(),
        message,
    }
}

/// Ok when `value` of `field` is a positive, finite length.
fn positive_length(file: &str, field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(field_error(
            file,
            field,
            format!("expected a positive length in metres, got {value}"),
        ))
    }
}
