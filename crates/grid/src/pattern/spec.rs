//! The pattern file (RON, cm): what a user writes. Checked while it is parsed, so an error names
//! the file, the position, the field and the value.

use atelier_files::check::{Validate, non_empty, positive};
use atelier_files::{ErrorKind, InvalidValue};
use serde::{Deserialize, Serialize};

use super::geometry::{Point, Segment, contains, flatten, self_intersection};

/// A sewing pattern: one panel's outline split into groups and teams, its grain line, and the
/// local constraints of its grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct PatternSpec {
    /// Panel name.
    #[serde(deserialize_with = "non_empty")]
    pub name: String,
    /// Where the shape comes from (a drafting method, a book, a measurement).
    #[serde(deserialize_with = "non_empty")]
    pub provenance: String,
    /// The grain line, from one point to another (cm): the warp direction.
    pub grain: (Point, Point),
    /// The closed outline.
    pub outline: Outline,
    /// Darts: wedges with no grid inside, their legs sewn together.
    #[serde(default)]
    pub darts: Vec<DartSpec>,
    /// Pleat lines: the nearest grid line is moved onto each, evenly spaced.
    #[serde(default)]
    pub pleats: Vec<PleatSpec>,
    /// Points (cm) where a node must sit; the nearest interior node is moved there and fixed.
    #[serde(default)]
    pub fixed_points: Vec<Point>,
    /// A height field for density control: spacing shrinks where it is steep.
    #[serde(default)]
    pub depth: Vec<Mountain>,
    /// Improvement weights and stopping rule; defaults when absent.
    #[serde(default)]
    pub improve: Option<ImproveSpec>,
}

/// The outline: four groups of teams around a quadrilateral grid, or two closed loops around a
/// ring (the drape disk with its hole).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Outline {
    /// A grid with four sides. The path runs counter-clockwise from `start`: `bottom` (grid
    /// v = 0, u increasing), `right` (u = max), `top` (v = max, u decreasing), `left` (u = 0),
    /// and must return to `start`. Opposite groups must total the same number of cells.
    Quad {
        /// Start point of the first bottom team, cm.
        start: Point,
        /// Teams along the bottom side.
        bottom: Vec<TeamSpec>,
        /// Teams up the right side.
        right: Vec<TeamSpec>,
        /// Teams back along the top.
        top: Vec<TeamSpec>,
        /// Teams down the left side.
        left: Vec<TeamSpec>,
    },
    /// A grid closed in u: `inner` and `outer` loops (each starting at its own start point and
    /// returning to it) with the same number of cells, joined by `radial_cells` cells along the
    /// straight line between the two starts.
    Ring {
        /// Start of the inner loop, cm.
        inner_start: Point,
        /// Teams around the inner loop.
        inner: Vec<TeamSpec>,
        /// Start of the outer loop, cm.
        outer_start: Point,
        /// Teams around the outer loop.
        outer: Vec<TeamSpec>,
        /// Cells from the inner loop to the outer.
        radial_cells: usize,
    },
}

/// A team: a stretch of outline with a function (a seam line, a hem, a dart opening) and a
/// number of grid cells along it; nodes are spaced evenly by arc length within it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TeamSpec {
    /// Name, unique in the panel; seams refer to it.
    pub name: String,
    /// Grid cells along the team (nodes = cells + 1, shared with the neighbours at the ends).
    pub cells: usize,
    /// The path from the previous team's end.
    pub path: Vec<Segment>,
}

/// A dart: the wedge between the two ends of its opening team and the apex.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DartSpec {
    /// Name.
    pub name: String,
    /// The team of a `Quad` outline the dart opens on (the wedge's base).
    pub opening: String,
    /// The apex, cm, inside the panel.
    pub apex: Point,
    /// Grid cells along each leg.
    pub cells: usize,
}

/// A pleat line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PleatSpec {
    /// Name.
    pub name: String,
    /// One end, cm.
    pub from: Point,
    /// The other end, cm.
    pub to: Point,
}

/// A Gaussian hill `h = height · exp(−|p − centre|² / radius²)` (cm) of the depth field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mountain {
    /// Centre, cm.
    pub centre: Point,
    /// Height, cm (may be negative: a valley).
    pub height: f64,
    /// Radius, cm.
    #[serde(deserialize_with = "positive")]
    pub radius: f64,
}

/// Improvement weights (dimensionless) and stopping rule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImproveSpec {
    /// Smoothness weight c₁.
    pub c1: f64,
    /// Shear weight c₂.
    pub c2: f64,
    /// Spacing weight c₃.
    pub c3: f64,
    /// Relative energy change that stops the iteration.
    #[serde(deserialize_with = "positive")]
    pub relative_tolerance: f64,
    /// Iteration cap.
    pub max_iterations: usize,
}

