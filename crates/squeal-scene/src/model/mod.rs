//! From a scene to an FE model with no more elements than the band needs.
//!
//! **Size rule.** For a plate-like body of thickness `t`, the shortest wave at the band
//! top `f` is the bending wave `lambda_b = 2 pi (D / (rho t))^(1/4) / sqrt(2 pi f)`,
//! `D = E t^3 / (12 (1 - nu^2))`. Element edges are at most
//! `lambda_b / mesh.elements_per_wavelength`, with at least `mesh.min_layers` layers
//! through each thickness. The pin face has `mesh.pin_face_elements` elements a side
//! (the contact grid); the plates share the pin's grid lines so the glued interfaces
//! conform. Orthotropic materials use the in-plane `E`, `nu` read off their compliance.
//!
//! Geometry: the disc spans z in [-thickness, 0] about the z axis; the pin face is
//! centred on (0, center_radius) on z = 0, x being the sliding direction and y the
//! radius there; the thin plate lies on the pin and the thick plate on the thin plate.

use crate::{Result, Scene, SceneError};
use squeal_core::{Material, Registry, SparseMat};
use squeal_fe::{assemble, DofMap, Mesh};
use std::time::Instant;

mod disc;
mod grid;
mod patch;
mod pin;
mod sizing;

pub use grid::{line_cells, ContactGrid};
use patch::{contact_layer, face_grid, Patch};
pub use sizing::element_size;
use sizing::{append_imported, graded, insert_edge, within, NodeBudget};

/// Which bodies to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyKind {
    /// The disc alone.
    Disc,
    /// The pin with its thin and thick plates.
    Pin,
    /// Everything in the scene.
    All,
}

/// The element size chosen for one body and why.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeRule {
    /// Body name.
    pub body: String,
    /// Bending wavelength at the band top (m).
    pub wavelength_m: f64,
    /// Target element edge (m).
    pub element_size_m: f64,
    /// Elements in each direction (r, theta, z for the disc; x, y, z for blocks); for an
    /// imported mesh `[0, 0, 0]` (the disc) or the pin face's `[nx, ny, 0]`.
    pub divisions: [usize; 3],
}

/// An assembled model on the free DOFs.
pub struct Model {
    /// The mesh of every built body.
    pub mesh: Mesh,
    /// Body names, indexed by `mesh.hex_body`.
    pub body_names: Vec<String>,
    /// DOF numbering (Dirichlet DOFs eliminated).
    pub dofs: DofMap,
    /// Stiffness (N/m).
    pub k: SparseMat,
    /// Mass (kg).
    pub m: SparseMat,
    /// Total mass (kg).
    pub total_mass: f64,
    /// Element sizes and their reasons.
    pub sizes: Vec<SizeRule>,
    /// Build time (s): meshing and assembly.
    pub build_time_s: f64,
    /// The node-to-node contact pairs between the pin face and the disc, when both are
    /// built.
    pub contact: Option<ContactGrid>,
}

/// Size and quality of one body of a built model.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyStats {
    /// Body name.
    pub body: String,
    /// Elements.
    pub elements: usize,
    /// Nodes (a node glued to an earlier body counts for that body).
    pub nodes: usize,
    /// Free DOFs on those nodes.
    pub dofs: usize,
    /// Smallest and largest element edge (m).
    pub edge_range_m: (f64, f64),
    /// Minimum scaled Jacobian over the body's elements (1 for a cube).
    pub min_scaled_jacobian: f64,
}

