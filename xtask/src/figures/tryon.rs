//! The try-on's figures and table (issue 11; `docs/tryon.md`): each synthetic photograph of
//! `atelier_tryon::examples` tried on with the sewn skirt (the sleeved dress's cost:
//! `docs/performance.md`) — photograph, fitted silhouette over the mask, composite, side by side (`tryon_<name>.png`) — and `tryon.md` with the overlap
//! before and after the fit, the worst joint-angle error, the size and the times. Then the
//! same photographs taken exactly from the front, fitted only, to measure what a frontal
//! silhouette leaves open, and one photograph segmented instead of masked.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use atelier::run::RunOptions;
use atelier_body::build::jis_9ar_description;
use atelier_tryon::camera::Camera;
use atelier_tryon::examples::{Example, examples};
use atelier_tryon::image::{Mask, encode, load_photo};
use atelier_tryon::pose::{FITTED, FitOptions, PoseFile, PoseFit, fit_pose, synthetic_photo};
use atelier_tryon::{TryonInputs, tryon};

/// The largest error over the fitted angles, degrees, and the joint it is at.
fn worst_angle(fit: &[[f64; 3]; 17], truth: &[[f64; 3]; 17]) -> (f64, String) {
    let mut worst = (0.0, String::from("-"));
    for (part, axes) in FITTED {
        for &a in axes {
            let e = (fit[part.index()][a] - truth[part.index()][a]).abs();
            if e > worst.0 {
                worst = (e, format!("{} {}", part.name(), ["x", "y", "z"][a]));
            }
        }
    }
    worst
}

fn mask_rgb(mask: &Mask) -> Vec<u8> {
    mask.data
        .iter()
        .flat_map(|&b| [if b { 255 } else { 0 }; 3])
        .collect()
}

/// Pictures of one height side by side, RGB.
fn tile(pictures: &[(usize, usize, Vec<u8>)]) -> (usize, usize, Vec<u8>) {
    let h = pictures[0].1;
    let w: usize = pictures.iter().map(|p| p.0).sum();
    let mut out = Vec::with_capacity(3 * w * h);
    for y in 0..h {
        for (pw, _, data) in pictures {
            out.extend_from_slice(&data[3 * y * pw..3 * (y + 1) * pw]);
        }
    }
    (w, h, out)
}

fn fit_only(e: &Example, yaw_deg: f64) -> Result<(PoseFit, Camera)> {
    let camera = Camera {
        yaw_deg,
        ..e.camera
    };
    let (_, mask) = synthetic_photo(&jis_9ar_description(), &e.sizes, &e.angles, &camera, e.size)
        .map_err(anyhow::Error::msg)?;
    let options = FitOptions {
        description: jis_9ar_description(),
        height_cm: e.sizes.height_cm,
        yaw_deg,
        start: PoseFile::default(),
    };
    Ok((
        fit_pose(&mask, &options).map_err(anyhow::Error::msg)?,
        camera,
    ))
}

