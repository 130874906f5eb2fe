//! Panels placed around the body before sewing (thesis §5.6: "the panels are arranged around
//! the body"). Each panel is wrapped, keeping its pattern lengths along the wrap, on a surface
//! that encloses the body with a clearance:
//!
//! - [`Placement::Trunk`]: an elliptic cylinder about the vertical, fitted at every height to the
//!   trunk and legs (arms and head excluded) — the bounding ellipse of the body's cross-section
//!   band plus the clearance, widened where the garment's panels at that height are wider than
//!   the ellipse so that panels never overlap. Pattern x becomes arc length from the panel's
//!   facing direction (0° = front, +z; 90° = the wearer's left, +x), pattern y becomes height.
//! - [`Placement::Limb`]: a circular cylinder about a limb's rest axis (an upper arm from its
//!   pivot to its child's), fitted to that limb's band; pattern y runs down the limb from the
//!   joint, pattern x is arc length from the limb's outer side, +x to the right of a viewer
//!   outside the limb (towards the back on the wearer's left arm, the front on the right).
//!
//! Seams then close along the chords between the wrapped edges; a garment panel seen from the
//! outside keeps its pattern orientation (pattern +x to the viewer's right).

use atelier_body::model::{LabelledMesh, Mannequin, Part};
use atelier_collide::V3;
use serde::{Deserialize, Serialize};

use crate::GarmentCloth;

/// Where one panel starts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Placement {
    /// Wrapped around the trunk.
    Trunk {
        /// Direction the panel's centre faces, degrees about +y from the front (+z); 180 = back.
        facing_deg: f64,
        /// World height of the pattern's y = 0, m.
        y0: f64,
        /// Pattern x placed at the facing direction, m (default 0).
        #[serde(default)]
        x0: f64,
    },
    /// Laid flat in a plane facing the body's front, for dressing through the body with
    /// one-sided contact (thesis §5.6): pattern x along world x, pattern y up, then turned
    /// about z and moved so that the pattern's origin is at `at`.
    Flat {
        /// World position of the pattern's origin (x, y, z), m.
        at: [f64; 3],
        /// Laid face down (a back panel, its outside facing −z): pattern x mirrored.
        #[serde(default)]
        back: bool,
        /// Turn about +z, degrees (a sleeve laid along an arm).
        #[serde(default)]
        angle_deg: f64,
        /// Folded along a line of constant pattern x (a sleeve's two halves, one in front of
        /// the limb and one behind it).
        #[serde(default)]
        fold: Option<Fold>,
    },
    /// Wrapped around a limb.
    Limb {
        /// Body part whose axis (pivot to its child's pivot) the panel wraps (`upper_arm_left` …).
        part: String,
        /// Pattern y placed at the part's pivot, m; pattern y decreasing runs down the limb.
        y0: f64,
        /// Extra distance down the limb, m (default 0).
        #[serde(default)]
        offset: f64,
    },
}

/// A fold of a flat-laid panel along the line pattern x = `at`: the part beyond it (on `side`)
/// is turned over about that line and laid `gap` behind the rest.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fold {
    /// Pattern x of the fold line, m.
    pub at: f64,
    /// The side laid behind: `Plus` (x > at) or `Minus` (x < at).
    pub side: Side,
    /// Distance between the two layers, m.
    pub gap: f64,
}

/// A side of a fold line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Side {
    /// Pattern x greater than the fold's.
    Plus,
    /// Pattern x less than the fold's.
    Minus,
}

/// Clearance and ease of the wrap.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlaceParams {
    /// Gap between the body's bounding ellipse and the wrap, m. Default 0.03.
    pub clearance: f64,
    /// The wrap's perimeter is at least this factor × the panels' total width at a height.
    /// Default 1.03.
    pub ease: f64,
    /// Half-height of the body band fitted at each height, m. Default 0.03.
    pub band: f64,
}

impl Default for PlaceParams {
    fn default() -> Self {
        Self {
            clearance: 0.03,
            ease: 1.03,
            band: 0.03,
        }
    }
}

