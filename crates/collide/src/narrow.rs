//! Narrow phase (thesis §5.3.2, (61)–(64)): does a moving point meet a moving triangle during
//! the step, when, where, and from which side?
//!
//! The thesis writes the test for a point and a plane: with `d_ξ = −n` (into the collided
//! surface), the normal speeds `a_i = ṙ_i·d_ξ`, `a_j = ṙ_j·d_ξ` and the distance `l_ij`, a hit is
//! possible only if `(a_i − a_j)Δt ≥ l_ij`; the segment is then intersected with the triangle's
//! plane and the barycentric coordinates decide. For a triangle that only translates during the
//! step this is exact. atelier solves the same question exactly for vertices that move on any
//! straight lines (rotating and deforming triangles: a body part swinging, cloth against cloth):
//! the point and the triangle are coplanar where the cubic
//! `((x₁−x₀) × (x₂−x₀)) · (p − x₀) = 0` has a root in `[0, Δt]`; the earliest root whose
//! barycentric coordinates lie inside is the contact (Provot 1997; Bridson et al. 2002). It reduces
//! to the thesis's linear test when the triangle translates.
//!
//! A point already within `thickness` in front of the triangle and approaching it is a contact at
//! `t = 0` (resting contact; a point that ended a step exactly on the surface is not lost to
//! rounding).

use arrayvec::ArrayVec;

use crate::geom::V3;

/// A contact found by the narrow phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Time from the start of the step to the contact, s (`Δt_c`).
    pub time: f64,
    /// Barycentric coordinates of the contact point on the triangle (sum 1, each ≥ −tolerance).
    pub weights: [f64; 3],
    /// Unit normal of the triangle at the contact, on the side the point came from
    /// (`−d_ξ` in the thesis).
    pub normal: V3,
}

/// Which sides of a triangle collide.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sides {
    /// Only a point coming from the side the triangle's normal (counter-clockwise winding)
    /// points to: a closed body with outward normals.
    Front,
    /// Either side (cloth against cloth).
    Both,
}

/// Which narrow-phase test to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NarrowTest {
    /// Exact for vertices moving on straight lines (the coplanarity cubic).
    #[default]
    Exact,
    /// The thesis's linear test (61)–(64): the start normal, the relative normal speed at the
    /// start, the crossing of the start plane — exact only for translating triangles. Kept to
    /// reproduce the thesis's observations.
    Thesis,
}

/// The thesis's test (61)–(64): `d_ξ = −n` of the triangle at the start, `a_i = ṙ_i·d_ξ`,
/// `a_j = ṙ_j·d_ξ` (the triangle's velocity at the point's projection), a hit only if
/// `(a_i − a_j)Δt ≥ l_ij`; the contact time `l_ij/(a_i − a_j)` and the inside test on the
/// triangle moved to that time.
pub fn point_triangle_thesis(
    p: &V3,
    v: &V3,
    x: [&V3; 3],
    u: [&V3; 3],
    dt: f64,
    thickness: f64,
    sides: Sides,
) -> Option<Hit> {
    let mut n = unit_normal(x)?;
    let mut s0 = (p - x[0]).dot(&n);
    if s0 < -thickness {
        if sides == Sides::Front {
            return None;
        }
        n = -n;
        s0 = -s0;
    }
    let w0 = barycentric(p, x);
    let uj = u[0] * w0[0] + u[1] * w0[1] + u[2] * w0[2];
    let d = -n;
    let a = (v - uj).dot(&d);
    let l = s0.max(0.0);
    if a <= 0.0 || a * dt < l {
        return None;
    }
    let t = l / a;
    let xt = [0, 1, 2].map(|k| x[k] + u[k] * t);
    let w = barycentric(&(p + v * t), [&xt[0], &xt[1], &xt[2]]);
    if !inside(&w) {
        return None;
    }
    Some(Hit {
        time: t,
        weights: w,
        normal: n,
    })
}

