//! Extended position-based dynamics (XPBD; Macklin, Müller, Chentanez 2016, "XPBD:
//! position-based simulation of compliant constrained dynamics", Algorithm 1) on the PARTY
//! topology, with sub-stepping (Macklin et al. 2019, "Small steps in physics simulation").
//!
//! Per substep of length h = Δt/substeps:
//!
//! 1. prediction: `ṙ ← ṙ·e^{−βh} + g·h`, `x̃ = x + ṙh`, with `β = c·S/μ` the rate of the linear
//!    drag `−c·S·ṙ`; pinned nodes (inverse mass 0) are put at `Pin::position(t + h)`. The drag
//!    decays the velocity the last substep ended with (exactly, so at any βh) and leaves the
//!    gravity kick alone: a cloth at rest then feels the full weight. Damping the kicked
//!    velocity instead (`(μṙ + μgh)/(μ + cSh)`, the form of PARTY's (18), where the internal
//!    forces are already in the kick) would scale the weight that the constraints balance by
//!    `1/(1 + βh)`: 17 % too little sag for cotton at c = 2.5 kg/(m²·s), h = 0.01 s. The price is
//!    a terminal speed too high by about βh/2 (free fall with drag is first order in h);
//! 2. λ ← 0, then `iterations` Gauss–Seidel sweeps: the distance constraints `C = l − l⁰` of all
//!    edges of the 8-neighbourhood, colour after colour ([`Cloth::colour_edge`]; edges of one
//!    colour share no node, so the order inside a colour does not matter), each solved with
//!    `Δλ = (−C − α̃λ)/(w_a + w_b + α̃)`, `α̃ = α/h²` (XPBD eq. 18), then (optionally) the bending
//!    hinges;
//! 3. `ṙ = (x − x_old)/h`.
//!
//! Compliance from the fabric: `α = s/k` per edge with `k = W·E/l⁰` the spring stiffness of
//! [`crate::baselines`] (the energy `½k(l − l⁰)²` is the XPBD energy `½α⁻¹C²`) and `s` =
//! [`XpbdParams::compliance_scale`] (1 = the fabric; 0 = inextensible, plain PBD constraints).
//! Bending (optional): the isometric hinges of [`crate::baselines`], each a vector constraint
//! `C = D` (the discrete curvature vector, m⁻¹) with compliance `α = 1/(S·B)`, so that
//! `½α⁻¹|C|² = ½·S·B·η²` is the strip's bending energy; its gradient is `w_j·I` at the three nodes,
//! so `Δλ = (−D − α̃λ)/(Σ w_j² m_j⁻¹ + α̃)` (a 3-vector) and `Δx_j = m_j⁻¹ w_j Δλ`.
//!
//! Time stepping matches [`crate::baselines::MassSpring`]: the state's velocity is the mid-step
//! velocity, and the first step after construction or [`Xpbd::reset`] (or on a state whose time
//! or Δt this solver did not produce) starts with a half kick of gravity, so free fall is exact.

use atelier_grid::NO_NODE;
use serde::{Deserialize, Serialize};

use std::time::Instant;

use super::{
    BaselineReport, Hinge, HookState, V3, check_input, fill_hinges, fill_stiffness,
    first_non_finite, non_finite, report, resize,
};
use crate::cloth::Cloth;
use crate::params::{ParamError, StepInput, check, check_damping};
use crate::state::ClothState;
use crate::step::{CollisionHook, NoCollision, Stage, StepError};

/// Parameters of the XPBD baseline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct XpbdParams {
    /// Linear damping per area c (force −c·S·ṙ on a node of area S), kg/(m²·s). Range
    /// [0, 1000]; default 0.2 (as [`crate::StepParams::damping`]).
    pub damping: f64,
    /// Substeps per step. Range [1, 10000]; default 10.
    pub substeps: usize,
    /// Gauss–Seidel sweeps over all constraints per substep. Range [1, 100000]; default 4.
    pub iterations: usize,
    /// Reference force of the secant spring stiffness as a fraction of each loop's apex force
    /// (see [`crate::baselines`]). Range (0, 1]; default 0.01.
    pub reference_force_fraction: f64,
    /// Factor s on the distance compliance α = s/k. Range [0, 1e6]; default 1 (the fabric's
    /// stiffness); 0 makes the edges inextensible.
    pub compliance_scale: f64,
    /// Add the isometric bending hinge constraints with compliance 1/(S·B). Default false.
    pub bending: bool,
}

impl Default for XpbdParams {
    fn default() -> Self {
        Self {
            damping: 0.2,
            substeps: 10,
            iterations: 4,
            reference_force_fraction: 0.01,
            compliance_scale: 1.0,
            bending: false,
        }
    }
}

