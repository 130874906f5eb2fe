//! A synthetic mannequin for tests, figures and benches: an analytic closed body in an A-pose,
//! roughly JIS 9AR (female, height 158 cm, bust 83, waist 64, hip 91 cm), with its exact front and
//! back orthographic range images and the landmarks the part split needs.
//!
//! The body is the union of seven *swept pieces*: the axial piece (trunk, neck and head along the
//! vertical axis), two arms (hands included), two legs, and two feet. A swept piece has a straight
//! axis in the image plane (`z` constant direction), and its cross-section perpendicular to the
//! axis is a superellipse `|s/a|^p + |(z − c)/b|^p ≤ 1` whose half-width `a` (in the image plane),
//! half-depth `b` and depth centre `c` vary smoothly along the axis (Catmull–Rom through knots),
//! rounded to a closed tip at each end by an elliptic cap. Since the cross-section plane contains
//! the line of sight, the range image of a piece is exact per pixel: at `(x, y)` with axial
//! coordinate `t` and offset `s`, the piece spans `z = c(t) ± b(t)(1 − |s/a(t)|^p)^{1/p}`. The
//! feet are ellipsoids elongated along `z` (toes forward). The union is closed and continuous;
//! the pieces overlap where they join, so every line of sight meets the body in one interval
//! (checked by the tests through the volume).

use std::path::{Path, PathBuf};

use super::body::RangeBody;
use super::image::{GrayImage, write_image};
use super::side::{SideFile, View};

/// Knots `(t mm along the axis, half-width a, half-depth b, depth centre c)`, mm.
type Knot = (f64, f64, f64, f64);

#[derive(Clone, Debug)]
struct Swept {
    start: [f64; 2],
    dir: [f64; 2],
    length: f64,
    cap0: f64,
    cap1: f64,
    p: f64,
    knots: Vec<Knot>,
}

impl Swept {
    fn new(start: [f64; 2], end: [f64; 2], caps: (f64, f64), p: f64, knots: Vec<Knot>) -> Self {
        let d = [end[0] - start[0], end[1] - start[1]];
        let length = d[0].hypot(d[1]);
        Self {
            start,
            dir: [d[0] / length, d[1] / length],
            length,
            cap0: caps.0,
            cap1: caps.1,
            p,
            knots,
        }
    }

    /// `(a, b, c)` at `t` by Catmull–Rom through the knots (clamped at the ends).
    fn profile(&self, t: f64) -> (f64, f64, f64) {
        let k = &self.knots;
        let n = k.len();
        let i = k.partition_point(|q| q.0 <= t).clamp(1, n - 1) - 1;
        let (t0, t1) = (k[i].0, k[i + 1].0);
        let u = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let get = |j: isize| k[j.clamp(0, n as isize - 1) as usize];
        let (pm, p0, p1, p2) = (get(i as isize - 1), k[i], k[i + 1], get(i as isize + 2));
        let cr = |a: f64, b: f64, c: f64, d: f64, ta: f64, tb: f64, tc: f64, td: f64| {
            // Tangents scaled to the segment (non-uniform Catmull–Rom).
            let m1 = if tc > ta {
                (c - a) / (tc - ta) * (tc - tb)
            } else {
                c - b
            };
            let m2 = if td > tb {
                (d - b) / (td - tb) * (tc - tb)
            } else {
                c - b
            };
            let (u2, u3) = (u * u, u * u * u);
            (2.0 * u3 - 3.0 * u2 + 1.0) * b
                + (u3 - 2.0 * u2 + u) * m1
                + (-2.0 * u3 + 3.0 * u2) * c
                + (u3 - u2) * m2
        };
        let f = |sel: fn(&Knot) -> f64| {
            cr(
                sel(&pm),
                sel(&p0),
                sel(&p1),
                sel(&p2),
                pm.0,
                p0.0,
                p1.0,
                p2.0,
            )
        };
        (f(|q| q.1), f(|q| q.2), f(|q| q.3))
    }

