//! The full pin-on-disc rig at several mesh densities, with its sliding equilibrium and
//! frictional operator, built once for the kernel benchmarks.
//!
//! Each density is the default scene with `mesh.elements_per_wavelength` changed; the
//! equilibrium (`lcp`, `lagrange`) and the operator are taken at [`MU`]. Benchmark ids
//! carry the constrained DOF count (the size of `Q(lambda)`).

use crate::models::FILE;
use squeal::analysis::pipeline::Prepared;
use squeal::core::operator::Qep;
use squeal::core::{FrictionalOperator, Material, Registry};
use squeal::scene::Scene;
use std::sync::OnceLock;
use std::time::Instant;

/// Friction coefficient of the benchmarked operators.
pub const MU: f64 = 0.7;

/// Mesh densities of the rig models, coarsest first: (`mesh.elements_per_wavelength`,
/// `mesh.pin_face_elements`). The last one is the default scene. The pin face mesh also
/// sets the disc's in-plane mesh under the pin, so both are lowered to spread the sizes.
const DENSITIES: [(f64, usize); 3] = [(4.0, 8), (6.0, 12), (10.0, 20)];

/// One rig model: scene, FE model, equilibrium operator and its QEP at [`MU`].
pub struct RigModel {
    /// `mesh.elements_per_wavelength`.
    pub epw: f64,
    /// `mesh.pin_face_elements`.
    pub pin_face: usize,
    /// Built scene, model, contact set and condensation.
    pub prep: Prepared,
    /// Materials by body index (for re-assembly).
    pub materials: Vec<Box<dyn Material>>,
    /// The frictional operator of the equilibrium's active set.
    pub op: FrictionalOperator,
    /// `op.at(MU)`.
    pub qep: Qep,
    /// Active contact pairs.
    pub active: usize,
    /// Time to build the scene, equilibrium and operator (s).
    pub setup_s: f64,
}

impl RigModel {
    /// Size of the constrained operator (the benchmark id).
    pub fn dofs(&self) -> usize {
        self.op.dim()
    }

    /// Free DOFs of the unconstrained model.
    pub fn full_dofs(&self) -> usize {
        self.prep.model.dofs.n_free()
    }

    /// The material references `assemble` takes.
    pub fn material_refs(&self) -> Vec<&dyn Material> {
        self.materials.iter().map(|m| m.as_ref()).collect()
    }

    fn new(registry: &Registry, base: &Scene, (epw, pin_face): (f64, usize)) -> RigModel {
        let start = Instant::now();
        let mut scene = base.clone();
        scene.mesh.elements_per_wavelength = epw;
        scene.mesh.pin_face_elements = pin_face;
        let prep = Prepared::new(registry, scene, FILE).expect("rig builds");
        let materials = rig_materials(registry, &prep);
        let eq = prep
            .equilibrium(registry, "lcp", "lagrange", MU)
            .expect("rig equilibrium");
        let op = prep.operator(&eq.eq.active).expect("rig operator");
        let qep = op.at(MU).expect("rig QEP");
        RigModel {
            epw,
            pin_face,
            active: eq.eq.active.iter().filter(|&&a| a).count(),
            prep,
            materials,
            op,
            qep,
            setup_s: start.elapsed().as_secs_f64(),
        }
    }
}

/// The materials of the built bodies, in body order (the scene builder does not return
/// them, so they are created again from the scene by body name).
fn rig_materials(registry: &Registry, prep: &Prepared) -> Vec<Box<dyn Material>> {
    let s = &prep.scene;
    prep.model
        .body_names
        .iter()
        .map(|name| {
            let spec = match name.as_str() {
                "disc" => s.disc.as_ref().map(|d| &d.material),
                "pin" => s.pin.as_ref().map(|p| &p.material),
                "thin_plate" => s.thin_plate.as_ref().map(|p| &p.material),
                "thick_plate" => s.thick_plate.as_ref().map(|p| &p.material),
                _ => None,
            }
            .unwrap_or_else(|| panic!("no material for body {name}"));
            let params = spec.params(FILE, name).expect("material params");
            registry
                .materials
                .create(&spec.kind, &params)
                .expect("material plugin")
        })
        .collect()
}

/// The rig models, coarsest first.
pub struct Rigs {
    /// By increasing size.
    pub rigs: Vec<RigModel>,
}

impl Rigs {
    /// The shared rig models (built on first use).
    pub fn get(registry: &Registry) -> &'static Rigs {
        static RIGS: OnceLock<Rigs> = OnceLock::new();
        RIGS.get_or_init(|| {
            let base = Scene::builtin("pin-on-disc").expect("default scene parses");
            Rigs {
                rigs: DENSITIES
                    .iter()
                    .map(|&d| RigModel::new(registry, &base, d))
                    .collect(),
            }
        })
    }

    /// The `k` smallest models.
    pub fn smallest(&self, k: usize) -> &[RigModel] {
        &self.rigs[..k.min(self.rigs.len())]
    }

    /// Prints one line per model.
    pub fn print_table(&self) {
        for r in &self.rigs {
            eprintln!(
                "model rig  epw={:<4} pin_face={:<3} dofs={:>7} (full {:>7}) elements={:>6} nnz(Kc)={:>9} \
                 nnz(Mc)={:>9} active pairs={:>4} setup={:.2}s",
                r.epw,
                r.pin_face,
                r.dofs(),
                r.full_dofs(),
                r.prep.model.mesh.hexes.len(),
                r.op.kc.compute_nnz(),
                r.op.mc.compute_nnz(),
                r.active,
                r.setup_s,
            );
        }
    }
}

/// A deterministic dense `n x m` matrix with entries in `[-1, 1)` (a stand-in for a
/// reduction basis: the kernels' cost does not depend on the values).
pub fn pseudo_random(n: usize, m: usize, seed: u64) -> squeal::core::faer::Mat<f64> {
    let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    squeal::core::faer::Mat::from_fn(n, m, |_, _| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    })
}
