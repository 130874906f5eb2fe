//! The shear loop as KES-FB1 measures it: G, 2HG and 2HG5 read off two branches, the virtual
//! KES-FB1 test of a loop, and measured loops (force–angle points) checked and reduced to the
//! KES values.

use crate::error::{ErrorKind, InvalidValue};
use crate::units;

use super::{
    DEG, KES_MAX_SHEAR_ANGLE, KES_SHEAR_ANGLES, MEASURED_MAX_ANGLE_DEG, MEASURED_MAX_FORCE_GF_CM,
    MEASURED_MIN_POINTS, ShearLoop, ShearState,
};

/// G, 2HG and 2HG5 read off two branches as KES-FB1 defines them. `upper` and `lower` are
/// `(angle rad, force N/m)` with the angle increasing and covering ±5°: G is the mean of the
/// four mean slopes between 0.5° and 5° (each branch, each sign; a mean slope is the secant,
/// the mean of the derivative), 2HG and 2HG5 the mean widths at ±0.5° and ±5°. The branches are
/// interpolated linearly between points.
fn kes_values(upper: &[(f64, f64)], lower: &[(f64, f64)]) -> (f64, f64, f64) {
    let (lo, hi) = KES_SHEAR_ANGLES;
    let at = |pts: &[(f64, f64)], x: f64| linear_at(pts, x);
    let slope = |pts: &[(f64, f64)]| {
        0.5 * ((at(pts, hi) - at(pts, lo)) + (at(pts, -lo) - at(pts, -hi))) / (hi - lo)
    };
    let g = 0.5 * (slope(upper) + slope(lower));
    let width = |x: f64| 0.5 * ((at(upper, x) - at(lower, x)) + (at(upper, -x) - at(lower, -x)));
    (g, width(lo), width(hi))
}

/// Linear interpolation in points sorted by x (constant beyond the ends).
fn linear_at(pts: &[(f64, f64)], x: f64) -> f64 {
    let k = pts.partition_point(|p| p.0 < x);
    if k == 0 {
        return pts.first().map_or(f64::NAN, |p| p.1);
    }
    if k >= pts.len() {
        return pts.last().map_or(f64::NAN, |p| p.1);
    }
    let ((x0, y0), (x1, y1)) = (pts[k - 1], pts[k]);
    if x1 <= x0 {
        return y1;
    }
    y0 + (y1 - y0) * (x - x0) / (x1 - x0)
}

/// What a KES-FB1 shear tester reports for a loop.
#[derive(Clone, Debug, PartialEq)]
pub struct KesShearTest {
    /// G: mean slope between 0.5° and 5° over both branches and both signs, N/(m·rad).
    pub g: f64,
    /// 2HG: mean loop width at ±0.5°, N/m.
    pub two_hg: f64,
    /// 2HG5: mean loop width at ±5°, N/m.
    pub two_hg5: f64,
    /// The recorded cycle `(γ rad, τ N/m)`: 0 → +8° → −8° → +8°.
    pub loop_points: Vec<(f64, f64)>,
}

/// Run a virtual KES-FB1 shear test on `l`: shear from rest to +8°, back to −8° and to +8° again,
/// with `steps_per_deg` samples per degree (±0.5° and ±5° are sampled exactly when it is even),
/// and measure G, 2HG and 2HG5 on the loop this leaves: the lower branch from the pass +8° → −8°,
/// the upper from −8° → +8°.
pub fn kes_shear_test(l: &ShearLoop, steps_per_deg: usize) -> KesShearTest {
    let n = (8 * steps_per_deg).max(2);
    let max = KES_MAX_SHEAR_ANGLE;
    let leg = |from: f64, to: f64, steps: usize| {
        (1..=steps).map(move |i| from + (to - from) * i as f64 / steps as f64)
    };
    let mut state = ShearState::VIRGIN;
    let mut loop_points = vec![(0.0, 0.0)];
    for g in leg(0.0, max, n) {
        loop_points.push((g, state.update(l, g)));
    }
    let mut lower: Vec<(f64, f64)> = leg(max, -max, 2 * n)
        .map(|g| (g, state.update(l, g)))
        .collect();
    loop_points.extend_from_slice(&lower);
    let upper: Vec<(f64, f64)> = leg(-max, max, 2 * n)
        .map(|g| (g, state.update(l, g)))
        .collect();
    loop_points.extend_from_slice(&upper);
    lower.reverse();
    let (g, two_hg, two_hg5) = kes_values(&upper, &lower);
    KesShearTest {
        g,
        two_hg,
        two_hg5,
        loop_points,
    }
}

