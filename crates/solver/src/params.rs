//! Step parameters: every knob with its unit, default and valid range, validated once.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::shear_angle::ShearMeasure;

/// How the internal axial forces p ≥ 0 are found (thesis (43)–(47)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum InternalMethod {
    /// The thesis: projected steepest descent `p ← max(0, p − γ ∂E/∂p)` with a fixed step.
    SteepestDescent,
    /// Projected gradient with Nesterov momentum and adaptive restart (FISTA); same fixed point,
    /// far fewer iterations on long tension paths.
    Accelerated,
}

/// How the shape constraints (49)–(51) are solved (the step's shape stage, [`crate::step`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ShapeMethod {
    /// Full Newton on the saddle-point (KKT) system with the geometric stiffness of the rows in
    /// tension ([`crate::kkt`]), factorized every iteration (faer LDLᵀ, symbolic analysis
    /// reused while the rows are unchanged). The default.
    Newton,
    /// Newton (fast projection, Goldenthal et al. 2007) on the constraint-space system, each
    /// linear solve by conjugate gradients preconditioned with a sparse LDLᵀ factorization
    /// (faer; symbolic analysis reused while the rows are unchanged), renewed when a solve needs
    /// more than `refactor_after` CG iterations (Gauss–Newton: no geometric stiffness).
    Direct {
        /// CG iterations above which the factorization is renewed (0: every Newton step).
        refactor_after: usize,
    },
    /// Newton with Jacobi-preconditioned conjugate gradients (nothing factorized).
    ConjugateGradient {
        /// CG iterations per Newton step (cap).
        cg_iterations: usize,
    },
    /// The thesis: local corrections, each row by its own diagonal, scaled by the largest
    /// constraint count of its nodes (`shape.step` the γ of (51)).
    Jacobi,
    /// Jacobi with Chebyshev semi-iterative acceleration (Wang 2015); `rho` estimates the
    /// spectral radius of the plain iteration, in (0, 1).
    Chebyshev {
        /// Spectral radius estimate.
        rho: f64,
    },
    /// Nonlinear Gauss–Seidel over colours of rows sharing no node, each row solved exactly,
    /// over-relaxed by `omega` in (0, 2).
    GaussSeidel {
        /// Over-relaxation factor.
        omega: f64,
    },
}

impl ShapeMethod {
    /// The default: [`ShapeMethod::Newton`].
    pub const DEFAULT: Self = Self::Newton;

    /// Whether the method solves the whole system at once (Newton, Direct, CG) rather than row
    /// by row (Jacobi, Chebyshev, Gauss–Seidel).
    pub fn is_global(self) -> bool {
        matches!(
            self,
            Self::Newton | Self::Direct { .. } | Self::ConjugateGradient { .. }
        )
    }
}

/// Whether the axial edges resist compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ConstraintKind {
    /// Length held at the target (a compressed edge is pushed back: the cloth buckles).
    Equality,
    /// Only stretching beyond the target is corrected (the cloth may shrink in plane).
    StretchOnly,
}

/// Where the axial force p of each edge — the force its tensile characteristic reads its
/// target strain at, (25) — comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Tension {
    /// The edge constraints' forces of the previous step's shape stage (−λ/Δt², the force the
    /// constraint actually exerted): nothing to solve, consistent with the dynamics. The
    /// default.
    #[default]
    Constraint,
    /// The thesis (43)–(47): forces p ≥ 0 that balance the external and bending forces at the
    /// start of the step as far as the edges can, by projected descent to `internal.tolerance`
    /// (it cannot balance a load across the cloth, and on long chains it needs many
    /// iterations: `docs/solver.md`).
    Balance,
}

/// How bending enters the step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum BendingModel {
    /// Bending as compliant constraints of the shape stage, solved with the other constraints
    /// (backward Euler: no stability limit from bending): for each node and grid direction with
    /// both neighbours, the turn of the grid line n·(t₊ − t₋) ≈ l̄·η held by a compliance from
    /// the spindle's local slope, linearised about the start of the step (the spindle's
    /// hysteresis then advances once per step, as the shear loop's). The default.
    #[default]
    Implicit,
    /// The thesis (28)–(32): an explicit force along the node normals from the slots' circle
    /// curvatures, with the linearised implicit term of `bending.implicit` (stable only up to
    /// Δt ≈ 0.4·h s/m; `docs/solver.md`).
    Thesis,
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

