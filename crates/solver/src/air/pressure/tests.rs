//! Tests of [`super`].

use super::*;
use approx::assert_relative_eq;

/// A flat square patch of `n × n` nodes, side `s`, lifted to height `h` above z = 0.
fn patch(n: usize, s: f64, h: f64) -> (Vec<V3>, Vec<[u32; 3]>, Vec<bool>) {
    let mut p = Vec::new();
    let mut boundary = Vec::new();
    for j in 0..n {
        for i in 0..n {
            p.push(V3::new(
                s * i as f64 / (n - 1) as f64,
                s * j as f64 / (n - 1) as f64,
                h,
            ));
            boundary.push(i == 0 || j == 0 || i == n - 1 || j == n - 1);
        }
    }
    let mut t = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let k = (j * n + i) as u32;
            let m = n as u32;
            t.push([k, k + 1, k + m + 1]);
            t.push([k, k + m + 1, k + m]);
        }
    }
    (p, t, boundary)
}

/// A flat patch lifted above the plane with trapped air v₀ at volume v: every node is pushed
/// along +z (out of the bubble) when P_b > P_a, along −z (into it) when P_b < P_a, by
/// S·|P_b − P_a|, and the pressure is Boyle's P_a·v₀/v.
#[test]
fn the_force_on_a_flat_lifted_patch_has_the_right_direction_and_size() {
    let (s, h) = (0.3, 0.004);
    let (p, t, boundary) = patch(11, s, h);
    let area = vec![s * s / 121.0; p.len()];
    let v = s * s * h;
    for (air, sign) in [(2.0 * v, 1.0), (0.5 * v, -1.0), (0.0, -1.0)] {
        let mut model = PressureModel::new(
            PressureParams {
                air,
                ..PressureParams::default()
            },
            plane_surface(),
        );
        let mut f = vec![V3::zeros(); p.len()];
        model.add_forces(&p, &t, &area, &boundary, 0.0, &mut f);
        let r = model.report().clone();
        assert_relative_eq!(r.volume, v, max_relative = 1e-12);
        let pb = ATMOSPHERE * air / v;
        assert_relative_eq!(r.pressure, pb, max_relative = 1e-12);
        for fi in &f {
            assert!(fi.x.abs() < 1e-9 && fi.y.abs() < 1e-9);
            assert_relative_eq!(fi.z, area[0] * (pb - ATMOSPHERE), max_relative = 1e-9);
            assert!(fi.z * sign > 0.0, "{} against {sign}", fi.z);
        }
    }
}

/// Boyle's law over a quasi-static lift: a sealed patch lifted from 2 mm to 40 mm keeps
/// P·V = P_a·v₀ in every state, in both bubble models (the pocket is sealed: its edge rests
/// on the plane).
#[test]
fn boyle_holds_in_a_sealed_pocket_over_a_lift() {
    let (s, n) = (0.3, 21);
    let air = 4e-4;
    for bubbles in [Bubbles::Single, Bubbles::Pockets { contact: 1e-3 }] {
        let mut model = PressureModel::new(
            PressureParams {
                air,
                bubbles,
                ..PressureParams::default()
            },
            plane_surface(),
        );
        for k in 0..20 {
            let lift = 0.002 + 0.038 * k as f64 / 19.0;
            // A dome: the edge on the plane, the inside raised (sealed by its edge).
            let (mut p, t, boundary) = patch(n, s, 0.0);
            for q in &mut p {
                let (u, v) = (q.x / s, q.y / s);
                q.z = lift * 16.0 * u * (1.0 - u) * v * (1.0 - v);
            }
            let area = vec![s * s / (n * n) as f64; p.len()];
            let mut f = vec![V3::zeros(); p.len()];
            model.add_forces(&p, &t, &area, &boundary, 1e-3, &mut f);
            let r = model.report().clone();
            assert_eq!(r.bubbles.len(), 1, "{bubbles:?}");
            assert!(!r.bubbles[0].vented);
            assert_relative_eq!(r.pressure * r.volume, ATMOSPHERE * air, max_relative = 1e-9);
        }
    }
}

