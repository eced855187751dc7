//! Unit tests of the free-interface synthesis on a small spring-mass model whose exact
//! constrained spectrum is known densely.

use super::*;
use squeal_core::faer::sparse::Triplet;
use squeal_core::faer::Side;
use squeal_core::{c64, SparseMat};
use squeal_core::{RealModes, SolveInfo};

const N: usize = 24;

/// A chain of `N` masses (diagonal mass) with springs to ground and to neighbours up to
/// three apart: symmetric positive definite, fully populated band.
fn model() -> (Mat<f64>, Vec<f64>) {
    let mut k = Mat::<f64>::zeros(N, N);
    for i in 0..N {
        k[(i, i)] += 1.0 + 0.1 * i as f64;
        for d in 1..=3 {
            if i + d < N {
                let s = 2.0 / d as f64 + 0.05 * ((i * 7 + d) % 5) as f64;
                k[(i, i)] += s;
                k[(i + d, i + d)] += s;
                k[(i, i + d)] -= s;
                k[(i + d, i)] -= s;
            }
        }
    }
    let m = (0..N).map(|i| 1.0 + 0.3 * ((i * 5) % 7) as f64).collect();
    (k, m)
}

fn sparse(k: &Mat<f64>) -> SparseMat {
    let mut trip = Vec::new();
    for j in 0..N {
        for i in 0..N {
            if k[(i, j)] != 0.0 {
                trip.push(Triplet::new(i, j, k[(i, j)]));
            }
        }
    }
    SparseMat::try_new_from_triplets(N, N, &trip).unwrap()
}

fn mass(m: &[f64]) -> SparseMat {
    let trip: Vec<_> = (0..N).map(|i| Triplet::new(i, i, m[i])).collect();
    SparseMat::try_new_from_triplets(N, N, &trip).unwrap()
}

/// The first `count` modes of `(K, diag(m))`, mass-normalized.
fn modes(k: &Mat<f64>, m: &[f64], count: usize) -> RealModes {
    let a = Mat::from_fn(N, N, |i, j| k[(i, j)] / (m[i] * m[j]).sqrt());
    let eig = a.self_adjoint_eigen(Side::Lower).unwrap();
    let omega2: Vec<f64> = (0..count).map(|c| eig.S()[c]).collect();
    let vectors = Mat::from_fn(N, count, |i, c| eig.U()[(i, c)] / m[i].sqrt());
    RealModes {
        freq_hz: omega2
            .iter()
            .map(|w| w.sqrt() / (2.0 * std::f64::consts::PI))
            .collect(),
        omega2,
        vectors,
        residuals: vec![0.0; count],
        info: SolveInfo::new("test"),
        above_band: Mat::zeros(N, 0),
    }
}

/// Pairs: "pin" DOFs (x, y, z) = (3i, 3i+1, 3i+2) against "disc" DOFs 12 + 3i .. .
fn pairs() -> Vec<PairDofs> {
    (0..4)
        .map(|i| PairDofs {
            pin: [3 * i, 3 * i + 1, 3 * i + 2],
            disc: [12 + 3 * i, 12 + 3 * i + 1, 12 + 3 * i + 2],
            direction: [0.6, 0.8, 0.0],
        })
        .collect()
}

/// The exact mu = 0 spectrum (omega^2, ascending) with the pairs `active` tied: the pin
/// normal DOF merged into the disc's (masses and stiffness summed).
fn exact_tied(k: &Mat<f64>, m: &[f64], active: &[usize]) -> Vec<f64> {
    let pr = pairs();
    let mut t: Vec<usize> = (0..N).collect();
    for &i in active {
        t[pr[i].pin[2]] = pr[i].disc[2];
    }
    let keep: Vec<usize> = (0..N).filter(|&j| t[j] == j).collect();
    let pos = |j: usize| keep.iter().position(|&x| x == t[j]).unwrap();
    let nc = keep.len();
    let mut kc = Mat::<f64>::zeros(nc, nc);
    let mut mc = vec![0.0; nc];
    for j in 0..N {
        mc[pos(j)] += m[j];
        for i in 0..N {
            kc[(pos(i), pos(j))] += k[(i, j)];
        }
    }
    let a = Mat::from_fn(nc, nc, |i, j| kc[(i, j)] / (mc[i] * mc[j]).sqrt());
    let eig = a.self_adjoint_eigen(Side::Lower).unwrap();
    (0..nc).map(|c| eig.S()[c]).collect()
}

