//! From a piece to an atelier pattern (`atelier_grid::pattern::PatternSpec`, a `Quad`
//! outline): four of its corners become the grid's corners, its outline is split into teams at
//! those corners, at its notches and at its darts' ends, and each team gets a number of cells.
//!
//! - *Corners:* given, or the four outline vertices that turn most (among the file's turn points
//!   when it marks at least four), the grid's bottom side chosen as the one lowest along the grain
//!   line (so the warp runs up the grid, as in the hand-drafted patterns).
//! - *Teams:* named by their breakpoints, `"k-(k+1)"` counted counter-clockwise from the first
//!   corner (the last returns to `0`); each is the outline's polyline between them, as `Line`s.
//! - *Cells:* given per team, or from a target cell size: opposite sides get the same total (the
//!   grid needs it), shared among their teams by length, at least one each.

use atelier_grid::ImproveParams;
use atelier_grid::pattern::{
    DartSpec, Outline, Panel, PatternSpec, Segment, TeamSpec, grid_fitting_darts, grid_pattern,
};

use crate::error::PieceProblem;
use crate::piece::{Piece, dist};

/// How to make a panel of a piece.
#[derive(Clone, Debug, PartialEq)]
pub struct PanelOptions {
    /// Target cell size, cm.
    pub spacing_cm: f64,
    /// The grid's four corners as points on the outline (cm), counter-clockwise from the
    /// bottom side's start; the file's turn points decide when absent.
    pub corners: Option<[[f64; 2]; 4]>,
    /// Cells of every team in outline order from the first corner; from `spacing_cm` when
    /// absent.
    pub cells: Option<Vec<usize>>,
    /// Cells along each dart leg, in the piece's dart order; from `spacing_cm` when absent.
    pub dart_cells: Option<Vec<usize>>,
}

impl Default for PanelOptions {
    fn default() -> Self {
        Self {
            spacing_cm: 2.0,
            corners: None,
            cells: None,
            dart_cells: None,
        }
    }
}

/// A piece's panel: the pattern, and where its teams start.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The pattern, ready for `atelier_grid::pattern::grid_pattern`.
    pub spec: PatternSpec,
    /// The breakpoints (team starts), cm, in outline order from the first corner.
    pub breakpoints: Vec<[f64; 2]>,
    /// Which breakpoints are the grid's corners.
    pub corners: [usize; 4],
}