/// The unit normal of a triangle (counter-clockwise), `None` for a degenerate one.
fn unit_normal(x: [&V3; 3]) -> Option<V3> {
    let n = (x[1] - x[0]).cross(&(x[2] - x[0]));
    let len = n.norm();
    (len > 0.0 && len.is_finite()).then(|| n / len)
}

/// Barycentric tolerance of the inside test.
const INSIDE: f64 = 1e-9;

/// The earliest contact of the point `p` (velocity `v`) with the triangle `x` (vertex
/// velocities `u`) during `[0, dt]`, if any.
pub fn point_triangle(
    p: &V3,
    v: &V3,
    x: [&V3; 3],
    u: [&V3; 3],
    dt: f64,
    thickness: f64,
    sides: Sides,
) -> Option<Hit> {
    let n = unit_normal(x)?;
    let s0 = (p - x[0]).dot(&n);
    // Resting contact: within the skin, projecting inside, approaching.
    if s0.abs() <= thickness && (sides == Sides::Both || s0 >= -thickness) {
        let side = if s0 >= 0.0 || sides == Sides::Front {
            1.0
        } else {
            -1.0
        };
        let w = barycentric(p, x);
        if inside(&w) {
            let ut = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
            if (v - ut).dot(&n) * side < 0.0 {
                return Some(Hit {
                    time: 0.0,
                    weights: w,
                    normal: n * side,
                });
            }
        }
    }
    let coeffs = coplanarity(p, v, x, u);
    // Behind a body triangle's plane at the start: a triangle that turns can sweep past a node
    // beside it and be met from the front later in the step, so the node is skipped only if it
    // stays behind the plane all step — every Bernstein coefficient of the coplanarity cubic on
    // [0, Δt] negative (the cubic lies in their convex hull). A translating triangle's distance
    // is linear in time: then this is "behind at the start and at the end".
    if sides == Sides::Front && s0 < -thickness && behind_all_step(coeffs, dt) {
        return None;
    }
    for t in cubic_roots_in(coeffs, dt) {
        let xt = [0, 1, 2].map(|k| x[k] + u[k] * t);
        let pt = p + v * t;
        let w = barycentric(&pt, [&xt[0], &xt[1], &xt[2]]);
        if !inside(&w) {
            continue;
        }
        let nt = (xt[1] - xt[0]).cross(&(xt[2] - xt[0]));
        let len = nt.norm();
        if len <= 0.0 {
            continue;
        }
        let nt = nt / len;
        let ut = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
        let approach = (v - ut).dot(&nt);
        if approach == 0.0 {
            continue;
        }
        // The point comes from the side its relative velocity leaves.
        let normal = if approach < 0.0 { nt } else { -nt };
        if sides == Sides::Front && normal.dot(&nt) < 0.0 {
            continue;
        }
        return Some(Hit {
            time: t,
            weights: w,
            normal,
        });
    }
    None
}

/// The last passage of the point `p` (velocity `v`) through the triangle `x` (vertex velocities
/// `u`) during `[0, dt]` from its side `side·n` (`side` ±1, `n` the counter-clockwise normal) to
/// the other, if the point ends the step more than `depth_tol` behind the triangle's end plane
/// and that last plane crossing was through the closed triangle. The hit's normal points to
/// the side the point came from.
///
/// A triangle that only translates cannot meet a point twice in a step (their normal distance
/// is linear in time), so after a contact the point's corrected path cannot pass through it. A
/// triangle that turns or deforms can: a node caught by a swinging body part slides on and is
/// overtaken, or a cloth triangle turned by the impulse of the contact swings into the node.
/// The collider asks this of every triangle a node has met in the pass, with the node's
/// corrected motion, and takes the contact again where it is found.
pub fn last_pass_through(
    p: &V3,
    v: &V3,
    x: [&V3; 3],
    u: [&V3; 3],
    dt: f64,
    side: f64,
    depth_tol: f64,
) -> Option<Hit> {
    let end = [0, 1, 2].map(|k| x[k] + u[k] * dt);
    let n_end = unit_normal([&end[0], &end[1], &end[2]])?;
    let depth = -(p + v * dt - end[0]).dot(&n_end) * side;
    if depth.is_nan() || depth <= depth_tol {
        return None;
    }
    let t = *cubic_roots_in(coplanarity(p, v, x, u), dt).last()?;
    let xt = [0, 1, 2].map(|k| x[k] + u[k] * t);
    let w = barycentric(&(p + v * t), [&xt[0], &xt[1], &xt[2]]);
    if !inside(&w) {
        return None;
    }
    let nt = unit_normal([&xt[0], &xt[1], &xt[2]])? * side;
    let ut = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
    // Front to back at the last crossing (a root where the point only touches the plane and
    // stays behind is not a passage).
    ((v - ut).dot(&nt) < 0.0).then_some(Hit {
        time: t,
        weights: w,
        normal: nt,
    })
}

