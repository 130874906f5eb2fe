//! The turn of a grid line at a node, for the implicit bending constraints of the shape stage:
//! the signed angle θ from the incoming edge's direction t₋ = (xᵢ − x₋)/|…| to the outgoing
//! one's t₊ = (x₊ − xᵢ)/|…|, measured about an axis m fixed over a step,
//! `θ = atan2((t₋ × t₊)·m, t₋·t₊)`. With m = t̄ × n (t̄ the line's mean direction, n the node
//! normal) a line turning towards +n has θ > 0, and θ ≈ n·(t₊ − t₋) for small turns; unlike that
//! projection, θ stays monotone through a sharp fold (up to ±π), so the Newton iteration of the
//! shape stage does not stall where a seam or a dart folds the cloth hard. The curvature is
//! θ/l̄, l̄ the mean rest length of the two edges.

use nalgebra::Vector3;

type V3 = Vector3<f64>;

/// The axis a node's line turns about over a step: `m = t̄ × n` normalised, t̄ the mean of the
/// two edge directions (the incoming one's alone when they cancel), n the node normal. Zero
/// when it cannot be formed (an edge of zero length, or a line along the normal).
pub fn turn_axis(before: &V3, node: &V3, after: &V3, normal: &V3) -> V3 {
    let (ea, eb) = (node - before, after - node);
    let (la, lb) = (ea.norm(), eb.norm());
    if la == 0.0 || lb == 0.0 {
        return V3::zeros();
    }
    let mut mean = ea / la + eb / lb;
    if mean.norm() < 1e-9 {
        mean = ea / la;
    }
    let m = mean.cross(normal);
    let len = m.norm();
    if len > 1e-12 { m / len } else { V3::zeros() }
}

/// The turn θ (rad) of the line `before → node → after` about `axis` and its gradient with
/// respect to the three points (before, node, after). Zero gradient for a degenerate line.
pub fn turn_and_gradient(axis: &V3, before: &V3, node: &V3, after: &V3) -> (f64, [V3; 3]) {
    let (ea, eb) = (node - before, after - node);
    let (la, lb) = (ea.norm(), eb.norm());
    if la == 0.0 || lb == 0.0 {
        return (0.0, [V3::zeros(); 3]);
    }
    let (ta, tb) = (ea / la, eb / lb);
    let y = ta.cross(&tb).dot(axis);
    let x = ta.dot(&tb);
    let r2 = x * x + y * y;
    if r2 == 0.0 {
        return (0.0, [V3::zeros(); 3]);
    }
    // ∂θ/∂t = (x ∂y/∂t − y ∂x/∂t)/(x² + y²), ∂y/∂t₋ = t₊ × m, ∂y/∂t₊ = m × t₋.
    let d_ta = (tb.cross(axis) * x - tb * y) / r2;
    let d_tb = (axis.cross(&ta) * x - ta * y) / r2;
    // ∂t/∂e = (I − t tᵀ)/|e|.
    let project = |t: &V3, v: &V3, l: f64| (v - t * t.dot(v)) / l;
    let g_before = -project(&ta, &d_ta, la);
    let g_after = project(&tb, &d_tb, lb);
    (y.atan2(x), [g_before, -(g_before + g_after), g_after])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line bent by θ towards the normal reads +θ, away from it −θ, through a fold of 170°.
    #[test]
    fn the_turn_is_the_signed_angle_up_to_a_sharp_fold() {
        let n = V3::new(0.0, 0.0, 1.0);
        for theta in [-3.0f64, -1.0, -0.01, 0.0, 0.2, 1.5, 2.97] {
            let before = V3::new(-1.0, 0.0, 0.0);
            let node = V3::zeros();
            let after = V3::new(theta.cos(), 0.0, theta.sin()) * 0.7;
            let axis = turn_axis(&before, &node, &V3::new(1.0, 0.0, 0.0), &n);
            let (got, _) = turn_and_gradient(&axis, &before, &node, &after);
            assert!((got - theta).abs() < 1e-12, "{theta}: {got}");
        }
    }

    /// The gradient is the central difference of the turn, on random lines.
    #[test]
    fn the_gradient_is_the_finite_difference() {
        let mut seed = 99u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 10_000) as f64 / 10_000.0 - 0.5
        };
        for _ in 0..50 {
            let p: [V3; 3] = [
                V3::new(-1.0 + rnd() * 0.3, rnd() * 0.3, rnd() * 0.3),
                V3::new(rnd() * 0.3, rnd() * 0.3, rnd() * 0.3),
                V3::new(1.0 + rnd() * 0.3, rnd() * 0.3, rnd() * 0.3),
            ];
            let axis = turn_axis(&p[0], &p[1], &p[2], &V3::new(0.1, 0.2, 1.0).normalize());
            let (_, g) = turn_and_gradient(&axis, &p[0], &p[1], &p[2]);
            let h = 1e-6;
            for k in 0..3 {
                for d in 0..3 {
                    let (mut a, mut b) = (p, p);
                    a[k][d] += h;
                    b[k][d] -= h;
                    let fd = (turn_and_gradient(&axis, &a[0], &a[1], &a[2]).0
                        - turn_and_gradient(&axis, &b[0], &b[1], &b[2]).0)
                        / (2.0 * h);
                    assert!(
                        (fd - g[k][d]).abs() < 1e-6,
                        "point {k} axis {d}: {fd} vs {}",
                        g[k][d]
                    );
                }
            }
        }
    }
}
