//! `atelier validate FILE…`: check atelier's data files — fabrics, patterns, garments, body
//! descriptions, motions, range-image side files, scenarios, try-on poses (RON), external
//! bodies (OBJ, PLY) and DXF-AAMA pattern files — and report each problem with
//! file:line:column and field (for a DXF file: the piece and the entity).
//!
//! A RON file's kind is found by trying each format: the first that reads it names it; when none
//! does, the error reported is the one that got furthest into the file (the format the file most
//! likely is), with that format's name; an error found after the file was read whole as a format
//! (a garment whose panel does not grid, a scenario naming a missing file) goes furthest.

use std::path::Path;

use atelier_fabric::{FileError, Position};

/// What a file turned out to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A fabric (`fixtures/fabrics`).
    Fabric,
    /// A sewing pattern.
    Pattern,
    /// A garment (panels and seams; its patterns are read and gridded too).
    Garment,
    /// A mannequin description.
    BodyDescription,
    /// A motion (checked against the default 9AR mannequin's joint limits).
    Motion,
    /// A range image's side file.
    RangeSide,
    /// An external body mesh (OBJ or PLY).
    Mesh,
    /// A scenario (the files it names must exist).
    Scenario,
    /// A try-on pose (`atelier tryon --pose`, `fitted_pose.ron`).
    TryonPose,
    /// A pattern file from pattern software or CAD (DXF-AAMA, FreeSewing SVG): read, each piece
    /// planned and gridded.
    DxfPattern,
}

impl Kind {
    /// Lower-case name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Fabric => "fabric",
            Kind::Pattern => "pattern",
            Kind::Garment => "garment",
            Kind::BodyDescription => "body description",
            Kind::Motion => "motion",
            Kind::RangeSide => "range side file",
            Kind::Mesh => "mesh",
            Kind::Scenario => "scenario",
            Kind::TryonPose => "try-on pose",
            Kind::DxfPattern => "pattern file (DXF-AAMA or FreeSewing SVG)",
        }
    }
}

/// The outcome for one file: its kind, or the error (with the kind it was most likely meant to
/// be, when known).
pub type Outcome = Result<Kind, (Option<Kind>, FileError)>;

/// Check one file.
pub fn validate(path: &Path) -> Outcome {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if ext == "obj" || ext == "ply" {
        return atelier_body::io::load_mesh(path)
            .map(|_| Kind::Mesh)
            .map_err(|e| (Some(Kind::Mesh), e));
    }
    if ext == "dxf" || ext == "svg" {
        return atelier::patterns::import(path, &atelier_import::PanelOptions::default())
            .map(|_| Kind::DxfPattern)
            .map_err(|e| {
                let full = e.to_string();
                let prefix = format!("{}: ", path.display());
                let message = full.strip_prefix(&prefix).unwrap_or(&full).to_owned();
                let kind = match &e {
                    atelier::patterns::PatternError::Import(
                        atelier_import::ImportError::Read { .. },
                    ) => atelier_fabric::ErrorKind::Io,
                    _ => atelier_fabric::ErrorKind::Inconsistent,
                };
                let error = FileError {
                    file: path.to_path_buf(),
                    position: None,
                    field: String::new(),
                    kind,
                    message,
                    source: None,
                };
                (Some(Kind::DxfPattern), error)
            });
    }
    // Unreadable files: one error, no guessing.
    if let Err(e) = std::fs::metadata(path) {
        return Err((
            None,
            FileError {
                file: path.to_path_buf(),
                position: None,
                field: String::new(),
                kind: atelier_fabric::ErrorKind::Io,
                message: e.to_string(),
                source: Some(e),
            },
        ));
    }
    // A file that reads as a scenario is one: its later checks (ranges, metric names, the
    // files it names) must not lose to another format's parse error.
    if let Ok(s) = atelier_files::files::load_ron::<atelier::scenario::Scenario>(path) {
        return atelier::scenario::Scenario::load(path)
            .and_then(|_| {
                s.check_files(&atelier::run::base_of(path))
                    .map_err(|e| FileError::from_invalid(path, e))
            })
            .map(|()| Kind::Scenario)
            .map_err(|e| (Some(Kind::Scenario), e));
    }
    let attempts: [(Kind, &Check); 8] = [
        (Kind::Fabric, &|p| {
            atelier_fabric::Fabric::load(p).map(|_| ())
        }),
        (Kind::Pattern, &|p| {
            let spec = atelier_grid::pattern::load_pattern(p)?;
            atelier_grid::pattern::grid_pattern(&spec, atelier_grid::ImproveParams::default())
                .map(|_| ())
                .map_err(|e| FileError::from_invalid(p, e))
        }),
        (Kind::Garment, &|p| {
            atelier::patterns::load_garment(p, atelier_grid::ImproveParams::default()).map(|_| ())
        }),
        (Kind::BodyDescription, &|p| {
            atelier_body::description::BodyDescription::load(p).map(|_| ())
        }),
        (Kind::Motion, &|p| {
            atelier_body::Motion::load(p, &atelier_body::build::jis_9ar()).map(|_| ())
        }),
        (Kind::RangeSide, &|p| {
            atelier_files::files::load_ron::<atelier_body::range::SideFile>(p).map(|_| ())
        }),
        (Kind::TryonPose, &|p| {
            let pose: atelier_tryon::pose::PoseFile = atelier_files::files::load_ron(p)?;
            pose.check().map_err(|e| FileError::from_invalid(p, e))
        }),
        (Kind::Scenario, &|p| {
            let s = atelier::scenario::Scenario::load(p)?;
            s.check_files(&atelier::run::base_of(p))
                .map_err(|e| FileError::from_invalid(p, e))
        }),
    ];
    let mut best: Option<(Kind, FileError)> = None;
    for (kind, attempt) in attempts {
        match attempt(path) {
            Ok(()) => return Ok(kind),
            Err(e) => {
                // An error found after the file was read as this kind (no position in it, or
                // in a file it names) goes furthest of all: the file is that kind.
                let read_as = |e: &FileError| e.position.is_none() || e.file != path;
                let further = match &best {
                    None => true,
                    Some((_, b)) if read_as(b) => false,
                    Some(_) if read_as(&e) => true,
                    Some((_, b)) => match (e.position, b.position) {
                        (Some(p), Some(q)) => later(p, q),
                        _ => false,
                    },
                };
                if further {
                    best = Some((kind, e));
                }
            }
        }
    }
    let (kind, e) = best.expect("at least one attempt");
    Err((Some(kind), e))
}

/// A reader that checks a file as one kind.
type Check = dyn Fn(&Path) -> Result<(), FileError>;

fn later(a: Position, b: Position) -> bool {
    (a.line, a.column) > (b.line, b.column)
}

/// One line per file: `ok  FILE (kind)` or `error  FILE:LINE:COL: field …: message (as kind)`.
pub fn report_line(path: &Path, outcome: &Outcome) -> String {
    match outcome {
        Ok(kind) => format!("ok     {} ({})", path.display(), kind.name()),
        Err((kind, e)) => match kind {
            Some(k) => format!("error  {e} (read as a {})", k.name()),
            None => format!("error  {e}"),
        },
    }
}
