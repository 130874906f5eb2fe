//! Baseline cloth solvers the PARTY step is measured against (`method.md` §2, last paragraph):
//! the same [`Cloth`] (topology, fabric, masses, pins) and [`ClothState`] in, the same state out,
//! each with its own parameter struct and a common [`BaselineReport`].
//!
//! - [`MassSpring`]: the explicit mass-spring model with Verlet integration of Yamada's wet-cloth
//!   thesis (`method.md` §5: Hooke springs (Y3.6) on the 8-neighbourhood, Verlet (Y3.1));
//! - [`Xpbd`]: extended position-based dynamics (Macklin, Müller, Chentanez 2016, "XPBD:
//!   position-based simulation of compliant constrained dynamics") with distance constraints on
//!   the same edges.
//!
//! # Stiffness from the fabric (shared by both baselines)
//!
//! A baseline is only a fair comparison if its springs are as stiff as the fabric PARTY
//! simulates. Both baselines are linear, so each edge gets one stiffness
//!
//! `k = W·E/l⁰` (N/m),
//!
//! with `l⁰` the edge's rest length, `W` the width it carries ([`Cloth::edge_widths`]: half the
//! cells beside it, area over length; for a diagonal, whose one cell has two diagonals, that is
//! exactly cell area / diagonal length / 2) and `E` the **secant** stiffness (force per width
//! over strain, N/m) of the edge's own tensile loop (its entry in [`Cloth::materials`]: warp or
//! weft for axial edges, the 45° or 135° bias loop for diagonals) from zero force to a reference
//! force `f_ref = fraction · f_max` on the loading branch:
//! `E = f_ref / (φ⁺(f_ref) − φ⁺(0))`, see [`secant_modulus`]. The default fraction is 1 %
//! (about 4.9 N/m for KES loops with Fm = 500 gf/cm): the force per width of cloth hanging under
//! its own weight over tens of centimetres (0.1–2 N/m) lies below it, so the springs are about
//! as stiff as the fabric in the drapes the project simulates. The secant to the apex (Fm/EMT)
//! would be 5–10 times stiffer for typical (convex, LT ≈ 0.7) KES loops, i.e. unfairly stiff
//! and needlessly small time steps. Hysteresis and the nonlinearity of the loops are not
//! modelled by the baselines; that is part of what they are measured for.
//!
//! # Bending (optional in both baselines)
//!
//! Neither Yamada's model nor plain XPBD cloth has a bending model tied to measured data. When
//! enabled, both use the same simple isometric bending along grid lines (the quadratic bending of
//! Bergou et al. 2006 restricted to the grid's axial triples): for every node `i` with both
//! neighbours `i−1`, `i+1` along u (and likewise v), rest spacings `h₁ = l⁰(i−1,i)`,
//! `h₂ = l⁰(i,i+1)`, the discrete curvature vector
//!
//! `D = a·x_{i−1} + b·x_i + c·x_{i+1}`, `a = 2/(h₁(h₁+h₂))`, `c = 2/(h₂(h₁+h₂))`, `b = −(a+c)`
//!
//! (zero for a straight line at any spacing, `|D| ≈ η` the curvature for an isometric bend), with
//! energy `½·S·B·|D|²`: `S` the node area (`S = h·W`, the strip length and width the node stands
//! for) and `B` the elastic rigidity of the spindle at that axis (mean of the two slots' entries;
//! the residual moment M₀ is ignored, as PARTY does with hysteresis off). This is the continuum
//! bending energy `½ W B η² h` of the strip the node represents. It is not the PARTY bending
//! force (normal-based curvature, moment differences): duplicating that would make the
//! comparison pointless. The hinge rests straight; on curved grid lines (annulus rings) it also
//! carries an in-plane term of the ring's curvature, which the stretch springs resist anyway.

