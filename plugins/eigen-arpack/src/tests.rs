//! Spring-mass chains with closed-form spectra, solved through the `arpack` plugin.

use super::*;
use squeal_core::eigen::dense_symmetric;
use squeal_core::eigen::SymmetricKernel;
use squeal_core::faer::sparse::Triplet;
use squeal_core::faer::Mat;
use squeal_core::linalg::spmv;
use squeal_core::spectral::{ShiftInvert, SpectralTransform};
use squeal_core::{EigenParams, EigenSolver, RealModes, SymmetricProblem};
use squeal_core::{Error, SparseMat};
use std::f64::consts::PI;

const K: f64 = 1.0e4; // N/m
const MASS: f64 = 1.0e-2; // kg

fn sparse(n: usize, t: &[Triplet<usize, usize, f64>]) -> SparseMat {
    SparseMat::try_new_from_triplets(n, n, t).unwrap()
}

/// Tridiagonal `a` on the diagonal, `b` off it, of size `n`, at offset `at` in `trip`.
fn tridiag(trip: &mut Vec<Triplet<usize, usize, f64>>, at: usize, n: usize, a: f64, b: f64) {
    for i in 0..n {
        trip.push(Triplet::new(at + i, at + i, a));
        if i + 1 < n {
            trip.push(Triplet::new(at + i, at + i + 1, b));
            trip.push(Triplet::new(at + i + 1, at + i, b));
        }
    }
}

/// Fixed-fixed chain of `n` DOFs: `K = k tridiag(-1, 2, -1)`, `M = m I`.
fn fixed_chain_lumped(n: usize) -> (SparseMat, SparseMat) {
    let (mut tk, mut tm) = (Vec::new(), Vec::new());
    tridiag(&mut tk, 0, n, 2.0 * K, -K);
    tridiag(&mut tm, 0, n, MASS, 0.0);
    (sparse(n, &tk), sparse(n, &tm))
}

/// `omega_j^2 = (2k/m)(1 - cos(j pi / (n + 1))) = (4k/m) sin^2(j pi / (2 (n + 1)))`.
fn fixed_chain_lumped_exact(n: usize, j: usize) -> f64 {
    let s = (j as f64 * PI / (2.0 * (n + 1) as f64)).sin();
    4.0 * K / MASS * s * s
}

/// Two identical, decoupled fixed-fixed chains of `n1` DOFs with consistent mass
/// `M = (m / 6) tridiag(1, 4, 1)`: every eigenvalue is exactly double.
fn twin_chains_consistent(n1: usize) -> (SparseMat, SparseMat) {
    let (mut tk, mut tm) = (Vec::new(), Vec::new());
    for at in [0, n1] {
        tridiag(&mut tk, at, n1, 2.0 * K, -K);
        tridiag(&mut tm, at, n1, 4.0 * MASS / 6.0, MASS / 6.0);
    }
    (sparse(2 * n1, &tk), sparse(2 * n1, &tm))
}

/// `lambda_j = (6k/m)(1 - c)/(2 + c)`, `c = cos(j pi / (n1 + 1))`, same sine eigenvectors
/// as the lumped chain.
fn consistent_chain_exact(n1: usize, j: usize) -> f64 {
    let x = j as f64 * PI / (n1 + 1) as f64;
    let one_minus_c = 2.0 * (0.5 * x).sin().powi(2);
    6.0 * K / MASS * one_minus_c / (2.0 + x.cos())
}

/// Free-free chain of `n` masses and `n - 1` springs: one rigid mode at 0.
fn free_chain(n: usize) -> (SparseMat, SparseMat) {
    let (mut tk, mut tm) = (Vec::new(), Vec::new());
    tridiag(&mut tk, 0, n, 2.0 * K, -K);
    tk.push(Triplet::new(0, 0, -K));
    tk.push(Triplet::new(n - 1, n - 1, -K));
    tridiag(&mut tm, 0, n, MASS, 0.0);
    (sparse(n, &tk), sparse(n, &tm))
}

/// `omega_j^2 = (4k/m) sin^2(j pi / (2 n))`, `j = 0..n`.
fn free_chain_exact(n: usize, j: usize) -> f64 {
    let s = (j as f64 * PI / (2.0 * n as f64)).sin();
    4.0 * K / MASS * s * s
}

/// A band top (Hz) halfway between two eigenvalues (rad/s)^2.
fn fmax_between(lo: f64, hi: f64) -> f64 {
    0.5 * (lo.sqrt() + hi.sqrt()) / (2.0 * PI)
}

