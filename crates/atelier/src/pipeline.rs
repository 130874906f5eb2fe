//! The garment pipeline (thesis §5.5–5.6): a garment's panels gridded, placed around the body,
//! sewn with gravity off, left to settle under gravity, then — with a motion — worn while the
//! body moves. One call runs the whole scene and returns its frames, phases and measurements; a
//! step that fails (divergence, non-finite value) ends the run with the failure recorded and
//! every frame up to the last good state kept.

use std::path::{Path, PathBuf};
use std::time::Instant;

use atelier_body::kinematics::{Body, Posed};
use atelier_body::model::{LabelledMesh, Mannequin};
use atelier_body::motion::{Motion, PoseRate};
use atelier_collide::parts::Motion as PartMotion;
use atelier_collide::{ContactMaterial, ContactParams, RigidParts, V3};
use atelier_fabric::{AnisotropyForm, Fabric, STANDARD_GRAVITY};
use atelier_grid::ImproveParams;
use atelier_grid::pattern::load_garment;
use atelier_solver::{
    BodyContact, ClothState, ConstraintKind, Solver, StageTimings, StepParams, StepReport,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::place::{PlaceParams, Placement, place};
use crate::{Chain, GarmentCloth, Sewing, SewingParams};

/// A garment scene: what to wear, on which body, doing what.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentSpec {
    /// Garment file (RON), relative to the scenario's folder.
    pub garment: PathBuf,
    /// Fabric file (RON), relative to the scenario's folder.
    pub fabric: PathBuf,
    /// One placement per panel, in the garment's panel order.
    pub placements: Vec<Placement>,
    /// Clearance and ease of the placement.
    #[serde(default)]
    pub place: PlaceParams,
    /// Body description file (RON); the built-in JIS 9AR mannequin when absent.
    #[serde(default)]
    pub body: Option<PathBuf>,
    /// Motion file (RON) the body performs after the garment has settled; none: stand still.
    #[serde(default)]
    pub motion: Option<PathBuf>,
    /// Time step Δt, s. Default 0.01.
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// Static friction ρ against the body. Default 0.3 (the thesis's dress).
    #[serde(default = "default_friction")]
    pub friction: f64,
    /// Restitution ν against the body. Default 0.1.
    #[serde(default = "default_restitution")]
    pub restitution: f64,
    /// Cloth against itself. Default false (the thesis left it out for speed).
    #[serde(default)]
    pub self_collision: bool,
    /// Contact skin, m: cloth nodes are kept this far outside the body. Default 0.003 (nodes
    /// hold the skin, the flat triangles between them do not: with a skin of 1 mm the body's
    /// creases showed through 2 cm cells).
    #[serde(default = "default_skin")]
    pub skin: f64,
    /// Sewing pull and threshold.
    #[serde(default)]
    pub sewing: SewingSpec,
    /// Longest time allowed for sewing, s (gravity off). Default 3.
    #[serde(default = "default_sew_limit")]
    pub sew_limit: f64,
    /// Time under gravity after sewing, before the motion starts, s. Default 1.
    #[serde(default = "default_settle")]
    pub settle: f64,
    /// Duration of the motion, s (0: no motion). Default 0.
    #[serde(default)]
    pub motion_time: f64,
    /// Interval between recorded frames, s. Default 0.04 (25 frames per second).
    #[serde(default = "default_frame_interval")]
    pub frame_interval: f64,
    /// Overrides of the solver's step parameters (Δt and gravity are set by the scene).
    #[serde(default = "default_step")]
    pub step: StepParams,
}

fn default_dt() -> f64 {
    0.01
}
fn default_friction() -> f64 {
    0.3
}
fn default_restitution() -> f64 {
    0.1
}
fn default_skin() -> f64 {
    3e-3
}
fn default_sew_limit() -> f64 {
    3.0
}
fn default_settle() -> f64 {
    1.0
}
fn default_frame_interval() -> f64 {
    0.04
}
/// The garment scenes' solver defaults: compliant shear diagonals.
fn default_step() -> StepParams {
    StepParams {
        diagonal_constraint: ConstraintKind::Compliant,
        ..StepParams::default()
    }
}

