//! The sparse solver a basis is handed as its `modal` solver ([`ModalSolvers`]): one
//! backend for the real-mode problems, another for the full-order complex ones.

use squeal_core::eigen::SymmetricProblem;
use squeal_core::faer::MatRef;
use squeal_core::operator::{ComplexModes, Qep, RealModes};
use squeal_core::spectral::ShiftInvert;
use squeal_core::{EigenParams, EigenSolver, FrictionalOperator, Params, Registry, Result};
use std::sync::Arc;

/// The real-mode problems of a basis (its tied real modes, a model stage's free modes) go
/// to `real`, the full-order complex problems some bases solve for themselves (`pod`'s
/// snapshots) to `complex`: the fastest backend differs between the two (on the default
/// rig `krylov`'s block Lanczos for the first, ARPACK for the second; see
/// [`super::MODAL_SOLVER`] and [`super::COMPLEX_SOLVER`]). Its name is `real`'s.
pub struct ModalSolvers {
    real: Arc<dyn EigenSolver>,
    complex: Arc<dyn EigenSolver>,
}

impl ModalSolvers {
    /// Real-mode problems to `real`, complex ones to `complex`.
    pub fn new(real: Arc<dyn EigenSolver>, complex: Arc<dyn EigenSolver>) -> Self {
        Self { real, complex }
    }

    /// The registered solver `real` for the real-mode problems and
    /// [`super::COMPLEX_SOLVER`] for the complex ones; `real` for both when the registry
    /// has no [`super::COMPLEX_SOLVER`] (a registry assembled without it).
    pub fn of(registry: &Registry, real: &str) -> Result<Arc<dyn EigenSolver>> {
        let real: Arc<dyn EigenSolver> = Arc::from(registry.eigen.create(real, &Params::new())?);
        let complex = match registry.eigen.create(super::COMPLEX_SOLVER, &Params::new()) {
            Ok(c) => Arc::from(c),
            Err(_) => real.clone(),
        };
        Ok(Arc::new(Self::new(real, complex)))
    }
}

impl EigenSolver for ModalSolvers {
    fn name(&self) -> &str {
        self.real.name()
    }

    fn solve_symmetric(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        self.real.solve_symmetric(problem, params)
    }

    fn solve_symmetric_on(
        &self,
        problem: &SymmetricProblem<'_>,
        op: &ShiftInvert<'_>,
        start: Option<MatRef<'_, f64>>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        self.real.solve_symmetric_on(problem, op, start, params)
    }

    fn solve_qep(&self, qep: &Qep, params: &EigenParams) -> Result<ComplexModes> {
        self.complex.solve_qep(qep, params)
    }

    fn solve_frictional(
        &self,
        op: &FrictionalOperator,
        mu: f64,
        params: &EigenParams,
    ) -> Result<ComplexModes> {
        self.complex.solve_frictional(op, mu, params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use squeal_core::faer::sparse::Triplet;
    use squeal_core::{Error, SparseMat};

    /// A solver that only says who it is: every solve fails naming it and the problem.
    struct Named(&'static str);

    impl EigenSolver for Named {
        fn name(&self) -> &str {
            self.0
        }
        fn solve_symmetric(&self, _: &SymmetricProblem<'_>, _: &EigenParams) -> Result<RealModes> {
            Err(Error::Invalid(format!("{}: real", self.0)))
        }
        fn solve_qep(&self, _: &Qep, _: &EigenParams) -> Result<ComplexModes> {
            Err(Error::Invalid(format!("{}: complex", self.0)))
        }
    }

    #[test]
    fn without_the_complex_solver_the_modal_solver_solves_both() {
        let mut reg = Registry::default();
        reg.eigen.register("lanczos", "stub", |_: &Params| {
            let s: Box<dyn EigenSolver> = Box::new(Named("lanczos"));
            Ok(s)
        });
        let split = ModalSolvers::of(&reg, "lanczos").unwrap();
        let eye = SparseMat::try_new_from_triplets(1, 1, &[Triplet::new(0, 0, 1.0)]).unwrap();
        let qep = Qep {
            m: eye.clone(),
            c: None,
            k: eye,
        };
        let e = split
            .solve_qep(&qep, &EigenParams::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("lanczos: complex"), "{e}");
        // an unknown modal solver is still refused
        assert!(ModalSolvers::of(&reg, "nonesuch").is_err());
    }

    #[test]
    fn real_problems_go_to_one_solver_and_complex_ones_to_the_other() {
        let split = ModalSolvers::new(Arc::new(Named("lanczos")), Arc::new(Named("arnoldi")));
        assert_eq!(split.name(), "lanczos");
        let eye = SparseMat::try_new_from_triplets(
            2,
            2,
            &[Triplet::new(0, 0, 1.0), Triplet::new(1, 1, 1.0)],
        )
        .unwrap();
        let problem = SymmetricProblem {
            k: eye.as_ref(),
            m: eye.as_ref(),
        };
        let p = EigenParams::default();
        let real = split.solve_symmetric(&problem, &p).unwrap_err().to_string();
        assert!(real.contains("lanczos: real"), "{real}");
        let op = ShiftInvert::new(eye.as_ref(), eye.as_ref(), -1.0).unwrap();
        let on = split
            .solve_symmetric_on(&problem, &op, None, &p)
            .unwrap_err()
            .to_string();
        assert!(on.contains("lanczos: real"), "{on}");
        let qep = Qep {
            m: eye.clone(),
            c: None,
            k: eye.clone(),
        };
        let complex = split.solve_qep(&qep, &p).unwrap_err().to_string();
        assert!(complex.contains("arnoldi: complex"), "{complex}");
    }
}
