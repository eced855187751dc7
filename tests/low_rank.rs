//! The low-rank (Woodbury) path of undamped frictional operators
//! (`squeal_core::lowrank`), on a coarse build of the default scene:
//!
//! - `U W(s)^T` reproduces `F_K - s F_M` to round-off;
//! - the Woodbury application of `A(s)^-1 M~` equals the sparse-LU one to 1e-10, for a
//!   shift below the spectrum and for indefinite shifts inside it;
//! - the band solve through the low-rank path (`LowRank::Always`) gives the same
//!   eigenvalues as the LU path (`LowRank::Never`) at mu = 0.3 and 0.7, and says so.

use squeal::analysis::pipeline::Prepared;
use squeal::core::faer::sparse::Triplet;
use squeal::core::lowrank::{FrictionLowRank, SymmetricPencil, SymmetricShift};
use squeal::core::operator::ComplexModes;
use squeal::core::qep::{solve_frictional_band_with, LowRank, QepBandOptions};
use squeal::core::spectral::{LinOp, SpectralTransform, SquaredShift};
use squeal::core::{c64, EigenParams, FrictionalOperator, SparseMat};
use squeal::scene::Scene;
use std::sync::{Arc, OnceLock};

fn coarse() -> Scene {
    Scene::builtin("pin-on-disc-coarse").unwrap()
}

/// The coarse operator (equilibrium at mu = 0.7), built once for all tests.
fn operator() -> &'static FrictionalOperator {
    static OP: OnceLock<FrictionalOperator> = OnceLock::new();
    OP.get_or_init(|| {
        let reg = squeal::registry();
        let prep = Prepared::new(&reg, coarse(), "coarse").unwrap();
        let eq = prep.equilibrium(&reg, "lcp", "lagrange", 0.7).unwrap();
        let op = prep.operator(&eq.eq.active).unwrap();
        assert!(op.cc.is_none() && op.fc.is_none(), "the scene is undamped");
        let u = op.friction_loads.as_ref().expect("friction_loads");
        assert!(u.ncols() >= 4, "only {} active pairs", u.ncols());
        op
    })
}

fn max_abs(a: &SparseMat) -> f64 {
    let a = a.as_ref();
    (0..a.ncols())
        .flat_map(|j| a.val_of_col(j).iter().map(|v| v.abs()))
        .fold(0.0, f64::max)
}

#[test]
fn u_w_transpose_reproduces_the_friction_part() {
    let op = operator();
    let n = op.dim();
    let fr = FrictionLowRank::new(op).unwrap();
    assert!(fr.identity_error <= 1e-13, "{}", fr.identity_error);
    for s in [0.0, 3.7e7, -1.2e9] {
        // F(s) = F_K - s F_M and U W(s)^T, entry by entry
        let f = squeal::core::linalg::add_scaled(op.fk.as_ref(), 1.0, op.fm.as_ref(), -s).unwrap();
        let w = squeal::core::linalg::add_scaled(fr.wk.as_ref(), 1.0, fr.wm.as_ref(), -s).unwrap();
        let (u, w) = (fr.u.as_ref(), w.as_ref());
        let mut trip = Vec::new();
        for p in 0..u.ncols() {
            for (i, a) in u.row_idx_of_col(p).zip(u.val_of_col(p)) {
                for (j, b) in w.row_idx_of_col(p).zip(w.val_of_col(p)) {
                    trip.push(Triplet::new(i, j, a * b));
                }
            }
        }
        let uw = SparseMat::try_new_from_triplets(n, n, &trip).unwrap();
        let diff = squeal::core::linalg::add_scaled(f.as_ref(), 1.0, uw.as_ref(), -1.0).unwrap();
        let (e, big) = (max_abs(&diff), max_abs(&f));
        assert!(big > 0.0);
        assert!(
            e <= 1e-13 * big,
            "s = {s}: |F - U W^T| = {e:e}, |F| = {big:e}"
        );
    }
}

