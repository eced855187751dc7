//! Criterion benchmarks of the squeal pipeline on the default scene's disc.
//!
//! One entry point, three groups (modules under `benches/squeal/`):
//!
//! * `assembly/disc/<dofs>`: [`squeal_fe::assemble`] of K and M on a prebuilt mesh and
//!   DOF map, at several mesh densities (`mesh.elements_per_wavelength`);
//! * `modal/disc/<solver>/<dofs>`: the symmetric modal solve up to 10.5 kHz through the
//!   registry's `arpack` and `krylov` plugins;
//! * `build/disc`: [`squeal_scene::build`] end to end (mesh, numbering, assembly).
//!
//! Run `cargo bench --bench squeal` (a few minutes on two cores), or
//! `cargo bench --bench squeal -- --test` to run every benchmark once as a smoke check.
//! The models are built once at start-up and a one-line summary of each is printed.

#[path = "squeal/assembly.rs"]
mod assembly;
#[path = "squeal/build.rs"]
mod build;
#[path = "squeal/modal.rs"]
mod modal;
#[path = "squeal/models.rs"]
mod models;

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
    let mut c = config();
    assembly::bench(&mut c, models);
    build::bench(&mut c, models);
    modal::bench(&mut c, models);
    c.final_summary();
}
