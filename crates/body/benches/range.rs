//! Benchmarks of the range images: the synthetic mannequin's body gridded from its range images,
//! and the error measurement (bench ids `grid_body/…`, as when they lived in `atelier-grid`).

use std::hint::black_box;

use atelier_body::range::synthetic::Mannequin;
use atelier_body::range::{BodyGridParams, grid_body, measure_error};
use criterion::{Criterion, criterion_group, criterion_main};

fn body(c: &mut Criterion) {
    let mut group = c.benchmark_group("grid_body");
    group.sample_size(10);
    let body = Mannequin::jis_9ar().body(2.5);
    let (mesh, _) = grid_body(&body, &BodyGridParams::default()).expect("grids");
    assert!(measure_error(&mesh, &body).total.mean_abs_mm <= 1.5);
    group.bench_function("mannequin_2.5mm", |b| {
        b.iter(|| grid_body(black_box(&body), &BodyGridParams::default()).expect("grids"));
    });
    group.bench_function("measure_error", |b| {
        b.iter(|| measure_error(black_box(&mesh), &body));
    });
    group.finish();
}

criterion_group!(benches, body);
criterion_main!(benches);
