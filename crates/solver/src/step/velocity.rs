//! Stage 3: the unconstrained velocity (18), with the bending stiffness implicit along the
//! normals (Jacobi-preconditioned BiCGSTAB).

use atelier_grid::{NO_NODE, SLOTS};

use super::par::fill;
use super::{Solver, V3};
use crate::cloth::Cloth;
use crate::params::{BendingModel, StepParams};
use crate::state::ClothState;

impl Solver {
    /// (18): ṙ⁰ = (μṙ + F^m Δt)/(μ + cΔt), with the bending stiffness k added implicitly along
    /// the normal, (μ + cΔt + kΔt²). Pinned nodes take their prescribed velocity. Returns the
    /// implicit solve's iterations and its final residual relative to its initial one (0 and 0
    /// when it did not run).
    pub(super) fn unconstrained_velocity(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
        dt: f64,
    ) -> (usize, f64) {
        let (mass, areas) = (cloth.masses(), cloth.topology().node_areas());
        let axial = cloth.bending_neighbours();
        let implicit = params.bending.implicit
            && !params.bending.off
            && params.bending.model == BendingModel::Thesis;
        let s = &mut self.s;
        let (f_m, normal) = (&s.f_m, &s.normal);
        let (vel0, pos) = (&state.velocities, &state.positions);
        fill(&mut s.vel, |i| {
            if cloth.is_pinned(i) {
                return V3::zeros();
            }
            let mu = mass[i];
            let c = params.damping * areas[i];
            (vel0[i] * mu + f_m[i] * dt) / (mu + c * dt)
        });
        let t1 = state.time + dt;
        for pin in cloth.pins() {
            let i = pin.node as usize;
            s.vel[i] = (pin.position(t1) - pos[i]) / dt;
        }
        if !implicit {
            return (0, 0.0);
        }
        // Implicit bending along the normals, linearised (method §2: explicit bending limits Δt
        // to ~2√(μ/k), k ≈ 16WB/h³, which scales with h²). Unknowns: the normal speeds w of the
        // free nodes; (μ + cΔt) w − Δt² K w = (μ + cΔt) n·ṙ_explicit, K the bending stiffness
        // for normal displacements (the same stencil as the force, with B), solved by
        // Jacobi-preconditioned BiCGSTAB to `bending.tolerance`. Statics are unchanged; rigid motions have K w = 0.
        let k_apply = |w: &[f64],
                       dm: &mut [f64],
                       out: &mut [f64],
                       s_coef: &[[f64; SLOTS]],
                       s_len: &[[f64; SLOTS]]| {
            fill(dm, |i| {
                let mut m = 0.0;
                for k in 0..SLOTS {
                    let a = axial[i][k];
                    if a == NO_NODE || s_coef[i][k] == 0.0 {
                        continue;
                    }
                    let l = s_len[i][k];
                    let deta = -2.0 * (w[a as usize] * normal[i].dot(&normal[a as usize]) - w[i])
                        / (l * l);
                    m += s_coef[i][k] * deta;
                }
                m
            });
            let dm: &[f64] = dm;
            fill(out, |i| {
                let mut f = 0.0;
                for k in 0..SLOTS {
                    let a = axial[i][k];
                    if a != NO_NODE {
                        f += (dm[a as usize] - dm[i]) / s_len[i][k];
                    }
                }
                f
            });
        };
        let diag = |i: usize| {
            let (mu, c) = (mass[i], params.damping * areas[i]);
            // Diagonal of −K: each slot's own δη term through M_i and M_a.
            let k: f64 = (0..SLOTS)
                .filter(|&slot| axial[i][slot] != NO_NODE)
                .map(|slot| {
                    let l = s.slot_len[i][slot];
                    2.0 * s.slot_coef[i][slot] / (l * l) * 3.0 / l
                })
                .sum();
            mu + c * dt + dt * dt * k
        };
        let free = |i: usize| !cloth.is_pinned(i);
        let vel = &s.vel;
        fill(&mut s.w, |i| normal[i].dot(&vel[i]));
        // rhs b = (μ + cΔt) w_explicit for free nodes; pinned w stay prescribed (moved to b).
        k_apply(&s.w, &mut s.w_dm, &mut s.w_ap, &s.slot_coef, &s.slot_len);
        for i in 0..s.w.len() {
            // r = b − A w with w = w_explicit: r = Δt² K w (free nodes).
            s.w_r[i] = if free(i) { dt * dt * s.w_ap[i] } else { 0.0 };
        }
        // The stencil is not exactly symmetric at free edges and clamps (the thesis's force is
        // not the gradient of an energy), so the solve is Jacobi-preconditioned BiCGSTAB.
        let n = s.w.len();
        let r0: f64 = s.w_r.iter().map(|x| x * x).sum::<f64>().sqrt();
        let (tol, cap) = (params.bending.tolerance * r0, params.bending.max_iterations);
        let (mut iterations, mut residual) = (0, 0.0);
        if r0 > 0.0 {
            let apply_a = |x: &[f64],
                           dm: &mut [f64],
                           out: &mut [f64],
                           s_coef: &[[f64; SLOTS]],
                           s_len: &[[f64; SLOTS]]| {
                k_apply(x, dm, out, s_coef, s_len);
                for i in 0..x.len() {
                    let (mu, c) = (mass[i], params.damping * areas[i]);
                    out[i] = if free(i) {
                        (mu + c * dt) * x[i] - dt * dt * out[i]
                    } else {
                        0.0
                    };
                }
            };
            let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
            let mut r_hat = std::mem::take(&mut s.w_rhat);
            r_hat.clear();
            r_hat.extend_from_slice(&s.w_r);
            let mut v = std::mem::take(&mut s.w_v);
            let mut y = std::mem::take(&mut s.w_y);
            let mut z = std::mem::take(&mut s.w_z);
            let mut t = std::mem::take(&mut s.w_t);
            for buf in [&mut v, &mut y, &mut z, &mut t] {
                buf.clear();
                buf.resize(n, 0.0);
            }
            let mut rho = 1.0;
            let mut alpha = 1.0;
            let mut omega = 1.0;
            s.w_p.iter_mut().for_each(|x| *x = 0.0);
            residual = r0;
            while iterations < cap {
                iterations += 1;
                let rho_new = dot(&r_hat, &s.w_r);
                if rho_new == 0.0 || omega == 0.0 {
                    break;
                }
                let beta = (rho_new / rho) * (alpha / omega);
                rho = rho_new;
                for i in 0..n {
                    s.w_p[i] = s.w_r[i] + beta * (s.w_p[i] - omega * v[i]);
                    y[i] = if free(i) { s.w_p[i] / diag(i) } else { 0.0 };
                }
                apply_a(&y, &mut s.w_dm, &mut v, &s.slot_coef, &s.slot_len);
                let rv = dot(&r_hat, &v);
                if rv == 0.0 || rv.is_nan() {
                    break;
                }
                alpha = rho / rv;
                for i in 0..n {
                    s.w[i] += alpha * y[i];
                    s.w_r[i] -= alpha * v[i];
                }
                residual = dot(&s.w_r, &s.w_r).sqrt();
                if residual <= tol {
                    break;
                }
                for (i, zi) in z.iter_mut().enumerate() {
                    *zi = if free(i) { s.w_r[i] / diag(i) } else { 0.0 };
                }
                apply_a(&z, &mut s.w_dm, &mut t, &s.slot_coef, &s.slot_len);
                let tt = dot(&t, &t);
                omega = if tt > 0.0 { dot(&t, &s.w_r) / tt } else { 0.0 };
                for i in 0..n {
                    s.w[i] += omega * z[i];
                    s.w_r[i] -= omega * t[i];
                }
                residual = dot(&s.w_r, &s.w_r).sqrt();
                if residual <= tol {
                    break;
                }
            }
            s.w_rhat = r_hat;
            s.w_v = v;
            s.w_y = y;
            s.w_z = z;
            s.w_t = t;
        }
        let w = &s.w;
        for (i, v) in s.vel.iter_mut().enumerate() {
            if free(i) {
                let n = normal[i];
                *v += n * (w[i] - n.dot(v));
            }
        }
        (iterations, if r0 > 0.0 { residual / r0 } else { 0.0 })
    }
}