//! # Collisions and seams (the garment pipeline)
//!
//! Both baselines take the same [`CollisionHook`] as the PARTY step ([`Xpbd::step_with`],
//! [`MassSpring::step_with`]), with the same meaning, so that the garment simulation can run any
//! of the three solvers on the same scene:
//!
//! - `transfer` is called once per step, before the constraint solve, with the positions at the
//!   start of the step and the velocities the step starts from (XPBD: the state's velocity;
//!   mass-spring: the same, and a change it makes to a node's velocity enters the Verlet
//!   recursion as that change of the node's previous position). It moves cloth with a moving
//!   body and hands out the step's [`Tie`]s and [`ContactPlane`]s, for the whole step of length
//!   Δt (the hook's `dt` is the outer Δt, not the substep).
//! - The ties and planes are enforced in **every substep** as position constraints (both
//!   baselines' substeps are position updates): XPBD after its prediction and after each
//!   Gauss–Seidel sweep (the distance constraints, the hinges, then the ties, then the planes);
//!   the mass-spring model, being explicit, once after the Verlet update of each substep, as a
//!   position correction (which the recursion then sees as a velocity change) — documented
//!   choice: the springs are forces, the seams and the body are hard constraints. A tie whose
//!   pair starts the step farther apart than its `length` is closed gradually: at the end of
//!   substep k of n the pair may be at most `gap₀ + (length − gap₀)·k/n` apart (`gap₀` its
//!   distance at the start of the step), so a seam is drawn together over the step as in PARTY,
//!   whose constraint is on the end of the step, instead of being yanked in the first substep.
//!   A contact plane (its point at the end of the step) is carried back along its body velocity
//!   to the end of each substep (`point − velocity·(t_end − t_k)`), and the node is put in front
//!   of it with the plane's Coulomb friction on its displacement relative to the body over the
//!   substep — PARTY's rule ([`crate::step`]) applied to the substep's velocity `(x − x_k)/h`.
//!   A node that starts the step behind its plane (within the skin, or inside) is brought out
//!   gradually, like a tie: at the end of substep k it may still be `d₀·(1 − k/n)` behind
//!   (`d₀ < 0` its distance at the start), in front by the end of the step as in PARTY.
//!   (Measured: pushed out within one substep, a node of the explicit model leaves with the
//!   push over the substep, `d₀/h`, up to 75 m/s at h = 40 µs, and the mass-spring skirt of
//!   `crates/atelier/tests/own/baselines.rs` rang up to 100 m/s within 0.05 s; with the gradual
//!   push its fastest node stays at the 5–10 m/s its placement's strains release.)
//!   Pinned nodes are left alone.
//! - `resolve` is called once, after the last substep (pass 0): it sees the whole step as
//!   PARTY's does — positions at the start, velocities `(x_end − x_start)/Δt` — and a change it
//!   makes to a node's velocity moves the node's end position by that change times Δt and is
//!   added to the node's velocity, as is its `exit` velocity (thesis (72)).
//!
//! `step` is `step_with(NoCollision)` and gives bit-identical numbers to the baselines without
//! a hook (tested).

pub mod mass_spring;
pub mod xpbd;

pub use mass_spring::{MassSpring, MassSpringParams, NoExtras, SpringExtras};
pub use xpbd::{Xpbd, XpbdParams};

use atelier_fabric::{Branch, TensileLoop};
use atelier_grid::NO_NODE;
use nalgebra::Vector3;

use atelier_collide::ContactPlane;

use crate::cloth::Cloth;
use crate::state::ClothState;
use crate::step::{CollisionHook, HookContext, Stage, StageTimings, StepError, Tie, plane_push};

type V3 = Vector3<f64>;

/// Diagnostics of one baseline step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BaselineReport {
    /// Solver sweeps over the constraints: substeps × iterations for [`Xpbd`]; 1 (one force
    /// evaluation) for [`MassSpring`].
    pub iterations: usize,
    /// Largest |ε| = |l − l⁰|/l⁰ over all edges (axial and diagonal) after the step.
    pub max_strain: f64,
    /// Kinetic energy ½ Σ μ|ṙ|² after the step (pinned nodes included), J.
    pub kinetic_energy: f64,
    /// Fastest node after the step, m/s.
    pub max_speed: f64,
    /// Wall time of the step: `velocity` the predictions (XPBD) or forces and integration
    /// (mass-spring), `shape` the constraint sweeps (XPBD, with the ties and planes) or the
    /// ties and planes (mass-spring), `transfer` and `collision` the hook, `update` the commit.
    pub timings: StageTimings,
}

