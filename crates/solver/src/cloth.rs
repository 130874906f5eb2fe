//! The static description of one piece of cloth for the solver: its topology, the fabric's
//! characteristics at every edge angle, node masses, and pins (inverse mass 0, fixed or moving).

use atelier_fabric::{AnisotropyForm, Fabric, InvalidValue, MaterialTable};
use atelier_grid::{ClothTopology, EdgeKind, NO_NODE, SLOTS};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::shear::ShearCurve;

/// How a pinned node moves (its position is prescribed; the solver never moves it otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum PinMotion {
    /// Held at its anchor.
    Fixed,
    /// Moving at a constant velocity (m/s) from its anchor, starting at time 0.
    Velocity([f64; 3]),
    /// `anchor + amplitude · sin(2π f t)`.
    Oscillate {
        /// m.
        amplitude: [f64; 3],
        /// Hz.
        frequency: f64,
    },
    /// Held at its anchor until `start`, then moved in a straight line towards `to` at `speed`,
    /// and held there: a picked point dragged to a target (Yamada's user drag).
    Ramp {
        /// Target, m.
        to: [f64; 3],
        /// When the drag starts, s.
        start: f64,
        /// Speed along the line, m/s (> 0).
        speed: f64,
    },
}

/// A pinned node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pin {
    /// Node index.
    pub node: u32,
    /// Position at time 0, m.
    pub anchor: Vector3<f64>,
    /// Prescribed motion.
    pub motion: PinMotion,
}

impl Pin {
    /// Prescribed position at time `t`.
    pub fn position(&self, t: f64) -> Vector3<f64> {
        match self.motion {
            PinMotion::Fixed => self.anchor,
            PinMotion::Velocity(v) => self.anchor + Vector3::from(v) * t,
            PinMotion::Oscillate {
                amplitude,
                frequency,
            } => {
                self.anchor
                    + Vector3::from(amplitude) * (2.0 * std::f64::consts::PI * frequency * t).sin()
            }
            PinMotion::Ramp { to, start, speed } => {
                let d = Vector3::from(to) - self.anchor;
                let l = d.norm();
                if l == 0.0 {
                    return self.anchor;
                }
                let s = (speed * (t - start)).clamp(0.0, l);
                self.anchor + d * (s / l)
            }
        }
    }
}

/// Why a cloth cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum ClothError {
    /// The fabric's characteristics cannot be interpolated to an edge angle.
    #[error("fabric `{fabric}`: {source}")]
    Material {
        /// Fabric name.
        fabric: String,
        /// What failed.
        #[source]
        source: InvalidValue,
    },
    /// A pin names a node that does not exist.
    #[error("pin on node {node}, but the cloth has {nodes} nodes")]
    NoSuchNode {
        /// Requested node.
        node: u32,
        /// Node count.
        nodes: usize,
    },
    /// A pin anchor or motion is not finite.
    #[error("pin on node {node} has a non-finite anchor or motion, or a ramp speed ≤ 0")]
    NotFinite {
        /// Node.
        node: u32,
    },
}

/// Shear angle at which the secant shear stiffness is taken for a fabric without KES shear
/// values, rad (2°, inside KES's 0.5°–5° range for G).
const SECANT_SHEAR_ANGLE: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// One piece of cloth: topology, materials, masses and pins. Immutable during a simulation
/// (pins are set before the first step), except for a pin released with [`Cloth::unpin`].
#[derive(Clone, Debug)]
pub struct Cloth {
    topology: ClothTopology,
    fabric: Fabric,
    form: AnisotropyForm,
    materials: MaterialTable,
    edge_material: Vec<u32>,
    slot_material: Vec<[u32; SLOTS]>,
    /// Axial neighbours of the grid lines that bend ([`Cloth::bending_neighbours`]).
    bend_slots: Vec<[u32; SLOTS]>,
    edge_width: Vec<f64>,
    colours: usize,
    colour_edge: Vec<u32>,
    axial_list: Vec<u32>,
    diagonal_list: Vec<u32>,
    phase_slot: Vec<u32>,
    shear: ShearCurve,
    diagonal_stiffness: Vec<f64>,
    mass: Vec<f64>,
    inv_mass: Vec<f64>,
    pins: Vec<Pin>,
    pin_of: Vec<u32>,
    incidence_offsets: Vec<u32>,
    incidence: Vec<Incidence>,
}

