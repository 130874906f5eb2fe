//! Agreement with the analytic mannequin (`range::synthetic`); the round trip mannequin → range images
//! → gridded body → error, standing and walking; files; typed errors.

use super::*;

/// A mannequin made of the gridded body's parts (each part's triangles; pivots from the rings;
/// the pelvis pivots at its centroid). The parts are open at the cuts but their union is closed.
fn mannequin_from(mesh: &BodyMesh) -> Mannequin {
    let parts = Part::ALL
        .iter()
        .map(|&part| {
            let mut map = BTreeMap::new();
            let mut vertices = Vec::new();
            let mut triangles = Vec::new();
            for (t, &tp) in mesh.triangles.iter().zip(&mesh.triangle_part) {
                if tp != part {
                    continue;
                }
                triangles.push(t.map(|i| {
                    *map.entry(i).or_insert_with(|| {
                        let p = mesh.positions[i as usize];
                        vertices.push(V3::new(p[0], p[1], p[2]));
                        (vertices.len() - 1) as u32
                    })
                }));
            }
            let pivot = mesh
                .pivots
                .iter()
                .find(|p| p.0 == part)
                .map(|p| V3::new(p.1[0], p.1[1], p.1[2]))
                .unwrap_or_else(|| vertices.iter().sum::<V3>() / vertices.len().max(1) as f64);
            PartMesh {
                part,
                vertices,
                triangles,
                pivot,
                limits: JointLimits::FIXED,
            }
        })
        .collect();
    Mannequin {
        name: "gridded synthetic JIS 9AR".into(),
        parts,
    }
}

/// The analytic mannequin gridded at 2.5 mm, and its analytic views.
fn analytic() -> (synthetic::SyntheticViews, RangeBody, BodyMesh) {
    let m = synthetic::Mannequin::jis_9ar();
    let views = m.views(2.5, "pgm");
    let body = m.body(2.5);
    let (mesh, _) = grid_body(&body, &BodyGridParams::default()).unwrap();
    (views, body, mesh)
}

#[test]
fn the_renderer_agrees_with_the_analytic_mannequin() {
    let (av, body, mesh) = analytic();
    let lm = labelled(&mesh);
    let frame = Frame {
        origin_mm: [av.front_side.origin.0, av.front_side.origin.1],
        width: av.front_image.width,
        height: av.front_image.height,
    };
    let params = RenderParams {
        frame: Some(frame),
        ..RenderParams::default()
    };
    let t = Instant::now();
    let v = render_views(&lm, 2.5, &params).unwrap();
    let secs = t.elapsed().as_secs_f64();
    // The same z-buffer as `measure_error`'s Z_e.
    let err = measure_error(&mesh, &body);
    let (w, h) = (frame.width, frame.height);
    let mut stats = Vec::new();
    for (view, ze, zr) in [
        (&v.front, &err.front.rendered_mm, &body.front),
        (&v.back, &err.back.rendered_mm, &body.back),
    ] {
        let (mut n, mut s, mut mask_diff) = (0usize, 0.0, 0usize);
        for r in 0..h {
            for c in 0..w {
                let k = r * w + c;
                let col = if view.view == View::Front {
                    c
                } else {
                    w - 1 - c
                };
                let z = view.depth_mm[r * w + col];
                let zm = f64::from(ze[k]);
                assert_eq!(z.is_nan(), zm.is_nan(), "{:?} ({c}, {r})", view.view);
                if !z.is_nan() {
                    assert!((z - zm).abs() < 1e-3, "{z} vs {zm}");
                }
                match (z.is_nan(), zr[k].is_nan()) {
                    (false, false) => {
                        n += 1;
                        s += (z - zr[k]).abs();
                    }
                    (true, true) => {}
                    _ => mask_diff += 1,
                }
            }
        }
        stats.push((s / n as f64, n, mask_diff));
    }
    // Landmarks against the analytic ones.
    let mut worst = (String::new(), 0.0f64);
    for (name, &(c, r)) in v.landmarks() {
        let (ca, ra) = av.front_side.landmarks[name];
        let d = (c - ca).hypot(r - ra);
        eprintln!("{name:12} ({c:7.2}, {r:7.2}) analytic ({ca:7.2}, {ra:7.2}): {d:5.2} px");
        if d > worst.1 {
            worst = (name.clone(), d);
        }
    }
    eprintln!(
        "gridded analytic mannequin ({} triangles) rendered at 2.5 mm in {:.1} ms with landmarks; mean |Δz| front {:.3} mm ({} samples, {} mask differences), back {:.3} mm ({}, {}); worst landmark {} at {:.2} px",
        lm.triangles.len(),
        secs * 1e3,
        stats[0].0,
        stats[0].1,
        stats[0].2,
        stats[1].0,
        stats[1].1,
        stats[1].2,
        worst.0,
        worst.1
    );
    for (mean, n, diff) in &stats {
        assert!(*mean < 1.5, "mean |Δz| {mean}");
        assert!((*diff as f64) < 0.01 * *n as f64, "{diff} of {n}");
    }
    assert!(worst.1 < 4.0, "{worst:?}");
    // The rendered views grid like the analytic ones.
    let (mesh2, _) = grid_body(&v.body().unwrap(), &BodyGridParams::default()).unwrap();
    assert_eq!(mesh2.edge_defects(), (0, 0));
}

