//! The pieces of the Newton iteration: rows evaluated, the step applied, the KKT system
//! factored and solved.

use rayon::prelude::*;

use super::{
    Constraint, HARD_REGULARISATION, MAX_MOVE, PAR_MIN, RowKind, ShapeProblem, ShapeSolver,
    TIE_COMPLIANCE, V3,
};
use crate::bend_angle::turn_and_gradient;
use crate::dual::{DualError, NONE, SLOTS};
use crate::kkt::{KktSystem, KktValues};
use crate::params::ConstraintKind;
use crate::shear_angle::cell_angle_gradient;

impl ShapeSolver {
    /// Every node of a group at the group's mass-weighted mean end position (a pinned member's
    /// position when it has one); momentum kept.
    pub(super) fn collapse(&self, p: &ShapeProblem<'_>, vel: &mut [V3]) {
        let (inv, mass, area, x0, dt) = (
            p.cloth.inverse_masses(),
            p.cloth.masses(),
            p.cloth.topology().node_areas(),
            p.positions,
            p.dt,
        );
        let damp = p.damping * dt;
        for r in 0..self.root.len() {
            let list = &self.members[self.member_ptr[r] as usize..self.member_ptr[r + 1] as usize];
            if list.len() < 2 {
                continue;
            }
            let end = if let Some(&k) = list.iter().find(|&&k| inv[k as usize] == 0.0) {
                x0[k as usize] + vel[k as usize] * dt
            } else {
                let (mut sum, mut m) = (V3::zeros(), 0.0);
                for &k in list {
                    let k = k as usize;
                    let mk = mass[k] + damp * area[k];
                    sum += (x0[k] + vel[k] * dt) * mk;
                    m += mk;
                }
                sum / m
            };
            for &k in list {
                let k = k as usize;
                if inv[k] > 0.0 {
                    vel[k] = (end - x0[k]) / dt;
                }
            }
        }
    }

