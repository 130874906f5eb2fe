//! Signed distance of points to a closed body mesh, and penetration counts.
//!
//! The body is a closed, consistently oriented triangle mesh (outward normals). The distance is
//! parry's point projection on a [`TriMesh`] built with [`TriMeshFlags::ORIENTED`] (its
//! pseudo-normals decide inside/outside); no vertex-merging flag is used, so
//! [`BodyDistance::update`] can move the vertices in the caller's order.

use std::collections::HashMap;

use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

use crate::V3;

/// Why a body mesh was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// No vertices or no triangles.
    #[error("empty body mesh ({vertices} vertices, {triangles} triangles)")]
    Empty {
        /// Vertex count.
        vertices: usize,
        /// Triangle count.
        triangles: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but there are {vertices} vertices")]
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The offending index.
        index: u32,
        /// Vertex count.
        vertices: usize,
    },
    /// A triangle uses the same vertex twice.
    #[error("triangle {triangle} repeats vertex {index}")]
    DegenerateTriangle {
        /// The triangle.
        triangle: usize,
        /// The repeated index.
        index: u32,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} is not finite: {position:?}")]
    NonFiniteVertex {
        /// The vertex.
        vertex: usize,
        /// Its position.
        position: [f64; 3],
    },
    /// An edge is not shared by exactly two triangles: the mesh is not closed (or not manifold).
    #[error("edge ({a}, {b}) is used by {count} triangle(s) (first: triangle {triangle}), not 2")]
    NotClosed {
        /// Smaller vertex of the edge.
        a: u32,
        /// Larger vertex of the edge.
        b: u32,
        /// How many triangles use it.
        count: usize,
        /// The first triangle using it.
        triangle: usize,
    },
    /// Two triangles run along an edge in the same direction: orientations are inconsistent.
    #[error("edge {a} → {b} runs the same way in triangles {first} and {second}")]
    Inconsistent {
        /// Start vertex of the directed edge.
        a: u32,
        /// End vertex of the directed edge.
        b: u32,
        /// First triangle.
        first: usize,
        /// Second triangle.
        second: usize,
    },
    /// [`BodyDistance::update`] got a different number of vertices.
    #[error("update with {got} vertices, the mesh has {expected}")]
    VertexCount {
        /// The mesh's vertex count.
        expected: usize,
        /// The count given.
        got: usize,
    },
}

/// Penetration summary of a set of points against the body.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Penetrations {
    /// Number of points deeper inside than the tolerance.
    pub count: usize,
    /// Largest depth (m, positive) among those points; 0 when none.
    pub max_depth: f64,
    /// Mean depth (m) over those points; 0 when none.
    pub mean_depth: f64,
    /// Index of the deepest of those points.
    pub deepest: Option<usize>,
}

/// Signed distance to a closed body mesh that may move (same triangles).
#[derive(Clone)]
pub struct BodyDistance {
    mesh: TriMesh,
    scratch: Vec<PVec>,
}

impl std::fmt::Debug for BodyDistance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BodyDistance")
            .field("vertices", &self.mesh.vertices().len())
            .field("triangles", &self.mesh.indices().len())
            .finish()
    }
}

fn to_glam(v: &V3) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

fn from_glam(v: PVec) -> V3 {
    V3::new(v.x, v.y, v.z)
}

fn check_vertices(vertices: &[V3]) -> Result<(), MeshError> {
    match vertices
        .iter()
        .position(|v| !v.iter().all(|x| x.is_finite()))
    {
        Some(i) => Err(MeshError::NonFiniteVertex {
            vertex: i,
            position: vertices[i].into(),
        }),
        None => Ok(()),
    }
}

/// A non-empty mesh with finite vertices, closed and consistently oriented.
pub(crate) fn check_closed(vertices: &[V3], triangles: &[[u32; 3]]) -> Result<(), MeshError> {
    if vertices.is_empty() || triangles.is_empty() {
        return Err(MeshError::Empty {
            vertices: vertices.len(),
            triangles: triangles.len(),
        });
    }
    check_vertices(vertices)?;
    check_topology(vertices.len(), triangles)
}

