//! Whether a run's steps converged: every PARTY step reports whether it met its tolerances
//! (`StepReport::converged`) and whether its shape stage ended at or below the relative
//! tolerance `StepParams::shape_tolerance` (`shape_converged`), with the largest violation it
//! ended with. A number obtained from an unconverged step is not a result: a run counts its
//! steps that did not converge ([`Tally`]), reports them (`report.json`'s `convergence`,
//! [`Convergence`]; the metric `unconverged_fraction`) and warns when there are any
//! ([`Convergence::warning`]).
//!
//! The baselines (XPBD, mass-spring, Yamada's model) have no tolerance to meet: their
//! convergence fields are `null`, not 0.

use atelier_solver::step::Constraint;
use atelier_solver::{SolveStats, StepReport};
use serde::{Deserialize, Serialize};

use crate::simulation::Phase;

/// The metric: steps that did not converge over steps taken.
pub const UNCONVERGED_FRACTION: &str = "unconverged_fraction";

/// The solver names of [`Convergence::solver`].
pub mod solvers {
    /// The PARTY step.
    pub const PARTY: &str = "party";
    /// The XPBD baseline.
    pub const XPBD: &str = "xpbd";
    /// The explicit mass-spring baseline.
    pub const MASS_SPRING: &str = "mass-spring";
    /// Yamada's wet-cloth mass-spring model.
    pub const YAMADA: &str = "yamada";
}

/// The step that ended with the run's largest violation, and its constraint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorstStep {
    /// The kind of constraint: `edge` (an axial edge's length), `cell` (a cell's shear),
    /// `bend` (a node's bending along u or v), `tie` (a seam tie being drawn together) or
    /// `plane` (a node's contact plane).
    pub constraint: String,
    /// Its index: the edge, the cell, the tie (in that step's ties) or the node (`bend`,
    /// `plane`).
    pub index: usize,
    /// `u` or `v` for `bend` (`null` otherwise).
    pub direction: Option<String>,
    /// Its violation (the run's `max_violation`).
    pub violation: f64,
    /// Simulated time at the start of that step, s.
    pub time_s: f64,
    /// The garment schedule's phase of that step (`Sewing`, `Pushing`, `Settling`, `Motion`);
    /// `null` for the other kinds.
    pub phase: Option<String>,
}

impl WorstStep {
    fn new(c: Constraint, violation: f64, time: f64, phase: Option<Phase>) -> Self {
        let (constraint, index, direction) = match c {
            Constraint::Edge(i) => ("edge", i, None),
            Constraint::Cell(i) => ("cell", i, None),
            Constraint::Tie(i) => ("tie", i, None),
            Constraint::Bend(i, d) => ("bend", i, Some(if d == 0 { "u" } else { "v" }.into())),
            Constraint::Plane(i) => ("plane", i, None),
        };
        Self {
            constraint: constraint.into(),
            index,
            direction,
            violation,
            // To the nanosecond, as the report's simulated time (summed steps carry noise).
            time_s: (time * 1e9).round() / 1e9,
            phase: phase.map(|p| format!("{p:?}")),
        }
    }

    /// "edge 12", "bend (u) of node 40", … with the time and phase of the step.
    pub fn describe(&self) -> String {
        let what = match (self.constraint.as_str(), &self.direction) {
            ("bend", Some(d)) => format!("bend ({d}) of node {}", self.index),
            ("bend", None) => format!("bend of node {}", self.index),
            ("plane", _) => format!("contact plane of node {}", self.index),
            (kind, _) => format!("{kind} {}", self.index),
        };
        let phase = self
            .phase
            .as_ref()
            .map_or(String::new(), |p| format!(", {p}"));
        format!("{what}, step at t = {:.3} s{phase}", self.time_s)
    }
}

/// Convergence of one run's steps (`report.json`'s `convergence`, and `comparison.convergence`
/// of a wet scene's compared run). The counts are `null` for a solver that does not report
/// convergence (the baselines), never 0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Convergence {
    /// The solver that took the steps: [`solvers`].
    pub solver: String,
    /// Steps taken (a step that failed is not counted).
    pub steps: usize,
    /// Steps that did not meet every tolerance (`StepReport::converged` false: the shape
    /// stage, the internal forces or the implicit bending solve).
    pub unconverged_steps: Option<usize>,
    /// Of those, steps whose shape stage ended above the shape tolerance (after the last
    /// collision pass).
    pub shape_unconverged_steps: Option<usize>,
    /// The largest relative violation any step ended with (edges: |l − l̄|/l⁰; cells: rad;
    /// ties and contact planes: over the node spacing).
    pub max_violation: Option<f64>,
    /// The shape tolerance the steps were held to (`StepParams::shape_tolerance`; an adaptive
    /// tolerance policy scales it while the cloth moves fast).
    pub tolerance: Option<f64>,
    /// The step with the largest violation and its constraint (`null`: no violation, or not
    /// reported).
    pub worst: Option<WorstStep>,
}

