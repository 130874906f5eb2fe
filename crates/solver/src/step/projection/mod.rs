//! The shape stage (thesis (49)–(51); `method.md` §2b): the end-of-step velocities corrected so
//! that the predicted positions `x = r + ṙΔt` meet the cloth's constraints to a relative
//! tolerance —
//!
//! - every axial edge at its target length `l̄ = l⁰(1 + φ(p/W))` (equality, or stretch-only),
//! - every cell's shear angle γ held by a compliant constraint whose compliance is the inverse
//!   of the local slope of the fabric's shear loop (XPBD form, multipliers reset each step), and
//!   by a hard limit at the locking angle,
//! - seams: node pairs tied at length 0 are one point (their nodes move as one, with their
//!   summed mass); pairs being drawn together are held within their length (inequality),
//! - contact planes (no node ends the step behind its plane; Coulomb friction), projected after
//!   every iteration,
//! - pins (inverse mass 0).
//!
//! Methods: a global Newton iteration on the constraint-space system of [`crate::dual`] solved by
//! the LDLᵀ factorization (reused as a CG preconditioner while it stays good) or by
//! Jacobi-preconditioned CG; or the local iterations the thesis uses (Jacobi, with Chebyshev
//! acceleration, or Gauss–Seidel by colour) on the same rows. Every method stops on the same
//! measure: the largest relative violation over all rows (edges |l − l̄|/l⁰, cells the compliant
//! residual |C + α̃λ| in radians, ties and planes their excess over the nodes' spacing).
//!
//! This file holds the problem, the solver's state and its outer loop ([`ShapeSolver::solve`]);
//! the rows are built in `rows`, the Newton iteration's pieces are in `newton`, the contact
//! planes' active set in `contacts`, and the local iterations in `local`.

use atelier_collide::ContactPlane;
use faer::Par;
use nalgebra::Vector3;

use atelier_fabric::{Branch, MaterialTable, TensileLoop, TensileState};

use super::Tie;
use crate::cloth::Cloth;
use crate::dual::{DualError, DualSystem, NONE, Preconditioner, SLOTS};
use crate::kkt::KktSystem;
use crate::params::{ConstraintKind, ShapeMethod};
use crate::shear_angle::ShearMeasure;

type V3 = Vector3<f64>;

mod contacts;
mod local;
mod newton;
mod rows;
mod spindle_row;

pub use spindle_row::SpindleRow;

/// Below this many rows, loops run on one thread.
const PAR_MIN: usize = 2048;

/// Relative residual of each Newton step's linear solve (an inexact Newton step: the outer
/// iteration measures the constraints themselves).
const LINEAR_TOLERANCE: f64 = 1e-3;

/// CG iterations per Newton step with the factorization as preconditioner (a stale one that
/// needs this many is renewed before the next step).
const LINEAR_CAP: usize = 50;

/// The largest move of a node in one Newton step, as a fraction of its spacing (a trust
/// region against the huge steps of a nearly singular system).
const MAX_MOVE: f64 = 0.5;

/// The length mismatch of twin seam edges above which the longer is eased (gathers): below
/// it the two rows' small contradiction is taken up by the tension of the shorter (measured on
/// the skirt: easing every mismatch made 3 of 118 steps miss the tolerance instead of 1).
const EASE_THRESHOLD: f64 = 0.01;

/// Rounds of [`ShapeSolver::hold_entering`] per Newton step.
const MAX_CONTACT_ROUNDS: usize = 1;

/// A node within this fraction of its spacing in front of its plane lies on it.
const ON_PLANE: f64 = 1e-3;

/// Backtracking halvings of a Newton step before it is taken as it is.
const LINE_SEARCH_HALVINGS: usize = 6;

