//! The frictional operator against its oracles on a tiny model
//! built through the production code paths: two hexahedral blocks (a "disc" block clamped
//! at its bottom, a "pin" block clamped at its top) touching at z = 0 with 3 x 3
//! node-to-node pairs, assembled by squeal-fe, paired by `ContactSet::from_pairs`,
//! eliminated by `build_operator`.
//!
//! - T1: mu = 0 gives no growing mode.
//! - T2: another admissible `L` (the disc-normal selector `-E_m`) gives the same spectrum;
//!   the unscaled `P~n` used as `L` (`P~n P~n^T = 2 I`) gives a different one.
//! - T3: the penalty model `K + kn (P~n + mu P~t)^T P~n` tends to the constrained spectrum
//!   like `1/kn`.
//! - T5: the full descriptor pencil in `(u, lambda u, r)` solved densely (QZ) has the
//!   eliminated operator's eigenvalues.

use squeal_contact::{build_operator, ContactSet};
use squeal_core::c64;
use squeal_core::faer::sparse::Triplet;
use squeal_core::faer::Mat;
use squeal_core::operator::Qep;
use squeal_core::qep::dense_qep;
use squeal_core::{FrictionalOperator, Material, SparseMat};
use squeal_fe::{assemble, DofMap, Mesh};

struct Tiny {
    m: SparseMat,
    k: SparseMat,
    set: ContactSet,
}

fn tiny() -> Tiny {
    let xs = [-0.004, 0.0, 0.004];
    let ys = [0.096, 0.1, 0.104];
    let lower = Mesh::block(&xs, &ys, &[-0.006, 0.0]).with_body(0);
    let upper = Mesh::block(&xs, &ys, &[0.0, 0.008]).with_body(1);
    let mut mesh = Mesh::default();
    mesh.append(&lower, "disc.", None);
    let map = mesh.append(&upper, "pin.", None);
    let _ = map;
    let mut fixed: Vec<usize> = mesh.node_set("disc.zmin").unwrap().to_vec();
    fixed.extend(mesh.node_set("pin.zmax").unwrap());
    fixed.sort_unstable();
    let dofs = DofMap::new(&mesh, &DofMap::node_dofs(&fixed));
    let steel = squeal_materials::Isotropic::new(210e9, 0.3, 7850.0).unwrap();
    let pad = squeal_materials::Isotropic::new(15e9, 0.15, 4000.0).unwrap();
    let mats: [&dyn Material; 2] = [&steel, &pad];
    let asm = assemble(&mesh, &dofs, &mats).unwrap();
    let (mut xy, mut pin, mut disc) = (Vec::new(), Vec::new(), Vec::new());
    let dof = |n: usize| [0, 1, 2].map(|a| dofs.free_of_full[3 * n + a].unwrap());
    for &s in mesh.node_set("pin.zmin").unwrap() {
        let p = mesh.nodes[s];
        let m = *mesh
            .node_set("disc.zmax")
            .unwrap()
            .iter()
            .find(|&&m| {
                let q = mesh.nodes[m];
                (q[0] - p[0]).abs() < 1e-12 && (q[1] - p[1]).abs() < 1e-12
            })
            .unwrap();
        xy.push([p[0], p[1]]);
        pin.push(dof(s));
        disc.push(dof(m));
    }
    let set = ContactSet::from_pairs(dofs.n_free(), xy, pin, disc, 1.0).unwrap();
    Tiny {
        m: asm.m,
        k: asm.k,
        set,
    }
}

