//! Cell counts matched across seams (thesis §4.4.2: the two teams of a seam have the same node
//! count). A drafted pattern's counts are the drafter's and never change; a pattern made from an
//! imported piece got its counts from a cell size, and the gridder may change them:
//!
//! 1. The teams joined by seams form classes (a team sewn to two others, through a chain of
//!    seams, is one class); a class with a drafted team takes its count, else the largest of its
//!    members' (the finer grid wins).
//! 2. A four-sided grid needs its opposite sides to total the same cells. Where they do not, a
//!    cell is added to the short side's team that is longest per cell (among the teams the
//!    gridder may change, whose class does not also lie on the long side), and with it to its
//!    whole class, until every free pattern balances. Counts only grow, so this ends; a side
//!    that has no team to grow is an error naming the panel and the sides.
//!
//! A dart's opening is never changed (it is one cell: its legs are sewn over it). Its legs run
//! across the grid from the side it opens on, so when the sides across grow, the legs' cells
//! grow with them ([`rescale_darts`]): a dart keeps its length in the grid's rows or columns, as
//! it was planned, and its apex stays where the cells around it can hold it.

use super::spec::{Outline, PatternSpec};

/// A team of a panel: (panel index, team name).
pub type TeamRef = (usize, String);

/// Why counts cannot be matched.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CountError {
    /// Two teams the gridder may not change (a drafted team, a dart's opening of an imported
    /// piece) joined through a chain of seams with different counts.
    #[error(
        "teams {a} and {b} are joined by seams but were drafted with {ca} and {cb} cells; a seam's teams must have the same count"
    )]
    Drafted {
        /// `panel.team`.
        a: String,
        /// `panel.team`.
        b: String,
        /// Cells of `a`.
        ca: usize,
        /// Cells of `b`.
        cb: usize,
    },
    /// A panel whose opposite sides cannot be made equal.
    #[error(
        "panel `{panel}`: its {short} side has {short_cells} cells and its {long} side {long_cells}, and no team of the {short} side can be given more (each is drafted, a dart's opening, or sewn to the {long} side)"
    )]
    Unbalanced {
        /// Panel name.
        panel: String,
        /// The side with fewer cells.
        short: &'static str,
        /// Its cells.
        short_cells: usize,
        /// The opposite side.
        long: &'static str,
        /// Its cells.
        long_cells: usize,
    },
}

const SIDES: [&str; 4] = ["bottom", "right", "top", "left"];

/// One team's place in the problem.
struct Slot {
    panel: usize,
    side: usize,
    length: f64,
    class: usize,
}

