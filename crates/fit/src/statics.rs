//! The string's static shape for given end positions: the paper runs its dynamics (S3)–(S7) to
//! rest; here the force balance of the inner particles is solved directly (the rest state of
//! the damped dynamics is a stable equilibrium, a local minimum of the energy): Newton's method
//! on the energy with a Levenberg shift where the Hessian is not positive definite, and a
//! backtracking line search, from a start shape.

use nalgebra::{DMatrix, DVector};

use crate::FitError;
use crate::string::{StringModel, V2};

/// A planar chain of particles held at both ends whose inner particles feel conservative forces:
/// the string model, and the finer rod that stands in for a real object.
pub trait Chain {
    /// Particles.
    fn particles(&self) -> usize;
    /// Check the chain's own values.
    fn validate(&self) -> Result<(), FitError>;
    /// Potential energy of shape `x`, J.
    fn energy(&self, x: &[V2]) -> f64;
    /// Force on every particle (minus the energy's gradient), N.
    fn forces(&self, x: &[V2], f: &mut [V2]);
    /// ∂F/∂x, 2I × 2I.
    fn force_jacobian(&self, x: &[V2]) -> DMatrix<f64>;
}

impl Chain for StringModel {
    fn particles(&self) -> usize {
        StringModel::particles(self)
    }
    fn validate(&self) -> Result<(), FitError> {
        self.params.validate()
    }
    fn energy(&self, x: &[V2]) -> f64 {
        StringModel::energy(self, x)
    }
    fn forces(&self, x: &[V2], f: &mut [V2]) {
        StringModel::forces(self, x, f);
    }
    fn force_jacobian(&self, x: &[V2]) -> DMatrix<f64> {
        StringModel::force_jacobian(self, x)
    }
}

/// Settings of the static solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticOptions {
    /// Converged when the largest force on an inner particle is below this, N. Default 1e-10.
    pub tolerance: f64,
    /// Newton iterations at most. Default 200.
    pub max_iterations: usize,
}

impl Default for StaticOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 200,
        }
    }
}

/// A static shape and how it was found.
#[derive(Clone, Debug, PartialEq)]
pub struct Equilibrium {
    /// The particles' positions, m.
    pub positions: Vec<V2>,
    /// Newton iterations made.
    pub iterations: usize,
    /// The largest force left on an inner particle, N.
    pub residual: f64,
}

fn inner_forces<C: Chain + ?Sized>(model: &C, x: &[V2]) -> (DVector<f64>, f64, usize) {
    let mut f = vec![V2::zeros(); x.len()];
    model.forces(x, &mut f);
    let n = x.len() - 2;
    let mut g = DVector::zeros(2 * n);
    let (mut worst, mut at) = (0.0, 1);
    for k in 0..n {
        g[2 * k] = f[k + 1].x;
        g[2 * k + 1] = f[k + 1].y;
        let m = f[k + 1].norm();
        if m > worst || m.is_nan() {
            worst = m;
            at = k + 1;
        }
    }
    (g, worst, at)
}

impl StringModel {
    /// The static shape with its ends at `start`'s first and last positions ([`equilibrium`]).
    pub fn equilibrium(
        &self,
        start: &[V2],
        options: &StaticOptions,
    ) -> Result<Equilibrium, FitError> {
        equilibrium(self, start, options)
    }
}

