//! Reference values: exact depths of a box (axis-aligned and rotated) and a sphere within its
//! chord error; agreement with the analytic mannequin ([`super::synthetic`]) (its own renderer of the error
//! and its analytic landmarks); the round trip mannequin → range images → gridded body → error;
//! files; typed errors.

use std::collections::BTreeMap;
use std::path::PathBuf;

use super::{BodyGridParams, BodyMesh, LANDMARKS, RangeBody, grid_body, measure_error, synthetic};

use super::Part;
use super::*;
use crate::model::{JointLimits, LabelledMesh, Mannequin, PartMesh, V3};
use std::time::Instant;

/// A fresh temporary directory, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> Self {
        let d =
            std::env::temp_dir().join(format!("atelier-body-range-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        Self(d)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A closed box `[lo, hi]` (m), outward triangles, mapped by `f`.
fn box_mesh(lo: [f64; 3], hi: [f64; 3], f: impl Fn(V3) -> V3) -> LabelledMesh {
    let vertices: Vec<V3> = (0..8)
        .map(|i| {
            f(V3::new(
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ))
        })
        .collect();
    // Faces as quads (counter-clockwise seen from outside).
    let quads = [
        [0, 2, 3, 1], // z = lo
        [4, 5, 7, 6], // z = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    let triangles: Vec<[u32; 3]> = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    LabelledMesh {
        vertices,
        vertex_part: vec![Part::Chest; 8],
        triangle_part: vec![Part::Chest; triangles.len()],
        triangles,
    }
}

/// A UV sphere (m), `nlat` × `nlon`, outward.
fn sphere_mesh(centre: V3, radius: f64, nlat: usize, nlon: usize) -> LabelledMesh {
    let mut vertices = vec![centre + V3::new(0.0, radius, 0.0)];
    for i in 1..nlat {
        let th = std::f64::consts::PI * i as f64 / nlat as f64;
        for j in 0..nlon {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / nlon as f64;
            vertices.push(
                centre + radius * V3::new(th.sin() * ph.cos(), th.cos(), -th.sin() * ph.sin()),
            );
        }
    }
    vertices.push(centre - V3::new(0.0, radius, 0.0));
    let south = (vertices.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * nlon + j % nlon) as u32;
    let mut triangles = Vec::new();
    for j in 0..nlon {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([south, ring(nlat - 1, j + 1), ring(nlat - 1, j)]);
    }
    for i in 1..nlat - 1 {
        for j in 0..nlon {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    let mut m = LabelledMesh {
        vertex_part: vec![Part::Head; vertices.len()],
        triangle_part: vec![Part::Head; triangles.len()],
        vertices,
        triangles,
    };
    // Orientation check: outward means a positive signed volume.
    let vol: f64 = m
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.vertices[i as usize] - centre);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    if vol < 0.0 {
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
    }
    m
}

/// The gridded body as a labelled mesh.
fn labelled(mesh: &BodyMesh) -> LabelledMesh {
    LabelledMesh {
        vertices: mesh
            .positions
            .iter()
            .map(|p| V3::new(p[0], p[1], p[2]))
            .collect(),
        triangles: mesh.triangles.clone(),
        vertex_part: mesh.vertex_part.clone(),
        triangle_part: mesh.triangle_part.clone(),
    }
}

mod from_images;
mod known_answers;
mod round_trip;
mod shapes;
