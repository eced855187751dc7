//! The stability pipeline of one scene: model -> contact set -> sliding equilibrium ->
//! frictional operator -> complex modes. Each stage is timed; the operator is built once
//! per active set and handed unchanged to any eigen solver or reduction basis.

mod method;
mod solvers;
mod stage;

pub use method::{run_mu_sweep, solve_modes, sweep_point, Method, StepResult, StepTimes};
pub use solvers::ModalSolvers;
pub use stage::{prepare_stage, prepare_stage_alone, stage_keys};

/// The eigen solver of every real-mode problem the analyses solve (body modes, free and
/// tied real modes of the bases, the modes of tracking), by registered name.
pub const MODAL_SOLVER: &str = "krylov";

/// The eigen solver of the full-order complex problems a basis solves for itself (the
/// snapshots of `pod`; [`ModalSolvers`]), by registered name: on the default rig ARPACK
/// solves the full frictional operator about 15 % faster than `krylov`'s Krylov-Schur
/// (`squeal bench`, mu 0.3: 22.6 s against 26.5 s).
pub const COMPLEX_SOLVER: &str = "arpack";

use crate::modal_cache::{CachedModal, ModalCache};
use squeal_contact::{
    build_operator, damping_matrix, problem, reference_load, solve_on, ContactError, ContactSet,
    LoadedEquilibrium,
};
use squeal_core::contact::{Condensation, NormalModes};
use squeal_core::linalg::Cholesky;
use squeal_core::operator::ComplexModes;
use squeal_core::{
    EigenParams, EigenSolver, FreeModel, FrictionalOperator, ModelStage, PairDofs, Params,
    RealModes, ReductionBasis, Registry, SymmetricProblem,
};
use squeal_scene::{build, BodyKind, Damping, Model, Scene, SceneError};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use thiserror::Error;

/// Errors of the pipeline, each naming its stage.
#[derive(Debug, Error)]
pub enum PipelineError {
    /// Reading or building the scene.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Contact set-up or equilibrium.
    #[error(transparent)]
    Contact(#[from] ContactError),
    /// Reading or evaluating an operator directory.
    #[error(transparent)]
    Io(#[from] squeal_io::IoError),
    /// Plugins and solvers.
    #[error("{stage}: {source}")]
    Core {
        /// Which stage failed.
        stage: String,
        /// Cause.
        source: squeal_core::Error,
    },
}

/// Result with [`PipelineError`].
pub type Result<T> = std::result::Result<T, PipelineError>;

fn core(stage: &str) -> impl FnOnce(squeal_core::Error) -> PipelineError + '_ {
    move |source| PipelineError::Core {
        stage: stage.to_string(),
        source,
    }
}

/// A built scene with its contact set and the condensation of its contact problem,
/// ready for equilibria at any mu.
pub struct Prepared {
    /// The scene.
    pub scene: Scene,
    /// Name of the scene in messages and outputs.
    pub file: String,
    /// The FE model (free DOFs).
    pub model: Model,
    /// Candidate contact pairs.
    pub set: ContactSet,
    /// The condensed contact problem (one factorization of `K`).
    pub condensation: Condensation,
    /// Load vector of the reference problem (zero).
    pub f: Vec<f64>,
    /// Initial gaps of the reference problem.
    pub g0: Vec<f64>,
    /// Build time (s).
    pub build_time_s: f64,
    /// The free model's normal modes and the bases' model stages, computed once.
    free: Mutex<FreeCache>,
    /// Real modes of the tied systems solved so far ([`Method::share_modal_cache`]).
    modal_cache: Arc<ModalCache>,
}

/// What [`Prepared`] keeps of the free (unconstrained) model between stages: its normal
/// modes up to the highest frequency asked so far, and the model stages of the bases
/// ([`ReductionBasis::prepare`], e.g. the free-interface synthesis of `cms`, which takes
/// the condensation's factor of `K`), by stage key.
#[derive(Default)]
struct FreeCache {
    /// Modes complete up to `.0` Hz at tolerance `.1`.
    modes: Option<(f64, f64, Arc<RealModes>)>,
    /// Model stages by [`ReductionBasis::stage_key`].
    stages: Vec<(String, ModelStage)>,
}

/// The modes of `modes` up to `fmax_hz` (they are sorted by frequency).
fn modes_below(modes: &RealModes, fmax_hz: f64) -> RealModes {
    let k = modes.freq_hz.iter().take_while(|&&f| f <= fmax_hz).count();
    RealModes {
        omega2: modes.omega2[..k].to_vec(),
        freq_hz: modes.freq_hz[..k].to_vec(),
        vectors: modes.vectors.as_ref().subcols(0, k).to_owned(),
        residuals: modes.residuals[..k].to_vec(),
        info: modes.info.clone(),
        above_band: squeal_core::faer::Mat::zeros(modes.vectors.nrows(), 0),
    }
}

impl Prepared {
    /// Builds the whole scene, its contact set and the condensation.
    pub fn new(registry: &Registry, scene: Scene, file: &str) -> Result<Self> {
        let start = Instant::now();
        let model = build(&scene, BodyKind::All, registry, file)?;
        let set = ContactSet::new(&model, &scene.contact.zone, scene.study.rotation)?;
        let build_time_s = start.elapsed().as_secs_f64();
        let (f, g0) = reference_load(&model, &set);
        let condensation = Condensation::new(&problem(&model, &set, &f, &g0))
            .map_err(core("condensation of the contact problem"))?;
        Ok(Self {
            scene,
            file: file.to_string(),
            model,
            set,
            condensation,
            f,
            g0,
            build_time_s,
            free: Mutex::new(FreeCache::default()),
            modal_cache: Arc::new(ModalCache::default()),
        })
    }

