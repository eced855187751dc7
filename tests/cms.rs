//! The `cms` basis (free-interface modal synthesis with residual flexibility, built once
//! per model and reused for every contact set) against full-order `arpack` on the coarse
//! rig: the equilibrium contact sets of a mu sweep and imposed rectangular zones, the raw
//! synthesis before the Ritz step, and the error without a synthesis.

use squeal::analysis::pipeline::{damped_operator, Method, Prepared};
use squeal::contact::ContactSet;
use squeal::core::operator::ComplexModes;
use squeal::core::{EigenParams, FrictionalOperator, ParamValue, Params, Registry};
use squeal::scene::{Damping, Scene, Zone};
use squeal_basis_cms::FreeInterface;

/// The free-interface synthesis in the model stage of `cms`.
fn synthesis(stage: &squeal::core::ModelStage) -> &FreeInterface {
    stage
        .downcast_ref::<FreeInterface>()
        .expect("the model stage of cms is its free-interface synthesis")
}

const FMAX: f64 = 10_000.0;

fn setup() -> (Registry, Prepared) {
    let reg = squeal::registry();
    let scene = Scene::builtin("pin-on-disc-coarse").unwrap();
    let prep = Prepared::new(&reg, scene, "pin-on-disc-coarse").unwrap();
    (reg, prep)
}

fn params() -> EigenParams {
    EigenParams {
        fmin_hz: 0.0,
        fmax_hz: FMAX,
        tol: 1e-12,
        ..EigenParams::default()
    }
}

fn full(reg: &Registry, op: &FrictionalOperator, mu: f64) -> ComplexModes {
    let mut m = Method::new(reg, "none", &Params::new(), "arpack", "arpack", params()).unwrap();
    m.solve(op, mu, true).unwrap().0
}

/// Largest relative frequency error and DvR error of `got` against `reference`, matching
/// each reference mode to the nearest eigenvalue; both must have the same mode count.
fn errors(reference: &ComplexModes, got: &ComplexModes) -> (f64, f64, f64) {
    assert_eq!(
        reference.len(),
        got.len(),
        "mode counts: reference {:?}, got {:?}",
        reference.freq_hz,
        got.freq_hz
    );
    let (mut df, mut ddvr, mut eta) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..reference.len() {
        let j = (0..got.len())
            .min_by(|&a, &b| {
                (got.lambda[a] - reference.lambda[i])
                    .norm()
                    .total_cmp(&(got.lambda[b] - reference.lambda[i]).norm())
            })
            .unwrap();
        df = df.max((got.freq_hz[j] - reference.freq_hz[i]).abs() / reference.freq_hz[i]);
        ddvr = ddvr.max((got.dvr[j] - reference.dvr[i]).abs());
        eta = eta.max(got.backward_error[j]);
    }
    (df, ddvr, eta)
}

