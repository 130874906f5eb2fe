//! The impulse model (thesis §5.3.3, (65)–(72)): one code path for cloth against a body and
//! cloth against cloth.
//!
//! Along `d_ξ` (into the collided surface) the normal components `a_i`, `a_j` become `b_i`, `b_j`
//! by momentum conservation (65) and restitution ν (66); the tangential relative speed `c`
//! becomes `c − ρa` if `c > ρa`, else 0 (static friction ρ, (69)–(70)). atelier writes this as one
//! impulse on the node and its opposite on the collided side, spread over the triangle's vertices
//! by their barycentric weights: with the reduced mass `m = 1/(1/μ_i + 1/μ_j)` and the collided
//! point's effective mass `1/μ_j = Σ w_k²/μ_k` (a body: `1/μ_j = 0`, so `b_i = −νa_i + (1+ν)a_j`,
//! (67) in the limit), the relative normal speed becomes `−ν` times itself and momentum is
//! conserved exactly. The node moves with the mean velocity (72) over the step — its old velocity
//! until the contact at `Δt_c`, the new one for `Δt_n = Δt − Δt_c` — and leaves with the new one.

use crate::geom::V3;

/// Restitution and friction of a contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactMaterial {
    /// Restitution ν (0: the normal relative speed is removed, 1: reversed).
    pub restitution: f64,
    /// Static friction ρ.
    pub friction: f64,
}

/// What a contact does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// The node's velocity after the contact, `ṙ′` (71).
    pub exit: V3,
    /// The node's mean velocity over the step (72): its displacement is `mean·Δt`.
    pub mean: V3,
    /// Velocity change of each vertex of the collided triangle (zero for a body).
    pub vertex_dv: [V3; 3],
    /// The impulse on the node, N·s.
    pub impulse: V3,
}

/// The response of a node (velocity `v`, inverse mass `inv_m`) meeting the point with barycentric
/// weights `w` of a triangle (vertex velocities `u`, inverse masses `inv_mu`, all zero for a
/// body) at time `t_c` of a step `dt`; `normal` points from the surface towards the side the node
/// came from. `None` when neither side can move or they are not approaching.
#[allow(clippy::too_many_arguments)]
pub fn respond(
    v: &V3,
    inv_m: f64,
    u: [&V3; 3],
    inv_mu: [f64; 3],
    w: [f64; 3],
    normal: &V3,
    t_c: f64,
    dt: f64,
    material: ContactMaterial,
) -> Option<Response> {
    let inv_mj: f64 = (0..3).map(|k| w[k] * w[k] * inv_mu[k]).sum();
    let inv_sum = inv_m + inv_mj;
    if inv_sum <= 0.0 {
        return None;
    }
    let reduced = 1.0 / inv_sum;
    let d = -normal;
    let vj = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
    let rel = v - vj;
    let a = rel.dot(&d);
    if a <= 0.0 {
        return None;
    }
    let tangential = rel - d * a;
    let c = tangential.norm();
    let c_after = if c > material.friction * a {
        c - material.friction * a
    } else {
        0.0
    };
    let mut impulse = d * (-(1.0 + material.restitution) * a * reduced);
    if c > 0.0 {
        impulse += tangential * ((c_after - c) / c * reduced);
    }
    let exit = v + impulse * inv_m;
    let vertex_dv = [0, 1, 2].map(|k| -impulse * (w[k] * inv_mu[k]));
    let t_c = t_c.clamp(0.0, dt);
    let mean = if dt > 0.0 {
        (v * t_c + exit * (dt - t_c)) / dt
    } else {
        exit
    };
    Some(Response {
        exit,
        mean,
        vertex_dv,
        impulse,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const MAT: ContactMaterial = ContactMaterial {
        restitution: 0.3,
        friction: 0.4,
    };

    #[test]
    fn a_body_reflects_the_normal_speed_by_restitution_and_applies_friction() {
        let z = V3::zeros();
        let up = V3::new(0.0, 0.0, 1.0);
        // Slides: c = 3 > ρa = 0.8.
        let r = respond(
            &V3::new(3.0, 0.0, -2.0),
            1.0,
            [&z, &z, &z],
            [0.0; 3],
            [1.0 / 3.0; 3],
            &up,
            0.0,
            0.01,
            MAT,
        )
        .expect("approaching");
        assert_relative_eq!(r.exit.z, 0.6, epsilon = 1e-15);
        assert_relative_eq!(r.exit.x, 3.0 - 0.4 * 2.0, epsilon = 1e-15);
        // Sticks: c = 0.5 < ρa.
        let r = respond(
            &V3::new(0.5, 0.0, -2.0),
            1.0,
            [&z, &z, &z],
            [0.0; 3],
            [1.0 / 3.0; 3],
            &up,
            0.0,
            0.01,
            MAT,
        )
        .expect("approaching");
        assert_relative_eq!(r.exit.x, 0.0, epsilon = 1e-15);
        // A moving body: b_i = −ν a_i + (1 + ν) a_j along d = −n.
        let ub = V3::new(0.0, 0.0, 1.0);
        let r = respond(
            &V3::new(0.0, 0.0, -2.0),
            1.0,
            [&ub, &ub, &ub],
            [0.0; 3],
            [0.2, 0.3, 0.5],
            &up,
            0.0,
            0.01,
            MAT,
        )
        .expect("approaching");
        let (ai, aj) = (2.0, -1.0);
        assert_relative_eq!(-r.exit.z, -0.3 * ai + 1.3 * aj, epsilon = 1e-15);
        // Receding: nothing.
        assert!(
            respond(
                &V3::new(0.0, 0.0, 1.0),
                1.0,
                [&z, &z, &z],
                [0.0; 3],
                [1.0 / 3.0; 3],
                &up,
                0.0,
                0.01,
                MAT
            )
            .is_none()
        );
    }

    #[test]
    fn cloth_against_cloth_conserves_momentum() {
        let v = V3::new(0.7, -0.2, -3.1);
        let u = [
            V3::new(0.1, 0.3, 0.9),
            V3::new(-0.4, 0.2, 1.3),
            V3::new(0.0, -0.6, 0.2),
        ];
        let (m, mu) = (0.013, [0.021, 0.008, 0.017]);
        let w = [0.25, 0.45, 0.3];
        let n = V3::new(0.1, -0.2, 1.0).normalize();
        let r = respond(
            &v,
            1.0 / m,
            [&u[0], &u[1], &u[2]],
            mu.map(|x| 1.0 / x),
            w,
            &n,
            0.004,
            0.01,
            MAT,
        )
        .expect("approaching");
        let before = v * m + u[0] * mu[0] + u[1] * mu[1] + u[2] * mu[2];
        let after = r.exit * m + (0..3).map(|k| (u[k] + r.vertex_dv[k]) * mu[k]).sum::<V3>();
        assert!(
            (after - before).norm() <= 1e-12 * before.norm(),
            "{before} → {after}"
        );
        // The relative normal speed at the contact point is −ν times itself (66).
        let vj = |dv: [V3; 3]| (0..3).map(|k| (u[k] + dv[k]) * w[k]).sum::<V3>();
        let d = -n;
        let a = (v - vj([V3::zeros(); 3])).dot(&d);
        let b = (r.exit - vj(r.vertex_dv)).dot(&d);
        assert_relative_eq!(b, -0.3 * a, epsilon = 1e-12);
        // Mean velocity (72).
        assert_relative_eq!(r.mean, (v * 0.004 + r.exit * 0.006) / 0.01, epsilon = 1e-14);
    }
}
