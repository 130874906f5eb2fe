//! `cargo xtask figures stability`: the stability map (issue 10) — for each solver (PARTY,
//! mass-spring, XPBD), time step × fabric (silk … denim) × the speed of the body holding the
//! cloth → stable, error or non-finite.
//!
//! Scene: a 0.4 m square sheet of 21 × 21 nodes (2 cm spacing), horizontal, held along one
//! edge by pins that move back and forth along the sheet (x) as `A sin(2πft)` with A = 5 cm and
//! f chosen for a peak speed of 0, 0.5, 1 or 2 m/s (0: fixed) — the "body" a garment hangs
//! from; 1 s simulated under gravity, each solver with its defaults but Δt (0.05–20 ms; PARTY
//! from 0.5 ms). Outcome:
//! `non-finite` — a step fails (divergence guard, non-finite state); `error` — it runs through
//! but some edge is stretched or compressed by more than 10 % at a check (every 0.05 s): the
//! answer is wrong although finite; `stable` — neither. Writes `stability.md` (one table per
//! solver) and `stability.png`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;
use atelier_fabric::{AnisotropyForm, Fabric, STANDARD_GRAVITY};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::baselines::{MassSpring, MassSpringParams, Xpbd, XpbdParams};
use atelier_solver::integrator::{
    Integrator, MassSpringIntegrator, Party, StepInput, XpbdIntegrator,
};
use atelier_solver::step::NoCollision;
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepParams};
use nalgebra::Vector3;
use plotters::prelude::*;
use rayon::prelude::*;

use crate::figures::plot::png;

const SOLVERS: [&str; 3] = ["PARTY", "mass-spring", "XPBD"];
const FABRICS: [&str; 4] = ["silk", "polyester_faille", "cotton_broad", "denim"];
const SPEEDS: [f64; 4] = [0.0, 0.5, 1.0, 2.0];
const STEPS_MS: [f64; 9] = [0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0];
/// PARTY is not run below this Δt (ms): its point is the large step, and 20 000 of its steps
/// per cell would dominate the run.
const PARTY_SMALLEST_MS: f64 = 0.5;
const SIDE: usize = 21;
const SPACING: f64 = 0.02;
const AMPLITUDE: f64 = 0.05;
const DURATION: f64 = 1.0;
const STRAIN_LIMIT: f64 = 0.10;

/// A case: solver, fabric, speed and time-step indices.
type Case = (usize, usize, usize, usize);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    Stable,
    Error,
    NonFinite,
    NotRun,
}

impl Outcome {
    fn word(self) -> &'static str {
        match self {
            Self::Stable => "stable",
            Self::Error => "error",
            Self::NonFinite => "non-finite",
            Self::NotRun => "not run",
        }
    }

    fn colour(self) -> RGBColor {
        match self {
            Self::Stable => RGBColor(0, 158, 115),
            Self::Error => RGBColor(230, 159, 0),
            Self::NonFinite => RGBColor(213, 94, 0),
            Self::NotRun => RGBColor(200, 200, 200),
        }
    }
}

/// The sheet of `fabric` held along its edge y = max by pins moving at peak `speed`.
fn scene(fabric: &Fabric, speed: f64) -> Result<(Cloth, ClothState)> {
    let size = (SIDE - 1) as f64 * SPACING;
    let grid = StructuredGrid::sheet(SIDE, SIDE, size, size);
    let topology = ClothTopology::from_structured(&grid)?;
    let mut cloth = Cloth::new(topology, fabric, AnisotropyForm::Thesis)?;
    let motion = if speed > 0.0 {
        PinMotion::Oscillate {
            amplitude: [AMPLITUDE, 0.0, 0.0],
            frequency: speed / (std::f64::consts::TAU * AMPLITUDE),
        }
    } else {
        PinMotion::Fixed
    };
    for node in (SIDE - 1) * SIDE..SIDE * SIDE {
        let [x, y] = grid.positions[node];
        cloth.pin(node as u32, Vector3::new(x, y, 0.0), motion)?;
    }
    let state = ClothState::flat(&cloth, 0.0);
    Ok((cloth, state))
}

fn largest_strain(cloth: &Cloth, state: &ClothState) -> f64 {
    atelier_solver::metrics::axial_strains(cloth, &state.positions)
        .map(f64::abs)
        .fold(0.0, f64::max)
}

