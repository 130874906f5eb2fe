//! External bodies: triangle meshes read from OBJ or ASCII PLY (a scan, or a mannequin written
//! by [`write_obj`] / [`write_ply`]), with optional part labels for articulation.
//!
//! - **OBJ**: `v x y z` and `f` lines (polygons fan-triangulated; indices 1-based, or negative =
//!   relative to the last vertex read; `i/t/n` forms accepted, texture and normal indices
//!   ignored). A `g` or `o` line whose name is a part name ([`Part::name`], `thigh_left`) labels
//!   the faces after it; any other name clears the label. Other statements are ignored.
//! - **PLY** (ASCII 1.0): element `vertex` with properties `x`, `y`, `z` and optionally an integer
//!   `part` ([`Part::index`]); element `face` with a list property (`vertex_indices`). Other
//!   elements and properties are skipped. A face takes the label of its first vertex.
//!
//! Labels are kept only when complete: every triangle (and, for vertex labels, every vertex)
//! labelled. Coordinates are read as they are, multiplied by [`LoadOptions::scale`] (the model
//! works in metres: use 0.001 for a scan in millimetres). Errors are [`FileError`]s with the line.

use std::path::Path;

use atelier_files::{ErrorKind, FileError, Position};

use crate::build::first_open_edge;
use crate::description::part_named;
use crate::model::{LabelledMesh, Part, V3};

/// A mesh read from a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExternalBody {
    /// Vertices (file units × [`LoadOptions::scale`]).
    pub vertices: Vec<V3>,
    /// Triangles, in the file's orientation.
    pub triangles: Vec<[u32; 3]>,
    /// Part of each vertex, when every vertex is labelled.
    pub vertex_part: Option<Vec<Part>>,
    /// Part of each triangle, when every triangle is labelled.
    pub triangle_part: Option<Vec<Part>>,
    /// Whether every edge lies in exactly two triangles running it in opposite directions.
    pub closed: bool,
}

impl ExternalBody {
    /// As a labelled mesh, if both labels are complete.
    pub fn labelled(&self) -> Option<LabelledMesh> {
        Some(LabelledMesh {
            vertices: self.vertices.clone(),
            triangles: self.triangles.clone(),
            vertex_part: self.vertex_part.clone()?,
            triangle_part: self.triangle_part.clone()?,
        })
    }
}

impl From<&LabelledMesh> for ExternalBody {
    fn from(m: &LabelledMesh) -> Self {
        let label = |v: &Vec<Part>, n: usize| (v.len() == n && n > 0).then(|| v.clone());
        ExternalBody {
            vertices: m.vertices.clone(),
            triangles: m.triangles.clone(),
            vertex_part: label(&m.vertex_part, m.vertices.len()),
            triangle_part: label(&m.triangle_part, m.triangles.len()),
            closed: first_open_edge(&m.triangles).is_none(),
        }
    }
}

/// How to read a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadOptions {
    /// Refuse a mesh that is not closed and consistently oriented ([`ErrorKind::Inconsistent`],
    /// naming the first open edge and the line of its face).
    pub require_closed: bool,
    /// Factor applied to the coordinates (1 when the file is in metres).
    pub scale: f64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            require_closed: false,
            scale: 1.0,
        }
    }
}

/// Read an OBJ or PLY mesh (by extension; otherwise PLY when the file starts with `ply`).
pub fn load_mesh(path: &Path) -> Result<ExternalBody, FileError> {
    load_mesh_with(path, &LoadOptions::default())
}

/// [`load_mesh`] with options.
pub fn load_mesh_with(path: &Path, opts: &LoadOptions) -> Result<ExternalBody, FileError> {
    let text = atelier_files::files::read_text(path)?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let is_ply = match ext.as_deref() {
        Some("ply") => true,
        Some("obj") => false,
        _ => text.lines().next().map(str::trim) == Some("ply"),
    };
    if is_ply {
        parse_ply(&text, path, opts)
    } else {
        parse_obj(&text, path, opts)
    }
}

fn err(file: &Path, line: Option<usize>, kind: ErrorKind, message: impl Into<String>) -> FileError {
    FileError {
        file: file.to_path_buf(),
        position: line.map(|line| Position { line, column: 1 }),
        field: String::new(),
        kind,
        message: message.into(),
        source: None,
    }
}

