//! Identifying the string's parameters from J observed static shapes (Sudoh et al. §4;
//! `method.md` §6).
//!
//! Unknowns: the model's inner node positions x_i^j of every shape (the ends sit on the
//! observed ends) and the parameters s, l, b, φ. Residuals, for every shape j and inner
//! particle i: `√c_s (x_i^j − y_i^j)` (the node on its marker, (8)) and `√c_f F_i^j` (the node in
//! equilibrium, (9)), two components each, so that their squares sum to
//! `E_all = Σ_j c_s E_s^j + c_f E_f^j` ((10)–(11)). Minimised by Levenberg–Marquardt (the
//! `levenberg-marquardt` crate, MINPACK's algorithm) with the analytic Jacobian of
//! [`StringModel::force_jacobian`] and [`StringModel::force_parameter_jacobian`].
//!
//! The paper's residuals are the norms `√c_s |x − y|` and `√c_f |F|`; their components give the
//! same sum of squares and a Jacobian that stays defined where a residual is zero.

use std::cell::Cell;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::storage::Owned;
use nalgebra::{DMatrix, DVector, Dyn};
use serde::{Deserialize, Serialize};

use crate::FitError;
use crate::string::{STANDARD_GRAVITY, StringModel, StringParams, V2};

/// The Levenberg–Marquardt implementation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Method {
    /// On the problem's block structure (Schur complement on the parameters), Marquardt
    /// damping, Nielsen's update: an iteration costs O(J) small solves.
    Schur,
    /// The `levenberg-marquardt` crate (MINPACK: dense pivoted QR of the whole Jacobian, trust
    /// region): an iteration costs O(J³) at J shapes (13 ms at J = 10, `docs/fit.md`).
    Minpack,
}

/// One gram-force, N.
pub const GRAM_FORCE: f64 = 9.80665e-3;

/// Settings of the identification (defaults: the paper's, with the units and iteration limit
/// discussed at each field).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FitOptions {
    /// Weight of the shape error c_s, 1/m². Default 100.
    pub c_s: f64,
    /// Weight of the force balance c_f, 1/N². Default 10 per gram-force squared,
    /// 10/(9.80665e-3)² = 1.04e5 N⁻² (the paper gives c_s = 100 and c_f = 10 without units; read
    /// as per m² and per N² the balance is so weak that fitted shapes are far from equilibrium —
    /// `docs/fit.md`).
    pub c_f: f64,
    /// Mass of each particle, kg. Default 1 g.
    pub mass: f64,
    /// Gravity, m/s². Default (0, −9.80665).
    pub gravity: [f64; 2],
    /// `Minpack` only: it gives up after `patience·(unknowns + 1)` residual evaluations.
    /// Default 100 (the crate's).
    pub patience: usize,
    /// The minimiser. Default `Schur`.
    pub method: Method,
    /// Iterations (Jacobian evaluations) at most; none: until a convergence criterion (or the
    /// patience). Default 1 000 (the paper stopped MATLAB's `lsqnonlin` at 50; these problems
    /// are ill-conditioned and converge slowly, `docs/fit.md`).
    pub max_iterations: Option<usize>,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            c_s: 100.0,
            c_f: 10.0 / (GRAM_FORCE * GRAM_FORCE),
            mass: 1e-3,
            gravity: [0.0, -STANDARD_GRAVITY],
            patience: 100,
            method: Method::Schur,
            max_iterations: Some(1000),
        }
    }
}

/// The outcome of an identification.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The model with the parameters found.
    pub model: StringModel,
    /// The model's node positions for every observed shape, m.
    pub positions: Vec<Vec<V2>>,
    /// E_all at the initial values.
    pub initial_cost: f64,
    /// E_all at the end.
    pub cost: f64,
    /// Levenberg–Marquardt iterations (Jacobian evaluations).
    pub iterations: usize,
    /// Residual evaluations.
    pub evaluations: usize,
    /// Why it stopped (the crate's termination reason).
    pub termination: String,
    /// Whether it stopped on a convergence criterion (not on the iteration limit, the patience
    /// or a numerical failure).
    pub converged: bool,
}

