//! The collision stages of a step (thesis §5.3–5.5, `method.md` §3): the geometric transfer of
//! body motion (staged model) and the physical collision pass (cloth against the body, cloth
//! against itself), over plain slices.

use rayon::prelude::*;

use crate::broad::{BroadPhase, new_broad};
use crate::geom::V3;
pub use crate::geom::closest_point;
use crate::narrow::{
    Hit, NarrowTest, Sides, last_pass_through, point_triangle, point_triangle_thesis,
};
use crate::parts::{Motion, PartsError, RigidParts};
use crate::response::respond;

pub use params::{ContactError, ContactParams, ContactPlane};

use node::{
    MAX_AGAIN, MAX_CONTACTS, NodeOutcome, NodeView, PASS_DEPTH, cloth_velocity, nearest_outside,
    push_out, recover, side_of, tangent_plane,
};

mod node;
mod params;
mod vertex;

use crate::geom::vertex_normals;

/// The cloth as a collision pass sees it.
pub struct ClothView<'a> {
    /// Positions at the start of the step.
    pub positions: &'a [V3],
    /// Velocities being corrected (a node moves by `velocity·dt`).
    pub velocities: &'a mut [V3],
    /// Added to the velocity after the position update: a contact's exit velocity minus the
    /// mean velocity the node moved with.
    pub exit: &'a mut [V3],
    /// Inverse masses (0: pinned, never moved).
    pub inverse_masses: &'a [f64],
    /// The cloth's triangles (for self-collision).
    pub triangles: &'a [[u32; 3]],
    /// Unit node normals (for one-sided contact); may be empty when not needed.
    pub normals: &'a [V3],
    /// Contact planes the shape iterations respect (`ContactParams::plane_reach`), one per
    /// node; may be empty when not used.
    pub planes: &'a mut [ContactPlane],
}

/// Counts of one pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PassStats {
    /// Node–triangle pairs the broad phase returned.
    pub candidates: usize,
    /// Contacts with the body.
    pub body_hits: usize,
    /// Contacts with the cloth itself.
    pub self_hits: usize,
    /// Nodes the geometric transfer moved with the body.
    pub transferred: usize,
    /// Nodes found inside the body (shallower than the recovery depth) and moved out.
    pub recovered: usize,
    /// Contacts taken again with a turning or deforming triangle a node had met in the pass
    /// (counted in `body_hits` and `self_hits` too).
    pub again: usize,
    /// Nodes put on the end plane of such a triangle after `MAX_AGAIN` contacts taken again.
    pub pushed: usize,
    /// Nodes given a contact plane for the shape iterations (within `plane_reach` of the body,
    /// or inside it, at the start of the step).
    pub planes: usize,
    /// Node planes lifted over a body vertex.
    pub vertex_planes: usize,
}

struct Body {
    start: Vec<V3>,
    end: Vec<V3>,
    /// Vertex velocity over the current step.
    vel: Vec<V3>,
    /// Vertex velocity over the previous step (zero before the first).
    prev_vel: Vec<V3>,
    triangles: Vec<[u32; 3]>,
    end_normals: Vec<V3>,
    broad: Box<dyn BroadPhase>,
    max_displacement: f64,
}

/// A node's velocity change and contact plane from the transfer on rigid parts (`None`: no body
/// point within reach).
type PartTransfer = Option<(V3, Option<ContactPlane>)>;

/// The collision stages. With no body and no self-collision it holds nothing and does nothing.
pub struct Collider {
    params: ContactParams,
    body: Option<Body>,
    /// The body as rigid parts (exact union distance) for the nearest-point queries: transfer
    /// and contact planes. Without it they use the body's triangles.
    parts: Option<RigidParts>,
    /// Per node: velocity change and contact plane found by the parts transfer.
    part_results: Vec<PartTransfer>,
    /// Per cloth node, the group of nodes that are one point of the garment (a seam's two
    /// sides): self-collision ignores a triangle with a node of the same group. Empty: every
    /// node is its own group.
    groups: Vec<u32>,
    /// Per node: its distance to the body at the start of the step as the parts transfer found
    /// it (negative inside), or a lower bound (the search reach) when it is farther.
    start_distance: Vec<f64>,
    cloth_broad: Option<Box<dyn BroadPhase>>,
    candidates: Vec<u32>,
    cloth_end: Vec<V3>,
    stats: PassStats,
}