/// Parameters of one step, grouped by stage ([`InternalParams`], [`ShapeParams`],
/// [`ShearParams`], [`BendingParams`]). The table in `docs/solver.md` is generated from
/// `StepParams::default()` (`cargo xtask knob-table`), so the docs cannot disagree with it.
/// In a scenario file: `step: (damping: 0.5, shape: (tolerance: 1e-6), bending: (off: true))`;
/// every field may be left out (its default).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StepParams {
    /// Linear damping per area c/S (air drag and internal friction), kg/(m²·s). Range [0, 1e3];
    /// default 0.2 (a light fabric's terminal speed of a few m/s; a physical value, not a
    /// convergence aid — see `docs/solver.md`).
    pub damping: f64,
    /// The internal-force stage.
    pub internal: InternalParams,
    /// The shape stage and the collision passes.
    pub shape: ShapeParams,
    /// The shear of the cells.
    pub shear: ShearParams,
    /// The bending stage.
    pub bending: BendingParams,
    /// Tolerance policy. Default `Fixed`.
    pub tolerance_policy: TolerancePolicy,
    /// Divergence guard: a step whose result stretches or shrinks any edge by more than this
    /// strain (|l/l⁰ − 1|; a diagonal's change over its cell's size, the longest of the
    /// diagonal and the cell's sides) fails with `StepError::Diverged` and keeps the state.
    /// Range > 0; default 1 (a doubled edge: far beyond any fabric's EMT).
    pub divergence_strain: f64,
    /// Track hysteresis (tensile minor loops, bending spindle, shear loop) when the fabric has
    /// it. Default true; false uses the loading branch, the spindle's centre line and the shear
    /// loop's centre line.
    pub hysteresis: bool,
}

impl Default for StepParams {
    fn default() -> Self {
        Self {
            damping: 0.2,
            internal: InternalParams::default(),
            shape: ShapeParams::default(),
            shear: ShearParams::default(),
            bending: BendingParams::default(),
            tolerance_policy: TolerancePolicy::Fixed,
            divergence_strain: 1.0,
            hysteresis: true,
        }
    }
}

/// The internal-force stage (thesis (43)–(47)): where the axial forces come from and how they are solved.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InternalParams {
    /// Where the edges' axial forces come from. Default `Constraint`.
    pub tension: Tension,
    /// Internal-force method ([`Tension::Balance`]). Default `Accelerated`.
    pub method: InternalMethod,
    /// Internal-force step γ as a fraction of the largest stable step 1/λ_max(AᵀA). Range (0, 2);
    /// default 1.
    pub step: f64,
    /// ε^c: the internal-force iterations stop when the projected gradient of E falls below
    /// ε^c times its value with all forces zero (a relative residual). Range (0, 1); default
    /// 1e-4.
    pub tolerance: f64,
    /// Iteration cap of the internal forces (a step whose forces stop at the cap says so in its
    /// report). Range ≥ 1; default 200 (warm-started, they usually need far fewer).
    pub max_iterations: usize,
}

impl Default for InternalParams {
    fn default() -> Self {
        Self {
            tension: Tension::Constraint,
            method: InternalMethod::Accelerated,
            step: 1.0,
            tolerance: 1e-4,
            max_iterations: 200,
        }
    }
}

/// The shape stage (thesis (49)–(51)) and the collision passes it runs with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ShapeParams {
    /// Shape-constraint method. Default `Newton`.
    pub method: ShapeMethod,
    /// Shape step γ of the Jacobi and Chebyshev methods: a row's correction times γ over the
    /// largest constraint count of its nodes. Range (0, 1]; default 1.
    pub step: f64,
    /// ε^e: the shape stage stops when the largest relative violation — |l − l̄|/l⁰ over the
    /// edges, the compliant residual |C + α̃λ| (rad) over the cells, the excess of ties and the
    /// depth behind contact planes over the node spacing — is at most this. Range (0, 0.1];
    /// default 1e-4. A step that ends above it is reported as not converged.
    pub tolerance: f64,
    /// Iteration cap of the shape stage per collision pass. Range ≥ 1; default 100 (the
    /// global methods need 2–10 where the cloth is not flat; a flat sheet starting to sag is
    /// a singular start and needs more).
    pub max_iterations: usize,
    /// Collision passes per step; the shape stage runs before each (the thesis: two passes).
    /// Range ≥ 1; default 2. Up to 4 more are made while the last pass's solve converged and
    /// its collision pass left the shape above the tolerance.
    pub collision_passes: usize,
    /// Axial edges: equality or stretch-only. Default `Equality` (see `docs/solver.md`).
    pub axial_constraint: ConstraintKind,
    /// Long-range attachments ([`crate::long_range`]) for the local shape methods: every free
    /// node held within its rest distance from the pins times (1 + the step's largest target
    /// strain). Nothing runs for a cloth without pins, nor with the global methods. Default
    /// false.
    pub long_range_attachments: bool,
}

