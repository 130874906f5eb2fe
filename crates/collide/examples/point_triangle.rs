//! The exact continuous collision test of a moving point against a moving triangle (the
//! narrow phase): when during a step of Δt = 10 ms a cloth node meets a body triangle, where,
//! and from which side. The exact test solves the coplanarity cubic, so it holds for triangles
//! that turn or deform during the step; the thesis's linear test, exact only for a translating
//! triangle, is shown beside it.
//!
//! `cargo run --release -p atelier-collide --example point_triangle`

#![allow(clippy::print_stdout)] // an example shows its results on stdout

use atelier_collide::V3;
use atelier_collide::narrow::{Sides, point_triangle, point_triangle_thesis};

/// A vector from its components (m or m/s).
fn v3([x, y, z]: [f64; 3]) -> V3 {
    V3::new(x, y, z)
}

fn main() {
    let dt = 0.01; // s
    let thickness = 1e-3; // m: the contact skin
    // A 15 cm right triangle in the plane z = 0, its normal (counter-clockwise) along +z.
    let x = [[-0.05, -0.05, 0.0], [0.10, -0.05, 0.0], [-0.05, 0.10, 0.0]].map(v3);
    let x = [&x[0], &x[1], &x[2]];
    let still = [0.0; 3];
    let tilt = [0.0, 0.0, 3.0]; // the second vertex rises: the triangle turns about an edge

    // (what, node position m, node velocity m/s, triangle vertex velocities m/s)
    let cases = [
        (
            "node falling at 2 m/s onto a still triangle",
            [0.01, 0.02, 0.01],
            [0.0, 0.0, -2.0],
            [still; 3],
        ),
        (
            "node falling beside it",
            [0.2, 0.0, 0.01],
            [0.0, 0.0, -2.0],
            [still; 3],
        ),
        (
            "node under it, rising at 1 m/s",
            [0.01, 0.02, -0.005],
            [0.0, 0.0, 1.0],
            [still; 3],
        ),
        (
            "node sliding at 5 m/s over the turning triangle",
            [0.0, -0.02, 0.02],
            [5.0, 0.0, -1.0],
            [still, tilt, still],
        ),
    ];
    for (what, p, v, u) in cases {
        let (p, v, u) = (v3(p), v3(v), u.map(v3));
        let u = [&u[0], &u[1], &u[2]];
        println!("{what}:");
        // `Sides::Both`, as for cloth against cloth; a closed body uses `Sides::Front`.
        match point_triangle(&p, &v, x, u, dt, thickness, Sides::Both) {
            Some(hit) => {
                // The contact point: the triangle at `hit.time`, weighted by `hit.weights`.
                let at: V3 = (0..3)
                    .map(|k| (x[k] + u[k] * hit.time) * hit.weights[k])
                    .sum();
                let (t, at) = (hit.time * 1e3, at * 1e3);
                let n = hit.normal.map(|c| c + 0.0); // −0 printed as 0
                println!(
                    "  exact:  contact at {t:.3} ms, at ({:.1}, {:.1}, {:.1}) mm",
                    at.x, at.y, at.z
                );
                println!(
                    "          from the side of n = ({:.2}, {:.2}, {:.2})",
                    n.x, n.y, n.z
                );
            }
            None => println!("  exact:  no contact during the step"),
        }
        match point_triangle_thesis(&p, &v, x, u, dt, thickness, Sides::Both) {
            Some(hit) => println!("  thesis: contact at {:.3} ms", hit.time * 1e3),
            None => println!("  thesis: no contact during the step"),
        }
    }
}
