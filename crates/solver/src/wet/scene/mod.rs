//! Yamada's experiment (thesis §4; `method.md` §5): a square of wet cloth lying on a plane,
//! one or two of its points picked and lifted, with or without air trapped under it — run on
//! Yamada's own mass-spring model or on the PARTY step, with the same geometry, picks, plane and
//! pressure, and measured the same way.
//!
//! - [`WetScene`]: the geometry, plane, air, picks and duration;
//! - [`WetSolver`]: Yamada's mass-spring Verlet step ([`YamadaParams`]) or the PARTY step
//!   ([`StepParams`]);
//! - [`run`]: the run, sampled into a [`WetRun`] (bubble volume and pressure over time, lifted
//!   area, tent height; the final shape; wall time), stopping at a failed step with the last
//!   good state;
//! - [`WetRun::folds`]: the folds around a pinch (the thesis saw a cross of four).

use std::time::Duration;

use atelier_fabric::Fabric;
use atelier_grid::{ClothTopology, StructuredGrid, TopologyError};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::contact::PlaneContact;
use super::pressure::{Bubble, Bubbles, PressureModel, PressureParams, Surface};
use super::stage::{NodeArea, PressureStage};
use super::volume::Plane;
use crate::cloth::{Cloth, ClothError, ClothOptions, PinMotion};
use crate::params::{ParamError, StepParams};
use crate::state::ClothState;
use crate::step::{SolveStats, StepError};

pub use stepping::{largest_dt_where, largest_stable_dt, run, yamada_springs};

mod measure;
mod stepping;

type V3 = Vector3<f64>;

/// A point picked and dragged in a straight line (Yamada's user drag, scripted).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pick {
    /// Where on the cloth, as fractions of its side along x and y ([0.5, 0.5]: the centre); the
    /// nearest node is picked.
    pub at: [f64; 2],
    /// How far it is moved from where it lies, m.
    pub by: [f64; 3],
    /// When the drag starts, s. Default 0.
    #[serde(default)]
    pub start: f64,
    /// Speed along the line, m/s (> 0).
    pub speed: f64,
    /// When it is let go, s; none: held to the end. Default none.
    #[serde(default)]
    pub release: Option<f64>,
}

/// A dome of the cloth at the start (air trapped under it, for the pocket model): the cloth is
/// raised by `height·(1 − (r/radius)²)²` within `radius` of `at`; it holds `π·radius²·height/3`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dome {
    /// Centre, as fractions of the cloth's side along x and y.
    pub at: [f64; 2],
    /// Radius, m.
    pub radius: f64,
    /// Height at the centre, m.
    pub height: f64,
}

/// The scene: a square cloth flat on the horizontal plane z = 0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WetScene {
    /// Side of the square, m. Range (0, 10]; default 0.3 (the thesis).
    pub size: f64,
    /// Particles per side (the cloth has `particles²`). Range [2, 1000]; default 50 (the
    /// thesis's 2 500).
    pub particles: usize,
    /// Height of a node lying on the plane (Yamada's sphere radius; PARTY's skin), m. Range
    /// [0, 0.01]; default 0.5 mm.
    pub rest: f64,
    /// Friction on the plane μ; none: the fabric's. Default none.
    pub friction: Option<f64>,
    /// The air (none: a dry cloth, no pressure force). Default: Yamada's single bubble with no
    /// air.
    pub pressure: Option<PressureParams>,
    /// The area each node stands for in the pressure force. Default `Lumped`, consistent with
    /// the cloth's lumped masses (Yamada's `Uniform` area goes with his uniform masses; with
    /// lumped masses it gives the edge nodes twice the pressure per mass of the others, and a
    /// floating cloth curls up at its edges).
    pub node_area: NodeArea,
    /// Start height of the cloth above its rest height, m; none: the height at which the
    /// single bubble holds its air at atmospheric pressure (v₀ over the cloth's area; 0 for no
    /// air, or for pockets). Default none.
    pub start_height: Option<f64>,
    /// Domes of the cloth at the start. Default none.
    pub domes: Vec<Dome>,
    /// The picks.
    pub picks: Vec<Pick>,
    /// Simulated time, s. Range (0, 100]; default 1.5.
    pub duration: f64,
    /// Interval between samples of the series, s. Default 1/120.
    pub sample_interval: f64,
    /// Interval between recorded frames of the cloth, s; none: only the final state. Default
    /// none.
    pub frame_interval: Option<f64>,
}