/// One edge as seen from one of its nodes, for gathers without indirection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incidence {
    /// Edge index.
    pub edge: u32,
    /// The edge's other node.
    pub other: u32,
    /// +1 when this node is the edge's first node (the edge direction points away from it).
    pub sign: f64,
    /// This node's share of a correction on the edge, w_i/(w_i + w_other) (0 when pinned).
    pub share: f64,
    /// Whether the edge is axial (4-neighbourhood).
    pub axial: bool,
}

/// How a fabric is turned into a cloth's materials.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClothOptions {
    /// Orthotropic interpolation law. Default `PlateTheory` (the thesis form can invert a
    /// tensile loop at angles between the measured ones; see `docs/fabric.md`).
    pub form: AnisotropyForm,
    /// Linear toe of every tensile loop below this fraction of its maximum force
    /// (`TensileLoop::with_linear_toe`): a finite initial modulus instead of the synthetic
    /// curves' zero one, which otherwise makes the strain targets infinitely sensitive to tiny
    /// forces and the step unstable (measured in `docs/solver.md`). Range [0, 1); default 0.01
    /// (5 gf/cm at the KES Fm).
    pub toe_fraction: f64,
}

impl Default for ClothOptions {
    fn default() -> Self {
        Self {
            form: AnisotropyForm::PlateTheory,
            toe_fraction: 0.01,
        }
    }
}

impl Cloth {
    /// Build a cloth from a topology and a fabric with the default [`ClothOptions`] and the
    /// given anisotropy form.
    pub fn new(
        topology: ClothTopology,
        fabric: &Fabric,
        form: AnisotropyForm,
    ) -> Result<Self, ClothError> {
        Self::with_options(
            topology,
            fabric,
            ClothOptions {
                form,
                ..ClothOptions::default()
            },
        )
    }