/// Change the cell counts of the `free` patterns so that every seam's two teams (`seams`, by
/// panel index and team name, already checked to exist) have one count and every free
/// four-sided pattern's opposite sides total the same. Patterns not free are left as they are;
/// a seam between two of them that differ is left for the seam check to report.
pub fn match_seam_counts(
    specs: &mut [PatternSpec],
    free: &[bool],
    seams: &[(TeamRef, TeamRef)],
) -> Result<(), CountError> {
    // Every team of every Quad pattern, with its side and length.
    let mut slots: Vec<Slot> = Vec::new();
    let mut index: Vec<Vec<(String, usize)>> = vec![Vec::new(); specs.len()];
    let mut cells: Vec<usize> = Vec::new();
    let mut fixed: Vec<bool> = Vec::new();
    for (pi, spec) in specs.iter().enumerate() {
        if !matches!(spec.outline, Outline::Quad { .. }) {
            continue;
        }
        let openings: Vec<&str> = spec.darts.iter().map(|d| d.opening.as_str()).collect();
        for (side, teams) in spec.resolve().into_iter().enumerate() {
            for t in teams {
                let length = t
                    .polyline
                    .windows(2)
                    .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
                    .sum();
                index[pi].push((t.name.clone(), slots.len()));
                fixed.push(!free[pi] || openings.contains(&t.name.as_str()));
                cells.push(t.cells);
                slots.push(Slot {
                    panel: pi,
                    side,
                    length,
                    class: slots.len(),
                });
            }
        }
    }
    let find = |r: &TeamRef| index[r.0].iter().find(|(n, _)| *n == r.1).map(|&(_, k)| k);
    // Classes by union–find over the seams.
    let mut parent: Vec<usize> = (0..slots.len()).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    for (a, b) in seams {
        if let (Some(a), Some(b)) = (find(a), find(b)) {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            parent[ra] = rb;
        }
    }
    for (k, slot) in slots.iter_mut().enumerate() {
        slot.class = root(&mut parent, k);
    }
    let name = |k: usize| {
        let n = index[slots[k].panel]
            .iter()
            .find(|&&(_, s)| s == k)
            .map_or("?", |(n, _)| n.as_str());
        format!("{}.{n}", specs[slots[k].panel].name)
    };
    // Each class's count: the drafted one, else the largest.
    let n_slots = slots.len();
    let mut class_cells = vec![0usize; n_slots];
    let mut class_fixed = vec![None::<usize>; n_slots];
    for k in 0..n_slots {
        let c = slots[k].class;
        if fixed[k] {
            if let Some(f) = class_fixed[c]
                && f != k
                && cells[f] != cells[k]
                && (free[slots[k].panel] || free[slots[f].panel])
            {
                return Err(CountError::Drafted {
                    a: name(f),
                    b: name(k),
                    ca: cells[f],
                    cb: cells[k],
                });
            }
            class_fixed[c].get_or_insert(k);
        }
        class_cells[c] = class_cells[c].max(cells[k]);
    }
    for c in 0..n_slots {
        if let Some(f) = class_fixed[c] {
            class_cells[c] = cells[f];
        }
    }
    for k in 0..n_slots {
        if !fixed[k] {
            cells[k] = class_cells[slots[k].class];
        }
    }
    // Balance the free patterns' opposite sides; counts only grow.
    let total = |cells: &[usize], p: usize, s: usize| -> usize {
        (0..n_slots)
            .filter(|&k| slots[k].panel == p && slots[k].side == s)
            .map(|k| cells[k])
            .sum()
    };
    // Each pass adds at least one cell; a chain of seams that makes a side grow with its
    // opposite side would never end, so the passes are capped (a garment's sides total a few
    // hundred cells).
    let mut settled = false;
    for _ in 0..100_000 {
        let mut changed = false;
        for p in (0..specs.len()).filter(|&p| free[p]) {
            for (a, b) in [(0, 2), (1, 3)] {
                let (ta, tb) = (total(&cells, p, a), total(&cells, p, b));
                if ta == tb {
                    continue;
                }
                let (short, long) = if ta < tb { (a, b) } else { (b, a) };
                let on_long: Vec<usize> = (0..n_slots)
                    .filter(|&k| slots[k].panel == p && slots[k].side == long)
                    .map(|k| slots[k].class)
                    .collect();
                let grow = (0..n_slots)
                    .filter(|&k| slots[k].panel == p && slots[k].side == short)
                    .filter(|&k| {
                        let c = slots[k].class;
                        class_fixed[c].is_none() && !fixed[k] && !on_long.contains(&c)
                    })
                    .max_by(|&i, &j| {
                        (slots[i].length / cells[i] as f64)
                            .total_cmp(&(slots[j].length / cells[j] as f64))
                    });
                let Some(k) = grow else {
                    return Err(CountError::Unbalanced {
                        panel: specs[p].name.clone(),
                        short: SIDES[short],
                        short_cells: ta.min(tb),
                        long: SIDES[long],
                        long_cells: ta.max(tb),
                    });
                };
                let c = slots[k].class;
                for j in 0..n_slots {
                    if slots[j].class == c && !fixed[j] {
                        cells[j] += 1;
                    }
                }
                changed = true;
            }
        }
        if !changed {
            settled = true;
            break;
        }
    }
    if !settled {
        let unbalanced = (0..specs.len())
            .filter(|&p| free[p])
            .flat_map(|p| [(p, 0, 2), (p, 1, 3)])
            .map(|(p, a, b)| (p, a, b, total(&cells, p, a), total(&cells, p, b)))
            .find(|&(_, _, _, ta, tb)| ta != tb);
        if let Some((p, a, b, ta, tb)) = unbalanced {
            let (short, long) = if ta < tb { (a, b) } else { (b, a) };
            return Err(CountError::Unbalanced {
                panel: specs[p].name.clone(),
                short: SIDES[short],
                short_cells: ta.min(tb),
                long: SIDES[long],
                long_cells: ta.max(tb),
            });
        }
    }
    // Write the counts back.
    for (pi, spec) in specs.iter_mut().enumerate() {
        if !free[pi] {
            continue;
        }
        if let Outline::Quad {
            bottom,
            right,
            top,
            left,
            ..
        } = &mut spec.outline
        {
            for t in [bottom, right, top, left].into_iter().flatten() {
                if let Some(&(_, k)) = index[pi].iter().find(|(n, _)| *n == t.name) {
                    t.cells = cells[k];
                }
            }
        }
    }
    Ok(())
}

