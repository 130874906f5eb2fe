//! Step parameters: every knob with its unit, default and valid range, validated once.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// How the internal axial forces p ≥ 0 are found (thesis (43)–(47)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum InternalMethod {
    /// The thesis: projected steepest descent `p ← max(0, p − γ ∂E/∂p)` with a fixed step.
    SteepestDescent,
    /// Projected gradient with Nesterov momentum and adaptive restart (FISTA); same fixed point,
    /// far fewer iterations on long tension paths.
    Accelerated,
}

/// How the shape constraints (49)–(51) are iterated.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ShapeMethod {
    /// The thesis: `ṙ ← ṙ + γ R/Δt` (Jacobi gradient steps, each node's step divided by its
    /// constraint count).
    Jacobi,
    /// The same steps with Chebyshev semi-iterative acceleration (Wang 2015); `rho` estimates the
    /// spectral radius of the plain iteration, in (0, 1).
    Chebyshev {
        /// Spectral radius estimate.
        rho: f64,
    },
    /// Nonlinear Gauss–Seidel by edge colour: each edge's error is removed exactly (mass-
    /// weighted), colour after colour, over-relaxed by `omega` in (0, 2); edges of one colour
    /// share no node, so a colour runs in parallel.
    GaussSeidel {
        /// Over-relaxation factor.
        omega: f64,
    },
    /// Fast projection (Goldenthal et al. 2007): each iteration is a Newton step on all length
    /// constraints at once, the mass-weighted least-change correction `J W Jᵀ λ = −C` solved by
    /// Jacobi-preconditioned conjugate gradients; converges where local iterations crawl
    /// (heavy cloth hanging from a few points).
    Newton {
        /// Conjugate-gradient iterations per Newton step (cap).
        cg_iterations: usize,
        /// Relative residual at which CG stops.
        cg_tolerance: f64,
    },
}

/// Whether an edge class resists compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ConstraintKind {
    /// Length held at the target (a compressed edge is pushed back: the cloth buckles).
    Equality,
    /// Only stretching beyond the target is corrected (the cloth may shrink in plane).
    StretchOnly,
    /// Diagonals only: an elastic spring of the fabric's shear stiffness (`Cloth::
    /// diagonal_stiffness`) held by a compliant (XPBD) constraint instead of a rigid one, so a
    /// cell shears under in-plane load as the fabric does (a rigid cell of four sides and two
    /// diagonals cannot change shape at all). Needs the Jacobi or Chebyshev shape method.
    Compliant,
}

/// The thresholds ε^c (internal forces) and ε^e (shape), fixed or scaled with the cloth's speed
/// (thesis, end of §3.8.2: loose while the cloth moves fast, tight as it settles).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum TolerancePolicy {
    /// Always the tight tolerances.
    Fixed,
    /// Tolerances × `loose_factor` when the fastest node moves faster than `fast_speed` (m/s),
    /// × 1 below `slow_speed`, interpolated geometrically in between.
    Adaptive {
        /// Factor on the tolerances at speed ≥ `fast_speed`, ≥ 1.
        loose_factor: f64,
        /// m/s.
        fast_speed: f64,
        /// m/s, below `fast_speed`.
        slow_speed: f64,
    },
}

