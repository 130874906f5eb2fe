//! Checks and repair of a scanned mesh: indices, finite coordinates, areas, the height (units),
//! non-manifold edges, a consistent orientation, small holes closed, debris dropped, the
//! inside-out case turned outward.

use std::collections::HashMap;

use crate::build::{first_open_edge, signed_volume};
use crate::model::V3;

use super::{ScanError, ScanOptions};

/// A hole that was closed.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedHole {
    /// Vertices on its border.
    pub vertices: usize,
    /// Length of its border, m.
    pub perimeter: f64,
    /// Mean of its border's vertices, m.
    pub centroid: V3,
    /// Triangles added to close it (`vertices − 2`).
    pub triangles_added: usize,
}

/// What the repair found and did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Repair {
    /// Holes closed, in the order their borders were found.
    pub holes: Vec<ClosedHole>,
    /// Triangles turned over to agree with their neighbours (the smaller side of each
    /// connected piece).
    pub reoriented_triangles: usize,
    /// Connected pieces found inside out (negative volume) and turned over.
    pub inside_out_pieces: usize,
    /// Connected pieces dropped as debris (area below [`ScanOptions::min_piece_area`]).
    pub dropped_pieces: usize,
    /// Triangles dropped with them.
    pub dropped_triangles: usize,
    /// Connected pieces kept.
    pub pieces: usize,
    /// Height (highest − lowest y), m.
    pub height: f64,
    /// Enclosed volume after the repair, m³.
    pub volume: f64,
    /// Plain-language notes (inside-out pieces turned, debris dropped, triangles reoriented).
    pub warnings: Vec<String>,
}

/// The mesh after repair: closed, every edge in two triangles running it in opposite
/// directions, every piece enclosing a positive volume. Vertices keep their indices (unused
/// ones stay).
pub(crate) struct Repaired {
    pub vertices: Vec<V3>,
    pub triangles: Vec<[u32; 3]>,
    pub repair: Repair,
}

/// Units a height could have been written in, with the factor to metres (the last three: a
/// file in metres whose coordinates were scaled down, e.g. loaded with scale 0.001 twice).
const UNITS: [(&str, f64); 6] = [
    ("mm", 0.001),
    ("cm", 0.01),
    ("dm", 0.1),
    ("m scaled down 10 times", 10.0),
    ("m scaled down 100 times", 100.0),
    ("m scaled down 1000 times", 1000.0),
];

/// A repaired mesh on its own: vertices, triangles, the report.
pub type RepairedMesh = (Vec<V3>, Vec<[u32; 3]>, Repair);

/// Check and repair a mesh on its own: the vertices (unchanged), the triangles (turned to one
/// orientation, debris dropped, holes closed, turned outward) and the report. The checks, in
/// order: triangles present, finite coordinates, indices in range, no zero-area triangle, a
/// plausible height ([`ScanOptions::min_height`]…[`ScanOptions::max_height`]), no edge in three
/// or more triangles, an orientable surface, holes no larger than
/// [`ScanOptions::max_hole_perimeter`], no hole border through a vertex twice.
pub fn check_and_repair(
    vertices: &[V3],
    triangles: &[[u32; 3]],
    opts: &ScanOptions,
) -> Result<RepairedMesh, ScanError> {
    let r = repair(vertices.to_vec(), triangles.to_vec(), opts)?;
    Ok((r.vertices, r.triangles, r.repair))
}

