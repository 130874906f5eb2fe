//! The validation scenes run by the runner: the drape testers, the cantilever, the catenary and
//! the virtual KES tensile and bending tests, each stepped to its end into a [`Simulated`].

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::scenes::{DrapeScene, RestCriterion, RestWatch, rms_speed};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepInput, StepParams};
use nalgebra::Vector3;

use super::to_y_up;
use crate::convergence::{Convergence, Tally, solvers};
use crate::export::Animation;
use crate::outcome::{ClothDetail, DrapeTop, KindOutputs, RunError, Simulated, Solid};
use crate::scenario::{
    CantileverSpec, CatenarySpec, DrapeSpec, KesBendingSpec, KesTensileSpec, StripDirection, Tester,
};
use crate::simulation::Timings;

/// A stepping loop shared by the validation scenes: steps `state` until `done` says so (or a
/// step fails), records a frame every `interval` and keeps the last good positions.
struct Stepper {
    frames: Animation,
    interval: f64,
    next_frame: f64,
    steps: usize,
    wall: Duration,
    timings: Timings,
    max_strain_error: f64,
    max_speed: f64,
    failure: Option<String>,
    last_good: Vec<Vector3<f64>>,
    tally: Tally,
    /// The shape tolerance of the steps.
    tolerance: f64,
    /// Per recorded frame, each node's largest strain error (the viewer's colours).
    strain: Vec<Vec<f32>>,
}

impl Stepper {
    fn new(state: &ClothState, interval: f64) -> Self {
        let mut frames = Animation::default();
        frames.push(state.time, state.positions.iter().map(to_y_up).collect());
        Self {
            frames,
            interval,
            next_frame: state.time + interval,
            steps: 0,
            wall: Duration::ZERO,
            timings: Timings::default(),
            max_strain_error: 0.0,
            max_speed: 0.0,
            failure: None,
            last_good: state.positions.clone(),
            tally: Tally::default(),
            tolerance: StepParams::default().shape.tolerance,
            strain: Vec::new(),
        }
    }

    /// One step; false when it failed (the state is then restored to the last good positions).
    fn step(
        &mut self,
        solver: &mut Solver,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
        input: StepInput,
    ) -> bool {
        self.last_good.copy_from_slice(&state.positions);
        if self.strain.is_empty() {
            // The first frame, before any step: against the rest lengths.
            self.strain
                .push(solver.node_strain_errors(cloth, state, params));
        }
        let t = state.time;
        let clock = Instant::now();
        let result = solver.step(cloth, state, params, input);
        self.wall += clock.elapsed();
        match result {
            Ok(r) => {
                self.steps += 1;
                self.tally.add(&r, t, None);
                self.tolerance = params.shape.tolerance;
                self.timings.add(&Timings {
                    solver: r.timings,
                    ..Timings::default()
                });
                self.max_strain_error = self.max_strain_error.max(r.max_strain_error);
                self.max_speed = r.max_speed;
                if state.time + 1e-9 * input.dt >= self.next_frame {
                    self.frames
                        .push(state.time, state.positions.iter().map(to_y_up).collect());
                    self.strain
                        .push(solver.node_strain_errors(cloth, state, params));
                    self.next_frame += self.interval;
                }
                true
            }
            Err(e) => {
                self.failure = Some(format!("step at time {t:.4} s: {e}"));
                state.positions.copy_from_slice(&self.last_good);
                state.time = t;
                false
            }
        }
    }

    /// Record the final state unless it is the last frame already.
    fn finish(&mut self, solver: &Solver, cloth: &Cloth, state: &ClothState, params: &StepParams) {
        if self
            .frames
            .times
            .last()
            .is_none_or(|&t| state.time > t + 1e-12)
        {
            self.frames
                .push(state.time, state.positions.iter().map(to_y_up).collect());
            self.strain
                .push(solver.node_strain_errors(cloth, state, params));
        }
    }

