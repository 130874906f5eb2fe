//! From a pattern to a gridded panel (thesis §4.4–4.6.1): boundary nodes evenly spaced within
//! each team, a Coons patch inside, darts cut out with their legs evenly divided and the apex
//! merged, pleat lines and fixed points imposed, the grid improved (on the depth field when
//! one is given), and the cloth topology cooked.

use std::f64::consts::PI;

use atelier_files::{ErrorKind, InvalidValue};

use super::spec::{DartSpec, Outline, PatternSpec, ResolvedTeam, find_team};
use crate::coons::{coons, coons_periodic, resample};
use crate::improve::{HeightField, ImproveParams, ImproveReport, Plane, Surface, improve};
use crate::patch::Patch;
use crate::quality::GridQuality;
use crate::topology::{ClothTopology, NO_NODE, Quad, TopologyError};

/// Pattern files are in centimetres; grids in metres.
const CM: f64 = 0.01;

/// A team's nodes in the finished panel, in outline order (counter-clockwise for a `Quad`;
/// along the loop for a `Ring`).
#[derive(Clone, Debug, PartialEq)]
pub struct Team {
    /// Team name.
    pub name: String,
    /// Topology node indices.
    pub nodes: Vec<u32>,
}

/// Node pairs to be sewn together.
#[derive(Clone, Debug, PartialEq)]
pub struct NodePairs {
    /// What they are (a dart's name).
    pub name: String,
    /// Pairs of topology node indices.
    pub pairs: Vec<(u32, u32)>,
}

/// A gridded panel.
#[derive(Clone, Debug)]
pub struct Panel {
    /// Panel name.
    pub name: String,
    /// The cooked cloth topology (rest positions in the pattern plane, m).
    pub topology: ClothTopology,
    /// Boundary teams.
    pub teams: Vec<Team>,
    /// Dart legs to be sewn within the panel.
    pub darts: Vec<NodePairs>,
    /// The grid before improvement (Coons with constraints imposed).
    pub initial: Patch,
    /// The grid after improvement.
    pub grid: Patch,
    /// Patch node → topology node ([`NO_NODE`] for nodes the grid dropped).
    pub topology_node: Vec<u32>,
    /// Quality before improvement.
    pub quality_before: GridQuality,
    /// Quality after improvement.
    pub quality_after: GridQuality,
    /// The energy history.
    pub improvement: ImproveReport,
    /// Depth field hills in metres (centre, height, radius), for drawing.
    pub depth: Vec<([f64; 2], f64, f64)>,
}

/// Errors building a panel from a (parsed, checked) pattern.
pub type BuildError = InvalidValue;