impl XpbdParams {
    /// Check every field against its range.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_damping(self.damping)?;
        check(
            "substeps",
            self.substeps as f64,
            (1..=10_000).contains(&self.substeps),
            "[1, 10000]",
        )?;
        check(
            "iterations",
            self.iterations as f64,
            (1..=100_000).contains(&self.iterations),
            "[1, 100000]",
        )?;
        check(
            "reference_force_fraction",
            self.reference_force_fraction,
            self.reference_force_fraction > 0.0 && self.reference_force_fraction <= 1.0,
            "(0, 1]",
        )?;
        check(
            "compliance_scale",
            self.compliance_scale,
            (0.0..=1e6).contains(&self.compliance_scale),
            "[0, 1e6]",
        )
    }
}

/// The XPBD baseline: reusable scratch buffers and the time it last committed; the simulation
/// state is passed in explicitly.
#[derive(Clone, Debug, Default)]
pub struct Xpbd {
    stiffness: Vec<f64>,
    hinges: Vec<Hinge>,
    x: Vec<V3>,
    x_old: Vec<V3>,
    v: Vec<V3>,
    lambda: Vec<f64>,
    lambda_bend: Vec<V3>,
    /// The collision hook's ties, planes and exit velocities over a step.
    hook: HookState,
    /// Time and Δt (bit patterns) after the last committed step.
    history: Option<(u64, u64)>,
}

impl Xpbd {
    /// A solver with empty scratch.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forget the last committed time: the next step starts with a half kick, treating the
    /// state's velocity as the velocity at the state's time.
    pub fn reset(&mut self) {
        self.history = None;
    }

    /// One step of length `input.dt` (`substeps` substeps). On error the state is unchanged.
    pub fn step(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &XpbdParams,
        input: StepInput,
    ) -> Result<BaselineReport, StepError> {
        self.step_with(cloth, state, params, input, &mut NoCollision)
    }

    /// One step with a collision hook, as the PARTY step drives it ([`crate::baselines`],
    /// "Collisions and seams"): `transfer` once before the substeps (the hook's Δt is the
    /// step's, not the substep's), its ties and contact planes enforced as position constraints
    /// after the prediction and after every sweep of every substep, `resolve` once after the
    /// last substep. On error the state is unchanged.
    pub fn step_with(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &XpbdParams,
        input: StepInput,
        hook: &mut dyn CollisionHook,
    ) -> Result<BaselineReport, StepError> {
        let t_start = Instant::now();
        let mut timings = crate::step::StageTimings::default();
        params.validate()?;
        input.validate()?;
        check_input(cloth, state)?;
        let topo = cloth.topology();
        let (n, edges) = (topo.node_count(), topo.edges());
        let (dt, time) = (input.dt, state.time);
        fill_stiffness(cloth, params.reference_force_fraction, &mut self.stiffness);
        if params.bending {
            fill_hinges(cloth, &mut self.hinges);
        } else {
            self.hinges.clear();
        }
        resize(&mut self.x, n, V3::zeros());
        resize(&mut self.x_old, n, V3::zeros());
        resize(&mut self.v, n, V3::zeros());
        resize(&mut self.lambda, edges.len(), 0.0);
        resize(&mut self.lambda_bend, self.hinges.len(), V3::zeros());
        self.x.copy_from_slice(&state.positions);
        self.v.copy_from_slice(&state.velocities);
        let starting = self.history != Some((time.to_bits(), dt.to_bits()));
        let (inv, masses, areas) = (cloth.inverse_masses(), cloth.masses(), topo.node_areas());
        let (g, c) = (input.gravity_vector(), params.damping);
        let h = dt / params.substeps as f64;
        let inv_h2 = 1.0 / (h * h);
        let colours = cloth.colour_count();

        let tc = Instant::now();
        self.hook
            .transfer(hook, cloth, &state.positions, &mut self.v, dt, time);
        if let Some(i) = first_non_finite(&self.v) {
            return Err(non_finite(Stage::Collision, "velocity", "node", i, time));
        }
        timings.transfer = tc.elapsed();
        let hooked = self.hook.active();

        for sub in 0..params.substeps {
            let frac = (sub + 1) as f64 / params.substeps as f64;
            let t_left = dt * (1.0 - frac);
            let t1 = if sub + 1 == params.substeps {
                time + dt
            } else {
                time + (sub + 1) as f64 * h
            };
            self.x_old.copy_from_slice(&self.x);
            // 1. Prediction.
            let kick = if starting && sub == 0 { 0.5 * h } else { h };
            for i in 0..n {
                if inv[i] == 0.0 {
                    continue;
                }
                let decay = (-c * areas[i] / masses[i] * kick).exp();
                self.v[i] = self.v[i] * decay + g * kick;
                self.x[i] += self.v[i] * h;
            }
            for pin in cloth.pins() {
                self.x[pin.node as usize] = pin.position(t1);
            }
            if hooked {
                self.hook
                    .enforce(&mut self.x, &self.x_old, inv, h, frac, t_left);
            }
            if let Some(i) = first_non_finite(&self.x) {
                return Err(non_finite(
                    Stage::Velocity,
                    "predicted position",
                    "node",
                    i,
                    time,
                ));
            }

            // 2. Constraint sweeps.
            self.lambda.fill(0.0);
            self.lambda_bend.fill(V3::zeros());
            for _ in 0..params.iterations {
                for colour in 0..colours {
                    for i in 0..n {
                        let e = cloth.colour_edge(i, colour);
                        if e == NO_NODE {
                            continue;
                        }
                        let e = e as usize;
                        let edge = &edges[e];
                        if edge.a as usize != i {
                            continue;
                        }
                        let k = self.stiffness[e];
                        if k.is_nan() || k <= 0.0 {
                            continue; // no stiffness: no constraint
                        }
                        let alpha = params.compliance_scale / k * inv_h2;
                        solve_distance(
                            &mut self.x,
                            inv,
                            [edge.a as usize, edge.b as usize],
                            edge.rest_length,
                            alpha,
                            &mut self.lambda[e],
                        );
                    }
                }
                for (hinge, lambda) in self.hinges.iter().zip(self.lambda_bend.iter_mut()) {
                    solve_hinge(&mut self.x, inv, hinge, inv_h2 / hinge.stiffness, lambda);
                }
                if hooked {
                    self.hook
                        .enforce(&mut self.x, &self.x_old, inv, h, frac, t_left);
                }
            }
            if let Some(e) = self.lambda.iter().position(|l| !l.is_finite()) {
                return Err(non_finite(
                    Stage::ShapeConstraints,
                    "distance multiplier λ",
                    "edge",
                    e,
                    time,
                ));
            }
            if let Some(k) = first_non_finite(&self.lambda_bend) {
                let node = self.hinges[k].nodes[1] as usize;
                return Err(non_finite(
                    Stage::Bending,
                    "bending multiplier λ",
                    "node",
                    node,
                    time,
                ));
            }
            if let Some(i) = first_non_finite(&self.x) {
                return Err(non_finite(
                    Stage::ShapeConstraints,
                    "position",
                    "node",
                    i,
                    time,
                ));
            }

            // 3. Velocity.
            for ((v, x1), x0) in self.v.iter_mut().zip(&self.x).zip(&self.x_old) {
                *v = (x1 - x0) / h;
            }
            if let Some(i) = first_non_finite(&self.v) {
                return Err(non_finite(Stage::Update, "velocity", "node", i, time));
            }
        }

        // The hook's collision pass over the whole step.
        let tc = Instant::now();
        if let Some(dv) = self
            .hook
            .resolve(hook, cloth, &state.positions, &mut self.x, dt, time)
        {
            for (v, d) in self.v.iter_mut().zip(dv) {
                *v += d;
            }
        }
        if let Some(i) = first_non_finite(&self.x).or_else(|| first_non_finite(&self.v)) {
            return Err(non_finite(Stage::Collision, "velocity", "node", i, time));
        }
        timings.collision = tc.elapsed();

        let tu = Instant::now();
        state.positions.copy_from_slice(&self.x);
        state.velocities.copy_from_slice(&self.v);
        state.time += dt;
        self.history = Some((state.time.to_bits(), dt.to_bits()));
        let mut r = report(cloth, state, params.substeps * params.iterations);
        timings.update = tu.elapsed();
        timings.shape = t_start
            .elapsed()
            .saturating_sub(timings.transfer + timings.collision + timings.update);
        r.timings = timings;
        Ok(r)
    }
}

