//! Benchmarks of the gridding: every panel of the eight-panel dress (parse excluded: the spec is
//! read once; timed is the initial grid, constraints, improvement, quality and topology), and
//! the whole garment file (parse, grid, seams). The body gridded from range images is benched in
//! `atelier-body` (`benches/range.rs`).

use std::hint::black_box;
use std::path::PathBuf;

use atelier_grid::ImproveParams;
use atelier_grid::pattern::{grid_pattern, load_garment, load_pattern};
use criterion::{Criterion, criterion_group, criterion_main};

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/patterns")
}

fn panels(c: &mut Criterion) {
    let mut group = c.benchmark_group("grid_panel");
    group.sample_size(20);
    for file in [
        "front_bodice",
        "back_bodice_right",
        "back_bodice_left",
        "front_skirt",
        "back_skirt_right",
        "back_skirt_left",
        "sleeve",
    ] {
        let spec = load_pattern(&fixtures().join(format!("dress/{file}.ron"))).expect("fixture");
        let panel = grid_pattern(&spec, ImproveParams::default()).expect("grids");
        assert!(panel.improvement.energy.windows(2).all(|w| w[1] <= w[0]));
        group.bench_function(file, |b| {
            b.iter(|| grid_pattern(black_box(&spec), ImproveParams::default()).expect("grids"));
        });
    }
    group.finish();
    let mut group = c.benchmark_group("grid_garment");
    group.sample_size(10);
    let path = fixtures().join("dress/dress.ron");
    group.bench_function("dress", |b| {
        b.iter(|| load_garment(black_box(&path), ImproveParams::default()).expect("loads"));
    });
    group.finish();
}

criterion_group!(benches, panels);
criterion_main!(benches);
