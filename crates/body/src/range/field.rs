//! Depth fields for gridding: the front and back depth maps with the invalid samples filled by the
//! silhouette's middle depth (so bilinear interpolation is defined up to and beyond the outline),
//! and the traced outline of the mask.

use super::body::RangeBody;

/// Filled depth maps of a body, mm, with bilinear interpolation and its gradient.
#[derive(Clone, Debug)]
pub(crate) struct DepthField {
    pub width: usize,
    pub height: usize,
    pub pixel: f64,
    pub origin: [f64; 2],
    pub front: Vec<f64>,
    pub back: Vec<f64>,
    /// Valid in both views.
    pub mask: Vec<bool>,
}

/// Which depth map to sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Layer {
    Front,
    Back,
    /// The mean of front and back (the silhouette's depth).
    Mid,
}

impl DepthField {
    pub fn new(body: &RangeBody) -> Self {
        let (w, h) = (body.width, body.height);
        let mask: Vec<bool> = (0..w * h).map(|k| body.valid(k)).collect();
        let mut mid = vec![f64::NAN; w * h];
        let mut frontier = Vec::new();
        for k in 0..w * h {
            if mask[k] {
                mid[k] = 0.5 * (body.front[k] + body.back[k]);
                frontier.push(k);
            }
        }
        // Breadth-first fill: each new ring of samples takes the mean of its assigned neighbours.
        while !frontier.is_empty() {
            let mut next = Vec::new();
            for &k in &frontier {
                let (c, r) = ((k % w) as isize, (k / w) as isize);
                for (dc, dr) in [
                    (1, 0),
                    (-1, 0),
                    (0, 1),
                    (0, -1),
                    (1, 1),
                    (1, -1),
                    (-1, 1),
                    (-1, -1),
                ] {
                    let (cc, rr) = (c + dc, r + dr);
                    if cc < 0 || rr < 0 || cc >= w as isize || rr >= h as isize {
                        continue;
                    }
                    let q = rr as usize * w + cc as usize;
                    if mid[q].is_nan() {
                        mid[q] = f64::INFINITY; // Marked; value set below.
                        next.push(q);
                    }
                }
            }
            let values: Vec<f64> = next
                .iter()
                .map(|&q| {
                    let (c, r) = ((q % w) as isize, (q / w) as isize);
                    let (mut s, mut n) = (0.0, 0);
                    for dr in -1..=1 {
                        for dc in -1..=1 {
                            let (cc, rr) = (c + dc, r + dr);
                            if cc < 0 || rr < 0 || cc >= w as isize || rr >= h as isize {
                                continue;
                            }
                            let v = mid[rr as usize * w + cc as usize];
                            if v.is_finite() {
                                s += v;
                                n += 1;
                            }
                        }
                    }
                    s / n.max(1) as f64
                })
                .collect();
            for (&q, v) in next.iter().zip(values) {
                mid[q] = v;
            }
            frontier = next;
        }
        let fill = |src: &[f64]| -> Vec<f64> {
            (0..w * h)
                .map(|k| if mask[k] { src[k] } else { mid[k] })
                .collect()
        };
        Self {
            width: w,
            height: h,
            pixel: body.pixel_size,
            origin: body.origin,
            front: fill(&body.front),
            back: fill(&body.back),
            mask,
        }
    }

    /// Depth (mm) and its gradient `[∂z/∂x, ∂z/∂y]` at world `p` (mm), bilinear.
    pub fn sample(&self, layer: Layer, p: [f64; 2]) -> (f64, [f64; 2]) {
        match layer {
            Layer::Front => self.bilinear(&self.front, p),
            Layer::Back => self.bilinear(&self.back, p),
            Layer::Mid => {
                let (a, ga) = self.bilinear(&self.front, p);
                let (b, gb) = self.bilinear(&self.back, p);
                (
                    0.5 * (a + b),
                    [0.5 * (ga[0] + gb[0]), 0.5 * (ga[1] + gb[1])],
                )
            }
        }
    }