    /// Evaluate every row at the predicted positions: constraint values, gradients (into the
    /// system), diagonal extras, right-hand sides and violations. Returns the largest violation
    /// and its row.
    pub(super) fn evaluate(
        &mut self,
        p: &ShapeProblem<'_>,
        vel: &[V3],
    ) -> (f64, Option<Constraint>) {
        let st = self.structure.as_mut().expect("prepared");
        let (x0, dt) = (p.positions, p.dt);
        for (x, (a, v)) in self.pred.iter_mut().zip(x0.iter().zip(vel)) {
            *x = a + v * dt;
        }
        let pred = &self.pred;
        let topo = p.cloth.topology();
        let (edges, cells) = (topo.edges(), topo.cells());
        let (kinds, corner_slot, dead, row_nodes, gathered, width_scale) = (
            &st.kinds,
            &st.corner_slot,
            &st.dead,
            &st.row_nodes,
            &st.gathered,
            &st.width_scale,
        );
        let (grad, extras, weight, scales) = st.system.rows_mut();
        let spacing = &self.spacing;
        let (ties, tie_index, lambda) = (p.ties, &self.open_tie_index, &self.lambda);
        let dt2 = dt * dt;
        let row = |(r, ((((g, c), (extra, row_scale)), b), viol)): (
            usize,
            (
                (((&mut [V3], &mut f64), (&mut f64, &mut f64)), &mut f64),
                &mut f64,
            ),
        )| {
            for gk in g.iter_mut() {
                *gk = V3::zeros();
            }
            if dead[r] {
                *c = 0.0;
                *extra = 1.0;
                *b = 0.0;
                *viol = 0.0;
                return;
            }
            let slot = corner_slot[r];
            let lam = lambda[r];
            // (value C, diagonal extra, inequality ≤ 0, violation scale)
            let (value, ex, inequality, scale, residual_is_compliant) = match kinds[r] {
                RowKind::Edge(e) => {
                    let edge = &edges[e as usize];
                    let d = pred[edge.b as usize] - pred[edge.a as usize];
                    let l = d.norm();
                    let n = if l > 0.0 { d / l } else { V3::zeros() };
                    g[slot[0] as usize] -= n;
                    g[slot[1] as usize] += n;
                    let l0 = edge.rest_length;
                    let (target, compliance) = match &p.tension {
                        Some(t) => {
                            let w = t.widths[e as usize] * width_scale[r];
                            let (eps, slope) = t.strain_and_slope(e as usize, -lam / (w * dt2));
                            (l0 * (1.0 + eps), l0 * slope / (w * dt2))
                        }
                        None => (p.targets[e as usize], 0.0),
                    };
                    // The compliance is in the target already (it moves with λ), so the
                    // residual is the length error itself.
                    (
                        l - target,
                        compliance,
                        p.axial == ConstraintKind::StretchOnly || gathered[r],
                        l0,
                        false,
                    )
                }
                RowKind::Cell(ci) => {
                    let cell = &cells[ci as usize];
                    let q = cell.nodes.map(|k| pred[k as usize]);
                    let (alpha, grad) = cell_angle_gradient(p.measure, &q);
                    let sh = &p.shear[ci as usize];
                    let gamma = sh.rest - alpha;
                    for k in 0..4 {
                        g[slot[k] as usize] -= grad[k];
                    }
                    if gamma.abs() > sh.lock {
                        (gamma - sh.lock.copysign(gamma), 0.0, false, 1.0, false)
                    } else {
                        (gamma - sh.offset, sh.compliance / dt2, false, 1.0, true)
                    }
                }
                RowKind::Bend(i, dir, [before, after]) => {
                    let bend = &p.bends[2 * i as usize + dir as usize];
                    let (theta, grad) = turn_and_gradient(
                        &bend.axis,
                        &pred[before as usize],
                        &pred[i as usize],
                        &pred[after as usize],
                    );
                    for k in 0..3 {
                        g[slot[k] as usize] += grad[k];
                    }
                    match &bend.spindle_row {
                        None => (theta - bend.offset, bend.compliance / dt2, false, 1.0, true),
                        // The turn at which the spindle gives the row's moment (the target
                        // follows λ, as an edge's does), the compliance from its slope there.
                        Some(row) => {
                            let (eta, slope) = row.curvature_at(row.moment(lam, dt));
                            let compliance = row.length * row.length / (slope * row.area);
                            (
                                theta - row.length * eta,
                                compliance / dt2,
                                false,
                                1.0,
                                false,
                            )
                        }
                    }
                }
                RowKind::Tie(t) => {
                    let tie = &ties[tie_index[t as usize] as usize];
                    let d = pred[tie.b as usize] - pred[tie.a as usize];
                    let l = d.norm();
                    let n = if l > 0.0 { d / l } else { V3::zeros() };
                    g[slot[0] as usize] -= n;
                    g[slot[1] as usize] += n;
                    // A seam being drawn together is a stiff spring, not a hard constraint:
                    // its compliance is TIE_COMPLIANCE of its own stiffness w_a + w_b, so a
                    // tie the cloth cannot follow this step (a dart closing only by buckling
                    // out of a flat panel, which a linearisation at the flat state cannot see)
                    // converges to the pull the cloth allows instead of stalling the solve; a
                    // free tie closes to within ~0.1 % of its gap per step, and the sewing hook
                    // draws it again the next.
                    let (wa, wb) = (
                        weight[row_nodes[r][slot[0] as usize] as usize].w,
                        weight[row_nodes[r][slot[1] as usize] as usize].w,
                    );
                    (
                        l - tie.length,
                        TIE_COMPLIANCE * (wa + wb),
                        true,
                        spacing[tie.a as usize],
                        true,
                    )
                }
            };
            *row_scale = scale;
            let active = !inequality || value > 0.0 || lam < 0.0;
            // Rows whose compliance lives in their value (edges: the target follows λ) take
            // no α̃λ term in their residual.
            let implicit_target = match kinds[r] {
                RowKind::Edge(_) => true,
                RowKind::Bend(i, dir, _) => {
                    p.bends[2 * i as usize + dir as usize].spindle_row.is_some()
                }
                RowKind::Cell(_) | RowKind::Tie(_) => false,
            };
            *c = value;
            if !active {
                for gk in g.iter_mut() {
                    *gk = V3::zeros();
                }
                *extra = 1.0;
                *b = 0.0;
                *viol = 0.0;
                return;
            }
            // Tiny regularisation of hard rows against their own stiffness Σ w|g|².
            let stiff: f64 = (0..SLOTS)
                .filter(|&k| row_nodes[r][k] != NONE)
                .map(|k| weight[row_nodes[r][k] as usize].w * g[k].norm_squared())
                .sum();
            *extra = if ex > 0.0 {
                ex
            } else {
                HARD_REGULARISATION * stiff.max(f64::MIN_POSITIVE)
            };
            *b = if implicit_target {
                -value
            } else {
                -(value + *extra * lam)
            };
            *viol = if residual_is_compliant {
                (value + *extra * lam).abs() / scale
            } else if inequality {
                value.max(0.0) / scale
            } else {
                value.abs() / scale
            };
        };
        if self.c.len() >= PAR_MIN {
            grad.par_chunks_mut(SLOTS)
                .zip(self.c.par_iter_mut())
                .zip(extras.par_iter_mut().zip(scales.par_iter_mut()))
                .zip(self.b.par_iter_mut())
                .zip(self.viol.par_iter_mut())
                .enumerate()
                .for_each(row);
        } else {
            grad.chunks_mut(SLOTS)
                .zip(self.c.iter_mut())
                .zip(extras.iter_mut().zip(scales.iter_mut()))
                .zip(self.b.iter_mut())
                .zip(self.viol.iter_mut())
                .enumerate()
                .for_each(row);
        }
        let mut worst = (0.0, None);
        let mut merit = 0.0;
        for (r, &v) in self.viol.iter().enumerate() {
            merit += v * v;
            if v > worst.0 {
                let which = match st.kinds[r] {
                    RowKind::Edge(e) => Constraint::Edge(e as usize),
                    RowKind::Cell(c) => Constraint::Cell(c as usize),
                    RowKind::Bend(i, d, _) => Constraint::Bend(i as usize, d),
                    RowKind::Tie(t) => Constraint::Tie(self.open_tie_index[t as usize] as usize),
                };
                worst = (v, Some(which));
            }
        }
        // Planes: penetration over the spacing.
        for (i, plane) in p.planes.iter().enumerate() {
            if plane.normal != V3::zeros() {
                let d = (self.pred[i] - plane.point).dot(&plane.normal);
                let v = (-d).max(0.0) / spacing[i];
                merit += v * v;
                if v > worst.0 {
                    worst = (v, Some(Constraint::Plane(i)));
                }
            }
        }
        self.merit = merit;
        worst
    }