/// The paper's initial values: l and φ from the first shape (its marker distances and bend
/// angles), every s and b given (Table 2 gives them per material).
pub fn initial_guess(first: &[V2], stretch: f64, bending: f64) -> Result<StringParams, FitError> {
    check_shape(first, 0)?;
    let i = first.len();
    let params = StringParams {
        stretch: vec![stretch; i - 1],
        length: (0..i - 1)
            .map(|k| (first[k + 1] - first[k]).norm())
            .collect(),
        bending: vec![bending; i - 2],
        natural_bend: (1..i - 1)
            .map(|k| StringModel::bend_angle(first, k))
            .collect(),
    };
    params.validate()?;
    Ok(params)
}

fn check_shape(shape: &[V2], j: usize) -> Result<(), FitError> {
    if shape.len() < 3 {
        return Err(FitError::invalid(
            "shapes",
            j,
            shape.len() as f64,
            format!("{} markers; a string needs at least 3", shape.len()),
        ));
    }
    if let Some(k) = shape
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(FitError::invalid(
            "shapes",
            j,
            f64::NAN,
            format!("marker {k} is not finite"),
        ));
    }
    if let Some(k) = (0..shape.len() - 1).find(|&k| shape[k + 1] == shape[k]) {
        return Err(FitError::invalid(
            "shapes",
            j,
            k as f64 + 1.0,
            format!("markers {k} and {} coincide", k + 1),
        ));
    }
    Ok(())
}

/// The parameters as Levenberg–Marquardt sees them: ln s, ln l, ln b, and φ through a logistic
/// onto (0, 2π), so that no step makes a stiffness or a length negative or a natural bend leave
/// its range (the paper's plain values have no such guard; `docs/fit.md`).
fn encode(p: &StringParams) -> Vec<f64> {
    let logit = |phi: f64| {
        let u = phi / std::f64::consts::TAU;
        (u / (1.0 - u)).ln()
    };
    p.stretch
        .iter()
        .chain(&p.length)
        .chain(&p.bending)
        .map(|v| v.ln())
        .chain(p.natural_bend.iter().map(|&v| logit(v)))
        .collect()
}

/// The inverse of [`encode`], and the derivative of each parameter by its encoded value.
fn decode(particles: usize, q: &[f64]) -> (StringParams, Vec<f64>) {
    let m = 3 * particles - 5;
    let mut v: Vec<f64> = q[..m].iter().map(|x| x.exp()).collect();
    let mut d = v.clone();
    for x in &q[m..] {
        // Kept off 0 and 2π by a hair where the logistic rounds onto them.
        let phi = (std::f64::consts::TAU / (1.0 + (-x).exp()))
            .clamp(1e-12, std::f64::consts::TAU * (1.0 - 1e-15));
        v.push(phi);
        d.push(phi * (1.0 - phi / std::f64::consts::TAU));
    }
    (StringParams::from_slice(particles, &v), d)
}

struct Problem<'a> {
    shapes: &'a [Vec<V2>],
    model: StringModel,
    c_s: f64,
    c_f: f64,
    /// Inner positions of every shape, then the parameters.
    p: DVector<f64>,
    jacobians: Cell<usize>,
    max_iterations: Option<usize>,
}

impl Problem<'_> {
    fn particles(&self) -> usize {
        self.shapes[0].len()
    }

    fn inner(&self) -> usize {
        self.particles() - 2
    }

    /// Shape j's positions: the markers' ends with the unknowns between them.
    fn positions(&self, j: usize) -> Vec<V2> {
        let (n, y) = (self.inner(), &self.shapes[j]);
        let mut x = y.clone();
        for k in 0..n {
            let at = 2 * (j * n + k);
            x[k + 1] = V2::new(self.p[at], self.p[at + 1]);
        }
        x
    }
}

