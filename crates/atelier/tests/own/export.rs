//! Exports: a two-part scene (a still tetrahedron and a quad moving over 3 frames) written as
//! OBJ, PLY and GLB and read back byte by byte; invalid input and unwritable targets fail with
//! typed errors and leave nothing behind.

use std::path::Path;

use atelier::export::{
    Animation, ExportError, FrameSelection, FrameValues, GlbOptions, Interpolation, MeshPart,
    VertexColours, write_glb, write_obj, write_ply,
};
use serde_json::Value;

use crate::scratch::Scratch;

/// A fresh, empty directory for one test, removed when it is done.
fn scratch(test: &str) -> Scratch {
    Scratch::new("export", test)
}

/// Names of the files in `dir`.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

const TETRA_TRIS: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
const QUAD_TRIS: [[u32; 3]; 2] = [[0, 2, 1], [0, 3, 2]];
const TIMES: [f64; 3] = [0.0, 0.5, 1.25];

/// Dyadic coordinates, so every value is exact in single precision.
fn tetra() -> Vec<[f64; 3]> {
    vec![
        [0.0, 0.0, 0.0],
        [0.5, 0.0, 0.0],
        [0.0, 0.0, 0.5],
        [0.125, 0.75, 0.125],
    ]
}

/// The quad at frame k: rising by 0.25 m per frame and tilting its far edge.
fn quad(k: usize) -> Vec<[f64; 3]> {
    let y = 1.0 + 0.25 * k as f64;
    let tilt = 0.125 * k as f64;
    vec![
        [-0.5, y, -0.5],
        [0.5, y, -0.5],
        [0.5, y + tilt, 0.5],
        [-0.5, y + tilt, 0.5],
    ]
}

fn parts() -> (Animation, Animation) {
    let body = Animation::still(tetra());
    let mut cloth = Animation::default();
    for (k, &t) in TIMES.iter().enumerate() {
        cloth.push(t, quad(k));
    }
    (body, cloth)
}

fn body_part() -> MeshPart<'static> {
    MeshPart::body("body", &TETRA_TRIS, [0.75, 0.75, 0.78])
}

fn cloth_part() -> MeshPart<'static> {
    MeshPart::cloth("skirt cloth", &QUAD_TRIS, [0.85, 0.35, 0.25])
}

