//! Benchmarks of the import (docs/patterns-import.md): the dress written by ezdxf read from
//! DXF (R2000 and R12: parse, pieces checked, notches and darts found), FreeSewing's Penelope
//! and Bella read from their SVG (parse, Béziers flattened, halves unfolded, V darts closed),
//! one piece planned and
//! gridded with the drafter's corners (the gridding of an imported piece), and the
//! corner search on the front bodice (every four of its six sharpest vertices planned and
//! gridded) against gridding it once.

use std::hint::black_box;
use std::path::PathBuf;

use atelier_grid::ImproveParams;
use atelier_import::{PanelOptions, dxf, plan_and_grid, svg};
use criterion::{Criterion, criterion_group, criterion_main};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/patterns/dxf")
}

fn import(c: &mut Criterion) {
    let mut group = c.benchmark_group("import_read");
    group.sample_size(20);
    for file in ["dress_aama_r2000.dxf", "dress_aama_r12.dxf"] {
        let path = dir().join(file);
        assert_eq!(dxf::read(&path).expect("reads").pieces.len(), 7);
        group.bench_function(file, |b| {
            b.iter(|| dxf::read(black_box(&path)).expect("reads"))
        });
    }
    for (file, pieces) in [("penelope.svg", 3), ("bella.svg", 3)] {
        let path = dir().join("../freesewing").join(file);
        assert_eq!(svg::read(&path).expect("reads").pieces.len(), pieces);
        group.bench_function(file, |b| {
            b.iter(|| svg::read(black_box(&path)).expect("reads"))
        });
    }
    group.finish();

    let pieces = dxf::read(&dir().join("dress_aama_r2000.dxf"))
        .expect("reads")
        .pieces;
    let front_bodice = pieces
        .iter()
        .find(|p| p.name == "front bodice")
        .expect("piece");
    let drafted = PanelOptions {
        corners: Some([[-20.25, 0.0], [20.25, 0.0], [19.2, 37.5], [-19.2, 37.5]]),
        ..PanelOptions::default()
    };
    let mut group = c.benchmark_group("import_piece");
    group.sample_size(10);
    group.bench_function("front_bodice_plan_and_grid", |b| {
        b.iter(|| {
            plan_and_grid(
                black_box(front_bodice),
                &drafted,
                "bench",
                ImproveParams::default(),
            )
            .expect("grids")
        });
    });
    group.bench_function("front_bodice_corner_search", |b| {
        b.iter(|| {
            plan_and_grid(
                black_box(front_bodice),
                &PanelOptions::default(),
                "bench",
                ImproveParams::default(),
            )
            .expect("grids")
        });
    });
    group.finish();
}

criterion_group!(benches, import);
criterion_main!(benches);
