//! Observation files (RON): the static shapes of one string-like object as marker positions in
//! an image, with the image's pixel size and the held ends' positions (`docs/fit.md`).
//!
//! ```ron
//! Observations(
//!     name: "rubber string",
//!     provenance: "synthetic: …",
//!     pixel_size: 0.002,             // m per pixel
//!     image: (640, 480),             // width, height, pixels
//!     shapes: [
//!         (ends: ((160.0, 120.0), (330.5, 210.0)),          // fixed end, manipulated end
//!          markers: [(160.2, 119.7), (181.0, 140.3), …]),   // the first and last at the ends
//!     ],
//! )
//! ```
//!
//! Pixels: u to the right, v down, from the image's top-left corner. Inside atelier positions
//! are metres with y up from the image's bottom-left corner: `x = u·p`, `y = (height − v)·p`.
//! The model's end particles sit on `ends` (the held positions, known from the manipulation);
//! the first and last markers are the observed ends and are not otherwise used.

use std::path::Path;

use atelier_files::{ErrorKind, FileError, InvalidValue, files};
use serde::{Deserialize, Serialize};

use crate::string::V2;

/// One observed static shape, pixels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObservedShape {
    /// The fixed end and the manipulated end, pixels.
    pub ends: ([f64; 2], [f64; 2]),
    /// The markers from the fixed end to the manipulated end, pixels.
    pub markers: Vec<[f64; 2]>,
}

/// The observed shapes of one object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Observations {
    /// The object's name.
    pub name: String,
    /// Where the observations come from.
    pub provenance: String,
    /// Size of a pixel, m (> 0).
    pub pixel_size: f64,
    /// Image width and height, pixels (> 0).
    pub image: (u32, u32),
    /// The shapes (at least one).
    pub shapes: Vec<ObservedShape>,
}

impl Observations {
    /// Read and check an observation file (errors name the file, line:column and field).
    pub fn load(path: &Path) -> Result<Self, FileError> {
        let text = files::read_text(path)?;
        Self::parse(&text, path)
    }

    /// Parse and check observation text; `file` names it in errors.
    pub fn parse(text: &str, file: &Path) -> Result<Self, FileError> {
        let o: Self = files::parse_ron(text, file)?;
        o.check().map_err(|e| files::located(file, text, e))?;
        Ok(o)
    }

    /// The RON text of these observations.
    pub fn to_ron(&self) -> String {
        let pretty = ron::ser::PrettyConfig::new().depth_limit(3);
        ron::ser::to_string_pretty(self, pretty).unwrap_or_default()
    }

    /// Check every value: a positive finite pixel size and image, at least one shape, every
    /// shape with at least 3 markers and as many as the first, every coordinate finite and
    /// inside the image, and not every shape the same.
    pub fn check(&self) -> Result<(), InvalidValue> {
        let bad =
            |field: String, kind, message: String| Err(InvalidValue::new(kind, field, message));
        if !(self.pixel_size.is_finite() && self.pixel_size > 0.0) {
            return bad(
                "pixel_size".into(),
                ErrorKind::OutOfRange,
                format!("{} is not a positive size", self.pixel_size),
            );
        }
        let (w, h) = (f64::from(self.image.0), f64::from(self.image.1));
        if self.image.0 == 0 || self.image.1 == 0 {
            return bad(
                "image".into(),
                ErrorKind::OutOfRange,
                format!("{} × {} pixels", self.image.0, self.image.1),
            );
        }
        if self.shapes.is_empty() {
            return bad("shapes".into(), ErrorKind::OutOfRange, "no shape".into());
        }
        let count = self.shapes[0].markers.len();
        let inside = |p: &[f64; 2]| p[0] >= 0.0 && p[0] <= w && p[1] >= 0.0 && p[1] <= h;
        for (j, s) in self.shapes.iter().enumerate() {
            let n = s.markers.len();
            if n < 3 {
                return bad(
                    format!("shapes[{j}].markers"),
                    ErrorKind::OutOfRange,
                    format!("{n} markers; a string needs at least 3"),
                );
            }
            if n != count {
                return bad(
                    format!("shapes[{j}].markers"),
                    ErrorKind::Inconsistent,
                    format!("{n} markers where shape 0 has {count}"),
                );
            }
            for (k, p) in s.markers.iter().enumerate() {
                if !(p[0].is_finite() && p[1].is_finite()) {
                    return bad(
                        format!("shapes[{j}].markers[{k}]"),
                        ErrorKind::NotFinite,
                        format!("({}, {})", p[0], p[1]),
                    );
                }
                if !inside(p) {
                    return bad(
                        format!("shapes[{j}].markers[{k}]"),
                        ErrorKind::OutOfRange,
                        format!("({}, {}) is outside the {w} × {h} image", p[0], p[1]),
                    );
                }
            }
            for (k, p) in [s.ends.0, s.ends.1].iter().enumerate() {
                if !(p[0].is_finite() && p[1].is_finite() && inside(p)) {
                    return bad(
                        format!("shapes[{j}].ends"),
                        if p[0].is_finite() && p[1].is_finite() {
                            ErrorKind::OutOfRange
                        } else {
                            ErrorKind::NotFinite
                        },
                        format!(
                            "the {} end ({}, {}) is outside the {w} × {h} image",
                            if k == 0 { "fixed" } else { "manipulated" },
                            p[0],
                            p[1]
                        ),
                    );
                }
            }
            if (s.ends.0[0] - s.ends.1[0]).abs() + (s.ends.0[1] - s.ends.1[1]).abs() == 0.0 {
                return bad(
                    format!("shapes[{j}].ends"),
                    ErrorKind::Inconsistent,
                    "both ends at one point".into(),
                );
            }
        }
        if self.shapes.len() > 1
            && self
                .shapes
                .iter()
                .all(|s| s.markers == self.shapes[0].markers)
        {
            return bad(
                "shapes".into(),
                ErrorKind::Inconsistent,
                format!(
                    "all {} shapes are the same: the parameters are not identifiable from one shape repeated",
                    self.shapes.len()
                ),
            );
        }
        Ok(())
    }