/// Check and repair a mesh; see [`check_and_repair`].
pub(crate) fn repair(
    vertices: Vec<V3>,
    triangles: Vec<[u32; 3]>,
    opts: &ScanOptions,
) -> Result<Repaired, ScanError> {
    if triangles.is_empty() || vertices.is_empty() {
        return Err(ScanError::Empty);
    }
    if let Some(k) = vertices
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(ScanError::NotFinite { vertex: k });
    }
    for (i, t) in triangles.iter().enumerate() {
        if let Some(&v) = t.iter().find(|&&v| v as usize >= vertices.len()) {
            return Err(ScanError::IndexOutOfRange {
                triangle: i,
                vertex: v,
                count: vertices.len(),
            });
        }
        let [a, b, c] = t.map(|k| vertices[k as usize]);
        let scale = (b - a)
            .norm_squared()
            .max((c - a).norm_squared())
            .max((c - b).norm_squared());
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || scale == 0.0 {
            return Err(ScanError::ZeroArea {
                triangle: i,
                vertices: *t,
            });
        }
        if (b - a).cross(&(c - a)).norm() <= 1e-12 * scale {
            return Err(ScanError::ZeroArea {
                triangle: i,
                vertices: *t,
            });
        }
    }
    // Units first: every length limit below is in metres.
    let height = {
        let used = triangles.iter().flatten().map(|&k| vertices[k as usize].y);
        let (lo, hi) = used.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
            (lo.min(y), hi.max(y))
        });
        hi - lo
    };
    if !(opts.min_height..=opts.max_height).contains(&height) {
        let (unit, scale) = UNITS
            .iter()
            .find(|(_, f)| (opts.min_height..=opts.max_height).contains(&(height * f)))
            .map_or((None, None), |&(u, f)| (Some(u), Some(f)));
        return Err(ScanError::Height {
            height,
            min: opts.min_height,
            max: opts.max_height,
            unit,
            scale,
        });
    }

    let mut triangles = triangles;
    let mut report = Repair {
        height,
        ..Repair::default()
    };
    let edges = edge_map(&triangles);
    if let Some((&(a, b), ts)) = edges
        .iter()
        .filter(|(_, ts)| ts.len() > 2)
        .min_by_key(|&(&e, _)| e)
    {
        return Err(ScanError::NonManifoldEdge {
            vertices: [a, b],
            triangles: ts.len(),
            at: (vertices[a as usize] + vertices[b as usize]) / 2.0,
        });
    }
    // Connected pieces (through shared edges) and a consistent orientation in each.
    let (piece, pieces, flips) = orient(&triangles, &edges)?;
    for (t, f) in triangles.iter_mut().zip(&flips) {
        if *f {
            t.swap(1, 2);
        }
    }
    report.reoriented_triangles = flips.iter().filter(|&&f| f).count();
    if report.reoriented_triangles > 0 {
        report.warnings.push(format!(
            "{} triangles turned over to agree with their neighbours",
            report.reoriented_triangles
        ));
    }
    // Debris: pieces with a small share of the area.
    let area = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|k| vertices[k as usize]);
        0.5 * (b - a).cross(&(c - a)).norm()
    };
    let mut piece_area = vec![0.0; pieces];
    for (t, &p) in triangles.iter().zip(&piece) {
        piece_area[p] += area(t);
    }
    let total: f64 = piece_area.iter().sum();
    let keep: Vec<bool> = piece_area
        .iter()
        .map(|&a| a >= opts.min_piece_area * total)
        .collect();
    report.dropped_pieces = keep.iter().filter(|&&k| !k).count();
    report.pieces = pieces - report.dropped_pieces;
    let mut kept_piece = Vec::with_capacity(triangles.len());
    let mut kept = Vec::with_capacity(triangles.len());
    for (t, &p) in triangles.iter().zip(&piece) {
        if keep[p] {
            kept.push(*t);
            kept_piece.push(p);
        }
    }
    report.dropped_triangles = triangles.len() - kept.len();
    if report.dropped_pieces > 0 {
        report.warnings.push(format!(
            "{} small pieces ({} triangles, each under {:.1} % of the area) dropped",
            report.dropped_pieces,
            report.dropped_triangles,
            100.0 * opts.min_piece_area
        ));
    }
    triangles = kept;
    let mut piece = kept_piece;

    // Holes: borders traced along the open edges, closed when small.
    for border in borders(&triangles, &vertices)? {
        let pts: Vec<V3> = border.iter().map(|&k| vertices[k as usize]).collect();
        let perimeter: f64 = (0..pts.len())
            .map(|k| (pts[(k + 1) % pts.len()] - pts[k]).norm())
            .sum();
        let centroid = pts.iter().sum::<V3>() / pts.len() as f64;
        if perimeter > opts.max_hole_perimeter {
            return Err(ScanError::HoleTooLarge {
                perimeter,
                vertices: border.len(),
                centroid,
                limit: opts.max_hole_perimeter,
            });
        }
        let fill = fill_hole(&border, &vertices);
        // The piece the hole belongs to: that of a triangle using its first vertex.
        let p = triangles
            .iter()
            .position(|t| t.contains(&border[0]))
            .map_or(0, |i| piece[i]);
        report.holes.push(ClosedHole {
            vertices: border.len(),
            perimeter,
            centroid,
            triangles_added: fill.len(),
        });
        piece.extend(std::iter::repeat_n(p, fill.len()));
        triangles.extend(fill);
    }
    if let Some((_, [a, b])) = first_open_edge(&triangles) {
        return Err(ScanError::NotClosed {
            vertices: [a, b],
            at: (vertices[a as usize] + vertices[b as usize]) / 2.0,
        });
    }
    // Inside out: pieces of negative volume are turned over.
    let mut vol = vec![0.0; pieces];
    for (t, &p) in triangles.iter().zip(&piece) {
        vol[p] += signed_volume(&vertices, std::slice::from_ref(t));
    }
    report.inside_out_pieces = vol.iter().filter(|&&v| v < 0.0).count();
    if report.inside_out_pieces > 0 {
        for (t, &p) in triangles.iter_mut().zip(&piece) {
            if vol[p] < 0.0 {
                t.swap(1, 2);
            }
        }
        report.warnings.push(format!(
            "{} of {} pieces were inside out (negative volume) and were turned over",
            report.inside_out_pieces, report.pieces
        ));
    }
    report.volume = signed_volume(&vertices, &triangles);
    Ok(Repaired {
        vertices,
        triangles,
        repair: report,
    })
}

