//! The sliding equilibrium on the embedded default scene: solver agreement, load,
//! directions, trend, penalty limit and bad input.

use squeal_contact::{problem, reference_load, solve_on, ContactSet, LoadedEquilibrium};
use squeal_contact_laws::{Lagrange, Penalty};
use squeal_core::contact::{Condensation, ContactProblem};
use squeal_core::{ContactLaw, EquilibriumSolver, Registry};
use squeal_equilibrium_lcp::LcpSolver;
use squeal_equilibrium_lorang::LorangSolver;
use squeal_scene::{build, BodyKind, Load, Model, Scene, Zone};
use std::sync::OnceLock;

struct Fixture {
    scene: Scene,
    model: Model,
    set: ContactSet,
    f: Vec<f64>,
    g0: Vec<f64>,
    cond: Condensation,
}

fn registry() -> Registry {
    let mut r = Registry::new();
    squeal_materials::register(&mut r);
    r
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let scene = Scene::builtin("pin-on-disc").unwrap();
        let model = build(&scene, BodyKind::All, &registry(), "builtin").unwrap();
        let set = ContactSet::new(&model, &Zone::Uniform, 1.0).unwrap();
        let (f, g0) = reference_load(&model, &set);
        let cond = Condensation::new(&problem(&model, &set, &f, &g0)).unwrap();
        Fixture {
            scene,
            model,
            set,
            f,
            g0,
            cond,
        }
    })
}

fn solve(solver: &dyn EquilibriumSolver, law: &dyn ContactLaw, mu: f64) -> LoadedEquilibrium {
    let fx = fixture();
    let prob = problem(&fx.model, &fx.set, &fx.f, &fx.g0);
    solve_on(&fx.cond, &prob, &fx.set, &fx.scene.load, solver, law, mu).unwrap()
}

const MUS: [f64; 5] = [0.0, 0.2, 0.4, 0.6, 0.8];

#[test]
fn lorang_and_lcp_agree_pair_by_pair() {
    for mu in MUS {
        let a = solve(&LorangSolver::default(), &Lagrange, mu);
        let b = solve(&LcpSolver::default(), &Lagrange, mu);
        let total = b.total_normal_force_n;
        let worst =
            a.eq.rn
                .iter()
                .zip(&b.eq.rn)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(worst <= 1e-8 * total, "mu {mu}: max |dRn| {worst:e} N");
        assert_eq!(a.eq.active, b.eq.active, "mu {mu}: active sets differ");
        for e in [&a, &b] {
            assert!(
                e.eq.equilibrium_residual <= 1e-10,
                "mu {mu}: {}",
                e.eq.equilibrium_residual
            );
            assert!(
                e.eq.complementarity_residual <= 1e-9,
                "mu {mu}: {}",
                e.eq.complementarity_residual
            );
        }
    }
}

#[test]
fn target_force_is_met_and_sliding_is_full() {
    for mu in MUS {
        let e = solve(&LcpSolver::default(), &Lagrange, mu);
        approx::assert_relative_eq!(e.total_normal_force_n, 200.0, max_relative = 1e-3);
        approx::assert_relative_eq!(
            e.total_tangential_force_n,
            mu * e.total_normal_force_n,
            max_relative = 1e-12
        );
        // the resultant is nearly mu Fn (directions vary a little across the face)
        let res = e.tangential_resultant_n[0].hypot(e.tangential_resultant_n[1]);
        assert!(res <= mu * 200.0 * (1.0 + 1e-3) && res >= mu * 200.0 * 0.99);
        assert!(e.eq.rn.iter().all(|&r| r >= 0.0));
    }
    // an imposed displacement instead: the force is linear in it
    let fx = fixture();
    let prob = problem(&fx.model, &fx.set, &fx.f, &fx.g0);
    let d = 10e-6;
    let load = Load {
        normal_force_n: None,
        disc_displacement_m: Some(d),
    };
    let a = solve_on(
        &fx.cond,
        &prob,
        &fx.set,
        &load,
        &LcpSolver::default(),
        &Lagrange,
        0.3,
    )
    .unwrap();
    let load2 = Load {
        normal_force_n: None,
        disc_displacement_m: Some(2.0 * d),
    };
    let b = solve_on(
        &fx.cond,
        &prob,
        &fx.set,
        &load2,
        &LcpSolver::default(),
        &Lagrange,
        0.3,
    )
    .unwrap();
    approx::assert_relative_eq!(
        b.total_normal_force_n,
        2.0 * a.total_normal_force_n,
        max_relative = 1e-12
    );
    approx::assert_relative_eq!(a.displacement_m, d, max_relative = 1e-14);
}

