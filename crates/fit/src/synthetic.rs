//! Synthetic real objects (no camera here; `method.md` §6): four objects like the paper's made
//! as fine elastic rods ([`crate::rod`]), held at a fixed end and moved to 20 positions of the
//! other end, solved to rest, observed as 9 markers at equal arc length with Gaussian pixel
//! noise (σ = 0.5 px, 1 px = 2 mm, seeded) in a 640 × 480 image.
//!
//! | object | length | mass | EA | EI | natural curvature |
//! |---|---|---|---|---|---|
//! | rubber string | 0.40 m | 20 g/m | 0.4 N (soft, extensible) | 1e-5 N·m² | none |
//! | chain | 0.40 m | 50 g/m | 500 N | 1e-8 N·m² (none to speak of) | none |
//! | UTP cable | 0.45 m | 30 g/m | 2 000 N | 4e-3 N·m², softer at three storage kinks | 1.5 rad/m, with three kinks of ±0.5 rad |
//! | grass leaf | 0.30 m | 10 → 2 g/m (tapered) | 200 N | 2e-4 → 2e-6 N·m² (tapered, cubic) | 2 rad/m |
//!
//! The values are chosen to look like the paper's objects (a limp stretchy cord, a chain that
//! hangs as a catenary, a springy cable that keeps its coil and kinks, a leaf stiff at its base
//! and limp at its tip), not measured.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use atelier_files::noise::Rng;

use crate::FitError;
use crate::observation::{Observations, ObservedShape};
use crate::rod::{Rod, RodSpec};
use crate::statics::{Chain, StaticOptions, equilibrium};
use crate::string::V2;

/// The paper's four objects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Object {
    /// A rubber string: soft, extensible, uniform.
    Rubber,
    /// A chain: no bending stiffness, inextensible, uniform.
    Chain,
    /// A UTP cable: stiff, with a natural curvature and kinks from storage (not uniform).
    Cable,
    /// A grass leaf: tapered stiffness and mass (not uniform).
    Leaf,
}

impl Object {
    /// All four, in the paper's order.
    pub const ALL: [Object; 4] = [Object::Rubber, Object::Chain, Object::Cable, Object::Leaf];

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Object::Rubber => "rubber string",
            Object::Chain => "chain",
            Object::Cable => "UTP cable",
            Object::Leaf => "grass leaf",
        }
    }

    /// The paper's initial s and b (Table 2).
    pub fn table2(self) -> (f64, f64) {
        match self {
            Object::Rubber => (0.02, 0.02),
            Object::Chain => (1.0, 0.01),
            Object::Cable => (10.0, 0.1),
            Object::Leaf => (3.0, 0.04),
        }
    }

    /// The fine rod standing in for it, with `segments` segments.
    pub fn rod(self, segments: usize) -> Result<Rod, FitError> {
        let kink = |u: f64, at: f64| (-((u - at) / 0.03).powi(2)).exp();
        match self {
            Object::Rubber => Rod::new(&RodSpec {
                length: 0.40,
                segments,
                mass_per_length: &|_| 0.02,
                axial: &|_| 0.4,
                bending: &|_| 1e-5,
                curvature: &|_| 0.0,
            }),
            Object::Chain => Rod::new(&RodSpec {
                length: 0.40,
                segments,
                mass_per_length: &|_| 0.05,
                axial: &|_| 500.0,
                bending: &|_| 1e-8,
                curvature: &|_| 0.0,
            }),
            Object::Cable => Rod::new(&RodSpec {
                length: 0.45,
                segments,
                mass_per_length: &|_| 0.03,
                axial: &|_| 2000.0,
                bending: &|u| 4e-3 * (1.0 - 0.5 * (kink(u, 0.25) + kink(u, 0.55) + kink(u, 0.8))),
                // A kink turns by about ±0.5 rad: ∫ c·exp(−(s/w)²) ds = c·w·√π·L.
                curvature: &|u| {
                    let c = 0.5 / (0.03 * PI.sqrt() * 0.45);
                    1.5 + c * (kink(u, 0.25) - kink(u, 0.55) + kink(u, 0.8))
                },
            }),
            Object::Leaf => Rod::new(&RodSpec {
                length: 0.30,
                segments,
                mass_per_length: &|u| 0.01 - 0.008 * u,
                axial: &|_| 200.0,
                bending: &|u| 2e-4 * (1.0 - 0.785 * u).powi(3),
                curvature: &|_| 2.0,
            }),
        }
    }
}

/// Settings of the synthetic observation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SyntheticOptions {
    /// Rod segments (≥ 100; a multiple of markers − 1). Default 120.
    pub segments: usize,
    /// Shapes (positions of the manipulated end). Default 20.
    pub shapes: usize,
    /// Markers, ends included. Default 9.
    pub markers: usize,
    /// Pixel noise σ, px. Default 0.5.
    pub noise_px: f64,
    /// Pixel size, m. Default 2 mm.
    pub pixel_size: f64,
    /// Image width and height, px. Default 640 × 480.
    pub image: (u32, u32),
    /// The fixed end, px. Default (160, 120).
    pub fixed_end: [f64; 2],
    /// Seed of the noise and of the end positions. Default 1.
    pub seed: u64,
}

impl Default for SyntheticOptions {
    fn default() -> Self {
        Self {
            segments: 120,
            shapes: 20,
            markers: 9,
            noise_px: 0.5,
            pixel_size: 0.002,
            image: (640, 480),
            fixed_end: [160.0, 120.0],
            seed: 1,
        }
    }
}

