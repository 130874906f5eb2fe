//! Stage 2: the internal axial forces p ≥ 0 (43)–(47) of the axial edges, by projected steepest
//! descent or its accelerated variant, to a relative tolerance; the step-size estimate λ_max, the
//! energy E and its gradient. (The diagonals carry nothing: they are not constraints any more,
//! `method.md` §2b; the phase machinery keeps its `diagonals` switch for the edge classes.)

use rayon::prelude::*;

use super::par::{PAR_MIN, SUM_CHUNK, det_sum, fill, resize};
use super::{Solver, V3};
use crate::cloth::Cloth;
use crate::params::{InternalMethod, StepParams, Tension};
use crate::state::ClothState;

/// One chunk of the fused internal-force pass: (chunk index, ((forces, previous forces),
/// partial sums)).
type ChunkItem<'a> = (usize, ((&'a mut [f64], &'a mut [f64]), &'a mut [f64; 2]));

/// ½ Σ |f_i|² over the free nodes (inverse mass > 0), summed deterministically.
fn free_energy(chunk: &mut Vec<f64>, f: &[V3], inv: &[f64]) -> f64 {
    0.5 * det_sum(chunk, f.len(), |i| {
        if inv[i] > 0.0 {
            f[i].norm_squared()
        } else {
            0.0
        }
    })
}

impl Solver {
    /// The internal-force stage: λ_max estimated when there is none, p warm-started from the
    /// state's forces (the diagonals' at zero), the axial phase to `internal_tolerance ×
    /// factor` of its projected gradient at p = 0 or `internal.max_iterations`, and F^m gathered
    /// (less the surface's reaction when a pressure stage is on). Returns the iterations, the
    /// final E over its value at p = 0, and whether the tolerance was met.
    pub(super) fn internal_forces(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
        factor: f64,
    ) -> (usize, f64, bool) {
        if params.internal.tension == Tension::Constraint {
            // The forces are the last step's constraint forces; nothing to balance.
            self.s.p.copy_from_slice(&state.axial_force);
            self.s.f_m.copy_from_slice(&self.s.f_sum);
            if self.pressure.is_some() {
                for (f, r) in self.s.f_m.iter_mut().zip(&self.s.reaction) {
                    *f -= r;
                }
            }
            return (0, 0.0, true);
        }
        if self.lambda.is_none() {
            self.lambda = Some([self.estimate_lambda(cloth, false), 1.0]);
        }
        self.s.p.copy_from_slice(&state.axial_force);
        for &e in cloth.diagonal_edge_list() {
            self.s.p[e as usize] = 0.0;
        }
        let e0 = self.energy_at_zero(cloth);
        let (iterations, converged) = self.internal_phase(cloth, params, false, factor);
        self.gather(cloth, false);
        let e = self.energy(cloth);
        let residual = if e0 > 0.0 { e / e0 } else { 0.0 };
        // The force the velocity takes (deviation from (18), `docs/solver.md`): F^sum without the
        // internal forces Σ p d. They lie along the edges at the start of the step, which the
        // converged shape stage's corrections span, so they change a converged step only at
        // second order — by their components along the motion as the edges turn, an explicit
        // force that pumped energy into a swinging drape at Δt 10 ms. p still sets the targets.
        self.s.f_m.copy_from_slice(&self.s.f_sum);
        if self.pressure.is_some() {
            // The surface's reaction was balanced in; the velocity carries the load into the
            // surface again, so that the contact's friction feels it.
            for (f, r) in self.s.f_m.iter_mut().zip(&self.s.reaction) {
                *f -= r;
            }
        }
        (iterations, residual, converged)
    }

    /// F^m = F_sum + Σ p d over incident edges (diagonals only when `diagonals`), from p.
    fn gather(&mut self, cloth: &Cloth, diagonals: bool) {
        self.gather_from(cloth, diagonals, false);
    }