/// The pattern of a piece.
pub fn plan(piece: &Piece, options: &PanelOptions, provenance: &str) -> Result<Plan, PieceProblem> {
    let mut piece = piece.clone();
    let corners = match options.corners {
        Some(points) => {
            let mut c = [0; 4];
            for (k, p) in points.iter().enumerate() {
                c[k] = piece.vertex_at(*p).ok_or_else(|| {
                    PieceProblem::Sides(format!(
                        "corner {k} ({:.2}, {:.2}) cm is not on the outline",
                        p[0], p[1]
                    ))
                })?;
            }
            // Later insertions may have moved earlier corners: look them up again.
            for (k, p) in points.iter().enumerate() {
                c[k] = piece.vertex_at(*p).expect("on the outline");
            }
            c
        }
        None => chosen_corners(&piece)?,
    };
    let n = piece.outline.len();
    // Breakpoints: corners, notches, dart ends; in outline order from the first corner.
    let mut breaks: Vec<usize> = corners.to_vec();
    breaks.extend(&piece.notches);
    for d in &piece.darts {
        breaks.extend([d.from, d.to]);
    }
    let offset = |k: usize| (k + n - corners[0]) % n;
    breaks.sort_by_key(|&k| offset(k));
    breaks.dedup();
    let corner_at: Vec<usize> = corners
        .iter()
        .map(|c| breaks.iter().position(|b| b == c).expect("a breakpoint"))
        .collect();
    if corner_at.windows(2).any(|w| w[0] >= w[1]) {
        return Err(PieceProblem::Sides(
            "the four corners are not in counter-clockwise order along the outline".into(),
        ));
    }
    let m = breaks.len();
    let names: Vec<String> = (0..m).map(|k| format!("{k}-{}", (k + 1) % m)).collect();
    let lengths: Vec<f64> = (0..m)
        .map(|k| piece.length_between(breaks[k], breaks[(k + 1) % m]))
        .collect();
    // Team k's side: the last corner at or before it.
    let side_of = |k: usize| {
        corner_at
            .iter()
            .rposition(|&c| c <= k)
            .expect("corner 0 is 0")
    };
    let cells = match &options.cells {
        Some(c) if c.len() == m => c.clone(),
        Some(c) => {
            return Err(PieceProblem::Sides(format!(
                "{} team cell counts given, the piece has {m} teams",
                c.len()
            )));
        }
        None => {
            if !(options.spacing_cm > 0.0 && options.spacing_cm.is_finite()) {
                return Err(PieceProblem::Sides(format!(
                    "cell size {} cm is not a positive length",
                    options.spacing_cm
                )));
            }
            // A dart's opening is closed by sewing its legs: one cell, as in the hand-drafted
            // patterns.
            let openings: Vec<bool> = (0..m)
                .map(|k| {
                    piece
                        .darts
                        .iter()
                        .any(|d| breaks[k] == d.from && breaks[(k + 1) % m] == d.to)
                })
                .collect();
            cells_by_length(
                &lengths,
                &(0..m).map(side_of).collect::<Vec<_>>(),
                &openings,
                options.spacing_cm,
            )
        }
    };
    let mut sides: [Vec<TeamSpec>; 4] = Default::default();
    for k in 0..m {
        let (from, to) = (breaks[k], breaks[(k + 1) % m]);
        let mut path = Vec::new();
        let mut v = from;
        while v != to {
            v = (v + 1) % n;
            let p = piece.outline[v];
            path.push(Segment::Line((p[0], p[1])));
        }
        sides[side_of(k)].push(TeamSpec {
            name: names[k].clone(),
            cells: cells[k],
            path,
        });
    }
    let mut darts = Vec::new();
    for (k, d) in piece.darts.iter().enumerate() {
        let opening = (0..m)
            .find(|&t| breaks[t] == d.from && breaks[(t + 1) % m] == d.to)
            .ok_or_else(|| {
                PieceProblem::Sides(format!(
                    "dart {k}: its opening is not one team (a notch or corner lies inside it)"
                ))
            })?;
        let leg = dist(piece.outline[d.from], d.apex).max(dist(piece.outline[d.to], d.apex));
        let cells = match &options.dart_cells {
            Some(c) => *c
                .get(k)
                .ok_or_else(|| PieceProblem::Sides(format!("no cell count given for dart {k}")))?,
            None => ((leg / options.spacing_cm).round() as usize).max(1),
        };
        darts.push(DartSpec {
            name: format!("dart {k}"),
            opening: names[opening].clone(),
            apex: (d.apex[0], d.apex[1]),
            cells,
        });
    }
    let start = piece.outline[corners[0]];
    let grain = piece.grain.unwrap_or(([0.0, 0.0], [0.0, 1.0]));
    let [bottom, right, top, left] = sides;
    let spec = PatternSpec {
        name: piece.name.clone(),
        provenance: provenance.to_owned(),
        grain: ((grain.0[0], grain.0[1]), (grain.1[0], grain.1[1])),
        outline: Outline::Quad {
            start: (start[0], start[1]),
            bottom,
            right,
            top,
            left,
        },
        darts,
        pleats: Vec::new(),
        fixed_points: Vec::new(),
        depth: Vec::new(),
        improve: None,
    };
    Ok(Plan {
        spec,
        breakpoints: breaks.iter().map(|&b| piece.outline[b]).collect(),
        corners: [corner_at[0], corner_at[1], corner_at[2], corner_at[3]],
    })
}

/// The four vertices that turn most (among the marked turn points when there are at least
/// four), in grid order ([`orient`]).
fn chosen_corners(piece: &Piece) -> Result<[usize; 4], PieceProblem> {
    corner_candidates(piece, 4)
        .into_iter()
        .next()
        .ok_or_else(|| {
            PieceProblem::Sides("fewer than four vertices: a grid needs four corners".into())
        })
}