    fn into_simulated(
        self,
        cloth: &Cloth,
        state: &ClothState,
        dt: f64,
        solid: Option<Solid>,
        mut metrics: BTreeMap<String, Option<f64>>,
    ) -> Simulated {
        metrics.insert("max_strain_error".into(), Some(self.max_strain_error));
        let ke = if self.failure.is_some() {
            None
        } else {
            Some(state.kinetic_energy(cloth))
        };
        metrics.insert("kinetic_energy_j".into(), ke);
        // Complete only when every frame has its values (a run of no step has none).
        let strain = if self.strain.len() == self.frames.frames.len() {
            self.strain
        } else {
            Vec::new()
        };
        Simulated {
            fabric: String::new(),
            cloth_triangles: cloth.topology().triangles().to_vec(),
            cloth: self.frames,
            solid,
            steps: self.steps,
            dt,
            simulated: state.time,
            wall_seconds: self.wall.as_secs_f64(),
            timings: self.timings,
            metrics,
            warnings: Vec::new(),
            failure: self.failure,
            outputs: KindOutputs::Cloth,
            convergence: Some(self.tally.convergence(self.tolerance)),
            detail: ClothDetail {
                strain_error: strain,
                ..ClothDetail::default()
            },
        }
    }
}

pub(super) fn drape(
    spec: &DrapeSpec,
    fabric: &Fabric,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let (preset, dt) = match spec.tester {
        Tester::Jis => (DrapeScene::jis(72, 8), 1e-3),
        Tester::Thesis => (DrapeScene::thesis(), 2.5e-3),
    };
    let mut scene = DrapeScene {
        n_around: spec.n_around.unwrap_or(preset.n_around),
        n_rings: spec.n_rings.unwrap_or(preset.n_rings),
        perturbation: spec.perturbation,
        seed: spec.seed,
        ..preset
    };
    scene.cloth_options.form = spec.form;
    let (cloth, mut state) = scene
        .build(fabric)
        .map_err(RunError::setup("drape scene"))?;
    let (params, input) = (spec.step.clone(), StepInput::new(spec.dt.unwrap_or(dt)));
    params.validate().map_err(RunError::setup("drape scene"))?;
    input.validate().map_err(RunError::setup("drape scene"))?;
    // The rest criterion of `run_drape` (RestCriterion::default()).
    let mut watch = RestWatch::new(RestCriterion::default(), input.dt);
    let eps = 1e-9 * input.dt;
    let mut stepper = Stepper::new(&state, spec.frame_interval);
    let mut solver = Solver::new();
    let mut settled = false;
    while state.time < spec.max_time - eps {
        if !stepper.step(&mut solver, &cloth, &mut state, &params, input) {
            break;
        }
        progress(state.time / spec.max_time);
        if spec.until_rest && watch.at_rest(state.time, rms_speed(&cloth, &state)) {
            settled = true;
            break;
        }
    }
    stepper.finish(&solver, &cloth, &state, &params);
    let mut metrics = BTreeMap::new();
    let ok = stepper.failure.is_none();
    let m = scene.measure(&cloth, &state);
    let mut put = |k: &str, v: f64| {
        metrics.insert(k.to_string(), ok.then_some(v));
    };
    put("drape_coefficient_percent", m.drape_coefficient);
    put("node_count", m.nodes as f64);
    put("shadow_area_m2", m.shadow_area);
    put("settled", if settled { 1.0 } else { 0.0 });
    put("rms_speed_m_s", rms_speed(&cloth, &state));
    put("min_edge_radius_m", m.min_edge_radius);
    put("max_edge_radius_m", m.max_edge_radius);
    let mut warnings = Vec::new();
    if spec.until_rest && !settled && ok {
        warnings.push(format!(
            "not at rest after {:.2} s: measured at the time cap",
            spec.max_time
        ));
    }
    let support = support_stand(
        scene.support_radius(),
        1.2 * (scene.specimen_radius() - scene.support_radius()),
    );
    let mut sim = stepper.into_simulated(&cloth, &state, input.dt, Some(support), metrics);
    sim.warnings.extend(warnings);
    if ok {
        // In the outputs' y-up frame the horizontal plane is (x, z) = (x, −y) of the z-up scene.
        let flat = |p: &Vector3<f64>| [p.x, -p.y];
        let ring = &state.positions[scene.outer_ring()];
        sim.outputs = KindOutputs::Drape(DrapeTop {
            outline_m: ring.iter().map(flat).collect(),
            node_points_m: m.folds.iter().map(|f| flat(&ring[f.index])).collect(),
            support_radius_m: scene.support_radius(),
            specimen_radius_m: scene.specimen_radius(),
        });
    }
    Ok(sim)
}

