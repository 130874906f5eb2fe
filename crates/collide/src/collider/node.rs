//! One node's collision in a pass: the node as the pass sees it, the outcome, and the
//! geometric pieces of the response (the tangent plane at a hit, recovery of a node found
//! inside, the nearest point outside).

use crate::geom::V3;

use super::{Body, ContactParams, ContactPlane, closest_point};

/// What one collision pass reads of the cloth.
#[derive(Clone, Copy)]
pub(super) struct NodeView<'a> {
    pub(super) positions: &'a [V3],
    pub(super) velocities: &'a [V3],
    pub(super) inverse_masses: &'a [f64],
    pub(super) triangles: &'a [[u32; 3]],
    pub(super) normals: &'a [V3],
}

/// What one node's contacts in a pass changed.
#[derive(Clone, Debug, Default)]
pub(super) struct NodeOutcome {
    /// Its new velocity (the mean velocity over the step), if a contact or recovery changed it.
    pub(super) velocity: Option<V3>,
    /// Added to its exit correction.
    pub(super) exit: V3,
    /// The contact plane of its last body contact.
    pub(super) plane: Option<ContactPlane>,
    /// Velocity changes of cloth triangle vertices it met (self-collision).
    pub(super) cloth_dv: Vec<(usize, V3)>,
    pub(super) candidates: usize,
    pub(super) body_hits: usize,
    pub(super) self_hits: usize,
    pub(super) recovered: bool,
}

impl NodeOutcome {
    pub(super) fn changed(&self) -> bool {
        self.velocity.is_some() || self.candidates > 0
    }
}

/// The tangent plane of the body at the point with weights `w` of triangle `t` nearest to `p`
/// (at `dist`), carried to the end of the step and lifted by the skin: the normal points from
/// the nearest point to the node (the triangle's normal when the node is on the surface).
pub(super) fn tangent_plane(
    body: &Body,
    p: &V3,
    dist: f64,
    t: usize,
    w: [f64; 3],
    params: &ContactParams,
) -> ContactPlane {
    let tri = body.triangles[t];
    let q0: V3 = (0..3).map(|k| body.start[tri[k] as usize] * w[k]).sum();
    let q1: V3 = (0..3).map(|k| body.end[tri[k] as usize] * w[k]).sum();
    let normal = if dist > 1e-9 {
        (p - q0) / (p - q0).norm()
    } else {
        let x = tri.map(|k| body.start[k as usize]);
        (x[1] - x[0]).cross(&(x[2] - x[0])).normalize()
    };
    ContactPlane {
        point: q1 + normal * params.thickness,
        normal,
        velocity: (0..3).map(|k| body.vel[tri[k] as usize] * w[k]).sum(),
        friction: params.material.friction,
    }
}

/// Contacts a node may take in one pass (each against a different triangle).
pub(super) const MAX_CONTACTS: usize = 3;

/// The velocity change that takes a node found behind a body triangle — over its face, less than
/// the recovery depth deep — back to the surface within the step (relative to the triangle's
/// motion): the shallowest such triangle decides.
pub(super) fn recover(
    body: &Body,
    p: &V3,
    v: &V3,
    dt: f64,
    params: ContactParams,
    candidates: &mut Vec<u32>,
) -> Option<V3> {
    candidates.clear();
    body.broad.query(p, p, params.recovery_depth, candidates);
    let mut best: Option<(f64, V3, V3)> = None;
    for &t in candidates.iter() {
        let tri = body.triangles[t as usize];
        let x = tri.map(|k| &body.start[k as usize]);
        let n = (x[1] - x[0]).cross(&(x[2] - x[0]));
        let len = n.norm();
        if len <= 0.0 {
            continue;
        }
        let n = n / len;
        let depth = -(p - x[0]).dot(&n);
        if depth <= params.thickness || depth > params.recovery_depth {
            continue;
        }
        let w = crate::narrow::barycentric(p, x);
        if w.iter().any(|&c| c < 0.0) || best.is_some_and(|b| depth >= b.0) {
            continue;
        }
        let u: V3 = (0..3).map(|k| body.vel[tri[k] as usize] * w[k]).sum();
        best = Some((depth, n, u));
    }
    let (depth, n, u) = best?;
    // Leave the step on the surface: relative normal speed at least depth/dt outwards.
    let need = depth / dt;
    let have = (v - u).dot(&n);
    (have < need).then(|| n * (need - have))
}

/// The nearest point within `radius` of `p` among the `candidates` triangles of the body at the
/// start of the step, with `p` on the outside (or within the skin): (distance, triangle,
/// barycentric weights).
pub(super) fn nearest_outside(
    body: &Body,
    p: &V3,
    candidates: &[u32],
    radius: f64,
    thickness: f64,
) -> Option<(f64, usize, [f64; 3])> {
    let mut best: Option<(f64, usize, [f64; 3])> = None;
    for &t in candidates {
        let tri = body.triangles[t as usize];
        let x = tri.map(|k| &body.start[k as usize]);
        let (q, w) = closest_point(p, x);
        let dist = (p - q).norm();
        if dist > radius || best.is_some_and(|b| dist >= b.0) {
            continue;
        }
        // Outside (or on) the body: the outward normal faces the node.
        let n = (x[1] - x[0]).cross(&(x[2] - x[0]));
        if (p - q).dot(&n) < -thickness * n.norm() {
            continue;
        }
        best = Some((dist, t as usize, w));
    }
    best
}