    fn cap(&self, t: f64) -> f64 {
        let mut f = 1.0;
        if t < self.cap0 {
            let q = 1.0 - t / self.cap0;
            f *= (1.0 - q * q).max(0.0).sqrt();
        }
        if t > self.length - self.cap1 {
            let q = 1.0 - (self.length - t) / self.cap1;
            f *= (1.0 - q * q).max(0.0).sqrt();
        }
        f
    }

    /// The z interval `(min, max)` at `(x, y)`, if the line of sight meets the piece.
    fn interval(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let (dx, dy) = (x - self.start[0], y - self.start[1]);
        let t = dx * self.dir[0] + dy * self.dir[1];
        if t <= 0.0 || t >= self.length {
            return None;
        }
        let s = -dx * self.dir[1] + dy * self.dir[0];
        let (a, b, c) = self.profile(t);
        let f = self.cap(t);
        let (a, b) = (a * f, b * f);
        let q = (s / a).abs();
        if q.is_nan() || q >= 1.0 {
            return None;
        }
        let dz = b * (1.0 - q.powf(self.p)).powf(1.0 / self.p);
        Some((c - dz, c + dz))
    }
}

#[derive(Clone, Debug)]
struct Ellipsoid {
    centre: [f64; 3],
    semi: [f64; 3],
}

impl Ellipsoid {
    fn interval(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let u = (x - self.centre[0]) / self.semi[0];
        let v = (y - self.centre[1]) / self.semi[1];
        let r = 1.0 - u * u - v * v;
        if r <= 0.0 {
            return None;
        }
        let dz = self.semi[2] * r.sqrt();
        Some((self.centre[2] - dz, self.centre[2] + dz))
    }
}

/// The synthetic body (mm, feet on `y = 0`, x to the body's left, z forward).
#[derive(Clone, Debug)]
pub struct Mannequin {
    swept: Vec<Swept>,
    feet: Vec<Ellipsoid>,
    /// A-pose: angle of the arms from the vertical, degrees.
    pub arm_angle_deg: f64,
    shoulder: [f64; 2],
    hip: [f64; 2],
    ankle: [f64; 2],
}

/// Heights and axial positions (mm) of the cuts between parts.
const CHIN_Y: f64 = 1375.0;
const NECK_Y: f64 = 1320.0;
const WAIST_Y: f64 = 980.0;
const HIP_Y: f64 = 850.0;
const ELBOW_T: f64 = 290.0;
const WRIST_T: f64 = 520.0;
const KNEE_Y: f64 = 430.0;
const ANKLE_Y: f64 = 80.0;

/// Rounded to 0.01 (landmark pixels: readable side files).
fn round2(v: f64) -> f64 {
    (v * 100.0).round() / 100.0
}

/// The images of one synthetic view pair, ready to write.
#[derive(Clone, Debug)]
pub struct SyntheticViews {
    /// Front image (grey 0 = no sample).
    pub front_image: GrayImage,
    /// Front side file (names `front.pgm` or `front.png`).
    pub front_side: SideFile,
    /// Back image (mirrored: columns run towards −x).
    pub back_image: GrayImage,
    /// Back side file.
    pub back_side: SideFile,
}

