//! FreeSewing's SVG output (`@freesewing/core`'s renderer; `fixtures/patterns/freesewing/`),
//! read with `roxmltree` (XML) and `svgtypes` (path data as absolute segments, transforms).
//!
//! What is read, as FreeSewing 4 writes it (the fixture README has excerpts):
//! - units: the root's `width` in `mm`, `cm` or `in` over its `viewBox` width (user units
//!   without a physical size are an error: a pattern's size is never guessed);
//! - a part: a `<g>` whose `id` holds `-part-` (`fs-stack-P-part-P`), named by what follows it,
//!   every `transform` from the root down applied;
//! - its seam line: the `<path>` whose class is exactly `fabric` (`fabric sa` is the cut line
//!   with the seam allowance, `fabric stroke-sm` a fold line drawn on the piece); Béziers are
//!   flattened to within [`FLATNESS`] of the curve;
//! - the grain line: a path with a `grainlineFrom` marker, from its first point to its last (or
//!   the fold, when its text says "cut on fold and grainline");
//! - the fold: a path with a `cutonfoldFrom` marker; a part cut on the fold is drawn as its half,
//!   and is read as the whole piece, mirrored across the fold line;
//! - notches: `<use>` of `#notch` or `#bnotch` at its x, y;
//! - the title: the `<text>` whose class holds `text-lg` and `font-bold`.
//!
//! Darts drawn as V notches in the seam line are closed: the outline runs straight across the
//! opening, and the V becomes an atelier dart (`Piece::close_v_darts`; a curved leg is taken
//! straight, with a warning). Everything else in a part (the cut line, annotations, the logo)
//! is not used.

use std::path::Path;

use roxmltree::{Document, Node};
use svgtypes::{SimplePathSegment, SimplifyingPathParser, Transform};

use crate::dxf::Import;
use crate::error::{ImportError, PieceProblem};
use crate::piece::{Piece, dist};

/// Largest distance of the flattened polyline from a Bézier curve, in the file's user units
/// (mm for FreeSewing: 1 µm).
pub const FLATNESS: f64 = 0.001;

/// A vertex where the seam line turns back (clockwise) by more than this (degrees) is a dart's
/// tip: Bella's waist dart turns it by 102°, its side dart by 137°, Penelope's by 176°; the
/// sharpest other reflex corner of the fixtures (Penelope's vent) by 45°.
pub const TIP_DEG: f64 = 95.0;

/// Walking a dart's leg from its tip, the first vertex that turns by more than this (degrees)
/// is the opening's end.
pub const LEG_DEG: f64 = 30.0;

/// Read a FreeSewing SVG file, its V darts closed ([`read_with`]).
pub fn read(path: &Path) -> Result<Import, ImportError> {
    read_with(path, true)
}

