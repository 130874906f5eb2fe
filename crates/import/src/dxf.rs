//! DXF-AAMA / ASTM D6673 pattern files, read with the `dxf` crate (R12 `POLYLINE` and R2000+
//! `LWPOLYLINE` outlines alike).
//!
//! Each piece is a block. What is read, by layer (the AAMA numbers):
//! - 1 boundary (the cut line) and the piece's system text (`Piece Name:`, `Quantity:`);
//! - 14 sew line: the seam line, which becomes the panel's outline when present (a garment is
//!   simulated on its seam lines; the cut line adds the seam allowance);
//! - 2 turn points (sharp corners), 4 notches (a `LINE` whose end on the outline is the notch, or
//!   a `POINT`), 7 grain line, 8 internal lines (two legs meeting inside the piece with their
//!   other ends on the outline are a dart);
//! - 3 curve points, 5 grade reference, 6 mirror, 9 stripe, 10 plaid, 11 internal cut-outs,
//!   13 drill holes, 15 annotation: not used, listed in the warnings, as is every entity type a
//!   layer does not take and every other layer.
//!
//! Units: the header's `$INSUNITS`; when it is unset (R12 has none), the style text `Units:`
//! (`METRIC`: millimetres, `ENGLISH`: inches, ASTM D6673's convention); neither is an error.
//! `$MEASUREMENT` is not used: it says metric or imperial, not which length, and the reader
//! cannot tell it from its default when absent.

use std::path::Path;

use dxf::entities::{Entity, EntityType};
use dxf::enums::Units;
use dxf::{Block, Drawing};

use crate::error::{ImportError, PieceProblem};
use crate::piece::{Dart, Piece, dist};

/// Pieces read from a file, and what was skipped on the way.
#[derive(Clone, Debug)]
pub struct Import {
    /// The pieces, in block order.
    pub pieces: Vec<Piece>,
    /// Entities and layers not used, pieces without sew lines, notches off the outline: one
    /// line each, naming the piece and the entity.
    pub warnings: Vec<String>,
    /// Centimetres per file unit.
    pub cm_per_unit: f64,
    /// The style name (`Style Name:` text), if any.
    pub style: Option<String>,
}

impl Import {
    /// The import of `named` pieces (each with the block or group it came from): refused when
    /// two share a name (seams will name pieces) or when there are none.
    pub(crate) fn collect(
        file: &Path,
        named: Vec<(Piece, String)>,
        warnings: Vec<String>,
        cm_per_unit: f64,
        style: Option<String>,
    ) -> Result<Self, ImportError> {
        for (k, (piece, source)) in named.iter().enumerate() {
            if let Some((_, first)) = named[..k].iter().find(|(p, _)| p.name == piece.name) {
                return Err(ImportError::DuplicateName {
                    file: file.to_path_buf(),
                    name: piece.name.clone(),
                    first: first.clone(),
                    second: source.clone(),
                });
            }
        }
        if named.is_empty() {
            return Err(ImportError::NoPieces {
                file: file.to_path_buf(),
                skipped: warnings,
            });
        }
        Ok(Self {
            pieces: named.into_iter().map(|(p, _)| p).collect(),
            warnings,
            cm_per_unit,
            style,
        })
    }
}

/// Read a DXF-AAMA file.
pub fn read(path: &Path) -> Result<Import, ImportError> {
    let file = path.to_path_buf();
    let drawing = load(path)?;
    let mut warnings = Vec::new();
    let texts: Vec<String> = drawing
        .entities()
        .chain(drawing.blocks().flat_map(|b| b.entities.iter()))
        .filter_map(text_of)
        .collect();
    let cm_per_unit = units(&drawing, &texts, &file)?;
    let style = system_value(&texts, "style name");
    let mut pieces: Vec<(Piece, String)> = Vec::new();
    for block in drawing.blocks() {
        if block.name.starts_with('*') {
            continue; // *Model_Space, *Paper_Space
        }
        if let Some(piece) = read_block(block, cm_per_unit, &file, &mut warnings)? {
            pieces.push((piece, block.name.clone()));
        }
    }
    for e in drawing.entities() {
        match &e.specific {
            EntityType::Insert(i) => {
                if (i.x_scale_factor, i.y_scale_factor) != (1.0, 1.0) {
                    warnings.push(format!(
                        "INSERT {} of block {:?} is scaled ({}, {}): the piece is read as drawn in its block",
                        e.common.handle.as_string(),
                        i.name,
                        i.x_scale_factor,
                        i.y_scale_factor
                    ));
                }
            }
            EntityType::Text(_) => {}
            _ => warnings.push(format!(
                "model space: {} not used (pieces are blocks)",
                describe(e)
            )),
        }
    }
    warnings.extend(unsupported_entities(path));
    Import::collect(&file, pieces, warnings, cm_per_unit, style)
}

