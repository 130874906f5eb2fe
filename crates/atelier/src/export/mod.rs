//! Exports of a run for other tools: the final meshes as Wavefront OBJ ([`write_obj`]) or
//! binary PLY with vertex colours ([`write_ply`]), and the whole run as a glTF 2.0 binary
//! ([`write_glb`]) whose motion is stored as morph targets, one per kept frame, driven by a
//! `weights` animation — the portable way to animate arbitrary vertex motion in glTF.
//!
//! A scene is a list of parts (the cloth, the body), each a [`MeshPart`] (name, fixed triangles,
//! colour, sidedness) with its positions: one frame for OBJ and PLY, an [`Animation`] (times and
//! frames; a static body has one frame) for glTF. Coordinates are metres in the body frame
//! (x = the body's left, y up, z forward), which is glTF's frame too, so nothing is converted.
//!
//! Every writer checks its whole input before it creates a file (a non-finite coordinate is
//! reported with its part, frame and vertex and never written), writes to a temporary file beside
//! the target and renames it into place, so a reader never sees a half-written export. The glTF
//! writer streams its binary chunk: besides the caller's frames it holds one frame's worth of
//! data and the animation's key weights (kept frames², see [`FrameSelection`] to subsample).
//! The formats are described for users in `docs/exports.md`.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

pub use gltf::write_glb;
pub use mesh::{write_obj, write_ply};

mod gltf;
mod mesh;

/// One mesh of a scene: a name, fixed triangles (indices into the part's own positions) and
/// how it is drawn.
#[derive(Clone, Copy, Debug)]
pub struct MeshPart<'a> {
    /// Name of the part (OBJ `o` group, PLY comment, glTF node, mesh and material name).
    pub name: &'a str,
    /// Triangles, counter-clockwise seen from the outside (this orients the normals).
    pub triangles: &'a [[u32; 3]],
    /// Display (sRGB) colour, components in [0, 1]; glTF receives its linear equivalent.
    pub colour: [f32; 3],
    /// Whether both faces are drawn (glTF `doubleSided`): true for cloth, whose inside shows.
    pub double_sided: bool,
    /// Per-vertex display (sRGB) colours marking named groups (glTF `COLOR_0`, linear, and
    /// `extras.panels` and `extras.panel_colours`, linear too; the viewer's colouring by panel).
    /// glTF only.
    pub vertex_colours: Option<VertexColours<'a>>,
    /// A value per vertex per animation frame (glTF: one `SCALAR` accessor per kept frame,
    /// listed with the largest value in the mesh's `extras` under the given name; the viewer's
    /// colouring by strain error). glTF only; one list per frame of the animation, one value
    /// per vertex, finite (else the export is refused).
    pub frame_values: Option<FrameValues<'a>>,
}

/// Per-vertex colours marking named groups of vertices (a garment's panels).
#[derive(Clone, Copy, Debug)]
pub struct VertexColours<'a> {
    /// Display (sRGB) colour of each vertex.
    pub colours: &'a [[f32; 3]],
    /// The groups' names.
    pub names: &'a [String],
    /// The display (sRGB) colour of each group, as its vertices have it.
    pub name_colours: &'a [[f32; 3]],
}

/// A value per vertex for every frame of a part's [`Animation`].
#[derive(Clone, Copy, Debug)]
pub struct FrameValues<'a> {
    /// The key in the mesh's `extras` (`strain_error`).
    pub name: &'a str,
    /// One list per frame, one value per vertex.
    pub values: &'a [Vec<f32>],
}

impl<'a> MeshPart<'a> {
    /// A cloth part: drawn double-sided.
    pub fn cloth(name: &'a str, triangles: &'a [[u32; 3]], colour: [f32; 3]) -> Self {
        Self {
            name,
            triangles,
            colour,
            double_sided: true,
            vertex_colours: None,
            frame_values: None,
        }
    }

    /// A body part (a closed surface): drawn single-sided.
    pub fn body(name: &'a str, triangles: &'a [[u32; 3]], colour: [f32; 3]) -> Self {
        Self {
            name,
            triangles,
            colour,
            double_sided: false,
            vertex_colours: None,
            frame_values: None,
        }
    }
}

/// The motion of one part over a run: `frames[k]` holds every vertex position (m) at
/// `times[k]` (s). Times increase strictly; every frame has the same number of vertices. A
/// static part has one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Animation {
    /// Time of each frame (s), strictly increasing.
    pub times: Vec<f64>,
    /// Vertex positions (m) of each frame.
    pub frames: Vec<Vec<[f64; 3]>>,
}

