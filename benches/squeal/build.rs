//! `build/disc`: `squeal_scene::build` end to end (mesh, numbering, assembly).

use crate::models::{Models, FILE};
use criterion::{Criterion, SamplingMode};
use squeal::scene::{build, BodyKind};
use std::time::Duration;

/// Build of the default disc.
pub fn bench(c: &mut Criterion, models: &Models) {
    let d = models.default_disc();
    let mut group = c.benchmark_group("build");
    group.sampling_mode(SamplingMode::Flat);
    group.measurement_time(Duration::from_secs(3));
    group.bench_function("disc", |b| {
        b.iter(|| build(&d.scene, BodyKind::Disc, &models.registry, FILE).expect("disc builds"))
    });
    group.finish();
}
