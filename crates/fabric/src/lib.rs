//! # atelier-fabric
//!
//! The measured mechanics of a fabric as the PARTY cloth model uses them (Sakaguchi's thesis
//! §3.6–3.7; `method.md` §0–§1): KES-F data converted to SI, the tensile characteristic with its
//! hysteresis (minor loops), the bending characteristic with its hysteresis (spindle model), the
//! in-plane shear characteristic with its hysteresis (the KES-FB1 loop), orthotropic
//! interpolation to any material angle, and fabric files with provenance.
//!
//! ```
//! use atelier_fabric::{Branch, TensileLoop, TensileState, TensileSummary, units};
//!
//! // A loop synthesised from KES summary values: LT 0.7, EMT 5 %, RT 50 %.
//! let summary = TensileSummary { lt: 0.7, emt: 0.05, rt: 0.5, f_max: units::KES_MAX_TENSILE_FORCE };
//! let major = TensileLoop::from_summary(&summary).unwrap();
//! assert!((major.summary().lt - 0.7).abs() < 1e-5);
//!
//! // One edge loaded to 100 N/m, then unloaded to 50 N/m: a minor loop inside the major one.
//! let mut edge = TensileState::VIRGIN;
//! let at_peak = edge.update(&major, 100.0);
//! let after = edge.update(&major, 50.0);
//! assert!(after < at_peak && after > major.strain(Branch::Loading, 50.0));
//! ```
//!
//! Modules: [`units`] (KES ↔ SI), [`tensile`], [`bending`], [`shear`], [`anisotropy`], [`fabric`] (the SI
//! fabric and the per-angle [`MaterialTable`]), [`spec`] (the file format), [`plausibility`],
//! and, re-exported from `atelier-files`, [`files`] (RON loading with positioned errors, atomic
//! writes) and [`error`].

pub mod anisotropy;
pub mod bending;
pub mod check;
pub mod fabric;
pub(crate) mod interp;
pub mod plausibility;
pub mod shear;
pub mod spec;
pub mod tensile;
pub mod units;

pub use anisotropy::{AnisotropyForm, Directions};
/// The file plumbing, from `atelier-files` (kept at these paths for the fabric crate's users).
pub use atelier_files::{error, files, noise, validated};
pub use bending::{
    BendingState, KesBendingTest, Spindle, SpindleFit, fit_spindle, kes_bending_test,
};
pub use error::{ErrorKind, FileError, InvalidValue, Position};
pub use fabric::{
    DEFAULT_LOCKING_ANGLE, Fabric, KES_PRETENSION, MAX_MONOTONE_REPAIR, MaterialTable,
    STANDARD_GRAVITY, Shear, bias_from_shear, bias_from_yarns, trellis_strain,
};
pub use plausibility::{FabricClass, PlausibilityWarning};
pub use shear::{
    KesShearTest, ShearCurve, ShearFit, ShearLoop, ShearState, fit_shear, kes_shear_test,
};
pub use spec::FabricSpec;
pub use tensile::{Branch, TABLE_SEGMENTS, TensileLoop, TensileState, TensileSummary};
