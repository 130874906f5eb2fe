//! A small stick-figure mannequin for the unit tests of posing and motion: every part a closed
//! cube hanging below (or above) its pivot, pivots laid out like a standing person.

use crate::model::{JointLimits, Mannequin, Part, PartMesh, V3};

fn cube(centre: V3, half: f64) -> (Vec<V3>, Vec<[u32; 3]>) {
    let v: Vec<V3> = (0..8)
        .map(|k| {
            let s = |b: usize| if k >> b & 1 == 1 { half } else { -half };
            centre + V3::new(s(0), s(1), s(2))
        })
        .collect();
    // Outward faces of the cube with vertex bits (x, y, z).
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (v, t)
}

/// The stick figure; joint limits wide (±170°) except where a test narrows them.
pub fn stick_figure() -> Mannequin {
    use Part::*;
    let pivot = |p: Part| -> V3 {
        match p {
            Pelvis => V3::new(0.0, 0.9, 0.0),
            Abdomen => V3::new(0.0, 1.0, 0.0),
            Chest => V3::new(0.0, 1.15, 0.0),
            Neck => V3::new(0.0, 1.4, 0.0),
            Head => V3::new(0.0, 1.48, 0.0),
            UpperArmLeft => V3::new(0.18, 1.35, 0.0),
            UpperArmRight => V3::new(-0.18, 1.35, 0.0),
            ForearmLeft => V3::new(0.22, 1.07, 0.0),
            ForearmRight => V3::new(-0.22, 1.07, 0.0),
            HandLeft => V3::new(0.25, 0.83, 0.0),
            HandRight => V3::new(-0.25, 0.83, 0.0),
            ThighLeft => V3::new(0.09, 0.85, 0.0),
            ThighRight => V3::new(-0.09, 0.85, 0.0),
            ShinLeft => V3::new(0.09, 0.47, 0.0),
            ShinRight => V3::new(-0.09, 0.47, 0.0),
            FootLeft => V3::new(0.09, 0.08, 0.0),
            FootRight => V3::new(-0.09, 0.08, 0.0),
        }
    };
    let parts = Part::ALL
        .iter()
        .map(|&p| {
            let up = matches!(p, Abdomen | Chest | Neck | Head);
            let offset = if up { 0.06 } else { -0.06 };
            let (vertices, triangles) = cube(pivot(p) + V3::new(0.0, offset, 0.01), 0.04);
            PartMesh {
                part: p,
                vertices,
                triangles,
                pivot: pivot(p),
                limits: JointLimits {
                    min_deg: [-170.0; 3],
                    max_deg: [170.0; 3],
                },
            }
        })
        .collect();
    Mannequin {
        name: "stick figure".into(),
        parts,
    }
}