fn coordinate(tok: Option<&str>, file: &Path, line: usize) -> Result<f64, FileError> {
    let tok = tok.ok_or_else(|| {
        err(
            file,
            Some(line),
            ErrorKind::TooShort,
            "a vertex needs three coordinates",
        )
    })?;
    let v: f64 = tok.parse().map_err(|_| {
        err(
            file,
            Some(line),
            ErrorKind::WrongType,
            format!("`{tok}` is not a number"),
        )
    })?;
    if !v.is_finite() {
        return Err(err(
            file,
            Some(line),
            ErrorKind::NotFinite,
            format!("coordinate {v} is not a finite number"),
        ));
    }
    Ok(v)
}

/// Shared ending: counts, labels, closedness.
fn finish(
    file: &Path,
    opts: &LoadOptions,
    vertices: Vec<V3>,
    faces: Vec<([u32; 3], Option<Part>, usize)>,
    vertex_part: Option<Vec<Part>>,
) -> Result<ExternalBody, FileError> {
    if vertices.is_empty() || faces.is_empty() {
        return Err(err(
            file,
            None,
            ErrorKind::TooShort,
            format!(
                "empty mesh: {} vertices, {} faces",
                vertices.len(),
                faces.len()
            ),
        ));
    }
    // A face without area has no normal: distance queries and inside/outside tests would
    // take an arbitrary side for it. Refused with its line (faces are triangulated fans, so a
    // polygon's degenerate part is named by the polygon's line).
    for (t, _, line) in &faces {
        let [a, b, c] = t.map(|k| vertices[k as usize]);
        let (u, v) = (b - a, c - a);
        let scale = u
            .norm_squared()
            .max(v.norm_squared())
            .max((c - b).norm_squared());
        if u.cross(&v).norm() <= 1e-12 * scale || scale == 0.0 {
            return Err(err(
                file,
                Some(*line),
                ErrorKind::Inconsistent,
                format!(
                    "face ({}, {}, {}) (1-based vertices) has zero area: its corners repeat or lie on one line",
                    t[0] + 1,
                    t[1] + 1,
                    t[2] + 1
                ),
            ));
        }
    }
    let triangles: Vec<[u32; 3]> = faces.iter().map(|f| f.0).collect();
    let triangle_part: Option<Vec<Part>> = faces.iter().map(|f| f.1).collect();
    let vertex_part = vertex_part.or_else(|| {
        // From the faces: each vertex takes the label of the first face using it.
        let labels = triangle_part.as_ref()?;
        let mut vp: Vec<Option<Part>> = vec![None; vertices.len()];
        for (t, &p) in triangles.iter().zip(labels) {
            for &k in t {
                vp[k as usize].get_or_insert(p);
            }
        }
        vp.into_iter().collect()
    });
    let open = first_open_edge(&triangles);
    if let Some((face, [a, b])) = open
        && opts.require_closed
    {
        return Err(err(
            file,
            Some(faces[face].2),
            ErrorKind::Inconsistent,
            format!(
                "the mesh is not closed: edge {} → {} (1-based vertices) is not shared by exactly two faces running it in opposite directions",
                a + 1,
                b + 1
            ),
        ));
    }
    let s = opts.scale;
    Ok(ExternalBody {
        vertices: vertices.into_iter().map(|v| v * s).collect(),
        triangles,
        vertex_part,
        triangle_part,
        closed: open.is_none(),
    })
}

/// Parse OBJ text; `file` names the source in errors.
pub fn parse_obj(text: &str, file: &Path, opts: &LoadOptions) -> Result<ExternalBody, FileError> {
    check_scale(file, opts)?;
    let mut vertices: Vec<V3> = Vec::new();
    // Polygons as (raw indices, label, line); positive indices are resolved at the end.
    let mut faces: Vec<([u32; 3], Option<Part>, usize)> = Vec::new();
    let mut label: Option<Part> = None;
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let content = raw.split('#').next().unwrap_or("");
        let mut toks = content.split_whitespace();
        match toks.next() {
            Some("v") => {
                let x = coordinate(toks.next(), file, line)?;
                let y = coordinate(toks.next(), file, line)?;
                let z = coordinate(toks.next(), file, line)?;
                vertices.push(V3::new(x, y, z));
            }
            Some("f") => {
                let mut poly: Vec<u32> = Vec::new();
                for tok in toks {
                    let first = tok.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| {
                        err(
                            file,
                            Some(line),
                            ErrorKind::WrongType,
                            format!("`{tok}` is not a vertex index"),
                        )
                    })?;
                    let n = vertices.len() as i64;
                    let idx = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || idx < 0 || idx >= n {
                        return Err(err(
                            file,
                            Some(line),
                            ErrorKind::OutOfRange,
                            format!("vertex index {i} out of range ({n} vertices read so far)"),
                        ));
                    }
                    poly.push(idx as u32);
                }
                if poly.len() < 3 {
                    return Err(err(
                        file,
                        Some(line),
                        ErrorKind::TooShort,
                        format!("a face needs at least 3 vertices, found {}", poly.len()),
                    ));
                }
                for j in 1..poly.len() - 1 {
                    faces.push(([poly[0], poly[j], poly[j + 1]], label, line));
                }
            }
            Some("g") | Some("o") => {
                label = toks.find_map(part_named);
            }
            _ => {}
        }
    }
    finish(file, opts, vertices, faces, None)
}

