use super::residual::{backward_errors, QepNorms, QepTerms};
use super::*;
use crate::eigen::EigenParams;
use crate::operator::{ComplexModes, FrictionalOperator, Qep, SolveInfo, StopReason};
use crate::spectral::{LinOp, QepShiftInvert, QepSymbolic, SpectralTransform};
use crate::{c64, Error, Result, SparseMat};
use faer::linalg::solvers::Solve;
use faer::sparse::Triplet;
use faer::Mat;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn info(solver: &str) -> SolveInfo {
    SolveInfo::new(solver)
}

fn c(re: f64, im: f64) -> c64 {
    c64::new(re, im)
}

/// Deterministic pseudo-random numbers in [-1, 1] (SplitMix64).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

fn sparse(a: &Mat<f64>) -> SparseMat {
    let mut t = Vec::new();
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            if a[(i, j)] != 0.0 {
                t.push(Triplet::new(i, j, a[(i, j)]));
            }
        }
    }
    SparseMat::try_new_from_triplets(a.nrows(), a.ncols(), &t).unwrap()
}

fn dense_of(rows: &[&[f64]]) -> Mat<f64> {
    Mat::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j])
}

/// A random QEP: `M` SPD, `K` SPD plus a non-symmetric part, `C` random (damped).
fn random_qep(n: usize, seed: u64, damped: bool) -> Qep {
    let mut rng = Rng(seed);
    let r = Mat::from_fn(n, n, |_, _| rng.next());
    let m = Mat::<f64>::identity(n, n) + &r * r.transpose() * faer::Scale(0.1 / n as f64);
    let b = Mat::from_fn(n, n, |_, _| rng.next());
    let k = &b * b.transpose()
        + Mat::<f64>::identity(n, n) * faer::Scale(n as f64)
        + Mat::from_fn(n, n, |_, _| 0.3 * rng.next());
    let cm = Mat::from_fn(n, n, |_, _| 0.2 * rng.next());
    Qep {
        m: sparse(&m),
        c: damped.then(|| sparse(&cm)),
        k: sparse(&k),
    }
}

/// `det` of a small dense matrix by Gaussian elimination with partial pivoting.
fn det(a: &Mat<f64>) -> f64 {
    let n = a.nrows();
    let mut a = a.clone();
    let mut d = 1.0;
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[(i, k)].abs().total_cmp(&a[(j, k)].abs()))
            .unwrap();
        if p != k {
            for j in 0..n {
                let t = a[(k, j)];
                a[(k, j)] = a[(p, j)];
                a[(p, j)] = t;
            }
            d = -d;
        }
        d *= a[(k, k)];
        for i in k + 1..n {
            let f = a[(i, k)] / a[(k, k)];
            for j in k..n {
                let v = a[(k, j)];
                a[(i, j)] -= f * v;
            }
        }
    }
    d
}

/// Companion matrices `A = [0 I; -K -C]`, `B = [I 0; 0 M]`, complex dense.
fn companion(qep: &Qep) -> (Mat<c64>, Mat<c64>) {
    let n = qep.dim();
    let k = qep.k.as_ref().to_dense();
    let m = qep.m.as_ref().to_dense();
    let cm = qep
        .c
        .as_ref()
        .map_or(Mat::zeros(n, n), |c| c.as_ref().to_dense());
    let a = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => c(0.0, 0.0),
        (true, false) => c(if j - n == i { 1.0 } else { 0.0 }, 0.0),
        (false, true) => c(-k[(i - n, j)], 0.0),
        (false, false) => c(-cm[(i - n, j - n)], 0.0),
    });
    let b = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => c(if i == j { 1.0 } else { 0.0 }, 0.0),
        (false, false) => c(m[(i - n, j - n)], 0.0),
        _ => c(0.0, 0.0),
    });
    (a, b)
}

fn materialize(op: &dyn LinOp<c64>) -> Mat<c64> {
    let nn = op.dim();
    let mut out = Mat::<c64>::zeros(nn, nn);
    let mut e = vec![c(0.0, 0.0); nn];
    let mut y = vec![c(0.0, 0.0); nn];
    for j in 0..nn {
        e[j] = c(1.0, 0.0);
        op.apply(&e, &mut y);
        e[j] = c(0.0, 0.0);
        for i in 0..nn {
            out[(i, j)] = y[i];
        }
    }
    out
}

