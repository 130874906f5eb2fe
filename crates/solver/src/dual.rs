//! The constraint-space system of the shape stage's global solve (`method.md` §2b): fast
//! projection (Goldenthal et al. 2007) with compliance (XPBD, Macklin et al. 2016).
//!
//! Each Newton iteration of the shape stage solves
//!
//! ```text
//!     (J W Jᵀ + Ã) Δλ = b,      Δx = W Jᵀ Δλ
//! ```
//!
//! J the constraints' gradients at the predicted positions, W the nodes' inverse masses (a node
//! on a contact plane may be restricted to the plane: W = w (I − n nᵀ)), Ã the compliances over
//! Δt² plus a tiny regularisation. This module owns the system's structure — which rows touch
//! which nodes, the sparsity pattern of the lower triangle of J W Jᵀ, the symbolic analysis of its
//! LDLᵀ factorization (faer, fill-reducing AMD ordering) — and the numeric work: assembly, the
//! numeric factorization, and preconditioned conjugate gradients whose preconditioner is the last
//! factorization. A fresh factorization solves in one CG iteration; one from an earlier iteration
//! or step (the values moved, the pattern did not) is a preconditioner that usually needs a few,
//! which is how the caller trades factorizations for iterations.
//!
//! The structure is built once per set of rows (a cloth's topology plus the step's tie rows) and
//! reused while it is unchanged; only values change between iterations.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::{LdltParams, LdltRegularization};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LdltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side, Spec};
use nalgebra::Vector3;
use rayon::prelude::*;

type V3 = Vector3<f64>;

/// Below this many rows the loops run on one thread.
const PAR_MIN: usize = 4096;

/// Slots per row: a row touches at most this many nodes (a cell's four corners).
pub const SLOTS: usize = 4;

/// An unused slot.
pub const NONE: u32 = u32::MAX;

/// Why the system could not be built or factorized.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DualError {
    /// A row names a node beyond the node count.
    #[error("constraint row {row} names node {node}, but there are {nodes} nodes")]
    NoSuchNode {
        /// The row.
        row: usize,
        /// The node it names.
        node: usize,
        /// Node count.
        nodes: usize,
    },
    /// The symbolic analysis failed (out of memory or index overflow).
    #[error("symbolic analysis of the constraint system failed: {0}")]
    Symbolic(String),
    /// The numeric factorization met a zero pivot (a constraint with no movable node that the
    /// caller did not switch off, or a non-finite value).
    #[error("the constraint system is singular at row {row} (after reordering)")]
    Singular {
        /// Pivot index in the reordered system.
        row: usize,
    },
}

/// A node's inverse mass, optionally restricted to a plane (normal `n`, unit; zero for none).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeWeight {
    /// Inverse mass, 1/kg (0: the node does not move).
    pub w: f64,
    /// Unit normal of a plane the node may not leave, or zero.
    pub n: V3,
}

impl NodeWeight {
    /// W·v.
    #[inline]
    pub fn apply(&self, v: &V3) -> V3 {
        if self.n == V3::zeros() {
            v * self.w
        } else {
            (v - self.n * self.n.dot(v)) * self.w
        }
    }
}

/// The preconditioner of the conjugate gradients.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preconditioner {
    /// The last LDLᵀ factorization (made first when there is none).
    Factor,
    /// The matrix's diagonal (Jacobi); nothing is factorized.
    Diagonal,
}

/// What one solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveStats {
    /// Conjugate-gradient iterations.
    pub iterations: usize,
    /// Final residual over the right-hand side's norm.
    pub relative_residual: f64,
}

