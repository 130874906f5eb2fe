//! Virtual KES-FB instruments on a simulated specimen (`method.md` §7, issue 21): the specimen is
//! clamped, one clamp is held, the other is driven the way the instrument drives it, and what the
//! instrument records is read from the **clamps' reactions** ([`Solver::constraint_forces`]: the
//! force the step's constraints exerted on the clamp's pinned nodes) — never from the model's
//! own characteristic functions or internal stresses. Each test then reduces its record as KES
//! does and must give back the fabric's input values.
//!
//! - [`shear_test`]: KES-FB1 shear — 20 cm wide × 5 cm between the clamps, warp along the 5 cm,
//!   the moving clamp slid parallel to itself through 0 → +8° → −8° → +8° (angle = clamp
//!   displacement / clamp gap) under the standard pretension of 10 gf/cm held like the
//!   instrument's weight (a constant pull across the clamps); G, 2HG and 2HG5 from the moving
//!   clamp's reaction along the shear direction per width ([`ShearCurve`]).
//! - [`fb1_tensile_test`] (and [`tensile_test`], its old signature): KES-FB1 tensile — the same
//!   specimen, the moving clamp pulled across at the KES strain rate until its reaction reaches
//!   F_m = 500 gf/cm and back until the reaction vanishes; EMT, LT, WT, RT from the reaction and
//!   the clamp displacement ([`TensileCurve::kes_values`]).
//! - [`bending_test`]: KES-FB2 — a 1 cm gauge between two clamps, one held, the other turned
//!   (and carried along the arc) through the curvature cycle 0 → +2.5 → −2.5 → 0 cm⁻¹ at
//!   0.5 cm⁻¹/s; the moment per width is the moving clamp's reaction moment; B and 2HB as KES
//!   reads them ([`BendingCurve`]).
//!
//! How each instrument is built, and what it measured for every fixture: `docs/validation.md`,
//! "Virtual KES instruments (issue 21)".

use atelier_fabric::{AnisotropyForm, Branch, Fabric, TensileLoop, units};
use atelier_grid::{ClothTopology, StructuredGrid, TopologyError};
use nalgebra::Vector3;

use crate::cloth::{Cloth, ClothError, PinMotion};
use crate::params::{ShapeParams, StepInput, StepParams};
use crate::state::ClothState;
use crate::step::{Solver, StepError};

type V3 = Vector3<f64>;

const DEG: f64 = std::f64::consts::PI / 180.0;

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
    /// The instrument could not reach its set point (force, pretension) within its step budget.
    #[error("KES instrument: {0}")]
    Instrument(String),
}

/// How well the steps of a virtual test met their constraints (the clamps read the constraint
/// forces, so a step that stops short of its tolerance reads a wrong force): the steps' counts
/// and their largest violation, [`crate::step::SolveStats`].
pub use crate::step::SolveStats;

/// One step of a virtual test, counted in `stats`.
fn counted_step(
    stats: &mut SolveStats,
    solver: &mut Solver,
    cloth: &Cloth,
    state: &mut ClothState,
    params: &StepParams,
    input: StepInput,
) -> Result<(), StepError> {
    let start = state.time;
    let r = solver.step(cloth, state, params, input)?;
    stats.add(&r, params, start);
    Ok(())
}

/// The sum of the forces the last step's constraints exerted on `nodes` (N) and their moment
/// (N·m) about `about`: minus what the clamp holding those nodes supplied.
fn clamp_reaction(
    solver: &Solver,
    dt: f64,
    positions: &[V3],
    nodes: &[usize],
    about: V3,
) -> (V3, V3) {
    let f = solver.constraint_forces(dt);
    nodes
        .iter()
        .fold((V3::zeros(), V3::zeros()), |(sum, moment), &i| {
            (sum + f[i], moment + (positions[i] - about).cross(&f[i]))
        })
}

