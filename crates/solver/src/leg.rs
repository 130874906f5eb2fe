//! The collision validation scene of the thesis's claim (§5.4–5.6): a cloth tube hanging around
//! a rigid leg that swings like a pendulum. With the physical collision model alone, a step of
//! 0.01 s lets cloth nodes into the leg; the staged model (transfer of the leg's motion, then
//! physical collision) lets none in; the physical model alone needs a step about ten times
//! smaller.
//!
//! The leg is a closed capsule-like cylinder (radius 6 cm, 80 cm long) hanging from a hip pivot
//! at the origin along −y and swinging about the x axis, `θ(t) = A sin 2πft`. The tube is a sheet
//! wrapped around it at radius 10 cm with a one-cell gap at the side (the topology has no
//! periodic rest layout for a cylinder), its top row held on the circle at the pivot's height.

use std::f64::consts::PI;
use std::time::{Duration, Instant};

use atelier_collide::distance::BodyDistance;
use atelier_collide::shapes::cylinder;
use atelier_collide::{ContactParams, V3};
use atelier_fabric::Fabric;
use atelier_grid::{ClothTopology, StructuredGrid};

use crate::cloth::{Cloth, ClothOptions, PinMotion};
use crate::contact::BodyContact;
use crate::params::{StepInput, StepParams};
use crate::scenes::SceneError;
use crate::state::ClothState;
use crate::step::{Solver, StepError};

/// The scene's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegScene {
    /// Time step, s.
    pub dt: f64,
    /// Simulated time, s.
    pub duration: f64,
    /// Swing amplitude, rad.
    pub amplitude: f64,
    /// Swing frequency, Hz.
    pub frequency: f64,
    /// Leg radius, m.
    pub leg_radius: f64,
    /// Leg length below the pivot, m.
    pub leg_length: f64,
    /// Tube radius, m.
    pub tube_radius: f64,
    /// Tube length, m.
    pub tube_length: f64,
    /// Grid spacing of the tube, m.
    pub spacing: f64,
    /// Contact parameters (staged or physical only, friction, restitution…).
    pub contact: ContactParams,
    /// Depth below which a node counts as inside the leg, m.
    pub tolerance: f64,
}

impl Default for LegScene {
    fn default() -> Self {
        Self {
            dt: 0.01,
            duration: 2.0,
            amplitude: 30f64.to_radians(),
            frequency: 1.0,
            leg_radius: 0.06,
            leg_length: 0.8,
            tube_radius: 0.1,
            tube_length: 0.6,
            spacing: 0.025,
            contact: ContactParams::default(),
            tolerance: 2e-3,
        }
    }
}

/// What the run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct LegRun {
    /// Steps taken.
    pub steps: usize,
    /// Cloth nodes.
    pub nodes: usize,
    /// Leg triangles.
    pub leg_triangles: usize,
    /// Steps after which at least one node was inside the leg deeper than the tolerance.
    pub frames_with_penetration: usize,
    /// The most nodes inside at once.
    pub max_inside: usize,
    /// The deepest penetration, m.
    pub max_depth: f64,
    /// Wall time of the steps (collision included, measurement excluded).
    pub wall: Duration,
    /// Wall time of the collision hook (transfer and passes).
    pub collision: Duration,
    /// Node–leg contacts, over all passes and steps: continuous-test hits plus nodes held by a
    /// contact plane (within `plane_reach` of the leg at the start of a step).
    pub contacts: usize,
    /// Node transfers of the leg's motion, over all steps.
    pub transfers: usize,
    /// Steps that missed their tolerance (`StepReport::converged` false).
    pub unconverged: usize,
}

fn rotate_x(p: &V3, theta: f64) -> V3 {
    let (c, s) = (theta.cos(), theta.sin());
    V3::new(p.x, c * p.y - s * p.z, s * p.y + c * p.z)
}