/// The structure, factorization and scratch of one constraint-space system.
pub struct DualSystem {
    nodes: usize,
    /// The node of each slot: row r has slots `SLOTS·r .. SLOTS·(r + 1)`, unused ones [`NONE`].
    slot_node: Vec<u32>,
    /// Nodes → slots (CSR).
    node_ptr: Vec<u32>,
    node_slot: Vec<u32>,
    /// Lower-triangle CSC pattern of the matrix.
    pattern: SymbolicSparseColMat<usize>,
    /// Assembly plan: for value k, the slot pairs `plan[plan_ptr[k]..plan_ptr[k + 1]]` whose
    /// products g_aᵀ W g_b add up to it (the two slots share a node).
    plan_ptr: Vec<u32>,
    plan: Vec<[u32; 2]>,
    /// Value index of each row's diagonal entry.
    diag: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    factor: Vec<f64>,
    factored: bool,
    mem: MemBuffer,
    /// Gradient of each slot's row with respect to its node (set by the caller; unused slots
    /// are ignored).
    pub grad: Vec<V3>,
    /// Each row's diagonal addition: compliance over Δt² plus regularisation; rows the caller
    /// switches off get gradients 0 and 1 here (set by the caller).
    pub extra: Vec<f64>,
    /// Each node's weight (set by the caller).
    pub weight: Vec<NodeWeight>,
    /// Each row's scale (its violation is its residual over this; 1 by default): the
    /// conjugate gradients stop on the residual measured in these units, so that rows in
    /// metres and rows in radians are solved to the same relative accuracy.
    pub row_scale: Vec<f64>,
    // CG scratch.
    d: Vec<f64>,
    u: Vec<V3>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
}

