//! Garments: panels (pattern files) and seams (pairs of teams, across panels or within one,
//! with orientation). A seam's teams must have the same node count (thesis §4.4.2).

use std::path::{Path, PathBuf};

use atelier_files::check::non_empty;
use atelier_files::files::load_ron;
use atelier_files::{ErrorKind, FileError, Position};
use serde::{Deserialize, Serialize};

use super::build::{Panel, grid_pattern};
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

/// A panel of a garment: a pattern file, relative to the garment file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PanelRef {
    /// Name the seams use.
    pub name: String,
    /// Pattern file.
    pub pattern: PathBuf,
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

/// Read a garment file, grid every panel, and pair the seams' nodes.
pub fn load_garment(path: &Path, params: ImproveParams) -> Result<Garment, FileError> {
    let spec: GarmentSpec = load_ron(path)?;
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let base = path.parent().unwrap_or(Path::new("."));
    let mut panels = Vec::with_capacity(spec.panels.len());
    for p in &spec.panels {
        let file = base.join(&p.pattern);
        let pattern = load_pattern(&file)?;
        let mut panel =
            grid_pattern(&pattern, params).map_err(|e| FileError::from_invalid(&file, e))?;
        panel.name = p.name.clone();
        panels.push(panel);
    }
    let fail = |k: usize, kind: ErrorKind, message: String| FileError {
        file: path.to_path_buf(),
        position: entry_position(&text, "seams", k),
        field: format!("seams[{k}]"),
        kind,
        message,
        source: None,
    };
    let mut seams = Vec::with_capacity(spec.seams.len());
    for (k, s) in spec.seams.iter().enumerate() {
        let find = |(panel, team): &(String, String)| -> Result<(usize, Vec<u32>), FileError> {
            let pi = panels
                .iter()
                .position(|p| p.name == *panel)
                .ok_or_else(|| {
                    fail(
                        k,
                        ErrorKind::Inconsistent,
                        format!("no panel named `{panel}`"),
                    )
                })?;
            let t = panels[pi]
                .teams
                .iter()
                .find(|t| t.name == *team)
                .ok_or_else(|| {
                    fail(
                        k,
                        ErrorKind::Inconsistent,
                        format!("panel `{panel}` has no team named `{team}`"),
                    )
                })?;
            Ok((pi, t.nodes.clone()))
        };
        let (pa, na) = find(&s.a)?;
        let (pb, mut nb) = find(&s.b)?;
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