impl Convergence {
    /// A solver that does not report convergence (a baseline): the steps, every other field
    /// `null`.
    pub fn not_reported(solver: &str, steps: usize) -> Self {
        Self {
            solver: solver.into(),
            steps,
            unconverged_steps: None,
            shape_unconverged_steps: None,
            max_violation: None,
            tolerance: None,
            worst: None,
        }
    }

    /// From counts kept elsewhere (the solver's own runs: `atelier_solver::scenes::DrapeRun`).
    pub fn from_counts(
        solver: &str,
        steps: usize,
        unconverged: usize,
        shape_unconverged: usize,
        max_violation: f64,
        tolerance: f64,
    ) -> Self {
        Self {
            solver: solver.into(),
            steps,
            unconverged_steps: Some(unconverged),
            shape_unconverged_steps: Some(shape_unconverged),
            max_violation: Some(max_violation),
            tolerance: Some(tolerance),
            worst: None,
        }
    }

    /// From the counts a solver's own runner kept ([`SolveStats`]: the virtual KES instruments,
    /// the PARTY runs of wet scenes); no schedule phase.
    pub fn from_stats(solver: &str, stats: &SolveStats) -> Self {
        Self {
            solver: solver.into(),
            steps: stats.steps,
            unconverged_steps: Some(stats.unconverged),
            shape_unconverged_steps: Some(stats.shape_unconverged),
            max_violation: Some(stats.worst_violation),
            tolerance: Some(stats.tolerance),
            worst: stats
                .worst
                .map(|c| WorstStep::new(c, stats.worst_violation, stats.worst_time, None)),
        }
    }

    /// Unconverged steps over steps (`null`: not reported, or no step taken).
    pub fn unconverged_fraction(&self) -> Option<f64> {
        let u = self.unconverged_steps?;
        (self.steps > 0).then(|| u as f64 / self.steps as f64)
    }

    /// Whether some step did not converge (false when not reported).
    pub fn any_unconverged(&self) -> bool {
        self.unconverged_steps.is_some_and(|u| u > 0)
    }

    /// The warning a run with unconverged steps carries (`None` when every step converged or
    /// the solver does not report it).
    pub fn warning(&self) -> Option<String> {
        let u = self.unconverged_steps.filter(|&u| u > 0)?;
        let shape = self.shape_unconverged_steps.unwrap_or(0);
        let other = u.saturating_sub(shape);
        let percent = 100.0 * u as f64 / self.steps.max(1) as f64;
        let percent = if percent >= 1.0 {
            format!("{percent:.1} %")
        } else {
            format!("{percent:.2} %")
        };
        let tolerance = self
            .tolerance
            .map_or("(not reported)".into(), |t| format!("{t:e}"));
        let largest = match (&self.worst, self.max_violation) {
            (Some(w), Some(v)) => format!("largest violation {v:.1e}: {}", w.describe()),
            (None, Some(v)) => format!("largest violation {v:.1e}"),
            _ => "largest violation not reported".into(),
        };
        let what = if shape > 0 {
            let rest = if other > 0 {
                format!(
                    ", and {other} stopped the internal-force or implicit bending iterations at their caps"
                )
            } else {
                String::new()
            };
            format!("{shape} ended above the shape tolerance {tolerance} ({largest}){rest}")
        } else {
            format!(
                "they stopped the internal-force or implicit bending iterations at their caps (every step met the shape tolerance {tolerance}; {largest})"
            )
        };
        Some(format!(
            "{u} of {} {} steps ({percent}) did not converge: {what}; numbers from those steps are not converged results",
            self.steps, self.solver
        ))
    }
}

/// Counts the steps of a PARTY run as they are taken.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    steps: usize,
    unconverged: usize,
    shape_unconverged: usize,
    max_violation: f64,
    worst: Option<WorstStep>,
}