/// The secant stiffness `E = f_ref / (φ⁺(f_ref) − φ⁺(0))` (force per width over strain, N/m) of
/// a tensile loop's loading branch at the reference force `f_ref = fraction · f_max`.
///
/// Falls back to the apex secant [`TensileLoop::secant_stiffness`] when the loop does not strain
/// at all up to `f_ref` (a vertical first segment), so the result is always finite and positive
/// for a valid loop and a fraction in (0, 1].
pub fn secant_modulus(tensile: &TensileLoop, fraction: f64) -> f64 {
    let f_ref = fraction * tensile.max_force();
    let strain = tensile.strain(Branch::Loading, f_ref) - tensile.strain(Branch::Loading, 0.0);
    let e = f_ref / strain;
    if e.is_finite() && e > 0.0 {
        e
    } else {
        tensile.secant_stiffness()
    }
}

/// The spring stiffness `k = W·E/l⁰` (N/m) of every edge of `cloth`, with `E` the secant modulus
/// of the edge's tensile loop at `fraction` of its apex force (module docs). Allocates; the
/// baselines fill their own buffers each step instead.
pub fn spring_stiffnesses(cloth: &Cloth, fraction: f64) -> Vec<f64> {
    let mut k = Vec::new();
    fill_stiffness(cloth, fraction, &mut k);
    k
}

/// [`spring_stiffnesses`] into a reused buffer (no allocation once sized).
pub(crate) fn fill_stiffness(cloth: &Cloth, fraction: f64, out: &mut Vec<f64>) {
    let (edges, mats, widths, table) = (
        cloth.topology().edges(),
        cloth.edge_materials(),
        cloth.edge_widths(),
        cloth.materials(),
    );
    out.clear();
    out.extend(
        edges
            .iter()
            .zip(mats)
            .zip(widths)
            .map(|((e, &m), &w)| w * secant_modulus(table.tensile(m), fraction) / e.rest_length),
    );
}

/// One bending hinge along a grid line (module docs): the curvature vector
/// `D = Σ weights[k]·x[nodes[k]]` and the stiffness `S·B` of the energy `½·S·B·|D|²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Hinge {
    /// `i−1`, `i`, `i+1`.
    pub nodes: [u32; 3],
    /// `a`, `b`, `c`, m⁻².
    pub weights: [f64; 3],
    /// `S·B`, N·m³.
    pub stiffness: f64,
}

impl Hinge {
    /// The curvature vector D at positions `x`, m⁻¹.
    #[inline]
    pub fn curvature(&self, x: &[V3]) -> V3 {
        let [p, q, r] = self.nodes.map(|n| x[n as usize]);
        p * self.weights[0] + q * self.weights[1] + r * self.weights[2]
    }
}

/// The hinges of every node with both neighbours along u, then along v, into a reused buffer.
pub(crate) fn fill_hinges(cloth: &Cloth, out: &mut Vec<Hinge>) {
    let topo = cloth.topology();
    let (axial, axial_edge, smats) = (
        cloth.bending_neighbours(),
        topo.axial_edges(),
        cloth.slot_materials(),
    );
    let (edges, areas, table) = (topo.edges(), topo.node_areas(), cloth.materials());
    out.clear();
    // Slots: +u, −u, +v, −v; a hinge runs from the minus to the plus neighbour.
    for (plus, minus) in [(0, 1), (2, 3)] {
        for i in 0..topo.node_count() {
            let (p, m) = (axial[i][plus], axial[i][minus]);
            if p == NO_NODE || m == NO_NODE {
                continue;
            }
            let h1 = edges[axial_edge[i][minus] as usize].rest_length;
            let h2 = edges[axial_edge[i][plus] as usize].rest_length;
            let a = 2.0 / (h1 * (h1 + h2));
            let c = 2.0 / (h2 * (h1 + h2));
            let b = 0.5
                * (table.bending(smats[i][plus]).rigidity()
                    + table.bending(smats[i][minus]).rigidity());
            out.push(Hinge {
                nodes: [m, i as u32, p],
                weights: [a, -(a + c), c],
                stiffness: areas[i] * b,
            });
        }
    }
}

