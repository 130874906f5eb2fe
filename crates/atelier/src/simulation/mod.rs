//! A garment scene stepped through time: [`Simulation::step`] advances one Δt through the
//! ordered stages of `architecture.md`, each timed, each skipped when the scene does not need
//! it:
//!
//! 1. body pose at t and t + Δt and the parts' motion (`body`; skipped while the body stands);
//! 2. bending force, 3. internal forces, 4. unconstrained velocity (`solver`);
//! 5. sewing ties and the geometric transfer of body motion with the contact planes (`collide`;
//!    the transfer only while the body moves);
//! 6. shape-constraint iterations, 7. collision passes (body, self when on; sewn points held),
//!    8. repeated as the step parameters say;
//! 9. position and hysteresis update (`solver`), then the diagnostics: how deep any node is
//!    inside the body.
//!
//! Around the step runs the dressing schedule (thesis §5.6), in phases: sewing with gravity off
//! (or, for one-sided dressing, sewing in front of the body and then pushing the garment
//! through it), settling under gravity, then the motion. A step that fails (a non-finite value,
//! a diverging edge) returns the error with the phase, the time, the stage and the node or edge,
//! and leaves the state as it was before the step: the last good state.

use std::time::{Duration, Instant};

use atelier_body::kinematics::Posed;
use atelier_body::model::LabelledMesh;
use atelier_collide::parts::Motion as PartMotion;
use atelier_collide::{ContactError, ContactMaterial, ContactParams, RigidParts, V3};
use atelier_fabric::InvalidValue;
use atelier_solver::baselines::{MassSpring, Xpbd};
use atelier_solver::integrator::{
    Integrator, MassSpringIntegrator, Party, StepInput, XpbdIntegrator,
};
use atelier_solver::{BodyContact, ClothState, Solver, StageTimings, StepError, StepReport};
use serde::{Deserialize, Serialize};

use crate::place::place;
use crate::scene::{ClothSolver, Dressing, Scene, SceneError};
use crate::{Chain, Sewing};

use diagnostics::{open_seams, penetration};
use setup::{exposed_triangles, part_motions, seam_groups};

mod diagnostics;
mod setup;

/// The phase of the dressing schedule a step belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Phase {
    /// Seams being drawn together, gravity off.
    Sewing,
    /// One-sided dressing: the sewn garment pushed through the body, gravity off.
    Pushing,
    /// Dressed, under gravity, body still.
    Settling,
    /// The body moves.
    Motion,
    /// The schedule is over (or could not go on: see the warnings).
    Done,
}

/// Wall time of a run's stages, summed over its steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Posing the body and setting the parts' motion.
    pub body: Duration,
    /// The solver's stages (bending … update; sewing and contact inside transfer/collision).
    pub solver: StageTimings,
    /// Diagnostics after the step (penetration of every node).
    pub diagnostics: Duration,
}

impl Timings {
    /// Sum of every stage.
    pub fn total(&self) -> Duration {
        self.body + self.solver.total() + self.diagnostics
    }

    /// Add another run's (or step's) timings.
    pub fn add(&mut self, t: &Timings) {
        self.body += t.body;
        self.diagnostics += t.diagnostics;
        self.solver += &t.solver;
    }
}

/// A step that failed; the state is the last good one.
#[derive(Debug, thiserror::Error)]
#[error("{phase:?} phase, time {time:.3} s: {source}")]
pub struct SimulationError {
    /// The phase it happened in.
    pub phase: Phase,
    /// Simulated time at the start of the step, s.
    pub time: f64,
    /// What went wrong.
    pub source: Failure,
}

