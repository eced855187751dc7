//! A free (unsupported) distorted block: six rigid-body modes, the seventh elastic, and
//! the right mass.

use crate::common::{column, hz, norm1, perturb, quad, sci, solver, steel, E_STEEL, RHO_STEEL};
use approx::assert_relative_eq;
use squeal_core::eigen::dense_symmetric;
use squeal_core::{EigenParams, SymmetricProblem};
use squeal_fe::mesh::{hex_volume, linspace};
use squeal_fe::{assemble, DofMap, Mesh};
use std::time::Instant;

const LX: f64 = 0.04;
const LY: f64 = 0.025;
const LZ: f64 = 0.015;

/// 4 x 2 x 2 elements, every node moved by up to 20 % of the spacing.
fn distorted_block() -> Mesh {
    let mut mesh = Mesh::block(
        &linspace(0.0, LX, 4),
        &linspace(0.0, LY, 2),
        &linspace(0.0, LZ, 2),
    );
    perturb(
        &mut mesh,
        [LX / 4.0, LY / 2.0, LZ / 2.0],
        0.2,
        0x5eed_1234,
        &|_| false,
    );
    mesh
}

/// The six rigid motions (3 translations, 3 small rotations about the centroid) as
/// free-DOF vectors.
fn rigid_motions(mesh: &Mesh, dofs: &DofMap) -> Vec<Vec<f64>> {
    let c = [LX / 2.0, LY / 2.0, LZ / 2.0];
    (0..6)
        .map(|k| {
            dofs.full_of_free
                .iter()
                .map(|&d| {
                    let (n, comp) = (d / 3, d % 3);
                    if k < 3 {
                        return if comp == k { 1.0 } else { 0.0 };
                    }
                    // rotation about axis a: u = e_a x (x - c)
                    let a = k - 3;
                    let p = mesh.nodes[n];
                    let r = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                    let mut e = [0.0; 3];
                    e[a] = 1.0;
                    let u = [
                        e[1] * r[2] - e[2] * r[1],
                        e[2] * r[0] - e[0] * r[2],
                        e[0] * r[1] - e[1] * r[0],
                    ];
                    u[comp] / LX
                })
                .collect()
        })
        .collect()
}

/// The free block, its DOF map and matrices.
fn free_block() -> (Mesh, DofMap, squeal_fe::Assembled) {
    let mesh = distorted_block();
    let dofs = DofMap::new(&mesh, &[]);
    assert_eq!(dofs.n_free(), 3 * mesh.n_nodes());
    let asm = assemble(&mesh, &dofs, &[&steel()]).expect("assembly");
    (mesh, dofs, asm)
}

/// Independent eigenvalue oracle: `M = L L^T`, `A = L^-1 K L^-T`, eigenvalues of `A` by
/// the cyclic Jacobi method (no faer eigen routine involved), sorted.
fn jacobi_eigenvalues(problem: &SymmetricProblem<'_>) -> Vec<f64> {
    use squeal_core::faer::linalg::triangular_solve::solve_lower_triangular_in_place;
    use squeal_core::faer::{Par, Side};
    let m = problem.m.to_dense();
    let l = m.llt(Side::Lower).expect("M is SPD").L().to_owned();
    let mut a = problem.k.to_dense();
    solve_lower_triangular_in_place(l.as_ref(), a.as_mut(), Par::Seq);
    let mut a = a.transpose().to_owned();
    solve_lower_triangular_in_place(l.as_ref(), a.as_mut(), Par::Seq);
    let n = a.nrows();
    let mut a: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| 0.5 * (a[(i, j)] + a[(j, i)])).collect())
        .collect();
    let frob2: f64 = a.iter().flatten().map(|v| v * v).sum();
    let mut converged = false;
    for _sweep in 0..60 {
        let off2: f64 = (0..n)
            .flat_map(|p| (p + 1..n).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q] * a[p][q])
            .sum();
        if off2 <= 1e-32 * frob2 {
            converged = true;
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (x, y) = (row[p], row[q]);
                    row[p] = c * x - s * y;
                    row[q] = s * x + c * y;
                }
                for k in 0..n {
                    let (x, y) = (a[p][k], a[q][k]);
                    a[p][k] = c * x - s * y;
                    a[q][k] = s * x + c * y;
                }
            }
        }
    }
    assert!(converged, "Jacobi oracle did not converge");
    let mut lam: Vec<f64> = (0..n).map(|i| a[i][i]).collect();
    lam.sort_by(f64::total_cmp);
    lam
}