/// Why a garment cannot be placed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlaceError {
    /// Placements and panels differ in number.
    #[error("{placements} placements for {panels} panels")]
    Count {
        /// Placements given.
        placements: usize,
        /// Panels in the garment.
        panels: usize,
    },
    /// A limb placement names no body part with a child.
    #[error(
        "panel {panel}: `{part}` is not a limb part (upper_arm_left, upper_arm_right, forearm_left, forearm_right, thigh_left, thigh_right, shin_left, shin_right)"
    )]
    Part {
        /// Panel index.
        panel: usize,
        /// The name given.
        part: String,
    },
    /// A value is not finite.
    #[error("panel {panel}: placement value {value} is not finite")]
    NotFinite {
        /// Panel index.
        panel: usize,
        /// The value.
        value: f64,
    },
}

/// Height bins of the trunk fit, m.
const BIN: f64 = 0.01;

/// Half-window of the smoothing of the trunk fit over height, m.
const SMOOTH: f64 = 0.06;

/// Positions of every node of `g` wrapped around `body` (rest pose of `mannequin`).
pub fn place(
    g: &GarmentCloth,
    placements: &[Placement],
    mannequin: &Mannequin,
    body: &LabelledMesh,
    params: &PlaceParams,
) -> Result<Vec<V3>, PlaceError> {
    let panels = g.offsets.len();
    if placements.len() != panels {
        return Err(PlaceError::Count {
            placements: placements.len(),
            panels,
        });
    }
    let rest = g.cloth.topology().rest_positions();
    let n = rest.len();
    let range = |k: usize| {
        let end = if k + 1 < panels {
            g.offsets[k + 1] as usize
        } else {
            n
        };
        g.offsets[k] as usize..end
    };
    for (k, p) in placements.iter().enumerate() {
        let values = match p {
            Placement::Trunk { facing_deg, y0, x0 } => vec![*facing_deg, *y0, *x0],
            Placement::Limb { y0, offset, .. } => vec![*y0, *offset],
            Placement::Flat {
                at,
                angle_deg,
                fold,
                ..
            } => {
                let mut v = vec![at[0], at[1], at[2], *angle_deg];
                if let Some(f) = fold {
                    v.extend([f.at, f.gap]);
                }
                v
            }
        };
        if let Some(&value) = values.iter().find(|v| !v.is_finite()) {
            return Err(PlaceError::NotFinite { panel: k, value });
        }
    }
    let mut out = vec![V3::zeros(); n];
    // Trunk panels: one fit for all of them.
    let trunk: Vec<usize> = (0..panels)
        .filter(|&k| matches!(placements[k], Placement::Trunk { .. }))
        .collect();
    if !trunk.is_empty() {
        let node_y = |k: usize, i: usize| match placements[k] {
            Placement::Trunk { y0, .. } => y0 + rest[i][1],
            Placement::Limb { .. } | Placement::Flat { .. } => 0.0,
        };
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &k in &trunk {
            for i in range(k) {
                lo = lo.min(node_y(k, i));
                hi = hi.max(node_y(k, i));
            }
        }
        let bins = (((hi - lo) / BIN).ceil() as usize).max(1) + 1;
        let edges = g.cloth.topology().edges();
        let height = |b: usize| lo + b as f64 * BIN;
        // Panels go around the body in rings (a bodice's panels side by side, a skirt's below
        // them): panels whose heights overlap by more than a bin are in one ring. The width the
        // wrap needs at a height is the largest ring's total width there (each panel's x extent
        // among its nodes in the bin), so panels that only meet at a height (a waist seam) do
        // not add up.
        let span = |k: usize| {
            range(k).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), i| {
                (a.min(node_y(k, i)), b.max(node_y(k, i)))
            })
        };
        let mut ring: Vec<usize> = (0..trunk.len()).collect();
        for x in 0..trunk.len() {
            for y in 0..x {
                let (sx, sy) = (span(trunk[x]), span(trunk[y]));
                if sx.1.min(sy.1) - sx.0.max(sy.0) > BIN {
                    let (rx, ry) = (ring[x], ring[y]);
                    ring.iter_mut().filter(|r| **r == rx).for_each(|r| *r = ry);
                }
            }
        }
        let mut width = vec![0.0; bins];
        for r in 0..trunk.len() {
            let mut ring_width = vec![0.0; bins];
            for (_, &k) in trunk.iter().enumerate().filter(|(x, _)| ring[*x] == r) {
                // The panel's extent at each bin's height: the x range where its edges cross
                // that height (the outline's width there; grid rows need not be level).
                let mut ext = vec![(f64::INFINITY, f64::NEG_INFINITY); bins];
                let nodes = range(k);
                for e in edges.iter().filter(|e| nodes.contains(&(e.a as usize))) {
                    let (a, b) = (e.a as usize, e.b as usize);
                    let (ya, yb) = (node_y(k, a), node_y(k, b));
                    let first = ((ya.min(yb) - lo) / BIN).ceil().max(0.0) as usize;
                    let last = (((ya.max(yb) - lo) / BIN).floor() as usize).min(bins - 1);
                    for (bin, e) in ext.iter_mut().enumerate().take(last + 1).skip(first) {
                        let dy = yb - ya;
                        let t = if dy.abs() > 0.0 {
                            (height(bin) - ya) / dy
                        } else {
                            0.0
                        };
                        let x = rest[a][0] + (rest[b][0] - rest[a][0]) * t;
                        *e = (e.0.min(x), e.1.max(x));
                    }
                }
                for (w, e) in ring_width.iter_mut().zip(&ext) {
                    if e.1 > e.0 {
                        *w += e.1 - e.0;
                    }
                }
            }
            for (w, rw) in width.iter_mut().zip(&ring_width) {
                *w = f64::max(*w, *rw);
            }
        }
        let trunk_vertices: Vec<V3> = body
            .vertices
            .iter()
            .zip(&body.vertex_part)
            .filter(|(_, p)| !is_arm_or_head(**p))
            .map(|(v, _)| *v)
            .collect();
        let raw: Vec<Ellipse> = (0..bins)
            .map(|b| Ellipse::fit(&trunk_vertices, height(b), params))
            .collect();
        // Smooth over the height (the largest semi-axes within ± SMOOTH, then their mean), so
        // that the wrap does not jump where the body's section does (the crotch, the arm roots),
        // then widen to the panels.
        let reach = (SMOOTH / BIN).round() as usize;
        let window = |b: usize| b.saturating_sub(reach)..(b + reach + 1).min(bins);
        let grown: Vec<Ellipse> = (0..bins)
            .map(|b| {
                let mut e = raw[b];
                for o in &raw[window(b)] {
                    e.a = e.a.max(o.a);
                    e.b = e.b.max(o.b);
                }
                e
            })
            .collect();
        let ellipses: Vec<Ellipse> = (0..bins)
            .map(|b| {
                let w = window(b);
                let k = w.len() as f64;
                let mut e = grown[w.clone()].iter().fold(
                    Ellipse {
                        cx: 0.0,
                        cz: 0.0,
                        a: 0.0,
                        b: 0.0,
                    },
                    |acc, o| Ellipse {
                        cx: acc.cx + o.cx / k,
                        cz: acc.cz + o.cz / k,
                        a: acc.a + o.a / k,
                        b: acc.b + o.b / k,
                    },
                );
                e.widen(params.ease * width[b]);
                e
            })
            .collect();
        for &k in &trunk {
            let Placement::Trunk { facing_deg, x0, .. } = placements[k] else {
                continue;
            };
            for i in range(k) {
                let y = node_y(k, i);
                let t = ((y - lo) / BIN).clamp(0.0, (bins - 1) as f64);
                let b = (t.floor() as usize).min(bins.saturating_sub(2));
                let e = if bins == 1 {
                    ellipses[0]
                } else {
                    ellipses[b].lerp(&ellipses[b + 1], t - b as f64)
                };
                let (x, z) = e.at_arc(facing_deg.to_radians(), rest[i][0] - x0);
                out[i] = V3::new(x, y, z);
            }
        }
    }
    for (k, p) in placements.iter().enumerate() {
        let Placement::Flat {
            at,
            back,
            angle_deg,
            fold,
        } = p
        else {
            continue;
        };
        let (sin, cos) = angle_deg.to_radians().sin_cos();
        for i in range(k) {
            let (mut x, y) = (rest[i][0], rest[i][1]);
            let mut z = at[2];
            if let Some(f) = fold {
                let beyond = match f.side {
                    Side::Plus => x > f.at,
                    Side::Minus => x < f.at,
                };
                if beyond {
                    x = 2.0 * f.at - x;
                    z -= f.gap;
                }
            }
            if *back {
                x = -x;
            }
            out[i] = V3::new(at[0] + x * cos - y * sin, at[1] + x * sin + y * cos, z);
        }
    }
    for (k, p) in placements.iter().enumerate() {
        let Placement::Limb { part, y0, offset } = p else {
            continue;
        };
        let Some(limb) = atelier_body::motion::part_named(part)
            .filter(|p| child(*p).is_some())
            .map(|p| (p, child(p).expect("filtered")))
        else {
            return Err(PlaceError::Part {
                panel: k,
                part: part.clone(),
            });
        };
        let origin = mannequin.part(limb.0).pivot;
        let axis = (mannequin.part(limb.1).pivot - origin).normalize();
        // The limb's outer side: away from the body's vertical axis, across the limb.
        let side = V3::new(origin.x.signum(), 0.0, 0.0);
        let out_dir = (side - axis * axis.dot(&side)).normalize();
        // Seen from outside the limb (looking along −out_dir, pattern y up the limb, i.e. along
        // −axis), the pattern's +x runs to the viewer's right: (−out_dir) × (−axis).
        let plus_x = out_dir.cross(&axis);
        let limb_vertices: Vec<V3> = body
            .vertices
            .iter()
            .zip(&body.vertex_part)
            .filter(|(_, q)| **q == limb.0 || **q == limb.1)
            .map(|(v, _)| *v)
            .collect();
        let r = range(k);
        let (wmin, wmax) = r
            .clone()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), i| {
                (a.min(rest[i][0]), b.max(rest[i][0]))
            });
        let from_width = params.ease * (wmax - wmin) / std::f64::consts::TAU;
        // One radius for the whole panel (a cylinder keeps every pattern length): the limb's
        // widest section over the panel's span, plus the clearance. Per-row radii stretched
        // the edges between rows wherever the fit jumped (the upper arm's mesh has a ring of
        // no vertices within the band 8–11 cm below the shoulder: radius 82 → 57 → 75 mm, the
        // sleeve's edges there placed at twice their length and the first step snapping them
        // back by 4.5 cm whatever its Δt).
        let down = |i: usize| (y0 - rest[i][1]) + offset;
        let (tmin, tmax) = r
            .clone()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), i| {
                (a.min(down(i)), b.max(down(i)))
            });
        let fit = limb_vertices
            .iter()
            .filter(|v| {
                let t = (*v - origin).dot(&axis);
                t > tmin - params.band && t < tmax + params.band
            })
            .map(|v| {
                let d = v - origin;
                (d - axis * d.dot(&axis)).norm()
            })
            .fold(0.0, f64::max);
        let radius = (fit + params.clearance).max(from_width);
        for i in r {
            let a = rest[i][0] / radius;
            out[i] = origin + axis * down(i) + (out_dir * a.cos() + plus_x * a.sin()) * radius;
        }
    }
    Ok(out)
}

