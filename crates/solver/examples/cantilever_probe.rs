//! Cantilever refinement from the command line (studies for `docs/validation.md`):
//! `cargo run --release -p atelier-solver --example cantilever_probe -- FABRIC [key=value ...]`
//! keys: `lambda` (wL³/B, default 8.0042 — the 41.5° chord), `dt`, `damping`, `hysteresis`,
//! `max_time`, `model` (implicit/thesis), `tol`; prints the chord angle per refinement.

use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{BendingModel, Cloth, ClothState, PinMotion, Solver, StepInput, StepParams};
use nalgebra::Vector3;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args
        .first()
        .cloned()
        .unwrap_or_else(|| "cotton_broad".into());
    let get = |key: &str, default: f64| -> f64 {
        args.iter()
            .find_map(|a| a.strip_prefix(&format!("{key}=")))
            .map_or(default, |v| v.parse().expect("number"))
    };
    let path = format!(
        "{}/../../fixtures/fabrics/{name}.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let f = Fabric::load(std::path::Path::new(&path)).expect("fabric");
    let c = (f.bending.warp.rigidity() / f.weight_per_area()).cbrt();
    let length = get("lambda", 8.00420).cbrt() * c;
    let cells: Vec<usize> = args
        .iter()
        .find_map(|a| a.strip_prefix("cells="))
        .map_or(vec![10, 20, 40, 80, 160], |v| {
            v.split(',').map(|x| x.parse().expect("cells")).collect()
        });
    for n in cells {
        let h = length / (n as f64 + 0.5);
        let nv = n + 2;
        let topo = ClothTopology::from_structured(&StructuredGrid::sheet(
            2,
            nv,
            0.01,
            (nv - 1) as f64 * h,
        ))
        .expect("grid");
        let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
        let place = |[x, y]: [f64; 2]| Vector3::new(y - 0.5 * h, x, 0.0);
        for node in 0..4 {
            let p = place(cloth.topology().rest_positions()[node]);
            cloth.pin(node as u32, p, PinMotion::Fixed).expect("pin");
        }
        let mut state = ClothState::placed(&cloth, place);
        let input = StepInput::new(get("dt", 0.005));
        let params = StepParams {
            damping: get("damping", 1.0),
            hysteresis: get("hysteresis", 0.0) != 0.0,
            shape: atelier_solver::ShapeParams {
                tolerance: get("tol", 1e-4),
                ..atelier_solver::ShapeParams::default()
            },
            bending: atelier_solver::BendingParams {
                model: if get("thesis", 0.0) != 0.0 {
                    BendingModel::Thesis
                } else {
                    BendingModel::Implicit
                },
                ..atelier_solver::BendingParams::default()
            },
            ..StepParams::default()
        };
        let mut solver = Solver::new();
        let t0 = std::time::Instant::now();
        let mut unconverged = 0;
        let mut result = Ok(());
        let mut vmax = 0.0;
        let mut calm_since: Option<f64> = None;
        while state.time < get("max_time", 6.0) {
            match solver.step(&cloth, &mut state, &params, input) {
                Ok(r) => {
                    if !r.converged && get("verbose", 0.0) != 0.0 {
                        println!(
                            "  t {:.3}: viol {:.2e} {:?} shape its {} backtracks? fact {} lin {} internal {} {} bending {}",
                            state.time,
                            r.violation,
                            r.worst,
                            r.shape_iterations,
                            r.factorizations,
                            r.linear_iterations,
                            r.internal_iterations,
                            r.internal_converged,
                            r.bending_residual
                        );
                    }
                    unconverged += usize::from(!r.converged);
                    vmax = r.max_speed;
                    if r.max_speed < get("rest", 1e-4) {
                        let since = *calm_since.get_or_insert(state.time);
                        if state.time - since > 0.5 {
                            break;
                        }
                    } else {
                        calm_since = None;
                    }
                }
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
        if let Some(dt2) = args.iter().find_map(|a| a.strip_prefix("then_dt=")) {
            let input2 = input.with_dt(dt2.parse().expect("dt"));
            let tip = (state.positions[2 * nv - 1] + state.positions[2 * nv - 2]) * 0.5;
            println!(
                "  before switch: chord {:.4}°",
                (-tip.z).atan2(tip.x).to_degrees()
            );
            let t1 = state.time;
            while state.time < t1 + 2.0 {
                let r = solver
                    .step(&cloth, &mut state, &params, input2)
                    .expect("step");
                let tip = (state.positions[2 * nv - 1] + state.positions[2 * nv - 2]) * 0.5;
                if ((state.time - t1) / 0.25).fract() < input2.dt / 0.25 {
                    println!(
                        "  t {:.3} chord {:.4}° vmax {:.2e} viol {:.1e} its {}",
                        state.time,
                        (-tip.z).atan2(tip.x).to_degrees(),
                        r.max_speed,
                        r.violation,
                        r.shape_iterations
                    );
                }
            }
        }
        let tip = (state.positions[2 * nv - 1] + state.positions[2 * nv - 2]) * 0.5;
        let angle = (-tip.z).atan2(tip.x).to_degrees();
        println!(
            "{name} λ {:.4} {n} cells: chord {angle:.3}° at t {:.2} s, vmax {vmax:.2e}, unconverged {unconverged}, wall {:.2} s {:?}",
            get("lambda", 8.00420),
            state.time,
            t0.elapsed().as_secs_f64(),
            result.err()
        );
    }
}
