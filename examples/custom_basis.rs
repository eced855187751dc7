//! A researcher's reduction basis written outside the library: the coupled mu = 0 real
//! modes plus `count` smoothed random vectors (`K_c^-1 M_c r`, one static solve each),
//! implemented against the public `ReductionBasis` trait with the shared machinery of
//! `squeal::core::reduction`, registered into `squeal::registry()` at run time, and
//! compared by the library's benchmark (`squeal::analysis::bench`) with the built-in
//! bases on a coarse build of the default scene (reference: full-order `arpack`).
//!
//! ```text
//! cargo run --release --example custom_basis
//! ```

use squeal::analysis::bench::{bench_case, BenchOptions};
use squeal::analysis::pipeline::Prepared;
use squeal::core::faer::Mat;
use squeal::core::reduction::{
    coupled_real_modes, m_orthonormal_extend, m_orthonormalize, sparse_times, StaticSolver,
    DEFAULT_RANK_TOL,
};
use squeal::core::{Basis, BasisRequest, Params, ReductionBasis, Result};
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
        Ok(basis)
    }
}

/// Registers `modes+random` (options `cutoff_factor`, default 1.5, and `count`, default
/// 40) into `reg`: from then on every tool that lists the registry's bases, `squeal
/// bench` included, runs it.
pub fn register(reg: &mut squeal::core::Registry) {
    reg.bases.register(
        "modes+random",
        "modes plus smoothed random vectors",
        |p: &Params| {
            let basis: Box<dyn ReductionBasis> = Box::new(ModesPlusRandom {
                cutoff_factor: p.num_or("cutoff_factor", 1.5)?,
                count: p.usize_or("count", 40)?,
            });
            Ok(basis)
        },
    );
}

fn main() -> std::result::Result<(), Box<dyn std::error::Error>> {
    let start = Instant::now();
    let mut reg = squeal::registry();
    register(&mut reg);

    let mut scene = Scene::builtin("pin-on-disc")?;
    scene.mesh.max_freq_hz = 4000.0;
    scene.mesh.pin_face_elements = 6;
    let mu = 0.7;
    let prep = Prepared::new(&reg, scene, "coarse pin-on-disc")?;
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu)?;
    let op = prep.operator(&eq.eq.active)?;
    // the benchmark of the library, unchanged: it finds `modes+random` in the registry
    let mut opts = BenchOptions::all(&reg);
    opts.band_hz = [0.0, 3000.0];
    opts.bases.retain(|b| b != "none");
    opts.eigens = vec!["dense".into()];
    let (reference, runs) = bench_case(&reg, "example", &op, &Vec::new(), mu, &opts, None, |_| {})?;
    println!(
        "coarse pin-on-disc, mu = {mu}: n_c = {}, reference `{}`: {} modes in 0-{} Hz, {} \
         unstable ({:.2} s)",
        op.dim(),
        reference.eigen,
        reference.modes,
        opts.band_hz[1],
        reference.unstable.len(),
        reference.time_s
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
        "missed u."
    );
    for r in runs.iter().filter(|r| !r.reference) {
        let e = &r.errors;
        println!(
            "{:<14} {:>5} {:>8.3} {:>8.3} {:>10.2e} {:>10.2e} {:>10.2e} {:>7} {:>9}",
            r.basis,
            r.basis_size,
            r.setup_s,
            r.solve_s,
            e.max_rel_freq_err,
            e.max_abs_dvr_err,
            e.max_backward_error,
            e.missed_modes,
            e.missed_unstable
        );
    }
    println!("total {:.1} s", start.elapsed().as_secs_f64());
    Ok(())
}
