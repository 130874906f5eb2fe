//! What a simulation is about: a [`Garment`] (its gridded panels, fabric, placements and seams),
//! the body that wears it, the motion the body performs, and the [`Settings`] of the physics and
//! of the schedule — together a [`Scene`]. [`GarmentSpec`] is the same written in a scenario
//! file, with paths; [`Scene::load`] reads the files it names.
//!
//! One garment per scene: the solver steps one cloth of one fabric, and a garment of several
//! fabrics (or layered garments) would need a cloth with a fabric per panel.

use std::path::{Path, PathBuf};

use atelier_body::kinematics::Body;
use atelier_body::model::Mannequin;
use atelier_body::motion::Motion;
use atelier_fabric::{
    AnisotropyForm, ErrorKind, Fabric, FileError, InvalidValue, STANDARD_GRAVITY,
};
use atelier_grid::ImproveParams;
use atelier_solver::StepParams;
use atelier_solver::baselines::{MassSpringParams, XpbdParams};
use serde::{Deserialize, Serialize};

use crate::place::{PlaceParams, Placement};
use crate::{GarmentCloth, SewingParams};

/// A garment scene as a scenario file writes it: what to wear (files, placements), on which
/// body, doing what, and how to simulate it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentSpec {
    /// Garment file (RON), relative to the scenario's folder.
    pub garment: PathBuf,
    /// Fabric file (RON), relative to the scenario's folder.
    pub fabric: PathBuf,
    /// One placement per panel, in the garment's panel order.
    pub placements: Vec<Placement>,
    /// Clearance and ease of the placement.
    #[serde(default)]
    pub place: PlaceParams,
    /// Body description file (RON), or a body scan (`.obj`, `.ply`, in metres; see
    /// `body_scan` for other units and a landmark file); the built-in JIS 9AR mannequin when
    /// absent.
    #[serde(default)]
    pub body: Option<PathBuf>,
    /// A body scan with its unit and landmark file (instead of `body`).
    #[serde(default)]
    pub body_scan: Option<BodyScanSpec>,
    /// Motion file (RON) the body performs after the garment has settled; none: stand still.
    #[serde(default)]
    pub motion: Option<PathBuf>,
    /// Physics and schedule.
    #[serde(default)]
    pub settings: Settings,
}

/// A body scan as a garment scene's body (`docs/body.md`, "Scans"): repaired, landmarked,
/// segmented into the 17 parts and articulated; the garment collides with the scan's own
/// surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyScanSpec {
    /// The mesh (OBJ or ASCII PLY), relative to the scenario's folder.
    pub mesh: PathBuf,
    /// Its length unit (default `m`).
    #[serde(default)]
    pub unit: LengthUnit,
    /// A landmark file (RON) giving or overriding landmarks.
    #[serde(default)]
    pub landmarks: Option<PathBuf>,
}

/// A mesh file's length unit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Metres.
    #[default]
    M,
    /// Decimetres.
    Dm,
    /// Centimetres.
    Cm,
    /// Millimetres.
    Mm,
    /// Inches.
    In,
}

impl LengthUnit {
    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            LengthUnit::M => 1.0,
            LengthUnit::Dm => 0.1,
            LengthUnit::Cm => 0.01,
            LengthUnit::Mm => 0.001,
            LengthUnit::In => 0.0254,
        }
    }
}

/// How the garment gets onto the body.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Dressing {
    /// Thesis §5.6: the panels placed around the body, their seams drawn together with gravity
    /// off and sewn; gravity starts when every pair is sewn.
    Sewn,
    /// The thesis's "semi-transparent" dressing (§5.6): the garment laid out and sewn in front
    /// of the body (gravity off), then pushed through it with one-sided contact — a panel's
    /// outside passes through the body, its inside catches — until no node is inside the body
    /// after `push_time`; then gravity starts and contact becomes two-sided. The contact is
    /// frictionless until then (pressed on by the push, friction would pin the garment where
    /// it first touches instead of letting it slide round the body).
    OneSided {
        /// Acceleration pushing every node towards the body (−z, the body's back), m/s².
        push: f64,
        /// Least time of the push, s.
        push_time: f64,
        /// Longest time of the push before the run gives up, s.
        push_limit: f64,
    },
}

