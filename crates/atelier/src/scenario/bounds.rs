//! The physical range of every metric an expectation may bound, so that an expectation that
//! cannot fail is refused when the scenario is read (issue 23: eight drape scenarios once
//! "expected" a drape coefficient in [0, 100] or [−1, 101], and every run met them).
//!
//! A metric's physical range is what its definition allows whatever the simulation does: a
//! drape coefficient lies in [0, 100] %, a fraction or a yes/no in [0, 1], a count, length,
//! energy or error is not negative, a pressure difference to the atmosphere is at least minus
//! one atmosphere. An expectation binds when its interval [min, max] (a missing bound is
//! infinite) leaves out part of that range.

use atelier_solver::wet::ATMOSPHERE;

use crate::convergence::UNCONVERGED_FRACTION;

/// The interval `metric` can take by definition, `(lo, hi)` (either may be infinite).
pub fn physical_range(metric: &str) -> (f64, f64) {
    const INF: f64 = f64::INFINITY;
    match metric {
        "drape_coefficient_percent"
        | "emt_percent"
        | "input_emt_percent"
        | "rt_percent"
        | "input_rt_percent" => (0.0, 100.0),
        "settled" | "converged" | "compare_failed" => (0.0, 1.0),
        m if m == UNCONVERGED_FRACTION => (0.0, 1.0),
        "chord_angle_deg" => (0.0, 90.0),
        "chord_angle_error_deg" => (-90.0, 90.0),
        "pressure_difference_pa" | "min_pressure_difference_pa" | "max_pressure_difference_pa" => {
            (-ATMOSPHERE, INF)
        }
        // Heights and displacements measured from a reference that the cloth may pass.
        "lowest_node_m"
        | "tip_droop_m"
        | "fold_ring_height_mm"
        | "tent_height_mm"
        | "compare_tent_height_mm"
        | "pinch_height_mm" => (-INF, INF),
        // Counts, sizes, times, energies, speeds, errors and costs.
        _ => (0.0, INF),
    }
}

/// Whether the expectation `[min, max]` on `metric` covers the metric's whole physical range
/// (then no run can miss it). `None` is an open side.
pub fn covers_everything(metric: &str, min: Option<f64>, max: Option<f64>) -> bool {
    let (lo, hi) = physical_range(metric);
    min.is_none_or(|m| m <= lo) && max.is_none_or(|m| m >= hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The drape scenarios' old bounds cover everything; the published ±8 points do not; a
    /// one-sided bound on a quantity that cannot be negative binds only from above.
    #[test]
    fn ranges_that_cannot_fail_are_recognised() {
        let dc = "drape_coefficient_percent";
        assert!(covers_everything(dc, Some(0.0), Some(100.0)));
        assert!(covers_everything(dc, Some(-1.0), Some(101.0)));
        assert!(!covers_everything(dc, Some(74.9), Some(90.9)));
        assert!(!covers_everything(dc, Some(0.5), None));
        assert!(covers_everything("max_penetration_m", Some(0.0), None));
        assert!(!covers_everything("max_penetration_m", None, Some(0.002)));
        assert!(covers_everything(UNCONVERGED_FRACTION, None, Some(1.0)));
        assert!(!covers_everything(UNCONVERGED_FRACTION, None, Some(0.0)));
        // Signed metrics: only both sides open cover them (and the loader refuses that anyway).
        assert!(!covers_everything("lowest_node_m", Some(-10.0), None));
        assert!(covers_everything("lowest_node_m", None, None));
        // A pressure difference of at least −1 atm is no bound.
        assert!(covers_everything(
            "min_pressure_difference_pa",
            Some(-2.0e5),
            None
        ));
        assert!(!covers_everything(
            "min_pressure_difference_pa",
            Some(0.0),
            None
        ));
    }
}
