//! The scan cut into the 17 parts at its landmarks: the limbs by planes through their joints
//! (each plane bisecting the angle between the two bones it separates), the trunk by horizontal
//! planes placed between the girth lines as on the 9AR mannequin.

use super::ScanError;
use super::landmarks::Landmarks;
use super::limbs::Adjacency;
use crate::model::{LabelledMesh, Part, V3};

/// Where the pelvis–abdomen boundary lies between the hip line (0) and the waist (1): the 9AR
/// mannequin's lumbar joint (90 cm between its hip line at 80 cm and its waist at 98 cm).
pub const PELVIS_ABDOMEN: f64 = 10.0 / 18.0;
/// Where the abdomen–chest boundary lies between the waist (0) and the bust (1): the 9AR
/// mannequin's thoracic joint (104 cm between its waist at 98 cm and its bust at 114 cm).
pub const ABDOMEN_CHEST: f64 = 6.0 / 16.0;

/// Tilt of the neck–head cut from the horizontal, rising backward from the chin, radians
/// (30°: the jaw's lower border runs from the chin up to the back of the skull).
pub const NECK_HEAD_TILT: f64 = std::f64::consts::FRAC_PI_6;

/// The vertices reached from the vertex nearest `seed` through vertices satisfying `inside`.
fn component(
    vertices: &[V3],
    adj: &Adjacency,
    inside: impl Fn(&V3) -> bool,
    seed: V3,
) -> Vec<bool> {
    let n = vertices.len();
    let mut member = vec![false; n];
    let Some(start) = (0..n).filter(|&k| inside(&vertices[k])).min_by(|&a, &b| {
        (vertices[a] - seed)
            .norm_squared()
            .total_cmp(&(vertices[b] - seed).norm_squared())
    }) else {
        return member;
    };
    member[start] = true;
    let mut stack = vec![start as u32];
    while let Some(v) = stack.pop() {
        for &w in adj.of(v) {
            if !member[w as usize] && inside(&vertices[w as usize]) {
                member[w as usize] = true;
                stack.push(w);
            }
        }
    }
    member
}

fn unit(v: V3) -> V3 {
    v.try_normalize(1e-12).unwrap_or_else(V3::zeros)
}

/// Normal of the plane bisecting the angle at joint `b` between the bones `a → b` and `b → c`
/// (pointing along the limb, towards `c`).
fn bisector(a: V3, b: V3, c: V3) -> V3 {
    unit(unit(b - a) + unit(c - b))
}

