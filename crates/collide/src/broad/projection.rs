//! Broad phase (b): the thesis's projection test (§5.3.1) on hashed 2D grids, no tree.
//!
//! Each triangle's swept box is projected onto the XY, XZ and YZ planes and binned into one
//! uniform 2D grid per plane. The grids are hashed (cell `(i, j)` → bucket), so their extent
//! is unbounded and a far-away vertex costs nothing; the buckets are rebuilt by a counting
//! sort at every update (three passes over the triangles, no allocation once warm).
//!
//! A query projects its grown segment onto the three planes, sums the entries of the covered
//! cells per plane, walks the plane with the fewest, and keeps a triangle only if its
//! projection overlaps the query's in all three planes: the box overlap (equivalent to the 3D
//! box overlap) and, per plane, the separating axis normal to the projected segment (the
//! triangle's six projected vertices must reach the segment's grown line) — both
//! conservative.

use super::{BroadPhase, segment_box, swept_boxes};
use crate::{Aabb, V3};

/// The coordinate axes `(u, v)` of the three projection planes XY, XZ, YZ.
const PLANES: [[usize; 2]; 3] = [[0, 1], [0, 2], [1, 2]];
/// A triangle covering more cells than this in a plane goes to that plane's oversize list.
const MAX_CELLS_PER_TRIANGLE: i64 = 64;
/// Cell indices must stay well inside `i32`; beyond, the triangle is oversize.
const MAX_CELL_INDEX: f64 = 1.0e9;

/// One binned triangle: its index and the cell it was binned in (hash buckets mix cells).
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    tri: u32,
    i: i32,
    j: i32,
}

/// The hashed grid of one projection plane.
#[derive(Clone, Debug, Default)]
struct PlaneGrid {
    /// Axes `(u, v)` of the plane.
    axes: [usize; 2],
    /// 1 / cell size.
    inv_h: f64,
    /// Per triangle: its cell range `[i0, j0, i1, j1]`; `i0 == i32::MIN` when oversize.
    range: Vec<[i32; 4]>,
    /// Bucket `b` holds `entries[starts[b]..starts[b + 1]]`.
    starts: Vec<u32>,
    entries: Vec<Entry>,
    /// Number of buckets − 1 (a power of two − 1).
    mask: u64,
    /// Triangles too large (or too far) to bin: checked by every query walking this plane.
    oversize: Vec<u32>,
}

/// The cell range `[i0, j0, i1, j1]` of the 2D box `[u0, u1] × [v0, v1]`, or `None` when it
/// would cover too many cells (`max_cells`) or leave the index range.
fn cell_range(inv_h: f64, lo: [f64; 2], hi: [f64; 2], max_cells: i64) -> Option<[i32; 4]> {
    let i0 = (lo[0] * inv_h).floor();
    let j0 = (lo[1] * inv_h).floor();
    let i1 = (hi[0] * inv_h).floor();
    let j1 = (hi[1] * inv_h).floor();
    let ok = |x: f64| x.abs() < MAX_CELL_INDEX; // false for NaN too
    if !(ok(i0) && ok(j0) && ok(i1) && ok(j1)) {
        return None;
    }
    let (i0, j0, i1, j1) = (i0 as i64, j0 as i64, i1 as i64, j1 as i64);
    let cells = (i1 - i0 + 1) * (j1 - j0 + 1);
    (cells <= max_cells).then_some([i0 as i32, j0 as i32, i1 as i32, j1 as i32])
}

/// The bucket of cell `(i, j)`.
#[inline]
fn bucket(i: i32, j: i32, mask: u64) -> usize {
    let mut h = u64::from(i as u32).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ u64::from(j as u32).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    h ^= h >> 29;
    (h & mask) as usize
}

impl PlaneGrid {
    fn lo_hi(&self, b: &Aabb) -> ([f64; 2], [f64; 2]) {
        let [u, v] = self.axes;
        ([b.min[u], b.min[v]], [b.max[u], b.max[v]])
    }

