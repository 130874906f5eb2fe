//! Conversions between the textile industry's KES-F units and SI.
//!
//! KES-F values are per centimetre of specimen width and use gram-force (1 gf = 9.806 65 mN).
//! Inside atelier everything is SI (`method.md` §0); these functions are the only place where the
//! factors live. Each `*_from_kes` function converts a KES value to SI, each `*_to_kes` the reverse
//! (for reports and plots).
//!
//! Factors (`reference/fabric-data.md` §1):
//!
//! | quantity | KES unit | SI unit | factor |
//! |---|---|---|---|
//! | tensile force per width F, Fm | gf/cm | N/m | 0.980665 |
//! | tensile energy WT | gf·cm/cm² | J/m² | 0.980665 |
//! | bending rigidity B | gf·cm²/cm | N·m | 9.80665e-5 |
//! | bending moment per width M, 2HB | gf·cm/cm | N·m/m = N | 9.80665e-3 |
//! | shear stiffness G | gf/(cm·deg) | N/(m·rad) | 0.980665·180/π = 56.1879 |
//! | shear hysteresis 2HG, 2HG5 | gf/cm | N/m | 0.980665 |
//! | mass per area W | mg/cm² | kg/m² | 0.01 |
//! | thickness T | mm | m | 1e-3 |
//! | curvature K | cm⁻¹ | m⁻¹ | 100 |
//! | strain EMT, RT | % | fraction | 0.01 |
//!
//! `method.md` §0 prints ×9.80665e-5 for the bending *moment* and for 2HB; that is the factor of the
//! rigidity B. A moment per width in gf·cm/cm is a force in gf, so its factor is 9.80665e-3, which is
//! also the only factor that keeps `M = B·K` unit-consistent (tested below).

/// One gram-force in newtons (standard gravity × 1 g).
pub const GRAM_FORCE_N: f64 = 9.806_65e-3;

/// gf/cm → N/m (tensile force per width, 2HG, 2HG5).
pub const FORCE_PER_WIDTH: f64 = GRAM_FORCE_N / 1e-2;
/// gf·cm/cm² → J/m² (tensile energy WT).
pub const ENERGY_PER_AREA: f64 = GRAM_FORCE_N * 1e-2 / 1e-4;
/// gf·cm²/cm → N·m (bending rigidity B per width).
pub const BENDING_RIGIDITY: f64 = GRAM_FORCE_N * 1e-4 / 1e-2;
/// gf·cm/cm → N (bending moment per width, 2HB).
pub const BENDING_MOMENT: f64 = GRAM_FORCE_N * 1e-2 / 1e-2;
/// gf/(cm·deg) → N/(m·rad) (shear stiffness G).
pub const SHEAR_STIFFNESS: f64 = FORCE_PER_WIDTH * 180.0 / std::f64::consts::PI;
/// mg/cm² → kg/m² (mass per area W).
pub const MASS_PER_AREA: f64 = 1e-6 / 1e-4;
/// mm → m (thickness T).
pub const THICKNESS: f64 = 1e-3;
/// cm⁻¹ → m⁻¹ (curvature K).
pub const CURVATURE: f64 = 1e2;
/// % → fraction (EMT, RT, strain in KES tables).
pub const PERCENT: f64 = 1e-2;

/// The KES maximum tensile force Fm = 500 gf/cm, in N/m.
pub const KES_MAX_TENSILE_FORCE: f64 = 500.0 * FORCE_PER_WIDTH;
/// The KES bending test's curvature limit ±2.5 cm⁻¹, in m⁻¹.
pub const KES_MAX_CURVATURE: f64 = 2.5 * CURVATURE;

