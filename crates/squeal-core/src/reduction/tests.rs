use super::project::dense_to_sparse;
use super::*;
use crate::contact::{Basis, BasisRequest, FreeModel, PairDofs};
use crate::eigen::{
    dense_symmetric, finish_real_modes, EigenParams, EigenSolver, SymmetricProblem,
};
use crate::linalg::{dot, spmv};
use crate::operator::{ComplexModes, FrictionalOperator, Qep, RealModes, SolveInfo};
use crate::qep::finish_modes;
use crate::qep::{backward_error, dense_qep};
use crate::{c64, Result, SparseMat};

/// Deterministic pseudo-random numbers in [-0.5, 0.5).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
    fn mat(&mut self, r: usize, c: usize) -> Mat<f64> {
        Mat::from_fn(r, c, |_, _| self.next())
    }
}

fn sparse(a: MatRef<'_, f64>) -> SparseMat {
    dense_to_sparse(a).unwrap()
}

/// A small frictional operator: `M`, `K` symmetric positive definite (banded), friction
/// parts of rank `na`, `F_X = U V_X^T` (`V_M^T` = rows of `M` at `na` "slave" DOFs, `V_K^T`
/// rows of another stiffness), the friction loads stored or not.
fn operator(n: usize, na: usize, with_loads: bool, seed: u64) -> FrictionalOperator {
    let mut rng = Rng(seed);
    // delocalized modes: K = 1e6 (B B^T + n I), M = I + 0.1 B' B'^T / n
    let b = rng.mat(n, n);
    let bm = rng.mat(n, n);
    let k = (&b * b.transpose() + Mat::<f64>::identity(n, n) * faer::Scale(n as f64))
        * faer::Scale(1e6);
    let m = Mat::<f64>::identity(n, n) + &bm * bm.transpose() * faer::Scale(0.1 / n as f64);
    let mut u = Mat::<f64>::zeros(n, na);
    for p in 0..na {
        let (a, b) = ((3 * p + 1) % n, (3 * p + 2) % n);
        u[(a, p)] = 0.8;
        u[(b, p)] = -0.6;
    }
    let slave: Vec<usize> = (0..na).map(|p| (3 * p) % n).collect();
    let rows = |x: &Mat<f64>| Mat::from_fn(na, n, |i, j| x[(slave[i], j)]);
    let fm = &u * rows(&m);
    // rows of another stiffness: with the rows of K itself, K~ = (I - mu U L) K and the
    // spectrum would not depend on mu (the constraint T is what makes friction bite)
    let b2 = rng.mat(n, n);
    let k2 = &b2 * b2.transpose() * faer::Scale(1e6);
    let fk = &u * rows(&k2);
    FrictionalOperator {
        mc: sparse(m.as_ref()),
        cc: None,
        kc: sparse(k.as_ref()),
        fm: sparse(fm.as_ref()),
        fc: None,
        fk: sparse(fk.as_ref()),
        t: None,
        friction_loads: with_loads.then(|| sparse(u.as_ref())),
        modal: Default::default(),
    }
}

/// The `dense` solver's behaviour, inline (core cannot depend on the plugin).
struct Dense;
impl EigenSolver for Dense {
    fn name(&self) -> &str {
        "dense-test"
    }
    fn solve_symmetric(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        let (w, v) = dense_symmetric(problem)?;
        Ok(finish_real_modes(problem, &w, v.as_ref(), params, info()))
    }
    fn solve_qep(&self, qep: &Qep, params: &EigenParams) -> Result<ComplexModes> {
        let (l, v) = dense_qep(qep)?;
        finish_modes(qep, &l, v.as_ref(), params, info())
    }
}

fn info() -> SolveInfo {
    SolveInfo::new("dense-test")
}

fn wide_band() -> EigenParams {
    EigenParams {
        fmin_hz: 0.0,
        fmax_hz: 1e6,
        ..EigenParams::default()
    }
}

/// Largest distance from each eigenvalue of `a` to its nearest unused one in `b`,
/// relative to the largest `|lambda|`.
fn spectral_distance(a: &[c64], b: &[c64]) -> f64 {
    assert_eq!(a.len(), b.len(), "spectra of different sizes");
    let scale = b.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    let mut used = vec![false; b.len()];
    let mut worst = 0.0f64;
    for x in a {
        let (j, d) = b
            .iter()
            .enumerate()
            .filter(|(j, _)| !used[*j])
            .map(|(j, y)| (j, (x - y).norm()))
            .min_by(|p, q| p.1.total_cmp(&q.1))
            .unwrap();
        used[j] = true;
        worst = worst.max(d);
    }
    worst / scale
}

