//! The explicit mass-spring cloth of Yamada's wet-cloth thesis (`method.md` §5), on the PARTY
//! topology: a particle per node, a Hooke spring on every edge of the 8-neighbourhood (axial and
//! diagonal), `F_s = Σ D_i k (d_i − l_i)` (Y3.6), and position Verlet integration
//! `P_{t+1} = 2P_t − P_{t−1} + (F_t/m)Δt²` (Y3.1).
//!
//! Forces on a free node: gravity `μg`, the springs `k(l − l⁰)` along each edge (tension and
//! compression alike, as Hooke's law has it), linear damping `−c·S·ṙ` with `c` the damping per
//! area (as [`crate::StepParams::damping`]) and `ṙ` the state's velocity, and optionally the
//! isometric bending hinges described in [`crate::baselines`] (off by default: Yamada's model
//! has no bending). Spring stiffness from the fabric: `k = W·E/l⁰`, see [`crate::baselines`].
//! Contact, friction and air pressure (Y3.2)–(Y3.10) are not part of the baseline itself; a scene
//! adds them through [`SpringExtras`] ([`MassSpring::step_with_extras`]; the wet cloth of
//! [`crate::wet`]), or through the PARTY step's [`CollisionHook`] ([`MassSpring::step_with`]:
//! the garment pipeline's seams and body contact, see [`crate::baselines`]).
//!
//! Substeps ([`MassSpringParams::substeps`], default 1): a step of length Δt is `substeps`
//! Verlet steps of Δt/substeps, so that a scene stepping at Δt = 0.01 s (the garment pipeline,
//! whose body is posed and whose hooks run once per step) can run the explicit model at the
//! 10⁻⁴ s it needs. With one substep the step is exactly the model above.
//!
//! Time stepping. The positions of the previous step are kept in the solver (position Verlet
//! needs `P_{t−1}`); the velocity written back is `(P_{t+1} − P_t)/Δt`, the mid-step velocity.
//! The first step after construction or [`MassSpring::reset`], or on a state whose time or Δt
//! is not the one this solver last committed, starts the recursion from the state's velocity
//! with the Taylor start `P_1 = P_0 + ṙ_0Δt + ½(F_0/m)Δt²`, i.e. `P_{−1} = P_0 − ṙ_0Δt + ½(F_0/m)Δt²`
//! (starting from `P_0 − ṙ_0Δt` alone would put a first-order error `½gΔt·t` on free fall).
//! Pinned nodes are set to their prescribed positions `Pin::position(t + Δt)`.
//!
//! Stability is explicit: see [`MassSpring::largest_stable_dt_estimate`].

use serde::{Deserialize, Serialize};

use std::time::Instant;

use super::{
    BaselineReport, Hinge, HookState, V3, check_input, fill_hinges, fill_stiffness,
    first_non_finite, non_finite, report, resize,
};
use crate::cloth::Cloth;
use crate::params::{ParamError, StepInput, check, check_damping};
use crate::state::ClothState;
use crate::step::{CollisionHook, NoCollision, Stage, StageTimings, StepError};

/// Parameters of the mass-spring baseline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MassSpringParams {
    /// Linear damping per area c (force −c·S·ṙ on a node of area S), kg/(m²·s). Range
    /// [0, 1000]; default 0.2 (as [`crate::StepParams::damping`]).
    pub damping: f64,
    /// Reference force of the secant spring stiffness as a fraction of each loop's apex force
    /// (see [`crate::baselines`]). Range (0, 1]; default 0.01.
    pub reference_force_fraction: f64,
    /// Add the isometric bending hinges of [`crate::baselines`] with the fabric's rigidity B.
    /// Default false (Yamada's model has no bending).
    pub bending: bool,
    /// Divergence guard: a step that starts with a spring stretched or shrunk by more than
    /// this strain (|l/l⁰ − 1|) fails with `StepError::Diverged` and keeps the state. Range
    /// above 0; default 10 (Yamada's soft springs legitimately reach strains of 2–3 under a
    /// vacuum; a spring eleven times its length has diverged).
    pub divergence_strain: f64,
    /// Verlet steps per step (each of Δt/substeps; the stability limit applies to that).
    /// Range [1, 100000]; default 1.
    pub substeps: usize,
}

