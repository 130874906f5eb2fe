//! Stage 4b: the shape-constraint iterations (49)–(51) — Jacobi, Chebyshev, Gauss–Seidel or
//! Newton — each ending with the hard constraints (pins, long-range attachments, ties, contact
//! planes) and, with a pressure stage, the air's pressure as a constraint.

use std::time::Instant;

use atelier_grid::NO_NODE;
use rayon::prelude::*;

use super::par::{PAR_MIN, det_sum, fill};
use super::scratch::Scratch;
use super::{Solver, V3, plane_push};
use crate::cloth::Cloth;
use crate::params::{ConstraintKind, ShapeMethod, StepParams};
use crate::state::ClothState;

/// `(Jᵀ x)_i` for the length constraints: the sum over the edges at node `i` of `x_e` times the
/// edge's unit direction, signed −1 where `i` is the edge's first node (∂l/∂r_a = −d).
fn jacobian_transpose(cloth: &Cloth, cdir: &[V3], x: &[f64], i: usize) -> V3 {
    cloth
        .incidence(i)
        .iter()
        .map(|inc| cdir[inc.edge as usize] * (-inc.sign * x[inc.edge as usize]))
        .sum()
}

impl Solver {
    /// Shape-constraint iterations (49)–(51): predicted positions r + ṙΔt; per edge the error
    /// C = l − l_target (stretch-only edges: only C > 0); per node R = Σ w_i/(w_i + w_a) C d
    /// and the scaled velocity step ṙ += γ R/(n Δt), n the node's constraint count; plain
    /// (Jacobi) or Chebyshev-accelerated. Stops when RMS(R) < ε^e or at the cap.
    pub(super) fn shape_iterations(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
        factor: f64,
    ) -> (usize, f64, usize) {
        let topo = cloth.topology();
        let edges = topo.edges();
        let inv = cloth.inverse_masses();
        let dt = params.dt;
        let tol = params.shape_tolerance * factor;
        let free = inv.iter().filter(|&&w| w > 0.0).count().max(1) as f64;
        let mut omega = 1.0;
        let mut residual = 0.0;
        let mut iterations = 0;
        let mut cg_total = 0;
        self.s.vel_prev.copy_from_slice(&self.s.vel);
        self.s.lambda_c.fill(0.0);
        // Contact planes: the Jacobi and Chebyshev node updates apply a node's plane as they
        // compute it (in parallel); the planes of tied nodes, and every plane with the other
        // methods, are applied after the ties in `project`.
        let in_loop = matches!(
            params.shape_method,
            ShapeMethod::Jacobi | ShapeMethod::Chebyshev { .. }
        );
        {
            let s = &mut self.s;
            s.tied.clear();
            s.tied.resize(s.planes.len(), false);
            for t in &s.ties {
                s.tied[t.a as usize] = true;
                s.tied[t.b as usize] = true;
            }
            s.plane_nodes.clear();
            s.plane_nodes
                .extend((0..s.planes.len() as u32).filter(|&i| {
                    s.planes[i as usize].normal != V3::zeros() && (!in_loop || s.tied[i as usize])
                }));
        }
        let stiffness = cloth.diagonal_stiffness();
        // The hard constraints first, so that an iteration that stops at once (the cloth's own
        // constraints already met) still leaves them met.
        Self::project(&mut self.s, cloth, state, dt, true);
        for k in 0..params.shape_max_iterations {
            let s = &mut self.s;
            let (pos, vel, target) = (&state.positions, &s.vel, &s.target);
            let (axial_kind, diagonal_kind) = (params.axial_constraint, params.diagonal_constraint);
            let gamma = params.shape_step;
            // Per edge, at the predicted positions r + ṙΔt: unit direction and length error.
            // A compliant edge (XPBD, α̃ = 1/(k Δt²)) corrects C + α̃λ scaled by w/(w + α̃) and
            // accumulates λ by the part its nodes actually take (γ over their constraint
            // counts); at the fixed point C = −α̃λ, the spring force −kC.
            let edge_error = |(e, ((dir, c), lambda)): (usize, ((&mut V3, &mut f64), &mut f64))| {
                let edge = &edges[e];
                let (a, b) = (edge.a as usize, edge.b as usize);
                let d = (pos[b] - pos[a]) + (vel[b] - vel[a]) * dt;
                let l = d.norm();
                *dir = if l > 0.0 { d / l } else { V3::zeros() };
                let kind = if edge.kind.is_axial() {
                    axial_kind
                } else {
                    diagonal_kind
                };
                *c = match kind {
                    ConstraintKind::Equality => l - target[e],
                    ConstraintKind::StretchOnly => (l - target[e]).max(0.0),
                    ConstraintKind::Compliant => {
                        let w = inv[a] + inv[b];
                        if w == 0.0 {
                            0.0
                        } else {
                            let alpha = 1.0 / (stiffness[e] * dt * dt);
                            let corr = (l - target[e] + alpha * *lambda) * w / (w + alpha);
                            let n =
                                0.5 * (cloth.incidence(a).len() + cloth.incidence(b).len()) as f64;
                            *lambda -= corr * gamma / (n * w);
                            corr
                        }
                    }
                };
            };
            if edges.len() >= PAR_MIN {
                s.cdir
                    .par_iter_mut()
                    .zip(s.c.par_iter_mut())
                    .zip(s.lambda_c.par_iter_mut())
                    .enumerate()
                    .for_each(edge_error);
            } else {
                s.cdir
                    .iter_mut()
                    .zip(s.c.iter_mut())
                    .zip(s.lambda_c.iter_mut())
                    .enumerate()
                    .for_each(edge_error);
            }
            // Per node, one pass: R (49)–(50) and the Jacobi / Chebyshev candidate velocity
            // (a node moves by γ times the mean of its constraints' corrections).
            if let ShapeMethod::Chebyshev { rho } = params.shape_method {
                omega = match k {
                    0 => 1.0,
                    1 => 2.0 / (2.0 - rho * rho),
                    _ => 4.0 / (4.0 - rho * rho * omega),
                };
            }
            let chebyshev = matches!(params.shape_method, ShapeMethod::Chebyshev { .. });
            {
                let (c, cdir, vel, prev, gamma) =
                    (&s.c, &s.cdir, &s.vel, &s.vel_prev, params.shape_step);
                let (planes, tied, pos) = (&s.planes, &s.tied, &state.positions);
                let node = |(i, (r, hat)): (usize, (&mut V3, &mut V3))| {
                    let inc = cloth.incidence(i);
                    let mut sum = V3::zeros();
                    for x in inc {
                        let e = x.edge as usize;
                        sum += cdir[e] * (x.sign * x.share * c[e]);
                    }
                    *r = sum;
                    let candidate = vel[i] + sum * (gamma / (inc.len() as f64 * dt));
                    *hat = if chebyshev {
                        prev[i] + (candidate - prev[i]) * omega
                    } else {
                        candidate
                    };
                    if in_loop && planes[i].normal != V3::zeros() && !tied[i] {
                        *hat = plane_push(*hat, &pos[i], &planes[i], dt);
                    }
                };
                if s.r.len() >= PAR_MIN {
                    s.r.par_iter_mut()
                        .zip(s.vel_hat.par_iter_mut())
                        .enumerate()
                        .for_each(node);
                } else {
                    s.r.iter_mut()
                        .zip(s.vel_hat.iter_mut())
                        .enumerate()
                        .for_each(node);
                }
            }
            let r = &s.r;
            // The residual (a full reduction) is checked every fourth iteration and at the cap.
            if k % 4 == 0 || k + 1 == params.shape_max_iterations {
                residual = (det_sum(&mut s.chunk, r.len(), |i| r[i].norm_squared()) / free).sqrt();
                if residual < tol {
                    break;
                }
            }
            iterations += 1;
            match params.shape_method {
                ShapeMethod::Newton {
                    cg_iterations,
                    cg_tolerance,
                } => {
                    cg_total += Self::newton_projection(s, cloth, dt, cg_iterations, cg_tolerance);
                }
                ShapeMethod::GaussSeidel { omega } => {
                    for colour in 0..cloth.colour_count() {
                        let (vel, pos, target) = (&s.vel, &state.positions, &s.target);
                        fill(&mut s.vel_hat, |i| {
                            let e = cloth.colour_edge(i, colour);
                            if e == NO_NODE || inv[i] == 0.0 {
                                return vel[i];
                            }
                            let edge = &edges[e as usize];
                            let (a, b) = (edge.a as usize, edge.b as usize);
                            let d = (pos[b] + vel[b] * dt) - (pos[a] + vel[a] * dt);
                            let l = d.norm();
                            let kind = if edge.kind.is_axial() {
                                params.axial_constraint
                            } else {
                                params.diagonal_constraint
                            };
                            let mut c = l - target[e as usize];
                            match kind {
                                ConstraintKind::StretchOnly => c = c.max(0.0),
                                // Rejected by `StepParams::validate`.
                                ConstraintKind::Compliant | ConstraintKind::Equality => {}
                            }
                            if l == 0.0 || c == 0.0 {
                                return vel[i];
                            }
                            let (wa, wb) = (inv[a], inv[b]);
                            let delta = omega * c / (wa + wb);
                            let sign = if i == a { wa } else { -wb };
                            vel[i] + d * (sign * delta / (l * dt))
                        });
                        std::mem::swap(&mut s.vel, &mut s.vel_hat);
                    }
                }
                ShapeMethod::Jacobi => std::mem::swap(&mut s.vel, &mut s.vel_hat),
                ShapeMethod::Chebyshev { .. } => {
                    // prev ← current, current ← new.
                    std::mem::swap(&mut s.vel_prev, &mut s.vel);
                    std::mem::swap(&mut s.vel, &mut s.vel_hat);
                }
            }
            Self::project(s, cloth, state, dt, false);
            if k % 4 == 3 {
                self.project_pressure(cloth, state, dt);
            }
        }
        self.project_pressure(cloth, state, dt);
        (iterations, residual, cg_total)
    }

