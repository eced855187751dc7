//! Sparse factorizations of the rig's frictional operator at `mu = 0.7`:
//!
//! * `factor/cholesky_kc/<dofs>`: real sparse Cholesky of `K_c` (symbolic + numeric), the
//!   factorization of the static responses and of the condensation;
//! * `factor/lu_squared/<dofs>`: real sparse LU of `K~ - s M~` at `s = (2 pi 5 kHz)^2`
//!   ([`SquaredShift::lu`]: sum, symbolic + numeric LU, one probe solve), the
//!   factorization of one window of the full-order band solve when `C = 0`;
//! * `factor/lu_complex/<dofs>`: complex sparse LU of `Q(sigma) = sigma^2 M~ + K~` at
//!   `sigma = i 2 pi 5 kHz` on a prebuilt symbolic analysis
//!   ([`QepShiftInvert::with_symbolic`]: numeric LU, one probe solve), at the two smallest
//!   sizes only (it is the slow one); the symbolic analysis time is printed once.
//!
//! Each factorization takes from a fraction of a second to tens of seconds: flat sampling,
//! so each sample is one factorization.

use crate::rig::Rigs;
use criterion::{BenchmarkId, Criterion, SamplingMode};
use squeal::core::c64;
use squeal::core::linalg::Cholesky;
use squeal::core::spectral::{QepShiftInvert, QepSymbolic, SquaredShift};
use std::time::{Duration, Instant};

/// Centre of the band (Hz) where the shifts are placed.
const F_SHIFT_HZ: f64 = 5_000.0;

/// Cholesky of `K_c`, real LU of the squared pencil, complex LU of `Q(sigma)`.
pub fn bench(c: &mut Criterion, rigs: &Rigs) {
    let omega = 2.0 * std::f64::consts::PI * F_SHIFT_HZ;
    let mut group = c.benchmark_group("factor");
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(3));
    for r in &rigs.rigs {
        group.bench_with_input(BenchmarkId::new("cholesky_kc", r.dofs()), r, |b, r| {
            b.iter(|| Cholesky::new(r.op.kc.as_ref(), "K_c").expect("K_c is SPD"))
        });
    }
    for r in &rigs.rigs {
        group.bench_with_input(BenchmarkId::new("lu_squared", r.dofs()), r, |b, r| {
            b.iter(|| SquaredShift::lu(&r.qep, omega * omega).expect("K~ - s M~ factorizes"))
        });
    }
    for r in rigs.smallest(2) {
        let sigma = c64::new(0.0, omega);
        // built on first use, so that a filtered-out size costs nothing
        let mut cell: Option<QepSymbolic> = None;
        group.bench_with_input(BenchmarkId::new("lu_complex", r.dofs()), r, |b, r| {
            let sym = &*cell.get_or_insert_with(|| {
                let t0 = Instant::now();
                let sym = QepSymbolic::new(&r.qep).expect("symbolic LU of Q");
                eprintln!(
                    "factor/lu_complex dofs={}: symbolic analysis {:.3}s (union pattern nnz {})",
                    r.dofs(),
                    t0.elapsed().as_secs_f64(),
                    sym.nnz()
                );
                sym
            });
            b.iter(|| {
                QepShiftInvert::with_symbolic(&r.qep, sigma, sym).expect("Q(sigma) factorizes")
            })
        });
    }
    group.finish();
}