fn params(fmax_hz: f64) -> EigenParams {
    EigenParams {
        fmax_hz,
        dense_below: 0,
        ..EigenParams::default()
    }
}

fn solve(k: &SparseMat, m: &SparseMat, p: &EigenParams) -> RealModes {
    let problem = SymmetricProblem {
        k: k.as_ref(),
        m: m.as_ref(),
    };
    ARPACK.solve_symmetric(&problem, p).unwrap()
}

fn assert_small_residuals(modes: &RealModes) {
    assert!(!modes.residuals.is_empty());
    for (i, r) in modes.residuals.iter().enumerate() {
        assert!(*r < 1e-10, "residual of mode {i} = {r:e}");
    }
}

/// `V^T M V = I` to `tol`.
fn assert_m_orthonormal(m: &SparseMat, v: &Mat<f64>, tol: f64) {
    let (n, c) = (v.nrows(), v.ncols());
    let mut mx = vec![0.0; n];
    for j in 0..c {
        let x: Vec<f64> = (0..n).map(|r| v[(r, j)]).collect();
        spmv(m.as_ref(), &x, &mut mx);
        for i in 0..c {
            let g: f64 = (0..n).map(|r| v[(r, i)] * mx[r]).sum();
            let want = if i == j { 1.0 } else { 0.0 };
            assert!(
                (g - want).abs() < tol,
                "(V^T M V)[{i}, {j}] = {g:e}, expected {want}"
            );
        }
    }
}

fn assert_rel(got: f64, want: f64, tol: f64, what: &str) {
    let rel = (got - want).abs() / want.abs();
    assert!(
        rel < tol,
        "{what}: got {got:.16e}, want {want:.16e}, rel {rel:e}"
    );
}

#[test]
fn fixed_chain_lowest_twenty_modes_match_the_closed_form() {
    let n = 300;
    let (k, m) = fixed_chain_lumped(n);
    let fmax = fmax_between(
        fixed_chain_lumped_exact(n, 20),
        fixed_chain_lumped_exact(n, 21),
    );
    let modes = solve(&k, &m, &params(fmax));
    assert_eq!(modes.omega2.len(), 20, "{:?}", modes.info);
    for (j, &l) in modes.omega2.iter().enumerate() {
        assert_rel(
            l,
            fixed_chain_lumped_exact(n, j + 1),
            1e-10,
            &format!("mode {}", j + 1),
        );
        let f = fixed_chain_lumped_exact(n, j + 1).sqrt() / (2.0 * PI);
        assert_rel(modes.freq_hz[j], f, 1e-10, "frequency");
    }
    assert_small_residuals(&modes);
    assert_m_orthonormal(&m, &modes.vectors, 1e-10);
    // Mode shapes: x_j(i) = sqrt(2 / (m (n + 1))) sin(i j pi / (n + 1)), up to sign.
    for j in 0..5 {
        let scale = (2.0 / (MASS * (n + 1) as f64)).sqrt();
        let exact: Vec<f64> = (0..n)
            .map(|i| scale * ((i + 1) as f64 * (j + 1) as f64 * PI / (n + 1) as f64).sin())
            .collect();
        let sign = if modes.vectors[(0, j)] * exact[0] < 0.0 {
            -1.0
        } else {
            1.0
        };
        let err = (0..n)
            .map(|i| (sign * modes.vectors[(i, j)] - exact[i]).abs())
            .fold(0.0, f64::max);
        assert!(
            err < 1e-8 * scale,
            "shape of mode {}: max error {err:e}",
            j + 1
        );
    }
    assert_eq!(modes.info.solver, "arpack");
    assert_eq!(modes.info.reason, squeal_core::StopReason::Converged);
    assert!(modes.info.iterations >= 1);
    assert!(modes.info.op_applications > 0);
    assert_eq!(modes.info.factorizations, 1);
}

#[test]
fn repeated_eigenvalues_are_found_with_their_multiplicity() {
    let n1 = 150;
    let (k, m) = twin_chains_consistent(n1);
    let fmax = fmax_between(
        consistent_chain_exact(n1, 10),
        consistent_chain_exact(n1, 11),
    );
    let modes = solve(&k, &m, &params(fmax));
    assert_eq!(
        modes.omega2.len(),
        20,
        "10 doublets expected: {:?} {:?}",
        modes.omega2,
        modes.info
    );
    for j in 1..=10 {
        let want = consistent_chain_exact(n1, j);
        let count = modes
            .omega2
            .iter()
            .filter(|&&l| (l - want).abs() < 1e-10 * want)
            .count();
        assert_eq!(count, 2, "eigenvalue {j} ({want:e}) found {count} times");
    }
    assert_small_residuals(&modes);
    // The two vectors of each doublet span the eigenspace: M-orthonormal.
    assert_m_orthonormal(&m, &modes.vectors, 1e-9);
}

