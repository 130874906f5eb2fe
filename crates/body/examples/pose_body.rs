//! The JIS L 4005 9AR mannequin (the default body), measured at rest and posed mid-stride from
//! the walk of `fixtures/motions/walk.ron`, with the analytic velocities the keyframed motion
//! gives every vertex.
//!
//! `cargo run --release -p atelier-body --example pose_body`
//!
//! Body frame, metres: x the body's left, y up, z forward (the walk goes along +z).

#![allow(clippy::print_stdout)] // an example shows its results on stdout

use std::path::Path;

use atelier_body::{Body, Motion, Part, V3, bounding_box, build};

const WALK: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/motions/walk.ron"
);

/// A position in m, printed in cm.
fn cm(p: V3) -> String {
    let p = p * 100.0;
    format!("({:.1}, {:.1}, {:.1}) cm", p.x, p.y, p.z)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The mannequin from its embedded description: 17 rigid parts in a joint tree.
    let mannequin = build::jis_9ar();
    let (vertices, triangles) = mannequin.counts();
    let s = build::measure(&mannequin); // sizes measured on the mesh, cm
    println!(
        "{}: {vertices} vertices, {triangles} triangles",
        mannequin.name
    );
    let (height, bust, waist, hip) = (s.height_cm, s.bust_cm, s.waist_cm, s.hip_cm);
    println!("  height {height:.1} cm, bust {bust:.1} cm, waist {waist:.1} cm, hip {hip:.1} cm");

    // The walk is checked against the mannequin's joint limits as it is read.
    let motion = Motion::load(Path::new(WALK), &mannequin)?;
    let (start, end) = motion.span();
    let body = Body::new(mannequin);
    let t = 1.4; // s: mid-stride, the right foot ahead
    let posed = body.at(&motion, t); // every vertex's position and velocity
    println!(
        "walk \"{}\" ({start:.1}–{end:.1} s) at t = {t} s:",
        motion.name
    );

    let (lo, hi) = bounding_box(&posed.positions);
    let size = (hi - lo) * 100.0;
    println!(
        "  bounding box {:.1} × {:.1} × {:.1} cm",
        size.x, size.y, size.z
    );
    // The parts' frames: the pelvis (the root of the tree) carries the walk's forward speed.
    let pelvis = body.frames(&motion.sample(t))[Part::Pelvis.index()];
    let speed = pelvis.velocity.z;
    println!(
        "  pelvis pivot {}, moving forward at {speed:.2} m/s",
        cm(pelvis.pivot)
    );

    // Each foot's lowest vertex, and the fastest vertex of each hand.
    let labels = &body.rest.vertex_part;
    for (foot, hand) in [
        (Part::FootLeft, Part::HandLeft),
        (Part::FootRight, Part::HandRight),
    ] {
        let of = |part: Part| (0..labels.len()).filter(move |&k| labels[k] == part);
        let sole = of(foot)
            .map(|k| posed.positions[k])
            .min_by(|a, b| a.y.total_cmp(&b.y))
            .ok_or("a foot without vertices")?;
        let fastest = of(hand)
            .map(|k| posed.velocities[k].norm())
            .fold(0.0, f64::max);
        println!(
            "  {foot:?} lowest at {}; {hand:?} up to {fastest:.2} m/s",
            cm(sole)
        );
    }
    Ok(())
}