impl Model {
    /// Per-body sizes and mesh quality.
    pub fn body_stats(&self) -> Vec<BodyStats> {
        let mut owner = vec![usize::MAX; self.mesh.n_nodes()];
        let mut out: Vec<BodyStats> = self
            .body_names
            .iter()
            .map(|b| BodyStats {
                body: b.clone(),
                elements: 0,
                nodes: 0,
                dofs: 0,
                edge_range_m: (f64::INFINITY, 0.0),
                min_scaled_jacobian: f64::INFINITY,
            })
            .collect();
        for (e, h) in self.mesh.hexes.iter().enumerate() {
            let b = self.mesh.hex_body[e];
            let st = &mut out[b];
            st.elements += 1;
            let x = self.mesh.hex_coords(e);
            st.min_scaled_jacobian = st
                .min_scaled_jacobian
                .min(squeal_fe::hex8::scaled_jacobian(&x));
            for l in squeal_fe::hex8::edge_lengths(&x) {
                st.edge_range_m = (st.edge_range_m.0.min(l), st.edge_range_m.1.max(l));
            }
            for &n in h {
                if owner[n] == usize::MAX {
                    owner[n] = b;
                }
            }
        }
        for (n, &b) in owner.iter().enumerate() {
            if b != usize::MAX {
                out[b].nodes += 1;
                out[b].dofs += (0..3)
                    .filter(|k| self.dofs.free_of_full[3 * n + k].is_some())
                    .count();
            }
        }
        out
    }
}

/// The model being built: the mesh so far and what each body added.
struct Assembly<'a> {
    cx: Context<'a>,
    mesh: Mesh,
    budget: NodeBudget,
    materials: Vec<Box<dyn Material>>,
    body_names: Vec<String>,
    sizes: Vec<SizeRule>,
    fixed_nodes: Vec<usize>,
    ties: Vec<squeal_fe::Tie>,
}

/// An imported body mesh: its scene table and the mesh read.
type Import = Option<(crate::MeshImport, crate::ImportedMesh)>;

/// What the bodies share, decided before any is built: the imported meshes, the contact
/// patch under the pin, its refinement and the lift of the pin assembly.
struct Layout {
    disc_import: Import,
    pin_import: Import,
    patch: Option<Patch>,
    /// The refined contact grid and the disc layer's thickness.
    fine: Option<(Patch, f64)>,
    /// How much higher the pin assembly sits (the disc's contact layer).
    lift: f64,
}

/// What every body builder reads: the scene, the plugins, and the file name of errors.
#[derive(Clone, Copy)]
struct Context<'a> {
    scene: &'a Scene,
    registry: &'a Registry,
    file: &'a str,
}

impl Context<'_> {
    /// The material of the table `field` from its spec.
    fn material(&self, spec: &crate::MaterialSpec, field: &str) -> Result<Box<dyn Material>> {
        let params = spec.params(self.file, field)?;
        self.registry
            .materials
            .create(&spec.kind, &params)
            .map_err(|source| SceneError::Core {
                file: self.file.into(),
                context: field.into(),
                source: Box::new(source),
            })
    }

    /// A body asked for whose table the scene does not have.
    fn missing(&self, field: &str) -> SceneError {
        self.field_error(
            field.into(),
            "this body is asked for but the scene has no such table",
        )
    }

    /// An error of the field `f` of `{body}.mesh`.
    fn group_error(&self, body: &str, f: &str, message: String) -> SceneError {
        self.field_error(format!("{body}.mesh.{f}"), message)
    }

    /// An error of the contact refinement (its layers and ties).
    fn refinement_error(&self, message: String) -> SceneError {
        self.field_error("mesh.contact_refinement".into(), message)
    }

    fn field_error(&self, field: String, message: impl Into<String>) -> SceneError {
        SceneError::Field {
            file: self.file.into(),
            field,
            message: message.into(),
        }
    }
}