impl Default for MassSpringParams {
    fn default() -> Self {
        Self {
            damping: 0.2,
            reference_force_fraction: 0.01,
            bending: false,
            divergence_strain: 10.0,
            substeps: 1,
        }
    }
}

impl MassSpringParams {
    /// Check every field against its range.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_damping(self.damping)?;
        check(
            "reference_force_fraction",
            self.reference_force_fraction,
            self.reference_force_fraction > 0.0 && self.reference_force_fraction <= 1.0,
            "(0, 1]",
        )?;
        check(
            "divergence_strain",
            self.divergence_strain,
            self.divergence_strain > 0.0,
            "> 0",
        )?;
        check(
            "substeps",
            self.substeps as f64,
            (1..=100_000).contains(&self.substeps),
            "[1, 100000]",
        )
    }

    /// The length of one Verlet step of a step of `dt`, Δt/substeps, s.
    pub fn substep(&self, dt: f64) -> f64 {
        dt / self.substeps as f64
    }
}

/// Forces and contacts a scene adds to the mass-spring step ([`MassSpring::step_with_extras`]).
/// With substeps, both are called in every substep with the substep's length and the state at
/// its start.
pub trait SpringExtras {
    /// Add forces at the start of the step, after the springs, gravity and damping (`forces`
    /// holds their sum; an extra that depends on the total, such as a normal force, sees it).
    fn add_forces(&mut self, cloth: &Cloth, state: &ClothState, dt: f64, forces: &mut [V3]);
    /// Correct the positions `next` the Verlet update computed from `state` (contacts,
    /// friction); pinned nodes must be left where they are.
    fn correct(&mut self, cloth: &Cloth, state: &ClothState, dt: f64, next: &mut [V3]);
}

/// No extras: the plain baseline.
pub struct NoExtras;

impl SpringExtras for NoExtras {
    fn add_forces(&mut self, _: &Cloth, _: &ClothState, _: f64, _: &mut [V3]) {}
    fn correct(&mut self, _: &Cloth, _: &ClothState, _: f64, _: &mut [V3]) {}
}

/// The time and Δt of the last committed step (bit patterns), for which `previous` holds P_{t−1}.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct History {
    time: u64,
    dt: u64,
}

/// The mass-spring Verlet baseline: the previous positions of the Verlet recursion and reusable
/// scratch buffers; the simulation state is passed in explicitly.
#[derive(Clone, Debug, Default)]
pub struct MassSpring {
    stiffness: Vec<f64>,
    /// The stiffness was given ([`MassSpring::with_stiffness`]), not taken from the fabric.
    given: bool,
    hinges: Vec<Hinge>,
    force: Vec<V3>,
    next: Vec<V3>,
    velocity: Vec<V3>,
    previous: Vec<V3>,
    history: Option<History>,
    /// The collision hook's ties, planes and exit velocities over a step.
    hook: HookState,
    /// The state before the step (restored on error) when it has several substeps or a hook.
    backup: Option<Backup>,
}

/// What a step with substeps changes before it can fail.
#[derive(Clone, Debug, Default)]
struct Backup {
    positions: Vec<V3>,
    velocities: Vec<V3>,
    time: f64,
    previous: Vec<V3>,
    history: Option<History>,
}

impl MassSpring {
    /// A solver with empty scratch and no history.
    pub fn new() -> Self {
        Self::default()
    }

    /// A solver whose springs have the given stiffness, one per edge of the cloth it will step
    /// (N/m), instead of the fabric's secant stiffness: Yamada's hand-set springs.
    pub fn with_stiffness(stiffness: Vec<f64>) -> Self {
        Self {
            stiffness,
            given: true,
            ..Self::default()
        }
    }

    /// The spring stiffness of every edge in the last step, N/m.
    pub fn stiffness(&self) -> &[f64] {
        &self.stiffness
    }

    /// Forget the previous positions: the next step starts the Verlet recursion afresh from the
    /// state's positions and velocities (call after changing a state from outside the solver
    /// without changing its time).
    pub fn reset(&mut self) {
        self.history = None;
    }

    /// One step of length Δt. On error the state is unchanged.
    pub fn step(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &MassSpringParams,
        input: StepInput,
    ) -> Result<BaselineReport, StepError> {
        self.step_full(cloth, state, params, input, &mut NoExtras, &mut NoCollision)
    }

