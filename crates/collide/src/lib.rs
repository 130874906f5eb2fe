//! # atelier-collide
//!
//! Cloth collision (thesis §5.2–5.5; `method.md` §3). Works on plain slices — positions,
//! velocities, inverse masses, triangles — and knows nothing of fabrics.

pub mod broad;
pub mod collider;
pub mod distance;
pub mod geom;
pub mod narrow;
pub mod parts;
pub mod response;
pub mod shapes;

pub use collider::{ClothView, Collider, ContactError, ContactParams, ContactPlane, PassStats};
pub use geom::{Aabb, V3};
pub use parts::{Nearest, RigidParts};
pub use response::ContactMaterial;