/// Tensile force per width: gf/cm → N/m.
pub fn force_from_kes(gf_per_cm: f64) -> f64 {
    gf_per_cm * FORCE_PER_WIDTH
}
/// Tensile force per width: N/m → gf/cm.
pub fn force_to_kes(n_per_m: f64) -> f64 {
    n_per_m / FORCE_PER_WIDTH
}
/// Tensile energy WT: gf·cm/cm² → J/m².
pub fn energy_from_kes(gf_cm_per_cm2: f64) -> f64 {
    gf_cm_per_cm2 * ENERGY_PER_AREA
}
/// Tensile energy WT: J/m² → gf·cm/cm².
pub fn energy_to_kes(j_per_m2: f64) -> f64 {
    j_per_m2 / ENERGY_PER_AREA
}
/// Bending rigidity B: gf·cm²/cm → N·m.
pub fn rigidity_from_kes(gf_cm2_per_cm: f64) -> f64 {
    gf_cm2_per_cm * BENDING_RIGIDITY
}
/// Bending rigidity B: N·m → gf·cm²/cm.
pub fn rigidity_to_kes(n_m: f64) -> f64 {
    n_m / BENDING_RIGIDITY
}
/// Bending moment per width (and 2HB): gf·cm/cm → N.
pub fn moment_from_kes(gf_cm_per_cm: f64) -> f64 {
    gf_cm_per_cm * BENDING_MOMENT
}
/// Bending moment per width (and 2HB): N → gf·cm/cm.
pub fn moment_to_kes(n: f64) -> f64 {
    n / BENDING_MOMENT
}
/// Shear stiffness G: gf/(cm·deg) → N/(m·rad).
pub fn shear_stiffness_from_kes(gf_per_cm_deg: f64) -> f64 {
    gf_per_cm_deg * SHEAR_STIFFNESS
}
/// Shear stiffness G: N/(m·rad) → gf/(cm·deg).
pub fn shear_stiffness_to_kes(n_per_m_rad: f64) -> f64 {
    n_per_m_rad / SHEAR_STIFFNESS
}
/// Mass per area W: mg/cm² → kg/m².
pub fn mass_per_area_from_kes(mg_per_cm2: f64) -> f64 {
    mg_per_cm2 * MASS_PER_AREA
}
/// Mass per area W: kg/m² → mg/cm².
pub fn mass_per_area_to_kes(kg_per_m2: f64) -> f64 {
    kg_per_m2 / MASS_PER_AREA
}
/// Thickness T: mm → m.
pub fn thickness_from_kes(mm: f64) -> f64 {
    mm * THICKNESS
}
/// Thickness T: m → mm.
pub fn thickness_to_kes(m: f64) -> f64 {
    m / THICKNESS
}
/// Curvature: cm⁻¹ → m⁻¹.
pub fn curvature_from_kes(per_cm: f64) -> f64 {
    per_cm * CURVATURE
}
/// Curvature: m⁻¹ → cm⁻¹.
pub fn curvature_to_kes(per_m: f64) -> f64 {
    per_m / CURVATURE
}
/// Strain: % → fraction.
pub fn strain_from_percent(percent: f64) -> f64 {
    percent * PERCENT
}
/// Strain: fraction → %.
pub fn strain_to_percent(fraction: f64) -> f64 {
    fraction / PERCENT
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The exact factors of `reference/fabric-data.md` §1.
    #[test]
    fn factors_match_the_reference_table() {
        let tight = 1e-12;
        assert_relative_eq!(force_from_kes(1.0), 0.980665, max_relative = tight);
        assert_relative_eq!(force_from_kes(500.0), 490.3325, max_relative = tight);
        assert_relative_eq!(energy_from_kes(1.0), 0.980665, max_relative = tight);
        assert_relative_eq!(rigidity_from_kes(1.0), 9.80665e-5, max_relative = tight);
        assert_relative_eq!(moment_from_kes(1.0), 9.80665e-3, max_relative = tight);
        // G: 0.980665 × 180/π = 56.18799…; the table prints 56.188.
        assert_relative_eq!(shear_stiffness_from_kes(1.0), 56.188, max_relative = 1e-5);
        assert_relative_eq!(
            shear_stiffness_from_kes(1.0),
            0.980665 * 180.0 / std::f64::consts::PI,
            max_relative = tight
        );
        assert_relative_eq!(mass_per_area_from_kes(1.0), 0.01, max_relative = tight);
        assert_relative_eq!(thickness_from_kes(1.0), 1e-3, max_relative = tight);
        assert_relative_eq!(curvature_from_kes(1.0), 100.0, max_relative = tight);
        assert_relative_eq!(strain_from_percent(5.0), 0.05, max_relative = tight);
        assert_relative_eq!(KES_MAX_TENSILE_FORCE, 490.3325, max_relative = tight);
    }

    /// M = B·K must hold in both unit systems: 1 gf·cm²/cm × 1 cm⁻¹ = 1 gf·cm/cm.
    #[test]
    fn moment_equals_rigidity_times_curvature_in_si() {
        let b = 0.118; // gf·cm²/cm (cotton broad)
        let k = 1.7; // cm⁻¹
        let m_si = rigidity_from_kes(b) * curvature_from_kes(k);
        assert_relative_eq!(m_si, moment_from_kes(b * k), max_relative = 1e-12);
    }

    #[test]
    fn conversions_round_trip() {
        type Conversion = fn(f64) -> f64;
        let pairs: [(Conversion, Conversion); 9] = [
            (force_from_kes, force_to_kes),
            (energy_from_kes, energy_to_kes),
            (rigidity_from_kes, rigidity_to_kes),
            (moment_from_kes, moment_to_kes),
            (shear_stiffness_from_kes, shear_stiffness_to_kes),
            (mass_per_area_from_kes, mass_per_area_to_kes),
            (thickness_from_kes, thickness_to_kes),
            (curvature_from_kes, curvature_to_kes),
            (strain_from_percent, strain_to_percent),
        ];
        for (to_si, to_kes) in pairs {
            assert_relative_eq!(to_kes(to_si(3.7)), 3.7, max_relative = 1e-14);
        }
    }
}
