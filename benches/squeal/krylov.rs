//! `krylov/arpack_window/<dofs>`: one shift-invert Krylov window of the full-order band
//! solve: ARPACK `znaupd/zneupd` ([`ArpackComplexKernel`]) for the [`NEV`] eigenvalues of
//! `OP = (K~ - s M~)^-1 M~` nearest `s = (2 pi 5 kHz)^2` ([`SquaredShift`], the path the
//! band driver takes when `C = 0`), tolerance 1e-12.
//!
//! The factorization is built once outside the timed loop (it is `factor/lu_squared`): the
//! time is the Arnoldi iteration alone (operator applications = sparse triangular solves,
//! orthogonalization, restarts). The first run of each size prints the converged count,
//! the operator applications and the frequency span found.

use crate::rig::Rigs;
use criterion::{BenchmarkId, Criterion, SamplingMode};
use squeal::core::qep::ComplexKernel;
use squeal::core::spectral::{SpectralTransform, SquaredShift};
use squeal_eigen_arpack::ArpackComplexKernel;
use std::time::{Duration, Instant};

/// Eigenvalues wanted in the window.
pub const NEV: usize = 20;

/// One ARPACK window at every rig size.
pub fn bench(c: &mut Criterion, rigs: &Rigs) {
    let omega = 2.0 * std::f64::consts::PI * 5_000.0;
    let kernel = ArpackComplexKernel;
    let mut group = c.benchmark_group("krylov");
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(3));
    for r in &rigs.rigs {
        // built on first use, so that a filtered-out size costs nothing
        let mut cell: Option<SquaredShift<'_>> = None;
        let mut reported = false;
        group.bench_with_input(BenchmarkId::new("arpack_window", r.dofs()), r, |b, _| {
            let op = &*cell.get_or_insert_with(|| {
                SquaredShift::lu(&r.qep, omega * omega).expect("K~ - s M~ factorizes")
            });
            b.iter(|| {
                let start = Instant::now();
                let before = op.applications();
                let out = kernel.largest(op, NEV, 1e-12, 300).expect("ARPACK window");
                if !reported {
                    reported = true;
                    let f: Vec<f64> = out
                        .theta
                        .iter()
                        .map(|&t| {
                            SquaredShift::lambda_of_s(op.pencil_eigenvalue(t)).im.abs()
                                / std::f64::consts::TAU
                        })
                        .collect();
                    let (lo, hi) = f
                        .iter()
                        .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
                    eprintln!(
                        "krylov/arpack_window dofs={}: {}/{NEV} converged (all: {}), {} \
                         applications, {} restarts, modes {lo:.0}-{hi:.0} Hz, first run {:.3}s",
                        r.dofs(),
                        out.theta.len(),
                        out.all_converged,
                        op.applications() - before,
                        out.iterations,
                        start.elapsed().as_secs_f64()
                    );
                }
                out
            })
        });
    }
    group.finish();
}