/// Every edge shared by exactly two triangles, running opposite ways.
fn check_topology(n_vertices: usize, triangles: &[[u32; 3]]) -> Result<(), MeshError> {
    // Undirected edge → (use count, first triangle); directed edge → first triangle.
    let mut edges: HashMap<(u32, u32), (usize, usize)> =
        HashMap::with_capacity(3 * triangles.len());
    let mut directed: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * triangles.len());
    let mut inconsistent = None;
    for (t, tri) in triangles.iter().enumerate() {
        for &index in tri {
            if index as usize >= n_vertices {
                return Err(MeshError::IndexOutOfRange {
                    triangle: t,
                    index,
                    vertices: n_vertices,
                });
            }
        }
        for k in 0..3 {
            if tri[k] == tri[(k + 1) % 3] {
                return Err(MeshError::DegenerateTriangle {
                    triangle: t,
                    index: tri[k],
                });
            }
        }
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_insert((0, t)).0 += 1;
            if let Some(&first) = directed.get(&(a, b)) {
                inconsistent.get_or_insert(MeshError::Inconsistent {
                    a,
                    b,
                    first,
                    second: t,
                });
            } else {
                directed.insert((a, b), t);
            }
        }
    }
    // Report the bad edge met first (by triangle, then edge) so the error is deterministic.
    let bad = edges
        .iter()
        .filter(|(_, (count, _))| *count != 2)
        .min_by_key(|&(&e, &(_, t))| (t, e));
    if let Some((&(a, b), &(count, triangle))) = bad {
        return Err(MeshError::NotClosed {
            a,
            b,
            count,
            triangle,
        });
    }
    inconsistent.map_or(Ok(()), Err)
}

impl BodyDistance {
    /// Build from a closed, consistently oriented mesh (outward normals).
    ///
    /// # Errors
    /// A [`MeshError`] naming the offending triangle, edge or vertex.
    pub fn new(vertices: &[V3], triangles: &[[u32; 3]]) -> Result<Self, MeshError> {
        check_closed(vertices, triangles)?;
        let verts: Vec<PVec> = vertices.iter().map(to_glam).collect();
        let mesh = TriMesh::with_flags(
            verts,
            triangles.to_vec(),
            TriMeshFlags::ORIENTED | TriMeshFlags::DEFORMABLE,
        )
        .map_err(|_| MeshError::Empty {
            vertices: vertices.len(),
            triangles: triangles.len(),
        })?;
        Ok(Self {
            mesh,
            scratch: Vec::new(),
        })
    }

    /// Move the body: new vertex positions, same order and triangles (refits parry's BVH and
    /// recomputes the pseudo-normals).
    ///
    /// # Errors
    /// [`MeshError::VertexCount`] or [`MeshError::NonFiniteVertex`]; the mesh is unchanged then.
    pub fn update(&mut self, vertices: &[V3]) -> Result<(), MeshError> {
        let expected = self.mesh.vertices().len();
        if vertices.len() != expected {
            return Err(MeshError::VertexCount {
                expected,
                got: vertices.len(),
            });
        }
        check_vertices(vertices)?;
        self.scratch.clear();
        self.scratch.extend(vertices.iter().map(to_glam));
        self.mesh.set_vertices(&self.scratch);
        Ok(())
    }

    /// Signed distance (m) from `p` to the body surface: negative inside.
    pub fn signed_distance(&self, p: &V3) -> f64 {
        let proj = self.mesh.project_local_point(to_glam(p), false);
        let d = (from_glam(proj.point) - p).norm();
        if proj.is_inside { -d } else { d }
    }

