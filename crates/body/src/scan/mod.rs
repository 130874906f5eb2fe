//! A body scan (one triangle mesh, metres, the body frame: x the body's left, y up, z forward,
//! feet near y = 0) made into the articulated body of a garment scene:
//!
//! 1. [`repair::check_and_repair`] — checks (indices, finite coordinates, face areas, a plausible height,
//!    no edge in three or more faces), a consistent orientation, small holes closed, debris
//!    dropped, inside-out pieces turned over ([`Repair`] reports each step);
//! 2. [`landmarks`] found on horizontal sections and on rings along the limbs, optionally given
//!    or overridden by a RON file ([`LandmarkFile`]);
//! 3. [`segment()`]: every vertex and triangle labelled with one of the 17 parts, then
//!    [`mannequin`] articulates it with the 9AR mannequin's joint limits.
//!
//! ```no_run
//! use atelier_body::io::load_mesh;
//! use atelier_body::scan::{ScanOptions, mannequin, prepare};
//! let scan = prepare(load_mesh("scan.obj".as_ref())?, &ScanOptions::default(), None)?;
//! println!("{} holes closed, waist {:.1} cm", scan.repair.holes.len(), 100.0 * scan.landmarks.waist.girth);
//! let body = mannequin(&scan)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod landmarks;
pub(crate) mod limbs;
pub mod repair;
pub mod segment;
pub(crate) mod slice;

pub use landmarks::{Girth, LandmarkFile, Landmarks, find_landmarks};
pub use limbs::ANKLE_HEIGHT;
pub use repair::{ClosedHole, Repair};
pub use segment::segment;

use crate::articulate::{ArticulateError, articulate};
use crate::io::ExternalBody;
use crate::model::{LabelledMesh, Mannequin, V3};

/// Limits of the checks and the repair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanOptions {
    /// Largest hole closed, as the length of its border, m. Default 0.15 m: the holes a scanner
    /// leaves (under the chin, between the fingers, the crown, the soles' edges) are a few
    /// centimetres across; a border of 15 cm is a 5 cm wide hole, about as wide as a wrist, and
    /// anything larger (a missing hand, an open top of the head) is not guessed at.
    pub max_hole_perimeter: f64,
    /// Smallest plausible height (highest − lowest y), m (default 0.5).
    pub min_height: f64,
    /// Largest plausible height, m (default 3).
    pub max_height: f64,
    /// Connected pieces with less than this share of the total area are dropped as debris
    /// (default 0.005; set 0 to keep every piece, e.g. for a body made of overlapping parts).
    pub min_piece_area: f64,
    /// Spacing of the horizontal sections and of the rings along the limbs, m (default 0.005).
    pub step: f64,
}

impl Default for ScanOptions {
    fn default() -> Self {
        ScanOptions {
            max_hole_perimeter: 0.15,
            min_height: 0.5,
            max_height: 3.0,
            min_piece_area: 0.005,
            step: 0.005,
        }
    }
}

/// Why a scan cannot be used. Vertex and triangle numbers are 0-based (add 1 for an OBJ line's
/// numbering).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ScanError {
    /// No triangles or no vertices.
    #[error("the scan has no triangles")]
    Empty,
    /// A vertex with a NaN or infinite coordinate.
    #[error("vertex {vertex} has a coordinate that is not a finite number")]
    NotFinite {
        /// The vertex.
        vertex: usize,
    },
    /// A triangle naming a vertex that does not exist.
    #[error("triangle {triangle} names vertex {vertex}, but the scan has {count} vertices")]
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The vertex named.
        vertex: u32,
        /// Vertices in the scan.
        count: usize,
    },
    /// A triangle without area (a repeated corner, or corners on one line).
    #[error("triangle {triangle} {vertices:?} has zero area")]
    ZeroArea {
        /// The triangle.
        triangle: usize,
        /// Its corners.
        vertices: [u32; 3],
    },
    /// The height is not a person's in metres: probably other units.
    #[error(
        "height {height:.6} m (highest − lowest y, as read) is outside {min}…{max} m{}",
        match (unit, scale) {
            (Some(u), Some(s)) => format!(": the file looks like it is in {u}; multiply its coordinates by {s} (a scene's `body_scan.unit`, `LoadOptions::scale`)"),
            _ => String::from(": not a body in any of mm, cm, dm or m (is y up?)"),
        }
    )]
    Height {
        /// The height found, in the file's units.
        height: f64,
        /// Smallest height accepted, m.
        min: f64,
        /// Largest height accepted, m.
        max: f64,
        /// The unit the file seems to be in (`mm`, `cm`, `dm`, or metres scaled down 10, 100 or
        /// 1000 times), when one gives a plausible height.
        unit: Option<&'static str>,
        /// The factor that makes the height plausible (0.001 for mm … 1000).
        scale: Option<f64>,
    },
    /// An edge in three or more triangles.
    #[error(
        "edge {vertices:?} lies in {triangles} triangles (at most two on a surface), at ({:.3}, {:.3}, {:.3}) m",
        at.x, at.y, at.z
    )]
    NonManifoldEdge {
        /// Its vertices.
        vertices: [u32; 2],
        /// Triangles using it.
        triangles: usize,
        /// Its midpoint.
        at: V3,
    },
    /// No consistent orientation exists (a Möbius-like piece).
    #[error("triangle {triangle} cannot be oriented consistently with its neighbours")]
    NonOrientable {
        /// A triangle where the contradiction showed.
        triangle: usize,
    },
    /// Two holes meet at one vertex.
    #[error(
        "vertex {vertex} at ({:.3}, {:.3}, {:.3}) m lies on the border of a hole more than once",
        at.x, at.y, at.z
    )]
    PinchedBorder {
        /// The vertex.
        vertex: u32,
        /// Where it is.
        at: V3,
    },
    /// A hole too large to close.
    #[error(
        "a hole with a border of {:.1} cm ({vertices} vertices) around ({:.3}, {:.3}, {:.3}) m is larger than the {:.1} cm closed automatically",
        100.0 * perimeter, centroid.x, centroid.y, centroid.z, 100.0 * limit
    )]
    HoleTooLarge {
        /// Length of its border, m.
        perimeter: f64,
        /// Vertices on its border.
        vertices: usize,
        /// Mean of its border's vertices, m.
        centroid: V3,
        /// The largest border closed ([`ScanOptions::max_hole_perimeter`]).
        limit: f64,
    },
    /// The mesh is still open after the holes were closed (a closing triangle met an existing
    /// edge).
    #[error(
        "edge {vertices:?} at ({:.3}, {:.3}, {:.3}) m is still open after the repair",
        at.x, at.y, at.z
    )]
    NotClosed {
        /// Its vertices.
        vertices: [u32; 2],
        /// Its midpoint.
        at: V3,
    },
    /// A landmark could not be found (the scan is not an A- or T-pose standing body).
    #[error("landmark `{what}` not found: {why}")]
    Landmark {
        /// Which landmark.
        what: &'static str,
        /// Why.
        why: String,
    },
    /// The segmentation left a part without triangles.
    #[error("no triangle was given to part `{}`", .0.name())]
    EmptyPart(crate::model::Part),
    /// Articulation failed.
    #[error(transparent)]
    Articulate(#[from] ArticulateError),
}