/// Iterations without a new low of the merit after which the line search is switched on for
/// the rest of the pass. Newton steps are otherwise taken whole (within the trust region): near
/// a solution the move towards the balance violates curved rows to second order (the Maratos
/// effect), the merit grows along the full step, and a line search that refuses it crawls by
/// 1/64 steps. Measured (`docs/solver.md`, "The line search, session 8"): 8 and 12 took the
/// sewn dress to 0.3 s in 21.1 iterations per step, 6 in 25.7, 3 in 55.8 with a step above
/// tolerance; without any line search the virtual KES shear test's steps cycled between two
/// iterates (4 steps above tolerance, G 6.7 % off).
const STALL_WINDOW: usize = 8;

/// Compliance of a seam being drawn together, as a fraction of its own stiffness (see the
/// tie rows in `evaluate`). Measured on the dress (cotton broad, Δt 10 ms): at 0.01 the pull
/// (about 20 N/m on the step's shortfall) lost to the bodice's 1 % hoop stretch and a side
/// seam stayed 13–21 mm open (297 of 310 pairs sewn at 2 s); at 1e-3 every pair is sewn at
/// 0.19 s; at 1e-4 the pull tore an edge (strain 1.35 at 0.14 s).
const TIE_COMPLIANCE: f64 = 1e-3;

/// Relative regularisation of hard rows (a compliance this small against the row's own
/// stiffness changes a converged length by ~1e-12 of the correction).
const HARD_REGULARISATION: f64 = 1e-12;

/// One cell's shear constraint for this step, linearised about the start of the step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellShear {
    /// The angle between the cell's u and v directions at rest, by the step's measure, rad.
    pub rest: f64,
    /// The shear angle at which the linearised shear force vanishes, γ₀ − τ₀/k, rad.
    pub offset: f64,
    /// Compliance 1/(k·S) of the cell (k the loop's local slope, N/(m·rad); S its area, m²).
    pub compliance: f64,
    /// Locking angle, rad (the shear angle is held within ±lock).
    pub lock: f64,
}

/// One node's bending along one grid direction for this step (the implicit bending model): the
/// turn θ of the grid line through the node about an axis fixed over the step
/// ([`crate::bend_angle`]), held by a compliant constraint linearised about the start of the
/// step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeBend {
    /// The axis the turn is measured about (m = t̄ × n at the start of the step).
    pub axis: V3,
    /// The turn at which the linearised moment vanishes, C₀ − m₀·l̄/k.
    pub offset: f64,
    /// Compliance l̄²/(k·S) (k the spindle's local slope, N·m; S the node's area; l̄ the mean
    /// rest length of the two edges).
    pub compliance: f64,
    /// With `bending.spindle_rows`, for a hysteretic row: the spindle read during the solve
    /// instead of the linearisation above.
    pub spindle_row: Option<SpindleRow>,
}

/// The axial edges' tensile characteristics, for [`Tension::Constraint`]: each edge's target
/// strain read at the force its own constraint exerts in the solve (implicit in the force).
#[derive(Clone, Copy)]
pub struct EdgeTension<'a> {
    /// Per-angle materials.
    pub table: &'a MaterialTable,
    /// Material entry of each edge.
    pub materials: &'a [u32],
    /// Width each edge carries, m.
    pub widths: &'a [f64],
    /// Tensile hysteresis state of each edge (peeked).
    pub states: &'a [TensileState],
    /// Whether to read through the states (false: the loading branch).
    pub hysteresis: bool,
}

impl EdgeTension<'_> {
    /// The strain of edge `e` at force per width `f` (N/m) and dε/df there ([`edge_strain`]).
    #[inline]
    fn strain_and_slope(&self, e: usize, f: f64) -> (f64, f64) {
        let l = self.table.tensile(self.materials[e]);
        edge_strain(l, self.hysteresis.then(|| &self.states[e]), f)
    }
}

