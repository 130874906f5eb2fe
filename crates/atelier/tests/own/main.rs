//! The facade's integration tests, in one test binary (one link instead of eleven, and the
//! harness runs tests of different files side by side; session 20). Each file is a module:
//!
//! - [`baselines`]: the baseline solvers (XPBD, mass-spring) in the garment pipeline;
//! - [`degenerate`]: degenerate geometry, each case a clear error;
//! - [`dress`]: the eight-panel dress end to end, sewn, settled and walked;
//! - [`dressing`], [`sewing`]: dressing by sewing on the mannequin;
//! - [`export`]: the exports read back;
//! - [`fabrics_on_body`]: fabrics tell apart on the body (issue 21, item 7);
//! - [`fit_cloth`]: cloth identification through the PARTY solver;
//! - [`long_run`]: the walking dress for 60 s (ignored: run by hand);
//! - [`run`]: `atelier::run`, a scenario run into a folder;
//! - the user's own pattern and body (issue 24): garments of pieces imported from pattern
//!   software ([`imported`]) and a body scan as a scene's body ([`scan_body`]).
//!
//! A file's tests are selected by its module path: `cargo test --release -p atelier --test own
//! fit_cloth::`.

mod garment_common;
mod scratch;

mod baselines;
mod degenerate;
mod dress;
mod dressing;
mod export;
mod fabrics_on_body;
mod fit_cloth;
mod imported;
mod long_run;
mod run;
mod scan_body;
mod sewing;
