//! Figures of the body gridded from range images (thesis Figs. 35–37): the synthetic 9AR
//! mannequin's range images gridded into one mesh, rendered front and back with flat shading and
//! a colour per part, and the error images |Z_e − Z_r|.

use std::path::{Path, PathBuf};

use anyhow::Result;
use atelier_body::range::synthetic::Mannequin;
use atelier_body::range::{BodyGridParams, BodyMesh, ErrorImage, Part, grid_body, measure_error};
use plotters::prelude::*;

use crate::figures::plot::{blit, png};
use atelier::picture::{Fit, View, part_colour, render, screen_box};

use crate::figures::plot::to_rgb;

/// Draw the body figures into `out`.
pub fn draw_all(out: &Path) -> Result<Vec<PathBuf>> {
    let body = Mannequin::jis_9ar().body(2.5);
    let (mesh, report) = grid_body(&body, &BodyGridParams::default())?;
    let error = measure_error(&mesh, &body);
    let parts_png = parts(
        &mesh,
        report.nodes,
        report.triangles,
        &out.join("body_parts.png"),
    )?;
    let caption = format!(
        "|Z_e − Z_r| (mm), synthetic 9AR mannequin, 2.5 mm pixels: {:.2} ± {:.2} mm, {} nodes = {:.2} % of {} samples",
        error.total.mean_abs_mm,
        error.total.sd_abs_mm,
        report.nodes,
        100.0 * error.compression,
        error.valid_samples
    );
    let error_png = error_images(
        &error.front,
        &error.back,
        &caption,
        &out.join("body_error.png"),
    )?;
    Ok(vec![parts_png, error_png])
}

fn parts(mesh: &BodyMesh, nodes: usize, triangles: usize, path: &Path) -> Result<PathBuf> {
    let (w, h) = (520usize, 900usize);
    let points: Vec<[f64; 3]> = mesh.positions.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let colour = |t: usize| part_colour(mesh.triangle_part[t].index());
    let views = [View::Front, View::Back].map(|view| {
        let (lo, hi) = screen_box(&points, view);
        render(
            &points,
            &mesh.triangles,
            &colour,
            view,
            Fit::new(lo, hi, w, h),
            w,
            h,
        )
    });
    png(path, (2 * w as u32 + 260, h as u32 + 60), |root| {
        root.draw(&Text::new(
            format!(
                "Body gridded from front and back range images: {nodes} nodes, {triangles} triangles, 17 parts (front | back)"
            ),
            (10, 12),
            ("sans-serif", 20).into_font(),
        ))?;
        for (v, pixels) in views.iter().enumerate() {
            blit(root, pixels, w, (v * w, 50))?;
        }
        for (k, p) in Part::ALL.iter().enumerate() {
            let y = 70 + 26 * k as i32;
            let x = 2 * w as i32 + 20;
            root.draw(&Rectangle::new(
                [(x, y), (x + 18, y + 18)],
                to_rgb(part_colour(p.index())).filled(),
            ))?;
            root.draw(&Text::new(
                p.name().to_owned(),
                (x + 26, y + 2),
                ("sans-serif", 15).into_font(),
            ))?;
        }
        Ok(())
    })
}

/// A blue–yellow–red ramp over `[0, max]`.
fn ramp(v: f64, max: f64) -> [f64; 3] {
    let t = (v / max).clamp(0.0, 1.0);
    if t < 0.5 {
        let s = t / 0.5;
        [0.15 + 0.85 * s, 0.3 + 0.65 * s, 0.7 - 0.5 * s]
    } else {
        let s = (t - 0.5) / 0.5;
        [1.0, 0.95 - 0.85 * s, 0.2 - 0.1 * s]
    }
}

fn error_images(
    front: &ErrorImage,
    back: &ErrorImage,
    caption: &str,
    path: &Path,
) -> Result<PathBuf> {
    const MAX_MM: f64 = 5.0;
    let (w, h) = (front.width, front.height);
    // Fit both views side by side into about 1100 × 900.
    let scale = (550.0 / w as f64).min(880.0 / h as f64);
    let (sw, sh) = ((w as f64 * scale) as usize, (h as f64 * scale) as usize);
    png(path, ((2 * sw + 200) as u32, (sh + 60) as u32), |root| {
        root.draw(&Text::new(
            caption.to_owned(),
            (10, 12),
            ("sans-serif", 17).into_font(),
        ))?;
        for (v, img) in [front, back].into_iter().enumerate() {
            for y in 0..sh {
                for x in 0..sw {
                    // Back view mirrored to the camera's view (stored in front column order).
                    let sx = ((x as f64 + 0.5) / scale) as usize;
                    let sx = if v == 1 {
                        w - 1 - sx.min(w - 1)
                    } else {
                        sx.min(w - 1)
                    };
                    let sy = (((y as f64 + 0.5) / scale) as usize).min(h - 1);
                    let k = sy * w + sx;
                    let e = img.error_mm[k];
                    let c = if e.is_finite() {
                        ramp(f64::from(e).abs(), MAX_MM)
                    } else if img.rendered_mm[k].is_finite() {
                        [0.6, 0.6, 0.6]
                    } else {
                        continue;
                    };
                    root.draw_pixel(((v * sw + x) as i32, (y + 50) as i32), &to_rgb(c))?;
                }
            }
        }
        // Colour bar.
        let x = 2 * sw as i32 + 40;
        for k in 0..=400 {
            let v = MAX_MM * f64::from(400 - k) / 400.0;
            root.draw(&Rectangle::new(
                [(x, 80 + k), (x + 24, 81 + k)],
                to_rgb(ramp(v, MAX_MM)).filled(),
            ))?;
        }
        for mm in [0.0, 1.0, 2.0, 3.0, 4.0, 5.0] {
            let y = 80 + (400.0 * (1.0 - mm / MAX_MM)) as i32;
            let label = if mm >= MAX_MM {
                "≥ 5 mm".to_owned()
            } else {
                format!("{mm:.0} mm")
            };
            root.draw(&Text::new(
                label,
                (x + 30, y - 7),
                ("sans-serif", 14).into_font(),
            ))?;
        }
        root.draw(&Text::new(
            "grey: mesh only".to_owned(),
            (x - 10, 500),
            ("sans-serif", 13).into_font(),
        ))?;
        Ok(())
    })
}
