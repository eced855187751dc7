//! How the default disc's dimensions were chosen: a Nelder-Mead fit of the clamped
//! annular disc (hub radius, outer radius, thickness) to the paper's Table 2.
//!
//! Run: `cargo run --release --example disc_fit -- [r_in R h]`
//! Objective: sum over the 16 labels of (log f_squeal - log f_paper)^2, a missing label
//! costing (log 1.5)^2. Uses the default scene's mesh rule and the `arpack` solver.

use squeal::analysis::modal::{compare_table2, normal_modes};
use squeal::core::{EigenParams, Params};
use squeal::scene::{build, BodyKind, Scene};

fn cost(x: &[f64; 3], verbose: bool) -> f64 {
    let reg = squeal::registry();
    let mut scene = Scene::builtin("pin-on-disc").unwrap();
    let d = scene.disc.as_mut().unwrap();
    (d.inner_radius_m, d.outer_radius_m, d.thickness_m) = (x[0], x[1], x[2]);
    if x[0] <= 0.005 || x[0] >= x[1] - 0.02 || x[1] < 0.12 || x[2] <= 0.002 {
        return 1e3;
    }
    let model = build(&scene, BodyKind::Disc, &reg, "fit").unwrap();
    let name = std::env::var("SQUEAL_FIT_EIGEN").unwrap_or_else(|_| "arpack".into());
    let solver = reg.eigen.create(&name, &Params::new()).unwrap();
    let params = EigenParams { fmax_hz: 11_500.0, tol: 1e-10, ..Default::default() };
    let (_, modes) = normal_modes(&model, solver.as_ref(), &params).unwrap();
    let rows = compare_table2(&modes);
    let c: f64 = rows
        .iter()
        .map(|r| r.squeal_hz.map_or(1.5f64.ln().powi(2), |f| (f / r.paper_hz).ln().powi(2)))
        .sum();
    if verbose {
        print!("{}", squeal::analysis::modal::format_table(&rows));
    }
    println!("r_in {:.4} R {:.4} h {:.4} -> cost {c:.5} ({} DOFs)", x[0], x[1], x[2], model.dofs.n_free());
    c
}

fn main() {
    let args: Vec<f64> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let x0 = if args.len() == 3 { [args[0], args[1], args[2]] } else { [0.05, 0.15, 0.02] };
    // Nelder-Mead
    let mut simplex: Vec<([f64; 3], f64)> = (0..4)
        .map(|i| {
            let mut x = x0;
            if i > 0 {
                x[i - 1] *= 1.1;
            }
            (x, cost(&x, false))
        })
        .collect();
    for _ in 0..60 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let c: [f64; 3] = std::array::from_fn(|k| simplex[..3].iter().map(|s| s.0[k]).sum::<f64>() / 3.0);
        let w = simplex[3];
        let at = |t: f64| -> [f64; 3] { std::array::from_fn(|k| c[k] + t * (w.0[k] - c[k])) };
        let r = at(-1.0);
        let fr = cost(&r, false);
        if fr < simplex[0].1 {
            let e = at(-2.0);
            let fe = cost(&e, false);
            simplex[3] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < simplex[2].1 {
            simplex[3] = (r, fr);
        } else {
            let k = at(0.5);
            let fk = cost(&k, false);
            if fk < w.1 {
                simplex[3] = (k, fk);
            } else {
                let best = simplex[0].0;
                for s in simplex.iter_mut().skip(1) {
                    s.0 = std::array::from_fn(|k| best[k] + 0.5 * (s.0[k] - best[k]));
                    s.1 = cost(&s.0, false);
                }
            }
        }
        let spread = simplex.iter().map(|s| s.1).fold(0.0f64, f64::max) - simplex.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
        if spread < 1e-6 {
            break;
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    println!("best:");
    cost(&simplex[0].0, true);
}
