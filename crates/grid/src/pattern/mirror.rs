//! A pattern turned over: the piece cut from the other side of the fabric (a left half from a
//! right half's pattern). Mirrored about the line x = 0 and traversed again counter-clockwise,
//! so that it grids like any pattern: every team keeps its name and cells and runs along the same
//! edge of the piece, so seams name the same teams on both halves.

use super::geometry::{Point, Segment};
use super::spec::{Outline, PatternSpec, TeamSpec};

fn flip(p: Point) -> Point {
    (-p.0, p.1)
}

/// The path of `teams` from `start` traversed backwards and mirrored: returns the new start
/// (the mirrored end) and the teams in reverse order, each running the other way.
fn reversed(start: Point, teams: &[TeamSpec]) -> (Point, Vec<TeamSpec>) {
    // Start of every segment, in order.
    let mut at = start;
    let mut out = Vec::with_capacity(teams.len());
    for t in teams {
        let mut path = Vec::with_capacity(t.path.len());
        for s in &t.path {
            let from = at;
            at = s.end();
            path.push(match *s {
                Segment::Line(_) => Segment::Line(flip(from)),
                Segment::Cubic(c1, c2, _) => Segment::Cubic(flip(c2), flip(c1), flip(from)),
                // Reversed, an arc turns the other way; mirrored, once more: the same sense.
                Segment::Arc { centre, ccw, .. } => Segment::Arc {
                    centre: flip(centre),
                    to: flip(from),
                    ccw,
                },
            });
        }
        path.reverse();
        out.push(TeamSpec {
            name: t.name.clone(),
            cells: t.cells,
            path,
        });
    }
    out.reverse();
    (flip(at), out)
}

/// End point of a chain of teams from `start`.
fn end_of(start: Point, teams: &[TeamSpec]) -> Point {
    teams
        .iter()
        .flat_map(|t| t.path.last())
        .last()
        .map_or(start, Segment::end)
}

impl PatternSpec {
    /// The pattern mirrored about x = 0 (a `Quad` outline; `None` for a `Ring`). The bottom side
    /// stays the bottom side and the top the top; the left and right sides change places. Darts,
    /// pleats, fixed points, depth hills and the grain line are mirrored with it.
    pub fn mirrored(&self) -> Option<PatternSpec> {
        let Outline::Quad {
            start,
            bottom,
            right,
            top,
            left,
        } = &self.outline
        else {
            return None;
        };
        // Counter-clockwise S →bottom→ B →right→ R →top→ T →left→ S. Mirrored and traversed
        // counter-clockwise again: m(B) →bottom'→ m(S) →left'→ m(T) →top'→ m(R) →right'→ m(B).
        let b = end_of(*start, bottom);
        let r = end_of(b, right);
        let t = end_of(r, top);
        let (new_start, new_bottom) = reversed(*start, bottom);
        let (_, new_right) = reversed(t, left);
        let (_, new_top) = reversed(r, top);
        let (_, new_left) = reversed(b, right);
        let mut m = self.clone();
        m.outline = Outline::Quad {
            start: new_start,
            bottom: new_bottom,
            right: new_right,
            top: new_top,
            left: new_left,
        };
        m.grain = (flip(self.grain.0), flip(self.grain.1));
        for d in &mut m.darts {
            d.apex = flip(d.apex);
        }
        for p in &mut m.pleats {
            (p.from, p.to) = (flip(p.from), flip(p.to));
        }
        for p in &mut m.fixed_points {
            *p = flip(*p);
        }
        for h in &mut m.depth {
            h.centre = flip(h.centre);
        }
        Some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::spec::DartSpec;

    fn team(name: &str, cells: usize, path: Vec<Segment>) -> TeamSpec {
        TeamSpec {
            name: name.into(),
            cells,
            path,
        }
    }

    fn spec() -> PatternSpec {
        PatternSpec {
            name: "p".into(),
            provenance: "test".into(),
            grain: ((1.0, 0.0), (1.0, 5.0)),
            outline: Outline::Quad {
                start: (0.0, 0.0),
                bottom: vec![
                    team("b1", 2, vec![Segment::Line((4.0, 0.0))]),
                    team("b2", 3, vec![Segment::Line((10.0, 0.0))]),
                ],
                right: vec![team(
                    "r",
                    4,
                    vec![Segment::Cubic((11.0, 3.0), (11.0, 6.0), (10.0, 8.0))],
                )],
                top: vec![
                    team("dart", 1, vec![Segment::Line((6.0, 8.0))]),
                    team("t", 4, vec![Segment::Line((0.0, 8.0))]),
                ],
                left: vec![team("l", 4, vec![Segment::Line((0.0, 0.0))])],
            },
            darts: vec![DartSpec {
                name: "d".into(),
                opening: "dart".into(),
                apex: (8.0, 5.0),
                cells: 2,
            }],
            pleats: Vec::new(),
            fixed_points: vec![(3.0, 3.0)],
            depth: Vec::new(),
            improve: None,
        }
    }

    fn area(poly: &[[f64; 2]]) -> f64 {
        let n = poly.len();
        (0..n)
            .map(|k| {
                let (a, b) = (poly[k], poly[(k + 1) % n]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>()
            / 2.0
    }

    #[test]
    fn a_mirrored_outline_is_the_mirror_image_traversed_counter_clockwise() {
        let s = spec();
        let m = s.mirrored().expect("a quad");
        let outline = |p: &PatternSpec| -> Vec<[f64; 2]> {
            let mut pts: Vec<[f64; 2]> = p
                .resolve()
                .iter()
                .flatten()
                .flat_map(|t| t.polyline[1..].to_vec())
                .collect();
            pts.dedup();
            pts
        };
        let (a, b) = (outline(&s), outline(&m));
        assert!((area(&a) - area(&b)).abs() < 1e-9 && area(&b) > 0.0);
        // Every mirrored point is a point of the original, and the reverse.
        for p in &b {
            assert!(
                a.iter()
                    .any(|q| (q[0] + p[0]).abs() < 1e-9 && (q[1] - p[1]).abs() < 1e-9)
            );
        }
        // Teams keep their names and cells and lie on the mirrored edge; the sides swap.
        let Outline::Quad { right, left, .. } = &m.outline else {
            panic!("quad")
        };
        assert_eq!(right[0].name, "l");
        assert_eq!(left[0].name, "r");
        assert_eq!(left[0].cells, 4);
        let sides = m.resolve();
        let r = &sides[3][0].polyline;
        assert_eq!(r.first().copied(), Some([-10.0, 8.0]));
        assert_eq!(r.last().copied(), Some([-10.0, 0.0]));
        // The curve bulges the mirrored way: its middle is at x = −10.75.
        let mid = r[r.len() / 2];
        assert!((mid[0] + 10.75).abs() < 1e-9, "{mid:?}");
        assert_eq!(m.darts[0].apex, (-8.0, 5.0));
        assert_eq!(m.fixed_points, vec![(-3.0, 3.0)]);
        assert_eq!(
            m.mirrored().expect("quad"),
            s,
            "mirrored twice is the original"
        );
    }
}
