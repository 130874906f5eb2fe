//! The collision model against reference values: Coulomb friction on a slope, restitution in a
//! bounce, no tunnelling for fast particles, and the one-sided rule.

use atelier_collide::broad::BroadKind;
use atelier_collide::{ClothView, Collider, ContactMaterial, ContactParams, V3};
use proptest::prelude::*;

const G: f64 = 9.80665;

/// A particle under gravity colliding with a static body, stepped by symplectic Euler with the
/// collider's mean and exit velocities.
struct Particle {
    p: V3,
    v: V3,
    normal: V3,
}

fn step(c: &mut Collider, part: &mut Particle, dt: f64) {
    part.v += V3::new(0.0, 0.0, -G) * dt;
    let mut vel = [part.v];
    let mut exit = [V3::zeros()];
    c.resolve(
        ClothView {
            positions: &[part.p],
            velocities: &mut vel,
            exit: &mut exit,
            inverse_masses: &[1.0],
            triangles: &[],
            normals: &[part.normal],
            planes: &mut [],
        },
        dt,
    );
    part.p += vel[0] * dt;
    part.v = vel[0] + exit[0];
}

fn params(restitution: f64, friction: f64, broad: BroadKind) -> ContactParams {
    ContactParams {
        material: ContactMaterial {
            restitution,
            friction,
        },
        thickness: 1e-4,
        staged: false,
        broad,
        ..ContactParams::default()
    }
}