/// Number of `|omega^2| < 1e-8 omega_7^2` in a sorted spectrum, and `omega_7^2`.
fn count_rigid(lam: &[f64]) -> (usize, f64) {
    let l7 = lam[6];
    (lam.iter().filter(|l| l.abs() < 1e-8 * l7).count(), l7)
}

#[test]
fn free_block_mass_and_rigid_null_space() {
    let (mesh, dofs, asm) = free_block();
    let (k, m) = (asm.k.as_ref(), asm.m.as_ref());
    // mass: rho * sum of element volumes, and the rigid translations carry all of it
    let volume: f64 = (0..mesh.hexes.len())
        .map(|e| hex_volume(&mesh.hex_coords(e)))
        .sum();
    eprintln!(
        "rigid: volume {volume:.6e} m^3 (undistorted {:.6e}), mass {:.6e} kg",
        LX * LY * LZ,
        asm.total_mass
    );
    assert_relative_eq!(asm.total_mass, RHO_STEEL * volume, max_relative = 1e-12);
    let rigid = rigid_motions(&mesh, &dofs);
    for t in &rigid[..3] {
        assert_relative_eq!(quad(m, t, t), RHO_STEEL * volume, max_relative = 1e-12);
    }
    // the six rigid motions are in the null space of K
    let kn = norm1(k);
    for (i, r) in rigid.iter().enumerate() {
        let mut kr = vec![0.0; r.len()];
        squeal_core::linalg::spmv(k, r, &mut kr);
        let rel = kr.iter().fold(0.0f64, |a, v| a.max(v.abs()))
            / (kn * r.iter().fold(0.0f64, |a, v| a.max(v.abs())));
        eprintln!("rigid: motion {i}: |K r|_inf / (|K|_1 |r|_inf) = {rel:.2e}");
        assert!(rel < 1e-12, "rigid motion {i} strains the block: {rel:e}");
    }
    // and the oracle spectrum has exactly six zero eigenvalues, then an elastic one
    let lam = jacobi_eigenvalues(&SymmetricProblem { k, m });
    let (n_zero, l7) = count_rigid(&lam);
    let scale = E_STEEL / RHO_STEEL / (LX * LX);
    eprintln!(
        "rigid: Jacobi oracle omega^2[0..8] = {}; f7 = {:.1} Hz, omega7^2 / (c/L)^2 = {:.3}",
        sci(&lam[..8]),
        hz(l7),
        l7 / scale
    );
    assert_eq!(n_zero, 6, "zero-energy modes: omega^2 = {}", sci(&lam[..8]));
    // clearly elastic: of the order of (c / L)^2, c = sqrt(E / rho), L the longest side
    assert!(
        l7 > 0.1 * scale,
        "7th eigenvalue {l7:e} is not elastic (scale {scale:e})"
    );
}

/// `squeal_core::eigen::dense_symmetric` on the 135-DOF free block: six rigid modes and
/// accurate eigenpairs (relative residual as in the eigen module docs).
#[test]
fn free_block_dense_symmetric_has_six_rigid_modes() {
    let (_, _, asm) = free_block();
    let (k, m) = (asm.k.as_ref(), asm.m.as_ref());
    let problem = SymmetricProblem { k, m };
    let t0 = Instant::now();
    let (lam, x) = dense_symmetric(&problem).expect("dense eigen");
    let mut order: Vec<usize> = (0..lam.len()).collect();
    order.sort_by(|&a, &b| lam[a].total_cmp(&lam[b]));
    let sorted: Vec<f64> = order.iter().map(|&i| lam[i]).collect();
    let (kn, mn) = (norm1(k), norm1(m));
    let residual = |i: usize| {
        let v = column(&x, i);
        let (mut kv, mut mv) = (vec![0.0; v.len()], vec![0.0; v.len()]);
        squeal_core::linalg::spmv(k, &v, &mut kv);
        squeal_core::linalg::spmv(m, &v, &mut mv);
        let r: Vec<f64> = kv.iter().zip(&mv).map(|(a, b)| a - lam[i] * b).collect();
        squeal_core::linalg::norm2(&r) / ((kn + lam[i].abs() * mn) * squeal_core::linalg::norm2(&v))
    };
    let worst = order[..8]
        .iter()
        .map(|&i| residual(i))
        .fold(0.0f64, f64::max);
    eprintln!(
        "rigid: dense_symmetric n = {} in {:.3} s; omega^2[0..8] = {}; max residual of the 8 lowest pairs {worst:.2e}",
        lam.len(),
        t0.elapsed().as_secs_f64(),
        sci(&sorted[..8])
    );
    let (n_zero, _) = count_rigid(&sorted);
    assert_eq!(
        n_zero,
        6,
        "dense_symmetric: zero-energy modes: omega^2 = {}",
        sci(&sorted[..8])
    );
    assert!(
        worst <= 1e-10,
        "dense_symmetric: eigenpair residual {worst:e}"
    );
    // the eigenvalues agree with the independent oracle
    let oracle = jacobi_eigenvalues(&problem);
    assert_relative_eq!(sorted[6], oracle[6], max_relative = 1e-9);
}

