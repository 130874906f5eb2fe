//! Garments: panels (pattern files) and seams (pairs of teams, across panels or within one,
//! with orientation). A seam's teams must have the same node count (thesis §4.4.2).

use std::path::{Path, PathBuf};

use atelier_files::check::non_empty;
use atelier_files::files::load_ron;
use atelier_files::{ErrorKind, FileError, InvalidValue, Position};
use serde::{Deserialize, Serialize};

use super::build::{Panel, grid_pattern};
use super::counts::{match_seam_counts, rescale_darts};
use super::geometry::Point;
use super::spec::PatternSpec;
use crate::improve::ImproveParams;

/// A garment file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentSpec {
    /// Garment name.
    #[serde(deserialize_with = "non_empty")]
    pub name: String,
    /// Where the design comes from.
    #[serde(deserialize_with = "non_empty")]
    pub provenance: String,
    /// The panels.
    pub panels: Vec<PanelRef>,
    /// The seams.
    pub seams: Vec<SeamSpec>,
}

/// A panel of a garment: a pattern file, relative to the garment file — an atelier pattern
/// (RON), or a piece of a file from pattern software or CAD (`.dxf` DXF-AAMA, `.svg`
/// FreeSewing), read by the facade's loader (`atelier::patterns::load_garment`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PanelRef {
    /// Name the seams use.
    pub name: String,
    /// Pattern file.
    pub pattern: PathBuf,
    /// The piece of an imported file (its name in the file); its teams are named by their
    /// breakpoints, `"k-(k+1)"`, as `atelier pattern` writes and draws them.
    #[serde(default)]
    pub piece: Option<String>,
    /// Cut from the other side of the fabric: the pattern mirrored about x = 0 (a left half
    /// from a right half's pattern). Teams keep their names.
    #[serde(default)]
    pub mirrored: bool,
    /// An imported piece's four grid corners (cm, points on its outline, counter-clockwise from
    /// the bottom side's start); searched when absent.
    #[serde(default)]
    pub corners: Option<[Point; 4]>,
    /// Points (cm) on an imported piece's outline where a team ends, as at a notch the file
    /// does not mark (where a seam stops: the top of a vent).
    #[serde(default)]
    pub notches: Vec<Point>,
}

/// A panel's pattern before gridding, as a [`PanelRef`] resolves to.
#[derive(Clone, Debug, PartialEq)]
pub struct PanelPattern {
    /// The pattern (before mirroring).
    pub spec: PatternSpec,
    /// Whether the gridder may change its cell counts to match seams: an imported piece's
    /// counts came from a cell size; a drafted pattern's are the drafter's.
    pub counts_free: bool,
}

/// A seam: team `a` of one panel sewn to team `b` of the same or another panel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamSpec {
    /// Seam name.
    pub name: String,
    /// (panel, team).
    pub a: (String, String),
    /// (panel, team).
    pub b: (String, String),
    /// Pair `a`'s first node with `b`'s last (two panels traversed counter-clockwise meet
    /// this way along a side seam).
    pub reversed: bool,
}

/// A seam as node pairs.
#[derive(Clone, Debug, PartialEq)]
pub struct Seam {
    /// Seam name.
    pub name: String,
    /// Panel index of side `a`.
    pub panel_a: usize,
    /// Panel index of side `b`.
    pub panel_b: usize,
    /// (node of `a`, node of `b`), topology node indices of their panels.
    pub pairs: Vec<(u32, u32)>,
}

/// A gridded garment.
#[derive(Clone, Debug)]
pub struct Garment {
    /// Garment name.
    pub name: String,
    /// Panels in file order (their names are the names the garment gave them).
    pub panels: Vec<Panel>,
    /// Seams between or within panels (dart legs are in each panel's `darts`).
    pub seams: Vec<Seam>,
}

/// Read and check a pattern file.
pub fn load_pattern(path: &Path) -> Result<PatternSpec, FileError> {
    load_ron(path)
}

/// Read a garment file, grid every panel, and pair the seams' nodes. Panels are atelier
/// pattern files (RON); a garment naming pieces of imported files needs
/// `atelier::patterns::load_garment`, which reads them.
pub fn load_garment(path: &Path, params: ImproveParams) -> Result<Garment, FileError> {
    load_garment_with(path, params, &mut drafted_pattern)
}