#[test]
fn orthonormalization_keeps_a_badly_scaled_static_vector_nearly_parallel_to_a_mode() {
    let op = operator(40, 3, true, 7);
    let m = op.mc.as_ref();
    let mut rng = Rng(11);
    let (modes, d0) = m_orthonormalize(m, rng.mat(40, 10).as_ref(), DEFAULT_RANK_TOL).unwrap();
    assert_eq!((modes.ncols(), d0), (10, 0));
    assert!(m_orthonormality_error(m, modes.as_ref()) < 1e-13);
    // a direction M-orthogonal to the modes
    let (all, _) =
        m_orthonormal_extend(m, modes.as_ref(), rng.mat(40, 1).as_ref(), DEFAULT_RANK_TOL).unwrap();
    let z: Vec<f64> = (0..40).map(|r| all[(r, 10)]).collect();
    // static vectors of size 1e-9 (a displacement in m), at angles 1e-6 and 1e-13 from
    // mode 0, plus a zero column
    let near = |angle: f64| -> Vec<f64> {
        (0..40)
            .map(|r| 1e-9 * (modes[(r, 0)] + angle * z[r]))
            .collect()
    };
    let (a, b) = (near(1e-6), near(1e-13));
    let new = Mat::from_fn(40, 3, |r, c| match c {
        0 => a[r],
        1 => b[r],
        _ => 0.0,
    });
    let (v, dropped) = m_orthonormal_extend(m, modes.as_ref(), new.as_ref(), 1e-10).unwrap();
    assert_eq!(
        v.ncols(),
        11,
        "the near-parallel static vector must survive"
    );
    assert_eq!(
        dropped, 2,
        "the 1e-13 one and the zero column are dropped and counted"
    );
    assert!(m_orthonormality_error(m, v.as_ref()) < 1e-12);
    // the kept direction is the new part of the static vector, z (up to sign)
    let kept: Vec<f64> = (0..40).map(|r| v[(r, 10)]).collect();
    let mut mz = vec![0.0; 40];
    spmv(m, &z, &mut mz);
    let cos = dot(&kept, &mz).abs();
    assert!((cos - 1.0).abs() < 1e-6, "cos = {cos}");
    // the modes are unchanged (first, bit for bit)
    for c in 0..10 {
        for r in 0..40 {
            assert_eq!(v[(r, c)], modes[(r, c)]);
        }
    }
    // the raw-Gram pitfall: the Gram matrix of the unscaled columns [modes | a] has its
    // smallest eigenvalue near (1e-9 * 1e-6)^2 relative to 1: a relative eigenvalue cut
    // at the same 1e-10 would drop the static vector
    let cols = Mat::from_fn(40, 11, |r, c| if c < 10 { modes[(r, c)] } else { a[r] });
    let g = tmul(cols.as_ref(), sparse_times(m, cols.as_ref()).as_ref());
    let ev = g.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
    let (lo, hi) = (ev[0], ev[ev.len() - 1]);
    assert!(lo < 1e-10 * hi, "{lo:e} vs {hi:e}");
}

#[test]
fn nearly_parallel_columns_of_one_block_come_out_m_orthonormal() {
    // eight columns within 1e-5 of one direction, then eight within 1e-9: each is
    // orthogonalized against its block's earlier columns with heavy cancellation, where
    // the M images carried through the projections lose accuracy and must be recomputed
    let op = operator(60, 3, true, 5);
    let m = op.mc.as_ref();
    let mut rng = Rng(23);
    let base = rng.mat(60, 1);
    let noise = rng.mat(60, 16);
    let cols = Mat::from_fn(60, 16, |r, c| {
        let eps = if c < 8 { 1e-5 } else { 1e-9 };
        base[(r, 0)] + eps * noise[(r, c)]
    });
    let (v, dropped) = m_orthonormalize(m, cols.as_ref(), DEFAULT_RANK_TOL).unwrap();
    assert_eq!(v.ncols() + dropped, 16);
    assert!(v.ncols() >= 9, "kept {} of 16", v.ncols());
    assert!(m_orthonormality_error(m, v.as_ref()) < 1e-12);
}

#[test]
fn blocked_extension_keeps_the_columns_one_by_one_extension_keeps() {
    // 20 random columns, then 50 combinations of them, perturbed by 1e-3, 1e-7 or not at
    // all (exact repeats of the span, to drop), across three blocks and their recursive
    // halves: the blocked extension must keep and drop what Gram-Schmidt column by column
    // keeps and drops, and span the same space
    let n = 200;
    let op = operator(n, 3, true, 9);
    let m = op.mc.as_ref();
    let mut rng = Rng(41);
    let first = rng.mat(n, 20);
    let mix = rng.mat(20, 50);
    let noise = rng.mat(n, 50);
    let combos = &first * &mix;
    let scale = |c: usize| [1e-3, 1e-7, 0.0][c % 3];
    let cols = Mat::from_fn(n, 70, |r, c| {
        if c < 20 {
            first[(r, c)]
        } else {
            combos[(r, c - 20)] + scale(c - 20) * noise[(r, c - 20)]
        }
    });
    let (v, dropped) = m_orthonormalize(m, cols.as_ref(), DEFAULT_RANK_TOL).unwrap();
    let mut one = Mat::<f64>::zeros(n, 0);
    let mut one_dropped = 0;
    for c in 0..70 {
        let (next, d) =
            m_orthonormal_extend(m, one.as_ref(), cols.subcols(c, 1), DEFAULT_RANK_TOL).unwrap();
        one = next;
        one_dropped += d;
    }
    let exact_repeats = (0..50).filter(|&c| scale(c) == 0.0).count();
    assert_eq!(dropped, exact_repeats);
    assert_eq!((v.ncols(), dropped), (one.ncols(), one_dropped));
    assert!(m_orthonormality_error(m, v.as_ref()) < 1e-12);
    // the same span: each basis M-projected on the other keeps its whole norm
    let cross = tmul(v.as_ref(), sparse_times(m, one.as_ref()).as_ref());
    for j in 0..one.ncols() {
        let kept: f64 = (0..cross.nrows()).map(|i| cross[(i, j)].powi(2)).sum();
        assert!((kept - 1.0).abs() < 1e-8, "column {j}: {kept}");
    }
}

