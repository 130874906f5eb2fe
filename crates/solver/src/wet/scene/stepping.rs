//! The run itself: the cloth stepped on Yamada's model or the PARTY step, sampled into a
//! [`WetRun`], stopping at a failed step with the last good state; and the search for the largest
//! stable time step.

use std::time::{Duration, Instant};

use atelier_fabric::Fabric;
use atelier_grid::EdgeKind;

use crate::baselines::{MassSpring, MassSpringParams, spring_stiffnesses};
use crate::cloth::Cloth;
use crate::params::{StepInput, StepParams};
use crate::state::ClothState;
use crate::step::{SolveStats, Solver};
use crate::wet::contact::{PlaneHook, YamadaExtras};
use crate::wet::pressure::ATMOSPHERE;
use crate::wet::volume::{Plane, plane_volume};

use super::{LIFTED, Springs, V3, WetError, WetFailure, WetRun, WetSample, WetScene, WetSolver};

/// Yamada's spring stiffness for every edge of `cloth`, N/m.
pub fn yamada_springs(cloth: &Cloth, springs: Springs) -> Vec<f64> {
    match springs {
        Springs::FromFabric { fraction } => spring_stiffnesses(cloth, fraction),
        Springs::Given { structural, shear } => cloth
            .topology()
            .edges()
            .iter()
            .map(|e| {
                if e.kind == EdgeKind::Diagonal {
                    shear
                } else {
                    structural
                }
            })
            .collect(),
    }
}

/// The largest |l/l⁰ − 1| over the axial edges.
fn max_axial_strain(cloth: &Cloth, positions: &[V3]) -> f64 {
    cloth
        .topology()
        .edges()
        .iter()
        .filter(|e| e.kind.is_axial())
        .map(|e| {
            ((positions[e.b as usize] - positions[e.a as usize]).norm() / e.rest_length - 1.0).abs()
        })
        .fold(0.0, f64::max)
}