#[test]
fn obj_has_one_group_per_part_with_normals_and_faces() {
    let dir = scratch("obj");
    let path = dir.join("scene.obj");
    let (body, cloth) = parts();
    write_obj(
        &path,
        &[
            (body_part(), body.last().expect("frame")),
            (cloth_part(), cloth.last().expect("frame")),
        ],
    )
    .expect("obj");
    let text = std::fs::read_to_string(&path).expect("read");
    let lines_with = |tag: &str| {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(tag))
            .collect::<Vec<_>>()
    };
    assert_eq!(lines_with("o"), ["o body", "o skirt_cloth"]);
    assert_eq!(lines_with("v").len(), 8);
    assert_eq!(lines_with("vn").len(), 8);
    let faces = lines_with("f");
    assert_eq!(faces.len(), 6);
    // The quad's faces are numbered after the tetrahedron's 4 vertices.
    assert_eq!(faces[4], "f 5//5 7//7 6//6");
    // Last frame of the quad, exact (OBJ keeps double precision).
    let v: Vec<[f64; 3]> = lines_with("v")
        .iter()
        .map(|l| {
            let c: Vec<f64> = l[2..]
                .split_whitespace()
                .map(|x| x.parse().expect("number"))
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    assert_eq!(&v[4..], quad(2).as_slice());
    // The quad is flat, its normal up and tilted towards −z (counter-clockwise seen from above).
    let n: Vec<f64> = lines_with("vn")[5][3..]
        .split_whitespace()
        .map(|x| x.parse().expect("number"))
        .collect();
    let expected = [0.0, 1.0, -0.25];
    let len = (1.0f64 + 0.0625).sqrt();
    for k in 0..3 {
        assert!((n[k] - expected[k] / len).abs() < 1e-6, "normal {n:?}");
    }
    assert_eq!(listing(&dir), ["scene.obj"], "no temporary left");
}

#[test]
#[allow(clippy::float_cmp, reason = "dyadic coordinates are stored exactly")]
fn ply_header_and_binary_payload_read_back() {
    let dir = scratch("ply");
    let path = dir.join("scene.ply");
    let (body, cloth) = parts();
    write_ply(
        &path,
        &[
            (body_part(), body.last().expect("frame")),
            (cloth_part(), cloth.last().expect("frame")),
        ],
    )
    .expect("ply");
    let bytes = std::fs::read(&path).expect("read");
    let end = b"end_header\n";
    let split = bytes
        .windows(end.len())
        .position(|w| w == end)
        .expect("end_header")
        + end.len();
    let header = std::str::from_utf8(&bytes[..split]).expect("ascii header");
    let lines: Vec<&str> = header.lines().collect();
    assert_eq!(lines[0], "ply");
    assert_eq!(lines[1], "format binary_little_endian 1.0");
    assert!(lines.contains(&"comment part body: vertices 0..4, faces 0..4"));
    assert!(lines.contains(&"comment part skirt_cloth: vertices 4..8, faces 4..6"));
    let properties: Vec<&str> = lines
        .iter()
        .filter(|l| l.starts_with("element") || l.starts_with("property"))
        .copied()
        .collect();
    assert_eq!(
        properties,
        [
            "element vertex 8",
            "property float x",
            "property float y",
            "property float z",
            "property float nx",
            "property float ny",
            "property float nz",
            "property uchar red",
            "property uchar green",
            "property uchar blue",
            "element face 6",
            "property list uchar int vertex_indices",
        ]
    );
    let body_bytes = &bytes[split..];
    let vertex_size = 6 * 4 + 3;
    assert_eq!(body_bytes.len(), 8 * vertex_size + 6 * (1 + 3 * 4));
    let f32_at = |o: usize| f32::from_le_bytes(body_bytes[o..o + 4].try_into().expect("4"));
    let i32_at = |o: usize| i32::from_le_bytes(body_bytes[o..o + 4].try_into().expect("4"));
    let expected: Vec<[f64; 3]> = tetra().into_iter().chain(quad(2)).collect();
    for (i, p) in expected.iter().enumerate() {
        let o = i * vertex_size;
        let got = [f32_at(o), f32_at(o + 4), f32_at(o + 8)];
        assert_eq!(got, p.map(|x| x as f32), "vertex {i}");
        let n = [f32_at(o + 12), f32_at(o + 16), f32_at(o + 20)];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-6, "unit normal at {i}");
        let rgb = &body_bytes[o + 24..o + 27];
        let want: [u8; 3] = if i < 4 {
            [191, 191, 199]
        } else {
            [217, 89, 64]
        };
        assert_eq!(rgb, want, "colour of vertex {i}");
    }
    let faces = &body_bytes[8 * vertex_size..];
    let mut read = Vec::new();
    for f in 0..6 {
        let o = f * 13;
        assert_eq!(faces[o], 3);
        let base = 8 * vertex_size + o + 1;
        read.push([i32_at(base), i32_at(base + 4), i32_at(base + 8)]);
    }
    assert_eq!(read[0], [0, 2, 1]);
    assert_eq!(read[4], [4, 6, 5]);
    assert_eq!(read[5], [4, 7, 6]);
}