/// The pattern of a panel that names an atelier pattern file.
pub fn drafted_pattern(file: &Path, panel: &PanelRef) -> Result<PanelPattern, FileError> {
    let imported = matches!(
        file.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("dxf" | "svg")
    );
    if imported || panel.piece.is_some() || panel.corners.is_some() || !panel.notches.is_empty() {
        return Err(FileError {
            file: file.to_path_buf(),
            position: None,
            field: "piece".into(),
            kind: ErrorKind::Inconsistent,
            message: format!(
                "panel `{}` names a piece of a pattern file from pattern software (piece, corners, notches, .dxf or .svg); this loader reads atelier pattern files only (the facade's `atelier::patterns::load_garment` reads both)",
                panel.name
            ),
            source: None,
        });
    }
    Ok(PanelPattern {
        spec: load_pattern(file)?,
        counts_free: false,
    })
}

/// [`load_garment`] with the panels' patterns from `pattern(file, panel)` (`file` is the panel's
/// pattern path joined to the garment's folder): mirrored where the garment says, their free cell
/// counts matched across the seams ([`match_seam_counts`]), gridded, and the seams paired.
pub fn load_garment_with(
    path: &Path,
    params: ImproveParams,
    pattern: &mut dyn FnMut(&Path, &PanelRef) -> Result<PanelPattern, FileError>,
) -> Result<Garment, FileError> {
    let spec: GarmentSpec = load_ron(path)?;
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let base = path.parent().unwrap_or(Path::new("."));
    let panel_fail = |k: usize, kind: ErrorKind, message: String| FileError {
        file: path.to_path_buf(),
        position: entry_position(&text, "panels", k),
        field: format!("panels[{k}]"),
        kind,
        message,
        source: None,
    };
    let mut specs = Vec::with_capacity(spec.panels.len());
    let mut free = Vec::with_capacity(spec.panels.len());
    for (k, p) in spec.panels.iter().enumerate() {
        let file = base.join(&p.pattern);
        let PanelPattern {
            spec: mut s,
            counts_free,
        } = pattern(&file, p)?;
        if p.mirrored {
            s = s.mirrored().ok_or_else(|| {
                panel_fail(
                    k,
                    ErrorKind::Inconsistent,
                    format!("panel `{}`: a ring pattern cannot be mirrored", p.name),
                )
            })?;
        }
        specs.push(s);
        free.push(counts_free);
    }
    let fail = |k: usize, kind: ErrorKind, message: String| FileError {
        file: path.to_path_buf(),
        position: entry_position(&text, "seams", k),
        field: format!("seams[{k}]"),
        kind,
        message,
        source: None,
    };
    // Seams by panel index, their teams checked to exist.
    let team_names: Vec<Vec<String>> = specs
        .iter()
        .map(|s| s.resolve().into_iter().flatten().map(|t| t.name).collect())
        .collect();
    let mut joined = Vec::with_capacity(spec.seams.len());
    for (k, s) in spec.seams.iter().enumerate() {
        let find = |(panel, team): &(String, String)| -> Result<usize, FileError> {
            let pi = spec
                .panels
                .iter()
                .position(|p| p.name == *panel)
                .ok_or_else(|| {
                    fail(
                        k,
                        ErrorKind::Inconsistent,
                        format!("no panel named `{panel}`"),
                    )
                })?;
            if !team_names[pi].contains(team) {
                return Err(fail(
                    k,
                    ErrorKind::Inconsistent,
                    format!("panel `{panel}` has no team named `{team}`"),
                ));
            }
            Ok(pi)
        };
        let (pa, pb) = (find(&s.a)?, find(&s.b)?);
        if pa == pb && s.a.1 == s.b.1 {
            return Err(fail(
                k,
                ErrorKind::Inconsistent,
                format!(
                    "seam `{}` joins team `{}` of panel `{}` to itself; a seam joins two different teams (a panel sewn to itself joins two of its own teams, as a tube)",
                    s.name, s.a.1, s.a.0
                ),
            ));
        }
        joined.push(((pa, s.a.1.clone()), (pb, s.b.1.clone())));
    }
    if free.iter().any(|&f| f) {
        let planned = specs.clone();
        match_seam_counts(&mut specs, &free, &joined).map_err(|e| FileError {
            file: path.to_path_buf(),
            position: entry_position(&text, "seams", 0),
            field: "seams".into(),
            kind: ErrorKind::Inconsistent,
            message: e.to_string(),
            source: None,
        })?;
        for ((s, before), _) in specs
            .iter_mut()
            .zip(&planned)
            .zip(&free)
            .filter(|(_, f)| **f)
        {
            rescale_darts(before, s);
        }
    }
    let mut panels = Vec::with_capacity(specs.len());
    for ((p, s), &counts_free) in spec.panels.iter().zip(&specs).zip(&free) {
        let gridded = if counts_free {
            grid_fitting_darts(s.clone(), params).map(|(_, panel)| panel)
        } else {
            grid_pattern(s, params)
        };
        let mut panel = gridded.map_err(|e| {
            let mut e = FileError::from_invalid(base.join(&p.pattern), e);
            let notes: Vec<&str> = [
                (p.mirrored, "mirrored"),
                (counts_free, "cell counts matched across the seams"),
            ]
            .into_iter()
            .filter_map(|(on, what)| on.then_some(what))
            .collect();
            if !notes.is_empty() {
                e.message = format!("panel `{}` ({}): {}", p.name, notes.join(", "), e.message);
            }
            e
        })?;
        panel.name = p.name.clone();
        panels.push(panel);
    }
    let mut seams = Vec::with_capacity(spec.seams.len());
    for (k, (s, ((pa, ta), (pb, tb)))) in spec.seams.iter().zip(joined).enumerate() {
        let nodes = |pi: usize, team: &str| -> Vec<u32> {
            panels[pi]
                .teams
                .iter()
                .find(|t| t.name == team)
                .map(|t| t.nodes.clone())
                .unwrap_or_default()
        };
        let (na, mut nb) = (nodes(pa, &ta), nodes(pb, &tb));
        if na.len() != nb.len() {
            return Err(fail(
                k,
                ErrorKind::Inconsistent,
                format!(
                    "seam `{}` joins {}.{} ({} nodes) to {}.{} ({} nodes); the counts must match",
                    s.name,
                    s.a.0,
                    s.a.1,
                    na.len(),
                    s.b.0,
                    s.b.1,
                    nb.len()
                ),
            ));
        }
        if s.reversed {
            nb.reverse();
        }
        seams.push(Seam {
            name: s.name.clone(),
            panel_a: pa,
            panel_b: pb,
            pairs: na.into_iter().zip(nb).collect(),
        });
    }
    Ok(Garment {
        name: spec.name,
        panels,
        seams,
    })
}

