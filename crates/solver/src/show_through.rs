//! Where the body shows through a garment: the body vertices that lie *outside* the cloth
//! covering them. Contact holds the cloth's nodes outside the body, not its triangles; where the
//! body is convex with a radius near the cell size (a shoulder point, a knee) it can poke
//! through the faces between nodes, and a picture shows a grey patch there.
//!
//! A body vertex counts when the line through it along its outward normal (area-weighted over
//! its triangles) meets the cloth *behind* it within `reach` and nowhere in front of it within
//! `reach`: cloth covers that spot, but on the wrong side. Its depth is the distance to the
//! nearest such hit behind it. A vertex with cloth in front of it (covered properly) or with
//! none within reach (uncovered: a hand, the head) does not count. The reach must stay below
//! the thickness of the thinnest limb the garment covers, or the cloth on a limb's far side
//! would count; [`SHOW_THROUGH_REACH`] = 2 cm.
//!
//! Pure geometry, independent of the solver: the cloth's triangles are found by a broad phase
//! over their boxes, the line met by the Möller–Trumbore test.

use atelier_collide::V3;
use atelier_collide::broad::{BroadKind, new_broad};
use atelier_collide::geom::{line_triangle, vertex_normals};

/// How far along a body vertex's normal the cloth is looked for, on either side, m.
pub const SHOW_THROUGH_REACH: f64 = 0.02;

/// The body vertices the cloth leaves outside ([`show_through`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShowThrough {
    /// Body vertices with cloth behind them and none in front, within the reach.
    pub vertices: Vec<u32>,
    /// The largest of their depths (cloth behind the vertex), m; 0 without any.
    pub deepest: f64,
}

/// The body vertices that show through the cloth (see the module documentation). Body
/// triangles are counter-clockwise seen from outside. Non-finite input counts nothing.
pub fn show_through(
    body: &[[f64; 3]],
    body_triangles: &[[u32; 3]],
    cloth: &[[f64; 3]],
    cloth_triangles: &[[u32; 3]],
    reach: f64,
) -> ShowThrough {
    let finite = |p: &[[f64; 3]]| p.iter().flatten().all(|c| c.is_finite());
    let indexed = |t: &[[u32; 3]], n: usize| t.iter().flatten().all(|&k| (k as usize) < n);
    if !finite(body)
        || !finite(cloth)
        || !indexed(body_triangles, body.len())
        || !indexed(cloth_triangles, cloth.len())
        || cloth_triangles.is_empty()
    {
        return ShowThrough::default();
    }
    let body: Vec<V3> = body.iter().map(|p| V3::from(*p)).collect();
    let cloth: Vec<V3> = cloth.iter().map(|p| V3::from(*p)).collect();
    let mut normals = Vec::new();
    vertex_normals(&body, body_triangles, &mut normals);
    let mut broad = new_broad(BroadKind::Bvh);
    broad.update(&cloth, &cloth, cloth_triangles, 0.0);
    let mut out = ShowThrough::default();
    let mut candidates = Vec::new();
    for (v, (p, &n)) in body.iter().zip(&normals).enumerate() {
        if n == V3::zeros() {
            continue;
        }
        candidates.clear();
        broad.query(&(p - n * reach), &(p + n * reach), 0.0, &mut candidates);
        let (mut front, mut behind) = (false, f64::INFINITY);
        for &t in &candidates {
            let x = cloth_triangles[t as usize].map(|k| cloth[k as usize]);
            if let Some(s) = line_triangle(p, &n, [&x[0], &x[1], &x[2]])
                && s.abs() <= reach
            {
                if s >= 0.0 {
                    front = true;
                    break;
                }
                behind = behind.min(-s);
            }
        }
        if !front && behind.is_finite() {
            out.vertices.push(v as u32);
            out.deepest = out.deepest.max(behind);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An octahedron of "radius" r centred at the origin, triangles counter-clockwise seen from
    /// outside: its six vertices' normals point along ±x, ±y, ±z.
    fn octahedron(r: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let v = vec![
            [r, 0.0, 0.0],
            [-r, 0.0, 0.0],
            [0.0, r, 0.0],
            [0.0, -r, 0.0],
            [0.0, 0.0, r],
            [0.0, 0.0, -r],
        ];
        let t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (v, t)
    }

    /// A square sheet of side 2a in the plane z = h, two triangles.
    fn sheet(a: f64, h: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (
            vec![[-a, -a, h], [a, -a, h], [a, a, h], [-a, a, h]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn a_sheet_in_front_of_the_tip_hides_it_and_one_behind_shows_it_by_its_depth() {
        let (body, bt) = octahedron(0.1);
        // Over the +z tip by 3 mm: covered; nothing else is within reach of the sheet.
        let (cloth, ct) = sheet(0.05, 0.103);
        let r = show_through(&body, &bt, &cloth, &ct, SHOW_THROUGH_REACH);
        assert_eq!(r, ShowThrough::default());
        // 4 mm below the tip: the tip pokes through by 4 mm; the line through it (along +z)
        // meets the sheet behind it and nothing in front.
        let (cloth, ct) = sheet(0.05, 0.096);
        let r = show_through(&body, &bt, &cloth, &ct, SHOW_THROUGH_REACH);
        assert_eq!(r.vertices, vec![4]);
        assert!((r.deepest - 0.004).abs() < 1e-12, "{}", r.deepest);
        // Beyond the reach behind the tip (3 cm): not covered there, not counted.
        let (cloth, ct) = sheet(0.05, 0.07);
        let r = show_through(&body, &bt, &cloth, &ct, SHOW_THROUGH_REACH);
        assert_eq!(r, ShowThrough::default());
    }

    #[test]
    fn a_sheet_too_small_to_cover_the_tip_leaves_it_uncovered_not_showing() {
        let (body, bt) = octahedron(0.1);
        // The sheet lies 4 mm below the tip but beside the line through it (x from 1 to 3 cm).
        let cloth = vec![
            [0.01, -0.01, 0.096],
            [0.03, -0.01, 0.096],
            [0.03, 0.01, 0.096],
            [0.01, 0.01, 0.096],
        ];
        let ct = vec![[0, 1, 2], [0, 2, 3]];
        let r = show_through(&body, &bt, &cloth, &ct, SHOW_THROUGH_REACH);
        assert_eq!(r, ShowThrough::default());
    }

    #[test]
    fn the_line_through_a_shared_edge_is_met_and_bad_input_counts_nothing() {
        let (body, bt) = octahedron(0.1);
        // The tip's line passes through the sheet's diagonal (0,0): met (edges included).
        let (cloth, ct) = sheet(0.05, 0.099);
        let r = show_through(&body, &bt, &cloth, &ct, SHOW_THROUGH_REACH);
        assert_eq!(r.vertices, vec![4]);
        let mut bad = cloth.clone();
        bad[0][0] = f64::NAN;
        assert_eq!(
            show_through(&body, &bt, &bad, &ct, SHOW_THROUGH_REACH),
            ShowThrough::default()
        );
        assert_eq!(
            show_through(&body, &bt, &cloth, &[[0, 1, 9]], SHOW_THROUGH_REACH),
            ShowThrough::default()
        );
    }
}
