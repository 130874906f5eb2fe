//! The mannequin's static model: 17 rigid parts, each a closed triangle mesh in the rest pose,
//! joined by joints with pivots and rotation limits, in the tree of [`Part::parent`] rooted at
//! the pelvis.
//!
//! Frame (shared with the range images, [`crate::range`]): x towards the body's left, y up, z forward; metres.
//! The rest pose stands upright with the arms slightly away from the torso (an A-pose) and the
//! feet on the plane y = 0.

pub use crate::part::Part;

/// 3-vector, m.
pub type V3 = nalgebra::Vector3<f64>;

/// Rotation limits of a joint, degrees. A joint's rotation is given by three angles: right-handed
/// rotations about the x, y and z axes of the parent's rest frame (x = the body's left, y = up,
/// z = forward), applied x first: `R = R_z(γ) · R_y(β) · R_x(α)`. With these signs a downward
/// segment swings **backward** for positive α: hip and shoulder flexion (forward) are negative,
/// knee flexion (shin back) positive, elbow flexion (forearm forward) negative, ankle
/// dorsiflexion (toes up) negative, neck flexion (head forward) positive; β > 0 turns the part
/// towards the body's left seen from above; γ > 0 swings a downward segment towards the body's
/// left (so abduction is positive γ for the left limbs and negative for the right).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    /// Smallest angles about x, y, z.
    pub min_deg: [f64; 3],
    /// Largest angles about x, y, z.
    pub max_deg: [f64; 3],
}

impl JointLimits {
    /// No rotation allowed.
    pub const FIXED: JointLimits = JointLimits {
        min_deg: [0.0; 3],
        max_deg: [0.0; 3],
    };

    /// Whether the angles (deg, about x, y, z) lie within the limits (with `slack` degrees).
    pub fn contains(&self, angles_deg: [f64; 3], slack: f64) -> bool {
        (0..3).all(|k| {
            angles_deg[k] >= self.min_deg[k] - slack && angles_deg[k] <= self.max_deg[k] + slack
        })
    }
}

/// One rigid part in the rest pose.
#[derive(Clone, Debug, PartialEq)]
pub struct PartMesh {
    /// Which part.
    pub part: Part,
    /// Vertices in the rest pose, world frame, m.
    pub vertices: Vec<V3>,
    /// Triangles, counter-clockwise seen from outside (outward normals); the mesh is closed.
    pub triangles: Vec<[u32; 3]>,
    /// The joint's pivot (where the part turns relative to its parent; for the pelvis, the root
    /// the whole body moves with), rest pose, world frame, m.
    pub pivot: V3,
    /// Rotation limits of the joint.
    pub limits: JointLimits,
}

/// The mannequin: its 17 parts, indexed by [`Part::index`].
#[derive(Clone, Debug, PartialEq)]
pub struct Mannequin {
    /// Name (the description's).
    pub name: String,
    /// Parts in [`Part::ALL`] order.
    pub parts: Vec<PartMesh>,
}

impl Mannequin {
    /// The part's mesh.
    pub fn part(&self, p: Part) -> &PartMesh {
        &self.parts[p.index()]
    }

    /// Total vertex and triangle counts.
    pub fn counts(&self) -> (usize, usize) {
        self.parts.iter().fold((0, 0), |(v, t), p| {
            (v + p.vertices.len(), t + p.triangles.len())
        })
    }

    /// All parts as one labelled mesh (vertices concatenated in part order), rest pose.
    pub fn labelled_mesh(&self) -> LabelledMesh {
        let mut m = LabelledMesh::default();
        for p in &self.parts {
            let base = m.vertices.len() as u32;
            m.vertices.extend_from_slice(&p.vertices);
            m.vertex_part
                .extend(std::iter::repeat_n(p.part, p.vertices.len()));
            m.triangles
                .extend(p.triangles.iter().map(|t| t.map(|k| k + base)));
            m.triangle_part
                .extend(std::iter::repeat_n(p.part, p.triangles.len()));
        }
        m
    }
}

/// A triangle mesh with a part label per vertex and per triangle (a posed mannequin, or a scan
/// with labels).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LabelledMesh {
    /// Vertices, m.
    pub vertices: Vec<V3>,
    /// Triangles (outward).
    pub triangles: Vec<[u32; 3]>,
    /// Part of each vertex.
    pub vertex_part: Vec<Part>,
    /// Part of each triangle.
    pub triangle_part: Vec<Part>,
}