/// Whether the cubic `c₀ + c₁t + c₂t² + c₃t³` is negative on all of `[0, T]`, by its Bernstein
/// coefficients on that interval (sufficient: the cubic lies in their convex hull).
fn behind_all_step(c: [f64; 4], t_max: f64) -> bool {
    let a = [
        c[0],
        c[1] * t_max,
        c[2] * t_max * t_max,
        c[3] * t_max * t_max * t_max,
    ];
    let b = [
        a[0],
        a[0] + a[1] / 3.0,
        a[0] + 2.0 * a[1] / 3.0 + a[2] / 3.0,
        a[0] + a[1] + a[2] + a[3],
    ];
    b.iter().all(|&v| v < 0.0)
}

/// The coefficients (constant first) of the coplanarity cubic
/// `f(t) = ((x₁−x₀) × (x₂−x₀)) · (p − x₀)` of a point and a triangle all moving linearly:
/// the signed distance of the point from the triangle's plane times twice its area.
fn coplanarity(p: &V3, v: &V3, x: [&V3; 3], u: [&V3; 3]) -> [f64; 4] {
    let (a, b) = (x[1] - x[0], x[2] - x[0]);
    let (da, db) = (u[1] - u[0], u[2] - u[0]);
    let (c, dc) = (p - x[0], v - u[0]);
    // (a + t da) × (b + t db) = a×b + t (a×db + da×b) + t² da×db
    let (k0, k1, k2) = (a.cross(&b), a.cross(&db) + da.cross(&b), da.cross(&db));
    [
        k0.dot(&c),
        k0.dot(&dc) + k1.dot(&c),
        k1.dot(&dc) + k2.dot(&c),
        k2.dot(&dc),
    ]
}

fn inside(w: &[f64; 3]) -> bool {
    w.iter().all(|&c| c >= -INSIDE)
}

/// Barycentric coordinates of the projection of `p` onto the plane of `x`.
pub fn barycentric(p: &V3, x: [&V3; 3]) -> [f64; 3] {
    let (e0, e1, ep) = (x[1] - x[0], x[2] - x[0], p - x[0]);
    let (d00, d01, d11) = (e0.dot(&e0), e0.dot(&e1), e1.dot(&e1));
    let (d20, d21) = (ep.dot(&e0), ep.dot(&e1));
    let den = d00 * d11 - d01 * d01;
    if den <= 0.0 {
        return [f64::NAN; 3];
    }
    let w1 = (d11 * d20 - d01 * d21) / den;
    let w2 = (d00 * d21 - d01 * d20) / den;
    [1.0 - w1 - w2, w1, w2]
}