/// Sets of four corners to try, in grid order: every four of the `among` vertices that turn
/// most (the marked turn points when there are at least four, else every vertex), the sets
/// with the most turning first.
pub fn corner_candidates(piece: &Piece, among: usize) -> Vec<[usize; 4]> {
    let n = piece.outline.len();
    let mut by_turn: Vec<usize> = if piece.turns.len() >= 4 {
        piece.turns.clone()
    } else {
        (0..n).collect()
    };
    by_turn.sort_by(|&a, &b| piece.turning_deg(b).total_cmp(&piece.turning_deg(a)));
    by_turn.truncate(among.max(4));
    let m = by_turn.len();
    let mut sets = Vec::new();
    for a in 0..m {
        for b in a + 1..m {
            for c in b + 1..m {
                for d in c + 1..m {
                    let mut four = [by_turn[a], by_turn[b], by_turn[c], by_turn[d]];
                    four.sort_unstable();
                    sets.push(four);
                }
            }
        }
    }
    let turn = |s: &[usize; 4]| s.iter().map(|&k| piece.turning_deg(k)).sum::<f64>();
    sets.sort_by(|x, y| turn(y).total_cmp(&turn(x)));
    sets.into_iter().map(|s| orient(piece, s)).collect()
}

/// Four corners (ascending along the outline) rotated so that the grid's bottom side is the
/// one lowest along the grain line.
fn orient(piece: &Piece, four: [usize; 4]) -> [usize; 4] {
    let (g0, g1) = piece.grain.unwrap_or(([0.0, 0.0], [0.0, 1.0]));
    let g = [g1[0] - g0[0], g1[1] - g0[1]];
    let height = |k: usize| {
        let (a, b) = (piece.outline[four[k]], piece.outline[four[(k + 1) % 4]]);
        (a[0] + b[0]) * g[0] + (a[1] + b[1]) * g[1]
    };
    let first = (0..4)
        .min_by(|&a, &b| height(a).total_cmp(&height(b)))
        .expect("four sides");
    [0, 1, 2, 3].map(|k| four[(first + k) % 4])
}

