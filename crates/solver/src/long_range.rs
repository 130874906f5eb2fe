//! Long-range attachments (Kim, Chentanez, Müller 2012, "Long range attachments — a method to
//! simulate inextensible clothing in computer games"): every free node is held within its rest
//! distance from the pins, scaled by the step's largest target strain.
//!
//! The bound is implied by the shape constraints themselves, so it changes no converged shape:
//! when every edge is at most `1 + ε` times its rest length, the image of a path in the rest mesh
//! is at most `1 + ε` times as long, and a node is no farther from a pin than the image of the
//! shortest rest path between them. The rest path's length is the straight distance in the
//! pattern plane when the node's panel is convex (the segment lies in the panel), otherwise the
//! shortest path along the mesh's edges (Dijkstra; longer than the geodesic, so still a valid
//! bound, only a looser one). What it changes is how fast the iterations get there: a cloth
//! hanging from a few pins carries its whole weight through them, and the local (Jacobi-type)
//! shape iterations move a correction about one edge per iteration, so the stretch piles up near
//! the pins step after step; the attachments pull every node back to where the constraints would
//! put it at most, in one projection.
//!
//! Each node keeps its [`PER_NODE`] nearest pins (dropping a bound loosens nothing that the
//! shape constraints do not hold anyway). Built when the pinned nodes change; a cloth without
//! pins has none and the projection costs nothing.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::Vector3;
use rayon::prelude::*;

use crate::cloth::Cloth;

type V3 = Vector3<f64>;

/// Pins kept per node (the nearest by rest distance).
pub const PER_NODE: usize = 4;

/// Nodes at or above which the projection runs in parallel.
const PAR_MIN: usize = 4096;

/// The attachments of one cloth's pins.
#[derive(Clone, Debug, Default)]
pub(crate) struct LongRange {
    /// The pinned nodes these were built for, in `Cloth::pins` order.
    pinned: Vec<u32>,
    /// Per node, up to [`PER_NODE`] `(index into Cloth::pins, rest distance in m)`, nearest
    /// first; `count[i]` of them are used.
    slots: Vec<[(u32, f64); PER_NODE]>,
    count: Vec<u8>,
    /// The pins' positions at the end of the step (scratch of [`LongRange::project`]).
    anchors: Vec<V3>,
}

#[derive(PartialEq)]
struct Entry(f64, u32);
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        // A min-heap on the distance.
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

impl LongRange {
    /// Whether these attachments belong to `cloth`'s current pins.
    pub(crate) fn matches(&self, cloth: &Cloth) -> bool {
        self.pinned.len() == cloth.pins().len()
            && self
                .pinned
                .iter()
                .zip(cloth.pins())
                .all(|(&a, p)| a == p.node)
            && self.count.len() == cloth.topology().node_count()
    }