/// A GLB file split into its JSON document and binary chunk, the header checked.
fn read_glb(path: &Path) -> (Value, Vec<u8>) {
    let bytes = std::fs::read(path).expect("read");
    let word = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().expect("4"));
    assert_eq!(&bytes[0..4], b"glTF", "magic");
    assert_eq!(word(4), 2, "version");
    assert_eq!(word(8) as usize, bytes.len(), "length");
    let json_len = word(12) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let json = &bytes[20..20 + json_len];
    let doc: Value = serde_json::from_slice(json).expect("JSON chunk");
    let text_end = json.iter().rposition(|&b| b != b' ').expect("text") + 1;
    assert!(json_len - text_end < 4, "padded with at most 3 spaces");
    let b = 20 + json_len;
    let bin_len = word(b) as usize;
    assert_eq!(&bytes[b + 4..b + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0);
    assert_eq!(b + 8 + bin_len, bytes.len());
    (doc, bytes[b + 8..].to_vec())
}

/// An accessor's floats, decoded from the binary chunk.
fn floats(doc: &Value, bin: &[u8], accessor: u64) -> Vec<f32> {
    let a = &doc["accessors"][accessor as usize];
    assert_eq!(a["componentType"], 5126);
    let width = if a["type"] == "VEC3" { 3 } else { 1 };
    let view = &doc["bufferViews"][a["bufferView"].as_u64().expect("view") as usize];
    let offset = view["byteOffset"].as_u64().expect("offset") as usize
        + a["byteOffset"].as_u64().unwrap_or(0) as usize;
    let count = a["count"].as_u64().expect("count") as usize * width;
    assert_eq!(view["byteLength"].as_u64(), Some(4 * count as u64));
    (0..count)
        .map(|i| {
            let o = offset + 4 * i;
            f32::from_le_bytes(bin[o..o + 4].try_into().expect("4"))
        })
        .collect()
}