impl Problem<'_> {
    /// Shape j's residuals r_j (per inner node: two position rows, two force rows), their
    /// Jacobian by the shape's own inner positions A_j and by the encoded parameters B_j.
    fn blocks(
        &self,
        j: usize,
        model: &StringModel,
        dq: &[f64],
        with_jacobian: bool,
    ) -> (DVector<f64>, DMatrix<f64>, DMatrix<f64>) {
        let n = self.inner();
        let (ws, wf) = (self.c_s.sqrt(), self.c_f.sqrt());
        let x = self.positions(j);
        let mut f = vec![V2::zeros(); self.particles()];
        model.forces(&x, &mut f);
        let mut r = DVector::zeros(4 * n);
        for k in 0..n {
            let d = (x[k + 1] - self.shapes[j][k + 1]) * ws;
            let g = f[k + 1] * wf;
            r[4 * k] = d.x;
            r[4 * k + 1] = d.y;
            r[4 * k + 2] = g.x;
            r[4 * k + 3] = g.y;
        }
        if !with_jacobian {
            return (r, DMatrix::zeros(0, 0), DMatrix::zeros(0, 0));
        }
        let dx = model.force_jacobian(&x);
        let dp = model.force_parameter_jacobian(&x);
        let mut a = DMatrix::zeros(4 * n, 2 * n);
        let mut b = DMatrix::zeros(4 * n, dq.len());
        for k in 0..n {
            a[(4 * k, 2 * k)] = ws;
            a[(4 * k + 1, 2 * k + 1)] = ws;
            for c in 0..2 {
                let fr = 2 * (k + 1) + c;
                // Inner nodes of the same shape (the ends are fixed).
                for m in 0..2 * n {
                    a[(4 * k + 2 + c, m)] = wf * dx[(fr, m + 2)];
                }
                for (q, d) in dq.iter().enumerate() {
                    b[(4 * k + 2 + c, q)] = wf * dp[(fr, q)] * d;
                }
            }
        }
        (r, a, b)
    }

    /// The model with the parameters of `p`, and each parameter's derivative by its encoded
    /// value.
    fn decoded(&self) -> (StringModel, Vec<f64>) {
        let off = 2 * self.inner() * self.shapes.len();
        let (params, dq) = decode(self.particles(), &self.p.as_slice()[off..]);
        (
            StringModel {
                params,
                ..self.model.clone()
            },
            dq,
        )
    }

    /// E_all at the current unknowns (infinite where not finite).
    fn cost(&self) -> f64 {
        let (model, dq) = self.decoded();
        let c: f64 = (0..self.shapes.len())
            .map(|j| self.blocks(j, &model, &dq, false).0.norm_squared())
            .sum();
        if c.is_finite() { c } else { f64::INFINITY }
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.p.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.p.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let (n, jn) = (self.inner(), self.shapes.len());
        let (model, dq) = self.decoded();
        let mut r = DVector::zeros(4 * n * jn);
        for j in 0..jn {
            let rj = self.blocks(j, &model, &dq, false).0;
            r.rows_mut(4 * n * j, 4 * n).copy_from(&rj);
        }
        r.iter().all(|v| v.is_finite()).then_some(r)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        if self
            .max_iterations
            .is_some_and(|m| self.jacobians.get() >= m)
        {
            // The iteration limit: stop here, keeping the last accepted step.
            return None;
        }
        self.jacobians.set(self.jacobians.get() + 1);
        let (n, jn) = (self.inner(), self.shapes.len());
        let (model, dq) = self.decoded();
        let off = 2 * n * jn;
        let mut jac = DMatrix::zeros(4 * n * jn, self.p.len());
        for j in 0..jn {
            let (_, a, b) = self.blocks(j, &model, &dq, true);
            jac.view_mut((4 * n * j, 2 * n * j), (4 * n, 2 * n))
                .copy_from(&a);
            jac.view_mut((4 * n * j, off), (4 * n, dq.len()))
                .copy_from(&b);
        }
        jac.iter().all(|v| v.is_finite()).then_some(jac)
    }
}