#[test]
fn svd_compression_keeps_the_dominant_directions() {
    let op = operator(30, 2, true, 3);
    let m = op.mc.as_ref();
    let mut rng = Rng(5);
    let ab = rng.mat(30, 2);
    // columns: a, b, a + b + 1e-4 c, 1e3 a (same direction as a)
    let c = rng.mat(30, 1);
    let v = Mat::from_fn(30, 4, |r, j| match j {
        0 => ab[(r, 0)],
        1 => ab[(r, 1)],
        2 => ab[(r, 0)] + ab[(r, 1)] + 1e-4 * c[(r, 0)],
        _ => 1e3 * ab[(r, 0)],
    });
    let (q, dropped) = m_svd_compress(m, v.as_ref(), 1e-2).unwrap();
    assert_eq!((q.ncols(), dropped), (2, 2));
    assert!(m_orthonormality_error(m, q.as_ref()) < 1e-13);
    let (q, dropped) = m_svd_compress(m, v.as_ref(), 1e-8).unwrap();
    assert_eq!((q.ncols(), dropped), (3, 1));
    assert!(m_svd_compress(m, v.as_ref(), 0.0).is_err());
}

#[test]
fn identity_and_full_rank_bases_reproduce_the_full_dense_spectrum() {
    let op = operator(24, 4, true, 21);
    for mu in [0.3, 0.7] {
        let full = op.at(mu).unwrap();
        let (lam, _) = dense_qep(&full).unwrap();
        let reference = finish_modes(
            &full,
            &lam,
            dense_qep(&full).unwrap().1.as_ref(),
            &wide_band(),
            info(),
        )
        .unwrap();
        assert!(reference.len() >= 10);
        // V = I: the projection is the operator itself
        let eye = Basis::new(Mat::<f64>::identity(24, 24));
        let red = solve_reduced(&op, &eye, mu, &Dense, &wide_band()).unwrap();
        assert_eq!(red.basis_size, 24);
        let d = spectral_distance(&red.modes.lambda, &reference.lambda);
        assert!(d < 1e-12, "mu {mu}: identity basis differs by {d:e}");
        // a random M-orthonormal basis of full rank: the same spectrum (congruence)
        let (v, dropped) = m_orthonormalize(
            op.mc.as_ref(),
            Rng(99).mat(24, 24).as_ref(),
            DEFAULT_RANK_TOL,
        )
        .unwrap();
        assert_eq!(dropped, 0);
        let basis = Basis::new(v);
        let red = solve_reduced(&op, &basis, mu, &Dense, &wide_band()).unwrap();
        let d = spectral_distance(&red.modes.lambda, &reference.lambda);
        assert!(d < 1e-10, "mu {mu}: rotated basis differs by {d:e}");
        let worst = red
            .modes
            .backward_error
            .iter()
            .fold(0.0f64, |a, &b| a.max(b));
        assert!(worst < 1e-12, "mu {mu}: backward error {worst:e}");
        // the reduced operator keeps the parts apart: F_r = V^T U V_K^T V
        let r = project(&op, basis.v.as_ref()).unwrap();
        assert!(r.t.is_none());
        assert_eq!(r.friction_loads.as_ref().unwrap().ncols(), 4);
        assert!(mac_sanity(&op, &red.modes));
    }
}

#[test]
fn symmetric_parts_project_by_their_lower_triangle_and_others_in_full() {
    let op = operator(40, 4, true, 5);
    let v = Rng(17).mat(40, 33);
    // both projections of `x`, dense
    let both = |x: &SparseMat| {
        let dense = |r: Result<SparseMat>| r.unwrap().as_ref().to_dense();
        (
            dense(project::project_symmetric_part(x.as_ref(), v.as_ref())),
            dense(project::project_part(x.as_ref(), v.as_ref())),
        )
    };
    // K_c and M_c are symmetric: the triangular product, mirrored, equals the full one
    for x in [&op.kc, &op.mc] {
        assert!(project::is_symmetric(x.as_ref()));
        let (sym, full) = both(x);
        assert_eq!(sym, sym.transpose().to_owned());
        let scale = full.norm_max();
        assert!((&sym - &full).norm_max() <= 1e-13 * scale);
    }
    // a part that is not symmetric (one entry changed by one bit) takes the full product
    let mut k = op.kc.as_ref().to_dense();
    k[(3, 7)] = f64::from_bits(k[(3, 7)].to_bits() + 1);
    let k = sparse(k.as_ref());
    assert!(!project::is_symmetric(k.as_ref()));
    let (a, b) = both(&k);
    assert_eq!(a, b);
    assert!(!project::is_symmetric(op.fk.as_ref()));
}