/// Parameters of one step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StepParams {
    /// Time step Δt, s. Range (0, 0.1]; default 0.01 (the thesis's).
    pub dt: f64,
    /// Gravity, m/s². Default (0, 0, −9.80665).
    pub gravity: [f64; 3],
    /// Linear damping per area c/S (air drag and internal friction), kg/(m²·s). Range [0, 1e3];
    /// default 0.2 (a light fabric's terminal speed of a few m/s; a physical value, not a
    /// convergence aid — see `docs/solver.md`).
    pub damping: f64,
    /// Internal-force method. Default `Accelerated`.
    pub internal_method: InternalMethod,
    /// Internal-force step γ as a fraction of the largest stable step 1/λ_max(AᵀA). Range (0, 2);
    /// default 1.
    pub internal_step: f64,
    /// ε^c: stop the internal-force iterations when the projected gradient of E falls below ε^c
    /// times its value with all forces zero (the thesis stops on E's relative change, which
    /// stalls when E cannot reach zero; see `docs/solver.md`). Range (0, 1); default 1e-4.
    pub internal_tolerance: f64,
    /// Iteration cap for the internal forces, per phase. Range ≥ 1; default 10 (the forces are
    /// warm-started, so a moving cloth converges over steps).
    pub internal_max_iterations: usize,
    /// Shape-constraint method. Default `Chebyshev { rho: 0.99 }`.
    pub shape_method: ShapeMethod,
    /// Shape step γ: a node moves by γ times the mean correction of its constraints (Jacobi
    /// averaging; γ > 1 over-relaxes). Range (0, 2); default 1.
    pub shape_step: f64,
    /// ε^e: stop the shape iterations when the RMS of R (the per-node length error) is below it,
    /// m. Range > 0; default 1e-6.
    pub shape_tolerance: f64,
    /// Iteration cap for the shape constraints per collision pass. Range ≥ 1; default 30 (the
    /// thesis: about 30 per pass, two passes).
    pub shape_max_iterations: usize,
    /// Collision passes per step; the shape iterations are split between them (the thesis: two
    /// passes of ~30 iterations). Range ≥ 1; default 2.
    pub collision_passes: usize,
    /// Axial edges: equality or stretch-only. Default `Equality` (see `docs/solver.md`).
    pub axial_constraint: ConstraintKind,
    /// Diagonal (bias) edges. Default `Equality`.
    pub diagonal_constraint: ConstraintKind,
    /// Tolerance policy. Default `Fixed`.
    pub tolerance_policy: TolerancePolicy,
    /// Treat the bending stiffness of each node implicitly along its normal (a diagonal,
    /// linearised implicit term). Lifts the explicit limit Δt < 2√(μ/k) on fine grids and stiff
    /// fabrics; changes no equilibrium. Default true.
    pub implicit_bending: bool,
    /// Linearise the implicit bending term with the regularised spindle's steepest slope,
    /// `bending_stick_slope`·B, where the fabric has bending hysteresis (instead of B). Cures
    /// the node-by-node chatter of hysteretic strips on fine grids (a 10-cell wool cantilever
    /// at Δt = 0.25·h: 7 cm/s for ever without it, at rest within 2 s with it), but made the
    /// walking dress diverge while settling (0.4 s, edge strain 1.2), so it is off by default
    /// until that is understood (`docs/solver.md`). Default false.
    pub implicit_stick_slope: bool,
    /// Regularisation of the bending hysteresis: the square-root curves after each turning point
    /// are infinitely steep, and an explicit bending force then amplifies rounding noise
    /// (measured: a flat sheet in free fall develops 3e-4 m/s of spurious velocity spread in
    /// 0.25 s). Their tangent is capped at this multiple of B over a tiny band
    /// (`Spindle::with_stick_slope`). Range > 1 (∞ = exact); default 4.
    pub bending_stick_slope: f64,
    /// Reversal dead band of the bending hysteresis, as a fraction of each characteristic's
    /// M₀/B (`Spindle::with_deadband`): curvature jitter smaller than this does not start a
    /// minor loop. Range [0, 1); default 0.05.
    pub bending_deadband: f64,
    /// Skip bending entirely (an inextensible chain or membrane). Default false.
    pub bending_off: bool,
    /// Long-range attachments ([`crate::long_range`]): hold every free node within its rest
    /// distance from the pins times (1 + the step's largest target strain) in the shape
    /// iterations — a bound the converged constraints imply, which carries the corrections of
    /// a cloth hanging from a few pins across it in one projection. Nothing runs for a cloth
    /// without pins. Default false (see `docs/solver.md`).
    pub long_range_attachments: bool,
    /// Divergence guard: a step whose result stretches or shrinks any edge by more than this
    /// strain (|l/l⁰ − 1|) fails with `StepError::Diverged` and keeps the state. Range > 0;
    /// default 1 (a doubled edge: far beyond any fabric's EMT).
    pub divergence_strain: f64,
    /// Track hysteresis (tensile minor loops, bending spindle) when the fabric has it. Default
    /// true; false uses the loading branch and the elastic spindle centre line.
    pub hysteresis: bool,
}