impl Animation {
    /// A part that does not move: one frame at t = 0.
    pub fn still(positions: Vec<[f64; 3]>) -> Self {
        Self {
            times: vec![0.0],
            frames: vec![positions],
        }
    }

    /// Record one more frame (checked only when written).
    pub fn push(&mut self, time: f64, positions: Vec<[f64; 3]>) {
        self.times.push(time);
        self.frames.push(positions);
    }

    /// The last frame, if any (what [`write_obj`] and [`write_ply`] usually receive).
    pub fn last(&self) -> Option<&[[f64; 3]]> {
        self.frames.last().map(Vec::as_slice)
    }
}

/// Which frames of an [`Animation`] go into a glTF file. The first and the last frame are
/// always kept. The file holds 12 bytes per vertex per kept frame (24 with morph normals) plus
/// 4 × kept² bytes of key weights, so a long run should be subsampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameSelection {
    /// Every frame.
    All,
    /// Every n-th frame (n ≥ 1), starting with the first, plus the last.
    Stride(usize),
    /// At most n frames (n ≥ 2), evenly spaced in frame index.
    AtMost(usize),
}

impl FrameSelection {
    /// The indices kept out of `frames` frames, increasing, or `None` for an invalid selection
    /// (`Stride(0)`, `AtMost(0)` or `AtMost(1)`).
    pub fn indices(self, frames: usize) -> Option<Vec<usize>> {
        if frames == 0 {
            return Some(Vec::new());
        }
        let last = frames - 1;
        match self {
            FrameSelection::All => Some((0..frames).collect()),
            FrameSelection::Stride(0) | FrameSelection::AtMost(0 | 1) => None,
            FrameSelection::Stride(s) => {
                let mut v: Vec<usize> = (0..frames).step_by(s).collect();
                if v.last() != Some(&last) {
                    v.push(last);
                }
                Some(v)
            }
            FrameSelection::AtMost(m) if frames <= m => Some((0..frames).collect()),
            FrameSelection::AtMost(m) => {
                let mut v: Vec<usize> = (0..m)
                    .map(|i| ((i * last) as f64 / (m - 1) as f64).round() as usize)
                    .collect();
                v.dedup();
                Some(v)
            }
        }
    }
}

/// How a glTF viewer moves between kept frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// Hold each frame until the next one.
    Step,
    /// Blend positions linearly between frames (each frame exact at its own time).
    Linear,
}

/// Options of [`write_glb`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GlbOptions {
    /// Frames kept (default: all).
    pub frames: FrameSelection,
    /// Interpolation between kept frames (default: linear).
    pub interpolation: Interpolation,
    /// Store each frame's normals as well as its positions (default: true). Without them a
    /// viewer shades every frame with the first frame's normals; with them the file is twice as
    /// large.
    pub morph_normals: bool,
}

impl Default for GlbOptions {
    fn default() -> Self {
        Self {
            frames: FrameSelection::All,
            interpolation: Interpolation::Linear,
            morph_normals: true,
        }
    }
}

/// Why an export failed. Nothing is left at the target path or beside it when it does.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The file could not be created, written or moved into place.
    #[error("cannot write {}", path.display())]
    Io {
        /// The export's target path.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// A coordinate is NaN or infinite (or beyond single precision, which the binary formats
    /// store): the run diverged or the positions were not filled in.
    #[error(
        "{}: part `{part}`, frame {frame}, vertex {vertex} is not finite ({position:?}); nothing was written",
        path.display()
    )]
    NonFinite {
        /// The export's target path.
        path: PathBuf,
        /// Name of the part.
        part: String,
        /// Frame index (0 for OBJ and PLY).
        frame: usize,
        /// Vertex index within the part.
        vertex: usize,
        /// The offending position.
        position: [f64; 3],
    },
    /// A part is malformed: no vertices or triangles, a triangle naming a missing vertex,
    /// frames of different sizes, times not increasing, a non-finite colour.
    #[error("{}: part `{part}`: {problem}; nothing was written", path.display())]
    InvalidPart {
        /// The export's target path.
        path: PathBuf,
        /// Name of the part.
        part: String,
        /// What is wrong.
        problem: String,
    },
    /// The scene itself cannot be exported: no parts, an invalid frame selection, or a size the
    /// format cannot hold.
    #[error("{}: {problem}; nothing was written", path.display())]
    InvalidScene {
        /// The export's target path.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
}

// ---------------------------------------------------------------------------------------------
// Checks shared by the writers.

fn invalid_part(path: &Path, part: &MeshPart<'_>, problem: String) -> ExportError {
    ExportError::InvalidPart {
        path: path.to_owned(),
        part: part.name.to_owned(),
        problem,
    }
}