/// Every expanded mode has unit MAC with itself.
fn mac_sanity(op: &FrictionalOperator, modes: &ComplexModes) -> bool {
    let n = op.dim();
    (0..modes.len()).all(|j| {
        let psi: Vec<c64> = (0..n).map(|r| modes.vectors[(r, j)]).collect();
        let re: Vec<f64> = psi.iter().map(|z| z.re).collect();
        mac_real_complex(op.mc.as_ref(), &re, &psi) <= 1.0 + 1e-12
    })
}

#[test]
fn backward_error_flags_a_perturbed_mode_and_a_truncated_basis() {
    let op = operator(30, 3, true, 5);
    let mu = 0.5;
    let full = op.at(mu).unwrap();
    let (lam, vec) = dense_qep(&full).unwrap();
    let modes = finish_modes(&full, &lam, vec.as_ref(), &wide_band(), info()).unwrap();
    let j = modes.len() / 2;
    let u: Vec<c64> = (0..30).map(|r| modes.vectors[(r, j)]).collect();
    let exact = backward_error(&full, modes.lambda[j], &u);
    assert!(exact < 1e-13, "exact mode: {exact:e}");
    let mut rng = Rng(17);
    let bent: Vec<c64> = u
        .iter()
        .map(|z| z + c64::new(1e-4 * rng.next(), 1e-4 * rng.next()))
        .collect();
    let perturbed = backward_error(&full, modes.lambda[j], &bent);
    assert!(perturbed > 1e-7, "perturbed mode: {perturbed:e}");
    let shifted = backward_error(&full, modes.lambda[j] * 1.001, &u);
    assert!(shifted > 1e-5, "shifted eigenvalue: {shifted:e}");
    // a basis of the 8 lowest real modes misses part of every mode: the backward error
    // on the full operator says so
    let req = BasisRequest {
        op: &op,
        mu,
        band_hz: (0.0, 1e6),
        modal: &Dense,
        reduced: &Dense,
        params: &wide_band(),
        stage: None,
        seed: None,
    };
    let rm = coupled_real_modes(&req, 1e6).unwrap();
    let v8 = rm.vectors.as_ref().subcols(0, 8).to_owned();
    let red = solve_reduced(&op, &Basis::new(v8), mu, &Dense, &wide_band()).unwrap();
    let worst = red
        .modes
        .backward_error
        .iter()
        .fold(0.0f64, |a, &b| a.max(b));
    assert!(
        worst > 1e-6,
        "truncated basis: largest backward error {worst:e}"
    );
}

#[test]
fn friction_load_span_is_recovered_from_fk() {
    let with = operator(36, 4, true, 8);
    let mut without = with.clone();
    without.friction_loads = None;
    let u = friction_load_directions(&with).unwrap();
    assert_eq!(u.ncols(), 4);
    let y = friction_load_directions(&without).unwrap();
    let m = with.mc.as_ref();
    let (q, _) = m_orthonormalize(m, u.as_ref(), DEFAULT_RANK_TOL).unwrap();
    let (all, dropped) = m_orthonormal_extend(m, q.as_ref(), y.as_ref(), 1e-8).unwrap();
    assert_eq!(all.ncols(), 4, "span(F_K Omega) must lie in span(U)");
    assert_eq!(dropped, y.ncols());
    let (qy, _) = m_orthonormalize(m, y.as_ref(), 1e-8).unwrap();
    assert_eq!(qy.ncols(), 4, "and fill it");
}

#[test]
fn energy_residual_vanishes_on_exact_modes_only() {
    let op = operator(20, 2, true, 13);
    let mu = 0.4;
    let full = op.at(mu).unwrap();
    let (lam, vec) = dense_qep(&full).unwrap();
    let modes = finish_modes(&full, &lam, vec.as_ref(), &wide_band(), info()).unwrap();
    let ks = StaticSolver::new(&op, 0.0).unwrap();
    let (eps, d) = energy_residuals(&full, &ks, &modes.lambda, modes.vectors.as_ref());
    assert_eq!(d.ncols(), modes.len());
    assert!(eps.iter().all(|&e| e < 1e-12), "{eps:?}");
    let mut rng = Rng(2);
    let bent = Mat::from_fn(20, modes.len(), |r, c| {
        modes.vectors[(r, c)] + c64::new(1e-3 * rng.next(), 0.0)
    });
    let (eps, _) = energy_residuals(&full, &ks, &modes.lambda, bent.as_ref());
    assert!(eps.iter().all(|&e| e > 1e-6), "{eps:?}");
}

#[test]
fn mac_is_phase_independent() {
    let op = operator(12, 1, false, 4);
    let mut rng = Rng(6);
    let phi: Vec<f64> = (0..12).map(|_| rng.next()).collect();
    let rot = c64::new(0.6, -0.8);
    let psi: Vec<c64> = phi.iter().map(|&x| rot * x * 3.0).collect();
    let mac = mac_real_complex(op.mc.as_ref(), &phi, &psi);
    assert!((mac - 1.0).abs() < 1e-14, "{mac}");
    let other: Vec<f64> = (0..12).map(|_| rng.next()).collect();
    let (q, _) = m_orthonormalize(
        op.mc.as_ref(),
        Mat::from_fn(12, 2, |r, c| if c == 0 { phi[r] } else { other[r] }).as_ref(),
        DEFAULT_RANK_TOL,
    )
    .unwrap();
    let orth: Vec<c64> = (0..12).map(|r| rot * q[(r, 1)]).collect();
    let mac = mac_real_complex(op.mc.as_ref(), &phi, &orth);
    assert!(mac < 1e-24, "{mac}");
}