impl Mannequin {
    /// The JIS 9AR-like mannequin in an A-pose (arms 25° from the vertical, feet 26 cm apart).
    pub fn jis_9ar() -> Self {
        let arm_angle_deg: f64 = 25.0;
        let axial = Swept::new(
            [0.0, 690.0],
            [0.0, 1580.0],
            (50.0, 110.0),
            2.0,
            [
                (690.0, 150.0, 100.0, -5.0),
                (720.0, 150.0, 100.0, -5.0),
                (800.0, 168.0, 115.0, -15.0),
                (900.0, 148.0, 100.0, -5.0),
                (980.0, 120.0, 82.0, 0.0),
                (1060.0, 135.0, 95.0, 5.0),
                (1140.0, 150.0, 112.0, 15.0),
                (1210.0, 158.0, 100.0, 5.0),
                (1260.0, 170.0, 78.0, -5.0),
                (1295.0, 140.0, 65.0, -10.0),
                (1325.0, 64.0, 55.0, -10.0),
                (1360.0, 52.0, 52.0, -5.0),
                (1395.0, 60.0, 72.0, 5.0),
                (1440.0, 72.0, 92.0, 10.0),
                (1500.0, 76.0, 98.0, 10.0),
                (1580.0, 76.0, 98.0, 10.0),
            ]
            .iter()
            .map(|&(y, a, b, c)| (y - 690.0, a, b, c))
            .collect(),
        );
        let shoulder = [160.0, 1250.0];
        let hip = [90.0, 900.0];
        let ankle = [130.0, 75.0];
        let (sa, ca) = arm_angle_deg.to_radians().sin_cos();
        let mut swept = vec![axial];
        for side in [1.0, -1.0] {
            let start = [side * (shoulder[0] - 40.0 * sa), shoulder[1] + 40.0 * ca];
            let end = [side * (shoulder[0] + 700.0 * sa), shoulder[1] - 700.0 * ca];
            swept.push(Swept::new(
                start,
                end,
                (40.0, 60.0),
                2.0,
                [
                    (0.0, 46.0, 48.0, -10.0),
                    (40.0, 48.0, 50.0, -10.0),
                    (140.0, 44.0, 45.0, -10.0),
                    (330.0, 35.0, 37.0, -10.0),
                    (390.0, 38.0, 40.0, -10.0),
                    (560.0, 27.0, 19.0, -10.0),
                    (610.0, 42.0, 15.0, -8.0),
                    (670.0, 45.0, 14.0, -8.0),
                    (740.0, 40.0, 12.0, -8.0),
                ]
                .to_vec(),
            ));
            let top = [side * hip[0], hip[1]];
            let d = [side * (ankle[0] - hip[0]), ankle[1] - hip[1]];
            let len = d[0].hypot(d[1]);
            let end = [
                top[0] + d[0] / len * (len + 45.0),
                top[1] + d[1] / len * (len + 45.0),
            ];
            swept.push(Swept::new(
                top,
                end,
                (60.0, 45.0),
                2.0,
                [
                    (0.0, 60.0, 70.0, -10.0),
                    (100.0, 76.0, 86.0, -5.0),
                    (180.0, 82.0, 88.0, 0.0),
                    (330.0, 70.0, 75.0, 0.0),
                    (470.0, 50.0, 52.0, 0.0),
                    (560.0, 55.0, 58.0, -15.0),
                    (730.0, 38.0, 40.0, -5.0),
                    (825.0, 32.0, 35.0, 0.0),
                    (870.0, 32.0, 35.0, 0.0),
                ]
                .to_vec(),
            ));
        }
        let feet = [1.0, -1.0]
            .iter()
            .map(|&side| Ellipsoid {
                centre: [side * ankle[0], 35.0, 45.0],
                semi: [45.0, 36.0, 115.0],
            })
            .collect();
        Self {
            swept,
            feet,
            arm_angle_deg,
            shoulder,
            hip,
            ankle,
        }
    }

    /// The body's z interval `(back, front)` on the line of sight through `(x, y)` (mm), if any.
    pub fn interval(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let mut out: Option<(f64, f64)> = None;
        let pieces = self
            .swept
            .iter()
            .map(|s| s.interval(x, y))
            .chain(self.feet.iter().map(|e| e.interval(x, y)));
        for (lo, hi) in pieces.flatten() {
            out = Some(match out {
                None => (lo, hi),
                Some((a, b)) => (a.min(lo), b.max(hi)),
            });
        }
        out
    }

