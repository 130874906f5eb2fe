//! Broad phase: which triangles a node's search segment may meet (thesis §5.3.1,
//! `method.md` §3).
//!
//! Every step the collided surface (body or cloth triangles) moves from `start` to `end`; each
//! triangle's *swept box* is the box of its six vertex positions (three at the start, three at
//! the end) grown by a margin. A colliding node is tested along its segment `a → b`
//! (`ṙ_iΔt`) grown by a radius (`|max ṙ_Ω|Δt`, the thesis's allowance for other points
//! moving into it). A broad phase returns every triangle that segment may meet —
//! conservatively: a triangle whose swept volume meets the grown segment is never left out.
//!
//! Two interchangeable implementations, plus brute force for tests:
//! - [`BvhBroad`]: a parry BVH over the swept boxes, built once and refitted every step.
//! - [`ProjectionBroad`]: the thesis's projection test without a tree — the swept boxes are
//!   binned into one hashed 2D grid per coordinate plane (XY, XZ, YZ); a query walks the plane
//!   whose covered cells hold the fewest entries and keeps a triangle only if its projection
//!   overlaps the query's projection in all three planes.
//! - [`BruteForce`]: every triangle whose swept box overlaps the query box.
//!
//! See `docs/collision-broad.md` for the method and the measured costs.

mod bvh;
mod projection;

pub use bvh::BvhBroad;
pub use projection::ProjectionBroad;

use crate::{Aabb, V3};

/// A broad phase: the candidate triangles for a node's search segment.
pub trait BroadPhase: Send + Sync {
    /// Set the triangles for this step: the surface moves from `start` to `end` (vertex
    /// positions, same length) during the step; `margin` (m) grows every triangle's swept box.
    /// Called every step; the BVH refits (never rebuilds while the triangle count stays), the
    /// projection test re-bins.
    ///
    /// # Panics
    /// If `start` and `end` differ in length or a triangle indexes past them.
    fn update(&mut self, start: &[V3], end: &[V3], triangles: &[[u32; 3]], margin: f64);

    /// Append to `out` every triangle whose swept volume may meet the segment `a`→`b` grown by
    /// `radius` (conservative: no true intersection may be missed). Duplicates not allowed.
    fn query(&self, a: &V3, b: &V3, radius: f64, out: &mut Vec<u32>);
}

/// Which broad phase to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum BroadKind {
    /// [`BvhBroad`]: parry BVH over the swept boxes, refitted every step (the default).
    #[default]
    Bvh,
    /// [`ProjectionBroad`]: the thesis's three-plane projection test on hashed 2D grids.
    Projection,
    /// [`BruteForce`]: test every triangle (for tests and tiny meshes).
    Brute,
}

/// A new, empty broad phase of the given kind.
pub fn new_broad(kind: BroadKind) -> Box<dyn BroadPhase> {
    match kind {
        BroadKind::Bvh => Box::new(BvhBroad::new()),
        BroadKind::Projection => Box::new(ProjectionBroad::new()),
        BroadKind::Brute => Box::new(BruteForce::new()),
    }
}

/// The swept box of triangle `t`: the box of its vertices at `start` and at `end`, grown by
/// `margin`.
pub fn swept_box(start: &[V3], end: &[V3], t: &[u32; 3], margin: f64) -> Aabb {
    let mut b = Aabb::EMPTY;
    for &v in t {
        b = b.including(&start[v as usize]).including(&end[v as usize]);
    }
    b.grown(margin)
}

/// The box of the segment `a → b` grown by `radius`.
pub fn segment_box(a: &V3, b: &V3, radius: f64) -> Aabb {
    Aabb {
        min: a.inf(b),
        max: a.sup(b),
    }
    .grown(radius.max(0.0))
}

/// Fill `out` with the swept boxes of all triangles (reusing its allocation).
fn swept_boxes(start: &[V3], end: &[V3], triangles: &[[u32; 3]], margin: f64, out: &mut Vec<Aabb>) {
    assert_eq!(
        start.len(),
        end.len(),
        "broad phase: start and end positions differ in length"
    );
    out.clear();
    out.extend(triangles.iter().map(|t| swept_box(start, end, t, margin)));
}

/// Brute force: every triangle whose swept box overlaps the query box (the reference of the
/// tests; fine for a few hundred triangles).
#[derive(Clone, Debug, Default)]
pub struct BruteForce {
    boxes: Vec<Aabb>,
}

impl BruteForce {
    /// An empty broad phase (no triangles until [`BroadPhase::update`]).
    pub fn new() -> Self {
        Self::default()
    }
}

impl BroadPhase for BruteForce {
    fn update(&mut self, start: &[V3], end: &[V3], triangles: &[[u32; 3]], margin: f64) {
        swept_boxes(start, end, triangles, margin, &mut self.boxes);
    }

    fn query(&self, a: &V3, b: &V3, radius: f64, out: &mut Vec<u32>) {
        let q = segment_box(a, b, radius);
        out.extend(
            self.boxes
                .iter()
                .enumerate()
                .filter(|(_, tb)| tb.overlaps(&q))
                .map(|(i, _)| i as u32),
        );
    }
}

#[cfg(test)]
mod tests;
