//! How the default disc's dimensions were chosen: a Nelder-Mead fit of the disc ring
//! and its hat (ring inner and outer radius, ring thickness, hat height, hat wall
//! thickness, hat radius) to the paper's Table 2.
//!
//! Run: `cargo run --release --example disc_fit -- [r_in R h hat_height hat_wall hat_radius]`
//! Objective: sum over the 16 labels of (log f_squeal - log f_paper)^2, a missing label
//! costing (log 1.5)^2; the pin face (radii 0.09 to 0.11 m) must stay on the ring.
//! `SQUEAL_FIT_EVAL=1` only evaluates the given point. Set `SQUEAL_FIT_EPW` to change elements per wavelength during the search (default 10).

use squeal::analysis::modal::{compare_table2, format_table, normal_modes};
use squeal::core::{EigenParams, Params};
use squeal::scene::{build, BodyKind, Hat, Scene};

const N: usize = 6;

fn cost(x: &[f64; N], epw: f64, verbose: bool) -> f64 {
    let [ri, r, h, hh, th, rh] = *x;
    if !(0.01..=0.088).contains(&ri)
        || r < 0.12
        || h < 0.004
        || hh < 0.002
        || th < 0.001
        || rh < ri
        || rh + th > 0.088
    {
        return 1e3;
    }
    let reg = squeal::registry();
    let mut scene = Scene::builtin("pin-on-disc").unwrap();
    scene.mesh.elements_per_wavelength = epw;
    let d = scene.disc.as_mut().unwrap();
    (d.inner_radius_m, d.outer_radius_m, d.thickness_m) = (ri, r, h);
    d.hat = Some(Hat {
        radius_m: Some(rh),
        height_m: hh,
        thickness_m: th,
    });
    let model = build(&scene, BodyKind::Disc, &reg, "fit").unwrap();
    let solver = reg.eigen.create("arpack", &Params::new()).unwrap();
    let params = EigenParams {
        fmax_hz: 11_500.0,
        tol: 1e-9,
        ..Default::default()
    };
    let (_, modes) = normal_modes(&model, solver.as_ref(), &params).unwrap();
    let rows = compare_table2(&modes);
    let c: f64 = rows
        .iter()
        .map(|r| {
            r.squeal_hz
                .map_or(1.5f64.ln().powi(2), |f| (f / r.paper_hz).ln().powi(2))
        })
        .sum();
    if verbose {
        print!("{}", format_table(&rows));
    }
    println!("x = {x:.4?} -> cost {c:.5} ({} DOFs)", model.dofs.n_free());
    c
}

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let epw: f64 = std::env::var("SQUEAL_FIT_EPW")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10.0);
    let x0: [f64; N] = if args.len() == N {
        std::array::from_fn(|i| args[i])
    } else {
        [0.07, 0.15, 0.02, 0.03, 0.004, 0.07]
    };
    if std::env::var("SQUEAL_FIT_EVAL").is_ok() {
        cost(&x0, epw, true);
        return;
    }
    let mut simplex: Vec<([f64; N], f64)> = (0..=N)
        .map(|i| {
            let mut x = x0;
            if i > 0 {
                x[i - 1] *= 1.15;
            }
            (x, cost(&x, epw, false))
        })
        .collect();
    for _ in 0..150 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let c: [f64; N] =
            std::array::from_fn(|k| simplex[..N].iter().map(|s| s.0[k]).sum::<f64>() / N as f64);
        let w = simplex[N];
        let at = |t: f64| -> [f64; N] { std::array::from_fn(|k| c[k] + t * (w.0[k] - c[k])) };
        let r = at(-1.0);
        let fr = cost(&r, epw, false);
        if fr < simplex[0].1 {
            let e = at(-2.0);
            let fe = cost(&e, epw, false);
            simplex[N] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < simplex[N - 1].1 {
            simplex[N] = (r, fr);
        } else {
            let k = at(0.5);
            let fk = cost(&k, epw, false);
            if fk < w.1 {
                simplex[N] = (k, fk);
            } else {
                let best = simplex[0].0;
                for s in simplex.iter_mut().skip(1) {
                    s.0 = std::array::from_fn(|k| best[k] + 0.5 * (s.0[k] - best[k]));
                    s.1 = cost(&s.0, epw, false);
                }
            }
        }
        let hi = simplex.iter().map(|s| s.1).fold(0.0f64, f64::max);
        let lo = simplex.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
        if hi - lo < 1e-7 {
            break;
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    println!("best:");
    cost(&simplex[0].0, epw, true);
}