/// Levenberg–Marquardt on the problem's block-arrow structure (each shape's positions couple
/// only with themselves and the parameters): the damped normal equations solved by the Schur
/// complement on the parameters, so that an iteration costs J small solves and one of the
/// parameters' size instead of a dense QR of the whole Jacobian. Marquardt's damping
/// `λ·D` with D the largest diagonal of JᵀJ seen so far (MINPACK's scaling) and Nielsen's
/// update. Returns (termination, iterations, evaluations,
/// converged).
fn schur_lm(pr: &mut Problem, max_iterations: Option<usize>) -> (String, usize, usize, bool) {
    let (n, jn) = (2 * pr.inner(), pr.shapes.len());
    let off = n * jn;
    let np = pr.p.len() - off;
    let mut cost = pr.cost();
    let mut evaluations = 1;
    let (mut lambda, mut nu) = (1e-3, 2.0);
    let (mut scale_u, mut scale_q): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    let mut iterations = 0;
    loop {
        if max_iterations.is_some_and(|m| iterations >= m) {
            return (
                format!("iteration limit ({iterations})"),
                iterations,
                evaluations,
                false,
            );
        }
        iterations += 1;
        let (model, dq) = pr.decoded();
        let blocks: Vec<_> = (0..jn).map(|j| pr.blocks(j, &model, &dq, true)).collect();
        let mut v = DMatrix::<f64>::zeros(np, np);
        let mut gq = DVector::<f64>::zeros(np);
        let mut us = Vec::with_capacity(jn);
        for (r, a, b) in &blocks {
            us.push((a.transpose() * a, a.transpose() * b, a.transpose() * r));
            v += b.transpose() * b;
            gq += b.transpose() * r;
        }
        // MINPACK's scaling: each unknown damped by the largest diagonal of JᵀJ it has had,
        // so that a direction once stiff stays damped as stiff (λ dimensionless).
        if scale_u.is_empty() {
            scale_u = vec![0.0; off];
            scale_q = vec![0.0; np];
            lambda = 1e-3;
        }
        for (j, u) in us.iter().enumerate() {
            for i in 0..n {
                scale_u[n * j + i] = scale_u[n * j + i].max(u.0[(i, i)]).max(1e-12);
            }
        }
        for i in 0..np {
            scale_q[i] = scale_q[i].max(v[(i, i)]).max(1e-12);
        }
        let mut accepted = false;
        while !accepted {
            // Damped blocks, their inverses applied through Cholesky.
            let damp = |m: &DMatrix<f64>, scale: &[f64]| {
                let mut d = m.clone();
                for i in 0..d.nrows() {
                    d[(i, i)] += lambda * scale[i];
                }
                d
            };
            let mut s = damp(&v, &scale_q);
            let mut rhs = -gq.clone();
            let mut chol = Vec::with_capacity(jn);
            let mut ok = true;
            for (j, (u, w, g)) in us.iter().enumerate() {
                let Some(c) = damp(u, &scale_u[n * j..n * (j + 1)]).cholesky() else {
                    ok = false;
                    break;
                };
                let uw = c.solve(w);
                let ug = c.solve(g);
                s -= w.transpose() * &uw;
                rhs += w.transpose() * &ug;
                chol.push((uw, ug));
            }
            let dq_step = if ok {
                s.clone().cholesky().map(|c| c.solve(&rhs))
            } else {
                None
            };
            let Some(dq_step) = dq_step else {
                lambda *= nu;
                nu *= 2.0;
                if lambda > 1e30 {
                    return ("damping overflow".into(), iterations, evaluations, false);
                }
                continue;
            };
            let mut step = DVector::<f64>::zeros(pr.p.len());
            let mut predicted = 0.0;
            for (j, ((uw, ug), (r, a, b))) in chol.iter().zip(&blocks).enumerate() {
                let du = -(ug + uw * &dq_step);
                let jd = a * &du + b * &dq_step;
                predicted -= 2.0 * r.dot(&jd) + jd.norm_squared();
                step.rows_mut(n * j, n).copy_from(&du);
            }
            step.rows_mut(off, np).copy_from(&dq_step);
            let old = pr.p.clone();
            pr.p += &step;
            let trial = pr.cost();
            evaluations += 1;
            let rho = (cost - trial) / predicted.max(1e-300);
            if trial.is_finite() && trial < cost && rho > 0.0 {
                let small = step.norm() <= 1e-12 * (old.norm() + 1e-12);
                let flat = (cost - trial) <= 1e-15 * cost;
                cost = trial;
                lambda *= (1.0 / 3.0f64).max(1.0 - (2.0 * rho - 1.0).powi(3));
                nu = 2.0;
                accepted = true;
                if small || flat || cost == 0.0 {
                    return ("converged".into(), iterations, evaluations, true);
                }
            } else {
                pr.p = old;
                lambda *= nu;
                nu *= 2.0;
                if lambda > 1e30 {
                    // No step lowers the cost: as converged as rounding allows.
                    return ("no further decrease".into(), iterations, evaluations, true);
                }
            }
        }
    }
}

