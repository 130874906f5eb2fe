//! An articulated body as rigid parts: each part a closed mesh in its rest frame that moves by a
//! rigid motion, the body the union of the parts.
//!
//! A mannequin's parts overlap where they meet (each part reaches into its parent so no gap
//! opens when a joint turns): a part's surface inside another part is not the body's surface.
//! The nearest point of a triangle soup can then lie on such an internal face and give a wrong
//! contact normal. The union's distance is exact for the cases contact needs:
//!
//! - a point outside every part: its distance to the union is the least distance to a part, and
//!   the nearest point of that part lies on the union's surface (were it strictly inside another
//!   part, that part would be nearer) — so [`RigidParts::nearest`] gives the true surface point
//!   and normal;
//! - a point inside some part is inside the body; the reported depth is the largest depth into a
//!   single part, a lower bound of the depth into the union (exact away from the joints).
//!
//! Distances come from parry's point projection on each part's mesh (built once, in the rest
//! frame, with pseudo-normals for the inside test): exact, no grid, no build cost beyond the
//! BVH. A point is taken into a part's rest frame by the inverse of the part's motion, and the
//! parts whose rest boxes lie beyond the search radius are skipped.

use nalgebra::Isometry3;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

use crate::V3;
use crate::distance::{MeshError, check_closed};
use crate::geom::Aabb;

/// A rigid motion: rest frame → world.
pub type Motion = Isometry3<f64>;

/// Why a rigid-part body was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PartsError {
    /// A part's mesh is not a closed, consistently oriented mesh.
    #[error("part {part}: {source}")]
    Mesh {
        /// The part.
        part: usize,
        /// What is wrong with its mesh.
        source: MeshError,
    },
    /// No parts.
    #[error("a rigid-part body needs at least one part")]
    Empty,
    /// The motions do not match the parts.
    #[error("{found} {which} motions for {parts} parts")]
    MotionCount {
        /// "start" or "end".
        which: &'static str,
        /// Motions given.
        found: usize,
        /// Parts.
        parts: usize,
    },
    /// A motion is not finite.
    #[error("the {which} motion of part {part} is not finite")]
    MotionNotFinite {
        /// "start" or "end".
        which: &'static str,
        /// The part.
        part: usize,
    },
    /// The time step is not positive and finite.
    #[error("time step {0} s is not positive and finite")]
    Step(f64),
}

struct Part {
    mesh: TriMesh,
    /// Box of the rest vertices.
    rest_box: Aabb,
}

/// The nearest point of the body to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// The part it lies on.
    pub part: usize,
    /// Signed distance from the query point, m: negative when the point is inside the part.
    pub distance: f64,
    /// The point, in the part's rest frame.
    pub rest_point: V3,
    /// Outward unit normal there, rest frame: from the surface point towards an outside query
    /// point (away from an inside one), the face normal when the query point is on the surface.
    pub rest_normal: V3,
}

/// The union of rigidly moving closed parts, with the motion of the current step.
pub struct RigidParts {
    parts: Vec<Part>,
    start: Vec<Motion>,
    end: Vec<Motion>,
    inv_start: Vec<Motion>,
    inv_end: Vec<Motion>,
    dt: f64,
    /// The previous step's motion (the identity before the first), for the change of velocity.
    prev_start: Vec<Motion>,
    prev_end: Vec<Motion>,
    prev_dt: f64,
}

impl std::fmt::Debug for RigidParts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RigidParts")
            .field("parts", &self.parts.len())
            .field("dt", &self.dt)
            .finish()
    }
}

fn to_glam(v: &V3) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

fn from_glam(v: PVec) -> V3 {
    V3::new(v.x, v.y, v.z)
}

