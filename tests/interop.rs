//! The frictional operator of the coarse rig handed to a researcher's own sparse types
//! (`sprs::CsMat`, `nalgebra_sparse::CscMatrix`) and back:
//!
//! - a product `X(mu) x = (X_c - mu F_X) x` computed with the foreign type equals squeal's
//!   own to round-off, for every part;
//! - the operator rebuilt from the foreign parts gives the same unstable modes as the
//!   original (full-order `arpack`, mu = 0.7, where the coarse rig flutters).

use squeal::analysis::pipeline::Prepared;
use squeal::core::interop::{from_nalgebra, from_sprs, to_nalgebra, to_sprs, OperatorParts};
use squeal::core::linalg::spmv;
use squeal::core::{EigenParams, FrictionalOperator, Params, SparseMat};
use squeal::scene::Scene;

const MU: f64 = 0.7;

fn operator() -> FrictionalOperator {
    let reg = squeal::registry();
    let prep = Prepared::new(
        &reg,
        Scene::builtin("pin-on-disc-coarse").unwrap(),
        "coarse",
    )
    .unwrap();
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", MU).unwrap();
    prep.operator(&eq.eq.active).unwrap()
}

/// `(X_c - mu F_X) x` by squeal's product.
fn own(xc: &SparseMat, fx: &SparseMat, x: &[f64]) -> Vec<f64> {
    let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
    spmv(xc.as_ref(), x, &mut a);
    spmv(fx.as_ref(), x, &mut b);
    a.iter().zip(&b).map(|(a, b)| a - MU * b).collect()
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let num = a
        .iter()
        .zip(b)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    let den = a.iter().map(|a| a * a).sum::<f64>().sqrt();
    num / den
}

fn probe(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| ((i * 7919) % 1013) as f64 / 1013.0 - 0.5)
        .collect()
}

#[test]
fn foreign_products_equal_squeals_for_every_part() {
    let op = operator();
    let x = probe(op.dim());
    let pairs = [("M", &op.mc, &op.fm), ("K", &op.kc, &op.fk)];
    // sprs: CsMat * dense vector
    let s = op.parts_as(to_sprs);
    for ((name, xc, fx), (sx, sf)) in pairs.iter().zip([(&s.mc, &s.fm), (&s.kc, &s.fk)]) {
        let xs = sprs_times(sx, &x);
        let fs = sprs_times(sf, &x);
        let theirs: Vec<f64> = xs.iter().zip(&fs).map(|(a, b)| a - MU * b).collect();
        let d = rel_diff(&own(xc, fx, &x), &theirs);
        assert!(d < 1e-14, "sprs {name}: {d:e}");
    }
    // nalgebra-sparse: CscMatrix * DVector
    let n = op.parts_as(to_nalgebra);
    let xv = nalgebra::DVector::from_column_slice(&x);
    for ((name, xc, fx), (nx, nf)) in pairs.iter().zip([(&n.mc, &n.fm), (&n.kc, &n.fk)]) {
        let theirs = nx * &xv - (nf * &xv) * MU;
        let d = rel_diff(&own(xc, fx, &x), theirs.as_slice());
        assert!(d < 1e-14, "nalgebra {name}: {d:e}");
    }
}

/// `A x` for a `sprs::CsMat` through its own entry iterator (sprs's products need
/// ndarray, which squeal does not pull in).
fn sprs_times(a: &sprs::CsMat<f64>, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; a.rows()];
    for (&v, (i, j)) in a.iter() {
        y[i] += v * x[j];
    }
    y
}

#[test]
fn an_operator_rebuilt_from_foreign_parts_has_the_same_unstable_modes() {
    let op = operator();
    let via_sprs: OperatorParts<sprs::CsMat<f64>> = op.parts_as(to_sprs);
    let back =
        FrictionalOperator::from_parts_with(via_sprs, |name, m| from_sprs(name, &m)).unwrap();
    let via_na = back.parts_as(to_nalgebra);
    let back =
        FrictionalOperator::from_parts_with(via_na, |name, m| from_nalgebra(name, &m)).unwrap();
    let arpack = squeal::registry()
        .eigen
        .create("arpack", &Params::new())
        .unwrap();
    let p = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: 3000.0,
        tol: 1e-12,
        ..EigenParams::default()
    };
    let a = arpack.solve_frictional(&op, MU, &p).unwrap();
    let b = arpack.solve_frictional(&back, MU, &p).unwrap();
    let unstable = |m: &squeal::core::ComplexModes| {
        (0..m.len())
            .filter(|&i| m.is_unstable(i, 1e-8))
            .map(|i| m.lambda[i])
            .collect::<Vec<_>>()
    };
    let (ua, ub) = (unstable(&a), unstable(&b));
    assert!(
        !ua.is_empty(),
        "the coarse rig is expected to flutter at mu {MU}"
    );
    assert_eq!(ua.len(), ub.len());
    for (x, y) in ua.iter().zip(&ub) {
        assert!((x - y).norm() <= 1e-9 * x.norm(), "{x} vs {y}");
    }
}
