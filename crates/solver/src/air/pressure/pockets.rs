//! Separate pockets of air (the pocket model): the lifted triangles grouped into connected
//! pockets, each carrying its air over from the last evaluation, and their pressures.

use super::{Bubble, NONE, PressureModel};

impl PressureModel {
    /// Find the pockets (connected lifted triangles), carry their air over from the last
    /// evaluation, and set their pressures.
    pub(super) fn pockets(
        &mut self,
        triangles: &[[u32; 3]],
        node_area: &[f64],
        boundary: &[bool],
        contact: f64,
        dt: f64,
    ) {
        let n = self.height.len();
        let pa = self.params.atmosphere;
        let lifted_node: Vec<bool> = self.height.iter().map(|&h| h > contact).collect();
        // Union–find over nodes through lifted triangles.
        let mut parent: Vec<u32> = (0..n as u32).collect();
        fn root(parent: &mut [u32], mut x: u32) -> u32 {
            while parent[x as usize] != x {
                parent[x as usize] = parent[parent[x as usize] as usize];
                x = parent[x as usize];
            }
            x
        }
        let lifted_tri: Vec<bool> = triangles
            .iter()
            .map(|t| t.iter().any(|&k| lifted_node[k as usize]))
            .collect();
        for (t, &up) in triangles.iter().zip(&lifted_tri) {
            if up {
                let r0 = root(&mut parent, t[0]);
                for &k in &t[1..] {
                    let r = root(&mut parent, k);
                    parent[r as usize] = r0;
                }
            }
        }
        // Components: index per root, over the nodes of lifted triangles.
        let mut in_pocket = vec![false; n];
        for (t, &up) in triangles.iter().zip(&lifted_tri) {
            if up {
                for &k in t {
                    in_pocket[k as usize] = true;
                }
            }
        }
        let mut id_of_root = vec![NONE; n];
        let mut pockets: Vec<Bubble> = Vec::new();
        let mut label = vec![NONE; n];
        for i in 0..n {
            if !in_pocket[i] {
                continue;
            }
            let r = root(&mut parent, i as u32) as usize;
            if id_of_root[r] == NONE {
                id_of_root[r] = pockets.len() as u32;
                pockets.push(Bubble {
                    air: 0.0,
                    volume: 0.0,
                    pressure: pa,
                    area: 0.0,
                    vented: false,
                    nodes: Vec::new(),
                });
            }
            let id = id_of_root[r];
            label[i] = id;
            pockets[id as usize].nodes.push(i as u32);
            if lifted_node[i] {
                pockets[id as usize].area += node_area[i];
            }
            // Open to the edge: a lifted node on the cloth's boundary.
            if boundary.get(i).copied().unwrap_or(false) && lifted_node[i] {
                pockets[id as usize].vented = true;
            }
        }
        // A pocket's volume: its lifted triangles, and the ring of triangles around them (a node
        // in the pocket, none lifted), whose small volume then grows continuously into the
        // pocket's as the pocket spreads instead of joining it in one jump.
        self.tri_bubble.clear();
        for (k, (t, &up)) in triangles.iter().zip(&lifted_tri).enumerate() {
            let id = if up {
                label[t[0] as usize]
            } else {
                t.iter()
                    .map(|&i| label[i as usize])
                    .find(|&l| l != NONE)
                    .unwrap_or(NONE)
            };
            if id != NONE {
                pockets[id as usize].volume += self.tri_volume[k];
            }
            self.tri_bubble.push(id);
        }
        // Carry the air over: each new pocket takes, from every old pocket it shares nodes
        // with, the old pocket's air in proportion to the new pockets' volumes among those the
        // old one overlaps.
        if !self.started {
            let total: f64 = pockets.iter().map(|p| p.volume.max(0.0)).sum();
            for p in &mut pockets {
                p.air = if total > 0.0 {
                    pa * self.params.air * p.volume.max(0.0) / total
                } else {
                    0.0
                };
            }
            self.started = true;
        } else if !self.label.is_empty() {
            let old = std::mem::take(&mut self.bubbles);
            // overlap[o] = new pockets sharing nodes with old pocket o.
            let mut overlap: Vec<Vec<usize>> = vec![Vec::new(); old.len()];
            for (new_id, p) in pockets.iter().enumerate() {
                for &k in &p.nodes {
                    let o = self.label[k as usize];
                    if o != NONE && !overlap[o as usize].contains(&new_id) {
                        overlap[o as usize].push(new_id);
                    }
                }
            }
            for (o, news) in overlap.iter().enumerate() {
                let total: f64 = news.iter().map(|&k| pockets[k].volume.max(0.0)).sum();
                for &k in news {
                    let share = if total > 0.0 {
                        pockets[k].volume.max(0.0) / total
                    } else {
                        1.0 / news.len() as f64
                    };
                    pockets[k].air += old[o].air * share;
                }
            }
        }
        for p in &mut pockets {
            if p.vented {
                p.air = pa * p.volume.max(0.0);
                p.pressure = pa;
                continue;
            }
            let floor = self.params.min_volume_fraction * p.air / pa;
            let boyle = if p.air > 0.0 {
                p.air / p.volume.max(floor).max(f64::MIN_POSITIVE)
            } else {
                0.0
            };
            (p.pressure, p.air) = self.admit(boyle, p.air, p.volume);
            p.air += dt * pa * self.params.leak * p.area * (pa - p.pressure);
            p.air = p.air.max(0.0);
        }
        self.label = label;
        self.bubbles = pockets;
    }
}