/// Run `scene` with `fabric` on `solver`. A failed step ends the run early with its
/// [`WetFailure`] and the last good state; bad parameters are an error before anything runs.
pub fn run(scene: &WetScene, fabric: &Fabric, solver: &WetSolver) -> Result<WetRun, WetError> {
    let t_setup = Instant::now();
    let (mut cloth, mut state) = scene.build(fabric)?;
    let contact = scene.contact(fabric);
    let stage = scene.pressure_stage(&cloth);
    let dt = solver.dt();
    match solver {
        WetSolver::Yamada(p) => {
            if !(p.damping >= 0.0 && p.damping <= 1000.0) {
                return Err(WetError::Range {
                    field: "yamada.damping",
                    value: p.damping.to_string(),
                    range: "[0, 1000]",
                });
            }
            MassSpringParams {
                damping: p.damping,
                ..MassSpringParams::default()
            }
            .validate()?;
        }
        WetSolver::Party(p) => p.step.validate()?,
    }
    // The scene's frame has z up.
    let input = StepInput::new(dt);
    input.validate()?;
    let picked: Vec<u32> = scene.picks.iter().map(|p| scene.node_at(p.at)).collect();
    let mut releases: Vec<(f64, u32)> = scene
        .picks
        .iter()
        .zip(&picked)
        .filter_map(|(p, &node)| p.release.map(|t| (t, node)))
        .collect();
    releases.sort_by(|a, b| a.0.total_cmp(&b.0));
    let steps = (scene.duration / dt).round().max(1.0) as usize;
    let triangles = cloth.topology().triangles().to_vec();
    let rest_positions = cloth.topology().rest_positions().to_vec();

    // The two solvers behind one `step` closure.
    enum Engine {
        Yamada {
            solver: Box<MassSpring>,
            params: MassSpringParams,
            extras: Box<YamadaExtras>,
        },
        Party {
            solver: Box<Solver>,
            params: StepParams,
            hook: PlaneHook,
        },
    }
    let mut engine = match solver {
        WetSolver::Yamada(p) => Engine::Yamada {
            solver: Box::new(MassSpring::with_stiffness(yamada_springs(
                &cloth, p.springs,
            ))),
            params: MassSpringParams {
                damping: p.damping,
                ..MassSpringParams::default()
            },
            extras: Box::new(YamadaExtras::new(Some(contact), stage)),
        },
        WetSolver::Party(p) => {
            let mut s = Box::new(Solver::new());
            s.pressure = stage;
            Engine::Party {
                solver: s,
                params: p.step.clone(),
                hook: PlaneHook { contact },
            }
        }
    };
    let setup = t_setup.elapsed();

    let sample = |cloth: &Cloth, state: &ClothState, engine: &Engine| -> WetSample {
        let report = match engine {
            Engine::Yamada { extras, .. } => extras.pressure.as_ref(),
            Engine::Party { solver, .. } => solver.pressure.as_ref(),
        }
        .filter(|p| p.model().evaluated())
        .map(|p| p.report());
        let pos = &state.positions;
        let plane = Plane::horizontal(0.0);
        let lifted_area = triangles
            .iter()
            .filter(|t| {
                t.iter()
                    .any(|&k| plane.height(&pos[k as usize]) - scene.rest > LIFTED)
            })
            .map(|t| {
                let [a, b, c] = t.map(|k| pos[k as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum();
        WetSample {
            time: state.time,
            volume: plane_volume(pos, &triangles, &plane, scene.rest),
            pressure: report.map(|r| r.pressure),
            bubbles: report.map_or(0, |r| r.bubbles.len()),
            air: report.map(|r| r.bubbles.iter().map(|b| b.air).sum::<f64>() / ATMOSPHERE),
            pressure_range: report.and_then(|r| {
                r.bubbles
                    .iter()
                    .filter(|b| !b.vented)
                    .map(|b| b.pressure)
                    .fold(None, |acc: Option<[f64; 2]>, p| {
                        Some(acc.map_or([p, p], |[lo, hi]| [lo.min(p), hi.max(p)]))
                    })
            }),
            lifted_area,
            tent_height: pos
                .iter()
                .enumerate()
                .filter(|&(i, _)| !cloth.is_pinned(i))
                .map(|(_, p)| plane.height(p) - scene.rest)
                .fold(0.0, f64::max),
            max_strain: max_axial_strain(cloth, pos),
            max_speed: state
                .velocities
                .iter()
                .map(|v| v.norm())
                .fold(0.0, f64::max),
        }
    };

    let mut samples = vec![sample(&cloth, &state, &engine)];
    let mut next_sample = scene.sample_interval;
    let mut frames = Vec::new();
    let mut next_frame = 0.0;
    if scene.frame_interval.is_some() {
        frames.push((state.time, state.positions.clone()));
        next_frame = scene.frame_interval.unwrap_or(f64::INFINITY);
    }
    let (mut wall, mut pressure_wall) = (Duration::ZERO, Duration::ZERO);
    let mut failure = None;
    let mut taken = 0;
    let mut stats = match solver {
        WetSolver::Yamada(_) => None,
        WetSolver::Party(_) => Some(SolveStats::default()),
    };
    for _ in 0..steps {
        while let Some(&(t, node)) = releases.first() {
            if t > state.time + 0.5 * dt {
                break;
            }
            cloth.unpin(node)?;
            if let Engine::Party { solver, .. } = &mut engine {
                solver.reset();
            }
            releases.remove(0);
        }
        let t0 = Instant::now();
        let result = match &mut engine {
            Engine::Yamada {
                solver,
                params,
                extras,
            } => solver
                .step_with_extras(&cloth, &mut state, params, input, extras.as_mut())
                .map(|_| ()),
            Engine::Party {
                solver,
                params,
                hook,
            } => {
                let start = state.time;
                solver
                    .step_with(&cloth, &mut state, params, input, hook)
                    .map(|r| {
                        pressure_wall += r.timings.pressure;
                        if let Some(s) = stats.as_mut() {
                            s.add(&r, params, start);
                        }
                    })
            }
        };
        wall += t0.elapsed();
        if let Err(error) = result {
            failure = Some(WetFailure {
                time: state.time,
                error,
            });
            break;
        }
        taken += 1;
        if state.time >= next_sample - 0.5 * dt {
            samples.push(sample(&cloth, &state, &engine));
            next_sample += scene.sample_interval;
        }
        if let Some(f) = scene.frame_interval
            && state.time >= next_frame - 0.5 * dt
        {
            frames.push((state.time, state.positions.clone()));
            next_frame += f;
        }
    }
    if samples.last().map(|s| s.time) != Some(state.time) {
        samples.push(sample(&cloth, &state, &engine));
    }
    if let Engine::Yamada { extras, .. } = &engine {
        pressure_wall = extras.pressure_time;
    }
    let bubbles = match &engine {
        Engine::Yamada { extras, .. } => extras.pressure.as_ref(),
        Engine::Party { solver, .. } => solver.pressure.as_ref(),
    }
    .map(|p| p.report().bubbles.clone())
    .unwrap_or_default();
    if scene.frame_interval.is_some() && frames.last().map(|f| f.0) != Some(state.time) {
        frames.push((state.time, state.positions.clone()));
    }
    Ok(WetRun {
        solver: solver.name(),
        dt,
        steps: taken,
        time: state.time,
        wall,
        pressure_wall,
        setup,
        samples,
        positions: state.positions,
        rest: rest_positions,
        triangles,
        particles: scene.particles,
        picked,
        bubbles,
        frames,
        failure,
        stats,
    })
}

/// The largest Δt in `[lo, hi]` at which `scene` runs to its end on `solver` (with that Δt)
/// without a failed step and with no node ever faster than `max_speed` (m/s)
/// ([`largest_dt_where`]).
pub fn largest_stable_dt(
    scene: &WetScene,
    fabric: &Fabric,
    solver: &WetSolver,
    range: (f64, f64),
    halvings: usize,
    max_speed: f64,
) -> Result<Option<f64>, WetError> {
    largest_dt_where(scene, fabric, solver, range, halvings, &|r: &WetRun| {
        r.failure.is_none() && r.samples.iter().all(|s| s.max_speed <= max_speed)
    })
}

/// The largest Δt in `[lo, hi]` whose run of `scene` on `solver` (with that Δt) `accept`s:
/// bisection on a log scale, `halvings` times (the answer lies within a factor
/// `(hi/lo)^(1/2^halvings)` below the boundary found); `Some(hi)` when `hi` is accepted, `None`
/// when `lo` is not. Acceptance need not be monotonic in Δt; this finds one boundary.
pub fn largest_dt_where(
    scene: &WetScene,
    fabric: &Fabric,
    solver: &WetSolver,
    (lo, hi): (f64, f64),
    halvings: usize,
    accept: &dyn Fn(&WetRun) -> bool,
) -> Result<Option<f64>, WetError> {
    let ok = |dt: f64| -> Result<bool, WetError> {
        Ok(accept(&run(scene, fabric, &solver.with_dt(dt))?))
    };
    if ok(hi)? {
        return Ok(Some(hi));
    }
    if !ok(lo)? {
        return Ok(None);
    }
    let (mut a, mut b) = (lo.ln(), hi.ln());
    for _ in 0..halvings {
        let m = 0.5 * (a + b);
        if ok(m.exp())? {
            a = m;
        } else {
            b = m;
        }
    }
    Ok(Some(a.exp()))
}