#[test]
fn a_grown_basis_projects_and_measures_residuals_as_the_direct_path() {
    let mut op = operator(30, 3, true, 21);
    // a damped operator, so the kept C_c image is exercised too
    let c = Mat::from_fn(30, 30, |i, j| if i == j { 2.0 } else { 0.0 });
    op.cc = Some(sparse(c.as_ref()));
    let mc = op.mc.as_ref();
    let mut rng = Rng(5);
    let (v0, _) = m_orthonormalize(mc, rng.mat(30, 6).as_ref(), DEFAULT_RANK_TOL).unwrap();
    let more = rng.mat(30, 5);
    let mut grown = GrowingBasis::new(&op, v0.clone()).unwrap();
    let dropped = grown.extend(more.as_ref(), DEFAULT_RANK_TOL).unwrap();
    assert_eq!((grown.len(), dropped), (11, 0));
    // the same columns as the one-shot extension
    let (direct, _) =
        m_orthonormal_extend(mc, v0.as_ref(), more.as_ref(), DEFAULT_RANK_TOL).unwrap();
    let diff = (&direct - grown.columns()).norm_max();
    assert!(diff < 1e-12, "columns differ by {diff:e}");
    // a dependent column is dropped and counted
    let dep = grown.columns().subcols(0, 2).to_owned();
    assert_eq!(grown.extend(dep.as_ref(), DEFAULT_RANK_TOL).unwrap(), 2);
    assert_eq!(grown.len(), 11);
    // the projection from the kept images is that of `project`, part by part
    let a = grown.project().unwrap();
    let b = project(&op, grown.columns()).unwrap();
    // (to round-off: `project` forms V^T X V as (X^T V)^T V)
    let damping = (a.cc.as_ref().unwrap(), b.cc.as_ref().unwrap());
    for (x, y) in [
        (&a.mc, &b.mc),
        (&a.kc, &b.kc),
        (&a.fk, &b.fk),
        (&a.fm, &b.fm),
        damping,
    ] {
        let (x, y) = (x.to_dense(), y.to_dense());
        assert!((&x - &y).norm_max() <= 1e-13 * y.norm_max());
    }
    // residuals of reduced modes from the images = those of the sparse products
    let mu = 0.3;
    let red = dense_qep(&grown.project().unwrap().at(mu).unwrap()).unwrap();
    let q = red.1.as_ref().subcols(0, 4);
    let lambda = &red.0[..4];
    let ks = StaticSolver::new(&op, 1e3).unwrap();
    let (eps, d) = grown.energy_residuals(mu, &ks, lambda, q);
    let u = expand(grown.columns(), q);
    let (eps0, d0) = energy_residuals(&op.at(mu).unwrap(), &ks, lambda, u.as_ref());
    for (e, e0) in eps.iter().zip(&eps0) {
        assert!(
            e0.is_finite() && *e0 > 0.0 && (e - e0).abs() <= 1e-8 * e0,
            "{e} vs {e0}"
        );
    }
    let dd = (0..d.nrows())
        .flat_map(|r| (0..d.ncols()).map(move |c| (r, c)))
        .map(|(r, c)| (d[(r, c)] - d0[(r, c)]).norm())
        .fold(0.0f64, f64::max);
    let scale = (0..d0.nrows())
        .flat_map(|r| (0..d0.ncols()).map(move |c| (r, c)))
        .map(|(r, c)| d0[(r, c)].norm())
        .fold(0.0f64, f64::max);
    assert!(
        dd <= 1e-10 * scale,
        "static responses differ by {dd:e} of {scale:e}"
    );
}

