//! What a step reports about the garment besides the solver: nodes inside the body (and how
//! deep), and the seams left open.

use atelier_collide::{RigidParts, V3};
use rayon::prelude::*;

use crate::Sewing;

/// Nodes inside the body at the end of the step and the deepest depth, m. A node whose
/// distance at the start of the step (`start_distance`, or a lower bound) exceeds how far it
/// moved plus how far any body point moved cannot be inside (the distance is 1-Lipschitz) and
/// is not queried.
pub(super) fn penetration(
    nodes: &[V3],
    start: &[V3],
    start_distance: &[f64],
    parts: &RigidParts,
) -> (usize, f64) {
    let body_moved = parts.max_displacement();
    nodes
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            if let (Some(d0), Some(x0)) = (start_distance.get(i), start.get(i))
                && *d0 - (p - x0).norm() - body_moved > 0.0
            {
                return (0, 0.0);
            }
            match parts.nearest(p, 0.0, true) {
                Some(n) if n.distance < 0.0 => (1, -n.distance),
                _ => (0, 0.0),
            }
        })
        .reduce(|| (0, 0.0), |a, b| (a.0 + b.0, a.1.max(b.1)))
}

/// The seams with open pairs: name, open pairs of all, the widest gap and where it is.
pub(super) fn open_seams(sewing: &Sewing, g: &crate::GarmentCloth, positions: &[V3]) -> String {
    // (name, open, all, widest gap, its midpoint)
    let mut seams: Vec<(&str, usize, usize, f64, V3)> = Vec::new();
    let open = sewing.unsewn();
    for (k, name) in g.pair_names.iter().enumerate() {
        let idx = match seams.iter().position(|s| s.0 == name) {
            Some(i) => i,
            None => {
                seams.push((name, 0, 0, 0.0, V3::zeros()));
                seams.len() - 1
            }
        };
        let seam = &mut seams[idx];
        seam.2 += 1;
        if open.binary_search(&k).is_ok() {
            let (a, b) = (
                positions[g.pairs[k].0 as usize],
                positions[g.pairs[k].1 as usize],
            );
            seam.1 += 1;
            if (a - b).norm() >= seam.3 {
                seam.3 = (a - b).norm();
                seam.4 = (a + b) * 0.5;
            }
        }
    }
    seams
        .iter()
        .filter(|s| s.1 > 0)
        .map(|s| {
            format!(
                "{} ({} of {}, widest {:.1} mm at ({:.3}, {:.3}, {:.3}) m)",
                s.0,
                s.1,
                s.2,
                s.3 * 1e3,
                s.4.x,
                s.4.y,
                s.4.z
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}
