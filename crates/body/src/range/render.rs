//! Range images of a posed body: orthographic front and back views rendered by a z-buffer at
//! pixel centres, encoded as 16-bit images with grey 0 = no sample, plus a part-label image per
//! view and the 31 landmarks ([`super::LANDMARKS`]) the gridding of bodies needs
//! (thesis §4.6.2). The output follows the conventions of [`super::SideFile`]
//! exactly, so [`Views::body`] (in memory) or [`Views::write`] (files) feed
//! [`super::grid_body`], and [`round_trip`] closes the loop
//! mannequin → range images → gridded body → error.
//!
//! ```
//! use atelier_body::range::{RenderParams, render_images};
//! use atelier_body::{LabelledMesh, Part, V3};
//!
//! // A tetrahedron (any closed, outward-oriented mesh renders).
//! let mesh = LabelledMesh {
//!     vertices: vec![
//!         V3::new(0.0, 0.0, 0.1),
//!         V3::new(0.1, 0.0, 0.0),
//!         V3::new(0.0, 0.1, 0.0),
//!         V3::new(-0.1, -0.1, -0.1),
//!     ],
//!     triangles: vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
//!     vertex_part: vec![Part::Head; 4],
//!     triangle_part: vec![Part::Head; 4],
//! };
//! let views = render_images(&mesh, 5.0, &RenderParams::default()).unwrap();
//! assert!(views.front.valid_samples() > 0);
//! ```
//!
//! Method, conventions and measured numbers: `docs/body-range.md`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{
    BodyGridParams, BodyMesh, ErrorReport, GrayImage, GridError, RangeBody, SideFile, View,
    grid_body, measure_error, write_image,
};

use crate::model::{LabelledMesh, Mannequin};

use super::find_landmarks;

/// Label value of a pixel without a sample in [`RangeView::part`].
pub const NO_PART: u8 = 255;

/// Largest image the renderer accepts, pixels per view.
pub const MAX_PIXELS: usize = 50_000_000;

/// Why range images could not be rendered, written or used.
#[derive(Debug, thiserror::Error)]
pub enum RangeError {
    /// The mesh has no vertices or no triangles.
    #[error("the mesh is empty ({vertices} vertices, {triangles} triangles)")]
    EmptyMesh {
        /// Vertices.
        vertices: usize,
        /// Triangles.
        triangles: usize,
    },
    /// The mesh is malformed (index out of range, non-finite coordinate, label count).
    #[error("bad mesh: {0}")]
    BadMesh(String),
    /// A pixel size that is not a positive finite number.
    #[error("the pixel size must be a positive finite number of mm, not {0}")]
    BadPixelSize(f64),
    /// A rendering parameter out of range.
    #[error("bad render parameter `{field}`: {message}")]
    BadParameter {
        /// The field of [`RenderParams`].
        field: &'static str,
        /// What is wrong.
        message: String,
    },
    /// No triangle faces the camera of this view (an empty or inside-out mesh, or one seen
    /// edge-on).
    #[error("no triangle faces the {0:?} camera (is the mesh inside out?)")]
    NoFacingTriangles(View),
    /// The view has no sample (the triangles fall between the pixel centres).
    #[error("the {0:?} view has no sample at this pixel size")]
    EmptyView(View),
    /// The image would be too large.
    #[error("the image would be {width} × {height} pixels (at most {MAX_PIXELS})")]
    TooLarge {
        /// Columns.
        width: usize,
        /// Rows.
        height: usize,
    },
    /// The body's depth does not fit 16 bits at the requested depth scale.
    #[error("depth range {span_mm:.1} mm does not fit 16 bits at {scale_mm} mm per grey unit")]
    DepthRange {
        /// Depth span to encode, mm.
        span_mm: f64,
        /// mm per grey unit.
        scale_mm: f64,
    },
    /// A landmark could not be found on the silhouette.
    #[error("landmark `{name}`: {message}")]
    Landmark {
        /// Landmark name (one of [`super::LANDMARKS`]).
        name: String,
        /// Why.
        message: String,
    },
    /// The views could not be turned into a [`RangeBody`].
    #[error("inconsistent views: {0}")]
    Views(#[from] atelier_files::FileError),
    /// Gridding the rendered body failed.
    #[error(transparent)]
    Grid(#[from] GridError),
    /// Writing files failed.
    #[error("writing {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// An image extension other than `pgm` or `png`.
    #[error("image extension must be `pgm` or `png`, not `{0}`")]
    BadExtension(String),
}

/// The image frame of the front view (the back view is its mirror).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// World `(x, y)`, mm, of the centre of front pixel (column 0, row 0).
    pub origin_mm: [f64; 2],
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
}

/// How to render and encode the views.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderParams {
    /// Depth resolution, mm per grey unit (default 0.02 mm: 1.31 m of depth in 16 bits).
    pub depth_scale_mm: f64,
    /// Empty border around the body's projection, mm (default 20; at least two pixels are kept).
    pub margin_mm: f64,
    /// Distance of each camera plane from the body's nearest point, mm (default 500, ≥ 10).
    pub standoff_mm: f64,
    /// A fixed image frame; `None` fits the frame to the body on a grid of whole pixels
    /// (pixel centres at integer multiples of the pixel size).
    pub frame: Option<Frame>,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            depth_scale_mm: 0.02,
            margin_mm: 20.0,
            standoff_mm: 500.0,
            frame: None,
        }
    }
}

