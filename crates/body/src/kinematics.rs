//! Forward kinematics: where every vertex of a posed mannequin is and how fast it moves.
//!
//! Each part turns rigidly about its joint's pivot. Down the tree from the pelvis,
//! `R_c = R_p · q_c`, `P_c = P_p + R_p (c₀ − p₀)`, and the velocities follow from the joints'
//! angular velocities in closed form: `ω_c = ω_p + R_p ω_joint`, `V_c = V_p + ω_p × (P_c − P_p)`,
//! and a vertex at `x` moves at `V_c + ω_c × (x − P_c)` — no finite differences.

use nalgebra::UnitQuaternion;

use crate::model::{LabelledMesh, Mannequin, Part, V3};
use crate::motion::{Motion, PoseRate};

/// The placement and motion of one part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartFrame {
    /// Rotation from the rest pose.
    pub rotation: UnitQuaternion<f64>,
    /// The pivot's position, m.
    pub pivot: V3,
    /// Angular velocity, rad/s, world frame.
    pub omega: V3,
    /// The pivot's velocity, m/s.
    pub velocity: V3,
}

/// The parts in an order where every parent comes before its children.
pub fn tree_order() -> Vec<Part> {
    let mut order: Vec<Part> = Vec::with_capacity(17);
    while order.len() < 17 {
        for p in Part::ALL {
            if !order.contains(&p) && p.parent().is_none_or(|q| order.contains(&q)) {
                order.push(p);
            }
        }
    }
    order
}

/// A mannequin ready to be posed: its rest mesh (parts concatenated in [`Part::ALL`] order) and
/// the range of vertices of each part.
#[derive(Clone, Debug)]
pub struct Body {
    /// The static model.
    pub mannequin: Mannequin,
    /// The rest mesh with part labels.
    pub rest: LabelledMesh,
    ranges: Vec<std::ops::Range<usize>>,
    order: Vec<Part>,
}

/// Vertex positions and velocities of a posed body, in the rest mesh's order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Posed {
    /// Positions, m.
    pub positions: Vec<V3>,
    /// Velocities, m/s.
    pub velocities: Vec<V3>,
}

impl Body {
    /// Prepare a mannequin for posing.
    pub fn new(mannequin: Mannequin) -> Self {
        let rest = mannequin.labelled_mesh();
        let mut ranges = Vec::with_capacity(17);
        let mut start = 0;
        for p in &mannequin.parts {
            ranges.push(start..start + p.vertices.len());
            start += p.vertices.len();
        }
        Self {
            mannequin,
            rest,
            ranges,
            order: tree_order(),
        }
    }

    /// The frames of all parts for a pose and its rates.
    pub fn frames(&self, rate: &PoseRate) -> [PartFrame; 17] {
        let mut f = [PartFrame {
            rotation: UnitQuaternion::identity(),
            pivot: V3::zeros(),
            omega: V3::zeros(),
            velocity: V3::zeros(),
        }; 17];
        for &p in &self.order {
            let c0 = self.mannequin.part(p).pivot;
            let q = rate.pose.rotations[p.index()];
            f[p.index()] = match p.parent() {
                None => PartFrame {
                    rotation: q,
                    pivot: c0 + rate.pose.root,
                    omega: rate.omega[p.index()],
                    velocity: rate.root_velocity,
                },
                Some(parent) => {
                    let fp = f[parent.index()];
                    let p0 = self.mannequin.part(parent).pivot;
                    let pivot = fp.pivot + fp.rotation * (c0 - p0);
                    PartFrame {
                        rotation: fp.rotation * q,
                        pivot,
                        omega: fp.omega + fp.rotation * rate.omega[p.index()],
                        velocity: fp.velocity + fp.omega.cross(&(pivot - fp.pivot)),
                    }
                }
            };
        }
        f
    }

    /// Pose the body: every vertex's position and velocity.
    pub fn pose_into(&self, rate: &PoseRate, out: &mut Posed) {
        self.pose_with_frames(rate, out);
    }

    /// Pose the body as [`Body::pose_into`] does and return the parts' frames it computed on the
    /// way (the same as [`Body::frames`]), so a caller that needs both runs the kinematics once.
    pub fn pose_with_frames(&self, rate: &PoseRate, out: &mut Posed) -> [PartFrame; 17] {
        let frames = self.frames(rate);
        let n = self.rest.vertices.len();
        out.positions.resize(n, V3::zeros());
        out.velocities.resize(n, V3::zeros());
        for (part, range) in self.mannequin.parts.iter().zip(&self.ranges) {
            let fr = frames[part.part.index()];
            let r = fr.rotation.to_rotation_matrix();
            for k in range.clone() {
                let x = fr.pivot + r * (self.rest.vertices[k] - part.pivot);
                out.positions[k] = x;
                out.velocities[k] = fr.velocity + fr.omega.cross(&(x - fr.pivot));
            }
        }
        frames
    }