/// One run: the outcome and the largest strain seen.
fn run(solver: &str, fabric: &Fabric, speed: f64, dt: f64) -> Result<(Outcome, f64)> {
    if solver == "PARTY" && dt < PARTY_SMALLEST_MS * 1e-3 - 1e-12 {
        return Ok((Outcome::NotRun, f64::NAN));
    }
    let (cloth, mut state) = scene(fabric, speed)?;
    let steps = (DURATION / dt).round() as usize;
    let check_every = ((0.05 / dt).round() as usize).max(1);
    // One interface for the three integrators: Δt and gravity are given with every step.
    let mut integrator: Box<dyn Integrator> = match solver {
        "PARTY" => Box::new(Party {
            solver: Solver::new(),
            params: StepParams::default(),
        }),
        "mass-spring" => Box::new(MassSpringIntegrator {
            solver: MassSpring::new(),
            params: MassSpringParams::default(),
        }),
        _ => Box::new(XpbdIntegrator {
            solver: Xpbd::new(),
            params: XpbdParams::default(),
        }),
    };
    let input = StepInput {
        dt,
        gravity: [0.0, 0.0, -STANDARD_GRAVITY],
    };
    let mut worst: f64 = 0.0;
    for k in 1..=steps {
        let ok = integrator
            .advance(&cloth, &mut state, input, &mut NoCollision)
            .is_ok();
        if !ok
            || state
                .positions
                .iter()
                .any(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Ok((Outcome::NonFinite, f64::INFINITY));
        }
        if k % check_every == 0 || k == steps {
            worst = worst.max(largest_strain(&cloth, &state));
        }
    }
    let outcome = if worst > STRAIN_LIMIT {
        Outcome::Error
    } else {
        Outcome::Stable
    };
    Ok((outcome, worst))
}