fn vec3s(v: &[f32]) -> Vec<[f32; 3]> {
    v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn true_bounds(points: &[[f32; 3]]) -> (Vec<f32>, Vec<f32>) {
    let mut lo = vec![f32::INFINITY; 3];
    let mut hi = vec![f32::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

fn as_f32s(v: &Value) -> Vec<f32> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number") as f32)
        .collect()
}

#[test]
#[allow(clippy::float_cmp, reason = "dyadic coordinates are stored exactly")]
fn glb_holds_meshes_materials_and_the_run_as_morph_targets() {
    let dir = scratch("glb");
    let path = dir.join("run.glb");
    let (body, cloth) = parts();
    write_glb(
        &path,
        &[(body_part(), &body), (cloth_part(), &cloth)],
        &GlbOptions::default(),
    )
    .expect("glb");
    let (doc, bin) = read_glb(&path);
    assert_eq!(doc["asset"]["version"], "2.0");
    assert_eq!(
        doc["buffers"][0]["byteLength"].as_u64(),
        Some(bin.len() as u64)
    );
    for view in doc["bufferViews"].as_array().expect("views") {
        assert_eq!(view["byteOffset"].as_u64().expect("offset") % 4, 0);
    }
    assert_eq!(doc["nodes"][1]["name"], "skirt cloth");
    assert_eq!(doc["materials"][0]["doubleSided"], false);
    assert_eq!(doc["materials"][1]["doubleSided"], true);
    let base_colour = as_f32s(&doc["materials"][1]["pbrMetallicRoughness"]["baseColorFactor"]);
    assert_eq!(base_colour.len(), 4);
    assert!((base_colour[0] - 0.6921).abs() < 1e-3, "sRGB 0.85 → linear");

    let frames = [tetra()]
        .into_iter()
        .chain((0..3).map(quad))
        .collect::<Vec<_>>();
    for (mesh, (tris, base, vertices)) in [(0usize, (12, &frames[0], 4)), (1, (6, &frames[1], 4))] {
        let prim = &doc["meshes"][mesh]["primitives"][0];
        assert_eq!(prim["mode"], 4);
        assert_eq!(prim["material"], mesh);
        let indices = &doc["accessors"][prim["indices"].as_u64().expect("idx") as usize];
        assert_eq!(indices["componentType"], 5125);
        assert_eq!(indices["count"], tris);
        let pos_id = prim["attributes"]["POSITION"].as_u64().expect("pos");
        let pos = &doc["accessors"][pos_id as usize];
        assert_eq!(pos["count"], vertices);
        let stored = vec3s(&floats(&doc, &bin, pos_id));
        let exact: Vec<[f32; 3]> = base.iter().map(|p| p.map(|x| x as f32)).collect();
        assert_eq!(stored, exact, "base positions of mesh {mesh}");
        let (lo, hi) = true_bounds(&exact);
        assert_eq!(as_f32s(&pos["min"]), lo);
        assert_eq!(as_f32s(&pos["max"]), hi);
        let normal_id = prim["attributes"]["NORMAL"].as_u64().expect("normal");
        assert_eq!(doc["accessors"][normal_id as usize]["count"], vertices);
    }
    // The still tetrahedron has no targets and no channel.
    assert!(doc["meshes"][0]["primitives"][0].get("targets").is_none());
    // The quad: one target per frame after the first.
    let prim = &doc["meshes"][1]["primitives"][0];
    let targets = prim["targets"].as_array().expect("targets");
    assert_eq!(targets.len(), TIMES.len() - 1);
    assert_eq!(as_f32s(&doc["meshes"][1]["weights"]), [0.0, 0.0]);
    let base = vec3s(&floats(
        &doc,
        &bin,
        prim["attributes"]["POSITION"].as_u64().expect("pos"),
    ));
    for (t, target) in targets.iter().enumerate() {
        let id = target["POSITION"].as_u64().expect("target position");
        let deltas = vec3s(&floats(&doc, &bin, id));
        let (lo, hi) = true_bounds(&deltas);
        assert_eq!(as_f32s(&doc["accessors"][id as usize]["min"]), lo);
        assert_eq!(as_f32s(&doc["accessors"][id as usize]["max"]), hi);
        assert!(target.get("NORMAL").is_some(), "morph normals by default");
        // Frame t + 1 reproduced exactly: base + delta.
        for (v, (b, d)) in base.iter().zip(&deltas).enumerate() {
            let got = [b[0] + d[0], b[1] + d[1], b[2] + d[2]];
            assert_eq!(
                got,
                quad(t + 1)[v].map(|x| x as f32),
                "frame {} vertex {v}",
                t + 1
            );
        }
    }
    // The animation: times as given, one weight vector per key, target k alone at key k.
    let anim = &doc["animations"][0];
    let channels = anim["channels"].as_array().expect("channels");
    assert_eq!(channels.len(), 1);
    assert_eq!(channels[0]["target"]["node"], 1);
    assert_eq!(channels[0]["target"]["path"], "weights");
    let sampler = &anim["samplers"][channels[0]["sampler"].as_u64().expect("s") as usize];
    assert_eq!(sampler["interpolation"], "LINEAR");
    let input = sampler["input"].as_u64().expect("input");
    let times = floats(&doc, &bin, input);
    assert_eq!(times, TIMES.map(|t| t as f32));
    assert_eq!(as_f32s(&doc["accessors"][input as usize]["min"]), [0.0]);
    assert_eq!(as_f32s(&doc["accessors"][input as usize]["max"]), [1.25]);
    let weights = floats(&doc, &bin, sampler["output"].as_u64().expect("output"));
    assert_eq!(weights, [0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    assert_eq!(listing(&dir), ["run.glb"], "no temporary left");
}

#[test]
fn glb_frames_can_be_subsampled_and_output_is_deterministic() {
    assert_eq!(FrameSelection::All.indices(3), Some(vec![0, 1, 2]));
    assert_eq!(FrameSelection::Stride(3).indices(8), Some(vec![0, 3, 6, 7]));
    assert_eq!(FrameSelection::Stride(2).indices(5), Some(vec![0, 2, 4]));
    assert_eq!(FrameSelection::AtMost(3).indices(9), Some(vec![0, 4, 8]));
    assert_eq!(FrameSelection::AtMost(5).indices(3), Some(vec![0, 1, 2]));
    assert_eq!(FrameSelection::Stride(0).indices(3), None);

    let dir = scratch("subsample");
    let (body, cloth) = parts();
    let options = GlbOptions {
        frames: FrameSelection::AtMost(2),
        interpolation: Interpolation::Step,
        morph_normals: false,
    };
    let scene = [(body_part(), &body), (cloth_part(), &cloth)];
    write_glb(&dir.join("a.glb"), &scene, &options).expect("glb");
    write_glb(&dir.join("b.glb"), &scene, &options).expect("glb");
    let a = std::fs::read(dir.join("a.glb")).expect("read");
    assert_eq!(
        a,
        std::fs::read(dir.join("b.glb")).expect("read"),
        "same bytes"
    );
    let (doc, bin) = read_glb(&dir.join("a.glb"));
    let targets = doc["meshes"][1]["primitives"][0]["targets"]
        .as_array()
        .expect("targets");
    assert_eq!(targets.len(), 1, "first and last frame kept");
    assert!(targets[0].get("NORMAL").is_none());
    let sampler = &doc["animations"][0]["samplers"][0];
    assert_eq!(sampler["interpolation"], "STEP");
    let times = floats(&doc, &bin, sampler["input"].as_u64().expect("input"));
    assert_eq!(times, [0.0, 1.25]);

    let bad = GlbOptions {
        frames: FrameSelection::AtMost(1),
        ..GlbOptions::default()
    };
    let err = write_glb(&dir.join("c.glb"), &scene, &bad).expect_err("invalid selection");
    assert!(matches!(err, ExportError::InvalidScene { .. }), "{err}");
}

#[test]
fn glb_carries_vertex_colours_and_values_per_kept_frame_for_the_viewer() {
    let dir = scratch("viewer_extras");
    let (body, cloth) = parts();
    let names = vec!["front".to_string(), "back".to_string()];
    // sRGB 0.5 is linear 0.21404114 (IEC 61966-2-1); 0 and 1 map to themselves.
    let colours = [
        [0.0, 0.5, 1.0],
        [0.0, 0.5, 1.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
    ];
    let values: Vec<Vec<f32>> = (0..TIMES.len())
        .map(|k| (0..4).map(|v| (10 * k + v) as f32 * 1e-3).collect())
        .collect();
    let mut cloth_p = cloth_part();
    cloth_p.vertex_colours = Some(VertexColours {
        colours: &colours,
        names: &names,
        name_colours: &[[0.0, 0.5, 1.0], [1.0, 0.0, 0.0]],
    });
    cloth_p.frame_values = Some(FrameValues {
        name: "strain_error",
        values: &values,
    });
    let options = GlbOptions {
        frames: FrameSelection::AtMost(2),
        ..GlbOptions::default()
    };
    let path = dir.join("run.glb");
    write_glb(&path, &[(body_part(), &body), (cloth_p, &cloth)], &options).expect("glb");
    let (doc, bin) = read_glb(&path);
    let mesh = &doc["meshes"][1];
    assert_eq!(
        mesh["extras"]["panels"],
        serde_json::json!(["front", "back"])
    );
    let given: Vec<f32> = as_f32s(&mesh["extras"]["panel_colours"][0]);
    assert!(
        (given[1] - 0.214_041_14).abs() < 1e-6,
        "linear, as COLOR_0: {given:?}"
    );
    assert_eq!(
        as_f32s(&mesh["extras"]["panel_colours"][1]),
        [1.0, 0.0, 0.0]
    );
    let colour = mesh["primitives"][0]["attributes"]["COLOR_0"]
        .as_u64()
        .expect("COLOR_0");
    let linear = vec3s(&floats(&doc, &bin, colour));
    assert!((linear[0][1] - 0.214_041_14).abs() < 1e-6, "{linear:?}");
    assert_eq!(linear[2], [1.0, 0.0, 0.0]);
    // The first and last frame are kept: their values, in that order.
    let extra = &mesh["extras"]["strain_error"];
    let accessors: Vec<u64> = extra["accessors"]
        .as_array()
        .expect("accessors")
        .iter()
        .map(|a| a.as_u64().expect("index"))
        .collect();
    assert_eq!(accessors.len(), 2);
    assert_eq!(floats(&doc, &bin, accessors[0]), values[0]);
    assert_eq!(floats(&doc, &bin, accessors[1]), values[TIMES.len() - 1]);
    assert_eq!(
        extra["max"].as_f64().expect("max") as f32,
        values[TIMES.len() - 1][3]
    );
    // The body carries neither.
    assert!(
        doc["meshes"][0]["primitives"][0]["attributes"]
            .get("COLOR_0")
            .is_none()
    );

    // Values for fewer frames than the animation holds are refused, and nothing is written.
    cloth_p.frame_values = Some(FrameValues {
        name: "strain_error",
        values: &values[..1],
    });
    let err = write_glb(&dir.join("bad.glb"), &[(cloth_p, &cloth)], &options)
        .expect_err("values for one frame of three");
    assert!(
        err.to_string()
            .contains("strain_error: 1 lists of values for 3 frames"),
        "{err}"
    );
    assert!(!dir.join("bad.glb").exists());
}

#[test]
fn glb_frames_of_arbitrary_coordinates_are_reproduced_to_single_precision() {
    let dir = scratch("precision");
    let mut cloth = Animation::default();
    for k in 0..4 {
        let s = 0.1 * k as f64;
        cloth.push(
            0.1 * k as f64,
            vec![
                [-0.3 + s, 1.7 - 0.33 * s, 0.01],
                [0.3, 1.7 + s * s, -0.02 * s],
                [0.3, 0.9 + s, 0.4 - s],
                [-1e-4 * s, 0.9, 0.4],
            ],
        );
    }
    let path = dir.join("run.glb");
    write_glb(&path, &[(cloth_part(), &cloth)], &GlbOptions::default()).expect("glb");
    let (doc, bin) = read_glb(&path);
    let prim = &doc["meshes"][0]["primitives"][0];
    let base = vec3s(&floats(
        &doc,
        &bin,
        prim["attributes"]["POSITION"].as_u64().expect("pos"),
    ));
    for (t, target) in prim["targets"]
        .as_array()
        .expect("targets")
        .iter()
        .enumerate()
    {
        let deltas = vec3s(&floats(
            &doc,
            &bin,
            target["POSITION"].as_u64().expect("pos"),
        ));
        for (v, (b, d)) in base.iter().zip(&deltas).enumerate() {
            let truth = cloth.frames[t + 1][v];
            for k in 0..3 {
                let got = f64::from(b[k] + d[k]);
                let scale = truth[k].abs().max(f64::from(d[k].abs()));
                assert!(
                    (got - truth[k]).abs() <= f64::from(f32::EPSILON) * scale,
                    "frame {} vertex {v}: {got} for {}",
                    t + 1,
                    truth[k]
                );
            }
        }
    }
    let times = floats(
        &doc,
        &bin,
        doc["animations"][0]["samplers"][0]["input"]
            .as_u64()
            .expect("in"),
    );
    let expected: Vec<f32> = cloth.times.iter().map(|&t| t as f32).collect();
    assert!(
        times
            .iter()
            .zip(&expected)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    );
}

#[test]
fn non_finite_positions_are_rejected_and_nothing_is_written() {
    let dir = scratch("nan");
    let (body, mut cloth) = parts();
    cloth.frames[2][3][1] = f64::NAN;
    let path = dir.join("run.glb");
    let err = write_glb(
        &path,
        &[(body_part(), &body), (cloth_part(), &cloth)],
        &GlbOptions::default(),
    )
    .expect_err("NaN");
    match &err {
        ExportError::NonFinite {
            path: p,
            part,
            frame,
            vertex,
            ..
        } => {
            assert_eq!(p, &path);
            assert_eq!((part.as_str(), *frame, *vertex), ("skirt cloth", 2, 3));
        }
        other => panic!("expected NonFinite, got {other:?}"),
    }
    let message = err.to_string();
    assert!(
        message.contains("skirt cloth") && message.contains("vertex 3"),
        "{message}"
    );
    let last = cloth.last().expect("frame");
    for (name, result) in [
        (
            "run.obj",
            write_obj(&dir.join("run.obj"), &[(cloth_part(), last)]),
        ),
        (
            "run.ply",
            write_ply(&dir.join("run.ply"), &[(cloth_part(), last)]),
        ),
    ] {
        assert!(
            matches!(result, Err(ExportError::NonFinite { vertex: 3, .. })),
            "{name}: {result:?}"
        );
    }
    let mut huge = tetra();
    huge[1][0] = 1e300;
    let result = write_ply(&dir.join("huge.ply"), &[(body_part(), &huge)]);
    assert!(matches!(
        result,
        Err(ExportError::NonFinite { vertex: 1, .. })
    ));
    assert!(listing(&dir).is_empty(), "left behind: {:?}", listing(&dir));
}

#[test]
fn malformed_parts_are_rejected() {
    let dir = scratch("malformed");
    let path = dir.join("bad.obj");
    let bad_tris = [[0u32, 1, 4]];
    let result = write_obj(
        &path,
        &[(MeshPart::body("body", &bad_tris, [0.5; 3]), &tetra())],
    );
    assert!(
        matches!(result, Err(ExportError::InvalidPart { .. })),
        "{result:?}"
    );
    let result = write_obj(&path, &[]);
    assert!(
        matches!(result, Err(ExportError::InvalidScene { .. })),
        "{result:?}"
    );
    let (_, mut cloth) = parts();
    cloth.times[2] = 0.5;
    let result = write_glb(
        &dir.join("bad.glb"),
        &[(cloth_part(), &cloth)],
        &GlbOptions::default(),
    );
    assert!(
        matches!(result, Err(ExportError::InvalidPart { .. })),
        "{result:?}"
    );
    let (_, mut cloth) = parts();
    cloth.frames[1].pop();
    let result = write_glb(
        &dir.join("bad.glb"),
        &[(cloth_part(), &cloth)],
        &GlbOptions::default(),
    );
    assert!(
        matches!(result, Err(ExportError::InvalidPart { .. })),
        "{result:?}"
    );
    assert!(listing(&dir).is_empty());
}

#[test]
fn unwritable_targets_fail_with_the_path() {
    let dir = scratch("unwritable");
    // A regular file where a directory should be (fails even for root).
    let blocker = dir.join("not-a-dir");
    std::fs::write(&blocker, b"x").expect("blocker");
    let (body, cloth) = parts();
    let scene = [(body_part(), &body), (cloth_part(), &cloth)];
    let missing = dir.join("missing").join("run.glb");
    for path in [blocker.join("run.glb"), missing] {
        let err = write_glb(&path, &scene, &GlbOptions::default()).expect_err("unwritable");
        match &err {
            ExportError::Io { path: p, .. } => assert_eq!(p, &path),
            other => panic!("expected Io, got {other:?}"),
        }
        assert!(std::error::Error::source(&err).is_some(), "cause kept");
        assert!(err.to_string().contains("run.glb"));
    }
    let err = write_obj(&blocker.join("x.obj"), &[(body_part(), &tetra())]).expect_err("obj");
    assert!(matches!(err, ExportError::Io { .. }));
    let err = write_ply(&blocker.join("x.ply"), &[(body_part(), &tetra())]).expect_err("ply");
    assert!(matches!(err, ExportError::Io { .. }));
    // A directory at the target itself: the rename fails and the temporary is removed.
    let target = dir.join("taken.obj");
    std::fs::create_dir(&target).expect("dir");
    let err = write_obj(&target, &[(body_part(), &tetra())]).expect_err("dir target");
    assert!(matches!(err, ExportError::Io { .. }));
    assert_eq!(listing(&dir), ["not-a-dir", "taken.obj"]);
}
