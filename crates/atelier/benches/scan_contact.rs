//! The cost of contact against a body scan (issue 24, "Docs and speed"): the nearest-point query
//! every cloth node makes each step (`RigidParts::nearest`, parry's projection on each part's
//! mesh), against the 9AR mannequin (2 832 triangles), the MakeHuman scan articulated by
//! `atelier_body::scan` (26 756 triangles and the caps of its cuts) and the same scan refined
//! 1-to-4 (107 024 triangles and caps). Each body is queried at 2 000 points 5 mm outside its
//! own trunk (points on its triangles between 0.5 and 1.15 m high, moved along the normals), with the 1 cm
//! search radius of contact; one iteration queries all 2 000.

use std::hint::black_box;
use std::path::Path;

use atelier_body::io::{ExternalBody, load_mesh};
use atelier_body::scan::{ScanOptions, mannequin, prepare, subdivided};
use atelier_body::{Mannequin, V3};
use atelier_collide::parts::RigidParts;
use criterion::{Criterion, criterion_group, criterion_main};

/// The body's parts as rigid colliders, and query points 5 mm outside its trunk.
fn setup(m: &Mannequin) -> (RigidParts, Vec<V3>) {
    let meshes: Vec<(&[V3], &[[u32; 3]])> = m
        .parts
        .iter()
        .map(|p| (p.vertices.as_slice(), p.triangles.as_slice()))
        .collect();
    let parts = RigidParts::new(&meshes).expect("closed parts");
    // Four points on every triangle of the trunk band, 5 mm out along the face's normal,
    // kept where they are outside the body (not under another part).
    let mut points = Vec::new();
    for p in &m.parts {
        for t in &p.triangles {
            let [a, b, c] = t.map(|k| p.vertices[k as usize]);
            let Some(n) = (b - a).cross(&(c - a)).try_normalize(0.0) else {
                continue;
            };
            for w in [
                [1.0, 1.0, 1.0],
                [4.0, 1.0, 1.0],
                [1.0, 4.0, 1.0],
                [1.0, 1.0, 4.0],
            ] {
                let q = (a * w[0] + b * w[1] + c * w[2]) / (w[0] + w[1] + w[2]) + n * 0.005;
                if (0.5..1.15).contains(&q.y)
                    && parts
                        .nearest(&q, 0.01, false)
                        .is_some_and(|h| h.distance > 0.0)
                {
                    points.push(q);
                }
            }
        }
    }
    let stride = (points.len() / 2000).max(1);
    let points: Vec<V3> = points.into_iter().step_by(stride).take(2000).collect();
    (parts, points)
}

fn scan_contact(c: &mut Criterion) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/tryon/makehuman/mh_rest.obj");
    let mesh = load_mesh(&path).expect("mh_rest.obj");
    let (fv, ft) = subdivided(&mesh.vertices, &mesh.triangles);
    let fine = ExternalBody {
        vertices: fv,
        triangles: ft,
        ..ExternalBody::default()
    };
    let opts = ScanOptions::default();
    let bodies = [
        ("mannequin_2832", atelier_body::build::jis_9ar()),
        (
            "scan_26756",
            mannequin(&prepare(mesh, &opts, None).expect("scan")).expect("articulated"),
        ),
        (
            "scan_107024",
            mannequin(&prepare(fine, &opts, None).expect("scan")).expect("articulated"),
        ),
    ];
    let mut group = c.benchmark_group("scan_contact");
    group.sample_size(20);
    for (name, body) in &bodies {
        let (parts, points) = setup(body);
        assert!(
            points.len() >= 1500,
            "{name}: {} query points",
            points.len()
        );
        group.bench_function(*name, |b| {
            b.iter(|| {
                points
                    .iter()
                    .filter(|p| parts.nearest(black_box(p), 0.01, false).is_some())
                    .count()
            });
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = scan_contact
}
criterion_main!(benches);
