//! One interface for the cloth integrators: the PARTY step ([`Solver`]) and the two baselines
//! ([`Xpbd`], [`MassSpring`]) behind the [`Integrator`] trait, so that a scene drives whichever
//! it was given through `Box<dyn Integrator>` without matching on the kind.
//!
//! What changes from step to step — the time step and gravity (a garment is sewn without it and
//! settles with it; a step that misses its tolerance is taken again in halves) — is given with
//! every step as a [`StepInput`]; the rest of each integrator's parameters is fixed when it is
//! built. A baseline's diagnostics come back as a [`StepReport`] (its sweeps as shape
//! iterations, its largest strain as the strain error), so callers read one report.

use crate::baselines::{BaselineReport, MassSpring, MassSpringParams, Xpbd, XpbdParams};
use crate::cloth::Cloth;
pub use crate::params::StepInput;
use crate::params::StepParams;
use crate::state::ClothState;
use crate::step::{CollisionHook, Solver, StepError, StepReport};
use nalgebra::Vector3;

/// A cloth integrator: one step of the cloth with a collision hook.
pub trait Integrator: Send {
    /// Its name in reports (`party`, `xpbd`, `mass_spring`).
    fn name(&self) -> &'static str;

    /// Advance `state` by `input.dt` under `input.gravity`; `hook` transfers the body's motion,
    /// ties seams and resolves collisions. On error the state is the last good one.
    fn advance(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        input: StepInput,
        hook: &mut dyn CollisionHook,
    ) -> Result<StepReport, StepError>;

    /// Whether its steps have a tolerance, so that a step's report says whether it met it (a
    /// caller may then take a step that missed it again in shorter steps). Default: no (the
    /// baselines).
    fn has_tolerance(&self) -> bool {
        false
    }

    /// Set the shape stage's tolerance (the largest relative strain error a step must meet)
    /// for the steps from now on. Returns whether the integrator has one; the default (the
    /// baselines, which have none) ignores it and returns false. The caller checks the value.
    fn set_shape_tolerance(&mut self, tolerance: f64) -> bool {
        let _ = tolerance;
        false
    }

    /// Per-node external forces (N, one per node; empty: none) added to every step from now on.
    /// Returns whether the integrator applies them; the default ignores them and returns false
    /// (the baselines).
    fn set_external_forces(&mut self, forces: Vec<Vector3<f64>>) -> bool {
        let _ = forces;
        false
    }

    /// Per node, the largest strain error of its axial edges in `state` (what a viewer colours
    /// the cloth by). Default (the baselines, which have no target length): the strain from the
    /// rest length, |ℓ/ℓ₀ − 1|.
    fn node_strain_errors(&self, cloth: &Cloth, state: &ClothState) -> Vec<f32> {
        let edges = cloth.topology().edges();
        let pos = &state.positions;
        let mut out = vec![0.0_f32; pos.len()];
        for &e in cloth.axial_edge_list() {
            let edge = &edges[e as usize];
            let l = (pos[edge.b as usize] - pos[edge.a as usize]).norm();
            let err = ((l - edge.rest_length) / edge.rest_length).abs() as f32;
            for n in [edge.a, edge.b] {
                out[n as usize] = out[n as usize].max(err);
            }
        }
        out
    }
}

/// The PARTY step with its parameters.
pub struct Party {
    /// The step's buffers and state.
    pub solver: Solver,
    /// Its parameters.
    pub params: StepParams,
}

impl Integrator for Party {
    fn name(&self) -> &'static str {
        "party"
    }

    fn advance(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        input: StepInput,
        hook: &mut dyn CollisionHook,
    ) -> Result<StepReport, StepError> {
        self.solver
            .step_with(cloth, state, &self.params, input, hook)
    }

    fn has_tolerance(&self) -> bool {
        true
    }

    fn set_shape_tolerance(&mut self, tolerance: f64) -> bool {
        self.params.shape.tolerance = tolerance;
        true
    }

    fn set_external_forces(&mut self, forces: Vec<Vector3<f64>>) -> bool {
        self.solver.external_forces = forces;
        true
    }

    fn node_strain_errors(&self, cloth: &Cloth, state: &ClothState) -> Vec<f32> {
        self.solver.node_strain_errors(cloth, state, &self.params)
    }
}