    /// The same from p (`from_y` false) or from the extrapolated point y of the accelerated
    /// method (`from_y` true).
    fn gather_from(&mut self, cloth: &Cloth, diagonals: bool, from_y: bool) {
        let s = &mut self.s;
        let p: &[f64] = if from_y { &s.p_y } else { &s.p };
        let (dir, f_sum) = (&s.dir, &s.f_sum);
        fill(&mut s.f_m, |i| {
            let mut f = f_sum[i];
            for inc in cloth.incidence(i) {
                if diagonals || inc.axial {
                    let e = inc.edge as usize;
                    f += dir[e] * (inc.sign * p[e]);
                }
            }
            f
        });
    }

    /// E = ½ Σ over free nodes |F^m|².
    fn energy(&mut self, cloth: &Cloth) -> f64 {
        free_energy(&mut self.s.chunk, &self.s.f_m, cloth.inverse_masses())
    }

    /// E at p = 0: ½ Σ over free nodes of the squared external-plus-bending force.
    fn energy_at_zero(&mut self, cloth: &Cloth) -> f64 {
        free_energy(&mut self.s.chunk, &self.s.f_sum, cloth.inverse_masses())
    }

    /// ∂E/∂p_e = (F^m_a [a free] − F^m_b [b free])·d_e for the edges of one phase.
    fn gradient(&mut self, cloth: &Cloth, diagonals: bool) {
        let topo = cloth.topology();
        let edges = topo.edges();
        let inv = cloth.inverse_masses();
        let s = &mut self.s;
        let (f_m, dir) = (&s.f_m, &s.dir);
        fill(&mut s.grad, |e| {
            let edge = &edges[e];
            if edge.kind.is_axial() == diagonals {
                return 0.0;
            }
            let (a, b) = (edge.a as usize, edge.b as usize);
            let fa = if inv[a] > 0.0 { f_m[a] } else { V3::zeros() };
            let fb = if inv[b] > 0.0 { f_m[b] } else { V3::zeros() };
            (fa - fb).dot(&dir[e])
        });
    }

    /// λ_max of AᵀA restricted to one phase's edges, by power iteration on the current geometry
    /// (with a 10 % margin).
    fn estimate_lambda(&mut self, cloth: &Cloth, diagonals: bool) -> f64 {
        let edges = cloth.topology().edges();
        let in_phase = |e: usize| edges[e].kind.is_axial() != diagonals;
        if !(0..edges.len()).any(in_phase) {
            return 1.0;
        }
        let saved_sum = std::mem::take(&mut self.s.f_sum);
        self.s.f_sum = vec![V3::zeros(); saved_sum.len()];
        let saved_p = self.s.p.clone();
        for (e, p) in self.s.p.iter_mut().enumerate() {
            *p = if in_phase(e) {
                1.0 + 0.1 * ((e * 7919) % 13) as f64
            } else {
                0.0
            };
        }
        let mut lambda = 1.0;
        for _ in 0..40 {
            self.gather(cloth, diagonals);
            self.gradient(cloth, diagonals);
            let norm_p = self.s.p.iter().map(|x| x * x).sum::<f64>().sqrt();
            let norm_g = self.s.grad.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm_g == 0.0 {
                break;
            }
            lambda = norm_g / norm_p;
            let (grad, p) = (&self.s.grad, &mut self.s.p);
            for (pi, gi) in p.iter_mut().zip(grad) {
                *pi = gi / norm_g;
            }
        }
        self.s.f_sum = saved_sum;
        self.s.p = saved_p;
        1.1 * lambda.max(1e-12)
    }

