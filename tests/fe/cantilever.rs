//! A slender steel cantilever against Euler-Bernoulli beam theory.
//!
//! `L = 0.2 m`, section `b = 0.01 m` (y) by `h = 0.005 m` (z): `L/h = 40`, so shear
//! deformation and rotary inertia shift the second z-bending frequency by about 0.25 %
//! (Timoshenko). Two elements through the thickness and the width, 80 along the length
//! (cubes of 2.5 mm). The x = 0 face is clamped (all its DOFs eliminated).
//!
//! `f_n = (beta_n L)^2 / (2 pi L^2) sqrt(E I / (rho A))`, `beta_1 L = 1.875104`,
//! `beta_2 L = 4.694091`; z bending: `I = b h^3 / 12`, y bending: `I = h b^3 / 12`.
//! The rectangular section separates z-bending (the lower) from y-bending modes; each
//! mode is classified by the component carrying most of its kinetic energy.

use crate::common::{column, quad, solver, steel, E_STEEL, RHO_STEEL};
use squeal_core::{EigenParams, SymmetricProblem};
use squeal_fe::mesh::linspace;
use squeal_fe::{assemble, DofMap, Mesh};
use std::f64::consts::PI;
use std::time::Instant;

const L: f64 = 0.2;
const B: f64 = 0.01;
const H: f64 = 0.005;
const BETA_L: [f64; 2] = [1.875104, 4.694091];

/// Euler-Bernoulli cantilever frequency (Hz) of mode `n` (0-based) for bending with
/// section depth `d` (the dimension along the displacement).
fn euler_bernoulli(n: usize, d: f64) -> f64 {
    // E I / (rho A) = E d^2 / (12 rho) for a rectangle
    BETA_L[n].powi(2) / (2.0 * PI * L * L) * (E_STEEL * d * d / (12.0 * RHO_STEEL)).sqrt()
}

#[test]
fn cantilever_bending_matches_euler_bernoulli() {
    let mesh = Mesh::block(
        &linspace(0.0, L, 80),
        &linspace(-B / 2.0, B / 2.0, 2),
        &linspace(-H / 2.0, H / 2.0, 2),
    );
    let clamped = DofMap::node_dofs(mesh.node_set("xmin").unwrap());
    let dofs = DofMap::new(&mesh, &clamped);
    assert_eq!(dofs.n_free(), 3 * (mesh.n_nodes() - 9));
    let mat = steel();
    let asm = assemble(&mesh, &dofs, &[&mat]).expect("assembly");
    let (k, m) = (asm.k.as_ref(), asm.m.as_ref());

    let fz = [euler_bernoulli(0, H), euler_bernoulli(1, H)];
    let fy = [euler_bernoulli(0, B), euler_bernoulli(1, B)];
    let params = EigenParams {
        fmax_hz: 1.5 * fz[1],
        ..Default::default()
    };
    let t0 = Instant::now();
    let modes = solver("arpack")
        .solve_symmetric(&SymmetricProblem { k, m }, &params)
        .expect("arpack");
    eprintln!(
        "cantilever: n = {}, {} modes below {:.1} Hz in {:.3} s",
        dofs.n_free(),
        modes.freq_hz.len(),
        params.fmax_hz,
        t0.elapsed().as_secs_f64()
    );

    // kinetic energy share of each component (the consistent mass does not couple them)
    let mut z_bending = Vec::new();
    let mut y_bending = Vec::new();
    for i in 0..modes.freq_hz.len() {
        let x = column(&modes.vectors, i);
        let total = quad(m, &x, &x);
        let share: Vec<f64> = (0..3)
            .map(|c| {
                let xc: Vec<f64> = x
                    .iter()
                    .zip(&dofs.full_of_free)
                    .map(|(&v, &d)| if d % 3 == c { v } else { 0.0 })
                    .collect();
                quad(m, &xc, &xc) / total
            })
            .collect();
        eprintln!(
            "cantilever: mode {}: {:9.3} Hz, energy shares x {:.4} y {:.4} z {:.4}, residual {:.1e}",
            i + 1,
            modes.freq_hz[i],
            share[0],
            share[1],
            share[2],
            modes.residuals[i]
        );
        assert!(modes.residuals[i] <= 1e-10);
        if share[2] > 0.95 {
            z_bending.push(modes.freq_hz[i]);
        } else if share[1] > 0.95 {
            y_bending.push(modes.freq_hz[i]);
        }
    }
    for (dir, found, beam) in [("z", &z_bending, fz), ("y", &y_bending, fy)] {
        for (n, (f, e)) in found.iter().zip(beam).enumerate() {
            eprintln!(
                "cantilever: {dir}-bending mode {}: FE {f:.3} Hz, Euler-Bernoulli {e:.3} Hz, error {:+.3} %",
                n + 1,
                100.0 * (f / e - 1.0)
            );
        }
    }
    assert!(z_bending.len() >= 2, "z-bending modes found: {z_bending:?}");
    for n in 0..2 {
        let err = z_bending[n] / fz[n] - 1.0;
        assert!(
            err.abs() < 0.01,
            "z-bending mode {}: {:.3} Hz vs Euler-Bernoulli {:.3} Hz ({:+.3} %)",
            n + 1,
            z_bending[n],
            fz[n],
            100.0 * err
        );
    }
    // the first y-bending mode lies in the band too (L/b = 20: shear effect ~0.1 %)
    assert!(
        !y_bending.is_empty(),
        "no y-bending mode below {} Hz",
        params.fmax_hz
    );
    let err = y_bending[0] / fy[0] - 1.0;
    assert!(
        err.abs() < 0.01,
        "y-bending mode 1: {:.3} Hz vs {:.3} Hz",
        y_bending[0],
        fy[0]
    );
}