/// The drape tester's support: a closed cylinder of the support's radius and height `depth`
/// under the specimen, top at z = 0 (y-up frame in the outputs).
fn support_stand(radius: f64, depth: f64) -> Solid {
    let n = 48;
    let mut v: Vec<[f64; 3]> = Vec::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        let (x, y) = (radius * a.cos(), radius * a.sin());
        v.push(to_y_up(&Vector3::new(x, y, 0.0)));
        v.push(to_y_up(&Vector3::new(x, y, -depth)));
    }
    let top = v.len() as u32;
    v.push(to_y_up(&Vector3::new(0.0, 0.0, 0.0)));
    let bottom = top + 1;
    v.push(to_y_up(&Vector3::new(0.0, 0.0, -depth)));
    let mut t = Vec::new();
    for k in 0..n as u32 {
        let j = (k + 1) % n as u32;
        let (a0, a1, b0, b1) = (2 * k, 2 * k + 1, 2 * j, 2 * j + 1);
        // In the z-up frame counter-clockwise about +z; the map to y up is a rotation.
        t.push([a0, a1, b1]);
        t.push([a0, b1, b0]);
        t.push([top, a0, b0]);
        t.push([bottom, b1, a1]);
    }
    Solid {
        name: "support",
        triangles: t,
        motion: Animation::still(v),
    }
}

/// An axis-aligned box (z-up frame), outward triangles.
fn block(lo: [f64; 3], hi: [f64; 3], name: &'static str) -> Solid {
    let mut v = Vec::new();
    for k in 0..8 {
        let p = Vector3::new(
            if k & 1 == 0 { lo[0] } else { hi[0] },
            if k & 2 == 0 { lo[1] } else { hi[1] },
            if k & 4 == 0 { lo[2] } else { hi[2] },
        );
        v.push(to_y_up(&p));
    }
    // Faces as quads (outward, counter-clockwise seen from outside).
    let quads = [
        [0, 2, 3, 1], // z lo
        [4, 5, 7, 6], // z hi
        [0, 1, 5, 4], // y lo
        [2, 6, 7, 3], // y hi
        [0, 4, 6, 2], // x lo
        [1, 3, 7, 5], // x hi
    ];
    let mut t = Vec::new();
    for q in quads {
        t.push([q[0], q[1], q[2]]);
        t.push([q[0], q[2], q[3]]);
    }
    Solid {
        name,
        triangles: t,
        motion: Animation::still(v),
    }
}