impl DualSystem {
    /// The system of `rows` over `nodes` nodes: each row lists the distinct nodes it touches in
    /// up to [`SLOTS`] slots, unused slots [`NONE`]. Builds the pattern, the assembly plan and
    /// the symbolic factorization.
    pub fn new(nodes: usize, rows: &[[u32; SLOTS]]) -> Result<Self, DualError> {
        let m = rows.len();
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
        let slot_node: Vec<u32> = rows.iter().flatten().copied().collect();
        let slots = slot_node.len();
        // Nodes → slots.
        let mut node_ptr = vec![0u32; nodes + 1];
        for &k in slot_node.iter().filter(|&&k| k != NONE) {
            node_ptr[k as usize + 1] += 1;
        }
        for i in 0..nodes {
            node_ptr[i + 1] += node_ptr[i];
        }
        let mut fill = node_ptr.clone();
        let mut node_slot = vec![0u32; node_ptr[nodes] as usize];
        for (s, &k) in slot_node.iter().enumerate().filter(|(_, k)| **k != NONE) {
            node_slot[fill[k as usize] as usize] = s as u32;
            fill[k as usize] += 1;
        }
        // Entries (row a ≥ row b) with their contributing slot pairs, column by column.
        let mut by_col: Vec<Vec<(u32, [u32; 2])>> = vec![Vec::new(); m];
        for i in 0..nodes {
            let list = &node_slot[node_ptr[i] as usize..node_ptr[i + 1] as usize];
            for &sa in list {
                for &sb in list {
                    let (ra, rb) = (sa as usize / SLOTS, sb as usize / SLOTS);
                    if ra >= rb {
                        by_col[rb].push((ra as u32, [sa, sb]));
                    }
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(m + 1);
        let mut row_idx = Vec::new();
        let mut plan_ptr = vec![0u32];
        let mut plan = Vec::new();
        let mut diag = vec![0usize; m];
        col_ptr.push(0usize);
        for (c, mut entries) in by_col.into_iter().enumerate() {
            // The diagonal is always present (a row with no node keeps its `extra`).
            entries.push((c as u32, [NONE; 2]));
            entries.sort_unstable_by_key(|e| e.0);
            let mut k = 0;
            while k < entries.len() {
                let row = entries[k].0;
                if row as usize == c {
                    diag[c] = row_idx.len();
                }
                row_idx.push(row as usize);
                while k < entries.len() && entries[k].0 == row {
                    if entries[k].1[0] != NONE {
                        plan.push(entries[k].1);
                    }
                    k += 1;
                }
                plan_ptr.push(plan.len() as u32);
            }
            col_ptr.push(row_idx.len());
        }
        let nnz = row_idx.len();
        let pattern = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
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
        let factor = vec![0.0; symbolic.len_val()];
        Ok(Self {
            nodes,
            slot_node,
            node_ptr,
            node_slot,
            pattern,
            plan_ptr,
            plan,
            diag,
            symbolic,
            values: vec![0.0; nnz],
            factor,
            factored: false,
            mem,
            grad: vec![V3::zeros(); slots],
            extra: vec![0.0; m],
            weight: vec![NodeWeight::default(); nodes],
            row_scale: vec![1.0; m],
            d: vec![0.0; m],
            u: vec![V3::zeros(); nodes],
            r: vec![0.0; m],
            z: vec![0.0; m],
            p: vec![0.0; m],
            q: vec![0.0; m],
        })
    }

    /// The gradients, extras and row scales to fill, beside the node weights (split borrows).
    pub fn rows_mut(&mut self) -> (&mut [V3], &mut [f64], &[NodeWeight], &mut [f64]) {
        (
            &mut self.grad,
            &mut self.extra,
            &self.weight,
            &mut self.row_scale,
        )
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.extra.len()
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// The node of slot `s` ([`NONE`] for an unused slot).
    #[inline]
    pub fn slot_node(&self, s: usize) -> u32 {
        self.slot_node[s]
    }

    /// Non-zeros of the lower triangle of the matrix, and of its factor.
    pub fn sizes(&self) -> (usize, usize) {
        (self.values.len(), self.factor.len())
    }

    /// Whether a factorization is available (possibly of earlier values).
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Forget the factorization (the next solve factorizes first).
    pub fn invalidate(&mut self) {
        self.factored = false;
    }

    /// Assemble J W Jᵀ + diag(extra) from the current gradients, weights and extras, and
    /// factorize it (LDLᵀ, the symbolic analysis reused). Pivots that come out non-positive or
    /// tiny are replaced by a small positive value (faer's dynamic regularisation); returns the
    /// number replaced.
    pub fn factorize(&mut self, par: Par) -> Result<(), DualError> {
        self.assemble();
        let scale = self
            .diag
            .iter()
            .map(|&k| self.values[k])
            .fold(0.0f64, f64::max)
            .max(f64::MIN_POSITIVE);
        let signs = vec![1i8; self.rows()];
        let reg = LdltRegularization {
            dynamic_regularization_signs: Some(&signs),
            dynamic_regularization_delta: 1e-10 * scale,
            dynamic_regularization_epsilon: 1e-14 * scale,
        };
        let a = SparseColMatRef::new(self.pattern.as_ref(), &self.values);
        let stack = MemStack::new(&mut self.mem);
        match self.symbolic.factorize_numeric_ldlt(
            &mut self.factor,
            a,
            Side::Lower,
            reg,
            par,
            stack,
            Spec::<LdltParams, f64>::default(),
        ) {
            Ok(_) => {
                self.factored = self.factor.iter().all(|x| x.is_finite());
                if self.factored {
                    Ok(())
                } else {
                    Err(DualError::Singular { row: 0 })
                }
            }
            Err(faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index }) => {
                self.factored = false;
                Err(DualError::Singular { row: index })
            }
        }
    }

    /// The lower triangle's values from the plan.
    fn assemble(&mut self) {
        let (plan_ptr, plan, grad, weight, slot_node) = (
            &self.plan_ptr,
            &self.plan,
            &self.grad,
            &self.weight,
            &self.slot_node,
        );
        let value = |k: usize| -> f64 {
            plan[plan_ptr[k] as usize..plan_ptr[k + 1] as usize]
                .iter()
                .map(|&[a, b]| {
                    let node = slot_node[a as usize] as usize;
                    grad[a as usize].dot(&weight[node].apply(&grad[b as usize]))
                })
                .sum()
        };
        if self.values.len() >= 4 * PAR_MIN {
            self.values
                .par_iter_mut()
                .enumerate()
                .for_each(|(k, v)| *v = value(k));
        } else {
            self.values
                .iter_mut()
                .enumerate()
                .for_each(|(k, v)| *v = value(k));
        }
        for (r, &k) in self.diag.iter().enumerate() {
            self.values[k] += self.extra[r];
        }
    }

    /// `u_i = Σ_{slots at i} g_s x_row(s)`, then `W_i u_i` (the correction Δx = W Jᵀ x).
    pub fn correction(&mut self, x: &[f64]) -> &[V3] {
        Self::w_jt(
            &self.node_ptr,
            &self.node_slot,
            &self.grad,
            &self.weight,
            x,
            &mut self.u,
        );
        &self.u
    }

    /// `Jᵀx` at node `i` (no weight): the force the rows' multipliers `x` exert on it.
    pub fn jt_at(&self, x: &[f64], i: usize) -> V3 {
        self.node_slot[self.node_ptr[i] as usize..self.node_ptr[i + 1] as usize]
            .iter()
            .map(|&s| self.grad[s as usize] * x[s as usize / SLOTS])
            .sum()
    }

    fn w_jt(
        node_ptr: &[u32],
        node_slot: &[u32],
        grad: &[V3],
        weight: &[NodeWeight],
        x: &[f64],
        out: &mut [V3],
    ) {
        let row_of = |s: u32| -> usize { s as usize / SLOTS };
        let body = |(i, u): (usize, &mut V3)| {
            let mut sum = V3::zeros();
            for &s in &node_slot[node_ptr[i] as usize..node_ptr[i + 1] as usize] {
                sum += grad[s as usize] * x[row_of(s)];
            }
            *u = weight[i].apply(&sum);
        };
        if out.len() >= PAR_MIN {
            out.par_iter_mut().enumerate().for_each(body);
        } else {
            out.iter_mut().enumerate().for_each(body);
        }
    }

    /// y = (J W Jᵀ + diag(extra)) x, matrix-free.
    fn apply(&mut self, x: &[f64], y: &mut [f64]) {
        Self::w_jt(
            &self.node_ptr,
            &self.node_slot,
            &self.grad,
            &self.weight,
            x,
            &mut self.u,
        );
        let (grad, slot_node, u, extra) = (&self.grad, &self.slot_node, &self.u, &self.extra);
        let body = |(r, yr): (usize, &mut f64)| {
            let mut s = extra[r] * x[r];
            for k in SLOTS * r..SLOTS * (r + 1) {
                if slot_node[k] != NONE {
                    s += grad[k].dot(&u[slot_node[k] as usize]);
                }
            }
            *yr = s;
        };
        if y.len() >= PAR_MIN {
            y.par_iter_mut().enumerate().for_each(body);
        } else {
            y.iter_mut().enumerate().for_each(body);
        }
    }

    /// The matrix's diagonal, Σ_slots g·W g + extra, into `out`.
    pub fn diagonal(&self, out: &mut [f64]) {
        let (grad, slot_node, weight, extra) =
            (&self.grad, &self.slot_node, &self.weight, &self.extra);
        for (r, d) in out.iter_mut().enumerate() {
            let mut v = extra[r];
            for k in SLOTS * r..SLOTS * (r + 1) {
                if slot_node[k] != NONE {
                    v += grad[k].dot(&weight[slot_node[k] as usize].apply(&grad[k]));
                }
            }
            *d = v;
        }
    }

    /// z = M⁻¹ r for the preconditioner (`diag`: the diagonal, for [`Preconditioner::Diagonal`]).
    fn precondition(&mut self, r: &[f64], z: &mut [f64], diag: Option<&[f64]>) {
        if let Some(d) = diag {
            for ((zk, rk), dk) in z.iter_mut().zip(r).zip(d) {
                *zk = if *dk > 0.0 { rk / dk } else { *rk };
            }
            return;
        }
        z.copy_from_slice(r);
        let ldlt = LdltRef::new(&self.symbolic, &self.factor);
        let n = z.len();
        let stack = MemStack::new(&mut self.mem);
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(z, n, 1),
            Par::Seq,
            stack,
        );
    }

    /// Solve (J W Jᵀ + diag(extra)) x = b by conjugate gradients with `pre`conditioning (the
    /// last factorization, made first when there is none; or the diagonal), to
    /// `‖r‖ ≤ tol·‖b‖` in the rows' scales or `max_iterations`. `x` is overwritten (the iteration starts from 0).
    pub fn solve(
        &mut self,
        b: &[f64],
        x: &mut [f64],
        tol: f64,
        max_iterations: usize,
        pre: Preconditioner,
        par: Par,
    ) -> Result<SolveStats, DualError> {
        let mut d = std::mem::take(&mut self.d);
        let diag = match pre {
            Preconditioner::Factor => {
                if !self.factored {
                    self.factorize(par)?;
                }
                None
            }
            Preconditioner::Diagonal => {
                self.diagonal(&mut d);
                Some(&d[..])
            }
        };
        let dot = |a: &[f64], b: &[f64]| -> f64 { a.iter().zip(b).map(|(x, y)| x * y).sum() };
        x.iter_mut().for_each(|v| *v = 0.0);
        let scaled = |v: &[f64], scale: &[f64]| -> f64 {
            v.iter()
                .zip(scale)
                .map(|(x, s)| (x / s) * (x / s))
                .sum::<f64>()
                .sqrt()
        };
        let b_norm = scaled(b, &self.row_scale);
        if b_norm == 0.0 {
            return Ok(SolveStats::default());
        }
        let mut r = std::mem::take(&mut self.r);
        let mut z = std::mem::take(&mut self.z);
        let mut p = std::mem::take(&mut self.p);
        let mut q = std::mem::take(&mut self.q);
        r.copy_from_slice(b);
        self.precondition(&r, &mut z, diag);
        p.copy_from_slice(&z);
        let mut rz = dot(&r, &z);
        let mut stats = SolveStats {
            iterations: 0,
            relative_residual: 1.0,
        };
        while stats.iterations < max_iterations.max(1) {
            stats.iterations += 1;
            self.apply(&p, &mut q);
            let pq = dot(&p, &q);
            if !(pq > 0.0) {
                break;
            }
            let alpha = rz / pq;
            for k in 0..x.len() {
                x[k] += alpha * p[k];
                r[k] -= alpha * q[k];
            }
            stats.relative_residual = scaled(&r, &self.row_scale) / b_norm;
            if stats.relative_residual <= tol {
                break;
            }
            self.precondition(&r, &mut z, diag);
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            for k in 0..p.len() {
                p[k] = z[k] + beta * p[k];
            }
        }
        self.r = r;
        self.z = z;
        self.p = p;
        self.q = q;
        self.d = d;
        Ok(stats)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small system against a dense solve: three nodes, two distance-like rows and one
    /// three-node row, one node on a plane.
    #[test]
    fn the_solve_matches_a_dense_solve() {
        let rows = [[0, 1, NONE, NONE], [1, 2, NONE, NONE], [0, 1, 2, NONE]];
        let mut sys = DualSystem::new(3, &rows).expect("system");
        let z = V3::zeros();
        let g = [
            V3::new(1.0, 0.2, -0.1),
            V3::new(-1.0, 0.1, 0.3),
            z,
            z,
            V3::new(0.0, 1.0, 0.5),
            V3::new(0.2, -1.0, 0.0),
            z,
            z,
            V3::new(0.3, 0.3, 0.3),
            V3::new(-0.5, 0.1, 0.9),
            V3::new(0.1, 0.7, -0.2),
            z,
        ];
        sys.grad.copy_from_slice(&g);
        sys.weight = vec![
            NodeWeight {
                w: 2.0,
                n: V3::zeros(),
            },
            NodeWeight {
                w: 1.0,
                n: V3::new(0.0, 0.0, 1.0),
            },
            NodeWeight {
                w: 0.5,
                n: V3::zeros(),
            },
        ];
        sys.extra = vec![0.1, 0.0, 0.3];
        let dense = |sys: &DualSystem| {
            let mut a = [[0.0; 3]; 3];
            for r in 0..3 {
                for s in 0..3 {
                    let mut v = if r == s { sys.extra[r] } else { 0.0 };
                    for kr in SLOTS * r..SLOTS * (r + 1) {
                        for ks in SLOTS * s..SLOTS * (s + 1) {
                            let node = sys.slot_node(kr);
                            if node != NONE && node == sys.slot_node(ks) {
                                v += g[kr].dot(&sys.weight[node as usize].apply(&g[ks]));
                            }
                        }
                    }
                    a[r][s] = v;
                }
            }
            a
        };
        let b = [1.0, -2.0, 0.5];
        let check = |a: &[[f64; 3]; 3], x: &[f64; 3]| {
            for r in 0..3 {
                let ax: f64 = (0..3).map(|s| a[r][s] * x[s]).sum();
                assert!((ax - b[r]).abs() < 1e-11, "row {r}: {ax} vs {}", b[r]);
            }
        };
        let mut x = [0.0; 3];
        let stats = sys
            .solve(&b, &mut x, 1e-14, 10, Preconditioner::Factor, Par::Seq)
            .expect("solve");
        assert!(stats.iterations <= 2, "{stats:?}");
        check(&dense(&sys), &x);
        // A stale factorization is a preconditioner: it still converges, in more iterations.
        sys.weight[2].w = 0.8;
        let mut y = [0.0; 3];
        let stats = sys
            .solve(&b, &mut y, 1e-13, 20, Preconditioner::Factor, Par::Seq)
            .expect("solve");
        assert!(stats.relative_residual <= 1e-13, "{stats:?}");
        check(&dense(&sys), &y);
        // The diagonal preconditioner converges too, with more iterations.
        let mut w = [0.0; 3];
        let stats = sys
            .solve(&b, &mut w, 1e-13, 50, Preconditioner::Diagonal, Par::Seq)
            .expect("solve");
        assert!(stats.relative_residual <= 1e-13, "{stats:?}");
        check(&dense(&sys), &w);
        // The correction W Jᵀ x of node 1 lies in its plane.
        let dx = sys.correction(&y);
        assert!(dx[1].z.abs() < 1e-15);
    }

    /// A row with no movable node (both nodes pinned) and no extra does not stop the
    /// factorization: its pivot is regularised, and the other row is solved exactly.
    #[test]
    fn a_row_of_pinned_nodes_is_regularised() {
        let rows = [[0, 1, NONE, NONE], [1, 2, NONE, NONE]];
        let mut sys = DualSystem::new(3, &rows).expect("system");
        let z = V3::zeros();
        sys.grad = vec![V3::x(), -V3::x(), z, z, V3::x(), -V3::x(), z, z];
        sys.weight = vec![
            NodeWeight::default(),
            NodeWeight::default(),
            NodeWeight {
                w: 1.0,
                n: V3::zeros(),
            },
        ];
        sys.extra = vec![0.0, 0.0];
        sys.factorize(Par::Seq).expect("regularised");
        let mut x = [0.0; 2];
        sys.solve(
            &[0.0, 1.0],
            &mut x,
            1e-12,
            5,
            Preconditioner::Factor,
            Par::Seq,
        )
        .expect("solve");
        assert!((x[1] - 1.0).abs() < 1e-9, "{x:?}");
    }

    #[test]
    fn a_row_naming_a_missing_node_is_refused() {
        let rows = [[0, 5, NONE, NONE]];
        assert!(matches!(
            DualSystem::new(3, &rows),
            Err(DualError::NoSuchNode {
                row: 0,
                node: 5,
                ..
            })
        ));
    }
}