impl Default for WetScene {
    fn default() -> Self {
        Self {
            size: 0.3,
            particles: 50,
            rest: 0.5e-3,
            friction: None,
            pressure: Some(PressureParams::default()),
            node_area: NodeArea::Lumped,
            start_height: None,
            domes: Vec::new(),
            picks: Vec::new(),
            duration: 1.5,
            sample_interval: 1.0 / 120.0,
            frame_interval: None,
        }
    }
}

/// Yamada's springs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Springs {
    /// Each edge's stiffness from the fabric's secant modulus at this fraction of the loop's
    /// apex force ([`crate::baselines`]): structural springs from warp and weft, shear
    /// (diagonal) springs from the bias loops, which are softer.
    FromFabric {
        /// Fraction of the apex force, (0, 1].
        fraction: f64,
    },
    /// Hand-set, as in the thesis: every structural (axial) spring, every shear (diagonal)
    /// spring, N/m.
    Given {
        /// Structural springs, N/m.
        structural: f64,
        /// Shear springs, N/m.
        shear: f64,
    },
}

/// Yamada's mass-spring step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct YamadaParams {
    /// Δt, s. Default 1/12 000 (the thesis).
    pub dt: f64,
    /// The springs. Default hand-set, structural 200 N/m, shear 50 N/m (the thesis gives no
    /// values, only that they were set for stability at its Δt: these are about the stiffest
    /// that stay stable at 1/12 000 s with the wet satin's 4.5 mg particles, `docs/wet.md`).
    pub springs: Springs,
    /// Linear damping per area, kg/(m²·s) (the thesis has none). Default 0.
    pub damping: f64,
}

impl Default for YamadaParams {
    fn default() -> Self {
        Self {
            dt: 1.0 / 12000.0,
            springs: Springs::Given {
                structural: 200.0,
                shear: 50.0,
            },
            damping: 0.0,
        }
    }
}

/// The PARTY step on a wet scene: its Δt and its parameters. In a scenario file
/// `Party(dt: 0.005, step: (shape: (tolerance: 1e-6)))`; both may be left out.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WetPartyParams {
    /// Δt, s. Range (0, 0.1]; default 0.01 (the thesis's).
    pub dt: f64,
    /// The step's parameters ([`StepParams`]; gravity is the scene's, along −z).
    pub step: StepParams,
}

impl Default for WetPartyParams {
    fn default() -> Self {
        Self {
            dt: 0.01,
            step: StepParams::default(),
        }
    }
}

/// Which solver runs the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum WetSolver {
    /// Yamada's mass-spring Verlet model.
    Yamada(YamadaParams),
    /// The PARTY step, with the pressure as its stage.
    Party(WetPartyParams),
}

impl WetSolver {
    /// Its Δt, s.
    pub fn dt(&self) -> f64 {
        match self {
            WetSolver::Yamada(p) => p.dt,
            WetSolver::Party(p) => p.dt,
        }
    }

    /// The same solver with another Δt.
    pub fn with_dt(&self, dt: f64) -> Self {
        match self {
            WetSolver::Yamada(p) => WetSolver::Yamada(YamadaParams { dt, ..*p }),
            WetSolver::Party(p) => WetSolver::Party(WetPartyParams { dt, ..p.clone() }),
        }
    }

    /// "yamada" or "party".
    pub fn name(&self) -> &'static str {
        match self {
            WetSolver::Yamada(_) => "yamada",
            WetSolver::Party(_) => "party",
        }
    }
}