impl RigidParts {
    /// A body of `parts` (rest vertices, outward triangles), each closed, at rest at the
    /// identity motion.
    ///
    /// # Errors
    /// [`PartsError::Mesh`] naming the part and its defect, or [`PartsError::Empty`].
    pub fn new(parts: &[(&[V3], &[[u32; 3]])]) -> Result<Self, PartsError> {
        if parts.is_empty() {
            return Err(PartsError::Empty);
        }
        let built = parts
            .iter()
            .enumerate()
            .map(|(k, (vertices, triangles))| {
                check_closed(vertices, triangles)
                    .map_err(|source| PartsError::Mesh { part: k, source })?;
                let mesh = TriMesh::with_flags(
                    vertices.iter().map(to_glam).collect(),
                    triangles.to_vec(),
                    TriMeshFlags::ORIENTED,
                )
                .map_err(|_| PartsError::Mesh {
                    part: k,
                    source: MeshError::Empty {
                        vertices: vertices.len(),
                        triangles: triangles.len(),
                    },
                })?;
                Ok(Part {
                    mesh,
                    rest_box: Aabb::from_points(vertices.iter()),
                })
            })
            .collect::<Result<Vec<_>, PartsError>>()?;
        let n = built.len();
        Ok(Self {
            parts: built,
            start: vec![Motion::identity(); n],
            end: vec![Motion::identity(); n],
            inv_start: vec![Motion::identity(); n],
            inv_end: vec![Motion::identity(); n],
            dt: 1.0,
            prev_start: vec![Motion::identity(); n],
            prev_end: vec![Motion::identity(); n],
            prev_dt: 1.0,
        })
    }

    /// Number of parts.
    pub fn len(&self) -> usize {
        self.parts.len()
    }

