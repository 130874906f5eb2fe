//! The force of the air on a wet cloth (Yamada (Y3.7)–(Y3.9)): the atmosphere presses on the
//! cloth's outside, the air trapped between the cloth and the surface presses on its inside,
//!
//! `F_p = −N S (P_a − P_b) = N S (P_b − P_a)`, `P_b = K / v`, `K = P_a v₀`,
//!
//! N the cloth's unit normal out of the bubble, S the cloth area a node stands for, v the
//! bubble's volume ([`super::volume`]) and v₀ the amount of air, as its volume at atmospheric
//! pressure. Water in the weave seals the cloth, so the air stays (Boyle at constant
//! temperature) unless a leak is given.
//!
//! **Sign.** The thesis prints (Y3.7) as `F_p = N S (P_a − P_b)` with N pointing from the bubble
//! outwards; read literally that pushes a cloth away from a vacuum. Its own text (§3.4, and the
//! conclusion's "inward force" that makes a lifted wet cloth stick) and physics need the
//! atmosphere to press the cloth *into* a bubble below atmospheric pressure, so the force here is
//! the negative of the printed one (`docs/wet.md`, deviations).
//!
//! Two bubble models:
//!
//! - [`Bubbles::Single`] (the thesis): one bubble under the whole cloth, every node pressed by
//!   `P_a − P_b`; with no air (v₀ = 0) the bubble is a vacuum and the whole atmosphere presses.
//! - [`Bubbles::Pockets`] (past the thesis): the cloth's lifted regions — triangles with a node
//!   farther than `contact` from the surface, connected through shared edges — are separate
//!   pockets, each with its own air. A pocket open to the cloth's edge is vented (at atmospheric
//!   pressure); a sealed pocket keeps its air across steps (split in proportion to volume when it
//!   splits, summed when pockets merge; a new sealed pocket lifting off the surface starts empty,
//!   a vacuum). Nodes in contact bound no pocket and feel no net pressure.
//!
//! **Large steps.** A sealed bubble is a very stiff spring: `dP/dV = −P/V`, so a 30 cm cloth
//! floating on 400 cm³ of air bounces on it at about 2 kHz. Yamada's Δt of 1/12 000 s resolves
//! that with the pressure taken at the current volume ([`PressureModel::add_forces`]). A solver
//! with a far larger step (the PARTY step) also takes it at the end of the step (backward
//! Euler), as a compliant volume constraint among its shape constraints
//! ([`PressureModel::project`], the XPBD form of the air's energy `P_a V − K ln V`): at the
//! predicted positions, the bubble's volume V and the pressure P' that the free nodes' motion
//! under `P' − P` would bring it to, `P'·(V + Δt²·s·(P' − P)) = K` with `s = Σ |g_i|²/m_i`,
//! `g_i = S_i N_i ≈ ∂V/∂x_i`, a quadratic solved exactly. Interleaved with the length
//! constraints, the step ends with Boyle's law met at its end positions; without it, the stale
//! pressure of the start of a 2 ms step overshoots the volume by tens of cm³ and the step
//! diverges (measured, `docs/wet.md`).
//!
//! An optional leak lets air through the wet fabric: `dK/dt = P_a q A (P_a − P_b)` for a sealed
//! pocket of lifted area A, q the fabric's air permeability when wet (m³ of air at atmospheric
//! pressure per second, per m² of cloth, per Pa of pressure difference). Default 0 (Yamada's
//! sealed cloth; the value is an assumption to be measured).

use atelier_collide::RigidParts;
use nalgebra::Vector3;

use super::volume::{Plane, prism};

mod pockets;

type V3 = Vector3<f64>;

/// Standard atmospheric pressure, Pa (Yamada's P_a).
pub const ATMOSPHERE: f64 = 101_325.0;

/// The surface the cloth lies on and traps air against.
pub enum Surface {
    /// A plane; nodes lying on it sit `rest` above it (Yamada's particles are spheres).
    Plane {
        /// The plane.
        plane: Plane,
        /// Height of a node lying flat on the plane, m.
        rest: f64,
    },
    /// A body: the union of rigid closed parts ([`RigidParts`], at the end of its current
    /// motion); a node's footprint is its nearest body point, lifted by `rest` along the normal.
    Body {
        /// The body.
        parts: Box<RigidParts>,
        /// Distance of a node lying on the body from its surface, m.
        rest: f64,
        /// How far from the body a footprint is searched, m (beyond it a node is far away).
        reach: f64,
    },
}