/// Pin `nodes` at their rest positions (in the x–y plane) shifted by `offset`: a rigid clamp
/// carried to a new place. The pins' motion over the next step is the straight line from
/// where the nodes are to there.
fn place_clamp(cloth: &mut Cloth, nodes: &[usize], offset: V3) -> Result<(), ClothError> {
    for &i in nodes {
        let [x, y] = cloth.topology().rest_positions()[i];
        cloth.pin(i as u32, V3::new(x, y, 0.0) + offset, PinMotion::Fixed)?;
    }
    Ok(())
}

/// Linear interpolation in points sorted by x (constant beyond the ends).
fn linear_at(pts: &[(f64, f64)], x: f64) -> f64 {
    let k = pts.partition_point(|p| p.0 < x);
    if k == 0 {
        return pts.first().map_or(f64::NAN, |p| p.1);
    }
    if k >= pts.len() {
        return pts.last().map_or(f64::NAN, |p| p.1);
    }
    let ((x0, y0), (x1, y1)) = (pts[k - 1], pts[k]);
    if x1 <= x0 {
        return y1;
    }
    y0 + (y1 - y0) * (x - x0) / (x1 - x0)
}

/// Points of a pass sorted by their first coordinate (a falling pass reversed).
fn ascending(pts: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut v = pts.to_vec();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v
}

/// Mean slope (secant) of `pts` between `a` and `b`.
fn secant(pts: &[(f64, f64)], a: f64, b: f64) -> f64 {
    (linear_at(pts, b) - linear_at(pts, a)) / (b - a)
}

// ---------------------------------------------------------------------------------------------
// The KES-FB1 specimen
// ---------------------------------------------------------------------------------------------

/// The KES-FB1 specimen: nodes across (u), nodes along the load (v), width and gauge, m.
pub const FB1_SPECIMEN: (usize, usize, f64, f64) = (21, 6, 0.20, 0.05);

/// The KES-FB1 specimen along `direction` in the x–y plane, the load along y: its bottom row
/// (nodes `0..nu`) clamped, its top row (the last `nu` nodes) free.
pub fn fb1_specimen(
    fabric: &Fabric,
    form: AnisotropyForm,
    direction: Direction,
) -> Result<(Cloth, ClothState), KesError> {
    let (nu, nv, width, gauge) = FB1_SPECIMEN;
    fb1_specimen_on(fabric, form, direction, nu, nv, width, gauge)
}

/// [`fb1_specimen`] on an `nu × nv` grid of a `width × gauge` rectangle.
fn fb1_specimen_on(
    fabric: &Fabric,
    form: AnisotropyForm,
    direction: Direction,
    nu: usize,
    nv: usize,
    width: f64,
    gauge: f64,
) -> Result<(Cloth, ClothState), KesError> {
    let mut grid = StructuredGrid::sheet(nu, nv, width, gauge);
    // The sheet's warp runs along y (across the clamps); a weft specimen turns the grain.
    if direction == Direction::Weft {
        grid.grain_angle = 0.0;
    }
    let topo = ClothTopology::from_structured(&grid)?;
    let mut cloth = Cloth::new(topo, fabric, form)?;
    let bottom: Vec<usize> = (0..nu).collect();
    place_clamp(&mut cloth, &bottom, V3::zeros())?;
    let state = ClothState::placed(&cloth, |[x, y]| V3::new(x, y, 0.0));
    Ok((cloth, state))
}

/// Step parameters of the instruments: the physical air damping, one shape pass (no
/// collisions) solved to `tolerance` — the clamps read the constraint forces, so the
/// constraints must be met. The instruments step without gravity (the specimen lies in the
/// instrument's plane): [`StepInput::weightless`].
fn instrument_params(tolerance: f64) -> StepParams {
    StepParams {
        shape: ShapeParams {
            collision_passes: 1,
            tolerance,
            max_iterations: 100,
            ..ShapeParams::default()
        },
        ..StepParams::default()
    }
}

// ---------------------------------------------------------------------------------------------
// KES-FB1 tensile
// ---------------------------------------------------------------------------------------------

