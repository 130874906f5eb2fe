//! `atelier-fit`: identifying model parameters from observed shapes (Sudoh et al.;
//! `method.md` §6; `docs/fit.md`).
//!
//! A string-like object is modelled by I particles in a vertical plane with stretch and
//! bending springs ([`string`]). Given J observed static shapes (marker positions, the two ends
//! held), the model's parameters — per segment the spring coefficient s and natural length l,
//! per inner particle the bending coefficient b and natural bend φ — are found together with
//! the model's node positions for every shape so that the nodes lie on the markers and every
//! inner node is in equilibrium ([`identify`](fn@identify), Levenberg–Marquardt with an analytic Jacobian).
//! [`string::StringModel::equilibrium`] then reproduces any shape for given end positions.

pub mod cloth;
pub mod differenced;
pub mod error;
pub mod experiment;
pub mod fabric_fit;
pub mod identify;
pub mod observation;
pub mod rod;
pub mod statics;
pub mod string;
pub mod strip;
pub mod synthetic;
pub mod turned;

pub use error::FitError;
pub use identify::{Fit, FitOptions, identify, initial_guess};
pub use string::{STANDARD_GRAVITY, StringModel, StringParams, V2};
