//! The side file: a small RON file describing one range image (one view of the body).
//!
//! ```ron
//! (
//!     view: Front,               // Front or Back
//!     image: "front.pgm",        // relative to this file; 16-bit PGM (P5) or grayscale PNG
//!     pixel_size: 2.5,           // mm, square pixels
//!     depth_scale: 0.02,         // mm per grey unit
//!     depth_offset: 500.0,       // mm: distance from the camera plane at grey value 0
//!     camera_z: 1000.0,          // world z (mm) of the camera plane
//!     origin: (-400.0, 1700.0),  // world (x, y) in mm of the centre of pixel (column 0, row 0)
//!     landmarks: { "crown": (160.0, 12.0) },  // named points, (column, row) in pixels
//! )
//! ```
//!
//! See `docs/grid-range.md` for the frame and the meaning of every field.

use std::collections::BTreeMap;
use std::path::Path;

use atelier_files::check::{self, Validate, validated};
use atelier_files::files::write_atomic;
use atelier_files::{ErrorKind, InvalidValue};
use serde::{Deserialize, Serialize};

/// Which camera took a range image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum View {
    /// In front of the body, looking along −z; image columns run towards +x.
    Front,
    /// Behind the body, looking along +z; image columns run towards −x (the image is mirrored).
    Back,
}

/// One view's side file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct SideFile {
    /// Which view.
    pub view: View,
    /// The image file, relative to the side file.
    #[serde(deserialize_with = "check::non_empty")]
    pub image: String,
    /// Pixel size, mm (square pixels).
    #[serde(deserialize_with = "check::positive")]
    pub pixel_size: f64,
    /// mm per grey unit.
    #[serde(deserialize_with = "check::positive")]
    pub depth_scale: f64,
    /// Distance from the camera plane at grey value 0, mm.
    #[serde(deserialize_with = "check::non_negative")]
    pub depth_offset: f64,
    /// World z of the camera plane, mm. A sample of grey value `v > 0` lies at distance
    /// `d = depth_offset + depth_scale·v` from it: world `z = camera_z − d` (front) or
    /// `z = camera_z + d` (back). Grey value 0 means no sample (the mask).
    pub camera_z: f64,
    /// World `(x, y)` in mm of the centre of pixel (column 0, row 0). Rows run towards −y;
    /// columns towards +x (front) or −x (back).
    pub origin: (f64, f64),
    /// Named points `(column, row)` in pixels (see [`crate::range::LANDMARKS`]).
    #[serde(default)]
    pub landmarks: BTreeMap<String, (f64, f64)>,
}

validated!(SideFile);

impl Validate for SideFile {
    fn validate(&self) -> Result<(), InvalidValue> {
        let finite = |v: f64, field: &str| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(InvalidValue::new(
                    ErrorKind::NotFinite,
                    field,
                    format!("{v} is not a finite number"),
                ))
            }
        };
        finite(self.camera_z, "camera_z")?;
        finite(self.origin.0, "origin")?;
        finite(self.origin.1, "origin")?;
        for (name, &(c, r)) in &self.landmarks {
            let field = format!("landmarks.{name}");
            finite(c, &field)?;
            finite(r, &field)?;
        }
        Ok(())
    }
}

impl SideFile {
    /// The RON text of this side file (the format read by [`crate::range::RangeBody::load`]).
    pub fn to_ron(&self) -> String {
        let view = match self.view {
            View::Front => "Front",
            View::Back => "Back",
        };
        let mut s = format!(
            "(\n    view: {view},\n    image: {:?},\n    pixel_size: {:?},\n    depth_scale: {:?},\n    depth_offset: {:?},\n    camera_z: {:?},\n    origin: ({:?}, {:?}),\n    landmarks: {{\n",
            self.image,
            self.pixel_size,
            self.depth_scale,
            self.depth_offset,
            self.camera_z,
            self.origin.0,
            self.origin.1
        );
        for (name, (c, r)) in &self.landmarks {
            s.push_str(&format!("        {name:?}: ({c:?}, {r:?}),\n"));
        }
        s.push_str("    },\n)\n");
        s
    }

    /// Write the side file atomically.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        write_atomic(path, self.to_ron().as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use atelier_files::files::parse_ron;

    fn side() -> SideFile {
        SideFile {
            view: View::Back,
            image: "b.png".into(),
            pixel_size: 2.5,
            depth_scale: 0.02,
            depth_offset: 500.0,
            camera_z: -1000.0,
            origin: (-400.0, 1700.0),
            landmarks: [("crown".to_owned(), (1.5, 2.0))].into_iter().collect(),
        }
    }

    #[test]
    fn side_file_round_trips() {
        let s = side();
        let back: SideFile = parse_ron(&s.to_ron(), Path::new("s.ron")).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn bad_pixel_sizes_are_rejected_at_their_position() {
        for (bad, kind) in [
            ("NaN", ErrorKind::NotFinite),
            ("-2.5", ErrorKind::Negative),
            ("0.0", ErrorKind::OutOfRange),
        ] {
            let text = side()
                .to_ron()
                .replace("pixel_size: 2.5", &format!("pixel_size: {bad}"));
            let e = parse_ron::<SideFile>(&text, Path::new("s.ron")).unwrap_err();
            assert_eq!((e.kind, e.field.as_str()), (kind, "pixel_size"), "{e}");
            assert_eq!(e.position.map(|p| p.line), Some(4), "{e}");
        }
    }

    #[test]
    fn unknown_fields_and_views_are_rejected() {
        let text = side().to_ron().replace("view: Back", "view: Side");
        let e = parse_ron::<SideFile>(&text, Path::new("s.ron")).unwrap_err();
        assert_eq!(e.kind, ErrorKind::UnknownVariant);
        let text = side().to_ron().replace("camera_z", "camera_zz");
        let e = parse_ron::<SideFile>(&text, Path::new("s.ron")).unwrap_err();
        assert_eq!(e.kind, ErrorKind::UnknownField);
        let text = side().to_ron().replace("(1.5, 2.0)", "(inf, 2.0)");
        let e = parse_ron::<SideFile>(&text, Path::new("s.ron")).unwrap_err();
        assert_eq!(
            (e.kind, e.field.as_str()),
            (ErrorKind::NotFinite, "landmarks.crown")
        );
    }
}
