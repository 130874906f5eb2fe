//! Posing the mannequin to a photograph (thesis §6.2, step 1, done here by optimisation where
//! the thesis posed by hand): the joint angles, the camera's scale and position, and the body's
//! girth within the size chart whose rendered silhouette best overlaps the person's mask.
//!
//! The distance minimised is the squared difference of the two silhouettes, both blurred by a
//! Gaussian: smooth in the parameters (the model's silhouette is rendered with 4 × 4 samples
//! per pixel), and with a basin as wide as the blur. Levenberg–Marquardt (the
//! `levenberg-marquardt` crate, Jacobian by central differences taken in parallel) runs coarse
//! to fine: on the mask reduced 4×, 2× and 1× (from the scale where the person is at most
//! 240 pixels tall), with the blur 4, 2 and 1 pixel of each. It starts from the standard pose
//! (or the user's) with the camera that puts the model's box on the mask's box.
//!
//! What one photograph determines. The camera is orthographic, so its scale and the body's
//! height are the same unknown: the height is given (default the description's, 158 cm for
//! 9AR), and the scale fitted. The girth — bust, waist and hip together, in the 9AR's
//! proportions — is fitted within the chart's bust range. The angles fitted are the major
//! joints' swings that a silhouette shows: each shoulder's flexion (x) and abduction (z), each
//! elbow's flexion, each hip's flexion and abduction, each knee's flexion; the others keep their
//! starting values. Seen exactly from the front, a limb swung forwards and the same limb swung
//! backwards have one silhouette, so a photograph for a walking pose should be taken at an
//! angle (`yaw_deg`, which the user gives); the elbows and knees bend one way only (their
//! limits), so their sign is never in doubt.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use atelier_body::build::Sizes;
use atelier_body::description::BodyDescription;
use atelier_body::{Body, Mannequin, Part, Pose, PoseRate, Posed, V3};
use atelier_fit::differenced::minimise_with;
use nalgebra::DVector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::camera::{Camera, blur, coverage, iou, reduce, samples_per_side};
use super::image::Mask;

/// The joint angles fitted: part, and the axes (0 x, 1 y, 2 z) of its joint.
pub const FITTED: [(Part, &[usize]); 8] = [
    (Part::UpperArmLeft, &[0, 2]),
    (Part::UpperArmRight, &[0, 2]),
    (Part::ForearmLeft, &[0]),
    (Part::ForearmRight, &[0]),
    (Part::ThighLeft, &[0, 2]),
    (Part::ThighRight, &[0, 2]),
    (Part::ShinLeft, &[0]),
    (Part::ShinRight, &[0]),
];

/// The size chart's bust range, cm: JIS L 4005 adult female numbers 3 to 21 (74 to 104 cm).
/// Waist and hip follow the bust in the description's proportions.
pub const BUST_RANGE_CM: (f64, f64) = (74.0, 104.0);

/// Samples per pixel side of the model's silhouette.
const SUPERSAMPLE: usize = 4;

/// The largest height, pixels, of the person at the finest level of the fit.
const FINEST_HEIGHT_PX: f64 = 240.0;

/// A pose as written in files: the `--pose` start and the fitted pose (`fitted_pose.ron`).
/// Joints are named by the part they move, angles (α, β, γ) in degrees as in motion files.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseFile {
    /// The camera (a start file may leave it out: it is then set from the mask's box).
    #[serde(default)]
    pub camera: Option<Camera>,
    /// The body's sizes (a start file may leave them out: the description's).
    #[serde(default)]
    pub sizes: Option<Sizes>,
    /// Joint angles, degrees; joints not named stay at rest.
    #[serde(default)]
    pub joints: BTreeMap<String, (f64, f64, f64)>,
}

