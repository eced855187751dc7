use super::super::{dense_qep, finish_modes};
use super::*;
use crate::eigen::{EigenParams, EigenSolver, SymmetricProblem};
use crate::operator::{ComplexModes, FrictionalOperator, Qep, RealModes, SolveInfo};
use crate::reduction::{m_orthonormalize, ReducedOperator};
use crate::{Basis, SparseMat};
use faer::sparse::Triplet;

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
    fn mat(&mut self, n: usize, scale: f64) -> Mat<f64> {
        Mat::from_fn(n, n, |_, _| scale * self.next())
    }
}

fn band(fmax: f64) -> EigenParams {
    EigenParams {
        fmin_hz: 0.0,
        fmax_hz: fmax,
        ..EigenParams::default()
    }
}

fn all_modes(qep: &Qep, fmax: f64) -> ComplexModes {
    let (l, v) = dense_qep(qep).unwrap();
    finish_modes(qep, &l, v.as_ref(), &band(fmax), SolveInfo::new("t")).unwrap()
}

/// A damped, non-symmetric QEP of size `n` with well separated eigenvalues.
fn random_qep(n: usize, seed: u64) -> Qep {
    let mut rng = Rng(seed);
    let b = rng.mat(n, 1.0);
    let m = Mat::<f64>::identity(n, n) + &b * b.transpose() * faer::Scale(0.05 / n as f64);
    let b = rng.mat(n, 1.0);
    let k = &b * b.transpose() + Mat::<f64>::identity(n, n) * faer::Scale(n as f64);
    let k = k + rng.mat(n, 0.5);
    Qep {
        m: sparse(&m),
        c: Some(sparse(&rng.mat(n, 0.05))),
        k: sparse(&k),
    }
}

#[test]
fn the_forward_error_of_a_perturbed_solve_stays_below_cond_times_eta() {
    let q = random_qep(10, 3);
    let exact = all_modes(&q, 1e3);
    assert!(exact.len() >= 8);
    assert!(
        exact.cond.iter().all(|c| c.is_finite() && *c >= 1.0),
        "{:?}",
        exact.cond
    );
    // left vectors: y^H Q(lambda) = 0 to round-off
    let y = exact.left_vectors.as_ref().unwrap();
    for j in 0..exact.len() {
        let l = exact.lambda[j];
        let qd = super::dense_q(&q, l);
        let yj = Mat::from_fn(q.dim(), 1, |r, _| y[(r, j)]);
        let res = yj.adjoint() * &qd;
        let rn = (0..q.dim())
            .map(|c| res[(0, c)].norm_sqr())
            .sum::<f64>()
            .sqrt();
        let scale = (0..q.dim())
            .map(|c| (0..q.dim()).map(|r| qd[(r, c)].norm()).sum::<f64>())
            .fold(0.0, f64::max);
        assert!(
            rn <= 1e-12 * scale,
            "mode {j}: ||y^H Q|| = {rn:e} vs {scale:e}"
        );
    }
    // the same problem perturbed by a relative 1e-7: its pairs, checked on the original
    let mut rng = Rng(11);
    let eps = 1e-7;
    let n = q.dim();
    let pert = |a: &SparseMat, rng: &mut Rng| {
        let d = a.as_ref().to_dense();
        let s = crate::linalg::norm1(a.as_ref()) * eps / n as f64;
        sparse(&(d + rng.mat(n, s)))
    };
    let qp = Qep {
        m: pert(&q.m, &mut rng),
        c: Some(pert(q.c.as_ref().unwrap(), &mut rng)),
        k: pert(&q.k, &mut rng),
    };
    let (lp, vp) = dense_qep(&qp).unwrap();
    let approx = finish_modes(&q, &lp, vp.as_ref(), &band(1e3), SolveInfo::new("t")).unwrap();
    assert_eq!(approx.len(), exact.len());
    let mut ratio_max = 0.0f64;
    for j in 0..approx.len() {
        let l = approx.lambda[j];
        let truth = exact
            .lambda
            .iter()
            .map(|e| (e - l).norm() / e.norm())
            .fold(f64::INFINITY, f64::min);
        let bound = approx.error_bound[j];
        assert!(
            approx.backward_error[j] > 1e-10,
            "the perturbation shows in eta"
        );
        assert!(
            truth <= 1.5 * bound,
            "mode {j}: error {truth:e} > bound {bound:e}"
        );
        assert!(
            bound <= 1e3 * truth,
            "mode {j}: bound {bound:e} far above {truth:e}"
        );
        ratio_max = ratio_max.max(truth / bound);
    }
    assert!(
        ratio_max > 1e-2,
        "the bound is never approached: {ratio_max:e}"
    );
}