/// Undirected edge (low, high) → the triangles using it.
fn edge_map(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), Vec<u32>> {
    let mut m: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(3 * triangles.len() / 2);
    for (i, t) in triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            m.entry((a.min(b), a.max(b))).or_default().push(i as u32);
        }
    }
    m
}

/// Whether triangle `t` runs the edge a → b.
fn runs(t: &[u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|e| t[e] == a && t[(e + 1) % 3] == b)
}

/// Connected pieces through manifold edges, and which triangles to turn over so that each
/// piece is consistently oriented (the smaller side of each piece is turned).
fn orient(
    triangles: &[[u32; 3]],
    edges: &HashMap<(u32, u32), Vec<u32>>,
) -> Result<(Vec<usize>, usize, Vec<bool>), ScanError> {
    let n = triangles.len();
    let mut piece = vec![usize::MAX; n];
    let mut flip = vec![false; n];
    let mut pieces = 0;
    let mut stack = Vec::new();
    for seed in 0..n {
        if piece[seed] != usize::MAX {
            continue;
        }
        let mut members = vec![seed];
        piece[seed] = pieces;
        stack.push(seed);
        while let Some(i) = stack.pop() {
            let t = triangles[i];
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                // The direction triangle i runs a → b in, once its flip is applied.
                for &j in &edges[&(a.min(b), a.max(b))] {
                    let j = j as usize;
                    if j == i {
                        continue;
                    }
                    // j must run b → a (after flips) to agree with i.
                    let same = runs(&triangles[j], a, b);
                    let want_flip = flip[i] ^ same;
                    if piece[j] == usize::MAX {
                        piece[j] = pieces;
                        flip[j] = want_flip;
                        members.push(j);
                        stack.push(j);
                    } else if flip[j] != want_flip {
                        return Err(ScanError::NonOrientable { triangle: j });
                    }
                }
            }
        }
        let flipped = members.iter().filter(|&&i| flip[i]).count();
        if 2 * flipped > members.len() {
            for &i in &members {
                flip[i] = !flip[i];
            }
        }
        pieces += 1;
    }
    Ok((piece, pieces, flip))
}