/// The Peirce cantilever: the strip of `segments` cells along its direction, two nodes (1 cm)
/// wide, clamped by two rows of pinned nodes at ±h/2 about the platform edge x = 0, its tip at
/// x = overhang; run until every node is slower than 5 mm/s after 1.5 s (or the time cap).
/// The chord angle from the edge to the tip is compared with the elastica's 41.5° (exact at the
/// default overhang 2.0003·c).
pub(super) fn cantilever(
    spec: &CantileverSpec,
    fabric: &Fabric,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let rigidity = match spec.direction {
        StripDirection::Warp => fabric.bending.warp.rigidity(),
        StripDirection::Weft => fabric.bending.weft.rigidity(),
    };
    let c = (rigidity / fabric.weight_per_area()).cbrt();
    let length = spec.overhang.unwrap_or(2.0003 * c);
    let segments = spec.segments;
    let h = length / (segments as f64 + 0.5);
    let width = 0.01;
    let nv = segments + 2;
    let mut grid = StructuredGrid::sheet(2, nv, width, (nv - 1) as f64 * h);
    if spec.direction == StripDirection::Weft {
        // Warp across the strip (along pattern x): the strip runs along the weft.
        grid.grain_angle = 0.0;
    }
    const SCENE: &str = "cantilever";
    let topo = ClothTopology::from_structured(&grid).map_err(RunError::setup(SCENE))?;
    let mut cloth =
        Cloth::new(topo, fabric, AnisotropyForm::Thesis).map_err(RunError::setup(SCENE))?;
    let place = |[x, y]: [f64; 2]| Vector3::new(y - 0.5 * h, x, 0.0);
    for node in 0..4 {
        let p = place(cloth.topology().rest_positions()[node]);
        cloth
            .pin(node as u32, p, PinMotion::Fixed)
            .map_err(RunError::setup(SCENE))?;
    }
    let mut state = ClothState::placed(&cloth, place);
    // Implicit bending keeps this stable up to about 0.4·h s/m; 0.25·h leaves a margin.
    let params = StepParams {
        damping: spec.damping,
        hysteresis: spec.hysteresis,
        ..StepParams::default()
    };
    let input = StepInput::new(0.25 * h);
    params.validate().map_err(RunError::setup(SCENE))?;
    input.validate().map_err(RunError::setup(SCENE))?;
    let mut stepper = Stepper::new(&state, spec.frame_interval);
    let mut solver = Solver::new();
    let mut at_rest = false;
    while state.time < spec.max_time {
        if !stepper.step(&mut solver, &cloth, &mut state, &params, input) {
            break;
        }
        progress(state.time / spec.max_time);
        if state.time > 1.5 && stepper.max_speed < 5e-3 {
            at_rest = true;
            break;
        }
    }
    stepper.finish(&solver, &cloth, &state, &params);
    let tip = (state.positions[2 * (nv - 1)] + state.positions[2 * (nv - 1) + 1]) * 0.5;
    let angle = (-tip.z).atan2(tip.x).to_degrees();
    let ok = stepper.failure.is_none();
    let mut metrics = BTreeMap::new();
    metrics.insert("bending_length_m".into(), Some(c));
    metrics.insert("overhang_m".into(), Some(length));
    metrics.insert("chord_angle_deg".into(), ok.then_some(angle));
    let reference = (spec.overhang.is_none()).then_some(41.5);
    metrics.insert(
        "chord_angle_error_deg".into(),
        reference.filter(|_| ok).map(|r| angle - r),
    );
    metrics.insert("tip_droop_m".into(), ok.then_some(-tip.z));
    metrics.insert("max_speed_m_s".into(), ok.then_some(stepper.max_speed));
    let platform = block(
        [-length, -0.01, -0.02],
        [0.0, width + 0.01, 0.0],
        "platform",
    );
    let mut sim = stepper.into_simulated(&cloth, &state, input.dt, Some(platform), metrics);
    if !at_rest && ok {
        sim.warnings.push(format!(
            "not at rest after {:.2} s (fastest node {:.2e} m/s)",
            spec.max_time,
            sim.metrics
                .get("max_speed_m_s")
                .copied()
                .flatten()
                .unwrap_or(f64::NAN)
        ));
    }
    Ok(sim)
}

/// The inextensible catenary with span `d` and length `l`: the parameter a of
/// l = 2a·sinh(d/2a), by bisection.
fn catenary_parameter(d: f64, l: f64) -> f64 {
    let (mut lo, mut hi): (f64, f64) = (1e-4, 1e4);
    for _ in 0..200 {
        let a = (lo * hi).sqrt();
        if 2.0 * a * (d / (2.0 * a)).sinh() > l {
            lo = a
        } else {
            hi = a
        }
    }
    (lo * hi).sqrt()
}

