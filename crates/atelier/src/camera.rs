//! An orthographic, level camera (the try-on's photograph, `atelier tryon`): no tilt, no roll;
//! it looks horizontally at the body from `yaw_deg` round the vertical axis (0: from the front;
//! 90: from the body's left), and maps a point to pixels by a scale and the pixel of the world
//! origin (the point between the mannequin's soles). It lives beside the rasteriser
//! ([`crate::picture`]), whose picture fitting it produces; the silhouette search that fits it
//! to a photograph is in `atelier-tryon`.

use serde::{Deserialize, Serialize};

use crate::picture::Fit;

/// An orthographic, level camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// Direction round the vertical axis, degrees: 0 from the front, 90 from the body's left.
    pub yaw_deg: f64,
    /// Pixels per metre.
    pub scale: f64,
    /// Pixel (column, row; row 0 at the top) of the world origin.
    pub origin_px: [f64; 2],
}

impl Camera {
    /// A point in the camera's view frame: (across to the right, up, towards the camera), m.
    pub fn view(&self, p: [f64; 3]) -> [f64; 3] {
        let (s, c) = self.yaw_deg.to_radians().sin_cos();
        [p[0] * c - p[2] * s, p[1], p[0] * s + p[2] * c]
    }

    /// A direction given in the body frame turned into the view frame.
    pub fn view_direction(&self, d: [f64; 3]) -> [f64; 3] {
        self.view(d)
    }

    /// The pixel (column, row) a point projects to.
    pub fn pixel(&self, p: [f64; 3]) -> [f64; 2] {
        let q = self.view(p);
        [
            self.origin_px[0] + self.scale * q[0],
            self.origin_px[1] - self.scale * q[1],
        ]
    }

    /// The picture fitting of this camera for a `w × h` picture at `ss` samples per pixel side
    /// (the fitting of `w·ss × h·ss` samples).
    pub fn fit(&self, w: usize, h: usize, ss: usize) -> Fit {
        // u = w/2 + (x − c₀)·s = origin + s·x  ⇒  c₀ = (w/2 − origin)/s (and likewise for v).
        let c0 = (0.5 * w as f64 - self.origin_px[0]) / self.scale;
        let c1 = (self.origin_px[1] - 0.5 * h as f64) / self.scale;
        Fit::with_scale(self.scale * ss as f64, [c0, c1])
    }
}