#[test]
fn friction_follows_the_disc_velocity_and_rotation_reversal_is_minus_mu() {
    let fx = fixture();
    // Pt: +e_i on the pin node, e_i the disc surface velocity direction (-y, x)/r
    for i in 0..fx.set.len() {
        let [x, y] = fx.set.xy[i];
        let r = x.hypot(y);
        let e = fx.set.direction[i];
        approx::assert_abs_diff_eq!(e[0], -y / r, epsilon = 1e-15);
        approx::assert_abs_diff_eq!(e[1], x / r, epsilon = 1e-15);
        let s = fx.set.pin_dofs[i];
        let pt = fx.set.pt.as_ref();
        for a in 0..2 {
            let v: f64 = pt
                .row_idx_of_col(s[a])
                .zip(pt.val_of_col(s[a]))
                .filter(|(row, _)| *row == i)
                .map(|(_, v)| *v)
                .sum();
            approx::assert_abs_diff_eq!(v, e[a], epsilon = 1e-15);
        }
    }
    // the resultant friction on the pin points along -x at the pin (x = 0, y > 0)
    let e = solve(&LcpSolver::default(), &Lagrange, 0.5);
    assert!(e.tangential_resultant_n[0] < -0.99 * 100.0);
    // reversing the rotation equals mu -> -mu
    let rev = ContactSet::new(&fx.model, &Zone::Uniform, -1.0).unwrap();
    let prob_rev = problem(&fx.model, &rev, &fx.f, &fx.g0);
    let prob = problem(&fx.model, &fx.set, &fx.f, &fx.g0);
    let cond_rev = Condensation::new(&prob_rev).unwrap();
    let a = LcpSolver::default()
        .solve_condensed(&cond_rev, &prob_rev, &Lagrange, 0.4)
        .unwrap();
    let b = LcpSolver::default()
        .solve_condensed(&fx.cond, &prob, &Lagrange, -0.4)
        .unwrap();
    let total: f64 = a.rn.iter().sum();
    for (x, y) in a.rn.iter().zip(&b.rn) {
        assert!((x - y).abs() <= 1e-10 * total);
    }
    // and it moves the zone the other way
    let fwd = LcpSolver::default()
        .solve_condensed(&fx.cond, &prob, &Lagrange, 0.4)
        .unwrap();
    let cx = |rn: &[f64]| -> f64 {
        rn.iter()
            .zip(&fx.set.xy)
            .map(|(r, p)| r * p[0])
            .sum::<f64>()
            / rn.iter().sum::<f64>()
    };
    assert!(cx(&fwd.rn) > 1e-3 && cx(&a.rn) < -1e-3);
}

#[test]
fn zone_shrinks_towards_the_leading_edge_as_mu_grows() {
    let runs: Vec<LoadedEquilibrium> = MUS
        .iter()
        .map(|&mu| solve(&LcpSolver::default(), &Lagrange, mu))
        .collect();
    let counts: Vec<usize> = runs
        .iter()
        .map(|e| e.eq.active.iter().filter(|&&a| a).count())
        .collect();
    assert!(
        counts.windows(2).all(|w| w[1] <= w[0]),
        "active pairs {counts:?}"
    );
    assert!(counts[4] < counts[0], "active pairs {counts:?}");
    // rotation +1: the disc enters under the pin at its +x edge (the leading edge)
    let cx: Vec<f64> = runs.iter().map(|e| e.centroid_m[0]).collect();
    assert!(
        cx[0].abs() < 1e-6,
        "uniform pressure centred at mu = 0: {cx:?}"
    );
    assert!(cx.windows(2).all(|w| w[1] > w[0]), "centroid x {cx:?}");
}

