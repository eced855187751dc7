//! The stability pipeline of one scene: model -> contact set -> sliding equilibrium ->
//! frictional operator -> complex modes. Each stage is timed; the operator is built once
//! per active set and handed unchanged to any eigen solver or reduction basis.

use crate::modal_cache::{CachedModal, ModalCache};
use squeal_contact::{
    build_operator, damping_matrix, problem, reference_load, solve_on, ContactError, ContactSet,
    LoadedEquilibrium,
};
use squeal_core::contact::{Condensation, NormalModes};
use squeal_core::linalg::Cholesky;
use squeal_core::qep::ComplexModes;
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

/// The model-stage keys ([`ReductionBasis::stage_key`]) of the bases named in `bases`
/// (`none` for full order, default parameters) at the band top `band_top_hz`, without
/// repeats: what a run that goes on with those bases still needs of the free model.
pub fn stage_keys<'a>(
    registry: &Registry,
    bases: impl IntoIterator<Item = &'a str>,
    band_top_hz: f64,
) -> Result<Vec<String>> {
    let mut keys = Vec::new();
    for b in bases.into_iter().filter(|b| *b != "none") {
        let plugin = registry
            .bases
            .create(b, &Params::new())
            .map_err(core(&format!("basis `{b}`")))?;
        if let Some(k) = plugin.stage_key(band_top_hz) {
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
    }
    Ok(keys)
}

/// The model stage of `basis` ([`ReductionBasis::prepare`]) on `model` and the candidate
/// pairs of `set`, with `k_factor` (a Cholesky factor of the model's `K`, when the caller
/// has one) and `normal_modes` (the free model's modes up to a frequency); `modal` and
/// `params` as the stage's solver and tolerances, `params.fmax_hz` the band top. `None`
/// when the basis has no model stage.
pub fn prepare_stage(
    basis: &dyn ReductionBasis,
    model: &Model,
    set: &ContactSet,
    k_factor: Option<Arc<Cholesky>>,
    normal_modes: &NormalModes<'_>,
    modal: &dyn EigenSolver,
    params: &EigenParams,
) -> Result<Option<ModelStage>> {
    if basis.stage_key(params.fmax_hz).is_none() {
        return Ok(None);
    }
    let pairs = pair_dofs(set);
    let free = FreeModel {
        k: model.k.as_ref(),
        m: model.m.as_ref(),
        pairs: &pairs,
        k_factor,
        normal_modes,
        modal,
        band_hz: (params.fmin_hz, params.fmax_hz),
        params,
    };
    basis
        .prepare(&free)
        .map_err(core(&format!("model stage of basis `{}`", basis.name())))
}

/// [`prepare_stage`] without a factor of `K` or kept modes: the normal modes of the free
/// model are solved by `modal` at the tolerances of `params`.
pub fn prepare_stage_alone(
    basis: &dyn ReductionBasis,
    model: &Model,
    set: &ContactSet,
    modal: &dyn EigenSolver,
    params: &EigenParams,
) -> Result<Option<ModelStage>> {
    let modes = |fmax_hz: f64| {
        modal.solve_symmetric(
            &SymmetricProblem {
                k: model.k.as_ref(),
                m: model.m.as_ref(),
            },
            &EigenParams {
                fmin_hz: 0.0,
                fmax_hz,
                nev_hint: None,
                ..params.clone()
            },
        )
    };
    prepare_stage(basis, model, set, None, &modes, modal, params)
}

/// The DOFs of the candidate pairs of `set`, in the synthesis's terms.
fn pair_dofs(set: &ContactSet) -> Vec<PairDofs> {
    (0..set.len())
        .map(|i| PairDofs {
            pin: set.pin_dofs[i],
            disc: set.disc_dofs[i],
            direction: set.direction[i],
        })
        .collect()
}

/// Complex modes of `op` at `mu` with the named eigen solver, timed.
pub fn solve_modes(
    registry: &Registry,
    op: &FrictionalOperator,
    mu: f64,
    eigen: &str,
    params: &EigenParams,
) -> Result<(ComplexModes, Box<dyn EigenSolver>)> {
    let solver = registry
        .eigen
        .create(eigen, &Params::new())
        .map_err(core("eigen solver"))?;
    let modes = solver
        .solve_frictional(op, mu, params)
        .map_err(core(&format!(
            "`{eigen}` on the frictional operator at mu = {mu}"
        )))?;
    Ok((modes, solver))
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

/// Converts the complex modes of `op` into a sweep point (signatures on `free`).
pub fn sweep_point(
    op: &FrictionalOperator,
    modes: &ComplexModes,
    free: &FreeModes,
    mu: f64,
    active_pairs: usize,
) -> crate::sweep::SweepPoint {
    crate::family::sweep_point(op, modes, free, mu, mu, active_pairs)
}

/// What the solve step of a sweep returns: the modes, the basis size (0 for full order)
/// and the time spent building the operator and basis (s).
pub type StepResult = (ComplexModes, usize, f64);

/// Runs a mu sweep: equilibrium per mu (the contact set may change), the operator rebuilt
/// only when the active set changes, `solve(op, mu, op_changed)` for the modes (full order
/// or through a basis the closure keeps across calls), signatures on `free`. Points
/// already in `checkpoint` are not recomputed; each new one is appended before the next
/// starts, so a killed run resumes where it stopped. Every point's result depends only on
/// its mu and contact set (bases fixed in mu depend on the contact set alone), so a resumed
/// run, or shards over parts of the mu list merged by mu, give the same points as one
/// uninterrupted run. `progress` sees every point.
#[allow(clippy::too_many_arguments)]
pub fn run_mu_sweep(
    prep: &Prepared,
    registry: &Registry,
    mus: &[f64],
    equilibrium: &str,
    law: &str,
    free: &FreeModes,
    checkpoint: Option<&crate::sweep::Checkpoint>,
    mut solve: impl FnMut(&FrictionalOperator, f64, bool) -> Result<StepResult>,
    progress: impl FnMut(&crate::sweep::SweepPoint),
) -> Result<Vec<crate::sweep::SweepPoint>> {
    let mut family = crate::family::SceneMu::new(prep, registry, equilibrium, law);
    crate::family::sweep_points(
        &mut family,
        mus,
        free,
        checkpoint,
        |_, op, mu, changed| solve(op, mu, changed),
        progress,
    )
}

/// How the complex modes of an operator are computed: full order with one eigen solver,
/// or through a reduction basis (projected once per contact set when the basis does not
/// depend on mu) and a reduced solver. One object serves a whole sweep.
pub struct Method {
    /// `none` or the basis plugin name.
    pub basis_name: String,
    /// Eigen solver name (of the reduced problem when there is a basis).
    pub eigen_name: String,
    basis: Option<Box<dyn squeal_core::ReductionBasis>>,
    eigen: Box<dyn EigenSolver>,
    modal: Arc<dyn EigenSolver>,
    params: EigenParams,
    cached: Option<squeal_core::reduction::ReducedOperator>,
    stage: Option<ModelStage>,
    condition: bool,
    last: StepTimes,
}

/// Where the time of the last [`Method::solve`] went (s); zero for stages it skipped.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepTimes {
    /// Building the basis (its real modes, static vectors, ...).
    pub basis_s: f64,
    /// Projecting the operator on the basis.
    pub projection_s: f64,
    /// The eigen solve (the reduced one with a basis, the full-order one without).
    pub solve_s: f64,
    /// Expanding the reduced modes and their backward errors on the full operator.
    pub expansion_s: f64,
    /// Left eigenvectors added to full-order modes for their condition numbers (see
    /// [`Method::set_condition`]).
    pub condition_s: f64,
}

impl Method {
    /// `basis = "none"` for full order; `basis_params` go to the basis plugin; `modal` is
    /// the sparse symmetric solver a basis uses for its real modes.
    pub fn new(
        registry: &Registry,
        basis: &str,
        basis_params: &Params,
        eigen: &str,
        modal: &str,
        params: EigenParams,
    ) -> Result<Self> {
        let b = if basis == "none" {
            None
        } else {
            Some(
                registry
                    .bases
                    .create(basis, basis_params)
                    .map_err(core("reduction basis"))?,
            )
        };
        Ok(Self {
            basis_name: basis.to_string(),
            eigen_name: eigen.to_string(),
            basis: b,
            eigen: registry
                .eigen
                .create(eigen, &Params::new())
                .map_err(core("eigen solver"))?,
            modal: Arc::from(
                registry
                    .eigen
                    .create(modal, &Params::new())
                    .map_err(core("modal eigen solver"))?,
            ),
            params,
            cached: None,
            stage: None,
            condition: false,
            last: StepTimes::default(),
        })
    }

    /// Whether full-order modes always get condition numbers and forward error
    /// estimates: the eigen solvers compute them only up to
    /// [`CONDITION_AUTO_MAX_DIM`](squeal_core::qep::CONDITION_AUTO_MAX_DIM) DOFs, and with
    /// this set they are added above that ([`squeal_core::qep::add_condition`], one
    /// factorization per mode, timed in [`StepTimes::condition_s`]). Reduced solves
    /// always have them.
    pub fn set_condition(&mut self, always: bool) {
        self.condition = always;
    }

    /// The key of the model stage the basis needs ([`ReductionBasis::stage_key`]), `None`
    /// for full order and for a basis without one (every basis but `cms`).
    pub fn stage_key(&self) -> Option<String> {
        self.basis
            .as_ref()
            .and_then(|b| b.stage_key(self.params.fmax_hz))
    }

    /// Builds the model stage the basis needs (once: a later call keeps the one it has)
    /// for `model` and the candidate pairs `set`, every contact set solved later being a
    /// subset of them ([`prepare_stage_alone`]). Returns it, shared (`None` when the
    /// basis has none).
    pub fn prepare_stage(&mut self, model: &Model, set: &ContactSet) -> Result<Option<ModelStage>> {
        let Some(basis) = &self.basis else {
            return Ok(None);
        };
        if self.stage.is_none() {
            self.stage = prepare_stage_alone(
                basis.as_ref(),
                model,
                set,
                self.modal.as_ref(),
                &self.params,
            )?;
        }
        Ok(self.stage.clone())
    }

    /// [`prepare_stage`](Self::prepare_stage) from the stages `prep` keeps (built there
    /// once, on the condensation's factor of `K`, and shared with every method and stage
    /// on the same scene).
    pub fn prepare_stage_on(&mut self, prep: &Prepared) -> Result<Option<ModelStage>> {
        let Some(basis) = &self.basis else {
            return Ok(None);
        };
        if self.stage.is_none() {
            self.stage = prep.model_stage(basis.as_ref(), self.modal.as_ref(), &self.params)?;
        }
        Ok(self.stage.clone())
    }

    /// Serves the basis's real-mode solves through `cache` (shared by every method on the
    /// same model, e.g. [`Prepared::modal_cache`]): a contact set whose modes another
    /// method or an earlier mu point already computed is not solved again. The basis
    /// times then leave that solve out.
    pub fn share_modal_cache(&mut self, cache: Arc<ModalCache>) {
        self.modal = Arc::new(CachedModal::new(self.modal.clone(), cache));
    }

    /// Hands a model stage built elsewhere (shared by parallel workers).
    pub fn set_stage(&mut self, stage: Option<ModelStage>) {
        self.stage = stage;
    }

    /// Where the time of the last [`solve`](Self::solve) went.
    pub fn last_times(&self) -> StepTimes {
        self.last
    }

    /// The modes of `op` at `mu`; `rebuilt` says the operator changed since the last call
    /// (a new contact set), which invalidates a cached basis. Returns the modes, the basis
    /// size (0 for full order) and the time spent on the basis and projection (s).
    pub fn solve(&mut self, op: &FrictionalOperator, mu: f64, rebuilt: bool) -> Result<StepResult> {
        let Some(basis) = &self.basis else {
            let mut modes = self
                .eigen
                .solve_frictional(op, mu, &self.params)
                .map_err(core(&format!("`{}` at mu = {mu}", self.eigen_name)))?;
            self.last = StepTimes {
                solve_s: modes.info.time_s,
                ..StepTimes::default()
            };
            if self.condition {
                let t = Instant::now();
                squeal_core::qep::add_condition(op, mu, &mut modes).map_err(core(&format!(
                    "condition numbers of the `{}` modes at mu = {mu}",
                    self.eigen_name
                )))?;
                self.last.condition_s = t.elapsed().as_secs_f64();
            }
            return Ok((modes, 0, 0.0));
        };
        let stale = rebuilt
            || self.cached.is_none()
            || (basis.depends_on_mu() && self.cached.as_ref().and_then(|c| c.basis.mu) != Some(mu));
        let mut setup = 0.0;
        self.last = StepTimes::default();
        if stale {
            let t = Instant::now();
            let req = squeal_core::contact::BasisRequest {
                op,
                mu,
                band_hz: (self.params.fmin_hz, self.params.fmax_hz),
                modal: self.modal.as_ref(),
                reduced: self.eigen.as_ref(),
                params: &self.params,
                stage: self.stage.as_deref(),
            };
            let b = squeal_core::contact::build_basis(basis.as_ref(), &req)
                .map_err(core(&format!("basis `{}` at mu = {mu}", self.basis_name)))?;
            self.cached = Some(
                squeal_core::reduction::ReducedOperator::new(op, b)
                    .map_err(core("projection on the basis"))?,
            );
            setup = t.elapsed().as_secs_f64();
            let projection_s = self.cached.as_ref().map_or(0.0, |c| c.projection_time_s);
            self.last.projection_s = projection_s;
            self.last.basis_s = setup - projection_s;
        }
        let red = self
            .cached
            .as_ref()
            .expect("basis built")
            .solve(op, mu, self.eigen.as_ref(), &self.params)
            .map_err(core(&format!("reduced solve at mu = {mu}")))?;
        self.last.solve_s = red.solve_time_s;
        self.last.expansion_s = red.expansion_time_s;
        Ok((red.modes, red.basis_size, setup))
    }
}
