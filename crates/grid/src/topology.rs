//! The cooked, immutable cloth topology the solver consumes (thesis §3.4, `method.md` §0 and §4):
//! nodes with rest positions in the pattern plane, axial (4-neighbourhood) and diagonal edges
//! (together the 8-neighbourhood) with rest length and material angle, triangles, node areas,
//! and the incidence lists the solver gathers over.
//!
//! Conventions: grid axes u (first index) and v (second index) are topological; the *material*
//! angle of an edge is measured in the pattern plane from the warp (grain) direction, in [0, π).
//! Triangles are counter-clockwise in the pattern plane, so a sheet's normal is the pattern
//! plane's +z wherever the cloth is placed flat.

use std::collections::HashMap;
use std::f64::consts::PI;

/// Marks an absent neighbour.
pub const NO_NODE: u32 = u32::MAX;

/// What an edge connects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EdgeKind {
    /// Along the grid's u axis (4-neighbourhood).
    AxialU,
    /// Along the grid's v axis (4-neighbourhood).
    AxialV,
    /// Across a cell (the diagonals of the 8-neighbourhood).
    Diagonal,
}

impl EdgeKind {
    /// Whether the edge belongs to the 4-neighbourhood.
    pub fn is_axial(self) -> bool {
        !matches!(self, EdgeKind::Diagonal)
    }
}

/// One edge of the 8-neighbourhood.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edge {
    /// First node.
    pub a: u32,
    /// Second node.
    pub b: u32,
    /// Axial (u or v) or diagonal.
    pub kind: EdgeKind,
    /// Rest length l⁰ in the pattern plane, m.
    pub rest_length: f64,
    /// Material angle θ from the warp, rad, in [0, π).
    pub material_angle: f64,
}

/// One grid cell (a quadrilateral `q0 q1 q2 q3`, u from q0 to q1, v from q0 to q3) with its
/// edges: the diagonals `q0–q2` ("plus") and `q1–q3` ("minus") belong to it alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// Corner nodes.
    pub nodes: [u32; 4],
    /// The u edges `q0–q1` and `q3–q2`.
    pub u_edges: [u32; 2],
    /// The v edges `q0–q3` and `q1–q2`.
    pub v_edges: [u32; 2],
    /// The diagonals `q0–q2` and `q1–q3`.
    pub diagonals: [u32; 2],
    /// Rest angle between the u and v sides at the cell's centre (mean of the corner angles of
    /// the parallelogram through the side midpoints), rad.
    pub rest_angle: f64,
    /// Rest area, m².
    pub area: f64,
}

/// The axial neighbour slots of a node: +u, −u, +v, −v.
pub const SLOTS: usize = 4;

/// A structured grid of `nu × nv` nodes in the pattern plane (node `(i, j)` at index
/// `j·nu + i`), optionally closed in u (an annulus: node `(nu, j)` is node `(0, j)`).
#[derive(Clone, Debug, PartialEq)]
pub struct StructuredGrid {
    /// Nodes along u.
    pub nu: usize,
    /// Nodes along v.
    pub nv: usize,
    /// Whether u wraps around.
    pub periodic_u: bool,
    /// Pattern-plane positions, m, `nu·nv` of them.
    pub positions: Vec<[f64; 2]>,
    /// Warp (grain) direction as an angle from the pattern x axis, rad.
    pub grain_angle: f64,
}

impl StructuredGrid {
    /// A rectangle `width × height` (m) with `nu × nv` nodes, u along x, v along y, the warp
    /// along y (so AxialV edges are warp, θ = 0, and AxialU edges weft, θ = 90°): the Coons
    /// patch of its four evenly divided sides, i.e. the uniform grid.
    pub fn sheet(nu: usize, nv: usize, width: f64, height: f64) -> Self {
        let (nu2, nv2) = (nu.max(2), nv.max(2));
        let side = |a: [f64; 2], b: [f64; 2], n: usize| crate::coons::resample(&[a, b], n);
        let mut positions = crate::coons::coons(
            &side([0.0, 0.0], [width, 0.0], nu2),
            &side([0.0, height], [width, height], nu2),
            &side([0.0, 0.0], [0.0, height], nv2),
            &side([width, 0.0], [width, height], nv2),
        );
        // Degenerate sizes (a single row or column) keep the count asked for; the topology
        // builder rejects them.
        positions.truncate(nu * nv);
        Self {
            nu,
            nv,
            periodic_u: false,
            positions,
            grain_angle: PI / 2.0,
        }
    }

