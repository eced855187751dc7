//! Unit tests against closed forms and the dense oracle.

use super::*;
use squeal_core::eigen::dense_symmetric;
use squeal_core::faer::sparse::Triplet;
use squeal_core::faer::{Mat, MatRef};
use squeal_core::spectral::SpectralTransform;
use squeal_core::{EigenParams, EigenSolver, RealModes, SymmetricProblem};
use squeal_core::{SparseMat, StopReason};
use std::f64::consts::PI;

const K: f64 = 1.0e6; // N/m
const MASS: f64 = 1.0; // kg

fn sparse(n: usize, trip: &[Triplet<usize, usize, f64>]) -> SparseMat {
    SparseMat::try_new_from_triplets(n, n, trip).unwrap()
}

/// Stiffness triplets of a spring chain of `n` masses starting at DOF `offset`;
/// spring `s` (0..=n) joins node `s - 1` and node `s`, the ends to the ground if fixed.
fn chain_k(
    trip: &mut Vec<Triplet<usize, usize, f64>>,
    offset: usize,
    n: usize,
    spring: impl Fn(usize) -> f64,
    fixed: bool,
) {
    for s in 0..=n {
        let ks = spring(s);
        let (a, b) = (s.checked_sub(1), (s < n).then_some(s));
        match (a, b) {
            (Some(a), Some(b)) => {
                trip.push(Triplet::new(offset + a, offset + a, ks));
                trip.push(Triplet::new(offset + b, offset + b, ks));
                trip.push(Triplet::new(offset + a, offset + b, -ks));
                trip.push(Triplet::new(offset + b, offset + a, -ks));
            }
            (Some(e), None) | (None, Some(e)) if fixed => {
                trip.push(Triplet::new(offset + e, offset + e, ks));
            }
            _ => {}
        }
    }
}

/// Lumped (`m I`) or consistent (`m/6 (1, 4, 1)`) mass of a chain at `offset`.
fn chain_m(trip: &mut Vec<Triplet<usize, usize, f64>>, offset: usize, n: usize, consistent: bool) {
    for i in 0..n {
        if consistent {
            trip.push(Triplet::new(offset + i, offset + i, 4.0 * MASS / 6.0));
            if i + 1 < n {
                trip.push(Triplet::new(offset + i, offset + i + 1, MASS / 6.0));
                trip.push(Triplet::new(offset + i + 1, offset + i, MASS / 6.0));
            }
        } else {
            trip.push(Triplet::new(offset + i, offset + i, MASS));
        }
    }
}

/// `omega^2` of mode `j` of a uniform chain: `(2k/m)(1 - cos(j pi / d))`, written as
/// `(4k/m) sin^2(j pi / 2d)` to avoid cancellation (`d = n + 1` fixed, `n` free).
fn closed_form(j: usize, d: usize) -> f64 {
    4.0 * K / MASS * (j as f64 * PI / (2.0 * d as f64)).sin().powi(2)
}

fn hz(omega2: f64) -> f64 {
    omega2.max(0.0).sqrt() / (2.0 * PI)
}

fn params(fmax_hz: f64) -> EigenParams {
    EigenParams {
        dense_below: 0,
        fmax_hz,
        ..Default::default()
    }
}

fn solve(k: &SparseMat, m: &SparseMat, p: &EigenParams) -> RealModes {
    solve_with(&KRYLOV, k, m, p)
}

/// The single-vector solver (`block = 1`).
const SINGLE: KrylovSolver = KernelSolver::new(NAME, LanczosKernel::SINGLE, KrylovSchurKernel);

fn solve_with(solver: &KrylovSolver, k: &SparseMat, m: &SparseMat, p: &EigenParams) -> RealModes {
    let problem = SymmetricProblem {
        k: k.as_ref(),
        m: m.as_ref(),
    };
    let modes = solver.solve_symmetric(&problem, p).unwrap();
    eprintln!(
        "n = {}: {} modes, {} restarts, {} op applications, reason {:?}, max residual {:.2e}, notes {:?}",
        k.nrows(),
        modes.omega2.len(),
        modes.info.iterations,
        modes.info.op_applications,
        modes.info.reason,
        modes.residuals.iter().copied().fold(0.0, f64::max),
        modes.info.notes,
    );
    modes
}