fn dense(a: &SparseMat) -> Mat<f64> {
    a.as_ref().to_dense()
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

/// Finite eigenvalues with Im > 0, sorted by imaginary part.
fn upper(mut l: Vec<c64>) -> Vec<c64> {
    l.retain(|z| z.is_finite() && z.im > 1e-8 * z.norm());
    l.sort_by(|a, b| a.im.total_cmp(&b.im));
    l
}

fn spectrum(q: &Qep) -> Vec<c64> {
    upper(dense_qep(q).unwrap().0)
}

fn close(a: &[c64], b: &[c64], tol: f64) -> f64 {
    assert_eq!(a.len(), b.len(), "spectra of different sizes");
    let scale = a.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    // match each eigenvalue to its nearest unused partner: coupled pairs share their
    // imaginary part, so an order by frequency alone is ambiguous
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
    assert!(
        worst <= tol * scale,
        "spectra differ by {:e} (relative)",
        worst / scale
    );
    worst / scale
}

/// The eliminated operator built densely from the definition with a given `L`:
/// `T^T (I - mu Pt^T L) X T`.
fn dense_operator(t: &Tiny, op: &FrictionalOperator, l: &Mat<f64>, mu: f64) -> Qep {
    let n = t.k.nrows();
    let tmap = op.t.as_ref().unwrap();
    let nc = op.dim();
    let tm = Mat::from_fn(n, nc, |i, j| if tmap[i] == j { 1.0 } else { 0.0 });
    let pt = dense(&t.set.pt);
    let p = Mat::<f64>::identity(n, n) - (pt.transpose() * l) * mu;
    let f = |x: &SparseMat| sparse(&(tm.transpose() * &p * dense(x) * &tm));
    Qep {
        m: f(&t.m),
        c: None,
        k: f(&t.k),
    }
}

#[test]
fn t1_no_growth_without_friction() {
    let t = tiny();
    let op = build_operator(
        t.m.as_ref(),
        None,
        t.k.as_ref(),
        &t.set,
        &vec![true; t.set.len()],
    )
    .unwrap();
    let l = spectrum(&op.at(0.0).unwrap());
    assert!(!l.is_empty());
    for z in &l {
        assert!(z.re <= 1e-9 * z.norm(), "growing mode {z} at mu = 0");
    }
    // and the mu = 0 operator is symmetric
    let k = dense(&op.at(0.0).unwrap().k);
    let asym = (&k - k.transpose()).norm_max() / k.norm_max();
    assert!(asym < 1e-14);
}

#[test]
fn t2_admissible_l_give_the_same_spectrum_and_unscaled_pn_does_not() {
    let t = tiny();
    let nc = t.set.len();
    let n = t.k.nrows();
    let op = build_operator(t.m.as_ref(), None, t.k.as_ref(), &t.set, &vec![true; nc]).unwrap();
    // a friction level past coupling so that the spectrum is sensitive to mu
    let mu = 0.6;
    let ours = spectrum(&op.at(mu).unwrap());
    // L = E_s (the slave-normal selector) built densely: same as the sparse operator
    let es = Mat::from_fn(
        nc,
        n,
        |i, j| if j == t.set.pin_dofs[i][2] { 1.0 } else { 0.0 },
    );
    close(&ours, &spectrum(&dense_operator(&t, &op, &es, mu)), 1e-10);
    // L = -E_m, the disc-normal selector: also L Pn^T = I, L Pt^T = 0
    let em = Mat::from_fn(nc, n, |i, j| {
        if j == t.set.disc_dofs[i][2] {
            -1.0
        } else {
            0.0
        }
    });
    let pn = dense(&t.set.pn);
    let check = &em * pn.transpose();
    assert!((&check - Mat::<f64>::identity(nc, nc)).norm_max() < 1e-15);
    close(&ours, &spectrum(&dense_operator(&t, &op, &em, mu)), 1e-9);
    // the unscaled P~n (P~n P~n^T = 2 I) doubles the effective friction
    let wrong = spectrum(&dense_operator(&t, &op, &pn, mu));
    let doubled = spectrum(&op.at(2.0 * mu).unwrap());
    close(&wrong, &doubled, 1e-9);
    let moved = std::panic::catch_unwind(|| close(&ours, &wrong, 1e-6));
    assert!(moved.is_err(), "the wrong L must change the spectrum");
}

#[test]
fn t3_penalty_tends_to_the_constrained_spectrum_like_one_over_kn() {
    let t = tiny();
    let nc = t.set.len();
    let mu = 0.3;
    let op = build_operator(t.m.as_ref(), None, t.k.as_ref(), &t.set, &vec![true; nc]).unwrap();
    let exact = spectrum(&op.at(mu).unwrap());
    let (pn, pt) = (dense(&t.set.pn), dense(&t.set.pt));
    let coupling = (&pn + &pt * mu).transpose() * &pn;
    let k = dense(&t.k);
    let mut errs = Vec::new();
    for kn in [1e11, 1e12, 1e13] {
        let q = Qep {
            m: t.m.clone(),
            c: None,
            k: sparse(&(&k + &coupling * kn)),
        };
        // the penalty model keeps nc extra (stiff) modes: compare the lowest ones
        let pen = spectrum(&q);
        let low: Vec<c64> = pen.into_iter().take(exact.len()).collect();
        errs.push(close(&exact, &low, 1.0));
    }
    assert!(errs[2] < 1e-3, "errors {errs:?}");
    for w in errs.windows(2) {
        let ratio = w[0] / w[1];
        assert!(
            (5.0..20.0).contains(&ratio),
            "errors {errs:?}: not like 1/kn"
        );
    }
}

#[test]
fn t5_descriptor_pencil_equals_the_eliminated_operator() {
    let t = tiny();
    let nc = t.set.len();
    let n = t.k.nrows();
    let mu = 0.5;
    let op = build_operator(t.m.as_ref(), None, t.k.as_ref(), &t.set, &vec![true; nc]).unwrap();
    let ours = spectrum(&op.at(mu).unwrap());
    assert!(
        ours.iter().any(|z| z.re > 1e-6 * z.norm()),
        "mu = {mu} should make the tiny model flutter"
    );
    // z = (u, w u, r) with lambda = s w (s balances K against M): A z = w B z,
    // A = [0 I 0; -K/s^2 0 G/s^2; Pn 0 0], B = [I 0 0; 0 M 0; 0 0 0], G = (Pn + mu Pt)^T
    let (k, m) = (dense(&t.k), dense(&t.m));
    let (pn, pt) = (dense(&t.set.pn), dense(&t.set.pt));
    let g = (&pn + &pt * mu).transpose().to_owned();
    let s = (k.norm_max() / m.norm_max()).sqrt();
    let s2 = s * s;
    let size = 2 * n + nc;
    let mut a = Mat::<f64>::zeros(size, size);
    let mut b = Mat::<f64>::zeros(size, size);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        b[(i, i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = -k[(i, j)] / s2;
            b[(n + i, n + j)] = m[(i, j)];
        }
        for c in 0..nc {
            a[(n + i, 2 * n + c)] = g[(i, c)] / s2;
            a[(2 * n + c, i)] = pn[(c, i)];
        }
    }
    let gev = a.generalized_eigen(&b).unwrap();
    let (sa, sb) = (gev.S_a(), gev.S_b());
    let lam: Vec<c64> = (0..size)
        .filter(|&i| sb[i].norm() > 1e-10 * sa[i].norm())
        .map(|i| sa[i] / sb[i] * s)
        .collect();
    let full = upper(lam);
    close(&ours, &full, 1e-8);
}
