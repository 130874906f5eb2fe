//! A finer, different model standing in for the real objects (no camera here): a discretised
//! elastic rod of N ≥ 100 segments in the vertical plane, with its own mass distribution,
//! axial stiffness, bending stiffness and natural curvature varying along it, held at its two
//! ends (pinned) and at rest under gravity.
//!
//! Energy: `Σ_i EA_i (|d_i| − l_i)² / (2 l_i)` over segments and `Σ_k EI_k (ψ_k − ψ⁰_k)² / (2 l̄_k)`
//! over inner nodes, `ψ_k = 2 tan(α_k/2)` the discrete integrated curvature of Bergou et al.
//! (α_k the turning angle at node k, counter-clockwise positive), `l̄_k` the mean rest length of
//! its two segments; minus gravity's work on the lumped node masses. It differs from the
//! fitted string model in resolution (N segments against 8), in the bending law (tan against
//! linear in the angle, and EI/l̄ against b/φ), in mass (distributed against 1 g per particle)
//! and in everything varying along it; so a fit cannot be exact and the test is honest.

use nalgebra::DMatrix;

use crate::FitError;
use crate::statics::Chain;
use crate::string::{
    STANDARD_GRAVITY, V2, bend_forces, bend_jacobian, spring_forces, spring_jacobian, turning,
};

/// The rod.
#[derive(Clone, Debug, PartialEq)]
pub struct Rod {
    /// Rest length of each segment, m (N).
    pub rest: Vec<f64>,
    /// Axial stiffness EA of each segment, N (N).
    pub axial: Vec<f64>,
    /// Bending stiffness EI at each inner node, N·m² (N − 1).
    pub bending: Vec<f64>,
    /// Natural turning angle at each inner node, rad, counter-clockwise (N − 1).
    pub natural_turn: Vec<f64>,
    /// Mass of each node, kg (N + 1).
    pub mass: Vec<f64>,
    /// Gravity, m/s².
    pub gravity: V2,
}

/// What varies along a rod, as functions of the arc-length fraction u in [0, 1].
pub struct RodSpec<'a> {
    /// Rest length, m.
    pub length: f64,
    /// Segments (≥ 100).
    pub segments: usize,
    /// Mass per length, kg/m.
    pub mass_per_length: &'a dyn Fn(f64) -> f64,
    /// EA, N.
    pub axial: &'a dyn Fn(f64) -> f64,
    /// EI, N·m².
    pub bending: &'a dyn Fn(f64) -> f64,
    /// Natural curvature, rad/m (counter-clockwise positive).
    pub curvature: &'a dyn Fn(f64) -> f64,
}

impl Rod {
    /// The rod of `spec`: equal segments, each node's mass from the segments beside it, the
    /// natural turn at a node its curvature times the segment length.
    pub fn new(spec: &RodSpec) -> Result<Self, FitError> {
        let n = spec.segments;
        if n < 2 {
            return Err(FitError::invalid("segments", 0, n as f64, "at least 2"));
        }
        if !(spec.length.is_finite() && spec.length > 0.0) {
            return Err(FitError::invalid(
                "length",
                0,
                spec.length,
                "must be finite and > 0",
            ));
        }
        let h = spec.length / n as f64;
        let mid = |i: usize| (i as f64 + 0.5) / n as f64;
        let node = |k: usize| k as f64 / n as f64;
        let mut mass = vec![0.0; n + 1];
        for i in 0..n {
            let m = (spec.mass_per_length)(mid(i)) * h;
            mass[i] += 0.5 * m;
            mass[i + 1] += 0.5 * m;
        }
        let rod = Self {
            rest: vec![h; n],
            axial: (0..n).map(|i| (spec.axial)(mid(i))).collect(),
            bending: (1..n).map(|k| (spec.bending)(node(k))).collect(),
            natural_turn: (1..n).map(|k| (spec.curvature)(node(k)) * h).collect(),
            mass,
            gravity: V2::new(0.0, -STANDARD_GRAVITY),
        };
        rod.check()?;
        Ok(rod)
    }

    fn check(&self) -> Result<(), FitError> {
        for (field, v) in [
            ("axial", &self.axial),
            ("bending", &self.bending),
            ("mass", &self.mass),
        ] {
            if let Some(k) = v.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(FitError::invalid(field, k, v[k], "must be finite and > 0"));
            }
        }
        if let Some(k) = self
            .natural_turn
            .iter()
            .position(|a| !(a.is_finite() && a.abs() < 3.0))
        {
            return Err(FitError::invalid(
                "natural_turn",
                k,
                self.natural_turn[k],
                "must be finite and within ±3 rad",
            ));
        }
        Ok(())
    }

    /// Segments N.
    pub fn segments(&self) -> usize {
        self.rest.len()
    }

    /// Rest length, m.
    pub fn length(&self) -> f64 {
        self.rest.iter().sum()
    }

    /// EI/l̄ at inner node k (1 ≤ k ≤ N − 1).
    fn stiffness(&self, k: usize) -> f64 {
        2.0 * self.bending[k - 1] / (self.rest[k - 1] + self.rest[k])
    }
}

/// ψ = 2 tan(α/2), ψ' and ψ''.
fn psi(alpha: f64) -> (f64, f64, f64) {
    let t = (0.5 * alpha).tan();
    let d1 = 1.0 + t * t;
    (2.0 * t, d1, d1 * t)
}

impl Chain for Rod {
    fn particles(&self) -> usize {
        self.rest.len() + 1
    }

    fn validate(&self) -> Result<(), FitError> {
        self.check()
    }