fn max_abs(a: faer::MatRef<'_, c64>) -> f64 {
    let mut m = 0.0f64;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            m = m.max(a[(i, j)].norm());
        }
    }
    m
}

#[test]
fn shift_invert_equals_dense_companion_resolvent() {
    let qep = random_qep(8, 7, true);
    let (a, b) = companion(&qep);
    let sym = QepSymbolic::new(&qep).unwrap();
    for (k, sigma) in [c(0.3, 1.7), c(0.0, 4.2), c(-0.5, 0.0)]
        .into_iter()
        .enumerate()
    {
        let shifted = &a - &b * faer::Scale(sigma);
        let r = shifted.partial_piv_lu().solve(&b);
        let op = if k == 0 {
            QepShiftInvert::new(&qep, sigma).unwrap()
        } else {
            QepShiftInvert::with_symbolic(&qep, sigma, &sym).unwrap()
        };
        assert_eq!(op.dim(), 16);
        let opm = materialize(&op);
        assert_eq!(op.applications(), 16);
        let err = max_abs((&opm - &r).as_ref());
        assert!(
            err <= 1e-12 * max_abs(r.as_ref()),
            "sigma = {sigma}: |OP - (A - sigma B)^-1 B| = {err:e}"
        );
    }
}

#[test]
fn shift_invert_on_an_eigenvalue_is_a_clear_error() {
    let k = sparse(&dense_of(&[&[1.0, 0.0], &[0.0, 4.0]]));
    let m = sparse(&Mat::<f64>::identity(2, 2));
    let qep = Qep { m, c: None, k };
    // lambda = i is an eigenvalue: Q(i) = -M + K = diag(0, 3).
    match QepShiftInvert::new(&qep, c(0.0, 1.0)) {
        Err(Error::Factorization { what, .. }) => assert!(what.contains("Q(sigma)"), "{what}"),
        Err(e) => panic!("wrong error {e}"),
        Ok(_) => panic!("singular Q(sigma) must be rejected"),
    }
}

fn hoffmann() -> FrictionalOperator {
    let empty = SparseMat::try_new_from_triplets(2, 2, &[]).unwrap();
    FrictionalOperator {
        mc: sparse(&Mat::<f64>::identity(2, 2)),
        cc: None,
        kc: sparse(&dense_of(&[&[1.0, 0.1], &[0.1, 1.2]])),
        fm: empty,
        fc: None,
        fk: sparse(&dense_of(&[&[0.0, 1.0], &[0.0, 0.0]])),
        t: None,
        friction_loads: None,
        modal: Default::default(),
    }
}

/// Roots with `Im > 0` of `det(lambda^2 I + K(mu)) = 0`, from the characteristic
/// polynomial `s^2 + (k11 + k22) s + k11 k22 - (k12 - mu kH) k21`, `s = lambda^2`.
fn hoffmann_closed_form(mu: f64) -> Vec<c64> {
    let (k11, k22, k12, k21, kh) = (1.0, 1.2, 0.1, 0.1, 1.0);
    let b = k11 + k22;
    let cc = k11 * k22 - (k12 - mu * kh) * k21;
    let disc = c(b * b - 4.0 * cc, 0.0).sqrt();
    let mut out: Vec<c64> = [(-b + disc) * 0.5, (c(-b, 0.0) - disc) * 0.5]
        .iter()
        .map(|&s| {
            let l = s.sqrt();
            if l.im < 0.0 {
                -l
            } else {
                l
            }
        })
        .collect();
    out.sort_by(|a, b| a.im.total_cmp(&b.im));
    out
}

struct PanicKernel;
impl ComplexKernel for PanicKernel {
    fn largest(
        &self,
        _: &dyn LinOp<c64>,
        _: usize,
        _: f64,
        _: usize,
    ) -> Result<ComplexKernelOutput> {
        panic!("a 2-DOF problem must be solved densely");
    }
}

