//! # squeal-contact
//!
//! From a built scene to the contact problem and the frictional operator:
//!
//! - [`ContactSet`]: the candidate pairs of the scene's contact zone, their normals
//!   `n_i = +e_z` (from the disc into the pin), their sliding directions
//!   `e_i = s (-y, x, 0) / r` (the disc's surface velocity at the pair for rotation
//!   `s Omega e_z`, pair by pair, never one global x) and the sparse `Pn`, `Pt`
//!   (row `i`: `+n_i` / `+e_i` on the pin node, `-n_i` / `-e_i` on the disc node).
//! - [`solve_loaded`]: the sliding equilibrium under the scene's load. The load is an
//!   axial displacement `delta` of the disc's clamp towards the pin; as the disc is free
//!   but for its clamp and the contact, that is exactly an initial interference
//!   `g0_i = -delta` on every pair with zero external force. The problem is positively
//!   homogeneous in `delta`, so a target total normal force is met exactly by one
//!   solve and a scaling.
//! - [`build_operator`]: the constrained frictional operator of an active set (see
//!   [`operator`]), with the scene's damping from [`damping_matrix`].
//!
//! Units: SI (m, N, kg, s).

pub mod damping;
pub mod files;
pub mod operator;

pub use damping::damping_matrix;
pub use operator::build_operator;

use squeal_core::contact::{Condensation, ContactProblem, Equilibrium};
use squeal_core::faer::sparse::Triplet;
use squeal_core::{ContactLaw, EquilibriumSolver, SparseMat};
use squeal_scene::{Load, Model, Zone};
use thiserror::Error;

/// Errors of contact set-up and equilibrium.
#[derive(Debug, Error)]
pub enum ContactError {
    /// The scene or model cannot give a contact problem.
    #[error("contact: {field}: {message}")]
    Setup {
        /// The scene field concerned.
        field: String,
        /// What is wrong and what is expected.
        message: String,
    },
    /// An error of a solver or of the core.
    #[error(transparent)]
    Core(#[from] squeal_core::Error),
}

/// Result with [`ContactError`].
pub type Result<T> = std::result::Result<T, ContactError>;

/// The pairs of a contact grid relative to the pin face's corner (m, grid order) and the
/// face size `[size_x, size_y]` (m): the coordinates zones are given in.
pub fn face_points(grid: &squeal_scene::ContactGrid) -> (Vec<[f64; 2]>, [f64; 2]) {
    let (x_lo, y_lo) = (grid.xs[0], grid.ys[0]);
    let size = [
        grid.xs[grid.xs.len() - 1] - x_lo,
        grid.ys[grid.ys.len() - 1] - y_lo,
    ];
    let rel = grid.xy.iter().map(|p| [p[0] - x_lo, p[1] - y_lo]).collect();
    (rel, size)
}

/// Candidate contact pairs with their kinematics, on the model's free DOFs.
#[derive(Debug, Clone)]
pub struct ContactSet {
    /// Index of each candidate pair in the model's [`ContactGrid`](squeal_scene::ContactGrid).
    pub grid_index: Vec<usize>,
    /// (x, y) of each pair (m).
    pub xy: Vec<[f64; 2]>,
    /// Free DOFs (x, y, z) of the pin node of each pair.
    pub pin_dofs: Vec<[usize; 3]>,
    /// Free DOFs (x, y, z) of the disc node of each pair.
    pub disc_dofs: Vec<[usize; 3]>,
    /// Sliding direction `e_i` of each pair (unit, in the disc plane).
    pub direction: Vec<[f64; 3]>,
    /// Normal projection `Pn`, `nc x n`.
    pub pn: SparseMat,
    /// Tangential projection `Pt`, `nc x n`.
    pub pt: SparseMat,
    /// Rotation sense (+1 counter-clockwise about +z).
    pub rotation: f64,
    /// Number of free DOFs of the model (columns of `Pn`, `Pt`).
    pub n: usize,
}

impl ContactSet {
    /// The pairs of `model` inside `zone`, for the disc rotating with sense `rotation`.
    pub fn new(model: &Model, zone: &Zone, rotation: f64) -> Result<Self> {
        let grid = model.contact.as_ref().ok_or_else(|| ContactError::Setup {
            field: "pin".into(),
            message: "the model has no contact pairs: a scene needs a [disc] and a [pin], \
                      built together"
                .into(),
        })?;
        if rotation != 1.0 && rotation != -1.0 {
            return Err(ContactError::Setup {
                field: "study.rotation".into(),
                message: format!("expected 1 or -1, got {rotation}"),
            });
        }
        let (rel, size) = face_points(grid);
        if let Zone::Mask {
            values: Some(v), ..
        } = zone
        {
            if v.len() != grid.len() {
                return Err(ContactError::Setup {
                    field: "contact.zone.values".into(),
                    message: format!("expected {} mask values, got {}", grid.len(), v.len()),
                });
            }
        }
        let selected = zone.select(&rel, size);
        let inside = |p: usize| -> bool { selected[p] };
        let dof = |node: usize, what: &str| -> Result<[usize; 3]> {
            let mut d = [0; 3];
            for (a, slot) in d.iter_mut().enumerate() {
                *slot =
                    model.dofs.free_of_full[3 * node + a].ok_or_else(|| ContactError::Setup {
                        field: what.into(),
                        message: format!(
                            "contact node {node} has a fixed DOF: contact nodes must be free"
                        ),
                    })?;
            }
            Ok(d)
        };
        let mut xy = Vec::new();
        let mut pin_dofs = Vec::new();
        let mut disc_dofs = Vec::new();
        let mut index = Vec::new();
        for p in (0..grid.len()).filter(|&p| inside(p)) {
            index.push(p);
            xy.push(grid.xy[p]);
            pin_dofs.push(dof(grid.pin_nodes[p], "pin")?);
            disc_dofs.push(dof(grid.disc_nodes[p], "disc")?);
        }
        if index.is_empty() {
            return Err(ContactError::Setup {
                field: "contact.zone".into(),
                message: "the zone holds no contact pair".into(),
            });
        }
        let mut set = Self::from_pairs(model.dofs.n_free(), xy, pin_dofs, disc_dofs, rotation)?;
        set.grid_index = index;
        Ok(set)
    }