    /// Build a cloth, interpolating the fabric to every distinct edge angle once.
    pub fn with_options(
        topology: ClothTopology,
        fabric: &Fabric,
        options: ClothOptions,
    ) -> Result<Self, ClothError> {
        let form = options.form;
        let angles: Vec<f64> = topology.edges().iter().map(|e| e.material_angle).collect();
        let toe = if (0.0..1.0).contains(&options.toe_fraction) {
            options.toe_fraction
        } else {
            0.01
        };
        let (materials, edge_material) = MaterialTable::build(fabric, form, &angles)
            .map(|(t, idx)| {
                (
                    t.map_tensile(|l| l.with_linear_toe(toe * l.max_force())),
                    idx,
                )
            })
            .map_err(|source| ClothError::Material {
                fabric: fabric.name.clone(),
                source,
            })?;
        let slot_material = topology
            .axial_edges()
            .iter()
            .map(|slots| {
                slots.map(|e| {
                    if e == NO_NODE {
                        NO_NODE
                    } else {
                        edge_material[e as usize]
                    }
                })
            })
            .collect();
        let mass: Vec<f64> = topology
            .node_areas()
            .iter()
            .map(|s| s * fabric.mass_per_area)
            .collect();
        let inv_mass = mass.iter().map(|m| 1.0 / m).collect();
        let n = topology.node_count();
        // Width an axial edge carries: half of each cell on either side, area / length.
        let mut edge_width = vec![0.0; topology.edges().len()];
        for (w, (e, cells)) in edge_width
            .iter_mut()
            .zip(topology.edges().iter().zip(topology.edge_cells()))
        {
            let area: f64 = cells
                .iter()
                .filter(|&&c| c != NO_NODE)
                .map(|&c| topology.cells()[c as usize].area)
                .sum();
            *w = if area > 0.0 {
                0.5 * area / e.rest_length
            } else {
                // An edge no cell touches (a bridge the gridding left between two dart apexes):
                // it carries the mean of its nodes' areas across its length, which equals the
                // cell-based width on a regular grid.
                0.5 * (topology.node_areas()[e.a as usize] + topology.node_areas()[e.b as usize])
                    / e.rest_length
            };
        }
        let colouring = topology.edge_colours();
        let colours = colouring.len();
        let mut colour_edge = vec![NO_NODE; n * colours];
        for (c, list) in colouring.iter().enumerate() {
            for &e in list {
                let edge = topology.edges()[e as usize];
                colour_edge[edge.a as usize * colours + c] = e;
                colour_edge[edge.b as usize * colours + c] = e;
            }
        }
        let (axial_list, diagonal_list): (Vec<u32>, Vec<u32>) = (0..topology.edges().len() as u32)
            .partition(|&e| topology.edges()[e as usize].kind != EdgeKind::Diagonal);
        let mut phase_slot = vec![0u32; topology.edges().len()];
        for list in [&axial_list, &diagonal_list] {
            for (k, &e) in list.iter().enumerate() {
                phase_slot[e as usize] = k as u32;
            }
        }
        let shear = ShearCurve::from_fabric(fabric);
        // A compliant diagonal's spring constant: with the fabric's shear stiffness G a cell of
        // rest area S sheared by γ stores ½ G γ² S; its two diagonals of rest length d change by
        // ∓ S γ / d each, so k = G d² / (2 S) per diagonal (k = G for a square cell).
        let g = fabric.shear.as_ref().map_or_else(
            || shear.secant_stiffness(SECANT_SHEAR_ANGLE),
            |s| s.stiffness,
        );
        let mut diagonal_stiffness = vec![0.0; topology.edges().len()];
        for cell in topology.cells() {
            for d in cell.diagonals {
                let l = topology.edges()[d as usize].rest_length;
                diagonal_stiffness[d as usize] = g * l * l / (2.0 * cell.area);
            }
        }
        let bend_slots = bending_lines(&topology);
        Ok(Self {
            bend_slots,
            shear,
            diagonal_stiffness,
            topology,
            fabric: fabric.clone(),
            form,
            materials,
            edge_material,
            slot_material,
            edge_width,
            colours,
            colour_edge,
            phase_slot,
            axial_list,
            diagonal_list,
            mass,
            inv_mass,
            pins: Vec::new(),
            pin_of: vec![NO_NODE; n],
            incidence_offsets: Vec::new(),
            incidence: Vec::new(),
        }
        .with_incidence())
    }

    /// Each node's axial neighbours (+u, −u, +v, −v) on the grid lines that carry bending:
    /// [`ClothTopology::axial_neighbours`] without the directions whose two neighbours turn by
    /// more than [`BEND_LINE_MAX_TURN`] in the pattern ([`NO_NODE`] in both slots). Where the
    /// gridder fans cells around a dart's apex, a node's "u" neighbours can sit at 100–125° to
    /// each other; the turn of such a stencil about t̄ × n reads ±π on the flat panel (the
    /// dress's bust-dart apexes: 4–5 rad at the placement), so it is no grid line and bends
    /// nothing — its neighbours' lines carry the bending there.
    pub fn bending_neighbours(&self) -> &[[u32; SLOTS]] {
        &self.bend_slots
    }

    /// Pin `node` at `anchor` with `motion` (re-pinning a node replaces its pin).
    pub fn pin(
        &mut self,
        node: u32,
        anchor: Vector3<f64>,
        motion: PinMotion,
    ) -> Result<(), ClothError> {
        let n = self.topology.node_count();
        if node as usize >= n {
            return Err(ClothError::NoSuchNode { node, nodes: n });
        }
        let finite = match motion {
            PinMotion::Fixed => true,
            PinMotion::Velocity(v) => v.iter().all(|x| x.is_finite()),
            PinMotion::Oscillate {
                amplitude,
                frequency,
            } => amplitude.iter().all(|x| x.is_finite()) && frequency.is_finite(),
            PinMotion::Ramp { to, start, speed } => {
                to.iter().all(|x| x.is_finite())
                    && start.is_finite()
                    && speed > 0.0
                    && speed.is_finite()
            }
        };
        if !(finite && anchor.iter().all(|x| x.is_finite())) {
            return Err(ClothError::NotFinite { node });
        }
        let pin = Pin {
            node,
            anchor,
            motion,
        };
        match self.pin_of[node as usize] {
            NO_NODE => {
                self.pin_of[node as usize] = self.pins.len() as u32;
                self.pins.push(pin);
            }
            k => self.pins[k as usize] = pin,
        }
        self.inv_mass[node as usize] = 0.0;
        self.update_shares(node as usize);
        Ok(())
    }

