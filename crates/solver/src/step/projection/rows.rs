//! The shape problem's rows: seam groups found, rows (edges, cells, ties, planes) built and
//! their multipliers reset once per step.

use super::{EASE_THRESHOLD, RowKind, ShapeProblem, ShapeSolver, Structure, V3};
use crate::cloth::Cloth;
use crate::dual::{DualError, DualSystem, NONE, NodeWeight, SLOTS};

pub(super) fn find(root: &mut [u32], mut i: u32) -> u32 {
    while root[i as usize] != i {
        let up = root[root[i as usize] as usize];
        root[i as usize] = up;
        i = up;
    }
    i
}

impl ShapeSolver {
    /// Group the nodes tied at length 0, list the open ties, (re)build the rows when they changed,
    /// and reset the multipliers (XPBD: once per step).
    pub(super) fn prepare(&mut self, p: &ShapeProblem<'_>) -> Result<(), DualError> {
        let cloth = p.cloth;
        let topo = cloth.topology();
        let n = topo.node_count();
        if self.spacing.len() != n {
            let mut sum = vec![0.0; n];
            let mut count = vec![0.0; n];
            for e in topo.edges().iter().filter(|e| e.kind.is_axial()) {
                for k in [e.a, e.b] {
                    sum[k as usize] += e.rest_length;
                    count[k as usize] += 1.0;
                }
            }
            let mean = sum.iter().sum::<f64>() / count.iter().sum::<f64>().max(1.0);
            self.spacing = sum
                .iter()
                .zip(&count)
                .map(|(s, c)| if *c > 0.0 { s / c } else { mean })
                .collect();
        }
        // Groups: union-find over the sewn ties; the smallest node of a group is its root.
        self.root.clear();
        self.root.extend(0..n as u32);
        for t in p.ties.iter().filter(|t| t.length == 0.0) {
            let (a, b) = (find(&mut self.root, t.a), find(&mut self.root, t.b));
            if a != b {
                let (lo, hi) = (a.min(b), a.max(b));
                self.root[hi as usize] = lo;
            }
        }
        for i in 0..n as u32 {
            let r = find(&mut self.root, i);
            self.root[i as usize] = r;
        }
        // Members of each root (CSR).
        self.member_ptr.clear();
        self.member_ptr.resize(n + 1, 0);
        for &r in &self.root {
            self.member_ptr[r as usize + 1] += 1;
        }
        for i in 0..n {
            self.member_ptr[i + 1] += self.member_ptr[i];
        }
        self.members.clear();
        self.members.resize(n, 0);
        let mut fill = self.member_ptr.clone();
        for (i, &r) in self.root.iter().enumerate() {
            self.members[fill[r as usize] as usize] = i as u32;
            fill[r as usize] += 1;
        }
        self.open_ties.clear();
        self.open_tie_index.clear();
        for (k, t) in p.ties.iter().enumerate() {
            if t.length > 0.0 {
                let (a, b) = (self.root[t.a as usize], self.root[t.b as usize]);
                if a != b {
                    self.open_ties.push((a, b));
                    self.open_tie_index.push(k as u32);
                }
            }
        }
        let with_cells = !p.shear.is_empty();
        let with_bends = !p.bends.is_empty();
        let same = self.structure.as_ref().is_some_and(|s| {
            s.root == self.root
                && s.open_ties == self.open_ties
                && s.with_cells == with_cells
                && s.with_bends == with_bends
        });
        if !same {
            self.structure = Some(self.build(cloth, with_cells, with_bends)?);
            self.analyses += 1;
        }
        let st = self.structure.as_mut().expect("built");
        // Node weights: a group moves with its summed mass; a group with a pinned node does not
        // move at all.
        let (inv, mass, area) = (cloth.inverse_masses(), cloth.masses(), topo.node_areas());
        let damp = p.damping * p.dt;
        for w in st.system.weight.iter_mut() {
            *w = NodeWeight::default();
        }
        for r in 0..n {
            let list = &self.members[self.member_ptr[r] as usize..self.member_ptr[r + 1] as usize];
            if list.is_empty() {
                continue;
            }
            let pinned = list.iter().any(|&k| inv[k as usize] == 0.0);
            let m: f64 = list
                .iter()
                .map(|&k| mass[k as usize] + damp * area[k as usize])
                .sum();
            st.system.weight[r].w = if pinned || m <= 0.0 { 0.0 } else { 1.0 / m };
        }
        // A row none of whose nodes can move cannot act (an edge between two pins: its length
        // is the pins' business, not the solve's).
        for r in 0..st.kinds.len() {
            let weight = &st.system.weight;
            st.dead[r] = st.collapsed[r]
                || st.row_nodes[r]
                    .iter()
                    .filter(|&&k| k != NONE)
                    .all(|&k| weight[k as usize].w == 0.0);
        }
        let rows = st.kinds.len();
        self.on_plane.clear();
        self.stuck.clear();
        // The multipliers start at zero every step (XPBD); a warm start from the last step's
        // forces was tried and measured: it saved no iterations on the drape (6.2 per step
        // either way) and cost them on cotton (10 against 6.1).
        self.lambda.clear();
        self.lambda.resize(rows, 0.0);
        for v in [
            &mut self.c,
            &mut self.viol,
            &mut self.b,
            &mut self.dl,
            &mut self.diag,
            &mut self.lambda_prev,
            &mut self.lambda_hat,
        ] {
            v.clear();
            v.resize(rows, 0.0);
        }
        for v in [
            &mut self.pred,
            &mut self.prev,
            &mut self.hat,
            &mut self.saved_vel,
            &mut self.base,
            &mut self.shift,
        ] {
            v.clear();
            v.resize(n, V3::zeros());
        }
        Ok(())
    }