fn assert_residuals(modes: &RealModes) {
    for (i, r) in modes.residuals.iter().enumerate() {
        assert!(*r < 1e-10, "mode {i}: residual {r:e}");
    }
}

/// `X^T M X = I` to `tol`.
fn assert_m_orthonormal(x: &Mat<f64>, m: &SparseMat, tol: f64) {
    let n = x.nrows();
    let mut mx = vec![0.0; n];
    for a in 0..x.ncols() {
        let xa: Vec<f64> = (0..n).map(|i| x[(i, a)]).collect();
        squeal_core::linalg::spmv(m.as_ref(), &xa, &mut mx);
        for b in 0..x.ncols() {
            let g: f64 = (0..n).map(|i| x[(i, b)] * mx[i]).sum();
            let expected = if a == b { 1.0 } else { 0.0 };
            assert!((g - expected).abs() < tol, "(X^T M X)[{a}, {b}] = {g:e}");
        }
    }
}

fn max_rel_err(got: &[f64], want: &[f64]) -> f64 {
    assert_eq!(got.len(), want.len());
    got.iter()
        .zip(want)
        .map(|(g, w)| (g - w).abs() / w.abs())
        .fold(0.0, f64::max)
}

#[test]
fn fixed_chain_matches_closed_form() {
    let n = 300;
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    chain_k(&mut kt, 0, n, |_| K, true);
    chain_m(&mut mt, 0, n, false);
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let fmax = 0.5 * (hz(closed_form(20, n + 1)) + hz(closed_form(21, n + 1)));
    let modes = solve(&k, &m, &params(fmax));
    let want: Vec<f64> = (1..=20).map(|j| closed_form(j, n + 1)).collect();
    let err = max_rel_err(&modes.omega2, &want);
    eprintln!("fixed chain: max relative error {err:.2e}");
    assert!(err < 1e-10, "max relative error {err:e}");
    assert_residuals(&modes);
    assert_eq!(modes.info.reason, StopReason::Converged);
    assert_eq!(modes.info.solver, "krylov");
    assert_m_orthonormal(&modes.vectors, &m, 1e-10);
    for (f, w) in modes.freq_hz.iter().zip(&want) {
        assert!((f - hz(*w)).abs() < 1e-9 * hz(*w));
    }
}

#[test]
fn identical_chains_give_every_eigenvalue_twice() {
    let half = 150;
    let n = 2 * half;
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    for off in [0, half] {
        chain_k(&mut kt, off, half, |_| K, true);
        chain_m(&mut mt, off, half, false);
    }
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    // 12 distinct frequencies, 24 modes: the first request (24 pairs) stays inside the
    // band, so the driver also grows its request.
    let fmax = 0.5 * (hz(closed_form(12, half + 1)) + hz(closed_form(13, half + 1)));
    let modes = solve(&k, &m, &params(fmax));
    let want: Vec<f64> = (1..=12)
        .flat_map(|j| [closed_form(j, half + 1); 2])
        .collect();
    assert_eq!(modes.omega2.len(), want.len(), "{:?}", modes.omega2);
    let err = max_rel_err(&modes.omega2, &want);
    eprintln!("identical chains: max relative error {err:.2e}");
    assert!(err < 1e-10, "max relative error {err:e}");
    assert_residuals(&modes);
    assert_eq!(modes.info.reason, StopReason::Converged);
    // The two copies are genuinely different (M-orthogonal) vectors.
    assert_m_orthonormal(&modes.vectors, &m, 1e-9);
}