/// Arms, hands and head: not part of the trunk wrap.
fn is_arm_or_head(p: Part) -> bool {
    matches!(
        p,
        Part::Head
            | Part::UpperArmLeft
            | Part::UpperArmRight
            | Part::ForearmLeft
            | Part::ForearmRight
            | Part::HandLeft
            | Part::HandRight
    )
}

/// The part a limb part's axis runs to.
fn child(p: Part) -> Option<Part> {
    match p {
        Part::UpperArmLeft => Some(Part::ForearmLeft),
        Part::UpperArmRight => Some(Part::ForearmRight),
        Part::ForearmLeft => Some(Part::HandLeft),
        Part::ForearmRight => Some(Part::HandRight),
        Part::ThighLeft => Some(Part::ShinLeft),
        Part::ThighRight => Some(Part::ShinRight),
        Part::ShinLeft => Some(Part::FootLeft),
        Part::ShinRight => Some(Part::FootRight),
        _ => None,
    }
}

/// An ellipse about the vertical: centre (x, z), semi-axes along x and z.
#[derive(Clone, Copy, Debug)]
struct Ellipse {
    cx: f64,
    cz: f64,
    a: f64,
    b: f64,
}

impl Ellipse {
    /// The ellipse through the extremes of the vertices within the band around `y` (a body's
    /// section is roughly elliptic), grown by the clearance.
    fn fit(vertices: &[V3], y: f64, params: &PlaceParams) -> Self {
        let mut band = params.band;
        let mut near: Vec<&V3> = Vec::new();
        // Above the head or below the feet: widen the band until some body is in it.
        while near.is_empty() && band < 2.0 {
            near = vertices.iter().filter(|v| (v.y - y).abs() < band).collect();
            band *= 2.0;
        }
        let (mut x0, mut x1, mut z0, mut z1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        if !near.is_empty() {
            (x0, x1, z0, z1) = (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            );
            for v in near {
                (x0, x1) = (x0.min(v.x), x1.max(v.x));
                (z0, z1) = (z0.min(v.z), z1.max(v.z));
            }
        }
        Self {
            cx: 0.5 * (x0 + x1),
            cz: 0.5 * (z0 + z1),
            a: 0.5 * (x1 - x0) + params.clearance,
            b: 0.5 * (z1 - z0) + params.clearance,
        }
    }

    /// Scale up (about the centre) until the perimeter is at least `need`.
    fn widen(&mut self, need: f64) {
        let p = self.perimeter();
        if p < need {
            self.a *= need / p;
            self.b *= need / p;
        }
    }

    fn lerp(&self, o: &Self, t: f64) -> Self {
        let f = |a: f64, b: f64| a + (b - a) * t;
        Self {
            cx: f(self.cx, o.cx),
            cz: f(self.cz, o.cz),
            a: f(self.a, o.a),
            b: f(self.b, o.b),
        }
    }

    /// Ramanujan's perimeter.
    fn perimeter(&self) -> f64 {
        let (a, b) = (self.a, self.b);
        let h = ((a - b) / (a + b)).powi(2);
        std::f64::consts::PI * (a + b) * (1.0 + 3.0 * h / (10.0 + (4.0 - 3.0 * h).sqrt()))
    }

    /// The point at arc length `s` from the point at parametric angle `theta`
    /// (x = cx + a sin θ, z = cz + b cos θ; s > 0 turns towards +x at the front).
    fn at_arc(&self, theta: f64, s: f64) -> (f64, f64) {
        // Integrate dθ = ds / |dP/dθ| in small steps (RK2).
        let speed = |t: f64| (self.a * t.cos()).hypot(self.b * t.sin());
        let steps = ((s.abs() / 1e-3).ceil() as usize).max(1);
        let ds = s / steps as f64;
        let mut t = theta;
        for _ in 0..steps {
            let mid = t + 0.5 * ds / speed(t);
            t += ds / speed(mid);
        }
        (self.cx + self.a * t.sin(), self.cz + self.b * t.cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Arc length along the ellipse is kept: a quarter perimeter from the front reaches the side.
    #[test]
    fn arc_length_on_the_ellipse() {
        let e = Ellipse {
            cx: 0.1,
            cz: -0.2,
            a: 0.2,
            b: 0.1,
        };
        let (x, z) = e.at_arc(0.0, 0.25 * e.perimeter());
        assert!((x - 0.3).abs() < 1e-4 && (z + 0.2).abs() < 1e-4, "{x} {z}");
        let (x, z) = e.at_arc(std::f64::consts::PI, 0.5 * e.perimeter());
        assert!((x - 0.1).abs() < 1e-4 && (z + 0.1).abs() < 1e-4, "{x} {z}");
        // A circle: exact.
        let c = Ellipse {
            cx: 0.0,
            cz: 0.0,
            a: 0.3,
            b: 0.3,
        };
        assert!((c.perimeter() - std::f64::consts::TAU * 0.3).abs() < 1e-12);
        let (x, z) = c.at_arc(0.0, 0.3);
        assert!((x - 1f64.sin() * 0.3).abs() < 1e-9 && (z - 1f64.cos() * 0.3).abs() < 1e-9);
    }
}
