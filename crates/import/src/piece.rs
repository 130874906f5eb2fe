//! A pattern piece as read from a file, before it becomes a panel: its closed outline (the seam
//! line, cm, counter-clockwise), the points where the outline turns and its notches (both as
//! vertices of the outline), its grain line, darts and the internal lines that are not darts.

use atelier_grid::pattern::geometry::{contains, segment_distance, self_intersection, signed_area};

use crate::error::PieceProblem;

/// Two points closer than this (cm) are the same point (1 µm).
pub const SAME_POINT_CM: f64 = 1e-4;

/// A notch or dart end farther than this from the outline (cm) is not on it.
pub const ON_OUTLINE_CM: f64 = 0.05;

/// An outline that encloses less than this (cm²) has no area.
pub const MIN_AREA_CM2: f64 = 1e-6;

/// A dart: a wedge from two points of the outline to an apex inside the piece, drawn as its two
/// legs.
#[derive(Clone, Debug, PartialEq)]
pub struct Dart {
    /// Outline vertex where the first leg starts (the opening's first end, in outline order).
    pub from: usize,
    /// Outline vertex where the second leg ends (the opening's other end).
    pub to: usize,
    /// The apex, cm.
    pub apex: [f64; 2],
}

/// One pattern piece.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// Name (the `Piece Name:` text, or the block's name).
    pub name: String,
    /// How many are cut (the `Quantity:` text; 1 when absent).
    pub quantity: u32,
    /// The closed outline, cm, counter-clockwise, the first point not repeated at the end.
    pub outline: Vec<[f64; 2]>,
    /// Outline vertices the file marks as turn points (sharp corners), ascending.
    pub turns: Vec<usize>,
    /// Outline vertices that are notches, ascending.
    pub notches: Vec<usize>,
    /// The grain line (warp direction), from → to, cm.
    pub grain: Option<([f64; 2], [f64; 2])>,
    /// Darts.
    pub darts: Vec<Dart>,
    /// Internal lines that are not darts (drawn only), cm.
    pub internal: Vec<Vec<[f64; 2]>>,
    /// Where the outline came from: the sew line (layer 14) or the cut line (layer 1).
    pub outline_source: String,
}

impl Piece {
    /// A piece from a closed outline (cm; either orientation; the last point may repeat the
    /// first): checked for finiteness, closure, area and self-intersection, turned
    /// counter-clockwise.
    pub fn new(
        name: &str,
        mut outline: Vec<[f64; 2]>,
        closed_flag: bool,
        outline_source: &str,
    ) -> Result<Self, PieceProblem> {
        if outline.iter().flatten().any(|v| !v.is_finite()) {
            return Err(PieceProblem::NotFinite);
        }
        outline.dedup_by(|b, a| dist(*a, *b) < SAME_POINT_CM);
        let ends_at_start =
            outline.len() > 1 && dist(outline[0], outline[outline.len() - 1]) < SAME_POINT_CM;
        if ends_at_start {
            outline.pop();
        } else if !closed_flag {
            let gap_cm = match (outline.first(), outline.last()) {
                (Some(&a), Some(&b)) => dist(a, b),
                _ => 0.0,
            };
            return Err(PieceProblem::NotClosed { gap_cm });
        }
        if outline.len() < 3 {
            return Err(PieceProblem::TooFewPoints(outline.len()));
        }
        // Crossing first: a symmetric bow-tie also encloses no signed area.
        if let Some((i, j)) = self_intersection(&outline) {
            return Err(PieceProblem::SelfIntersecting {
                at: outline[i],
                edges: (i, j),
            });
        }
        let area = signed_area(&outline);
        if area.abs() < MIN_AREA_CM2 {
            return Err(PieceProblem::ZeroArea {
                area_cm2: area.abs(),
            });
        }
        if area < 0.0 {
            outline.reverse();
        }
        Ok(Self {
            name: name.to_owned(),
            quantity: 1,
            outline,
            turns: Vec::new(),
            notches: Vec::new(),
            grain: None,
            darts: Vec::new(),
            internal: Vec::new(),
            outline_source: outline_source.to_owned(),
        })
    }

