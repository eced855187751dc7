//! `modal/disc/<solver>/<dofs>`: symmetric modal solve up to 10.5 kHz via the registry.
//!
//! A solve takes seconds, so each of the 10 samples is a single solve (flat sampling,
//! a short target time): criterion's "Unable to complete 10 samples" notice is expected.
//! The first solve of each case prints its mode count and largest residual.

use crate::models::{DiscModel, Models};
use criterion::{BenchmarkId, Criterion, SamplingMode};
use squeal::core::{EigenParams, Params, SymmetricProblem};
use std::time::{Duration, Instant};

/// The band and tolerance of the benchmarked solves.
fn params() -> EigenParams {
    EigenParams {
        fmax_hz: 10_500.0,
        tol: 1e-12,
        ..Default::default()
    }
}

/// `arpack` and `krylov` on the default disc, `arpack` also on the finest one.
pub fn bench(c: &mut Criterion, models: &Models) {
    let mut cases: Vec<(&str, &DiscModel)> = vec![
        ("arpack", models.default_disc()),
        ("krylov", models.default_disc()),
    ];
    if models.discs.len() - 1 != models.default {
        cases.push(("arpack", models.finest_disc()));
    }
    let params = params();
    let mut group = c.benchmark_group("modal/disc");
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(1));
    for (name, d) in cases {
        let solver = models
            .registry
            .eigen
            .create(name, &Params::new())
            .unwrap_or_else(|e| panic!("eigen plugin {name}: {e}"));
        let problem = SymmetricProblem {
            k: d.model.k.as_ref(),
            m: d.model.m.as_ref(),
        };
        let mut reported = false;
        group.bench_with_input(BenchmarkId::new(name, d.dofs()), &problem, |b, problem| {
            b.iter(|| {
                let start = Instant::now();
                let modes = solver
                    .solve_symmetric(problem, &params)
                    .expect("modal solve");
                if !reported {
                    reported = true;
                    let max_res = modes.residuals.iter().copied().fold(0.0, f64::max);
                    eprintln!(
                        "modal {name} dofs={} modes<=10.5kHz={} max residual={max_res:.2e} \
                         (converged {}/{} requested, {} op applications, {:?}) first solve {:.3}s",
                        d.dofs(),
                        modes.freq_hz.len(),
                        modes.info.converged,
                        modes.info.requested,
                        modes.info.op_applications,
                        modes.info.reason,
                        start.elapsed().as_secs_f64(),
                    );
                }
                modes
            })
        });
    }
    group.finish();
}
