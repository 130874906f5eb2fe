//! Broad phase (a): a parry BVH over the triangles' swept boxes, refitted every step.

use parry3d_f64::bounding_volume::Aabb as PAabb;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};

use super::{BroadPhase, segment_box, swept_boxes};
use crate::{Aabb, V3};

/// nalgebra → glam (both are three `f64`).
fn to_glam(v: &V3) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

/// Our box → parry's box.
fn to_parry(b: &Aabb) -> PAabb {
    PAabb::new(to_glam(&b.min), to_glam(&b.max))
}

/// Leaf count above which the per-step refit runs on rayon's pool (parry's parallel refit only
/// splits subtrees of more than 2048 leaves anyway).
const PARALLEL_REFIT_LEAVES: usize = 16_384;

/// A parry [`Bvh`] over the triangles' swept boxes (leaf id = triangle index).
///
/// Built once with the binned strategy; every later [`BroadPhase::update`] with the same
/// triangle count writes each leaf's new box in place and refits the tree (same topology, new
/// boxes); a different triangle count rebuilds it. A query walks the tree with the segment's
/// box grown by the radius, so it returns exactly the triangles [`super::BruteForce`] returns.
#[derive(Default)]
pub struct BvhBroad {
    bvh: Bvh,
    workspace: BvhWorkspace,
    boxes: Vec<Aabb>,
    /// Triangle count the tree was built for.
    built_for: Option<usize>,
    /// Number of builds so far (for tests: refits must not rebuild).
    builds: usize,
}

impl std::fmt::Debug for BvhBroad {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BvhBroad")
            .field("triangles", &self.boxes.len())
            .field("builds", &self.builds)
            .finish_non_exhaustive()
    }
}

impl BvhBroad {
    /// An empty broad phase (no triangles until [`BroadPhase::update`]).
    pub fn new() -> Self {
        Self::default()
    }

    /// How many times the tree has been built (not refitted) so far.
    pub fn builds(&self) -> usize {
        self.builds
    }
}

impl BroadPhase for BvhBroad {
    fn update(&mut self, start: &[V3], end: &[V3], triangles: &[[u32; 3]], margin: f64) {
        swept_boxes(start, end, triangles, margin, &mut self.boxes);
        let n = self.boxes.len();
        if self.built_for != Some(n) {
            let leaves: Vec<PAabb> = self.boxes.iter().map(to_parry).collect();
            self.bvh = if n == 0 {
                Bvh::new()
            } else {
                Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves)
            };
            self.built_for = Some(n);
            self.builds += 1;
            return;
        }
        if n == 0 {
            return;
        }
        // Change-detection margin 0: every leaf gets its exact new box, so a refitted tree
        // answers exactly like a fresh one (a fat leaf box would only add candidates).
        for (i, b) in self.boxes.iter().enumerate() {
            self.bvh
                .insert_or_update_partially(to_parry(b), i as u32, 0.0);
        }
        if n >= PARALLEL_REFIT_LEAVES {
            self.bvh.refit_parallel(&mut self.workspace);
        } else {
            self.bvh.refit(&mut self.workspace);
        }
    }

    fn query(&self, a: &V3, b: &V3, radius: f64, out: &mut Vec<u32>) {
        if self.boxes.is_empty() {
            return;
        }
        let q = to_parry(&segment_box(a, b, radius));
        out.extend(self.bvh.intersect_aabb(&q));
    }
}
