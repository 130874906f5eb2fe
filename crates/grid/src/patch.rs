//! A structured patch under construction: `nu × nv` grid slots, each holding a node or nothing
//! (inside a dart), several slots may share one node (a dart's apex), and nodes may be fixed
//! (boundary, dart and pleat lines, fixed points). The improvement ([`crate::improve`]) moves the
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

    /// The node of slot `s` and its neighbours along the four directions (+u, +v, −u, −v), each
    /// `None` where absent or where the neighbour is the same node (a merged apex).
    pub fn neighbourhood(&self, s: usize) -> Option<(u32, [Option<u32>; 4])> {
        let n = self.node_of[s];
        if n == NO_NODE {
            return None;
        }
        let (i, j) = ((s % self.nu) as isize, (s / self.nu) as isize);
        let nb = DIRECTIONS.map(|(di, dj)| self.node(i + di, j + dj).filter(|&m| m != n));
        Some((n, nb))
    }

    /// The quadrilateral cells: slots `(i, j)` whose four corners `(i,j) (i+1,j) (i+1,j+1)
    /// (i,j+1)` all hold nodes, as node quadruples (some may repeat at a merged apex).
    pub fn quads(&self) -> Vec<[u32; 4]> {
        let cells_u = if self.periodic_u { self.nu } else { self.nu - 1 };
        let mut out = Vec::new();
        for j in 0..self.nv.saturating_sub(1) as isize {
            for i in 0..cells_u as isize {
                let q = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(a, b)| self.node(a, b));
                if let [Some(a), Some(b), Some(c), Some(d)] = q {
                    out.push([a, b, c, d]);
                }
            }
        }
        out
    }

    /// Grid lines as runs of nodes: every row (along u) and column (along v), split where a slot
    /// is empty; consecutive repeats (a merged apex) collapsed. A complete periodic row is one
    /// closed run (its first node repeated at the end). Each run has at least two nodes.
    pub fn lines(&self) -> Vec<(LineAxis, Vec<u32>)> {
        let mut out = Vec::new();
        let mut push = |axis: LineAxis, nodes: &[Option<u32>], closed: bool| {
            let mut run: Vec<u32> = Vec::new();
            let flush = |run: &mut Vec<u32>, out: &mut Vec<(LineAxis, Vec<u32>)>| {
                if run.len() >= 2 {
                    out.push((axis, std::mem::take(run)));
                } else {
                    run.clear();
                }
            };
            for n in nodes {
                match n {
                    Some(n) => {
                        if run.last() != Some(n) {
                            run.push(*n);
                        }
                    }
                    None => flush(&mut run, &mut out),
                }
            }
            if closed && nodes.iter().all(Option::is_some) && run.first() != run.last() {
                run.push(run[0]);
            }
            flush(&mut run, &mut out);
        };
        for j in 0..self.nv as isize {
            let row: Vec<_> = (0..self.nu as isize).map(|i| self.node(i, j)).collect();
            push(LineAxis::U, &row, self.periodic_u);
        }
        for i in 0..self.nu as isize {
            let col: Vec<_> = (0..self.nv as isize).map(|j| self.node(i, j)).collect();
            push(LineAxis::V, &col, false);
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
