//! Benches of the string identification (`docs/fit.md`, `docs/performance.md`), on the
//! synthetic rubber string (9 markers, 20 shapes, σ = 0.5 px):
//!
//! - `fit/lm_iteration_j4`, `fit/lm_iteration_j10`: a fit stopped after one Levenberg–Marquardt
//!   iteration (residuals, the analytic Jacobian, one trust-region step), J = 4 and 10 shapes;
//! - `fit/full_j4`, `fit/full_j10`: the whole fit with the default options (at most 1 000
//!   iterations; the goal: J = 10 under one second), and `fit/full_j10_minpack` with
//!   the `levenberg-marquardt` crate instead (at most 200 iterations);
//! - `fit/reproduce_10`: ten unobserved shapes reproduced by the fitted model (quasi-static
//!   manipulation, 20 equilibria each).
//!
//! - `turned/path`, `turned/fit`: the turned spindle strip (wool tropical, 60 stations): one
//!   path through 0°, 45°, 90° (the forward model), and the whole fit of B and M₀ to its own
//!   shapes at 10 points each.
//!
//! `cargo test --benches` runs each once (criterion's test mode).

use atelier_fit::FitOptions;
use atelier_fit::cloth::ProfilePoint;
use atelier_fit::experiment::{fit, paper_initial, reproduce};
use atelier_fit::synthetic::{Object, SyntheticOptions, observe};
use atelier_fit::turned::{TurnedProfile, TurnedStrip, fit_turned};
use criterion::{Criterion, criterion_group, criterion_main};

fn benches(c: &mut Criterion) {
    let (obs, _) = observe(Object::Rubber, &SyntheticOptions::default()).expect("observed");
    let (s, b) = Object::Rubber.table2();
    let initial = paper_initial(&obs, 0, s, b).expect("initial");
    let one = FitOptions {
        max_iterations: Some(1),
        ..FitOptions::default()
    };
    let full = FitOptions::default();
    let j4: Vec<usize> = (0..4).collect();
    let j10: Vec<usize> = (0..10).collect();
    let mut g = c.benchmark_group("fit");
    g.sample_size(10);
    g.bench_function("lm_iteration_j4", |b| {
        b.iter(|| fit(&obs, &j4, &initial, &one).expect("fit"));
    });
    g.bench_function("lm_iteration_j10", |b| {
        b.iter(|| fit(&obs, &j10, &initial, &one).expect("fit"));
    });
    g.bench_function("full_j4", |b| {
        b.iter(|| fit(&obs, &j4, &initial, &full).expect("fit"));
    });
    g.bench_function("full_j10", |b| {
        b.iter(|| fit(&obs, &j10, &initial, &full).expect("fit"));
    });
    let minpack = FitOptions {
        method: atelier_fit::identify::Method::Minpack,
        max_iterations: Some(200),
        ..FitOptions::default()
    };
    g.bench_function("full_j10_minpack", |b| {
        b.iter(|| fit(&obs, &j10, &initial, &minpack).expect("fit"));
    });
    let fitted = fit(&obs, &j10, &initial, &full).expect("fit");
    let unobserved: Vec<usize> = (10..20).collect();
    g.bench_function("reproduce_10", |b| {
        b.iter(|| reproduce(&fitted.model, &obs, &fitted.positions, &unobserved));
    });
    g.finish();
    let (bw, m0) = (
        atelier_fabric::units::rigidity_from_kes(0.067),
        0.5 * atelier_fabric::units::moment_from_kes(0.033),
    );
    let w = 16.29e-2 * atelier_fabric::STANDARD_GRAVITY;
    let length = 2.0003 * (bw / w).cbrt();
    let strip = TurnedStrip::new(length, w).expect("strip");
    let angles = [0.0, 45.0, 90.0];
    let shapes = strip.shapes(bw, m0, &angles).expect("shapes");
    let profiles: Vec<TurnedProfile> = angles
        .iter()
        .zip(&shapes)
        .map(|(&a, line)| TurnedProfile {
            clamp_deg: a,
            points: (1..=10)
                .map(|k| ProfilePoint {
                    s: 6.0 * k as f64 * length / 60.0,
                    x: line[6 * k].0,
                    droop: line[6 * k].1,
                })
                .collect(),
        })
        .collect();
    let mut g = c.benchmark_group("turned");
    g.sample_size(10);
    g.bench_function("path", |b| {
        b.iter(|| strip.shapes(bw, m0, &angles).expect("shapes"));
    });
    g.bench_function("fit", |b| {
        b.iter(|| fit_turned(&profiles, length, w).expect("fit"));
    });
    g.finish();
}

criterion_group!(fit_benches, benches);
criterion_main!(fit_benches);
