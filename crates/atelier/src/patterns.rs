//! `atelier pattern FILE --out DIR`: a pattern file from pattern software or apparel CAD
//! (DXF-AAMA, [`atelier_import`]) read into pieces, each made an atelier pattern and gridded;
//! written as one pattern RON and one grid OBJ per piece and a picture of all pieces
//! (`docs/patterns-import.md`). Composes the importer and the gridder; computes nothing itself.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use atelier_files::{ErrorKind, FileError};
use atelier_grid::ImproveParams;
use atelier_grid::pattern::{
    Garment, Panel, PanelPattern, PanelRef, drafted_pattern, load_garment_with,
};
use atelier_import::{ImportError, PanelOptions, Piece, PieceProblem, Plan, plan_and_grid};

use crate::export::{ExportError, MeshPart, write_obj};

/// A piece read, planned and gridded.
#[derive(Clone, Debug)]
pub struct ImportedPiece {
    /// As read.
    pub piece: Piece,
    /// Its pattern.
    pub plan: Plan,
    /// Its grid.
    pub panel: Panel,
}

/// Everything read from a pattern file.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The pieces, in file order.
    pub pieces: Vec<ImportedPiece>,
    /// What was read but not used (entities, layers), one line each.
    pub warnings: Vec<String>,
}