#[test]
fn consistent_mass_doublets_match_dense_oracle() {
    let half = 100;
    let n = 2 * half;
    let spring = |s: usize| K * (1.0 + 0.3 * (s as f64).sin());
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    for off in [0, half] {
        chain_k(&mut kt, off, half, spring, true);
        chain_m(&mut mt, off, half, true);
    }
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let problem = SymmetricProblem {
        k: k.as_ref(),
        m: m.as_ref(),
    };
    let (mut dense, _) = dense_symmetric(&problem).unwrap();
    dense.sort_by(f64::total_cmp);
    // Exact doublets by construction.
    for p in 0..10 {
        assert!((dense[2 * p] - dense[2 * p + 1]).abs() < 1e-9 * dense[2 * p]);
    }
    let count = 30;
    let fmax = 0.5 * (hz(dense[count - 1]) + hz(dense[count]));
    let modes = solve(&k, &m, &params(fmax));
    let err = max_rel_err(&modes.omega2, &dense[..count]);
    eprintln!("consistent-mass doublets: max relative error vs dense {err:.2e}");
    assert!(err < 1e-10, "max relative error {err:e}");
    assert_residuals(&modes);
    assert_m_orthonormal(&modes.vectors, &m, 1e-9);
}

#[test]
fn free_chain_has_one_rigid_body_mode() {
    let n = 300;
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    chain_k(&mut kt, 0, n, |_| K, false);
    chain_m(&mut mt, 0, n, false);
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let fmax = 0.5 * (hz(closed_form(15, n)) + hz(closed_form(16, n)));
    let modes = solve(&k, &m, &params(fmax));
    assert_eq!(modes.omega2.len(), 16, "{:?}", modes.omega2);
    // Rigid-body mode: zero to round-off relative to the first elastic mode.
    assert!(
        modes.omega2[0].abs() < 1e-9 * closed_form(1, n),
        "{}",
        modes.omega2[0]
    );
    assert!(modes.freq_hz[0] < 1e-4 * modes.freq_hz[1]);
    let want: Vec<f64> = (1..16).map(|j| closed_form(j, n)).collect();
    let err = max_rel_err(&modes.omega2[1..], &want);
    eprintln!("free chain: max relative error {err:.2e}");
    assert!(err < 1e-10, "max relative error {err:e}");
    // The rigid mode is the uniform translation.
    let x0: Vec<f64> = (0..n).map(|i| modes.vectors[(i, 0)]).collect();
    let mean = x0.iter().sum::<f64>() / n as f64;
    assert!(x0.iter().all(|v| (v - mean).abs() < 1e-8 * mean.abs()));
    assert_residuals(&modes);
}

/// True eigenvalues of the fixed chain of `n` masses.
fn fixed_chain_spectrum(n: usize) -> Vec<f64> {
    (1..=n).map(|j| closed_form(j, n + 1)).collect()
}

/// Every value is within `tol` (relative) of an exact eigenvalue.
fn assert_true_eigenvalues(values: &[f64], exact: &[f64], tol: f64) {
    for &l in values {
        let nearest = exact
            .iter()
            .map(|e| (e - l).abs() / e)
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < tol, "{l} is not an eigenvalue ({nearest:e})");
    }
}

#[test]
fn restart_cap_reports_non_convergence() {
    let n = 300;
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    chain_k(&mut kt, 0, n, |_| K, true);
    chain_m(&mut mt, 0, n, false);
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let exact = fixed_chain_spectrum(n);
    let fmax = 0.5 * (hz(exact[19]) + hz(exact[20]));

    // Default shift: one restart converges the 24 pairs, but the validation run that
    // would look for missed copies cannot start, so convergence is not claimed.
    let p = EigenParams {
        max_restarts: 1,
        ..params(fmax)
    };
    let modes = solve_with(&SINGLE, &k, &m, &p);
    assert_eq!(modes.info.reason, StopReason::MaxIterations);
    assert!(modes.info.iterations <= 1);
    assert_true_eigenvalues(&modes.omega2, &exact, 1e-10);
    assert_residuals(&modes);

    // A shift at the band top separates the wanted theta poorly: after one restart
    // only part of the request has converged, and only that part is returned.
    let p = EigenParams {
        max_restarts: 1,
        shift_hz: Some(fmax),
        ..params(fmax)
    };
    let modes = solve_with(&SINGLE, &k, &m, &p);
    assert_eq!(modes.info.reason, StopReason::MaxIterations);
    assert!(
        modes.info.converged < modes.info.requested,
        "{:?}",
        modes.info
    );
    assert!(modes.info.iterations <= 1);
    assert_true_eigenvalues(&modes.omega2, &exact, 1e-10);
    assert_residuals(&modes);

    // Kernel level, no restart at all: fewer pairs than requested, all of them exact.
    let sigma = -exact[0];
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), sigma).unwrap();
    let out = LanczosKernel::SINGLE.largest(&op, 24, 1e-12, 0).unwrap();
    assert_capped(&out, &op, 24, &exact);
}

