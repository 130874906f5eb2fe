//! How collisions are computed ([`ContactParams`]), the contact planes a pass hands to the shape
//! solve, and the errors of a pass.

use crate::broad::BroadKind;
use crate::geom::V3;
use crate::narrow::NarrowTest;
use crate::parts::PartsError;
use crate::response::ContactMaterial;

/// How collisions are computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactParams {
    /// Restitution ν and static friction ρ (the thesis's dress: 0.1 and 0.3).
    pub material: ContactMaterial,
    /// Contact skin, m: a node closer than this to a surface and approaching it is in contact.
    pub thickness: f64,
    /// Collide only where the cloth's normal and the body's normal agree (the thesis's
    /// "semi-transparent" body): a garment passes through the body from outside and catches on
    /// its inside.
    pub one_sided: bool,
    /// Cloth against its own triangles.
    pub self_collision: bool,
    /// Staged model (§5.4): transfer the body's motion to the cloth within reach before the
    /// shape constraints; `false` is the physical model alone.
    pub staged: bool,
    /// The search reach of the transfer beyond the body's largest displacement in the step, m
    /// (the thesis: 7 cm).
    pub transfer_margin: f64,
    /// Broad phase for the body and for the cloth.
    pub broad: BroadKind,
    /// Narrow-phase test (exact by default; the thesis's linear test to reproduce it).
    pub narrow: NarrowTest,
    /// A node found behind a body triangle (over its face, less than this deep, m) with no
    /// contact in the pass is moved out within the step (addition: the thesis has no recovery;
    /// a node squeezed into a crease between two moving parts otherwise stays inside). 0 turns
    /// it off; keep it below half the thinnest body part.
    pub recovery_depth: f64,
    /// Body contact kept inside the shape iterations (addition; see `docs/collision.md`): a
    /// node within this distance of the body at the start of the step, or that met it in a
    /// pass, gets the body's tangent plane (moved to the end of the step) as a one-sided
    /// constraint that every shape iteration respects, so the cloth's constraints and the
    /// contact are solved together instead of in turn. 0 turns it off. Default 0.01 m.
    pub plane_reach: f64,
    /// Body vertices against the cloth's triangles (addition; `docs/collision.md` §4c, see
    /// `Collider::vertex_planes`). Default false: the sewn skirt in cotton broad does not come
    /// to rest with it.
    pub vertex_planes: bool,
}

/// A one-sided contact constraint for one node: its position at the end of the step must
/// satisfy `(x − point)·normal ≥ 0`. A zero normal means none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactPlane {
    /// A point of the plane (the body surface plus the skin), end of step, m.
    pub point: V3,
    /// Unit normal, away from the body; zero when the node has no plane.
    pub normal: V3,
    /// The body point's velocity over the step (friction acts on the velocity relative to it).
    pub velocity: V3,
    /// Static friction ρ of the contact.
    pub friction: f64,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            material: ContactMaterial {
                restitution: 0.1,
                friction: 0.3,
            },
            thickness: 1e-3,
            one_sided: false,
            self_collision: false,
            staged: true,
            transfer_margin: 0.07,
            broad: BroadKind::Bvh,
            narrow: NarrowTest::Exact,
            recovery_depth: 5e-3,
            plane_reach: 0.01,
            vertex_planes: false,
        }
    }
}

/// Why parameters or a body were refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// A parameter outside its range.
    #[error("contact parameter `{name}` = {value} is out of range ({rule})")]
    Param {
        /// Field.
        name: &'static str,
        /// Value.
        value: f64,
        /// The rule.
        rule: &'static str,
    },
    /// Body arrays of different lengths.
    #[error("body start has {start} vertices, end {end}")]
    BodyMismatch {
        /// Start positions.
        start: usize,
        /// End positions.
        end: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error("body triangle {triangle} names vertex {vertex}, there are {count}")]
    BodyIndex {
        /// Triangle.
        triangle: usize,
        /// Vertex named.
        vertex: u32,
        /// Vertices.
        count: usize,
    },
    /// A non-finite body vertex.
    #[error("body vertex {vertex} is not finite")]
    BodyNotFinite {
        /// Vertex.
        vertex: usize,
    },
    /// The rigid parts or their motion were refused.
    #[error(transparent)]
    Parts(#[from] PartsError),
}

impl ContactParams {
    /// Check the ranges.
    pub fn check(&self) -> Result<(), ContactError> {
        let rules: [(&'static str, f64, bool, &'static str); 5] = [
            (
                "restitution",
                self.material.restitution,
                (0.0..=1.0).contains(&self.material.restitution),
                "0 ≤ ν ≤ 1",
            ),
            (
                "friction",
                self.material.friction,
                self.material.friction >= 0.0 && self.material.friction.is_finite(),
                "ρ ≥ 0, finite",
            ),
            (
                "thickness",
                self.thickness,
                self.thickness >= 0.0 && self.thickness.is_finite(),
                "≥ 0 m, finite",
            ),
            (
                "transfer_margin",
                self.transfer_margin,
                self.transfer_margin >= 0.0 && self.transfer_margin.is_finite(),
                "≥ 0 m, finite",
            ),
            (
                "plane_reach",
                self.plane_reach,
                self.plane_reach >= 0.0 && self.plane_reach.is_finite(),
                "≥ 0 m, finite",
            ),
        ];
        for (name, value, ok, rule) in rules {
            if !ok {
                return Err(ContactError::Param { name, value, rule });
            }
        }
        Ok(())
    }
}