#[test]
fn residuals_are_small_on_a_nonuniform_chain_and_match_the_dense_oracle() {
    let n = 300;
    let (mut tk, mut tm) = (Vec::new(), Vec::new());
    let spring = |s: usize| K * (1.0 + 0.5 * (0.7 * s as f64).sin());
    for i in 0..n {
        // Spring i joins DOF i - 1 (or the wall) and DOF i; spring n joins DOF n-1 and the wall.
        tk.push(Triplet::new(i, i, spring(i) + spring(i + 1)));
        if i + 1 < n {
            tk.push(Triplet::new(i, i + 1, -spring(i + 1)));
            tk.push(Triplet::new(i + 1, i, -spring(i + 1)));
        }
        tm.push(Triplet::new(
            i,
            i,
            MASS * (1.0 + 0.3 * (1.3 * i as f64).cos()),
        ));
    }
    let (k, m) = (sparse(n, &tk), sparse(n, &tm));
    let problem = SymmetricProblem {
        k: k.as_ref(),
        m: m.as_ref(),
    };
    let (mut exact, _) = dense_symmetric(&problem).unwrap();
    exact.sort_by(f64::total_cmp);
    let modes = solve(&k, &m, &params(fmax_between(exact[29], exact[30])));
    assert_eq!(modes.omega2.len(), 30, "{:?}", modes.info);
    for (j, &l) in modes.omega2.iter().enumerate() {
        assert_rel(l, exact[j], 1e-9, &format!("mode {}", j + 1));
    }
    assert_small_residuals(&modes);
    assert_m_orthonormal(&m, &modes.vectors, 1e-10);
}

#[test]
fn free_chain_with_a_rigid_mode_works_with_the_negative_shift() {
    let n = 300;
    let (k, m) = free_chain(n);
    let fmax = fmax_between(free_chain_exact(n, 19), free_chain_exact(n, 20));
    let modes = solve(&k, &m, &params(fmax));
    assert_eq!(modes.omega2.len(), 20, "{:?}", modes.info);
    let first = free_chain_exact(n, 1);
    assert!(
        modes.omega2[0].abs() < 1e-10 * first,
        "rigid mode: omega^2 = {:e}",
        modes.omega2[0]
    );
    assert!(modes.freq_hz[0] < 1e-5 * first.sqrt());
    for j in 1..20 {
        assert_rel(
            modes.omega2[j],
            free_chain_exact(n, j),
            1e-10,
            &format!("mode {j}"),
        );
    }
    // The rigid mode is a uniform translation.
    let x0 = modes.vectors[(0, 0)];
    for i in 0..n {
        assert!((modes.vectors[(i, 0)] - x0).abs() < 1e-8 * x0.abs());
    }
    assert_small_residuals(&modes);
}

#[test]
fn band_growth_and_fmin_filter() {
    // 60 modes below the top: the driver must grow nev from 24 and drop those below fmin.
    let n = 300;
    let (k, m) = fixed_chain_lumped(n);
    let p = EigenParams {
        fmin_hz: fmax_between(
            fixed_chain_lumped_exact(n, 10),
            fixed_chain_lumped_exact(n, 11),
        ),
        ..params(fmax_between(
            fixed_chain_lumped_exact(n, 60),
            fixed_chain_lumped_exact(n, 61),
        ))
    };
    let modes = solve(&k, &m, &p);
    assert_eq!(modes.omega2.len(), 50, "{:?}", modes.info);
    for (c, &l) in modes.omega2.iter().enumerate() {
        assert_rel(l, fixed_chain_lumped_exact(n, c + 11), 1e-10, "banded mode");
    }
    assert!(modes.info.requested > 24, "{:?}", modes.info);
    assert_small_residuals(&modes);
}

#[test]
fn runs_are_reproducible() {
    let (k, m) = twin_chains_consistent(150);
    let p = params(fmax_between(
        consistent_chain_exact(150, 6),
        consistent_chain_exact(150, 7),
    ));
    let a = solve(&k, &m, &p);
    let b = solve(&k, &m, &p);
    assert_eq!(a.omega2, b.omega2);
    assert_eq!(a.vectors, b.vectors);
    assert_eq!(a.info.iterations, b.info.iterations);
}

