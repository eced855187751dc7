//! `assembly/disc/<dofs>` and `assembly/rig/<dofs>`: K and M assembly on a prebuilt mesh
//! and DOF map, for the disc alone and for the full rig (disc, pin, plates; the id is the
//! rig's free DOF count before the contact constraints).

use crate::models::Models;
use crate::rig::Rigs;
use criterion::{BenchmarkId, Criterion, SamplingMode};
use squeal::fe::assemble;
use std::time::Duration;

/// Assembly at every mesh density, disc and full rig.
pub fn bench(c: &mut Criterion, models: &Models, rigs: &Rigs) {
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
    let mut group = c.benchmark_group("assembly/rig");
    group.sampling_mode(SamplingMode::Flat);
    group.measurement_time(Duration::from_secs(3));
    for r in &rigs.rigs {
        let materials = r.material_refs();
        let model = &r.prep.model;
        group.bench_with_input(BenchmarkId::from_parameter(r.full_dofs()), r, |b, _| {
            b.iter(|| assemble(&model.mesh, &model.dofs, &materials).expect("assembly"))
        });
    }
    group.finish();
}