/// Run every case (in parallel) and write the table and the picture.
pub fn draw_all(root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let fabrics: Vec<Fabric> = FABRICS
        .iter()
        .map(|f| Fabric::load(&root.join(format!("fixtures/fabrics/{f}.ron"))))
        .collect::<Result<_, _>>()?;
    let mut cases = Vec::new();
    for s in 0..SOLVERS.len() {
        for f in 0..FABRICS.len() {
            for v in 0..SPEEDS.len() {
                for d in 0..STEPS_MS.len() {
                    cases.push((s, f, v, d));
                }
            }
        }
    }
    let t0 = std::time::Instant::now();
    let results: Vec<(Case, (Outcome, f64))> = cases
        .par_iter()
        .map(|&(s, f, v, d)| {
            let r = run(SOLVERS[s], &fabrics[f], SPEEDS[v], STEPS_MS[d] * 1e-3)?;
            Ok(((s, f, v, d), r))
        })
        .collect::<Result<_>>()?;
    eprintln!(
        "stability: {} runs in {:.0} s",
        results.len(),
        t0.elapsed().as_secs_f64()
    );
    let at = |s, f, v, d| {
        results
            .iter()
            .find(|r| r.0 == (s, f, v, d))
            .map(|r| r.1)
            .expect("every case ran")
    };
    let mut md = String::from(
        "# Stability map\n\nWritten by `cargo xtask figures stability` (see `xtask/src/figures/stability.rs` for the scene). Each cell: the outcome and the largest axial strain seen (%).\n",
    );
    for (s, name) in SOLVERS.iter().enumerate() {
        let _ = write!(md, "\n## {name}\n\n| fabric | body speed, m/s |");
        for dt in STEPS_MS {
            let _ = write!(md, " Δt {dt} ms |");
        }
        md.push_str("\n|---|---|");
        md.push_str(&"---|".repeat(STEPS_MS.len()));
        md.push('\n');
        for (f, fabric) in FABRICS.iter().enumerate() {
            for (v, speed) in SPEEDS.iter().enumerate() {
                let _ = write!(md, "| {fabric} | {speed} |");
                for d in 0..STEPS_MS.len() {
                    let (o, strain) = at(s, f, v, d);
                    if matches!(o, Outcome::NonFinite | Outcome::NotRun) {
                        let _ = write!(md, " {} |", o.word());
                    } else {
                        let _ = write!(md, " {} ({:.1}) |", o.word(), 100.0 * strain);
                    }
                }
                md.push('\n');
            }
        }
    }
    let table = out.join("stability.md");
    atelier_files::files::write_atomic(&table, md.as_bytes())?;
    // Summary: per solver and speed, the largest Δt up to which every smaller step run was
    // stable, over the fabrics (smallest – largest).
    let mut summary = String::from("| solver |");
    for speed in SPEEDS {
        let _ = write!(summary, " stable up to, held edge at {speed} m/s |");
    }
    summary.push_str(" outcomes beyond |\n|---|");
    summary.push_str(&"---|".repeat(SPEEDS.len() + 1));
    summary.push('\n');
    for (s, name) in SOLVERS.iter().enumerate() {
        let _ = write!(summary, "| {name} |");
        let mut beyond = std::collections::BTreeSet::new();
        for v in 0..SPEEDS.len() {
            let limits: Vec<Option<f64>> = (0..FABRICS.len())
                .map(|f| {
                    let mut last = None;
                    for (d, &ms) in STEPS_MS.iter().enumerate() {
                        match at(s, f, v, d).0 {
                            Outcome::NotRun => continue,
                            Outcome::Stable => last = Some(ms),
                            o => {
                                beyond.insert(o.word());
                                break;
                            }
                        }
                    }
                    last
                })
                .collect();
            let text = |x: Option<f64>| x.map_or("none".to_string(), |ms| format!("{ms} ms"));
            // The smallest limit over the fabrics ("none" if some fabric was never stable).
            let lo: Option<f64> = limits
                .iter()
                .copied()
                .collect::<Option<Vec<f64>>>()
                .map(|l| l.into_iter().fold(f64::MAX, f64::min));
            let hi = limits
                .iter()
                .copied()
                .flatten()
                .fold(None, |a: Option<f64>, b| Some(a.map_or(b, |a| a.max(b))));
            if lo == hi {
                let _ = write!(summary, " {} |", text(lo));
            } else {
                let _ = write!(summary, " {} – {} |", text(lo), text(hi));
            }
        }
        let beyond: Vec<&str> = beyond.into_iter().collect();
        let _ = writeln!(summary, " {} |", beyond.join(", "));
    }
    let summary_path = out.join("stability_summary.md");
    atelier_files::files::write_atomic(&summary_path, summary.as_bytes())?;
    let rows = FABRICS.len() * SPEEDS.len();
    let (cell_w, cell_h, left, top) = (40i32, 22i32, 150i32, 70i32);
    let panel_w = left + cell_w * STEPS_MS.len() as i32 + 30;
    let size = (
        (panel_w * SOLVERS.len() as i32) as u32,
        (top + cell_h * rows as i32 + 70) as u32,
    );
    let picture = out.join("stability.png");
    png(&picture, size, |root| {
        let text = |s: &str, x: i32, y: i32, px: u32| {
            root.draw(&Text::new(
                s.to_string(),
                (x, y),
                ("sans-serif", px).into_font().color(&BLACK),
            ))
        };
        for (s, name) in SOLVERS.iter().enumerate() {
            let x0 = panel_w * s as i32;
            text(name, x0 + left, 10, 20)?;
            text("Δt, ms", x0 + left, 34, 13)?;
            for (d, dt) in STEPS_MS.iter().enumerate() {
                text(&format!("{dt}"), x0 + left + cell_w * d as i32 + 8, 50, 13)?;
            }
            for (f, fabric) in FABRICS.iter().enumerate() {
                for (v, speed) in SPEEDS.iter().enumerate() {
                    let r = (f * SPEEDS.len() + v) as i32;
                    let y = top + cell_h * r;
                    if s == 0 || v == 0 {
                        let label = if v == 0 {
                            format!("{} {speed} m/s", fabric.replace('_', " "))
                        } else {
                            format!("{speed} m/s")
                        };
                        if s == 0 {
                            text(&label, x0 + 6, y + 4, 12)?;
                        }
                    }
                    for d in 0..STEPS_MS.len() {
                        let (o, _) = at(s, f, v, d);
                        let x = x0 + left + cell_w * d as i32;
                        root.draw(&Rectangle::new(
                            [(x, y), (x + cell_w - 2, y + cell_h - 2)],
                            o.colour().filled(),
                        ))?;
                    }
                }
            }
        }
        let y = top + cell_h * rows as i32 + 20;
        for (k, o) in [
            Outcome::Stable,
            Outcome::Error,
            Outcome::NonFinite,
            Outcome::NotRun,
        ]
        .iter()
        .enumerate()
        {
            let x = 20 + 260 * k as i32;
            root.draw(&Rectangle::new(
                [(x, y), (x + 20, y + 16)],
                o.colour().filled(),
            ))?;
            let what = match o {
                Outcome::Stable => "stable (strain ≤ 10 %)",
                Outcome::Error => "finite, strain > 10 %",
                Outcome::NonFinite => "non-finite / diverged",
                Outcome::NotRun => "not run (PARTY below 0.5 ms)",
            };
            text(what, x + 28, y + 1, 14)?;
        }
        Ok(())
    })?;
    Ok(vec![table, summary_path, picture])
}
