//! Virtual try-on from one photograph (thesis chapter 6, `atelier tryon`): the mannequin posed
//! to the person's silhouette ([`pose`]); the garment sewn on in the standard pose and carried
//! to the fitted pose through time by the garment pipeline; then rendered with the photograph's
//! camera, lit from a direction the user sets, over the photograph ([`composite`]).

pub mod camera;
pub mod composite;
pub mod examples;
pub mod image;
pub mod pose;
pub mod yaw;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use atelier_body::build::jis_9ar_description;
use atelier_body::description::BodyDescription;
use atelier_body::motion::{KeyframeSpec, LimitPolicy, MotionSpec};
use atelier_body::{Mannequin, Motion};
use atelier_fabric::FileError;

use atelier::report::Report;
pub use atelier::report::{LOW_IOU, TryonInfo};
use atelier::run::{
    RunError, RunOptions, base_of, outputs, prepare_folder, simulate_scene, write_run,
};
use atelier::scenario::{Scenario, ScenarioKind};
use atelier::scene::{Garment, GarmentSpec, Scene};
use image::{Mask, Photo};
use pose::{FitOptions, PoseFile, PoseFit};

/// How fast the mannequin turns from the standard pose to the fitted one, degrees per second
/// (the largest joint's turn sets the motion's length; at least [`MIN_MOTION_S`]).
pub const TURN_RATE_DEG_S: f64 = 90.0;
/// Shortest motion, s.
pub const MIN_MOTION_S: f64 = 0.5;
/// Time the garment settles in the fitted pose after the motion, s.
pub const HOLD_S: f64 = 0.5;

/// What `atelier tryon` is given.
#[derive(Clone, Debug)]
pub struct TryonInputs {
    /// The photograph (PNG).
    pub photo: PathBuf,
    /// The person's mask (PNG); `None`: segment the photograph's plain background.
    pub mask: Option<PathBuf>,
    /// The garment: a scenario file of kind `Garment` (garment, fabric, placements, settings).
    pub garment: PathBuf,
    /// A start pose (RON, [`PoseFile`]); `None`: the standard pose.
    pub pose: Option<PathBuf>,
    /// The camera's direction round the vertical, degrees (0: from the front); `None`: unknown,
    /// searched ([`yaw::fit_pose_any_yaw`]).
    pub yaw_deg: Option<f64>,
    /// The person's height, cm; `None`: the body description's.
    pub height_cm: Option<f64>,
    /// Direction towards the light, body frame (x the body's left, y up, z forward).
    pub light: [f64; 3],
    /// Colour of the garment, RGB in [0, 1].
    pub colour: [f64; 3],
    /// The segmentation's colour threshold (0–255), without a mask.
    pub threshold: u8,
}

impl TryonInputs {
    /// Inputs with the defaults: from the front, the description's height, light from the
    /// front, above and the body's left, the pipeline's cloth colour, threshold 40.
    pub fn new(photo: PathBuf, mask: Option<PathBuf>, garment: PathBuf) -> Self {
        Self {
            photo,
            mask,
            garment,
            pose: None,
            yaw_deg: Some(0.0),
            height_cm: None,
            light: DEFAULT_LIGHT,
            colour: atelier::picture::CLOTH,
            threshold: 40,
        }
    }
}

/// The default light: from the front, above, and the body's left.
pub const DEFAULT_LIGHT: [f64; 3] = [0.4, 0.6, 1.0];

