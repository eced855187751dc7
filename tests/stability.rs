//! Full-order complex eigen solvers on the frictional operator:
//!
//! - every registered backend gives the two-DOF Hoffmann model (read as a custom operator
//!   from files) its closed-form eigenvalues, falling back to `dense` and saying so;
//! - `arpack`, `krylov` and `dense` agree on a coarse build of the default scene;
//! - `arpack` and `krylov` agree on the default scene at mu = 0.3 and 0.7, every mode in
//!   0-10 kHz, with backward errors <= 1e-10;
//! - an exported operator (both forms) re-imported gives identical eigenvalues.

use squeal::analysis::pipeline::Prepared;
use squeal::core::operator::ComplexModes;
use squeal::core::{c64, EigenParams, FrictionalOperator, Params};
use squeal::scene::Scene;

fn solve(name: &str, op: &FrictionalOperator, mu: f64, fmax: f64) -> ComplexModes {
    let reg = squeal::registry();
    let solver = reg.eigen.create(name, &Params::new()).unwrap();
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: fmax,
        tol: 1e-12,
        ..EigenParams::default()
    };
    solver.solve_frictional(op, mu, &params).unwrap()
}

/// Same modes: equal count, frequencies to `ftol` relative, real parts to `rtol |lambda|`
/// (matched to the nearest eigenvalue: coupled pairs share a frequency).
fn agree(a: &ComplexModes, b: &ComplexModes, ftol: f64, rtol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: {} vs {} modes", a.len(), b.len());
    let mut used = vec![false; b.len()];
    for (i, la) in a.lambda.iter().enumerate() {
        let (j, _) = b
            .lambda
            .iter()
            .enumerate()
            .filter(|(j, _)| !used[*j])
            .map(|(j, lb)| (j, (la - lb).norm()))
            .min_by(|p, q| p.1.total_cmp(&q.1))
            .unwrap();
        used[j] = true;
        let lb = b.lambda[j];
        let df = (a.freq_hz[i] - b.freq_hz[j]).abs() / b.freq_hz[j];
        assert!(
            df <= ftol,
            "{what}: mode {i} at {} Hz: frequency differs by {df:e}",
            a.freq_hz[i]
        );
        let dr = (la.re - lb.re).abs() / lb.norm();
        assert!(
            dr <= rtol,
            "{what}: mode {i} at {} Hz: real part differs by {dr:e} |lambda|",
            a.freq_hz[i]
        );
    }
}

#[test]
fn hoffmann_custom_operator_through_every_backend() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("crates/squeal-io/tests/data/hoffmann");
    let op = squeal_io::read_operator_dir(&dir).unwrap();
    // closed form: m = 1, k11 = 1, k22 = 1.2, k12 = k21 = 0.1, kH = 1
    let (k11, k22, k12, k21, kh) = (1.0, 1.2, 0.1, 0.1, 1.0);
    let mu_c = ((k11 - k22) * (k11 - k22) + 4.0 * k12 * k21) / (4.0 * k21 * kh);
    approx::assert_relative_eq!(mu_c, 0.2, max_relative = 1e-14);
    let mu = 0.3;
    // lambda^2 = -s, s = (k11 + k22)/2 +- sqrt(((k11 - k22)/2)^2 + k21 (k12 - mu kH))
    let disc = c64::new(((k11 - k22) / 2.0f64).powi(2) + k21 * (k12 - mu * kh), 0.0).sqrt();
    let mut exact: Vec<c64> = [1.0, -1.0]
        .iter()
        .map(|&sg| {
            let s = c64::new((k11 + k22) / 2.0, 0.0) + disc * sg;
            c64::new(0.0, 1.0) * s.sqrt()
        })
        .collect();
    exact.sort_by(|a, b| b.re.total_cmp(&a.re));
    approx::assert_abs_diff_eq!(exact[0].re, 0.04762, epsilon = 1e-5);
    approx::assert_abs_diff_eq!(exact[0].im, 1.04989, epsilon = 1e-5);
    let names = squeal::registry().eigen.names();
    assert!(names.len() >= 3, "{names:?}");
    for name in &names {
        let m = solve(name, &op, mu, 1.0);
        assert_eq!(m.len(), 2, "{name}");
        let mut got = m.lambda.clone();
        got.sort_by(|a, b| b.re.total_cmp(&a.re));
        for (g, e) in got.iter().zip(&exact) {
            assert!((g - e).norm() <= 1e-10 * e.norm(), "{name}: {g} vs {e}");
        }
        assert!(
            m.is_unstable(0, 1e-8) != m.is_unstable(1, 1e-8),
            "{name}: one unstable mode"
        );
        if name != "dense" {
            assert!(
                m.info.notes.iter().any(|n| n.contains("dense")),
                "{name}: {:?}",
                m.info.notes
            );
        }
        // below mu_c: stable
        let s = solve(name, &op, 0.19, 1.0);
        assert!((0..s.len()).all(|i| !s.is_unstable(i, 1e-8)), "{name}");
    }
}

