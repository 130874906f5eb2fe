//! The garment over the photograph (thesis §6.2, step 3): the dressed mannequin rendered with
//! the fitted camera, 2 × 2 samples per pixel; where the garment is the nearest surface it is
//! drawn, shaded by the light; where the mannequin's body is nearest, or nothing, the
//! photograph shows. So the body parts the garment covers are hidden and those it does not
//! (face, hands, legs) are the photograph's own, and every pixel outside the garment's
//! footprint is the photograph's, bit for bit.

use super::camera::Camera;
use super::image::{Mask, Photo};
use atelier::picture::{MeshRef, rasterise, triangle_shade};

/// A composite and where the garment is.
#[derive(Clone, Debug)]
pub struct Composite {
    /// Samples, in the photograph's layout (its channels).
    pub data: Vec<u8>,
    /// Pixels the garment covers at least one sample of.
    pub footprint: Vec<bool>,
}

/// Draw the garment (`cloth`, both sides) over `photo`, hidden where the `body` is nearer the
/// camera, coloured `colour` and lit from `light` (a direction in the body frame towards the
/// light: x the body's left, y up, z forward).
pub fn composite(
    photo: &Photo,
    camera: &Camera,
    cloth: MeshRef<'_>,
    body: MeshRef<'_>,
    colour: [f64; 3],
    light: [f64; 3],
) -> Composite {
    let (w, h) = (photo.width, photo.height);
    // 2 × 2 samples per pixel, fewer for a photograph too large for them (each sample holds a
    // depth and a triangle).
    let ss = super::camera::samples_per_side((w, h), 2);
    let mut points: Vec<[f64; 3]> = cloth.0.iter().map(|&p| camera.view(p)).collect();
    let mut triangles: Vec<[u32; 3]> = cloth.1.to_vec();
    triangles.extend(cloth.1.iter().map(|t| [t[0], t[2], t[1]]));
    let n_cloth = triangles.len();
    let base = points.len() as u32;
    points.extend(body.0.iter().map(|&p| camera.view(p)));
    triangles.extend(body.1.iter().map(|t| t.map(|k| k + base)));
    let ids = rasterise(&points, &triangles, camera.fit(w, h, ss), w * ss, h * ss);
    // One shade per garment triangle (the samples look them up).
    let light = Some(camera.view_direction(light));
    let shades: Vec<[f64; 3]> = triangles[..n_cloth]
        .iter()
        .map(|t| {
            let shade = triangle_shade(t.map(|k| points[k as usize]), light);
            colour.map(|c| c * shade)
        })
        .collect();
    let mut data = photo.data.clone();
    let mut footprint = vec![false; w * h];
    let ch = photo.channels;
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0; 3];
            let mut k = 0usize;
            for sy in 0..ss {
                for sx in 0..ss {
                    if let Some(t) = ids[(y * ss + sy) * w * ss + x * ss + sx]
                        && (t as usize) < n_cloth
                    {
                        let c = shades[t as usize];
                        for i in 0..3 {
                            sum[i] += c[i];
                        }
                        k += 1;
                    }
                }
            }
            if k == 0 {
                continue;
            }
            let p = y * w + x;
            footprint[p] = true;
            let n = (ss * ss) as f64;
            let cover = k as f64 / n;
            for i in 0..3 {
                let photo_v = f64::from(photo.data[p * ch + i]) / 255.0;
                let v = sum[i] / n + (1.0 - cover) * photo_v;
                data[p * ch + i] = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            }
            if ch == 4 {
                let a = f64::from(photo.data[p * ch + 3]) / 255.0;
                data[p * ch + 3] = ((cover + (1.0 - cover) * a) * 255.0).round() as u8;
            }
        }
    }
    Composite { data, footprint }
}

/// The fit pictured: the photograph faded, the pixels in both the mask and the fitted
/// silhouette tinted green, in the mask only red, in the silhouette only blue (RGB samples).
pub fn overlay(photo: &Photo, mask: &Mask, silhouette: &[f64]) -> Vec<u8> {
    let mut out = Vec::with_capacity(3 * photo.width * photo.height);
    for (k, (&m, &s)) in mask.data.iter().zip(silhouette).enumerate() {
        let base = photo.rgb(k).map(|v| 0.5 * f64::from(v) + 0.5 * 235.0);
        let tint: Option<[f64; 3]> = match (m, s >= 0.5) {
            (true, true) => Some([60.0, 170.0, 75.0]),
            (true, false) => Some([220.0, 50.0, 40.0]),
            (false, true) => Some([40.0, 90.0, 220.0]),
            (false, false) => None,
        };
        let c = match tint {
            Some(t) => [0, 1, 2].map(|i| 0.45 * base[i] + 0.55 * t[i]),
            None => base,
        };
        out.extend(c.map(|v| v.round().clamp(0.0, 255.0) as u8));
    }
    out
}