/// A strip two nodes (1 cm) wide hung from both ends, bending off, started on a circular arc of
/// its own length through both supports; compared at the end with the inextensible catenary
/// z = a(cosh(x/a) − cosh(d/2a)).
pub(super) fn catenary(
    spec: &CatenarySpec,
    fabric: &Fabric,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let (length, span, segments) = (spec.length, spec.span, spec.segments);
    const SCENE: &str = "catenary";
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(segments + 1, 2, length, 0.01))
            .map_err(RunError::setup(SCENE))?;
    let mut cloth =
        Cloth::new(topo, fabric, AnisotropyForm::Thesis).map_err(RunError::setup(SCENE))?;
    let a = catenary_parameter(span, length);
    let (mut lo, mut hi) = (1e-6_f64, std::f64::consts::PI - 1e-9);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if span / (2.0 * mid.sin()) * 2.0 * mid > length {
            hi = mid
        } else {
            lo = mid
        }
    }
    let half = 0.5 * (lo + hi);
    let radius = span / (2.0 * half.sin());
    let place = |[x, y]: [f64; 2]| {
        let phi = -half + 2.0 * half * x / length;
        Vector3::new(radius * phi.sin(), y, -radius * (phi.cos() - half.cos()))
    };
    let n_u = segments + 1;
    for j in 0..2 {
        for i in [0, segments] {
            let node = j * n_u + i;
            let p = place(cloth.topology().rest_positions()[node]);
            cloth
                .pin(node as u32, p, PinMotion::Fixed)
                .map_err(RunError::setup(SCENE))?;
        }
    }
    let mut state = ClothState::placed(&cloth, place);
    let input = StepInput::new(spec.dt);
    input.validate().map_err(RunError::setup(SCENE))?;
    let params = StepParams {
        damping: spec.damping,
        bending: atelier_solver::BendingParams {
            off: true,
            ..atelier_solver::BendingParams::default()
        },
        ..StepParams::default()
    };
    params.validate().map_err(RunError::setup(SCENE))?;
    let mut stepper = Stepper::new(&state, spec.frame_interval);
    let mut solver = Solver::new();
    let steps = (spec.duration / spec.dt).round() as usize;
    for _ in 0..steps {
        if !stepper.step(&mut solver, &cloth, &mut state, &params, input) {
            break;
        }
        progress(state.time / spec.duration);
    }
    stepper.finish(&solver, &cloth, &state, &params);
    let ok = stepper.failure.is_none();
    let mut worst: f64 = 0.0;
    for p in &state.positions {
        let exact = a * ((p.x / a).cosh() - (span / (2.0 * a)).cosh());
        worst = worst.max((p.z - exact).abs());
    }
    let sag = -state
        .positions
        .iter()
        .map(|p| p.z)
        .fold(f64::INFINITY, f64::min);
    let mut metrics = BTreeMap::new();
    metrics.insert("catenary_parameter_m".into(), Some(a));
    metrics.insert("max_deviation_m".into(), ok.then_some(worst));
    metrics.insert(
        "max_deviation_percent_span".into(),
        ok.then_some(100.0 * worst / span),
    );
    metrics.insert("sag_m".into(), ok.then_some(sag));
    metrics.insert("max_speed_m_s".into(), ok.then_some(stepper.max_speed));
    Ok(stepper.into_simulated(&cloth, &state, input.dt, None, metrics))
}

/// The two recorded frames of a virtual KES test: the specimen at rest and at the end.
fn kes_frames(start: Vec<[f64; 3]>, end: &ClothState, time: f64) -> Animation {
    let mut a = Animation::default();
    a.push(0.0, start);
    a.push(time, end.positions.iter().map(to_y_up).collect());
    a
}