/// Result of reducing a measured shear loop to the KES values.
#[derive(Clone, Debug, PartialEq)]
pub struct ShearFit {
    /// The reconstructed loop of the measured G, 2HG, 2HG5.
    pub shear_loop: ShearLoop,
    /// Root-mean-square distance (N/m) of the measured points with 0.5° ≤ |γ| ≤ 5° from the
    /// reconstructed branches: how far the measured branches are from straight lines.
    pub rms_residual: f64,
    /// Number of those points.
    pub points_used: usize,
}

/// Check one point of a measured shear branch in KES units `(angle °, force gf/cm)`, given the
/// points before it; the error's field is the point's index `[i]`.
pub(crate) fn check_shear_point(
    before: &[(f64, f64)],
    point: (f64, f64),
) -> Result<(), InvalidValue> {
    let i = before.len();
    let at = format!("[{i}]");
    let (a, f) = point;
    if !(a.is_finite() && f.is_finite()) {
        return Err(InvalidValue::new(
            ErrorKind::NotFinite,
            at,
            format!("point ({a}, {f})"),
        ));
    }
    if a.abs() > MEASURED_MAX_ANGLE_DEG {
        return Err(InvalidValue::new(
            ErrorKind::OutOfRange,
            at,
            format!(
                "angle {a}° lies beyond ±{MEASURED_MAX_ANGLE_DEG}°; KES-FB1 measures to ±8° \
                 (angles are in degrees)"
            ),
        ));
    }
    if f.abs() > MEASURED_MAX_FORCE_GF_CM {
        return Err(InvalidValue::new(
            ErrorKind::OutOfRange,
            at,
            format!(
                "force {f} gf/cm is implausible for a shear force per width (above \
                 ±{MEASURED_MAX_FORCE_GF_CM}); a force for the whole specimen, or not gf/cm?"
            ),
        ));
    }
    if let Some(&(ap, fp)) = before.last() {
        if a <= ap {
            return Err(InvalidValue::new(
                ErrorKind::NonMonotone,
                at,
                format!(
                    "angle {a}° does not increase (previous {ap}°): list each branch with the \
                     angle increasing; a branch that turns back makes the loop cross itself"
                ),
            ));
        }
        if f < fp {
            return Err(InvalidValue::new(
                ErrorKind::NonMonotone,
                at,
                format!("force {f} gf/cm falls (previous {fp}) while the angle increases"),
            ));
        }
    }
    Ok(())
}

/// Check a whole measured shear branch in KES units: every point (see [`check_shear_point`]),
/// at least [`MEASURED_MIN_POINTS`] points, and the KES measuring range −5°…+5° covered.
pub(crate) fn check_shear_branch(points: &[(f64, f64)]) -> Result<(), InvalidValue> {
    for i in 0..points.len() {
        check_shear_point(&points[..i], points[i])?;
    }
    check_shear_extent(points)
}

/// The checks of a complete branch that no single point decides: enough points, −5°…+5° covered.
pub(crate) fn check_shear_extent(points: &[(f64, f64)]) -> Result<(), InvalidValue> {
    if points.len() < MEASURED_MIN_POINTS {
        return Err(InvalidValue::new(
            ErrorKind::TooShort,
            "",
            format!(
                "{} point(s); a branch needs at least {MEASURED_MIN_POINTS}",
                points.len()
            ),
        ));
    }
    let (first, last) = (points[0].0, points[points.len() - 1].0);
    let need = KES_SHEAR_ANGLES.1 / DEG;
    // A hair of slack: ±5° given exactly may come back from radians as 4.999…°.
    let slack = 1e-9 * need;
    if first > -need + slack || last < need - slack {
        return Err(InvalidValue::new(
            ErrorKind::OutOfRange,
            "",
            format!(
                "the branch spans {first}°…{last}°; it must cover −{need}°…+{need}° (the KES \
                 measuring points; angles are in degrees, not radians)"
            ),
        ));
    }
    Ok(())
}