    fn energy(&self, x: &[V2]) -> f64 {
        let mut e = 0.0;
        for i in 0..x.len() - 1 {
            let d = (x[i + 1] - x[i]).norm() - self.rest[i];
            e += 0.5 * self.axial[i] * d * d / self.rest[i];
        }
        for k in 1..x.len() - 1 {
            let a = turning(&(x[k] - x[k - 1]), &(x[k + 1] - x[k]));
            let t = psi(a).0 - psi(self.natural_turn[k - 1]).0;
            e += 0.5 * self.stiffness(k) * t * t;
        }
        e - x
            .iter()
            .zip(&self.mass)
            .map(|(q, m)| m * self.gravity.dot(q))
            .sum::<f64>()
    }

    fn forces(&self, x: &[V2], f: &mut [V2]) {
        for (q, m) in f.iter_mut().zip(&self.mass) {
            *q = self.gravity * *m;
        }
        for i in 0..x.len() - 1 {
            spring_forces(x, i, self.axial[i], self.rest[i], f);
        }
        for k in 1..x.len() - 1 {
            let (d1, _) = self.bend_derivatives(x, k);
            bend_forces(x, k, d1, f);
        }
    }

    fn force_jacobian(&self, x: &[V2]) -> DMatrix<f64> {
        let n = x.len();
        let mut j = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n - 1 {
            spring_jacobian(x, i, self.axial[i], self.rest[i], &mut j);
        }
        for k in 1..n - 1 {
            let (d1, d2) = self.bend_derivatives(x, k);
            bend_jacobian(x, k, d1, d2, &mut j);
        }
        j
    }
}

impl Rod {
    /// E'(α) and E''(α) of the bending energy `EI/l̄·(ψ − ψ⁰)²/2` at inner node k.
    fn bend_derivatives(&self, x: &[V2], k: usize) -> (f64, f64) {
        let (p, d1, d2) = psi(turning(&(x[k] - x[k - 1]), &(x[k + 1] - x[k])));
        let kk = self.stiffness(k);
        let diff = p - psi(self.natural_turn[k - 1]).0;
        (kk * diff * d1, kk * (d1 * d1 + diff * d2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::statics::{StaticOptions, equilibrium};
    use approx::assert_relative_eq;

    fn rod(segments: usize) -> Rod {
        Rod::new(&RodSpec {
            length: 0.3,
            segments,
            mass_per_length: &|u| 0.02 * (1.0 - 0.5 * u),
            axial: &|u| 50.0 * (1.0 + u),
            bending: &|u| 1e-4 * (1.0 - 0.8 * u),
            curvature: &|u| 3.0 * (u - 0.3),
        })
        .expect("rod")
    }

    /// The rod's forces are minus its energy's gradient and its Jacobian the forces' central
    /// differences (a curved shape of 12 segments).
    #[test]
    fn the_rods_jacobian_is_the_finite_differences() {
        let r = rod(12);
        let x: Vec<V2> = (0..13)
            .map(|k| {
                let a = 0.2 * k as f64;
                V2::new(a.sin(), 1.0 - a.cos()) * 0.12 + V2::new(0.0, 0.001 * (k % 3) as f64)
            })
            .collect();
        let mut f = vec![V2::zeros(); 13];
        r.forces(&x, &mut f);
        let j = r.force_jacobian(&x);
        let h = 1e-7;
        for c in 0..26 {
            let (mut a, mut b) = (x.clone(), x.clone());
            a[c / 2][c % 2] += h;
            b[c / 2][c % 2] -= h;
            assert_relative_eq!(
                -f[c / 2][c % 2],
                (r.energy(&a) - r.energy(&b)) / (2.0 * h),
                epsilon = 1e-6,
                max_relative = 1e-5
            );
            let (mut fa, mut fb) = (vec![V2::zeros(); 13], vec![V2::zeros(); 13]);
            r.forces(&a, &mut fa);
            r.forces(&b, &mut fb);
            for row in 0..26 {
                let fd = (fa[row / 2][row % 2] - fb[row / 2][row % 2]) / (2.0 * h);
                assert_relative_eq!(j[(row, c)], fd, epsilon = 1e-4, max_relative = 1e-5);
            }
        }
    }

    /// A uniform heavy rod with negligible bending stiffness, nearly inextensible, hung between
    /// two points at one height sags as the continuous catenary of its length (within 0.5 % at
    /// 120 segments).
    #[test]
    fn a_limp_rod_sags_as_the_catenary() {
        let (len, span) = (0.4, 0.3);
        let r = Rod::new(&RodSpec {
            length: len,
            segments: 120,
            mass_per_length: &|_| 0.02,
            axial: &|_| 1e3,
            bending: &|_| 1e-9,
            curvature: &|_| 0.0,
        })
        .expect("rod");
        let start: Vec<V2> = (0..=120)
            .map(|k| {
                let u = k as f64 / 120.0;
                V2::new(span * u, -0.12 * (std::f64::consts::PI * u).sin())
            })
            .collect();
        let eq = equilibrium(
            &r,
            &start,
            &StaticOptions {
                tolerance: 1e-9,
                ..StaticOptions::default()
            },
        )
        .expect("equilibrium");
        // Catenary y = a cosh(x/a) through the supports: length = 2a sinh(span/2a).
        let (mut lo, mut hi) = (0.01, 10.0);
        for _ in 0..200 {
            let a = 0.5 * (lo + hi);
            if 2.0 * a * (span / (2.0 * a)).sinh() > len {
                lo = a;
            } else {
                hi = a;
            }
        }
        let a = 0.5 * (lo + hi);
        let sag = a * ((span / (2.0 * a)).cosh() - 1.0);
        assert_relative_eq!(-eq.positions[60].y, sag, max_relative = 5e-3);
    }
}
