//! The solver benchmark: a basis registered at run time (the `custom_basis` example's)
//! is benchmarked with no change to the bench code, and the mode comparison behind every
//! error figure detects what it must.

#[path = "../examples/custom_basis.rs"]
#[allow(dead_code)]
mod custom_basis;

use squeal::analysis::bench::{bench_case, compare, speed_ratios, stages_for, BenchOptions};
use squeal::analysis::pipeline::Prepared;
use squeal::core::reduction::PairSolves;
use squeal::core::{c64, FrictionalOperator, Params};
use squeal::scene::Scene;

fn coarse(reg: &squeal::core::Registry) -> Prepared {
    Prepared::new(reg, Scene::builtin("pin-on-disc-coarse").unwrap(), "coarse").unwrap()
}

fn coarse_operator(reg: &squeal::core::Registry, mu: f64) -> FrictionalOperator {
    let prep = coarse(reg);
    let eq = prep.equilibrium(reg, "lcp", "lagrange", mu).unwrap();
    prep.operator(&eq.eq.active).unwrap()
}

#[test]
fn a_basis_registered_at_run_time_appears_in_the_bench() {
    let mut reg = squeal::registry();
    let before = BenchOptions::all(&reg).bases;
    assert!(!before.iter().any(|b| b == "modes+random"));
    custom_basis::register(&mut reg);
    let mut opts = BenchOptions::all(&reg);
    assert!(opts.bases.iter().any(|b| b == "modes+random"));
    assert!(opts.bases.iter().any(|b| b == "none"));
    opts.band_hz = [0.0, 4000.0];
    opts.bases.retain(|b| b != "none");
    opts.eigens = vec!["dense".into()];
    opts.vary = vec![("count".into(), vec![10.0])];
    let mu = 0.7;
    let op = coarse_operator(&reg, mu);
    let mut seen = Vec::new();
    let (reference, runs) = bench_case(&reg, "mu=0.7", &op, &Vec::new(), mu, &opts, None, |r| {
        seen.push(format!("{}/{} {}", r.basis, r.eigen, r.basis_opts))
    })
    .unwrap();
    assert!(reference.modes > 5, "reference modes {}", reference.modes);
    // every registered basis ran (one run each with defaults), the new one also with the
    // varied parameter only it accepts
    for b in before.iter().filter(|b| *b != "none") {
        assert!(
            runs.iter()
                .any(|r| &r.basis == b && r.basis_opts.is_empty()),
            "{b} missing from {seen:?}"
        );
        assert!(!runs
            .iter()
            .any(|r| &r.basis == b && !r.basis_opts.is_empty()));
    }
    let custom: Vec<_> = runs.iter().filter(|r| r.basis == "modes+random").collect();
    assert_eq!(custom.len(), 2, "{seen:?}");
    assert_eq!(custom[1].basis_opts, "count=10");
    for r in &custom {
        assert_eq!(r.status, "ok");
        assert!(r.basis_size > 10 && r.basis_size < op.dim());
        assert!(r.errors.max_rel_freq_err.is_finite());
        assert!(r.errors.max_backward_error > 0.0);
        assert_eq!(r.errors.reference_modes, reference.modes);
    }
    // 40 random vectors enrich more than 10: a bigger basis, no larger frequency error
    assert!(custom[0].basis_size > custom[1].basis_size);
    // the reference is a run of its own, exact against itself
    let refrun = runs.iter().find(|r| r.reference).unwrap();
    assert_eq!(refrun.errors.max_rel_freq_err, 0.0);
    assert_eq!(seen.len(), runs.len());
    // residue is accurate on this case: it has a speed ratio
    assert!(speed_ratios(&runs)
        .iter()
        .any(|s| s.method == "residue/dense"));
}

