//! Grid improvement (thesis §4.5, (53)–(60); `method.md` §4): minimise
//! `E = c₁E₁ + c₂E₂ + c₃E₃` over the free nodes of a [`Patch`] by gradient steps.
//!
//! The nodes live in a plane (the pattern plane or a range image's plane) and are *lifted* onto a
//! surface ([`Surface`]): the plane itself, a height field `z = h(x, y)` for density control, or
//! a body's range image. Every term is measured on the lifted points `X`, so spacing shrinks where
//! the surface is steep.
//!
//! - `E₁` smoothness (54): `½ |X − ¼ Σ X_a|²` over the 4-neighbourhood of every node that has one.
//! - `E₂` shear (55): `½ Σ_k (d_k · d_{k+1})²` over consecutive axes (+u, +v, −u, −v) of every node,
//!   `d` unit vectors; zero when the axes are orthogonal.
//! - `E₃` spacing (56): `½ Σ_lines Σ_edges (|e| − ē)²`, the spread of edge lengths along every grid
//!   line about the line's mean. The thesis writes it as the pull of each node towards the point at
//!   its even-spacing position along its own line, `f(l) − r`; the spread has the same minimiser
//!   (even spacing on every line) and, unlike the pull, is an energy whose exact gradient exists, so
//!   descent is monotone (deviation, documented in `docs/grid.md`).
//!
//! `E₁` and `E₃` are divided by `h̄²` (the mean axial edge length of the initial grid, squared), so
//! the weights are dimensionless. The gradient is exact (checked against finite differences); the
//! step `r ← r − γ∇E` is accepted only if it lowers `E` (Armijo backtracking), so the energy
//! decreases monotonically, as the thesis's Fig. 31 shows.
//!
//! Nothing in `E₁…E₃` stops a cell from folding over, and on strongly curved outlines the descent
//! does fold cells (measured on the dress's front bodice with `c₃ = 3`). A fold barrier
//! `E_fold = Σ (ln(x/δ))²` over the cell triangles whose plane area ratio `x = a/ā` is below
//! `δ = 0.2` (zero elsewhere, infinite at `x ≤ 0`) keeps every triangle that starts unfolded
//! unfolded; it is zero on any healthy grid, so it does not move the minimum of a good grid
//! (addition, documented in `docs/grid.md`).

use crate::patch::Patch;

/// A surface the plane positions are lifted onto.
pub trait Surface: Sync {
    /// The lifted point of `node` at plane position `p` and its derivatives `∂X/∂x`, `∂X/∂y`.
    fn lift(&self, node: usize, p: [f64; 2]) -> ([f64; 3], [[f64; 3]; 2]);
}

/// The plane itself (`z = 0`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Plane;

impl Surface for Plane {
    fn lift(&self, _node: usize, p: [f64; 2]) -> ([f64; 3], [[f64; 3]; 2]) {
        ([p[0], p[1], 0.0], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    }
}

/// A height field `z = h(x, y)` over the plane: `f(p)` returns `h` and `∇h`.
pub struct HeightField<F>(pub F);

impl<F: Fn([f64; 2]) -> (f64, [f64; 2]) + Sync> Surface for HeightField<F> {
    fn lift(&self, _node: usize, p: [f64; 2]) -> ([f64; 3], [[f64; 3]; 2]) {
        let (h, g) = (self.0)(p);
        ([p[0], p[1], h], [[1.0, 0.0, g[0]], [0.0, 1.0, g[1]]])
    }
}

/// Weights and stopping rule of the improvement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImproveParams {
    /// Smoothness weight c₁.
    pub c1: f64,
    /// Shear weight c₂.
    pub c2: f64,
    /// Spacing weight c₃.
    pub c3: f64,
    /// Stop when an accepted step lowers `E` by less than this fraction of `E`.
    pub relative_tolerance: f64,
    /// Stop after this many accepted steps at most.
    pub max_iterations: usize,
}

/// Defaults: `c₁ = 1, c₂ = 1, c₃ = 5` — chosen on the dress's front bodice so the improvement
/// follows the thesis's Fig. 32 (shear SD down by about 40 %, v-length SD down, u-length SD
/// unchanged); see `docs/grid.md` for the sweep.
impl Default for ImproveParams {
    fn default() -> Self {
        Self {
            c1: 1.0,
            c2: 1.0,
            c3: 5.0,
            relative_tolerance: 1e-6,
            max_iterations: 2000,
        }
    }
}