#[test]
fn hoffmann_two_dof_matches_closed_form() {
    let op = hoffmann();
    let (k11, k22, k12, k21, kh) = (1.0, 1.2, 0.1, 0.1, 1.0);
    let mu_c = ((k11 - k22) * (k11 - k22) + 4.0 * k12 * k21) / (4.0 * k21 * kh);
    assert!((mu_c - 0.2f64).abs() < 1e-14);
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: 1.0,
        ..Default::default()
    };

    // mu = 0.3: the closed form gives lambda = +-0.04762 + 1.04989 i.
    let qep = op.at(0.3).unwrap();
    let modes = solve_qep_band("test", &PanicKernel, &qep, &params).unwrap();
    assert!(
        modes
            .info
            .notes
            .iter()
            .any(|s| s.contains("solved densely instead of `test`")),
        "{:?}",
        modes.info.notes
    );
    let exact = hoffmann_closed_form(0.3);
    assert!((exact[0].re.abs() - 0.04762).abs() < 1e-5 && (exact[0].im - 1.04989).abs() < 1e-5);
    assert_eq!(modes.len(), 2);
    let mut got = modes.lambda.clone();
    got.sort_by(|a, b| a.re.total_cmp(&b.re));
    let mut want = exact.clone();
    want.sort_by(|a, b| a.re.total_cmp(&b.re));
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).norm() <= 1e-10, "{g} vs {w}");
    }
    for i in 0..2 {
        assert!(
            modes.backward_error[i] <= 1e-14,
            "{:?}",
            modes.backward_error
        );
        assert!((modes.freq_hz[i] - modes.lambda[i].im / TWO_PI).abs() < 1e-15);
        assert!((modes.dvr[i] - modes.lambda[i].re / modes.lambda[i].im).abs() < 1e-15);
    }
    assert_eq!((0..2).filter(|&i| modes.is_unstable(i, 1e-10)).count(), 1);

    // T1 (mu = 0) and just below mu_c: no instability; just above: exactly one.
    for (mu, unstable) in [
        (0.0, 0),
        (0.19, 0),
        (mu_c * (1.0 - 1e-3), 0),
        (mu_c * (1.0 + 1e-3), 1),
    ] {
        let qep = op.at(mu).unwrap();
        let modes = solve_qep_band("test", &PanicKernel, &qep, &params).unwrap();
        assert_eq!(modes.len(), 2, "mu = {mu}");
        let n_unstable = (0..modes.len())
            .filter(|&i| modes.is_unstable(i, 1e-10))
            .count();
        assert_eq!(n_unstable, unstable, "mu = {mu}: {:?}", modes.lambda);
        let want = hoffmann_closed_form(mu);
        for w in &want {
            let d = modes
                .lambda
                .iter()
                .map(|g| (g - w).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 1e-10, "mu = {mu}: {w} not found in {:?}", modes.lambda);
        }
    }
}

#[test]
fn dense_qep_random_damped_pencils() {
    for (seed, n) in [(1u64, 6usize), (2, 9), (3, 14)] {
        let qep = random_qep(n, seed, true);
        let (lam, u) = dense_qep(&qep).unwrap();
        assert_eq!(lam.len(), 2 * n, "M is invertible: 2n finite roots");
        for k in 0..lam.len() {
            let uk: Vec<c64> = (0..n).map(|r| u[(r, k)]).collect();
            let be = backward_error(&qep, lam[k], &uk);
            assert!(be <= 1e-12, "seed {seed}: eta = {be:e} for {}", lam[k]);
        }
        // Trace and determinant of the companion matrix B^-1 A:
        // sum lambda = -tr(M^-1 C), prod lambda = det K / det M.
        let m = qep.m.as_ref().to_dense();
        let k = qep.k.as_ref().to_dense();
        let cm = qep.c.as_ref().unwrap().as_ref().to_dense();
        let minv_c = m.partial_piv_lu().solve(&cm);
        let tr: f64 = (0..n).map(|i| minv_c[(i, i)]).sum();
        let sum: c64 = lam.iter().fold(c(0.0, 0.0), |a, &b| a + b);
        let scale: f64 = lam.iter().map(|l| l.norm()).sum();
        assert!(
            (sum - c(-tr, 0.0)).norm() <= 1e-12 * scale,
            "{sum} vs {}",
            -tr
        );
        let prod: c64 = lam.iter().fold(c(1.0, 0.0), |a, &b| a * b);
        let want = det(&k) / det(&m);
        assert!(
            (prod - c(want, 0.0)).norm() <= 1e-10 * want.abs(),
            "{prod} vs {want}"
        );
    }
}

