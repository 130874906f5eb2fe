//! The garment pipeline run to its end (thesis §5.5–5.6): a scene loaded from its spec, the
//! [`Simulation`] stepped through its schedule — dressing, settling, the motion — with frames
//! recorded at the spec's interval and the measurements a report needs. A step that fails ends
//! the run with the failure recorded and every frame up to the last good state kept.

use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::convergence::{Convergence, Tally, solvers};
use crate::scene::{ClothSolver, GarmentSpec, Scene, SceneError};
use crate::simulation::{Phase, Simulation, StepOutcome, Timings};

/// What the steps of a garment run measured so far, step by step: what `report.json`'s garment
/// metrics and convergence read. [`run_scene`] keeps one; so does a caller stepping a
/// [`Simulation`] itself (the Python bindings), so both count alike.
#[derive(Clone, Debug)]
pub struct StepStats {
    /// `None` for PARTY (whose steps report convergence), else the baseline's name.
    pub baseline: Option<&'static str>,
    /// The shape tolerance of the steps.
    pub tolerance: f64,
    /// The convergence of PARTY's steps.
    pub tally: Tally,
    /// Steps taken.
    pub steps: usize,
    /// Largest strain error any step left, and the last step's.
    pub max_strain_error: (f64, f64),
    /// Kinetic energy after the last step, J.
    pub kinetic_energy: f64,
    /// Largest kinetic energy over the motion phase, J.
    pub max_motion_energy: f64,
    /// Deepest any node went inside the body, m (the push not counted).
    pub max_penetration: f64,
    /// Steps after which some node was inside the body (the push not counted).
    pub steps_with_penetration: usize,
    /// Nodes inside the body after the last step.
    pub inside: usize,
}

impl StepStats {
    /// Nothing counted yet, for the scene's solver.
    pub fn new(scene: &Scene) -> Self {
        Self {
            baseline: match &scene.settings.solver {
                ClothSolver::Party => None,
                ClothSolver::Xpbd(_) => Some(solvers::XPBD),
                ClothSolver::MassSpring(_) => Some(solvers::MASS_SPRING),
            },
            tolerance: scene.settings.step.shape.tolerance,
            tally: Tally::default(),
            steps: 0,
            max_strain_error: (0.0, 0.0),
            kinetic_energy: 0.0,
            max_motion_energy: 0.0,
            max_penetration: 0.0,
            steps_with_penetration: 0,
            inside: 0,
        }
    }

    /// Count one step that started at `start_time`.
    pub fn add(&mut self, outcome: &StepOutcome, start_time: f64) {
        self.steps += 1;
        let r = &outcome.report;
        if self.baseline.is_none() {
            self.tally.add(r, start_time, Some(outcome.phase));
        }
        self.max_strain_error.0 = self.max_strain_error.0.max(r.max_strain_error);
        self.max_strain_error.1 = r.max_strain_error;
        self.kinetic_energy = r.kinetic_energy;
        if outcome.phase == Phase::Motion {
            self.max_motion_energy = self.max_motion_energy.max(r.kinetic_energy);
        }
        self.inside = outcome.inside;
        if outcome.phase != Phase::Pushing {
            self.max_penetration = self.max_penetration.max(outcome.depth);
            self.steps_with_penetration += usize::from(outcome.inside > 0);
        }
    }

    /// Whether the steps converged (a baseline: not reported).
    pub fn convergence(&self) -> Convergence {
        match self.baseline {
            None => self.tally.convergence(self.tolerance),
            Some(name) => Convergence::not_reported(name, self.steps),
        }
    }
}

/// One recorded instant.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// Simulated time, s.
    pub time: f64,
    /// Phase.
    pub phase: Phase,
    /// Cloth node positions, m.
    pub cloth: Vec<[f64; 3]>,
    /// Body vertex positions, m.
    pub body: Vec<[f64; 3]>,
    /// Each cloth node's largest axial strain error (`Simulation::node_strain_errors`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub strain_error: Vec<f32>,
}