    /// One step with a scene's extra forces and contacts. On error the state is unchanged.
    pub fn step_with_extras(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &MassSpringParams,
        input: StepInput,
        extras: &mut dyn SpringExtras,
    ) -> Result<BaselineReport, StepError> {
        self.step_full(cloth, state, params, input, extras, &mut NoCollision)
    }

    /// One step with a collision hook, as the PARTY step drives it ([`crate::baselines`],
    /// "Collisions and seams"): `transfer` once before the substeps with the step's Δt (a
    /// velocity change it makes enters the Verlet recursion), its ties and contact planes
    /// applied as position corrections after the Verlet update of every substep, `resolve`
    /// once after the last. On error the state is unchanged.
    pub fn step_with(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &MassSpringParams,
        input: StepInput,
        hook: &mut dyn CollisionHook,
    ) -> Result<BaselineReport, StepError> {
        self.step_full(cloth, state, params, input, &mut NoExtras, hook)
    }

    fn step_full(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &MassSpringParams,
        input: StepInput,
        extras: &mut dyn SpringExtras,
        hook: &mut dyn CollisionHook,
    ) -> Result<BaselineReport, StepError> {
        let t_start = Instant::now();
        params.validate()?;
        input.validate()?;
        check_input(cloth, state)?;
        let time = state.time;
        let h = params.substep(input.dt);
        let mut backup = self.backup.take().unwrap_or_default();
        backup.positions.clone_from(&state.positions);
        backup.velocities.clone_from(&state.velocities);
        backup.time = time;
        backup.previous.clone_from(&self.previous);
        backup.history = self.history;
        let result = self.substeps(cloth, state, params, input, extras, hook, &backup, h);
        let out = match result {
            Ok(mut timings) => {
                let tu = Instant::now();
                let mut r = report(cloth, state, params.substeps);
                timings.update += tu.elapsed();
                timings.velocity = t_start.elapsed().saturating_sub(
                    timings.transfer + timings.shape + timings.collision + timings.update,
                );
                r.timings = timings;
                Ok(r)
            }
            Err(e) => {
                state.positions.copy_from_slice(&backup.positions);
                state.velocities.copy_from_slice(&backup.velocities);
                state.time = backup.time;
                self.previous.clone_from(&backup.previous);
                self.history = backup.history;
                Err(e)
            }
        };
        self.backup = Some(backup);
        out
    }

    /// The hook's transfer, the substeps with the ties and planes, the hook's resolve; the
    /// state changes as it goes (the caller restores it on error).
    #[allow(clippy::too_many_arguments)]
    fn substeps(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &MassSpringParams,
        input: StepInput,
        extras: &mut dyn SpringExtras,
        hook: &mut dyn CollisionHook,
        start: &Backup,
        h: f64,
    ) -> Result<StageTimings, StepError> {
        let mut timings = StageTimings::default();
        let (dt, time) = (input.dt, state.time);
        let n = cloth.topology().node_count();
        let inv = cloth.inverse_masses();

        // The hook's transfer, at the start of the step: a velocity change is also a change of
        // the previous position the Verlet recursion continues from.
        let tc = Instant::now();
        let continuing = self.history
            == Some(History {
                time: time.to_bits(),
                dt: h.to_bits(),
            })
            && self.previous.len() == n;
        resize(&mut self.velocity, n, V3::zeros());
        self.velocity.copy_from_slice(&state.velocities);
        self.hook
            .transfer(hook, cloth, &state.positions, &mut self.velocity, dt, time);
        if let Some(i) = first_non_finite(&self.velocity) {
            return Err(non_finite(Stage::Collision, "velocity", "node", i, time));
        }
        for i in 0..n {
            let (after, before) = (self.velocity[i], state.velocities[i]);
            if after != before {
                if continuing {
                    self.previous[i] -= (after - before) * h;
                }
                state.velocities[i] = after;
            }
        }
        timings.transfer = tc.elapsed();

        for k in 0..params.substeps {
            let frac = (k + 1) as f64 / params.substeps as f64;
            self.verlet(
                cloth,
                state,
                params,
                input.gravity_vector(),
                extras,
                h,
                frac,
                dt * (1.0 - frac),
                &mut timings,
            )?;
        }
        if params.substeps > 1 {
            // The substeps' times summed to time + Δt up to rounding: the step ends at it.
            state.time = time + dt;
            self.history = Some(History {
                time: state.time.to_bits(),
                dt: h.to_bits(),
            });
        }

        // The hook's collision pass over the whole step.
        let tc = Instant::now();
        if let Some(dv) = self.hook.resolve(
            hook,
            cloth,
            &start.positions,
            &mut state.positions,
            dt,
            time,
        ) {
            for i in 0..n {
                if dv[i] != V3::zeros() && inv[i] > 0.0 {
                    state.velocities[i] += dv[i];
                    // The recursion continues with the new velocity.
                    self.previous[i] = state.positions[i] - state.velocities[i] * h;
                }
            }
        }
        if let Some(i) =
            first_non_finite(&state.positions).or_else(|| first_non_finite(&state.velocities))
        {
            return Err(non_finite(Stage::Collision, "velocity", "node", i, time));
        }
        timings.collision = tc.elapsed();
        Ok(timings)
    }

