//! Tests of [`super`].

use super::*;
use nalgebra::{Rotation3, Unit};

fn around(d: &BodyDescription, p: Part) -> usize {
    d.part(p)
        .and_then(|pd| pd.around)
        .unwrap_or(d.resolution.around)
}

#[test]
fn every_part_is_closed_and_outward() {
    let d = jis_9ar_description();
    let scaled = Mannequin::from_description(
        &d,
        &Sizes {
            height_cm: 165.0,
            bust_cm: 88.0,
            waist_cm: 70.0,
            hip_cm: 95.0,
        },
    )
    .expect("builds");
    for m in [jis_9ar(), scaled] {
        assert_eq!(m.parts.len(), 17);
        for (k, p) in m.parts.iter().enumerate() {
            assert_eq!(p.part, Part::ALL[k]);
            assert_eq!(first_open_edge(&p.triangles), None, "{}", p.part.name());
            let v = signed_volume(&p.vertices, &p.triangles);
            assert!(v > 0.0, "{} volume {v}", p.part.name());
            // Inside tests work: the pivot of the part lies in the part or its parent.
            let host = p.part.parent().map_or(p, |q| m.part(q));
            assert!(
                contains(&host.vertices, &host.triangles, &p.pivot),
                "pivot of {} outside {}",
                p.part.name(),
                host.part.name()
            );
        }
    }
}

#[test]
fn the_default_has_one_to_three_thousand_triangles() {
    let (v, t) = jis_9ar().counts();
    assert!((1000..=3000).contains(&t), "{t} triangles, {v} vertices");
}

fn assert_sizes(m: &MeasuredSizes, want: &Sizes) {
    for (name, got, want) in [
        ("height", m.height_cm, want.height_cm),
        ("bust", m.bust_cm, want.bust_cm),
        ("waist", m.waist_cm, want.waist_cm),
        ("hip", m.hip_cm, want.hip_cm),
    ] {
        assert!((got - want).abs() < 1.0, "{name}: {got} cm, want {want}");
    }
}

#[test]
fn the_default_measures_jis_9ar_on_its_mesh() {
    let m = measure(&jis_9ar());
    assert_sizes(&m, &Sizes::JIS_9AR);
    // The draft itself is within 2 cm of its sizes before the girth correction.
    let drawn =
        measure(&Mannequin::from_description_as_drawn(&jis_9ar_description()).expect("builds"));
    for (got, want) in [
        (drawn.height_cm, 158.0),
        (drawn.bust_cm, 83.0),
        (drawn.waist_cm, 64.0),
        (drawn.hip_cm, 91.0),
    ] {
        assert!((got - want).abs() < 2.0, "as drawn {drawn:?}");
    }
}

#[test]
fn scaled_mannequins_measure_what_was_asked() {
    let d = jis_9ar_description();
    for want in [
        Sizes {
            height_cm: 165.0,
            bust_cm: 88.0,
            waist_cm: 70.0,
            hip_cm: 95.0,
        },
        Sizes {
            height_cm: 150.0,
            bust_cm: 78.0,
            waist_cm: 60.0,
            hip_cm: 86.0,
        },
        Sizes {
            height_cm: 170.0,
            bust_cm: 96.0,
            waist_cm: 82.0,
            hip_cm: 100.0,
        },
    ] {
        let m = Mannequin::from_description(&d, &want).expect("builds");
        assert_sizes(&measure(&m), &want);
        // Feet stay on the floor.
        let sole = m
            .parts
            .iter()
            .flat_map(|p| p.vertices.iter().map(|q| q.y))
            .fold(f64::INFINITY, f64::min);
        assert!(sole.abs() < 1e-12);
    }
}

#[test]
fn bad_sizes_are_typed_errors() {
    let d = jis_9ar_description();
    let mut s = Sizes::JIS_9AR;
    s.bust_cm = f64::NAN;
    assert!(matches!(
        Mannequin::from_description(&d, &s),
        Err(BodyError::Sizes(e)) if e.kind == ErrorKind::NotFinite
    ));
    s.bust_cm = 300.0;
    assert!(matches!(
        Mannequin::from_description(&d, &s),
        Err(BodyError::Sizes(e)) if e.kind == ErrorKind::OutOfRange
    ));
    let mut bad = d.clone();
    bad.parts.pop();
    assert!(matches!(
        Mannequin::from_description(&bad, &Sizes::JIS_9AR),
        Err(BodyError::Description(e)) if e.kind == ErrorKind::MissingField
    ));
}

/// Rotations about world axes (x: flexion, z: abduction) through each joint, at least as
/// large as the walk and arm-raise fixtures use.
fn test_rotations(p: Part) -> Vec<(V3, f64)> {
    use Part::*;
    let x = |lo: f64, hi: f64| vec![(V3::x(), lo), (V3::x(), hi)];
    let mut r = match p {
        Head | Neck => x(-20.0, 20.0),
        Chest | Abdomen => x(-10.0, 10.0),
        UpperArmLeft | UpperArmRight => x(-30.0, 30.0),
        ForearmLeft | ForearmRight => x(-45.0, 0.0),
        HandLeft | HandRight => x(-30.0, 30.0),
        ThighLeft | ThighRight => x(-35.0, 20.0),
        ShinLeft | ShinRight => x(0.0, 65.0),
        FootLeft | FootRight => x(-20.0, 25.0),
        Pelvis => vec![],
    };
    match p {
        UpperArmLeft => r.push((V3::z(), 80.0)),
        UpperArmRight => r.push((V3::z(), -80.0)),
        ThighLeft | ThighRight | Chest | Abdomen | Neck => {
            r.push((V3::z(), 10.0));
            r.push((V3::z(), -10.0));
            r.push((V3::y(), 10.0));
            r.push((V3::y(), -10.0));
        }
        _ => {}
    }
    r
}

