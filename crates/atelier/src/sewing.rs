//! Dressing by sewing (thesis §5.6): the panels are placed around the body, the node pairs of
//! every seam are drawn together (the thesis: by springs, with gravity off), and a pair closer
//! than a threshold is sewn — from then on its two nodes move as one. Gravity starts when every
//! pair is sewn.
//!
//! The pull is written as a velocity: each step an unsewn pair closes a fixed fraction of its gap
//! (a critically damped spring in effect: no overshoot, no oscillation), shared between its nodes
//! by inverse mass. A sewn pair is held together after every collision pass: both nodes are given
//! the velocities that bring them to their mass-weighted mean end position, which conserves their
//! momentum.

use atelier_collide::V3;
use atelier_solver::{CollisionHook, HookContext};

/// How the seams are closed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SewingParams {
    /// Natural angular frequency ω of the critically damped pull, rad/s.
    pub omega: f64,
    /// A pair closer than this is sewn, m.
    pub threshold: f64,
    /// Largest closing speed of a pair, m/s (keeps the cloth from being yanked).
    pub max_speed: f64,
}

impl Default for SewingParams {
    fn default() -> Self {
        Self {
            omega: 10.0,
            threshold: 2e-3,
            max_speed: 1.0,
        }
    }
}

/// The sewing stage, as a collision hook.
pub struct Sewing {
    params: SewingParams,
    pairs: Vec<(u32, u32)>,
    sewn: Vec<bool>,
}

impl Sewing {
    /// Sew `pairs` (node indices of the cloth).
    pub fn new(pairs: Vec<(u32, u32)>, params: SewingParams) -> Self {
        let sewn = vec![false; pairs.len()];
        Self {
            params,
            pairs,
            sewn,
        }
    }

    /// Pairs sewn so far, of all.
    pub fn progress(&self) -> (usize, usize) {
        (self.sewn.iter().filter(|&&s| s).count(), self.sewn.len())
    }

    /// Indices of the pairs not sewn yet.
    pub fn unsewn(&self) -> Vec<usize> {
        (0..self.sewn.len()).filter(|&k| !self.sewn[k]).collect()
    }

    /// Whether every pair is sewn.
    pub fn done(&self) -> bool {
        self.sewn.iter().all(|&s| s)
    }

    /// The largest distance between the two nodes of a pair at `positions`.
    pub fn largest_gap(&self, positions: &[V3]) -> f64 {
        self.pairs
            .iter()
            .map(|&(a, b)| (positions[a as usize] - positions[b as usize]).norm())
            .fold(0.0, f64::max)
    }
}

impl CollisionHook for Sewing {
    fn transfer(&mut self, ctx: HookContext<'_>) {
        let (x, v, w) = (ctx.positions, ctx.velocities, ctx.inverse_masses);
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let gap = x[b] - x[a];
            if !self.sewn[k] && gap.norm() < self.params.threshold {
                self.sewn[k] = true;
            }
            if self.sewn[k] {
                continue;
            }
            let ws = w[a] + w[b];
            if ws <= 0.0 {
                continue;
            }
            let w0 = self.params.omega;
            let mut want = (gap * (w0 * w0) - (v[b] - v[a]) * (2.0 * w0)) * ctx.dt;
            // Never faster than `max_speed` towards each other.
            let closing = (v[a] - v[b]).dot(&gap) / gap.norm().max(f64::MIN_POSITIVE);
            let speed = want.norm();
            if closing + speed > self.params.max_speed && speed > 0.0 {
                want *= ((self.params.max_speed - closing).max(0.0) / speed).min(1.0);
            }
            v[a] += want * (w[a] / ws);
            v[b] -= want * (w[b] / ws);
        }
    }

    fn resolve(&mut self, ctx: HookContext<'_>) {
        let (x, v, w, dt) = (ctx.positions, ctx.velocities, ctx.inverse_masses, ctx.dt);
        // The gap an unsewn pair may keep at the end of this pass: it closes by the fraction
        // ω·Δt of its predicted gap per pass, at most `max_speed·Δt`.
        let rate = (self.params.omega * dt).min(1.0);
        let most = self.params.max_speed * dt;
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let ws = w[a] + w[b];
            if ws <= 0.0 {
                continue;
            }
            let (ea, eb) = (x[a] + v[a] * dt, x[b] + v[b] * dt);
            // Mass-weighted mean: weights are the masses, i.e. the other node's inverse mass.
            let e = (ea * w[b] + eb * w[a]) / ws;
            if self.sewn[k] {
                v[a] = (e - x[a]) / dt;
                v[b] = (e - x[b]) / dt;
            } else {
                let gap = eb - ea;
                let len = gap.norm();
                let keep = if len > 0.0 {
                    (len - (rate * len).min(most)) / len
                } else {
                    0.0
                };
                // Both ends move towards the mean, keeping `keep` of the gap (momentum kept).
                let (na, nb) = (e - gap * (keep * w[a] / ws), e + gap * (keep * w[b] / ws));
                v[a] = (na - x[a]) / dt;
                v[b] = (nb - x[b]) / dt;
            }
        }
    }
}

/// Several hooks called in order (sewing, then the body), borrowed for a step.
pub struct Chain<'a>(pub Vec<&'a mut dyn CollisionHook>);

impl CollisionHook for Chain<'_> {
    fn transfer(&mut self, mut ctx: HookContext<'_>) {
        for h in &mut self.0 {
            h.transfer(reborrow(&mut ctx));
        }
    }

    fn resolve(&mut self, mut ctx: HookContext<'_>) {
        for h in &mut self.0 {
            h.resolve(reborrow(&mut ctx));
        }
    }
}

/// The same context again, for the next hook of a chain.
fn reborrow<'b>(ctx: &'b mut HookContext<'_>) -> HookContext<'b> {
    HookContext {
        positions: ctx.positions,
        velocities: &mut *ctx.velocities,
        exit: &mut *ctx.exit,
        inverse_masses: ctx.inverse_masses,
        dt: ctx.dt,
        time: ctx.time,
        pass: ctx.pass,
    }
}
