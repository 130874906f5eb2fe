//! The shear a fabric's tensile loops imply (the bias against warp and weft, the trellis
//! relation inverted): [`ShearCurve`].

use crate::anisotropy::Directions;
use crate::tensile::{Branch, TensileLoop};

use super::{KES_SHEAR_ANGLES, ShearLoop};

/// Samples of a [`ShearCurve`].
const CURVE_SAMPLES: usize = 512;

/// Smallest shear angle (rad) a [`ShearCurve`]'s secant is taken at when the curve hardly shears:
/// it bounds the derived stiffness for data that imply a nearly shear-rigid weave.
const MIN_SECANT_ANGLE: f64 = 1e-4;

/// The loading shear curve γ(τ) a fabric's warp, weft and 45° bias loading branches imply, by
/// inverting the trellis relation of [`crate::bias_from_shear`]:
/// `φ₄₅(2τ) = ½ φ_v(τ) + ½ φ_u(τ) + √(1 + sin γ) − 1`. For a bias loop derived from KES shear values
/// it returns their loading angle (stick below HG, slope G, saturation at the locking angle); for
/// measured bias curves it is the shear those curves imply. Tabulated at `τ_k = τ_max (k/N)²`
/// (fine where the stick ends), odd in τ, non-decreasing.
#[derive(Clone, Debug, PartialEq)]
pub struct ShearCurve {
    tau_max: f64,
    gamma: Vec<f64>,
}

impl ShearCurve {
    /// Build from a fabric's tensile loops' loading branches (the 45° bias; 135° is not used);
    /// [`ShearCurve::from_fabric`] takes them from a fabric.
    pub fn from_tensile(d: &Directions<TensileLoop>) -> Self {
        let tau_max = 0.5
            * d.bias45
                .max_force()
                .min(2.0 * d.warp.max_force())
                .min(2.0 * d.weft.max_force());
        let mut last: f64 = 0.0;
        let gamma = (0..=CURVE_SAMPLES)
            .map(|k| {
                let tau = tau_max * (k as f64 / CURVE_SAMPLES as f64).powi(2);
                let s = d.bias45.strain(Branch::Loading, 2.0 * tau)
                    - 0.5
                        * (d.warp.strain(Branch::Loading, tau)
                            + d.weft.strain(Branch::Loading, tau));
                let sin_g = ((1.0 + s.max(0.0)).powi(2) - 1.0).clamp(0.0, 1.0);
                // Keep γ non-decreasing (measured curves can dip slightly).
                last = last.max(sin_g.asin());
                last
            })
            .collect();
        Self { tau_max, gamma }
    }

    /// The largest tabulated shear force per width, N/m.
    pub fn max_force(&self) -> f64 {
        self.tau_max
    }

    /// Shear angle at shear force per width `tau` (N/m), rad; odd in τ, constant beyond τ_max.
    pub fn angle(&self, tau: f64) -> f64 {
        let x =
            ((tau.abs() / self.tau_max).sqrt() * CURVE_SAMPLES as f64).min(CURVE_SAMPLES as f64);
        let k = (x as usize).min(CURVE_SAMPLES - 1);
        let (a, b) = (
            k as f64 / CURVE_SAMPLES as f64,
            (k + 1) as f64 / CURVE_SAMPLES as f64,
        );
        let t = ((tau.abs() / self.tau_max).min(1.0) - a * a) / (b * b - a * a);
        let g = self.gamma[k] + t * (self.gamma[k + 1] - self.gamma[k]);
        g.copysign(tau)
    }

    /// The shear force per width (N/m) at which the curve reaches `gamma` (rad, ≥ 0), by
    /// bisection; τ_max when it never does.
    pub fn force(&self, gamma: f64) -> f64 {
        if self.angle(self.tau_max) <= gamma {
            return self.tau_max;
        }
        let (mut lo, mut hi) = (0.0, self.tau_max);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.angle(mid) < gamma {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// Secant stiffness τ/γ at shear angle `gamma` (rad), N/(m·rad). When the curve never reaches
    /// `gamma` the secant at τ_max is returned.
    pub fn secant_stiffness(&self, gamma: f64) -> f64 {
        if self.angle(self.tau_max) <= gamma {
            return self.tau_max / self.angle(self.tau_max).max(f64::MIN_POSITIVE);
        }
        self.force(gamma) / gamma
    }

    /// The elastic-with-hysteresis loop this loading curve implies, measured as KES-FB1 would on
    /// a loading branch: G = the mean slope of τ(γ) between 0.5° and 5°, HG = τ(0.5°) − G·0.5°
    /// (clamped at 0), the half width constant (one branch cannot tell the growth of the width
    /// from the slope). When the curve does not reach 5° the slope is taken up to its largest
    /// angle; when it does not reach 0.5° (or the slope is not positive) the loop is elastic with
    /// the secant stiffness at its largest angle (taken at least at 1e-4 rad, which bounds the
    /// stiffness of data implying a shear-rigid weave).
    pub fn to_loop(&self) -> ShearLoop {
        let (lo, hi) = KES_SHEAR_ANGLES;
        let top = self.angle(self.tau_max);
        let hi = hi.min(top);
        let secant = || self.tau_max / top.max(MIN_SECANT_ANGLE);
        let elastic = |g: f64| ShearLoop {
            stiffness: g,
            hg: 0.0,
            hg5: 0.0,
            join: 0.0,
            deadband: 0.0,
        };
        if hi <= lo {
            return elastic(secant());
        }
        let (t_lo, t_hi) = (self.force(lo), self.force(hi));
        let g = (t_hi - t_lo) / (hi - lo);
        if !(g > 0.0 && g.is_finite()) {
            return elastic(secant());
        }
        let two_hg = 2.0 * (t_lo - g * lo).max(0.0);
        ShearLoop::from_kes(g, two_hg, None).unwrap_or_else(|_| elastic(g))
    }
}