    /// A contact set from explicit pairs on a model with `n` free DOFs: pair `i` joins
    /// the pin node with free DOFs `pin_dofs[i]` to the disc node with `disc_dofs[i]` at
    /// `xy[i]` (m, the disc axis at the origin). Normals are `+e_z`.
    pub fn from_pairs(
        n: usize,
        xy: Vec<[f64; 2]>,
        pin_dofs: Vec<[usize; 3]>,
        disc_dofs: Vec<[usize; 3]>,
        rotation: f64,
    ) -> Result<Self> {
        let nc = xy.len();
        if pin_dofs.len() != nc || disc_dofs.len() != nc {
            return Err(ContactError::Setup {
                field: "pairs".into(),
                message: format!(
                    "{nc} positions but {} pin and {} disc DOF triples",
                    pin_dofs.len(),
                    disc_dofs.len()
                ),
            });
        }
        if let Some(d) = pin_dofs
            .iter()
            .chain(&disc_dofs)
            .flatten()
            .find(|&&d| d >= n)
        {
            return Err(ContactError::Setup {
                field: "pairs".into(),
                message: format!("DOF {d} out of range (the model has {n} free DOFs)"),
            });
        }
        let direction: Vec<[f64; 3]> = xy
            .iter()
            .map(|&[x, y]| {
                let r = x.hypot(y);
                [-rotation * y / r, rotation * x / r, 0.0]
            })
            .collect();
        let mut set = ContactSet {
            grid_index: (0..nc).collect(),
            xy,
            pin_dofs,
            disc_dofs,
            direction,
            pn: SparseMat::try_new_from_triplets(nc, n, &[]).expect("empty"),
            pt: SparseMat::try_new_from_triplets(nc, n, &[]).expect("empty"),
            rotation,
            n,
        };
        set.rebuild_projections()?;
        Ok(set)
    }

    /// Rebuilds `Pn` and `Pt` from the pairs' DOFs and directions.
    pub fn rebuild_projections(&mut self) -> Result<()> {
        let (nc, n) = (self.len(), self.n);
        let (mut tn, mut tt) = (Vec::new(), Vec::new());
        for i in 0..nc {
            let (s, m, e) = (self.pin_dofs[i], self.disc_dofs[i], self.direction[i]);
            tn.push(Triplet::new(i, s[2], 1.0));
            tn.push(Triplet::new(i, m[2], -1.0));
            for a in 0..3 {
                if e[a] != 0.0 {
                    tt.push(Triplet::new(i, s[a], e[a]));
                    tt.push(Triplet::new(i, m[a], -e[a]));
                }
            }
        }
        self.pn =
            SparseMat::try_new_from_triplets(nc, n, &tn).map_err(|e| ContactError::Setup {
                field: "pairs".into(),
                message: format!("building Pn: {e:?}"),
            })?;
        self.pt =
            SparseMat::try_new_from_triplets(nc, n, &tt).map_err(|e| ContactError::Setup {
                field: "pairs".into(),
                message: format!("building Pt: {e:?}"),
            })?;
        Ok(())
    }
    /// Number of candidate pairs.
    pub fn len(&self) -> usize {
        self.grid_index.len()
    }

