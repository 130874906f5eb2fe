//! A drape run from the command line, for the studies of `docs/validation.md`:
//! `cargo run --release -p atelier-solver --example drape_probe -- FABRIC [key=value ...]`
//! with keys `around`, `rings`, `dt`, `tol`, `cap`, `shear` (scale), `measure` (midpoint or
//! corners), `b` (bending scale), `g` (scale of G), `hg` (scale of 2HG and 2HG5), `seed`,
//! `bratio` (warp B over weft B, their geometric mean kept), `max_time`, `perturb` (m), `ramp`
//! (s of gravity ramped up from zero first), `support` (hinged or clamped; default the JIS
//! scene's, clamped), `hysteresis` (0/1), `method` (direct, cg, jacobi, chebyshev, gs). Prints
//! the drape, the convergence counts and the wall time.

use std::time::Instant;

use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_solver::scenes::{DrapeScene, RestCriterion, run_drape};
use atelier_solver::{ShapeMethod, ShearMeasure, Solver, StepInput, StepParams};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args
        .first()
        .cloned()
        .unwrap_or_else(|| "polyester_faille".into());
    let get = |key: &str, default: f64| -> f64 {
        args.iter()
            .find_map(|a| a.strip_prefix(&format!("{key}=")))
            .map_or(default, |v| v.parse().expect("number"))
    };
    let word = |key: &str, default: &str| -> String {
        args.iter()
            .find_map(|a| a.strip_prefix(&format!("{key}=")))
            .unwrap_or(default)
            .to_string()
    };
    let path = format!(
        "{}/../../fixtures/fabrics/{name}.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut fabric = Fabric::load(std::path::Path::new(&path)).expect("fabric");
    if let Some(s) = fabric.shear.as_mut() {
        s.stiffness *= get("g", 1.0);
        s.hysteresis *= get("hg", 1.0);
        if let Some(h5) = s.hysteresis_5deg.as_mut() {
            *h5 *= get("hg", 1.0);
        }
    }
    let b = get("b", 1.0);
    if b != 1.0 {
        fabric.bending = fabric.bending.map(|s| {
            atelier_fabric::Spindle::new(s.rigidity() * b, s.residual_moment() * b).expect("B")
        });
    }
    // Bending anisotropy: warp B and M₀ × √r, weft ÷ √r (their geometric mean kept), the bias
    // directions again by Huber's rule (docs/fabric.md §6), as a loaded file would derive them.
    let r = get("bratio", 1.0);
    if r != 1.0 {
        let k = r.sqrt();
        let (w, f) = (&fabric.bending.warp, &fabric.bending.weft);
        let huber = atelier_fabric::anisotropy::huber_bias;
        let warp = atelier_fabric::Spindle::new(w.rigidity() * k, w.residual_moment() * k);
        let weft = atelier_fabric::Spindle::new(f.rigidity() / k, f.residual_moment() / k);
        let (warp, weft) = (warp.expect("B"), weft.expect("B"));
        let bias = atelier_fabric::Spindle::new(
            huber(warp.rigidity(), weft.rigidity()),
            huber(warp.residual_moment(), weft.residual_moment()),
        )
        .expect("B");
        fabric.bending.warp = warp;
        fabric.bending.weft = weft;
        fabric.bending.bias45 = bias.clone();
        fabric.bending.bias135 = bias;
    }
    let mut scene = DrapeScene::jis(get("around", 72.0) as usize, get("rings", 8.0) as usize);
    match word("support", "").as_str() {
        "hinged" => scene.support = atelier_solver::scenes::Support::Hinged,
        "clamped" => scene.support = atelier_solver::scenes::Support::Clamped,
        _ => {}
    }
    scene.perturbation = get("perturb", 1e-4);
    scene.seed = get("seed", 1.0) as u64;
    scene.cloth_options.form = AnisotropyForm::Compliance;
    let method = match word("method", "direct").as_str() {
        "cg" => ShapeMethod::ConjugateGradient { cg_iterations: 500 },
        "jacobi" => ShapeMethod::Jacobi,
        "chebyshev" => ShapeMethod::Chebyshev { rho: 0.99 },
        "gs" => ShapeMethod::GaussSeidel { omega: 1.0 },
        "direct0" => ShapeMethod::Direct { refactor_after: 0 },
        _ => ShapeMethod::DEFAULT,
    };
    let input = StepInput::new(get("dt", 0.01));
    let params = StepParams {
        hysteresis: get("hysteresis", 1.0) != 0.0,
        damping: get("damping", 0.2),
        divergence_strain: get("divergence", 1.0),
        shape: atelier_solver::ShapeParams {
            tolerance: get("tol", 1e-4),
            max_iterations: get("cap", 100.0) as usize,
            method,
            collision_passes: get("passes", 2.0) as usize,
            ..atelier_solver::ShapeParams::default()
        },
        shear: atelier_solver::ShearParams {
            scale: get("shear", 1.0),
            measure: if word("measure", "midpoint") == "corners" {
                ShearMeasure::Corners
            } else {
                ShearMeasure::Midpoint
            },
            ..atelier_solver::ShearParams::default()
        },
        bending: atelier_solver::BendingParams {
            off: get("bending_off", 0.0) != 0.0,
            implicit_stick_slope: get("stick", 0.0) != 0.0,
            ..atelier_solver::BendingParams::default()
        },
        ..StepParams::default()
    };
    let (cloth, mut state) = scene.build(&fabric).expect("scene");
    let mut solver = Solver::new();
    let stop = RestCriterion {
        max_time: get("max_time", 6.0),
        ..RestCriterion::default()
    };
    if get("verbose", 0.0) != 0.0 {
        let steps = (get("max_time", 6.0) / input.dt).round() as usize;
        for _ in 0..steps {
            if state.time < get("from", 0.0) - 1e-9 {
                solver
                    .step(&cloth, &mut state, &params, input)
                    .expect("step");
                continue;
            }
            match solver.step(&cloth, &mut state, &params, input) {
                Ok(r) => println!(
                    "t {:.3} conv {} viol {:.2e} {:?} shape its {} fact {} lin {} internal {} {:.1e} {} bending {} {:.1e} vmax {:.3} ke {:.2e}",
                    state.time,
                    r.converged,
                    r.violation,
                    r.worst,
                    r.shape_iterations,
                    r.factorizations,
                    r.linear_iterations,
                    r.internal_iterations,
                    r.internal_residual,
                    r.internal_converged,
                    r.bending_iterations,
                    r.bending_residual,
                    r.max_speed,
                    r.kinetic_energy
                ),
                Err(e) => {
                    println!("failed: {e}");
                    return;
                }
            }
        }
        return;
    }
    let t0 = Instant::now();
    // Gravity ramped up from zero over `ramp` seconds (a quasi-static release) before the run.
    let ramp = get("ramp", 0.0);
    while state.time < ramp - 1e-9 {
        let s = ((state.time + input.dt) / ramp).min(1.0);
        let g = input.gravity.map(|c| c * s);
        solver
            .step(
                &cloth,
                &mut state,
                &params,
                StepInput {
                    gravity: g,
                    ..input
                },
            )
            .expect("ramp step");
    }
    let run = run_drape(
        &scene,
        &cloth,
        &mut state,
        &mut solver,
        &params,
        input,
        &stop,
    );
    let wall = t0.elapsed();
    match run {
        Ok(run) => {
            println!(
                "{name}: DC {:.1} % nodes {} settled {} t {:.2} s steps {} wall {:.1} s ({:.2} ms/step) unconverged {} mean shape its {:.1} max strain err {:.2e} max axial strain {:.2e}",
                run.measure.drape_coefficient,
                run.measure.nodes,
                run.settled,
                run.time,
                run.steps,
                wall.as_secs_f64(),
                1e3 * wall.as_secs_f64() / run.steps as f64,
                run.unconverged_steps,
                run.mean_shape_iterations,
                run.max_strain_error,
                run.max_axial_strain,
            );
            let strains = state.strains(&cloth);
            let mut idx: Vec<usize> = (0..strains.len())
                .filter(|&e| cloth.topology().edges()[e].kind.is_axial())
                .collect();
            idx.sort_by(|&a, &b| strains[b].total_cmp(&strains[a]));
            for &e in idx.iter().take(4) {
                let ed = cloth.topology().edges()[e];
                println!(
                    "  edge {e} {:?} nodes {} {} (rings {} {}) strain {:.3e} force {:.3e} N",
                    ed.kind,
                    ed.a,
                    ed.b,
                    ed.a as usize / scene.n_around,
                    ed.b as usize / scene.n_around,
                    strains[e],
                    state.axial_force[e]
                );
            }
            let prominences: Vec<String> = run
                .measure
                .folds
                .iter()
                .map(|f| format!("{:.0}", 1e3 * f.prominence))
                .collect();
            println!("  prominences mm: {}", prominences.join(" "));
            for s in run.trace.iter().step_by(5) {
                println!(
                    "  t {:.1} DC {:.1} nodes {} v {:.4}",
                    s.time, s.drape_coefficient, s.nodes, s.rms_speed
                );
            }
        }
        Err(e) => println!("{name}: failed: {e}"),
    }
}
