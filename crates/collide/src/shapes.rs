//! Closed test bodies with outward triangles (benches, validation scenes).

use std::f64::consts::PI;

use crate::geom::V3;

/// A closed cylinder with flat caps: `around` vertices per ring, `rings` rings from y = 0 to
/// y = −length, outward (counter-clockwise seen from outside) triangles.
pub fn cylinder(radius: f64, length: f64, around: usize, rings: usize) -> (Vec<V3>, Vec<[u32; 3]>) {
    let mut v = Vec::with_capacity(around * rings + 2);
    for j in 0..rings {
        let y = -length * j as f64 / (rings - 1) as f64;
        for i in 0..around {
            let a = 2.0 * PI * i as f64 / around as f64;
            v.push(V3::new(radius * a.sin(), y, radius * a.cos()));
        }
    }
    let (top, bottom) = (v.len() as u32, v.len() as u32 + 1);
    v.push(V3::zeros());
    v.push(V3::new(0.0, -length, 0.0));
    let idx = |i: usize, j: usize| (j * around + i % around) as u32;
    let mut t = Vec::new();
    for j in 0..rings - 1 {
        for i in 0..around {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            // Ring j above ring j + 1; i increases towards +x from +z: outward winding.
            t.push([a, d, c]);
            t.push([a, c, b]);
        }
    }
    for i in 0..around {
        t.push([top, idx(i, 0), idx(i + 1, 0)]);
        t.push([bottom, idx(i + 1, rings - 1), idx(i, rings - 1)]);
    }
    (v, t)
}

/// The box between corners `lo` and `hi`: 8 vertices, 12 outward triangles.
pub fn box_mesh(lo: V3, hi: V3) -> (Vec<V3>, Vec<[u32; 3]>) {
    let v: Vec<V3> = (0..8)
        .map(|i| {
            V3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if (i >> 1) & 1 == 0 { lo.y } else { hi.y },
                if (i >> 2) & 1 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    let quads = [
        [0, 2, 3, 1], // z = lo, normal −z
        [4, 5, 7, 6], // z = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    let mut t = Vec::new();
    for [a, b, c, d] in quads {
        t.push([a, b, c]);
        t.push([a, c, d]);
    }
    (v, t)
}
