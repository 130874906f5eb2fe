//! The shear angle of a grid cell from its deformation (`method.md` §2b), and its gradient with
//! respect to the cell's four corners, for the shear constraints of the shape stage.
//!
//! A cell `q0 q1 q2 q3` (u from q0 to q1, v from q0 to q3) has the angle α between its u and v
//! directions; its shear angle is γ = α₀ − α, α₀ the angle at rest in the pattern plane, positive
//! when the angle between u and v closes. Two measures are offered, because they differ in how
//! much of a fold they count as shear:
//!
//! - [`ShearMeasure::Midpoint`] (default): the angle between the cell's midpoint vectors
//!   `s_u = ½(q1 + q2 − q0 − q3)` and `s_v = ½(q3 + q2 − q0 − q1)`. They are the half difference
//!   and half sum of the diagonals `d₊ = q2 − q0`, `d₋ = q3 − q1`, so they lie in the plane of the
//!   diagonals — the cell's tangent plane — whatever the cell's shape. A fold of the cell about a
//!   diagonal by a dihedral half-angle β changes this angle by O(β²) only.
//! - [`ShearMeasure::Corners`]: the mean of the four 3-D corner angles between the edges that
//!   meet at each corner (α at q0 and q2, π − α at q1 and q3 for a parallelogram). A fold about
//!   a diagonal closes the two corners on the fold line and leaves the other two.
//!
//! Both are exact for a flat parallelogram, invariant under rigid motions, and blind to a bend
//! along a grid line (the cell stays a plane rectangle). Neither can tell a fold about a
//! diagonal from shear: a quadrilateral with its four sides fixed has two shape freedoms, and
//! both measures read a fold of half-angle β as a shear of about β²/2 (the tests give the closed
//! forms). That spurious shear falls with the fourth power of the spacing in energy, so it is a
//! discretisation error that refinement removes (`docs/solver.md`).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

type V3 = Vector3<f64>;

/// How the angle between a cell's u and v directions is measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ShearMeasure {
    /// The angle between the midpoint vectors (in the plane of the diagonals).
    #[default]
    Midpoint,
    /// The mean of the four 3-D corner angles between the edges.
    Corners,
}

/// Angle between `a` and `b` (rad, in [0, π]) and its gradients with respect to `a` and `b`.
/// Zero gradients when either vector vanishes or they are parallel (the angle is then not
/// differentiable; the cell is degenerate).
fn angle_and_gradient(a: &V3, b: &V3) -> (f64, V3, V3) {
    let (la, lb) = (a.norm(), b.norm());
    if la == 0.0 || lb == 0.0 {
        return (0.0, V3::zeros(), V3::zeros());
    }
    let c = a.cross(b);
    let s = c.norm();
    let angle = s.atan2(a.dot(b));
    if s == 0.0 {
        return (angle, V3::zeros(), V3::zeros());
    }
    // ∂α/∂a = −(unit vector ⊥ a in the plane of a and b, towards b)/|a|, and the same for b.
    let towards_b = c.cross(a) / (s * la);
    let towards_a = b.cross(&c) / (s * lb);
    (angle, -towards_b / la, -towards_a / lb)
}

/// The angle α between the cell's u and v directions (rad) by `measure`, corners in the order
/// `q0 q1 q2 q3`.
pub fn cell_angle(measure: ShearMeasure, q: &[V3; 4]) -> f64 {
    cell_angle_gradient(measure, q).0
}

