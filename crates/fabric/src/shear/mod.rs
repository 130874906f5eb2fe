//! The in-plane shear characteristic τ = ϕʰ(γ) and its hysteresis, as KES-FB1 measures it: the
//! instrument imposes the shear angle γ and records the shear force per width τ, so the shear
//! enters the cloth step as a resistance to deformation (`method.md` §2b), in the manner of the
//! bending spindle ([`crate::bending`]).
//!
//! **Branches.** KES-FB1 cycles a 20 × 5 cm specimen to ±8° and reports G (the mean slope between
//! 0.5° and 5°), 2HG (the loop width at 0.5°) and 2HG5 (at 5°). The loop is reconstructed as
//! `upper(γ) = Gγ + h(|γ|)` (angle rising) and `lower(γ) = Gγ − h(|γ|)` (falling), with the half
//! width `h = HG = 2HG/2` for `|γ| ≤ 0.5°`, growing linearly to `HG5 = 2HG5/2` at 5° and constant
//! beyond (`h = HG` throughout when 2HG5 is not given). The loop is odd: `lower(−γ) = −upper(γ)`.
//!
//! **Curves between the branches (Masing's rule, with a finite slope).** Write a point between
//! the branches by its normalised distance `q ∈ [0, 1]` from the branch it heads for (the *target*:
//! `upper` while γ rises, `lower` while it falls): `τ = (1 − q)·target(γ) + q·opposite(γ)`. From a
//! turning point at `(γ_t, q₀)` the curve is
//!
//! ```text
//! q(s) = max(0, q₀ − φ(s/Δ_j)),   φ(u) = 2u − u² (u < 1), 1 (u ≥ 1),   s = |γ − γ_t|
//! ```
//!
//! the same curve for every turning point, shifted to start there (assumption (II) of the bending
//! model, Masing's rule). From a turning point on a branch (`q₀ = 1`) it reaches the opposite
//! branch after exactly the **join angle** Δ_j with zero relative slope (τ and dτ/dγ continuous);
//! from a turning point inside the loop (`q₀ < 1`) it reaches the target earlier, at
//! `s = Δ_j (1 − √(1 − q₀))`, and follows it from there with a kink of `4h√(1 − q₀)/Δ_j` — as the
//! spindle does (`method.md` §1.2). The initial curve from rest is the reversal curve scaled by ½
//! (`q = ½(1 − 2|γ|/Δ_j)²`, reaching the branch at `|γ| = Δ_j/2`). Every curve starts with the
//! finite slope `G + 2h(|γ_t|)·φ′(0)/Δ_j = G + 4h/Δ_j` — a cell is never rigid.
//!
//! **Join rule.** `Δ_j = min(2HG/G, 2.5°)`: the angle over which the elastic part Gγ grows by the
//! loop width 2HG, the bending spindle's `2M₀/B` transferred to shear. The initial slope at rest is
//! then `G + 4HG/Δ_j = 3G`. The cap keeps the KES cycle's reversals at ±8° rejoined by ±5.5°, before
//! the measuring points 5°…0.5° (none of the fixtures reaches it: their Δ_j are 0.75°–1.67°).
//!
//! **Why truncate instead of joining smoothly from inside the loop.** A smooth join from every
//! turning point needs a curve whose shape depends on q₀; either its span shrinks with q₀ (and
//! its curvature grows) or its initial slope does, and both let a small cycle `a → b → a` return
//! above where it started and *create* energy (`docs/fabric.md`, with the numbers). With one
//! shape for all curves, a falling curve from b always lies below the rising curve that reached b,
//! so every such cycle dissipates ≥ 0 (the proof is two lines on the concavity of φ; tested).
//!
//! **Dead band.** With [`ShearLoop::with_deadband`] a change of direction counts only once γ has
//! moved back by more than the band from its extreme; inside the band γ runs back along the
//! current curve (behind a turning point: parallel to the branches). The new curve then starts at
//! the edge of the band, on the current curve, so τ stays continuous (the bending spindle starts
//! it at the extreme instead and jumps by up to `√(8·band·M₀B)`).
//!
//! Units: γ in rad, τ in N/m, G in N/(m·rad).
//!
//! This file holds the loop and its state; the KES values, the virtual KES-FB1 test and measured
//! loops are in `measured`, the shear implied by tensile loops in `curve`.

use crate::error::{ErrorKind, InvalidValue};
use crate::units;

pub use curve::ShearCurve;
pub use measured::{KesShearTest, ShearFit, fit_shear, kes_shear_test};
pub(crate) use measured::{
    check_shear_branch, check_shear_branches_apart, check_shear_extent, check_shear_point,
    fit_checked,
};