/// Grid a pattern: the initial grid, its improvement with `params` (the file's `improve` block
/// overrides them), the topology.
///
/// The spec is checked first (a spec built in code has not been through the parser's checks), so
/// bad input is an error, never a panic.
pub fn grid_pattern(spec: &PatternSpec, params: ImproveParams) -> Result<Panel, BuildError> {
    atelier_files::check::Validate::validate(spec)?;
    for (name, c) in [("c1", params.c1), ("c2", params.c2), ("c3", params.c3)] {
        if !(c.is_finite() && c >= 0.0) {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                format!("improve.{name}"),
                format!("weight {c} must be finite and ≥ 0"),
            ));
        }
    }
    let params = spec.improve.as_ref().map_or(params, |s| ImproveParams {
        c1: s.c1,
        c2: s.c2,
        c3: s.c3,
        relative_tolerance: s.relative_tolerance,
        max_iterations: s.max_iterations,
    });
    let sides = spec.resolve();
    let mut builder = match &spec.outline {
        Outline::Quad { .. } => Builder::quad(&sides),
        Outline::Ring { radial_cells, .. } => Builder::ring(spec, &sides, *radial_cells),
    };
    for (k, d) in spec.darts.iter().enumerate() {
        builder
            .dart(&sides, d)
            .map_err(|e| e.within(&format!("darts[{k}]")))?;
    }
    for (k, p) in spec.pleats.iter().enumerate() {
        builder
            .pleat([p.from.0 * CM, p.from.1 * CM], [p.to.0 * CM, p.to.1 * CM])
            .map_err(|e| e.within(&format!("pleats[{k}]")))?;
    }
    for (k, p) in spec.fixed_points.iter().enumerate() {
        builder
            .fix_point([p.0 * CM, p.1 * CM])
            .map_err(|e| e.within(&format!("fixed_points[{k}]")))?;
    }
    builder.relax_constrained();
    let depth: Vec<([f64; 2], f64, f64)> = spec
        .depth
        .iter()
        .map(|m| {
            (
                [m.centre.0 * CM, m.centre.1 * CM],
                m.height * CM,
                m.radius * CM,
            )
        })
        .collect();
    let hills = depth.clone();
    let field = HeightField(move |p: [f64; 2]| {
        let (mut h, mut g) = (0.0, [0.0, 0.0]);
        for (c, height, radius) in &hills {
            let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
            let v = height * (-(dx * dx + dy * dy) / (radius * radius)).exp();
            h += v;
            g[0] -= 2.0 * dx / (radius * radius) * v;
            g[1] -= 2.0 * dy / (radius * radius) * v;
        }
        (h, g)
    });
    let surface: &dyn Surface = if depth.is_empty() { &Plane } else { &field };
    let initial = builder.patch.clone();
    let quality_before = GridQuality::measure(&initial, surface);
    let improvement = improve(&mut builder.patch, surface, params);
    let quality_after = GridQuality::measure(&builder.patch, surface);
    let (g0, g1) = spec.grain;
    let grain_angle = (g1.1 - g0.1).atan2(g1.0 - g0.0);
    let (topology, topology_node) = cook(&builder.patch, grain_angle)?;
    let map = |nodes: &[u32]| -> Vec<u32> {
        nodes
            .iter()
            .map(|&n| topology_node[n as usize])
            .filter(|&n| n != NO_NODE)
            .collect()
    };
    let teams = builder
        .teams
        .iter()
        .map(|(name, nodes)| Team {
            name: name.clone(),
            nodes: map(nodes),
        })
        .collect();
    let darts = builder
        .darts
        .iter()
        .map(|(name, pairs)| NodePairs {
            name: name.clone(),
            pairs: pairs
                .iter()
                .map(|&(a, b)| (topology_node[a as usize], topology_node[b as usize]))
                .collect(),
        })
        .collect();
    Ok(Panel {
        name: spec.name.clone(),
        topology,
        teams,
        darts,
        initial,
        grid: builder.patch,
        topology_node,
        quality_before,
        quality_after,
        improvement,
        depth,
    })
}

/// Cook a patch: keep the nodes some slot uses, renumber them in slot order, and build the
/// topology from the quads (checkerboard split).
pub fn cook(patch: &Patch, grain_angle: f64) -> Result<(ClothTopology, Vec<u32>), BuildError> {
    let mut new_index = vec![NO_NODE; patch.node_count()];
    let mut positions = Vec::new();
    for &n in &patch.node_of {
        if n != NO_NODE && new_index[n as usize] == NO_NODE {
            new_index[n as usize] = positions.len() as u32;
            positions.push(patch.positions[n as usize]);
        }
    }
    let (quads, at): (Vec<Quad>, Vec<(usize, usize)>) = patch
        .cells()
        .into_iter()
        .map(|(q, (i, j))| {
            (
                Quad {
                    nodes: q.map(|k| new_index[k as usize]),
                    flip: (i + j) % 2 == 1,
                },
                (i, j),
            )
        })
        .unzip();
    let topo = ClothTopology::from_quads(&positions, &quads, grain_angle).map_err(|e| {
        let place = match e {
            TopologyError::BadCell { cell, .. } => {
                format!(" (the cell at column {}, row {})", at[cell].0, at[cell].1)
            }
            _ => String::new(),
        };
        InvalidValue::new(
            ErrorKind::Inconsistent,
            "",
            format!(
                "the grid cannot be cooked: {e}{place}; check that darts and pleats fit the \
                 grid (a dart's apex must lie between the rows its legs end on)"
            ),
        )
    })?;
    Ok((topo, new_index))
}