/// Why a try-on could not run.
#[derive(Debug, thiserror::Error)]
pub enum TryonError {
    /// An input file is missing or invalid (the message names file, position and field).
    #[error("{0}")]
    File(#[from] FileError),
    /// The mask or the fit cannot be used (the message says why).
    #[error("{0}")]
    Input(String),
    /// The garment run failed to start or its outputs could not be written.
    #[error(transparent)]
    Run(#[from] RunError),
}

/// The photograph and the mask (read or segmented), checked against each other.
pub fn load_inputs(inputs: &TryonInputs) -> Result<(Photo, Mask), TryonError> {
    let photo = image::load_photo(&inputs.photo)?;
    let mask = match &inputs.mask {
        Some(m) => image::load_mask(m, (photo.width, photo.height))?,
        None => {
            let mask = image::segment_plain_background(&photo, inputs.threshold);
            image::check_mask(&mask).map_err(|m| {
                TryonError::Input(format!(
                    "{}: the plain-background segmentation failed: {m}; give a mask with --mask",
                    inputs.photo.display()
                ))
            })?;
            mask
        }
    };
    Ok((photo, mask))
}

/// The motion from the standard pose (t = 0) to the fitted one, at [`TURN_RATE_DEG_S`].
pub fn motion_to(
    angles: &[[f64; 3]; 17],
    mannequin: &Mannequin,
) -> Result<(Motion, f64), TryonError> {
    let largest = angles.iter().flatten().fold(0.0f64, |m, a| m.max(a.abs()));
    let duration = (largest / TURN_RATE_DEG_S).max(MIN_MOTION_S);
    let pose = PoseFile::from_angles(angles, None, None);
    let spec = MotionSpec {
        name: "to the photograph's pose".into(),
        provenance: "atelier tryon: the standard pose to the pose fitted to the photograph".into(),
        limits: LimitPolicy::Clamp,
        keyframes: vec![
            KeyframeSpec {
                time: 0.0,
                root_cm: (0.0, 0.0, 0.0),
                joints: BTreeMap::new(),
            },
            KeyframeSpec {
                time: duration,
                root_cm: (0.0, 0.0, 0.0),
                joints: pose.joints,
            },
        ],
    };
    let motion = Motion::new(&spec, mannequin).map_err(|e| TryonError::Input(e.to_string()))?;
    Ok((motion, duration))
}

/// The try-on's garment scene: `spec`'s garment and fabric (paths relative to `base`) sewn on
/// `mannequin` in the standard pose, then moved to the joint `angles` ([`motion_to`]) and held
/// there for [`HOLD_S`].
pub fn posed_scene(
    spec: &GarmentSpec,
    base: &Path,
    mannequin: Mannequin,
    angles: &[[f64; 3]; 17],
) -> Result<Scene, TryonError> {
    let (motion, motion_s) = motion_to(angles, &mannequin)?;
    let garment = Garment::load(
        &base.join(&spec.garment),
        &base.join(&spec.fabric),
        spec.placements.clone(),
        spec.place,
    )
    .map_err(RunError::from)?;
    let mut settings = spec.settings.clone();
    settings.motion_time = motion_s + HOLD_S;
    Ok(Scene::new(garment, mannequin, Some(motion), settings).map_err(RunError::from)?)
}

/// Run a try-on into `out`: fit, dress, move, composite; writes `composite.png`,
/// `overlay.png`, `footprint.png`, `fitted_pose.ron` and the garment run's usual outputs and `report.json` (with
/// a `tryon` section). A fit below [`LOW_IOU`] is reported in the warnings, not hidden.
pub fn tryon(
    inputs: &TryonInputs,
    out: &Path,
    options: &RunOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Report, TryonError> {
    let clock = Instant::now();
    let (photo, mask) = load_inputs(inputs)?;
    let scenario = Scenario::load(&inputs.garment)?;
    let ScenarioKind::Garment(spec) = &scenario.kind else {
        return Err(TryonError::Input(format!(
            "{}: a {} scenario; the garment must be a scenario of kind Garment (garment, fabric, placements)",
            inputs.garment.display(),
            scenario.kind.name()
        )));
    };
    let base = base_of(&inputs.garment);
    let description: BodyDescription = match &spec.body {
        None => jis_9ar_description(),
        Some(p) => BodyDescription::load(&base.join(p))?,
    };
    let start = match &inputs.pose {
        None => PoseFile::default(),
        Some(p) => {
            let start: PoseFile = atelier_files::files::load_ron(p)?;
            start.check().map_err(|e| FileError::from_invalid(p, e))?;
            start
        }
    };
    let height_cm = inputs.height_cm.unwrap_or(description.sizes.height_cm);
    let fit_options = FitOptions {
        description: description.clone(),
        height_cm,
        yaw_deg: inputs.yaw_deg.unwrap_or(0.0),
        start,
    };
    let (fit, yaw_tried) = match inputs.yaw_deg {
        Some(_) => (pose::fit_pose(&mask, &fit_options), Vec::new()),
        None => match yaw::fit_pose_any_yaw(&mask, &fit_options) {
            Ok(s) => (Ok(s.fit), s.tried),
            Err(e) => (Err(e), Vec::new()),
        },
    };
    let fit = fit.map_err(TryonError::Input)?;
    progress(0.1);

    // The garment on the fitted mannequin, moved from the standard pose to the fitted one.
    let mannequin = Mannequin::from_description(&description, &fit.sizes)
        .map_err(|e| TryonError::Input(format!("the fitted body: {e}")))?;
    let scene = posed_scene(spec, &base, mannequin, &fit.angles)?;
    let motion_s = scene.settings.motion_time - HOLD_S;
    prepare_folder(out)?;
    let mut sim_progress = |f: f64| progress(0.1 + 0.9 * f);
    let sim = simulate_scene(scene, &mut sim_progress)?;

    // The composite, the overlay and the fitted pose.
    let last = |frames: &[Vec<[f64; 3]>]| frames.last().cloned().unwrap_or_default();
    let cloth = last(&sim.cloth.frames);
    let solid = sim
        .solid
        .as_ref()
        .ok_or_else(|| TryonError::Input("the garment run has no body".into()))?;
    let body = last(&solid.motion.frames);
    let picture = composite::composite(
        &photo,
        &fit.camera,
        (&cloth, &sim.cloth_triangles),
        (&body, &solid.triangles),
        inputs.colour,
        inputs.light,
    );
    let write = |name: &str, bytes: &[u8]| -> Result<(), RunError> {
        let path = out.join(name);
        atelier_files::files::write_atomic(&path, bytes)
            .map_err(|source| RunError::Output { path, source })
    };
    let io = |e: std::io::Error| RunError::Output {
        path: out.to_path_buf(),
        source: e,
    };
    write(
        outputs::COMPOSITE,
        &image::encode(photo.width, photo.height, photo.channels, &picture.data).map_err(io)?,
    )?;
    write(
        outputs::OVERLAY,
        &image::encode(
            photo.width,
            photo.height,
            3,
            &composite::overlay(&photo, &mask, &fit.silhouette),
        )
        .map_err(io)?,
    )?;
    let footprint: Vec<u8> = picture
        .footprint
        .iter()
        .flat_map(|&b| [if b { 255 } else { 0 }; 3])
        .collect();
    write(
        outputs::FOOTPRINT,
        &image::encode(photo.width, photo.height, 3, &footprint).map_err(io)?,
    )?;
    let fitted = PoseFile::from_angles(&fit.angles, Some(fit.camera), Some(fit.sizes));
    let ron_text = ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .to_string_pretty(&fitted, ron::ser::PrettyConfig::default())
        .map_err(|e| TryonError::Input(format!("the fitted pose does not serialise: {e}")))?;
    write(
        outputs::FITTED_POSE,
        format!(
            "// atelier tryon: the pose fitted to {}\n{ron_text}\n",
            inputs.photo.display()
        )
        .as_bytes(),
    )?;

    let info = info(inputs, &mask, &fit, &fitted, motion_s, &picture, yaw_tried);
    let setup = (clock.elapsed().as_secs_f64() - sim.wall_seconds).max(0.0);
    let mut warnings = fit_warnings(&mask, &fit);
    if spec.motion.is_some() {
        warnings.push(format!(
            "{}: the garment scenario's own motion is not run; the try-on moves the body to the fitted pose",
            inputs.garment.display()
        ));
    }
    let report = write_run(
        &scenario,
        Some(&inputs.garment),
        &sim,
        setup,
        out,
        options,
        |r| {
            r.outputs.extend(
                [
                    outputs::COMPOSITE,
                    outputs::OVERLAY,
                    outputs::FITTED_POSE,
                    outputs::FOOTPRINT,
                ]
                .map(String::from),
            );
            r.warnings.extend(warnings);
            r.tryon = Some(info);
        },
    )?;
    Ok(report)
}

fn info(
    inputs: &TryonInputs,
    mask: &Mask,
    fit: &PoseFit,
    fitted: &PoseFile,
    motion_s: f64,
    picture: &composite::Composite,
    yaw_tried: Vec<(f64, f64)>,
) -> TryonInfo {
    TryonInfo {
        photo: inputs.photo.display().to_string(),
        mask: inputs.mask.as_ref().map(|m| m.display().to_string()),
        mask_pixels: mask.count(),
        iou_before: fit.iou_before,
        iou_after: fit.iou_after,
        fit_s: fit.seconds,
        evaluations: fit.evaluations,
        termination: fit.termination.clone(),
        camera: fit.camera,
        yaw_tried,
        sizes: fit.sizes,
        joints: fitted.joints.clone(),
        motion_s,
        person_outside_mannequin_px: mask
            .data
            .iter()
            .zip(&fit.silhouette)
            .filter(|(m, s)| **m && **s < 0.5)
            .count(),
        garment_pixels: picture.footprint.iter().filter(|&&b| b).count(),
        light: inputs.light,
    }
}

/// What the user should know about the fit.
pub fn fit_warnings(mask: &Mask, fit: &PoseFit) -> Vec<String> {
    let mut w = Vec::new();
    if fit.iou_after < LOW_IOU {
        w.push(format!(
            "the mannequin could not match the mask: silhouette overlap {:.3} after fitting (below {LOW_IOU}); the composite is not to be trusted",
            fit.iou_after
        ));
    }
    if let Some([x0, y0, x1, y1]) = mask.bounds()
        && (x0 == 0 || y0 == 0 || x1 + 1 == mask.width || y1 + 1 == mask.height)
    {
        w.push(
            "the person touches the picture's edge: a cut-off silhouette misleads the fit".into(),
        );
    }
    w
}
