//! Benchmarks of the scan pipeline (bench ids `scan/…`): landmarks and segmentation of the
//! MakeHuman base mesh (13 380 vertices) and of the same mesh split 1-to-4 (53 514 vertices);
//! the goal is ≤ 1 s for a 20 000-vertex scan.

use std::hint::black_box;
use std::path::Path;

use atelier_body::io::load_mesh;
use atelier_body::scan::{ScanOptions, find_landmarks, segment, subdivided};
use criterion::{Criterion, criterion_group, criterion_main};

fn scan(c: &mut Criterion) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/tryon/makehuman/mh_rest.obj");
    let mesh = load_mesh(&path).expect("mh_rest.obj");
    let fine = subdivided(&mesh.vertices, &mesh.triangles);
    let opts = ScanOptions::default();
    let mut group = c.benchmark_group("scan");
    group.sample_size(10);
    for (name, v, t) in [
        ("landmarks_segment_13k", &mesh.vertices, &mesh.triangles),
        ("landmarks_segment_53k", &fine.0, &fine.1),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                let l = find_landmarks(black_box(v), t, &opts).expect("landmarks");
                segment(v, t, &l).expect("segments")
            });
        });
    }
    group.finish();
}

criterion_group!(benches, scan);
criterion_main!(benches);