/// One rendered view.
#[derive(Clone, Debug, PartialEq)]
pub struct RangeView {
    /// Front or back.
    pub view: View,
    /// The 16-bit range image (grey 0 = no sample), in the camera's column order (the back view
    /// is mirrored: its columns run towards −x).
    pub image: GrayImage,
    /// The side file (image name `front.pgm` / `back.pgm` until [`Views::write`] renames it;
    /// landmarks in the front view).
    pub side: SideFile,
    /// World z, mm, of the surface seen at each pixel centre before encoding (NaN = no sample),
    /// image order.
    pub depth_mm: Vec<f64>,
    /// [`super::Part::index`] of the triangle seen at each pixel, [`NO_PART`] where
    /// none; image order.
    pub part: Vec<u8>,
}

impl RangeView {
    /// Samples with a value.
    pub fn valid_samples(&self) -> usize {
        self.image.data.iter().filter(|&&v| v > 0).count()
    }

    /// World `(x, y)`, mm, of the centre of pixel `(c, r)` of this view.
    pub fn world(&self, c: f64, r: f64) -> [f64; 2] {
        let px = self.side.pixel_size;
        let sx = if self.view == View::Front { 1.0 } else { -1.0 };
        [
            self.side.origin.0 + sx * c * px,
            self.side.origin.1 - r * px,
        ]
    }

    /// The world z (mm) the grey value at `(c, r)` encodes, if any.
    pub fn decoded(&self, c: usize, r: usize) -> Option<f64> {
        let v = self.image.get(c, r);
        (v > 0).then(|| {
            let d = self.side.depth_offset + self.side.depth_scale * f64::from(v);
            match self.view {
                View::Front => self.side.camera_z - d,
                View::Back => self.side.camera_z + d,
            }
        })
    }
}

/// The front and back views of one body, registered as `docs/grid-range.md` requires, with the
/// landmarks in the front view.
#[derive(Clone, Debug, PartialEq)]
pub struct Views {
    /// Front view (camera in front, looking along −z).
    pub front: RangeView,
    /// Back view (camera behind, looking along +z; mirrored).
    pub back: RangeView,
    /// Rendering wall time, s (both views, without landmarks).
    pub render_seconds: f64,
}

impl Views {
    /// The landmarks, front pixels `(column, row)`.
    pub fn landmarks(&self) -> &BTreeMap<String, (f64, f64)> {
        &self.front.side.landmarks
    }

    /// The two views as a [`RangeBody`] (in memory, as [`RangeBody::load`] would read the
    /// files). Fails when the landmarks are missing (made by [`render_images`] alone).
    pub fn body(&self) -> Result<RangeBody, RangeError> {
        Ok(RangeBody::from_views(
            (&self.front.side, &self.front.image, Path::new("front.ron")),
            (&self.back.side, &self.back.image, Path::new("back.ron")),
        )?)
    }