impl Default for StepParams {
    fn default() -> Self {
        Self {
            dt: 0.01,
            gravity: [0.0, 0.0, -atelier_fabric::STANDARD_GRAVITY],
            damping: 0.2,
            internal_method: InternalMethod::Accelerated,
            internal_step: 1.0,
            internal_tolerance: 1e-4,
            internal_max_iterations: 10,
            shape_method: ShapeMethod::Chebyshev { rho: 0.99 },
            shape_step: 1.0,
            shape_tolerance: 1e-6,
            shape_max_iterations: 30,
            collision_passes: 2,
            axial_constraint: ConstraintKind::Equality,
            diagonal_constraint: ConstraintKind::Equality,
            tolerance_policy: TolerancePolicy::Fixed,
            implicit_bending: true,
            implicit_stick_slope: false,
            bending_stick_slope: 4.0,
            bending_deadband: 0.05,
            bending_off: false,
            long_range_attachments: false,
            divergence_strain: 1.0,
            hysteresis: true,
        }
    }
}

/// A parameter outside its range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("step parameter `{name}` = {value} is outside its range {range}")]
pub struct ParamError {
    /// Field name.
    pub name: &'static str,
    /// Offending value.
    pub value: f64,
    /// The valid range in words.
    pub range: &'static str,
}

/// `Ok` when `ok` holds and `value` is finite, else the error naming the field and its range.
pub(crate) fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    range: &'static str,
) -> Result<(), ParamError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ParamError { name, value, range })
    }
}

/// The fields every solver's parameters share: Δt, gravity and damping.
pub(crate) fn check_motion(dt: f64, gravity: [f64; 3], damping: f64) -> Result<(), ParamError> {
    check("dt", dt, dt > 0.0 && dt <= 0.1, "(0, 0.1] s")?;
    for g in gravity {
        check("gravity", g, g.abs() <= 1e3, "|g| ≤ 1000 m/s²")?;
    }
    check(
        "damping",
        damping,
        (0.0..=1e3).contains(&damping),
        "[0, 1000] kg/(m²·s)",
    )
}

