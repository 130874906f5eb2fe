//! The one-dimensional mass-spring model of a string-like object (Sudoh et al., (S1)–(S7);
//! `method.md` §6): I particles in a vertical plane, a spring between neighbours and a bending
//! spring at every inner particle.
//!
//! - Stretch (S1): on P_i from the spring to P_{i+1}, `S = s_i (|x_{i+1} − x_i| − l_i)/l_i · u`,
//!   u the unit vector from P_i to P_{i+1}; the reaction on P_{i+1}.
//! - Bending (S2): at an inner particle P_k, with θ_k the angle between its two segments (π when
//!   straight) and φ_k its natural bend, each neighbour is pushed perpendicular to its segment by
//!   `b_k (θ_k − φ_k)/(φ_k |segment|)` and P_k takes the reaction.
//!
//! **Sign and angle (a reading of the paper).** The paper prints (S2) with N "pointing outwards
//! from the bend angle"; read literally, a joint bent more than its natural bend (θ < φ) would
//! be pushed to bend further. Physically the force restores the natural bend, and so it does
//! here: the forces are minus the gradient of the energy `b_k (θ_k − φ_k)² / (2 φ_k)` whose
//! derivative with respect to θ is the paper's moment `b_k (θ_k − φ_k)/φ_k`, and a neighbour's
//! force has exactly the paper's size. θ_k is signed (measured on one side of the string, in
//! (0, 2π)) so that a natural bend φ_k ≠ π has a side: θ_k = π − α_k, α_k the turning angle from
//! segment k−1 to segment k, counter-clockwise positive. Likewise (S1) is minus the gradient of
//! `s_i (|d| − l_i)² / (2 l_i)`. The model is conservative, so a static shape is a stationary
//! point of its energy plus gravity's, and the force Jacobian is symmetric.
//!
//! Indices here are 0-based: particles 0..I, segment i joins particles i and i + 1 (I − 1
//! segments), joint k is particle k for k in 1..I−1 (I − 2 joints, stored at index k − 1).

use nalgebra::{DMatrix, Matrix2, Vector2};
use serde::{Deserialize, Serialize};

use crate::FitError;

/// A point or vector of the vertical plane, m (x horizontal, y up).
pub type V2 = Vector2<f64>;

/// Standard gravity, m/s².
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// The parameters of a string of I particles: per segment `s` and `l`, per inner particle `b`
/// and `φ`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StringParams {
    /// Spring coefficients s_i, N (I − 1).
    pub stretch: Vec<f64>,
    /// Natural lengths l_i, m (I − 1).
    pub length: Vec<f64>,
    /// Bending coefficients b_k of the inner particles, N·m, ≥ 0 (I − 2).
    pub bending: Vec<f64>,
    /// Natural bends φ_k of the inner particles, rad in (0, 2π) (π: straight) (I − 2).
    pub natural_bend: Vec<f64>,
}

impl StringParams {
    /// Particles I.
    pub fn particles(&self) -> usize {
        self.stretch.len() + 1
    }

    /// How many numbers the parameters are: 2(I − 1) + 2(I − 2).
    pub fn len(&self) -> usize {
        self.stretch.len() + self.length.len() + self.bending.len() + self.natural_bend.len()
    }

    /// Whether there are no parameters (never, for a valid string).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The parameters as one vector: s, l, b, φ.
    pub fn to_vec(&self) -> Vec<f64> {
        [
            &self.stretch[..],
            &self.length[..],
            &self.bending[..],
            &self.natural_bend[..],
        ]
        .concat()
    }

    /// The parameters of I particles from one vector laid out as [`StringParams::to_vec`].
    pub fn from_slice(particles: usize, v: &[f64]) -> Self {
        let (n, m) = (particles - 1, particles - 2);
        Self {
            stretch: v[..n].to_vec(),
            length: v[n..2 * n].to_vec(),
            bending: v[2 * n..2 * n + m].to_vec(),
            natural_bend: v[2 * n + m..2 * n + 2 * m].to_vec(),
        }
    }

