//! One node's collision in a pass: the node as the pass sees it, the outcome, and the
//! geometric pieces of the response (the tangent plane at a hit, recovery of a node found
//! inside, the nearest point outside).

use crate::geom::V3;
use crate::narrow::{Hit, barycentric, last_pass_through};

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
    /// Contacts taken again with a triangle it met.
    pub(super) again: usize,
    /// Put on the end plane of a turning triangle it met (`push_out`).
    pub(super) pushed: bool,
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

/// How far behind a triangle it has met a node's corrected path may end, having passed through
/// it, before the contact is taken again, m: far above rounding (positions of order 1 m are
/// rounded at ~1e-16 m, and a contact without restitution ends exactly on the plane of a
/// triangle that only translates), far below any skin.
pub(super) const PASS_DEPTH: f64 = 1e-12;

/// The velocity of cloth node `k` as this pass has changed it so far (`dv`: the changes of the
/// triangles one node has met).
pub(super) fn cloth_velocity(k: usize, velocities: &[V3], dv: &[(usize, V3)]) -> V3 {
    velocities[k]
        + dv.iter()
            .filter(|(j, _)| *j == k)
            .map(|(_, d)| d)
            .sum::<V3>()
}

/// The side of a triangle (start vertices `x`, velocities `u`) a hit came from: +1 in front of
/// its counter-clockwise normal at the time of the hit, −1 behind.
pub(super) fn side_of(hit: &Hit, x: &[V3; 3], u: &[V3; 3]) -> f64 {
    let xt = [0, 1, 2].map(|k| x[k] + u[k] * hit.time);
    let n = (xt[1] - xt[0]).cross(&(xt[2] - xt[0]));
    if hit.normal.dot(&n) < 0.0 { -1.0 } else { 1.0 }
}

/// The failsafe after `MAX_AGAIN` contacts taken again: if the node (start `p`, mean velocity
/// `v`, inverse mass `inv_m`) still ends the step more than `PASS_DEPTH` behind a triangle it
/// met (start `x`, velocities `u`, inverse masses `inv_mu`; `side` the side it came from),
/// having passed through it, the node's end and the triangle's are moved apart along the
/// triangle's end normal, by their inverse masses (momentum is conserved), until the node's end
/// lies on the triangle's end plane (a few Gauss–Newton steps: moving a cloth triangle's vertices
/// by different amounts turns it). Changes `v`; returns the triangle's velocity changes, or
/// `None` if nothing was moved.
#[allow(clippy::too_many_arguments)]
pub(super) fn push_out(
    p: &V3,
    v: &mut V3,
    inv_m: f64,
    x: &[V3; 3],
    u: &[V3; 3],
    inv_mu: [f64; 3],
    dt: f64,
    side: f64,
) -> Option<[V3; 3]> {
    let pass = last_pass_through(
        p,
        v,
        [&x[0], &x[1], &x[2]],
        [&u[0], &u[1], &u[2]],
        dt,
        side,
        PASS_DEPTH,
    )?;
    let mut u = *u;
    let mut dv = [V3::zeros(); 3];
    for _ in 0..PUSH_STEPS {
        let end = [0, 1, 2].map(|k| x[k] + u[k] * dt);
        let n = (end[1] - end[0]).cross(&(end[2] - end[0]));
        let len = n.norm();
        if len.is_nan() || len <= 0.0 {
            break;
        }
        let n = n * (side / len);
        let q = p + *v * dt;
        let gap = (q - end[0]).dot(&n);
        if gap >= 0.0 {
            break;
        }
        // The triangle's point under the node's end carries the constraint (the weights of
        // the passage for an end beyond the triangle's edges).
        let w = Some(barycentric(&q, [&end[0], &end[1], &end[2]]))
            .filter(|w| w.iter().all(|c| (0.0..=1.0).contains(c)))
            .unwrap_or(pass.weights);
        let denom = inv_m + (0..3).map(|k| w[k] * w[k] * inv_mu[k]).sum::<f64>();
        if denom.is_nan() || denom <= 0.0 {
            break;
        }
        let lambda = -gap / denom / dt;
        *v += n * (inv_m * lambda);
        for k in 0..3 {
            let d = n * (-w[k] * inv_mu[k] * lambda);
            u[k] += d;
            dv[k] += d;
        }
    }
    Some(dv)
}

/// Gauss–Newton steps of `push_out`.
const PUSH_STEPS: usize = 4;

/// Triangles a node may meet in one pass (a node in a crease between two parts meets both).
pub(super) const MAX_CONTACTS: usize = 3;

/// Contacts a node may take again in one pass with a triangle it met that turned or deformed
/// into its corrected path (`narrow::last_pass_through`). Each such contact leaves the node
/// moving with the triangle's local normal speed, which a turning triangle overtakes again,
/// but by far less: in the constructed case of `a_turning_body_triangle_overtakes_the_node_it_caught`
/// (tests/tunnelling.rs) the node ends 0.8 mm behind after two, 2e-11 m after five and within
/// `PASS_DEPTH` after ???.
pub(super) const MAX_AGAIN: usize = 2;

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
        let w = barycentric(p, x);
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