/// The strain of an axial edge at force per width `f` (N/m) on loop `l` (through its
/// hysteresis `state`, or the loading branch), and dε/df there by a forward difference over a
/// small part of the loop's range (in compression the strain at zero force, and the toe's
/// slope, which the Newton rows use as their compliance). Smoother forms of the compression
/// side were tried and measured (`docs/solver.md`, "The tensile toe").
#[inline]
pub(super) fn edge_strain(l: &TensileLoop, state: Option<&TensileState>, f: f64) -> (f64, f64) {
    let at = |f: f64| match state {
        Some(st) => st.strain(l, f),
        None => l.strain(Branch::Loading, f),
    };
    let f = f.max(0.0);
    let h = 1e-6 * l.max_force() + 1e-3 * f;
    let eps = at(f);
    (eps, ((at(f + h) - eps) / h).max(0.0))
}

/// What the shape stage works on in one step.
pub struct ShapeProblem<'a> {
    /// The cloth.
    pub cloth: &'a Cloth,
    /// Positions at the start of the step, m.
    pub positions: &'a [V3],
    /// Time step, s.
    pub dt: f64,
    /// Simulated time at the start of the step, s (pins' positions).
    pub time: f64,
    /// Linear damping per area c/S, kg/(m²·s): the stage weights each node by the inverse of
    /// μ + cΔt, the mass of the velocity update (18), so that the damping, implicit in that
    /// update, is implicit for the constraint forces too (with 1/μ the damping would also eat a
    /// fraction cΔt/(μ + cΔt) of the static load: a cantilever at rest drooped as under 4 %
    /// less gravity at Δt 5 ms).
    pub damping: f64,
    /// Target length of every edge (axial ones used), m; with `internal.tension` set, only for
    /// reports (the targets then follow the solve's forces).
    pub targets: &'a [f64],
    /// With [`Tension::Constraint`]: the tensile characteristics the edge targets are read from
    /// at each edge's own constraint force, l̄ = l⁰(1 + φ(−λ/(W·Δt²))), with the compliance
    /// l⁰φ'/(W·Δt²) in the Newton system.
    pub tension: Option<EdgeTension<'a>>,
    /// Axial edges: equality or stretch-only.
    pub axial: ConstraintKind,
    /// How a cell's angle is measured.
    pub measure: ShearMeasure,
    /// One entry per cell; empty for no shear constraints.
    pub shear: &'a [CellShear],
    /// Two entries per node (u, v direction; used where the node has both neighbours in that
    /// direction); empty for no bending constraints.
    pub bends: &'a [NodeBend],
    /// Node pairs held within a length (length 0: sewn, one point).
    pub ties: &'a [Tie],
    /// One per node; a zero normal for none.
    pub planes: &'a [ContactPlane],
}

/// A constraint of the shape stage, for reports: which one was violated most.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Constraint {
    /// An axial edge's length (edge index).
    Edge(usize),
    /// A cell's shear (cell index).
    Cell(usize),
    /// A tie being drawn together (index in the step's ties).
    Tie(usize),
    /// A node's bending along a grid direction (node index, 0 for u and 1 for v).
    Bend(usize, u8),
    /// A node's contact plane (node index).
    Plane(usize),
}

/// What one call of [`ShapeSolver::solve`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShapeReport {
    /// Iterations (corrections applied).
    pub iterations: usize,
    /// Largest relative violation after the last iteration.
    pub violation: f64,
    /// Whether it is at or below the tolerance.
    pub converged: bool,
    /// Numeric factorizations made.
    pub factorizations: usize,
    /// Conjugate-gradient iterations.
    pub linear_iterations: usize,
    /// Halvings of Newton steps by the line search.
    pub backtracks: usize,
    /// Whether the line search was switched on (the merit stalled for [`STALL_WINDOW`]
    /// iterations).
    pub line_search: bool,
    /// The constraint with the largest violation (None when nothing is violated).
    pub worst: Option<Constraint>,
    /// Whether the solve was made again with the loaded edges warm-started after the first
    /// ended above the tolerance ([`ShapeSolver::solve`]).
    pub retried: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum RowKind {
    Edge(u32),
    Cell(u32),
    Tie(u32),
    /// Node, direction (0 u, 1 v); the neighbours before and after.
    Bend(u32, u8, [u32; 2]),
}