#[test]
fn the_comparison_counts_missed_false_and_shifted_modes() {
    let reg = squeal::registry();
    let mu = 0.7;
    let op = coarse_operator(&reg, mu);
    let arpack = reg.eigen.create("arpack", &Params::new()).unwrap();
    let params = squeal::core::EigenParams {
        fmax_hz: 4000.0,
        ..Default::default()
    };
    let reference = arpack.solve_frictional(&op, mu, &params).unwrap();
    let band = [0.0, 4000.0];
    let unstable: Vec<usize> = (0..reference.len())
        .filter(|&i| reference.is_unstable(i, 1e-8))
        .collect();
    assert!(
        !unstable.is_empty(),
        "the coarse scene flutters at mu = 0.7"
    );
    let same = compare(&reference, &reference, band, 1e-8);
    assert_eq!(same.missed_modes, 0);
    assert_eq!(same.reference_unstable, unstable.len());
    assert_eq!(same.max_rel_freq_err, 0.0);
    // drop the unstable mode: one mode and one instability missed
    let u = unstable[0];
    let mut dropped = reference.clone();
    dropped.lambda.remove(u);
    dropped.freq_hz.remove(u);
    dropped.dvr.remove(u);
    dropped.backward_error.remove(u);
    let e = compare(&reference, &dropped, band, 1e-8);
    assert!(e.missed_modes >= 1 && e.missed_unstable == 1, "{e:?}");
    // mirror its real part (a missed instability) and give a neutral mode far from it a
    // positive one (a false instability)
    let mut flipped = reference.clone();
    flipped.lambda[u] = c64::new(-flipped.lambda[u].re, flipped.lambda[u].im);
    flipped.dvr[u] = -flipped.dvr[u];
    let fu = reference.freq_hz[u];
    let neutral = (0..reference.len())
        .find(|&i| (reference.freq_hz[i] - fu).abs() > 0.05 * fu && reference.dvr[i].abs() < 1e-9)
        .expect("a neutral mode away from the flutter");
    let l = reference.lambda[neutral];
    flipped.lambda[neutral] = c64::new(1e-3 * l.im, l.im);
    flipped.dvr[neutral] = 1e-3;
    let e = compare(&reference, &flipped, band, 1e-8);
    assert_eq!((e.missed_unstable, e.false_unstable), (1, 1), "{e:?}");
    assert!(e.max_abs_dvr_err > reference.dvr[u], "{e:?}");
    // shift one frequency by 0.5 %: found, with that error
    let mut shifted = reference.clone();
    let k = reference.len() / 2;
    shifted.lambda[k] *= 1.005;
    shifted.freq_hz[k] *= 1.005;
    let e = compare(&reference, &shifted, band, 1e-8);
    assert_eq!(e.missed_modes, 0);
    assert!((e.max_rel_freq_err - 0.005).abs() < 1e-9, "{e:?}");
    // the full-order solve above 1000 DOFs has error bounds only for the modes whose
    // class depends on them; added for every mode, they are recorded and the shifted
    // mode's error (0.5 %) is far above them
    assert!(
        shifted.cond.iter().any(|c| c.is_nan()),
        "{:?}",
        shifted.cond
    );
    for i in 0..shifted.len() {
        let needs = squeal::core::operator::needs_condition(
            reference.lambda[i],
            reference.backward_error[i],
            reference.cond_floor[i],
        );
        assert_eq!(
            !reference.cond[i].is_nan(),
            needs,
            "mode {i}: {:?}",
            reference.lambda[i]
        );
    }
    squeal::core::qep::add_condition(&op, mu, &mut shifted).unwrap();
    let e = compare(&reference, &shifted, band, 1e-8);
    assert!(e.max_error_bound > 0.0 && e.max_error_bound < 1e-6, "{e:?}");
    assert!(e.max_cond >= 1.0 && e.max_cond.is_finite(), "{e:?}");
    assert_eq!(e.above_bound, 1, "{e:?}");
    assert!((e.max_rel_lambda_err - 0.005).abs() < 1e-9, "{e:?}");
}

