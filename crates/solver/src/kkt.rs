//! The shape stage's full Newton system (`method.md` §2b): the saddle-point (KKT) form of one
//! iteration, with the geometric stiffness of the rows in tension.
//!
//! [`crate::dual`] solves the constraint-space system `(J W Jᵀ + Ã) Δλ = b`, which is Newton's
//! method with the Hessian of the Lagrangian replaced by the mass matrix (Gauss–Newton). Under
//! tension the dropped term `−Σ λ_r ∇²C_r` is what turns a taut edge's sideways motion into a
//! restoring force; without it the iteration converges only linearly (a hanging sheet: 20
//! iterations with 17 halvings at 1e-8) and, on a garment drawn together by its seams, not at
//! all. Here the iteration solves
//!
//! ```text
//!     [ K   Jᵀ ] [  Δx ]   [ M·s ]        K = M + Σ_{r in tension} |λ_r| ∇²C_r  (≽ M),
//!     [ J  −Ã  ] [ −Δλ ] = [  b₀ ]
//! ```
//!
//! s the move back to the implicit-Euler balance, b₀ = −(C + Ãλ). Only the rows whose Hessian
//! term is positive semi-definite contribute to K: edges and seam ties in tension, whose
//! `∇²C = (I − nnᵀ)/l` per node pair (cells and bending rows keep Gauss–Newton), so K stays
//! positive definite and the matrix quasi-definite: faer's LDLᵀ with signed dynamic
//! regularisation factorizes it in any symmetric (AMD) ordering without pivoting. A node held on
//! its contact plane gets a stiffness along the normal 10⁸ times its mass (the plane restriction
//! of [`crate::dual::NodeWeight`]); a node that does not move (pinned) has no columns in J.
//!
//! The system is scaled symmetrically before factorizing — node unknowns by √w, rows by
//! 1/√(Σ w|g|² + α̃) — so that both blocks have unit-size pivots whatever the masses and
//! stiffnesses.

use std::collections::HashMap;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::{LdltParams, LdltRegularization};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LdltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side, Spec};
use nalgebra::Vector3;

use crate::dual::{DualError, NONE, NodeWeight, SLOTS};

type V3 = Vector3<f64>;

/// Stiffness of a contact plane's normal over the node's mass.
const PLANE_STIFFNESS: f64 = 1e8;

/// Lower-triangle positions of a 3×3 diagonal block, (a, b) with a ≥ b.
const LOWER: [(usize, usize); 6] = [(0, 0), (1, 0), (1, 1), (2, 0), (2, 1), (2, 2)];

/// What the caller supplies for one assembly: the rows' gradients per slot (as in
/// [`crate::dual::DualSystem`]), their compliances, the nodes' weights, and for each row with a
/// Hessian term its tension over length `|λ|/l` (0 for none) — the row's direction is its second
/// slot's gradient.
pub struct KktValues<'a> {
    /// Gradient per slot.
    pub grad: &'a [V3],
    /// Diagonal addition per row (compliance over Δt², or 1 for a switched-off row).
    pub extra: &'a [f64],
    /// Weight per node.
    pub weight: &'a [NodeWeight],
    /// Geometric stiffness coefficient per row (|λ|/l of a row in tension, else 0).
    pub tension_over_length: &'a [f64],
}

/// Structure, scaling and factorization of the KKT system of one set of rows.
pub struct KktSystem {
    nodes: usize,
    rows: usize,
    slot_node: Vec<u32>,
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    factor: Vec<f64>,
    mem: MemBuffer,
    signs: Vec<i8>,
    /// Value index of each node's diagonal block, lower entries in [`LOWER`] order.
    node_diag: Vec<[usize; 6]>,
    /// For rows with a Hessian term: the value indices of the off-diagonal block between its
    /// two nodes, `(3·hi + a, 3·lo + b)` at `3a + b`, and whether hi is the second slot's node.
    pair: Vec<Option<([usize; 9], bool)>>,
    /// Value indices of each slot's three Jacobian entries.
    slot_j: Vec<[usize; 3]>,
    row_diag: Vec<usize>,
    /// The scaling: √w per node, 1/√(Σ w|g|² + α̃) per row.
    node_scale: Vec<f64>,
    row_scale: Vec<f64>,
    rhs: Vec<f64>,
}