    /// The points deeper inside the body than `tolerance` (m): how many, how deep.
    pub fn penetrations(&self, points: &[V3], tolerance: f64) -> Penetrations {
        let mut out = Penetrations::default();
        let mut sum = 0.0;
        for (i, p) in points.iter().enumerate() {
            let depth = -self.signed_distance(p);
            if depth > tolerance {
                out.count += 1;
                sum += depth;
                if out.deepest.is_none() || depth > out.max_depth {
                    out.max_depth = depth;
                    out.deepest = Some(i);
                }
            }
        }
        if out.count > 0 {
            out.mean_depth = sum / out.count as f64;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Unit cube [0, 1]³, 12 triangles, outward normals.
    fn cube() -> (Vec<V3>, Vec<[u32; 3]>) {
        crate::shapes::box_mesh(V3::zeros(), V3::repeat(1.0))
    }

    /// Exact signed distance to the unit cube.
    fn cube_sd(p: &V3) -> f64 {
        let q = (p - V3::repeat(0.5)).abs() - V3::repeat(0.5);
        let outside = q.map(|x| x.max(0.0)).norm();
        outside + q.max().min(0.0)
    }

    /// Icosphere of radius 1 with `levels` subdivisions.
    fn icosphere(levels: usize) -> (Vec<V3>, Vec<[u32; 3]>) {
        let g = (1.0 + 5f64.sqrt()) / 2.0;
        let mut v: Vec<V3> = [
            [-1.0, g, 0.0],
            [1.0, g, 0.0],
            [-1.0, -g, 0.0],
            [1.0, -g, 0.0],
            [0.0, -1.0, g],
            [0.0, 1.0, g],
            [0.0, -1.0, -g],
            [0.0, 1.0, -g],
            [g, 0.0, -1.0],
            [g, 0.0, 1.0],
            [-g, 0.0, -1.0],
            [-g, 0.0, 1.0],
        ]
        .iter()
        .map(|p| V3::from(*p).normalize())
        .collect();
        let mut t: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..levels {
            let mut mid = HashMap::new();
            let mut next = Vec::new();
            let mut m = |a: u32, b: u32, v: &mut Vec<V3>| -> u32 {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                    (v.len() - 1) as u32
                })
            };
            for [a, b, c] in t {
                let (ab, bc, ca) = (m(a, b, &mut v), m(b, c, &mut v), m(c, a, &mut v));
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            t = next;
        }
        (v, t)
    }

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn cube_distance_is_exact() {
        let (v, t) = cube();
        let body = BodyDistance::new(&v, &t).unwrap();
        let mut s = 1;
        for _ in 0..2000 {
            let p = V3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 3.0 - V3::repeat(1.0);
            let (got, want) = (body.signed_distance(&p), cube_sd(&p));
            assert_relative_eq!(got, want, epsilon = 1e-12);
        }
        assert_relative_eq!(
            body.signed_distance(&V3::repeat(0.5)),
            -0.5,
            epsilon = 1e-12
        );
        assert_relative_eq!(
            body.signed_distance(&V3::new(2.0, 0.5, 0.5)),
            1.0,
            epsilon = 1e-12
        );
    }

    #[test]
    fn icosphere_distance_within_chord_error() {
        let (v, t) = icosphere(3);
        // Chord error: the largest gap between the unit sphere and a flat triangle,
        // 1 − (distance of the face's plane from the centre).
        let sag = t
            .iter()
            .map(|[a, b, c]| {
                let (a, b, c) = (v[*a as usize], v[*b as usize], v[*c as usize]);
                1.0 - (b - a).cross(&(c - a)).normalize().dot(&a).abs()
            })
            .fold(0.0, f64::max);
        assert!(sag > 0.0 && sag < 0.02);
        let body = BodyDistance::new(&v, &t).unwrap();
        let mut s = 2;
        let mut inside = 0;
        for _ in 0..2000 {
            let p = V3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 4.0 - V3::repeat(2.0);
            let want = p.norm() - 1.0;
            let got = body.signed_distance(&p);
            assert!((got - want).abs() <= sag + 1e-12, "{p:?}: {got} vs {want}");
            if want.abs() > sag {
                assert_eq!(got < 0.0, want < 0.0, "sign at {p:?}");
            }
            inside += usize::from(got < 0.0);
        }
        assert!(inside > 100);
        // Moving body: shifted sphere.
        let mut body = body;
        let shift = V3::new(3.0, 0.0, 0.0);
        let moved: Vec<V3> = v.iter().map(|p| p + shift).collect();
        body.update(&moved).unwrap();
        assert!(body.signed_distance(&shift) < -1.0 + sag + 1e-12);
        assert!(body.signed_distance(&V3::zeros()) > 1.9);
    }

    #[test]
    fn penetration_counts() {
        let (v, t) = cube();
        let body = BodyDistance::new(&v, &t).unwrap();
        let pts = [
            V3::new(0.5, 0.5, 0.5),   // depth 0.5
            V3::new(0.5, 0.5, 0.9),   // depth 0.1
            V3::new(0.5, 0.5, 0.995), // depth 0.005 (under tolerance)
            V3::new(0.5, 0.5, 1.5),   // outside
            V3::new(0.8, 0.2, 0.3),   // depth 0.2
        ];
        let p = body.penetrations(&pts, 0.01);
        assert_eq!(p.count, 3);
        assert_eq!(p.deepest, Some(0));
        assert_relative_eq!(p.max_depth, 0.5, epsilon = 1e-12);
        assert_relative_eq!(p.mean_depth, 0.8 / 3.0, epsilon = 1e-12);
        let none = body.penetrations(&pts[3..4], 0.0);
        assert_eq!(none, Penetrations::default());
    }

    #[test]
    fn mesh_errors() {
        let (v, t) = cube();
        assert!(matches!(
            BodyDistance::new(&[], &t),
            Err(MeshError::Empty { vertices: 0, .. })
        ));
        assert!(matches!(
            BodyDistance::new(&v, &[]),
            Err(MeshError::Empty { triangles: 0, .. })
        ));
        let mut bad = t.clone();
        bad[4][1] = 8;
        assert_eq!(
            BodyDistance::new(&v, &bad).unwrap_err(),
            MeshError::IndexOutOfRange {
                triangle: 4,
                index: 8,
                vertices: 8
            }
        );
        let mut nan = v.clone();
        nan[3].y = f64::NAN;
        assert!(matches!(
            BodyDistance::new(&nan, &t),
            Err(MeshError::NonFiniteVertex { vertex: 3, .. })
        ));
        let open = &t[..11];
        let err = BodyDistance::new(&v, open).unwrap_err();
        assert!(
            err == MeshError::NotClosed {
                a: 5,
                b: 7,
                count: 1,
                triangle: 2
            },
            "{err}"
        );
        let mut flipped = t.clone();
        flipped[5] = [flipped[5][0], flipped[5][2], flipped[5][1]];
        assert!(matches!(
            BodyDistance::new(&v, &flipped),
            Err(MeshError::Inconsistent { .. })
        ));
        let mut degenerate = t.clone();
        degenerate[2] = [1, 1, 5];
        assert!(matches!(
            BodyDistance::new(&v, &degenerate),
            Err(MeshError::DegenerateTriangle {
                triangle: 2,
                index: 1
            })
        ));
        let mut body = BodyDistance::new(&v, &t).unwrap();
        assert_eq!(
            body.update(&v[..7]).unwrap_err(),
            MeshError::VertexCount {
                expected: 8,
                got: 7
            }
        );
        assert!(matches!(
            body.update(&nan),
            Err(MeshError::NonFiniteVertex { vertex: 3, .. })
        ));
        assert!(
            !MeshError::Empty {
                vertices: 0,
                triangles: 0
            }
            .to_string()
            .is_empty()
        );
    }
}