    /// Always false (a body has at least one part).
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// The motion of every part over the coming step: rest → world at its start and its end.
    ///
    /// # Errors
    /// A count mismatch, a non-finite motion or a bad `dt`; the body keeps its previous motion.
    pub fn set_motion(
        &mut self,
        start: &[Motion],
        end: &[Motion],
        dt: f64,
    ) -> Result<(), PartsError> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(PartsError::Step(dt));
        }
        for (which, m) in [("start", start), ("end", end)] {
            if m.len() != self.parts.len() {
                return Err(PartsError::MotionCount {
                    which,
                    found: m.len(),
                    parts: self.parts.len(),
                });
            }
            if let Some(part) = m.iter().position(|m| {
                !(m.translation.vector.iter().all(|x| x.is_finite())
                    && m.rotation.coords.iter().all(|x| x.is_finite()))
            }) {
                return Err(PartsError::MotionNotFinite { which, part });
            }
        }
        std::mem::swap(&mut self.prev_start, &mut self.start);
        std::mem::swap(&mut self.prev_end, &mut self.end);
        self.prev_dt = self.dt;
        self.start.copy_from_slice(start);
        self.end.copy_from_slice(end);
        for (inv, m) in self.inv_start.iter_mut().zip(start) {
            *inv = m.inverse();
        }
        for (inv, m) in self.inv_end.iter_mut().zip(end) {
            *inv = m.inverse();
        }
        self.dt = dt;
        Ok(())
    }

    /// Signed distance of a point given in part `k`'s rest frame to that part alone, m.
    pub fn rest_distance(&self, k: usize, p: &V3) -> f64 {
        let (proj, _) = self.parts[k]
            .mesh
            .project_local_point_and_get_location(to_glam(p), false);
        let gap = (from_glam(proj.point) - p).norm();
        if proj.is_inside { -gap } else { gap }
    }

    /// The nearest body point to `p` (world, at the start of the step, or at its end when
    /// `at_end`) among the points within `radius`, or `None` when there is none. A point inside
    /// a part is always found (with a negative distance), however deep.
    pub fn nearest(&self, p: &V3, radius: f64, at_end: bool) -> Option<Nearest> {
        let inv = if at_end {
            &self.inv_end
        } else {
            &self.inv_start
        };
        let mut best: Option<Nearest> = None;
        for (k, part) in self.parts.iter().enumerate() {
            let q = inv[k].transform_point(&(*p).into()).coords;
            let inside_box =
                (0..3).all(|a| part.rest_box.min[a] <= q[a] && q[a] <= part.rest_box.max[a]);
            // Outside the box: only points within the radius (and nearer than the best so far,
            // unless that best is inside) can matter.
            let limit = match best {
                Some(b) if b.distance >= 0.0 => b.distance.min(radius),
                Some(_) => -1.0,
                None => radius,
            };
            if !inside_box && (limit < 0.0 || box_distance(&part.rest_box, &q) > limit) {
                continue;
            }
            let max_dist = if inside_box { f64::MAX } else { limit };
            let Some((proj, (tri, _))) = part
                .mesh
                .project_local_point_and_get_location_with_max_dist(to_glam(&q), false, max_dist)
            else {
                continue;
            };
            let surface = from_glam(proj.point);
            let gap = (q - surface).norm();
            let distance = if proj.is_inside { -gap } else { gap };
            if distance > radius || best.is_some_and(|b| distance >= b.distance) {
                continue;
            }
            let rest_normal = if gap > 1e-9 {
                (q - surface) / distance
            } else {
                let t = part.mesh.triangle(tri);
                from_glam(t.scaled_normal()).normalize()
            };
            best = Some(Nearest {
                part: k,
                distance,
                rest_point: surface,
                rest_normal,
            });
        }
        best
    }

    /// Signed distance of `p` to the body (the least over the parts; see the module notes for
    /// points inside), at the start of the step or at its end; `radius` bounds the search for
    /// outside points (a farther point reports `radius`).
    pub fn signed_distance(&self, p: &V3, radius: f64, at_end: bool) -> f64 {
        self.nearest(p, radius, at_end)
            .map_or(radius, |n| n.distance)
    }

    /// A nearest point and its outward normal in the world, at the start of the step or at its
    /// end.
    pub fn place(&self, n: &Nearest, at_end: bool) -> (V3, V3) {
        let m = if at_end {
            &self.end[n.part]
        } else {
            &self.start[n.part]
        };
        (
            m.transform_point(&n.rest_point.into()).coords,
            m.transform_vector(&n.rest_normal),
        )
    }

    /// The velocity of a body point over the step (its displacement from start to end / Δt).
    pub fn velocity(&self, n: &Nearest) -> V3 {
        let a = self.start[n.part].transform_point(&n.rest_point.into());
        let b = self.end[n.part].transform_point(&n.rest_point.into());
        (b - a) / self.dt
    }

    /// The change of a body point's velocity since the previous step (the staged model's
    /// transfer; the body is at rest before the first step).
    pub fn velocity_change(&self, n: &Nearest) -> V3 {
        let q = n.rest_point.into();
        let before = (self.prev_end[n.part].transform_point(&q)
            - self.prev_start[n.part].transform_point(&q))
            / self.prev_dt;
        self.velocity(n) - before
    }

    /// Whether no part moves in this step nor moved in the previous one (the staged transfer
    /// then has nothing to add).
    pub fn is_still(&self) -> bool {
        self.start == self.end && self.prev_start == self.prev_end
    }

    /// The largest displacement of any part's box corner over the step (bounds every surface
    /// point's displacement).
    pub fn max_displacement(&self) -> f64 {
        let mut worst = 0.0f64;
        for (k, part) in self.parts.iter().enumerate() {
            let (lo, hi) = (part.rest_box.min, part.rest_box.max);
            for c in 0..8 {
                let corner = V3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                );
                let a = self.start[k].transform_point(&corner.into());
                let b = self.end[k].transform_point(&corner.into());
                worst = worst.max((b - a).norm());
            }
        }
        worst
    }
}

