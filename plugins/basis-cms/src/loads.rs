//! The `cms` basis of an operator read from files: a free-interface synthesis on its
//! friction load directions.
//!
//! An operator directory is already the constrained operator of one contact set: it has
//! no free model and no pairs to tie. What it has is where friction acts, the friction
//! load directions `U` (`n x nA`, given as `U` in its `operator.toml`, or their span
//! recovered from `F_K = U V_K^T`). The synthesis then takes them as its interface:
//!
//! - free-interface modes `Phi` of the operator's real-mode pair `(K_s, M_s)`
//!   ([`real_mode_pair`]) up to `modes_factor x` the band top (`K_s Phi = M_s Phi
//!   Omega^2`, `Phi^T M_s Phi = I`);
//! - the residual attachment modes `G U = (K_s^-1 - Phi Omega^-2 Phi^T) U`, the static
//!   flexibility of the friction loads that the kept modes leave out;
//! - the frictional operator at mu projected on `[Phi, G U]` and solved (the request's
//!   reduced solver): the synthesized modes up to `cutoff_factor x` the band top;
//! - the synthesized modes expanded, real and imaginary parts, and with `second_order`
//!   the static correction of each, `K_s^-1 Q(lambda) u` (the residual the synthesis
//!   leaves, as a static response), `M_c`-orthonormalized: the Ritz vectors of the exact
//!   operator.
//!
//! Rebuilt at every mu like the scene's `cms`. An operator with neither `U` nor friction
//! parts has no interface, and is refused with what to add.

use squeal_core::faer::Mat;
use squeal_core::linalg::expand;
use squeal_core::reduction::{
    coupled_real_modes_on, energy_residuals, friction_load_directions, m_orthonormalize, project,
    real_mode_pair, StaticSolver,
};
use squeal_core::{Basis, BasisRequest, EigenParams, Error, Result};
use std::time::Instant;

use super::{CmsBasis, NAME};

/// Real and imaginary parts of the complex columns `u`, side by side; an imaginary part
/// below `1e-8` of its column's largest modulus (a real mode) is left out.
fn parts(u: &Mat<squeal_core::c64>, out: &mut Vec<Vec<f64>>) {
    for c in 0..u.ncols() {
        let col = u.col(c);
        let scale = col.iter().fold(0.0f64, |m, z| m.max(z.norm()));
        out.push(col.iter().map(|z| z.re).collect());
        if col.iter().fold(0.0f64, |m, z| m.max(z.im.abs())) > 1e-8 * scale {
            out.push(col.iter().map(|z| z.im).collect());
        }
    }
}

/// The basis of an operator read from files (module docs).
pub(crate) fn build_on_loads(cms: &CmsBasis, request: &BasisRequest<'_>) -> Result<Basis> {
    let op = request.op;
    if op.friction_loads.is_none() && !op.has_friction() {
        return Err(Error::Invalid(
            "`cms` synthesizes an operator read from files on its friction load directions, \
             and this one has none: give `U = \"U\"` in its operator.toml (an n x nA matrix, \
             one column per friction load) or its friction parts (FK, FM, FC)"
                .into(),
        ));
    }
    let top = request.band_hz.1;
    let (mu, n) = (request.mu, op.dim());
    // free-interface modes of the real-mode pair and its static solver
    let clock = Instant::now();
    let ks = StaticSolver::new(op, 0.0)?;
    let modes = coupled_real_modes_on(request, cms.modes_factor * top, &ks)?;
    let pair = real_mode_pair(op)?;
    let t_modes = clock.elapsed().as_secs_f64();
    // residual attachment modes G U = K_s^-1 U - Phi Omega_s^-2 Phi^T U
    let clock = Instant::now();
    let u = friction_load_directions(op)?;
    let phi = &modes.vectors;
    let mut ptu = phi.transpose() * &u;
    for (k, &o2) in modes.omega2.iter().enumerate() {
        let s = 1.0 / (o2 + pair.shift);
        for c in 0..ptu.ncols() {
            ptu[(k, c)] *= s;
        }
    }
    let mut g = u;
    ks.solve_in_place(g.as_mut());
    g -= phi * &ptu;
    let loads = g.ncols();
    let space = squeal_core::linalg::hcat(phi.as_ref(), g.as_ref());
    drop(g);
    let (w, dropped_space) = m_orthonormalize(op.mc.as_ref(), space.as_ref(), cms.rank_tol)?;
    drop(space);
    let t_attach = clock.elapsed().as_secs_f64();
    // the synthesis: the frictional operator on the free-interface space
    let clock = Instant::now();
    let cutoff = cms.cutoff_factor * top;
    let reduced = project(op, w.as_ref())?;
    let syn = request.reduced.solve_frictional(
        &reduced,
        mu,
        &EigenParams {
            fmin_hz: 0.0,
            fmax_hz: cutoff,
            nev_hint: None,
            ..request.params.clone()
        },
    )?;
    if syn.is_empty() {
        return Err(Error::Invalid(format!(
            "cms: no synthesized mode below {cutoff:.1} Hz"
        )));
    }
    let t_synthesis = clock.elapsed().as_secs_f64();
    // the synthesized modes expanded, and their static corrections
    let clock = Instant::now();
    let expanded = expand(w.as_ref(), syn.vectors.as_ref());
    let mut cols = Vec::new();
    parts(&expanded, &mut cols);
    if cms.second_order {
        let qep = op.at(mu)?;
        let (_, d) = energy_residuals(&qep, &ks, &syn.lambda, expanded.as_ref());
        parts(&d, &mut cols);
    }
    drop(ks);
    let raw = Mat::from_fn(n, cols.len(), |r, c| cols[c][r]);
    drop(cols);
    let (v, dropped) = m_orthonormalize(op.mc.as_ref(), raw.as_ref(), cms.rank_tol)?;
    let t_expansion = clock.elapsed().as_secs_f64();
    let mut basis = Basis::new(v);
    basis.dropped = dropped;
    basis.steps = vec![
        ("free-interface modes".into(), t_modes),
        ("attachment modes".into(), t_attach),
        ("synthesis".into(), t_synthesis),
        ("expansion".into(), t_expansion),
    ];
    basis.notes.push(format!(
        "{NAME}: {} synthesized modes up to {cutoff:.1} Hz from {} free-interface modes of \
         the real-mode pair ({}) to {:.1} Hz and {loads} attachment modes of the friction \
         loads{} ({dropped_space} removed by the rank cut), {} vectors{} ({dropped} removed by \
         the rank cut)",
        syn.len(),
        modes.omega2.len(),
        pair.source,
        cms.modes_factor * top,
        if op.friction_loads.is_some() {
            " (U of the operator)"
        } else {
            " (their span recovered from F_K)"
        },
        basis.len(),
        if cms.second_order {
            " with their static corrections"
        } else {
            ""
        },
    ));
    if cms.on_pairs {
        basis.notes.push(format!(
            "{NAME}: projection=pairs needs the pairs of a scene's model; this operator was \
             projected the full way"
        ));
    }
    Ok(basis)
}
