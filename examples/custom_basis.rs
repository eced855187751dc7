//! A researcher's reduction basis written outside the library: the coupled mu = 0 real
//! modes plus `count` smoothed random vectors (`K_c^-1 M_c r`, one static solve each),
//! implemented against the public `ReductionBasis` trait with the shared machinery of
//! `squeal::core::reduction`, registered into `squeal::registry()` at run time, and
//! compared with the built-in `enriched` basis on a coarse build of the default scene
//! (reference: full-order `arpack`).
//!
//! ```text
//! cargo run --release --example custom_basis
//! ```

use squeal::analysis::pipeline::Prepared;
use squeal::core::faer::Mat;
use squeal::core::qep::ComplexModes;
use squeal::core::reduction::{
    coupled_real_modes, m_orthonormal_extend, m_orthonormalize, sparse_times, StaticSolver,
    DEFAULT_RANK_TOL,
};
use squeal::core::{
    Basis, BasisRequest, EigenParams, Params, ReducedOperator, ReductionBasis, Result,
};
use squeal::scene::Scene;
use std::time::Instant;

/// Real modes up to `cutoff_factor x` band top plus `count` smoothed random vectors.
struct ModesPlusRandom {
    cutoff_factor: f64,
    count: usize,
}

impl ReductionBasis for ModesPlusRandom {
    fn name(&self) -> &str {
        "modes+random"
    }

    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis> {
        let start = Instant::now();
        let op = request.op;
        let modes = coupled_real_modes(request, self.cutoff_factor * request.band_hz.1)?;
        let (v, d0) = m_orthonormalize(op.mc.as_ref(), modes.vectors.as_ref(), DEFAULT_RANK_TOL)?;
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let r = Mat::from_fn(op.dim(), self.count, |_, _| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        });
        let mut smooth = sparse_times(op.mc.as_ref(), r.as_ref());
        StaticSolver::new(op, 0.0)?.solve_in_place(smooth.as_mut());
        let (v, d1) = m_orthonormal_extend(
            op.mc.as_ref(),
            v.as_ref(),
            smooth.as_ref(),
            DEFAULT_RANK_TOL,
        )?;
        let mut basis = Basis::new(v);
        basis.dropped = d0 + d1;
        basis.notes.push(format!(
            "modes+random: {} modes + {} smoothed random vectors",
            modes.freq_hz.len(),
            self.count
        ));
        basis.time_s = start.elapsed().as_secs_f64();
        Ok(basis)
    }
}

/// Largest relative frequency error, largest DvR error and missed modes (no partner
/// within 1 %) of `got` against `reference`.
fn errors(reference: &ComplexModes, got: &ComplexModes) -> (f64, f64, usize) {
    let (mut df, mut dd, mut missed) = (0.0f64, 0.0f64, 0);
    let mut used = vec![false; got.len()];
    for i in 0..reference.len() {
        let best = (0..got.len()).filter(|&j| !used[j]).min_by(|&a, &b| {
            let da = (reference.lambda[i] - got.lambda[a]).norm();
            let db = (reference.lambda[i] - got.lambda[b]).norm();
            da.total_cmp(&db)
        });
        match best {
            Some(j) if (got.freq_hz[j] / reference.freq_hz[i] - 1.0).abs() <= 0.01 => {
                used[j] = true;
                df = df.max((got.freq_hz[j] / reference.freq_hz[i] - 1.0).abs());
                dd = dd.max((got.dvr[j] - reference.dvr[i]).abs());
            }
            _ => missed += 1,
        }
    }
    (df, dd, missed)
}

fn main() -> std::result::Result<(), Box<dyn std::error::Error>> {
    let start = Instant::now();
    let mut reg = squeal::registry();
    reg.bases.register(
        "modes+random",
        "modes plus smoothed random vectors",
        |p: &Params| {
            p.reject_unknown("modes+random", &["cutoff_factor", "count"])?;
            let basis: Box<dyn ReductionBasis> = Box::new(ModesPlusRandom {
                cutoff_factor: p.num_or("cutoff_factor", 1.5)?,
                count: p.usize_or("count", 40)?,
            });
            Ok(basis)
        },
    );

    let mut scene = Scene::builtin("pin-on-disc")?;
    scene.mesh.max_freq_hz = 4000.0;
    scene.mesh.pin_face_elements = 6;
    let fmax = 3000.0;
    let mu = 0.7;
    let prep = Prepared::new(&reg, scene, "coarse pin-on-disc")?;
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu)?;
    let op = prep.operator(&eq.eq.active)?;
    let params = EigenParams {
        fmin_hz: 0.0,
        fmax_hz: fmax,
        tol: 1e-12,
        ..EigenParams::default()
    };
    let arpack = reg.eigen.create("arpack", &Params::new())?;
    let dense = reg.eigen.create("dense", &Params::new())?;
    let t = Instant::now();
    let reference = arpack.solve_frictional(&op, mu, &params)?;
    println!(
        "coarse pin-on-disc, mu = {mu}: n_c = {}, reference `arpack`: {} modes in 0-{fmax} Hz \
         ({:.2} s)",
        op.dim(),
        reference.len(),
        t.elapsed().as_secs_f64()
    );
    println!(
        "{:<14} {:>5} {:>8} {:>8} {:>10} {:>10} {:>10} {:>7} {:>9}",
        "basis",
        "size",
        "build s",
        "solve s",
        "max df/f",
        "max dDvR",
        "max eta",
        "missed",
        "unstable"
    );
    for name in ["modes+random", "enriched", "modes"] {
        let basis = reg.bases.create(name, &Params::new())?;
        let b = basis.build(&BasisRequest {
            op: &op,
            mu,
            band_hz: (0.0, fmax),
            modal: arpack.as_ref(),
            reduced: dense.as_ref(),
            params: &params,
        })?;
        let red = ReducedOperator::new(&op, b)?;
        let wide = EigenParams {
            fmax_hz: 1.01 * fmax,
            ..params.clone()
        };
        let s = red.solve(&op, mu, dense.as_ref(), &wide)?;
        let (df, dd, missed) = errors(&reference, &s.modes);
        let eta = s.modes.backward_error.iter().fold(0.0f64, |a, &b| a.max(b));
        let unstable = (0..s.modes.len())
            .filter(|&i| s.modes.is_unstable(i, 1e-8) && s.modes.freq_hz[i] <= fmax)
            .count();
        println!(
            "{name:<14} {:>5} {:>8.3} {:>8.3} {df:>10.2e} {dd:>10.2e} {eta:>10.2e} {missed:>7} {unstable:>9}",
            s.basis_size,
            s.basis_time_s,
            s.projection_time_s + s.solve_time_s + s.expansion_time_s,
        );
    }
    let ref_unstable = (0..reference.len())
        .filter(|&i| reference.is_unstable(i, 1e-8))
        .count();
    println!(
        "reference: {ref_unstable} unstable; total {:.1} s",
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