impl PoseFile {
    /// Check names and values (every joint a part, every angle finite).
    pub fn check(&self) -> Result<(), atelier_fabric::InvalidValue> {
        use atelier_fabric::{ErrorKind, InvalidValue};
        for (name, a) in &self.joints {
            if atelier_body::motion::part_named(name).is_none() {
                return Err(InvalidValue::new(
                    ErrorKind::UnknownVariant,
                    format!("joints.{name}"),
                    format!("no joint named `{name}`"),
                ));
            }
            if ![a.0, a.1, a.2].iter().all(|v| v.is_finite()) {
                return Err(InvalidValue::new(
                    ErrorKind::NotFinite,
                    format!("joints.{name}"),
                    format!("({}, {}, {}) is not finite", a.0, a.1, a.2),
                ));
            }
        }
        if let Some(c) = &self.camera
            && !(c.scale.is_finite() && c.scale > 0.0 && c.yaw_deg.is_finite())
        {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                "camera",
                "the scale must be finite and positive, the yaw finite",
            ));
        }
        if let Some(s) = &self.sizes {
            s.check().map_err(|e| e.within("sizes"))?;
        }
        Ok(())
    }

    /// The angles of every part (rest where not named).
    pub fn angles(&self) -> [[f64; 3]; 17] {
        let mut a = [[0.0; 3]; 17];
        for (name, v) in &self.joints {
            if let Some(p) = atelier_body::motion::part_named(name) {
                a[p.index()] = [v.0, v.1, v.2];
            }
        }
        a
    }

    /// A pose file from the angles of every part (only non-zero joints written).
    pub fn from_angles(
        angles: &[[f64; 3]; 17],
        camera: Option<Camera>,
        sizes: Option<Sizes>,
    ) -> Self {
        let joints = Part::ALL
            .iter()
            .filter(|p| angles[p.index()].iter().any(|&v| v != 0.0))
            .map(|p| {
                let a = angles[p.index()];
                (p.name().to_string(), (a[0], a[1], a[2]))
            })
            .collect();
        Self {
            camera,
            sizes,
            joints,
        }
    }
}

/// What the fit is given besides the mask.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// The body description the mannequin is built from.
    pub description: BodyDescription,
    /// The body's height, cm (one photograph cannot tell it from the camera's scale).
    pub height_cm: f64,
    /// The camera's direction round the vertical, degrees (0: the photograph from the front).
    pub yaw_deg: f64,
    /// The start: angles, and optionally camera and sizes.
    pub start: PoseFile,
}

/// The fitted pose and how well it matches.
#[derive(Clone, Debug)]
pub struct PoseFit {
    /// Angles of every part, degrees.
    pub angles: [[f64; 3]; 17],
    /// The fitted camera.
    pub camera: Camera,
    /// The fitted sizes.
    pub sizes: Sizes,
    /// The silhouettes' overlap at the start (standard or given pose, camera from the mask's box).
    pub iou_before: f64,
    /// The silhouettes' overlap fitted.
    pub iou_after: f64,
    /// The fitted mannequin's silhouette at the mask's resolution (coverage).
    pub silhouette: Vec<f64>,
    /// Residual evaluations (each a rendered silhouette).
    pub evaluations: usize,
    /// Wall time of the fit, s.
    pub seconds: f64,
    /// How the last level's minimisation ended.
    pub termination: String,
}

/// The model: description, base sizes and joint limits. Its parameter vector, in units of about
/// a pixel's effect each: scale (percent of the start's), origin column and row (pixels), bust
/// girth (cm), then the fitted angles (degrees, in the order of [`FITTED`]).
struct Model<'a> {
    options: &'a FitOptions,
    base: Sizes,
    limits: [atelier_body::JointLimits; 17],
    bodies: Bodies<'a>,
}

/// The start's camera scale, px/m: the unit of the scale parameter.
#[derive(Clone, Copy, Debug)]
struct Start {
    scale: f64,
}

impl Model<'_> {
    fn sizes(&self, bust: f64) -> Sizes {
        let g = bust / self.base.bust_cm;
        Sizes {
            height_cm: self.options.height_cm,
            bust_cm: bust,
            waist_cm: self.base.waist_cm * g,
            hip_cm: self.base.hip_cm * g,
        }
    }

    /// Camera, sizes and angles of a parameter vector, clamped into their ranges; and how far
    /// outside the ranges the vector lies (per parameter, in its units).
    fn decode(
        &self,
        x: &DVector<f64>,
        start: Start,
        base_angles: &[[f64; 3]; 17],
    ) -> (Camera, Sizes, [[f64; 3]; 17], Vec<f64>) {
        let mut excess = Vec::with_capacity(x.len());
        let scale = start.scale * (1.0 + 0.01 * x[0]).max(0.05);
        let camera = Camera {
            yaw_deg: self.options.yaw_deg,
            scale,
            origin_px: [x[1], x[2]],
        };
        let bust = x[3].clamp(BUST_RANGE_CM.0, BUST_RANGE_CM.1);
        excess.push(x[3] - bust);
        let mut angles = *base_angles;
        let mut k = 4;
        for (part, axes) in FITTED {
            let lim = self.limits[part.index()];
            for &a in axes {
                let v = x[k].clamp(lim.min_deg[a], lim.max_deg[a]);
                excess.push(x[k] - v);
                angles[part.index()][a] = v;
                k += 1;
            }
        }
        (camera, self.sizes(bust), angles, excess)
    }

    fn encode(
        &self,
        camera: &Camera,
        start: Start,
        sizes: &Sizes,
        angles: &[[f64; 3]; 17],
    ) -> DVector<f64> {
        let mut x = vec![
            100.0 * (camera.scale / start.scale - 1.0),
            camera.origin_px[0],
            camera.origin_px[1],
            sizes.bust_cm,
        ];
        for (part, axes) in FITTED {
            for &a in axes {
                x.push(angles[part.index()][a]);
            }
        }
        DVector::from_vec(x)
    }
}

