//! Virtual try-on (issue 11): the round trip on synthetic photographs (the pose and size that
//! made the photograph recovered from its mask), the composite's promise (the photograph
//! untouched outside the garment), and the refusals of bad input.

use std::path::{Path, PathBuf};

use atelier::run::RunOptions;
use atelier_body::build::jis_9ar_description;
use atelier_tryon::examples::{Example, examples};
use atelier_tryon::image::{Mask, Photo, encode, load_photo, segment_plain_background};
use atelier_tryon::pose::{FITTED, FitOptions, PoseFile, fit_pose, synthetic_photo};
use atelier_tryon::{TryonError, TryonInputs, fit_warnings, load_inputs, tryon};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("atelier-tryon-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn example(name: &str) -> Example {
    examples()
        .into_iter()
        .find(|e| e.name == name)
        .expect("example")
}

fn photo_of(e: &Example) -> (Photo, Mask) {
    synthetic_photo(
        &jis_9ar_description(),
        &e.sizes,
        &e.angles,
        &e.camera,
        e.size,
    )
    .expect("photo")
}

fn write_rgb(path: &Path, w: usize, h: usize, data: &[u8]) {
    std::fs::write(path, encode(w, h, 3, data).expect("encode")).expect("write");
}

fn mask_bytes(mask: &Mask) -> Vec<u8> {
    mask.data
        .iter()
        .flat_map(|&b| [if b { 255 } else { 0 }; 3])
        .collect()
}

/// Fit the example's mask from the standard pose; every fitted angle within 5° of the truth,
/// the silhouettes overlapping by at least 0.95, and the size and scale recovered.
fn round_trip(name: &str) {
    let e = example(name);
    let (_, mask) = photo_of(&e);
    let options = FitOptions {
        description: jis_9ar_description(),
        height_cm: e.sizes.height_cm,
        yaw_deg: e.camera.yaw_deg,
        start: PoseFile::default(),
    };
    let fit = fit_pose(&mask, &options).expect("fit");
    let mut worst: (f64, String) = (0.0, String::new());
    for (part, axes) in FITTED {
        for &a in axes {
            let err = (fit.angles[part.index()][a] - e.angles[part.index()][a]).abs();
            if err > worst.0 {
                worst = (err, format!("{} axis {a}", part.name()));
            }
        }
    }
    assert!(
        worst.0 <= 5.0,
        "{name}: {} off by {:.2}° (fitted {:?})",
        worst.1,
        worst.0,
        fit.angles
    );
    assert!(fit.iou_after >= 0.95, "{name}: IoU {:.4}", fit.iou_after);
    assert!(
        fit.iou_before < fit.iou_after,
        "{name}: {} → {}",
        fit.iou_before,
        fit.iou_after
    );
    assert!(
        (fit.sizes.bust_cm - e.sizes.bust_cm).abs() <= 2.0,
        "{name}: bust {:.2} cm, truth {}",
        fit.sizes.bust_cm,
        e.sizes.bust_cm
    );
    assert!(
        (fit.camera.scale / e.camera.scale - 1.0).abs() <= 0.02,
        "{name}: scale {:.2} px/m, truth {}",
        fit.camera.scale,
        e.camera.scale
    );
}

#[test]
fn round_trip_standing() {
    round_trip("standing");
}

#[test]
fn round_trip_arms_raised() {
    round_trip("arms_raised");
}

#[test]
fn round_trip_mid_stride() {
    round_trip("mid_stride");
}