/// The cloth solver that steps a garment. The seams and the body reach every solver through the
/// same collision hook (`atelier_solver::baselines`, "Collisions and seams").
///
/// In a scenario file: `solver: Party` (the default), `solver: Xpbd((substeps: 10, iterations:
/// 4))`, `solver: MassSpring((substeps: 100))`. Every solver takes Δt and gravity from the scene
/// with each step (`settings.dt`; gravity off while sewing); a baseline's substeps divide the
/// scene's Δt. The mass-spring model is explicit: its substep Δt/substeps must lie
/// below its stability limit (about 1.2·10⁻⁴ s for cotton on the dress's 2 cm grid).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ClothSolver {
    /// The PARTY step (thesis §3.5, §3.8) with `settings.step`.
    #[default]
    Party,
    /// The XPBD baseline (distance constraints from the fabric's secant stiffness).
    Xpbd(XpbdParams),
    /// The explicit mass-spring baseline (Yamada's model, Verlet).
    MassSpring(MassSpringParams),
}

impl ClothSolver {
    /// A short name (reports, figures).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Party => "PARTY",
            Self::Xpbd(_) => "XPBD",
            Self::MassSpring(_) => "mass-spring",
        }
    }
}

/// The physics of a garment scene and its schedule: sew (or push), settle, move.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Settings {
    /// Time step Δt, s. Default 0.01 (the thesis's).
    pub dt: f64,
    /// Gravity once the garment is on, m/s² (body frame: y up). Default (0, −9.80665, 0).
    pub gravity: [f64; 3],
    /// Static friction ρ against the body. Default 0.3 (the thesis's dress).
    pub friction: f64,
    /// Restitution ν against the body. Default 0.1.
    pub restitution: f64,
    /// Contact skin, m: cloth nodes are kept this far outside the body. Default 0.003 (nodes
    /// hold the skin, the flat triangles between them do not: with a skin of 1 mm the body's
    /// creases showed through 2 cm cells).
    pub skin: f64,
    /// Cloth against itself, once the garment is on (not while its seams are drawn together:
    /// a seam's two sides pass the cloth between them), the two sides of every seam excepted.
    /// Default false (the thesis left it out for speed).
    pub self_collision: bool,
    /// Body vertices against the cloth's faces (`docs/collision.md` §4c): a body vertex that
    /// pokes through a cloth triangle lifts the contact planes of its nodes. Default false: on
    /// the silk dress and `dress_sewn` it leaves no body vertex showing (18 and 13 without),
    /// but the sewn skirt in cotton broad does not come to rest with it (docs/validation.md,
    /// "The body through the cloth's faces").
    pub vertex_planes: bool,
    /// The staged model of moving bodies (thesis §5.4): the body's motion transferred to the
    /// cloth near it before the shape constraints. Default true; false: the physical model
    /// alone.
    pub staged: bool,
    /// How the garment gets onto the body. Default `Sewn`.
    pub dressing: Dressing,
    /// Sewing pull and threshold.
    pub sewing: SewingSpec,
    /// Longest time allowed for sewing (or pushing), s (gravity off). Default 3.
    pub sew_limit: f64,
    /// Time under gravity after dressing, before the motion starts, s. Default 1.
    pub settle: f64,
    /// Duration of the motion, s (0: no motion). Default 0.
    pub motion_time: f64,
    /// Interval between recorded frames, s. Default 0.04 (25 frames per second).
    pub frame_interval: f64,
    /// Overrides of the solver's step parameters: damping (air drag), tolerances and iteration
    /// caps, tolerance policy, methods (Δt and gravity are the scene's, given with every step). Default: the
    /// solver's defaults (diagonals held at the targets of the fabric's shear characteristic,
    /// as in the thesis).
    pub step: StepParams,
    /// The cloth solver. Default `Party` (the thesis's; `step` then applies). The baselines
    /// take their own parameters and ignore `step`; one-sided dressing needs `Party` (its push
    /// is an external force only the PARTY step takes).
    pub solver: ClothSolver,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            dt: 0.01,
            gravity: [0.0, -STANDARD_GRAVITY, 0.0],
            friction: 0.3,
            restitution: 0.1,
            skin: 3e-3,
            self_collision: false,
            vertex_planes: false,
            staged: true,
            dressing: Dressing::Sewn,
            sewing: SewingSpec::default(),
            sew_limit: 3.0,
            settle: 1.0,
            motion_time: 0.0,
            frame_interval: 0.04,
            step: StepParams::default(),
            solver: ClothSolver::Party,
        }
    }
}