/// Read a FreeSewing SVG file; `close_darts`: turn darts drawn as V notches into darts (else
/// the outline is kept as drawn).
pub fn read_with(path: &Path, close_darts: bool) -> Result<Import, ImportError> {
    let file = path.to_path_buf();
    let fail = |message: String| ImportError::Read {
        file: file.clone(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let doc = Document::parse(&text).map_err(|e| fail(format!("not SVG (XML): {e}")))?;
    let root = doc.root_element();
    if root.tag_name().name() != "svg" {
        return Err(fail(format!(
            "not SVG: the root element is <{}>",
            root.tag_name().name()
        )));
    }
    let cm = units(root).ok_or_else(|| ImportError::NoUnits { file: file.clone() })?;
    let mut warnings = Vec::new();
    let mut pieces: Vec<(Piece, String)> = Vec::new();
    let mut parts = Vec::new();
    collect_parts(root, Transform::default(), &mut parts);
    for (node, transform) in parts {
        let id = node.attribute("id").unwrap_or_default();
        let name = id.split("-part-").nth(1).unwrap_or(id).to_owned();
        let piece = read_part(node, transform, cm, &name, close_darts, &mut warnings).map_err(
            |(entity, problem)| ImportError::Piece {
                file: file.clone(),
                piece: name.clone(),
                entity,
                problem,
            },
        )?;
        pieces.push((piece, id.to_owned()));
    }
    let style = root
        .attribute(("http://freesewing.org/namespaces/freesewing", "freesewing"))
        .or_else(|| root.attribute("freesewing"))
        .map(|v| format!("FreeSewing {v}"));
    Import::collect(&file, pieces, warnings, cm, style)
}

/// Centimetres per user unit: the root's width with its unit over the viewBox's width.
fn units(root: Node<'_, '_>) -> Option<f64> {
    let width = root.attribute("width")?.trim();
    let (number, unit) = width.split_at(width.find(|c: char| c.is_ascii_alphabetic())?);
    let number: f64 = number.trim().parse().ok()?;
    let cm = match unit {
        "mm" => 0.1,
        "cm" => 1.0,
        "in" => 2.54,
        _ => return None,
    };
    let view_width = root
        .attribute("viewBox")
        .and_then(|v| v.split([' ', ',']).filter(|s| !s.is_empty()).nth(2))
        .and_then(|w| w.parse::<f64>().ok())
        .unwrap_or(number);
    (number > 0.0 && view_width > 0.0 && number.is_finite() && view_width.is_finite())
        .then(|| cm * number / view_width)
}

/// The element's own transform (identity when it has none or it does not parse).
fn own_transform(node: Node<'_, '_>) -> Transform {
    node.attribute("transform")
        .and_then(|t| t.parse::<Transform>().ok())
        .unwrap_or_default()
}

/// `outer` after `inner`: a point is mapped by `inner`, then by `outer`.
fn then(outer: Transform, inner: Transform) -> Transform {
    Transform::new(
        outer.a * inner.a + outer.c * inner.b,
        outer.b * inner.a + outer.d * inner.b,
        outer.a * inner.c + outer.c * inner.d,
        outer.b * inner.c + outer.d * inner.d,
        outer.a * inner.e + outer.c * inner.f + outer.e,
        outer.b * inner.e + outer.d * inner.f + outer.f,
    )
}

fn apply(t: &Transform, x: f64, y: f64) -> [f64; 2] {
    [t.a * x + t.c * y + t.e, t.b * x + t.d * y + t.f]
}

/// Every part group below `node`, with the transform from its coordinates to the root's.
fn collect_parts<'a, 'i>(
    node: Node<'a, 'i>,
    parent: Transform,
    out: &mut Vec<(Node<'a, 'i>, Transform)>,
) {
    for child in node.children().filter(Node::is_element) {
        let name = child.tag_name().name();
        if matches!(name, "defs" | "style" | "symbol" | "metadata" | "title") {
            continue;
        }
        let t = then(parent, own_transform(child));
        if name == "g"
            && child
                .attribute("id")
                .is_some_and(|id| id.contains("-part-"))
        {
            out.push((child, t));
        } else {
            collect_parts(child, t, out);
        }
    }
}

/// A path's points in cm in the pattern frame (y up), every subpath in turn; and whether the
/// first subpath was closed by `z`.
fn path_points(d: &str, t: &Transform, cm: f64) -> Result<(Vec<[f64; 2]>, bool), String> {
    let to_cm = |p: [f64; 2]| {
        let q = apply(t, p[0], p[1]);
        [q[0] * cm, -q[1] * cm]
    };
    let mut pts: Vec<[f64; 2]> = Vec::new();
    let mut at = [0.0, 0.0];
    let mut closed = false;
    let mut subpaths = 0;
    for segment in SimplifyingPathParser::from(d) {
        match segment.map_err(|e| format!("path data: {e}"))? {
            SimplePathSegment::MoveTo { x, y } => {
                subpaths += 1;
                if subpaths > 1 {
                    break; // the outline is the first subpath
                }
                at = [x, y];
                pts.push(to_cm(at));
            }
            SimplePathSegment::LineTo { x, y } => {
                at = [x, y];
                pts.push(to_cm(at));
            }
            SimplePathSegment::CurveTo {
                x1,
                y1,
                x2,
                y2,
                x,
                y,
            } => {
                let c = [at, [x1, y1], [x2, y2], [x, y]];
                // Uniform steps in t: the polyline stays within |B''|max / (8 n²) of the curve,
                // and |B''| ≤ 6·max|second difference of the control points|.
                let second = |i: usize| {
                    let q = [
                        c[i][0] - 2.0 * c[i + 1][0] + c[i + 2][0],
                        c[i][1] - 2.0 * c[i + 1][1] + c[i + 2][1],
                    ];
                    q[0].hypot(q[1])
                };
                let m = second(0).max(second(1));
                let n = ((0.75 * m / FLATNESS).sqrt().ceil() as usize).clamp(1, 4096);
                for k in 1..=n {
                    let s = k as f64 / n as f64;
                    let r = 1.0 - s;
                    let w = [r * r * r, 3.0 * r * r * s, 3.0 * r * s * s, s * s * s];
                    let p = [
                        w[0] * c[0][0] + w[1] * c[1][0] + w[2] * c[2][0] + w[3] * c[3][0],
                        w[0] * c[0][1] + w[1] * c[1][1] + w[2] * c[2][1] + w[3] * c[3][1],
                    ];
                    pts.push(to_cm(p));
                }
                at = [x, y];
            }
            SimplePathSegment::Quadratic { x1, y1, x, y } => {
                let n = 32;
                for k in 1..=n {
                    let s = k as f64 / n as f64;
                    let r = 1.0 - s;
                    let p = [
                        r * r * at[0] + 2.0 * r * s * x1 + s * s * x,
                        r * r * at[1] + 2.0 * r * s * y1 + s * s * y,
                    ];
                    pts.push(to_cm(p));
                }
                at = [x, y];
            }
            SimplePathSegment::ClosePath => {
                closed = true;
            }
        }
    }
    Ok((pts, closed))
}

fn classes<'a>(node: Node<'a, '_>) -> Vec<&'a str> {
    node.attribute("class")
        .unwrap_or_default()
        .split_whitespace()
        .collect()
}

fn describe(node: Node<'_, '_>) -> String {
    format!(
        "<{}> {}",
        node.tag_name().name(),
        node.attribute("id")
            .map_or("(no id)".to_owned(), |i| format!("id {i}"))
    )
}

/// Read one part group.
fn read_part(
    group: Node<'_, '_>,
    group_transform: Transform,
    cm: f64,
    name: &str,
    close_darts: bool,
    warnings: &mut Vec<String>,
) -> Result<Piece, (String, PieceProblem)> {
    let mut seam: Option<(Vec<[f64; 2]>, bool, String)> = None;
    let mut grain = None;
    let mut fold = None;
    let mut fold_grain = None;
    let mut notches = Vec::new();
    let mut title = None;
    let mut stack = vec![(group, group_transform)];
    while let Some((node, t)) = stack.pop() {
        for child in node.children().filter(Node::is_element) {
            let ct = then(t, own_transform(child));
            match child.tag_name().name() {
                "g" => stack.push((child, ct)),
                "path" => {
                    let Some(d) = child.attribute("d") else {
                        continue;
                    };
                    let marker = child.attribute("marker-start").unwrap_or_default();
                    let is_seam = classes(child) == ["fabric"];
                    if !(is_seam || marker.contains("grainline") || marker.contains("cutonfold")) {
                        continue;
                    }
                    let (pts, closed) = path_points(d, &ct, cm)
                        .map_err(|e| (describe(child), PieceProblem::Sides(e)))?;
                    if is_seam {
                        if seam.is_some() {
                            warnings.push(format!(
                                "piece {name:?}: a second seam line {} not used",
                                describe(child)
                            ));
                        } else {
                            seam = Some((pts, closed, describe(child)));
                        }
                    } else if let (Some(&a), Some(&b)) = (pts.first(), pts.last()) {
                        if marker.contains("grainline") {
                            grain = Some((a, b));
                        } else {
                            fold = Some((a, b));
                            // FreeSewing's "cut on fold and grainline": the grain runs along it.
                            if child
                                .attribute("data-text")
                                .is_some_and(|t| t.to_ascii_lowercase().contains("grainline"))
                            {
                                fold_grain = Some((a, b));
                            }
                        }
                    }
                }
                "use" => {
                    let href = child
                        .attribute(("http://www.w3.org/1999/xlink", "href"))
                        .or_else(|| child.attribute("href"))
                        .unwrap_or_default();
                    if href == "#notch" || href == "#bnotch" {
                        let num = |a: &str| {
                            child
                                .attribute(a)
                                .and_then(|v| v.parse::<f64>().ok())
                                .unwrap_or(0.0)
                        };
                        let q = apply(&ct, num("x"), num("y"));
                        notches.push(([q[0] * cm, -q[1] * cm], describe(child)));
                    }
                }
                "text" => {
                    let c = classes(child);
                    if c.contains(&"text-lg") && c.contains(&"font-bold") {
                        let t: String = child
                            .descendants()
                            .filter(|n| n.is_text())
                            .filter_map(|n| n.text())
                            .collect();
                        title.get_or_insert(t.trim().to_owned());
                    }
                }
                _ => {}
            }
        }
    }
    let Some((mut outline, closed, entity)) = seam else {
        return Err((
            format!("part group {}", describe(group)),
            PieceProblem::Sides("no seam line (a path of class `fabric`)".into()),
        ));
    };
    if let Some((a, b)) = fold {
        outline =
            unfold(&outline, a, b).map_err(|why| (entity.clone(), PieceProblem::Sides(why)))?;
        // The notches of the half, and their mirror images off the fold.
        let mirrored: Vec<_> = notches
            .iter()
            .filter(|(p, _)| line_distance(*p, a, b) > 0.05)
            .map(|(p, w)| (reflect(*p, a, b), format!("{w} (mirrored)")))
            .collect();
        notches.extend(mirrored);
    }
    // An unfolded outline is closed by construction.
    let closed = closed || fold.is_some();
    let mut piece = Piece::new(name, outline, closed, "seam line (class `fabric`)")
        .map_err(|p| (entity.clone(), p))?;
    let darts = if close_darts {
        piece.close_v_darts(TIP_DEG, LEG_DEG)
    } else {
        0
    };
    if darts > 0 {
        warnings.push(format!(
            "piece {name:?}: {darts} dart(s) drawn as V notches in the seam line closed; their legs are taken straight"
        ));
    }
    if let Some(t) = title.filter(|t| !t.is_empty() && !name.ends_with(t.as_str())) {
        warnings.push(format!("piece {name:?}: titled {t:?}"));
    }
    piece.grain = grain.or(fold_grain);
    if piece.grain.is_none() {
        warnings.push(format!(
            "piece {name:?}: no grain line; the warp is taken along +y"
        ));
    }
    for (p, what) in notches {
        match piece.vertex_at(p) {
            Some(k) => piece.notches.push(k),
            None => warnings.push(format!(
                "piece {name:?}: notch {what} at ({:.2}, {:.2}) cm is not on the seam line; not used",
                p[0], p[1]
            )),
        }
    }
    piece.notches.sort_unstable();
    piece.notches.dedup();
    Ok(piece)
}

fn line_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (ux, uy) = (b[0] - a[0], b[1] - a[1]);
    let len = ux.hypot(uy);
    if len == 0.0 {
        return dist(p, a);
    }
    ((p[0] - a[0]) * uy - (p[1] - a[1]) * ux).abs() / len
}

fn reflect(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let (ux, uy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = ux * ux + uy * uy;
    let s = ((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / len2;
    let foot = [a[0] + s * ux, a[1] + s * uy];
    [2.0 * foot[0] - p[0], 2.0 * foot[1] - p[1]]
}

/// The whole piece from its half cut on the fold `a`–`b`: the outline's run of vertices on the
/// fold line is replaced by the half mirrored across it.
fn unfold(half: &[[f64; 2]], a: [f64; 2], b: [f64; 2]) -> Result<Vec<[f64; 2]>, String> {
    let mut pts = half.to_vec();
    if pts.len() > 1 && dist(pts[0], pts[pts.len() - 1]) < 1e-9 {
        pts.pop();
    }
    let n = pts.len();
    let on: Vec<bool> = pts.iter().map(|&p| line_distance(p, a, b) < 0.05).collect();
    let count = on.iter().filter(|&&o| o).count();
    if count < 2 {
        return Err(format!(
            "the fold line touches {count} vertex of the seam line (two or more needed)"
        ));
    }
    // The chain off the fold: from the last vertex of the on-fold run to the first, forwards.
    let start = (0..n)
        .find(|&k| on[k] && !on[(k + 1) % n])
        .ok_or("the seam line lies on the fold line")?;
    let mut chain = vec![pts[start]];
    let mut k = (start + 1) % n;
    while !on[k] {
        chain.push(pts[k]);
        k = (k + 1) % n;
    }
    chain.push(pts[k]);
    if chain.len() + count - 2 != n {
        return Err("the seam line meets the fold line in more than one run".into());
    }
    let mut whole = chain.clone();
    whole.extend(
        chain[1..chain.len() - 1]
            .iter()
            .rev()
            .map(|&p| reflect(p, a, b)),
    );
    Ok(whole)
}