/// Run the scene with `fabric`; the step parameters are the defaults with the scene's Δt and
/// gravity along −y.
pub fn run_leg(scene: &LegScene, fabric: &Fabric) -> Result<LegRun, LegError> {
    let circumference = 2.0 * PI * scene.tube_radius;
    let nu = (circumference / scene.spacing).round() as usize; // one cell short: the gap
    let nv = (scene.tube_length / scene.spacing).round() as usize + 1;
    let width = (nu - 1) as f64 * scene.spacing;
    let grid = StructuredGrid::sheet(nu, nv, width, scene.tube_length);
    let topo = ClothTopology::from_structured(&grid).map_err(SceneError::from)?;
    let mut cloth =
        Cloth::with_options(topo, fabric, ClothOptions::default()).map_err(SceneError::from)?;
    // Wrap: u runs around the leg starting half a gap past the +x side; v runs down from the
    // pivot's height (v = 0 at the bottom of the sheet).
    let (r, len) = (scene.tube_radius, scene.tube_length);
    let gap = circumference - width;
    let place = move |[x, y]: [f64; 2]| {
        let a = PI / 2.0 + 0.5 * gap / r + x / r;
        V3::new(r * a.sin(), y - len, r * a.cos())
    };
    for i in 0..nu {
        let node = ((nv - 1) * nu + i) as u32;
        let p = place(cloth.topology().rest_positions()[node as usize]);
        cloth
            .pin(node, p, PinMotion::Fixed)
            .map_err(SceneError::from)?;
    }
    let mut state = ClothState::placed(&cloth, place);
    let (leg, tris) = cylinder(scene.leg_radius, scene.leg_length, 24, 17);
    let mut contact = BodyContact::new(&cloth, scene.contact)?;
    let mut distance = BodyDistance::new(&leg, &tris)?;
    // The body frame has y up.
    let params = StepParams::default();
    let input = StepInput {
        dt: scene.dt,
        gravity: [0.0, -atelier_fabric::STANDARD_GRAVITY, 0.0],
    };
    let mut solver = Solver::new();
    let steps = (scene.duration / scene.dt).round() as usize;
    let angle = |t: f64| scene.amplitude * (2.0 * PI * scene.frequency * t).sin();
    let mut run = LegRun {
        steps,
        nodes: cloth.topology().node_count(),
        leg_triangles: tris.len(),
        frames_with_penetration: 0,
        max_inside: 0,
        max_depth: 0.0,
        wall: Duration::ZERO,
        collision: Duration::ZERO,
        contacts: 0,
        transfers: 0,
        unconverged: 0,
    };
    let (mut start, mut end) = (leg.clone(), leg.clone());
    for k in 0..steps {
        let t = k as f64 * scene.dt;
        let (a0, a1) = (angle(t), angle(t + scene.dt));
        for ((s, e), p) in start.iter_mut().zip(end.iter_mut()).zip(&leg) {
            *s = rotate_x(p, a0);
            *e = rotate_x(p, a1);
        }
        let t0 = Instant::now();
        contact.set_body(&start, &end, &tris, scene.dt)?;
        let report = solver.step_with(&cloth, &mut state, &params, input, &mut contact)?;
        run.wall += t0.elapsed();
        run.collision += report.timings.collision + report.timings.transfer;
        run.unconverged += usize::from(!report.converged);
        let stats = contact.take_stats();
        run.contacts += stats.body_hits + stats.planes;
        run.transfers += stats.transferred;
        distance.update(&end)?;
        let pen = distance.penetrations(&state.positions, scene.tolerance);
        if pen.count > 0 {
            run.frames_with_penetration += 1;
            run.max_inside = run.max_inside.max(pen.count);
            run.max_depth = run.max_depth.max(pen.max_depth);
        }
    }
    Ok(run)
}

/// Why the leg scene stopped.
#[derive(Debug, thiserror::Error)]
pub enum LegError {
    /// Building the tube.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Contact parameters or the leg.
    #[error(transparent)]
    Contact(#[from] atelier_collide::ContactError),
    /// The leg mesh for the distance measure.
    #[error(transparent)]
    Mesh(#[from] atelier_collide::distance::MeshError),
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
}
