//! # atelier-body
//!
//! The human body of the PARTY thesis (§2.4 (II), §4.6.2, §5.6): a surface of triangles split
//! into 17 rigid parts in a tree with movable joints, driven by keyframed motion; and its range
//! images ([`range`]): the body gridded from front and back range images (§4.6.2, §4.7.2) and
//! the range images of a posed mannequin rendered for it. The parts are [`part::Part`].

pub mod articulate;
pub mod build;
pub mod description;
pub mod io;
pub mod kinematics;
pub mod model;
pub mod motion;
pub mod part;
pub mod range;
pub mod scan;
#[cfg(test)]
mod testing;

pub use kinematics::{Body, PartFrame, Posed, bounding_box};
pub use model::{JointLimits, LabelledMesh, Mannequin, Part, PartMesh, V3};
pub use motion::{LimitPolicy, Motion, MotionError, MotionSpec, Pose, PoseRate};