/// How the virtual KES-FB1 tensile instrument is run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TensileProtocol {
    /// Force per width at which the clamp turns back, N/m. Default F_m = 500 gf/cm.
    pub max_force: f64,
    /// Strain rate of the clamp, 1/s. Default 4e-3 (KES-FB1 standard).
    pub strain_rate: f64,
    /// Time step, s. Default 0.01 (a strain of 4e-5 per step at the standard rate).
    pub dt: f64,
}

impl Default for TensileProtocol {
    fn default() -> Self {
        Self {
            max_force: units::KES_MAX_TENSILE_FORCE,
            strain_rate: 4e-3,
            dt: 0.01,
        }
    }
}

/// The simulated tensile loop.
#[derive(Clone, Debug)]
pub struct TensileCurve {
    /// (force per width, N/m; strain) after every step: the moving clamp's reaction across the
    /// clamps over the specimen's width, and the clamp's displacement over the gauge. Loading up
    /// to the first point at F_m, then unloading; the last point has force 0.
    pub points: Vec<(f64, f64)>,
    /// The specimen at the end, and its cloth (for pictures).
    pub cloth: Cloth,
    /// Its state.
    pub state: ClothState,
    /// Steps taken.
    pub steps: usize,
    /// How well the steps met their constraints.
    pub stats: SolveStats,
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

/// The KES values of a fabric's own tensile loop (its input), for comparison.
pub fn input_values(l: &TensileLoop) -> TensileValues {
    let s = l.summary();
    TensileValues {
        emt: s.emt,
        lt: s.lt,
        wt: s.wt(),
        rt: s.rt,
    }
}

/// The virtual KES-FB1 tensile test along `direction`: the bottom clamp held, the top clamp
/// pulled across (along y) at `protocol.strain_rate` until the force per width its reaction
/// shows reaches `protocol.max_force`, then driven back until that force vanishes. The last
/// clamp moves before F_m and before zero are shortened (from the secant of the last two
/// records) so that the record turns at F_m and ends at 0 to 1e-4 of F_m, as the instrument's
/// force trigger does.
pub fn fb1_tensile_test(
    fabric: &Fabric,
    form: AnisotropyForm,
    direction: Direction,
    protocol: &TensileProtocol,
) -> Result<TensileCurve, KesError> {
    let (nu, nv, width, gauge) = FB1_SPECIMEN;
    let (mut cloth, mut state) = fb1_specimen(fabric, form, direction)?;
    let top: Vec<usize> = ((nv - 1) * nu..nv * nu).collect();
    place_clamp(&mut cloth, &top, V3::zeros())?;
    let (params, input) = (instrument_params(1e-7), StepInput::weightless(protocol.dt));
    let mut solver = Solver::new();
    let fm = protocol.max_force;
    let de = protocol.strain_rate * protocol.dt;
    let trigger = 1e-4 * fm;
    // A budget far beyond any fabric's EMT (KES fabrics stay below ~50 %).
    let budget = (2.0 / de) as usize + 100;
    let mut points: Vec<(f64, f64)> = Vec::new();
    let mut stats = SolveStats::default();
    let mut strain = 0.0;
    let mut step_to = |cloth: &mut Cloth,
                       state: &mut ClothState,
                       solver: &mut Solver,
                       strain: f64|
     -> Result<f64, KesError> {
        place_clamp(cloth, &top, V3::new(0.0, strain * gauge, 0.0))?;
        counted_step(&mut stats, solver, cloth, state, &params, input)?;
        let (f, _) = clamp_reaction(solver, input.dt, &state.positions, &top, V3::zeros());
        // The specimen pulls the top clamp back (−y): the instrument reads that pull.
        Ok(-f.y / width)
    };
    // Loading, to F_m.
    let (mut f_prev, mut e_prev) = (0.0, 0.0);
    loop {
        let mut next = strain + de;
        if let Some(&(f, e)) = points.last() {
            let k = (f - f_prev) / (e - e_prev);
            if k > 0.0 && f + k * de > fm {
                next = strain + ((fm - f) / k).max(1e-3 * de);
            }
            (f_prev, e_prev) = (f, e);
        }
        strain = next;
        let f = step_to(&mut cloth, &mut state, &mut solver, strain)?;
        points.push((f, strain));
        if f >= fm - trigger {
            break;
        }
        if points.len() > budget {
            return Err(KesError::Instrument(format!(
                "tensile: no {fm} N/m within a strain of {strain}"
            )));
        }
    }
    // Unloading, to zero force.
    let (mut f_prev, mut e_prev) = points[points.len().saturating_sub(2)];
    loop {
        let &(f, e) = points.last().expect("loaded");
        let mut next = strain - de;
        let k = (f - f_prev) / (e - e_prev);
        if k > 0.0 && f - k * de < 0.0 {
            next = strain - (f / k).max(1e-3 * de);
        }
        (f_prev, e_prev) = (f, e);
        strain = next;
        let f = step_to(&mut cloth, &mut state, &mut solver, strain)?;
        if f <= trigger {
            // The force crosses zero: record the crossing (interpolated in the last move).
            let (fa, ea) = *points.last().expect("loaded");
            let at = if fa - f > 0.0 {
                ea + (strain - ea) * fa / (fa - f)
            } else {
                strain
            };
            points.push((0.0, at));
            break;
        }
        points.push((f, strain));
        if points.len() > 2 * budget || strain < -0.1 {
            return Err(KesError::Instrument(
                "tensile: the force did not return to zero".into(),
            ));
        }
    }
    Ok(TensileCurve {
        points,
        cloth,
        state,
        steps: stats.steps,
        stats,
    })
}

/// The KES-FB1 tensile test along `direction` with the old signature: the clamp-driven
/// [`fb1_tensile_test`] at the standard rate with F_m the largest force of `path` (N/m). The
/// other levels of `path` and `hold` no longer matter (the instrument records every step; the
/// force levels used to be applied as loads on the free edge, which the clamp-driven test
/// replaces).
pub fn tensile_test(
    fabric: &Fabric,
    form: AnisotropyForm,
    direction: Direction,
    path: &[f64],
    hold: usize,
) -> Result<TensileCurve, KesError> {
    let _ = hold;
    let protocol = TensileProtocol {
        max_force: path.iter().copied().fold(0.0, f64::max),
        ..TensileProtocol::default()
    };
    fb1_tensile_test(fabric, form, direction, &protocol)
}

/// A quasi-static KES path `0 → peak → 0` (N/m) in `levels` equal steps each way.
pub fn cycle(peak: f64, levels: usize) -> Vec<f64> {
    let up = (1..=levels).map(move |k| peak * k as f64 / levels as f64);
    let down = (0..levels)
        .rev()
        .map(move |k| peak * k as f64 / levels as f64);
    up.chain(down).collect()
}

// ---------------------------------------------------------------------------------------------
// KES-FB1 shear
// ---------------------------------------------------------------------------------------------

/// How the virtual KES-FB1 shear instrument is run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShearProtocol {
    /// Largest shear angle of the cycle, rad. Default 8°.
    pub max_angle: f64,
    /// Shear rate (clamp speed over the clamp gap), rad/s. Default 1°/s (about twice the
    /// instrument's; the model has no rate dependence but inertia and air damping, and halving
    /// it changes G, 2HG, 2HG5 by < 0.1 %: test `virtual_kes_shear_test_is_quasi_static`).
    pub rate: f64,
    /// Time step, s. Default 0.1 (0.1° per step at the default rate).
    pub dt: f64,
    /// Pretension across the clamps, N/m. Default 10 gf/cm (KES-FB1 standard).
    pub tension: f64,
    /// Nodes across (u, the 20 cm) and between the clamps (v, the 5 cm). Default 21 × 6 (1 cm).
    pub grid: (usize, usize),
    /// The shape stage's tolerance (relative strain of the edges, rad of the cells). Default
    /// 1e-6 (a pull error of ≤ 0.6 % of the pretension on the softest fixture's warp).
    pub tolerance: f64,
}

