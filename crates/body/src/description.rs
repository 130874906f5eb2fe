//! The parametric body description (RON, cm and degrees): what a user writes to define a
//! mannequin. Each of the 17 parts is a tube swept along a straight axis from its joint pivot,
//! with superellipse cross-sections at given distances along the axis, closed by flat caps at
//! both ends, and the rotation limits of its joint. The description also names the sizes it was
//! drafted for and the heights of the bust, waist and hip lines. Checked while it is parsed, so
//! an error names the file, the position, the field and the value (see `docs/body-model.md`).

use std::path::Path;

use atelier_files::check::{Validate, non_empty, positive};
use atelier_files::{ErrorKind, FileError, InvalidValue};
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize};

use crate::model::{JointLimits, Part};

/// A body description: the drafted sizes, the measuring lines, the mesh resolution and the 17
/// parts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct BodyDescription {
    /// Name (becomes the mannequin's).
    #[serde(deserialize_with = "non_empty")]
    pub name: String,
    /// Where the shape comes from (a size chart, a survey, a scan).
    #[serde(deserialize_with = "non_empty")]
    pub provenance: String,
    /// The sizes the description was drafted for (building at these sizes keeps its shape).
    pub sizes: Sizes,
    /// Heights above the floor (cm) of the lines where the girths are measured.
    pub levels: Levels,
    /// Mesh resolution.
    pub resolution: Resolution,
    /// The parts, each exactly once, in any order.
    pub parts: Vec<PartDescription>,
}

/// Body sizes, cm: height and the three torso girths.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sizes {
    /// Height (top of the head above the soles), cm.
    #[serde(deserialize_with = "positive")]
    pub height_cm: f64,
    /// Bust girth, cm.
    #[serde(deserialize_with = "positive")]
    pub bust_cm: f64,
    /// Waist girth, cm.
    #[serde(deserialize_with = "positive")]
    pub waist_cm: f64,
    /// Hip girth, cm.
    #[serde(deserialize_with = "positive")]
    pub hip_cm: f64,
}

impl Sizes {
    /// JIS L 4005 adult female 9AR: height 158, bust 83, waist 64, hip 91 cm.
    pub const JIS_9AR: Sizes = Sizes {
        height_cm: 158.0,
        bust_cm: 83.0,
        waist_cm: 64.0,
        hip_cm: 91.0,
    };

    /// Check every size is finite and positive.
    pub fn check(&self) -> Result<(), InvalidValue> {
        for (name, v) in [
            ("height_cm", self.height_cm),
            ("bust_cm", self.bust_cm),
            ("waist_cm", self.waist_cm),
            ("hip_cm", self.hip_cm),
        ] {
            atelier_files::check::positive_value(v).map_err(|e| e.within(name))?;
        }
        Ok(())
    }
}

/// Heights above the floor (cm, in the body as described) of the girth lines.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct Levels {
    /// Bust line, cm.
    #[serde(deserialize_with = "positive")]
    pub bust_cm: f64,
    /// Waist line, cm.
    #[serde(deserialize_with = "positive")]
    pub waist_cm: f64,
    /// Hip line, cm.
    #[serde(deserialize_with = "positive")]
    pub hip_cm: f64,
}

impl Validate for Levels {
    fn validate(&self) -> Result<(), InvalidValue> {
        if self.hip_cm >= self.waist_cm || self.waist_cm >= self.bust_cm {
            return Err(InvalidValue::new(
                ErrorKind::NonMonotone,
                "",
                format!(
                    "the lines must rise hip < waist < bust (hip {}, waist {}, bust {})",
                    self.hip_cm, self.waist_cm, self.bust_cm
                ),
            ));
        }
        Ok(())
    }
}
atelier_files::validated!(Levels);

/// Mesh resolution.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Resolution {
    /// Vertices around each cross-section (3 to 256), unless a part sets its own.
    #[serde(deserialize_with = "around")]
    pub around: usize,
}

/// One part: its joint, its axis, its cross-sections and its rotation limits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct PartDescription {
    /// The part's name, as [`Part::name`] spells it (`"thigh_left"`).
    pub part: String,
    /// The joint's pivot in the rest pose, cm (world frame: x the body's left, y up, z forward).
    #[serde(deserialize_with = "finite3")]
    pub pivot: [f64; 3],
    /// Direction of the part's axis from the pivot (normalised when built; not zero).
    #[serde(deserialize_with = "finite3")]
    pub axis: [f64; 3],
    /// Cross-sections, strictly increasing along the axis; at least two.
    pub sections: Vec<Section>,
    /// Rotation limits of the joint, degrees (the convention of [`JointLimits`]).
    pub limits: Limits,
    /// Vertices around each section for this part (default: the description's resolution).
    #[serde(default, deserialize_with = "opt_around")]
    pub around: Option<usize>,
}

