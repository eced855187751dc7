//! Damping of the stability analysis (`[damping]` of a scene), on the coarse rig:
//!
//! - Rayleigh damping without friction is proportional damping: every mode keeps its
//!   undamped `omega = |lambda|` and gets `Re(lambda) = -(alpha + beta omega^2) / 2`;
//! - tangential contact dashpots are dissipative (no mode grows without friction), leave
//!   rigid motions undamped and sum to the coefficient times the face area;
//! - with friction, `arpack` (companion-form shift-invert), `dense` and the `enriched`
//!   basis agree on the damped operator, heavily damped roots (damping ratio above `1/sqrt 2`) dropped by
//!   both.

use squeal::analysis::pipeline::{damped_operator, Prepared};
use squeal::core::operator::ComplexModes;
use squeal::core::{EigenParams, FrictionalOperator, Params};
use squeal::scene::{Damping, Scene};

const FMAX: f64 = 2500.0;

fn solve(name: &str, op: &FrictionalOperator, mu: f64) -> ComplexModes {
    let solver = squeal::registry()
        .eigen
        .create(name, &Params::new())
        .unwrap();
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: FMAX,
        tol: 1e-12,
        ..EigenParams::default()
    };
    solver.solve_frictional(op, mu, &params).unwrap()
}

fn coarse(damping: Damping) -> (Prepared, Vec<bool>) {
    let reg = squeal::registry();
    let mut scene = Scene::builtin("pin-on-disc-coarse").unwrap();
    scene.damping = damping;
    let prep = Prepared::new(&reg, scene, "coarse").unwrap();
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", 0.5).unwrap();
    let active = eq.eq.active.clone();
    (prep, active)
}

#[test]
fn rayleigh_damping_is_proportional_damping_without_friction() {
    let (alpha, beta) = (40.0, 2e-7);
    let (prep, active) = coarse(Damping {
        rayleigh_alpha_per_s: Some(alpha),
        rayleigh_beta_s: Some(beta),
        ..Damping::default()
    });
    let op = prep.operator(&active).unwrap();
    assert!(op.cc.is_some() && op.fc.is_some());
    let undamped = damped_operator(&prep.model, &Damping::default(), &prep.set, &active).unwrap();
    assert!(undamped.cc.is_none());
    let free = solve("dense", &undamped, 0.0);
    // (`dense` on the damped companion form is checked against `arpack` below)
    for name in ["arpack"] {
        let m = solve(name, &op, 0.0);
        assert_eq!(
            m.len(),
            free.len(),
            "{name}: damping changed the mode count"
        );
        assert!(m.len() >= 5);
        for (i, l) in m.lambda.iter().enumerate() {
            let w = l.norm();
            let w0 = 2.0 * std::f64::consts::PI * free.freq_hz[i];
            assert!(
                (w - w0).abs() <= 1e-8 * w0,
                "{name}: mode {i}: |lambda| {w} vs omega {w0}"
            );
            let re = -(alpha + beta * w * w) / 2.0;
            assert!(
                (l.re - re).abs() <= 1e-8 * w,
                "{name}: mode {i}: Re(lambda) = {} vs {re}",
                l.re
            );
            assert!(
                m.backward_error[i] <= 1e-10,
                "{name}: {}",
                m.backward_error[i]
            );
        }
    }
}