    /// An annulus (the drape-test disk with its support hole) centred at the origin: `n_around`
    /// nodes per ring (u, periodic), `n_rings` rings (v) from `r_inner` to `r_outer` (m), the warp
    /// along y: the periodic Coons patch of the two circles and a radial seam, i.e. the exact
    /// polar grid (the same grid as the `Ring` pattern `fixtures/patterns/drape_annulus.ron`
    /// before improvement).
    pub fn annulus(n_around: usize, n_rings: usize, r_inner: f64, r_outer: f64) -> Self {
        let ring = |r: f64| -> Vec<[f64; 2]> {
            (0..n_around)
                .map(|i| {
                    let psi = 2.0 * PI * i as f64 / n_around as f64;
                    [r * psi.cos(), r * psi.sin()]
                })
                .collect()
        };
        let positions = if n_around >= 3 && n_rings >= 2 {
            crate::coons::coons_periodic(
                &ring(r_inner),
                &ring(r_outer),
                &crate::coons::resample(&[[r_inner, 0.0], [r_outer, 0.0]], n_rings),
            )
        } else {
            Vec::new()
        };
        Self {
            nu: n_around,
            nv: n_rings,
            periodic_u: true,
            positions,
            grain_angle: PI / 2.0,
        }
    }

    /// Index of node `(i, j)`; `i` wraps when the grid is periodic.
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.nu + if self.periodic_u { i % self.nu } else { i }
    }
}

/// Why a grid cannot be turned into a topology.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TopologyError {
    /// Too few nodes in a direction.
    #[error(
        "a grid needs at least 2 nodes along v and 2 (3 when periodic) along u, got {nu} × {nv}"
    )]
    TooSmall {
        /// Nodes along u.
        nu: usize,
        /// Nodes along v.
        nv: usize,
    },
    /// The position list does not have `nu·nv` entries.
    #[error("expected {expected} positions, got {found}")]
    PositionCount {
        /// `nu·nv`.
        expected: usize,
        /// Given.
        found: usize,
    },
    /// A non-finite coordinate.
    #[error("node {node} has a non-finite position ({x}, {y})")]
    NotFinite {
        /// Node index.
        node: usize,
        /// x.
        x: f64,
        /// y.
        y: f64,
    },
    /// A quad names a node that does not exist.
    #[error("cell {cell} names node {node}, but there are only {count} nodes")]
    NoSuchNode {
        /// Cell index.
        cell: usize,
        /// The node named.
        node: u32,
        /// Nodes given.
        count: usize,
    },
    /// Two nodes of an edge coincide.
    #[error("edge {a}–{b} has zero length")]
    ZeroLength {
        /// Node.
        a: u32,
        /// Node.
        b: u32,
    },
    /// A cell is degenerate or folded against the others.
    #[error("cell {cell} is degenerate or inverted (signed area {area})")]
    BadCell {
        /// Cell index (row by row for a structured grid).
        cell: usize,
        /// Its signed area relative to the grid's orientation, m².
        area: f64,
    },
    /// No cell has an area (nothing to build).
    #[error("no cell with a positive area")]
    Empty,
}

/// One quadrilateral of a grid, `q0 q1 q2 q3` with u from q0 to q1 and v from q0 to q3.
/// Corners may repeat (a dart apex merges nodes): a quad with three distinct corners becomes a
/// triangle without a shear cell, one with fewer is dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Quad {
    /// Corner nodes.
    pub nodes: [u32; 4],
    /// Split along `q1–q3` instead of `q0–q2` (alternate in a checkerboard).
    pub flip: bool,
}

