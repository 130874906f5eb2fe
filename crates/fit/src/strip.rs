//! The turned cantilever in the PARTY solver (`docs/fit.md`, bending hysteresis): the virtual
//! instrument that observes a strip held horizontally and then with its clamp turned, and the
//! forward model that fits the solver's own B and M₀ to such observations.
//!
//! The strip is the Cantilever scenario's (1 cm wide, two nodes across, clamped by its first
//! two rows at ±h/2 about the clamp's edge), laid out straight; gravity comes on over
//! `load_time`, then the clamp turns downwards about its edge at `rate_deg_s`, holding at each
//! requested angle until every node is slower than `rest_speed`. The profiles are the
//! centreline's free points in the fixed frame (x forward, droop downwards).

use atelier_fabric::{AnisotropyForm, Fabric, Spindle};
use atelier_files::{ErrorKind, InvalidValue};
use atelier_grid::{ClothTopology, StructuredGrid, TopologyError};
use atelier_solver::kes::Direction as StripDirection;
use atelier_solver::{
    Cloth, ClothError, ClothState, ParamError, PinMotion, Solver, StepError, StepInput, StepParams,
};
use nalgebra::{DVector, Vector3};

use crate::cloth::ProfilePoint;
use crate::turned::{TurnedProfile, minimise};

/// Why the turned strip could not be run or fitted.
#[derive(Debug, thiserror::Error)]
pub enum StripError {
    /// An argument out of range (the overhang, the cell count, a clamp angle).
    #[error(transparent)]
    Invalid(#[from] InvalidValue),
    /// The strip's grid could not be built.
    #[error(transparent)]
    Topology(#[from] TopologyError),
    /// The strip's cloth or its clamp could not be built.
    #[error(transparent)]
    Cloth(#[from] ClothError),
    /// The step parameters are out of range.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// A step failed (the stage and node are in the source).
    #[error("at {clamp_deg:.1}°: {source}")]
    Step {
        /// The clamp's angle when it failed, degrees.
        clamp_deg: f64,
        /// The step's error.
        source: StepError,
    },
    /// A hold ran out of time before the strip came to rest.
    #[error(
        "not at rest {max_hold:.0} s after turning to {clamp_deg:.1}° (fastest node {fastest:.2e} m/s)"
    )]
    NotAtRest {
        /// The longest hold, s.
        max_hold: f64,
        /// The clamp's angle, degrees.
        clamp_deg: f64,
        /// The fastest node's speed at the end of the hold, m/s.
        fastest: f64,
    },
    /// The fit's first strip did not come to rest.
    #[error(
        "the solver's strip does not come to rest at the start B {rigidity:.3e} N·m, M₀ {residual_moment:.3e} N"
    )]
    Start {
        /// B, N·m.
        rigidity: f64,
        /// M₀, N.
        residual_moment: f64,
    },
}

/// How the turned strip is run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TurnedRun {
    /// Cells along the overhang. Default 10.
    pub segments: usize,
    /// Damping c/S, kg/(m²·s). Default 1.
    pub damping: f64,
    /// Clamp turning rate, °/s. Default 22.5.
    pub rate_deg_s: f64,
    /// Time over which gravity comes on, s. Default 1.
    pub load_time: f64,
    /// Every node slower than this at a hold, m/s. Default 1e-3.
    pub rest_speed: f64,
    /// Longest hold, s. Default 30.
    pub max_hold: f64,
}

impl Default for TurnedRun {
    fn default() -> Self {
        Self {
            segments: 10,
            // Quasi-static (measured, `docs/fit.md`, "The instrument's rate and damping"): at
            // 5 kg/(m²·s) and 45°/s the drag at silk's tip (5 mg/cm², overhang 2.2 cm) was 18 %
            // of its weight while the clamp turned, c·ωL against w·g, and the hysteretic strip
            // kept the path's memory: the continuum fit read silk's B 10 % high and M₀ 34 % low.
            // Here the drag is 1.8 % and every fixture strip at 16 cells gives B within 1.6 %
            // and M₀ within 5.1 %.
            damping: 1.0,
            rate_deg_s: 22.5,
            load_time: 1.0,
            rest_speed: 1e-3,
            max_hold: 30.0,
        }
    }
}

