//! A fit of the disc ring and its hat (ring inner and outer radius, ring thickness, hat
//! height, hat wall thickness, hat radius) to the paper's Table 2: Nelder-Mead here, and
//! the evaluator behind `scripts/disc_fit_lp.py`, the sequential linear program that
//! gave the default disc (session 8: 16 of 16 labels within 5 %).
//!
//! Run: `cargo run --release --example disc_fit -- [r_in R h hat_height hat_wall hat_radius]`
//! With `SQUEAL_FIT_FAMILY=flange` the hat's lower end is closed by an annular plate
//! clamped at its bore (a bolted hub flange), two more parameters:
//! `-- [r_in R h hat_height hat_wall hat_radius flange_bore flange_thickness]`.
//! Objective: sum over the 16 labels of (log f_squeal - log f_paper)^2, a missing label
//! costing (log 1.5)^2; the pin face (radii 0.09 to 0.11 m) must stay on the ring.
//! `SQUEAL_FIT_COST=hinge` weighs misfits beyond 4 % (2.5 % for a,0,3 and a,0,4) 100x
//! instead (the acceptance's shape).
//! `SQUEAL_FIT_EVAL=1` only evaluates the given point. The search meshes the disc with the
//! default scene's size rule; `SQUEAL_FIT_EPW`, `SQUEAL_FIT_LAYERS` and `SQUEAL_FIT_GRADING`
//! override its elements per wavelength, minimum layers and grading ratio;
//! `SQUEAL_FIT_CORRECT=1` then scales each label by its default-rule / search-rule ratio
//! at the starting point (a coarse search that aims at the default mesh's frequencies).

use squeal::analysis::modal::{compare_table2, format_table, normal_modes, TableRow};
use squeal::core::{EigenParams, Params};
use squeal::scene::{build, BodyKind, Flange, Hat, MeshRule, Scene};

/// The disc of parameter vector `x` (6 values: ring and hat; 8: plus the flange), `None`
/// when infeasible.
fn disc_scene(x: &[f64]) -> Option<Scene> {
    let (ri, r, h, hh, th, rh) = (x[0], x[1], x[2], x[3], x[4], x[5]);
    if !(0.01..=0.088).contains(&ri)
        || r < 0.12
        || h < 0.004
        || hh < 0.002
        || th < 0.001
        || rh < ri
        || rh + th > 0.088
    {
        return None;
    }
    let flange = match x[6..] {
        [rf, tf] if rf > 0.005 && rf < rh - 0.002 && tf >= 0.001 => Some(Flange {
            inner_radius_m: rf,
            thickness_m: tf,
        }),
        [] => None,
        _ => return None,
    };
    let mut scene = Scene::builtin("pin-on-disc").unwrap();
    let d = scene.disc.as_mut().unwrap();
    (d.inner_radius_m, d.outer_radius_m, d.thickness_m) = (ri, r, h);
    d.hat = Some(Hat {
        radius_m: Some(rh),
        height_m: hh,
        thickness_m: th,
        flange,
    });
    Some(scene)
}

/// The search's mesh rule and, per Table 2 row, a factor that maps its frequencies to
/// the default rule's (1 without `SQUEAL_FIT_CORRECT`).
struct Search {
    rule: MeshRule,
    correction: Vec<f64>,
}

/// Table 2 rows of the disc `x` on the search's mesh, corrected, `None` when infeasible.
fn table(x: &[f64], search: &Search) -> Option<(Vec<TableRow>, usize)> {
    let (mut rows, dofs) = table_on(x, &search.rule)?;
    for (r, c) in rows.iter_mut().zip(&search.correction) {
        r.squeal_hz = r.squeal_hz.map(|f| f * c);
    }
    Some((rows, dofs))
}

/// Table 2 rows of the disc `x` on the mesh rule `rule`, `None` when infeasible.
fn table_on(x: &[f64], rule: &MeshRule) -> Option<(Vec<TableRow>, usize)> {
    let mut scene = disc_scene(x)?;
    scene.mesh = rule.clone();
    let reg = squeal::registry();
    let model = build(&scene, BodyKind::Disc, &reg, "fit").ok()?;
    let solver = reg.eigen.create("arpack", &Params::new()).unwrap();
    let params = EigenParams {
        fmax_hz: 11_500.0,
        tol: 1e-9,
        ..Default::default()
    };
    let (_, modes) = normal_modes(&model, solver.as_ref(), &params).ok()?;
    Some((compare_table2(&modes), model.dofs.n_free()))
}

/// Log error of each Table 2 label (a missing label counts as a 50 % error).
fn log_errors(rows: &[TableRow]) -> Vec<f64> {
    rows.iter()
        .map(|r| r.squeal_hz.map_or(1.5f64.ln(), |f| (f / r.paper_hz).ln()))
        .collect()
}

/// Hinge residuals shaped like the acceptance: 10 x the excess over 4 % (2.5 % for the
/// squeal partners a,0,3 and a,0,4), plus 0.1 x the error as a light pull.
fn hinge_residuals(rows: &[TableRow]) -> Vec<f64> {
    let e = log_errors(rows);
    let mut res = Vec::with_capacity(2 * e.len());
    for (r, &e) in rows.iter().zip(&e) {
        let limit = if r.label == "a,0,3" || r.label == "a,0,4" {
            0.025
        } else {
            0.04
        };
        res.push(10.0 * e.signum() * (e.abs() - limit).max(0.0));
        res.push(0.1 * e);
    }
    res
}