/// The drawing, read by the `dxf` crate. The crate panics on some hostile values (a header date
/// far out of range: `DateTime + TimeDelta overflowed`, found by the hostile-input tests); such a
/// panic is caught here, its message kept, and the file reported as unreadable. The panic hook
/// is silenced for the call so that the program's one-line error is all the user sees.
fn load(path: &Path) -> Result<Drawing, ImportError> {
    let read = || Drawing::load_file(path);
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let outcome = std::panic::catch_unwind(read);
    std::panic::set_hook(previous);
    let message = match outcome {
        Ok(Ok(drawing)) => return Ok(drawing),
        Ok(Err(e)) => e.to_string(),
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            format!("the DXF reader failed on this file ({what})")
        }
    };
    Err(ImportError::Read {
        file: path.to_path_buf(),
        message,
    })
}

/// Centimetres per unit of the file.
fn units(drawing: &Drawing, texts: &[String], file: &Path) -> Result<f64, ImportError> {
    let cm = match drawing.header.default_drawing_units {
        Units::Unitless => None,
        Units::Inches => Some(2.54),
        Units::Feet => Some(30.48),
        Units::Yards => Some(91.44),
        Units::Millimeters => Some(0.1),
        Units::Centimeters => Some(1.0),
        Units::Decimeters => Some(10.0),
        Units::Meters => Some(100.0),
        other => {
            return Err(ImportError::Units {
                file: file.to_path_buf(),
                units: format!("{other:?}"),
            });
        }
    };
    if let Some(cm) = cm {
        return Ok(cm);
    }
    match system_value(texts, "units").map(|u| u.to_ascii_uppercase()) {
        Some(u) if u.starts_with("METRIC") => Ok(0.1),
        Some(u) if u.starts_with("ENGLISH") || u.starts_with("IMPERIAL") => Ok(2.54),
        _ => Err(ImportError::NoUnits {
            file: file.to_path_buf(),
        }),
    }
}

/// The value of a system text `Key: value` (key case-insensitive).
fn system_value(texts: &[String], key: &str) -> Option<String> {
    texts.iter().find_map(|t| {
        let (k, v) = t.split_once(':')?;
        (k.trim().eq_ignore_ascii_case(key)).then(|| v.trim().to_owned())
    })
}

fn text_of(e: &Entity) -> Option<String> {
    match &e.specific {
        EntityType::Text(t) => Some(t.value.clone()),
        EntityType::MText(t) => Some(t.text.clone()),
        _ => None,
    }
}

/// `LWPOLYLINE 2F on layer 14`.
fn describe(e: &Entity) -> String {
    format!(
        "{} {} on layer {}",
        type_name(&e.specific),
        e.common.handle.as_string(),
        e.common.layer
    )
}

fn type_name(t: &EntityType) -> String {
    let known = match t {
        EntityType::Line(_) => "LINE",
        EntityType::LwPolyline(_) => "LWPOLYLINE",
        EntityType::Polyline(_) => "POLYLINE",
        EntityType::ModelPoint(_) => "POINT",
        EntityType::Text(_) => "TEXT",
        EntityType::MText(_) => "MTEXT",
        EntityType::Circle(_) => "CIRCLE",
        EntityType::Arc(_) => "ARC",
        EntityType::Ellipse(_) => "ELLIPSE",
        EntityType::Spline(_) => "SPLINE",
        EntityType::Insert(_) => "INSERT",
        EntityType::Solid(_) => "SOLID",
        _ => "",
    };
    if !known.is_empty() {
        return known.to_owned();
    }
    // Any other type: its variant's name, from the debug form (rare, so its cost is no matter).
    let debug = format!("{t:?}");
    debug
        .split('(')
        .next()
        .unwrap_or("entity")
        .to_ascii_uppercase()
}