    /// A pixel position in metres (y up).
    pub fn to_metres(&self, p: [f64; 2]) -> V2 {
        V2::new(p[0], f64::from(self.image.1) - p[1]) * self.pixel_size
    }

    /// A position in metres in pixels.
    pub fn to_pixels(&self, x: &V2) -> [f64; 2] {
        [
            x.x / self.pixel_size,
            f64::from(self.image.1) - x.y / self.pixel_size,
        ]
    }

    /// Shape j as the fit uses it, metres: the held ends with the inner markers between them.
    pub fn shape(&self, j: usize) -> Vec<V2> {
        let s = &self.shapes[j];
        let n = s.markers.len();
        let mut x: Vec<V2> = s.markers.iter().map(|p| self.to_metres(*p)).collect();
        x[0] = self.to_metres(s.ends.0);
        x[n - 1] = self.to_metres(s.ends.1);
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(shapes: &str) -> String {
        format!(
            "Observations(name: \"t\", provenance: \"test\", pixel_size: 0.002, image: (640, 480), shapes: [{shapes}])"
        )
    }

    const A: &str =
        "(ends: ((10.0, 10.0), (50.0, 10.0)), markers: [(10.0, 10.0), (30.0, 20.0), (50.0, 10.0)])";
    const B: &str =
        "(ends: ((10.0, 10.0), (60.0, 10.0)), markers: [(10.0, 10.0), (35.0, 25.0), (60.0, 10.0)])";

    /// A good file reads; metres have y up from the bottom-left corner.
    #[test]
    fn a_good_file_reads_and_converts() {
        let o = Observations::parse(&text(&format!("{A}, {B}")), "t.ron".as_ref()).expect("reads");
        let s = o.shape(1);
        assert_eq!(s.len(), 3);
        assert!((s[1] - V2::new(0.07, 0.91)).norm() < 1e-12, "{s:?}");
        let back = Observations::parse(&o.to_ron(), "t.ron".as_ref()).expect("round trip");
        assert_eq!(back, o);
    }

    /// Bad input, one case each: fewer than three markers, different counts, NaN, every shape
    /// the same, an end outside the image; each error names the file, the line:column and
    /// the field.
    #[test]
    fn bad_files_are_refused_with_file_position_and_field() {
        let cases = [
            (
                "(ends: ((10.0, 10.0), (50.0, 10.0)), markers: [(10.0, 10.0), (50.0, 10.0)])"
                    .to_string(),
                "shapes[0].markers",
                "2 markers",
            ),
            (
                format!(
                    "{A}, (ends: ((10.0, 10.0), (50.0, 10.0)), markers: [(10.0, 10.0), (20.0, 12.0), (30.0, 12.0), (50.0, 10.0)])"
                ),
                "shapes[1].markers",
                "4 markers where shape 0 has 3",
            ),
            (
                format!(
                    "{A}, (ends: ((10.0, 10.0), (50.0, 10.0)), markers: [(10.0, 10.0), (NaN, 12.0), (50.0, 10.0)])"
                ),
                "shapes[1].markers[1]",
                "NaN",
            ),
            (format!("{A}, {A}, {A}"), "shapes", "not identifiable"),
            (
                format!(
                    "{A}, (ends: ((10.0, 10.0), (700.0, 10.0)), markers: [(10.0, 10.0), (35.0, 25.0), (60.0, 10.0)])"
                ),
                "shapes[1].ends",
                "outside the 640 × 480 image",
            ),
        ];
        for (shapes, field, says) in cases {
            let e = Observations::parse(&text(&shapes), "obs.ron".as_ref()).expect_err("refused");
            let msg = e.to_string();
            assert!(msg.starts_with("obs.ron:1:"), "{msg}");
            assert_eq!(e.field, field, "{msg}");
            assert!(msg.contains(says), "{msg}");
        }
    }
}