/// A triangle mesh: vertex positions (m) and triangles.
pub type Mesh = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// A mannequin of `sizes` posed at `angles`: its vertices and triangles.
pub fn posed_mannequin(
    description: &BodyDescription,
    sizes: &Sizes,
    angles: &[[f64; 3]; 17],
) -> Result<Mesh, String> {
    let mannequin = Mannequin::from_description(description, sizes).map_err(|e| e.to_string())?;
    let body = Body::new(mannequin);
    Ok((posed(&body, angles), body.rest.triangles.clone()))
}

/// Where the fitted mannequin's joints appear in the photograph: the pixel (column, row) of
/// every part's joint centre (its pivot: a forearm's is the elbow, a hand's the wrist, a shin's
/// the knee, a foot's the ankle), posed at the fit's angles and sizes, through its camera.
pub fn joint_pixels(
    description: &BodyDescription,
    fit: &PoseFit,
) -> Result<[[f64; 2]; 17], String> {
    let mannequin =
        Mannequin::from_description(description, &fit.sizes).map_err(|e| e.to_string())?;
    let frames = Body::new(mannequin).frames(&at_rest(&fit.angles));
    Ok(frames.map(|f| fit.camera.pixel([f.pivot.x, f.pivot.y, f.pivot.z])))
}

/// The pose at `angles` (degrees, by part), held still, the root at the origin.
fn at_rest(angles: &[[f64; 3]; 17]) -> PoseRate {
    let list: Vec<(Part, [f64; 3])> = Part::ALL.iter().map(|&p| (p, angles[p.index()])).collect();
    PoseRate {
        pose: Pose::from_angles(&list, V3::zeros()),
        omega: [V3::zeros(); 17],
        root_velocity: V3::zeros(),
    }
}

/// The vertices of `body` posed at `angles`.
fn posed(body: &Body, angles: &[[f64; 3]; 17]) -> Vec<[f64; 3]> {
    let mut out = Posed::default();
    body.pose_into(&at_rest(angles), &mut out);
    out.positions.iter().map(|p| [p.x, p.y, p.z]).collect()
}

/// The mannequins the fit has built, by size: most evaluations change only angles, and building
/// a mannequin (the description scaled, its girths corrected) costs more than posing it. The
/// last few sizes are kept.
struct Bodies<'a> {
    description: &'a BodyDescription,
    built: Mutex<Vec<(Sizes, Arc<Body>)>>,
}

impl Bodies<'_> {
    /// Sizes kept.
    const KEPT: usize = 8;

    fn at(&self, sizes: &Sizes) -> Result<Arc<Body>, String> {
        let lock = || {
            self.built
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        };
        if let Some((_, body)) = lock().iter().find(|(s, _)| s == sizes) {
            return Ok(Arc::clone(body));
        }
        let mannequin =
            Mannequin::from_description(self.description, sizes).map_err(|e| e.to_string())?;
        let body = Arc::new(Body::new(mannequin));
        let mut built = lock();
        if built.len() >= Self::KEPT {
            built.remove(0);
        }
        built.push((*sizes, Arc::clone(&body)));
        Ok(body)
    }

    /// The vertices of the mannequin of `sizes` posed at `angles`, and the mannequin.
    fn posed(
        &self,
        sizes: &Sizes,
        angles: &[[f64; 3]; 17],
    ) -> Result<(Vec<[f64; 3]>, Arc<Body>), String> {
        let body = self.at(sizes)?;
        Ok((posed(&body, angles), body))
    }
}