    /// The air's pressure at the end of the step as a constraint on the velocities (when a
    /// pressure stage is on), then the hard constraints again; timed into `pressure_time`.
    fn project_pressure(&mut self, cloth: &Cloth, state: &ClothState, dt: f64) {
        if let Some(p) = &mut self.pressure {
            let t0 = Instant::now();
            let s = &mut self.s;
            s.pred.copy_from_slice(&s.vel);
            p.project(&state.positions, cloth.inverse_masses(), dt, &mut s.vel);
            // The Chebyshev iteration extrapolates from the previous iterate: move it by the same
            // change, so that the pressure's correction is not over-relaxed.
            for ((prev, v), before) in s.vel_prev.iter_mut().zip(&s.vel).zip(&s.pred) {
                *prev += v - before;
            }
            Self::project(s, cloth, state, dt, true);
            self.s.pressure_time += t0.elapsed();
        }
    }

    /// The hard constraints every shape iteration ends with: pins at their prescribed
    /// positions, ties (a pair farther apart than its length drawn together along its line,
    /// each node by its share of the inverse mass: momentum kept), and contact planes (no node
    /// ends the step behind its plane), in that order. `every_plane`: every node's plane, not
    /// only those the node update leaves to this pass.
    fn project(s: &mut Scratch, cloth: &Cloth, state: &ClothState, dt: f64, every_plane: bool) {
        let inv = cloth.inverse_masses();
        for pin in cloth.pins() {
            let i = pin.node as usize;
            let v = (pin.position(state.time + dt) - state.positions[i]) / dt;
            s.vel[i] = v;
            s.vel_prev[i] = v;
        }
        if s.long_range_on
            && let Some(lr) = &mut s.long_range
        {
            lr.project(
                cloth,
                &state.positions,
                &mut s.vel,
                state.time + dt,
                dt,
                s.long_range_slack,
            );
        }
        for tie in &s.ties {
            let (a, b) = (tie.a as usize, tie.b as usize);
            let ws = inv[a] + inv[b];
            if ws <= 0.0 {
                continue;
            }
            let gap = (state.positions[b] + s.vel[b] * dt) - (state.positions[a] + s.vel[a] * dt);
            let l = gap.norm();
            if l <= tie.length {
                continue;
            }
            let shift = gap * ((l - tie.length) / (l * ws * dt));
            s.vel[a] += shift * inv[a];
            s.vel[b] -= shift * inv[b];
        }
        if every_plane {
            for i in 0..s.planes.len() {
                if s.planes[i].normal != V3::zeros() {
                    s.vel[i] = plane_push(s.vel[i], &state.positions[i], &s.planes[i], dt);
                }
            }
        } else {
            for &i in &s.plane_nodes {
                let i = i as usize;
                s.vel[i] = plane_push(s.vel[i], &state.positions[i], &s.planes[i], dt);
            }
        }
    }