#[test]
fn concurrent_solves_are_serialized_and_correct() {
    let n = 300;
    let (k, m) = fixed_chain_lumped(n);
    let fmax = fmax_between(
        fixed_chain_lumped_exact(n, 12),
        fixed_chain_lumped_exact(n, 13),
    );
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|_| s.spawn(|| solve(&k, &m, &params(fmax))))
            .collect();
        for h in handles {
            let modes = h.join().unwrap();
            assert_eq!(modes.omega2.len(), 12);
            for (j, &l) in modes.omega2.iter().enumerate() {
                assert_rel(l, fixed_chain_lumped_exact(n, j + 1), 1e-10, "threaded");
            }
        }
    });
}

#[test]
fn kernel_returns_operator_eigenvalues() {
    let n = 200;
    let (k, m) = fixed_chain_lumped(n);
    let sigma = -50.0;
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), sigma).unwrap();
    let out = ArpackKernel.largest(&op, 8, 1e-12, 300).unwrap();
    assert!(out.all_converged);
    assert_eq!(out.theta.len(), 8);
    assert_eq!(out.vectors.ncols(), 8);
    assert_eq!(out.vectors.nrows(), n);
    assert!(out.iterations >= 1);
    let mut theta = out.theta.clone();
    theta.sort_by(|a, b| b.total_cmp(a));
    for (j, t) in theta.iter().enumerate() {
        let want = 1.0 / (fixed_chain_lumped_exact(n, j + 1) - sigma);
        assert_rel(*t, want, 1e-11, "theta");
    }
}

#[test]
fn iteration_cap_is_not_an_error() {
    // A clustered spectrum (lambda_i = 1 + 1e-3 i, relative gaps ~ 0.4 %), ncv = 30 and
    // a cap of a few Lanczos updates: ARPACK stops with info = 1, and the kernel returns
    // what converged (possibly nothing) instead of failing.
    let n = 300;
    let tk: Vec<_> = (0..n)
        .map(|i| Triplet::new(i, i, 1.0 + 1e-3 * i as f64))
        .collect();
    let tm: Vec<_> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    let (k, m) = (sparse(n, &tk), sparse(n, &tm));
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), -1.0).unwrap();
    // One update: nothing has converged yet (dseupd is skipped).
    let out = ArpackKernel.largest(&op, 10, 1e-12, 1).unwrap();
    assert!(!out.all_converged);
    assert!(out.theta.is_empty(), "converged {} of 10", out.theta.len());
    assert_eq!((out.vectors.nrows(), out.vectors.ncols()), (n, 0));
    // Seven updates: some have (6 with ARPACK-NG 3.8 and the fixed start vector);
    // dseupd extracts exactly those, and they are genuine eigenpairs.
    let out = ArpackKernel.largest(&op, 10, 1e-12, 7).unwrap();
    assert!(!out.all_converged);
    let nconv = out.theta.len();
    assert!(0 < nconv && nconv < 10, "converged {nconv} of 10");
    assert_eq!((out.vectors.nrows(), out.vectors.ncols()), (n, nconv));
    let (mut kx, mut mx) = (vec![0.0; n], vec![0.0; n]);
    for (j, t) in out.theta.iter().enumerate() {
        let lam = op.pencil_eigenvalue(*t);
        let i = ((lam - 1.0) / 1e-3).round();
        assert!((lam - (1.0 + 1e-3 * i)).abs() < 1e-10, "lambda = {lam}");
        let x: Vec<f64> = (0..n).map(|r| out.vectors[(r, j)]).collect();
        spmv(k.as_ref(), &x, &mut kx);
        spmv(m.as_ref(), &x, &mut mx);
        let r: f64 = kx.iter().zip(&mx).map(|(a, b)| (a - lam * b).powi(2)).sum();
        let xx: f64 = x.iter().map(|v| v * v).sum();
        assert!(r.sqrt() < 1e-9 * xx.sqrt(), "residual of pair {j}");
    }
    // With enough restarts the same request converges.
    let out = ArpackKernel.largest(&op, 10, 1e-12, 300).unwrap();
    assert!(out.all_converged);
    assert!(out.iterations > 1);
    let mut lam: Vec<f64> = out.theta.iter().map(|&t| op.pencil_eigenvalue(t)).collect();
    lam.sort_by(f64::total_cmp);
    for (i, l) in lam.iter().enumerate() {
        assert_rel(*l, 1.0 + 1e-3 * i as f64, 1e-11, "clustered");
    }
}