impl Default for ShapeParams {
    fn default() -> Self {
        Self {
            method: ShapeMethod::DEFAULT,
            step: 1.0,
            tolerance: 1e-4,
            max_iterations: 100,
            collision_passes: 2,
            axial_constraint: ConstraintKind::Equality,
            long_range_attachments: false,
        }
    }
}

/// The shear of the cells (method.md §2b): how the angle is measured, the fabric's stiffness scaled, the reversal band.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ShearParams {
    /// How a cell's shear angle is measured (`shear_angle`). Default `Midpoint` (the angle
    /// between the cell's midpoint vectors, in the plane of its diagonals).
    pub measure: ShearMeasure,
    /// Factor on the fabric's shear stiffness (the loop's stresses and slopes): 1 the fabric,
    /// 0 no shear resistance at all (the lower bound of the drape studies). Range [0, 1e3];
    /// default 1.
    pub scale: f64,
    /// Reversal dead band of the shear loop, rad: an angle change back smaller than this does
    /// not start a minor loop. Range [0, 0.1); default 1e-4 rad (0.006°).
    pub deadband: f64,
}

impl Default for ShearParams {
    fn default() -> Self {
        Self {
            measure: ShearMeasure::Midpoint,
            scale: 1.0,
            deadband: 1e-4,
        }
    }
}

/// The bending stage (thesis (28)–(32)): its model, its implicit solve and its hysteresis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BendingParams {
    /// How bending enters the step. Default `Implicit`.
    pub model: BendingModel,
    /// [`BendingModel::Thesis`] only: treat the bending stiffness of each node implicitly along
    /// its normal (a linearised implicit term solved by BiCGSTAB). Lifts the explicit limit Δt < 2√(μ/k) on fine grids and
    /// stiff fabrics; changes no equilibrium. Default true.
    pub implicit: bool,
    /// Relative residual at which the implicit bending solve stops. Range (0, 1); default 1e-6.
    pub tolerance: f64,
    /// Iteration cap of the implicit bending solve (a step that stops at it says so). Range ≥ 1;
    /// default 200.
    pub max_iterations: usize,
    /// Linearise the implicit bending term with the regularised spindle's steepest slope,
    /// `bending.stick_slope`·B, where the fabric has bending hysteresis (instead of B). Default
    /// false (`docs/solver.md`).
    pub implicit_stick_slope: bool,
    /// [`BendingModel::Implicit`] only: linearise each hysteretic bending row with the
    /// regularised spindle's steepest slope, `bending.stick_slope`·B, instead of its local slope
    /// at the start of the step. A row linearised softer than the reversal chord it then
    /// travels overshoots; on refined grids the cloth flips between two shapes every step and
    /// never rests (`docs/validation.md`, "A period-2 oscillation on refined grids"). Changes
    /// no equilibrium of a step that ends where it starts. With the exact spindle
    /// (`stick_slope` ∞) there is no steepest slope and the local one is used. Default false
    /// (opt-in until the validation is measured with it).
    pub steepest_slope: bool,
    /// [`BendingModel::Implicit`] with the `Newton` shape method only: read each hysteretic
    /// bending row on the spindle itself during the solve — the turn at which the spindle,
    /// from the committed state, gives the moment the row's multiplier exerts, with the
    /// compliance of its slope there, as an edge's row reads its tensile loop at its own
    /// force — instead of linearising it at the start of the step (backward Euler in the
    /// hysteresis; `docs/validation.md`, "Bending rows read on the spindle, session 24").
    /// Takes precedence over `bending.steepest_slope`. Default false.
    pub spindle_rows: bool,
    /// Regularisation of the bending hysteresis: the tangent of the spindle's square-root curves
    /// is capped at this multiple of B over a tiny band (`Spindle::with_stick_slope`). Range > 1
    /// (∞ = exact); default 4.
    pub stick_slope: f64,
    /// Reversal dead band of the bending hysteresis, as a fraction of each characteristic's
    /// M₀/B (`Spindle::with_deadband`). Range [0, 1); default 0.05.
    pub deadband: f64,
    /// Skip bending entirely (an inextensible chain or membrane). Default false.
    pub off: bool,
}

