//! The mesh rule and imported meshes, each with the check of its table.

use super::{field_error, Scene};
use crate::{Result, SceneError};
use serde::{Deserialize, Serialize};

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

/// Checks the `[mesh]` table (rule, limits, contact refinement).
pub(super) fn validate_mesh(scene: &Scene, file: &str) -> Result<()> {
    let field = |f: &str, m: String| field_error(file, f, m);
    let m = &scene.mesh;
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
        let Some(p) = &scene.pin else {
            return Err(field(
                "mesh.contact_refinement",
                "refines the pin face's contact grid: a [pin] table is required".into(),
            ));
        };
        if p.mesh.is_some() || scene.disc.as_ref().is_some_and(|d| d.mesh.is_some()) {
            return Err(field(
                "mesh.contact_refinement",
                "only generated meshes are refined; an imported mesh brings its own grid".into(),
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
    Ok(())
}

/// Checks the imported meshes (`disc.mesh`, `pin.mesh`), what they exclude, and that a body is present.
pub(super) fn validate_imports(scene: &Scene, file: &str) -> Result<()> {
    let field = |f: &str, m: String| field_error(file, f, m);
    let imports = [
        (
            "disc.mesh",
            scene.disc.as_ref().and_then(|d| d.mesh.as_ref()),
        ),
        ("pin.mesh", scene.pin.as_ref().and_then(|p| p.mesh.as_ref())),
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
        if imp.contact_group.is_none() && scene.disc.is_some() && scene.pin.is_some() {
            return Err(field(
                &format!("{name}.contact_group"),
                "expected the physical group of the contact face: the scene has a disc \
                 and a pin in contact"
                    .into(),
            ));
        }
    }
    if scene
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
    if scene.pin.as_ref().is_some_and(|p| p.mesh.is_some()) {
        for (name, plate) in [
            ("thin_plate", &scene.thin_plate),
            ("thick_plate", &scene.thick_plate),
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
    if scene.disc.is_none() && scene.pin.is_none() {
        return Err(field(
            "disc",
            "a scene needs at least a [disc] or a [pin]".into(),
        ));
    }
    Ok(())
}