/// Resize `v` to `n` entries (no allocation when it already has them).
pub(crate) fn resize<T: Clone>(v: &mut Vec<T>, n: usize, x: T) {
    if v.len() != n {
        v.clear();
        v.resize(n, x);
    }
}

/// Index of the first vector with a non-finite component.
pub(crate) fn first_non_finite(v: &[V3]) -> Option<usize> {
    v.iter()
        .position(|x| !(x.x.is_finite() && x.y.is_finite() && x.z.is_finite()))
}

/// The checks shared by every baseline before a step: the state matches the cloth and its
/// positions and velocities are finite.
pub(crate) fn check_input(cloth: &Cloth, state: &ClothState) -> Result<(), StepError> {
    let n = cloth.topology().node_count();
    for (what, found) in [
        ("positions", state.positions.len()),
        ("velocities", state.velocities.len()),
    ] {
        if found != n {
            return Err(StepError::Mismatch {
                what,
                expected: n,
                found,
            });
        }
    }
    if !state.time.is_finite() {
        return Err(non_finite(Stage::Input, "time", "node", 0, state.time));
    }
    if let Some(i) = first_non_finite(&state.positions) {
        return Err(non_finite(Stage::Input, "position", "node", i, state.time));
    }
    if let Some(i) = first_non_finite(&state.velocities) {
        return Err(non_finite(Stage::Input, "velocity", "node", i, state.time));
    }
    Ok(())
}

/// A [`StepError::NonFinite`].
pub(crate) fn non_finite(
    stage: Stage,
    quantity: &'static str,
    location: &'static str,
    index: usize,
    time: f64,
) -> StepError {
    StepError::NonFinite {
        stage,
        quantity,
        location,
        index,
        time,
    }
}

/// The report of a committed state.
pub(crate) fn report(cloth: &Cloth, state: &ClothState, iterations: usize) -> BaselineReport {
    let pos = &state.positions;
    let max_strain = cloth
        .topology()
        .edges()
        .iter()
        .map(|e| ((pos[e.b as usize] - pos[e.a as usize]).norm() / e.rest_length - 1.0).abs())
        .fold(0.0, f64::max);
    BaselineReport {
        iterations,
        max_strain,
        kinetic_energy: state.kinetic_energy(cloth),
        max_speed: state
            .velocities
            .iter()
            .map(|v| v.norm())
            .fold(0.0, f64::max),
        timings: StageTimings::default(),
    }
}

/// The hook's state over one baseline step (module docs, "Collisions and seams"): its ties with
/// their gaps at the start of the step, its contact planes, its exit velocities.
#[derive(Clone, Debug, Default)]
pub(crate) struct HookState {
    ties: Vec<Tie>,
    /// Each tie's distance at the start of the step, m.
    gap0: Vec<f64>,
    planes: Vec<ContactPlane>,
    /// Nodes with a plane this step.
    plane_nodes: Vec<u32>,
    /// Each plane node's distance in front of its plane at the start of the step (negative:
    /// behind it), m.
    plane_d0: Vec<f64>,
    exit: Vec<V3>,
    /// Whole-step velocities handed to `resolve`, and a copy to see what it changed.
    vel: Vec<V3>,
    vel_before: Vec<V3>,
}

impl HookState {
    /// Call the hook's `transfer` at the start of a step of length `dt`: `velocities` (the
    /// velocities the step starts from) may be changed; the ties and planes are kept for
    /// [`HookState::enforce`].
    pub fn transfer(
        &mut self,
        hook: &mut dyn CollisionHook,
        cloth: &Cloth,
        positions: &[V3],
        velocities: &mut [V3],
        dt: f64,
        time: f64,
    ) {
        let n = positions.len();
        resize(&mut self.planes, n, ContactPlane::default());
        resize(&mut self.exit, n, V3::zeros());
        self.planes.fill(ContactPlane::default());
        self.exit.fill(V3::zeros());
        self.ties.clear();
        hook.transfer(HookContext {
            positions,
            velocities,
            exit: &mut self.exit,
            inverse_masses: cloth.inverse_masses(),
            dt,
            time,
            pass: 0,
            planes: &mut self.planes,
            ties: &mut self.ties,
        });
        let inv = cloth.inverse_masses();
        // Ties naming nodes outside the cloth are the hook's bug; they are ignored rather
        // than allowed to panic.
        self.ties
            .retain(|t| (t.a as usize) < n && (t.b as usize) < n && t.length.is_finite());
        self.gap0.clear();
        self.gap0.extend(
            self.ties
                .iter()
                .map(|t| (positions[t.b as usize] - positions[t.a as usize]).norm()),
        );
        self.plane_nodes.clear();
        self.plane_nodes.extend(
            (0..n as u32).filter(|&i| {
                self.planes[i as usize].normal != V3::zeros() && inv[i as usize] > 0.0
            }),
        );
        self.plane_d0.clear();
        self.plane_d0.extend(self.plane_nodes.iter().map(|&i| {
            let p = &self.planes[i as usize];
            (positions[i as usize] - (p.point - p.velocity * dt)).dot(&p.normal)
        }));
    }

