//! The `pod` basis against full-order `arpack` on the embedded coarse rig
//! (`pin-on-disc-coarse`, about 1800 constrained DOFs, band 0-6 kHz), on one contact set
//! (the equilibrium at mu = 1.2, where a flutter pair near 2.3 kHz is unstable) for
//! every mu, snapshots at mu = 0, 0.6 and 1.2:
//!
//! - at the snapshot friction coefficients the reduced modes reproduce every full-order
//!   mode of the band to tight relative error (the snapshots are in the basis);
//! - between snapshots they interpolate: every mode found, errors far below those of a
//!   basis built from a single snapshot of the same operator;
//! - the basis is fixed in mu, `M_c`-orthonormal, its build cost (snapshot solves) is
//!   reported apart from the per-mu cost, and `max_size` caps it;
//! - every reduced mode carries a forward error estimate (`error_bound`, from the reduced
//!   left eigenvectors), and the true error stays below it.
//!
//! A table is printed with `--nocapture`.

use squeal_analysis::pipeline::Prepared;
use squeal_core::operator::ComplexModes;
use squeal_core::reduction::m_orthonormality_error;
use squeal_core::{
    Basis, BasisRequest, EigenParams, EigenSolver, FrictionalOperator, Params, ReducedOperator,
    Registry,
};
use squeal_scene::Scene;

const FMAX: f64 = 6000.0;

fn registry() -> Registry {
    let mut reg = Registry::new();
    squeal_materials::register(&mut reg);
    squeal_contact_laws::register(&mut reg);
    squeal_equilibrium_lcp::register(&mut reg);
    squeal_eigen_dense::register(&mut reg);
    squeal_eigen_arpack::register(&mut reg);
    squeal_basis_pod::register(&mut reg);
    reg
}

fn params(fmax: f64) -> EigenParams {
    EigenParams {
        fmin_hz: 0.0,
        fmax_hz: fmax,
        tol: 1e-12,
        ..EigenParams::default()
    }
}

fn operator(reg: &Registry) -> FrictionalOperator {
    let prep = Prepared::new(reg, Scene::builtin("pin-on-disc-coarse").unwrap(), "coarse").unwrap();
    let eq = prep.equilibrium(reg, "lcp", "lagrange", 1.2).unwrap();
    prep.operator(&eq.eq.active).unwrap()
}

fn build(reg: &Registry, opts: Params, op: &FrictionalOperator, arpack: &dyn EigenSolver) -> Basis {
    let dense = reg.eigen.create("dense", &Params::new()).unwrap();
    let ep = params(FMAX);
    let pod = reg.bases.create("pod", &opts).unwrap();
    squeal_core::contact::build_basis(
        pod.as_ref(),
        &BasisRequest {
            op,
            mu: 1.2,
            band_hz: (0.0, FMAX),
            modal: arpack,
            reduced: dense.as_ref(),
            params: &ep,
            stage: None,
            seed: None,
        },
    )
    .unwrap()
}