/// What made a step fail.
#[derive(Debug, thiserror::Error)]
pub enum Failure {
    /// The cloth step: the stage and the node or edge that went non-finite or diverged.
    #[error(transparent)]
    Step(#[from] StepError),
    /// The body stage: the motion gave a pose the contact refused (a non-finite part motion).
    #[error("body stage: {0}")]
    Body(ContactError),
}

/// What one step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutcome {
    /// The phase of the step.
    pub phase: Phase,
    /// The solver's diagnostics. A baseline solver (`settings.solver` XPBD or mass-spring)
    /// fills in its iterations, strain, energy, speed and timings only: it has no tolerance,
    /// so its `converged`, `shape_converged`, `violation` and `worst` say nothing (the run's
    /// convergence is not reported, `crate::convergence`).
    pub report: StepReport,
    /// Nodes inside the body after the step.
    pub inside: usize,
    /// The deepest of them, m (0 when none).
    pub depth: f64,
    /// Wall time of the step's stages.
    pub timings: Timings,
    /// The steps the cloth took to cover Δt: 1, or more when a PARTY step that ended above its
    /// tolerance was taken again in halves (its report then sums them).
    pub substeps: usize,
    /// The contact counts of the step (continuous-test candidates and hits, transfers, planes).
    pub contacts: atelier_collide::PassStats,
}

/// A garment scene being simulated.
pub struct Simulation {
    scene: Scene,
    state: ClothState,
    /// The cloth integrator (`settings.solver`: PARTY or a baseline) with its parameters.
    integrator: Box<dyn Integrator>,
    /// Gravity given to the steps: none while sewing and pushing, the scene's from settling on.
    gravity: [f64; 3],
    sewing: Sewing,
    contact: BodyContact,
    phase: Phase,
    phase_start: f64,
    rest: LabelledMesh,
    /// The body at the start and the end of the coming step.
    posed: Posed,
    next_posed: Posed,
    motion_start: Vec<PartMotion>,
    motion_end: Vec<PartMotion>,
    surface_triangles: Vec<[u32; 3]>,
    sewn_at: Option<f64>,
    last_inside: usize,
    /// Cloth positions at the start of the last step (the diagnostics' bound).
    start_positions: Vec<V3>,
    warnings: Vec<String>,
}