    /// Whether the step has ties or planes to enforce.
    pub fn active(&self) -> bool {
        !self.ties.is_empty() || !self.plane_nodes.is_empty()
    }

    /// Enforce the ties, then the planes, on the positions `x` at the end of a substep that
    /// started at `x_old`, lasted `h`, ends a fraction `frac` into the step and `t_left` before
    /// its end (module docs).
    pub fn enforce(&self, x: &mut [V3], x_old: &[V3], inv: &[f64], h: f64, frac: f64, t_left: f64) {
        for (tie, &g0) in self.ties.iter().zip(&self.gap0) {
            let (a, b) = (tie.a as usize, tie.b as usize);
            let ws = inv[a] + inv[b];
            if ws <= 0.0 {
                continue;
            }
            let length = if g0 > tie.length {
                g0 + (tie.length - g0) * frac
            } else {
                tie.length
            };
            let gap = x[b] - x[a];
            let l = gap.norm();
            if l <= length || l == 0.0 {
                continue;
            }
            let shift = gap * ((l - length) / (l * ws));
            x[a] += shift * inv[a];
            x[b] -= shift * inv[b];
        }
        for (&i, &d0) in self.plane_nodes.iter().zip(&self.plane_d0) {
            let i = i as usize;
            let mut plane = self.planes[i];
            plane.point -= plane.velocity * t_left;
            if d0 < 0.0 {
                // Behind its plane at the start: brought out gradually, in front by the end.
                plane.point += plane.normal * (d0 * (1.0 - frac));
            }
            let v = (x[i] - x_old[i]) / h;
            x[i] = x_old[i] + plane_push(v, &x_old[i], &plane, h) * h;
        }
    }

    /// Call the hook's `resolve` once after the last substep: `start` the positions at the
    /// start of the step, `end` at its end (changed where the hook changed a node's
    /// velocity). Returns, per node, the change of velocity to add to the node's velocity
    /// (the hook's change plus its exit velocity), or `None` when nothing changed.
    pub fn resolve(
        &mut self,
        hook: &mut dyn CollisionHook,
        cloth: &Cloth,
        start: &[V3],
        end: &mut [V3],
        dt: f64,
        time: f64,
    ) -> Option<&[V3]> {
        let n = start.len();
        resize(&mut self.vel, n, V3::zeros());
        resize(&mut self.vel_before, n, V3::zeros());
        for ((v, x1), x0) in self.vel.iter_mut().zip(end.iter()).zip(start) {
            *v = (x1 - x0) / dt;
        }
        self.vel_before.copy_from_slice(&self.vel);
        hook.resolve(HookContext {
            positions: start,
            velocities: &mut self.vel,
            exit: &mut self.exit,
            inverse_masses: cloth.inverse_masses(),
            dt,
            time,
            pass: 0,
            planes: &mut self.planes,
            ties: &mut self.ties,
        });
        let mut changed = false;
        for i in 0..n {
            let (after, before) = (self.vel[i], self.vel_before[i]);
            let dv = if after == before {
                V3::zeros()
            } else {
                end[i] = start[i] + after * dt;
                after - before
            };
            // vel now holds the change to add to the node's velocity.
            self.vel[i] = dv + self.exit[i];
            changed |= self.vel[i] != V3::zeros();
        }
        changed.then_some(self.vel.as_slice())
    }
}
