//! Set-up helpers of a garment scene: seam groups (nodes tied at length 0), the body parts'
//! motion over a step, and the body's triangles the cloth can reach.

use atelier_body::kinematics::PartFrame;
use atelier_body::model::LabelledMesh;
use atelier_collide::RigidParts;
use atelier_collide::parts::Motion as PartMotion;
use rayon::prelude::*;

/// For every node, the smallest node it is joined to through seam pairs (itself when none).
pub(super) fn seam_groups(n: usize, pairs: &[(u32, u32)]) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for &(a, b) in pairs {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        parent[hi as usize] = lo;
    }
    (0..n as u32).map(|i| root(&mut parent, i)).collect()
}

/// The rigid motion of every part (rest → world) for the parts' `frames` in a pose (from
/// [`atelier_body::kinematics::Body::pose_with_frames`]), in the mannequin's part order.
pub(super) fn part_motions(
    body: &atelier_body::kinematics::Body,
    frames: &[PartFrame; 17],
    out: &mut [PartMotion],
) {
    for (m, part) in out.iter_mut().zip(&body.mannequin.parts) {
        let f = frames[part.part.index()];
        let r = f.rotation;
        *m = PartMotion::from_parts((f.pivot - r * part.pivot).into(), r);
    }
}

/// The body triangles not buried in another part: a triangle whose three vertices are all more
/// than 1 mm inside some other part is left out of the continuous test.
pub(super) fn exposed_triangles(
    mannequin: &atelier_body::model::Mannequin,
    rest: &LabelledMesh,
    parts: &RigidParts,
) -> Vec<[u32; 3]> {
    // Part k of `parts` is `mannequin.parts[k]`.
    let index_of = |part: atelier_body::model::Part| {
        mannequin
            .parts
            .iter()
            .position(|p| p.part == part)
            .expect("every labelled part is a mannequin part")
    };
    // Whether each vertex lies more than 1 mm inside a part other than its own (once per
    // vertex, in parallel: a vertex is shared by about six triangles).
    let buried: Vec<bool> = (0..rest.vertices.len())
        .into_par_iter()
        .map(|v| {
            let (p, own) = (rest.vertices[v], index_of(rest.vertex_part[v]));
            (0..parts.len())
                .filter(|&k| k != own)
                .any(|k| parts.rest_distance(k, &p) < -1e-3)
        })
        .collect();
    rest.triangles
        .iter()
        .filter(|t| !t.iter().all(|&v| buried[v as usize]))
        .copied()
        .collect()
}