/// What a garment run produced.
#[derive(Clone, Debug)]
pub struct GarmentRun {
    /// Cloth triangles (node indices).
    pub cloth_triangles: Vec<[u32; 3]>,
    /// Body triangles (vertex indices).
    pub body_triangles: Vec<[u32; 3]>,
    /// Recorded frames (the first is the placed garment, the last the final or last good state).
    pub frames: Vec<Frame>,
    /// Pairs sewn at the end, and pairs to sew.
    pub pairs: (usize, usize),
    /// Simulated time at which every pair was sewn, s.
    pub sewn_at: Option<f64>,
    /// Steps taken.
    pub steps: usize,
    /// Wall time of the steps, s.
    pub wall_seconds: f64,
    /// Time per stage summed over the steps.
    pub timings: Timings,
    /// Deepest any node went inside the body over the run, m (checked after every step; the
    /// steps of a one-sided push, which goes through the body by design, are not counted).
    pub max_penetration: f64,
    /// Steps after which some node was inside the body (the push not counted).
    pub steps_with_penetration: usize,
    /// Nodes inside the body after the last step, pushed or not (a push that did not get the
    /// garment through leaves them there, and the run ends with it).
    pub inside_at_end: usize,
    /// Largest strain error any step left, and the last step's.
    pub max_strain_error: (f64, f64),
    /// Kinetic energy at the end, J.
    pub kinetic_energy: f64,
    /// Largest kinetic energy over the motion phase, J (0 without one).
    pub max_motion_energy: f64,
    /// Whether the steps converged (PARTY; the baselines do not report it).
    pub convergence: Convergence,
    /// The failure that ended the run early, if any.
    pub failure: Option<String>,
    /// Things the user should know.
    pub warnings: Vec<String>,
    /// The garment's panel names and the panel of each cloth node.
    pub panels: (Vec<String>, Vec<u16>),
}

impl GarmentRun {
    /// A run before its first step: the meshes, the frames so far and the pairs, nothing
    /// measured yet.
    fn started(
        cloth_triangles: Vec<[u32; 3]>,
        body_triangles: Vec<[u32; 3]>,
        frames: Vec<Frame>,
        pairs: (usize, usize),
    ) -> Self {
        Self {
            cloth_triangles,
            body_triangles,
            frames,
            pairs,
            sewn_at: None,
            steps: 0,
            wall_seconds: 0.0,
            timings: Timings::default(),
            max_penetration: 0.0,
            steps_with_penetration: 0,
            inside_at_end: 0,
            max_strain_error: (0.0, 0.0),
            kinetic_energy: 0.0,
            max_motion_energy: 0.0,
            convergence: Convergence::not_reported(solvers::PARTY, 0),
            failure: None,
            warnings: Vec::new(),
            panels: (Vec::new(), Vec::new()),
        }
    }

    /// Root-mean-square speed of the cloth's nodes between the last two recorded frames, m/s:
    /// whether the garment has come to rest. `None` with fewer than two frames or without
    /// cloth.
    pub fn final_rms_speed(&self) -> Option<f64> {
        let [.., before, last] = self.frames.as_slice() else {
            return None;
        };
        let dt = last.time - before.time;
        if last.cloth.is_empty() || last.cloth.len() != before.cloth.len() || dt <= 0.0 {
            return None;
        }
        let sum: f64 = last
            .cloth
            .iter()
            .zip(&before.cloth)
            .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>())
            .sum();
        Some((sum / last.cloth.len() as f64).sqrt() / dt)
    }
}

