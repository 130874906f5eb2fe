//! Grid quality as the thesis reports it (Fig. 32): u- and v-edge length, shear angle and cell
//! area, each as mean ± SD, and the cell-area histogram.

use crate::improve::{Surface, norm, sub};
use crate::patch::{LineAxis, Patch};

/// Mean and standard deviation (population) of a sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub sd: f64,
    /// Sample size.
    pub count: usize,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl Stats {
    /// Statistics of `values` (all zero for an empty sample).
    pub fn of(values: &[f64]) -> Self {
        if values.is_empty() {
            return Self::default();
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        Self {
            mean,
            sd: var.sqrt(),
            count: values.len(),
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// The quality of a grid, measured on the lifted surface.
#[derive(Clone, Debug, PartialEq)]
pub struct GridQuality {
    /// Edge lengths along u, m.
    pub u_length: Stats,
    /// Edge lengths along v, m.
    pub v_length: Stats,
    /// Departure from a right angle between consecutive axes at every node, degrees (signed:
    /// a sheared cell has corners at 90° ± γ, so the mean stays near zero and the SD measures
    /// the shear).
    pub shear_deg: Stats,
    /// Cell areas (full cells; the plane area of the lifted quad's two triangles), m².
    pub cell_area: Stats,
    /// The raw samples, for histograms: u lengths, v lengths, shear angles, cell areas.
    pub samples: [Vec<f64>; 4],
}

impl GridQuality {
    /// Measure a patch lifted onto `surface`.
    pub fn measure(patch: &Patch, surface: &dyn Surface) -> Self {
        let x: Vec<[f64; 3]> = (0..patch.node_count())
            .map(|n| surface.lift(n, patch.positions[n]).0)
            .collect();
        let (mut u, mut v) = (Vec::new(), Vec::new());
        for (axis, line) in patch.lines() {
            for w in line.windows(2) {
                let l = norm(sub(x[w[1] as usize], x[w[0] as usize]));
                match axis {
                    LineAxis::U => u.push(l),
                    LineAxis::V => v.push(l),
                }
            }
        }
        let mut shear = Vec::new();
        for s in 0..patch.node_of.len() {
            let Some((n, nb)) = patch.neighbourhood(s) else {
                continue;
            };
            for k in 0..4 {
                if let (Some(a), Some(b)) = (nb[k], nb[(k + 1) % 4]) {
                    let (ea, eb) = (
                        sub(x[a as usize], x[n as usize]),
                        sub(x[b as usize], x[n as usize]),
                    );
                    let c = (crate::improve::dot(ea, eb) / (norm(ea) * norm(eb))).clamp(-1.0, 1.0);
                    shear.push(c.acos().to_degrees() - 90.0);
                }
            }
        }
        let area: Vec<f64> = patch
            .quads()
            .iter()
            .filter(|q| {
                let mut d = q.to_vec();
                d.dedup();
                d.len() == 4 && q[0] != q[3]
            })
            .map(|q| {
                let p = q.map(|k| x[k as usize]);
                // The mean of the two splits (a lifted quad need not be planar).
                0.5 * (tri_area(p[0], p[1], p[2])
                    + tri_area(p[0], p[2], p[3])
                    + tri_area(p[0], p[1], p[3])
                    + tri_area(p[1], p[2], p[3]))
            })
            .collect();
        Self {
            u_length: Stats::of(&u),
            v_length: Stats::of(&v),
            shear_deg: Stats::of(&shear),
            cell_area: Stats::of(&area),
            samples: [u, v, shear, area],
        }
    }

    /// Histogram of the cell areas: `bins` equal bins over `[min, max]`, as (lower edge, count).
    pub fn area_histogram(&self, bins: usize) -> Vec<(f64, usize)> {
        histogram(&self.samples[3], bins)
    }
}

/// Histogram of `values` in `bins` equal bins over their range, as (lower edge, count).
pub fn histogram(values: &[f64], bins: usize) -> Vec<(f64, usize)> {
    let s = Stats::of(values);
    let bins = bins.max(1);
    let width = ((s.max - s.min) / bins as f64).max(f64::MIN_POSITIVE);
    let mut out: Vec<(f64, usize)> = (0..bins).map(|b| (s.min + b as f64 * width, 0)).collect();
    for v in values {
        let b = (((v - s.min) / width) as usize).min(bins - 1);
        out[b].1 += 1;
    }
    out
}

fn tri_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (u, v) = (sub(b, a), sub(c, a));
    0.5 * norm([
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ])
}