/// A free model of two bodies (DOFs `0..15` and `15..30`, each a random banded symmetric
/// positive definite stiffness, not coupled) with four candidate pairs (pin node `i` at
/// DOFs `3i..3i+3`, disc node at `15 + 3i..`), and the operator that ties the pairs
/// `active`: the pin's normal DOF eliminated into its disc partner, the rest renumbered.
fn tied_model(active: &[usize]) -> (SparseMat, Vec<PairDofs>, FrictionalOperator, Mat<f64>) {
    const N: usize = 30;
    let mut rng = Rng(29);
    let mut k = Mat::<f64>::zeros(N, N);
    for body in [0..15, 15..30] {
        for i in body.clone() {
            k[(i, i)] += 4.0 + rng.next();
            for j in (i + 1)..(i + 4).min(body.end) {
                let s = 1.0 + 0.5 * rng.next();
                k[(i, i)] += s;
                k[(j, j)] += s;
                k[(i, j)] -= s;
                k[(j, i)] -= s;
            }
        }
    }
    let k = &k * faer::Scale(1e7);
    let pairs: Vec<PairDofs> = (0..4)
        .map(|i| PairDofs {
            pin: [3 * i, 3 * i + 1, 3 * i + 2],
            disc: [15 + 3 * i, 15 + 3 * i + 1, 15 + 3 * i + 2],
            direction: [(0.3 + i as f64).cos(), (0.3 + i as f64).sin(), 0.0],
        })
        .collect();
    let eliminated: Vec<usize> = active.iter().map(|&i| pairs[i].pin[2]).collect();
    let kept: Vec<usize> = (0..N).filter(|j| !eliminated.contains(j)).collect();
    let t: Vec<usize> = (0..N)
        .map(|j| {
            let to = active
                .iter()
                .find(|&&i| pairs[i].pin[2] == j)
                .map_or(j, |&i| pairs[i].disc[2]);
            kept.iter().position(|&x| x == to).unwrap()
        })
        .collect();
    let nc = kept.len();
    let mut kc = Mat::<f64>::zeros(nc, nc);
    for j in 0..N {
        for i in 0..N {
            kc[(t[i], t[j])] += k[(i, j)];
        }
    }
    let id = sparse(Mat::<f64>::identity(nc, nc).as_ref());
    let op = FrictionalOperator {
        mc: id.clone(),
        cc: None,
        kc: sparse(kc.as_ref()),
        fm: sparse(Mat::<f64>::zeros(nc, nc).as_ref()),
        fc: None,
        fk: sparse(Mat::<f64>::zeros(nc, nc).as_ref()),
        t: Some(t),
        friction_loads: None,
        modal: Default::default(),
    };
    (sparse(k.as_ref()), pairs, op, kc)
}

fn pair_solves(k: &SparseMat, pairs: &[PairDofs]) -> Result<PairSolves> {
    let m = sparse(Mat::<f64>::identity(k.nrows(), k.nrows()).as_ref());
    let modes = |_: f64| -> Result<RealModes> { unreachable!("tied solves need no modes") };
    PairSolves::new(&FreeModel {
        k: k.as_ref(),
        m: m.as_ref(),
        pairs,
        k_factor: None,
        normal_modes: &modes,
        modal: &Dense,
        band_hz: (0.0, 1.0),
        params: &wide_band(),
        contact_sets: None,
    })
}

#[test]
fn tied_solves_through_the_free_factor_match_the_factorized_tied_stiffness() {
    for active in [vec![0, 2, 3], vec![1], vec![], vec![0, 1, 2, 3]] {
        let (k, pairs, op, kc) = tied_model(&active);
        let solves = pair_solves(&k, &pairs).unwrap();
        let tied = StaticSolver::tied(&op, &solves).unwrap();
        let direct = StaticSolver::new(&op, 0.0).unwrap();
        let b = Rng(7).mat(op.dim(), 5);
        let (mut x, mut y) = (b.clone(), b.clone());
        tied.solve_in_place(x.as_mut());
        direct.solve_in_place(y.as_mut());
        let scale = (0..5)
            .flat_map(|c| (0..op.dim()).map(move |r| (r, c)))
            .fold(0.0f64, |a, (r, c)| a.max(y[(r, c)].abs()));
        for c in 0..5 {
            for r in 0..op.dim() {
                assert!(
                    (x[(r, c)] - y[(r, c)]).abs() <= 1e-12 * scale,
                    "active {active:?}: {} vs {}",
                    x[(r, c)],
                    y[(r, c)]
                );
            }
        }
        // and it is K_c's solve: K_c x = b
        let kx = &kc * &x;
        let worst = (0..5)
            .flat_map(|c| (0..op.dim()).map(move |r| (r, c)))
            .fold(0.0f64, |a, (r, c)| a.max((kx[(r, c)] - b[(r, c)]).abs()));
        assert!(worst <= 1e-9, "active {active:?}: residual {worst:e}");
        assert!(tied
            .method
            .contains(&format!("{} tied pairs", active.len())));
    }
}

/// The friction load directions `U = T^T P~t^T` of the contact set `active`: `+e` on the
/// pin's in-plane DOFs and `-e` on the disc's, one column per active pair.
fn friction_loads(op: &FrictionalOperator, pairs: &[PairDofs], active: &[usize]) -> SparseMat {
    let t = op.t.as_ref().unwrap();
    let mut u = Mat::<f64>::zeros(op.dim(), active.len());
    for (c, &i) in active.iter().enumerate() {
        let p = &pairs[i];
        for a in 0..2 {
            u[(t[p.pin[a]], c)] += p.direction[a];
            u[(t[p.disc[a]], c)] -= p.direction[a];
        }
    }
    sparse(u.as_ref())
}