#[test]
fn cms_matches_full_order_on_equilibrium_sets_and_zones() {
    let (reg, prep) = setup();
    let mut cms = Method::new(&reg, "cms", &Params::new(), "dense", "arpack", params()).unwrap();
    let stage = cms
        .prepare_stage(&prep.model, &prep.set, None)
        .unwrap()
        .expect("cms has a model stage");
    let fi = synthesis(&stage);
    assert_eq!(fi.pairs(), prep.set.len());
    // free modes up to 3 x the band top (the default modes_factor)
    assert!(fi.cutoff_hz <= 3.0 * FMAX && fi.cutoff_hz > 2.0 * FMAX && fi.modes() > 10);
    let mut unstable_seen = 0;
    let mut check = |op: &FrictionalOperator, mu: f64, what: &str| {
        let reference = full(&reg, op, mu);
        let (got, size, _) = cms.solve(op, mu, true).unwrap();
        let (df, ddvr, eta) = errors(&reference, &got);
        let unstable = (0..reference.len())
            .filter(|&i| reference.is_unstable(i, 1e-8))
            .count();
        unstable_seen += unstable;
        println!(
            "{what} mu {mu}: {} modes ({unstable} unstable), basis {size}, df/f {df:.1e}, \
             dDvR {ddvr:.1e}, worst backward error {eta:.1e}",
            reference.len()
        );
        assert!(df <= 2e-4, "{what} mu {mu}: df/f {df:e}");
        assert!(ddvr <= 1e-4, "{what} mu {mu}: dDvR {ddvr:e}");
        assert!(eta <= 1e-6, "{what} mu {mu}: backward error {eta:e}");
    };
    for mu in [0.3, 0.7, 1.0] {
        let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu).unwrap();
        let op = prep.operator(&eq.eq.active).unwrap();
        check(&op, mu, "equilibrium");
    }
    let zones = [(0.010, 0.003, 0.010, 0.014), (0.002, 0.002, 0.008, 0.008)];
    for (x0_m, y0_m, a_m, b_m) in zones {
        let zone = Zone::Rectangle {
            x0_m,
            y0_m,
            a_m,
            b_m,
        };
        let set = ContactSet::new(&prep.model, &zone, prep.scene.study.rotation).unwrap();
        assert!(set.len() < prep.set.len());
        let op = damped_operator(
            &prep.model,
            &Damping::default(),
            &set,
            &vec![true; set.len()],
        )
        .unwrap();
        check(&op, 0.43, "zone");
    }
    assert!(
        unstable_seen > 0,
        "no unstable mode anywhere: the test would be weak"
    );
}

#[test]
fn the_raw_synthesis_is_close_before_the_ritz_step() {
    let (reg, prep) = setup();
    let mut cms = Method::new(&reg, "cms", &Params::new(), "dense", "arpack", params()).unwrap();
    let stage = cms
        .prepare_stage(&prep.model, &prep.set, None)
        .unwrap()
        .unwrap();
    let fi = synthesis(&stage);
    let mu = 0.7;
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu).unwrap();
    let op = prep.operator(&eq.eq.active).unwrap();
    let reference = full(&reg, &op, mu);
    let active = fi.active_in(&op).unwrap();
    assert_eq!(active.len(), eq.eq.active.iter().filter(|&&a| a).count());
    let syn = fi.synthesize(&active, mu).unwrap();
    let mut worst = 0.0f64;
    for i in 0..reference.len() {
        let nearest = (0..syn.s.len())
            .map(|k| (syn.lambda(k) - reference.lambda[i]).norm())
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(nearest / reference.lambda[i].norm());
    }
    println!(
        "raw synthesis: worst |dlambda|/|lambda| {worst:.2e} over {} modes",
        reference.len()
    );
    // the static residual flexibility is an approximation, but a close one
    assert!(worst > 0.0 && worst < 2e-2, "{worst:e}");
}

#[test]
fn cms_without_a_synthesis_is_a_clear_error() {
    let (reg, prep) = setup();
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", 0.3).unwrap();
    let op = prep.operator(&eq.eq.active).unwrap();
    let mut cms = Method::new(&reg, "cms", &Params::new(), "dense", "arpack", params()).unwrap();
    let err = cms.solve(&op, 0.3, true).unwrap_err().to_string();
    assert!(err.contains("free-interface synthesis"), "{err}");
    assert!(reg
        .bases
        .create(
            "cms",
            &Params::parse_kv("modes_factor=0.5")
                .map(|(k, v)| {
                    let mut p = Params::new();
                    p.0.insert(k, v);
                    p
                })
                .unwrap()
        )
        .is_err());
}