/// The borders of the mesh: loops of directed open edges (a → b runs along the mesh's own
/// triangles), as vertex lists in that direction.
pub(crate) fn borders(triangles: &[[u32; 3]], vertices: &[V3]) -> Result<Vec<Vec<u32>>, ScanError> {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * triangles.len());
    for t in triangles {
        for e in 0..3 {
            *directed.entry((t[e], t[(e + 1) % 3])).or_insert(0) += 1;
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    let mut open: Vec<(u32, u32)> = directed
        .keys()
        .filter(|&&(a, b)| !directed.contains_key(&(b, a)))
        .copied()
        .collect();
    open.sort_unstable();
    for &(a, b) in &open {
        if next.insert(a, b).is_some() {
            return Err(ScanError::PinchedBorder {
                vertex: a,
                at: vertices[a as usize],
            });
        }
    }
    let mut loops = Vec::new();
    let mut done: std::collections::HashSet<u32> = std::collections::HashSet::new();
    for &(start, _) in &open {
        if done.contains(&start) {
            continue;
        }
        let mut lp = vec![start];
        done.insert(start);
        let mut v = next[&start];
        while v != start {
            if !done.insert(v) {
                return Err(ScanError::PinchedBorder {
                    vertex: v,
                    at: vertices[v as usize],
                });
            }
            lp.push(v);
            v = match next.get(&v) {
                Some(&w) => w,
                None => {
                    return Err(ScanError::PinchedBorder {
                        vertex: v,
                        at: vertices[v as usize],
                    });
                }
            };
        }
        loops.push(lp);
    }
    Ok(loops)
}

/// Triangles closing a border (given in the direction its own triangles run it): ear clipping
/// of the reversed border in its best-fit plane (Newell's normal), so every added triangle runs
/// each border edge opposite to the mesh's triangle and the orientation stays consistent. When
/// no ear is free of other border points (a border far from planar), the most convex corner is
/// clipped.
pub(crate) fn fill_hole(border: &[u32], vertices: &[V3]) -> Vec<[u32; 3]> {
    let poly: Vec<u32> = border.iter().rev().copied().collect();
    let pts: Vec<V3> = poly.iter().map(|&k| vertices[k as usize]).collect();
    let n = pts.len();
    let mut normal = V3::zeros();
    for k in 0..n {
        normal += pts[k].cross(&pts[(k + 1) % n]);
    }
    let normal = normal
        .try_normalize(0.0)
        .unwrap_or_else(|| V3::new(0.0, 1.0, 0.0));
    let helper = if normal.x.abs() < 0.9 {
        V3::x()
    } else {
        V3::y()
    };
    let u = normal.cross(&helper).normalize();
    let v = normal.cross(&u);
    let p2: Vec<(f64, f64)> = pts.iter().map(|p| (p.dot(&u), p.dot(&v))).collect();
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut idx: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n.saturating_sub(2));
    while idx.len() > 3 {
        let m = idx.len();
        let mut best: Option<(usize, f64)> = None;
        let mut ear = None;
        for i in 0..m {
            let (a, b, c) = (idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]);
            let turn = cross(p2[a], p2[b], p2[c]);
            if best.is_none_or(|(_, t)| turn > t) {
                best = Some((i, turn));
            }
            if turn <= 0.0 {
                continue;
            }
            let blocked = idx.iter().any(|&q| {
                q != a
                    && q != b
                    && q != c
                    && cross(p2[a], p2[b], p2[q]) >= 0.0
                    && cross(p2[b], p2[c], p2[q]) >= 0.0
                    && cross(p2[c], p2[a], p2[q]) >= 0.0
            });
            if !blocked {
                ear = Some(i);
                break;
            }
        }
        let i = ear.unwrap_or_else(|| best.map_or(0, |b| b.0));
        out.push([
            poly[idx[(i + m - 1) % m]],
            poly[idx[i]],
            poly[idx[(i + 1) % m]],
        ]);
        idx.remove(i);
    }
    if idx.len() == 3 {
        out.push([poly[idx[0]], poly[idx[1]], poly[idx[2]]]);
    }
    out
}