/// Distance from `q` to a box (0 inside).
fn box_distance(b: &Aabb, q: &V3) -> f64 {
    let d = (b.min - q).sup(&(q - b.max)).sup(&V3::zeros());
    d.norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;
    use nalgebra::{Translation3, UnitQuaternion};

    fn cube(half: f64) -> (Vec<V3>, Vec<[u32; 3]>) {
        shapes::box_mesh(V3::repeat(-half), V3::repeat(half))
    }

    /// Two overlapping unit cubes: a point outside both gets the union's surface, never the
    /// face of one cube that lies inside the other.
    #[test]
    fn the_union_of_overlapping_parts_has_no_internal_faces() {
        let (v, t) = cube(0.5);
        let shifted: Vec<V3> = v.iter().map(|p| p + V3::new(0.6, 0.0, 0.0)).collect();
        let body = RigidParts::new(&[(&v, &t), (&shifted, &t)]).unwrap();
        // Above the overlap (x = 0.3): the nearest point is on the top faces, 0.2 away.
        let n = body.nearest(&V3::new(0.3, 0.7, 0.0), 1.0, false).unwrap();
        assert!((n.distance - 0.2).abs() < 1e-12, "{n:?}");
        assert!((n.rest_normal - V3::y()).norm() < 1e-12);
        // Inside the overlap, 0.05 below the top: inside the body, at depth ≥ 0.05.
        let n = body.nearest(&V3::new(0.3, 0.45, 0.0), 1.0, false).unwrap();
        assert!((n.distance + 0.05).abs() < 1e-12, "{n:?}");
        assert!((n.rest_normal - V3::y()).norm() < 1e-12, "{n:?}");
        // Beyond the radius: nothing.
        assert!(body.nearest(&V3::new(0.3, 2.0, 0.0), 1.0, false).is_none());
    }

    /// A part moved rigidly: distances follow the motion, points and normals are carried to the
    /// end of the step, and the surface velocity is the displacement over Δt.
    #[test]
    fn distances_follow_the_rigid_motion() {
        let (v, t) = cube(0.5);
        let mut body = RigidParts::new(&[(&v, &t)]).unwrap();
        let start =
            Motion::from_parts(Translation3::new(1.0, 0.0, 0.0), UnitQuaternion::identity());
        let end = Motion::from_parts(
            Translation3::new(1.0, 0.1, 0.0),
            UnitQuaternion::from_axis_angle(&V3::z_axis(), std::f64::consts::FRAC_PI_2),
        );
        body.set_motion(&[start], &[end], 0.01).unwrap();
        let p = V3::new(1.0, 0.8, 0.0);
        let n = body.nearest(&p, 1.0, false).unwrap();
        assert!((n.distance - 0.3).abs() < 1e-12);
        let (q0, n0) = body.place(&n, false);
        assert!((q0 - V3::new(1.0, 0.5, 0.0)).norm() < 1e-12 && (n0 - V3::y()).norm() < 1e-12);
        // Turned a quarter about z and lifted 0.1: the top face's centre is now at x = 0.5.
        let (q1, n1) = body.place(&n, true);
        assert!((q1 - V3::new(0.5, 0.1, 0.0)).norm() < 1e-12, "{q1}");
        assert!((n1 + V3::x()).norm() < 1e-12, "{n1}");
        assert!((body.velocity(&n) - (q1 - q0) / 0.01).norm() < 1e-9);
        // At rest before: the whole velocity is new; the same motion again: no change.
        assert!((body.velocity_change(&n) - body.velocity(&n)).norm() < 1e-9);
        // At the end of the step the same world point is 0.8 − 0.1 − ... from the moved cube.
        let d_end = body.signed_distance(&V3::new(1.0, 0.8, 0.0), 1.0, true);
        assert!((d_end - 0.2).abs() < 1e-12, "{d_end}");
        assert!(body.max_displacement() > 0.5);
    }

    /// Bad input is refused with the part and the reason.
    #[test]
    fn bad_parts_and_motions_are_refused() {
        let (v, t) = cube(0.5);
        let open: Vec<[u32; 3]> = t[1..].to_vec();
        assert!(matches!(
            RigidParts::new(&[(&v, &t), (&v, &open)]),
            Err(PartsError::Mesh { part: 1, .. })
        ));
        assert_eq!(RigidParts::new(&[]).unwrap_err(), PartsError::Empty);
        let mut body = RigidParts::new(&[(&v, &t)]).unwrap();
        let id = Motion::identity();
        assert!(matches!(
            body.set_motion(&[id, id], &[id], 0.01),
            Err(PartsError::MotionCount { which: "start", .. })
        ));
        let mut bad = id;
        bad.translation.vector.x = f64::NAN;
        assert!(matches!(
            body.set_motion(&[id], &[bad], 0.01),
            Err(PartsError::MotionNotFinite {
                which: "end",
                part: 0
            })
        ));
        assert_eq!(
            body.set_motion(&[id], &[id], 0.0),
            Err(PartsError::Step(0.0))
        );
    }
}