#[test]
fn the_second_order_directions_sharpen_the_ritz_step() {
    let (reg, prep) = setup();
    let mu = 0.7;
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu).unwrap();
    let op = prep.operator(&eq.eq.active).unwrap();
    let reference = full(&reg, &op, mu);
    let run = |second_order: f64| {
        let mut p = Params::new();
        let (k, v) = Params::parse_kv(&format!("second_order={second_order}")).unwrap();
        p.0.insert(k, v);
        let mut m = Method::new(&reg, "cms", &p, "dense", "arpack", params()).unwrap();
        m.prepare_stage(&prep.model, &prep.set, None).unwrap();
        let (got, size, _) = m.solve(&op, mu, true).unwrap();
        let (df, ddvr, _) = errors(&reference, &got);
        (df, ddvr, size)
    };
    let (df1, ddvr1, n1) = run(0.0);
    let (df2, ddvr2, n2) = run(1.0);
    println!("first order: df/f {df1:.1e} dDvR {ddvr1:.1e} ({n1} vectors); second order: df/f {df2:.1e} dDvR {ddvr2:.1e} ({n2} vectors)");
    assert!(n2 > n1);
    assert!(df2 < 0.5 * df1, "df/f {df2:e} vs {df1:e}");
    assert!(ddvr2 < ddvr1, "dDvR {ddvr2:e} vs {ddvr1:e}");
}

#[test]
fn a_prepared_model_computes_its_free_modes_and_synthesis_once() {
    let (reg, prep) = setup();
    let arpack = reg.eigen.create("arpack", &Params::new()).unwrap();
    // the highest cutoff first: a lower one is its leading part, bit for bit
    let high = prep.normal_modes(arpack.as_ref(), 30_000.0, 1e-10).unwrap();
    let low = prep.normal_modes(arpack.as_ref(), 12_000.0, 1e-10).unwrap();
    assert!(!low.freq_hz.is_empty() && low.freq_hz.len() < high.freq_hz.len());
    assert!(low.freq_hz.iter().all(|&f| f <= 12_000.0));
    assert!(high.freq_hz[low.freq_hz.len()] > 12_000.0);
    assert_eq!(low.freq_hz[..], high.freq_hz[..low.freq_hz.len()]);
    assert_eq!(
        low.vectors.as_ref(),
        high.vectors.as_ref().subcols(0, low.freq_hz.len())
    );
    // two methods on the same model share one synthesis ...
    let cms = || Method::new(&reg, "cms", &Params::new(), "dense", "arpack", params()).unwrap();
    let (mut a, mut b) = (cms(), cms());
    let stage_a = a.prepare_stage_on(&prep).unwrap().unwrap();
    let stage_b = b.prepare_stage_on(&prep).unwrap().unwrap();
    assert!(std::sync::Arc::ptr_eq(&stage_a, &stage_b));
    let fa = synthesis(&stage_a);
    // ... which, built on the condensation's factor of K, synthesizes what one built
    // from scratch does
    let fresh_stage = cms()
        .prepare_stage(&prep.model, &prep.set, None)
        .unwrap()
        .unwrap();
    let fresh = synthesis(&fresh_stage);
    assert_eq!(fa.modes(), fresh.modes());
    let all: Vec<usize> = (0..fa.pairs()).collect();
    let mut sa: Vec<f64> = fa
        .synthesize(&all, 0.4)
        .unwrap()
        .s
        .iter()
        .map(|s| s.re)
        .collect();
    let mut sf: Vec<f64> = fresh
        .synthesize(&all, 0.4)
        .unwrap()
        .s
        .iter()
        .map(|s| s.re)
        .collect();
    sa.sort_by(f64::total_cmp);
    sf.sort_by(f64::total_cmp);
    for (x, y) in sa.iter().zip(&sf) {
        assert!((x - y).abs() <= 1e-9 * y.abs().max(1.0), "{x} vs {y}");
    }
}

