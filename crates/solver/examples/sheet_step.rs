//! A 50 cm square of cotton broad held flat by two adjacent corners and let go: it swings down
//! under gravity for half a second with the default [`StepParams`] (Δt = 10 ms). The cloth is
//! built from a structured grid and a fabric file, the two corners are fixed pins, and the
//! [`StepReport`] of every step is summarised.
//!
//! `cargo run --release -p atelier-solver --example sheet_step`

#![allow(clippy::print_stdout)] // an example shows its results on stdout

use std::path::Path;

use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepInput, StepParams};
use nalgebra::Vector3;

const FABRIC: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/fabrics/cotton_broad.ron"
);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // 21 × 21 nodes over 0.5 m × 0.5 m (2.5 cm cells); the warp runs along the pattern's y.
    let n = 21;
    let fabric = Fabric::load(Path::new(FABRIC))?;
    let topology = ClothTopology::from_structured(&StructuredGrid::sheet(n, n, 0.5, 0.5))?;
    let mut cloth = Cloth::new(topology, &fabric, AnisotropyForm::Thesis)?;

    // Pin the two corners of the pattern's top row (y = 0.5 m) where they lie in the horizontal
    // plane z = 0 (gravity is −z), then lay the whole sheet flat there at rest.
    for node in [(n - 1) * n, n * n - 1] {
        let [x, y] = cloth.topology().rest_positions()[node];
        cloth.pin(node as u32, Vector3::new(x, y, 0.0), PinMotion::Fixed)?;
    }
    let mut state = ClothState::flat(&cloth, 0.0);
    let (params, input) = (StepParams::default(), StepInput::default());
    let mut solver = Solver::new();

    let steps = (0.5 / input.dt).round() as usize;
    let (mut unconverged, mut worst_violation, mut iterations) = (0, 0.0_f64, 0);
    // Every 10th step's report: shape iterations, the relative constraint violation it ended
    // with (|l − l̄|/l⁰ of the edges, rad for the cells), the fastest node, the kinetic energy.
    println!("   t (s)  shape its  violation  max speed (m/s)  kinetic energy (mJ)");
    for k in 1..=steps {
        let r = solver.step(&cloth, &mut state, &params, input)?;
        unconverged += usize::from(!r.converged);
        worst_violation = worst_violation.max(r.violation);
        iterations += r.shape_iterations;
        if k % 10 == 0 {
            let (t, its, viol) = (state.time, r.shape_iterations, r.violation);
            let (speed, ke) = (r.max_speed, r.kinetic_energy * 1e3);
            println!("  {t:6.2}  {its:9}  {viol:9.2e}  {speed:15.3}  {ke:19.3}");
        }
    }
    let per_step = iterations as f64 / steps as f64;
    println!("{steps} steps: {unconverged} unconverged, {per_step:.1} shape iterations per step");
    println!("largest violation at the end of a step {worst_violation:.2e}");

    // The largest strain (l − l⁰)/l⁰ over all edges, and how far the free edge's middle fell.
    let strains = state.strains(&cloth);
    let mut largest = (0, f64::NEG_INFINITY);
    for (edge, &strain) in strains.iter().enumerate() {
        if strain > largest.1 {
            largest = (edge, strain);
        }
    }
    let kind = cloth.topology().edges()[largest.0].kind;
    println!(
        "largest strain {:.3} % (a {kind:?} edge)",
        largest.1 * 100.0
    );
    let z = state.positions[n / 2].z * 100.0; // node (n/2, 0): the middle of the free edge
    println!("free edge's middle at z = {z:.1} cm (started at 0, pins at 0)");
    Ok(())
}