    /// Check the sizes and ranges: at least three particles, every value finite, s, l > 0,
    /// b ≥ 0, φ in (0, 2π).
    pub fn validate(&self) -> Result<(), FitError> {
        let i = self.particles();
        if i < 3 {
            return Err(FitError::invalid(
                "stretch",
                0,
                i as f64,
                "a string needs at least 3 particles",
            ));
        }
        for (field, v, n) in [
            ("length", &self.length, i - 1),
            ("bending", &self.bending, i - 2),
            ("natural_bend", &self.natural_bend, i - 2),
        ] {
            if v.len() != n {
                return Err(FitError::invalid(
                    field,
                    v.len(),
                    v.len() as f64,
                    format!("{} values for {i} particles, expected {n}", v.len()),
                ));
            }
        }
        for (field, v) in [("stretch", &self.stretch), ("length", &self.length)] {
            if let Some(k) = v.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(FitError::invalid(field, k, v[k], "must be finite and > 0"));
            }
        }
        // No bending stiffness at a joint is a chain's: allowed.
        if let Some(k) = self
            .bending
            .iter()
            .position(|x| !(x.is_finite() && *x >= 0.0))
        {
            return Err(FitError::invalid(
                "bending",
                k,
                self.bending[k],
                "must be finite and ≥ 0",
            ));
        }
        if let Some(k) = self
            .natural_bend
            .iter()
            .position(|x| !(*x > 0.0 && *x < std::f64::consts::TAU))
        {
            return Err(FitError::invalid(
                "natural_bend",
                k,
                self.natural_bend[k],
                "must lie in (0, 2π)",
            ));
        }
        Ok(())
    }
}

/// The string model: its parameters, the mass of every particle and gravity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StringModel {
    /// s, l, b, φ.
    pub params: StringParams,
    /// Mass of each particle, kg (the paper: 1 g).
    pub mass: f64,
    /// Gravity, m/s² (default (0, −9.80665)).
    pub gravity: V2,
}

/// ∂(angle of v)/∂v = perp(v)/|v|², perp(v) = (−v_y, v_x).
pub(crate) fn angle_gradient(v: &V2) -> V2 {
    V2::new(-v.y, v.x) / v.norm_squared()
}

/// ∂²(angle of v)/∂v² (symmetric).
pub(crate) fn angle_hessian(v: &V2) -> Matrix2<f64> {
    let n2 = v.norm_squared();
    let (x, y) = (v.x, v.y);
    Matrix2::new(2.0 * x * y, y * y - x * x, y * y - x * x, -2.0 * x * y) / (n2 * n2)
}

/// The signed turning angle from `e1` to `e2`, in (−π, π].
pub(crate) fn turning(e1: &V2, e2: &V2) -> f64 {
    (e1.x * e2.y - e1.y * e2.x).atan2(e1.dot(e2))
}

/// A spring of stiffness `s` (force at 100 % strain) and rest length `l` between particles
/// `i` and `i + 1`: its force (S1) added to `f`.
pub(crate) fn spring_forces(x: &[V2], i: usize, s: f64, l: f64, f: &mut [V2]) {
    let d = x[i + 1] - x[i];
    let len = d.norm();
    let force = s * (len - l) / l * (d / len);
    f[i] += force;
    f[i + 1] -= force;
}

/// The same spring's ∂F/∂x added to `j` (2I × 2I).
pub(crate) fn spring_jacobian(x: &[V2], i: usize, s: f64, l: f64, j: &mut DMatrix<f64>) {
    let d = x[i + 1] - x[i];
    let len = d.norm();
    let u = d / len;
    let uu = u * u.transpose();
    // F_i = S(d), F_{i+1} = −S(d), d = x_{i+1} − x_i, ∂S/∂d = k.
    let k = (uu + (Matrix2::identity() - uu) * ((len - l) / len)) * (s / l);
    for (a, b, m) in [(i, i + 1, k), (i, i, -k), (i + 1, i + 1, -k), (i + 1, i, k)] {
        let mut v = j.fixed_view_mut::<2, 2>(2 * a, 2 * b);
        v += m;
    }
}

/// ∂α/∂x over particles (k − 1, k, k + 1) of the turning angle α at inner particle k
/// (α = angle(e2) − angle(e1)).
fn turning_gradient(x: &[V2], k: usize) -> [V2; 3] {
    let (g1, g2) = (
        angle_gradient(&(x[k] - x[k - 1])),
        angle_gradient(&(x[k + 1] - x[k])),
    );
    [g1, -(g1 + g2), g2]
}