impl Default for BendingParams {
    fn default() -> Self {
        Self {
            model: BendingModel::Implicit,
            implicit: true,
            tolerance: 1e-6,
            max_iterations: 200,
            implicit_stick_slope: false,
            steepest_slope: false,
            spindle_rows: false,
            stick_slope: 4.0,
            deadband: 0.05,
            off: false,
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

/// What a step is given besides the cloth, its state and the integrator's parameters: the
/// time step and gravity, which change from step to step (a garment is sewn without gravity
/// and settles with it; a step that misses its tolerance is taken again in halves). Every
/// integrator takes them with each step; none stores them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepInput {
    /// Time step Δt, s. Range (0, 0.1].
    pub dt: f64,
    /// Gravity, m/s² (the scene's frame). Each component within ±1000.
    pub gravity: [f64; 3],
}

impl StepInput {
    /// Δt under standard gravity along −z (the solver tests' and instruments' frame).
    pub fn new(dt: f64) -> Self {
        Self {
            dt,
            gravity: [0.0, 0.0, -atelier_fabric::STANDARD_GRAVITY],
        }
    }

    /// Δt without gravity.
    pub fn weightless(dt: f64) -> Self {
        Self {
            dt,
            gravity: [0.0; 3],
        }
    }

    /// The same gravity with another Δt.
    pub fn with_dt(self, dt: f64) -> Self {
        Self { dt, ..self }
    }

    /// Gravity as a vector.
    pub fn gravity_vector(&self) -> Vector3<f64> {
        Vector3::from(self.gravity)
    }

    /// Check Δt and gravity against their ranges.
    pub fn validate(&self) -> Result<(), ParamError> {
        check("dt", self.dt, self.dt > 0.0 && self.dt <= 0.1, "(0, 0.1] s")?;
        for g in self.gravity {
            check("gravity", g, g.abs() <= 1e3, "|g| ≤ 1000 m/s²")?;
        }
        Ok(())
    }
}

impl Default for StepInput {
    /// 0.01 s (the thesis's Δt) under standard gravity along −z.
    fn default() -> Self {
        Self::new(0.01)
    }
}

/// The damping every integrator's parameters have.
pub(crate) fn check_damping(damping: f64) -> Result<(), ParamError> {
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
        check_damping(self.damping)?;
        check(
            "internal.step",
            self.internal.step,
            self.internal.step > 0.0 && self.internal.step < 2.0,
            "(0, 2)",
        )?;
        check(
            "internal.tolerance",
            self.internal.tolerance,
            self.internal.tolerance > 0.0 && self.internal.tolerance < 1.0,
            "(0, 1)",
        )?;
        check(
            "internal.max_iterations",
            self.internal.max_iterations as f64,
            self.internal.max_iterations >= 1,
            "≥ 1",
        )?;
        check(
            "shape.step",
            self.shape.step,
            self.shape.step > 0.0 && self.shape.step <= 1.0,
            "(0, 1]",
        )?;
        check(
            "shape.tolerance",
            self.shape.tolerance,
            self.shape.tolerance > 0.0 && self.shape.tolerance <= 0.1,
            "(0, 0.1]",
        )?;
        for (name, value) in [
            ("shape.max_iterations", self.shape.max_iterations),
            ("shape.collision_passes", self.shape.collision_passes),
            ("bending.max_iterations", self.bending.max_iterations),
        ] {
            check(name, value as f64, value >= 1, "≥ 1")?;
        }
        check(
            "bending.tolerance",
            self.bending.tolerance,
            self.bending.tolerance > 0.0 && self.bending.tolerance < 1.0,
            "(0, 1)",
        )?;
        check(
            "shear.scale",
            self.shear.scale,
            (0.0..=1e3).contains(&self.shear.scale),
            "[0, 1000]",
        )?;
        check(
            "shear.deadband",
            self.shear.deadband,
            (0.0..0.1).contains(&self.shear.deadband),
            "[0, 0.1) rad",
        )?;
        match self.shape.method {
            ShapeMethod::Chebyshev { rho } => {
                check("shape.method.rho", rho, rho > 0.0 && rho < 1.0, "(0, 1)")?
            }
            ShapeMethod::GaussSeidel { omega } => check(
                "shape.method.omega",
                omega,
                omega > 0.0 && omega < 2.0,
                "(0, 2)",
            )?,
            ShapeMethod::ConjugateGradient { cg_iterations } => check(
                "shape.method.cg_iterations",
                cg_iterations as f64,
                cg_iterations >= 1,
                "≥ 1",
            )?,
            ShapeMethod::Newton | ShapeMethod::Direct { .. } | ShapeMethod::Jacobi => {}
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

    #[test]
    fn defaults_are_valid_and_ranges_are_enforced() {
        StepParams::default().validate().expect("defaults valid");
        StepInput::default()
            .validate()
            .expect("default input valid");
        let bad = StepInput::new(0.0);
        assert_eq!(bad.validate().expect_err("dt").name, "dt");
        let bad = StepInput {
            gravity: [0.0, 2e3, 0.0],
            ..StepInput::default()
        };
        assert_eq!(bad.validate().expect_err("gravity").name, "gravity");
        let bad = StepParams {
            shape: ShapeParams {
                method: ShapeMethod::Chebyshev { rho: 1.0 },
                ..ShapeParams::default()
            },
            ..StepParams::default()
        };
        assert_eq!(bad.validate().expect_err("rho").name, "shape.method.rho");
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
