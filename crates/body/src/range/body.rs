//! A body measured by two range images (front and back) registered on one pixel grid.

use std::collections::BTreeMap;
use std::path::Path;

use atelier_files::files::load_ron;
use atelier_files::{ErrorKind, FileError, InvalidValue};

use super::image::{GrayImage, read_image};
use super::side::{SideFile, View};

/// The landmarks the part split needs, all on the silhouette (outline) of the front view, given
/// in the front side file as `(column, row)` pixels. `_l`/`_r` are the body's left (+x) and right.
pub const LANDMARKS: [&str; 31] = [
    "chin_l",
    "chin_r",
    "neck_l",
    "neck_r",
    "shoulder_l",
    "shoulder_r",
    "armpit_l",
    "armpit_r",
    "elbow_out_l",
    "elbow_in_l",
    "elbow_out_r",
    "elbow_in_r",
    "wrist_out_l",
    "wrist_in_l",
    "wrist_out_r",
    "wrist_in_r",
    "waist_l",
    "waist_r",
    "hip_l",
    "hip_r",
    "crotch",
    "thigh_l",
    "thigh_r",
    "knee_out_l",
    "knee_in_l",
    "knee_out_r",
    "knee_in_r",
    "ankle_out_l",
    "ankle_in_l",
    "ankle_out_r",
    "ankle_in_r",
];

/// Two registered range images of one body, in world millimetres.
///
/// Both depth maps are stored in the *front* column order: sample `(c, r)` (index `r·width + c`)
/// lies at world `x = origin[0] + c·pixel_size`, `y = origin[1] − r·pixel_size`. `front[k]` is
/// the largest world z of the body along that line of sight, `back[k]` the smallest; NaN where the
/// view has no sample.
#[derive(Clone, Debug, PartialEq)]
pub struct RangeBody {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Pixel size, mm.
    pub pixel_size: f64,
    /// World `(x, y)`, mm, of the centre of sample `(0, 0)`.
    pub origin: [f64; 2],
    /// Front depth (world z, mm; NaN = no sample).
    pub front: Vec<f64>,
    /// Back depth (world z, mm; NaN = no sample).
    pub back: Vec<f64>,
    /// Landmarks in world `(x, y)`, mm.
    pub landmarks: BTreeMap<String, [f64; 2]>,
}

fn invalid(file: &Path, kind: ErrorKind, field: &str, message: String) -> FileError {
    FileError::from_invalid(file, InvalidValue::new(kind, field, message))
}

impl RangeBody {
    /// Load a body from its front and back side files (each naming its image).
    pub fn load(front_side: &Path, back_side: &Path) -> Result<Self, FileError> {
        let front: SideFile = load_ron(front_side)?;
        let back: SideFile = load_ron(back_side)?;
        let image_path = |side: &Path, name: &str| {
            side.parent()
                .map_or_else(|| Path::new(name).to_path_buf(), |d| d.join(name))
        };
        let fi = read_image(&image_path(front_side, &front.image))?;
        let bi = read_image(&image_path(back_side, &back.image))?;
        Self::from_views((&front, &fi, front_side), (&back, &bi, back_side))
    }