pub fn draw_all(root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let garment = root.join("fixtures/scenarios/skirt_sewn.ron");
    let mut written = Vec::new();
    let mut md = String::new();
    writeln!(md, "# Try-on on synthetic photographs\n")?;
    writeln!(
        md,
        "The 9AR mannequin at bust 88 cm (two sizes up), posed, photographed by an orthographic camera 240 px/m, {} × {} px; fitted from the standard pose with the camera from the mask's box; then the sewn skirt (`skirt_sewn.ron`) dressed on the fitted body and moved to the fitted pose. Angle error: the largest over the 12 fitted angles.\n",
        examples()[0].size.0,
        examples()[0].size.1
    )?;
    writeln!(
        md,
        "| photograph | view | IoU before | IoU after | worst angle error | bust (truth 88 cm) | fit | evaluations | garment and motion | whole try-on |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|---|")?;
    for e in examples() {
        let dir = out.join(e.name);
        std::fs::create_dir_all(&dir)?;
        let (photo, mask) = synthetic_photo(
            &jis_9ar_description(),
            &e.sizes,
            &e.angles,
            &e.camera,
            e.size,
        )
        .map_err(anyhow::Error::msg)?;
        let (w, h) = e.size;
        std::fs::write(dir.join("photo.png"), encode(w, h, 3, &photo.data)?)?;
        std::fs::write(dir.join("mask.png"), encode(w, h, 3, &mask_rgb(&mask))?)?;
        let mut inputs = TryonInputs::new(
            dir.join("photo.png"),
            Some(dir.join("mask.png")),
            garment.clone(),
        );
        inputs.yaw_deg = Some(e.camera.yaw_deg);
        let clock = std::time::Instant::now();
        let report = tryon(
            &inputs,
            &dir.join("out"),
            &RunOptions::default(),
            &mut |_| {},
        )
        .with_context(|| format!("try-on of {}", e.name))?;
        let whole = clock.elapsed().as_secs_f64();
        let Some(info) = &report.tryon else {
            bail!("{}: no try-on section", e.name)
        };
        let fitted = PoseFile {
            joints: info.joints.clone(),
            ..PoseFile::default()
        }
        .angles();
        let (err, joint) = worst_angle(&fitted, &e.angles);
        writeln!(
            md,
            "| {} | {:+.0}° | {:.3} | {:.4} | {err:.2}° ({joint}) | {:.2} cm | {:.2} s | {} | {:.2} s | {whole:.1} s |",
            e.name,
            e.camera.yaw_deg,
            info.iou_before,
            info.iou_after,
            info.sizes.bust_cm,
            info.fit_s,
            info.evaluations,
            report.wall_s,
        )?;
        let picture = |name: &str| -> Result<(usize, usize, Vec<u8>)> {
            let p = load_photo(&dir.join("out").join(name))?;
            Ok((p.width, p.height, p.data))
        };
        let (tw, th, data) = tile(&[
            (w, h, photo.data.clone()),
            picture("overlay.png")?,
            picture("composite.png")?,
        ]);
        let path = out.join(format!("tryon_{}.png", e.name));
        atelier_files::files::write_atomic(&path, &encode(tw, th, 3, &data)?)?;
        written.push(path);
    }
    writeln!(
        md,
        "\n## The same photographs taken exactly from the front (fit only)\n\nA limb swung towards the camera and the same limb swung away have one silhouette; so have a forearm bent forwards and an arm lifted a little more. The fit takes the smallest turn from the start among the poses the silhouette allows (the prior, `PRIOR` in `tryon/pose.rs`).\n"
    )?;
    writeln!(
        md,
        "| photograph | IoU after | worst angle error | fit |\n|---|---|---|---|"
    )?;
    for e in examples() {
        let (fit, _) = fit_only(&e, 0.0)?;
        let (err, joint) = worst_angle(&fit.angles, &e.angles);
        writeln!(
            md,
            "| {} | {:.4} | {err:.1}° ({joint}) | {:.2} s |",
            e.name, fit.iou_after, fit.seconds
        )?;
    }
    // One photograph segmented instead of masked.
    let e = &examples()[1];
    let dir = out.join(e.name);
    let mut inputs = TryonInputs::new(dir.join("photo.png"), None, garment);
    inputs.yaw_deg = Some(e.camera.yaw_deg);
    let report = tryon(
        &inputs,
        &dir.join("segmented"),
        &RunOptions::default(),
        &mut |_| {},
    )
    .context("segmented try-on")?;
    if let Some(info) = &report.tryon {
        writeln!(
            md,
            "\n## Without a mask\n\n`{}` with the plain background segmented (threshold 40): IoU {:.3} → {:.4}, fit {:.2} s.",
            e.name, info.iou_before, info.iou_after, info.fit_s
        )?;
    }
    let path = out.join("tryon.md");
    atelier_files::files::write_atomic(&path, md.as_bytes())?;
    eprint!("{md}");
    written.push(path);
    Ok(written)
}