/// How the trapped air is divided.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Bubbles {
    /// Yamada's model: one bubble for the whole cloth.
    Single,
    /// Separate pockets of the lifted cloth, each with its own air.
    Pockets {
        /// A node farther than this from its footprint is lifted, m.
        contact: f64,
    },
}

/// The pressure model's parameters.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PressureParams {
    /// Atmospheric pressure P_a, Pa. Default 101 325.
    pub atmosphere: f64,
    /// Trapped air v₀ (its volume at atmospheric pressure), m³. Default 0.
    pub air: f64,
    /// Single bubble (Yamada) or pockets. Default `Single`.
    pub bubbles: Bubbles,
    /// Air permeability of the wet fabric q, m³/(s·m²·Pa). Default 0 (sealed).
    pub leak: f64,
    /// The largest pressure difference the wet fabric holds, Pa: beyond it air passes through
    /// the water in its pores (their capillary entry pressure, Young–Laplace `4γ cos θ / d`:
    /// about 10 kPa for 30 µm pores in water), so that `|P_a − P_b|` never exceeds it and the
    /// bubble gains (or loses) the air that keeps it there. None (default): the fabric holds any
    /// difference (Yamada's sealed cloth).
    pub breakthrough: Option<f64>,
    /// A bubble squeezed below this fraction of its air's atmospheric volume is taken at it
    /// (the pressure then at most P_a over the fraction): keeps K/v finite when the cloth is
    /// pressed flat on trapped air. Default 0.01.
    pub min_volume_fraction: f64,
}

impl Default for PressureParams {
    fn default() -> Self {
        Self {
            atmosphere: ATMOSPHERE,
            air: 0.0,
            bubbles: Bubbles::Single,
            leak: 0.0,
            breakthrough: None,
            min_volume_fraction: 0.01,
        }
    }
}

/// One bubble (or pocket) now.
#[derive(Clone, Debug, PartialEq)]
pub struct Bubble {
    /// Its air, K = P·V, J.
    pub air: f64,
    /// Its volume, m³.
    pub volume: f64,
    /// Its pressure, Pa.
    pub pressure: f64,
    /// The cloth area over it: the rest area of its lifted nodes, m².
    pub area: f64,
    /// Open to the cloth's edge (at atmospheric pressure).
    pub vented: bool,
    /// Its nodes (pockets only; empty for the single bubble).
    pub nodes: Vec<u32>,
}

/// What the pressure model measured at its last evaluation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PressureReport {
    /// Total trapped volume, m³ (the single bubble's, or the pockets' sum).
    pub volume: f64,
    /// The single bubble's pressure, or the pockets' volume-weighted mean (P_a with none), Pa.
    pub pressure: f64,
    /// Cloth area lifted off the surface: the rest area of the lifted nodes, m².
    pub lifted_area: f64,
    /// Highest node above its footprint, m.
    pub tent_height: f64,
    /// The bubbles.
    pub bubbles: Vec<Bubble>,
}

/// The pressure force of (Y3.7)–(Y3.9) on a cloth, with its bubbles' state.
pub struct PressureModel {
    params: PressureParams,
    surface: Surface,
    /// Pockets: each node's pocket at the last evaluation (`NONE` when in contact).
    label: Vec<u32>,
    bubbles: Vec<Bubble>,
    started: bool,
    report: PressureReport,
    // scratch
    normal: Vec<V3>,
    footprint: Vec<V3>,
    height: Vec<f64>,
    tri_volume: Vec<f64>,
    node_pressure: Vec<f64>,
    foot_normal: Vec<V3>,
    /// Each triangle's bubble at the last evaluation (`NONE`: none).
    tri_bubble: Vec<u32>,
    /// Predicted positions and heights of a projection.
    pred: Vec<V3>,
    height_y: Vec<f64>,
}

const NONE: u32 = u32::MAX;

/// A node less than this above its rest height lies on the surface (m).
const LYING: f64 = 1e-6;

/// The positive root of `a P² + c P − K = 0` (a ≥ 0, K ≥ 0), without cancellation.
fn positive_root(a: f64, c: f64, k: f64) -> f64 {
    let d = (c * c + 4.0 * a * k).sqrt();
    if c > 0.0 {
        2.0 * k / (c + d)
    } else {
        (d - c) / (2.0 * a)
    }
}