#[test]
fn dense_qep_undamped_branch_matches_the_companion_form() {
    // C = 0 takes the n x n branch (M^-1 K); the same pencil with an explicit zero C
    // takes the 2n companion: same roots, small backward errors, +-lambda pairs
    for (seed, n) in [(4u64, 5usize), (5, 11), (6, 17)] {
        let qep = random_qep(n, seed, false);
        let (lam, u) = dense_qep(&qep).unwrap();
        assert_eq!(lam.len(), 2 * n);
        let zero = Qep {
            c: Some(sparse(&Mat::<f64>::zeros(n, n))),
            ..qep.clone()
        };
        let (want, _) = dense_qep(&zero).unwrap();
        let scale = want.iter().map(|l| l.norm()).fold(0.0, f64::max);
        for k in 0..lam.len() {
            let uk: Vec<c64> = (0..n).map(|r| u[(r, k)]).collect();
            let be = backward_error(&qep, lam[k], &uk);
            assert!(be <= 1e-12, "seed {seed}: eta = {be:e} for {}", lam[k]);
            let d = want
                .iter()
                .map(|w| (w - lam[k]).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                d <= 1e-10 * scale,
                "seed {seed}: {} not a companion root",
                lam[k]
            );
            assert!(lam.iter().any(|l| (l + lam[k]).norm() <= 1e-12 * scale));
        }
    }
}

#[test]
fn dense_qep_rigid_body_root_is_zero_and_dropped() {
    // Free-free chain of 3 unit masses: K singular, omega^2 = 0, 1, 3.
    let k = sparse(&dense_of(&[
        &[1.0, -1.0, 0.0],
        &[-1.0, 2.0, -1.0],
        &[0.0, -1.0, 1.0],
    ]));
    let m = sparse(&Mat::<f64>::identity(3, 3));
    let params = EigenParams::default();
    for damping in [None, Some(0.01), Some(-0.1)] {
        // Some(a > 0): C = a K (rigid motion undamped); Some(a < 0): C = |a| M.
        let cmat = damping.map(|a: f64| {
            if a > 0.0 {
                crate::linalg::add_scaled(k.as_ref(), a, k.as_ref(), 0.0).unwrap()
            } else {
                crate::linalg::add_scaled(m.as_ref(), -a, m.as_ref(), 0.0).unwrap()
            }
        });
        let qep = Qep {
            m: m.clone(),
            c: cmat,
            k: k.clone(),
        };
        let (lam, u) = dense_qep(&qep).unwrap();
        assert_eq!(lam.len(), 6);
        let zeros = lam.iter().filter(|l| l.re == 0.0 && l.im == 0.0).count();
        let want_zeros = if damping.is_some_and(|a| a < 0.0) {
            1
        } else {
            2
        };
        assert_eq!(zeros, want_zeros, "{damping:?}: {lam:?}");
        let modes = finish_modes(&qep, &lam, u.as_ref(), &params, info("test")).unwrap();
        assert_eq!(modes.len(), 2, "{damping:?}: {:?}", modes.lambda);
        for (i, w2) in [1.0f64, 3.0].iter().enumerate() {
            // |lambda|^2 = omega^2 for Rayleigh and mass damping alike.
            assert!(
                (modes.lambda[i].norm_sqr() - w2).abs() < 1e-12,
                "{:?}",
                modes.lambda
            );
            assert!(modes.backward_error[i] < 1e-14);
            let nrm: f64 = (0..3).map(|r| modes.vectors[(r, i)].norm_sqr()).sum();
            assert!((nrm - 1.0).abs() < 1e-14);
        }
    }
}

#[test]
fn dense_qep_singular_mass_is_a_clear_error() {
    let k = sparse(&Mat::<f64>::identity(2, 2));
    let m = sparse(&dense_of(&[&[1.0, 0.0], &[0.0, 0.0]]));
    let e = dense_qep(&Qep { m, c: None, k }).unwrap_err().to_string();
    assert!(e.contains("singular mass"), "{e}");
}

/// A legitimate kernel for small operators: the operator materialized column by column
/// and diagonalized densely.
struct DenseOpKernel;
impl ComplexKernel for DenseOpKernel {
    fn largest(
        &self,
        op: &dyn LinOp<c64>,
        nev: usize,
        _tol: f64,
        _max_restarts: usize,
    ) -> Result<ComplexKernelOutput> {
        let a = materialize(op);
        let eig = a.eigen().unwrap();
        let mut idx: Vec<usize> = (0..a.nrows()).collect();
        idx.sort_by(|&i, &j| eig.S()[j].norm().total_cmp(&eig.S()[i].norm()));
        idx.truncate(nev);
        Ok(ComplexKernelOutput {
            theta: idx.iter().map(|&i| eig.S()[i]).collect(),
            vectors: Mat::from_fn(a.nrows(), idx.len(), |r, k| eig.U()[(r, idx[k])]),
            iterations: 1,
            all_converged: true,
        })
    }
}

