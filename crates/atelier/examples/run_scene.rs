//! A scenario run through the facade, without the command-line program and without writing
//! anything: the Peirce cantilever of cotton broad
//! (`fixtures/scenarios/cantilever_cotton_broad.ron`, under a second), simulated by
//! [`atelier::run::simulate`], its metrics printed and checked against the scenario's
//! expectations.
//!
//! `cargo run --release -p atelier --example run_scene`
//!
//! (`atelier::run::run` does the same and also writes the report, OBJ/PLY, glTF and pictures
//! into a folder; `atelier run FILE --out DIR` is that call.)

#![allow(clippy::print_stdout)] // an example shows its results on stdout

use std::path::Path;

use atelier::run::{base_of, check_expectations, simulate};
use atelier::scenario::Scenario;

const SCENARIO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/scenarios/cantilever_cotton_broad.ron"
);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = Path::new(SCENARIO);
    let scenario = Scenario::load(path)?;
    println!("{}: {}", scenario.name, scenario.reproduces);

    // Relative paths in the scenario (its fabric file) resolve from the scenario's folder.
    // `progress` receives the fraction of simulated time done; this example ignores it.
    let sim = simulate(&scenario, &base_of(path), &mut |_fraction| {})?;
    println!(
        "{}: {} steps of {:.3} ms, {:.2} s simulated in {:.2} s wall",
        sim.fabric,
        sim.steps,
        sim.dt * 1e3,
        sim.simulated,
        sim.wall_seconds
    );
    if let Some(failure) = &sim.failure {
        println!("stopped early: {failure}");
    }
    if let Some(c) = &sim.convergence {
        let unconverged = c.unconverged_steps.unwrap_or(0);
        println!(
            "solver {}: {unconverged} of {} steps above tolerance",
            c.solver, c.steps
        );
    }

    // Every metric the run measured; the unit is the name's suffix (_deg, _cm, _percent, …).
    println!("metrics:");
    for (name, value) in &sim.metrics {
        let shown = match *value {
            Some(v) if v != 0.0 && v.abs() < 1e-3 => format!("{v:.3e}"),
            Some(v) => format!("{v:.4}"),
            None => "(not measured)".into(),
        };
        println!("  {name:<24} {shown}");
    }
    // The scenario's own bounds on those metrics, as the report would state them.
    for e in check_expectations(&scenario, &sim.metrics) {
        let (min, max) = (
            e.min.unwrap_or(f64::NEG_INFINITY),
            e.max.unwrap_or(f64::INFINITY),
        );
        let verdict = if e.met { "met" } else { "NOT met" };
        println!("expectation {} in [{min}, {max}]: {verdict}", e.metric);
    }
    for w in &sim.warnings {
        println!("warning: {w}");
    }
    Ok(())
}