mod curve;
mod measured;

const DEG: f64 = std::f64::consts::PI / 180.0;

/// The KES-FB1 measuring angles (rad): G is the mean slope between them, 2HG the width at the
/// first, 2HG5 at the second.
pub const KES_SHEAR_ANGLES: (f64, f64) = (0.5 * DEG, 5.0 * DEG);

/// The KES-FB1 cycle's largest angle, ±8° (rad).
pub const KES_MAX_SHEAR_ANGLE: f64 = 8.0 * DEG;

/// Largest join angle Δ_j (rad): 2.5°, so that the KES cycle's reversal curves from ±8° have
/// rejoined their branches by ±5.5°, before the measuring points.
pub const MAX_JOIN_ANGLE: f64 = 2.5 * DEG;

/// Largest |angle| a measured loop may contain, degrees (KES measures to ±8°; more is a unit
/// slip or not a KES record).
pub const MEASURED_MAX_ANGLE_DEG: f64 = 30.0;

/// Largest |force| a measured loop may contain, gf/cm: the stiffest fabrics in the bands
/// (denim, G ≤ 6 gf/(cm·deg)) stay below about 60 gf/cm at ±8°; more is a unit slip (a force
/// for the whole 20 cm specimen in gf, for example).
pub const MEASURED_MAX_FORCE_GF_CM: f64 = 200.0;

/// Fewest points per measured branch.
pub const MEASURED_MIN_POINTS: usize = 4;

/// φ(u) = 2u − u² on [0, 1), 1 beyond: the normalised progress of a curve towards its branch.
#[inline]
fn progress(u: f64) -> f64 {
    if u >= 1.0 { 1.0 } else { u * (2.0 - u) }
}

/// φ′(u) = 2(1 − u) on [0, 1), 0 beyond.
#[inline]
fn progress_slope(u: f64) -> f64 {
    if u >= 1.0 { 0.0 } else { 2.0 * (1.0 - u) }
}

/// A reconstructed KES-FB1 shear loop (SI: γ in rad, τ in N/m).
#[derive(Clone, Debug, PartialEq)]
pub struct ShearLoop {
    /// G, N/(m·rad).
    stiffness: f64,
    /// HG = 2HG/2, N/m.
    hg: f64,
    /// HG5 = 2HG5/2, N/m (= HG when 2HG5 is not given).
    hg5: f64,
    /// Δ_j, rad (0 for an elastic loop).
    join: f64,
    /// Reversal dead band, rad.
    deadband: f64,
}