    /// The normal modes of the free model (no pair tied) up to `fmax_hz`, by `solver` at
    /// relative tolerance `tol`. Computed once: a later call up to the same or a lower
    /// frequency, at the same or a looser tolerance, takes them from the first (callers
    /// that need several cutoffs ask for the highest first).
    pub fn normal_modes(
        &self,
        solver: &dyn EigenSolver,
        fmax_hz: f64,
        tol: f64,
    ) -> Result<RealModes> {
        self.normal_modes_core(solver, fmax_hz, tol)
            .map_err(core("normal modes of the free model"))
    }

    /// [`normal_modes`](Self::normal_modes) with the solver's own error.
    fn normal_modes_core(
        &self,
        solver: &dyn EigenSolver,
        fmax_hz: f64,
        tol: f64,
    ) -> squeal_core::Result<RealModes> {
        let mut cache = self.free.lock().unwrap_or_else(|p| p.into_inner());
        if let Some((top, t, modes)) = &cache.modes {
            if *top >= fmax_hz && *t <= tol {
                return Ok(modes_below(modes, fmax_hz));
            }
        }
        let modes = solver.solve_symmetric(
            &SymmetricProblem {
                k: self.model.k.as_ref(),
                m: self.model.m.as_ref(),
            },
            &EigenParams {
                fmin_hz: 0.0,
                fmax_hz,
                tol,
                nev_hint: None,
                ..EigenParams::default()
            },
        )?;
        cache.modes = Some((fmax_hz, tol, Arc::new(modes.clone())));
        Ok(modes)
    }

    /// The model stage of `basis` ([`ReductionBasis::prepare`]) for a band whose top is
    /// `params.fmax_hz`: built once per stage key on the free model, its candidate pairs,
    /// the condensation's factor of `K` and the normal modes kept here (by `modal` at the
    /// tolerance of `params`), then shared by every method and stage on the scene. `None`
    /// when the basis has no model stage.
    pub fn model_stage(
        &self,
        basis: &dyn ReductionBasis,
        modal: &dyn EigenSolver,
        params: &EigenParams,
    ) -> Result<Option<ModelStage>> {
        let Some(key) = basis.stage_key(params.fmax_hz) else {
            return Ok(None);
        };
        let kept = |cache: &FreeCache| {
            cache
                .stages
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, s)| s.clone())
        };
        if let Some(stage) = kept(&self.free.lock().unwrap_or_else(|p| p.into_inner())) {
            return Ok(Some(stage));
        }
        let modes = |fmax_hz: f64| self.normal_modes_core(modal, fmax_hz, params.tol);
        let stage = prepare_stage(
            basis,
            &self.model,
            &self.set,
            Some(self.condensation.factor().clone()),
            &modes,
            modal,
            params,
            None,
        )?;
        if let Some(stage) = &stage {
            let mut cache = self.free.lock().unwrap_or_else(|p| p.into_inner());
            if kept(&cache).is_none() {
                cache.stages.push((key, stage.clone()));
            }
        }
        Ok(stage)
    }

    /// Drops the kept model stages whose keys are not in `keep` (a free-interface
    /// synthesis holds `n x 3 pairs` values, gigabytes on a large model) once no stage
    /// ahead needs them; a later [`model_stage`](Self::model_stage) builds them again.
    pub fn release_stages_except(&self, keep: &[String]) {
        self.free
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .stages
            .retain(|(k, _)| keep.contains(k));
    }

    /// Drops everything kept between stages: the model stages, the free model's normal
    /// modes and the real modes of the tied systems ([`ModalCache`]), for a stage that
    /// needs none of them (full-order solves); later stages build them again.
    pub fn release_kept(&self) {
        let mut free = self.free.lock().unwrap_or_else(|p| p.into_inner());
        free.stages.clear();
        free.modes = None;
        drop(free);
        self.modal_cache.clear();
    }

    /// This model with `cache` for the real modes of its tied systems in place of its own
    /// (e.g. a cache that keeps them in files, [`ModalCache::spilling`]).
    pub fn with_modal_cache(mut self, cache: ModalCache) -> Self {
        self.modal_cache = Arc::new(cache);
        self
    }

    /// The model, its candidate pairs and the scene's damping, everything else dropped
    /// (the condensation's factor of `K`, the kept modes and model stages): what the
    /// frictional operators of known active sets ([`damped_operator`]) need, for a stage
    /// that solves no more equilibria.
    pub fn into_model(self) -> (Model, ContactSet, Damping) {
        (self.model, self.set, self.scene.damping)
    }

    /// The real modes of the tied systems solved on this model so far, for
    /// [`Method::share_modal_cache`].
    pub fn modal_cache(&self) -> Arc<ModalCache> {
        self.modal_cache.clone()
    }

    /// The sliding equilibrium at `mu` under the scene's load.
    pub fn equilibrium(
        &self,
        registry: &Registry,
        solver: &str,
        law: &str,
        mu: f64,
    ) -> Result<LoadedEquilibrium> {
        self.equilibrium_with(registry, solver, law, &Params::new(), mu)
    }

    /// [`equilibrium`](Self::equilibrium) with parameters for the contact law (a
    /// penalty's stiffness).
    pub fn equilibrium_with(
        &self,
        registry: &Registry,
        solver: &str,
        law: &str,
        law_params: &Params,
        mu: f64,
    ) -> Result<LoadedEquilibrium> {
        squeal_contact::check_user_mu(mu)?;
        let s = registry
            .equilibrium
            .create(solver, &Params::new())
            .map_err(core("equilibrium solver"))?;
        let l = registry
            .contact_laws
            .create(law, law_params)
            .map_err(core("contact law"))?;
        let prob = problem(&self.model, &self.set, &self.f, &self.g0);
        Ok(solve_on(
            &self.condensation,
            &prob,
            &self.set,
            &self.scene.load,
            s.as_ref(),
            l.as_ref(),
            mu,
        )?)
    }

    /// The frictional operator of an active set, with the scene's damping.
    pub fn operator(&self, active: &[bool]) -> Result<FrictionalOperator> {
        damped_operator(&self.model, &self.scene.damping, &self.set, active)
    }
}