#[test]
fn the_composite_keeps_the_photograph_outside_the_garment() {
    let dir = temp_dir("composite");
    let e = example("arms_raised");
    let (photo, mask) = photo_of(&e);
    let (w, h) = e.size;
    write_rgb(&dir.join("photo.png"), w, h, &photo.data);
    write_rgb(&dir.join("mask.png"), w, h, &mask_bytes(&mask));
    let mut inputs = TryonInputs::new(
        dir.join("photo.png"),
        Some(dir.join("mask.png")),
        root().join("fixtures/scenarios/skirt_sewn.ron"),
    );
    inputs.yaw_deg = Some(e.camera.yaw_deg);
    let out = dir.join("out");
    let report = tryon(&inputs, &out, &RunOptions::default(), &mut |_| {}).expect("tryon");
    assert!(report.passed(), "{}", report.summary_line());
    let info = report.tryon.as_ref().expect("tryon section");
    assert!(info.iou_after >= 0.95, "IoU {}", info.iou_after);
    for name in [
        "composite.png",
        "overlay.png",
        "footprint.png",
        "fitted_pose.ron",
        "report.json",
        "final.obj",
    ] {
        assert!(out.join(name).is_file(), "{name} missing");
        assert!(
            name == "report.json" || report.outputs.iter().any(|o| o == name),
            "{name} not listed"
        );
    }
    let composite = load_photo(&out.join("composite.png")).expect("composite");
    let footprint = load_photo(&out.join("footprint.png")).expect("footprint");
    let original = load_photo(&dir.join("photo.png")).expect("photo");
    assert_eq!(
        (composite.width, composite.height, composite.channels),
        (w, h, 3)
    );
    let mut inside = 0;
    let mut changed_inside = 0;
    for k in 0..w * h {
        if footprint.rgb(k)[0] == 0 {
            assert_eq!(
                composite.rgb(k),
                original.rgb(k),
                "pixel ({}, {}) outside the garment changed",
                k % w,
                k / w
            );
        } else {
            inside += 1;
            changed_inside += usize::from(composite.rgb(k) != original.rgb(k));
        }
    }
    assert_eq!(inside, info.garment_pixels);
    // The skirt covers a good part of the person, and it shows.
    assert!(
        inside * 5 > mask.count(),
        "{inside} garment pixels of {}",
        mask.count()
    );
    assert!(
        changed_inside * 100 >= inside * 95,
        "{changed_inside} of {inside} changed"
    );
    // The face and the feet are the photograph's: no garment in the person's top and bottom
    // tenths.
    let [_, y0, _, y1] = mask.bounds().expect("someone");
    let tenth = (y1 - y0) / 10;
    for y in (y0..y0 + tenth).chain(y1 - tenth..=y1) {
        for x in 0..w {
            assert_eq!(footprint.rgb(y * w + x)[0], 0, "garment at ({x}, {y})");
        }
    }
    // The fitted pose file reads back as a start pose.
    let fitted: PoseFile =
        atelier_files::files::load_ron(&out.join("fitted_pose.ron")).expect("fitted pose");
    fitted.check().expect("valid");
    assert!(fitted.camera.is_some() && fitted.sizes.is_some());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_plain_background_segmentation_recovers_the_mask() {
    for e in examples() {
        let (photo, mask) = photo_of(&e);
        let seg = segment_plain_background(&photo, 40);
        let wrong = seg
            .data
            .iter()
            .zip(&mask.data)
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            wrong * 1000 <= mask.count(),
            "{}: {wrong} pixels differ of {}",
            e.name,
            mask.count()
        );
    }
}

#[test]
fn a_mask_the_mannequin_cannot_match_is_reported() {
    // A filled disc: nothing like a person.
    let (w, h) = (300, 300);
    let data = (0..w * h)
        .map(|k| {
            let (x, y) = ((k % w) as f64 - 150.0, (k / w) as f64 - 150.0);
            x * x + y * y < 100.0 * 100.0
        })
        .collect();
    let mask = Mask {
        width: w,
        height: h,
        data,
    };
    let options = FitOptions {
        description: jis_9ar_description(),
        height_cm: 158.0,
        yaw_deg: 0.0,
        start: PoseFile::default(),
    };
    let fit = fit_pose(&mask, &options).expect("fit runs");
    assert!(fit.iou_after < 0.8, "IoU {}", fit.iou_after);
    let warnings = fit_warnings(&mask, &fit);
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("could not match the mask")),
        "{warnings:?}"
    );
}