/// The static shape of `chain` with its ends at `start`'s first and last positions, found from
/// `start` (validated: finite, the chain's particle count, no two neighbours at one point).
pub fn equilibrium<C: Chain + ?Sized>(
    chain: &C,
    start: &[V2],
    options: &StaticOptions,
) -> Result<Equilibrium, FitError> {
    chain.validate()?;
    let i = chain.particles();
    if start.len() != i {
        return Err(FitError::invalid(
            "start",
            start.len(),
            start.len() as f64,
            format!("{} positions for a string of {i} particles", start.len()),
        ));
    }
    if let Some(k) = start
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(FitError::invalid(
            "start",
            k,
            f64::NAN,
            "position not finite",
        ));
    }
    if let Some(k) = (0..i - 1).find(|&k| (start[k + 1] - start[k]).norm() == 0.0) {
        return Err(FitError::invalid(
            "start",
            k + 1,
            0.0,
            "at the same point as the particle before it",
        ));
    }
    let n = i - 2;
    let mut x = start.to_vec();
    let mut energy = chain.energy(&x);
    let mut shift = 0.0;
    for iteration in 0..options.max_iterations {
        let (g, worst, at) = inner_forces(chain, &x);
        if worst < options.tolerance {
            return Ok(Equilibrium {
                positions: x,
                iterations: iteration,
                residual: worst,
            });
        }
        if !worst.is_finite() {
            return Err(FitError::NoEquilibrium {
                iterations: iteration,
                residual: worst,
                particle: at,
            });
        }
        let j = chain.force_jacobian(&x);
        let h: DMatrix<f64> = -j.view((2, 2), (2 * n, 2 * n));
        let scale = h.diagonal().amax().max(1e-12);
        // Newton step on the energy (gradient −g), shifted until the Hessian is positive
        // definite and the energy falls.
        let mut accepted = false;
        for _ in 0..60 {
            let shifted = &h + DMatrix::identity(2 * n, 2 * n) * (shift * scale);
            if let Some(ch) = shifted.cholesky() {
                let step = ch.solve(&g);
                let mut t = 1.0;
                for _ in 0..30 {
                    let mut y = x.clone();
                    for k in 0..n {
                        y[k + 1] += V2::new(step[2 * k], step[2 * k + 1]) * t;
                    }
                    let e = chain.energy(&y);
                    // Sufficient decrease of the energy; near the solution, where the
                    // decrease is below the energy's rounding, a smaller force instead.
                    let decrease = e <= energy + 1e-4 * t * (-g.dot(&step));
                    let rounding = (e - energy).abs() <= 1e-12 * energy.abs().max(1e-300)
                        && inner_forces(chain, &y).1 < worst;
                    if e.is_finite() && (decrease || rounding) {
                        x = y;
                        energy = e;
                        accepted = true;
                        break;
                    }
                    t *= 0.5;
                }
            }
            if accepted {
                shift *= 0.1;
                break;
            }
            shift = if shift == 0.0 { 1e-8 } else { shift * 10.0 };
        }
        if !accepted {
            // The energy no longer falls: converged as far as rounding allows.
            let (_, worst, at) = inner_forces(chain, &x);
            if worst < options.tolerance * 1e3 {
                return Ok(Equilibrium {
                    positions: x,
                    iterations: iteration + 1,
                    residual: worst,
                });
            }
            return Err(FitError::NoEquilibrium {
                iterations: iteration + 1,
                residual: worst,
                particle: at,
            });
        }
    }
    let (_, worst, at) = inner_forces(chain, &x);
    Err(FitError::NoEquilibrium {
        iterations: options.max_iterations,
        residual: worst,
        particle: at,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::string::{STANDARD_GRAVITY, StringParams};
    use approx::assert_relative_eq;

    /// A chain-like string (no bending stiffness to speak of, stiff springs) hung between two
    /// points at the same height settles on the catenary: its sag matches the inextensible
    /// discrete chain's within 0.1 %. Reference: a chain of n equal links of weight w each
    /// between supports, solved here by shooting on the horizontal tension (each link's slope
    /// from the vertical force it carries).
    #[test]
    fn a_chain_hangs_as_the_discrete_catenary() {
        let (i, link) = (21usize, 0.02);
        let model = StringModel::new(StringParams {
            stretch: vec![1e4; i - 1],
            length: vec![link; i - 1],
            bending: vec![1e-9; i - 2],
            natural_bend: vec![std::f64::consts::PI; i - 2],
        });
        let span = 0.3;
        let start: Vec<V2> = (0..i)
            .map(|k| {
                let u = k as f64 / (i - 1) as f64;
                V2::new(span * u, -0.1 * (std::f64::consts::PI * u).sin())
            })
            .collect();
        let eq = model
            .equilibrium(&start, &StaticOptions::default())
            .expect("equilibrium");
        let sag = -eq.positions[i / 2].y;
        // Discrete chain: masses at the inner joints, links inextensible; the vertical force
        // in link k (from the left) is V_k = w·((i − 2)/2 − k) by symmetry, its slope V_k/H.
        let w = 1e-3 * STANDARD_GRAVITY;
        let width = |h: f64| -> (f64, f64) {
            let (mut x, mut y) = (0.0, 0.0);
            for k in 0..i - 1 {
                let v = w * ((i - 2) as f64 / 2.0 - k as f64);
                let n = (h * h + v * v).sqrt();
                x += link * h / n;
                y -= link * v / n;
            }
            (x, y)
        };
        let (mut lo, mut hi) = (1e-6, 10.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if width(mid).0 < span {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let h = 0.5 * (lo + hi);
        let mut y = 0.0;
        for k in 0..(i - 1) / 2 {
            let v = w * ((i - 2) as f64 / 2.0 - k as f64);
            y -= link * v / (h * h + v * v).sqrt();
        }
        assert_relative_eq!(sag, -y, max_relative = 1e-3);
        assert!(eq.residual < 1e-10);
    }
}