/// What the improvement did.
#[derive(Clone, Debug, PartialEq)]
pub struct ImproveReport {
    /// `E` before the first step and after every accepted step (monotone decreasing).
    pub energy: Vec<f64>,
    /// The parts `[c₁E₁, c₂E₂, c₃E₃, E_fold]` (scaled) before and after.
    pub parts_before: [f64; 4],
    /// See `parts_before`.
    pub parts_after: [f64; 4],
    /// Whether the relative-change rule stopped it (rather than the iteration cap).
    pub converged: bool,
}

/// The energy of a patch on a surface, with its scale `h̄²` fixed.
pub struct Energy<'a> {
    patch: &'a Patch,
    surface: &'a dyn Surface,
    params: ImproveParams,
    scale: f64,
    lines: Vec<Vec<u32>>,
    triangles: Vec<[u32; 3]>,
    orientation: f64,
    mean_area: f64,
    /// Every node slot's node and 4-neighbourhood (the patch's structure, computed once).
    stencils: Vec<(u32, [Option<u32>; 4])>,
}

/// Triangles whose plane area falls below this fraction of the mean cell triangle's are pushed
/// back by the fold barrier.
const FOLD_RATIO: f64 = 0.2;

impl<'a> Energy<'a> {
    /// Set up the energy; `h̄` is measured on the patch as given.
    pub fn new(patch: &'a Patch, surface: &'a dyn Surface, params: ImproveParams) -> Self {
        let lines: Vec<Vec<u32>> = patch.lines().into_iter().map(|(_, l)| l).collect();
        let lifted: Vec<[f64; 3]> = lift_all(patch, surface, &patch.positions)
            .into_iter()
            .map(|(x, _)| x)
            .collect();
        let (mut sum, mut count) = (0.0, 0usize);
        for l in &lines {
            for w in l.windows(2) {
                sum += norm(sub(lifted[w[1] as usize], lifted[w[0] as usize]));
                count += 1;
            }
        }
        let mean = if count > 0 { sum / count as f64 } else { 1.0 };
        // Both splits of every full cell; the one triangle of a cell with a merged corner.
        let mut triangles = Vec::new();
        for q in patch.quads() {
            let mut d = q.to_vec();
            d.dedup();
            if d.len() > 1 && d[0] == d[d.len() - 1] {
                d.pop();
            }
            match d.len() {
                4 => triangles.extend([
                    [q[0], q[1], q[2]],
                    [q[0], q[2], q[3]],
                    [q[0], q[1], q[3]],
                    [q[1], q[2], q[3]],
                ]),
                3 => triangles.push([d[0], d[1], d[2]]),
                _ => {}
            }
        }
        let orientation = patch.orientation(&patch.positions);
        let p = &patch.positions;
        let area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|k| p[k as usize]);
            0.5 * orientation * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
        };
        let total: f64 = triangles.iter().map(|t| area(t).abs()).sum();
        // The barrier guards triangles that are unfolded now and can move; one already folded
        // (a split across the concave side of a non-convex cell) is left alone.
        triangles.retain(|t| area(t) > 0.0 && t.iter().any(|&k| !patch.fixed[k as usize]));
        let stencils = (0..patch.node_of.len())
            .filter_map(|s| patch.neighbourhood(s))
            .collect();
        Self {
            patch,
            surface,
            params,
            stencils,
            scale: 1.0 / (mean * mean).max(f64::MIN_POSITIVE),
            lines,
            mean_area: (total / triangles.len().max(1) as f64).max(f64::MIN_POSITIVE),
            triangles,
            orientation,
        }
    }

    /// The scaled parts `[c₁E₁/h̄², c₂E₂, c₃E₃/h̄², E_fold]` at plane positions `p`.
    pub fn parts(&self, p: &[[f64; 2]]) -> [f64; 4] {
        self.evaluate(p, None)
    }

    /// `E` at plane positions `p`.
    pub fn value(&self, p: &[[f64; 2]]) -> f64 {
        self.parts(p).iter().sum()
    }

    /// `E` and its gradient with respect to the plane positions (zero at fixed nodes).
    pub fn gradient(&self, p: &[[f64; 2]]) -> (f64, Vec<[f64; 2]>) {
        let mut g = vec![[0.0; 2]; p.len()];
        let e = self.evaluate(p, Some(&mut g)).iter().sum();
        (e, g)
    }

    fn evaluate(&self, p: &[[f64; 2]], grad: Option<&mut Vec<[f64; 2]>>) -> [f64; 4] {
        let patch = self.patch;
        let lifted = lift_all(patch, self.surface, p);
        let x = |n: u32| lifted[n as usize].0;
        let want = grad.is_some();
        let mut g3 = if want {
            vec![[0.0; 3]; p.len()]
        } else {
            Vec::new()
        };
        let add = |g3: &mut Vec<[f64; 3]>, n: u32, v: [f64; 3], w: f64| {
            if want {
                let t = &mut g3[n as usize];
                for k in 0..3 {
                    t[k] += w * v[k];
                }
            }
        };
        let ImproveParams { c1, c2, c3, .. } = self.params;
        let (mut e1, mut e2, mut e3) = (0.0, 0.0, 0.0);
        for &(n, nb) in &self.stencils {
            let xn = x(n);
            // Smoothness.
            if c1 != 0.0
                && let [Some(a), Some(b), Some(c), Some(d)] = nb
            {
                let r: [f64; 3] =
                    std::array::from_fn(|k| xn[k] - 0.25 * (x(a)[k] + x(b)[k] + x(c)[k] + x(d)[k]));
                let w = c1 * self.scale;
                e1 += 0.5 * w * dot(r, r);
                add(&mut g3, n, r, w);
                for m in [a, b, c, d] {
                    add(&mut g3, m, r, -0.25 * w);
                }
            }
            // Shear.
            if c2 != 0.0 {
                for k in 0..4 {
                    let (Some(a), Some(b)) = (nb[k], nb[(k + 1) % 4]) else {
                        continue;
                    };
                    let (ea, eb) = (sub(x(a), xn), sub(x(b), xn));
                    let (la, lb) = (norm(ea), norm(eb));
                    let (da, db) = (scale(ea, 1.0 / la), scale(eb, 1.0 / lb));
                    let c = dot(da, db);
                    e2 += 0.5 * c2 * c * c;
                    // ∂c/∂ea = (db − c·da)/|ea|, likewise for eb.
                    let ga = scale(sub(db, scale(da, c)), c2 * c / la);
                    let gb = scale(sub(da, scale(db, c)), c2 * c / lb);
                    add(&mut g3, a, ga, 1.0);
                    add(&mut g3, b, gb, 1.0);
                    add(&mut g3, n, ga, -1.0);
                    add(&mut g3, n, gb, -1.0);
                }
            }
        }
        // Spacing: the spread of edge lengths along each line.
        if c3 != 0.0 {
            let w = c3 * self.scale;
            for line in &self.lines {
                let lens: Vec<f64> = line
                    .windows(2)
                    .map(|e| norm(sub(x(e[1]), x(e[0]))))
                    .collect();
                let mean = lens.iter().sum::<f64>() / lens.len() as f64;
                for (e, &l) in line.windows(2).zip(&lens) {
                    let dev = l - mean;
                    e3 += 0.5 * w * dev * dev;
                    // The mean's own derivative drops out: Σ (l − ē) = 0.
                    let u = scale(sub(x(e[1]), x(e[0])), w * dev / l);
                    add(&mut g3, e[1], u, 1.0);
                    add(&mut g3, e[0], u, -1.0);
                }
            }
        }
        // Fold barrier, in the plane: (ln(x/δ))² for triangles whose area ratio x = a/ā < δ.
        let mut e4 = 0.0;
        let mut g2 = if want {
            vec![[0.0; 2]; p.len()]
        } else {
            Vec::new()
        };
        for t in &self.triangles {
            let [a, b, c] = t.map(|k| p[k as usize]);
            let area = 0.5
                * self.orientation
                * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
            let x = area / self.mean_area;
            if x >= FOLD_RATIO {
                continue;
            }
            if x <= 0.0 {
                e4 = f64::INFINITY;
                continue;
            }
            let l = (x / FOLD_RATIO).ln();
            e4 += l * l;
            if want {
                let w = 2.0 * l / x / self.mean_area * 0.5 * self.orientation;
                let d = [
                    [b[1] - c[1], c[0] - b[0]],
                    [c[1] - a[1], a[0] - c[0]],
                    [a[1] - b[1], b[0] - a[0]],
                ];
                for (k, dk) in t.iter().zip(d) {
                    g2[*k as usize][0] += w * dk[0];
                    g2[*k as usize][1] += w * dk[1];
                }
            }
        }
        if let Some(g) = grad {
            for (n, gn) in g.iter_mut().enumerate() {
                if patch.fixed[n] {
                    *gn = [0.0; 2];
                    continue;
                }
                let j = lifted[n].1;
                *gn = [dot(j[0], g3[n]) + g2[n][0], dot(j[1], g3[n]) + g2[n][1]];
            }
        }
        [e1, e2, e3, e4]
    }
}