impl ShearLoop {
    /// The loop of the KES values, given in SI: G in N/(m·rad), 2HG and 2HG5 in N/m (see
    /// [`ShearLoop::from_kes_units`] for gf/(cm·deg) and gf/cm). G must be positive, the widths
    /// finite and ≥ 0, and both branches must rise with γ: `G > |HG5 − HG|/4.5°` (otherwise the
    /// lower branch would fall between 0.5° and 5°: an `Inconsistent` error).
    pub fn from_kes(
        g_n_per_m_rad: f64,
        two_hg_n_per_m: f64,
        two_hg5_n_per_m: Option<f64>,
    ) -> Result<Self, InvalidValue> {
        let g = g_n_per_m_rad;
        let checks = [
            ("g", Some(g)),
            ("two_hg", Some(two_hg_n_per_m)),
            ("two_hg5", two_hg5_n_per_m),
        ];
        for (name, v) in checks {
            let Some(v) = v else { continue };
            if !v.is_finite() {
                return Err(InvalidValue::new(
                    ErrorKind::NotFinite,
                    name,
                    format!("{v}"),
                ));
            }
            if v < 0.0 {
                return Err(InvalidValue::new(ErrorKind::Negative, name, format!("{v}")));
            }
        }
        if g == 0.0 {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                "g",
                "the shear stiffness G must be positive",
            ));
        }
        let hg = 0.5 * two_hg_n_per_m;
        let hg5 = two_hg5_n_per_m.map_or(hg, |w| 0.5 * w);
        let growth = (hg5 - hg).abs() / (KES_SHEAR_ANGLES.1 - KES_SHEAR_ANGLES.0);
        if growth >= g {
            return Err(InvalidValue::new(
                ErrorKind::Inconsistent,
                "two_hg5",
                format!(
                    "2HG5 − 2HG = {:.4} gf/cm over 4.5° exceeds 2G·4.5° = {:.4} gf/cm: a branch \
                     of the loop would fall between 0.5° and 5°",
                    units::force_to_kes(2.0 * (hg5 - hg)),
                    units::force_to_kes(2.0 * g * (KES_SHEAR_ANGLES.1 - KES_SHEAR_ANGLES.0))
                ),
            ));
        }
        let reference = if hg > 0.0 { hg } else { hg5 };
        let join = if reference > 0.0 {
            (2.0 * reference / g).min(MAX_JOIN_ANGLE)
        } else {
            0.0
        };
        Ok(Self {
            stiffness: g,
            hg,
            hg5,
            join,
            deadband: 0.0,
        })
    }

    /// The loop of KES values in KES units: G in gf/(cm·deg), 2HG and 2HG5 in gf/cm.
    pub fn from_kes_units(
        g_gf_cm_deg: f64,
        two_hg_gf_cm: f64,
        two_hg5_gf_cm: Option<f64>,
    ) -> Result<Self, InvalidValue> {
        Self::from_kes(
            units::shear_stiffness_from_kes(g_gf_cm_deg),
            units::force_from_kes(two_hg_gf_cm),
            two_hg5_gf_cm.map(units::force_from_kes),
        )
    }

    /// An elastic characteristic without hysteresis: τ = Gγ (G in N/(m·rad), > 0).
    pub fn elastic(g_n_per_m_rad: f64) -> Result<Self, InvalidValue> {
        Self::from_kes(g_n_per_m_rad, 0.0, None)
    }

    /// The loop of a measured force–angle record, reduced to G, 2HG and 2HG5 as KES defines them
    /// (see [`fit_shear`]); `upper` and `lower` are `(angle rad, force N/m)` points of the two
    /// branches, each listed with the angle increasing.
    pub fn from_measured(upper: &[(f64, f64)], lower: &[(f64, f64)]) -> Result<Self, InvalidValue> {
        fit_shear(upper, lower).map(|f| f.shear_loop)
    }

    /// The same loop with a reversal dead band: a change of direction counts as a turning point
    /// only once γ has moved back by more than `band` (rad) from its extreme, so the jitter of an
    /// iterative solver does not start minor loops. Negative or NaN bands are treated as 0.
    #[must_use]
    pub fn with_deadband(mut self, band_rad: f64) -> Self {
        self.deadband = if band_rad > 0.0 { band_rad } else { 0.0 };
        self
    }

    /// The reversal dead band, rad.
    pub fn deadband(&self) -> f64 {
        self.deadband
    }

    /// Shear stiffness G, N/(m·rad).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Half the loop width at `gamma` (rad), N/m: HG up to 0.5°, linear to HG5 at 5°, HG5
    /// beyond; even in γ.
    pub fn half_width(&self, gamma: f64) -> f64 {
        let x = gamma.abs();
        let (lo, hi) = KES_SHEAR_ANGLES;
        if x <= lo {
            self.hg
        } else if x >= hi {
            self.hg5
        } else {
            self.hg + (self.hg5 - self.hg) * (x - lo) / (hi - lo)
        }
    }

    /// d h/dγ at `gamma` (the slope of the half width; the value right of a kink).
    fn half_width_slope(&self, gamma: f64) -> f64 {
        let x = gamma.abs();
        let (lo, hi) = KES_SHEAR_ANGLES;
        if x >= lo && x < hi {
            (self.hg5 - self.hg) / (hi - lo) * gamma.signum()
        } else {
            0.0
        }
    }

    /// The branch travelled while γ rises, `Gγ + h(|γ|)`, N/m.
    pub fn upper(&self, gamma: f64) -> f64 {
        self.stiffness * gamma + self.half_width(gamma)
    }

    /// The branch travelled while γ falls, `Gγ − h(|γ|)`, N/m.
    pub fn lower(&self, gamma: f64) -> f64 {
        self.stiffness * gamma - self.half_width(gamma)
    }

    /// Whether the loop has hysteresis (2HG or 2HG5 > 0); an elastic one needs no state.
    pub fn is_hysteretic(&self) -> bool {
        self.hg > 0.0 || self.hg5 > 0.0
    }

    /// The join angle Δ_j, rad: a curve from a turning point on a branch reaches the opposite
    /// branch after Δ_j, the initial curve reaches its branch after Δ_j/2. 0 when elastic.
    pub fn join_angle(&self) -> f64 {
        self.join
    }

    /// The slope dτ/dγ of the initial curve at rest, N/(m·rad): `G + 4HG/Δ_j` (3G unless the
    /// join angle is capped); G when elastic.
    pub fn initial_slope(&self) -> f64 {
        if self.join > 0.0 {
            self.stiffness + 4.0 * self.hg / self.join
        } else {
            self.stiffness
        }
    }

    /// An upper bound of [`ShearState::tangent`] over every state and angle, N/(m·rad):
    /// `G + |HG5 − HG|/4.5° + 4·max(HG, HG5)/Δ_j` (the steepest start of a curve).
    pub fn max_tangent(&self) -> f64 {
        let growth = (self.hg5 - self.hg).abs() / (KES_SHEAR_ANGLES.1 - KES_SHEAR_ANGLES.0);
        if self.join > 0.0 {
            self.stiffness + growth + 4.0 * self.hg.max(self.hg5) / self.join
        } else {
            self.stiffness
        }
    }

    /// The branch travelled in direction `d` (+1 rising, −1 falling) and the opposite one.
    #[inline]
    fn branches(&self, gamma: f64, rising: bool) -> (f64, f64) {
        let (g, h) = (self.stiffness * gamma, self.half_width(gamma));
        if rising {
            (g + h, g - h)
        } else {
            (g - h, g + h)
        }
    }

    /// Slopes of the target and opposite branches.
    #[inline]
    fn branch_slopes(&self, gamma: f64, rising: bool) -> (f64, f64) {
        let dh = self.half_width_slope(gamma);
        let g = self.stiffness;
        if rising {
            (g + dh, g - dh)
        } else {
            (g - dh, g + dh)
        }
    }

    /// The initial curve from rest at `gamma`: `sign(γ)·(upper(|γ|) − 2h·q)`, q = ½(1 − 2|γ|/Δ_j)².
    fn initial_curve(&self, gamma: f64) -> f64 {
        let x = gamma.abs();
        let (up, lo) = self.branches(x, true);
        let r = if self.join > 0.0 {
            (1.0 - 2.0 * x / self.join).max(0.0)
        } else {
            0.0
        };
        let q = 0.5 * r * r;
        (up - (up - lo) * q).copysign(gamma)
    }

    /// dτ/dγ of the initial curve (even in γ).
    fn initial_slope_at(&self, gamma: f64) -> f64 {
        let x = gamma.abs();
        let (up, lo) = self.branches(x, true);
        let (dup, dlo) = self.branch_slopes(x, true);
        let (r, dr) = if self.join > 0.0 && 2.0 * x < self.join {
            (1.0 - 2.0 * x / self.join, -2.0 / self.join)
        } else {
            (0.0, 0.0)
        };
        let (q, dq) = (0.5 * r * r, r * dr);
        dup - (dup - dlo) * q - (up - lo) * dq
    }
}