/// A scan ready for a scene: the repaired mesh labelled with the 17 parts, its landmarks and
/// what the repair did.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    /// The repaired mesh, every vertex and triangle labelled.
    pub mesh: LabelledMesh,
    /// The landmarks (found, or given by the landmark file).
    pub landmarks: Landmarks,
    /// The checks' and repair's report.
    pub repair: Repair,
}

/// Repair, landmark and segment a scan. `overrides` gives landmarks that replace the found ones
/// (its fields that are set).
pub fn prepare(
    mesh: ExternalBody,
    opts: &ScanOptions,
    overrides: Option<&LandmarkFile>,
) -> Result<Scan, ScanError> {
    let fixed = repair::repair(mesh.vertices, mesh.triangles, opts)?;
    let mut landmarks = find_landmarks(&fixed.vertices, &fixed.triangles, opts)?;
    if let Some(o) = overrides {
        o.apply(&mut landmarks);
    }
    let mesh = segment(&fixed.vertices, &fixed.triangles, &landmarks)?;
    Ok(Scan {
        mesh,
        landmarks,
        repair: fixed.repair,
    })
}

/// How close (m) a child's vertex must be to its parent's for the articulation to count it as
/// where the two meet: the parts of a segmented scan touch along their shared border, so one
/// ring of vertices either side suffices; 1 cm is above the spacing of a typical scan.
pub const ARTICULATE_REACH: f64 = 0.01;

/// The scan as an articulated mannequin: [`articulate`] with the 9AR mannequin's joint limits
/// and [`ARTICULATE_REACH`], then every part closed where it was cut from its neighbours, since
/// contact needs closed parts: each cut border is capped by a fan from a new vertex at its
/// centroid (a fan adds no edge between border vertices, so it closes any border, planar or
/// not, where ear clipping can meet an existing edge: the cut under the jaw does). The caps lie
/// where two parts touch, inside the body: a point outside is nearest to the scan's own surface
/// (or to a cap's rim, which lies on it), so contact is against the scan itself; a point inside
/// near a cut is given the depth to the nearer cap (less than its depth into the body).
pub fn mannequin(scan: &Scan) -> Result<Mannequin, ScanError> {
    let mut m = articulate(&scan.mesh, &crate::build::jis_9ar(), ARTICULATE_REACH)?;
    for part in &mut m.parts {
        let loops = repair::borders(&part.triangles, &part.vertices)?;
        for border in &loops {
            let centre = part.vertices.len() as u32;
            let n = border.len();
            part.vertices.push(
                border
                    .iter()
                    .map(|&k| part.vertices[k as usize])
                    .sum::<V3>()
                    / n as f64,
            );
            // The border runs a → b along the part's own triangles; the cap runs b → a.
            part.triangles
                .extend((0..n).map(|k| [border[(k + 1) % n], border[k], centre]));
        }
        if let Some((_, [a, b])) = crate::build::first_open_edge(&part.triangles) {
            return Err(ScanError::NotClosed {
                vertices: [a, b],
                at: 0.5 * (part.vertices[a as usize] + part.vertices[b as usize]),
            });
        }
    }
    m.name = "body scan".into();
    Ok(m)
}

/// The mesh refined 1-to-4: every triangle split at its edges' midpoints (a finer scan of the
/// same surface, for the benchmarks' larger scans).
pub fn subdivided(v: &[V3], t: &[[u32; 3]]) -> (Vec<V3>, Vec<[u32; 3]>) {
    let mut v = v.to_vec();
    let mut mid: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    let mut out = Vec::with_capacity(4 * t.len());
    for tri in t {
        let m = [0, 1, 2].map(|e| {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push((v[a as usize] + v[b as usize]) / 2.0);
                (v.len() - 1) as u32
            })
        });
        out.push([tri[0], m[0], m[2]]);
        out.push([tri[1], m[1], m[0]]);
        out.push([tri[2], m[2], m[1]]);
        out.push(m);
    }
    (v, out)
}
