//! The in-plane shear characteristic a cell uses: shear angle γ as a function of the shear force
//! per width τ, recovered from the fabric's warp, weft and 45° bias loading branches by inverting
//! the trellis relation of `atelier_fabric::bias_from_shear`:
//! `φ₄₅(2τ) = ½ φ_v(τ) + ½ φ_u(τ) + √(1 + sin γ) − 1`.
//! For a fabric whose bias loop was derived from KES shear data this returns that data's shear
//! angle exactly (stick below HG, slope G, saturation at the locking angle); for measured bias
//! curves it is the shear those curves imply.

use atelier_fabric::{Branch, Fabric};

/// Samples of the table.
const SAMPLES: usize = 512;

/// γ(τ) tabulated at `τ_k = τ_max (k/N)²` (fine where the stick ends), odd in τ.
#[derive(Clone, Debug)]
pub struct ShearCurve {
    tau_max: f64,
    gamma: Vec<f64>,
}

impl ShearCurve {
    /// Build from a fabric's loading branches.
    pub fn from_fabric(fabric: &Fabric) -> Self {
        let d = &fabric.tensile;
        let tau_max = 0.5
            * d.bias45
                .max_force()
                .min(2.0 * d.warp.max_force())
                .min(2.0 * d.weft.max_force());
        let mut last: f64 = 0.0;
        let gamma = (0..=SAMPLES)
            .map(|k| {
                let tau = tau_max * (k as f64 / SAMPLES as f64).powi(2);
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

    /// Secant stiffness τ/γ at shear angle `gamma` (rad), N/(m·rad): the force per width at which
    /// the curve reaches `gamma`, found by bisection, divided by `gamma`. When the curve never
    /// reaches `gamma` the secant at τ_max is returned.
    pub fn secant_stiffness(&self, gamma: f64) -> f64 {
        if self.angle(self.tau_max) <= gamma {
            return self.tau_max / self.angle(self.tau_max).max(f64::MIN_POSITIVE);
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
        0.5 * (lo + hi) / gamma
    }

    /// Shear angle at shear force per width `tau` (N/m), rad; odd in τ, constant beyond τ_max.
    pub fn angle(&self, tau: f64) -> f64 {
        let x = ((tau.abs() / self.tau_max).sqrt() * SAMPLES as f64).min(SAMPLES as f64);
        let k = (x as usize).min(SAMPLES - 1);
        let (a, b) = (k as f64 / SAMPLES as f64, (k + 1) as f64 / SAMPLES as f64);
        let t = ((tau.abs() / self.tau_max).min(1.0) - a * a) / (b * b - a * a);
        let g = self.gamma[k] + t * (self.gamma[k + 1] - self.gamma[k]);
        g.copysign(tau)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use atelier_fabric::{Shear, TensileLoop, bias_from_shear, units};

    /// The curve recovers the KES shear angle the bias loop was built from.
    #[test]
    fn inverts_the_bias_relation() {
        let fm = units::KES_MAX_TENSILE_FORCE;
        let shear = Shear {
            stiffness: units::shear_stiffness_from_kes(1.5),
            hysteresis: units::force_from_kes(2.5),
            hysteresis_5deg: None,
            locking_angle: atelier_fabric::DEFAULT_LOCKING_ANGLE,
        };
        let spec = atelier_fabric::TensileSummary {
            lt: 0.7,
            emt: 0.04,
            rt: 0.5,
            f_max: fm,
        };
        let warp = TensileLoop::from_summary(&spec).expect("loop");
        let weft = TensileLoop::from_summary(&atelier_fabric::TensileSummary { emt: 0.06, ..spec })
            .expect("loop");
        let bias = bias_from_shear(&warp, &weft, &shear).expect("bias");
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/fabrics/cotton_broad.ron"
        ))
        .expect("fixture");
        let mut fabric =
            Fabric::from_ron_str(&text, std::path::Path::new("cotton_broad.ron")).expect("fabric");
        fabric.tensile.warp = warp;
        fabric.tensile.weft = weft;
        fabric.tensile.bias45 = bias;
        let curve = ShearCurve::from_fabric(&fabric);
        for &tau in &[0.5, 1.0, 2.0, 5.0, 20.0, 100.0] {
            let expect = shear.loading_angle(tau);
            assert!(
                (curve.angle(tau) - expect).abs() < 2e-3 * expect.max(1e-3),
                "τ = {tau}: {} vs {expect}",
                curve.angle(tau)
            );
            assert!((curve.angle(-tau) + curve.angle(tau)).abs() < 1e-15);
        }
        // Stick below HG.
        assert!(curve.angle(0.9 * 0.5 * shear.hysteresis).abs() < 1e-9);
    }
}
