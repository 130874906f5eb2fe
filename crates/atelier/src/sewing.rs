//! Dressing by sewing (thesis §5.6): the panels are placed around the body, the node pairs of
//! every seam are drawn together (the thesis: by springs, with gravity off), and a pair closer
//! than a threshold is sewn — from then on its two nodes move as one. Gravity starts when every
//! pair is sewn.
//!
//! The pull is a tie inside the shape iterations ([`Tie`]): each step an unsewn pair may end at
//! most `(1 − ω·Δt)` times its gap apart (at most `max_speed·Δt` closer), so the gap shrinks
//! geometrically like a critically damped spring's, with no overshoot. Because the tie is
//! enforced in every iteration with the cloth's own constraints and the body's contact planes,
//! the whole panel moves with the seam instead of the seam's nodes being yanked after the
//! iterations (which left the pull fighting the cloth: darts stalled 1 cm open). A sewn pair is a
//! tie of length 0, and sewn pairs join their nodes into one point of the garment (union–find: a
//! corner where several seams meet — side seam, armhole and underarm at the armpit — is one
//! point, and a pair whose nodes are already joined through other seams counts as sewn); after
//! each collision pass every joined point is put at its nodes' mass-weighted mean (momentum
//! kept), so it stays shut whatever the contacts did.

use atelier_collide::V3;
use atelier_solver::{CollisionHook, HookContext, Tie};

/// How the seams are closed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SewingParams {
    /// Fraction of a pair's gap closed per second, 1/s (ω; the gap shrinks by ω·Δt per step).
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
    /// Union–find over the nodes of the pairs: sewn pairs join their nodes into one point (a
    /// corner where several seams meet is one point of the garment).
    parent: std::collections::HashMap<u32, u32>,
    /// The nodes of each joined point with more than one node (rebuilt when a pair is sewn).
    groups: Vec<Vec<u32>>,
}

impl Sewing {
    /// Sew `pairs` (node indices of the cloth).
    pub fn new(pairs: Vec<(u32, u32)>, params: SewingParams) -> Self {
        let sewn = vec![false; pairs.len()];
        let parent = pairs.iter().flat_map(|&(a, b)| [(a, a), (b, b)]).collect();
        Self {
            params,
            pairs,
            sewn,
            parent,
            groups: Vec::new(),
        }
    }

    fn root(&mut self, mut x: u32) -> u32 {
        while self.parent[&x] != x {
            let up = self.parent[&self.parent[&x]];
            self.parent.insert(x, up);
            x = up;
        }
        x
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

    /// Sew the pairs now closer than the threshold, and those whose nodes other sewn pairs have
    /// already joined; rebuild the joined points when anything changed.
    fn sew(&mut self, x: &[V3]) {
        let mut changed = false;
        for k in 0..self.pairs.len() {
            if self.sewn[k] {
                continue;
            }
            let (a, b) = self.pairs[k];
            if (x[b as usize] - x[a as usize]).norm() < self.params.threshold {
                let (ra, rb) = (self.root(a), self.root(b));
                self.parent.insert(ra, rb);
                self.sewn[k] = true;
                changed = true;
            }
        }
        if !changed {
            return;
        }
        for k in 0..self.pairs.len() {
            let (a, b) = self.pairs[k];
            if !self.sewn[k] && self.root(a) == self.root(b) {
                self.sewn[k] = true;
            }
        }
        let mut nodes: Vec<u32> = self.parent.keys().copied().collect();
        nodes.sort_unstable();
        let mut by_root: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
        for n in nodes {
            let r = self.root(n);
            by_root.entry(r).or_default().push(n);
        }
        self.groups = by_root.into_values().filter(|g| g.len() > 1).collect();
    }
}

impl CollisionHook for Sewing {
    fn transfer(&mut self, ctx: HookContext<'_>) {
        self.sew(ctx.positions);
        let x = ctx.positions;
        let keep = 1.0 - (self.params.omega * ctx.dt).min(1.0);
        let most = self.params.max_speed * ctx.dt;
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let gap = (x[b as usize] - x[a as usize]).norm();
            let length = if self.sewn[k] {
                0.0
            } else {
                (gap * keep).max(gap - most)
            };
            ctx.ties.push(Tie { a, b, length });
        }
    }

    fn resolve(&mut self, ctx: HookContext<'_>) {
        let (x, v, w, dt) = (ctx.positions, ctx.velocities, ctx.inverse_masses, ctx.dt);
        // Every joined point ends the pass at its nodes' mass-weighted mean end position
        // (momentum kept); pinned nodes are not moved (their points keep them).
        for group in &self.groups {
            let (mut sum, mut mass) = (V3::zeros(), 0.0);
            for &i in group {
                let i = i as usize;
                if w[i] > 0.0 {
                    sum += (x[i] + v[i] * dt) / w[i];
                    mass += 1.0 / w[i];
                }
            }
            if mass <= 0.0 {
                continue;
            }
            let e = sum / mass;
            for &i in group {
                let i = i as usize;
                if w[i] > 0.0 {
                    v[i] = (e - x[i]) / dt;
                }
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
        planes: &mut *ctx.planes,
        ties: &mut *ctx.ties,
    }
}