    /// Switch the long-range attachments on for this step when asked for and the cloth has pins
    /// (building them when the pins changed), with the step's largest target strain as slack.
    pub(super) fn prepare_long_range(&mut self, cloth: &Cloth, params: &StepParams) {
        let s = &mut self.s;
        s.long_range_on = params.long_range_attachments && !cloth.pins().is_empty();
        if !s.long_range_on {
            return;
        }
        if !s.long_range.as_ref().is_some_and(|lr| lr.matches(cloth)) {
            s.long_range = Some(crate::long_range::LongRange::build(cloth));
        }
        let edges = cloth.topology().edges();
        s.long_range_slack = s
            .target
            .iter()
            .zip(edges)
            .map(|(t, e)| t / e.rest_length - 1.0)
            .fold(0.0, f64::max);
    }

    /// One Gauss–Newton step on the shape objective E^e = ½ Σ (l − l_target)² (49): the
    /// correction δx minimising |C + J δx|² (J at the predicted positions) with the least change
    /// in the mass metric, found by Jacobi-preconditioned CG on
    /// `(W^½ JᵀJ W^½ + εI) y = −W^½ Jᵀ C`, `δx = W^½ y` (pinned nodes have W = 0 and do not
    /// move); then ṙ += δx/Δt. Unlike the dual (λ) form this stays well posed when the
    /// 8-neighbourhood's targets are not exactly compatible. Uses `s.c` and `s.cdir` as computed
    /// for the residual; returns the CG iterations.
    fn newton_projection(
        s: &mut Scratch,
        cloth: &Cloth,
        dt: f64,
        max_cg: usize,
        cg_tol: f64,
    ) -> usize {
        let topo = cloth.topology();
        let inv = cloth.inverse_masses();
        let n = inv.len();
        let sqrt_w = |i: usize| inv[i].sqrt();
        // Levenberg regularisation, tiny against the operator's diagonal (~ w·degree).
        let mean_diag = inv.iter().map(|w| w * 8.0).sum::<f64>() / n as f64;
        let eps = 1e-10 * mean_diag;
        // out = (W^½ Jᵀ J W^½ + ε) y, with q_e = J_e W^½ y.
        fn apply(
            cloth: &Cloth,
            inv: &[f64],
            cdir: &[V3],
            eps: f64,
            y: &[V3],
            q: &mut [f64],
            out: &mut [V3],
        ) {
            let edges = cloth.topology().edges();
            fill(q, |e| {
                let (a, b) = (edges[e].a as usize, edges[e].b as usize);
                cdir[e].dot(&(y[b] * inv[b].sqrt() - y[a] * inv[a].sqrt()))
            });
            let q: &[f64] = q;
            fill(out, |i| {
                jacobian_transpose(cloth, cdir, q, i) * inv[i].sqrt() + y[i] * eps
            });
        }
        let (c, cdir) = (&s.c, &s.cdir);
        // rhs = −W^½ Jᵀ C, kept in r; x (here `pred` reused as y) starts at 0.
        fill(&mut s.r, |i| {
            -jacobian_transpose(cloth, cdir, c, i) * sqrt_w(i)
        });
        let diag = |i: usize| inv[i] * topo.incident_edges(i).len() as f64 * 0.5 + eps;
        s.pred.iter_mut().for_each(|y| *y = V3::zeros());
        {
            let (r, z) = (&s.r, &mut s.vel_hat);
            fill(z, |i| r[i] / diag(i));
        }
        s.vel_prev.copy_from_slice(&s.vel_hat); // search direction p
        let (r, z) = (&s.r, &s.vel_hat);
        let mut rz = det_sum(&mut s.chunk, n, |i| r[i].dot(&z[i]));
        let r0 = det_sum(&mut s.chunk, n, |i| r[i].norm_squared()).sqrt();
        let mut iterations = 0;
        if r0 > 0.0 {
            while iterations < max_cg {
                iterations += 1;
                apply(
                    cloth,
                    inv,
                    &s.cdir,
                    eps,
                    &s.vel_prev,
                    &mut s.cg_q,
                    &mut s.cg_y,
                );
                let (p, ap) = (&s.vel_prev, &s.cg_y);
                let pap = det_sum(&mut s.chunk, n, |i| p[i].dot(&ap[i]));
                if pap.is_nan() || pap <= 0.0 {
                    break;
                }
                let alpha = rz / pap;
                for i in 0..n {
                    s.pred[i] += s.vel_prev[i] * alpha;
                    s.r[i] -= s.cg_y[i] * alpha;
                }
                let r = &s.r;
                let rn = det_sum(&mut s.chunk, n, |i| r[i].norm_squared()).sqrt();
                if rn <= cg_tol * r0 {
                    break;
                }
                {
                    let (r, z) = (&s.r, &mut s.vel_hat);
                    fill(z, |i| r[i] / diag(i));
                }
                let (r, z) = (&s.r, &s.vel_hat);
                let rz_new = det_sum(&mut s.chunk, n, |i| r[i].dot(&z[i]));
                let beta = rz_new / rz;
                rz = rz_new;
                for i in 0..n {
                    s.vel_prev[i] = s.vel_hat[i] + s.vel_prev[i] * beta;
                }
            }
        }
        for i in 0..n {
            s.vel[i] += s.pred[i] * (sqrt_w(i) / dt);
        }
        iterations
    }
}
