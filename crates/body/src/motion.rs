//! Poses and keyframed motion (thesis §5.6: the walk was 20 keyframes over 6 s, filmed).
//!
//! A pose gives every joint three angles (degrees, the convention of [`crate::JointLimits`]:
//! right-handed rotations about the parent's rest x, y, z axes, applied x first) and the root
//! (pelvis) a translation. A motion file lists keyframes; between two keyframes each joint's
//! rotation is interpolated by quaternion slerp and the root's translation linearly, so the
//! motion is exact at the keyframes, and the joints' angular velocities are known in closed form
//! (the slerp's constant rotation rate between keyframes).

use std::collections::BTreeMap;
use std::path::Path;

use atelier_files::check::{Validate, non_empty};
use atelier_files::{ErrorKind, FileError, InvalidValue};
use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::model::{Mannequin, Part, V3};

/// What to do with a keyframe rotation beyond a joint's limit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum LimitPolicy {
    /// Refuse the motion (typed error naming the keyframe, the joint, the axis and the value).
    #[default]
    Error,
    /// Clamp the angle to the limit (counted in [`Motion::clamped`]).
    Clamp,
}

/// One keyframe of a motion file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyframeSpec {
    /// Time, s.
    pub time: f64,
    /// Translation of the pelvis pivot from its rest position, cm.
    #[serde(default)]
    pub root_cm: (f64, f64, f64),
    /// Joint angles (α, β, γ) in degrees, keyed by the part the joint moves (`thigh_left` is
    /// the left hip; `pelvis` turns the whole body). Joints not listed stay at rest.
    #[serde(default)]
    pub joints: BTreeMap<String, (f64, f64, f64)>,
}

/// A motion file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct MotionSpec {
    /// Name.
    #[serde(deserialize_with = "non_empty")]
    pub name: String,
    /// Where the motion comes from (a film, a published gait curve…).
    #[serde(deserialize_with = "non_empty")]
    pub provenance: String,
    /// Rotations beyond a joint's limit: refuse or clamp.
    #[serde(default)]
    pub limits: LimitPolicy,
    /// The keyframes, times strictly increasing.
    pub keyframes: Vec<KeyframeSpec>,
}

atelier_files::validated!(MotionSpec);

impl Validate for MotionSpec {
    fn validate(&self) -> Result<(), InvalidValue> {
        if self.keyframes.is_empty() {
            return Err(InvalidValue::new(
                ErrorKind::TooShort,
                "keyframes",
                "a motion needs at least one keyframe",
            ));
        }
        for (k, f) in self.keyframes.iter().enumerate() {
            let field = format!("keyframes[{k}]");
            if !f.time.is_finite() {
                return Err(InvalidValue::new(
                    ErrorKind::NotFinite,
                    format!("{field}.time"),
                    format!("time {} is not finite", f.time),
                ));
            }
            if k > 0 && f.time <= self.keyframes[k - 1].time {
                return Err(InvalidValue::new(
                    ErrorKind::NonMonotone,
                    format!("{field}.time"),
                    format!(
                        "time {} s does not follow {} s; keyframe times must increase",
                        f.time,
                        self.keyframes[k - 1].time
                    ),
                ));
            }
            let r = f.root_cm;
            if ![r.0, r.1, r.2].iter().all(|v| v.is_finite()) {
                return Err(InvalidValue::new(
                    ErrorKind::NotFinite,
                    format!("{field}.root_cm"),
                    format!("({}, {}, {}) is not finite", r.0, r.1, r.2),
                ));
            }
            for (name, a) in &f.joints {
                if part_named(name).is_none() {
                    return Err(InvalidValue::new(
                        ErrorKind::UnknownVariant,
                        format!("{field}.joints.{name}"),
                        format!("no joint or part named `{name}` (known: {})", known_names()),
                    ));
                }
                if ![a.0, a.1, a.2].iter().all(|v| v.is_finite()) {
                    return Err(InvalidValue::new(
                        ErrorKind::NotFinite,
                        format!("{field}.joints.{name}"),
                        format!("({}, {}, {}) is not finite", a.0, a.1, a.2),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The part called `name` ([`Part::name`]).
pub fn part_named(name: &str) -> Option<Part> {
    Part::ALL.into_iter().find(|p| p.name() == name)
}

fn known_names() -> String {
    Part::ALL.map(Part::name).join(", ")
}

/// The rotation of joint angles (α, β, γ) in degrees: `R_z(γ) · R_y(β) · R_x(α)`.
pub fn rotation(angles_deg: [f64; 3]) -> UnitQuaternion<f64> {
    let [a, b, c] = angles_deg.map(f64::to_radians);
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), c)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), b)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), a)
}

/// A pose: each joint's rotation (indexed by [`Part::index`]; the pelvis entry turns the whole
/// body about its pivot) and the root's translation.
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    /// Joint rotations relative to the parent's rest frame.
    pub rotations: [UnitQuaternion<f64>; 17],
    /// Translation of the pelvis pivot from rest, m.
    pub root: V3,
}