struct Builder {
    patch: Patch,
    /// (side, first cell along the side) of every team, for slots.
    sides: usize,
    teams: Vec<(String, Vec<u32>)>,
    darts: Vec<(String, Vec<(u32, u32)>)>,
    /// Interior nodes moved onto pleat lines and fixed points.
    moved: Vec<u32>,
}

/// Nodes of a side: the teams' polylines resampled (cm → m) and joined.
fn side_nodes(teams: &[ResolvedTeam]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    for t in teams {
        let poly: Vec<[f64; 2]> = t.polyline.iter().map(|p| [p[0] * CM, p[1] * CM]).collect();
        let nodes = resample(&poly, t.cells + 1);
        let skip = usize::from(!out.is_empty());
        out.extend_from_slice(&nodes[skip..]);
    }
    out
}

impl Builder {
    fn quad(sides: &[Vec<ResolvedTeam>]) -> Self {
        let bottom = side_nodes(&sides[0]);
        let right = side_nodes(&sides[1]);
        let mut top = side_nodes(&sides[2]);
        top.reverse();
        let mut left = side_nodes(&sides[3]);
        left.reverse();
        let (nu, nv) = (bottom.len(), right.len());
        let patch = Patch::full(nu, nv, false, coons(&bottom, &top, &left, &right));
        let mut b = Self {
            patch,
            sides: 4,
            teams: Vec::new(),
            darts: Vec::new(),
            moved: Vec::new(),
        };
        b.collect_teams(sides);
        b
    }

    fn ring(spec: &PatternSpec, sides: &[Vec<ResolvedTeam>], radial: usize) -> Self {
        let mut inner = side_nodes(&sides[0]);
        inner.pop();
        let mut outer = side_nodes(&sides[1]);
        outer.pop();
        let Outline::Ring {
            inner_start,
            outer_start,
            ..
        } = spec.outline
        else {
            unreachable!("ring builder on a ring outline")
        };
        let seam = resample(
            &[
                [inner_start.0 * CM, inner_start.1 * CM],
                [outer_start.0 * CM, outer_start.1 * CM],
            ],
            radial + 1,
        );
        let nu = inner.len();
        let patch = Patch::full(nu, radial + 1, true, coons_periodic(&inner, &outer, &seam));
        let mut b = Self {
            patch,
            sides: 2,
            teams: Vec::new(),
            darts: Vec::new(),
            moved: Vec::new(),
        };
        b.collect_teams(sides);
        b
    }

    /// The slot of index `k` along `side` (Quad: bottom, right, top, left counter-clockwise;
    /// Ring: inner, outer), stepped `inward` cells into the grid.
    fn side_slot(&self, side: usize, k: usize, inward: usize) -> (isize, isize) {
        let (nu, nv) = (self.patch.nu as isize, self.patch.nv as isize);
        let (k, b) = (k as isize, inward as isize);
        if self.sides == 2 {
            return if side == 0 { (k, b) } else { (k, nv - 1 - b) };
        }
        match side {
            0 => (k, b),
            1 => (nu - 1 - b, k),
            2 => (nu - 1 - k, nv - 1 - b),
            _ => (b, nv - 1 - k),
        }
    }

    fn collect_teams(&mut self, sides: &[Vec<ResolvedTeam>]) {
        for (s, side) in sides.iter().enumerate() {
            let mut offset = 0;
            for t in side {
                let nodes = (offset..=offset + t.cells)
                    .map(|k| {
                        let (i, j) = self.side_slot(s, k, 0);
                        self.patch.node(i, j).expect("full patch")
                    })
                    .collect();
                self.teams.push((t.name.clone(), nodes));
                offset += t.cells;
            }
        }
    }