/// A kernel run stopped by a restart cap of 0: not all `nev` pairs, no restart, and the
/// pairs it returns true eigenvalues of the chain (`exact`).
fn assert_capped(out: &KernelOutput, op: &ShiftInvert<'_>, nev: usize, exact: &[f64]) {
    assert!(!out.all_converged);
    assert_eq!(out.iterations, 0);
    assert!(out.theta.len() < nev, "{}", out.theta.len());
    let lam: Vec<f64> = out.theta.iter().map(|&t| op.pencil_eigenvalue(t)).collect();
    assert_true_eigenvalues(&lam, exact, 1e-10);
}

#[test]
fn high_multiplicity_through_breakdowns() {
    // M = I, K = diag with three values of multiplicity 20 each: the Krylov space of
    // any vector has dimension 3, so every step past the third is a breakdown.
    let n = 60;
    let kt: Vec<_> = (0..n)
        .map(|i| Triplet::new(i, i, [1.0, 4.0, 9.0][i % 3] * 1e4))
        .collect();
    let mt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let fmax = hz(6.0e4);
    let modes = solve(&k, &m, &params(fmax));
    assert_eq!(modes.omega2.len(), 40, "{:?}", modes.omega2);
    for (i, l) in modes.omega2.iter().enumerate() {
        let want = if i < 20 { 1e4 } else { 4e4 };
        assert!((l - want).abs() < 1e-10 * want, "mode {i}: {l}");
    }
    assert_residuals(&modes);
    assert_eq!(modes.info.reason, StopReason::Converged);
    assert_m_orthonormal(&modes.vectors, &m, 1e-10);
}

#[test]
fn kernel_is_deterministic_and_finds_the_largest() {
    let n = 200;
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    chain_k(
        &mut kt,
        0,
        n,
        |s| K * (1.0 + 0.5 * (0.37 * s as f64).cos()),
        true,
    );
    chain_m(&mut mt, 0, n, true);
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let sigma = -1.0e3;
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), sigma).unwrap();
    let nev = 12;
    let a = LanczosKernel::SINGLE.largest(&op, nev, 1e-12, 300).unwrap();
    let b = LanczosKernel::SINGLE.largest(&op, nev, 1e-12, 300).unwrap();
    assert!(a.all_converged);
    assert_eq!(a.theta.len(), nev);
    assert_eq!(a.theta, b.theta);
    assert_eq!(a.iterations, b.iterations);
    assert!(a.vectors == b.vectors);
    eprintln!(
        "kernel: {} restarts, {} applications for two calls",
        a.iterations,
        op.applications()
    );

    let problem = SymmetricProblem {
        k: k.as_ref(),
        m: m.as_ref(),
    };
    let (mut dense, _) = dense_symmetric(&problem).unwrap();
    dense.sort_by(f64::total_cmp);
    let mut theta = a.theta.clone();
    theta.sort_by(|x, y| y.total_cmp(x));
    for (t, l) in theta.iter().zip(&dense) {
        let want = 1.0 / (l - sigma);
        assert!((t - want).abs() < 1e-11 * want, "{t} vs {want}");
    }
}