    /// Build a body from parsed side files and decoded images; the paths name the side files in
    /// errors.
    pub fn from_views(
        front: (&SideFile, &GrayImage, &Path),
        back: (&SideFile, &GrayImage, &Path),
    ) -> Result<Self, FileError> {
        let (fs, fi, fpath) = front;
        let (bs, bi, bpath) = back;
        if fs.view != View::Front {
            return Err(invalid(
                fpath,
                ErrorKind::Inconsistent,
                "view",
                "the front side file must say `view: Front`".into(),
            ));
        }
        if bs.view != View::Back {
            return Err(invalid(
                bpath,
                ErrorKind::Inconsistent,
                "view",
                "the back side file must say `view: Back`".into(),
            ));
        }
        if (fi.width, fi.height) != (bi.width, bi.height) {
            return Err(invalid(
                bpath,
                ErrorKind::Inconsistent,
                "image",
                format!(
                    "the back image is {} × {} pixels, the front {} × {}",
                    bi.width, bi.height, fi.width, fi.height
                ),
            ));
        }
        for (im, path) in [(fi, fpath), (bi, bpath)] {
            if im.data.len() != im.width * im.height {
                return Err(invalid(
                    path,
                    ErrorKind::Inconsistent,
                    "image",
                    format!(
                        "{} samples for a {} × {} image",
                        im.data.len(),
                        im.width,
                        im.height
                    ),
                ));
            }
        }
        let (w, h, px) = (fi.width, fi.height, fs.pixel_size);
        if (bs.pixel_size - px).abs() > 1e-9 * px {
            return Err(invalid(
                bpath,
                ErrorKind::Inconsistent,
                "pixel_size",
                format!(
                    "back pixel size {} mm differs from the front's {px} mm",
                    bs.pixel_size
                ),
            ));
        }
        // The back image is mirrored: its column c is the front's column w − 1 − c.
        let back_x0 = bs.origin.0 - (w as f64 - 1.0) * px;
        let tol = 1e-3 * px;
        if (back_x0 - fs.origin.0).abs() > tol || (bs.origin.1 - fs.origin.1).abs() > tol {
            return Err(invalid(
                bpath,
                ErrorKind::Inconsistent,
                "origin",
                format!(
                    "the back view does not register with the front: its last column lies at x = {back_x0} mm, row 0 at y = {} mm; the front's first column at x = {} mm, row 0 at y = {} mm",
                    bs.origin.1, fs.origin.0, fs.origin.1
                ),
            ));
        }
        let depth = |s: &SideFile, im: &GrayImage, sign: f64| -> Vec<f64> {
            let mut out = vec![f64::NAN; w * h];
            for r in 0..h {
                for c in 0..w {
                    let v = im.get(c, r);
                    if v == 0 {
                        continue;
                    }
                    let d = s.depth_offset + s.depth_scale * f64::from(v);
                    let col = if sign > 0.0 { c } else { w - 1 - c };
                    out[r * w + col] = s.camera_z - sign * d;
                }
            }
            out
        };
        let front_z = depth(fs, fi, 1.0);
        let back_z = depth(bs, bi, -1.0);
        for (z, path, side) in [(&front_z, fpath, fs), (&back_z, bpath, bs)] {
            if z.iter().all(|v| v.is_nan()) {
                return Err(invalid(
                    path,
                    ErrorKind::TooShort,
                    "image",
                    format!(
                        "`{}` has no valid sample (every value is 0: an empty mask)",
                        side.image
                    ),
                ));
            }
        }
        for (s, path) in [(fs, fpath), (bs, bpath)] {
            for (name, &(c, r)) in &s.landmarks {
                if !(-0.5..=w as f64 - 0.5).contains(&c) || !(-0.5..=h as f64 - 0.5).contains(&r) {
                    return Err(invalid(
                        path,
                        ErrorKind::OutOfRange,
                        &format!("landmarks.{name}"),
                        format!("({c}, {r}) lies outside the {w} × {h} image"),
                    ));
                }
            }
        }
        for name in LANDMARKS {
            if !fs.landmarks.contains_key(name) {
                return Err(invalid(
                    fpath,
                    ErrorKind::MissingField,
                    &format!("landmarks.{name}"),
                    "the part split needs this landmark".into(),
                ));
            }
        }
        let origin = [fs.origin.0, fs.origin.1];
        let landmarks = fs
            .landmarks
            .iter()
            .map(|(k, &(c, r))| (k.clone(), [origin[0] + c * px, origin[1] - r * px]))
            .collect();
        Ok(Self {
            width: w,
            height: h,
            pixel_size: px,
            origin,
            front: front_z,
            back: back_z,
            landmarks,
        })
    }

    /// World `(x, y)` of sample `(c, r)`.
    pub fn world(&self, c: f64, r: f64) -> [f64; 2] {
        [
            self.origin[0] + c * self.pixel_size,
            self.origin[1] - r * self.pixel_size,
        ]
    }

    /// Fractional `(column, row)` of world `(x, y)`.
    pub fn pixel(&self, p: [f64; 2]) -> [f64; 2] {
        [
            (p[0] - self.origin[0]) / self.pixel_size,
            (self.origin[1] - p[1]) / self.pixel_size,
        ]
    }

    /// Whether sample `k` is valid in both views.
    pub fn valid(&self, k: usize) -> bool {
        !self.front[k].is_nan() && !self.back[k].is_nan()
    }

    /// Valid samples of both views together (the thesis's "effective data").
    pub fn valid_samples(&self) -> usize {
        self.front
            .iter()
            .chain(&self.back)
            .filter(|v| !v.is_nan())
            .count()
    }

    /// The body's volume by the range images, mm³: `Σ (front − back)·pixel²` over samples valid in
    /// both views (exact when every line of sight meets the body in one interval).
    pub fn volume_mm3(&self) -> f64 {
        (0..self.front.len())
            .filter(|&k| self.valid(k))
            .map(|k| self.front[k] - self.back[k])
            .sum::<f64>()
            * self.pixel_size
            * self.pixel_size
    }

    /// The landmark `name` in world mm.
    pub fn landmark(&self, name: &str) -> Option<[f64; 2]> {
        self.landmarks.get(name).copied()
    }
}