/// Pockets: two separate domes are two pockets with their own pressures; one touching the
/// cloth's edge is vented (atmospheric pressure, no force); nodes in contact feel nothing.
#[test]
fn separate_domes_are_separate_pockets_and_an_open_one_is_vented() {
    let (s, n) = (0.4, 41);
    let (mut p, t, boundary) = patch(n, s, 0.0);
    let dome = |q: &V3, cx: f64, cy: f64, r: f64, h: f64| {
        let d2 = ((q.x - cx).powi(2) + (q.y - cy).powi(2)) / (r * r);
        if d2 < 1.0 { h * (1.0 - d2) } else { 0.0 }
    };
    for q in &mut p {
        // Two sealed domes, and one reaching past the edge at x = 0.
        q.z = dome(q, 0.12, 0.2, 0.06, 0.02)
            + dome(q, 0.28, 0.2, 0.06, 0.01)
            + dome(q, 0.0, 0.05, 0.05, 0.01);
    }
    let area = vec![s * s / (n * n) as f64; p.len()];
    let mut model = PressureModel::new(
        PressureParams {
            air: 0.0,
            bubbles: Bubbles::Pockets { contact: 1e-4 },
            ..PressureParams::default()
        },
        plane_surface(),
    );
    let mut f = vec![V3::zeros(); p.len()];
    model.add_forces(&p, &t, &area, &boundary, 0.0, &mut f);
    let r = model.report().clone();
    assert_eq!(r.bubbles.len(), 3);
    assert_eq!(r.bubbles.iter().filter(|b| b.vented).count(), 1);
    for b in &r.bubbles {
        if b.vented {
            assert_relative_eq!(b.pressure, ATMOSPHERE);
        } else {
            // Lifted off a vacuum (no air at the start): the whole atmosphere presses.
            assert!(b.pressure.abs() < 1e-12, "{}", b.pressure);
        }
    }
    // A node far from every dome feels no force.
    let far = 35 * n + 20;
    assert!(f[far].norm() < 1e-12);
}

/// The leak lets air into a pocket below atmospheric pressure: its air grows by
/// P_a·q·A·(P_a − P_b)·Δt per step.
#[test]
fn a_leak_fills_a_pocket_below_the_atmosphere() {
    let (s, n) = (0.3, 11);
    let (p, t, boundary) = patch(n, s, 0.01);
    let area = vec![s * s / (n * n) as f64; p.len()];
    let q = 1e-9;
    let mut model = PressureModel::new(
        PressureParams {
            air: 0.0,
            leak: q,
            ..PressureParams::default()
        },
        plane_surface(),
    );
    let mut f = vec![V3::zeros(); p.len()];
    let dt = 0.01;
    model.add_forces(&p, &t, &area, &boundary, dt, &mut f);
    let r0 = model.report().clone();
    let a = r0.lifted_area;
    assert_relative_eq!(a, s * s, max_relative = 1e-12);
    let air = model.bubbles()[0].air;
    assert_relative_eq!(
        air,
        dt * ATMOSPHERE * q * a * ATMOSPHERE,
        max_relative = 1e-12
    );
}

fn plane_surface() -> Surface {
    Surface::Plane {
        plane: Plane::horizontal(0.0),
        rest: 0.0,
    }
}

/// A smooth dome of height `h` and radius `r` centred at (cx, cy), zero outside.
fn dome(q: &V3, cx: f64, cy: f64, r: f64, h: f64) -> f64 {
    let d2 = ((q.x - cx).powi(2) + (q.y - cy).powi(2)) / (r * r);
    if d2 < 1.0 {
        h * (1.0 - d2).powi(2)
    } else {
        0.0
    }
}