fn invalid_scene(path: &Path, problem: String) -> ExportError {
    ExportError::InvalidScene {
        path: path.to_owned(),
        problem,
    }
}

/// Finite and representable in single precision (what PLY and glTF store).
fn representable(x: f64) -> bool {
    x.is_finite() && x.abs() <= f64::from(f32::MAX)
}

/// Check one part's fixed data (non-empty, colour) and one frame of its positions.
fn check_frame(
    path: &Path,
    part: &MeshPart<'_>,
    frame: usize,
    positions: &[[f64; 3]],
    expected_len: usize,
) -> Result<(), ExportError> {
    if positions.len() != expected_len {
        return Err(invalid_part(
            path,
            part,
            format!(
                "frame {frame} has {} vertices, frame 0 has {expected_len}",
                positions.len()
            ),
        ));
    }
    if let Some((vertex, p)) = positions
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|&x| representable(x)))
    {
        return Err(ExportError::NonFinite {
            path: path.to_owned(),
            part: part.name.to_owned(),
            frame,
            vertex,
            position: *p,
        });
    }
    Ok(())
}

/// Check a part's triangles and colour against its vertex count.
fn check_part(path: &Path, part: &MeshPart<'_>, vertices: usize) -> Result<(), ExportError> {
    if vertices == 0 || part.triangles.is_empty() {
        return Err(invalid_part(
            path,
            part,
            format!(
                "{vertices} vertices and {} triangles (a part needs both)",
                part.triangles.len()
            ),
        ));
    }
    if vertices > u32::MAX as usize {
        return Err(invalid_part(
            path,
            part,
            format!("{vertices} vertices exceed 32-bit indices"),
        ));
    }
    if let Some((t, tri)) = part
        .triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= vertices))
    {
        return Err(invalid_part(
            path,
            part,
            format!("triangle {t} {tri:?} names a vertex beyond its {vertices} vertices"),
        ));
    }
    if !part.colour.iter().all(|c| c.is_finite()) {
        return Err(invalid_part(
            path,
            part,
            format!("colour {:?} is not finite", part.colour),
        ));
    }
    Ok(())
}

/// Check a single-frame scene (OBJ, PLY).
fn check_static(path: &Path, parts: &[(MeshPart<'_>, &[[f64; 3]])]) -> Result<(), ExportError> {
    if parts.is_empty() {
        return Err(invalid_scene(path, "no parts to export".into()));
    }
    for (part, positions) in parts {
        check_part(path, part, positions.len())?;
        check_frame(path, part, 0, positions, positions.len())?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Geometry.

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Area-weighted vertex normals (each triangle adds its unnormalised normal, twice its area, to
/// its three vertices), unit length; a vertex on no triangle of positive area gets +y.
fn vertex_normals(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut n = vec![[0.0; 3]; positions.len()];
    for tri in triangles {
        let [a, b, c] = tri.map(|i| positions[i as usize]);
        let f = cross(sub(b, a), sub(c, a));
        for &i in tri {
            for k in 0..3 {
                n[i as usize][k] += f[k];
            }
        }
    }
    for v in &mut n {
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        *v = if len > 0.0 && len.is_finite() {
            v.map(|x| x / len)
        } else {
            [0.0, 1.0, 0.0]
        };
    }
    n
}

/// Bytes of a display colour.
fn colour_bytes(c: [f32; 3]) -> [u8; 3] {
    c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// Linear-light equivalent of an sRGB display component (glTF `baseColorFactor` is linear).
fn srgb_to_linear(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A part name fit for a one-line text field (OBJ `o`, PLY comment): whitespace and control
/// characters become `_`.
fn one_line_name(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_whitespace() || c.is_control() {
                '_'
            } else {
                c
            }
        })
        .collect();
    if s.is_empty() { "part".into() } else { s }
}

// ---------------------------------------------------------------------------------------------
// Atomic streaming output.

/// Write through `body` into a temporary file beside `path`, then rename it into place; on any
/// failure the temporary file is removed.
fn write_atomically(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), ExportError> {
    let tmp = atelier_files::files::temporary_sibling(path);
    let result = (|| {
        let mut w = BufWriter::new(File::create(&tmp)?);
        body(&mut w)?;
        let f = w.into_inner().map_err(io::IntoInnerError::into_error)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|source| ExportError::Io {
        path: path.to_owned(),
        source,
    })
}

fn put_f32s(w: &mut impl Write, v: [f32; 3]) -> io::Result<()> {
    for x in v {
        w.write_all(&x.to_le_bytes())?;
    }
    Ok(())
}

fn to_f32(p: [f64; 3]) -> [f32; 3] {
    p.map(|x| x as f32)
}

// ---------------------------------------------------------------------------------------------
// OBJ and PLY.