impl Tally {
    /// Count one step's report; `start_time` is the simulated time at the start of the step,
    /// `phase` the garment schedule's phase (none for the other scenes).
    pub fn add(&mut self, report: &StepReport, start_time: f64, phase: Option<Phase>) {
        self.steps += 1;
        self.unconverged += usize::from(!report.converged);
        self.shape_unconverged += usize::from(!report.shape_converged);
        // A NaN violation becomes the worst (and stays: nothing compares above it).
        if report.violation.is_nan() || report.violation > self.max_violation {
            self.max_violation = report.violation;
            self.worst = report
                .worst
                .map(|c| WorstStep::new(c, report.violation, start_time, phase));
        }
    }

    /// Steps counted.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// The run's convergence, its steps held to the shape tolerance `tolerance`.
    pub fn convergence(&self, tolerance: f64) -> Convergence {
        Convergence {
            solver: solvers::PARTY.into(),
            steps: self.steps,
            unconverged_steps: Some(self.unconverged),
            shape_unconverged_steps: Some(self.shape_unconverged),
            max_violation: Some(self.max_violation),
            tolerance: Some(tolerance),
            worst: self.worst.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(converged: bool, shape_converged: bool, violation: f64) -> StepReport {
        StepReport {
            converged,
            shape_converged,
            violation,
            worst: Some(Constraint::Edge(7)),
            ..StepReport::default()
        }
    }

    #[test]
    fn a_tally_counts_unconverged_steps_and_keeps_the_worst() {
        let mut t = Tally::default();
        t.add(&report(true, true, 5e-5), 0.0, Some(Phase::Sewing));
        t.add(&report(false, false, 3.2e-3), 0.01, Some(Phase::Settling));
        t.add(&report(false, true, 1e-5), 0.02, Some(Phase::Settling));
        let c = t.convergence(1e-4);
        assert_eq!(c.steps, 3);
        assert_eq!(c.unconverged_steps, Some(2));
        assert_eq!(c.shape_unconverged_steps, Some(1));
        assert_eq!(c.max_violation, Some(3.2e-3));
        let w = c.worst.as_ref().expect("worst");
        assert_eq!((w.constraint.as_str(), w.index), ("edge", 7));
        assert_eq!(w.phase.as_deref(), Some("Settling"));
        assert!((c.unconverged_fraction().expect("fraction") - 2.0 / 3.0).abs() < 1e-15);
        let warning = c.warning().expect("a warning");
        assert!(
            warning.starts_with("2 of 3 party steps (66.7 %) did not converge: 1 ended above the shape tolerance 1e-4 (largest violation 3.2e-3: edge 7, step at t = 0.010 s, Settling), and 1 stopped"),
            "{warning}"
        );
        assert!(warning.ends_with("not converged results"), "{warning}");
    }

    #[test]
    fn converged_runs_and_baselines_do_not_warn() {
        let mut t = Tally::default();
        t.add(&report(true, true, 5e-5), 0.0, None);
        let c = t.convergence(1e-4);
        assert_eq!(c.unconverged_fraction(), Some(0.0));
        assert!(c.warning().is_none() && !c.any_unconverged());
        let b = Convergence::not_reported(solvers::XPBD, 10);
        assert_eq!(b.unconverged_fraction(), None);
        assert!(b.warning().is_none() && !b.any_unconverged());
        let json = serde_json::to_string(&b).expect("json");
        assert!(json.contains("\"unconverged_steps\":null"), "{json}");
    }

    #[test]
    fn solver_stats_become_a_convergence() {
        let stats = SolveStats {
            steps: 40,
            unconverged: 3,
            shape_unconverged: 2,
            worst_violation: 2e-6,
            worst: Some(Constraint::Bend(5, 1)),
            worst_time: 1.25,
            tolerance: 1e-7,
        };
        let c = Convergence::from_stats(solvers::PARTY, &stats);
        assert_eq!(c.steps, 40);
        assert_eq!(c.unconverged_steps, Some(3));
        assert_eq!(c.shape_unconverged_steps, Some(2));
        assert_eq!((c.max_violation, c.tolerance), (Some(2e-6), Some(1e-7)));
        let w = c.worst.as_ref().expect("worst");
        assert_eq!(w.describe(), "bend (v) of node 5, step at t = 1.250 s");
        assert!(
            c.warning()
                .expect("a warning")
                .starts_with("3 of 40 party steps (7.5 %)")
        );
    }
}