/// The camera that puts the model's box on the mask's box (scale from the heights, origin from
/// the centres).
fn camera_from_boxes(points: &[[f64; 3]], mask: &Mask, yaw_deg: f64) -> Option<Camera> {
    let [x0, y0, x1, y1] = mask.bounds()?;
    let probe = Camera {
        yaw_deg,
        scale: 1.0,
        origin_px: [0.0, 0.0],
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &p in points {
        let q = probe.view(p);
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let th = (y1 + 1 - y0) as f64;
    let scale = th / (hi[1] - lo[1]).max(1e-9);
    let centre = [0.5 * (x0 + x1 + 1) as f64, 0.5 * (y0 + y1 + 1) as f64];
    Some(Camera {
        yaw_deg,
        scale,
        origin_px: [
            centre[0] - scale * 0.5 * (lo[0] + hi[0]),
            centre[1] + scale * 0.5 * (lo[1] + hi[1]),
        ],
    })
}

/// Fit the mannequin to a mask. Errors: a start pose or size the mannequin cannot be built
/// with (the message says why).
pub fn fit_pose(mask: &Mask, options: &FitOptions) -> Result<PoseFit, String> {
    let clock = Instant::now();
    options
        .start
        .check()
        .map_err(|e| format!("the start pose: {e}"))?;
    let mut base = options.start.sizes.unwrap_or(options.description.sizes);
    base.height_cm = options.height_cm;
    let bodies = Bodies {
        description: &options.description,
        built: Mutex::new(Vec::new()),
    };
    let mut limits = [atelier_body::JointLimits::FIXED; 17];
    for p in &bodies.at(&base)?.mannequin.parts {
        limits[p.part.index()] = p.limits;
    }
    let model = Model {
        options,
        base,
        limits,
        bodies,
    };
    let start_angles = options.start.angles();
    let (points, body) = model.bodies.posed(&base, &start_angles)?;
    let triangles = &body.rest.triangles;
    let camera0 = match options.start.camera {
        Some(c) => Camera {
            yaw_deg: options.yaw_deg,
            ..c
        },
        None => camera_from_boxes(&points, mask, options.yaw_deg).ok_or("the mask is empty")?,
    };
    let full = (mask.width, mask.height);
    let target_full = mask.coverage();
    let full_ss = samples_per_side(full, SUPERSAMPLE);
    let before = coverage(&points, triangles, &camera0, full, full_ss);
    let iou_before = iou(&before, &target_full);

    let person_height = mask.bounds().map_or(1, |b| b[3] + 1 - b[1]) as f64;
    let finest = (person_height / FINEST_HEIGHT_PX).ceil().max(1.0) as usize;
    let evaluations = std::sync::atomic::AtomicUsize::new(0);
    // The coarse search per limb, then the camera from the boxes again.
    let searched = search_limbs(&model, mask, &start_angles, 4 * finest, &evaluations)?;
    let camera1 = if options.start.camera.is_some() {
        camera0
    } else {
        let (points, _) = model.bodies.posed(&base, &searched)?;
        camera_from_boxes(&points, mask, options.yaw_deg).ok_or("the mask is empty")?
    };
    let start = Start {
        scale: camera1.scale,
    };
    // An angle on its limit starts 1° inside: a central difference across the limit sees the
    // wall's penalty, not the silhouette (the elbows and knees rest on theirs).
    let mut searched = searched;
    for (part, axes) in FITTED {
        let lim = model.limits[part.index()];
        for &a in axes {
            let v = &mut searched[part.index()][a];
            if lim.max_deg[a] - lim.min_deg[a] > 2.0 {
                *v = v.clamp(lim.min_deg[a] + 1.0, lim.max_deg[a] - 1.0);
            }
        }
    }
    let mut x = model.encode(&camera1, start, &base, &searched);
    let bust0 = x[3];
    x[3] = bust0.clamp(BUST_RANGE_CM.0, BUST_RANGE_CM.1);
    let mut termination = String::new();
    for (factor, sigma) in [(4 * finest, 4.0), (2 * finest, 2.0), (finest, 1.0)] {
        let (reduced, rw, rh) = reduce(&target_full, full, factor);
        let target = blur(&reduced, (rw, rh), sigma);
        let norm = 1.0 / (reduced.iter().sum::<f64>().max(1.0)).sqrt();
        let f = factor as f64;
        let residuals = |x: &DVector<f64>| -> Option<DVector<f64>> {
            evaluations.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let (camera, sizes, angles, excess) = model.decode(x, start, &start_angles);
            let (points, body) = model.bodies.posed(&sizes, &angles).ok()?;
            let level_camera = Camera {
                scale: camera.scale / f,
                origin_px: [camera.origin_px[0] / f, camera.origin_px[1] / f],
                ..camera
            };
            let c = blur(
                &coverage(
                    &points,
                    &body.rest.triangles,
                    &level_camera,
                    (rw, rh),
                    SUPERSAMPLE,
                ),
                (rw, rh),
                sigma,
            );
            let mut r: Vec<f64> = c.iter().zip(&target).map(|(m, t)| norm * (m - t)).collect();
            // Outside a range: a steep penalty (the silhouette is evaluated at the clamped values).
            r.extend(excess.iter().map(|e| 0.1 * e));
            // The prior: the smallest turn from the start among the poses a silhouette allows.
            for (part, axes) in FITTED {
                for &a in axes {
                    r.push(
                        PRIOR.sqrt() * (angles[part.index()][a] - start_angles[part.index()][a])
                            / 10.0,
                    );
                }
            }
            Some(DVector::from_vec(r))
        };
        let step = (f / finest as f64 * 0.5).max(0.5);
        let (end, how) = minimise_with(x.clone(), step, 8, residuals);
        x = end;
        termination = how;
    }
    let (camera, sizes, angles, _) = model.decode(&x, start, &start_angles);
    let (points, body) = model.bodies.posed(&sizes, &angles)?;
    let silhouette = coverage(&points, &body.rest.triangles, &camera, full, full_ss);
    let iou_after = iou(&silhouette, &target_full);
    Ok(PoseFit {
        angles,
        camera,
        sizes,
        iou_before,
        iou_after,
        silhouette,
        evaluations: evaluations.into_inner(),
        seconds: clock.elapsed().as_secs_f64(),
        termination,
    })
}

/// The weight of the prior per (10°)² of turn from the start, against a silhouette distance
/// normalised by the person's area (so that a mismatch of the whole silhouette costs about 1).
const PRIOR: f64 = 1e-5;

/// The prior's cost of `angles` (the fitted ones) away from `start`.
fn prior(angles: &[[f64; 3]; 17], start: &[[f64; 3]; 17]) -> f64 {
    FITTED
        .iter()
        .flat_map(|(p, axes)| {
            axes.iter()
                .map(move |&a| (angles[p.index()][a] - start[p.index()][a]) / 10.0)
        })
        .map(|d| PRIOR * d * d)
        .sum()
}

/// The coarse search: each limb's joints in turn (shoulder flexion and abduction together, then
/// the elbow; hip flexion and abduction, then the knee) over a grid of 15° (shoulders) or 10°
/// (the others) across their limits, the camera put on the mask's box for every candidate, the
/// others held; twice round. A candidate replaces the current angles only when its silhouette
/// distance (on the mask reduced `factor` times, blurred 1 pixel) is smaller: the start is kept
/// where nothing beats it.
fn search_limbs(
    model: &Model<'_>,
    mask: &Mask,
    start: &[[f64; 3]; 17],
    factor: usize,
    evaluations: &std::sync::atomic::AtomicUsize,
) -> Result<[[f64; 3]; 17], String> {
    let (reduced, rw, rh) = reduce(&mask.coverage(), (mask.width, mask.height), factor);
    let target = blur(&reduced, (rw, rh), 1.0);
    let area = reduced.iter().sum::<f64>().max(1.0);
    let f = factor as f64;
    // Shifts up to a sixth of the person's height.
    let shift = mask
        .bounds()
        .map_or(0, |b| (b[3] + 1 - b[1]) / (6 * factor)) as isize;
    let distance = |angles: &[[f64; 3]; 17]| -> f64 {
        evaluations.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let Ok((points, body)) = model.bodies.posed(&model.base, angles) else {
            return f64::INFINITY;
        };
        let Some(camera) = camera_from_boxes(&points, mask, model.options.yaw_deg) else {
            return f64::INFINITY;
        };
        let level = Camera {
            scale: camera.scale / f,
            origin_px: [camera.origin_px[0] / f, camera.origin_px[1] / f],
            ..camera
        };
        let c = blur(
            &coverage(&points, &body.rest.triangles, &level, (rw, rh), 2),
            (rw, rh),
            1.0,
        );
        // The best horizontal shift (the box's centre is thrown off by limbs not yet fitted).
        let misfit = (-shift..=shift)
            .map(|d| {
                let mut sum = 0.0;
                for y in 0..rh {
                    for x in 0..rw {
                        let xs = x as isize - d;
                        let m = if xs >= 0 && (xs as usize) < rw {
                            c[y * rw + xs as usize]
                        } else {
                            0.0
                        };
                        sum += (m - target[y * rw + x]).powi(2);
                    }
                }
                sum
            })
            .fold(f64::INFINITY, f64::min);
        misfit / area + prior(angles, start)
    };
    let grid = |lo: f64, hi: f64, step: f64| -> Vec<f64> {
        let n = ((hi - lo) / step).floor() as usize;
        (0..=n).map(|k| lo + step * k as f64).collect()
    };
    let mut best = *start;
    let mut best_d = distance(&best);
    use Part::*;
    // Pairs first (the two sides' swing together, so that one limb cannot settle where the
    // other belongs), then each limb's joint.
    let groups: [(&[(Part, usize)], f64); 12] = [
        (&[(ThighLeft, 0), (ThighRight, 0)], 10.0),
        (&[(UpperArmLeft, 2), (UpperArmRight, 2)], 15.0),
        (&[(UpperArmLeft, 0), (UpperArmRight, 0)], 15.0),
        (&[(UpperArmLeft, 0), (UpperArmLeft, 2)], 15.0),
        (&[(ForearmLeft, 0)], 10.0),
        (&[(UpperArmRight, 0), (UpperArmRight, 2)], 15.0),
        (&[(ForearmRight, 0)], 10.0),
        (&[(ThighLeft, 0), (ThighLeft, 2)], 10.0),
        (&[(ShinLeft, 0)], 10.0),
        (&[(ThighRight, 0), (ThighRight, 2)], 10.0),
        (&[(ShinRight, 0)], 10.0),
        (&[(ShinLeft, 0), (ShinRight, 0)], 10.0),
    ];
    for _round in 0..2 {
        for (joints, step) in groups {
            let mut candidates: Vec<[[f64; 3]; 17]> = vec![];
            let values: Vec<Vec<f64>> = joints
                .iter()
                .map(|&(p, a)| {
                    let lim = model.limits[p.index()];
                    grid(lim.min_deg[a], lim.max_deg[a], step)
                })
                .collect();
            let mut idx = vec![0usize; joints.len()];
            loop {
                let mut c = best;
                for (k, &(p, a)) in joints.iter().enumerate() {
                    c[p.index()][a] = values[k][idx[k]];
                }
                candidates.push(c);
                let mut k = 0;
                while k < idx.len() {
                    idx[k] += 1;
                    if idx[k] < values[k].len() {
                        break;
                    }
                    idx[k] = 0;
                    k += 1;
                }
                if k == idx.len() {
                    break;
                }
            }
            let scored: Vec<(f64, usize)> = candidates
                .par_iter()
                .enumerate()
                .map(|(i, c)| (distance(c), i))
                .collect();
            if let Some(&(d, i)) = scored.iter().min_by(|a, b| a.0.total_cmp(&b.0))
                && d < best_d
            {
                best_d = d;
                best = candidates[i];
            }
        }
    }
    Ok(best)
}

/// A synthetic photograph for tests and figures: the mannequin of `sizes` at `angles` seen by
/// `camera`, skin-coloured and shaded, over a plain background; and its exact mask.
pub fn synthetic_photo(
    description: &BodyDescription,
    sizes: &Sizes,
    angles: &[[f64; 3]; 17],
    camera: &Camera,
    (w, h): (usize, usize),
) -> Result<(super::image::Photo, Mask), String> {
    let (points, triangles) = posed_mannequin(description, sizes, angles)?;
    let view: Vec<[f64; 3]> = points.iter().map(|&p| camera.view(p)).collect();
    const SKIN: [f64; 3] = [0.87, 0.67, 0.55];
    const BACKGROUND: [u8; 3] = [214, 222, 230];
    let light = camera.view_direction([0.3, 0.5, 1.0]);
    let pixels = atelier::picture::render_lit(
        &view,
        &triangles,
        &|_| SKIN,
        atelier::picture::View::Front,
        camera.fit(w, h, 1),
        (w, h),
        Some(light),
    );
    let mut data = Vec::with_capacity(3 * w * h);
    let mut mask = Vec::with_capacity(w * h);
    for p in &pixels {
        data.extend_from_slice(&p.map_or(BACKGROUND, atelier::picture::to_bytes));
        mask.push(p.is_some());
    }
    Ok((
        super::image::Photo {
            width: w,
            height: h,
            channels: 3,
            data,
        },
        Mask {
            width: w,
            height: h,
            data: mask,
        },
    ))
}