impl Collider {
    /// A collider with checked parameters.
    pub fn new(params: ContactParams) -> Result<Self, ContactError> {
        params.check()?;
        Ok(Self {
            params,
            body: None,
            parts: None,
            part_results: Vec::new(),
            groups: Vec::new(),
            start_distance: Vec::new(),
            cloth_broad: None,
            candidates: Vec::new(),
            cloth_end: Vec::new(),
            stats: PassStats::default(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &ContactParams {
        &self.params
    }

    /// Counts since the last [`Collider::take_stats`].
    pub fn take_stats(&mut self) -> PassStats {
        std::mem::take(&mut self.stats)
    }

    /// The body over the coming step: vertices at its start and its end, triangles with outward
    /// (counter-clockwise) normals. The first call builds the broad phase; later calls with the
    /// same triangles refit it.
    pub fn set_body(
        &mut self,
        start: &[V3],
        end: &[V3],
        triangles: &[[u32; 3]],
        dt: f64,
    ) -> Result<(), ContactError> {
        if start.len() != end.len() {
            return Err(ContactError::BodyMismatch {
                start: start.len(),
                end: end.len(),
            });
        }
        if let Some(vertex) = start
            .iter()
            .chain(end)
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(ContactError::BodyNotFinite {
                vertex: vertex % start.len().max(1),
            });
        }
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&vertex) = tri.iter().find(|&&k| k as usize >= start.len()) {
                return Err(ContactError::BodyIndex {
                    triangle: t,
                    vertex,
                    count: start.len(),
                });
            }
        }
        let same = self
            .body
            .as_ref()
            .is_some_and(|b| b.triangles == triangles && b.start.len() == start.len());
        if !same {
            self.body = Some(Body {
                start: Vec::new(),
                end: Vec::new(),
                vel: vec![V3::zeros(); start.len()],
                prev_vel: vec![V3::zeros(); start.len()],
                triangles: triangles.to_vec(),
                end_normals: Vec::new(),
                broad: new_broad(self.params.broad),
                max_displacement: 0.0,
            });
        }
        let body = self.body.as_mut().expect("set above");
        std::mem::swap(&mut body.prev_vel, &mut body.vel);
        body.start.clear();
        body.start.extend_from_slice(start);
        body.end.clear();
        body.end.extend_from_slice(end);
        body.vel.clear();
        let inv_dt = if dt > 0.0 { 1.0 / dt } else { 0.0 };
        body.vel
            .extend(start.iter().zip(end).map(|(a, b)| (b - a) * inv_dt));
        if self.params.vertex_planes {
            vertex_normals(end, triangles, &mut body.end_normals);
        }
        body.max_displacement = start
            .iter()
            .zip(end)
            .map(|(a, b)| (b - a).norm())
            .fold(0.0, f64::max);
        // Swept boxes grown by the skin; the transfer queries with its reach as the radius.
        body.broad
            .update(start, end, triangles, self.params.thickness);
        Ok(())
    }

    /// Remove the body (nothing collides with it afterwards).
    pub fn clear_body(&mut self) {
        self.body = None;
        self.parts = None;
    }

    /// The body as rigid parts as well (its triangles, given to [`Collider::set_body`], keep the
    /// continuous test): the transfer of body motion and the contact planes then take the
    /// nearest point of the parts' union, which no face buried in another part can be.
    pub fn set_parts(&mut self, parts: RigidParts) {
        self.parts = Some(parts);
    }

    /// The rigid parts, if set.
    pub fn parts(&self) -> Option<&RigidParts> {
        self.parts.as_ref()
    }

    /// Each node's distance to the body at the start of the last step as the parts transfer
    /// found it (negative inside), or a lower bound when it was beyond the search's reach; empty
    /// without rigid parts.
    pub fn start_distances(&self) -> &[f64] {
        &self.start_distance
    }

    /// The parts' motion over the coming step (rest → world at its start and end).
    ///
    /// # Errors
    /// [`ContactError::Parts`] when no parts are set or the motion is refused.
    pub fn set_part_motion(
        &mut self,
        start: &[Motion],
        end: &[Motion],
        dt: f64,
    ) -> Result<(), ContactError> {
        match self.parts.as_mut() {
            Some(parts) => Ok(parts.set_motion(start, end, dt)?),
            None => Err(ContactError::Parts(PartsError::Empty)),
        }
    }

    /// Nodes that are one point of the garment (`groups[i]` the same for the nodes of a seam's
    /// two sides): self-collision lets them and the triangles around them pass, as it does a
    /// node and its own triangles. Empty: none.
    pub fn set_cloth_groups(&mut self, groups: Vec<u32>) {
        self.groups = groups;
    }

    /// Turn self-collision on or off (the cloth's broad phase is built at the next pass that
    /// needs it).
    pub fn set_self_collision(&mut self, on: bool) {
        self.params.self_collision = on;
    }

    /// Change the static friction ρ against the body (and the cloth).
    pub fn set_friction(&mut self, friction: f64) {
        self.params.material.friction = friction;
    }

    /// Turn one-sided contact on or off (the thesis's dressing through the body, then normal
    /// contact once the garment is on).
    pub fn set_one_sided(&mut self, on: bool) {
        self.params.one_sided = on;
    }

    /// Whether any collision work is configured.
    pub fn is_active(&self) -> bool {
        self.body.is_some() || self.parts.is_some() || self.params.self_collision
    }

    /// The staged model's geometric stage (thesis §5.4, (75)): every free cloth node within
    /// reach (the body's largest displacement this step plus the margin) of the body, on its
    /// outside, takes on the change of the body's velocity at the nearest body point since the
    /// previous step, so the cloth moves with the body and the physical stage sees a small
    /// relative speed.
    ///
    /// `normals` (the cloth's unit node normals, or empty) decide one-sided contact on rigid
    /// parts: a node whose normal disagrees with the body's gets no plane.
    pub fn transfer(
        &mut self,
        positions: &[V3],
        velocities: &mut [V3],
        inverse_masses: &[f64],
        normals: &[V3],
        planes: &mut [ContactPlane],
    ) {
        if self.parts.is_some() {
            self.transfer_parts(positions, velocities, inverse_masses, normals, planes);
            return;
        }
        let Some(body) = self.body.as_ref() else {
            return;
        };
        if !self.params.staged {
            if self.params.plane_reach > 0.0 && !planes.is_empty() {
                for (i, p) in positions.iter().enumerate() {
                    if inverse_masses[i] == 0.0 {
                        continue;
                    }
                    self.candidates.clear();
                    body.broad
                        .query(p, p, self.params.plane_reach, &mut self.candidates);
                    if let Some((dist, t, w)) = nearest_outside(
                        body,
                        p,
                        &self.candidates,
                        self.params.plane_reach,
                        self.params.thickness,
                    ) {
                        planes[i] = tangent_plane(body, p, dist, t, w, &self.params);
                        self.stats.planes += 1;
                    }
                }
            }
            return;
        }
        let reach = body.max_displacement + self.params.transfer_margin;
        // Search a small ball first: most cloth near a body is within a centimetre of it, and a
        // nearest point found inside the small ball is the nearest within the whole reach (any
        // nearer triangle would have been a candidate too).
        let near = reach.min(body.max_displacement + 0.01);
        let mut transferred = 0;
        for (i, p) in positions.iter().enumerate() {
            if inverse_masses[i] == 0.0 {
                continue;
            }
            let mut best: Option<(f64, usize, [f64; 3])> = None;
            for radius in [near, reach] {
                self.candidates.clear();
                body.broad.query(p, p, radius, &mut self.candidates);
                best = nearest_outside(body, p, &self.candidates, radius, self.params.thickness);
                if best.is_some() || radius >= reach {
                    break;
                }
            }
            if let Some((dist, t, w)) = best {
                if dist < self.params.plane_reach && !planes.is_empty() {
                    planes[i] = tangent_plane(body, p, dist, t, w, &self.params);
                    self.stats.planes += 1;
                }
                let tri = body.triangles[t];
                let dv: V3 = (0..3)
                    .map(|k| (body.vel[tri[k] as usize] - body.prev_vel[tri[k] as usize]) * w[k])
                    .sum();
                velocities[i] += dv;
                transferred += 1;
            }
        }
        self.stats.transferred += transferred;
    }

    /// The transfer on rigid parts, node by node in parallel: the nearest point of the union
    /// within reach (the parts' largest displacement plus the margin when staged, else the
    /// plane reach) gives the change of the body's velocity (staged, nodes outside) and, within
    /// `plane_reach` or inside, the contact plane at the end of the step.
    fn transfer_parts(
        &mut self,
        positions: &[V3],
        velocities: &mut [V3],
        inverse_masses: &[f64],
        normals: &[V3],
        planes: &mut [ContactPlane],
    ) {
        let Some(parts) = self.parts.as_ref() else {
            return;
        };
        let p = self.params;
        let with_planes = p.plane_reach > 0.0 && !planes.is_empty();
        // The body's motion reaches as far as it moves plus the margin; a still body has none to
        // transfer, and only the planes' reach is searched.
        let transfer = p.staged && !parts.is_still();
        let reach = if transfer {
            (parts.max_displacement() + p.transfer_margin).max(p.plane_reach)
        } else {
            p.plane_reach
        };
        self.part_results.clear();
        self.part_results.resize(positions.len(), None);
        self.start_distance.clear();
        self.start_distance.resize(positions.len(), reach);
        let find = |(i, (out, dist)): (usize, (&mut PartTransfer, &mut f64))| {
            if inverse_masses[i] == 0.0 {
                return;
            }
            let Some(n) = parts.nearest(&positions[i], reach, false) else {
                return;
            };
            *dist = n.distance;
            let dv = if transfer && n.distance >= -p.thickness {
                parts.velocity_change(&n)
            } else {
                V3::zeros()
            };
            // One-sided: only where the cloth's inside faces the body, and not for a node deep
            // inside (one passing through the body from its outside, met its far side).
            let one_sided_miss = p.one_sided
                && ((!normals.is_empty() && normals[i].dot(&parts.place(&n, false).1) <= 0.0)
                    || n.distance < -p.recovery_depth);
            let plane = (with_planes && n.distance < p.plane_reach && !one_sided_miss).then(|| {
                let (q, normal) = parts.place(&n, true);
                ContactPlane {
                    point: q + normal * p.thickness,
                    normal,
                    velocity: parts.velocity(&n),
                    friction: p.material.friction,
                }
            });
            *out = Some((dv, plane));
        };
        if positions.len() >= 256 {
            self.part_results
                .par_iter_mut()
                .zip(self.start_distance.par_iter_mut())
                .enumerate()
                .for_each(find);
        } else {
            self.part_results
                .iter_mut()
                .zip(self.start_distance.iter_mut())
                .enumerate()
                .for_each(find);
        }
        for (i, r) in self.part_results.iter().enumerate() {
            let Some((dv, plane)) = r else {
                continue;
            };
            if transfer {
                velocities[i] += dv;
                self.stats.transferred += 1;
            }
            if let Some(plane) = plane {
                planes[i] = *plane;
                self.stats.planes += 1;
            }
        }
    }

    /// One physical collision pass: every free node against the body's triangles (moving from
    /// start to end) and, with self-collision, against the cloth's triangles that do not contain
    /// it. Each node takes its earliest contact, then the next, up to three. With self-collision
    /// nodes are visited in index order (a contact changes the triangle's vertices too); without
    /// it every node's contacts depend on that node alone and the nodes are resolved in parallel
    /// (the same result as in order).
    pub fn resolve(&mut self, cloth: ClothView<'_>, dt: f64) {
        if !self.is_active() || dt <= 0.0 {
            return;
        }
        let ClothView {
            positions,
            velocities,
            exit,
            inverse_masses,
            triangles,
            normals,
            planes,
        } = cloth;
        let n = positions.len();
        let p = self.params;
        if p.self_collision {
            self.cloth_end.clear();
            self.cloth_end
                .extend((0..n).map(|i| positions[i] + velocities[i] * dt));
            let broad = self.cloth_broad.get_or_insert_with(|| new_broad(p.broad));
            broad.update(positions, &self.cloth_end, triangles, p.thickness);
            let mut candidates = std::mem::take(&mut self.candidates);
            for i in 0..n {
                if inverse_masses[i] == 0.0 {
                    continue;
                }
                let view = NodeView {
                    positions,
                    velocities,
                    inverse_masses,
                    triangles,
                    normals,
                };
                let r = self.node_pass(i, &view, dt, &mut candidates);
                self.apply(i, &r, velocities, exit, planes);
                for &(k, dv) in &r.cloth_dv {
                    velocities[k] += dv;
                }
            }
            self.candidates = candidates;
            return;
        }
        let view = NodeView {
            positions,
            velocities,
            inverse_masses,
            triangles,
            normals,
        };
        let this = &*self;
        let results: Vec<(usize, NodeOutcome)> = (0..n)
            .into_par_iter()
            .with_min_len(256)
            .map_init(Vec::new, |candidates, i| {
                if inverse_masses[i] == 0.0 {
                    return (i, NodeOutcome::default());
                }
                (i, this.node_pass(i, &view, dt, candidates))
            })
            .filter(|(_, r)| r.changed())
            .collect();
        for (i, r) in &results {
            self.apply(*i, r, velocities, exit, planes);
        }
    }

    /// Write one node's outcome and count it.
    fn apply(
        &mut self,
        i: usize,
        r: &NodeOutcome,
        velocities: &mut [V3],
        exit: &mut [V3],
        planes: &mut [ContactPlane],
    ) {
        self.stats.candidates += r.candidates;
        self.stats.body_hits += r.body_hits;
        self.stats.self_hits += r.self_hits;
        self.stats.recovered += usize::from(r.recovered);
        self.stats.again += r.again;
        self.stats.pushed += usize::from(r.pushed);
        if let Some(v) = r.velocity {
            velocities[i] = v;
        }
        exit[i] += r.exit;
        if let Some(plane) = r.plane
            && !planes.is_empty()
        {
            planes[i] = plane;
        }
    }

    /// One node's contacts in a pass: its earliest contact, then (with its corrected motion)
    /// the earliest with a surface it has not met yet, up to `MAX_CONTACTS` — a node in a crease
    /// between two parts meets both. A triangle it has met is not hit again unless it turned or
    /// deformed into the corrected path, so that the node would end the step behind it having
    /// passed through it; then the contact is taken again at that last passage. Reads the node's
    /// own velocity (and, with self-collision, the velocities of the cloth triangles it meets, as
    /// its contacts in this pass change them); returns what changes.
    fn node_pass(
        &self,
        i: usize,
        view: &NodeView<'_>,
        dt: f64,
        candidates: &mut Vec<u32>,
    ) -> NodeOutcome {
        let p = self.params;
        let test = match p.narrow {
            NarrowTest::Exact => point_triangle,
            NarrowTest::Thesis => point_triangle_thesis,
        };
        let NodeView {
            positions,
            velocities,
            inverse_masses,
            triangles,
            normals,
        } = *view;
        let mut out = NodeOutcome::default();
        let pi = positions[i];
        let mut vi = velocities[i];
        // The triangles met so far: (triangle, whether it is the cloth's, the side the node
        // came from as ±1 times the triangle's counter-clockwise normal).
        let mut met: [(usize, bool, f64); MAX_CONTACTS] = [(usize::MAX, false, 1.0); MAX_CONTACTS];
        let mut n_met = 0;
        let mut again_left = MAX_AGAIN;
        // Whether the last round asked every met triangle `last_pass_through` with the node's
        // final motion and none answered (then the failsafe below has nothing to do).
        let mut settled = false;
        loop {
            let end = pi + vi * dt;
            let new = n_met < MAX_CONTACTS;
            // Earliest contact: (hit, triangle, whether it is the cloth's).
            let mut best: Option<(Hit, usize, bool)> = None;
            if new && let Some(body) = self.body.as_ref() {
                candidates.clear();
                body.broad.query(&pi, &end, p.thickness, candidates);
                out.candidates += candidates.len();
                for &t in candidates.iter() {
                    let tri = body.triangles[t as usize];
                    let x = tri.map(|k| &body.start[k as usize]);
                    let u = tri.map(|k| &body.vel[k as usize]);
                    if let Some(hit) = test(&pi, &vi, x, u, dt, p.thickness, Sides::Front) {
                        if p.one_sided && !normals.is_empty() && normals[i].dot(&hit.normal) <= 0.0
                        {
                            continue;
                        }
                        if best.is_none_or(|b| hit.time < b.0.time)
                            && !met[..n_met]
                                .iter()
                                .any(|m| (m.0, m.1) == (t as usize, false))
                        {
                            best = Some((hit, t as usize, false));
                        }
                    }
                }
            }
            if new
                && p.self_collision
                && let Some(broad) = self.cloth_broad.as_ref()
            {
                candidates.clear();
                broad.query(&pi, &end, p.thickness, candidates);
                out.candidates += candidates.len();
                for &t in candidates.iter() {
                    let tri = triangles[t as usize];
                    if tri.contains(&(i as u32))
                        || (!self.groups.is_empty()
                            && tri
                                .iter()
                                .any(|&k| self.groups[k as usize] == self.groups[i]))
                    {
                        continue;
                    }
                    let x = tri.map(|k| &positions[k as usize]);
                    let u = tri.map(|k| &velocities[k as usize]);
                    if let Some(hit) = test(&pi, &vi, x, u, dt, p.thickness, Sides::Both)
                        && best.is_none_or(|b| hit.time < b.0.time)
                        && !met[..n_met]
                            .iter()
                            .any(|m| (m.0, m.1) == (t as usize, true))
                    {
                        best = Some((hit, t as usize, true));
                    }
                }
            }
            // A triangle met before that turned or deformed into the corrected path: the node
            // would end the step behind it, having passed through it after the contact.
            for &(t, is_cloth, side) in met[..n_met].iter().filter(|_| again_left > 0) {
                let (x, u) = self.met_motion(t, is_cloth, view, &out.cloth_dv);
                if let Some(hit) = last_pass_through(
                    &pi,
                    &vi,
                    [&x[0], &x[1], &x[2]],
                    [&u[0], &u[1], &u[2]],
                    dt,
                    side,
                    PASS_DEPTH,
                ) && best.is_none_or(|b| hit.time < b.0.time)
                {
                    best = Some((hit, t, is_cloth));
                }
            }
            let Some((hit, t, is_cloth)) = best else {
                if n_met == 0
                    && p.recovery_depth > p.thickness
                    && self.parts.is_none()
                    && let Some(body) = self.body.as_ref()
                    && let Some(dv) = recover(body, &pi, &vi, dt, p, candidates)
                {
                    vi += dv;
                    out.velocity = Some(vi);
                    out.recovered = true;
                }
                settled = again_left > 0;
                break;
            };
            let again = met[..n_met].iter().any(|m| (m.0, m.1) == (t, is_cloth));
            let (tri, inv_mu, u) = if is_cloth {
                let tri = triangles[t];
                (
                    tri,
                    tri.map(|k| inverse_masses[k as usize]),
                    // Met again: as this pass has moved it.
                    tri.map(|k| {
                        if again {
                            cloth_velocity(k as usize, velocities, &out.cloth_dv)
                        } else {
                            velocities[k as usize]
                        }
                    }),
                )
            } else {
                let body = self.body.as_ref().expect("body hit");
                let tri = body.triangles[t];
                (tri, [0.0; 3], tri.map(|k| body.vel[k as usize]))
            };
            if again {
                again_left -= 1;
                out.again += 1;
            } else {
                let x = if is_cloth {
                    tri.map(|k| positions[k as usize])
                } else {
                    let body = self.body.as_ref().expect("body hit");
                    tri.map(|k| body.start[k as usize])
                };
                met[n_met] = (t, is_cloth, side_of(&hit, &x, &u));
                n_met += 1;
            }
            let Some(r) = respond(
                &vi,
                inverse_masses[i],
                [&u[0], &u[1], &u[2]],
                inv_mu,
                hit.weights,
                &hit.normal,
                hit.time,
                dt,
                p.material,
            ) else {
                break;
            };
            vi = r.mean;
            out.velocity = Some(vi);
            out.exit += r.exit - r.mean;
            if is_cloth {
                for (&k, dv) in tri.iter().zip(r.vertex_dv) {
                    out.cloth_dv.push((k as usize, dv));
                }
                out.self_hits += 1;
            } else {
                if p.plane_reach > 0.0 {
                    let body = self.body.as_ref().expect("body hit");
                    let q: V3 = (0..3)
                        .map(|k| body.end[tri[k] as usize] * hit.weights[k])
                        .sum();
                    out.plane = Some(ContactPlane {
                        point: q + hit.normal * p.thickness,
                        normal: hit.normal,
                        velocity: (0..3)
                            .map(|k| body.vel[tri[k] as usize] * hit.weights[k])
                            .sum(),
                        friction: p.material.friction,
                    });
                }
                out.body_hits += 1;
            }
        }
        if !settled {
            // The contacts taken again (all of `MAX_AGAIN`, or one the response refused) may
            // not have kept the node in front of a turning triangle: put its end on the
            // triangle's end plane (`push_out`).
            for &(t, is_cloth, side) in &met[..n_met] {
                let (tri, inv_mu) = if is_cloth {
                    let tri = triangles[t];
                    (tri, tri.map(|k| inverse_masses[k as usize]))
                } else {
                    (self.body.as_ref().expect("body hit").triangles[t], [0.0; 3])
                };
                let (x, u) = self.met_motion(t, is_cloth, view, &out.cloth_dv);
                let dv = push_out(&pi, &mut vi, inverse_masses[i], &x, &u, inv_mu, dt, side);
                if let Some(dv) = dv {
                    out.velocity = Some(vi);
                    out.pushed = true;
                    if is_cloth {
                        for (&k, dv) in tri.iter().zip(dv) {
                            out.cloth_dv.push((k as usize, dv));
                        }
                    }
                }
            }
        }
        out
    }

    /// The start vertices and velocities of a triangle a node has met (a cloth triangle's
    /// velocities as this node's contacts in the pass have changed them: `dv`).
    fn met_motion(
        &self,
        t: usize,
        is_cloth: bool,
        view: &NodeView<'_>,
        dv: &[(usize, V3)],
    ) -> ([V3; 3], [V3; 3]) {
        if is_cloth {
            let tri = view.triangles[t];
            (
                tri.map(|k| view.positions[k as usize]),
                tri.map(|k| cloth_velocity(k as usize, view.velocities, dv)),
            )
        } else {
            let body = self.body.as_ref().expect("body hit");
            let tri = body.triangles[t];
            (
                tri.map(|k| body.start[k as usize]),
                tri.map(|k| body.vel[k as usize]),
            )
        }
    }
}