impl Simulation {
    /// Place the garment around the body and prepare every stage.
    ///
    /// The body stands in its motion's first pose (the rest pose without a motion) until the
    /// motion starts: a motion that starts away from rest (arms held out to dress by one-sided
    /// contact, then lowered) dresses the body in that pose.
    pub fn new(scene: Scene) -> Result<Self, SceneError> {
        let g = &scene.garment;
        let rest = scene.body.rest.clone();
        let n_parts = scene.body.mannequin.parts.len();
        let mut start_pose = vec![PartMotion::identity(); n_parts];
        let mut posed = Posed {
            positions: rest.vertices.clone(),
            velocities: vec![V3::zeros(); rest.vertices.len()],
        };
        if let Some(m) = &scene.motion {
            let first = m.sample(0.0);
            let frames = scene.body.pose_with_frames(&first, &mut posed);
            posed.velocities.iter_mut().for_each(|v| *v = V3::zeros());
            part_motions(&scene.body, &frames, &mut start_pose);
        }
        let standing = LabelledMesh {
            vertices: posed.positions.clone(),
            ..rest.clone()
        };
        let placed = place(
            &g.cloth,
            &g.placements,
            &scene.body.mannequin,
            &standing,
            &g.place,
        )?;
        let mut state = ClothState::placed(&g.cloth.cloth, |p: [f64; 2]| V3::new(p[0], p[1], 0.0));
        state.positions.copy_from_slice(&placed);
        let settings = &scene.settings;
        let sewing = Sewing::new(g.cloth.pairs.clone(), settings.sewing.params());
        let one_sided = matches!(settings.dressing, Dressing::OneSided { .. });
        let contact_params = ContactParams {
            material: ContactMaterial {
                restitution: settings.restitution,
                // One-sided dressing slides the garment round the body: frictionless until
                // gravity starts.
                friction: if one_sided { 0.0 } else { settings.friction },
            },
            // Self-collision starts once the garment is on (`start_settling`): while seams are
            // drawn together, a seam's two sides must pass the cloth between them.
            self_collision: false,
            thickness: settings.skin,
            staged: settings.staged,
            one_sided,
            vertex_planes: settings.vertex_planes,
            ..ContactParams::default()
        };
        let mut contact = BodyContact::new(&g.cloth.cloth, contact_params)?;
        if settings.self_collision {
            // The two sides of a seam are one point of the garment: they never collide.
            contact.set_cloth_groups(seam_groups(
                g.cloth.cloth.topology().node_count(),
                &g.cloth.pairs,
            ));
        }
        let part_meshes: Vec<(&[V3], &[[u32; 3]])> = scene
            .body
            .mannequin
            .parts
            .iter()
            .map(|p| (p.vertices.as_slice(), p.triangles.as_slice()))
            .collect();
        let parts = RigidParts::new(&part_meshes)?;
        // The continuous test needs only the faces on the body's surface: a face buried in
        // another part (the parts overlap at the joints) can only be met from inside.
        let surface_triangles = exposed_triangles(&scene.body.mannequin, &rest, &parts);
        // A wrap can reach into the body where it starts (a sleeve's cap wrapped about the
        // shoulder joint lies partly inside the shoulder): every placed node inside the body or
        // within the skin is moved out along the surface normal to twice the skin (no farther:
        // its neighbours stay where they were placed). One-sided dressing starts in front of
        // the body and is left as laid out.
        if !one_sided {
            let mut at_start = parts;
            at_start.set_motion(&start_pose, &start_pose, settings.dt)?;
            let out = 2.0 * settings.skin;
            for x in &mut state.positions {
                if let Some(n) = at_start.nearest(x, settings.skin, false) {
                    let (q, normal) = at_start.place(&n, false);
                    *x = q + normal * out;
                }
            }
            contact.set_parts(at_start);
        } else {
            contact.set_parts(parts);
        }
        contact.set_body(
            &posed.positions,
            &posed.positions,
            &surface_triangles,
            settings.dt,
        )?;
        // Standing: the same pose at both ends of the step.
        contact.set_part_motion(&start_pose, &start_pose, settings.dt)?;
        let params = settings.step.clone();
        let integrator: Box<dyn Integrator> = match &settings.solver {
            ClothSolver::Party => Box::new(Party {
                solver: Solver::new(),
                params,
            }),
            ClothSolver::Xpbd(p) => Box::new(XpbdIntegrator {
                solver: Xpbd::new(),
                params: p.clone(),
            }),
            ClothSolver::MassSpring(p) => Box::new(MassSpringIntegrator {
                solver: MassSpring::new(),
                params: p.clone(),
            }),
        };
        Ok(Self {
            state,
            integrator,
            gravity: [0.0; 3],
            sewing,
            contact,
            phase: Phase::Sewing,
            phase_start: 0.0,
            next_posed: posed.clone(),
            posed,
            motion_start: start_pose.clone(),
            motion_end: start_pose,
            rest,
            surface_triangles,
            sewn_at: None,
            last_inside: 0,
            start_positions: Vec::new(),
            warnings: scene.notes.clone(),
            scene,
        })
    }