#[test]
fn friction_statics_from_the_kept_free_responses_match_a_solve_of_the_loads() {
    let (k, pairs, _, _) = tied_model(&[]);
    let solves = pair_solves(&k, &pairs).unwrap();
    // a stage whose responses are all solved ahead (what a benchmark asks)
    let ahead = pair_solves(&k, &pairs).unwrap();
    ahead.solve_friction_responses();
    assert_eq!(ahead.kept_friction_responses(), 4);
    // contact sets sharing pairs: the later ones find some responses kept, solve the rest
    for (active, held) in [
        (vec![0, 2], 2),
        (vec![0, 1, 2, 3], 4),
        (vec![3], 4),
        (vec![1, 2], 4),
    ] {
        let (_, _, mut op, kc) = tied_model(&active);
        op.friction_loads = Some(friction_loads(&op, &pairs, &active));
        let (kept, reused) = StaticSolver::tied(&op, &solves)
            .unwrap()
            .friction_statics(&op)
            .unwrap();
        assert!(
            reused,
            "active {active:?}: the kept responses were not used"
        );
        assert_eq!(solves.kept_friction_responses(), held);
        let (early, _) = StaticSolver::tied(&op, &ahead)
            .unwrap()
            .friction_statics(&op)
            .unwrap();
        assert!((&early - &kept).norm_max() <= 1e-14 * kept.norm_max());
        let (solved, reused) = StaticSolver::new(&op, 0.0)
            .unwrap()
            .friction_statics(&op)
            .unwrap();
        assert!(!reused);
        assert_eq!(kept.ncols(), active.len());
        let scale = solved.norm_max();
        assert!(scale > 0.0);
        assert!(
            (&kept - &solved).norm_max() <= 1e-12 * scale,
            "active {active:?}: {:e} of {scale:e}",
            (&kept - &solved).norm_max()
        );
        // and they are K_c's responses to the loads
        let u = op.friction_loads.as_ref().unwrap().as_ref().to_dense();
        let worst = (&(&kc * &kept) - &u).norm_max();
        assert!(worst <= 1e-9, "active {active:?}: residual {worst:e}");
    }
    // a column that is not its pair's friction load is solved, not taken from the kept
    // responses
    let active = [0, 2];
    let (_, _, mut op, _) = tied_model(&active);
    let mut u = friction_loads(&op, &pairs, &active).as_ref().to_dense();
    let t = op.t.clone().unwrap();
    u[(t[pairs[2].pin[0]], 1)] *= 2.0;
    op.friction_loads = Some(sparse(u.as_ref()));
    let (x, reused) = StaticSolver::tied(&op, &solves)
        .unwrap()
        .friction_statics(&op)
        .unwrap();
    assert!(!reused);
    let (y, _) = StaticSolver::new(&op, 0.0)
        .unwrap()
        .friction_statics(&op)
        .unwrap();
    assert!((&x - &y).norm_max() <= 1e-12 * y.norm_max());
}

#[test]
fn tied_solves_through_the_static_space_match_those_on_the_kept_responses() {
    let (k, pairs, _, _) = tied_model(&[]);
    let n = k.nrows();
    let m = sparse(Mat::<f64>::identity(n, n).as_ref());
    let modes = |_: f64| -> Result<RealModes> { unreachable!("tied solves need no modes") };
    let params = wide_band();
    let free = FreeModel {
        k: k.as_ref(),
        m: m.as_ref(),
        pairs: &pairs,
        k_factor: None,
        normal_modes: &modes,
        modal: &Dense,
        band_hz: (0.0, 1.0),
        params: &params,
        contact_sets: None,
    };
    let kept = PairSolves::new(&free).unwrap();
    let mut shared = PairSolves::new(&free).unwrap();
    let space = StaticSpace::new(&free, &shared)
        .unwrap()
        .expect("independent responses");
    shared.share_normals_with(&space).unwrap();
    // Z = Q_1 R_11 is the kept Z
    let (mut z1, mut z2) = (Mat::<f64>::zeros(n, 4), Mat::<f64>::zeros(n, 4));
    kept.normal_responses_into(z1.as_mut());
    shared.normal_responses_into(z2.as_mut());
    let scale = z1.norm_max();
    assert!(scale > 0.0);
    assert!((&z1 - &z2).norm_max() <= 1e-13 * scale);
    // and the tied solves agree, whichever pairs are active (the last one or not)
    for active in [vec![0, 2, 3], vec![1], vec![0, 1, 2, 3], vec![2], vec![]] {
        let (_, _, op, kc) = tied_model(&active);
        let b = Rng(11).mat(op.dim(), 3);
        let (mut x, mut y) = (b.clone(), b.clone());
        StaticSolver::tied(&op, &kept)
            .unwrap()
            .solve_in_place(x.as_mut());
        StaticSolver::tied(&op, &shared)
            .unwrap()
            .solve_in_place(y.as_mut());
        let scale = x.norm_max();
        assert!(
            (&x - &y).norm_max() <= 1e-12 * scale,
            "active {active:?}: {:e} of {scale:e}",
            (&x - &y).norm_max()
        );
        let worst = (&(&kc * &y) - &b).norm_max();
        assert!(worst <= 1e-9, "active {active:?}: residual {worst:e}");
    }
    // a space of other pair solves is refused
    let (k2, pairs2, _, _) = tied_model(&[]);
    let other = PairSolves::new(&FreeModel {
        pairs: &pairs2[..3],
        k: k2.as_ref(),
        ..free
    });
    assert!(other.unwrap().share_normals_with(&space).is_err());
}