/// Two identical 1-D chains of `n / 2` masses between fixed walls (every mode a doublet,
/// like a disc), coupled by circulatory (skew, friction-like) terms `-+ mu a` that split
/// doublets into flutter pairs, with light Rayleigh damping.
fn chain_qep(n: usize, mu: f64) -> Qep {
    let h = n / 2;
    let mut k = Mat::<f64>::zeros(n, n);
    for off in [0, h] {
        for i in 0..=h {
            let ks = 1e4 * (1.0 + 0.2 * (i as f64).cos());
            let (a, b) = (i.checked_sub(1), (i < h).then_some(i));
            if let Some(a) = a {
                k[(off + a, off + a)] += ks;
            }
            if let Some(b) = b {
                k[(off + b, off + b)] += ks;
            }
            if let (Some(a), Some(b)) = (a, b) {
                k[(off + a, off + b)] -= ks;
                k[(off + b, off + a)] -= ks;
            }
        }
    }
    let m = Mat::from_fn(n, n, |i, j| {
        if i == j {
            1.0 + 0.3 * ((i % h) as f64).sin()
        } else {
            0.0
        }
    });
    let mut kt = k.clone();
    for i in [10, 23, 37] {
        kt[(i, h + i)] -= mu * 1e3;
        kt[(h + i, i)] += mu * 1e3;
    }
    let cm = &k * faer::Scale(1e-7) + &m * faer::Scale(0.01);
    Qep {
        m: sparse(&m),
        c: Some(sparse(&cm)),
        k: sparse(&kt),
    }
}

fn assert_same_modes(a: &ComplexModes, b: &ComplexModes) {
    assert_eq!(a.len(), b.len(), "{:?}\n{:?}", a.freq_hz, b.freq_hz);
    for i in 0..a.len() {
        assert!(
            (a.lambda[i] - b.lambda[i]).norm() <= 1e-9 * a.lambda[i].norm(),
            "{i}: {} vs {}",
            a.lambda[i],
            b.lambda[i]
        );
        // The test kernel (dense eigen of the materialized operator) is accurate relative
        // to the largest |theta|: pairs far from the shift lose a few digits.
        assert!(a.backward_error[i] <= 1e-13, "{:?}", a.backward_error);
        assert!(b.backward_error[i] <= 1e-11, "{:?}", b.backward_error);
        let n = a.vectors.nrows();
        let dot: c64 = (0..n).fold(c(0.0, 0.0), |s, r| {
            s + a.vectors[(r, i)].conj() * b.vectors[(r, i)]
        });
        assert!(
            (dot.norm() - 1.0).abs() < 1e-8,
            "mode {i}: |<u_a, u_b>| = {}",
            dot.norm()
        );
    }
}

#[test]
fn band_driver_finds_every_mode_of_a_chain() {
    let qep = chain_qep(100, 0.4);
    let params = EigenParams {
        fmin_hz: 5.0,
        fmax_hz: 25.0,
        dense_below: 0,
        nev_hint: Some(4),
        ..Default::default()
    };
    let (lam, u) = dense_qep(&qep).unwrap();
    let info = info("dense");
    let reference = finish_modes(&qep, &lam, u.as_ref(), &params, info).unwrap();
    assert!(reference.len() >= 20, "{}", reference.len());
    assert!(
        (0..reference.len()).any(|i| reference.is_unstable(i, 1e-10)),
        "friction must destabilize a mode: {:?}",
        reference.dvr
    );

    let modes = solve_qep_band("dense-op", &DenseOpKernel, &qep, &params).unwrap();
    assert_same_modes(&reference, &modes);
    // one for the window, plus one per mode when the left eigenvectors (cond,
    // error_bound) come from inverse iteration rather than the transposed dense solve
    let f = modes.info.factorizations;
    assert!(f == 1 || f == 1 + modes.len(), "{f}");
    assert!(
        modes.info.requested > 4,
        "nev must have grown: {:?}",
        modes.info.notes
    );
    assert!(modes.info.op_applications >= 200);
    assert_eq!(modes.info.reason, StopReason::Converged);

    // Forced window splitting: at most 8 pairs per Krylov run.
    let opts = QepBandOptions {
        max_nev: 8,
        ..Default::default()
    };
    let sym = QepSymbolic::new(&qep).unwrap();
    let split =
        solve_qep_band_with("dense-op", &DenseOpKernel, &qep, &params, &opts, Some(&sym)).unwrap();
    assert_same_modes(&reference, &split);
    assert!(split.info.factorizations > 2, "{:?}", split.info.notes);
    assert!(split.info.notes.iter().any(|s| s.contains("split")));
    assert_eq!(split.info.reason, StopReason::Converged);
}