/// The sewing stage's parameters, as written in a scene.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SewingSpec {
    /// Fraction of a pair's gap closed per second (ω), 1/s. Default 10.
    pub omega: f64,
    /// A pair closer than this is sewn (then held shut), m. Default 0.01 (with 5 mm the stiff
    /// denim's last pair at the armpit stalled at 9 mm: the fabric cannot fold into the crease
    /// between arm and chest).
    pub threshold: f64,
    /// Largest closing speed of a pair, m/s. Default 1.
    pub max_speed: f64,
}

impl Default for SewingSpec {
    fn default() -> Self {
        Self {
            omega: 10.0,
            threshold: 0.01,
            max_speed: 1.0,
        }
    }
}

impl SewingSpec {
    /// The sewing hook's parameters.
    pub fn params(&self) -> SewingParams {
        SewingParams {
            omega: self.omega,
            threshold: self.threshold,
            max_speed: self.max_speed,
        }
    }
}

impl Settings {
    /// Every range, with the field's path (`settings.dt`, …) in the error.
    pub fn check(&self) -> Result<(), InvalidValue> {
        let rules: [(&str, f64, bool, &str); 12] = [
            (
                "dt",
                self.dt,
                self.dt > 0.0 && self.dt <= 0.1,
                "in (0, 0.1] s",
            ),
            ("friction", self.friction, self.friction >= 0.0, "≥ 0"),
            (
                "restitution",
                self.restitution,
                (0.0..=1.0).contains(&self.restitution),
                "in [0, 1]",
            ),
            (
                "skin",
                self.skin,
                (0.0..=0.05).contains(&self.skin),
                "in [0, 0.05] m",
            ),
            ("sew_limit", self.sew_limit, self.sew_limit >= 0.0, "≥ 0 s"),
            ("settle", self.settle, self.settle >= 0.0, "≥ 0 s"),
            (
                "motion_time",
                self.motion_time,
                self.motion_time >= 0.0,
                "≥ 0 s",
            ),
            (
                "frame_interval",
                self.frame_interval,
                self.frame_interval > 0.0,
                "> 0 s",
            ),
            (
                "sewing.omega",
                self.sewing.omega,
                self.sewing.omega > 0.0,
                "> 0 1/s",
            ),
            (
                "sewing.threshold",
                self.sewing.threshold,
                self.sewing.threshold > 0.0,
                "> 0 m",
            ),
            (
                "sewing.max_speed",
                self.sewing.max_speed,
                self.sewing.max_speed > 0.0,
                "> 0 m/s",
            ),
            (
                "gravity",
                self.gravity.iter().map(|g| g.abs()).fold(0.0, f64::max),
                self.gravity.iter().all(|g| g.abs() <= 1e3),
                "each component within ±1000 m/s²",
            ),
        ];
        for (name, value, ok, range) in rules {
            if !value.is_finite() {
                return Err(InvalidValue::new(
                    ErrorKind::NotFinite,
                    format!("settings.{name}"),
                    format!("{value}"),
                ));
            }
            if !ok {
                return Err(InvalidValue::new(
                    ErrorKind::OutOfRange,
                    format!("settings.{name}"),
                    format!("{value} must be {range}"),
                ));
            }
        }
        if let Dressing::OneSided {
            push,
            push_time,
            push_limit,
        } = self.dressing
        {
            for (name, v) in [
                ("push", push),
                ("push_time", push_time),
                ("push_limit", push_limit),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(InvalidValue::new(
                        ErrorKind::OutOfRange,
                        format!("settings.dressing.{name}"),
                        format!("{v} must be finite and > 0"),
                    ));
                }
            }
            if push_limit < push_time {
                return Err(InvalidValue::new(
                    ErrorKind::Inconsistent,
                    "settings.dressing.push_limit",
                    format!("{push_limit} s is shorter than push_time {push_time} s"),
                ));
            }
        }
        check_step(&self.step)?;
        let baseline = match &self.solver {
            ClothSolver::Party => Ok(()),
            ClothSolver::Xpbd(p) => p.validate(),
            ClothSolver::MassSpring(p) => p.validate(),
        };
        baseline.map_err(|e| {
            InvalidValue::new(
                ErrorKind::OutOfRange,
                format!("settings.solver.{}", e.name),
                e.to_string(),
            )
        })?;
        if self.solver != ClothSolver::Party && matches!(self.dressing, Dressing::OneSided { .. }) {
            return Err(InvalidValue::new(
                ErrorKind::Inconsistent,
                "settings.solver",
                format!(
                    "{}: one-sided dressing pushes the garment with an external force, which only the Party solver takes",
                    self.solver.name()
                ),
            ));
        }
        Ok(())
    }
}