/// The angle α between the cell's u and v directions (rad) and its gradient with respect to each
/// corner.
pub fn cell_angle_gradient(measure: ShearMeasure, q: &[V3; 4]) -> (f64, [V3; 4]) {
    match measure {
        ShearMeasure::Midpoint => {
            let su = 0.5 * (q[1] + q[2] - q[0] - q[3]);
            let sv = 0.5 * (q[3] + q[2] - q[0] - q[1]);
            let (alpha, ga, gb) = angle_and_gradient(&su, &sv);
            // ∂s_u/∂q = (−½, ½, ½, −½), ∂s_v/∂q = (−½, −½, ½, ½).
            let grad = [
                0.5 * (-ga - gb),
                0.5 * (ga - gb),
                0.5 * (ga + gb),
                0.5 * (-ga + gb),
            ];
            (alpha, grad)
        }
        ShearMeasure::Corners => {
            let mut grad = [V3::zeros(); 4];
            let mut sum = 0.0;
            // Corner k: the edges to its u neighbour and to its v neighbour. At q0 and q2 the
            // corner angle is α, at q1 and q3 it is π − α.
            let corners: [(usize, usize, usize, f64); 4] = [
                (0, 1, 3, 1.0),
                (1, 0, 2, -1.0),
                (2, 3, 1, 1.0),
                (3, 2, 0, -1.0),
            ];
            for (k, a, b, sign) in corners {
                let (theta, ga, gb) = angle_and_gradient(&(q[a] - q[k]), &(q[b] - q[k]));
                sum += if sign > 0.0 {
                    theta
                } else {
                    std::f64::consts::PI - theta
                };
                grad[a] += ga * (0.25 * sign);
                grad[b] += gb * (0.25 * sign);
                grad[k] -= (ga + gb) * (0.25 * sign);
            }
            (0.25 * sum, grad)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Unit};

    fn parallelogram(a: f64, b: f64, alpha: f64) -> [V3; 4] {
        let u = V3::new(a, 0.0, 0.0);
        let v = V3::new(b * alpha.cos(), b * alpha.sin(), 0.0);
        [V3::zeros(), u, u + v, v]
    }

    /// A flat parallelogram reads its angle exactly with both measures, whatever its rigid
    /// placement.
    #[test]
    fn a_flat_parallelogram_reads_its_angle_after_any_rigid_motion() {
        let rot = Rotation3::from_axis_angle(&Unit::new_normalize(V3::new(0.3, -1.0, 0.7)), 1.1);
        let shift = V3::new(0.2, -0.4, 1.3);
        for alpha in [0.3, 1.0, std::f64::consts::FRAC_PI_2, 2.2] {
            let q = parallelogram(0.01, 0.013, alpha).map(|p| rot * p + shift);
            for m in [ShearMeasure::Midpoint, ShearMeasure::Corners] {
                let got = cell_angle(m, &q);
                assert!((got - alpha).abs() < 1e-12, "{m:?}: {got} vs {alpha}");
            }
        }
    }

    /// The gradients are the central differences of the angle, on random non-planar cells.
    #[test]
    fn gradients_are_the_finite_differences() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 10_000) as f64 / 10_000.0 - 0.5
        };
        for _ in 0..50 {
            let base = parallelogram(1.0, 1.2, 1.3);
            let q: [V3; 4] = base.map(|p| p + V3::new(rnd(), rnd(), rnd()) * 0.3);
            for m in [ShearMeasure::Midpoint, ShearMeasure::Corners] {
                let (_, g) = cell_angle_gradient(m, &q);
                let h = 1e-6;
                for k in 0..4 {
                    for d in 0..3 {
                        let (mut qp, mut qm) = (q, q);
                        qp[k][d] += h;
                        qm[k][d] -= h;
                        let fd = (cell_angle(m, &qp) - cell_angle(m, &qm)) / (2.0 * h);
                        assert!(
                            (fd - g[k][d]).abs() < 1e-6 * (1.0 + fd.abs()),
                            "{m:?} corner {k} axis {d}: {fd} vs {}",
                            g[k][d]
                        );
                    }
                }
            }
        }
    }

    /// A square folded about its diagonal q0–q2 (each half turned by β out of the plane, the
    /// edges kept): both measures count it as a shear of about β²/2. The numbers are the closed
    /// forms: midpoint cos α = (1 − cos²β)/(1 + cos²β); corners γ = (π/2 − acos(sin²β))/2.
    #[test]
    fn a_fold_about_a_diagonal_is_second_order_in_the_fold_angle() {
        for beta in [0.05f64, 0.1, 0.3] {
            let (c, s) = (beta.cos(), beta.sin());
            let q = [
                V3::new(-1.0, 0.0, 0.0),
                V3::new(0.0, -c, s),
                V3::new(1.0, 0.0, 0.0),
                V3::new(0.0, c, s),
            ];
            let mid = std::f64::consts::FRAC_PI_2 - cell_angle(ShearMeasure::Midpoint, &q);
            let corners = std::f64::consts::FRAC_PI_2 - cell_angle(ShearMeasure::Corners, &q);
            let mid_exact = std::f64::consts::FRAC_PI_2 - ((1.0 - c * c) / (1.0 + c * c)).acos();
            let corners_exact = 0.5 * (std::f64::consts::FRAC_PI_2 - (s * s).acos());
            assert!((mid - mid_exact).abs() < 1e-12, "{mid} vs {mid_exact}");
            assert!((corners - corners_exact).abs() < 1e-12);
            // Second order: γ/β² near ½ for both.
            for g in [mid, corners] {
                assert!(
                    (g / (beta * beta) - 0.5).abs() < 0.05,
                    "{}",
                    g / (beta * beta)
                );
            }
        }
    }
}