#[test]
fn kernel_handles_tiny_problems_and_full_requests() {
    let n = 7;
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    chain_k(&mut kt, 0, n, |_| K, true);
    chain_m(&mut mt, 0, n, false);
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), -1.0).unwrap();
    for nev in [0, 1, 6, 7, 9] {
        let out = LanczosKernel::SINGLE.largest(&op, nev, 1e-12, 50).unwrap();
        assert!(out.all_converged, "nev = {nev}");
        assert_eq!(out.theta.len(), nev.min(n));
        let mut theta = out.theta.clone();
        theta.sort_by(|x, y| y.total_cmp(x));
        for (j, t) in theta.iter().enumerate() {
            let want = 1.0 / (closed_form(j + 1, n + 1) + 1.0);
            assert!((t - want).abs() < 1e-12 * want, "nev = {nev}, j = {j}");
        }
    }
    assert!(LanczosKernel::SINGLE.largest(&op, 3, 0.0, 50).is_err());
}

#[test]
fn registered_with_no_parameters() {
    let mut reg = Registry::new();
    register(&mut reg);
    assert_eq!(reg.eigen.names(), vec!["krylov".to_string()]);
    let (name, desc) = &reg.eigen.describe()[0];
    assert_eq!(name, "krylov");
    assert!(desc.contains("Lanczos"));
    let solver = reg.eigen.create("krylov", &Params::new()).unwrap();
    assert_eq!(solver.name(), "krylov");
    assert_refused(&reg, "ncv", 40.0);
}

/// Creating `krylov` with `key = value` fails with an error that names `key`.
fn assert_refused(reg: &Registry, key: &str, value: f64) {
    let e = reg
        .eigen
        .create("krylov", &Params::new().with_num(key, value))
        .err()
        .unwrap_or_else(|| panic!("{key} = {value} must be rejected"))
        .to_string();
    assert!(e.contains(key), "{e}");
}

#[test]
fn validation_recovers_copies_invisible_to_the_first_krylov_space() {
    // Two identical chains and a start vector identical on both: every Krylov vector is
    // symmetric, so the antisymmetric copy of each doublet is invisible to the first run.
    let half = 150;
    let n = 2 * half;
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    for off in [0, half] {
        chain_k(&mut kt, off, half, |_| K, true);
        chain_m(&mut mt, off, half, false);
    }
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let exact: Vec<f64> = (1..=half).map(|j| closed_form(j, half + 1)).collect();
    let sigma = -exact[0];
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), sigma).unwrap();
    let start: Vec<f64> = (0..n)
        .map(|i| 1.0 + 0.1 * ((i % half) as f64).sin())
        .collect();
    let nev = 24;

    let mut ctx = Ctx {
        op: &op,
        tol: 1e-12,
        max_restarts: 300,
        restarts: 0,
        dirs: Directions::new(),
    };
    let first = ctx.run(&Pairs::new(n), nev, start.clone(), None).unwrap();
    assert!(first.complete);
    let mut lam: Vec<f64> = first
        .pairs
        .theta
        .iter()
        .map(|&t| op.pencil_eigenvalue(t))
        .collect();
    lam.sort_by(f64::total_cmp);
    // The first run alone: one copy of each of the 24 lowest distinct values.
    assert!(max_rel_err(&lam, &exact[..nev]) < 1e-10, "{lam:?}");

    let out = largest_from(&op, nev, 1e-12, 300, start).unwrap();
    assert!(out.all_converged);
    let mut lam: Vec<f64> = out.theta.iter().map(|&t| op.pencil_eigenvalue(t)).collect();
    lam.sort_by(f64::total_cmp);
    let want: Vec<f64> = exact[..nev / 2].iter().flat_map(|&l| [l, l]).collect();
    let err = max_rel_err(&lam, &want);
    eprintln!(
        "symmetric start: {} restarts, {} applications, max relative error {err:.2e}",
        out.iterations,
        op.applications()
    );
    assert!(err < 1e-10, "{lam:?}");
}