/// The rows and their system, for one grouping of the nodes and one set of open ties.
struct Structure {
    system: DualSystem,
    kinds: Vec<RowKind>,
    /// For each row, the slot of each of its original nodes (edge and tie: 2, cell: 4;
    /// `u8::MAX` beyond).
    corner_slot: Vec<[u8; 4]>,
    /// Each row's nodes (roots), [`NONE`] for unused slots.
    row_nodes: Vec<[u32; SLOTS]>,
    /// Rows that cannot act: all their nodes one point (fixed by the structure), or none of
    /// their nodes free to move (set each step from the pins).
    dead: Vec<bool>,
    /// Rows dead by the structure alone.
    collapsed: Vec<bool>,
    /// Edge rows that only resist stretching this step: an edge whose two nodes a tie draws
    /// together (a dart closing at its apex gathers the cloth between the legs; held at its
    /// length the edge would make the tie unattainable).
    gathered: Vec<bool>,
    /// Edge rows standing for their twins as well (both ends already one point each, so
    /// the rows are one row repeated): the kept row's width as a multiple of its edge's own
    /// (1 for every other row).
    width_scale: Vec<f64>,
    /// For an edge row retired as a twin, the row that stands for it (`NONE` otherwise).
    twin_of: Vec<u32>,
    /// The share of the standing row's force an edge row's own edge carries (1 for a row
    /// without twins, 0 for a gathered twin).
    force_share: Vec<f64>,
    /// Jacobi scaling: 1 / the largest row count over the row's nodes.
    local_scale: Vec<f64>,
    /// Rows in colours sharing no node (Gauss–Seidel), built on first use.
    colours: Vec<Vec<u32>>,
    root: Vec<u32>,
    open_ties: Vec<(u32, u32)>,
    with_cells: bool,
    with_bends: bool,
    /// The full Newton system ([`ShapeMethod::Newton`]), built on first use.
    kkt: Option<KktSystem>,
}

/// The shape stage's persistent state: the system (rebuilt only when the rows change), the
/// multipliers and the scratch.
#[derive(Default)]
pub struct ShapeSolver {
    structure: Option<Structure>,
    root: Vec<u32>,
    member_ptr: Vec<u32>,
    members: Vec<u32>,
    open_ties: Vec<(u32, u32)>,
    open_tie_index: Vec<u32>,
    /// Mean rest length of the axial edges at each node, m.
    spacing: Vec<f64>,
    lambda: Vec<f64>,
    c: Vec<f64>,
    viol: Vec<f64>,
    b: Vec<f64>,
    dl: Vec<f64>,
    diag: Vec<f64>,
    pred: Vec<V3>,
    prev: Vec<V3>,
    hat: Vec<V3>,
    lambda_prev: Vec<f64>,
    lambda_hat: Vec<f64>,
    saved_vel: Vec<V3>,
    /// The base point of the global methods, as end-of-step velocities: the prediction plus
    /// every correction the rows did not make (pins, planes, the pressure stage). The step's
    /// solution is `base + W Jᵀλ/Δt` with J at the solution (implicit Euler).
    base: Vec<V3>,
    /// Each node's move towards that balance this iteration, `base + W Jᵀλ/Δt − v` (× Δt, m).
    shift: Vec<V3>,
    /// Σ violation² of the last evaluation (the line search's merit).
    merit: f64,
    /// Nodes held on their contact plane in the Newton system (their weight projected onto
    /// the plane), per root node.
    on_plane: Vec<bool>,
    /// Nodes held on their plane for the rest of the step since a Newton step would have
    /// carried them through it ([`ShapeSolver::hold_entering`]).
    stuck: Vec<bool>,
    /// Symbolic analyses made (diagnostics).
    pub analyses: usize,
    /// The full Newton step per root node (m) and whether `apply` takes it.
    newton_dx: Vec<V3>,
    full_newton: bool,
    /// |λ|/l of each edge and tie row in tension (the geometric stiffness), else 0.
    tension_over_length: Vec<f64>,
    /// The velocities a first pass started from (for its warm-started second solve).
    start_vel: Vec<V3>,
}