impl Default for ShearProtocol {
    fn default() -> Self {
        Self {
            max_angle: 8.0 * DEG,
            rate: DEG,
            dt: 0.1,
            tension: units::force_from_kes(10.0),
            grid: (21, 6),
            tolerance: 1e-5,
        }
    }
}

/// KES summary values of a shear loop (SI: G in N/(m·rad), widths in N/m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShearValues {
    /// G: the mean of the four mean slopes (secants) between 0.5° and 5° — upper and lower
    /// branch, positive and negative side.
    pub g: f64,
    /// 2HG: the mean loop width at ±0.5°.
    pub two_hg: f64,
    /// 2HG5: the mean loop width at ±5°.
    pub two_hg5: f64,
}

/// The simulated shear loop.
#[derive(Clone, Debug)]
pub struct ShearCurve {
    /// (shear angle, rad; shear force per width, N/m) after every step of the three passes
    /// 0 → +max, +max → −max, −max → +max: the angle the instrument imposes (clamp displacement
    /// over the clamp gap), the force the moving clamp's reaction shows along its motion over
    /// the specimen's width.
    pub passes: [Vec<(f64, f64)>; 3],
    /// The pull across the clamps the moving clamp's reaction shows at each point of the
    /// passes, N/m (the pretension, held by the instrument).
    pub tension: [Vec<f64>; 3],
    /// G, 2HG, 2HG5 read off the lower branch (+max → −max) and the upper branch (−max → +max).
    pub values: ShearValues,
    /// The largest relative deviation of the pull from the pretension over the last two passes.
    pub tension_error: f64,
    /// The root-mean-square relative deviation of the pull from the pretension over the last
    /// two passes.
    pub tension_rms_error: f64,
    /// The specimen at the end, and its cloth.
    pub cloth: Cloth,
    /// Its state.
    pub state: ClothState,
    /// Steps taken (pretensioning included).
    pub steps: usize,
    /// How well the steps met their constraints.
    pub stats: SolveStats,
}