/// The frictional operator of the closed pairs `active` of `set` on `model`, damped as
/// `damping` says (see [`squeal_contact::damping`]).
pub fn damped_operator(
    model: &Model,
    damping: &Damping,
    set: &ContactSet,
    active: &[bool],
) -> Result<FrictionalOperator> {
    let c = damping_matrix(model, set, active, damping)?;
    Ok(build_operator(
        model.m.as_ref(),
        c.as_ref().map(|c| c.as_ref()),
        model.k.as_ref(),
        set,
        active,
    )?)
}

/// Free-interface normal modes of the scene's bodies (no contact), the reference of mode
/// signatures, tracking and the MAC chart.
pub struct FreeModes {
    /// Frequencies (Hz).
    pub freq_hz: Vec<f64>,
    /// `body:label` of each mode (e.g. `disc:a,0,3`, `pin:tilt-y`).
    pub labels: Vec<String>,
    /// `M phi` on the model's free DOFs, one column per mode (`phi` M-orthonormal).
    pub mphi: squeal_core::faer::Mat<f64>,
}

/// Relative tolerance of the free-interface modes of tracking (their signatures only
/// need a few digits; the free-interface synthesis of `cms` at the default tolerance
/// serves them).
pub const TRACKING_TOL: f64 = 1e-10;

impl Prepared {
    /// Normal modes of the bodies without contact up to `fmax_hz` (from
    /// [`Prepared::normal_modes`]: a synthesis built before serves them).
    pub fn free_interface_modes(
        &self,
        registry: &Registry,
        eigen: &str,
        fmax_hz: f64,
    ) -> Result<FreeModes> {
        let solver = registry
            .eigen
            .create(eigen, &Params::new())
            .map_err(core("eigen solver"))?;
        let modes = self.normal_modes(solver.as_ref(), fmax_hz, TRACKING_TOL)?;
        let records = crate::modal::label_modes(&self.model, &modes);
        let n = self.model.m.nrows();
        let k = modes.freq_hz.len();
        let mut mphi = squeal_core::faer::Mat::<f64>::zeros(n, k);
        let mut y = vec![0.0; n];
        for c in 0..k {
            let x: Vec<f64> = modes.vectors.col(c).iter().copied().collect();
            squeal_core::linalg::spmv(self.model.m.as_ref(), &x, &mut y);
            for r in 0..n {
                mphi[(r, c)] = y[r];
            }
        }
        Ok(FreeModes {
            freq_hz: modes.freq_hz.clone(),
            labels: records
                .iter()
                .map(|r| format!("{}:{}", r.body, r.label))
                .collect(),
            mphi,
        })
    }
}