impl Pose {
    /// The rest pose.
    pub fn rest() -> Self {
        Self {
            rotations: [UnitQuaternion::identity(); 17],
            root: V3::zeros(),
        }
    }

    /// A pose from joint angles (degrees) and a root translation (m).
    pub fn from_angles(angles: &[(Part, [f64; 3])], root: V3) -> Self {
        let mut pose = Self::rest();
        pose.root = root;
        for &(p, a) in angles {
            pose.rotations[p.index()] = rotation(a);
        }
        pose
    }
}

/// A pose and its rates at one instant: each joint's angular velocity relative to its parent
/// (in the parent's frame, rad/s) and the root's velocity.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseRate {
    /// The pose.
    pub pose: Pose,
    /// Angular velocity of each joint relative to its parent, in the parent's (posed) frame.
    pub omega: [V3; 17],
    /// Velocity of the pelvis pivot, m/s.
    pub root_velocity: V3,
}

/// A keyframed motion, checked against a mannequin's joint limits.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// Name.
    pub name: String,
    times: Vec<f64>,
    rotations: Vec<[UnitQuaternion<f64>; 17]>,
    roots: Vec<V3>,
    /// Angles clamped to their joint's limits (with [`LimitPolicy::Clamp`]).
    pub clamped: usize,
}

/// Why a motion cannot be used with a mannequin.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MotionError {
    /// A keyframe turns a joint beyond its limit (policy `Error`).
    #[error(
        "keyframe {keyframe} (t = {time} s): joint `{joint}` angle {value}° about {axis} lies outside its limits [{min}°, {max}°]"
    )]
    BeyondLimit {
        /// Keyframe index.
        keyframe: usize,
        /// Its time, s.
        time: f64,
        /// Joint (part name).
        joint: &'static str,
        /// `x`, `y` or `z`.
        axis: char,
        /// The angle, degrees.
        value: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
}

impl Motion {
    /// Read a motion file and check it against `mannequin`'s joint limits.
    pub fn load(path: &Path, mannequin: &Mannequin) -> Result<Self, FileError> {
        let spec: MotionSpec = atelier_files::files::load_ron(path)?;
        Self::new(&spec, mannequin).map_err(|e| {
            let field = match &e {
                MotionError::BeyondLimit {
                    keyframe, joint, ..
                } => format!("keyframes[{keyframe}].joints.{joint}"),
            };
            FileError::from_invalid(
                path,
                InvalidValue::new(ErrorKind::OutOfRange, field, e.to_string()),
            )
        })
    }