/// G, 2HG and 2HG5 as KES-FB1 reads them off the upper branch (angle rising) and the lower
/// branch (angle falling), both as `(angle rad, force N/m)`.
pub fn shear_values(upper: &[(f64, f64)], lower: &[(f64, f64)]) -> ShearValues {
    let (upper, lower) = (ascending(upper), ascending(lower));
    let (lo, hi) = atelier_fabric::shear::KES_SHEAR_ANGLES;
    let slope = |pts: &[(f64, f64)]| 0.5 * (secant(pts, lo, hi) + secant(pts, -hi, -lo));
    let width = |x: f64| {
        0.5 * ((linear_at(&upper, x) - linear_at(&lower, x))
            + (linear_at(&upper, -x) - linear_at(&lower, -x)))
    };
    ShearValues {
        g: 0.5 * (slope(&upper) + slope(&lower)),
        two_hg: width(lo),
        two_hg5: width(hi),
    }
}

/// The virtual KES-FB1 shear test (warp across the clamps, as the standard has it): the
/// specimen pulled to `protocol.tension` across the clamps, then the moving clamp slid parallel
/// to itself (along x) through 0 → +max → −max → +max at `protocol.rate`.
///
/// The pretension is held as the instrument's weight holds it — a constant pull across the
/// clamps, the moving clamp free to follow along y: the clamp's y is servoed to the pull its
/// reaction shows. It follows the path on which the warp between the clamps keeps its length,
/// y = √(y₀² − d²) (y₀ the pretensioned gap, d the displacement), plus an integral correction
/// of a fifth of the pull's error over the specimen's tangent stiffness per step (stable for
/// branches up to ten times stiffer than the loading branch, which the tensile minor loops are).
/// [`ShearCurve::tension_error`] says how well it held.
pub fn shear_test(
    fabric: &Fabric,
    form: AnisotropyForm,
    protocol: &ShearProtocol,
) -> Result<ShearCurve, KesError> {
    let (nu, nv) = protocol.grid;
    let (width, gauge) = (FB1_SPECIMEN.2, FB1_SPECIMEN.3);
    let (mut cloth, mut state) =
        fb1_specimen_on(fabric, form, Direction::Warp, nu, nv, width, gauge)?;
    let top: Vec<usize> = ((nv - 1) * nu..nv * nu).collect();
    place_clamp(&mut cloth, &top, V3::zeros())?;
    let params = instrument_params(protocol.tolerance);
    let input = StepInput::weightless(protocol.dt);
    let mut solver = Solver::new();
    let t = protocol.tension;
    // The servo's gain: the specimen's stiffness across the clamps at the pretension, on the
    // warp's loading branch (only how fast the servo settles depends on it, not what is read).
    let warp = &fabric.tensile.warp;
    let h = 1e-3 * t;
    let slope =
        2.0 * h / (warp.strain(Branch::Loading, t + h) - warp.strain(Branch::Loading, t - h));
    let stiffness = slope * width / gauge;
    let mut stats = SolveStats::default();
    let mut step_to = |cloth: &mut Cloth,
                       state: &mut ClothState,
                       solver: &mut Solver,
                       d: f64,
                       y: f64|
     -> Result<(f64, f64), KesError> {
        place_clamp(cloth, &top, V3::new(d, y - gauge, 0.0))?;
        counted_step(&mut stats, solver, cloth, state, &params, input)?;
        let (f, _) = clamp_reaction(solver, input.dt, &state.positions, &top, V3::zeros());
        // The shear force: what holds the clamp against the specimen along its motion (the
        // specimen pulls it back, −x); the pull across the clamps (−y).
        Ok((-f.x / width, -f.y / width))
    };
    // Pretension: the clamp pulled across until the pull settles at T (from below, at the
    // loading branch's tangent at T: the loading branch is convex, so it never overshoots).
    let mut y = gauge;
    let mut pull = 0.0;
    let mut settled = 0;
    let mut pretension_steps = 0;
    while settled < 3 {
        y += (t - pull) * width / stiffness;
        (_, pull) = step_to(&mut cloth, &mut state, &mut solver, 0.0, y)?;
        pretension_steps += 1;
        settled = if (pull - t).abs() < 1e-4 * t {
            settled + 1
        } else {
            0
        };
        if pretension_steps > 2000 {
            return Err(KesError::Instrument(format!(
                "shear: the pretension did not settle ({pull} N/m of {t})"
            )));
        }
    }
    let y0 = y;
    let mut correction = 0.0;
    // The cycle.
    let per_step = protocol.rate * protocol.dt;
    let n = (protocol.max_angle / per_step).round().max(1.0) as usize;
    let max = protocol.max_angle;
    let legs = [(0.0, max, n), (max, -max, 2 * n), (-max, max, 2 * n)];
    let mut passes: [Vec<(f64, f64)>; 3] = Default::default();
    let mut tension: [Vec<f64>; 3] = Default::default();
    for (pass, &(from, to, count)) in legs.iter().enumerate() {
        for i in 1..=count {
            let gamma = from + (to - from) * i as f64 / count as f64;
            let d = gamma * gauge;
            correction += 0.2 * (t - pull) * width / stiffness;
            let y = (y0 * y0 - d * d).sqrt() + correction;
            let (fs, p) = step_to(&mut cloth, &mut state, &mut solver, d, y)?;
            pull = p;
            passes[pass].push((gamma, fs));
            tension[pass].push(p);
        }
    }
    let values = shear_values(&passes[2], &passes[1]);
    let tension_error = tension[1..]
        .iter()
        .flatten()
        .map(|p| (p / t - 1.0).abs())
        .fold(0.0, f64::max);
    let measured: Vec<f64> = tension[1..].iter().flatten().map(|p| p / t - 1.0).collect();
    let tension_rms_error =
        (measured.iter().map(|e| e * e).sum::<f64>() / measured.len().max(1) as f64).sqrt();
    Ok(ShearCurve {
        passes,
        tension,
        values,
        tension_error,
        tension_rms_error,
        cloth,
        state,
        steps: stats.steps,
        stats,
    })
}

