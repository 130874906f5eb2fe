//! The PARTY cloth step (thesis §3.5, §3.8; `method.md` §2) as an ordered list of stages, each a
//! function of its own, each timed:
//!
//! 1. geometry and bending force (28)–(32);
//! 2. internal axial forces p ≥ 0 by projected descent (43)–(47), axial edges then diagonals;
//! 3. unconstrained velocity (18);
//! 4. shape-constraint targets from the tensile and shear characteristics, and the constraint
//!    iterations (49)–(51), interleaved with collision passes;
//! 5. position update, hysteresis update, diagnostics.
//!
//! Nothing in the state changes until every stage has succeeded: a non-finite value stops the
//! step with the stage and node (or edge), and the state from before the step is kept.

use std::time::{Duration, Instant};

use atelier_fabric::Branch;
use atelier_grid::{NO_NODE, SLOTS};
use nalgebra::Vector3;
use rayon::prelude::*;

use crate::cloth::Cloth;
use crate::params::{ConstraintKind, InternalMethod, ParamError, ShapeMethod, StepParams};
use crate::state::ClothState;

type V3 = Vector3<f64>;

/// One chunk of the fused internal-force pass: (chunk index, ((forces, previous forces),
/// partial sums)).
type ChunkItem<'a> = (usize, ((&'a mut [f64], &'a mut [f64]), &'a mut [f64; 2]));

/// Below this many items a loop runs on one thread (rayon's overhead would dominate).
const PAR_MIN: usize = 1024;
/// Chunk size of the deterministic reductions (fixed, so sums do not depend on thread count).
const SUM_CHUNK: usize = 2048;

/// The stages of a step, for timings and errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Positions and velocities handed to the step.
    Input,
    /// Normals, curvatures and bending forces.
    Bending,
    /// Internal axial forces.
    InternalForces,
    /// Unconstrained velocity.
    Velocity,
    /// The air pressure force of a wet cloth.
    Pressure,
    /// Shape-constraint targets and iterations.
    ShapeConstraints,
    /// A collision pass (the hook).
    Collision,
    /// Position and hysteresis update.
    Update,
}

/// A step that could not be completed; the state is as it was before the step.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StepError {
    /// A parameter is outside its range.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// The state does not match the cloth.
    #[error("the state has {found} {what}, the cloth {expected}")]
    Mismatch {
        /// What is counted.
        what: &'static str,
        /// The cloth's count.
        expected: usize,
        /// The state's count.
        found: usize,
    },
    /// The step would stretch an edge beyond `StepParams::divergence_strain`.
    #[error(
        "diverging: edge {edge} would reach strain {strain:.3} (limit {limit}) at time {time} s; Δt too large or tolerances too loose"
    )]
    Diverged {
        /// The edge.
        edge: usize,
        /// Its strain |l/l⁰ − 1| after the step.
        strain: f64,
        /// The limit.
        limit: f64,
        /// Simulated time at the start of the step.
        time: f64,
    },
    /// A value became NaN or infinite.
    #[error("non-finite {quantity} at {location} {index} in stage {stage:?} (time {time} s)")]
    NonFinite {
        /// The stage that produced it.
        stage: Stage,
        /// What quantity.
        quantity: &'static str,
        /// "node" or "edge".
        location: &'static str,
        /// Its index.
        index: usize,
        /// Simulated time at the start of the step.
        time: f64,
    },
}

/// Per-stage wall time of one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimings {
    /// Normals, curvature, bending force.
    pub bending: Duration,
    /// Internal forces.
    pub internal: Duration,
    /// Unconstrained velocity.
    pub velocity: Duration,
    /// Targets and constraint iterations.
    pub shape: Duration,
    /// Collision hook: the passes between shape iterations.
    pub collision: Duration,
    /// Collision hook: the transfer of body motion before the shape constraints.
    pub transfer: Duration,
    /// Update and diagnostics.
    pub update: Duration,
    /// The air pressure force ([`Solver::pressure`]; zero when off).
    pub pressure: Duration,
}

impl StageTimings {
    /// Sum of all stages.
    pub fn total(&self) -> Duration {
        self.bending
            + self.internal
            + self.velocity
            + self.transfer
            + self.shape
            + self.collision
            + self.update
            + self.pressure
    }
}

/// Diagnostics of one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Internal-force iterations (axial phase, diagonal phase).
    pub internal_iterations: [usize; 2],
    /// Final E over its value at p = 0 (1 = nothing balanced, 0 = all external load carried).
    pub internal_residual: f64,
    /// Shape iterations over all passes.
    pub shape_iterations: usize,
    /// Conjugate-gradient iterations over all passes (Newton shape method only).
    pub cg_iterations: usize,
    /// RMS of the per-node length error R after the last iteration, m.
    pub shape_residual: f64,
    /// Largest |ε − ε̄| over the edges after the update (stretch-only edges: excess only).
    pub max_strain_error: f64,
    /// Kinetic energy after the step, J.
    pub kinetic_energy: f64,
    /// Fastest node after the step, m/s.
    pub max_speed: f64,
    /// Edges whose force per width lay above the measured range (strain extrapolated).
    pub extrapolated_edges: usize,
    /// The tolerance factor the policy applied (1 = tight).
    pub tolerance_factor: f64,
    /// Wall time per stage.
    pub timings: StageTimings,
}

/// Everything a collision pass may look at and change.
pub struct HookContext<'a> {
    /// Positions at the start of the step.
    pub positions: &'a [V3],
    /// Velocities being corrected (the node moves by `velocity·dt` this step).
    pub velocities: &'a mut [V3],
    /// Added to the velocities after the position update (zero at the start of the step): a
    /// contact's exit velocity minus the mean velocity the node moved with (thesis (72)).
    pub exit: &'a mut [V3],
    /// Inverse masses (0 for pinned nodes, which a hook must not move).
    pub inverse_masses: &'a [f64],
    /// Time step, s.
    pub dt: f64,
    /// Simulated time at the start of the step, s.
    pub time: f64,
    /// Which pass (0-based).
    pub pass: usize,
    /// Contact planes (one per node, a zero normal for none) that the following shape
    /// iterations respect; a hook sets them for nodes touching the body. Reset every step.
    pub planes: &'a mut [atelier_collide::ContactPlane],
    /// Node pairs held within a distance inside the shape iterations (seams being sewn, sewn
    /// seams); a hook adds them in `transfer`. Cleared every step.
    pub ties: &'a mut Vec<Tie>,
}

/// Two nodes that must end the step no farther apart than `length` (a seam being drawn
/// together, or sewn at length 0). Each shape iteration moves a pair that is too far apart
/// towards its mass-weighted centre (momentum kept) until it is `length` apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tie {
    /// First node.
    pub a: u32,
    /// Second node.
    pub b: u32,
    /// Largest distance at the end of the step, m.
    pub length: f64,
}