    /// The volume (mm³) by midpoint quadrature of `front − back` on a 1 mm grid (the pieces'
    /// union has no closed form; the quadrature error is far below 0.1 %).
    pub fn volume_mm3(&self) -> f64 {
        let h = 1.0;
        let mut v = 0.0;
        let (x0, x1, y0, y1) = self.bounds();
        let nx = ((x1 - x0) / h) as usize;
        let ny = ((y1 - y0) / h) as usize;
        for j in 0..ny {
            let y = y0 + (j as f64 + 0.5) * h;
            for i in 0..nx {
                let x = x0 + (i as f64 + 0.5) * h;
                if let Some((lo, hi)) = self.interval(x, y) {
                    v += hi - lo;
                }
            }
        }
        v * h * h
    }

    /// A box `(x0, x1, y0, y1)` (mm) containing the body's projection with a margin.
    pub fn bounds(&self) -> (f64, f64, f64, f64) {
        (-540.0, 540.0, -20.0, 1600.0)
    }

    fn arm_axis(&self, side: f64) -> ([f64; 2], [f64; 2]) {
        let (sa, ca) = self.arm_angle_deg.to_radians().sin_cos();
        (
            [side * self.shoulder[0], self.shoulder[1]],
            [side * sa, -ca],
        )
    }

    fn leg_axis(&self, side: f64) -> ([f64; 2], [f64; 2]) {
        let d = [
            side * (self.ankle[0] - self.hip[0]),
            self.ankle[1] - self.hip[1],
        ];
        let l = d[0].hypot(d[1]);
        ([side * self.hip[0], self.hip[1]], [d[0] / l, d[1] / l])
    }

    /// The last point inside the body marching from `p` along `d` (0.05 mm steps, up to `max`).
    fn march(&self, p: [f64; 2], d: [f64; 2], max: f64) -> [f64; 2] {
        let mut last = p;
        let mut t = 0.0;
        while t < max {
            let q = [p[0] + t * d[0], p[1] + t * d[1]];
            if self.interval(q[0], q[1]).is_some() {
                last = q;
            } else if t > 0.0 {
                break;
            }
            t += 0.05;
        }
        last
    }

    /// The landmarks (world mm) on the silhouette, computed from the analytic shape.
    pub fn landmarks(&self) -> Vec<(String, [f64; 2])> {
        let mut out = Vec::new();
        let mut push = |name: &str, p: [f64; 2]| out.push((name.to_owned(), p));
        for (side, sfx) in [(1.0, "l"), (-1.0, "r")] {
            let out_dir = [side, 0.0];
            push(
                &format!("chin_{sfx}"),
                self.march([0.0, CHIN_Y], out_dir, 400.0),
            );
            push(
                &format!("neck_{sfx}"),
                self.march([0.0, NECK_Y], out_dir, 400.0),
            );
            push(
                &format!("waist_{sfx}"),
                self.march([0.0, WAIST_Y], out_dir, 400.0),
            );
            push(
                &format!("hip_{sfx}"),
                self.march([0.0, HIP_Y], out_dir, 400.0),
            );
            // Armpit: the highest row with a gap between the trunk and the arm.
            let mut armpit = [0.0, 0.0];
            let mut y = 1000.0;
            while y < 1300.0 {
                let edge = self.march([0.0, y], out_dir, 400.0);
                let beyond = [edge[0] + side * 0.5, y];
                let next = (0..300)
                    .map(|k| [beyond[0] + side * k as f64 * 0.5, y])
                    .find(|q| self.interval(q[0], q[1]).is_some());
                match next {
                    Some(q) => armpit = [0.5 * (edge[0] + q[0]), y],
                    None => break,
                }
                y += 0.25;
            }
            push(&format!("armpit_{sfx}"), armpit);
            let (o, d) = self.arm_axis(side);
            // The outward normal of the arm axis in the image plane (up and away from the trunk).
            let n = [-d[1] * side, d[0] * side];
            let n = if n[1] < 0.0 { [-n[0], -n[1]] } else { n };
            let ta = (armpit[0] - o[0]) * d[0] + (armpit[1] - o[1]) * d[1];
            let axis_at = |t: f64| [o[0] + t * d[0], o[1] + t * d[1]];
            push(
                &format!("shoulder_{sfx}"),
                self.march(axis_at(ta), n, 300.0),
            );
            for (name, t) in [("elbow", ELBOW_T), ("wrist", WRIST_T)] {
                let c = axis_at(t);
                push(&format!("{name}_out_{sfx}"), self.march(c, n, 300.0));
                push(
                    &format!("{name}_in_{sfx}"),
                    self.march(c, [-n[0], -n[1]], 300.0),
                );
            }
            let (o, d) = self.leg_axis(side);
            // Perpendicular to the leg axis, pointing away from the body's midline.
            let n = [-d[1], d[0]];
            let n = if n[0] * side < 0.0 { [-n[0], -n[1]] } else { n };
            for (name, y) in [("knee", KNEE_Y), ("ankle", ANKLE_Y)] {
                let t = (y - o[1]) / d[1];
                let c = [o[0] + t * d[0], o[1] + t * d[1]];
                push(&format!("{name}_out_{sfx}"), self.march(c, n, 300.0));
                push(
                    &format!("{name}_in_{sfx}"),
                    self.march(c, [-n[0], -n[1]], 300.0),
                );
            }
        }
        // Crotch: the lowest point of the midline.
        let crotch = self.march([0.0, WAIST_Y], [0.0, -1.0], 800.0);
        push("crotch", crotch);
        let yc = crotch[1] + 20.0;
        for (side, sfx) in [(1.0, "l"), (-1.0, "r")] {
            push(
                &format!("thigh_{sfx}"),
                self.march([0.0, yc], [side, 0.0], 400.0),
            );
        }
        out
    }