fn lift_all(
    patch: &Patch,
    surface: &dyn Surface,
    p: &[[f64; 2]],
) -> Vec<([f64; 3], [[f64; 3]; 2])> {
    (0..patch.node_count())
        .map(|n| surface.lift(n, p[n]))
        .collect()
}

/// Improve a patch in place: gradient steps with Armijo backtracking on the free nodes.
pub fn improve(patch: &mut Patch, surface: &dyn Surface, params: ImproveParams) -> ImproveReport {
    let positions = {
        let energy = Energy::new(patch, surface, params);
        let mut p = patch.positions.clone();
        let parts_before = energy.parts(&p);
        let (mut e, mut g) = energy.gradient(&p);
        let mut history = vec![e];
        let h = 1.0 / energy.scale.sqrt();
        let gmax = g.iter().map(|v| v[0].hypot(v[1])).fold(0.0, f64::max);
        // First trial step moves the node with the largest gradient by a tenth of the spacing.
        let mut gamma = if gmax > 0.0 { 0.1 * h / gmax } else { 0.0 };
        let mut converged = gmax == 0.0;
        let mut trial = p.clone();
        for _ in 0..params.max_iterations {
            if converged {
                break;
            }
            let g2: f64 = g.iter().map(|v| v[0] * v[0] + v[1] * v[1]).sum();
            let mut accepted = None;
            for _ in 0..60 {
                for ((t, q), d) in trial.iter_mut().zip(&p).zip(&g) {
                    *t = [q[0] - gamma * d[0], q[1] - gamma * d[1]];
                }
                let et = energy.value(&trial);
                if et.is_finite() && et <= e - 1e-4 * gamma * g2 {
                    accepted = Some(et);
                    break;
                }
                gamma *= 0.5;
            }
            let Some(et) = accepted else {
                converged = true;
                break;
            };
            std::mem::swap(&mut p, &mut trial);
            let drop = (e - et) / e.max(f64::MIN_POSITIVE);
            history.push(et);
            gamma *= 1.5;
            (e, g) = energy.gradient(&p);
            if drop < params.relative_tolerance {
                converged = true;
            }
        }
        let parts_after = energy.parts(&p);
        (
            p,
            ImproveReport {
                energy: history,
                parts_before,
                parts_after,
                converged,
            },
        )
    };
    patch.positions = positions.0;
    positions.1
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coons::{coons, resample};
    use proptest::prelude::*;

    /// A distorted patch: a quadrilateral with one curved side, interior jiggled.
    fn distorted(nu: usize, nv: usize, jiggle: &[f64]) -> Patch {
        let bottom = resample(&[[0.0, 0.0], [0.3, -0.05], [1.0, 0.0]], nu);
        let top = resample(&[[0.1, 0.8], [1.1, 1.0]], nu);
        let left = resample(&[[0.0, 0.0], [0.1, 0.8]], nv);
        let right = resample(&[[1.0, 0.0], [1.3, 0.5], [1.1, 1.0]], nv);
        let mut p = Patch::full(nu, nv, false, coons(&bottom, &top, &left, &right));
        for (n, q) in p.positions.iter_mut().enumerate() {
            if !p.fixed[n] {
                q[0] += 0.02 * jiggle[(2 * n) % jiggle.len()];
                q[1] += 0.02 * jiggle[(2 * n + 1) % jiggle.len()];
            }
        }
        p
    }

    fn mountain() -> HeightField<impl Fn([f64; 2]) -> (f64, [f64; 2]) + Sync> {
        HeightField(|p: [f64; 2]| {
            let (dx, dy) = (p[0] - 0.5, p[1] - 0.5);
            let h = 0.4 * (-(dx * dx + dy * dy) / 0.08).exp();
            (h, [-2.0 * dx / 0.08 * h, -2.0 * dy / 0.08 * h])
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The analytic gradient matches central differences, on the plane and on a mountain.
        #[test]
        fn gradient_matches_finite_differences(
            jiggle in prop::collection::vec(-1.0f64..1.0, 8..40),
            c in prop::array::uniform3(0.1f64..3.0),
            lifted in any::<bool>(),
        ) {
            let patch = distorted(6, 5, &jiggle);
            let params = ImproveParams { c1: c[0], c2: c[1], c3: c[2], ..Default::default() };
            let m = mountain();
            let surface: &dyn Surface = if lifted { &m } else { &Plane };
            let energy = Energy::new(&patch, surface, params);
            let (_, g) = energy.gradient(&patch.positions);
            let h = 1e-6;
            for n in 0..patch.node_count() {
                for k in 0..2 {
                    let mut p = patch.positions.clone();
                    p[n][k] += h;
                    let ep = energy.value(&p);
                    p[n][k] -= 2.0 * h;
                    let em = energy.value(&p);
                    let fd = if patch.fixed[n] { 0.0 } else { (ep - em) / (2.0 * h) };
                    let tol = 1e-5 * (1.0 + fd.abs());
                    prop_assert!((fd - g[n][k]).abs() < tol,
                        "node {} axis {}: analytic {} vs fd {}", n, k, g[n][k], fd);
                }
            }
        }
    }

    #[test]
    fn the_fold_barrier_gradient_matches_finite_differences() {
        let mut patch = distorted(6, 5, &[0.0]);
        // Squeeze node (2, 2) towards its +u neighbour: thin triangles, barrier active.
        let (n, m) = (2 * 6 + 2, 2 * 6 + 3);
        let (a, b) = (patch.positions[n], patch.positions[m]);
        patch.positions[n] = [a[0] + 0.85 * (b[0] - a[0]), a[1] + 0.85 * (b[1] - a[1])];
        let energy = Energy::new(&patch, &Plane, ImproveParams::default());
        assert!(energy.parts(&patch.positions)[3] > 0.0, "barrier inactive");
        let (_, g) = energy.gradient(&patch.positions);
        let h = 1e-7;
        for k in 0..2 {
            let mut p = patch.positions.clone();
            p[n][k] += h;
            let ep = energy.value(&p);
            p[n][k] -= 2.0 * h;
            let em = energy.value(&p);
            let fd = (ep - em) / (2.0 * h);
            assert!(
                (fd - g[n][k]).abs() < 1e-5 * (1.0 + fd.abs()),
                "{fd} vs {}",
                g[n][k]
            );
        }
        // The improvement opens the squeezed cell again without folding anything.
        let report = improve(&mut patch, &Plane, ImproveParams::default());
        assert!(report.parts_after[3] < report.parts_before[3]);
        assert!(patch.min_cell_area(&patch.positions, patch.orientation(&patch.positions)) > 0.0);
    }

    #[test]
    #[allow(clippy::float_cmp, reason = "fixed nodes are never written")]
    fn improvement_is_monotone_and_evens_the_grid() {
        let jiggle = [0.9, -0.4, 0.3, 0.7, -0.8, 0.1, -0.6, 0.5, 0.2];
        let mut patch = distorted(9, 8, &jiggle);
        let before = patch.clone();
        let report = improve(&mut patch, &Plane, ImproveParams::default());
        assert!(report.energy.windows(2).all(|w| w[1] <= w[0]));
        let (first, last) = (report.energy[0], *report.energy.last().unwrap());
        assert!(last < 0.7 * first, "energy {first} → {last}");
        // Fixed nodes did not move.
        for n in 0..patch.node_count() {
            if patch.fixed[n] {
                assert_eq!(patch.positions[n], before.positions[n]);
            }
        }
    }

    #[test]
    fn a_uniform_grid_is_already_optimal() {
        let (nu, nv) = (6, 4);
        let pos = coons(
            &resample(&[[0.0, 0.0], [1.0, 0.0]], nu),
            &resample(&[[0.0, 0.6], [1.0, 0.6]], nu),
            &resample(&[[0.0, 0.0], [0.0, 0.6]], nv),
            &resample(&[[1.0, 0.0], [1.0, 0.6]], nv),
        );
        let patch = Patch::full(nu, nv, false, pos);
        let energy = Energy::new(&patch, &Plane, ImproveParams::default());
        let (e, g) = energy.gradient(&patch.positions);
        assert!(e < 1e-25, "E = {e}");
        assert!(g.iter().all(|v| v[0].abs() < 1e-12 && v[1].abs() < 1e-12));
    }
}
