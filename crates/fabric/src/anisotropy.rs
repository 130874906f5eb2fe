//! Orthotropic interpolation of a characteristic to any material angle θ (thesis §3.7.1,
//! (33)–(36); `method.md` §1.3).
//!
//! θ is measured from the warp in the flat pattern: 0° = warp (v), 90° = weft (u), 45° and 135° the
//! two bias directions. From the warp, weft and bias values φ_v, φ_u, φ_b at the same argument
//! (force for tensile curves, curvature for bending), with `c = cos θ`, `s = sin θ`:
//!
//! - [`AnisotropyForm::Thesis`] (default), the reciprocal form (33)/(35):
//!   `1/φ_θ = c⁴/φ_v + G′ s²c² + s⁴/φ_u`, `G′ = 4/φ_b − 1/φ_v − 1/φ_u`;
//! - [`AnisotropyForm::Compliance`], the linear form of classical orthotropic plate theory:
//!   `φ_θ = c⁴ φ_v + G″ s²c² + s⁴ φ_u`, `G″ = 4φ_b − φ_v − φ_u`.
//!
//! Both reproduce the three given directions exactly. Expanded, both are `w_v·x_v + w_b·x_b + w_u·x_u`
//! with `w_v = c²(c² − s²)`, `w_b = 4s²c²`, `w_u = s²(s² − c²)` and `x = 1/φ` (thesis) or `x = φ`
//! (compliance). The 45° data serve θ ∈ [0°, 90°] ∪ [180°, 270°], the 135° data the other
//! quadrants; both forms are symmetric under θ → θ + 180°.
//!
//! For a tensile curve φ is a strain per force, a compliance, so the compliance form is plate theory
//! and the thesis form interpolates stiffness. For bending φ is a moment per curvature, a stiffness,
//! so there it is the *thesis* form that matches plate theory. The weights `w_v` and `w_u` change
//! sign across the quadrant, so either form can give a non-positive value for strongly anisotropic
//! data; [`interpolate`] then returns `None` and the caller reports the angle.

use serde::{Deserialize, Serialize};

/// Which interpolation law is used between the measured directions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum AnisotropyForm {
    /// The thesis's reciprocal form (33)–(36).
    #[default]
    Thesis,
    /// The linear (plate-theory compliance) form.
    Compliance,
    /// Classical orthotropic plate theory for both quantities: the compliance (linear) form for
    /// tensile curves (strain per force) and the reciprocal form for bending (moment per
    /// curvature). The thesis form applied to tensile curves can turn a loop inside out for
    /// strongly anisotropic fabrics at angles between the measured ones (measured: the cotton
    /// fixture at 52.5°, branches crossing by 15 % of the apex strain), so a cloth of arbitrary
    /// edge angles defaults to this.
    PlateTheory,
}

impl AnisotropyForm {
    /// The form used for tensile (compliance-like) characteristics.
    pub fn for_tensile(self) -> AnisotropyForm {
        match self {
            AnisotropyForm::PlateTheory => AnisotropyForm::Compliance,
            f => f,
        }
    }

    /// The form used for bending (stiffness-like) characteristics.
    pub fn for_bending(self) -> AnisotropyForm {
        match self {
            AnisotropyForm::PlateTheory => AnisotropyForm::Thesis,
            f => f,
        }
    }
}

/// Values of one quantity in the four measured directions.
#[derive(Clone, Debug, PartialEq)]
pub struct Directions<T> {
    /// 0°: along the warp (v).
    pub warp: T,
    /// 90°: along the weft (u).
    pub weft: T,
    /// 45° bias.
    pub bias45: T,
    /// 135° bias.
    pub bias135: T,
}

impl<T> Directions<T> {
    /// The bias value that serves angle `theta` (rad): 45° for θ mod 180° ≤ 90°, else 135°.
    pub fn bias_for(&self, theta: f64) -> &T {
        if bias_side(theta) == 0 {
            &self.bias45
        } else {
            &self.bias135
        }
    }

    /// Apply `f` to each direction.
    pub fn map<U>(&self, mut f: impl FnMut(&T) -> U) -> Directions<U> {
        Directions {
            warp: f(&self.warp),
            weft: f(&self.weft),
            bias45: f(&self.bias45),
            bias135: f(&self.bias135),
        }
    }
}

/// Which bias serves angle `theta` (rad): 0 for 45° (θ mod 180° ≤ 90°), 1 for 135°.
pub fn bias_side(theta: f64) -> usize {
    usize::from(canonical_angle(theta) > std::f64::consts::FRAC_PI_2)
}

/// θ reduced to [0, π): the characteristic of a line does not depend on its orientation.
pub fn canonical_angle(theta: f64) -> f64 {
    let r = theta.rem_euclid(std::f64::consts::PI);
    // rem_euclid can round up to π itself.
    if r >= std::f64::consts::PI { 0.0 } else { r }
}

/// The weights `(w_v, w_b, w_u)` of the expanded interpolation at angle `theta` (rad).
pub fn weights(theta: f64) -> (f64, f64, f64) {
    let (s, c) = theta.sin_cos();
    let (s2, c2) = (s * s, c * c);
    (c2 * (c2 - s2), 4.0 * s2 * c2, s2 * (s2 - c2))
}

/// Weights smaller than this are treated as exactly zero (they come from cos 90° ≈ 6e-17).
const NEGLIGIBLE_WEIGHT: f64 = 1e-12;