/// Check that two measured branches (KES units, each valid alone) do not cross: the lower branch
/// (angle falling) must not lie above the upper one (angle rising) anywhere both are measured.
/// The error names the first offending point of either branch (`lower[i]` or `upper[i]`).
pub(crate) fn check_shear_branches_apart(
    upper: &[(f64, f64)],
    lower: &[(f64, f64)],
) -> Result<(), InvalidValue> {
    let (from, to) = (
        upper[0].0.max(lower[0].0),
        upper[upper.len() - 1].0.min(lower[lower.len() - 1].0),
    );
    let scale = upper
        .iter()
        .chain(lower)
        .map(|p| p.1.abs())
        .fold(0.0, f64::max);
    let tol = 1e-9 * scale;
    let crossing = |name: &str, pts: &[(f64, f64)], other: &[(f64, f64)], sign: f64| {
        pts.iter()
            .enumerate()
            .filter(|(_, p)| p.0 >= from && p.0 <= to)
            .find(|(_, p)| sign * (p.1 - linear_at(other, p.0)) > tol)
            .map(|(i, p)| {
                InvalidValue::new(
                    ErrorKind::Inconsistent,
                    format!("{name}[{i}]"),
                    format!(
                        "at {}° the lower branch ({:.4} gf/cm) lies above the upper ({:.4} \
                         gf/cm): the branches cross (are `upper` and `lower` swapped?)",
                        p.0,
                        if sign > 0.0 {
                            p.1
                        } else {
                            linear_at(other, p.0)
                        },
                        if sign > 0.0 {
                            linear_at(other, p.0)
                        } else {
                            p.1
                        },
                    ),
                )
            })
    };
    // The first offending point in angle order, of either branch.
    let a = crossing("lower", lower, upper, 1.0);
    let b = crossing("upper", upper, lower, -1.0);
    let angle_of = |e: &InvalidValue, pts_l: &[(f64, f64)], pts_u: &[(f64, f64)]| {
        let idx: usize = e
            .field
            .split(['[', ']'])
            .nth(1)
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        if e.field.starts_with("lower") {
            pts_l[idx].0
        } else {
            pts_u[idx].0
        }
    };
    match (a, b) {
        (None, None) => Ok(()),
        (Some(e), None) | (None, Some(e)) => Err(e),
        (Some(x), Some(y)) => {
            if angle_of(&x, lower, upper) <= angle_of(&y, lower, upper) {
                Err(x)
            } else {
                Err(y)
            }
        }
    }
}

/// Reduce a measured shear loop to G, 2HG and 2HG5 as KES-FB1 defines them (the mean slope
/// between 0.5° and 5° over both branches and both signs — the secant of each, linear between
/// points —, the mean widths at ±0.5° and ±5°) and reconstruct the loop from them. `upper`
/// (angle rising) and `lower` (falling) are `(angle rad, force N/m)` points, each listed with
/// the angle increasing, covering ±5°, the force non-decreasing along each, the lower never
/// above the upper (the checks of a measured loop in a fabric file, `docs/fabric.md` §7).
pub fn fit_shear(upper: &[(f64, f64)], lower: &[(f64, f64)]) -> Result<ShearFit, InvalidValue> {
    let kes = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> {
        pts.iter()
            .map(|&(a, f)| (a / DEG, units::force_to_kes(f)))
            .collect()
    };
    let (up_kes, lo_kes) = (kes(upper), kes(lower));
    check_shear_branch(&up_kes).map_err(|e| e.within("upper"))?;
    check_shear_branch(&lo_kes).map_err(|e| e.within("lower"))?;
    check_shear_branches_apart(&up_kes, &lo_kes)?;
    fit_checked(upper, lower)
}

/// [`fit_shear`] on branches already checked (in KES units, by the caller).
pub(crate) fn fit_checked(
    upper: &[(f64, f64)],
    lower: &[(f64, f64)],
) -> Result<ShearFit, InvalidValue> {
    let (g, two_hg, two_hg5) = kes_values(upper, lower);
    if g.is_nan() || g <= 0.0 {
        return Err(InvalidValue::new(
            ErrorKind::Inconsistent,
            "",
            format!(
                "the mean slope between 0.5° and 5° is {:.4} gf/(cm·deg); a shear loop must \
                 rise with the angle",
                units::shear_stiffness_to_kes(g)
            ),
        ));
    }
    let shear_loop = ShearLoop::from_kes(g, two_hg.max(0.0), Some(two_hg5.max(0.0)))?;
    let (lo, hi) = KES_SHEAR_ANGLES;
    let residuals: Vec<f64> = upper
        .iter()
        .map(|&(a, f)| (a, f - shear_loop.upper(a)))
        .chain(lower.iter().map(|&(a, f)| (a, f - shear_loop.lower(a))))
        .filter(|(a, _)| a.abs() >= lo && a.abs() <= hi)
        .map(|(_, r)| r)
        .collect();
    let rms = if residuals.is_empty() {
        0.0
    } else {
        (residuals.iter().map(|r| r * r).sum::<f64>() / residuals.len() as f64).sqrt()
    };
    Ok(ShearFit {
        shear_loop,
        rms_residual: rms,
        points_used: residuals.len(),
    })
}
