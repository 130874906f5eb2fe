//! The sewn dress in silk, cotton broad and denim at rest, side by side (issue 21, item 7): front
//! and side views, with bending hysteresis (the defaults) and without, and a table of the hems'
//! extents (`metrics::hem_extent`, the report's `hem_width_m` / `hem_depth_m`). The same runs as
//! `crates/atelier/tests/own/fabrics_on_body.rs`, which asserts the ordering.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use atelier::picture::garment_views;
use atelier::pipeline::{GarmentRun, run_garment};
use atelier::scenario::{Scenario, ScenarioKind};
use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_solver::metrics::{HEM_BAND, hem_extent};
use plotters::prelude::*;
use rayon::prelude::*;

use crate::figures::plot::{blit, png};

/// The fabrics, by fixture file, in the order drawn.
const FABRICS: [&str; 3] = ["silk", "cotton_broad", "denim"];

/// Time under gravity after sewing, s (as the test: the scenario's 1 s leaves the hems swinging).
const SETTLE: f64 = 3.0;

/// One dress at rest and what the table reads from it.
struct Dressed {
    fabric: &'static str,
    hysteresis: bool,
    bending_length: f64,
    run: GarmentRun,
}

impl Dressed {
    fn last(&self) -> &atelier::pipeline::Frame {
        self.run
            .frames
            .last()
            .expect("a run records its last frame")
    }

    /// Root-mean-square node speed between the last two frames, m/s.
    fn speed(&self) -> f64 {
        self.run.final_rms_speed().unwrap_or(f64::NAN)
    }
}

fn dress(root: &Path, fabric: &'static str, hysteresis: bool) -> Result<Dressed> {
    let dir = root.join("fixtures/scenarios");
    let s = Scenario::load(&dir.join("dress_sewn.ron"))?;
    let ScenarioKind::Garment(mut spec) = s.kind else {
        bail!("dress_sewn is not a garment scenario")
    };
    spec.fabric = Path::new("../fabrics").join(format!("{fabric}.ron"));
    spec.settings.settle = SETTLE;
    spec.settings.step.hysteresis = hysteresis;
    let bending_length = Fabric::load(&dir.join(&spec.fabric))?
        .bending_length(0.0, AnisotropyForm::default())
        .map_err(anyhow::Error::msg)?;
    let run =
        run_garment(&spec, &dir, &mut |_| {}).with_context(|| format!("the dress in {fabric}"))?;
    if run.frames.len() < 2 {
        bail!("the dress in {fabric}: fewer than two frames");
    }
    Ok(Dressed {
        fabric,
        hysteresis,
        bending_length,
        run,
    })
}

/// Draw the dresses into `out`; returns the files written.
pub fn draw_all(root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let cases: Vec<(&'static str, bool)> = [true, false]
        .into_iter()
        .flat_map(|h| FABRICS.map(|f| (f, h)))
        .collect();
    let dressed: Vec<Dressed> = cases
        .par_iter()
        .map(|&(f, h)| dress(root, f, h))
        .collect::<Result<_>>()?;
    let mut md = format!(
        "# The dress in three fabrics, at rest\n\nThe eight-panel dress (`dress_sewn.ron`) sewn, then {SETTLE} s under gravity; Δt 0.01 s. Hem: the cloth nodes within {:.0} cm of the lowest; width = front view (x), depth = side view (z). Speed: root mean square over the nodes between the last two frames (0.04 s apart).\n\n| bending hysteresis | fabric | c = (B/W)^⅓, warp | hem width | hem depth | rms speed at the end | steps above the tolerance |\n|---|---|---|---|---|---|---|\n",
        HEM_BAND * 100.0
    );
    for d in &dressed {
        let hem = hem_extent(&d.last().cloth, HEM_BAND).context("non-finite cloth")?;
        let c = &d.run.convergence;
        writeln!(
            md,
            "| {} | {} | {:.2} cm | {:.1} cm | {:.1} cm | {:.1} mm/s | {} of {} |",
            if d.hysteresis { "on (default)" } else { "off" },
            d.fabric.replace('_', " "),
            d.bending_length * 100.0,
            hem.width * 100.0,
            hem.depth * 100.0,
            d.speed() * 1e3,
            c.unconverged_steps.unwrap_or(0),
            c.steps
        )?;
    }
    let table = out.join("dress_fabrics.md");
    atelier_files::files::write_atomic(&table, md.as_bytes())?;
    let (w, h, top, label) = (300usize, 420usize, 40usize, 36usize);
    let rows = dressed.len() / FABRICS.len();
    let path = png(
        &out.join("dress_fabrics.png"),
        (
            (FABRICS.len() * 2 * w) as u32,
            (top + rows * (h + label)) as u32,
        ),
        |area| {
            area.draw(&Text::new(
                format!(
                    "The sewn dress after {SETTLE} s under gravity, front and side: bending length grows left to right"
                ),
                (10, 12),
                ("sans-serif", 19).into_font(),
            ))?;
            for (k, d) in dressed.iter().enumerate() {
                let (row, col) = (k / FABRICS.len(), k % FABRICS.len());
                let last = d.last();
                let pixels = garment_views(
                    (&last.cloth, &d.run.cloth_triangles),
                    Some((&last.body, &d.run.body_triangles)),
                    w,
                    h,
                );
                let (x0, y0) = (col * 2 * w, top + row * (h + label));
                let hem = hem_extent(&last.cloth, HEM_BAND).context("non-finite cloth")?;
                area.draw(&Text::new(
                    format!(
                        "{}, c {:.2} cm, hysteresis {}: hem {:.1} × {:.1} cm",
                        d.fabric.replace('_', " "),
                        d.bending_length * 100.0,
                        if d.hysteresis { "on" } else { "off" },
                        hem.width * 100.0,
                        hem.depth * 100.0
                    ),
                    ((x0 + 10) as i32, (y0 + 8) as i32),
                    ("sans-serif", 16).into_font(),
                ))?;
                blit(area, &pixels, 2 * w, (x0, y0 + label))?;
            }
            Ok(())
        },
    )?;
    Ok(vec![path, table])
}