// ---------------------------------------------------------------------------------------------
// KES-FB2 bending
// ---------------------------------------------------------------------------------------------

/// The simulated bending loop.
#[derive(Clone, Debug)]
pub struct BendingCurve {
    /// (curvature, 1/m; moment per width, N) on the three passes: 0 → +K, +K → −K, −K → 0: the
    /// curvature the instrument imposes (the moving clamp's turn over the gauge), the moment
    /// the moving clamp's reaction shows about the bending axis over the specimen's width.
    pub passes: [Vec<(f64, f64)>; 3],
    /// Bending rigidity B from the loop, N·m: the mean of the least-squares slopes over
    /// 0.5–1.5 cm⁻¹ of both branches on each side.
    pub rigidity: f64,
    /// Hysteresis width 2HB at ±1 cm⁻¹, N (mean of both sides).
    pub two_hb: f64,
    /// The largest force the moving clamp's reaction showed, per width, N/m (0 in pure
    /// bending: how far the specimen is from it).
    pub max_clamp_force: f64,
    /// The specimen at the end.
    pub cloth: Cloth,
    /// Its state.
    pub state: ClothState,
    /// Time step, s (5 s over the steps per leg: the KES rate of 0.5 cm⁻¹/s).
    pub dt: f64,
    /// Steps taken.
    pub steps: usize,
    /// How well the steps met their constraints.
    pub stats: SolveStats,
}