    /// Release `node`'s pin (nothing when it has none): it moves freely again with its mass.
    /// Call [`crate::Solver::reset`] afterwards (the solver's cached estimates depend on pins).
    pub fn unpin(&mut self, node: u32) -> Result<(), ClothError> {
        let n = self.topology.node_count();
        if node as usize >= n {
            return Err(ClothError::NoSuchNode { node, nodes: n });
        }
        let k = self.pin_of[node as usize];
        if k == NO_NODE {
            return Ok(());
        }
        self.pins.swap_remove(k as usize);
        if let Some(moved) = self.pins.get(k as usize) {
            self.pin_of[moved.node as usize] = k;
        }
        self.pin_of[node as usize] = NO_NODE;
        self.inv_mass[node as usize] = 1.0 / self.mass[node as usize];
        self.update_shares(node as usize);
        Ok(())
    }

    fn with_incidence(mut self) -> Self {
        let topo = &self.topology;
        let n = topo.node_count();
        let mut offsets = Vec::with_capacity(n + 1);
        let mut list = Vec::with_capacity(2 * topo.edges().len());
        offsets.push(0);
        for i in 0..n {
            for &e in topo.incident_edges(i) {
                let edge = topo.edges()[e as usize];
                let (other, sign) = if edge.a as usize == i {
                    (edge.b, 1.0)
                } else {
                    (edge.a, -1.0)
                };
                list.push(Incidence {
                    edge: e,
                    other,
                    sign,
                    share: 0.0,
                    axial: edge.kind.is_axial(),
                });
            }
            offsets.push(list.len() as u32);
        }
        self.incidence_offsets = offsets;
        self.incidence = list;
        for i in 0..n {
            self.update_shares(i);
        }
        self
    }

    /// Recompute the correction shares around `node` after its inverse mass changed.
    fn update_shares(&mut self, node: usize) {
        let (a, b) = (
            self.incidence_offsets[node] as usize,
            self.incidence_offsets[node + 1] as usize,
        );
        for k in a..b {
            let other = self.incidence[k].other as usize;
            let (wi, wo) = (self.inv_mass[node], self.inv_mass[other]);
            self.incidence[k].share = if wi + wo > 0.0 { wi / (wi + wo) } else { 0.0 };
            // The other node's view of the same edge.
            let (oa, ob) = (
                self.incidence_offsets[other] as usize,
                self.incidence_offsets[other + 1] as usize,
            );
            for m in oa..ob {
                if self.incidence[m].other as usize == node {
                    self.incidence[m].share = if wi + wo > 0.0 { wo / (wi + wo) } else { 0.0 };
                }
            }
        }
    }

    /// The edges around `node`, with their other node, sign and correction share.
    #[inline]
    pub fn incidence(&self, node: usize) -> &[Incidence] {
        &self.incidence
            [self.incidence_offsets[node] as usize..self.incidence_offsets[node + 1] as usize]
    }

    /// The topology.
    pub fn topology(&self) -> &ClothTopology {
        &self.topology
    }

    /// The fabric.
    pub fn fabric(&self) -> &Fabric {
        &self.fabric
    }

    /// The anisotropy form the materials were interpolated with.
    pub fn anisotropy_form(&self) -> AnisotropyForm {
        self.form
    }

    /// The per-angle material table.
    pub fn materials(&self) -> &MaterialTable {
        &self.materials
    }

    /// Material entry of each edge.
    pub fn edge_materials(&self) -> &[u32] {
        &self.edge_material
    }

    /// Material entry of each node's axial slots (the bending characteristic at that edge's
    /// angle); [`NO_NODE`] where the slot is empty.
    pub fn slot_materials(&self) -> &[[u32; SLOTS]] {
        &self.slot_material
    }

