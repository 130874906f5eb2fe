//! The collision hook: what a collision pass sees and may change ([`HookContext`], [`Tie`]),
//! the trait ([`CollisionHook`]), and the two places of the step that call it (the transfer of
//! body motion and the passes between shape iterations); [`plane_push`], the contact plane
//! every shape iteration respects.

use super::scratch::Scratch;
use super::{Solver, V3};
use crate::cloth::Cloth;
use crate::state::ClothState;

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

impl Solver {
    /// The transfer of body motion after the unconstrained velocity (the staged collision
    /// model): exit velocities, contact planes and ties start the step empty, then the hook
    /// moves the cloth with a moving body (pass 0).
    pub(super) fn transfer_body_motion(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        dt: f64,
        hook: &mut dyn CollisionHook,
    ) {
        let s = &mut self.s;
        s.exit.iter_mut().for_each(|e| *e = V3::zeros());
        s.planes
            .iter_mut()
            .for_each(|p| *p = atelier_collide::ContactPlane::default());
        s.ties.clear();
        hook.transfer(context(s, cloth, state, dt, 0));
    }

    /// Collision pass `pass`, after a round of shape iterations: the hook resolves contacts by
    /// changing the velocities.
    pub(super) fn collision_pass(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        dt: f64,
        pass: usize,
        hook: &mut dyn CollisionHook,
    ) {
        hook.resolve(context(&mut self.s, cloth, state, dt, pass));
    }
}

/// What the hook sees of the step in pass `pass`.
fn context<'a>(
    s: &'a mut Scratch,
    cloth: &'a Cloth,
    state: &'a ClothState,
    dt: f64,
    pass: usize,
) -> HookContext<'a> {
    HookContext {
        positions: &state.positions,
        velocities: &mut s.vel,
        exit: &mut s.exit,
        inverse_masses: cloth.inverse_masses(),
        dt,
        time: state.time,
        pass,
        planes: &mut s.planes,
        ties: &mut s.ties,
    }
}