#[test]
fn square_membrane_doublets_match_closed_form() {
    // Fixed square grid of springs: K = k (T x I + I x T), M = m I. Modes (i, j) and
    // (j, i) are exact doublets, coupled through the whole matrix (no block structure).
    let g = 25;
    let n = g * g;
    let id = |r: usize, c: usize| r * g + c;
    let mut kt = Vec::new();
    for r in 0..g {
        for c in 0..g {
            kt.push(Triplet::new(id(r, c), id(r, c), 4.0 * K));
            if c + 1 < g {
                kt.push(Triplet::new(id(r, c), id(r, c + 1), -K));
                kt.push(Triplet::new(id(r, c + 1), id(r, c), -K));
            }
            if r + 1 < g {
                kt.push(Triplet::new(id(r, c), id(r + 1, c), -K));
                kt.push(Triplet::new(id(r + 1, c), id(r, c), -K));
            }
        }
    }
    let mut mt = Vec::new();
    chain_m(&mut mt, 0, n, false);
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let mut exact: Vec<f64> = (1..=g)
        .flat_map(|i| (1..=g).map(move |j| closed_form(i, g + 1) + closed_form(j, g + 1)))
        .collect();
    exact.sort_by(f64::total_cmp);
    // Band top between two distinct values, about 40 modes.
    let count = (40..exact.len())
        .find(|&c| exact[c] > exact[c - 1] * (1.0 + 1e-6))
        .unwrap();
    let fmax = 0.5 * (hz(exact[count - 1]) + hz(exact[count]));
    let modes = solve(&k, &m, &params(fmax));
    let err = max_rel_err(&modes.omega2, &exact[..count]);
    eprintln!("membrane: {count} modes, max relative error {err:.2e}");
    assert!(err < 1e-10, "max relative error {err:e}");
    assert_residuals(&modes);
    assert_eq!(modes.info.reason, StopReason::Converged);
    assert_m_orthonormal(&modes.vectors, &m, 1e-9);
}

/// The two identical chains with consistent mass and varying springs of
/// `consistent_mass_doublets_match_dense_oracle`: exact doublets.
fn twin_chains(half: usize) -> (SparseMat, SparseMat) {
    let spring = |s: usize| K * (1.0 + 0.3 * (s as f64).sin());
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    for off in [0, half] {
        chain_k(&mut kt, off, half, spring, true);
        chain_m(&mut mt, off, half, true);
    }
    (sparse(2 * half, &kt), sparse(2 * half, &mt))
}

/// [`twin_chains`] and their whole spectrum by the dense oracle, ascending.
fn twin_chains_and_spectrum(half: usize) -> (SparseMat, SparseMat, Vec<f64>) {
    let (k, m) = twin_chains(half);
    let problem = SymmetricProblem {
        k: k.as_ref(),
        m: m.as_ref(),
    };
    let (mut dense, _) = dense_symmetric(&problem).unwrap();
    dense.sort_by(f64::total_cmp);
    (k, m, dense)
}

#[test]
fn block_kernel_finds_doublets_and_matches_the_dense_oracle() {
    let (k, m, dense) = twin_chains_and_spectrum(200);
    let sigma = -0.1 * dense[0];
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), sigma).unwrap();
    for block in [2, 5, 8] {
        let nev = 20;
        let out = LanczosKernel { block }
            .largest(&op, nev, 1e-12, 100)
            .unwrap();
        assert!(out.all_converged, "block {block}");
        assert_eq!(out.theta.len(), nev, "block {block}");
        let mut lam: Vec<f64> = out.theta.iter().map(|&t| op.pencil_eigenvalue(t)).collect();
        lam.sort_by(f64::total_cmp);
        let err = max_rel_err(&lam, &dense[..nev]);
        eprintln!(
            "block {block}: {} restarts, max relative error {err:.2e}",
            out.iterations
        );
        assert!(err < 1e-10, "block {block}: max relative error {err:e}");
        assert_m_orthonormal(&out.vectors, &m, 1e-9);
    }
}

#[test]
fn block_and_single_vector_solvers_agree_through_the_band_driver() {
    let (k, m, dense) = twin_chains_and_spectrum(150);
    let count = 30;
    let fmax = 0.5 * (hz(dense[count - 1]) + hz(dense[count]));
    let block = solve(&k, &m, &params(fmax));
    let single = solve_with(&SINGLE, &k, &m, &params(fmax));
    assert_eq!(block.omega2.len(), count);
    assert_eq!(single.omega2.len(), count);
    assert!(max_rel_err(&block.omega2, &dense[..count]) < 1e-10);
    assert!(max_rel_err(&single.omega2, &dense[..count]) < 1e-10);
    assert_residuals(&block);
    assert_eq!(block.info.reason, StopReason::Converged);
    assert_m_orthonormal(&block.vectors, &m, 1e-9);
}

