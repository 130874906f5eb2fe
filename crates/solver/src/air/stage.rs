//! The pressure force as a stage of a solver: a [`PressureModel`] with the cloth geometry it
//! needs (oriented triangles, the area each node stands for, the cloth's edge), and the
//! report of its last evaluation.

use atelier_grid::{ClothTopology, NO_NODE};
use nalgebra::Vector3;

use super::pressure::{PressureModel, PressureReport};

type V3 = Vector3<f64>;

/// The area S a node stands for in (Y3.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum NodeArea {
    /// Yamada's: the cloth's rest area over the number of nodes, the same for every node.
    Uniform,
    /// A quarter of each incident cell ([`ClothTopology::node_areas`]): a node on the edge
    /// stands for half, a corner for a quarter of an inner node's area.
    Lumped,
}

/// The pressure force on one cloth, ready to be evaluated every step.
pub struct PressureStage {
    model: PressureModel,
    triangles: Vec<[u32; 3]>,
    node_area: Vec<f64>,
    boundary: Vec<bool>,
}

impl PressureStage {
    /// The stage on a cloth of topology `topology`: its triangles (counter-clockwise in the
    /// pattern plane, so the cloth must lie with its pattern's front — the side its normals
    /// point to — away from the surface), its node areas after `area`, and its edge nodes (a
    /// node missing an axial neighbour).
    pub fn for_cloth(model: PressureModel, topology: &ClothTopology, area: NodeArea) -> Self {
        let n = topology.node_count();
        let node_area = match area {
            NodeArea::Uniform => vec![topology.area() / n as f64; n],
            NodeArea::Lumped => topology.node_areas().to_vec(),
        };
        let boundary = topology
            .axial_neighbours()
            .iter()
            .map(|s| s.contains(&NO_NODE))
            .collect();
        Self::new(model, topology.triangles().to_vec(), node_area, boundary)
    }

    /// The stage on any triangle mesh: `triangles` oriented with their normals away from the
    /// surface, `node_area[i]` the area node i stands for, `boundary[i]` whether node i lies on
    /// the cloth's edge (only the pocket model looks at it).
    pub fn new(
        model: PressureModel,
        triangles: Vec<[u32; 3]>,
        node_area: Vec<f64>,
        boundary: Vec<bool>,
    ) -> Self {
        Self {
            model,
            triangles,
            node_area,
            boundary,
        }
    }

    /// Evaluate the bubbles at `positions` and add the pressure forces to `forces` (`dt`
    /// advances the leak).
    pub fn add_forces(&mut self, positions: &[V3], dt: f64, forces: &mut [V3]) {
        self.model.add_forces(
            positions,
            &self.triangles,
            &self.node_area,
            &self.boundary,
            dt,
            forces,
        );
    }

    /// The force in three parts, for a large-step solver: evaluate the bubbles at `positions`
    /// ([`PressureModel::evaluate`]), predict their pressures at the end of the step from the
    /// velocities the step would end with without them ([`PressureModel::predict`]), and add
    /// the forces ([`PressureModel::apply`]).
    pub fn add_forces_predicted(
        &mut self,
        positions: &[V3],
        predicted: &[V3],
        inverse_masses: &[f64],
        dt: f64,
        forces: &mut [V3],
    ) {
        self.model.evaluate(
            positions,
            &self.triangles,
            &self.node_area,
            &self.boundary,
            dt,
        );
        self.model
            .predict(predicted, &self.node_area, inverse_masses, dt);
        self.model.apply(&self.node_area, forces);
    }

    /// The surface's reaction on the nodes resting on it this step
    /// ([`PressureModel::support`]).
    pub fn support(
        &self,
        velocities: &[V3],
        inverse_masses: &[f64],
        dt: f64,
        forces: &mut [V3],
        reaction: &mut Vec<V3>,
    ) {
        self.model
            .support(velocities, inverse_masses, dt, forces, reaction);
    }

    /// The backward-Euler pressure as a constraint on `velocities` ([`PressureModel::project`]);
    /// returns the largest pressure change, Pa.
    pub fn project(
        &mut self,
        positions: &[V3],
        inverse_masses: &[f64],
        dt: f64,
        velocities: &mut [V3],
    ) -> f64 {
        self.model.project(
            positions,
            &self.triangles,
            &self.node_area,
            inverse_masses,
            dt,
            velocities,
        )
    }

    /// What the last evaluation measured.
    pub fn report(&self) -> &PressureReport {
        self.model.report()
    }

    /// The model.
    pub fn model(&self) -> &PressureModel {
        &self.model
    }

    /// The model, to change its surface (a moving body).
    pub fn model_mut(&mut self) -> &mut PressureModel {
        &mut self.model
    }

    /// The oriented triangles.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The area each node stands for, m².
    pub fn node_area(&self) -> &[f64] {
        &self.node_area
    }
}
