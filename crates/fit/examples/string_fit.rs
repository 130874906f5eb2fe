//! String identification on a synthetic problem (Sudoh et al.): a 9-particle string with a
//! natural curvature (the "truth") is held by its ends at four positions, and its static shapes
//! are the observations. From the paper's kind of initial guess (natural lengths and bends read
//! off the first shape, stretch and bending coefficients off by a factor of 3),
//! Levenberg–Marquardt finds every parameter again, and the fitted model predicts a fifth,
//! unobserved shape.
//!
//! `cargo run --release -p atelier-fit --example string_fit`

#![allow(clippy::print_stdout)] // an example shows its results on stdout

use atelier_fit::statics::StaticOptions;
use atelier_fit::{FitOptions, StringModel, StringParams, V2, identify, initial_guess};

/// A sagging start for the static solve: the first end at the origin, the last at `(ex, ey)` m.
fn start(i: usize, (ex, ey): (f64, f64)) -> Vec<V2> {
    let u = |k: usize| k as f64 / (i - 1) as f64;
    let sag = |u: f64| 0.02 * (std::f64::consts::PI * u).sin();
    (0..i)
        .map(|k| V2::new(ex * u(k), ey * u(k) - sag(u(k))))
        .collect()
}

/// The largest relative difference between two parameter lists.
fn worst(found: &[f64], truth: &[f64]) -> f64 {
    let rel = |(f, t): (&f64, &f64)| ((f - t) / t).abs();
    found.iter().zip(truth).map(rel).fold(0.0, f64::max)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let i = 9; // particles of 1 g; 8 segments of 3 cm
    let truth = StringModel::new(StringParams {
        stretch: vec![2.0; i - 1],  // s, N
        length: vec![0.03; i - 1],  // l, m
        bending: vec![0.02; i - 2], // b, N·m
        // φ, rad (π: straight): a natural curl
        natural_bend: (0..i - 2).map(|k| 2.8 + 0.05 * k as f64).collect(),
    });
    let statics = StaticOptions::default();
    let ends = [(0.15, 0.05), (0.2, -0.05), (0.1, -0.1), (0.18, 0.1)];
    let mut observed = Vec::new();
    for end in ends {
        observed.push(truth.equilibrium(&start(i, end), &statics)?.positions);
    }

    // Initial values as in the paper, then the fit (no iteration limit: run to convergence).
    let initial = initial_guess(&observed[0], 6.0, 0.006)?;
    let options = FitOptions {
        max_iterations: None,
        ..FitOptions::default()
    };
    let fit = identify(&observed, &initial, &options)?;
    let (it, why) = (fit.iterations, &fit.termination);
    println!(
        "{it} iterations ({why}): E_all {:.3e} → {:.3e}",
        fit.initial_cost, fit.cost
    );

    let (p, t) = (&fit.model.params, &truth.params);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (s, b) = (mean(&p.stretch), mean(&p.bending));
    println!("mean s {s:.4} N (truth 2, guess 6), mean b {b:.5} N·m (truth 0.02, guess 0.006)");
    println!(
        "largest relative error: s {:.1e}, l {:.1e}, b {:.1e}, φ {:.1e}",
        worst(&p.stretch, &t.stretch),
        worst(&p.length, &t.length),
        worst(&p.bending, &t.bending),
        worst(&p.natural_bend, &t.natural_bend)
    );

    // A shape that was not observed: the truth's and the fitted model's, from the same start.
    let end = (0.12, 0.08);
    let actual = truth.equilibrium(&start(i, end), &statics)?.positions;
    let predicted = fit.model.equilibrium(&start(i, end), &statics)?.positions;
    let error = predicted
        .iter()
        .zip(&actual)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    println!("unobserved shape (end at 12, 8 cm) predicted to within {error:.1e} m");
    Ok(())
}
