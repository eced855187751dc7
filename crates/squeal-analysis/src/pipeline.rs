//! The stability pipeline of one scene: model -> contact set -> sliding equilibrium ->
//! frictional operator -> complex modes. Each stage is timed; the operator is built once
//! per active set and handed unchanged to any eigen solver or reduction basis.

use squeal_contact::{
    build_operator, problem, reference_load, solve_on, ContactError, ContactSet, LoadedEquilibrium,
};
use squeal_core::contact::Condensation;
use squeal_core::qep::ComplexModes;
use squeal_core::{EigenParams, EigenSolver, FrictionalOperator, Params, Registry};
use squeal_scene::{build, BodyKind, Model, Scene, SceneError};
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
        })
    }

    /// The sliding equilibrium at `mu` under the scene's load.
    pub fn equilibrium(
        &self,
        registry: &Registry,
        solver: &str,
        law: &str,
        mu: f64,
    ) -> Result<LoadedEquilibrium> {
        squeal_contact::check_user_mu(mu)?;
        let s = registry
            .equilibrium
            .create(solver, &Params::new())
            .map_err(core("equilibrium solver"))?;
        let l = registry
            .contact_laws
            .create(law, &Params::new())
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

    /// The frictional operator of an active set.
    pub fn operator(&self, active: &[bool]) -> Result<FrictionalOperator> {
        Ok(build_operator(
            self.model.m.as_ref(),
            None,
            self.model.k.as_ref(),
            &self.set,
            active,
        )?)
    }
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