    pub(super) fn build(
        &self,
        cloth: &Cloth,
        with_cells: bool,
        with_bends: bool,
    ) -> Result<Structure, DualError> {
        let topo = cloth.topology();
        let n = topo.node_count();
        let root = &self.root;
        let mut kinds = Vec::new();
        let mut rows: Vec<[u32; SLOTS]> = Vec::new();
        let mut corner_slot = Vec::new();
        let mut dead = Vec::new();
        let mut push = |kind: RowKind, corners: &[u32]| {
            let mut nodes = [NONE; SLOTS];
            let mut slot = [u8::MAX; 4];
            let mut len = 0;
            for (k, &c) in corners.iter().enumerate() {
                let r = root[c as usize];
                let s = match nodes[..len].iter().position(|&x| x == r) {
                    Some(s) => s,
                    None => {
                        nodes[len] = r;
                        len += 1;
                        len - 1
                    }
                };
                slot[k] = s as u8;
            }
            kinds.push(kind);
            rows.push(nodes);
            corner_slot.push(slot);
            dead.push(len < 2);
        };
        for (e, edge) in topo.edges().iter().enumerate() {
            if edge.kind.is_axial() {
                push(RowKind::Edge(e as u32), &[edge.a, edge.b]);
            }
        }
        if with_cells {
            for (c, cell) in topo.cells().iter().enumerate() {
                push(RowKind::Cell(c as u32), &cell.nodes);
            }
        }
        for (k, &(a, b)) in self.open_ties.iter().enumerate() {
            push(RowKind::Tie(k as u32), &[a, b]);
        }
        if with_bends {
            let axial = cloth.bending_neighbours();
            for (i, slots) in axial.iter().enumerate() {
                for dir in 0..2u8 {
                    // Slots: +u, −u, +v, −v.
                    let (after, before) = (slots[2 * dir as usize], slots[2 * dir as usize + 1]);
                    if after != atelier_grid::NO_NODE && before != atelier_grid::NO_NODE {
                        push(
                            RowKind::Bend(i as u32, dir, [before, after]),
                            &[before, i as u32, after],
                        );
                    }
                }
            }
        }
        let system = DualSystem::new(n, &rows)?;
        let tied: std::collections::HashSet<(u32, u32)> = self
            .open_ties
            .iter()
            .map(|&(a, b)| (a.min(b), a.max(b)))
            .collect();
        let edges = topo.edges();
        let mut gathered: Vec<bool> = kinds
            .iter()
            .map(|k| match k {
                RowKind::Edge(e) => {
                    let edge = &edges[*e as usize];
                    let (a, b) = (root[edge.a as usize], root[edge.b as usize]);
                    tied.contains(&(a.min(b), a.max(b)))
                }
                _ => false,
            })
            .collect();
        // Eased seams: edges that join the same two points of the garment once every seam is
        // closed (the two sides' edges along a seam) are one seam line, whose length the
        // shorter side sets; the longer ones gather (stretch-only), as a sewing machine eases
        // the longer side in. Held at their own lengths, two edges of different rest lengths
        // between the same points contradict each other: a sleeve cap 1.7 cm longer than its
        // armhole never closed, and the edge along it was torn to 108 % strain.
        let mut seam = root.clone();
        for &(a, b) in &self.open_ties {
            let (ra, rb) = (find(&mut seam, a), find(&mut seam, b));
            if ra != rb {
                seam[ra.max(rb) as usize] = ra.min(rb);
            }
        }
        let mut shortest: std::collections::HashMap<(u32, u32), f64> =
            std::collections::HashMap::new();
        let seam_pair = |seam: &mut [u32], e: &atelier_grid::Edge| {
            let (a, b) = (find(seam, e.a), find(seam, e.b));
            (a.min(b), a.max(b))
        };
        let mut pair_of = vec![(NONE, NONE); kinds.len()];
        let mut count_of: std::collections::HashMap<(u32, u32), u32> =
            std::collections::HashMap::new();
        for (r, k) in kinds.iter().enumerate() {
            if let RowKind::Edge(e) = k {
                let edge = &edges[*e as usize];
                let key = seam_pair(&mut seam, edge);
                pair_of[r] = key;
                *count_of.entry(key).or_insert(0) += 1;
                let l = shortest.entry(key).or_insert(f64::INFINITY);
                *l = l.min(edge.rest_length);
            }
        }
        for (r, k) in kinds.iter().enumerate() {
            if let RowKind::Edge(e) = k {
                let key = pair_of[r];
                if count_of[&key] > 1
                    && edges[*e as usize].rest_length > shortest[&key] * (1.0 + EASE_THRESHOLD)
                {
                    gathered[r] = true;
                }
            }
        }
        // Twins already joined at both ends (a sewn seam's two sides) are the same row twice
        // (the same two nodes, the same gradient): with rest lengths even 1e-4 apart they ask
        // for two lengths at once, and the Newton step stalled at that difference (skirt: 2e-4
        // against the 1e-4 tolerance, 200 iterations). One row stands for them: the shortest
        // (which sets the seam line's length, as for eased seams), with the widths of the
        // twins that are not gathered added to its own (parallel edges carry the seam line's
        // tension together); the others retire.
        let widths = cloth.edge_widths();
        let mut width_scale = vec![1.0; kinds.len()];
        let mut twin_of = vec![NONE; kinds.len()];
        let mut by_ends: std::collections::HashMap<(u32, u32), Vec<usize>> =
            std::collections::HashMap::new();
        for (r, k) in kinds.iter().enumerate() {
            if matches!(k, RowKind::Edge(_)) && !dead[r] {
                let (a, b) = (rows[r][0], rows[r][1]);
                by_ends.entry((a.min(b), a.max(b))).or_default().push(r);
            }
        }
        let edge_of = |r: usize| match kinds[r] {
            RowKind::Edge(e) => e as usize,
            _ => unreachable!("edge rows only"),
        };
        for twins in by_ends.values().filter(|t| t.len() > 1) {
            let keep = *twins
                .iter()
                .min_by(|&&x, &&y| {
                    edges[edge_of(x)]
                        .rest_length
                        .total_cmp(&edges[edge_of(y)].rest_length)
                        .then(x.cmp(&y))
                })
                .expect("two or more");
            for &r in twins.iter().filter(|&&r| r != keep) {
                dead[r] = true;
                twin_of[r] = keep as u32;
                if !gathered[r] {
                    width_scale[keep] += widths[edge_of(r)] / widths[edge_of(keep)];
                }
            }
        }
        let force_share: Vec<f64> = (0..kinds.len())
            .map(|r| match (kinds[r], twin_of[r]) {
                (RowKind::Edge(_), NONE) => 1.0 / width_scale[r],
                (RowKind::Edge(e), k) if !gathered[r] => {
                    let k = k as usize;
                    widths[e as usize] / (widths[edge_of(k)] * width_scale[k])
                }
                _ => 0.0,
            })
            .collect();
        // Row counts per node for the Jacobi scaling.
        let mut count = vec![0u32; n];
        for (r, nodes) in rows.iter().enumerate() {
            if !dead[r] {
                for &k in nodes.iter().filter(|&&k| k != NONE) {
                    count[k as usize] += 1;
                }
            }
        }
        let local_scale: Vec<f64> = rows
            .iter()
            .map(|nodes| {
                let m = nodes
                    .iter()
                    .filter(|&&k| k != NONE)
                    .map(|&k| count[k as usize])
                    .max()
                    .unwrap_or(1)
                    .max(1);
                1.0 / f64::from(m)
            })
            .collect();
        Ok(Structure {
            system,
            kinds,
            corner_slot,
            row_nodes: rows,
            collapsed: dead.clone(),
            gathered,
            width_scale,
            twin_of,
            force_share,
            dead,
            local_scale,
            colours: Vec::new(),
            root: self.root.clone(),
            open_ties: self.open_ties.clone(),
            with_cells,
            with_bends,
            kkt: None,
        })
    }
}