    fn bilinear(&self, v: &[f64], p: [f64; 2]) -> (f64, [f64; 2]) {
        let (w, h) = (self.width, self.height);
        let cx = ((p[0] - self.origin[0]) / self.pixel).clamp(0.0, (w - 1) as f64);
        let cy = ((self.origin[1] - p[1]) / self.pixel).clamp(0.0, (h - 1) as f64);
        let i = (cx.floor() as usize).min(w.saturating_sub(2));
        let j = (cy.floor() as usize).min(h.saturating_sub(2));
        let (fx, fy) = (cx - i as f64, cy - j as f64);
        let i1 = (i + 1).min(w - 1);
        let j1 = (j + 1).min(h - 1);
        let (a, b, c, d) = (v[j * w + i], v[j * w + i1], v[j1 * w + i], v[j1 * w + i1]);
        let z =
            a * (1.0 - fx) * (1.0 - fy) + b * fx * (1.0 - fy) + c * (1.0 - fx) * fy + d * fx * fy;
        let dzdx = ((b - a) * (1.0 - fy) + (d - c) * fy) / self.pixel;
        let dzdy = -((c - a) * (1.0 - fx) + (d - b) * fx) / self.pixel;
        (z, [dzdx, dzdy])
    }

    /// The outer outline of the mask (valid in both views) as a closed loop of world points (mm):
    /// the midpoints of the pixel cracks between valid and invalid samples, lightly smoothed.
    pub fn outline(&self) -> Vec<[f64; 2]> {
        let (w, h) = (self.width as isize, self.height as isize);
        let inside = |c: isize, r: isize| {
            c >= 0 && r >= 0 && c < w && r < h && self.mask[(r * w + c) as usize]
        };
        // Directed crack edges, clockwise around each valid sample in screen coordinates
        // (x right, y = row down): the sample lies to the right of its edges.
        // Corner (i, j) is the top-left corner of sample (i, j).
        let mut out_edges: std::collections::HashMap<(isize, isize), Vec<(isize, isize)>> =
            std::collections::HashMap::new();
        let mut starts = Vec::new();
        for r in 0..h {
            for c in 0..w {
                if !inside(c, r) {
                    continue;
                }
                let mut add = |from: (isize, isize), dir: (isize, isize)| {
                    out_edges.entry(from).or_default().push(dir);
                    starts.push((from, dir));
                };
                if !inside(c, r - 1) {
                    add((c, r), (1, 0));
                }
                if !inside(c + 1, r) {
                    add((c + 1, r), (0, 1));
                }
                if !inside(c, r + 1) {
                    add((c + 1, r + 1), (-1, 0));
                }
                if !inside(c - 1, r) {
                    add((c, r + 1), (0, -1));
                }
            }
        }
        let mut used: std::collections::HashSet<((isize, isize), (isize, isize))> =
            std::collections::HashSet::new();
        let mut best: Vec<[f64; 2]> = Vec::new();
        for &(v0, d0) in &starts {
            if used.contains(&(v0, d0)) {
                continue;
            }
            let mut loop_pts = Vec::new();
            let (mut v, mut d) = (v0, d0);
            loop {
                used.insert((v, d));
                // Midpoint of the edge in pixel coordinates (corner (i, j) is at (i − ½, j − ½)).
                let mx = v.0 as f64 - 0.5 + 0.5 * d.0 as f64;
                let my = v.1 as f64 - 0.5 + 0.5 * d.1 as f64;
                loop_pts.push([
                    self.origin[0] + mx * self.pixel,
                    self.origin[1] - my * self.pixel,
                ]);
                let end = (v.0 + d.0, v.1 + d.1);
                let Some(cands) = out_edges.get(&end) else {
                    break;
                };
                let free: Vec<_> = cands
                    .iter()
                    .filter(|&&e| !used.contains(&(end, e)))
                    .collect();
                let right = (-d.1, d.0);
                let next = if free.len() > 1 {
                    free.iter()
                        .find(|&&&e| e == right)
                        .copied()
                        .unwrap_or(free[0])
                } else if let Some(e) = free.first() {
                    *e
                } else {
                    break;
                };
                v = end;
                d = *next;
                if (v, d) == (v0, d0) {
                    break;
                }
            }
            if loop_pts.len() > best.len() {
                best = loop_pts;
            }
        }
        // Smooth the staircase: two passes of (¼, ½, ¼).
        let n = best.len();
        for _ in 0..2 {
            if n < 3 {
                break;
            }
            best = (0..n)
                .map(|i| {
                    let (a, b, c) = (best[(i + n - 1) % n], best[i], best[(i + 1) % n]);
                    [
                        0.25 * a[0] + 0.5 * b[0] + 0.25 * c[0],
                        0.25 * a[1] + 0.5 * b[1] + 0.25 * c[1],
                    ]
                })
                .collect();
        }
        best
    }
}