/// Two sealed pockets keep their own air: squeezing one (its dome lowered from 10 to 4 mm
/// in steps) raises its pressure by Boyle's law, P·V = K of its own, while the other's
/// volume, air and pressure stay as they were.
#[test]
fn two_pockets_each_keep_their_own_air_and_pressure() {
    let (s, n) = (0.4, 41);
    let (flat, t, boundary) = patch(n, s, 0.0);
    let area = vec![s * s / (n * n) as f64; flat.len()];
    let mut model = PressureModel::new(
        PressureParams {
            air: 0.0,
            bubbles: Bubbles::Pockets { contact: 1e-4 },
            ..PressureParams::default()
        },
        plane_surface(),
    );
    let shape = |h1: f64| -> Vec<V3> {
        flat.iter()
            .map(|q| {
                V3::new(
                    q.x,
                    q.y,
                    dome(q, 0.12, 0.2, 0.07, h1) + dome(q, 0.28, 0.2, 0.07, 0.01),
                )
            })
            .collect()
    };
    // The first evaluation shares the air by volume: give each dome its own volume's worth
    // (P = P_a at the start).
    let start = shape(0.01);
    let mut f = vec![V3::zeros(); start.len()];
    model.params.air = plane_volume_of(&start, &t);
    model.add_forces(&start, &t, &area, &boundary, 0.0, &mut f);
    let r0 = model.report().clone();
    assert_eq!(r0.bubbles.len(), 2);
    let (k1, k2) = (r0.bubbles[0].air, r0.bubbles[1].air);
    for b in &r0.bubbles {
        assert!(!b.vented);
        assert_relative_eq!(b.pressure, ATMOSPHERE, max_relative = 1e-9);
    }
    let mut last = ATMOSPHERE;
    for k in 1..=6 {
        let h1 = 0.01 - 0.001 * k as f64;
        let p = shape(h1);
        model.add_forces(&p, &t, &area, &boundary, 0.0, &mut f);
        let r = model.report().clone();
        assert_eq!(r.bubbles.len(), 2);
        // Pocket order follows the node order: the squeezed dome (lower x) comes first.
        let (b1, b2) = (&r.bubbles[0], &r.bubbles[1]);
        assert_relative_eq!(b1.air, k1, max_relative = 1e-12);
        assert_relative_eq!(b2.air, k2, max_relative = 1e-12);
        assert_relative_eq!(b1.pressure * b1.volume, k1, max_relative = 1e-9);
        assert_relative_eq!(b2.pressure, ATMOSPHERE, max_relative = 1e-9);
        assert!(b1.pressure > last, "{} ≤ {last}", b1.pressure);
        last = b1.pressure;
    }
    // Squeezed to 40 % of its height (the volume too, the shape being the same), the
    // first pocket is at 2.5 atmospheres.
    assert_relative_eq!(last / ATMOSPHERE, 2.5, max_relative = 0.05);
}

/// (Y3.10) over the whole cloth.
fn plane_volume_of(p: &[V3], t: &[[u32; 3]]) -> f64 {
    super::super::volume::plane_volume(p, t, &Plane::horizontal(0.0), 0.0)
}

/// The breakthrough pressure: a sealed vacuum lifted off the plane stays at P_a − Δp (air
/// comes in through the cloth: K = (P_a − Δp)·V), and a bubble squeezed past P_a + Δp lets
/// air out.
#[test]
fn beyond_the_breakthrough_pressure_air_passes_the_cloth() {
    let (s, n) = (0.3, 21);
    let (mut p, t, boundary) = patch(n, s, 0.0);
    for q in &mut p {
        q.z = dome(q, 0.15, 0.15, 0.1, 0.02);
    }
    let area = vec![s * s / (n * n) as f64; p.len()];
    let dp = 10_000.0;
    let v = plane_volume_of(&p, &t);
    for (air, expected) in [(0.0, ATMOSPHERE - dp), (3.0 * v, ATMOSPHERE + dp)] {
        let mut model = PressureModel::new(
            PressureParams {
                air,
                breakthrough: Some(dp),
                ..PressureParams::default()
            },
            plane_surface(),
        );
        let mut f = vec![V3::zeros(); p.len()];
        model.add_forces(&p, &t, &area, &boundary, 0.0, &mut f);
        let b = &model.bubbles()[0];
        assert_relative_eq!(b.pressure, expected, max_relative = 1e-12);
        assert_relative_eq!(b.air, expected * v, max_relative = 1e-9);
    }
    // Within the band nothing passes.
    let mut model = PressureModel::new(
        PressureParams {
            air: 1.05 * v,
            breakthrough: Some(dp),
            ..PressureParams::default()
        },
        plane_surface(),
    );
    let mut f = vec![V3::zeros(); p.len()];
    model.add_forces(&p, &t, &area, &boundary, 0.0, &mut f);
    assert_relative_eq!(
        model.bubbles()[0].air,
        ATMOSPHERE * 1.05 * v,
        max_relative = 1e-12
    );
}

