//! The disc models shared by the benchmarks, built once.

use squeal::core::{Material, Registry};
use squeal::scene::{build, BodyKind, Model, Scene};
use std::sync::OnceLock;

/// File name used in scene errors.
pub const FILE: &str = "bench";

/// One disc model at a given mesh density.
pub struct DiscModel {
    /// `mesh.elements_per_wavelength` of the scene it was built from.
    pub epw: f64,
    /// The scene (default scene with `epw` set).
    pub scene: Scene,
    /// Mesh, DOF map, K and M.
    pub model: Model,
    /// Materials by body index (the disc's alone).
    pub materials: Vec<Box<dyn Material>>,
}

impl DiscModel {
    /// Number of free DOFs.
    pub fn dofs(&self) -> usize {
        self.model.dofs.n_free()
    }

    /// Stored entries of K (both triangles).
    pub fn nnz_k(&self) -> usize {
        self.model.k.compute_nnz()
    }

    /// The material references `assemble` takes.
    pub fn material_refs(&self) -> Vec<&dyn Material> {
        self.materials.iter().map(|m| m.as_ref()).collect()
    }
}

/// The registry and the disc models, coarsest first.
pub struct Models {
    /// Every built-in plugin.
    pub registry: Registry,
    /// Disc models by increasing size.
    pub discs: Vec<DiscModel>,
    /// Index in `discs` of the scene's own mesh density.
    pub default: usize,
}

impl Models {
    /// The shared models (built on first use).
    pub fn get() -> &'static Models {
        static MODELS: OnceLock<Models> = OnceLock::new();
        MODELS.get_or_init(Models::new)
    }

    fn new() -> Models {
        let registry = squeal::registry();
        let base = Scene::builtin("pin-on-disc").expect("default scene parses");
        let own = base.mesh.elements_per_wavelength;
        let mut epws = vec![8.0, own, 18.0];
        epws.sort_by(f64::total_cmp);
        epws.dedup();
        let discs: Vec<DiscModel> = epws
            .iter()
            .map(|&epw| {
                let mut scene = base.clone();
                scene.mesh.elements_per_wavelength = epw;
                let model = build(&scene, BodyKind::Disc, &registry, FILE).expect("disc builds");
                let spec = &scene
                    .disc
                    .as_ref()
                    .expect("default scene has a disc")
                    .material;
                let params = spec
                    .params(FILE, "disc.material")
                    .expect("disc material params");
                let mat = registry
                    .materials
                    .create(&spec.kind, &params)
                    .expect("disc material plugin");
                DiscModel {
                    epw,
                    scene,
                    model,
                    materials: vec![mat],
                }
            })
            .collect();
        let default = epws
            .iter()
            .position(|&e| e == own)
            .expect("own density present");
        Models {
            registry,
            discs,
            default,
        }
    }

    /// The disc at the scene's own mesh density.
    pub fn default_disc(&self) -> &DiscModel {
        &self.discs[self.default]
    }

    /// The finest disc.
    pub fn finest_disc(&self) -> &DiscModel {
        self.discs.last().expect("at least one disc")
    }

    /// Prints one line per model: density, DOFs, elements, nodes, nnz(K), build time.
    pub fn print_table(&self) {
        for d in &self.discs {
            eprintln!(
                "model disc epw={:<4} dofs={:>7} elements={:>6} nodes={:>6} nnz(K)={:>9} build={:.3}s{}",
                d.epw,
                d.dofs(),
                d.model.mesh.hexes.len(),
                d.model.mesh.n_nodes(),
                d.nnz_k(),
                d.model.build_time_s,
                if std::ptr::eq(d, self.default_disc()) { " (default)" } else { "" },
            );
        }
    }
}
