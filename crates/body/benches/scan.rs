//! Benchmarks of the scan pipeline (bench ids `scan/…`): landmarks and segmentation of the
//! MakeHuman base mesh (13 380 vertices) and of the same mesh split 1-to-4 (53 514 vertices);
//! the goal is ≤ 1 s for a 20 000-vertex scan.

use std::collections::HashMap;
use std::hint::black_box;
use std::path::Path;

use atelier_body::V3;
use atelier_body::io::load_mesh;
use atelier_body::scan::{ScanOptions, find_landmarks, segment};
use criterion::{Criterion, criterion_group, criterion_main};

/// Every triangle split into four at its edges' midpoints.
fn subdivide(v: &[V3], t: &[[u32; 3]]) -> (Vec<V3>, Vec<[u32; 3]>) {
    let mut v = v.to_vec();
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut out = Vec::with_capacity(4 * t.len());
    for tri in t {
        let m = [0, 1, 2].map(|e| {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push((v[a as usize] + v[b as usize]) / 2.0);
                (v.len() - 1) as u32
            })
        });
        out.push([tri[0], m[0], m[2]]);
        out.push([tri[1], m[1], m[0]]);
        out.push([tri[2], m[2], m[1]]);
        out.push(m);
    }
    (v, out)
}

fn scan(c: &mut Criterion) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/tryon/makehuman/mh_rest.obj");
    let mesh = load_mesh(&path).expect("mh_rest.obj");
    let fine = subdivide(&mesh.vertices, &mesh.triangles);
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