/// The cloth topology: immutable, shared by every state of the same garment.
#[derive(Clone, Debug)]
pub struct ClothTopology {
    rest: Vec<[f64; 2]>,
    edges: Vec<Edge>,
    axial: Vec<[u32; SLOTS]>,
    axial_edge: Vec<[u32; SLOTS]>,
    triangles: Vec<[u32; 3]>,
    node_area: Vec<f64>,
    incidence_offsets: Vec<u32>,
    incidence: Vec<u32>,
    tri_offsets: Vec<u32>,
    tri_incidence: Vec<u32>,
    cells: Vec<Cell>,
    edge_cells: Vec<[u32; 2]>,
    grid: Option<(usize, usize, bool)>,
}

impl ClothTopology {
    /// Cook a structured grid: axial edges along u and v, both diagonals of every cell,
    /// two triangles per cell (the split alternates in a checkerboard so no direction is
    /// favoured), node areas as a quarter of each incident cell.
    pub fn from_structured(g: &StructuredGrid) -> Result<Self, TopologyError> {
        let (nu, nv) = (g.nu, g.nv);
        if nv < 2 || nu < 2 || (g.periodic_u && nu < 3) {
            return Err(TopologyError::TooSmall { nu, nv });
        }
        if g.positions.len() != nu * nv {
            return Err(TopologyError::PositionCount {
                expected: nu * nv,
                found: g.positions.len(),
            });
        }
        let cells_u = if g.periodic_u { nu } else { nu - 1 };
        let quads: Vec<Quad> = (0..nv - 1)
            .flat_map(|j| {
                (0..cells_u).map(move |i| Quad {
                    nodes: [
                        g.index(i, j),
                        g.index(i + 1, j),
                        g.index(i + 1, j + 1),
                        g.index(i, j + 1),
                    ]
                    .map(|k| k as u32),
                    flip: (i + j) % 2 == 1,
                })
            })
            .collect();
        let mut topo = Self::from_quads(&g.positions, &quads, g.grain_angle)?;
        topo.grid = Some((nu, nv, g.periodic_u));
        Ok(topo)
    }