    /// Whether there is no pair.
    pub fn is_empty(&self) -> bool {
        self.grid_index.is_empty()
    }
}

/// A sliding equilibrium under the scene's load.
#[derive(Debug, Clone)]
pub struct LoadedEquilibrium {
    /// The equilibrium (reactions in N, displacements in m relative to the disc's rigid
    /// approach `delta`).
    pub eq: Equilibrium,
    /// Axial approach of the disc's clamp towards the pin (m).
    pub displacement_m: f64,
    /// Total normal force on the pin, `sum Rn` (N).
    pub total_normal_force_n: f64,
    /// Total friction force magnitude, `mu sum Rn` (N) (full sliding).
    pub total_tangential_force_n: f64,
    /// Resultant friction force on the pin `sum mu Rn_i e_i`, (x, y) (N).
    pub tangential_resultant_n: [f64; 2],
    /// Centroid of `Rn` (m).
    pub centroid_m: [f64; 2],
}

/// Solves the sliding equilibrium of `set` under `load` with `solver` and `law`:
/// one condensation (one factorization of `K`) and one solve at a reference approach,
/// scaled to the target force or the imposed displacement (exact: the problem is
/// positively homogeneous).
pub fn solve_loaded(
    model: &Model,
    set: &ContactSet,
    load: &Load,
    solver: &dyn EquilibriumSolver,
    law: &dyn ContactLaw,
    mu: f64,
) -> Result<LoadedEquilibrium> {
    let start = std::time::Instant::now();
    check_user_mu(mu)?;
    let (f, g0) = reference_load(model, set);
    let problem = problem(model, set, &f, &g0);
    let cond = Condensation::new(&problem)?;
    let mut out = solve_on(&cond, &problem, set, load, solver, law, mu)?;
    out.eq.time_s = start.elapsed().as_secs_f64();
    Ok(out)
}

/// Reference approach used before scaling (m).
pub const REFERENCE_APPROACH_M: f64 = 1e-4;

/// Zero external force and the interference `-delta_ref` on every pair.
pub fn reference_load(model: &Model, set: &ContactSet) -> (Vec<f64>, Vec<f64>) {
    (
        vec![0.0; model.dofs.n_free()],
        vec![-REFERENCE_APPROACH_M; set.len()],
    )
}

/// The contact problem of `set` on `model` with load `f` and initial gaps `g0`.
pub fn problem<'a>(
    model: &'a Model,
    set: &'a ContactSet,
    f: &'a [f64],
    g0: &'a [f64],
) -> ContactProblem<'a> {
    ContactProblem {
        k: model.k.as_ref(),
        f,
        pn: set.pn.as_ref(),
        pt: set.pt.as_ref(),
        g0,
    }
}

/// Rejects a negative or non-finite friction coefficient given by a user (the rotation
/// sense, not the sign of mu, reverses the friction).
pub fn check_user_mu(mu: f64) -> Result<()> {
    if mu.is_finite() && mu >= 0.0 {
        Ok(())
    } else {
        Err(ContactError::Setup {
            field: "mu".into(),
            message: format!(
                "expected a friction coefficient >= 0, got {mu} (reverse the rotation with \
                 study.rotation = -1 instead of a negative mu)"
            ),
        })
    }
}

/// Solves on an existing condensation of the reference problem (reused across mu) and
/// scales to the load.
pub fn solve_on(
    cond: &Condensation,
    problem: &ContactProblem<'_>,
    set: &ContactSet,
    load: &Load,
    solver: &dyn EquilibriumSolver,
    law: &dyn ContactLaw,
    mu: f64,
) -> Result<LoadedEquilibrium> {
    let mut eq = solver.solve_condensed(cond, problem, law, mu)?;
    let total: f64 = eq.rn.iter().sum();
    let scale = match (load.normal_force_n, load.disc_displacement_m) {
        (Some(force), _) => force / total,
        (None, Some(d)) => d / REFERENCE_APPROACH_M,
        (None, None) => {
            return Err(ContactError::Setup {
                field: "load".into(),
                message: "give normal_force_n or disc_displacement_m".into(),
            })
        }
    };
    eq.rn.iter_mut().for_each(|r| *r *= scale);
    eq.u.iter_mut().for_each(|u| *u *= scale);
    let total = total * scale;
    let mut tr = [0.0; 2];
    let mut c = [0.0; 2];
    for i in 0..set.len() {
        for a in 0..2 {
            tr[a] += mu * eq.rn[i] * set.direction[i][a];
            c[a] += eq.rn[i] * set.xy[i][a] / total;
        }
    }
    Ok(LoadedEquilibrium {
        displacement_m: REFERENCE_APPROACH_M * scale,
        total_normal_force_n: total,
        total_tangential_force_n: mu * total,
        tangential_resultant_n: tr,
        centroid_m: c,
        eq,
    })
}
