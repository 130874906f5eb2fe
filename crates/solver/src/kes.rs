//! Virtual KES-FB tests on a simulated specimen (`method.md` §7): the strip, loaded the way the
//! KES instruments load a specimen, must give back the characteristics it was built from.
//!
//! - [`tensile_test`]: KES-FB1 — a 20 cm wide strip with a 5 cm gauge along the tested
//!   direction, one edge clamped, a force per width on the other edge stepped along a path
//!   (0 → F_m → 0 for the full loop); the mean strain of the interior edges along the load at
//!   each level. [`TensileCurve::kes_values`] gives EMT, LT, WT and RT of the simulated loop.
//! - [`bending_test`]: KES-FB2 — a strip of 1 cm gauge (10 cells) bent to a uniform curvature
//!   0 → +2.5 → −2.5 → 0 cm⁻¹; the moment per width and the curvature at the middle nodes as
//!   the solver's bending stage evaluates them; B is the slope over 0.5–1.5 cm⁻¹, 2HB the loop's
//!   width at ±1 cm⁻¹.

use atelier_fabric::{AnisotropyForm, Fabric, units};
use atelier_grid::{ClothTopology, StructuredGrid, TopologyError};
use nalgebra::Vector3;

use crate::cloth::{Cloth, ClothError, PinMotion};
use crate::params::StepParams;
use crate::state::ClothState;
use crate::step::{Solver, StepError};

type V3 = Vector3<f64>;

/// The direction a specimen is cut along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum Direction {
    /// Along the warp.
    #[default]
    Warp,
    /// Along the weft.
    Weft,
}

/// Why a virtual test could not run.
#[derive(Debug, thiserror::Error)]
pub enum KesError {
    /// The specimen's grid.
    #[error(transparent)]
    Grid(#[from] TopologyError),
    /// The cloth (the fabric at the specimen's angles).
    #[error(transparent)]
    Cloth(#[from] ClothError),
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
}

/// The simulated tensile loop.
#[derive(Clone, Debug)]
pub struct TensileCurve {
    /// (force per width, N/m; mean strain) after each level of the path.
    pub points: Vec<(f64, f64)>,
    /// The specimen at the end, and its cloth (for pictures).
    pub cloth: Cloth,
    /// Its state.
    pub state: ClothState,
    /// Steps taken.
    pub steps: usize,
}

/// KES summary values of a tensile loop (SI inside: strain as a fraction, energy in J/m²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TensileValues {
    /// Strain at the largest force (EMT as a fraction).
    pub emt: f64,
    /// Linearity LT = WT / (F_m·EMT/2).
    pub lt: f64,
    /// Work of loading WT, J/m².
    pub wt: f64,
    /// Resilience RT = recovered work / WT (a fraction).
    pub rt: f64,
}

impl TensileCurve {
    /// EMT, LT, WT and RT of the loop (trapezoidal areas under the loading and unloading
    /// branches: the path's rising and falling halves).
    pub fn kes_values(&self) -> TensileValues {
        values_of(&self.points)
    }
}

/// EMT, LT, WT and RT of a loop given as (force, strain) points, rising then falling.
pub fn values_of(points: &[(f64, f64)]) -> TensileValues {
    let peak = points
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.0.total_cmp(&b.1.0))
        .map_or(0, |(k, _)| k);
    let area = |pts: &[(f64, f64)]| {
        pts.windows(2)
            .map(|w| 0.5 * (w[0].0 + w[1].0) * (w[1].1 - w[0].1))
            .sum::<f64>()
            .abs()
    };
    let mut rising = vec![(0.0, 0.0)];
    rising.extend_from_slice(&points[..=peak]);
    let falling = &points[peak..];
    let (fm, emt) = points[peak];
    let wt = area(&rising);
    let recovered = area(falling);
    TensileValues {
        emt,
        lt: if fm * emt > 0.0 {
            wt / (0.5 * fm * emt)
        } else {
            0.0
        },
        wt,
        rt: if wt > 0.0 { recovered / wt } else { 0.0 },
    }
}

/// The KES-FB1 specimen: nodes across (u), nodes along the load (v), width and gauge, m.
pub const FB1_SPECIMEN: (usize, usize, f64, f64) = (21, 6, 0.20, 0.05);