/// A baseline integrator with its parameters behind [`Integrator`], its report converted
/// (both baselines step alike).
macro_rules! baseline_integrator {
    ($(#[$doc:meta])* $name:ident, $solver:ty, $params:ty, $label:literal) => {
        $(#[$doc])*
        pub struct $name {
            /// The integrator.
            pub solver: $solver,
            /// Its parameters.
            pub params: $params,
        }

        impl Integrator for $name {
            fn name(&self) -> &'static str {
                $label
            }

            fn advance(
                &mut self,
                cloth: &Cloth,
                state: &mut ClothState,
                input: StepInput,
                hook: &mut dyn CollisionHook,
            ) -> Result<StepReport, StepError> {
                self.solver
                    .step_with(cloth, state, &self.params, input, hook)
                    .map(StepReport::from)
            }
        }
    };
}

baseline_integrator!(
    /// The XPBD baseline with its parameters.
    XpbdIntegrator,
    Xpbd,
    XpbdParams,
    "xpbd"
);
baseline_integrator!(
    /// The mass-spring baseline with its parameters.
    MassSpringIntegrator,
    MassSpring,
    MassSpringParams,
    "mass_spring"
);

impl From<BaselineReport> for StepReport {
    /// A baseline's diagnostics in the PARTY step's report: its sweeps as shape iterations, its
    /// largest strain |l/l⁰ − 1| as the strain error (a baseline's springs rest at l⁰), its
    /// timings; it has no tolerance, so its tolerance factor is 1.
    fn from(r: BaselineReport) -> Self {
        StepReport {
            shape_iterations: r.iterations,
            max_strain_error: r.max_strain,
            kinetic_energy: r.kinetic_energy,
            max_speed: r.max_speed,
            tolerance_factor: 1.0,
            timings: r.timings,
            ..StepReport::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloth::PinMotion;
    use crate::step::NoCollision;
    use atelier_fabric::{AnisotropyForm, Fabric};
    use atelier_grid::{ClothTopology, StructuredGrid};
    use nalgebra::Vector3;

    /// A 9 × 9 cotton sheet held at two corners of one edge, lying flat.
    fn sheet() -> (Cloth, ClothState) {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/fabrics/cotton_broad.ron"
        );
        let fabric = Fabric::load(std::path::Path::new(path)).expect("fixture fabric");
        let grid = StructuredGrid::sheet(9, 9, 0.2, 0.2);
        let topology = ClothTopology::from_structured(&grid).expect("sheet");
        let mut cloth = Cloth::new(topology, &fabric, AnisotropyForm::Thesis).expect("cloth");
        for node in [72u32, 80] {
            let [x, y] = cloth.topology().rest_positions()[node as usize];
            cloth
                .pin(node, Vector3::new(x, y, 0.0), PinMotion::Fixed)
                .expect("pin");
        }
        let state = ClothState::flat(&cloth, 0.0);
        (cloth, state)
    }

    /// The per-node strain errors the viewer colours by, against known answers: the flat
    /// sheet has none; one corner node moved outward along the warp stretches the one axial
    /// edge along it by a known strain (its node and its neighbour show it; the node's other
    /// edge, across the warp, is stretched by the second order only); after a PARTY step the
    /// nodes' largest value is the step's `max_strain_error`.
    #[test]
    fn node_strain_errors_are_the_edges_strains_and_match_the_step_report() {
        let (cloth, mut state) = sheet();
        let party = Party {
            solver: Solver::new(),
            params: StepParams::default(),
        };
        let xpbd = XpbdIntegrator {
            solver: Xpbd::new(),
            params: XpbdParams::default(),
        };
        let flat = party.node_strain_errors(&cloth, &state);
        assert!(flat.iter().all(|&e| e == 0.0), "flat sheet");
        // Node 0 is a corner: its edges go to node 1 (along u) and node 9 (along v), 2.5 cm.
        let rest = cloth.topology().rest_positions();
        let h = rest[1][0] - rest[0][0];
        assert!((h - 0.025).abs() < 1e-12, "{h}");
        let stretch = 0.04;
        state.positions[0].x -= stretch * h;
        for integrator in [&party as &dyn Integrator, &xpbd] {
            let e = integrator.node_strain_errors(&cloth, &state);
            assert!((f64::from(e[0]) - stretch).abs() < 1e-6, "{}", e[0]);
            assert!((f64::from(e[1]) - stretch).abs() < 1e-6, "{}", e[1]);
            // The edge to node 9 turns but hardly lengthens: √(1 + 0.04²) − 1 = 8.0e-4.
            assert!((f64::from(e[9]) - (1.0 + stretch * stretch).sqrt() + 1.0).abs() < 1e-6);
            assert_eq!(e[40], 0.0, "an untouched node");
        }
        let mut party = party;
        state.positions[0].x += stretch * h;
        let report = party
            .advance(&cloth, &mut state, StepInput::new(1e-3), &mut NoCollision)
            .expect("step");
        let e = party.node_strain_errors(&cloth, &state);
        let largest = e.iter().copied().fold(0.0_f32, f32::max);
        assert!(
            (f64::from(largest) - report.max_strain_error).abs()
                <= 1e-6 * report.max_strain_error.max(1e-9),
            "{largest} vs {}",
            report.max_strain_error
        );
    }

    /// Stepping through the trait is stepping the integrator itself, Δt and gravity given per
    /// step: the same positions, bit for bit, for each of the three.
    #[test]
    fn the_trait_steps_each_integrator_as_it_steps_itself() {
        let (cloth, start) = sheet();
        let mut integrators: Vec<Box<dyn Integrator>> = vec![
            Box::new(Party {
                solver: Solver::new(),
                params: StepParams::default(),
            }),
            Box::new(XpbdIntegrator {
                solver: Xpbd::new(),
                params: XpbdParams::default(),
            }),
            Box::new(MassSpringIntegrator {
                solver: MassSpring::new(),
                params: MassSpringParams::default(),
            }),
        ];
        for integrator in &mut integrators {
            // The mass-spring model is explicit: its own default Δt (the others take 5 ms).
            let dt = match integrator.name() {
                "mass_spring" => 1.0 / 12000.0,
                _ => 0.005,
            };
            let input = StepInput {
                dt,
                gravity: [0.0, 0.0, -9.80665],
            };
            let mut through_trait = start.clone();
            let mut direct = start.clone();
            let (mut party, mut xpbd, mut spring) = (Solver::new(), Xpbd::new(), MassSpring::new());
            for _ in 0..20 {
                integrator
                    .advance(&cloth, &mut through_trait, input, &mut NoCollision)
                    .expect("step through the trait");
                match integrator.name() {
                    "party" => party
                        .step(&cloth, &mut direct, &StepParams::default(), input)
                        .map(|_| ()),
                    "xpbd" => xpbd
                        .step(&cloth, &mut direct, &XpbdParams::default(), input)
                        .map(|_| ()),
                    _ => spring
                        .step(&cloth, &mut direct, &MassSpringParams::default(), input)
                        .map(|_| ()),
                }
                .expect("direct step");
            }
            assert_eq!(
                through_trait.positions,
                direct.positions,
                "{}",
                integrator.name()
            );
            // The sheet fell: the test compares moving states, not two copies of the start.
            let fallen = through_trait
                .positions
                .iter()
                .map(|p| -p.z)
                .fold(0.0, f64::max);
            assert!(fallen > 0.0, "{}: fell {fallen} m", integrator.name());
        }
    }
}