/// A cloth over a body (the thesis's future work): a sheet wrapped at radius R + d around a
/// cylinder of radius R (a 720-sided prism, `RigidParts`), over an angle 2α and a length L,
/// traps V = α·L·((R + d)² − R²) between itself and its footprint, and Boyle's law holds in
/// it as d grows from 2 to 20 mm.
#[test]
fn the_bubble_over_a_cylinder_has_the_shell_volume_and_obeys_boyle() {
    let (radius, length) = (0.05, 0.4);
    let (cv, ct) = atelier_collide::shapes::cylinder(radius, length, 720, 2);
    let parts = RigidParts::new(&[(&cv, &ct)]).expect("closed cylinder");
    // The cylinder's axis is y (from 0 to −length); the sheet spans the angle [−α, α]
    // around +z and y in [−0.3, −0.1].
    let (alpha, y0, y1, n_a, n_y) = (0.9f64, -0.3, -0.1, 61, 41);
    let sheet = |d: f64| -> (Vec<V3>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for j in 0..n_y {
            for i in 0..n_a {
                let a = -alpha + 2.0 * alpha * i as f64 / (n_a - 1) as f64;
                let y = y0 + (y1 - y0) * j as f64 / (n_y - 1) as f64;
                p.push(V3::new((radius + d) * a.sin(), y, (radius + d) * a.cos()));
            }
        }
        let mut t = Vec::new();
        for j in 0..n_y - 1 {
            for i in 0..n_a - 1 {
                let k = (j * n_a + i) as u32;
                let m = n_a as u32;
                // Normals away from the axis: angle increasing towards +x, y upward.
                t.push([k, k + 1, k + m + 1]);
                t.push([k, k + m + 1, k + m]);
            }
        }
        (p, t)
    };
    let exact = |d: f64| alpha * (y1 - y0) * ((radius + d).powi(2) - radius * radius);
    let air = exact(0.002);
    let mut model = PressureModel::new(
        PressureParams {
            air,
            ..PressureParams::default()
        },
        Surface::Body {
            parts: Box::new(parts),
            rest: 0.0,
            reach: 0.1,
        },
    );
    for k in 0..10 {
        let d = 0.002 + 0.002 * k as f64;
        let (p, t) = sheet(d);
        let n = p.len();
        let area = vec![0.0; n];
        let boundary = vec![false; n];
        let mut f = vec![V3::zeros(); n];
        model.add_forces(&p, &t, &area, &boundary, 0.0, &mut f);
        let r = model.report();
        // The chords of the cloth's polygon and of the 720-sided body cost a little
        // volume: within 0.5 % here.
        assert_relative_eq!(r.volume, exact(d), max_relative = 5e-3);
        assert_relative_eq!(r.pressure * r.volume, ATMOSPHERE * air, max_relative = 1e-9);
    }
}

/// The backward-Euler prediction: nodes that cannot move (inverse mass 0) and move at a
/// known velocity give the pressure at the volume they reach, K/(V + Δt·gᵀu); free nodes
/// pushed by the pressure itself end nearer to atmospheric pressure than Boyle's at the
/// start, and exactly where their own motion brings the volume.
#[test]
fn the_predicted_pressure_is_boyles_at_the_end_of_the_step() {
    let (s, n, h) = (0.3, 11, 0.004);
    let (p, t, boundary) = patch(n, s, h);
    let area = vec![s * s / ((n - 1) * (n - 1)) as f64; p.len()];
    let v = s * s * h;
    let air = 1.2 * v;
    let dt = 0.01;
    // Held nodes rising at 1 mm/s: the volume at the end is V + s²·Δt·1e-3.
    let mut model = PressureModel::new(
        PressureParams {
            air,
            ..PressureParams::default()
        },
        plane_surface(),
    );
    model.evaluate(&p, &t, &area, &boundary, dt);
    let up = vec![V3::new(0.0, 0.0, 1e-3); p.len()];
    model.predict(&up, &area, &vec![0.0; p.len()], dt);
    let end = v + s * s * dt * 1e-3;
    // g = S·N sums to the patch's area only approximately at its edge (area per node is
    // uniform here), hence the tolerance.
    assert_relative_eq!(
        model.bubbles()[0].pressure,
        ATMOSPHERE * air / end,
        max_relative = 1e-3
    );
    // Free nodes of mass m at rest: P·(V + Δt²·s·(P − P_a)) = K.
    let m = 1e-5;
    let inv = vec![1.0 / m; p.len()];
    let mut model = PressureModel::new(
        PressureParams {
            air,
            ..PressureParams::default()
        },
        plane_surface(),
    );
    model.evaluate(&p, &t, &area, &boundary, dt);
    let boyle = model.bubbles()[0].pressure;
    model.predict(&vec![V3::zeros(); p.len()], &area, &inv, dt);
    let pb = model.bubbles()[0].pressure;
    let sum: f64 = area.iter().map(|a| a * a / m).sum();
    assert!(pb < boyle && pb > ATMOSPHERE, "{pb} {boyle}");
    assert_relative_eq!(
        pb * (v + dt * dt * sum * (pb - ATMOSPHERE)),
        ATMOSPHERE * air,
        max_relative = 1e-9
    );
}