/// Check J shapes for an identification: at least one, each of at least 3 finite markers, all
/// with as many markers as `initial` has particles, and not all the same shape (one shape
/// repeated carries no more than one).
pub fn check_shapes(shapes: &[Vec<V2>], particles: usize) -> Result<(), FitError> {
    if shapes.is_empty() {
        return Err(FitError::invalid("shapes", 0, 0.0, "no shape observed"));
    }
    for (j, s) in shapes.iter().enumerate() {
        check_shape(s, j)?;
        if s.len() != particles {
            return Err(FitError::invalid(
                "shapes",
                j,
                s.len() as f64,
                format!(
                    "{} markers where the first shape (or the model) has {particles}",
                    s.len()
                ),
            ));
        }
    }
    if shapes.len() > 1 && shapes.iter().all(|s| s == &shapes[0]) {
        return Err(FitError::invalid(
            "shapes",
            1,
            shapes.len() as f64,
            "every shape is the same: the parameters are not identifiable from one shape repeated",
        ));
    }
    Ok(())
}

/// Find the parameters (from `initial`) and node positions (from the markers) that make every
/// shape of `shapes` — marker positions in metres, x horizontal and y up, first and last
/// markers the held ends — a static shape of the model.
pub fn identify(
    shapes: &[Vec<V2>],
    initial: &StringParams,
    options: &FitOptions,
) -> Result<Fit, FitError> {
    initial.validate()?;
    check_shapes(shapes, initial.particles())?;
    for (field, v) in [
        ("c_s", options.c_s),
        ("c_f", options.c_f),
        ("mass", options.mass),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(FitError::invalid(field, 0, v, "must be finite and > 0"));
        }
    }
    if options.patience == 0 {
        return Err(FitError::invalid("patience", 0, 0.0, "must be ≥ 1"));
    }
    let model = StringModel {
        params: initial.clone(),
        mass: options.mass,
        gravity: V2::new(options.gravity[0], options.gravity[1]),
    };
    let n = initial.particles() - 2;
    let mut p: Vec<f64> = shapes
        .iter()
        .flat_map(|s| s[1..=n].iter().flat_map(|q| [q.x, q.y]))
        .collect();
    p.extend(encode(initial));
    let problem = Problem {
        shapes,
        model,
        c_s: options.c_s,
        c_f: options.c_f,
        p: DVector::from_vec(p),
        jacobians: Cell::new(0),
        max_iterations: options.max_iterations,
    };
    let initial_cost = problem.cost();
    let (problem, termination, iterations, evaluations, converged) = match options.method {
        Method::Schur => {
            let mut problem = problem;
            let (t, i, e, c) = schur_lm(&mut problem, options.max_iterations);
            (problem, t, i, e, c)
        }
        Method::Minpack => {
            let (problem, report) = LevenbergMarquardt::new()
                .with_patience(options.patience)
                .minimize(problem);
            let iterations = problem.jacobians.get();
            let termination = if options.max_iterations.is_some_and(|m| iterations >= m)
                && matches!(report.termination, TerminationReason::User(_))
            {
                format!("iteration limit ({iterations})")
            } else {
                format!("{:?}", report.termination)
            };
            let converged = report.termination.was_successful();
            (
                problem,
                termination,
                iterations,
                report.number_of_evaluations,
                converged,
            )
        }
    };
    let positions = (0..shapes.len()).map(|j| problem.positions(j)).collect();
    Ok(Fit {
        model: problem.decoded().0,
        positions,
        initial_cost,
        cost: problem.cost(),
        iterations,
        evaluations,
        termination,
        converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::statics::StaticOptions;

    /// Shapes made by the model itself (no noise, no mismatch) are fitted to rounding: from
    /// the paper's kind of initial guess (l, φ from the first shape, s and b off by factors of
    /// 3), J = 4 shapes of a 9-particle string with a natural curvature are reproduced with
    /// E_all below 1e-20 and every static shape re-solved with the parameters found lies
    /// within 1 µm of its markers; both minimisers find the same parameters (within 1e-6).
    #[test]
    fn shapes_of_the_model_itself_are_fitted_exactly() {
        let i = 9;
        let truth = StringModel::new(StringParams {
            stretch: vec![2.0; i - 1],
            length: vec![0.03; i - 1],
            bending: vec![0.02; i - 2],
            natural_bend: (0..i - 2).map(|k| 2.8 + 0.05 * k as f64).collect(),
        });
        let shapes: Vec<Vec<V2>> = [(0.15, 0.05), (0.2, -0.05), (0.1, -0.1), (0.18, 0.1)]
            .iter()
            .map(|&(ex, ey)| {
                let start: Vec<V2> = (0..i)
                    .map(|k| {
                        let u = k as f64 / (i - 1) as f64;
                        V2::new(ex * u, ey * u - 0.02 * (std::f64::consts::PI * u).sin())
                    })
                    .collect();
                truth
                    .equilibrium(&start, &StaticOptions::default())
                    .expect("equilibrium")
                    .positions
            })
            .collect();
        let initial = initial_guess(&shapes[0], 6.0, 0.006).expect("guess");
        let options = FitOptions {
            max_iterations: None,
            ..FitOptions::default()
        };
        let fit = identify(&shapes, &initial, &options).expect("fit");
        // The crate's MINPACK minimiser reaches the same parameters.
        let minpack = identify(
            &shapes,
            &initial,
            &FitOptions {
                method: Method::Minpack,
                ..options.clone()
            },
        )
        .expect("fit");
        assert!(minpack.cost < 1e-20, "{minpack:?}");
        for (a, b) in fit
            .model
            .params
            .to_vec()
            .iter()
            .zip(minpack.model.params.to_vec())
        {
            assert!((a - b).abs() < 1e-6 * b.abs().max(1e-3), "{a} vs {b}");
        }
        eprintln!(
            "exact fit: {} iterations, {} evaluations, E_all {:e} → {:e} ({})",
            fit.iterations, fit.evaluations, fit.initial_cost, fit.cost, fit.termination
        );
        assert!(fit.converged, "{fit:?}");
        assert!(fit.cost < 1e-20, "{} from {}", fit.cost, fit.initial_cost);
        for shape in &shapes {
            let eq = fit
                .model
                .equilibrium(shape, &StaticOptions::default())
                .expect("equilibrium");
            let worst = eq
                .positions
                .iter()
                .zip(shape)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            assert!(worst < 1e-6, "{worst}");
        }
    }

    /// Bad input: fewer than three markers, different counts, NaN, every shape the same.
    #[test]
    fn bad_shapes_are_refused_with_their_position() {
        let good: Vec<V2> = (0..5).map(|k| V2::new(0.01 * k as f64, 0.0)).collect();
        let guess = initial_guess(&good, 1.0, 0.01).expect("guess");
        let cases: Vec<(Vec<Vec<V2>>, &str)> = vec![
            (vec![good[..2].to_vec()], "at least 3"),
            (vec![good.clone(), good[..4].to_vec()], "4 markers"),
            (
                vec![good.clone(), {
                    let mut g = good.clone();
                    g[2].y = f64::NAN;
                    g
                }],
                "marker 2 is not finite",
            ),
            (vec![good.clone(), good.clone()], "not identifiable"),
        ];
        for (shapes, says) in cases {
            let e = identify(&shapes, &guess, &FitOptions::default()).expect_err("refused");
            assert!(e.to_string().contains(says), "{e}");
        }
    }
}