fn report(x: &[f64], rows: &[TableRow], dofs: usize, c: f64, verbose: bool) {
    let within5 = rows
        .iter()
        .filter(|r| {
            r.squeal_hz
                .is_some_and(|f| (f / r.paper_hz - 1.0).abs() <= 0.05)
        })
        .count();
    if verbose {
        print!("{}", format_table(rows));
    }
    println!("x = {x:.4?} -> cost {c:.5}, {within5}/16 within 5 % ({dofs} DOFs)");
}

fn cost(x: &[f64], search: &Search, verbose: bool) -> f64 {
    let Some((rows, dofs)) = table(x, search) else {
        return 1e3;
    };
    // log least squares, or (SQUEAL_FIT_COST=hinge) the acceptance's shape
    let hinge = std::env::var("SQUEAL_FIT_COST").is_ok_and(|c| c == "hinge");
    let c: f64 = if hinge {
        hinge_residuals(&rows).iter().map(|r| r * r).sum()
    } else {
        log_errors(&rows).iter().map(|e| e * e).sum()
    };
    report(x, &rows, dofs, c, verbose);
    c
}

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    // the search's mesh rule: the default scene's, knobs overridable
    let default_rule = Scene::builtin("pin-on-disc").unwrap().mesh;
    let mut rule = default_rule.clone();
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
    if let Some(v) = env("SQUEAL_FIT_EPW") {
        rule.elements_per_wavelength = v;
    }
    if let Some(v) = env("SQUEAL_FIT_LAYERS") {
        rule.min_layers = v as usize;
    }
    if let Some(v) = env("SQUEAL_FIT_GRADING") {
        rule.grading_ratio = v;
    }
    let flange = std::env::var("SQUEAL_FIT_FAMILY").is_ok_and(|f| f == "flange");
    let x0: Vec<f64> = match (flange, args.len()) {
        (false, 6) | (true, 8) => args,
        (false, _) => vec![0.07, 0.15, 0.02, 0.03, 0.004, 0.07],
        (true, _) => vec![
            0.0677, 0.1324, 0.0118, 0.0111, 0.0018, 0.0677, 0.0575, 0.0073,
        ],
    };
    // with SQUEAL_FIT_CORRECT=1 the search runs on its (coarser) rule with each label's
    // frequency scaled by default-rule / search-rule at the starting point
    let correction = if std::env::var("SQUEAL_FIT_CORRECT").is_ok() {
        let fine = table_on(&x0, &default_rule).expect("the starting point must be feasible");
        let coarse = table_on(&x0, &rule).expect("the starting point must be feasible");
        let c: Vec<f64> = fine
            .0
            .iter()
            .zip(&coarse.0)
            .map(|(f, c)| match (f.squeal_hz, c.squeal_hz) {
                (Some(f), Some(c)) => f / c,
                _ => 1.0,
            })
            .collect();
        // a label the two meshes name differently (a ratio far from the others) or miss
        // takes the median ratio
        let mut sorted = c.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        let c: Vec<f64> = c
            .into_iter()
            .map(|r| {
                if (r / median - 1.0).abs() > 0.02 || r == 1.0 {
                    median
                } else {
                    r
                }
            })
            .collect();
        println!("correction default / search rule per label: {c:.4?}");
        c
    } else {
        vec![1.0; 16]
    };
    let search = Search { rule, correction };
    let n = x0.len();
    let f = |x: &[f64]| cost(x, &search, false);
    if std::env::var("SQUEAL_FIT_EVAL").is_ok() {
        cost(&x0, &search, true);
        return;
    }
    let mut simplex: Vec<(Vec<f64>, f64)> = (0..=n)
        .map(|i| {
            let mut x = x0.clone();
            if i > 0 {
                x[i - 1] *= 1.15;
            }
            let c = f(&x);
            (x, c)
        })
        .collect();
    for _ in 0..150 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let c: Vec<f64> = (0..n)
            .map(|k| simplex[..n].iter().map(|s| s.0[k]).sum::<f64>() / n as f64)
            .collect();
        let w = simplex[n].clone();
        let at = |t: f64| -> Vec<f64> { (0..n).map(|k| c[k] + t * (w.0[k] - c[k])).collect() };
        let r = at(-1.0);
        let fr = f(&r);
        if fr < simplex[0].1 {
            let e = at(-2.0);
            let fe = f(&e);
            simplex[n] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (r, fr);
        } else {
            let k = at(0.5);
            let fk = f(&k);
            if fk < w.1 {
                simplex[n] = (k, fk);
            } else {
                let best = simplex[0].0.clone();
                for s in simplex.iter_mut().skip(1) {
                    s.0 = (0..n).map(|k| best[k] + 0.5 * (s.0[k] - best[k])).collect();
                    s.1 = f(&s.0);
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
    cost(&simplex[0].0, &search, true);
}