#[test]
fn tied_solves_refuse_an_operator_they_do_not_describe() {
    let (k, pairs, mut op, _) = tied_model(&[0, 2]);
    let solves = pair_solves(&k, &pairs).unwrap();
    // a map that merges two DOFs that are not the normals of a pair
    let mut t = op.t.clone().unwrap();
    t[pairs[1].pin[0]] = t[pairs[1].disc[0]];
    op.t = Some(t);
    let e = StaticSolver::tied(&op, &solves).err().unwrap().to_string();
    assert!(e.contains("not the normals"), "{e}");
    op.t = None;
    let e = StaticSolver::tied(&op, &solves).err().unwrap().to_string();
    assert!(e.contains("no index map"), "{e}");
    // without pair solves (or at a shift) the solver factorizes its own K_c
    op.t = tied_model(&[0, 2]).2.t;
    let own = StaticSolver::tied_or_new(&op, None, 0.0).unwrap();
    assert_eq!(own.method, "K_c factorization");
    let shifted = StaticSolver::tied_or_new(&op, Some(&solves), 1.0).unwrap();
    assert_eq!(shifted.method, "K_c factorization");
}

#[test]
fn carried_images_stay_exact_when_a_block_pass_leaves_columns_short() {
    // 12 random columns, then 12 within 1e-6 of their span (a second block that the block
    // passes leave at about 1e-6 of its norm, its images recomputed together) and 8 of
    // those again within 1e-6 of each other: the images the extension hands back, used by
    // the next extension, must equal M V to the rounding of the columns
    let n = 150;
    let op = operator(n, 3, true, 13);
    let m = op.mc.as_ref();
    let mut rng = Rng(71);
    let first = rng.mat(n, 12);
    let mix = rng.mat(12, 20);
    let noise = rng.mat(n, 20);
    let near = &first * &mix;
    let cols = Mat::from_fn(n, 32, |r, c| {
        if c < 12 {
            first[(r, c)]
        } else if c < 24 {
            near[(r, c - 12)] + 1e-6 * noise[(r, c - 12)]
        } else {
            near[(r, c - 24)] + 1e-6 * noise[(r, c - 24)] + 1e-12 * noise[(r, c - 12)]
        }
    });
    let mut v = Mat::<f64>::zeros(n, 0);
    let mut mv = Mat::<f64>::zeros(n, 0);
    let mut dropped = 0;
    for c0 in [0, 12, 24] {
        let w = if c0 == 24 { 8 } else { 12 };
        dropped += super::orthonormal::m_orthonormal_extend_in_place(
            m,
            &mut v,
            &mut mv,
            cols.as_ref().subcols(c0, w),
            DEFAULT_RANK_TOL,
        )
        .unwrap();
    }
    assert_eq!(v.ncols() + dropped, 32);
    assert_eq!(v.ncols(), 24, "the last 8 repeat the second block to 1e-12");
    assert!(m_orthonormality_error(m, v.as_ref()) < 1e-12);
    let exact = crate::linalg::symmetric_times(m, v.as_ref());
    let mut worst = 0.0f64;
    for j in 0..v.ncols() {
        let scale = (0..n).fold(0.0f64, |a, i| a.max(exact[(i, j)].abs()));
        for i in 0..n {
            worst = worst.max((mv[(i, j)] - exact[(i, j)]).abs() / scale);
        }
    }
    assert!(worst < 1e-11, "carried image off by {worst:e}");
}

#[test]
fn directions_travel_between_contact_sets_on_the_free_dofs() {
    let (_, pairs, from, _) = tied_model(&[0, 2]);
    let (_, _, to, _) = tied_model(&[2, 3]);
    let mut rng = Rng(7);
    let v = Mat::from_fn(from.dim(), 3, |_, _| rng.next());
    let w = to_free_dofs(&from, v.as_ref()).unwrap();
    let t = from.t.as_ref().unwrap();
    assert_eq!(w.nrows(), t.len());
    // both DOFs of a tie carry the constrained value
    for &i in &[0, 2] {
        let (p, d) = (pairs[i].pin[2], pairs[i].disc[2]);
        assert_eq!(t[p], t[d]);
        for c in 0..3 {
            assert_eq!(w[(p, c)], w[(d, c)]);
        }
    }
    // back onto the same contact set: the columns themselves
    let back = from_free_dofs(&from, w.as_ref()).unwrap();
    assert_eq!(back, v);
    // onto another one: a new tie takes the mean of its two DOFs, the rest their value
    let moved = from_free_dofs(&to, w.as_ref()).unwrap();
    let tt = to.t.as_ref().unwrap();
    assert_eq!(moved.nrows(), to.dim());
    let (p, d) = (pairs[3].pin[2], pairs[3].disc[2]);
    for c in 0..3 {
        let mean = 0.5 * (w[(p, c)] + w[(d, c)]);
        assert!((moved[(tt[p], c)] - mean).abs() <= 1e-15 * mean.abs().max(1.0));
        let (p0, d0) = (pairs[0].pin[2], pairs[0].disc[2]);
        assert_eq!(moved[(tt[p0], c)], w[(p0, c)]);
        assert_eq!(moved[(tt[d0], c)], w[(d0, c)]);
    }
    // an operator without its index map, or columns of the wrong length: nothing
    let mut bare = from.clone();
    bare.t = None;
    assert!(to_free_dofs(&bare, v.as_ref()).is_none());
    assert!(from_free_dofs(&from, v.as_ref()).is_none());
}