impl ShapeSolver {
    /// Correct `vel` until the largest violation is at most `tol` or `max_iterations`
    /// corrections were made; `after` runs after every correction, before the hard
    /// constraints are projected again (the pressure stage's volume constraint, the long-range
    /// attachments). The rows are (re)built and the multipliers reset when `first_pass` (once
    /// per step). `step` is the Jacobi and Chebyshev γ.
    ///
    /// A first pass of a global method that ends above the tolerance is solved once more from
    /// the same start with the rows of loaded edges warm-started
    /// ([`ShapeSolver::warm_start_loaded_edges`]), when there are such rows and the rows did not
    /// change this step; the report then counts both solves' work.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &mut self,
        p: &ShapeProblem<'_>,
        vel: &mut [V3],
        method: ShapeMethod,
        step: f64,
        tol: f64,
        max_iterations: usize,
        first_pass: bool,
        after: &mut dyn FnMut(&mut [V3]),
    ) -> Result<ShapeReport, DualError> {
        let retry = first_pass && method.is_global();
        if retry {
            self.start_vel.clear();
            self.start_vel.extend_from_slice(vel);
        }
        let analyses = self.analyses;
        let mut run = |this: &mut Self, vel: &mut [V3], warm: bool| {
            this.solve_from(
                p,
                vel,
                method,
                step,
                tol,
                max_iterations,
                first_pass,
                warm,
                after,
            )
        };
        let cold = run(self, vel, false)?;
        // Not when the rows changed this step (seams closed: the ties' pull is gone, and the
        // last step's forces are the balance of another system).
        if cold.converged || !retry || self.analyses != analyses || !self.has_loaded_edges(p) {
            return Ok(cold);
        }
        vel.copy_from_slice(&self.start_vel);
        let mut warm = run(self, vel, true)?;
        warm.iterations += cold.iterations;
        warm.factorizations += cold.factorizations;
        warm.linear_iterations += cold.linear_iterations;
        warm.backtracks += cold.backtracks;
        warm.retried = true;
        Ok(warm)
    }

    /// One solve of [`ShapeSolver::solve`], its loaded edges warm-started when `warm_start`.
    #[allow(clippy::too_many_arguments)]
    fn solve_from(
        &mut self,
        p: &ShapeProblem<'_>,
        vel: &mut [V3],
        method: ShapeMethod,
        step: f64,
        tol: f64,
        max_iterations: usize,
        first_pass: bool,
        warm_start: bool,
        after: &mut dyn FnMut(&mut [V3]),
    ) -> Result<ShapeReport, DualError> {
        let mut warm = false;
        if first_pass || self.structure.is_none() {
            self.prepare(p)?;
            if warm_start {
                warm = self.warm_start_loaded_edges(p);
            }
        }
        let mut report = ShapeReport::default();
        self.project(p, vel);
        if first_pass {
            // The prediction is the base point; warm-started multipliers are not applied to
            // it yet (the first Newton step moves towards them).
            self.base.copy_from_slice(vel);
        } else {
            // Later passes: the velocities already carry the corrections of the multipliers.
            self.rebase(p, vel);
        }
        let mut omega = 1.0;
        let (mut violation, mut worst) = self.evaluate(p, vel);
        // The lowest merit so far and the iteration that reached it.
        let mut best = (f64::INFINITY, 0usize);
        loop {
            report.violation = violation;
            report.worst = worst;
            // A warm start meets the rows at the prediction only if the prediction is also the
            // balance with those multipliers, x̃ + W Jᵀλ: checked before the first iteration.
            if violation <= tol && (!warm || report.iterations > 0 || self.balanced(p, vel, tol)) {
                report.converged = true;
                break;
            }
            if report.iterations >= max_iterations {
                break;
            }
            let k = report.iterations;
            report.iterations += 1;
            if method.is_global() {
                self.update_contacts(p, vel);
                self.shift_towards_balance(p, vel, method != ShapeMethod::Newton);
            }
            self.full_newton = method == ShapeMethod::Newton;
            let newton = match method {
                ShapeMethod::Newton => {
                    self.newton_step()?;
                    report.factorizations += 1;
                    // A released node on its plane that the step would carry through it is held
                    // after all and the step solved again (an active-set correction): the
                    // projection would push it back, which the step did not foresee, and the
                    // step would be no descent direction for the rows at that node.
                    for round in 0..=MAX_CONTACT_ROUNDS {
                        if !self.hold_entering(p, vel) || round == MAX_CONTACT_ROUNDS {
                            break;
                        }
                        self.shift_towards_balance(p, vel, false);
                        self.newton_step()?;
                        report.factorizations += 1;
                    }
                    true
                }
                ShapeMethod::Direct { refactor_after } => {
                    // CG preconditioned by the factorization at hand (made first when there is
                    // none); when it does not reach the tolerance within `refactor_after`
                    // iterations the factorization is renewed and the solve repeated, so every
                    // Newton step is solved to LINEAR_TOLERANCE.
                    let st = self.structure.as_mut().expect("prepared");
                    let mut fresh = false;
                    if !st.system.is_factored() {
                        st.system.factorize(Par::Seq)?;
                        report.factorizations += 1;
                        fresh = true;
                    }
                    let mut stats = st.system.solve(
                        &self.b,
                        &mut self.dl,
                        LINEAR_TOLERANCE,
                        if fresh {
                            LINEAR_CAP
                        } else {
                            refactor_after.max(1)
                        },
                        Preconditioner::Factor,
                        Par::Seq,
                    )?;
                    report.linear_iterations += stats.iterations;
                    if stats.relative_residual > LINEAR_TOLERANCE && !fresh {
                        st.system.factorize(Par::Seq)?;
                        report.factorizations += 1;
                        stats = st.system.solve(
                            &self.b,
                            &mut self.dl,
                            LINEAR_TOLERANCE,
                            LINEAR_CAP,
                            Preconditioner::Factor,
                            Par::Seq,
                        )?;
                        report.linear_iterations += stats.iterations;
                    }
                    true
                }
                ShapeMethod::ConjugateGradient { cg_iterations } => {
                    let st = self.structure.as_mut().expect("prepared");
                    let stats = st.system.solve(
                        &self.b,
                        &mut self.dl,
                        LINEAR_TOLERANCE,
                        cg_iterations,
                        Preconditioner::Diagonal,
                        Par::Seq,
                    )?;
                    report.linear_iterations += stats.iterations;
                    true
                }
                ShapeMethod::Jacobi => {
                    self.jacobi(step);
                    self.apply(p, vel, 1.0, false, false);
                    false
                }
                ShapeMethod::Chebyshev { rho } => {
                    omega = match k {
                        0 => 1.0,
                        1 => 2.0 / (2.0 - rho * rho),
                        _ => 4.0 / (4.0 - rho * rho * omega),
                    };
                    // x_{k+1} = x_{k−1} + ω (x̂ − x_{k−1}), x̂ the Jacobi iterate from x_k; the
                    // multipliers the same way, so that compliant rows keep C + α̃λ consistent.
                    self.hat.copy_from_slice(vel);
                    self.lambda_hat.copy_from_slice(&self.lambda);
                    self.jacobi(step);
                    self.apply(p, vel, 1.0, false, false);
                    if k > 0 {
                        for (v, prev) in vel.iter_mut().zip(&self.prev) {
                            *v = prev + (*v - prev) * omega;
                        }
                        for (l, prev) in self.lambda.iter_mut().zip(&self.lambda_prev) {
                            *l = prev + (*l - prev) * omega;
                        }
                    }
                    std::mem::swap(&mut self.prev, &mut self.hat);
                    std::mem::swap(&mut self.lambda_prev, &mut self.lambda_hat);
                    false
                }
                ShapeMethod::GaussSeidel { omega } => {
                    self.gauss_seidel(p, vel, omega);
                    false
                }
            };
            if !newton {
                self.hat.copy_from_slice(vel);
                after(vel);
                self.project(p, vel);
                (violation, worst) = self.evaluate(p, vel);
                continue;
            }
            // The Newton step, whole (within the trust region) while the merit Σ violation²
            // keeps reaching new lows at least every STALL_WINDOW iterations; after that, for
            // the rest of the pass, halved while it does not reduce the merit (the last halving
            // taken whatever it gives).
            let merit = self.merit;
            if !report.line_search {
                if merit < (1.0 - 1e-4) * best.0 {
                    best = (merit, report.iterations);
                } else if report.iterations - best.1 >= STALL_WINDOW {
                    report.line_search = true;
                }
            }
            let halvings = if report.line_search {
                LINE_SEARCH_HALVINGS
            } else {
                0
            };
            self.saved_vel.copy_from_slice(vel);
            self.lambda_prev.copy_from_slice(&self.lambda);
            self.prev.copy_from_slice(&self.base);
            let mut scale = 1.0;
            for halving in 0..=halvings {
                self.apply(p, vel, scale, true, true);
                // What the hard constraints and the pressure change moves the base point too.
                self.hat.copy_from_slice(vel);
                after(vel);
                self.project(p, vel);
                for ((b, v), before) in self.base.iter_mut().zip(vel.iter()).zip(&self.hat) {
                    *b += v - before;
                }
                (violation, worst) = self.evaluate(p, vel);
                if self.merit <= (1.0 - 1e-4 * scale) * merit || halving == halvings {
                    break;
                }
                vel.copy_from_slice(&self.saved_vel);
                self.lambda.copy_from_slice(&self.lambda_prev);
                self.base.copy_from_slice(&self.prev);
                // The gradients back at the restored positions (the trial's evaluation
                // replaced them; Δx = W Jᵀ Δλ needs the Jacobian the step was solved with).
                self.evaluate(p, vel);
                scale *= 0.5;
                report.backtracks += 1;
            }
        }
        Ok(report)
    }

    /// Start the rows of edges on a loading branch above their dead band at the force their
    /// hysteresis state last committed (every other row starts at zero).
    ///
    /// From λ = 0 the first evaluation reads such an edge at zero force: a reversal onto the
    /// minor unloading branch, which near zero force is about a hundred times stiffer than the
    /// loading toe. The Newton iteration then crosses that kink back and forth and ends with
    /// the edges in compression, where a column between two clamps cannot meet its targets (the
    /// virtual KES-FB1 tensile test: 653 of 1 110 steps above the tolerance). Started at the
    /// committed force the iteration begins on the branch the edge travels. Edges within their
    /// band of zero, unloading, or without hysteresis start at zero as before (a start at their
    /// last force moved the bending instrument by 3–4 %: `docs/solver.md`, "Warm start of
    /// loaded edges"). The global methods only: their first step moves the positions towards
    /// the balance with the multipliers (the local methods would need the positions moved too).
    /// Returns whether any row was started.
    fn warm_start_loaded_edges(&mut self, p: &ShapeProblem<'_>) -> bool {
        let dt2 = p.dt * p.dt;
        let loaded: Vec<(usize, f64)> = self.loaded_edges(p).collect();
        for &(r, f) in &loaded {
            self.lambda[r] = -f * dt2;
        }
        !loaded.is_empty()
    }

    /// Whether any row would be warm-started ([`ShapeSolver::warm_start_loaded_edges`]).
    fn has_loaded_edges(&self, p: &ShapeProblem<'_>) -> bool {
        self.loaded_edges(p).next().is_some()
    }

    /// The rows of edges on a loading branch above their tensile dead band, with the force
    /// (N) their hysteresis state committed, over the row's width.
    fn loaded_edges<'s>(
        &'s self,
        p: &'s ShapeProblem<'_>,
    ) -> impl Iterator<Item = (usize, f64)> + 's {
        let t = p.tension.filter(|t| t.hysteresis);
        let st = self.structure.as_ref();
        st.zip(t).into_iter().flat_map(move |(st, t)| {
            st.kinds.iter().enumerate().filter_map(move |(r, kind)| {
                let RowKind::Edge(e) = *kind else { return None };
                if st.dead[r] || st.twin_of[r] != NONE || st.gathered[r] {
                    return None;
                }
                let e = e as usize;
                let state = &t.states[e];
                let band = t.table.tensile(t.materials[e]).deadband();
                (state.branch() == Branch::Loading && state.force() > band)
                    .then(|| (r, state.force() * t.widths[e] * st.width_scale[r]))
            })
        })
    }

    /// Whether `vel` is the balance with the current multipliers: every node within `tol` of
    /// its mean edge spacing of `base + W Jᵀλ/Δt` (J as the last evaluation left it).
    fn balanced(&mut self, p: &ShapeProblem<'_>, vel: &[V3], tol: f64) -> bool {
        self.shift_towards_balance(p, vel, false);
        self.shift
            .iter()
            .zip(&self.spacing)
            .all(|(s, h)| s.norm() <= tol * h)
    }

    /// The largest violation at `vel` and where it is, without correcting anything (after the
    /// collision passes: what the step ends with).
    pub fn measure(&mut self, p: &ShapeProblem<'_>, vel: &[V3]) -> (f64, Option<Constraint>) {
        if self.structure.is_none() {
            return (0.0, None);
        }
        self.evaluate(p, vel)
    }

    /// The force each axial edge's constraint exerted in the last solve, −λ/Δt² (N, tension
    /// positive), into `out` (one entry per edge of the topology; diagonals and edges without a
    /// row get 0).
    pub fn edge_forces(&self, dt: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|f| *f = 0.0);

        if let Some(st) = &self.structure {
            for (r, kind) in st.kinds.iter().enumerate() {
                if let RowKind::Edge(e) = kind {
                    // A row standing for its twins shares its force with them by width (the
                    // same force per width in each); a retired twin gets its share here.
                    let keep = match st.twin_of[r] {
                        NONE => r,
                        k => k as usize,
                    };
                    out[*e as usize] = -self.lambda[keep] * st.force_share[r] / (dt * dt);
                }
            }
        }
    }

    /// The force every constraint of the last solve exerted on each node, Σ_rows ∂C/∂x·λ/Δt²
    /// (N), into `out` (one entry per node). For a pinned node this is the reaction its pin
    /// must supply against the cloth (with the opposite sign): what a clamp of a tensile or
    /// shear tester measures. A group of sewn nodes reports its total on its first node.
    pub fn node_forces(&self, dt: f64, out: &mut [V3]) {
        out.iter_mut().for_each(|f| *f = V3::zeros());
        if let Some(st) = &self.structure {
            for r in 0..st.kinds.len() {
                if st.dead[r] {
                    continue;
                }
                let l = self.lambda[r] / (dt * dt);
                for k in SLOTS * r..SLOTS * (r + 1) {
                    let node = st.system.slot_node(k);
                    if node != NONE {
                        out[node as usize] += st.system.grad[k] * l;
                    }
                }
            }
        }
    }

    /// Number of rows of the current structure (0 before the first step).
    pub fn rows(&self) -> usize {
        self.structure.as_ref().map_or(0, |s| s.kinds.len())
    }

    /// Non-zeros of the system's lower triangle and of its factor.
    pub fn sizes(&self) -> (usize, usize) {
        self.structure.as_ref().map_or((0, 0), |s| s.system.sizes())
    }
}

#[cfg(test)]
mod tests;