/// Joints (bending nodes) of the KES-FB2 specimen along its 1 cm gauge, the two at the clamps'
/// edges included.
pub const FB2_JOINTS: usize = 11;

/// The KES-FB2 bending test along `direction`: a strip of 1 cm gauge between two clamps (each
/// one grid row deep), one clamp held, the other turned about the bending axis and carried along
/// the arc so that the strip can take a uniform curvature K = (the clamp's turn)/(gauge):
/// 0 → +2.5 → −2.5 → 0 cm⁻¹ at the KES rate 0.5 cm⁻¹/s, `per_leg` steps for 0 → 2.5 cm⁻¹
/// (Δt = 5 s/`per_leg`). The interior nodes are free: the solver's bending constraints and edges
/// hold them. The moment is the moving clamp's reaction moment about the bending axis through
/// its edge, per width.
///
/// The strip's bending lives at its nodes (joints), each standing for one spacing h of the
/// fabric; the two joints at the clamps' edges stand half in the jaw. The gauge is therefore
/// divided into [`FB2_JOINTS`] spacings (h = 1 cm / 11) with the jaws' lines half a spacing
/// inside the clamps, so that the joints carry exactly the gauge's length of fabric; the
/// moving clamp sits where a polygon of equal turns θ = K·h from the held clamp puts it (the
/// strip's equilibrium shape under a uniform moment), so the instrument imposes no force.
pub fn bending_test(
    fabric: &Fabric,
    form: AnisotropyForm,
    direction: Direction,
    per_leg: usize,
) -> Result<BendingCurve, KesError> {
    let (gauge, width) = (0.01, 0.01);
    let joints = FB2_JOINTS;
    let h = gauge / joints as f64;
    // Rows 0, 1: the held clamp; rows joints, joints + 1: the moving clamp.
    let nv = joints + 2;
    let mut grid = StructuredGrid::sheet(2, nv, width, (nv - 1) as f64 * h);
    if direction == Direction::Weft {
        grid.grain_angle = 0.0;
    }
    let topo = ClothTopology::from_structured(&grid)?;
    let mut cloth = Cloth::new(topo, fabric, form)?;
    // The strip lies along y (x across it), bending about x; row j at rest at y = j·h.
    let row = |j: usize| [2 * j, 2 * j + 1];
    // Row j of the polygon of equal turns θ at rows 1..: its (y, z) position.
    let polygon = |theta: f64, j: usize| -> (f64, f64) {
        let (mut y, mut z) = (0.0, 0.0);
        for k in 0..j {
            let a = if k == 0 { 0.0 } else { k as f64 * theta };
            y += h * a.cos();
            z += h * a.sin();
        }
        (y, z)
    };
    let rest = cloth.topology().rest_positions().to_vec();
    let moving: Vec<usize> = [row(joints), row(joints + 1)].concat();
    let held: Vec<usize> = [row(0), row(1)].concat();
    let place_moving = |cloth: &mut Cloth, k: f64| -> Result<V3, ClothError> {
        let theta = k * h;
        for j in [joints, joints + 1] {
            let (y, z) = polygon(theta, j);
            for i in row(j) {
                cloth.pin(i as u32, V3::new(rest[i][0], y, z), PinMotion::Fixed)?;
            }
        }
        let (y, z) = polygon(theta, joints);
        Ok(V3::new(0.0, y, z))
    };
    for &i in &held {
        cloth.pin(
            i as u32,
            V3::new(rest[i][0], rest[i][1], 0.0),
            PinMotion::Fixed,
        )?;
    }
    place_moving(&mut cloth, 0.0)?;
    let mut state = ClothState::placed(&cloth, |[x, y]| V3::new(x, y, 0.0));
    let kmax = units::KES_MAX_CURVATURE;
    let dt = (kmax / (0.5 * units::CURVATURE)) / per_leg as f64;
    let (params, input) = (instrument_params(1e-7), StepInput::weightless(dt));
    let mut solver = Solver::new();
    let leg = |a: f64, b: f64, n: usize| (1..=n).map(move |i| a + (b - a) * i as f64 / n as f64);
    let path: Vec<(usize, f64)> = leg(0.0, kmax, per_leg)
        .map(|k| (0, k))
        .chain(leg(kmax, -kmax, 2 * per_leg).map(|k| (1, k)))
        .chain(leg(-kmax, 0.0, per_leg).map(|k| (2, k)))
        .collect();
    let mut passes: [Vec<(f64, f64)>; 3] = Default::default();
    let mut stats = SolveStats::default();
    let mut max_force: f64 = 0.0;
    for (pass, k) in path {
        let edge = place_moving(&mut cloth, k)?;
        counted_step(&mut stats, &mut solver, &cloth, &mut state, &params, input)?;
        let (f, m) = clamp_reaction(&solver, dt, &state.positions, &moving, edge);
        max_force = max_force.max(f.norm() / width);
        // The specimen's moment on the clamp about x; the instrument holds it with the opposite.
        passes[pass].push((k, -m.x / width));
    }
    let one = units::CURVATURE;
    let fit = |pts: &[(f64, f64)], sign: f64| {
        let sel: Vec<(f64, f64)> = pts
            .iter()
            .copied()
            .filter(|p| sign * p.0 >= 0.5 * one - 1e-9 && sign * p.0 <= 1.5 * one + 1e-9)
            .collect();
        let n = sel.len() as f64;
        let (sx, sy) = sel.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
        let (mx, my) = (sx / n, sy / n);
        let (num, den) = sel.iter().fold((0.0, 0.0), |a, p| {
            (a.0 + (p.0 - mx) * (p.1 - my), a.1 + (p.0 - mx).powi(2))
        });
        num / den
    };
    let rigidity = 0.25
        * (fit(&passes[0], 1.0)
            + fit(&passes[1], 1.0)
            + fit(&passes[1], -1.0)
            + fit(&passes[2], -1.0));
    let (p0, p1, p2) = (
        ascending(&passes[0]),
        ascending(&passes[1]),
        ascending(&passes[2]),
    );
    let two_hb = 0.5
        * ((linear_at(&p0, one) - linear_at(&p1, one))
            + (linear_at(&p2, -one) - linear_at(&p1, -one)));
    Ok(BendingCurve {
        passes,
        rigidity,
        two_hb,
        max_clamp_force: max_force,
        cloth,
        state,
        dt,
        steps: stats.steps,
        stats,
    })
}