/// Largest relative eigenvalue error `|lambda_r - lambda| / |lambda|` over the reference
/// modes (each matched to its nearest unused reduced mode), the number of reference
/// modes without a partner within 1 %, and the number of matched modes whose error
/// exceeds their own `error_bound` (plus 1e-14 for round-off).
fn errors(reference: &ComplexModes, reduced: &ComplexModes) -> (f64, usize, usize) {
    let mut used = vec![false; reduced.len()];
    let (mut worst, mut missing, mut above) = (0.0f64, 0, 0);
    for i in 0..reference.len() {
        let l = reference.lambda[i];
        let best = (0..reduced.len())
            .filter(|&j| !used[j])
            .map(|j| (j, (reduced.lambda[j] - l).norm() / l.norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some((j, e)) if e <= 1e-2 => {
                used[j] = true;
                worst = worst.max(e);
                above += usize::from(e > reduced.error_bound[j] + 1e-14);
            }
            _ => missing += 1,
        }
    }
    (worst, missing, above)
}

#[test]
fn pod_reproduces_snapshots_and_interpolates_on_the_coarse_rig() {
    let reg = registry();
    let op = operator(&reg);
    let arpack = reg.eigen.create("arpack", &Params::new()).unwrap();
    let dense = reg.eigen.create("dense", &Params::new()).unwrap();
    let (k, v) = Params::parse_kv("snapshots=0,0.6,1.2").unwrap();
    let basis = build(
        &reg,
        Params::new().with(&k, v).with_num("svd_tol", 1e-12),
        &op,
        arpack.as_ref(),
    );
    assert!(basis.mu.is_none(), "pod is fixed in mu");
    assert!(m_orthonormality_error(op.mc.as_ref(), basis.v.as_ref()) < 1e-8);
    assert!(basis.time_s > 0.0);
    assert!(
        basis
            .notes
            .iter()
            .filter(|n| n.contains("snapshot mu"))
            .count()
            == 3,
        "{:?}",
        basis.notes
    );
    // a basis from the mu = 0.6 snapshot alone, for comparison
    let single = build(
        &reg,
        Params::new()
            .with_num("snapshots", 0.6)
            .with_num("svd_tol", 1e-12),
        &op,
        arpack.as_ref(),
    );
    println!(
        "n_c = {}, pod basis {} vectors (single snapshot: {}), build {:.3} s\n{}",
        op.dim(),
        basis.len(),
        single.len(),
        basis.time_s,
        basis.notes.join("\n")
    );
    let red = ReducedOperator::new(&op, basis).unwrap();
    let red1 = ReducedOperator::new(&op, single).unwrap();
    let mut unstable = 0;
    println!(
        "{:>5} {:>5} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9}",
        "mu", "modes", "pod err", "single err", "max eta", "max bound", "full s", "per-mu s"
    );
    for mu in [0.0, 0.3, 0.6, 0.9, 1.2] {
        let t = std::time::Instant::now();
        let reference = arpack.solve_frictional(&op, mu, &params(FMAX)).unwrap();
        let full_s = t.elapsed().as_secs_f64();
        assert!(reference.len() >= 15, "mu {mu}: {} modes", reference.len());
        unstable += (0..reference.len())
            .filter(|&i| reference.is_unstable(i, 1e-8))
            .count();
        let solved = red
            .solve(&op, mu, dense.as_ref(), &params(FMAX * 1.01))
            .unwrap();
        let (err, missing, above) = errors(&reference, &solved.modes);
        let (err1, missing1, above1) = errors(
            &reference,
            &red1
                .solve(&op, mu, dense.as_ref(), &params(FMAX * 1.01))
                .unwrap()
                .modes,
        );
        let eta = solved
            .modes
            .backward_error
            .iter()
            .fold(0.0f64, |a, &b| a.max(b));
        let per_mu = solved.solve_time_s + solved.expansion_time_s;
        let bound = solved
            .modes
            .error_bound
            .iter()
            .fold(0.0f64, |a, &b| a.max(b));
        assert!(
            solved.modes.error_bound.iter().all(|b| b.is_finite()),
            "mu {mu}: {:?}",
            solved.modes.error_bound
        );
        println!(
            "{mu:>5} {:>5} {err:>10.2e} {err1:>10.2e} {eta:>10.2e} {bound:>10.2e} {full_s:>9.3} \
             {per_mu:>9.4}",
            reference.len()
        );
        // the forward error estimate bounds the true error of every mode (to round-off),
        // for the good basis and the poor one alike
        assert_eq!(
            (above, above1),
            (0, 0),
            "mu {mu}: errors above their error_bound"
        );
        assert_eq!(missing, 0, "mu {mu}: pod misses modes");
        // the build cost is reported apart from the per-mu cost
        assert!(solved.basis_time_s > per_mu, "mu {mu}");
        if [0.0, 0.6, 1.2].contains(&mu) {
            assert!(err <= 1e-10, "mu {mu}: pod error {err:e} at a snapshot");
        } else {
            assert!(err <= 1e-5, "mu {mu}: pod error {err:e} between snapshots");
            assert!(
                missing1 > 0 || err < 0.1 * err1,
                "mu {mu}: pod {err:e} vs single snapshot {err1:e}"
            );
        }
    }
    assert!(
        unstable > 0,
        "no unstable mode at any mu: the test proves little"
    );
}

#[test]
fn pod_max_size_caps_the_basis() {
    let reg = registry();
    let op = operator(&reg);
    let arpack = reg.eigen.create("arpack", &Params::new()).unwrap();
    let capped = build(
        &reg,
        Params::new().with_num("max_size", 12.0),
        &op,
        arpack.as_ref(),
    );
    assert_eq!(capped.len(), 12);
    assert!(
        capped.notes[0].contains("capped at 12"),
        "{:?}",
        capped.notes
    );
    assert!(capped.dropped > 0);
}
