//! The plane the wet cloth lies on, in both solvers.
//!
//! - Yamada's model ([`YamadaExtras`], for the mass-spring Verlet step): particles are spheres
//!   of radius `rest` that may not sink into the plane. A particle touching it (height at most
//!   `rest`) feels the normal force (Y3.4), `|F_n| = |F_g| + |F_p| − |F_s sin θ|`: whatever part
//!   of the other forces presses it into the plane, cancelled; and friction (Y3.5),
//!   `|F_f| = μ|F_n|` against its sliding (static = kinetic), applied to the step's tangential
//!   displacement so that it stops a particle but never drives it backwards. A particle that
//!   arrives below `rest` is put back on it (the sphere's margin).
//! - The PARTY step ([`PlaneHook`]): every free node gets a contact plane at height `rest`
//!   that the shape iterations respect, with Coulomb friction μ on the velocity change that
//!   holds it out (the impulse form of (Y3.4)–(Y3.5): the normal impulse carries gravity and
//!   pressure alike).

use nalgebra::Vector3;

use super::stage::PressureStage;
use super::volume::Plane;
use crate::baselines::SpringExtras;
use crate::cloth::Cloth;
use crate::state::ClothState;
use crate::step::{CollisionHook, HookContext};

type V3 = Vector3<f64>;

/// A plane with friction, on which nodes rest at height `rest`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneContact {
    /// The plane (normal towards the cloth).
    pub plane: Plane,
    /// Height of a node lying on the plane (Yamada's sphere radius; PARTY's skin), m.
    pub rest: f64,
    /// Friction coefficient μ (static = kinetic).
    pub friction: f64,
}

impl PlaneContact {
    /// Height of `p` above its rest height on the plane, m.
    pub fn gap(&self, p: &V3) -> f64 {
        self.plane.height(p) - self.rest
    }
}

/// Yamada's wet forces for the mass-spring step: the pressure (when on), then the plane's
/// normal force and friction.
pub struct YamadaExtras {
    /// The plane (none: the cloth hangs free).
    pub contact: Option<PlaneContact>,
    /// The pressure force (none: a dry cloth).
    pub pressure: Option<PressureStage>,
    /// Normal force |F_n| on each node this step, N.
    normal_force: Vec<f64>,
    /// Wall time spent in the pressure force so far.
    pub pressure_time: std::time::Duration,
}

impl YamadaExtras {
    /// The extras with a plane and an optional pressure stage.
    pub fn new(contact: Option<PlaneContact>, pressure: Option<PressureStage>) -> Self {
        Self {
            contact,
            pressure,
            normal_force: Vec::new(),
            pressure_time: std::time::Duration::ZERO,
        }
    }
}

impl SpringExtras for YamadaExtras {
    fn add_forces(&mut self, cloth: &Cloth, state: &ClothState, dt: f64, forces: &mut [V3]) {
        if let Some(p) = &mut self.pressure {
            let t0 = std::time::Instant::now();
            p.add_forces(&state.positions, dt, forces);
            self.pressure_time += t0.elapsed();
        }
        let Some(c) = &self.contact else {
            return;
        };
        let n = c.plane.normal;
        self.normal_force.clear();
        self.normal_force.resize(forces.len(), 0.0);
        let inv = cloth.inverse_masses();
        for (i, (f, x)) in forces.iter_mut().zip(&state.positions).enumerate() {
            if inv[i] > 0.0 && c.gap(x) <= TOUCH {
                let into = -f.dot(&n);
                if into > 0.0 {
                    *f += n * into;
                    self.normal_force[i] = into;
                }
            }
        }
    }

    fn correct(&mut self, cloth: &Cloth, state: &ClothState, dt: f64, next: &mut [V3]) {
        let Some(c) = &self.contact else {
            return;
        };
        let n = c.plane.normal;
        let inv = cloth.inverse_masses();
        for (i, (x1, x0)) in next.iter_mut().zip(&state.positions).enumerate() {
            if inv[i] == 0.0 {
                continue;
            }
            // Friction: the tangential displacement shrinks by μ|F_n|Δt²/m, down to zero.
            let fnorm = self.normal_force.get(i).copied().unwrap_or(0.0);
            if fnorm > 0.0 {
                let u = *x1 - x0;
                let ut = u - n * u.dot(&n);
                let l = ut.norm();
                if l > 0.0 {
                    let cut = (c.friction * fnorm * dt * dt * inv[i]).min(l);
                    *x1 -= ut * (cut / l);
                }
            }
            // The sphere's margin: no particle below its rest height.
            let gap = c.gap(x1);
            if gap < 0.0 {
                *x1 -= n * gap;
            }
        }
    }
}

/// A node within this of its rest height is touching the plane, m.
const TOUCH: f64 = 1e-9;

/// The plane as a collision hook of the PARTY step: a contact plane for every free node.
pub struct PlaneHook {
    /// The plane and its friction.
    pub contact: PlaneContact,
}

impl CollisionHook for PlaneHook {
    fn resolve(&mut self, _ctx: HookContext<'_>) {}

    fn transfer(&mut self, ctx: HookContext<'_>) {
        let c = &self.contact;
        let plane = atelier_collide::ContactPlane {
            point: c.plane.point + c.plane.normal * c.rest,
            normal: c.plane.normal,
            velocity: V3::zeros(),
            friction: c.friction,
        };
        for (p, &w) in ctx.planes.iter_mut().zip(ctx.inverse_masses) {
            if w > 0.0 {
                *p = plane;
            }
        }
    }
}