/// A cross-section perpendicular to the axis: the superellipse
/// `|s/half_x|^exponent + |t/half_z|^exponent = 1` in the section's (u, v) frame (see
/// `docs/body-model.md`: u is world x made perpendicular to the axis, v completes the frame and
/// points forward, or up when the axis is horizontal).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Section {
    /// Distance from the pivot along the axis, cm (negative: behind the pivot, inside the parent).
    #[serde(deserialize_with = "finite")]
    pub at: f64,
    /// Half-width along u (across x), cm.
    #[serde(deserialize_with = "positive")]
    pub half_x: f64,
    /// Half-width along v (across z), cm.
    #[serde(deserialize_with = "positive")]
    pub half_z: f64,
    /// Superellipse exponent (2 = ellipse; larger is boxier), 1 to 10.
    #[serde(default = "two", deserialize_with = "exponent")]
    pub exponent: f64,
    /// Offset of the section's centre from the axis along (u, v), cm.
    #[serde(default, deserialize_with = "finite2")]
    pub centre: (f64, f64),
}

/// Rotation limits, degrees: `(min, max)` about x, y and z, with `min ≤ 0 ≤ max` (the rest pose
/// is allowed) and both within ±180°.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct Limits {
    /// About x (flexion; see [`JointLimits`] for the signs).
    #[serde(deserialize_with = "finite2")]
    pub x: (f64, f64),
    /// About y (axial rotation).
    #[serde(deserialize_with = "finite2")]
    pub y: (f64, f64),
    /// About z (abduction).
    #[serde(deserialize_with = "finite2")]
    pub z: (f64, f64),
}

impl Validate for Limits {
    fn validate(&self) -> Result<(), InvalidValue> {
        for (name, (lo, hi)) in [("x", self.x), ("y", self.y), ("z", self.z)] {
            if !(-180.0..=180.0).contains(&lo) || !(-180.0..=180.0).contains(&hi) {
                return Err(InvalidValue::new(
                    ErrorKind::OutOfRange,
                    name,
                    format!("({lo}, {hi}) must lie within ±180°"),
                ));
            }
            if lo > 0.0 || hi < 0.0 {
                return Err(InvalidValue::new(
                    ErrorKind::Inconsistent,
                    name,
                    format!("({lo}, {hi}) must satisfy min ≤ 0 ≤ max (the rest pose)"),
                ));
            }
        }
        Ok(())
    }
}
atelier_files::validated!(Limits);

impl Limits {
    /// As the model's joint limits.
    pub fn joint_limits(&self) -> JointLimits {
        JointLimits {
            min_deg: [self.x.0, self.y.0, self.z.0],
            max_deg: [self.x.1, self.y.1, self.z.1],
        }
    }
}

fn two() -> f64 {
    2.0
}

fn finite_value(v: f64) -> Result<f64, InvalidValue> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(InvalidValue::new(
            ErrorKind::NotFinite,
            "",
            format!("{v} is not a finite number"),
        ))
    }
}

fn finite<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    finite_value(f64::deserialize(d)?).map_err(D::Error::custom)
}

fn finite2<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
    let (a, b) = <(f64, f64)>::deserialize(d)?;
    for (k, v) in [a, b].into_iter().enumerate() {
        finite_value(v)
            .map_err(|e| e.within(&format!("[{k}]")))
            .map_err(D::Error::custom)?;
    }
    Ok((a, b))
}

fn finite3<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
    let v = <(f64, f64, f64)>::deserialize(d)?;
    let v = [v.0, v.1, v.2];
    for (k, c) in v.iter().enumerate() {
        finite_value(*c)
            .map_err(|e| e.within(&format!("[{k}]")))
            .map_err(D::Error::custom)?;
    }
    Ok(v)
}

fn exponent<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = finite_value(f64::deserialize(d)?).map_err(D::Error::custom)?;
    if !(1.0..=10.0).contains(&v) {
        return Err(D::Error::custom(InvalidValue::new(
            ErrorKind::OutOfRange,
            "",
            format!("exponent {v} must lie in [1, 10]"),
        )));
    }
    Ok(v)
}

fn around_value(n: usize) -> Result<usize, InvalidValue> {
    if (3..=256).contains(&n) {
        Ok(n)
    } else {
        Err(InvalidValue::new(
            ErrorKind::OutOfRange,
            "",
            format!("{n} vertices around a section: must lie in [3, 256]"),
        ))
    }
}