#[test]
fn impossible_requests_are_typed_errors() {
    let (k, m) = fixed_chain_lumped(10);
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), -1.0).unwrap();
    for nev in [0, 10, 11] {
        let e = ArpackKernel.largest(&op, nev, 1e-12, 300).err().unwrap();
        let Error::Backend(b) = e else {
            panic!("expected a backend error")
        };
        let a = b.downcast_ref::<ArpackError>().expect("an ArpackError");
        assert_eq!(*a, ArpackError::BadRequest { nev, n: 10 });
    }
    // max_restarts = 0 reaches ARPACK, which rejects it as info = -4.
    let e = ArpackKernel.largest(&op, 2, 1e-12, 0).err().unwrap();
    let Error::Backend(b) = e else {
        panic!("expected a backend error")
    };
    let a = b.downcast_ref::<ArpackError>().unwrap();
    assert!(
        matches!(
            a,
            ArpackError::InvalidArgument {
                routine: Routine::Dsaupd,
                code: -4,
                ..
            }
        ),
        "{a:?}"
    );
    assert!(a.to_string().contains("dsaupd") && a.to_string().contains("-4"));
}

#[test]
fn info_codes_name_the_routine_and_the_meaning() {
    let cases: [(Routine, i32, &[&str]); 7] = [
        (
            Routine::Dsaupd,
            1,
            &["dsaupd", "maximum number of iterations", "3 of 8"],
        ),
        (
            Routine::Dsaupd,
            3,
            &["dsaupd", "no shifts", "ncv = 17", "nev = 8"],
        ),
        (
            Routine::Dsaupd,
            -9999,
            &["dsaupd", "Lanczos factorization", "size 3"],
        ),
        (
            Routine::Dsaupd,
            -3,
            &["dsaupd", "invalid argument", "info = -3", "NCV"],
        ),
        (Routine::Dseupd, -14, &["dseupd", "no Ritz value converged"]),
        (Routine::Dseupd, -17, &["dseupd", "-17"]),
        (Routine::Dseupd, 42, &["dseupd", "undocumented", "42"]),
    ];
    for (routine, code, needles) in cases {
        let msg = ArpackError::from_info(routine, code, 8, 17, 3).to_string();
        for needle in needles {
            assert!(msg.contains(needle), "{code}: `{msg}` lacks `{needle}`");
        }
    }
    // -12 means different things in the two routines.
    let a = ArpackError::from_info(Routine::Dsaupd, -12, 8, 17, 0).to_string();
    let e = ArpackError::from_info(Routine::Dseupd, -12, 8, 17, 0).to_string();
    assert!(a.contains("IPARAM(1)") && e.contains("BE"), "{a} / {e}");
    // Conversion into the core error keeps the typed value.
    let core: Error = ArpackError::Tridiagonal {
        routine: Routine::Dsaupd,
    }
    .into();
    assert!(core.to_string().contains("dsteqr"));
    let Error::Backend(b) = core else {
        panic!("expected Error::Backend")
    };
    assert!(b.downcast_ref::<ArpackError>().is_some());
}

#[test]
fn registered_under_its_name_and_rejects_unknown_parameters() {
    let mut reg = squeal_core::Registry::new();
    register(&mut reg);
    assert_eq!(reg.eigen.names(), vec!["arpack".to_string()]);
    let (name, desc) = &reg.eigen.describe()[0];
    assert_eq!(name, "arpack");
    assert!(desc.contains("dsaupd") && desc.contains("shift-invert"));
    let solver = reg.eigen.create("arpack", &Params::new()).unwrap();
    assert_eq!(solver.name(), "arpack");
    let e = reg
        .eigen
        .create("arpack", &Params::new().with_num("ncv", 40.0))
        .err()
        .unwrap();
    assert!(
        matches!(&e, Error::Param { name, .. } if name == "ncv"),
        "{e}"
    );
    // And the created solver works.
    let (k, m) = fixed_chain_lumped(150);
    let problem = SymmetricProblem {
        k: k.as_ref(),
        m: m.as_ref(),
    };
    let p = params(fmax_between(
        fixed_chain_lumped_exact(150, 3),
        fixed_chain_lumped_exact(150, 4),
    ));
    let modes = solver.solve_symmetric(&problem, &p).unwrap();
    assert_eq!(modes.omega2.len(), 3);
}
