//! Benchmarks of the fabric lookups the solver makes per edge and per step, and of the per-angle
//! table build it makes once. Inputs are seeded; each bench checks its answer before timing.
//! Throughput is per lookup (1024 edges per iteration), so criterion reports ns per lookup.

use std::hint::black_box;
use std::path::PathBuf;

use atelier_fabric::{
    AnisotropyForm, BendingState, Branch, Fabric, MaterialTable, TensileState, units,
};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const EDGES: usize = 1024;

fn cotton() -> Fabric {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/fabrics/cotton_broad.ron");
    Fabric::load(&path).expect("fixture")
}

/// A seeded xorshift sequence in [0, 1).
fn uniform(n: usize, mut seed: u64) -> Vec<f64> {
    (0..n)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

/// A triangle wave 0 → 100 → 0 with period 200 steps: slow drift, one reversal per 100 steps.
fn triangle(step: usize) -> f64 {
    let phase = (step % 200) as f64;
    if phase < 100.0 { phase } else { 200.0 - phase }
}

fn tensile(c: &mut Criterion) {
    let fabric = cotton();
    let l = fabric.tensile.warp.clone();
    let fm = l.max_force();
    // Forces per edge for two alternating steps: every other step reverses some edges.
    let a: Vec<f64> = uniform(EDGES, 1).iter().map(|x| x * fm).collect();
    let b: Vec<f64> = uniform(EDGES, 2).iter().map(|x| x * fm).collect();
    // Check: the lookup agrees with the synthetic closed form at the seeded forces.
    let s = atelier_fabric::TensileSummary {
        lt: 0.72,
        emt: 0.03,
        rt: 0.48,
        f_max: units::KES_MAX_TENSILE_FORCE,
    };
    for &f in a.iter().filter(|&&f| f > 0.01 * fm) {
        assert!((l.strain(Branch::Loading, f) - s.loading_strain(f)).abs() < 1e-4 * s.emt);
    }
    let mut g = c.benchmark_group("tensile");
    g.throughput(Throughput::Elements(EDGES as u64));
    g.bench_function("major_strain_lookup", |bench| {
        bench.iter(|| {
            a.iter()
                .map(|&f| l.strain(Branch::Loading, black_box(f)))
                .sum::<f64>()
        })
    });
    let mut states = vec![TensileState::VIRGIN; EDGES];
    let mut flip = false;
    g.bench_function("hysteresis_update", |bench| {
        bench.iter(|| {
            flip = !flip;
            let forces = if flip { &a } else { &b };
            let mut sum = 0.0;
            for (st, &f) in states.iter_mut().zip(forces) {
                sum += st.update(&l, black_box(f));
            }
            sum
        })
    });
    // Typical step: forces drift slowly and turn once per 100 steps (most updates stay on their
    // branch).
    let mut steady = vec![TensileState::VIRGIN; EDGES];
    let mut step = 0usize;
    g.bench_function("hysteresis_update_steady", |bench| {
        bench.iter(|| {
            step += 1;
            let drift = 0.002 * fm * triangle(step);
            let mut sum = 0.0;
            for (st, &f) in steady.iter_mut().zip(&a) {
                sum += st.update(&l, black_box(0.5 * f + drift));
            }
            sum
        })
    });
    g.bench_function("hysteresis_peek", |bench| {
        bench.iter(|| {
            states
                .iter()
                .zip(&a)
                .map(|(st, &f)| st.strain(&l, black_box(f)))
                .sum::<f64>()
        })
    });
    g.finish();
}

fn bending(c: &mut Criterion) {
    let fabric = cotton();
    let s = fabric.bending.warp;
    let k = units::KES_MAX_CURVATURE;
    let a: Vec<f64> = uniform(EDGES, 3)
        .iter()
        .map(|x| (2.0 * x - 1.0) * k)
        .collect();
    let b: Vec<f64> = uniform(EDGES, 4)
        .iter()
        .map(|x| (2.0 * x - 1.0) * k)
        .collect();
    // Check: on a virgin state beyond M₀/B the moment is on the branch.
    let eta = 2.0 * s.residual_moment() / s.rigidity();
    assert!((BendingState::VIRGIN.moment(&s, eta) - s.rising_branch(eta)).abs() < 1e-12);
    let mut g = c.benchmark_group("bending");
    g.throughput(Throughput::Elements(EDGES as u64));
    let mut states = vec![BendingState::VIRGIN; EDGES];
    let mut flip = false;
    g.bench_function("moment_update", |bench| {
        bench.iter(|| {
            flip = !flip;
            let etas = if flip { &a } else { &b };
            let mut sum = 0.0;
            for (st, &e) in states.iter_mut().zip(etas) {
                sum += st.update(&s, black_box(e));
            }
            sum
        })
    });
    let mut steady = vec![BendingState::VIRGIN; EDGES];
    let mut step = 0usize;
    g.bench_function("moment_update_steady", |bench| {
        bench.iter(|| {
            step += 1;
            let drift = 0.005 * k * triangle(step);
            let mut sum = 0.0;
            for (st, &e) in steady.iter_mut().zip(&a) {
                sum += st.update(&s, black_box(0.5 * e + drift));
            }
            sum
        })
    });
    g.finish();
}

fn anisotropy(c: &mut Criterion) {
    let fabric = cotton();
    let angles: Vec<f64> = (0..16).map(|k| (k as f64 * 11.25).to_radians()).collect();
    // Check: the 0° entry is the warp loop.
    let (t, idx) = MaterialTable::build(&fabric, AnisotropyForm::Thesis, &angles).expect("table");
    assert!((t.tensile(idx[0]).apex_strain() - fabric.tensile.warp.apex_strain()).abs() < 1e-12);
    let mut g = c.benchmark_group("anisotropy");
    g.sample_size(20);
    for form in [AnisotropyForm::Thesis, AnisotropyForm::Compliance] {
        g.bench_function(format!("tensile_at_one_angle_{form:?}"), |bench| {
            bench.iter(|| fabric.tensile_at(black_box(0.3), form).expect("defined"))
        });
    }
    g.bench_function("material_table_16_angles", |bench| {
        bench.iter(|| {
            MaterialTable::build(&fabric, AnisotropyForm::Thesis, black_box(&angles))
                .expect("table")
        })
    });
    g.finish();
}

criterion_group!(benches, tensile, bending, anisotropy);
criterion_main!(benches);