fn around<'de, D: Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
    around_value(usize::deserialize(d)?).map_err(D::Error::custom)
}

fn opt_around<'de, D: Deserializer<'de>>(d: D) -> Result<Option<usize>, D::Error> {
    Option::<usize>::deserialize(d)?
        .map(around_value)
        .transpose()
        .map_err(D::Error::custom)
}

/// The part of a name as [`Part::name`] spells it.
pub fn part_named(name: &str) -> Option<Part> {
    Part::ALL.into_iter().find(|p| p.name() == name)
}

impl PartDescription {
    /// The part (valid once the description is checked).
    pub fn part(&self) -> Option<Part> {
        part_named(&self.part)
    }
}

impl Validate for PartDescription {
    fn validate(&self) -> Result<(), InvalidValue> {
        if part_named(&self.part).is_none() {
            let names: Vec<&str> = Part::ALL.iter().map(|p| p.name()).collect();
            return Err(InvalidValue::new(
                ErrorKind::UnknownVariant,
                "part",
                format!(
                    "unknown part `{}`, expected one of {}",
                    self.part,
                    names.join(", ")
                ),
            ));
        }
        let a = self.axis;
        if (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt() < 1e-9 {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                "axis",
                "the axis must not be zero",
            ));
        }
        if self.sections.len() < 2 {
            return Err(InvalidValue::new(
                ErrorKind::TooShort,
                "sections",
                format!("{} section(s): at least two needed", self.sections.len()),
            ));
        }
        for (k, w) in self.sections.windows(2).enumerate() {
            if w[1].at <= w[0].at {
                return Err(InvalidValue::new(
                    ErrorKind::NonMonotone,
                    format!("sections[{}].at", k + 1),
                    format!(
                        "sections must increase along the axis: {} after {}",
                        w[1].at, w[0].at
                    ),
                ));
            }
        }
        Ok(())
    }
}
atelier_files::validated!(PartDescription);

impl Validate for BodyDescription {
    fn validate(&self) -> Result<(), InvalidValue> {
        let mut seen: [Option<usize>; 17] = [None; 17];
        for (k, pd) in self.parts.iter().enumerate() {
            // Each part is already checked while parsed; re-check for values built in code.
            pd.validate()
                .map_err(|e| e.within(&format!("parts[{k}]")))?;
            let Some(p) = pd.part() else { continue };
            if let Some(first) = seen[p.index()] {
                return Err(InvalidValue::new(
                    ErrorKind::DuplicateField,
                    format!("parts[{k}].part"),
                    format!("part `{}` listed twice (first at parts[{first}])", p.name()),
                ));
            }
            seen[p.index()] = Some(k);
        }
        if let Some(missing) = Part::ALL.iter().find(|p| seen[p.index()].is_none()) {
            return Err(InvalidValue::new(
                ErrorKind::MissingField,
                "parts",
                format!("part `{}` is missing", missing.name()),
            ));
        }
        self.sizes.check().map_err(|e| e.within("sizes"))?;
        self.levels.validate().map_err(|e| e.within("levels"))?;
        if self.levels.bust_cm >= self.sizes.height_cm {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                "levels.bust_cm",
                format!(
                    "bust line {} lies above the height {}",
                    self.levels.bust_cm, self.sizes.height_cm
                ),
            ));
        }
        Ok(())
    }
}
atelier_files::validated!(BodyDescription);

impl BodyDescription {
    /// Parse RON text; `file` names the source in errors.
    pub fn parse(text: &str, file: &Path) -> Result<Self, FileError> {
        atelier_files::files::parse_ron(text, file)
    }

    /// Read and parse a description file.
    pub fn load(path: &Path) -> Result<Self, FileError> {
        atelier_files::files::load_ron(path)
    }