/// Why a wet scene cannot be run.
#[derive(Debug, thiserror::Error)]
pub enum WetError {
    /// A scene field is out of range.
    #[error("wet scene: `{field}` = {value} is outside {range}")]
    Range {
        /// The field.
        field: &'static str,
        /// Its value.
        value: String,
        /// Its range.
        range: &'static str,
    },
    /// The grid could not be cooked.
    #[error(transparent)]
    Topology(#[from] TopologyError),
    /// The cloth could not be assembled.
    #[error(transparent)]
    Cloth(#[from] ClothError),
    /// A step parameter is out of range.
    #[error(transparent)]
    Params(#[from] ParamError),
}

/// One sample of a run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WetSample {
    /// Simulated time, s.
    pub time: f64,
    /// Volume between the cloth and the plane (Y3.10), m³.
    pub volume: f64,
    /// The trapped air's pressure (the single bubble's, or the pockets' volume-weighted mean),
    /// Pa; none without pressure.
    pub pressure: Option<f64>,
    /// Bubbles (pockets) at this time; 0 without pressure.
    pub bubbles: usize,
    /// The lowest and highest pressure of a sealed bubble, Pa; none without one.
    pub pressure_range: Option<[f64; 2]>,
    /// The trapped air, as its volume at atmospheric pressure (Σ K / P_a), m³; none without
    /// pressure.
    pub air: Option<f64>,
    /// Cloth area with a node more than [`LIFTED`] above its rest height, m².
    pub lifted_area: f64,
    /// The highest node that is not held, above its rest height, m.
    pub tent_height: f64,
    /// Largest strain |l/l⁰ − 1| of a structural (axial) edge.
    pub max_strain: f64,
    /// Fastest node, m/s.
    pub max_speed: f64,
}

/// A node this far above its rest height is lifted off the plane (metrics only), m.
pub const LIFTED: f64 = 1e-3;

/// A failed step: when, and what.
#[derive(Clone, Debug, PartialEq)]
pub struct WetFailure {
    /// Simulated time of the last good state, s.
    pub time: f64,
    /// The step's error.
    pub error: StepError,
}

/// A finished (or stopped) run.
#[derive(Clone, Debug)]
pub struct WetRun {
    /// "yamada" or "party".
    pub solver: &'static str,
    /// Δt, s.
    pub dt: f64,
    /// Steps taken.
    pub steps: usize,
    /// Simulated time reached, s.
    pub time: f64,
    /// Wall time of the steps (setup and sampling excluded).
    pub wall: Duration,
    /// Wall time of the pressure force within the steps (zero without pressure; Yamada's
    /// timed around its evaluation, PARTY's as the step's pressure stage).
    pub pressure_wall: Duration,
    /// Wall time of building the cloth.
    pub setup: Duration,
    /// The series.
    pub samples: Vec<WetSample>,
    /// Positions at the end (the last good state after a failure), m.
    pub positions: Vec<V3>,
    /// Rest positions of the nodes on the cloth, m (x, y in [0, size]).
    pub rest: Vec<[f64; 2]>,
    /// Triangles (normals up when the cloth lies flat).
    pub triangles: Vec<[u32; 3]>,
    /// Particles per side.
    pub particles: usize,
    /// Picked nodes.
    pub picked: Vec<u32>,
    /// The bubbles at the end (none without pressure).
    pub bubbles: Vec<Bubble>,
    /// Recorded frames (time, positions), the first at time 0 and the last the final state,
    /// when the scene asks for them.
    pub frames: Vec<(f64, Vec<V3>)>,
    /// The failed step, if one failed.
    pub failure: Option<WetFailure>,
    /// Whether the steps converged (the PARTY step's reports, counted); none for Yamada's
    /// model, which has no tolerance to meet.
    pub stats: Option<SolveStats>,
}

/// Folds around a point, from the cloth's height on a circle around it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Folds {
    /// The folds (ridges) found.
    pub count: usize,
    /// Their directions, degrees from +x, ascending.
    pub angles_deg: Vec<f64>,
    /// Their prominences, m.
    pub prominences: Vec<f64>,
    /// Largest deviation of the angle between neighbouring folds from 360°/count, degrees
    /// (0: evenly spread).
    pub spacing_deviation_deg: f64,
    /// Smallest over largest prominence (1: all folds alike).
    pub prominence_ratio: f64,
    /// Mean height of the cloth on the circle above the plane, m.
    pub mean_height: f64,
}

impl WetScene {
    /// The thesis's demo (Figs. 4.3–4.6): the default square with `air` m³ of air under it (none:
    /// dry), pinched at its centre (`points` = 1) or at two points 9 cm apart on its centre line
    /// (`points` ≥ 2), lifted 2 cm at 2 cm/s from the start and held, for 1.5 s.
    pub fn thesis_pinch(points: usize, air: Option<f64>) -> Self {
        let pick = |x: f64| Pick {
            at: [x, 0.5],
            by: [0.0, 0.0, 0.02],
            start: 0.0,
            speed: 0.02,
            release: None,
        };
        Self {
            pressure: air.map(|air| PressureParams {
                air,
                ..PressureParams::default()
            }),
            picks: if points <= 1 {
                vec![pick(0.5)]
            } else {
                vec![pick(0.35), pick(0.65)]
            },
            duration: 1.5,
            ..Self::default()
        }
    }

