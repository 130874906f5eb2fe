//! Broad-phase benchmarks: BVH (refit) against the projection test (re-bin), brute force at
//! the smallest size. A closed wavy body of 1 k, 10 k and 100 k triangles moves 1 cm per step
//! (and deforms); 3 k and 30 k cloth nodes near its surface move at up to 1 m/s with
//! Δt = 0.01 s, each queried along its step segment grown by the largest displacement.
//!
//! `cargo bench -p atelier-collide --bench broad`; per-query ns = median / node count.

use std::f64::consts::{PI, TAU};
use std::hint::black_box;
use std::time::Duration;

use atelier_collide::V3;
use atelier_collide::broad::{BroadKind, BroadPhase, ProjectionBroad, new_broad};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

const DT: f64 = 0.01;
const SPEED: f64 = 1.0;
const MARGIN: f64 = 1e-3;

/// A torso-sized wavy closed surface (latitude–longitude grid) at time `t`: radius about
/// 0.25 m, stretched to 0.6 m tall, translated at 1 m/s along x and breathing.
fn body(nlat: usize, nlon: usize, t: f64) -> Vec<V3> {
    let mut v = Vec::with_capacity(nlat * nlon + 2);
    let shift = V3::new(SPEED * t, 0.0, 0.0);
    v.push(V3::new(0.0, 0.0, -0.6) + shift);
    v.push(V3::new(0.0, 0.0, 0.6) + shift);
    for i in 1..=nlat {
        let th = PI * i as f64 / (nlat + 1) as f64;
        for j in 0..nlon {
            let ph = TAU * j as f64 / nlon as f64;
            let r = 0.25 * (1.0 + 0.08 * (5.0 * th + 3.0 * t).sin() * (3.0 * ph).cos());
            v.push(
                V3::new(
                    r * th.sin() * ph.cos(),
                    r * th.sin() * ph.sin(),
                    -0.6 * th.cos(),
                ) + shift,
            );
        }
    }
    v
}

fn body_triangles(nlat: usize, nlon: usize) -> Vec<[u32; 3]> {
    let idx = |i: usize, j: usize| (2 + (i - 1) * nlon + j % nlon) as u32;
    let mut t = Vec::new();
    for j in 0..nlon {
        t.push([0, idx(1, j + 1), idx(1, j)]);
        t.push([1, idx(nlat, j), idx(nlat, j + 1)]);
    }
    for i in 1..nlat {
        for j in 0..nlon {
            t.push([idx(i, j), idx(i, j + 1), idx(i + 1, j + 1)]);
            t.push([idx(i, j), idx(i + 1, j + 1), idx(i + 1, j)]);
        }
    }
    t
}

/// Grid sizes giving about `n` triangles.
fn grid_for(n: usize) -> (usize, usize) {
    let nlat = ((n as f64 / 4.0).sqrt()).round() as usize;
    (nlat, (n / (2 * nlat)).max(3))
}

struct Lcg(u64);
impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `m` cloth nodes within 0–2 cm outside the body surface, each with its step segment.
fn nodes(m: usize, verts: &[V3]) -> Vec<(V3, V3)> {
    let mut rng = Lcg(12345);
    (0..m)
        .map(|_| {
            let p = verts[2 + (rng.unit() * (verts.len() - 2) as f64) as usize];
            // Outward from the body's axis (the body sits on the z axis at t = 0).
            let out = V3::new(p.x, p.y, 0.0).normalize();
            let a = p + out * (0.02 * rng.unit());
            let dir = V3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5);
            let v = dir.normalize() * SPEED * rng.unit();
            (a, a + v * DT)
        })
        .collect()
}

/// A named broad-phase constructor.
type Maker = (&'static str, Box<dyn Fn() -> Box<dyn BroadPhase>>);

fn bench(c: &mut Criterion) {
    let radius = SPEED * DT; // largest displacement of any node
    for n in [1_000usize, 10_000, 100_000] {
        let (nlat, nlon) = grid_for(n);
        let tris = body_triangles(nlat, nlon);
        let nt = tris.len();
        let mut kinds: Vec<Maker> = vec![
            ("bvh", Box::new(|| new_broad(BroadKind::Bvh))),
            ("projection", Box::new(|| new_broad(BroadKind::Projection))),
            (
                "projection-boxes",
                Box::new(|| Box::new(ProjectionBroad::new().with_segment_test(false))),
            ),
        ];
        if n == 1_000 {
            kinds.push(("brute", Box::new(|| new_broad(BroadKind::Brute))));
        }
        let s0 = body(nlat, nlon, 0.0);
        let s1 = body(nlat, nlon, DT);

        let mut g = c.benchmark_group(format!("update/{nt}"));
        for (name, make) in &kinds {
            if *name == "projection-boxes" {
                continue; // same update as "projection"
            }
            let mut bp = make();
            bp.update(&s0, &s1, &tris, MARGIN);
            let mut step = 0usize;
            g.bench_function(*name, |b| {
                b.iter(|| {
                    // Alternate two body poses so every update moves every triangle.
                    step += 1;
                    let (x, y) = if step.is_multiple_of(2) {
                        (&s0, &s1)
                    } else {
                        (&s1, &s0)
                    };
                    bp.update(black_box(x), black_box(y), &tris, MARGIN);
                });
            });
        }
        g.finish();

        for m in [3_000usize, 30_000] {
            let q = nodes(m, &s0);
            let mut g = c.benchmark_group(format!("query/{nt}"));
            g.throughput(Throughput::Elements(m as u64));
            for (name, make) in &kinds {
                let mut bp = make();
                bp.update(&s0, &s1, &tris, MARGIN);
                let mut out = Vec::new();
                let mut total = 0usize;
                for (a, b) in &q {
                    out.clear();
                    bp.query(a, b, radius, &mut out);
                    total += out.len();
                }
                eprintln!(
                    "{nt} triangles, {m} nodes, {name}: {:.2} candidates per query",
                    total as f64 / m as f64
                );
                g.bench_with_input(BenchmarkId::new(*name, m), &q, |bch, q| {
                    bch.iter(|| {
                        let mut count = 0;
                        for (a, b) in q {
                            out.clear();
                            bp.query(a, b, radius, &mut out);
                            count += out.len();
                        }
                        black_box(count)
                    });
                });
            }
            g.finish();
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