/// A garment ready to simulate: its panels gridded and joined into one cloth of its fabric, with
/// the seams to sew and where each panel starts.
pub struct Garment {
    /// The garment's name.
    pub name: String,
    /// The cloth and its seam pairs.
    pub cloth: GarmentCloth,
    /// The fabric.
    pub fabric: Fabric,
    /// One placement per panel.
    pub placements: Vec<Placement>,
    /// Clearance and ease of the placement.
    pub place: PlaceParams,
}

/// Why a scene could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read or is invalid (the error names file, position and field).
    #[error(transparent)]
    File(#[from] FileError),
    /// The body description's mannequin could not be built (the file named first).
    #[error("{}: {source}", file.display())]
    Mannequin {
        /// The body description.
        file: PathBuf,
        /// Why.
        source: atelier_body::build::BodyError,
    },
    /// The garment could not be assembled.
    #[error(transparent)]
    Assemble(#[from] crate::AssembleError),
    /// The panels could not be placed.
    #[error(transparent)]
    Place(#[from] crate::place::PlaceError),
    /// A setting is out of range.
    #[error("{0}")]
    Invalid(#[from] InvalidValue),
    /// The body's contact could not be set up.
    #[error(transparent)]
    Contact(#[from] atelier_collide::ContactError),
    /// The body's parts could not be set up as rigid colliders.
    #[error("body: {0}")]
    Parts(#[from] atelier_collide::parts::PartsError),
    /// A body scan could not be made a body (the mesh named first).
    #[error("{}: {source}", file.display())]
    Scan {
        /// The mesh.
        file: PathBuf,
        /// Why.
        source: atelier_body::scan::ScanError,
    },
    /// `body` and `body_scan` both given.
    #[error("a garment scene takes `body` or `body_scan`, not both")]
    TwoBodies,
}

/// `settings.step` checked, an error naming the field as the scenario file spells it.
pub(crate) fn check_step(step: &StepParams) -> Result<(), InvalidValue> {
    step.validate().map_err(|e| {
        InvalidValue::new(
            ErrorKind::OutOfRange,
            format!("settings.step.{}", e.name),
            e.to_string(),
        )
    })
}

impl Garment {
    /// Read a garment file and grid its panels (default improvement), read the fabric, and
    /// join them into one cloth with the given placements.
    pub fn load(
        garment: &Path,
        fabric: &Path,
        placements: Vec<Placement>,
        place: PlaceParams,
    ) -> Result<Self, SceneError> {
        let pattern = crate::patterns::load_garment(garment, ImproveParams::default())?;
        let fabric = Fabric::load(fabric)?;
        if placements.len() != pattern.panels.len() {
            return Err(crate::place::PlaceError::Count {
                placements: placements.len(),
                panels: pattern.panels.len(),
            }
            .into());
        }
        let cloth = GarmentCloth::new(&pattern, &fabric, AnisotropyForm::PlateTheory)?;
        Ok(Self {
            name: pattern.name,
            cloth,
            fabric,
            placements,
            place,
        })
    }
}

/// Everything a [`crate::simulation::Simulation`] needs.
pub struct Scene {
    /// The garment.
    pub garment: Garment,
    /// The body, ready to be posed.
    pub body: Body,
    /// The motion performed after the garment has settled, if any.
    pub motion: Option<Motion>,
    /// Physics and schedule.
    pub settings: Settings,
    /// What was done to the body before the run (a scan's repair and landmarks), reported with
    /// the run's warnings.
    pub notes: Vec<String>,
}

impl Scene {
    /// A scene from its parts, with the settings checked.
    pub fn new(
        garment: Garment,
        mannequin: Mannequin,
        motion: Option<Motion>,
        settings: Settings,
    ) -> Result<Self, SceneError> {
        settings.check()?;
        Ok(Self {
            garment,
            body: Body::new(mannequin),
            motion,
            settings,
            notes: Vec::new(),
        })
    }

    /// Read every file a spec names (relative to `base`) and check its settings.
    pub fn load(spec: &GarmentSpec, base: &Path) -> Result<Self, SceneError> {
        spec.settings.check()?;
        let resolve = |p: &Path| base.join(p);
        let garment = Garment::load(
            &resolve(&spec.garment),
            &resolve(&spec.fabric),
            spec.placements.clone(),
            spec.place,
        )?;
        let is_mesh = |p: &Path| {
            matches!(
                p.extension()
                    .and_then(|e| e.to_str())
                    .map(str::to_ascii_lowercase)
                    .as_deref(),
                Some("obj" | "ply")
            )
        };
        let scan = match (&spec.body, &spec.body_scan) {
            (Some(_), Some(_)) => return Err(SceneError::TwoBodies),
            (None, Some(s)) => Some(s.clone()),
            (Some(p), None) if is_mesh(p) => Some(BodyScanSpec {
                mesh: p.clone(),
                unit: LengthUnit::M,
                landmarks: None,
            }),
            _ => None,
        };
        let mut notes = Vec::new();
        let mannequin = match (&spec.body, scan) {
            (_, Some(s)) => {
                let (mannequin, said) = load_scan(&s, base)?;
                notes = said;
                mannequin
            }
            (None, None) => atelier_body::build::jis_9ar(),
            (Some(p), None) => {
                let d = atelier_body::description::BodyDescription::load(&resolve(p))?;
                Mannequin::from_description(&d, &d.sizes).map_err(|source| {
                    SceneError::Mannequin {
                        file: p.clone(),
                        source,
                    }
                })?
            }
        };
        let motion = match &spec.motion {
            Some(p) if spec.settings.motion_time > 0.0 => {
                Some(Motion::load(&resolve(p), &mannequin)?)
            }
            _ => None,
        };
        let mut scene = Self::new(garment, mannequin, motion, spec.settings.clone())?;
        scene.notes = notes;
        Ok(scene)
    }
}

/// A body scan as a mannequin, with what was done to it in words.
fn load_scan(s: &BodyScanSpec, base: &Path) -> Result<(Mannequin, Vec<String>), SceneError> {
    use atelier_body::scan::{LandmarkFile, ScanOptions, mannequin, prepare};
    let file = base.join(&s.mesh);
    let mesh = atelier_body::io::load_mesh_with(
        &file,
        &atelier_body::io::LoadOptions {
            require_closed: false,
            scale: s.unit.metres(),
        },
    )?;
    let overrides = s
        .landmarks
        .as_ref()
        .map(|p| LandmarkFile::load(&base.join(p)))
        .transpose()?;
    let fail = |source| SceneError::Scan {
        file: file.clone(),
        source,
    };
    let scan = prepare(mesh, &ScanOptions::default(), overrides.as_ref()).map_err(fail)?;
    let body = mannequin(&scan).map_err(fail)?;
    let r = &scan.repair;
    let mut notes: Vec<String> = r
        .holes
        .iter()
        .map(|h| {
            format!(
                "body scan: a hole of {} vertices ({:.1} cm of border) at ({:.3}, {:.3}, {:.3}) m closed with {} triangles",
                h.vertices,
                100.0 * h.perimeter,
                h.centroid.x,
                h.centroid.y,
                h.centroid.z,
                h.triangles_added
            )
        })
        .collect();
    notes.extend(r.warnings.iter().map(|w| format!("body scan: {w}")));
    let l = &scan.landmarks;
    notes.push(format!(
        "body scan {}: {} vertices, {} triangles, height {:.1} cm; waist {:.1} cm at {:.3} m, hip {:.1} cm at {:.3} m, crotch at {:.3} m",
        file.display(),
        scan.mesh.vertices.len(),
        scan.mesh.triangles.len(),
        100.0 * r.height,
        100.0 * l.waist.girth,
        l.waist.height,
        100.0 * l.hip.girth,
        l.hip.height,
        l.crotch.y
    ));
    Ok((body, notes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_name_the_field_out_of_range() {
        let bad = Settings {
            friction: -0.1,
            ..Settings::default()
        };
        let e = bad.check().expect_err("negative friction");
        assert_eq!(e.field, "settings.friction");
        let bad = Settings {
            step: StepParams {
                shape: atelier_solver::ShapeParams {
                    max_iterations: 0,
                    ..Settings::default().step.shape
                },
                ..Settings::default().step
            },
            ..Settings::default()
        };
        let e = bad.check().expect_err("no iterations");
        assert_eq!(e.field, "settings.step.shape.max_iterations");
        let bad = Settings {
            dressing: Dressing::OneSided {
                push: 5.0,
                push_time: 1.0,
                push_limit: 0.5,
            },
            ..Settings::default()
        };
        assert_eq!(
            bad.check().expect_err("limit").kind,
            ErrorKind::Inconsistent
        );
        let bad = Settings {
            dt: f64::NAN,
            ..Settings::default()
        };
        assert_eq!(bad.check().expect_err("NaN").kind, ErrorKind::NotFinite);
        assert!(Settings::default().check().is_ok());
    }

    #[test]
    fn a_baseline_solver_is_checked_with_the_field_named() {
        let bad = Settings {
            solver: ClothSolver::Xpbd(XpbdParams {
                substeps: 0,
                ..XpbdParams::default()
            }),
            ..Settings::default()
        };
        let e = bad.check().expect_err("no substeps");
        assert_eq!(e.field, "settings.solver.substeps");
        assert_eq!(e.kind, ErrorKind::OutOfRange);
        let bad = Settings {
            solver: ClothSolver::MassSpring(MassSpringParams {
                damping: -1.0,
                ..MassSpringParams::default()
            }),
            ..Settings::default()
        };
        assert_eq!(
            bad.check().expect_err("damping").field,
            "settings.solver.damping"
        );
        // Δt is the scene's alone: a baseline has no Δt of its own to set.
        let refused = ron::from_str::<Settings>("(solver: Xpbd((dt: 5.0)))")
            .expect_err("a baseline's dt is not a field");
        assert!(refused.to_string().contains("dt"), "{refused}");
        let bad = Settings {
            solver: ClothSolver::Xpbd(XpbdParams::default()),
            dressing: Dressing::OneSided {
                push: 2.0,
                push_time: 0.5,
                push_limit: 2.0,
            },
            ..Settings::default()
        };
        let e = bad.check().expect_err("one-sided");
        assert_eq!(
            (e.field.as_str(), e.kind),
            ("settings.solver", ErrorKind::Inconsistent)
        );
        // The default is PARTY, and a settings block without `solver` still parses to it.
        let parsed: Settings = ron::from_str("(dt: 0.01, settle: 0.5)").expect("parses");
        assert_eq!(parsed.solver, ClothSolver::Party);
        let parsed: Settings =
            ron::from_str("(solver: Xpbd((substeps: 5, iterations: 2)))").expect("parses");
        assert_eq!(
            parsed.solver,
            ClothSolver::Xpbd(XpbdParams {
                substeps: 5,
                iterations: 2,
                ..XpbdParams::default()
            })
        );
    }
}