#[test]
fn cms_projected_on_the_pairs_matches_the_explicit_projection() {
    let (reg, prep) = setup();
    let method = |projection: &str| {
        let p = Params::new().with("projection", ParamValue::Str(projection.into()));
        let mut m = Method::new(&reg, "cms", &p, "dense", "arpack", params()).unwrap();
        m.prepare_stage(&prep.model, &prep.set, None).unwrap();
        m
    };
    let (mut explicit, mut on_pairs) = (method("full"), method("pairs"));
    let mut compared = 0;
    for mu in [0.0, 0.3, 0.7, 1.0] {
        let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu).unwrap();
        let op = prep.operator(&eq.eq.active).unwrap();
        let (a, na, _) = explicit.solve(&op, mu, true).unwrap();
        let (b, nb, _) = on_pairs.solve(&op, mu, true).unwrap();
        let reference = full(&reg, &op, mu);
        let (df, ddvr, eta) = errors(&reference, &b);
        let (dfa, ddvra, _) = errors(&reference, &a);
        println!(
            "mu {mu}: explicit {na} vectors df/f {dfa:.1e} dDvR {ddvra:.1e}; on the pairs \
             {nb} vectors df/f {df:.1e} dDvR {ddvr:.1e}, worst backward error {eta:.1e}"
        );
        // the same subspace: the same Ritz values, to far below the basis's own error
        assert_eq!(
            a.len(),
            b.len(),
            "mu {mu}: {:?} vs {:?}",
            a.freq_hz,
            b.freq_hz
        );
        for i in 0..a.len() {
            let (j, d) = (0..b.len())
                .map(|j| (j, (b.lambda[j] - a.lambda[i]).norm()))
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .unwrap();
            assert!(
                d <= 1e-7 * a.lambda[i].norm(),
                "mu {mu}: {} vs {}",
                a.lambda[i],
                b.lambda[j]
            );
            compared += 1;
        }
        assert!(df <= 2e-4 && ddvr <= 1e-4 && eta <= 1e-6, "mu {mu}");
        assert!(b
            .info
            .notes
            .iter()
            .any(|n| n.contains("projected on the pairs")));
    }
    assert!(compared > 10);
}

#[test]
fn cms_projection_option_is_checked() {
    let reg = squeal::registry();
    let p = Params::new().with("projection", ParamValue::Str("sideways".into()));
    let err = Method::new(&reg, "cms", &p, "dense", "arpack", params())
        .err()
        .expect("an unknown projection is refused")
        .to_string();
    assert!(err.contains("projection") && err.contains("pairs"), "{err}");
}

#[test]
fn a_damped_operator_is_projected_the_full_way_under_projection_pairs() {
    let (reg, prep) = setup();
    let mu = 0.5;
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu).unwrap();
    let damping = Damping {
        rayleigh_alpha_per_s: Some(20.0),
        rayleigh_beta_s: Some(1e-7),
        ..Damping::default()
    };
    let op = damped_operator(&prep.model, &damping, &prep.set, &eq.eq.active).unwrap();
    assert!(op.cc.is_some());
    let run = |projection: &str| {
        let p = Params::new().with("projection", ParamValue::Str(projection.into()));
        let mut m = Method::new(&reg, "cms", &p, "dense", "arpack", params()).unwrap();
        m.prepare_stage(&prep.model, &prep.set, None).unwrap();
        m.solve(&op, mu, true).unwrap().0
    };
    let (full, pairs) = (run("full"), run("pairs"));
    assert!(!pairs
        .info
        .notes
        .iter()
        .any(|n| n.contains("projected on the pairs")));
    assert_eq!(full.len(), pairs.len());
    // the same basis but for round-off: the `pairs` stage solves the static responses per
    // case where the `full` one stores them, and the orthonormalization's rank cut may then
    // keep or drop a nearly dependent direction (up to 4e-8 relative here, on the modes
    // above the band); a damped operator projected on the pairs, its damping lost, would
    // move the real parts by their whole size
    for (a, b) in full.lambda.iter().zip(&pairs.lambda) {
        assert!((a - b).norm() <= 1e-6 * a.norm(), "{a} vs {b}");
        assert!((a.re - b.re).abs() <= 1e-3 * a.re.abs(), "{a} vs {b}");
    }
    assert!(pairs.lambda.iter().any(|l| l.re < 0.0), "no damped mode");
}
