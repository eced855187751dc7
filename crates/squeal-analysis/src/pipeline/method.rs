//! A method (reduction basis + eigen solver, or full order) solving the frictional
//! operator of one contact set at one mu, and the mu sweep that drives it.

use super::*;

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
    let mut family = crate::family::SceneMu::new(
        prep,
        registry,
        equilibrium,
        law,
        &squeal_core::Params::new(),
    );
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
    /// The steps of the last basis built ([`squeal_core::Basis::steps`]).
    last_steps: Vec<(String, f64)>,
    /// Whether a basis starts from the seed its build at the previous point left
    /// ([`Method::set_warm_start`]).
    warm_start: bool,
    seed: squeal_core::Seed,
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
    /// the sparse symmetric solver a basis uses for its real modes (the full-order complex
    /// problems a basis solves go to [`COMPLEX_SOLVER`] when registered:
    /// [`ModalSolvers::of`]).
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
            modal: ModalSolvers::of(registry, modal).map_err(core("modal eigen solver"))?,
            params,
            cached: None,
            stage: None,
            condition: false,
            last: StepTimes::default(),
            last_steps: Vec::new(),
            warm_start: false,
            seed: squeal_core::Seed::default(),
        })
    }

    /// Hands each basis the seed the basis built at the previous call left
    /// ([`squeal_core::Basis::seed`]: the real modes of a basis that computes them start
    /// from the previous contact set's, the residue method also from the previous point's
    /// target modes): for a sweep, whose consecutive points are near each other. Off by
    /// default, so that a study's cases, solved in any order by any worker, do not
    /// depend on which case came before.
    pub fn set_warm_start(&mut self, on: bool) {
        self.warm_start = on;
        if !on {
            self.seed = squeal_core::Seed::default();
        }
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
    /// subset of them ([`prepare_stage_alone`]), `contact_sets` of them when the caller
    /// knows how many. Returns it, shared (`None` when the basis has none).
    pub fn prepare_stage(
        &mut self,
        model: &Model,
        set: &ContactSet,
        contact_sets: Option<usize>,
    ) -> Result<Option<ModelStage>> {
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
                contact_sets,
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

    /// The steps of the basis the last [`solve`](Self::solve) built, with their times
    /// (s; [`squeal_core::Basis::steps`]); empty when it built none or its basis does not
    /// time its steps.
    pub fn last_basis_steps(&self) -> &[(String, f64)] {
        &self.last_steps
    }

    /// The modes of `op` at `mu`; `rebuilt` says the operator changed since the last call
    /// (a new contact set), which invalidates a cached basis. Returns the modes, the basis
    /// size (0 for full order) and the time spent on the basis and projection (s).
    pub fn solve(&mut self, op: &FrictionalOperator, mu: f64, rebuilt: bool) -> Result<StepResult> {
        self.last_steps.clear();
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
            // the stale basis goes before the new one is built: both at once would be the
            // largest allocation of a sweep twice
            self.cached = None;
            let t = Instant::now();
            let req = squeal_core::contact::BasisRequest {
                op,
                mu,
                band_hz: (self.params.fmin_hz, self.params.fmax_hz),
                modal: self.modal.as_ref(),
                reduced: self.eigen.as_ref(),
                params: &self.params,
                stage: self.stage.as_deref(),
                seed: Some(&self.seed).filter(|s| !s.is_empty()),
            };
            let mut b = squeal_core::contact::build_basis(basis.as_ref(), &req)
                .map_err(core(&format!("basis `{}` at mu = {mu}", self.basis_name)))?;
            let seed = std::mem::take(&mut b.seed);
            self.last_steps = std::mem::take(&mut b.steps);
            if self.warm_start {
                self.seed = seed;
            }
            self.cached = Some(
                squeal_core::reduction::ReducedOperator::new(op, b)
                    .map_err(core("projection on the basis"))?,
            );
            setup = t.elapsed().as_secs_f64();
            let projection_s = self.cached.as_ref().map_or(0.0, |c| c.projection_time_s);
            self.last.projection_s = projection_s;
            self.last.basis_s = setup - projection_s;
        }
        let mut red = self
            .cached
            .as_ref()
            .expect("basis built")
            .solve(op, mu, self.eigen.as_ref(), &self.params)
            .map_err(core(&format!("reduced solve at mu = {mu}")))?;
        let t = Instant::now();
        let free = self.stage.as_ref().and_then(|s| basis.stage_factor(s));
        squeal_core::reduction::energy_bounds_on(free.as_deref(), op, mu, &mut red.modes)
            .map_err(core(&format!("energy-norm error bounds at mu = {mu}")))?;
        self.last.solve_s = red.solve_time_s;
        self.last.expansion_s = red.expansion_time_s + t.elapsed().as_secs_f64();
        Ok((red.modes, red.basis_size, setup))
    }
}