/// The round trip on any mannequin: render at 2.5 mm, grid, measure; prints Table 2.
fn check_round_trip(m: &Mannequin, max_mean_mm: f64) -> RoundTrip {
    let rt = round_trip(m, 2.5, &BodyGridParams::default()).unwrap();
    let e = &rt.error;
    eprint!("{}", e.table());
    eprintln!(
        "{}: {} × {} px, render {:.1} ms, render + landmarks {:.3} s, gridding {:.3} s; total {:.2} ± {:.2} mm (signed {:.2} ± {:.2}), {} nodes / {} valid samples = {:.2} %, uncovered {}, spurious {}",
        m.name,
        rt.views.front.image.width,
        rt.views.front.image.height,
        rt.views.render_seconds * 1e3,
        rt.render_seconds,
        rt.grid_seconds,
        e.total.mean_abs_mm,
        e.total.sd_abs_mm,
        e.total.mean_signed_mm,
        e.total.sd_signed_mm,
        e.total.nodes,
        e.valid_samples,
        100.0 * e.compression,
        e.uncovered,
        e.spurious
    );
    assert_eq!(rt.mesh.edge_defects(), (0, 0));
    assert!(e.total.mean_abs_mm < max_mean_mm, "{}", e.total.mean_abs_mm);
    assert!(e.compression < 0.05);
    assert!(e.parts.iter().all(|(_, s)| s.samples > 0));
    rt
}