/// The real roots of `c₀ + c₁t + c₂t² + c₃t³` in `[0, T]`, ascending. The interval is split at
/// the critical points (roots of the derivative), and every piece with a sign change (or an
/// end at zero) is bisected to full precision, so no root is skipped for lack of a good start.
pub fn cubic_roots_in(c: [f64; 4], t_max: f64) -> ArrayVec<f64, 4> {
    let f = |t: f64| ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
    // The size of f's terms over [0, T]: |c_k|·T^k. (Not max |c_k|: with T = Δt = 0.01 s the
    // cubic term of a turning triangle weighs 1e-6 of its coefficient, and a tolerance scaled by
    // the coefficient took an end 7e-12 m behind a triangle for a root at T.)
    let scale = (0..4)
        .map(|k| c[k].abs() * t_max.powi(k as i32))
        .fold(0.0, f64::max);
    if scale == 0.0 || !scale.is_finite() {
        return ArrayVec::new();
    }
    // Critical points of f: 3c₃t² + 2c₂t + c₁ = 0. At most two inside, so at most four knots
    // and three roots: fixed-size buffers, no allocation per candidate.
    let mut knots: ArrayVec<f64, 4> = ArrayVec::new();
    knots.push(0.0);
    let (qa, qb, qc) = (3.0 * c[3], 2.0 * c[2], c[1]);
    if qa.abs() > 1e-300 {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            // Numerically stable pair.
            let q = -0.5 * (qb + qb.signum() * sq);
            let mut r: ArrayVec<f64, 2> = ArrayVec::new();
            if q != 0.0 {
                r.push(qc / q);
            }
            r.push(q / qa);
            for t in r {
                if t > 0.0 && t < t_max {
                    knots.push(t);
                }
            }
        }
    } else if qb.abs() > 1e-300 {
        let t = -qc / qb;
        if t > 0.0 && t < t_max {
            knots.push(t);
        }
    }
    knots.push(t_max);
    knots.sort_by(f64::total_cmp);
    let tol = 1e-14 * scale;
    let mut roots: ArrayVec<f64, 4> = ArrayVec::new();
    for w in knots.windows(2) {
        let (mut lo, mut hi) = (w[0], w[1]);
        let (mut flo, fhi) = (f(lo), f(hi));
        if flo.abs() <= tol {
            if roots
                .last()
                .is_none_or(|r| (lo - r).abs() > 1e-15 * t_max.max(1e-300))
            {
                roots.push(lo);
            }
            continue;
        }
        if fhi.abs() <= tol {
            roots.push(hi);
            continue;
        }
        if flo.signum() == fhi.signum() {
            continue;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            let fm = f(mid);
            if fm.signum() == flo.signum() {
                lo = mid;
                flo = fm;
            } else {
                hi = mid;
            }
        }
        roots.push(0.5 * (lo + hi));
    }
    // A root equal (within 1e-15·T) to the one kept before it is dropped (`Vec::dedup_by`'s rule).
    let mut kept: ArrayVec<f64, 4> = ArrayVec::new();
    for r in roots {
        if kept
            .last()
            .is_none_or(|k| !((r - *k).abs() <= 1e-15 * t_max.max(1e-300)))
        {
            kept.push(r);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn tri() -> [V3; 3] {
        [
            V3::new(0.0, 0.0, 0.0),
            V3::new(1.0, 0.0, 0.0),
            V3::new(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn cubic_roots_are_found_in_order() {
        // (t − 0.1)(t − 0.2)(t − 0.5)
        let c = [-0.01, 0.17, -0.8, 1.0];
        let r = cubic_roots_in(c, 1.0);
        assert_eq!(r.len(), 3, "{r:?}");
        for (a, b) in r.iter().zip([0.1, 0.2, 0.5]) {
            assert_relative_eq!(*a, b, epsilon = 1e-12);
        }
        assert_eq!(cubic_roots_in(c, 0.15).len(), 1);
        // Linear and constant cases.
        assert_relative_eq!(cubic_roots_in([-0.3, 1.0, 0.0, 0.0], 1.0)[0], 0.3);
        assert!(cubic_roots_in([1.0, 0.0, 0.0, 0.0], 1.0).is_empty());
    }

    #[test]
    fn a_falling_point_hits_a_static_triangle_at_the_right_time() {
        let x = tri();
        let z = V3::zeros();
        let p = V3::new(0.2, 0.2, 0.3);
        let v = V3::new(0.0, 0.0, -10.0);
        let hit = point_triangle(
            &p,
            &v,
            [&x[0], &x[1], &x[2]],
            [&z, &z, &z],
            0.05,
            0.0,
            Sides::Front,
        )
        .expect("hits");
        assert_relative_eq!(hit.time, 0.03, epsilon = 1e-12);
        assert_relative_eq!(hit.weights[1], 0.2, epsilon = 1e-12);
        assert_relative_eq!(hit.normal.z, 1.0);
        // Too short a step, or from below with front-only sides: no hit.
        assert!(
            point_triangle(
                &p,
                &v,
                [&x[0], &x[1], &x[2]],
                [&z, &z, &z],
                0.02,
                0.0,
                Sides::Front
            )
            .is_none()
        );
        let below = V3::new(0.2, 0.2, -0.3);
        let up = V3::new(0.0, 0.0, 10.0);
        assert!(
            point_triangle(
                &below,
                &up,
                [&x[0], &x[1], &x[2]],
                [&z, &z, &z],
                0.05,
                0.0,
                Sides::Front
            )
            .is_none()
        );
        let h = point_triangle(
            &below,
            &up,
            [&x[0], &x[1], &x[2]],
            [&z, &z, &z],
            0.05,
            0.0,
            Sides::Both,
        )
        .expect("two-sided");
        assert_relative_eq!(h.normal.z, -1.0);
    }

    #[test]
    fn a_tilting_triangle_sweeps_a_resting_point() {
        // The triangle tilts (vertex 2 rises, the x-axis edge stays) during the step; a point
        // above its far corner, at rest, is met on the way — the thesis's linear test, with the
        // start normal and the mean vertex speed, would meet it at t = 0.2/(50·1/3) = 0.012,
        // after the step.
        let x = tri();
        let (dt, omega) = (0.01, 50.0);
        let u: Vec<V3> = x.iter().map(|q| V3::new(0.0, 0.0, omega * q.y)).collect();
        let p = V3::new(0.1, 0.8, 0.2);
        let z = V3::zeros();
        let hit = point_triangle(
            &p,
            &z,
            [&x[0], &x[1], &x[2]],
            [&u[0], &u[1], &u[2]],
            dt,
            0.0,
            Sides::Both,
        )
        .expect("swept");
        // Vertex 2 rises at 50 m/s: z(t) = 50·y·t, the plane reaches z = 0.2 at y = 0.8 when
        // t = 0.2/(50·0.8) = 0.005.
        assert_relative_eq!(hit.time, 0.005, epsilon = 1e-12);
    }

    /// The tilting triangle of `a_tilting_triangle_sweeps_a_resting_point`, tilting down
    /// (z = −50·y·t), and a point starting 5 mm behind its plane beside it. With
    /// p(t) = (−0.02 + 10t, 0.5 − 20t, −0.005 − 19t) its height above the plane is
    /// d(t) = −0.005 + 6t − 1000t² = −1000(t − 1 ms)(t − 5 ms): the plane sweeps past it at 1 ms
    /// (x = −0.01: beside the triangle), and it passes back through the face at 5 ms
    /// (x = 0.03, y = 0.4), front to back, ending 45 mm behind.
    fn behind_then_through() -> ([V3; 3], [V3; 3], V3, V3) {
        let x = tri();
        let u = x.map(|q| V3::new(0.0, 0.0, -50.0 * q.y));
        (
            x,
            u,
            V3::new(-0.02, 0.5, -0.005),
            V3::new(10.0, -20.0, -19.0),
        )
    }

    #[test]
    fn a_turning_body_triangle_is_met_by_a_point_that_started_behind_its_plane() {
        let (x, u, p, v) = behind_then_through();
        let hit = point_triangle(
            &p,
            &v,
            [&x[0], &x[1], &x[2]],
            [&u[0], &u[1], &u[2]],
            0.01,
            0.0,
            Sides::Front,
        )
        .expect("met from the front at 5 ms");
        assert_relative_eq!(hit.time, 0.005, epsilon = 1e-12);
        assert!(hit.normal.z > 0.0, "{hit:?}");
        // The triangle translating instead (every vertex at −25 m/s, its speed under the
        // point's start): d(t) = −0.005 + 6t, out in front at 0.83 ms and in front to the end,
        // so never met from the front (its one plane crossing is from behind).
        let ut = [V3::new(0.0, 0.0, -25.0); 3];
        assert!(
            point_triangle(
                &p,
                &v,
                [&x[0], &x[1], &x[2]],
                [&ut[0], &ut[1], &ut[2]],
                0.01,
                0.0,
                Sides::Front
            )
            .is_none()
        );
    }

    #[test]
    fn behind_all_step_needs_the_whole_interval() {
        // −1 − t: negative throughout.
        assert!(behind_all_step([-1.0, -1.0, 0.0, 0.0], 1.0));
        // −1 + 10t − 10t²: −1 at both ends, +1.5 at t = 0.5.
        assert!(!behind_all_step([-1.0, 10.0, -10.0, 0.0], 1.0));
        // −1 + t³ on [0, 2]: 7 at the end.
        assert!(!behind_all_step([-1.0, 0.0, 0.0, 1.0], 2.0));
        // −1 + t³ on [0, 0.5]: −0.875 at the end, negative throughout.
        assert!(behind_all_step([-1.0, 0.0, 0.0, 1.0], 0.5));
    }

    #[test]
    fn the_last_passage_through_a_triangle_is_found_and_only_if_the_point_ends_behind() {
        let x = tri();
        let z = V3::zeros();
        let zs = [&z, &z, &z];
        let xs = [&x[0], &x[1], &x[2]];
        // Straight through a resting triangle: z(t) = 0.1 − 20t, through at 5 ms at (0.2, 0.2),
        // ends 0.1 m behind.
        let p = V3::new(0.2, 0.2, 0.1);
        let v = V3::new(0.0, 0.0, -20.0);
        let hit = last_pass_through(&p, &v, xs, zs, 0.01, 1.0, 1e-12).expect("through");
        assert_relative_eq!(hit.time, 0.005, epsilon = 1e-15);
        assert_relative_eq!(hit.normal.z, 1.0);
        for (w, e) in hit.weights.iter().zip([0.6, 0.2, 0.2]) {
            assert_relative_eq!(*w, e, epsilon = 1e-12);
        }
        // Seen from the back it ends in front: nothing.
        assert!(last_pass_through(&p, &v, xs, zs, 0.01, -1.0, 1e-12).is_none());
        // Ending on the plane, or less than the tolerance behind it: nothing.
        let on = V3::new(0.0, 0.0, -10.0);
        assert!(last_pass_through(&p, &on, xs, zs, 0.01, 1.0, 1e-12).is_none());
        let near = V3::new(0.0, 0.0, -10.0 - 0.5e-12 / 0.01);
        assert!(last_pass_through(&p, &near, xs, zs, 0.01, 1.0, 1e-12).is_none());
        // Beside the triangle: ends behind its plane without passing through it.
        let beside = V3::new(0.8, 0.8, 0.1);
        assert!(last_pass_through(&beside, &v, xs, zs, 0.01, 1.0, 1e-12).is_none());
        // Two plane crossings of a tilting triangle: the last, through the face, at 5 ms.
        let (x, u, p, v) = behind_then_through();
        let hit = last_pass_through(
            &p,
            &v,
            [&x[0], &x[1], &x[2]],
            [&u[0], &u[1], &u[2]],
            0.01,
            1.0,
            1e-12,
        )
        .expect("through at 5 ms");
        assert_relative_eq!(hit.time, 0.005, epsilon = 1e-12);
        // The same path shifted 0.1 m in −x crosses the plane last beside the face (x = −0.05).
        let p_beside = p - V3::new(0.1, 0.0, 0.0);
        assert!(
            last_pass_through(
                &p_beside,
                &v,
                [&x[0], &x[1], &x[2]],
                [&u[0], &u[1], &u[2]],
                0.01,
                1.0,
                1e-12
            )
            .is_none()
        );
    }
}
