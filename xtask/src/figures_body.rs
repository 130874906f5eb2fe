//! Figures of the body gridded from range images (thesis Figs. 35–37): the synthetic 9AR
//! mannequin's range images gridded into one mesh, rendered front and back with flat shading and
//! a colour per part, and the error images |Z_e − Z_r|.

use std::path::{Path, PathBuf};

use anyhow::Result;
use atelier_grid::range::synthetic::Mannequin;
use atelier_grid::range::{BodyGridParams, BodyMesh, ErrorImage, Part, grid_body, measure_error};
use plotters::prelude::*;

use crate::plot::png;

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

/// One colour per part (hues around the wheel, left and right parts in neighbouring shades).
fn part_colour(p: Part) -> [f64; 3] {
    let k = p.index() as f64;
    let hue = (k * 0.618_034).fract();
    hsv(hue, 0.55, 0.95)
}

fn hsv(h: f64, s: f64, v: f64) -> [f64; 3] {
    let i = (h * 6.0).floor();
    let f = h * 6.0 - i;
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - f * s), v * (1.0 - (1.0 - f) * s));
    match i as i32 % 6 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    }
}

/// Orthographic z-buffer render of `mesh` seen along −z (front, `back == false`) or +z (back,
/// mirrored so the viewer's right is the body's left), flat shaded by the normal's component
/// towards the viewer. Returns RGB pixels (`None` = background), `w × h`.
fn render(mesh: &BodyMesh, back: bool, w: usize, h: usize) -> Vec<Option<[f64; 3]>> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &mesh.positions {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let scale = (0.94 * w as f64 / (hi[0] - lo[0])).min(0.94 * h as f64 / (hi[1] - lo[1]));
    let cx = 0.5 * (lo[0] + hi[0]);
    let cy = 0.5 * (lo[1] + hi[1]);
    let sign = if back { -1.0 } else { 1.0 };
    let project = |p: [f64; 3]| -> [f64; 3] {
        // Front: the body's left (+x) on the viewer's right; back: mirrored.
        [
            0.5 * w as f64 + sign * (p[0] - cx) * scale,
            0.5 * h as f64 - (p[1] - cy) * scale,
            sign * p[2],
        ]
    };
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    let mut colour = vec![None; w * h];
    for (t, part) in mesh.triangles.iter().zip(&mesh.triangle_part) {
        let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
        let n = cross(sub(b, a), sub(c, a));
        let len = dot(n, n).sqrt();
        if len == 0.0 {
            continue;
        }
        let facing = sign * n[2] / len;
        if facing <= 0.0 {
            continue;
        }
        let shade = 0.25 + 0.75 * facing;
        let base = part_colour(*part);
        let rgb = base.map(|v| v * shade);
        let [pa, pb, pc] = [a, b, c].map(project);
        let x0 = pa[0].min(pb[0]).min(pc[0]).floor().max(0.0) as usize;
        let x1 = (pa[0].max(pb[0]).max(pc[0]).ceil() as usize).min(w - 1);
        let y0 = pa[1].min(pb[1]).min(pc[1]).floor().max(0.0) as usize;
        let y1 = (pa[1].max(pb[1]).max(pc[1]).ceil() as usize).min(h - 1);
        let area = edge(pa, pb, pc);
        if area.abs() < 1e-12 {
            continue;
        }
        for y in y0..=y1 {
            for x in x0..=x1 {
                let q = [x as f64 + 0.5, y as f64 + 0.5, 0.0];
                let (l0, l1, l2) = (
                    edge(pb, pc, q) / area,
                    edge(pc, pa, q) / area,
                    edge(pa, pb, q) / area,
                );
                if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                    continue;
                }
                let z = l0 * pa[2] + l1 * pb[2] + l2 * pc[2];
                let k = y * w + x;
                if z > depth[k] {
                    depth[k] = z;
                    colour[k] = Some(rgb);
                }
            }
        }
    }
    colour
}

fn edge(a: [f64; 3], b: [f64; 3], p: [f64; 3]) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn to_rgb(c: [f64; 3]) -> RGBColor {
    let q = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    RGBColor(q(c[0]), q(c[1]), q(c[2]))
}

fn parts(mesh: &BodyMesh, nodes: usize, triangles: usize, path: &Path) -> Result<PathBuf> {
    let (w, h) = (520usize, 900usize);
    let views = [render(mesh, false, w, h), render(mesh, true, w, h)];
    png(path, (2 * w as u32 + 260, h as u32 + 60), |root| {
        root.draw(&Text::new(
            format!(
                "Body gridded from front and back range images: {nodes} nodes, {triangles} triangles, 17 parts (front | back)"
            ),
            (10, 12),
            ("sans-serif", 20).into_font(),
        ))?;
        for (v, pixels) in views.iter().enumerate() {
            for y in 0..h {
                for x in 0..w {
                    if let Some(c) = pixels[y * w + x] {
                        root.draw_pixel(((v * w + x) as i32, (y + 50) as i32), &to_rgb(c))?;
                    }
                }
            }
        }
        for (k, p) in Part::ALL.iter().enumerate() {
            let y = 70 + 26 * k as i32;
            let x = 2 * w as i32 + 20;
            root.draw(&Rectangle::new(
                [(x, y), (x + 18, y + 18)],
                to_rgb(part_colour(*p)).filled(),
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