/// The Hoffmann two-DOF model, flutter from mu_c = 0.2.
fn hoffmann(mu: f64) -> Qep {
    let m = Mat::<f64>::identity(2, 2);
    let k = Mat::from_fn(2, 2, |i, j| [[1.0, 0.1 - mu], [0.1, 1.2]][i][j]);
    Qep {
        m: sparse(&m),
        c: None,
        k: sparse(&k),
    }
}

#[test]
fn cond_grows_without_bound_towards_a_coalescence() {
    let at = |mu: f64| {
        let m = all_modes(&hoffmann(mu), 1.0);
        assert_eq!(m.len(), 2, "mu {mu}");
        m.cond.iter().fold(0.0f64, |a, &b| a.max(b))
    };
    let (c0, c1, c2) = (at(0.0), at(0.2 - 1e-4), at(0.2 - 1e-6));
    assert!(c0 < 30.0, "{c0}");
    assert!(c1 > 10.0 * c0 && c2 > 5.0 * c1, "{c0} {c1} {c2}");
}

#[test]
fn a_semisimple_doublet_gets_the_condition_of_its_members() {
    // M = I, K = diag(1, 1, 4, 9): lambda = i twice; symmetric, so for M-orthonormal real
    // x, cond = (|l|^2 ||M|| + ||K||) / (2 |l|^2) = (1 + 9) / 2 = 5
    let k = Mat::from_fn(
        4,
        4,
        |i, j| if i == j { [1.0, 1.0, 4.0, 9.0][i] } else { 0.0 },
    );
    let q = Qep {
        m: sparse(&Mat::<f64>::identity(4, 4)),
        c: None,
        k: sparse(&k),
    };
    let i = c64::new(0.0, 1.0);
    let x = Mat::from_fn(4, 2, |r, c| {
        if r == c {
            c64::new(1.0, 0.0)
        } else {
            c64::new(0.0, 0.0)
        }
    });
    let m = finish_modes(&q, &[i, i], x.as_ref(), &band(1.0), SolveInfo::new("t")).unwrap();
    assert_eq!(m.len(), 2);
    for c in &m.cond {
        assert!((c - 5.0).abs() <= 1e-10 * 5.0, "{:?}", m.cond);
    }
    assert!(
        m.error_bound.iter().all(|e| *e <= 1e-14),
        "{:?}",
        m.error_bound
    );
}

/// A sparse chain of `n` masses with circulatory (friction-like) couplings and damping.
fn chain(n: usize) -> Qep {
    let mut t = Vec::new();
    let (mut m, mut c) = (Vec::new(), Vec::new());
    for i in 0..n {
        let ks = 1e4 * (2.0 + (i as f64 * 0.37).sin());
        t.push(Triplet::new(i, i, 2.0 * ks));
        if i + 1 < n {
            t.push(Triplet::new(i, i + 1, -ks));
            t.push(Triplet::new(i + 1, i, -ks));
        }
        if i + 7 < n && i % 5 == 0 {
            t.push(Triplet::new(i, i + 7, 300.0));
            t.push(Triplet::new(i + 7, i, -300.0));
        }
        m.push(Triplet::new(i, i, 1.0 + 0.3 * (i as f64 * 0.11).cos()));
        c.push(Triplet::new(i, i, 0.5));
    }
    Qep {
        m: SparseMat::try_new_from_triplets(n, n, &m).unwrap(),
        c: Some(SparseMat::try_new_from_triplets(n, n, &c).unwrap()),
        k: SparseMat::try_new_from_triplets(n, n, &t).unwrap(),
    }
}