/// The imported meshes, the contact patch and its refinement of the scene.
fn layout(cx: Context<'_>) -> Result<Layout> {
    let (scene, file) = (cx.scene, cx.file);
    let rule = &scene.mesh;
    // Imported meshes: read by Scene::from_file, else now (relative to the working
    // directory).
    let import = |imp: Option<&crate::MeshImport>,
                  field: &str|
     -> Result<Option<(crate::MeshImport, crate::ImportedMesh)>> {
        match imp {
            None => Ok(None),
            Some(imp) => {
                let im = match &imp.loaded {
                    Some(l) => l.clone(),
                    None => imp.load(None, file, field)?,
                };
                Ok(Some((imp.clone(), im)))
            }
        }
    };
    let disc_import = import(
        scene.disc.as_ref().and_then(|d| d.mesh.as_ref()),
        "disc.mesh",
    )?;
    let pin_import = import(scene.pin.as_ref().and_then(|p| p.mesh.as_ref()), "pin.mesh")?;
    // The contact patch under the pin: a Cartesian grid blended into the polar disc; the
    // grid lines of an imported pin's contact group when the scene has a disc.
    let patch = match (&scene.pin, &pin_import) {
        (Some(_), Some((imp, im))) if scene.disc.is_some() => {
            let g = imp.contact_group.as_deref().ok_or_else(|| {
                cx.group_error(
                    "pin",
                    "contact_group",
                    "expected the pin face's group".into(),
                )
            })?;
            let set = im
                .mesh
                .node_set(g)
                .map_err(|m| cx.group_error("pin", "contact_group", m))?;
            let (xs, ys) = face_grid(&im.mesh, set).map_err(|m| {
                cx.group_error(
                    "pin",
                    "contact_group",
                    format!("group `{g}` of {}: {m}", im.path.display()),
                )
            })?;
            Some(Patch::from_grid(xs, ys))
        }
        (Some(p), _) => Some(Patch::new(p, rule.pin_face_elements)),
        (None, _) => None,
    };
    // Contact refinement: the fine contact grid, carried by tied contact layers; the disc
    // layer (element_m thick) lifts the pin assembly by `lift`.
    let fine = match (&rule.contact_refinement, &patch) {
        (Some(r), Some(pa)) if pin_import.is_none() && disc_import.is_none() => {
            Some((pa.refined(r), r.element_m))
        }
        _ => None,
    };
    let lift = fine.as_ref().map_or(0.0, |f| f.1);
    Ok(Layout {
        disc_import,
        pin_import,
        patch,
        fine,
        lift,
    })
}

/// Builds the bodies of `scene` selected by `which`, with materials from `registry`;
/// `file` names the scene in errors.
pub fn build(scene: &Scene, which: BodyKind, registry: &Registry, file: &str) -> Result<Model> {
    let start = Instant::now();
    let cx = Context {
        scene,
        registry,
        file,
    };
    let lay = layout(cx)?;
    let mut asm = Assembly {
        cx,
        mesh: Mesh::default(),
        budget: NodeBudget::new(scene.mesh.max_dofs),
        materials: Vec::new(),
        body_names: Vec::new(),
        sizes: Vec::new(),
        fixed_nodes: Vec::new(),
        ties: Vec::new(),
    };
    if which == BodyKind::Disc || (which == BodyKind::All && scene.disc.is_some()) {
        match &lay.disc_import {
            Some((imp, im)) => disc::imported(&mut asm, imp, im)?,
            None => disc::generated(&mut asm, &lay)?,
        }
    }
    if which == BodyKind::Pin || (which == BodyKind::All && scene.pin.is_some()) {
        match &lay.pin_import {
            Some((imp, im)) => pin::imported(&mut asm, imp, im, &lay)?,
            None => pin::generated(&mut asm, &lay)?,
        }
    }
    let contact = grid::pairs(&asm.mesh, &lay, scene, which, file)?;
    let Assembly {
        mesh,
        materials,
        body_names,
        sizes,
        mut fixed_nodes,
        ties,
        ..
    } = asm;
    fixed_nodes.sort_unstable();
    fixed_nodes.dedup();
    let dofs = DofMap::with_ties(&mesh, &DofMap::node_dofs(&fixed_nodes), &ties)
        .map_err(|m| cx.refinement_error(m))?;
    let refs: Vec<&dyn Material> = materials.iter().map(|m| m.as_ref()).collect();
    let asm = assemble(&mesh, &dofs, &refs).map_err(|source| SceneError::Core {
        file: file.into(),
        context: "assembly".into(),
        source: Box::new(source),
    })?;
    Ok(Model {
        mesh,
        body_names,
        dofs,
        k: asm.k,
        m: asm.m,
        total_mass: asm.total_mass,
        sizes,
        build_time_s: start.elapsed().as_secs_f64(),
        contact,
    })
}