    /// Cook any quadrilateral grid: nodes at `positions` (pattern plane, m), cells as [`Quad`]s
    /// (their u and v sides give each node's axial slots; the first quad to claim a slot keeps
    /// it), the warp at `grain_angle` from the pattern x axis. Edges are shared between cells;
    /// every full cell gets both diagonals and a shear [`Cell`]; node areas are a quarter of each
    /// full cell and a third of each triangle.
    pub fn from_quads(
        positions: &[[f64; 2]],
        quads: &[Quad],
        grain_angle: f64,
    ) -> Result<Self, TopologyError> {
        if let Some((node, p)) = positions
            .iter()
            .enumerate()
            .find(|(_, p)| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(TopologyError::NotFinite {
                node,
                x: p[0],
                y: p[1],
            });
        }
        let n = positions.len();
        for (cell, q) in quads.iter().enumerate() {
            if let Some(&node) = q.nodes.iter().find(|&&k| k as usize >= n) {
                return Err(TopologyError::NoSuchNode {
                    cell,
                    node,
                    count: n,
                });
            }
        }
        let grain = [grain_angle.cos(), grain_angle.sin()];
        let mut topo = Self {
            rest: positions.to_vec(),
            edges: Vec::new(),
            axial: vec![[NO_NODE; SLOTS]; n],
            axial_edge: vec![[NO_NODE; SLOTS]; n],
            triangles: Vec::with_capacity(2 * quads.len()),
            node_area: vec![0.0; n],
            incidence_offsets: Vec::new(),
            incidence: Vec::new(),
            tri_offsets: Vec::new(),
            tri_incidence: Vec::new(),
            cells: Vec::new(),
            edge_cells: Vec::new(),
            grid: None,
        };
        let mut index: HashMap<(u32, u32), u32> = HashMap::new();
        let mut edge =
            |topo: &mut Self, a: u32, b: u32, kind: EdgeKind| -> Result<u32, TopologyError> {
                if let Some(&e) = index.get(&(a.min(b), a.max(b))) {
                    return Ok(e);
                }
                let (pa, pb) = (positions[a as usize], positions[b as usize]);
                let e = [pb[0] - pa[0], pb[1] - pa[1]];
                let len = e[0].hypot(e[1]);
                if len <= 0.0 {
                    return Err(TopologyError::ZeroLength { a, b });
                }
                let cross = grain[0] * e[1] - grain[1] * e[0];
                let dot = grain[0] * e[0] + grain[1] * e[1];
                let mut angle = cross.atan2(dot).rem_euclid(PI);
                // Rounding can put a warp edge just below π; the angle is taken modulo π.
                if angle >= PI - 1e-12 {
                    angle = 0.0;
                }
                topo.edges.push(Edge {
                    a,
                    b,
                    kind,
                    rest_length: len,
                    material_angle: angle,
                });
                let id = (topo.edges.len() - 1) as u32;
                index.insert((a.min(b), a.max(b)), id);
                Ok(id)
            };
        // Axial slot: `a`'s slot `fwd` is `b`, `b`'s slot `fwd ^ 1` is `a`, first claim wins.
        let claim = |topo: &mut Self, a: u32, b: u32, e: u32, fwd: usize| {
            let (a, b) = (a as usize, b as usize);
            if topo.axial[a][fwd] == NO_NODE {
                topo.axial[a][fwd] = b as u32;
                topo.axial_edge[a][fwd] = e;
            }
            if topo.axial[b][fwd ^ 1] == NO_NODE {
                topo.axial[b][fwd ^ 1] = a as u32;
                topo.axial_edge[b][fwd ^ 1] = e;
            }
        };
        let signed_area = |p: &[[f64; 2]]| -> f64 {
            0.5 * (0..p.len())
                .map(|k| {
                    let (a, b) = (p[k], p[(k + 1) % p.len()]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum::<f64>()
        };
        let orientation = quads
            .iter()
            .map(|q| signed_area(&q.nodes.map(|k| positions[k as usize])))
            .find(|a| *a != 0.0 && a.is_finite())
            .ok_or(TopologyError::Empty)?
            .signum();
        let ccw = |t: [u32; 3]| -> [u32; 3] {
            if orientation > 0.0 {
                t
            } else {
                [t[0], t[2], t[1]]
            }
        };
        for (ci, quad) in quads.iter().enumerate() {
            let q = quad.nodes;
            // Sides: (from, to, slot of `to` seen from `from`).
            let sides = [
                (q[0], q[1], 0),
                (q[3], q[2], 0),
                (q[0], q[3], 2),
                (q[1], q[2], 2),
            ];
            let mut side_edges = [NO_NODE; 4];
            for (k, &(a, b, fwd)) in sides.iter().enumerate() {
                if a != b {
                    let kind = if fwd == 0 {
                        EdgeKind::AxialU
                    } else {
                        EdgeKind::AxialV
                    };
                    let e = edge(&mut topo, a, b, kind)?;
                    claim(&mut topo, a, b, e, fwd);
                    side_edges[k] = e;
                }
            }
            let mut distinct: Vec<u32> = Vec::with_capacity(4);
            for k in 0..4 {
                if q[k] != q[(k + 1) % 4] && !distinct.contains(&q[k]) {
                    distinct.push(q[k]);
                }
            }
            let p: Vec<[f64; 2]> = distinct.iter().map(|&k| positions[k as usize]).collect();
            let area = signed_area(&p) * orientation;
            match distinct.len() {
                4 => {}
                3 => {
                    if area.is_nan() || area <= 0.0 {
                        return Err(TopologyError::BadCell { cell: ci, area });
                    }
                    topo.triangles
                        .push(ccw([distinct[0], distinct[1], distinct[2]]));
                    for &k in &distinct {
                        topo.node_area[k as usize] += area / 3.0;
                    }
                    continue;
                }
                _ => continue,
            }
            if area.is_nan() || area <= 0.0 {
                return Err(TopologyError::BadCell { cell: ci, area });
            }
            let plus = edge(&mut topo, q[0], q[2], EdgeKind::Diagonal)?;
            let minus = edge(&mut topo, q[1], q[3], EdgeKind::Diagonal)?;
            let p = q.map(|k| positions[k as usize]);
            let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            let su = {
                let (m0, m1) = (mid(p[0], p[3]), mid(p[1], p[2]));
                [m1[0] - m0[0], m1[1] - m0[1]]
            };
            let sv = {
                let (m0, m1) = (mid(p[0], p[1]), mid(p[3], p[2]));
                [m1[0] - m0[0], m1[1] - m0[1]]
            };
            let rest_angle = (su[0] * sv[1] - su[1] * sv[0])
                .abs()
                .atan2(su[0] * sv[0] + su[1] * sv[1]);
            topo.cells.push(Cell {
                nodes: q,
                u_edges: [side_edges[0], side_edges[1]],
                v_edges: [side_edges[2], side_edges[3]],
                diagonals: [plus, minus],
                rest_angle,
                area,
            });
            if quad.flip {
                topo.triangles.push(ccw([q[0], q[1], q[3]]));
                topo.triangles.push(ccw([q[1], q[2], q[3]]));
            } else {
                topo.triangles.push(ccw([q[0], q[1], q[2]]));
                topo.triangles.push(ccw([q[0], q[2], q[3]]));
            }
            for k in q {
                topo.node_area[k as usize] += 0.25 * area;
            }
        }
        topo.build_incidence();
        Ok(topo)
    }

    /// Several topologies as one (a garment's panels in one cloth): nodes, edges, triangles and
    /// cells concatenated in order, every index shifted by the parts before it; no edge joins two
    /// parts (seams are pairs of nodes, sewn by the simulation). Returns the union and the first
    /// node index of each part.
    pub fn union(parts: &[&ClothTopology]) -> (ClothTopology, Vec<u32>) {
        let mut topo = Self {
            rest: Vec::new(),
            edges: Vec::new(),
            axial: Vec::new(),
            axial_edge: Vec::new(),
            triangles: Vec::new(),
            node_area: Vec::new(),
            incidence_offsets: Vec::new(),
            incidence: Vec::new(),
            tri_offsets: Vec::new(),
            tri_incidence: Vec::new(),
            cells: Vec::new(),
            edge_cells: Vec::new(),
            grid: None,
        };
        let mut offsets = Vec::with_capacity(parts.len());
        for p in parts {
            let (n0, e0) = (topo.rest.len() as u32, topo.edges.len() as u32);
            offsets.push(n0);
            let shift = |k: u32, by: u32| if k == NO_NODE { NO_NODE } else { k + by };
            topo.rest.extend_from_slice(&p.rest);
            topo.node_area.extend_from_slice(&p.node_area);
            topo.edges.extend(p.edges.iter().map(|e| Edge {
                a: e.a + n0,
                b: e.b + n0,
                ..*e
            }));
            topo.axial
                .extend(p.axial.iter().map(|s| s.map(|k| shift(k, n0))));
            topo.axial_edge
                .extend(p.axial_edge.iter().map(|s| s.map(|k| shift(k, e0))));
            topo.triangles
                .extend(p.triangles.iter().map(|t| t.map(|k| k + n0)));
            topo.cells.extend(p.cells.iter().map(|c| Cell {
                nodes: c.nodes.map(|k| k + n0),
                u_edges: c.u_edges.map(|k| k + e0),
                v_edges: c.v_edges.map(|k| k + e0),
                diagonals: c.diagonals.map(|k| k + e0),
                ..*c
            }));
        }
        topo.build_incidence();
        (topo, offsets)
    }

    /// CSR lists: for each node, the edges (and triangles) touching it; for each edge, its cells.
    fn build_incidence(&mut self) {
        let n = self.rest.len();
        let (offsets, list) = csr(n, self.edges.iter().map(|e| [e.a, e.b]));
        self.incidence_offsets = offsets;
        self.incidence = list;
        let (offsets, list) = csr(n, self.triangles.iter().copied());
        self.tri_offsets = offsets;
        self.tri_incidence = list;
        self.edge_cells = vec![[NO_NODE; 2]; self.edges.len()];
        for (ci, c) in self.cells.iter().enumerate() {
            for e in c.u_edges.iter().chain(&c.v_edges).chain(&c.diagonals) {
                let slot = &mut self.edge_cells[*e as usize];
                let k = usize::from(slot[0] != NO_NODE);
                slot[k] = ci as u32;
            }
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.rest.len()
    }

    /// Rest positions in the pattern plane, m.
    pub fn rest_positions(&self) -> &[[f64; 2]] {
        &self.rest
    }

    /// All edges (axial and diagonal).
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// Axial neighbours of each node per slot (+u, −u, +v, −v); [`NO_NODE`] where absent.
    pub fn axial_neighbours(&self) -> &[[u32; SLOTS]] {
        &self.axial
    }

    /// The edge index of each axial slot; [`NO_NODE`] where absent.
    pub fn axial_edges(&self) -> &[[u32; SLOTS]] {
        &self.axial_edge
    }

    /// Triangles, counter-clockwise in the pattern plane.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Area each node represents (S), m²: a quarter of every incident cell.
    pub fn node_areas(&self) -> &[f64] {
        &self.node_area
    }

    /// Total pattern area, m².
    pub fn area(&self) -> f64 {
        self.node_area.iter().sum()
    }

    /// Edges incident to `node`.
    pub fn incident_edges(&self, node: usize) -> &[u32] {
        let (a, b) = (
            self.incidence_offsets[node] as usize,
            self.incidence_offsets[node + 1] as usize,
        );
        &self.incidence[a..b]
    }

    /// Triangles incident to `node`.
    pub fn incident_triangles(&self, node: usize) -> &[u32] {
        let (a, b) = (
            self.tri_offsets[node] as usize,
            self.tri_offsets[node + 1] as usize,
        );
        &self.tri_incidence[a..b]
    }

    /// The grid cells.
    pub fn cells(&self) -> &[Cell] {
        &self.cells
    }

    /// The (up to two) cells each edge borders; [`NO_NODE`] where absent. A diagonal has one.
    pub fn edge_cells(&self) -> &[[u32; 2]] {
        &self.edge_cells
    }

    /// `(nu, nv, periodic_u)` of the structured grid this came from.
    pub fn grid_shape(&self) -> Option<(usize, usize, bool)> {
        self.grid
    }

    /// Greedy edge colouring: groups of edges that share no node, so a colour can be processed
    /// in parallel without conflicts. Deterministic (edges in index order).
    pub fn edge_colours(&self) -> Vec<Vec<u32>> {
        let n = self.rest.len();
        let mut used: Vec<u64> = vec![0; n];
        let mut colours: Vec<Vec<u32>> = Vec::new();
        for (ei, e) in self.edges.iter().enumerate() {
            let busy = used[e.a as usize] | used[e.b as usize];
            let c = (!busy).trailing_zeros() as usize;
            if c >= colours.len() {
                colours.resize_with(c + 1, Vec::new);
            }
            colours[c].push(ei as u32);
            used[e.a as usize] |= 1 << c;
            used[e.b as usize] |= 1 << c;
        }
        colours
    }
}

/// Compressed lists of the items touching each of `n` nodes, in item order.
fn csr<const K: usize>(
    n: usize,
    items: impl Iterator<Item = [u32; K]> + Clone,
) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; n + 1];
    for item in items.clone() {
        for v in item {
            offsets[v as usize + 1] += 1;
        }
    }
    for k in 0..n {
        offsets[k + 1] += offsets[k];
    }
    let mut fill = offsets.clone();
    let mut list = vec![0u32; offsets[n] as usize];
    for (idx, item) in items.enumerate() {
        for v in item {
            list[fill[v as usize] as usize] = idx as u32;
            fill[v as usize] += 1;
        }
    }
    (offsets, list)
}

#[cfg(test)]
mod tests;