/// Interpolate to angle `theta` (rad) from the warp, weft and bias values (the bias value must be
/// the one serving θ, see [`Directions::bias_for`]). `None` when the form gives no positive value
/// (or, for the thesis form, mixes zero and non-zero data with a negative weight). All-zero data
/// give zero.
pub fn interpolate(
    form: AnisotropyForm,
    theta: f64,
    warp: f64,
    weft: f64,
    bias: f64,
) -> Option<f64> {
    interpolate_weighted(form, weights(theta), warp, weft, bias)
}

/// [`interpolate`] with the angle's [`weights`] computed once by the caller (a table of many
/// values at one angle).
pub fn interpolate_weighted(
    form: AnisotropyForm,
    (wv, wb, wu): (f64, f64, f64),
    warp: f64,
    weft: f64,
    bias: f64,
) -> Option<f64> {
    let terms = [(wv, warp), (wb, bias), (wu, weft)];
    if terms.iter().any(|t| !t.1.is_finite() || t.1 < 0.0) {
        return None;
    }
    match form {
        // A scalar's kind is unknown here; callers resolve PlateTheory with for_tensile /
        // for_bending, and a bare PlateTheory interpolates linearly.
        AnisotropyForm::Compliance | AnisotropyForm::PlateTheory => {
            let v: f64 = terms.iter().map(|&(w, x)| w * x).sum();
            let scale = warp.max(weft).max(bias);
            if v < -1e-12 * scale {
                None
            } else {
                Some(v.max(0.0))
            }
        }
        AnisotropyForm::Thesis => {
            if warp == 0.0 && weft == 0.0 && bias == 0.0 {
                return Some(0.0);
            }
            let mut inverse = 0.0;
            let (mut plus_inf, mut minus_inf) = (false, false);
            for (w, x) in terms {
                if w.abs() < NEGLIGIBLE_WEIGHT {
                    continue;
                }
                if x == 0.0 {
                    if w > 0.0 {
                        plus_inf = true;
                    } else {
                        minus_inf = true;
                    }
                } else {
                    inverse += w / x;
                }
            }
            match (plus_inf, minus_inf) {
                (_, true) => None,
                (true, false) => Some(0.0),
                _ if inverse > 0.0 => Some(1.0 / inverse),
                _ => None,
            }
        }
    }
}

/// A bias value for data that give none, from warp and weft alone: the value that makes the
/// thesis form's coupling term the geometric mean, `G′ = 2/√(φ_v φ_u)`, i.e.
/// `φ_b = (2/(φ_v^-½ + φ_u^-½))²` (Huber's approximation for orthotropic plates; isotropic data give
/// `φ_b = φ_v = φ_u`). Used for the bias bending of fabrics measured in warp and weft only.
pub fn huber_bias(warp: f64, weft: f64) -> f64 {
    if warp == 0.0 || weft == 0.0 {
        return 0.0;
    }
    let h = 2.0 / (warp.sqrt().recip() + weft.sqrt().recip());
    h * h
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    #[test]
    fn both_forms_are_exact_in_the_measured_directions() {
        let (v, u, b) = (0.03, 0.07, 0.2);
        for form in [AnisotropyForm::Thesis, AnisotropyForm::Compliance] {
            let at = |deg: f64| interpolate(form, deg.to_radians(), v, u, b).expect("defined");
            assert_relative_eq!(at(0.0), v, max_relative = 1e-12);
            assert_relative_eq!(at(90.0), u, max_relative = 1e-12);
            assert_relative_eq!(at(45.0), b, max_relative = 1e-12);
            assert_relative_eq!(at(135.0), b, max_relative = 1e-12);
            assert_relative_eq!(at(180.0), v, max_relative = 1e-12);
        }
    }

    #[test]
    fn isotropic_data_stay_isotropic() {
        for form in [AnisotropyForm::Thesis, AnisotropyForm::Compliance] {
            for i in 0..16 {
                let th = i as f64 * PI / 16.0;
                let v = interpolate(form, th, 0.05, 0.05, 0.05).expect("defined");
                assert_relative_eq!(v, 0.05, max_relative = 1e-12);
            }
        }
        assert_relative_eq!(huber_bias(2.0, 2.0), 2.0, max_relative = 1e-12);
    }

    #[test]
    fn zero_data_and_impossible_mixtures() {
        assert_eq!(
            interpolate(AnisotropyForm::Thesis, 0.3, 0.0, 0.0, 0.0),
            Some(0.0)
        );
        // Strongly anisotropic data with a soft bias: the thesis form's reciprocal turns negative.
        let th = 57.0_f64.to_radians();
        assert_eq!(
            interpolate(AnisotropyForm::Thesis, th, 1.0, 10.0, 100.0),
            None
        );
        assert!(interpolate(AnisotropyForm::Compliance, th, 1.0, 10.0, 100.0).is_some());
        assert_eq!(
            interpolate(AnisotropyForm::Compliance, th, 1.0, f64::NAN, 1.0),
            None
        );
    }

    #[test]
    fn canonical_angle_folds_by_half_turns() {
        assert_relative_eq!(canonical_angle(-0.25 * PI), 0.75 * PI, max_relative = 1e-12);
        assert_relative_eq!(canonical_angle(2.25 * PI), 0.25 * PI, max_relative = 1e-12);
    }
}