    /// Build a motion from a checked spec; rotations beyond a joint's limit are refused or
    /// clamped as the spec says.
    pub fn new(spec: &MotionSpec, mannequin: &Mannequin) -> Result<Self, MotionError> {
        let mut clamped = 0;
        let mut rotations = Vec::with_capacity(spec.keyframes.len());
        for (k, f) in spec.keyframes.iter().enumerate() {
            let mut r = [UnitQuaternion::identity(); 17];
            for (name, a) in &f.joints {
                let part = part_named(name).expect("checked at parse");
                let limits = mannequin.part(part).limits;
                let mut angles = [a.0, a.1, a.2];
                for axis in 0..3 {
                    let (lo, hi) = (limits.min_deg[axis], limits.max_deg[axis]);
                    let v = angles[axis];
                    if v < lo - 1e-9 || v > hi + 1e-9 {
                        match spec.limits {
                            LimitPolicy::Error => {
                                return Err(MotionError::BeyondLimit {
                                    keyframe: k,
                                    time: f.time,
                                    joint: part.name(),
                                    axis: ['x', 'y', 'z'][axis],
                                    value: v,
                                    min: lo,
                                    max: hi,
                                });
                            }
                            LimitPolicy::Clamp => {
                                angles[axis] = v.clamp(lo, hi);
                                clamped += 1;
                            }
                        }
                    }
                }
                r[part.index()] = rotation(angles);
            }
            rotations.push(r);
        }
        Ok(Self {
            name: spec.name.clone(),
            times: spec.keyframes.iter().map(|f| f.time).collect(),
            roots: spec
                .keyframes
                .iter()
                .map(|f| V3::new(f.root_cm.0, f.root_cm.1, f.root_cm.2) * 0.01)
                .collect(),
            rotations,
            clamped,
        })
    }

    /// First and last keyframe times, s.
    pub fn span(&self) -> (f64, f64) {
        (self.times[0], *self.times.last().expect("non-empty"))
    }

    /// Keyframe times, s.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The pose and its rates at time `t` (held at the first and last keyframes outside the
    /// span, with zero rates).
    pub fn sample(&self, t: f64) -> PoseRate {
        let n = self.times.len();
        let still = |k: usize| PoseRate {
            pose: Pose {
                rotations: self.rotations[k],
                root: self.roots[k],
            },
            omega: [V3::zeros(); 17],
            root_velocity: V3::zeros(),
        };
        if n == 1 || t <= self.times[0] {
            return still(0);
        }
        if t >= self.times[n - 1] {
            return still(n - 1);
        }
        let k = self.times.partition_point(|&tk| tk <= t) - 1;
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let h = t1 - t0;
        let s = (t - t0) / h;
        let mut pose = Pose::rest();
        let mut omega = [V3::zeros(); 17];
        for (j, w) in omega.iter_mut().enumerate() {
            let (q0, q1) = (self.rotations[k][j], self.rotations[k + 1][j]);
            // q(s) = q0 · Δ^s, Δ = q0⁻¹ q1 on the short arc; the body-frame rate is θ·axis/h.
            let mut delta = q0.inverse() * q1;
            if delta.w < 0.0 {
                delta = UnitQuaternion::new_unchecked(-delta.into_inner());
            }
            let q = match delta.axis_angle() {
                Some((axis, angle)) => {
                    let qs = q0 * UnitQuaternion::from_axis_angle(&axis, s * angle);
                    *w = qs * (axis.into_inner() * (angle / h));
                    qs
                }
                None => q0,
            };
            pose.rotations[j] = q;
        }
        let (r0, r1) = (self.roots[k], self.roots[k + 1]);
        pose.root = r0 + (r1 - r0) * s;
        PoseRate {
            pose,
            omega,
            root_velocity: (r1 - r0) / h,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::stick_figure;

    fn fixture(name: &str) -> std::path::PathBuf {
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/motions")
            .join(name)
    }

    #[test]
    fn the_motion_fixtures_load() {
        let m = stick_figure();
        let walk = Motion::load(&fixture("walk.ron"), &m).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(walk.times().len(), 61);
        assert_eq!(walk.span(), (0.0, 6.0));
        // Walking: the pelvis moves forward at about 1.2 m/s once the ramp is over.
        let v = walk.sample(3.05).root_velocity;
        assert!((v.z - 1.2).abs() < 0.05, "{v}");
        let raise = Motion::load(&fixture("arm_raise.ron"), &m).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(raise.span(), (0.0, 3.0));
        let up = raise.sample(1.5).pose.rotations[Part::UpperArmLeft.index()];
        assert!((up.angle().to_degrees() - 80.0).abs() < 1e-9);
    }
}
