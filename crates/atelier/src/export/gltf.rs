//! The whole run as a glTF 2.0 binary: the parts' meshes, their motion as morph targets
//! driven by a `weights` animation, streamed chunk by chunk.

use std::io::{self, Write};
use std::path::Path;

use serde_json::{Value, json};

use super::{
    Animation, ExportError, FrameSelection, GlbOptions, Interpolation, MeshPart, check_frame,
    check_part, invalid_part, invalid_scene, put_f32s, srgb_to_linear, to_f32, vertex_normals,
    write_atomically,
};

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
    /// Part: its vertex colours.
    Colours(usize),
    /// Part, kept frame: its values per vertex.
    Values(usize, usize),
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
    if let Some(vc) = part.vertex_colours
        && (vc.colours.len() != n
            || vc.names.len() != vc.name_colours.len()
            || vc
                .colours
                .iter()
                .chain(vc.name_colours)
                .flatten()
                .any(|c| !c.is_finite()))
    {
        return Err(invalid_part(
            path,
            part,
            format!(
                "{} vertex colours for {n} vertices, {} names for {} group colours, or a colour not finite",
                vc.colours.len(),
                vc.names.len(),
                vc.name_colours.len()
            ),
        ));
    }
    if let Some(v) = part.frame_values {
        let bad = v.values.len() != anim.frames.len()
            || v.values
                .iter()
                .any(|f| f.len() != n || f.iter().any(|x| !x.is_finite()));
        if bad {
            return Err(invalid_part(
                path,
                part,
                format!(
                    "{}: {} lists of values for {} frames of {n} vertices, or a value not finite",
                    v.name,
                    v.values.len(),
                    anim.frames.len()
                ),
            ));
        }
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
        let mut extras = serde_json::Map::new();
        if !targets.is_empty() {
            mesh["weights"] = json!(vec![0.0; targets.len()]);
            extras.insert("targetNames".into(), json!(target_names));
            primitive["targets"] = json!(targets);
        }
        if let Some(vc) = p.part.vertex_colours {
            primitive["attributes"]["COLOR_0"] =
                json!(layout.add(Blob::Colours(i), FLOAT, "VEC3", n, Some(ARRAY_BUFFER), None,));
            extras.insert("panels".into(), json!(vc.names));
            // Linear, as COLOR_0.
            let linear: Vec<[f32; 3]> = vc
                .name_colours
                .iter()
                .map(|c| c.map(srgb_to_linear))
                .collect();
            extras.insert("panel_colours".into(), json!(linear));
        }
        if let Some(values) = p.part.frame_values {
            let accessors: Vec<usize> = (0..p.keep.len())
                .map(|t| layout.add(Blob::Values(i, t), FLOAT, "SCALAR", n, None, None))
                .collect();
            let max = p
                .keep
                .iter()
                .flat_map(|&k| &values.values[k])
                .fold(0.0_f32, |m, &v| m.max(v));
            extras.insert(
                values.name.into(),
                json!({ "accessors": accessors, "max": max }),
            );
        }
        if !extras.is_empty() {
            mesh["extras"] = Value::Object(extras);
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
        Blob::Colours(i) => {
            let vc = glb[i].part.vertex_colours.expect("laid out with colours");
            for c in vc.colours {
                put_f32s(w, c.map(srgb_to_linear))?;
            }
        }
        Blob::Values(i, t) => {
            let p = &glb[i];
            let values = p.part.frame_values.expect("laid out with values");
            for v in &values.values[p.keep[t]] {
                w.write_all(&v.to_le_bytes())?;
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