/// Grid a free pattern; when a dart runs into another constraint in the grid (or its legs are
/// longer than the grid is across), that dart's legs get one cell fewer until it fits or has
/// one cell. Returns the pattern as fitted with its grid (`atelier_import` fits the darts of a
/// piece it plans this way too).
pub fn grid_fitting_darts(
    mut spec: PatternSpec,
    params: ImproveParams,
) -> Result<(PatternSpec, Panel), InvalidValue> {
    loop {
        let e = match grid_pattern(&spec, params) {
            Ok(panel) => return Ok((spec, panel)),
            Err(e) => e,
        };
        let dart = e
            .field
            .strip_prefix("darts[")
            .and_then(|r| r.split(']').next())
            .and_then(|k| k.parse::<usize>().ok())
            .filter(|_| e.message.contains("overlaps") || e.message.contains("they need"));
        match dart.and_then(|k| spec.darts.get_mut(k)) {
            Some(d) if d.cells > 1 => d.cells -= 1,
            _ => return Err(e),
        }
    }
}

/// Where the `k`-th entry of the list under `key` starts in a RON text (1-based line and
/// column): the `k`-th parenthesis opened directly inside the list, skipping strings and
/// comments. `None` when the text does not have it.
fn entry_position(text: &str, key: &str, k: usize) -> Option<Position> {
    let start = text.find(&format!("{key}:"))?;
    let (mut depth, mut seen, mut in_string, mut line_comment) = (0i32, 0usize, false, false);
    let mut prev = '\0';
    for (offset, c) in text[start..].char_indices() {
        if line_comment {
            line_comment = c != '\n';
        } else if in_string {
            in_string = !(c == '"' && prev != '\\');
        } else {
            match c {
                '"' => in_string = true,
                '/' if prev == '/' => line_comment = true,
                '[' => depth += 1,
                ']' => {
                    depth -= 1;
                    if depth == 0 {
                        return None;
                    }
                }
                '(' => {
                    if depth == 1 {
                        if seen == k {
                            let before = &text[..start + offset];
                            let line = before.matches('\n').count() + 1;
                            let column = before.len() - before.rfind('\n').map_or(0, |p| p + 1) + 1;
                            return Some(Position { line, column });
                        }
                        seen += 1;
                    }
                    depth += 1;
                }
                ')' => depth -= 1,
                _ => {}
            }
        }
        prev = c;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_are_located() {
        let text = "(\n  name: \"x\",\n  seams: [\n    (a: (\"p\", \"t\")),\n    // (skip)\n    (a: (\"q\", \"[\")),\n  ],\n)";
        let p = entry_position(text, "seams", 1).expect("found");
        assert_eq!((p.line, p.column), (6, 5));
        assert!(entry_position(text, "seams", 2).is_none());
    }
}