#[test]
fn round_trip_of_a_mannequin_assembled_from_the_gridded_analytic_body() {
    let (_, _, mesh) = analytic();
    let m = mannequin_from(&mesh);
    let rt = check_round_trip(&m, 1.5);
    // Files: PGM and PNG read back to the same body.
    for ext in ["pgm", "png"] {
        let dir = TempDir::new(ext);
        let (f, b) = rt.views.write(&dir.0, ext).unwrap();
        let loaded = RangeBody::load(&f, &b).unwrap();
        let mem = rt.views.body().unwrap();
        let same = |x: &[f64], y: &[f64]| {
            x.len() == y.len()
                && x.iter()
                    .zip(y)
                    .all(|(p, q)| (p.is_nan() && q.is_nan()) || (p - q).abs() < 1e-9)
        };
        assert!(same(&loaded.front, &mem.front) && same(&loaded.back, &mem.back));
        assert_eq!(
            (loaded.width, loaded.height, loaded.origin),
            (mem.width, mem.height, mem.origin)
        );
        assert_eq!(loaded.landmarks, mem.landmarks);
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let p = RenderParams::default();
    let good = box_mesh([0.0; 3], [0.1; 3], |v| v);
    assert!(matches!(
        render_views(&LabelledMesh::default(), 2.5, &p),
        Err(RangeError::EmptyMesh { .. })
    ));
    for px in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            render_views(&good, px, &p),
            Err(RangeError::BadPixelSize(_))
        ));
    }
    // One triangle facing the back camera only.
    let back_only = LabelledMesh {
        vertices: vec![
            V3::new(0.0, 0.0, 0.0),
            V3::new(0.0, 0.1, 0.0),
            V3::new(0.1, 0.0, 0.0),
        ],
        triangles: vec![[0, 1, 2]],
        vertex_part: vec![Part::Head; 3],
        triangle_part: vec![Part::Head],
    };
    assert!(matches!(
        render_views(&back_only, 2.5, &p),
        Err(RangeError::NoFacingTriangles(View::Front))
    ));
    let mut front_only = back_only.clone();
    front_only.triangles = vec![[0, 2, 1]];
    assert!(matches!(
        render_views(&front_only, 2.5, &p),
        Err(RangeError::NoFacingTriangles(View::Back))
    ));
    // Edge-on: no triangle faces either camera.
    let mut edge_on = back_only.clone();
    edge_on.vertices = vec![
        V3::new(0.0, 0.0, 0.0),
        V3::new(0.0, 0.1, 0.0),
        V3::new(0.0, 0.0, 0.1),
    ];
    assert!(matches!(
        render_views(&edge_on, 2.5, &p),
        Err(RangeError::NoFacingTriangles(View::Front))
    ));
    // A tiny closed box between pixel centres.
    let tiny = box_mesh([0.0004, 0.0004, 0.0], [0.0006, 0.0006, 0.001], |v| v);
    assert!(matches!(
        render_views(&tiny, 2.5, &p),
        Err(RangeError::EmptyView(View::Front))
    ));
    let mut nan = good.clone();
    nan.vertices[3].y = f64::NAN;
    assert!(matches!(
        render_views(&nan, 2.5, &p),
        Err(RangeError::BadMesh(_))
    ));
    let mut idx = good.clone();
    idx.triangles[0][1] = 99;
    assert!(matches!(
        render_views(&idx, 2.5, &p),
        Err(RangeError::BadMesh(_))
    ));
    let mut labels = good.clone();
    labels.triangle_part.pop();
    assert!(matches!(
        render_views(&labels, 2.5, &p),
        Err(RangeError::BadMesh(_))
    ));
    assert!(matches!(
        render_views(&good, 1e-5, &p),
        Err(RangeError::TooLarge { .. })
    ));
    let deep = box_mesh([0.0, 0.0, -1.0], [0.1, 0.1, 1.0], |v| v);
    assert!(matches!(
        render_views(&deep, 2.5, &p),
        Err(RangeError::DepthRange { .. })
    ));
    for (field, params) in [
        (
            "depth_scale_mm",
            RenderParams {
                depth_scale_mm: 0.0,
                ..p
            },
        ),
        (
            "margin_mm",
            RenderParams {
                margin_mm: f64::NAN,
                ..p
            },
        ),
        (
            "standoff_mm",
            RenderParams {
                standoff_mm: 1.0,
                ..p
            },
        ),
    ] {
        match render_views(&good, 2.5, &params) {
            Err(RangeError::BadParameter { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{field}: {other:?}"),
        }
    }
    // A box has no body parts: no landmarks, but its images render.
    assert!(matches!(
        render_views(&good, 2.5, &p),
        Err(RangeError::Landmark { .. })
    ));
    let v = render_images(&good, 2.5, &p).unwrap();
    assert!(matches!(v.body(), Err(RangeError::Views(_))));
    let dir = TempDir::new("ext");
    assert!(matches!(
        v.write(&dir.0, "jpg"),
        Err(RangeError::BadExtension(_))
    ));
    assert!(matches!(
        v.write(&dir.0.join("missing"), "pgm"),
        Err(RangeError::Io { .. })
    ));
}

#[test]
fn round_trip_of_the_parametric_jis_9ar() {
    let m = crate::build::jis_9ar();
    let (nv, nt) = m.counts();
    eprintln!("jis_9ar: {nv} vertices, {nt} triangles");
    check_round_trip(&m, 3.0);
}

/// The parametric mannequin in a walk-like pose (mid-stance of the left leg, right leg swinging
/// forward, arms swinging, elbows bent, torso turned a little).
fn walk_pose_mesh() -> LabelledMesh {
    use crate::kinematics::{Body, Posed};
    use crate::motion::{Pose, PoseRate};
    use Part::*;
    let body = Body::new(crate::build::jis_9ar());
    let pose = Pose::from_angles(
        &[
            (Pelvis, [0.0, 5.0, 0.0]),
            (ThighLeft, [10.0, 0.0, 0.0]),
            (ThighRight, [-25.0, 0.0, 0.0]),
            (ShinRight, [40.0, 0.0, 0.0]),
            (FootRight, [-10.0, 0.0, 0.0]),
            (UpperArmLeft, [-15.0, 0.0, 0.0]),
            (UpperArmRight, [15.0, 0.0, 0.0]),
            (ForearmLeft, [-25.0, 0.0, 0.0]),
            (ForearmRight, [-10.0, 0.0, 0.0]),
            (Chest, [0.0, -5.0, 0.0]),
            (Neck, [5.0, 0.0, 0.0]),
        ],
        V3::zeros(),
    );
    let rate = PoseRate {
        pose,
        omega: [V3::zeros(); 17],
        root_velocity: V3::zeros(),
    };
    let mut posed = Posed::default();
    body.pose_into(&rate, &mut posed);
    LabelledMesh {
        vertices: posed.positions,
        ..body.rest.clone()
    }
}

#[test]
fn round_trip_of_the_parametric_jis_9ar_in_a_walk_pose() {
    let mesh = walk_pose_mesh();
    let rt = round_trip_mesh(&mesh, 2.5, &BodyGridParams::default()).unwrap();
    let e = &rt.error;
    eprintln!(
        "JIS 9AR walk pose: total {:.2} ± {:.2} mm, {:.2} %, feet {:.2} / {:.2} mm",
        e.total.mean_abs_mm,
        e.total.sd_abs_mm,
        100.0 * e.compression,
        e.parts[Part::FootLeft.index()].1.mean_abs_mm,
        e.parts[Part::FootRight.index()].1.mean_abs_mm
    );
    assert_eq!(rt.mesh.edge_defects(), (0, 0));
    assert!(e.total.mean_abs_mm < 3.0);
}

/// Debug pictures: part labels with the landmarks (white), into `$ATELIER_RANGE_DUMP`.
#[test]
#[ignore = "writes debug pictures"]
fn dump_pictures() {
    let Some(dir) = std::env::var_os("ATELIER_RANGE_DUMP") else {
        return;
    };
    let dir = PathBuf::from(dir);
    for (name, mesh) in [
        ("rest", crate::build::jis_9ar().labelled_mesh()),
        ("walk", walk_pose_mesh()),
    ] {
        let v = render_views(&mesh, 2.5, &RenderParams::default()).unwrap();
        let (w, h) = (v.front.image.width, v.front.image.height);
        let mut img = GrayImage {
            width: w,
            height: h,
            maxval: 65535,
            data: v
                .front
                .part
                .iter()
                .map(|&p| {
                    if p == NO_PART {
                        0
                    } else {
                        8000 + 3000 * u16::from(p)
                    }
                })
                .collect(),
        };
        for &(c, r) in v.landmarks().values() {
            for dr in -1..=1 {
                for dc in -1..=1 {
                    let (cc, rr) = (c.round() as isize + dc, r.round() as isize + dr);
                    if cc >= 0 && rr >= 0 && (cc as usize) < w && (rr as usize) < h {
                        img.data[rr as usize * w + cc as usize] = 65535;
                    }
                }
            }
        }
        write_image(&dir.join(format!("{name}_parts.png")), &img).unwrap();
        v.write(&dir, "png").unwrap();
    }
}

/// More poses of the parametric mannequin: those that keep the limbs apart in the front view
/// round-trip; those that hide a joint or close the armpit are typed errors.
#[test]
fn other_poses_round_trip_or_are_typed_errors() {
    use crate::kinematics::{Body, Posed};
    use crate::motion::{Pose, PoseRate};
    use Part::*;
    let body = Body::new(crate::build::jis_9ar());
    // Expectation: 0 = a landmark error, 1 = a closed round trip, 2 = a round trip whose gridded
    // mesh folds (the gridding's limit, not the renderer's: near-horizontal arms, a raised forearm).
    type Case = (&'static str, Vec<(Part, [f64; 3])>, u8);
    let cases: [Case; 6] = [
        (
            "arms 20° up",
            vec![
                (UpperArmLeft, [0.0, 0.0, 20.0]),
                (UpperArmRight, [0.0, 0.0, -20.0]),
            ],
            1,
        ),
        (
            "arms 60° up (near T)",
            vec![
                (UpperArmLeft, [0.0, 0.0, 60.0]),
                (UpperArmRight, [0.0, 0.0, -60.0]),
            ],
            2,
        ),
        (
            "legs apart",
            vec![(ThighLeft, [0.0, 0.0, 8.0]), (ThighRight, [0.0, 0.0, -8.0])],
            1,
        ),
        (
            "left forearm raised",
            vec![(ForearmLeft, [-120.0, 0.0, 0.0])],
            2,
        ),
        (
            "arms into the trunk",
            vec![
                (UpperArmLeft, [0.0, 0.0, -60.0]),
                (UpperArmRight, [0.0, 0.0, 60.0]),
            ],
            0,
        ),
        (
            "arms overhead",
            vec![
                (UpperArmLeft, [0.0, 0.0, 120.0]),
                (UpperArmRight, [0.0, 0.0, -120.0]),
            ],
            0,
        ),
    ];
    for (name, angles, ok) in cases {
        let rate = PoseRate {
            pose: Pose::from_angles(&angles, V3::zeros()),
            omega: [V3::zeros(); 17],
            root_velocity: V3::zeros(),
        };
        let mut posed = Posed::default();
        body.pose_into(&rate, &mut posed);
        let mesh = LabelledMesh {
            vertices: posed.positions,
            ..body.rest.clone()
        };
        // The images always render.
        assert!(render_images(&mesh, 2.5, &RenderParams::default()).is_ok());
        match round_trip_mesh(&mesh, 2.5, &BodyGridParams::default()) {
            Ok(rt) => {
                let e = &rt.error.total;
                eprintln!(
                    "{name}: {:.2} ± {:.2} mm, {:.2} %, edge defects {:?}",
                    e.mean_abs_mm,
                    e.sd_abs_mm,
                    100.0 * rt.error.compression,
                    rt.mesh.edge_defects()
                );
                assert!(ok > 0, "{name} should not round-trip");
                if ok == 1 {
                    assert_eq!(rt.mesh.edge_defects(), (0, 0), "{name}");
                }
                assert!(e.mean_abs_mm < 2.0, "{name}");
            }
            Err(err) => {
                eprintln!("{name}: {err}");
                assert_eq!(ok, 0, "{name}: {err}");
                assert!(matches!(err, RangeError::Landmark { .. }), "{name}: {err}");
            }
        }
    }
}