/// Load, place, dress, settle and move: the whole garment scene. `base` is the folder relative
/// paths are resolved against; `progress` receives the fraction of the planned time done.
pub fn run_garment(
    spec: &GarmentSpec,
    base: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<GarmentRun, SceneError> {
    run_scene(Scene::load(spec, base)?, progress)
}

/// [`run_garment`] on a scene already set up (the try-on builds its own body and motion).
pub fn run_scene(scene: Scene, progress: &mut dyn FnMut(f64)) -> Result<GarmentRun, SceneError> {
    let frame_interval = scene.settings.frame_interval;
    let mut stats = StepStats::new(&scene);
    let mut sim = Simulation::new(scene)?;
    let to3 = |v: &[atelier_collide::V3]| -> Vec<[f64; 3]> {
        v.iter().map(|p| [p.x, p.y, p.z]).collect()
    };
    let frame = |sim: &Simulation| Frame {
        time: sim.time(),
        phase: sim.phase(),
        cloth: to3(&sim.state().positions),
        body: to3(sim.body_positions()),
        strain_error: sim.node_strain_errors(),
    };
    let mut run = GarmentRun::started(
        sim.cloth_triangles().to_vec(),
        sim.body_triangles().to_vec(),
        vec![frame(&sim)],
        sim.sewing_progress(),
    );
    let planned = sim.planned_time().max(f64::MIN_POSITIVE);
    let mut next_frame = frame_interval;
    let clock = Instant::now();
    loop {
        let start_time = sim.time();
        let outcome = match sim.step() {
            Ok(Some(o)) => o,
            Ok(None) => break,
            Err(e) => {
                run.failure = Some(e.to_string());
                break;
            }
        };
        run.timings.add(&outcome.timings);
        stats.add(&outcome, start_time);
        if sim.time() + 1e-9 >= next_frame {
            run.frames.push(frame(&sim));
            next_frame += frame_interval;
        }
        progress((sim.time() / planned).min(1.0));
    }
    run.wall_seconds = clock.elapsed().as_secs_f64();
    run.pairs = sim.sewing_progress();
    run.sewn_at = sim.sewn_at();
    run.warnings = sim.warnings().to_vec();
    run.panels = sim.node_panels();
    run.steps = stats.steps;
    run.max_strain_error = stats.max_strain_error;
    run.kinetic_energy = stats.kinetic_energy;
    run.max_motion_energy = stats.max_motion_energy;
    run.inside_at_end = stats.inside;
    run.max_penetration = stats.max_penetration;
    run.steps_with_penetration = stats.steps_with_penetration;
    run.convergence = stats.convergence();
    let last_time = run.frames.last().map_or(-1.0, |f| f.time);
    if (sim.time() - last_time).abs() > 1e-12 {
        run.frames.push(frame(&sim));
    }
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(time: f64, cloth: Vec<[f64; 3]>) -> Frame {
        Frame {
            time,
            phase: Phase::Settling,
            cloth,
            body: Vec::new(),
            strain_error: Vec::new(),
        }
    }

    fn run_with(frames: Vec<Frame>) -> GarmentRun {
        GarmentRun::started(Vec::new(), Vec::new(), frames, (0, 0))
    }

    /// Two nodes, one moved 3 mm in x and 4 mm in z between frames 0.04 s apart (5 mm: 0.125
    /// m/s), the other still: the root mean square is 0.125/√2 m/s; earlier frames do not count.
    #[test]
    fn final_rms_speed_is_the_root_mean_square_over_the_last_two_frames() {
        let run = run_with(vec![
            frame(0.0, vec![[9.0, 9.0, 9.0], [9.0, 9.0, 9.0]]),
            frame(1.0, vec![[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]),
            frame(1.04, vec![[0.003, 0.0, 0.004], [1.0, 1.0, 1.0]]),
        ]);
        let v = run.final_rms_speed().expect("two frames");
        assert!((v - 0.125 / 2f64.sqrt()).abs() < 1e-12, "{v}");
        assert_eq!(
            run_with(vec![frame(0.0, vec![[0.0; 3]])]).final_rms_speed(),
            None
        );
        assert_eq!(
            run_with(vec![frame(0.0, vec![]), frame(0.04, vec![])]).final_rms_speed(),
            None
        );
    }
}