#[test]
fn block_kernel_restart_cap_returns_only_converged_pairs() {
    // M = I, K = diag: twenty well separated eigenvalues, then a cluster of a hundred of
    // relative width 1e-5 that the fortieth pair falls in, then the rest of the spectrum.
    // One basis without a restart converges the twenty, not the cluster.
    let n = 3000;
    let exact: Vec<f64> = (0..n)
        .map(|i| match i {
            0..20 => 1.0 + i as f64,
            20..120 => 100.0 * (1.0 + 1e-7 * (i - 20) as f64),
            _ => 1.0e3 + i as f64,
        })
        .collect();
    let kt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, exact[i])).collect();
    let mt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), -0.5).unwrap();
    let out = LanczosKernel { block: 4 }
        .largest(&op, 40, 1e-12, 0)
        .unwrap();
    assert_capped(&out, &op, 40, &exact);
    assert!(out.theta.len() >= 20, "{}", out.theta.len());
}

#[test]
fn block_kernel_replaces_exhausted_directions() {
    // M = I, K = diag with three values of multiplicity 80: the block Krylov space of 8
    // start vectors has dimension 24 (8 copies of each value), so later blocks break
    // down and take fresh directions. A Krylov method holds at most the block size of
    // copies of one eigenvalue: 8 are all the lowest value; asking 16 returns true
    // eigenpairs, M-orthonormal, whatever mix of values the fresh directions reach.
    let n = 240;
    let values = [1.0e4, 4.0e4, 9.0e4];
    let kt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, values[i % 3])).collect();
    let mt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), -1.0e3).unwrap();
    let kernel = LanczosKernel { block: 8 };
    let out = kernel.largest(&op, 8, 1e-12, 50).unwrap();
    assert!(out.all_converged);
    assert_eq!(out.theta.len(), 8);
    for t in &out.theta {
        let l = op.pencil_eigenvalue(*t);
        assert!((l - 1e4).abs() < 1e-10 * 1e4, "{l}");
    }
    assert_m_orthonormal(&out.vectors, &m, 1e-10);
    let out = kernel.largest(&op, 16, 1e-12, 50).unwrap();
    assert_eq!(out.theta.len(), 16);
    for (j, t) in out.theta.iter().enumerate() {
        let l = op.pencil_eigenvalue(*t);
        assert!(
            values.iter().any(|v| (l - v).abs() < 1e-10 * v),
            "pair {j}: {l} is no eigenvalue"
        );
        let x: Vec<f64> = out.vectors.col(j).iter().copied().collect();
        let kx: Vec<f64> = (0..n).map(|i| values[i % 3] * x[i]).collect();
        let r = kx
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - l * b).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(r < 1e-8 * l, "pair {j}: residual {r:e}");
    }
    assert_m_orthonormal(&out.vectors, &m, 1e-10);
}

#[test]
fn block_parameter_is_read_and_checked() {
    let mut reg = Registry::new();
    register(&mut reg);
    assert!(reg
        .eigen
        .create("krylov", &Params::new().with_num("block", 4.0))
        .is_ok());
    assert_refused(&reg, "block", 0.0);
}