/// What a [`ShearState`] is travelling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// The initial curve from rest.
    Virgin,
    /// γ rising after a turning point (heading for the upper branch).
    Rising,
    /// γ falling after a turning point (heading for the lower branch).
    Falling,
}

/// The shear hysteresis state of one cell (or cell corner): the last angle, the extreme of the
/// current direction of travel, and the turning point of the curve it travels. Five words,
/// `Copy`, O(1) to evaluate and update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShearState {
    angle: f64,
    extreme: f64,
    turn: f64,
    q0: f64,
    mode: Mode,
}

impl Default for ShearState {
    fn default() -> Self {
        Self::VIRGIN
    }
}

impl ShearState {
    /// At rest, never sheared.
    pub const VIRGIN: Self = Self {
        angle: 0.0,
        extreme: 0.0,
        turn: 0.0,
        q0: 0.5,
        mode: Mode::Virgin,
    };

    /// The last committed angle, rad.
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// The last turning point `(γ_t, τ_t)` on `l`, or `None` while on the initial curve.
    pub fn turning_point(&self, l: &ShearLoop) -> Option<(f64, f64)> {
        (self.mode != Mode::Virgin).then(|| (self.turn, self.eval(l, self.turn)))
    }

    /// Shear force per width τ (N/m) at `gamma` (rad) if the cell moved there now, without
    /// committing (for the iterations inside a step). O(1). A non-finite angle gives NaN.
    #[inline]
    pub fn stress(&self, l: &ShearLoop, gamma: f64) -> f64 {
        match self.advance(l, gamma) {
            Some(next) => next.eval(l, gamma),
            None => f64::NAN,
        }
    }

    /// dτ/dγ (N/(m·rad)) at `gamma` on the curve [`ShearState::stress`] would use, without
    /// committing: finite, at least `G − |HG5 − HG|/4.5° > 0` and at most
    /// [`ShearLoop::max_tangent`]. At a kink (0.5°, 5°, where a curve from inside the loop meets
    /// its branch) the slope on the side of larger |γ − γ_t| is returned.
    #[inline]
    pub fn tangent(&self, l: &ShearLoop, gamma: f64) -> f64 {
        match self.advance(l, gamma) {
            Some(next) => next.slope(l, gamma),
            None => f64::NAN,
        }
    }