    /// Write `front.ron`, `back.ron` and their images (`front.EXT`, `back.EXT`, `ext` `"pgm"`
    /// or `"png"`, 16-bit) into `dir` (which must exist), each atomically; returns the paths of
    /// the front and back side files.
    pub fn write(&self, dir: &Path, ext: &str) -> Result<(PathBuf, PathBuf), RangeError> {
        let ext = ext.to_ascii_lowercase();
        if ext != "pgm" && ext != "png" {
            return Err(RangeError::BadExtension(ext));
        }
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| RangeError::Io { path, source }
        };
        let mut out = Vec::new();
        for (v, name) in [(&self.front, "front"), (&self.back, "back")] {
            let image = format!("{name}.{ext}");
            let ip = dir.join(&image);
            write_image(&ip, &v.image).map_err(io(&ip))?;
            let side = SideFile {
                image,
                ..v.side.clone()
            };
            let sp = dir.join(format!("{name}.ron"));
            side.write(&sp).map_err(io(&sp))?;
            out.push(sp);
        }
        let back = out.pop().unwrap_or_default();
        let front = out.pop().unwrap_or_default();
        Ok((front, back))
    }
}

/// Check the mesh; returns its bounds `([xmin, ymin, zmin], [xmax, ymax, zmax])` in mm over the
/// vertices used by triangles.
fn check_mesh(mesh: &LabelledMesh) -> Result<([f64; 3], [f64; 3]), RangeError> {
    if mesh.vertices.is_empty() || mesh.triangles.is_empty() {
        return Err(RangeError::EmptyMesh {
            vertices: mesh.vertices.len(),
            triangles: mesh.triangles.len(),
        });
    }
    if mesh.triangle_part.len() != mesh.triangles.len() {
        return Err(RangeError::BadMesh(format!(
            "{} triangle labels for {} triangles",
            mesh.triangle_part.len(),
            mesh.triangles.len()
        )));
    }
    let n = mesh.vertices.len();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &i in tri {
            let Some(v) = mesh.vertices.get(i as usize) else {
                return Err(RangeError::BadMesh(format!(
                    "triangle {t} uses vertex {i}, the mesh has {n}"
                )));
            };
            if !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite()) {
                return Err(RangeError::BadMesh(format!(
                    "vertex {i} is not finite: ({}, {}, {})",
                    v.x, v.y, v.z
                )));
            }
            for k in 0..3 {
                lo[k] = lo[k].min(v[k] * 1e3);
                hi[k] = hi[k].max(v[k] * 1e3);
            }
        }
    }
    Ok((lo, hi))
}

/// Rasterise the triangles facing `view` at the front-order pixel grid: world z (mm) and the
/// part index per pixel, front column order.
fn rasterise(
    mesh: &LabelledMesh,
    frame: &Frame,
    px: f64,
    view: View,
) -> Result<(Vec<f64>, Vec<u8>), RangeError> {
    let (w, h) = (frame.width, frame.height);
    let mut z = vec![f64::NAN; w * h];
    let mut part = vec![NO_PART; w * h];
    let front = view == View::Front;
    let mut facing = 0usize;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        // Pixel coordinates (column, row) and depth (mm).
        let p = tri.map(|i| {
            let v = mesh.vertices[i as usize];
            [
                (v.x * 1e3 - frame.origin_mm[0]) / px,
                (frame.origin_mm[1] - v.y * 1e3) / px,
                v.z * 1e3,
            ]
        });
        // Signed area in pixel coordinates; rows run down, so a triangle counter-clockwise seen
        // from +z (facing the front camera) has a negative `det` here.
        let det =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        let faces = if front { det < 0.0 } else { det > 0.0 };
        if !faces {
            continue;
        }
        facing += 1;
        let label = mesh.triangle_part[t].index() as u8;
        super::measure::rasterize_triangle(p, label, front, w, h, &mut z, &mut part);
    }
    if facing == 0 {
        return Err(RangeError::NoFacingTriangles(view));
    }
    if z.iter().all(|v| v.is_nan()) {
        return Err(RangeError::EmptyView(view));
    }
    Ok((z, part))
}