/// The points of a polyline entity in file units, arcs (bulges) flattened; and its closed flag.
fn polyline(e: &Entity) -> Option<(Vec<[f64; 2]>, bool)> {
    let (pts, closed): (Vec<([f64; 2], f64)>, bool) = match &e.specific {
        EntityType::LwPolyline(p) => (
            p.vertices.iter().map(|v| ([v.x, v.y], v.bulge)).collect(),
            p.is_closed(),
        ),
        EntityType::Polyline(p) => (
            p.vertices()
                .map(|v| ([v.location.x, v.location.y], v.bulge))
                .collect(),
            p.is_closed(),
        ),
        _ => return None,
    };
    let mut out = Vec::with_capacity(pts.len());
    let n = pts.len();
    for k in 0..n {
        let (a, bulge) = pts[k];
        out.push(a);
        let last = k + 1 == n;
        if bulge != 0.0 && (!last || closed) {
            let b = pts[(k + 1) % n].0;
            flatten_bulge(a, b, bulge, &mut out);
        }
    }
    Some((out, closed))
}

/// The arc from `a` to `b` with DXF bulge `bulge` (tan of a quarter of the included angle,
/// positive counter-clockwise), its inner points appended to `out`, at most 1° apart.
fn flatten_bulge(a: [f64; 2], b: [f64; 2], bulge: f64, out: &mut Vec<[f64; 2]>) {
    let theta = 4.0 * bulge.atan(); // included angle, signed
    let chord = dist(a, b);
    if chord == 0.0 || !theta.is_finite() {
        return;
    }
    let radius = chord / (2.0 * (theta / 2.0).sin().abs());
    let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
    let normal = [-(b[1] - a[1]) / chord, (b[0] - a[0]) / chord];
    // Centre on the left of a→b for a counter-clockwise arc shorter than a half circle.
    let h = (radius * radius - chord * chord / 4.0).max(0.0).sqrt();
    let side = if (theta > 0.0) == (theta.abs() < std::f64::consts::PI) {
        1.0
    } else {
        -1.0
    };
    let c = [mid[0] + side * h * normal[0], mid[1] + side * h * normal[1]];
    let start = (a[1] - c[1]).atan2(a[0] - c[0]);
    let steps = (theta.abs().to_degrees().ceil() as usize).max(1);
    for k in 1..steps {
        let t = start + theta * k as f64 / steps as f64;
        out.push([c[0] + radius * t.cos(), c[1] + radius * t.sin()]);
    }
}

/// The raw content of a block, sorted by layer.
#[derive(Default)]
struct Layers<'a> {
    boundary: Vec<&'a Entity>,
    sew: Vec<&'a Entity>,
    turns: Vec<[f64; 2]>,
    notches: Vec<([f64; 2], Option<[f64; 2]>, String)>,
    grain: Vec<&'a Entity>,
    internal: Vec<(Vec<[f64; 2]>, String)>,
    texts: Vec<String>,
}