/// Label every vertex and triangle with a part:
///
/// - **arms**: below the armpit, the vertices beyond it (in x) reached from the elbow without
///   crossing the armpit's height; above it, the vertices beyond the armpit and beyond the plane
///   through the shoulder joint perpendicular to the upper arm. Within the arm, the hand lies
///   beyond the wrist's bisecting plane, the forearm beyond the elbow's, the rest is upper arm;
/// - **legs**: below the crotch, the vertices reached from the knee; above it, those on the
///   leg's side beyond the plane through the hip joint whose normal bisects the thigh's axis
///   and the outward direction (the groin fold runs up and out from the crotch). Within the leg,
///   foot beyond the ankle's bisecting plane, shin beyond the knee's;
/// - **trunk**: pelvis below [`PELVIS_ABDOMEN`] of the way from the hip line to the waist,
///   abdomen below [`ABDOMEN_CHEST`] of the way from the waist to the bust, chest below the
///   neck base, head above the plane through the chin rising backward at [`NECK_HEAD_TILT`],
///   neck between.
///
/// A triangle takes the part most of its corners have (its first corner's when all three
/// differ). Every part must receive triangles ([`ScanError::EmptyPart`]).
pub fn segment(
    vertices: &[V3],
    triangles: &[[u32; 3]],
    l: &Landmarks,
) -> Result<LabelledMesh, ScanError> {
    let n = vertices.len();
    let adj = Adjacency::new(n, triangles);
    let mut part: Vec<Option<Part>> = vec![None; n];
    // Arms.
    for left in [true, false] {
        let (pit, s, e, w, tip) = if left {
            (
                l.armpit_left,
                l.shoulder_left,
                l.elbow_left,
                l.wrist_left,
                l.hand_tip_left,
            )
        } else {
            (
                l.armpit_right,
                l.shoulder_right,
                l.elbow_right,
                l.wrist_right,
                l.hand_tip_right,
            )
        };
        let beyond = |p: &V3| (p.x > pit.x) == left;
        let below = component(vertices, &adj, |p| p.y < pit.y && beyond(p), e);
        let u = unit(e - s);
        let (n_e, n_w) = (bisector(s, e, w), bisector(e, w, tip));
        let (upper, fore, hand) = if left {
            (Part::UpperArmLeft, Part::ForearmLeft, Part::HandLeft)
        } else {
            (Part::UpperArmRight, Part::ForearmRight, Part::HandRight)
        };
        for (k, p) in vertices.iter().enumerate() {
            let on_arm = below[k] || (p.y >= pit.y && beyond(p) && (p - s).dot(&u) > 0.0);
            if on_arm && part[k].is_none() {
                part[k] = Some(if (p - w).dot(&n_w) > 0.0 {
                    hand
                } else if (p - e).dot(&n_e) > 0.0 {
                    fore
                } else {
                    upper
                });
            }
        }
    }
    // Legs.
    for left in [true, false] {
        let (h, k_, a, tip) = if left {
            (l.hip_left, l.knee_left, l.ankle_left, l.toe_left)
        } else {
            (l.hip_right, l.knee_right, l.ankle_right, l.toe_right)
        };
        let side = |p: &V3| (p.x > l.crotch.x) == left;
        let below = component(vertices, &adj, |p| p.y < l.crotch.y && side(p), k_);
        let out = V3::new(if left { 1.0 } else { -1.0 }, 0.0, 0.0);
        let n_h = unit(unit(k_ - h) + out);
        let (n_k, n_a) = (bisector(h, k_, a), bisector(k_, a, tip));
        let (thigh, shin, foot) = if left {
            (Part::ThighLeft, Part::ShinLeft, Part::FootLeft)
        } else {
            (Part::ThighRight, Part::ShinRight, Part::FootRight)
        };
        for (k, p) in vertices.iter().enumerate() {
            if part[k].is_some() {
                continue;
            }
            let on_leg = below[k] || (p.y >= l.crotch.y && side(p) && (p - h).dot(&n_h) > 0.0);
            if on_leg {
                part[k] = Some(if (p - a).dot(&n_a) > 0.0 {
                    foot
                } else if (p - k_).dot(&n_k) > 0.0 {
                    shin
                } else {
                    thigh
                });
            }
        }
    }
    // Trunk.
    let y_pa = l.hip.height + PELVIS_ABDOMEN * (l.waist.height - l.hip.height);
    let y_ac = l.waist.height + ABDOMEN_CHEST * (l.bust.height - l.waist.height);
    for (k, p) in vertices.iter().enumerate() {
        if part[k].is_none() {
            part[k] = Some(if p.y < y_pa {
                Part::Pelvis
            } else if p.y < y_ac {
                Part::Abdomen
            } else if p.y < l.neck_base.y {
                Part::Chest
            } else if (p.y - l.chin.y) * NECK_HEAD_TILT.cos()
                + (p.z - l.chin.z) * NECK_HEAD_TILT.sin()
                < 0.0
            {
                Part::Neck
            } else {
                Part::Head
            });
        }
    }
    let vertex_part: Vec<Part> = part
        .into_iter()
        .map(|p| p.expect("every vertex labelled"))
        .collect();
    let triangle_part: Vec<Part> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| vertex_part[k as usize]);
            if b == c { b } else { a }
        })
        .collect();
    let mut has = [false; 17];
    for p in &triangle_part {
        has[p.index()] = true;
    }
    if let Some(p) = Part::ALL.into_iter().find(|p| !has[p.index()]) {
        return Err(ScanError::EmptyPart(p));
    }
    Ok(LabelledMesh {
        vertices: vertices.to_vec(),
        triangles: triangles.to_vec(),
        vertex_part,
        triangle_part,
    })
}