#[test]
fn band_driver_rejects_bad_band() {
    let qep = chain_qep(100, 0.0);
    let params = EigenParams {
        fmin_hz: 30.0,
        fmax_hz: 25.0,
        ..Default::default()
    };
    let e = solve_qep_band("x", &DenseOpKernel, &qep, &params)
        .unwrap_err()
        .to_string();
    assert!(e.contains("fmin_hz"), "{e}");
}

#[test]
fn finish_modes_normalizes_phase_and_sorts() {
    let qep = random_qep(5, 11, true);
    let (lam, u) = dense_qep(&qep).unwrap();
    // Same pairs, vectors scaled by arbitrary complex factors, reversed order.
    let rev: Vec<c64> = lam.iter().rev().cloned().collect();
    let nn = lam.len();
    let scaled = Mat::from_fn(5, nn, |r, k| u[(r, nn - 1 - k)] * c(-3.0, 2.0 + k as f64));
    let params = EigenParams {
        fmax_hz: 1e3,
        ..Default::default()
    };
    let a = finish_modes(&qep, &lam, u.as_ref(), &params, info("a")).unwrap();
    let b = finish_modes(&qep, &rev, scaled.as_ref(), &params, info("b")).unwrap();
    assert_eq!(a.len(), lam.iter().filter(|l| l.im > 0.0).count());
    assert!(a.freq_hz.windows(2).all(|w| w[0] <= w[1]));
    for i in 0..a.len() {
        assert_eq!(a.lambda[i], b.lambda[i]);
        let d = max_abs((a.vectors.col(i).as_mat() - b.vectors.col(i).as_mat()).as_ref());
        assert!(d < 1e-13, "phase normalization not deterministic: {d:e}");
    }
}

#[test]
fn batched_backward_errors_equal_the_single_ones() {
    for damped in [false, true] {
        let qep = random_qep(7, 23, damped);
        let (lam, u) = dense_qep(&qep).unwrap();
        // Perturbed pairs, so the errors are far from round-off and comparable.
        let lam: Vec<c64> = lam.iter().map(|l| *l * c(1.0 + 1e-3, 2e-4)).collect();
        let mut rng = Rng(5);
        let u = Mat::from_fn(7, lam.len(), |r, k| u[(r, k)] + c(1e-3 * rng.next(), 0.0));
        let norms = QepNorms::of(&qep);
        let batch = backward_errors(&QepTerms::of_qep(&qep), &norms, &lam, u.as_ref());
        assert_eq!(batch.len(), lam.len());
        for (j, l) in lam.iter().enumerate() {
            let col: Vec<c64> = (0..7).map(|r| u[(r, j)]).collect();
            let one = backward_error(&qep, *l, &col);
            assert!(one > 1e-8, "the perturbation should show: {one:e}");
            assert!(
                (batch[j] - one).abs() <= 1e-12 * one,
                "pair {j} (damped {damped}): batched {} vs single {one}",
                batch[j]
            );
        }
    }
}