/// Read one block as a piece (`None` when it holds no outline: not a piece).
fn read_block(
    block: &Block,
    cm: f64,
    file: &Path,
    warnings: &mut Vec<String>,
) -> Result<Option<Piece>, ImportError> {
    let scale = |p: [f64; 2]| [p[0] * cm, p[1] * cm];
    let mut l = Layers::default();
    let mut unused: Vec<String> = Vec::new();
    for e in &block.entities {
        let layer = e.common.layer.trim();
        let is_poly = matches!(
            e.specific,
            EntityType::LwPolyline(_) | EntityType::Polyline(_)
        );
        match (layer, &e.specific) {
            ("1", _) if is_poly => l.boundary.push(e),
            ("14", _) if is_poly => l.sew.push(e),
            ("1" | "15", EntityType::Text(_) | EntityType::MText(_)) => {
                l.texts.extend(text_of(e));
            }
            ("2", EntityType::ModelPoint(p)) => l.turns.push(scale([p.location.x, p.location.y])),
            ("3", EntityType::ModelPoint(_)) => {}
            ("4", EntityType::Line(line)) => l.notches.push((
                scale([line.p1.x, line.p1.y]),
                Some(scale([line.p2.x, line.p2.y])),
                describe(e),
            )),
            ("4", EntityType::ModelPoint(p)) => {
                l.notches
                    .push((scale([p.location.x, p.location.y]), None, describe(e)));
            }
            ("7", EntityType::Line(_)) => l.grain.push(e),
            ("8", EntityType::Line(line)) => l.internal.push((
                vec![scale([line.p1.x, line.p1.y]), scale([line.p2.x, line.p2.y])],
                describe(e),
            )),
            ("8", _) if is_poly => {
                if let Some((pts, _)) = polyline(e) {
                    l.internal
                        .push((pts.into_iter().map(scale).collect(), describe(e)));
                }
            }
            _ => unused.push(describe(e)),
        }
    }
    if l.boundary.is_empty() && l.sew.is_empty() {
        return Ok(None);
    }
    let name = system_value(&l.texts, "piece name").unwrap_or_else(|| block.name.clone());
    for u in unused {
        warnings.push(format!("piece {name:?}: {u} not used"));
    }
    let piece_error = |entity: String, problem: PieceProblem| ImportError::Piece {
        file: file.to_path_buf(),
        piece: name.clone(),
        entity,
        problem,
    };
    let (outline_entity, source) = match (l.sew.first(), l.boundary.first()) {
        (Some(s), _) => (*s, "sew line (layer 14)"),
        (None, Some(b)) => {
            warnings.push(format!(
                "piece {name:?}: no sew line (layer 14); its cut line {} is used as the seam line, seam allowance included",
                describe(b)
            ));
            (*b, "cut line (layer 1)")
        }
        (None, None) => unreachable!("checked above"),
    };
    for extra in l.sew.iter().skip(1).chain(l.boundary.iter().skip(1)) {
        warnings.push(format!(
            "piece {name:?}: a second outline {} not used",
            describe(extra)
        ));
    }
    let (pts, closed) = polyline(outline_entity).expect("a polyline");
    let mut piece = Piece::new(&name, pts.into_iter().map(scale).collect(), closed, source)
        .map_err(|p| piece_error(describe(outline_entity), p))?;
    if let Some(q) = system_value(&l.texts, "quantity") {
        match q.parse::<u32>() {
            Ok(q) if q > 0 => piece.quantity = q,
            _ => warnings.push(format!(
                "piece {name:?}: Quantity {q:?} is not a count; 1 assumed"
            )),
        }
    }
    for t in l.turns {
        match piece.vertex_at(t) {
            Some(k) => piece.turns.push(k),
            None => warnings.push(format!(
                "piece {name:?}: turn point ({:.2}, {:.2}) cm is not on the outline; not used",
                t[0], t[1]
            )),
        }
    }
    for (a, b, what) in l.notches {
        // A slit notch's end on the outline is the notch.
        let on = [Some(a), b]
            .into_iter()
            .flatten()
            .find_map(|p| piece.vertex_at(p));
        match on {
            Some(k) => piece.notches.push(k),
            None => warnings.push(format!(
                "piece {name:?}: notch {what} does not touch the outline; not used"
            )),
        }
    }
    if let Some(g) = l.grain.first() {
        if let EntityType::Line(line) = &g.specific {
            piece.grain = Some((scale([line.p1.x, line.p1.y]), scale([line.p2.x, line.p2.y])));
        }
        for extra in l.grain.iter().skip(1) {
            warnings.push(format!(
                "piece {name:?}: a second grain line {} not used",
                describe(extra)
            ));
        }
    } else {
        warnings.push(format!(
            "piece {name:?}: no grain line (layer 7); the warp is taken along +y"
        ));
    }
    darts_and_lines(&mut piece, l.internal, warnings);
    piece.turns.sort_unstable();
    piece.turns.dedup();
    piece.notches.sort_unstable();
    piece.notches.dedup();
    Ok(Some(piece))
}