/// Scale the dart legs' cells of `after` (a free pattern whose counts were matched) by how much
/// the grid grew across each dart: a dart opening on the bottom or top side runs up the grid and
/// scales with the left/right total, one opening on the left or right side with the bottom/top
/// total. `before` is the same pattern as planned.
pub fn rescale_darts(before: &PatternSpec, after: &mut PatternSpec) {
    // Each side's total cells, and the side each team lies on.
    type Sides = ([usize; 4], Vec<(String, usize)>);
    let totals = |s: &PatternSpec| -> Option<Sides> {
        let sides = s.resolve();
        if sides.len() != 4 {
            return None;
        }
        let mut total = [0; 4];
        let mut side_of = Vec::new();
        for (k, teams) in sides.iter().enumerate() {
            total[k] = teams.iter().map(|t| t.cells).sum();
            side_of.extend(teams.iter().map(|t| (t.name.clone(), k)));
        }
        Some((total, side_of))
    };
    let (Some((t0, side_of)), Some((t1, _))) = (totals(before), totals(after)) else {
        return;
    };
    for d in &mut after.darts {
        let Some(&(_, side)) = side_of.iter().find(|(n, _)| *n == d.opening) else {
            continue;
        };
        let across = if side % 2 == 0 { 1 } else { 0 };
        if t0[across] > 0 && t1[across] != t0[across] {
            let scaled = d.cells as f64 * t1[across] as f64 / t0[across] as f64;
            d.cells = (scaled.round() as usize).max(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::geometry::Segment;
    use crate::pattern::spec::TeamSpec;

    /// A w × h rectangle, its sides one team each (`b`, `r`, `t`, `l`), or the right side split
    /// in two at mid-height (`r1`, `r2`).
    fn rect(name: &str, w: f64, h: f64, cells: [usize; 4], split_right: bool) -> PatternSpec {
        let team = |n: &str, c: usize, to: (f64, f64)| TeamSpec {
            name: n.into(),
            cells: c,
            path: vec![Segment::Line(to)],
        };
        let right = if split_right {
            vec![
                team("r1", cells[1] / 2, (w, h / 2.0)),
                team("r2", cells[1] - cells[1] / 2, (w, h)),
            ]
        } else {
            vec![team("r", cells[1], (w, h))]
        };
        PatternSpec {
            name: name.into(),
            provenance: "test".into(),
            grain: ((0.0, 0.0), (0.0, 1.0)),
            outline: Outline::Quad {
                start: (0.0, 0.0),
                bottom: vec![team("b", cells[0], (w, 0.0))],
                right,
                top: vec![team("t", cells[2], (0.0, h))],
                left: vec![team("l", cells[3], (0.0, 0.0))],
            },
            darts: Vec::new(),
            pleats: Vec::new(),
            fixed_points: Vec::new(),
            depth: Vec::new(),
            improve: None,
        }
    }

    fn counts(s: &PatternSpec) -> Vec<(String, usize)> {
        s.resolve()
            .into_iter()
            .flatten()
            .map(|t| (t.name, t.cells))
            .collect()
    }

    fn r(p: usize, t: &str) -> TeamRef {
        (p, t.into())
    }

    #[test]
    fn seams_take_the_finer_count_and_the_sides_rebalance() {
        // Panel 0 (10 × 20 cm, 5 × 10 cells) sewn along its right side to panel 1's left side,
        // which was planned coarser (8 cells): the class takes 10, and panel 1's right side grows
        // to 10 to balance.
        let mut specs = vec![
            rect("a", 10.0, 20.0, [5, 10, 5, 10], false),
            rect("b", 10.0, 20.0, [5, 8, 5, 8], false),
        ];
        match_seam_counts(&mut specs, &[true, true], &[(r(0, "r"), r(1, "l"))]).expect("matched");
        assert_eq!(
            counts(&specs[1]),
            [("b", 5), ("r", 10), ("t", 5), ("l", 10)].map(|(n, c)| (n.to_owned(), c))
        );
        assert_eq!(counts(&specs[0])[1], ("r".to_owned(), 10));
    }

    #[test]
    fn a_drafted_count_is_kept_and_the_free_pattern_follows_it() {
        // Panel 0 is drafted with 12 cells on its right side; free panel 1 (planned with 8 on
        // its left, split 4 + 4 on its right) takes 12 on the left and grows its right to 12,
        // a cell at a time on the team longest per cell.
        let mut specs = vec![
            rect("drafted", 10.0, 20.0, [5, 12, 5, 12], false),
            rect("free", 10.0, 20.0, [5, 8, 5, 8], true),
        ];
        match_seam_counts(&mut specs, &[false, true], &[(r(0, "r"), r(1, "l"))]).expect("matched");
        let c = counts(&specs[1]);
        assert_eq!(c[4], ("l".to_owned(), 12));
        assert_eq!(c[1].1 + c[2].1, 12);
        assert_eq!((c[1].1, c[2].1), (6, 6), "equal halves share the growth");
        assert_eq!(
            counts(&specs[0])[1],
            ("r".to_owned(), 12),
            "drafted unchanged"
        );
    }

    #[test]
    fn a_side_that_cannot_grow_is_an_error_naming_the_panel() {
        // Free panel 1's left side is sewn to drafted panel 0 (12 cells) and its right side to
        // drafted panel 2 (8 cells): nothing can balance it.
        let mut specs = vec![
            rect("d12", 10.0, 20.0, [5, 12, 5, 12], false),
            rect("free", 10.0, 20.0, [5, 10, 5, 10], false),
            rect("d8", 10.0, 20.0, [5, 8, 5, 8], false),
        ];
        let e = match_seam_counts(
            &mut specs,
            &[false, true, false],
            &[(r(0, "r"), r(1, "l")), (r(1, "r"), r(2, "l"))],
        )
        .expect_err("cannot balance");
        assert!(
            matches!(&e, CountError::Unbalanced { panel, short_cells: 8, long_cells: 12, .. } if panel == "free"),
            "{e}"
        );
    }

    #[test]
    fn a_tube_sewn_to_itself_balances() {
        // One free panel whose left and right sides are sewn (a tube), planned 10 and 8: both 10.
        let mut specs = vec![rect("tube", 10.0, 20.0, [5, 8, 5, 10], false)];
        match_seam_counts(&mut specs, &[true], &[(r(0, "l"), r(0, "r"))]).expect("matched");
        let c = counts(&specs[0]);
        assert_eq!((c[1].1, c[3].1), (10, 10));
    }
}