/// The KES-FB1 specimen along `direction` in the x–y plane, the load along y: its bottom row
/// (nodes `0..nu`) clamped, its top row (the last `nu` nodes) free to be pulled.
pub fn fb1_specimen(
    fabric: &Fabric,
    form: AnisotropyForm,
    direction: Direction,
) -> Result<(Cloth, ClothState), KesError> {
    let (nu, nv, width, gauge) = FB1_SPECIMEN;
    let mut grid = StructuredGrid::sheet(nu, nv, width, gauge);
    // The sheet's warp runs along y (the load); a weft specimen turns the grain across.
    if direction == Direction::Weft {
        grid.grain_angle = 0.0;
    }
    let topo = ClothTopology::from_structured(&grid)?;
    let mut cloth = Cloth::new(topo, fabric, form)?;
    let place = |[x, y]: [f64; 2]| V3::new(x, y, 0.0);
    for i in 0..nu {
        let p = cloth.topology().rest_positions()[i];
        cloth.pin(i as u32, place(p), PinMotion::Fixed)?;
    }
    let state = ClothState::placed(&cloth, place);
    Ok((cloth, state))
}

/// The KES-FB1 tensile test along `direction` over `path` (forces per width, N/m), holding each
/// level `hold` steps of 0.01 s.
pub fn tensile_test(
    fabric: &Fabric,
    form: AnisotropyForm,
    direction: Direction,
    path: &[f64],
    hold: usize,
) -> Result<TensileCurve, KesError> {
    let (nu, nv, width, gauge) = FB1_SPECIMEN;
    let (cloth, mut state) = fb1_specimen(fabric, form, direction)?;
    let params = StepParams {
        dt: 0.01,
        gravity: [0.0; 3],
        damping: 5.0,
        // A quasi-static test with loads of 500 gf/cm on a few milligrams per node: the
        // internal forces must balance each node's load tightly, or the remainder accelerates
        // the light edge nodes far in one step.
        internal_tolerance: 1e-9,
        internal_max_iterations: 500,
        shape_tolerance: 1e-9,
        shape_max_iterations: 200,
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let h = width / (nu - 1) as f64;
    let top: Vec<usize> = ((nv - 1) * nu..nv * nu).collect();
    let mut points = Vec::with_capacity(path.len());
    let mut steps = 0;
    for &per_width in path {
        solver.external_forces = vec![V3::zeros(); nu * nv];
        for &i in &top {
            let share = if i == top[0] || i == top[nu - 1] {
                0.5 * h
            } else {
                h
            };
            solver.external_forces[i] = V3::new(0.0, per_width * share, 0.0);
        }
        for _ in 0..hold {
            solver.step(&cloth, &mut state, &params)?;
            steps += 1;
        }
        // Mean strain of the load-direction edges of the interior columns.
        let strains: Vec<f64> = (2..nu - 2)
            .flat_map(|i| (0..nv - 1).map(move |j| (j * nu + i, (j + 1) * nu + i)))
            .map(|(a, b)| {
                (state.positions[b] - state.positions[a]).norm() / (gauge / (nv - 1) as f64) - 1.0
            })
            .collect();
        points.push((
            per_width,
            strains.iter().sum::<f64>() / strains.len() as f64,
        ));
    }
    Ok(TensileCurve {
        points,
        cloth,
        state,
        steps,
    })
}

/// A quasi-static KES path `0 → peak → 0` (N/m) in `levels` equal steps each way.
pub fn cycle(peak: f64, levels: usize) -> Vec<f64> {
    let up = (1..=levels).map(move |k| peak * k as f64 / levels as f64);
    let down = (0..levels)
        .rev()
        .map(move |k| peak * k as f64 / levels as f64);
    up.chain(down).collect()
}

/// The simulated bending loop.
#[derive(Clone, Debug)]
pub struct BendingCurve {
    /// (curvature, 1/m; moment per width, N) on the three passes: 0 → +K, +K → −K, −K → 0.
    pub passes: [Vec<(f64, f64)>; 3],
    /// Bending rigidity B from the loop, N·m (slope over 0.5–1.5 cm⁻¹ of both passes).
    pub rigidity: f64,
    /// Hysteresis width 2HB at ±1 cm⁻¹, N.
    pub two_hb: f64,
    /// The specimen at the end.
    pub cloth: Cloth,
    /// Its state.
    pub state: ClothState,
    /// Steps taken.
    pub steps: usize,
}

/// The KES-FB2 bending test along `direction`: the instrument imposes a uniform curvature on
/// the whole 1 cm gauge; here every node of the strip (10 cells along the tested direction, 2
/// nodes across 1 cm) is moved, step by step, onto a circular arc of curvature K: 0 → +2.5 →
/// −2.5 → 0 cm⁻¹ in `per_leg` steps of 1 ms per leg. The solver's bending stage estimates the
/// curvature from the node normals and evaluates the moment through the hysteresis states it
/// commits each step (with its regularisation: stick slope, dead band). (Driving only the
/// clamps and letting the interior settle is a dynamic problem in its own right: at Δt = 2e-4 s
/// the interior rings by ±1 cm⁻¹ and every step starts a minor loop; see `docs/solver.md`.)
pub fn bending_test(
    fabric: &Fabric,
    form: AnisotropyForm,
    direction: Direction,
    per_leg: usize,
) -> Result<BendingCurve, KesError> {
    let (cells, gauge, width) = (10usize, 0.01, 0.01);
    let h = gauge / cells as f64;
    let nv = cells + 3; // one clamp row beyond each end
    let mut grid = StructuredGrid::sheet(2, nv, width, (nv - 1) as f64 * h);
    if direction == Direction::Weft {
        grid.grain_angle = 0.0;
    }
    let topo = ClothTopology::from_structured(&grid)?;
    let mut cloth = Cloth::new(topo, fabric, form)?;
    let centre = 0.5 * (nv - 1) as f64 * h;
    // Node (i, j) on the arc of curvature k through the centre, tangent along x there.
    let on_arc = |k: f64, x: f64, y: f64| {
        let s = y - centre;
        if k.abs() < 1e-12 {
            V3::new(s, x, 0.0)
        } else {
            V3::new((k * s).sin() / k, x, (1.0 - (k * s).cos()) / k)
        }
    };
    let rest = cloth.topology().rest_positions().to_vec();
    for (node, &[x, y]) in rest.iter().enumerate() {
        cloth.pin(node as u32, on_arc(0.0, x, y), PinMotion::Fixed)?;
    }
    let mut state = ClothState::placed(&cloth, |[x, y]| on_arc(0.0, x, y));
    let params = StepParams {
        dt: 1e-3,
        gravity: [0.0; 3],
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let kmax = units::KES_MAX_CURVATURE;
    let leg = |a: f64, b: f64| (1..=per_leg).map(move |i| a + (b - a) * i as f64 / per_leg as f64);
    let path: Vec<(usize, f64)> = leg(0.0, kmax)
        .map(|k| (0, k))
        .chain(leg(kmax, -kmax).map(|k| (1, k)))
        .chain(leg(-kmax, 0.0).map(|k| (2, k)))
        .collect();
    let middle = [2 * (nv / 2), 2 * (nv / 2) + 1];
    let mut passes: [Vec<(f64, f64)>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    let mut steps = 0;
    for (pass, k) in path {
        for (node, &[x, y]) in rest.iter().enumerate() {
            cloth.pin(node as u32, on_arc(k, x, y), PinMotion::Fixed)?;
        }
        solver.step(&cloth, &mut state, &params)?;
        steps += 1;
        let eta = middle
            .iter()
            .map(|&i| 0.5 * (solver.last_curvatures()[i][2] + solver.last_curvatures()[i][3]))
            .sum::<f64>()
            / 2.0;
        let moment: f64 = middle
            .iter()
            .map(|&i| solver.last_node_moments()[i])
            .sum::<f64>()
            / width;
        passes[pass].push((eta, moment));
    }
    // The strip's normal may point either way: orient curvature (and moment) so that the first
    // leg bends positively, as the instrument's first pass does.
    let orientation = passes[0].last().map_or(1.0, |p| p.0.signum());
    for pass in &mut passes {
        for p in pass.iter_mut() {
            *p = (orientation * p.0, orientation * p.1);
        }
    }
    let slope = |pts: &[(f64, f64)], sign: f64| {
        let sel: Vec<(f64, f64)> = pts
            .iter()
            .copied()
            .filter(|p| {
                sign * p.0 >= 0.5 * units::CURVATURE && sign * p.0 <= 1.5 * units::CURVATURE
            })
            .collect();
        let n = sel.len() as f64;
        let (sx, sy) = sel.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
        let (mx, my) = (sx / n, sy / n);
        let (num, den) = sel.iter().fold((0.0, 0.0), |a, p| {
            (a.0 + (p.0 - mx) * (p.1 - my), a.1 + (p.0 - mx).powi(2))
        });
        num / den
    };
    let at = |pts: &[(f64, f64)], eta: f64| {
        pts.iter()
            .min_by(|a, b| (a.0 - eta).abs().total_cmp(&(b.0 - eta).abs()))
            .map_or(0.0, |p| p.1)
    };
    let one = units::CURVATURE;
    let rigidity = 0.5 * (slope(&passes[0], 1.0) + slope(&passes[1], -1.0));
    let two_hb = 0.5
        * ((at(&passes[0], one) - at(&passes[1], one))
            + (at(&passes[2], -one) - at(&passes[1], -one)));
    Ok(BendingCurve {
        passes,
        rigidity,
        two_hb,
        cloth,
        state,
        steps,
    })
}