#[test]
fn contact_dashpots_dissipate_and_leave_rigid_motion_free() {
    let ct = 5e6;
    let damping = Damping {
        contact_tangential_n_s_per_m3: Some(ct),
        ..Damping::default()
    };
    let (prep, active) = coarse(damping.clone());
    let c = squeal::contact::damping_matrix(&prep.model, &prep.set, &active, &damping)
        .unwrap()
        .unwrap();
    // a common translation of pin and disc nodes stretches no dashpot
    let n = c.nrows();
    let mut u = vec![0.0; n];
    for i in 0..prep.set.len() {
        for a in 0..2 {
            u[prep.set.pin_dofs[i][a]] = 1.0 + a as f64;
            u[prep.set.disc_dofs[i][a]] = 1.0 + a as f64;
        }
    }
    let mut cu = vec![0.0; n];
    squeal::core::linalg::spmv(c.as_ref(), &u, &mut cu);
    assert!(
        cu.iter().all(|v| v.abs() <= 1e-9 * ct),
        "C_t moves rigid translations"
    );
    // the dashpots of the closed pairs sum to the coefficient times their area
    let grid = prep.model.contact.as_ref().unwrap();
    let areas = grid.tributary_areas();
    let closed: f64 = (0..prep.set.len())
        .filter(|&i| active[i])
        .map(|i| areas[prep.set.grid_index[i]])
        .sum();
    let diag: f64 = (0..prep.set.len())
        .filter(|&i| active[i])
        .map(|i| {
            let p = prep.set.pin_dofs[i][0];
            let col = c.as_ref();
            col.row_idx_of_col(p)
                .zip(col.val_of_col(p))
                .find(|(r, _)| *r == p)
                .map_or(0.0, |(_, v)| *v)
        })
        .sum();
    assert!(closed > 0.0);
    approx::assert_relative_eq!(diag, ct * closed, max_relative = 1e-12);
    // no mode grows without friction, and the dashpots damp some of them
    let op = prep.operator(&active).unwrap();
    let m = solve("arpack", &op, 0.0);
    assert!(m.len() >= 5);
    let mut damped = 0;
    for l in &m.lambda {
        assert!(l.re <= 1e-10 * l.norm(), "mode grows without friction: {l}");
        if l.re < -1e-4 * l.norm() {
            damped += 1;
        }
    }
    assert!(
        damped >= 1,
        "no mode is damped by the contact: {:?}",
        m.lambda
    );
}

#[test]
fn damped_frictional_operator_arpack_matches_dense() {
    let (prep, active) = coarse(Damping {
        rayleigh_ratio: Some(0.02),
        rayleigh_freqs_hz: Some([500.0, 2500.0]),
        contact_tangential_n_s_per_m3: Some(1e6),
        ..Damping::default()
    });
    let op = prep.operator(&active).unwrap();
    let (dense, arpack) = (solve("dense", &op, 0.5), solve("arpack", &op, 0.5));
    assert_eq!(dense.len(), arpack.len());
    assert!(dense.len() >= 5);
    for (a, d) in arpack.lambda.iter().zip(&dense.lambda) {
        assert!((a - d).norm() <= 1e-8 * d.norm(), "{a} vs {d}");
    }
    assert!(arpack.backward_error.iter().all(|&b| b <= 1e-10));
    // a reduction basis carries the damping through the projection
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: FMAX,
        tol: 1e-12,
        ..EigenParams::default()
    };
    let mut method = squeal::analysis::pipeline::Method::new(
        &squeal::registry(),
        "enriched",
        &Params::new(),
        "dense",
        "arpack",
        params,
    )
    .unwrap();
    let (reduced, size, _) = method.solve(&op, 0.5, true).unwrap();
    assert!(size > 0 && size < op.dim());
    assert_eq!(reduced.len(), dense.len());
    // the basis has no static responses to the dashpot forces, so with these strong
    // contact dashpots it is off by up to 4.5e-3 |lambda| (measured; 7.4e-2 ignoring the damping
    // altogether): the damping must be carried by the projection
    let worst = |modes: &ComplexModes| {
        modes
            .lambda
            .iter()
            .zip(&dense.lambda)
            .map(|(r, d)| (r - d).norm() / d.norm())
            .fold(0.0f64, f64::max)
    };
    let err = worst(&reduced);
    let undamped = damped_operator(&prep.model, &Damping::default(), &prep.set, &active).unwrap();
    let (ignored, _, _) = method.solve(&undamped, 0.5, true).unwrap();
    assert_eq!(ignored.len(), dense.len());
    let err_ignored = worst(&ignored);
    println!("enriched: {err:.1e} |lambda| with the damping projected, {err_ignored:.1e} without");
    assert!(err <= 1e-2, "enriched off by {err:.2e} |lambda|");
    assert!(
        err <= 0.25 * err_ignored,
        "{err:.2e} vs {err_ignored:.2e} without damping"
    );
}