    /// Apply `scale` times the correction Δx = W Jᵀ Δλ (per root) to every member's velocity,
    /// and add `scale`·Δλ to the multipliers (inequality rows kept ≤ 0). With `trust`, the scale
    /// is reduced so that no node moves by more than [`MAX_MOVE`] of its spacing (a Newton step
    /// from a nearly singular system can be huge).
    /// With `shifted` (the global methods), each node also moves by its `shift` (scaled alike).
    pub(super) fn apply(
        &mut self,
        p: &ShapeProblem<'_>,
        vel: &mut [V3],
        scale: f64,
        trust: bool,
        shifted: bool,
    ) {
        let st = self.structure.as_mut().expect("prepared");
        let dx = if self.full_newton {
            &self.newton_dx[..]
        } else {
            st.system.correction(&self.dl)
        };
        let dt = p.dt;
        let (root, shift, full) = (&self.root, &self.shift, self.full_newton);
        let step = |i: usize| {
            if full {
                dx[root[i] as usize]
            } else if shifted {
                dx[root[i] as usize] + shift[i]
            } else {
                dx[root[i] as usize]
            }
        };
        let mut scale = scale;
        if trust {
            let spacing = &self.spacing;
            let ratio = (0..vel.len())
                .map(|i| step(i).norm() / spacing[i])
                .fold(0.0, f64::max);
            if ratio * scale > MAX_MOVE {
                scale = MAX_MOVE / ratio;
            }
        }
        let body = |(i, v): (usize, &mut V3)| {
            *v += step(i) * (scale / dt);
        };
        if vel.len() >= PAR_MIN {
            vel.par_iter_mut().enumerate().for_each(body);
        } else {
            vel.iter_mut().enumerate().for_each(body);
        }
        for (r, (l, d)) in self.lambda.iter_mut().zip(&self.dl).enumerate() {
            *l += d * scale;
            let inequality = match st.kinds[r] {
                RowKind::Edge(_) => p.axial == ConstraintKind::StretchOnly || st.gathered[r],
                RowKind::Tie(_) => true,
                RowKind::Cell(_) | RowKind::Bend(..) => false,
            };
            if inequality && *l > 0.0 {
                *l = 0.0;
            }
        }
    }

    /// The base point from the current velocities and multipliers, `base = v − W Jᵀλ/Δt` with J
    /// at the current positions: for a pass after the first, whose velocities already carry the
    /// multipliers' corrections (and the collision pass's changes, which the base takes).
    pub(super) fn rebase(&mut self, p: &ShapeProblem<'_>, vel: &[V3]) {
        self.evaluate(p, vel);
        let st = self.structure.as_mut().expect("prepared");
        let u = st.system.correction(&self.lambda);
        let (root, dt) = (&self.root, p.dt);
        for (i, (b, v)) in self.base.iter_mut().zip(vel).enumerate() {
            *b = v - u[root[i] as usize] / dt;
        }
    }