fn check_scale(file: &Path, opts: &LoadOptions) -> Result<(), FileError> {
    if opts.scale.is_finite() && opts.scale > 0.0 {
        Ok(())
    } else {
        Err(err(
            file,
            None,
            ErrorKind::OutOfRange,
            format!("scale {} must be finite and positive", opts.scale),
        ))
    }
}

#[derive(Debug)]
enum Prop {
    Scalar(String),
    List,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Prop>,
}

/// Parse ASCII PLY text; `file` names the source in errors.
pub fn parse_ply(text: &str, file: &Path, opts: &LoadOptions) -> Result<ExternalBody, FileError> {
    check_scale(file, opts)?;
    let mut lines = text.lines().enumerate().map(|(k, l)| (k + 1, l));
    let syntax = |line: usize, m: String| err(file, Some(line), ErrorKind::Syntax, m);
    match lines.next() {
        Some((_, l)) if l.trim() == "ply" => {}
        _ => return Err(syntax(1, "a PLY file starts with `ply`".into())),
    }
    let mut elements: Vec<Element> = Vec::new();
    let mut ended = false;
    for (line, l) in lines.by_ref() {
        let toks: Vec<&str> = l.split_whitespace().collect();
        match toks.as_slice() {
            ["format", "ascii", _] => {}
            ["format", f, _] => {
                return Err(syntax(
                    line,
                    format!("PLY format `{f}`: only ascii is read"),
                ));
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count = count.parse().map_err(|_| {
                    syntax(line, format!("element count `{count}` is not a number"))
                })?;
                elements.push(Element {
                    name: (*name).to_owned(),
                    count,
                    props: Vec::new(),
                });
            }
            ["property", "list", _, _, _] => elements
                .last_mut()
                .ok_or_else(|| syntax(line, "property before any element".into()))?
                .props
                .push(Prop::List),
            ["property", _, name] => elements
                .last_mut()
                .ok_or_else(|| syntax(line, "property before any element".into()))?
                .props
                .push(Prop::Scalar((*name).to_owned())),
            ["end_header"] => {
                ended = true;
                break;
            }
            _ => return Err(syntax(line, format!("unexpected header line `{l}`"))),
        }
    }
    if !ended {
        return Err(err(file, None, ErrorKind::Syntax, "no `end_header`"));
    }
    let mut vertices: Vec<V3> = Vec::new();
    let mut vertex_part: Option<Vec<Part>> = None;
    let mut faces: Vec<([u32; 3], Option<Part>, usize)> = Vec::new();
    let mut last_line = 0;
    for el in &elements {
        let is_vertex = el.name == "vertex";
        let is_face = el.name == "face";
        let has_part = is_vertex
            && el
                .props
                .iter()
                .any(|p| matches!(p, Prop::Scalar(n) if n == "part"));
        if has_part {
            vertex_part = Some(Vec::with_capacity(el.count));
        }
        for _ in 0..el.count {
            let (line, l) = lines.next().ok_or_else(|| {
                err(
                    file,
                    Some(last_line + 1),
                    ErrorKind::TooShort,
                    format!("the file ends before its {} {} elements", el.count, el.name),
                )
            })?;
            last_line = line;
            let toks: Vec<&str> = l.split_whitespace().collect();
            let mut at = 0;
            let mut xyz = [f64::NAN; 3];
            let mut part = None;
            let mut list: Option<Vec<i64>> = None;
            let short = || {
                err(
                    file,
                    Some(line),
                    ErrorKind::TooShort,
                    format!("too few values for a {}", el.name),
                )
            };
            for p in &el.props {
                match p {
                    Prop::Scalar(name) => {
                        let tok = *toks.get(at).ok_or_else(short)?;
                        at += 1;
                        if is_vertex {
                            match name.as_str() {
                                "x" | "y" | "z" => {
                                    let c = usize::from(name == "y") + 2 * usize::from(name == "z");
                                    xyz[c] = coordinate(Some(tok), file, line)?;
                                }
                                "part" => {
                                    let i: i64 = tok.parse().map_err(|_| {
                                        err(
                                            file,
                                            Some(line),
                                            ErrorKind::WrongType,
                                            format!("part label `{tok}` is not an integer"),
                                        )
                                    })?;
                                    part = Some(
                                        usize::try_from(i)
                                            .ok()
                                            .and_then(Part::from_index)
                                            .ok_or_else(|| {
                                                err(
                                                    file,
                                                    Some(line),
                                                    ErrorKind::OutOfRange,
                                                    format!("part label {i} is not in 0..17"),
                                                )
                                            })?,
                                    );
                                }
                                _ => {}
                            }
                        }
                    }
                    Prop::List => {
                        let n_tok = *toks.get(at).ok_or_else(short)?;
                        at += 1;
                        let n: usize = n_tok.parse().map_err(|_| {
                            err(
                                file,
                                Some(line),
                                ErrorKind::WrongType,
                                format!("list length `{n_tok}` is not a count"),
                            )
                        })?;
                        let items = toks.get(at..at + n).ok_or_else(short)?;
                        at += n;
                        if list.is_none() {
                            let parsed: Result<Vec<i64>, _> =
                                items.iter().map(|t| t.parse::<i64>()).collect();
                            list = Some(parsed.map_err(|_| {
                                err(
                                    file,
                                    Some(line),
                                    ErrorKind::WrongType,
                                    "a vertex index is not an integer",
                                )
                            })?);
                        }
                    }
                }
            }
            if is_vertex {
                if xyz.iter().any(|c| c.is_nan()) {
                    return Err(err(
                        file,
                        Some(line),
                        ErrorKind::MissingField,
                        "a vertex needs properties x, y and z",
                    ));
                }
                vertices.push(V3::from(xyz));
                if let (Some(vp), Some(p)) = (vertex_part.as_mut(), part) {
                    vp.push(p);
                }
            } else if is_face {
                let poly = list.ok_or_else(|| {
                    err(
                        file,
                        Some(line),
                        ErrorKind::MissingField,
                        "a face needs a list of vertex indices",
                    )
                })?;
                if poly.len() < 3 {
                    return Err(err(
                        file,
                        Some(line),
                        ErrorKind::TooShort,
                        format!("a face needs at least 3 vertices, found {}", poly.len()),
                    ));
                }
                let n = vertices.len() as i64;
                if let Some(&bad) = poly.iter().find(|&&i| i < 0 || i >= n) {
                    return Err(err(
                        file,
                        Some(line),
                        ErrorKind::OutOfRange,
                        format!("vertex index {bad} out of range (0..{n})"),
                    ));
                }
                let label = vertex_part
                    .as_ref()
                    .and_then(|vp| vp.get(poly[0] as usize).copied());
                for j in 1..poly.len() - 1 {
                    faces.push((
                        [poly[0] as u32, poly[j] as u32, poly[j + 1] as u32],
                        label,
                        line,
                    ));
                }
            }
        }
    }
    finish(file, opts, vertices, faces, vertex_part)
}