    /// The attachments of `cloth`'s pins.
    pub(crate) fn build(cloth: &Cloth) -> Self {
        let topo = cloth.topology();
        let n = topo.node_count();
        let rest = topo.rest_positions();
        let edges = topo.edges();
        // Adjacency by edges (axial and diagonal).
        let mut offsets = vec![0usize; n + 1];
        for e in edges {
            offsets[e.a as usize + 1] += 1;
            offsets[e.b as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut adjacent = vec![(0u32, 0.0f64); offsets[n]];
        for e in edges {
            let (a, b) = (e.a as usize, e.b as usize);
            adjacent[fill[a]] = (e.b, e.rest_length);
            fill[a] += 1;
            adjacent[fill[b]] = (e.a, e.rest_length);
            fill[b] += 1;
        }
        let convex = convex_components(cloth, &offsets, &adjacent);
        let mut slots = vec![[(u32::MAX, f64::INFINITY); PER_NODE]; n];
        let mut count = vec![0u8; n];
        let mut dist = vec![f64::INFINITY; n];
        let mut heap = BinaryHeap::new();
        for (k, pin) in cloth.pins().iter().enumerate() {
            let p = pin.node as usize;
            dist.iter_mut().for_each(|d| *d = f64::INFINITY);
            dist[p] = 0.0;
            heap.push(Entry(0.0, p as u32));
            let mut reached = Vec::new();
            while let Some(Entry(d, i)) = heap.pop() {
                let i = i as usize;
                if d > dist[i] {
                    continue;
                }
                reached.push(i);
                for &(j, l) in &adjacent[offsets[i]..offsets[i + 1]] {
                    let nd = d + l;
                    if nd < dist[j as usize] {
                        dist[j as usize] = nd;
                        heap.push(Entry(nd, j));
                    }
                }
            }
            let straight = convex[p];
            for i in reached {
                if cloth.inverse_masses()[i] == 0.0 {
                    continue;
                }
                let d = if straight {
                    let (a, b) = (rest[i], rest[p]);
                    (a[0] - b[0]).hypot(a[1] - b[1])
                } else {
                    dist[i]
                };
                insert(&mut slots[i], &mut count[i], (k as u32, d));
            }
        }
        Self {
            pinned: cloth.pins().iter().map(|p| p.node).collect(),
            slots,
            count,
            anchors: Vec::new(),
        }
    }

    /// Hold every attached node's end-of-step position `x + v·Δt` within `(1 + slack)` times its
    /// rest distance from each of its pins' positions at `t_end`, by changing its velocity.
    pub(crate) fn project(
        &mut self,
        cloth: &Cloth,
        positions: &[V3],
        vel: &mut [V3],
        t_end: f64,
        dt: f64,
        slack: f64,
    ) {
        self.anchors.clear();
        self.anchors
            .extend(cloth.pins().iter().map(|p| p.position(t_end)));
        let (anchors, slots, counts) = (&self.anchors, &self.slots, &self.count);
        let scale = 1.0 + slack;
        let node = |(i, v): (usize, &mut V3)| {
            let count = counts[i] as usize;
            if count == 0 {
                return;
            }
            let mut x = positions[i] + *v * dt;
            let mut moved = false;
            for &(k, rest) in &slots[i][..count] {
                let c = anchors[k as usize];
                let d = x - c;
                let bound = rest * scale;
                let l2 = d.norm_squared();
                if l2 > bound * bound {
                    x = c + d * (bound / l2.sqrt());
                    moved = true;
                }
            }
            if moved {
                *v = (x - positions[i]) / dt;
            }
        };
        if vel.len() >= PAR_MIN {
            vel.par_iter_mut().enumerate().for_each(node);
        } else {
            vel.iter_mut().enumerate().for_each(node);
        }
    }
}

/// Keep the `PER_NODE` smallest distances, sorted.
fn insert(slots: &mut [(u32, f64); PER_NODE], count: &mut u8, entry: (u32, f64)) {
    let c = *count as usize;
    let mut k = c.min(PER_NODE);
    if k == PER_NODE {
        if entry.1 >= slots[PER_NODE - 1].1 {
            return;
        }
        k = PER_NODE - 1;
    } else {
        *count += 1;
    }
    while k > 0 && slots[k - 1].1 > entry.1 {
        slots[k] = slots[k - 1];
        k -= 1;
    }
    slots[k] = entry;
}

/// Per node: whether its connected component's rest region is convex (its triangles' total
/// area equals the area of its nodes' convex hull, to 1e-9 relative), so that the straight
/// segment between two of its nodes lies in the cloth.
fn convex_components(cloth: &Cloth, offsets: &[usize], adjacent: &[(u32, f64)]) -> Vec<bool> {
    let topo = cloth.topology();
    let n = topo.node_count();
    let rest = topo.rest_positions();
    let mut component = vec![u32::MAX; n];
    let mut members: Vec<Vec<usize>> = Vec::new();
    for start in 0..n {
        if component[start] != u32::MAX {
            continue;
        }
        let id = members.len() as u32;
        let mut stack = vec![start];
        component[start] = id;
        let mut list = Vec::new();
        while let Some(i) = stack.pop() {
            list.push(i);
            for &(j, _) in &adjacent[offsets[i]..offsets[i + 1]] {
                if component[j as usize] == u32::MAX {
                    component[j as usize] = id;
                    stack.push(j as usize);
                }
            }
        }
        members.push(list);
    }
    let mut area = vec![0.0; members.len()];
    for t in topo.triangles() {
        let [a, b, c] = t.map(|k| rest[k as usize]);
        let doubled = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        area[component[t[0] as usize] as usize] += 0.5 * doubled.abs();
    }
    let convex: Vec<bool> = members
        .iter()
        .zip(&area)
        .map(|(list, &a)| {
            let hull = hull_area(list.iter().map(|&i| rest[i]).collect());
            a > 0.0 && (hull - a).abs() <= 1e-9 * hull.max(a)
        })
        .collect();
    component.iter().map(|&c| convex[c as usize]).collect()
}

/// Area of the convex hull of points in the plane (Andrew's monotone chain).
fn hull_area(mut p: Vec<[f64; 2]>) -> f64 {
    if p.len() < 3 {
        return 0.0;
    }
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let points: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in points {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    let m = hull.len();
    0.5 * (0..m)
        .map(|k| {
            let (a, b) = (hull[k], hull[(k + 1) % m]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        .abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hull_of_a_square_with_inner_points_is_the_square() {
        let mut p = vec![[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]];
        p.extend([[1.0, 0.5], [0.5, 0.5], [1.0, 0.0]]);
        assert!((hull_area(p) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn the_nearest_pins_are_kept_sorted() {
        let mut slots = [(u32::MAX, f64::INFINITY); PER_NODE];
        let mut count = 0;
        for (k, d) in [3.0, 1.0, 5.0, 2.0, 0.5, 4.0].into_iter().enumerate() {
            insert(&mut slots, &mut count, (k as u32, d));
        }
        assert_eq!(count as usize, PER_NODE);
        let kept: Vec<f64> = slots.iter().map(|s| s.1).collect();
        assert_eq!(kept, vec![0.5, 1.0, 2.0, 3.0]);
    }
}