    /// The outline vertex at `p`, inserted on the nearest edge when `p` lies on it between
    /// vertices; `None` when `p` is farther than [`ON_OUTLINE_CM`] from the outline. Indices of
    /// turns, notches and darts after the insertion point are moved up.
    pub fn vertex_at(&mut self, p: [f64; 2]) -> Option<usize> {
        let n = self.outline.len();
        let (mut best, mut best_t, mut best_d) = (0, 0.0, f64::INFINITY);
        for k in 0..n {
            let (d, t) = segment_distance(p, self.outline[k], self.outline[(k + 1) % n]);
            if d < best_d {
                (best, best_t, best_d) = (k, t, d);
            }
        }
        if best_d > ON_OUTLINE_CM {
            return None;
        }
        let (a, b) = (self.outline[best], self.outline[(best + 1) % n]);
        let q = [a[0] + best_t * (b[0] - a[0]), a[1] + best_t * (b[1] - a[1])];
        if dist(q, a) < SAME_POINT_CM * 10.0 {
            return Some(best);
        }
        if dist(q, b) < SAME_POINT_CM * 10.0 {
            return Some((best + 1) % n);
        }
        let at = best + 1;
        self.outline.insert(at, q);
        let shift = |v: &mut usize| {
            if *v >= at {
                *v += 1;
            }
        };
        self.turns.iter_mut().for_each(shift);
        self.notches.iter_mut().for_each(shift);
        for d in &mut self.darts {
            shift(&mut d.from);
            shift(&mut d.to);
        }
        Some(at)
    }

    /// Darts drawn as V notches in the outline itself (FreeSewing's way): a vertex where the
    /// counter-clockwise outline turns clockwise by more than `tip_deg` (a reflex inside angle
    /// sharper than 180° − `tip_deg`) is a dart's tip; walking from it
    /// both ways along the legs to the first vertex that turns by more than `leg_deg` finds
    /// the opening's ends. The legs and the tip leave the outline, which now runs straight
    /// across the opening, and become a [`Dart`] (its legs straight, as the gridder makes
    /// them: a curved leg is straightened). Returns how many were closed. Call it before
    /// turns and notches are set (it renumbers the outline).
    pub fn close_v_darts(&mut self, tip_deg: f64, leg_deg: f64) -> usize {
        // Each dart as points (opening ends, apex): indices move as vertices leave.
        let mut found: Vec<([f64; 2], [f64; 2], [f64; 2])> = Vec::new();
        loop {
            let n = self.outline.len();
            if n < 6 {
                break;
            }
            // A tip turns the outline back clockwise (the piece's inside angle there is
            // reflex); a convex corner turns it counter-clockwise.
            let Some(tip) = (0..n).find(|&k| self.turning_deg(k) < -tip_deg) else {
                break;
            };
            let walk = |step: usize| {
                let mut k = tip;
                for _ in 0..n {
                    k = (k + step) % n;
                    if self.turning_deg(k).abs() > leg_deg {
                        return Some(k);
                    }
                }
                None
            };
            let (Some(from), Some(to)) = (walk(n - 1), walk(1)) else {
                break;
            };
            if from == to {
                break;
            }
            // Keep everything outside the V, from `to` round to `from`.
            let mut kept = Vec::with_capacity(n);
            let mut k = to;
            loop {
                kept.push(self.outline[k]);
                if k == from {
                    break;
                }
                k = (k + 1) % n;
            }
            if kept.len() < 3 || self_intersection(&kept).is_some() {
                break;
            }
            found.push((self.outline[from], self.outline[to], self.outline[tip]));
            self.outline = kept;
        }
        let at = |outline: &[[f64; 2]], p: [f64; 2]| {
            outline.iter().position(|&q| dist(q, p) < SAME_POINT_CM)
        };
        for (a, b, apex) in &found {
            if let (Some(from), Some(to)) = (at(&self.outline, *a), at(&self.outline, *b)) {
                self.darts.push(Dart {
                    from,
                    to,
                    apex: *apex,
                });
            }
        }
        found.len()
    }

