use super::*;
use squeal_core::faer::sparse::Triplet;
use squeal_core::{c64, FrictionalOperator, SparseMat};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn sparse(n: usize, entries: &[(usize, usize, f64)]) -> SparseMat {
    let t: Vec<_> = entries
        .iter()
        .map(|&(i, j, v)| Triplet::new(i, j, v))
        .collect();
    SparseMat::try_new_from_triplets(n, n, &t).unwrap()
}

/// Uniform fixed-fixed chain: `omega_j = 2 sqrt(k/m) sin(j pi / (2 (n + 1)))`.
fn chain(n: usize, k: f64, m: f64) -> (SparseMat, SparseMat, Vec<f64>) {
    let mut ke = Vec::new();
    for i in 0..n {
        ke.push((i, i, 2.0 * k));
        if i + 1 < n {
            ke.push((i, i + 1, -k));
            ke.push((i + 1, i, -k));
        }
    }
    let me: Vec<_> = (0..n).map(|i| (i, i, m)).collect();
    let omega = (1..=n)
        .map(|j| {
            2.0 * (k / m).sqrt() * (j as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64)).sin()
        })
        .collect();
    (sparse(n, &ke), sparse(n, &me), omega)
}

fn solver(params: Params) -> Box<dyn EigenSolver> {
    let mut reg = Registry::new();
    register(&mut reg);
    reg.eigen.create(NAME, &params).unwrap()
}

#[test]
fn symmetric_chain_matches_closed_form_in_band() {
    let (k, m, omega) = chain(40, 1e6, 2.0);
    let params = EigenParams {
        fmin_hz: 20.0,
        fmax_hz: 150.0,
        ..Default::default()
    };
    let s = solver(Params::new());
    let modes = s
        .solve_symmetric(
            &SymmetricProblem {
                k: k.as_ref(),
                m: m.as_ref(),
            },
            &params,
        )
        .unwrap();
    let want: Vec<f64> = omega
        .iter()
        .map(|w| w / TWO_PI)
        .filter(|&f| (20.0..=150.0).contains(&f))
        .collect();
    assert!(want.len() >= 5);
    assert_eq!(modes.freq_hz.len(), want.len());
    for (g, w) in modes.freq_hz.iter().zip(&want) {
        assert!((g - w).abs() <= 1e-10 * w, "{g} vs {w}");
    }
    for (j, r) in modes.residuals.iter().enumerate() {
        assert!(*r < 1e-13, "residual {r:e}");
        // M-normalized: x^T M x = 1 with M = 2 I.
        let nrm: f64 = (0..40).map(|i| 2.0 * modes.vectors[(i, j)].powi(2)).sum();
        assert!((nrm - 1.0).abs() < 1e-12);
    }
    assert_eq!(modes.info.solver, NAME);
}

fn hoffmann() -> FrictionalOperator {
    FrictionalOperator {
        mc: sparse(2, &[(0, 0, 1.0), (1, 1, 1.0)]),
        cc: None,
        kc: sparse(2, &[(0, 0, 1.0), (0, 1, 0.1), (1, 0, 0.1), (1, 1, 1.2)]),
        fm: sparse(2, &[]),
        fc: None,
        fk: sparse(2, &[(0, 1, 1.0)]),
        t: None,
        friction_loads: None,
        modal: Default::default(),
    }
}

#[test]
fn hoffmann_flutter_above_mu_c() {
    let op = hoffmann();
    let s = solver(Params::new());
    let params = EigenParams {
        fmax_hz: 1.0,
        ..Default::default()
    };
    // Closed form at mu = 0.3: lambda^2 = -(1.1 +- 0.1 i).
    let modes = s.solve_frictional(&op, 0.3, &params).unwrap();
    assert_eq!(modes.len(), 2);
    for s2 in [c64::new(-1.1, -0.1), c64::new(-1.1, 0.1)] {
        let mut l = s2.sqrt();
        if l.im < 0.0 {
            l = -l;
        }
        let d = modes
            .lambda
            .iter()
            .map(|g| (g - l).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-12, "{l} not in {:?}", modes.lambda);
    }
    assert!(modes.backward_error.iter().all(|&e| e < 1e-14));
    let unstable = |mu: f64| {
        let m = s.solve_frictional(&op, mu, &params).unwrap();
        (0..m.len()).filter(|&i| m.is_unstable(i, 1e-10)).count()
    };
    assert_eq!(unstable(0.0), 0);
    assert_eq!(unstable(0.199), 0);
    assert_eq!(unstable(0.201), 1);
    assert_eq!(unstable(0.3), 1);
}

#[test]
fn undamped_symmetric_qep_gives_the_normal_modes() {
    let (k, m, omega) = chain(30, 4e5, 0.5);
    let qep = Qep { m, c: None, k };
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: 200.0,
        ..Default::default()
    };
    let modes = DenseSolver::default().solve_qep(&qep, &params).unwrap();
    let want: Vec<f64> = omega
        .iter()
        .copied()
        .filter(|w| w / TWO_PI <= 200.0)
        .collect();
    assert_eq!(modes.len(), want.len());
    for (l, w) in modes.lambda.iter().zip(&want) {
        assert!(
            l.re.abs() < 1e-10 * w && (l.im - w).abs() < 1e-10 * w,
            "{l} vs {w}"
        );
    }
}

#[test]
fn too_large_problems_and_unknown_options_are_refused() {
    let (k, m, _) = chain(10, 1.0, 1.0);
    let s = solver(Params::new().with_num("max_dim", 5.0));
    let e = s
        .solve_symmetric(
            &SymmetricProblem {
                k: k.as_ref(),
                m: m.as_ref(),
            },
            &EigenParams::default(),
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("max_dim") && e.contains("10"), "{e}");
    let e = s
        .solve_qep(&Qep { m, c: None, k }, &EigenParams::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("max_dim"), "{e}");
    let mut reg = Registry::new();
    register(&mut reg);
    let e = reg
        .eigen
        .create(NAME, &Params::new().with_num("maxdim", 5.0))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("maxdim"), "{e}");
}