/// Internal lines: pairs of straight legs sharing an end inside the piece whose other ends lie
/// on the outline are darts (apex inside); the rest are kept as drawn lines.
fn darts_and_lines(
    piece: &mut Piece,
    lines: Vec<(Vec<[f64; 2]>, String)>,
    warnings: &mut Vec<String>,
) {
    let mut used = vec![false; lines.len()];
    for i in 0..lines.len() {
        for j in i + 1..lines.len() {
            if used[i] || used[j] || lines[i].0.len() != 2 || lines[j].0.len() != 2 {
                continue;
            }
            let (a, b) = (&lines[i].0, &lines[j].0);
            // The shared end (the apex) and the two outer ends.
            let shared = [(0, 0), (0, 1), (1, 0), (1, 1)]
                .into_iter()
                .find(|&(p, q)| dist(a[p], b[q]) < 1e-3);
            let Some((p, q)) = shared else { continue };
            let apex = a[p];
            if !piece.contains(apex) {
                continue;
            }
            let (ea, eb) = (a[1 - p], b[1 - q]);
            let (Some(_), Some(_)) = (piece.vertex_at(ea), piece.vertex_at(eb)) else {
                continue;
            };
            // Both ends inserted: look them up again (the second insertion may move the first).
            let (ka, kb) = (
                piece.vertex_at(ea).expect("on the outline"),
                piece.vertex_at(eb).expect("on the outline"),
            );
            // The opening runs counter-clockwise along the outline, the short way.
            let (from, to) = if piece.length_between(ka, kb) <= piece.length_between(kb, ka) {
                (ka, kb)
            } else {
                (kb, ka)
            };
            piece.darts.push(Dart { from, to, apex });
            used[i] = true;
            used[j] = true;
        }
    }
    for (k, (pts, what)) in lines.into_iter().enumerate() {
        if !used[k] {
            warnings.push(format!(
                "piece {:?}: internal line {what} is not a dart leg; drawn only",
                piece.name
            ));
            piece.internal.push(pts);
        }
    }
}

/// Entity types the `dxf` crate reads (its `EntityType`s); it skips every other type without a
/// trace (a `HATCH`, for one), so [`unsupported_entities`] lists those from the file itself.
const READ_BY_THE_CRATE: &[&str] = &[
    "3DFACE",
    "3DSOLID",
    "ACAD_PROXY_ENTITY",
    "ARC",
    "ARCALIGNEDTEXT",
    "ATTDEF",
    "ATTRIB",
    "BODY",
    "CIRCLE",
    "DIMENSION",
    "ELLIPSE",
    "HELIX",
    "IMAGE",
    "INSERT",
    "LEADER",
    "LIGHT",
    "LINE",
    "3DLINE",
    "LWPOLYLINE",
    "MLINE",
    "MTEXT",
    "OLEFRAME",
    "OLE2FRAME",
    "POINT",
    "POLYLINE",
    "RAY",
    "REGION",
    "RTEXT",
    "SECTION",
    "SEQEND",
    "SHAPE",
    "SOLID",
    "SPLINE",
    "TEXT",
    "TOLERANCE",
    "TRACE",
    "DGNUNDERLAY",
    "DWFUNDERLAY",
    "PDFUNDERLAY",
    "VERTEX",
    "WIPEOUT",
    "XLINE",
];

/// The entities of the BLOCKS and ENTITIES sections whose type the `dxf` crate does not read,
/// counted by type from the file's group codes (ASCII DXF: a code line, then a value line); one
/// warning per type. Not a DXF reader: it only looks at `0` codes and section names.
fn unsupported_entities(path: &Path) -> Vec<String> {
    let Ok(bytes) = std::fs::read(path) else {
        return Vec::new();
    };
    let text = String::from_utf8_lossy(&bytes);
    let mut lines = text.lines().map(str::trim);
    let (mut section, mut after_section) = (String::new(), false);
    let mut counts: Vec<(String, usize)> = Vec::new();
    while let (Some(code), Some(value)) = (lines.next(), lines.next()) {
        match code {
            "0" => {
                after_section = value == "SECTION";
                let in_geometry = section == "BLOCKS" || section == "ENTITIES";
                let structural = matches!(value, "SECTION" | "ENDSEC" | "BLOCK" | "ENDBLK" | "EOF");
                if in_geometry && !structural && !READ_BY_THE_CRATE.contains(&value) {
                    match counts.iter_mut().find(|(t, _)| t == value) {
                        Some((_, n)) => *n += 1,
                        None => counts.push((value.to_owned(), 1)),
                    }
                }
            }
            "2" if after_section => {
                section = value.to_owned();
                after_section = false;
            }
            _ => {}
        }
    }
    counts
        .into_iter()
        .map(|(t, n)| {
            format!(
                "{n} {t} entit{} not read (the DXF reader does not support the type)",
                if n == 1 { "y" } else { "ies" }
            )
        })
        .collect()
}