#[test]
fn operator_modes_are_checked_on_the_parts_like_the_assembled_operator() {
    // A random operator whose friction parts overlap the symmetric ones partly.
    let (a, b) = (random_qep(6, 3, true), random_qep(6, 4, true));
    let lower = |m: &SparseMat, s: f64| {
        let d = m.to_dense();
        sparse(&Mat::from_fn(6, 6, |i, j| {
            if i > j + 1 {
                s * d[(i, j)]
            } else {
                0.0
            }
        }))
    };
    let op = FrictionalOperator {
        mc: a.m.clone(),
        cc: a.c.clone(),
        kc: a.k.clone(),
        fm: lower(&b.m, 0.3),
        fc: Some(lower(b.c.as_ref().unwrap(), 0.5)),
        fk: lower(&b.k, 2.0),
        t: None,
        friction_loads: None,
        modal: Default::default(),
    };
    let params = EigenParams {
        fmax_hz: 1e3,
        ..Default::default()
    };
    for mu in [0.0, 0.4, 1.3] {
        let full = op.at(mu).unwrap();
        let (lam, u) = dense_qep(&full).unwrap();
        let lam: Vec<c64> = lam.iter().map(|l| *l * c(1.0, 1e-4)).collect();
        let assembled = finish_modes(&full, &lam, u.as_ref(), &params, info("t")).unwrap();
        let mut parts =
            finish_operator_modes(&op, mu, &lam, u.as_ref(), &params, info("t")).unwrap();
        assert!(!assembled.is_empty());
        assert_eq!(assembled.lambda, parts.lambda);
        // without left vectors, only the modes whose class depends on them get `cond`;
        // condition numbers added afterwards equal those of the solve that computed them
        assert!(parts.left_vectors.is_none());
        for j in 0..parts.len() {
            let needs = crate::operator::needs_condition(
                parts.lambda[j],
                parts.backward_error[j],
                parts.cond_floor[j],
            );
            assert_eq!(!parts.cond[j].is_nan(), needs, "mu {mu}, mode {j}");
        }
        add_condition(&op, mu, &mut parts).unwrap();
        assert!(parts.left_vectors.is_some());
        for j in 0..parts.len() {
            let (x, y) = (assembled.error_bound[j], parts.error_bound[j]);
            assert!(x.is_finite() && x > 0.0, "mu {mu}: bound {x}");
            assert!((x - y).abs() <= 1e-8 * x, "mu {mu}: bound {x} vs added {y}");
            let (x, y) = (assembled.cond[j], parts.cond[j]);
            assert!((x - y).abs() <= 1e-8 * x, "mu {mu}: cond {x} vs added {y}");
        }
        for (x, y) in assembled.backward_error.iter().zip(&parts.backward_error) {
            assert!(*x > 1e-8, "the perturbation should show: {x:e}");
            assert!(
                (x - y).abs() <= 1e-12 * x,
                "mu {mu}: assembled {x} vs parts {y}"
            );
        }
    }
    assert!(finish_operator_modes(
        &op,
        f64::NAN,
        &[],
        Mat::zeros(6, 0).as_ref(),
        &params,
        info("t")
    )
    .is_err());
}

/// Timing probe (run with `--ignored --nocapture`): dense_qep at companion sizes 500
/// and 1000 on random damped pencils, with the worst backward error.
#[test]
#[ignore]
fn dense_qep_timing() {
    for n in [250, 500] {
        let qep = random_qep(n, 5, true);
        let t = std::time::Instant::now();
        let (lam, u) = dense_qep(&qep).unwrap();
        let dt = t.elapsed().as_secs_f64();
        let worst = (0..lam.len())
            .map(|k| {
                let uk: Vec<c64> = (0..n).map(|r| u[(r, k)]).collect();
                backward_error(&qep, lam[k], &uk)
            })
            .fold(0.0, f64::max);
        eprintln!(
            "dense_qep n = {n} (companion {}): {dt:.2} s, {} roots, worst eta {worst:.1e}",
            2 * n,
            lam.len()
        );
        assert_eq!(lam.len(), 2 * n);
    }
}

#[test]
fn band_pairs_drop_real_and_heavily_damped_roots_only() {
    let w = 2.0 * std::f64::consts::PI * 1000.0;
    let lambda = [
        c(-0.01 * w, w),        // lightly damped: kept
        c(0.05 * w, 1.1 * w),   // unstable: kept
        c(-0.99 * w, w),        // damping ratio 0.70: kept
        c(-1.01 * w, w),        // damping ratio 0.71 > 1/sqrt 2: dropped
        c(-5e5, 2.0),           // overdamped cluster member: dropped
        c(-3.0 * w, 1e-12 * w), // real root: dropped
        c(0.0, -w),             // conjugate member: dropped
    ];
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: 5000.0,
        ..EigenParams::default()
    };
    let kept: Vec<usize> = band_pairs(&lambda, &params).iter().map(|p| p.1).collect();
    assert_eq!(kept, vec![2, 0, 1]);
}
