//! The local iterations the thesis uses, kept as options: Jacobi and Gauss–Seidel by colour
//! (with the greedy colouring of the rows).

use super::{ShapeProblem, ShapeSolver, V3};
use crate::dual::{DualSystem, NONE, SLOTS};

impl ShapeSolver {
    /// Δλ_r = s_r b_r / D_r (the local scaling of the Jacobi methods).
    pub(super) fn jacobi(&mut self, step: f64) {
        let st = self.structure.as_ref().expect("prepared");
        st.system.diagonal(&mut self.diag);
        for r in 0..self.dl.len() {
            self.dl[r] = if self.diag[r] > 0.0 {
                step * st.local_scale[r] * self.b[r] / self.diag[r]
            } else {
                0.0
            };
        }
    }

    /// One sweep of nonlinear Gauss–Seidel over the row colours: each row of a colour solved
    /// exactly at the current positions (over-relaxed by ω), colour after colour.
    pub(super) fn gauss_seidel(&mut self, p: &ShapeProblem<'_>, vel: &mut [V3], omega: f64) {
        {
            let st = self.structure.as_mut().expect("prepared");
            if st.colours.is_empty() {
                st.colours = colour_rows(&st.system, st.kinds.len());
            }
        }
        let colours = self.structure.as_ref().expect("prepared").colours.len();
        for colour in 0..colours {
            // Rows were evaluated before this sweep for the first colour; re-evaluate after.
            if colour > 0 {
                self.evaluate(p, vel);
            }
            let st = self.structure.as_ref().expect("prepared");
            st.system.diagonal(&mut self.diag);
            self.dl.iter_mut().for_each(|d| *d = 0.0);
            for &r in &st.colours[colour] {
                let r = r as usize;
                if self.diag[r] > 0.0 {
                    self.dl[r] = omega * self.b[r] / self.diag[r];
                }
            }
            self.apply(p, vel, 1.0, false, false);
        }
    }
}

/// Greedy colouring of rows so that no two rows of a colour share a node.
pub(super) fn colour_rows(system: &DualSystem, rows: usize) -> Vec<Vec<u32>> {
    let mut colours: Vec<Vec<u32>> = Vec::new();
    let mut used: Vec<Vec<bool>> = Vec::new();
    let n = system.nodes();
    for r in 0..rows {
        let nodes: Vec<usize> = (SLOTS * r..SLOTS * (r + 1))
            .map(|s| system.slot_node(s))
            .filter(|&k| k != NONE)
            .map(|k| k as usize)
            .collect();
        let c = (0..colours.len())
            .find(|&c| nodes.iter().all(|&k| !used[c][k]))
            .unwrap_or_else(|| {
                colours.push(Vec::new());
                used.push(vec![false; n]);
                colours.len() - 1
            });
        for &k in &nodes {
            used[c][k] = true;
        }
        colours[c].push(r as u32);
    }
    colours
}