    /// Check every field against its range (done again by [`run`] and [`WetScene::build`]).
    pub fn validate(&self) -> Result<(), WetError> {
        let range = |field, value: f64, ok: bool, range| {
            if ok {
                Ok(())
            } else {
                Err(WetError::Range {
                    field,
                    value: value.to_string(),
                    range,
                })
            }
        };
        range(
            "size",
            self.size,
            self.size > 0.0 && self.size <= 10.0,
            "(0, 10]",
        )?;
        range(
            "particles",
            self.particles as f64,
            (2..=1000).contains(&self.particles),
            "[2, 1000]",
        )?;
        range(
            "rest",
            self.rest,
            (0.0..=0.01).contains(&self.rest),
            "[0, 0.01]",
        )?;
        range(
            "duration",
            self.duration,
            self.duration > 0.0 && self.duration <= 100.0,
            "(0, 100]",
        )?;
        range(
            "sample_interval",
            self.sample_interval,
            self.sample_interval > 0.0 && self.sample_interval.is_finite(),
            "(0, ∞)",
        )?;
        if let Some(f) = self.frame_interval {
            range("frame_interval", f, f > 0.0 && f.is_finite(), "(0, ∞)")?;
        }
        for d in &self.domes {
            range(
                "domes.at",
                d.at[0].min(d.at[1]),
                d.at.iter().all(|a| (0.0..=1.0).contains(a)),
                "[0, 1]²",
            )?;
            range(
                "domes.radius",
                d.radius,
                d.radius > 0.0 && d.radius <= self.size,
                "(0, size]",
            )?;
            range(
                "domes.height",
                d.height,
                (0.0..=1.0).contains(&d.height),
                "[0, 1]",
            )?;
        }
        if let Some(mu) = self.friction {
            range("friction", mu, (0.0..=10.0).contains(&mu), "[0, 10]")?;
        }
        if let Some(h) = self.start_height {
            range("start_height", h, (0.0..=1.0).contains(&h), "[0, 1]")?;
        }
        if let Some(p) = &self.pressure {
            range(
                "pressure.atmosphere",
                p.atmosphere,
                p.atmosphere > 0.0 && p.atmosphere < 1e7,
                "(0, 1e7)",
            )?;
            range(
                "pressure.air",
                p.air,
                (0.0..10.0).contains(&p.air),
                "[0, 10)",
            )?;
            range(
                "pressure.leak",
                p.leak,
                (0.0..1.0).contains(&p.leak),
                "[0, 1)",
            )?;
            range(
                "pressure.min_volume_fraction",
                p.min_volume_fraction,
                p.min_volume_fraction > 0.0 && p.min_volume_fraction < 1.0,
                "(0, 1)",
            )?;
            if let Bubbles::Pockets { contact } = p.bubbles {
                range(
                    "pressure.bubbles.contact",
                    contact,
                    contact > 0.0 && contact < 0.1,
                    "(0, 0.1)",
                )?;
            }
        }
        for pick in &self.picks {
            range(
                "picks.at",
                pick.at[0].min(pick.at[1]),
                pick.at.iter().all(|a| (0.0..=1.0).contains(a)),
                "[0, 1]²",
            )?;
            range(
                "picks.by",
                pick.by.iter().map(|x| x.abs()).fold(0.0, f64::max),
                pick.by.iter().all(|x| x.abs() <= 10.0),
                "[−10, 10] m",
            )?;
            range(
                "picks.speed",
                pick.speed,
                pick.speed > 0.0 && pick.speed <= 100.0,
                "(0, 100] m/s",
            )?;
            range("picks.start", pick.start, pick.start >= 0.0, "[0, ∞)")?;
            if let Some(r) = pick.release {
                range("picks.release", r, r >= pick.start, "[start, ∞)")?;
            }
        }
        Ok(())
    }