#[test]
fn bench_json_round_trips_failed_runs() {
    // a basis whose build always fails: a failed run with unmeasured (NaN) errors next
    // to the successful `modes` one
    struct Failing;
    impl squeal::core::ReductionBasis for Failing {
        fn name(&self) -> &str {
            "failing"
        }
        fn build(
            &self,
            _: &squeal::core::BasisRequest<'_>,
        ) -> squeal::core::Result<squeal::core::Basis> {
            Err(squeal::core::Error::Invalid(
                "this basis always fails".into(),
            ))
        }
    }
    let mut reg = squeal::registry();
    reg.bases.register("failing", "always fails", |_: &Params| {
        let b: Box<dyn squeal::core::ReductionBasis> = Box::new(Failing);
        Ok(b)
    });
    let mu = 0.3;
    let op = coarse_operator(&reg, mu);
    let mut opts = BenchOptions::all(&reg);
    opts.band_hz = [0.0, 4000.0];
    opts.bases = vec!["modes".into(), "failing".into()];
    opts.eigens = vec!["dense".into()];
    opts.vary = Vec::new();
    let (_, runs) = bench_case(&reg, "mu=0.3", &op, &Vec::new(), mu, &opts, None, |_| {}).unwrap();
    let failed = runs
        .iter()
        .find(|r| r.basis == "failing")
        .expect("the failing run");
    assert!(
        failed.status.contains("this basis always fails"),
        "{}",
        failed.status
    );
    assert!(failed.status.starts_with("error"), "{}", failed.status);
    assert!(failed.errors.max_rel_freq_err.is_nan());
    assert!(failed.speedup.is_nan(), "a failed run has no speed-up");
    assert!(runs.iter().any(|r| r.status == "ok" && !r.reference));
    let text = serde_json::to_string(&runs).unwrap();
    assert!(text.contains("null"), "NaN is written as null");
    let back: Vec<squeal::analysis::bench::BenchRun> = serde_json::from_str(&text).unwrap();
    assert_eq!(back.len(), runs.len());
    for (a, b) in runs.iter().zip(&back) {
        assert_eq!(a.status, b.status);
        let (x, y) = (a.errors.max_rel_freq_err, b.errors.max_rel_freq_err);
        assert!(x == y || (x.is_nan() && y.is_nan()), "{x} vs {y}");
    }
}

/// A basis of the test whose model stage is `PairSolves` under one shared key; its
/// `complete_stage` solves the friction responses of every candidate pair (what a basis
/// sharing another's stage adds to it).
struct SharingStage {
    completes: bool,
}

impl squeal::core::ReductionBasis for SharingStage {
    fn name(&self) -> &str {
        "sharing"
    }
    fn stage_key(&self, _: f64) -> Option<String> {
        Some("pair solves shared by two test bases".into())
    }
    fn prepare(
        &self,
        free: &squeal::core::FreeModel<'_>,
    ) -> squeal::core::Result<Option<squeal::core::ModelStage>> {
        PairSolves::stage(free)
    }
    fn complete_stage(&self, stage: &squeal::core::ModelStage) -> squeal::core::Result<()> {
        if self.completes {
            if let Some(p) = PairSolves::in_stage(Some(stage.as_ref())) {
                p.solve_friction_responses();
            }
        }
        Ok(())
    }
    fn build(
        &self,
        _: &squeal::core::BasisRequest<'_>,
    ) -> squeal::core::Result<squeal::core::Basis> {
        Err(squeal::core::Error::Invalid("not built here".into()))
    }
}

#[test]
fn a_model_stage_shared_by_two_bases_is_completed_before_any_case_is_timed() {
    // two bases with one stage key: whichever prepares it, the one that completes it
    // (the friction responses of every pair) has done so before any case is timed
    let mut reg = squeal::registry();
    for (name, completes) in [("sharing-plain", false), ("sharing-completing", true)] {
        reg.bases
            .register(name, "a test basis sharing a stage", move |_: &Params| {
                let b: Box<dyn squeal::core::ReductionBasis> = Box::new(SharingStage { completes });
                Ok(b)
            });
    }
    let prep = coarse(&reg);
    let set = squeal::contact::ContactSet::new(
        &prep.model,
        &squeal::scene::Zone::Uniform,
        prep.scene.study.rotation,
    )
    .unwrap();
    let mut opts = BenchOptions::all(&reg);
    opts.vary = Vec::new();
    let mut kept = |bases: &[&str]| {
        opts.bases = bases.iter().map(|b| b.to_string()).collect();
        let stages = stages_for(&reg, &opts, &prep.model, &set).unwrap();
        assert_eq!(stages.len(), 1, "one stage for bases {bases:?}");
        stages[0]
            .stage
            .downcast_ref::<PairSolves>()
            .expect("the shared stage is the pair solves")
            .kept_friction_responses()
    };
    assert_eq!(kept(&["sharing-plain", "sharing-completing"]), set.len());
    assert_eq!(kept(&["sharing-completing", "sharing-plain"]), set.len());
    // the plain one alone adds nothing
    assert_eq!(kept(&["sharing-plain"]), 0);
}