/// A start shape between `a` and `b` for a chain of `n` particles and rest length `length`: a
/// sine sag below the chord whose arc length is `length` (the chord when shorter).
pub fn sag_start(a: V2, b: V2, n: usize, length: f64) -> Vec<V2> {
    let chord = b - a;
    let down = {
        let perp = V2::new(chord.y, -chord.x).normalize();
        if perp.y > 0.0 { -perp } else { perp }
    };
    let curve = |h: f64| -> Vec<V2> {
        (0..n)
            .map(|k| {
                let u = k as f64 / (n - 1) as f64;
                a + chord * u + down * (h * (PI * u).sin())
            })
            .collect()
    };
    let arc = |x: &[V2]| x.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>();
    if arc(&curve(0.0)) >= length {
        return curve(0.0);
    }
    let (mut lo, mut hi) = (0.0, length);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if arc(&curve(mid)) < length {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    curve(0.5 * (lo + hi))
}

/// The synthetic observation of `object`: the fine rod's static shapes for `shapes` positions
/// of the manipulated end (seeded: distance 0.45–0.9 of the length from the fixed end, 60°
/// below to 30° above the horizontal in strata taken in a shuffled order, to the right), 9 markers at equal arc length with pixel
/// noise. Returns the observations and the noise-free markers (metres) of every shape.
pub fn observe(
    object: Object,
    options: &SyntheticOptions,
) -> Result<(Observations, Vec<Vec<V2>>), FitError> {
    let o = options;
    if o.segments < 100 || o.markers < 3 || !o.segments.is_multiple_of(o.markers - 1) {
        return Err(FitError::invalid(
            "segments",
            0,
            o.segments as f64,
            format!(
                "need ≥ 100 segments, a multiple of markers − 1 = {}",
                o.markers.max(2) - 1
            ),
        ));
    }
    let rod = object.rod(o.segments)?;
    let length = rod.length();
    let mut obs = Observations {
        name: object.name().into(),
        provenance: format!(
            "synthetic (atelier_fit::synthetic): a {}-segment elastic rod standing in for a {}, {} markers, σ = {} px, seed {}",
            o.segments,
            object.name(),
            o.markers,
            o.noise_px,
            o.seed
        ),
        pixel_size: o.pixel_size,
        image: o.image,
        shapes: Vec::new(),
    };
    let fixed = obs.to_metres(o.fixed_end);
    let mut noise = Rng::new(o.seed);
    let mut truth = Vec::new();
    let step = o.segments / (o.markers - 1);
    // Stratified angles in a seeded order, so that any first J shapes spread over the range
    // (the paper's observed and unobserved shapes come from the same manipulations).
    let mut order: Vec<usize> = (0..o.shapes).collect();
    for k in (1..order.len()).rev() {
        let m = ((k + 1) as f64 * noise.uniform()) as usize;
        order.swap(k, m.min(k));
    }
    for &slot in &order {
        let f = (slot as f64 + noise.uniform()) / o.shapes as f64;
        let d = length * (0.45 + 0.45 * noise.uniform());
        let angle = (-60.0 + 90.0 * f).to_radians();
        let end = fixed + V2::new(angle.cos(), angle.sin()) * d;
        let start = sag_start(fixed, end, rod.particles(), length);
        let eq = equilibrium(
            &rod,
            &start,
            &StaticOptions {
                tolerance: 1e-9,
                max_iterations: 500,
            },
        )?;
        let markers: Vec<V2> = (0..o.markers).map(|k| eq.positions[k * step]).collect();
        let mut px: Vec<[f64; 2]> = markers.iter().map(|x| obs.to_pixels(x)).collect();
        for p in &mut px {
            p[0] += o.noise_px * noise.normal();
            p[1] += o.noise_px * noise.normal();
        }
        obs.shapes.push(ObservedShape {
            ends: (obs.to_pixels(&fixed), obs.to_pixels(&end)),
            markers: px,
        });
        truth.push(markers);
    }
    obs.check()
        .map_err(|e| FitError::invalid("shapes", 0, f64::NAN, e.to_string()))?;
    Ok((obs, truth))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The noise has the asked σ and no bias (10 000 draws: mean within 0.03, σ within 3 %).
    #[test]
    fn the_noise_is_standard_normal() {
        let mut n = Rng::new(7);
        let x: Vec<f64> = (0..10_000).map(|_| n.normal()).collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64;
        assert!(mean.abs() < 0.03, "{mean}");
        assert!((var.sqrt() - 1.0).abs() < 0.03, "{var}");
    }

    /// Every object gives 20 shapes inside the image, its markers within a few pixels of noise
    /// of the truth (the noise's RMS is 0.5 px per coordinate, within 0.1), and the polyline
    /// through its true markers no longer than the rod and at least 90 % of it (chain, cable,
    /// leaf; the rubber stretches).
    #[test]
    fn every_object_is_observed() {
        for object in Object::ALL {
            let (obs, truth) = observe(object, &SyntheticOptions::default()).expect("observed");
            assert_eq!(obs.shapes.len(), 20);
            let mut sq = 0.0;
            let mut count = 0;
            for (s, t) in obs.shapes.iter().zip(&truth) {
                for (p, x) in s.markers.iter().zip(t) {
                    let q = obs.to_pixels(x);
                    sq += (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
                    count += 2;
                }
                let polyline: f64 = t.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
                let rod = object.rod(120).expect("rod").length();
                if object != Object::Rubber {
                    assert!(
                        polyline < rod * 1.001 && polyline > rod * 0.9,
                        "{object:?}: {polyline} vs {rod}"
                    );
                }
            }
            let rms = (sq / count as f64).sqrt();
            assert!((rms - 0.5).abs() < 0.1, "{object:?}: noise RMS {rms}");
        }
    }
}
