//! Range images of bodies: a body gridded from its front and back range images (thesis
//! §4.6.2, §4.7.2; `method.md` §4), and the range images of a posed mannequin rendered for it.
//!
//! - [`image`]: 16-bit PGM and grayscale PNG reading and writing;
//! - [`side`]: the RON side file describing one view;
//! - [`body`]: [`RangeBody`], two registered range images with landmarks
//!   ([`RangeBody::load`]`(front_side, back_side)`);
//! - [`part`] (the crate's `part`, re-exported): the 17 parts and their tree rooted at the pelvis;
//! - [`gridding`]: [`grid_body`], the body split into parts, each a front and a back patch joined
//!   along the silhouette, improved on the range images; one closed [`BodyMesh`];
//! - [`measure`]: [`measure_error`], the thesis's error (re-rendered `Z_e` against `Z_r`);
//! - [`synthetic`]: an analytic JIS 9AR-like mannequin with exact range images (test data);
//! - [`render`]: range images, part labels and landmarks of a posed mannequin, rendered with the
//!   one rasteriser ([`measure::rasterize_triangle`], also the error measure's), and
//!   [`round_trip`] mannequin → range images → gridded body → error.
//!
//! (This was `atelier_grid::range` until issue 22: the parts, views and landmarks are the
//! body's; the gridding uses `atelier-grid`'s Coons patches and improvement.)
//!
//! ```
//! use atelier_body::range::{BodyGridParams, grid_body, measure_error, synthetic::Mannequin};
//!
//! let body = Mannequin::jis_9ar().body(5.0);
//! let (mesh, _report) = grid_body(&body, &BodyGridParams::default()).unwrap();
//! let error = measure_error(&mesh, &body);
//! assert_eq!(mesh.edge_defects(), (0, 0));
//! assert!(error.total.mean_abs_mm < 3.0);
//! ```
//!
//! Method, file format and measured numbers: `docs/grid-range.md` and `docs/body-range.md`.

pub mod body;
mod field;
pub mod gridding;
pub mod image;
mod landmarks;
pub mod measure;
pub mod render;
pub mod side;
pub mod synthetic;

pub use crate::part::{self, Part};
pub use body::{LANDMARKS, RangeBody};
pub use gridding::{
    BodyGridParams, BodyGridReport, BodyMesh, BoundaryRing, GridError, PatchReport, grid_body,
};
pub use image::{GrayImage, read_image, write_image};
pub use landmarks::find_landmarks;
pub use measure::{ErrorImage, ErrorReport, ErrorStats, measure_error};
pub use render::{
    Frame, MAX_PIXELS, NO_PART, RangeError, RangeView, RenderParams, RoundTrip, Views,
    render_images, render_views, round_trip, round_trip_mesh,
};
pub use side::{SideFile, View};

#[cfg(test)]
mod tests;