    /// Re-bin all boxes with cell size `h`.
    fn rebuild(&mut self, boxes: &[Aabb], h: f64) {
        self.inv_h = 1.0 / h;
        self.range.clear();
        self.oversize.clear();
        let mut total = 0usize;
        for (t, b) in boxes.iter().enumerate() {
            let (lo, hi) = self.lo_hi(b);
            match cell_range(self.inv_h, lo, hi, MAX_CELLS_PER_TRIANGLE) {
                Some(r) => {
                    total += ((r[2] - r[0] + 1) * (r[3] - r[1] + 1)) as usize;
                    self.range.push(r);
                }
                None => {
                    self.range.push([i32::MIN; 4]);
                    self.oversize.push(t as u32);
                }
            }
        }
        let nb = total.max(1).next_power_of_two();
        self.mask = (nb - 1) as u64;
        self.starts.clear();
        self.starts.resize(nb + 1, 0);
        let binned = |r: &[i32; 4]| r[0] != i32::MIN;
        for r in self.range.iter().filter(|r| binned(r)) {
            for i in r[0]..=r[2] {
                for j in r[1]..=r[3] {
                    self.starts[bucket(i, j, self.mask)] += 1;
                }
            }
        }
        // Exclusive prefix sum: starts[b] = first slot of bucket b.
        let mut acc = 0u32;
        for s in &mut self.starts {
            let c = *s;
            *s = acc;
            acc += c;
        }
        self.entries.clear();
        self.entries.resize(total, Entry::default());
        for (t, r) in self.range.iter().enumerate() {
            if !binned(r) {
                continue;
            }
            for i in r[0]..=r[2] {
                for j in r[1]..=r[3] {
                    let b = bucket(i, j, self.mask);
                    let slot = &mut self.starts[b];
                    self.entries[*slot as usize] = Entry {
                        tri: t as u32,
                        i,
                        j,
                    };
                    *slot += 1;
                }
            }
        }
        // The cursors now point at the next bucket's first slot: shift back by one.
        for b in (1..=nb).rev() {
            self.starts[b] = self.starts[b - 1];
        }
        self.starts[0] = 0;
    }

    #[inline]
    fn bucket_entries(&self, i: i32, j: i32) -> &[Entry] {
        let b = bucket(i, j, self.mask);
        &self.entries[self.starts[b] as usize..self.starts[b + 1] as usize]
    }
}

/// Per plane, the separating axis normal to the projected query segment.
#[derive(Clone, Copy, Debug, Default)]
struct SegmentAxis {
    active: bool,
    axes: [usize; 2],
    /// Unit normal of the projected segment.
    n: [f64; 2],
    /// `n · a` (= `n · b`).
    s: f64,
    /// Half-width of the query along `n` (radius grown as a box, plus rounding slack).
    half: f64,
    /// `|n_u| + |n_v|`: how a box margin widens an interval along `n`.
    w: f64,
}

impl SegmentAxis {
    fn new(axes: [usize; 2], a: &V3, b: &V3, radius: f64) -> Self {
        let [u, v] = axes;
        let d = [b[u] - a[u], b[v] - a[v]];
        let len = d[0].hypot(d[1]);
        let scale = a[u].abs() + a[v].abs() + b[u].abs() + b[v].abs();
        if len.is_nan() || len <= 1e-12 * (1.0 + scale) {
            return Self::default();
        }
        let n = [-d[1] / len, d[0] / len];
        let w = n[0].abs() + n[1].abs();
        let s = n[0] * a[u] + n[1] * a[v];
        // Rounding slack keeps the test conservative at exact contact.
        let slack = 1e-9 * (1.0 + scale + radius.abs());
        Self {
            active: true,
            axes,
            n,
            s,
            half: radius.max(0.0) * w + slack,
            w,
        }
    }
}

/// The thesis's projection test without a tree (see the module docs).
///
/// Cell size of each plane: the median, over the triangles, of the larger side of the swept
/// box's projection (so a typical triangle covers 1–4 cells and a typical query a few);
/// falls back to the mean, then 1 m, for fully degenerate meshes.
#[derive(Clone, Debug)]
pub struct ProjectionBroad {
    start: Vec<V3>,
    end: Vec<V3>,
    triangles: Vec<[u32; 3]>,
    margin: f64,
    boxes: Vec<Aabb>,
    planes: [PlaneGrid; 3],
    scratch: Vec<f64>,
    fine: bool,
}

impl Default for ProjectionBroad {
    fn default() -> Self {
        Self::new()
    }
}

impl ProjectionBroad {
    /// An empty broad phase (no triangles until [`BroadPhase::update`]), with the per-plane
    /// segment test on.
    pub fn new() -> Self {
        Self {
            start: Vec::new(),
            end: Vec::new(),
            triangles: Vec::new(),
            margin: 0.0,
            boxes: Vec::new(),
            planes: PLANES.map(|axes| PlaneGrid {
                axes,
                ..PlaneGrid::default()
            }),
            scratch: Vec::new(),
            fine: true,
        }
    }