    fn dart(&mut self, sides: &[Vec<ResolvedTeam>], d: &DartSpec) -> Result<(), InvalidValue> {
        let (side, team, offset) = find_team(sides, &d.opening).expect("checked at parse");
        let width = sides[side][team].cells;
        let legs = d.cells;
        let apex = [d.apex.0 * CM, d.apex.1 * CM];
        let slot = |b: &Self, a: usize, t: usize| -> usize {
            let (i, j) = b.side_slot(side, a, t);
            b.patch.slot(i, j).expect("inside the grid")
        };
        // Every slot of the wedge must still be plain (no other dart there).
        for a in offset..=offset + width {
            for t in 0..=legs {
                let s = slot(self, a, t);
                let n = self.patch.node_of[s];
                let plain = n != NO_NODE && (t == 0 || !self.patch.fixed[n as usize]);
                if !plain {
                    return Err(InvalidValue::new(
                        ErrorKind::Inconsistent,
                        "",
                        format!("dart `{}` overlaps another constraint", d.name),
                    ));
                }
            }
        }
        let ends = [offset, offset + width]
            .map(|a| self.patch.positions[self.patch.node_of[slot(self, a, 0)] as usize]);
        let apex_node = self.patch.node_of[slot(self, offset, legs)];
        let mut pairs = Vec::with_capacity(legs);
        for t in 0..=legs {
            let f = t as f64 / legs as f64;
            for (end, a) in ends.iter().zip([offset, offset + width]) {
                let n = self.patch.node_of[slot(self, a, t)];
                self.patch.positions[n as usize] = [
                    end[0] + f * (apex[0] - end[0]),
                    end[1] + f * (apex[1] - end[1]),
                ];
                self.patch.fixed[n as usize] = true;
            }
            if t < legs {
                pairs.push((
                    self.patch.node_of[slot(self, offset, t)],
                    self.patch.node_of[slot(self, offset + width, t)],
                ));
            }
        }
        // Cut the wedge's cells: the cell between local (a, t) and (a + 1, t + 1).
        for a in offset..offset + width {
            for t in 0..legs {
                let corners = [(a, t), (a + 1, t + 1)].map(|(a, t)| self.side_slot(side, a, t));
                let (i, j) = (
                    corners[0].0.min(corners[1].0),
                    corners[0].1.min(corners[1].1),
                );
                let s = self.patch.slot(i, j).expect("inside the grid");
                self.patch.cut[s] = true;
            }
        }
        for a in offset..=offset + width {
            let s = slot(self, a, legs);
            self.patch.node_of[s] = apex_node;
            for t in 0..legs {
                if a > offset && a < offset + width {
                    let s = slot(self, a, t);
                    self.patch.node_of[s] = NO_NODE;
                }
            }
        }
        self.patch.positions[apex_node as usize] = apex;
        self.patch.fixed[apex_node as usize] = true;
        // The opening team keeps only its two ends.
        if let Some((_, nodes)) = self.teams.iter_mut().find(|(n, _)| *n == d.opening) {
            let (first, last) = (nodes[0], nodes[nodes.len() - 1]);
            *nodes = vec![first, last];
        }
        self.darts.push((d.name.clone(), pairs));
        Ok(())
    }

    /// Rearrange the free nodes near moved constraint nodes (pleat lines, fixed points)
    /// smoothly (thesis §4.4.3; dart legs take the place of their own grid columns and need
    /// no rearranging): Jacobi steps towards the mean of the 4-neighbourhood
    /// for every free node within two grid steps of a constrained interior node.
    fn relax_constrained(&mut self) {
        if self.moved.is_empty() {
            return;
        }
        let p = &self.patch;
        let mut near = vec![false; p.node_count()];
        let mut frontier: Vec<u32> = self.moved.clone();
        for _ in 0..2 {
            let mut next = Vec::new();
            for s in 0..p.node_of.len() {
                let Some((n, nb)) = p.neighbourhood(s) else {
                    continue;
                };
                if frontier.contains(&n) {
                    for m in nb.into_iter().flatten() {
                        if !p.fixed[m as usize] && !near[m as usize] {
                            near[m as usize] = true;
                            next.push(m);
                        }
                    }
                }
            }
            frontier = next;
        }
        for _ in 0..50 {
            let mut sum = vec![([0.0; 2], 0usize); self.patch.node_count()];
            for s in 0..self.patch.node_of.len() {
                let Some((n, nb)) = self.patch.neighbourhood(s) else {
                    continue;
                };
                if near[n as usize] {
                    for m in nb.into_iter().flatten() {
                        let q = self.patch.positions[m as usize];
                        let e = &mut sum[n as usize];
                        e.0[0] += q[0];
                        e.0[1] += q[1];
                        e.1 += 1;
                    }
                }
            }
            for (n, (acc, count)) in sum.into_iter().enumerate() {
                if near[n] && count > 0 {
                    self.patch.positions[n] = [acc[0] / count as f64, acc[1] / count as f64];
                }
            }
        }
    }