atelier_files::validated!(PatternSpec);

/// One team with its resolved geometry: start, flattened polyline (cm).
#[derive(Clone, Debug)]
pub(crate) struct ResolvedTeam {
    pub name: String,
    pub cells: usize,
    pub polyline: Vec<[f64; 2]>,
    /// The field path of the team in the file.
    pub field: String,
}

impl PatternSpec {
    /// The teams of each side in order (Quad: bottom, right, top, left; Ring: inner, outer), with
    /// their flattened paths.
    pub(crate) fn resolve(&self) -> Vec<Vec<ResolvedTeam>> {
        let chain = |start: Point, teams: &[TeamSpec], field: &str| -> (Vec<ResolvedTeam>, Point) {
            let mut at = start;
            let mut out = Vec::new();
            for (k, t) in teams.iter().enumerate() {
                let poly = flatten([at.0, at.1], &t.path);
                at = t.path.last().map_or(at, Segment::end);
                out.push(ResolvedTeam {
                    name: t.name.clone(),
                    cells: t.cells,
                    polyline: poly,
                    field: format!("outline.{field}[{k}]"),
                });
            }
            (out, at)
        };
        match &self.outline {
            Outline::Quad {
                start,
                bottom,
                right,
                top,
                left,
            } => {
                let (b, at) = chain(*start, bottom, "bottom");
                let (r, at) = chain(at, right, "right");
                let (t, at) = chain(at, top, "top");
                let (l, _) = chain(at, left, "left");
                vec![b, r, t, l]
            }
            Outline::Ring {
                inner_start,
                inner,
                outer_start,
                outer,
                ..
            } => {
                let (i, _) = chain(*inner_start, inner, "inner");
                let (o, _) = chain(*outer_start, outer, "outer");
                vec![i, o]
            }
        }
    }

    /// The closed outline polygon (cm): for a ring, the outer loop.
    pub(crate) fn outline_polygon(&self) -> Vec<[f64; 2]> {
        let sides = self.resolve();
        let sides: &[Vec<ResolvedTeam>] = match self.outline {
            Outline::Quad { .. } => &sides,
            Outline::Ring { .. } => &sides[1..],
        };
        let mut poly: Vec<[f64; 2]> = Vec::new();
        for team in sides.iter().flatten() {
            let skip = usize::from(!poly.is_empty());
            poly.extend_from_slice(&team.polyline[skip..]);
        }
        poly.pop(); // closing point repeats the start
        poly
    }

    fn points(&self) -> Vec<(String, Point)> {
        let mut out = vec![
            ("grain".to_owned(), self.grain.0),
            ("grain".to_owned(), self.grain.1),
        ];
        let mut teams = |side: &str, start: Option<(&str, Point)>, list: &[TeamSpec]| {
            if let Some((f, p)) = start {
                out.push((format!("outline.{f}"), p));
            }
            for (k, t) in list.iter().enumerate() {
                for (s, seg) in t.path.iter().enumerate() {
                    let c = seg.coordinates();
                    for xy in c.chunks(2) {
                        out.push((format!("outline.{side}[{k}].path[{s}]"), (xy[0], xy[1])));
                    }
                }
            }
        };
        match &self.outline {
            Outline::Quad {
                start,
                bottom,
                right,
                top,
                left,
            } => {
                teams("bottom", Some(("start", *start)), bottom);
                teams("right", None, right);
                teams("top", None, top);
                teams("left", None, left);
            }
            Outline::Ring {
                inner_start,
                inner,
                outer_start,
                outer,
                ..
            } => {
                teams("inner", Some(("inner_start", *inner_start)), inner);
                teams("outer", Some(("outer_start", *outer_start)), outer);
            }
        }
        for (k, d) in self.darts.iter().enumerate() {
            out.push((format!("darts[{k}].apex"), d.apex));
        }
        for (k, p) in self.pleats.iter().enumerate() {
            out.push((format!("pleats[{k}].from"), p.from));
            out.push((format!("pleats[{k}].to"), p.to));
        }
        for (k, p) in self.fixed_points.iter().enumerate() {
            out.push((format!("fixed_points[{k}]"), *p));
        }
        for (k, m) in self.depth.iter().enumerate() {
            out.push((format!("depth[{k}].centre"), m.centre));
            out.push((format!("depth[{k}].height"), (m.height, 0.0)));
        }
        out
    }
}