/// A piece's pattern and grid. With corners given, that plan; without, every set of
/// [`corner_candidates`] among the six vertices that turn most is planned and gridded, and
/// the grid with the least shear spread after improvement is kept (a set whose teams a dart
/// or the gridder cannot use is passed over). Either way, where a dart's wedge runs into
/// another in the grid, its legs are given fewer cells (`grid_shortening_darts`). The error
/// is the first candidate's when none grids.
pub fn plan_and_grid(
    piece: &Piece,
    options: &PanelOptions,
    provenance: &str,
    params: ImproveParams,
) -> Result<(Plan, Panel), PieceProblem> {
    if let Some(corners) = options.corners {
        return grid_shortening_darts(piece, options, corners, provenance, params);
    }
    let mut first_error = None;
    let mut best: Option<(Plan, Panel)> = None;
    for set in corner_candidates(piece, 6) {
        let corners = set.map(|k| piece.outline[k]);
        match grid_shortening_darts(piece, options, corners, provenance, params) {
            Ok((p, panel)) => {
                let better = best.as_ref().is_none_or(|(_, b)| {
                    panel.quality_after.shear_deg.sd < b.quality_after.shear_deg.sd
                });
                if better {
                    best = Some((p, panel));
                }
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    best.ok_or_else(|| {
        first_error.unwrap_or_else(|| PieceProblem::Sides("no four corners to try".into()))
    })
}

/// Plan and grid with the given corners; when a dart's wedge runs into another constraint in
/// the grid (two darts whose apexes lie close: the bodice's waist and bust darts) or its legs
/// are longer than the grid is across, that dart's legs get one cell fewer (its apex then sits
/// nearer its opening in the grid), until it fits or has one cell. Leg counts given in
/// `options` are never changed.
fn grid_shortening_darts(
    piece: &Piece,
    options: &PanelOptions,
    corners: [[f64; 2]; 4],
    provenance: &str,
    params: ImproveParams,
) -> Result<(Plan, Panel), PieceProblem> {
    let o = PanelOptions {
        corners: Some(corners),
        ..options.clone()
    };
    let mut p = plan(piece, &o, provenance)?;
    let cannot = |e| PieceProblem::Sides(format!("cannot grid it: {e}"));
    if options.dart_cells.is_some() {
        // Leg counts given are never changed.
        let panel = grid_pattern(&p.spec, params).map_err(cannot)?;
        return Ok((p, panel));
    }
    let (spec, panel) = grid_fitting_darts(p.spec, params).map_err(cannot)?;
    p.spec = spec;
    Ok((p, panel))
}

/// Cells per team: opposite sides (0 and 2, 1 and 3) share a total, the longer side's length
/// over the spacing (at least what the teams need on either), split by length among the teams
/// not marked `single`, one at least each; the teams marked `single` get exactly one.
fn cells_by_length(lengths: &[f64], side: &[usize], single: &[bool], spacing: f64) -> Vec<usize> {
    let on = |s: usize| (0..lengths.len()).filter(move |&k| side[k] == s);
    let side_len = |s: usize| on(s).map(|k| lengths[k]).sum::<f64>();
    let mut out = vec![0; lengths.len()];
    for (a, b) in [(0, 2), (1, 3)] {
        let total = ((side_len(a).max(side_len(b)) / spacing).round() as usize)
            .max(on(a).count())
            .max(on(b).count())
            .max(1);
        for s in [a, b] {
            let (free, fixed): (Vec<usize>, Vec<usize>) = on(s).partition(|&k| !single[k]);
            for &k in &fixed {
                out[k] = 1;
            }
            if free.is_empty() {
                continue;
            }
            let spare = total.saturating_sub(fixed.len()).max(free.len()) - free.len();
            let len: f64 = free.iter().map(|&k| lengths[k]).sum();
            // One each, the rest by the largest remainders of the length shares.
            let share: Vec<f64> = free
                .iter()
                .map(|&k| spare as f64 * lengths[k] / len)
                .collect();
            let mut given: Vec<usize> = share.iter().map(|x| x.floor() as usize).collect();
            let mut order: Vec<usize> = (0..free.len()).collect();
            order.sort_by(|&i, &j| {
                (share[j] - share[j].floor()).total_cmp(&(share[i] - share[i].floor()))
            });
            let left = spare - given.iter().sum::<usize>();
            for &i in order.iter().take(left) {
                given[i] += 1;
            }
            for (i, &k) in free.iter().enumerate() {
                out[k] = 1 + given[i];
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 30 × 20 cm rectangle with a notch on the bottom and a dart from the top.
    fn piece() -> Piece {
        let mut p = Piece::new(
            "rect",
            vec![[0.0, 0.0], [30.0, 0.0], [30.0, 20.0], [0.0, 20.0]],
            true,
            "test",
        )
        .expect("piece");
        p.grain = Some(([5.0, 5.0], [5.0, 15.0]));
        let k = p.vertex_at([10.0, 0.0]).expect("on");
        p.notches.push(k);
        let (a, b) = (
            p.vertex_at([16.0, 20.0]).expect("on"),
            p.vertex_at([14.0, 20.0]).expect("on"),
        );
        p.darts.push(crate::piece::Dart {
            from: a,
            to: b,
            apex: [15.0, 12.0],
        });
        p
    }

    #[test]
    fn a_rectangle_gets_its_corners_teams_and_matching_cells() {
        let plan = plan(&piece(), &PanelOptions::default(), "test").expect("plan");
        let Outline::Quad {
            start,
            bottom,
            right,
            top,
            left,
        } = &plan.spec.outline
        else {
            panic!("quad")
        };
        assert_eq!(
            *start,
            (0.0, 0.0),
            "the bottom side is the lowest along the grain"
        );
        let count = |s: &[TeamSpec]| s.iter().map(|t| t.cells).sum::<usize>();
        assert_eq!(
            (bottom.len(), right.len(), top.len(), left.len()),
            (2, 1, 3, 1)
        );
        assert_eq!(count(bottom), 15, "30 cm at 2 cm");
        assert_eq!(count(top), 15, "opposite sides match");
        assert_eq!((count(right), count(left)), (10, 10));
        assert_eq!(bottom[0].cells, 5, "10 cm of 30");
        assert_eq!(plan.spec.darts[0].opening, top[1].name);
        assert_eq!(plan.spec.darts[0].cells, 4, "a leg of 8.06 cm");
        let panel = grid_pattern(&plan.spec, Default::default()).expect("grids");
        assert!(panel.topology.node_count() > 100);
    }

    #[test]
    fn cells_split_by_length_keep_the_total_and_one_each() {
        let cells = cells_by_length(
            &[1.0, 9.0, 0.1, 10.0, 5.0, 5.0],
            &[0, 0, 0, 1, 2, 3],
            &[false; 6],
            1.0,
        );
        assert_eq!(cells[..3].iter().sum::<usize>(), 10);
        assert!(cells[..3].iter().all(|&c| c >= 1));
        assert_eq!(cells[4], 10, "opposite the bottom");
        assert_eq!((cells[3], cells[5]), (10, 10));
    }
}