    /// One Verlet step of length `h` under gravity `g` from the state, committed into it; then
    /// the hook's ties and planes (`frac` of the step done, `t_left` to its end).
    #[allow(clippy::too_many_arguments)]
    fn verlet(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &MassSpringParams,
        g: V3,
        extras: &mut dyn SpringExtras,
        h: f64,
        frac: f64,
        t_left: f64,
        timings: &mut StageTimings,
    ) -> Result<(), StepError> {
        let topo = cloth.topology();
        let n = topo.node_count();
        let (dt, time) = (h, state.time);
        resize(&mut self.force, n, V3::zeros());
        resize(&mut self.next, n, V3::zeros());
        resize(&mut self.velocity, n, V3::zeros());
        if !self.given {
            fill_stiffness(cloth, params.reference_force_fraction, &mut self.stiffness);
        } else if self.stiffness.len() != topo.edges().len() {
            return Err(StepError::Mismatch {
                what: "spring stiffnesses",
                expected: topo.edges().len(),
                found: self.stiffness.len(),
            });
        }
        let (pos, vel) = (&state.positions, &state.velocities);

        // 1. Bending hinges (optional).
        self.force.fill(V3::zeros());
        if params.bending {
            fill_hinges(cloth, &mut self.hinges);
            for h in &self.hinges {
                let d = h.curvature(pos);
                for (&node, &w) in h.nodes.iter().zip(&h.weights) {
                    self.force[node as usize] -= d * (h.stiffness * w);
                }
            }
            if let Some(i) = first_non_finite(&self.force) {
                return Err(non_finite(Stage::Bending, "bending force", "node", i, time));
            }
        }

        // 2. Springs (Y3.6), gravity, damping.
        let mut worst = (0, 0.0);
        for (e, (edge, &k)) in topo.edges().iter().zip(&self.stiffness).enumerate() {
            let (a, b) = (edge.a as usize, edge.b as usize);
            let d = pos[b] - pos[a];
            let l = d.norm();
            let strain = (l - edge.rest_length).abs() / edge.rest_length;
            if strain > worst.1 {
                worst = (e, strain);
            }
            if l > 0.0 {
                let f = d * (k * (l - edge.rest_length) / l);
                self.force[a] += f;
                self.force[b] -= f;
            }
        }
        if worst.1 > params.divergence_strain {
            return Err(StepError::Diverged {
                edge: worst.0,
                strain: worst.1,
                limit: params.divergence_strain,
                time,
            });
        }
        let c = params.damping;
        for (((f, &m), &s), v) in self
            .force
            .iter_mut()
            .zip(cloth.masses())
            .zip(topo.node_areas())
            .zip(vel)
        {
            *f += g * m - v * (c * s);
        }
        extras.add_forces(cloth, state, dt, &mut self.force);
        if let Some(i) = first_non_finite(&self.force) {
            return Err(non_finite(Stage::InternalForces, "force", "node", i, time));
        }

        // 3. Verlet (Y3.1), pins, velocity.
        let here = History {
            time: time.to_bits(),
            dt: dt.to_bits(),
        };
        let continuing = self.history == Some(here) && self.previous.len() == n;
        let inv = cloth.inverse_masses();
        for i in 0..n {
            let a = self.force[i] * inv[i];
            self.next[i] = if inv[i] == 0.0 {
                pos[i]
            } else if continuing {
                pos[i] * 2.0 - self.previous[i] + a * (dt * dt)
            } else {
                pos[i] + vel[i] * dt + a * (0.5 * dt * dt)
            };
        }
        for pin in cloth.pins() {
            self.next[pin.node as usize] = pin.position(time + dt);
        }
        extras.correct(cloth, state, dt, &mut self.next);
        if self.hook.active() {
            let tc = Instant::now();
            self.hook
                .enforce(&mut self.next, pos, inv, dt, frac, t_left);
            timings.shape += tc.elapsed();
        }
        for ((v, x1), x0) in self.velocity.iter_mut().zip(&self.next).zip(pos) {
            *v = (x1 - x0) / dt;
        }
        if let Some(i) = first_non_finite(&self.next) {
            return Err(non_finite(Stage::Update, "position", "node", i, time));
        }
        if let Some(i) = first_non_finite(&self.velocity) {
            return Err(non_finite(Stage::Update, "velocity", "node", i, time));
        }

        // Commit: previous ← P_t, state ← P_{t+1}.
        std::mem::swap(&mut self.previous, &mut state.positions);
        std::mem::swap(&mut state.positions, &mut self.next);
        state.velocities.copy_from_slice(&self.velocity);
        state.time += dt;
        self.history = Some(History {
            time: state.time.to_bits(),
            dt: dt.to_bits(),
        });
        Ok(())
    }

