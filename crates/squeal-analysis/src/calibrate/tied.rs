//! Modes of the tied system recognised by their make-up, and mode counts below a
//! frequency.

use super::evaluate::*;
use super::spec::Search;
use crate::modal::ModeRecord;
use crate::pipeline::{Prepared, Result};
use squeal_core::faer::Mat;
use squeal_core::linalg::spmv;
use squeal_core::{EigenParams, Params, RealModes, Registry, SymmetricProblem};
use squeal_scene::Model;

/// `M phi` of the free-interface modes (columns).
pub(super) fn times_mass(model: &Model, modes: &RealModes) -> Mat<f64> {
    let n = model.m.nrows();
    let mut out = Mat::<f64>::zeros(n, modes.freq_hz.len());
    let mut y = vec![0.0; n];
    for c in 0..modes.freq_hz.len() {
        let x: Vec<f64> = modes.vectors.col(c).iter().copied().collect();
        spmv(model.m.as_ref(), &x, &mut y);
        for (r, v) in y.iter().enumerate() {
            out[(r, c)] = *v;
        }
    }
    out
}

/// Count residual: the `count`-th mode of `body` should lie below `below`, the next
/// above; each on the wrong side adds its log-distance to the threshold.
pub(super) fn count_residual(
    records: &[ModeRecord],
    body: &str,
    below: f64,
    count: usize,
    top: f64,
) -> Measured {
    let f: Vec<f64> = records
        .iter()
        .filter(|r| r.body == body)
        .map(|r| r.freq_hz)
        .collect();
    let n = f.iter().filter(|&&x| x < below).count();
    let mut r = 0.0;
    if count > 0 {
        let last = f.get(count - 1).copied().unwrap_or(top);
        r += (last / below).ln().max(0.0);
    }
    if let Some(&next) = f.get(count) {
        r += (below / next).ln().max(0.0);
    }
    Measured {
        extra: Vec::new(),
        value: n as f64,
        residual: r,
        note: format!(
            "{n} below {below:.0} Hz: {}",
            f.iter()
                .take(count + 2)
                .map(|x| format!("{x:.0}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Real modes of the tied system (closed pairs bonded, mu = 0) on the whole face
/// (`mu = None`) or on the sliding equilibrium's contact set at `mu`, up to `fmax`; with
/// their shapes on the model's free DOFs.
pub(super) fn tied_modes(
    registry: &Registry,
    prep: &Prepared,
    search: &Search,
    mu: Option<f64>,
    fmax: f64,
) -> Result<(RealModes, Vec<Vec<f64>>)> {
    let active = match mu {
        None => vec![true; prep.set.len()],
        Some(mu) => {
            prep.equilibrium(registry, &search.equilibrium, "lagrange", mu)?
                .eq
                .active
        }
    };
    let op = prep.operator(&active)?;
    let solver = registry
        .eigen
        .create(&search.eigen, &Params::new())
        .map_err(|e| core("eigen solver", e))?;
    let modes = solver
        .solve_symmetric(
            &SymmetricProblem {
                k: op.kc.as_ref(),
                m: op.mc.as_ref(),
            },
            &EigenParams {
                fmax_hz: fmax,
                tol: 1e-10,
                ..EigenParams::default()
            },
        )
        .map_err(|e| core("tied modes", e))?;
    let shapes = (0..modes.freq_hz.len())
        .map(|c| {
            let uc: Vec<f64> = modes.vectors.col(c).iter().copied().collect();
            op.expand(&uc)
        })
        .collect();
    Ok((modes, shapes))
}

/// The free-interface modes whose `body:label` starts with `makeup` (or with one of its
/// `|`-separated alternatives), the lowest `lowest` of them when given.
pub(super) fn makeup_columns(
    records: &[ModeRecord],
    makeup: &str,
    lowest: Option<usize>,
) -> Vec<usize> {
    let mut cols: Vec<usize> = (0..records.len())
        .filter(|&k| {
            let name = format!("{}:{}", records[k].body, records[k].label);
            makeup.split('|').any(|m| name.starts_with(m.trim()))
        })
        .collect();
    cols.sort_by(|&a, &b| records[a].freq_hz.total_cmp(&records[b].freq_hz));
    cols.truncate(lowest.unwrap_or(usize::MAX));
    cols
}

/// The tied mode in `win` with the largest MAC share on the free-interface modes `matching`.
#[allow(clippy::too_many_arguments)]
pub(super) fn pick_by_makeup(
    model: &Model,
    modes: &RealModes,
    shapes: &[Vec<f64>],
    records: &[ModeRecord],
    mphi: &Mat<f64>,
    matching: &[usize],
    target: f64,
    win: [f64; 2],
) -> Measured {
    let n = model.m.nrows();
    let mut mu_buf = vec![0.0; n];
    // (mode, share, MAC per free-interface mode)
    type Pick = (usize, f64, Vec<(f64, usize)>);
    let mut best: Option<Pick> = None;
    for (i, u) in shapes.iter().enumerate() {
        let f = modes.freq_hz[i];
        if f < win[0] || f > win[1] {
            continue;
        }
        spmv(model.m.as_ref(), u, &mut mu_buf);
        let norm: f64 = u.iter().zip(&mu_buf).map(|(a, b)| a * b).sum();
        let macs: Vec<(f64, usize)> = (0..mphi.ncols())
            .map(|k| {
                let c: f64 = (0..n).map(|r| mphi[(r, k)] * u[r]).sum();
                (c * c / norm.max(f64::MIN_POSITIVE), k)
            })
            .collect();
        let share: f64 = macs
            .iter()
            .filter(|(_, k)| matching.contains(k))
            .map(|(m, _)| m)
            .sum();
        if best.as_ref().is_none_or(|b| share > b.1) {
            best = Some((i, share, macs));
        }
    }
    match best {
        None => missing(format!("no tied mode in {:.0}-{:.0} Hz", win[0], win[1])),
        Some((i, share, mut macs)) => {
            let f = modes.freq_hz[i];
            macs.sort_by(|a, b| b.0.total_cmp(&a.0));
            let top: Vec<String> = macs
                .iter()
                .take(3)
                .map(|(m, k)| {
                    format!(
                        "{}:{} {:.0} Hz {:.2}",
                        records[*k].body, records[*k].label, records[*k].freq_hz, m
                    )
                })
                .collect();
            Measured {
                extra: Vec::new(),
                value: f,
                residual: (f / target).ln(),
                note: format!("share {share:.2}; {}", top.join(", ")),
            }
        }
    }
}