    /// Whether `p` lies inside the outline.
    pub fn contains(&self, p: [f64; 2]) -> bool {
        contains(&self.outline, p)
    }

    /// Area, cm².
    pub fn area_cm2(&self) -> f64 {
        signed_area(&self.outline)
    }

    /// Width and height of the bounding box, cm.
    pub fn size_cm(&self) -> [f64; 2] {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &self.outline {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        [hi[0] - lo[0], hi[1] - lo[1]]
    }

    /// The grain line's angle from the pattern's +x axis, degrees (90 when it runs along +y;
    /// 90 when the piece has none).
    pub fn grain_deg(&self) -> f64 {
        self.grain
            .map_or(90.0, |(a, b)| (b[1] - a[1]).atan2(b[0] - a[0]).to_degrees())
    }

    /// The turning angle of the outline at vertex `k`, degrees: 0 on a straight run, positive
    /// where a counter-clockwise outline turns left (a convex corner).
    pub fn turning_deg(&self, k: usize) -> f64 {
        let n = self.outline.len();
        let (a, b, c) = (
            self.outline[(k + n - 1) % n],
            self.outline[k],
            self.outline[(k + 1) % n],
        );
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
        (u[0] * v[1] - u[1] * v[0])
            .atan2(u[0] * v[0] + u[1] * v[1])
            .to_degrees()
    }

    /// Length of the outline from vertex `from` to vertex `to`, counter-clockwise, cm.
    pub fn length_between(&self, from: usize, to: usize) -> f64 {
        let n = self.outline.len();
        let mut k = from;
        let mut len = 0.0;
        loop {
            let next = (k + 1) % n;
            len += dist(self.outline[k], self.outline[next]);
            k = next;
            if k == to {
                return len;
            }
        }
    }
}

/// Distance between two points.
pub fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Vec<[f64; 2]> {
        vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]
    }

    #[test]
    fn a_clockwise_outline_is_turned_and_a_repeated_end_dropped() {
        let mut cw = square();
        cw.reverse();
        cw.push(cw[0]);
        let p = Piece::new("p", cw, false, "test").expect("piece");
        assert_eq!(p.outline.len(), 4);
        assert!((p.area_cm2() - 100.0).abs() < 1e-12);
        assert!((p.turning_deg(0) - 90.0).abs() < 1e-9);
    }

    #[test]
    fn bad_outlines_are_named() {
        let open = vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]];
        assert!(matches!(
            Piece::new("p", open, false, "t"),
            Err(PieceProblem::NotClosed { gap_cm }) if (gap_cm - 200f64.sqrt()).abs() < 1e-9
        ));
        let bow = vec![[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]];
        assert!(matches!(
            Piece::new("p", bow, true, "t"),
            Err(PieceProblem::SelfIntersecting { .. })
        ));
        let line = vec![[0.0, 0.0], [5.0, 0.0], [10.0, 0.0]];
        assert!(matches!(
            Piece::new("p", line, true, "t"),
            Err(PieceProblem::ZeroArea { .. })
        ));
        let nan = vec![[0.0, 0.0], [f64::NAN, 0.0], [10.0, 10.0]];
        assert_eq!(
            Piece::new("p", nan, true, "t"),
            Err(PieceProblem::NotFinite)
        );
    }

    #[test]
    fn a_point_on_an_edge_becomes_a_vertex_and_indices_move_up() {
        let mut p = Piece::new("p", square(), true, "t").expect("piece");
        p.turns = vec![0, 1, 2, 3];
        assert_eq!(p.vertex_at([10.0, 4.0]), Some(2));
        assert_eq!(p.turns, vec![0, 1, 3, 4]);
        assert_eq!(
            p.vertex_at([10.0, 4.0 + 1e-5]),
            Some(2),
            "the same point again"
        );
        assert_eq!(p.vertex_at([5.0, 5.0]), None, "inside, not on the outline");
        assert!((p.length_between(1, 2) - 4.0).abs() < 1e-12);
        assert!((p.length_between(2, 1) - 36.0).abs() < 1e-12);
    }
}
