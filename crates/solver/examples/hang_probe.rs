//! A 1 m cotton sheet hanging from its top edge (the scene of `tests/solver/hanging.rs`), step
//! by step: `cargo run --release -p atelier-solver --example hang_probe -- [n] [steps]`.

use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepInput, StepParams, Tension};
use nalgebra::Vector3;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map_or(41, |a| a.parse().expect("n"));
    let steps: usize = args.get(1).map_or(20, |a| a.parse().expect("steps"));
    let balance = args.iter().any(|a| a == "balance");
    let path = format!(
        "{}/../../fixtures/fabrics/cotton_broad.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let f = Fabric::load(std::path::Path::new(&path)).expect("fabric");
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(n, n, 1.0, 1.0)).expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(x, 0.0, y);
    for i in 0..n {
        let node = (n - 1) * n + i;
        let p = place(cloth.topology().rest_positions()[node]);
        cloth.pin(node as u32, p, PinMotion::Fixed).expect("pin");
    }
    let mut state = ClothState::placed(&cloth, place);
    let input = StepInput::new(std::env::var("DT").map_or(0.01, |v| v.parse().expect("dt")));
    let params = StepParams {
        damping: 1.0,
        hysteresis: !args.iter().any(|a| a == "nohyst"),
        internal: atelier_solver::InternalParams {
            tension: if balance {
                Tension::Balance
            } else {
                Tension::Constraint
            },
            ..atelier_solver::InternalParams::default()
        },
        shear: atelier_solver::ShearParams {
            scale: if args.iter().any(|a| a == "noshear") {
                0.0
            } else {
                std::env::var("SHEAR").map_or(1.0, |v| v.parse().expect("scale"))
            },
            measure: if args.iter().any(|a| a == "corners") {
                atelier_solver::ShearMeasure::Corners
            } else {
                atelier_solver::ShearMeasure::Midpoint
            },
            ..atelier_solver::ShearParams::default()
        },
        bending: atelier_solver::BendingParams {
            off: args.iter().any(|a| a == "nobend"),
            ..atelier_solver::BendingParams::default()
        },
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    for _ in 0..steps {
        if let Some((e, t)) =
            state
                .axial_force
                .iter()
                .enumerate()
                .fold(None, |a: Option<(usize, f64)>, (e, &t)| match a {
                    Some((_, b)) if b <= t => a,
                    _ => Some((e, t)),
                })
        {
            let edge = cloth.topology().edges()[e];
            eprintln!(
                "  min T {t:.3e} edge {e} {:?} nodes {} {} at {:?}",
                edge.kind, edge.a, edge.b, state.positions[edge.a as usize]
            );
        }
        match solver.step(&cloth, &mut state, &params, input) {
            Ok(r) => println!(
                "target strain [{:.3e}, {:.3e}] T [{:.3e}, {:.3e}] t {:.3} conv {} viol {:.2e} {:?} its {} fact {} lin {} vmax {:.3} strain err {:.2e}",
                solver
                    .last_targets()
                    .iter()
                    .zip(cloth.topology().edges())
                    .map(|(t, e)| t / e.rest_length - 1.0)
                    .fold(f64::INFINITY, f64::min),
                solver
                    .last_targets()
                    .iter()
                    .zip(cloth.topology().edges())
                    .map(|(t, e)| t / e.rest_length - 1.0)
                    .fold(f64::NEG_INFINITY, f64::max),
                state
                    .axial_force
                    .iter()
                    .cloned()
                    .fold(f64::INFINITY, f64::min),
                state
                    .axial_force
                    .iter()
                    .cloned()
                    .fold(f64::NEG_INFINITY, f64::max),
                state.time,
                r.converged,
                r.violation,
                r.worst,
                r.shape_iterations,
                r.factorizations,
                r.linear_iterations,
                r.max_speed,
                r.max_strain_error
            ),
            Err(e) => {
                println!("failed: {e}");
                return;
            }
        }
    }
}
