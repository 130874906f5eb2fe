//! The mannequin's silhouette as the photograph's camera ([`Camera`], in the facade beside the
//! rasteriser) sees it.
//!
//! The camera is orthographic and level (no tilt, no roll): it looks horizontally at the body
//! from `yaw_deg` round the vertical axis (0: from the front; 90: from the body's left), and
//! maps a point to pixels by a scale and the pixel of the world origin (the point between the
//! mannequin's soles). The silhouette is rendered with `ss × ss` samples per pixel, so its
//! coverage moves with the parameters in steps of `1/ss²` — fine enough for the differences a
//! Levenberg–Marquardt Jacobian takes.

pub use atelier::camera::Camera;

/// The most samples a full-resolution render takes (16 M): a large photograph is rendered with
/// fewer samples per pixel rather than with gigabytes of buffer.
pub const MAX_SAMPLES: usize = 1 << 24;

/// Samples per pixel side for a `w × h` render: `wanted`, or fewer (at least 1) so that the
/// render stays within [`MAX_SAMPLES`].
pub fn samples_per_side((w, h): (usize, usize), wanted: usize) -> usize {
    let mut ss = wanted.max(1);
    while ss > 1 && w.saturating_mul(h).saturating_mul(ss * ss) > MAX_SAMPLES {
        ss -= 1;
    }
    ss
}

/// The fraction of each pixel of a `w × h` picture the mesh covers, from `ss × ss` samples per
/// pixel (row 0 at the top). Triangles facing away from the camera are skipped (a closed
/// surface's front faces cover its silhouette); each front triangle is filled row by row
/// between its edges, a sample counting when its centre lies inside or on an edge.
pub fn coverage(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    camera: &Camera,
    (w, h): (usize, usize),
    ss: usize,
) -> Vec<f64> {
    let (sw, sh) = (w * ss, h * ss);
    let mut out = vec![0.0; w * h];
    if sw == 0 || sh == 0 {
        return out;
    }
    let k = ss as f64;
    // Sample coordinates: column = (origin + scale·x)·ss, row = (origin − scale·y)·ss.
    let points: Vec<[f64; 3]> = positions
        .iter()
        .map(|&p| {
            let q = camera.view(p);
            [
                (camera.origin_px[0] + camera.scale * q[0]) * k,
                (camera.origin_px[1] - camera.scale * q[1]) * k,
                q[2],
            ]
        })
        .collect();
    let mut samples = vec![0u8; sw * sh];
    for t in triangles {
        let [a, b, c] = t.map(|i| points[i as usize]);
        // Rows grow downwards, so a triangle facing the camera (counter-clockwise in the view
        // frame) is clockwise here: its signed area is negative.
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        // (NaN coordinates fail the test too.)
        if area.is_nan() || area >= 0.0 {
            continue;
        }
        let y_lo = a[1].min(b[1]).min(c[1]);
        let y_hi = a[1].max(b[1]).max(c[1]);
        let r0 = (y_lo - 0.5).ceil().max(0.0) as usize;
        let r1 = (y_hi - 0.5).floor();
        if r1 < 0.0 {
            continue;
        }
        let r1 = (r1 as usize).min(sh - 1);
        let edges = [(a, b), (b, c), (c, a)];
        for row in r0..=r1 {
            let yc = row as f64 + 0.5;
            let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
            let mut empty = false;
            for (p, q) in edges {
                // Inside: (q − p) × (s − p) ≤ 0 (clockwise), linear in the sample's x.
                let slope = -(q[1] - p[1]);
                let constant = (q[0] - p[0]) * (yc - p[1]) + (q[1] - p[1]) * p[0];
                if slope > 0.0 {
                    hi = hi.min(-constant / slope);
                } else if slope < 0.0 {
                    lo = lo.max(-constant / slope);
                } else if constant > 0.0 {
                    empty = true;
                }
            }
            if empty || lo > hi {
                continue;
            }
            let c0 = (lo - 0.5).ceil().max(0.0);
            let c1 = (hi - 0.5).floor().min((sw - 1) as f64);
            if c1 < c0 {
                continue;
            }
            samples[row * sw + c0 as usize..=row * sw + c1 as usize].fill(1);
        }
    }
    let per = 1.0 / (ss * ss) as f64;
    for (y, row) in samples.chunks_exact(sw).enumerate() {
        let base = (y / ss) * w;
        for (x, &v) in row.iter().enumerate() {
            if v != 0 {
                out[base + x / ss] += per;
            }
        }
    }
    out
}