/// Largest relative difference between the Woodbury and LU applications of
/// `A(s)^-1 M~` at `mu`, on three complex vectors.
fn woodbury_vs_lu(op: &FrictionalOperator, pencil: &Arc<SymmetricPencil>, mu: f64, s: f64) -> f64 {
    let n = op.dim();
    let qep = op.at(mu).unwrap();
    let fr = FrictionLowRank::new(op).unwrap();
    let shift = Arc::new(SymmetricShift::new(op, pencil.clone(), &fr, s).unwrap());
    let lr = SquaredShift::low_rank(&qep, shift, mu).unwrap();
    let lu = SquaredShift::lu(&qep, s).unwrap();
    let mut worst = 0.0f64;
    for k in 0..3 {
        let x: Vec<c64> = (0..n)
            .map(|i| {
                let t = (i * (k + 2)) as f64;
                c64::new((0.3 * t).sin() + 0.2, (0.7 * t).cos())
            })
            .collect();
        let (mut y1, mut y2) = (vec![c64::new(0.0, 0.0); n], vec![c64::new(0.0, 0.0); n]);
        lr.apply(&x, &mut y1);
        lu.apply(&x, &mut y2);
        let num: f64 = y1.iter().zip(&y2).map(|(a, b)| (a - b).norm_sqr()).sum();
        let den: f64 = y2.iter().map(|b| b.norm_sqr()).sum();
        worst = worst.max((num / den).sqrt());
    }
    assert_eq!(lr.applications(), 3);
    worst
}

#[test]
fn woodbury_apply_equals_lu_apply_for_definite_and_indefinite_shifts() {
    let op = operator();
    let pencil = Arc::new(SymmetricPencil::new(op).unwrap());
    assert!(pencil.asymmetry() <= 1e-12, "{}", pencil.asymmetry());
    let w = |f: f64| (2.0 * std::f64::consts::PI * f).powi(2);
    // below the spectrum (S positive definite), then inside it (S indefinite: the band
    // 0-2500 Hz holds many modes of the coarse model)
    for s in [-w(50.0), w(1234.5), w(2345.6)] {
        for mu in [0.3, 0.7] {
            let e = woodbury_vs_lu(op, &pencil, mu, s);
            assert!(
                e <= 1e-10,
                "s = {s:e}, mu = {mu}: relative difference {e:e}"
            );
        }
    }
}

fn band(op: &FrictionalOperator, mu: f64, low_rank: LowRank) -> ComplexModes {
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: 2500.0,
        tol: 1e-12,
        dense_below: 0,
        ..EigenParams::default()
    };
    let options = QepBandOptions {
        low_rank,
        ..QepBandOptions::default()
    };
    solve_frictional_band_with(
        "krylov",
        &squeal_eigen_krylov::KrylovSchurKernel,
        op,
        mu,
        &params,
        &options,
    )
    .unwrap()
}

#[test]
fn band_solve_low_rank_equals_lu() {
    let op = operator();
    for mu in [0.3, 0.7] {
        let lr = band(op, mu, LowRank::Always);
        let lu = band(op, mu, LowRank::Never);
        let says = |m: &ComplexModes| m.info.notes.iter().any(|s| s.contains("low-rank path"));
        assert!(says(&lr), "mu = {mu}: {:?}", lr.info.notes);
        assert!(!says(&lu), "mu = {mu}: {:?}", lu.info.notes);
        assert!(lu.len() >= 5, "mu = {mu}: {} modes", lu.len());
        assert_eq!(lr.len(), lu.len(), "mu = {mu}");
        // matched by nearest eigenvalue: the two members of a flutter pair share their
        // frequency, so their order in the two lists may differ
        for a in &lr.lambda {
            let b = lu
                .lambda
                .iter()
                .min_by(|x, y| (*x - a).norm().total_cmp(&(*y - a).norm()))
                .unwrap();
            let d = (a - b).norm() / b.norm();
            assert!(d <= 1e-9, "mu = {mu}: {a} vs {b} ({d:e})");
        }
        assert!(
            lr.backward_error.iter().all(|&e| e <= 1e-10),
            "mu = {mu}: {:?}",
            lr.backward_error
        );
    }
}

#[test]
fn always_refuses_an_operator_without_friction_loads() {
    let mut op = operator().clone();
    op.friction_loads = None;
    let params = EigenParams {
        fmax_hz: 2500.0,
        dense_below: 0,
        ..EigenParams::default()
    };
    let options = QepBandOptions {
        low_rank: LowRank::Always,
        ..QepBandOptions::default()
    };
    let err = solve_frictional_band_with(
        "krylov",
        &squeal_eigen_krylov::KrylovSchurKernel,
        &op,
        0.7,
        &params,
        &options,
    )
    .unwrap_err();
    assert!(err.to_string().contains("friction_loads"), "{err}");
}
