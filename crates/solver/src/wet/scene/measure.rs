//! What a finished wet run is measured by: [`WetRun`]'s folds around a pinch and its summaries.

use crate::metrics::{FoldPeak, NodeCountParams, fold_peaks};

use super::{Folds, WetRun, WetSample};

impl WetRun {
    /// The final sample.
    pub fn last(&self) -> &WetSample {
        self.samples.last().expect("a run has its first sample")
    }

    /// The height of the cloth above the plane at rest point `(x, y)` (bilinear over its grid
    /// cell), m.
    pub fn height_at(&self, x: f64, y: f64) -> f64 {
        let n = self.particles;
        let side = self.rest[n * n - 1][0];
        let h = side / (n - 1) as f64;
        let (u, v) = (
            (x / h).clamp(0.0, (n - 1) as f64),
            (y / h).clamp(0.0, (n - 1) as f64),
        );
        let (i, j) = (
            (u.floor() as usize).min(n - 2),
            (v.floor() as usize).min(n - 2),
        );
        let (a, b) = (u - i as f64, v - j as f64);
        let z = |i: usize, j: usize| self.positions[j * n + i].z;
        (1.0 - a) * (1.0 - b) * z(i, j)
            + a * (1.0 - b) * z(i + 1, j)
            + (1.0 - a) * b * z(i, j + 1)
            + a * b * z(i + 1, j + 1)
    }

    /// The folds around the rest position of node `centre`: the cloth's height sampled at 360
    /// points on the circle of `radius` (in the cloth, at rest) around it, smoothed and its
    /// local maxima of at least `min_prominence` counted ([`fold_peaks`]).
    pub fn folds(&self, centre: u32, radius: f64, min_prominence: f64) -> Folds {
        let samples = 360;
        let [cx, cy] = self.rest[centre as usize];
        let angle = |k: usize| std::f64::consts::TAU * k as f64 / samples as f64;
        let profile: Vec<f64> = (0..samples)
            .map(|k| self.height_at(cx + radius * angle(k).cos(), cy + radius * angle(k).sin()))
            .collect();
        let peaks: Vec<FoldPeak> = fold_peaks(
            &profile,
            &NodeCountParams {
                smoothing: 5f64.to_radians(),
                min_prominence,
            },
        );
        let mut angles_deg: Vec<f64> = peaks.iter().map(|p| angle(p.index).to_degrees()).collect();
        angles_deg.sort_by(f64::total_cmp);
        let prominences: Vec<f64> = peaks.iter().map(|p| p.prominence).collect();
        let count = peaks.len();
        let spacing_deviation_deg = if count >= 2 {
            let even = 360.0 / count as f64;
            (0..count)
                .map(|k| {
                    let gap = if k + 1 < count {
                        angles_deg[k + 1] - angles_deg[k]
                    } else {
                        angles_deg[0] + 360.0 - angles_deg[k]
                    };
                    (gap - even).abs()
                })
                .fold(0.0, f64::max)
        } else {
            0.0
        };
        let (lo, hi) = prominences
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        Folds {
            count,
            angles_deg,
            prominences,
            spacing_deviation_deg,
            prominence_ratio: if count > 0 { lo / hi } else { 0.0 },
            mean_height: profile.iter().sum::<f64>() / samples as f64,
        }
    }

    /// RMS distance between this run's final nodes and `other`'s (same scene), m.
    pub fn rms_distance(&self, other: &WetRun) -> f64 {
        let n = self.positions.len().min(other.positions.len()).max(1);
        (self
            .positions
            .iter()
            .zip(&other.positions)
            .map(|(a, b)| (a - b).norm_squared())
            .sum::<f64>()
            / n as f64)
            .sqrt()
    }

    /// Wall time per simulated second.
    pub fn wall_per_second(&self) -> f64 {
        if self.time > 0.0 {
            self.wall.as_secs_f64() / self.time
        } else {
            f64::INFINITY
        }
    }
}