impl KktSystem {
    /// The system of `rows` (each up to [`SLOTS`] distinct nodes, unused slots [`NONE`]) over
    /// `nodes` nodes; `paired[r]` marks the two-node rows that may carry a Hessian term.
    pub fn new(nodes: usize, rows: &[[u32; SLOTS]], paired: &[bool]) -> Result<Self, DualError> {
        let m = rows.len();
        let n3 = 3 * nodes;
        let dim = n3 + m;
        for (r, list) in rows.iter().enumerate() {
            for &k in list {
                if k != NONE && k as usize >= nodes {
                    return Err(DualError::NoSuchNode {
                        row: r,
                        node: k as usize,
                        nodes,
                    });
                }
            }
        }
        // Every entry (row ≥ col) of the lower triangle, then its CSC position.
        let mut entries: Vec<(usize, usize)> = Vec::new();
        for i in 0..nodes {
            for (a, b) in LOWER {
                entries.push((3 * i + a, 3 * i + b));
            }
        }
        for (r, list) in rows.iter().enumerate() {
            if paired[r] && list[0] != NONE && list[1] != NONE {
                let (lo, hi) = (list[0].min(list[1]) as usize, list[0].max(list[1]) as usize);
                for a in 0..3 {
                    for b in 0..3 {
                        entries.push((3 * hi + a, 3 * lo + b));
                    }
                }
            }
            for &k in list.iter().filter(|&&k| k != NONE) {
                for c in 0..3 {
                    entries.push((n3 + r, 3 * k as usize + c));
                }
            }
            entries.push((n3 + r, n3 + r));
        }
        entries.sort_unstable_by_key(|&(row, col)| (col, row));
        entries.dedup();
        let mut col_ptr = vec![0usize; dim + 1];
        let mut row_idx = Vec::with_capacity(entries.len());
        let mut index = HashMap::with_capacity(entries.len());
        for (k, &(row, col)) in entries.iter().enumerate() {
            col_ptr[col + 1] += 1;
            row_idx.push(row);
            index.insert((row, col), k);
        }
        for c in 0..dim {
            col_ptr[c + 1] += col_ptr[c];
        }
        let at = |row: usize, col: usize| index[&(row, col)];
        let node_diag = (0..nodes)
            .map(|i| LOWER.map(|(a, b)| at(3 * i + a, 3 * i + b)))
            .collect();
        let mut pair = Vec::with_capacity(m);
        let mut slot_j = Vec::with_capacity(SLOTS * m);
        let mut row_diag = Vec::with_capacity(m);
        for (r, list) in rows.iter().enumerate() {
            pair.push(if paired[r] && list[0] != NONE && list[1] != NONE {
                let (lo, hi) = (list[0].min(list[1]) as usize, list[0].max(list[1]) as usize);
                let mut block = [0usize; 9];
                for a in 0..3 {
                    for b in 0..3 {
                        block[3 * a + b] = at(3 * hi + a, 3 * lo + b);
                    }
                }
                Some((block, list[1] as usize == hi))
            } else {
                None
            });
            for &k in list {
                slot_j.push(if k == NONE {
                    [usize::MAX; 3]
                } else {
                    [0, 1, 2].map(|c| at(n3 + r, 3 * k as usize + c))
                });
            }
            row_diag.push(at(n3 + r, n3 + r));
        }
        let nnz = row_idx.len();
        let pattern = SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| DualError::Symbolic(format!("{e:?}")))?;
        let mem = MemBuffer::new(StackReq::any_of(&[
            symbolic.factorize_numeric_ldlt_scratch::<f64>(
                Par::Seq,
                Spec::<LdltParams, f64>::default(),
            ),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]));
        let mut signs = vec![1i8; n3];
        signs.resize(dim, -1);
        Ok(Self {
            nodes,
            rows: m,
            slot_node: rows.iter().flatten().copied().collect(),
            pattern,
            factor: vec![0.0; symbolic.len_val()],
            symbolic,
            values: vec![0.0; nnz],
            mem,
            signs,
            node_diag,
            pair,
            slot_j,
            row_diag,
            node_scale: vec![0.0; nodes],
            row_scale: vec![0.0; m],
            rhs: vec![0.0; dim],
        })
    }

    /// Non-zeros of the lower triangle and of the factor.
    pub fn sizes(&self) -> (usize, usize) {
        (self.values.len(), self.factor.len())
    }

    /// Assemble the scaled matrix from `v` and factorize it.
    pub fn factorize(&mut self, v: &KktValues<'_>) -> Result<(), DualError> {
        let (nodes, rows) = (self.nodes, self.rows);
        debug_assert_eq!(v.extra.len(), rows);
        self.values.iter_mut().for_each(|x| *x = 0.0);
        for (i, d) in self.node_scale.iter_mut().enumerate() {
            *d = v.weight[i].w.max(0.0).sqrt();
        }
        for r in 0..rows {
            let mut s = v.extra[r];
            for k in SLOTS * r..SLOTS * (r + 1) {
                let node = self.slot_node[k];
                if node != NONE {
                    s += v.weight[node as usize].w * v.grad[k].norm_squared();
                }
            }
            self.row_scale[r] = if s > 0.0 && s.is_finite() {
                1.0 / s.sqrt()
            } else {
                1.0
            };
        }
        // Node blocks: w·M = I (or I for a node that does not move), the plane's normal.
        for i in 0..nodes {
            let w = v.weight[i];
            let plane = if w.w > 0.0 { PLANE_STIFFNESS } else { 0.0 };
            for (k, (a, b)) in LOWER.iter().enumerate() {
                let identity = if a == b { 1.0 } else { 0.0 };
                self.values[self.node_diag[i][k]] = identity + plane * w.n[*a] * w.n[*b];
            }
        }
        // Geometric stiffness of rows in tension: c (I − nnᵀ) on both diagonal blocks, −c on
        // the pair's block, scaled by √w of each side.
        for r in 0..rows {
            let c = v.tension_over_length[r];
            let Some((block, _)) = self.pair[r] else {
                continue;
            };
            // (NaN counts as no tension.)
            if c.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let (na, nb) = (self.slot_node[SLOTS * r], self.slot_node[SLOTS * r + 1]);
            let n = v.grad[SLOTS * r + 1];
            let p = |a: usize, b: usize| c * (if a == b { 1.0 } else { 0.0 } - n[a] * n[b]);
            let (da, db) = (self.node_scale[na as usize], self.node_scale[nb as usize]);
            for (node, d) in [(na, da), (nb, db)] {
                for (k, &(a, b)) in LOWER.iter().enumerate() {
                    self.values[self.node_diag[node as usize][k]] += d * d * p(a, b);
                }
            }
            for a in 0..3 {
                for b in 0..3 {
                    self.values[block[3 * a + b]] -= da * db * p(a, b);
                }
            }
        }
        for r in 0..rows {
            let sr = self.row_scale[r];
            for k in SLOTS * r..SLOTS * (r + 1) {
                let node = self.slot_node[k];
                if node == NONE {
                    continue;
                }
                let d = self.node_scale[node as usize];
                for c in 0..3 {
                    self.values[self.slot_j[k][c]] += sr * d * v.grad[k][c];
                }
            }
            self.values[self.row_diag[r]] = -sr * sr * v.extra[r];
        }
        if !self.values.iter().all(|x| x.is_finite()) {
            return Err(DualError::Singular { row: 0 });
        }
        let reg = LdltRegularization {
            dynamic_regularization_signs: Some(&self.signs),
            dynamic_regularization_delta: 1e-10,
            dynamic_regularization_epsilon: 1e-14,
        };
        let a = SparseColMatRef::new(self.pattern.as_ref(), &self.values);
        let stack = MemStack::new(&mut self.mem);
        let result = self.symbolic.factorize_numeric_ldlt(
            &mut self.factor,
            a,
            Side::Lower,
            reg,
            Par::Seq,
            stack,
            Spec::<LdltParams, f64>::default(),
        );
        let ok = result.is_ok();
        match result.map(|_| ()) {
            Ok(()) if ok && self.factor.iter().all(|x| x.is_finite()) => Ok(()),
            Ok(()) => Err(DualError::Singular { row: 0 }),
            Err(faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index }) => {
                Err(DualError::Singular { row: index })
            }
        }
    }

    /// Solve with the last factorization for the right-hand side `[M·s; b₀]` given as the
    /// nodes' moves `s` (m; their mass from the weights of the last assembly) and the rows'
    /// `b₀`: the nodes' steps into `dx` and the multipliers' into `dl`.
    pub fn solve(
        &mut self,
        weight: &[NodeWeight],
        s: &[V3],
        b0: &[f64],
        dx: &mut [V3],
        dl: &mut [f64],
    ) {
        let n3 = 3 * self.nodes;
        for i in 0..self.nodes {
            // d·(m s) = s/√w.
            let d = self.node_scale[i];
            let f = if weight[i].w > 0.0 { 1.0 / d } else { 0.0 };
            for (c, x) in s[i].iter().enumerate() {
                self.rhs[3 * i + c] = f * x;
            }
        }
        for ((out, scale), b) in self.rhs[n3..].iter_mut().zip(&self.row_scale).zip(b0) {
            *out = scale * b;
        }
        let ldlt = LdltRef::new(&self.symbolic, &self.factor);
        let dim = self.rhs.len();
        let stack = MemStack::new(&mut self.mem);
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut self.rhs, dim, 1),
            Par::Seq,
            stack,
        );
        for (i, x) in dx.iter_mut().enumerate() {
            let d = self.node_scale[i];
            *x = V3::new(self.rhs[3 * i], self.rhs[3 * i + 1], self.rhs[3 * i + 2]) * d;
        }
        for (r, l) in dl.iter_mut().enumerate() {
            *l = -self.row_scale[r] * self.rhs[n3 + r];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// Three nodes, two distance rows (one in tension) and a compliant row over all three,
    /// one node on a plane: the sparse scaled solve against a dense solve of the same KKT
    /// system written out directly.
    #[test]
    fn the_solve_matches_a_dense_kkt_solve() {
        let nodes = 3;
        let rows = [[0, 1, NONE, NONE], [1, 2, NONE, NONE], [0, 1, 2, NONE]];
        let paired = [true, true, false];
        let mut sys = KktSystem::new(nodes, &rows, &paired).unwrap();
        let n01 = V3::new(1.0, 0.2, -0.1).normalize();
        let n12 = V3::new(0.3, -1.0, 0.4).normalize();
        let grad = vec![
            -n01,
            n01,
            V3::zeros(),
            V3::zeros(),
            -n12,
            n12,
            V3::zeros(),
            V3::zeros(),
            V3::new(0.5, 1.0, 0.0),
            V3::new(-1.0, 0.2, 0.3),
            V3::new(0.5, -1.2, -0.3),
            V3::zeros(),
        ];
        let extra = [1e-6, 0.0, 0.4];
        let weight = [
            NodeWeight {
                w: 2.0,
                n: V3::zeros(),
            },
            NodeWeight {
                w: 0.5,
                n: V3::new(0.0, 0.0, 1.0),
            },
            NodeWeight {
                w: 1.0,
                n: V3::zeros(),
            },
        ];
        let tol = [0.0, 3.0, 0.0];
        sys.factorize(&KktValues {
            grad: &grad,
            extra: &extra,
            weight: &weight,
            tension_over_length: &tol,
        })
        .unwrap();
        let s = [
            V3::new(0.1, -0.2, 0.3),
            V3::new(0.05, 0.1, 0.0),
            V3::new(-0.1, 0.0, 0.2),
        ];
        let b0 = [0.01, -0.02, 0.03];
        let mut dx = [V3::zeros(); 3];
        let mut dl = [0.0; 3];
        sys.solve(&weight, &s, &b0, &mut dx, &mut dl);
        // Dense: [K Jᵀ; J −Ã][Δx; −Δλ] = [M s; b₀].
        let dim = 9 + 3;
        let mut a = DMatrix::<f64>::zeros(dim, dim);
        let mut rhs = DVector::<f64>::zeros(dim);
        for i in 0..3 {
            let m = 1.0 / weight[i].w;
            for p in 0..3 {
                for q in 0..3 {
                    let id = if p == q { 1.0 } else { 0.0 };
                    a[(3 * i + p, 3 * i + q)] =
                        m * id + PLANE_STIFFNESS * m * weight[i].n[p] * weight[i].n[q];
                }
                rhs[3 * i + p] = m * s[i][p];
            }
        }
        let c = 3.0;
        for p in 0..3 {
            for q in 0..3 {
                let g = c * (if p == q { 1.0 } else { 0.0 } - n12[p] * n12[q]);
                a[(3 + p, 3 + q)] += g;
                a[(6 + p, 6 + q)] += g;
                a[(3 + p, 6 + q)] -= g;
                a[(6 + p, 3 + q)] -= g;
            }
        }
        for (r, list) in rows.iter().enumerate() {
            for (k, &node) in list.iter().enumerate() {
                if node == NONE {
                    continue;
                }
                for p in 0..3 {
                    let g = grad[SLOTS * r + k][p];
                    a[(9 + r, 3 * node as usize + p)] = g;
                    a[(3 * node as usize + p, 9 + r)] = g;
                }
            }
            a[(9 + r, 9 + r)] = -extra[r];
            rhs[9 + r] = b0[r];
        }
        let y = a.lu().solve(&rhs).unwrap();
        for i in 0..3 {
            for p in 0..3 {
                let want = y[3 * i + p];
                assert!(
                    (dx[i][p] - want).abs() <= 1e-7 * (1.0 + want.abs()),
                    "dx {i} {p}"
                );
            }
        }
        for r in 0..3 {
            let want = -y[9 + r];
            assert!(
                (dl[r] - want).abs() <= 1e-7 * (1.0 + want.abs()),
                "dl {r}: {} {want}",
                dl[r]
            );
        }
    }
}