/// The registry's Krylov solvers (no dense fallback) on the free block.
#[test]
fn free_block_krylov_solvers_find_six_rigid_modes() {
    let (_, _, asm) = free_block();
    let (k, m) = (asm.k.as_ref(), asm.m.as_ref());
    let problem = SymmetricProblem { k, m };
    let lam = jacobi_eigenvalues(&problem);
    let (n_zero, l7) = count_rigid(&lam);
    assert_eq!(n_zero, 6, "oracle: omega^2 = {}", sci(&lam[..8]));
    assert!(
        lam[7] > l7 * (1.0 + 1e-6),
        "f7 and f8 must be distinct for the band test"
    );
    let zero = 1e-8 * l7;
    for name in ["arpack", "krylov"] {
        let s = solver(name);
        let below = EigenParams {
            fmax_hz: 0.5 * hz(l7),
            dense_below: 0,
            ..Default::default()
        };
        let t0 = Instant::now();
        let modes = s.solve_symmetric(&problem, &below).expect("solve below f7");
        eprintln!(
            "rigid: {name}: {} modes below {:.1} Hz in {:.3} s, omega^2 = {}, residuals <= {:.2e}, notes {:?}",
            modes.omega2.len(),
            below.fmax_hz,
            t0.elapsed().as_secs_f64(),
            sci(&modes.omega2),
            modes.residuals.iter().fold(0.0f64, |a, &r| a.max(r)),
            modes.info.notes
        );
        assert!(
            modes.info.notes.iter().all(|n| !n.contains("densely")),
            "{name} fell back to the dense solver"
        );
        assert_eq!(
            modes.omega2.len(),
            6,
            "{name}: omega^2 = {}",
            sci(&modes.omega2)
        );
        for (i, &l) in modes.omega2.iter().enumerate() {
            assert!(
                l.abs() < zero,
                "{name}: rigid mode {i} has omega^2 = {l:e}, 7th {l7:e}"
            );
            assert!(
                modes.residuals[i] <= 1e-10,
                "{name}: residual {:e}",
                modes.residuals[i]
            );
            // a rigid mode is a rigid motion: no strain energy relative to its mass
            let x = column(&modes.vectors, i);
            assert!(quad(k, &x, &x).abs() < zero * quad(m, &x, &x));
        }

        // band top between f7 and f8: the seventh mode appears, equal to the oracle's
        let with7 = EigenParams {
            fmax_hz: 0.5 * (hz(l7) + hz(lam[7])),
            ..below
        };
        let modes = s.solve_symmetric(&problem, &with7).expect("solve up to f7");
        assert_eq!(
            modes.omega2.len(),
            7,
            "{name}: omega^2 = {}",
            sci(&modes.omega2)
        );
        eprintln!(
            "rigid: {name}: f7 = {:.6} Hz (oracle {:.6} Hz), rel diff of omega^2 {:.2e}",
            modes.freq_hz[6],
            hz(l7),
            (modes.omega2[6] / l7 - 1.0).abs()
        );
        assert_relative_eq!(modes.omega2[6], l7, max_relative = 1e-9);
        assert!(
            modes.residuals[6] <= 1e-10,
            "{name}: residual {:e}",
            modes.residuals[6]
        );
    }
}