/// The strip of `fabric` cut along `direction`, overhanging by `overhang` (m), observed at
/// each of `angles` (degrees, non-decreasing, in [0, 180]). Step parameters: Δt = 0.25·h,
/// shape tolerance 1e-8 m (the default 1e-6 m over this Δt leaves the nodes jittering at cm/s),
/// `bending.implicit_stick_slope` on (without it a hysteretic strip chatters and never rests).
pub fn turned_strip(
    fabric: &Fabric,
    direction: StripDirection,
    overhang: f64,
    angles: &[f64],
    run: &TurnedRun,
) -> Result<Vec<TurnedProfile>, StripError> {
    if !(overhang.is_finite() && overhang > 0.0) {
        return Err(InvalidValue::new(
            ErrorKind::OutOfRange,
            "overhang",
            format!("{overhang} m: need a positive overhang"),
        )
        .into());
    }
    if run.segments < 4 {
        return Err(InvalidValue::new(
            ErrorKind::OutOfRange,
            "segments",
            format!("{} cells: need at least 4", run.segments),
        )
        .into());
    }
    let mut last = 0.0;
    for (k, &a) in angles.iter().enumerate() {
        if !(a.is_finite() && (last..=180.0).contains(&a)) {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                format!("angles[{k}]"),
                format!("{a}°: angles must rise from 0 to at most 180"),
            )
            .into());
        }
        last = a;
    }
    let segments = run.segments;
    let h = overhang / (segments as f64 + 0.5);
    let nv = segments + 2;
    let mut grid = StructuredGrid::sheet(2, nv, 0.01, (nv - 1) as f64 * h);
    if direction == StripDirection::Weft {
        // Warp across the strip: the strip runs along the weft.
        grid.grain_angle = 0.0;
    }
    let topo = ClothTopology::from_structured(&grid)?;
    let mut cloth = Cloth::new(topo, fabric, AnisotropyForm::Thesis)?;
    let place = |[x, y]: [f64; 2]| Vector3::new(y - 0.5 * h, x, 0.0);
    let rest = cloth.topology().rest_positions()[..4].to_vec();
    let clamp = |cloth: &mut Cloth, beta: f64| -> Result<(), StripError> {
        for (node, &r) in rest.iter().enumerate() {
            let p = place(r);
            let q = Vector3::new(p.x * beta.cos(), p.y, -p.x * beta.sin());
            cloth.pin(node as u32, q, PinMotion::Fixed)?;
        }
        Ok(())
    };
    clamp(&mut cloth, 0.0)?;
    let mut state = ClothState::placed(&cloth, place);
    let params = StepParams {
        damping: run.damping,
        shape: atelier_solver::ShapeParams {
            tolerance: 1e-8,
            ..atelier_solver::ShapeParams::default()
        },
        bending: atelier_solver::BendingParams {
            implicit_stick_slope: true,
            ..atelier_solver::BendingParams::default()
        },
        ..StepParams::default()
    };
    params.validate()?;
    let full = StepInput::new(0.25 * h);
    full.validate()?;
    let mut solver = Solver::new();
    let rate = run.rate_deg_s.to_radians();
    let mut beta = 0.0f64;
    let mut profiles = Vec::with_capacity(angles.len());
    for &target in angles {
        let target = target.to_radians();
        let start = state.time;
        loop {
            let f = (state.time / run.load_time).min(1.0);
            let input = StepInput {
                gravity: full.gravity.map(|c| c * f),
                ..full
            };
            if beta < target {
                beta = (beta + rate * input.dt).min(target);
                clamp(&mut cloth, beta)?;
            }
            solver
                .step(&cloth, &mut state, &params, input)
                .map_err(|source| StripError::Step {
                    clamp_deg: beta.to_degrees(),
                    source,
                })?;
            let fastest = state
                .velocities
                .iter()
                .map(|v| v.norm())
                .fold(0.0, f64::max);
            if f >= 1.0 && beta >= target && state.time - start > 0.5 && fastest < run.rest_speed {
                break;
            }
            if state.time - start > run.max_hold {
                return Err(StripError::NotAtRest {
                    max_hold: run.max_hold,
                    clamp_deg: beta.to_degrees(),
                    fastest,
                });
            }
        }
        let points = (1..nv)
            .map(|j| {
                let p = (state.positions[2 * j] + state.positions[2 * j + 1]) * 0.5;
                ProfilePoint {
                    s: ((j as f64 - 0.5) * h).min(overhang),
                    x: p.x,
                    droop: -p.z,
                }
            })
            .collect();
        profiles.push(TurnedProfile {
            clamp_deg: beta.to_degrees(),
            points,
        });
    }
    Ok(profiles)
}