/// The collision stages of a step: a transfer after the unconstrained velocity (the staged
/// model's geometric stage), and a pass after each round of shape-constraint iterations.
pub trait CollisionHook: Send {
    /// Resolve contacts by changing velocities.
    fn resolve(&mut self, ctx: HookContext<'_>);
    /// Before the shape constraints: move the cloth with a moving body (default: nothing).
    fn transfer(&mut self, _ctx: HookContext<'_>) {}
}

/// No collisions.
pub struct NoCollision;

impl CollisionHook for NoCollision {
    fn resolve(&mut self, _ctx: HookContext<'_>) {}
}

/// Reusable scratch buffers of the step (no allocation once sized).
#[derive(Default)]
struct Scratch {
    tri_normal: Vec<V3>,
    normal: Vec<V3>,
    exit: Vec<V3>,
    dir: Vec<V3>,
    len: Vec<f64>,
    eta: Vec<[f64; SLOTS]>,
    node_moment: Vec<f64>,
    slot_coef: Vec<[f64; SLOTS]>,
    slot_len: Vec<[f64; SLOTS]>,
    w: Vec<f64>,
    w_r: Vec<f64>,
    w_z: Vec<f64>,
    w_p: Vec<f64>,
    w_ap: Vec<f64>,
    w_dm: Vec<f64>,
    w_rhat: Vec<f64>,
    w_v: Vec<f64>,
    w_y: Vec<f64>,
    w_t: Vec<f64>,
    f_sum: Vec<V3>,
    f_m: Vec<V3>,
    p: Vec<f64>,
    p_prev: Vec<f64>,
    p_warm: Vec<f64>,
    ph_p: Vec<f64>,
    ph_prev: Vec<f64>,
    ph_y: Vec<f64>,
    ph_partial: Vec<[f64; 2]>,
    p_y: Vec<f64>,
    grad: Vec<f64>,
    force_per_width: Vec<f64>,
    target: Vec<f64>,
    shear: Vec<f64>,
    /// Accumulated XPBD multipliers of compliant diagonals (reset each step).
    lambda_c: Vec<f64>,
    /// Contact planes set by the hooks this step.
    planes: Vec<atelier_collide::ContactPlane>,
    /// Nodes whose contact plane `project` applies (see `shape_iterations`).
    plane_nodes: Vec<u32>,
    /// Nodes in a tie this step.
    tied: Vec<bool>,
    /// Time spent in the pressure projections this step.
    pressure_time: Duration,
    /// The surface's reaction on the nodes lying on it (pressure stage only).
    reaction: Vec<V3>,
    /// Node pairs held within a distance this step.
    ties: Vec<Tie>,
    /// The long-range attachments of the cloth's pins (built when the pins change).
    long_range: Option<crate::long_range::LongRange>,
    /// Whether `project` applies them this step.
    long_range_on: bool,
    /// This step's largest target strain (the attachments' slack).
    long_range_slack: f64,
    vel: Vec<V3>,
    vel_prev: Vec<V3>,
    vel_hat: Vec<V3>,
    pred: Vec<V3>,
    c: Vec<f64>,
    cdir: Vec<V3>,
    r: Vec<V3>,
    chunk: Vec<f64>,
    cg_x: Vec<f64>,
    cg_r: Vec<f64>,
    cg_z: Vec<f64>,
    cg_p: Vec<f64>,
    cg_q: Vec<f64>,
    cg_y: Vec<V3>,
}

/// The PARTY solver: stateless between steps apart from scratch buffers and cached step-size
/// estimates; the simulation state is passed in explicitly.
#[derive(Default)]
pub struct Solver {
    s: Scratch,
    /// λ_max(AᵀA) of the axial and diagonal phases, estimated on the first step.
    lambda: Option<[f64; 2]>,
    /// External forces per node (N) added in the next steps; empty for none.
    pub external_forces: Vec<V3>,
    /// The air pressure of a wet cloth ([`crate::wet`]): its force at the start of the step joins
    /// the external forces, and the shape iterations take the air's pressure at the end of the
    /// step as a compliant volume constraint (`wet::pressure`, "Large steps"). None (the
    /// default): no pressure, and nothing of it runs.
    pub pressure: Option<crate::wet::PressureStage>,
}

fn resize<T: Clone>(v: &mut Vec<T>, n: usize, x: T) {
    if v.len() != n {
        v.clear();
        v.resize(n, x);
    }
}

/// ½ Σ |f_i|² over the free nodes (inverse mass > 0), summed deterministically.
fn free_energy(chunk: &mut Vec<f64>, f: &[V3], inv: &[f64]) -> f64 {
    0.5 * det_sum(chunk, f.len(), |i| {
        if inv[i] > 0.0 {
            f[i].norm_squared()
        } else {
            0.0
        }
    })
}

/// Deterministic sum of `f(i)` for `i < n`: fixed chunks summed in parallel, then in order.
fn det_sum(chunk: &mut Vec<f64>, n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let chunks = n.div_ceil(SUM_CHUNK);
    resize(chunk, chunks, 0.0);
    let body = |(k, out): (usize, &mut f64)| {
        let end = ((k + 1) * SUM_CHUNK).min(n);
        *out = (k * SUM_CHUNK..end).map(&f).sum();
    };
    if n >= PAR_MIN {
        chunk.par_iter_mut().enumerate().for_each(body);
    } else {
        chunk.iter_mut().enumerate().for_each(body);
    }
    chunk.iter().sum()
}

/// `out[i] = f(i)` over a slice, in parallel above [`PAR_MIN`].
fn fill<T: Send>(out: &mut [T], f: impl Fn(usize) -> T + Sync + Send) {
    if out.len() >= PAR_MIN {
        out.par_iter_mut().enumerate().for_each(|(i, o)| *o = f(i));
    } else {
        out.iter_mut().enumerate().for_each(|(i, o)| *o = f(i));
    }
}

/// `(Jᵀ x)_i` for the length constraints: the sum over the edges at node `i` of `x_e` times the
/// edge's unit direction, signed −1 where `i` is the edge's first node (∂l/∂r_a = −d).
fn jacobian_transpose(cloth: &Cloth, cdir: &[V3], x: &[f64], i: usize) -> V3 {
    cloth
        .incidence(i)
        .iter()
        .map(|inc| cdir[inc.edge as usize] * (-inc.sign * x[inc.edge as usize]))
        .sum()
}

/// A bending characteristic with the step's regularisation: stick slope and reversal dead band
/// (a fraction of M₀/B).
fn regularised(s: &atelier_fabric::Spindle, stick: f64, band: f64) -> atelier_fabric::Spindle {
    s.with_stick_slope(stick)
        .with_deadband(band * s.residual_moment() / s.rigidity())
}

/// A node's velocity such that it ends the step in front of `plane`: pushed out along the
/// normal, and Coulomb friction taking up to ρ times that change off its velocity relative to
/// the body, along the plane.
pub(crate) fn plane_push(v: V3, x: &V3, plane: &atelier_collide::ContactPlane, dt: f64) -> V3 {
    let d = (x + v * dt - plane.point).dot(&plane.normal);
    if d >= 0.0 {
        return v;
    }
    let dn = -d / dt;
    let mut v = v + plane.normal * dn;
    let rel = v - plane.velocity;
    let tangential = rel - plane.normal * rel.dot(&plane.normal);
    let t = tangential.norm();
    if t > 0.0 {
        v -= tangential * ((plane.friction * dn).min(t) / t);
    }
    v
}

fn first_non_finite_v(v: &[V3]) -> Option<usize> {
    v.iter()
        .position(|x| !(x.x.is_finite() && x.y.is_finite() && x.z.is_finite()))
}

fn first_non_finite(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}

impl Solver {
    /// A solver with empty scratch.
    pub fn new() -> Self {
        Self::default()
    }

    /// Target length of every edge in the last step, m (diagnostics).
    pub fn last_targets(&self) -> &[f64] {
        &self.s.target
    }

    /// Node bending moment M of the last step (thesis (31)), N·m (diagnostics and virtual tests).
    pub fn last_node_moments(&self) -> &[f64] {
        &self.s.node_moment
    }

    /// Curvature of each node's axial slots in the last step, m⁻¹ (diagnostics).
    pub fn last_curvatures(&self) -> &[[f64; SLOTS]] {
        &self.s.eta
    }

    /// Forget cached estimates (call when switching to a different cloth or changing pins).
    pub fn reset(&mut self) {
        self.lambda = None;
    }

    /// One step without collisions.
    pub fn step(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
    ) -> Result<StepReport, StepError> {
        self.step_with(cloth, state, params, &mut NoCollision)
    }

    /// One step with a collision hook between shape-constraint iterations.
    pub fn step_with(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
        hook: &mut dyn CollisionHook,
    ) -> Result<StepReport, StepError> {
        if cloth.topology().edges().len() >= PAR_MIN {
            // Run the whole step on a pool thread: the parallel loops inside then split work
            // by stealing instead of each injecting a job from outside the pool (measured:
            // ~20 % of a 1 681-node step went to thread hand-offs).
            rayon::scope(|_| self.step_inner(cloth, state, params, hook))
        } else {
            self.step_inner(cloth, state, params, hook)
        }
    }

    fn step_inner(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
        hook: &mut dyn CollisionHook,
    ) -> Result<StepReport, StepError> {
        params.validate()?;
        let topo = cloth.topology();
        let (n, ne) = (topo.node_count(), topo.edges().len());
        for (what, expected, found) in [
            ("positions", n, state.positions.len()),
            ("velocities", n, state.velocities.len()),
            ("edge forces", ne, state.axial_force.len()),
            ("tensile states", ne, state.tensile.len()),
            ("bending states", n, state.bending.len()),
            (
                "cell shear angles",
                topo.cells().len(),
                state.shear_angle.len(),
            ),
        ] {
            if expected != found {
                return Err(StepError::Mismatch {
                    what,
                    expected,
                    found,
                });
            }
        }
        let non_finite = |stage, quantity, location, index| StepError::NonFinite {
            stage,
            quantity,
            location,
            index,
            time: state.time,
        };
        if let Some(i) = first_non_finite_v(&state.positions) {
            return Err(non_finite(Stage::Input, "position", "node", i));
        }
        if let Some(i) = first_non_finite_v(&state.velocities) {
            return Err(non_finite(Stage::Input, "velocity", "node", i));
        }
        self.size(n, ne, topo.triangles().len(), topo.cells().len());
        let mut report = StepReport::default();
        let dt = params.dt;

        // 1. Geometry and bending.
        let t0 = Instant::now();
        self.geometry(cloth, state);
        if params.bending_off {
            self.s.f_sum.iter_mut().for_each(|f| *f = V3::zeros());
            self.s.slot_coef.iter_mut().for_each(|k| *k = [0.0; SLOTS]);
        } else {
            self.bending(cloth, state, params);
        }
        self.add_external(cloth, params);
        if let Some(i) = first_non_finite_v(&self.s.f_sum) {
            return Err(non_finite(Stage::Bending, "bending force", "node", i));
        }
        report.timings.bending = t0.elapsed();
        if let Some(p) = &mut self.pressure {
            // The pressure predicted for the end of the step (backward Euler) from the
            // velocities the other forces would give.
            let t0 = Instant::now();
            let (mass, areas, f) = (cloth.masses(), cloth.topology().node_areas(), &self.s.f_sum);
            let vel0 = &state.velocities;
            fill(&mut self.s.pred, |i| {
                let c = params.damping * areas[i];
                (vel0[i] * mass[i] + f[i] * dt) / (mass[i] + c * dt)
            });
            for pin in cloth.pins() {
                let i = pin.node as usize;
                self.s.pred[i] = (pin.position(state.time + dt) - state.positions[i]) / dt;
            }
            p.add_forces_predicted(
                &state.positions,
                &self.s.pred,
                cloth.inverse_masses(),
                dt,
                &mut self.s.f_sum,
            );
            p.support(
                &state.velocities,
                cloth.inverse_masses(),
                dt,
                &mut self.s.f_sum,
                &mut self.s.reaction,
            );
            if let Some(i) = first_non_finite_v(&self.s.f_sum) {
                return Err(non_finite(Stage::Pressure, "pressure force", "node", i));
            }
            report.timings.pressure = t0.elapsed();
        }

        // 2. Internal forces.
        let t0 = Instant::now();
        if self.lambda.is_none() {
            self.lambda = Some([
                self.estimate_lambda(cloth, false),
                self.estimate_lambda(cloth, true),
            ]);
        }
        let max_speed0 = state
            .velocities
            .iter()
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        report.tolerance_factor = params.tolerance_factor(max_speed0);
        self.s.p.copy_from_slice(&state.axial_force);
        let e0 = self.energy_at_zero(cloth);
        report.internal_iterations[0] =
            self.internal_phase(cloth, params, false, report.tolerance_factor);
        report.internal_iterations[1] =
            self.internal_phase(cloth, params, true, report.tolerance_factor);
        self.gather(cloth, true);
        let e = self.energy(cloth);
        report.internal_residual = if e0 > 0.0 { e / e0 } else { 0.0 };
        if self.pressure.is_some() {
            // The surface's reaction was balanced in; the velocity carries the load into the
            // surface again, so that the contact's friction feels it.
            for (f, r) in self.s.f_m.iter_mut().zip(&self.s.reaction) {
                *f -= r;
            }
        }
        if let Some(i) = first_non_finite(&self.s.p) {
            return Err(non_finite(Stage::InternalForces, "axial force", "edge", i));
        }
        report.timings.internal = t0.elapsed();

        // 3. Unconstrained velocity.
        let t0 = Instant::now();
        self.unconstrained_velocity(cloth, state, params);
        if let Some(i) = first_non_finite_v(&self.s.vel) {
            return Err(non_finite(Stage::Velocity, "velocity", "node", i));
        }
        report.timings.velocity = t0.elapsed();

        // 3b. Transfer of body motion (staged collision model).
        let t0 = Instant::now();
        self.s.exit.iter_mut().for_each(|e| *e = V3::zeros());
        self.s
            .planes
            .iter_mut()
            .for_each(|p| *p = atelier_collide::ContactPlane::default());
        self.s.ties.clear();
        hook.transfer(HookContext {
            positions: &state.positions,
            velocities: &mut self.s.vel,
            exit: &mut self.s.exit,
            inverse_masses: cloth.inverse_masses(),
            dt,
            time: state.time,
            pass: 0,
            planes: &mut self.s.planes,
            ties: &mut self.s.ties,
        });
        if let Some(i) = first_non_finite_v(&self.s.vel) {
            return Err(non_finite(Stage::Collision, "velocity", "node", i));
        }
        report.timings.transfer = t0.elapsed();

        // 4. Shape constraints, interleaved with collision passes.
        let t0 = Instant::now();
        report.extrapolated_edges = self.targets(cloth, state, params);
        if let Some(i) = first_non_finite(&self.s.target) {
            return Err(non_finite(
                Stage::ShapeConstraints,
                "target length",
                "edge",
                i,
            ));
        }
        self.prepare_long_range(cloth, params);
        let mut collision_time = Duration::ZERO;
        self.s.pressure_time = Duration::ZERO;
        for pass in 0..params.collision_passes {
            let (iters, residual, cg) =
                self.shape_iterations(cloth, state, params, report.tolerance_factor);
            report.shape_iterations += iters;
            report.cg_iterations += cg;
            report.shape_residual = residual;
            if let Some(i) = first_non_finite_v(&self.s.vel) {
                return Err(non_finite(Stage::ShapeConstraints, "velocity", "node", i));
            }
            let tc = Instant::now();
            hook.resolve(HookContext {
                positions: &state.positions,
                velocities: &mut self.s.vel,
                exit: &mut self.s.exit,
                inverse_masses: cloth.inverse_masses(),
                dt,
                time: state.time,
                pass,
                planes: &mut self.s.planes,
                ties: &mut self.s.ties,
            });
            collision_time += tc.elapsed();
            if let Some(i) = first_non_finite_v(&self.s.vel) {
                return Err(non_finite(Stage::Collision, "velocity", "node", i));
            }
        }
        report.timings.collision = collision_time;
        report.timings.pressure += self.s.pressure_time;
        report.timings.shape = t0.elapsed() - collision_time - self.s.pressure_time;

        // 5. Update and commit.
        let t0 = Instant::now();
        let positions = &state.positions;
        let vel = &self.s.vel;
        fill(&mut self.s.pred, |i| positions[i] + vel[i] * dt);
        if let Some(i) = first_non_finite_v(&self.s.pred) {
            return Err(non_finite(Stage::Update, "position", "node", i));
        }
        {
            let (edges, pred) = (cloth.topology().edges(), &self.s.pred);
            let worst = edges
                .iter()
                .enumerate()
                .map(|(e, edge)| {
                    (
                        e,
                        ((pred[edge.b as usize] - pred[edge.a as usize]).norm() / edge.rest_length
                            - 1.0)
                            .abs(),
                    )
                })
                .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
            if worst.1 > params.divergence_strain {
                return Err(StepError::Diverged {
                    edge: worst.0,
                    strain: worst.1,
                    limit: params.divergence_strain,
                    time: state.time,
                });
            }
        }
        std::mem::swap(&mut state.positions, &mut self.s.pred);
        for ((v, w), e) in state
            .velocities
            .iter_mut()
            .zip(&self.s.vel)
            .zip(&self.s.exit)
        {
            *v = w + e;
        }
        state.axial_force.copy_from_slice(&self.s.p);
        state.shear_angle.copy_from_slice(&self.s.shear);
        self.commit_hysteresis(cloth, state, params);
        state.time += dt;
        report.max_strain_error = self.max_strain_error(cloth, state, params);
        report.kinetic_energy = state.kinetic_energy(cloth);
        report.max_speed = state
            .velocities
            .iter()
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        report.timings.update = t0.elapsed();
        Ok(report)
    }

    fn size(&mut self, n: usize, ne: usize, nt: usize, nc: usize) {
        let s = &mut self.s;
        let z = V3::zeros();
        resize(&mut s.tri_normal, nt, z);
        for v in [
            &mut s.normal,
            &mut s.exit,
            &mut s.f_sum,
            &mut s.f_m,
            &mut s.vel,
            &mut s.vel_prev,
            &mut s.vel_hat,
            &mut s.pred,
            &mut s.r,
        ] {
            resize(v, n, z);
        }
        resize(&mut s.eta, n, [0.0; SLOTS]);
        for v in [
            &mut s.node_moment,
            &mut s.w,
            &mut s.w_r,
            &mut s.w_z,
            &mut s.w_p,
            &mut s.w_ap,
            &mut s.w_dm,
        ] {
            resize(v, n, 0.0);
        }
        resize(&mut s.slot_coef, n, [0.0; SLOTS]);
        resize(&mut s.slot_len, n, [0.0; SLOTS]);
        resize(&mut s.dir, ne, z);
        resize(&mut s.cdir, ne, z);
        for v in [
            &mut s.len,
            &mut s.p,
            &mut s.p_prev,
            &mut s.p_warm,
            &mut s.p_y,
            &mut s.grad,
            &mut s.force_per_width,
            &mut s.target,
            &mut s.lambda_c,
            &mut s.c,
            &mut s.cg_x,
            &mut s.cg_r,
            &mut s.cg_z,
            &mut s.cg_p,
            &mut s.cg_q,
        ] {
            resize(v, ne, 0.0);
        }
        resize(&mut s.cg_y, n, z);
        resize(&mut s.planes, n, atelier_collide::ContactPlane::default());
        resize(&mut s.shear, nc, 0.0);
        if self.external_forces.len() != n {
            self.external_forces.clear();
        }
    }

    /// Edge directions and lengths, triangle and node normals (area-weighted) at the start of
    /// the step.
    fn geometry(&mut self, cloth: &Cloth, state: &ClothState) {
        let topo = cloth.topology();
        let (edges, pos) = (topo.edges(), &state.positions);
        let s = &mut self.s;
        fill(&mut s.len, |e| {
            (pos[edges[e].b as usize] - pos[edges[e].a as usize]).norm()
        });
        let len = &s.len;
        fill(&mut s.dir, |e| {
            let d = pos[edges[e].b as usize] - pos[edges[e].a as usize];
            if len[e] > 0.0 {
                d / len[e]
            } else {
                V3::zeros()
            }
        });
        let tris = topo.triangles();
        fill(&mut s.tri_normal, |t| {
            let [a, b, c] = tris[t].map(|k| pos[k as usize]);
            (b - a).cross(&(c - a))
        });
        let tn = &s.tri_normal;
        // A pinned node takes the normal of the clamp it belongs to (its triangles whose nodes
        // are all pinned), so a clamp imposes its tangent plane on the bending at its edge;
        // with the free triangles mixed in, the clamp would act half as stiff and the
        // cantilever converge at first order only (docs/solver.md).
        let clamped = |t: u32| {
            tris[t as usize]
                .iter()
                .all(|&k| cloth.is_pinned(k as usize))
        };
        fill(&mut s.normal, |i| {
            let incident = topo.incident_triangles(i);
            let mut sum: V3 = V3::zeros();
            if cloth.is_pinned(i) {
                sum = incident
                    .iter()
                    .filter(|&&t| clamped(t))
                    .map(|&t| tn[t as usize])
                    .sum();
            }
            if sum == V3::zeros() {
                sum = incident.iter().map(|&t| tn[t as usize]).sum();
            }
            let norm = sum.norm();
            if norm > 0.0 { sum / norm } else { V3::zeros() }
        });
    }

    /// Bending (28)–(32): curvature η = −2 n·(r_a − r_i)/l² per axial slot, moment per width
    /// from the spindle (peeked through the hysteresis state), node moment
    /// M = Σ_dir ½ Σ W_a m_a over directions with both neighbours (a free edge carries no moment),
    /// force F = n Σ (M_a − M)/l_a. Also the diagonal bending stiffness for the implicit term.
    fn bending(&mut self, cloth: &Cloth, state: &ClothState, params: &StepParams) {
        let topo = cloth.topology();
        let (axial, areas, mats, table) = (
            topo.axial_neighbours(),
            topo.node_areas(),
            cloth.slot_materials(),
            cloth.materials(),
        );
        let pos = &state.positions;
        let hysteresis = params.hysteresis && cloth.bending_hysteretic();
        let (stick, band) = (params.bending_stick_slope, params.bending_deadband);
        let s = &mut self.s;
        let normal = &s.normal;
        fill(&mut s.eta, |i| {
            let mut eta = [0.0; SLOTS];
            for k in 0..SLOTS {
                let a = axial[i][k];
                if a != NO_NODE {
                    let d = pos[a as usize] - pos[i];
                    eta[k] = -2.0 * normal[i].dot(&d) / d.norm_squared();
                }
            }
            eta
        });
        let eta = &s.eta;
        let bending_states = &state.bending;
        fill(&mut s.node_moment, |i| {
            let mut m = 0.0;
            for dir in 0..2 {
                let (k0, k1) = (2 * dir, 2 * dir + 1);
                if axial[i][k0] == NO_NODE || axial[i][k1] == NO_NODE {
                    continue;
                }
                for k in [k0, k1] {
                    let spindle = regularised(table.bending(mats[i][k]), stick, band);
                    let l = (pos[axial[i][k] as usize] - pos[i]).norm();
                    let per_width = if hysteresis {
                        bending_states[i][k].moment(&spindle, eta[i][k])
                    } else {
                        spindle.rigidity() * eta[i][k]
                    };
                    m += 0.5 * (areas[i] / l) * per_width;
                }
            }
            m
        });
        let moment = &s.node_moment;
        fill(&mut s.f_sum, |i| {
            let f: f64 = axial[i]
                .iter()
                .filter(|&&a| a != NO_NODE)
                .map(|&a| (moment[a as usize] - moment[i]) / (pos[a as usize] - pos[i]).norm())
                .sum();
            normal[i] * f
        });
        // Linearised bending for the implicit solve: per slot W·B/2 where the direction has both
        // neighbours (the node moment counts only those), and the slot length.
        // With hysteresis the curve after a turning point is steeper than B (up to the stick
        // slope): linearising with B alone leaves (stick − 1)·B explicit, which alternates
        // step by step on fine grids (`implicit_stick_slope`).
        let steepest = |sp: &atelier_fabric::Spindle| {
            if params.implicit_stick_slope && hysteresis && sp.is_hysteretic() && stick.is_finite()
            {
                stick
            } else {
                1.0
            }
        };
        fill(&mut s.slot_coef, |i| {
            let mut coef = [0.0; SLOTS];
            for dir in 0..2 {
                let (k0, k1) = (2 * dir, 2 * dir + 1);
                if axial[i][k0] == NO_NODE || axial[i][k1] == NO_NODE {
                    continue;
                }
                for k in [k0, k1] {
                    let l = (pos[axial[i][k] as usize] - pos[i]).norm();
                    let spindle = table.bending(mats[i][k]);
                    coef[k] = 0.5 * (areas[i] / l) * spindle.rigidity() * steepest(spindle);
                }
            }
            coef
        });
        fill(&mut s.slot_len, |i| {
            let mut len = [0.0; SLOTS];
            for k in 0..SLOTS {
                if axial[i][k] != NO_NODE {
                    len[k] = (pos[axial[i][k] as usize] - pos[i]).norm();
                }
            }
            len
        });
    }

    /// F_sum += μ g + external forces.
    fn add_external(&mut self, cloth: &Cloth, params: &StepParams) {
        let g = params.gravity_vector();
        let masses = cloth.masses();
        let ext = &self.external_forces;
        for (i, f) in self.s.f_sum.iter_mut().enumerate() {
            *f += g * masses[i];
            if let Some(x) = ext.get(i) {
                *f += x;
            }
        }
    }

    /// F^m = F_sum + Σ p d over incident edges (diagonals only when `diagonals`), from p.
    fn gather(&mut self, cloth: &Cloth, diagonals: bool) {
        self.gather_from(cloth, diagonals, false);
    }

    /// The same from p (`from_y` false) or from the extrapolated point y of the accelerated
    /// method (`from_y` true).
    fn gather_from(&mut self, cloth: &Cloth, diagonals: bool, from_y: bool) {
        let s = &mut self.s;
        let p: &[f64] = if from_y { &s.p_y } else { &s.p };
        let (dir, f_sum) = (&s.dir, &s.f_sum);
        fill(&mut s.f_m, |i| {
            let mut f = f_sum[i];
            for inc in cloth.incidence(i) {
                if diagonals || inc.axial {
                    let e = inc.edge as usize;
                    f += dir[e] * (inc.sign * p[e]);
                }
            }
            f
        });
    }

    /// E = ½ Σ over free nodes |F^m|².
    fn energy(&mut self, cloth: &Cloth) -> f64 {
        free_energy(&mut self.s.chunk, &self.s.f_m, cloth.inverse_masses())
    }

    /// E at p = 0: ½ Σ over free nodes of the squared external-plus-bending force.
    fn energy_at_zero(&mut self, cloth: &Cloth) -> f64 {
        free_energy(&mut self.s.chunk, &self.s.f_sum, cloth.inverse_masses())
    }

    /// ∂E/∂p_e = (F^m_a [a free] − F^m_b [b free])·d_e for the edges of one phase.
    fn gradient(&mut self, cloth: &Cloth, diagonals: bool) {
        let topo = cloth.topology();
        let edges = topo.edges();
        let inv = cloth.inverse_masses();
        let s = &mut self.s;
        let (f_m, dir) = (&s.f_m, &s.dir);
        fill(&mut s.grad, |e| {
            let edge = &edges[e];
            if edge.kind.is_axial() == diagonals {
                return 0.0;
            }
            let (a, b) = (edge.a as usize, edge.b as usize);
            let fa = if inv[a] > 0.0 { f_m[a] } else { V3::zeros() };
            let fb = if inv[b] > 0.0 { f_m[b] } else { V3::zeros() };
            (fa - fb).dot(&dir[e])
        });
    }

    /// λ_max of AᵀA restricted to one phase's edges, by power iteration on the current geometry
    /// (with a 10 % margin).
    fn estimate_lambda(&mut self, cloth: &Cloth, diagonals: bool) -> f64 {
        let edges = cloth.topology().edges();
        let in_phase = |e: usize| edges[e].kind.is_axial() != diagonals;
        if !(0..edges.len()).any(in_phase) {
            return 1.0;
        }
        let saved_sum = std::mem::take(&mut self.s.f_sum);
        self.s.f_sum = vec![V3::zeros(); saved_sum.len()];
        let saved_p = self.s.p.clone();
        for (e, p) in self.s.p.iter_mut().enumerate() {
            *p = if in_phase(e) {
                1.0 + 0.1 * ((e * 7919) % 13) as f64
            } else {
                0.0
            };
        }
        let mut lambda = 1.0;
        for _ in 0..40 {
            self.gather(cloth, diagonals);
            self.gradient(cloth, diagonals);
            let norm_p = self.s.p.iter().map(|x| x * x).sum::<f64>().sqrt();
            let norm_g = self.s.grad.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm_g == 0.0 {
                break;
            }
            lambda = norm_g / norm_p;
            let (grad, p) = (&self.s.grad, &mut self.s.p);
            for (pi, gi) in p.iter_mut().zip(grad) {
                *pi = gi / norm_g;
            }
        }
        self.s.f_sum = saved_sum;
        self.s.p = saved_p;
        1.1 * lambda.max(1e-12)
    }

    /// One phase of the internal-force solve (thesis (45)–(47)): projected steepest descent, or
    /// the accelerated variant; only this phase's p change. Returns the iterations used.
    fn internal_phase(
        &mut self,
        cloth: &Cloth,
        params: &StepParams,
        diagonals: bool,
        factor: f64,
    ) -> usize {
        let edges = cloth.topology().edges();
        let lambda = self.lambda.map_or(1.0, |l| l[usize::from(diagonals)]);
        let mut gamma = params.internal_step / lambda;
        let in_phase = |e: usize| edges[e].kind.is_axial() != diagonals;
        // Scale of the optimality test: the gradient with all forces zero (the load itself).
        for e in 0..self.s.p_y.len() {
            self.s.p_y[e] = if in_phase(e) { 0.0 } else { self.s.p[e] };
        }
        self.gather_from(cloth, diagonals, true);
        self.gradient(cloth, diagonals);
        let g_ref = self.projected_gradient_norm(cloth, diagonals, true);
        let e_zero = self.energy(cloth);
        self.gather(cloth, diagonals);
        let mut e_start = self.energy(cloth);
        if g_ref == 0.0 || e_start > e_zero {
            // Nothing to carry, or a warm start worse than no forces at all (the load changed):
            // start this phase from zero.
            for (e, p) in self.s.p.iter_mut().enumerate() {
                if in_phase(e) {
                    *p = 0.0;
                }
            }
            self.gather(cloth, diagonals);
            e_start = e_zero;
            if g_ref == 0.0 {
                return 0;
            }
        }
        let tol = params.internal_tolerance * factor * g_ref;
        self.s.p_prev.copy_from_slice(&self.s.p);
        self.s.p_warm.copy_from_slice(&self.s.p);
        let mut e_old = e_start;
        let mut iterations = 0;
        match params.internal_method {
            InternalMethod::SteepestDescent => {
                while iterations < params.internal_max_iterations {
                    self.gradient(cloth, diagonals);
                    if self.projected_gradient_norm(cloth, diagonals, false) <= tol {
                        break;
                    }
                    iterations += 1;
                    self.s.p_prev.copy_from_slice(&self.s.p);
                    let (grad, p) = (&self.s.grad, &mut self.s.p);
                    for (e, pe) in p.iter_mut().enumerate() {
                        if in_phase(e) {
                            *pe = (*pe - gamma * grad[e]).max(0.0);
                        }
                    }
                    self.gather(cloth, diagonals);
                    let e_new = self.energy(cloth);
                    if e_new > e_old * (1.0 + 1e-12) {
                        // Step too long for this geometry: back off and re-estimate next step.
                        self.s.p.copy_from_slice(&self.s.p_prev);
                        self.gather(cloth, diagonals);
                        gamma *= 0.5;
                        self.lambda = None;
                        continue;
                    }
                    e_old = e_new;
                }
            }
            InternalMethod::Accelerated => {
                iterations = self.accelerated_phase(cloth, params, diagonals, gamma, tol);
                self.gather(cloth, diagonals);
                if self.energy(cloth) > e_start * (1.0 + 1e-9) {
                    // Worse than the warm start (a step too long for this geometry): keep the
                    // warm start and re-estimate the step next time.
                    self.s.p.copy_from_slice(&self.s.p_warm);
                    self.gather(cloth, diagonals);
                    self.lambda = None;
                }
            }
        }
        iterations
    }

    /// The accelerated internal-force iterations of one phase: FISTA with gradient restart
    /// (O'Donoghue & Candès 2015) on compact arrays of the phase's edges, three passes per
    /// iteration (gather at the extrapolated point; one fused pass for the gradient, the
    /// projected step, the optimality measure and the restart test; the next extrapolation),
    /// all parallel with deterministic chunked reductions. Writes the phase's forces back into
    /// `s.p`; returns the iterations.
    fn accelerated_phase(
        &mut self,
        cloth: &Cloth,
        params: &StepParams,
        diagonals: bool,
        gamma: f64,
        tol: f64,
    ) -> usize {
        let list: &[u32] = if diagonals {
            cloth.diagonal_edge_list()
        } else {
            cloth.axial_edge_list()
        };
        let m = list.len();
        let slots = cloth.phase_slots();
        let edges = cloth.topology().edges();
        let inv = cloth.inverse_masses();
        let s = &mut self.s;
        for v in [&mut s.ph_p, &mut s.ph_prev, &mut s.ph_y] {
            v.clear();
            v.extend(list.iter().map(|&e| s.p[e as usize]));
        }
        let chunks = m.div_ceil(SUM_CHUNK);
        resize(&mut s.ph_partial, chunks, [0.0; 2]);
        let mut t: f64 = 1.0;
        let mut iterations = 0;
        while iterations < params.internal_max_iterations {
            // F^m at y: the phase's forces from y, the other phase's from p (fixed).
            {
                let (y, p, dir, f_sum) = (&s.ph_y, &s.p, &s.dir, &s.f_sum);
                fill(&mut s.f_m, |i| {
                    let mut f = f_sum[i];
                    for inc in cloth.incidence(i) {
                        let e = inc.edge as usize;
                        let force = if inc.axial != diagonals {
                            y[slots[e] as usize]
                        } else if diagonals {
                            p[e]
                        } else {
                            continue;
                        };
                        f += dir[e] * (inc.sign * force);
                    }
                    f
                });
            }
            // Fused: gradient at y, projected step, optimality and restart measures.
            {
                let (f_m, dir, y) = (&s.f_m, &s.dir, &s.ph_y);
                let body = |(c, ((p, prev), out)): ChunkItem<'_>| {
                    let (mut norm2, mut restart) = (0.0, 0.0);
                    for (k, (pk, prevk)) in p.iter_mut().zip(prev.iter_mut()).enumerate() {
                        let idx = c * SUM_CHUNK + k;
                        let e = list[idx] as usize;
                        let (a, b) = (edges[e].a as usize, edges[e].b as usize);
                        let fa = if inv[a] > 0.0 { f_m[a] } else { V3::zeros() };
                        let fb = if inv[b] > 0.0 { f_m[b] } else { V3::zeros() };
                        let g = (fa - fb).dot(&dir[e]);
                        let yk = y[idx];
                        let pg = if yk > 0.0 { g } else { g.min(0.0) };
                        norm2 += pg * pg;
                        let new = (yk - gamma * g).max(0.0);
                        restart += (yk - new) * (new - *pk);
                        *prevk = *pk;
                        *pk = new;
                    }
                    *out = [norm2, restart];
                };
                let zipped = s
                    .ph_p
                    .par_chunks_mut(SUM_CHUNK)
                    .zip(s.ph_prev.par_chunks_mut(SUM_CHUNK))
                    .zip(s.ph_partial.par_iter_mut());
                if m >= PAR_MIN {
                    zipped.enumerate().for_each(body);
                } else {
                    s.ph_p
                        .chunks_mut(SUM_CHUNK)
                        .zip(s.ph_prev.chunks_mut(SUM_CHUNK))
                        .zip(s.ph_partial.iter_mut())
                        .enumerate()
                        .for_each(body);
                }
            }
            let (norm2, restart) = s
                .ph_partial
                .iter()
                .fold((0.0, 0.0), |a, b| (a.0 + b[0], a.1 + b[1]));
            iterations += 1;
            if norm2.sqrt() <= tol {
                break;
            }
            let t_next = 0.5 * (1.0 + (1.0 + 4.0 * t * t).sqrt());
            let beta = if restart > 0.0 {
                0.0
            } else {
                (t - 1.0) / t_next
            };
            t = if restart > 0.0 { 1.0 } else { t_next };
            let (p, prev) = (&s.ph_p, &s.ph_prev);
            fill(&mut s.ph_y, |k| (p[k] + beta * (p[k] - prev[k])).max(0.0));
        }
        for (k, &e) in list.iter().enumerate() {
            s.p[e as usize] = s.ph_p[k];
        }
        iterations
    }

    /// Norm of the projected gradient over one phase's edges (components pushing a zero force
    /// below zero do not count): zero exactly at the constrained minimum. `at_y`: the forces
    /// are those of the extrapolated point.
    fn projected_gradient_norm(&self, cloth: &Cloth, diagonals: bool, at_y: bool) -> f64 {
        let edges = cloth.topology().edges();
        let p = if at_y { &self.s.p_y } else { &self.s.p };
        let g = &self.s.grad;
        (0..edges.len())
            .filter(|&e| edges[e].kind.is_axial() != diagonals)
            .map(|e| if p[e] > 0.0 { g[e] } else { g[e].min(0.0) })
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt()
    }

    /// (18): ṙ⁰ = (μṙ + F^m Δt)/(μ + cΔt), with the bending stiffness k added implicitly along
    /// the normal, (μ + cΔt + kΔt²). Pinned nodes take their prescribed velocity.
    fn unconstrained_velocity(&mut self, cloth: &Cloth, state: &ClothState, params: &StepParams) {
        let dt = params.dt;
        let (mass, areas) = (cloth.masses(), cloth.topology().node_areas());
        let axial = cloth.topology().axial_neighbours();
        let implicit = params.implicit_bending && !params.bending_off;
        let s = &mut self.s;
        let (f_m, normal) = (&s.f_m, &s.normal);
        let (vel0, pos) = (&state.velocities, &state.positions);
        fill(&mut s.vel, |i| {
            if cloth.is_pinned(i) {
                return V3::zeros();
            }
            let mu = mass[i];
            let c = params.damping * areas[i];
            (vel0[i] * mu + f_m[i] * dt) / (mu + c * dt)
        });
        let t1 = state.time + dt;
        for pin in cloth.pins() {
            let i = pin.node as usize;
            s.vel[i] = (pin.position(t1) - pos[i]) / dt;
        }
        if !implicit {
            return;
        }
        // Implicit bending along the normals, linearised (method §2: explicit bending limits Δt
        // to ~2√(μ/k), k ≈ 16WB/h³, which scales with h²). Unknowns: the normal speeds w of the
        // free nodes; (μ + cΔt) w − Δt² K w = (μ + cΔt) n·ṙ_explicit, K the bending stiffness
        // for normal displacements (the same stencil as the force, with B), solved by
        // Jacobi-preconditioned CG. Statics are unchanged; rigid motions have K w = 0.
        let k_apply = |w: &[f64],
                       dm: &mut [f64],
                       out: &mut [f64],
                       s_coef: &[[f64; SLOTS]],
                       s_len: &[[f64; SLOTS]]| {
            fill(dm, |i| {
                let mut m = 0.0;
                for k in 0..SLOTS {
                    let a = axial[i][k];
                    if a == NO_NODE || s_coef[i][k] == 0.0 {
                        continue;
                    }
                    let l = s_len[i][k];
                    let deta = -2.0 * (w[a as usize] * normal[i].dot(&normal[a as usize]) - w[i])
                        / (l * l);
                    m += s_coef[i][k] * deta;
                }
                m
            });
            let dm: &[f64] = dm;
            fill(out, |i| {
                let mut f = 0.0;
                for k in 0..SLOTS {
                    let a = axial[i][k];
                    if a != NO_NODE {
                        f += (dm[a as usize] - dm[i]) / s_len[i][k];
                    }
                }
                f
            });
        };
        let diag = |i: usize| {
            let (mu, c) = (mass[i], params.damping * areas[i]);
            // Diagonal of −K: each slot's own δη term through M_i and M_a.
            let k: f64 = (0..SLOTS)
                .filter(|&slot| axial[i][slot] != NO_NODE)
                .map(|slot| {
                    let l = s.slot_len[i][slot];
                    2.0 * s.slot_coef[i][slot] / (l * l) * 3.0 / l
                })
                .sum();
            mu + c * dt + dt * dt * k
        };
        let free = |i: usize| !cloth.is_pinned(i);
        let vel = &s.vel;
        fill(&mut s.w, |i| normal[i].dot(&vel[i]));
        // rhs b = (μ + cΔt) w_explicit for free nodes; pinned w stay prescribed (moved to b).
        k_apply(&s.w, &mut s.w_dm, &mut s.w_ap, &s.slot_coef, &s.slot_len);
        for i in 0..s.w.len() {
            let (mu, c) = (mass[i], params.damping * areas[i]);
            // r = b − A w with w = w_explicit: r = Δt² K w (free nodes).
            s.w_r[i] = if free(i) { dt * dt * s.w_ap[i] } else { 0.0 };
            let _ = (mu, c);
        }
        // The stencil is not exactly symmetric at free edges and clamps (the thesis's force is
        // not the gradient of an energy), so the solve is Jacobi-preconditioned BiCGSTAB.
        let n = s.w.len();
        let r0: f64 = s.w_r.iter().map(|x| x * x).sum::<f64>().sqrt();
        if r0 > 0.0 {
            let apply_a = |x: &[f64],
                           dm: &mut [f64],
                           out: &mut [f64],
                           s_coef: &[[f64; SLOTS]],
                           s_len: &[[f64; SLOTS]]| {
                k_apply(x, dm, out, s_coef, s_len);
                for i in 0..x.len() {
                    let (mu, c) = (mass[i], params.damping * areas[i]);
                    out[i] = if free(i) {
                        (mu + c * dt) * x[i] - dt * dt * out[i]
                    } else {
                        0.0
                    };
                }
            };
            let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
            let mut r_hat = std::mem::take(&mut s.w_rhat);
            r_hat.clear();
            r_hat.extend_from_slice(&s.w_r);
            let mut v = std::mem::take(&mut s.w_v);
            let mut y = std::mem::take(&mut s.w_y);
            let mut z = std::mem::take(&mut s.w_z);
            let mut t = std::mem::take(&mut s.w_t);
            for buf in [&mut v, &mut y, &mut z, &mut t] {
                buf.clear();
                buf.resize(n, 0.0);
            }
            let mut rho = 1.0;
            let mut alpha = 1.0;
            let mut omega = 1.0;
            s.w_p.iter_mut().for_each(|x| *x = 0.0);
            for _ in 0..10 {
                let rho_new = dot(&r_hat, &s.w_r);
                if rho_new == 0.0 || omega == 0.0 {
                    break;
                }
                let beta = (rho_new / rho) * (alpha / omega);
                rho = rho_new;
                for i in 0..n {
                    s.w_p[i] = s.w_r[i] + beta * (s.w_p[i] - omega * v[i]);
                    y[i] = if free(i) { s.w_p[i] / diag(i) } else { 0.0 };
                }
                apply_a(&y, &mut s.w_dm, &mut v, &s.slot_coef, &s.slot_len);
                let rv = dot(&r_hat, &v);
                if rv == 0.0 || rv.is_nan() {
                    break;
                }
                alpha = rho / rv;
                for i in 0..n {
                    s.w[i] += alpha * y[i];
                    s.w_r[i] -= alpha * v[i];
                }
                if dot(&s.w_r, &s.w_r).sqrt() <= 1e-4 * r0 {
                    break;
                }
                for (i, zi) in z.iter_mut().enumerate() {
                    *zi = if free(i) { s.w_r[i] / diag(i) } else { 0.0 };
                }
                apply_a(&z, &mut s.w_dm, &mut t, &s.slot_coef, &s.slot_len);
                let tt = dot(&t, &t);
                omega = if tt > 0.0 { dot(&t, &s.w_r) / tt } else { 0.0 };
                for i in 0..n {
                    s.w[i] += omega * z[i];
                    s.w_r[i] -= omega * t[i];
                }
                if dot(&s.w_r, &s.w_r).sqrt() <= 1e-4 * r0 {
                    break;
                }
            }
            s.w_rhat = r_hat;
            s.w_v = v;
            s.w_y = y;
            s.w_z = z;
            s.w_t = t;
        }
        let w = &s.w;
        for (i, v) in s.vel.iter_mut().enumerate() {
            if free(i) {
                let n = normal[i];
                *v += n * (w[i] - n.dot(v));
            }
        }
    }

    /// Target lengths: axial edges l⁰(1 + φ_θ(p/W)) through their hysteresis state (25); each
    /// cell's diagonals from the cell's axial targets and its shear angle γ(τ),
    /// τ = p₊/D₊ − p₋/D₋ (parallelogram geometry). Returns the number of extrapolated edges.
    fn targets(&mut self, cloth: &Cloth, state: &ClothState, params: &StepParams) -> usize {
        let topo = cloth.topology();
        let edges = topo.edges();
        let (widths, mats, table) = (
            cloth.edge_widths(),
            cloth.edge_materials(),
            cloth.materials(),
        );
        let hysteresis = params.hysteresis && cloth.tensile_hysteretic();
        let s = &mut self.s;
        let p = &s.p;
        fill(&mut s.force_per_width, |e| {
            if edges[e].kind.is_axial() {
                p[e] / widths[e]
            } else {
                0.0
            }
        });
        let fpw = &s.force_per_width;
        let tensile = &state.tensile;
        fill(&mut s.target, |e| {
            let edge = &edges[e];
            if !edge.kind.is_axial() {
                return edge.rest_length;
            }
            let l = table.tensile(mats[e]);
            let strain = if hysteresis {
                tensile[e].strain(l, fpw[e])
            } else {
                l.strain(Branch::Loading, fpw[e])
            };
            edge.rest_length * (1.0 + strain)
        });
        let extrapolated = (0..edges.len())
            .filter(|&e| edges[e].kind.is_axial() && !table.tensile(mats[e]).in_range(fpw[e]))
            .count();
        let shear_curve = cloth.shear_curve();
        let cells = topo.cells();
        let compliant = params.diagonal_constraint == ConstraintKind::Compliant;
        fill(&mut s.shear, |c| {
            if compliant {
                // The spring carries the shear; the targets keep the rest angle.
                return 0.0;
            }
            let cell = &cells[c];
            let [dp, dm] = cell
                .diagonals
                .map(|d| p[d as usize] / edges[d as usize].rest_length);
            shear_curve.angle(dp - dm)
        });
        for (c, cell) in cells.iter().enumerate() {
            let mean =
                |pair: [u32; 2], t: &[f64]| 0.5 * (t[pair[0] as usize] + t[pair[1] as usize]);
            let (a, b) = (mean(cell.u_edges, &s.target), mean(cell.v_edges, &s.target));
            let rest = |pair: [u32; 2]| {
                0.5 * (edges[pair[0] as usize].rest_length + edges[pair[1] as usize].rest_length)
            };
            let (a0, b0) = (rest(cell.u_edges), rest(cell.v_edges));
            let (alpha0, alpha) = (cell.rest_angle, cell.rest_angle - s.shear[c]);
            for (k, sign) in [(0, 1.0), (1, -1.0)] {
                let d = cell.diagonals[k] as usize;
                let now = a * a + b * b + sign * 2.0 * a * b * alpha.cos();
                let rest = a0 * a0 + b0 * b0 + sign * 2.0 * a0 * b0 * alpha0.cos();
                s.target[d] = edges[d].rest_length * (now.max(0.0) / rest).sqrt();
            }
        }
        extrapolated
    }

    /// Shape-constraint iterations (49)–(51): predicted positions r + ṙΔt; per edge the error
    /// C = l − l_target (stretch-only edges: only C > 0); per node R = Σ w_i/(w_i + w_a) C d
    /// and the scaled velocity step ṙ += γ R/(n Δt), n the node's constraint count; plain
    /// (Jacobi) or Chebyshev-accelerated. Stops when RMS(R) < ε^e or at the cap.
    fn shape_iterations(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
        factor: f64,
    ) -> (usize, f64, usize) {
        let topo = cloth.topology();
        let edges = topo.edges();
        let inv = cloth.inverse_masses();
        let dt = params.dt;
        let tol = params.shape_tolerance * factor;
        let free = inv.iter().filter(|&&w| w > 0.0).count().max(1) as f64;
        let mut omega = 1.0;
        let mut residual = 0.0;
        let mut iterations = 0;
        let mut cg_total = 0;
        self.s.vel_prev.copy_from_slice(&self.s.vel);
        self.s.lambda_c.fill(0.0);
        // Contact planes: the Jacobi and Chebyshev node updates apply a node's plane as they
        // compute it (in parallel); the planes of tied nodes, and every plane with the other
        // methods, are applied after the ties in `project`.
        let in_loop = matches!(
            params.shape_method,
            ShapeMethod::Jacobi | ShapeMethod::Chebyshev { .. }
        );
        {
            let s = &mut self.s;
            s.tied.clear();
            s.tied.resize(s.planes.len(), false);
            for t in &s.ties {
                s.tied[t.a as usize] = true;
                s.tied[t.b as usize] = true;
            }
            s.plane_nodes.clear();
            s.plane_nodes
                .extend((0..s.planes.len() as u32).filter(|&i| {
                    s.planes[i as usize].normal != V3::zeros() && (!in_loop || s.tied[i as usize])
                }));
        }
        let stiffness = cloth.diagonal_stiffness();
        // The hard constraints first, so that an iteration that stops at once (the cloth's own
        // constraints already met) still leaves them met.
        Self::project(&mut self.s, cloth, state, dt, true);
        for k in 0..params.shape_max_iterations {
            let s = &mut self.s;
            let (pos, vel, target) = (&state.positions, &s.vel, &s.target);
            let (axial_kind, diagonal_kind) = (params.axial_constraint, params.diagonal_constraint);
            let gamma = params.shape_step;
            // Per edge, at the predicted positions r + ṙΔt: unit direction and length error.
            // A compliant edge (XPBD, α̃ = 1/(k Δt²)) corrects C + α̃λ scaled by w/(w + α̃) and
            // accumulates λ by the part its nodes actually take (γ over their constraint
            // counts); at the fixed point C = −α̃λ, the spring force −kC.
            let edge_error = |(e, ((dir, c), lambda)): (usize, ((&mut V3, &mut f64), &mut f64))| {
                let edge = &edges[e];
                let (a, b) = (edge.a as usize, edge.b as usize);
                let d = (pos[b] - pos[a]) + (vel[b] - vel[a]) * dt;
                let l = d.norm();
                *dir = if l > 0.0 { d / l } else { V3::zeros() };
                let kind = if edge.kind.is_axial() {
                    axial_kind
                } else {
                    diagonal_kind
                };
                *c = match kind {
                    ConstraintKind::Equality => l - target[e],
                    ConstraintKind::StretchOnly => (l - target[e]).max(0.0),
                    ConstraintKind::Compliant => {
                        let w = inv[a] + inv[b];
                        if w == 0.0 {
                            0.0
                        } else {
                            let alpha = 1.0 / (stiffness[e] * dt * dt);
                            let corr = (l - target[e] + alpha * *lambda) * w / (w + alpha);
                            let n =
                                0.5 * (cloth.incidence(a).len() + cloth.incidence(b).len()) as f64;
                            *lambda -= corr * gamma / (n * w);
                            corr
                        }
                    }
                };
            };
            if edges.len() >= PAR_MIN {
                s.cdir
                    .par_iter_mut()
                    .zip(s.c.par_iter_mut())
                    .zip(s.lambda_c.par_iter_mut())
                    .enumerate()
                    .for_each(edge_error);
            } else {
                s.cdir
                    .iter_mut()
                    .zip(s.c.iter_mut())
                    .zip(s.lambda_c.iter_mut())
                    .enumerate()
                    .for_each(edge_error);
            }
            // Per node, one pass: R (49)–(50) and the Jacobi / Chebyshev candidate velocity
            // (a node moves by γ times the mean of its constraints' corrections).
            if let ShapeMethod::Chebyshev { rho } = params.shape_method {
                omega = match k {
                    0 => 1.0,
                    1 => 2.0 / (2.0 - rho * rho),
                    _ => 4.0 / (4.0 - rho * rho * omega),
                };
            }
            let chebyshev = matches!(params.shape_method, ShapeMethod::Chebyshev { .. });
            {
                let (c, cdir, vel, prev, gamma) =
                    (&s.c, &s.cdir, &s.vel, &s.vel_prev, params.shape_step);
                let (planes, tied, pos) = (&s.planes, &s.tied, &state.positions);
                let node = |(i, (r, hat)): (usize, (&mut V3, &mut V3))| {
                    let inc = cloth.incidence(i);
                    let mut sum = V3::zeros();
                    for x in inc {
                        let e = x.edge as usize;
                        sum += cdir[e] * (x.sign * x.share * c[e]);
                    }
                    *r = sum;
                    let candidate = vel[i] + sum * (gamma / (inc.len() as f64 * dt));
                    *hat = if chebyshev {
                        prev[i] + (candidate - prev[i]) * omega
                    } else {
                        candidate
                    };
                    if in_loop && planes[i].normal != V3::zeros() && !tied[i] {
                        *hat = plane_push(*hat, &pos[i], &planes[i], dt);
                    }
                };
                if s.r.len() >= PAR_MIN {
                    s.r.par_iter_mut()
                        .zip(s.vel_hat.par_iter_mut())
                        .enumerate()
                        .for_each(node);
                } else {
                    s.r.iter_mut()
                        .zip(s.vel_hat.iter_mut())
                        .enumerate()
                        .for_each(node);
                }
            }
            let r = &s.r;
            // The residual (a full reduction) is checked every fourth iteration and at the cap.
            if k % 4 == 0 || k + 1 == params.shape_max_iterations {
                residual = (det_sum(&mut s.chunk, r.len(), |i| r[i].norm_squared()) / free).sqrt();
                if residual < tol {
                    break;
                }
            }
            iterations += 1;
            match params.shape_method {
                ShapeMethod::Newton {
                    cg_iterations,
                    cg_tolerance,
                } => {
                    cg_total += Self::newton_projection(s, cloth, dt, cg_iterations, cg_tolerance);
                }
                ShapeMethod::GaussSeidel { omega } => {
                    for colour in 0..cloth.colour_count() {
                        let (vel, pos, target) = (&s.vel, &state.positions, &s.target);
                        fill(&mut s.vel_hat, |i| {
                            let e = cloth.colour_edge(i, colour);
                            if e == NO_NODE || inv[i] == 0.0 {
                                return vel[i];
                            }
                            let edge = &edges[e as usize];
                            let (a, b) = (edge.a as usize, edge.b as usize);
                            let d = (pos[b] + vel[b] * dt) - (pos[a] + vel[a] * dt);
                            let l = d.norm();
                            let kind = if edge.kind.is_axial() {
                                params.axial_constraint
                            } else {
                                params.diagonal_constraint
                            };
                            let mut c = l - target[e as usize];
                            match kind {
                                ConstraintKind::StretchOnly => c = c.max(0.0),
                                // Rejected by `StepParams::validate`.
                                ConstraintKind::Compliant | ConstraintKind::Equality => {}
                            }
                            if l == 0.0 || c == 0.0 {
                                return vel[i];
                            }
                            let (wa, wb) = (inv[a], inv[b]);
                            let delta = omega * c / (wa + wb);
                            let sign = if i == a { wa } else { -wb };
                            vel[i] + d * (sign * delta / (l * dt))
                        });
                        std::mem::swap(&mut s.vel, &mut s.vel_hat);
                    }
                }
                ShapeMethod::Jacobi => std::mem::swap(&mut s.vel, &mut s.vel_hat),
                ShapeMethod::Chebyshev { .. } => {
                    // prev ← current, current ← new.
                    std::mem::swap(&mut s.vel_prev, &mut s.vel);
                    std::mem::swap(&mut s.vel, &mut s.vel_hat);
                }
            }
            Self::project(s, cloth, state, dt, false);
            if k % 4 == 3 {
                self.project_pressure(cloth, state, dt);
            }
        }
        self.project_pressure(cloth, state, dt);
        (iterations, residual, cg_total)
    }

    /// The air's pressure at the end of the step as a constraint on the velocities (when a
    /// pressure stage is on), then the hard constraints again; timed into `pressure_time`.
    fn project_pressure(&mut self, cloth: &Cloth, state: &ClothState, dt: f64) {
        if let Some(p) = &mut self.pressure {
            let t0 = Instant::now();
            let s = &mut self.s;
            s.pred.copy_from_slice(&s.vel);
            p.project(&state.positions, cloth.inverse_masses(), dt, &mut s.vel);
            // The Chebyshev iteration extrapolates from the previous iterate: move it by the same
            // change, so that the pressure's correction is not over-relaxed.
            for ((prev, v), before) in s.vel_prev.iter_mut().zip(&s.vel).zip(&s.pred) {
                *prev += v - before;
            }
            Self::project(s, cloth, state, dt, true);
            self.s.pressure_time += t0.elapsed();
        }
    }

    /// The hard constraints every shape iteration ends with: pins at their prescribed
    /// positions, ties (a pair farther apart than its length drawn together along its line,
    /// each node by its share of the inverse mass: momentum kept), and contact planes (no node
    /// ends the step behind its plane), in that order. `every_plane`: every node's plane, not
    /// only those the node update leaves to this pass.
    fn project(s: &mut Scratch, cloth: &Cloth, state: &ClothState, dt: f64, every_plane: bool) {
        let inv = cloth.inverse_masses();
        for pin in cloth.pins() {
            let i = pin.node as usize;
            let v = (pin.position(state.time + dt) - state.positions[i]) / dt;
            s.vel[i] = v;
            s.vel_prev[i] = v;
        }
        if s.long_range_on
            && let Some(lr) = &mut s.long_range
        {
            lr.project(
                cloth,
                &state.positions,
                &mut s.vel,
                state.time + dt,
                dt,
                s.long_range_slack,
            );
        }
        for tie in &s.ties {
            let (a, b) = (tie.a as usize, tie.b as usize);
            let ws = inv[a] + inv[b];
            if ws <= 0.0 {
                continue;
            }
            let gap = (state.positions[b] + s.vel[b] * dt) - (state.positions[a] + s.vel[a] * dt);
            let l = gap.norm();
            if l <= tie.length {
                continue;
            }
            let shift = gap * ((l - tie.length) / (l * ws * dt));
            s.vel[a] += shift * inv[a];
            s.vel[b] -= shift * inv[b];
        }
        if every_plane {
            for i in 0..s.planes.len() {
                if s.planes[i].normal != V3::zeros() {
                    s.vel[i] = plane_push(s.vel[i], &state.positions[i], &s.planes[i], dt);
                }
            }
        } else {
            for &i in &s.plane_nodes {
                let i = i as usize;
                s.vel[i] = plane_push(s.vel[i], &state.positions[i], &s.planes[i], dt);
            }
        }
    }

    /// Switch the long-range attachments on for this step when asked for and the cloth has pins
    /// (building them when the pins changed), with the step's largest target strain as slack.
    fn prepare_long_range(&mut self, cloth: &Cloth, params: &StepParams) {
        let s = &mut self.s;
        s.long_range_on = params.long_range_attachments && !cloth.pins().is_empty();
        if !s.long_range_on {
            return;
        }
        if !s.long_range.as_ref().is_some_and(|lr| lr.matches(cloth)) {
            s.long_range = Some(crate::long_range::LongRange::build(cloth));
        }
        let edges = cloth.topology().edges();
        s.long_range_slack = s
            .target
            .iter()
            .zip(edges)
            .map(|(t, e)| t / e.rest_length - 1.0)
            .fold(0.0, f64::max);
    }

    /// One Gauss–Newton step on the shape objective E^e = ½ Σ (l − l_target)² (49): the
    /// correction δx minimising |C + J δx|² (J at the predicted positions) with the least change
    /// in the mass metric, found by Jacobi-preconditioned CG on
    /// `(W^½ JᵀJ W^½ + εI) y = −W^½ Jᵀ C`, `δx = W^½ y` (pinned nodes have W = 0 and do not
    /// move); then ṙ += δx/Δt. Unlike the dual (λ) form this stays well posed when the
    /// 8-neighbourhood's targets are not exactly compatible. Uses `s.c` and `s.cdir` as computed
    /// for the residual; returns the CG iterations.
    fn newton_projection(
        s: &mut Scratch,
        cloth: &Cloth,
        dt: f64,
        max_cg: usize,
        cg_tol: f64,
    ) -> usize {
        let topo = cloth.topology();
        let inv = cloth.inverse_masses();
        let n = inv.len();
        let sqrt_w = |i: usize| inv[i].sqrt();
        // Levenberg regularisation, tiny against the operator's diagonal (~ w·degree).
        let mean_diag = inv.iter().map(|w| w * 8.0).sum::<f64>() / n as f64;
        let eps = 1e-10 * mean_diag;
        // out = (W^½ Jᵀ J W^½ + ε) y, with q_e = J_e W^½ y.
        fn apply(
            cloth: &Cloth,
            inv: &[f64],
            cdir: &[V3],
            eps: f64,
            y: &[V3],
            q: &mut [f64],
            out: &mut [V3],
        ) {
            let edges = cloth.topology().edges();
            fill(q, |e| {
                let (a, b) = (edges[e].a as usize, edges[e].b as usize);
                cdir[e].dot(&(y[b] * inv[b].sqrt() - y[a] * inv[a].sqrt()))
            });
            let q: &[f64] = q;
            fill(out, |i| {
                jacobian_transpose(cloth, cdir, q, i) * inv[i].sqrt() + y[i] * eps
            });
        }
        let (c, cdir) = (&s.c, &s.cdir);
        // rhs = −W^½ Jᵀ C, kept in r; x (here `pred` reused as y) starts at 0.
        fill(&mut s.r, |i| {
            -jacobian_transpose(cloth, cdir, c, i) * sqrt_w(i)
        });
        let diag = |i: usize| inv[i] * topo.incident_edges(i).len() as f64 * 0.5 + eps;
        s.pred.iter_mut().for_each(|y| *y = V3::zeros());
        {
            let (r, z) = (&s.r, &mut s.vel_hat);
            fill(z, |i| r[i] / diag(i));
        }
        s.vel_prev.copy_from_slice(&s.vel_hat); // search direction p
        let (r, z) = (&s.r, &s.vel_hat);
        let mut rz = det_sum(&mut s.chunk, n, |i| r[i].dot(&z[i]));
        let r0 = det_sum(&mut s.chunk, n, |i| r[i].norm_squared()).sqrt();
        let mut iterations = 0;
        if r0 > 0.0 {
            while iterations < max_cg {
                iterations += 1;
                apply(
                    cloth,
                    inv,
                    &s.cdir,
                    eps,
                    &s.vel_prev,
                    &mut s.cg_q,
                    &mut s.cg_y,
                );
                let (p, ap) = (&s.vel_prev, &s.cg_y);
                let pap = det_sum(&mut s.chunk, n, |i| p[i].dot(&ap[i]));
                if pap.is_nan() || pap <= 0.0 {
                    break;
                }
                let alpha = rz / pap;
                for i in 0..n {
                    s.pred[i] += s.vel_prev[i] * alpha;
                    s.r[i] -= s.cg_y[i] * alpha;
                }
                let r = &s.r;
                let rn = det_sum(&mut s.chunk, n, |i| r[i].norm_squared()).sqrt();
                if rn <= cg_tol * r0 {
                    break;
                }
                {
                    let (r, z) = (&s.r, &mut s.vel_hat);
                    fill(z, |i| r[i] / diag(i));
                }
                let (r, z) = (&s.r, &s.vel_hat);
                let rz_new = det_sum(&mut s.chunk, n, |i| r[i].dot(&z[i]));
                let beta = rz_new / rz;
                rz = rz_new;
                for i in 0..n {
                    s.vel_prev[i] = s.vel_hat[i] + s.vel_prev[i] * beta;
                }
            }
        }
        for i in 0..n {
            s.vel[i] += s.pred[i] * (sqrt_w(i) / dt);
        }
        iterations
    }

    /// Commit the hysteresis states at this step's forces and curvatures.
    fn commit_hysteresis(&mut self, cloth: &Cloth, state: &mut ClothState, params: &StepParams) {
        if !params.hysteresis {
            return;
        }
        let topo = cloth.topology();
        let (edges, mats, table) = (topo.edges(), cloth.edge_materials(), cloth.materials());
        if cloth.tensile_hysteretic() {
            let fpw = &self.s.force_per_width;
            for (e, st) in state.tensile.iter_mut().enumerate() {
                if edges[e].kind.is_axial() {
                    st.update(table.tensile(mats[e]), fpw[e]);
                }
            }
        }
        if cloth.bending_hysteretic() && !params.bending_off {
            let (axial, smats, eta) =
                (topo.axial_neighbours(), cloth.slot_materials(), &self.s.eta);
            for (i, slots) in state.bending.iter_mut().enumerate() {
                for (k, st) in slots.iter_mut().enumerate() {
                    if axial[i][k] != NO_NODE {
                        let spindle = regularised(
                            table.bending(smats[i][k]),
                            params.bending_stick_slope,
                            params.bending_deadband,
                        );
                        st.update(&spindle, eta[i][k]);
                    }
                }
            }
        }
    }

    /// Largest |ε − ε̄| after the update (stretch-only edges count only excess stretch).
    fn max_strain_error(&self, cloth: &Cloth, state: &ClothState, params: &StepParams) -> f64 {
        let edges = cloth.topology().edges();
        let pos = &state.positions;
        edges
            .iter()
            .enumerate()
            .map(|(e, edge)| {
                let l = (pos[edge.b as usize] - pos[edge.a as usize]).norm();
                let err = (l - self.s.target[e]) / edge.rest_length;
                let kind = if edge.kind.is_axial() {
                    params.axial_constraint
                } else {
                    params.diagonal_constraint
                };
                match kind {
                    ConstraintKind::Equality => err.abs(),
                    ConstraintKind::StretchOnly => err.max(0.0),
                    // A spring: its stretch is the shear, not an error.
                    ConstraintKind::Compliant => 0.0,
                }
            })
            .fold(0.0, f64::max)
    }
}
