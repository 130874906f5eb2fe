//! The collision hook the step calls: [`atelier_collide::Collider`] adapted to a [`Cloth`] — its
//! triangles for self-collision, its node normals for one-sided contact, its inverse masses.

use atelier_collide::geom::vertex_normals;
use atelier_collide::parts::Motion;
use atelier_collide::{
    ClothView, Collider, ContactError, ContactParams, PassStats, RigidParts, V3,
};

use crate::cloth::Cloth;
use crate::step::{CollisionHook, HookContext};

/// Collisions of one cloth with a body (moving or not) and with itself.
pub struct BodyContact {
    collider: Collider,
    triangles: Vec<[u32; 3]>,
    normals: Vec<V3>,
}

impl BodyContact {
    /// A hook for `cloth` with checked contact parameters; no body until
    /// [`BodyContact::set_body`].
    pub fn new(cloth: &Cloth, params: ContactParams) -> Result<Self, ContactError> {
        Ok(Self {
            collider: Collider::new(params)?,
            triangles: cloth.topology().triangles().to_vec(),
            normals: Vec::new(),
        })
    }

    /// The body over the coming step (vertices at its start and end, outward triangles).
    pub fn set_body(
        &mut self,
        start: &[V3],
        end: &[V3],
        triangles: &[[u32; 3]],
        dt: f64,
    ) -> Result<(), ContactError> {
        self.collider.set_body(start, end, triangles, dt)
    }

    /// The body as rigid parts too (see [`Collider::set_parts`]).
    pub fn set_parts(&mut self, parts: RigidParts) {
        self.collider.set_parts(parts);
    }

    /// The rigid parts, if set.
    pub fn parts(&self) -> Option<&RigidParts> {
        self.collider.parts()
    }

    /// Each node's distance to the body at the start of the last step, or a lower bound
    /// (see [`Collider::start_distances`]).
    pub fn start_distances(&self) -> &[f64] {
        self.collider.start_distances()
    }

    /// The parts' motion over the coming step.
    ///
    /// # Errors
    /// When no parts are set or the motion is refused.
    pub fn set_part_motion(
        &mut self,
        start: &[Motion],
        end: &[Motion],
        dt: f64,
    ) -> Result<(), ContactError> {
        self.collider.set_part_motion(start, end, dt)
    }

    /// Nodes that are one point of the garment (see [`Collider::set_cloth_groups`]).
    pub fn set_cloth_groups(&mut self, groups: Vec<u32>) {
        self.collider.set_cloth_groups(groups);
    }

    /// Turn self-collision on or off.
    pub fn set_self_collision(&mut self, on: bool) {
        self.collider.set_self_collision(on);
    }

    /// Change the static friction ρ.
    pub fn set_friction(&mut self, friction: f64) {
        self.collider.set_friction(friction);
    }

    /// Turn one-sided contact on or off.
    pub fn set_one_sided(&mut self, on: bool) {
        self.collider.set_one_sided(on);
    }

    /// Counts since the last call.
    pub fn take_stats(&mut self) -> PassStats {
        self.collider.take_stats()
    }

    /// Area-weighted node normals of the cloth at `positions` (for one-sided contact).
    fn update_normals(&mut self, positions: &[V3]) {
        vertex_normals(positions, &self.triangles, &mut self.normals);
    }
}

impl CollisionHook for BodyContact {
    fn transfer(&mut self, ctx: HookContext<'_>) {
        if self.collider.params().one_sided {
            self.update_normals(ctx.positions);
        } else {
            self.normals.clear();
        }
        self.collider.transfer(
            ctx.positions,
            ctx.velocities,
            ctx.inverse_masses,
            &self.normals,
            ctx.planes,
        );
        self.collider.vertex_planes(
            ctx.positions,
            ctx.inverse_masses,
            &self.triangles,
            ctx.planes,
        );
    }

    fn resolve(&mut self, ctx: HookContext<'_>) {
        if !self.collider.is_active() {
            return;
        }
        if self.collider.params().one_sided {
            self.update_normals(ctx.positions);
        } else {
            self.normals.clear();
        }
        self.collider.resolve(
            ClothView {
                positions: ctx.positions,
                velocities: ctx.velocities,
                exit: ctx.exit,
                inverse_masses: ctx.inverse_masses,
                triangles: &self.triangles,
                normals: &self.normals,
                planes: ctx.planes,
            },
            ctx.dt,
        );
    }
}
