//! The paper's experiments (Sudoh et al. §5) on observations: fit J shapes, reproduce shapes
//! as the model's static shapes at their held ends, and measure the reproduction error.
//!
//! A reproduced shape is the fitted model's equilibrium at the shape's two held ends, reached
//! by moving the manipulated end there quasi-statically from a known state ([`reproduce`]) —
//! not solved from the target's markers, so that an unobserved shape is a prediction. Its error is the mean distance, in pixels, of the
//! model's inner particles from their markers (the ends sit on the held positions and are
//! left out; the paper averages over every particle, which with 9 markers gives 7/9 of these
//! numbers).

use serde::{Deserialize, Serialize};

use crate::identify::{Fit, FitOptions, identify, initial_guess};
use crate::observation::Observations;
use crate::statics::{StaticOptions, equilibrium};
use crate::string::{StringModel, V2};
use crate::{FitError, StringParams};

/// One reproduced shape.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Reproduced {
    /// The shape's index in the observations.
    pub shape: usize,
    /// The model's static shape, metres (empty when none was found).
    pub positions: Vec<V2>,
    /// Mean distance of the inner particles from their markers, px (`None`: no equilibrium).
    pub error_px: Option<f64>,
}

/// Moves of the manipulated end on a path between two shapes (quasi-static steps).
const PATH_STEPS: usize = 20;

/// The static shapes of `model` at the held ends of shapes `which`, and their errors.
///
/// Each shape is reached as the paper's simulation reaches it, by manipulating the model: from
/// the known static state among `states` (the fit's node positions of its observed shapes, or
/// the observed markers for an unfitted model) whose manipulated end is nearest, the
/// manipulated end is moved in a straight line to the target in 20 steps, the model solved to
/// equilibrium at each (the fixed end is the same in every shape). A shape of `states` itself
/// is solved from its own state.
pub fn reproduce(
    model: &StringModel,
    obs: &Observations,
    states: &[Vec<V2>],
    which: &[usize],
) -> Vec<Reproduced> {
    which
        .iter()
        .map(|&j| {
            let target = obs.shape(j);
            let n = target.len();
            let failed = Reproduced {
                shape: j,
                positions: Vec::new(),
                error_px: None,
            };
            let Some(from) = states.iter().min_by(|a, b| {
                let d = |s: &Vec<V2>| (s[s.len() - 1] - target[n - 1]).norm();
                d(a).total_cmp(&d(b))
            }) else {
                return failed;
            };
            if from.len() != n {
                return failed;
            }
            let (a, b) = (from[n - 1], target[n - 1]);
            let steps = if (a - b).norm() > 0.0 { PATH_STEPS } else { 1 };
            let mut x = from.clone();
            x[0] = target[0];
            for k in 1..=steps {
                x[n - 1] = a + (b - a) * (k as f64 / steps as f64);
                match equilibrium(model, &x, &StaticOptions::default()) {
                    Ok(eq) => x = eq.positions,
                    Err(_) => return failed,
                }
            }
            let err = inner_distance_px(&x, &target, obs.pixel_size);
            Reproduced {
                shape: j,
                positions: x,
                error_px: Some(err),
            }
        })
        .collect()
}

/// Mean distance of the inner particles of `positions` from `reference` (both metres), px.
pub fn inner_distance_px(positions: &[V2], reference: &[V2], pixel_size: f64) -> f64 {
    let n = positions.len();
    positions[1..n - 1]
        .iter()
        .zip(&reference[1..n - 1])
        .map(|(p, q)| (p - q).norm())
        .sum::<f64>()
        / (n - 2) as f64
        / pixel_size
}

/// Mean over `r` of the distance from the noise-free markers `truth` (shape index → markers,
/// metres), px; `None` when any shape has no equilibrium.
pub fn mean_error_from_truth(r: &[Reproduced], truth: &[Vec<V2>], pixel_size: f64) -> Option<f64> {
    let e: Option<Vec<f64>> = r
        .iter()
        .map(|x| {
            (!x.positions.is_empty())
                .then(|| inner_distance_px(&x.positions, &truth[x.shape], pixel_size))
        })
        .collect();
    e.filter(|v| !v.is_empty())
        .map(|v| v.iter().sum::<f64>() / v.len() as f64)
}

/// Mean of the errors that were measured; `None` when any shape has no equilibrium.
pub fn mean_error(r: &[Reproduced]) -> Option<f64> {
    let e: Option<Vec<f64>> = r.iter().map(|x| x.error_px).collect();
    e.filter(|v| !v.is_empty())
        .map(|v| v.iter().sum::<f64>() / v.len() as f64)
}

/// The paper's initial parameters for `obs`: l and φ from shape `first`, s and b given.
pub fn paper_initial(
    obs: &Observations,
    first: usize,
    stretch: f64,
    bending: f64,
) -> Result<StringParams, FitError> {
    initial_guess(&obs.shape(first), stretch, bending)
}

/// Fit shapes `which` of `obs` from `initial`.
pub fn fit(
    obs: &Observations,
    which: &[usize],
    initial: &StringParams,
    options: &FitOptions,
) -> Result<Fit, FitError> {
    let shapes: Vec<Vec<V2>> = which.iter().map(|&j| obs.shape(j)).collect();
    identify(&shapes, initial, options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::{Object, SyntheticOptions, observe};

    /// Without noise, the chain (the most string-like object: no bending, inextensible) fitted
    /// on 4 shapes reproduces them within 1 px, and predicts 10 unobserved shapes within 2 px;
    /// the initial guess (Table 2) is worse than the fit on the unobserved shapes.
    #[test]
    fn the_chain_is_fitted_and_predicted() {
        let (obs, _) = observe(
            Object::Chain,
            &SyntheticOptions {
                noise_px: 0.0,
                ..SyntheticOptions::default()
            },
        )
        .expect("observed");
        let (s, b) = Object::Chain.table2();
        let initial = paper_initial(&obs, 0, s, b).expect("initial");
        let f = fit(&obs, &[0, 1, 2, 3], &initial, &FitOptions::default()).expect("fit");
        let observed = reproduce(&f.model, &obs, &f.positions, &[0, 1, 2, 3]);
        let unobserved: Vec<usize> = (10..20).collect();
        let predicted =
            mean_error(&reproduce(&f.model, &obs, &f.positions, &unobserved)).expect("predicted");
        let guessed = mean_error(&reproduce(
            &StringModel::new(initial),
            &obs,
            &[obs.shape(0)],
            &unobserved,
        ));
        eprintln!(
            "chain: {} iterations, E_all {:e} → {:e}; observed {:?} px; unobserved {predicted:.2} px; initial {guessed:?} px",
            f.iterations,
            f.initial_cost,
            f.cost,
            observed.iter().map(|r| r.error_px).collect::<Vec<_>>()
        );
        for r in &observed {
            assert!(r.error_px.expect("equilibrium") < 1.0, "{r:?}");
        }
        assert!(predicted < 2.0, "{predicted}");
        assert!(guessed.is_none_or(|g| g > predicted));
    }
}