/// A square plane 4 m wide through the origin, tilted by `alpha` about the x axis (two
/// counter-clockwise triangles, normal up the slope's outside).
fn slope(alpha: f64) -> (Vec<V3>, Vec<[u32; 3]>) {
    let (c, s) = (alpha.cos(), alpha.sin());
    let corner = |x: f64, y: f64| V3::new(x, y * c, y * s);
    (
        vec![
            corner(-2.0, -2.0),
            corner(2.0, -2.0),
            corner(2.0, 2.0),
            corner(-2.0, 2.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

#[test]
fn a_particle_on_a_slope_sticks_below_the_friction_angle_and_slides_above() {
    let dt = 1e-3;
    for rho in [0.2f64, 0.5, 0.9] {
        for (alpha, slides) in [(rho.atan() * 0.9, false), (rho.atan() * 1.1, true)] {
            let (v, t) = slope(alpha);
            let mut c = Collider::new(params(0.0, rho, BroadKind::Bvh)).expect("params");
            c.set_body(&v, &v, &t, dt).expect("body");
            let normal = V3::new(0.0, -alpha.sin(), alpha.cos());
            let mut part = Particle {
                p: V3::zeros(),
                v: V3::zeros(),
                normal,
            };
            let steps = 1000;
            for _ in 0..steps {
                step(&mut c, &mut part, dt);
            }
            let along = -part.p.dot(&V3::new(0.0, alpha.cos(), alpha.sin()));
            let off = part.p.dot(&normal);
            assert!(
                off.abs() < 1e-6,
                "ρ {rho} α {alpha}: left the slope by {off}"
            );
            if slides {
                // Coulomb: a = g (sin α − ρ cos α), s = a t²/2 (discrete sum: a dt² n(n+1)/2).
                let a = G * (alpha.sin() - rho * alpha.cos());
                let expect = a * dt * dt * (steps * (steps + 1)) as f64 / 2.0;
                assert!(
                    (along - expect).abs() < 0.02 * expect,
                    "ρ {rho}: slid {along} m, Coulomb {expect} m"
                );
            } else {
                assert!(
                    along.abs() < 1e-12,
                    "ρ {rho}: crept {along} m below the friction angle"
                );
            }
        }
    }
}

#[test]
fn a_bounce_rises_to_restitution_squared_of_the_drop() {
    for (nu, broad) in [(0.5, BroadKind::Bvh), (0.8, BroadKind::Projection)] {
        let (v, t) = slope(0.0);
        let dt = 1e-5;
        let mut c = Collider::new(params(nu, 0.0, broad)).expect("params");
        c.set_body(&v, &v, &t, dt).expect("body");
        let h = 0.5;
        let mut part = Particle {
            p: V3::new(0.3, 0.1, h),
            v: V3::zeros(),
            normal: V3::z(),
        };
        let (mut bounced, mut apex) = (false, 0.0f64);
        for _ in 0..300_000 {
            step(&mut c, &mut part, dt);
            if part.v.z > 0.0 {
                bounced = true;
            }
            if bounced {
                apex = apex.max(part.p.z);
                if part.v.z < 0.0 {
                    break;
                }
            }
        }
        let ratio = apex / h;
        assert!(
            (ratio - nu * nu).abs() < 0.01 * nu * nu,
            "ν {nu}: rose to {ratio} of the drop, expected {}",
            nu * nu
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    /// Fast particles (up to 20 m/s at Δt 0.01 s) against triangles moving up to 5 m/s never end
    /// a step on the far side of the triangle they crossed.
    #[test]
    fn no_tunnelling(
        tri in prop::array::uniform3(prop::array::uniform3(-0.5f64..0.5)),
        tri_v in prop::array::uniform3(-5.0f64..5.0),
        start in prop::array::uniform3(-0.5f64..0.5),
        vel in prop::array::uniform3(-20.0f64..20.0),
        projection in any::<bool>(),
    ) {
        let dt = 0.01;
        let x: Vec<V3> = tri.iter().map(|q| V3::new(q[0], q[1], q[2])).collect();
        let n = (x[1] - x[0]).cross(&(x[2] - x[0]));
        prop_assume!(n.norm() > 1e-3);
        let n = n.normalize();
        let u = V3::new(tri_v[0], tri_v[1], tri_v[2]);
        let end: Vec<V3> = x.iter().map(|q| q + u * dt).collect();
        let p = V3::new(start[0], start[1], start[2]);
        let v = V3::new(vel[0], vel[1], vel[2]);
        // Start in front of the triangle's plane by more than the skin.
        prop_assume!((p - x[0]).dot(&n) > 1e-3);
        let broad = if projection { BroadKind::Projection } else { BroadKind::Bvh };
        let mut c = Collider::new(params(0.2, 0.4, broad)).expect("params");
        c.set_body(&x, &end, &[[0, 1, 2]], dt).expect("body");
        let mut vels = [v];
        let mut exit = [V3::zeros()];
        c.resolve(ClothView {
            positions: &[p],
            velocities: &mut vels,
            exit: &mut exit,
            inverse_masses: &[1.0],
            triangles: &[],
            normals: &[],
            planes: &mut [],
        }, dt);
        let q = p + vels[0] * dt;
        // Relative to the triangle (it translates): the path p → q against the static triangle
        // at the start must not cross it.
        let q_rel = q - u * dt;
        let (s0, s1) = ((p - x[0]).dot(&n), (q_rel - x[0]).dot(&n));
        if s1 < -1e-9 {
            // Crossed the plane: the crossing must lie outside the triangle.
            let t = s0 / (s0 - s1);
            let c = p + (q_rel - p) * t;
            let w = atelier_collide::narrow::barycentric(&c, [&x[0], &x[1], &x[2]]);
            prop_assert!(w.iter().any(|&k| k < -1e-9), "tunnelled: s {s0} → {s1}, at {w:?}");
        }
    }
}

#[test]
fn one_sided_contact_lets_a_node_through_from_outside_and_catches_it_inside() {
    // A body surface facing +z; nodes falling onto it from above.
    let (v, t) = slope(0.0);
    let dt = 0.01;
    let one_sided = ContactParams {
        one_sided: true,
        ..params(0.0, 0.0, BroadKind::Bvh)
    };
    for (node_normal, caught) in [(V3::z(), true), (-V3::z(), false)] {
        let mut c = Collider::new(one_sided).expect("params");
        c.set_body(&v, &v, &t, dt).expect("body");
        let mut part = Particle {
            p: V3::new(0.0, 0.0, 0.05),
            v: V3::new(0.0, 0.0, -2.0),
            normal: node_normal,
        };
        for _ in 0..10 {
            step(&mut c, &mut part, dt);
        }
        if caught {
            assert!(part.p.z > -1e-9, "not caught: z = {}", part.p.z);
        } else {
            assert!(part.p.z < -0.1, "not let through: z = {}", part.p.z);
        }
    }
}

#[test]
fn bad_contact_parameters_and_bodies_are_refused() {
    let bad = ContactParams {
        material: ContactMaterial {
            restitution: 1.5,
            friction: 0.3,
        },
        ..ContactParams::default()
    };
    assert!(Collider::new(bad).is_err());
    let mut c = Collider::new(ContactParams::default()).expect("params");
    let v = vec![V3::zeros(); 3];
    assert!(c.set_body(&v, &v[..2], &[[0, 1, 2]], 0.01).is_err());
    assert!(c.set_body(&v, &v, &[[0, 1, 3]], 0.01).is_err());
    let nan = vec![V3::zeros(), V3::new(f64::NAN, 0.0, 0.0), V3::zeros()];
    assert!(c.set_body(&nan, &nan, &[[0, 1, 2]], 0.01).is_err());
}

#[test]
fn without_a_body_or_self_collision_nothing_is_built_or_done() {
    let mut c = Collider::new(ContactParams::default()).expect("params");
    assert!(!c.is_active());
    let mut vel = [V3::new(0.0, 0.0, -1.0)];
    let mut exit = [V3::zeros()];
    c.resolve(
        ClothView {
            positions: &[V3::zeros()],
            velocities: &mut vel,
            exit: &mut exit,
            inverse_masses: &[1.0],
            triangles: &[],
            normals: &[],
            planes: &mut [],
        },
        0.01,
    );
    assert_eq!(c.take_stats().candidates, 0);
    assert_eq!(vel[0], V3::new(0.0, 0.0, -1.0));
}

#[test]
fn self_collision_stops_a_node_at_a_cloth_triangle_and_conserves_momentum() {
    // Cloth: a triangle (nodes 0–2) at rest at z = 0 and a loose node 3 falling onto it; masses
    // differ. The triangle's own nodes never collide with it.
    let x = [
        V3::new(0.0, 0.0, 0.0),
        V3::new(0.2, 0.0, 0.0),
        V3::new(0.0, 0.2, 0.0),
        V3::new(0.05, 0.05, 0.03),
    ];
    let masses = [0.002, 0.003, 0.0025, 0.001];
    let inv: Vec<f64> = masses.iter().map(|m| 1.0 / m).collect();
    let mut vel = [
        V3::zeros(),
        V3::zeros(),
        V3::zeros(),
        V3::new(0.3, 0.0, -6.0),
    ];
    let mut exit = [V3::zeros(); 4];
    let before: V3 = vel.iter().zip(&masses).map(|(v, m)| v * *m).sum();
    let params = ContactParams {
        self_collision: true,
        ..params(0.2, 0.3, BroadKind::Bvh)
    };
    let mut c = Collider::new(params).expect("params");
    let dt = 0.01;
    c.resolve(
        ClothView {
            positions: &x,
            velocities: &mut vel,
            exit: &mut exit,
            inverse_masses: &inv,
            triangles: &[[0, 1, 2]],
            normals: &[],
            planes: &mut [],
        },
        dt,
    );
    let stats = c.take_stats();
    assert_eq!(stats.self_hits, 1, "{stats:?}");
    let exit_v: Vec<V3> = vel.iter().zip(&exit).map(|(v, e)| v + e).collect();
    let after: V3 = exit_v.iter().zip(&masses).map(|(v, m)| v * *m).sum();
    assert!(
        (after - before).norm() <= 1e-12 * before.norm(),
        "{before} → {after}"
    );
    // The node ends the step above the (moving) triangle's plane.
    let end: Vec<V3> = (0..4).map(|k| x[k] + vel[k] * dt).collect();
    let n = (end[1] - end[0]).cross(&(end[2] - end[0])).normalize();
    assert!((end[3] - end[0]).dot(&n) >= -1e-12);
}

#[test]
fn a_node_slightly_inside_the_body_is_moved_out_within_the_step() {
    let (v, t) = slope(0.0);
    let dt = 0.01;
    for (depth, recovered) in [(0.003, true), (0.02, false)] {
        let mut c = Collider::new(params(0.0, 0.0, BroadKind::Bvh)).expect("params");
        c.set_body(&v, &v, &t, dt).expect("body");
        let p = V3::new(0.1, 0.2, -depth);
        let mut vel = [V3::zeros()];
        let mut exit = [V3::zeros()];
        c.resolve(
            ClothView {
                positions: &[p],
                velocities: &mut vel,
                exit: &mut exit,
                inverse_masses: &[1.0],
                triangles: &[],
                normals: &[],
                planes: &mut [],
            },
            dt,
        );
        let end = p + vel[0] * dt;
        if recovered {
            assert!(end.z.abs() < 1e-12, "ends at {}", end.z);
            assert_eq!(c.take_stats().recovered, 1);
        } else {
            assert!(
                (end.z + depth).abs() < 1e-15,
                "deeper than the recovery depth: left alone"
            );
        }
    }
}

/// A low square pyramid (base ±5 cm at z = 0, apex 1 cm up) closed by its base, and a square
/// sheet of two triangles 8 mm up, corners at (±2, ±2) cm: every corner is 2 mm above the
/// pyramid's face, so node contact leaves the sheet where it is, while the apex pokes 2 mm
/// through the sheet's diagonal. Returns the sheet's height over the apex after each node is
/// moved onto its plane where it lies behind it (what the shape solve does), the nodes that
/// had a plane, and the nodes whose plane the apex lifted.
fn sheet_over_the_apex(params: ContactParams) -> (f64, usize, usize) {
    let body = vec![
        V3::new(-0.05, -0.05, 0.0),
        V3::new(0.05, -0.05, 0.0),
        V3::new(0.05, 0.05, 0.0),
        V3::new(-0.05, 0.05, 0.0),
        V3::new(0.0, 0.0, 0.01),
    ];
    let tris = vec![
        [0, 1, 4],
        [1, 2, 4],
        [2, 3, 4],
        [3, 0, 4],
        [0, 2, 1],
        [0, 3, 2],
    ];
    let mut c = Collider::new(params).expect("params");
    c.set_body(&body, &body, &tris, 1e-3).expect("body");
    let mut x = vec![
        V3::new(-0.02, -0.02, 0.008),
        V3::new(0.02, -0.02, 0.008),
        V3::new(0.02, 0.02, 0.008),
        V3::new(-0.02, 0.02, 0.008),
    ];
    let sheet = [[0u32, 1, 2], [0, 2, 3]];
    let mut vel = vec![V3::zeros(); 4];
    let inv = [1.0; 4];
    let mut planes = vec![atelier_collide::ContactPlane::default(); 4];
    c.transfer(&x, &mut vel, &inv, &[], &mut planes);
    let own = planes.iter().filter(|p| p.normal != V3::zeros()).count();
    let lifted = c.vertex_planes(&x, &inv, &sheet, &mut planes);
    for (xi, p) in x.iter_mut().zip(&planes) {
        let d = (*xi - p.point).dot(&p.normal);
        if d < 0.0 {
            *xi -= p.normal * d;
        }
    }
    // The sheet's height at the apex's (x, y) = (0, 0), on the diagonal 0–2, along the apex's
    // normal (+z).
    let height = 0.5 * (x[0].z + x[2].z) - 0.01;
    (height, own, lifted)
}

#[test]
fn a_body_vertex_under_a_cloth_triangle_lifts_the_triangle_over_it() {
    let base = ContactParams {
        staged: false,
        vertex_planes: true,
        ..ContactParams::default()
    };
    // Node contact alone: all four nodes have a plane and lie in front of it; the apex stays
    // 2 mm through the sheet.
    let off = ContactParams {
        vertex_planes: false,
        ..base
    };
    let (height, own, lifted) = sheet_over_the_apex(off);
    assert_eq!((own, lifted), (4, 0));
    assert!((height + 0.002).abs() < 1e-12, "{height}");
    // With body-vertex planes the sheet clears the apex by the skin.
    let (height, own, lifted) = sheet_over_the_apex(base);
    // The two nodes of the diagonal the apex's line meets; the other two weigh nothing there.
    assert_eq!((own, lifted), (4, 2));
    assert!((height - base.thickness).abs() < 1e-12, "{height}");
    // One-sided contact (a garment passing through the body): nothing lifted.
    let one_sided = ContactParams {
        one_sided: true,
        ..base
    };
    let (_, _, lifted) = sheet_over_the_apex(one_sided);
    assert_eq!(lifted, 0);
}
