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

use serde_json::{Value, json};

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
}

impl<'a> MeshPart<'a> {
    /// A cloth part: drawn double-sided.
    pub fn cloth(name: &'a str, triangles: &'a [[u32; 3]], colour: [f32; 3]) -> Self {
        Self {
            name,
            triangles,
            colour,
            double_sided: true,
        }
    }

    /// A body part (a closed surface): drawn single-sided.
    pub fn body(name: &'a str, triangles: &'a [[u32; 3]], colour: [f32; 3]) -> Self {
        Self {
            name,
            triangles,
            colour,
            double_sided: false,
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
    let tmp = atelier_fabric::files::temporary_sibling(path);
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

/// Write the parts' meshes (each with its own positions, m) as a Wavefront OBJ file: a comment
/// header, then per part an `o` group with its vertices (`v`, full double precision),
/// area-weighted unit vertex normals (`vn`) and triangles (`f v//vn`, 1-based, numbered across
/// the whole file). Colours and sidedness are not stored (OBJ has no standard for them).
pub fn write_obj(path: &Path, parts: &[(MeshPart<'_>, &[[f64; 3]])]) -> Result<(), ExportError> {
    check_static(path, parts)?;
    let vertices: usize = parts.iter().map(|(_, p)| p.len()).sum();
    let triangles: usize = parts.iter().map(|(m, _)| m.triangles.len()).sum();
    write_atomically(path, |w| {
        writeln!(
            w,
            "# atelier export: {} parts, {vertices} vertices, {triangles} triangles",
            parts.len()
        )?;
        writeln!(w, "# metres; x = the body's left, y up, z forward")?;
        let mut offset = 1usize;
        for (part, positions) in parts {
            writeln!(w, "o {}", one_line_name(part.name))?;
            for p in *positions {
                writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
            }
            for n in vertex_normals(positions, part.triangles) {
                let n = to_f32(n);
                writeln!(w, "vn {} {} {}", n[0], n[1], n[2])?;
            }
            for tri in part.triangles {
                let [a, b, c] = tri.map(|i| i as usize + offset);
                writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
            }
            offset += positions.len();
        }
        Ok(())
    })
}

/// Write the parts' meshes as a binary little-endian PLY file: one vertex element (`x y z` and
/// `nx ny nz` as `float`, area-weighted unit normals; `red green blue` as `uchar`, the part's
/// colour) and one face element (`list uchar int vertex_indices`), parts one after the other;
/// a header comment per part gives its name and its vertex and face ranges.
pub fn write_ply(path: &Path, parts: &[(MeshPart<'_>, &[[f64; 3]])]) -> Result<(), ExportError> {
    check_static(path, parts)?;
    let vertices: usize = parts.iter().map(|(_, p)| p.len()).sum();
    let faces: usize = parts.iter().map(|(m, _)| m.triangles.len()).sum();
    if vertices > i32::MAX as usize {
        return Err(invalid_scene(
            path,
            format!("{vertices} vertices exceed PLY's int indices"),
        ));
    }
    let mut header = String::from("ply\nformat binary_little_endian 1.0\n");
    header.push_str("comment atelier export: metres; x = the body's left, y up, z forward\n");
    let (mut v0, mut f0) = (0usize, 0usize);
    for (part, positions) in parts {
        let (v1, f1) = (v0 + positions.len(), f0 + part.triangles.len());
        header.push_str(&format!(
            "comment part {}: vertices {v0}..{v1}, faces {f0}..{f1}\n",
            one_line_name(part.name)
        ));
        (v0, f0) = (v1, f1);
    }
    header.push_str(&format!("element vertex {vertices}\n"));
    for p in ["x", "y", "z", "nx", "ny", "nz"] {
        header.push_str(&format!("property float {p}\n"));
    }
    for p in ["red", "green", "blue"] {
        header.push_str(&format!("property uchar {p}\n"));
    }
    header.push_str(&format!(
        "element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    ));
    write_atomically(path, |w| {
        w.write_all(header.as_bytes())?;
        for (part, positions) in parts {
            let rgb = colour_bytes(part.colour);
            for (p, n) in positions
                .iter()
                .zip(vertex_normals(positions, part.triangles))
            {
                put_f32s(w, to_f32(*p))?;
                put_f32s(w, to_f32(n))?;
                w.write_all(&rgb)?;
            }
        }
        let mut offset = 0i32;
        for (part, positions) in parts {
            for tri in part.triangles {
                w.write_all(&[3])?;
                for &i in tri {
                    w.write_all(&(i as i32 + offset).to_le_bytes())?;
                }
            }
            offset += positions.len() as i32;
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// glTF binary.

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const TRIANGLES: u32 = 4;

/// One part as laid out in the glTF file.
struct GlbPart<'p> {
    part: &'p MeshPart<'p>,
    anim: &'p Animation,
    /// Frames kept (indices into `anim.frames`); the first is the base mesh, each further one a
    /// morph target.
    keep: Vec<usize>,
    /// Base positions and normals as stored.
    base: Vec<[f32; 3]>,
    base_normals: Vec<[f32; 3]>,
    /// Which distinct time list (animation input) this part's keys use.
    times: usize,
}

/// A block of the binary chunk, written in layout order.
#[derive(Clone, Copy)]
enum Blob {
    Indices(usize),
    BasePositions(usize),
    BaseNormals(usize),
    /// Part, target (kept frame `target + 1`).
    TargetPositions(usize, usize),
    TargetNormals(usize, usize),
    Times(usize),
    Weights(usize),
}

/// Buffer views and accessors (one view per accessor) as the binary chunk is laid out.
#[derive(Default)]
struct Layout {
    blobs: Vec<Blob>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    bytes: u64,
}

impl Layout {
    /// Add a block of `count` elements of `kind` (`SCALAR`/`VEC3`) of 4-byte components;
    /// returns the accessor index.
    fn add(
        &mut self,
        blob: Blob,
        component: u32,
        kind: &str,
        count: usize,
        target: Option<u32>,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> usize {
        let width = if kind == "VEC3" { 3 } else { 1 };
        let len = 4 * width * count as u64;
        let mut view = json!({ "buffer": 0, "byteOffset": self.bytes, "byteLength": len });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        let mut accessor = json!({
            "bufferView": self.views.len(),
            "componentType": component,
            "count": count,
            "type": kind,
        });
        if let Some((min, max)) = bounds {
            accessor["min"] = json!(min);
            accessor["max"] = json!(max);
        }
        self.blobs.push(blob);
        self.views.push(view);
        self.accessors.push(accessor);
        self.bytes += len; // every block is a multiple of 4 bytes: views stay 4-aligned
        self.accessors.len() - 1
    }
}

/// Stored morph delta: what a viewer adds (in single precision) to the stored base to get as
/// close as it can to `p`.
fn delta(base: [f32; 3], p: [f64; 3]) -> [f32; 3] {
    [0, 1, 2].map(|k| (p[k] - f64::from(base[k])) as f32)
}

/// Componentwise bounds of stored vectors.
fn bounds(values: impl Iterator<Item = [f32; 3]>) -> (Vec<f32>, Vec<f32>) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for v in values {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo.to_vec(), hi.to_vec())
}

/// Check an animated part and choose its frames.
fn check_animated<'p>(
    path: &Path,
    part: &'p MeshPart<'p>,
    anim: &'p Animation,
    selection: FrameSelection,
) -> Result<GlbPart<'p>, ExportError> {
    if anim.frames.is_empty() || anim.times.len() != anim.frames.len() {
        return Err(invalid_part(
            path,
            part,
            format!(
                "{} times for {} frames (a part needs at least one frame and one time per frame)",
                anim.times.len(),
                anim.frames.len()
            ),
        ));
    }
    let n = anim.frames[0].len();
    check_part(path, part, n)?;
    for (k, frame) in anim.frames.iter().enumerate() {
        check_frame(path, part, k, frame, n)?;
    }
    if let Some(k) = anim.times.iter().position(|t| !t.is_finite()) {
        return Err(invalid_part(
            path,
            part,
            format!("time of frame {k} is {}", anim.times[k]),
        ));
    }
    let keep = selection.indices(anim.frames.len()).ok_or_else(|| {
        invalid_scene(
            path,
            format!(
                "frame selection {selection:?} keeps no frames (Stride needs n ≥ 1, AtMost n ≥ 2)"
            ),
        )
    })?;
    for pair in keep.windows(2) {
        let (a, b) = (anim.times[pair[0]], anim.times[pair[1]]);
        if (b as f32) <= (a as f32) {
            return Err(invalid_part(
                path,
                part,
                format!(
                    "times of frames {} and {} ({a} s, {b} s) do not increase in single precision",
                    pair[0], pair[1]
                ),
            ));
        }
    }
    let base: Vec<[f32; 3]> = anim.frames[keep[0]].iter().map(|p| to_f32(*p)).collect();
    // Deltas of representable positions can still overflow single precision.
    for &k in &keep[1..] {
        for (vertex, (b, p)) in base.iter().zip(&anim.frames[k]).enumerate() {
            if !delta(*b, *p).iter().all(|d| d.is_finite()) {
                return Err(ExportError::NonFinite {
                    path: path.to_owned(),
                    part: part.name.to_owned(),
                    frame: k,
                    vertex,
                    position: *p,
                });
            }
        }
    }
    let base_normals = vertex_normals(&anim.frames[keep[0]], part.triangles)
        .into_iter()
        .map(to_f32)
        .collect();
    Ok(GlbPart {
        part,
        anim,
        keep,
        base,
        base_normals,
        times: 0,
    })
}

/// Write a run as a glTF 2.0 binary (`.glb`): per part a node, a mesh (triangles as
/// `UNSIGNED_INT` indices, `POSITION` with its bounds and area-weighted `NORMAL` as `FLOAT`
/// `VEC3`) and a PBR material of the part's colour (metallic 0, roughness 0.9, `doubleSided`
/// as the part says). A part with more than one kept frame has one morph target per kept frame
/// after the first (position deltas from the first, and normal deltas unless
/// `options.morph_normals` is false) and an animation channel on the node's `weights`: at the
/// time of kept frame k exactly target k has weight 1 (at the first frame, none), so the file
/// reproduces every kept frame exactly up to single precision. Parts may have different times;
/// a static part (one frame) is not animated. All channels form one animation, `run`.
pub fn write_glb(
    path: &Path,
    parts: &[(MeshPart<'_>, &Animation)],
    options: &GlbOptions,
) -> Result<(), ExportError> {
    if parts.is_empty() {
        return Err(invalid_scene(path, "no parts to export".into()));
    }
    let mut glb = Vec::with_capacity(parts.len());
    let mut time_lists: Vec<Vec<f32>> = Vec::new();
    for (part, anim) in parts {
        let mut p = check_animated(path, part, anim, options.frames)?;
        let times: Vec<f32> = p.keep.iter().map(|&k| anim.times[k] as f32).collect();
        p.times = match time_lists.iter().position(|t| *t == times) {
            Some(i) => i,
            None => {
                time_lists.push(times);
                time_lists.len() - 1
            }
        };
        glb.push(p);
    }

    // Layout: per part its mesh data, then the animation's inputs and outputs.
    let mut layout = Layout::default();
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    let mut nodes = Vec::new();
    for (i, p) in glb.iter().enumerate() {
        let n = p.base.len();
        let indices = layout.add(
            Blob::Indices(i),
            UNSIGNED_INT,
            "SCALAR",
            3 * p.part.triangles.len(),
            Some(ELEMENT_ARRAY_BUFFER),
            None,
        );
        let position = layout.add(
            Blob::BasePositions(i),
            FLOAT,
            "VEC3",
            n,
            Some(ARRAY_BUFFER),
            Some(bounds(p.base.iter().copied())),
        );
        let normal = layout.add(
            Blob::BaseNormals(i),
            FLOAT,
            "VEC3",
            n,
            Some(ARRAY_BUFFER),
            None,
        );
        let mut targets = Vec::new();
        let mut target_names = Vec::new();
        for (t, &k) in p.keep.iter().enumerate().skip(1) {
            let frame = &p.anim.frames[k];
            let b = bounds(p.base.iter().zip(frame).map(|(b, q)| delta(*b, *q)));
            let pos = layout.add(
                Blob::TargetPositions(i, t - 1),
                FLOAT,
                "VEC3",
                n,
                Some(ARRAY_BUFFER),
                Some(b),
            );
            let mut target = json!({ "POSITION": pos });
            if options.morph_normals {
                target["NORMAL"] = json!(layout.add(
                    Blob::TargetNormals(i, t - 1),
                    FLOAT,
                    "VEC3",
                    n,
                    Some(ARRAY_BUFFER),
                    None,
                ));
            }
            targets.push(target);
            target_names.push(format!("frame {k} (t = {} s)", p.anim.times[k]));
        }
        let mut primitive = json!({
            "attributes": { "POSITION": position, "NORMAL": normal },
            "indices": indices,
            "material": i,
            "mode": TRIANGLES,
        });
        let mut mesh = json!({ "name": p.part.name });
        if !targets.is_empty() {
            mesh["weights"] = json!(vec![0.0; targets.len()]);
            mesh["extras"] = json!({ "targetNames": target_names });
            primitive["targets"] = json!(targets);
        }
        mesh["primitives"] = json!([primitive]);
        meshes.push(mesh);
        let [r, g, b] = p.part.colour.map(srgb_to_linear);
        materials.push(json!({
            "name": p.part.name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [r, g, b, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 0.9,
            },
            "doubleSided": p.part.double_sided,
        }));
        nodes.push(json!({ "name": p.part.name, "mesh": i }));
    }
    let mut time_accessors = vec![None; time_lists.len()];
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    let interpolation = match options.interpolation {
        Interpolation::Step => "STEP",
        Interpolation::Linear => "LINEAR",
    };
    for (i, p) in glb.iter().enumerate() {
        let keys = p.keep.len();
        if keys < 2 {
            continue;
        }
        let input = *time_accessors[p.times].get_or_insert_with(|| {
            let t = &time_lists[p.times];
            layout.add(
                Blob::Times(p.times),
                FLOAT,
                "SCALAR",
                keys,
                None,
                Some((vec![t[0]], vec![t[keys - 1]])),
            )
        });
        let output = layout.add(
            Blob::Weights(i),
            FLOAT,
            "SCALAR",
            keys * (keys - 1),
            None,
            None,
        );
        channels.push(json!({
            "sampler": samplers.len(),
            "target": { "node": i, "path": "weights" },
        }));
        samplers.push(json!({ "input": input, "output": output, "interpolation": interpolation }));
    }

    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("atelier ", env!("CARGO_PKG_VERSION")),
            "extras": { "units": "metres", "frame": "x = the body's left, y up, z forward" },
        },
        "scene": 0,
        "scenes": [{ "nodes": (0..glb.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": layout.accessors,
        "bufferViews": layout.views,
        "buffers": [{ "byteLength": layout.bytes }],
    });
    if !channels.is_empty() {
        doc["animations"] = json!([{ "name": "run", "samplers": samplers, "channels": channels }]);
    }
    let mut json_bytes =
        serde_json::to_vec(&doc).map_err(|e| invalid_scene(path, format!("glTF JSON: {e}")))?;
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    let bin_len = layout.bytes; // already a multiple of 4
    let total = 12 + 8 + json_bytes.len() as u64 + 8 + bin_len;
    if total > u64::from(u32::MAX) {
        return Err(invalid_scene(
            path,
            format!(
                "{total} bytes exceed the 4 GiB a GLB file can hold; keep fewer frames \
                 (FrameSelection) or drop morph normals"
            ),
        ));
    }

    write_atomically(path, |w| {
        for word in [
            GLB_MAGIC,
            2,
            total as u32,
            json_bytes.len() as u32,
            CHUNK_JSON,
        ] {
            w.write_all(&word.to_le_bytes())?;
        }
        w.write_all(&json_bytes)?;
        for word in [bin_len as u32, CHUNK_BIN] {
            w.write_all(&word.to_le_bytes())?;
        }
        for blob in &layout.blobs {
            write_blob(w, *blob, &glb, &time_lists)?;
        }
        Ok(())
    })
}

/// Write one block of the binary chunk, exactly as [`write_glb`]'s layout sized it.
fn write_blob(
    w: &mut impl Write,
    blob: Blob,
    glb: &[GlbPart<'_>],
    time_lists: &[Vec<f32>],
) -> io::Result<()> {
    match blob {
        Blob::Indices(i) => {
            for tri in glb[i].part.triangles {
                for &v in tri {
                    w.write_all(&v.to_le_bytes())?;
                }
            }
        }
        Blob::BasePositions(i) => {
            for &b in &glb[i].base {
                put_f32s(w, b)?;
            }
        }
        Blob::BaseNormals(i) => {
            for &n in &glb[i].base_normals {
                put_f32s(w, n)?;
            }
        }
        Blob::TargetPositions(i, t) => {
            let p = &glb[i];
            for (b, q) in p.base.iter().zip(&p.anim.frames[p.keep[t + 1]]) {
                put_f32s(w, delta(*b, *q))?;
            }
        }
        Blob::TargetNormals(i, t) => {
            let p = &glb[i];
            let normals = vertex_normals(&p.anim.frames[p.keep[t + 1]], p.part.triangles);
            for (b, n) in p.base_normals.iter().zip(normals) {
                put_f32s(w, delta(*b, n))?;
            }
        }
        Blob::Times(s) => {
            for t in &time_lists[s] {
                w.write_all(&t.to_le_bytes())?;
            }
        }
        Blob::Weights(i) => {
            // Key j: all zero at the first kept frame, else target j − 1 alone at weight 1.
            let keys = glb[i].keep.len();
            for j in 0..keys {
                for t in 0..keys - 1 {
                    let v: f32 = if j == t + 1 { 1.0 } else { 0.0 };
                    w.write_all(&v.to_le_bytes())?;
                }
            }
        }
    }
    Ok(())
}