    /// The free node nearest to `p`, with its slot coordinates.
    fn nearest_free(&self, p: [f64; 2]) -> Option<(u32, isize, isize)> {
        let mut best: Option<(f64, u32, isize, isize)> = None;
        for (s, &n) in self.patch.node_of.iter().enumerate() {
            if n == NO_NODE || self.patch.fixed[n as usize] {
                continue;
            }
            let q = self.patch.positions[n as usize];
            let d = (q[0] - p[0]).hypot(q[1] - p[1]);
            if best.is_none_or(|b| d < b.0) {
                best = Some((
                    d,
                    n,
                    (s % self.patch.nu) as isize,
                    (s / self.patch.nu) as isize,
                ));
            }
        }
        best.map(|(_, n, i, j)| (n, i, j))
    }

    fn pleat(&mut self, from: [f64; 2], to: [f64; 2]) -> Result<(), InvalidValue> {
        let none = || {
            InvalidValue::new(
                ErrorKind::Inconsistent,
                "",
                "no free node near the pleat line",
            )
        };
        let (_, i0, j0) = self.nearest_free(from).ok_or_else(none)?;
        let (_, i1, j1) = self.nearest_free(to).ok_or_else(none)?;
        // Along whichever axis the line runs more; the grid line through the middle.
        let (along_v, fixed_index, range) = if (j1 - j0).abs() >= (i1 - i0).abs() {
            (true, (i0 + i1) / 2, (j0, j1))
        } else {
            (false, (j0 + j1) / 2, (i0, i1))
        };
        let (lo, hi) = (range.0.min(range.1), range.0.max(range.1));
        if hi == lo {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                "",
                "the pleat line is shorter than one grid cell",
            ));
        }
        let forward = range.1 >= range.0;
        for k in lo..=hi {
            let (i, j) = if along_v {
                (fixed_index, k)
            } else {
                (k, fixed_index)
            };
            let Some(n) = self.patch.node(i, j) else {
                continue;
            };
            if self.patch.fixed[n as usize] {
                continue;
            }
            let f = (k - lo) as f64 / (hi - lo) as f64;
            let f = if forward { f } else { 1.0 - f };
            self.patch.positions[n as usize] = [
                from[0] + f * (to[0] - from[0]),
                from[1] + f * (to[1] - from[1]),
            ];
            self.patch.fixed[n as usize] = true;
            self.moved.push(n);
        }
        Ok(())
    }

    fn fix_point(&mut self, p: [f64; 2]) -> Result<(), InvalidValue> {
        let (n, _, _) = self
            .nearest_free(p)
            .ok_or_else(|| InvalidValue::new(ErrorKind::Inconsistent, "", "no free node to fix"))?;
        self.patch.positions[n as usize] = p;
        self.patch.fixed[n as usize] = true;
        self.moved.push(n);
        Ok(())
    }
}

/// The warp's angle from the pattern x axis for a grain line, rad (for callers drawing it).
pub fn grain_angle(spec: &PatternSpec) -> f64 {
    let (a, b) = spec.grain;
    (b.1 - a.1).atan2(b.0 - a.0).rem_euclid(2.0 * PI)
}
