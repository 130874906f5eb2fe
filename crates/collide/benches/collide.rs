//! Benchmarks of the narrow phase (per candidate pair) and of a full collision pass at the
//! thesis's sizes: a 2 704-node cloth (52 × 52) wrapped 2 mm outside a 1 296-triangle body
//! (the thesis: 2 704 nodes, 1 256 triangles), moving inwards, the body swinging slightly —
//! set the body, transfer its motion, two physical passes; each broad phase, with and without
//! self-collision.

use std::hint::black_box;

use atelier_collide::broad::BroadKind;
use atelier_collide::narrow::{Sides, point_triangle, point_triangle_thesis};
use atelier_collide::shapes::cylinder;
use atelier_collide::{ClothView, Collider, ContactParams, V3};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

/// A seeded xorshift sequence in [−1, 1).
fn noise(n: usize, mut seed: u64) -> Vec<f64> {
    (0..n)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            2.0 * ((seed >> 11) as f64 / (1u64 << 53) as f64) - 1.0
        })
        .collect()
}

fn narrow(c: &mut Criterion) {
    const PAIRS: usize = 1024;
    let r = noise(PAIRS * 24, 7);
    let v3 = |k: usize, s: f64| V3::new(r[k] * s, r[k + 1] * s, r[k + 2] * s);
    let cases: Vec<_> = (0..PAIRS)
        .map(|i| {
            let b = i * 24;
            (
                v3(b, 0.1) + V3::new(0.0, 0.0, 0.05),
                v3(b + 3, 1.0) + V3::new(0.0, 0.0, -5.0),
                [v3(b + 6, 0.1), v3(b + 9, 0.1), v3(b + 12, 0.1)],
                [v3(b + 15, 1.0), v3(b + 18, 1.0), v3(b + 21, 1.0)],
            )
        })
        .collect();
    let hits = cases
        .iter()
        .filter(|(p, v, x, u)| {
            point_triangle(
                p,
                v,
                [&x[0], &x[1], &x[2]],
                [&u[0], &u[1], &u[2]],
                0.01,
                1e-3,
                Sides::Both,
            )
            .is_some()
        })
        .count();
    assert!(hits > 0, "the bench cases must include hits");
    let mut group = c.benchmark_group("narrow");
    group.throughput(Throughput::Elements(PAIRS as u64));
    group.bench_function("exact_cubic", |b| {
        b.iter(|| {
            cases
                .iter()
                .filter(|(p, v, x, u)| {
                    point_triangle(
                        black_box(p),
                        v,
                        [&x[0], &x[1], &x[2]],
                        [&u[0], &u[1], &u[2]],
                        0.01,
                        1e-3,
                        Sides::Both,
                    )
                    .is_some()
                })
                .count()
        });
    });
    group.bench_function("thesis_linear", |b| {
        b.iter(|| {
            cases
                .iter()
                .filter(|(p, v, x, u)| {
                    point_triangle_thesis(
                        black_box(p),
                        v,
                        [&x[0], &x[1], &x[2]],
                        [&u[0], &u[1], &u[2]],
                        0.01,
                        1e-3,
                        Sides::Both,
                    )
                    .is_some()
                })
                .count()
        });
    });
    group.finish();
}

/// The cloth: 52 × 52 nodes wrapped around the body at radius `r`, rows along −y.
fn cloth(r: f64) -> (Vec<V3>, Vec<V3>, Vec<[u32; 3]>) {
    let (nu, nv) = (52usize, 52usize);
    let jitter = noise(nu * nv * 3, 11);
    let mut x = Vec::with_capacity(nu * nv);
    let mut v = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let a = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
            let (s, c) = a.sin_cos();
            x.push(V3::new(
                r * s,
                -0.1 - 0.8 * j as f64 / (nv - 1) as f64,
                r * c,
            ));
            let k = 3 * (j * nu + i);
            v.push(
                V3::new(-0.5 * s, 0.0, -0.5 * c)
                    + V3::new(jitter[k], jitter[k + 1], jitter[k + 2]) * 0.2,
            );
        }
    }
    let mut t = Vec::new();
    for j in 0..nv - 1 {
        for i in 0..nu - 1 {
            let q = [
                j * nu + i,
                j * nu + i + 1,
                (j + 1) * nu + i + 1,
                (j + 1) * nu + i,
            ]
            .map(|k| k as u32);
            t.push([q[0], q[2], q[1]]);
            t.push([q[0], q[3], q[2]]);
        }
    }
    (x, v, t)
}

fn full_pass(c: &mut Criterion) {
    let dt = 0.01;
    let (body, tris) = cylinder(0.15, 1.0, 36, 18);
    let end: Vec<V3> = body.iter().map(|p| p + V3::new(0.0, 0.0, 0.005)).collect();
    let (x, v0, ct) = cloth(0.152);
    let inv = vec![1.0 / 0.002; x.len()];
    let mut group = c.benchmark_group("collision_pass_2704_nodes_1296_triangles");
    group.sample_size(20);
    for (name, broad, self_collision, staged) in [
        ("bvh", BroadKind::Bvh, false, true),
        ("bvh_physical_only", BroadKind::Bvh, false, false),
        ("projection", BroadKind::Projection, false, true),
        ("bvh_with_self", BroadKind::Bvh, true, true),
    ] {
        let params = ContactParams {
            broad,
            self_collision,
            staged,
            ..ContactParams::default()
        };
        let mut collider = Collider::new(params).expect("params");
        let mut vel = v0.clone();
        let mut exit = vec![V3::zeros(); x.len()];
        let mut pass = |collider: &mut Collider| {
            vel.copy_from_slice(&v0);
            exit.iter_mut().for_each(|e| *e = V3::zeros());
            collider.set_body(&body, &end, &tris, dt).expect("body");
            collider.transfer(&x, &mut vel, &inv, &[], &mut []);
            for _ in 0..2 {
                collider.resolve(
                    ClothView {
                        positions: &x,
                        velocities: &mut vel,
                        exit: &mut exit,
                        inverse_masses: &inv,
                        triangles: &ct,
                        normals: &[],
                        planes: &mut [],
                    },
                    dt,
                );
            }
            collider.take_stats()
        };
        let stats = pass(&mut collider);
        assert!(stats.body_hits > 100, "{name}: {stats:?}");
        group.bench_function(name, |b| b.iter(|| pass(black_box(&mut collider))));
    }
    group.finish();
}

criterion_group!(benches, narrow, full_pass);
criterion_main!(benches);
