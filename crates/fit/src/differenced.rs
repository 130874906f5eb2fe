//! Levenberg–Marquardt (the `levenberg-marquardt` crate) on a problem given only by its
//! residual function: the Jacobian by central differences, its columns evaluated in parallel.
//! For forward models that are only piecewise smooth in their parameters (a hysteretic path's
//! reversals, a rendered silhouette's pixels) the difference step is chosen to see through the
//! kinks.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use rayon::prelude::*;

/// A least-squares problem given by its residual function.
struct Differenced<'a, F> {
    residuals: &'a F,
    p: DVector<f64>,
    step: f64,
}

impl<F: Fn(&DVector<f64>) -> Option<DVector<f64>> + Sync> LeastSquaresProblem<f64, Dyn, Dyn>
    for Differenced<'_, F>
{
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
        (self.residuals)(&self.p)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        central_differences(&self.p, self.step, self.residuals)
    }
}

/// Levenberg–Marquardt from `start` on the problem whose residuals are `residuals`, the
/// Jacobian by central differences of `step` in every parameter: the parameters it ends at and
/// how it ended. The crate's default patience (at most 100·(n + 1) residual evaluations).
pub fn minimise(
    start: DVector<f64>,
    step: f64,
    residuals: impl Fn(&DVector<f64>) -> Option<DVector<f64>> + Sync,
) -> (DVector<f64>, String) {
    minimise_with(start, step, 100, residuals)
}

/// [`minimise`] with at most `patience`·(n + 1) residual evaluations besides the Jacobians'.
pub fn minimise_with(
    start: DVector<f64>,
    step: f64,
    patience: usize,
    residuals: impl Fn(&DVector<f64>) -> Option<DVector<f64>> + Sync,
) -> (DVector<f64>, String) {
    let problem = Differenced {
        residuals: &residuals,
        p: start,
        step,
    };
    let (problem, report) = LevenbergMarquardt::new()
        .with_patience(patience)
        .minimize(problem);
    (problem.p, format!("{:?}", report.termination))
}

/// The Jacobian of `residuals` at `p` by central differences with `step` in every parameter,
/// the columns in parallel (None when a residual evaluation fails).
fn central_differences(
    p: &DVector<f64>,
    step: f64,
    residuals: &(impl Fn(&DVector<f64>) -> Option<DVector<f64>> + Sync),
) -> Option<DMatrix<f64>> {
    let columns: Option<Vec<DVector<f64>>> = (0..p.len())
        .into_par_iter()
        .map(|c| {
            let (mut a, mut b) = (p.clone(), p.clone());
            a[c] += step;
            b[c] -= step;
            Some((residuals(&a)? - residuals(&b)?) / (2.0 * step))
        })
        .collect();
    Some(DMatrix::from_columns(&columns?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_fitted_exactly_and_a_failed_evaluation_stops_the_fit() {
        // y = 2x − 1 at five points: the residuals are linear, so the minimum is exact.
        let xs = [0.0, 1.0, 2.0, 3.0, 4.0];
        let r = |p: &DVector<f64>| {
            Some(DVector::from_iterator(
                5,
                xs.iter().map(|&x| p[0] * x + p[1] - (2.0 * x - 1.0)),
            ))
        };
        let (p, how) = minimise(DVector::from_vec(vec![0.0, 0.0]), 1e-3, r);
        assert!(
            (p[0] - 2.0).abs() < 1e-9 && (p[1] + 1.0).abs() < 1e-9,
            "{p} ({how})"
        );
        // A residual function that fails away from the start leaves the start.
        let fails = |p: &DVector<f64>| (p[0] == 0.0).then(|| DVector::from_vec(vec![1.0]));
        let (p, _) = minimise_with(DVector::from_vec(vec![0.0]), 1e-3, 5, fails);
        assert!(p[0] == 0.0, "{p}");
    }
}