    /// The start height above the rest height, m.
    pub fn start_lift(&self) -> f64 {
        self.start_height.unwrap_or(match &self.pressure {
            Some(p) if p.bubbles == Bubbles::Single => p.air / (self.size * self.size),
            _ => 0.0,
        })
    }

    /// The node nearest to `at` (fractions of the side).
    pub fn node_at(&self, at: [f64; 2]) -> u32 {
        let k =
            |a: f64| ((a * (self.particles - 1) as f64).round() as usize).min(self.particles - 1);
        (k(at[1]) * self.particles + k(at[0])) as u32
    }

    /// The plane contact with the fabric's friction unless the scene gives its own.
    pub fn contact(&self, fabric: &Fabric) -> PlaneContact {
        PlaneContact {
            plane: Plane::horizontal(0.0),
            rest: self.rest,
            friction: self.friction.unwrap_or(fabric.friction),
        }
    }

    /// The cloth (picks pinned with their ramps) and its state at time 0.
    pub fn build(&self, fabric: &Fabric) -> Result<(Cloth, ClothState), WetError> {
        self.validate()?;
        let n = self.particles;
        let grid = StructuredGrid::sheet(n, n, self.size, self.size);
        let topology = ClothTopology::from_structured(&grid)?;
        let mut cloth = Cloth::with_options(topology, fabric, ClothOptions::default())?;
        let (half, z0) = (0.5 * self.size, self.rest + self.start_lift());
        let place = |[x, y]: [f64; 2]| {
            let dome: f64 = self
                .domes
                .iter()
                .map(|d| {
                    let (cx, cy) = (d.at[0] * self.size, d.at[1] * self.size);
                    let r2 = ((x - cx).powi(2) + (y - cy).powi(2)) / (d.radius * d.radius);
                    if r2 < 1.0 {
                        d.height * (1.0 - r2).powi(2)
                    } else {
                        0.0
                    }
                })
                .sum();
            V3::new(x - half, y - half, z0 + dome)
        };
        let state0 = ClothState::placed(&cloth, place);
        for pick in &self.picks {
            let node = self.node_at(pick.at);
            let anchor = state0.positions[node as usize];
            let to = anchor + V3::from(pick.by);
            cloth.pin(
                node,
                anchor,
                PinMotion::Ramp {
                    to: to.into(),
                    start: pick.start,
                    speed: pick.speed,
                },
            )?;
        }
        let state = ClothState::placed(&cloth, place);
        Ok((cloth, state))
    }

    /// The pressure stage of the scene on `cloth` (none when the scene is dry).
    pub fn pressure_stage(&self, cloth: &Cloth) -> Option<PressureStage> {
        self.pressure.map(|p| {
            let model = PressureModel::new(
                p,
                Surface::Plane {
                    plane: Plane::horizontal(0.0),
                    rest: self.rest,
                },
            );
            PressureStage::for_cloth(model, cloth.topology(), self.node_area)
        })
    }
}

#[cfg(test)]
mod tests;
