//! Exact depths of a box (axis-aligned and rotated) and a sphere within its chord error.

use super::*;

#[test]
fn an_axis_aligned_box_renders_exactly() {
    let px = 2.5;
    // Sides halfway between pixel centres; front at z = 40.123 mm, back at −30 mm.
    let m = box_mesh(
        [-0.05125, 0.10125, -0.030],
        [0.04875, 0.20125, 0.040123],
        |v| v,
    );
    let v = render_images(&m, px, &RenderParams::default()).unwrap();
    let (w, h) = (v.front.image.width, v.front.image.height);
    let mut n = [0, 0];
    for r in 0..h {
        for c in 0..w {
            for (k, view) in [&v.front, &v.back].into_iter().enumerate() {
                let [x, y] = view.world(c as f64, r as f64);
                let inside = (-51.25..48.75).contains(&x) && (101.25..201.25).contains(&y);
                let z = view.depth_mm[r * w + c];
                assert_eq!(!z.is_nan(), inside, "view {k} ({c}, {r}) at ({x}, {y})");
                assert_eq!(view.image.get(c, r) > 0, inside);
                if inside {
                    n[k] += 1;
                    let want = if k == 0 { 40.123 } else { -30.0 };
                    assert!((z - want).abs() < 1e-9, "{z} vs {want}");
                    let dec = view.decoded(c, r).unwrap();
                    assert!((dec - want).abs() <= 0.5 * view.side.depth_scale + 1e-9);
                    assert_eq!(view.part[r * w + c], Part::Chest.index() as u8);
                } else {
                    assert_eq!(view.part[r * w + c], NO_PART);
                }
            }
        }
    }
    assert_eq!(n, [40 * 40, 40 * 40]);
    // The views register and decode to the same body.
    let mut views = v.clone();
    views.front.side.landmarks = LANDMARKS
        .iter()
        .map(|&s| (s.to_owned(), (1.0, 1.0)))
        .collect();
    let body = views.body().unwrap();
    assert!((body.volume_mm3() - 1600.0 * 70.123 * px * px).abs() < 1600.0 * 0.02 * px * px);
}

#[test]
fn a_rotated_box_renders_its_slanted_faces_exactly() {
    let (ca, sa) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
    let (cb, sb) = (35f64.to_radians().cos(), 35f64.to_radians().sin());
    let centre = V3::new(0.01, 1.0, 0.02);
    // R = R_y(35°)·R_x(20°), about the centre.
    let rot = |v: V3| {
        let v1 = V3::new(v.x, ca * v.y - sa * v.z, sa * v.y + ca * v.z);
        V3::new(cb * v1.x + sb * v1.z, v1.y, -sb * v1.x + cb * v1.z)
    };
    let half = [0.08, 0.05, 0.03];
    let m = box_mesh([-half[0], -half[1], -half[2]], half, |v| centre + rot(v));
    let v = render_images(&m, 1.0, &RenderParams::default()).unwrap();
    let (w, h) = (v.front.image.width, v.front.image.height);
    // Inverse rotation (transpose).
    let inv = |v: V3| {
        let v1 = V3::new(cb * v.x - sb * v.z, v.y, sb * v.x + cb * v.z);
        V3::new(v1.x, ca * v1.y + sa * v1.z, -sa * v1.y + ca * v1.z)
    };
    let (mut compared, mut worst) = (0, 0.0f64);
    for r in 0..h {
        for c in 0..w {
            let [x, y] = v.front.world(c as f64, r as f64);
            // Slab intersection of the line (x, y, t) with the box, in the box frame (mm).
            let o = inv(V3::new(x, y, 0.0) - centre * 1e3);
            let d = inv(V3::new(0.0, 0.0, 1.0));
            let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
            for k in 0..3 {
                let hk = half[k] * 1e3;
                let (a, b) = ((-hk - o[k]) / d[k], (hk - o[k]) / d[k]);
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
            let z = v.front.depth_mm[r * w + c];
            // Skip samples within 1e-6 mm of an edge of the silhouette.
            if t1 - t0 > 1e-6 {
                assert!(!z.is_nan(), "({c}, {r}) should be covered");
                let zb = v.back.depth_mm[r * w + (w - 1 - c)];
                worst = worst.max((z - t1).abs()).max((zb - t0).abs());
                compared += 1;
            } else if t1 < t0 - 1e-6 {
                assert!(z.is_nan(), "({c}, {r}) should be empty");
            }
        }
    }
    eprintln!("rotated box: {compared} samples, worst depth error {worst:e} mm");
    assert!(compared > 15_000, "{compared}");
    assert!(worst < 1e-9, "worst depth error {worst} mm");
}

#[test]
fn a_sphere_renders_within_its_chord_error() {
    let (centre, radius) = (V3::new(0.0123, 1.1, 0.021), 0.1);
    let (nlat, nlon) = (64, 128);
    let m = sphere_mesh(centre, radius, nlat, nlon);
    let px = 1.0;
    let t = Instant::now();
    let v = render_images(&m, px, &RenderParams::default()).unwrap();
    let secs = t.elapsed().as_secs_f64();
    let (w, h) = (v.front.image.width, v.front.image.height);
    let r_mm = radius * 1e3;
    // Sagitta of the largest angular step: the polyhedron lies within it inside the sphere.
    let step = std::f64::consts::PI / nlat as f64;
    let sag = r_mm * (1.0 - step.cos());
    let (mut n, mut sum, mut worst) = (0usize, 0.0, 0.0f64);
    for r in 0..h {
        for c in 0..w {
            let [x, y] = v.front.world(c as f64, r as f64);
            let (dx, dy) = (x - centre.x * 1e3, y - centre.y * 1e3);
            let rho = dx.hypot(dy);
            let zf = v.front.depth_mm[r * w + c];
            let zb = v.back.depth_mm[r * w + (w - 1 - c)];
            if rho > r_mm {
                assert!(zf.is_nan() && zb.is_nan(), "({c}, {r}) outside the disc");
                continue;
            }
            if rho < r_mm - sag {
                assert!(!zf.is_nan() && !zb.is_nan(), "({c}, {r}) inside the disc");
            }
            let nz = (1.0 - (rho / r_mm).powi(2)).sqrt();
            if nz < 0.5 {
                continue;
            }
            let dz = r_mm * nz;
            let (ef, eb) = (centre.z * 1e3 + dz - zf, zb - (centre.z * 1e3 - dz));
            // The chords lie inside the sphere.
            for e in [ef, eb] {
                assert!(e > -1e-9 && e <= sag / nz + 1e-9, "{e} mm at ({c}, {r})");
                sum += e;
                worst = worst.max(e);
                n += 1;
            }
        }
    }
    eprintln!(
        "sphere R 100 mm, {} triangles, {w} × {h} px at 1 mm: {:.1} ms; depth error (n_z ≥ 0.5) mean {:.4} mm, max {:.4} mm (sagitta {:.4} mm)",
        m.triangles.len(),
        secs * 1e3,
        sum / n as f64,
        worst,
        sag
    );
    assert!(n > 40_000);
}