/// The team named `name` on the four sides of a quad outline: (side, index in side, first
/// cell index along the side).
pub(crate) fn find_team(sides: &[Vec<ResolvedTeam>], name: &str) -> Option<(usize, usize, usize)> {
    for (s, side) in sides.iter().enumerate() {
        let mut offset = 0;
        for (k, t) in side.iter().enumerate() {
            if t.name == name {
                return Some((s, k, offset));
            }
            offset += t.cells;
        }
    }
    None
}

fn invalid(kind: ErrorKind, field: impl Into<String>, message: impl Into<String>) -> InvalidValue {
    InvalidValue::new(kind, field, message)
}

/// The most nodes one panel's grid may have (a 1000 × 1000 grid; the scaling benchmarks go
/// to 100 000 nodes). A larger count is almost certainly a typo, and would exhaust memory
/// rather than fail.
pub const MAX_PANEL_NODES: usize = 1_000_000;

impl Validate for PatternSpec {
    fn validate(&self) -> Result<(), InvalidValue> {
        for (field, p) in self.points() {
            if !(p.0.is_finite() && p.1.is_finite()) {
                return Err(invalid(
                    ErrorKind::NotFinite,
                    field,
                    format!("({}, {}) is not a finite point", p.0, p.1),
                ));
            }
        }
        let (g0, g1) = self.grain;
        if (g1.0 - g0.0).hypot(g1.1 - g0.1) == 0.0 {
            return Err(invalid(
                ErrorKind::OutOfRange,
                "grain",
                "the grain line's two points coincide",
            ));
        }
        let sides = self.resolve();
        let mut names = std::collections::HashSet::new();
        for team in sides.iter().flatten() {
            if team.cells == 0 {
                return Err(invalid(
                    ErrorKind::OutOfRange,
                    format!("{}.cells", team.field),
                    format!("team `{}` has 0 cells; it needs at least 1", team.name),
                ));
            }
            let length: f64 = team
                .polyline
                .windows(2)
                .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
                .sum();
            if length <= 1e-9 {
                return Err(invalid(
                    ErrorKind::OutOfRange,
                    format!("{}.path", team.field),
                    format!("team `{}` has zero length", team.name),
                ));
            }
            if !names.insert(team.name.clone()) {
                return Err(invalid(
                    ErrorKind::Inconsistent,
                    format!("{}.name", team.field),
                    format!("team name `{}` is used twice", team.name),
                ));
            }
        }
        let total = |k: usize| {
            sides[k]
                .iter()
                .fold(0usize, |a, t| a.saturating_add(t.cells))
        };
        let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) <= 1e-6;
        match &self.outline {
            Outline::Quad {
                start,
                bottom,
                right,
                top,
                left,
            } => {
                for (side, list) in [
                    ("bottom", bottom),
                    ("right", right),
                    ("top", top),
                    ("left", left),
                ] {
                    if list.is_empty() {
                        return Err(invalid(
                            ErrorKind::TooShort,
                            format!("outline.{side}"),
                            "every side needs at least one team",
                        ));
                    }
                }
                for (a, b, name) in [(0, 2, "bottom and top"), (1, 3, "right and left")] {
                    if total(a) != total(b) {
                        return Err(invalid(
                            ErrorKind::Inconsistent,
                            "outline",
                            format!(
                                "opposite groups {name} have {} and {} cells; a structured grid needs equal totals",
                                total(a),
                                total(b)
                            ),
                        ));
                    }
                }
                let nodes = (total(0).saturating_add(1)).saturating_mul(total(1).saturating_add(1));
                if nodes > MAX_PANEL_NODES {
                    return Err(invalid(
                        ErrorKind::OutOfRange,
                        "outline",
                        format!(
                            "{} × {} cells make {nodes} nodes; a panel may have at most {MAX_PANEL_NODES}",
                            total(0),
                            total(1)
                        ),
                    ));
                }
                let end = *sides[3]
                    .last()
                    .and_then(|t| t.polyline.last())
                    .expect("teams");
                if !close(end, [start.0, start.1]) {
                    return Err(invalid(
                        ErrorKind::Inconsistent,
                        "outline.left",
                        format!(
                            "the outline ends at ({}, {}), not at its start ({}, {})",
                            end[0], end[1], start.0, start.1
                        ),
                    ));
                }
            }
            Outline::Ring {
                inner_start,
                outer_start,
                radial_cells,
                ..
            } => {
                if sides[0].is_empty() || sides[1].is_empty() {
                    return Err(invalid(
                        ErrorKind::TooShort,
                        "outline",
                        "a ring needs inner and outer teams",
                    ));
                }
                if total(0) != total(1) || total(0) < 3 {
                    return Err(invalid(
                        ErrorKind::Inconsistent,
                        "outline",
                        format!(
                            "inner and outer loops have {} and {} cells; they must be equal and at least 3",
                            total(0),
                            total(1)
                        ),
                    ));
                }
                if *radial_cells == 0 {
                    return Err(invalid(
                        ErrorKind::OutOfRange,
                        "outline.radial_cells",
                        "a ring needs at least 1 radial cell",
                    ));
                }
                let nodes = total(0).saturating_mul(radial_cells.saturating_add(1));
                if nodes > MAX_PANEL_NODES {
                    return Err(invalid(
                        ErrorKind::OutOfRange,
                        "outline",
                        format!(
                            "{} × {radial_cells} cells make {nodes} nodes; a panel may have at most {MAX_PANEL_NODES}",
                            total(0)
                        ),
                    ));
                }
                for (k, start, name) in [(0, inner_start, "inner"), (1, outer_start, "outer")] {
                    let end = *sides[k]
                        .last()
                        .and_then(|t| t.polyline.last())
                        .expect("teams");
                    if !close(end, [start.0, start.1]) {
                        return Err(invalid(
                            ErrorKind::Inconsistent,
                            format!("outline.{name}"),
                            format!("the {name} loop does not return to its start"),
                        ));
                    }
                }
                if !self.darts.is_empty() {
                    return Err(invalid(
                        ErrorKind::Inconsistent,
                        "darts",
                        "darts are supported on Quad outlines only",
                    ));
                }
            }
        }
        let poly = self.outline_polygon();
        if let Some((a, b)) = self_intersection(&poly) {
            return Err(invalid(
                ErrorKind::Inconsistent,
                "outline",
                format!(
                    "the outline crosses itself near ({:.2}, {:.2}) and ({:.2}, {:.2})",
                    poly[a][0], poly[a][1], poly[b][0], poly[b][1]
                ),
            ));
        }
        // A boundary that folds back along itself (all corners on a line) crosses nowhere but
        // encloses nothing: say so here rather than as a grid without a cell of positive area.
        let (area, perimeter) =
            poly.iter()
                .zip(poly.iter().cycle().skip(1))
                .fold((0.0, 0.0), |(a, l), (p, q)| {
                    (
                        a + 0.5 * (p[0] * q[1] - q[0] * p[1]),
                        l + (q[0] - p[0]).hypot(q[1] - p[1]),
                    )
                });
        if area.abs() <= 1e-9 * perimeter * perimeter {
            return Err(invalid(
                ErrorKind::Inconsistent,
                "outline",
                format!(
                    "the outline encloses no area ({area:.3e} cm² inside a boundary of {perimeter:.2} cm): its sides are collinear or run back along each other"
                ),
            ));
        }
        for (k, d) in self.darts.iter().enumerate() {
            let Some((side, team, _)) = find_team(&sides, &d.opening) else {
                return Err(invalid(
                    ErrorKind::Inconsistent,
                    format!("darts[{k}].opening"),
                    format!("no team named `{}`", d.opening),
                ));
            };
            if !contains(&poly, [d.apex.0, d.apex.1]) {
                return Err(invalid(
                    ErrorKind::OutOfRange,
                    format!("darts[{k}].apex"),
                    format!("apex ({}, {}) lies outside the panel", d.apex.0, d.apex.1),
                ));
            }
            let across = total((side + 1) % 4);
            if d.cells == 0 || d.cells >= across {
                return Err(invalid(
                    ErrorKind::OutOfRange,
                    format!("darts[{k}].cells"),
                    format!(
                        "legs of {} cells; they need 1 to {} (the grid is {across} cells across)",
                        d.cells,
                        across - 1
                    ),
                ));
            }
            let _ = team;
        }
        for (k, p) in self.fixed_points.iter().enumerate() {
            if !contains(&poly, [p.0, p.1]) {
                return Err(invalid(
                    ErrorKind::OutOfRange,
                    format!("fixed_points[{k}]"),
                    format!("({}, {}) lies outside the panel", p.0, p.1),
                ));
            }
        }
        for (k, p) in self.pleats.iter().enumerate() {
            for (end, q) in [("from", p.from), ("to", p.to)] {
                if !contains(&poly, [q.0, q.1]) {
                    return Err(invalid(
                        ErrorKind::OutOfRange,
                        format!("pleats[{k}].{end}"),
                        format!("({}, {}) lies outside the panel", q.0, q.1),
                    ));
                }
            }
        }
        if let Some(imp) = &self.improve {
            for (name, c) in [("c1", imp.c1), ("c2", imp.c2), ("c3", imp.c3)] {
                if !(c.is_finite() && c >= 0.0) {
                    return Err(invalid(
                        ErrorKind::OutOfRange,
                        format!("improve.{name}"),
                        format!("weight {c} must be finite and ≥ 0"),
                    ));
                }
            }
        }
        Ok(())
    }
}