    /// The body at time `t` of a motion.
    pub fn at(&self, motion: &Motion, t: f64) -> Posed {
        let mut out = Posed::default();
        self.pose_into(&motion.sample(t), &mut out);
        out
    }

    /// The largest vertex displacement between `t` and `t + dt` (the collision search uses it).
    pub fn max_displacement(&self, motion: &Motion, t: f64, dt: f64) -> f64 {
        let (a, b) = (self.at(motion, t), self.at(motion, t + dt));
        a.positions
            .iter()
            .zip(&b.positions)
            .map(|(p, q)| (q - p).norm())
            .fold(0.0, f64::max)
    }
}

/// The world bounding box of some positions: (min corner, max corner).
pub fn bounding_box(positions: &[V3]) -> (V3, V3) {
    positions.iter().fold(
        (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{KeyframeSpec, LimitPolicy, MotionSpec, rotation};
    use crate::testing::stick_figure;
    use proptest::prelude::*;
    use std::collections::BTreeMap;

    /// (time, root cm, joint angles by name).
    type Frame<'a> = (f64, (f64, f64, f64), &'a [(&'a str, (f64, f64, f64))]);

    fn spec(frames: &[Frame<'_>]) -> MotionSpec {
        MotionSpec {
            name: "test".into(),
            provenance: "test".into(),
            limits: LimitPolicy::Error,
            keyframes: frames
                .iter()
                .map(|(t, root, joints)| KeyframeSpec {
                    time: *t,
                    root_cm: *root,
                    joints: joints
                        .iter()
                        .map(|(n, a)| ((*n).to_owned(), *a))
                        .collect::<BTreeMap<_, _>>(),
                })
                .collect(),
        }
    }

    fn swing() -> MotionSpec {
        spec(&[
            (
                0.0,
                (0.0, 0.0, 0.0),
                &[
                    ("thigh_left", (-30.0, 5.0, 3.0)),
                    ("shin_left", (10.0, 0.0, 0.0)),
                    ("pelvis", (0.0, 4.0, 0.0)),
                    ("upper_arm_right", (-20.0, 0.0, -10.0)),
                ],
            ),
            (
                0.4,
                (0.0, 1.0, 50.0),
                &[
                    ("thigh_left", (15.0, -5.0, 0.0)),
                    ("shin_left", (60.0, 0.0, 0.0)),
                    ("pelvis", (0.0, -4.0, 2.0)),
                    ("upper_arm_right", (25.0, 10.0, -5.0)),
                    ("forearm_right", (-40.0, 0.0, 0.0)),
                ],
            ),
            (
                1.0,
                (0.0, 0.0, 120.0),
                &[
                    ("thigh_left", (-10.0, 0.0, 0.0)),
                    ("head", (20.0, 30.0, 0.0)),
                ],
            ),
        ])
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Parts are rigid: every distance within a part is kept to 1e-12 under any pose.
        #[test]
        fn parts_are_rigid(angles in prop::collection::vec(prop::array::uniform3(-170.0f64..170.0), 17),
                           root in prop::array::uniform3(-2.0f64..2.0)) {
            let body = Body::new(stick_figure());
            let parts: Vec<(Part, [f64; 3])> = Part::ALL.iter().zip(&angles).map(|(p, a)| (*p, *a)).collect();
            let rate = PoseRate {
                pose: crate::motion::Pose::from_angles(&parts, V3::new(root[0], root[1], root[2])),
                omega: [V3::zeros(); 17],
                root_velocity: V3::zeros(),
            };
            let mut posed = Posed::default();
            body.pose_into(&rate, &mut posed);
            for (k, part) in body.mannequin.parts.iter().enumerate() {
                let range = body.ranges[k].clone();
                for a in range.clone() {
                    for b in range.clone() {
                        let d0 = (body.rest.vertices[a] - body.rest.vertices[b]).norm();
                        let d1 = (posed.positions[a] - posed.positions[b]).norm();
                        prop_assert!((d0 - d1).abs() < 1e-12, "{:?}: {d0} → {d1}", part.part);
                    }
                }
            }
        }
    }

    #[test]
    fn interpolation_is_exact_at_keyframes() {
        let m = stick_figure();
        let s = swing();
        let motion = Motion::new(&s, &m).expect("within limits");
        for f in &s.keyframes {
            let pose = motion.sample(f.time).pose;
            for (name, a) in &f.joints {
                let p = crate::motion::part_named(name).expect("known");
                let q = rotation([a.0, a.1, a.2]);
                assert!(
                    pose.rotations[p.index()].angle_to(&q) < 1e-12,
                    "{name} at {}",
                    f.time
                );
            }
            let r = V3::new(f.root_cm.0, f.root_cm.1, f.root_cm.2) * 0.01;
            assert!((pose.root - r).norm() < 1e-15);
        }
    }

    #[test]
    fn slerp_turns_at_a_constant_rate_between_keyframes() {
        let m = stick_figure();
        let motion = Motion::new(&swing(), &m).expect("within limits");
        let j = Part::ThighLeft.index();
        let w: Vec<f64> = [0.05, 0.15, 0.2, 0.35]
            .iter()
            .map(|&t| motion.sample(t).omega[j].norm())
            .collect();
        for x in &w {
            assert!((x - w[0]).abs() < 1e-12 * w[0], "{w:?}");
        }
        // The angle swept over the first segment is the rate times its length.
        let (q0, q1) = (
            motion.sample(0.0).pose.rotations[j],
            motion.sample(0.4).pose.rotations[j],
        );
        assert!((q0.angle_to(&q1) - w[0] * 0.4).abs() < 1e-12);
    }

    #[test]
    fn analytic_velocities_match_central_differences_to_second_order() {
        let body = Body::new(stick_figure());
        let motion = Motion::new(&swing(), &body.mannequin).expect("within limits");
        for &t in &[0.13, 0.27, 0.61, 0.85] {
            let v = body.at(&motion, t).velocities;
            let err = |h: f64| -> f64 {
                let (a, b) = (body.at(&motion, t - h), body.at(&motion, t + h));
                a.positions
                    .iter()
                    .zip(&b.positions)
                    .zip(&v)
                    .map(|((p, q), v)| ((q - p) / (2.0 * h) - v).norm())
                    .fold(0.0, f64::max)
            };
            let (e1, e2) = (err(1e-3), err(5e-4));
            assert!(e1 < 1e-4, "t = {t}: central difference off by {e1} m/s");
            // Second order: halving h divides the error by about four.
            assert!(e2 < 0.3 * e1, "t = {t}: {e1} → {e2}");
        }
    }

    #[test]
    fn bounding_box_and_displacement() {
        let body = Body::new(stick_figure());
        let motion = Motion::new(&swing(), &body.mannequin).expect("within limits");
        let (lo, hi) = bounding_box(&body.at(&motion, 0.5).positions);
        assert!(lo.x < -0.2 && hi.x > 0.2 && lo.y < 0.1 && hi.y > 1.5);
        let d = body.max_displacement(&motion, 0.5, 0.01);
        let vmax = body
            .at(&motion, 0.505)
            .velocities
            .iter()
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        assert!((d - vmax * 0.01).abs() < 0.05 * d, "{d} vs {}", vmax * 0.01);
    }

    #[test]
    fn bad_motions_are_refused() {
        use atelier_files::ErrorKind;
        let parse = |text: &str| -> Result<MotionSpec, atelier_files::FileError> {
            atelier_files::files::parse_ron(text, std::path::Path::new("motion.ron"))
        };
        let cases = [
            (
                r#"(name: "m", provenance: "p", keyframes: [(time: 0.0, joints: {"tail": (1.0, 0.0, 0.0)})])"#,
                ErrorKind::UnknownVariant,
                "keyframes[0].joints.tail",
            ),
            (
                r#"(name: "m", provenance: "p", keyframes: [(time: 0.0), (time: 0.0)])"#,
                ErrorKind::NonMonotone,
                "keyframes[1].time",
            ),
            (
                r#"(name: "m", provenance: "p", keyframes: [(time: 0.0, joints: {"head": (NaN, 0.0, 0.0)})])"#,
                ErrorKind::NotFinite,
                "keyframes[0].joints.head",
            ),
            (
                r#"(name: "m", provenance: "p", keyframes: [(time: 0.0, root_cm: (0.0, inf, 0.0))])"#,
                ErrorKind::NotFinite,
                "keyframes[0].root_cm",
            ),
        ];
        for (text, kind, field) in cases {
            let e = parse(text).expect_err(field);
            assert_eq!((e.kind, e.field.as_str()), (kind, field), "{e}");
            assert!(e.position.is_some(), "{e}");
        }
        // Beyond a joint's limit: an error, or clamped when the file says so.
        let mut m = stick_figure();
        m.parts[Part::ShinLeft.index()].limits = crate::model::JointLimits {
            min_deg: [0.0, 0.0, 0.0],
            max_deg: [140.0, 0.0, 0.0],
        };
        let over = spec(&[(0.0, (0.0, 0.0, 0.0), &[("shin_left", (-10.0, 0.0, 0.0))])]);
        assert!(matches!(
            Motion::new(&over, &m),
            Err(crate::motion::MotionError::BeyondLimit { axis: 'x', .. })
        ));
        let clamp = MotionSpec {
            limits: LimitPolicy::Clamp,
            ..over
        };
        let motion = Motion::new(&clamp, &m).expect("clamped");
        assert_eq!(motion.clamped, 1);
        assert!(motion.sample(0.0).pose.rotations[Part::ShinLeft.index()].angle() < 1e-15);
    }
}