    /// Width each axial edge carries (half the cells beside it, area over length), m; the
    /// force per width of an edge is p/W.
    pub fn edge_widths(&self) -> &[f64] {
        &self.edge_width
    }

    /// Number of edge colours (groups of edges sharing no node).
    pub fn colour_count(&self) -> usize {
        self.colours
    }

    /// The edge of colour `colour` at `node`, if any ([`NO_NODE`] otherwise).
    pub fn colour_edge(&self, node: usize, colour: usize) -> u32 {
        self.colour_edge[node * self.colours + colour]
    }

    /// Indices of the axial edges.
    pub fn axial_edge_list(&self) -> &[u32] {
        &self.axial_list
    }

    /// Position of each edge in its class's list ([`Self::axial_edge_list`] or
    /// [`Self::diagonal_edge_list`]).
    pub fn phase_slots(&self) -> &[u32] {
        &self.phase_slot
    }

    /// Indices of the diagonal edges.
    pub fn diagonal_edge_list(&self) -> &[u32] {
        &self.diagonal_list
    }

    /// The in-plane shear characteristic of the cells.
    pub fn shear_curve(&self) -> &ShearCurve {
        &self.shear
    }

    /// Spring constant of each diagonal when diagonals are compliant
    /// (`ConstraintKind::Compliant`), N/m; 0 for axial edges. From the fabric's KES shear
    /// stiffness G, or when the fabric has none the secant of its shear curve at 2°.
    pub fn diagonal_stiffness(&self) -> &[f64] {
        &self.diagonal_stiffness
    }

    /// Node masses μ = m_A·S, kg.
    pub fn masses(&self) -> &[f64] {
        &self.mass
    }

    /// Inverse masses; 0 for pinned nodes.
    pub fn inverse_masses(&self) -> &[f64] {
        &self.inv_mass
    }

    /// Pins.
    pub fn pins(&self) -> &[Pin] {
        &self.pins
    }

    /// Whether `node` is pinned.
    pub fn is_pinned(&self, node: usize) -> bool {
        self.pin_of[node] != NO_NODE
    }

    /// Whether any edge's tensile loop has hysteresis.
    pub fn tensile_hysteretic(&self) -> bool {
        (0..self.materials.len() as u32).any(|i| self.materials.tensile(i).is_hysteretic())
    }

    /// Whether any bending characteristic has hysteresis.
    pub fn bending_hysteretic(&self) -> bool {
        (0..self.materials.len() as u32).any(|i| self.materials.bending(i).is_hysteretic())
    }
}

/// The largest turn, in the pattern plane, of a grid line through a node that still carries
/// bending (45°: the line's turn then reads within a factor √2 of the fold about t̄ × n). At 60°
/// the dress's two stencils at 57° (nodes 206 and 226, beside the bust-dart apexes) stalled the
/// converged (Newton) step of branch `lead` at 0.12–0.15 rad while the darts were sewn.
pub const BEND_LINE_MAX_TURN: f64 = std::f64::consts::FRAC_PI_4;

/// [`Cloth::bending_neighbours`] of `topology`.
fn bending_lines(topology: &ClothTopology) -> Vec<[u32; SLOTS]> {
    let rest = topology.rest_positions();
    let min_cos = BEND_LINE_MAX_TURN.cos();
    topology
        .axial_neighbours()
        .iter()
        .enumerate()
        .map(|(i, slots)| {
            let mut out = *slots;
            for dir in 0..2 {
                let (after, before) = (slots[2 * dir], slots[2 * dir + 1]);
                if after == NO_NODE || before == NO_NODE {
                    continue;
                }
                let at = |k: u32| rest[k as usize];
                let (b, p, a) = (at(before), rest[i], at(after));
                let (e1, e2) = ([p[0] - b[0], p[1] - b[1]], [a[0] - p[0], a[1] - p[1]]);
                let (l1, l2) = (e1[0].hypot(e1[1]), e2[0].hypot(e2[1]));
                let cos = (e1[0] * e2[0] + e1[1] * e2[1]) / (l1 * l2);
                if !(cos >= min_cos) {
                    out[2 * dir] = NO_NODE;
                    out[2 * dir + 1] = NO_NODE;
                }
            }
            out
        })
        .collect()
}