#[test]
fn penalty_tends_to_lagrange_like_one_over_kn() {
    let exact = solve(&LcpSolver::default(), &Lagrange, 0.3);
    let mut errs = Vec::new();
    for kn in [1e9, 1e10, 1e11, 1e12] {
        let p = solve(&LcpSolver::default(), &Penalty::new(kn).unwrap(), 0.3);
        let err =
            p.eq.rn
                .iter()
                .zip(&exact.eq.rn)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                / exact.total_normal_force_n;
        errs.push(err);
    }
    assert!(errs.windows(2).all(|w| w[1] < w[0]), "errors {errs:?}");
    // asymptotically one decade per decade of kn
    let ratio = errs[2] / errs[3];
    assert!((5.0..20.0).contains(&ratio), "errors {errs:?}");
}

#[test]
fn bad_input_gives_clear_errors() {
    let fx = fixture();
    for mu in [-0.1, f64::NAN] {
        let msg = squeal_contact::check_user_mu(mu).unwrap_err().to_string();
        assert!(msg.contains("mu") && msg.contains(">= 0"), "{msg}");
    }
    let nan = LcpSolver::default().solve(
        &problem(&fx.model, &fx.set, &fx.f, &fx.g0),
        &Lagrange,
        f64::NAN,
    );
    assert!(nan.unwrap_err().to_string().contains("mu"));
    // a load that opens every pair: the disc pulled away from the pin
    let g_open = vec![1e-4; fx.set.len()];
    let prob = ContactProblem {
        g0: &g_open,
        ..problem(&fx.model, &fx.set, &fx.f, &fx.g0)
    };
    for solver in [
        &LcpSolver::default() as &dyn EquilibriumSolver,
        &LorangSolver::default(),
    ] {
        let msg = solver.solve(&prob, &Lagrange, 0.3).unwrap_err().to_string();
        assert!(msg.contains("no contact"), "{msg}");
    }
    // a scene without contact pairs: the disc alone
    let disc = build(&fx.scene, BodyKind::Disc, &registry(), "builtin").unwrap();
    let msg = ContactSet::new(&disc, &Zone::Uniform, 1.0)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("no contact pairs"), "{msg}");
    // a zone with no pair in it
    let zone = Zone::Rectangle {
        x0_m: 0.0001,
        y0_m: 0.0001,
        a_m: 0.0002,
        b_m: 0.0002,
    };
    let msg = ContactSet::new(&fx.model, &zone, 1.0)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("contact.zone"), "{msg}");
}

#[test]
fn zones_select_their_pairs() {
    let fx = fixture();
    let rect = Zone::Rectangle {
        x0_m: 0.010,
        y0_m: 0.0,
        a_m: 0.010,
        b_m: 0.020,
    };
    // 11 of 21 columns, every row
    assert_eq!(
        ContactSet::new(&fx.model, &rect, 1.0).unwrap().len(),
        11 * 21
    );
    let plateaus = Zone::Plateaus {
        patch_m: 0.005,
        seed: 42,
        fraction: None,
        count: Some(1),
        region_m: None,
    };
    // one 5 mm patch on a 1 mm grid: the 5 x 5 pairs of its cell, and the face's far
    // edge where the patch reaches it
    let set = ContactSet::new(&fx.model, &plateaus, 1.0).unwrap();
    let r = plateaus.plateau_rectangles([0.02, 0.02]).unwrap()[0];
    let side = |start: f64| if start + 0.005 > 0.02 - 1e-9 { 6 } else { 5 };
    assert_eq!(set.len(), side(r[0]) * side(r[1]), "patch at {r:?}");
    let mut values = vec![0u8; fx.set.len()];
    values[0] = 1;
    values[440] = 1;
    let mask = Zone::Mask {
        values: Some(values),
        file: None,
    };
    let set = ContactSet::new(&fx.model, &mask, 1.0).unwrap();
    assert_eq!(set.grid_index, vec![0, 440]);
    // the corner pairs of the mask are the face's corners
    assert!(set.xy[0][0] < set.xy[1][0] && set.xy[0][1] < set.xy[1][1]);
}
