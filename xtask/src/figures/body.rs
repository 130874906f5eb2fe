//! Figures of the mannequin (issue 6): front and side views at rest and at phases of the walk,
//! the arm raise, and the front and back range images of the rest pose with their landmarks.

use std::path::{Path, PathBuf};

use anyhow::Result;
use atelier_body::range::{RenderParams, render_views};
use atelier_body::{Body, LabelledMesh, Motion};
use plotters::prelude::*;

use crate::figures::plot::{blit, png};
use atelier::picture::{Fit, View, part_colour, render, screen_box};

use crate::figures::plot::to_rgb;

/// Draw the body figures into `out`; returns the files written.
pub fn draw_all(root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let mannequin = atelier_body::build::jis_9ar();
    let body = Body::new(mannequin);
    let walk = Motion::load(&root.join("fixtures/motions/walk.ron"), &body.mannequin)?;
    let raise = Motion::load(
        &root.join("fixtures/motions/arm_raise.ron"),
        &body.mannequin,
    )?;
    let (nv, nt) = body.mannequin.counts();
    // The walk from the second full cycle on (steady amplitude): quarter cycles of 1.1 s.
    let walk_times = [0.0, 2.5, 2.775, 3.05, 3.325];
    let mut written = vec![
        poses(
            &body,
            &walk,
            &walk_times,
            &format!(
                "Mannequin (JIS 9AR, {nv} vertices, {nt} triangles, 17 parts): rest, and the walk at quarter gait cycles"
            ),
            &out.join("body_walk.png"),
        )?,
        poses(
            &body,
            &raise,
            &[0.0, 0.75, 1.5],
            "Arm raise: rest, halfway, 80° abduction",
            &out.join("body_arm_raise.png"),
        )?,
    ];
    written.push(range_images(
        &body.rest,
        &out.join("body_range_images.png"),
    )?);
    Ok(written)
}

fn posed_mesh(body: &Body, motion: &Motion, t: f64) -> Vec<[f64; 3]> {
    body.at(motion, t)
        .positions
        .iter()
        .map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Front (top row) and left side (bottom row) views of the body at the given times, all at the
/// same scale.
fn poses(body: &Body, motion: &Motion, times: &[f64], title: &str, path: &Path) -> Result<PathBuf> {
    let (w, h) = (330usize, 560usize);
    let meshes: Vec<Vec<[f64; 3]>> = times.iter().map(|&t| posed_mesh(body, motion, t)).collect();
    let colour = |t: usize| part_colour(body.rest.triangle_part[t].index());
    // One scale for every panel: the largest screen box of any pose, each centred on itself.
    let mut span = [0.0f64; 2];
    for m in &meshes {
        for view in [View::Front, View::Left] {
            let (lo, hi) = screen_box(m, view);
            span = [span[0].max(hi[0] - lo[0]), span[1].max(hi[1] - lo[1])];
        }
    }
    png(
        path,
        ((w * times.len()) as u32, (2 * h + 50) as u32),
        |root| {
            root.draw(&Text::new(
                title.to_owned(),
                (10, 12),
                ("sans-serif", 19).into_font(),
            ))?;
            for (k, (m, t)) in meshes.iter().zip(times).enumerate() {
                for (row, view) in [View::Front, View::Left].into_iter().enumerate() {
                    let (lo, hi) = screen_box(m, view);
                    let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
                    let fit = Fit::new(
                        [c[0] - 0.5 * span[0], c[1] - 0.5 * span[1]],
                        [c[0] + 0.5 * span[0], c[1] + 0.5 * span[1]],
                        w,
                        h,
                    );
                    let pixels = render(m, &body.rest.triangles, &colour, view, fit, w, h);
                    blit(root, &pixels, w, (k * w, row * h + 40))?;
                    let label = format!(
                        "t = {t:.3} s, {}",
                        if row == 0 { "front" } else { "left side" }
                    );
                    root.draw(&Text::new(
                        label,
                        ((k * w + 10) as i32, (row * h + 44) as i32),
                        ("sans-serif", 15).into_font(),
                    ))?;
                }
            }
            Ok(())
        },
    )
}

/// The rest pose's front and back range images (grey = depth, nearer brighter) with the
/// landmarks the gridding needs.
fn range_images(mesh: &LabelledMesh, path: &Path) -> Result<PathBuf> {
    let views = render_views(mesh, 2.5, &RenderParams::default())?;
    let (w, h) = (views.front.image.width, views.front.image.height);
    let scale = (520.0 / w as f64).min(860.0 / h as f64).min(1.0);
    let (sw, sh) = ((w as f64 * scale) as usize, (h as f64 * scale) as usize);
    let landmarks = views.landmarks().clone();
    png(path, ((2 * sw + 40) as u32, (sh + 60) as u32), |root| {
        root.draw(&Text::new(
            format!(
                "Range images, rest pose, 2.5 mm pixels ({w} × {h}): front | back (mirrored); {} landmarks",
                landmarks.len()
            ),
            (10, 12),
            ("sans-serif", 16).into_font(),
        ))?;
        for (v, view) in [&views.front, &views.back].into_iter().enumerate() {
            let data = &view.image.data;
            let (lo, hi) = data
                .iter()
                .filter(|&&d| d > 0)
                .fold((u16::MAX, 0u16), |(a, b), &d| (a.min(d), b.max(d)));
            let x0 = v * (sw + 40);
            for y in 0..sh {
                for x in 0..sw {
                    let sx = (((x as f64 + 0.5) / scale) as usize).min(w - 1);
                    let sy = (((y as f64 + 0.5) / scale) as usize).min(h - 1);
                    let d = data[sy * w + sx];
                    if d == 0 {
                        continue;
                    }
                    // Larger grey = farther from the camera: draw near as bright.
                    let g = 1.0 - 0.85 * f64::from(d - lo) / f64::from((hi - lo).max(1));
                    root.draw_pixel(((x0 + x) as i32, (y + 50) as i32), &to_rgb([g, g, g]))?;
                }
            }
        }
        for (name, (c, r)) in &landmarks {
            let p = ((c * scale) as i32, (r * scale) as i32 + 50);
            root.draw(&Circle::new(p, 3, RGBColor(220, 30, 30).filled()))?;
            if name.ends_with("_l") || name.ends_with("_r") {
                continue;
            }
            root.draw(&Text::new(
                name.clone(),
                (p.0 + 4, p.1 - 6),
                ("sans-serif", 10).into_font(),
            ))?;
        }
        Ok(())
    })
}
