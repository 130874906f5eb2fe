//! A structured patch under construction: `nu × nv` grid slots, each holding a node or nothing
//! (inside a dart), several slots may share one node (a dart's apex), and nodes may be fixed
//! (boundary, dart and pleat lines, fixed points). The improvement ([`crate::improve`](fn@crate::improve)) moves the
//! free nodes; [`crate::topology`] cooks the result.

use crate::topology::NO_NODE;

/// Axis directions of a slot, in the cyclic order the shear energy uses: +u, +v, −u, −v.
pub const DIRECTIONS: [(isize, isize); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

/// A structured patch: slots, nodes, fixed flags.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// Slots along u.
    pub nu: usize,
    /// Slots along v.
    pub nv: usize,
    /// Whether u wraps around (a tube or an annulus).
    pub periodic_u: bool,
    /// Slot `(i, j)` (index `j·nu + i`) → node index, or [`NO_NODE`].
    pub node_of: Vec<u32>,
    /// Node positions in the plane (the pattern plane or the image plane), m.
    pub positions: Vec<[f64; 2]>,
    /// Fixed nodes do not move during improvement.
    pub fixed: Vec<bool>,
    /// Cells cut out (inside a dart), indexed like slots by their `(i, j)` corner.
    pub cut: Vec<bool>,
}