impl PressureModel {
    /// A model on `surface` with `params` (the air given as the single bubble's, or shared by
    /// the pockets present at the first evaluation in proportion to their volume).
    pub fn new(params: PressureParams, surface: Surface) -> Self {
        Self {
            params,
            surface,
            label: Vec::new(),
            bubbles: Vec::new(),
            started: false,
            report: PressureReport::default(),
            normal: Vec::new(),
            footprint: Vec::new(),
            height: Vec::new(),
            tri_volume: Vec::new(),
            node_pressure: Vec::new(),
            foot_normal: Vec::new(),
            tri_bubble: Vec::new(),
            pred: Vec::new(),
            height_y: Vec::new(),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &PressureParams {
        &self.params
    }

    /// The surface (a body's motion may be updated through it).
    pub fn surface_mut(&mut self) -> &mut Surface {
        &mut self.surface
    }

    /// The bubbles at the last evaluation.
    pub fn bubbles(&self) -> &[Bubble] {
        &self.bubbles
    }

    /// Footprints and heights of every node.
    fn measure(&mut self, positions: &[V3]) {
        let n = positions.len();
        self.footprint.resize(n, V3::zeros());
        self.foot_normal.resize(n, V3::zeros());
        self.height.resize(n, 0.0);
        match &self.surface {
            Surface::Plane { plane, rest } => {
                for (i, p) in positions.iter().enumerate() {
                    let h = plane.height(p);
                    self.footprint[i] = p - plane.normal * h + plane.normal * *rest;
                    self.foot_normal[i] = plane.normal;
                    self.height[i] = h - rest;
                }
            }
            Surface::Body { parts, rest, reach } => {
                for (i, p) in positions.iter().enumerate() {
                    match parts.nearest(p, *reach, true) {
                        Some(near) => {
                            let (q, normal) = parts.place(&near, true);
                            self.footprint[i] = q + normal * *rest;
                            self.foot_normal[i] = normal;
                            self.height[i] = near.distance - rest;
                        }
                        None => {
                            // Beyond reach: no footprint (no volume under it).
                            self.footprint[i] = *p;
                            self.foot_normal[i] = V3::zeros();
                            self.height[i] = *reach;
                        }
                    }
                }
            }
        }
    }

    /// One fused pass over the triangles at `positions` with node heights `height`: the
    /// area-weighted node normals (normalised after) and each triangle's signed volume over its
    /// footprint.
    fn triangle_pass(&mut self, positions: &[V3], use_start_heights: bool, triangles: &[[u32; 3]]) {
        let (n, nt) = (positions.len(), triangles.len());
        self.normal.clear();
        self.normal.resize(n, V3::zeros());
        self.tri_volume.resize(nt, 0.0);
        let plane = match &self.surface {
            Surface::Plane { plane, .. } => Some(plane.normal),
            Surface::Body { .. } => None,
        };
        let (normal, volume) = (&mut self.normal[..], &mut self.tri_volume[..]);
        let height = if use_start_heights {
            &self.height[..]
        } else {
            &self.height_y[..]
        };
        let footprint = &self.footprint[..];
        for (t, vol) in triangles.iter().zip(volume.iter_mut()) {
            let (i0, i1, i2) = (t[0] as usize, t[1] as usize, t[2] as usize);
            let (a, b, c) = (positions[i0], positions[i1], positions[i2]);
            let w = (b - a).cross(&(c - a));
            normal[i0] += w;
            normal[i1] += w;
            normal[i2] += w;
            *vol = match plane {
                // (Y3.10): projected area × mean height above the rest height.
                Some(up) => w.dot(&up) * (height[i0] + height[i1] + height[i2]) * (1.0 / 6.0),
                None => prism([a, b, c], [footprint[i0], footprint[i1], footprint[i2]]),
            };
        }
        for v in &mut self.normal {
            let l = v.norm();
            if l > 0.0 {
                *v /= l;
            }
        }
    }

    /// Evaluate the bubbles at `positions` and add each node's pressure force to `forces`
    /// (`node_area[i]`: the cloth area S node i stands for; `triangles` oriented away from the
    /// surface; `boundary[i]`: node i lies on the cloth's edge). `dt` advances the leak. The
    /// pressure is Boyle's at the current volume ([`PressureModel::evaluate`], then
    /// [`PressureModel::apply`]). What was measured is in [`PressureModel::report`].
    pub fn add_forces(
        &mut self,
        positions: &[V3],
        triangles: &[[u32; 3]],
        node_area: &[f64],
        boundary: &[bool],
        dt: f64,
        forces: &mut [V3],
    ) {
        self.evaluate(positions, triangles, node_area, boundary, dt);
        self.apply(node_area, forces);
    }

    /// Evaluate the bubbles at `positions`: footprints, normals, volumes, pockets, and each
    /// bubble's pressure by Boyle's law (after the breakthrough and the leak).
    pub fn evaluate(
        &mut self,
        positions: &[V3],
        triangles: &[[u32; 3]],
        node_area: &[f64],
        boundary: &[bool],
        dt: f64,
    ) {
        self.measure(positions);
        self.triangle_pass(positions, true, triangles);
        let pa = self.params.atmosphere;
        self.report.tent_height = self.height.iter().copied().fold(0.0, f64::max);
        match self.params.bubbles {
            Bubbles::Single => {
                let volume: f64 = self.tri_volume.iter().sum();
                self.tri_bubble.clear();
                self.tri_bubble.resize(triangles.len(), 0);
                if !self.started {
                    self.bubbles = vec![Bubble {
                        air: pa * self.params.air,
                        volume,
                        pressure: pa,
                        area: 0.0,
                        vented: false,
                        nodes: Vec::new(),
                    }];
                    self.started = true;
                }
                let lifted: f64 = self
                    .height
                    .iter()
                    .zip(node_area)
                    .filter(|&(&h, _)| h > LYING)
                    .map(|(_, s)| s)
                    .sum();
                let air = self.bubbles[0].air;
                let floor = self.params.min_volume_fraction * air / pa;
                let boyle = if air > 0.0 {
                    air / volume.max(floor)
                } else {
                    0.0
                };
                let (pressure, air) = self.admit(boyle, air, volume);
                let b = &mut self.bubbles[0];
                b.air = air;
                b.air += dt * pa * self.params.leak * lifted * (pa - pressure);
                b.air = b.air.max(0.0);
                b.volume = volume;
                b.pressure = pressure;
                b.area = lifted;
            }
            Bubbles::Pockets { contact } => {
                self.pockets(triangles, node_area, boundary, contact, dt);
            }
        }
        self.refresh_report();
    }

    /// The report's volume, pressure, lifted area and bubbles from the bubbles now.
    fn refresh_report(&mut self) {
        let pa = self.params.atmosphere;
        let volume: f64 = self.bubbles.iter().map(|b| b.volume).sum();
        self.report.volume = volume;
        self.report.pressure = match self.params.bubbles {
            Bubbles::Single => self.bubbles.first().map_or(pa, |b| b.pressure),
            Bubbles::Pockets { .. } if volume > 0.0 => {
                self.bubbles
                    .iter()
                    .map(|b| b.pressure * b.volume)
                    .sum::<f64>()
                    / volume
            }
            Bubbles::Pockets { .. } => pa,
        };
        self.report.lifted_area = self.bubbles.iter().map(|b| b.area).sum();
        self.report.bubbles.clone_from(&self.bubbles);
    }

    /// Add each node's pressure force `S_i N_i (P_b − P_a)` at the bubbles' current pressures
    /// (a node in no bubble, or in a vented one, feels none).
    pub fn apply(&mut self, node_area: &[f64], forces: &mut [V3]) {
        let pa = self.params.atmosphere;
        match self.params.bubbles {
            Bubbles::Single => {
                let pressure = self.bubbles.first().map_or(pa, |b| b.pressure);
                for ((f, normal), s) in forces.iter_mut().zip(&self.normal).zip(node_area) {
                    *f += normal * (s * (pressure - pa));
                }
            }
            Bubbles::Pockets { .. } => {
                self.node_pressure.clear();
                self.node_pressure.resize(forces.len(), pa);
                for b in &self.bubbles {
                    for &k in &b.nodes {
                        self.node_pressure[k as usize] = b.pressure;
                    }
                }
                for (i, f) in forces.iter_mut().enumerate() {
                    *f += self.normal[i] * (node_area[i] * (self.node_pressure[i] - pa));
                }
            }
        }
    }

    /// The backward-Euler pressure of each sealed bubble, predicted from the velocities
    /// `predicted` the step would end with without the pressure force and the constraints
    /// (pinned nodes: their prescribed velocity): the end volume is
    /// `V + Δt·gᵀu + Δt²·s·(P − P_a)` (`g_i = S_i N_i`, `s = Σ |g_i|²/m_i` over the bubble's
    /// nodes off the surface; a node lying on it counts only when moving off), and
    /// `P = K / (end volume)` a quadratic in P. Called between [`PressureModel::evaluate`] and
    /// [`PressureModel::apply`] by a large-step solver, whose first steps would otherwise
    /// launch the light cloth with a stale pressure (module docs, "Large steps").
    pub fn predict(
        &mut self,
        predicted: &[V3],
        node_area: &[f64],
        inverse_masses: &[f64],
        dt: f64,
    ) {
        let pa = self.params.atmosphere;
        let n = predicted.len();
        let single = matches!(self.params.bubbles, Bubbles::Single);
        let mut bubbles = std::mem::take(&mut self.bubbles);
        for b in &mut bubbles {
            if b.vented || (b.air <= 0.0 && self.params.breakthrough.is_none()) {
                continue;
            }
            let (mut rate, mut s) = (0.0, 0.0);
            let nodes: &mut dyn Iterator<Item = usize> = if single {
                &mut (0..n)
            } else {
                &mut b.nodes.iter().map(|&i| i as usize)
            };
            for i in nodes {
                let g = self.normal[i] * node_area[i];
                let un = g.dot(&predicted[i]);
                if self.height[i] > LYING || inverse_masses[i] == 0.0 {
                    rate += un;
                    s += inverse_masses[i] * g.norm_squared();
                } else {
                    rate += un.max(0.0);
                }
            }
            let floor = self.params.min_volume_fraction * b.air / pa;
            let a = dt * dt * s;
            let c = b.volume + dt * rate - a * pa;
            let p = if b.air <= 0.0 {
                0.0
            } else if a > 0.0 {
                positive_root(a, c, b.air)
            } else {
                b.air / c.max(floor)
            };
            let p = p.min(b.air / floor.max(f64::MIN_POSITIVE));
            (b.pressure, b.air) = self.admit(p, b.air, b.volume);
        }
        self.bubbles = bubbles;
        self.refresh_report();
    }

    /// Whether the model has been evaluated (its report measures something).
    pub fn evaluated(&self) -> bool {
        self.started
    }

    /// What the last [`PressureModel::add_forces`] measured.
    pub fn report(&self) -> &PressureReport {
        &self.report
    }

    /// The surface's reaction (Yamada's normal force (Y3.4)) on the nodes that rest on it this
    /// step: those lying on it at the last [`PressureModel::add_forces`], and those its load
    /// would bring onto it within the step (`h + Δt·v·n + Δt²·m⁻¹·f·n ≤ 0`). The part of
    /// `forces` pressing such a node into the surface, `r_i = max(0, −f_i·n_i)·n_i`, is added to
    /// `forces` and written to `reaction` (zero elsewhere). A large-step solver balances its
    /// internal forces against the loads the surface does not carry, then takes the reaction
    /// back out so that the contact's friction still feels the full normal load (Y3.5).
    pub fn support(
        &self,
        velocities: &[V3],
        inverse_masses: &[f64],
        dt: f64,
        forces: &mut [V3],
        reaction: &mut Vec<V3>,
    ) {
        reaction.clear();
        reaction.resize(forces.len(), V3::zeros());
        for (i, (f, r)) in forces.iter_mut().zip(reaction.iter_mut()).enumerate() {
            let n = self.foot_normal[i];
            if n == V3::zeros() {
                continue;
            }
            let into = -f.dot(&n);
            if into <= 0.0 {
                continue;
            }
            let h = self.height[i];
            let arrives = h + dt * velocities[i].dot(&n) - dt * dt * inverse_masses[i] * into;
            if h <= LYING || arrives <= 0.0 {
                *r = n * into;
                *f += *r;
            }
        }
    }

    /// Take the air's pressure at the end of the step (backward Euler) inside a large-step
    /// solver's constraint iterations (module docs, "Large steps"): at the predicted positions
    /// `y = x + v·Δt` each sealed bubble's volume V(y), and the pressure P' with
    /// `P'·(V(y) + Δt²·s·(P' − P)) = K` (P the pressure applied so far this step, `s = Σ m⁻¹|g|²`
    /// over the bubble's free nodes off the surface, `g_i = S_i N_i(y)`); the free nodes'
    /// velocities change by `Δt·m⁻¹·g·(P' − P)` and P' becomes the applied pressure. Uses the
    /// bubbles and footprints of the last [`PressureModel::add_forces`]; returns the largest
    /// |P' − P| (Pa).
    pub fn project(
        &mut self,
        positions: &[V3],
        triangles: &[[u32; 3]],
        node_area: &[f64],
        inverse_masses: &[f64],
        dt: f64,
        velocities: &mut [V3],
    ) -> f64 {
        let n = positions.len();
        let pa = self.params.atmosphere;
        let breakthrough = self.params.breakthrough;
        if !self
            .bubbles
            .iter()
            .any(|b| !b.vented && (b.air > 0.0 || breakthrough.is_some()))
        {
            return 0.0;
        }
        self.pred.resize(n, V3::zeros());
        self.height_y.resize(n, 0.0);
        let reach = match &self.surface {
            Surface::Body { reach, .. } => *reach,
            Surface::Plane { .. } => 0.0,
        };
        for i in 0..n {
            let y = positions[i] + velocities[i] * dt;
            self.pred[i] = y;
            let fnormal = self.foot_normal[i];
            self.height_y[i] = if fnormal == V3::zeros() {
                reach
            } else {
                (y - self.footprint[i]).dot(&fnormal)
            };
        }
        let pred = std::mem::take(&mut self.pred);
        self.triangle_pass(&pred, false, triangles);
        self.pred = pred;
        let mut volume = vec![0.0; self.bubbles.len()];
        for (v, &b) in self.tri_volume.iter().zip(&self.tri_bubble) {
            if b != NONE {
                volume[b as usize] += v;
            }
        }
        let mut largest: f64 = 0.0;
        let params = self.params;
        for (k, b) in self.bubbles.iter_mut().enumerate() {
            if b.vented || (b.air <= 0.0 && breakthrough.is_none()) {
                continue;
            }
            let free = |i: usize| inverse_masses[i] > 0.0 && self.height_y[i] > LYING;
            let nodes: &mut dyn Iterator<Item = usize> = match self.params.bubbles {
                Bubbles::Single => &mut (0..n),
                Bubbles::Pockets { .. } => &mut b.nodes.iter().map(|&i| i as usize),
            };
            let s: f64 = nodes
                .filter(|&i| free(i))
                .map(|i| inverse_masses[i] * (self.normal[i] * node_area[i]).norm_squared())
                .sum();
            let floor = self.params.min_volume_fraction * b.air / pa;
            let a = dt * dt * s;
            let c = volume[k] - a * b.pressure;
            let p = if a > 0.0 && b.air > 0.0 {
                positive_root(a, c, b.air)
            } else {
                b.air / volume[k].max(floor)
            };
            let p = p.min(b.air / floor.max(f64::MIN_POSITIVE));
            // Beyond the breakthrough difference air passes the cloth (see `admit`).
            let p = match params.breakthrough {
                Some(d) if (p - pa).abs() > d => {
                    let q = p.clamp(pa - d, pa + d);
                    b.air = q * volume[k].max(0.0);
                    q
                }
                Some(_) => p,
                None => p,
            };
            let dp = p - b.pressure;
            largest = largest.max(dp.abs());
            let nodes: &mut dyn Iterator<Item = usize> = match self.params.bubbles {
                Bubbles::Single => &mut (0..n),
                Bubbles::Pockets { .. } => &mut b.nodes.iter().map(|&i| i as usize),
            };
            for i in nodes {
                if free(i) {
                    velocities[i] += self.normal[i] * (dt * inverse_masses[i] * node_area[i] * dp);
                }
            }
            b.pressure = p;
            b.volume = volume[k];
        }
        // The report follows the applied pressures.
        self.refresh_report();
        largest
    }

    /// The pressure the fabric lets the bubble have, with its air: Boyle's `pressure` unless
    /// it lies beyond the breakthrough difference, where air passes through the cloth until the
    /// bubble holds `P_a ∓ Δp` at its `volume`.
    fn admit(&self, pressure: f64, air: f64, volume: f64) -> (f64, f64) {
        let Some(dp) = self.params.breakthrough else {
            return (pressure, air);
        };
        let pa = self.params.atmosphere;
        if (pressure - pa).abs() <= dp {
            (pressure, air)
        } else {
            let p = pressure.clamp(pa - dp, pa + dp);
            (p, p * volume.max(0.0))
        }
    }
}

#[cfg(test)]
mod tests;
