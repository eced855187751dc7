//! Criterion benchmarks of the squeal pipeline: the disc alone and the full pin-on-disc
//! rig (frictional operator at mu = 0.7), at several mesh densities so that scaling with
//! the DOF count is visible. Benchmark ids end with the DOF count.
//!
//! One entry point, groups in modules under `benches/squeal/` (see `benches/README.md`):
//!
//! * `assembly/disc/<dofs>`, `assembly/rig/<dofs>`: [`squeal_fe::assemble`] of K and M on a
//!   prebuilt mesh and DOF map (disc at `mesh.elements_per_wavelength` 8, 10, 18; rig at
//!   (`elements_per_wavelength`, `pin_face_elements`) = (4, 8), (6, 12), (10, 20));
//! * `build/disc`: [`squeal_scene::build`] end to end (mesh, numbering, assembly);
//! * `modal/disc/<solver>/<dofs>`: the symmetric modal solve up to 10.5 kHz through the
//!   registry's `arpack` and `krylov` plugins;
//! * `factor/{cholesky_kc,lu_squared,lu_complex}/<dofs>`: sparse Cholesky of `K_c`, real LU
//!   of `K~ - s M~`, complex LU of `Q(sigma)` (two smallest rigs);
//! * `krylov/arpack_window/<dofs>`: one ARPACK shift-invert window (nev 20);
//! * `projection/m<M>/<dofs>`: `V^T X V` of the whole operator on `M` = 100, 300 columns;
//! * `sparse_times/{squeal,faer}/m<M>/<dofs>`: `M_c V`, squeal's blocked product against
//!   faer's;
//! * `dense_qep/<m>`: the dense reduced QEP at m = 100, 200, 400.
//!
//! Run `cargo bench --bench squeal -- --quick` (about 5 minutes on two cores), one group with
//! a filter (`cargo bench --bench squeal -- --quick factor/`), or
//! `cargo bench --bench squeal -- --test` to run every benchmark once as a smoke check.
//! The models are built once at start-up and a one-line summary of each is printed.

#[path = "squeal/assembly.rs"]
mod assembly;
#[path = "squeal/build.rs"]
mod build;
#[path = "squeal/factor.rs"]
mod factor;
#[path = "squeal/krylov.rs"]
mod krylov;
#[path = "squeal/modal.rs"]
mod modal;
#[path = "squeal/models.rs"]
mod models;
#[path = "squeal/reduced.rs"]
mod reduced;
#[path = "squeal/rig.rs"]
mod rig;

use criterion::Criterion;
use std::time::Duration;

/// Settings for a 2-core machine: few samples, short windows.
fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .configure_from_args()
}

fn main() {
    let models = models::Models::get();
    models.print_table();
    let rigs = rig::Rigs::get(&models.registry);
    rigs.print_table();
    let mut c = config();
    assembly::bench(&mut c, models, rigs);
    build::bench(&mut c, models);
    modal::bench(&mut c, models);
    factor::bench(&mut c, rigs);
    krylov::bench(&mut c, rigs);
    reduced::bench_projection(&mut c, rigs);
    reduced::bench_sparse_times(&mut c, rigs);
    reduced::bench_dense_qep(&mut c, rigs);
    c.final_summary();
}