    /// Set the shape stage's tolerance (`settings.step.shape.tolerance`, the largest relative
    /// strain error a step must meet) for the steps from now on: a loose one while dressing and
    /// a tight one for a measurement, or one sewn state settled at two tolerances (what
    /// `docs/validation.md` compares for the sewn dress). A value outside the field's range is
    /// refused, naming the field, and nothing changes. `Ok(false)`: the scene's solver is a
    /// baseline, which has no tolerance (the value is kept in the settings, unused).
    pub fn set_shape_tolerance(&mut self, tolerance: f64) -> Result<bool, InvalidValue> {
        let mut step = self.scene.settings.step.clone();
        step.shape.tolerance = tolerance;
        crate::scene::check_step(&step)?;
        self.scene.settings.step = step;
        Ok(self.integrator.set_shape_tolerance(tolerance))
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The cloth's state (positions, velocities, forces, hysteresis).
    pub fn state(&self) -> &ClothState {
        &self.state
    }

    /// Each cloth node's largest axial strain error in the current state (the integrator's
    /// [`Integrator::node_strain_errors`]): what the viewer colours the cloth by.
    pub fn node_strain_errors(&self) -> Vec<f32> {
        self.integrator
            .node_strain_errors(&self.scene.garment.cloth.cloth, &self.state)
    }

    /// The garment's panel names and the panel of each cloth node.
    pub fn node_panels(&self) -> (Vec<String>, Vec<u16>) {
        let cloth = &self.scene.garment.cloth;
        let n = self.state.positions.len();
        let mut of_node = vec![0_u16; n];
        for (k, w) in cloth.offsets.iter().enumerate() {
            let end = cloth.offsets.get(k + 1).map_or(n, |&e| e as usize);
            for p in &mut of_node[(*w as usize).min(n)..end.min(n)] {
                *p = k as u16;
            }
        }
        (cloth.panel_names.clone(), of_node)
    }

    /// The phase the next step belongs to.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.state.time
    }

    /// The body's vertices now (the rest mesh's order).
    pub fn body_positions(&self) -> &[V3] {
        &self.posed.positions
    }

    /// The body's triangles (the rest mesh's).
    pub fn body_triangles(&self) -> &[[u32; 3]] {
        &self.rest.triangles
    }

    /// The cloth's triangles.
    pub fn cloth_triangles(&self) -> &[[u32; 3]] {
        self.scene.garment.cloth.cloth.topology().triangles()
    }

    /// Pairs sewn, of all.
    pub fn sewing_progress(&self) -> (usize, usize) {
        self.sewing.progress()
    }

    /// When every pair was sewn, s.
    pub fn sewn_at(&self) -> Option<f64> {
        self.sewn_at
    }

    /// Things the user should know (seams left open, a push that did not finish).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The longest the schedule can take, s (for progress bars).
    pub fn planned_time(&self) -> f64 {
        let s = &self.scene.settings;
        let push = match s.dressing {
            Dressing::Sewn => 0.0,
            Dressing::OneSided { push_limit, .. } => push_limit,
        };
        let motion = if self.scene.motion.is_some() {
            s.motion_time
        } else {
            0.0
        };
        s.sew_limit + push + s.settle + motion
    }

    /// Change phase where the schedule says so (before a step).
    fn advance_phase(&mut self) {
        let s = &self.scene.settings;
        let (t, dt) = (self.state.time, s.dt);
        let elapsed = t - self.phase_start;
        let due = |limit: f64| elapsed >= limit - 0.5 * dt;
        match self.phase {
            Phase::Sewing if self.sewing.done() => {
                self.sewn_at = Some(t);
                self.phase_start = t;
                match s.dressing {
                    Dressing::Sewn => self.start_settling(),
                    Dressing::OneSided { push, .. } => {
                        self.phase = Phase::Pushing;
                        let masses = self.scene.garment.cloth.cloth.masses();
                        let push = masses
                            .iter()
                            .map(|m| V3::new(0.0, 0.0, -push * m))
                            .collect();
                        if !self.integrator.set_external_forces(push) {
                            self.warnings.push(format!(
                                "the {} integrator applies no external force: the garment is not pushed through the body",
                                self.integrator.name()
                            ));
                        }
                    }
                }
            }
            Phase::Sewing if due(s.sew_limit) => {
                self.warnings.push(format!(
                    "sewing not finished after {:.2} s: {} of {} pairs sewn; open: {}",
                    s.sew_limit,
                    self.sewing.progress().0,
                    self.sewing.progress().1,
                    open_seams(
                        &self.sewing,
                        &self.scene.garment.cloth,
                        &self.state.positions
                    )
                ));
                self.phase = Phase::Done;
            }
            Phase::Pushing => {
                let Dressing::OneSided {
                    push_time,
                    push_limit,
                    ..
                } = s.dressing
                else {
                    unreachable!("pushing only in one-sided dressing")
                };
                if due(push_time) && self.last_inside == 0 {
                    self.integrator.set_external_forces(Vec::new());
                    self.contact.set_one_sided(false);
                    self.contact.set_friction(s.friction);
                    self.phase_start = t;
                    self.start_settling();
                } else if due(push_limit) {
                    self.warnings.push(format!(
                        "the push did not get the garment through the body in {push_limit:.2} s: {} nodes still inside ({})",
                        self.last_inside,
                        self.inside_by_part()
                    ));
                    self.phase = Phase::Done;
                }
            }
            Phase::Settling if due(s.settle) => {
                if self.scene.motion.is_some() && s.motion_time > 0.0 {
                    self.phase = Phase::Motion;
                    self.phase_start = t;
                } else {
                    self.phase = Phase::Done;
                }
            }
            Phase::Motion if due(s.motion_time) => self.phase = Phase::Done,
            _ => {}
        }
    }

