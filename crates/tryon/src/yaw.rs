//! The camera's direction round the vertical when the user does not know it: the pose fit run
//! over a grid of directions and refined about the best (by the silhouettes' overlap).
//!
//! One silhouette cannot tell a camera in front of the body from one behind it (the outline of
//! a body seen from behind is the mirror image of a mirrored pose seen from the front), so the
//! search covers the front half, −90° (from the body's right) to +90° (from its left). Within
//! it, a pose can still trade against the direction (an arm swung forwards seen from the left
//! is an arm swung back seen from the right, nearly), so the overlap alone decides and the
//! direction found is reported with every overlap tried.

use super::image::Mask;
use super::pose::{FitOptions, PoseFit, fit_pose};

/// The grid of the search, degrees: every 30° across the front half.
pub const YAW_GRID_DEG: [f64; 7] = [-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0];

/// The refinement's steps about the best direction so far, degrees (each tries ± the step).
pub const YAW_REFINE_DEG: [f64; 2] = [15.0, 7.5];

/// A fit whose camera direction was searched.
#[derive(Clone, Debug)]
pub struct YawSearch {
    /// The best fit (its camera's `yaw_deg` is the direction found).
    pub fit: PoseFit,
    /// Every direction tried and its fit's overlap (IoU), in the order tried.
    pub tried: Vec<(f64, f64)>,
    /// Wall time of the whole search, s.
    pub seconds: f64,
}

/// Fit the mannequin to a mask with the camera's direction unknown: `fit_pose` at every
/// direction of [`YAW_GRID_DEG`], then at ± each step of [`YAW_REFINE_DEG`] about the best so
/// far (within ±90°); the fit with the largest overlap wins. `options.yaw_deg` is ignored.
/// Errors: as `fit_pose`.
pub fn fit_pose_any_yaw(mask: &Mask, options: &FitOptions) -> Result<YawSearch, String> {
    let clock = std::time::Instant::now();
    let mut tried = Vec::new();
    let mut best: Option<PoseFit> = None;
    let mut run = |yaw: f64, best: &mut Option<PoseFit>| -> Result<(), String> {
        let fit = fit_pose(
            mask,
            &FitOptions {
                yaw_deg: yaw,
                ..options.clone()
            },
        )?;
        tried.push((yaw, fit.iou_after));
        if best.as_ref().is_none_or(|b| fit.iou_after > b.iou_after) {
            *best = Some(fit);
        }
        Ok(())
    };
    for yaw in YAW_GRID_DEG {
        run(yaw, &mut best)?;
    }
    for step in YAW_REFINE_DEG {
        let centre = best.as_ref().map_or(0.0, |b| b.camera.yaw_deg);
        for yaw in [centre - step, centre + step] {
            if (-90.0..=90.0).contains(&yaw) {
                run(yaw, &mut best)?;
            }
        }
    }
    Ok(YawSearch {
        fit: best.ok_or("no direction tried")?,
        tried,
        seconds: clock.elapsed().as_secs_f64(),
    })
}