/// The embedded coarse rig (about 1600 DOFs).
fn coarse() -> Scene {
    Scene::builtin("pin-on-disc-coarse").unwrap()
}

#[test]
fn backends_agree_on_a_coarse_scene_and_export_round_trips() {
    let reg = squeal::registry();
    let prep = Prepared::new(&reg, coarse(), "coarse").unwrap();
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", 0.5).unwrap();
    let op = prep.operator(&eq.eq.active).unwrap();
    assert!(op.dim() <= 2000, "coarse scene has {} DOFs", op.dim());
    let fmax = 2500.0;
    let dense = solve("dense", &op, 0.5, fmax);
    assert!(dense.len() >= 5);
    for name in ["arpack", "krylov"] {
        let m = solve(name, &op, 0.5, fmax);
        agree(&m, &dense, 1e-8, 1e-6, name);
        assert!(
            m.backward_error.iter().all(|&b| b <= 1e-10),
            "{name}: {:?}",
            m.backward_error
        );
    }
    // export both forms, read each back: the same eigenvalues
    let dir = std::env::temp_dir().join(format!("squeal-export-{}", std::process::id()));
    squeal_io::write_operator_dir(
        &dir,
        &op,
        &squeal_io::OperatorMeta {
            scene: "coarse".into(),
            mu: 0.5,
            active_pairs: eq.eq.active.iter().filter(|&&a| a).count(),
            source: "test".into(),
        },
    )
    .unwrap();
    squeal::contact::files::write_full_form(
        &dir,
        &prep.model.m,
        None,
        &prep.model.k,
        &prep.set,
        &eq.eq.active,
    )
    .unwrap();
    let constrained = squeal_io::read_operator_dir(&dir).unwrap();
    let full = squeal::contact::files::read_full_form(&dir).unwrap();
    let reference = solve("arpack", &op, 0.5, fmax);
    for (what, back) in [("constrained form", constrained), ("full form", full)] {
        let again = solve("arpack", &back, 0.5, fmax);
        assert_eq!(again.len(), reference.len(), "{what}");
        for (a, b) in again.lambda.iter().zip(&reference.lambda) {
            assert!((a - b).norm() <= 1e-12 * b.norm(), "{what}: {a} vs {b}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The default rig on the previous size rule (10 per wavelength, 2 layers, grading 1.5:
/// about 60k DOFs, on the low-rank path): the default rule's 173k DOFs would cost this
/// test about 10 minutes of CI's 30 on two cores, and the solvers' agreement does not
/// depend on the mesh density.
#[test]
fn arpack_and_krylov_agree_on_the_default_scene() {
    let reg = squeal::registry();
    let mut scene = Scene::builtin("pin-on-disc").unwrap();
    (
        scene.mesh.elements_per_wavelength,
        scene.mesh.min_layers,
        scene.mesh.grading_ratio,
    ) = (10.0, 2, 1.5);
    scene.mesh.plate_elements_per_wavelength = None;
    let prep = Prepared::new(&reg, scene, "default, previous rule").unwrap();
    for mu in [0.3, 0.7] {
        let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu).unwrap();
        let op = prep.operator(&eq.eq.active).unwrap();
        let a = solve("arpack", &op, mu, 10_000.0);
        let k = solve("krylov", &op, mu, 10_000.0);
        assert!(a.len() >= 30, "mu {mu}: {} modes", a.len());
        agree(&a, &k, 1e-8, 1e-6, &format!("mu {mu}"));
        for m in [&a, &k] {
            let worst = m.backward_error.iter().fold(0.0f64, |x, &b| x.max(b));
            assert!(worst <= 1e-10, "mu {mu}: backward error {worst:e}");
        }
    }
}
