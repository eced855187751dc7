//! `assembly/disc/<dofs>`: K and M assembly on a prebuilt mesh and DOF map.

use crate::models::Models;
use criterion::{BenchmarkId, Criterion, SamplingMode};
use squeal::fe::assemble;
use std::time::Duration;

/// Assembly at every mesh density.
pub fn bench(c: &mut Criterion, models: &Models) {
    let mut group = c.benchmark_group("assembly/disc");
    group.sampling_mode(SamplingMode::Flat);
    group.measurement_time(Duration::from_secs(3));
    for d in &models.discs {
        let materials = d.material_refs();
        group.bench_with_input(BenchmarkId::from_parameter(d.dofs()), d, |b, d| {
            b.iter(|| assemble(&d.model.mesh, &d.model.dofs, &materials).expect("assembly"))
        });
    }
    group.finish();
}