/// What can go wrong: reading the file, making a piece a pattern, gridding it, writing.
#[derive(Debug, thiserror::Error)]
pub enum PatternError {
    /// The file or a piece in it.
    #[error(transparent)]
    Import(#[from] ImportError),
    /// A piece that cannot be made a four-sided pattern, or whose pattern cannot be gridded.
    #[error("{}: piece {piece:?}: {problem}", file.display())]
    Plan {
        /// The file.
        file: PathBuf,
        /// The piece.
        piece: String,
        /// Why.
        problem: PieceProblem,
    },
    /// An output could not be written.
    #[error("{}: {message}", path.display())]
    Write {
        /// The output.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

/// Read a pattern file (`.dxf` DXF-AAMA, `.svg` FreeSewing) and grid every piece.
pub fn import(file: &Path, options: &PanelOptions) -> Result<Imported, PatternError> {
    let read = atelier_import::read(file)?;
    let provenance = format!("imported from {}", file.display());
    let mut pieces = Vec::with_capacity(read.pieces.len());
    for piece in read.pieces {
        let (plan, panel) = plan_and_grid(&piece, options, &provenance, ImproveParams::default())
            .map_err(|problem| PatternError::Plan {
            file: file.to_path_buf(),
            piece: piece.name.clone(),
            problem,
        })?;
        pieces.push(ImportedPiece { piece, plan, panel });
    }
    Ok(Imported {
        pieces,
        warnings: read.warnings,
    })
}

/// Read a garment file whose panels are atelier pattern files or pieces of files from pattern
/// software (`piece: "…"` with a `.dxf` or `.svg` pattern): each imported piece planned like
/// `atelier pattern` plans it (2 cm cells, its corners given or searched, `notches` added), its
/// cell counts then matched across the seams by the gridder
/// (`atelier_grid::pattern::load_garment_with`). A file is read once however many panels name
/// its pieces; the import's warnings are not errors and are not repeated here (`atelier pattern`
/// and `atelier validate` print them).
pub fn load_garment(path: &Path, params: ImproveParams) -> Result<Garment, FileError> {
    let mut files: HashMap<PathBuf, Vec<Piece>> = HashMap::new();
    let mut resolve = |file: &Path, panel: &PanelRef| -> Result<PanelPattern, FileError> {
        let Some(name) = &panel.piece else {
            return drafted_pattern(file, panel);
        };
        let fail = |field: &str, kind: ErrorKind, message: String| FileError {
            file: file.to_path_buf(),
            position: None,
            field: field.to_owned(),
            kind,
            message,
            source: None,
        };
        if !files.contains_key(file) {
            let read = atelier_import::read(file).map_err(|e| {
                fail(
                    "",
                    ErrorKind::Inconsistent,
                    format!("panel `{}`: {e}", panel.name),
                )
            })?;
            files.insert(file.to_path_buf(), read.pieces);
        }
        let pieces = &files[file];
        let mut piece = pieces
            .iter()
            .find(|p| p.name == *name)
            .cloned()
            .ok_or_else(|| {
                let names: Vec<&str> = pieces.iter().map(|p| p.name.as_str()).collect();
                fail(
                    "piece",
                    ErrorKind::Inconsistent,
                    format!(
                        "panel `{}`: the file has no piece named `{name}` (it has: {})",
                        panel.name,
                        names.join(", ")
                    ),
                )
            })?;
        for (k, &(x, y)) in panel.notches.iter().enumerate() {
            let v = piece.vertex_at([x, y]).ok_or_else(|| {
                fail(
                    &format!("notches[{k}]"),
                    ErrorKind::Inconsistent,
                    format!(
                        "panel `{}`: notch ({x}, {y}) cm is not on the outline of piece `{name}`",
                        panel.name
                    ),
                )
            })?;
            if !piece.notches.contains(&v) {
                piece.notches.push(v);
            }
        }
        let options = PanelOptions {
            corners: panel.corners.map(|c| c.map(|(x, y)| [x, y])),
            ..PanelOptions::default()
        };
        let provenance = format!("piece `{name}` imported from {}", file.display());
        let (plan, _) =
            plan_and_grid(&piece, &options, &provenance, params).map_err(|problem| {
                fail(
                    "piece",
                    ErrorKind::Inconsistent,
                    format!("panel `{}` (piece `{name}`): {problem}", panel.name),
                )
            })?;
        Ok(PanelPattern {
            spec: plan.spec,
            counts_free: true,
        })
    };
    load_garment_with(path, params, &mut resolve)
}

/// A file name for a piece: letters and digits kept, the rest `_`.
pub fn slug(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() { "piece".into() } else { s }
}

/// Write each piece's pattern (`NAME.ron`, atelier's pattern format) and grid (`NAME.obj`, in
/// metres in the pattern plane) into `out`; returns the files written.
pub fn write_pieces(imported: &Imported, out: &Path) -> Result<Vec<PathBuf>, PatternError> {
    let fail = |path: &Path, message: String| PatternError::Write {
        path: path.to_path_buf(),
        message,
    };
    std::fs::create_dir_all(out).map_err(|e| fail(out, e.to_string()))?;
    let mut written = Vec::new();
    for p in &imported.pieces {
        let name = slug(&p.piece.name);
        let ron_path = out.join(format!("{name}.ron"));
        // The reader's extensions: `Line(x, y)`, not `Line((x, y))`.
        let config = ron::ser::PrettyConfig::new().extensions(
            ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES
                | ron::extensions::Extensions::IMPLICIT_SOME,
        );
        let text = ron::ser::to_string_pretty(&p.plan.spec, config)
            .map_err(|e| fail(&ron_path, e.to_string()))?;
        let text = format!(
            "// {} — written by `atelier pattern`: teams are named by their breakpoints, counter-clockwise from the grid's first corner\n{text}\n",
            p.piece.name
        );
        atelier_files::files::write_atomic(&ron_path, text.as_bytes())
            .map_err(|e| fail(&ron_path, e.to_string()))?;
        written.push(ron_path);
        let obj_path = out.join(format!("{name}.obj"));
        let topology = &p.panel.topology;
        let positions: Vec<[f64; 3]> = topology
            .rest_positions()
            .iter()
            .map(|q| [q[0], q[1], 0.0])
            .collect();
        let part = MeshPart {
            vertex_colours: None,
            frame_values: None,
            name: &p.piece.name,
            triangles: topology.triangles(),
            colour: [0.8, 0.8, 0.8],
            double_sided: true,
        };
        write_obj(&obj_path, &[(part, &positions)])
            .map_err(|e: ExportError| fail(&obj_path, e.to_string()))?;
        written.push(obj_path);
    }
    Ok(written)
}

/// The pieces as drawings for [`crate::chart::write_pieces`] (cm): the seam line, the grid's
/// axial edges, grain line, notches, corners, darts and internal lines.
pub fn drawings(imported: &Imported) -> Vec<crate::chart::PieceDrawing> {
    let pt = |p: [f64; 2]| (p[0], p[1]);
    imported
        .pieces
        .iter()
        .map(|p| {
            let topology = &p.panel.topology;
            let rest = topology.rest_positions();
            let cm = |k: u32| {
                let q = rest[k as usize];
                (q[0] * 100.0, q[1] * 100.0)
            };
            crate::chart::PieceDrawing {
                name: p.piece.name.clone(),
                outline: p.piece.outline.iter().copied().map(pt).collect(),
                grid: topology
                    .edges()
                    .iter()
                    .filter(|e| e.kind.is_axial())
                    .map(|e| [cm(e.a), cm(e.b)])
                    .collect(),
                grain: p.piece.grain.map(|(a, b)| [pt(a), pt(b)]),
                notches: p
                    .piece
                    .notches
                    .iter()
                    .map(|&k| pt(p.piece.outline[k]))
                    .collect(),
                corners: p
                    .plan
                    .corners
                    .iter()
                    .map(|&k| pt(p.plan.breakpoints[k]))
                    .collect(),
                darts: p
                    .piece
                    .darts
                    .iter()
                    .map(|d| {
                        [
                            pt(p.piece.outline[d.from]),
                            pt(d.apex),
                            pt(p.piece.outline[d.to]),
                        ]
                    })
                    .collect(),
                lines: p
                    .piece
                    .internal
                    .iter()
                    .map(|l| l.iter().copied().map(pt).collect())
                    .collect(),
                breakpoints: p.plan.breakpoints.iter().copied().map(pt).collect(),
            }
        })
        .collect()
}