/// The sewing stage's parameters, as written in a scene.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SewingSpec {
    /// Fraction of a pair's gap closed per second (ω), 1/s. Default 10.
    pub omega: f64,
    /// A pair closer than this is sewn, m. Default 0.005.
    pub threshold: f64,
    /// Largest closing speed of a pair, m/s. Default 1.
    pub max_speed: f64,
}

impl Default for SewingSpec {
    fn default() -> Self {
        Self {
            omega: 10.0,
            threshold: 5e-3,
            max_speed: 1.0,
        }
    }
}

/// The phase a step belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Phase {
    /// Seams being drawn together, gravity off.
    Sewing,
    /// Sewn, under gravity, body still.
    Settling,
    /// The body moves.
    Motion,
}

/// One recorded instant.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Simulated time, s.
    pub time: f64,
    /// Phase.
    pub phase: Phase,
    /// Cloth node positions, m.
    pub cloth: Vec<[f64; 3]>,
    /// Body vertex positions, m.
    pub body: Vec<[f64; 3]>,
}

/// Why a garment scene could not start.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// A file could not be loaded.
    #[error("{0}")]
    File(String),
    /// The garment could not be assembled.
    #[error(transparent)]
    Assemble(#[from] crate::AssembleError),
    /// The panels could not be placed.
    #[error(transparent)]
    Place(#[from] crate::place::PlaceError),
    /// A parameter is out of range.
    #[error("{0}")]
    Invalid(String),
}

/// What a garment run produced.
#[derive(Clone, Debug)]
pub struct GarmentRun {
    /// Cloth triangles (node indices).
    pub cloth_triangles: Vec<[u32; 3]>,
    /// Body triangles (vertex indices).
    pub body_triangles: Vec<[u32; 3]>,
    /// Recorded frames (the first is the placed garment, the last the final or last good state).
    pub frames: Vec<Frame>,
    /// Pairs to sew and pairs sewn at the end.
    pub pairs: (usize, usize),
    /// Simulated time at which every pair was sewn, s.
    pub sewn_at: Option<f64>,
    /// Steps taken.
    pub steps: usize,
    /// Wall time of the steps, s.
    pub wall_seconds: f64,
    /// Time per stage summed over the steps.
    pub timings: StageTimings,
    /// Deepest any node went inside the body over the run (checked every step), m.
    pub max_penetration: f64,
    /// Largest strain error any step left, and the last step's.
    pub max_strain_error: (f64, f64),
    /// Kinetic energy at the end, J.
    pub kinetic_energy: f64,
    /// The failure that ended the run early, if any.
    pub failure: Option<String>,
    /// Things the user should know.
    pub warnings: Vec<String>,
}

/// Load, place, sew, settle and move: the whole garment scene. `base` is the folder relative
/// paths are resolved against; `progress` receives the fraction of simulated time done.
pub fn run_garment(
    spec: &GarmentSpec,
    base: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<GarmentRun, PipelineError> {
    for (name, value, ok) in [
        ("dt", spec.dt, spec.dt > 0.0 && spec.dt <= 0.1),
        ("friction", spec.friction, spec.friction >= 0.0),
        ("skin", spec.skin, spec.skin >= 0.0 && spec.skin <= 0.05),
        (
            "restitution",
            spec.restitution,
            (0.0..=1.0).contains(&spec.restitution),
        ),
        ("sew_limit", spec.sew_limit, spec.sew_limit >= 0.0),
        ("settle", spec.settle, spec.settle >= 0.0),
        ("motion_time", spec.motion_time, spec.motion_time >= 0.0),
        (
            "frame_interval",
            spec.frame_interval,
            spec.frame_interval > 0.0,
        ),
    ] {
        if !(ok && value.is_finite()) {
            return Err(PipelineError::Invalid(format!(
                "scene field `{name}` = {value} is out of range"
            )));
        }
    }
    let resolve = |p: &Path| base.join(p);
    let garment = load_garment(&resolve(&spec.garment), ImproveParams::default())
        .map_err(|e| PipelineError::File(e.to_string()))?;
    let fabric =
        Fabric::load(&resolve(&spec.fabric)).map_err(|e| PipelineError::File(e.to_string()))?;
    let mannequin: Mannequin = match &spec.body {
        None => atelier_body::build::jis_9ar(),
        Some(p) => {
            let d = atelier_body::description::BodyDescription::load(&resolve(p))
                .map_err(|e| PipelineError::File(e.to_string()))?;
            Mannequin::from_description(&d, &d.sizes)
                .map_err(|e| PipelineError::File(format!("{}: {e}", p.display())))?
        }
    };
    let motion = match &spec.motion {
        Some(p) if spec.motion_time > 0.0 => Some(
            Motion::load(&resolve(p), &mannequin)
                .map_err(|e| PipelineError::File(e.to_string()))?,
        ),
        _ => None,
    };
    let g = GarmentCloth::new(&garment, &fabric, AnisotropyForm::PlateTheory)?;
    let body = Body::new(mannequin);
    let rest = body.rest.clone();
    let placed = place(&g, &spec.placements, &body.mannequin, &rest, &spec.place)?;
    let mut state = ClothState::placed(&g.cloth, |p: [f64; 2]| V3::new(p[0], p[1], 0.0));
    state.positions.copy_from_slice(&placed);

    let mut sewing = Sewing::new(
        g.pairs.clone(),
        SewingParams {
            omega: spec.sewing.omega,
            threshold: spec.sewing.threshold,
            max_speed: spec.sewing.max_speed,
        },
    );
    let contact_params = ContactParams {
        material: ContactMaterial {
            restitution: spec.restitution,
            friction: spec.friction,
        },
        self_collision: spec.self_collision,
        thickness: spec.skin,
        ..ContactParams::default()
    };
    let mut contact = BodyContact::new(&g.cloth, contact_params)
        .map_err(|e| PipelineError::Invalid(e.to_string()))?;
    let dt = spec.dt;
    let mut params = StepParams {
        dt,
        gravity: [0.0; 3],
        ..spec.step.clone()
    };
    params
        .validate()
        .map_err(|e| PipelineError::Invalid(e.to_string()))?;
    let part_meshes: Vec<(&[V3], &[[u32; 3]])> = body
        .mannequin
        .parts
        .iter()
        .map(|p| (p.vertices.as_slice(), p.triangles.as_slice()))
        .collect();
    let parts =
        RigidParts::new(&part_meshes).map_err(|e| PipelineError::Invalid(format!("body: {e}")))?;
    // The continuous test needs only the faces on the body's surface: a face buried in another
    // part (the parts overlap at the joints) can only be met from inside.
    let surface_triangles = exposed_triangles(&body.mannequin, &rest, &parts);
    contact.set_parts(parts);
    let to3 = |v: &[V3]| -> Vec<[f64; 3]> { v.iter().map(|p| [p.x, p.y, p.z]).collect() };
    let mut run = GarmentRun {
        cloth_triangles: g.cloth.topology().triangles().to_vec(),
        body_triangles: rest.triangles.clone(),
        frames: vec![Frame {
            time: 0.0,
            phase: Phase::Sewing,
            cloth: to3(&state.positions),
            body: to3(&rest.vertices),
        }],
        pairs: (0, g.pairs.len()),
        sewn_at: None,
        steps: 0,
        wall_seconds: 0.0,
        timings: StageTimings::default(),
        max_penetration: 0.0,
        max_strain_error: (0.0, 0.0),
        kinetic_energy: 0.0,
        failure: None,
        warnings: Vec::new(),
    };
    let mut posed = Posed {
        positions: rest.vertices.clone(),
        velocities: vec![V3::zeros(); rest.vertices.len()],
    };
    let mut next_posed = posed.clone();
    contact
        .set_body(&posed.positions, &posed.positions, &surface_triangles, dt)
        .map_err(|e| PipelineError::Invalid(e.to_string()))?;
    let still = vec![PartMotion::identity(); body.mannequin.parts.len()];
    let (mut motion_start, mut motion_end) = (still.clone(), still.clone());
    let mut solver = Solver::new();
    let mut phase = Phase::Sewing;
    let mut phase_start = 0.0;
    let mut next_frame = spec.frame_interval;
    let total_guess = spec.sew_limit + spec.settle + spec.motion_time;
    let clock = Instant::now();
    loop {
        let t = state.time;
        // Phase changes.
        if phase == Phase::Sewing && sewing.done() {
            run.sewn_at = Some(t);
            phase = Phase::Settling;
            phase_start = t;
            params.gravity = [0.0, -STANDARD_GRAVITY, 0.0];
        } else if phase == Phase::Sewing && t >= spec.sew_limit - 0.5 * dt {
            run.warnings.push(format!(
                "sewing not finished after {:.2} s: {} of {} pairs sewn; open: {}",
                spec.sew_limit,
                sewing.progress().0,
                sewing.progress().1,
                open_seams(&sewing, &g, &state.positions)
            ));
            break;
        }
        if phase == Phase::Settling && t - phase_start >= spec.settle - 0.5 * dt {
            if motion.is_none() || spec.motion_time <= 0.0 {
                break;
            }
            phase = Phase::Motion;
            phase_start = t;
        }
        if phase == Phase::Motion && t - phase_start >= spec.motion_time - 0.5 * dt {
            break;
        }
        // The body over this step.
        if phase == Phase::Motion
            && let Some(m) = &motion
        {
            let tm = t - phase_start;
            let (a, b) = (m.sample(tm), m.sample(tm + dt));
            body.pose_into(&a, &mut posed);
            body.pose_into(&b, &mut next_posed);
            part_motions(&body, &a, &mut motion_start);
            part_motions(&body, &b, &mut motion_end);
            contact
                .set_body(
                    &posed.positions,
                    &next_posed.positions,
                    &surface_triangles,
                    dt,
                )
                .map_err(|e| PipelineError::Invalid(e.to_string()))?;
        }
        contact
            .set_part_motion(&motion_start, &motion_end, dt)
            .map_err(|e| PipelineError::Invalid(e.to_string()))?;
        let report: Result<StepReport, _> = {
            let mut hooks = Chain(vec![&mut sewing, &mut contact]);
            solver.step_with(&g.cloth, &mut state, &params, &mut hooks)
        };
        let report = match report {
            Ok(r) => r,
            Err(e) => {
                run.failure = Some(format!("{phase:?} phase, time {t:.3} s: {e}"));
                break;
            }
        };
        run.steps += 1;
        add_timings(&mut run.timings, &report.timings);
        run.max_strain_error.0 = run.max_strain_error.0.max(report.max_strain_error);
        run.max_strain_error.1 = report.max_strain_error;
        run.kinetic_energy = report.kinetic_energy;
        if phase == Phase::Motion {
            std::mem::swap(&mut posed, &mut next_posed);
        }
        // Penetration against the posed parts (the body at the end of the step).
        let depth = penetration(&state.positions, contact.parts().expect("set above"));
        run.max_penetration = run.max_penetration.max(depth);
        if state.time + 1e-9 >= next_frame {
            run.frames.push(Frame {
                time: state.time,
                phase,
                cloth: to3(&state.positions),
                body: to3(&posed.positions),
            });
            next_frame += spec.frame_interval;
        }
        progress((state.time / total_guess).min(1.0));
    }
    run.wall_seconds = clock.elapsed().as_secs_f64();
    run.pairs.0 = sewing.progress().0;
    let last_time = run.frames.last().map_or(-1.0, |f| f.time);
    if (state.time - last_time).abs() > 1e-12 {
        run.frames.push(Frame {
            time: state.time,
            phase,
            cloth: to3(&state.positions),
            body: to3(&posed.positions),
        });
    }
    Ok(run)
}

/// The seams with open pairs: name, open pairs of all, the widest gap and where it is.
fn open_seams(sewing: &Sewing, g: &GarmentCloth, positions: &[V3]) -> String {
    // (name, open, all, widest gap, its midpoint)
    let mut seams: Vec<(&str, usize, usize, f64, V3)> = Vec::new();
    let open = sewing.unsewn();
    for (k, name) in g.pair_names.iter().enumerate() {
        let idx = match seams.iter().position(|s| s.0 == name) {
            Some(i) => i,
            None => {
                seams.push((name, 0, 0, 0.0, V3::zeros()));
                seams.len() - 1
            }
        };
        let seam = &mut seams[idx];
        seam.2 += 1;
        if open.binary_search(&k).is_ok() {
            let (a, b) = (
                positions[g.pairs[k].0 as usize],
                positions[g.pairs[k].1 as usize],
            );
            seam.1 += 1;
            if (a - b).norm() >= seam.3 {
                seam.3 = (a - b).norm();
                seam.4 = (a + b) * 0.5;
            }
        }
    }
    seams
        .iter()
        .filter(|s| s.1 > 0)
        .map(|s| {
            format!(
                "{} ({} of {}, widest {:.1} mm at ({:.3}, {:.3}, {:.3}) m)",
                s.0,
                s.1,
                s.2,
                s.3 * 1e3,
                s.4.x,
                s.4.y,
                s.4.z
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn add_timings(sum: &mut StageTimings, t: &StageTimings) {
    sum.bending += t.bending;
    sum.internal += t.internal;
    sum.velocity += t.velocity;
    sum.shape += t.shape;
    sum.collision += t.collision;
    sum.transfer += t.transfer;
    sum.update += t.update;
}

/// The deepest any node is inside the body at the end of the step, m (0 when none is).
fn penetration(nodes: &[V3], parts: &RigidParts) -> f64 {
    nodes
        .par_iter()
        .map(|p| {
            parts
                .nearest(p, 0.0, true)
                .map_or(0.0, |n| (-n.distance).max(0.0))
        })
        .reduce(|| 0.0, f64::max)
}

/// The rigid motion of every part (rest → world) in a pose, in the mannequin's part order.
fn part_motions(body: &Body, rate: &PoseRate, out: &mut [PartMotion]) {
    let frames = body.frames(rate);
    for (m, part) in out.iter_mut().zip(&body.mannequin.parts) {
        let f = frames[part.part.index()];
        let r = f.rotation;
        *m = PartMotion::from_parts((f.pivot - r * part.pivot).into(), r);
    }
}

/// The body triangles not buried in another part: a triangle whose three vertices are all more
/// than 1 mm inside some other part is left out of the continuous test.
fn exposed_triangles(
    mannequin: &Mannequin,
    rest: &LabelledMesh,
    parts: &RigidParts,
) -> Vec<[u32; 3]> {
    // Part k of `parts` is `mannequin.parts[k]`.
    let index_of = |part: atelier_body::model::Part| {
        mannequin
            .parts
            .iter()
            .position(|p| p.part == part)
            .expect("every labelled part is a mannequin part")
    };
    let buried = |v: u32, own: usize| {
        let p = rest.vertices[v as usize];
        (0..parts.len())
            .filter(|&k| k != own)
            .any(|k| parts.rest_distance(k, &p) < -1e-3)
    };
    rest.triangles
        .iter()
        .zip(&rest.triangle_part)
        .filter(|(t, part)| {
            let own = index_of(**part);
            !t.iter().all(|&v| buried(v, own))
        })
        .map(|(t, _)| *t)
        .collect()
}