    /// The description of a part, if listed.
    pub fn part(&self, p: Part) -> Option<&PartDescription> {
        self.parts.iter().find(|d| d.part() == Some(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FIXTURE: &str = include_str!("../../../fixtures/bodies/jis_9ar.ron");

    fn parse(text: &str) -> Result<BodyDescription, FileError> {
        BodyDescription::parse(text, Path::new("test.ron"))
    }

    #[test]
    fn the_fixture_parses() {
        let d = parse(FIXTURE).expect("fixture parses");
        assert_eq!(d.parts.len(), 17);
        assert_eq!(d.sizes, Sizes::JIS_9AR);
        for p in Part::ALL {
            assert!(d.part(p).is_some(), "{}", p.name());
        }
    }

    /// The fixture with the first occurrence of `from` replaced by `to`.
    fn edit(from: &str, to: &str) -> String {
        assert!(FIXTURE.contains(from), "fixture lacks {from}");
        FIXTURE.replacen(from, to, 1)
    }

    fn line_of(text: &str, needle: &str) -> usize {
        text.lines()
            .position(|l| l.contains(needle))
            .expect("needle present")
            + 1
    }

    #[test]
    fn an_unknown_part_is_refused_at_its_position() {
        let text = edit("part: \"head\"", "part: \"tail\"");
        let e = parse(&text).expect_err("unknown part");
        assert_eq!(e.kind, ErrorKind::UnknownVariant, "{e}");
        assert!(e.field.ends_with(".part"), "{e}");
        assert!(e.message.contains("tail"), "{e}");
        let line = e.position.expect("position").line;
        assert!(line >= line_of(&text, "\"tail\""), "{e}");
    }

    #[test]
    fn nan_is_refused_at_its_position() {
        let text = edit("half_x: 6.3", "half_x: NaN");
        let e = parse(&text).expect_err("NaN");
        assert_eq!(e.kind, ErrorKind::NotFinite, "{e}");
        assert!(e.field.ends_with("half_x"), "{e}");
        assert_eq!(e.position.expect("position").line, line_of(&text, "NaN"));
        let text = edit("pivot: (0.0, 141.0", "pivot: (0.0, inf");
        let e = parse(&text).expect_err("inf");
        assert_eq!(e.kind, ErrorKind::NotFinite, "{e}");
        assert!(e.field.ends_with("pivot[1]"), "{e}");
    }

    #[test]
    fn a_negative_size_is_refused() {
        let text = edit("half_z: 8.0", "half_z: -8.0");
        let e = parse(&text).expect_err("negative");
        assert_eq!(e.kind, ErrorKind::Negative, "{e}");
        let text = edit("waist_cm: 64.0", "waist_cm: -64.0");
        assert_eq!(
            parse(&text).expect_err("negative").kind,
            ErrorKind::Negative
        );
    }

    #[test]
    fn sections_must_increase_along_the_axis() {
        let text = edit("at: 4.0,", "at: -1.0,");
        let e = parse(&text).expect_err("not increasing");
        assert_eq!(e.kind, ErrorKind::NonMonotone, "{e}");
        assert!(e.field.contains("sections["), "{e}");
        assert!(e.position.is_some());
    }

    /// The text with the part block named `name` removed (blocks start with `(` on their own
    /// line followed by `part: "name"` and end with the matching `),`).
    fn without_part(text: &str, name: &str) -> String {
        let lines: Vec<&str> = text.lines().collect();
        let at = lines
            .iter()
            .position(|l| l.trim() == format!("part: \"{name}\","))
            .expect("part present");
        let start = (0..at)
            .rev()
            .find(|&k| lines[k].trim() == "(")
            .expect("block start");
        let indent = lines[start].len() - lines[start].trim_start().len();
        let end = (at..lines.len())
            .find(|&k| {
                lines[k].trim() == ")," && lines[k].len() - lines[k].trim_start().len() == indent
            })
            .expect("block end");
        let mut out: Vec<&str> = lines[..start].to_vec();
        out.extend_from_slice(&lines[end + 1..]);
        out.join("\n")
    }

    #[test]
    fn a_missing_or_repeated_part_is_refused() {
        let text = without_part(FIXTURE, "hand_right");
        let e = parse(&text).expect_err("missing");
        assert_eq!(e.kind, ErrorKind::MissingField, "{e}");
        assert!(e.message.contains("hand_right"), "{e}");
        let text = edit("part: \"hand_right\"", "part: \"hand_left\"");
        let e = parse(&text).expect_err("twice");
        assert_eq!(e.kind, ErrorKind::DuplicateField, "{e}");
        assert!(e.message.contains("hand_left"), "{e}");
    }

    #[test]
    fn unknown_fields_and_bad_limits_are_refused() {
        let text = edit("provenance:", "colour: \"pink\",\n    provenance:");
        assert_eq!(
            parse(&text).expect_err("field").kind,
            ErrorKind::UnknownField
        );
        let text = edit("provenance: \"", "nom: \"");
        let e = parse(&text).expect_err("missing provenance");
        assert!(
            matches!(e.kind, ErrorKind::UnknownField | ErrorKind::MissingField),
            "{e}"
        );
        let text = FIXTURE.replacen("x: (0.0, 140.0)", "x: (10.0, 140.0)", 1);
        assert_ne!(text, FIXTURE);
        assert_eq!(
            parse(&text).expect_err("rest pose outside").kind,
            ErrorKind::Inconsistent
        );
    }
}