    /// Render the front and back views at `pixel_size` mm. Depths are encoded with
    /// `depth_scale` 0.02 mm per grey unit, cameras 1 m in front of and behind the origin.
    pub fn views(&self, pixel_size: f64, image_ext: &str) -> SyntheticViews {
        let (x0, x1, y0, y1) = self.bounds();
        let w = ((x1 - x0) / pixel_size).ceil() as usize + 1;
        let h = ((y1 - y0) / pixel_size).ceil() as usize + 1;
        let (scale, offset, cam) = (0.02, 500.0, 1000.0);
        let mut front = vec![0u16; w * h];
        let mut back = vec![0u16; w * h];
        let encode = |d: f64| ((d - offset) / scale).round().clamp(1.0, 65535.0) as u16;
        for r in 0..h {
            let y = y1 - r as f64 * pixel_size;
            for c in 0..w {
                let x = x0 + c as f64 * pixel_size;
                if let Some((lo, hi)) = self.interval(x, y) {
                    front[r * w + c] = encode(cam - hi);
                    // Back image mirrored.
                    back[r * w + (w - 1 - c)] = encode(lo + cam);
                }
            }
        }
        let landmarks = self.landmarks();
        let side = |view: View, name: &str, origin: (f64, f64)| SideFile {
            view,
            image: format!("{name}.{image_ext}"),
            pixel_size,
            depth_scale: scale,
            depth_offset: offset,
            camera_z: if view == View::Front { cam } else { -cam },
            origin,
            landmarks: if view == View::Front {
                landmarks
                    .iter()
                    .map(|(n, p)| {
                        (
                            n.clone(),
                            (
                                round2((p[0] - x0) / pixel_size),
                                round2((y1 - p[1]) / pixel_size),
                            ),
                        )
                    })
                    .collect()
            } else {
                Default::default()
            },
        };
        let image = |data| GrayImage {
            width: w,
            height: h,
            maxval: 65535,
            data,
        };
        SyntheticViews {
            front_image: image(front),
            front_side: side(View::Front, "front", (x0, y1)),
            back_image: image(back),
            back_side: side(View::Back, "back", (x0 + (w - 1) as f64 * pixel_size, y1)),
        }
    }