/// A bending energy E(α) at inner particle k, given its derivative `d1` = E'(α): its forces
/// −E'·∂α/∂x added to `f`.
pub(crate) fn bend_forces(x: &[V2], k: usize, d1: f64, f: &mut [V2]) {
    for (a, g) in turning_gradient(x, k).iter().enumerate() {
        f[k - 1 + a] -= g * d1;
    }
}

/// The same bending energy's ∂F/∂x, −(E''·∂α/∂x ∂α/∂xᵀ + E'·∂²α/∂x²), added to `j`;
/// `d2` = E''(α).
pub(crate) fn bend_jacobian(x: &[V2], k: usize, d1: f64, d2: f64, j: &mut DMatrix<f64>) {
    let (e1, e2) = (x[k] - x[k - 1], x[k + 1] - x[k]);
    let g = turning_gradient(x, k);
    // ∂e1/∂x: (−1, 1, 0); ∂e2/∂x: (0, −1, 1).
    let (t1, t2) = ([-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]);
    let (h1, h2) = (angle_hessian(&e1), angle_hessian(&e2));
    for a in 0..3 {
        for b in 0..3 {
            let hess = h2 * (t2[a] * t2[b]) - h1 * (t1[a] * t1[b]);
            let m = -(g[a] * g[b].transpose() * d2 + hess * d1);
            let mut v = j.fixed_view_mut::<2, 2>(2 * (k - 1 + a), 2 * (k - 1 + b));
            v += m;
        }
    }
}

impl StringModel {
    /// The model with the paper's particle mass (1 g) and standard gravity.
    pub fn new(params: StringParams) -> Self {
        Self {
            params,
            mass: 1e-3,
            gravity: V2::new(0.0, -STANDARD_GRAVITY),
        }
    }

    /// Particles I.
    pub fn particles(&self) -> usize {
        self.params.particles()
    }

    /// The bend angle θ_k of inner particle `k` (1 ≤ k ≤ I − 2) in shape `x`, rad in (0, 2π).
    pub fn bend_angle(x: &[V2], k: usize) -> f64 {
        std::f64::consts::PI - turning(&(x[k] - x[k - 1]), &(x[k + 1] - x[k]))
    }

    /// The potential energy of shape `x`: springs, bending springs and gravity, J.
    pub fn energy(&self, x: &[V2]) -> f64 {
        let p = &self.params;
        let mut e = 0.0;
        for i in 0..x.len() - 1 {
            let d = (x[i + 1] - x[i]).norm() - p.length[i];
            e += 0.5 * p.stretch[i] * d * d / p.length[i];
        }
        for k in 1..x.len() - 1 {
            let (b, phi) = (p.bending[k - 1], p.natural_bend[k - 1]);
            let t = Self::bend_angle(x, k) - phi;
            e += 0.5 * b * t * t / phi;
        }
        e - x
            .iter()
            .map(|q| self.mass * self.gravity.dot(q))
            .sum::<f64>()
    }

    /// The force on every particle of shape `x` (S3) at rest — springs, bending and gravity,
    /// without the holding forces f° of the ends — into `f`.
    pub fn forces(&self, x: &[V2], f: &mut [V2]) {
        let p = &self.params;
        f.iter_mut().for_each(|q| *q = self.gravity * self.mass);
        for i in 0..x.len() - 1 {
            spring_forces(x, i, p.stretch[i], p.length[i], f);
        }
        for k in 1..x.len() - 1 {
            // E = b(θ − φ)²/(2φ), θ = π − α: E'(α) = −b(θ − φ)/φ.
            let (b, phi) = (p.bending[k - 1], p.natural_bend[k - 1]);
            let theta = Self::bend_angle(x, k);
            bend_forces(x, k, -b * (theta - phi) / phi, f);
        }
    }

    /// ∂F/∂x of [`StringModel::forces`]: a symmetric 2I × 2I matrix (minus the energy's
    /// Hessian), particle i's x and y at rows and columns 2i and 2i + 1.
    pub fn force_jacobian(&self, x: &[V2]) -> DMatrix<f64> {
        let n = x.len();
        let p = &self.params;
        let mut j = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n - 1 {
            spring_jacobian(x, i, p.stretch[i], p.length[i], &mut j);
        }
        for k in 1..n - 1 {
            let (b, phi) = (p.bending[k - 1], p.natural_bend[k - 1]);
            let theta = Self::bend_angle(x, k);
            bend_jacobian(x, k, -b * (theta - phi) / phi, b / phi, &mut j);
        }
        j
    }