#[test]
fn transposed_solve_dense_and_sparse_inverse_iteration_agree() {
    let n = 300;
    let q = chain(n);
    let (l, v) = dense_qep(&q).unwrap();
    let modes = finish_modes(&q, &l, v.as_ref(), &band(8.0), SolveInfo::new("t")).unwrap();
    let k = modes.len();
    assert!(k >= 10, "{k}");
    let terms = QepTerms::of_qep(&q);
    let norms = terms.norms();
    let all: Vec<usize> = (0..k).collect();
    let cond_of = |left: &Mat<c64>| {
        condition_numbers(
            &terms,
            &norms,
            &modes.lambda,
            modes.vectors.as_ref(),
            left.as_ref(),
            &vec![0.0; k],
        )
        .0
    };
    let mut by_transposed = Mat::<c64>::zeros(n, k);
    let missed = from_transposed(&q, &modes.lambda, by_transposed.as_mut()).unwrap();
    assert!(missed.is_empty(), "{missed:?}");
    let mut by_dense = Mat::<c64>::zeros(n, k);
    let mut by_sparse = Mat::<c64>::zeros(n, k);
    assert_eq!(
        inverse_iteration(&q, &modes.lambda, &all, false, by_dense.as_mut()).unwrap(),
        k
    );
    assert_eq!(
        inverse_iteration(&q, &modes.lambda, &all, true, by_sparse.as_mut()).unwrap(),
        k
    );
    let (ct, cd, cs) = (
        cond_of(&by_transposed),
        cond_of(&by_dense),
        cond_of(&by_sparse),
    );
    for j in 0..k {
        for (name, c) in [("dense LU", cd[j]), ("sparse LU", cs[j])] {
            let rel = (c - ct[j]).abs() / ct[j];
            assert!(rel <= 1e-7, "mode {j}: {name} {c} vs transposed {}", ct[j]);
        }
    }
    // finish_modes took one of the two routes and says which
    assert!(modes
        .info
        .notes
        .iter()
        .any(|s| s.contains("left eigenvectors")));
    for j in 0..k {
        assert!((modes.cond[j] - ct[j]).abs() <= 1e-7 * ct[j]);
    }
}

/// The dense solver's behaviour, inline (core cannot depend on the plugin).
struct Dense;
impl EigenSolver for Dense {
    fn name(&self) -> &str {
        "dense-test"
    }
    fn solve_symmetric(&self, _: &SymmetricProblem<'_>, _: &EigenParams) -> Result<RealModes> {
        unreachable!("not used")
    }
    fn solve_qep(&self, qep: &Qep, params: &EigenParams) -> Result<ComplexModes> {
        let (l, v) = dense_qep(qep)?;
        finish_modes(qep, &l, v.as_ref(), params, SolveInfo::new("dense-test"))
    }
}

#[test]
fn a_reduced_solve_on_a_complete_basis_has_the_full_condition_numbers() {
    let q = random_qep(12, 5);
    let op = FrictionalOperator {
        mc: q.m.clone(),
        cc: q.c.clone(),
        kc: q.k.clone(),
        fm: SparseMat::try_new_from_triplets(12, 12, &[]).unwrap(),
        fc: None,
        fk: sparse(&Rng(9).mat(12, 2.0)),
        t: None,
        friction_loads: None,
        modal: Default::default(),
    };
    let mu = 0.4;
    let full = Dense.solve_frictional(&op, mu, &band(1e3)).unwrap();
    let (v, _) = m_orthonormalize(op.mc.as_ref(), Rng(2).mat(12, 1.0).as_ref(), 1e-10).unwrap();
    assert_eq!(v.ncols(), 12);
    let red = ReducedOperator::new(&op, Basis::new(v)).unwrap();
    let solved = red.solve(&op, mu, &Dense, &band(1e3)).unwrap().modes;
    assert_eq!(solved.len(), full.len());
    assert!(solved.left_vectors.is_some());
    for j in 0..full.len() {
        let rel = (solved.cond[j] - full.cond[j]).abs() / full.cond[j];
        assert!(
            rel <= 1e-8,
            "mode {j}: {} vs {}",
            solved.cond[j],
            full.cond[j]
        );
        assert!(solved.error_bound[j] <= 1e-12, "{}", solved.error_bound[j]);
    }
    // without left vectors the estimate is not made up
    let plain = super::super::finish_operator_modes(
        &op,
        mu,
        &full.lambda,
        full.vectors.as_ref(),
        &band(1e3),
        SolveInfo::new("t"),
    )
    .unwrap();
    assert!(plain.cond.iter().all(|c| c.is_nan()) && plain.left_vectors.is_none());
}