/// The outcome of fitting the solver's own B and M₀ to turned-strip profiles.
#[derive(Clone, Debug, PartialEq)]
pub struct PartyHysteresisFit {
    /// Bending rigidity B, N·m.
    pub rigidity: f64,
    /// Residual moment M₀, N.
    pub residual_moment: f64,
    /// RMS distance of the points from the solver's strip, m.
    pub rms: f64,
    /// Solver runs made.
    pub runs: usize,
    /// How the minimiser ended.
    pub termination: String,
}

struct PartyProblem<'a> {
    base: &'a Fabric,
    direction: StripDirection,
    overhang: f64,
    profiles: &'a [TurnedProfile],
    angles: Vec<f64>,
    run: TurnedRun,
    runs: std::sync::atomic::AtomicUsize,
}

impl PartyProblem<'_> {
    fn residuals_at(&self, p: &DVector<f64>) -> Option<DVector<f64>> {
        self.runs.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let spindle = Spindle::new(p[0].exp(), p[1].exp()).ok()?;
        let mut fabric = self.base.clone();
        match self.direction {
            StripDirection::Warp => fabric.bending.warp = spindle,
            StripDirection::Weft => fabric.bending.weft = spindle,
        }
        let shapes = turned_strip(
            &fabric,
            self.direction,
            self.overhang,
            &self.angles,
            &self.run,
        )
        .ok()?;
        let rows: usize = self.profiles.iter().map(|p| p.points.len()).sum();
        let mut r = DVector::zeros(2 * rows);
        let mut row = 0;
        for (observed, model) in self.profiles.iter().zip(&shapes) {
            let line: Vec<(f64, f64, f64)> =
                model.points.iter().map(|q| (q.s, q.x, q.droop)).collect();
            for q in &observed.points {
                let (x, y) = along(&line, q.s);
                r[row] = x - q.x;
                r[row + 1] = y - q.droop;
                row += 2;
            }
        }
        Some(r)
    }
}

/// The point at arc length `s` on a polyline of `(s, x, droop)` (the clamp's edge at s = 0),
/// linearly; beyond its ends, the end segment extended.
fn along(line: &[(f64, f64, f64)], s: f64) -> (f64, f64) {
    let mut prev = (0.0, 0.0, 0.0);
    for (k, &q) in line.iter().enumerate() {
        if s <= q.0 || k + 1 == line.len() {
            let t = if q.0 > prev.0 {
                (s - prev.0) / (q.0 - prev.0)
            } else {
                1.0
            };
            return (prev.1 + t * (q.1 - prev.1), prev.2 + t * (q.2 - prev.2));
        }
        prev = q;
    }
    (0.0, 0.0)
}

/// Fit the solver's B and M₀ of `direction` (every other value of `base` kept) so that its
/// turned strip (`run`) passes nearest the observed profiles; start from `start` (B, M₀) —
/// the continuum strip's fit ([`crate::turned::fit_turned`]) is a good one.
/// Levenberg–Marquardt (the `levenberg-marquardt` crate) on (ln B, ln M₀).
pub fn fit_turned_party(
    profiles: &[TurnedProfile],
    overhang: f64,
    base: &Fabric,
    direction: StripDirection,
    run: &TurnedRun,
    start: (f64, f64),
) -> Result<PartyHysteresisFit, StripError> {
    let angles: Vec<f64> = profiles.iter().map(|p| p.clamp_deg).collect();
    let problem = PartyProblem {
        base,
        direction,
        overhang,
        profiles,
        angles,
        run: *run,
        runs: std::sync::atomic::AtomicUsize::new(0),
    };
    let start = DVector::from_vec(vec![start.0.ln(), start.1.ln()]);
    let r0 = problem.residuals_at(&start).ok_or(StripError::Start {
        rigidity: start[0].exp(),
        residual_moment: start[1].exp(),
    })?;
    let rows = r0.len() / 2;
    // Central differences of 1e-3 in (ln B, ln M₀).
    let (p, termination) = minimise(start, 1e-3, |p| problem.residuals_at(p));
    let cost = problem
        .residuals_at(&p)
        .map_or(f64::NAN, |r| r.norm_squared());
    Ok(PartyHysteresisFit {
        rigidity: p[0].exp(),
        residual_moment: p[1].exp(),
        rms: (cost / rows as f64).sqrt(),
        runs: problem.runs.load(std::sync::atomic::Ordering::Relaxed),
        termination,
    })
}
