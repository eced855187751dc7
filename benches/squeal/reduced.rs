//! The two kernels of every reduced method:
//!
//! * `projection/m<M>/<dofs>`: [`squeal::core::reduction::project`] of the whole frictional
//!   operator (`M_c`, `K_c`, `F_M`, `F_K`) on a dense `n x M` basis, `X_r = V^T X V`
//!   (the gather product `X^T V`, then a dense `(X^T V)^T V`; the friction parts touch only
//!   the rows of the contact DOFs), `M` = 100 and 300, at every rig size;
//! * `sparse_times/{squeal,gather,faer}/m<M>/<dofs>`: `M_c V` on the same `n x M` basis by
//!   [`squeal::core::linalg::sparse_times`] (column blocks, parallel, scattered into the
//!   rows), by [`squeal::core::linalg::sparse_transpose_times`] (the same blocks, each
//!   entry gathered from one column: `M_c^T V = M_c V` for the symmetric `M_c`; the
//!   projection's product) and by faer 0.24's `sparse_dense_matmul` (serial, one pass over
//!   `M_c` per column), which the first replaced in the orthonormalization and the
//!   synthesis (both give the same bits);
//! * `dense_qep/<m>`: [`dense_qep`] on a reduced QEP of size `m` = 100, 200, 400 (the
//!   smallest rig's operator at `mu = 0.7` projected on `m` columns): scaled companion form
//!   of size `2m`, one dense LU of `M_r`, faer's real non-symmetric eigendecomposition.
//!
//! The basis is a fixed pseudo-random matrix: these kernels' cost does not depend on the
//! values, only on `n`, `nnz` and `m`.

use crate::rig::{pseudo_random, Rigs, MU};
use criterion::{BenchmarkId, Criterion, SamplingMode};
use squeal::core::faer::sparse::linalg::matmul::sparse_dense_matmul;
use squeal::core::faer::{Accum, Mat, Par};
use squeal::core::linalg::{sparse_times, sparse_transpose_times};
use squeal::core::qep::dense_qep;
use squeal::core::reduction::project;
use std::time::Duration;

/// Basis sizes of the projection benchmark.
const PROJECT_M: [usize; 2] = [100, 300];
/// Sizes of the dense reduced QEP.
const DENSE_M: [usize; 3] = [100, 200, 400];

/// Projection at every rig size and basis size.
pub fn bench_projection(c: &mut Criterion, rigs: &Rigs) {
    let mut group = c.benchmark_group("projection");
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(3));
    for m in PROJECT_M {
        for r in &rigs.rigs {
            let mut basis = None;
            group.bench_with_input(BenchmarkId::new(format!("m{m}"), r.dofs()), r, |b, r| {
                let v = &*basis.get_or_insert_with(|| pseudo_random(r.dofs(), m, 7));
                b.iter(|| project(&r.op, v.as_ref()).expect("projection"))
            });
        }
    }
    group.finish();
}

/// `M_c V` by squeal's blocked scatter and gather products and by faer's, at every rig
/// size and basis size.
pub fn bench_sparse_times(c: &mut Criterion, rigs: &Rigs) {
    let mut group = c.benchmark_group("sparse_times");
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(3));
    for m in PROJECT_M {
        for r in &rigs.rigs {
            let v = pseudo_random(r.dofs(), m, 7);
            let mc = r.op.mc.as_ref();
            group.bench_with_input(
                BenchmarkId::new(format!("squeal/m{m}"), r.dofs()),
                &v,
                |b, v| b.iter(|| sparse_times(mc, v.as_ref())),
            );
            group.bench_with_input(
                BenchmarkId::new(format!("gather/m{m}"), r.dofs()),
                &v,
                |b, v| b.iter(|| sparse_transpose_times(mc, v.as_ref())),
            );
            group.bench_with_input(
                BenchmarkId::new(format!("faer/m{m}"), r.dofs()),
                &v,
                |b, v| {
                    b.iter(|| {
                        let mut y = Mat::<f64>::zeros(r.dofs(), m);
                        sparse_dense_matmul(
                            y.as_mut(),
                            Accum::Replace,
                            mc,
                            v.as_ref(),
                            1.0,
                            Par::rayon(0),
                        );
                        y
                    })
                },
            );
        }
    }
    group.finish();
}

/// Dense reduced QEP at m = 100, 200, 400.
pub fn bench_dense_qep(c: &mut Criterion, rigs: &Rigs) {
    let r = &rigs.rigs[0];
    let mut group = c.benchmark_group("dense_qep");
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(3));
    for m in DENSE_M {
        let mut reduced = None;
        group.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, &m| {
            let qep = &*reduced.get_or_insert_with(|| {
                let v = pseudo_random(r.dofs(), m, 11);
                project(&r.op, v.as_ref())
                    .expect("projection")
                    .at(MU)
                    .expect("reduced QEP")
            });
            b.iter(|| dense_qep(qep).expect("dense QEP"))
        });
    }
    group.finish();
}