#[test]
fn calls_above_the_block_pair_cap_take_the_single_vector_kernel() {
    let n = 3000;
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    chain_k(&mut kt, 0, n, |_| K, true);
    chain_m(&mut mt, 0, n, false);
    let (k, m) = (sparse(n, &kt), sparse(n, &mt));
    let exact = fixed_chain_spectrum(n);
    let op = ShiftInvert::new(k.as_ref(), m.as_ref(), -exact[0]).unwrap();
    let above = BLOCK_MAX_NEV + 4;
    let block = LanczosKernel { block: 8 }
        .largest(&op, above, 1e-10, 300)
        .unwrap();
    let single = LanczosKernel::SINGLE
        .largest(&op, above, 1e-10, 300)
        .unwrap();
    // the same path: the same pairs to the last bit, all of them true eigenvalues
    assert!(block.all_converged);
    assert_eq!(block.theta, single.theta);
    let lam: Vec<f64> = block
        .theta
        .iter()
        .map(|&t| op.pencil_eigenvalue(t))
        .collect();
    assert_true_eigenvalues(&lam, &exact, 1e-9);
    // at the cap the block kernel runs: another path, the same eigenvalues
    let at = LanczosKernel { block: 8 }
        .largest(&op, BLOCK_MAX_NEV, 1e-10, 300)
        .unwrap();
    let at_single = LanczosKernel::SINGLE
        .largest(&op, BLOCK_MAX_NEV, 1e-10, 300)
        .unwrap();
    assert!(at.all_converged);
    assert_ne!(at.theta, at_single.theta);
    let lam: Vec<f64> = at.theta.iter().map(|&t| op.pencil_eigenvalue(t)).collect();
    assert_true_eigenvalues(&lam, &exact, 1e-9);
}

/// The modes of a nearby problem (one chain's springs stiffened by 10 % over a stretch,
/// as a contact set that ties a few more pairs) as the start: the same modes to the
/// tolerance, from fewer applications of `OP` than the pseudo-random start.
#[test]
fn a_nearby_problems_modes_start_the_band_with_fewer_applications() {
    let half = 400;
    let (k0, m) = twin_chains(half);
    let spring = |s: usize| {
        let stiffer = if (100..140).contains(&s) { 1.1 } else { 1.0 };
        K * (1.0 + 0.3 * (s as f64).sin()) * stiffer
    };
    let mut kt = Vec::new();
    chain_k(&mut kt, 0, half, spring, true);
    chain_k(
        &mut kt,
        half,
        half,
        |s| K * (1.0 + 0.3 * (s as f64).sin()),
        true,
    );
    let k1 = sparse(2 * half, &kt);
    fn p<'a>(k: &'a SparseMat, m: &'a SparseMat) -> SymmetricProblem<'a> {
        SymmetricProblem {
            k: k.as_ref(),
            m: m.as_ref(),
        }
    }
    let (mut exact, _) = dense_symmetric(&p(&k1, &m)).unwrap();
    exact.sort_by(f64::total_cmp);
    let count = 40;
    let fmax = 0.5 * (hz(exact[count - 1]) + hz(exact[count]));
    let params = params(fmax);
    let before = KRYLOV.solve_symmetric(&p(&k0, &m), &params).unwrap();
    assert!(before.omega2.len() >= count - 2);
    let sigma = -0.1 * exact[0];
    let solve = |start: Option<MatRef<'_, f64>>| {
        let op = ShiftInvert::new(k1.as_ref(), m.as_ref(), sigma).unwrap();
        KRYLOV
            .solve_symmetric_on(&p(&k1, &m), &op, start, &params)
            .unwrap()
    };
    let fresh = solve(None);
    // the band's modes and the pairs above it the solve found
    let (band, above) = (&before.vectors, &before.above_band);
    assert!(above.ncols() > 0 && above.ncols() <= squeal_core::eigen::ABOVE_BAND_KEPT);
    let start = squeal_core::linalg::hcat(band.as_ref(), above.as_ref());
    let started = solve(Some(start.as_ref()));
    eprintln!(
        "fresh: {} applications, {} restarts; from the nearby modes ({}): {} applications, {} \
         restarts, notes {:?}",
        fresh.info.op_applications,
        fresh.info.iterations,
        before.omega2.len(),
        started.info.op_applications,
        started.info.iterations,
        started.info.notes
    );
    for modes in [&fresh, &started] {
        assert_eq!(modes.omega2.len(), count);
        assert!(max_rel_err(&modes.omega2, &exact[..count]) < 1e-10);
        assert_residuals(modes);
        assert_m_orthonormal(&modes.vectors, &m, 1e-9);
    }
    assert!(started.info.notes.iter().any(|n| n.contains("nearby")));
    assert!(
        started.info.op_applications < fresh.info.op_applications,
        "{} >= {}",
        started.info.op_applications,
        fresh.info.op_applications
    );
}