/// The mesh as OBJ text: vertices, then faces grouped (`g part_name`) by triangle label.
pub fn obj_text(m: &ExternalBody) -> String {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(40 * (m.vertices.len() + m.triangles.len()));
    s.push_str("# atelier-body mesh (x = body's left, y up, z forward)\n");
    for v in &m.vertices {
        let _ = writeln!(s, "v {} {} {}", v.x, v.y, v.z);
    }
    let mut current: Option<Part> = None;
    for (k, t) in m.triangles.iter().enumerate() {
        let label = m.triangle_part.as_ref().and_then(|l| l.get(k).copied());
        if label.is_some() && label != current {
            let _ = writeln!(s, "g {}", label.map_or("", Part::name));
            current = label;
        }
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// The mesh as ASCII PLY text, with the integer vertex property `part` when labelled.
pub fn ply_text(m: &ExternalBody) -> String {
    use std::fmt::Write as _;
    let labels = m
        .vertex_part
        .as_ref()
        .filter(|l| l.len() == m.vertices.len());
    let mut s = String::with_capacity(40 * (m.vertices.len() + m.triangles.len()));
    s.push_str(
        "ply\nformat ascii 1.0\ncomment atelier-body mesh (x = body's left, y up, z forward)\n",
    );
    let _ = writeln!(s, "element vertex {}", m.vertices.len());
    s.push_str("property double x\nproperty double y\nproperty double z\n");
    if labels.is_some() {
        s.push_str("property int part\n");
    }
    let _ = writeln!(s, "element face {}", m.triangles.len());
    s.push_str("property list uchar int vertex_indices\nend_header\n");
    for (k, v) in m.vertices.iter().enumerate() {
        let _ = write!(s, "{} {} {}", v.x, v.y, v.z);
        if let Some(l) = labels {
            let _ = write!(s, " {}", l[k].index());
        }
        s.push('\n');
    }
    for t in &m.triangles {
        let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
    }
    s
}

/// Write the mesh as OBJ, atomically.
pub fn write_obj(path: &Path, m: &ExternalBody) -> std::io::Result<()> {
    atelier_files::files::write_atomic(path, obj_text(m).as_bytes())
}

/// Write the mesh as ASCII PLY, atomically.
pub fn write_ply(path: &Path, m: &ExternalBody) -> std::io::Result<()> {
    atelier_files::files::write_atomic(path, ply_text(m).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obj(text: &str) -> Result<ExternalBody, FileError> {
        parse_obj(text, Path::new("t.obj"), &LoadOptions::default())
    }

    fn closed_obj(text: &str) -> Result<ExternalBody, FileError> {
        parse_obj(
            text,
            Path::new("t.obj"),
            &LoadOptions {
                require_closed: true,
                scale: 1.0,
            },
        )
    }

    const TETRA: &str = "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ng head\nf 1 3 2\nf 1 2 4\ng neck\nf -4 -1 -2\nf 2/1 3/1/1 4//1\n";

    #[test]
    fn an_obj_is_read_with_its_groups() {
        let b = closed_obj(TETRA).expect("reads");
        assert_eq!(b.vertices.len(), 4);
        assert_eq!(
            b.triangles,
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
        );
        assert!(b.closed);
        assert!(crate::build::signed_volume(&b.vertices, &b.triangles) > 0.0);
        assert_eq!(
            b.triangle_part,
            Some(vec![Part::Head, Part::Head, Part::Neck, Part::Neck])
        );
        assert_eq!(b.vertex_part.as_ref().map(Vec::len), Some(4));
        // A quad is fanned; an unknown group name drops the labels.
        let q = obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng lid\nf 1 2 3 4\n").expect("reads");
        assert_eq!(q.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(q.triangle_part, None);
        assert!(!q.closed);
    }

    #[test]
    fn an_open_mesh_is_refused_when_closed_is_required() {
        let text = TETRA.replace("f 2/1 3/1/1 4//1\n", "");
        let e = closed_obj(&text).expect_err("open");
        assert_eq!(e.kind, ErrorKind::Inconsistent, "{e}");
        assert!(e.message.contains("edge"), "{e}");
        assert!(e.position.is_some());
        // Without the requirement it loads and says so.
        assert!(!obj(&text).expect("loads").closed);
        // A flipped face is not consistently oriented.
        let flipped = TETRA.replace("f 1 3 2", "f 1 2 3");
        assert_eq!(
            closed_obj(&flipped).expect_err("flipped").kind,
            ErrorKind::Inconsistent
        );
    }

    #[test]
    fn bad_objs_are_typed_errors_with_their_line() {
        let e = obj("# nothing here\n\n").expect_err("empty");
        assert_eq!(e.kind, ErrorKind::TooShort, "{e}");
        let e = obj("v 0 0 0\nv 1 0 0\n").expect_err("no faces");
        assert_eq!(e.kind, ErrorKind::TooShort, "{e}");
        let e = obj("v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n").expect_err("NaN");
        assert_eq!(e.kind, ErrorKind::NotFinite, "{e}");
        assert_eq!(e.position.map(|p| p.line), Some(2));
        let e = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").expect_err("index");
        assert_eq!(e.kind, ErrorKind::OutOfRange, "{e}");
        assert_eq!(e.position.map(|p| p.line), Some(4));
        let e = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n").expect_err("negative index");
        assert_eq!(e.kind, ErrorKind::OutOfRange, "{e}");
        let e = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 0 2\n").expect_err("zero index");
        assert_eq!(e.kind, ErrorKind::OutOfRange, "{e}");
        let e = obj("v 0 0\n").expect_err("short vertex");
        assert_eq!(e.kind, ErrorKind::TooShort, "{e}");
        let e = obj("v 0 0 zero\n").expect_err("not a number");
        assert_eq!(e.kind, ErrorKind::WrongType, "{e}");
        let e = obj("v 0 0 0\nv 1 0 0\nf 1 2\n").expect_err("short face");
        assert_eq!(e.kind, ErrorKind::TooShort, "{e}");
    }

    const PLY: &str = "ply\nformat ascii 1.0\ncomment test\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty int part\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0 4\n1 0 0 4\n0 1 0 11\n0 0 1 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n4 1 2 3 0\n";

    fn ply(text: &str) -> Result<ExternalBody, FileError> {
        parse_ply(text, Path::new("t.ply"), &LoadOptions::default())
    }

    #[test]
    fn a_ply_is_read_with_its_labels() {
        let b = ply(PLY).expect("reads");
        assert_eq!(b.vertices.len(), 4);
        assert_eq!(b.triangles.len(), 5);
        assert_eq!(
            b.vertex_part,
            Some(vec![
                Part::Pelvis,
                Part::Pelvis,
                Part::ThighLeft,
                Part::Pelvis
            ])
        );
        assert_eq!(b.triangle_part.as_ref().map(|t| t[0]), Some(Part::Pelvis));
        assert!(
            !b.closed,
            "the quad's second triangle repeats the edge 1 → 3"
        );
        // A face that repeats a vertex has a triangle without area: refused with its line.
        let e = ply(&PLY.replace("4 1 2 3 0", "4 1 2 3 1")).expect_err("zero area");
        assert_eq!(e.kind, ErrorKind::Inconsistent, "{e}");
        assert_eq!(e.position.map(|p| p.line), Some(19));
        assert!(e.message.contains("zero area"), "{e}");
        let e = ply(&PLY.replace("0 1 0 11", "0 nan 0 11")).expect_err("NaN");
        assert_eq!(e.kind, ErrorKind::NotFinite, "{e}");
        assert_eq!(e.position.map(|p| p.line), Some(14));
        let e = ply(&PLY.replace("3 0 1 3", "3 0 1 7")).expect_err("index");
        assert_eq!(e.kind, ErrorKind::OutOfRange, "{e}");
        assert_eq!(e.position.map(|p| p.line), Some(17));
        let e = ply(&PLY.replace("0 1 0 11", "0 1 0 17")).expect_err("label");
        assert_eq!(e.kind, ErrorKind::OutOfRange, "{e}");
        let e = ply(&PLY.replace("ascii", "binary_little_endian")).expect_err("binary");
        assert_eq!(e.kind, ErrorKind::Syntax, "{e}");
        let e = ply(&PLY.replace("4 1 2 3 0\n", "")).expect_err("truncated");
        assert_eq!(e.kind, ErrorKind::TooShort, "{e}");
    }

    #[test]
    fn the_mannequin_round_trips_through_obj_and_ply() {
        let m = crate::build::jis_9ar().labelled_mesh();
        let body = ExternalBody::from(&m);
        assert!(body.closed);
        let dir = std::env::temp_dir().join(format!("atelier-body-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let strict = LoadOptions {
            require_closed: true,
            scale: 1.0,
        };
        for name in ["body.obj", "body.ply"] {
            let path = dir.join(name);
            if name.ends_with("obj") {
                write_obj(&path, &body).expect("writes");
            } else {
                write_ply(&path, &body).expect("writes");
            }
            let back = load_mesh_with(&path, &strict).expect("reads back");
            assert_eq!(back, body, "{name}");
            assert_eq!(back.labelled().as_ref(), Some(&m), "{name}");
        }
        // Millimetres: the scale option.
        let mm = load_mesh_with(
            &dir.join("body.ply"),
            &LoadOptions {
                require_closed: false,
                scale: 1000.0,
            },
        )
        .expect("reads");
        assert!((mm.vertices[5] - body.vertices[5] * 1000.0).norm() < 1e-9);
        std::fs::remove_dir_all(&dir).expect("cleanup");
        let e = load_mesh(&dir.join("missing.obj")).expect_err("missing");
        assert_eq!(e.kind, ErrorKind::Io);
    }
}