    fn start_settling(&mut self) {
        self.phase = Phase::Settling;
        self.gravity = self.scene.settings.gravity;
        if self.scene.settings.self_collision {
            self.contact.set_self_collision(true);
        }
    }

    /// One step of Δt through every stage; `Ok(None)` once the schedule is over (nothing is
    /// done then). On an error the state is the last good one.
    pub fn step(&mut self) -> Result<Option<StepOutcome>, SimulationError> {
        self.advance_phase();
        if self.phase == Phase::Done {
            return Ok(None);
        }
        let (t, dt) = (self.state.time, self.scene.settings.dt);
        let mut timings = Timings::default();
        let moving = self.phase == Phase::Motion;
        self.start_positions.clone_from(&self.state.positions);
        let (report, substeps) = self
            .span(t - self.phase_start, dt, moving, RETRY_DEPTH, &mut timings)
            .map_err(|source| SimulationError {
                phase: self.phase,
                time: t,
                source,
            })?;
        timings.solver = report.timings;
        // Diagnostics: every node against the body at the end of the step.
        let clock = Instant::now();
        let parts = self.contact.parts().expect("set in new");
        let (inside, depth) = penetration(
            &self.state.positions,
            &self.start_positions,
            self.contact.start_distances(),
            parts,
        );
        self.last_inside = inside;
        timings.diagnostics = clock.elapsed();
        Ok(Some(StepOutcome {
            phase: self.phase,
            report,
            inside,
            depth,
            timings,
            substeps,
            contacts: self.contact.take_stats(),
        }))
    }
}

impl Simulation {
    /// The cloth over `h` seconds from `tm` (the motion's clock): the body posed at both ends
    /// when `moving`, then the cloth step with its hooks (sewing, then the body). A PARTY step
    /// that ends above its tolerance is taken again from the same state as two steps of h/2
    /// (to `depth` halvings; the state of the unhalved step is kept when a half fails): a
    /// step that does not converge is not a result, and a shorter step is the honest way to
    /// one that does. Its report: converged only when every part converged, counts summed.
    fn span(
        &mut self,
        tm: f64,
        h: f64,
        moving: bool,
        depth: u32,
        timings: &mut Timings,
    ) -> Result<(StepReport, usize), Failure> {
        let before = (depth > 0 && self.integrator.has_tolerance())
            .then(|| (self.state.clone(), self.posed.clone()));
        let whole = self.cloth_step(tm, h, moving, timings)?;
        let Some((state, posed)) = before.filter(|_| !whole.converged) else {
            return Ok((whole, 1));
        };
        let after = (
            std::mem::replace(&mut self.state, state),
            std::mem::replace(&mut self.posed, posed),
        );
        let halves = self
            .span(tm, 0.5 * h, moving, depth - 1, timings)
            .and_then(|a| {
                self.span(tm + 0.5 * h, 0.5 * h, moving, depth - 1, timings)
                    .map(|b| (a, b))
            });
        match halves {
            Ok(((a, na), (b, nb))) => {
                let mut r = b;
                r.converged = a.converged && b.converged;
                r.shape_converged = a.shape_converged && b.shape_converged;
                if a.violation > b.violation {
                    (r.violation, r.worst) = (a.violation, a.worst);
                }
                r.shape_iterations += a.shape_iterations + whole.shape_iterations;
                r.factorizations += a.factorizations + whole.factorizations;
                r.linear_iterations += a.linear_iterations + whole.linear_iterations;
                r.internal_iterations += a.internal_iterations + whole.internal_iterations;
                r.max_strain_error = r.max_strain_error.max(a.max_strain_error);
                r.timings = whole.timings;
                r.timings += &a.timings;
                r.timings += &b.timings;
                Ok((r, na + nb))
            }
            Err(_) => {
                (self.state, self.posed) = after;
                Ok((whole, 1))
            }
        }
    }