/// A separable Gaussian blur of standard deviation `sigma` pixels (kernel cut at 3σ; outside
/// the picture counts as 0). `sigma ≤ 0` returns the picture unchanged.
pub fn blur(image: &[f64], (w, h): (usize, usize), sigma: f64) -> Vec<f64> {
    if sigma <= 0.0 {
        return image.to_vec();
    }
    let r = (3.0 * sigma).ceil() as isize;
    let kernel: Vec<f64> = (-r..=r)
        .map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp())
        .collect();
    let total: f64 = kernel.iter().sum();
    let kernel: Vec<f64> = kernel.iter().map(|v| v / total).collect();
    // Along the rows of a `cols`-wide picture, zero-padded by r: no bounds tests inside.
    let pass = |src: &[f64], cols: usize| -> Vec<f64> {
        let r = r as usize;
        let mut padded = vec![0.0; cols + 2 * r];
        let mut dst = vec![0.0; src.len()];
        for (row_in, row_out) in src.chunks_exact(cols).zip(dst.chunks_exact_mut(cols)) {
            padded[r..r + cols].copy_from_slice(row_in);
            for (x, out) in row_out.iter_mut().enumerate() {
                *out = padded[x..x + kernel.len()]
                    .iter()
                    .zip(&kernel)
                    .map(|(v, k)| v * k)
                    .sum();
            }
        }
        dst
    };
    let transpose = |src: &[f64], cols: usize, rows: usize| -> Vec<f64> {
        let mut dst = vec![0.0; src.len()];
        for y in 0..rows {
            for x in 0..cols {
                dst[x * rows + y] = src[y * cols + x];
            }
        }
        dst
    };
    let across = pass(image, w);
    let down = pass(&transpose(&across, w, h), h);
    transpose(&down, h, w)
}

/// A picture reduced by an integer `factor` (each output pixel the mean of `factor²` input
/// pixels; a partial block at the right or bottom edge averages what it has).
pub fn reduce(image: &[f64], (w, h): (usize, usize), factor: usize) -> (Vec<f64>, usize, usize) {
    let (rw, rh) = (w.div_ceil(factor), h.div_ceil(factor));
    let mut sum = vec![0.0; rw * rh];
    let mut count = vec![0.0f64; rw * rh];
    for y in 0..h {
        for x in 0..w {
            let k = (y / factor) * rw + x / factor;
            sum[k] += image[y * w + x];
            count[k] += 1.0;
        }
    }
    let out = sum.iter().zip(&count).map(|(s, c)| s / c).collect();
    (out, rw, rh)
}

/// Intersection over union of two masks given as coverage (a pixel counts when ≥ ½).
pub fn iou(a: &[f64], b: &[f64]) -> f64 {
    let (mut inter, mut union) = (0usize, 0usize);
    for (&p, &q) in a.iter().zip(b) {
        let (p, q) = (p >= 0.5, q >= 0.5);
        inter += usize::from(p && q);
        union += usize::from(p || q);
    }
    if union == 0 {
        0.0
    } else {
        inter as f64 / union as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square (two triangles, facing +z) at the origin.
    fn square() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn coverage_of_a_square_is_its_area_in_pixels() {
        let (p, t) = square();
        // 10 px per metre, the origin at pixel (3.25, 15.5): the square spans 3.25..13.25 across
        // and 5.5..15.5 down; its area is exactly 100 px².
        let cam = Camera {
            yaw_deg: 0.0,
            scale: 10.0,
            origin_px: [3.25, 15.5],
        };
        let c = coverage(&p, &t, &cam, (20, 20), 4);
        let area: f64 = c.iter().sum();
        assert!((area - 100.0).abs() < 1e-9, "area {area}");
        // The columns cut by the left edge are a quarter covered... sampled at 4 per side:
        // column 3 spans 3..4, the edge at 3.25 leaves 3 of its 4 sample columns inside.
        assert!((c[10 * 20 + 3] - 0.75).abs() < 1e-12, "{}", c[10 * 20 + 3]);
        // Seen from the side (yaw 90°), the square is edge-on: nothing.
        let side = Camera {
            yaw_deg: 90.0,
            ..cam
        };
        assert!(
            coverage(&p, &t, &side, (20, 20), 4)
                .iter()
                .all(|&v| v == 0.0)
        );
        // From behind the square faces away: nothing either (one-sided, as a closed body's
        // back faces are).
        let back = Camera {
            yaw_deg: 180.0,
            ..cam
        };
        assert!(
            coverage(&p, &t, &back, (20, 20), 4)
                .iter()
                .all(|&v| v == 0.0)
        );
    }

    #[test]
    fn blur_keeps_the_total_and_reduce_keeps_the_mean() {
        let mut img = vec![0.0; 31 * 31];
        img[15 * 31 + 15] = 1.0;
        let b = blur(&img, (31, 31), 2.0);
        let total: f64 = b.iter().sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        // Symmetric, peaked at the centre, its variance along x σ² (to the cut at 3σ).
        assert!((b[15 * 31 + 14] - b[15 * 31 + 16]).abs() < 1e-15);
        let var: f64 = (0..31)
            .map(|x| {
                let col: f64 = (0..31).map(|y| b[y * 31 + x]).sum();
                col * (x as f64 - 15.0).powi(2)
            })
            .sum();
        assert!((var - 4.0).abs() < 0.1, "variance {var}");
        let (r, rw, rh) = reduce(&b, (31, 31), 4);
        assert_eq!((rw, rh), (8, 8));
        // 31 = 7·4 + 3: the last block averages 3 columns; the total of means × counts holds.
        assert!(r.iter().all(|v| v.is_finite()));
        assert_eq!(samples_per_side((420, 460), 4), 4);
        // 24 megapixels: one sample per pixel (4 would take 384 M samples).
        assert_eq!(samples_per_side((4000, 6000), 4), 1);
        assert_eq!(samples_per_side((2000, 2000), 4), 2);
        assert!((iou(&[1.0, 1.0, 0.0, 0.0], &[1.0, 0.0, 1.0, 0.0]) - 1.0 / 3.0).abs() < 1e-15);
    }
}