impl StepParams {
    /// Check every field against its range.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_motion(self.dt, self.gravity, self.damping)?;
        check(
            "internal_step",
            self.internal_step,
            self.internal_step > 0.0 && self.internal_step < 2.0,
            "(0, 2)",
        )?;
        check(
            "internal_tolerance",
            self.internal_tolerance,
            self.internal_tolerance > 0.0 && self.internal_tolerance < 1.0,
            "(0, 1)",
        )?;
        check(
            "internal_max_iterations",
            self.internal_max_iterations as f64,
            self.internal_max_iterations >= 1,
            "≥ 1",
        )?;
        check(
            "shape_step",
            self.shape_step,
            self.shape_step > 0.0 && self.shape_step <= 1.0,
            "(0, 1]",
        )?;
        check(
            "shape_tolerance",
            self.shape_tolerance,
            self.shape_tolerance > 0.0,
            "> 0 m",
        )?;
        check(
            "shape_max_iterations",
            self.shape_max_iterations as f64,
            self.shape_max_iterations >= 1,
            "≥ 1",
        )?;
        check(
            "collision_passes",
            self.collision_passes as f64,
            self.collision_passes >= 1,
            "≥ 1",
        )?;
        if self.axial_constraint == ConstraintKind::Compliant {
            return Err(ParamError {
                name: "axial_constraint",
                value: 0.0,
                range: "Equality or StretchOnly (Compliant is for diagonals)",
            });
        }
        if self.diagonal_constraint == ConstraintKind::Compliant
            && !matches!(
                self.shape_method,
                ShapeMethod::Jacobi | ShapeMethod::Chebyshev { .. }
            )
        {
            return Err(ParamError {
                name: "diagonal_constraint",
                value: 0.0,
                range: "Compliant needs the Jacobi or Chebyshev shape method",
            });
        }
        match self.shape_method {
            ShapeMethod::Chebyshev { rho } => {
                check("shape_method.rho", rho, rho > 0.0 && rho < 1.0, "(0, 1)")?
            }
            ShapeMethod::GaussSeidel { omega } => check(
                "shape_method.omega",
                omega,
                omega > 0.0 && omega < 2.0,
                "(0, 2)",
            )?,
            ShapeMethod::Newton {
                cg_iterations,
                cg_tolerance,
            } => {
                check(
                    "shape_method.cg_iterations",
                    cg_iterations as f64,
                    cg_iterations >= 1,
                    "≥ 1",
                )?;
                check(
                    "shape_method.cg_tolerance",
                    cg_tolerance,
                    cg_tolerance > 0.0 && cg_tolerance < 1.0,
                    "(0, 1)",
                )?;
            }
            ShapeMethod::Jacobi => {}
        }
        if let TolerancePolicy::Adaptive {
            loose_factor,
            fast_speed,
            slow_speed,
        } = self.tolerance_policy
        {
            check(
                "tolerance_policy.loose_factor",
                loose_factor,
                loose_factor >= 1.0,
                "≥ 1",
            )?;
            check(
                "tolerance_policy.slow_speed",
                slow_speed,
                slow_speed >= 0.0,
                "≥ 0 m/s",
            )?;
            check(
                "tolerance_policy.fast_speed",
                fast_speed,
                fast_speed > slow_speed,
                "> slow_speed",
            )?;
        }
        Ok(())
    }

    /// Gravity as a vector.
    pub fn gravity_vector(&self) -> Vector3<f64> {
        Vector3::from(self.gravity)
    }

    /// The tolerance factor (≥ 1) for a cloth whose fastest node moves at `max_speed` m/s.
    pub fn tolerance_factor(&self, max_speed: f64) -> f64 {
        match self.tolerance_policy {
            TolerancePolicy::Fixed => 1.0,
            TolerancePolicy::Adaptive {
                loose_factor,
                fast_speed,
                slow_speed,
            } => {
                let s = ((max_speed - slow_speed) / (fast_speed - slow_speed)).clamp(0.0, 1.0);
                loose_factor.powf(s)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Compliant constraints: diagonals only, and only with the local shape methods.
    #[test]
    fn compliant_constraints_are_checked() {
        let ok = StepParams {
            diagonal_constraint: ConstraintKind::Compliant,
            ..StepParams::default()
        };
        ok.validate().expect("compliant diagonals with Chebyshev");
        let axial = StepParams {
            axial_constraint: ConstraintKind::Compliant,
            ..StepParams::default()
        };
        assert_eq!(
            axial.validate().expect_err("axial").name,
            "axial_constraint"
        );
        let newton = StepParams {
            shape_method: ShapeMethod::GaussSeidel { omega: 1.0 },
            ..ok
        };
        assert_eq!(
            newton.validate().expect_err("GS").name,
            "diagonal_constraint"
        );
    }

    #[test]
    fn defaults_are_valid_and_ranges_are_enforced() {
        StepParams::default().validate().expect("defaults valid");
        let bad = StepParams {
            dt: 0.0,
            ..StepParams::default()
        };
        assert_eq!(bad.validate().expect_err("dt").name, "dt");
        let bad = StepParams {
            shape_method: ShapeMethod::Chebyshev { rho: 1.0 },
            ..StepParams::default()
        };
        assert_eq!(bad.validate().expect_err("rho").name, "shape_method.rho");
        let bad = StepParams {
            damping: f64::NAN,
            ..StepParams::default()
        };
        assert_eq!(bad.validate().expect_err("nan").name, "damping");
    }

    #[test]
    fn adaptive_tolerance_interpolates_geometrically() {
        let p = StepParams {
            tolerance_policy: TolerancePolicy::Adaptive {
                loose_factor: 100.0,
                fast_speed: 1.0,
                slow_speed: 0.0,
            },
            ..StepParams::default()
        };
        assert!((p.tolerance_factor(0.0) - 1.0).abs() < 1e-12);
        assert!((p.tolerance_factor(0.5) - 10.0).abs() < 1e-9);
        assert!((p.tolerance_factor(5.0) - 100.0).abs() < 1e-9);
    }
}