#[test]
fn no_pair_gives_the_free_modes() {
    let (k, m) = model();
    let fi = FreeInterface::new(
        sparse(&k).as_ref(),
        mass(&m).as_ref(),
        &pairs(),
        &modes(&k, &m, 10),
    )
    .unwrap();
    let syn = fi.synthesize(&[], 0.4).unwrap();
    let mut s: Vec<f64> = syn.s.iter().map(|z| z.re).collect();
    s.sort_by(f64::total_cmp);
    let free = modes(&k, &m, 10).omega2;
    for (a, b) in s.iter().zip(&free) {
        assert!((a - b).abs() <= 1e-12 * b, "{a} vs {b}");
    }
}

#[test]
fn mu_zero_converges_to_the_tied_spectrum() {
    let (k, m) = model();
    let active = [0, 2, 3];
    let exact = exact_tied(&k, &m, &active);
    let mut errors = Vec::new();
    for count in [6, 12, 18] {
        let fi = FreeInterface::new(
            sparse(&k).as_ref(),
            mass(&m).as_ref(),
            &pairs(),
            &modes(&k, &m, count),
        )
        .unwrap();
        let syn = fi.synthesize(&active, 0.0).unwrap();
        let mut s: Vec<f64> = syn.s.iter().map(|z| z.re).collect();
        s.sort_by(f64::total_cmp);
        // the lowest three synthesized eigenvalues against the exact ones
        let err = (0..3)
            .map(|i| (s[i] - exact[i]).abs() / exact[i])
            .fold(0.0f64, f64::max);
        errors.push(err);
    }
    assert!(errors[0] < 0.1, "6 modes: {errors:?}");
    assert!(errors[2] < errors[0] * 0.5, "no convergence: {errors:?}");
}

#[test]
fn expanded_modes_satisfy_the_ties_exactly() {
    let (k, m) = model();
    let fi = FreeInterface::new(
        sparse(&k).as_ref(),
        mass(&m).as_ref(),
        &pairs(),
        &modes(&k, &m, 12),
    )
    .unwrap();
    let active = [1, 3];
    let syn = fi.synthesize(&active, 0.5).unwrap();
    let which: Vec<usize> = (0..syn.s.len()).collect();
    let u = fi.expand(&syn, &which);
    let pr = pairs();
    for c in 0..which.len() {
        let scale = (0..N).map(|i| u[(i, c)].norm()).fold(0.0f64, f64::max);
        for &i in &active {
            let gap = (u[(pr[i].pin[2], c)] - u[(pr[i].disc[2], c)]).norm();
            assert!(
                gap <= 1e-10 * scale,
                "mode {c} pair {i}: gap {gap:e} of {scale:e}"
            );
        }
    }
    let w = fi.correction(&syn, &which).unwrap();
    for c in 0..which.len() {
        let scale = (0..N).map(|i| w[(i, c)].norm()).fold(0.0f64, f64::max);
        for &i in &active {
            let gap = (w[(pr[i].pin[2], c)] - w[(pr[i].disc[2], c)]).norm();
            assert!(gap <= 1e-10 * scale, "correction {c} pair {i}: gap {gap:e}");
        }
    }
    // and friction makes the synthesized pencil non-symmetric: some s may be complex,
    // but conjugate pairs come together
    let complex: Vec<&c64> = syn
        .s
        .iter()
        .filter(|z| z.im.abs() > 1e-9 * z.norm())
        .collect();
    for z in &complex {
        assert!(syn
            .s
            .iter()
            .any(|w| (w - z.conj()).norm() <= 1e-9 * z.norm()));
    }
}

#[test]
fn bad_inputs_are_errors() {
    let (k, m) = model();
    let mut bad = modes(&k, &m, 5);
    bad.omega2[0] = 0.0;
    assert!(FreeInterface::new(sparse(&k).as_ref(), mass(&m).as_ref(), &pairs(), &bad).is_err());
    assert!(FreeInterface::new(
        sparse(&k).as_ref(),
        mass(&m).as_ref(),
        &[],
        &modes(&k, &m, 5)
    )
    .is_err());
    let fi = FreeInterface::new(
        sparse(&k).as_ref(),
        mass(&m).as_ref(),
        &pairs(),
        &modes(&k, &m, 5),
    )
    .unwrap();
    assert!(fi.synthesize(&[7], 0.3).is_err());
    assert!(fi.synthesize(&[0], f64::NAN).is_err());
}

