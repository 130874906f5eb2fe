//! The step's scratch buffers: sized once for a cloth, reused by every step after (no
//! allocation per step once sized).

use atelier_grid::SLOTS;

use super::par::resize;
use super::projection::{CellShear, NodeBend};
use super::{Solver, Tie, V3};
use crate::cloth::Cloth;

/// Reusable scratch buffers of the step (no allocation once sized).
#[derive(Default)]
pub(super) struct Scratch {
    pub(super) tri_normal: Vec<V3>,
    pub(super) normal: Vec<V3>,
    pub(super) exit: Vec<V3>,
    pub(super) dir: Vec<V3>,
    pub(super) len: Vec<f64>,
    pub(super) eta: Vec<[f64; SLOTS]>,
    pub(super) node_moment: Vec<f64>,
    pub(super) slot_coef: Vec<[f64; SLOTS]>,
    pub(super) slot_len: Vec<[f64; SLOTS]>,
    pub(super) w: Vec<f64>,
    pub(super) w_r: Vec<f64>,
    pub(super) w_z: Vec<f64>,
    pub(super) w_p: Vec<f64>,
    pub(super) w_ap: Vec<f64>,
    pub(super) w_dm: Vec<f64>,
    pub(super) w_rhat: Vec<f64>,
    pub(super) w_v: Vec<f64>,
    pub(super) w_y: Vec<f64>,
    pub(super) w_t: Vec<f64>,
    pub(super) f_sum: Vec<V3>,
    pub(super) f_m: Vec<V3>,
    pub(super) p: Vec<f64>,
    pub(super) p_prev: Vec<f64>,
    pub(super) p_warm: Vec<f64>,
    pub(super) ph_p: Vec<f64>,
    pub(super) ph_prev: Vec<f64>,
    pub(super) ph_y: Vec<f64>,
    pub(super) ph_partial: Vec<[f64; 2]>,
    pub(super) p_y: Vec<f64>,
    pub(super) grad: Vec<f64>,
    pub(super) force_per_width: Vec<f64>,
    pub(super) target: Vec<f64>,
    /// Each cell's shear angle at the end of the step, rad.
    pub(super) shear: Vec<f64>,
    /// Each cell's shear constraint of this step (empty: none).
    pub(super) cell_shear: Vec<CellShear>,
    /// Each node's bending constraints of this step, u and v (empty: none).
    pub(super) node_bend: Vec<NodeBend>,
    /// Contact planes set by the hooks this step.
    pub(super) planes: Vec<atelier_collide::ContactPlane>,
    /// The surface's reaction on the nodes lying on it (pressure stage only).
    pub(super) reaction: Vec<V3>,
    /// Node pairs held within a distance this step.
    pub(super) ties: Vec<Tie>,
    /// The long-range attachments of the cloth's pins (built when the pins change).
    pub(super) long_range: Option<crate::long_range::LongRange>,
    /// Whether `project` applies them this step.
    pub(super) long_range_on: bool,
    /// This step's largest target strain (the attachments' slack).
    pub(super) long_range_slack: f64,
    pub(super) vel: Vec<V3>,
    pub(super) pred: Vec<V3>,
    pub(super) chunk: Vec<f64>,
}

impl Solver {
    /// Size the scratch for `cloth` (nothing changes when it already is), and drop external
    /// forces that do not have one entry per node.
    pub(super) fn size(&mut self, cloth: &Cloth) {
        let topo = cloth.topology();
        let (n, ne, nt, nc) = (
            topo.node_count(),
            topo.edges().len(),
            topo.triangles().len(),
            topo.cells().len(),
        );
        let s = &mut self.s;
        let z = V3::zeros();
        resize(&mut s.tri_normal, nt, z);
        for v in [
            &mut s.normal,
            &mut s.exit,
            &mut s.f_sum,
            &mut s.f_m,
            &mut s.vel,
            &mut s.pred,
        ] {
            resize(v, n, z);
        }
        resize(&mut s.eta, n, [0.0; SLOTS]);
        for v in [
            &mut s.node_moment,
            &mut s.w,
            &mut s.w_r,
            &mut s.w_z,
            &mut s.w_p,
            &mut s.w_ap,
            &mut s.w_dm,
        ] {
            resize(v, n, 0.0);
        }
        resize(&mut s.slot_coef, n, [0.0; SLOTS]);
        resize(&mut s.slot_len, n, [0.0; SLOTS]);
        resize(&mut s.dir, ne, z);
        for v in [
            &mut s.len,
            &mut s.p,
            &mut s.p_prev,
            &mut s.p_warm,
            &mut s.p_y,
            &mut s.grad,
            &mut s.force_per_width,
            &mut s.target,
        ] {
            resize(v, ne, 0.0);
        }
        resize(&mut s.planes, n, atelier_collide::ContactPlane::default());
        resize(&mut s.shear, nc, 0.0);
        if self.external_forces.len() != n {
            self.external_forces.clear();
        }
    }
}