    /// An analytic estimate of the largest stable Δt of this baseline on `cloth`, s: the
    /// linearised system at rest, `M ẍ = −K x − C ẋ`, advanced by Verlet with the backward-
    /// difference damping used here, is stable when `ω²Δt² + 2βΔt < 4` for every mode, i.e.
    /// `Δt < (−β + √(β² + 4ω²))/ω²` (= 2/ω without damping), with `β = c·S/μ`.
    ///
    /// ω² is bounded per free node by Gershgorin's theorem on `M⁻¹K`:
    /// `ω_i² ≤ (2 Σ_e k_e + Σ_h S_h B_h |w_i| Σ_j |w_j|)/μ_i` over the node's springs `e` and
    /// bending hinges `h` (when enabled), and the estimate is the smallest node value. This is
    /// the single-spring limit `2√(μ/k)` corrected for the springs a node shares with its
    /// neighbours: a safe (lower) estimate for the unstrained linear system. Tension adds
    /// geometric stiffness below `k` and barely moves the limit. Measured by bisection on hanging
    /// strips (test suite), the true limit is 1.21 (cotton), 1.24 (denim) and 1.32 (silk) times
    /// this estimate; the plain `2√(μ_min/k_max)` would be 1.44 times the true limit for cotton,
    /// i.e. unstable. `f64::INFINITY` when no node is free. Allocates (not for inner loops).
    pub fn largest_stable_dt_estimate(cloth: &Cloth, params: &MassSpringParams) -> f64 {
        let topo = cloth.topology();
        let n = topo.node_count();
        let mut row = vec![0.0; n];
        for (edge, k) in topo.edges().iter().zip(super::spring_stiffnesses(
            cloth,
            params.reference_force_fraction,
        )) {
            row[edge.a as usize] += 2.0 * k;
            row[edge.b as usize] += 2.0 * k;
        }
        if params.bending {
            let mut hinges = Vec::new();
            fill_hinges(cloth, &mut hinges);
            for h in &hinges {
                let sum: f64 = h.weights.iter().map(|w| w.abs()).sum();
                for (&node, &w) in h.nodes.iter().zip(&h.weights) {
                    row[node as usize] += h.stiffness * w.abs() * sum;
                }
            }
        }
        let (inv, areas, masses) = (cloth.inverse_masses(), topo.node_areas(), cloth.masses());
        (0..n)
            .filter(|&i| inv[i] > 0.0)
            .map(|i| {
                let omega2 = row[i] / masses[i];
                let beta = params.damping * areas[i] / masses[i];
                if omega2 > 0.0 {
                    (-beta + (beta * beta + 4.0 * omega2).sqrt()) / omega2
                } else if beta > 0.0 {
                    2.0 / beta
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min)
    }
}