    /// With `fine = false` a candidate only needs its box projections to overlap the query's
    /// (the same set as [`super::BruteForce`]); with `true` (the default) it must also reach
    /// the projected segment's grown line in each plane.
    #[must_use]
    pub fn with_segment_test(mut self, fine: bool) -> Self {
        self.fine = fine;
        self
    }

    /// Cell size of the plane with axes `[u, v]`.
    fn cell_size(&mut self, [u, v]: [usize; 2]) -> f64 {
        self.scratch.clear();
        self.scratch.extend(
            self.boxes
                .iter()
                .map(|b| (b.max[u] - b.min[u]).max(b.max[v] - b.min[v])),
        );
        if self.scratch.is_empty() {
            return 1.0;
        }
        let mid = self.scratch.len() / 2;
        let (_, &mut median, _) = self.scratch.select_nth_unstable_by(mid, f64::total_cmp);
        if median.is_finite() && median > 0.0 {
            return median;
        }
        let finite: Vec<f64> = self
            .scratch
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .collect();
        let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;
        if mean.is_finite() && mean > 0.0 {
            mean
        } else {
            1.0
        }
    }

    /// Whether triangle `t` passes the three-plane test against the query.
    #[inline]
    fn accept(&self, t: usize, q: &Aabb, axes: &[SegmentAxis; 3]) -> bool {
        if !self.boxes[t].overlaps(q) {
            return false;
        }
        if !self.fine {
            return true;
        }
        let tri = &self.triangles[t];
        for ax in axes.iter().filter(|ax| ax.active) {
            let [u, v] = ax.axes;
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for &k in tri {
                for p in [&self.start[k as usize], &self.end[k as usize]] {
                    let x = ax.n[0] * p[u] + ax.n[1] * p[v];
                    lo = lo.min(x);
                    hi = hi.max(x);
                }
            }
            let grow = self.margin * ax.w + ax.half;
            if hi + grow < ax.s || lo - grow > ax.s {
                return false;
            }
        }
        true
    }
}

impl BroadPhase for ProjectionBroad {
    fn update(&mut self, start: &[V3], end: &[V3], triangles: &[[u32; 3]], margin: f64) {
        swept_boxes(start, end, triangles, margin, &mut self.boxes);
        self.start.clear();
        self.start.extend_from_slice(start);
        self.end.clear();
        self.end.extend_from_slice(end);
        self.triangles.clear();
        self.triangles.extend_from_slice(triangles);
        self.margin = margin.max(0.0);
        for p in 0..3 {
            let h = self.cell_size(self.planes[p].axes);
            self.planes[p].rebuild(&self.boxes, h);
        }
    }

    fn query(&self, a: &V3, b: &V3, radius: f64, out: &mut Vec<u32>) {
        let n = self.boxes.len();
        if n == 0 {
            return;
        }
        let q = segment_box(a, b, radius);
        let axes = PLANES.map(|ax| SegmentAxis::new(ax, a, b, radius));

        // Choose the plane whose covered cells hold the fewest entries (a linear scan costs n).
        let cell_cap = (4 * n + 16) as i64;
        let mut best: Option<(usize, [i32; 4])> = None;
        let mut best_cost = n;
        for (p, grid) in self.planes.iter().enumerate() {
            let (lo, hi) = grid.lo_hi(&q);
            let Some(r) = cell_range(grid.inv_h, lo, hi, cell_cap) else {
                continue;
            };
            let mut cost = grid.oversize.len();
            'cells: for i in r[0]..=r[2] {
                for j in r[1]..=r[3] {
                    cost += grid.bucket_entries(i, j).len() + 1;
                    if cost >= best_cost {
                        break 'cells;
                    }
                }
            }
            if cost < best_cost {
                best_cost = cost;
                best = Some((p, r));
            }
        }

        let Some((p, r)) = best else {
            out.extend(
                (0..n)
                    .filter(|&t| self.accept(t, &q, &axes))
                    .map(|t| t as u32),
            );
            return;
        };
        let grid = &self.planes[p];
        for i in r[0]..=r[2] {
            for j in r[1]..=r[3] {
                for e in grid.bucket_entries(i, j) {
                    if e.i != i || e.j != j {
                        continue; // another cell sharing the bucket
                    }
                    // Report a triangle only from the first cell it shares with the query.
                    let tr = &grid.range[e.tri as usize];
                    if i != tr[0].max(r[0]) || j != tr[1].max(r[1]) {
                        continue;
                    }
                    if self.accept(e.tri as usize, &q, &axes) {
                        out.push(e.tri);
                    }
                }
            }
        }
        out.extend(
            grid.oversize
                .iter()
                .copied()
                .filter(|&t| self.accept(t as usize, &q, &axes)),
        );
    }
}
