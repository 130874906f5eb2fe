//! Helpers shared by the garment tests (`dress.rs`, `baselines.rs`).

use atelier::pipeline::GarmentRun;
use atelier_collide::V3;
use atelier_collide::distance::BodyDistance;

/// The deepest any cloth node of any frame lies inside any body part, m, measured on each
/// part's own mesh posed as in the frame.
pub fn deepest_inside_any_frame(run: &GarmentRun) -> f64 {
    let mannequin = atelier_body::build::jis_9ar();
    let mut parts: Vec<(std::ops::Range<usize>, BodyDistance)> = Vec::new();
    let mut start = 0;
    for p in &mannequin.parts {
        let range = start..start + p.vertices.len();
        start = range.end;
        parts.push((
            range,
            BodyDistance::new(&p.vertices, &p.triangles).expect("closed part"),
        ));
    }
    let mut worst = 0.0f64;
    for f in &run.frames {
        let body: Vec<V3> = f.body.iter().map(|p| V3::new(p[0], p[1], p[2])).collect();
        for (range, d) in &mut parts {
            d.update(&body[range.clone()]).expect("posed part");
            for p in &f.cloth {
                worst = worst.max(-d.signed_distance(&V3::new(p[0], p[1], p[2])));
            }
        }
    }
    worst
}

pub fn all_finite(run: &GarmentRun) -> bool {
    run.frames.iter().all(|f| {
        f.cloth
            .iter()
            .chain(&f.body)
            .flatten()
            .all(|c| c.is_finite())
    })
}