#[test]
fn children_reach_into_their_parents_at_rest_and_turned() {
    let d = jis_9ar_description();
    for m in [
        jis_9ar(),
        Mannequin::from_description(
            &d,
            &Sizes {
                height_cm: 150.0,
                bust_cm: 78.0,
                waist_cm: 60.0,
                hip_cm: 86.0,
            },
        )
        .expect("builds"),
    ] {
        let mut failures = Vec::new();
        for p in Part::ALL {
            let Some(parent) = p.parent() else { continue };
            let (child, host) = (m.part(p), m.part(parent));
            let n = around(&d, p);
            // The proximal boundary: the first ring and its cap centre.
            let nv = child.vertices.len();
            let mut boundary: Vec<V3> = child.vertices[..n].to_vec();
            boundary.push(child.vertices[nv - 2]);
            let mut turns = vec![(V3::x(), 0.0)];
            turns.extend(test_rotations(p));
            for (axis, deg) in turns {
                let r = Rotation3::from_axis_angle(&Unit::new_normalize(axis), deg.to_radians());
                let outside = boundary
                    .iter()
                    .map(|q| child.pivot + r * (q - child.pivot))
                    .filter(|q| !contains(&host.vertices, &host.triangles, q))
                    .count();
                if outside > 0 {
                    failures.push(format!(
                        "{} turned {deg}° about {:?}: {outside} proximal points outside {}",
                        p.name(),
                        axis.as_slice(),
                        parent.name()
                    ));
                }
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
}

#[test]
fn left_and_right_mirror_each_other() {
    let m = jis_9ar();
    use Part::*;
    for (l, r) in [
        (UpperArmLeft, UpperArmRight),
        (ForearmLeft, ForearmRight),
        (HandLeft, HandRight),
        (ThighLeft, ThighRight),
        (ShinLeft, ShinRight),
        (FootLeft, FootRight),
    ] {
        let (a, b) = (m.part(l), m.part(r));
        assert!((a.pivot.x + b.pivot.x).abs() < 1e-9);
        assert!(a.pivot.x > 0.0, "left is +x");
        assert!((a.limits.min_deg[0] - b.limits.min_deg[0]).abs() < 1e-12);
        assert!((a.limits.max_deg[2] + b.limits.min_deg[2]).abs() < 1e-12);
        let (va, vb) = (
            signed_volume(&a.vertices, &a.triangles),
            signed_volume(&b.vertices, &b.triangles),
        );
        assert!((va - vb).abs() < 1e-9 * va);
    }
    // The walk's joint angles lie within the limits: knee flexion positive, hip flexion
    // negative (model.rs convention).
    assert!(m.part(ShinLeft).limits.contains([60.0, 0.0, 0.0], 0.0));
    assert!(m.part(ThighLeft).limits.contains([-25.0, 0.0, 0.0], 0.0));
    assert!(m.part(UpperArmLeft).limits.contains([0.0, 0.0, 80.0], 0.0));
    assert!(
        m.part(UpperArmRight)
            .limits
            .contains([0.0, 0.0, -80.0], 0.0)
    );
}

#[test]
fn winding_number_and_hull_on_a_cube() {
    let d = jis_9ar_description();
    let m = Mannequin::from_description_as_drawn(&d).expect("builds");
    let head = m.part(Part::Head);
    let c = head.vertices.iter().sum::<V3>() / head.vertices.len() as f64;
    assert!((winding_number(&head.vertices, &head.triangles, &c) - 1.0).abs() < 1e-9);
    let far = c + V3::new(1.0, 0.0, 0.0);
    assert!(winding_number(&head.vertices, &head.triangles, &far).abs() < 1e-9);
    let square = vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.5, 0.5)];
    assert_eq!(convex_hull(square).len(), 4);
}

#[test]
fn no_gaps_open_along_the_fixture_motions() {
    let d = jis_9ar_description();
    let body = crate::Body::new(jis_9ar());
    let mut offsets = vec![0usize];
    for p in &body.mannequin.parts {
        offsets.push(offsets.last().copied().unwrap_or(0) + p.vertices.len());
    }
    for name in ["walk.ron", "arm_raise.ron"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/motions")
            .join(name);
        let motion = crate::Motion::load(&path, &body.mannequin).expect("within the limits");
        let (t0, t1) = motion.span();
        for k in 0..=60 {
            let t = t0 + (t1 - t0) * k as f64 / 60.0;
            let posed = body.at(&motion, t);
            let verts = |p: Part| &posed.positions[offsets[p.index()]..offsets[p.index() + 1]];
            for p in Part::ALL {
                let Some(parent) = p.parent() else { continue };
                let host = verts(parent);
                let tris = &body.mannequin.part(parent).triangles;
                let child = verts(p);
                let ring = &child[..around(&d, p)];
                for q in ring.iter().chain([&child[child.len() - 2]]) {
                    assert!(
                        contains(host, tris, q),
                        "{name} t = {t}: {} leaves {}",
                        p.name(),
                        parent.name()
                    );
                }
            }
        }
    }
}