/// One XPBD distance-constraint update (XPBD eqs. 17–18) on the edge `a–b` with rest length
/// `rest` and time-scaled compliance `alpha` (α̃ = α/h²); accumulates the multiplier.
#[inline]
fn solve_distance(
    x: &mut [V3],
    inv: &[f64],
    [a, b]: [usize; 2],
    rest: f64,
    alpha: f64,
    lambda: &mut f64,
) {
    let (wa, wb) = (inv[a], inv[b]);
    let w = wa + wb;
    if w == 0.0 {
        return;
    }
    let d = x[b] - x[a];
    let l = d.norm();
    if l == 0.0 {
        return;
    }
    let n = d / l;
    let dl = (-(l - rest) - alpha * *lambda) / (w + alpha);
    x[a] -= n * (wa * dl);
    x[b] += n * (wb * dl);
    *lambda += dl;
}

/// One XPBD update of a bending hinge, the vector constraint `C = D` with time-scaled compliance
/// `alpha` (α̃ = 1/(S·B·h²)); accumulates the vector multiplier.
#[inline]
fn solve_hinge(x: &mut [V3], inv: &[f64], hinge: &Hinge, alpha: f64, lambda: &mut V3) {
    let w: f64 = hinge
        .nodes
        .iter()
        .zip(&hinge.weights)
        .map(|(&j, &wj)| wj * wj * inv[j as usize])
        .sum();
    if w == 0.0 {
        return;
    }
    let d = hinge.curvature(x);
    let dl = (-d - *lambda * alpha) / (w + alpha);
    for (&j, &wj) in hinge.nodes.iter().zip(&hinge.weights) {
        x[j as usize] += dl * (inv[j as usize] * wj);
    }
    *lambda += dl;
}