impl Patch {
    /// A full patch: one node per slot, row by row; the boundary rows and (unless periodic)
    /// columns fixed.
    pub fn full(nu: usize, nv: usize, periodic_u: bool, positions: Vec<[f64; 2]>) -> Self {
        assert_eq!(positions.len(), nu * nv, "one position per slot");
        let fixed = (0..nu * nv)
            .map(|s| {
                let (i, j) = (s % nu, s / nu);
                j == 0 || j == nv - 1 || (!periodic_u && (i == 0 || i == nu - 1))
            })
            .collect();
        Self {
            nu,
            nv,
            periodic_u,
            node_of: (0..(nu * nv) as u32).collect(),
            positions,
            fixed,
            cut: vec![false; nu * nv],
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.positions.len()
    }

    /// The slot index of `(i, j)`, wrapping u when periodic; `None` outside the patch.
    pub fn slot(&self, i: isize, j: isize) -> Option<usize> {
        if j < 0 || j >= self.nv as isize {
            return None;
        }
        let i = if self.periodic_u {
            i.rem_euclid(self.nu as isize)
        } else if i < 0 || i >= self.nu as isize {
            return None;
        } else {
            i
        };
        Some(j as usize * self.nu + i as usize)
    }

    /// The node in slot `(i, j)`, if any.
    pub fn node(&self, i: isize, j: isize) -> Option<u32> {
        self.slot(i, j)
            .map(|s| self.node_of[s])
            .filter(|&n| n != NO_NODE)
    }

    /// Whether cell `(i, j)` (corners `(i,j) (i+1,j) (i+1,j+1) (i,j+1)`) exists: inside the
    /// patch, not cut out, all four corners holding nodes.
    pub fn cell_on(&self, i: isize, j: isize) -> bool {
        if j < 0 || j + 1 >= self.nv as isize {
            return false;
        }
        if !self.periodic_u && (i < 0 || i + 1 >= self.nu as isize) {
            return false;
        }
        let Some(s) = self.slot(i, j) else {
            return false;
        };
        !self.cut[s]
            && [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                .iter()
                .all(|&(a, b)| self.node(a, b).is_some())
    }

    /// Whether the grid edge from slot `(i, j)` one step along `(di, dj)` (an axis direction)
    /// exists: both ends hold distinct nodes and a cell beside it exists.
    pub fn edge_on(&self, i: isize, j: isize, di: isize, dj: isize) -> bool {
        let (Some(a), Some(b)) = (self.node(i, j), self.node(i + di, j + dj)) else {
            return false;
        };
        if a == b {
            return false;
        }
        // The edge runs from (i0, j0) one step along +u or +v.
        let (i0, j0) = (i.min(i + di), j.min(j + dj));
        if dj == 0 {
            self.cell_on(i0, j0) || self.cell_on(i0, j0 - 1)
        } else {
            self.cell_on(i0, j0) || self.cell_on(i0 - 1, j0)
        }
    }

    /// The node of slot `s` and its neighbours along the four directions (+u, +v, −u, −v), each
    /// `None` where absent, where the edge to it does not exist (across a dart) or where the
    /// neighbour is the same node (a merged apex).
    pub fn neighbourhood(&self, s: usize) -> Option<(u32, [Option<u32>; 4])> {
        let n = self.node_of[s];
        if n == NO_NODE {
            return None;
        }
        let (i, j) = ((s % self.nu) as isize, (s / self.nu) as isize);
        let nb = DIRECTIONS.map(|(di, dj)| {
            if self.edge_on(i, j, di, dj) {
                self.node(i + di, j + dj)
            } else {
                None
            }
        });
        Some((n, nb))
    }

    /// The quadrilateral cells that exist, as node quadruples (some may repeat at a merged
    /// apex).
    pub fn quads(&self) -> Vec<[u32; 4]> {
        self.cells().into_iter().map(|(q, _)| q).collect()
    }

    /// The cells that exist with their `(i, j)`.
    pub fn cells(&self) -> Vec<([u32; 4], (usize, usize))> {
        let cells_u = if self.periodic_u {
            self.nu
        } else {
            self.nu - 1
        };
        let mut out = Vec::new();
        for j in 0..self.nv.saturating_sub(1) as isize {
            for i in 0..cells_u as isize {
                if self.cell_on(i, j) {
                    let q = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                        .map(|(a, b)| self.node(a, b).expect("cell_on"));
                    out.push((q, (i as usize, j as usize)));
                }
            }
        }
        out
    }

    /// The smallest signed area (m², in the plane, relative to `orientation`) over the cells'
    /// triangles at positions `p`; negative when a cell has folded over. Cells with a merged
    /// corner count as one triangle.
    pub fn min_cell_area(&self, p: &[[f64; 2]], orientation: f64) -> f64 {
        let tri = |a: u32, b: u32, c: u32| {
            let (a, b, c) = (p[a as usize], p[b as usize], p[c as usize]);
            0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) * orientation
        };
        let mut min = f64::INFINITY;
        for q in self.quads() {
            let t = [
                tri(q[0], q[1], q[2]),
                tri(q[0], q[2], q[3]),
                tri(q[0], q[1], q[3]),
                tri(q[1], q[2], q[3]),
            ];
            // A merged corner makes one of each split's triangles empty: skip exact zeros.
            for a in t {
                if a != 0.0 || q.windows(2).all(|w| w[0] != w[1]) && q[0] != q[3] {
                    min = min.min(a);
                }
            }
        }
        min
    }

    /// The orientation of the cells at positions `p`: +1 when counter-clockwise in the plane
    /// (u × v > 0), −1 otherwise (by the sum of the cells' signed areas).
    pub fn orientation(&self, p: &[[f64; 2]]) -> f64 {
        let total: f64 = self
            .quads()
            .iter()
            .map(|q| {
                let c = q.map(|k| p[k as usize]);
                (0..4)
                    .map(|k| c[k][0] * c[(k + 1) % 4][1] - c[(k + 1) % 4][0] * c[k][1])
                    .sum::<f64>()
            })
            .sum();
        if total < 0.0 { -1.0 } else { 1.0 }
    }

    /// Grid lines as runs of nodes: every row (along u) and column (along v), split where an
    /// edge does not exist; a merged apex (an edge from a node to itself) is skipped. A complete
    /// periodic row is one closed run (its first node repeated at the end). Each run has at
    /// least two nodes.
    pub fn lines(&self) -> Vec<(LineAxis, Vec<u32>)> {
        let mut out = Vec::new();
        let mut walk = |axis: LineAxis, steps: usize, at: &dyn Fn(isize) -> (isize, isize)| {
            let (di, dj) = match axis {
                LineAxis::U => (1, 0),
                LineAxis::V => (0, 1),
            };
            let mut run: Vec<u32> = Vec::new();
            for k in 0..steps as isize {
                let (i, j) = at(k);
                let (a, b) = (self.node(i, j), self.node(i + di, j + dj));
                if a.is_some() && a == b {
                    continue;
                }
                if self.edge_on(i, j, di, dj) {
                    let (a, b) = (a.expect("edge"), b.expect("edge"));
                    if run.last() != Some(&a) {
                        if run.len() >= 2 {
                            out.push((axis, std::mem::take(&mut run)));
                        }
                        run.clear();
                        run.push(a);
                    }
                    run.push(b);
                } else {
                    if run.len() >= 2 {
                        out.push((axis, std::mem::take(&mut run)));
                    }
                    run.clear();
                }
            }
            if run.len() >= 2 {
                out.push((axis, run));
            }
        };
        let row_steps = if self.periodic_u {
            self.nu
        } else {
            self.nu - 1
        };
        for j in 0..self.nv as isize {
            walk(LineAxis::U, row_steps, &|k| (k, j));
        }
        for i in 0..self.nu as isize {
            walk(LineAxis::V, self.nv - 1, &|k| (i, k));
        }
        out
    }
}

/// Which grid axis a line runs along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineAxis {
    /// Along u (a row).
    U,
    /// Along v (a column).
    V,
}