/// The virtual KES-FB1 tensile test: the specimen's loop 0 → F_m → 0, read from the moving
/// clamp's reaction against its displacement, summarised as EMT, LT, WT and RT and compared
/// with the fabric's own KES values (its loop's summary as loaded: `kes::input_values`). Until
/// issue 23 the reference was the fabric's tensile model stepped along the same path and
/// summarised by the same code as the specimen — the model against itself. The chart still
/// draws the model's loop beside the specimen's.
pub(super) fn kes_tensile(spec: &KesTensileSpec, fabric: &Fabric) -> Result<Simulated, RunError> {
    use atelier_fabric::{TensileState, units};
    use atelier_solver::kes;
    const SCENE: &str = "KES tensile test";
    let path = kes::cycle(units::force_from_kes(spec.max_force_gf_cm), spec.levels);
    let form = AnisotropyForm::Thesis;
    let clock = Instant::now();
    let curve = kes::tensile_test(fabric, form, spec.direction, &path, 3)
        .map_err(RunError::setup(SCENE))?;
    let wall = clock.elapsed().as_secs_f64();
    let input_loop = match spec.direction {
        StripDirection::Warp => &fabric.tensile.warp,
        StripDirection::Weft => &fabric.tensile.weft,
    };
    let mut st = TensileState::VIRGIN;
    let model: Vec<(f64, f64)> = path
        .iter()
        .map(|&f| (f, st.update(input_loop, f)))
        .collect();
    let (sim, input) = (curve.kes_values(), kes::input_values(input_loop));
    let mut metrics = BTreeMap::new();
    let errors = [
        (sim.emt, input.emt),
        (sim.lt, input.lt),
        (sim.wt, input.wt),
        (sim.rt, input.rt),
    ]
    .map(|(a, b)| (a / b - 1.0).abs());
    for (k, v) in [
        ("emt_percent", 100.0 * sim.emt),
        ("input_emt_percent", 100.0 * input.emt),
        ("lt", sim.lt),
        ("input_lt", input.lt),
        ("wt_gf_cm_cm2", units::energy_to_kes(sim.wt)),
        ("input_wt_gf_cm_cm2", units::energy_to_kes(input.wt)),
        ("rt_percent", 100.0 * sim.rt),
        ("input_rt_percent", 100.0 * input.rt),
        (
            "largest_relative_error",
            errors.iter().copied().fold(0.0, f64::max),
        ),
    ] {
        metrics.insert(k.to_string(), Some(v));
    }
    let kes = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> {
        pts.iter()
            .map(|&(f, e)| (100.0 * e, units::force_to_kes(f)))
            .collect()
    };
    let chart = crate::chart::Chart {
        title: format!("KES-FB1 tensile, {} {:?}", fabric.name, spec.direction),
        x_label: "strain (%)".into(),
        y_label: "force per width (gf/cm)".into(),
        series: vec![
            crate::chart::Series {
                name: "the fabric's loop".into(),
                points: std::iter::once((0.0, 0.0)).chain(kes(&model)).collect(),
            },
            crate::chart::Series {
                name: "simulated specimen".into(),
                points: std::iter::once((0.0, 0.0))
                    .chain(kes(&curve.points))
                    .collect(),
            },
        ],
        markers: None,
        equal_aspect: false,
    };
    kes_simulated(
        curve.cloth,
        &curve.state,
        &curve.stats,
        kes::TensileProtocol::default().dt,
        wall,
        metrics,
        chart,
    )
}

