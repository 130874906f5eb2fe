//! The contact planes inside the shape solve: the active set updated, entering nodes held,
//! the velocities projected onto the planes.

use super::{ON_PLANE, ShapeProblem, ShapeSolver, V3};
use crate::step::plane_push;

impl ShapeSolver {
    /// The contact planes in the Newton system: a node that lies on its plane (pushed there by
    /// the last projection) moves only along it in the next step, W = w(I − nnᵀ) — unless the
    /// rows' forces pull it off the plane, when it is released. Without this the Newton step
    /// moves nodes through the body, the projection pushes them back, and a seam drawn
    /// together around the body never converges. Renews the factorization when the set
    /// changed.
    pub(super) fn update_contacts(&mut self, p: &ShapeProblem<'_>, vel: &[V3]) {
        let Some(st) = self.structure.as_mut() else {
            return;
        };
        let n = self.root.len();
        if self.on_plane.len() != n {
            self.on_plane = vec![false; n];
            self.stuck = vec![false; n];
        }
        let mut changed = false;
        for i in 0..n {
            let r = self.root[i] as usize;
            let plane = &p.planes[i];
            let mut on = false;
            if plane.normal != V3::zeros() && st.system.weight[r].w > 0.0 {
                let x = p.positions[i] + vel[i] * p.dt;
                let d = (x - plane.point).dot(&plane.normal);
                // Released when the balance the rows' forces alone would give, x̃ + w Jᵀλ (the
                // inertial prediction moved by the constraint forces), lies in front of the
                // plane: the contact would have to pull. Releasing on the constraint forces'
                // direction alone (Jᵀλ·n > 0) let a node whose inertia carries it into the
                // body go, the Newton step moved it in, and the projection pushed it back:
                // the step was then no descent direction for the rows at that node (a sewn
                // armhole stalled at 4e-2 for 100 iterations).
                let balance = p.positions[i]
                    + self.base[i] * p.dt
                    + st.system.jt_at(&self.lambda, r) * st.system.weight[r].w;
                let pulled_off = (balance - plane.point).dot(&plane.normal) > 0.0;
                on = d <= ON_PLANE * self.spacing[i] && (!pulled_off || self.stuck[i]);
            }
            if on != self.on_plane[i] {
                self.on_plane[i] = on;
                changed = true;
            }
        }
        if changed {
            for w in st.system.weight.iter_mut() {
                w.n = V3::zeros();
            }
            for i in 0..n {
                if self.on_plane[i] {
                    st.system.weight[self.root[i] as usize].n = p.planes[i].normal;
                }
            }
            st.system.invalidate();
        }
    }

    /// Hold on its plane every released node that lies on it and that the Newton step just
    /// solved would carry behind it; whether any was.
    pub(super) fn hold_entering(&mut self, p: &ShapeProblem<'_>, vel: &[V3]) -> bool {
        let Some(st) = self.structure.as_mut() else {
            return false;
        };
        let mut changed = false;
        for i in 0..self.root.len() {
            let r = self.root[i] as usize;
            let plane = &p.planes[i];
            if self.on_plane[i] || plane.normal == V3::zeros() || st.system.weight[r].w <= 0.0 {
                continue;
            }
            let d = (p.positions[i] + vel[i] * p.dt - plane.point).dot(&plane.normal);
            if d <= ON_PLANE * self.spacing[i] && d + self.newton_dx[r].dot(&plane.normal) < 0.0 {
                self.on_plane[i] = true;
                self.stuck[i] = true;
                st.system.weight[r].n = plane.normal;
                changed = true;
            }
        }
        if changed {
            st.system.invalidate();
        }
        changed
    }

    /// Pins at their prescribed positions, groups collapsed, nodes pushed in front of their
    /// planes (with friction), groups collapsed again.
    pub(super) fn project(&self, p: &ShapeProblem<'_>, vel: &mut [V3]) {
        for pin in p.cloth.pins() {
            let i = pin.node as usize;
            vel[i] = (pin.position(p.time + p.dt) - p.positions[i]) / p.dt;
        }
        self.collapse(p, vel);
        let inv = p.cloth.inverse_masses();
        for (i, plane) in p.planes.iter().enumerate() {
            if plane.normal == V3::zeros() {
                continue;
            }
            let pushed = plane_push(vel[i], &p.positions[i], plane, p.dt);
            let change = pushed - vel[i];
            if change == V3::zeros() {
                continue;
            }
            // A sewn group moves as one point: the push of one member's plane moves all of
            // them (pushing the member alone and collapsing again would move the group by
            // only its share, and repeated projections would drift it outwards).
            let r = self.root[i] as usize;
            let members =
                &self.members[self.member_ptr[r] as usize..self.member_ptr[r + 1] as usize];
            if members.len() > 1 {
                for &k in members {
                    if inv[k as usize] > 0.0 {
                        vel[k as usize] += change;
                    }
                }
            } else {
                vel[i] = pushed;
            }
        }
    }
}