    /// One cloth step of `h` seconds from `tm` (see [`Self::span`]).
    fn cloth_step(
        &mut self,
        tm: f64,
        h: f64,
        moving: bool,
        timings: &mut Timings,
    ) -> Result<StepReport, Failure> {
        if moving && let Some(m) = &self.scene.motion {
            let clock = Instant::now();
            let (a, b) = (m.sample(tm), m.sample(tm + h));
            let body = &self.scene.body;
            let frames_a = body.pose_with_frames(&a, &mut self.posed);
            let frames_b = body.pose_with_frames(&b, &mut self.next_posed);
            part_motions(body, &frames_a, &mut self.motion_start);
            part_motions(body, &frames_b, &mut self.motion_end);
            self.contact
                .set_body(
                    &self.posed.positions,
                    &self.next_posed.positions,
                    &self.surface_triangles,
                    h,
                )
                .and_then(|()| {
                    self.contact
                        .set_part_motion(&self.motion_start, &self.motion_end, h)
                })
                .map_err(Failure::Body)?;
            timings.body += clock.elapsed();
        }
        let mut hooks = Chain(vec![&mut self.sewing, &mut self.contact]);
        let input = StepInput {
            dt: h,
            gravity: self.gravity,
        };
        let report = self
            .integrator
            .advance(
                &self.scene.garment.cloth.cloth,
                &mut self.state,
                input,
                &mut hooks,
            )
            .map_err(Failure::Step)?;
        if moving {
            std::mem::swap(&mut self.posed, &mut self.next_posed);
        }
        Ok(report)
    }
}

/// Halvings of a PARTY step that ends above its tolerance (a step of Δt/4 at most).
const RETRY_DEPTH: u32 = 2;

impl Simulation {
    /// The nodes inside the body now.
    pub fn inside_nodes(&self) -> Vec<usize> {
        let parts = self.contact.parts().expect("set in new");
        (0..self.state.positions.len())
            .filter(|&i| {
                parts
                    .nearest(&self.state.positions[i], 0.0, true)
                    .is_some_and(|n| n.distance < 0.0)
            })
            .collect()
    }

    /// The nodes inside the body now, by part: "part: count (deepest mm)", the deepest first.
    pub fn inside_by_part(&self) -> String {
        let parts = self.contact.parts().expect("set in new");
        let names = &self.scene.body.mannequin.parts;
        let mut by: Vec<(usize, usize, f64)> = Vec::new();
        for p in &self.state.positions {
            if let Some(n) = parts.nearest(p, 0.0, true)
                && n.distance < 0.0
            {
                match by.iter_mut().find(|b| b.0 == n.part) {
                    Some(b) => {
                        b.1 += 1;
                        b.2 = b.2.max(-n.distance);
                    }
                    None => by.push((n.part, 1, -n.distance)),
                }
            }
        }
        by.sort_by(|a, b| b.2.total_cmp(&a.2));
        by.iter()
            .map(|(k, count, depth)| {
                format!("{}: {count} ({:.1} mm)", names[*k].part.name(), depth * 1e3)
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}
