//! A drape run from the command line, for the studies of `docs/validation.md`:
//! `cargo run --release -p atelier-solver --example drape_probe -- FABRIC [key=value ...]`
//! with keys `around`, `rings`, `dt`, `tol`, `cap`, `shear` (scale), `measure` (midpoint or
//! corners), `b` (bending scale), `g` (scale of G), `hg` (scale of 2HG and 2HG5), `seed`,
//! `bratio` (warp B over weft B, their geometric mean kept), `max_time`, `perturb` (m), `ramp`
//! (s of gravity ramped up from zero first), `support` (hinged or clamped; default the JIS
//! scene's, clamped), `hysteresis` (0/1), `method` (direct, cg, jacobi, chebyshev, gs), `m0`
//! (scale of the bending residual moment M₀ alone), `bband` (bending dead band, × M₀/B),
//! `stick_slope` (bending), `steepest` (0/1: `bending.steepest_slope`), `spindle_rows` (0/1:
//! `bending.spindle_rows`), `sband` (shear dead band, rad), `drift` (s stepped after the run,
//! then where the remaining motion is: one step's move against two steps'). Prints the drape,
//! the convergence counts and the wall time.

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
    let m0 = get("m0", 1.0);
    if m0 != 1.0 {
        fabric.bending = fabric.bending.map(|s| {
            atelier_fabric::Spindle::new(s.rigidity(), s.residual_moment() * m0).expect("2HB")
        });
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
            deadband: get("sband", 1e-4),
            measure: if word("measure", "midpoint") == "corners" {
                ShearMeasure::Corners
            } else {
                ShearMeasure::Midpoint
            },
            ..atelier_solver::ShearParams::default()
        },
        bending: atelier_solver::BendingParams {
            deadband: get("bband", 0.05),
            stick_slope: get("stick_slope", 4.0),
            off: get("bending_off", 0.0) != 0.0,
            implicit_stick_slope: get("stick", 0.0) != 0.0,
            steepest_slope: get("steepest", 0.0) != 0.0,
            spindle_rows: get("spindle_rows", 0.0) != 0.0,
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
    // `drift=s`: after the run, s seconds more, and where the remaining motion is: each node's
    // velocity in cylindrical components about the support's axis (RMS radial, tangential,
    // vertical; the mean angular velocity), the RMS speed per ring, and the displacement over
    // the interval against the speed times the interval (a steady drift moves by about that,
    // an oscillation by much less).
    let drift = get("drift", 0.0);
    if drift > 0.0 {
        let start = state.positions.clone();
        let steps = (drift / input.dt).round() as usize;
        let mut before = [state.positions.clone(), state.positions.clone()];
        let mut rms_step = Vec::new();
        for k in 0..steps {
            before = [before[1].clone(), state.positions.clone()];
            let report = solver
                .step(&cloth, &mut state, &params, input)
                .expect("drift step");
            let moved = |from: &[nalgebra::Vector3<f64>]| {
                let s: f64 = state
                    .positions
                    .iter()
                    .zip(from)
                    .map(|(x, y)| (x - y).norm_squared())
                    .sum();
                (s / from.len() as f64).sqrt()
            };
            if k + 4 >= steps {
                rms_step.push(format!(
                    "t {:.2}: RMS |Δx| over one step {:.2e} m, over two {:.2e} m, RMS v·Δt {:.2e} m, shape its {}, bending its {}",
                    state.time,
                    moved(&before[1]),
                    moved(&before[0]),
                    input.dt
                        * (state.velocities.iter().map(|v| v.norm_squared()).sum::<f64>()
                            / state.velocities.len() as f64)
                            .sqrt(),
                    report.shape_iterations,
                    report.bending_iterations
                ));
            }
        }
        for line in &rms_step {
            println!("  {line}");
        }
        let axis = nalgebra::Vector3::new(0.0, 0.0, 1.0);
        let (mut vr, mut vt, mut vz, mut w, mut n) = (0.0, 0.0, 0.0, 0.0, 0usize);
        let (mut dsum, mut dtheta) = (0.0, 0.0);
        let rings = scene.n_rings;
        let mut per_ring = vec![(0.0, 0usize); rings + 1];
        for (i, (x, v)) in state.positions.iter().zip(&state.velocities).enumerate() {
            let radial = nalgebra::Vector3::new(x.x, x.y, 0.0);
            let r = radial.norm();
            if r < 1e-6 || v.norm() == 0.0 {
                continue;
            }
            let er = radial / r;
            let et = axis.cross(&er);
            vr += v.dot(&er).powi(2);
            vt += v.dot(&et).powi(2);
            vz += v.z.powi(2);
            w += v.dot(&et) / r;
            n += 1;
            let d = x - start[i];
            dsum += d.norm_squared();
            let a0 = start[i].y.atan2(start[i].x);
            let a1 = x.y.atan2(x.x);
            let mut da = a1 - a0;
            if da > std::f64::consts::PI {
                da -= 2.0 * std::f64::consts::PI;
            } else if da < -std::f64::consts::PI {
                da += 2.0 * std::f64::consts::PI;
            }
            dtheta += da;
            let k = (i / scene.n_around).min(rings);
            per_ring[k].0 += v.norm_squared();
            per_ring[k].1 += 1;
        }
        let nf = n.max(1) as f64;
        let rms = ((vr + vt + vz) / nf).sqrt();
        println!(
            "drift {drift} s: moving nodes {n}; RMS speed {:.2e} m/s (radial {:.2e}, tangential {:.2e}, vertical {:.2e}); mean angular velocity {:.2e} rad/s; mean turn over the interval {:.2e} rad; RMS displacement {:.2e} m against RMS speed × interval {:.2e} m",
            rms,
            (vr / nf).sqrt(),
            (vt / nf).sqrt(),
            (vz / nf).sqrt(),
            w / nf,
            dtheta / nf,
            (dsum / nf).sqrt(),
            rms * drift
        );
        let rows: Vec<String> = per_ring
            .iter()
            .enumerate()
            .filter(|(_, (_, c))| *c > 0)
            .map(|(k, (s, c))| format!("{k}:{:.1e}", (s / *c as f64).sqrt()))
            .collect();
        println!("  RMS speed by ring (m/s): {}", rows.join(" "));
        let m = scene.measure(&cloth, &state);
        println!(
            "  after the drift: DC {:.1} % nodes {}",
            m.drape_coefficient, m.nodes
        );
    }
}
