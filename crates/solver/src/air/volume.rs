//! The volume of air between a cloth and the surface it lies on (Yamada (Y3.10), and its
//! generalisation to a curved body).
//!
//! **On a plane** (Y3.10): `v = Σ_t (U·N_t) A_t h̄_t` over the cloth's triangles — the signed
//! prism between each triangle and its projection on the plane: `(U·N_t) A_t` is the projected
//! area, `h̄_t` the mean height of the triangle's corners above the plane. It is the exact volume
//! of the polyhedron between the triangulated cloth and its vertical projection, and where the
//! cloth folds over, the downward-facing layer's prisms are negative and cancel the overlap.
//!
//! **On any surface** (the thesis's future work): each cloth node is projected to its nearest
//! point on the surface (its *footprint*), and each triangle with its footprint triangle bounds a
//! twisted prism; the bubble is the sum of their signed volumes (each split into three
//! tetrahedra). On a plane the footprint is the vertical projection and the sum equals (Y3.10)
//! exactly; on a curved surface the prisms' side faces are slightly warped and the sum is exact
//! as the cloth is refined (tested on a sphere).

use nalgebra::Vector3;

type V3 = Vector3<f64>;

/// A plane: a point on it and its unit normal (the side the cloth lies on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point of the plane, m.
    pub point: V3,
    /// Unit normal, pointing to the cloth's side.
    pub normal: V3,
}

impl Plane {
    /// The horizontal plane through `point` with +z up.
    pub fn horizontal(height: f64) -> Self {
        Self {
            point: V3::new(0.0, 0.0, height),
            normal: V3::z(),
        }
    }

    /// Signed height of `p` above the plane, m.
    pub fn height(&self, p: &V3) -> f64 {
        (p - self.point).dot(&self.normal)
    }
}

/// (Y3.10): the signed volume between the cloth (`positions`, `triangles` oriented with their
/// normals away from the plane) and the plane, heights measured above `plane` minus `rest`
/// (the height at which a node lies flat on it: Yamada's particles are spheres), m³.
pub fn plane_volume(positions: &[V3], triangles: &[[u32; 3]], plane: &Plane, rest: f64) -> f64 {
    triangles
        .iter()
        .map(|t| plane_prism(positions, t, plane, rest))
        .sum()
}

/// One triangle's signed prism (Y3.10): projected area × mean height.
pub fn plane_prism(positions: &[V3], t: &[u32; 3], plane: &Plane, rest: f64) -> f64 {
    let [a, b, c] = t.map(|k| positions[k as usize]);
    let projected = 0.5 * (b - a).cross(&(c - a)).dot(&plane.normal);
    let mean = (plane.height(&a) + plane.height(&b) + plane.height(&c)) / 3.0 - rest;
    projected * mean
}

/// The signed volume of the tetrahedron (a, b, c, d): positive when (b − a, c − a, d − a) is
/// right-handed.
fn tetrahedron(a: &V3, b: &V3, c: &V3, d: &V3) -> f64 {
    (b - a).cross(&(c - a)).dot(&(d - a)) / 6.0
}

/// The signed volume of the twisted prism between a cloth triangle (a, b, c) and its footprint
/// (a', b', c') below it: positive when the triangle's normal points away from its footprint.
/// Three tetrahedra: (a', b', c', a), (b', c', a, b), (c', a, b, c) — the standard split of a
/// prism along the diagonals a→b' … taken from the footprint up.
pub fn prism(top: [V3; 3], base: [V3; 3]) -> f64 {
    let [a, b, c] = top;
    let [a0, b0, c0] = base;
    tetrahedron(&a0, &b0, &c0, &a) + tetrahedron(&b0, &c0, &a, &b) + tetrahedron(&c0, &a, &b, &c)
}