/// The virtual KES-FB2 bending test: B and 2HB of the specimen's loop against the fabric's.
pub(super) fn kes_bending(spec: &KesBendingSpec, fabric: &Fabric) -> Result<Simulated, RunError> {
    use atelier_fabric::units;
    use atelier_solver::kes;
    const SCENE: &str = "KES bending test";
    let clock = Instant::now();
    let curve = kes::bending_test(
        fabric,
        AnisotropyForm::Thesis,
        spec.direction,
        spec.steps_per_leg,
    )
    .map_err(RunError::setup(SCENE))?;
    let wall = clock.elapsed().as_secs_f64();
    let spindle = match spec.direction {
        StripDirection::Warp => &fabric.bending.warp,
        StripDirection::Weft => &fabric.bending.weft,
    };
    let (b_in, hb_in) = (spindle.rigidity(), 2.0 * spindle.residual_moment());
    let mut metrics = BTreeMap::new();
    for (k, v) in [
        ("b_gf_cm2_cm", units::rigidity_to_kes(curve.rigidity)),
        ("input_b_gf_cm2_cm", units::rigidity_to_kes(b_in)),
        ("two_hb_gf_cm_cm", units::moment_to_kes(curve.two_hb)),
        ("input_two_hb_gf_cm_cm", units::moment_to_kes(hb_in)),
        (
            "largest_relative_error",
            ((curve.rigidity / b_in - 1.0).abs()).max((curve.two_hb / hb_in - 1.0).abs()),
        ),
    ] {
        metrics.insert(k.to_string(), Some(v));
    }
    // The fabric's own loop along the same curvature path, through its hysteresis state.
    let mut st = atelier_fabric::BendingState::VIRGIN;
    let model: Vec<(f64, f64)> = curve
        .passes
        .iter()
        .flatten()
        .map(|&(eta, _)| (eta, st.update(spindle, eta)))
        .collect();
    let kes_pts = |pts: &mut dyn Iterator<Item = (f64, f64)>| -> Vec<(f64, f64)> {
        pts.map(|(eta, m)| (units::curvature_to_kes(eta), units::moment_to_kes(m)))
            .collect()
    };
    let chart = crate::chart::Chart {
        title: format!("KES-FB2 bending, {} {:?}", fabric.name, spec.direction),
        x_label: "curvature (1/cm)".into(),
        y_label: "moment per width (gf·cm/cm)".into(),
        series: vec![
            crate::chart::Series {
                name: "the fabric's spindle".into(),
                points: kes_pts(&mut model.iter().copied()),
            },
            crate::chart::Series {
                name: "simulated specimen".into(),
                points: kes_pts(&mut curve.passes.iter().flatten().copied()),
            },
        ],
        markers: None,
        equal_aspect: false,
    };
    kes_simulated(
        curve.cloth,
        &curve.state,
        &curve.stats,
        curve.dt,
        wall,
        metrics,
        chart,
    )
}

/// A virtual KES test's outputs: its specimen at the end, its steps (`stats`, counted by the
/// instrument) of `dt`, and its loop as the chart.
fn kes_simulated(
    cloth: Cloth,
    state: &ClothState,
    stats: &atelier_solver::SolveStats,
    dt: f64,
    wall: f64,
    mut metrics: BTreeMap<String, Option<f64>>,
    chart: crate::chart::Chart,
) -> Result<Simulated, RunError> {
    let rest: Vec<[f64; 3]> = cloth
        .topology()
        .rest_positions()
        .iter()
        .map(|&[x, y]| to_y_up(&Vector3::new(x, y, 0.0)))
        .collect();
    metrics.insert(
        "kinetic_energy_j".into(),
        Some(state.kinetic_energy(&cloth)),
    );
    Ok(Simulated {
        fabric: String::new(),
        cloth_triangles: cloth.topology().triangles().to_vec(),
        cloth: kes_frames(rest, state, state.time),
        solid: None,
        steps: stats.steps,
        dt,
        simulated: state.time,
        wall_seconds: wall,
        timings: Timings::default(),
        metrics,
        warnings: Vec::new(),
        failure: None,
        outputs: KindOutputs::Chart(chart),
        convergence: Some(Convergence::from_stats(solvers::PARTY, stats)),
        detail: ClothDetail::default(),
    })
}