#[test]
fn bad_inputs_are_refused_naming_the_file_and_the_reason() {
    let dir = temp_dir("bad");
    let e = example("standing");
    let (photo, mask) = photo_of(&e);
    let (w, h) = e.size;
    let photo_path = dir.join("photo.png");
    write_rgb(&photo_path, w, h, &photo.data);
    let garment = root().join("fixtures/scenarios/dress_sewn.ron");
    let refuse = |mask_path: &Path| -> String {
        let inputs = TryonInputs::new(
            photo_path.clone(),
            Some(mask_path.to_path_buf()),
            garment.clone(),
        );
        match load_inputs(&inputs) {
            Err(TryonError::File(e)) => {
                assert_eq!(e.file, mask_path);
                e.to_string()
            }
            other => panic!(
                "{} accepted or wrong error: {:?}",
                mask_path.display(),
                other.err()
            ),
        }
    };
    // An empty mask.
    let empty = dir.join("empty.png");
    write_rgb(&empty, w, h, &vec![0; 3 * w * h]);
    assert!(
        refuse(&empty).contains("nobody to fit"),
        "{}",
        refuse(&empty)
    );
    // A mask of another size.
    let small = dir.join("small.png");
    write_rgb(&small, w / 2, h, &vec![0; 3 * (w / 2) * h]);
    let m = refuse(&small);
    assert!(
        m.contains(&format!("{} × {h}", w / 2)) && m.contains(&format!("{w} × {h}")),
        "{m}"
    );
    // The photograph given as its own mask: not black and white (the first grey pixel named).
    let m = refuse(&photo_path);
    assert!(m.contains("not a mask") && m.contains(':'), "{m}");
    // Not a PNG at all, and no file.
    let text = dir.join("mask.png");
    std::fs::write(&text, "not a picture").expect("write");
    assert!(
        refuse(&text).contains("not a readable PNG"),
        "{}",
        refuse(&text)
    );
    let m = refuse(&dir.join("missing.png"));
    assert!(m.contains("missing.png"), "{m}");
    // A mask that is all person.
    let full = dir.join("full.png");
    write_rgb(&full, w, h, &vec![255; 3 * w * h]);
    assert!(refuse(&full).contains("no background"), "{}", refuse(&full));
    // A garment that is not a garment scenario.
    let good_mask = dir.join("good.png");
    write_rgb(&good_mask, w, h, &mask_bytes(&mask));
    let inputs = TryonInputs::new(
        photo_path.clone(),
        Some(good_mask),
        root().join("fixtures/scenarios/drape_jis_silk.ron"),
    );
    match tryon(
        &inputs,
        &dir.join("out"),
        &RunOptions::default(),
        &mut |_| {},
    ) {
        Err(TryonError::Input(m)) => assert!(m.contains("kind Garment"), "{m}"),
        other => panic!("a drape scenario accepted as a garment: {:?}", other.err()),
    }
    // A start pose naming a joint that does not exist.
    let pose = dir.join("start.ron");
    std::fs::write(&pose, "(joints: {\"elbow\": (0.0, 0.0, 10.0)})").expect("write");
    let mut inputs = TryonInputs::new(photo_path.clone(), Some(dir.join("good.png")), garment);
    inputs.pose = Some(pose);
    match tryon(
        &inputs,
        &dir.join("out"),
        &RunOptions::default(),
        &mut |_| {},
    ) {
        Err(TryonError::File(e)) => assert_eq!(e.field, "joints.elbow", "{e}"),
        other => panic!("a bad start pose accepted: {:?}", other.err()),
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_given_start_pose_is_where_the_fit_starts() {
    // Started at the truth (as `--pose` gives it), the start already overlaps (the standard pose
    // overlaps the arms-raised silhouette by 0.29) and the fit stays there.
    let e = example("arms_raised");
    let (_, mask) = photo_of(&e);
    let start = PoseFile::from_angles(&e.angles, None, None);
    let text = ron::ser::to_string(&start).expect("serialises");
    let start: PoseFile =
        atelier_files::files::parse_ron(&text, Path::new("start.ron")).expect("reads back");
    let options = FitOptions {
        description: jis_9ar_description(),
        height_cm: e.sizes.height_cm,
        yaw_deg: e.camera.yaw_deg,
        start,
    };
    let fit = fit_pose(&mask, &options).expect("fit");
    assert!(fit.iou_before >= 0.9, "IoU at the start {}", fit.iou_before);
    assert!(fit.iou_after >= 0.95, "IoU {}", fit.iou_after);
    for (part, axes) in FITTED {
        for &a in axes {
            let err = (fit.angles[part.index()][a] - e.angles[part.index()][a]).abs();
            assert!(err <= 5.0, "{} axis {a}: {err:.2}°", part.name());
        }
    }
}