#[test]
fn solved_and_stored_responses_expand_alike() {
    // the memory-light ways (static responses solved per expansion, or stored without
    // their second-order terms) against the one that stores both
    let (k, m) = model();
    let build = |limit: usize, gaps: usize| {
        FreeInterface::with_limits(
            sparse(&k).as_ref(),
            mass(&m).as_ref(),
            &pairs(),
            &modes(&k, &m, 12),
            limit,
            gaps,
        )
        .unwrap()
    };
    let first_only = 24 * N * pairs().len();
    let (stored, partly) = (build(usize::MAX, usize::MAX), build(first_only, usize::MAX));
    // solved, with the second-order gaps kept (the correction merged into one solve) and
    // without
    let (solved, unmerged) = (build(0, usize::MAX), build(0, 0));
    assert!(stored.stores_responses() && stored.stores_second_order());
    assert!(partly.stores_responses() && !partly.stores_second_order());
    for s in [&solved, &unmerged] {
        assert!(!s.stores_responses() && !s.stores_second_order());
    }
    assert!(solved.keeps_second_gaps() && !unmerged.keeps_second_gaps());
    assert!(!stored.keeps_second_gaps() && !partly.keeps_second_gaps());
    let active = [0, 2, 3];
    let a = stored.synthesize(&active, 0.6).unwrap();
    let which: Vec<usize> = (0..a.s.len()).collect();
    for other in [&partly, &solved, &unmerged] {
        let b = other.synthesize(&active, 0.6).unwrap();
        // the expansion and its correction together (the shared static response), too
        let (eb, cb) = other.expand_with_correction(&b, &which).unwrap();
        for (x, y) in [
            (stored.expand(&a, &which), other.expand(&b, &which)),
            (
                stored.correction(&a, &which).unwrap(),
                other.correction(&b, &which).unwrap(),
            ),
            (stored.expand(&a, &which), eb),
            (stored.correction(&a, &which).unwrap(), cb),
        ] {
            let scale = (0..N)
                .flat_map(|i| (0..which.len()).map(move |c| (i, c)))
                .map(|(i, c)| x[(i, c)].norm())
                .fold(0.0f64, f64::max);
            let diff = (0..N)
                .flat_map(|i| (0..which.len()).map(move |c| (i, c)))
                .map(|(i, c)| (x[(i, c)] - y[(i, c)]).norm())
                .fold(0.0f64, f64::max);
            assert!(
                scale > 0.0 && diff <= 1e-12 * scale,
                "differ by {diff:e} of {scale:e}"
            );
        }
    }
}

#[test]
fn pairs_projection_is_the_projection_of_its_columns() {
    let (k, m) = model();
    let fi = FreeInterface::with_pair_moments(
        sparse(&k).as_ref(),
        mass(&m).as_ref(),
        &pairs(),
        &modes(&k, &m, 12),
        None,
    )
    .unwrap();
    assert!(fi.has_pair_moments() && !fi.stores_responses());
    let md = Mat::from_fn(N, N, |i, j| if i == j { m[i] } else { 0.0 });
    let active = [1, 3];
    for second_order in [false, true] {
        let syn = fi.synthesize(&active, 0.5).unwrap();
        let which: Vec<usize> = (0..syn.s.len()).filter(|&c| syn.s[c].im >= 0.0).collect();
        let t: Vec<usize> = (0..N).collect();
        let p = fi
            .project_on_pairs(&syn, &which, second_order, &t, N)
            .unwrap();
        let cols = squeal_core::ImplicitColumns::ncols(&p.columns);
        let u = p
            .columns
            .unconstrained(Mat::<f64>::identity(cols, cols).as_ref());
        for (name, x, red) in [("K", &k, &p.reduced.kc), ("M", &md, &p.reduced.mc)] {
            let g = u.transpose() * x * &u;
            let err = (&g - red.to_dense()).norm_max() / g.norm_max();
            assert!(err < 1e-9, "second order {second_order}: {name}: {err:e}");
        }
    }
}

#[test]
fn pair_moments_beyond_their_memory_limit_are_refused() {
    let (k, m) = model();
    let args = (sparse(&k), mass(&m), pairs(), modes(&k, &m, 6));
    let moments = |limit| {
        super::pairs::PairMoments::zeros(args.0.as_ref(), args.1.as_ref(), &args.2, &args.3, limit)
    };
    // 4 pairs: 288 * 16 bytes
    assert!(moments(288 * 16).is_ok());
    let err = moments(288 * 16 - 1).err().expect("refused").to_string();
    assert!(
        err.contains("projection") && err.contains("4 candidate pairs"),
        "{err}"
    );
}

#[test]
fn second_gaps_are_kept_for_many_contact_sets_only() {
    use super::construct::gaps_pay;
    assert!(gaps_pay(4761, 1400) && gaps_pay(1681, 280));
    assert!(!gaps_pay(4761, 280) && !gaps_pay(1681, 10));
    // a model whose responses are stored keeps no gaps, whatever the number of sets
    let (k, m) = model();
    let fi = FreeInterface::for_contact_sets(
        sparse(&k).as_ref(),
        mass(&m).as_ref(),
        &pairs(),
        &modes(&k, &m, 12),
        None,
        1000,
    )
    .unwrap();
    assert!(fi.stores_responses() && !fi.keeps_second_gaps());
}