    /// Write the views into `dir` (`front.ron`, `back.ron` and their images, `image_ext` "pgm" or
    /// "png"); returns the two side-file paths.
    pub fn write_views(
        &self,
        dir: &Path,
        pixel_size: f64,
        image_ext: &str,
    ) -> std::io::Result<(PathBuf, PathBuf)> {
        let v = self.views(pixel_size, image_ext);
        write_image(&dir.join(&v.front_side.image), &v.front_image)?;
        write_image(&dir.join(&v.back_side.image), &v.back_image)?;
        let (f, b) = (dir.join("front.ron"), dir.join("back.ron"));
        v.front_side.write(&f)?;
        v.back_side.write(&b)?;
        Ok((f, b))
    }

    /// The range body directly (no files).
    pub fn body(&self, pixel_size: f64) -> RangeBody {
        let v = self.views(pixel_size, "pgm");
        RangeBody::from_views(
            (&v.front_side, &v.front_image, Path::new("front.ron")),
            (&v.back_side, &v.back_image, Path::new("back.ron")),
        )
        .expect("the synthetic views are consistent")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Girth of the axial piece's (elliptic) cross-section at height `y`, mm (Ramanujan).
    fn girth(m: &Mannequin, y: f64) -> f64 {
        let (a, b, _) = m.swept[0].profile(y - 690.0);
        let f = m.swept[0].cap(y - 690.0);
        let (a, b) = (a * f, b * f);
        std::f64::consts::PI * (3.0 * (a + b) - ((3.0 * a + b) * (a + 3.0 * b)).sqrt())
    }

    #[test]
    fn the_mannequin_has_jis_9ar_sizes() {
        let m = Mannequin::jis_9ar();
        let max_girth = |y0: f64, y1: f64| {
            (0..=80)
                .map(|k| girth(&m, y0 + (y1 - y0) * k as f64 / 80.0))
                .fold(0.0, f64::max)
        };
        let min_girth = |y0: f64, y1: f64| {
            (0..=80)
                .map(|k| girth(&m, y0 + (y1 - y0) * k as f64 / 80.0))
                .fold(f64::INFINITY, f64::min)
        };
        let (bust, waist, hip) = (
            max_girth(1080.0, 1200.0),
            min_girth(940.0, 1020.0),
            max_girth(760.0, 860.0),
        );
        assert!((bust - 830.0).abs() < 20.0, "bust {bust}");
        assert!((waist - 640.0).abs() < 15.0, "waist {waist}");
        assert!((hip - 910.0).abs() < 20.0, "hip {hip}");
        // Height 158 cm: the crown.
        let top = m.march([0.0, 1500.0], [0.0, 1.0], 200.0)[1];
        assert!((top - 1580.0).abs() < 1.0, "height {top}");
        let bottom = m.march([130.0, 30.0], [0.0, -1.0], 100.0)[1];
        assert!(bottom.abs() < 1.0, "sole {bottom}");
    }

    #[test]
    fn the_range_images_hold_the_mannequin_volume() {
        let m = Mannequin::jis_9ar();
        let body = m.body(2.5);
        let (v, vr) = (m.volume_mm3(), body.volume_mm3());
        // About 53 L for a 158 cm, 50 kg body; one line of sight, one interval.
        assert!((50e6..56e6).contains(&v), "volume {v}");
        assert!((vr - v).abs() < 0.003 * v, "{vr} vs {v}");
        // Every landmark lies on the body, within a pixel of its outline.
        for (name, p) in m.landmarks() {
            let inside = m.interval(p[0], p[1]).is_some();
            let near_out = [[2.5, 0.0], [-2.5, 0.0], [0.0, 2.5], [0.0, -2.5]]
                .iter()
                .any(|d| m.interval(p[0] + d[0], p[1] + d[1]).is_none());
            assert!(near_out, "{name} is not on the outline");
            assert!(inside || name.starts_with("armpit"), "{name} off the body");
        }
    }
}
