//! The simulation state of one cloth: everything that evolves and would be saved to resume a run
//! (positions, velocities, the warm-start axial forces, the hysteresis states). Reusable scratch
//! lives in [`crate::Solver`], not here.

use atelier_fabric::{BendingState, ShearState, TensileState};
use atelier_grid::SLOTS;
use nalgebra::Vector3;

use crate::cloth::Cloth;

/// Per-node and per-edge state, arrays per field.
#[derive(Clone, Debug, PartialEq)]
pub struct ClothState {
    /// Simulated time, s.
    pub time: f64,
    /// Node positions, m.
    pub positions: Vec<Vector3<f64>>,
    /// Node velocities, m/s.
    pub velocities: Vec<Vector3<f64>>,
    /// Axial force p of each edge from the last step (warm start), N.
    pub axial_force: Vec<f64>,
    /// Tensile hysteresis state of each edge.
    pub tensile: Vec<TensileState>,
    /// Bending hysteresis state of each node's axial slots.
    pub bending: Vec<[BendingState; SLOTS]>,
    /// Shear angle of each cell at the end of the last step (rad), for reports.
    pub shear_angle: Vec<f64>,
    /// Shear hysteresis state of each cell.
    pub shear: Vec<ShearState>,
}

impl ClothState {
    /// The cloth at rest, each pattern point `(x, y)` placed at `place([x, y])`; pinned nodes are
    /// put at their pin's position at time 0.
    pub fn placed(cloth: &Cloth, place: impl Fn([f64; 2]) -> Vector3<f64>) -> Self {
        let topo = cloth.topology();
        let mut positions: Vec<Vector3<f64>> =
            topo.rest_positions().iter().map(|&p| place(p)).collect();
        for pin in cloth.pins() {
            positions[pin.node as usize] = pin.position(0.0);
        }
        let n = positions.len();
        let e = topo.edges().len();
        Self {
            time: 0.0,
            positions,
            velocities: vec![Vector3::zeros(); n],
            axial_force: vec![0.0; e],
            tensile: vec![TensileState::VIRGIN; e],
            bending: vec![[BendingState::VIRGIN; SLOTS]; n],
            shear_angle: vec![0.0; topo.cells().len()],
            shear: vec![ShearState::VIRGIN; topo.cells().len()],
        }
    }

    /// The cloth flat in the horizontal plane z = `height`, pattern x → world x, y → world y.
    pub fn flat(cloth: &Cloth, height: f64) -> Self {
        Self::placed(cloth, |[x, y]| Vector3::new(x, y, height))
    }

    /// Kinetic energy ½ Σ μ|ṙ|², J (pinned nodes included with their own mass).
    pub fn kinetic_energy(&self, cloth: &Cloth) -> f64 {
        self.velocities
            .iter()
            .zip(cloth.masses())
            .map(|(v, m)| 0.5 * m * v.norm_squared())
            .sum()
    }

    /// The strain `(l − l⁰)/l⁰` of every edge now.
    pub fn strains(&self, cloth: &Cloth) -> Vec<f64> {
        cloth
            .topology()
            .edges()
            .iter()
            .map(|e| {
                (self.positions[e.b as usize] - self.positions[e.a as usize]).norm() / e.rest_length
                    - 1.0
            })
            .collect()
    }
}