    /// Each node's move back to the implicit-Euler balance with the current Jacobian,
    /// `shift = (base + W J(x)ᵀλ/Δt − v)·Δt`, and the right-hand sides corrected by J·shift:
    /// the Newton step then solves for the total multipliers with J at the current iterate
    /// (a sequential-quadratic-programming step), so that its fixed point is `x = x̃ + W J(x)ᵀλ`
    /// exactly. Accumulating corrections made with the Jacobians of earlier iterates (plain
    /// fast projection) instead converges to a point whose balance depends on Δt: a cantilever
    /// at rest drooped 0.3° less at Δt 20 ms than at 1.25 ms.
    pub(super) fn shift_towards_balance(
        &mut self,
        p: &ShapeProblem<'_>,
        vel: &[V3],
        correct_rows: bool,
    ) {
        let st = self.structure.as_mut().expect("prepared");
        let u = st.system.correction(&self.lambda);
        let (root, dt, base) = (&self.root, p.dt, &self.base);
        for (i, (s, v)) in self.shift.iter_mut().zip(vel).enumerate() {
            *s = (base[i] + u[root[i] as usize] / dt - v) * dt;
        }
        if !correct_rows {
            return;
        }
        let (shift, grad) = (&self.shift, &st.system.grad);
        for (r, b) in self.b.iter_mut().enumerate() {
            for k in SLOTS * r..SLOTS * (r + 1) {
                let node = st.system.slot_node(k);
                if node != NONE {
                    *b -= grad[k].dot(&shift[node as usize]);
                }
            }
        }
    }

    /// One full Newton step ([`ShapeMethod::Newton`]): the KKT system at the current iterate
    /// (gradients, compliances and weights as `evaluate` and `update_contacts` left them, the
    /// geometric stiffness of the edges and ties in tension from the current multipliers),
    /// solved for the nodes' steps (`newton_dx`, including the move to the balance) and the
    /// multipliers' (`dl`).
    pub(super) fn newton_step(&mut self) -> Result<(), DualError> {
        let st = self.structure.as_mut().expect("prepared");
        if st.kkt.is_none() {
            let paired: Vec<bool> = st
                .kinds
                .iter()
                .map(|k| matches!(k, RowKind::Edge(_) | RowKind::Tie(_)))
                .collect();
            st.kkt = Some(KktSystem::new(st.system.nodes(), &st.row_nodes, &paired)?);
        }
        self.factor_kkt()?;
        let st = self.structure.as_mut().expect("prepared");
        let kkt = st.kkt.as_mut().expect("built");
        // The balance move per root (every member of a group has its root's).
        let n = st.system.nodes();
        self.newton_dx.resize(n, V3::zeros());
        let roots_shift = &mut self.hat;
        roots_shift.iter_mut().for_each(|v| *v = V3::zeros());
        for (i, &r) in self.root.iter().enumerate() {
            if r as usize == i {
                roots_shift[i] = self.shift[i];
            }
        }
        kkt.solve(
            &st.system.weight,
            &self.hat,
            &self.b,
            &mut self.newton_dx,
            &mut self.dl,
        );
        Ok(())
    }

    /// Assemble and factorize the KKT system at the current iterate.
    pub(super) fn factor_kkt(&mut self) -> Result<(), DualError> {
        let st = self.structure.as_mut().expect("prepared");
        let rows = st.kinds.len();
        self.tension_over_length.clear();
        self.tension_over_length.resize(rows, 0.0);
        for r in 0..rows {
            if !matches!(st.kinds[r], RowKind::Edge(_) | RowKind::Tie(_)) || st.dead[r] {
                continue;
            }
            let lam = self.lambda[r];
            let g = st.system.grad[SLOTS * r + 1];
            if lam >= 0.0 || g == V3::zeros() {
                continue;
            }
            let (a, b) = (st.row_nodes[r][0], st.row_nodes[r][1]);
            if a == NONE || b == NONE {
                continue;
            }
            let l = (self.pred[b as usize] - self.pred[a as usize]).norm();
            if l > 0.0 {
                self.tension_over_length[r] = -lam / l;
            }
        }
        let kkt = st.kkt.as_mut().expect("built");
        kkt.factorize(&KktValues {
            grad: &st.system.grad,
            extra: &st.system.extra,
            weight: &st.system.weight,
            tension_over_length: &self.tension_over_length,
        })
    }
}