    /// Move the cell to `gamma` (rad), detecting a reversal, and return τ (N/m). O(1). A
    /// non-finite angle returns NaN and leaves the state as it was.
    #[inline]
    pub fn update(&mut self, l: &ShearLoop, gamma: f64) -> f64 {
        match self.advance(l, gamma) {
            Some(next) => {
                *self = next;
                next.eval(l, gamma)
            }
            None => f64::NAN,
        }
    }

    /// τ on the curve currently travelled at `gamma`, without reversal detection.
    pub fn branch_stress(&self, l: &ShearLoop, gamma: f64) -> f64 {
        self.eval(l, gamma)
    }

    /// Normalised distance q from the target branch on the current curve, and dq/dγ.
    #[inline]
    fn distance(&self, l: &ShearLoop, gamma: f64) -> (f64, f64) {
        let rising = self.mode == Mode::Rising;
        let s = if rising {
            gamma - self.turn
        } else {
            self.turn - gamma
        };
        if s <= 0.0 || l.join <= 0.0 {
            return (self.q0, 0.0);
        }
        let u = s / l.join;
        let q = self.q0 - progress(u);
        if q <= 0.0 {
            return (0.0, 0.0);
        }
        // dq/dγ = −φ′(u)/Δ_j · ds/dγ, ds/dγ = ±1.
        let dq = -progress_slope(u) / l.join;
        (q, if rising { dq } else { -dq })
    }

    #[inline]
    fn eval(&self, l: &ShearLoop, gamma: f64) -> f64 {
        if !l.is_hysteretic() {
            return l.stiffness * gamma;
        }
        match self.mode {
            Mode::Virgin => l.initial_curve(gamma),
            Mode::Rising | Mode::Falling => {
                let (target, opposite) = l.branches(gamma, self.mode == Mode::Rising);
                let (q, _) = self.distance(l, gamma);
                target + (opposite - target) * q
            }
        }
    }

    #[inline]
    fn slope(&self, l: &ShearLoop, gamma: f64) -> f64 {
        if !l.is_hysteretic() {
            return l.stiffness;
        }
        match self.mode {
            Mode::Virgin => l.initial_slope_at(gamma),
            Mode::Rising | Mode::Falling => {
                let rising = self.mode == Mode::Rising;
                let (target, opposite) = l.branches(gamma, rising);
                let (dt, dop) = l.branch_slopes(gamma, rising);
                let (q, dq) = self.distance(l, gamma);
                dt + (dop - dt) * q + (opposite - target) * dq
            }
        }
    }

    /// The state after moving to `gamma` (None for a non-finite angle).
    #[inline]
    fn advance(&self, l: &ShearLoop, gamma: f64) -> Option<Self> {
        if !gamma.is_finite() {
            return None;
        }
        if !l.is_hysteretic() {
            return Some(Self {
                angle: gamma,
                extreme: gamma,
                ..*self
            });
        }
        // Direction of travel: +1 rising, −1 falling, 0 at rest on the initial curve.
        let dir = match self.mode {
            Mode::Virgin => {
                if self.extreme > 0.0 {
                    1.0
                } else if self.extreme < 0.0 {
                    -1.0
                } else {
                    0.0
                }
            }
            Mode::Rising => 1.0,
            Mode::Falling => -1.0,
        };
        let back = dir * (self.extreme - gamma);
        if back <= 0.0 || dir == 0.0 {
            // Onwards (or from rest): a new extreme.
            return Some(Self {
                angle: gamma,
                extreme: gamma,
                ..*self
            });
        }
        if back <= l.deadband {
            // Inside the dead band: back along the current curve, the extreme kept.
            return Some(Self {
                angle: gamma,
                ..*self
            });
        }
        // A reversal, at the edge of the dead band (the extreme itself without one).
        let turn = if l.deadband > 0.0 {
            self.extreme - dir * l.deadband
        } else {
            self.extreme
        };
        let tau_t = self.eval(l, turn);
        let rising = dir < 0.0;
        let (target, opposite) = l.branches(turn, rising);
        let width = opposite - target;
        let q0 = if width.abs() > 0.0 {
            ((tau_t - target) / width).clamp(0.0, 1.0)
        } else {
            0.0
        };
        Some(Self {
            angle: gamma,
            extreme: gamma,
            turn,
            q0,
            mode: if rising { Mode::Rising } else { Mode::Falling },
        })
    }
}

#[cfg(test)]
mod tests;