/// The signed volume between the cloth and its footprint (`footprint[i]`: node i's nearest
/// point on the surface), m³: the sum of every triangle's [`prism`].
pub fn footprint_volume(positions: &[V3], footprint: &[V3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            prism(
                t.map(|k| positions[k as usize]),
                t.map(|k| footprint[k as usize]),
            )
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// A square grid of `n × n` nodes over [−s, s]², heights from `h(x, y)`, triangles up.
    fn grid(n: usize, s: f64, h: impl Fn(f64, f64) -> f64) -> (Vec<V3>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (
                    -s + 2.0 * s * i as f64 / (n - 1) as f64,
                    -s + 2.0 * s * j as f64 / (n - 1) as f64,
                );
                p.push(V3::new(x, y, h(x, y)));
            }
        }
        let mut t = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let k = (j * n + i) as u32;
                let n = n as u32;
                t.push([k, k + 1, k + n + 1]);
                t.push([k, k + n + 1, k + n]);
            }
        }
        (p, t)
    }

    /// (Y3.10) is exact for a pyramid: a square base 2s wide, apex height H at the centre, on a
    /// grid whose lines pass through the apex and the ridges (odd n): V = (2s)²·H/3.
    #[test]
    fn the_volume_of_a_pyramid_is_exact() {
        let (s, height) = (0.15, 0.04);
        for n in [3, 5, 11, 21] {
            let (p, t) = grid(n, s, |x, y| height * (1.0 - x.abs().max(y.abs()) / s));
            // The ridges run along the diagonals: split each cell along the diagonal that
            // follows them (both quadrant diagonals are ridges of a square pyramid).
            let t: Vec<[u32; 3]> = t
                .chunks(2)
                .flat_map(|c| {
                    let [k, k1, k2] = c[0];
                    let k3 = c[1][2];
                    let centre = (p[k as usize] + p[k2 as usize]) * 0.5;
                    if centre.x * centre.y > 0.0 {
                        vec![[k, k1, k2], [k, k2, k3]]
                    } else {
                        vec![[k, k1, k3], [k1, k2, k3]]
                    }
                })
                .collect();
            let v = plane_volume(&p, &t, &Plane::horizontal(0.0), 0.0);
            assert_relative_eq!(v, 4.0 * s * s * height / 3.0, max_relative = 1e-12);
        }
    }

    /// A tent (a ridge along y, height H at x = 0, zero at x = ±s): V = (2s)²·H/2, exact on any
    /// grid with a node line on the ridge; a shifted flat sheet at height h0 adds (2s)²·h0; the
    /// rest height is taken off.
    #[test]
    fn the_volume_of_a_tent_is_exact() {
        let (s, height, h0) = (0.15, 0.05, 0.002);
        for n in [3, 7, 31] {
            let (p, t) = grid(n, s, |x, _| h0 + height * (1.0 - x.abs() / s));
            let v = plane_volume(&p, &t, &Plane::horizontal(0.0), h0);
            assert_relative_eq!(v, 4.0 * s * s * height / 2.0, max_relative = 1e-12);
        }
    }

    /// A sheet folded over on itself (a Z-fold: out along x to the fold, back over itself,
    /// out again) holds exactly the volume under its top layer: the two lower layers' prisms
    /// cancel where the layers overlap, as Yamada's signed sum intends.
    #[test]
    fn a_fold_cancels() {
        // Three layers, each a strip of width w along x, 1 m along y, at heights 0.01, 0.02,
        // 0.03: x from 0 to w (up-facing), back from w to 0 (down-facing), out to w again.
        let w = 0.2;
        let layer = |z: f64, x0: f64, x1: f64| {
            [
                V3::new(x0, 0.0, z),
                V3::new(x1, 0.0, z),
                V3::new(x1, 1.0, z),
                V3::new(x0, 1.0, z),
            ]
        };
        let mut p: Vec<V3> = Vec::new();
        let mut t = Vec::new();
        for (z, x0, x1) in [(0.01, 0.0, w), (0.02, w, 0.0), (0.03, 0.0, w)] {
            let base = p.len() as u32;
            p.extend_from_slice(&layer(z, x0, x1));
            // Counter-clockwise seen from +z when x0 < x1 (up-facing), clockwise otherwise.
            t.push([base, base + 1, base + 2]);
            t.push([base, base + 2, base + 3]);
        }
        let v = plane_volume(&p, &t, &Plane::horizontal(0.0), 0.0);
        // Up, down, up: 0.01·w − 0.02·w + 0.03·w = 0.02·w (1 m along y).
        assert_relative_eq!(v, 0.02 * w, max_relative = 1e-12);
    }

    /// On a plane, the footprint volume (vertical projections as footprints) equals (Y3.10).
    #[test]
    fn the_footprint_volume_on_a_plane_is_yamadas() {
        let (p, t) = grid(9, 0.15, |x, y| {
            0.01 + 0.02 * (3.0 * x).cos() * (2.0 * y).sin().abs()
        });
        let plane = Plane::horizontal(0.0);
        let foot: Vec<V3> = p.iter().map(|q| V3::new(q.x, q.y, 0.0)).collect();
        assert_relative_eq!(
            footprint_volume(&p, &foot, &t),
            plane_volume(&p, &t, &plane, 0.0),
            max_relative = 1e-12
        );
    }

    /// On a sphere of radius R, a cloth cap at radius R + d over the polar cap of half-angle α
    /// (its footprint on the sphere by the nearest point) encloses the spherical shell sector
    /// V = 2π(1 − cos α)((R + d)³ − R³)/3; the discrete sum converges to it at second order.
    #[test]
    fn the_footprint_volume_over_a_sphere_converges_to_the_shell() {
        let (r, d, alpha) = (0.1f64, 0.01f64, 0.8f64);
        let exact =
            2.0 * std::f64::consts::PI * (1.0 - alpha.cos()) * ((r + d).powi(3) - r.powi(3)) / 3.0;
        let mut errors = Vec::new();
        for n in [8, 16, 32] {
            // A polar grid: rings k = 1..n at polar angle α·k/n, 4n nodes around, plus the pole.
            let around = 4 * n;
            let mut p = vec![V3::new(0.0, 0.0, r + d)];
            for k in 1..=n {
                let th = alpha * k as f64 / n as f64;
                for m in 0..around {
                    let ph = std::f64::consts::TAU * m as f64 / around as f64;
                    p.push(V3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * (r + d));
                }
            }
            let idx = |k: usize, m: usize| (1 + (k - 1) * around + m % around) as u32;
            let mut t = Vec::new();
            for m in 0..around {
                t.push([0, idx(1, m), idx(1, m + 1)]);
            }
            for k in 1..n {
                for m in 0..around {
                    t.push([idx(k, m), idx(k + 1, m), idx(k + 1, m + 1)]);
                    t.push([idx(k, m), idx(k + 1, m + 1), idx(k, m + 1)]);
                }
            }
            let foot: Vec<V3> = p.iter().map(|q| q.normalize() * r).collect();
            let v = footprint_volume(&p, &foot, &t);
            errors.push(((v - exact) / exact).abs());
        }
        eprintln!("sphere shell: relative errors {errors:?}");
        assert!(errors[2] < 2e-3, "{errors:?}");
        // Second order: each halving of the spacing divides the error by about four.
        assert!(
            errors[1] < 0.35 * errors[0] && errors[2] < 0.35 * errors[1],
            "{errors:?}"
        );
    }
}