    /// One phase of the internal-force solve (thesis (45)–(47)): projected steepest descent, or
    /// the accelerated variant; only this phase's p change. Returns the iterations used and
    /// whether the projected gradient met the tolerance.
    fn internal_phase(
        &mut self,
        cloth: &Cloth,
        params: &StepParams,
        diagonals: bool,
        factor: f64,
    ) -> (usize, bool) {
        let edges = cloth.topology().edges();
        let lambda = self.lambda.map_or(1.0, |l| l[usize::from(diagonals)]);
        let mut gamma = params.internal.step / lambda;
        let in_phase = |e: usize| edges[e].kind.is_axial() != diagonals;
        // Scale of the optimality test: the gradient with all forces zero (the load itself).
        for e in 0..self.s.p_y.len() {
            self.s.p_y[e] = if in_phase(e) { 0.0 } else { self.s.p[e] };
        }
        self.gather_from(cloth, diagonals, true);
        self.gradient(cloth, diagonals);
        let g_ref = self.projected_gradient_norm(cloth, diagonals, true);
        let e_zero = self.energy(cloth);
        self.gather(cloth, diagonals);
        let mut e_start = self.energy(cloth);
        if g_ref == 0.0 || e_start > e_zero {
            // Nothing to carry, or a warm start worse than no forces at all (the load changed):
            // start this phase from zero.
            for (e, p) in self.s.p.iter_mut().enumerate() {
                if in_phase(e) {
                    *p = 0.0;
                }
            }
            self.gather(cloth, diagonals);
            e_start = e_zero;
            if g_ref == 0.0 {
                return (0, true);
            }
        }
        let tol = params.internal.tolerance * factor * g_ref;
        self.s.p_prev.copy_from_slice(&self.s.p);
        self.s.p_warm.copy_from_slice(&self.s.p);
        let mut e_old = e_start;
        let mut iterations = 0;
        let mut converged = false;
        match params.internal.method {
            InternalMethod::SteepestDescent => {
                loop {
                    self.gradient(cloth, diagonals);
                    if self.projected_gradient_norm(cloth, diagonals, false) <= tol {
                        converged = true;
                        break;
                    }
                    if iterations >= params.internal.max_iterations {
                        break;
                    }
                    iterations += 1;
                    self.s.p_prev.copy_from_slice(&self.s.p);
                    let (grad, p) = (&self.s.grad, &mut self.s.p);
                    for (e, pe) in p.iter_mut().enumerate() {
                        if in_phase(e) {
                            *pe = (*pe - gamma * grad[e]).max(0.0);
                        }
                    }
                    self.gather(cloth, diagonals);
                    let e_new = self.energy(cloth);
                    if e_new > e_old * (1.0 + 1e-12) {
                        // Step too long for this geometry: back off and re-estimate next step.
                        self.s.p.copy_from_slice(&self.s.p_prev);
                        self.gather(cloth, diagonals);
                        gamma *= 0.5;
                        self.lambda = None;
                        continue;
                    }
                    e_old = e_new;
                }
            }
            InternalMethod::Accelerated => {
                (iterations, converged) =
                    self.accelerated_phase(cloth, params, diagonals, gamma, tol);
                self.gather(cloth, diagonals);
                if self.energy(cloth) > e_start * (1.0 + 1e-9) {
                    // Worse than the warm start (a step too long for this geometry): keep the
                    // warm start and re-estimate the step next time.
                    self.s.p.copy_from_slice(&self.s.p_warm);
                    self.gather(cloth, diagonals);
                    self.lambda = None;
                    converged = false;
                }
            }
        }
        (iterations, converged)
    }