/// The frame fitted to the body: whole pixels, at least `margin` mm and two pixels around it.
fn fit_frame(lo: [f64; 3], hi: [f64; 3], px: f64, margin: f64) -> Result<Frame, RangeError> {
    let m = margin.max(2.0 * px);
    let c0 = ((lo[0] - m) / px).floor();
    let c1 = ((hi[0] + m) / px).ceil();
    let r0 = ((lo[1] - m) / px).floor();
    let r1 = ((hi[1] + m) / px).ceil();
    let (wf, hf) = (c1 - c0 + 1.0, r1 - r0 + 1.0);
    if wf * hf > MAX_PIXELS as f64 || wf.is_nan() || hf.is_nan() {
        return Err(RangeError::TooLarge {
            width: wf.min(usize::MAX as f64) as usize,
            height: hf.min(usize::MAX as f64) as usize,
        });
    }
    Ok(Frame {
        origin_mm: [c0 * px, r1 * px],
        width: wf as usize,
        height: hf as usize,
    })
}

/// Render the front and back range images of `mesh` (metres, x to the body's left, y up,
/// z forward) at `pixel_size_mm`, **without** landmarks (see [`render_views`]).
///
/// Each view samples the surface at the pixel centres: the front view the largest z of the
/// triangles facing +z (counter-clockwise seen from the front), the back view the smallest z of
/// those facing −z, by barycentric interpolation of the vertex depths (exact for a flat face).
/// Depths are encoded as `z = camera_z ∓ (depth_offset + depth_scale·v)`, the front camera plane
/// `standoff_mm` in front of the body's nearest point (rounded up to a whole mm), the back one as
/// far behind, `depth_offset = standoff_mm − 10` (so the nearest surface has grey ≈ 10 mm /
/// depth_scale); grey 0 = no sample.
pub fn render_images(
    mesh: &LabelledMesh,
    pixel_size_mm: f64,
    params: &RenderParams,
) -> Result<Views, RangeError> {
    let start = Instant::now();
    let px = pixel_size_mm;
    if !(px > 0.0 && px.is_finite()) {
        return Err(RangeError::BadPixelSize(px));
    }
    let bad = |field, message: String| RangeError::BadParameter { field, message };
    if !(params.depth_scale_mm > 0.0 && params.depth_scale_mm.is_finite()) {
        return Err(bad(
            "depth_scale_mm",
            format!("{} is not a positive number", params.depth_scale_mm),
        ));
    }
    if !(params.margin_mm >= 0.0 && params.margin_mm.is_finite()) {
        return Err(bad(
            "margin_mm",
            format!("{} is not a non-negative number", params.margin_mm),
        ));
    }
    if !(params.standoff_mm >= 10.0 && params.standoff_mm.is_finite()) {
        return Err(bad(
            "standoff_mm",
            format!("{} is not a number ≥ 10", params.standoff_mm),
        ));
    }
    let (lo, hi) = check_mesh(mesh)?;
    let frame = match params.frame {
        Some(f) => {
            if !(f.origin_mm[0].is_finite() && f.origin_mm[1].is_finite()) {
                return Err(bad("frame", "the origin is not finite".into()));
            }
            if f.width < 2 || f.height < 2 || f.width.saturating_mul(f.height) > MAX_PIXELS {
                return Err(RangeError::TooLarge {
                    width: f.width,
                    height: f.height,
                });
            }
            f
        }
        None => fit_frame(lo, hi, px, params.margin_mm)?,
    };
    let (w, h) = (frame.width, frame.height);
    // Depth encoding.
    let scale = params.depth_scale_mm;
    let offset = params.standoff_mm - 10.0;
    let cam_front = (hi[2] + params.standoff_mm).ceil();
    let cam_back = (lo[2] - params.standoff_mm).floor();
    let span = (cam_front - lo[2] - offset).max(hi[2] - cam_back - offset);
    if span / scale > 65535.0 {
        return Err(RangeError::DepthRange {
            span_mm: span,
            scale_mm: scale,
        });
    }
    let mut views = Vec::new();
    for view in [View::Front, View::Back] {
        let (z, part) = rasterise(mesh, &frame, px, view)?;
        let mut data = vec![0u16; w * h];
        let mut depth = vec![f64::NAN; w * h];
        let mut labels = vec![NO_PART; w * h];
        for r in 0..h {
            for c in 0..w {
                let k = r * w + c;
                let col = if view == View::Front { c } else { w - 1 - c };
                let j = r * w + col;
                depth[j] = z[k];
                labels[j] = part[k];
                if z[k].is_nan() {
                    continue;
                }
                let d = if view == View::Front {
                    cam_front - z[k]
                } else {
                    z[k] - cam_back
                };
                data[j] = ((d - offset) / scale).round().clamp(1.0, 65535.0) as u16;
            }
        }
        let (name, camera_z, origin) = match view {
            View::Front => ("front.pgm", cam_front, frame.origin_mm),
            View::Back => (
                "back.pgm",
                cam_back,
                [frame.origin_mm[0] + (w - 1) as f64 * px, frame.origin_mm[1]],
            ),
        };
        views.push(RangeView {
            view,
            image: GrayImage {
                width: w,
                height: h,
                maxval: 65535,
                data,
            },
            side: SideFile {
                view,
                image: name.into(),
                pixel_size: px,
                depth_scale: scale,
                depth_offset: offset,
                camera_z,
                origin: (origin[0], origin[1]),
                landmarks: BTreeMap::new(),
            },
            depth_mm: depth,
            part: labels,
        });
    }
    let back = views.pop().ok_or(RangeError::EmptyView(View::Back))?;
    let front = views.pop().ok_or(RangeError::EmptyView(View::Front))?;
    Ok(Views {
        front,
        back,
        render_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Render the front and back range images of a posed body ([`render_images`]) and find the 31
/// landmarks of [`super::LANDMARKS`] on the front silhouette ([`find_landmarks`]),
/// stored in the front side file (pixels, rounded to 0.01).
pub fn render_views(
    mesh: &LabelledMesh,
    pixel_size_mm: f64,
    params: &RenderParams,
) -> Result<Views, RangeError> {
    let mut views = render_images(mesh, pixel_size_mm, params)?;
    let lm = find_landmarks(mesh, &views)?;
    views.front.side.landmarks = lm
        .into_iter()
        .map(|(k, (c, r))| (k, (round2(c), round2(r))))
        .collect();
    Ok(views)
}

fn round2(v: f64) -> f64 {
    (v * 100.0).round() / 100.0
}

/// The round trip mannequin → range images → gridded body → error.
#[derive(Clone, Debug)]
pub struct RoundTrip {
    /// The rendered views (with landmarks).
    pub views: Views,
    /// The body gridded from them.
    pub mesh: BodyMesh,
    /// Its error against the rendered range images (thesis Table 2).
    pub error: ErrorReport,
    /// Wall time of rendering and landmarks, s.
    pub render_seconds: f64,
    /// Wall time of the gridding, s.
    pub grid_seconds: f64,
}

/// Render `mesh` at `pixel_size_mm`, grid the rendered body with `grid` and measure the gridded
/// mesh against the rendered images.
pub fn round_trip_mesh(
    mesh: &LabelledMesh,
    pixel_size_mm: f64,
    grid: &BodyGridParams,
) -> Result<RoundTrip, RangeError> {
    let t0 = Instant::now();
    let views = render_views(mesh, pixel_size_mm, &RenderParams::default())?;
    let render_seconds = t0.elapsed().as_secs_f64();
    let body = views.body()?;
    let t1 = Instant::now();
    let (gridded, _) = grid_body(&body, grid)?;
    let grid_seconds = t1.elapsed().as_secs_f64();
    let error = measure_error(&gridded, &body);
    Ok(RoundTrip {
        views,
        mesh: gridded,
        error,
        render_seconds,
        grid_seconds,
    })
}

/// [`round_trip_mesh`] of a mannequin in its rest pose.
pub fn round_trip(
    mannequin: &Mannequin,
    pixel_size_mm: f64,
    grid: &BodyGridParams,
) -> Result<RoundTrip, RangeError> {
    round_trip_mesh(&mannequin.labelled_mesh(), pixel_size_mm, grid)
}