    /// ∂F/∂(s, l, b, φ) of [`StringModel::forces`]: 2I rows, one column per parameter in the
    /// order of [`StringParams::to_vec`].
    pub fn force_parameter_jacobian(&self, x: &[V2]) -> DMatrix<f64> {
        let n = x.len();
        let p = &self.params;
        let mut j = DMatrix::zeros(2 * n, p.len());
        let mut put = |row: usize, col: usize, v: V2| {
            j[(2 * row, col)] += v.x;
            j[(2 * row + 1, col)] += v.y;
        };
        let (cs, cl, cb, cphi) = (0, n - 1, 2 * (n - 1), 2 * (n - 1) + (n - 2));
        for i in 0..n - 1 {
            let d = x[i + 1] - x[i];
            let len = d.norm();
            let u = d / len;
            let (s, l) = (p.stretch[i], p.length[i]);
            let ds = u * ((len - l) / l);
            let dl = u * (-s * len / (l * l));
            put(i, cs + i, ds);
            put(i + 1, cs + i, -ds);
            put(i, cl + i, dl);
            put(i + 1, cl + i, -dl);
        }
        for k in 1..n - 1 {
            let (e1, e2) = (x[k] - x[k - 1], x[k + 1] - x[k]);
            let (b, phi) = (p.bending[k - 1], p.natural_bend[k - 1]);
            let theta = std::f64::consts::PI - turning(&e1, &e2);
            let (g1, g2) = (angle_gradient(&e1), angle_gradient(&e2));
            // c = b(θ − φ)/φ: ∂c/∂b = (θ − φ)/φ, ∂c/∂φ = −bθ/φ².
            for (col, dc) in [
                (cb + k - 1, (theta - phi) / phi),
                (cphi + k - 1, -b * theta / (phi * phi)),
            ] {
                put(k - 1, col, g1 * dc);
                put(k, col, -(g1 + g2) * dc);
                put(k + 1, col, g2 * dc);
            }
        }
        j
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn model(i: usize, seed: &[f64]) -> StringModel {
        let at = |k: usize| seed[k % seed.len()];
        StringModel::new(StringParams {
            stretch: (0..i - 1).map(|k| 0.5 + at(k)).collect(),
            length: (0..i - 1).map(|k| 0.04 + 0.02 * at(k + 3)).collect(),
            bending: (0..i - 2).map(|k| 0.01 + 0.05 * at(k + 5)).collect(),
            natural_bend: (0..i - 2).map(|k| 2.4 + 1.5 * at(k + 7)).collect(),
        })
    }

    fn shape(i: usize, seed: &[f64]) -> Vec<V2> {
        let mut x = vec![V2::zeros()];
        let mut a: f64 = -0.3;
        for k in 1..i {
            a += 0.8 * (seed[k % seed.len()] - 0.5);
            let l = 0.03 + 0.03 * seed[(k + 2) % seed.len()];
            x.push(x[k - 1] + V2::new(a.cos(), a.sin()) * l);
        }
        x
    }

    /// Central differences of `f` (a function of all 2I coordinates) at `x`.
    fn numeric<Fv: Fn(&[V2]) -> Vec<f64>>(x: &[V2], f: Fv) -> DMatrix<f64> {
        let h = 1e-7;
        let rows = f(x).len();
        let mut j = DMatrix::zeros(rows, 2 * x.len());
        for c in 0..2 * x.len() {
            let (mut a, mut b) = (x.to_vec(), x.to_vec());
            a[c / 2][c % 2] += h;
            b[c / 2][c % 2] -= h;
            let (fa, fb) = (f(&a), f(&b));
            for r in 0..rows {
                j[(r, c)] = (fa[r] - fb[r]) / (2.0 * h);
            }
        }
        j
    }

    fn flat(v: &[V2]) -> Vec<f64> {
        v.iter().flat_map(|q| [q.x, q.y]).collect()
    }

    fn forces_of(m: &StringModel, x: &[V2]) -> Vec<f64> {
        let mut f = vec![V2::zeros(); x.len()];
        m.forces(x, &mut f);
        flat(&f)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The forces are minus the energy's gradient, and both Jacobians equal central
        /// differences (within 1e-5 of the largest entry): any shape of 3 to 12 particles
        /// turning by less than ±0.4 rad per joint, any parameters in the ranges above.
        #[test]
        fn the_jacobians_are_the_finite_differences(
            i in 3usize..12,
            seed in proptest::collection::vec(0.0f64..1.0, 16),
        ) {
            let m = model(i, &seed);
            let x = shape(i, &seed);
            let f = forces_of(&m, &x);
            let grad = numeric(&x, |y| vec![m.energy(y)]);
            for c in 0..2 * i {
                prop_assert!((f[c] + grad[(0, c)]).abs() < 1e-6 * (1.0 + f[c].abs()), "{c}: {} vs {}", f[c], -grad[(0, c)]);
            }
            let analytic = m.force_jacobian(&x);
            let fd = numeric(&x, |y| forces_of(&m, y));
            let scale = fd.amax().max(1.0);
            prop_assert!((&analytic - &fd).amax() < 1e-5 * scale, "{}", (&analytic - &fd).amax());
            prop_assert!((&analytic - analytic.transpose()).amax() < 1e-9 * scale);
            let analytic = m.force_parameter_jacobian(&x);
            let p0 = m.params.to_vec();
            let mut fd = DMatrix::zeros(2 * i, p0.len());
            for c in 0..p0.len() {
                let h = 1e-7 * p0[c].abs().max(1e-3);
                let (mut a, mut b) = (p0.clone(), p0.clone());
                a[c] += h;
                b[c] -= h;
                let fa = forces_of(&StringModel { params: StringParams::from_slice(i, &a), ..m.clone() }, &x);
                let fb = forces_of(&StringModel { params: StringParams::from_slice(i, &b), ..m.clone() }, &x);
                for r in 0..2 * i {
                    fd[(r, c)] = (fa[r] - fb[r]) / (2.0 * h);
                }
            }
            let scale = fd.amax().max(1.0);
            prop_assert!((&analytic - &fd).amax() < 1e-5 * scale, "{}", (&analytic - &fd).amax());
        }
    }

    /// A straight string at its natural lengths with φ = π feels only gravity; its bend angles
    /// are π. A right-angle turn counter-clockwise has θ = π/2.
    #[test]
    fn straight_and_right_angle() {
        let x: Vec<V2> = (0..5).map(|k| V2::new(0.05 * k as f64, 0.0)).collect();
        let m = StringModel::new(StringParams {
            stretch: vec![1.0; 4],
            length: vec![0.05; 4],
            bending: vec![0.1; 3],
            natural_bend: vec![std::f64::consts::PI; 3],
        });
        let mut f = vec![V2::zeros(); 5];
        m.forces(&x, &mut f);
        for q in &f {
            assert_relative_eq!(q.x, 0.0, epsilon = 1e-15);
            assert_relative_eq!(q.y, -1e-3 * STANDARD_GRAVITY, epsilon = 1e-15);
        }
        let y = [V2::new(0.0, 0.0), V2::new(1.0, 0.0), V2::new(1.0, 1.0)];
        assert_relative_eq!(
            StringModel::bend_angle(&y, 1),
            std::f64::consts::FRAC_PI_2,
            epsilon = 1e-15
        );
    }

    /// The bending force restores the natural bend: a joint bent to θ = π/2 with φ = π pushes
    /// its neighbours so as to open the angle (on the outer neighbour along the outward normal),
    /// with the paper's size b(θ − φ)/(φ|segment|), and the three forces sum to zero.
    #[test]
    fn bending_restores_with_the_papers_size() {
        let y = [V2::new(0.0, 0.0), V2::new(0.1, 0.0), V2::new(0.1, 0.1)];
        let b = 0.2;
        let m = StringModel {
            gravity: V2::zeros(),
            ..StringModel::new(StringParams {
                stretch: vec![1.0; 2],
                length: vec![0.1; 2],
                bending: vec![b],
                natural_bend: vec![std::f64::consts::PI],
            })
        };
        let mut f = vec![V2::zeros(); 3];
        m.forces(&y, &mut f);
        let size = b * (std::f64::consts::FRAC_PI_2 - std::f64::consts::PI).abs()
            / (std::f64::consts::PI * 0.1);
        // The first particle moves down (away from the third), the third to the right.
        assert_relative_eq!(f[0], V2::new(0.0, -size), epsilon = 1e-12);
        assert_relative_eq!(f[2], V2::new(size, 0.0), epsilon = 1e-12);
        assert_relative_eq!(f[0] + f[1] + f[2], V2::zeros(), epsilon = 1e-12);
    }
}