    /// The accelerated internal-force iterations of one phase: FISTA with gradient restart
    /// (O'Donoghue & Candès 2015) on compact arrays of the phase's edges, three passes per
    /// iteration (gather at the extrapolated point; one fused pass for the gradient, the
    /// projected step, the optimality measure and the restart test; the next extrapolation),
    /// all parallel with deterministic chunked reductions. Writes the phase's forces back into
    /// `s.p`; returns the iterations and whether the projected gradient met `tol`.
    fn accelerated_phase(
        &mut self,
        cloth: &Cloth,
        params: &StepParams,
        diagonals: bool,
        gamma: f64,
        tol: f64,
    ) -> (usize, bool) {
        let list: &[u32] = if diagonals {
            cloth.diagonal_edge_list()
        } else {
            cloth.axial_edge_list()
        };
        let m = list.len();
        let slots = cloth.phase_slots();
        let edges = cloth.topology().edges();
        let inv = cloth.inverse_masses();
        let s = &mut self.s;
        for v in [&mut s.ph_p, &mut s.ph_prev, &mut s.ph_y] {
            v.clear();
            v.extend(list.iter().map(|&e| s.p[e as usize]));
        }
        let chunks = m.div_ceil(SUM_CHUNK);
        resize(&mut s.ph_partial, chunks, [0.0; 2]);
        let mut t: f64 = 1.0;
        let mut iterations = 0;
        let mut converged = false;
        while iterations < params.internal.max_iterations {
            // F^m at y: the phase's forces from y, the other phase's from p (fixed).
            {
                let (y, p, dir, f_sum) = (&s.ph_y, &s.p, &s.dir, &s.f_sum);
                fill(&mut s.f_m, |i| {
                    let mut f = f_sum[i];
                    for inc in cloth.incidence(i) {
                        let e = inc.edge as usize;
                        let force = if inc.axial != diagonals {
                            y[slots[e] as usize]
                        } else if diagonals {
                            p[e]
                        } else {
                            continue;
                        };
                        f += dir[e] * (inc.sign * force);
                    }
                    f
                });
            }
            // Fused: gradient at y, projected step, optimality and restart measures.
            {
                let (f_m, dir, y) = (&s.f_m, &s.dir, &s.ph_y);
                let body = |(c, ((p, prev), out)): ChunkItem<'_>| {
                    let (mut norm2, mut restart) = (0.0, 0.0);
                    for (k, (pk, prevk)) in p.iter_mut().zip(prev.iter_mut()).enumerate() {
                        let idx = c * SUM_CHUNK + k;
                        let e = list[idx] as usize;
                        let (a, b) = (edges[e].a as usize, edges[e].b as usize);
                        let fa = if inv[a] > 0.0 { f_m[a] } else { V3::zeros() };
                        let fb = if inv[b] > 0.0 { f_m[b] } else { V3::zeros() };
                        let g = (fa - fb).dot(&dir[e]);
                        let yk = y[idx];
                        let pg = if yk > 0.0 { g } else { g.min(0.0) };
                        norm2 += pg * pg;
                        let new = (yk - gamma * g).max(0.0);
                        restart += (yk - new) * (new - *pk);
                        *prevk = *pk;
                        *pk = new;
                    }
                    *out = [norm2, restart];
                };
                let zipped = s
                    .ph_p
                    .par_chunks_mut(SUM_CHUNK)
                    .zip(s.ph_prev.par_chunks_mut(SUM_CHUNK))
                    .zip(s.ph_partial.par_iter_mut());
                if m >= PAR_MIN {
                    zipped.enumerate().for_each(body);
                } else {
                    s.ph_p
                        .chunks_mut(SUM_CHUNK)
                        .zip(s.ph_prev.chunks_mut(SUM_CHUNK))
                        .zip(s.ph_partial.iter_mut())
                        .enumerate()
                        .for_each(body);
                }
            }
            let (norm2, restart) = s
                .ph_partial
                .iter()
                .fold((0.0, 0.0), |a, b| (a.0 + b[0], a.1 + b[1]));
            iterations += 1;
            if norm2.sqrt() <= tol {
                converged = true;
                break;
            }
            let t_next = 0.5 * (1.0 + (1.0 + 4.0 * t * t).sqrt());
            let beta = if restart > 0.0 {
                0.0
            } else {
                (t - 1.0) / t_next
            };
            t = if restart > 0.0 { 1.0 } else { t_next };
            let (p, prev) = (&s.ph_p, &s.ph_prev);
            fill(&mut s.ph_y, |k| (p[k] + beta * (p[k] - prev[k])).max(0.0));
        }
        for (k, &e) in list.iter().enumerate() {
            s.p[e as usize] = s.ph_p[k];
        }
        (iterations, converged)
    }

    /// Norm of the projected gradient over one phase's edges (components pushing a zero force
    /// below zero do not count): zero exactly at the constrained minimum. `at_y`: the forces
    /// are those of the extrapolated point.
    fn projected_gradient_norm(&self, cloth: &Cloth, diagonals: bool, at_y: bool) -> f64 {
        let edges = cloth.topology().edges();
        let p = if at_y { &self.s.p_y } else { &self.s.p };
        let g = &self.s.grad;
        (0..edges.len())
            .filter(|&e| edges[e].kind.is_axial() != diagonals)
            .map(|e| if p[e] > 0.0 { g[e] } else { g[e].min(0.0) })
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt()
    }
}
